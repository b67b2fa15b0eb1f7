/* fcm_mg_setup() with new values of the matrix (same pattern and eliminated rows) gives the
 * hierarchy fcm_mg_create() builds from those values, bit for bit: the cycle and a CG + MG
 * solve from both are the same bits, on the uncut cube and on the cut hemisphere (block
 * smoother on cut cells and on coarse cells with little material), for the default smoother
 * (SGS in slab order with vertex and cut-cell blocks) and the V- and W-cycle; then values that
 * make a level's Galerkin diagonal non-positive are reported and a further setup with good
 * values recovers. */
#include "mg_util.h"

#include <math.h>

/* One cycle from 0 and a CG + MG solve to 1e-9, as one vector of 2 n. */
static void run(fcm_ctx *ctx, fcm_mg *mg, const problem *p, double *out)
{
  TEST_OK(ctx, fcm_mg_operator(mg, p->b, out));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = 1e-9;
  fcm_krylov_info ki;
  memset(out + p->n, 0, sizeof *out * (size_t)p->n);
  TEST_OK(ctx, fcm_cg_solve(ctx, p->n, fcm_csr_operator, p->A, fcm_mg_operator, mg, p->b,
                            out + p->n, &ko, &ki));
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
    fcm_index nnz = 0;
    fcm_csr_get_size(p.A, NULL, NULL, &nnz);
    double *v0 = malloc(sizeof *v0 * (size_t)nnz);
    memcpy(v0, fcm_csr_values_read(p.A), sizeof *v0 * (size_t)nnz);
    const size_t bytes = sizeof(double) * 2 * (size_t)p.n;
    double *x0 = malloc(bytes), *x1 = malloc(bytes), *x2 = malloc(bytes);
    for (int cyc = 1; cyc <= 2; cyc++) {
      fcm_mg_options o = fcm_mg_options_default();
      o.cycle_index = cyc;
      o.coarse_dofs = 100;
      fcm_mg *updated = NULL, *fresh = NULL;
      memcpy(fcm_csr_values(p.A), v0, sizeof *v0 * (size_t)nnz);
      TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &updated));
      TEST_TRUE(fcm_mg_num_levels(updated) >= 3);
      run(ctx, updated, &p, x0);
      for (int round = 1; round <= 2; round++) { /* two value changes in a row */
        scale_symmetric(p.A, v0, 0.2 * round);
        TEST_OK(ctx, fcm_mg_setup(updated));
        TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &fresh));
        run(ctx, updated, &p, x1);
        run(ctx, fresh, &p, x2);
        const int same = memcmp(x1, x2, bytes) == 0;
        printf("%s, cycle index %d, values %d: updated and fresh hierarchy %s\n",
               kind ? "cut hemisphere" : "cube", cyc, round, same ? "identical" : "DIFFER");
        TEST_TRUE(same);
        /* the new values change the result (the comparison is not vacuous) */
        TEST_TRUE(memcmp(x1, x0, bytes) != 0);
        fcm_mg_destroy(&fresh);
      }
      /* a coarse diagonal that is not positive is named; good values set up again */
      double *v = fcm_csr_values(p.A);
      for (fcm_index k = 0; k < nnz; k++)
        v[k] = -v0[k];
      TEST_TRUE(fcm_mg_setup(updated) != FCM_OK);
      fcm_ctx_error_clear(ctx);
      scale_symmetric(p.A, v0, 0.2);
      TEST_OK(ctx, fcm_mg_setup(updated));
      TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &fresh));
      run(ctx, updated, &p, x1);
      run(ctx, fresh, &p, x2);
      TEST_TRUE(memcmp(x1, x2, bytes) == 0);
      fcm_mg_destroy(&fresh);
      fcm_mg_destroy(&updated);
    }
    free(x0);
    free(x1);
    free(x2);
    free(v0);
    problem_free(&p);
  }
  fcm_ctx_destroy(&ctx);
  printf("ok\n");
  return TEST_RESULT();
}
