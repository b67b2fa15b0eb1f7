/* The slab orders that let the threads share the smoothers are sound on every level of the
 * uncut cube, the embedded hemisphere, the hemisphere cut through (two bodies), the two balls
 * and the Hex20 hemisphere: every row and block once, no coupled rows or touching blocks in
 * two slabs of one colour (fcm__mg_slabs_check()). The orders leave work to share: the finest
 * Hex8 level has two thick row slabs and the thin one between them, and the hemisphere's
 * blocks lie in several slabs of each colour; Hex20's finest rows, numbered corners first,
 * stay in one slab. A cycle and a CG + multigrid solve on the hemisphere give bitwise the same
 * result for 1 and 2 threads. */
#include "mg/mg_impl.h"
#include "mg_util.h"

#include <omp.h>

/* Check every level of a multigrid on p; the largest row and block slab counts of level 0. */
static void check_levels(fcm_ctx *ctx, const problem *p, fcm_index *rows0, fcm_index *blocks0)
{
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 100;
  fcm_mg *mg = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, &o, &mg));
  if (!mg) return;
  TEST_TRUE(fcm_mg_num_levels(mg) >= 3);
  for (int l = 0; l + 1 < fcm_mg_num_levels(mg); l++) {
    fcm_index rs = -1, bs = -1;
    TEST_OK(ctx, fcm__mg_slabs_check(mg, l, &rs, &bs));
    TEST_TRUE(rs >= 1); /* every level but the coarsest is smoothed */
    TEST_TRUE(bs >= 0);
    if (l == 0) *rows0 = rs, *blocks0 = bs;
  }
  fcm_index rs = 0, bs = 0;
  TEST_ERR(ctx, fcm__mg_slabs_check(mg, fcm_mg_num_levels(mg) - 1, &rs, &bs), FCM_ERR_ARG, "level");
  fcm_mg_destroy(&mg);
}

/* One cycle and a CG + multigrid solve with `threads` threads. */
static double *solve(fcm_ctx *ctx, const problem *p, int threads)
{
  omp_set_num_threads(threads);
  fcm_mg *mg = NULL;
  double *x = calloc((size_t)p->n, sizeof *x), *y = calloc((size_t)p->n, sizeof *y);
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, NULL, &mg));
  TEST_OK(ctx, fcm_mg_cycle(mg, p->b, y));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = 1e-9;
  fcm_krylov_info ki;
  TEST_OK(ctx,
          fcm_cg_solve(ctx, p->n, fcm_csr_operator, p->A, fcm_mg_operator, mg, p->b, x, &ko, &ki));
  for (fcm_index i = 0; i < p->n; i++)
    x[i] += y[i]; /* both in one vector: a difference in either shows */
  free(y);
  fcm_mg_destroy(&mg);
  return x;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const int threads = omp_get_max_threads();
  for (int kind = 0; kind < 5; kind++) {
    problem p;
    if (kind == 0)
      problem_cube(ctx, 12, &p);
    else if (kind == 1)
      problem_hemisphere(ctx, 16, 0, &p);
    else if (kind == 2)
      problem_hemisphere(ctx, 12, 2, &p);
    else if (kind == 3)
      problem_balls(ctx, 8, &p);
    else
      problem_hemisphere_of(ctx, FCM_ELEMENT_HEX20, 8, 0, 1e-9, &p);
    fcm_index rows0 = 0, blocks0 = 0;
    check_levels(ctx, &p, &rows0, &blocks0);
    if (kind == 0) TEST_TRUE(rows0 == 3 && blocks0 == 0); /* uncut: no blocks */
    if (kind == 1) {
      TEST_TRUE(rows0 == 3);
      TEST_TRUE(blocks0 >= 8); /* at least 4 slabs of each colour */
      double *x1 = solve(ctx, &p, 1), *x2 = solve(ctx, &p, 2);
      TEST_TRUE(memcmp(x1, x2, sizeof *x1 * (size_t)p.n) == 0);
      free(x1), free(x2);
      omp_set_num_threads(threads);
    }
    if (kind == 4) TEST_TRUE(rows0 == 1 && blocks0 >= 2);
    problem_free(&p);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
