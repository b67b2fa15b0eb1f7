/* fcm-scaling: how the cost of one static solve grows with the number of DOFs.
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
 * --backend petsc (a build with PETSc, under mpirun -n P): the same problems of the
 * bodies ball and hollow also through the PETSc adapter (fcm/petsc.h, the linear static
 * driver: partition, rules of the own cells, MATMPIAIJ assembly, KSP) on every process, solved
 * by petsc-gamg (CG + GAMG with the rigid-body near-null space, stopping on the true residual)
 * petsc-mumps (MUMPS Cholesky) and petsc-mg (CG + fcm's multigrid hierarchy as PETSc's PCMG,
 * lib/src/petsc/pcmg.c); process 0 also runs the serial solvers (the others wait
 * sleeping) and compares the PETSc solution with CHOLMOD's (else cg-mg's); it alone prints
 * and writes.
 * Writes CSV (--csv FILE, atomically) and a plot (--png FILE, gnuplot), prints the fitted
 * exponents of time against DOFs and the claims (see usage()); exit 0 when every row ran or was
 * skipped (and, with --check, every claim holds), 1 when a computation failed or a solution
 * disagreed with CHOLMOD's (or a claim failed under --check), 2 on a usage error. */
#define _GNU_SOURCE
#include "app_env.h"
#include "cli.h"
#include "fcm-scaling-study.h"

#include <fcm/fcm.h>
#if FCM_HAVE_PETSC
#include <fcm/petsc.h>
#endif

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
      "PETSc row that ran: its KSP + PC).\n");
  fprintf(
      f,
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
      "time (setup+solve and solve alone) against DOFs and checks the claims, per element on\n"
      "the bodies ball and hollow: cg-mg iterations flat within 1.5x over the sizes, cg-mg's\n"
      "time exponent at most 1.2 and below cholmod's, cg-mg faster than cholmod at the largest\n"
      "size both ran; on cut, the V-cycle factor at most 0.8 wherever there are 2+ levels.\n"
      "--check makes a failed claim exit 1.\n"
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

/* The rows of the study (static: a few hundred kB). */
static table results;

/* The settings from the command line, validated, with the defaults filled in: -1 to go on, or
 * the exit code (0 after --help, 2 on a usage error). It stays long: it is one table of the
 * options with their checks, and splitting it would scatter them. */
static int parse_options(int argc, char **argv, settings *o)
{
  memset(o, 0, sizeof *o);
  o->rtol = 1e-8, o->agree = 1e-4, o->budget = -1.0, o->mem_fraction = 0.8;
  o->clock = CLOCK_CPU;
  o->max_iterations = 20000;
  o->coarse_dofs = 200;
  o->constrain_ratio = fcm_space_options_default().constrain_ratio;
  const char *sizes = NULL, *elements = NULL, *bodies = NULL, *solvers = NULL;
  int seen_budget = 0;
  const cli_option opts[] = {
      {"--quick", NULL, CLI_FLAG, &o->quick, NULL, "hex8, n = 8,16,32, budget 120 s", 0, 0, 0, NULL,
       NULL, NULL},
      {"--csv", NULL, CLI_STRING, &o->csv, "FILE", "write the rows as CSV (atomically)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--png", NULL, CLI_STRING, &o->png, "FILE",
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
      {"--rtol", NULL, CLI_DOUBLE, &o->rtol, "R",
       "relative residual of every solver (default 1e-8)", 1e-14, 1e-2, 0, NULL, NULL, NULL},
      {"--agree", NULL, CLI_DOUBLE, &o->agree, "TOL",
       "largest ||x - x_cholmod||/||x_cholmod|| accepted (default\n1e-4: a residual of rtol allows "
       "an error of up to kappa x\nrtol)",
       0, 1, CLI_LO_OPEN, NULL, NULL, NULL},
      {"--max-iterations", NULL, CLI_INT, &o->max_iterations, "K",
       "iterations / cycles before a solver fails (default 20000)", 1, 1e7, 0, NULL, NULL, NULL},
      {"--budget", NULL, CLI_DOUBLE, &o->budget, "S",
       "skip a solver (and a problem) whose estimated wall time\nexceeds S seconds (default 900; "
       "--quick 120)",
       0, 1e7, CLI_LO_OPEN, NULL, NULL, &seen_budget},
      {"--mem-fraction", NULL, CLI_DOUBLE, &o->mem_fraction, "F",
       "skip what would need more than F x MemAvailable (default 0.8)", 0, 1, CLI_LO_OPEN, NULL,
       NULL, NULL},
      {"--coarse-dofs", NULL, CLI_LLONG, &o->coarse_dofs, "N",
       "multigrid: coarsen until a level has at most N DOFs\n(fcm_mg_options.coarse_dofs; default "
       "200, so that n = 8 has 2+ levels:\nthe library's 2000 would solve it directly)",
       1, 1e9, 0, NULL, NULL, NULL},
      {"--constrain-ratio", NULL, CLI_DOUBLE, &o->constrain_ratio, "R",
       "the space's constrain_ratio (fcm_space_options; default\nthe library's, 1e-9): DOF copies "
       "of smaller support move with\ntheir piece",
       0, 0.5, CLI_HI_OPEN, NULL, NULL, NULL},
      {"--threads", NULL, CLI_INT, &o->threads, "T",
       "OpenMP threads (and CHOLMOD's BLAS threads); 0: the\nenvironment's (default)", 0, 1024, 0,
       NULL, NULL, NULL},
      {"--clock", NULL, CLI_CHOICE, &o->clock, "C",
       "cpu (default: process CPU seconds; on a shared machine\nthe wall clock also measures the "
       "other load) or wall: the\ntimes the exponents, claims and plot use",
       0, 0, 0, clock_names, NULL, NULL},
      {"--check", NULL, CLI_FLAG, &o->check, NULL,
       "exit 1 when a claim fails or cannot be measured\n(--backend petsc: the "
       "claims on the PETSc rows)",
       0, 0, 0, NULL, NULL, NULL},
      {"--backend", NULL, CLI_CHOICE, &o->backend, "NAME",
       "serial (default) or petsc: add the rows of the PETSc\nsolvers petsc-gamg, petsc-mumps "
       "and petsc-mg on every MPI process\n(mpirun -n 2 " PROG " --backend petsc; PETSc "
       "options such as\n-ksp_type go to them; needs a build with PETSc)",
       0, 0, 0, backend_names, NULL, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  const int code = cli_parse_args(PROG, opts, argc, argv, NULL, 0, NULL, usage);
  if (code >= 0) return code;
  const int petsc = o->backend == BACKEND_PETSC;
#if !FCM_HAVE_PETSC
  if (petsc) {
    fprintf(stderr, PROG ": --backend petsc: this fcm was built without PETSc (CMake option "
                         "FCM_WITH_PETSC; Debian: bash setup.sh deps --petsc, then rebuild)\n");
    return 2;
  }
#endif
  const fcm_index def_sizes[4] = {8, 16, 32, 64};
  o->nsizes = o->quick ? 3 : 4;
  memcpy(o->sizes, def_sizes, sizeof def_sizes);
  o->types[0] = FCM_ELEMENT_HEX8, o->types[1] = FCM_ELEMENT_HEX20;
  o->ntypes = o->quick ? 1 : 2;
  for (int b = 0; b < NBODY; b++)
    o->bodies[b] = b;
  o->nbodies = NBODY;
  for (int s = 0; s < NSOLVER; s++)
    o->solvers[s] = s;
  o->nsolvers = NSOLVER;
  if (!seen_budget) o->budget = o->quick ? 120.0 : 900.0;
  if (sizes && !parse_sizes(sizes, o)) return 2;
  if (elements) {
    if (!cli_element_list(PROG, "--elements", elements, o->types, &o->ntypes)) return 2;
    for (int i = 0; i < o->ntypes; i++)
      if (o->types[i] != FCM_ELEMENT_HEX8 && o->types[i] != FCM_ELEMENT_HEX20) {
        fprintf(stderr, PROG ": --elements: %s: only hex8 and hex20 (box grids)\n",
                fcm_element_get_info(o->types[i])->name);
        return 2;
      }
  }
  if (petsc) { /* default: the embedded bodies; the references and the PETSc solvers */
    o->bodies[0] = B_BALL, o->bodies[1] = B_HOLLOW, o->nbodies = 2;
    o->solvers[0] = S_CHOLMOD, o->solvers[1] = S_CGMG, o->solvers[2] = S_PGAMG;
    o->solvers[3] = S_PMUMPS, o->solvers[4] = S_PMG, o->nsolvers = 5;
  } else {
    o->nsolvers = NSOLVER - 3; /* the serial ones */
  }
  if (bodies && !parse_names("--bodies", bodies, body_names, o->bodies, &o->nbodies)) return 2;
  if (solvers && !parse_names("--solvers", solvers, solver_names, o->solvers, &o->nsolvers))
    return 2;
  for (int i = 0; i < o->nsolvers && !petsc; i++)
    if (IS_PETSC(o->solvers[i])) {
      fprintf(stderr, PROG ": --solvers: %s runs with --backend petsc only\n",
              solver_names[o->solvers[i]]);
      return 2;
    }
  if (petsc && o->constrain_ratio != fcm_space_options_default().constrain_ratio) {
    fprintf(stderr,
            PROG ": --constrain-ratio: the PETSc backend builds its space with the "
                 "library's default (%g); drop the option with --backend petsc\n",
            fcm_space_options_default().constrain_ratio);
    return 2;
  }
  /* cholmod first: it gives the reference solution */
  for (int i = 1; i < o->nsolvers; i++)
    if (o->solvers[i] == S_CHOLMOD) {
      memmove(o->solvers + 1, o->solvers, sizeof *o->solvers * (size_t)i);
      o->solvers[0] = S_CHOLMOD;
    }
  return -1;
}

static int scaling_main(int argc, char **argv, int pargc, char **pargv)
{
  settings o;
  const int code = parse_options(argc, argv, &o);
  if (code >= 0) return code;
  const int petsc = o.backend == BACKEND_PETSC;
#if !FCM_HAVE_PETSC
  (void)pargc;
  (void)pargv;
#endif
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
         scaling_rss_reset() < 0.0 ? "; peak memory not measured (no /proc/self/clear_refs)" : "");
  const int failed = scaling_run_study(ctx, &o, &results);
  const int claims = petsc ? scaling_summary_petsc(&o, &results) : scaling_summary(&o, &results);
  int ok = !failed && (!o.check || claims);
  if (failed) printf("\nsome rows FAILED (see their notes)\n");
  if (!scaling_write_csv(&o, &results)) ok = 0;
  if (o.png && !scaling_write_png(&o, &results)) ok = 0;
#if FCM_HAVE_PETSC
  if (petsc) { /* process 0 decided */
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    fcm_petsc_finalize();
  }
#endif
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
