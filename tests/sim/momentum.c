/* A free Stable Neo-Hookean body (no constraints, no loads) with a rigid initial velocity
 * (translation + rotation about a point off the centre of mass), stepped with backward
 * Euler under the paper's stopping rule: the total linear momentum sum_a (M v)_a is
 * conserved to 1e-10 (internal forces sum to zero and Newton starts at u^ = u_n + h v_n),
 * also when computed from an independently assembled mass matrix, and the centre of mass
 * moves uniformly: sum (M u) = t p. The body does deform (spin), so Newton works.
 * Resuming from a checkpoint (get_state/set_state) in a new integrator is bitwise exact. */
#include "sim_util.h"

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  fcm_csr *M = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  double lo[3] = {0, 0, 0}, hi[3] = {1.0, 0.6, 0.4};
  fcm_index cells[3] = {2, 2, 1};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index n = fcm_space_num_dofs(space);
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.35, 800.0};
  fcm_material el = {FCM_MATERIAL_LINEAR, mat.young, mat.poisson, mat.density};
  TEST_OK(ctx, fcm_space_matrix_create(space, &M));
  TEST_OK(ctx, fcm_assemble_mass(space, &el, NULL, M));
  double *Mv = calloc((size_t)n, sizeof *Mv), *ones = calloc((size_t)n, sizeof *ones);
  double *Mu = calloc((size_t)n, sizeof *Mu);

  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.02;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  const double v0[3] = {0.3, -0.2, 0.1}, omega[3] = {1.0, 2.0, 3.0}, c[3] = {0.2, 0.1, 0.4};
  TEST_OK(ctx, fcm_integrator_set_rigid_velocity(integ, v0, omega, c));
  double p0[3], q[3];
  TEST_OK(ctx, fcm_integrator_momentum(integ, p0, NULL));
  double pn = sqrt(p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]);
  double mass = 0.0;
  for (fcm_index i = 0; i < n; i += 3)
    ones[i] = 1.0;
  TEST_OK(ctx, fcm_csr_apply(M, 1.0, ones, 0.0, Mv));
  for (fcm_index i = 0; i < n; i++)
    mass += Mv[i];
  TEST_NEAR(mass, 800.0 * 0.24, 1e-12, 0);
  int newton = 0;
  double umax = 0.0;
  double *cu = calloc((size_t)n, sizeof *cu), *cv = calloc((size_t)n, sizeof *cv), ct = 0;
  long long cs = 0;
  for (int s = 1; s <= 20; s++) {
    if (s == 11) { /* checkpoint: the state, and no kept factorization, as a resumed run */
      fcm_integrator_get_state(integ, cu, cv, &ct, &cs);
      fcm_integrator_drop_factorization(integ);
    }
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    newton += info.newton_iterations;
    TEST_OK(ctx, fcm_integrator_momentum(integ, q, NULL));
    for (int i = 0; i < 3; i++)
      TEST_NEAR(q[i], p0[i], 0, 1e-10 * pn);
    /* The same from our own mass matrix: p_i = sum over nodes of (M v)_{3a+i}. */
    TEST_OK(ctx, fcm_csr_apply(M, 1.0, fcm_integrator_velocity(integ), 0.0, Mv));
    TEST_OK(ctx, fcm_csr_apply(M, 1.0, fcm_integrator_displacement(integ), 0.0, Mu));
    double p[3] = {0, 0, 0}, mu[3] = {0, 0, 0};
    for (fcm_index k = 0; k < n; k++)
      p[k % 3] += Mv[k], mu[k % 3] += Mu[k];
    double t = fcm_integrator_time(integ);
    for (int i = 0; i < 3; i++) {
      TEST_NEAR(p[i], p0[i], 0, 1e-10 * pn);
      TEST_NEAR(mu[i], t * p0[i], 0, 1e-10 * t * pn);
    }
    for (fcm_index k = 0; k < n; k++)
      umax = fmax(umax, fabs(fcm_integrator_displacement(integ)[k]));
  }
  TEST_TRUE(newton >= 20); /* the spin deforms the body: at least one update per step */
  TEST_TRUE(umax > 0.1);
  /* Resuming from the checkpoint in a new integrator gives bitwise the same run. */
  {
    fcm_integrator *again = NULL;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &again));
    TEST_OK(ctx, fcm_integrator_setup(again));
    TEST_OK(ctx, fcm_integrator_set_state(again, cu, cv, ct, cs));
    for (int s = 11; s <= 20; s++)
      TEST_OK(ctx, fcm_integrator_step(again, NULL));
    TEST_TRUE(fcm_integrator_step_count(again) == 20 && ct > 0.0);
    TEST_TRUE(fcm_integrator_time(again) == fcm_integrator_time(integ));
    TEST_TRUE(!memcmp(fcm_integrator_displacement(again), fcm_integrator_displacement(integ),
                      sizeof(double) * (size_t)n));
    TEST_TRUE(!memcmp(fcm_integrator_velocity(again), fcm_integrator_velocity(integ),
                      sizeof(double) * (size_t)n));
    fcm_integrator_destroy(&again);
  }
  free(cu), free(cv);
  fcm_integrator_destroy(&integ);

  free(Mv), free(ones), free(Mu);
  fcm_csr_destroy(&M);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
