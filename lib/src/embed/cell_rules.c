/* Cut-cell rules: creation (fcm_cell_rules_create, fcm_cell_rules_create_cut and the
 * reduced and distributed variants) as one build in phases: set-up, the cells in parallel, the
 * AUTO simplification choice, gathering in cell order, statistics. */
#include "embed/rules_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

fcm_cell_rules_options fcm_cell_rules_options_default(void)
{
  fcm_cell_rules_options o;
  memset(&o, 0, sizeof o);
  o.kinds = FCM_RULES_ALL;
  o.strength[FCM_RULE_STIFFNESS] = -1;
  o.strength[FCM_RULE_MASS] = -1;
  o.axis_degree[FCM_RULE_STIFFNESS] = FCM_DEFAULT;
  o.axis_degree[FCM_RULE_MASS] = FCM_DEFAULT;
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

/* The build shared by fcm_cell_rules_create() and fcm_cell_rules_create_cut(): R (from
 * rules_alloc, with its cut triangles set) is filled; `prev` (or NULL) is the object being
 * extended by the triangles from first_new on. With x (distributed classification, no cuts):
 * the cells of x->remote are skipped and their classes taken from x->exchange, before the
 * AUTO choice (red). */
static fcm_status build_rules_x(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                const fcm_cell_rules *prev, fcm_index first_new, int keep,
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
  /* a cut checks the cells it integrates again (process_cell()): the others keep prev's */
  for (fcm_index c = 0; c < nc && !prev; c++)
    FCM_TRY(ctx, fcm__embed_check_convex(ctx, mesh, c, o));

  /* 1. set-up */
  FCM_TRY(ctx, fcm__embed_build_setup(ctx, mesh, geom, o, R, &B));
  B.prev = prev;
  B.first_new = first_new;
  B.keep = keep;
  B.red = red;
  B.remote = x ? x->remote : NULL;
  if (R->num_cut_tris > 0) FCM_TRY(ctx, fcm__embed_cut_setup(&B, R, first_new));
  FCM_ALLOC_RAW(ctx, (size_t)nc, out); /* zeroed cell by cell by fcm__embed_run_cells() */
  const double t_setup = fcm_wtime();
  /* 2. parallel per-cell work */
  const int nthreads = fcm_ctx_num_threads(ctx);
  FCM_TRY(ctx, fcm__embed_run_cells(&B, R, nthreads, out, &sums, o));
  if (x) FCM_TRY(ctx, fcm__embed_exchange_classes(&B, R, x, out, &sums, exchanged));
  if (o->simplify == FCM_CELL_SIMPLIFY_AUTO)
    FCM_TRY(ctx, fcm__embed_auto_simplify(&B, R, nthreads, out, &sums));
  const double t_loop = fcm_wtime();
  /* 3. gather, 4. statistics */
  FCM_TRY(ctx, fcm__embed_gather_rules(ctx, R, out, prev));
  if (B.cut_tree) FCM_TRY(ctx, fcm__embed_gather_links(&B, R, out));
  {
    /* the kept face polygons (which move out of the cells' outputs) and the statistics (which
     * read the outputs' other fields and allocate nothing) side by side; the polygons' error,
     * on whichever thread, goes to the context (no caller builds rules inside an fcm__loop
     * iteration, whose record would want it) */
    fcm_status kept = FCM_OK;
#pragma omp parallel sections num_threads(2) if (B.cut_tree && nthreads > 1)
    {
#pragma omp section
      if (B.cut_tree) kept = fcm__embed_keep_face_polygons(&B, R, out);
#pragma omp section
      fcm__embed_gather_stats(R, geom, out, &sums, nthreads);
    }
    FCM_TRY(ctx, kept);
  }
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
    R->stats.num_integrated -= R->stats.num_kept;
  }
  R->stats.time_setup = t_setup - t_start;
  R->stats.time_gather = fcm_wtime() - t_loop;
  R->stats.time_total = fcm_wtime() - t_start;
cleanup:
  if (out) { /* many small arrays per integrated cell: freed on the context's threads */
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx)) schedule(dynamic, 256) if (nc > 4096)
    for (fcm_index c = 0; c < nc; c++)
      fcm__embed_cell_out_free(ctx, out + c);
  }
  fcm__free(ctx, out);
  fcm__embed_build_release(&B);
  return st;
}

static fcm_status build_rules(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                              const fcm_cell_rules *prev, fcm_index first_new, int keep,
                              fcm__rules_reduce *red, fcm_cell_rules *R)
{
  int exchanged = 0;
  return build_rules_x(ctx, mesh, geom, prev, first_new, keep, red, R, NULL, &exchanged);
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
  FCM_TRY(ctx, fcm__embed_check_options(ctx, &o, red != NULL));
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
  FCM_TRY(ctx, fcm__embed_rules_alloc(ctx, mesh, &o, &R));
  FCM_TRY(ctx, build_rules_x(ctx, mesh, geom, NULL, 0, 0,
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
  return fcm__cell_rules_create_cut_keep(ctx, mesh, geom, prev, cut, 1, rules);
}

fcm_status fcm__cell_rules_create_cut_keep(fcm_ctx *ctx, const fcm_mesh *mesh,
                                           const fcm_geometry *geom, const fcm_cell_rules *prev,
                                           const fcm_surface *cut, int keep, fcm_cell_rules **rules)
{
  fcm_status st = FCM_OK;
  fcm_cell_rules *R = NULL, *least = NULL;
  unsigned char *inner = NULL;
  fcm_index *ref = NULL;
  fcm__cut_wall *walls = NULL;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "embed cut: output pointer is NULL");
  *rules = NULL;
  FCM_CHECK(ctx && mesh && geom && prev && cut, ctx, FCM_ERR_ARG,
            "embed cut: NULL argument (ctx, mesh, geometry, rules and cut are required)");
  FCM_CHECK(fcm_mesh_num_cells(mesh) == prev->num_cells &&
                fcm_mesh_element_type(mesh) == prev->type,
            ctx, FCM_ERR_ARG, "embed cut: the mesh (%lld cells) is not the rules' mesh (%lld)",
            (long long)fcm_mesh_num_cells(mesh), (long long)prev->num_cells);
  FCM_CHECK(geom->num_cells > 0 || prev->opts.moments != FCM_CELL_MOMENTS_VOLUME, ctx,
            FCM_ERR_UNSUPPORTED,
            "embed cut: moments = volume with a geometry that has no volume mesh (a surface "
            "geometry made with volume_mesh = 0); use moments = auto");
  FCM_CHECK(prev->num_cuts < 1 << 20, ctx, FCM_ERR_UNSUPPORTED,
            "embed cut: %d cuts already (limit 2^20)", prev->num_cuts);
  FCM_TRY(ctx, fcm__embed_cut_check(ctx, cut, "embed cut"));
  const fcm_index nt = fcm_surface_num_triangles(cut);
  const double *x = fcm_surface_coords(cut);
  const fcm_index *tv = fcm_surface_triangles(cut);
  FCM_ALLOC(ctx, 3 * (size_t)nt + 1, inner);
  FCM_ALLOC(ctx, (size_t)nt + 1, ref);
  FCM_ALLOC(ctx, 3 * (size_t)nt + 1, walls);
  FCM_TRY(ctx, fcm__embed_cut_inner_edges(ctx, cut, inner, ref, walls));
  /* A cut that meets the parts of some cell in a way the tolerances cannot resolve (the
   * splitting changes their volume) is shifted by a small deterministic translation and
   * applied again: 1e-7, 1e-6, then 1e-5 of the mean cell size, along a fixed direction
   * with no rational relation to the axes. If none resolves it, the attempt whose largest
   * volume change is least is taken when that change is the tolerance's own (kept while the
   * next attempts are made, two sets of rules at once, rather than made again). A cell's
   * change is the new cut's alone (fcm__embed_cell_pieces()): an earlier cut taken so would
   * otherwise make every later one through its cells degenerate. */
  const double h = mean_cell_size(mesh);
  static const double dir[3] = {0.4636476090008061, 0.5880026035475675, 0.6628738660715610};
  static const double shift[CUT_ATTEMPTS] = {0.0, 1e-7, 1e-6, 1e-5};
  fcm_index degenerate = 0;
  for (int attempt = 0; attempt < CUT_ATTEMPTS; attempt++) {
    FCM_TRY(ctx, fcm__embed_rules_alloc(ctx, mesh, &prev->opts, &R));
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
      R->num_cut_tris +=
          fcm__embed_cut_tri_setup(v[0], v[1], v[2], prev->num_cuts, inner + 3 * t, &w[0][0],
                                   walls + 3 * t, R->cut_tris + R->num_cut_tris);
    }
    R->num_cuts = prev->num_cuts + 1;
    R->prev_num_pieces = prev->num_pieces;
    R->parent_id = prev->id;
    /* rules built with a cell_mask: the same cells get points (the others are classified,
     * split and get their cut faces: the same pieces and DOF copies on every process) */
    R->opts.cell_mask = prev->own;
    st = build_rules(ctx, mesh, geom, prev, prev->num_cut_tris, keep, NULL, R);
    R->opts.cell_mask = NULL;
    FCM_TRY(ctx, st);
    for (int j = 0; j < 3; j++)
      R->stats.cut_shift[j] = d * dir[j];
    degenerate = R->stats.num_degenerate;
    R->stats.cut_attempts = attempt + 1;
    if (degenerate == 0) break;
    const double change = R->stats.split_change; /* kept: the attempt of least change */
    if (!least || isnan(least->stats.split_change) || change < least->stats.split_change) {
      fcm_cell_rules_destroy(&least);
      least = R;
      R = NULL;
    } else {
      fcm_cell_rules_destroy(&R);
    }
  }
  if (degenerate > 0) { /* none resolved: the attempt of least change, if it is the tolerance's */
    R = least;
    least = NULL;
    R->stats.cut_attempts = CUT_ATTEMPTS;
    degenerate = R->stats.num_degenerate;
  }
  if (prev->masked) {
    R->masked = 1;
    FCM_ALLOC(ctx, (size_t)prev->num_cells + 1, R->own);
    memcpy(R->own, prev->own, (size_t)prev->num_cells);
  }
  FCM_CHECK(degenerate == 0 || R->stats.split_change <= DEGENERATE_ACCEPT_RTOL, ctx,
            FCM_ERR_GEOMETRY,
            "embed cut: the cut meets %lld cell(s) in a degenerate way that shifts of up to %g "
            "(1e-5 of the mean cell size %g) did not resolve: splitting them changes their "
            "volume (by up to %.3g of a cell's, more than the tolerance's %g); move the cut",
            (long long)degenerate, shift[CUT_ATTEMPTS - 1] * h, h, R->stats.split_change,
            DEGENERATE_ACCEPT_RTOL);
  *rules = R;
  R = NULL;
cleanup:
  fcm__free(ctx, inner);
  fcm__free(ctx, ref);
  fcm__free(ctx, walls);
  fcm_cell_rules_destroy(&R);
  fcm_cell_rules_destroy(&least);
  return st;
}
