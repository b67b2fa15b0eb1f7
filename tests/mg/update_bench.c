/* What creating a hierarchy costs beyond setting up its values, and what
 * fcm__mg_create_from() saves: on the Hex8 hemisphere of mg_util.h (n x n/2 x n cells, the
 * top split by a plane), CPU time on one thread (the median of `reps` runs) of
 * fcm_mg_setup() (new values: Galerkin values, block inverses, the coarsest factor),
 * fcm_mg_create(), fcm__mg_create_from() on the same space and matrix (everything kept) and
 * fcm__mg_create_from() after a second cut (the hierarchy before it, detached).
 * Usage: mg_update_bench [n [reps]] (default 32 5). Label bench. */
#include "mg/mg_impl.h"
#include "mg_util.h"

#include <omp.h>
#include <stdio.h>
#include <time.h>

static double cpu_now(void)
{
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n)
{
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return v[n / 2];
}

int main(int argc, char **argv)
{
  const fcm_index n = argc > 1 ? atoll(argv[1]) : 32;
  const int reps = argc > 2 ? atoi(argv[2]) : 5;
  TEST_TRUE(n >= 4 && n % 2 == 0 && reps >= 1 && reps <= 100);
  omp_set_num_threads(1);
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  problem p, q;
  problem_hemisphere(ctx, n, 1, &p);
  /* the second cut: a plane z = 0.13 through the top, on the first one's rules */
  memset(&q, 0, sizeof q);
  {
    fcm_surface *s = NULL;
    const double pt[3] = {0, 0, 0.13}, nz[3] = {0, 0.2, 1}, lo[3] = {-2, 0.6, -0.5},
                 hi[3] = {2, 2, 0.5};
    TEST_OK(ctx, fcm_surface_create_plane(ctx, pt, nz, lo, hi, &s));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, p.mesh, p.geom, p.rules, s, &q.rules));
    fcm_surface_destroy(&s);
    q.mesh = p.mesh;
    TEST_OK(ctx, fcm_space_create_embedded(ctx, p.mesh, q.rules, &q.space));
    finish_space(ctx, &q, 0);
    const double flo[3] = {-2, 0, -2}, fhi[3] = {2, 0, 2};
    clamp_box(ctx, &q, flo, fhi);
  }
  fcm_mg_options o = fcm_mg_options_default();
  double *t[4];
  for (int k = 0; k < 4; k++)
    t[k] = calloc((size_t)reps, sizeof *t[k]);
  for (int r = 0; r < reps; r++) {
    fcm_mg *mg = NULL, *up = NULL, *cut = NULL;
    double t0 = cpu_now();
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg));
    t[1][r] = cpu_now() - t0;
    t0 = cpu_now();
    TEST_OK(ctx, fcm_mg_setup(mg));
    t[0][r] = cpu_now() - t0;
    t0 = cpu_now();
    TEST_OK(ctx, fcm__mg_create_from(ctx, &mg, p.space, p.A, &o, &up));
    t[2][r] = cpu_now() - t0;
    fcm__mg_detach(up);
    t0 = cpu_now();
    TEST_OK(ctx, fcm__mg_create_from(ctx, &up, q.space, q.A, &o, &cut));
    t[3][r] = cpu_now() - t0;
    fcm__mg_kept kept;
    fcm__mg_get_kept(cut, &kept);
    if (r == 0)
      printf("after the cut: %d levels, kept %d plans, %d row orders, %d block smoothers, "
             "analysis %d\n",
             fcm_mg_num_levels(cut), kept.plans, kept.row_orders, kept.block_smoothers,
             kept.analysis);
    fcm_mg_destroy(&cut);
  }
  const double setup = median(t[0], reps), create = median(t[1], reps);
  printf("hemisphere n = %lld: %lld -> %lld DOFs, CPU s on 1 thread, median of %d\n", (long long)n,
         (long long)p.n, (long long)q.n, reps);
  printf("  fcm_mg_setup                         %.4f\n", setup);
  printf("  fcm_mg_create                        %.4f (beyond the setup: %.4f)\n", create,
         create - setup);
  printf("  fcm__mg_create_from, no change       %.4f\n", median(t[2], reps));
  printf("  fcm__mg_create_from, after the cut   %.4f\n", median(t[3], reps));
  for (int k = 0; k < 4; k++)
    free(t[k]);
  fcm_csr_destroy(&q.A);
  fcm_space_destroy(&q.space);
  fcm_cell_rules_destroy(&q.rules);
  free(q.b);
  problem_free(&p);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
