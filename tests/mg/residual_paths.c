/* Level 0's residual (fcm__mg_residual(): a copy's three rows of one pattern side by side)
 * against b + fcm_csr_apply(A, -1, x, 0, .), bit for bit, on the uncut cube and the cut
 * hemisphere (Hex8), with one and two threads; most rows go three at a time. The matrix
 * values are scaled per entry so that a term out of order would change the rounding. */
#include "mg/levels_impl.h"
#include "mg_util.h"

#include <math.h>

static void check_residual(fcm_ctx *ctx, const fcm_mg *mg, const fcm_csr *A, int nt)
{
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  double *b = malloc(sizeof *b * (size_t)n), *x = malloc(sizeof *x * (size_t)n);
  double *r = malloc(sizeof *r * (size_t)n), *y = malloc(sizeof *y * (size_t)n);
  for (fcm_index i = 0; i < n; i++) {
    b[i] = sin(0.37 * (double)i);
    x[i] = 1e-3 * cos(0.11 * (double)i) + 1e-2;
  }
  fcm__mg_residual(mg, b, x, r);
  TEST_OK(ctx, fcm_csr_apply(A, -1.0, x, 0.0, y));
  fcm_index differ = 0, triples = 0;
  for (fcm_index i = 0; i < n; i++) {
    y[i] += b[i];
    differ += memcmp(&r[i], &y[i], sizeof *r) != 0;
  }
  for (fcm_index i = 0; mg->lev[0].rows.triple && i < n; i++)
    triples += mg->lev[0].rows.triple[i] != 0;
  printf("residual, %d threads: %lld rows, %lld copies of three rows together, %lld differ\n", nt,
         (long long)n, (long long)triples, (long long)differ);
  TEST_TRUE(differ == 0 && 3 * triples >= n / 2);
  free(b);
  free(x);
  free(r);
  free(y);
}

static void check(fcm_ctx *ctx, const problem *p)
{
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 100;
  fcm_mg *mg = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, &o, &mg));
  if (!mg) return;
  TEST_TRUE(fcm_mg_num_levels(mg) >= 2);
  fcm_index nnz = 0;
  fcm_csr_get_size(p->A, NULL, NULL, &nnz);
  double *v = fcm_csr_values(p->A);
  for (fcm_index q = 0; q < nnz; q++) /* every entry its own rounding */
    v[q] *= 1.0 + 1e-3 * sin(0.7 * (double)q);
  for (int nt = 1; nt <= 2; nt++) {
    TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, nt));
    check_residual(ctx, mg, p->A, nt);
  }
  fcm_mg_destroy(&mg);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  problem p;
  problem_cube(ctx, 8, &p);
  check(ctx, &p);
  problem_free(&p);
  problem_hemisphere(ctx, 12, 1, &p);
  check(ctx, &p);
  problem_free(&p);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
