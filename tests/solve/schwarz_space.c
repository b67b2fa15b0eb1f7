/* Schwarz blocks from a space (fcm_space_cell_blocks, fem): one block of 3 x
 * nodes-per-cell DOFs per flagged cell, in cell order with the DOFs of the cell's nodes,
 * counts checked against the mesh; setup and apply are bitwise identical on 1, 2 and 3
 * threads, and so is a preconditioned CG solve of a Hex20 elasticity step M + dt^2 K;
 * CG and MINRES with Schwarz converge; a flagged inactive cell and a single output
 * buffer are rejected. */
#include "solve_test_util.h"

#include <omp.h>

/* Schwarz with one block per flagged cell: count, fill, create. */
static fcm_status schwarz_on_cells(fcm_ctx *ctx, const fcm_space *space, const fcm_csr *A,
                                   const unsigned char *flag, fcm_schwarz **P)
{
  fcm_status st;
  fcm_index nb = 0, nd = 0;
  if ((st = fcm_space_cell_blocks(space, flag, &nb, &nd, NULL, NULL))) return st;
  fcm_index *ptr = malloc(sizeof *ptr * (size_t)(nb + 1)),
            *dofs = malloc(sizeof *dofs * (size_t)(nd + 1));
  if (!ptr || !dofs) abort();
  st = fcm_space_cell_blocks(space, flag, &nb, &nd, ptr, dofs);
  if (!st) st = fcm_schwarz_create(ctx, A, nb, ptr, dofs, NULL, P);
  free(ptr);
  free(dofs);
  return st;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL, *space2 = NULL;
  fcm_csr *A = NULL, *K = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index cells[3] = {4, 4, 4};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX20, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  const fcm_index n = fcm_space_num_dofs(space), nc = fcm_mesh_num_cells(mesh);
  const int npc = fcm_mesh_nodes_per_cell(mesh);

  /* A = M + dt^2 K, clamped at x = 0 */
  fcm_material mat = {FCM_MATERIAL_LINEAR, 3e6, 0.4, 1000.0};
  const double dt = 1.0 / 60.0;
  TEST_OK(ctx, fcm_space_matrix_create(space, &A));
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_assemble_mass(space, &mat, NULL, A));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, K));
  fcm_index nnz;
  fcm_csr_get_size(A, NULL, NULL, &nnz);
  double *av = fcm_csr_values(A);
  const double *kv = fcm_csr_values(K);
  for (fcm_index p = 0; p < nnz; p++)
    av[p] += dt * dt * kv[p];
  const double plo[3] = {0, -HUGE_VAL, -HUGE_VAL}, phi[3] = {0, HUGE_VAL, HUGE_VAL};
  fcm_index nfix = 0;
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-12, 0, NULL, &nfix));
  fcm_index *fixn = malloc(sizeof *fixn * (size_t)nfix),
            *fixd = malloc(sizeof *fixd * 3 * (size_t)nfix);
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-12, nfix, fixn, &nfix));
  for (fcm_index k = 0; k < nfix; k++)
    for (int i = 0; i < 3; i++)
      fixd[3 * k + i] = fcm_space_node_dof(space, fixn[k]) + i;
  double *b = calloc((size_t)n, sizeof *b);
  rng r = {17};
  for (fcm_index i = 0; i < n; i++)
    b[i] = rng_uniform(&r);
  TEST_OK(ctx, fcm_space_apply_dirichlet(space, 3 * nfix, fixd, NULL, A, b));

  /* flag two thirds of the cells; the uncovered DOFs counted from the mesh */
  unsigned char *flag = calloc((size_t)nc, 1), *covered = calloc((size_t)n, 1);
  fcm_index nflag = 0, ncov = 0;
  const fcm_index *cn = fcm_mesh_cells(mesh);
  for (fcm_index c = 0; c < nc; c++) {
    flag[c] = (c % 3) != 0;
    if (!flag[c]) continue;
    nflag++;
    for (int a = 0; a < npc; a++)
      for (int i = 0; i < 3; i++)
        covered[fcm_space_node_dof(space, cn[c * npc + a]) + i] = 1;
  }
  for (fcm_index i = 0; i < n; i++)
    ncov += covered[i];

  /* the blocks: counts, then the DOFs of the flagged cells' nodes in order */
  {
    fcm_index nb = -1, nd = -1;
    TEST_OK(ctx, fcm_space_cell_blocks(space, flag, &nb, &nd, NULL, NULL));
    TEST_TRUE(nb == nflag && nd == 3 * npc * nflag);
    fcm_index *ptr = malloc(sizeof *ptr * (size_t)(nb + 1)),
              *dofs = malloc(sizeof *dofs * (size_t)nd);
    TEST_OK(ctx, fcm_space_cell_blocks(space, flag, &nb, &nd, ptr, dofs));
    fcm_index k = 0;
    for (fcm_index c = 0; c < nc; c++) {
      if (!flag[c]) continue;
      TEST_TRUE(ptr[k] == 3 * npc * k);
      for (int a = 0; a < npc; a++)
        for (int i = 0; i < 3; i++)
          TEST_TRUE(dofs[ptr[k] + 3 * a + i] == fcm_space_node_dof(space, cn[c * npc + a]) + i);
      k++;
    }
    TEST_TRUE(k == nb && ptr[nb] == nd);
    TEST_ERR(ctx, fcm_space_cell_blocks(space, flag, &nb, &nd, ptr, NULL), FCM_ERR_ARG,
             "both block_ptr and block_dofs");
    free(ptr);
    free(dofs);
  }

  enum { NV = 3 };
  double *rv = malloc(sizeof *rv * (size_t)(NV * n)), *z[3], *x[3];
  for (fcm_index i = 0; i < NV * n; i++)
    rv[i] = rng_uniform(&r);
  int iters[3] = {0, 0, 0};
  for (int t = 0; t < 3; t++) {
    omp_set_num_threads(t + 1);
    fcm_schwarz *P = NULL;
    TEST_OK(ctx, schwarz_on_cells(ctx, space, A, flag, &P));
    fcm_schwarz_info si;
    fcm_schwarz_get_info(P, &si);
    TEST_TRUE(si.num_blocks == nflag && si.block_dofs == 3 * npc * nflag);
    TEST_TRUE(si.outside_dofs == n - ncov && si.max_block_size == 3 * npc);
    TEST_TRUE(si.num_colors >= 2 && si.clamped_eigenvalues == 0 && si.negative_eigenvalues == 0);
    z[t] = malloc(sizeof *z[t] * (size_t)(NV * n));
    for (int v = 0; v < NV; v++)
      TEST_OK(ctx, fcm_schwarz_apply(P, rv + v * n, z[t] + v * n));
    x[t] = calloc((size_t)n, sizeof *x[t]);
    fcm_krylov_options o = fcm_krylov_options_default();
    fcm_krylov_info info;
    TEST_OK(ctx,
            fcm_cg_solve(ctx, n, fcm_csr_operator, A, fcm_schwarz_operator, P, b, x[t], &o, &info));
    iters[t] = info.iterations;
    if (t == 0) {
      /* MINRES with the same preconditioner reaches the same tolerance */
      double *y = calloc((size_t)n, sizeof *y);
      o.check_true_residual = 1;
      TEST_OK(ctx, fcm_minres_solve(ctx, n, fcm_csr_operator, A, fcm_schwarz_operator, P, b, y, &o,
                                    &info));
      TEST_TRUE(info.true_residual < 1e-6);
      free(y);
    }
    fcm_schwarz_destroy(&P);
  }
  for (int t = 1; t < 3; t++) {
    TEST_TRUE(memcmp(z[0], z[t], sizeof *z[0] * (size_t)(NV * n)) == 0);
    TEST_TRUE(memcmp(x[0], x[t], sizeof *x[0] * (size_t)n) == 0);
    TEST_TRUE(iters[t] == iters[0]);
  }
  TEST_TRUE(true_residual(A, b, x[0], n) < 1e-7);
  omp_set_num_threads(2);

  /* unpreconditioned CG needs more iterations than with Schwarz */
  {
    double *y = calloc((size_t)n, sizeof *y);
    fcm_krylov_options o = fcm_krylov_options_default();
    o.max_iterations = 5000;
    fcm_krylov_info info;
    TEST_OK(ctx, fcm_cg_solve(ctx, n, fcm_csr_operator, A, NULL, NULL, b, y, &o, &info));
    if (!(info.iterations > iters[0]))
      TEST_FAIL_("plain CG %d iterations, with Schwarz %d", info.iterations, iters[0]);
    free(y);
  }

  /* a flagged inactive cell */
  unsigned char *active = malloc((size_t)nc);
  memset(active, 1, (size_t)nc);
  active[0] = 0;
  TEST_OK(ctx, fcm_space_create(ctx, mesh, active, &space2));
  fcm_csr *A2 = NULL;
  fcm_schwarz *P2 = NULL;
  TEST_OK(ctx, fcm_space_matrix_create(space2, &A2));
  memset(flag, 0, (size_t)nc);
  flag[0] = 1;
  TEST_ERR(ctx, schwarz_on_cells(ctx, space2, A2, flag, &P2), FCM_ERR_ARG,
           "cell 0 is flagged but inactive");
  TEST_TRUE(P2 == NULL);
  fcm_csr_destroy(&A2);

  for (int t = 0; t < 3; t++) {
    free(z[t]);
    free(x[t]);
  }
  free(active);
  free(rv);
  free(flag);
  free(covered);
  free(b);
  free(fixn);
  free(fixd);
  fcm_csr_destroy(&A);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space2);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
