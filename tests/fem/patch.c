/* Patch test, run for every element type: a linear displacement field imposed
 * on the boundary of a distorted mesh is reproduced exactly inside, and the
 * stresses it produces are constant. */
#include "fem_util.h"
#include "la/mat3.h"

static void linear_field(const double x[3], double u[3])
{
  static const double A[9] = {1e-3, 2e-3, -1e-3, 0.5e-3, -2e-3, 1.5e-3, 3e-3, 1e-3, 2.5e-3};
  static const double c[3] = {0.1, -0.2, 0.3};
  fcm__mat3_mulv(A, x, u);
  for (int i = 0; i < 3; i++)
    u[i] += c[i];
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, distorted_box(ctx, type, 3, 0.25, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  fcm_material mat = {FCM_MATERIAL_LINEAR, 2.0e5, 0.3, 1.0};
  TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, K));

  fcm_index n = fcm_space_num_dofs(space), nnodes = fcm_mesh_num_nodes(mesh), ncon = 0;
  double *b = calloc((size_t)n, sizeof *b), *u = calloc((size_t)n, sizeof *u);
  double *vals = calloc((size_t)n, sizeof *vals);
  fcm_index *dofs = calloc((size_t)n, sizeof *dofs);
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index i = 0; i < nnodes; i++) {
    int boundary = 0;
    for (int d = 0; d < 3; d++)
      if (X[3 * i + d] < 1e-12 || X[3 * i + d] > 1 - 1e-12) boundary = 1;
    if (!boundary) continue;
    double ul[3];
    linear_field(X + 3 * i, ul);
    for (int d = 0; d < 3; d++) {
      dofs[ncon] = fcm_space_node_dof(space, i) + d;
      vals[ncon++] = ul[d];
    }
  }
  TEST_TRUE(ncon < n); /* there are free interior nodes */
  TEST_OK(ctx, fcm_space_apply_dirichlet(space, ncon, dofs, vals, K, b));
  TEST_OK(ctx, direct_solve(ctx, K, b, u));

  /* Every node, interior ones included, carries the linear field. */
  double maxerr = 0.0;
  for (fcm_index i = 0; i < nnodes; i++) {
    double ul[3];
    linear_field(X + 3 * i, ul);
    for (int d = 0; d < 3; d++)
      maxerr = fmax(maxerr, fabs(u[fcm_space_node_dof(space, i) + d] - ul[d]));
  }
  TEST_NEAR(maxerr, 0.0, 0.0, 1e-12);

  /* The displacement gradient is the constant matrix at sample points of every cell. */
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  double Xc[3 * FCM_ELEMENT_MAX_NODES], dN[3 * FCM_ELEMENT_MAX_NODES];
  double maxgrad = 0.0;
  const double xi[3] = {0.2, 0.15, info->shape == FCM_SHAPE_TET ? 0.3 : -0.4};
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm_mesh_cell_coords(mesh, c, Xc);
    double J[9], Ji[9] = {0};
    fcm_element_jacobian(type, Xc, xi, J);
    fcm__mat3_inv(J, Ji);
    fcm_element_eval_grad(type, xi, dN);
    double G[9] = {0}; /* du_i/dx_j */
    const fcm_index *cn = fcm_mesh_cells(mesh) + c * info->num_nodes;
    for (int a = 0; a < info->num_nodes; a++) {
      double g[3];
      fcm__mat3_tmulv(Ji, dN + 3 * a, g);
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          G[3 * i + j] += u[fcm_space_node_dof(space, cn[a]) + i] * g[j];
    }
    double e1[3] = {1, 0, 0}, e2[3] = {0, 1, 0}, e3[3] = {0, 0, 1}, z[3] = {0, 0, 0}, u0[3];
    double *E[3] = {e1, e2, e3};
    linear_field(z, u0);
    for (int j = 0; j < 3; j++) {
      double uj[3];
      linear_field(E[j], uj);
      for (int i = 0; i < 3; i++)
        maxgrad = fmax(maxgrad, fabs(G[3 * i + j] - (uj[i] - u0[i])));
    }
  }
  /* stresses = lambda tr(eps) I + 2 mu eps: constant to 1e-10 relative to E |grad u| */
  TEST_NEAR(maxgrad, 0.0, 0.0, 1e-10 * 3e-3);

  free(b), free(u), free(vals), free(dofs);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
