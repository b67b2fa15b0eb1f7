/* The phases of the cut-cell rules build around the per-cell work: options and convexity
 * checks, the result object, what every cell reads (rules, search trees), gathering the
 * cells' output in cell order and the statistics. */
#include "embed/rules_impl.h"
#include "simplify/simplify_impl.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

fcm_status fcm__embed_check_options(fcm_ctx *ctx, const fcm_cell_rules_options *o, int reduced)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(o->kinds != 0 && (o->kinds & ~(unsigned)FCM_RULES_ALL) == 0, ctx, FCM_ERR_ARG,
            "embed: kinds = 0x%x must be a non-empty set of FCM_RULES_STIFFNESS (0x%x) and "
            "FCM_RULES_MASS (0x%x)",
            o->kinds, FCM_RULES_STIFFNESS, FCM_RULES_MASS);
  FCM_CHECK((int)o->simplify >= 0 && o->simplify < FCM_CELL_SIMPLIFY_COUNT, ctx, FCM_ERR_ARG,
            "embed: simplify = %d is not a mode (0 off, 1 on, 2 auto)", (int)o->simplify);
  FCM_CHECK((int)o->moments >= 0 && o->moments < FCM_CELL_MOMENTS_COUNT, ctx, FCM_ERR_ARG,
            "embed: moments = %d is not a path (0 auto, 1 volume, 2 surface)", (int)o->moments);
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
  FCM_CHECK(o->stiffness_on_mass_space == 0 || o->stiffness_on_mass_space == 1, ctx, FCM_ERR_ARG,
            "embed: stiffness_on_mass_space = %d must be 0 or 1", o->stiffness_on_mass_space);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    FCM_CHECK(
        o->axis_degree[k] >= -1 && o->axis_degree[k] <= FCM_SIMPLIFY_MAX_STRENGTH, ctx, FCM_ERR_ARG,
        "embed: %s axis_degree = %d outside [0, %d] (-1: element default; >= strength: "
        "every polynomial of total degree <= strength)",
        k == FCM_RULE_MASS ? "mass" : "stiffness", o->axis_degree[k], FCM_SIMPLIFY_MAX_STRENGTH);
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

/* FCM_ERR_GEOMETRY when background cell c is not convex (the rules build's first check). */
fcm_status fcm__embed_check_convex(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_index c,
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

/* Kind k's strength and degree cap per variable (<= the strength) from the options and the
 * element's defaults: the element's cap only with the element's strength. */
static void kind_space(const fcm_element_info *info, const fcm_cell_rules_options *o, int k,
                       int *strength, int *axis)
{
  const int es = k == FCM_RULE_MASS ? info->mass_strength : info->stiffness_strength;
  const int ea = k == FCM_RULE_MASS ? info->mass_axis_degree : es;
  *strength = o->strength[k] >= 0 ? o->strength[k] : es;
  *axis = o->axis_degree[k] >= 0 ? o->axis_degree[k] : o->strength[k] >= 0 ? *strength : ea;
  *axis = FCM_MIN(*axis, *strength);
}

/* The rules objects' numbers (fcm_cell_rules.id), from 1. */
static atomic_ullong rules_ids = 1;

/* Phase 1a: the result object with its per-cell arrays, strengths and catalogue rules. */
fcm_status fcm__embed_rules_alloc(fcm_ctx *ctx, const fcm_mesh *mesh,
                                  const fcm_cell_rules_options *o, fcm_cell_rules **out)
{
  fcm_status st = FCM_OK;
  fcm_cell_rules *R = NULL;
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  FCM_ALLOC(ctx, 1, R);
  R->ctx = ctx;
  R->id = atomic_fetch_add(&rules_ids, 1);
  R->num_cells = nc;
  R->type = info->type;
  R->surface_strength = o->surface_strength;
  FCM_ALLOC(ctx, (size_t)nc, R->cls);
  FCM_ALLOC(ctx, (size_t)nc, R->fraction);
  FCM_ALLOC(ctx, (size_t)nc + 1, R->piece_off);
  R->opts = *o;
  R->stats.kinds = o->kinds;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    R->strength[k] = R->axis_degree[k] = -1;
    if (!KIND_BUILT(o->kinds, k)) continue;
    kind_space(info, o, k, &R->strength[k], &R->axis_degree[k]);
    FCM_TRY(ctx, fcm_rule_create(ctx, info->shape, R->strength[k], &R->uncut[k]));
    FCM_ALLOC(ctx, (size_t)fcm_rule_num_points(R->uncut[k]), R->uncut_flags[k]);
  }
  *out = R;
  R = NULL;
cleanup:
  fcm_cell_rules_destroy(&R);
  return st;
}

void fcm__embed_build_release(build *B)
{
  fcm_aabb_tree_destroy(&B->cut_tree);
  if (B->ctx) {
    fcm__free(B->ctx, B->region);
    fcm__free(B->ctx, B->rebuild);
    fcm__free(B->ctx, B->prev_region);
    fcm__free(B->ctx, B->same_links);
  }
  B->region = B->rebuild = B->prev_region = B->same_links = NULL;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    fcm_rule_destroy(&B->tet_rule[k]);
  fcm_rule_destroy(&B->tri_rule);
  if (B->ctx) fcm__moment_quad_free(B->ctx, &B->mq);
}

/* Phase 1b: what every cell reads: tet rules, search trees of the embedded cells and
 * boundary triangles, which kinds get stabilization points. */
fcm_status fcm__embed_build_setup(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                  const fcm_cell_rules_options *o, const fcm_cell_rules *R,
                                  build *B)
{
  fcm_status st = FCM_OK;
  memset(B, 0, sizeof *B);
  B->ctx = ctx, B->mesh = mesh, B->geom = geom, B->o = o;
  const fcm_element_info *einfo = fcm_mesh_get_element_info(mesh);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    B->space_m[k] = R->strength[k], B->space_q[k] = R->axis_degree[k];
    if (k == FCM_RULE_STIFFNESS && o->stiffness_on_mass_space)
      kind_space(einfo, o, FCM_RULE_MASS, &B->space_m[k], &B->space_q[k]);
  }
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!KIND_BUILT(o->kinds, k)) continue; /* tet_rule[k] NULL marks a kind not built */
    FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_TET, B->space_m[k], &B->tet_rule[k]));
    B->full_rule[k] = R->uncut[k];
  }
  B->stabilize[FCM_RULE_STIFFNESS] = o->stabilization.mode == FCM_STABILIZATION_MASS_STIFFNESS;
  B->stabilize[FCM_RULE_MASS] = o->stabilization.mode != FCM_STABILIZATION_OFF;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    B->stabilize[k] = B->stabilize[k] && B->tet_rule[k];
  FCM_TRY(ctx, fcm__geom_tree(ctx, geom, 0, &B->tree));
  /* the surface path needs the whole closed boundary (a crop keeps it for this path); a
   * geometry without cells has no other path */
  FCM_CHECK(geom->num_cells > 0 || o->moments != FCM_CELL_MOMENTS_VOLUME, ctx, FCM_ERR_UNSUPPORTED,
            "embed: moments = volume with a geometry that has no volume mesh (a surface geometry "
            "made with volume_mesh = 0); use moments = auto");
  B->surface = o->moments != FCM_CELL_MOMENTS_VOLUME &&
               (o->simplify != FCM_CELL_SIMPLIFY_OFF || geom->num_cells == 0) &&
               geom->num_tris > 0 && (!geom->tri_orig || geom->num_tris == geom->orig_tris);
  if (o->surface_strength >= 0)
    FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_TRI, o->surface_strength, &B->tri_rule));
  if (o->surface_strength >= 0 || B->surface) {
    FCM_TRY(ctx, fcm__geom_tree(ctx, geom, 1, &B->tri_tree));
  }
  if (B->surface) { /* both kinds' strengths, built or not: the rules of one kind do not
                       depend on which others are built */
    const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
    int m = 0;
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      int axis;
      kind_space(info, o, o->stiffness_on_mass_space ? FCM_RULE_MASS : k, &B->fit_strength[k],
                 &axis);
      B->fit_M[k] = fcm__simplify_num_basis(B->fit_strength[k]);
      B->grid_M = FCM_MAX(B->grid_M, o->stiffness_on_mass_space
                                         ? fcm__simplify_space_size(B->fit_strength[k], axis)
                                         : B->fit_M[k]);
      fcm_rule *t = NULL;
      FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_TET, B->fit_strength[k], &t));
      B->fit_tet_points[k] = fcm_rule_num_points(t);
      fcm_rule_destroy(&t);
      m = FCM_MAX(m, B->fit_strength[k]);
    }
    FCM_TRY(ctx, fcm__moment_quad_create(ctx, m, &B->mq));
  }
cleanup:
  if (st != FCM_OK) fcm__embed_build_release(B);
  return st;
}

/* The copies of one gathering pass: per array, the run of bytes pending (src to dst), extended
 * while the next piece's source follows it in memory (the pieces a cut copies from the rules it
 * extends lie one after another there, as in R), else copied and restarted. */
enum { GATHER_ARRAYS = 3 * FCM_RULE_KIND_COUNT + 5 };
typedef struct gather_run {
  unsigned char *dst[GATHER_ARRAYS];
  const unsigned char *src[GATHER_ARRAYS];
  size_t len[GATHER_ARRAYS];
} gather_run;

static void run_flush(gather_run *g, int a)
{
  if (g->len[a]) memcpy(g->dst[a], g->src[a], g->len[a]);
  g->len[a] = 0;
}

static void run_add(gather_run *g, int a, void *dst, const void *src, size_t len)
{
  if (!len) return;
  if (g->len[a] && g->src[a] + g->len[a] == (const unsigned char *)src &&
      g->dst[a] + g->len[a] == (unsigned char *)dst) {
    g->len[a] += len;
    return;
  }
  run_flush(g, a);
  g->dst[a] = dst, g->src[a] = src, g->len[a] = len;
}

/* Cells c0 to c1 - 1's pieces' rules, surface rules and cut faces from out into R's arrays
 * (their offsets set). */
static void gather_cells(fcm_cell_rules *R, const cell_out *out, fcm_index c0, fcm_index c1)
{
  gather_run g;
  memset(g.len, 0, sizeof g.len);
  for (fcm_index c = c0; c < c1; c++) {
    const cell_out *o = out + c;
    for (int i = 0; i < o->np; i++) {
      const piece_out *q = o->pc + i;
      const fcm_index p = R->piece_off[c] + i;
      for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
        const size_t n = (size_t)(R->off[k][p + 1] - R->off[k][p]), o0 = (size_t)R->off[k][p];
        run_add(&g, 3 * k, R->points[k] + 3 * o0, q->pts[k], 3 * n * sizeof(double));
        run_add(&g, 3 * k + 1, R->weights[k] + o0, q->w[k], n * sizeof(double));
        run_add(&g, 3 * k + 2, R->flags[k] + o0, q->flag[k], n);
      }
      const int a = 3 * FCM_RULE_KIND_COUNT;
      run_add(&g, a, R->cfxi + 9 * R->cfoff[p], q->cfxi, 9 * (size_t)q->ncf * sizeof(double));
      const size_t n = (size_t)q->ns, o0 = (size_t)R->soff[p];
      run_add(&g, a + 1, R->spoints + 3 * o0, q->spts, 3 * n * sizeof(double));
      run_add(&g, a + 2, R->sweights + o0, q->sw, n * sizeof(double));
      run_add(&g, a + 3, R->snormals + 3 * o0, q->snrm, 3 * n * sizeof(double));
      run_add(&g, a + 4, R->stris + o0, q->stri, n * sizeof(fcm_index));
    }
  }
  for (int a = 0; a < GATHER_ARRAYS; a++)
    run_flush(&g, a);
}

/* The cells one task of the gathering copies. */
#define GATHER_CHUNK 256

/* Phase 3: concatenate the pieces' volume and surface rules in cell order. */
fcm_status fcm__embed_gather_rules(fcm_ctx *ctx, fcm_cell_rules *R, const cell_out *out,
                                   const fcm_cell_rules *prev)
{
  fcm_status st = FCM_OK;
  const fcm_index nc = R->num_cells;
  R->piece_off[0] = 0;
  for (fcm_index c = 0; c < nc; c++)
    R->piece_off[c + 1] = R->piece_off[c] + out[c].np;
  const fcm_index np = R->piece_off[nc];
  R->num_pieces = np;
  FCM_ALLOC_RAW(ctx, (size_t)np + 1, R->piece_cell);
  FCM_ALLOC_RAW(ctx, (size_t)np + 1, R->piece_volume);
  FCM_ALLOC_RAW(ctx, (size_t)np + 1, R->piece_parent);
  FCM_ALLOC_RAW(ctx, (size_t)np + 1, R->piece_component);
  FCM_ALLOC_RAW(ctx, (size_t)np + 1, R->soff);
  FCM_ALLOC_RAW(ctx, (size_t)np + 1, R->cfoff);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    FCM_ALLOC_RAW(ctx, (size_t)np + 1, R->off[k]);
  fcm__free(ctx, R->piece_copied);
  R->piece_copied = NULL;
  if (prev) FCM_ALLOC(ctx, (size_t)np + 1, R->piece_copied);
  /* every piece's entries of the arrays above in one pass over the cells (the slot past the
   * last piece of the first four is never read: zeroed as before) */
  R->piece_cell[np] = 0, R->piece_volume[np] = 0.0, R->piece_parent[np] = 0;
  R->piece_component[np] = 0;
  R->soff[0] = R->cfoff[0] = 0;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    R->off[k][0] = 0;
  for (fcm_index c = 0; c < nc; c++) {
    const cell_out *o = out + c;
    const int cut = R->cls[c] == FCM_CELL_CUT;
    for (int i = 0; i < o->np; i++) {
      const piece_out *q = o->pc + i;
      const fcm_index p = R->piece_off[c] + i;
      R->piece_cell[p] = c;
      R->piece_volume[p] = q->volume;
      R->piece_parent[p] = prev ? prev->piece_off[c] + q->parent : -1;
      R->piece_component[p] = q->component;
      if (R->piece_copied) R->piece_copied[p] = q->copied;
      for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
        R->off[k][p + 1] = R->off[k][p] + (cut ? q->n[k] : 0);
      R->cfoff[p + 1] = R->cfoff[p] + q->ncf;
      R->soff[p + 1] = R->soff[p] + q->ns;
    }
  }
  /* written whole by the copies below */
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    const size_t tot = (size_t)R->off[k][np];
    FCM_ALLOC_RAW(ctx, 3 * tot, R->points[k]);
    FCM_ALLOC_RAW(ctx, tot, R->weights[k]);
    FCM_ALLOC_RAW(ctx, tot, R->flags[k]);
  }
  FCM_ALLOC(ctx, 9 * (size_t)R->cfoff[np] + 1, R->cfxi);
  const size_t tot = (size_t)R->soff[np];
  FCM_ALLOC_RAW(ctx, 3 * tot, R->spoints);
  FCM_ALLOC_RAW(ctx, tot, R->sweights);
  FCM_ALLOC_RAW(ctx, 3 * tot, R->snormals);
  FCM_ALLOC_RAW(ctx, tot, R->stris);
  /* the copies, each task's cells into their own ranges */
  const fcm_index nchunks = (nc + GATHER_CHUNK - 1) / GATHER_CHUNK;
#pragma omp parallel for schedule(dynamic, 1) num_threads(fcm_ctx_num_threads(ctx))
  for (fcm_index ch = 0; ch < nchunks; ch++)
    gather_cells(R, out, ch * GATHER_CHUNK, FCM_MIN(nc, (ch + 1) * GATHER_CHUNK));
cleanup:
  return st;
}

/* Phase 4: the statistics (times are filled in by the caller). */
void fcm__embed_gather_stats(fcm_cell_rules *R, const fcm_geometry *geom, const cell_out *out,
                             const cell_sums *sums, int nthreads)
{
  fcm_cell_rules_stats *S = &R->stats;
  const fcm_index nc = R->num_cells;
  S->num_cells = nc;
  for (fcm_index c = 0; c < nc; c++) {
    const cell_out *o = out + c;
    for (int i = 0; i < o->np; i++) {
      const piece_out *q = o->pc + i;
      for (int k = 0; k < FCM_RULE_KIND_COUNT && !q->copied; k++) {
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
      S->dropped_area += o->dropped_area;
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
  S->moved_volume = sums->counts.moved_volume;
  S->num_degenerate = sums->counts.degenerate;
  S->split_change = sums->counts.split_change;
  S->surface_triangles = sums->counts.surface_triangles;
  S->num_surface_cells = sums->counts.surface_cells;
  S->num_surface_fallbacks = sums->counts.surface_fallbacks;
  S->num_kept = sums->counts.kept;
  S->geometry_volume = fcm_geometry_volume(geom);
  S->num_threads = nthreads;
  S->time_intersect = sums->time_intersect;
  S->time_simplify = sums->time_simplify;
}
