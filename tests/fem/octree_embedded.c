/* An embedded ball in an octree background refined along its boundary (Hex8, Hex20): every cell
 * the boundary crosses is at the finest level, the cut-cell rules' volume of the octree's cells
 * of all sizes sums to the ball's volume (also after refining the cells of small volume
 * fraction once more), the constrained mass totals rho |ball|, and what the
 * hanging-node constraints do not cover is refused: the multigrid on the unconstrained
 * matrix, the integrators with a preconditioner that works on the space's cells and nodes as they
 * are. */
#include "fem_util.h"

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *ball = NULL;
  fcm_cell_rules *rules = NULL, *cut_rules = NULL;
  fcm_space *space = NULL;
  fcm_csr *M = NULL, *T = NULL, *Mr = NULL;
  fcm_surface *cut = NULL;
  fcm_mg *mg = NULL;
  fcm_integrator *integ = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.48, 0.51, 0.5};
  const fcm_index cells[3] = {3, 3, 3};
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.3, 3, &ball));
  fcm_octree_options o = fcm_octree_options_default();
  o.refine = fcm_geometry_boundary_meets_box;
  o.refine_user = ball;
  o.refine_level = 2;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, cells, &o, &mesh));
  TEST_TRUE(fcm_mesh_max_level(mesh) == 2 && fcm_mesh_num_hanging(mesh) > 0);
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.stabilization.mode = FCM_STABILIZATION_OFF;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, ball, &ro, &rules));

  /* the boundary crosses only finest cells; their volumes sum to the ball's */
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  double vol = 0.0;
  fcm_index crossed = 0;
  for (fcm_index k = 0; k < nc; k++) {
    const double phi = fcm_cell_rules_volume_fraction(rules, k);
    const double h = 1.0 / (3.0 * (double)(1 << fcm_mesh_cell_level(mesh, k)));
    vol += phi * h * h * h;
    if (phi > 1e-9 && phi < 1 - 1e-9) {
      crossed++;
      TEST_TRUE(fcm_mesh_cell_level(mesh, k) == 2);
    }
  }
  TEST_TRUE(crossed > 0);
  const fcm_cell_rules_stats *stats = fcm_cell_rules_get_stats(rules);
  TEST_NEAR(vol, stats->embedded_volume, 1e-12, 0.0);
  TEST_NEAR(stats->embedded_volume, fcm_geometry_volume(ball), 1e-10, 0.0);

  /* refine the cut cells with a small volume fraction once more: the new mesh's rules still
   * hold the whole ball, and those regions are now one level finer */
  {
    unsigned char *flags = calloc((size_t)nc, 1);
    fcm_index nflag = 0;
    for (fcm_index k = 0; k < nc; k++) {
      const double phi = fcm_cell_rules_volume_fraction(rules, k);
      nflag += flags[k] = phi > 1e-9 && phi < 0.15;
    }
    TEST_TRUE(nflag > 0);
    fcm_mesh *fine = NULL;
    fcm_cell_rules *fine_rules = NULL;
    TEST_OK(ctx, fcm_mesh_create_refined(ctx, mesh, flags, &fine));
    TEST_TRUE(fcm_mesh_max_level(fine) == 3);
    TEST_TRUE(fcm_mesh_num_cells(fine) >= nc + 7 * nflag);
    TEST_OK(ctx, fcm_cell_rules_create(ctx, fine, ball, &ro, &fine_rules));
    TEST_NEAR(fcm_cell_rules_get_stats(fine_rules)->embedded_volume, fcm_geometry_volume(ball),
              1e-10, 0.0);
    fcm_cell_rules_destroy(&fine_rules);
    fcm_mesh_destroy(&fine);
    free(flags);
  }

  /* the constrained mass (T^T M T) totals rho |kept ball| */
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  TEST_OK(ctx, fcm_space_hanging_matrix_create(space, NULL, &T));
  TEST_OK(ctx, fcm_space_matrix_create(space, &M));
  const double rho = 3.0;
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e3, 0.3, rho};
  TEST_OK(ctx, fcm_assemble_mass(space, &mat, NULL, M));
  TEST_OK(ctx, fcm_csr_create_ptap(ctx, M, T, &Mr));
  fcm_index nr = 0;
  fcm_csr_get_size(Mr, &nr, NULL, NULL);
  double *ones = calloc((size_t)nr, sizeof *ones), *y = calloc((size_t)nr, sizeof *y);
  for (fcm_index i = 0; i < nr; i += 3)
    ones[i] = 1.0;
  TEST_OK(ctx, fcm_csr_apply(Mr, 1.0, ones, 0.0, y));
  double total = 0.0;
  for (fcm_index i = 0; i < nr; i++)
    total += y[i];
  TEST_NEAR(total, rho * (stats->embedded_volume - stats->dropped_volume), 1e-12, 0.0);

  /* a cut applies; refused: */
  const double p[3] = {0.5, 0.5, 0.5}, nx[3] = {1, 0, 0};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nx, lo, hi, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, ball, rules, cut, &cut_rules));
  /* the multigrid needs the constrained operator P^T M P + I_h, not M */
  TEST_ERR(ctx, fcm_mg_create(ctx, space, M, NULL, &mg), FCM_ERR_ARG, "hanging DOF");
  fcm_integrator_options io = fcm_integrator_options_default();
  io.kind = FCM_INTEGRATOR_STATIC;
  io.linear_solver = FCM_LINEAR_CG;
  io.preconditioner = FCM_PRECOND_BLOCK_JACOBI;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &io, &integ));
  TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_UNSUPPORTED,
           "preconditioner FCM_PRECOND_BLOCK_JACOBI works");

  free(ones), free(y);
  fcm_integrator_destroy(&integ);
  fcm_surface_destroy(&cut);
  fcm_cell_rules_destroy(&cut_rules);
  fcm_csr_destroy(&Mr);
  fcm_csr_destroy(&M);
  fcm_csr_destroy(&T);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
