/* Additive Schwarz setup on a matrix whose pattern differs from the one at creation: the
 * setup finds each block's entries where they now lie, so S_K and z = S r are bit for bit
 * those of a preconditioner created on the new matrix. Patterns: a band of half-width 3 and
 * one of half-width 5 (every row's entries shift), both ways, and a block whose entries are
 * not all stored in the narrow band (scanned) but are in the wide one. The block smoother's
 * variant (the S_K only) holds each of these well-conditioned blocks as the inverse X of its
 * Cholesky factor, lower triangular with X^T X the preconditioner's S_K to rounding, and
 * refuses the apply. */
#include "solve/solve_impl.h"
#include "solve_test_util.h"

#include <math.h>

enum { N = 40, NB = 5 };
static const fcm_index ptr[NB + 1] = {0, 4, 8, 12, 15, 19};
static const fcm_index dofs[19] = {0,  1,  2,  3,  2,  3,  4,  5,  10, 11,
                                   12, 13, 20, 22, 25, 30, 31, 32, 33};

/* Symmetric, diagonally dominant (positive definite) band matrix of half-width w, values
 * from seed. */
static fcm_csr *band(fcm_ctx *ctx, int w, unsigned seed)
{
  fcm_index *ri = malloc(sizeof *ri * N * N), *ci = malloc(sizeof *ci * N * N), nt = 0;
  double *v = malloc(sizeof *v * N * N), off[N][N], row[N] = {0};
  rng r = {seed};
  for (int i = 0; i < N; i++)
    for (int j = 0; j <= i; j++) {
      off[i][j] = off[j][i] = (i - j <= w && i != j) ? rng_uniform(&r) : 0.0;
      row[i] += fabs(off[i][j]);
      if (j < i) row[j] += fabs(off[i][j]);
    }
  for (int i = 0; i < N; i++)
    for (int j = 0; j < N; j++)
      if (abs(i - j) <= w) ri[nt] = i, ci[nt] = j, v[nt++] = i == j ? row[i] + 1.0 : off[i][j];
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, N, N, nt, ri, ci, v, FCM_CSR_SYMMETRIC, &A));
  free(ri);
  free(ci);
  free(v);
  return A;
}

/* P (set up last on A) against a preconditioner created on A: S_K and S r bit for bit. */
static void same_as_fresh(fcm_ctx *ctx, const fcm_schwarz *P, const fcm_csr *A, const char *what)
{
  fcm_schwarz *Q = NULL;
  double r[N], z1[N], z2[N];
  TEST_OK(ctx, fcm_schwarz_create(ctx, A, NB, ptr, dofs, NULL, &Q));
  for (fcm_index k = 0; k < NB; k++) {
    const fcm_index *d1 = NULL, *d2 = NULL;
    const double *S1 = NULL, *S2 = NULL;
    const int m = fcm__schwarz_block(P, k, &d1, &S1);
    TEST_TRUE(fcm__schwarz_block(Q, k, &d2, &S2) == m);
    if (memcmp(S1, S2, sizeof *S1 * (size_t)m * (size_t)m))
      TEST_FAIL_("%s: block %lld's S_K differs from a fresh preconditioner's", what, (long long)k);
  }
  rng g = {11};
  for (int i = 0; i < N; i++)
    r[i] = rng_uniform(&g);
  TEST_OK(ctx, fcm_schwarz_apply(P, r, z1));
  TEST_OK(ctx, fcm_schwarz_apply(Q, r, z2));
  if (memcmp(z1, z2, sizeof z1)) TEST_FAIL_("%s: S r differs from a fresh preconditioner's", what);
  fcm_schwarz_destroy(&Q);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  fcm_csr *A3 = band(ctx, 3, 1), *A5 = band(ctx, 5, 2), *B3 = band(ctx, 3, 3);
  fcm_schwarz *P = NULL, *Pb = NULL;
  TEST_OK(ctx, fcm_schwarz_create(ctx, A3, NB, ptr, dofs, NULL, &P));
  same_as_fresh(ctx, P, A3, "created");
  TEST_OK(ctx, fcm_schwarz_setup(P, A5));
  same_as_fresh(ctx, P, A5, "narrow -> wide band");
  TEST_OK(ctx, fcm_schwarz_setup(P, B3));
  same_as_fresh(ctx, P, B3, "wide -> narrow band");
  TEST_OK(ctx, fcm_schwarz_setup(P, A5));
  same_as_fresh(ctx, P, A5, "narrow -> wide band again");
  TEST_OK(ctx, fcm_schwarz_setup(P, A5));
  same_as_fresh(ctx, P, A5, "wide band twice");

  /* the block smoother's variant: the same S_K, no apply */
  TEST_OK(ctx, fcm__schwarz_create_blocks(ctx, A5, NB, ptr, dofs, &Pb));
  int factors = 0;
  TEST_OK(ctx, fcm_schwarz_setup(Pb, A3));
  TEST_OK(ctx, fcm_schwarz_setup(P, A3));
  for (fcm_index k = 0; k < NB; k++) {
    const fcm_index *d1 = NULL, *d2 = NULL;
    const double *S1 = NULL, *S2 = NULL;
    const int m = fcm__schwarz_block(P, k, &d1, &S1);
    TEST_TRUE(fcm__schwarz_block(Pb, k, &d2, &S2) == m);
    if (!fcm__schwarz_block_factor(Pb, k)) { /* S_K's lower triangle, packed */
      for (int i = 0; i < m; i++)
        for (int j = 0; j <= i; j++)
          TEST_TRUE(S2[FCM__SCHWARZ_PACKED(i, j)] == S1[i * m + j]);
      continue;
    }
    factors++; /* S2 holds X's lower triangle (packed), with S_K = X^T X */
    TEST_TRUE(fcm__schwarz_slot_size(Pb, k) == (size_t)(m * (m + 1) / 2));
    double smax = 0.0, diff = 0.0;
    for (int i = 0; i < m; i++)
      for (int j = 0; j < m; j++) {
        double s = 0.0;
        for (int q = i > j ? i : j; q < m; q++)
          s += S2[FCM__SCHWARZ_PACKED(q, i)] * S2[FCM__SCHWARZ_PACKED(q, j)];
        smax = fmax(smax, fabs(S1[i * m + j]));
        diff = fmax(diff, fabs(s - S1[i * m + j]));
      }
    TEST_TRUE(diff <= 1e-14 * smax);
  }
  TEST_TRUE(factors == NB); /* every block here is well conditioned */
  double r[N] = {0}, z[N];
  TEST_ERR(ctx, fcm_schwarz_apply(Pb, r, z), FCM_ERR_ARG, "block smoother's blocks only");

  fcm_schwarz_destroy(&P);
  fcm_schwarz_destroy(&Pb);
  fcm_csr_destroy(&A3);
  fcm_csr_destroy(&A5);
  fcm_csr_destroy(&B3);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
