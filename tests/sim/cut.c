/* Cutting during a run through the host-simulator calls: a spinning, flying
 * embedded body is stepped, then cut by a plane between two steps
 * (fcm_cell_rules_create_cut -> fcm_space_create_embedded -> fcm_integrator_create_cut).
 * At the cut the new DOF copies inherit their parents' values: the body's mass, linear and
 * angular momentum (fcm_space_momentum, authentic points) are unchanged to 1e-12 relative,
 * and the field is unchanged at points of every element; the time and step count carry
 * over. Then the run goes on with Newton converging, linear momentum stays conserved (free
 * body), and the two halves separate: the displacement jumps across the cut, while a run
 * without the cut keeps one element per cell. */
#include "sim_util.h"

static fcm_ctx *ctx;

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-0.3, -0.3, -0.3}, hi[3] = {1.3, 0.9, 0.9};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  const fcm_index n[3] = {4, 3, 3}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_surface *cut = NULL;
  fcm_space *s0 = NULL, *s1 = NULL;
  fcm_integrator *i0 = NULL, *i1 = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &r0));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r0, &s0));
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2.0e4, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.02;
  TEST_OK(ctx, fcm_integrator_create(ctx, s0, &mat, &o, &i0));
  TEST_OK(ctx, fcm_integrator_setup(i0));
  const double v0[3] = {0.2, 0.0, 0.1}, omega[3] = {0.0, 0.0, 6.0}, c[3] = {0.5, 0.3, 0.3};
  TEST_OK(ctx, fcm_integrator_set_rigid_velocity(i0, v0, omega, c));
  for (int s = 0; s < 3 && i0; s++) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(i0, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  }
  /* the cut: a plane across the long axis, off the grid planes */
  const double p[3] = {0.47, 0.3, 0.3}, nrm[3] = {1.0, 0.05, 0.0}, bl[3] = {-0.2, -0.2, -0.2},
               bh[3] = {1.2, 0.8, 0.8};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nrm, bl, bh, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r1, &s1));
  TEST_OK(ctx, fcm_integrator_create_cut(i0, s1, &i1));
  if (!i1) goto done;
  TEST_TRUE(fcm_integrator_time(i1) == fcm_integrator_time(i0));
  TEST_TRUE(fcm_integrator_step_count(i1) == 3);
  TEST_TRUE(fcm_integrator_num_dofs(i1) > fcm_integrator_num_dofs(i0));
  double m0, m1, p0[3], p1[3], L0[3], L1[3];
  TEST_OK(ctx, fcm_space_momentum(s0, mat.density, fcm_integrator_displacement(i0),
                                  fcm_integrator_velocity(i0), &m0, p0, L0));
  TEST_OK(ctx, fcm_space_momentum(s1, mat.density, fcm_integrator_displacement(i1),
                                  fcm_integrator_velocity(i1), &m1, p1, L1));
  TEST_NEAR(m0, 1000.0 * 0.36, 1e-12, 0);
  TEST_NEAR(m1, m0, 1e-12, 0);
  const double pn = sqrt(p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]);
  const double Ln = sqrt(L0[0] * L0[0] + L0[1] * L0[1] + L0[2] * L0[2]);
  for (int i = 0; i < 3; i++) {
    TEST_NEAR(p1[i], p0[i], 0, 1e-12 * pn);
    TEST_NEAR(L1[i], L0[i], 0, 1e-12 * Ln);
  }
  /* the field at the centre of every new element equals the old field there */
  const double xi_c[3] = {0.0, 0.0, 0.0}, xi_t[3] = {0.25, 0.25, 0.25};
  const double *xi = fcm_mesh_get_element_info(mesh)->shape == FCM_SHAPE_TET ? xi_t : xi_c;
  int split = 0;
  for (fcm_index e = 0; e < fcm_space_num_elements(s1); e++) {
    const fcm_index cell = fcm_space_element_cell(s1, e);
    fcm_index e0;
    TEST_TRUE(fcm_space_cell_elements(s0, cell, &e0) == 1);
    split += fcm_space_cell_elements(s1, cell, NULL) > 1;
    double a[3], b[3];
    TEST_OK(ctx, fcm_space_element_eval(s1, e, xi, fcm_integrator_displacement(i1), a));
    TEST_OK(ctx, fcm_space_element_eval(s0, e0, xi, fcm_integrator_displacement(i0), b));
    for (int i = 0; i < 3; i++)
      TEST_NEAR(a[i], b[i], 0, 1e-15);
  }
  TEST_TRUE(split > 0);
  /* go on: the halves fly apart; the linear momentum of the free body (sum of M v over all
   * DOFs, stabilization mass included) is conserved; the body's own (authentic points) to
   * the fictitious mass fraction alpha sum |K| / V (about 1e-5 here) */
  double q0[3], q1[3];
  TEST_OK(ctx, fcm_integrator_momentum(i1, q0, NULL));
  for (int s = 0; s < 8; s++) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(i1, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  }
  double p2[3];
  TEST_OK(ctx, fcm_space_momentum(s1, mat.density, fcm_integrator_displacement(i1),
                                  fcm_integrator_velocity(i1), NULL, p2, NULL));
  TEST_OK(ctx, fcm_integrator_momentum(i1, q1, NULL));
  for (int i = 0; i < 3; i++) {
    TEST_NEAR(q1[i], q0[i], 0, 1e-10 * pn);
    TEST_NEAR(p2[i], p0[i], 0, 1e-4 * pn);
  }
  double jump = 0.0;
  for (fcm_index cell = 0; cell < fcm_mesh_num_cells(mesh); cell++) {
    fcm_index e;
    if (fcm_space_cell_elements(s1, cell, &e) != 2) continue;
    double a[3], b[3];
    TEST_OK(ctx, fcm_space_element_eval(s1, e, xi, fcm_integrator_displacement(i1), a));
    TEST_OK(ctx, fcm_space_element_eval(s1, e + 1, xi, fcm_integrator_displacement(i1), b));
    jump = fmax(jump, sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                           (a[2] - b[2]) * (a[2] - b[2])));
  }
  TEST_TRUE(jump > 1e-3);
done:
  fcm_integrator_destroy(&i0);
  fcm_integrator_destroy(&i1);
  fcm_space_destroy(&s0);
  fcm_space_destroy(&s1);
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&r1);
  fcm_surface_destroy(&cut);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
