/* Interactive steps (fcm_integrator_options.newton_fixed_iterations, multigrid_fixed_cycles):
 * - the fixed-iteration rule runs exactly N Newton iterations on a nonlinear beam that the
 *   accurate default needs more for, accepts the state (FCM_STEP_FIXED_ITERATIONS) and reports
 *   the residual it reached above the tolerance, the tolerance and the rule's reference as the
 *   monitor saw them; more iterations reach a smaller residual; a linear problem that converges
 *   in one iteration stops there (FCM_STEP_CONVERGED);
 * - fixed multigrid cycles (3 V-cycles, 1 + 1 Gauss-Seidel sweeps) on a linear beam run
 *   exactly 3 cycles per step, and the warm start from the previous step's correction stays
 *   closer to the direct solution than the same cycles started cold;
 * - options out of range and fixed cycles without the multigrid solver are refused. */
#include "sim_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MG_STEPS = 8 };

/* A beam clamped at x = 0 under gravity (0, 0, gz), set up (NULL on failure). */
static fcm_integrator *make(fcm_ctx *ctx, const fcm_space *space, const fcm_material *mat,
                            fcm_index nfix, const fcm_index *fix, const fcm_integrator_options *o,
                            double gz)
{
  fcm_integrator *integ = NULL;
  const double g[3] = {0.0, 0.0, gz};
  fcm_motion fixed = fcm_motion_default();
  TEST_OK(ctx, fcm_integrator_create(ctx, space, mat, o, &integ));
  if (!integ) return NULL;
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  return integ;
}

static fcm_integrator_options newton_options(int fixed, newton_log *log)
{
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.02;
  o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
  o.newton_tolerance = 1e-10;
  o.newton_fixed_iterations = fixed;
  o.monitor = newton_log_fn;
  o.monitor_user = log;
  return o;
}

/* One step of a Stable Neo-Hookean beam under ten times gravity from rest with N fixed
 * iterations (0: the accurate rule); its info. */
static fcm_step_info snh_step(fcm_ctx *ctx, const fcm_space *space, fcm_index nfix,
                              const fcm_index *fix, int fixed, newton_log *log)
{
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.3, 1000.0};
  fcm_integrator_options o = newton_options(fixed, log);
  fcm_step_info info;
  memset(&info, 0, sizeof info);
  fcm_integrator *integ = make(ctx, space, &mat, nfix, fix, &o, -98.1);
  log->count = 0;
  if (integ) {
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    /* accepted: the state moved on */
    TEST_TRUE(fcm_integrator_step_count(integ) == 1 && fcm_integrator_time(integ) == o.dt);
  }
  fcm_integrator_destroy(&integ);
  return info;
}

static void fixed_newton(fcm_ctx *ctx, const fcm_space *space, fcm_index nfix, const fcm_index *fix)
{
  newton_log log;
  const fcm_step_info full = snh_step(ctx, space, nfix, fix, 0, &log);
  /* the accurate default needs more than two iterations here */
  TEST_TRUE(full.reason == FCM_STEP_CONVERGED && full.newton_iterations > 2);
  TEST_TRUE(full.residual <= full.tolerance && full.residual_reference > 0.0);
  printf("accurate: %d iterations, residual %.3e, tolerance %.3e\n", full.newton_iterations,
         full.residual, full.tolerance);
  double prev = HUGE_VAL;
  for (int N = 1; N <= 2; N++) {
    const fcm_step_info fi = snh_step(ctx, space, nfix, fix, N, &log);
    printf("fixed %d: %d iterations, residual %.3e, tolerance %.3e, reference %.3e (%s)\n", N,
           fi.newton_iterations, fi.residual, fi.tolerance, fi.residual_reference,
           fcm_step_reason_name(fi.reason));
    TEST_TRUE(fi.reason == FCM_STEP_FIXED_ITERATIONS && fi.halvings == 0);
    TEST_TRUE(!strcmp(fcm_step_reason_name(fi.reason), "fixed-iterations"));
    /* exactly N iterations: the monitor saw the start and N updates */
    TEST_TRUE(fi.newton_iterations == N && log.count == N + 1 && log.iteration[N] == N);
    /* the residual reached and the tolerance are the last iteration's, and it is above */
    TEST_TRUE(fi.residual == log.residual[N] && fi.tolerance == log.tolerance[N]);
    TEST_TRUE(fi.residual > fi.tolerance);
    TEST_NEAR(fi.tolerance, 1e-10 * fi.residual_reference, 1e-14, 0.0);
    /* Newton makes progress: more iterations, a smaller residual */
    TEST_TRUE(fi.residual < prev);
    prev = fi.residual;
  }
  /* a linear problem converges in one iteration: the rule stops there, reporting it */
  {
    const fcm_material lin = {FCM_MATERIAL_LINEAR, 1.0e5, 0.3, 1000.0};
    fcm_integrator_options o = newton_options(3, &log);
    o.newton_tolerance = 1e-8;
    fcm_integrator *integ = make(ctx, space, &lin, nfix, fix, &o, -9.81);
    fcm_step_info info;
    log.count = 0;
    if (integ) TEST_OK(ctx, fcm_integrator_step(integ, &info));
    if (integ)
      TEST_TRUE(info.reason == FCM_STEP_CONVERGED && info.newton_iterations == 1 &&
                info.residual <= info.tolerance);
    fcm_integrator_destroy(&integ);
  }
}

static fcm_integrator_options mg_options(int fixed_cycles)
{
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.01;
  o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
  o.newton_tolerance = 1e-12;
  o.newton_fixed_iterations = 1;
  o.linear_solver = fixed_cycles > 0 ? FCM_LINEAR_MULTIGRID : FCM_LINEAR_DIRECT;
  o.multigrid_fixed_cycles = fixed_cycles;
  o.multigrid.cycle_index = 1; /* V-cycles, 1 pre + 1 post symmetric Gauss-Seidel step */
  o.multigrid.coarse_dofs = 100;
  return o;
}

/* MG_STEPS steps of a linear beam with one Newton iteration each: direct (cycles 0), or 3
 * fixed multigrid cycles warm-started (cold: the warm start dropped before every step).
 * Final displacement into u. */
static void mg_run(fcm_ctx *ctx, const fcm_space *space, fcm_index nfix, const fcm_index *fix,
                   int cycles, int cold, double *u)
{
  const fcm_material lin = {FCM_MATERIAL_LINEAR, 1.0e5, 0.3, 1000.0};
  fcm_integrator_options o = mg_options(cycles);
  fcm_integrator *integ = make(ctx, space, &lin, nfix, fix, &o, -9.81);
  if (!integ) return;
  for (int s = 0; s < MG_STEPS; s++) {
    fcm_step_info info;
    if (cold) fcm_integrator_drop_factorization(integ);
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    TEST_TRUE(info.newton_iterations == 1 && info.halvings == 0);
    if (cycles > 0) {
      /* the cycles are not converged: the step is accepted by the fixed-iteration rule */
      TEST_TRUE(info.reason == FCM_STEP_FIXED_ITERATIONS && info.residual > info.tolerance);
      TEST_TRUE(info.linear_iterations == cycles && info.multigrid_cycles == cycles);
    }
  }
  TEST_TRUE(fcm_integrator_multigrid(integ) == NULL ||
            fcm_mg_num_levels(fcm_integrator_multigrid(integ)) >= 2);
  memcpy(u, fcm_integrator_displacement(integ), sizeof *u * (size_t)fcm_integrator_num_dofs(integ));
  fcm_integrator_destroy(&integ);
}

static void fixed_cycles(fcm_ctx *ctx)
{
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  const double lo[3] = {0, 0, 0}, hi[3] = {4, 1, 1};
  const fcm_index cells[3] = {16, 4, 4};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  if (mesh) TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index nfix = 0;
  fcm_index *fix = mesh ? plane_nodes(ctx, mesh, 0, 0.0, &nfix) : NULL;
  if (!space || !fix) goto done;
  const fcm_index n = fcm_space_num_dofs(space);
  double *ud = calloc((size_t)n, sizeof *ud), *uw = calloc((size_t)n, sizeof *uw),
         *uc = calloc((size_t)n, sizeof *uc);
  TEST_TRUE(ud && uw && uc);
  if (ud && uw && uc) {
    mg_run(ctx, space, nfix, fix, 0, 0, ud);
    mg_run(ctx, space, nfix, fix, 3, 0, uw);
    mg_run(ctx, space, nfix, fix, 3, 1, uc);
    const double scale = vec_norm(n, ud), ew = vec_dist(n, uw, ud), ec = vec_dist(n, uc, ud);
    printf("3 V-cycles per step after %d steps: error vs direct warm %.3e, cold %.3e (|u| %.3e)\n",
           MG_STEPS, ew / scale, ec / scale, scale);
    TEST_TRUE(scale > 0.0);
    /* the warm start is closer to the direct solution than cold cycles, by a clear factor */
    TEST_TRUE(ew < 0.5 * ec);
    TEST_TRUE(ew < 0.05 * scale);
  }
  free(ud);
  free(uw);
  free(uc);
done:
  free(fix);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
}

static void refused(fcm_ctx *ctx, const fcm_space *space, fcm_index nfix, const fcm_index *fix)
{
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e5, 0.3, 1000.0};
  fcm_integrator *integ = NULL;
  fcm_integrator_options o = fcm_integrator_options_default();
  o.newton_fixed_iterations = -1;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  if (integ) TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG, "newton_fixed_iterations");
  fcm_integrator_destroy(&integ);
  /* fixed cycles with the direct solver (exact) or CG (stops at its tolerance): refused */
  for (int k = 0; k < 2; k++) {
    o = fcm_integrator_options_default();
    o.linear_solver = k == 0 ? FCM_LINEAR_DIRECT : FCM_LINEAR_CG;
    o.multigrid_fixed_cycles = 3;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    if (integ)
      TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG,
               "multigrid_fixed_cycles = 3 needs the multigrid solver");
    fcm_integrator_destroy(&integ);
  }
  o = fcm_integrator_options_default();
  o.linear_solver = FCM_LINEAR_MULTIGRID;
  o.multigrid_fixed_cycles = 1001;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  if (integ)
    TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG, "multigrid_fixed_cycles = 1001");
  fcm_integrator_destroy(&integ);
  /* the finest level's block fraction outside (0, 1]: refused, naming it */
  static const double bad_fraction[] = {0.0, 1.5, NAN};
  for (int k = 0; k < 3; k++) {
    o = fcm_integrator_options_default();
    o.linear_solver = FCM_LINEAR_MULTIGRID;
    o.multigrid.block_fraction = bad_fraction[k];
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    if (integ) TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG, "multigrid.block_fraction");
    fcm_integrator_destroy(&integ);
  }
  (void)nfix;
  (void)fix;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, beam_mesh(ctx, FCM_ELEMENT_HEX8, 4, 4.0, &mesh));
  if (mesh) TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index nfix = 0;
  fcm_index *fix = mesh ? plane_nodes(ctx, mesh, 0, 0.0, &nfix) : NULL;
  if (space && fix) {
    fixed_newton(ctx, space, nfix, fix);
    refused(ctx, space, nfix, fix);
  }
  fixed_cycles(ctx);
  free(fix);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
