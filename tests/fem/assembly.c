/* Assembly facts, run for every element type on a distorted mesh: the mass
 * matrix sums to rho * volume and reproduces first moments, the stiffness is
 * exactly symmetric (its values, bit for bit, here and on a finer mesh with
 * another Poisson ratio) with exactly six zero-energy modes, the body force
 * totals rho g V, and results are bitwise independent of the number of
 * threads. */
#include "fem_util.h"
#include "la/la_impl.h"

#include <omp.h>

static fcm_status assemble_K(fcm_space *space, const fcm_material *mat, fcm_csr **K)
{
  fcm_status st = fcm_space_matrix_create(space, K);
  if (st == FCM_OK) st = fcm_assemble_stiffness(space, mat, NULL, *K);
  return st;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL, *K1 = NULL, *M = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, distorted_box(ctx, type, 2, 0.25, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e3, 0.25, 7.5};
  fcm_index n = fcm_space_num_dofs(space), nnodes = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  TEST_TRUE(n == 3 * nnodes);
  TEST_TRUE(fcm_space_num_colors(space) >= 8 && fcm_space_num_colors(space) <= 64);

  /* Mass: 1^T M_xx 1 = rho V with V = 1 (the distortion keeps the box), and
   * 1^T M_xx x = rho int x dV = rho / 2 for the unit cube. */
  TEST_OK(ctx, fcm_space_matrix_create(space, &M));
  TEST_OK(ctx, fcm_assemble_mass(space, &mat, NULL, M));
  double *xcoord = calloc((size_t)n, sizeof *xcoord), *ones = calloc((size_t)n, sizeof *ones);
  double *y = calloc((size_t)n, sizeof *y);
  for (fcm_index i = 0; i < nnodes; i++) {
    fcm_index d = fcm_space_node_dof(space, i);
    ones[d] = 1.0;
    xcoord[d] = X[3 * i];
  }
  TEST_OK(ctx, fcm_csr_apply(M, 1.0, ones, 0.0, y));
  double total = 0.0, moment = 0.0;
  for (fcm_index i = 0; i < n; i++)
    total += y[i], moment += y[i] * xcoord[i];
  TEST_NEAR(total, mat.density, 1e-12, 0.0);
  TEST_NEAR(moment, mat.density * 0.5, 1e-12, 0.0);
  double asym = 1.0;
  TEST_OK(ctx, fcm_csr_asymmetry(M, &asym));
  TEST_TRUE(asym < 1e-15);

  /* Body force of gravity totals rho g V and its moment rho g int y dV. */
  double g[3] = {0.0, -9.81, 0.0}, *f = calloc((size_t)n, sizeof *f);
  TEST_OK(ctx, fcm_assemble_body_force(space, &mat, g, NULL, f));
  double fy = 0.0, fx = 0.0;
  for (fcm_index i = 0; i < nnodes; i++) {
    fcm_index d = fcm_space_node_dof(space, i);
    fx += f[d];
    fy += f[d + 1];
  }
  TEST_NEAR(fy, -9.81 * mat.density, 1e-12, 0.0);
  TEST_NEAR(fx, 0.0, 0.0, 1e-12);

  /* Stiffness: symmetric, positive semi-definite with exactly six zero modes. */
  omp_set_num_threads(1);
  TEST_OK(ctx, assemble_K(space, &mat, &K1));
  omp_set_num_threads(3);
  TEST_OK(ctx, assemble_K(space, &mat, &K));
  fcm_index nnz = 0;
  fcm_csr_get_size(K, NULL, NULL, &nnz);
  TEST_TRUE(memcmp(fcm_csr_values(K), fcm_csr_values(K1), sizeof(double) * (size_t)nnz) == 0);
  TEST_OK(ctx, fcm_csr_asymmetry(K, &asym));
  TEST_TRUE(asym == 0.0);
  int ni = (int)n;
  double *dense = calloc((size_t)ni * ni, sizeof *dense), *ev = calloc((size_t)ni, sizeof *ev);
  const fcm_index *rp = fcm_csr_row_ptr(K);
  const int *ci = fcm_csr_col_idx(K);
  const double *v = fcm_csr_values(K);
  for (int i = 0; i < ni; i++)
    for (fcm_index e = rp[i]; e < rp[i + 1]; e++)
      dense[i + (size_t)ci[e] * ni] = v[e];
  TEST_OK(ctx, fcm__syev(ctx, 0, ni, dense, ni, ev));
  double lmax = ev[ni - 1];
  int zeros = 0;
  for (int i = 0; i < ni; i++)
    if (fabs(ev[i]) < 1e-10 * lmax) zeros++;
  TEST_TRUE(zeros == 6);
  TEST_TRUE(ev[0] > -1e-10 * lmax);
  TEST_TRUE(ev[6] > 1e-6 * lmax);

  /* On a finer mesh and with lambda != mu (nu = 0.25 above makes them equal): the kernel
   * sums a diagonal node block's entries (i, j) and (j, i) from lambda and mu terms in
   * different orders, and their bits differ unless it symmetrizes them. */
  {
    const fcm_material mat3 = {FCM_MATERIAL_LINEAR, 1.0e3, 0.3, 7.5};
    fcm_mesh *fine = NULL;
    fcm_space *fs = NULL;
    fcm_csr *KF = NULL;
    TEST_OK(ctx, distorted_box(ctx, type, 4, 0.25, &fine));
    TEST_OK(ctx, fcm_space_create(ctx, fine, NULL, &fs));
    TEST_OK(ctx, assemble_K(fs, &mat3, &KF));
    TEST_OK(ctx, fcm_csr_asymmetry(KF, &asym));
    TEST_TRUE(asym == 0.0);
    fcm_csr_destroy(&KF);
    fcm_space_destroy(&fs);
    fcm_mesh_destroy(&fine);
  }

  /* Errors: wrong matrix, bad material, Dirichlet index out of range and twice. */
  fcm_material bad = {FCM_MATERIAL_LINEAR, 1.0, 0.5, 1.0};
  TEST_ERR(ctx, fcm_assemble_stiffness(space, &bad, NULL, K), FCM_ERR_ARG, "nu = 0.5");
  bad.poisson = 0.3, bad.young = -1;
  TEST_ERR(ctx, fcm_assemble_mass(space, &bad, NULL, M), FCM_ERR_ARG, "E = -1");
  fcm_index idx[2] = {0, n};
  TEST_ERR(ctx, fcm_space_apply_dirichlet(space, 2, idx, NULL, K, f), FCM_ERR_ARG, "out of range");
  idx[1] = 0;
  TEST_ERR(ctx, fcm_space_apply_dirichlet(space, 2, idx, NULL, K, f), FCM_ERR_ARG, "twice");

  free(xcoord), free(ones), free(y), free(f), free(dense), free(ev);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&K1);
  fcm_csr_destroy(&M);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
