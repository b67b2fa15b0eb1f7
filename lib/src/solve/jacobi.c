/* Jacobi preconditioners from a CSR matrix: the inverse |diagonal|, or the inverses of
 * the nodal 3x3 diagonal blocks with a guarded fallback for blocks that are not SPD. */
#include "la/mat3.h"
#include "solve/solve_impl.h"

#include <math.h>

struct fcm_jacobi {
  fcm_ctx *ctx;
  fcm_index n;
  fcm_jacobi_kind kind;
  double *inv; /* SCALAR: n inverse diagonals; BLOCK3: n/3 row-major 3x3 inverses */
  fcm_index fallbacks;
  int ready;
};

static double entry(const fcm_csr *A, const double *vals, fcm_index i, fcm_index j)
{
  fcm_index p = fcm_csr_position(A, i, j);
  return p >= 0 ? vals[p] : 0.0;
}

/* 1/|d| for a diagonal entry of row i; a negative d counts as a fallback. */
static fcm_status inverse_diagonal(fcm_ctx *ctx, fcm_index i, double d, double *inv,
                                   fcm_index *fallbacks)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(isfinite(d), ctx, FCM_ERR_NUMERIC, "jacobi: diagonal entry of row %lld is %g",
            (long long)i, d);
  FCM_CHECK(d != 0.0, ctx, FCM_ERR_SINGULAR,
            "jacobi: diagonal entry of row %lld is zero (Jacobi needs a_ii != 0)", (long long)i);
  if (d < 0.0) (*fallbacks)++;
  *inv = 1.0 / fabs(d);
cleanup:
  return st;
}

/* Cholesky test of the symmetric 3x3 B with pivots relative to its largest diagonal. */
static int spd3(const double B[9])
{
  double dmax = FCM_MAX(FCM_MAX(fabs(B[0]), fabs(B[4])), fabs(B[8]));
  double tol = 1e-12 * dmax;
  double l00 = B[0];
  if (!(l00 > tol)) return 0;
  l00 = sqrt(l00);
  double l10 = B[3] / l00, l20 = B[6] / l00;
  double d1 = B[4] - l10 * l10;
  if (!(d1 > tol)) return 0;
  double l11 = sqrt(d1);
  double l21 = (B[7] - l20 * l10) / l11;
  double d2 = B[8] - l20 * l20 - l21 * l21;
  return d2 > tol;
}

fcm_status fcm_jacobi_setup(fcm_jacobi *P, const fcm_csr *A)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P ? P->ctx : NULL;
  fcm_index nr = -1, nc = -1;
  FCM_CHECK(P && A, ctx, FCM_ERR_ARG, "jacobi_setup: NULL argument");
  fcm_csr_get_size(A, &nr, &nc, NULL);
  FCM_CHECK(nr == P->n && nc == P->n, ctx, FCM_ERR_ARG,
            "jacobi_setup: matrix is %lld x %lld, the preconditioner was created for %lld x %lld",
            (long long)nr, (long long)nc, (long long)P->n, (long long)P->n);
  P->ready = 0;
  P->fallbacks = 0;
  const double *vals = fcm_csr_values_read(A);
  if (P->kind == FCM_JACOBI_SCALAR) {
    for (fcm_index i = 0; i < P->n; i++)
      FCM_TRY(ctx, inverse_diagonal(ctx, i, entry(A, vals, i, i), &P->inv[i], &P->fallbacks));
  } else {
    for (fcm_index k = 0; k < P->n / 3; k++) {
      double B[9], *Binv = P->inv + 9 * k;
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          B[3 * i + j] = entry(A, vals, 3 * k + i, 3 * k + j);
      for (int i = 0; i < 9; i++)
        FCM_CHECK(isfinite(B[i]), ctx, FCM_ERR_NUMERIC,
                  "jacobi: entry (%lld, %lld) of the 3x3 block of node %lld is %g",
                  (long long)(3 * k + i / 3), (long long)(3 * k + i % 3), (long long)k, B[i]);
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < i; j++)
          B[3 * i + j] = B[3 * j + i] = 0.5 * (B[3 * i + j] + B[3 * j + i]);
      if (spd3(B) && fcm__mat3_inv(B, Binv) > 0.0) {
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < i; j++)
            Binv[3 * i + j] = Binv[3 * j + i] = 0.5 * (Binv[3 * i + j] + Binv[3 * j + i]);
        continue;
      }
      /* not SPD: inverse |diagonal| of the block */
      fcm_index dummy = 0;
      for (int i = 0; i < 9; i++)
        Binv[i] = 0.0;
      for (int i = 0; i < 3; i++)
        FCM_TRY(ctx, inverse_diagonal(ctx, 3 * k + i, B[4 * i], &Binv[4 * i], &dummy));
      P->fallbacks++;
    }
  }
  P->ready = 1;
cleanup:
  return st;
}

fcm_status fcm_jacobi_create(fcm_ctx *ctx, const fcm_csr *A, fcm_jacobi_kind kind, fcm_jacobi **out)
{
  fcm_status st = FCM_OK;
  fcm_jacobi *P = NULL;
  fcm_index nr = -1, nc = -1;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "jacobi_create: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(A, ctx, FCM_ERR_ARG, "jacobi_create: matrix is NULL");
  FCM_CHECK(kind == FCM_JACOBI_SCALAR || kind == FCM_JACOBI_BLOCK3, ctx, FCM_ERR_ARG,
            "jacobi_create: kind = %d is not FCM_JACOBI_SCALAR (%d) or FCM_JACOBI_BLOCK3 (%d)",
            (int)kind, (int)FCM_JACOBI_SCALAR, (int)FCM_JACOBI_BLOCK3);
  fcm_csr_get_size(A, &nr, &nc, NULL);
  FCM_CHECK(nr == nc, ctx, FCM_ERR_ARG, "jacobi_create: matrix is %lld x %lld, not square",
            (long long)nr, (long long)nc);
  FCM_CHECK(kind != FCM_JACOBI_BLOCK3 || nr % 3 == 0, ctx, FCM_ERR_ARG,
            "jacobi_create: 3x3 block Jacobi needs a size divisible by 3, got %lld", (long long)nr);
  FCM_ALLOC(ctx, 1, P);
  P->ctx = ctx;
  P->n = nr;
  P->kind = kind;
  FCM_ALLOC(ctx, kind == FCM_JACOBI_SCALAR ? (size_t)nr : (size_t)(3 * nr), P->inv);
  FCM_TRY(ctx, fcm_jacobi_setup(P, A));
  *out = P;
  P = NULL;
cleanup:
  fcm_jacobi_destroy(&P);
  return st;
}

fcm_status fcm_jacobi_apply(const fcm_jacobi *P, const double *r, double *z)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P ? P->ctx : NULL;
  FCM_CHECK(P, ctx, FCM_ERR_ARG, "jacobi_apply: preconditioner is NULL");
  FCM_CHECK(P->ready, ctx, FCM_ERR_ARG, "jacobi_apply: the last setup failed");
  FCM_CHECK((r && z) || P->n == 0, ctx, FCM_ERR_ARG, "jacobi_apply: r or z is NULL");
  FCM_CHECK(!r || r != z, ctx, FCM_ERR_ARG, "jacobi_apply: r and z must be different arrays");
  const fcm_index n = P->n;
  const double *inv = P->inv;
  if (P->kind == FCM_JACOBI_SCALAR) {
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx))                                     \
    schedule(static) if (n >= FCM__SOLVE_PARALLEL_MIN)
    for (fcm_index i = 0; i < n; i++)
      z[i] = inv[i] * r[i];
  } else {
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx))                                     \
    schedule(static) if (n >= FCM__SOLVE_PARALLEL_MIN)
    for (fcm_index k = 0; k < n / 3; k++)
      fcm__mat3_mulv(inv + 9 * k, r + 3 * k, z + 3 * k);
  }
cleanup:
  return st;
}

fcm_status fcm_jacobi_operator(void *user, const double *r, double *z)
{
  return fcm_jacobi_apply((const fcm_jacobi *)user, r, z);
}

fcm_index fcm_jacobi_num_fallbacks(const fcm_jacobi *P)
{
  return P ? P->fallbacks : 0;
}

void fcm_jacobi_destroy(fcm_jacobi **P)
{
  if (!P || !*P) return;
  fcm__free((*P)->ctx, (*P)->inv);
  fcm__free((*P)->ctx, *P);
  *P = NULL;
}
