/* fcm-scaling: the study — the problems (an embedded body in a box of Hex8 / Hex20 cells,
 * clamped in a rigid base), the serial solvers and the PETSc rows timed and measured, the
 * budget estimates that skip what would take too long, and the loop over the study's rows. */
#define _GNU_SOURCE
#include "cli.h"
#include "fcm-scaling-study.h"

#include <fcm/fcm.h>
#if FCM_HAVE_PETSC
#include <fcm/petsc.h>
#endif

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

const char *const solver_names[NSOLVER + 1] = {"cholmod",     "cg-jacobi", "minres-schwarz",
                                               "cg-mg",       "mg",        "petsc-gamg",
                                               "petsc-mumps", "petsc-mg",  NULL};
const char *const backend_names[3] = {"serial", "petsc", NULL};
const char *const body_names[NBODY + 1] = {"ball", "hollow", "cube", "cut", NULL};
const char *const clock_names[3] = {"wall", "cpu", NULL};

/* Exponents the estimates use before two sizes of a solver are measured: time ~ dofs^t,
 * extra memory ~ dofs^m (CHOLMOD: ~N^2 flops and ~N^(4/3) fill for 3D nested dissection). */
static const double default_time_exp[NSOLVER] = {2.0, 1.4, 1.4, 1.15, 1.15, 1.15, 2.0, 1.15};
static const double default_mem_exp[NSOLVER] = {1.4, 1.0, 1.0, 1.0, 1.0, 1.0, 1.4, 1.0};

/* ------------------------------------------------------------- measurement */

static double cpu_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A "Key:  value kB" line of a /proc file in MB; < 0 when unavailable. */
static double proc_kb(const char *path, const char *key)
{
  FILE *f = fopen(path, "r");
  if (!f) return -1.0;
  char line[256];
  const size_t k = strlen(key);
  double v = -1.0;
  while (fgets(line, sizeof line, f))
    if (!strncmp(line, key, k) && line[k] == ':') {
      v = atof(line + k + 1) / 1024.0;
      break;
    }
  fclose(f);
  return v;
}

/* Give freed memory back to the kernel and reset the high-water mark VmHWM to the current
 * resident size (Linux: writing 5 to /proc/self/clear_refs); returns the current VmRSS in
 * MB, or -1 when the mark cannot be reset (then peaks are not measured). */
double scaling_rss_reset(void)
{
#ifdef __GLIBC__
  malloc_trim(0);
#endif
  FILE *f = fopen("/proc/self/clear_refs", "w");
  if (!f) return -1.0;
  const int ok = fputs("5", f) >= 0;
  if (fclose(f) != 0 || !ok) return -1.0;
  return proc_kb("/proc/self/status", "VmRSS");
}

static double rss_peak(void)
{
  return proc_kb("/proc/self/status", "VmHWM");
}
static double mem_available(void)
{
  return proc_kb("/proc/meminfo", "MemAvailable");
}

/* ------------------------------------------------------------- the problem */

typedef struct problem {
  fcm_mesh *mesh;
  fcm_geometry *geom;
  fcm_cell_rules *rules0, *rules;
  fcm_space *space;
  fcm_csr *A;
  double *b;
  fcm_index n;
  int vcycle; /* cube, cut: mg runs V-cycles (their rows give the V-cycle factor) */
} problem;

static void problem_free(problem *p)
{
  fcm_csr_destroy(&p->A);
  fcm_space_destroy(&p->space);
  fcm_cell_rules_destroy(&p->rules);
  fcm_cell_rules_destroy(&p->rules0);
  fcm_geometry_destroy(&p->geom);
  fcm_mesh_destroy(&p->mesh);
  free(p->b);
  memset(p, 0, sizeof *p);
}

/* Clamp every copy of every active node with y <= ymax. */
static fcm_status clamp_below(fcm_ctx *ctx, problem *p, double ymax)
{
  const double lo[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, hi[3] = {HUGE_VAL, ymax, HUGE_VAL};
  fcm_index cnt = 0, nd = 0;
  fcm_status st = fcm_mesh_nodes_in_box(ctx, p->mesh, lo, hi, 1e-9, 0, NULL, &cnt);
  if (st != FCM_OK) return st;
  fcm_index *nodes = malloc(sizeof *nodes * ((size_t)cnt + 1)), *dofs = NULL;
  if (!nodes) return FCM_ERR_ALLOC;
  st = fcm_mesh_nodes_in_box(ctx, p->mesh, lo, hi, 1e-9, cnt, nodes, &cnt);
  size_t total = 0;
  for (fcm_index i = 0; st == FCM_OK && i < cnt; i++)
    if (fcm_space_node_dof(p->space, nodes[i]) >= 0)
      total += 3 * (size_t)fcm_space_node_copies(p->space, nodes[i]);
  if (st == FCM_OK && !(dofs = malloc(sizeof *dofs * (total + 1)))) st = FCM_ERR_ALLOC;
  for (fcm_index i = 0; st == FCM_OK && i < cnt; i++) {
    const fcm_index d0 = fcm_space_node_dof(p->space, nodes[i]);
    if (d0 < 0) continue;
    for (fcm_index k = 0; k < 3 * fcm_space_node_copies(p->space, nodes[i]); k++)
      dofs[nd++] = d0 + k;
  }
  if (st == FCM_OK) st = fcm_space_apply_dirichlet(p->space, nd, dofs, NULL, p->A, p->b);
  free(nodes);
  free(dofs);
  return st;
}

#define TRY(call)                                                                                  \
  do {                                                                                             \
    st = (call);                                                                                   \
    if (st != FCM_OK) goto done;                                                                   \
  } while (0)

static fcm_status problem_build(fcm_ctx *ctx, const settings *o, fcm_element_type type, int body,
                                fcm_index n, problem *p)
{
  fcm_status st = FCM_OK;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c[3] = {0, 0, 0};
  const fcm_index cells[3] = {n, n, n};
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e5, 0.3, 1000.0};
  const double g[3] = {0.0, -9.81, 0.0};
  fcm_surface *cut = NULL;
  memset(p, 0, sizeof *p);
  TRY(fcm_mesh_create_box(ctx, type, lo, hi, cells, &p->mesh));
  if (body == B_CUBE) {
    TRY(fcm_space_create(ctx, p->mesh, NULL, &p->space));
  } else {
    if (body == B_HOLLOW)
      TRY(fcm_geometry_create_hollow_ball(ctx, c, 0.5, 0.9, 0.25, 16, 3, &p->geom));
    else
      TRY(fcm_geometry_create_ball(ctx, c, 0.9, 6, &p->geom));
    fcm_cell_rules_options ro = fcm_cell_rules_options_default();
    ro.kinds = FCM_RULES_STIFFNESS; /* a static problem needs no mass rules */
    TRY(fcm_cell_rules_create(ctx, p->mesh, p->geom, &ro, &p->rules0));
    if (body == B_CUT) {
      const double q[3] = {0.05, 0.0, 0.0}, nx[3] = {1, 0, 0};
      const double bl[3] = {-0.5, 0.0, -1.5}, bh[3] = {0.5, 1.5, 1.5};
      TRY(fcm_surface_create_plane(ctx, q, nx, bl, bh, &cut));
      TRY(fcm_cell_rules_create_cut(ctx, p->mesh, p->geom, p->rules0, cut, &p->rules));
    }
    fcm_space_options so = fcm_space_options_default();
    so.constrain_ratio = o->constrain_ratio;
    TRY(fcm_space_create_embedded_with(ctx, p->mesh, p->rules ? p->rules : p->rules0, &so,
                                       &p->space));
  }
  p->n = fcm_space_num_dofs(p->space);
  p->b = calloc((size_t)p->n + 1, sizeof *p->b);
  if (!p->b) {
    st = FCM_ERR_ALLOC;
    goto done;
  }
  TRY(fcm_space_matrix_create(p->space, &p->A));
  TRY(fcm_assemble_stiffness(p->space, &mat, NULL, p->A));
  TRY(fcm_assemble_body_force(p->space, &mat, g, NULL, p->b));
  TRY(clamp_below(ctx, p, body == B_CUBE ? -1.0 : -0.5));
  p->vcycle = body == B_CUBE || body == B_CUT;
done:
  fcm_surface_destroy(&cut);
  if (st != FCM_OK) problem_free(p);
  return st;
}

/* ------------------------------------------------------------- the solvers */

static double norm2(fcm_index n, const double *x)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += x[i] * x[i];
  return sqrt(s);
}

/* r->relres = ||b - A x|| / ||b|| on the serial problem (0 for b = 0); 0 when it cannot be
 * computed (no memory), r->relres then untouched. */
static int relative_residual(const problem *p, const double *x, row *r)
{
  double *ax = malloc(sizeof *ax * ((size_t)p->n + 1));
  const int ok = ax && fcm_csr_apply(p->A, 1.0, x, 0.0, ax) == FCM_OK;
  if (ok) {
    for (fcm_index i = 0; i < p->n; i++)
      ax[i] = p->b[i] - ax[i];
    const double bn = norm2(p->n, p->b);
    r->relres = bn > 0.0 ? norm2(p->n, ax) / bn : 0.0;
  }
  free(ax);
  return ok;
}

/* The commas of a message become semicolons (it goes into a CSV field). */
static void set_note(row *r, const char *msg)
{
  size_t k = 0;
  for (; msg[k] && k + 1 < sizeof r->note; k++)
    r->note[k] = msg[k];
  r->note[k] = 0;
  for (char *q = r->note; *q; q++)
    if (*q == ',' || *q == '\n') *q = ';';
}

/* r->diff = ||x - xref|| / ||xref|| (absolute when xref = 0); beyond --agree the row failed,
 * its note naming the reference `what`. */
static void compare(const settings *o, fcm_index n, const double *x, const double *xref,
                    const char *what, row *r)
{
  double dn = 0.0;
  for (fcm_index i = 0; i < n; i++)
    dn += (x[i] - xref[i]) * (x[i] - xref[i]);
  const double xn = norm2(n, xref);
  r->diff = xn > 0.0 ? sqrt(dn) / xn : sqrt(dn);
  if (!(r->diff <= o->agree)) {
    r->status = ROW_FAILED;
    char msg[200];
    snprintf(msg, sizeof msg, "differs from %s by %.3e > --agree %.1e", what, r->diff, o->agree);
    set_note(r, msg);
  }
}

/* Schwarz blocks of the simulations: cut cells with volume fraction below 0.5. */
static fcm_status schwarz_build(fcm_ctx *ctx, const problem *p, fcm_schwarz **S)
{
  const fcm_index nc = fcm_mesh_num_cells(p->mesh);
  const fcm_cell_rules *rules = fcm_space_cell_rules(p->space);
  unsigned char *flag = calloc((size_t)nc + 1, 1);
  fcm_index nb = 0, nd = 0, *ptr = NULL, *dofs = NULL;
  fcm_status st = FCM_OK;
  if (!flag) return FCM_ERR_ALLOC;
  for (fcm_index c = 0; rules && c < nc; c++)
    flag[c] = fcm_space_cell_active(p->space, c) &&
              fcm_cell_rules_class(rules, c) == FCM_CELL_CUT &&
              fcm_cell_rules_volume_fraction(rules, c) < 0.5;
  TRY(fcm_space_cell_blocks(p->space, flag, &nb, &nd, NULL, NULL));
  ptr = malloc(sizeof *ptr * ((size_t)nb + 1));
  dofs = malloc(sizeof *dofs * ((size_t)nd + 1));
  if (!ptr || !dofs) {
    st = FCM_ERR_ALLOC;
    goto done;
  }
  TRY(fcm_space_cell_blocks(p->space, flag, &nb, &nd, ptr, dofs));
  TRY(fcm_schwarz_create(ctx, p->A, nb, ptr, dofs, NULL, S));
done:
  free(flag);
  free(ptr);
  free(dofs);
  return st;
}

/* Run one solver on p into r (x: the solution out); xref: CHOLMOD's solution or NULL. */
static void run_solver(fcm_ctx *ctx, const settings *o, const problem *p, int s, double *x,
                       const double *xref, row *r)
{
  fcm_status st = FCM_OK;
  fcm_direct *d = NULL;
  fcm_jacobi *J = NULL;
  fcm_schwarz *S = NULL;
  fcm_mg *mg = NULL;
  fcm_krylov_options ko = fcm_krylov_options_default();
  fcm_krylov_info ki;
  fcm_mg_solve_info mi;
  fcm_mg_options mo = fcm_mg_options_default();
  const char *stage = "setup";
  mo.coarse_dofs = (fcm_index)o->coarse_dofs;
  if (p->vcycle) mo.cycle_index = 1;
  ko.rtol = o->rtol;
  ko.max_iterations = o->max_iterations;
  memset(x, 0, sizeof *x * (size_t)p->n);
  r->base_mb = scaling_rss_reset();
  double w0 = omp_get_wtime(), c0 = cpu_now(), w1 = w0, c1 = c0;
  switch (s) {
  case S_CHOLMOD:
    fcm_blas_set_num_threads(o->threads > 0 ? o->threads : omp_get_max_threads());
    st = fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, p->A, &d);
    if (st == FCM_OK) st = fcm_direct_analyze(d);
    if (st == FCM_OK) st = fcm_direct_factor(d, fcm_csr_values_read(p->A));
    w1 = omp_get_wtime(), c1 = cpu_now();
    if (st == FCM_OK) stage = "solve", st = fcm_direct_solve(d, p->b, x);
    fcm_blas_set_num_threads(1);
    r->iterations = 1;
    r->factor = -1.0;
    break;
  case S_CGJ:
  case S_MINRES:
  case S_CGMG:
    if (s == S_CGJ)
      st = fcm_jacobi_create(ctx, p->A, FCM_JACOBI_SCALAR, &J);
    else if (s == S_MINRES)
      st = schwarz_build(ctx, p, &S);
    else
      st = fcm_mg_create(ctx, p->space, p->A, &mo, &mg);
    w1 = omp_get_wtime(), c1 = cpu_now();
    if (st == FCM_OK) {
      stage = "solve";
      if (s == S_MINRES)
        st = fcm_minres_solve(ctx, p->n, fcm_csr_operator, p->A, fcm_schwarz_operator, S, p->b, x,
                              &ko, &ki);
      else
        st = fcm_cg_solve(ctx, p->n, fcm_csr_operator, p->A,
                          s == S_CGJ ? fcm_jacobi_operator : fcm_mg_operator,
                          s == S_CGJ ? (void *)J : (void *)mg, p->b, x, &ko, &ki);
      r->iterations = ki.iterations;
      r->factor = ki.iterations > 0 && ki.relative_residual > 0.0
                      ? pow(ki.relative_residual, 1.0 / ki.iterations)
                      : 0.0;
    }
    break;
  case S_MG:
    st = fcm_mg_create(ctx, p->space, p->A, &mo, &mg);
    w1 = omp_get_wtime(), c1 = cpu_now();
    if (st == FCM_OK) {
      stage = "solve";
      st = fcm_mg_solve(mg, p->b, x, o->rtol, o->max_iterations, &mi);
      r->iterations = mi.cycles;
      r->factor = mi.convergence_factor;
    }
    break;
  default:
    break;
  }
  const double w2 = omp_get_wtime(), c2 = cpu_now();
  if (mg) r->levels = fcm_mg_num_levels(mg);
  r->peak_mb = r->base_mb >= 0.0 ? rss_peak() : -1.0;
  r->setup_s = w1 - w0, r->solve_s = w2 - w1;
  r->setup_cpu = c1 - c0, r->solve_cpu = c2 - c1;
  if (st == FCM_OK || st == FCM_ERR_NOT_CONVERGED) /* the true residual, computed here */
    (void)relative_residual(p, x, r);
  if (st == FCM_ERR_UNSUPPORTED && (s == S_CGMG || s == S_MG) && !strcmp(stage, "setup")) {
    r->status = ROW_SKIPPED;
    char msg[400];
    snprintf(msg, sizeof msg, "multigrid does not support this space: %s",
             fcm_ctx_error_message(ctx));
    set_note(r, msg);
  } else if (st != FCM_OK) {
    r->status = ROW_FAILED;
    char msg[400];
    snprintf(msg, sizeof msg, "%s: %s", stage, fcm_ctx_error_message(ctx));
    set_note(r, msg);
  } else if (xref) {
    compare(o, p->n, x, xref, "cholmod", r);
  }
  fcm_direct_destroy(&d);
  fcm_jacobi_destroy(&J);
  fcm_schwarz_destroy(&S);
  fcm_mg_destroy(&mg);
}

/* ------------------------------------------------------------- estimates and fits */

/* Least-squares slope of log y against log x over m points; NAN with fewer than 2 distinct x. */
static double fit_slope(int m, const double *x, const double *y)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int k = 0;
  for (int i = 0; i < m; i++) {
    if (!(x[i] > 0.0 && y[i] > 0.0)) continue;
    const double lx = log(x[i]), ly = log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, k++;
  }
  const double den = k * sxx - sx * sx;
  if (k < 2 || !(den > 1e-12)) return NAN;
  return (k * sxy - sx * sy) / den;
}

double scaling_row_time(const row *r, int clock, int solve_only)
{
  if (clock == CLOCK_CPU) return solve_only ? r->solve_cpu : r->setup_cpu + r->solve_cpu;
  return solve_only ? r->solve_s : r->setup_s + r->solve_s;
}

/* The rows of one series (element, body, solver) that ran, in order of size. */
int scaling_series(const table *tb, fcm_element_type type, int body, int s, const row **out,
                   int cap)
{
  int m = 0;
  for (int i = 0; i < tb->nrows && m < cap; i++)
    if (tb->rows[i].type == type && tb->rows[i].body == body && tb->rows[i].solver == s &&
        tb->rows[i].status == ROW_OK)
      out[m++] = &tb->rows[i];
  return m;
}

double scaling_series_exponent(const table *tb, fcm_element_type type, int body, int s, int clock,
                               int solve_only)
{
  const row *sr[64];
  double x[64], y[64];
  const int m = scaling_series(tb, type, body, s, sr, 64);
  for (int i = 0; i < m; i++)
    x[i] = (double)sr[i]->dofs, y[i] = scaling_row_time(sr[i], clock, solve_only);
  return fit_slope(m, x, y);
}

/* Seconds of a row for the estimates: the smaller of wall and CPU time (on a loaded machine
 * the wall clock grows with the other load, while the CPU time of a single-threaded phase
 * is what it costs on an idle core). */
static double est_time(const row *r)
{
  return fmin(r->setup_s + r->solve_s, r->setup_cpu + r->solve_cpu);
}

/* Estimated wall seconds and extra MB of solver s at `dofs` from its measured rows of the
 * series (the last size scaled by the DOF ratio; the exponent fitted over the last two sizes
 * when both exist, else the default); 0 when nothing is measured yet. */
static void estimate(const table *tb, fcm_element_type type, int body, int s, fcm_index dofs,
                     double *t, double *mb)
{
  const row *sr[64];
  const int m = scaling_series(tb, type, body, s, sr, 64);
  *t = 0.0, *mb = 0.0;
  if (m == 0) return;
  const row *a = sr[m - 1];
  double te = default_time_exp[s], me = default_mem_exp[s];
  if (m >= 2 && sr[m - 2]->dofs < a->dofs) {
    const row *z = sr[m - 2];
    const double lr = log((double)a->dofs / (double)z->dofs);
    const double ta = est_time(a), tz = est_time(z);
    const double ma = a->peak_mb - a->base_mb, mz = z->peak_mb - z->base_mb;
    if (ta > 0.05 && tz > 0.05) te = fmin(fmax(log(ta / tz) / lr, 1.0), 3.0);
    if (ma > 20.0 && mz > 20.0) me = fmin(fmax(log(ma / mz) / lr, 1.0), 2.0);
  }
  const double ratio = (double)dofs / (double)a->dofs;
  *t = est_time(a) * pow(ratio, te);
  *mb = a->peak_mb >= 0.0 ? (a->peak_mb - a->base_mb) * pow(ratio, me) : 0.0;
}

/* ------------------------------------------------------------- rows out */

static int add_skip(const settings *o, table *tb, fcm_element_type t, int body, fcm_index n,
                    fcm_index dofs, int s, const char *why)
{
  if (tb->nrows >= MAX_ROWS) return 1;
  row *r = &tb->rows[tb->nrows++];
  memset(r, 0, sizeof *r);
  r->type = t, r->body = body, r->n = n, r->dofs = dofs, r->solver = s;
  r->status = ROW_SKIPPED;
  r->factor = r->relres = r->diff = r->peak_mb = r->base_mb = -1.0;
  r->processes = IS_PETSC(s) ? o->size : 1;
  set_note(r, why);
  fprintf(stderr, PROG ": %s %s n=%lld %s skipped: %s\n", fcm_element_get_info(t)->name,
          body_names[body], (long long)n, solver_names[s], r->note);
  scaling_print_row(r);
  return scaling_write_csv(o, tb);
}

/* scaling_print_row() and the CSV so far; 0 when the CSV cannot be written. */
static int emit(const settings *o, table *tb, const row *r)
{
  scaling_print_row(r);
  return scaling_write_csv(o, tb);
}

/* ------------------------------------------------------------- the PETSc rows */

/* Every process waits here for the others (process 0 comes last, after its serial solvers),
 * sleeping between polls: a blocking MPI wait spins, and the spinning processes would take
 * the cores of the serial solvers being timed. Then process 0's `*fatal` reaches every one. */
static void sync_processes(const settings *o, int *fatal)
{
#if FCM_HAVE_PETSC
  if (o->size <= 1) return;
  MPI_Request req;
  int done = 0;
  MPI_Ibarrier(MPI_COMM_WORLD, &req);
  while (MPI_Test(&req, &done, MPI_STATUS_IGNORE) == MPI_SUCCESS && !done) {
    const struct timespec ts = {0, 2000000};
    nanosleep(&ts, NULL);
  }
  MPI_Bcast(fatal, 1, MPI_INT, 0, MPI_COMM_WORLD);
#else
  (void)o;
  (void)fatal;
#endif
}

#if FCM_HAVE_PETSC
/* The PETSc solvers' options strings (the command line's PETSc options override them: the
 * backend reads the command line after them). CG stops on the true residual ||b - A x||_2, as
 * the serial solvers do. */
static const char *petsc_solver_options(int s)
{
  return s == S_PGAMG ? "-ksp_type cg -pc_type gamg -ksp_norm_type unpreconditioned"
         : s == S_PMG ? "-ksp_type cg -pc_type mg -ksp_norm_type unpreconditioned"
                      : "-ksp_type preonly -pc_type cholesky -pc_factor_mat_solver_type mumps";
}

/* One PETSc row (collective: every process calls it with the same arguments but p and xref,
 * which only process 0 has: the serial problem (NULL when it was not built) and the reference
 * solution (NULL: none)). The same problem as problem_build() through the PETSc adapter: mesh
 * and geometry on every process, fcm_petsc_problem_create() (static; partition, rules of the
 * own cells, space, DOF numbering), gravity, every copy of every node with y <= -0.5 clamped,
 * setup (assembly, elimination, KSP), one step (the solve; GAMG's set-up or MUMPS's
 * factorization included). Times: process 0's wall clock, CPU summed over the processes; RSS
 * peak and base summed. The row is filled on process 0. */
static void run_petsc(fcm_ctx *ctx, const settings *o, fcm_element_type type, int body, fcm_index n,
                      int s, const problem *p, const double *xref, row *r)
{
  fcm_status st = FCM_OK;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_petsc_problem *P = NULL;
  fcm_index *nodes = NULL;
  double *u = NULL;
  const char *stage = "problem";
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c[3] = {0, 0, 0};
  const fcm_index cells[3] = {n, n, n};
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e5, 0.3, 1000.0};
  const double g[3] = {0.0, -9.81, 0.0};
  fcm_petsc_step_info si;
  fcm_petsc_info info;
  memset(&si, 0, sizeof si);
  memset(&info, 0, sizeof info);
  r->processes = o->size;
  MPI_Barrier(MPI_COMM_WORLD);
  double base = scaling_rss_reset();
  const double w0 = omp_get_wtime(), c0 = cpu_now();
  double w1 = w0, c1 = c0;
  TRY(fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  if (body == B_HOLLOW)
    TRY(fcm_geometry_create_hollow_ball(ctx, c, 0.5, 0.9, 0.25, 16, 3, &geom));
  else
    TRY(fcm_geometry_create_ball(ctx, c, 0.9, 6, &geom));
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_STATIC;
  po.solver.rtol = o->rtol;
  po.solver.max_iterations = o->max_iterations;
  po.solver.petsc_options = petsc_solver_options(s);
  TRY(fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P));
  {
    const double blo[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, bhi[3] = {HUGE_VAL, -0.5, HUGE_VAL};
    fcm_index cnt = 0;
    TRY(fcm_mesh_nodes_in_box(ctx, mesh, blo, bhi, 1e-9, 0, NULL, &cnt));
    nodes = malloc(sizeof *nodes * ((size_t)cnt + 1));
    if (!nodes) {
      st = FCM_ERR_ALLOC;
      goto done;
    }
    TRY(fcm_mesh_nodes_in_box(ctx, mesh, blo, bhi, 1e-9, cnt, nodes, &cnt));
    const fcm_motion clamp = fcm_motion_default();
    TRY(fcm_petsc_problem_add_gravity(P, g));
    TRY(fcm_petsc_problem_add_constraint(P, cnt, nodes, &clamp));
  }
  stage = "setup";
  TRY(fcm_petsc_problem_setup(P));
  w1 = omp_get_wtime(), c1 = cpu_now();
  stage = "solve";
  st = fcm_petsc_problem_step(P, &si);
  const double w2 = omp_get_wtime(), c2 = cpu_now();
  double peak = base >= 0.0 ? rss_peak() : -1.0;
  r->setup_s = w1 - w0, r->solve_s = w2 - w1;
  double cpu[2] = {c1 - c0, c2 - c1}, mem[2] = {peak, base}, sum[2];
  int known = peak >= 0.0, all_known = 0;
  MPI_Allreduce(cpu, sum, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  r->setup_cpu = sum[0], r->solve_cpu = sum[1];
  MPI_Allreduce(mem, sum, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&known, &all_known, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  r->peak_mb = all_known ? sum[0] : -1.0, r->base_mb = all_known ? sum[1] : -1.0;
  r->iterations = si.iterations;
  if (st != FCM_OK) goto done;
  stage = "result";
  TRY(fcm_petsc_problem_get_info(P, &info));
  r->dofs = info.num_dofs;
  u = malloc(sizeof *u * ((size_t)info.num_dofs + 1));
  const int have_u = u != NULL;
  int all_u = 0;
  MPI_Allreduce(&have_u, &all_u, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (!all_u) {
    st = FCM_ERR_ALLOC;
    goto done;
  }
  TRY(fcm_petsc_problem_get_state(P, u, NULL));
  {
    char what[160];
    snprintf(what, sizeof what, "%s + %s%s%s%s", info.ksp_type, info.pc_type,
             info.factor_package[0] ? " (" : "", info.factor_package,
             info.factor_package[0] ? ")" : "");
    set_note(r, what);
  }
done:
  if (o->rank == 0 && st != FCM_OK) {
    r->status = ROW_FAILED;
    char msg[400];
    snprintf(msg, sizeof msg, "%s: %s", stage, fcm_ctx_error_message(ctx));
    set_note(r, msg);
  } else if (o->rank == 0 && p) {
    if (p->n != r->dofs) {
      r->status = ROW_FAILED;
      char msg[200];
      snprintf(msg, sizeof msg, "%lld dofs but the serial problem has %lld", (long long)r->dofs,
               (long long)p->n);
      set_note(r, msg);
    } else {
      if (relative_residual(p, u, r))
        r->factor = s == S_PMUMPS                          ? -1.0
                    : r->iterations > 0 && r->relres > 0.0 ? pow(r->relres, 1.0 / r->iterations)
                                                           : 0.0;
      if (xref) compare(o, p->n, u, xref, "the serial solution", r);
    }
  }
  free(u);
  free(nodes);
  fcm_petsc_problem_destroy(&P);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
}
#endif

/* ------------------------------------------------------------- the study */

/* What one series (element, body) carries from size to size. */
typedef struct series_state {
  fcm_element_type t;
  int body;
  char skipped[NSOLVER][200];  /* why a solver stopped (it stays skipped at larger sizes) */
  fcm_index last_n, last_dofs; /* the last problem built */
  double last_prob_mb, last_prob_s;
  int failed, fatal;
} series_state;

/* One size of a series: the solvers wanted, the serial problem and the solutions. */
typedef struct size_state {
  fcm_index n;
  int want[NSOLVER], nserial, npetsc;
  problem p;
  int have_p, have_ref, have_mgref; /* built; CHOLMOD's solution, else cg-mg's, in xref */
  double *x, *xref;
} size_state;

/* Every wanted serial solver gets a skipped row saying `why`. */
static void skip_serial(const settings *o, table *tb, series_state *ss, const size_state *sz,
                        const char *const why[NSOLVER])
{
  for (int s = 0; s < NSOLVER; s++)
    if (sz->want[s] && !IS_PETSC(s) && !add_skip(o, tb, ss->t, ss->body, sz->n, 0, s, why[s]))
      ss->fatal = 1;
}

/* 1 when the problem of this size is not built: every serial solver already stopped at a
 * smaller size, or the problem, estimated from the previous size by the cell ratio, would
 * exceed the memory or the time budget (the rows say so). */
static int problem_skipped(const settings *o, table *tb, series_state *ss, const size_state *sz)
{
  const char *why[NSOLVER];
  int all_skipped = 1;
  for (int s = 0; s < NSOLVER; s++) {
    why[s] = ss->skipped[s];
    if (sz->want[s] && !IS_PETSC(s) && !ss->skipped[s][0]) all_skipped = 0;
  }
  if (all_skipped) {
    skip_serial(o, tb, ss, sz, why);
    return 1;
  }
  const double avail = mem_available();
  if (ss->last_n <= 0) return 0;
  const double ratio = pow((double)sz->n / (double)ss->last_n, 3.0);
  const double est_mb = ss->last_prob_mb * ratio, est_s = ss->last_prob_s * ratio;
  const fcm_index est_dofs = (fcm_index)((double)ss->last_dofs * ratio);
  char reason[200];
  reason[0] = 0;
  if (avail > 0.0 && est_mb > o->mem_fraction * avail)
    snprintf(reason, sizeof reason,
             "the problem would need about %.0f MB (%.0f MB available); about %lld dofs", est_mb,
             avail, (long long)est_dofs);
  else if (est_s > o->budget)
    snprintf(reason, sizeof reason,
             "building the problem would take about %.0f s > --budget %.0f s; about %lld dofs",
             est_s, o->budget, (long long)est_dofs);
  if (!reason[0]) return 0;
  for (int s = 0; s < NSOLVER; s++)
    why[s] = reason;
  skip_serial(o, tb, ss, sz, why);
  return 1;
}

/* Build the serial problem of this size (timed, its memory measured for the next estimate);
 * 1 on success, else failed rows for the serial solvers. */
static int build_size(fcm_ctx *ctx, const settings *o, table *tb, series_state *ss, size_state *sz)
{
  const char *en = fcm_element_get_info(ss->t)->name;
  fprintf(stderr, PROG ": %s %s n=%lld: building the problem\n", en, body_names[ss->body],
          (long long)sz->n);
  const double base = scaling_rss_reset();
  const double w0 = omp_get_wtime();
  fcm_status st = problem_build(ctx, o, ss->t, ss->body, sz->n, &sz->p);
  const double build_s = omp_get_wtime() - w0;
  if (st != FCM_OK) {
    fprintf(stderr, PROG ": %s %s n=%lld: building the problem failed: %s\n", en,
            body_names[ss->body], (long long)sz->n, fcm_ctx_error_message(ctx));
    for (int s = 0; s < NSOLVER; s++)
      if (sz->want[s] && !IS_PETSC(s) && tb->nrows < MAX_ROWS) {
        row *r = &tb->rows[tb->nrows++];
        memset(r, 0, sizeof *r);
        r->type = ss->t, r->body = ss->body, r->n = sz->n, r->solver = s, r->status = ROW_FAILED;
        r->factor = r->relres = r->diff = r->peak_mb = r->base_mb = -1.0;
        r->processes = 1;
        char msg[400];
        snprintf(msg, sizeof msg, "problem: %s", fcm_ctx_error_message(ctx));
        set_note(r, msg);
        if (!emit(o, tb, r)) ss->fatal = 1;
      }
    ss->failed = 1;
    return 0;
  }
  sz->have_p = 1;
  const double peak = base >= 0.0 ? rss_peak() : -1.0;
  ss->last_prob_mb = peak >= 0.0 ? fmax(peak - base, 1.0) : 0.0;
  ss->last_prob_s = build_s, ss->last_n = sz->n, ss->last_dofs = sz->p.n;
  fprintf(stderr, PROG ": %s %s n=%lld: %lld dofs, built in %.1f s (%.0f MB)\n", en,
          body_names[ss->body], (long long)sz->n, (long long)sz->p.n, build_s, ss->last_prob_mb);
  return 1;
}

/* The serial solvers of one size on process 0, each skipped when its estimate from the
 * smaller sizes exceeds the memory or the time budget. */
static void serial_size(fcm_ctx *ctx, const settings *o, table *tb, series_state *ss,
                        size_state *sz)
{
  const fcm_index n = sz->n;
  const problem *p = &sz->p;
  if (problem_skipped(o, tb, ss, sz) || !build_size(ctx, o, tb, ss, sz)) return;
  sz->x = malloc(sizeof *sz->x * ((size_t)p->n + 1));
  sz->xref = malloc(sizeof *sz->xref * ((size_t)p->n + 1));
  if (!sz->x || !sz->xref) {
    fprintf(stderr, PROG ": out of memory for the solution vectors\n");
    ss->fatal = 1;
    return;
  }
  for (int si = 0; si < o->nsolvers && !ss->fatal; si++) {
    const int s = o->solvers[si];
    if (!sz->want[s] || IS_PETSC(s)) continue;
    if (ss->skipped[s][0]) {
      if (!add_skip(o, tb, ss->t, ss->body, n, p->n, s, ss->skipped[s])) ss->failed = 1;
      continue;
    }
    double est_s = 0.0, est_mb = 0.0;
    estimate(tb, ss->t, ss->body, s, p->n, &est_s, &est_mb);
    const double now_avail = mem_available();
    char why[200];
    why[0] = 0;
    if (now_avail > 0.0 && est_mb > o->mem_fraction * now_avail)
      snprintf(why, sizeof why, "would need about %.0f MB more (%.0f MB available)", est_mb,
               now_avail);
    else if (est_s > o->budget)
      snprintf(why, sizeof why, "would take about %.0f s > --budget %.0f s", est_s, o->budget);
    if (why[0]) {
      char w2[200];
      snprintf(w2, sizeof w2, "n=%lld %s", (long long)n, why);
      snprintf(ss->skipped[s], sizeof ss->skipped[s], "%.150s (and larger)", w2);
      if (!add_skip(o, tb, ss->t, ss->body, n, p->n, s, why)) ss->failed = 1;
      continue;
    }
    if (tb->nrows >= MAX_ROWS) break;
    row *r = &tb->rows[tb->nrows++];
    memset(r, 0, sizeof *r);
    r->type = ss->t, r->body = ss->body, r->n = n, r->dofs = p->n, r->solver = s;
    r->factor = r->relres = r->diff = -1.0;
    r->processes = 1;
    fprintf(stderr, PROG ": %s %s n=%lld %s ...\n", fcm_element_get_info(ss->t)->name,
            body_names[ss->body], (long long)n, solver_names[s]);
    run_solver(ctx, o, p, s, s == S_CHOLMOD ? sz->xref : sz->x, sz->have_ref ? sz->xref : NULL, r);
    if (s == S_CHOLMOD && r->status == ROW_OK) sz->have_ref = 1;
    /* the PETSc rows' reference when CHOLMOD's is missing: cg-mg's solution */
    if (s == S_CGMG && r->status == ROW_OK && !sz->have_ref && !sz->have_mgref) {
      memcpy(sz->xref, sz->x, sizeof *sz->x * (size_t)p->n);
      sz->have_mgref = 1;
    }
    if (r->status == ROW_FAILED) ss->failed = 1;
    if (r->status == ROW_SKIPPED) snprintf(ss->skipped[s], sizeof ss->skipped[s], "%s", r->note);
    if (!emit(o, tb, r)) ss->fatal = 1;
  }
}

#if FCM_HAVE_PETSC
/* The PETSc solvers of one size on every process: process 0 decides (skips like the serial
 * solvers), every process runs the row. */
static void petsc_size(fcm_ctx *ctx, const settings *o, table *tb, series_state *ss,
                       const size_state *sz)
{
  const int root = o->rank == 0;
  const fcm_index n = sz->n;
  for (int si = 0; si < o->nsolvers && sz->npetsc && !ss->fatal; si++) {
    const int s = o->solvers[si];
    if (!sz->want[s] || !IS_PETSC(s)) continue;
    int go = 0;
    if (root) {
      const fcm_index dofs = sz->have_p ? sz->p.n : 0;
      double est_s = 0.0, est_mb = 0.0;
      estimate(tb, ss->t, ss->body, s, dofs > 0 ? dofs : ss->last_dofs, &est_s, &est_mb);
      const double now_avail = mem_available();
      char why[200];
      why[0] = 0;
      if (ss->skipped[s][0])
        snprintf(why, sizeof why, "%s", ss->skipped[s]);
      else if (now_avail > 0.0 && est_mb > o->mem_fraction * now_avail)
        snprintf(why, sizeof why, "would need about %.0f MB more (%.0f MB available)", est_mb,
                 now_avail);
      else if (est_s > o->budget)
        snprintf(why, sizeof why, "would take about %.0f s > --budget %.0f s", est_s, o->budget);
      if (why[0] && !ss->skipped[s][0])
        snprintf(ss->skipped[s], sizeof ss->skipped[s], "n=%lld %.150s (and larger)", (long long)n,
                 why);
      if (why[0]) {
        if (!add_skip(o, tb, ss->t, ss->body, n, dofs, s, why)) ss->fatal = 1;
      } else {
        go = tb->nrows < MAX_ROWS;
      }
    }
    MPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!go) continue;
    row scratch, *r = root ? &tb->rows[tb->nrows++] : &scratch;
    memset(r, 0, sizeof *r);
    r->type = ss->t, r->body = ss->body, r->n = n, r->solver = s;
    r->factor = r->relres = r->diff = -1.0;
    if (root)
      fprintf(stderr, PROG ": %s %s n=%lld %s on %d processes ...\n",
              fcm_element_get_info(ss->t)->name, body_names[ss->body], (long long)n,
              solver_names[s], o->size);
    run_petsc(ctx, o, ss->t, ss->body, n, s, sz->have_p ? &sz->p : NULL,
              sz->have_ref || sz->have_mgref ? sz->xref : NULL, r);
    if (root) {
      if (r->status == ROW_FAILED) ss->failed = 1;
      if (!emit(o, tb, r)) ss->fatal = 1;
    }
    MPI_Bcast(&ss->fatal, 1, MPI_INT, 0, MPI_COMM_WORLD);
  }
}
#endif

/* Process 0 runs the serial solvers of one size and decides what runs; the PETSc solvers run
 * on every process (--backend petsc), each other process waiting in sync_processes() while
 * process 0 works alone. */
int scaling_run_study(fcm_ctx *ctx, const settings *o, table *tb)
{
  int failed = 0, fatal = 0;
  printf("%-5s %-6s %3s %9s %-14s %6s %7s %9s %9s %8s %9s %9s\n", "elem", "body", "n", "dofs",
         "solver", "its", "factor", "setup_s", "solve_s", "peak_MB", "relres", "diff");
  for (int ti = 0; ti < o->ntypes && !fatal; ti++)
    for (int bi = 0; bi < o->nbodies && !fatal; bi++) {
      series_state ss;
      memset(&ss, 0, sizeof ss);
      ss.t = o->types[ti], ss.body = o->bodies[bi];
      for (int ni = 0; ni < o->nsizes && !ss.fatal; ni++) {
        size_state sz;
        memset(&sz, 0, sizeof sz);
        sz.n = o->sizes[ni];
        for (int si = 0; si < o->nsolvers; si++) {
          const int s = o->solvers[si];
          if ((ss.body == B_CUBE || ss.body == B_CUT) && s != S_MG) continue;
          sz.want[s] = 1;
          if (IS_PETSC(s))
            sz.npetsc++;
          else
            sz.nserial++;
        }
        if (!sz.nserial && !sz.npetsc) continue;
        if (o->rank == 0 && sz.nserial) serial_size(ctx, o, tb, &ss, &sz);
        sync_processes(o, &ss.fatal);
#if FCM_HAVE_PETSC
        petsc_size(ctx, o, tb, &ss, &sz);
#endif
        free(sz.x);
        free(sz.xref);
        if (sz.have_p) problem_free(&sz.p);
      }
      failed |= ss.failed;
      fatal |= ss.fatal;
    }
  return failed || fatal;
}
