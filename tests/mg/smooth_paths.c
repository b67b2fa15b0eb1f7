/* The sweeps the cycle runs agree with one row at a time: on every smoothed level of the uncut
 * cube and the cut hemisphere (Hex8), one SGS step and one block sweep through the paths the
 * cycle takes (a copy's three rows of one column pattern summed together, their Gauss-Seidel
 * updates chained through the copy's 3 x 3 block; the block products from S_K's lower
 * triangle, or X^T (X r) where the block holds the inverse X of its Cholesky factor) give the
 * iterate of the reference (a row at a time, the full S_K) to rounding,
 * with the block sweep symmetric and one way. Most copies of level 0 take the three-row path,
 * and the sweeps move x by far more than the tolerance. The X blocks' sizes modulo four are
 * printed (the X r product takes four rows at a time; mg_block_apply covers every size). */
#include "mg/levels_impl.h"
#include "mg_util.h"

#include <math.h>

/* Max |x_fast - x_plain| against max |x_plain - x| over each smoothed level of a multigrid on
 * p with block_sweep; the copies of level 0 on the three-row path, and its blocks held as
 * X (cut: some, the cut cells' blocks; else none, the uncut cube has no blocks). */
static void check(fcm_ctx *ctx, const problem *p, int block_sweep, int cut)
{
  fcm_mg_options o = fcm_mg_options_default();
  o.block_sweep = block_sweep;
  o.coarse_dofs = 100;
  fcm_mg *mg = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, &o, &mg));
  if (!mg) return;
  TEST_TRUE(fcm_mg_num_levels(mg) >= 2);
  for (int l = 0; l + 1 < fcm_mg_num_levels(mg); l++) {
    fcm_mg_level_info li;
    TEST_OK(ctx, fcm_mg_get_level_info(mg, l, &li));
    const fcm_index n = li.dofs;
    double *b = malloc(sizeof *b * (size_t)n), *x = malloc(sizeof *x * (size_t)n);
    double *xf = malloc(sizeof *xf * (size_t)n), *xp = malloc(sizeof *xp * (size_t)n);
    for (fcm_index i = 0; i < n; i++) {
      b[i] = l == 0 ? p->b[i] : sin(0.37 * (double)i);
      x[i] = 1e-3 * cos(0.11 * (double)i);
    }
    fcm_index triples = -1, factors = -1;
    TEST_OK(ctx, fcm__mg_smooth_paths(mg, l, b, x, xf, xp, &triples, &factors));
    double diff = 0.0, move = 0.0, size = 0.0;
    for (fcm_index i = 0; i < n; i++) {
      diff = fmax(diff, fabs(xf[i] - xp[i]));
      move = fmax(move, fabs(xp[i] - x[i]));
      size = fmax(size, fabs(xp[i]));
    }
    printf("level %d: %lld DOFs, %lld copies of three rows together, %lld blocks as X^T X, "
           "max |x_fast - x_plain| %.2e, max |x_plain - x| %.2e, max |x_plain| %.2e\n",
           l, (long long)n, (long long)triples, (long long)factors, diff, move, size);
    TEST_TRUE(isfinite(diff) && diff <= 1e-12 * size);
    TEST_TRUE(move > 1e6 * diff && move > 0.0);
    if (l == 0) TEST_TRUE(3 * triples >= n / 2 && (factors > 0) == cut);
    if (cut) {
      int rem[4] = {0, 0, 0, 0};
      for (fcm_index k = 0; k < fcm__schwarz_num_blocks(mg->lev[l].blk); k++) {
        const fcm_index *d = NULL;
        const double *S = NULL;
        const int m = fcm__schwarz_block(mg->lev[l].blk, k, &d, &S);
        if (m > 4 && fcm__schwarz_block_factor(mg->lev[l].blk, k)) rem[m % 4]++;
      }
      printf("level %d: X blocks of more than 4 DOFs by size mod 4: %d, %d, %d, %d\n", l, rem[0],
             rem[1], rem[2], rem[3]);
    }
    free(b);
    free(x);
    free(xf);
    free(xp);
  }
  fcm_index t = 0;
  double z = 0.0;
  TEST_ERR(ctx, fcm__mg_smooth_paths(mg, fcm_mg_num_levels(mg) - 1, &z, &z, &z, &z, &t, &t),
           FCM_ERR_ARG, "level");
  fcm_mg_destroy(&mg);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  problem p;
  problem_cube(ctx, 8, &p);
  check(ctx, &p, 0, 0);
  problem_free(&p);
  problem_hemisphere(ctx, 16, 1, &p);
  check(ctx, &p, 0, 1);
  check(ctx, &p, 1, 1);
  problem_free(&p);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
