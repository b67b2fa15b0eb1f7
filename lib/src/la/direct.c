/* fcm_direct: the phase-checked front of the sparse direct solvers (analyze once,
 * factor and solve many times); the library calls live in the adapter files. */
#include "la/la_impl.h"

#include <math.h>

struct fcm_direct {
  fcm_ctx *ctx;
  const fcm__direct_ops *ops;
  fcm_direct_method method;
  void *impl;
  fcm_index n, nnz;
  fcm_index *row_ptr; /* copy of the pattern's rows, to name entries in messages */
  int *col_idx;
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
  fcm_timer_start(&t);
  if (s->n > 0) FCM_TRY(ctx, s->ops->analyze(ctx, s->impl, &s->info));
  s->analyzed = 1;
cleanup:
  fcm_timer_stop(&t);
  if (s) s->info.time_analyze += t.total;
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
  if (s->n > 0) FCM_TRY(ctx, s->ops->solve(ctx, s->impl, b, x));
  s->info.solves++;
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
  fcm__free(ctx, *s);
  *s = NULL;
}
