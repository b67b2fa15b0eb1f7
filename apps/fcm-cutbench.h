/* fcm-cutbench: the cutting scenarios of three papers (Dick et al. 2011, Koschier et al. 2017,
 * Ton-That et al. 2024) as scenes, run through the scene runner, with each cut's latency split
 * by phase and the step times beside the papers' figures. Shared types of apps/fcm-cutbench*.c. */
#ifndef FCM_APPS_CUTBENCH_H
#define FCM_APPS_CUTBENCH_H

#include <fcm/fcm.h>

#include <stdio.h>

#define PROG "fcm-cutbench"

/** Cut events (cuts applied before one step) a scenario can have. */
#define CUTBENCH_MAX_EVENTS 16

/** The rows: each scenario of a paper's table. */
typedef enum cutbench_row_id {
  ROW_DICK_BUNNY3 = 0,   /* Dick 2011 Table 1, Bunny 3 */
  ROW_DICK_BUNNY2,       /* Bunny 2 */
  ROW_DICK_BUNNY,        /* Bunny */
  ROW_KOSCHIER_BUNNY,    /* Koschier 2017 §7, the groove carved and peeled */
  ROW_KOSCHIER_PLATE,    /* Koschier 2017 §7, the plate with attached objects, bumpy cut */
  ROW_TONTHAT_SLAB,      /* Ton-That 2024 Table 2, the thinly cut slab */
  ROW_TONTHAT_ACCORDION, /* Ton-That 2024 Table 2, the hanging cube cut into an accordion */
  ROW_TONTHAT_OCTOPUS,   /* Ton-That 2024 Table 2, the octopus: mouth, jaw, tentacles */
  ROW_COUNT
} cutbench_row_id;

/** A paper's figures for one row (the constant table in fcm-cutbench-scenes.c). */
typedef struct cutbench_paper {
  const char *row;      /* the row's name: "dick-bunny3" */
  const char *paper;    /* "Dick 2011 Table 1" */
  const char *model;    /* "Bunny 3" */
  const char *size;     /* "5.48k -> 8.27k hexahedra" */
  double size_target;   /* what fcm's row is sized to: active cells (Dick) or DOFs */
  int size_is_cells;    /* 1: size_target counts cells, 0: DOFs */
  double cut_s;         /* the paper's cut latency (s); 0: not published */
  double step_s;        /* the paper's mean step (s) */
  double step_max_s;    /* the paper's largest step (s); 0: not published */
  double step_factor;   /* the target: fcm's mean step <= step_factor * step_s */
  const char *machine;  /* the paper's machine and method */
  const char *element;  /* fcm's element */
  const char *material; /* fcm's material model */
  int quick;            /* 1: --quick runs this row (the smallest of each paper) */
} cutbench_paper;

/** The papers' rows, ROW_COUNT entries. */
extern const cutbench_paper cutbench_papers[ROW_COUNT];

/** The body: a closed triangle surface and its measures. */
typedef struct cutbench_model {
  char path[4096];     /* the surface file (absolute) */
  char name[64];       /* "lobed" (generated) or the file's stem */
  int fill_holes;      /* the scene's geometry.fill_holes */
  double lo[3], hi[3]; /* bounding box */
  double volume, area; /* enclosed volume, surface area */
  long long triangles; /* triangles of the rows' generated bodies (plate, octopus) */
} cutbench_model;

/** A scenario written out: the scene file (and its cut surfaces beside it). */
typedef struct cutbench_scene {
  char json_path[4096];
  double h;                            /* the background's cell size */
  int steps;                           /* steps the row runs */
  int events;                          /* cut events */
  int event_step[CUTBENCH_MAX_EVENTS]; /* the step (1-based) each event precedes */
} cutbench_scene;

/** A text grown printf-style in a fixed buffer (scene files, gnuplot scripts); ok drops to 0
 * when it would overflow. */
typedef struct cutbench_text {
  char s[1 << 16];
  size_t n;
  int ok;
} cutbench_text;

/** Append to t (nothing once t->ok is 0). */
void cutbench_put(cutbench_text *t, const char *fmt, ...);

/** Write the generated bunny-like surface (a closed, outward-oriented star-shaped surface
 * with a body, a head, two ears and a tail, about 0.16 m long, its base at y = 0) with about
 * `triangles` triangles to `path`; 1 on success, 0 with a message. */
int cutbench_write_lobed(const char *path, long long triangles);

/** Read the model's bounding box, volume and area; 0 with a message. */
int cutbench_model_measure(fcm_ctx *ctx, cutbench_model *m);

/** Write row `row`'s scene into directory `dir` (the scene `<dir>/<name>.json`, its cut
 * surfaces `<dir>/<surf_dir>/<name>_cut<k>.obj`): sized to `scale` times the paper's size,
 * the body `body` (a path as the scene will name it: relative to dir, or absolute), Dick's
 * blades pushed in `dick_events` cut events (1 to CUTBENCH_MAX_EVENTS; the other rows have
 * their own), `solver` the members of the scene's solver object ("" for the defaults). 1 on
 * success. */
int cutbench_write_scene(cutbench_row_id row, const cutbench_model *m, const char *body,
                         double scale, int dick_events, const char *solver, const char *dir,
                         const char *surf_dir, const char *name, cutbench_scene *out);

/** What one run of a row's scene measured. */
typedef struct cutbench_run {
  int ran, ok;
  int skipped; /* the option set is not a valid scene solver for this build (see note) */
  char note[256];
  double setup_s;  /* fcm_simulation_create() */
  long long cells; /* active background cells */
  long long dofs_before, dofs_after;
  int events;               /* cut events applied */
  double cut_mean, cut_max; /* one event's latency: rules + space + integrator */
  double cut_rules, cut_space, cut_integ, cut_other; /* per event, mean */
  double cut_solver; /* the new linear solver's structure (analysis or hierarchy without
                        values), per event, mean */
  double cut_factor; /* the factorization (or the hierarchy's first set-up) of the step after
                        a cut, mean over the events */
  long long steps;
  double step_mean, step_max;        /* wall seconds of a step, the cuts before it excluded */
  double newton, linear;             /* per step, mean */
  double *u;                         /* the final displacement (malloc'd), for the comparison */
  long long n;                       /* its length */
  int runs;                          /* the runs the figures are the medians of (--repeat) */
  double cut_max_lo, cut_max_hi;     /* the largest cut's range over the runs */
  double step_mean_lo, step_mean_hi; /* the mean step's range over the runs */
} cutbench_run;

/** One row: the paper's figures, the default run and the interactive one (when an option set
 * is given), the displacement difference between them. */
typedef struct cutbench_row {
  cutbench_row_id id;
  double h;              /* the cell size used */
  cutbench_run run[2];   /* 0: the accurate defaults, 1: the interactive option set */
  char interactive[512]; /* the option set ("" for none): members of "solver" */
  double disp_diff;      /* max |u_default - u_interactive| (m); -1 when not both ran */
  double disp_max;       /* max |u_default| (m) */
} cutbench_row;

/* ---- shared by the scene writers (fcm-cutbench-scenes.c, fcm-cutbench-bodies.c) */

/** A triangle soup written as an OBJ; ok drops to 0 when out of memory. */
typedef struct soup {
  double *x;
  long long nv, nt, capv, capt;
  long long *t;
  int ok;
} soup;

long long soup_vertex(soup *s, const double p[3]);
void soup_triangle(soup *s, long long a, long long b, long long c);
/** A patch p(u, v), (u, v) in [0,1]^2, as an nu x nv grid of quads, two triangles each. */
typedef void (*patch_fn)(double u, double v, const double *par, double p[3]);
void soup_patch(soup *s, patch_fn f, const double *par, int nu, int nv);
/** An axis-aligned rectangle in the plane x_axis = value, spanning [lo, hi] on the others. */
void soup_rect(soup *s, int axis, double value, const double lo[3], const double hi[3]);
int soup_write(soup *s, const char *path);
/** Free the soup's arrays and make it empty (ok again). */
void soup_clear(soup *s);
/** The soup's bounding box, enclosed volume and area into m (a closed surface). */
void soup_measure(const soup *s, cutbench_model *m);
/** Write the soup as the cut surface of event k: <dir>/<surf_dir>/<name>_cut<k+1>.obj, then
 * clear it. */
int write_event(soup *s, const char *dir, const char *surf_dir, const char *name, int k);

/** The cell size at which a body of volume V and area A has about n cells (c = 0.75) or nodes
 * of active cells (c = 2.0). */
double size_for(double V, double A, double n, double c);
/** The box [0, L]'s cell size whose grid (half a cell around it) has 3 x nodes nearest `dofs`,
 * its cells per axis into n. */
double slab_size(double dofs, const double L[3], fcm_index n[3]);
/** The scene's head: name, description, background (fitted grid for a surface body m), body,
 * material, solver, time; then the start of the effects list. */
void scene_head(cutbench_text *t, const char *name, const char *desc, const cutbench_model *m,
                const char *body, double h, const char *material, double young, double poisson,
                const char *solver, double dt, int steps);
/** Insert `text` before the first occurrence of `key` in t; 0 (and t->ok 0) when key is
 * missing or the text does not fit. */
int scene_insert(cutbench_text *t, const char *key, const char *text);
/** Insert the background grid of the box [0, L] (n cells of size h per axis, half a cell
 * around it) and the box geometry before the scene's material; 0 when it does not fit. */
int scene_box_grid(cutbench_text *t, const double L[3], double h, const fcm_index n[3]);
/** The cut effects of sc (event k at the start of step event_step[k]) and the scene's end. */
void scene_cuts(cutbench_text *t, const cutbench_scene *sc, const char *surf_dir, const char *name,
                double dt);

/** Rows with a generated body of their own (fcm-cutbench-bodies.c): write the body, the cut
 * surfaces and the scene text into t (the plate, the accordion, the octopus); 1 on success. */
int cutbench_koschier_plate(cutbench_text *t, const cutbench_paper *p, double scale,
                            long long triangles, const char *solver, const char *dir,
                            const char *surf_dir, const char *name, cutbench_scene *sc);
int cutbench_tonthat_accordion(cutbench_text *t, const cutbench_paper *p, double scale,
                               const char *solver, const char *dir, const char *surf_dir,
                               const char *name, cutbench_scene *sc);
int cutbench_tonthat_octopus(cutbench_text *t, const cutbench_paper *p, double scale,
                             long long triangles, const char *solver, const char *dir,
                             const char *surf_dir, const char *name, cutbench_scene *sc);

/* ---- fcm-cutbench-output.c: table, CSV, PNG */

/** The run a row's targets are judged on: the interactive one when it ran, else the default. */
const cutbench_run *cutbench_judged(const cutbench_row *r);

void cutbench_print_header(void);
void cutbench_print_row(const cutbench_row *r);
/** The verdict lines after the table; returns the number of rows whose targets fail. */
int cutbench_print_verdicts(const cutbench_row *rows, int n);
int cutbench_write_csv(const char *path, const cutbench_row *rows, int n);
int cutbench_write_png(const char *path, const cutbench_row *rows, int n);

#endif /* FCM_APPS_CUTBENCH_H */
