/* The Newton matrix a dynamic step takes when the exact tangent is indefinite: on one Hex8
 * cell of Stable Neo-Hookean material, compressed to J = 0.027 and, in a second state, with
 * one corner pushed through the opposite face (inverted quadrature points), the assembled
 * element tangent K(u) has a negative eigenvalue (the premise), its PSD-projected version
 * K+(u) has none below -1e-10 x its largest, and M/h^2 + K+(u) is positive definite for the
 * step of Ton-That's scenes (h = 0.033 s, E = 1e6 Pa, rho = 1000 kg/m^3), where
 * M/h^2 + K(u) is not. Eigenvalues by LAPACK (dsyevd) of the dense 24 x 24 matrices. */
#include "sim_util.h"
#include "la/la_impl.h"

#include <string.h>

enum { N = 24 };

static void dense(const fcm_csr *A, double *D)
{
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  memset(D, 0, sizeof(double) * N * N);
  for (fcm_index i = 0; i < N; i++)
    for (fcm_index e = rp[i]; e < rp[i + 1]; e++)
      D[i * N + ci[e]] = v[e];
}

/* Smallest and largest eigenvalue of a * A + b * B (dense, symmetric). */
static void extremes(fcm_ctx *ctx, double a, const double *A, double b, const double *B, double *lo,
                     double *hi)
{
  double S[N * N], w[N];
  for (int k = 0; k < N * N; k++)
    S[k] = a * A[k] + (B ? b * B[k] : 0.0);
  TEST_OK(ctx, fcm__syev(ctx, 0, N, S, N, w));
  *lo = w[0];
  *hi = w[N - 1];
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_assembly_workspace *ws = NULL;
  fcm_csr *K = NULL, *Kp = NULL, *M = NULL;
  static double Dk[N * N], Dp[N * N], Dm[N * N];
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {0.054, 0.054, 0.054}, h = 0.033;
  const fcm_index cells[3] = {1, 1, 1};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  TEST_TRUE(fcm_space_num_dofs(space) == N);
  TEST_OK(ctx, fcm_assembly_workspace_create(space, NULL, &ws));
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_space_matrix_create(space, &Kp));
  TEST_OK(ctx, fcm_space_matrix_create(space, &M));
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e6, 0.4, 1000.0};
  fcm_material_params p, pp;
  TEST_OK(ctx, fcm_material_setup(ctx, &mat, &p));
  pp = p;
  pp.project_psd = 1;
  fcm_linear_form form = fcm_linear_form_default();
  form.term = FCM_LINEAR_MASS;
  form.material = &mat;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, M, NULL));
  dense(M, Dm);
  const double *X = fcm_mesh_coords(mesh);
  double u[N];
  for (int state = 0; state < 2; state++) {
    for (fcm_index a = 0; a < 8; a++)
      for (int i = 0; i < 3; i++)
        u[fcm_space_node_dof(space, a) + i] = -0.7 * (X[3 * a + i] - 0.027);
    if (state == 1) /* the corner at the origin through the opposite face */
      for (int i = 0; i < 3; i++)
        u[fcm_space_node_dof(space, 0) + i] = 0.07;
    fcm_csr_set_zero(K);
    fcm_csr_set_zero(Kp);
    TEST_OK(ctx, fcm_assembly_workspace_hyperelastic(ws, &p, u, NULL, NULL, K));
    TEST_OK(ctx, fcm_assembly_workspace_hyperelastic(ws, &pp, u, NULL, NULL, Kp));
    dense(K, Dk);
    dense(Kp, Dp);
    double kmin, kmax, pmin, pmax, hmin, hmax, emin, emax;
    extremes(ctx, 1.0, Dk, 0.0, NULL, &kmin, &kmax);
    extremes(ctx, 1.0, Dp, 0.0, NULL, &pmin, &pmax);
    extremes(ctx, 1.0, Dp, 1.0 / (h * h), Dm, &hmin, &hmax);
    extremes(ctx, 1.0, Dk, 1.0 / (h * h), Dm, &emin, &emax);
    printf("state %d: K [%.3e, %.3e], K+ [%.3e, %.3e], M/h^2 + K+ [%.3e, %.3e], "
           "M/h^2 + K [%.3e, %.3e]\n",
           state, kmin, kmax, pmin, pmax, hmin, hmax, emin, emax);
    TEST_TRUE(kmin < -1e-3 * kmax);                /* the exact tangent is indefinite */
    TEST_TRUE(emin < 0.0);                         /* and the inertia does not make it definite */
    TEST_TRUE(pmin >= -1e-10 * pmax);              /* the projected one is PSD */
    TEST_TRUE(hmin > 0.0 && hmin >= hmax * 1e-12); /* and with M/h^2 definite */
  }
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&Kp);
  fcm_csr_destroy(&M);
  fcm_assembly_workspace_destroy(&ws);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
