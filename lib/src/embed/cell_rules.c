/* Per-background-cell rule storage: the parallel build (intersect, classify, simplify,
 * stabilize, per cell into private buffers, then gathered in cell order), accessors,
 * statistics and the point dump. */
#include "embed/embed_impl.h"
#include "element/element_impl.h"

#include <math.h>
#include <omp.h>
#include <string.h>

#define GIB (1024.0 * 1024.0 * 1024.0)

fcm_cell_rules_options fcm_cell_rules_options_default(void)
{
  fcm_cell_rules_options o;
  memset(&o, 0, sizeof o);
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
  o.num_threads = FCM_DEFAULT;
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

/* What one cell produced (private to the thread that built it). */
typedef struct cell_out {
  int n[FCM_RULE_KIND_COUNT];
  double *pts[FCM_RULE_KIND_COUNT];
  double *w[FCM_RULE_KIND_COUNT];
  unsigned char *flag[FCM_RULE_KIND_COUNT];
  int ninit[FCM_RULE_KIND_COUNT], nsimp[FCM_RULE_KIND_COUNT], nstab[FCM_RULE_KIND_COUNT];
  unsigned char skipped[FCM_RULE_KIND_COUNT], fallback[FCM_RULE_KIND_COUNT];
  double residual[FCM_RULE_KIND_COUNT];
  double tsimp[FCM_RULE_KIND_COUNT]; /* fcm_simplify's time_total */
  int ns;
  double *spts, *sw, *snrm;
  fcm_index *stri;
  double volume;
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
} build;

/* What one thread summed over the cells it built. */
typedef struct cell_sums {
  fcm__embed_counts counts;
  double time_intersect, time_simplify; /* seconds of one core */
} cell_sums;

static void cell_out_free(fcm_ctx *ctx, cell_out *o)
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
  o->spts = o->sw = o->snrm = NULL;
  o->stri = NULL;
}

/* The one call into the simplification module: reduce the rule (n points, in place) to
 * at most M points; record skipped / fallback / residual. */
static fcm_status simplify_rule(fcm_ctx *ctx, const fcm_simplify_options *opts, int strength,
                                int *n, double *pts, double *w, cell_out *o, int k)
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
    n[k] = ws->num_tets * (size_t)fcm_rule_num_points(B->tet_rule[k]) +
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

/* The last step of a cut cell: simplify the kinds with simp[k] set, then append the
 * stabilization points. */
static fcm_status finish_cell(const build *B, const fcm_cell_rules *R, cell_out *o,
                              const int simp[FCM_RULE_KIND_COUNT], cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  const double t1 = fcm_wtime();
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
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

/* Intersect, classify and build the rules of background cell c into o (the thread's own
 * buffers); R->cls[c] and R->fraction[c] are written here (one writer per cell). */
static fcm_status process_cell(const build *B, fcm_cell_rules *R, fcm_index c, fcm__embed_ws *ws,
                               cell_out *o, cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  fcm__embed_cell cell;
  double vol = 0.0;
  const double t0 = fcm_wtime();
  FCM_TRY(ctx, fcm__embed_cell_setup(ctx, B->mesh, c, opt->clip_rtol, &cell));
  FCM_TRY(ctx, fcm__embed_cell_tets(ctx, B->geom, B->tree, &cell, opt->clip_rtol, opt->sliver_rtol,
                                    ws, &sums->counts, &vol));
  /* |K ∩ Ω| <= |K|: the clipped volumes can sum to |K| (1 + 1e-12) through rounding. A cut
   * cell has phi < uncut_fraction <= 1, so its rule needs no rescaling; only the recorded
   * fraction and volume are clamped. */
  const double phi = fmin(vol / cell.volume, 1.0);
  fcm_cell_class cls = FCM_CELL_CUT;
  if (phi >= opt->uncut_fraction)
    cls = FCM_CELL_UNCUT;
  else if (phi < opt->min_fraction || ws->num_tets == 0)
    cls = FCM_CELL_DROPPED;
  R->cls[c] = (unsigned char)cls;
  R->fraction[c] = phi;
  o->volume = phi * cell.volume;
  if (cls == FCM_CELL_CUT) {
    FCM_TRY(ctx, check_rule_memory(B, R, &cell, ws));
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const size_t n0 = ws->num_tets * (size_t)fcm_rule_num_points(B->tet_rule[k]);
      const size_t ns = B->stabilize[k] ? (size_t)fcm_rule_num_points(B->full_rule[k]) : 0;
      FCM_ALLOC(ctx, 3 * (n0 + ns), o->pts[k]);
      FCM_ALLOC(ctx, n0 + ns, o->w[k]);
      FCM_ALLOC(ctx, n0 + ns, o->flag[k]);
      FCM_TRY(ctx, fcm__embed_map_tets(ctx, &cell, ws, B->tet_rule[k], o->pts[k], o->w[k]));
      o->n[k] = o->ninit[k] = o->nsimp[k] = (int)n0;
    }
  }
  if (B->tri_rule && cls != FCM_CELL_DROPPED) {
    FCM_TRY(ctx, fcm__embed_cell_surface(ctx, B->geom, B->tri_tree, &cell, opt->sliver_rtol,
                                         B->tri_rule, ws, &sums->counts));
    const size_t ns = ws->num_spts;
    if (ns > 0) {
      FCM_ALLOC(ctx, 3 * ns, o->spts);
      FCM_ALLOC(ctx, ns, o->sw);
      FCM_ALLOC(ctx, 3 * ns, o->snrm);
      FCM_ALLOC(ctx, ns, o->stri);
      for (size_t j = 0; j < ns; j++) {
        double det;
        FCM_TRY(ctx, fcm__embed_to_reference(ctx, &cell, ws->spts + 3 * j, o->spts + 3 * j, &det));
      }
      memcpy(o->sw, ws->sw, ns * sizeof *o->sw);
      memcpy(o->snrm, ws->snrm, 3 * ns * sizeof *o->snrm);
      memcpy(o->stri, ws->stri, ns * sizeof *o->stri);
      o->ns = (int)ns;
    }
  }
  sums->time_intersect += fcm_wtime() - t0;
  if (cls == FCM_CELL_CUT && opt->simplify != FCM_CELL_SIMPLIFY_AUTO) {
    const int on = opt->simplify == FCM_CELL_SIMPLIFY_ON;
    const int simp[FCM_RULE_KIND_COUNT] = {on, on};
    FCM_TRY(ctx, finish_cell(B, R, o, simp, sums));
  }
cleanup:
  return st;
}

static fcm_status check_options(fcm_ctx *ctx, const fcm_cell_rules_options *o)
{
  fcm_status st = FCM_OK;
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
            "embed: progress_interval = %g must be finite and >= 0 seconds",
            o->progress_interval);
  FCM_CHECK(o->max_rule_memory >= 0.0 && !isnan(o->max_rule_memory), ctx, FCM_ERR_ARG,
            "embed: max_rule_memory = %g bytes must be >= 0 (0: no limit)", o->max_rule_memory);
  FCM_CHECK(o->num_threads >= 1 || o->num_threads == FCM_DEFAULT, ctx, FCM_ERR_ARG,
            "embed: num_threads = %d must be >= 1, or FCM_DEFAULT (-1)", o->num_threads);
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
  FCM_ALLOC(ctx, (size_t)nc + 1, R->soff);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    R->strength[k] = o->strength[k] >= 0 ? o->strength[k] : element_strength[k];
    FCM_TRY(ctx, fcm_rule_create(ctx, info->shape, R->strength[k], &R->uncut[k]));
    FCM_ALLOC(ctx, (size_t)fcm_rule_num_points(R->uncut[k]), R->uncut_flags[k]);
    FCM_ALLOC(ctx, (size_t)nc + 1, R->off[k]);
  }
  *out = R;
  R = NULL;
cleanup:
  fcm_cell_rules_destroy(&R);
  return st;
}

static void build_release(build *B)
{
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
    FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_TET, R->strength[k], &B->tet_rule[k]));
    B->full_rule[k] = R->uncut[k];
  }
  B->stabilize[FCM_RULE_STIFFNESS] = o->stabilization.mode == FCM_STABILIZATION_MASS_STIFFNESS;
  B->stabilize[FCM_RULE_MASS] = o->stabilization.mode != FCM_STABILIZATION_OFF;
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
      if (s == FCM_OK) s = process_cell(B, R, c, ws, out + c, &mine);
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
      sums->counts.pieces += mine.counts.pieces;
      sums->counts.tets += mine.counts.tets;
      sums->counts.slivers += mine.counts.slivers;
      sums->counts.surface_triangles += mine.counts.surface_triangles;
      sums->counts.sliver_volume += mine.counts.sliver_volume;
      sums->time_intersect += mine.time_intersect;
      sums->time_simplify += mine.time_simplify;
    }
  }
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
  if (opt->progress) opt->progress(nc, nc, opt->progress_user);
cleanup:
  return st;
}

/* Finish the cut cells list[0 .. n) in parallel (simplify the kinds that pay, stabilize);
 * the error is the lowest failing one's. */
static fcm_status auto_finish(const build *B, const fcm_cell_rules *R, int nthreads, cell_out *out,
                              const fcm_index *list, fcm_index n,
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
      fcm_status s = finish_cell(B, R, out + list[i], simp, &mine);
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
 * simplified nor stabilized): per kind, the simplification time of every cut cell from the
 * deterministic model fcm_simplify_cost_estimate() and the points it would keep (min(N, M)),
 * against the assembly time of the points it removes over the expected assemblies
 * (fcm_simplify_pays()). The rules are then those of OFF or ON for each kind, and the same
 * inputs always give the same decision (no timing: runs, thread counts and resumed runs
 * agree). Then finish every cut cell. */
static fcm_status auto_simplify(const build *B, fcm_cell_rules *R, int nthreads, cell_out *out,
                                cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  const fcm_index nc = R->num_cells;
  fcm_index *cut = NULL, ncut = 0;
  int pays[FCM_RULE_KIND_COUNT] = {0, 0};
  for (fcm_index c = 0; c < nc; c++)
    ncut += R->cls[c] == FCM_CELL_CUT;
  FCM_ALLOC(ctx, (size_t)ncut + 1, cut);
  ncut = 0;
  for (fcm_index c = 0; c < nc; c++)
    if (R->cls[c] == FCM_CELL_CUT) cut[ncut++] = c;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    fcm_simplify_decision *d = &R->stats.decision[k];
    const fcm_element_type type = fcm_mesh_element_type(B->mesh);
    const int m = R->strength[k];
    const double M = (double)(m + 1) * (m + 2) * (m + 3) / 6.0;
    d->expected_assemblies = opt->expected_assemblies[k];
    d->point_cost =
        opt->point_cost[k] == FCM_DEFAULT ? fcm_cell_rules_point_cost(type, k) : opt->point_cost[k];
    double ntot = 0.0;
    for (fcm_index i = 0; i < ncut; i++) {
      const fcm_index n = out[cut[i]].ninit[k];
      ntot += (double)n;
      d->estimated_time += fcm_simplify_cost_estimate(m, n);
      d->estimated_kept += (double)n < M ? (double)n : M;
    }
    d->cost_plain = ntot * d->point_cost * d->expected_assemblies;
    d->cost_simplified =
        d->estimated_time + d->estimated_kept * d->point_cost * d->expected_assemblies;
    pays[k] = fcm_simplify_pays(d->expected_assemblies, d->point_cost, ntot, d->estimated_kept,
                                d->estimated_time);
  }
  FCM_TRY(ctx, auto_finish(B, R, nthreads, out, cut, ncut, pays, sums));
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    R->stats.decision[k].simplified = pays[k];
cleanup:
  fcm__free(ctx, cut);
  return st;
}

/* Phase 3: concatenate the cells' volume and surface rules in cell order. */
static fcm_status gather_rules(fcm_ctx *ctx, fcm_cell_rules *R, const cell_out *out)
{
  fcm_status st = FCM_OK;
  const fcm_index nc = R->num_cells;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    fcm_index *off = R->off[k];
    off[0] = 0;
    for (fcm_index c = 0; c < nc; c++)
      off[c + 1] = off[c] + out[c].n[k];
    const size_t tot = (size_t)off[nc];
    FCM_ALLOC(ctx, 3 * tot, R->points[k]);
    FCM_ALLOC(ctx, tot, R->weights[k]);
    FCM_ALLOC(ctx, tot, R->flags[k]);
    for (fcm_index c = 0; c < nc; c++) {
      const size_t n = (size_t)out[c].n[k], o0 = (size_t)off[c];
      if (!n) continue;
      memcpy(R->points[k] + 3 * o0, out[c].pts[k], 3 * n * sizeof(double));
      memcpy(R->weights[k] + o0, out[c].w[k], n * sizeof(double));
      memcpy(R->flags[k] + o0, out[c].flag[k], n);
    }
  }
  R->soff[0] = 0;
  for (fcm_index c = 0; c < nc; c++)
    R->soff[c + 1] = R->soff[c] + out[c].ns;
  const size_t tot = (size_t)R->soff[nc];
  FCM_ALLOC(ctx, 3 * tot, R->spoints);
  FCM_ALLOC(ctx, tot, R->sweights);
  FCM_ALLOC(ctx, 3 * tot, R->snormals);
  FCM_ALLOC(ctx, tot, R->stris);
  for (fcm_index c = 0; c < nc; c++) {
    const size_t n = (size_t)out[c].ns, o0 = (size_t)R->soff[c];
    if (!n) continue;
    memcpy(R->spoints + 3 * o0, out[c].spts, 3 * n * sizeof(double));
    memcpy(R->sweights + o0, out[c].sw, n * sizeof(double));
    memcpy(R->snormals + 3 * o0, out[c].snrm, 3 * n * sizeof(double));
    memcpy(R->stris + o0, out[c].stri, n * sizeof(fcm_index));
  }
cleanup:
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
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      S->points_initial[k] += o->ninit[k];
      S->points_simplified[k] += o->nsimp[k];
      S->points_stabilization[k] += o->nstab[k];
      S->simplify_skipped[k] += o->skipped[k];
      S->simplify_fallbacks[k] += o->fallback[k];
      S->max_residual[k] = fmax(S->max_residual[k], o->residual[k]);
      S->decision[k].time_simplify += o->tsimp[k];
    }
    for (int j = 0; j < o->ns; j++)
      S->embedded_area += o->sw[j];
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
    S->points_total[k] = R->off[k][nc] + S->num_uncut * fcm_rule_num_points(R->uncut[k]);
  S->surface_points = R->soff[nc];
  S->num_candidates = sums->counts.candidates;
  S->num_pieces = sums->counts.pieces;
  S->num_tets = sums->counts.tets;
  S->num_slivers = sums->counts.slivers;
  S->sliver_volume = sums->counts.sliver_volume;
  S->surface_triangles = sums->counts.surface_triangles;
  S->geometry_volume = fcm_geometry_volume(geom);
  S->num_threads = nthreads;
  S->time_intersect = sums->time_intersect;
  S->time_simplify = sums->time_simplify;
}

fcm_status fcm_cell_rules_create(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                 const fcm_cell_rules_options *opts, fcm_cell_rules **rules)
{
  fcm_status st = FCM_OK;
  fcm_cell_rules *R = NULL;
  const fcm_cell_rules_options o = opts ? *opts : fcm_cell_rules_options_default();
  build B;
  cell_out *out = NULL;
  cell_sums sums;
  fcm_index nc = 0;
  memset(&B, 0, sizeof B);
  const double t_start = fcm_wtime();
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "embed: output pointer is NULL");
  *rules = NULL;
  FCM_CHECK(ctx && mesh && geom, ctx, FCM_ERR_ARG,
            "embed: NULL argument (ctx, mesh and geometry are required)");
  FCM_TRY(ctx, check_options(ctx, &o));
  nc = fcm_mesh_num_cells(mesh);
  for (fcm_index c = 0; c < nc; c++)
    FCM_CHECK(fcm_mesh_cell_is_convex(mesh, c, o.convex_rtol), ctx, FCM_ERR_GEOMETRY,
              "embed: background cell %lld (%s) is not a convex polyhedron with planar faces and "
              "straight edges (relative tolerance %g); cut-cell quadrature needs convex cells",
              (long long)c, fcm_mesh_get_element_info(mesh)->name, o.convex_rtol);

  /* 1. set-up */
  FCM_TRY(ctx, rules_alloc(ctx, mesh, &o, &R));
  FCM_TRY(ctx, build_setup(ctx, mesh, geom, &o, R, &B));
  FCM_ALLOC(ctx, (size_t)nc, out);
  const double t_setup = fcm_wtime();
  /* 2. parallel per-cell work */
  const int nthreads = o.num_threads > 0 ? o.num_threads : omp_get_max_threads();
  FCM_TRY(ctx, run_cells(&B, R, nthreads, out, &sums, &o));
  if (o.simplify == FCM_CELL_SIMPLIFY_AUTO)
    FCM_TRY(ctx, auto_simplify(&B, R, nthreads, out, &sums));
  const double t_loop = fcm_wtime();
  /* 3. gather, 4. statistics */
  FCM_TRY(ctx, gather_rules(ctx, R, out));
  gather_stats(R, geom, out, &sums, nthreads);
  FCM_TRY(ctx, fcm__embed_outside(ctx, mesh, geom, &R->stats));
  if (o.simplify != FCM_CELL_SIMPLIFY_AUTO)
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
      R->stats.decision[k].simplified = o.simplify == FCM_CELL_SIMPLIFY_ON;
  R->stats.time_setup = t_setup - t_start;
  R->stats.time_gather = fcm_wtime() - t_loop;
  R->stats.time_total = fcm_wtime() - t_start;
  *rules = R;
  R = NULL;
cleanup:
  if (out)
    for (fcm_index c = 0; c < nc; c++)
      cell_out_free(ctx, out + c);
  fcm__free(ctx, out);
  build_release(&B);
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
  fcm__free(ctx, R->fraction);
  fcm__free(ctx, R->soff);
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
  FCM_CHECK((int)kind >= 0 && kind < FCM_RULE_KIND_COUNT, ctx, FCM_ERR_ARG,
            "cell rules: kind %d out of range [0,%d)", (int)kind, (int)FCM_RULE_KIND_COUNT);
  if (rules->cls[cell] == FCM_CELL_UNCUT) {
    n = fcm_rule_num_points(rules->uncut[kind]);
    p = fcm_rule_points(rules->uncut[kind]);
    w = fcm_rule_weights(rules->uncut[kind]);
    f = rules->uncut_flags[kind];
  } else if (rules->cls[cell] == FCM_CELL_CUT) {
    const fcm_index o0 = rules->off[kind][cell];
    n = (int)(rules->off[kind][cell + 1] - o0);
    p = rules->points[kind] + 3 * o0;
    w = rules->weights[kind] + o0;
    f = rules->flags[kind] + o0;
  }
cleanup:
  if (num_points) *num_points = n;
  if (points) *points = p;
  if (weights) *weights = w;
  if (flags) *flags = f;
  return st;
}

fcm_status fcm_cell_rules_get_surface(const fcm_cell_rules *rules, fcm_index cell, int *num_points,
                                      const double **points, const double **weights,
                                      const double **normals, const fcm_index **triangles)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  int n = 0;
  fcm_index o0 = 0;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(cell >= 0 && cell < rules->num_cells, ctx, FCM_ERR_ARG,
            "cell rules: cell %lld out of range [0,%lld)", (long long)cell,
            (long long)rules->num_cells);
  o0 = rules->soff[cell];
  n = (int)(rules->soff[cell + 1] - o0);
cleanup:
  if (num_points) *num_points = n;
  if (points) *points = n ? rules->spoints + 3 * o0 : NULL;
  if (weights) *weights = n ? rules->sweights + o0 : NULL;
  if (normals) *normals = n ? rules->snormals + 3 * o0 : NULL;
  if (triangles) *triangles = n ? rules->stris + o0 : NULL;
  return st;
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
          "  candidates %lld, pieces %lld, tets %lld, slivers dropped %lld (volume %.3g)\n"
          "  embedded volume %.17g (geometry %.17g, in dropped cells %.3g)\n",
          fcm_element_get_info(rules->type)->name, (long long)S->num_cells, (long long)S->num_uncut,
          (long long)S->num_cut, (long long)S->num_dropped, S->num_threads,
          (long long)S->num_candidates, (long long)S->num_pieces, (long long)S->num_tets,
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
    fprintf(stream,
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
  FCM_CHECK((int)kind >= 0 && kind < FCM_RULE_KIND_COUNT, ctx, FCM_ERR_ARG,
            "cell rules view: kind %d out of range [0,%d)", (int)kind, (int)FCM_RULE_KIND_COUNT);
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
