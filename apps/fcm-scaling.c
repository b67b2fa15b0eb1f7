/* fcm-scaling: how the cost of one static solve grows with the number of DOFs (issue 13).
 *
 * Static linear elasticity (E = 1e5, nu = 0.3, rho = 1000, gravity 9.81 along -y) of an
 * embedded body in the box [-1, 1]^3 of n^3 Hex8 or Hex20 cells, built the library's normal
 * way: fcm_cell_rules_create() (default options, stiffness rules only: a static problem),
 * fcm_space_create_embedded(), fcm_assemble_stiffness() / fcm_assemble_body_force(),
 * fcm_space_apply_dirichlet(). Bodies:
 *   ball    the ball |x| <= 0.9;
 *   hollow  the hollow ball 0.5 <= |x| <= 0.9 with three holes of radius 0.25 along the axes
 *           (fcm_geometry_create_hollow_ball());
 *   cube    the whole box, uncut (fcm_space_create()), clamped on its face y = -1;
 *   cut     the ball with an XFEM plane cut x = 0.05 through its upper half y >= 0
 *           (fcm_cell_rules_create_cut(), fcm_surface_create_plane()): two half-domes joined
 *           below y = 0.
 * The embedded bodies are set in a rigid base: every copy of every background node with
 * y <= -0.5 is clamped (the part of the body below that plane is held; y = -0.5 is a grid
 * plane when n is a multiple of 4).
 * Solvers, each to the same relative residual ||b - A x||_2 <= rtol ||b||_2 (MINRES: in its
 * preconditioned norm, see --help): cholmod (fcm_direct), cg-jacobi, minres-schwarz (the
 * Schwarz preconditioner of the simulations: one block per cut cell of volume fraction
 * below 0.5, fcm_space_cell_blocks() + fcm_schwarz_create()), cg-mg (fcm_cg_solve() with
 * fcm_mg_operator()) and mg (fcm_mg_solve()), with the library's multigrid defaults (W-cycle).
 * The bodies cube and cut run mg only, with V-cycles: their rows give the V-cycle convergence
 * factor (Dick et al. 2011, Fig. 10).
 * --backend petsc (issue 14; a build with PETSc, under mpirun -n P): the same problems of the
 * bodies ball and hollow also through the PETSc adapter (fcm/petsc.h, the linear static
 * driver: partition, rules of the own cells, MATMPIAIJ assembly, KSP) on every process, solved
 * by petsc-gamg (CG + GAMG with the rigid-body near-null space, stopping on the true residual)
 * petsc-mumps (MUMPS Cholesky) and petsc-mg (CG + fcm's multigrid hierarchy as PETSc's PCMG,
 * lib/src/petsc/pcmg.c); process 0 also runs the serial solvers (the others wait
 * sleeping) and compares the PETSc solution with CHOLMOD's (else cg-mg's); it alone prints
 * and writes.
 * Writes CSV (--csv FILE, atomically) and a plot (--png FILE, gnuplot), prints the fitted
 * exponents of time against DOFs and the claims of issue 13; exit 0 when every row ran or was
 * skipped (and, with --check, every claim holds), 1 when a computation failed or a solution
 * disagreed with CHOLMOD's (or a claim failed under --check), 2 on a usage error. */
#define _GNU_SOURCE
#include "app_env.h"
#include "cli.h"

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

#define PROG "fcm-scaling"

/* S_PGAMG, S_PMUMPS, S_PMG: the PETSc backend (--backend petsc, fcm/petsc.h), on every MPI process
 */
enum { S_CHOLMOD, S_CGJ, S_MINRES, S_CGMG, S_MG, S_PGAMG, S_PMUMPS, S_PMG, NSOLVER };
static const char *const solver_names[] = {"cholmod",     "cg-jacobi", "minres-schwarz",
                                           "cg-mg",       "mg",        "petsc-gamg",
                                           "petsc-mumps", "petsc-mg",  NULL};
#define IS_PETSC(s) ((s) == S_PGAMG || (s) == S_PMUMPS || (s) == S_PMG)
enum { BACKEND_SERIAL, BACKEND_PETSC };
static const char *const backend_names[] = {"serial", "petsc", NULL};
enum { B_BALL, B_HOLLOW, B_CUBE, B_CUT, NBODY };
static const char *const body_names[] = {"ball", "hollow", "cube", "cut", NULL};
enum { CLOCK_WALL, CLOCK_CPU };
static const char *const clock_names[] = {"wall", "cpu", NULL};

/* Exponents the estimates use before two sizes of a solver are measured: time ~ dofs^t,
 * extra memory ~ dofs^m (CHOLMOD: ~N^2 flops and ~N^(4/3) fill for 3D nested dissection). */
static const double default_time_exp[NSOLVER] = {2.0, 1.4, 1.4, 1.15, 1.15, 1.15, 2.0, 1.15};
static const double default_mem_exp[NSOLVER] = {1.4, 1.0, 1.0, 1.0, 1.0, 1.0, 1.4, 1.0};

enum { ROW_OK, ROW_SKIPPED, ROW_FAILED };
static const char *const status_names[] = {"ok", "skipped", "failed"};

typedef struct row {
  fcm_element_type type;
  int body, solver, status;
  fcm_index n, dofs;
  int iterations, levels;      /* levels: of the multigrid hierarchy (cg-mg, mg), else 0 */
  double factor;               /* mean reduction per iteration / cycle; < 0: none (cholmod) */
  double setup_s, solve_s;     /* wall clock */
  double setup_cpu, solve_cpu; /* process CPU seconds (all threads) */
  double peak_mb, base_mb;     /* VmHWM over setup + solve; VmRSS before it; < 0 unknown */
  double relres, diff; /* ||b - Ax|| / ||b||; ||x - x_cholmod|| / ||x_cholmod|| (< 0: none) */
  int processes;       /* MPI processes of the row (serial solvers: 1) */
  char note[200];
} row;

#define MAX_ROWS 2048
static row rows[MAX_ROWS];
static int nrows = 0;

typedef struct settings {
  int quick, check, threads, max_iterations, clock;
  long long coarse_dofs;  /* fcm_mg_options.coarse_dofs */
  double constrain_ratio; /* fcm_space_options.constrain_ratio */
  double rtol, agree, budget, mem_fraction;
  fcm_index sizes[16];
  int nsizes;
  fcm_element_type types[FCM_ELEMENT_COUNT];
  int ntypes;
  int bodies[NBODY], nbodies;
  int solvers[NSOLVER], nsolvers;
  const char *csv, *png;
  int backend;    /* BACKEND_SERIAL or BACKEND_PETSC */
  int rank, size; /* MPI (petsc backend; else 0 and 1): process 0 prints and writes */
} settings;

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
static double rss_reset(void)
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
  r->base_mb = rss_reset();
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
  if (st == FCM_OK || st == FCM_ERR_NOT_CONVERGED) { /* the true residual, computed here */
    double *ax = malloc(sizeof *ax * ((size_t)p->n + 1));
    if (ax && fcm_csr_apply(p->A, 1.0, x, 0.0, ax) == FCM_OK) {
      for (fcm_index i = 0; i < p->n; i++)
        ax[i] = p->b[i] - ax[i];
      const double bn = norm2(p->n, p->b);
      r->relres = bn > 0.0 ? norm2(p->n, ax) / bn : 0.0;
    }
    free(ax);
  }
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
    double dn = 0.0;
    for (fcm_index i = 0; i < p->n; i++)
      dn += (x[i] - xref[i]) * (x[i] - xref[i]);
    const double xn = norm2(p->n, xref);
    r->diff = xn > 0.0 ? sqrt(dn) / xn : sqrt(dn);
    if (!(r->diff <= o->agree)) {
      r->status = ROW_FAILED;
      char msg[200];
      snprintf(msg, sizeof msg, "differs from cholmod by %.3e > --agree %.1e", r->diff, o->agree);
      set_note(r, msg);
    }
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

static double row_time(const row *r, int clock, int solve_only)
{
  if (clock == CLOCK_CPU) return solve_only ? r->solve_cpu : r->setup_cpu + r->solve_cpu;
  return solve_only ? r->solve_s : r->setup_s + r->solve_s;
}

/* The rows of one series (element, body, solver) that ran, in order of size. */
static int series(fcm_element_type type, int body, int s, const row **out, int cap)
{
  int m = 0;
  for (int i = 0; i < nrows && m < cap; i++)
    if (rows[i].type == type && rows[i].body == body && rows[i].solver == s &&
        rows[i].status == ROW_OK)
      out[m++] = &rows[i];
  return m;
}

static double series_exponent(fcm_element_type type, int body, int s, int clock, int solve_only)
{
  const row *sr[64];
  double x[64], y[64];
  const int m = series(type, body, s, sr, 64);
  for (int i = 0; i < m; i++)
    x[i] = (double)sr[i]->dofs, y[i] = row_time(sr[i], clock, solve_only);
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
static void estimate(fcm_element_type type, int body, int s, fcm_index dofs, double *t, double *mb)
{
  const row *sr[64];
  const int m = series(type, body, s, sr, 64);
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

/* ------------------------------------------------------------- output */

/* ",v" with `digits` decimals (scientific when sci), or "," alone for a negative v. */
static void csv_field_num(FILE *f, double v, int digits, int sci)
{
  fputc(',', f);
  if (v >= 0.0 && isfinite(v)) fprintf(f, sci ? "%.*e" : "%.*f", digits, v);
}

static void write_row(FILE *f, const row *r)
{
  fprintf(f, "%s,%lld,", fcm_element_get_info(r->type)->name, (long long)r->n);
  if (r->dofs > 0) fprintf(f, "%lld", (long long)r->dofs);
  fprintf(f, ",%s,", solver_names[r->solver]);
  const int ran = r->status != ROW_SKIPPED;
  if (ran && r->iterations > 0) fprintf(f, "%d", r->iterations);
  csv_field_num(f, ran && r->solver != S_CHOLMOD ? r->factor : -1.0, 4, 0);
  csv_field_num(f, ran ? r->setup_s : -1.0, 4, 0);
  csv_field_num(f, ran ? r->solve_s : -1.0, 4, 0);
  csv_field_num(f, ran ? r->peak_mb : -1.0, 1, 0);
  fprintf(f, ",%s,%s", body_names[r->body], status_names[r->status]);
  csv_field_num(f, ran ? r->relres : -1.0, 3, 1);
  csv_field_num(f, ran ? r->diff : -1.0, 3, 1);
  csv_field_num(f, ran ? r->setup_cpu : -1.0, 4, 0);
  csv_field_num(f, ran ? r->solve_cpu : -1.0, 4, 0);
  csv_field_num(f, ran ? r->base_mb : -1.0, 1, 0);
  fputc(',', f);
  if (ran && r->levels > 0) fprintf(f, "%d", r->levels);
  fprintf(f, ",%d,%s\n", r->processes > 0 ? r->processes : 1, r->note);
}

static const char csv_header[] =
    "element,cells,dofs,solver,iterations,convergence_factor,setup_s,solve_s,peak_rss_mb,"
    "body,status,relative_residual,diff_cholmod,setup_cpu_s,solve_cpu_s,base_rss_mb,levels,"
    "processes,note\n";

static void print_row(const row *r)
{
  if (r->status == ROW_SKIPPED) {
    printf("%-5s %-6s %3lld %9lld %-14s skipped: %s\n", fcm_element_get_info(r->type)->name,
           body_names[r->body], (long long)r->n, (long long)r->dofs, solver_names[r->solver],
           r->note);
  } else {
    printf("%-5s %-6s %3lld %9lld %-14s %6d %7.4f %9.3f %9.3f %8.1f %9.2e %9.2e %s%s\n",
           fcm_element_get_info(r->type)->name, body_names[r->body], (long long)r->n,
           (long long)r->dofs, solver_names[r->solver], r->iterations,
           r->factor >= 0 ? r->factor : 0.0, r->setup_s, r->solve_s, r->peak_mb, r->relres,
           r->diff >= 0 ? r->diff : 0.0, r->status == ROW_FAILED ? "FAILED: " : "", r->note);
  }
  fflush(stdout);
}

/* Two panels: setup + solve time against DOFs (log-log, the fitted exponents in the legend) and
 * iterations against DOFs, one line per (element, body, solver) of the bodies ball and
 * hollow. The data go inline into the script. */
static int write_png(const settings *o)
{
  size_t cap = 1 << 16, len = 0;
  char *body = malloc(cap);
  if (!body) return 0;
  int ok = 1;
#define ADD(...)                                                                                   \
  do {                                                                                             \
    int k_ = snprintf(body + len, cap - len, __VA_ARGS__);                                         \
    if (k_ < 0 || (size_t)k_ >= cap - len) {                                                       \
      ok = 0;                                                                                      \
      goto out;                                                                                    \
    }                                                                                              \
    len += (size_t)k_;                                                                             \
  } while (0)
  const char *colors[NSOLVER] = {"#000000", "#1f77b4", "#2ca02c", "#d62728",
                                 "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"};
  for (int panel = 0; panel < 2; panel++) {
    if (panel == 0)
      ADD("set multiplot layout 1,2\nset logscale xy\nset xlabel 'DOFs'\nset ylabel '%s seconds, "
          "setup + solve'\nset key top left font ',8'\nset grid\nset title 'fcm-scaling: time to "
          "the solution (legend: fitted exponents of setup+solve / solve alone)'\n",
          o->clock == CLOCK_CPU ? "CPU" : "wall");
    else
      ADD("set logscale xy\nset ylabel 'iterations (cycles)'\nset title "
          "'iterations to rtol %.0e'\nset key top left font ',8'\n",
          o->rtol);
    int first = 1;
    for (int ti = 0; ti < o->ntypes; ti++)
      for (int bi = 0; bi < o->nbodies; bi++) {
        const int b = o->bodies[bi];
        if (b != B_BALL && b != B_HOLLOW) continue;
        for (int si = 0; si < o->nsolvers; si++) {
          const int s = o->solvers[si];
          const row *sr[64];
          const int m = series(o->types[ti], b, s, sr, 64);
          if (m == 0 || (panel == 1 && s == S_CHOLMOD)) continue;
          const double e = series_exponent(o->types[ti], b, s, o->clock, 0);
          const double e1 = series_exponent(o->types[ti], b, s, o->clock, 1);
          char expo[40] = "";
          if (panel == 0 && isfinite(e)) snprintf(expo, sizeof expo, " (%.2f / %.2f)", e, e1);
          ADD("%s '-' using 1:2 with linespoints lc rgb '%s' pt %d dt %d title '%s %s %s%s'",
              first ? "plot" : ",", colors[s], 4 + 2 * bi, 1 + ti,
              fcm_element_get_info(o->types[ti])->name, body_names[b], solver_names[s], expo);
          first = 0;
        }
      }
    if (first) {
      ADD("plot 1 title 'no data'\n");
      continue;
    }
    ADD("\n");
    for (int ti = 0; ti < o->ntypes; ti++)
      for (int bi = 0; bi < o->nbodies; bi++) {
        const int b = o->bodies[bi];
        if (b != B_BALL && b != B_HOLLOW) continue;
        for (int si = 0; si < o->nsolvers; si++) {
          const int s = o->solvers[si];
          const row *sr[64];
          const int m = series(o->types[ti], b, s, sr, 64);
          if (m == 0 || (panel == 1 && s == S_CHOLMOD)) continue;
          for (int i = 0; i < m; i++)
            ADD("%lld %.6g\n", (long long)sr[i]->dofs,
                panel == 0 ? fmax(row_time(sr[i], o->clock, 0), 1e-4) : (double)sr[i]->iterations);
          ADD("e\n");
        }
      }
  }
  ADD("unset multiplot\n");
#undef ADD
  ok = cli_gnuplot_png(PROG, "1400,650 font ',10'", o->png, body);
out:
  if (!ok) fprintf(stderr, PROG ": --png: the plot script grew too large\n");
  free(body);
  return ok;
}

/* ------------------------------------------------------------- summary and claims */

static int claim(const char *what, int holds, int measured)
{
  printf("  %-74s %s\n", what, !measured ? "NOT MEASURED" : holds ? "holds" : "FAILS");
  return measured && holds;
}

/* Prints the exponents, the V-cycle factors and the claims; returns 1 when every claim holds. */
static int summary(const settings *o)
{
  printf("\nfitted exponents of time against DOFs (least squares in log-log over the sizes that "
         "ran; %s clock): setup+solve / solve alone\n",
         clock_names[o->clock]);
  for (int ti = 0; ti < o->ntypes; ti++)
    for (int bi = 0; bi < o->nbodies; bi++) {
      const int b = o->bodies[bi];
      if (b != B_BALL && b != B_HOLLOW) continue;
      printf("  %-5s %-6s", fcm_element_get_info(o->types[ti])->name, body_names[b]);
      for (int si = 0; si < o->nsolvers; si++) {
        const int s = o->solvers[si];
        const double e1 = series_exponent(o->types[ti], b, s, o->clock, 0);
        const double e2 = series_exponent(o->types[ti], b, s, o->clock, 1);
        printf("  %s %.2f / %.2f", solver_names[s], e1, e2);
      }
      printf("\n");
    }
  printf("\nmultigrid convergence factor per cycle (mg rows: V-cycles on cube and cut, W-cycles, "
         "the default, on ball and hollow; Dick et al. 2011 Fig. 10, V: 0.66 uncut, 0.75 cut)\n");
  for (int ti = 0; ti < o->ntypes; ti++)
    for (int b = 0; b < NBODY; b++) {
      const row *sr[64];
      const int m = series(o->types[ti], b, S_MG, sr, 64);
      if (m == 0) continue;
      printf("  %-5s %-6s", fcm_element_get_info(o->types[ti])->name, body_names[b]);
      for (int i = 0; i < m; i++)
        printf("  n=%lld: %.3f (%d levels)", (long long)sr[i]->n, sr[i]->factor, sr[i]->levels);
      printf("\n");
    }
  printf("\nclaims of issue 13 (per element; bodies ball and hollow, the V-factor on cut; times "
         "setup+solve, %s clock)\n",
         clock_names[o->clock]);
  int all = 1;
  for (int ti = 0; ti < o->ntypes; ti++) {
    const fcm_element_type t = o->types[ti];
    const char *en = fcm_element_get_info(t)->name;
    char what[200];
    for (int bi = 0; bi < o->nbodies; bi++) {
      const int b = o->bodies[bi];
      if (b != B_BALL && b != B_HOLLOW) continue;
      const row *mg[64], *ch[64];
      const int m = series(t, b, S_CGMG, mg, 64), mc = series(t, b, S_CHOLMOD, ch, 64);
      int lo = 1 << 30, hi = 0;
      for (int i = 0; i < m; i++)
        lo = mg[i]->iterations < lo ? mg[i]->iterations : lo,
        hi = mg[i]->iterations > hi ? mg[i]->iterations : hi;
      snprintf(what, sizeof what, "%s %s: cg-mg iterations flat within 1.5x (%d..%d, n=%lld..%lld)",
               en, body_names[b], m ? lo : 0, hi, m ? (long long)mg[0]->n : 0LL,
               m ? (long long)mg[m - 1]->n : 0LL);
      all &= claim(what, hi <= 1.5 * lo, m >= 2);
      const double ec = series_exponent(t, b, S_CGMG, o->clock, 0);
      const double eh = series_exponent(t, b, S_CHOLMOD, o->clock, 0);
      snprintf(what, sizeof what, "%s %s: cg-mg time exponent %.2f <= 1.2 and below cholmod's %.2f",
               en, body_names[b], ec, eh);
      all &= claim(what, ec <= 1.2 && ec < eh, isfinite(ec) && isfinite(eh));
      /* the largest size where both ran */
      const row *a = NULL, *c = NULL;
      for (int i = m - 1; i >= 0 && !a; i--)
        for (int j = 0; j < mc; j++)
          if (ch[j]->n == mg[i]->n) a = mg[i], c = ch[j];
      snprintf(what, sizeof what,
               "%s %s: cg-mg faster than cholmod at the largest n both ran (%lld: %.3g vs %.3g s)",
               en, body_names[b], a ? (long long)a->n : 0LL, a ? row_time(a, o->clock, 0) : 0.0,
               c ? row_time(c, o->clock, 0) : 0.0);
      all &= claim(what, a && row_time(a, o->clock, 0) < row_time(c, o->clock, 0), a != NULL);
    }
    for (int bi = 0; bi < o->nbodies; bi++) {
      if (o->bodies[bi] != B_CUT) continue;
      const row *sr[64];
      const int m = series(t, B_CUT, S_MG, sr, 64);
      double worst = 0.0;
      int k = 0;
      for (int i = 0; i < m; i++)
        if (sr[i]->iterations >= 2 && sr[i]->levels >= 2) /* a factor needs 2 cycles */
          worst = fmax(worst, sr[i]->factor), k++;
      snprintf(what, sizeof what,
               "%s cut: V-cycle factor <= 0.8 at every n with 2+ levels (worst %.3f of %d)", en,
               worst, k);
      all &= claim(what, worst <= 0.8, k >= 1);
    }
  }
  return all;
}

/* --backend petsc: the issue-13 summary (printed, not claimed), the PETSc rows' cost per DOF,
 * and their claims: every PETSc row that ran agrees with the serial solution (CHOLMOD's, else
 * cg-mg's) within --agree and reports its iterations. 1 when every claim holds. */
static int summary_petsc(const settings *o)
{
  (void)summary(o);
  printf("(with --backend petsc the claims of issue 13 above are printed, not checked)\n");
  printf("\nPETSc rows on %d process%s (peak - base RSS summed over the processes; CPU seconds "
         "summed; per DOF)\n",
         o->size, o->size == 1 ? "" : "es");
  for (int i = 0; i < nrows; i++) {
    const row *r = &rows[i];
    if (!IS_PETSC(r->solver) || r->status != ROW_OK || r->dofs <= 0) continue;
    const double d = (double)r->dofs;
    printf("  %-5s %-6s n=%-3lld %-12s %9lld dofs: %7.0f bytes/dof, setup %.2e s/dof, solve "
           "%.2e s/dof (wall), %.2e s/dof (CPU); %s\n",
           fcm_element_get_info(r->type)->name, body_names[r->body], (long long)r->n,
           solver_names[r->solver], (long long)r->dofs,
           r->peak_mb >= 0.0 ? (r->peak_mb - r->base_mb) * 1048576.0 / d : 0.0, r->setup_s / d,
           r->solve_s / d, (r->setup_cpu + r->solve_cpu) / d, r->note);
  }
  printf("\nclaims of the PETSc rows (issue 14)\n");
  int all = 1;
  for (int ti = 0; ti < o->ntypes; ti++)
    for (int si = 0; si < o->nsolvers; si++) {
      const int s = o->solvers[si];
      if (!IS_PETSC(s)) continue;
      const fcm_element_type t = o->types[ti];
      int ran = 0, agree = 0, with_ref = 0, its = 0;
      double worst = 0.0;
      for (int i = 0; i < nrows; i++) {
        const row *r = &rows[i];
        if (r->type != t || r->solver != s || r->status == ROW_SKIPPED) continue;
        ran++;
        its += r->iterations >= 1;
        if (r->diff >= 0.0) with_ref++, agree += r->diff <= o->agree, worst = fmax(worst, r->diff);
      }
      char what[200];
      snprintf(what, sizeof what,
               "%s %s: agrees with the serial solution within %.0e (%d of %d rows, worst %.2e)",
               fcm_element_get_info(t)->name, solver_names[s], o->agree, agree, ran, worst);
      all &= claim(what, agree == ran, ran > 0 && with_ref == ran);
      snprintf(what, sizeof what, "%s %s: iterations reported (%d of %d rows)",
               fcm_element_get_info(t)->name, solver_names[s], its, ran);
      all &= claim(what, its == ran, ran > 0);
    }
  return all;
}

/* ------------------------------------------------------------- rows out */

/* The rows so far into --csv (atomically: a temporary renamed over the file); called after
 * every row, so an interrupted run leaves the rows it finished. 1 on success. */
static int write_csv(const settings *o)
{
  if (!o->csv || o->rank != 0) return 1;
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, o->csv, &out);
  if (!f) return 0;
  fputs(csv_header, f);
  for (int i = 0; i < nrows; i++)
    write_row(f, &rows[i]);
  return cli_output_commit(PROG, &out);
}

static int add_skip(const settings *o, fcm_element_type t, int body, fcm_index n, fcm_index dofs,
                    int s, const char *why)
{
  if (nrows >= MAX_ROWS) return 1;
  row *r = &rows[nrows++];
  memset(r, 0, sizeof *r);
  r->type = t, r->body = body, r->n = n, r->dofs = dofs, r->solver = s;
  r->status = ROW_SKIPPED;
  r->factor = r->relres = r->diff = r->peak_mb = r->base_mb = -1.0;
  r->processes = IS_PETSC(s) ? o->size : 1;
  set_note(r, why);
  fprintf(stderr, PROG ": %s %s n=%lld %s skipped: %s\n", fcm_element_get_info(t)->name,
          body_names[body], (long long)n, solver_names[s], r->note);
  print_row(r);
  return write_csv(o);
}

/* print_row() and the CSV so far; 0 when the CSV cannot be written. */
static int emit(const settings *o, const row *r)
{
  print_row(r);
  return write_csv(o);
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
  double base = rss_reset();
  const double w0 = omp_get_wtime(), c0 = cpu_now();
  double w1 = w0, c1 = c0;
  TRY(fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  if (body == B_HOLLOW)
    TRY(fcm_geometry_create_hollow_ball(ctx, c, 0.5, 0.9, 0.25, 16, 3, &geom));
  else
    TRY(fcm_geometry_create_ball(ctx, c, 0.9, 6, &geom));
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_STATIC;
  po.rtol = o->rtol;
  po.max_iterations = o->max_iterations;
  po.petsc_options = petsc_solver_options(s);
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
      double *ax = malloc(sizeof *ax * ((size_t)p->n + 1));
      if (ax && fcm_csr_apply(p->A, 1.0, u, 0.0, ax) == FCM_OK) {
        for (fcm_index i = 0; i < p->n; i++)
          ax[i] = p->b[i] - ax[i];
        const double bn = norm2(p->n, p->b);
        r->relres = bn > 0.0 ? norm2(p->n, ax) / bn : 0.0;
        r->factor = s == S_PMUMPS                          ? -1.0
                    : r->iterations > 0 && r->relres > 0.0 ? pow(r->relres, 1.0 / r->iterations)
                                                           : 0.0;
      }
      free(ax);
      if (xref) {
        double dn = 0.0;
        for (fcm_index i = 0; i < p->n; i++)
          dn += (u[i] - xref[i]) * (u[i] - xref[i]);
        const double xn = norm2(p->n, xref);
        r->diff = xn > 0.0 ? sqrt(dn) / xn : sqrt(dn);
        if (!(r->diff <= o->agree)) {
          r->status = ROW_FAILED;
          char msg[200];
          snprintf(msg, sizeof msg, "differs from the serial solution by %.3e > --agree %.1e",
                   r->diff, o->agree);
          set_note(r, msg);
        }
      }
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

/* Process 0 runs the serial solvers of one size and decides what runs; the PETSc solvers run
 * on every process (--backend petsc), each other process waiting in sync_processes() while
 * process 0 works alone. */
static int run_study(fcm_ctx *ctx, const settings *o)
{
  int failed = 0, fatal = 0;
  const int root = o->rank == 0;
  printf("%-5s %-6s %3s %9s %-14s %6s %7s %9s %9s %8s %9s %9s\n", "elem", "body", "n", "dofs",
         "solver", "its", "factor", "setup_s", "solve_s", "peak_MB", "relres", "diff");
  for (int ti = 0; ti < o->ntypes && !fatal; ti++)
    for (int bi = 0; bi < o->nbodies && !fatal; bi++) {
      const fcm_element_type t = o->types[ti];
      const int body = o->bodies[bi];
      const char *en = fcm_element_get_info(t)->name;
      char skipped[NSOLVER][200];
      memset(skipped, 0, sizeof skipped);
      fcm_index last_n = 0, last_dofs = 0;
      double last_prob_mb = 0.0, last_prob_s = 0.0;
      for (int ni = 0; ni < o->nsizes && !fatal; ni++) {
        const fcm_index n = o->sizes[ni];
        int want[NSOLVER] = {0}, nserial = 0, npetsc = 0;
        for (int si = 0; si < o->nsolvers; si++) {
          const int s = o->solvers[si];
          if ((body == B_CUBE || body == B_CUT) && s != S_MG) continue;
          want[s] = 1;
          if (IS_PETSC(s))
            npetsc++;
          else
            nserial++;
        }
        if (!nserial && !npetsc) continue;
        problem p;
        memset(&p, 0, sizeof p);
        int have_p = 0, have_ref = 0, have_mgref = 0;
        double *x = NULL, *xref = NULL;
        char why[200];
        if (!root || !nserial) goto serial_done;
        int all_skipped = 1; /* every solver already stopped at a smaller size: no problem */
        for (int s = 0; s < NSOLVER; s++)
          if (want[s] && !IS_PETSC(s) && !skipped[s][0]) all_skipped = 0;
        if (all_skipped) {
          for (int s = 0; s < NSOLVER; s++)
            if (want[s] && !IS_PETSC(s) && !add_skip(o, t, body, n, 0, s, skipped[s])) fatal = 1;
          goto serial_done;
        }
        /* the problem itself: estimated from the previous size by the cell ratio */
        const double avail = mem_available();
        if (last_n > 0) {
          const double ratio = pow((double)n / (double)last_n, 3.0);
          const double est_mb = last_prob_mb * ratio, est_s = last_prob_s * ratio;
          const fcm_index est_dofs = (fcm_index)((double)last_dofs * ratio);
          why[0] = 0;
          if (avail > 0.0 && est_mb > o->mem_fraction * avail)
            snprintf(why, sizeof why,
                     "the problem would need about %.0f MB (%.0f MB available); about %lld dofs",
                     est_mb, avail, (long long)est_dofs);
          else if (est_s > o->budget)
            snprintf(why, sizeof why,
                     "building the problem would take about %.0f s > --budget %.0f s; about %lld "
                     "dofs",
                     est_s, o->budget, (long long)est_dofs);
          if (why[0]) {
            for (int s = 0; s < NSOLVER; s++)
              if (want[s] && !IS_PETSC(s) && !add_skip(o, t, body, n, 0, s, why)) fatal = 1;
            goto serial_done;
          }
        }
        fprintf(stderr, PROG ": %s %s n=%lld: building the problem\n", en, body_names[body],
                (long long)n);
        const double base = rss_reset();
        const double w0 = omp_get_wtime();
        fcm_status st = problem_build(ctx, o, t, body, n, &p);
        const double build_s = omp_get_wtime() - w0;
        if (st != FCM_OK) {
          fprintf(stderr, PROG ": %s %s n=%lld: building the problem failed: %s\n", en,
                  body_names[body], (long long)n, fcm_ctx_error_message(ctx));
          for (int s = 0; s < NSOLVER; s++)
            if (want[s] && !IS_PETSC(s) && nrows < MAX_ROWS) {
              row *r = &rows[nrows++];
              memset(r, 0, sizeof *r);
              r->type = t, r->body = body, r->n = n, r->solver = s, r->status = ROW_FAILED;
              r->factor = r->relres = r->diff = r->peak_mb = r->base_mb = -1.0;
              r->processes = 1;
              char msg[400];
              snprintf(msg, sizeof msg, "problem: %s", fcm_ctx_error_message(ctx));
              set_note(r, msg);
              if (!emit(o, r)) fatal = 1;
            }
          failed = 1;
          goto serial_done;
        }
        have_p = 1;
        const double peak = base >= 0.0 ? rss_peak() : -1.0;
        last_prob_mb = peak >= 0.0 ? fmax(peak - base, 1.0) : 0.0;
        last_prob_s = build_s, last_n = n, last_dofs = p.n;
        fprintf(stderr, PROG ": %s %s n=%lld: %lld dofs, built in %.1f s (%.0f MB)\n", en,
                body_names[body], (long long)n, (long long)p.n, build_s, last_prob_mb);
        x = malloc(sizeof *x * ((size_t)p.n + 1));
        xref = malloc(sizeof *xref * ((size_t)p.n + 1));
        if (!x || !xref) {
          fprintf(stderr, PROG ": out of memory for the solution vectors\n");
          fatal = 1;
          goto serial_done;
        }
        for (int si = 0; si < o->nsolvers && !fatal; si++) {
          const int s = o->solvers[si];
          if (!want[s] || IS_PETSC(s)) continue;
          if (skipped[s][0]) {
            if (!add_skip(o, t, body, n, p.n, s, skipped[s])) failed = 1;
            continue;
          }
          double est_s = 0.0, est_mb = 0.0;
          estimate(t, body, s, p.n, &est_s, &est_mb);
          const double now_avail = mem_available();
          why[0] = 0;
          if (now_avail > 0.0 && est_mb > o->mem_fraction * now_avail)
            snprintf(why, sizeof why, "would need about %.0f MB more (%.0f MB available)", est_mb,
                     now_avail);
          else if (est_s > o->budget)
            snprintf(why, sizeof why, "would take about %.0f s > --budget %.0f s", est_s,
                     o->budget);
          if (why[0]) {
            char w2[200];
            snprintf(w2, sizeof w2, "n=%lld %s", (long long)n, why);
            snprintf(skipped[s], sizeof skipped[s], "%.150s (and larger)", w2);
            if (!add_skip(o, t, body, n, p.n, s, why)) failed = 1;
            continue;
          }
          if (nrows >= MAX_ROWS) break;
          row *r = &rows[nrows++];
          memset(r, 0, sizeof *r);
          r->type = t, r->body = body, r->n = n, r->dofs = p.n, r->solver = s;
          r->factor = r->relres = r->diff = -1.0;
          r->processes = 1;
          fprintf(stderr, PROG ": %s %s n=%lld %s ...\n", en, body_names[body], (long long)n,
                  solver_names[s]);
          run_solver(ctx, o, &p, s, s == S_CHOLMOD ? xref : x, have_ref ? xref : NULL, r);
          if (s == S_CHOLMOD && r->status == ROW_OK) have_ref = 1;
          /* the PETSc rows' reference when CHOLMOD's is missing: cg-mg's solution */
          if (s == S_CGMG && r->status == ROW_OK && !have_ref && !have_mgref) {
            memcpy(xref, x, sizeof *x * (size_t)p.n);
            have_mgref = 1;
          }
          if (r->status == ROW_FAILED) failed = 1;
          if (r->status == ROW_SKIPPED) snprintf(skipped[s], sizeof skipped[s], "%s", r->note);
          if (!emit(o, r)) fatal = 1;
        }
      serial_done:
        sync_processes(o, &fatal);
#if FCM_HAVE_PETSC
        for (int si = 0; si < o->nsolvers && npetsc && !fatal; si++) {
          const int s = o->solvers[si];
          if (!want[s] || !IS_PETSC(s)) continue;
          int go = 0;
          if (root) {
            const fcm_index dofs = have_p ? p.n : 0;
            double est_s = 0.0, est_mb = 0.0;
            estimate(t, body, s, dofs > 0 ? dofs : last_dofs, &est_s, &est_mb);
            const double now_avail = mem_available();
            why[0] = 0;
            if (skipped[s][0])
              snprintf(why, sizeof why, "%s", skipped[s]);
            else if (now_avail > 0.0 && est_mb > o->mem_fraction * now_avail)
              snprintf(why, sizeof why, "would need about %.0f MB more (%.0f MB available)", est_mb,
                       now_avail);
            else if (est_s > o->budget)
              snprintf(why, sizeof why, "would take about %.0f s > --budget %.0f s", est_s,
                       o->budget);
            if (why[0] && !skipped[s][0])
              snprintf(skipped[s], sizeof skipped[s], "n=%lld %.150s (and larger)", (long long)n,
                       why);
            if (why[0]) {
              if (!add_skip(o, t, body, n, dofs, s, why)) fatal = 1;
            } else {
              go = nrows < MAX_ROWS;
            }
          }
          MPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
          if (!go) continue;
          row scratch, *r = root ? &rows[nrows++] : &scratch;
          memset(r, 0, sizeof *r);
          r->type = t, r->body = body, r->n = n, r->solver = s;
          r->factor = r->relres = r->diff = -1.0;
          if (root)
            fprintf(stderr, PROG ": %s %s n=%lld %s on %d processes ...\n", en, body_names[body],
                    (long long)n, solver_names[s], o->size);
          run_petsc(ctx, o, t, body, n, s, have_p ? &p : NULL, have_ref || have_mgref ? xref : NULL,
                    r);
          if (root) {
            if (r->status == ROW_FAILED) failed = 1;
            if (!emit(o, r)) fatal = 1;
          }
          MPI_Bcast(&fatal, 1, MPI_INT, 0, MPI_COMM_WORLD);
        }
#endif
        free(x);
        free(xref);
        if (have_p) problem_free(&p);
      }
    }
  return failed || fatal;
}

/* ------------------------------------------------------------- main */

static void usage(FILE *f, const cli_option *opts)
{
  fprintf(
      f,
      "usage: " PROG " [options]\n"
      "How the cost of a static solve grows with the DOFs: linear elasticity under gravity of\n"
      "an embedded body in the box [-1,1]^3 of n^3 Hex8 or Hex20 cells, set in a rigid base\n"
      "(every node copy with y <= -0.5 clamped), solved by\n"
      "  cholmod         sparse Cholesky (CHOLMOD); its convergence_factor is empty\n"
      "  cg-jacobi       CG, scalar Jacobi preconditioner\n"
      "  minres-schwarz  MINRES, the additive Schwarz preconditioner of the simulations (one\n"
      "                  block per cut cell of volume fraction < 0.5); it stops on the\n"
      "                  preconditioned residual norm (relative_residual is the 2-norm)\n"
      "  cg-mg           CG, one multigrid cycle as preconditioner (the library's defaults:\n"
      "                  W-cycle, symmetric Gauss-Seidel with block smoothing at cut cells)\n"
      "  mg              multigrid cycles alone (W; V for the bodies cube and cut)\n"
      "all to the relative residual --rtol. Bodies: ball (radius 0.9), hollow (radii 0.5 and\n"
      "0.9, three holes of radius 0.25 along the axes), cube (the whole box, uncut, clamped at\n"
      "y = -1) and cut (the ball with a plane cut x = 0.05 through its upper half); cube and\n"
      "cut run mg only and give the V-cycle factor (Dick et al. 2011 Fig. 10: 0.66 uncut, 0.75\n"
      "cut).\n"
      "CSV columns: element,cells (n per axis),dofs,solver,iterations (cycles for mg; 1 for\n"
      "cholmod),convergence_factor (mg: mean residual reduction per cycle after the first;\n"
      "Krylov: (final relative residual)^(1/iterations); empty for cholmod),setup_s,solve_s\n"
      "(wall clock),peak_rss_mb (the process's peak resident memory during this row's setup and\n"
      "solve, problem included: the kernel's high-water mark is reset before the row by writing\n"
      "5 to /proc/self/clear_refs and VmHWM read after it), then body,status (ok, skipped,\n"
      "failed),relative_residual (||b - A x||/||b||, computed here),diff_cholmod (||x -\n"
      "x_cholmod||/||x_cholmod||),setup_cpu_s,solve_cpu_s (process CPU, all threads),\n"
      "base_rss_mb (resident before the row),levels (multigrid levels),processes (MPI\n"
      "processes of the row: 1 for the serial solvers),note (why skipped or failed; for a\n"
      "PETSc row that ran: its KSP + PC).\n"
      "--backend petsc (mpirun -n P " PROG " --backend petsc): rows of\n"
      "  petsc-gamg      CG + GAMG, rigid-body near-null space, on the true residual\n"
      "  petsc-mumps     MUMPS sparse Cholesky (preonly)\n"
      "  petsc-mg        CG + fcm's geometric multigrid as PCMG (-pc_type mg), on the true "
      "residual\n"
      "on every process through the PETSc adapter (fcm/petsc.h), bodies ball and hollow;\n"
      "default solvers cholmod,cg-mg,petsc-gamg,petsc-mumps,petsc-mg (the serial ones on\n"
      "process 0 give\n"
      "the reference: diff_cholmod is against CHOLMOD's solution, else cg-mg's). PETSc rows:\n"
      "setup_s is the whole distributed problem (partition, rules, space, assembly,\n"
      "elimination), solve_s the KSP solve with GAMG's or PCMG's set-up or MUMPS's\n"
      "factorization;\n"
      "setup_cpu_s, solve_cpu_s, peak_rss_mb and base_rss_mb are summed over the processes\n"
      "(process 0 also holds the serial problem: peak - base is the PETSc run's own);\n"
      "relative_residual is computed with the serial matrix. PETSc options on the command\n"
      "line (-ksp_type ...) apply to every PETSc row. --check then claims: every PETSc row\n"
      "agrees with the serial solution within --agree and reports its iterations.\n"
      "Before each size a solver is skipped (and at every larger size) when its time (the\n"
      "smaller of wall and CPU seconds: less sensitive to load), scaled from the previous sizes,\n"
      "would exceed --budget, or its memory would exceed\n"
      "--mem-fraction of MemAvailable; the problem itself likewise. Rows say what was skipped\n"
      "and why. Progress goes to stderr.\n"
      "Default: hex8 and hex20, n = 8,16,32,64, all bodies and serial solvers. --quick: hex8, n =\n"
      "8,16,32 (the same facts on fewer sizes; budget 120 s). Prints the fitted exponents of\n"
      "time (setup+solve and solve alone) against DOFs and the claims of issue 13; --check\n"
      "makes a failed claim exit 1.\n"
      "options:\n");
  cli_print_options(f, opts);
}

static int parse_sizes(const char *s, settings *o)
{
  char tok[16][CLI_TOKEN];
  int m = 0;
  if (!cli_list(PROG, "--sizes", s, tok, 16, &m)) return 0;
  for (int i = 0; i < m; i++) {
    long long v = 0;
    if (!cli_int(PROG, "--sizes", tok[i], 2, 512, &v)) return 0;
    o->sizes[i] = (fcm_index)v;
    if (i > 0 && o->sizes[i] <= o->sizes[i - 1]) {
      fprintf(stderr, PROG ": --sizes: sizes must increase (%s)\n", s);
      return 0;
    }
  }
  o->nsizes = m;
  return 1;
}

static int parse_names(const char *opt, const char *s, const char *const *names, int *out, int *n)
{
  char tok[8][CLI_TOKEN];
  int m = 0;
  if (!cli_list(PROG, opt, s, tok, 8, &m)) return 0;
  for (int i = 0; i < m; i++) {
    if (!cli_choice(PROG, opt, tok[i], names, &out[i])) return 0;
    for (int j = 0; j < i; j++)
      if (out[j] == out[i]) {
        fprintf(stderr, PROG ": %s: %s given twice\n", opt, tok[i]);
        return 0;
      }
  }
  *n = m;
  return 1;
}

static int scaling_main(int argc, char **argv, int pargc, char **pargv);

int main(int argc, char **argv)
{
  app_env_init(argc, argv);
  char **pargv = calloc((size_t)argc + 2, sizeof *pargv);
  if (!pargv) return 1;
  int pargc = 1;
  cli_split_petsc_args(&argc, argv, &pargc, pargv);
  const int rc = scaling_main(argc, argv, pargc, pargv);
  free(pargv);
  return rc;
}

static int scaling_main(int argc, char **argv, int pargc, char **pargv)
{
  settings o;
  memset(&o, 0, sizeof o);
  o.rtol = 1e-8, o.agree = 1e-4, o.budget = -1.0, o.mem_fraction = 0.8;
  o.clock = CLOCK_CPU;
  o.max_iterations = 20000;
  o.coarse_dofs = 200;
  o.constrain_ratio = fcm_space_options_default().constrain_ratio;
  const char *sizes = NULL, *elements = NULL, *bodies = NULL, *solvers = NULL;
  int seen_budget = 0;
  const cli_option opts[] = {
      {"--quick", NULL, CLI_FLAG, &o.quick, NULL,
       "hex8, n = 8,16,32, budget 120 s (under 5 minutes on 2 cores)", 0, 0, 0, NULL, NULL, NULL},
      {"--csv", NULL, CLI_STRING, &o.csv, "FILE", "write the rows as CSV (atomically)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--png", NULL, CLI_STRING, &o.png, "FILE",
       "plot time (setup + solve) and iterations against DOFs\n(log-log, needs gnuplot)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--sizes", NULL, CLI_STRING, &sizes, "N,N,...",
       "cells per axis, increasing (default "
       "8,16,32,64)",
       0, 0, 0, NULL, NULL, NULL},
      {"--elements", NULL, CLI_STRING, &elements, "E,...", "hex8, hex20 (default both)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--bodies", NULL, CLI_STRING, &bodies, "B,...", "ball, hollow, cube, cut (default all)", 0,
       0, 0, NULL, NULL, NULL},
      {"--solvers", NULL, CLI_STRING, &solvers, "S,...",
       "cholmod, cg-jacobi, minres-schwarz, cg-mg, mg (default all);\n--backend petsc also "
       "petsc-gamg, petsc-mumps, petsc-mg "
       "(default\ncholmod,cg-mg,petsc-gamg,petsc-mumps,petsc-mg); "
       "cholmod first "
       "gives\nthe reference solution",
       0, 0, 0, NULL, NULL, NULL},
      {"--rtol", NULL, CLI_DOUBLE, &o.rtol, "R", "relative residual of every solver (default 1e-8)",
       1e-14, 1e-2, 0, NULL, NULL, NULL},
      {"--agree", NULL, CLI_DOUBLE, &o.agree, "TOL",
       "largest ||x - x_cholmod||/||x_cholmod|| accepted (default\n1e-4: a residual of rtol allows "
       "an "
       "error of up to kappa x\nrtol; cg-jacobi on Hex20 reaches 1.2e-5 at rtol 1e-8)",
       0, 1, CLI_LO_OPEN, NULL, NULL, NULL},
      {"--max-iterations", NULL, CLI_INT, &o.max_iterations, "K",
       "iterations / cycles before a solver fails (default 20000)", 1, 1e7, 0, NULL, NULL, NULL},
      {"--budget", NULL, CLI_DOUBLE, &o.budget, "S",
       "skip a solver (and a problem) whose estimated wall time\nexceeds S seconds (default 900; "
       "--quick 120)",
       0, 1e7, CLI_LO_OPEN, NULL, NULL, &seen_budget},
      {"--mem-fraction", NULL, CLI_DOUBLE, &o.mem_fraction, "F",
       "skip what would need more than F x MemAvailable (default 0.8)", 0, 1, CLI_LO_OPEN, NULL,
       NULL, NULL},
      {"--coarse-dofs", NULL, CLI_LLONG, &o.coarse_dofs, "N",
       "multigrid: coarsen until a level has at most N DOFs\n(fcm_mg_options.coarse_dofs; default "
       "200, so that n = 8 has 2+ levels:\nthe library's 2000 would solve it directly)",
       1, 1e9, 0, NULL, NULL, NULL},
      {"--constrain-ratio", NULL, CLI_DOUBLE, &o.constrain_ratio, "R",
       "the space's constrain_ratio (fcm_space_options; default\nthe library's, 1e-9): DOF copies "
       "of smaller support move with\ntheir piece",
       0, 0.5, CLI_HI_OPEN, NULL, NULL, NULL},
      {"--threads", NULL, CLI_INT, &o.threads, "T",
       "OpenMP threads (and CHOLMOD's BLAS threads); 0: the\nenvironment's (default)", 0, 1024, 0,
       NULL, NULL, NULL},
      {"--clock", NULL, CLI_CHOICE, &o.clock, "C",
       "cpu (default: process CPU seconds; on a shared machine\nthe wall clock also measures the "
       "other load) or wall: the\ntimes the exponents, claims and plot use",
       0, 0, 0, clock_names, NULL, NULL},
      {"--check", NULL, CLI_FLAG, &o.check, NULL,
       "exit 1 when a claim of issue 13 fails or cannot be measured\n(--backend petsc: the "
       "claims on the PETSc rows)",
       0, 0, 0, NULL, NULL, NULL},
      {"--backend", NULL, CLI_CHOICE, &o.backend, "NAME",
       "serial (default) or petsc: add the rows of the PETSc\nsolvers petsc-gamg, petsc-mumps "
       "and petsc-mg on every MPI process\n(mpirun -n 2 " PROG " --backend petsc; PETSc "
       "options such as\n-ksp_type go to them; needs a build with PETSc)",
       0, 0, 0, backend_names, NULL, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  const int code = cli_parse_args(PROG, opts, argc, argv, NULL, 0, NULL, usage);
  if (code >= 0) return code;
  const int petsc = o.backend == BACKEND_PETSC;
#if !FCM_HAVE_PETSC
  (void)pargc;
  (void)pargv;
  if (petsc) {
    fprintf(stderr, PROG ": --backend petsc: this fcm was built without PETSc (CMake option "
                         "FCM_WITH_PETSC; Debian: bash setup.sh deps --petsc, then rebuild)\n");
    return 2;
  }
#endif
  const fcm_index def_sizes[4] = {8, 16, 32, 64};
  o.nsizes = o.quick ? 3 : 4;
  memcpy(o.sizes, def_sizes, sizeof def_sizes);
  o.types[0] = FCM_ELEMENT_HEX8, o.types[1] = FCM_ELEMENT_HEX20;
  o.ntypes = o.quick ? 1 : 2;
  for (int b = 0; b < NBODY; b++)
    o.bodies[b] = b;
  o.nbodies = NBODY;
  for (int s = 0; s < NSOLVER; s++)
    o.solvers[s] = s;
  o.nsolvers = NSOLVER;
  if (!seen_budget) o.budget = o.quick ? 120.0 : 900.0;
  if (sizes && !parse_sizes(sizes, &o)) return 2;
  if (elements) {
    if (!cli_element_list(PROG, "--elements", elements, o.types, &o.ntypes)) return 2;
    for (int i = 0; i < o.ntypes; i++)
      if (o.types[i] != FCM_ELEMENT_HEX8 && o.types[i] != FCM_ELEMENT_HEX20) {
        fprintf(stderr, PROG ": --elements: %s: only hex8 and hex20 (box grids)\n",
                fcm_element_get_info(o.types[i])->name);
        return 2;
      }
  }
  if (petsc) { /* default: the embedded bodies; the references and the PETSc solvers */
    o.bodies[0] = B_BALL, o.bodies[1] = B_HOLLOW, o.nbodies = 2;
    o.solvers[0] = S_CHOLMOD, o.solvers[1] = S_CGMG, o.solvers[2] = S_PGAMG;
    o.solvers[3] = S_PMUMPS, o.solvers[4] = S_PMG, o.nsolvers = 5;
  } else {
    o.nsolvers = NSOLVER - 3; /* the serial ones */
  }
  if (bodies && !parse_names("--bodies", bodies, body_names, o.bodies, &o.nbodies)) return 2;
  if (solvers && !parse_names("--solvers", solvers, solver_names, o.solvers, &o.nsolvers)) return 2;
  for (int i = 0; i < o.nsolvers && !petsc; i++)
    if (IS_PETSC(o.solvers[i])) {
      fprintf(stderr, PROG ": --solvers: %s runs with --backend petsc only\n",
              solver_names[o.solvers[i]]);
      return 2;
    }
  if (petsc && o.constrain_ratio != fcm_space_options_default().constrain_ratio) {
    fprintf(stderr,
            PROG ": --constrain-ratio: the PETSc backend builds its space with the "
                 "library's default (%g); drop the option with --backend petsc\n",
            fcm_space_options_default().constrain_ratio);
    return 2;
  }
  /* cholmod first: it gives the reference solution */
  for (int i = 1; i < o.nsolvers; i++)
    if (o.solvers[i] == S_CHOLMOD) {
      memmove(o.solvers + 1, o.solvers, sizeof *o.solvers * (size_t)i);
      o.solvers[0] = S_CHOLMOD;
    }
  if (o.threads > 0) omp_set_num_threads(o.threads);
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) {
    fprintf(stderr, PROG ": cannot create a context\n");
    return 1;
  }
  o.rank = 0, o.size = 1;
#if FCM_HAVE_PETSC
  if (petsc) {
    if (fcm_petsc_initialize(ctx, &pargc, &pargv) != FCM_OK) {
      fprintf(stderr, PROG ": %s\n", fcm_ctx_error_message(ctx));
      fcm_ctx_destroy(&ctx);
      return 1;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &o.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &o.size);
    if (o.rank != 0) { /* process 0 prints and writes */
      if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) {
        fcm_petsc_finalize();
        fcm_ctx_destroy(&ctx);
        return 1;
      }
      o.png = NULL;
    }
  }
#endif
  char procs[64] = "";
  if (petsc) snprintf(procs, sizeof procs, "; PETSc rows on %d MPI process(es)", o.size);
  printf("fcm-scaling: %s; rtol %.1e, %d OpenMP threads, budget %.0f s per row%s%s\n",
         o.quick ? "--quick: hex8 on n = 8, 16, 32 only (the full run adds hex20 and n = 64)"
                 : "study",
         o.rtol, omp_get_max_threads(), o.budget, procs,
         rss_reset() < 0.0 ? "; peak memory not measured (no /proc/self/clear_refs)" : "");
  const int failed = run_study(ctx, &o);
  const int claims = petsc ? summary_petsc(&o) : summary(&o);
  int ok = !failed && (!o.check || claims);
  if (failed) printf("\nsome rows FAILED (see their notes)\n");
  if (!write_csv(&o)) ok = 0;
  if (o.png && !write_png(&o)) ok = 0;
#if FCM_HAVE_PETSC
  if (petsc) { /* process 0 decided */
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    fcm_petsc_finalize();
  }
#endif
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
