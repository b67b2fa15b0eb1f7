/* Scene objects: ownership, the name tables of the scene keys, reading a scene file (the
 * sections are parsed in parse_model.c and parse_solver.c, the effects in effects.c) and the
 * accessors. The summary printed by fcm_scene_view() is in view.c. */
#define _POSIX_C_SOURCE 200809L
#include "scene/scene_impl.h"

#include <stdalign.h>
#include <stddef.h>
#include <string.h>

/* ---------------------------------------------------------------- ownership */

struct fcm__scene_block {
  fcm__scene_block *next;
  alignas(max_align_t) unsigned char data[];
};

void *fcm__scene_alloc(fcm_scene *s, size_t n, size_t size)
{
  if (size != 0 && n > (SIZE_MAX - sizeof(fcm__scene_block)) / size) {
    fcm__error(s->ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
               "scene: allocation of %zu x %zu bytes overflows", n, size);
    return NULL;
  }
  fcm__scene_block *b = fcm__calloc(s->ctx, 1, sizeof *b + n * size);
  if (!b) return NULL;
  b->next = s->blocks;
  s->blocks = b;
  return b->data;
}

void fcm_scene_destroy(fcm_scene **scene)
{
  if (!scene || !*scene) return;
  fcm_scene *s = *scene;
  while (s->blocks) {
    fcm__scene_block *next = s->blocks->next;
    fcm__free(s->ctx, s->blocks);
    s->blocks = next;
  }
  fcm__free(s->ctx, s);
  *scene = NULL;
}

/* ---------------------------------------------------------------- name lists */

const char *const fcm__scene_element_names[] = {"tet4", "tet10", "hex8", "hex20"};
const char *const fcm__scene_axis_names[] = {"x", "y", "z"};
const char *const fcm__scene_implicit_names[] = {"sphere", "torus",        "box",       "gyroid",
                                                 "union",  "intersection", "difference"};
const char *const fcm__scene_simplify_names[] = {"auto", "lp", "recombine", "eliminate"};
const char *const fcm__scene_moments_names[] = {"auto", "volume", "surface"};
const char *const fcm__scene_stabilization_names[] = {"mass_stiffness", "mass", "off"};
const char *const fcm__scene_solver_names[] = {"direct", "minres", "cg", "multigrid"};
const int fcm__scene_solver_values[] = {FCM_LINEAR_DIRECT, FCM_LINEAR_MINRES, FCM_LINEAR_CG,
                                        FCM_LINEAR_MULTIGRID};
const char *const fcm__scene_direct_names[] = {"cholmod", "umfpack"};
/* in the order of fcm_preconditioner */
const char *const fcm__scene_preconditioner_names[] = {"none", "jacobi", "block_jacobi", "schwarz",
                                                       "multigrid"};
/* solver.multigrid.smoother ("sgs_colored" also accepted, as the other names are written) */
const char *const fcm__scene_smoother_names[] = {"sgs", "jacobi", "sgs-colored", "sgs_colored"};
const int fcm__scene_smoother_values[] = {FCM_MG_SMOOTHER_SGS, FCM_MG_SMOOTHER_JACOBI,
                                          FCM_MG_SMOOTHER_SGS_COLORED, FCM_MG_SMOOTHER_SGS_COLORED};
const char *const fcm__scene_clamp_names[] = {"clamp", "paper"};
/* in the order of fcm_preconditioner_tangent */
const char *const fcm__scene_tangent_names[] = {"projected", "linear", "exact"};
const char *const fcm__scene_newton_rule_names[] = {"auto", "representative", "relative"};
/* solver.on_inversion: fcm_scene_solver.stop_on_inversion 0 or 1 */
const char *const fcm__scene_inversion_names[] = {"warn", "stop"};
const int fcm__scene_newton_rule_values[] = {FCM_NEWTON_TOL_AUTO, FCM_NEWTON_TOL_REPRESENTATIVE,
                                             FCM_NEWTON_TOL_RELATIVE};
/* time.integrator: the dynamic schemes (fcm_time_scheme_name()) */
const char *const fcm__scene_integrator_names[] = {"backward_euler", "newmark", "hht",
                                                   "generalized_alpha"};
const int fcm__scene_integrator_values[] = {FCM_SCHEME_BACKWARD_EULER, FCM_SCHEME_NEWMARK,
                                            FCM_SCHEME_HHT, FCM_SCHEME_GENERALIZED_ALPHA};

const char *fcm__scene_choice_name(const char *const *names, const int *values, int n, int value)
{
  const int i = fcm__scene_choice_index(values, n, value);
  return i >= 0 ? names[i] : "?";
}

int fcm__scene_choice_index(const int *values, int n, int value)
{
  for (int i = 0; i < n; i++)
    if (values[i] == value) return i;
  return -1;
}

/* ---------------------------------------------------------------- the whole scene */

static int name_char(char c)
{
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.';
}

/* Whether a name is usable in file names: [A-Za-z0-9_.-], 1..64 characters, not "." or "..". */
static int valid_name(const char *s)
{
  size_t n = strlen(s);
  if (n == 0 || n > 64 || !strcmp(s, ".") || !strcmp(s, "..")) return 0;
  for (; *s; s++)
    if (!name_char(*s)) return 0;
  return 1;
}

/* The stem of a path's last component ("dir/x.json" -> "x"), its characters outside
 * [A-Za-z0-9_.-] replaced by '_' ("my scene.json" -> "my_scene", with a warning through the
 * context's log); "scene" if nothing usable is left or there is no file (a string). */
static fcm_status default_name(fcm__scene_parser *p, const char *source, const char **out)
{
  fcm_status st = FCM_OK;
  if (!strcmp(source, "<string>")) return fcm__scene_strdup(p, "scene", out); /* no file */
  const char *b = strrchr(source, '/');
  b = b ? b + 1 : source;
  size_t n = strlen(b);
  const char *dot = strrchr(b, '.');
  if (dot && dot != b) n = (size_t)(dot - b);
  if (n > 64) n = 64;
  char buf[65];
  memcpy(buf, b, n);
  buf[n] = '\0';
  if (!valid_name(buf)) {
    char stem[65];
    memcpy(stem, buf, n + 1);
    for (size_t k = 0; k < n; k++)
      if (!name_char(buf[k])) buf[k] = '_';
    if (!valid_name(buf)) strcpy(buf, "scene");
    fcm__log(p->ctx, FCM_LOG_WARNING,
             "scene %s: no \"name\" and the file name '%s' is not a usable one ([A-Za-z0-9_.-], "
             "1 to 64 characters): named '%s' (its output files start with it)",
             source, stem, buf);
  }
  FCM_TRY(p->ctx, fcm__scene_strdup(p, buf, out));
cleanup:
  return st;
}

static fcm_status parse_root(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"version",  "name",     "description", "background",
                                     "geometry", "material", "quadrature",  "solver",
                                     "time",     "output",   "effects"};
  fcm_scene *s = p->scene;
  long long version = 1;
  SCENE_CHECK(fcm__json_get_kind(root) == FCM__JSON_OBJECT, p, FCM_ERR_ARG,
              "expected a JSON object at the top level");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, root, keys, SCENE_COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_int(p, root, "version", 0, 1, 1, &version));
  FCM_TRY(p->ctx, fcm__scene_read_string(p, root, "name", 0, &s->name));
  if (s->name) {
    fcm__scene_path_push_key(p, "name");
    SCENE_CHECK(valid_name(s->name), p, FCM_ERR_ARG,
                "expected 1 to 64 characters from [A-Za-z0-9_.-] (it names output files), "
                "got \"%.64s\"",
                s->name);
    fcm__scene_path_pop(p, 0);
  } else {
    FCM_TRY(p->ctx, default_name(p, p->source, &s->name));
  }
  s->description = "";
  FCM_TRY(p->ctx, fcm__scene_read_string(p, root, "description", 0, &s->description));
  FCM_TRY(p->ctx, fcm__scene_read_background(p, root));
  FCM_TRY(p->ctx, fcm__scene_read_geometry(p, root));
  if (s->background.fit && s->geometry.kind == FCM_SCENE_GEOMETRY_NONE) {
    fcm__scene_path_push_key(p, "background");
    fcm__scene_path_push_key(p, "fit_background");
    SCENE_CHECK(0, p, FCM_ERR_ARG,
                "needs an embedded \"geometry\" to fit the grid around (the scene has none)");
  }
  if (s->background.octree) {
    fcm__scene_path_push_key(p, "background");
    fcm__scene_path_push_key(p, "octree");
    SCENE_CHECK(s->background.element == FCM_ELEMENT_HEX8 ||
                    s->background.element == FCM_ELEMENT_HEX20,
                p, FCM_ERR_ARG, "octree refinement needs hexahedra: element \"hex8\" or \"hex20\"");
    fcm__scene_path_push_key(p, "boundary");
    SCENE_CHECK(!s->background.octree_boundary || s->geometry.kind != FCM_SCENE_GEOMETRY_NONE, p,
                FCM_ERR_ARG, "needs an embedded \"geometry\" whose boundary it refines along");
    fcm__scene_path_pop(p, 0);
  }
  FCM_TRY(p->ctx, fcm__scene_read_material(p, root));
  FCM_TRY(p->ctx, fcm__scene_read_quadrature(p, root));
  FCM_TRY(p->ctx, fcm__scene_read_solver(p, root));
  FCM_TRY(p->ctx, fcm__scene_read_time(p, root));
  FCM_TRY(p->ctx, fcm__scene_read_output(p, root));
  FCM_TRY(p->ctx, fcm__scene_read_effects(p, root));
  if (s->background.octree_cuts && fcm_scene_count_effects(s, FCM_EFFECT_CUT) == 0) {
    fcm__scene_path_push_key(p, "background");
    fcm__scene_path_push_key(p, "octree");
    fcm__scene_path_push_key(p, "cuts");
    SCENE_CHECK(0, p, FCM_ERR_ARG,
                "needs \"cut\" effects whose surfaces it refines along (the scene has none)");
  }
cleanup:
  return st;
}

/* 1-based line and column (in bytes) of a byte offset. */
static void line_column(const char *text, size_t offset, long *line, long *col)
{
  *line = 1;
  *col = 1;
  for (size_t i = 0; i < offset; i++) {
    if (text[i] == '\n') {
      (*line)++;
      *col = 1;
    } else {
      (*col)++;
    }
  }
}

/* Parse `length` bytes of text (NUL at text[length]) into a new scene. */
static fcm_status create(fcm_ctx *ctx, const char *text, size_t length, const char *source,
                         fcm_scene **out)
{
  fcm_status st = FCM_OK;
  fcm__json *root = NULL;
  fcm_scene *s = NULL;
  fcm__scene_parser p;
  memset(&p, 0, sizeof p);
  p.ctx = ctx;
  p.source = source;
  p.norm = fcm__json_new_object();
  FCM_CHECK(p.norm, ctx, FCM_ERR_ALLOC, "scene: out of memory for the normalized scene");
  FCM_ALLOC(ctx, 1, s);
  s->ctx = ctx;
  p.scene = s;
  FCM_TRY(ctx, fcm__scene_strdup(&p, source, &s->source));
  p.source = s->source;
  {
    /* Relative file names are resolved against the source's directory part. */
    const char *slash = strrchr(source, '/');
    size_t n = slash ? (size_t)(slash - source) + 1 : 0;
    char *dir = fcm__scene_alloc(s, n + 1, 1);
    if (!dir) {
      st = FCM_ERR_ALLOC;
      fcm__trace(ctx, __FILE__, __LINE__, __func__);
      goto cleanup;
    }
    memcpy(dir, source, n);
    p.base_dir = dir;
  }
  size_t nul = strlen(text);
  if (nul < length) {
    long line, col;
    line_column(text, nul, &line, &col);
    FCM_CHECK(0, ctx, FCM_ERR_FORMAT, "%s:%ld:%ld: malformed JSON: NUL byte in the text", source,
              line, col);
  }
  size_t at = 0;
  root = fcm__json_parse(text, length, &at);
  if (!root) {
    long line, col;
    char near[32];
    size_t k = 0, a = at, b = at;
    line_column(text, at, &line, &col);
    /* Up to 12 characters either side of the position, within its line. */
    while (a > 0 && at - a < 12 && text[a - 1] != '\n')
      a--;
    while (b < length && b - at < 12 && text[b] != '\n')
      b++;
    for (size_t i = a; i < b; i++)
      near[k++] = ((unsigned char)text[i] < 0x20 || text[i] == 0x7f) ? ' ' : text[i];
    near[k] = '\0';
    if (at >= length)
      FCM_CHECK(0, ctx, FCM_ERR_FORMAT, "%s:%ld:%ld: malformed JSON: unexpected end of input",
                source, line, col);
    FCM_CHECK(0, ctx, FCM_ERR_FORMAT,
              "%s:%ld:%ld: malformed JSON near '%s' (JSON has no comments, trailing commas, "
              "NaN or Infinity)",
              source, line, col, near);
  }
  FCM_TRY(ctx, parse_root(&p, root));
  {
    char *json = p.norm_failed ? NULL : fcm__json_print(p.norm);
    FCM_CHECK(json, ctx, FCM_ERR_ALLOC, "scene: out of memory for the normalized scene");
    st = fcm__scene_strdup(&p, json, &s->json);
    fcm__json_free_text(json);
    FCM_TRY(ctx, st);
  }
  *out = s;
  s = NULL;
cleanup:
  fcm__json_delete(p.norm);
  fcm__json_delete(root);
  fcm_scene_destroy(&s);
  return st;
}

fcm_status fcm_scene_create_from_string(fcm_ctx *ctx, const char *json_text,
                                        const char *source_name, fcm_scene **scene)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(scene, ctx, FCM_ERR_ARG, "scene: output pointer is NULL");
  *scene = NULL;
  FCM_CHECK(ctx && json_text, ctx, FCM_ERR_ARG, "scene: %s is NULL", ctx ? "json_text" : "ctx");
  FCM_TRY(ctx,
          create(ctx, json_text, strlen(json_text), source_name ? source_name : "<string>", scene));
cleanup:
  return st;
}

fcm_status fcm_scene_create_from_file(fcm_ctx *ctx, const char *path, fcm_scene **scene)
{
  fcm_status st = FCM_OK;
  char *text = NULL;
  size_t len = 0;
  FCM_CHECK(scene, ctx, FCM_ERR_ARG, "scene: output pointer is NULL");
  *scene = NULL;
  FCM_CHECK(ctx && path, ctx, FCM_ERR_ARG, "scene: %s is NULL", ctx ? "path" : "ctx");
  /* regular files only, up to 1 GiB (a device or pipe is refused, not read) */
  FCM_TRY(ctx, fcm__file_read_all(ctx, "scene", path, (size_t)1 << 30, &text, &len));
  FCM_TRY(ctx, create(ctx, text, len, path, scene));
cleanup:
  fcm__free(ctx, text);
  return st;
}

/* ---------------------------------------------------------------- accessors */

const char *fcm_scene_name(const fcm_scene *s)
{
  return s->name;
}
const char *fcm_scene_description(const fcm_scene *s)
{
  return s->description;
}
const char *fcm_scene_json(const fcm_scene *s)
{
  return s->json;
}
const char *fcm_scene_source(const fcm_scene *s)
{
  return s->source;
}
const fcm_scene_background *fcm_scene_get_background(const fcm_scene *s)
{
  return &s->background;
}
const fcm_scene_geometry *fcm_scene_get_geometry(const fcm_scene *s)
{
  return &s->geometry;
}
const fcm_material *fcm_scene_get_material(const fcm_scene *s)
{
  return &s->material;
}
const fcm_scene_quadrature *fcm_scene_get_quadrature(const fcm_scene *s)
{
  return &s->quadrature;
}
const fcm_scene_solver *fcm_scene_get_solver(const fcm_scene *s)
{
  return &s->solver;
}
const fcm_scene_time *fcm_scene_get_time(const fcm_scene *s)
{
  return &s->time;
}
const fcm_scene_output *fcm_scene_get_output(const fcm_scene *s)
{
  return &s->output;
}
int fcm_scene_num_effects(const fcm_scene *s)
{
  return s->num_effects;
}

const fcm_effect *fcm_scene_get_effect(const fcm_scene *s, int i)
{
  return (i >= 0 && i < s->num_effects) ? &s->effects[i] : NULL;
}

int fcm_scene_count_effects(const fcm_scene *s, fcm_effect_type type)
{
  int n = 0;
  for (int i = 0; i < s->num_effects; i++)
    n += s->effects[i].type == type;
  return n;
}
