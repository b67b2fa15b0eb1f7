/* fcm_direct: the phase-checked front of the sparse direct solvers (analyze once,
 * factor and solve many times); the library calls live in the adapter files. */
#include "la/la_impl.h"

#include <math.h>
#include <string.h>

struct fcm_direct {
  fcm_ctx *ctx;
  const fcm__direct_ops *ops;
  fcm_direct_method method;
  void *impl;
  fcm_index n, nnz;
  fcm_index *row_ptr; /* copy of the pattern's rows, to name entries in messages */
  int *col_idx;
  double *values; /* copy of the factored values, for the residual check */
  double *b_copy; /* n: b of the solve (x may alias it) */
  double norm_a;  /* ||A||_inf of the factored values */
  int analyzed, factored;
  fcm_direct_info info;
};

const char *fcm_direct_method_name(fcm_direct_method method)
{
  switch (method) {
  case FCM_DIRECT_CHOLMOD:
    return "cholmod";
  case FCM_DIRECT_UMFPACK:
    return "umfpack";
  }
  return "unknown";
}

fcm_status fcm_direct_create(fcm_ctx *ctx, fcm_direct_method method, const fcm_csr *A,
                             fcm_direct **out)
{
  fcm_status st = FCM_OK;
  fcm_direct *s = NULL;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "direct_create: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(A, ctx, FCM_ERR_ARG, "direct_create: pattern matrix is NULL");
  FCM_CHECK(method == FCM_DIRECT_CHOLMOD || method == FCM_DIRECT_UMFPACK, ctx, FCM_ERR_UNSUPPORTED,
            "direct_create: unknown method %d (valid: %d cholmod, %d umfpack)", (int)method,
            (int)FCM_DIRECT_CHOLMOD, (int)FCM_DIRECT_UMFPACK);
  FCM_CHECK(A->nrows == A->ncols, ctx, FCM_ERR_ARG,
            "direct_create: %s needs a square matrix, got %lld x %lld",
            fcm_direct_method_name(method), (long long)A->nrows, (long long)A->ncols);
  FCM_CHECK(method != FCM_DIRECT_CHOLMOD || A->kind == FCM_CSR_SYMMETRIC, ctx, FCM_ERR_ARG,
            "direct_create: cholmod needs an FCM_CSR_SYMMETRIC matrix (got a general one); use "
            "umfpack for general matrices");
  FCM_ALLOC(ctx, 1, s);
  s->ctx = ctx;
  s->method = method;
  s->ops = method == FCM_DIRECT_CHOLMOD ? &fcm__cholmod_ops : &fcm__umfpack_ops;
  s->n = A->nrows;
  s->nnz = A->nnz;
  s->info.failed_column = -1;
  FCM_ALLOC(ctx, s->n + 1, s->row_ptr);
  FCM_ALLOC(ctx, s->nnz, s->col_idx);
  for (fcm_index i = 0; i <= s->n; i++)
    s->row_ptr[i] = A->row_ptr[i];
  for (fcm_index p = 0; p < s->nnz; p++)
    s->col_idx[p] = A->col_idx[p];
  FCM_ALLOC(ctx, FCM_MAX(s->nnz, 1), s->values);
  FCM_ALLOC(ctx, FCM_MAX(s->n, 1), s->b_copy);
  if (s->n > 0) FCM_TRY(ctx, s->ops->create(ctx, A, &s->impl));
  *out = s;
  s = NULL;
cleanup:
  fcm_direct_destroy(&s);
  return st;
}

fcm_status fcm_direct_analyze(fcm_direct *s)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  fcm_timer t = fcm_timer_init();
  FCM_CHECK(s, ctx, FCM_ERR_ARG, "direct_analyze: solver is NULL");
  if (s->analyzed) goto cleanup;
  fcm__blas_check(ctx); /* the factorizations spend most of their time in DGEMM */
  fcm_timer_start(&t);
  if (s->n > 0) FCM_TRY(ctx, s->ops->analyze(ctx, s->impl, &s->info));
  s->analyzed = 1;
cleanup:
  fcm_timer_stop(&t);
  if (s) s->info.time_analyze += t.total;
  return st;
}

fcm_status fcm__direct_set_ordering(fcm_direct *s, const fcm_index *perm)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  unsigned char *seen = NULL;
  FCM_CHECK(s && (perm || s->n == 0), ctx, FCM_ERR_ARG, "direct ordering: NULL solver or perm");
  FCM_CHECK(!s->analyzed, ctx, FCM_ERR_ARG,
            "direct ordering: the %s solver is analyzed already; give the ordering before "
            "fcm_direct_analyze()",
            s->ops->name);
  FCM_CHECK(s->ops->set_ordering, ctx, FCM_ERR_UNSUPPORTED,
            "direct ordering: %s takes no given ordering (cholmod does)", s->ops->name);
  FCM_ALLOC(ctx, s->n + 1, seen);
  for (fcm_index k = 0; k < s->n; k++) {
    FCM_CHECK(perm[k] >= 0 && perm[k] < s->n && !seen[perm[k]], ctx, FCM_ERR_ARG,
              "direct ordering: perm[%lld] = %lld is outside [0, %lld) or repeated: not a "
              "permutation",
              (long long)k, (long long)perm[k], (long long)s->n);
    seen[perm[k]] = 1;
  }
  if (s->n > 0) FCM_TRY(ctx, s->ops->set_ordering(ctx, s->impl, perm));
cleanup:
  if (s) fcm__free(ctx, seen);
  return st;
}

fcm_status fcm__direct_get_ordering(const fcm_direct *s, fcm_index *perm)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  FCM_CHECK(s && (perm || s->n == 0), ctx, FCM_ERR_ARG, "direct ordering: NULL solver or perm");
  FCM_CHECK(s->analyzed, ctx, FCM_ERR_ARG,
            "direct ordering: the %s solver is not analyzed; call fcm_direct_analyze() first",
            s->ops->name);
  FCM_CHECK(s->ops->get_ordering, ctx, FCM_ERR_UNSUPPORTED,
            "direct ordering: %s keeps no symmetric ordering (cholmod does)", s->ops->name);
  if (s->n > 0) s->ops->get_ordering(s->impl, perm);
cleanup:
  return st;
}

fcm_status fcm_direct_factor(fcm_direct *s, const double *values)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  fcm_timer t = fcm_timer_init();
  FCM_CHECK(s, ctx, FCM_ERR_ARG, "direct_factor: solver is NULL");
  FCM_CHECK(s->analyzed, ctx, FCM_ERR_ARG,
            "direct_factor: %s solver not analyzed; call fcm_direct_analyze() first", s->ops->name);
  FCM_CHECK(values || s->nnz == 0, ctx, FCM_ERR_ARG, "direct_factor: values is NULL");
  s->factored = 0;
  s->info.failed_column = -1;
  s->info.factorizations++;
  for (fcm_index i = 0; i < s->n; i++)
    for (fcm_index p = s->row_ptr[i]; p < s->row_ptr[i + 1]; p++)
      FCM_CHECK(isfinite(values[p]), ctx, FCM_ERR_NUMERIC,
                "direct_factor: matrix entry (%lld, %d) is %g", (long long)i, s->col_idx[p],
                values[p]);
  fcm_timer_start(&t);
  if (s->n > 0) FCM_TRY(ctx, s->ops->factor(ctx, s->impl, values, &s->info));
  /* UMFPACK's rcond is min/max |diag U| of the row-scaled matrix: ~1e-16 or below for the
   * numerically singular systems (a free static body, too weak a quadrature) whose
   * rounding-level pivot CHOLMOD turned into "not positive definite". */
  FCM_CHECK(s->method != FCM_DIRECT_UMFPACK || s->n == 0 ||
                !(s->info.rcond < FCM__SINGULAR_UMFPACK_RCOND),
            ctx, FCM_ERR_SINGULAR,
            "direct_factor: umfpack pivots span %.3g (min/max |diag U|, threshold %.0e; n = %lld): "
            "the matrix is numerically singular; %s",
            s->info.rcond, FCM__SINGULAR_UMFPACK_RCOND, (long long)s->n, FCM__SINGULAR_HINT);
  s->norm_a = 0.0;
  for (fcm_index i = 0; i < s->n; i++) {
    double row = 0.0;
    for (fcm_index p = s->row_ptr[i]; p < s->row_ptr[i + 1]; p++)
      row += fabs(values[p]);
    s->norm_a = fmax(s->norm_a, row);
  }
  if (s->nnz > 0) memcpy(s->values, values, sizeof *values * (size_t)s->nnz);
  s->factored = 1;
cleanup:
  fcm_timer_stop(&t);
  if (s) s->info.time_factor += t.total;
  return st;
}

fcm_status fcm_direct_solve(fcm_direct *s, const double *b, double *x)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  fcm_timer t = fcm_timer_init();
  FCM_CHECK(s, ctx, FCM_ERR_ARG, "direct_solve: solver is NULL");
  FCM_CHECK(s->factored, ctx, FCM_ERR_ARG,
            "direct_solve: %s solver has no valid factorization; call fcm_direct_factor() first "
            "(and check its status)",
            s->ops->name);
  FCM_CHECK((b && x) || s->n == 0, ctx, FCM_ERR_ARG, "direct_solve: b or x is NULL");
  fcm_timer_start(&t);
  if (s->n > 0) {
    memcpy(s->b_copy, b, sizeof *b * (size_t)s->n);
    FCM_TRY(ctx, s->ops->solve(ctx, s->impl, b, x));
  }
  s->info.solves++;
  if (s->n > 0) {
    /* Residual check: a backward-stable solve of a nonsingular system has a
     * backward error of a few n eps; far above it the system is singular (b outside the
     * range, or a null direction blown up by a rounding-level pivot). */
    double nr = 0.0, nx = 0.0, nb = 0.0;
    for (fcm_index i = 0; i < s->n; i++) {
      double r = s->b_copy[i];
      for (fcm_index p = s->row_ptr[i]; p < s->row_ptr[i + 1]; p++)
        r -= s->values[p] * x[s->col_idx[p]];
      nr = fmax(nr, fabs(r));
      nx = fmax(nx, fabs(x[i]));
      nb = fmax(nb, fabs(s->b_copy[i]));
    }
    const double den = s->norm_a * nx + nb;
    const double eta = den > 0.0 ? nr / den : (nr > 0.0 ? INFINITY : 0.0);
    s->info.backward_error = isnan(eta) ? INFINITY : eta;
    FCM_CHECK(s->info.backward_error <= FCM__SINGULAR_BACKWARD_ERROR, ctx, FCM_ERR_SINGULAR,
              "direct_solve: %s solution has backward error %.3g (> %.0e; n = %lld): the "
              "matrix is numerically singular; %s",
              s->ops->name, s->info.backward_error, FCM__SINGULAR_BACKWARD_ERROR, (long long)s->n,
              FCM__SINGULAR_HINT);
  }
cleanup:
  fcm_timer_stop(&t);
  if (s) s->info.time_solve += t.total;
  return st;
}

void fcm_direct_get_info(const fcm_direct *s, fcm_direct_info *info)
{
  if (!info) return;
  if (s) {
    *info = s->info;
  } else {
    fcm_direct_info zero = {0};
    zero.failed_column = -1;
    *info = zero;
  }
}

void fcm_direct_destroy(fcm_direct **s)
{
  if (!s || !*s) return;
  fcm_ctx *ctx = (*s)->ctx;
  if ((*s)->impl) (*s)->ops->destroy(ctx, (*s)->impl);
  fcm__free(ctx, (*s)->row_ptr);
  fcm__free(ctx, (*s)->col_idx);
  fcm__free(ctx, (*s)->values);
  fcm__free(ctx, (*s)->b_copy);
  fcm__free(ctx, *s);
  *s = NULL;
}
