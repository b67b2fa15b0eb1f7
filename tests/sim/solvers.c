/* The direct path and its reuse counters. (1) Linear material, constant dt, fixed
 * constraints: 30 backward Euler steps take one Newton update each with a single
 * factorization and a single symbolic analysis; the same with UMFPACK as the method.
 * (2) Stable Neo-Hookean: the factorization is redone per Newton update, the analysis
 * stays 1 over 20 steps. (3) A uniformly compressed SNH body (F = 0.5 I) with a large
 * step and no tangent projection has an indefinite Newton matrix: CHOLMOD reports "not
 * positive definite", the Newton loop takes the PSD-projected tangent for the rest of the
 * step (counted as projection fallbacks; no UMFPACK, no second analysis, no warning), and
 * the step still converges; with projection on CHOLMOD never fails. */
#include "sim_util.h"

static fcm_status make(fcm_ctx *ctx, fcm_space *space, const fcm_material *mat,
                       const fcm_integrator_options *o, fcm_index nfix, const fcm_index *fix,
                       const double *grav, fcm_integrator **integ)
{
  fcm_motion fixed = fcm_motion_default();
  fcm_status st = fcm_integrator_create(ctx, space, mat, o, integ);
  if (!st && grav) st = fcm_integrator_add_gravity(*integ, grav, NULL, NULL);
  if (!st && nfix) st = fcm_integrator_add_constraint(*integ, nfix, fix, &fixed, NULL);
  if (!st) st = fcm_integrator_setup(*integ);
  return st;
}

static void count_warnings(void *user, fcm_log_level level, const char *msg)
{
  if (level == FCM_LOG_WARNING && strstr(msg, "UMFPACK")) ++*(int *)user;
}

int main(int argc, char **argv)
{
  int warnings = 0;
  fcm_ctx_options co = fcm_ctx_options_default();
  co.log = count_warnings;
  co.log_user = &warnings;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL, *cube = NULL;
  fcm_space *space = NULL, *cspace = NULL;
  fcm_integrator *integ = NULL;
  fcm_element_type type;
  if (argc < 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(&co, &ctx));
  TEST_OK(ctx, beam_mesh(ctx, type, 4, 4.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index nfix = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix);
  const double grav[3] = {0, 0, -9.81};
  fcm_step_info info;

  /* 1. Linear: factor once. */
  for (int method = 0; method < 2; method++) {
    fcm_material lin = {FCM_MATERIAL_LINEAR, 1.0e6, 0.3, 1000.0};
    fcm_integrator_options o = fcm_integrator_options_default();
    o.dt = 0.01;
    o.direct_method = method == 0 ? FCM_DIRECT_CHOLMOD : FCM_DIRECT_UMFPACK;
    TEST_OK(ctx, make(ctx, space, &lin, &o, nfix, fix, grav, &integ));
    for (int s = 0; s < 30; s++) {
      TEST_OK(ctx, fcm_integrator_step(integ, &info));
      TEST_TRUE(info.newton_iterations == 1);
      TEST_TRUE(info.tangent_assemblies == (s == 0));
    }
    TEST_TRUE(info.total_factorizations == 1);
    TEST_TRUE(info.total_analyses == 1);
    TEST_TRUE(info.total_direct_fallbacks == 0);
    fcm_integrator_destroy(&integ);
  }

  /* 2. Nonlinear: refactor per update, analyze once. */
  {
    fcm_material snh = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e6, 0.3, 1000.0};
    fcm_integrator_options o = fcm_integrator_options_default();
    o.dt = 0.01;
    o.reuse_factorization = 0; /* full Newton (the kept factorization: tests/sim/reuse.c) */
    TEST_OK(ctx, make(ctx, space, &snh, &o, nfix, fix, grav, &integ));
    long long updates = 0;
    for (int s = 0; s < 20; s++) {
      TEST_OK(ctx, fcm_integrator_step(integ, &info));
      TEST_TRUE(info.factorizations == info.newton_iterations);
      updates += info.newton_iterations;
    }
    TEST_TRUE(updates >= 20);
    TEST_TRUE(info.total_factorizations == updates);
    TEST_TRUE(info.total_analyses == 1);
    fcm_integrator_destroy(&integ);
  }

  /* 3. Indefinite Newton matrix of a dynamic step: CHOLMOD finds the exact tangent not
   * positive definite, the Newton loop takes the projected one (SPD with M/h^2) instead of
   * an LU factorization, and still converges. */
  {
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    fcm_index cells[3] = {2, 2, 2};
    TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &cube));
    TEST_OK(ctx, fcm_space_create(ctx, cube, NULL, &cspace));
    fcm_index n = fcm_space_num_dofs(cspace);
    double *u0 = calloc((size_t)n, sizeof *u0);
    const double *X = fcm_mesh_coords(cube);
    for (fcm_index a = 0; a < fcm_mesh_num_nodes(cube); a++)
      for (int i = 0; i < 3; i++)
        u0[fcm_space_node_dof(cspace, a) + i] = -0.5 * (X[3 * a + i] - 0.5);
    fcm_material snh = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.4, 100.0};
    for (int project = 0; project < 2; project++) {
      fcm_integrator_options o = fcm_integrator_options_default();
      o.dt = 1.0;
      o.project_psd = project;
      o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
      o.newton_tolerance = 1e-9;
      warnings = 0;
      TEST_OK(ctx, make(ctx, cspace, &snh, &o, 0, NULL, NULL, &integ));
      TEST_OK(ctx, fcm_integrator_set_state(integ, u0, NULL, 0.0, 0));
      TEST_OK(ctx, fcm_integrator_step(integ, &info));
      TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
      if (argc > 2)
        printf("project %d: newton %d, backtracks %d, fallbacks %d, projection fallbacks %d, "
               "factorizations %d\n",
               project, info.newton_iterations, info.line_search_backtracks, info.direct_fallbacks,
               info.projection_fallbacks, info.factorizations);
      if (project) {
        TEST_TRUE(info.direct_fallbacks == 0);
        TEST_TRUE(info.total_analyses == 1);
        TEST_TRUE(warnings == 0);
      } else {
        TEST_TRUE(info.direct_fallbacks == 0 && info.total_direct_fallbacks == 0);
        TEST_TRUE(info.projection_fallbacks >= 1);
        TEST_TRUE(info.total_analyses == 1);
        TEST_TRUE(warnings == 0);
      }
      /* It expanded back towards the reference (J grew from 1/8). */
      const double *u = fcm_integrator_displacement(integ);
      double shrink = 0.0, count = 0.0;
      for (fcm_index a = 0; a < fcm_mesh_num_nodes(cube); a++)
        if (X[3 * a] == 1.0) shrink += u[fcm_space_node_dof(cspace, a)], count += 1.0;
      TEST_TRUE(shrink / count > -0.25 + 1e-3);
      fcm_integrator_destroy(&integ);
    }
    free(u0);
  }

  free(fix);
  fcm_space_destroy(&space);
  fcm_space_destroy(&cspace);
  fcm_mesh_destroy(&mesh);
  fcm_mesh_destroy(&cube);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
