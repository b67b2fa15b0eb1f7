/* fcm embed, internal part: the rule-storage struct and the per-background-cell
 * kernels (cell setup, clipping into tets, rule mapping, surface clipping). */
#ifndef FCM_EMBED_IMPL_H
#define FCM_EMBED_IMPL_H

#include "core/core_impl.h"
#include "fcm/embed.h"
#include "fcm/quad.h"
#include "geom/geom_impl.h"
#include "la/mat3.h"

#include <math.h>

/* A cut triangle prepared for splitting: its plane (unit normal) and the three
 * planes through its edges perpendicular to it (outward: the triangle is where all three
 * are <= 0); lo/hi its bounding box; `cut` the cut surface it came from. */
typedef struct fcm__cut_tri {
  double x[3][3];
  fcm__plane plane;
  fcm__plane edge[3];
  double lo[3], hi[3];
  int cut;
  /* edge k (x[k] -> x[k+1]) is shared with a coplanar triangle of the same cut: the two
   * cover the plane on both sides of it, so it splits nothing and bounds nothing */
  unsigned char inner[3];
  /* edge k's plane is a wall shared with the edge's other triangle, and a part lying flat on
   * it (within the tolerance everywhere) belongs to this triangle's column, not the other's */
  unsigned char owns[3];
} fcm__cut_tri;

struct fcm_cell_rules {
  fcm_ctx *ctx;
  fcm_index num_cells;
  fcm_element_type type;
  int strength[FCM_RULE_KIND_COUNT];
  int axis_degree[FCM_RULE_KIND_COUNT]; /* cut-cell rules' degree cap per variable (<= strength) */
  int surface_strength;
  unsigned char *cls; /* num_cells fcm_cell_class values */
  double *fraction;   /* num_cells volume fractions */
  /* Material pieces: cell c has pieces [piece_off[c], piece_off[c+1]) (uncut: one, dropped:
   * none, cut: one or, when cuts split it, more), each with its cell and volume. */
  fcm_index num_pieces;
  fcm_index *piece_off; /* num_cells + 1 */
  fcm_index *piece_cell;
  double *piece_volume;
  /* Pieces of cut cells: entries [off[p], off[p+1]) of the concatenated arrays (empty
   * otherwise). */
  fcm_index *off[FCM_RULE_KIND_COUNT];
  double *points[FCM_RULE_KIND_COUNT]; /* x 3 */
  double *weights[FCM_RULE_KIND_COUNT];
  unsigned char *flags[FCM_RULE_KIND_COUNT];
  /* Uncut cells share the catalogue rule of each kind (flags all 0). */
  fcm_rule *uncut[FCM_RULE_KIND_COUNT];
  unsigned char *uncut_flags[FCM_RULE_KIND_COUNT];
  /* Surface rules of the pieces of non-dropped cells: entries [soff[p], soff[p+1]). */
  fcm_index *soff;
  double *spoints;  /* x 3 */
  double *sweights; /* area weights */
  double *snormals; /* x 3 */
  fcm_index *stris; /* boundary triangle of each point */
  /* The cut faces of the pieces (their side of the cuts): triangles [cfoff[p], cfoff[p+1]),
   * 9 reference coordinates each (3 vertices in the cell's reference element). */
  fcm_index *cfoff;
  double *cfxi;
  /* Cutting: the options the rules were built with (fcm_cell_rules_create_cut() reuses
   * them), the cut triangles of every cut so far, and the links: pairs of pieces of
   * face-neighbouring cells that share a face of positive area not lying on a cut (only
   * around cut cells: 2 x num_links piece ids, ascending pairs, sorted). */
  fcm_cell_rules_options opts; /* cell_mask reset to NULL after the build */
  int masked;                  /* built with a cell_mask: unflagged cells have no points */
  unsigned char *own;          /* masked: copy of the cell_mask (num cells), else NULL; the
                                  assembly gives unflagged uncut cells no points either
                                  (fcm__cell_rules_owns()) */
  int num_cuts;
  fcm_index num_cut_tris;
  fcm__cut_tri *cut_tris;
  fcm_index num_links;
  fcm_index *links;
  /* reached[c]: a cut triangle's box meets cell c's (NULL without cuts). Every cell sharing a
   * node with such a cell is in the links' region, so the links between the pieces of a
   * node's support are all known when one of its cells is reached. */
  unsigned char *reached;
  /* cell_mvol[c]: a body given by its surface alone, the body's volume in cell c as the cut
   * cells' split measures it (fcm__parts' whole_mvol), kept from cut to cut; NaN where not
   * measured yet (NULL without cuts). */
  double *cell_mvol;
  /* cell_volume[c]: the volume of cell c's corner polyhedron (fcm__embed_cell's volume), kept
   * from cut to cut so that a cell whose rules a cut copies needs no set-up; NaN where no cut
   * set the cell up yet (NULL without cuts). */
  double *cell_volume;
  /* face_nfp[c] >= 0: cell c's face polygons (face_meta[c], FCM__EMBED_FMETA ints each, and
   * face_x[c]: fcm__parts' fmeta and fx) made from the cuts' triangles that reach it in one
   * pass, as a cut that does not reach it makes them again; -1: none kept (NULL without
   * cuts). */
  int *face_nfp;
  int **face_meta;
  double **face_x;
  /* piece_parent[p]: the piece of the rules this object extends that holds piece p (-1
   * for rules made by fcm_cell_rules_create()); prev_num_pieces: how many that object had.
   * piece_component[p]: the number of piece p among the connected components of its cell's
   * parts before the components without volume were dropped: a later cut numbers the
   * pieces under the earlier cuts (its parents) the same way, whatever volume they keep */
  fcm_index *piece_parent;
  fcm_index prev_num_pieces;
  int *piece_component;
  /* id: this object's number, unique in the process; parent_id: the number of the rules a cut
   * extended into it (0 for fcm_cell_rules_create()). piece_copied[p] (NULL without a parent):
   * piece p's volume and surface rules are its parent piece's, copied bits (a cell the cut
   * does not reach, or one whose pieces it leaves whole): fcm__cell_rules_piece_copied() */
  unsigned long long id, parent_id;
  unsigned char *piece_copied;
  fcm_cell_rules_stats stats;
};

/* A background cell prepared for clipping and mapping. */
typedef struct fcm__embed_cell {
  fcm_element_type type;
  const fcm_element_info *info;
  fcm_index id;
  double X[3 * FCM_ELEMENT_MAX_NODES]; /* nodal coordinates */
  fcm__plane planes[FCM_ELEMENT_MAX_FACES];
  int num_planes;
  double size;         /* diagonal of the corners' bounding box */
  double tol;          /* clipping tolerance: clip_rtol * size */
  double volume;       /* |K| of the corner polyhedron */
  double lo[3], hi[3]; /* corner bounding box widened by tol */
  int affine;          /* closed-form inverse map */
  double A[9], Ainv[9], xi0[3], detA;
} fcm__embed_cell;

/* Per-thread workspace of the kernels; zero-initialize, release with
 * fcm__embed_ws_free(). */
typedef struct fcm__embed_ws {
  fcm__idbuf cand;
  double *tets; /* 12 per tet: c, a, b, e */
  double *vol;  /* signed volume per tet */
  size_t num_tets, tet_cap;
  double *spts; /* surface scratch: physical points (x 3), weights, normals (x 3), tris */
  double *sw, *snrm;
  fcm_index *stri;
  size_t num_spts, spt_cap;
  fcm__poly poly, scratch;
  struct fcm__parts *parts; /* cells reached by cuts (and their neighbours): NULL until used */
  /* the surface path: signed rule, line crossings, candidate points and their status */
  struct fcm__srule *sr, *bnd; /* the signed rule; points on the material's boundary */
  struct fcm__crossings *cr;
  double *cand_x;
  int *cand_in;
  const struct fcm__parts *cand_parts; /* non-NULL: candidates inside piece cand_piece only */
  int cand_piece;
  /* the face planes of that piece's parts, part after part: a count c, the part's tolerance,
   * 1 when the body fills the part (else 0), then c planes (n, d) */
  double *cand_pl;
  size_t cand_npl, cand_plcap;
  size_t cand_cap;
} fcm__embed_ws;

void fcm__embed_ws_free(fcm_ctx *ctx, fcm__embed_ws *ws);

/* The surface path's part of ws (surface_cells.c). */
void fcm__embed_surface_ws_free(fcm_ctx *ctx, fcm__embed_ws *ws);

/* Gather cell `id` of `mesh` with its size, tolerance and bounding box (widened by the
 * tolerance) only: what a search for the cut triangles near it reads. */
void fcm__embed_cell_box(const fcm_mesh *mesh, fcm_index id, double clip_rtol,
                         fcm__embed_cell *cell);

/* Gather cell `id` of `mesh` and compute its planes, size, tolerance, volume and map.
 * FCM_ERR_GEOMETRY when the corner polyhedron has no positive volume. */
fcm_status fcm__embed_cell_setup(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_index id, double clip_rtol,
                                 fcm__embed_cell *cell);

/* fcm__embed_cell_setup()'s first part: the cell's corners, size, tolerance, box and volume
 * (not its planes or map): what a cell whose rules are copied needs. */
fcm_status fcm__embed_cell_setup_volume(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_index id,
                                        double clip_rtol, fcm__embed_cell *cell);

/* Counters of the per-cell kernels (summed over cells into the statistics). */
typedef struct fcm__embed_counts {
  fcm_index candidates;        /* (background cell, embedded cell) pairs from the tree */
  fcm_index parts;             /* non-empty clipped polyhedra (convex parts) */
  fcm_index tets;              /* tets kept */
  fcm_index slivers;           /* tets dropped as slivers */
  fcm_index surface_triangles; /* clipped boundary triangles kept */
  double sliver_volume;        /* summed volume of the dropped slivers */
  double moved_volume;         /* volume the rescaled rules of non-convex parts move */
  fcm_index degenerate;        /* cells whose cut splitting changed the parts' volume */
  double split_change;         /* the largest such change, relative to its cell's volume */
  fcm_index surface_cells;     /* cut cells fitted on surface moments */
  fcm_index surface_fallbacks; /* of those, cells whose fit failed (volume path instead) */
  fcm_index kept;              /* cells a cut reaches whose pieces it leaves unchanged */
} fcm__embed_counts;

/* Add one cell's fcm__embed_append_tets() results (tets kept, slivers dropped and their volume,
 * volume moved) to counts (may be NULL). */
static inline void fcm__embed_counts_add_tets(fcm__embed_counts *counts, size_t tets,
                                              fcm_index slivers, double lost, double moved)
{
  if (!counts) return;
  counts->tets += (fcm_index)tets;
  counts->slivers += slivers;
  counts->sliver_volume += lost;
  counts->moved_volume += moved;
}

/* ---------------------------------------------------------------- distributed classification */

/* A rules build whose classification is shared among processes (the PETSc adapter, with a
 * cell_mask): this process intersects only the cells NOT flagged in `remote`; the class, volume
 * fraction and embedded volume of the flagged ones are classified by another process and
 * handed over by `exchange`, so no cell is intersected twice. The rules of the cells this
 * process does intersect are those of fcm_cell_rules_create() bit for bit (the per-cell work
 * reads nothing of other cells), and so are the class, fraction and pieces of every cell when
 * the exchange hands over the other processes' results unchanged.
 *
 * `exchange` is called exactly once per build (collectively, so it may communicate), with this
 * process's status so far. On FCM_OK, cls / fraction / volume (num cells each) hold the results
 * of this process's cells (those of the remote cells undefined) and `counts` this process's
 * counters: it fills in the remote cells' entries and may sum the counters over the processes
 * (the statistics then describe the whole build). On a failure the arrays are NULL and it only
 * lets the other processes know. It returns the status every process agrees on (FCM_OK only when
 * every process is fine), with the message set. */
typedef struct fcm__rules_exchange {
  const unsigned char *remote; /* num cells; 1: classified by another process */
  fcm_status (*exchange)(void *user, fcm_status st, unsigned char *cls, double *fraction,
                         double *volume, fcm__embed_counts *counts);
  void *user;
} fcm__rules_exchange;

/* Clip every candidate embedded cell E by the planes of `cell` and tetrahedralize the
 * pieces into ws->tets / ws->vol. Both tolerances follow the smaller of the two scales,
 * so that geometry much thinner than the background cell keeps its volume: a vertex is
 * on a plane within min(cell->tol, clip_rtol * t_E), t_E = 6 |E| / diam(E)^2 being E's
 * thickness, and tets with volume <= sliver_rtol * min(|K|, |E|) are dropped (counted,
 * with their volume). *volume = sum of the kept tets' volumes. */
fcm_status fcm__embed_cell_tets(fcm_ctx *ctx, const fcm_geometry *geom, const fcm_aabb_tree *tree,
                                const fcm__embed_cell *cell, double clip_rtol, double sliver_rtol,
                                fcm__embed_ws *ws, fcm__embed_counts *counts, double *volume);

/* Clip embedded cell e by the planes of `cell` into ws->poly (empty: nf == 0); *tol and
 * *vmin are the vertex-on-plane tolerance and the sliver volume for it (see above). */
fcm_status fcm__embed_clip_cell(fcm_ctx *ctx, const fcm_geometry *geom, const fcm__embed_cell *cell,
                                fcm_index e, double clip_rtol, double sliver_rtol,
                                fcm__embed_ws *ws, double *tol, double *vmin);

/* Fan-tetrahedralize p and append the tets with volume > vmin to ws->tets / ws->vol; the
 * kept volume is added to *vsum, dropped slivers to *lost and *nslivers, and the volume that
 * rescaling a slightly non-convex part's tets moves to *moved. */
fcm_status fcm__embed_append_tets(fcm_ctx *ctx, fcm__embed_ws *ws, const fcm__poly *p, double vmin,
                                  double *vsum, double *lost, double *moved, fcm_index *nslivers);

/* Reference coordinates xi and det J_K(xi) of the physical point x. */
fcm_status fcm__embed_to_reference(fcm_ctx *ctx, const fcm__embed_cell *cell, const double x[3],
                                   double xi[3], double *det);

/* fcm__embed_to_reference() of an affine cell, the same bits, inline (the moment rules map
 * every point of their fan tets). */
static inline void fcm__embed_to_reference_affine(const fcm__embed_cell *cell, const double x[3],
                                                  double xi[3])
{
  const double r[3] = {x[0] - cell->X[0], x[1] - cell->X[1], x[2] - cell->X[2]};
  double s[3];
  fcm__mat3_mulv(cell->Ainv, r, s);
  for (int d = 0; d < 3; d++)
    xi[d] = cell->xi0[d] + s[d];
}

/* Map the tet rule `rule` onto every tet of ws and into the reference cell: writes
 * ws->num_tets * rule points to pts (x 3) and reference weights to w. */
fcm_status fcm__embed_map_tets(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__embed_ws *ws,
                               const fcm_rule *rule, double *pts, double *w);

/* Clip the candidate boundary triangles by the planes of `cell` (a triangle flat on a
 * cell plane is kept only when its outward normal agrees with the plane's) and map the
 * triangle rule onto the fan triangles: physical points, area weights, unit normals and
 * triangle ids into ws->spts, ws->sw, ws->snrm, ws->stri (ws->num_spts of them).
 * With parts P (NULL: the whole cell), only the share of `piece`: each clipped polygon is
 * clipped further by every part of the piece (fcm__embed_clip_to_part), so a boundary
 * triangle that a cut crosses is split exactly between the pieces on its two sides.
 * counts->surface_triangles += clipped triangles kept (per piece when P is given). */
fcm_status fcm__embed_cell_surface(fcm_ctx *ctx, const fcm_geometry *geom,
                                   const fcm_aabb_tree *tri_tree, const fcm__embed_cell *cell,
                                   const struct fcm__parts *P, int piece, double sliver_rtol,
                                   const fcm_rule *tri_rule, fcm__embed_ws *ws,
                                   fcm__embed_counts *counts);

/* A selection of embedded-boundary points: nonzero when the point x (physical, reference
 * configuration) with unit outward normal n belongs to it. */
typedef int (*fcm__embed_select_fn)(void *user, const double x[3], const double n[3]);

/* The area of the embedded boundary that select() takes (decided at each surface point): in
 * the cells `rules` keeps (their surface weights) and in the cells it dropped (their part of
 * the boundary clipped and integrated as a kept cell's would be; only those cells are
 * clipped). Both 0 when the rules carry no surface rules; a masked build counts its own cells.
 * `mesh` and `geom` are the rules'. Allocates scratch (accessors.c). */
fcm_status fcm__embed_selected_area(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                    const fcm_cell_rules *rules, fcm__embed_select_fn select,
                                    void *user, double *kept, double *dropped);

/* ---------------------------------------------------------------- cutting (pieces.c) */

/* The cuts' tolerance, relative to the cell size: a part vertex this close to a cut triangle's
 * plane lies on it (the splitting and the connectivity tests share it). */
#define FCM__EMBED_MATCH_RTOL 1e-9

/* The cut triangles that can reach `cell`: those whose boxes meet the cell's box widened by
 * twice the cuts' tolerance (a triangle that far outside the corners' box still takes part
 * in the tests of the cell's parts), into buf (ascending). */
fcm_status fcm__embed_cut_candidates(fcm_ctx *ctx, const fcm_aabb_tree *cut_tree,
                                     const fcm__embed_cell *cell, fcm__idbuf *buf);

/* A wall that the two triangles of an edge share (fcm__embed_cut_inner_edges()): its unit
 * normal, pointing out of the triangle that owns this edge slot (the other's is its negation,
 * bit for bit), and the edge's vertex it passes through: 1 the edge's start (x[k]), 2 its end
 * (x[k + 1]), 0 no shared wall (the triangle's own edge plane); owns: 1 in exactly one of the
 * two triangles' slots, whose column takes a part lying flat on the wall (that the tolerance
 * cannot place on either side: left to both, it would join the two sides of the surface). */
typedef struct fcm__cut_wall {
  double n[3];
  unsigned char through, owns;
} fcm__cut_wall;

/* Prepare triangle (a, b, c), with the plane of the triangle ref (9 doubles; NULL: its
 * own) oriented as its own, and the edge planes of walls (3, one per edge; NULL: all its own,
 * through the edge perpendicular to the triangle); 0 when it has no area (relative 1e-14 of its
 * longest edge squared): such a triangle separates nothing and is skipped. */
int fcm__embed_cut_tri_setup(const double a[3], const double b[3], const double c[3], int cut,
                             const unsigned char inner[3], const double *ref,
                             const fcm__cut_wall *walls, fcm__cut_tri *t);

/* For each edge of the cut surface's triangles (3 per triangle, edge k from vertex k to
 * k + 1), whether exactly one other triangle shares it and lies in the same plane (the
 * smaller triangle's far vertex within 1e-12 of the longest edge from the larger one's
 * plane) on the other side of the edge. ref[t]: the largest triangle of t's coplanar patch
 * (triangles joined through such edges); all of a patch take its plane, so that they
 * classify every point alike (a sliver's own normal can be off by far more than the
 * tolerances). walls (3 per triangle): an edge that exactly two triangles share, not inner,
 * whose consistently oriented normals lie within 60 degrees of each other, gets one wall for
 * both, through the edge along the mean of their normals: the two triangles' columns then meet
 * on that wall (with each its own perpendicular edge plane, the columns of two nearly
 * coplanar triangles overlap on one side of the surface and leave a gap on the other, thin
 * wedges that the tolerances cannot resolve and that split a cell's parts many times over). */
fcm_status fcm__embed_cut_inner_edges(fcm_ctx *ctx, const fcm_surface *cut, unsigned char *inner,
                                      fcm_index *ref, fcm__cut_wall *walls);

/* The ints per face polygon in fcm__parts' and cell_out's fmeta. */
#define FCM__EMBED_FMETA 5

/* Convex parts of the embedded geometry inside one background cell and the material piece
 * of each: the clipped embedded cells, split by the cut triangles that reach the cell. */
typedef struct fcm__parts {
  fcm__poly *poly;
  double *tol, *vmin; /* per part: clip tolerance and sliver volume of its embedded cell */
  int *piece;         /* per part: material piece, 0 .. num_pieces-1 (fcm__embed_pieces) */
  int *parent;        /* per part: its piece under the triangles before first_new only */
  int num_parents;
  size_t n, cap;
  int num_pieces;
  fcm__poly w[3], scratch; /* splitting workspace */
  fcm__idbuf tcand;        /* cut triangles reaching the cell, ascending */
  /* Polygons of part faces lying on the cell's faces (fcm__embed_face_polygons): polygon i
   * is on cell face fmeta[F i], belongs to piece fmeta[F i+1], has fmeta[F i+2] vertices and
   * its part fmeta[F i+3], stored consecutively in fx (x 3), the polygon's then its part's;
   * fmeta[F i+4] is 1 where the body fills the part (F = FCM__EMBED_FMETA). */
  double *fx;
  int *fmeta;
  size_t nfx, capfx, nfp, capfp;
  int *uf;            /* union-find scratch, n entries */
  double split_error; /* |parts' volume after the new cut's splits - before| (the splits by
                         the triangles from first_new on, fcm__embed_cell_pieces) */
  size_t ufcap;
  /* A geometry without a volume mesh (surface_parts.c): the parts are the cell split by the
   * cuts, mvol[i] the body's volume inside part i (parts without are dropped), and parts join
   * only through faces whose overlap holds material. NULL: the parts are embedded cells. */
  struct fcm__material *mat;
  double *mvol;
  int whole; /* with mat: the one part is the cell itself, unsplit */
} fcm__parts;

void fcm__embed_parts_free(fcm_ctx *ctx, fcm__parts *P);

/* Clip every candidate embedded cell by the cell's planes (as fcm__embed_cell_tets) and keep
 * the non-empty convex parts in P (P->n of them, every piece 0). counts->parts is added.
 * whole_mvol (NULL: none): with a geometry without a volume mesh, the body's volume in the whole
 * cell, in and out (fcm__embed_drop_dry()). */
fcm_status fcm__embed_cell_parts(fcm_ctx *ctx, const fcm_geometry *geom, const fcm_aabb_tree *tree,
                                 const fcm__embed_cell *cell, double clip_rtol, double sliver_rtol,
                                 fcm__embed_ws *ws, fcm__parts *P, double *whole_mvol,
                                 fcm__embed_counts *counts);

/* Split the parts by the planes and edge planes of the cut triangles tris[P->tcand] that
 * reach them, then group them into material pieces: two parts connect when they share a
 * face of positive area that does not lie on a cut triangle; the connected components,
 * numbered by their first part, are the pieces (P->piece, P->num_pieces). The triangles are
 * taken in ascending order, one cut's after the other's (a surface body's dry parts dropped
 * and lumps split after each cut), so the parts and pieces do not depend on first_new; those
 * below first_new are the earlier cuts: the pieces under
 * them alone (what the rules being extended had) are P->parent / P->num_parents, one piece
 * when none of them reaches the cell. P->split_error: how much the new cut's splits (the
 * triangles from first_new on) changed the parts' total volume (rounding only, unless the cut
 * meets the parts in a degenerate way the tolerances cannot resolve; the earlier cuts' splits
 * change it as they did when they were made, which shifting the new cut cannot change). */
fcm_status fcm__embed_cell_pieces(fcm_ctx *ctx, const fcm__embed_cell *cell,
                                  const fcm__cut_tri *tris, fcm_index first_new, fcm__parts *P);

/* Fan-tetrahedralize the parts i with label[i] == piece (label: P->piece or P->parent)
 * into ws->tets / ws->vol (slivers dropped and counted as in fcm__embed_cell_tets);
 * *volume = the kept tets' volume. */
fcm_status fcm__embed_piece_tets(fcm_ctx *ctx, const fcm__parts *P, const int *label, int piece,
                                 fcm__embed_ws *ws, fcm__embed_counts *counts, double *volume);

/* Clip the polygon x (n vertices, capacity cap, work: cap x 3 doubles) lying on the
 * embedded boundary (outward unit normal nrm) to part i of P: by each of the part's face
 * planes, a polygon flat on a face kept when the face's outward normal agrees with nrm.
 * Returns the new vertex count (< 3: nothing of it on the part), -1 on overflow. */
int fcm__embed_clip_to_part(const fcm__parts *P, size_t i, double *x, int n, int cap,
                            const double nrm[3], double *work);

/* fcm__embed_clip_to_part with the polygon's own face found with a tolerance: a face on whose
 * plane every vertex lies within flat_tol keeps the polygon whole (when their normals agree;
 * else nothing is left) instead of classifying its vertices with the part's clipping
 * tolerance, which rounding in the polygon's vertices can exceed (flat_tol < 0: no such face,
 * as fcm__embed_clip_to_part). */
int fcm__embed_clip_to_part_flat(const fcm__parts *P, size_t i, double *x, int n, int cap,
                                 const double nrm[3], double flat_tol, double *work);

/* How far x lies outside part i of P: the largest signed distance to the planes of its faces
 * with area (<= 0 inside). */
double fcm__embed_part_excess(const fcm__parts *P, size_t i, const double x[3]);

/* fcm__embed_clip_to_part() and fcm__embed_part_excess() on the part's planes pl (np of them,
 * from fcm__embed_part_planes(); tol: the part's clipping tolerance), the same results, for
 * many polygons or points against one part. */
int fcm__embed_clip_to_planes(const fcm__plane *pl, int np, double tol, double *x, int n, int cap,
                              const double nrm[3], double *work);
double fcm__embed_planes_excess(const fcm__plane *pl, int np, const double x[3]);

/* ---------------------------------------------------------------- pieces of output points
 * (piece_locate.c) Where points and triangles of the embedded geometry's boundary lie among
 * the material pieces of cut-cell rules, for output of the embedded surface: the convex parts
 * and pieces of a cell are made again exactly as the build of the rules made them (the same
 * parts, splits by the cut triangles and components, mapped to the rules' pieces through
 * their component numbers), so what a piece's material holds goes to that piece. */
typedef struct fcm__embed_finder fcm__embed_finder;

/* Polygons with the rules' piece of each (-1: no piece holds it: a dropped cell or piece):
 * polygon k has nv[k] vertices, stored consecutively in x (x 3). */
typedef struct fcm__embed_polys {
  double *x;
  int *nv;
  fcm_index *piece;
  size_t n, cap, nx, capx;
} fcm__embed_polys;

void fcm__embed_polys_free(fcm_ctx *ctx, fcm__embed_polys *p);

/* Append polygon x (n vertices, 3 n doubles) of `piece` to out, its arrays doubled as they
 * fill. */
fcm_status fcm__embed_polys_push(fcm_ctx *ctx, fcm__embed_polys *out, const double *x, int n,
                                 fcm_index piece);

/* A finder for the geometry `geom` embedded in `mesh` (both borrowed; the search tree of the
 * geometry's cells is built here, once). */
fcm_status fcm__embed_finder_create(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                    fcm__embed_finder **out);
void fcm__embed_finder_destroy(fcm__embed_finder **f);

/* Answer for rules R (borrowed until the next call; built on the finder's mesh and geometry):
 * the search tree of R's cut triangles. FCM_ERR_ARG when R is on another mesh. */
fcm_status fcm__embed_finder_set_rules(fcm__embed_finder *f, const fcm_cell_rules *R);

/* Whether triangle x (3 vertices x 3) may cross or touch a cut: the plane of a cut triangle
 * has vertices of it strictly on both sides and no outer edge plane of that cut triangle has
 * them all strictly outside, or a vertex lies on the cut triangle within twice the cuts'
 * tolerance of a cell of the mesh's mean size (conservative: a triangle that passes beside a
 * cut's edge may count, one that a cut crosses always does). 0 without cuts. */
fcm_status fcm__embed_finder_crosses(fcm__embed_finder *f, const double x[9], int *crosses);

/* Whether point x lies within w of a cut triangle of R: within w of its plane and inside its
 * three edge planes pushed out by w (0 without cuts). A point that parts of two pieces hold
 * (fcm__embed_finder_point() gives -2) mostly lies on a cut triangle within the cuts'
 * tolerance, but not always (two pieces of one cell may touch away from the cuts): a caller
 * must not rely on it. */
fcm_status fcm__embed_finder_near_cut(fcm__embed_finder *f, const double x[3], double w, int *near);

/* Free what the finder holds for its rules (the cut triangles' tree, the current cell's parts
 * and the work space), keeping what it holds for its mesh and geometry; set rules again
 * before the next question. NULL: nothing. */
void fcm__embed_finder_release(fcm__embed_finder *f);

/* The piece of R that holds point x of cell c, x on the boundary of the material: the piece of
 * every part containing x within the cuts' tolerance (FCM__EMBED_MATCH_RTOL of the cell size).
 * *piece = -1 when no part of a piece does, -2 when parts of several pieces do (x on a cut). */
fcm_status fcm__embed_finder_point(fcm__embed_finder *f, fcm_index c, const double x[3],
                                   fcm_index *piece);

/* The share of the boundary triangle x (3 vertices x 3, counter-clockwise seen from outside)
 * inside cell c, split between R's pieces in c: clipped by the cell's planes as the surface
 * rules are (fcm__embed_cell_surface), then, in a cell with several pieces, to every part
 * (fcm__embed_clip_to_part), each polygon going to its part's piece. Polygons of no more than
 * 1e-12 of the cell size squared are left out. Appended to *out. */
fcm_status fcm__embed_finder_clip(fcm__embed_finder *f, fcm_index c, const double x[9],
                                  fcm__embed_polys *out);

/* Triangles, 9 doubles each (3 vertices), grown as they are appended. */
typedef struct fcm__tribuf {
  double *t;
  int n, cap;
} fcm__tribuf;

/* Append the fan of the polygon x (m vertices) to b, with x's orientation. */
fcm_status fcm__embed_tris_fan(fcm_ctx *ctx, fcm__tribuf *b, const double *x, int m);

/* The faces of `piece`'s parts that lie on a cut triangle (the piece's side of the cuts),
 * fan-triangulated with their outward orientation: *tri (allocated, 9 doubles = 3 physical
 * vertices per triangle; NULL when none) and *ntri. On a body given by its surface (P->mat),
 * the part of each such face inside the body (fcm__material_face_inside()) where the body does
 * not fill the part: a cut face does not reach beyond the body. */
fcm_status fcm__embed_cut_faces(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *tris,
                                const fcm__parts *P, int piece, double **tri, int *ntri);

/* Record the polygons of part faces lying on the cell's faces (P->fx, P->fmeta). */
fcm_status fcm__embed_face_polygons(fcm_ctx *ctx, const fcm__embed_cell *cell, fcm__parts *P);

/* The plane face f of p lies on (the one it carries) into pl; 0 when the face has no area. */
int fcm__embed_face_plane(const fcm__poly *p, int f, fcm__plane *pl);

/* Gather face f of p into x (fn x 3); its vertex count. */
int fcm__embed_face_coords(const fcm__poly *p, int f, double *x);

/* Area of the part of polygon a (na vertices) inside the convex polygon b (nb vertices,
 * counter-clockwise around its unit normal nb_normal), both on one plane; `tol` is the
 * on-edge tolerance. overlap (may be NULL; room for 3 x FCM__POLY_MAX_VERTS) gets that part,
 * *num_overlap (may be NULL) its vertex count (0 when empty). */
double fcm__embed_overlap(const double *a, int na, const double *b, int nb,
                          const double nb_normal[3], double tol, double *overlap, int *num_overlap);

/* Whether two faces on one plane join their convex parts (vertices va, nva and vb, nvb): face
 * a (na vertices) and the convex face b (nb vertices, counter-clockwise around nb_normal)
 * overlap by more than `atol` in area, in a polygon wider than 4 tol (2 area / perimeter: a
 * sliver face's band of tolerance can reach across a cut), and unless the overlap lies on the
 * cuts tris[ids[0 .. n)] (fcm__embed_on_cut(), twice the tolerance `tol`), in which case the
 * parts join only when they do not lie on opposite sides of the cut triangle under the
 * overlap's centroid (a part within tol of the plane, or crossing it, lies on no side).
 * Deciding by the parts' sides rather than by where each cell placed the cut: the crossing of
 * a plane almost parallel to a face is ill-conditioned, so two cells can place it a little
 * apart on their shared face, and the pieces on the two sides of the cut then overlap in a
 * strip along it, which must not join them; a sliver cut off between the face and the cut
 * joins the material on its own side. */
int fcm__embed_linked(const double *a, int na, const double *va, int nva, const double *b, int nb,
                      const double *vb, int nvb, const double nb_normal[3], double tol, double atol,
                      const fcm__cut_tri *tris, const fcm_index *ids, size_t n);

/* 1 when the polygon x (m vertices; m = 1: a point) lies on the cuts tris[ids[0 .. n)]:
 * every vertex and the vertex centroid lie on one of the triangles within `tol`. A face
 * that the splitting (same tolerance) put on a cut passes; a face with one vertex off the
 * cuts does not, however thin it is. */
int fcm__embed_on_cut(const fcm__cut_tri *tris, const fcm_index *ids, size_t n, const double *x,
                      int m, double tol);

/* FCM_ERR_GEOMETRY when every triangle of the cut surface has no area (as
 * fcm__embed_cut_tri_setup() judges it): such a cut separates nothing. The message starts
 * with `what` and gives the count and the first triangle's vertices. No allocation. */
fcm_status fcm__embed_cut_check(fcm_ctx *ctx, const fcm_surface *cut, const char *what);

/* The embedding diagnostics of the statistics S (geometry, embedded and sliver volumes
 * already set): bounding boxes, volume ratio, the volume outside the mesh and beyond each
 * face of its bounding box. FCM_ERR_GEOMETRY, with both bounding boxes, when a geometry of
 * positive volume has none inside the mesh; FCM_ERR_ALLOC. Single-threaded. */
fcm_status fcm__embed_outside(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                              fcm_cell_rules_stats *S);

/* The volume of geom beyond each side of the box [mlo, mhi] (sides -x, +x, -y, +y, -z, +z),
 * summed over the geometry's cells in order (the clipped part of a straddling cell). */
fcm_status fcm__embed_outside_sides(fcm_ctx *ctx, const double mlo[3], const double mhi[3],
                                    const fcm_geometry *geom, double side[6]);

/* The part of geom a rules build on mesh needs when it classifies (intersects) the cells
 * flagged in `classify` and builds surface rules on those flagged in `surface` (NULL: none;
 * ignored when opts->surface_strength < 0): the geometry cells, and boundary triangles, whose
 * boxes meet the box the kernels query for such a cell (its corners' box widened by the
 * clipping tolerance, fcm__embed_cell_setup()), found with the same trees, so every candidate
 * of those cells is kept (fcm__geom_create_subset(): original order, original ids in
 * cell_orig / tri_orig, the whole geometry's volume and bounding box). The whole geometry's
 * outside volumes per side of the mesh box are stored for fcm__embed_outside(). A rules
 * build with the crop gives those cells the classes, fractions and rules of a build with
 * geom bit for bit (candidates are taken in ascending id order; the surface points carry the
 * original triangle ids). The options are checked as the rules build checks them (with a
 * reduce), and every flagged cell for convexity, with the build's messages. */
FCM_COMPONENT_API fcm_status fcm__embed_crop_geometry(fcm_ctx *ctx, const fcm_mesh *mesh,
                                                      const fcm_geometry *geom,
                                                      const fcm_cell_rules_options *opts,
                                                      const unsigned char *classify,
                                                      const unsigned char *surface,
                                                      fcm_geometry **out);

/* fcm_cell_rules_create_cut() with keep = 1; keep = 0 integrates again every cell the new cut
 * reaches, whether it changes its pieces or not, and makes the face polygons of every cell
 * near the cuts for the links (none taken from prev): the reference its shortcuts are
 * tested against. */
fcm_status fcm__cell_rules_create_cut_keep(fcm_ctx *ctx, const fcm_mesh *mesh,
                                           const fcm_geometry *geom, const fcm_cell_rules *prev,
                                           const fcm_surface *cut, int keep,
                                           fcm_cell_rules **rules);

/* 0 when the rules were built with a cell_mask that does not flag `cell` (the cell belongs to
 * another process: no points, uncut or not); 1 otherwise. */
static inline int fcm__cell_rules_owns(const fcm_cell_rules *R, fcm_index cell)
{
  return !R || !R->own || R->own[cell];
}

/* 1 when piece p of R holds the bits of the volume and surface rules (points, weights, flags of
 * every kind and the surface points, weights, normals) of its parent piece in `from`, the rules
 * R extends: R copied them (its cut faces may be new); 0 when not known. */
static inline int fcm__cell_rules_piece_copied(const fcm_cell_rules *R, fcm_index p,
                                               const fcm_cell_rules *from)
{
  return R && from && R->piece_copied && R->parent_id == from->id && R->piece_copied[p];
}

/* A sum over the processes of a distributed run (the PETSc backend's reduce): agree on st
 * (on a failure anywhere every process returns it), then sum values[0 .. count) in place, the
 * same bits on every process. Collective. */
typedef struct fcm__rules_reduce {
  fcm_status (*fn)(void *user, fcm_status st, double *values, fcm_index count);
  void *user;
  int called; /* set once fn was called (every process calls it exactly once) */
} fcm__rules_reduce;

/* fcm_cell_rules_create() for a distributed run with a cell_mask and simplify = AUTO: the
 * choice's inputs (each kind's cut-cell point counts and the modelled simplification time,
 * which the mask limits to this process's cells) are summed through red->fn, so every
 * process takes the choice the unmasked (serial) build takes. red->fn is called exactly once
 * by every process when simplify is AUTO, with the status reached so far (also on a failure
 * before the choice, so no process waits for another). red NULL: fcm_cell_rules_create().
 * Collective when red is given and simplify is AUTO. */
fcm_status fcm__cell_rules_create_reduced(fcm_ctx *ctx, const fcm_mesh *mesh,
                                          const fcm_geometry *geom,
                                          const fcm_cell_rules_options *opts,
                                          fcm__rules_reduce *red, fcm_cell_rules **rules);

/* fcm__cell_rules_create_reduced() with the classification of the cells flagged in x->remote
 * taken from x->exchange (fcm__rules_exchange above; x NULL: fcm__cell_rules_create_reduced()).
 * The exchange runs before the AUTO choice's reduce; on a failure before either, both are
 * still called, in that order. simplify = AUTO needs red. The statistics' counters are this
 * process's unless the exchange sums them; time_intersect covers this process's cells.
 * Collective. */
FCM_COMPONENT_API fcm_status fcm__cell_rules_create_distributed(fcm_ctx *ctx, const fcm_mesh *mesh,
                                                                const fcm_geometry *geom,
                                                                const fcm_cell_rules_options *opts,
                                                                fcm__rules_reduce *red,
                                                                const fcm__rules_exchange *x,
                                                                fcm_cell_rules **rules);

/* ---------------------------------------------------------------- coarse classification */

/* Classify the cells of `mesh` against geom's closed boundary cheaply, without clipping or rules
 * (classify_coarse.c): cls[c] (num cells) FCM_CELL_CUT when a boundary triangle meets the
 * bounding box of the cell's nodes (conservative: such a cell may still hold no material, and
 * the rules build may drop a cut cell below min_fraction), else FCM_CELL_UNCUT (wholly inside the
 * body) or FCM_CELL_DROPPED (wholly outside). counts (may be NULL): the cells of each class, by
 * fcm_cell_class. Errors: FCM_ERR_ARG (NULL), FCM_ERR_ALLOC. Single-threaded. */
fcm_status fcm__embed_classify_coarse(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                      unsigned char *cls, fcm_index counts[3]);

/* ---------------------------------------------------------------- surface moments */

/* The Gauss rules on [0, 1] exact for degrees m, m + 1 and m + 2 and the triangle rule exact
 * for degree m + 1 that the surface moments of degree m use. */
typedef struct fcm__moment_quad {
  int m;
  int ng[3];
  double *gt[3], *ga[3];
  int nt;
  double *tx, *tw; /* (u, v) on the unit triangle, weights summing to 1/2 */
} fcm__moment_quad;

fcm_status fcm__moment_quad_create(fcm_ctx *ctx, int m, fcm__moment_quad *q);
void fcm__moment_quad_free(fcm_ctx *ctx, fcm__moment_quad *q);

/* A signed rule: points (x 3, reference coordinates) with weights of both signs. */
typedef struct fcm__srule {
  double *x, *w;
  size_t n, cap;
} fcm__srule;

/* Room in s for `more` points beyond its n (capacity doubled from 1024). */
fcm_status fcm__srule_room(fcm_ctx *ctx, fcm__srule *s, size_t more);

void fcm__srule_free(fcm_ctx *ctx, fcm__srule *s);

/* Boxes (physical) that no boundary triangle comes within `pad` of, and the body's winding
 * number about them (1 inside): fcm__embed_inside_line() answers a point in one without a line
 * query of its own. */
enum { FCM__CLEAR_BOXES = 8 };
typedef struct fcm__clear_box {
  double lo[3], hi[3], pad;
  int winding;
} fcm__clear_box;

/* Crossings of a line with the boundary: xi_3 values and signs (+1 leaving the body); and the
 * clear boxes the inside tests with this scratch found lately, for boundary triangles `tree`
 * (zeroed: none). */
typedef struct fcm__crossings {
  double *z;
  int *sign;
  size_t n, cap;
  const fcm_aabb_tree *tree;
  fcm__clear_box clear[FCM__CLEAR_BOXES];
  int nclear, next;
  int tries, found, skipped; /* the recent looks for a clear box, those that found one */
  /* fcm__embed_inside_column()'s cell (col_key: its id, first corner and det A): col_face 1
   * (-1) when no boundary triangle comes near its top (bottom) face, the winding number there
   * col_winding; 0: neither; col_n triangles that may meet it, in its reference coordinates
   * (col_x, 9 each) with their vertex ids (col_v, 3 each) */
  double col_key[5];
  const fcm_aabb_tree *col_tree;
  int col_face, col_winding;
  size_t col_n, col_cap;
  double *col_x;
  fcm_index *col_v;
} fcm__crossings;

void fcm__crossings_free(fcm_ctx *ctx, fcm__crossings *c);

/* *touched: some boundary triangle of g (tree: their boxes) has a part inside the affine
 * `cell`; then box (lo[3], hi[3], reference coordinates) bounds the material in the cell: those
 * parts and the cell corners inside the body (else it is empty, lo > hi). bnd (NULL: not
 * wanted): the vertices and centroids of those parts, points on the material's boundary. */
fcm_status fcm__embed_material_box(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                   const fcm__embed_cell *cell, fcm__idbuf *buf, fcm__crossings *cr,
                                   fcm__srule *bnd, double box[6], int *touched);

/* The signed rule s (reference coordinates of `cell`, which must be affine) that integrates
 * every polynomial of degree <= q->m exactly over the part of the cell inside the body bounded
 * by g's boundary triangles (closed, counter-clockwise seen from outside; tree: their boxes),
 * from the triangles that meet the cell (surface_moments.c explains how). base (NULL: the
 * cell's lower bounds): where the antiderivative in each direction starts, valid when the
 * material lies at or above it (the lower corner of its box: the rule's points then stay in
 * the box). FCM_ERR_GEOMETRY when a line through the cell shows the surface is not closed (on
 * a tree other than the geometry's own, fcm__geom_tree(): on that one a line's shorter half is
 * taken, the geometry closed where it was made). buf and cr are scratch. */
fcm_status fcm__embed_moment_rule(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                  const fcm__embed_cell *cell, const fcm__moment_quad *q,
                                  const double base[3], fcm__idbuf *buf, fcm__crossings *cr,
                                  fcm__srule *s);

/* fcm__embed_moment_rule(), the same bits, for a cell that fcm__embed_cell_clear() found not
 * clear, with buf as it left it (the triangles near the cell: those that meet it are taken
 * from them); the winding number about the cell's corner is taken from a clear box kept in cr
 * (fcm__embed_inside_line()) where one holds it: then only the crossings inside the cell's
 * edge are looked for. Else a clear box around the corner is kept when there is one. */
fcm_status fcm__embed_moment_rule_kept(fcm_ctx *ctx, const fcm_geometry *g,
                                       const fcm_aabb_tree *tree, const fcm__embed_cell *cell,
                                       const fcm__moment_quad *q, const double base[3],
                                       fcm__idbuf *buf, fcm__crossings *cr, fcm__srule *s);

/* *clear: no boundary triangle's box comes within the rounding distance of the line queries
 * (fcm__embed_moment_rule()) of the affine cell's box: the cell lies wholly inside or wholly
 * outside the body, far enough from its boundary that every line through it decides alike.
 * buf is scratch. */
fcm_status fcm__embed_cell_clear(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                 const fcm__embed_cell *cell, fcm__idbuf *buf, int *clear);

/* fcm__embed_moment_rule() of a clear cell (fcm__embed_cell_clear()), the same bits, without
 * its line query where *winding is known: the body's winding number about the cell (1 inside,
 * 0 outside; FCM__WINDING_UNKNOWN: not known, then found by the line query and stored). Clear
 * cells that share a point share it. */
#define FCM__WINDING_UNKNOWN (-1000)
fcm_status fcm__embed_moment_rule_clear(fcm_ctx *ctx, const fcm_geometry *g,
                                        const fcm_aabb_tree *tree, const fcm__embed_cell *cell,
                                        const fcm__moment_quad *q, const double base[3],
                                        fcm__idbuf *buf, fcm__crossings *cr, int *winding,
                                        fcm__srule *s);

/* The winding number of the body's boundary around the points (a, b, z[i]) (reference
 * coordinates of `cell`, affine), i < n, into inside[i]: 1 inside the body, 0 outside, decided
 * consistently for points on the boundary. Same errors and scratch as above. */
fcm_status fcm__embed_inside_line(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                  const fcm__embed_cell *cell, double a, double b, int n,
                                  const double *z, int *inside, fcm__idbuf *buf,
                                  fcm__crossings *cr);

/* fcm__embed_inside_line(), the same answers, for the columns of one hexahedral cell in turn
 * (on the geometry's own tree of its boundary triangles, fcm__geom_tree(), and not a subset):
 * where no boundary triangle comes near the cell's top (or bottom) face, the winding number
 * is the same all over that face (one line query for the cell), and a column's points take it
 * with the crossings between them and the face, from the triangles that meet the cell only
 * (kept in cr for the next column). Other cells: fcm__embed_inside_line(). */
fcm_status fcm__embed_inside_column(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                    const fcm__embed_cell *cell, double a, double b, int n,
                                    const double *z, int *inside, fcm__idbuf *buf,
                                    fcm__crossings *cr);

/* ---------------------------------------------------------------- parts of a surface body
 * (surface_parts.c; its cut faces: surface_faces.c) */

/* The body of a geometry without a volume mesh (its closed boundary) and the scratch of the
 * material tests on it; one per thread. */
typedef struct fcm__material fcm__material;

fcm_status fcm__material_create(fcm_ctx *ctx, const fcm_geometry *geom, fcm__material **out);
void fcm__material_destroy(fcm_ctx *ctx, fcm__material **m);

/* The volume of the body inside the convex polyhedron p (surface moments on the tets of a fan
 * of p), a part of cell (which names the errors). With out (cell affine): also the signed
 * rule of degree q->m of that material, appended to out in cell's reference coordinates. */
fcm_status fcm__material_poly(fcm_ctx *ctx, fcm__material *m, const fcm__poly *p,
                              const fcm__moment_quad *q, const fcm__embed_cell *cell,
                              fcm__srule *out, double *volume);

/* Whether the body covers more than atol of the area of the planar convex polygon x (n
 * vertices, unit normal nrm) on a face of cell (which names the errors): its volume in the
 * prism of half-height h on the polygon, over 2 h. An error is kept in m and the answer is
 * then 1. */
int fcm__material_on_face(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                          const double *x, int n, const double nrm[3], double h, double atol);

/* The part of the planar convex polygon x (n vertices, physical) on a face of cell inside the
 * body, fanned into b with x's orientation: x is split along the lines where the boundary
 * triangles near it cross its plane, into convex polygons that no boundary crosses, and those
 * the body holds (an inside test at each one's vertex centroid; where a boundary triangle
 * lies in the plane, moved 1e-8 of the cell size into the part, x's outward normal pointing
 * out of it) are kept. Polygons of no more area than 1e-9 of the cell size squared are left
 * out. */
fcm_status fcm__material_face_inside(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                                     const double *x, int n, fcm__tribuf *b);

/* The first error fcm__material_on_face() kept (FCM_OK: none), cleared. */
fcm_status fcm__material_status(fcm__material *m);

/* Whether the overlap of the touching faces a (na vertices) and b (nb, outward normal
 * nb_normal) of two parts, on a face of cell (its size sets the tolerances), holds material
 * (fcm__material_on_face()). */
int fcm__embed_overlap_material(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                                const double *a, int na, const double *b, int nb,
                                const double nb_normal[3]);

/* fcm__embed_overlap_material() where `full` says whether the body fills one of the two parts
 * to a depth of 4 prism half-heights at least (fcm__embed_part_face_full()): then the half of
 * the prism on that part's side is material, and an
 * overlap of more than 4 times the area threshold is covered without the moments (their
 * answer, half the prism at least, is above twice the threshold). */
int fcm__embed_overlap_material_full(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                                     const double *a, int na, const double *b, int nb,
                                     const double nb_normal[3], int full);

/* Split every part of P by triangle t (its plane and edge planes, as a cut's) and drop the
 * emptied ones. */
/* Split part i of P by triangle t (as fcm__embed_parts_split does each part): its pieces in slot
 * i and appended; slot i emptied (nf == 0) when nothing is left, to be compacted. */
fcm_status fcm__embed_part_split(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *t,
                                 fcm__parts *P, size_t i);

fcm_status fcm__embed_parts_split(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *t,
                                  fcm__parts *P);

/* Drop the parts left empty (nf == 0). */
void fcm__embed_parts_compact(fcm__parts *P);

/* The parts of P in piece `piece` into Q (its parts replaced). */
fcm_status fcm__embed_parts_copy(fcm_ctx *ctx, const fcm__parts *P, int piece, fcm__parts *Q);

/* Store polyhedron q as part `slot` of P (slot == P->n appends), material not known. */
fcm_status fcm__embed_parts_put(fcm_ctx *ctx, fcm__parts *P, size_t slot, const fcm__poly *q,
                                double tol, double vmin, int parent);

/* Connected components of the parts of P when the triangles tris[P->tcand.ids[0 .. ntri)]
 * separate (and, with P->mat, faces without material): label[i] numbered by first part,
 * *count of them. */
fcm_status fcm__embed_parts_components(fcm_ctx *ctx, const fcm__embed_cell *cell,
                                       const fcm__cut_tri *tris, size_t ntri, fcm__parts *P,
                                       int *label, int *count);

/* Surface body (P->mat): every part that holds more than one separate lump of the body is
 * replaced by its pieces wholly inside the body (split by the boundary triangles), so that the
 * components of the parts are the material's. The parts wholly inside the body are left. */
fcm_status fcm__embed_split_lumps(fcm_ctx *ctx, const fcm__embed_cell *cell, fcm__parts *P);

/* Surface body (P->mat): the parts of piece `piece` split by the body's boundary triangles
 * that meet the cell into parts wholly inside or outside the body; the inside ones
 * fan-tetrahedralized into ws->tets (as fcm__embed_piece_tets), their volume *volume. The
 * volume path's start for a piece whose surface fit fails. Tets below their part's sliver volume
 * are dropped, unless every tet is (a piece that holds more than a sliver in all): then each
 * of positive volume is kept. */
fcm_status fcm__embed_piece_body_tets(fcm_ctx *ctx, const fcm__embed_cell *cell, fcm__parts *P,
                                      int piece, fcm__embed_ws *ws, double *volume);

/* Surface body (P->mat): the body's volume in each part into P->mvol where it is not known
 * (0: not computed; < 0: a piece of a part wholly inside the body, its own volume; the whole
 * cell: *whole_mvol where known (not NaN), else measured, and stored there unless whole_mvol is
 * NULL); parts with no more than their vmin are dropped. Nothing without P->mat. */
fcm_status fcm__embed_drop_dry(fcm_ctx *ctx, const fcm__embed_cell *cell, fcm__parts *P,
                               double *whole_mvol);

/* Surface body: whether part i lies wholly inside the body (its material, P->mvol, is its
 * volume up to rounding). */
int fcm__embed_part_full(const fcm__parts *P, size_t i);

/* fcm__embed_part_full() for the face-link shortcut (fcm__embed_overlap_material_full()) on a
 * face of unit normal nrm: the part is full and reaches at least 4 prism half-heights along nrm,
 * so the half of the prism on its side is material (a thinner full slab holds less). size: the
 * cell's. */
int fcm__embed_part_face_full(const fcm__parts *P, size_t i, const double nrm[3], double size);

/* fcm__embed_part_face_full() with full = fcm__embed_part_full(P, i) known (a part's faces ask
 * it once). */
int fcm__embed_part_face_deep(const fcm__parts *P, size_t i, int full, const double nrm[3],
                              double size);

/* Whether the convex polyhedron p (a part of affine cell) is a box in cell's reference
 * coordinates: 8 vertices, each at a corner of their reference bounding box lo..hi within
 * 1e-13 of the reference cell's size, every corner taken once (a part of a box cell that cuts
 * along the grid's axes split), and the box not flat (fcm__embed_box_cell()). */
fcm_status fcm__embed_part_box(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__poly *p,
                               double lo[3], double hi[3], int *is_box);

/* A tet or cell whose 6 x volume is below this fraction of its size cubed is flat: its map is
 * too ill-conditioned for line crossings (fan tets skip it, a box or prism keeps its fan). */
#define FCM__EMBED_FLAT_RTOL 1e-12

/* Whether the affine cell k (detA and size set) is not flat. */
static inline int fcm__embed_cell_solid(const fcm__embed_cell *k)
{
  return fabs(k->detA) > FCM__EMBED_FLAT_RTOL * k->size * k->size * k->size && isfinite(k->detA);
}

/* The box lo..hi of the reference coordinates of the affine cell as an affine Hex8 cell k of
 * its own: k's reference point eta is cell's c + h eta (c, h: the box's centre and half
 * sides). Returns 1, or 0 when k is flat. */
int fcm__embed_box_cell(const fcm__embed_cell *cell, const double lo[3], const double hi[3],
                        fcm__embed_cell *k);

/* The prism of half-height h along the unit normal nrm on the polygon x (n vertices) as one
 * affine Hex8 cell k (id: the cell that names the errors), when the polygon is a parallelogram
 * (4 vertices, x0 + x2 = x1 + x3 within 1e-12 of its extent) and the prism not flat: then 1;
 * else 0. */
int fcm__embed_prism_cell(const double *x, int n, const double nrm[3], double h, fcm_index id,
                          fcm__embed_cell *k);

/* The planes of the faces with area of part i of P into pl (room for FCM__POLY_MAX_FACES);
 * their count. */
int fcm__embed_part_planes(const fcm__parts *P, size_t i, fcm__plane *pl);

/* As fcm__material_poly() for the whole affine cell: the surface moments of the cell itself. */
fcm_status fcm__material_cell(fcm_ctx *ctx, fcm__material *m, const fcm__moment_quad *q,
                              const fcm__embed_cell *cell, fcm__srule *out, double *volume);

#endif /* FCM_EMBED_IMPL_H */
