/* Assembly on an embedded (FCM) space: a ball embedded in a coarse background
 * grid of every element type. The mass matrix totals rho |ball| and its first
 * moments, gravity totals rho g |ball|, the surface rules give zero net force for
 * a uniform pressure and int x n_x dA = |ball| (divergence theorem), and the
 * stiffness keeps exactly six zero-energy modes. */
#include "fem_util.h"
#include "la/la_impl.h"

static void pressure(void *user, const double x[3], const double n[3], double t[3])
{
  (void)user, (void)x;
  for (int i = 0; i < 3; i++)
    t[i] = -2.5 * n[i];
}

static void x_normal(void *user, const double x[3], const double n[3], double t[3])
{
  (void)user;
  t[0] = x[0] * n[0], t[1] = 0.0, t[2] = 0.0;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *ball = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_csr *M = NULL, *K = NULL;
  fcm_element_type type;
  if (argc < 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c[3] = {0.1, -0.05, 0.03};
  fcm_index cells[3] = {3, 3, 3};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.8, 3, &ball));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.surface_strength = 2;
  ro.simplify = argc > 2 && !strcmp(argv[2], "simplify");
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, ball, &ro, &rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  TEST_TRUE(fcm_cell_rules_get_stats(rules)->num_cut > 0);
  double V = fcm_geometry_volume(ball), rho = 3.0;

  fcm_index n = fcm_space_num_dofs(space), nnodes = fcm_mesh_num_nodes(mesh);
  double *ones = calloc((size_t)n, sizeof *ones), *xc = calloc((size_t)n, sizeof *xc);
  double *y = calloc((size_t)n, sizeof *y), *f = calloc((size_t)n, sizeof *f);
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index i = 0; i < nnodes; i++) {
    fcm_index d = fcm_space_node_dof(space, i);
    if (d < 0) continue;
    ones[d] = 1.0;
    xc[d] = X[3 * i];
  }
  /* Stiffness on the stabilized embedded body: six rigid modes, no spurious zero modes
   * (without stabilization tiny cut cells give near-zero eigenvalues, lib/METHOD.md §7). */
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  fcm_material kmat = {FCM_MATERIAL_LINEAR, 1.0e3, 0.3, 1.0};
  TEST_OK(ctx, fcm_assemble_stiffness(space, &kmat, NULL, K));
  int ni = (int)n;
  if (ni <= 1500) {
    double *dense = calloc((size_t)ni * ni, sizeof *dense), *ev = calloc((size_t)ni, sizeof *ev);
    const fcm_index *rp = fcm_csr_row_ptr(K);
    const int *ci = fcm_csr_col_idx(K);
    const double *v = fcm_csr_values(K);
    for (int i = 0; i < ni; i++)
      for (fcm_index e = rp[i]; e < rp[i + 1]; e++)
        dense[i + (size_t)ci[e] * ni] = v[e];
    TEST_OK(ctx, fcm__syev(ctx, 0, ni, dense, ni, ev));
    int zeros = 0;
    for (int i = 0; i < ni; i++)
      if (fabs(ev[i]) < 1e-9 * ev[ni - 1]) zeros++;
    TEST_TRUE(zeros == 6);
    free(dense), free(ev);
  }

  /* Without stabilization the mass and its moments are those of the embedded body. */
  fcm_cell_rules_destroy(&rules);
  fcm_space_destroy(&space);
  ro.stabilization.mode = FCM_STABILIZATION_OFF;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, ball, &ro, &rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  TEST_TRUE(fcm_space_num_dofs(space) == n);
  /* dropped cells lose their (tiny) volume */
  const fcm_cell_rules_stats *stats = fcm_cell_rules_get_stats(rules);
  double Vkept = stats->embedded_volume - stats->dropped_volume;
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e3, 0.3, rho};
  TEST_OK(ctx, fcm_space_matrix_create(space, &M));
  TEST_OK(ctx, fcm_assemble_mass(space, &mat, NULL, M));
  TEST_OK(ctx, fcm_csr_apply(M, 1.0, ones, 0.0, y));
  double total = 0.0, moment = 0.0;
  for (fcm_index i = 0; i < n; i++)
    total += y[i], moment += y[i] * xc[i];
  TEST_NEAR(total, rho * Vkept, 1e-12, 0.0);
  TEST_NEAR(Vkept, V, 1e-3, 0.0); /* little is dropped at this resolution */
  /* first moment: rho * |ball| * centre_x (the tet mesh of the ball is symmetric about c) */
  TEST_NEAR(moment, rho * Vkept * c[0], 1e-3, 1e-12);

  double g[3] = {0, 0, -9.81};
  TEST_OK(ctx, fcm_assemble_body_force(space, &mat, g, NULL, f));
  double fz = 0.0;
  for (fcm_index i = 2; i < n; i += 3)
    fz += f[i];
  TEST_NEAR(fz, -9.81 * rho * Vkept, 1e-12, 0.0);

  /* Surface rules: a closed surface under uniform pressure has zero net force;
   * int x n_x dA equals the enclosed volume. */
  memset(f, 0, sizeof *f * (size_t)n);
  TEST_OK(ctx, fcm_assemble_surface_traction(space, pressure, NULL, f));
  double net[3] = {0, 0, 0}, fabs_sum = 0.0;
  for (fcm_index i = 0; i < n; i++)
    net[i % 3] += f[i], fabs_sum += fabs(f[i]);
  for (int d = 0; d < 3; d++)
    TEST_NEAR(net[d], 0.0, 0.0, 1e-12 * fabs_sum);
  TEST_TRUE(fabs_sum > 1.0);
  memset(f, 0, sizeof *f * (size_t)n);
  TEST_OK(ctx, fcm_assemble_surface_traction(space, x_normal, NULL, f));
  double div = 0.0;
  for (fcm_index i = 0; i < n; i += 3)
    div += f[i];
  TEST_NEAR(div, V, 1e-12, 0.0);

  free(ones), free(xc), free(y), free(f);
  fcm_csr_destroy(&M);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
