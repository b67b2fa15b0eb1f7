/* Hyperelastic assembly, run for every element type on a distorted mesh: the
 * linear model reproduces the linear stiffness (K u and K itself), and for the
 * nonlinear models the internal force is the derivative of the energy and the
 * tangent the derivative of the force (central differences) and exactly symmetric
 * (its values, bit for bit); NaN input is caught. */
#include "fem_util.h"

static double dot(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * b[i];
  return s;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL, *T = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, distorted_box(ctx, type, 2, 0.2, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index n = fcm_space_num_dofs(space), nnz = 0;
  double *u = calloc((size_t)n, sizeof *u), *du = calloc((size_t)n, sizeof *du);
  double *f = calloc((size_t)n, sizeof *f), *fp = calloc((size_t)n, sizeof *fp);
  double *fm = calloc((size_t)n, sizeof *fm), *Ku = calloc((size_t)n, sizeof *Ku);
  unsigned long long seed = 99;
  for (fcm_index i = 0; i < n; i++)
    u[i] = 0.05 * urand(&seed), du[i] = urand(&seed);

  /* Linear model == linear stiffness: same matrix, force = K u, energy = u.K u / 2. */
  fcm_material lin = {FCM_MATERIAL_LINEAR, 1.0e4, 0.3, 1.0};
  fcm_material_params p;
  TEST_OK(ctx, fcm_material_setup(ctx, &lin, &p));
  fcm_material el = {FCM_MATERIAL_LINEAR, lin.young, lin.poisson, lin.density};
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_space_matrix_create(space, &T));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &el, NULL, K));
  double E = 0.0;
  TEST_OK(ctx, fcm_assemble_hyperelastic(space, &p, u, NULL, &E, f, T));
  TEST_OK(ctx, fcm_csr_apply(K, 1.0, u, 0.0, Ku));
  fcm_csr_get_size(K, NULL, NULL, &nnz);
  double kmax = 0.0, kdiff = 0.0, fdiff = 0.0, fbig = 0.0;
  for (fcm_index e = 0; e < nnz; e++) {
    kmax = fmax(kmax, fabs(fcm_csr_values(K)[e]));
    kdiff = fmax(kdiff, fabs(fcm_csr_values(K)[e] - fcm_csr_values(T)[e]));
  }
  for (fcm_index i = 0; i < n; i++) {
    fbig = fmax(fbig, fabs(Ku[i]));
    fdiff = fmax(fdiff, fabs(Ku[i] - f[i]));
  }
  TEST_TRUE(kdiff <= 1e-12 * kmax);
  TEST_TRUE(fdiff <= 1e-12 * fbig);
  TEST_NEAR(E, 0.5 * dot(n, u, Ku), 1e-12, 0.0);

  /* Nonlinear models: directional derivatives by central differences. */
  static const fcm_material_model models[] = {FCM_MATERIAL_STVK, FCM_MATERIAL_COROTATED,
                                              FCM_MATERIAL_STABLE_NEO_HOOKEAN};
  for (int m = 0; m < 3; m++) {
    fcm_material mat = {models[m], 1.0e4, 0.4, 1.0};
    TEST_OK(ctx, fcm_material_setup(ctx, &mat, &p));
    memset(f, 0, sizeof *f * (size_t)n);
    fcm_csr_set_zero(T);
    TEST_OK(ctx, fcm_assemble_hyperelastic(space, &p, u, NULL, &E, f, T));
    double h = 1e-6, Ep = 0, Em = 0;
    for (fcm_index i = 0; i < n; i++)
      u[i] += h * du[i];
    memset(fp, 0, sizeof *fp * (size_t)n);
    TEST_OK(ctx, fcm_assemble_hyperelastic(space, &p, u, NULL, &Ep, fp, NULL));
    for (fcm_index i = 0; i < n; i++)
      u[i] -= 2 * h * du[i];
    memset(fm, 0, sizeof *fm * (size_t)n);
    TEST_OK(ctx, fcm_assemble_hyperelastic(space, &p, u, NULL, &Em, fm, NULL));
    for (fcm_index i = 0; i < n; i++)
      u[i] += h * du[i];
    /* dE/du . du */
    TEST_NEAR((Ep - Em) / (2 * h), dot(n, f, du), 1e-6, 0.0);
    /* T du vs (f(u + h du) - f(u - h du)) / 2h */
    TEST_OK(ctx, fcm_csr_apply(T, 1.0, du, 0.0, Ku));
    double err = 0.0, ref = 0.0;
    for (fcm_index i = 0; i < n; i++) {
      double fd = (fp[i] - fm[i]) / (2 * h);
      err = fmax(err, fabs(fd - Ku[i]));
      ref = fmax(ref, fabs(Ku[i]));
    }
    TEST_TRUE(err <= 1e-6 * ref);
    double asym = 1;
    TEST_OK(ctx, fcm_csr_asymmetry(T, &asym));
    TEST_TRUE(asym == 0.0);
  }

  /* A NaN displacement is reported, not propagated. */
  u[0] = NAN;
  TEST_ERR(ctx, fcm_assemble_hyperelastic(space, &p, u, NULL, &E, f, NULL), FCM_ERR_NUMERIC, "NaN");

  free(u), free(du), free(f), free(fp), free(fm), free(Ku);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&T);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
