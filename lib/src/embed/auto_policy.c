/* FCM_CELL_SIMPLIFY_AUTO: whether simplifying the cut-cell rules pays, from a deterministic
 * model of the simplification time against the assembly time of the points it removes. */
#include "embed/rules_impl.h"
#include "simplify/simplify_impl.h"
#include "fcm/la.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

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
 * hemisphere at res 8, geometry n 8, with the elements' default strengths, on one core);
 * re-measure after a change of the assembly kernels. */
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

/* Finish the pieces list[0 .. n) in parallel (simplify the kinds that pay, stabilize);
 * the error is the lowest failing one's. */
static fcm_status auto_finish(const build *B, int nthreads, piece_out *const *list, fcm_index n,
                              const int pays[FCM_RULE_KIND_COUNT], cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  fcm__loop loop;
  fcm__loop_begin(ctx, &loop);
  /* one BLAS thread inside the threads, whatever their count (fcm__embed_run_cells) */
  const int blas_threads = fcm_blas_set_num_threads(1);
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
      fcm_status s = fcm__embed_finish_cell(B, list[i], simp, &mine);
      fcm__loop_leave(&loop, &it, s);
    }
#pragma omp critical(fcm_embed_auto_sum)
    sums->time_simplify += mine.time_simplify;
  }
  if (blas_threads > 1) fcm_blas_set_num_threads(blas_threads);
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
fcm_status fcm__embed_auto_simplify(const build *B, fcm_cell_rules *R, int nthreads, cell_out *out,
                                    cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  const fcm_index nc = R->num_cells;
  piece_out **cut = NULL;
  fcm_index ncut = 0;
  int pays[FCM_RULE_KIND_COUNT] = {0, 0};
  /* the pieces of the cut cells integrated here (with a cell_mask: this process's only; the
   * others have no points), not those a cut copies from the rules it extends: finished there */
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
        if (!out[c].pc[i].copied) cut[ncut++] = out[c].pc + i;
#undef AUTO_CELL
  /* the choice's inputs per kind: points, modelled simplification time, points kept */
  double in[3 * FCM_RULE_KIND_COUNT];
  memset(in, 0, sizeof in);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!B->tet_rule[k]) continue;
    const int m = R->strength[k];
    /* the points a simplified rule keeps: the moments of its space (Q2 for Hex8's mass) */
    const double M = (double)fcm__simplify_space_size(m, R->axis_degree[k]);
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
  FCM_TRY(ctx, auto_finish(B, nthreads, cut, ncut, pays, sums));
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    R->stats.decision[k].simplified = pays[k];
cleanup:
  fcm__free(ctx, cut);
  return st;
}
