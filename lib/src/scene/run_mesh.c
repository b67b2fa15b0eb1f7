/* The scene runner, the set-up's first phases: the embedded geometry of every kind (shapes,
 * meshes, surfaces, voxels, level sets, transformed), the background mesh (a grid, fitted around
 * the geometry or refined as an octree along its boundary and the cut surfaces, or a Gmsh mesh),
 * with errors naming the scene section they come from. The rest of the building: run.c. */
#include "scene/run_impl.h"
#include "scene/scene_impl.h"

#include "core/core_impl.h"
#include "fcm/embed.h"
#include "fcm/geom.h"
#include "fcm/levelset.h"
#include "fcm/mesh.h"
#include "fcm/voxels.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The last part of a path: what the phases' words name a file by. */
static const char *base_name(const char *path)
{
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

static fcm_status build_voxels(fcm_simulation *S, const fcm_scene_geometry *g, fcm_geometry **raw)
{
  fcm_status st = FCM_OK;
  fcm_voxel_image *img = NULL;
  fcm_voxel_options vo = fcm_voxel_options_default();
  fcm_voxel_info info;
  vo.threshold = g->threshold;
  vo.labels = g->labels;
  vo.num_labels = g->num_labels;
  vo.merge = g->merge;
  fcm__sim_phase_begin(S, FCM_SETUP_READ, 0, "reading the voxel image %s", base_name(g->image));
  FCM_TRY(S->ctx, fcm_voxel_image_create_from_file(S->ctx, g->image, &img));
  fcm__sim_phase_end(S);
  fcm__sim_phase_begin(S, FCM_SETUP_GEOMETRY, 0, "merging the selected voxels into boxes");
  FCM_TRY(S->ctx, fcm_geometry_create_from_voxels(S->ctx, img, &vo, raw, &info));
  fcm__sim_phase_end(S);
  fcm_index d[3];
  fcm_voxel_image_dims(img, d);
  char nan_note[64] = "";
  if (info.num_nan > 0)
    snprintf(nan_note, sizeof nan_note, "; %lld NaN values counted as outside",
             (long long)info.num_nan);
  snprintf(S->geometry_note, sizeof S->geometry_note,
           "voxels: %lld of %lld x %lld x %lld selected, merged into %lld boxes%s",
           (long long)info.num_selected, (long long)d[0], (long long)d[1], (long long)d[2],
           (long long)info.num_boxes, nan_note);
cleanup:
  fcm_voxel_image_destroy(&img);
  return st;
}

static fcm_status build_level_set(fcm_simulation *S, const fcm_scene_geometry *g,
                                  fcm_geometry **raw)
{
  fcm_status st = FCM_OK;
  fcm_implicit_tree tree = {g->num_implicit, g->implicit};
  fcm_level_set_options lo = fcm_level_set_options_default();
  fcm_level_set_info info;
  lo.refinement = g->refinement;
  lo.max_subcells = g->max_subcells;
  lo.progress = S->opts.geometry_progress;
  lo.progress_user = S->opts.geometry_progress_user;
  lo.progress_interval = S->opts.rules_progress_interval;
  FCM_TRY(S->ctx, fcm_implicit_check(S->ctx, &tree));
  fcm__sim_phase_begin(S, FCM_SETUP_GEOMETRY, lo.progress != NULL,
                       "marching the level set (refinement %d)", g->refinement);
  FCM_TRY(S->ctx, fcm_geometry_create_from_level_set(S->ctx, fcm_implicit_eval, &tree, g->min,
                                                     g->max, g->cells, &lo, raw, &info));
  fcm__sim_phase_end(S);
  snprintf(S->geometry_note, sizeof S->geometry_note,
           "level set: %lld tets, %lld cut cells at refinement %d (h %.3g m), volume %.6g m^3, "
           "estimated error %.2g m^3 (%.2g%%)",
           (long long)info.num_tets, (long long)info.cells_cut, g->refinement, info.h, info.volume,
           info.error_estimate, 100.0 * info.error_estimate / info.volume);
cleanup:
  return st;
}

/* The scene path an error while building the geometry of kind `k` belongs to. */
static const char *geometry_path(fcm_scene_geometry_kind k)
{
  switch (k) {
  case FCM_SCENE_GEOMETRY_GMSH:
    return "geometry.mesh";
  case FCM_SCENE_GEOMETRY_TETGEN:
    return "geometry.tetgen";
  case FCM_SCENE_GEOMETRY_VOXELS:
    return "geometry.voxels";
  case FCM_SCENE_GEOMETRY_LEVEL_SET:
    return "geometry.level_set";
  case FCM_SCENE_GEOMETRY_SURFACE:
    return "geometry.surface";
  case FCM_SCENE_GEOMETRY_NONE:
    return "geometry";
  default:
    return "geometry.shape";
  }
}

/* geometry.surface: read, optionally close holes (logged as a warning with what was
 * closed), check, then tetrahedralize or keep the surface alone; a phase each. */
static fcm_status build_surface_geometry(fcm_simulation *S, const fcm_scene_geometry *g,
                                         fcm_geometry **raw)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_surface *surf = NULL, *filled = NULL;
  fcm__sim_phase_begin(S, FCM_SETUP_READ, 0, "reading the surface %s", base_name(g->mesh));
  FCM_TRY(ctx, fcm_surface_create_from_file(ctx, g->mesh, &surf));
  fcm__sim_phase_end(S);
  if (g->fill_holes) {
    fcm_surface_fill_info fi;
    fcm__sim_phase_begin(S, FCM_SETUP_FILL_HOLES, 0, "filling the surface's holes");
    FCM_TRY(ctx, fcm_surface_create_filled(ctx, surf, &g->fill, &filled, &fi));
    if (fi.num_loops > 0) {
      char list[256];
      size_t n = 0;
      list[0] = '\0';
      for (fcm_index i = 0; i < fi.num_filled && i < FCM_SURFACE_FILL_MAX_LOOPS; i++) {
        int k = snprintf(list + n, sizeof list - n, "%s%lld", i ? ", " : "",
                         (long long)fi.loop_edges[i]);
        if (k < 0 || (size_t)k >= sizeof list - n) break;
        n += (size_t)k;
      }
      fcm__log(ctx, FCM_LOG_WARNING,
               "scene %s: geometry.surface %s: fill_holes closed %lld of %lld hole(s) (edges: "
               "%s), adding %lld triangles of total area %g; largest left open: %lld edges",
               fcm_scene_name(S->scene), g->mesh, (long long)fi.num_filled, (long long)fi.num_loops,
               list, (long long)fi.triangles_added, fi.area_added, (long long)fi.largest_left);
    }
    fcm_surface_destroy(&surf);
    surf = filled;
    filled = NULL;
    fcm__sim_phase_end(S);
  }
  /* the checks here, so that a failure names the scene and the file */
  {
    char what[512];
    fcm_surface_report rep;
    fcm_surface_mesh_options mo = g->surface;
    snprintf(what, sizeof what, "scene %s: geometry.surface %s", fcm_scene_name(S->scene), g->mesh);
    fcm__sim_phase_begin(
        S, FCM_SETUP_SURFACE_CHECK, 0,
        "checking the surface (orientation, closed, manifold, self-intersections)");
    FCM_TRY(ctx, fcm_surface_create_oriented(ctx, surf, &filled, NULL));
    fcm_surface_destroy(&surf);
    surf = filled;
    filled = NULL;
    FCM_TRY(ctx, fcm_surface_check(surf, NULL, &rep));
    FCM_TRY(ctx, fcm_surface_report_check(surf, what, &rep));
    fcm__sim_phase_end(S);
    mo.check_intersections = 0; /* done above */
    mo.orient = 0;
    if (mo.volume_mesh < 0) /* auto: the distributed backend partitions the work by the
                               geometry's cells; cuts split the surface body's cells without
                               them, unless the volume path is asked for */
      mo.volume_mesh = S->distributed || (fcm_scene_count_effects(S->scene, FCM_EFFECT_CUT) > 0 &&
                                          fcm_scene_get_quadrature(S->scene)->rules.moments ==
                                              FCM_CELL_MOMENTS_VOLUME);
    if (mo.volume_mesh)
      fcm__sim_phase_begin(S, FCM_SETUP_VOLUME_MESH, 0,
                           "meshing the volume inside %lld triangles with Gmsh",
                           (long long)fcm_surface_num_triangles(surf));
    else
      fcm__sim_phase_begin(S, FCM_SETUP_GEOMETRY, 0,
                           "building the geometry of %lld surface triangles",
                           (long long)fcm_surface_num_triangles(surf));
    FCM_TRY(ctx, fcm_geometry_create_from_surface(ctx, surf, &mo, raw));
    fcm__sim_phase_end(S);
  }
cleanup:
  fcm_surface_destroy(&surf);
  fcm_surface_destroy(&filled);
  return st;
}

/* background.fit_background: cubes of the given edge over the geometry's bounding box
 * grown by the margin, the grid centred on the box. */
static fcm_status fit_background(fcm_simulation *S, const fcm_scene_background *bg, double min[3],
                                 double max[3], fcm_index cells[3])
{
  fcm_status st = FCM_OK;
  double lo[3], hi[3], h = bg->fit_cell_size;
  fcm_geometry_bounding_box(S->geom, lo, hi);
  double total = 1.0;
  for (int d = 0; d < 3; d++) {
    FCM_CHECK(lo[d] <= hi[d], S->ctx, FCM_ERR_GEOMETRY,
              "scene %s: background.fit_background: the geometry is empty",
              fcm_scene_name(S->scene));
    double len = hi[d] - lo[d] + 2.0 * bg->fit_margin;
    double n = ceil(len / h - 1e-9);
    if (n < 1.0) n = 1.0;
    total *= n;
    FCM_CHECK(total <= 1e8, S->ctx, FCM_ERR_ARG,
              "scene %s: background.fit_background: cell_size %g gives more than 1e8 cells "
              "around the geometry's box [%g, %g] x [%g, %g] x [%g, %g]; use larger cells",
              fcm_scene_name(S->scene), h, lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]);
    double c = 0.5 * (lo[d] + hi[d]);
    cells[d] = (fcm_index)n;
    min[d] = c - 0.5 * n * h, max[d] = c + 0.5 * n * h;
  }
cleanup:
  return st;
}

/* The embedded geometry of the scene (S->geom); an error names the section of its kind. */
static fcm_status build_geometry(fcm_simulation *S, const fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_geometry *raw = NULL;
  static const char *const shapes[] = {"box", "ball", "hemisphere", "hollow ball", "tube"};
  const int shape = g->kind >= FCM_SCENE_GEOMETRY_BOX && g->kind <= FCM_SCENE_GEOMETRY_TUBE;
  if (shape)
    fcm__sim_phase_begin(S, FCM_SETUP_GEOMETRY, 0, "building the geometry (%s)",
                         shapes[g->kind - FCM_SCENE_GEOMETRY_BOX]);
  else if (g->kind == FCM_SCENE_GEOMETRY_GMSH || g->kind == FCM_SCENE_GEOMETRY_TETGEN)
    fcm__sim_phase_begin(S, FCM_SETUP_READ, 0, "reading the %s mesh %s",
                         g->kind == FCM_SCENE_GEOMETRY_GMSH ? "Gmsh" : "TetGen",
                         base_name(g->mesh));
  switch (g->kind) {
  case FCM_SCENE_GEOMETRY_BOX:
    FCM_TRY(ctx, fcm_geometry_create_box(ctx, g->min, g->max, g->cells, &raw));
    break;
  case FCM_SCENE_GEOMETRY_BALL:
    FCM_TRY(ctx, fcm_geometry_create_ball(ctx, g->center, g->radius, g->resolution, &raw));
    break;
  case FCM_SCENE_GEOMETRY_HEMISPHERE:
    FCM_TRY(ctx, fcm_geometry_create_hemisphere(ctx, g->center, g->radius, g->resolution, &raw));
    break;
  case FCM_SCENE_GEOMETRY_HOLLOW_BALL:
    FCM_TRY(ctx, fcm_geometry_create_hollow_ball(ctx, g->center, g->inner_radius, g->outer_radius,
                                                 g->hole_radius, g->resolution, g->layers, &raw));
    break;
  case FCM_SCENE_GEOMETRY_TUBE:
    FCM_TRY(ctx, fcm_geometry_create_tube(ctx, g->center, g->axis, g->inner_radius, g->outer_radius,
                                          g->length, g->radial_cells, g->angular_cells,
                                          g->axial_cells, &raw));
    break;
  case FCM_SCENE_GEOMETRY_GMSH:
    FCM_TRY(ctx, fcm_geometry_create_from_gmsh(ctx, g->mesh, &raw));
    break;
  case FCM_SCENE_GEOMETRY_TETGEN:
    FCM_TRY(ctx, fcm_geometry_create_from_tetgen(ctx, g->mesh, g->ele, &raw));
    break;
  case FCM_SCENE_GEOMETRY_SURFACE:
    FCM_TRY(ctx, build_surface_geometry(S, g, &raw));
    break;
  case FCM_SCENE_GEOMETRY_VOXELS:
    FCM_TRY(ctx, build_voxels(S, g, &raw));
    break;
  case FCM_SCENE_GEOMETRY_LEVEL_SET:
    FCM_TRY(ctx, build_level_set(S, g, &raw));
    break;
  default:
    FCM_CHECK(0, ctx, FCM_ERR_ARG, "scene %s: geometry kind %d outside [1, %d)",
              fcm_scene_name(S->scene), (int)g->kind, (int)FCM_SCENE_GEOMETRY_KIND_COUNT);
  }
  if (shape || g->kind == FCM_SCENE_GEOMETRY_GMSH || g->kind == FCM_SCENE_GEOMETRY_TETGEN)
    fcm__sim_phase_end(S);
  if (g->has_transform) {
    fcm__sim_phase_begin(S, FCM_SETUP_TRANSFORM, 0, "transforming the geometry");
    FCM_TRY(ctx, fcm_geometry_create_transformed(ctx, raw, g->transform, g->offset, &S->geom));
    fcm__sim_phase_end(S);
  } else {
    S->geom = raw;
    raw = NULL;
  }
cleanup:
  if (st != FCM_OK) fcm__sim_name_section(ctx, geometry_path(g->kind));
  fcm_geometry_destroy(&raw);
  return st;
}

/* What the octree background refines along: the embedded boundary to one level, the cut
 * effects' surfaces (before they apply) to another. */
typedef struct grid_refine {
  const fcm_geometry *geom;
  int boundary_level, cut_level, num_cuts;
  fcm_surface **cuts;
} grid_refine;

static int grid_refine_fn(const double lo[3], const double hi[3], int level, void *user)
{
  const grid_refine *g = user;
  if (level < g->boundary_level) {
    const int r = fcm_geometry_boundary_meets_box(lo, hi, level, (void *)g->geom);
    if (r) return r;
  }
  for (int k = 0; k < g->num_cuts && level < g->cut_level; k++) {
    const int r = g->cuts[k] ? fcm_surface_meets_box(lo, hi, level, g->cuts[k]) : 0;
    if (r) return r;
  }
  return 0;
}

/* The background grid over [min, max] with `cells` cubes: a box grid, or with "octree" the grid
 * refined along the embedded boundary (S->geom, built before), in the region and along the cut
 * surfaces, 2:1 balanced. */
static fcm_status create_grid(fcm_simulation *S, const fcm_scene_background *bg,
                              const double min[3], const double max[3], const fcm_index cells[3])
{
  fcm_status st = FCM_OK;
  /* "when": "cut": the cuts' refinement waits for the first cut (run.c) */
  const int cut_level = bg->octree_cuts_at_cut ? 0 : bg->octree_cuts;
  grid_refine g = {S->geom, bg->octree_boundary, cut_level, 0, NULL};
  if (!bg->octree) return fcm_mesh_create_box(S->ctx, bg->element, min, max, cells, &S->mesh);
  fcm_octree_options o = fcm_octree_options_default();
  o.region_level = bg->octree_region;
  for (int d = 0; d < 3; d++) {
    o.region_lo[d] = bg->octree_region_min[d];
    o.region_hi[d] = bg->octree_region_max[d];
  }
  if (cut_level > 0) {
    const int n = fcm_scene_count_effects(S->scene, FCM_EFFECT_CUT);
    FCM_ALLOC(S->ctx, (size_t)n, g.cuts);
    for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
      const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
      if (e->type != FCM_EFFECT_CUT) continue;
      st = fcm__sim_cut_surface(S, &e->cut, &g.cuts[g.num_cuts++]);
      if (st != FCM_OK) {
        char section[64];
        snprintf(section, sizeof section, "effects[%d].cut", k);
        fcm__sim_name_section(S->ctx, section);
        goto cleanup;
      }
    }
  }
  if (bg->octree_boundary > 0 || cut_level > 0) {
    o.refine_level = FCM_MAX(bg->octree_boundary, cut_level);
    o.refine = grid_refine_fn;
    o.refine_user = &g;
  }
  FCM_TRY(S->ctx, fcm_mesh_create_octree(S->ctx, bg->element, min, max, cells, &o, &S->mesh));
cleanup:
  for (int k = 0; k < g.num_cuts; k++)
    fcm_surface_destroy(&g.cuts[k]);
  fcm__free(S->ctx, g.cuts);
  return st;
}

fcm_status fcm__sim_build_mesh_geometry(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_scene *scene = S->scene;
  const fcm_scene_background *bg = fcm_scene_get_background(scene);
  const fcm_scene_geometry *g = fcm_scene_get_geometry(scene);
  if (bg->kind == FCM_SCENE_BACKGROUND_GRID && bg->fit) {
    double min[3], max[3];
    fcm_index cells[3];
    FCM_TRY(ctx, build_geometry(S, g)); /* the parser ensured there is one */
    fcm__sim_phase_begin(S, FCM_SETUP_BACKGROUND, 0,
                         "fitting the background grid around the geometry");
    st = fit_background(S, bg, min, max, cells);
    if (st == FCM_OK) st = create_grid(S, bg, min, max, cells);
    if (st != FCM_OK) fcm__sim_name_section(ctx, "background.fit_background");
    FCM_TRY(ctx, st);
  } else if (bg->kind == FCM_SCENE_BACKGROUND_GRID) {
    if (bg->octree_boundary > 0 || bg->octree_cuts > 0) { /* refined along the geometry's
                                                             boundary or cuts: built first */
      FCM_TRY(ctx, build_geometry(S, g));
    }
    fcm__sim_phase_begin(S, FCM_SETUP_BACKGROUND, 0,
                         "building the background grid (%lld x %lld x %lld cells%s)",
                         (long long)bg->cells[0], (long long)bg->cells[1], (long long)bg->cells[2],
                         bg->octree ? ", refined as an octree" : "");
    st = create_grid(S, bg, bg->min, bg->max, bg->cells);
  } else {
    fcm__sim_phase_begin(S, FCM_SETUP_BACKGROUND, 0, "reading the background mesh %s",
                         base_name(bg->mesh));
    st = fcm_mesh_create_from_gmsh(ctx, bg->mesh, &S->mesh);
  }
  if (st != FCM_OK)
    fcm__sim_name_section(ctx,
                          bg->kind == FCM_SCENE_BACKGROUND_GRID ? "background" : "background.mesh");
  FCM_TRY(ctx, st);
  fcm__sim_phase_end(S);
  S->nn = fcm_mesh_num_nodes(S->mesh);

  if (g->kind != FCM_SCENE_GEOMETRY_NONE && !S->geom) {
    FCM_TRY(ctx, build_geometry(S, g));
  }
cleanup:
  return st;
}

fcm_status fcm__scene_mesh_geometry(fcm_ctx *ctx, const fcm_scene *scene, fcm_mesh **mesh,
                                    fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  fcm_simulation *S = NULL;
  *mesh = NULL;
  *geom = NULL;
  FCM_ALLOC(ctx, 1, S);
  S->ctx = ctx;
  S->scene = scene;
  S->opts = fcm_simulation_options_default();
  S->distributed = 1; /* the PETSc backend's partition and linear driver */
  FCM_TRY(ctx, fcm__sim_build_mesh_geometry(S));
  *mesh = S->mesh;
  *geom = S->geom;
  S->mesh = NULL;
  S->geom = NULL;
cleanup:
  fcm_simulation_destroy(&S);
  return st;
}
