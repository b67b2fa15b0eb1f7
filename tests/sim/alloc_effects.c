/* Allocation failures in the integrator entry points alloc_failure.c does not reach: on an
 * embedded beam with surface rules, fcm_integrator_add_body_force (a field),
 * fcm_integrator_add_traction, a Nitsche boundary constraint on the embedded end face
 * (fcm_integrator_add_boundary_constraint), then setup, a step and fcm_integrator_energy. Failing
 * the k-th allocation (k = 0, 1, ... until the sequence succeeds) gives FCM_ERR_ALLOC and leaks
 * nothing. */
#include "sim_util.h"
#include "alloc_loop.h"

#include <omp.h>

typedef struct fixture {
  fcm_ctx *ctx;
  fcm_space *space;
  fcm_index nfix;
  fcm_index *fix;
  double energy[3];
} fixture;

static void field(void *user, const double x[3], const double normal[3], double value[3])
{
  (void)user;
  value[0] = 10.0 * x[2];
  value[1] = normal ? 5.0 * normal[1] : 0.0;
  value[2] = -100.0;
}

static double ramp(void *user, double t)
{
  (void)user;
  return t < 1.0 ? t : 1.0;
}

/* The embedded end face x = 1.7 (Nitsche boundary constraint). */
static int end_face(void *user, const double X[3], const double n[3])
{
  (void)user, (void)n;
  return X[0] > 1.69;
}

static fcm_status run(void *u)
{
  fixture *x = u;
  fcm_status st;
  fcm_integrator *integ = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e6, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_motion fixed = fcm_motion_default(), pull = fcm_motion_default();
  pull.velocity[0] = 0.1;
  o.dt = 0.01;
  if ((st = fcm_integrator_create(x->ctx, x->space, &mat, &o, &integ))) goto done;
  if ((st = fcm_integrator_add_body_force(integ, field, NULL, ramp, NULL))) goto done;
  if ((st = fcm_integrator_add_traction(integ, field, NULL, NULL, NULL))) goto done;
  if ((st = fcm_integrator_add_constraint(integ, x->nfix, x->fix, &fixed, NULL))) goto done;
  if ((st = fcm_integrator_add_boundary_constraint(integ, end_face, NULL, &pull, NULL, NULL)))
    goto done;
  if ((st = fcm_integrator_setup(integ))) goto done;
  if ((st = fcm_integrator_step(integ, NULL))) goto done;
  st = fcm_integrator_energy(integ, &x->energy[0], &x->energy[1], &x->energy[2]);
done:
  fcm_integrator_destroy(&integ);
  return st;
}

int main(void)
{
  omp_set_num_threads(1); /* the failing allocator counts calls in order */
  failing f;
  static fixture x;
  x.ctx = failing_ctx(&f);
  TEST_TRUE(x.ctx != NULL);
  if (!x.ctx) return TEST_RESULT();
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules = NULL;
  const double lo[3] = {0, 0, 0}, hi[3] = {1.7, 1, 1};
  const fcm_index n[3] = {2, 1, 1};
  TEST_OK(x.ctx, beam_mesh(x.ctx, FCM_ELEMENT_HEX8, 2, 2.0, &mesh));
  TEST_OK(x.ctx, fcm_geometry_create_box(x.ctx, lo, hi, n, &g));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.num_threads = 1;
  ro.surface_strength = 2;
  TEST_OK(x.ctx, fcm_cell_rules_create(x.ctx, mesh, g, &ro, &rules));
  TEST_OK(x.ctx, fcm_space_create_embedded(x.ctx, mesh, rules, &x.space));
  x.fix = plane_nodes(x.ctx, mesh, 0, 0.0, &x.nfix);
  if (x.space && x.fix) {
    alloc_loop(x.ctx, &f, "integrator with body-force field and traction", run, NULL, &x, 10,
               20000);
    if (!(x.energy[0] > 0.0 && x.energy[2] > 0.0)) /* Psi(I) is not zero for SNH */
      TEST_FAIL_("energies %g %g %g: the loads did not move the body", x.energy[0], x.energy[1],
                 x.energy[2]);
  }
  free(x.fix);
  fcm_space_destroy(&x.space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(x.ctx) == 0);
  fcm_ctx_destroy(&x.ctx);
  return TEST_RESULT();
}
