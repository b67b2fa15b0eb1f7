/* fcm-scaling: shared declarations of the scaling study — the solvers, bodies and settings,
 * one result row and the table of rows, the study (fcm-scaling-study.c) and its output
 * (fcm-scaling-output.c). fcm-scaling.c parses the options and runs the study. */
#ifndef FCM_SCALING_STUDY_H
#define FCM_SCALING_STUDY_H

#include <fcm/fcm.h>

#define PROG "fcm-scaling"

/** The solvers; S_PGAMG, S_PMUMPS, S_PMG: the PETSc backend (--backend petsc, fcm/petsc.h), on
 *  every MPI process. */
enum { S_CHOLMOD, S_CGJ, S_MINRES, S_CGMG, S_MG, S_PGAMG, S_PMUMPS, S_PMG, NSOLVER };
/** Names of the solvers, as on the command line and in the CSV (NULL-terminated). */
extern const char *const solver_names[NSOLVER + 1];
#define IS_PETSC(s) ((s) == S_PGAMG || (s) == S_PMUMPS || (s) == S_PMG)
enum { BACKEND_SERIAL, BACKEND_PETSC };
extern const char *const backend_names[3];
/** The bodies embedded in the box. */
enum { B_BALL, B_HOLLOW, B_CUBE, B_CUT, NBODY };
extern const char *const body_names[NBODY + 1];
/** The clock the exponents, claims and plot use. */
enum { CLOCK_WALL, CLOCK_CPU };
extern const char *const clock_names[3];

enum { ROW_OK, ROW_SKIPPED, ROW_FAILED };

/** One measured (element, body, size, solver). */
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

/** The rows of the study, in the order they ran. */
typedef struct table {
  row rows[MAX_ROWS];
  int nrows;
} table;

/** The study's settings (fcm-scaling.c fills them from the command line). */
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

/* ---------------------------------------------------------------- the study */

/** Every (element, body, size, solver) of `o` into `tb`, rows printed and the CSV rewritten as
 *  they come; 1 when a row failed or the study had to stop, else 0. Process 0 runs the serial
 *  solvers and decides what runs; the PETSc solvers run on every process (--backend petsc). */
int scaling_run_study(fcm_ctx *ctx, const settings *o, table *tb);

/** Give freed memory back and reset the kernel's high-water mark VmHWM to the current resident
 *  size; the current VmRSS in MB, or -1 when the mark cannot be reset (peaks not measured). */
double scaling_rss_reset(void);

/** Seconds of a row: setup + solve (or the solve alone) on `clock` (CLOCK_WALL, CLOCK_CPU). */
double scaling_row_time(const row *r, int clock, int solve_only);

/** The rows of one series (element, body, solver) that ran, in order of size, into out[0..cap). */
int scaling_series(const table *tb, fcm_element_type type, int body, int s, const row **out,
                   int cap);

/** Least-squares exponent of time against DOFs over a series; NAN with fewer than 2 sizes. */
double scaling_series_exponent(const table *tb, fcm_element_type type, int body, int s, int clock,
                               int solve_only);

/* ---------------------------------------------------------------- output */

/** One row on stdout (the table printed as the study runs). */
void scaling_print_row(const row *r);

/** The rows so far into --csv (atomically); called after every row, so an interrupted run
 *  leaves the rows it finished. 1 on success (and without --csv, and on processes other than
 *  0); 0 with a message on stderr. */
int scaling_write_csv(const settings *o, const table *tb);

/** Time and iterations against DOFs plotted with gnuplot into --png (atomically); without
 *  gnuplot a message and success. 1 on success, 0 on failure. */
int scaling_write_png(const settings *o, const table *tb);

/** The fitted exponents, the multigrid factors and the claims on stdout; 1 when every claim
 *  holds. */
int scaling_summary(const settings *o, const table *tb);

/** --backend petsc: scaling_summary() (printed, not claimed), the PETSc rows' cost per DOF and
 *  their claims; 1 when every claim holds. */
int scaling_summary_petsc(const settings *o, const table *tb);

#endif
