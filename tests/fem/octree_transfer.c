/* Fields carried onto a refined octree (fcm_space_transfer_refined()), Hex8 and Hex20, plain
 * and embedded (a ball): a continuous random field keeps its momentum and kinetic energy to
 * 1e-12, the hanging nodes of the new space carry
 * the values of their constraints, and a background that does not refine the old one is refused. */
#include "fem_util.h"

static double sphere(const double x[3], void *user)
{
  (void)user;
  return sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 0.6;
}

/* Momentum (3) and kinetic energy (u^T M u) of u on s (density 2). */
static void moments(fcm_ctx *ctx, const fcm_space *s, const double *u, double p[4])
{
  fcm_csr *M = NULL;
  const fcm_index n = fcm_space_num_dofs(s);
  double *y = calloc((size_t)n, sizeof *y);
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0, 0.3, 2.0};
  TEST_OK(ctx, fcm_space_matrix_create(s, &M));
  TEST_OK(ctx, fcm_assemble_mass(s, &mat, NULL, M));
  TEST_OK(ctx, fcm_csr_apply(M, 1.0, u, 0.0, y));
  p[0] = p[1] = p[2] = p[3] = 0.0;
  for (fcm_index i = 0; i < n; i++)
    p[i % 3] += y[i], p[3] += u[i] * y[i];
  free(y);
  fcm_csr_destroy(&M);
}

static void run(fcm_ctx *ctx, fcm_element_type type, int embedded)
{
  fcm_mesh *m0 = NULL, *m1 = NULL, *other = NULL;
  fcm_space *s0 = NULL, *s1 = NULL, *so = NULL;
  fcm_geometry *ball = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_csr *T0 = NULL, *T1 = NULL;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.45, 0.5, 0.52};
  const fcm_index n[3] = {2, 2, 2};
  fcm_octree_options o = fcm_octree_options_default();
  o.surface = sphere;
  o.surface_level = 2;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n, &o, &m0));
  const fcm_index nc0 = fcm_mesh_num_cells(m0);
  unsigned char *flags = calloc((size_t)nc0, 1);
  for (fcm_index k = 0; k < nc0; k += 3)
    flags[k] = 1;
  TEST_OK(ctx, fcm_mesh_create_refined(ctx, m0, flags, &m1));
  TEST_TRUE(fcm_mesh_num_cells(m1) > nc0 && fcm_mesh_max_level(m1) == 3);
  if (embedded) {
    fcm_cell_rules_options ro = fcm_cell_rules_options_default();
    ro.stabilization.mode = FCM_STABILIZATION_OFF;
    ro.min_fraction = 0.0; /* no cell dropped: both spaces hold the whole ball (a dropped cell
                              loses its material, a different part on each background) */
    TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.35, 3, &ball));
    TEST_OK(ctx, fcm_cell_rules_create(ctx, m0, ball, &ro, &r0));
    TEST_OK(ctx, fcm_cell_rules_create(ctx, m1, ball, &ro, &r1));
    TEST_OK(ctx, fcm_space_create_embedded(ctx, m0, r0, &s0));
    TEST_OK(ctx, fcm_space_create_embedded(ctx, m1, r1, &s1));
  } else {
    TEST_OK(ctx, fcm_space_create(ctx, m0, NULL, &s0));
    TEST_OK(ctx, fcm_space_create(ctx, m1, NULL, &s1));
  }
  /* a random continuous field on the old space */
  const fcm_index n0 = fcm_space_num_dofs(s0), n1 = fcm_space_num_dofs(s1);
  fcm_index nr0 = 0, nr1 = 0;
  TEST_OK(ctx, fcm_space_hanging_matrix_create(s0, NULL, &T0));
  fcm_csr_get_size(T0, NULL, &nr0, NULL);
  double *v = calloc((size_t)nr0, sizeof *v), *u0 = calloc((size_t)n0, sizeof *u0);
  unsigned long long seed = 5;
  for (fcm_index i = 0; i < nr0; i++)
    v[i] = urand(&seed);
  TEST_OK(ctx, fcm_csr_apply(T0, 1.0, v, 0.0, u0));
  double *u1 = calloc((size_t)n1, sizeof *u1);
  TEST_OK(ctx, fcm_space_transfer_refined(s0, s1, u0, u1));
  /* the hanging nodes of the new space hold their constraints' values */
  fcm_index *free1 = calloc((size_t)n1, sizeof *free1);
  TEST_OK(ctx, fcm_space_hanging_matrix_create(s1, free1, &T1));
  fcm_csr_get_size(T1, NULL, &nr1, NULL);
  double *w = calloc((size_t)nr1, sizeof *w), *u1c = calloc((size_t)n1, sizeof *u1c);
  fcm_index hanging = 0;
  for (fcm_index i = 0; i < n1; i++)
    if (free1[i] >= 0)
      w[free1[i]] = u1[i];
    else
      hanging++;
  TEST_TRUE(hanging > 0);
  TEST_OK(ctx, fcm_csr_apply(T1, 1.0, w, 0.0, u1c));
  for (fcm_index i = 0; i < n1; i++)
    TEST_NEAR(u1c[i], u1[i], 0.0, 1e-13);
  /* momentum and kinetic energy are kept (embedded too: the old and new cut cells integrate
   * the same field over the same material) */
  const double tol = 1e-12;
  double p0[4], p1[4];
  moments(ctx, s0, u0, p0);
  moments(ctx, s1, u1, p1);
  const double scale = fabs(p0[0]) + fabs(p0[1]) + fabs(p0[2]);
  for (int k = 0; k < 3; k++)
    TEST_NEAR(p1[k], p0[k], 0.0, tol * scale);
  TEST_NEAR(p1[3], p0[3], tol, 0.0);
  /* a background that does not refine the old one */
  const double hi2[3] = {1.5, 1, 1};
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi2, n, NULL, &other));
  TEST_OK(ctx, fcm_space_create(ctx, other, NULL, &so));
  double *uo = calloc((size_t)fcm_space_num_dofs(so), sizeof *uo);
  if (!embedded)
    TEST_ERR(ctx, fcm_space_transfer_refined(s0, so, u0, uo), FCM_ERR_ARG, "must refine the old");
  free(flags), free(v), free(u0), free(u1), free(free1), free(w), free(u1c), free(uo);
  fcm_csr_destroy(&T0);
  fcm_csr_destroy(&T1);
  fcm_space_destroy(&s0);
  fcm_space_destroy(&s1);
  fcm_space_destroy(&so);
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&r1);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&m0);
  fcm_mesh_destroy(&m1);
  fcm_mesh_destroy(&other);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  run(ctx, type, 0);
  run(ctx, type, 1);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
