/* fcm-converge: shared declarations of the convergence / accuracy-versus-time study —
 * the problems on the embedded hemisphere, one run (FCM or staircase FEM) with its errors. */
#ifndef FCM_CONVERGE_STUDY_H
#define FCM_CONVERGE_STUDY_H

#include <fcm/core.h>
#include <fcm/element.h>
#include <fcm/embed.h>
#include <fcm/fem.h>
#include <fcm/geom.h>
#include <fcm/la.h>
#include <fcm/mesh.h>

#include <stdio.h>

#define CV_PROG "fcm-converge"

/** The discretizations compared. */
typedef enum cv_method {
  CV_FCM = 0,     /* exact embedded geometry, cut-cell rules */
  CV_FEM = 1,     /* staircase: cells whose centroid is inside, full standard rules */
  CV_NITSCHE = 2, /* FCM with the exact displacement imposed weakly (symmetric Nitsche) on the
                     curved boundary instead of the traction ("fcm-nitsche", --boundary nitsche) */
  CV_METHOD_COUNT
} cv_method;

/** Which boundary-value problem. */
typedef enum cv_problem {
  CV_MANUFACTURED = 0, /* smooth exact field, body force + traction derived from it */
  CV_REFERENCE = 1     /* localized body load, error against a fine boundary-conforming Tet10 */
} cv_problem;

/** How the staircase FEM receives the surface load of the manufactured problem. */
typedef enum cv_fem_traction {
  CV_TRACTION_PROJECTED = 0, /* true surface load carried along rays from the centre */
  CV_TRACTION_NAIVE = 1,     /* sigma(u(x)) n_true(x) per staircase face area */
  CV_TRACTION_FACE = 2       /* sigma(u(x)) n_face: the staircase's own exact data (control) */
} cv_fem_traction;

/** Settings shared by every run of a study. */
typedef struct cv_setup {
  cv_problem problem;
  double radius;         /* hemisphere radius (centre 0, flat face on y = 0) */
  int geom_n;            /* fcm_geometry_create_hemisphere resolution (24 n^3 tets) */
  double young, poisson; /* linear elastic material */
  int strength;          /* cut-cell stiffness strength; -1: the element default */
  int surface_strength;  /* surface rules (FCM traction, FEM staircase faces); -1: default */
  int simplify;          /* FCM cut-cell rules simplified (1) or not (0) */
  double stab_alpha;     /* stabilization weight factor; 0: off */
  double min_fraction;   /* FCM: cells with phi below this are dropped */
  int error_strength;    /* strength of the error-norm rules */
  cv_fem_traction fem_traction;
  int ref_refine; /* reference mode: uniform 8-splits of the geometry tets */
  int verbose;
} cv_setup;

/** One run: an element type at one resolution with one method. */
typedef struct cv_result {
  fcm_element_type element;
  cv_method method;
  int res; /* cells per unit length; h = 1 / res */
  double h;
  int strength; /* stiffness strength of the cut cells (FCM), of the full cells (FEM) */
  fcm_index dofs;
  fcm_index active_cells, cut_cells;
  fcm_index points;  /* stiffness quadrature points stored for the active cells */
  double t_rules;    /* FCM: cell rules; FEM: centroid classification */
  double t_assembly; /* space, pattern, stiffness, loads, Dirichlet elimination */
  double t_solve;    /* CHOLMOD analyze + factor + solve */
  double t_total;    /* sum of the three */
  double c_rules, c_assembly, c_solve, c_total; /* the same in process CPU seconds */
  double err_l2, err_h1;   /* ||u_h - u||_L2, |u_h - u|_H1 over the measured domain */
  double norm_l2, norm_h1; /* ||u||_L2, |u|_H1 over the same domain */
  double measured_volume;  /* volume the errors were integrated over */
  double domain_volume;    /* |Omega| (the polyhedron) */
  int failed;              /* 1: the run failed (message in `note`) */
  char note[160];
} cv_result;

/** The study's fixed objects: context, embedded geometry, exact/reference solution. */
typedef struct cv_study cv_study;

/** Create the study: the hemisphere geometry, its lookup structures and, in reference
 * mode, the boundary-conforming Tet10 reference solution (progress on stderr). */
fcm_status cv_study_create(fcm_ctx *ctx, const cv_setup *setup, cv_study **study);
void cv_study_destroy(cv_study **study);
const fcm_geometry *cv_study_geometry(const cv_study *study);
/** Reference mode: DOFs and seconds of the reference solve (0 otherwise). */
void cv_study_reference_info(const cv_study *study, fcm_index *dofs, double *seconds);

/** Per-run overrides (e.g. the m-sweep's strength); a NULL pointer means none. */
typedef struct cv_run_options {
  int strength; /* FCM cut-cell stiffness strength; -1 the element's default, -2 the setup's */
  int simplify; /* 0 or 1; -1: the setup's */
} cv_run_options;

/** Solve one (element, res, method) problem and measure its errors; the error rules of the
 * embedded geometry on the mesh are built once per mesh and passed in `err_rules`
 * (cv_error_rules_create). A failure of the discretization (a singular matrix) is recorded
 * in res->failed / res->note and returns FCM_OK; other errors are returned. */
fcm_status cv_run(cv_study *study, const fcm_mesh *mesh, const fcm_cell_rules *err_rules,
                  cv_method method, const cv_run_options *ro, cv_result *res);

/** High-strength rules of the geometry on `mesh` for the error norms (no simplification,
 * no stabilization, only empty cells dropped). */
fcm_status cv_error_rules_create(cv_study *study, const fcm_mesh *mesh, fcm_cell_rules **rules);

/** The background box [-1,1] x [0,1] x [-1,1] with res cells per unit length. */
fcm_status cv_mesh_create(fcm_ctx *ctx, fcm_element_type type, int res, fcm_mesh **mesh);

/** The manufactured displacement, its gradient G[3*i + j] = du_i/dx_j and the body force
 * b = -div sigma(u) for the Lame parameters (lambda, mu). */
void cv_exact(const double x[3], double u[3], double G[9]);
void cv_exact_body_force(double lambda, double mu, const double x[3], double b[3]);

/** Least-squares slope of log(err) against log(h) over n points; NaN when n < 2. */
double cv_fit_rate(int n, const double *h, const double *err);

/* ---------------------------------------------------------------- output (fcm-converge-output.c)
 */

/** A fitted rate: element x method x norm over the finest `levels` successful levels. */
typedef struct cv_rate {
  fcm_element_type element;
  cv_method method;
  int norm; /* 0: L2, 1: H1 */
  double rate;
  int levels;   /* levels used in the fit */
  int monotone; /* 1: the error decreased at every refinement (all levels) */
  double h_min, h_max;
} cv_rate;

/** Fit the rates of every (element, method, norm) present in `res` over the finest `fit`
 * successful levels; writes at most 16 entries into `rates`, returns their number. */
int cv_rates_compute(const cv_result *res, int nres, int fit, cv_rate *rates);

const char *cv_method_name(cv_method m);

/** Tables on stdout: levels, rates, accuracy versus time. */
void cv_print_levels(FILE *f, const cv_result *res, int nres);
void cv_print_rates(FILE *f, const cv_rate *rates, int nrates);
/** cpu: 1 ranks by process CPU seconds, 0 by wall-clock seconds. */
void cv_print_pareto(FILE *f, const cv_result *res, int nres, int cpu);
/** The m-sweep table. */
void cv_print_sweep(FILE *f, const cv_result *res, int nres);

/** CSV files, written atomically (FILE.tmp, rename); return 1 on success (message on
 * stderr otherwise). */
int cv_write_levels_csv(const char *path, const cv_result *res, int nres);
int cv_write_rates_csv(const char *path, const cv_rate *rates, int nrates);
int cv_write_sweep_csv(const char *path, const cv_result *res, int nres);

/** gnuplot availability (1) — 0 prints a message naming the package once. */
int cv_have_gnuplot(void);
/** PNG plots through gnuplot, atomically; return 1 on success. */
int cv_plot_convergence(const char *path, const cv_result *res, int nres, const cv_rate *rates,
                        int nrates, const char *title);
int cv_plot_pareto(const char *path, const cv_result *res, int nres, int cpu, const char *title);
int cv_plot_sweep(const char *path, const cv_result *res, int nres, const char *title);

#endif /* FCM_CONVERGE_STUDY_H */
