/* Per-background-cell rule storage: the parallel build (intersect, classify, simplify,
 * stabilize, per cell into private buffers, then gathered in cell order), accessors,
 * statistics and the point dump. */
#include "embed/embed_impl.h"
#include "element/element_impl.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define GIB (1024.0 * 1024.0 * 1024.0)

/* Whether the options / rules ask for volume rules of kind k. */
#define KIND_BUILT(kinds, k) ((((unsigned)(kinds)) >> (unsigned)(k)) & 1u)

const char *fcm_rule_kind_name(fcm_rule_kind kind)
{
  static const char *const names[FCM_RULE_KIND_COUNT] = {"stiffness", "mass"};
  return (int)kind >= 0 && kind < FCM_RULE_KIND_COUNT ? names[kind] : "invalid";
}

fcm_cell_rules_options fcm_cell_rules_options_default(void)
{
  fcm_cell_rules_options o;
  memset(&o, 0, sizeof o);
  o.kinds = FCM_RULES_ALL;
  o.strength[FCM_RULE_STIFFNESS] = -1;
  o.strength[FCM_RULE_MASS] = -1;
  o.surface_strength = -1;
  o.min_fraction = 1e-4;
  o.uncut_fraction = 1.0 - 1e-12;
  o.clip_rtol = 1e-12;
  o.sliver_rtol = 1e-14;
  o.convex_rtol = 1e-10;
  o.simplify = FCM_CELL_SIMPLIFY_ON;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    o.expected_assemblies[k] = 1.0;
    o.point_cost[k] = FCM_DEFAULT;
  }
  o.simplify_options = fcm_simplify_options_default();
  o.stabilization = fcm_stabilization_options_default();
  o.max_rule_memory = 4.0 * GIB;
  o.progress = NULL;
  o.progress_user = NULL;
  o.progress_interval = 0.1;
  return o;
}

const char *fcm_cell_simplify_name(fcm_cell_simplify mode)
{
  static const char *const names[FCM_CELL_SIMPLIFY_COUNT] = {"off", "on", "auto"};
  return (int)mode >= 0 && mode < FCM_CELL_SIMPLIFY_COUNT ? names[mode] : "invalid";
}

int fcm_simplify_pays(double assemblies, double point_cost, double points_before,
                      double points_after, double simplify_time)
{
  if (!(isfinite(assemblies) && isfinite(point_cost) && isfinite(points_before) &&
        isfinite(points_after) && isfinite(simplify_time)) ||
      assemblies < 0.0 || point_cost < 0.0 || points_after < 0.0 || simplify_time < 0.0)
    return 0;
  return (points_before - points_after) * point_cost * assemblies > simplify_time;
}

/* Core-seconds per cut-cell point per assembly. Measured with
 *   OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive fcm-converge payoff --csv payoff.csv
 * (column point_cost: the CPU time an assembly saves divided by the points it saves, on the
 * hemisphere at res 8, geometry n 8, with the elements' default strengths; 2026-11-23, one
 * core of the 2-core development machine); re-measure after a change of the assembly
 * kernels. */
double fcm_cell_rules_point_cost(fcm_element_type type, fcm_rule_kind kind)
{
  static const double cost[FCM_ELEMENT_COUNT][FCM_RULE_KIND_COUNT] = {
      [FCM_ELEMENT_TET4] = {4.84e-7, 7.90e-8},
      [FCM_ELEMENT_TET10] = {1.24e-6, 1.29e-7},
      [FCM_ELEMENT_HEX8] = {9.27e-7, 9.98e-8},
      [FCM_ELEMENT_HEX20] = {3.55e-6, 2.45e-7},
  };
  if ((int)type < 0 || type >= FCM_ELEMENT_COUNT || (int)kind < 0 || kind >= FCM_RULE_KIND_COUNT)
    return 0.0;
  return cost[type][kind];
}

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
  int nfp; /* face polygons: meta (face, piece, vertices, part vertices) x nfp, coordinates fx
              (the polygon's, then its part's) */
  int *fmeta;
  double *fx;
} cell_out;

/* Everything the per-cell work reads; the trees and rules are owned (build_release). */
typedef struct build {
  fcm_ctx *ctx;
  const fcm_mesh *mesh;
  const fcm_geometry *geom;
  const fcm_cell_rules_options *o;
  fcm_aabb_tree *tree, *tri_tree;
  fcm_rule *tet_rule[FCM_RULE_KIND_COUNT];        /* rule mapped onto each tet */
  const fcm_rule *full_rule[FCM_RULE_KIND_COUNT]; /* catalogue rule of the cell shape (in R) */
  fcm_rule *tri_rule;                             /* NULL: no surface rules */
  int stabilize[FCM_RULE_KIND_COUNT];
  /* Cutting: the tree of R->cut_tris (NULL without cuts); region[c]: cell c shares a node
   * with a cell the cuts reach (its face polygons are recorded for the links); rebuild[c]:
   * integrate cell c (NULL: every cell), else copy its rules from prev; prev_region[c]: the
   * region of prev, whose links cover the pairs of its cells (NULL: prev has no cuts). */
  fcm_aabb_tree *cut_tree;
  const fcm__cut_tri *cut_tris;
  unsigned char *region, *rebuild, *prev_region;
  const fcm_cell_rules *prev;
  fcm_index first_new;    /* cut triangles from here on are new (those of the cut being added) */
  fcm__rules_reduce *red; /* distributed AUTO: sums the choice's inputs (NULL: none) */
  const unsigned char *remote; /* distributed classification: cells another process classifies
                                  (skipped here), NULL: none */
} build;

/* What one thread summed over the cells it built. */
/* A cell whose parts' total volume the cut splitting changes by more than this fraction of
 * the cell's volume meets the cut in a way the tolerances cannot resolve (near-coincident
 * vertices classified differently); fcm_cell_rules_create_cut() then shifts the cut. */
#define DEGENERATE_RTOL 1e-12

typedef struct cell_sums {
  fcm__embed_counts counts;
  double time_intersect, time_simplify; /* seconds of one core */
} cell_sums;

static void piece_out_free(fcm_ctx *ctx, piece_out *o)
{
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    fcm__free(ctx, o->pts[k]);
    fcm__free(ctx, o->w[k]);
    fcm__free(ctx, o->flag[k]);
    o->pts[k] = o->w[k] = NULL;
    o->flag[k] = NULL;
  }
  fcm__free(ctx, o->spts);
  fcm__free(ctx, o->sw);
  fcm__free(ctx, o->snrm);
  fcm__free(ctx, o->stri);
  fcm__free(ctx, o->cfxi);
  o->spts = o->sw = o->snrm = o->cfxi = NULL;
  o->stri = NULL;
}

static void cell_out_free(fcm_ctx *ctx, cell_out *o)
{
  if (o->pc)
    for (int i = 0; i < o->np; i++)
      piece_out_free(ctx, o->pc + i);
  if (o->pc != &o->one) fcm__free(ctx, o->pc);
  o->pc = NULL;
  o->np = 0;
  fcm__free(ctx, o->fmeta);
  fcm__free(ctx, o->fx);
  o->fmeta = NULL;
  o->fx = NULL;
}

/* The one call into the simplification module: reduce the rule (n points, in place) to
 * at most M points; record skipped / fallback / residual. */
static fcm_status simplify_rule(fcm_ctx *ctx, const fcm_simplify_options *opts, int strength,
                                int *n, double *pts, double *w, piece_out *o, int k)
{
  fcm_status st = FCM_OK;
  fcm_simplify_result res;
  fcm_simplify_info info;
  memset(&res, 0, sizeof res);
  FCM_TRY(ctx, fcm_simplify(ctx, strength, *n, pts, w, opts, &res, &info));
  FCM_CHECK(res.count >= 1 && res.count <= *n, ctx, FCM_ERR_INTERNAL,
            "embed: simplification returned %lld of %d points", (long long)res.count, *n);
  for (fcm_index i = 0; i < res.count; i++) { /* indices ascending: compaction is safe */
    const fcm_index j = res.indices[i];
    if (j != i) memmove(pts + 3 * i, pts + 3 * j, 3 * sizeof *pts);
    w[i] = res.weights[i];
  }
  *n = (int)res.count;
  o->skipped[k] = (unsigned char)info.skipped;
  o->fallback[k] = (unsigned char)info.fallback;
  o->residual[k] = info.residual;
  o->tsimp[k] += info.time_total;
cleanup:
  fcm_simplify_result_destroy(&res);
  return st;
}

/* Bytes that building the cut-cell rules of one background cell takes at its peak,
 * approximately, for n[k] initial points of each kind: the points, weights and flags of
 * both kinds (33 bytes a point) plus the largest simplification. Recombination (what
 * fcm_simplify's AUTO picks above 12 M points) keeps O(n) arrays: indices, weights, packed
 * points, about 56 bytes a point. The LP holds the M x n moment matrix, its row space and
 * GLPK's constraint matrix (about 56 bytes a nonzero): 72 M bytes a point, M = (m+1)(m+2)
 * (m+3)/6 moments of strength m. Not included: the LP that fcm_simplify tries after a
 * failed recombination. Measured (one Hex8 cell, 192k embedded tets, 5.2M points, AUTO):
 * estimate 0.42 GB, peak resident 0.29 GB. */
static double rule_memory_estimate(const size_t n[FCM_RULE_KIND_COUNT],
                                   const int strength[FCM_RULE_KIND_COUNT], int simplify,
                                   fcm_simplify_method method)
{
  enum { AUTO_RECOMBINE_RATIO = 12 }; /* fcm_simplify: AUTO recombines above 12 M points */
  double storage = 0.0, simplify_peak = 0.0;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    const double m = strength[k], M = (m + 1) * (m + 2) * (m + 3) / 6, nk = (double)n[k];
    storage += 33.0 * nk;
    if (!simplify || nk <= M) continue;
    const int lp = method == FCM_SIMPLIFY_LP ||
                   (method == FCM_SIMPLIFY_AUTO && nk <= AUTO_RECOMBINE_RATIO * M);
    simplify_peak = fmax(simplify_peak, lp ? 72.0 * M * nk : 56.0 * nk);
  }
  return storage + simplify_peak;
}

/* Refuse a cell whose rule building would take more than opt->max_rule_memory bytes,
 * before anything is allocated for it. */
static fcm_status check_rule_memory(const build *B, const fcm_cell_rules *R,
                                    const fcm__embed_cell *cell, const fcm__embed_ws *ws)
{
  fcm_status st = FCM_OK;
  const double limit = B->o->max_rule_memory;
  size_t n[FCM_RULE_KIND_COUNT];
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    n[k] = !B->tet_rule[k]
               ? 0
               : ws->num_tets * (size_t)fcm_rule_num_points(B->tet_rule[k]) +
                     (B->stabilize[k] ? (size_t)fcm_rule_num_points(B->full_rule[k]) : 0);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    FCM_CHECK(n[k] <= (size_t)1 << 30, B->ctx, FCM_ERR_UNSUPPORTED,
              "embed: background cell %lld would get %zu initial %s points (limit 2^30)",
              (long long)cell->id, n[k], k == FCM_RULE_MASS ? "mass" : "stiffness");
  const double need =
      rule_memory_estimate(n, R->strength, B->o->simplify, B->o->simplify_options.method);
  FCM_CHECK(limit <= 0.0 || need <= limit, B->ctx, FCM_ERR_UNSUPPORTED,
            "embed: background cell %lld holds %zu embedded tets (%zu stiffness, %zu mass "
            "points); building its rules needs about %.3g GiB, above the limit of %.3g GiB "
            "(fcm_cell_rules_options.max_rule_memory; scene key quadrature.max_rule_memory_gib): "
            "refine the background mesh there, coarsen the embedded geometry, lower the rule "
            "strengths or raise the limit",
            (long long)cell->id, ws->num_tets, n[FCM_RULE_STIFFNESS], n[FCM_RULE_MASS], need / GIB,
            limit / GIB);
cleanup:
  return st;
}

/* The last step of a cut cell's piece: simplify the kinds with simp[k] set, then append the
 * stabilization points. */
static fcm_status finish_cell(const build *B, const fcm_cell_rules *R, piece_out *o,
                              const int simp[FCM_RULE_KIND_COUNT], cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  const double t1 = fcm_wtime();
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!B->tet_rule[k]) continue; /* a kind not built */
    if (simp[k]) {
      FCM_TRY(ctx, simplify_rule(ctx, &opt->simplify_options, R->strength[k], &o->n[k], o->pts[k],
                                 o->w[k], o, k));
      o->nsimp[k] = o->n[k];
    }
    if (B->stabilize[k]) {
      fcm_index n = o->n[k];
      const fcm_index cap = n + fcm_rule_num_points(B->full_rule[k]);
      FCM_TRY(ctx, fcm_stabilization_append(ctx, &opt->stabilization, B->full_rule[k], cap, &n,
                                            o->pts[k], o->w[k], o->flag[k]));
      o->nstab[k] = (int)n - o->n[k];
      o->n[k] = (int)n;
    }
  }
cleanup:
  sums->time_simplify += fcm_wtime() - t1;
  return st;
}

/* Map the tets in ws into piece o's initial rules of both kinds. */
static fcm_status map_piece(const build *B, const fcm_cell_rules *R, const fcm__embed_cell *cell,
                            fcm__embed_ws *ws, piece_out *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  FCM_TRY(ctx, check_rule_memory(B, R, cell, ws));
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!B->tet_rule[k]) continue; /* a kind not built: no points */
    const size_t n0 = ws->num_tets * (size_t)fcm_rule_num_points(B->tet_rule[k]);
    const size_t ns = B->stabilize[k] ? (size_t)fcm_rule_num_points(B->full_rule[k]) : 0;
    FCM_ALLOC(ctx, 3 * (n0 + ns), o->pts[k]);
    FCM_ALLOC(ctx, n0 + ns, o->w[k]);
    FCM_ALLOC(ctx, n0 + ns, o->flag[k]);
    FCM_TRY(ctx, fcm__embed_map_tets(ctx, cell, ws, B->tet_rule[k], o->pts[k], o->w[k]));
    o->n[k] = o->ninit[k] = o->nsimp[k] = (int)n0;
  }
cleanup:
  return st;
}

/* The surface points in ws (physical: one piece's, fcm__embed_cell_surface()) into o,
 * mapped to reference coordinates. */
static fcm_status surface_piece(const build *B, const fcm__embed_cell *cell,
                                const fcm__embed_ws *ws, piece_out *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const size_t ns = ws->num_spts;
  if (ns == 0) return FCM_OK;
  FCM_ALLOC(ctx, 3 * ns, o->spts);
  FCM_ALLOC(ctx, ns, o->sw);
  FCM_ALLOC(ctx, 3 * ns, o->snrm);
  FCM_ALLOC(ctx, ns, o->stri);
  size_t i = 0;
  for (size_t j = 0; j < ns; j++) {
    double det;
    FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, ws->spts + 3 * j, o->spts + 3 * i, &det));
    o->sw[i] = ws->sw[j];
    memcpy(o->snrm + 3 * i, ws->snrm + 3 * j, 3 * sizeof *o->snrm);
    o->stri[i] = ws->stri[j];
    i++;
  }
  o->ns = (int)ns;
cleanup:
  return st;
}

/* Copy the rules of cell c from the previous rules object (a cell no new cut reaches). */
static fcm_status copy_cell(const build *B, fcm_index c, cell_out *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules *Q = B->prev;
  const fcm_index p0 = Q->piece_off[c], np = Q->piece_off[c + 1] - p0;
  for (fcm_index i = 0; i < np; i++) {
    piece_out *po = o->pc + i;
    const fcm_index p = p0 + i;
    po->volume = Q->piece_volume[p];
    po->component = Q->piece_component[p];
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const size_t a = (size_t)Q->off[k][p], n = (size_t)Q->off[k][p + 1] - a;
      if (n) {
        FCM_ALLOC(ctx, 3 * n, po->pts[k]);
        FCM_ALLOC(ctx, n, po->w[k]);
        FCM_ALLOC(ctx, n, po->flag[k]);
        memcpy(po->pts[k], Q->points[k] + 3 * a, 3 * n * sizeof(double));
        memcpy(po->w[k], Q->weights[k] + a, n * sizeof(double));
        memcpy(po->flag[k], Q->flags[k] + a, n);
      }
      po->n[k] = po->ninit[k] = po->nsimp[k] = (int)n;
    }
    const size_t a = (size_t)Q->soff[p], n = (size_t)Q->soff[p + 1] - a;
    if (n) {
      FCM_ALLOC(ctx, 3 * n, po->spts);
      FCM_ALLOC(ctx, n, po->sw);
      FCM_ALLOC(ctx, 3 * n, po->snrm);
      FCM_ALLOC(ctx, n, po->stri);
      memcpy(po->spts, Q->spoints + 3 * a, 3 * n * sizeof(double));
      memcpy(po->sw, Q->sweights + a, n * sizeof(double));
      memcpy(po->snrm, Q->snormals + 3 * a, 3 * n * sizeof(double));
      memcpy(po->stri, Q->stris + a, n * sizeof(fcm_index));
    }
    po->ns = (int)n;
    const size_t c0 = (size_t)Q->cfoff[p], nc = (size_t)Q->cfoff[p + 1] - c0;
    if (nc) {
      FCM_ALLOC(ctx, 9 * nc, po->cfxi);
      memcpy(po->cfxi, Q->cfxi + 9 * c0, 9 * nc * sizeof(double));
    }
    po->ncf = (int)nc;
  }
cleanup:
  return st;
}

/* Room for np pieces in o (inline for one). */
static fcm_status cell_out_pieces(fcm_ctx *ctx, cell_out *o, int np)
{
  fcm_status st = FCM_OK;
  o->np = np;
  if (np <= 1) {
    o->pc = &o->one;
  } else {
    FCM_ALLOC(ctx, (size_t)np, o->pc);
  }
cleanup:
  return st;
}

/* Renumber the labels (P->piece, *count of them) so that labels whose parts keep no more than
 * vmin of volume (all slivers, or flat on a cut) are removed: those parts get -1. vol gets the
 * volume of each remaining label and was[i] the label that remaining label i had. */
static fcm_status drop_empty(const build *B, fcm__embed_ws *ws, double vmin, int *label, int *count,
                             double *vol, int *was, cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  fcm__parts *P = ws->parts;
  int kept = 0, *renum = NULL;
  FCM_ALLOC(ctx, (size_t)*count + 1, renum);
  for (int i = 0; i < *count; i++) {
    double v = 0.0;
    FCM_TRY(ctx, fcm__embed_piece_tets(ctx, P, label, i, ws, sums ? &sums->counts : NULL, &v));
    renum[i] = v > vmin ? kept : -1;
    if (v > vmin) vol[kept] = v, was[kept++] = i;
  }
  for (size_t j = 0; j < P->n; j++)
    label[j] = label[j] >= 0 ? renum[label[j]] : -1;
  *count = kept;
cleanup:
  fcm__free(ctx, renum);
  return st;
}

/* The convex parts and material pieces of a cell that cuts reach (or that lies next to
 * such a cell): parts, split, grouped; empty pieces (all slivers) are removed. On return
 * P->piece numbers the pieces with volume, -1 for parts of removed ones; vol[i] is the
 * volume of piece i (P->num_pieces of them) and comp[i] its number among all the
 * components; P->parent numbers the components under the earlier cuts only, empty ones
 * included (the numbering of the pieces of the rules being extended, before their empty
 * components were dropped: a component can lose its last volume to the new cut). */
static fcm_status cell_pieces(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                              cell_sums *sums, double **vol, int **comp)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  fcm__parts *P = ws->parts;
  FCM_TRY(ctx, fcm__embed_cell_parts(ctx, B->geom, B->tree, cell, opt->clip_rtol, opt->sliver_rtol,
                                     ws, P, &sums->counts));
  FCM_TRY(ctx, fcm__embed_cut_candidates(ctx, B->cut_tree, cell, &P->tcand));
  if (P->tcand.n > 0) {
    FCM_TRY(ctx, fcm__embed_cell_pieces(ctx, cell, B->cut_tris, B->first_new, P));
    sums->counts.degenerate += !(P->split_error <= DEGENERATE_RTOL * cell->volume);
  }
  FCM_ALLOC(ctx, (size_t)P->num_pieces + 1, *vol);
  if (B->prev) {
    /* a piece in an earlier piece that the build that made it removed (no more than a sliver)
     * holds no more volume than that one, up to rounding at the threshold: removed too, so
     * that every kept piece lies in a kept earlier one */
    const fcm_index p0 = B->prev->piece_off[cell->id], had = B->prev->piece_off[cell->id + 1] - p0;
    for (size_t j = 0; j < P->n; j++) {
      int found = 0;
      for (fcm_index q = 0; q < had && !found; q++)
        found = B->prev->piece_component[p0 + q] == P->parent[j];
      if (!found) P->piece[j] = -1;
    }
  }
  /* a piece is kept when it holds more than a sliver of the cell (a piece flat on a cut
   * carries no material and would tie the nodes of both sides together) */
  FCM_ALLOC(ctx, (size_t)P->num_pieces + 1, *comp);
  FCM_TRY(ctx, drop_empty(B, ws, opt->sliver_rtol * cell->volume, P->piece, &P->num_pieces, *vol,
                          *comp, sums));
cleanup:
  return st;
}

/* Intersect, classify and build the rules of background cell c into o (the thread's own
 * buffers); R->cls[c] and R->fraction[c] are written here (one writer per cell). Cells the
 * cuts reach are split into material pieces first; each piece then takes the
 * path of a cut cell. */
static fcm_status process_cell(const build *B, fcm_cell_rules *R, fcm_index c, fcm__embed_ws *ws,
                               cell_out *o, cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  fcm__embed_cell cell;
  double vol = 0.0, *pvol = NULL;
  int *pcomp = NULL;
  fcm__parts *P = NULL;
  const int integrate = !B->rebuild || B->rebuild[c];
  const int own = !opt->cell_mask || opt->cell_mask[c]; /* 0: classified, no points */
  const double t0 = fcm_wtime();
  FCM_TRY(ctx, fcm__embed_cell_setup(ctx, B->mesh, c, opt->clip_rtol, &cell));
  if (B->cut_tree && B->region[c]) {
    if (!ws->parts) FCM_ALLOC(ctx, 1, ws->parts);
    P = ws->parts;
    FCM_TRY(ctx, cell_pieces(B, &cell, ws, sums, &pvol, &pcomp));
    for (int i = 0; i < P->num_pieces; i++)
      vol += pvol[i];
    FCM_TRY(ctx, fcm__embed_face_polygons(ctx, &cell, P));
    if (P->nfp > 0) {
      FCM_ALLOC(ctx, 4 * P->nfp, o->fmeta);
      FCM_ALLOC(ctx, 3 * P->nfx, o->fx);
      memcpy(o->fmeta, P->fmeta, 4 * P->nfp * sizeof(int));
      memcpy(o->fx, P->fx, 3 * P->nfx * sizeof(double));
      o->nfp = (int)P->nfp;
    }
  } else {
    FCM_TRY(ctx, fcm__embed_cell_tets(ctx, B->geom, B->tree, &cell, opt->clip_rtol,
                                      opt->sliver_rtol, ws, &sums->counts, &vol));
  }
  const int np = P ? P->num_pieces : ws->num_tets > 0;
  /* |K ∩ Ω| <= |K|: the clipped volumes can sum to |K| (1 + 1e-12) through rounding. A cut
   * cell has phi < uncut_fraction <= 1, so its rule needs no rescaling; only the recorded
   * fraction and volume are clamped. A cell split into several pieces is cut whatever its
   * fraction. */
  const double phi = fmin(vol / cell.volume, 1.0);
  fcm_cell_class cls = FCM_CELL_CUT;
  if (phi < opt->min_fraction || np == 0)
    cls = FCM_CELL_DROPPED;
  else if (phi >= opt->uncut_fraction && np == 1)
    cls = FCM_CELL_UNCUT;
  R->cls[c] = (unsigned char)cls;
  R->fraction[c] = phi;
  o->volume = phi * cell.volume;
  FCM_TRY(ctx, cell_out_pieces(ctx, o, cls == FCM_CELL_DROPPED ? 0 : np));
  if (o->np == 1) o->pc[0].volume = o->volume;
  for (int i = 0; i < o->np; i++) { /* the earlier piece that holds each piece */
    o->pc[i].parent = i;
    o->pc[i].component = P ? pcomp[i] : 0;
    if (P && B->prev && integrate) {
      /* the component under the earlier cuts of the piece's first part, and the earlier
       * piece numbered so (not its rank among the components that keep volume now) */
      const fcm_index p0 = B->prev->piece_off[c], had = B->prev->piece_off[c + 1] - p0;
      size_t j = 0;
      while (j < P->n && P->piece[j] != i)
        j++;
      const int comp = j < P->n ? P->parent[j] : -1;
      o->pc[i].parent = -1;
      for (fcm_index q = 0; q < had && comp >= 0; q++)
        if (B->prev->piece_component[p0 + q] == comp) o->pc[i].parent = (int)q;
      FCM_CHECK(o->pc[i].parent >= 0, ctx, FCM_ERR_INTERNAL,
                "embed: piece %d of cell %lld lies in no piece of the rules being extended (%lld "
                "pieces there)",
                i, (long long)c, (long long)had);
    }
  }
  for (int i = 0; P && i < o->np && o->np > 1; i++)
    o->pc[i].volume = pvol[i];
  if (!integrate) {
    FCM_CHECK(B->prev->piece_off[c + 1] - B->prev->piece_off[c] == o->np &&
                  B->prev->cls[c] == R->cls[c],
              ctx, FCM_ERR_INTERNAL,
              "embed: cell %lld, which the new cut does not reach, now has %d pieces (class %d) "
              "instead of %lld (class %d)",
              (long long)c, o->np, (int)R->cls[c],
              (long long)(B->prev->piece_off[c + 1] - B->prev->piece_off[c]), (int)B->prev->cls[c]);
    FCM_TRY(ctx, copy_cell(B, c, o));
    goto cleanup;
  }
  /* the pieces' sides of the cuts: on every cell, masked or not (the space's DOF copies
   * depend on them: a cut along cell faces separates cells without splitting any) */
  if (P && P->tcand.n > 0 && cls != FCM_CELL_DROPPED)
    for (int i = 0; i < o->np; i++) {
      double *phys = NULL;
      int nt = 0;
      FCM_TRY(ctx, fcm__embed_cut_faces(ctx, &cell, B->cut_tris, P, i, &phys, &nt));
      o->pc[i].cfxi = phys;
      o->pc[i].ncf = nt;
      for (int k = 0; k < 3 * nt; k++) {
        double xi[3], det;
        FCM_TRY(ctx, fcm__embed_to_reference(ctx, &cell, phys + 3 * k, xi, &det));
        memcpy(phys + 3 * k, xi, sizeof xi);
      }
    }
  if (!own) { /* classification, piece volumes and cut faces only (cell_mask) */
    sums->time_intersect += fcm_wtime() - t0;
    goto cleanup;
  }
  if (cls == FCM_CELL_CUT) {
    for (int i = 0; i < o->np; i++) {
      double v;
      if (P) FCM_TRY(ctx, fcm__embed_piece_tets(ctx, P, P->piece, i, ws, NULL, &v));
      FCM_TRY(ctx, map_piece(B, R, &cell, ws, o->pc + i));
    }
  }
  if (B->tri_rule && cls != FCM_CELL_DROPPED) {
    for (int i = 0; i < o->np; i++) { /* split cells: each piece its exact share */
      if (i == 0 || o->np > 1)
        FCM_TRY(ctx, fcm__embed_cell_surface(ctx, B->geom, B->tri_tree, &cell, o->np > 1 ? P : NULL,
                                             i, opt->sliver_rtol, B->tri_rule, ws, &sums->counts));
      FCM_TRY(ctx, surface_piece(B, &cell, ws, o->pc + i));
    }
  }
  sums->time_intersect += fcm_wtime() - t0;
  if (cls == FCM_CELL_CUT && opt->simplify != FCM_CELL_SIMPLIFY_AUTO) {
    const int on = opt->simplify == FCM_CELL_SIMPLIFY_ON;
    const int simp[FCM_RULE_KIND_COUNT] = {on, on};
    for (int i = 0; i < o->np; i++)
      FCM_TRY(ctx, finish_cell(B, R, o->pc + i, simp, sums));
  }
cleanup:
  fcm__free(ctx, pvol);
  fcm__free(ctx, pcomp);
  return st;
}

static fcm_status check_options(fcm_ctx *ctx, const fcm_cell_rules_options *o, int reduced)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(o->kinds != 0 && (o->kinds & ~(unsigned)FCM_RULES_ALL) == 0, ctx, FCM_ERR_ARG,
            "embed: kinds = 0x%x must be a non-empty set of FCM_RULES_STIFFNESS (0x%x) and "
            "FCM_RULES_MASS (0x%x)",
            o->kinds, FCM_RULES_STIFFNESS, FCM_RULES_MASS);
  FCM_CHECK((int)o->simplify >= 0 && o->simplify < FCM_CELL_SIMPLIFY_COUNT, ctx, FCM_ERR_ARG,
            "embed: simplify = %d is not a mode (0 off, 1 on, 2 auto)", (int)o->simplify);
  if (o->simplify == FCM_CELL_SIMPLIFY_AUTO) {
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const char *kn = k == FCM_RULE_MASS ? "mass" : "stiffness";
      FCM_CHECK(isfinite(o->expected_assemblies[k]) && o->expected_assemblies[k] >= 0.0, ctx,
                FCM_ERR_ARG, "embed: expected_assemblies[%s] = %g must be finite and >= 0", kn,
                o->expected_assemblies[k]);
      FCM_CHECK(o->point_cost[k] == FCM_DEFAULT ||
                    (isfinite(o->point_cost[k]) && o->point_cost[k] > 0.0),
                ctx, FCM_ERR_ARG,
                "embed: point_cost[%s] = %g must be > 0 seconds (FCM_DEFAULT: the measured "
                "constant of the element)",
                kn, o->point_cost[k]);
    }
  }
  FCM_CHECK(!o->cell_mask || reduced || o->simplify != FCM_CELL_SIMPLIFY_AUTO, ctx, FCM_ERR_ARG,
            "embed: cell_mask with simplify = auto: the choice would depend on the mask (use on "
            "or off)");
  const int smax = o->simplify ? FCM_SIMPLIFY_MAX_STRENGTH : FCM_RULE_MAX_STRENGTH;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    FCM_CHECK(o->strength[k] >= -1 && o->strength[k] <= smax, ctx, FCM_ERR_ARG,
              "embed: %s strength = %d outside [0, %d] (-1: element default)",
              k == FCM_RULE_MASS ? "mass" : "stiffness", o->strength[k], smax);
  FCM_CHECK(o->surface_strength >= -1 && o->surface_strength <= FCM_RULE_MAX_STRENGTH, ctx,
            FCM_ERR_ARG, "embed: surface strength = %d outside [0, %d] (-1: none)",
            o->surface_strength, FCM_RULE_MAX_STRENGTH);
  FCM_CHECK(o->min_fraction >= 0.0 && o->min_fraction < o->uncut_fraction &&
                o->uncut_fraction <= 1.0,
            ctx, FCM_ERR_ARG,
            "embed: thresholds min_fraction = %g, uncut_fraction = %g must satisfy "
            "0 <= min_fraction < uncut_fraction <= 1",
            o->min_fraction, o->uncut_fraction);
  FCM_CHECK(o->clip_rtol >= 0.0 && o->clip_rtol < 1e-3 && o->sliver_rtol >= 0.0 &&
                o->sliver_rtol < 1e-3 && o->convex_rtol >= 0.0 && o->convex_rtol < 1e-2,
            ctx, FCM_ERR_ARG,
            "embed: tolerances clip_rtol = %g, sliver_rtol = %g (each in [0, 1e-3)), "
            "convex_rtol = %g (in [0, 1e-2)) out of range",
            o->clip_rtol, o->sliver_rtol, o->convex_rtol);
  FCM_CHECK(o->progress_interval >= 0.0 && isfinite(o->progress_interval), ctx, FCM_ERR_ARG,
            "embed: progress_interval = %g must be finite and >= 0 seconds", o->progress_interval);
  FCM_CHECK(o->max_rule_memory >= 0.0 && !isnan(o->max_rule_memory), ctx, FCM_ERR_ARG,
            "embed: max_rule_memory = %g bytes must be >= 0 (0: no limit)", o->max_rule_memory);
  FCM_CHECK((int)o->stabilization.mode >= 0 &&
                o->stabilization.mode < FCM_STABILIZATION_MODE_COUNT &&
                (o->stabilization.mode == FCM_STABILIZATION_OFF ||
                 (isfinite(o->stabilization.alpha) && o->stabilization.alpha > 0.0)),
            ctx, FCM_ERR_ARG, "embed: stabilization mode %d / alpha = %g invalid (alpha > 0)",
            (int)o->stabilization.mode, o->stabilization.alpha);
cleanup:
  return st;
}

/* Boxes (n x 6) of the embedded cells or of the boundary triangles. */
static fcm_status geometry_boxes(fcm_ctx *ctx, const fcm_geometry *g, int tris, double **out,
                                 fcm_index *n)
{
  fcm_status st = FCM_OK;
  const int npv = tris ? 3 : g->npc;
  const fcm_index *conn = tris ? g->tris : g->cells;
  const fcm_index m = tris ? g->num_tris : g->num_cells;
  double *b = NULL;
  FCM_ALLOC(ctx, 6 * (size_t)m, b);
  for (fcm_index i = 0; i < m; i++) {
    double *bi = b + 6 * i;
    for (int d = 0; d < 3; d++)
      bi[d] = HUGE_VAL, bi[3 + d] = -HUGE_VAL;
    for (int a = 0; a < npv; a++)
      for (int d = 0; d < 3; d++) {
        const double v = g->coords[3 * conn[(size_t)npv * (size_t)i + a] + d];
        bi[d] = fmin(bi[d], v);
        bi[3 + d] = fmax(bi[3 + d], v);
      }
  }
  *out = b;
  *n = m;
cleanup:
  return st;
}

/* FCM_ERR_GEOMETRY when background cell c is not convex (the rules build's first check). */
static fcm_status check_convex(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_index c,
                               const fcm_cell_rules_options *o)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(fcm_mesh_cell_is_convex(mesh, c, o->convex_rtol), ctx, FCM_ERR_GEOMETRY,
            "embed: background cell %lld (%s) is not a convex polyhedron with planar faces and "
            "straight edges (relative tolerance %g); cut-cell quadrature needs convex cells",
            (long long)c, fcm_mesh_get_element_info(mesh)->name, o->convex_rtol);
cleanup:
  return st;
}

fcm_status fcm__embed_crop_geometry(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                    const fcm_cell_rules_options *opts,
                                    const unsigned char *classify, const unsigned char *surface,
                                    fcm_geometry **out)
{
  fcm_status st = FCM_OK;
  double *boxes = NULL;
  fcm_index nbox = 0;
  fcm_aabb_tree *tree = NULL, *tri_tree = NULL;
  unsigned char *keep_cell = NULL, *keep_tri = NULL;
  fcm__idbuf ids = {NULL, 0, 0};
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "embed crop: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(ctx && mesh && geom && opts && classify, ctx, FCM_ERR_ARG,
            "embed crop: NULL argument (ctx, mesh, geometry, options, classify)");
  FCM_TRY(ctx, check_options(ctx, opts, 1));
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  FCM_TRY(ctx, geometry_boxes(ctx, geom, 0, &boxes, &nbox));
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, nbox, boxes, &tree));
  FCM_FREE(ctx, boxes);
  FCM_TRY(ctx, geometry_boxes(ctx, geom, 1, &boxes, &nbox));
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, nbox, boxes, &tri_tree));
  FCM_ALLOC(ctx, (size_t)geom->num_cells + 1, keep_cell);
  FCM_ALLOC(ctx, (size_t)geom->num_tris + 1, keep_tri);
  for (fcm_index c = 0; c < nc; c++) {
    const int cls = classify[c] != 0, srf = surface && surface[c] && opts->surface_strength >= 0;
    if (!cls && !srf) continue;
    fcm__embed_cell cell; /* the box the kernels query: the corners' widened by cell.tol */
    FCM_TRY(ctx, check_convex(ctx, mesh, c, opts));
    FCM_TRY(ctx, fcm__embed_cell_setup(ctx, mesh, c, opts->clip_rtol, &cell));
    if (cls) {
      FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, cell.lo, cell.hi, &ids));
      for (size_t k = 0; k < ids.n; k++)
        keep_cell[ids.ids[k]] = 1;
    }
    if (srf) {
      FCM_TRY(ctx, fcm__geom_tree_query(ctx, tri_tree, cell.lo, cell.hi, &ids));
      for (size_t k = 0; k < ids.n; k++)
        keep_tri[ids.ids[k]] = 1;
    }
  }
  FCM_TRY(ctx, fcm__geom_create_subset(ctx, geom, keep_cell, keep_tri, out));
  /* the whole geometry's volume beyond each side of the mesh box (fcm__embed_outside()) */
  fcm_geometry *g = *out;
  fcm_mesh_bounding_box(mesh, g->outside_mesh_lo, g->outside_mesh_hi);
  FCM_TRY(ctx, fcm__embed_outside_sides(ctx, g->outside_mesh_lo, g->outside_mesh_hi, geom,
                                        g->outside_side));
  g->has_outside = 1;
cleanup:
  if (st != FCM_OK) fcm_geometry_destroy(out);
  fcm__free(ctx, boxes);
  fcm__free(ctx, keep_cell);
  fcm__free(ctx, keep_tri);
  fcm__geom_idbuf_free(ctx, &ids);
  fcm_aabb_tree_destroy(&tree);
  fcm_aabb_tree_destroy(&tri_tree);
  return st;
}

/* Phase 1a: the result object with its per-cell arrays, strengths and catalogue rules. */
static fcm_status rules_alloc(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_cell_rules_options *o,
                              fcm_cell_rules **out)
{
  fcm_status st = FCM_OK;
  fcm_cell_rules *R = NULL;
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  const int element_strength[FCM_RULE_KIND_COUNT] = {
      [FCM_RULE_STIFFNESS] = info->stiffness_strength, [FCM_RULE_MASS] = info->mass_strength};
  FCM_ALLOC(ctx, 1, R);
  R->ctx = ctx;
  R->num_cells = nc;
  R->type = info->type;
  R->surface_strength = o->surface_strength;
  FCM_ALLOC(ctx, (size_t)nc, R->cls);
  FCM_ALLOC(ctx, (size_t)nc, R->fraction);
  FCM_ALLOC(ctx, (size_t)nc + 1, R->piece_off);
  R->opts = *o;
  R->stats.kinds = o->kinds;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    R->strength[k] = -1;
    if (!KIND_BUILT(o->kinds, k)) continue;
    R->strength[k] = o->strength[k] >= 0 ? o->strength[k] : element_strength[k];
    FCM_TRY(ctx, fcm_rule_create(ctx, info->shape, R->strength[k], &R->uncut[k]));
    FCM_ALLOC(ctx, (size_t)fcm_rule_num_points(R->uncut[k]), R->uncut_flags[k]);
  }
  *out = R;
  R = NULL;
cleanup:
  fcm_cell_rules_destroy(&R);
  return st;
}

static void build_release(build *B)
{
  fcm_aabb_tree_destroy(&B->cut_tree);
  if (B->ctx) {
    fcm__free(B->ctx, B->region);
    fcm__free(B->ctx, B->rebuild);
    fcm__free(B->ctx, B->prev_region);
  }
  B->region = B->rebuild = B->prev_region = NULL;
  fcm_aabb_tree_destroy(&B->tree);
  fcm_aabb_tree_destroy(&B->tri_tree);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    fcm_rule_destroy(&B->tet_rule[k]);
  fcm_rule_destroy(&B->tri_rule);
}

/* Phase 1b: what every cell reads: tet rules, search trees of the embedded cells and
 * boundary triangles, which kinds get stabilization points. */
static fcm_status build_setup(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                              const fcm_cell_rules_options *o, const fcm_cell_rules *R, build *B)
{
  fcm_status st = FCM_OK;
  double *boxes = NULL;
  fcm_index nbox = 0;
  memset(B, 0, sizeof *B);
  B->ctx = ctx, B->mesh = mesh, B->geom = geom, B->o = o;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!KIND_BUILT(o->kinds, k)) continue; /* tet_rule[k] NULL marks a kind not built */
    FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_TET, R->strength[k], &B->tet_rule[k]));
    B->full_rule[k] = R->uncut[k];
  }
  B->stabilize[FCM_RULE_STIFFNESS] = o->stabilization.mode == FCM_STABILIZATION_MASS_STIFFNESS;
  B->stabilize[FCM_RULE_MASS] = o->stabilization.mode != FCM_STABILIZATION_OFF;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    B->stabilize[k] = B->stabilize[k] && B->tet_rule[k];
  FCM_TRY(ctx, geometry_boxes(ctx, geom, 0, &boxes, &nbox));
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, nbox, boxes, &B->tree));
  FCM_FREE(ctx, boxes);
  if (o->surface_strength >= 0) {
    FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_TRI, o->surface_strength, &B->tri_rule));
    FCM_TRY(ctx, geometry_boxes(ctx, geom, 1, &boxes, &nbox));
    FCM_TRY(ctx, fcm_aabb_tree_create(ctx, nbox, boxes, &B->tri_tree));
  }
cleanup:
  fcm__free(ctx, boxes);
  if (st != FCM_OK) build_release(B);
  return st;
}

/* Phase 1c (cuts only): the tree of R's cut triangles, the region (cells sharing a node with
 * a cell the cuts reach) and, when extending `prev` by the triangles from first_new on,
 * the cells to integrate (those the new triangles reach). */
static fcm_status cut_setup(build *B, fcm_cell_rules *R, fcm_index first_new)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_mesh *mesh = B->mesh;
  const fcm_index nc = fcm_mesh_num_cells(mesh), nn = fcm_mesh_num_nodes(mesh);
  const int npc = fcm_mesh_nodes_per_cell(mesh);
  const fcm_index *cells = fcm_mesh_cells(mesh);
  double *boxes = NULL;
  unsigned char *node_hit = NULL; /* 1: a cell the cuts reach holds the node; 2: the earlier */
  fcm__idbuf ids = {NULL, 0, 0};
  FCM_ALLOC(ctx, 6 * (size_t)R->num_cut_tris + 6, boxes);
  for (fcm_index t = 0; t < R->num_cut_tris; t++) {
    memcpy(boxes + 6 * t, R->cut_tris[t].lo, 3 * sizeof(double));
    memcpy(boxes + 6 * t + 3, R->cut_tris[t].hi, 3 * sizeof(double));
  }
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, R->num_cut_tris, boxes, &B->cut_tree));
  B->cut_tris = R->cut_tris;
  FCM_ALLOC(ctx, (size_t)nc + 1, B->region);
  FCM_ALLOC(ctx, (size_t)nn + 1, node_hit);
  fcm__free(ctx, R->reached);
  R->reached = NULL;
  FCM_ALLOC(ctx, (size_t)nc + 1, R->reached);
  if (B->prev) FCM_ALLOC(ctx, (size_t)nc + 1, B->rebuild);
  if (B->prev && first_new > 0) FCM_ALLOC(ctx, (size_t)nc + 1, B->prev_region);
  for (fcm_index c = 0; c < nc; c++) {
    fcm__embed_cell cell;
    FCM_TRY(ctx, fcm__embed_cell_setup(ctx, mesh, c, B->o->clip_rtol, &cell));
    FCM_TRY(ctx, fcm__embed_cut_candidates(ctx, B->cut_tree, &cell, &ids));
    if (ids.n == 0) continue;
    R->reached[c] = 1;
    for (int a = 0; a < npc; a++) /* ids ascending: the earlier cuts' triangles first */
      node_hit[cells[(size_t)npc * c + a]] |= (unsigned char)(ids.ids[0] < first_new ? 3 : 1);
    if (B->rebuild && ids.ids[ids.n - 1] >= first_new) B->rebuild[c] = 1;
  }
  for (fcm_index c = 0; c < nc; c++)
    for (int a = 0; a < npc; a++) {
      const unsigned char h = node_hit[cells[(size_t)npc * c + a]];
      B->region[c] |= h != 0;
      if (B->prev_region) B->prev_region[c] |= (h & 2) != 0;
    }
cleanup:
  fcm__free(ctx, boxes);
  fcm__free(ctx, node_hit);
  fcm__geom_idbuf_free(ctx, &ids);
  return st;
}

/* Phase 2: every cell in parallel into its own cell_out; thread sums into *sums. An error
 * is that of the lowest failing cell, whatever the thread count. */
static fcm_status run_cells(const build *B, fcm_cell_rules *R, int nthreads, cell_out *out,
                            cell_sums *sums, const fcm_cell_rules_options *opt)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index nc = R->num_cells;
  fcm_index done = 0;
  double last = fcm_wtime();
  fcm__loop loop;
  fcm__loop_begin(ctx, &loop);
  memset(sums, 0, sizeof *sums);
#pragma omp parallel num_threads(nthreads)
  {
    cell_sums mine;
    memset(&mine, 0, sizeof mine);
    fcm__embed_ws *ws = NULL;
#pragma omp for schedule(dynamic, 4)
    for (fcm_index c = 0; c < nc; c++) {
      if (fcm__loop_skip(&loop, c)) continue;
      fcm__loop_iter it;
      fcm__loop_enter(&loop, &it, c);
      fcm_status s = FCM_OK;
      if (!ws) { /* the thread's workspace, made by its first cell */
        ws = fcm__calloc(ctx, 1, sizeof *ws);
        if (!ws) s = FCM_ERR_ALLOC;
      }
      const int remote = B->remote && B->remote[c]; /* classified by another process */
      if (s == FCM_OK && !remote) s = process_cell(B, R, c, ws, out + c, &mine);
      fcm__loop_leave(&loop, &it, s);
      if (opt->progress) { /* counted by all threads, reported by the calling one */
#pragma omp atomic
        done++;
        if (omp_get_thread_num() == 0 && fcm_wtime() - last >= opt->progress_interval) {
          fcm_index now;
#pragma omp atomic read
          now = done;
          opt->progress(now, nc, opt->progress_user);
          last = fcm_wtime();
        }
      }
    }
    if (ws) fcm__embed_ws_free(ctx, ws);
    fcm__free(ctx, ws);
#pragma omp critical(fcm_embed_sum)
    {
      sums->counts.candidates += mine.counts.candidates;
      sums->counts.parts += mine.counts.parts;
      sums->counts.tets += mine.counts.tets;
      sums->counts.slivers += mine.counts.slivers;
      sums->counts.surface_triangles += mine.counts.surface_triangles;
      sums->counts.sliver_volume += mine.counts.sliver_volume;
      sums->counts.degenerate += mine.counts.degenerate;
      sums->time_intersect += mine.time_intersect;
      sums->time_simplify += mine.time_simplify;
    }
  }
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
  if (opt->progress) opt->progress(nc, nc, opt->progress_user);
cleanup:
  return st;
}

/* Finish the pieces list[0 .. n) in parallel (simplify the kinds that pay, stabilize);
 * the error is the lowest failing one's. */
static fcm_status auto_finish(const build *B, const fcm_cell_rules *R, int nthreads,
                              piece_out *const *list, fcm_index n,
                              const int pays[FCM_RULE_KIND_COUNT], cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  fcm__loop loop;
  fcm__loop_begin(ctx, &loop);
#pragma omp parallel num_threads(nthreads)
  {
    cell_sums mine;
    memset(&mine, 0, sizeof mine);
#pragma omp for schedule(dynamic, 1)
    for (fcm_index i = 0; i < n; i++) {
      if (fcm__loop_skip(&loop, i)) continue;
      fcm__loop_iter it;
      fcm__loop_enter(&loop, &it, i);
      int simp[FCM_RULE_KIND_COUNT];
      for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
        simp[k] = pays[k];
      fcm_status s = finish_cell(B, R, list[i], simp, &mine);
      fcm__loop_leave(&loop, &it, s);
    }
#pragma omp critical(fcm_embed_auto_sum)
    sums->time_simplify += mine.time_simplify;
  }
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
cleanup:
  return st;
}

/* Phase 2b of FCM_CELL_SIMPLIFY_AUTO (the cells are intersected and mapped, not yet
 * simplified nor stabilized): per kind, the simplification time of every cut-cell piece
 * from the deterministic model fcm_simplify_cost_estimate() and the points it would keep
 * (min(N, M)), against the assembly time of the points it removes over the expected
 * assemblies (fcm_simplify_pays()). The rules are then those of OFF or ON for each kind,
 * and the same inputs always give the same decision (no timing: runs, thread counts and
 * resumed runs agree). Then finish every piece that was integrated here. */
static fcm_status auto_simplify(const build *B, fcm_cell_rules *R, int nthreads, cell_out *out,
                                cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  const fcm_index nc = R->num_cells;
  piece_out **cut = NULL;
  fcm_index ncut = 0;
  int pays[FCM_RULE_KIND_COUNT] = {0, 0};
  /* the cut cells integrated here (with a cell_mask: this process's only; the others have
   * no points) */
#define AUTO_CELL(c)                                                                               \
  (R->cls[c] == FCM_CELL_CUT && (!B->rebuild || B->rebuild[c]) &&                                  \
   (!opt->cell_mask || opt->cell_mask[c]))
  for (fcm_index c = 0; c < nc; c++)
    if (AUTO_CELL(c)) ncut += out[c].np;
  FCM_ALLOC(ctx, (size_t)ncut + 1, cut);
  ncut = 0;
  for (fcm_index c = 0; c < nc; c++)
    if (AUTO_CELL(c))
      for (int i = 0; i < out[c].np; i++)
        cut[ncut++] = out[c].pc + i;
#undef AUTO_CELL
  /* the choice's inputs per kind: points, modelled simplification time, points kept */
  double in[3 * FCM_RULE_KIND_COUNT];
  memset(in, 0, sizeof in);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!B->tet_rule[k]) continue;
    const int m = R->strength[k];
    const double M = (double)(m + 1) * (m + 2) * (m + 3) / 6.0;
    for (fcm_index i = 0; i < ncut; i++) {
      const fcm_index n = cut[i]->ninit[k];
      in[3 * k] += (double)n;
      in[3 * k + 1] += fcm_simplify_cost_estimate(m, n);
      in[3 * k + 2] += (double)n < M ? (double)n : M;
    }
  }
  if (B->red && !B->prev) { /* distributed, masked: every process's cut cells */
    B->red->called = 1;
    FCM_TRY(ctx, B->red->fn(B->red->user, FCM_OK, in, 3 * FCM_RULE_KIND_COUNT));
  }
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!B->tet_rule[k]) continue; /* a kind not built: nothing to decide */
    fcm_simplify_decision *d = &R->stats.decision[k];
    const fcm_element_type type = fcm_mesh_element_type(B->mesh);
    d->expected_assemblies = opt->expected_assemblies[k];
    d->point_cost =
        opt->point_cost[k] == FCM_DEFAULT ? fcm_cell_rules_point_cost(type, k) : opt->point_cost[k];
    const double ntot = in[3 * k];
    d->estimated_time = in[3 * k + 1];
    d->estimated_kept = in[3 * k + 2];
    d->cost_plain = ntot * d->point_cost * d->expected_assemblies;
    d->cost_simplified =
        d->estimated_time + d->estimated_kept * d->point_cost * d->expected_assemblies;
    pays[k] = fcm_simplify_pays(d->expected_assemblies, d->point_cost, ntot, d->estimated_kept,
                                d->estimated_time);
    /* A cut added later decides as the rules it extends did: one object, one choice. */
    if (B->prev) pays[k] = B->prev->stats.decision[k].simplified;
  }
  FCM_TRY(ctx, auto_finish(B, R, nthreads, cut, ncut, pays, sums));
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    R->stats.decision[k].simplified = pays[k];
cleanup:
  fcm__free(ctx, cut);
  return st;
}

/* Phase 3: concatenate the pieces' volume and surface rules in cell order. */
static fcm_status gather_rules(fcm_ctx *ctx, fcm_cell_rules *R, const cell_out *out,
                               const fcm_cell_rules *prev)
{
  fcm_status st = FCM_OK;
  const fcm_index nc = R->num_cells;
  fcm_index np = 0;
  for (fcm_index c = 0; c < nc; c++)
    np += out[c].np;
  R->num_pieces = np;
  FCM_ALLOC(ctx, (size_t)np + 1, R->piece_cell);
  FCM_ALLOC(ctx, (size_t)np + 1, R->piece_volume);
  FCM_ALLOC(ctx, (size_t)np + 1, R->piece_parent);
  FCM_ALLOC(ctx, (size_t)np + 1, R->piece_component);
  FCM_ALLOC(ctx, (size_t)np + 1, R->soff);
  R->piece_off[0] = 0;
  for (fcm_index c = 0; c < nc; c++) {
    R->piece_off[c + 1] = R->piece_off[c] + out[c].np;
    for (int i = 0; i < out[c].np; i++) {
      R->piece_cell[R->piece_off[c] + i] = c;
      R->piece_volume[R->piece_off[c] + i] = out[c].pc[i].volume;
      R->piece_parent[R->piece_off[c] + i] = prev ? prev->piece_off[c] + out[c].pc[i].parent : -1;
      R->piece_component[R->piece_off[c] + i] = out[c].pc[i].component;
    }
  }
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    fcm_index *off = NULL;
    FCM_ALLOC(ctx, (size_t)np + 1, R->off[k]);
    off = R->off[k];
    for (fcm_index c = 0; c < nc; c++)
      for (int i = 0; i < out[c].np; i++) {
        const fcm_index p = R->piece_off[c] + i;
        off[p + 1] = off[p] + (R->cls[c] == FCM_CELL_CUT ? out[c].pc[i].n[k] : 0);
      }
    const size_t tot = (size_t)off[np];
    FCM_ALLOC(ctx, 3 * tot, R->points[k]);
    FCM_ALLOC(ctx, tot, R->weights[k]);
    FCM_ALLOC(ctx, tot, R->flags[k]);
    for (fcm_index c = 0; c < nc; c++)
      for (int i = 0; i < out[c].np; i++) {
        const fcm_index p = R->piece_off[c] + i;
        const size_t n = (size_t)(off[p + 1] - off[p]), o0 = (size_t)off[p];
        if (!n) continue;
        memcpy(R->points[k] + 3 * o0, out[c].pc[i].pts[k], 3 * n * sizeof(double));
        memcpy(R->weights[k] + o0, out[c].pc[i].w[k], n * sizeof(double));
        memcpy(R->flags[k] + o0, out[c].pc[i].flag[k], n);
      }
  }
  FCM_ALLOC(ctx, (size_t)np + 1, R->cfoff);
  for (fcm_index c = 0; c < nc; c++)
    for (int i = 0; i < out[c].np; i++) {
      const fcm_index p = R->piece_off[c] + i;
      R->cfoff[p + 1] = R->cfoff[p] + out[c].pc[i].ncf;
    }
  FCM_ALLOC(ctx, 9 * (size_t)R->cfoff[np] + 1, R->cfxi);
  for (fcm_index c = 0; c < nc; c++)
    for (int i = 0; i < out[c].np; i++)
      if (out[c].pc[i].ncf)
        memcpy(R->cfxi + 9 * R->cfoff[R->piece_off[c] + i], out[c].pc[i].cfxi,
               9 * (size_t)out[c].pc[i].ncf * sizeof(double));
  R->soff[0] = 0;
  for (fcm_index c = 0; c < nc; c++)
    for (int i = 0; i < out[c].np; i++) {
      const fcm_index p = R->piece_off[c] + i;
      R->soff[p + 1] = R->soff[p] + out[c].pc[i].ns;
    }
  const size_t tot = (size_t)R->soff[np];
  FCM_ALLOC(ctx, 3 * tot, R->spoints);
  FCM_ALLOC(ctx, tot, R->sweights);
  FCM_ALLOC(ctx, 3 * tot, R->snormals);
  FCM_ALLOC(ctx, tot, R->stris);
  for (fcm_index c = 0; c < nc; c++)
    for (int i = 0; i < out[c].np; i++) {
      const piece_out *o = out[c].pc + i;
      const size_t n = (size_t)o->ns, o0 = (size_t)R->soff[R->piece_off[c] + i];
      if (!n) continue;
      memcpy(R->spoints + 3 * o0, o->spts, 3 * n * sizeof(double));
      memcpy(R->sweights + o0, o->sw, n * sizeof(double));
      memcpy(R->snormals + 3 * o0, o->snrm, 3 * n * sizeof(double));
      memcpy(R->stris + o0, o->stri, n * sizeof(fcm_index));
    }
cleanup:
  return st;
}

static int cmp_link(const void *a, const void *b)
{
  const fcm_index *x = a, *y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return (x[1] > y[1]) - (x[1] < y[1]);
}

/* Whether the earlier pieces qa of cell ca and qb of cell cb (ca < cb, face neighbours) were
 * linked in the rules being extended: a cut only separates, so pieces whose parents it had
 * separated stay apart, whatever the face tests on the new, smaller pieces say (near a cut
 * within the tolerances those can differ). Cells outside the earlier region had one piece
 * each, linked to its neighbours'. */
static int earlier_link(const build *B, fcm_index ca, fcm_index cb, int qa, int qb)
{
  if (!B->prev_region || !B->prev_region[ca] || !B->prev_region[cb]) return 1;
  const fcm_cell_rules *Q = B->prev;
  const fcm_index key[2] = {Q->piece_off[ca] + qa, Q->piece_off[cb] + qb};
  return bsearch(key, Q->links, (size_t)Q->num_links, 2 * sizeof *Q->links, cmp_link) != NULL;
}

/* Phase 3b (cuts only): the links between pieces of face-neighbouring region cells: a
 * polygon of one cell's piece on the shared face overlaps a polygon of the other cell's
 * piece with positive area, and the overlap does not lie on a cut triangle, and
 * their parents were linked (earlier_link()). */
static fcm_status gather_links(const build *B, fcm_cell_rules *R, const cell_out *out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_mesh *mesh = B->mesh;
  const int nf = fcm_mesh_get_element_info(mesh)->num_faces;
  const fcm_index *nbr = fcm_mesh_neighbors(mesh);
  fcm_index *links = NULL;
  size_t nl = 0, cap = 0;
  fcm__idbuf tc = {NULL, 0, 0};
  for (fcm_index c = 0; c < R->num_cells; c++) {
    const cell_out *oa = out + c;
    if (!B->region[c] || oa->np == 0) continue;
    fcm__embed_cell cell;
    FCM_TRY(ctx, fcm__embed_cell_setup(ctx, mesh, c, B->o->clip_rtol, &cell));
    const double mtol = FCM__EMBED_MATCH_RTOL * cell.size, atol = 1e-12 * cell.size * cell.size;
    for (int f = 0; f < nf; f++) {
      const fcm_index c2 = nbr[(size_t)nf * c + f];
      if (c2 <= c || !B->region[c2] || out[c2].np == 0) continue;
      int f2 = 0;
      while (f2 < nf && nbr[(size_t)nf * c2 + f2] != c)
        f2++;
      if (f2 == nf) continue;
      const cell_out *ob = out + c2;
      const fcm_index pa0 = R->piece_off[c], pb0 = R->piece_off[c2];
      size_t xa = 0;
      for (int i = 0; i < oa->nfp; i++) {
        const int *ma = oa->fmeta + 4 * i;
        const double *A = oa->fx + 3 * xa;
        xa += (size_t)(ma[2] + ma[3]);
        if (ma[0] != f || ma[1] < 0) continue;
        size_t xb = 0;
        for (int j = 0; j < ob->nfp; j++) {
          const int *mb = ob->fmeta + 4 * j;
          const double *Bx = ob->fx + 3 * xb;
          xb += (size_t)(mb[2] + mb[3]);
          if (mb[0] != f2 || mb[1] < 0) continue;
          const fcm_index pa = pa0 + ma[1], pb = pb0 + mb[1];
          int known = 0;
          for (size_t l = nl; l-- > 0 && !known;)
            known = links[2 * l] == pa && links[2 * l + 1] == pb;
          if (known) continue;
          double lo[3], hi[3];
          const double *nb = cell.planes[f].n; /* polygon B faces out of c2: normal -n_f */
          const double nbn[3] = {-nb[0], -nb[1], -nb[2]};
          for (int d = 0; d < 3; d++) {
            lo[d] = HUGE_VAL, hi[d] = -HUGE_VAL;
            for (int k = 0; k < ma[2]; k++)
              lo[d] = fmin(lo[d], A[3 * k + d] - mtol), hi[d] = fmax(hi[d], A[3 * k + d] + mtol);
          }
          FCM_TRY(ctx, fcm__geom_tree_query(ctx, B->cut_tree, lo, hi, &tc));
          if (!fcm__embed_linked(A, ma[2], A + 3 * ma[2], ma[3], Bx, mb[2], Bx + 3 * mb[2], mb[3],
                                 nbn, mtol, atol, B->cut_tris, tc.ids, tc.n))
            continue;
          if (!earlier_link(B, c, c2, out[c].pc[ma[1]].parent, out[c2].pc[mb[1]].parent)) continue;
          if (nl + 1 > cap) {
            const size_t ncap = cap ? 2 * cap : 256;
            void *q = links;
            FCM_TRY(ctx, fcm__resize(ctx, &q, 2 * nl, 2 * ncap, sizeof(fcm_index)));
            links = q;
            cap = ncap;
          }
          links[2 * nl] = pa, links[2 * nl + 1] = pb;
          nl++;
        }
      }
    }
  }
  if (nl) qsort(links, nl, 2 * sizeof *links, cmp_link);
  R->links = links;
  R->num_links = (fcm_index)nl;
  links = NULL;
cleanup:
  fcm__free(ctx, links);
  fcm__geom_idbuf_free(ctx, &tc);
  return st;
}

/* Phase 4: the statistics (times are filled in by the caller). */
static void gather_stats(fcm_cell_rules *R, const fcm_geometry *geom, const cell_out *out,
                         const cell_sums *sums, int nthreads)
{
  fcm_cell_rules_stats *S = &R->stats;
  const fcm_index nc = R->num_cells;
  S->num_cells = nc;
  for (fcm_index c = 0; c < nc; c++) {
    const cell_out *o = out + c;
    for (int i = 0; i < o->np; i++) {
      const piece_out *q = o->pc + i;
      for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
        S->points_initial[k] += q->ninit[k];
        S->points_simplified[k] += q->nsimp[k];
        S->points_stabilization[k] += q->nstab[k];
        S->simplify_skipped[k] += q->skipped[k];
        S->simplify_fallbacks[k] += q->fallback[k];
        S->max_residual[k] = fmax(S->max_residual[k], q->residual[k]);
        S->decision[k].time_simplify += q->tsimp[k];
      }
      for (int j = 0; j < q->ns; j++)
        S->embedded_area += q->sw[j];
    }
    S->num_split += o->np > 1;
    S->embedded_volume += o->volume;
    switch ((fcm_cell_class)R->cls[c]) {
    case FCM_CELL_UNCUT:
      S->num_uncut++;
      break;
    case FCM_CELL_CUT:
      S->num_cut++;
      break;
    default:
      S->num_dropped++;
      S->dropped_volume += o->volume;
      break;
    }
  }
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    S->points_total[k] =
        R->uncut[k] ? R->off[k][R->num_pieces] + S->num_uncut * fcm_rule_num_points(R->uncut[k])
                    : 0;
  S->surface_points = R->soff[R->num_pieces];
  S->num_material_pieces = R->num_pieces;
  S->num_links = R->num_links;
  S->num_candidates = sums->counts.candidates;
  S->num_parts = sums->counts.parts;
  S->num_tets = sums->counts.tets;
  S->num_slivers = sums->counts.slivers;
  S->sliver_volume = sums->counts.sliver_volume;
  S->num_degenerate = sums->counts.degenerate;
  S->surface_triangles = sums->counts.surface_triangles;
  S->geometry_volume = fcm_geometry_volume(geom);
  S->num_threads = nthreads;
  S->time_intersect = sums->time_intersect;
  S->time_simplify = sums->time_simplify;
}

/* The remote cells' class, fraction and volume from the exchange (x) into R and out; *exchanged
 * is set once the exchange ran (whatever its outcome). */
static fcm_status exchange_classes(const build *B, fcm_cell_rules *R, const fcm__rules_exchange *x,
                                   cell_out *out, cell_sums *sums, int *exchanged)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index nc = R->num_cells;
  double *volume = fcm__calloc(ctx, (size_t)nc + 1, sizeof *volume);
  st = volume ? FCM_OK : FCM_ERR_ALLOC;
  if (st != FCM_OK) fcm__error(ctx, st, __FILE__, __LINE__, __func__, "embed: out of memory");
  for (fcm_index c = 0; volume && c < nc; c++)
    if (!x->remote[c]) volume[c] = out[c].volume;
  *exchanged = 1;
  st = x->exchange(x->user, st, st == FCM_OK ? R->cls : NULL, st == FCM_OK ? R->fraction : NULL,
                   st == FCM_OK ? volume : NULL, st == FCM_OK ? &sums->counts : NULL);
  FCM_TRY(ctx, st);
  for (fcm_index c = 0; c < nc; c++) {
    if (!x->remote[c]) continue;
    const int cls = R->cls[c];
    const double phi = R->fraction[c], v = volume[c];
    FCM_CHECK((cls == FCM_CELL_UNCUT || cls == FCM_CELL_CUT || cls == FCM_CELL_DROPPED) &&
                  phi >= 0.0 && phi <= 1.0 && v >= 0.0 && isfinite(v),
              ctx, FCM_ERR_INTERNAL,
              "embed: the classification handed over for cell %lld is invalid (class %d, "
              "fraction %g, volume %g)",
              (long long)c, cls, phi, v);
    /* as process_cell() leaves an unflagged cell: at most one piece (no cuts), no points */
    out[c].volume = v;
    FCM_TRY(ctx, cell_out_pieces(ctx, out + c, cls == FCM_CELL_DROPPED ? 0 : 1));
    if (out[c].np == 1) {
      out[c].pc[0].volume = v;
      out[c].pc[0].parent = 0;
    }
  }
cleanup:
  fcm__free(ctx, volume);
  return st;
}

/* The build shared by fcm_cell_rules_create() and fcm_cell_rules_create_cut(): R (from
 * rules_alloc, with its cut triangles set) is filled; `prev` (or NULL) is the object being
 * extended by the triangles from first_new on. With x (distributed classification, no cuts):
 * the cells of x->remote are skipped and their classes taken from x->exchange, before the
 * AUTO choice (red). */
static fcm_status build_rules_x(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                const fcm_cell_rules *prev, fcm_index first_new,
                                fcm__rules_reduce *red, fcm_cell_rules *R,
                                const fcm__rules_exchange *x, int *exchanged)
{
  fcm_status st = FCM_OK;
  const fcm_cell_rules_options *o = &R->opts;
  build B;
  cell_out *out = NULL;
  cell_sums sums;
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  memset(&B, 0, sizeof B);
  const double t_start = fcm_wtime();
  for (fcm_index c = 0; c < nc; c++)
    FCM_TRY(ctx, check_convex(ctx, mesh, c, o));

  /* 1. set-up */
  FCM_TRY(ctx, build_setup(ctx, mesh, geom, o, R, &B));
  B.prev = prev;
  B.first_new = first_new;
  B.red = red;
  B.remote = x ? x->remote : NULL;
  if (R->num_cut_tris > 0) FCM_TRY(ctx, cut_setup(&B, R, first_new));
  FCM_ALLOC(ctx, (size_t)nc, out);
  const double t_setup = fcm_wtime();
  /* 2. parallel per-cell work */
  const int nthreads = fcm_ctx_num_threads(ctx);
  FCM_TRY(ctx, run_cells(&B, R, nthreads, out, &sums, o));
  if (x) FCM_TRY(ctx, exchange_classes(&B, R, x, out, &sums, exchanged));
  if (o->simplify == FCM_CELL_SIMPLIFY_AUTO)
    FCM_TRY(ctx, auto_simplify(&B, R, nthreads, out, &sums));
  const double t_loop = fcm_wtime();
  /* 3. gather, 4. statistics */
  FCM_TRY(ctx, gather_rules(ctx, R, out, prev));
  if (B.cut_tree) FCM_TRY(ctx, gather_links(&B, R, out));
  gather_stats(R, geom, out, &sums, nthreads);
  FCM_TRY(ctx, fcm__embed_outside(ctx, mesh, geom, &R->stats));
  if (o->simplify != FCM_CELL_SIMPLIFY_AUTO)
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
      R->stats.decision[k].simplified =
          o->simplify == FCM_CELL_SIMPLIFY_ON && KIND_BUILT(o->kinds, k);
  R->stats.num_integrated = nc;
  if (B.rebuild) {
    R->stats.num_integrated = 0;
    for (fcm_index c = 0; c < nc; c++)
      R->stats.num_integrated += B.rebuild[c];
  }
  R->stats.time_setup = t_setup - t_start;
  R->stats.time_gather = fcm_wtime() - t_loop;
  R->stats.time_total = fcm_wtime() - t_start;
cleanup:
  if (out)
    for (fcm_index c = 0; c < nc; c++)
      cell_out_free(ctx, out + c);
  fcm__free(ctx, out);
  build_release(&B);
  return st;
}

static fcm_status build_rules(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                              const fcm_cell_rules *prev, fcm_index first_new,
                              fcm__rules_reduce *red, fcm_cell_rules *R)
{
  int exchanged = 0;
  return build_rules_x(ctx, mesh, geom, prev, first_new, red, R, NULL, &exchanged);
}

/* fcm_cell_rules_create() with the AUTO choice's reduce (red) and the distributed
 * classification (x), each NULL when not used. */
static fcm_status create_rules(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                               const fcm_cell_rules_options *opts, fcm__rules_reduce *red,
                               const fcm__rules_exchange *x, fcm_cell_rules **rules)
{
  fcm_status st = FCM_OK;
  fcm_cell_rules *R = NULL;
  int exchanged = 0;
  const fcm_cell_rules_options o = opts ? *opts : fcm_cell_rules_options_default();
  if (red) red->called = 0;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "embed: output pointer is NULL");
  *rules = NULL;
  FCM_CHECK(ctx && mesh && geom, ctx, FCM_ERR_ARG,
            "embed: NULL argument (ctx, mesh and geometry are required)");
  FCM_CHECK(!red || red->fn, ctx, FCM_ERR_ARG, "embed: a reduce without a function");
  FCM_TRY(ctx, check_options(ctx, &o, red != NULL));
  FCM_CHECK(!x || (x->remote && x->exchange), ctx, FCM_ERR_ARG,
            "embed: distributed classification without a remote mask or exchange function");
  FCM_CHECK(!x || red || o.simplify != FCM_CELL_SIMPLIFY_AUTO, ctx, FCM_ERR_ARG,
            "embed: distributed classification with simplify = auto and no reduce: the choice "
            "would depend on the distribution (use on or off)");
  for (fcm_index c = 0; x && o.cell_mask && c < fcm_mesh_num_cells(mesh); c++)
    FCM_CHECK(!(o.cell_mask[c] && x->remote[c]), ctx, FCM_ERR_ARG,
              "embed: cell %lld is flagged in the cell_mask (this process integrates it) and as "
              "classified by another process",
              (long long)c);
  FCM_TRY(ctx, rules_alloc(ctx, mesh, &o, &R));
  FCM_TRY(ctx, build_rules_x(ctx, mesh, geom, NULL, 0,
                             o.simplify == FCM_CELL_SIMPLIFY_AUTO ? red : NULL, R, x, &exchanged));
  R->masked = o.cell_mask != NULL;
  if (R->masked) {
    const fcm_index nc = fcm_mesh_num_cells(mesh);
    FCM_ALLOC(ctx, (size_t)nc + 1, R->own);
    memcpy(R->own, o.cell_mask, (size_t)nc);
  }
  R->opts.cell_mask = NULL; /* borrowed for the call only */
  *rules = R;
  R = NULL;
cleanup:
  /* failed before the exchange or the choice: meet the other processes there, in the order
   * they call them (the exchange first) */
  if (x && !exchanged)
    st = x->exchange(x->user, st != FCM_OK ? st : FCM_ERR_INTERNAL, NULL, NULL, NULL, NULL);
  if (red && red->fn && !red->called && o.simplify == FCM_CELL_SIMPLIFY_AUTO) {
    red->called = 1;
    st = red->fn(red->user, st, NULL, 0);
  }
  fcm_cell_rules_destroy(&R);
  if (st != FCM_OK && rules) fcm_cell_rules_destroy(rules);
  return st;
}

fcm_status fcm_cell_rules_create(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                 const fcm_cell_rules_options *opts, fcm_cell_rules **rules)
{
  return create_rules(ctx, mesh, geom, opts, NULL, NULL, rules);
}

fcm_status fcm__cell_rules_create_reduced(fcm_ctx *ctx, const fcm_mesh *mesh,
                                          const fcm_geometry *geom,
                                          const fcm_cell_rules_options *opts,
                                          fcm__rules_reduce *red, fcm_cell_rules **rules)
{
  return create_rules(ctx, mesh, geom, opts, red, NULL, rules);
}

fcm_status fcm__cell_rules_create_distributed(fcm_ctx *ctx, const fcm_mesh *mesh,
                                              const fcm_geometry *geom,
                                              const fcm_cell_rules_options *opts,
                                              fcm__rules_reduce *red, const fcm__rules_exchange *x,
                                              fcm_cell_rules **rules)
{
  return create_rules(ctx, mesh, geom, opts, red, x, rules);
}

#define CUT_ATTEMPTS 4

/* The mean cell size: the cube root of the mesh's bounding-box volume per cell (its longest
 * side per cell for a flat box). */
static double mean_cell_size(const fcm_mesh *mesh)
{
  const double *X = fcm_mesh_coords(mesh);
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (fcm_index i = 0; i < fcm_mesh_num_nodes(mesh); i++)
    for (int d = 0; d < 3; d++)
      lo[d] = fmin(lo[d], X[3 * i + d]), hi[d] = fmax(hi[d], X[3 * i + d]);
  const double n = (double)fcm_mesh_num_cells(mesh);
  const double v = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  const double side = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  return v > 0.0 ? cbrt(v / n) : side / n;
}

fcm_status fcm_cell_rules_create_cut(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                     const fcm_cell_rules *prev, const fcm_surface *cut,
                                     fcm_cell_rules **rules)
{
  fcm_status st = FCM_OK;
  fcm_cell_rules *R = NULL;
  unsigned char *inner = NULL;
  fcm_index *ref = NULL;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "embed cut: output pointer is NULL");
  *rules = NULL;
  FCM_CHECK(ctx && mesh && geom && prev && cut, ctx, FCM_ERR_ARG,
            "embed cut: NULL argument (ctx, mesh, geometry, rules and cut are required)");
  FCM_CHECK(fcm_mesh_num_cells(mesh) == prev->num_cells &&
                fcm_mesh_element_type(mesh) == prev->type,
            ctx, FCM_ERR_ARG, "embed cut: the mesh (%lld cells) is not the rules' mesh (%lld)",
            (long long)fcm_mesh_num_cells(mesh), (long long)prev->num_cells);
  FCM_CHECK(prev->num_cuts < 1 << 20, ctx, FCM_ERR_UNSUPPORTED,
            "embed cut: %d cuts already (limit 2^20)", prev->num_cuts);
  FCM_TRY(ctx, fcm__embed_cut_check(ctx, cut, "embed cut"));
  const fcm_index nt = fcm_surface_num_triangles(cut);
  const double *x = fcm_surface_coords(cut);
  const fcm_index *tv = fcm_surface_triangles(cut);
  FCM_ALLOC(ctx, 3 * (size_t)nt + 1, inner);
  FCM_ALLOC(ctx, (size_t)nt + 1, ref);
  FCM_TRY(ctx, fcm__embed_cut_inner_edges(ctx, cut, inner, ref));
  /* A cut that meets the parts of some cell in a way the tolerances cannot resolve (the
   * splitting changes their volume) is shifted by a small deterministic translation and
   * applied again: 1e-7, 1e-6, then 1e-5 of the mean cell size, along a fixed direction
   * with no rational relation to the axes. */
  const double h = mean_cell_size(mesh);
  static const double dir[3] = {0.4636476090008061, 0.5880026035475675, 0.6628738660715610};
  static const double shift[CUT_ATTEMPTS] = {0.0, 1e-7, 1e-6, 1e-5};
  fcm_index degenerate = 0;
  for (int attempt = 0; attempt < CUT_ATTEMPTS; attempt++) {
    fcm_cell_rules_destroy(&R);
    FCM_TRY(ctx, rules_alloc(ctx, mesh, &prev->opts, &R));
    FCM_ALLOC(ctx, (size_t)(prev->num_cut_tris + nt), R->cut_tris);
    if (prev->num_cut_tris)
      memcpy(R->cut_tris, prev->cut_tris, (size_t)prev->num_cut_tris * sizeof *R->cut_tris);
    R->num_cut_tris = prev->num_cut_tris;
    const double d = shift[attempt] * h;
    for (fcm_index t = 0; t < nt; t++) {
      double v[3][3], w[3][3];
      for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++) {
          v[k][j] = x[3 * tv[3 * t + k] + j] + d * dir[j];
          w[k][j] = x[3 * tv[3 * ref[t] + k] + j] + d * dir[j];
        }
      R->num_cut_tris += fcm__embed_cut_tri_setup(v[0], v[1], v[2], prev->num_cuts, inner + 3 * t,
                                                  &w[0][0], R->cut_tris + R->num_cut_tris);
    }
    R->num_cuts = prev->num_cuts + 1;
    R->prev_num_pieces = prev->num_pieces;
    /* rules built with a cell_mask: the same cells get points (the others are classified,
     * split and get their cut faces: the same pieces and DOF copies on every process) */
    R->opts.cell_mask = prev->own;
    st = build_rules(ctx, mesh, geom, prev, prev->num_cut_tris, NULL, R);
    R->opts.cell_mask = NULL;
    FCM_TRY(ctx, st);
    degenerate = R->stats.num_degenerate;
    for (int j = 0; j < 3; j++)
      R->stats.cut_shift[j] = d * dir[j];
    R->stats.cut_attempts = attempt + 1;
    if (degenerate == 0) break;
  }
  if (prev->masked) {
    R->masked = 1;
    FCM_ALLOC(ctx, (size_t)prev->num_cells + 1, R->own);
    memcpy(R->own, prev->own, (size_t)prev->num_cells);
  }
  FCM_CHECK(degenerate == 0, ctx, FCM_ERR_GEOMETRY,
            "embed cut: the cut meets %lld cell(s) in a degenerate way that shifts of up to %g "
            "(1e-5 of the mean cell size %g) did not resolve: splitting them changes their "
            "volume; move the cut",
            (long long)degenerate, shift[CUT_ATTEMPTS - 1] * h, h);
  *rules = R;
  R = NULL;
cleanup:
  fcm__free(ctx, inner);
  fcm__free(ctx, ref);
  fcm_cell_rules_destroy(&R);
  return st;
}

void fcm_cell_rules_destroy(fcm_cell_rules **rules)
{
  if (!rules || !*rules) return;
  fcm_cell_rules *R = *rules;
  fcm_ctx *ctx = R->ctx;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    fcm__free(ctx, R->off[k]);
    fcm__free(ctx, R->points[k]);
    fcm__free(ctx, R->weights[k]);
    fcm__free(ctx, R->flags[k]);
    fcm_rule_destroy(&R->uncut[k]);
    fcm__free(ctx, R->uncut_flags[k]);
  }
  fcm__free(ctx, R->cls);
  fcm__free(ctx, R->own);
  fcm__free(ctx, R->fraction);
  fcm__free(ctx, R->piece_off);
  fcm__free(ctx, R->piece_cell);
  fcm__free(ctx, R->piece_volume);
  fcm__free(ctx, R->piece_parent);
  fcm__free(ctx, R->piece_component);
  fcm__free(ctx, R->cut_tris);
  fcm__free(ctx, R->links);
  fcm__free(ctx, R->reached);
  fcm__free(ctx, R->soff);
  fcm__free(ctx, R->cfoff);
  fcm__free(ctx, R->cfxi);
  fcm__free(ctx, R->spoints);
  fcm__free(ctx, R->sweights);
  fcm__free(ctx, R->snormals);
  fcm__free(ctx, R->stris);
  fcm__free(ctx, R);
  *rules = NULL;
}

fcm_index fcm_cell_rules_num_cells(const fcm_cell_rules *rules)
{
  return rules->num_cells;
}
fcm_element_type fcm_cell_rules_element_type(const fcm_cell_rules *rules)
{
  return rules->type;
}
int fcm_cell_rules_surface_strength(const fcm_cell_rules *rules)
{
  return rules->surface_strength;
}

int fcm_cell_rules_has_kind(const fcm_cell_rules *rules, fcm_rule_kind kind)
{
  return rules && (int)kind >= 0 && kind < FCM_RULE_KIND_COUNT && rules->uncut[kind] != NULL;
}

/* FCM_ERR_ARG (set on ctx) unless the rules of `kind` were built; `what` names the caller. */
static fcm_status check_kind(const fcm_cell_rules *R, fcm_rule_kind kind, const char *what)
{
  fcm_status st = FCM_OK;
  FCM_CHECK((int)kind >= 0 && kind < FCM_RULE_KIND_COUNT, R->ctx, FCM_ERR_ARG,
            "%s: kind %d out of range [0,%d)", what, (int)kind, (int)FCM_RULE_KIND_COUNT);
  FCM_CHECK(R->uncut[kind], R->ctx, FCM_ERR_ARG,
            "%s: no %s rules were built (fcm_cell_rules_options.kinds = 0x%x lacks "
            "FCM_RULES_%s = 0x%x; request them when creating the rules)",
            what, fcm_rule_kind_name(kind), R->stats.kinds,
            kind == FCM_RULE_MASS ? "MASS" : "STIFFNESS", 1u << (unsigned)kind);
cleanup:
  return st;
}

int fcm_cell_rules_strength(const fcm_cell_rules *rules, fcm_rule_kind kind)
{
  return (int)kind >= 0 && kind < FCM_RULE_KIND_COUNT ? rules->strength[kind] : -1;
}

fcm_cell_class fcm_cell_rules_class(const fcm_cell_rules *rules, fcm_index cell)
{
  if (cell < 0 || cell >= rules->num_cells) return FCM_CELL_DROPPED;
  return (fcm_cell_class)rules->cls[cell];
}

double fcm_cell_rules_volume_fraction(const fcm_cell_rules *rules, fcm_index cell)
{
  if (cell < 0 || cell >= rules->num_cells) return 0.0;
  return rules->fraction[cell];
}

/* The volume rule of kind k over the pieces [p0, p1) of a cell of class cls: the catalogue
 * rule for an uncut cell, else the stored points of those pieces (consecutive). */
static void rule_range(const fcm_cell_rules *R, fcm_cell_class cls, fcm_rule_kind k, fcm_index p0,
                       fcm_index p1, int *n, const double **p, const double **w,
                       const unsigned char **f)
{
  *n = 0, *p = *w = NULL, *f = NULL;
  if (cls == FCM_CELL_UNCUT) {
    *n = fcm_rule_num_points(R->uncut[k]);
    *p = fcm_rule_points(R->uncut[k]);
    *w = fcm_rule_weights(R->uncut[k]);
    *f = R->uncut_flags[k];
  } else if (cls == FCM_CELL_CUT) {
    const fcm_index o0 = R->off[k][p0];
    *n = (int)(R->off[k][p1] - o0);
    *p = R->points[k] + 3 * o0;
    *w = R->weights[k] + o0;
    *f = R->flags[k] + o0;
  }
}

fcm_status fcm_cell_rules_get(const fcm_cell_rules *rules, fcm_index cell, fcm_rule_kind kind,
                              int *num_points, const double **points, const double **weights,
                              const unsigned char **flags)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  int n = 0;
  const double *p = NULL, *w = NULL;
  const unsigned char *f = NULL;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(cell >= 0 && cell < rules->num_cells, ctx, FCM_ERR_ARG,
            "cell rules: cell %lld out of range [0,%lld)", (long long)cell,
            (long long)rules->num_cells);
  FCM_TRY(ctx, check_kind(rules, kind, "cell rules"));
  rule_range(rules, (fcm_cell_class)rules->cls[cell], kind, rules->piece_off[cell],
             rules->piece_off[cell + 1], &n, &p, &w, &f);
cleanup:
  if (num_points) *num_points = n;
  if (points) *points = p;
  if (weights) *weights = w;
  if (flags) *flags = f;
  return st;
}

/* The surface points [s0, s1) into the outputs (each may be NULL; NULL pointers and 0 points
 * when empty or R is NULL). */
static void surface_range(const fcm_cell_rules *R, fcm_index s0, fcm_index s1, int *num_points,
                          const double **points, const double **weights, const double **normals,
                          const fcm_index **triangles)
{
  const int n = R ? (int)(s1 - s0) : 0;
  if (num_points) *num_points = n;
  if (points) *points = n ? R->spoints + 3 * s0 : NULL;
  if (weights) *weights = n ? R->sweights + s0 : NULL;
  if (normals) *normals = n ? R->snormals + 3 * s0 : NULL;
  if (triangles) *triangles = n ? R->stris + s0 : NULL;
}

fcm_status fcm_cell_rules_get_surface(const fcm_cell_rules *rules, fcm_index cell, int *num_points,
                                      const double **points, const double **weights,
                                      const double **normals, const fcm_index **triangles)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  fcm_index s0 = 0, s1 = 0;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(cell >= 0 && cell < rules->num_cells, ctx, FCM_ERR_ARG,
            "cell rules: cell %lld out of range [0,%lld)", (long long)cell,
            (long long)rules->num_cells);
  s0 = rules->soff[rules->piece_off[cell]];
  s1 = rules->soff[rules->piece_off[cell + 1]];
cleanup:
  surface_range(rules, s0, s1, num_points, points, weights, normals, triangles);
  return st;
}

fcm_index fcm_cell_rules_num_pieces(const fcm_cell_rules *rules)
{
  return rules ? rules->num_pieces : 0;
}

fcm_index fcm_cell_rules_cell_pieces(const fcm_cell_rules *rules, fcm_index cell, fcm_index *first)
{
  if (!rules || cell < 0 || cell >= rules->num_cells) {
    if (first) *first = 0;
    return 0;
  }
  if (first) *first = rules->piece_off[cell];
  return rules->piece_off[cell + 1] - rules->piece_off[cell];
}

fcm_index fcm_cell_rules_piece_cell(const fcm_cell_rules *rules, fcm_index piece)
{
  if (!rules || piece < 0 || piece >= rules->num_pieces) return -1;
  return rules->piece_cell[piece];
}

double fcm_cell_rules_piece_volume(const fcm_cell_rules *rules, fcm_index piece)
{
  if (!rules || piece < 0 || piece >= rules->num_pieces) return 0.0;
  return rules->piece_volume[piece];
}

fcm_status fcm_cell_rules_get_piece(const fcm_cell_rules *rules, fcm_index piece,
                                    fcm_rule_kind kind, int *num_points, const double **points,
                                    const double **weights, const unsigned char **flags)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  int n = 0;
  const double *p = NULL, *w = NULL;
  const unsigned char *f = NULL;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(piece >= 0 && piece < rules->num_pieces, ctx, FCM_ERR_ARG,
            "cell rules: piece %lld out of range [0,%lld)", (long long)piece,
            (long long)rules->num_pieces);
  FCM_TRY(ctx, check_kind(rules, kind, "cell rules"));
  rule_range(rules, (fcm_cell_class)rules->cls[rules->piece_cell[piece]], kind, piece, piece + 1,
             &n, &p, &w, &f);
cleanup:
  if (num_points) *num_points = n;
  if (points) *points = n ? p : NULL;
  if (weights) *weights = n ? w : NULL;
  if (flags) *flags = n ? f : NULL;
  return st;
}

fcm_status fcm_cell_rules_get_piece_surface(const fcm_cell_rules *rules, fcm_index piece,
                                            int *num_points, const double **points,
                                            const double **weights, const double **normals,
                                            const fcm_index **triangles)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  fcm_index s0 = 0, s1 = 0;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(piece >= 0 && piece < rules->num_pieces, ctx, FCM_ERR_ARG,
            "cell rules: piece %lld out of range [0,%lld)", (long long)piece,
            (long long)rules->num_pieces);
  s0 = rules->soff[piece];
  s1 = rules->soff[piece + 1];
cleanup:
  surface_range(rules, s0, s1, num_points, points, weights, normals, triangles);
  return st;
}

fcm_index fcm_cell_rules_piece_parent(const fcm_cell_rules *rules, fcm_index piece)
{
  if (!rules || piece < 0 || piece >= rules->num_pieces) return -1;
  return rules->piece_parent[piece];
}

fcm_index fcm_cell_rules_parent_num_pieces(const fcm_cell_rules *rules)
{
  return rules ? rules->prev_num_pieces : 0;
}

fcm_index fcm_cell_rules_get_piece_cut_faces(const fcm_cell_rules *rules, fcm_index piece,
                                             const double **xi)
{
  if (!rules || piece < 0 || piece >= rules->num_pieces) {
    if (xi) *xi = NULL;
    return 0;
  }
  const fcm_index n = rules->cfoff[piece + 1] - rules->cfoff[piece];
  if (xi) *xi = n ? rules->cfxi + 9 * rules->cfoff[piece] : NULL;
  return n;
}

fcm_index fcm_cell_rules_num_links(const fcm_cell_rules *rules)
{
  return rules ? rules->num_links : 0;
}

const fcm_index *fcm_cell_rules_links(const fcm_cell_rules *rules)
{
  return rules ? rules->links : NULL;
}

int fcm_cell_rules_num_cuts(const fcm_cell_rules *rules)
{
  return rules ? rules->num_cuts : 0;
}

const fcm_cell_rules_stats *fcm_cell_rules_get_stats(const fcm_cell_rules *rules)
{
  return &rules->stats;
}

void fcm_cell_rules_view(const fcm_cell_rules *rules, FILE *stream)
{
  if (!rules || !stream) return;
  const fcm_cell_rules_stats *S = &rules->stats;
  static const char *names[FCM_RULE_KIND_COUNT] = {"stiffness", "mass"};
  fprintf(stream,
          "cell rules: %s, %lld cells: %lld uncut, %lld cut, %lld dropped (%d threads)\n"
          "  candidates %lld, convex parts %lld, tets %lld, slivers dropped %lld (volume %.3g)\n"
          "  embedded volume %.17g (geometry %.17g, in dropped cells %.3g)\n",
          fcm_element_get_info(rules->type)->name, (long long)S->num_cells, (long long)S->num_uncut,
          (long long)S->num_cut, (long long)S->num_dropped, S->num_threads,
          (long long)S->num_candidates, (long long)S->num_parts, (long long)S->num_tets,
          (long long)S->num_slivers, S->sliver_volume, S->embedded_volume, S->geometry_volume,
          S->dropped_volume);
  fprintf(stream, "  embedded / geometry volume %.6f; outside the background mesh %.3g",
          S->volume_ratio, S->outside_volume);
  static const char *const sides[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  for (int k = 0; k < 6; k++)
    if (S->outside_side_volume[k] > 0.0)
      fprintf(stream, ", beyond %s %.3g", sides[k], S->outside_side_volume[k]);
  fputc('\n', stream);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    if (!rules->uncut[k])
      fprintf(stream, "  %-9s not built (fcm_cell_rules_options.kinds)\n", names[k]);
    else
      fprintf(
          stream,
          "  %-9s strength %d: cut-cell points %lld initial -> %lld simplified "
          "(+%lld stabilization), total %lld; skipped %lld, fallbacks %lld, max residual %.3g\n",
          names[k], rules->strength[k], (long long)S->points_initial[k],
          (long long)S->points_simplified[k], (long long)S->points_stabilization[k],
          (long long)S->points_total[k], (long long)S->simplify_skipped[k],
          (long long)S->simplify_fallbacks[k], S->max_residual[k]);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    const fcm_simplify_decision *d = &S->decision[k];
    if (d->point_cost > 0.0)
      fprintf(stream,
              "  %-9s simplify auto: %s for %g assemblies (%.3g core-s per point): estimated "
              "%.3g core-s simplifying to %.0f points; assembly %.3g core-s plain vs %.3g "
              "simplify + assembly\n",
              names[k], d->simplified ? "on" : "off", d->expected_assemblies, d->point_cost,
              d->estimated_time, d->estimated_kept, d->cost_plain, d->cost_simplified);
  }
  if (rules->surface_strength >= 0)
    fprintf(stream, "  surface strength %d: %lld triangles, %lld points, area %.17g\n",
            rules->surface_strength, (long long)S->surface_triangles, (long long)S->surface_points,
            S->embedded_area);
  fprintf(stream,
          "  time: setup %.3g s, intersect %.3g core-s, simplify %.3g core-s, gather %.3g s, "
          "total %.3g s\n",
          S->time_setup, S->time_intersect, S->time_simplify, S->time_gather, S->time_total);
}

fcm_status fcm_cell_rules_view_points(const fcm_cell_rules *rules, const fcm_mesh *mesh,
                                      fcm_rule_kind kind, FILE *stream)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], x[3];
  FCM_CHECK(rules && mesh && stream, ctx, FCM_ERR_ARG,
            "cell rules view: NULL argument (rules, mesh and stream are required)");
  FCM_TRY(ctx, check_kind(rules, kind, "cell rules view"));
  FCM_CHECK(fcm_mesh_num_cells(mesh) == rules->num_cells &&
                fcm_mesh_element_type(mesh) == rules->type,
            ctx, FCM_ERR_ARG, "cell rules view: mesh (%lld cells) is not the rules' mesh (%lld)",
            (long long)fcm_mesh_num_cells(mesh), (long long)rules->num_cells);
  FCM_CHECK(fprintf(stream, "# cell xi eta zeta X Y Z w_ref w_phys flag\n") > 0, ctx, FCM_ERR_IO,
            "cell rules view: write failed");
  for (fcm_index c = 0; c < rules->num_cells; c++) {
    int n;
    const double *p, *w;
    const unsigned char *f;
    FCM_TRY(ctx, fcm_cell_rules_get(rules, c, kind, &n, &p, &w, &f));
    if (!n) continue;
    fcm_mesh_cell_coords(mesh, c, X);
    for (int j = 0; j < n; j++) {
      fcm_element_map(rules->type, X, p + 3 * j, x);
      const double det = fcm_element_jacobian(rules->type, X, p + 3 * j, J);
      FCM_CHECK(fprintf(stream, "%lld %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %d\n",
                        (long long)c, p[3 * j], p[3 * j + 1], p[3 * j + 2], x[0], x[1], x[2], w[j],
                        w[j] * det, (int)f[j]) > 0,
                ctx, FCM_ERR_IO, "cell rules view: write failed");
    }
  }
cleanup:
  return st;
}
