/* fcm scene, internal part: the JSON tree adapter (cJSON is touched only in
 * json_adapter.c), the typed readers that name JSON paths in errors, the section parsers with
 * the name tables they share with the summary, and the effect table. */
#ifndef FCM_SCENE_IMPL_H
#define FCM_SCENE_IMPL_H

#include "core/core_impl.h"
#include "fcm/scene.h"
#include "fcm/simulation.h"

#include <math.h>

/* ---------------------------------------------------------------- JSON tree */

/* A node of a parsed JSON document (a cJSON item underneath). */
typedef struct fcm__json fcm__json;

typedef enum fcm__json_kind {
  FCM__JSON_NULL = 0,
  FCM__JSON_BOOL,
  FCM__JSON_NUMBER,
  FCM__JSON_STRING,
  FCM__JSON_ARRAY,
  FCM__JSON_OBJECT,
  FCM__JSON_INVALID
} fcm__json_kind;

/* Parse `length` bytes of `text` (NUL-terminated at text[length]). On failure returns
 * NULL and sets *error_offset to the byte offset where parsing stopped. The tree is
 * allocated with malloc by the parser library; release it with fcm__json_delete(). */
fcm__json *fcm__json_parse(const char *text, size_t length, size_t *error_offset);
void fcm__json_delete(fcm__json *root);

fcm__json_kind fcm__json_get_kind(const fcm__json *node);
/* Member name of an object member, NULL otherwise. */
const char *fcm__json_key(const fcm__json *node);
/* Value of a number (inf for overflowing literals such as 1e999). */
double fcm__json_number(const fcm__json *node);
int fcm__json_bool(const fcm__json *node);
const char *fcm__json_string(const fcm__json *node);
/* First child of an array or object, and the next sibling; NULL at the end. */
const fcm__json *fcm__json_child(const fcm__json *node);
const fcm__json *fcm__json_next(const fcm__json *node);
/* Number of children of an array or object. */
int fcm__json_size(const fcm__json *node);
/* Member of an object by exact (case-sensitive) name, the first one; NULL if absent. */
const fcm__json *fcm__json_member(const fcm__json *object, const char *key);

/* The normalized scene tree (json_adapter.c): an object to which the parser adds every value
 * it reads, at its JSON path ("effects[2].motion.end"), with the defaults it fills in. put_*
 * replace what is at the path; put_copy puts a copy of an input value only where nothing is
 * yet (a section the readers then complete). They return 0 when an allocation failed. */
fcm__json *fcm__json_new_object(void);
/* An object without members: what a section parser reads when the section is absent, so that
 * its defaults are recorded too. */
const fcm__json *fcm__json_empty_object(void);
/* Remove the value at `path` of the normalized tree, if there is one. */
void fcm__json_remove_path(fcm__json *root, const char *path);
int fcm__json_put_copy(fcm__json *root, const char *path, const fcm__json *value);
int fcm__json_put_number(fcm__json *root, const char *path, double x);
int fcm__json_put_bool(fcm__json *root, const char *path, int b);
int fcm__json_put_string(fcm__json *root, const char *path, const char *s);
int fcm__json_put_numbers(fcm__json *root, const char *path, const double *x, int n);
/* The tree as indented JSON text (malloc'd: fcm__json_free_text()), NULL on failure. */
char *fcm__json_print(const fcm__json *root);
void fcm__json_free_text(char *text);

/* ---------------------------------------------------------------- the scene */

typedef struct fcm__scene_block fcm__scene_block;

struct fcm_scene {
  fcm_ctx *ctx;
  fcm__scene_block *blocks; /* every allocation owned by the scene, freed at destroy */
  const char *name, *description, *source;
  const char *json; /* the normalized scene (fcm_scene_json()) */
  fcm_scene_background background;
  fcm_scene_geometry geometry;
  fcm_material material;
  fcm_scene_quadrature quadrature;
  fcm_scene_solver solver;
  fcm_scene_time time;
  fcm_scene_output output;
  int num_effects;
  fcm_effect *effects;
};

/* Zeroed array of n elements of `size` bytes owned by the scene (freed with it). Records
 * FCM_ERR_ALLOC and returns NULL on failure. */
void *fcm__scene_alloc(fcm_scene *scene, size_t n, size_t size);

/* ---------------------------------------------------------------- the parser */

#define FCM__SCENE_PATH_LEN 256

/* State of one parse: where errors go and the JSON path of the value being read. */
typedef struct fcm__scene_parser {
  fcm_ctx *ctx;
  fcm_scene *scene;
  const char *source;   /* name in messages */
  const char *base_dir; /* prefix for relative file names ("" or ending in '/') */
  char path[FCM__SCENE_PATH_LEN];
  size_t path_len;
  fcm__json *norm; /* the normalized tree (NULL: not recorded) */
  int norm_failed; /* an allocation of the normalized tree failed */
} fcm__scene_parser;

/* Record an error "<source>: <path>: <message>" (or "<source>: <message>" at the root). */
fcm_status fcm__scene_error(fcm__scene_parser *p, fcm_status code, const char *file, int line,
                            const char *func, const char *fmt, ...) FCM__PRINTF(6, 7);

/* FCM_CHECK with the JSON path of the parser in the message. */
#define SCENE_CHECK(cond, p, code, ...)                                                            \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      st = fcm__scene_error((p), (code), __FILE__, __LINE__, __func__, __VA_ARGS__);               \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)

/* Append ".key" (or "key" at the root) or "[i]" to the path; return the old length to
 * pass to fcm__scene_path_pop(). */
size_t fcm__scene_path_push_key(fcm__scene_parser *p, const char *key);
size_t fcm__scene_path_push_index(fcm__scene_parser *p, int index);
void fcm__scene_path_pop(fcm__scene_parser *p, size_t old_len);

/* Remove the value at the parser's path + key from its normalized tree: a key whose absence
 * means something no value of it says (an initial velocity's "center": the centre of mass). */
void fcm__scene_forget(fcm__scene_parser *p, const char *key);

/* The normalized scene's "time" section as resolved (t): static or the integrator with its
 * parameter ("alpha" of "hht", "rho_inf" of "generalized_alpha"), dt, the step count, and for
 * static scenes the load steps (the parser is at the root). */
void fcm__scene_put_resolved_time(fcm__scene_parser *p, const fcm_scene_time *t);

/* Short description of a JSON value for messages: 3.5, "text", true, null, an array, ... */
void fcm__scene_describe(const fcm__json *node, char *buf, size_t len);

/* A closed, open or half-open interval of numbers; +-HUGE_VAL for none. */
typedef struct fcm__range {
  double lo, hi;
  int lo_open, hi_open;
} fcm__range;

/* Ranges used often. */
#define FCM__ANY         ((fcm__range){-HUGE_VAL, HUGE_VAL, 1, 1})
#define FCM__POSITIVE    ((fcm__range){0.0, HUGE_VAL, 1, 1})
#define FCM__NONNEGATIVE ((fcm__range){0.0, HUGE_VAL, 0, 1})

/* "a finite number > 0", "a finite number in (-1, 0.5)", ... */
void fcm__scene_range_text(fcm__range r, char *buf, size_t len);

/* Any kind: the reader checks the node itself (numbers, with their range in the message). */
#define FCM__SCENE_ANY_KIND FCM__JSON_INVALID

/* The one field lookup of the typed readers: the member `key` of obj.
 * Absent: *out = NULL and FCM_OK, or, when required, "missing; expected <want>" at path.key.
 * Present: the path is extended by key and left so for the caller's further checks (the
 * caller pops back to the length it saved on entry); unless kind is FCM__SCENE_ANY_KIND the
 * member must be of that kind, and an array of exactly `len` entries when len >= 0, else
 * "expected <want>, got <what it is>". On an error *out is NULL. */
fcm_status fcm__scene_field(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                            int required, const char *want, fcm__json_kind kind, int len,
                            const fcm__json **out);

/* The typed readers. Each reads member `key` of `obj`: when the member is absent and
 * `required` is 0 the output keeps the value the caller put there (the default); when it
 * is absent and required, or present with the wrong type or out of range, it fails with
 * FCM_ERR_ARG naming the JSON path, the allowed values and what it got. */
fcm_status fcm__scene_read_number(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, fcm__range range, double *out);
fcm_status fcm__scene_read_int(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                               int required, long long lo, long long hi, long long *out);
fcm_status fcm__scene_read_bool(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                int required, int *out);
/* true (1), false (0) or the string `word` (word_value). */
fcm_status fcm__scene_read_bool_or_word(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                        int required, const char *word, int word_value, int *out);
/* String copied into the scene; non-empty, no control characters. */
fcm_status fcm__scene_read_string(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, const char **out);
/* Array of 3 numbers, each in `range`. */
fcm_status fcm__scene_read_vec3(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                int required, fcm__range range, double out[3]);
/* Array of 3 integers in [lo, hi]. */
fcm_status fcm__scene_read_ivec3(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                 int required, long long lo, long long hi, fcm_index out[3]);
/* One of `n` names; *out is its index. */
fcm_status fcm__scene_read_choice(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, const char *const *names, int n, int *out);
/* A member that must be an object; *out NULL when absent and optional. */
fcm_status fcm__scene_read_object(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, const fcm__json **out);
/* A file name resolved against the scene's directory and copied into the scene; the file
 * must be a readable regular file (FCM_ERR_IO naming the resolved path otherwise).
 * `suffix` (may be NULL) is appended to the name before the check (TetGen base names). */
fcm_status fcm__scene_read_file(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                int required, const char *suffix, const char **out);

/* `node` (at the current path) must be an object whose member names are all in
 * `allowed` (n names) and distinct; otherwise FCM_ERR_ARG listing the allowed names. */
fcm_status fcm__scene_check_object(fcm__scene_parser *p, const fcm__json *node,
                                   const char *const *allowed, int n);

/* Copy a string into the scene. */
fcm_status fcm__scene_strdup(fcm__scene_parser *p, const char *s, const char **out);

/* ---------------------------------------------------------------- the sections */

/* Number of entries of an array. */
#define SCENE_COUNT(a) ((int)(sizeof(a) / sizeof *(a)))

/* Read a choice into an enum of any integer type. */
#define SCENE_READ_CHOICE(p, obj, key, required, names, out)                                       \
  do {                                                                                             \
    int ch_ = (int)(out);                                                                          \
    FCM_TRY((p)->ctx, fcm__scene_read_choice((p), (obj), (key), (required), (names),               \
                                             SCENE_COUNT(names), &ch_));                           \
    (out) = ch_;                                                                                   \
  } while (0)

/* Read a choice given by names[i] into out = values[i] (the library's enum values, whose
 * order need not be the names' order). */
#define SCENE_READ_CHOICE_AS(p, obj, key, required, names, values, out)                            \
  do {                                                                                             \
    int ch_ = fcm__scene_choice_index((values), SCENE_COUNT(names), (int)(out));                   \
    FCM_TRY((p)->ctx, fcm__scene_read_choice((p), (obj), (key), (required), (names),               \
                                             SCENE_COUNT(names), &ch_));                           \
    if (ch_ >= 0) (out) = (values)[ch_]; /* an enum of the library */                              \
  } while (0)

/* The name of `value` in a names/values table (for the summary). */
#define SCENE_CHOICE_NAME(names, values, value)                                                    \
  fcm__scene_choice_name((names), (values), SCENE_COUNT(names), (int)(value))

/* Read an integer member into an int-like destination. */
#define SCENE_READ_INT(p, obj, key, required, lo, hi, out)                                         \
  do {                                                                                             \
    long long v_ = (long long)(out);                                                               \
    FCM_TRY((p)->ctx, fcm__scene_read_int((p), (obj), (key), (required), (lo), (hi), &v_));        \
    (out) = (int)v_;                                                                               \
  } while (0)

/* Push a key for the checks of one section; popped at cleanup by the caller's `old`. */
#define SCENE_ENTER(p, key) fcm__scene_path_push_key((p), (key))

/* The name of `value` among n names/values (the summary's names of library enums); "?" if none. */
const char *fcm__scene_choice_name(const char *const *names, const int *values, int n, int value);
/* The index of `value` among n values; -1 if none. */
int fcm__scene_choice_index(const int *values, int n, int value);

/* Names of the scene's choices (scene.c), read by the section parsers and printed by the
 * summary. Without a values table the index is the library's enum value. */
extern const char *const fcm__scene_element_names[4];        /* fcm_element_type */
extern const char *const fcm__scene_axis_names[3];           /* 0, 1, 2 */
extern const char *const fcm__scene_implicit_names[7];       /* fcm_implicit_kind */
extern const char *const fcm__scene_simplify_names[4];       /* fcm_simplify_method */
extern const char *const fcm__scene_moments_names[3];        /* fcm_cell_moments */
extern const char *const fcm__scene_stabilization_names[3];  /* fcm_stabilization_mode */
extern const char *const fcm__scene_solver_names[4];         /* with fcm__scene_solver_values */
extern const int fcm__scene_solver_values[4];                /* fcm_linear_solver */
extern const char *const fcm__scene_direct_names[2];         /* fcm_direct_method */
extern const char *const fcm__scene_preconditioner_names[5]; /* fcm_preconditioner */
extern const char *const fcm__scene_smoother_names[4];       /* with fcm__scene_smoother_values */
extern const int fcm__scene_smoother_values[4];              /* fcm_mg_smoother */
extern const char *const fcm__scene_clamp_names[2];          /* fcm_schwarz_clamp */
extern const char *const fcm__scene_tangent_names[3];        /* fcm_preconditioner_tangent */
extern const char *const fcm__scene_newton_rule_names[3];    /* with the values */
extern const int fcm__scene_newton_rule_values[3];           /* fcm_newton_tolerance */
extern const char *const fcm__scene_inversion_names[2];      /* stop_on_inversion 0, 1 */
extern const char *const fcm__scene_integrator_names[4];     /* with the values */
extern const int fcm__scene_integrator_values[4];            /* fcm_time_scheme */

/* The section parsers, in the order parse_root() calls them: each reads its member of the
 * root object (absent and optional: the defaults) into p->scene and validates it; "geometry"
 * after "background" (a level set samples the background grid), "solver" after it too
 * (multigrid needs a hex grid). parse_model.c: background, geometry, material;
 * parse_solver.c: quadrature, solver, time, output. */
fcm_status fcm__scene_read_background(fcm__scene_parser *p, const fcm__json *root);
fcm_status fcm__scene_read_geometry(fcm__scene_parser *p, const fcm__json *root);
fcm_status fcm__scene_read_material(fcm__scene_parser *p, const fcm__json *root);
fcm_status fcm__scene_read_quadrature(fcm__scene_parser *p, const fcm__json *root);
fcm_status fcm__scene_read_solver(fcm__scene_parser *p, const fcm__json *root);
fcm_status fcm__scene_read_time(fcm__scene_parser *p, const fcm__json *root);
fcm_status fcm__scene_read_output(fcm__scene_parser *p, const fcm__json *root);

/* ---------------------------------------------------------------- regions and effects */

/* Parse a region object at member `key` of obj (absent and optional: kind ALL). With
 * `allow_nodes` 0 a node set is rejected (surface effects need positions). */
fcm_status fcm__scene_read_region(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, int allow_nodes, fcm_region *out);

/* The one effect table: each effect type has a name, a parser/validator that fills the
 * union member of an fcm_effect from the effect's parameter object (the path already ends
 * in "effects[i].<name>"), scene-level rules, and a summary printer. The simulation
 * pipeline attaches its contribution hooks (setup, per-step constraints and forces) to
 * this same table, so that only the effects named in a scene are computed. */
/* What an effect needs the pipeline to build (flags of fcm__effect_type.needs). */
enum { FCM__NEEDS_SURFACE_RULES = 1 /* surface rules on the cut cells */ };

/* State the initialize hooks share (run.c): the velocity being built and the body's
 * centre of mass in the reference configuration. */
typedef struct fcm__effect_init {
  double *v;
  double com[3];
} fcm__effect_init;

/* An effect module: parsing and printing (effects*.c), what it needs from the pipeline,
 * and the hooks through which the scene runner (run.c) lets it contribute. A NULL hook means
 * the effect has nothing to do at that stage. */
typedef struct fcm__effect_type {
  fcm_effect_type type;
  const char *name;
  const char *summary; /* one line for documentation and listings */
  int max_count;       /* 0: any number per scene; else at most this many */
  int allowed_static;  /* 0: an error in a static scene (needs inertia) */
  fcm_status (*parse)(fcm__scene_parser *p, const fcm__json *params, fcm_effect *effect);
  void (*view)(const fcm_effect *effect, FILE *stream);
  unsigned needs; /* FCM__NEEDS_* */
  /* before the integrator exists: adjust its options (e.g. damping coefficients) */
  void (*configure)(const fcm_effect *effect, fcm_integrator_options *opts);
  /* before the integrator's setup: add energy/force terms (loads) or constraints */
  fcm_status (*apply)(fcm_simulation *sim, const fcm_effect *effect);
  /* after the setup, dynamic scenes: set the initial state */
  fcm_status (*initialize)(fcm_simulation *sim, const fcm_effect *effect, fcm__effect_init *init);
} fcm__effect_type;

/* The run-time hooks (run.c). */
void fcm__effect_configure_damping(const fcm_effect *effect, fcm_integrator_options *opts);
fcm_status fcm__effect_apply_gravity(fcm_simulation *sim, const fcm_effect *effect);
fcm_status fcm__effect_apply_constraint(fcm_simulation *sim, const fcm_effect *effect);
fcm_status fcm__effect_apply_surface_load(fcm_simulation *sim, const fcm_effect *effect);
fcm_status fcm__effect_apply_contact(fcm_simulation *sim, const fcm_effect *effect);
fcm_status fcm__effect_initialize_velocity(fcm_simulation *sim, const fcm_effect *effect,
                                           fcm__effect_init *init);

/* Entry of `type`, or NULL; entry by name, or NULL. */
const fcm__effect_type *fcm__scene_effect_type(fcm_effect_type type);
const fcm__effect_type *fcm__scene_effect_type_find(const char *name);

/* The optional "transform" member of o (scale, rotation, translation) into x -> A x + b;
 * *has = 1 when present (A, b untouched otherwise). */
fcm_status fcm__scene_read_transform(fcm__scene_parser *p, const fcm__json *o, double A[9],
                                     double b[3], int *has);

/* Parse the "effects" array (absent: no effects) into p->scene. */
fcm_status fcm__scene_read_effects(fcm__scene_parser *p, const fcm__json *root);

/* Print a region on one line (no newline). */
void fcm__scene_region_view(const fcm_region *r, FILE *stream);

/* Time window members "start" (>= 0, default 0) and "end" (> start, default HUGE_VAL) of
 * obj; its printer (", t in [a, b] s", ", from t = a s" or nothing). (effects_region.c) */
fcm_status fcm__scene_read_window(fcm__scene_parser *p, const fcm__json *obj, double *start,
                                  double *end);
void fcm__scene_view_window(double start, double end, FILE *stream);

/* A rigid motion's "velocity", "rotation" {"axis", "center", "speed"} and window ("start",
 * "end") of o into m (its other members untouched). (effects_region.c) */
fcm_status fcm__scene_read_rigid_motion(fcm__scene_parser *p, const fcm__json *o, fcm_motion *m);

/* The cut and contact effects' parsers and printers (effects_contact.c). */
fcm_status fcm__effect_parse_cut(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e);
void fcm__effect_view_cut(const fcm_effect *e, FILE *stream);
fcm_status fcm__effect_parse_contact(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e);
void fcm__effect_view_contact(const fcm_effect *e, FILE *stream);

#endif /* FCM_SCENE_IMPL_H */
