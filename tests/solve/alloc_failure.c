/* Allocation failures in the solve module: failing the k-th allocation for k = 0, 1, ...
 * of the workspace (with its history), the Jacobi and the Schwarz builders (from blocks,
 * and from the cell blocks of a space), a second Schwarz setup, MINRES and CG (workspace and
 * one-shot) gives FCM_ERR_ALLOC and leaks nothing, until everything succeeds. */
#include "solve_test_util.h"

#include <omp.h>

#define N  6
#define NN (N * N * N)

typedef struct fixture {
  fcm_csr *A;   /* shifted Laplacian (indefinite) */
  fcm_csr *SPD; /* the Laplacian (positive definite), for CG */
  fcm_space *space;
  fcm_csr *K; /* stiffness of the space */
  unsigned char flag[8];
  fcm_index bptr[28], bdofs[NN];
  int nb;
  fcm_index cell_nb, cell_ptr[9], cell_dofs[8 * 60]; /* fcm_space_cell_blocks of flag */
  double b[NN];
} fixture;

static fcm_status run(fcm_ctx *ctx, fixture *f)
{
  fcm_status st = FCM_OK;
  fcm_krylov *ws = NULL;
  fcm_jacobi *J = NULL;
  fcm_schwarz *P = NULL, *Q = NULL;
  double x[NN];
  fcm_krylov_options o = fcm_krylov_options_default();
  o.record_history = 1;
  o.max_iterations = 500;
  fcm_krylov_info info;
  if ((st = fcm_krylov_create(ctx, NN, &ws))) goto done;
  if ((st = fcm_jacobi_create(ctx, f->A, FCM_JACOBI_BLOCK3, &J))) goto done;
  if ((st = fcm_schwarz_create(ctx, f->A, f->nb, f->bptr, f->bdofs, NULL, &P))) goto done;
  if ((st = fcm_schwarz_create(ctx, f->K, f->cell_nb, f->cell_ptr, f->cell_dofs, NULL, &Q)))
    goto done;
  memset(x, 0, sizeof x);
  if ((st = fcm_krylov_minres(ws, fcm_csr_operator, f->A, fcm_schwarz_operator, P, f->b, x, &o,
                              &info)))
    goto done;
  o.max_iterations = 800; /* grows the history */
  memset(x, 0, sizeof x);
  if ((st = fcm_krylov_minres(ws, fcm_csr_operator, f->A, fcm_jacobi_operator, J, f->b, x, &o,
                              &info)))
    goto done;
  o.record_history = 0;
  memset(x, 0, sizeof x);
  if ((st = fcm_minres_solve(ctx, NN, fcm_csr_operator, f->A, NULL, NULL, f->b, x, &o, &info)))
    goto done;
  /* a second setup of the same Schwarz preconditioner, then CG (workspace with history,
   * and one-shot) on the positive definite Laplacian with it */
  if ((st = fcm_schwarz_setup(P, f->SPD))) goto done;
  o.record_history = 1;
  memset(x, 0, sizeof x);
  if ((st = fcm_krylov_cg(ws, fcm_csr_operator, f->SPD, fcm_schwarz_operator, P, f->b, x, &o,
                          &info)))
    goto done;
  o.record_history = 0;
  memset(x, 0, sizeof x);
  st = fcm_cg_solve(ctx, NN, fcm_csr_operator, f->SPD, fcm_jacobi_operator, J, f->b, x, &o, &info);
  if (st == FCM_OK && info.reason != FCM_KRYLOV_CONVERGED_RTOL &&
      info.reason != FCM_KRYLOV_CONVERGED_ATOL)
    st = FCM_ERR_INTERNAL; /* CG converges here */
done:
  fcm_schwarz_destroy(&Q);
  fcm_schwarz_destroy(&P);
  fcm_jacobi_destroy(&J);
  fcm_krylov_destroy(&ws);
  return st;
}

int main(void)
{
  omp_set_num_threads(1); /* the failing allocator counts calls in order */
  fcm_ctx *ctx0 = NULL, *ctx = NULL;
  fcm_mesh *mesh = NULL;
  static fixture f;
  TEST_OK(ctx0, fcm_ctx_create(NULL, &ctx0));
  TEST_OK(ctx0, laplace3d(ctx0, N, 1.3, NULL, &f.A));
  TEST_OK(ctx0, laplace3d(ctx0, N, 0.0, NULL, &f.SPD));
  for (int K = 0; K < N; K += 2)
    for (int J = 0; J < N; J += 2)
      for (int I = 0; I < N; I += 2) {
        for (int c = 0; c < 8; c++)
          f.bdofs[f.bptr[f.nb] + c] = (I + (c & 1)) + N * ((J + (c >> 1 & 1)) + N * (K + (c >> 2)));
        f.bptr[f.nb + 1] = f.bptr[f.nb] + 8;
        f.nb++;
      }
  rng r = {2};
  for (int i = 0; i < NN; i++)
    f.b[i] = rng_uniform(&r);
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index cells[3] = {2, 2, 2};
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0, 0.3, 1.0};
  TEST_OK(ctx0, fcm_mesh_create_box(ctx0, FCM_ELEMENT_HEX20, lo, hi, cells, &mesh));
  TEST_OK(ctx0, fcm_space_create(ctx0, mesh, NULL, &f.space));
  TEST_OK(ctx0, fcm_space_matrix_create(f.space, &f.K));
  TEST_OK(ctx0, fcm_assemble_stiffness(f.space, &mat, NULL, f.K));
  /* stiffness without boundary conditions: singular, but its cell blocks are not zero */
  for (int c = 0; c < 8; c++)
    f.flag[c] = (unsigned char)(c % 2);
  fcm_index nd = 0;
  TEST_OK(ctx0, fcm_space_cell_blocks(f.space, f.flag, &f.cell_nb, &nd, NULL, NULL));
  TEST_TRUE(f.cell_nb == 4 && nd == 4 * 60);
  TEST_OK(ctx0, fcm_space_cell_blocks(f.space, f.flag, &f.cell_nb, &nd, f.cell_ptr, f.cell_dofs));

  failing fl;
  ctx = failing_ctx(&fl);
  TEST_TRUE(ctx != NULL);
  long long k;
  for (k = 0;; k++) {
    fl.count = 0;
    fl.fail_at = k;
    fcm_status st = run(ctx, &f);
    if (fcm_ctx_live_allocations(ctx) != 0)
      TEST_FAIL_("failing allocation %lld: %lld allocations leaked", k,
                 fcm_ctx_live_allocations(ctx));
    if (st == FCM_OK) break;
    if (st != FCM_ERR_ALLOC) {
      TEST_FAIL_("failing allocation %lld: %s (%s)", k, fcm_status_name(st),
                 fcm_ctx_error_message(ctx));
      break;
    }
    fcm_ctx_error_clear(ctx);
  }
  TEST_TRUE(k >= 15); /* the loop did exercise the builders */
  fcm_ctx_destroy(&ctx);
  fcm_csr_destroy(&f.K);
  fcm_space_destroy(&f.space);
  fcm_mesh_destroy(&mesh);
  fcm_csr_destroy(&f.A);
  fcm_csr_destroy(&f.SPD);
  TEST_TRUE(fcm_ctx_live_allocations(ctx0) == 0);
  fcm_ctx_destroy(&ctx0);
  return TEST_RESULT();
}
