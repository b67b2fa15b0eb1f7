/* Krylov Newton solves agree with the direct one. With the Newton tolerance 1e-10
 * (relative) and Krylov rtol 1e-12, three backward Euler steps of a Stable Neo-Hookean
 * body give displacements within 1e-8 (relative) of the CHOLMOD run, for CG and MINRES
 * with no, Jacobi, block-Jacobi and Schwarz preconditioning: (A) a clamped beam under
 * gravity on a plain space; (B) an embedded box [0, 1.1]^3 in a 2^3 grid over
 * [0, 4/3]^3 (hexahedra: 7 cut cells with volume fractions 0.27, 0.42 and 0.65, the first
 * two kinds with Schwarz blocks), clamped at x = 0, under gravity and an end traction. Krylov runs
 * report iterations and no symbolic analysis; the direct runs no iterations. */
#include "sim_util.h"

typedef struct variant {
  fcm_linear_solver solver;
  fcm_preconditioner precond;
} variant;

static const variant variants[] = {
    {FCM_LINEAR_DIRECT, FCM_PRECOND_NONE},    {FCM_LINEAR_CG, FCM_PRECOND_NONE},
    {FCM_LINEAR_CG, FCM_PRECOND_JACOBI},      {FCM_LINEAR_CG, FCM_PRECOND_SCHWARZ},
    {FCM_LINEAR_MINRES, FCM_PRECOND_JACOBI},  {FCM_LINEAR_MINRES, FCM_PRECOND_BLOCK_JACOBI},
    {FCM_LINEAR_MINRES, FCM_PRECOND_SCHWARZ},
};

static void end_traction(void *user, const double x[3], const double n[3], double t[3])
{
  (void)user, (void)x;
  t[0] = t[1] = 0.0;
  t[2] = n[0] > 0.5 ? -2.0e3 : 0.0;
}

static void run(fcm_ctx *ctx, fcm_space *space, const fcm_material *mat, fcm_index nfix,
                const fcm_index *fix, int traction, int verbose, const char *label)
{
  fcm_index n = fcm_space_num_dofs(space);
  double *uref = calloc((size_t)n, sizeof *uref);
  const double grav[3] = {0, 0, -9.81};
  fcm_motion fixed = fcm_motion_default();
  for (size_t k = 0; k < sizeof variants / sizeof variants[0]; k++) {
    fcm_integrator *integ = NULL;
    fcm_integrator_options o = fcm_integrator_options_default();
    o.dt = 0.01;
    o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    o.newton_tolerance = 1e-10;
    o.linear_solver = variants[k].solver;
    o.preconditioner = variants[k].precond;
    o.krylov_rtol = 1e-12;
    o.krylov_max_iterations = 5000;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
    if (traction) TEST_OK(ctx, fcm_integrator_add_traction(integ, end_traction, NULL, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    long long its = 0;
    int newton = 0;
    double tt = 0.0;
    fcm_step_info info;
    for (int s = 0; s < 3; s++) {
      TEST_OK(ctx, fcm_integrator_step(integ, &info));
      its += info.linear_iterations;
      newton += info.newton_iterations;
      tt += info.time_total;
    }
    const double *u = fcm_integrator_displacement(integ);
    if (k == 0) {
      memcpy(uref, u, sizeof *uref * (size_t)n);
      TEST_TRUE(its == 0);
      TEST_TRUE(info.total_analyses == 1);
      TEST_TRUE(vec_norm(n, uref) > 0.0);
    } else {
      TEST_TRUE(its > 0);
      TEST_TRUE(info.total_analyses == 0);
      TEST_TRUE(vec_dist(n, u, uref) <= 1e-8 * vec_norm(n, uref));
    }
    if (verbose)
      printf("%s solver %d precond %d: newton %d, linear iterations %lld, rel. diff %.2e, %.3f s\n",
             label, (int)variants[k].solver, (int)variants[k].precond, newton, its,
             vec_dist(n, u, uref) / vec_norm(n, uref), tt);
    fcm_integrator_destroy(&integ);
  }
  free(uref);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_geometry *box = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_element_type type;
  if (argc < 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  int verbose = argc > 2 && !strcmp(argv[2], "-v");
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e6, 0.3, 1000.0};

  /* (A) plain beam. */
  TEST_OK(ctx, beam_mesh(ctx, type, 4, 4.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index nfix = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix);
  run(ctx, space, &mat, nfix, fix, 0, verbose, "beam");
  free(fix);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);

  /* (B) embedded box with cut cells. */
  {
    double lo[3] = {0, 0, 0}, hi[3] = {4.0 / 3.0, 4.0 / 3.0, 4.0 / 3.0}, ghi[3] = {1.1, 1.1, 1.1};
    fcm_index cells[3] = {2, 2, 2}, gcells[3] = {2, 2, 2};
    TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
    TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, ghi, gcells, &box));
    fcm_cell_rules_options ro = fcm_cell_rules_options_default();
    ro.surface_strength = 2;
    ro.simplify = 0;
    TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, box, &ro, &rules));
    fcm_index ncut = fcm_cell_rules_get_stats(rules)->num_cut;
    TEST_TRUE(type == FCM_ELEMENT_HEX8 ? ncut == 7 : ncut > 0);
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
    fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix);
    run(ctx, space, &mat, nfix, fix, 1, verbose, "embedded");
    free(fix);
    fcm_space_destroy(&space);
    fcm_cell_rules_destroy(&rules);
    fcm_geometry_destroy(&box);
    fcm_mesh_destroy(&mesh);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
