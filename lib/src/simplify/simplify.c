/* fcm_simplify(): argument checks, weight normalization, the attempts (the chosen path,
 * then a GLPK path, then the chosen path with a looser rank threshold), verification with
 * a least-squares re-fit on the kept support when needed, and the fallback to the
 * unchanged input rule.
 *
 * Longva et al. 2020 §4.4: a basic feasible solution of P w = P w0, w >= 0 has at most
 * rank P <= M non-zeros, so a subset of the input points (inside the geometry whenever
 * the input points are) carries positive weights with the input's moments. The paper
 * finds one with an LP; the default here reaches one by Carathéodory elimination (no LP),
 * which starts from the feasible w0 and keeps every weight >= 0 by construction. Unlike
 * the authors' code every result is checked (weights > 0, count <= M, relative moment
 * residual <= tolerance) and a failure never aborts: the input rule comes back. */
#include "la/la_impl.h"
#include "simplify/simplify_impl.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* AUTO uses recombination above this many points per basis function. Measured by
 * tests/simplify/bench_simplify.c: the plain LP is as fast up to N ~ 8 M, recombination
 * 1.6-3x faster at 16-32 M, 3-4x at the paper's M = 35, N = 2,900 and 12-23x at
 * M = 286, N = 110,592. */
#define AUTO_RECOMBINE_RATIO 12

/* Elimination: an LU pivot below this times rank_tol of the largest one means the moment
 * rows are dependent (rank_tol 1e-13 gives 1e-10; LU pivots are not singular values). */
#define PIVOT_FACTOR 1e3

fcm_simplify_options fcm_simplify_options_default(void)
{
  fcm_simplify_options o;
  memset(&o, 0, sizeof o);
  o.method = FCM_SIMPLIFY_AUTO;
  o.rank_tol = 1e-13;
  o.residual_tol = 1e-12;
  o.lp_iteration_limit = FCM_DEFAULT;
  o.lp_time_limit = 60.0;
  o.elimination_block = FCM_DEFAULT;
  o.axis_degree = FCM_DEFAULT;
  return o;
}

const char *fcm_simplify_method_name(fcm_simplify_method method)
{
  switch (method) {
  case FCM_SIMPLIFY_AUTO:
    return "auto";
  case FCM_SIMPLIFY_LP:
    return "lp";
  case FCM_SIMPLIFY_RECOMBINE:
    return "recombine";
  case FCM_SIMPLIFY_ELIMINATE:
    return "eliminate";
  default:
    return "unknown";
  }
}

const char *fcm_simplify_reason_name(fcm_simplify_reason reason)
{
  switch (reason) {
  case FCM_SIMPLIFY_REASON_NONE:
    return "none";
  case FCM_SIMPLIFY_REASON_LP:
    return "lp";
  case FCM_SIMPLIFY_REASON_LP_ERROR:
    return "lp-error";
  case FCM_SIMPLIFY_REASON_NUMERIC:
    return "numeric";
  case FCM_SIMPLIFY_REASON_NOT_POSITIVE:
    return "not-positive";
  case FCM_SIMPLIFY_REASON_RESIDUAL:
    return "residual";
  case FCM_SIMPLIFY_REASON_COUNT:
    return "count";
  case FCM_SIMPLIFY_REASON_NO_PROGRESS:
    return "no-progress";
  default:
    return "unknown";
  }
}

void fcm__simplify_set_moments(fcm__attempt *a, int ncols, const double *g, const double *lam)
{
  const int M = a->box.num_basis;
  if (a->have_moments) return;
  for (int i = 0; i < M; i++)
    a->moments[i] = 0.0;
  for (int c = 0; c < ncols; c++)
    for (int i = 0; i < M; i++)
      a->moments[i] += (lam ? lam[c] : 1.0) * g[i + (size_t)c * (size_t)M];
  a->have_moments = 1;
}

void fcm__simplify_take_support(fcm__attempt *a, int n, const int *idx, const double *scale,
                                const double *x, const char *what)
{
  a->count = 0;
  for (int j = 0; j < n; j++)
    if (x[j] > 0.0) {
      if (a->count == a->capacity) {
        fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_COUNT,
                           "%s kept more than M = %d positive weights", what, a->capacity);
        return;
      }
      a->support[a->count] = idx ? idx[j] : j;
      a->w[a->count++] = scale ? scale[j] * x[j] : x[j];
    }
  if (a->count == 0)
    fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_NOT_POSITIVE, "%s kept no positive weight", what);
}

void fcm__simplify_fail(fcm__attempt *a, fcm_simplify_reason reason, const char *fmt, ...)
{
  va_list ap;
  a->reason = reason;
  va_start(ap, fmt);
  vsnprintf(a->message, sizeof a->message, fmt, ap);
  va_end(ap);
}

fcm_status fcm__simplify_soften(fcm__attempt *a, fcm_status st, const char *what)
{
  if (st == FCM_OK || st == FCM_ERR_ALLOC) return st;
  fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_NUMERIC, "%s failed: %s", what, fcm_status_name(st));
  return FCM_OK;
}

fcm_status fcm__simplify_row_space(fcm__attempt *a, int rows, int cols, double *g, double *q,
                                   int *r)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = a->ctx;
  const int k = FCM_MIN(rows, cols);
  double *s = NULL;
  const double t0 = fcm_wtime();
  *r = 0;
  FCM_ALLOC(ctx, (size_t)k, s);
  FCM_TRY(ctx, fcm__simplify_soften(a, fcm__gesvd(ctx, rows, cols, g, rows, s, NULL, 1, q, k),
                                    "SVD of the moment matrix"));
  if (a->reason != FCM_SIMPLIFY_REASON_NONE) goto cleanup;
  if (!(s[0] > 0.0 && isfinite(s[0]))) {
    fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_NUMERIC, "moment matrix has s_max = %g", s[0]);
    goto cleanup;
  }
  while (*r < k && s[*r] > a->rank_tol * s[0])
    (*r)++;
cleanup:
  a->time_svd += fcm_wtime() - t0;
  fcm__free(ctx, s);
  return st;
}

/* Relative residual max|P_S w - b| / max|b| of weights w on the support (PS is M x count). */
static double residual_of(int M, int count, const double *PS, const double *w, const double *b)
{
  double num = 0.0, den = 0.0;
  for (int i = 0; i < M; i++) {
    double s = 0.0;
    for (int c = 0; c < count; c++)
      s += PS[i + (size_t)c * (size_t)M] * w[c];
    num = fmax(num, fabs(s - b[i]));
    den = fmax(den, fabs(b[i]));
  }
  const double res = num / den;
  return isnan(res) ? INFINITY : res;
}

/* Verify the path's weights (positive by construction); only when their residual is above
 * the tolerance, re-fit them on the support by least squares (P_S w_S = b) and verify
 * those. */
static fcm_status refit_verify(fcm__attempt *a, double tol, double *residual)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = a->ctx;
  const int M = a->box.num_basis, count = a->count;
  double *PS = NULL, *A = NULL, *B = NULL;
  *residual = INFINITY;
  FCM_ALLOC(ctx, (size_t)M * (size_t)count, PS);
  FCM_ALLOC(ctx, (size_t)M * (size_t)count, A);
  FCM_ALLOC(ctx, (size_t)FCM_MAX(M, count), B);
  for (int c = 0; c < count; c++)
    fcm__simplify_basis_eval(&a->box, a->points + 3 * (size_t)a->support[c],
                             PS + (size_t)c * (size_t)M);
  if (!a->have_moments) { /* no path got as far as evaluating the basis on every point */
    double *scratch = NULL;
    FCM_ALLOC(ctx, fcm__simplify_moments_scratch(a->box.m), scratch);
    fcm__simplify_moments(&a->box, a->n, a->points, NULL, a->w0, a->moments, scratch);
    fcm__free(ctx, scratch);
    a->have_moments = 1;
  }
  memcpy(A, PS, sizeof *A * (size_t)M * (size_t)count);
  memcpy(B, a->moments, sizeof *B * (size_t)M);

  const double lp_res = residual_of(M, count, PS, a->w, a->moments);
  if (lp_res <= tol) { /* the path's own weights verify: no re-fit needed */
    *residual = lp_res;
    goto checks;
  }
  st = fcm__lstsq(ctx, M, count, 1, A, M, B, FCM_MAX(M, count), -1.0, NULL);
  if (st == FCM_ERR_ALLOC) {
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  int refit_ok = st == FCM_OK;
  st = FCM_OK;
  for (int c = 0; refit_ok && c < count; c++)
    refit_ok = B[c] > 0.0 && isfinite(B[c]);
  const double fit_res = refit_ok ? residual_of(M, count, PS, B, a->moments) : INFINITY;

  if (refit_ok && fit_res <= tol) {
    memcpy(a->w, B, sizeof *B * (size_t)count);
    *residual = fit_res;
  } else {
    *residual = fmin(lp_res, fit_res);
    fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_RESIDUAL,
                       "relative moment residual %.3g (path) / %.3g (re-fit%s) above %.3g", lp_res,
                       fit_res, refit_ok ? "" : ", not positive", tol);
  }
checks:
  for (int c = 0; a->reason == FCM_SIMPLIFY_REASON_NONE && c < count; c++)
    if (!(a->w[c] > 0.0) || !isfinite(a->w[c]))
      fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_NOT_POSITIVE, "weight %d = %g not positive", c,
                         a->w[c]);
  if (a->reason == FCM_SIMPLIFY_REASON_NONE && count > M)
    fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_COUNT, "%d points exceed M = %d", count, M);
cleanup:
  fcm__free(ctx, PS);
  fcm__free(ctx, A);
  fcm__free(ctx, B);
  return st;
}

static fcm_status check_options(fcm_ctx *ctx, const fcm_simplify_options *o)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(o->method >= FCM_SIMPLIFY_AUTO && o->method < FCM_SIMPLIFY_METHOD_COUNT, ctx,
            FCM_ERR_ARG, "simplify: method = %d out of range [0, %d)", (int)o->method,
            (int)FCM_SIMPLIFY_METHOD_COUNT);
  FCM_CHECK(o->rank_tol >= 0.0 && o->rank_tol < 1.0, ctx, FCM_ERR_ARG,
            "simplify: rank_tol = %g out of range [0, 1)", o->rank_tol);
  FCM_CHECK(o->residual_tol > 0.0 && o->residual_tol < 1.0, ctx, FCM_ERR_ARG,
            "simplify: residual_tol = %g out of range (0, 1)", o->residual_tol);
  FCM_CHECK(o->lp_iteration_limit >= 1 || o->lp_iteration_limit == FCM_DEFAULT, ctx, FCM_ERR_ARG,
            "simplify: lp_iteration_limit = %d must be >= 1, or FCM_DEFAULT (-1: automatic)",
            o->lp_iteration_limit);
  FCM_CHECK(o->lp_time_limit >= 0.0 && isfinite(o->lp_time_limit), ctx, FCM_ERR_ARG,
            "simplify: lp_time_limit = %g must be finite and >= 0 (0: none)", o->lp_time_limit);
  FCM_CHECK((o->elimination_block >= 1 && o->elimination_block <= FCM__ELIM_BLOCK_MAX) ||
                o->elimination_block == FCM_DEFAULT,
            ctx, FCM_ERR_ARG,
            "simplify: elimination_block = %d out of range [1, %d], or FCM_DEFAULT (-1: measured)",
            o->elimination_block, FCM__ELIM_BLOCK_MAX);
  FCM_CHECK((o->axis_degree >= 0 && o->axis_degree <= FCM_SIMPLIFY_MAX_STRENGTH) ||
                o->axis_degree == FCM_DEFAULT,
            ctx, FCM_ERR_ARG,
            "simplify: axis_degree = %d out of range [0, %d], or FCM_DEFAULT (-1: every degree)",
            o->axis_degree, FCM_SIMPLIFY_MAX_STRENGTH);
cleanup:
  return st;
}

/* The input rule unchanged (N <= M, or every attempt failed). */
static fcm_status keep_input(fcm_ctx *ctx, int n, const double *weights, fcm_simplify_result *out)
{
  fcm_status st = FCM_OK;
  FCM_ALLOC(ctx, (size_t)n, out->indices);
  FCM_ALLOC(ctx, (size_t)n, out->weights);
  for (int j = 0; j < n; j++) {
    out->indices[j] = j;
    out->weights[j] = weights[j];
  }
  out->count = n;
cleanup:
  return st;
}

static void append_message(fcm_simplify_info *info, int attempt, fcm_simplify_method method,
                           double tol, const char *msg)
{
  const size_t len = strlen(info->message);
  if (len + 1 < sizeof info->message)
    snprintf(info->message + len, sizeof info->message - len, "%s[%d %s, rank_tol %.0e] %s",
             len ? "; " : "", attempt, fcm_simplify_method_name(method), tol, msg);
}

/* The attempts in order (lib/METHOD.md §6): the chosen path, the other path, the chosen path
 * with a looser rank cut. */
enum { ATTEMPT_CHOSEN, ATTEMPT_OTHER, ATTEMPT_LOOSER, ATTEMPT_COUNT };

/* Working state of one fcm_simplify() call: the positive-weight points and the attempt. */
typedef struct simplify_run {
  fcm_ctx *ctx;
  int ni;               /* input points */
  int np;               /* points of positive weight */
  int *map;             /* np: input index of each positive-weight point */
  double *packed;       /* np x 3 copy when some weights are zero, else NULL */
  const double *points; /* np x 3: the input or `packed` */
  double scale;         /* np / total weight: the attempts see mean-1 weights */
  double *w0, *moments;
  fcm__attempt a;
} simplify_run;

/* Set-up phase: arguments, options, finite points and weights; *total is the weight sum. */
static fcm_status check_input(fcm_ctx *ctx, int strength, fcm_index n, const double *points,
                              const double *weights, const fcm_simplify_options *o,
                              int force_lp_failure, int *ni, double *total)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(strength >= 0 && strength <= FCM_SIMPLIFY_MAX_STRENGTH, ctx, FCM_ERR_ARG,
            "simplify: strength = %d out of range [0, %d]", strength, FCM_SIMPLIFY_MAX_STRENGTH);
  FCM_CHECK(n >= 1, ctx, FCM_ERR_ARG, "simplify: n = %lld points, must be >= 1", (long long)n);
  FCM_CHECK(points && weights, ctx, FCM_ERR_ARG, "simplify: points and weights must not be NULL");
  FCM_TRY(ctx, check_options(ctx, o));
  FCM_CHECK(force_lp_failure >= 0 && force_lp_failure <= 2, ctx, FCM_ERR_ARG,
            "simplify: force_lp_failure = %d out of range [0, 2]", force_lp_failure);
  FCM_TRY(ctx, fcm__index_to_int(ctx, n, "simplify: number of points", ni));
  *total = 0.0;
  for (int j = 0; j < *ni; j++) {
    FCM_CHECK(isfinite(points[3 * (size_t)j]) && isfinite(points[3 * (size_t)j + 1]) &&
                  isfinite(points[3 * (size_t)j + 2]),
              ctx, FCM_ERR_ARG, "simplify: point %d = (%g, %g, %g) is not finite", j,
              points[3 * (size_t)j], points[3 * (size_t)j + 1], points[3 * (size_t)j + 2]);
    FCM_CHECK(weights[j] >= 0.0 && isfinite(weights[j]), ctx, FCM_ERR_ARG,
              "simplify: weight %d = %g, weights must be finite and >= 0", j, weights[j]);
    *total += weights[j];
  }
  FCM_CHECK(*total > 0.0 && isfinite(*total), ctx, FCM_ERR_ARG,
            "simplify: total weight %g of %d points must be finite and > 0", *total, *ni);
cleanup:
  return st;
}

/* Set-up phase: points of zero weight take no part; r->points are the np others. */
static fcm_status pack_positive(simplify_run *r, const double *points, const double *weights)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = r->ctx;
  for (int j = 0; j < r->ni; j++)
    r->np += weights[j] > 0.0;
  FCM_ALLOC(ctx, (size_t)r->np, r->map);
  for (int j = 0, k = 0; j < r->ni; j++)
    if (weights[j] > 0.0) r->map[k++] = j;
  r->points = points;
  if (r->np < r->ni) {
    FCM_ALLOC(ctx, 3 * (size_t)r->np, r->packed);
    for (int k = 0; k < r->np; k++)
      for (int d = 0; d < 3; d++)
        r->packed[3 * (size_t)k + d] = points[3 * (size_t)r->map[k] + d];
    r->points = r->packed;
  }
cleanup:
  return st;
}

/* Set-up phase: mean-1 weights (with tiny weights GLPK reports "optimal" with w = 0, as
 * measured), the attempt's buffers and parameters and the box of the basis (the moments
 * come from the first path that evaluates the basis on every point). */
static fcm_status setup_attempt(simplify_run *r, int strength, const double *weights, double total,
                                const fcm_simplify_options *o, int force_lp_failure)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = r->ctx;
  fcm__attempt *a = &r->a;
  const int M = fcm__simplify_space_size(strength, o->axis_degree), np = r->np;
  r->scale = (double)np / total;
  FCM_CHECK(isfinite(r->scale), ctx, FCM_ERR_ARG,
            "simplify: total weight %g of %d points too small to normalize (> %g needed)", total,
            r->ni, (double)np / DBL_MAX);
  FCM_ALLOC(ctx, (size_t)np, r->w0);
  for (int k = 0; k < np; k++)
    r->w0[k] = weights[r->map[k]] * r->scale;
  FCM_ALLOC(ctx, (size_t)M, r->moments);
  FCM_ALLOC(ctx, (size_t)M, a->support);
  FCM_ALLOC(ctx, (size_t)M, a->w);
  a->ctx = ctx;
  a->n = np;
  a->points = r->points;
  a->w0 = r->w0;
  a->moments = r->moments;
  a->capacity = M;
  a->lp.it_lim = o->lp_iteration_limit > 0 ? o->lp_iteration_limit : 20 * M + 1000;
  a->lp.tm_lim = o->lp_time_limit;
  a->lp.force_failure = force_lp_failure;
  a->elim_block = o->elimination_block > 0 ? o->elimination_block : FCM__ELIM_BLOCK;
  double t0 = fcm_wtime();
  fcm__simplify_box(strength, np, r->points, &a->box);
  fcm__simplify_box_cap(&a->box, o->axis_degree);
  a->time_basis += fcm_wtime() - t0;
cleanup:
  return st;
}

/* Attempt phase: run the attempts until one passes the re-fit and verification;
 * *success says whether one did. Failed attempts leave their reason and message in info. */
static fcm_status run_attempts(simplify_run *r, const fcm_simplify_options *o,
                               fcm_simplify_info *info, int *success)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = r->ctx;
  fcm__attempt *a = &r->a;
  /* The GLPK paths: the plain LP up to AUTO_RECOMBINE_RATIO points per basis function. */
  const fcm_simplify_method glpk =
      r->np > AUTO_RECOMBINE_RATIO * a->capacity ? FCM_SIMPLIFY_RECOMBINE : FCM_SIMPLIFY_LP;
  const fcm_simplify_method chosen =
      o->method == FCM_SIMPLIFY_AUTO ? FCM_SIMPLIFY_ELIMINATE : o->method;
  fcm_simplify_method other = glpk;
  if (chosen == FCM_SIMPLIFY_LP) other = FCM_SIMPLIFY_RECOMBINE;
  if (chosen == FCM_SIMPLIFY_RECOMBINE) other = FCM_SIMPLIFY_LP;
  fcm_simplify_method plan[ATTEMPT_COUNT];
  double tols[ATTEMPT_COUNT];
  plan[ATTEMPT_CHOSEN] = chosen, tols[ATTEMPT_CHOSEN] = o->rank_tol;
  plan[ATTEMPT_OTHER] = other, tols[ATTEMPT_OTHER] = o->rank_tol;
  plan[ATTEMPT_LOOSER] = chosen;
  tols[ATTEMPT_LOOSER] = fmin(1e-3, fmax(100.0 * o->rank_tol, 1e-14));
  *success = 0;
  for (int k = 0; k < ATTEMPT_COUNT && !*success; k++) {
    double residual = INFINITY;
    a->rank_tol = tols[k];
    a->pivot_tol = a->lp.force_failure ? INFINITY : fmin(1e-3, PIVOT_FACTOR * tols[k]);
    a->eliminate = 0;
    a->count = 0;
    a->rank = 0;
    a->reason = FCM_SIMPLIFY_REASON_NONE;
    a->message[0] = '\0';
    info->attempts = k + 1;
    info->method_used = plan[k];
    if (plan[k] == FCM_SIMPLIFY_LP)
      FCM_TRY(ctx, fcm__simplify_run_lp(a));
    else if (plan[k] == FCM_SIMPLIFY_RECOMBINE)
      FCM_TRY(ctx, fcm__simplify_run_recombine(a));
    else
      FCM_TRY(ctx, fcm__simplify_run_eliminate(a));
    if (a->reason == FCM_SIMPLIFY_REASON_NONE) {
      double t0 = fcm_wtime();
      st = refit_verify(a, o->residual_tol, &residual);
      info->time_refit += fcm_wtime() - t0;
      FCM_TRY(ctx, st);
    }
    info->rank = a->rank;
    if (a->reason == FCM_SIMPLIFY_REASON_NONE) {
      *success = 1;
      info->residual = residual;
    } else {
      if (info->reason == FCM_SIMPLIFY_REASON_NONE) info->reason = a->reason;
      append_message(info, k + 1, plan[k], tols[k], a->message);
    }
  }
cleanup:
  return st;
}

/* Gather phase: the support of the successful attempt in input numbering and scale. */
static fcm_status gather_result(const simplify_run *r, fcm_simplify_result *out)
{
  fcm_status st = FCM_OK;
  const fcm__attempt *a = &r->a;
  FCM_ALLOC(r->ctx, (size_t)a->count, out->indices);
  FCM_ALLOC(r->ctx, (size_t)a->count, out->weights);
  for (int c = 0; c < a->count; c++) {
    out->indices[c] = r->map[a->support[c]];
    out->weights[c] = a->w[c] / r->scale;
  }
  out->count = a->count;
cleanup:
  return st;
}

/* Gather phase: the positive-weight points unchanged (np <= M). */
static fcm_status keep_positive(const simplify_run *r, const double *weights,
                                fcm_simplify_result *out)
{
  fcm_status st = FCM_OK;
  FCM_ALLOC(r->ctx, (size_t)r->np, out->indices);
  FCM_ALLOC(r->ctx, (size_t)r->np, out->weights);
  for (int k = 0; k < r->np; k++) {
    out->indices[k] = r->map[k];
    out->weights[k] = weights[r->map[k]];
  }
  out->count = r->np;
cleanup:
  return st;
}

/* Statistics phase: the attempt's counters and times. */
static void record_statistics(const fcm__attempt *a, double t_start, fcm_simplify_info *info)
{
  info->lp_iterations = a->lp_iterations;
  info->num_lps = a->num_lps;
  info->num_eliminations = a->num_eliminations;
  info->rounds = a->rounds;
  info->time_basis = a->time_basis;
  info->time_svd = a->time_svd;
  info->time_lp = a->time_lp;
  info->flops = a->flops;
  info->time_total = fcm_wtime() - t_start;
}

fcm_status fcm_simplify(fcm_ctx *ctx, int strength, fcm_index n, const double *points,
                        const double *weights, const fcm_simplify_options *opts,
                        fcm_simplify_result *out, fcm_simplify_info *info)
{
  return fcm__simplify_hooked(ctx, strength, n, points, weights, opts, 0, out, info);
}

fcm_status fcm__simplify_hooked(fcm_ctx *ctx, int strength, fcm_index n, const double *points,
                                const double *weights, const fcm_simplify_options *opts,
                                int force_lp_failure, fcm_simplify_result *out,
                                fcm_simplify_info *info)
{
  fcm_status st = FCM_OK;
  fcm_simplify_info local_info;
  fcm_simplify_options o = opts ? *opts : fcm_simplify_options_default();
  simplify_run r;
  double total = 0.0;
  int success = 0;
  const double t_start = fcm_wtime();

  memset(&r, 0, sizeof r);
  r.ctx = ctx;
  if (!info) info = &local_info;
  memset(info, 0, sizeof *info);
  if (!ctx) return FCM_ERR_ARG;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "simplify: out must not be NULL");
  memset(out, 0, sizeof *out);
  out->ctx = ctx;
  FCM_TRY(ctx, check_input(ctx, strength, n, points, weights, &o, force_lp_failure, &r.ni, &total));

  const int M = fcm__simplify_space_size(strength, o.axis_degree);
  info->n = n;
  info->num_basis = M;
  info->method_used = FCM_SIMPLIFY_AUTO;
  if (r.ni <= M) { /* nothing to remove */
    info->skipped = 1;
    FCM_TRY(ctx, keep_input(ctx, r.ni, weights, out));
    info->kept = out->count;
    goto cleanup;
  }
  FCM_TRY(ctx, pack_positive(&r, points, weights));
  if (r.np <= M) { /* nothing to remove among the positive weights */
    info->skipped = 1;
    FCM_TRY(ctx, keep_positive(&r, weights, out));
    info->kept = out->count;
    goto cleanup;
  }
  FCM_TRY(ctx, setup_attempt(&r, strength, weights, total, &o, force_lp_failure));
  FCM_TRY(ctx, run_attempts(&r, &o, info, &success));
  if (success) {
    FCM_TRY(ctx, gather_result(&r, out));
  } else {
    info->fallback = 1;
    fcm__log(ctx, FCM_LOG_WARNING,
             "simplify: %lld points, strength %d: every attempt failed, the input rule is kept "
             "(%s)",
             (long long)n, strength, info->message);
    FCM_TRY(ctx, keep_input(ctx, r.ni, weights, out));
  }
  info->kept = out->count;

cleanup:
  record_statistics(&r.a, t_start, info);
  if (st != FCM_OK && out) {
    fcm__free(ctx, out->indices);
    fcm__free(ctx, out->weights);
    memset(out, 0, sizeof *out);
  }
  fcm__free(ctx, r.map);
  fcm__free(ctx, r.packed);
  fcm__free(ctx, r.w0);
  fcm__free(ctx, r.moments);
  fcm__free(ctx, r.a.ws);
  fcm__free(ctx, r.a.iws);
  fcm__free(ctx, r.a.support);
  fcm__free(ctx, r.a.w);
  return st;
}

double fcm_simplify_cost_estimate(int strength, fcm_index n)
{
  if (strength < 0 || strength > FCM_SIMPLIFY_MAX_STRENGTH || n < 0) return 0.0;
  const double M = fcm__simplify_num_basis(strength), N = (double)n;
  return N > M ? 2.5e-9 * N * M + 6.6e-10 * M * M * M : 0.0;
}

void fcm_simplify_result_destroy(fcm_simplify_result *res)
{
  if (!res) return;
  if (res->ctx) {
    fcm__free(res->ctx, res->indices);
    fcm__free(res->ctx, res->weights);
  }
  memset(res, 0, sizeof *res);
}
