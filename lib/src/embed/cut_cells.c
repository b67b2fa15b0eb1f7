/* The rules of a cut cell's material piece: its embedded tets mapped onto initial volume
 * rules (after the memory check), its surface points, simplification and stabilization. */
#include "embed/rules_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
static fcm_status check_rule_memory(const build *B, const fcm__embed_cell *cell,
                                    const fcm__embed_ws *ws)
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
      rule_memory_estimate(n, B->space_m, B->o->simplify, B->o->simplify_options.method);
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
fcm_status fcm__embed_finish_cell(const build *B, piece_out *o, const int simp[FCM_RULE_KIND_COUNT],
                                  cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  const double t1 = fcm_wtime();
  /* the points are written in place: never those of the rules being extended */
  FCM_CHECK(
      !o->borrowed, ctx, FCM_ERR_INTERNAL,
      "cell rules: finishing a piece whose points are borrowed from the rules being extended");
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!B->tet_rule[k]) continue; /* a kind not built */
    if (simp[k] && !o->fitted) {   /* on the kind's moment space */
      fcm_simplify_options so = opt->simplify_options;
      so.axis_degree = B->space_q[k];
      FCM_TRY(ctx, simplify_rule(ctx, &so, B->space_m[k], &o->n[k], o->pts[k], o->w[k], o, k));
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
fcm_status fcm__embed_map_piece(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                                piece_out *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  FCM_TRY(ctx, check_rule_memory(B, cell, ws));
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
fcm_status fcm__embed_surface_piece(const build *B, const fcm__embed_cell *cell,
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
