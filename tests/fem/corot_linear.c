/* The element-corotated linear model (FCM_MATERIAL_COROTATED_LINEAR), run for every element
 * type on a distorted mesh and on an embedded ball (cut cells: fictitious points, F averaged
 * over the material):
 *  - at u = 0 the tangent is the linear stiffness K (to 1e-12) and force and energy vanish; at
 *    a small displacement the force is K u up to the second order;
 *  - a rigid motion (rotation by 1.2 rad and a translation) has zero energy and force (to 1e-12
 *    of the force scale |K| L), and rotating a deformed body rotates its force and keeps its
 *    energy;
 *  - the force is the energy's gradient (central differences at a deformed state) and the
 *    tangent is the force's derivative, at a rigidly rotated state and at a deformed and
 *    rotated one (the exact Hessian); there the PSD tangent (project_psd, the warped
 *    R K R^T) is positive semi-definite and misses the rotation terms; both are exactly
 *    symmetric;
 *  - the element matrices are kept: later assemblies build none, until the Lame parameters
 *    change.
 * Usage: fem_corot_linear <element> */
#include "fem/fem_impl.h"
#include "fem_util.h"

static fcm_ctx *ctx;

static double dot(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * b[i];
  return s;
}

static double max_abs(fcm_index n, const double *a)
{
  double m = 0.0;
  for (fcm_index i = 0; i < n; i++)
    m = fmax(m, fabs(a[i]));
  return m;
}

/* Energy and force (f may be NULL) at u. */
static double eval(fcm_assembly_workspace *ws, const fcm_material_params *p, const double *u,
                   double *f, fcm_csr *T, fcm_index n)
{
  double E = NAN;
  if (f) memset(f, 0, sizeof *f * (size_t)n);
  if (T) fcm_csr_set_zero(T);
  TEST_OK(ctx, fcm_assembly_workspace_hyperelastic(ws, p, u, &E, f, T));
  return E;
}

/* The force's derivative at x along du by central differences of step 1e-6 into df (u, fm:
 * work vectors of n). */
static void force_derivative(fcm_assembly_workspace *ws, const fcm_material_params *p,
                             const double *x, const double *du, double *u, double *fm, double *df,
                             fcm_index n)
{
  const double h = 1e-6;
  for (fcm_index i = 0; i < n; i++)
    u[i] = x[i] + h * du[i];
  eval(ws, p, u, df, NULL, n);
  for (fcm_index i = 0; i < n; i++)
    u[i] = x[i] - h * du[i];
  eval(ws, p, u, fm, NULL, n);
  for (fcm_index i = 0; i < n; i++)
    df[i] = (df[i] - fm[i]) / (2 * h);
}

/* u = Q (X + w) + t - X at every DOF (w: a displacement, NULL for none). */
static void rotate(const fcm_space *s, const fcm_mesh *m, const double Q[9], const double t[3],
                   const double *w, double *u)
{
  const double *X = fcm_mesh_coords(m);
  for (fcm_index k = 0; k < fcm_mesh_num_nodes(m); k++) {
    const fcm_index d = fcm_space_node_dof(s, k);
    if (d < 0) continue;
    double x[3];
    for (int i = 0; i < 3; i++)
      x[i] = X[3 * k + i] + (w ? w[d + i] : 0.0);
    for (int i = 0; i < 3; i++)
      u[d + i] = Q[3 * i] * x[0] + Q[3 * i + 1] * x[1] + Q[3 * i + 2] * x[2] + t[i] - X[3 * k + i];
  }
}

/* Every check on one space (mesh: its background mesh). */
static void check_space(fcm_space *space, const fcm_mesh *mesh)
{
  fcm_csr *K = NULL, *T = NULL;
  fcm_assembly_workspace *ws = NULL;
  TEST_OK(ctx, fcm_assembly_workspace_create(space, NULL, &ws));
  const fcm_index n = fcm_space_num_dofs(space);
  double *u = calloc((size_t)n, sizeof *u), *du = calloc((size_t)n, sizeof *du);
  double *w = calloc((size_t)n, sizeof *w), *f = calloc((size_t)n, sizeof *f);
  double *f2 = calloc((size_t)n, sizeof *f2), *Ku = calloc((size_t)n, sizeof *Ku);
  double *fp = calloc((size_t)n, sizeof *fp), *fm = calloc((size_t)n, sizeof *fm);
  unsigned long long seed = 7;
  for (fcm_index i = 0; i < n; i++)
    w[i] = 0.05 * urand(&seed), du[i] = urand(&seed);

  const fcm_material lin = {FCM_MATERIAL_LINEAR, 1.0e4, 0.3, 1.0};
  fcm_material cl = lin;
  cl.model = FCM_MATERIAL_COROTATED_LINEAR;
  fcm_material_params p;
  TEST_OK(ctx, fcm_material_setup(ctx, &cl, &p));
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_space_matrix_create(space, &T));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &lin, NULL, K));
  fcm_index nnz = 0;
  fcm_csr_get_size(K, NULL, NULL, &nnz);
  const double kmax = max_abs(nnz, fcm_csr_values(K));

  /* u = 0: T = K, f = 0, E = 0; all elements built once, none again */
  double E = eval(ws, &p, u, f, T, n);
  TEST_TRUE(fcm__assembly_corot_built(ws) == fcm_space_num_elements(space));
  double kdiff = 0.0;
  for (fcm_index e = 0; e < nnz; e++)
    kdiff = fmax(kdiff, fabs(fcm_csr_values(K)[e] - fcm_csr_values(T)[e]));
  TEST_TRUE(kdiff <= 1e-12 * kmax);
  TEST_TRUE(max_abs(n, f) == 0.0 && E == 0.0);
  /* small displacement: f = K u + O(|u|^2) */
  for (fcm_index i = 0; i < n; i++)
    u[i] = 1e-7 * w[i];
  eval(ws, &p, u, f, NULL, n);
  const fcm_index ne = fcm_space_num_elements(space);
  TEST_TRUE(fcm__assembly_corot_built(ws) == ne);
  TEST_OK(ctx, fcm_csr_apply(K, 1.0, u, 0.0, Ku));
  for (fcm_index i = 0; i < n; i++)
    f2[i] = f[i] - Ku[i];
  printf("small strain: |f - K u| / |K u| = %.3g\n", max_abs(n, f2) / max_abs(n, Ku));
  TEST_TRUE(max_abs(n, f2) <= 1e-6 * max_abs(n, Ku));

  /* rigid motion: rotation by 1.2 rad about (1, 2, 3)/|.|, and a translation */
  double Q[9];
  {
    const double a[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)}, th = 1.2;
    const double c = cos(th), s = sin(th);
    const double K3[9] = {0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0};
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        double kk = 0.0;
        for (int l = 0; l < 3; l++)
          kk += K3[3 * i + l] * K3[3 * l + j];
        Q[3 * i + j] = (i == j) + s * K3[3 * i + j] + (1 - c) * kk;
      }
  }
  const double tr[3] = {0.3, -0.7, 0.2}, zero[3] = {0, 0, 0};
  rotate(space, mesh, Q, tr, NULL, u);
  E = eval(ws, &p, u, f, NULL, n);
  printf("rigid motion: E = %.3g, |f| / (|K| L) = %.3g\n", E, max_abs(n, f) / kmax);
  TEST_TRUE(max_abs(n, f) <= 1e-12 * kmax);
  TEST_TRUE(fabs(E) <= 1e-24 * kmax);

  /* rotated deformation: the same energy, the force rotated */
  const double E0 = eval(ws, &p, w, f, NULL, n);
  rotate(space, mesh, Q, tr, w, u);
  E = eval(ws, &p, u, f2, NULL, n);
  TEST_NEAR(E, E0, 1e-12, 0.0);
  double fdiff = 0.0;
  const double fscale = max_abs(n, f);
  for (fcm_index d = 0; d < n; d += 3)
    for (int i = 0; i < 3; i++)
      fdiff = fmax(fdiff, fabs(f2[d + i] - (Q[3 * i] * f[d] + Q[3 * i + 1] * f[d + 1] +
                                            Q[3 * i + 2] * f[d + 2])));
  TEST_TRUE(fdiff <= 1e-11 * fscale);
  TEST_TRUE(E0 > 0.0 && fscale > 0.0);

  /* the force is the energy's gradient: central differences at w */
  {
    const double h = 1e-6;
    for (fcm_index i = 0; i < n; i++)
      u[i] = w[i] + h * du[i];
    const double Ep = eval(ws, &p, u, NULL, NULL, n);
    for (fcm_index i = 0; i < n; i++)
      u[i] = w[i] - h * du[i];
    const double Em = eval(ws, &p, u, NULL, NULL, n);
    eval(ws, &p, w, f, NULL, n);
    const double fd = (Ep - Em) / (2 * h), an = dot(n, f, du);
    printf("gradient: f.du = %.12g, FD = %.12g\n", an, fd);
    TEST_NEAR(an, fd, 1e-6, 0.0);
  }
  /* at a rigidly rotated state the tangent is the force's derivative */
  {
    rotate(space, mesh, Q, zero, NULL, w);
    eval(ws, &p, w, f, T, n);
    TEST_OK(ctx, fcm_csr_apply(T, 1.0, du, 0.0, Ku));
    force_derivative(ws, &p, w, du, u, fm, fp, n);
    double diff = 0.0;
    for (fcm_index i = 0; i < n; i++)
      diff = fmax(diff, fabs(fp[i] - Ku[i]));
    printf("tangent at a rotation: |T du - FD| / |T du| = %.3g\n", diff / max_abs(n, Ku));
    TEST_TRUE(diff <= 1e-6 * max_abs(n, Ku));
  }
  /* at a deformed and rotated state: the exact Hessian; the PSD tangent misses its rotation
   * terms there, of the order of the strains (w is about 5 %) */
  {
    double *x = calloc((size_t)n, sizeof *x), *dv = calloc((size_t)n, sizeof *dv);
    double *Tv = calloc((size_t)n, sizeof *Tv);
    for (fcm_index i = 0; i < n; i++)
      dv[i] = 0.05 * urand(&seed); /* a deformation of about 5 % (w holds a rotation now) */
    rotate(space, mesh, Q, tr, dv, x);
    force_derivative(ws, &p, x, du, u, fm, fp, n);
    eval(ws, &p, x, f, T, n);
    TEST_OK(ctx, fcm_csr_apply(T, 1.0, du, 0.0, Ku));
    double diff = 0.0;
    for (fcm_index i = 0; i < n; i++)
      diff = fmax(diff, fabs(fp[i] - Ku[i]));
    const double scale = max_abs(n, Ku);
    printf("exact tangent, deformed: |T du - FD| / |T du| = %.3g\n", diff / scale);
    TEST_TRUE(diff <= 1e-6 * scale);
    double asym = 1.0;
    TEST_OK(ctx, fcm_csr_asymmetry(T, &asym));
    TEST_TRUE(asym == 0.0);
    fcm_material_params pp = p;
    pp.project_psd = 1;
    eval(ws, &pp, x, f, T, n);
    TEST_OK(ctx, fcm_csr_apply(T, 1.0, du, 0.0, Ku));
    double miss = 0.0;
    for (fcm_index i = 0; i < n; i++)
      miss = fmax(miss, fabs(fp[i] - Ku[i]));
    printf("PSD tangent, deformed: |T du - FD| / |T du| = %.3g\n", miss / max_abs(n, Ku));
    TEST_TRUE(miss >= 1e-3 * max_abs(n, Ku));
    TEST_OK(ctx, fcm_csr_asymmetry(T, &asym));
    TEST_TRUE(asym == 0.0);
    for (int k = 0; k < 5; k++) {
      for (fcm_index i = 0; i < n; i++)
        dv[i] = urand(&seed) - 0.5;
      TEST_OK(ctx, fcm_csr_apply(T, 1.0, dv, 0.0, Tv));
      TEST_TRUE(dot(n, dv, Tv) >= -1e-12 * kmax * dot(n, dv, dv));
    }
    free(x), free(dv), free(Tv);
  }
  TEST_TRUE(fcm__assembly_corot_built(ws) == ne);
  /* other Lame parameters: every element built again */
  cl.young = 2.0e4;
  TEST_OK(ctx, fcm_material_setup(ctx, &cl, &p));
  eval(ws, &p, w, f, NULL, n);
  TEST_TRUE(fcm__assembly_corot_built(ws) == 2 * ne);

  free(u), free(du), free(w), free(f), free(f2), free(Ku), free(fp), free(fm);
  fcm_assembly_workspace_destroy(&ws);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&T);
}

int main(int argc, char **argv)
{
  fcm_mesh *mesh = NULL, *grid = NULL;
  fcm_space *space = NULL, *embedded = NULL;
  fcm_geometry *ball = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, distorted_box(ctx, type, 2, 0.2, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  if (space) check_space(space, mesh);
  /* an embedded ball: cut cells with their fictitious points and the material-averaged F */
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.52, 0.49, 0.47};
  const fcm_index nc[3] = {3, 3, 3};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, nc, &grid));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.4, 2, &ball));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, grid, ball, NULL, &rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, grid, rules, &embedded));
  if (embedded) check_space(embedded, grid);
  fcm_space_destroy(&space);
  fcm_space_destroy(&embedded);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&mesh);
  fcm_mesh_destroy(&grid);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
