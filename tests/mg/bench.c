/* Timing of one static solve (uncut cube clamped at x = 0, or the embedded hemisphere:
 * argument cube | hemisphere, then cell counts n) by CHOLMOD, CG + Jacobi, CG + MG (one
 * V-cycle per iteration) and MG alone, all to the relative residual 1e-8: DOFs, iterations,
 * setup and solve seconds (wall clock), one line per solver. A precursor of the fcm-scaling
 * app; label bench (not in the default run). Asserts only that every solver converged and
 * that the solutions agree to 1e-6. */
#include "mg_util.h"

#include <omp.h>

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  if (argc < 3) return 2;
  const int hemi = !strcmp(argv[1], "hemisphere");
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  printf("body,cells,dofs,solver,iterations,setup_s,solve_s\n");
  for (int a = 2; a < argc; a++) {
    const fcm_index n = atoi(argv[a]);
    problem p;
    if (hemi)
      problem_hemisphere(ctx, n, 0, &p);
    else
      problem_cube(ctx, n, &p);
    double *x = calloc((size_t)p.n, sizeof *x), *xd = calloc((size_t)p.n, sizeof *xd);
    double t0 = omp_get_wtime();
    fcm_direct *d = NULL;
    TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, p.A, &d));
    TEST_OK(ctx, fcm_direct_analyze(d));
    TEST_OK(ctx, fcm_direct_factor(d, fcm_csr_values_read(p.A)));
    double t1 = omp_get_wtime();
    TEST_OK(ctx, fcm_direct_solve(d, p.b, xd));
    double t2 = omp_get_wtime();
    fcm_direct_destroy(&d);
    printf("%s,%lld,%lld,cholmod,1,%.3f,%.3f\n", argv[1], (long long)n, (long long)p.n, t1 - t0,
           t2 - t1);
    fcm_krylov_options ko = fcm_krylov_options_default();
    ko.rtol = 1e-8;
    ko.max_iterations = 100000;
    fcm_krylov_info ki;
    fcm_jacobi *J = NULL;
    t0 = omp_get_wtime();
    TEST_OK(ctx, fcm_jacobi_create(ctx, p.A, FCM_JACOBI_SCALAR, &J));
    t1 = omp_get_wtime();
    TEST_OK(ctx, fcm_cg_solve(ctx, p.n, fcm_csr_operator, p.A, fcm_jacobi_operator, J, p.b, x, &ko,
                              &ki));
    t2 = omp_get_wtime();
    printf("%s,%lld,%lld,cg-jacobi,%d,%.3f,%.3f\n", argv[1], (long long)n, (long long)p.n,
           ki.iterations, t1 - t0, t2 - t1);
    fcm_jacobi_destroy(&J);
    fcm_mg *mg = NULL;
    t0 = omp_get_wtime();
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, NULL, &mg));
    t1 = omp_get_wtime();
    memset(x, 0, sizeof *x * (size_t)p.n);
    TEST_OK(ctx,
            fcm_cg_solve(ctx, p.n, fcm_csr_operator, p.A, fcm_mg_operator, mg, p.b, x, &ko, &ki));
    t2 = omp_get_wtime();
    printf("%s,%lld,%lld,cg-mg,%d,%.3f,%.3f\n", argv[1], (long long)n, (long long)p.n,
           ki.iterations, t1 - t0, t2 - t1);
    double dn = 0.0, xn = 0.0;
    for (fcm_index i = 0; i < p.n; i++)
      dn += (x[i] - xd[i]) * (x[i] - xd[i]), xn += xd[i] * xd[i];
    TEST_TRUE(sqrt(dn) <= 1e-6 * sqrt(xn));
    memset(x, 0, sizeof *x * (size_t)p.n);
    fcm_mg_solve_info si;
    t1 = omp_get_wtime();
    TEST_OK(ctx, fcm_mg_solve(mg, p.b, x, 1e-8, 1000, &si));
    t2 = omp_get_wtime();
    printf("%s,%lld,%lld,mg,%d,%.3f,%.3f\n", argv[1], (long long)n, (long long)p.n, si.cycles, 0.0,
           t2 - t1);
    fflush(stdout);
    fcm_mg_destroy(&mg);
    free(x);
    free(xd);
    problem_free(&p);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
