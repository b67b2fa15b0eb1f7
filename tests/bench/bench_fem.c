/* Benchmark of the linear FEM slice: assembly time per cell and per non-zero for
 * each element type on a box grid of about 100k DOFs, and CHOLMOD analysis,
 * factorization and solve times. Prints its figures; asserts only that the
 * solve worked (residual) so it can run under ctest -L bench. */
#include "fcm/fcm.h"
#include "test.h"

#include <omp.h>

int main(int argc, char **argv)
{
  /* cells per direction giving 35,937 nodes = 107,811 DOFs for every type */
  static const struct {
    fcm_element_type type;
    fcm_index n;
  } cases[] = {{FCM_ELEMENT_TET4, 32},
               {FCM_ELEMENT_TET10, 16},
               {FCM_ELEMENT_HEX8, 32},
               {FCM_ELEMENT_HEX20, 20}};
  double scale = argc > 1 ? atof(argv[1]) : 1.0; /* shrink for a quick look: bench_fem 0.5 */
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1e7, 0.3, 1000};
  printf("threads: %d\n", omp_get_max_threads());
  printf("%-6s %8s %9s %11s %10s %11s %10s %9s %9s %9s %9s %9s\n", "elem", "cells", "dofs", "nnz",
         "K [s]", "us/cell", "ns/nnz", "M [s]", "analyze", "factor", "GFLOP/s", "solve");
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    fcm_index n = (fcm_index)(cases[k].n * scale + 0.5);
    if (n < 1) n = 1;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, g[3] = {0, 0, -9.81};
    fcm_index cells[3] = {n, n, n};
    fcm_mesh *mesh = NULL;
    fcm_space *space = NULL;
    fcm_csr *K = NULL, *M = NULL;
    fcm_direct *solver = NULL;
    TEST_OK(ctx, fcm_mesh_create_box(ctx, cases[k].type, lo, hi, cells, &mesh));
    TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
    TEST_OK(ctx, fcm_space_matrix_create(space, &K));
    TEST_OK(ctx, fcm_space_matrix_create(space, &M));
    fcm_index ndof = fcm_space_num_dofs(space), nnz = 0, ncell = fcm_mesh_num_cells(mesh);
    fcm_csr_get_size(K, NULL, NULL, &nnz);
    /* best of 3 assemblies (the first one also warms up the threads) */
    double tK = 1e30, tM = 1e30;
    for (int rep = 0; rep < 3; rep++) {
      fcm_csr_set_zero(K);
      fcm_csr_set_zero(M);
      double t0 = fcm_wtime();
      TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, K));
      double t1 = fcm_wtime();
      TEST_OK(ctx, fcm_assemble_mass(space, &mat, NULL, M));
      double t2 = fcm_wtime();
      tK = fmin(tK, t1 - t0);
      tM = fmin(tM, t2 - t1);
    }
    double *f = calloc((size_t)ndof, sizeof *f), *u = calloc((size_t)ndof, sizeof *u);
    double *r = calloc((size_t)ndof, sizeof *r);
    TEST_OK(ctx, fcm_assemble_body_force(space, &mat, g, NULL, f));
    /* clamp the z = 0 face */
    double plo[3] = {-1, -1, 0}, phi[3] = {2, 2, 0};
    fcm_index nfix = 0;
    TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-9, 0, NULL, &nfix));
    fcm_index *nodes = calloc((size_t)nfix, sizeof *nodes),
              *dofs = calloc(3 * (size_t)nfix, sizeof *dofs);
    TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-9, nfix, nodes, &nfix));
    for (fcm_index i = 0; i < nfix; i++)
      for (int d = 0; d < 3; d++)
        dofs[3 * i + d] = fcm_space_node_dof(space, nodes[i]) + d;
    TEST_OK(ctx, fcm_space_apply_dirichlet(space, 3 * nfix, dofs, NULL, K, f));
    fcm_direct_info di;
    TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, K, &solver));
    TEST_OK(ctx, fcm_direct_analyze(solver));
    TEST_OK(ctx, fcm_direct_factor(solver, fcm_csr_values(K)));
    TEST_OK(ctx, fcm_direct_solve(solver, f, u));
    fcm_direct_get_info(solver, &di);
    TEST_OK(ctx, fcm_csr_apply(K, 1.0, u, 0.0, r));
    double rn = 0, fn = 0;
    for (fcm_index i = 0; i < ndof; i++)
      rn += (r[i] - f[i]) * (r[i] - f[i]), fn += f[i] * f[i];
    TEST_TRUE(sqrt(rn) <= 1e-8 * sqrt(fn));
    printf("%-6s %8lld %9lld %11lld %10.3f %11.1f %10.2f %9.3f %9.3f %9.3f %9.2f %9.3f\n",
           fcm_element_get_info(cases[k].type)->name, (long long)ncell, (long long)ndof,
           (long long)nnz, tK, 1e6 * tK / (double)ncell, 1e9 * tK / (double)nnz, tM,
           di.time_analyze, di.time_factor, di.factor_flops / di.time_factor * 1e-9, di.time_solve);
    fflush(stdout);
    free(f), free(u), free(r), free(nodes), free(dofs);
    fcm_direct_destroy(&solver);
    fcm_csr_destroy(&K);
    fcm_csr_destroy(&M);
    fcm_space_destroy(&space);
    fcm_mesh_destroy(&mesh);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
