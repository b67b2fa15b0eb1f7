/* bench_roofline: the timing helpers, the core's peaks (one-thread DGEMM, STREAM triad) and
 * CHOLMOD's factorization of 3D elasticity, the rows measured per BLAS kernel set. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include "la/la_impl.h"
#include "roofline.h"

#include <time.h>

int roofline_failures = 0;

/* CPU seconds of the process (one thread in the child): on cores shared with other work the
 * wall clock would also measure that work. */
double roofline_cpu_seconds(void)
{
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

double roofline_best_of(int reps, void (*fn)(void *), void *arg)
{
  double best = 1e30;
  for (int r = 0; r < reps; r++) {
    const double t0 = roofline_cpu_seconds();
    fn(arg);
    best = fmin(best, roofline_cpu_seconds() - t0);
  }
  return best;
}

typedef struct gemm_args {
  int n;
  double *a, *b, *c;
} gemm_args;

static void gemm_once(void *p)
{
  gemm_args *g = p;
  fcm__gemm('N', 'N', g->n, g->n, g->n, 1.0, g->a, g->n, g->b, g->n, 0.0, g->c, g->n);
}

/* The core's DGEMM peak: C = A B with n = 2000 through fcm's BLAS adapter, best of 3. */
int run_dgemm(fcm_ctx *ctx, int cells, bench_result *r)
{
  (void)ctx, (void)cells;
  gemm_args g = {2000, NULL, NULL, NULL};
  const size_t nn = (size_t)g.n * g.n;
  g.a = malloc(nn * sizeof *g.a), g.b = malloc(nn * sizeof *g.b), g.c = malloc(nn * sizeof *g.c);
  if (!g.a || !g.b || !g.c) return 0;
  for (size_t i = 0; i < nn; i++)
    g.a[i] = 0.5 + (double)(i % 7) / 7.0, g.b[i] = 1.0 - (double)(i % 5) / 5.0;
  gemm_once(&g); /* warm-up: pages, kernel set-up */
  r->size = g.n;
  r->seconds = roofline_best_of(3, gemm_once, &g);
  r->work = 2.0 * g.n * (double)g.n * g.n;
  free(g.a), free(g.b), free(g.c);
  return 1;
}

typedef struct triad_args {
  size_t n;
  double *a, *b, *c;
} triad_args;

static void triad_once(void *p)
{
  triad_args *t = p;
  const double s = 3.0;
  for (size_t i = 0; i < t->n; i++)
    t->a[i] = t->b[i] + s * t->c[i];
}

/* STREAM triad a = b + s c over 3 arrays of 10^7 doubles (240 MB, far beyond the caches),
 * 24 bytes per element as STREAM counts them, best of 5. */
int run_triad(fcm_ctx *ctx, int cells, bench_result *r)
{
  (void)ctx, (void)cells;
  triad_args t = {10000000, NULL, NULL, NULL};
  t.a = malloc(t.n * sizeof *t.a), t.b = malloc(t.n * sizeof *t.b), t.c = malloc(t.n * sizeof *t.c);
  if (!t.a || !t.b || !t.c) return 0;
  for (size_t i = 0; i < t.n; i++)
    t.a[i] = 0.0, t.b[i] = 1.0, t.c[i] = 2.0;
  triad_once(&t);
  r->size = (double)t.n;
  r->seconds = roofline_best_of(5, triad_once, &t);
  r->work = 24.0 * (double)t.n;
  r->check = t.a[t.n / 2] == 7.0 ? 0.0 : -1.0; /* b + 3 c */
  free(t.a), free(t.b), free(t.c);
  return r->check == 0.0;
}

/* CHOLMOD's numeric factorization of 3D linear elasticity (Hex8 box of cells^3 cells, the
 * z = 0 face clamped), assembled by fcm; flops as CHOLMOD counts them, best of 2. The check
 * is the solution's 2-norm under gravity. */
int run_cholmod(fcm_ctx *ctx, int cells, bench_result *r)
{
  int ok = 0;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, g[3] = {0, 0, -9.81};
  const double plo[3] = {-1, -1, 0}, phi[3] = {2, 2, 0};
  const fcm_index n3[3] = {cells, cells, cells};
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e7, 0.3, 1000};
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL;
  fcm_direct *solver = NULL;
  fcm_index nfix = 0, *nodes = NULL, *dofs = NULL;
  double *f = NULL, *u = NULL, *res = NULL;
  if (fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &mesh) ||
      fcm_space_create(ctx, mesh, NULL, &space) || fcm_space_matrix_create(space, &K) ||
      fcm_assemble_stiffness(space, &mat, NULL, K))
    goto done;
  const fcm_index ndof = fcm_space_num_dofs(space);
  f = calloc((size_t)ndof, sizeof *f), u = calloc((size_t)ndof, sizeof *u);
  res = calloc((size_t)ndof, sizeof *res);
  if (!f || !u || !res || fcm_assemble_body_force(space, &mat, g, NULL, f) ||
      fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-9, 0, NULL, &nfix))
    goto done;
  nodes = calloc((size_t)nfix, sizeof *nodes), dofs = calloc(3 * (size_t)nfix, sizeof *dofs);
  if (!nodes || !dofs || fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-9, nfix, nodes, &nfix))
    goto done;
  for (fcm_index i = 0; i < nfix; i++)
    for (int d = 0; d < 3; d++)
      dofs[3 * i + d] = fcm_space_node_dof(space, nodes[i]) + d;
  if (fcm_space_apply_dirichlet(space, 3 * nfix, dofs, NULL, K, f) ||
      fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, K, &solver) || fcm_direct_analyze(solver))
    goto done;
  r->seconds = 1e30;
  for (int rep = 0; rep < 2; rep++) {
    const double t0 = roofline_cpu_seconds();
    if (fcm_direct_factor(solver, fcm_csr_values(K))) goto done;
    r->seconds = fmin(r->seconds, roofline_cpu_seconds() - t0);
  }
  if (fcm_direct_solve(solver, f, u) || fcm_csr_apply(K, 1.0, u, 0.0, res)) goto done;
  fcm_direct_info di;
  fcm_direct_get_info(solver, &di);
  double rn = 0, fn = 0, un = 0;
  for (fcm_index i = 0; i < ndof; i++)
    rn += (res[i] - f[i]) * (res[i] - f[i]), fn += f[i] * f[i], un += u[i] * u[i];
  ROOFLINE_CHECK(sqrt(rn) <= 1e-8 * sqrt(fn));
  r->size = (double)ndof;
  r->work = di.factor_flops;
  r->check = sqrt(un);
  ok = 1;
done:
  if (!ok) fcm_ctx_error_view(ctx, stderr);
  free(f), free(u), free(res), free(nodes), free(dofs);
  fcm_direct_destroy(&solver);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  return ok;
}
