/* The hierarchy, the cycle and CG + MG give bitwise the same result for 1 and 2 threads,
 * with both smoothers, on the uncut cube and on the cut hemisphere; fcm_mg_setup() with the
 * same values reproduces the same iterates; argument errors are reported. */
#include "mg_util.h"

#include <omp.h>

static double *solve(fcm_ctx *ctx, problem *p, fcm_mg_smoother sm, int threads, int resetup)
{
  omp_set_num_threads(threads);
  fcm_mg_options o = fcm_mg_options_default();
  o.smoother = sm;
  o.omega = sm == FCM_MG_SMOOTHER_JACOBI ? 0.6 : 1.2;
  o.coarse_dofs = 100;
  fcm_mg *mg = NULL;
  double *x = calloc((size_t)p->n, sizeof *x);
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, &o, &mg));
  if (resetup) TEST_OK(ctx, fcm_mg_setup(mg));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = 1e-9;
  fcm_krylov_info ki;
  TEST_OK(ctx, fcm_cg_solve(ctx, p->n, fcm_csr_operator, p->A, fcm_mg_operator, mg, p->b, x, &ko,
                            &ki));
  fcm_mg_solve_info si;
  TEST_OK(ctx, fcm_mg_solve(mg, p->b, x, 1e-12, 50, &si)); /* a few more cycles from there */
  fcm_mg_destroy(&mg);
  return x;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  for (int kind = 0; kind < 2; kind++) {
    problem p;
    if (kind == 0)
      problem_cube(ctx, 8, &p);
    else
      problem_hemisphere(ctx, 8, 1, &p);
    for (int sm = 0; sm < 2; sm++) {
      double *x1 = solve(ctx, &p, (fcm_mg_smoother)sm, 1, 0);
      double *x2 = solve(ctx, &p, (fcm_mg_smoother)sm, 2, 0);
      double *x3 = solve(ctx, &p, (fcm_mg_smoother)sm, 2, 1);
      TEST_TRUE(memcmp(x1, x2, sizeof *x1 * (size_t)p.n) == 0);
      TEST_TRUE(memcmp(x1, x3, sizeof *x1 * (size_t)p.n) == 0);
      free(x1), free(x2), free(x3);
    }
    if (kind == 0) {
      /* errors */
      fcm_mg *mg = NULL;
      fcm_mg_options o = fcm_mg_options_default();
      o.omega = 2.0;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "omega");
      o = fcm_mg_options_default();
      o.smoother = FCM_MG_SMOOTHER_JACOBI;
      o.omega = 1.5;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "omega");
      o = fcm_mg_options_default();
      o.max_levels = 0;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "max_levels");
      TEST_TRUE(mg == NULL);
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, NULL, NULL, &mg), FCM_ERR_ARG, "NULL");
      /* eliminated rows must not change between create and setup */
      TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, NULL, &mg));
      fcm_index d = 3 * 100; /* an interior DOF: eliminate it */
      fcm_index one[1] = {d};
      double *b = calloc((size_t)p.n, sizeof *b);
      TEST_OK(ctx, fcm_space_apply_dirichlet(p.space, 1, one, NULL, p.A, b));
      TEST_ERR(ctx, fcm_mg_setup(mg), FCM_ERR_ARG, "eliminated");
      free(b);
      fcm_mg_destroy(&mg);
      /* a Hex20 grid is refused */
      fcm_mesh *m20 = NULL;
      fcm_space *s20 = NULL;
      fcm_csr *A20 = NULL;
      const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
      const fcm_index c[3] = {2, 2, 2};
      fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0, 0.3, 1.0};
      TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX20, lo, hi, c, &m20));
      TEST_OK(ctx, fcm_space_create(ctx, m20, NULL, &s20));
      TEST_OK(ctx, fcm_space_matrix_create(s20, &A20));
      TEST_OK(ctx, fcm_assemble_mass(s20, &mat, NULL, A20));
      TEST_ERR(ctx, fcm_mg_create(ctx, s20, A20, NULL, &mg), FCM_ERR_UNSUPPORTED, "Hex8");
      fcm_csr_destroy(&A20);
      fcm_space_destroy(&s20);
      fcm_mesh_destroy(&m20);
    }
    problem_free(&p);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
