/* Roofline benchmark: what one core can do and what fcm's kernels get of it, with the
 * OpenBLAS kernels OpenBLAS falls back to on a CPU it does not know (Prescott, SSE3) and with
 * the ones fcm selects for the CPU (fcm_blas_info_get(): SkylakeX, Zen, Haswell, ...).
 *
 *   bench_roofline [CSV [CELLS]]   CSV: the table as CSV (default bench_roofline.csv),
 *                                  CELLS: Hex8 cells per direction of the elasticity box (24)
 *
 * OpenBLAS reads OPENBLAS_CORETYPE only when it loads, so the program runs itself once per
 * kernel set ("child" mode, one OpenMP and one BLAS thread, times in CPU seconds: on cores
 * shared with other work the wall clock would measure that work too) and collects the rows;
 * OpenBLAS's own choice is measured too when it is neither. `bench_roofline child CELLS [ROW]`
 * prints the raw rows of the kernels it is started with (e.g. another BLAS preloaded), or the
 * one row named ROW (`once` likewise). fcm's own element
 * kernels and CSR SpMV do not use the BLAS: one more child (`bench_roofline once CELLS`) measures
 * them once, kernel set "any" in the table, and a last line gives their time per cell. Each row
 * is a time, a rate (GFLOP/s or GB/s) and the fraction of the core's measured peak: the best DGEMM
 * rate for flop-bound rows, the best STREAM triad bandwidth for memory-bound rows. Prints the
 * table, writes the CSV and ends with a one-line summary. Asserts that each CHOLMOD solve has a
 * small residual and that the kernel sets give the same solution to round-off. Label bench: never
 * in the default run. The simplification rows end with one line per
 * strength comparing their paths (run_simp()). */
#define _POSIX_C_SOURCE 200809L /* popen, readlink */
#include "fcm/fcm.h"
#include "la/la_impl.h"
#include "simplify/simplify_impl.h"
#include "test.h"

#include <time.h>
#include <unistd.h>

enum { MAX_ROWS = 64 };

/* ------------------------------------------------------------------ child: the measurements */

/* One measurement: the problem size, the best time and the work done in it (flops or bytes). */
typedef struct bench_result {
  double size; /* n of DGEMM, doubles per triad array, DOFs of the factorization */
  double seconds;
  double work;
  double check; /* a number every kernel set must reproduce to round-off (0: none) */
} bench_result;

typedef struct bench_item {
  const char *name; /* the row's name */
  const char *unit; /* "GFLOP/s" (work in flops) or "GB/s" (work in bytes) */
  const char *peak; /* the row whose best rate is the peak this one is a fraction of */
  int (*run)(fcm_ctx *ctx, int cells, bench_result *r);
} bench_item;

/* CPU seconds of the process (one thread in the child): on cores shared with other work the
 * wall clock would also measure that work. */
static double cpu_seconds(void)
{
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double best_of(int reps, void (*fn)(void *), void *arg)
{
  double best = 1e30;
  for (int r = 0; r < reps; r++) {
    const double t0 = cpu_seconds();
    fn(arg);
    best = fmin(best, cpu_seconds() - t0);
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
static int run_dgemm(fcm_ctx *ctx, int cells, bench_result *r)
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
  r->seconds = best_of(3, gemm_once, &g);
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
static int run_triad(fcm_ctx *ctx, int cells, bench_result *r)
{
  (void)ctx, (void)cells;
  triad_args t = {10000000, NULL, NULL, NULL};
  t.a = malloc(t.n * sizeof *t.a), t.b = malloc(t.n * sizeof *t.b), t.c = malloc(t.n * sizeof *t.c);
  if (!t.a || !t.b || !t.c) return 0;
  for (size_t i = 0; i < t.n; i++)
    t.a[i] = 0.0, t.b[i] = 1.0, t.c[i] = 2.0;
  triad_once(&t);
  r->size = (double)t.n;
  r->seconds = best_of(5, triad_once, &t);
  r->work = 24.0 * (double)t.n;
  r->check = t.a[t.n / 2] == 7.0 ? 0.0 : -1.0; /* b + 3 c */
  free(t.a), free(t.b), free(t.c);
  return r->check == 0.0;
}

/* CHOLMOD's numeric factorization of 3D linear elasticity (Hex8 box of cells^3 cells, the
 * z = 0 face clamped), assembled by fcm; flops as CHOLMOD counts them, best of 2. The check
 * is the solution's 2-norm under gravity. */
static int run_cholmod(fcm_ctx *ctx, int cells, bench_result *r)
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
    const double t0 = cpu_seconds();
    if (fcm_direct_factor(solver, fcm_csr_values(K))) goto done;
    r->seconds = fmin(r->seconds, cpu_seconds() - t0);
  }
  if (fcm_direct_solve(solver, f, u) || fcm_csr_apply(K, 1.0, u, 0.0, res)) goto done;
  fcm_direct_info di;
  fcm_direct_get_info(solver, &di);
  double rn = 0, fn = 0, un = 0;
  for (fcm_index i = 0; i < ndof; i++)
    rn += (res[i] - f[i]) * (res[i] - f[i]), fn += f[i] * f[i], un += u[i] * u[i];
  TEST_TRUE(sqrt(rn) <= 1e-8 * sqrt(fn));
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

/* ------------------------------------------------------------------ fcm's element kernels */

/* fcm's own assembly kernels and CSR SpMV do not call the BLAS: they are measured once, in a
 * child started with the selected kernel set (kernel set "any" in the table). Each assembly row
 * assembles a box of cells into its matrix, best of 3; size is the number of cells and the
 * flops are the minimal count of the element matrices (kernel_flops()), not counting the
 * scatter; the time per cell is printed below the table. */

typedef enum kernel_row { ROW_STIFFNESS, ROW_SNH, ROW_MASS } kernel_row;

typedef struct assembly_args {
  fcm_assembly_workspace *ws;
  kernel_row kind;
  fcm_material mat;
  fcm_material_params params;
  const double *u;
  fcm_csr *A;
  double *force;
  int ok;
} assembly_args;

static void assembly_once(void *p)
{
  assembly_args *a = p;
  fcm_linear_form form = fcm_linear_form_default();
  form.material = &a->mat;
  if (a->kind == ROW_SNH) {
    a->ok &= fcm_assembly_workspace_hyperelastic(a->ws, &a->params, a->u, NULL, a->force, a->A) ==
             FCM_OK;
    return;
  }
  form.term = a->kind == ROW_MASS ? FCM_LINEAR_MASS : FCM_LINEAR_STIFFNESS;
  a->ok &= fcm_assembly_workspace_linear(a->ws, &form, a->A, NULL) == FCM_OK;
}

/* The minimal flops of one element matrix with nn nodes on nq points (a flop = one add or one
 * multiply, a fused multiply-add is two). Per point: the Jacobian X^T dN (18 nn), its inverse
 * (about 40) and the physical gradients J^-T dN (18 nn), w det J (1).
 * - Stiffness: H = sum_q w_q det J_q g_q g_q^T on its upper triangle, ndof (ndof + 1) / 2 entries
 *   of 2 nq flops, plus w det J g (ndof per point); then per node pair a <= b the 3 x 3 block
 *   lambda H_ab + mu H_ab^T + mu tr(H_ab) I (33 flops).
 * - SNH force + tangent: F = I + sum_a u_a g_a^T (18 nn), the force P g_a (6 per DOF), the
 *   tangent C_b = w det J A g_b (27 entries of 6 flops per node) and per node pair a <= b the
 *   block g_a^T C_b (9 entries of 6 flops); the material's own P and dP/dF are not counted.
 * - Mass: the scalar block sum_q w_q det J_q rho N N^T, nn (nn + 1) / 2 entries of 2 nq flops
 *   (memory-bound: measured in bytes, see run_mass()). */
static double kernel_flops(kernel_row kind, double nn, double nq)
{
  const double ndof = 3 * nn, pairs = nn * (nn + 1) / 2, grad = 36 * nn + 41;
  switch (kind) {
  case ROW_STIFFNESS:
    return nq * (grad + ndof) + ndof * (ndof + 1) / 2 * 2 * nq + 33 * pairs;
  case ROW_SNH:
    return nq * (grad + 18 * nn + 6 * ndof + 162 * nn + 54 * pairs);
  default:
    return nq * (grad + nn) + pairs * 2 * nq;
  }
}

/* Assemble `kind` on a box of n^3 cells of `type` (SNH: at a smooth displacement of about 1 %
 * strain), best of 3 repetitions of the whole assembly; r->work: flops, or for the mass the
 * bytes of the global matrix entries it adds to (8 read + 8 written per element matrix entry). */
static int run_assembly(fcm_ctx *ctx, fcm_element_type type, int n, kernel_row kind,
                        bench_result *r)
{
  int ok = 0;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n3[3] = {n, n, n};
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  double *u = NULL, *force = NULL;
  fcm_rule *rule = NULL;
  assembly_args a;
  memset(&a, 0, sizeof a);
  a.kind = kind;
  a.mat = (fcm_material){kind == ROW_SNH ? FCM_MATERIAL_STABLE_NEO_HOOKEAN : FCM_MATERIAL_LINEAR,
                         1e7, 0.3, 1000};
  a.ok = 1;
  if (fcm_mesh_create_box(ctx, type, lo, hi, n3, &mesh) ||
      fcm_space_create(ctx, mesh, NULL, &space) || fcm_space_matrix_create(space, &a.A) ||
      fcm_assembly_workspace_create(space, NULL, &a.ws) ||
      fcm_material_setup(ctx, &a.mat, &a.params) ||
      fcm_element_standard_rule(ctx, type, kind == ROW_MASS ? FCM_RULE_MASS : FCM_RULE_STIFFNESS,
                                FCM_DEFAULT, &rule))
    goto done;
  const fcm_index ndof = fcm_space_num_dofs(space), nnodes = fcm_mesh_num_nodes(mesh);
  u = calloc((size_t)ndof, sizeof *u), force = calloc((size_t)ndof, sizeof *force);
  if (!u || !force) goto done;
  const double *xyz = fcm_mesh_coords(mesh);
  for (fcm_index i = 0; i < nnodes; i++) {
    const double *x = xyz + 3 * i;
    const fcm_index d = fcm_space_node_dof(space, i);
    for (int k = 0; k < 3; k++)
      u[d + k] = 0.01 * sin(3.0 * x[(k + 1) % 3] + k) * x[k];
  }
  a.u = u, a.force = force;
  assembly_once(&a); /* warm-up: tabulation, pages */
  r->seconds = best_of(3, assembly_once, &a);
  if (!a.ok) goto done;
  const double cells = (double)fcm_mesh_num_cells(mesh);
  const double nn = fcm_element_get_info(type)->num_nodes, nq = fcm_rule_num_points(rule);
  r->size = cells;
  r->work = kind == ROW_MASS ? cells * 16.0 * 9 * nn * nn : cells * kernel_flops(kind, nn, nq);
  fcm_index nnz = 0;
  fcm_csr_get_size(a.A, NULL, NULL, &nnz);
  double tr = 0.0; /* every kernel row adds positive diagonal entries */
  const fcm_index *rp = fcm_csr_row_ptr(a.A);
  const int *ci = fcm_csr_col_idx(a.A);
  const double *v = fcm_csr_values(a.A);
  for (fcm_index i = 0; i < ndof; i++)
    for (fcm_index k = rp[i]; k < rp[i + 1]; k++)
      if (ci[k] == i) tr += v[k];
  r->check = tr;
  ok = tr > 0.0 && nnz > 0;
done:
  if (!ok) fcm_ctx_error_view(ctx, stderr);
  free(u), free(force);
  fcm_rule_destroy(&rule);
  fcm_assembly_workspace_destroy(&a.ws);
  fcm_csr_destroy(&a.A);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  return ok;
}

/* Box sizes at the default 24: 4,096 to 13,824 cells, matrices of 40 to 190 MB (beyond the
 * last-level cache). */
static int run_hex8_stiffness(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_HEX8, cells, ROW_STIFFNESS, r);
}

static int run_hex20_stiffness(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_HEX20, (2 * cells + 2) / 3, ROW_STIFFNESS, r);
}

static int run_tet10_stiffness(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_TET10, (cells + 1) / 2, ROW_STIFFNESS, r);
}

static int run_hex20_snh(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_HEX20, (2 * cells + 2) / 3, ROW_SNH, r);
}

static int run_hex20_mass(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_HEX20, (2 * cells + 2) / 3, ROW_MASS, r);
}

typedef struct spmv_args {
  const fcm_csr *A;
  const double *x;
  double *y;
  int ok;
} spmv_args;

static void spmv_once(void *p)
{
  spmv_args *s = p;
  s->ok &= fcm_csr_apply(s->A, 1.0, s->x, 0.0, s->y) == FCM_OK;
}

/* y = K x with the Hex8 elasticity matrix of (4 cells / 3)^3 cells (100 MB at the default 24,
 * beyond the last-level cache), best of 10. Bytes: the values (8)
 * and column indices (4) of every entry, the row pointers (8 per row), x read and y written once
 * (8 + 8 per row): the least a CSR SpMV moves. The check: x^T K x > 0. */
static int run_spmv(fcm_ctx *ctx, int cells, bench_result *r)
{
  int ok = 0;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index m = 4 * (fcm_index)cells / 3, n3[3] = {m, m, m};
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e7, 0.3, 1000};
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL;
  double *x = NULL, *y = NULL;
  if (fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &mesh) ||
      fcm_space_create(ctx, mesh, NULL, &space) || fcm_space_matrix_create(space, &K) ||
      fcm_assemble_stiffness(space, &mat, NULL, K))
    goto done;
  fcm_index n = 0, nnz = 0;
  fcm_csr_get_size(K, &n, NULL, &nnz);
  x = malloc((size_t)n * sizeof *x), y = malloc((size_t)n * sizeof *y);
  if (!x || !y) goto done;
  for (fcm_index i = 0; i < n; i++)
    x[i] = 1.0 + 0.5 * sin(0.37 * (double)i);
  spmv_args s = {K, x, y, 1};
  spmv_once(&s);
  r->seconds = best_of(10, spmv_once, &s);
  double xkx = 0.0;
  for (fcm_index i = 0; i < n; i++)
    xkx += x[i] * y[i];
  r->size = (double)n;
  r->work = 12.0 * (double)nnz + 24.0 * (double)n;
  r->check = xkx;
  ok = s.ok && xkx > 0.0;
done:
  if (!ok) fcm_ctx_error_view(ctx, stderr);
  free(x), free(y);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  return ok;
}

/* ------------------------------------------------------------------ simplification rows */

/* Simplification of real cut-cell rules: the ball of radius 0.8 (fcm_geometry_create_ball,
 * resolution 6, as tests/embed/bench.c) in a box grid of 8^3 Hex8 cells over [-1,1]^3; the
 * SIMP_CELLS cut cells with volume fraction in [0.25, 0.75] spread over the grid. Per cell:
 * - the volume path's input: the cell's stiffness rule of strength m without simplification
 *   (the geometry's tets clipped by the cell, a tet rule on each; FCM_CELL_MOMENTS_VOLUME);
 * - the surface path's input (FCM_CELL_MOMENTS_AUTO, the default): candidates as that path
 *   picks them (the points of a grid over the material's box in the cell inside the material,
 *   about c(m) M of them (fcm__fit_candidates_per_moment), and up to M points on the material's
 *   boundary: vertices and centroids of
 *   the boundary triangles' parts in the cell; the sets 4, 16, 64 times larger that path
 *   retries on, up to the first that fits) and the material's moments in the basis of the
 *   material's box (here from the volume rule, exact to rounding for a polyhedral body).
 * Rows per strength: "simp_fit_mM" the default path (fcm__simplify_fit on each candidate set in
 * turn until one fits, all of them timed),
 * "simp_elim1_mM" fcm_simplify's elimination one direction at a time (elimination_block = 1,
 * the unblocked path), "simp_elim_mM" the same with the default blocked elimination. Time: mean
 * over the cells of the best of SIMP_REPS calls, the whole call (basis, factorization,
 * elimination or NNLS, re-fit and verification). Flops: the algorithm's arithmetic as the
 * library counts it (fcm_simplify_info.flops: LU, triangular solves and tableau updates;
 * fcm__fit.flops: NNLS gradients, QR updates, solves and residuals), not the basis
 * evaluation and verification. Every rule is checked: no fallback, at most M points, the
 * residual within the default tolerance. The point counts go to stderr. */
enum { SIMP_CELLS = 4, SIMP_REPS = 3, SIMP_GRID = 8 };
/* The surface path's retries: up to SIMP_GRIDS candidate sets, each aiming at SIMP_GROW times
 * as many points as the one before. */
enum { SIMP_GRIDS = 4, SIMP_GROW = 4 };

typedef struct simp_cell {
  int n;                    /* volume rule points */
  double *pts, *w;          /* the volume rule (reference coordinates) */
  int grids;                /* candidate sets the surface path fits on (the last one fits) */
  int nc[SIMP_GRIDS];       /* candidates of each */
  double *cand[SIMP_GRIDS]; /* nc x 3 each */
  double *mom;              /* M moments in the basis of box */
  fcm__cheb_box box;        /* the material's box -> [-1, 1]^3 */
  double atol;              /* absolute moment residual accepted (as the surface path) */
} simp_cell;

typedef struct simp_input {
  int m, cells;
  simp_cell c[SIMP_CELLS];
} simp_input;

static void simp_free(simp_input *in)
{
  for (int k = 0; k < in->cells; k++) {
    free(in->c[k].pts), free(in->c[k].w), free(in->c[k].mom);
    for (int a = 0; a < SIMP_GRIDS; a++)
      free(in->c[k].cand[a]);
  }
  in->cells = 0;
}

/* 1 when x lies in the tet v (4 x 3) up to rounding. */
static int in_tet(const double *v, const double *x)
{
  double a[3][3], r[3];
  for (int d = 0; d < 3; d++) {
    for (int c = 0; c < 3; c++)
      a[d][c] = v[3 * (c + 1) + d] - v[d];
    r[d] = x[d] - v[d];
  }
  const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                     a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                     a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  double l[3];
  for (int c = 0; c < 3; c++) { /* Cramer: column c replaced by r */
    double b[3][3];
    memcpy(b, a, sizeof b);
    for (int d = 0; d < 3; d++)
      b[d][c] = r[d];
    l[c] = (b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
            b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
            b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0])) /
           det;
  }
  const double eps = 1e-12;
  return l[0] >= -eps && l[1] >= -eps && l[2] >= -eps && l[0] + l[1] + l[2] <= 1.0 + eps;
}

/* The geometry's tets that meet the box lo..hi (up to rounding): their ids into near, count
 * returned. */
static fcm_index tets_near(const fcm_geometry *g, const double lo[3], const double hi[3],
                           fcm_index *near)
{
  const double *X = fcm_geometry_coords(g);
  const fcm_index *cells = fcm_geometry_cells(g);
  fcm_index n = 0;
  for (fcm_index t = 0; t < fcm_geometry_num_cells(g); t++) {
    int meets = 1;
    for (int d = 0; d < 3 && meets; d++) {
      double a = 1e30, b = -1e30;
      for (int v = 0; v < 4; v++)
        a = fmin(a, X[3 * cells[4 * t + v] + d]), b = fmax(b, X[3 * cells[4 * t + v] + d]);
      meets = a <= hi[d] + 1e-12 && b >= lo[d] - 1e-12;
    }
    if (meets) near[n++] = t;
  }
  return n;
}

/* 1 when the physical point x lies in one of the geometry's tets near[0..n). */
static int in_geometry(const fcm_geometry *g, fcm_index n, const fcm_index *near, const double *x)
{
  const double *X = fcm_geometry_coords(g);
  const fcm_index *cells = fcm_geometry_cells(g);
  for (fcm_index k = 0; k < n; k++) {
    double v[12];
    for (int a = 0; a < 4; a++)
      memcpy(v + 3 * a, X + 3 * cells[4 * near[k] + a], 3 * sizeof *v);
    if (in_tet(v, x)) return 1;
  }
  return 0;
}

/* The part of boundary triangle tri (node ids into X) in the box lo..hi, clipped plane by
 * plane (Sutherland-Hodgman): its vertices into poly (at most 9), their number returned. */
static int clip_triangle(const double *X, const fcm_index *tri, const double lo[3],
                         const double hi[3], double *poly)
{
  double buf[3 * 9];
  int n = 3;
  for (int a = 0; a < 3; a++)
    memcpy(poly + 3 * a, X + 3 * tri[a], 3 * sizeof *poly);
  for (int pl = 0; pl < 6 && n > 0; pl++) {
    const int d = pl % 3;
    const double s = pl < 3 ? 1.0 : -1.0, c = pl < 3 ? lo[d] : hi[d]; /* s (x_d - c) >= 0 */
    int m = 0;
    for (int i = 0; i < n; i++) {
      const double *p = poly + 3 * i, *q = poly + 3 * ((i + 1) % n);
      const double fp = s * (p[d] - c), fq = s * (q[d] - c);
      if (fp >= 0.0) memcpy(buf + 3 * m++, p, 3 * sizeof *p);
      if ((fp >= 0.0) != (fq >= 0.0) && m < 9) {
        const double u = fp / (fp - fq);
        for (int e = 0; e < 3; e++)
          buf[3 * m + e] = p[e] + u * (q[e] - p[e]);
        buf[3 * m + d] = c;
        m++;
      }
    }
    n = m;
    memcpy(poly, buf, 3 * (size_t)n * sizeof *poly);
  }
  return n;
}

/* Candidate set `a` of one cell (physical box clo..chi, reference [-1, 1]^3) for strength m:
 * the grid over the material's box (reference mbox) inside the geometry, sized for about
 * c(m) M grow of them, and up to M grow boundary points (the vertices and centroids of the
 * boundary triangles' parts in the cell), grow = SIMP_GROW^a. */
static int simp_candidates(const fcm_geometry *g, fcm_index nnear, const fcm_index *near,
                           const double clo[3], const double chi[3], int m, int M, double vol,
                           const double mbox[6], int a, simp_cell *c)
{
  int grow = 1;
  for (int k = 0; k < a; k++)
    grow *= SIMP_GROW;
  M *= grow;
  const double bv = (mbox[3] - mbox[0]) * (mbox[4] - mbox[1]) * (mbox[5] - mbox[2]);
  const double per = fcm__fit_candidates_per_moment(m);
  const int n = (int)fmin(64.0, fmax(2.0, ceil(cbrt(per * M * bv / vol))));
  const fcm_index nt = fcm_geometry_num_boundary_triangles(g);
  const fcm_index *tri = fcm_geometry_boundary_triangles(g);
  const double *X = fcm_geometry_coords(g);
  double *cand = c->cand[a] =
      malloc(3 * ((size_t)(n + 1) * (n + 1) * (n + 1) + (size_t)M) * sizeof *cand);
  double *bnd = malloc(3 * 10 * (size_t)nt * sizeof *bnd);
  if (!cand || !bnd) return free(bnd), 0;
  int nc = 0;
  for (int i = 0; i <= n; i++)
    for (int j = 0; j <= n; j++)
      for (int k = 0; k <= n; k++) {
        const int ijk[3] = {i, j, k};
        double xi[3], x[3];
        for (int d = 0; d < 3; d++) {
          xi[d] = mbox[d] + (mbox[3 + d] - mbox[d]) * ijk[d] / n;
          x[d] = clo[d] + 0.5 * (xi[d] + 1.0) * (chi[d] - clo[d]);
        }
        if (in_geometry(g, nnear, near, x)) memcpy(cand + 3 * (size_t)nc++, xi, sizeof xi);
      }
  size_t nb = 0;
  for (fcm_index t = 0; t < nt; t++) { /* the parts' vertices, then their centroid */
    double poly[3 * 9];
    const int np = clip_triangle(X, tri + 3 * t, clo, chi, poly);
    double cen[3] = {0, 0, 0};
    for (int i = 0; i <= np && np >= 3; i++) {
      const double *x = i < np ? poly + 3 * i : cen;
      for (int d = 0; d < 3; d++) {
        if (i < np) cen[d] += poly[3 * i + d] / np;
        bnd[3 * nb + d] = 2.0 * (x[d] - clo[d]) / (chi[d] - clo[d]) - 1.0;
      }
      nb++;
    }
  }
  const size_t take = nb < (size_t)M ? nb : (size_t)M;
  for (size_t i = 0; i < take; i++)
    memcpy(cand + 3 * (size_t)nc++, bnd + 3 * (i * nb / take), 3 * sizeof *bnd);
  c->nc[a] = nc;
  free(bnd);
  return 1;
}

/* The material's box in the cell lo..hi, in reference coordinates (as the surface path): the
 * boundary triangles' parts in the cell and the cell's corners inside the body. */
static void material_box(const fcm_geometry *g, fcm_index nnear, const fcm_index *near,
                         const double lo[3], const double hi[3], double mbox[6])
{
  const fcm_index *tri = fcm_geometry_boundary_triangles(g);
  const double *X = fcm_geometry_coords(g);
  for (int d = 0; d < 3; d++)
    mbox[d] = 1e30, mbox[3 + d] = -1e30;
  for (int k = 0; k < 8 + fcm_geometry_num_boundary_triangles(g); k++) {
    double poly[3 * 9];
    int np = 1;
    if (k < 8) { /* a corner of the cell */
      for (int d = 0; d < 3; d++)
        poly[d] = (k >> d) & 1 ? hi[d] : lo[d];
      if (!in_geometry(g, nnear, near, poly)) continue;
    } else {
      np = clip_triangle(X, tri + 3 * (k - 8), lo, hi, poly);
    }
    for (int i = 0; i < np; i++)
      for (int d = 0; d < 3; d++) {
        const double xi = 2.0 * (poly[3 * i + d] - lo[d]) / (hi[d] - lo[d]) - 1.0;
        mbox[d] = fmin(mbox[d], xi), mbox[3 + d] = fmax(mbox[3 + d], xi);
      }
  }
}

/* The surface path's fit of one cell: on its candidate sets in turn until one fits (f->ok);
 * f->flops sums the attempts'. */
static int simp_fit(fcm_ctx *ctx, const simp_cell *c, fcm__fit *f)
{
  double flops = 0.0;
  for (int a = 0; a < c->grids; a++) {
    if (fcm__simplify_fit(ctx, &c->box, c->nc[a], c->cand[a], c->mom, 1e-12, c->atol, f)) return 0;
    flops += f->flops;
    if (f->ok) break;
  }
  f->flops = flops;
  return 1;
}

/* The inputs of strength m (see the section comment). */
static int simp_setup(fcm_ctx *ctx, int m, simp_input *in)
{
  int ok = 0;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, centre[3] = {0.013, 0.007, 0.003};
  const fcm_index n3[3] = {SIMP_GRID, SIMP_GRID, SIMP_GRID};
  const int M = fcm__simplify_num_basis(m);
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_index cut[SIMP_GRID * SIMP_GRID * SIMP_GRID], ncut = 0;
  double *work = NULL, *wf = NULL;
  int *idx = NULL;
  fcm_index *near = NULL;
  memset(in, 0, sizeof *in);
  in->m = m;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.kinds = FCM_RULES_STIFFNESS;
  o.strength[FCM_RULE_STIFFNESS] = m;
  o.simplify = FCM_CELL_SIMPLIFY_OFF;
  o.moments = FCM_CELL_MOMENTS_VOLUME;
  o.stabilization.mode = FCM_STABILIZATION_OFF;
  if (fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &mesh) ||
      fcm_geometry_create_ball(ctx, centre, 0.8, 6, &g) ||
      fcm_cell_rules_create(ctx, mesh, g, &o, &rules))
    goto done;
  for (fcm_index k = 0; k < fcm_mesh_num_cells(mesh); k++) {
    const double phi = fcm_cell_rules_volume_fraction(rules, k);
    if (fcm_cell_rules_class(rules, k) == FCM_CELL_CUT && phi >= 0.25 && phi <= 0.75)
      cut[ncut++] = k;
  }
  work = malloc(fcm__simplify_moments_scratch(m) * sizeof *work);
  idx = malloc((size_t)M * sizeof *idx), wf = malloc((size_t)M * sizeof *wf);
  near = malloc((size_t)fcm_geometry_num_cells(g) * sizeof *near);
  if (ncut < SIMP_CELLS || !work || !idx || !wf || !near) goto done;
  for (int k = 0; k < SIMP_CELLS; k++) {
    const fcm_index cell = cut[(size_t)k * (size_t)ncut / SIMP_CELLS];
    simp_cell *c = &in->c[in->cells++];
    int n;
    const double *p, *w;
    double X[8 * 3], clo[3] = {1e30, 1e30, 1e30}, chi[3] = {-1e30, -1e30, -1e30};
    if (fcm_cell_rules_get(rules, cell, FCM_RULE_STIFFNESS, &n, &p, &w, NULL)) goto done;
    c->n = n;
    c->pts = malloc(3 * (size_t)n * sizeof *c->pts), c->w = malloc((size_t)n * sizeof *c->w);
    c->mom = malloc((size_t)M * sizeof *c->mom);
    if (!c->pts || !c->w || !c->mom) goto done;
    memcpy(c->pts, p, 3 * (size_t)n * sizeof *p);
    memcpy(c->w, w, (size_t)n * sizeof *w);
    /* the material's box in reference coordinates */
    fcm_mesh_cell_coords(mesh, cell, X);
    for (int a = 0; a < 8; a++)
      for (int d = 0; d < 3; d++)
        clo[d] = fmin(clo[d], X[3 * a + d]), chi[d] = fmax(chi[d], X[3 * a + d]);
    double mbox[6], vol = 0.0;
    const fcm_index nnear = tets_near(g, clo, chi, near);
    material_box(g, nnear, near, clo, chi, mbox);
    for (int j = 0; j < n; j++) {
      vol += w[j];
      for (int d = 0; d < 3; d++)
        TEST_TRUE(p[3 * j + d] >= mbox[d] - 1e-12 && p[3 * j + d] <= mbox[3 + d] + 1e-12);
    }
    c->box.m = m, c->box.num_basis = M;
    for (int d = 0; d < 3; d++) { /* as the surface path: the material's box -> [-1, 1] */
      c->box.scale[d] = 2.0 / (mbox[3 + d] - mbox[d]);
      c->box.shift[d] = -(mbox[d] + mbox[3 + d]) / (mbox[3 + d] - mbox[d]);
    }
    fcm__simplify_moments(&c->box, n, c->pts, NULL, c->w, c->mom, work);
    c->atol = 1e-14 * (mbox[3] - mbox[0]) * (mbox[4] - mbox[1]) * (mbox[5] - mbox[2]);
    fcm__fit f;
    memset(&f, 0, sizeof f);
    f.idx = idx, f.w = wf;
    for (int a = 0; a < SIMP_GRIDS && !f.ok; a++) { /* the sets until one fits */
      if (!simp_candidates(g, nnear, near, clo, chi, m, M, vol, mbox, a, c)) goto done;
      c->grids = a + 1;
      if (fcm__simplify_fit(ctx, &c->box, c->nc[a], c->cand[a], c->mom, 1e-12, c->atol, &f))
        goto done;
    }
    if (!f.ok) {
      fprintf(stderr, "simplify m = %d: cell %lld: no candidate set fits: %s\n", m, (long long)cell,
              f.message);
      goto done;
    }
  }
  ok = 1;
done:
  if (!ok) fcm_ctx_error_view(ctx, stderr), simp_free(in);
  free(work), free(idx), free(wf), free(near);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  return ok;
}

/* Path 0: the default surface path's fit; 1: elimination one direction at a time; 2: the
 * default (blocked) elimination. */
static int run_simp(fcm_ctx *ctx, int m, int path, bench_result *r)
{
  simp_input in;
  static const char *names[3] = {"fit (NNLS)", "elimination, rank-1", "elimination, blocked"};
  if (!simp_setup(ctx, m, &in)) return 0;
  const int M = fcm__simplify_num_basis(m);
  int ok = 1, *idx = malloc((size_t)M * sizeof *idx);
  double *wf = malloc((size_t)M * sizeof *wf), size = 0, secs = 0, flops = 0, kept = 0, grids = 0;
  fcm_simplify_options so = fcm_simplify_options_default();
  so.method = FCM_SIMPLIFY_ELIMINATE;
  so.elimination_block = path == 1 ? 1 : FCM_DEFAULT;
  for (int k = 0; k < in.cells && ok && idx && wf; k++) {
    const simp_cell *c = &in.c[k];
    double best = 1e30;
    for (int rep = 0; rep < SIMP_REPS && ok; rep++) {
      double t0, fl, res;
      int cnt;
      if (path == 0) {
        fcm__fit f;
        memset(&f, 0, sizeof f);
        f.idx = idx, f.w = wf;
        t0 = cpu_seconds();
        ok = simp_fit(ctx, c, &f);
        best = fmin(best, cpu_seconds() - t0);
        ok = ok && f.ok;
        fl = f.flops, cnt = f.count, res = f.residual;
      } else {
        fcm_simplify_result res_;
        fcm_simplify_info info;
        t0 = cpu_seconds();
        ok = fcm_simplify(ctx, m, c->n, c->pts, c->w, &so, &res_, &info) == FCM_OK;
        best = fmin(best, cpu_seconds() - t0);
        ok = ok && !info.fallback;
        fl = info.flops, cnt = (int)res_.count, res = info.residual;
        fcm_simplify_result_destroy(&res_);
      }
      TEST_TRUE(ok && cnt <= M && res <= 1e-12);
      if (rep == 0) {
        size += (double)(path == 0 ? c->nc[c->grids - 1] : c->n) / in.cells;
        grids += (double)c->grids / in.cells;
        flops += fl / in.cells, kept += (double)cnt / in.cells;
      }
    }
    secs += best / in.cells;
  }
  if (ok && path == 0)
    fprintf(stderr,
            "simplify m = %d (M = %d), %s: %.0f candidates (the set that fits; %.2f sets fitted), "
            "%.1f kept (mean of %d cells)\n",
            m, M, names[path], size, grids, kept, in.cells);
  else if (ok)
    fprintf(stderr, "simplify m = %d (M = %d), %s: %.0f points in, %.1f kept (mean of %d cells)\n",
            m, M, names[path], size, kept, in.cells);
  else
    fcm_ctx_error_view(ctx, stderr);
  r->size = size, r->seconds = secs, r->work = flops;
  free(idx), free(wf);
  simp_free(&in);
  return ok;
}

#define SIMP_ROWS(m)                                                                               \
  static int run_simp_fit_m##m(fcm_ctx *ctx, int cells, bench_result *r)                           \
  {                                                                                                \
    (void)cells;                                                                                   \
    return run_simp(ctx, m, 0, r);                                                                 \
  }                                                                                                \
  static int run_simp_elim1_m##m(fcm_ctx *ctx, int cells, bench_result *r)                         \
  {                                                                                                \
    (void)cells;                                                                                   \
    return run_simp(ctx, m, 1, r);                                                                 \
  }                                                                                                \
  static int run_simp_elim_m##m(fcm_ctx *ctx, int cells, bench_result *r)                          \
  {                                                                                                \
    (void)cells;                                                                                   \
    return run_simp(ctx, m, 2, r);                                                                 \
  }
SIMP_ROWS(3)
SIMP_ROWS(5)
SIMP_ROWS(7)
SIMP_ROWS(9)
#define SIMP_ITEMS(m)                                                                              \
  {"simp_fit_m" #m, "GFLOP/s", "dgemm", run_simp_fit_m##m},                                        \
      {"simp_elim1_m" #m, "GFLOP/s", "dgemm", run_simp_elim1_m##m},                                \
  {                                                                                                \
    "simp_elim_m" #m, "GFLOP/s", "dgemm", run_simp_elim_m##m                                       \
  }

/* The rows, in order. A kernel of fcm goes here as one more entry (element stiffness and
 * tangent assembly against "dgemm", CSR SpMV and mass assembly against "triad"); the peaks
 * ("dgemm", "triad") come first. */
static const bench_item items[] = {
    {"dgemm", "GFLOP/s", "dgemm", run_dgemm},
    {"triad", "GB/s", "triad", run_triad},
    {"cholmod_factor", "GFLOP/s", "dgemm", run_cholmod},
    SIMP_ITEMS(3),
    SIMP_ITEMS(5),
    SIMP_ITEMS(7),
    SIMP_ITEMS(9),
};
enum { NITEMS = sizeof items / sizeof items[0] };

/* fcm's kernels that do not use the BLAS: measured once (kernel set "any"), not per set. */
static const bench_item once_items[] = {
    {"hex8_stiffness", "GFLOP/s", "dgemm", run_hex8_stiffness},
    {"hex20_stiffness", "GFLOP/s", "dgemm", run_hex20_stiffness},
    {"tet10_stiffness", "GFLOP/s", "dgemm", run_tet10_stiffness},
    {"hex20_snh", "GFLOP/s", "dgemm", run_hex20_snh},
    {"hex20_mass", "GB/s", "triad", run_hex20_mass},
    {"csr_spmv", "GB/s", "triad", run_spmv},
};
enum { NALL = NITEMS + (int)(sizeof once_items / sizeof once_items[0]) };

/* Item i of items[] followed by once_items[] (i < NALL). */
static const bench_item *item_at(int i)
{
  return i < NITEMS ? &items[i] : &once_items[i - NITEMS];
}

/* The number of items measured per kernel set (once = 0) or once (once = 1). */
static int count_items(int once)
{
  return once ? NALL - NITEMS : NITEMS;
}

/* Child: one line "ROW item size seconds work check" per item measured per kernel set
 * (once = 0) or once (once = 1) on stdout; only the item named `only` when it is not NULL. */
static int child(int cells, int once, const char *only)
{
  fcm_blas_set_num_threads(1);
  fcm_ctx_options o = fcm_ctx_options_default();
  o.num_threads = 1;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(&o, &ctx));
  if (!ctx) return 1;
  for (int i = once ? NITEMS : 0; i < (once ? NALL : NITEMS); i++) {
    bench_result r = {0, 0, 0, 0};
    if (only && strcmp(only, item_at(i)->name)) continue;
    if (!item_at(i)->run(ctx, cells, &r)) {
      TEST_FAIL_("bench_roofline: %s failed", item_at(i)->name);
      continue;
    }
    printf("ROW %s %.17g %.17g %.17g %.17g\n", item_at(i)->name, r.size, r.seconds, r.work,
           r.check);
    fflush(stdout);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}

/* ------------------------------------------------------------------ parent: the table */

typedef struct row {
  char set[32];  /* kernel set */
  char role[16]; /* "fallback", "selected", "loaded" */
  int item;
  bench_result r;
} row;

/* The index of the item named `name` in items[] then once_items[], -1 when none is. */
static int item_index(const char *name)
{
  for (int i = 0; i < NALL; i++)
    if (!strcmp(item_at(i)->name, name)) return i;
  return -1;
}

/* The children's environment: one BLAS and one OpenMP thread. OMP_THREAD_LIMIT too: CHOLMOD
 * (SuiteSparse 5.x) runs the scatter loops of its supernodal factorization in OpenMP teams of a
 * size fixed when it was built (num_threads(CHOLMOD_OMP_NUM_THREADS), 4 in Debian's build),
 * which OMP_NUM_THREADS does not limit; their CPU time would count in a one-thread row. */
#define ONE_THREAD "OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 OMP_THREAD_LIMIT=1"

/* Run `self child CELLS` (once: `self once CELLS`, the items that do not use the BLAS) under
 * OPENBLAS_CORETYPE=core (NULL: as loaded) and append its rows. */
static void measure(const char *self, int cells, const char *core, const char *role, int once,
                    row *rows, int *nrows)
{
  char cmd[4200];
  const char *mode = once ? "once" : "child";
  if (core)
    snprintf(cmd, sizeof cmd, "OPENBLAS_CORETYPE=%s " ONE_THREAD " '%s' %s %d", core, self, mode,
             cells);
  else
    snprintf(cmd, sizeof cmd, ONE_THREAD " '%s' %s %d", self, mode, cells);
  FILE *p = popen(cmd, "r");
  TEST_TRUE(p != NULL);
  if (!p) return;
  char line[512], name[64];
  int got = 0;
  while (fgets(line, sizeof line, p)) {
    row w;
    memset(&w, 0, sizeof w);
    if (*nrows >= MAX_ROWS || sscanf(line, "ROW %63s %lf %lf %lf %lf", name, &w.r.size,
                                     &w.r.seconds, &w.r.work, &w.r.check) != 5)
      continue;
    w.item = item_index(name);
    if (w.item < 0) continue;
    snprintf(w.set, sizeof w.set, "%s", once ? "any" : core ? core : "as loaded");
    snprintf(w.role, sizeof w.role, "%s", role);
    rows[(*nrows)++] = w;
    got++;
  }
  TEST_TRUE(pclose(p) == 0);
  TEST_TRUE(got == count_items(once));
}

/* GFLOP/s or GB/s (work in flops or bytes). */
static double rate(const row *w)
{
  return w->r.seconds > 0 ? 1e-9 * w->r.work / w->r.seconds : 0.0;
}

/* The best rate of the item named `name` over all rows (the peak), 0 when none. */
static double peak_of(const row *rows, int nrows, const char *name)
{
  double p = 0.0;
  for (int i = 0; i < nrows; i++)
    if (!strcmp(item_at(rows[i].item)->name, name)) p = fmax(p, rate(&rows[i]));
  return p;
}

/* The row of item `name` measured with the kernel set of role `role`, or NULL. */
static const row *find(const row *rows, int nrows, const char *name, const char *role)
{
  for (int i = 0; i < nrows; i++)
    if (!strcmp(item_at(rows[i].item)->name, name) && !strcmp(rows[i].role, role)) return &rows[i];
  return NULL;
}

static void report(const row *rows, int nrows, const char *csv_path)
{
  FILE *csv = fopen(csv_path, "w");
  TEST_TRUE(csv != NULL);
  if (csv) fprintf(csv, "kernels,role,item,size,cpu_seconds,rate,unit,peak,fraction_of_peak\n");
  printf("%-12s %-9s %-15s %10s %10s %10s %-8s %7s\n", "kernels", "role", "item", "size", "cpu s",
         "rate", "unit", "peak");
  for (int i = 0; i < nrows; i++) {
    const row *w = &rows[i];
    const bench_item *it = item_at(w->item);
    const double pk = peak_of(rows, nrows, it->peak), x = rate(w);
    printf("%-12s %-9s %-15s %10.0f %10.4f %10.2f %-8s %6.1f%%\n", w->set, w->role, it->name,
           w->r.size, w->r.seconds, x, it->unit, pk > 0 ? 100.0 * x / pk : 0.0);
    if (csv)
      fprintf(csv, "%s,%s,%s,%.0f,%.6g,%.6g,%s,%s,%.4f\n", w->set, w->role, it->name, w->r.size,
              w->r.seconds, x, it->unit, it->peak, pk > 0 ? x / pk : 0.0);
  }
  if (csv) TEST_TRUE(fclose(csv) == 0);
}

/* One line: the peaks, and CHOLMOD with the selected kernels against the fallback. */
static void summary(const row *rows, int nrows)
{
  const row *gs = find(rows, nrows, "dgemm", "selected"),
            *gf = find(rows, nrows, "dgemm", "fallback");
  const row *cs = find(rows, nrows, "cholmod_factor", "selected");
  const row *cf = find(rows, nrows, "cholmod_factor", "fallback");
  const double dpk = peak_of(rows, nrows, "dgemm"), tpk = peak_of(rows, nrows, "triad");
  printf("roofline: DGEMM peak %.1f GFLOP/s, triad %.1f GB/s", dpk, tpk);
  if (gs && gf) printf("; DGEMM %s %.1f vs %s %.1f GFLOP/s", gs->set, rate(gs), gf->set, rate(gf));
  if (cs && cf)
    printf("; CHOLMOD factor (%.0f DOFs) %.3f s (%.0f%% of peak) vs %.3f s: %.2fx", cs->r.size,
           cs->r.seconds, 100.0 * rate(cs) / dpk, cf->r.seconds, cf->r.seconds / cs->r.seconds);
  printf("\n");
}

/* fcm's kernels (the rows measured once): time per cell (per SpMV for csr_spmv) and the
 * fraction of the peak, one line. */
static void report_kernels(const row *rows, int nrows)
{
  const double dpk = peak_of(rows, nrows, "dgemm"), tpk = peak_of(rows, nrows, "triad");
  printf("fcm kernels (any kernel set):");
  for (int i = 0; i < nrows; i++) {
    const row *w = &rows[i];
    const bench_item *it = item_at(w->item);
    if (w->item < NITEMS) continue;
    const double pk = strcmp(it->peak, "dgemm") ? tpk : dpk;
    if (strcmp(it->name, "csr_spmv"))
      printf(" %s %.2f us/cell %.1f%%;", it->name, 1e6 * w->r.seconds / w->r.size,
             pk > 0 ? 100.0 * rate(w) / pk : 0.0);
    else
      printf(" %s %.2f ms %.1f%%;", it->name, 1e3 * w->r.seconds,
             pk > 0 ? 100.0 * rate(w) / pk : 0.0);
  }
  printf("\n");
}

/* One line per strength: ms per cell of the default path (the surface path's fit), the rank-1
 * elimination (the old path) and the blocked one, with the kernels fcm selects (or the only set
 * measured), and the default and the blocked elimination against the rank-1 one. */
static void simp_summary(const row *rows, int nrows)
{
  const char *role = find(rows, nrows, "dgemm", "selected") ? "selected" : "loaded";
  static const int ms[] = {3, 5, 7, 9};
  for (int k = 0; k < 4; k++) {
    char n[3][32];
    const row *w[3];
    snprintf(n[0], sizeof n[0], "simp_fit_m%d", ms[k]);
    snprintf(n[1], sizeof n[1], "simp_elim1_m%d", ms[k]);
    snprintf(n[2], sizeof n[2], "simp_elim_m%d", ms[k]);
    for (int p = 0; p < 3; p++)
      w[p] = find(rows, nrows, n[p], role);
    if (!w[0] || !w[1] || !w[2]) continue;
    printf("simplification m = %d (%s kernels), ms per cell: default (fit) %.3f, elimination "
           "rank-1 (old) %.3f, blocked %.3f; against the old: default %.2fx, blocked %.2fx\n",
           ms[k], role, 1e3 * w[0]->r.seconds, 1e3 * w[1]->r.seconds, 1e3 * w[2]->r.seconds,
           w[1]->r.seconds / w[0]->r.seconds, w[1]->r.seconds / w[2]->r.seconds);
  }
}

int main(int argc, char **argv)
{
  if (argc >= 3 && !strcmp(argv[1], "child")) return child(atoi(argv[2]), 0, argv[3]);
  if (argc >= 3 && !strcmp(argv[1], "once")) return child(atoi(argv[2]), 1, argv[3]);
  const char *csv = argc > 1 ? argv[1] : "bench_roofline.csv";
  const int cells = argc > 2 ? atoi(argv[2]) : 24;
  if (cells < 2 || cells > 200) {
    fprintf(stderr, "usage: bench_roofline [CSV [CELLS in 2..200]]\n");
    return 2;
  }
  char self[4096];
  const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
  if (len <= 0) {
    fprintf(stderr, "bench_roofline: cannot find its own executable\n");
    return 1;
  }
  self[len] = '\0';

  fcm_blas_info b;
  TEST_TRUE(fcm_blas_info_get(NULL, &b) == FCM_OK);
  printf("BLAS: %s, kernels %s (%s) as loaded%s; CPU %s: %s\n", b.config[0] ? b.config : b.name,
         b.core[0] ? b.core : "unknown", fcm_isa_name(b.core_isa),
         b.fallback ? " (a fallback)" : "", fcm_isa_name(b.cpu_isa),
         b.cpu_core[0] ? b.cpu_core : "no kernel set to select");
  row rows[MAX_ROWS];
  int nrows = 0;
  if (strcmp(b.name, "OpenBLAS") == 0 && b.cpu_core[0]) {
    /* the set OpenBLAS falls back to on a CPU it does not know, then the selected one */
    measure(self, cells, "Prescott", "fallback", 0, rows, &nrows);
    measure(self, cells, b.cpu_core, "selected", 0, rows, &nrows);
    /* and OpenBLAS's own choice, when it is a third set */
    if (b.core[0] && strcmp(b.core, "Prescott") && strcmp(b.core, b.cpu_core))
      measure(self, cells, b.core, "loaded", 0, rows, &nrows);
    measure(self, cells, b.cpu_core, "fcm", 1, rows, &nrows);
  } else {
    measure(self, cells, NULL, "loaded", 0, rows, &nrows);
    measure(self, cells, NULL, "fcm", 1, rows, &nrows);
  }
  report(rows, nrows, csv);
  /* the same solution, to round-off, with every kernel set */
  const row *c0 = find(rows, nrows, "cholmod_factor", "fallback");
  const row *c1 = find(rows, nrows, "cholmod_factor", "selected");
  if (c0 && c1) TEST_NEAR(c1->r.check, c0->r.check, 1e-10, 0.0);
  summary(rows, nrows);
  report_kernels(rows, nrows);
  simp_summary(rows, nrows);
  return TEST_RESULT();
}
