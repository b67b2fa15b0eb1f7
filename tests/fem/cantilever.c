/* A cantilever under its own weight (8 x 1 x 1, clamped at x = 0): the tip
 * deflection of the quadratic elements at moderate resolution lies within 2 %
 * of Timoshenko beam theory, and refining moves it towards the theory. */
#include "fem_util.h"

/* Timoshenko tip deflection of a cantilever under a uniform load q per length:
 * q L^4 / (8 E I) + q L^2 / (2 kappa G A), rectangular section b x h with
 * Cowper's shear coefficient kappa = 10 (1 + nu) / (12 + 11 nu). */
static double timoshenko(double L, double b, double h, const fcm_material *m, double g)
{
  double A = b * h, I = b * h * h * h / 12.0, q = m->density * g * A;
  double G = m->young / (2.0 * (1.0 + m->poisson));
  double kappa = 10.0 * (1.0 + m->poisson) / (12.0 + 11.0 * m->poisson);
  return q * L * L * L * L / (8.0 * m->young * I) + q * L * L / (2.0 * kappa * G * A);
}

/* Deflection (-u_z) at the centre of the tip face, on a mesh of nx x n x n cells. */
static double tip_deflection(fcm_ctx *ctx, fcm_element_type type, fcm_index nx, fcm_index n,
                             const fcm_material *mat, double g)
{
  double lo[3] = {0, 0, 0}, hi[3] = {8, 1, 1}, accel[3] = {0, 0, -g}, result = NAN;
  fcm_index cells[3] = {nx, n, n}, nfix = 0;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_assemble_stiffness(space, mat, NULL, K));
  fcm_index ndof = fcm_space_num_dofs(space);
  double *f = calloc((size_t)ndof, sizeof *f), *u = calloc((size_t)ndof, sizeof *u);
  TEST_OK(ctx, fcm_assemble_body_force(space, mat, accel, NULL, f));
  double plo[3] = {0, -1, -1}, phi[3] = {0, 2, 2};
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-9, 0, NULL, &nfix));
  fcm_index *nodes = calloc((size_t)nfix, sizeof *nodes),
            *dofs = calloc(3 * (size_t)nfix, sizeof *dofs);
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-9, nfix, nodes, &nfix));
  for (fcm_index k = 0; k < nfix; k++)
    for (int d = 0; d < 3; d++)
      dofs[3 * k + d] = fcm_space_node_dof(space, nodes[k]) + d;
  TEST_OK(ctx, fcm_space_apply_dirichlet(space, 3 * nfix, dofs, NULL, K, f));
  TEST_OK(ctx, direct_solve(ctx, K, f, u));
  /* the tip-face centre (8, 0.5, 0.5) is a node for even n */
  double tlo[3] = {8, 0.5, 0.5};
  fcm_index tip = -1, cnt = 0;
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, tlo, tlo, 1e-9, 1, &tip, &cnt));
  TEST_TRUE(cnt == 1);
  if (cnt == 1) result = -u[fcm_space_node_dof(space, tip) + 2];
  free(f), free(u), free(nodes), free(dofs);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  return result;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e7, 0.3, 1000.0};
  double ref = timoshenko(8.0, 1.0, 1.0, &mat, 9.81);
  double coarse = tip_deflection(ctx, type, 8, 2, &mat, 9.81);
  double fine = tip_deflection(ctx, type, 16, 4, &mat, 9.81);
  TEST_NEAR(fine, ref, 0.02, 0.0);
  TEST_TRUE(fabs(fine - ref) <= fabs(coarse - ref) + 1e-3 * ref);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  if (getenv("FCM_TEST_VERBOSE"))
    printf("%s: Timoshenko %.6g, coarse %.6g (%.2f%%), fine %.6g (%.2f%%)\n", argv[1], ref, coarse,
           100 * (coarse - ref) / ref, fine, 100 * (fine - ref) / ref);
  return TEST_RESULT();
}
