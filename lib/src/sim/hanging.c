/* sim: hanging-node constraints of an octree space inside the integrator.
 *
 * The space's hanging DOFs follow their masters, u = T u_free (fcm_space_hanging_matrix_create()).
 * The integrator keeps its vectors on all DOFs and writes T as the square matrix P (n x n) whose
 * row of a free DOF is that DOF itself and whose row of a hanging DOF holds its masters' weights
 * (the masters are free DOFs). Then the Newton system of the constrained problem,
 * T^T H T dv = -T^T g, is the system on all DOFs
 *   (P^T H P + I_h) d = -P^T g,
 * I_h the identity on the hanging DOFs: their rows and columns of P^T H P are zero, so their
 * entries of d come out zero and are then filled from the masters (d = P d). The gradient the
 * Newton loop sees is the reduced one, P^T g (zero on the hanging DOFs): its norms, the stopping
 * rule and the reactions are those of the constrained problem, and its slope g.d with d = P dv
 * is the full gradient's. Mass, loads and the boundary terms enter g and H, so they are reduced
 * alike. The state stays in the range of P: every increment is P times something, and the
 * initial guess of a step is filled from its masters. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"

#include <string.h>

static const char *precond_name(fcm_preconditioner p)
{
  switch (p) {
  case FCM_PRECOND_NONE:
    return "FCM_PRECOND_NONE";
  case FCM_PRECOND_JACOBI:
    return "FCM_PRECOND_JACOBI";
  case FCM_PRECOND_BLOCK_JACOBI:
    return "FCM_PRECOND_BLOCK_JACOBI";
  case FCM_PRECOND_SCHWARZ:
    return "FCM_PRECOND_SCHWARZ";
  case FCM_PRECOND_MULTIGRID:
    return "FCM_PRECOND_MULTIGRID";
  }
  return "(unknown)";
}

fcm_status fcm__sim_hanging_setup(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_integrator_options *o = &I->opts;
  const fcm_index nh = fcm_mesh_num_hanging(fcm_space_mesh(I->space)), n = I->n;
  fcm_index *free_dof = NULL, *col_dof = NULL, *rows = NULL, *cols = NULL;
  fcm_csr *T = NULL;
  if (nh == 0) return FCM_OK;
  FCM_CHECK(!fcm__integrator_distributed(I, NULL), ctx, FCM_ERR_UNSUPPORTED,
            "integrator: the space's mesh is an octree with %lld hanging (cell, node) pairs and "
            "the integrator has a distributed backend; hanging-node constraints are applied by "
            "the serial solvers only",
            (long long)nh);
  /* the multigrid (solver and preconditioner) coarsens the octree itself (fcm/mg.h) on the
   * constrained matrix below */
  FCM_CHECK(o->linear_solver == FCM_LINEAR_DIRECT || o->linear_solver == FCM_LINEAR_MULTIGRID ||
                o->preconditioner == FCM_PRECOND_NONE || o->preconditioner == FCM_PRECOND_JACOBI ||
                o->preconditioner == FCM_PRECOND_MULTIGRID,
            ctx, FCM_ERR_UNSUPPORTED,
            "integrator: the space's mesh is an octree with %lld hanging (cell, node) pairs; "
            "preconditioner %s works on the space's nodes and cells as they are (block Jacobi "
            "and Schwarz are not available there yet): use FCM_PRECOND_JACOBI, "
            "FCM_PRECOND_MULTIGRID or FCM_PRECOND_NONE, or the direct or multigrid solver",
            (long long)nh, precond_name(o->preconditioner));
  FCM_ALLOC(ctx, n, free_dof);
  FCM_TRY(ctx, fcm_space_hanging_matrix_create(I->space, free_dof, &T));
  fcm_index nfree = 0, nnz = 0;
  fcm_csr_get_size(T, NULL, &nfree, &nnz);
  FCM_ALLOC(ctx, nfree, col_dof);
  FCM_ALLOC(ctx, nnz, rows);
  FCM_ALLOC(ctx, nnz, cols);
  for (fcm_index d = 0; d < n; d++)
    if (free_dof[d] >= 0) col_dof[free_dof[d]] = d;
  {
    const fcm_index *rp = fcm_csr_row_ptr(T);
    const int *ci = fcm_csr_col_idx(T);
    for (fcm_index r = 0; r < n; r++)
      for (fcm_index e = rp[r]; e < rp[r + 1]; e++) {
        rows[e] = r;
        cols[e] = col_dof[ci[e]];
      }
    FCM_TRY(ctx, fcm_csr_create_triplets(ctx, n, n, nnz, rows, cols, fcm_csr_values_read(T),
                                         FCM_CSR_GENERAL, &I->hP));
  }
  I->nhang = 0;
  for (fcm_index d = 0; d < n; d++)
    I->nhang += free_dof[d] < 0;
  FCM_ALLOC(ctx, I->nhang, I->hang);
  I->nhang = 0;
  for (fcm_index d = 0; d < n; d++)
    if (free_dof[d] < 0) I->hang[I->nhang++] = d;
cleanup:
  fcm_csr_destroy(&T);
  fcm__free(ctx, free_dof);
  fcm__free(ctx, col_dof);
  fcm__free(ctx, rows);
  fcm__free(ctx, cols);
  return st;
}

void fcm__sim_hanging_destroy(fcm_integrator *I)
{
  fcm_csr_destroy(&I->hP);
  fcm_csr_destroy(&I->Ha);
  fcm__ptap_destroy(&I->hptap);
  fcm__free(I->ctx, I->hmirror);
  I->hmirror = NULL;
  fcm__free(I->ctx, I->hang);
  I->hang = NULL;
  I->nhang = 0;
}

fcm_status fcm__sim_hanging_constraints(fcm_integrator *I, int *owner)
{
  fcm_status st = FCM_OK;
  if (!I->hP) return FCM_OK;
  const fcm_index *rp = fcm_csr_row_ptr(I->hP);
  const int *ci = fcm_csr_col_idx(I->hP);
  for (fcm_index k = 0; k < I->nhang; k++) {
    const fcm_index d = I->hang[k];
    if (owner[d] == 0) continue;
    for (fcm_index e = rp[d]; e < rp[d + 1]; e++)
      FCM_CHECK(owner[ci[e]] == owner[d], I->ctx, FCM_ERR_UNSUPPORTED,
                "constraint %d: DOF %lld (node %lld, component %c) hangs on a coarser cell of "
                "the octree, and its master DOF %lld (node %lld) is %s; a hanging node follows "
                "its masters, so a constraint must hold them too (select the coarse face or "
                "edge the node lies on, or refine the octree there)",
                owner[d] - 1, (long long)d, (long long)(d / 3), "xyz"[d % 3], (long long)ci[e],
                (long long)(ci[e] / 3), owner[ci[e]] == 0 ? "free" : "held by another constraint");
    owner[d] = 0; /* it follows its masters, which the constraint holds */
  }
cleanup:
  return st;
}

/* x = P x (the hanging entries from their masters) or, transposed, x = P^T x (each hanging
 * entry added to its masters with its weights, then zeroed); the masters are free DOFs, so the
 * order of the hanging DOFs does not matter. */
static void apply(const fcm_integrator *I, double *x, int transpose)
{
  if (!I->hP) return;
  const fcm_index *rp = fcm_csr_row_ptr(I->hP);
  const int *ci = fcm_csr_col_idx(I->hP);
  const double *pv = fcm_csr_values_read(I->hP);
  for (fcm_index k = 0; k < I->nhang; k++) {
    const fcm_index d = I->hang[k];
    double s = 0.0;
    for (fcm_index e = rp[d]; e < rp[d + 1]; e++)
      if (transpose)
        x[ci[e]] += pv[e] * x[d];
      else
        s += pv[e] * x[ci[e]];
    x[d] = s;
  }
}

void fcm__sim_hanging_fill(const fcm_integrator *I, double *x)
{
  apply(I, x, 0);
}

void fcm__sim_hanging_reduce(const fcm_integrator *I, double *g)
{
  apply(I, g, 1);
}

fcm_status fcm__sim_hanging_storage(fcm_integrator *I, fcm_csr **A)
{
  fcm_status st = FCM_OK;
  if (!I->Ha) FCM_TRY(I->ctx, fcm__space_matrix_create_rows(I->space, &I->Ha));
  FCM_TRY(I->ctx, fcm_csr_create_ptap(I->ctx, I->Ha, I->hP, A));
cleanup:
  return st;
}

/* H = P^T Ha P + I_h through the Galerkin product's plan (la/ptap.c: patterns once, values on
 * the context's threads, independent of their number), made at the first call on Ha's pattern:
 * its C has H's pattern (fcm__sim_hanging_storage() makes H by the same product), so its values
 * go to H directly and C itself is dropped. */
fcm_status fcm__sim_hanging_matrix(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_index n = I->n;
  fcm_csr *C = NULL;
  const int nt = fcm_ctx_num_threads(ctx);
  if (!I->hptap) {
    FCM_TRY(ctx, fcm__ptap_create(ctx, I->Ha, n, fcm_csr_row_ptr(I->hP), fcm_csr_col_idx(I->hP),
                                  fcm_csr_values_read(I->hP), 1, nt, &I->hptap, &C));
    fcm_index nnz_c = 0, nnz_h = 0;
    fcm_csr_get_size(C, NULL, NULL, &nnz_c);
    fcm_csr_get_size(I->H, NULL, NULL, &nnz_h);
    FCM_CHECK(nnz_c == nnz_h, ctx, FCM_ERR_INTERNAL,
              "integrator: the constrained Newton matrix has %lld entries, its product %lld",
              (long long)nnz_h, (long long)nnz_c);
    FCM_ALLOC_RAW(ctx, (size_t)nnz_h + 1, I->hmirror);
    const fcm_index *hp = fcm_csr_row_ptr(I->H);
    const int *hc = fcm_csr_col_idx(I->H);
    for (fcm_index i = 0; i < n; i++)
      for (fcm_index e = hp[i]; e < hp[i + 1]; e++)
        I->hmirror[e] = hc[e] > i ? fcm_csr_position(I->H, hc[e], i) : -1;
  }
  fcm__ptap_apply(I->hptap, I->Ha, I->H, nt);
  fcm_index nnz = 0;
  fcm_csr_get_size(I->H, NULL, NULL, &nnz);
  double *hv = fcm_csr_values(I->H);
  /* exactly symmetric (the product sums (i, j) and (j, i) in different orders) */
  for (fcm_index e = 0; e < nnz; e++)
    if (I->hmirror[e] >= 0) {
      const fcm_index m = I->hmirror[e];
      const double s = 0.5 * (hv[e] + hv[m]);
      hv[e] = hv[m] = s;
    }
  for (fcm_index k = 0; k < I->nhang; k++)
    hv[fcm_csr_position(I->H, I->hang[k], I->hang[k])] = 1.0;
cleanup:
  fcm_csr_destroy(&C);
  if (st != FCM_OK) {
    fcm__ptap_destroy(&I->hptap);
    fcm__free(ctx, I->hmirror);
    I->hmirror = NULL;
  }
  return st;
}
