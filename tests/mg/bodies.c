/* Separated material is never merged: a body of two disjoint embedded balls (K + M) keeps
 * two bodies on every level of the hierarchy (no coarse DOF is shared between them), down
 * to a 2 x 1 x 1 grid (coarsening stops when a level would not shrink), and the V-cycle
 * still converges (factor <= 0.5). Odd cell counts (5 x 7 x 3) coarsen and converge, with
 * the V- and (no worse) the W-cycle. A space with constrained copies (XFEM split
 * hemisphere, constrain_ratio 1e-3) builds and converges. The same on Hex20 grids, whose
 * first coarse level is the Hex8 p-level on the same grid. */
#include "mg_util.h"

/* The two balls on a 16 x 8 x 8 grid of `type`: two bodies on every level. Hex8: 16x8x8 ->
 * 8x4x4 -> 4x2x2 -> 2x1x1 (the 1x1x1 grid would keep the two cells: no reduction, so
 * coarsening stops); Hex20: the p-level first keeps the grid (16x8x8 Hex20, then Hex8). */
static void balls(fcm_ctx *ctx, fcm_element_type type, int verbose)
{
  problem p;
  const int p_level = type == FCM_ELEMENT_HEX20;
  problem_balls_of(ctx, type, 8, &p);
  TEST_TRUE(fcm_space_num_bodies(p.space) == 2);
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 1; /* every level down to the coarsest grid */
  fcm_mg *mg = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg));
  TEST_TRUE(fcm_mg_num_levels(mg) == 4 + p_level);
  for (int l = 0; l < fcm_mg_num_levels(mg); l++) {
    fcm_mg_level_info li;
    TEST_OK(ctx, fcm_mg_get_level_info(mg, l, &li));
    TEST_TRUE(li.bodies == 2);
    TEST_TRUE(li.grid[0] == 16 >> (l > p_level ? l - p_level : 0));
    if (verbose)
      printf("balls %s level %d: grid %lldx%lldx%lld cells %lld copies %lld dofs %lld "
             "bodies %lld\n",
             p_level ? "Hex20" : "Hex8", l, (long long)li.grid[0], (long long)li.grid[1],
             (long long)li.grid[2], (long long)li.cells, (long long)li.copies, (long long)li.dofs,
             (long long)li.bodies);
    if (l == fcm_mg_num_levels(mg) - 1) TEST_TRUE(li.cells == 2 && li.copies == 16);
  }
  double *x = calloc((size_t)p.n, sizeof *x);
  fcm_mg_solve_info si;
  TEST_OK(ctx, fcm_mg_solve(mg, p.b, x, 1e-8, 100, &si));
  TEST_TRUE(si.convergence_factor <= 0.5);
  if (verbose) printf("balls: factor %.3f, %d cycles\n", si.convergence_factor, si.cycles);
  free(x);
  fcm_mg_destroy(&mg);
  problem_free(&p);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const int verbose = getenv("FCM_TEST_VERBOSE") != NULL;
  balls(ctx, FCM_ELEMENT_HEX8, verbose);
  balls(ctx, FCM_ELEMENT_HEX20, verbose);
  problem p;
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 1;
  fcm_mg *mg = NULL;
  double *x = NULL;
  fcm_mg_solve_info si;

  /* odd counts, uncut box clamped at x = 0 */
  {
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1.4, 0.6};
    const fcm_index cells[3] = {5, 7, 3};
    memset(&p, 0, sizeof p);
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &p.mesh));
    TEST_OK(ctx, fcm_space_create(ctx, p.mesh, NULL, &p.space));
    finish_space(ctx, &p, 0);
    const double flo[3] = {0, -1, -1}, fhi[3] = {0, 2, 2};
    clamp_box(ctx, &p, flo, fhi);
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg));
    TEST_TRUE(fcm_mg_num_levels(mg) == 4); /* 5x7x3 -> 3x4x2 -> 2x2x1 -> 1x1x1 */
    for (int l = 0; l < fcm_mg_num_levels(mg); l++) {
      fcm_mg_level_info li;
      TEST_OK(ctx, fcm_mg_get_level_info(mg, l, &li));
      TEST_TRUE(li.bodies == 1);
    }
    x = calloc((size_t)p.n, sizeof *x);
    TEST_OK(ctx, fcm_mg_solve(mg, p.b, x, 1e-8, 100, &si));
    TEST_TRUE(si.convergence_factor <= 0.5);
    if (verbose) printf("odd box: factor %.3f, %d cycles\n", si.convergence_factor, si.cycles);
    fcm_mg_destroy(&mg);
    /* the W-cycle reduces at least as well */
    fcm_mg_options ow = o;
    ow.cycle_index = 2;
    const double fv = si.convergence_factor;
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &ow, &mg));
    memset(x, 0, sizeof *x * (size_t)p.n);
    TEST_OK(ctx, fcm_mg_solve(mg, p.b, x, 1e-8, 100, &si));
    TEST_TRUE(si.convergence_factor <= fv + 0.02);
    if (verbose) printf("odd box W: factor %.3f, %d cycles\n", si.convergence_factor, si.cycles);
    free(x);
    fcm_mg_destroy(&mg);
    problem_free(&p);
  }
  /* constrained copies (elements use other nodes' copies in place of tiny ones): corners
   * of coarse cells that no fine copy interpolates from are constrained, the coarse
   * matrices stay positive definite (this failed with "row ... has no diagonal entry") */
  problem_hemisphere_with(ctx, 16, 2, 1e-3, &p);
  TEST_TRUE(fcm_space_num_constrained_copies(p.space) > 0);
  TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, NULL, &mg));
  x = calloc((size_t)p.n, sizeof *x);
  if (mg) TEST_OK(ctx, fcm_mg_solve(mg, p.b, x, 1e-8, 200, &si));
  TEST_TRUE(si.convergence_factor <= 0.8);
  if (verbose)
    printf("split, constrained copies: factor %.3f, %d cycles\n", si.convergence_factor, si.cycles);
  free(x);
  fcm_mg_destroy(&mg);
  problem_free(&p);
  /* the same on Hex20 (constraint targets may be mid-edge copies: the p-level injects them) */
  problem_hemisphere_of(ctx, FCM_ELEMENT_HEX20, 12, 2, 1e-2, &p);
  TEST_TRUE(fcm_space_num_constrained_copies(p.space) > 0);
  TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, NULL, &mg));
  x = calloc((size_t)p.n, sizeof *x);
  if (mg) TEST_OK(ctx, fcm_mg_solve(mg, p.b, x, 1e-8, 200, &si));
  TEST_TRUE(si.convergence_factor <= 0.8);
  if (verbose)
    printf("split Hex20, constrained copies: factor %.3f, %d cycles\n", si.convergence_factor,
           si.cycles);
  free(x);
  fcm_mg_destroy(&mg);
  problem_free(&p);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
