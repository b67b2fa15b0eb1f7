/* fcm-models: what a real surface model costs on the surface path (the defaults: no volume
 * mesh, cut-cell moments from the boundary triangles) against the volume path (a Gmsh volume
 * mesh and sub-tet rules), each configuration run in its own process; and the ball study
 * (rule time against cut cells on a ball whose surface refines with the grid). Shared types of
 * apps/fcm-models*.c. */
#ifndef FCM_APPS_MODELS_H
#define FCM_APPS_MODELS_H

#include <fcm/fcm.h>

#include <stdio.h>

#define PROG "fcm-models"

/** Models, cell sizes and ball sizes a run can hold. */
#define MODELS_MAX_MODELS 16
#define MODELS_MAX_SIZES  16
#define MODELS_MAX_BALL   16
/** Largest mass strength whose global moments are compared: (s+1)(s+2)(s+3)/6 monomials. */
#define MODELS_MAX_STRENGTH 10
#define MODELS_MAX_MOMENTS  286

/** The two configurations of a model: the defaults, and the volume mesh with sub-tet rules. */
enum { PATH_NEW = 0, PATH_OLD = 1, NPATH };

/** One model to measure: a file (after --scale, with --fill-holes), or a generated one. */
typedef struct model_input {
  char name[64];       /* "bumpy", "pebble" or the file's stem */
  char path[4096];     /* the OBJ/STL/OFF/PLY file (absolute) */
  double lo[3], hi[3]; /* its bounding box after the scale */
  double scale;        /* applied by the scene's transform */
  int fill_holes;      /* the scene's fill_holes */
} model_input;

/** What one configuration measured (written by the child process through a pipe). */
typedef struct model_run {
  int ran; /* 1: the configuration ran (0: skipped, see note) */
  int ok;  /* 1: set-up and every step succeeded */
  char note[256];
  double t_geometry, t_rules, t_space, t_integrator, t_setup; /* set-up phases, seconds */
  long long cells, cut_cells, dofs;
  double points_initial[2], points_final[2]; /* per cut cell: stiffness, mass */
  int strength[2];                           /* stiffness, mass */
  double peak_mb;                            /* VmHWM of the process */
  long long steps;
  double step_s, assembly_s, factor_s, solve_s, log_s; /* per step */
  double wall;                                         /* the whole child, seconds */
  int num_moments;                                     /* monomials up to the mass strength */
  double volume;                                       /* moment 1 in scaled coordinates */
  double moments[MODELS_MAX_MOMENTS];                  /* of the mass rules over the whole body */
} model_run;

/** One (model, cell size) pair: both configurations and the moments compared. */
typedef struct model_pair {
  int model;
  double h;
  model_run run[NPATH];
  double moment_diff; /* max |m_new - m_old| / |volume|, -1 when not both ran */
} model_pair;

/** One size of the ball study. */
typedef struct ball_row {
  int n; /* cells across the ball */
  long long triangles, cells, cut_cells;
  double rules_s;      /* fcm_cell_rules_create() wall time */
  double points_final; /* stiffness + mass points per cut cell */
  int strength[2];     /* stiffness, mass */
  int ok;
  char note[160];
} ball_row;

/** Everything the command line asked for. */
typedef struct models_settings {
  model_input models[MODELS_MAX_MODELS];
  int nmodels;
  double sizes[MODELS_MAX_SIZES];
  int nsizes;
  fcm_element_type element;
  int steps;
  int fill_holes;
  double scale;
  long long bumpy_triangles;
  int new_only; /* --new-only: skip the volume path */
  int ball_study, quick;
  const char *csv, *png;
} models_settings;

/* ---- fcm-models-run.c: one configuration, generated surfaces, the ball study */

/** Write the bumpy sphere (radius about 0.5 m around the origin, about `triangles` triangles)
 * as an OBJ to `path`; 1 on success, 0 with a message. */
int models_write_bumpy(const char *path, long long triangles);

/** Run one configuration in this process and fill *r (the child's work). */
void models_run_config(const model_input *m, double h, fcm_element_type element, int path,
                       int steps, model_run *r);

/** The ball study on the sizes n[0..count); rows into out. 1 when every size ran. */
int models_ball_study(const int *n, int count, fcm_element_type element, ball_row *out);

/** Least-squares slope of log y against log x over the rows with x, y > 0 (NaN with < 2). */
double models_fit_exponent(const double *x, const double *y, int count);

/* ---- fcm-models-output.c: table, CSV, PNG */

void models_print_header(void);
void models_print_pair(const models_settings *o, const model_pair *p);
int models_write_csv(const models_settings *o, const model_pair *pairs, int npairs);
int models_write_png(const models_settings *o, const model_pair *pairs, int npairs);
int models_write_ball_png(const char *path, const ball_row *rows, int count, double exponent);
int models_write_ball_csv(const char *path, const ball_row *rows, int count);

#endif /* FCM_APPS_MODELS_H */
