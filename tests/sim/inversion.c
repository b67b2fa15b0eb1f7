/* Inverted quadrature points in the step info: every node of a unit cube (2 x 2 x 2 cells) is
 * driven to u(X) = t (0, 0, -a x z^2), which folds the upper corner at x = 1 through itself
 * (J = 1 - 2 a t x z for the exact field). Two static steps reach t = 0.5 and t = 1. After each
 * the test computes J = det F at every point of the standard stiffness rule of every cell on
 * its own — F from central differences of the interpolated field (fcm_space_element_eval(),
 * exact for these polynomials) and the element map's Jacobian — and checks
 * fcm_step_info.inverted_points against the count of points with J <= 0, the first cell and
 * point reported (lowest cell, rule order) and J there. A free body spinning without
 * deformation reports none. */
#include "sim_util.h"

static const double A = 1.6; /* J <= 0 where x z >= 1 / (2 A t) */

typedef struct expect {
  fcm_index count, first_cell;
  double X[3], det, min_abs;
} expect;

/* J at every rule point of every cell, from the field u alone. */
static void count_inverted(fcm_ctx *ctx, const fcm_space *space, const fcm_mesh *mesh,
                           const fcm_rule *rule, const double *u, expect *e)
{
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  const int nq = fcm_rule_num_points(rule), nn = fcm_mesh_nodes_per_cell(mesh);
  const double *pts = fcm_rule_points(rule), h = 1e-3;
  double *X = malloc(sizeof *X * 3 * (size_t)nn);
  e->count = 0, e->first_cell = -1, e->det = 0.0, e->min_abs = HUGE_VAL;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm_index elem = -1;
    TEST_TRUE(fcm_space_cell_elements(space, c, &elem) == 1);
    fcm_mesh_cell_coords(mesh, c, X);
    for (int q = 0; q < nq; q++) {
      const double *xi = pts + 3 * q;
      double G[9], Jm[9], F[9]; /* G_ik = du_i/dxi_k; Jm_jk = dX_j/dxi_k */
      for (int k = 0; k < 3; k++) {
        double xp[3] = {xi[0], xi[1], xi[2]}, xm[3] = {xi[0], xi[1], xi[2]}, up[3], um[3];
        xp[k] += h, xm[k] -= h;
        TEST_OK(ctx, fcm_space_element_eval(space, elem, xp, u, up));
        TEST_OK(ctx, fcm_space_element_eval(space, elem, xm, u, um));
        for (int i = 0; i < 3; i++)
          G[3 * i + k] = (up[i] - um[i]) / (2.0 * h);
      }
      fcm_element_jacobian(type, X, xi, Jm);
      /* F = I + G Jm^-1: solve F Jm = Jm + G column by column via the inverse of Jm */
      double d = Jm[0] * (Jm[4] * Jm[8] - Jm[5] * Jm[7]) - Jm[1] * (Jm[3] * Jm[8] - Jm[5] * Jm[6]) +
                 Jm[2] * (Jm[3] * Jm[7] - Jm[4] * Jm[6]);
      double Ji[9] = {(Jm[4] * Jm[8] - Jm[5] * Jm[7]) / d, (Jm[2] * Jm[7] - Jm[1] * Jm[8]) / d,
                      (Jm[1] * Jm[5] - Jm[2] * Jm[4]) / d, (Jm[5] * Jm[6] - Jm[3] * Jm[8]) / d,
                      (Jm[0] * Jm[8] - Jm[2] * Jm[6]) / d, (Jm[2] * Jm[3] - Jm[0] * Jm[5]) / d,
                      (Jm[3] * Jm[7] - Jm[4] * Jm[6]) / d, (Jm[1] * Jm[6] - Jm[0] * Jm[7]) / d,
                      (Jm[0] * Jm[4] - Jm[1] * Jm[3]) / d};
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
          F[3 * i + j] = i == j ? 1.0 : 0.0;
          for (int k = 0; k < 3; k++)
            F[3 * i + j] += G[3 * i + k] * Ji[3 * k + j];
        }
      const double J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                       F[2] * (F[3] * F[7] - F[4] * F[6]);
      e->min_abs = fmin(e->min_abs, fabs(J));
      if (J > 0.0) continue;
      if (e->count++ == 0) {
        e->first_cell = c;
        e->det = J;
        fcm_element_map(type, X, xi, e->X);
      }
    }
  }
  free(X);
}

static void prescribed(const double X[3], double t, double u[3])
{
  u[0] = u[1] = 0.0;
  u[2] = -A * t * X[0] * X[2] * X[2];
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  fcm_rule *rule = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index cells[3] = {2, 2, 2};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  TEST_OK(ctx, fcm_element_standard_rule(ctx, type, FCM_RULE_STIFFNESS, FCM_DEFAULT, &rule));
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.3, 1000.0};
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  const double *Xn = fcm_mesh_coords(mesh);

  /* Static: every node driven on its own (velocity g(X) per unit time from t = 0). */
  {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.kind = FCM_INTEGRATOR_STATIC;
    o.dt = 0.5;
    o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    for (fcm_index a = 0; a < nn; a++) {
      fcm_motion m = fcm_motion_default();
      prescribed(Xn + 3 * a, 1.0, m.velocity);
      TEST_OK(ctx, fcm_integrator_add_constraint(integ, 1, &a, &m, NULL));
    }
    TEST_OK(ctx, fcm_integrator_setup(integ));
    fcm_index previous = 0;
    for (int step = 1; step <= 2; step++) {
      fcm_step_info si;
      expect e;
      TEST_OK(ctx, fcm_integrator_step(integ, &si));
      TEST_TRUE(si.reason == FCM_STEP_CONVERGED);
      const double *u = fcm_integrator_displacement(integ);
      for (fcm_index a = 0; a < nn; a++) { /* the field is the prescribed one */
        double g[3];
        prescribed(Xn + 3 * a, 0.5 * step, g);
        TEST_NEAR(u[fcm_space_node_dof(space, a) + 2], g[2], 0, 1e-14);
      }
      count_inverted(ctx, space, mesh, rule, u, &e);
      TEST_TRUE(e.min_abs > 1e-6);   /* no point sits on J = 0: the count is unambiguous */
      TEST_TRUE(e.count > previous); /* some inverted, more at t = 1 than at t = 0.5 ... */
      TEST_TRUE(e.count < fcm_mesh_num_cells(mesh) * fcm_rule_num_points(rule)); /* not all */
      TEST_TRUE(si.inverted_points == e.count);
      TEST_TRUE(si.inverted_cell == e.first_cell);
      for (int i = 0; i < 3; i++)
        TEST_NEAR(si.inverted_position[i], e.X[i], 0, 1e-14);
      TEST_NEAR(si.inverted_det, e.det, 1e-8, 1e-12);
      TEST_TRUE(si.inverted_det <= 0.0);
      previous = e.count;
    }
    fcm_integrator_destroy(&integ);
  }

  /* Backward Euler: a free body in rigid rotation is never inverted. */
  {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.dt = 0.05;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    const double omega[3] = {0.0, 0.0, 3.0}, c[3] = {0.5, 0.5, 0.5};
    TEST_OK(ctx, fcm_integrator_set_rigid_velocity(integ, NULL, omega, c));
    for (int step = 0; step < 2; step++) {
      fcm_step_info si;
      TEST_OK(ctx, fcm_integrator_step(integ, &si));
      TEST_TRUE(si.inverted_points == 0 && si.inverted_cell == -1 && si.inverted_det == 0.0);
    }
    fcm_integrator_destroy(&integ);
  }

  fcm_rule_destroy(&rule);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
