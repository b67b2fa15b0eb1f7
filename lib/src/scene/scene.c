/* Scene objects: reading a scene file, parsing and validating every section (effects are
 * in effects.c), the accessors and the normalized summary printed by fcm_scene_view(). */
#define _POSIX_C_SOURCE 200809L
#include "scene/scene_impl.h"
#include "geom/geom_impl.h"

#include <errno.h>
#include <stdalign.h>
#include <stddef.h>
#include <string.h>

#define COUNT(a) ((int)(sizeof(a) / sizeof *(a)))
#define GIB      (1024.0 * 1024.0 * 1024.0)

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

static const char *const element_names[] = {"tet4", "tet10", "hex8", "hex20"};
static const char *const model_names[] = {"linear", "stvk", "corotated", "snh",
                                          "stable_neo_hookean"};
static const fcm_material_model model_values[] = {
    FCM_MATERIAL_LINEAR, FCM_MATERIAL_STVK, FCM_MATERIAL_COROTATED, FCM_MATERIAL_STABLE_NEO_HOOKEAN,
    FCM_MATERIAL_STABLE_NEO_HOOKEAN};
static const char *const shape_names[] = {"box", "ball", "hemisphere", "hollow_ball", "tube"};
static const char *const axis_names[] = {"x", "y", "z"};
static const char *const simplify_names[] = {"auto", "lp", "recombine", "eliminate"};
static const char *const stabilization_names[] = {"mass_stiffness", "mass", "off"};
static const char *const solver_names[] = {"direct", "minres", "cg", "multigrid"};
static const int solver_values[] = {FCM_LINEAR_DIRECT, FCM_LINEAR_MINRES, FCM_LINEAR_CG,
                                    FCM_LINEAR_MULTIGRID};
static const char *const direct_names[] = {"cholmod", "umfpack"};
/* in the order of fcm_preconditioner */
static const char *const preconditioner_names[] = {"none", "jacobi", "block_jacobi", "schwarz",
                                                   "multigrid"};
/* solver.multigrid: smoothers ("sgs_colored" also accepted, as the other names are written),
 * cycles (V: cycle_index 1, W: 2) */
static const char *const smoother_names[] = {"sgs", "jacobi", "sgs-colored", "sgs_colored"};
static const int smoother_values[] = {FCM_MG_SMOOTHER_SGS, FCM_MG_SMOOTHER_JACOBI,
                                      FCM_MG_SMOOTHER_SGS_COLORED, FCM_MG_SMOOTHER_SGS_COLORED};
static const char *const cycle_names[] = {"v", "w"};
static const int cycle_values[] = {1, 2};
/* background elements the multigrid supports (fcm_mg_create()) */
static const fcm_element_type multigrid_elements[] = {FCM_ELEMENT_HEX8, FCM_ELEMENT_HEX20};
static const char *const clamp_names[] = {"clamp", "paper"};
/* in the order of fcm_preconditioner_tangent */
static const char *const tangent_names[] = {"projected", "linear", "exact"};
static const char *const newton_rule_names[] = {"auto", "representative", "relative"};
/* solver.on_inversion: fcm_scene_solver.stop_on_inversion 0 or 1 */
static const char *const inversion_names[] = {"warn", "stop"};
static const int newton_rule_values[] = {FCM_NEWTON_TOL_AUTO, FCM_NEWTON_TOL_REPRESENTATIVE,
                                         FCM_NEWTON_TOL_RELATIVE};
static const char *const integrator_names[] = {"backward_euler"};
static const int integrator_values[] = {FCM_INTEGRATOR_BACKWARD_EULER};

/* Read a choice into an enum of any integer type. */
#define READ_CHOICE(p, obj, key, required, names, out)                                             \
  do {                                                                                             \
    int ch_ = (int)(out);                                                                          \
    FCM_TRY((p)->ctx,                                                                              \
            fcm__scene_read_choice((p), (obj), (key), (required), (names), COUNT(names), &ch_));   \
    (out) = ch_;                                                                                   \
  } while (0)

/* Read a choice given by names[i] into out = values[i] (the library's enum values, whose
 * order need not be the names' order). */
#define READ_CHOICE_AS(p, obj, key, required, names, values, out)                                  \
  do {                                                                                             \
    int ch_ = -1;                                                                                  \
    FCM_TRY((p)->ctx,                                                                              \
            fcm__scene_read_choice((p), (obj), (key), (required), (names), COUNT(names), &ch_));   \
    if (ch_ >= 0) (out) = (values)[ch_]; /* an enum of the library */                              \
  } while (0)

/* The name of `value` in a names/values table (for the summary). */
#define CHOICE_NAME(names, values, value) choice_name((names), (values), COUNT(names), (int)(value))

static const char *choice_name(const char *const *names, const int *values, int n, int value)
{
  for (int i = 0; i < n; i++)
    if (values[i] == value) return names[i];
  return "?";
}

/* Read an integer member into an int-like destination. */
#define READ_INT(p, obj, key, required, lo, hi, out)                                               \
  do {                                                                                             \
    long long v_ = (long long)(out);                                                               \
    FCM_TRY((p)->ctx, fcm__scene_read_int((p), (obj), (key), (required), (lo), (hi), &v_));        \
    (out) = (int)v_;                                                                               \
  } while (0)

/* Push a key for the checks of one section; popped at cleanup by the caller's `old`. */
#define ENTER(p, key) fcm__scene_path_push_key((p), (key))

/* ---------------------------------------------------------------- background */

/* "fit_background": {"cell_size": h, "margin": m}: a grid of cubes of edge h around the
 * geometry's bounding box grown by m on every side, placed when the simulation is built. */
static fcm_status read_fit_background(fcm__scene_parser *p, const fcm__json *o,
                                      fcm_scene_background *b)
{
  fcm_status st = FCM_OK;
  static const char *const fit_keys[] = {"cell_size", "margin"};
  static const char *const excluded[] = {"box", "cells", "mesh"};
  const fcm__json *fit = NULL;
  size_t old = p->path_len;
  for (int i = 0; i < COUNT(excluded); i++) {
    if (!fcm__json_member(o, excluded[i])) continue;
    fcm__scene_path_push_key(p, excluded[i]);
    SCENE_CHECK(0, p, FCM_ERR_ARG,
                "not allowed with \"fit_background\" (which places the grid around the "
                "geometry: give either \"fit_background\" or \"box\" and \"cells\")");
  }
  b->kind = FCM_SCENE_BACKGROUND_GRID;
  b->fit = 1;
  READ_CHOICE(p, o, "element", 1, element_names, b->element);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "fit_background", 1, &fit));
  ENTER(p, "fit_background");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, fit, fit_keys, COUNT(fit_keys)));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, fit, "cell_size", 1, FCM__POSITIVE, &b->fit_cell_size));
  b->fit_margin = b->fit_cell_size;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, fit, "margin", 0, FCM__NONNEGATIVE, &b->fit_margin));
  b->cells[0] = b->cells[1] = b->cells[2] = 1;
  b->max[0] = b->max[1] = b->max[2] = 1.0;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

static fcm_status read_background(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"element", "box", "cells", "mesh", "fit_background"};
  static const char *const box_keys[] = {"min", "max"};
  fcm_scene_background *b = &p->scene->background;
  const fcm__json *o = NULL, *box = NULL;
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "background", 1, &o));
  ENTER(p, "background");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  if (fcm__json_member(o, "fit_background")) {
    FCM_TRY(p->ctx, read_fit_background(p, o, b));
    goto cleanup;
  }
  if (fcm__json_member(o, "mesh")) {
    for (int i = 0; i < 3; i++) {
      if (!fcm__json_member(o, keys[i])) continue;
      fcm__scene_path_push_key(p, keys[i]);
      SCENE_CHECK(0, p, FCM_ERR_ARG,
                  "not allowed with \"mesh\" (the mesh file sets the element type and cells)");
    }
    b->kind = FCM_SCENE_BACKGROUND_MESH;
    b->element = FCM_ELEMENT_COUNT;
    FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "mesh", 1, NULL, &b->mesh));
    goto cleanup;
  }
  SCENE_CHECK(fcm__json_member(o, "box"), p, FCM_ERR_ARG,
              "expected either \"box\" (with \"element\" and \"cells\") for a generated grid, "
              "\"fit_background\" (with \"element\") for a grid around the geometry, "
              "or \"mesh\" (a Gmsh file)");
  b->kind = FCM_SCENE_BACKGROUND_GRID;
  READ_CHOICE(p, o, "element", 1, element_names, b->element);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "box", 1, &box));
  {
    size_t o2 = ENTER(p, "box");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, box, box_keys, COUNT(box_keys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, box, "min", 1, FCM__ANY, b->min));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, box, "max", 1, FCM__ANY, b->max));
    for (int d = 0; d < 3; d++)
      SCENE_CHECK(b->min[d] < b->max[d], p, FCM_ERR_ARG,
                  "expected min[%d] < max[%d], got min[%d] = %g >= max[%d] = %g", d, d, d,
                  b->min[d], d, b->max[d]);
    fcm__scene_path_pop(p, o2);
  }
  FCM_TRY(p->ctx, fcm__scene_read_ivec3(p, o, "cells", 1, 1, 1000000, b->cells));
  {
    double total = (double)b->cells[0] * (double)b->cells[1] * (double)b->cells[2];
    fcm__scene_path_push_key(p, "cells");
    SCENE_CHECK(total <= 1e8, p, FCM_ERR_ARG, "expected at most 1e8 cells in total, got %.0f",
                total);
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- geometry */

fcm_status fcm__scene_read_transform(fcm__scene_parser *p, const fcm__json *o, double A[9],
                                     double b[3], int *has)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"scale", "rotation", "translation"};
  static const char *const rkeys[] = {"axis", "angle"};
  const fcm__json *t = NULL, *rot = NULL;
  double scale[3] = {1, 1, 1}, axis[3] = {0, 0, 1}, angle = 0.0, offset[3] = {0, 0, 0};
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "transform", 0, &t));
  if (!t) return FCM_OK;
  ENTER(p, "transform");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, t, keys, COUNT(keys)));
  const fcm__json *sc = fcm__json_member(t, "scale");
  if (sc && fcm__json_get_kind(sc) == FCM__JSON_NUMBER) {
    FCM_TRY(p->ctx, fcm__scene_read_number(p, t, "scale", 1, FCM__POSITIVE, &scale[0]));
    scale[1] = scale[2] = scale[0];
  } else {
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, t, "scale", 0, FCM__POSITIVE, scale));
  }
  FCM_TRY(p->ctx, fcm__scene_read_object(p, t, "rotation", 0, &rot));
  if (rot) {
    size_t o2 = ENTER(p, "rotation");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, rot, rkeys, COUNT(rkeys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, rot, "axis", 1, FCM__ANY, axis));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, rot, "angle", 1, FCM__ANY, &angle));
    double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    fcm__scene_path_push_key(p, "axis");
    SCENE_CHECK(n > 0.0 && isfinite(n), p, FCM_ERR_ARG,
                "expected a non-zero vector, got (%g, %g, %g)", axis[0], axis[1], axis[2]);
    for (int d = 0; d < 3; d++)
      axis[d] /= n;
    fcm__scene_path_pop(p, o2);
  }
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, t, "translation", 0, FCM__ANY, offset));
  /* A = R(axis, angle) diag(scale): Rodrigues' formula, column j scaled by scale[j]. */
  double c = cos(angle), s = sin(angle), *a = axis;
  double R[9] = {c + a[0] * a[0] * (1 - c),        a[0] * a[1] * (1 - c) - a[2] * s,
                 a[0] * a[2] * (1 - c) + a[1] * s, a[1] * a[0] * (1 - c) + a[2] * s,
                 c + a[1] * a[1] * (1 - c),        a[1] * a[2] * (1 - c) - a[0] * s,
                 a[2] * a[0] * (1 - c) - a[1] * s, a[2] * a[1] * (1 - c) + a[0] * s,
                 c + a[2] * a[2] * (1 - c)};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      A[3 * i + j] = R[3 * i + j] * scale[j];
  memcpy(b, offset, sizeof offset);
  *has = 1;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "surface": a triangle surface file tetrahedralized when the simulation is built. */
static fcm_status read_surface_geometry(fcm__scene_parser *p, const fcm__json *o,
                                        fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {
      "surface",        "max_volume",         "size",     "quality", "fill_holes",
      "max_hole_edges", "max_hole_perimeter", "transform"};
  static const char *const exts[] = {".obj", ".off", ".stl", ".ply"};
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  g->kind = FCM_SCENE_GEOMETRY_SURFACE;
  FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "surface", 1, NULL, &g->mesh));
  {
    size_t n = strlen(g->mesh);
    int known = 0;
    for (int i = 0; i < COUNT(exts); i++) {
      size_t e = strlen(exts[i]);
      int eq = n >= e;
      for (size_t k = 0; eq && k < e; k++) {
        char c = g->mesh[n - e + k];
        eq = (c >= 'A' && c <= 'Z' ? (char)(c - 'A' + 'a') : c) == exts[i][k];
      }
      known |= eq;
    }
    fcm__scene_path_push_key(p, "surface");
    SCENE_CHECK(known, p, FCM_ERR_ARG,
                "expected a file ending in .obj, .off, .stl or .ply, got '%s'", g->mesh);
    fcm__scene_path_pop(p, old);
  }
  g->surface = fcm_surface_mesh_options_default();
  g->fill = fcm_surface_fill_options_default();
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "max_volume", 0, FCM__NONNEGATIVE, &g->surface.max_volume));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "size", 0, FCM__NONNEGATIVE, &g->surface.size));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "quality", 0, (fcm__range){0.0, 1.0, 0, 0},
                                         &g->surface.quality));
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "fill_holes", 0, &g->fill_holes));
  long long me = 0;
  FCM_TRY(p->ctx, fcm__scene_read_int(p, o, "max_hole_edges", 0, 0, 1000000000, &me));
  g->fill.max_edges = (fcm_index)me;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "max_hole_perimeter", 0, FCM__NONNEGATIVE,
                                         &g->fill.max_perimeter));
  if (!g->fill_holes) {
    static const char *const fill_keys[] = {"max_hole_edges", "max_hole_perimeter"};
    for (int i = 0; i < COUNT(fill_keys); i++) {
      if (!fcm__json_member(o, fill_keys[i])) continue;
      fcm__scene_path_push_key(p, fill_keys[i]);
      SCENE_CHECK(0, p, FCM_ERR_ARG, "only used with \"fill_holes\": true");
    }
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

static const char *const implicit_names[] = {"sphere", "torus",        "box",       "gyroid",
                                             "union",  "intersection", "difference"};

/* One implicit (an object with one member named by its kind) at the current path into
 * nodes[*n ...]; *root is the index of its node. CSG arrays of k >= 2 operands fold left:
 * ((a op b) op c) ... */
static fcm_status read_implicit(fcm__scene_parser *p, const fcm__json *node, double h,
                                fcm_implicit *nodes, int *n, int *root)
{
  fcm_status st = FCM_OK;
  static const char *const sphere_keys[] = {"center", "radius"};
  static const char *const torus_keys[] = {"center", "axis", "major_radius", "minor_radius"};
  static const char *const box_keys[] = {"min", "max"};
  static const char *const gyroid_keys[] = {"min", "max", "period", "thickness", "type"};
  static const char *const gyroid_types[] = {"sheet", "solid"};
  size_t old = p->path_len;
  SCENE_CHECK(fcm__json_get_kind(node) == FCM__JSON_OBJECT && fcm__json_size(node) == 1, p,
              FCM_ERR_ARG,
              "expected an object with exactly one member: sphere, torus, box, gyroid, union, "
              "intersection or difference");
  const fcm__json *m = fcm__json_child(node);
  const char *key = fcm__json_key(m);
  int kind = -1;
  for (int k = 0; k < COUNT(implicit_names); k++)
    if (strcmp(key, implicit_names[k]) == 0) kind = k;
  SCENE_CHECK(kind >= 0, p, FCM_ERR_ARG,
              "unknown implicit \"%.64s\"; expected sphere, torus, box, gyroid, union, "
              "intersection or difference",
              key);
  ENTER(p, key);
  fcm_implicit q;
  memset(&q, 0, sizeof q);
  q.kind = (fcm_implicit_kind)kind;
  if (q.kind >= FCM_IMPLICIT_UNION) {
    SCENE_CHECK(fcm__json_get_kind(m) == FCM__JSON_ARRAY && fcm__json_size(m) >= 2, p, FCM_ERR_ARG,
                "expected an array of at least 2 implicits");
    int r = -1, i = 0;
    for (const fcm__json *c = fcm__json_child(m); c; c = fcm__json_next(c), i++) {
      size_t o2 = fcm__scene_path_push_index(p, i);
      int ci = -1;
      FCM_TRY(p->ctx, read_implicit(p, c, h, nodes, n, &ci));
      fcm__scene_path_pop(p, o2);
      if (r < 0) {
        r = ci;
        continue;
      }
      SCENE_CHECK(*n < FCM_IMPLICIT_MAX_NODES, p, FCM_ERR_ARG,
                  "the implicit tree has more than %d nodes", FCM_IMPLICIT_MAX_NODES);
      q.a = r, q.b = ci;
      nodes[*n] = q;
      r = (*n)++;
    }
    *root = r;
  } else {
    SCENE_CHECK(fcm__json_get_kind(m) == FCM__JSON_OBJECT, p, FCM_ERR_ARG,
                "expected an object of parameters");
    SCENE_CHECK(*n < FCM_IMPLICIT_MAX_NODES, p, FCM_ERR_ARG,
                "the implicit tree has more than %d nodes", FCM_IMPLICIT_MAX_NODES);
    switch (q.kind) {
    case FCM_IMPLICIT_SPHERE:
      FCM_TRY(p->ctx, fcm__scene_check_object(p, m, sphere_keys, COUNT(sphere_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, m, "center", 0, FCM__ANY, q.center));
      FCM_TRY(p->ctx, fcm__scene_read_number(p, m, "radius", 1, FCM__POSITIVE, &q.radius));
      break;
    case FCM_IMPLICIT_TORUS:
      FCM_TRY(p->ctx, fcm__scene_check_object(p, m, torus_keys, COUNT(torus_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, m, "center", 0, FCM__ANY, q.center));
      q.axis = 2;
      READ_CHOICE(p, m, "axis", 0, axis_names, q.axis);
      FCM_TRY(p->ctx, fcm__scene_read_number(p, m, "major_radius", 1, FCM__POSITIVE, &q.radius));
      FCM_TRY(p->ctx, fcm__scene_read_number(p, m, "minor_radius", 1,
                                             (fcm__range){0.0, q.radius, 1, 0}, &q.minor_radius));
      break;
    case FCM_IMPLICIT_BOX:
    case FCM_IMPLICIT_GYROID:
      if (q.kind == FCM_IMPLICIT_BOX)
        FCM_TRY(p->ctx, fcm__scene_check_object(p, m, box_keys, COUNT(box_keys)));
      else
        FCM_TRY(p->ctx, fcm__scene_check_object(p, m, gyroid_keys, COUNT(gyroid_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, m, "min", 1, FCM__ANY, q.min));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, m, "max", 1, FCM__ANY, q.max));
      for (int d = 0; d < 3; d++)
        SCENE_CHECK(q.min[d] < q.max[d], p, FCM_ERR_ARG,
                    "expected min[%d] < max[%d], got min[%d] = %g >= max[%d] = %g", d, d, d,
                    q.min[d], d, q.max[d]);
      if (q.kind == FCM_IMPLICIT_GYROID) {
        int type = 0;
        READ_CHOICE(p, m, "type", 0, gyroid_types, type);
        q.sheet = type == 0;
        FCM_TRY(p->ctx, fcm__scene_read_number(p, m, "period", 1, FCM__POSITIVE, &q.period));
        q.thickness = q.sheet ? 0.1 * q.period : 0.0;
        FCM_TRY(p->ctx,
                fcm__scene_read_number(p, m, "thickness", 0,
                                       q.sheet ? (fcm__range){0.0, q.period / 4, 1, 1}
                                               : (fcm__range){-q.period / 4, q.period / 4, 1, 1},
                                       &q.thickness));
      }
      break;
    default:
      break;
    }
    /* a feature below the sampling spacing only samples noise: refused before building */
    char why[512];
    const char *feature;
    if (!fcm__implicit_resolved(&q, h, &feature, why, sizeof why)) {
      if (feature) fcm__scene_path_push_key(p, feature);
      SCENE_CHECK(0, p, FCM_ERR_ARG, "%s", why);
    }
    nodes[*n] = q;
    *root = (*n)++;
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "voxels": the image and its selection. */
static fcm_status read_voxels(fcm__scene_parser *p, const fcm__json *o, fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  size_t old = p->path_len;
  const fcm__json *lab = NULL;
  FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "voxels", 1, NULL, &g->image));
  g->threshold = 0.5;
  g->merge = 1;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "threshold", 0, FCM__ANY, &g->threshold));
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "merge", 0, &g->merge));
  FCM_TRY(p->ctx, fcm__scene_field(p, o, "labels", 0, "an array of 1 to 256 numbers",
                                   FCM__JSON_ARRAY, -1, &lab));
  if (lab) {
    const int nl = fcm__json_size(lab);
    SCENE_CHECK(nl >= 1 && nl <= 256, p, FCM_ERR_ARG, "expected 1 to 256 labels, got %d", nl);
    SCENE_CHECK(!fcm__json_member(o, "threshold"), p, FCM_ERR_ARG,
                "give either \"labels\" or \"threshold\", not both");
    double *l = fcm__scene_alloc(p->scene, (size_t)nl, sizeof *l);
    FCM_CHECK(l, p->ctx, FCM_ERR_ALLOC, "scene: out of memory");
    int i = 0;
    for (const fcm__json *c = fcm__json_child(lab); c; c = fcm__json_next(c), i++) {
      SCENE_CHECK(fcm__json_get_kind(c) == FCM__JSON_NUMBER && isfinite(fcm__json_number(c)), p,
                  FCM_ERR_ARG, "labels[%d]: expected a finite number", i);
      l[i] = fcm__json_number(c);
    }
    g->labels = l;
    g->num_labels = nl;
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "level_set": the implicit tree, its sampling box (default: the background grid) and the
 * refinement. */
static fcm_status read_level_set(fcm__scene_parser *p, const fcm__json *o, fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  size_t old = p->path_len;
  fcm_implicit *nodes = fcm__scene_alloc(p->scene, FCM_IMPLICIT_MAX_NODES, sizeof *nodes);
  FCM_CHECK(nodes, p->ctx, FCM_ERR_ALLOC, "scene: out of memory");
  int n = 0, root = -1;
  g->refinement = 4;
  READ_INT(p, o, "refinement", 0, 1, 64, g->refinement);
  long long max_subcells = FCM_LEVEL_SET_MAX_SUBCELLS;
  FCM_TRY(p->ctx,
          fcm__scene_read_int(p, o, "max_subcells", 0, 0, (long long)1 << 50, &max_subcells));
  g->max_subcells = (fcm_index)max_subcells;
  const int nbox =
      !!fcm__json_member(o, "min") + !!fcm__json_member(o, "max") + !!fcm__json_member(o, "cells");
  SCENE_CHECK(nbox == 0 || nbox == 3, p, FCM_ERR_ARG,
              "the sampling box of a level set needs all of \"min\", \"max\" and \"cells\" "
              "(or none: the background grid)");
  if (nbox == 3) {
    g->has_box = 1;
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "min", 1, FCM__ANY, g->min));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "max", 1, FCM__ANY, g->max));
    for (int d = 0; d < 3; d++)
      SCENE_CHECK(g->min[d] < g->max[d], p, FCM_ERR_ARG,
                  "expected min[%d] < max[%d], got min[%d] = %g >= max[%d] = %g", d, d, d,
                  g->min[d], d, g->max[d]);
    FCM_TRY(p->ctx, fcm__scene_read_ivec3(p, o, "cells", 1, 1, 10000, g->cells));
  } else {
    const fcm_scene_background *b = &p->scene->background;
    SCENE_CHECK(b->kind == FCM_SCENE_BACKGROUND_GRID && !b->fit &&
                    !fcm__json_member(o, "transform"),
                p, FCM_ERR_ARG,
                "a level set is sampled on the background grid only when the background is a "
                "grid with its box given (not fit_background) and there is no transform; give "
                "\"min\", \"max\" and \"cells\"");
    memcpy(g->min, b->min, sizeof g->min);
    memcpy(g->max, b->max, sizeof g->max);
    memcpy(g->cells, b->cells, sizeof g->cells);
  }
  /* the sampling spacing (fcm_level_set_info.h) every feature of the tree must resolve */
  double h = 0.0;
  for (int d = 0; d < 3; d++)
    h = fmax(h, (g->max[d] - g->min[d]) / ((double)g->cells[d] * g->refinement));
  ENTER(p, "level_set");
  FCM_TRY(p->ctx, read_implicit(p, fcm__json_member(o, "level_set"), h, nodes, &n, &root));
  fcm__scene_path_pop(p, old);
  g->implicit = nodes;
  g->num_implicit = n;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

static fcm_status read_geometry(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const any_keys[] = {"shape",
                                         "mesh",
                                         "tetgen",
                                         "transform",
                                         "min",
                                         "max",
                                         "cells",
                                         "center",
                                         "radius",
                                         "resolution",
                                         "inner_radius",
                                         "outer_radius",
                                         "hole_radius",
                                         "layers",
                                         "axis",
                                         "length",
                                         "radial_cells",
                                         "angular_cells",
                                         "axial_cells",
                                         "surface",
                                         "max_volume",
                                         "size",
                                         "quality",
                                         "fill_holes",
                                         "max_hole_edges",
                                         "max_hole_perimeter",
                                         "voxels",
                                         "threshold",
                                         "labels",
                                         "merge",
                                         "level_set",
                                         "refinement",
                                         "max_subcells"};
  static const char *const voxel_keys[] = {"voxels", "threshold", "labels", "merge", "transform"};
  static const char *const level_set_keys[] = {"level_set", "refinement", "max_subcells", "min",
                                               "max",       "cells",      "transform"};
  static const char *const box_keys[] = {"shape", "min", "max", "cells", "transform"};
  static const char *const ball_keys[] = {"shape", "center", "radius", "resolution", "transform"};
  static const char *const hollow_keys[] = {"shape",        "center",      "inner_radius",
                                            "outer_radius", "hole_radius", "resolution",
                                            "layers",       "transform"};
  static const char *const tube_keys[] = {
      "shape",  "center",       "axis",          "inner_radius", "outer_radius",
      "length", "radial_cells", "angular_cells", "axial_cells",  "transform"};
  static const char *const mesh_keys[] = {"mesh", "transform"};
  static const char *const tetgen_keys[] = {"tetgen", "transform"};
  fcm_scene_geometry *g = &p->scene->geometry;
  const fcm__json *o = NULL;
  size_t old = p->path_len;
  for (int i = 0; i < 9; i++)
    g->transform[i] = (i % 4 == 0);
  g->kind = FCM_SCENE_GEOMETRY_NONE;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "geometry", 0, &o));
  if (!o) return FCM_OK;
  ENTER(p, "geometry");
  /* Typos first (against every geometry key), then the keys of the chosen kind. */
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, any_keys, COUNT(any_keys)));
  int nd = !!fcm__json_member(o, "shape") + !!fcm__json_member(o, "mesh") +
           !!fcm__json_member(o, "tetgen") + !!fcm__json_member(o, "surface") +
           !!fcm__json_member(o, "voxels") + !!fcm__json_member(o, "level_set");
  SCENE_CHECK(nd == 1, p, FCM_ERR_ARG,
              "expected exactly one of \"shape\" (a procedural shape), \"mesh\" (a Gmsh file), "
              "\"tetgen\" (a TetGen base name), \"surface\" (an .obj, .off, .stl or .ply "
              "triangle surface), \"voxels\" (an image file) or \"level_set\" (an implicit "
              "body), got %d of them",
              nd);
  if (fcm__json_member(o, "surface")) {
    FCM_TRY(p->ctx, read_surface_geometry(p, o, g));
  } else if (fcm__json_member(o, "voxels")) {
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, voxel_keys, COUNT(voxel_keys)));
    g->kind = FCM_SCENE_GEOMETRY_VOXELS;
    FCM_TRY(p->ctx, read_voxels(p, o, g));
  } else if (fcm__json_member(o, "level_set")) {
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, level_set_keys, COUNT(level_set_keys)));
    g->kind = FCM_SCENE_GEOMETRY_LEVEL_SET;
    FCM_TRY(p->ctx, read_level_set(p, o, g));
  } else if (fcm__json_member(o, "mesh")) {
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, mesh_keys, COUNT(mesh_keys)));
    g->kind = FCM_SCENE_GEOMETRY_GMSH;
    FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "mesh", 1, NULL, &g->mesh));
  } else if (fcm__json_member(o, "tetgen")) {
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, tetgen_keys, COUNT(tetgen_keys)));
    g->kind = FCM_SCENE_GEOMETRY_TETGEN;
    FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "tetgen", 1, ".node", &g->mesh));
    FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "tetgen", 1, ".ele", &g->ele));
  } else {
    int shape = 0;
    FCM_TRY(p->ctx,
            fcm__scene_read_choice(p, o, "shape", 1, shape_names, COUNT(shape_names), &shape));
    g->kind = (fcm_scene_geometry_kind)(FCM_SCENE_GEOMETRY_BOX + shape);
    switch (g->kind) {
    case FCM_SCENE_GEOMETRY_BOX:
      FCM_TRY(p->ctx, fcm__scene_check_object(p, o, box_keys, COUNT(box_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "min", 1, FCM__ANY, g->min));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "max", 1, FCM__ANY, g->max));
      for (int d = 0; d < 3; d++)
        SCENE_CHECK(g->min[d] < g->max[d], p, FCM_ERR_ARG,
                    "expected min[%d] < max[%d], got min[%d] = %g >= max[%d] = %g", d, d, d,
                    g->min[d], d, g->max[d]);
      g->cells[0] = g->cells[1] = g->cells[2] = 1;
      FCM_TRY(p->ctx, fcm__scene_read_ivec3(p, o, "cells", 0, 1, 10000, g->cells));
      break;
    case FCM_SCENE_GEOMETRY_BALL:
    case FCM_SCENE_GEOMETRY_HEMISPHERE:
      FCM_TRY(p->ctx, fcm__scene_check_object(p, o, ball_keys, COUNT(ball_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "center", 0, FCM__ANY, g->center));
      FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "radius", 1, FCM__POSITIVE, &g->radius));
      g->resolution = 4;
      READ_INT(p, o, "resolution", 0, 1, 1000, g->resolution);
      break;
    case FCM_SCENE_GEOMETRY_HOLLOW_BALL:
      FCM_TRY(p->ctx, fcm__scene_check_object(p, o, hollow_keys, COUNT(hollow_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "center", 0, FCM__ANY, g->center));
      FCM_TRY(p->ctx,
              fcm__scene_read_number(p, o, "outer_radius", 1, FCM__POSITIVE, &g->outer_radius));
      FCM_TRY(p->ctx,
              fcm__scene_read_number(p, o, "inner_radius", 1,
                                     (fcm__range){0.0, g->outer_radius, 1, 1}, &g->inner_radius));
      FCM_TRY(p->ctx,
              fcm__scene_read_number(p, o, "hole_radius", 0,
                                     (fcm__range){0.0, g->outer_radius, 0, 1}, &g->hole_radius));
      g->resolution = 8;
      g->layers = 2;
      READ_INT(p, o, "resolution", 0, 1, 1000, g->resolution);
      READ_INT(p, o, "layers", 0, 1, 1000, g->layers);
      break;
    default: /* tube */
      FCM_TRY(p->ctx, fcm__scene_check_object(p, o, tube_keys, COUNT(tube_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "center", 0, FCM__ANY, g->center));
      g->axis = 2;
      READ_CHOICE(p, o, "axis", 0, axis_names, g->axis);
      FCM_TRY(p->ctx,
              fcm__scene_read_number(p, o, "outer_radius", 1, FCM__POSITIVE, &g->outer_radius));
      FCM_TRY(p->ctx,
              fcm__scene_read_number(p, o, "inner_radius", 1,
                                     (fcm__range){0.0, g->outer_radius, 1, 1}, &g->inner_radius));
      FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "length", 1, FCM__POSITIVE, &g->length));
      g->radial_cells = 2;
      g->angular_cells = 24;
      g->axial_cells = 16;
      READ_INT(p, o, "radial_cells", 0, 1, 10000, g->radial_cells);
      READ_INT(p, o, "angular_cells", 0, 6, 10000, g->angular_cells);
      READ_INT(p, o, "axial_cells", 0, 1, 10000, g->axial_cells);
      break;
    }
  }
  FCM_TRY(p->ctx, fcm__scene_read_transform(p, o, g->transform, g->offset, &g->has_transform));
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- material */

static fcm_status read_material(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"model", "young", "poisson", "density"};
  fcm_material *m = &p->scene->material;
  const fcm__json *o = NULL;
  size_t old = p->path_len;
  int model = 3; /* "snh" */
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "material", 1, &o));
  ENTER(p, "material");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx,
          fcm__scene_read_choice(p, o, "model", 0, model_names, COUNT(model_names), &model));
  m->model = model_values[model];
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "young", 1, FCM__POSITIVE, &m->young));
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "poisson", 1, (fcm__range){-1.0, 0.5, 1, 1}, &m->poisson));
  m->density = 1000.0;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "density", 0, FCM__NONNEGATIVE, &m->density));
  /* The material module's own rule must agree with the ranges above. */
  FCM_ASSERT(fcm_material_validate(NULL, m) == FCM_OK, p->ctx);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- quadrature */

static fcm_status read_quadrature(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"stiffness_strength", "mass_strength",      "surface_strength",
                                     "simplify",           "simplify_method",    "stabilization",
                                     "min_fraction",       "max_rule_memory_gib"};
  static const char *const skeys[] = {"mode", "alpha"};
  fcm_cell_rules_options *q = &p->scene->quadrature.rules;
  const fcm__json *o = NULL, *stab = NULL;
  size_t old = p->path_len;
  *q = fcm_cell_rules_options_default();
  double gib = q->max_rule_memory / GIB;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "quadrature", 0, &o));
  if (!o) return FCM_OK;
  ENTER(p, "quadrature");
  size_t here = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  READ_INT(p, o, "stiffness_strength", 0, 0, 20, q->strength[FCM_RULE_STIFFNESS]);
  READ_INT(p, o, "mass_strength", 0, 0, 20, q->strength[FCM_RULE_MASS]);
  READ_INT(p, o, "surface_strength", 0, 0, 20, q->surface_strength);
  {
    int simplify = (int)q->simplify;
    FCM_TRY(p->ctx, fcm__scene_read_bool_or_word(p, o, "simplify", 0, "auto",
                                                 FCM_CELL_SIMPLIFY_AUTO, &simplify));
    q->simplify = (fcm_cell_simplify)simplify;
  }
  READ_CHOICE(p, o, "simplify_method", 0, simplify_names, q->simplify_options.method);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "stabilization", 0, &stab));
  if (stab) {
    ENTER(p, "stabilization");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, stab, skeys, COUNT(skeys)));
    READ_CHOICE(p, stab, "mode", 0, stabilization_names, q->stabilization.mode);
    FCM_TRY(p->ctx, fcm__scene_read_number(p, stab, "alpha", 0, (fcm__range){0.0, 1.0, 1, 0},
                                           &q->stabilization.alpha));
    fcm__scene_path_pop(p, here);
  }
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "min_fraction", 0, (fcm__range){0.0, 1.0, 0, 1},
                                         &q->min_fraction));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "max_rule_memory_gib", 0,
                                         (fcm__range){0.0, 1048576.0, 0, 0}, &gib));
  q->max_rule_memory = gib * GIB;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- solver */

/* "solver.multigrid": the fcm_mg_options of the multigrid (preconditioner or solver). */
static fcm_status read_multigrid(fcm__scene_parser *p, const fcm__json *mg,
                                 fcm_integrator_options *s)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"smoother", "omega",       "pre_smooth",     "post_smooth",
                                     "cycle",    "coarse_dofs", "block_smoothing"};
  fcm_mg_options *m = &s->multigrid;
  size_t old = ENTER(p, "multigrid");
  long long coarse = (long long)m->coarse_dofs;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, mg, keys, COUNT(keys)));
  READ_CHOICE_AS(p, mg, "smoother", 0, smoother_names, smoother_values, m->smoother);
  if (m->smoother == FCM_MG_SMOOTHER_JACOBI)
    m->omega = 0.6; /* the damped Jacobi default (1.0 over-corrects elasticity) */
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, mg, "omega", 0, (fcm__range){0.0, 2.0, 1, 1}, &m->omega));
  if (m->smoother == FCM_MG_SMOOTHER_JACOBI && m->omega > 1.0) {
    fcm__scene_path_push_key(p, "omega");
    SCENE_CHECK(0, p, FCM_ERR_ARG,
                "expected a finite number in (0, 1] with the \"jacobi\" smoother, got %g "
                "((0, 2) for the Gauss-Seidel smoothers)",
                m->omega);
  }
  READ_INT(p, mg, "pre_smooth", 0, 0, 100, m->pre_smooth);
  READ_INT(p, mg, "post_smooth", 0, 0, 100, m->post_smooth);
  READ_CHOICE_AS(p, mg, "cycle", 0, cycle_names, cycle_values, m->cycle_index);
  FCM_TRY(p->ctx, fcm__scene_read_int(p, mg, "coarse_dofs", 0, 1, 1000000000, &coarse));
  m->coarse_dofs = (fcm_index)coarse;
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, mg, "block_smoothing", 0, &m->block_smoothing));
  SCENE_CHECK(m->pre_smooth + m->post_smooth >= 1, p, FCM_ERR_ARG,
              "pre_smooth = %d and post_smooth = %d: at least one smoothing step is needed",
              m->pre_smooth, m->post_smooth);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* Cross checks of the multigrid choice: a grid background of a supported element, and a
 * symmetric cycle when it preconditions CG or MINRES. The path is "solver.<key>". */
static fcm_status check_multigrid(fcm__scene_parser *p, const fcm_integrator_options *s)
{
  fcm_status st = FCM_OK;
  const int as_solver = s->linear_solver == FCM_LINEAR_MULTIGRID;
  const int as_pc = (s->linear_solver == FCM_LINEAR_CG || s->linear_solver == FCM_LINEAR_MINRES) &&
                    s->preconditioner == FCM_PRECOND_MULTIGRID;
  const fcm_scene_background *b = &p->scene->background;
  size_t old = p->path_len;
  if (!as_solver && !as_pc) return FCM_OK;
  ENTER(p, as_solver ? "method" : "preconditioner");
  SCENE_CHECK(b->kind == FCM_SCENE_BACKGROUND_GRID, p, FCM_ERR_ARG,
              "\"multigrid\" needs a \"background\" grid (\"box\" and \"cells\": a structured "
              "box grid of hex8 or hex20 cells); a Gmsh background mesh is not supported");
  int supported = 0;
  for (size_t k = 0; k < COUNT(multigrid_elements); k++)
    supported |= b->element == multigrid_elements[k];
  SCENE_CHECK(supported, p, FCM_ERR_ARG,
              "\"multigrid\" supports \"hex8\" and \"hex20\" background grids only, the "
              "background has \"element\": \"%s\"",
              (int)b->element >= 0 && (size_t)b->element < COUNT(element_names)
                  ? element_names[b->element]
                  : "?");
  fcm__scene_path_pop(p, old);
  if (as_pc) {
    ENTER(p, "multigrid");
    SCENE_CHECK(s->multigrid.pre_smooth == s->multigrid.post_smooth, p, FCM_ERR_ARG,
                "pre_smooth = %d and post_smooth = %d must be equal when the multigrid "
                "preconditions \"%s\" (the cycle must be symmetric positive definite)",
                s->multigrid.pre_smooth, s->multigrid.post_smooth,
                CHOICE_NAME(solver_names, solver_values, s->linear_solver));
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

static fcm_status read_solver(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {
      "method",    "direct",         "preconditioner", "schwarz",          "rtol",
      "atol",      "max_iterations", "newton",         "threads",          "preconditioner_tangent",
      "multigrid", "petsc_options",  "on_inversion",   "stagnation_window"};
  static const char *const skeys[] = {"threshold", "epsilon", "clamp"};
  static const char *const nkeys[] = {"rtol",        "max_iterations",
                                      "line_search", "project_psd",
                                      "rule",        "representative_acceleration"};
  fcm_scene_solver *sv = &p->scene->solver;
  fcm_integrator_options *s = &sv->integrator;
  const fcm__json *o = NULL, *sw = NULL, *nw = NULL, *mg = NULL;
  size_t old = p->path_len;
  *s = fcm_integrator_options_default();
  sv->threads = FCM_DEFAULT;
  sv->petsc_options = NULL;
  sv->stop_on_inversion = 0;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "solver", 0, &o));
  if (!o) return FCM_OK;
  ENTER(p, "solver");
  size_t here = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  READ_CHOICE_AS(p, o, "method", 0, solver_names, solver_values, s->linear_solver);
  READ_CHOICE(p, o, "direct", 0, direct_names, s->direct_method);
  READ_CHOICE(p, o, "preconditioner", 0, preconditioner_names, s->preconditioner);
  READ_CHOICE(p, o, "preconditioner_tangent", 0, tangent_names, s->preconditioner_tangent);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "schwarz", 0, &sw));
  if (sw) {
    ENTER(p, "schwarz");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, sw, skeys, COUNT(skeys)));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, sw, "threshold", 0, (fcm__range){0.0, 1.0, 1, 0},
                                           &s->schwarz_theta));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, sw, "epsilon", 0, (fcm__range){0.0, 1.0, 1, 1},
                                           &s->schwarz.epsilon));
    READ_CHOICE(p, sw, "clamp", 0, clamp_names, s->schwarz.clamp);
    fcm__scene_path_pop(p, here);
  }
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "rtol", 0, (fcm__range){0.0, 1.0, 0, 1}, &s->krylov_rtol));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "atol", 0, FCM__NONNEGATIVE, &s->krylov_atol));
  READ_INT(p, o, "max_iterations", 0, 1, 1000000000, s->krylov_max_iterations);
  READ_INT(p, o, "stagnation_window", 0, 0, 1000000000, s->krylov_stagnation_window);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "newton", 0, &nw));
  if (nw) {
    ENTER(p, "newton");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, nw, nkeys, COUNT(nkeys)));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, nw, "rtol", 0, (fcm__range){0.0, 1.0, 1, 1},
                                           &s->newton_tolerance));
    READ_INT(p, nw, "max_iterations", 0, 1, 1000000, s->newton_max_iterations);
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, nw, "line_search", 0, &s->line_search));
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, nw, "project_psd", 0, &s->project_psd));
    READ_CHOICE_AS(p, nw, "rule", 0, newton_rule_names, newton_rule_values, s->tolerance_mode);
    FCM_TRY(p->ctx, fcm__scene_read_number(p, nw, "representative_acceleration", 0, FCM__POSITIVE,
                                           &s->rep_acceleration));
    fcm__scene_path_pop(p, here);
  }
  READ_INT(p, o, "threads", 0, 0, 4096, sv->threads);
  if (sv->threads == 0) sv->threads = FCM_DEFAULT; /* "threads": 0, the OpenMP default */
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "multigrid", 0, &mg));
  if (mg) FCM_TRY(p->ctx, read_multigrid(p, mg, s));
  FCM_TRY(p->ctx, check_multigrid(p, s));
  FCM_TRY(p->ctx, fcm__scene_read_string(p, o, "petsc_options", 0, &sv->petsc_options));
  READ_CHOICE(p, o, "on_inversion", 0, inversion_names, sv->stop_on_inversion);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- time */

static fcm_status read_time(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"static",   "integrator", "dt",
                                     "duration", "steps",      "load_steps"};
  fcm_scene_time *t = &p->scene->time;
  const fcm__json *o = NULL;
  size_t old = p->path_len;
  double duration = 0.0;
  long long steps = 0;
  size_t here = 0;
  int is_static = 0;
  fcm_integrator_kind dynamic = FCM_INTEGRATOR_BACKWARD_EULER;
  t->dt = 1.0 / 60.0;
  t->load_steps = 1;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "time", 0, &o));
  if (o) {
    ENTER(p, "time");
    here = p->path_len;
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "static", 0, &is_static));
    READ_CHOICE_AS(p, o, "integrator", 0, integrator_names, integrator_values, dynamic);
    FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "dt", 0, FCM__POSITIVE, &t->dt));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "duration", 0, FCM__POSITIVE, &duration));
    FCM_TRY(p->ctx, fcm__scene_read_int(p, o, "steps", 0, 1, 1000000000, &steps));
    READ_INT(p, o, "load_steps", 0, 1, 1000000, t->load_steps);
    SCENE_CHECK(!(duration > 0.0 && steps > 0), p, FCM_ERR_ARG,
                "expected either \"duration\" or \"steps\", got both");
    if (fcm__json_member(o, "load_steps")) {
      fcm__scene_path_push_key(p, "load_steps");
      SCENE_CHECK(is_static, p, FCM_ERR_ARG, "only for static scenes (\"static\": true)");
      fcm__scene_path_pop(p, here);
    }
    if (fcm__json_member(o, "integrator")) {
      fcm__scene_path_push_key(p, "integrator");
      SCENE_CHECK(!is_static, p, FCM_ERR_ARG, "not used by static scenes (\"static\": true)");
      fcm__scene_path_pop(p, here);
    }
  }
  t->integrator = is_static ? FCM_INTEGRATOR_STATIC : dynamic;
  if (steps == 0 && !(duration > 0.0)) {
    if (is_static)
      steps = 1;
    else
      duration = 1.0;
  }
  if (steps == 0) {
    /* A duration that is a whole number of steps up to rounding keeps that number. */
    double n = duration / t->dt, r = floor(n + 0.5);
    double count = fabs(n - r) <= 1e-9 * FCM_MAX(r, 1.0) ? r : ceil(n);
    if (o) fcm__scene_path_push_key(p, fcm__json_member(o, "duration") ? "duration" : "dt");
    SCENE_CHECK(count >= 1.0 && count <= 1e9, p, FCM_ERR_ARG,
                "expected at most 1e9 steps of dt = %g, got duration / dt = %g", t->dt, n);
    steps = (long long)FCM_MAX(count, 1.0);
  }
  t->num_steps = (fcm_index)steps;
  t->duration = (double)steps * t->dt;
  SCENE_CHECK(isfinite(t->duration), p, FCM_ERR_ARG,
              "expected a finite simulated time, got steps * dt = %g", t->duration);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- output */

static fcm_status read_output(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"directory", "frame_interval", "checkpoint_interval",
                                     "background", "surface"};
  fcm_scene_output *out = &p->scene->output;
  const fcm__json *o = NULL;
  size_t old = p->path_len;
  out->directory = "fcm-output";
  out->frame_interval = 1;
  out->write_background = 1;
  out->write_surface = 1;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "output", 0, &o));
  if (!o) return FCM_OK;
  ENTER(p, "output");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_string(p, o, "directory", 0, &out->directory));
  READ_INT(p, o, "frame_interval", 0, 1, 1000000000, out->frame_interval);
  READ_INT(p, o, "checkpoint_interval", 0, 0, 1000000000, out->checkpoint_interval);
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "background", 0, &out->write_background));
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "surface", 0, &out->write_surface));
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- the whole scene */

/* Whether a name is usable in file names: [A-Za-z0-9_.-], 1..64 characters, not "." or "..". */
static int valid_name(const char *s)
{
  size_t n = strlen(s);
  if (n == 0 || n > 64 || !strcmp(s, ".") || !strcmp(s, "..")) return 0;
  for (; *s; s++)
    if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') ||
          *s == '_' || *s == '-' || *s == '.'))
      return 0;
  return 1;
}

/* The stem of a path's last component ("dir/x.json" -> "x"); "scene" if that is not a
 * valid name. */
static fcm_status default_name(fcm__scene_parser *p, const char *source, const char **out)
{
  fcm_status st = FCM_OK;
  const char *b = strrchr(source, '/');
  b = b ? b + 1 : source;
  size_t n = strlen(b);
  const char *dot = strrchr(b, '.');
  if (dot && dot != b) n = (size_t)(dot - b);
  if (n > 64) n = 64;
  char buf[65];
  memcpy(buf, b, n);
  buf[n] = '\0';
  if (!valid_name(buf)) strcpy(buf, "scene");
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
  FCM_TRY(p->ctx, fcm__scene_check_object(p, root, keys, COUNT(keys)));
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
  FCM_TRY(p->ctx, read_background(p, root));
  FCM_TRY(p->ctx, read_geometry(p, root));
  if (s->background.fit && s->geometry.kind == FCM_SCENE_GEOMETRY_NONE) {
    fcm__scene_path_push_key(p, "background");
    fcm__scene_path_push_key(p, "fit_background");
    SCENE_CHECK(0, p, FCM_ERR_ARG,
                "needs an embedded \"geometry\" to fit the grid around (the scene has none)");
  }
  FCM_TRY(p->ctx, read_material(p, root));
  FCM_TRY(p->ctx, read_quadrature(p, root));
  FCM_TRY(p->ctx, read_solver(p, root));
  FCM_TRY(p->ctx, read_time(p, root));
  FCM_TRY(p->ctx, read_output(p, root));
  FCM_TRY(p->ctx, fcm__scene_read_effects(p, root));
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
  *out = s;
  s = NULL;
cleanup:
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

/* ---------------------------------------------------------------- view */

/* " (sgs omega 1, 1+1 steps, V-cycle, coarse 2000 DOFs)" */
static void view_multigrid(FILE *f, const fcm_mg_options *m)
{
  fprintf(f, " (%s omega %g, %d+%d steps%s, %s-cycle, coarse %lld DOFs)",
          CHOICE_NAME(smoother_names, smoother_values, m->smoother), m->omega, m->pre_smooth,
          m->post_smooth, m->block_smoothing ? " with vertex blocks" : "",
          m->cycle_index == 2 ? "W" : "V", (long long)m->coarse_dofs);
}

static void view_strength(FILE *f, const char *what, int m)
{
  if (m >= 0)
    fprintf(f, " %s %d", what, m);
  else
    fprintf(f, " %s default", what);
}

void fcm_scene_view(const fcm_scene *s, FILE *f)
{
  const fcm_scene_background *b = &s->background;
  const fcm_scene_geometry *g = &s->geometry;
  const fcm_cell_rules_options *q = &s->quadrature.rules;
  const fcm_integrator_options *so = &s->solver.integrator;
  const fcm_scene_time *t = &s->time;
  fprintf(f, "scene %s (%s)\n", s->name, s->source);
  if (s->description[0]) fprintf(f, "  %s\n", s->description);
  if (b->kind == FCM_SCENE_BACKGROUND_GRID && b->fit)
    fprintf(f, "background: %s grid of %g m cubes fitted around the geometry, margin %g m\n",
            element_names[b->element], b->fit_cell_size, b->fit_margin);
  else if (b->kind == FCM_SCENE_BACKGROUND_GRID)
    fprintf(f, "background: %s grid %lld x %lld x %lld over [%g, %g] x [%g, %g] x [%g, %g] m\n",
            element_names[b->element], (long long)b->cells[0], (long long)b->cells[1],
            (long long)b->cells[2], b->min[0], b->max[0], b->min[1], b->max[1], b->min[2],
            b->max[2]);
  else
    fprintf(f, "background: mesh %s\n", b->mesh);
  fprintf(f, "geometry: ");
  switch (g->kind) {
  case FCM_SCENE_GEOMETRY_NONE:
    fprintf(f, "none (plain FEM on the background mesh)");
    break;
  case FCM_SCENE_GEOMETRY_BOX:
    fprintf(f, "box [%g, %g] x [%g, %g] x [%g, %g] m, %lld x %lld x %lld cubes", g->min[0],
            g->max[0], g->min[1], g->max[1], g->min[2], g->max[2], (long long)g->cells[0],
            (long long)g->cells[1], (long long)g->cells[2]);
    break;
  case FCM_SCENE_GEOMETRY_BALL:
  case FCM_SCENE_GEOMETRY_HEMISPHERE:
    fprintf(f, "%s centre (%g, %g, %g) radius %g m, resolution %d",
            g->kind == FCM_SCENE_GEOMETRY_BALL ? "ball" : "hemisphere", g->center[0], g->center[1],
            g->center[2], g->radius, g->resolution);
    break;
  case FCM_SCENE_GEOMETRY_HOLLOW_BALL:
    fprintf(f,
            "hollow ball centre (%g, %g, %g) radii %g..%g m, holes %g m, resolution %d, "
            "%d layers",
            g->center[0], g->center[1], g->center[2], g->inner_radius, g->outer_radius,
            g->hole_radius, g->resolution, g->layers);
    break;
  case FCM_SCENE_GEOMETRY_TUBE:
    fprintf(f, "tube centre (%g, %g, %g) along %s, radii %g..%g m, length %g m, %d x %d x %d cells",
            g->center[0], g->center[1], g->center[2], axis_names[g->axis], g->inner_radius,
            g->outer_radius, g->length, g->radial_cells, g->angular_cells, g->axial_cells);
    break;
  case FCM_SCENE_GEOMETRY_GMSH:
    fprintf(f, "mesh %s", g->mesh);
    break;
  case FCM_SCENE_GEOMETRY_SURFACE:
    fprintf(f, "surface %s, tetrahedralized (max_volume %g, size %g, quality %g), fill_holes %s",
            g->mesh, g->surface.max_volume, g->surface.size, g->surface.quality,
            g->fill_holes ? "yes" : "no");
    break;
  case FCM_SCENE_GEOMETRY_VOXELS:
    fprintf(f, "voxels %s, ", g->image);
    if (g->num_labels > 0) {
      fprintf(f, "labels");
      for (int k = 0; k < g->num_labels; k++)
        fprintf(f, "%s%g", k ? ", " : " ", g->labels[k]);
    } else {
      fprintf(f, "threshold %g", g->threshold);
    }
    fprintf(f, ", %s", g->merge ? "merged into boxes" : "one cell per voxel");
    break;
  case FCM_SCENE_GEOMETRY_LEVEL_SET:
    fprintf(f,
            "level set of %d implicit node%s (root %s), refinement %d, sampled on [%g, %g] x "
            "[%g, %g] x [%g, %g] in %lld x %lld x %lld cells",
            g->num_implicit, g->num_implicit == 1 ? "" : "s",
            implicit_names[g->implicit[g->num_implicit - 1].kind], g->refinement, g->min[0],
            g->max[0], g->min[1], g->max[1], g->min[2], g->max[2], (long long)g->cells[0],
            (long long)g->cells[1], (long long)g->cells[2]);
    break;
  default:
    fprintf(f, "tetgen %s, %s", g->mesh, g->ele);
    break;
  }
  if (g->has_transform)
    fprintf(f, ", mapped by x -> A x + b, A = [%g %g %g; %g %g %g; %g %g %g], b = (%g, %g, %g)",
            g->transform[0], g->transform[1], g->transform[2], g->transform[3], g->transform[4],
            g->transform[5], g->transform[6], g->transform[7], g->transform[8], g->offset[0],
            g->offset[1], g->offset[2]);
  fprintf(f, "\n");
  fprintf(f, "material: %s, E = %g Pa, nu = %g, rho = %g kg/m^3\n",
          fcm_material_model_name(s->material.model), s->material.young, s->material.poisson,
          s->material.density);
  fprintf(f, "quadrature: strengths");
  view_strength(f, "stiffness", q->strength[FCM_RULE_STIFFNESS]);
  view_strength(f, "mass", q->strength[FCM_RULE_MASS]);
  if (q->surface_strength >= 0)
    view_strength(f, "surface", q->surface_strength);
  else
    fprintf(f, " surface automatic");
  fprintf(f, "; simplify %s (%s); stabilization %s alpha %g; min fraction %g\n",
          fcm_cell_simplify_name(q->simplify), simplify_names[q->simplify_options.method],
          stabilization_names[q->stabilization.mode], q->stabilization.alpha, q->min_fraction);
  fprintf(f, "solver: %s", CHOICE_NAME(solver_names, solver_values, so->linear_solver));
  if (so->linear_solver == FCM_LINEAR_DIRECT)
    fprintf(f, " (%s)", direct_names[so->direct_method]);
  else if (so->linear_solver == FCM_LINEAR_MULTIGRID) {
    view_multigrid(f, &so->multigrid);
    fprintf(f, ", rtol %g, atol %g, at most %d cycles", so->krylov_rtol, so->krylov_atol,
            so->krylov_max_iterations);
  } else {
    fprintf(f, " preconditioner %s (%s tangent)", preconditioner_names[so->preconditioner],
            tangent_names[so->preconditioner_tangent]);
    if (so->preconditioner == FCM_PRECOND_SCHWARZ)
      fprintf(f, " (threshold %g, epsilon %g, %s)", so->schwarz_theta, so->schwarz.epsilon,
              clamp_names[so->schwarz.clamp]);
    if (so->preconditioner == FCM_PRECOND_MULTIGRID) view_multigrid(f, &so->multigrid);
    fprintf(f, ", rtol %g, atol %g, at most %d iterations", so->krylov_rtol, so->krylov_atol,
            so->krylov_max_iterations);
    if (so->krylov_stagnation_window > 0)
      fprintf(f, ", stagnation window %d", so->krylov_stagnation_window);
    else
      fprintf(f, ", no stagnation test");
  }
  fprintf(f,
          "; Newton %s rule, rtol %g, at most %d iterations, line search %s, PSD projection %s, "
          "|a_rep| %g m/s^2; threads %d\n",
          CHOICE_NAME(newton_rule_names, newton_rule_values, so->tolerance_mode),
          so->newton_tolerance, so->newton_max_iterations, so->line_search ? "on" : "off",
          so->project_psd ? "on" : "off", so->rep_acceleration,
          s->solver.threads > 0 ? s->solver.threads : 0);
  fprintf(f, "on inversion: %s\n", inversion_names[s->solver.stop_on_inversion ? 1 : 0]);
  if (t->integrator == FCM_INTEGRATOR_STATIC)
    fprintf(f, "time: static, %lld step(s) of %g s, %d load step(s) each\n",
            (long long)t->num_steps, t->dt, t->load_steps);
  else
    fprintf(f, "time: %s, %lld steps of dt = %g s, %g s in all\n",
            CHOICE_NAME(integrator_names, integrator_values, t->integrator),
            (long long)t->num_steps, t->dt, t->duration);
  fprintf(f, "output: %s, every %d step(s), background %s, surface %s", s->output.directory,
          s->output.frame_interval, s->output.write_background ? "yes" : "no",
          s->output.write_surface ? "yes" : "no");
  if (s->output.checkpoint_interval > 0)
    fprintf(f, ", checkpoint every %d step(s)", s->output.checkpoint_interval);
  fprintf(f, "\n");
  fprintf(f, "effects: %d\n", s->num_effects);
  for (int i = 0; i < s->num_effects; i++) {
    const fcm__effect_type *type = fcm__scene_effect_type(s->effects[i].type);
    fprintf(f, "  [%d] %s: ", i, type->name);
    type->view(&s->effects[i], f);
    fprintf(f, "\n");
  }
}
