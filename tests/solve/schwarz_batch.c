/* The block smoother's set-up factors blocks of one size four at a time (build_batch()): each
 * block's slot (X of its Cholesky factor, or S_K where a block takes another path) and its
 * factor flag are bit for bit those of a block smoother holding that block alone (set up one
 * block at a time), on a dense symmetric matrix: blocks of six DOFs in batches, a batch with
 * an indefinite block (its Cholesky factor does not exist: the eigen path) and one with a
 * nearly singular block (the factor exists, the bound fails: S_K by the product), a batch of
 * mixed sizes and a last short batch; set up twice (the second set-up writes X's lower triangle
 * alone, the zeros above staying), on new values in between. */
#include "solve/solve_impl.h"
#include "solve_test_util.h"

#include <math.h>

enum { N = 48, NB = 17, M = 6 };

/* Symmetric N x N matrix, all entries stored: diagonally dominant from seed, but row 30 with a
 * negative diagonal (block 5 indefinite) and rows 40, 41 equal up to 1e-12 (block 9 nearly
 * singular). */
static fcm_csr *dense(fcm_ctx *ctx, unsigned seed)
{
  fcm_index *ri = malloc(sizeof *ri * N * N), *ci = malloc(sizeof *ci * N * N), nt = 0;
  double *v = malloc(sizeof *v * N * N), a[N][N], row[N] = {0};
  rng r = {seed};
  for (int i = 0; i < N; i++)
    for (int j = 0; j < i; j++) {
      a[i][j] = a[j][i] = rng_uniform(&r) - 0.5;
      row[i] += fabs(a[i][j]), row[j] += fabs(a[i][j]);
    }
  for (int i = 0; i < N; i++)
    a[i][i] = row[i] + 1.0;
  a[30][30] = -a[30][30];
  for (int j = 0; j < N; j++) /* row and column 41 = row 40 up to 1e-12 */
    if (j != 40 && j != 41) a[41][j] = a[j][41] = a[40][j] * (1.0 + 1e-12);
  a[41][41] = a[40][40] * (1.0 + 1e-12), a[40][41] = a[41][40] = a[40][40];
  for (int i = 0; i < N; i++)
    for (int j = 0; j < N; j++)
      ri[nt] = i, ci[nt] = j, v[nt++] = a[i][j];
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, N, N, nt, ri, ci, v, FCM_CSR_SYMMETRIC, &A));
  free(ri), free(ci), free(v);
  return A;
}

/* Six DOFs each, from the well-behaved ones (all but 30, 40, 41), but block 5 with DOF 30
 * (indefinite), block 9 with 40 and 41 (nearly singular) and block 13 of five DOFs. Batches
 * of four: 0-3 (all X), 4-7 (one by the eigen path), 8-11 (one by the product), 12-15 (mixed
 * sizes: one at a time), 16 (short). */
static fcm_index ptr[NB + 1], dofs[NB * M];

static void make_blocks(void)
{
  fcm_index good[N], ng = 0, q = 0;
  for (fcm_index i = 0; i < N; i++)
    if (i != 30 && i != 40 && i != 41) good[ng++] = i;
  for (int k = 0; k < NB; k++) {
    const int m = k == 13 ? M - 1 : M;
    ptr[k] = q;
    for (int i = 0; i < m; i++) /* 5 i mod 45 distinct for i < 9 */
      dofs[q++] = good[(4 * k + 5 * i) % ng];
    if (k == 5) dofs[ptr[k]] = 30;
    if (k == 9) dofs[ptr[k]] = 40, dofs[ptr[k] + 1] = 41;
    ptr[k + 1] = q;
  }
}

static void compare(fcm_ctx *ctx, const fcm_schwarz *P, const fcm_csr *A, const char *what)
{
  int factors = 0;
  for (fcm_index k = 0; k < NB; k++) {
    fcm_schwarz *Q = NULL;
    const fcm_index one[2] = {0, ptr[k + 1] - ptr[k]};
    TEST_OK(ctx, fcm__schwarz_create_blocks(ctx, A, 1, one, dofs + ptr[k], &Q));
    if (!Q) return;
    const fcm_index *d1 = NULL, *d2 = NULL;
    const double *S1 = NULL, *S2 = NULL;
    const int m = fcm__schwarz_block(P, k, &d1, &S1);
    TEST_TRUE(fcm__schwarz_block(Q, 0, &d2, &S2) == m);
    TEST_TRUE(fcm__schwarz_block_factor(P, k) == fcm__schwarz_block_factor(Q, 0));
    factors += fcm__schwarz_block_factor(P, k);
    TEST_TRUE(fcm__schwarz_slot_size(P, k) == (size_t)(m * (m + 1) / 2));
    if (memcmp(S1, S2, sizeof *S1 * fcm__schwarz_slot_size(P, k)))
      TEST_FAIL_("%s: block %lld's slot differs from the block's set up alone", what, (long long)k);
    fcm_schwarz_destroy(&Q);
  }
  /* every block but the indefinite (5) and the nearly singular (9) one holds X */
  TEST_TRUE(factors == NB - 2);
  TEST_TRUE(!fcm__schwarz_block_factor(P, 5) && !fcm__schwarz_block_factor(P, 9));
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  make_blocks();
  fcm_csr *A = dense(ctx, 3), *B = dense(ctx, 5);
  fcm_schwarz *P = NULL;
  TEST_OK(ctx, fcm__schwarz_create_blocks(ctx, A, NB, ptr, dofs, &P));
  compare(ctx, P, A, "created");
  TEST_OK(ctx, fcm_schwarz_setup(P, B));
  compare(ctx, P, B, "set up on new values");
  TEST_OK(ctx, fcm_schwarz_setup(P, A));
  compare(ctx, P, A, "set up again");
  fcm_schwarz_destroy(&P);
  fcm_csr_destroy(&A);
  fcm_csr_destroy(&B);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
