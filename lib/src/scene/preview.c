/* The scene runner's look before the set-up: the background nodes the regions select, checked
 * against a coarse classification of the cells, and the preview files (the grid, the embedded
 * surface, each effect's nodes or boundary points, the cut surfaces) with their summary. */
#include "scene/run_impl.h"
#include "scene/scene_impl.h"

#include "core/core_impl.h"
#include "embed/embed_impl.h"
#include "io/io_impl.h"
#include "fcm/io.h"
#include "fcm/mesh.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* Sub-triangles per edge of a surface triangle at most, when sampling it. */
#define PREVIEW_MAX_SPLIT 16

fcm_index fcm__sim_select_nodes(const fcm_mesh *mesh, const fcm_region *r, fcm_index *nodes,
                                fcm_index *bad)
{
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  fcm_index n = 0;
  if (bad) *bad = -1;
  if (r->kind == FCM_REGION_NODES) {
    for (fcm_index k = 0; k < r->num_nodes; k++) {
      const fcm_index a = r->nodes[k];
      if (a < 0 || a >= nn) {
        if (bad && *bad < 0) *bad = a;
        continue;
      }
      if (nodes) nodes[n] = a;
      n++;
    }
    return n;
  }
  for (fcm_index a = 0; a < nn; a++)
    if (fcm_region_contains(r, X + 3 * a)) {
      if (nodes) nodes[n] = a;
      n++;
    }
  return n;
}

/* The region of effect e and what it selects (NULL and NOTHING: none). */
static const fcm_region *effect_region(const fcm_effect *e, fcm_preview_selects *what)
{
  *what = FCM_PREVIEW_NOTHING;
  switch (e->type) {
  case FCM_EFFECT_FIXED:
    *what = e->fixed.boundary ? FCM_PREVIEW_BOUNDARY : FCM_PREVIEW_NODES;
    return &e->fixed.region;
  case FCM_EFFECT_MOTION:
    *what = e->motion.boundary ? FCM_PREVIEW_BOUNDARY : FCM_PREVIEW_NODES;
    return &e->motion.region;
  case FCM_EFFECT_INITIAL_VELOCITY:
    *what = FCM_PREVIEW_NODES;
    return &e->initial_velocity.region;
  case FCM_EFFECT_TRACTION:
    *what = FCM_PREVIEW_BOUNDARY;
    return &e->traction.region;
  case FCM_EFFECT_PRESSURE:
    *what = FCM_PREVIEW_BOUNDARY;
    return &e->pressure.region;
  default:
    return NULL;
  }
}

/* The region in words for messages. */
static void region_words(const fcm_region *r, char *buf, size_t len)
{
  switch (r->kind) {
  case FCM_REGION_BOX:
    snprintf(buf, len, "box [%g, %g, %g] to [%g, %g, %g]", r->min[0], r->min[1], r->min[2],
             r->max[0], r->max[1], r->max[2]);
    break;
  case FCM_REGION_HALF_SPACE:
    snprintf(buf, len, "half_space through (%g, %g, %g) with normal (%g, %g, %g)", r->point[0],
             r->point[1], r->point[2], r->normal[0], r->normal[1], r->normal[2]);
    break;
  case FCM_REGION_NODES:
    snprintf(buf, len, "nodes: %lld ids", (long long)r->num_nodes);
    break;
  default:
    snprintf(buf, len, "all");
  }
}

/* The coarse classification: cls (NULL without a geometry: every cell has material), counts
 * per class, and the nodes a cell with material uses (active, num nodes entries). */
typedef struct activity {
  unsigned char *cls, *active;
  fcm_index counts[3], num_active;
} activity;

static void activity_free(fcm_ctx *ctx, activity *A)
{
  fcm__free(ctx, A->cls);
  fcm__free(ctx, A->active);
  A->cls = A->active = NULL;
}

static fcm_status activity_build(fcm_simulation *S, activity *A)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_index nc = fcm_mesh_num_cells(S->mesh);
  const int npc = fcm_mesh_nodes_per_cell(S->mesh);
  const fcm_index *cells = fcm_mesh_cells(S->mesh);
  memset(A, 0, sizeof *A);
  FCM_ALLOC(ctx, (size_t)S->nn + 1, A->active);
  if (S->geom) {
    FCM_ALLOC(ctx, (size_t)nc + 1, A->cls);
    FCM_TRY(ctx, fcm__embed_classify_coarse(ctx, S->mesh, S->geom, A->cls, A->counts));
  } else {
    A->counts[FCM_CELL_UNCUT] = nc;
  }
  for (fcm_index c = 0; c < nc; c++)
    if (!A->cls || A->cls[c] != FCM_CELL_DROPPED)
      for (int a = 0; a < npc; a++)
        A->active[cells[(size_t)npc * c + a]] = 1;
  for (fcm_index a = 0; a < S->nn; a++)
    A->num_active += A->active[a];
cleanup:
  if (st != FCM_OK) activity_free(ctx, A);
  return st;
}

/* The checks of fcm__sim_check_regions() on a classification. */
static fcm_status check_regions(fcm_simulation *S, const activity *A)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_index *nodes = NULL;
  char words[160];
  /* no node active at all: the body misses the mesh, which the rules build reports with both
   * boxes, a better message than any region's */
  if (A->num_active == 0) return FCM_OK;
  FCM_ALLOC(ctx, (size_t)S->nn + 1, nodes);
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    fcm_preview_selects what;
    const fcm_region *r = effect_region(e, &what);
    if (what != FCM_PREVIEW_NODES || e->type == FCM_EFFECT_INITIAL_VELOCITY) continue;
    fcm_index bad, active = 0;
    const fcm_index n = fcm__sim_select_nodes(S->mesh, r, nodes, &bad);
    region_words(r, words, sizeof words);
    FCM_CHECK(bad < 0, ctx, FCM_ERR_ARG, "scene %s: effects[%d]: node %lld out of range [0, %lld)",
              fcm_scene_name(S->scene), k, (long long)bad, (long long)S->nn);
    FCM_CHECK(n > 0, ctx, FCM_ERR_ARG,
              "scene %s: effects[%d]: the %s region (%s) contains no background-mesh node",
              fcm_scene_name(S->scene), k, fcm_effect_type_name(e->type), words);
    for (fcm_index j = 0; j < n; j++)
      active += A->active[nodes[j]];
    FCM_CHECK(active > 0, ctx, FCM_ERR_ARG,
              "scene %s: effects[%d]: the %s region (%s) selects %lld background-mesh node%s, none "
              "of them active: no background cell around them holds material (%lld of %lld nodes "
              "are active), so it would hold nothing; move the region onto the body",
              fcm_scene_name(S->scene), k, fcm_effect_type_name(e->type), words, (long long)n,
              n == 1 ? "" : "s", (long long)A->num_active, (long long)S->nn);
  }
cleanup:
  fcm__free(ctx, nodes);
  return st;
}

fcm_status fcm__sim_check_regions(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  activity A;
  memset(&A, 0, sizeof A);
  int any = 0;
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    any |= (e->type == FCM_EFFECT_FIXED && !e->fixed.boundary) ||
           (e->type == FCM_EFFECT_MOTION && !e->motion.boundary);
  }
  if (!any) return FCM_OK; /* nothing to check: no classification */
  FCM_TRY(S->ctx, activity_build(S, &A));
  FCM_TRY(S->ctx, check_regions(S, &A));
cleanup:
  activity_free(S->ctx, &A);
  return st;
}

/* ---------------------------------------------------------------- the preview files */

/* The parts written so far (for the .pvd) and the writer they share. */
typedef struct preview {
  fcm_simulation *S;
  const char *dir, *name;
  fcm_vtu *vtu;
  int num_parts;
  const char *parts[5];
} preview;

/* Write the writer's data set as <dir>/<name>_preview_<part>.vtu and clear it. */
static fcm_status write_part(preview *P, const char *part)
{
  fcm_status st = FCM_OK;
  char path[4096];
  snprintf(path, sizeof path, "%s/%s_preview_%s.vtu", P->dir, P->name, part);
  FCM_TRY(P->S->ctx, fcm_vtu_write(P->vtu, path, NULL));
  P->parts[P->num_parts++] = part;
cleanup:
  fcm_vtu_clear(P->vtu);
  return st;
}

/* <dir>/<name>_preview.pvd: the parts of one data set. */
static fcm_status write_pvd(preview *P)
{
  fcm_status st = FCM_OK;
  char path[4096], files[5][512];
  const char *names[5] = {NULL}, *file[5] = {NULL};
  snprintf(path, sizeof path, "%s/%s_preview.pvd", P->dir, P->name);
  for (int k = 0; k < P->num_parts; k++) {
    snprintf(files[k], sizeof files[k], "%s_preview_%s.vtu", P->name, P->parts[k]);
    names[k] = P->parts[k], file[k] = files[k];
  }
  FCM_TRY(P->S->ctx, fcm__pvd_write_parts(P->S->ctx, path, P->num_parts, names, file));
cleanup:
  return st;
}

/* The background grid with the cell classes and the active nodes. */
static fcm_status write_grid(preview *P, const activity *A)
{
  fcm_status st = FCM_OK;
  fcm_simulation *S = P->S;
  fcm_ctx *ctx = S->ctx;
  const fcm_index nc = fcm_mesh_num_cells(S->mesh);
  int32_t *cls = NULL, *act = NULL;
  FCM_ALLOC(ctx, (size_t)nc + 1, cls);
  FCM_ALLOC(ctx, (size_t)S->nn + 1, act);
  for (fcm_index c = 0; c < nc; c++)
    cls[c] = A->cls ? A->cls[c] : FCM_CELL_UNCUT;
  for (fcm_index a = 0; a < S->nn; a++)
    act[a] = A->active[a];
  FCM_TRY(ctx, fcm_vtu_set_points(P->vtu, S->nn, fcm_mesh_coords(S->mesh)));
  FCM_TRY(ctx, fcm_vtu_set_cells(P->vtu, fcm_mesh_get_element_info(S->mesh)->vtk_cell_type, nc,
                                 fcm_mesh_cells(S->mesh)));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(P->vtu, FCM_VTU_CELL_DATA, "class", 1, nc, cls));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(P->vtu, FCM_VTU_POINT_DATA, "active", 1, S->nn, act));
  FCM_TRY(ctx, write_part(P, "grid"));
cleanup:
  fcm_vtu_clear(P->vtu);
  fcm__free(ctx, cls);
  fcm__free(ctx, act);
  return st;
}

/* The embedded surface's triangles (the geometry's nodes as points). */
static fcm_status write_surface(preview *P)
{
  fcm_status st = FCM_OK;
  const fcm_geometry *g = P->S->geom;
  fcm_ctx *ctx = P->S->ctx;
  FCM_TRY(ctx, fcm_vtu_set_points(P->vtu, fcm_geometry_num_nodes(g), fcm_geometry_coords(g)));
  FCM_TRY(ctx, fcm_vtu_set_cells(P->vtu, FCM_VTK_TRIANGLE, fcm_geometry_num_boundary_triangles(g),
                                 fcm_geometry_boundary_triangles(g)));
  FCM_TRY(ctx, write_part(P, "surface"));
cleanup:
  fcm_vtu_clear(P->vtu);
  return st;
}

/* Sample points of the surface's triangles (n x n sub-triangles' centroids each, n the longest
 * edge over h rounded up, at most PREVIEW_MAX_SPLIT): *x (3 per point, caller frees), *np. */
static fcm_status sample_surface(fcm_ctx *ctx, const fcm_geometry *g, double h, double **x,
                                 fcm_index *np)
{
  fcm_status st = FCM_OK;
  const fcm_index nt = fcm_geometry_num_boundary_triangles(g);
  const fcm_index *tri = fcm_geometry_boundary_triangles(g);
  const double *X = fcm_geometry_coords(g);
  int *split = NULL;
  fcm_index n = 0, m = 0;
  *x = NULL;
  FCM_ALLOC(ctx, (size_t)nt + 1, split);
  for (fcm_index t = 0; t < nt; t++) {
    double e = 0.0;
    for (int k = 0; k < 3; k++) {
      const double *p = X + 3 * tri[3 * t + k], *q = X + 3 * tri[3 * t + (k + 1) % 3];
      e = fmax(e, sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                       (p[2] - q[2]) * (p[2] - q[2])));
    }
    const double s = h > 0.0 ? ceil(e / h) : 1.0;
    split[t] = s < 1.0 ? 1 : (s > PREVIEW_MAX_SPLIT ? PREVIEW_MAX_SPLIT : (int)s);
    n += (fcm_index)split[t] * split[t];
  }
  FCM_ALLOC_RAW(ctx, 3 * (size_t)n + 3, *x);
  for (fcm_index t = 0; t < nt; t++) {
    const double *a = X + 3 * tri[3 * t], *b = X + 3 * tri[3 * t + 1], *c = X + 3 * tri[3 * t + 2];
    const int s = split[t];
    for (int i = 0; i < s; i++)
      for (int j = 0; i + j < s; j++)
        for (int up = 0; up < 2; up++) {
          if (up && i + j == s - 1) continue; /* the row's last sub-triangle has no twin */
          const double u = (i + (up ? 2.0 : 1.0) / 3.0) / s, v = (j + (up ? 2.0 : 1.0) / 3.0) / s;
          for (int d = 0; d < 3; d++)
            (*x)[3 * m + d] = a[d] + u * (b[d] - a[d]) + v * (c[d] - a[d]);
          m++;
        }
  }
  *np = m;
cleanup:
  fcm__free(ctx, split);
  if (st != FCM_OK) fcm__free(ctx, *x), *x = NULL;
  return st;
}

/* The points each effect selects: its background nodes (what = NODES; point arrays `effect`
 * and `active`) or the surface samples in its region (BOUNDARY; `effect`), one vertex per
 * (effect, point) pair; the counts into effects (may be NULL). */
static fcm_status write_selection(preview *P, const activity *A, fcm_preview_selects what,
                                  const double *samples, fcm_index num_samples,
                                  fcm_preview_effect *effects)
{
  fcm_status st = FCM_OK;
  fcm_simulation *S = P->S;
  fcm_ctx *ctx = S->ctx;
  const double *X = fcm_mesh_coords(S->mesh);
  fcm_index *nodes = NULL, total = 0, cap = 0;
  double *x = NULL;
  int32_t *eff = NULL, *act = NULL;
  FCM_ALLOC(ctx, (size_t)S->nn + 1, nodes);
  for (int pass = 0; pass < 2; pass++) { /* count, then fill */
    if (pass == 1) {
      if (total == 0) goto cleanup;
      cap = total;
      FCM_ALLOC_RAW(ctx, 3 * (size_t)cap, x);
      FCM_ALLOC_RAW(ctx, (size_t)cap, eff);
      FCM_ALLOC_RAW(ctx, (size_t)cap, act);
      total = 0;
    }
    for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
      fcm_preview_selects sel;
      const fcm_region *r = effect_region(fcm_scene_get_effect(S->scene, k), &sel);
      if (sel != what) continue;
      fcm_index n = 0, active = 0;
      if (what == FCM_PREVIEW_NODES) {
        n = fcm__sim_select_nodes(S->mesh, r, nodes, NULL);
        for (fcm_index j = 0; j < n; j++) {
          active += A->active[nodes[j]];
          if (pass == 1) {
            memcpy(x + 3 * (total + j), X + 3 * nodes[j], 3 * sizeof *x);
            eff[total + j] = k, act[total + j] = A->active[nodes[j]];
          }
        }
      } else {
        for (fcm_index j = 0; j < num_samples; j++)
          if (fcm_region_contains(r, samples + 3 * j)) {
            if (pass == 1) {
              memcpy(x + 3 * (total + n), samples + 3 * j, 3 * sizeof *x);
              eff[total + n] = k, act[total + n] = 1;
            }
            n++;
          }
      }
      total += n;
      if (pass == 1 || !effects) continue;
      effects[k].nodes = what == FCM_PREVIEW_NODES ? n : 0;
      effects[k].active_nodes = what == FCM_PREVIEW_NODES ? active : 0;
      effects[k].boundary_points = what == FCM_PREVIEW_BOUNDARY ? n : 0;
    }
  }
  FCM_TRY(ctx, fcm_vtu_set_points(P->vtu, total, x));
  FCM_TRY(ctx, fcm_vtu_set_cells(P->vtu, FCM_VTK_VERTEX, total, NULL));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(P->vtu, FCM_VTU_POINT_DATA, "effect", 1, total, eff));
  if (what == FCM_PREVIEW_NODES)
    FCM_TRY(ctx, fcm_vtu_add_field_int32(P->vtu, FCM_VTU_POINT_DATA, "active", 1, total, act));
  FCM_TRY(ctx, write_part(P, what == FCM_PREVIEW_NODES ? "nodes" : "boundary_points"));
cleanup:
  fcm_vtu_clear(P->vtu);
  fcm__free(ctx, nodes);
  fcm__free(ctx, x);
  fcm__free(ctx, eff);
  fcm__free(ctx, act);
  return st;
}

/* The cut surfaces, one after the other, with cell arrays `effect` and `time`. */
static fcm_status write_cuts(preview *P, fcm_preview_effect *effects)
{
  fcm_status st = FCM_OK;
  fcm_simulation *S = P->S;
  fcm_ctx *ctx = S->ctx;
  fcm_surface *surf = NULL;
  double *x = NULL, *time = NULL;
  fcm_index *tri = NULL, nv = 0, nt = 0;
  int32_t *eff = NULL;
  for (int pass = 0; pass < 2; pass++) { /* count, then fill */
    if (pass == 1) {
      if (nt == 0) goto cleanup;
      FCM_ALLOC_RAW(ctx, 3 * (size_t)nv, x);
      FCM_ALLOC_RAW(ctx, 3 * (size_t)nt, tri);
      FCM_ALLOC_RAW(ctx, (size_t)nt, eff);
      FCM_ALLOC_RAW(ctx, (size_t)nt, time);
      nv = nt = 0;
    }
    for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
      const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
      if (e->type != FCM_EFFECT_CUT) continue;
      FCM_TRY(ctx, fcm__sim_cut_surface(S, &e->cut, &surf));
      const fcm_index sv = surf ? fcm_surface_num_vertices(surf) : 0;
      const fcm_index ntri = surf ? fcm_surface_num_triangles(surf) : 0;
      if (effects) effects[k].cut_triangles = ntri;
      if (pass == 1 && surf) {
        memcpy(x + 3 * nv, fcm_surface_coords(surf), 3 * (size_t)sv * sizeof *x);
        const fcm_index *t = fcm_surface_triangles(surf);
        for (fcm_index j = 0; j < ntri; j++) {
          for (int a = 0; a < 3; a++)
            tri[3 * (nt + j) + a] = nv + t[3 * j + a];
          eff[nt + j] = k, time[nt + j] = e->cut.time;
        }
      }
      nv += sv, nt += ntri;
      fcm_surface_destroy(&surf);
    }
  }
  FCM_TRY(ctx, fcm_vtu_set_points(P->vtu, nv, x));
  FCM_TRY(ctx, fcm_vtu_set_cells(P->vtu, FCM_VTK_TRIANGLE, nt, tri));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(P->vtu, FCM_VTU_CELL_DATA, "effect", 1, nt, eff));
  FCM_TRY(ctx, fcm_vtu_add_field(P->vtu, FCM_VTU_CELL_DATA, "time", 1, nt, time));
  FCM_TRY(ctx, write_part(P, "cuts"));
cleanup:
  fcm_vtu_clear(P->vtu);
  fcm_surface_destroy(&surf);
  fcm__free(ctx, x);
  fcm__free(ctx, tri);
  fcm__free(ctx, eff);
  fcm__free(ctx, time);
  return st;
}

/* The background cells' size: (volume of the mesh's box / cells)^(1/3). */
static double cell_size(const fcm_mesh *mesh)
{
  double lo[3], hi[3];
  fcm_mesh_bounding_box(mesh, lo, hi);
  const double v = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  return v > 0.0 && nc > 0 ? cbrt(v / (double)nc) : 0.0;
}

/* Every file of the preview and the counts (the mesh and geometry built). */
static fcm_status write_files(fcm_simulation *S, const char *dir, const activity *A,
                              fcm_simulation_preview_info *info, fcm_preview_effect *effects)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  double *samples = NULL;
  fcm_index ns = 0;
  preview P = {S, dir, fcm_scene_name(S->scene), NULL, 0, {NULL}};
  info->sample_spacing = cell_size(S->mesh);
  FCM_TRY(ctx, fcm_vtu_create(ctx, &P.vtu));
  FCM_TRY(ctx, write_grid(&P, A));
  if (S->geom) {
    FCM_TRY(ctx, write_surface(&P));
    FCM_TRY(ctx, sample_surface(ctx, S->geom, info->sample_spacing, &samples, &ns));
    info->surface_triangles = fcm_geometry_num_boundary_triangles(S->geom);
    info->surface_samples = ns;
  }
  FCM_TRY(ctx, write_selection(&P, A, FCM_PREVIEW_NODES, NULL, 0, effects));
  FCM_TRY(ctx, write_selection(&P, A, FCM_PREVIEW_BOUNDARY, samples, ns, effects));
  if (S->geom) FCM_TRY(ctx, write_cuts(&P, effects));
  FCM_TRY(ctx, write_pvd(&P));
  info->files = P.num_parts + 1;
cleanup:
  fcm_vtu_destroy(&P.vtu);
  fcm__free(ctx, samples);
  return st;
}

fcm_status fcm_simulation_write_preview(fcm_ctx *ctx, const fcm_scene *scene,
                                        const fcm_simulation_options *opts, const char *dir,
                                        fcm_simulation_preview_info *info,
                                        fcm_preview_effect *effects)
{
  fcm_status st = FCM_OK;
  fcm_simulation *S = NULL;
  fcm_simulation_preview_info own;
  activity A;
  memset(&A, 0, sizeof A);
  if (!info) info = &own;
  memset(info, 0, sizeof *info);
  FCM_CHECK(ctx && scene && dir, ctx, FCM_ERR_ARG, "simulation: preview: NULL argument");
  if (effects) {
    memset(effects, 0, (size_t)fcm_scene_num_effects(scene) * sizeof *effects);
    for (int k = 0; k < fcm_scene_num_effects(scene); k++)
      effect_region(fcm_scene_get_effect(scene, k), &effects[k].selects);
  }
  FCM_ALLOC(ctx, 1, S);
  S->ctx = ctx;
  S->scene = scene;
  S->opts = opts ? *opts : fcm_simulation_options_default();
  S->phase = -1;
  FCM_TRY(ctx, fcm__sim_build_mesh_geometry(S));
  FCM_TRY(ctx, activity_build(S, &A));
  info->element = fcm_mesh_element_type(S->mesh);
  info->num_cells = fcm_mesh_num_cells(S->mesh);
  info->num_nodes = S->nn;
  memcpy(info->cells, A.counts, sizeof A.counts);
  info->active_nodes = A.num_active;
  FCM_TRY(ctx, write_files(S, dir, &A, info, effects));
  FCM_TRY(ctx, check_regions(S, &A));
cleanup:
  activity_free(ctx, &A);
  fcm_simulation_destroy(&S);
  return st;
}

void fcm_simulation_preview_view(const fcm_scene *scene, const fcm_simulation_preview_info *info,
                                 const fcm_preview_effect *effects, FILE *f)
{
  if (!scene || !info || !f) return;
  const fcm_element_info *ei = fcm_element_get_info(info->element);
  fprintf(f, "preview of scene %s\n", fcm_scene_name(scene));
  fprintf(f,
          "  background  %s, %lld cells: %lld inside, %lld cut, %lld outside; %lld nodes, %lld "
          "active\n",
          ei ? ei->name : "?", (long long)info->num_cells, (long long)info->cells[FCM_CELL_UNCUT],
          (long long)info->cells[FCM_CELL_CUT], (long long)info->cells[FCM_CELL_DROPPED],
          (long long)info->num_nodes, (long long)info->active_nodes);
  if (info->surface_triangles > 0)
    fprintf(f, "  surface     %lld triangles, %lld sample points (spacing %.3g m)\n",
            (long long)info->surface_triangles, (long long)info->surface_samples,
            info->sample_spacing);
  else
    fprintf(f, "  surface     none (no geometry: the background mesh is the body)\n");
  for (int k = 0; effects && k < fcm_scene_num_effects(scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(scene, k);
    const fcm_preview_effect *p = effects + k;
    const char *name = fcm_effect_type_name(e->type);
    if (p->selects == FCM_PREVIEW_NODES)
      fprintf(f, "  effects[%d]  %s: region selects %lld nodes, %lld active\n", k, name,
              (long long)p->nodes, (long long)p->active_nodes);
    else if (p->selects == FCM_PREVIEW_BOUNDARY)
      fprintf(f, "  effects[%d]  %s: region selects %lld boundary points%s\n", k, name,
              (long long)p->boundary_points,
              p->boundary_points == 0 ? " (none: check it against the surface)" : "");
    else if (e->type == FCM_EFFECT_CUT)
      fprintf(f, "  effects[%d]  cut at t = %g s: %lld triangles%s\n", k, e->cut.time,
              (long long)p->cut_triangles,
              p->cut_triangles == 0 ? " (the plane misses the body)" : "");
  }
}
