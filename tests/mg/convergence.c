/* Multigrid on Hex8 and Hex20 box grids, static linear elasticity (argument: cube, hemisphere, cut:
 * an XFEM plane cut through the hemisphere's top, split: the plane through the whole body,
 * two bodies each clamped, hollow: a hollow ball with three holes; with the suffix -hex20 on Hex20
 * grids, where the first coarse level is the p-level Hex20 -> Hex8 on the same grid, and with the
 * suffix -jacobi smoothed by damped Jacobi, omega left at the default (the smoother's own,
 * fcm_mg_smoother_omega()); then the cell
 * counts n, default 4 8 16): the V-cycle and the two-grid convergence factors stay below 0.8 for
 * every n and, on the cube and the embedded hemisphere, the factor at the largest n is at most 1.25
 * x the one at the next (with the XFEM cut it varies with the cut's position in the grid), CG
 * preconditioned by one V-cycle converges in a number of iterations that does not grow with n (at
 * most 1.5 x the count at the smallest n, plus 2) and far fewer than CG + Jacobi, and its solution
 * equals CHOLMOD's to the tolerance. FCM_TEST_VERBOSE=1 prints the figures. */
#include "mg_util.h"

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  if (argc < 2) return 2;
  char name[32];
  snprintf(name, sizeof name, "%s", argv[1]);
  size_t len = strlen(name);
  /* suffix -jacobi: the damped Jacobi smoother at its default relaxation */
  const int jacobi = len > 7 && !strcmp(name + len - 7, "-jacobi");
  if (jacobi) name[len -= 7] = '\0';
  const int hex20 = len > 6 && !strcmp(name + len - 6, "-hex20");
  if (hex20) name[len - 6] = '\0';
  const fcm_element_type type = hex20 ? FCM_ELEMENT_HEX20 : FCM_ELEMENT_HEX8;
  const int kind = !strcmp(name, "cube")         ? 0
                   : !strcmp(name, "hemisphere") ? 1
                   : !strcmp(name, "cut")        ? 2
                   : !strcmp(name, "split")      ? 3
                   : !strcmp(name, "hollow")     ? 4
                                                 : -1;
  if (kind < 0) return 2;
  const int verbose = getenv("FCM_TEST_VERBOSE") != NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  /* further arguments: other sizes (even), for measurements */
  fcm_index sizes[8] = {4, 8, 16};
  int ns = 3;
  if (argc > 2) {
    ns = 0;
    for (int a = 2; a < argc && ns < 8; a++)
      sizes[ns++] = atoi(argv[a]);
  }
  double factor[8] = {0}, fmax = 0.0, factor2[8] = {0}, fmax2 = 0.0;
  int it_mg[8] = {0}, it_jac[8] = {0};
  for (int s = 0; s < ns; s++) {
    problem p;
    if (kind == 0)
      problem_cube_of(ctx, type, sizes[s], &p);
    else if (kind == 4)
      problem_hollow_of(ctx, type, sizes[s], &p);
    else
      problem_hemisphere_of(ctx, type, sizes[s], kind - 1,
                            fcm_space_options_default().constrain_ratio, &p);
    fcm_mg_options o = fcm_mg_options_default();
    o.coarse_dofs = 50; /* coarsen as far as the grid allows, for every n */
    o.cycle_index = 1;  /* the V-cycle (the default is the W-cycle) */
    if (jacobi) /* omega left at its default: the smoother's own (fcm_mg_smoother_omega()) */
      o.smoother = FCM_MG_SMOOTHER_JACOBI;
    if (getenv("FCM_TEST_MG_SMOOTH"))
      o.pre_smooth = o.post_smooth = atoi(getenv("FCM_TEST_MG_SMOOTH"));
    if (getenv("FCM_TEST_MG_OMEGA")) o.omega = atof(getenv("FCM_TEST_MG_OMEGA"));
    if (getenv("FCM_TEST_MG_CYCLE")) o.cycle_index = atoi(getenv("FCM_TEST_MG_CYCLE"));
    if (getenv("FCM_TEST_MG_LEVELS")) o.max_levels = atoi(getenv("FCM_TEST_MG_LEVELS"));
    if (getenv("FCM_TEST_MG_SMOOTHER"))
      o.smoother = (fcm_mg_smoother)atoi(getenv("FCM_TEST_MG_SMOOTHER"));
    /* the finest level's block set (fcm_mg_blocks) and the one-way block sweeps */
    if (getenv("FCM_TEST_MG_BLOCKS")) o.blocks = (fcm_mg_blocks)atoi(getenv("FCM_TEST_MG_BLOCKS"));
    if (getenv("FCM_TEST_MG_BLOCK_SWEEP")) o.block_sweep = atoi(getenv("FCM_TEST_MG_BLOCK_SWEEP"));
    /* the one-way pointwise sweeps */
    if (getenv("FCM_TEST_MG_POINT_SWEEP")) o.point_sweep = atoi(getenv("FCM_TEST_MG_POINT_SWEEP"));
    /* the finest level's blocks only at the cells with a small piece */
    if (getenv("FCM_TEST_MG_BLOCK_FRACTION"))
      o.block_fraction = atof(getenv("FCM_TEST_MG_BLOCK_FRACTION"));
    fcm_mg *mg = NULL;
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg));
    if (!mg) {
      problem_free(&p);
      break;
    }
    double *x = calloc((size_t)p.n + 1, sizeof *x), *xd = calloc((size_t)p.n + 1, sizeof *xd);
    fcm_mg_solve_info si;
    TEST_OK(ctx, fcm_mg_solve(mg, p.b, x, 1e-8, 200, &si));
    factor[s] = si.convergence_factor;
    fmax = fmax > factor[s] ? fmax : factor[s];
    /* CG + MG against CHOLMOD */
    direct_solve(ctx, p.A, p.b, xd);
    fcm_krylov_options ko = fcm_krylov_options_default();
    ko.rtol = 1e-10;
    ko.max_iterations = 5000;
    fcm_krylov_info ki;
    memset(x, 0, sizeof *x * (size_t)p.n);
    TEST_OK(ctx,
            fcm_cg_solve(ctx, p.n, fcm_csr_operator, p.A, fcm_mg_operator, mg, p.b, x, &ko, &ki));
    it_mg[s] = ki.iterations;
    double dn = 0.0, xn = 0.0;
    for (fcm_index i = 0; i < p.n; i++)
      dn += (x[i] - xd[i]) * (x[i] - xd[i]), xn += xd[i] * xd[i];
    TEST_TRUE(sqrt(dn) <= 1e-7 * sqrt(xn));
    fcm_jacobi *J = NULL;
    TEST_OK(ctx, fcm_jacobi_create(ctx, p.A, FCM_JACOBI_SCALAR, &J));
    memset(x, 0, sizeof *x * (size_t)p.n);
    fcm_cg_solve(ctx, p.n, fcm_csr_operator, p.A, fcm_jacobi_operator, J, p.b, x, &ko, &ki);
    fcm_ctx_error_clear(ctx);
    it_jac[s] = ki.iterations;
    if (verbose) {
      printf("%s n=%lld dofs=%lld levels=%d: V-cycle factor %.3f (%d cycles to 1e-8), "
             "CG+MG %d, CG+Jacobi %d iterations (rtol 1e-10)\n",
             argv[1], (long long)sizes[s], (long long)p.n, fcm_mg_num_levels(mg), factor[s],
             si.cycles, it_mg[s], it_jac[s]);
      for (int l = 0; l < fcm_mg_num_levels(mg); l++) {
        fcm_mg_level_info li;
        TEST_OK(ctx, fcm_mg_get_level_info(mg, l, &li));
        printf("  level %d: grid %lldx%lldx%lld cells %lld copies %lld dofs %lld nnz %lld "
               "bodies %lld\n",
               l, (long long)li.grid[0], (long long)li.grid[1], (long long)li.grid[2],
               (long long)li.cells, (long long)li.copies, (long long)li.dofs, (long long)li.nnz,
               (long long)li.bodies);
      }
    }
    TEST_TRUE(fcm_mg_num_levels(mg) >= 2);
    /* default options: the coarsest level (up to 2000 DOFs, here an intermediate level of
     * the run above) is factored by CHOLMOD, so it must be positive definite (a prolongation
     * that zeroed the clamped rows made it singular next to the clamped face) */
    fcm_mg *mg2 = NULL;
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, NULL, &mg2));
    memset(x, 0, sizeof *x * (size_t)p.n);
    if (mg2) TEST_OK(ctx, fcm_mg_solve(mg2, p.b, x, 1e-8, 200, &si));
    fcm_mg_destroy(&mg2);
    /* the two-grid method (the first coarse level solved exactly) */
    fcm_mg_options o2 = o;
    o2.max_levels = 2;
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o2, &mg2));
    memset(x, 0, sizeof *x * (size_t)p.n);
    if (mg2) TEST_OK(ctx, fcm_mg_solve(mg2, p.b, x, 1e-8, 200, &si));
    factor2[s] = si.convergence_factor;
    fmax2 = fmax2 > factor2[s] ? fmax2 : factor2[s];
    if (verbose) printf("  two-grid factor %.3f\n", factor2[s]);
    fcm_mg_destroy(&mg2);
    fcm_jacobi_destroy(&J);
    free(x);
    free(xd);
    fcm_mg_destroy(&mg);
    problem_free(&p);
  }
  /* Dick et al. Fig. 10: 0.66 uncut, 0.75 cut. The XFEM cut's factor depends on where the
   * cut meets the grid (measured 0.2 to 0.7 for n = 4 ... 28, not growing with n; the same
   * for the cut through the whole body, so it is not the cut's end), so only the bound
   * applies there. */
  TEST_TRUE(fmax <= 0.8);
  /* bounded independent of h: the factor has stopped growing at the last two sizes (the
   * smallest grids, almost all cut cells smoothed as blocks, converge faster) */
  if (kind < 2 && ns >= 2) TEST_TRUE(factor[ns - 1] <= 1.25 * factor[ns - 2] + 0.02);
  TEST_TRUE(fmax2 <= 0.8);
  if (kind < 2 && ns >= 2) TEST_TRUE(factor2[ns - 1] <= 1.25 * factor2[ns - 2] + 0.02);
  for (int s = 1; s < ns; s++) {
    TEST_TRUE(it_mg[s] <= 1.5 * it_mg[0] + 2);
    TEST_TRUE(3 * it_mg[s] < it_jac[s]);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
