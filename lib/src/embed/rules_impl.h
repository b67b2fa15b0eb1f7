/* embed module, private to the files of the cut-cell rules build: what one cell and one piece
 * produce, what every cell reads, and the calls between the build's phases (cell_rules.c
 * drives; rules_build.c, classify.c, cut_cells.c, auto_policy.c, distribute.c, cuts.c). */
#ifndef FCM_EMBED_RULES_IMPL_H
#define FCM_EMBED_RULES_IMPL_H

#include "embed/embed_impl.h"
#include "element/element_impl.h"

#define GIB (1024.0 * 1024.0 * 1024.0)

/* Whether the options / rules ask for volume rules of kind k. */
#define KIND_BUILT(kinds, k) ((((unsigned)(kinds)) >> (unsigned)(k)) & 1u)

/* A cell whose parts' total volume the cut splitting changes by more than this fraction of
 * the cell's volume meets the cut in a way the tolerances cannot resolve (near-coincident
 * vertices classified differently); fcm_cell_rules_create_cut() then shifts the cut. */
#define DEGENERATE_RTOL 1e-12
/* A cut whose degenerate cells no shift resolves is still taken, in its attempt of least change,
 * when that change is at most this fraction of every cell's volume: the layer the cuts'
 * tolerance leaves. A vertex taken as on a plane lies up to FCM__EMBED_MATCH_RTOL x the cell's
 * diagonal off it, and the two halves of a split then overlap or part in a layer that thin
 * over some of their cap (measured: up to 1.7e-10 on 2,000 warped sheets in one cell, every
 * piece on its side; `embed_cut_warped study 2000`). */
#define DEGENERATE_ACCEPT_RTOL 1e-9

/* What one material piece of a cell produced (private to the thread that built it). */
typedef struct piece_out {
  int n[FCM_RULE_KIND_COUNT];
  double *pts[FCM_RULE_KIND_COUNT];
  double *w[FCM_RULE_KIND_COUNT];
  unsigned char *flag[FCM_RULE_KIND_COUNT];
  int ninit[FCM_RULE_KIND_COUNT], nsimp[FCM_RULE_KIND_COUNT], nstab[FCM_RULE_KIND_COUNT];
  unsigned char skipped[FCM_RULE_KIND_COUNT], fallback[FCM_RULE_KIND_COUNT];
  double residual[FCM_RULE_KIND_COUNT];
  double tsimp[FCM_RULE_KIND_COUNT]; /* fcm_simplify's time_total */
  unsigned char copied; /* rules copied from the rules being extended (not counted as built) */
  /* pts, w, flag, spts, sw, snrm, stri (borrowed) and cfxi (cf_borrowed) point into the rules
   * being extended: read only, not freed */
  unsigned char borrowed, cf_borrowed;
  unsigned char fitted; /* rules fitted on surface moments (at most M points: not simplified) */
  int parent;    /* the piece of the same cell in the rules being extended that holds this one */
  int component; /* its number among the cell's components before empty ones were dropped */
  int ns;
  double *spts, *sw, *snrm;
  fcm_index *stri;
  int ncf;      /* cut-face triangles */
  double *cfxi; /* 9 reference coordinates each */
  double volume;
} piece_out;

/* What one cell produced: its pieces (pc == &one for at most one piece), and for cells
 * next to cuts the polygons of its pieces on its faces (for the links between cells). */
typedef struct cell_out {
  int np;
  piece_out one;
  piece_out *pc;
  double volume;
  double dropped_area; /* a dropped cell's share of the embedded surface (surface rules on) */
  int nfp;             /* face polygons: meta (FCM__EMBED_FMETA each) x nfp, coordinates fx (the
                          polygon's, then its part's) */
  int *fmeta;
  double *fx;
  /* the face polygons come from the parts of the earlier cuts' triangles alone, split in one
   * pass (a region cell no new triangle reaches): the rules keep them for the next cut */
  unsigned char fp_keep;
} cell_out;

/* Everything the per-cell work reads; the trees and rules are owned (fcm__embed_build_release). */
typedef struct build {
  fcm_ctx *ctx;
  const fcm_mesh *mesh;
  const fcm_geometry *geom;
  const fcm_cell_rules_options *o;
  const fcm_aabb_tree *tree, *tri_tree;           /* the geometry's own (fcm__geom_tree()) */
  fcm_rule *tet_rule[FCM_RULE_KIND_COUNT];        /* rule mapped onto each tet */
  const fcm_rule *full_rule[FCM_RULE_KIND_COUNT]; /* catalogue rule of the cell shape (in R) */
  fcm_rule *tri_rule;                             /* NULL: no surface rules */
  int surface;                                    /* the surface path is on (tri_tree is built) */
  fcm__moment_quad mq; /* its quadratures, exact for the largest of fit_strength */
  int fit_strength[FCM_RULE_KIND_COUNT];   /* each kind's strength, built or not */
  int fit_M[FCM_RULE_KIND_COUNT];          /* the number of moments of total degree <= each
                                              kind's strength (sizes the candidates and the
                                              path choice, whatever the cap per variable) */
  int fit_tet_points[FCM_RULE_KIND_COUNT]; /* points of the tet rule of that strength */
  /* The cut cells' moment space of each built kind: R's strength and axis_degree, but the
   * stiffness's is the mass kind's with o->stiffness_on_mass_space; grid_M: the candidates'
   * size, the largest total-degree space of the kinds (their rules then do not depend on each
   * other's cap per variable), or with the shared space its own size. */
  int space_m[FCM_RULE_KIND_COUNT], space_q[FCM_RULE_KIND_COUNT], grid_M;
  int stabilize[FCM_RULE_KIND_COUNT];
  /* Cutting: the tree of R->cut_tris (NULL without cuts); region[c]: cell c shares a node
   * with a cell the cuts reach (its face polygons are recorded for the links); rebuild[c]:
   * integrate cell c (NULL: every cell), else copy its rules from prev; prev_region[c]: the
   * region of prev, whose links cover the pairs of its cells (NULL: prev has no cuts);
   * same_links[c]: cell c and its face neighbours in the region are in prev's region and
   * the new cut reaches none of them: their links are prev's, c needs no face polygons. */
  fcm_aabb_tree *cut_tree;
  const fcm__cut_tri *cut_tris;
  unsigned char *region, *rebuild, *prev_region, *same_links;
  double *cell_mvol; /* R->cell_mvol for a body given by its surface, else NULL */
  const fcm_cell_rules *prev;
  fcm_index first_new; /* cut triangles from here on are new (those of the cut being added) */
  int keep; /* cuts: keep the cells the new cut leaves unchanged, and the links of cells it does
               not reach (fcm__cell_rules_create_cut_keep()) */
  fcm__rules_reduce *red;      /* distributed AUTO: sums the choice's inputs (NULL: none) */
  const unsigned char *remote; /* distributed classification: cells another process classifies
                                  (skipped here), NULL: none */
} build;

/* What one thread summed over the cells it built. */
typedef struct cell_sums {
  fcm__embed_counts counts;
  double time_intersect, time_simplify; /* seconds of one core */
} cell_sums;

/* ---- rules_build.c: around the per-cell work */

/* FCM_ERR_ARG naming the first bad option (reduced: a reduce for the AUTO choice is given). */
fcm_status fcm__embed_check_options(fcm_ctx *ctx, const fcm_cell_rules_options *o, int reduced);

/* FCM_ERR_GEOMETRY when background cell c is not convex (the rules build's first check). */
fcm_status fcm__embed_check_convex(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_index c,
                                   const fcm_cell_rules_options *o);

/* Phase 1a: the result object with its per-cell arrays, strengths and catalogue rules. */
fcm_status fcm__embed_rules_alloc(fcm_ctx *ctx, const fcm_mesh *mesh,
                                  const fcm_cell_rules_options *o, fcm_cell_rules **out);

/* Phase 1b: what every cell reads (B is zeroed first; fcm__embed_build_release() frees it). */
fcm_status fcm__embed_build_setup(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                  const fcm_cell_rules_options *o, const fcm_cell_rules *R,
                                  build *B);
void fcm__embed_build_release(build *B);

/* Phase 3: concatenate the pieces' volume and surface rules in cell order. */
fcm_status fcm__embed_gather_rules(fcm_ctx *ctx, fcm_cell_rules *R, const cell_out *out,
                                   const fcm_cell_rules *prev);

/* Phase 4: the statistics (times are filled in by the caller). */
void fcm__embed_gather_stats(fcm_cell_rules *R, const fcm_geometry *geom, const cell_out *out,
                             const cell_sums *sums, int nthreads);

/* ---- classify.c: the per-cell work */

void fcm__embed_cell_out_free(fcm_ctx *ctx, cell_out *o);

/* Room for np pieces in o (inline for one). */
fcm_status fcm__embed_cell_out_pieces(fcm_ctx *ctx, cell_out *o, int np);

/* Phase 2: every cell in parallel into its own cell_out; thread sums into *sums. An error
 * is that of the lowest failing cell, whatever the thread count. */
fcm_status fcm__embed_run_cells(const build *B, fcm_cell_rules *R, int nthreads, cell_out *out,
                                cell_sums *sums, const fcm_cell_rules_options *opt);

/* ---- cut_cells.c: the rules of a cut cell's pieces */

/* Simplify the kinds with simp[k] set, then append the stabilization points. */
fcm_status fcm__embed_finish_cell(const build *B, piece_out *o, const int simp[FCM_RULE_KIND_COUNT],
                                  cell_sums *sums);

/* Map the tets in ws into piece o's initial rules of both kinds (after the memory check). */
fcm_status fcm__embed_map_piece(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                                piece_out *o);

/* The surface points in ws into o, mapped to reference coordinates. */
fcm_status fcm__embed_surface_piece(const build *B, const fcm__embed_cell *cell,
                                    const fcm__embed_ws *ws, piece_out *o);

/* ---- surface_cells.c: the surface path */

/* The material volume of an affine cell from the surface moments (the signed rule stays in
 * ws for the fit); box: the reference bounding box of the boundary's parts in the cell. */
fcm_status fcm__embed_surface_volume(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                                     double *vol, double box[6]);

/* After fcm__embed_surface_volume() on the same cell (volume vol, box): piece o's rules of
 * every kind built, fitted on candidates inside the material (o->fitted); *ok = 0 (o left
 * without points, why says what failed) when the candidates cannot carry the moments. */
fcm_status fcm__embed_surface_piece_fit(const build *B, const fcm__embed_cell *cell,
                                        fcm__embed_ws *ws, const double box[6], double vol,
                                        piece_out *o, int *ok, char *why, size_t why_len);

/* Piece `piece` of a cell of a body without a volume mesh (P->mat, the parts split by the
 * cuts): its rules of every kind built, fitted on points inside the piece to the moments of the
 * body in its parts (o->fitted); where no fit is found (*fell_back = 1), the initial rules of
 * the volume path on its parts split by the boundary (fcm__embed_piece_body_tets()), to be
 * simplified. */
fcm_status fcm__embed_surface_cut_piece(const build *B, const fcm__embed_cell *cell,
                                        fcm__embed_ws *ws, fcm__parts *P, int piece, piece_out *o,
                                        int *fell_back);

/* ---- auto_policy.c */

/* Phase 2b of FCM_CELL_SIMPLIFY_AUTO: choose per kind whether simplification pays, then
 * finish every piece integrated here. */
fcm_status fcm__embed_auto_simplify(const build *B, fcm_cell_rules *R, int nthreads, cell_out *out,
                                    cell_sums *sums);

/* ---- distribute.c */

/* The remote cells' class, fraction and volume from the exchange (x) into R and out;
 * *exchanged is set once the exchange ran (whatever its outcome). */
fcm_status fcm__embed_exchange_classes(const build *B, fcm_cell_rules *R,
                                       const fcm__rules_exchange *x, cell_out *out, cell_sums *sums,
                                       int *exchanged);

/* ---- cuts.c */

/* Phase 1c (cuts only): the tree of R's cut triangles, the region and the cells to
 * integrate. */
fcm_status fcm__embed_cut_setup(build *B, fcm_cell_rules *R, fcm_index first_new);

/* Phase 3b (cuts only): the links between pieces of face-neighbouring region cells. */
fcm_status fcm__embed_gather_links(const build *B, fcm_cell_rules *R, const cell_out *out);

/* Phase 3c (cuts only): the face polygons R keeps for the next cut (fcm_cell_rules'
 * face_nfp): those of the cells out marks fp_keep (moved from out), and the earlier rules'
 * of the cells the new cut does not reach. */
fcm_status fcm__embed_keep_face_polygons(const build *B, fcm_cell_rules *R, cell_out *out);

/* Copies of cell c's face polygons that Q keeps (Q->face_nfp[c] >= 0): *nfp of them. */
fcm_status fcm__embed_copy_face_polygons(fcm_ctx *ctx, const fcm_cell_rules *Q, fcm_index c,
                                         int **meta, double **x, int *nfp);

#endif /* FCM_EMBED_RULES_IMPL_H */
