/* The scene runner: builds the pipeline a scene asks for (mesh, geometry, cell rules, space,
 * integrator with exactly its effects), steps it, writes frames and the per-step log. */
#include "scene/run_impl.h"
#include "scene/scene_impl.h"

#include "core/core_impl.h"
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"
#include "sim/sim_backend.h"
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/geom.h"
#include "fcm/io.h"
#include "fcm/levelset.h"
#include "fcm/voxels.h"
#include "fcm/mesh.h"
#include "io/io_impl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

fcm_simulation_options fcm_simulation_options_default(void)
{
  fcm_simulation_options o;
  memset(&o, 0, sizeof o);
  o.max_steps = FCM_DEFAULT;
  o.checkpoint_interval = FCM_DEFAULT;
  o.rules_progress_interval = 0.1;
  return o;
}

fcm_status fcm__sim_grow(fcm_ctx *ctx, void **array, long long *cap, long long need, size_t size)
{
  fcm_status st = FCM_OK;
  if (need <= *cap) return FCM_OK;
  long long c = *cap ? *cap : 64;
  while (c < need)
    c *= 2;
  FCM_TRY(ctx, fcm__resize(ctx, array, (size_t)*cap, (size_t)c, size));
  *cap = c;
cleanup:
  return st;
}

/* ---------------------------------------------------------------- effect hooks
 * The run-time hooks of the effect modules; the table that names them per effect type is
 * in effects.c (fcm__effect_type). */

static double window_scale(void *user, double t)
{
  const fcm_effect *e = user;
  double s = e->type == FCM_EFFECT_TRACTION ? e->traction.start : e->pressure.start;
  double f = e->type == FCM_EFFECT_TRACTION ? e->traction.end : e->pressure.end;
  return (t >= s - 1e-12 && t <= f + 1e-12) ? 1.0 : 0.0;
}

static void surface_field(void *user, const double x[3], const double normal[3], double value[3])
{
  const fcm_effect *e = user;
  value[0] = value[1] = value[2] = 0.0;
  if (e->type == FCM_EFFECT_TRACTION) {
    if (fcm_region_contains(&e->traction.region, x))
      for (int d = 0; d < 3; d++)
        value[d] = e->traction.traction[d];
  } else if (normal && fcm_region_contains(&e->pressure.region, x)) {
    for (int d = 0; d < 3; d++)
      value[d] = -e->pressure.pressure * normal[d];
  }
}

/* Background nodes of a region: count only (nodes NULL) or fill. */
static fcm_status region_nodes(fcm_simulation *S, const fcm_region *r, int effect_index,
                               fcm_index *nodes, fcm_index *count)
{
  fcm_status st = FCM_OK;
  const double *X = fcm_mesh_coords(S->mesh);
  fcm_index n = 0;
  if (r->kind == FCM_REGION_NODES) {
    for (fcm_index k = 0; k < r->num_nodes; k++) {
      FCM_CHECK(r->nodes[k] >= 0 && r->nodes[k] < S->nn, S->ctx, FCM_ERR_ARG,
                "scene %s: effects[%d]: node %lld out of range [0, %lld)", fcm_scene_name(S->scene),
                effect_index, (long long)r->nodes[k], (long long)S->nn);
      if (nodes) nodes[n] = r->nodes[k];
      n++;
    }
  } else {
    for (fcm_index a = 0; a < S->nn; a++)
      if (fcm_region_contains(r, X + 3 * a)) {
        if (nodes) nodes[n] = a;
        n++;
      }
  }
  FCM_CHECK(n > 0, S->ctx, FCM_ERR_ARG,
            "scene %s: effects[%d]: the region contains no background-mesh node",
            fcm_scene_name(S->scene), effect_index);
  *count = n;
cleanup:
  return st;
}

fcm_status fcm__effect_apply_constraint(fcm_simulation *S, const fcm_effect *e)
{
  fcm_status st = FCM_OK;
  fcm_index *nodes = NULL, n = 0;
  int id = -1;
  const fcm_region *r = e->type == FCM_EFFECT_FIXED ? &e->fixed.region : &e->motion.region;
  fcm_motion m = fcm_motion_default();
  if (e->type == FCM_EFFECT_FIXED) {
    for (int d = 0; d < 3; d++)
      m.components[d] = e->fixed.components[d];
  } else {
    m = e->motion.motion;
  }
  if (!S->react_effect) { /* the log's reaction columns: one group per constraint effect */
    FCM_ALLOC(S->ctx, fcm_scene_num_effects(S->scene), S->react_effect);
    FCM_ALLOC(S->ctx, fcm_scene_num_effects(S->scene), S->react_id);
  }
  const int boundary = e->type == FCM_EFFECT_FIXED ? e->fixed.boundary : e->motion.boundary;
  if (boundary) { /* embedded-boundary points in the region: Nitsche or penalty */
    FCM_CHECK(S->c.surface_rules, S->ctx, FCM_ERR_ARG,
              "scene %s: effects[%d]: %s on the \"boundary\" needs an embedded geometry",
              fcm_scene_name(S->scene), e->index, fcm_effect_type_name(e->type));
    FCM_TRY(S->ctx, fcm_integrator_add_boundary_constraint(
                        S->integ, fcm_region_select, (void *)r, &m,
                        e->type == FCM_EFFECT_FIXED ? &e->fixed.boundary_options
                                                    : &e->motion.boundary_options,
                        &id));
    S->react_effect[S->num_react] = e->index;
    S->react_id[S->num_react++] = -1 - id; /* negative: a boundary constraint */
    S->c.constraints++;
    goto cleanup;
  }
  FCM_TRY(S->ctx, region_nodes(S, r, e->index, NULL, &n));
  FCM_ALLOC(S->ctx, n, nodes);
  FCM_TRY(S->ctx, region_nodes(S, r, e->index, nodes, &n));
  FCM_TRY(S->ctx, fcm_integrator_add_constraint(S->integ, n, nodes, &m, &id));
  S->react_effect[S->num_react] = e->index;
  S->react_id[S->num_react++] = id;
  S->c.constraints++;
  S->c.constrained_nodes += n;
cleanup:
  fcm__free(S->ctx, nodes);
  return st;
}

fcm_status fcm__effect_apply_gravity(fcm_simulation *S, const fcm_effect *e)
{
  fcm_status st = FCM_OK;
  FCM_TRY(S->ctx, fcm_integrator_add_gravity(S->integ, e->gravity.acceleration, NULL, NULL));
cleanup:
  return st;
}

fcm_status fcm__effect_apply_surface_load(fcm_simulation *S, const fcm_effect *e)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(S->c.surface_rules, S->ctx, FCM_ERR_ARG,
            "scene %s: effects[%d]: %s needs an embedded geometry with surface rules",
            fcm_scene_name(S->scene), e->index, fcm_effect_type_name(e->type));
  if (!S->loads) FCM_ALLOC(S->ctx, fcm_scene_num_effects(S->scene), S->loads);
  FCM_CHECK(S->num_loads < fcm_scene_num_effects(S->scene), S->ctx, FCM_ERR_INTERNAL,
            "scene %s: effects[%d]: surface load applied twice", fcm_scene_name(S->scene),
            e->index);
  fcm_effect *copy = &S->loads[S->num_loads++];
  *copy = *e; /* its region arrays stay the scene's, read only */
  FCM_TRY(S->ctx, fcm_integrator_add_traction(S->integ, surface_field, copy, window_scale, copy));
cleanup:
  return st;
}

void fcm__effect_configure_damping(const fcm_effect *e, fcm_integrator_options *o)
{
  if (o->kind != FCM_INTEGRATOR_BACKWARD_EULER) return; /* (static scenes reject damping) */
  o->rayleigh_mass += e->damping.mass;
  o->rayleigh_stiffness += e->damping.stiffness;
}

/* Centre of mass of the body at displacement u (NULL: the reference one), as the space
 * integrates it: 1^T M x / 1^T M 1 per component, x = X + u (exact for the mass quadrature,
 * embedded or not). Needs the mass matrix (dynamic scenes). In a distributed run M is this
 * process's partial mass matrix (sim_backend.h): the sums are its parts, summed over the
 * processes (collective; a local failure meets the others in that sum). */
static fcm_status center_of_mass(const fcm_simulation *S, const double *u, double com[3])
{
  fcm_status st = FCM_OK;
  fcm_index n = fcm_integrator_num_dofs(S->integ);
  const fcm_csr *M = fcm_integrator_mass(S->integ);
  const double *X = fcm_mesh_coords(S->mesh);
  double *x = NULL, *Mx = NULL, q[6] = {0, 0, 0, 0, 0, 0}, *num = q, *den = q + 3;
  FCM_CHECK(M, S->ctx, FCM_ERR_ARG,
            "simulation %s: the centre of mass needs the mass matrix (static scenes have none)",
            fcm_scene_name(S->scene));
  x = fcm__calloc(S->ctx, (size_t)n + 1, sizeof *x);
  Mx = fcm__calloc(S->ctx, (size_t)n + 1, sizeof *Mx);
  if (!x || !Mx) { /* fcm__calloc() recorded the message */
    st = FCM_ERR_ALLOC;
    fcm__trace(S->ctx, __FILE__, __LINE__, __func__);
  }
  if (st == FCM_OK) {
    for (fcm_index a = 0; a < S->nn; a++) {
      const fcm_index d0 = fcm_space_node_dof(S->space, a);
      for (fcm_index dof = d0; d0 >= 0 && dof < d0 + 3 * fcm_space_node_copies(S->space, a);
           dof += 3)
        for (int d = 0; d < 3; d++)
          x[dof + d] = X[3 * a + d] + (u ? u[dof + d] : 0.0);
    }
    st = fcm__space_matrix_apply(S->space, M, x, Mx);
  }
  if (st == FCM_OK) {
    for (fcm_index i = 0; i < n; i++)
      num[i % 3] += Mx[i];
    for (fcm_index i = 0; i < n; i++)
      x[i] = 1.0;
    st = fcm__space_matrix_apply(S->space, M, x, Mx);
  }
  if (st == FCM_OK)
    for (fcm_index i = 0; i < n; i++)
      den[i % 3] += Mx[i];
  FCM_TRY(S->ctx, fcm__integrator_reduce_status(S->integ, st, q, 6));
  for (int d = 0; d < 3; d++)
    com[d] = den[d] > 0.0 ? num[d] / den[d] : 0.0;
cleanup:
  fcm__free(S->ctx, x);
  fcm__free(S->ctx, Mx);
  return st;
}

fcm_status fcm_simulation_center_of_mass(const fcm_simulation *S, double com[3])
{
  fcm_status st = FCM_OK;
  FCM_CHECK(S && com, S ? S->ctx : NULL, FCM_ERR_ARG, "simulation: center_of_mass: NULL");
  FCM_TRY(S->ctx, center_of_mass(S, fcm_integrator_displacement(S->integ), com));
cleanup:
  return st;
}

/* Initial velocity: v = v0 + omega x (X - c) on the region's nodes, c the centre of mass of
 * the body in the reference configuration. */
fcm_status fcm__effect_initialize_velocity(fcm_simulation *S, const fcm_effect *e,
                                           fcm__effect_init *init)
{
  const double *X = fcm_mesh_coords(S->mesh);
  const fcm_region *r = &e->initial_velocity.region;
  for (fcm_index a = 0; a < S->nn; a++) {
    fcm_index dof = fcm_space_node_dof(S->space, a);
    if (dof < 0) continue;
    int in = 0;
    if (r->kind == FCM_REGION_NODES) {
      for (fcm_index j = 0; j < r->num_nodes && !in; j++)
        in = r->nodes[j] == a;
    } else {
      in = fcm_region_contains(r, X + 3 * a);
    }
    for (fcm_index k = 0; in && k < fcm_space_node_copies(S->space, a); k++)
      fcm_effect_initial_velocity_eval(&e->initial_velocity, X + 3 * a, init->com,
                                       init->v + dof + 3 * k);
  }
  S->c.initial_velocity++;
  return FCM_OK;
}

/* Run the initialize hooks of the scene's effects into one velocity, set once. */
static fcm_status initialize_effects(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_index n = fcm_integrator_num_dofs(S->integ);
  fcm__effect_init init = {NULL, {0, 0, 0}};
  int any = 0;
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++)
    any |= fcm__scene_effect_type(fcm_scene_get_effect(S->scene, k)->type)->initialize != NULL;
  if (!any) return FCM_OK;
  FCM_ALLOC(S->ctx, n, init.v);
  memcpy(init.v, fcm_integrator_velocity(S->integ), (size_t)n * sizeof *init.v);
  FCM_TRY(S->ctx, center_of_mass(S, NULL, init.com));
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    const fcm__effect_type *t = fcm__scene_effect_type(e->type);
    if (t->initialize) FCM_TRY(S->ctx, t->initialize(S, e, &init));
  }
  FCM_TRY(S->ctx, fcm_integrator_set_state(S->integ, NULL, init.v, fcm_integrator_time(S->integ),
                                           fcm_integrator_step_count(S->integ)));
cleanup:
  fcm__free(S->ctx, init.v);
  return st;
}

/* ---------------------------------------------------------------- building */

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
  FCM_TRY(S->ctx, fcm_voxel_image_create_from_file(S->ctx, g->image, &img));
  FCM_TRY(S->ctx, fcm_geometry_create_from_voxels(S->ctx, img, &vo, raw, &info));
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
  FCM_TRY(S->ctx, fcm_geometry_create_from_level_set(S->ctx, fcm_implicit_eval, &tree, g->min,
                                                     g->max, g->cells, &lo, raw, &info));
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
 * closed), tetrahedralize. */
static fcm_status build_surface_geometry(fcm_simulation *S, const fcm_scene_geometry *g,
                                         fcm_geometry **raw)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_surface *surf = NULL, *filled = NULL;
  FCM_TRY(ctx, fcm_surface_create_from_file(ctx, g->mesh, &surf));
  if (g->fill_holes) {
    fcm_surface_fill_info fi;
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
  }
  /* the checks here, so that a failure names the scene and the file */
  {
    char what[512];
    fcm_surface_report rep;
    fcm_surface_mesh_options mo = g->surface;
    snprintf(what, sizeof what, "scene %s: geometry.surface %s", fcm_scene_name(S->scene), g->mesh);
    FCM_TRY(ctx, fcm_surface_create_oriented(ctx, surf, &filled, NULL));
    fcm_surface_destroy(&surf);
    surf = filled;
    filled = NULL;
    FCM_TRY(ctx, fcm_surface_check(surf, NULL, &rep));
    FCM_TRY(ctx, fcm_surface_report_check(surf, what, &rep));
    mo.check_intersections = 0; /* done above */
    mo.orient = 0;
    FCM_TRY(ctx, fcm_geometry_create_from_surface(ctx, surf, &mo, raw));
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

/* Put the scene section `path` before the recorded error's message, unless the message
 * names it already. */
static void name_section(fcm_ctx *ctx, const char *path)
{
  if (!strstr(fcm_ctx_error_message(ctx), path)) fcm__error_prefix(ctx, path);
}

static fcm_status build_geometry(fcm_simulation *S, const fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_geometry *raw = NULL;
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
  if (g->has_transform) {
    FCM_TRY(ctx, fcm_geometry_create_transformed(ctx, raw, g->transform, g->offset, &S->geom));
  } else {
    S->geom = raw;
    raw = NULL;
  }
cleanup:
  fcm_geometry_destroy(&raw);
  return st;
}

/* Stiffness assemblies per time or load step that FCM_CELL_SIMPLIFY_AUTO assumes: the default
 * scene takes 508 Newton iterations in 210 steps (2.4 per step), each assembling force and
 * tangent, plus line-search and predictor force evaluations. */
#define RUN_ASSEMBLIES_PER_STEP 3.0

static fcm_status build_rules(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  const fcm_scene_quadrature *q = fcm_scene_get_quadrature(S->scene);
  const fcm_scene_solver *sv = fcm_scene_get_solver(S->scene);
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  int nsurf = 0;
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    nsurf += !!(fcm__scene_effect_type(e->type)->needs & FCM__NEEDS_SURFACE_RULES);
    nsurf += (e->type == FCM_EFFECT_FIXED && e->fixed.boundary) ||
             (e->type == FCM_EFFECT_MOTION && e->motion.boundary); /* Nitsche's points */
  }
  /* Only the rules the scene calls for: mass rules serve the mass matrix (inertia, Rayleigh
   * damping) and the momentum, so a static scene builds none (the log's mass then comes from
   * the piece volumes, see log_momentum()). */
  const int dynamic = fcm_scene_get_time(S->scene)->integrator != FCM_INTEGRATOR_STATIC;
  ro.kinds = FCM_RULES_STIFFNESS | (dynamic ? FCM_RULES_MASS : 0u);
  ro.strength[FCM_RULE_STIFFNESS] = q->stiffness_strength;
  ro.strength[FCM_RULE_MASS] = q->mass_strength;
  if (q->surface_strength >= 0)
    ro.surface_strength = q->surface_strength;
  else if (nsurf > 0)
    ro.surface_strength = q->stiffness_strength >= 0
                              ? q->stiffness_strength
                              : fcm_mesh_get_element_info(S->mesh)->stiffness_strength;
  else
    ro.surface_strength = -1;
  ro.min_fraction = q->min_fraction;
  ro.max_rule_memory = q->max_rule_memory_gib * 1024.0 * 1024.0 * 1024.0;
  ro.simplify = q->simplify;
  if (q->simplify == FCM_CELL_SIMPLIFY_AUTO) {
    /* The assemblies the run expects: stiffness-kind rules (force + tangent, body forces) once
     * per Newton iteration, about RUN_ASSEMBLIES_PER_STEP per step and load step; mass rules
     * once (the constant mass matrix of a dynamic run), never in a static one. */
    const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
    ro.expected_assemblies[FCM_RULE_STIFFNESS] =
        RUN_ASSEMBLIES_PER_STEP * (double)tm->num_steps * (dynamic ? 1.0 : (double)tm->load_steps);
    ro.expected_assemblies[FCM_RULE_MASS] = dynamic ? 1.0 : 0.0;
  }
  ro.simplify_options.method = q->simplify_method;
  ro.stabilization = q->stabilization;
  ro.num_threads = sv->threads;
  ro.progress = S->opts.rules_progress;
  ro.progress_user = S->opts.rules_progress_user;
  ro.progress_interval = S->opts.rules_progress_interval;
  const fcm__simulation_config *cfg = S->config;
  const fcm__backend *b = cfg ? cfg->backend : NULL;
  ro.cell_mask = cfg ? cfg->cell_mask : NULL;
  fcm__rules_reduce red = {b ? b->reduce : NULL, b ? b->user : NULL, 0};
  if (cfg && cfg->exchange) /* distributed: each process classifies its share of the cells */
    FCM_TRY(S->ctx, fcm__cell_rules_create_distributed(S->ctx, S->mesh, S->geom, &ro,
                                                       b ? &red : NULL, cfg->exchange, &S->rules));
  else if (b) /* distributed: the auto choice's inputs summed over the processes */
    FCM_TRY(S->ctx, fcm__cell_rules_create_reduced(S->ctx, S->mesh, S->geom, &ro, &red, &S->rules));
  else
    FCM_TRY(S->ctx, fcm_cell_rules_create(S->ctx, S->mesh, S->geom, &ro, &S->rules));
  S->c.cell_rules = 1;
  S->c.surface_rules = ro.surface_strength >= 0;
  S->c.rule_kinds = fcm_cell_rules_get_stats(S->rules)->kinds;
cleanup:
  return st;
}

static fcm_integrator_options integrator_options(fcm_simulation *S)
{
  const fcm_scene_quadrature *q = fcm_scene_get_quadrature(S->scene);
  const fcm_scene_solver *sv = fcm_scene_get_solver(S->scene);
  const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = tm->integrator;
  o.dt = tm->dt;
  o.load_steps = tm->load_steps;
  o.newton_max_iterations = sv->newton_max_iterations;
  o.newton_tolerance = sv->newton_rtol;
  /* AUTO: static scenes have no mass and no inertia; the force-balance (relative) rule needs
   * neither, where the representative force would take a body-force pass of its own. */
  o.tolerance_mode = sv->newton_rule;
  o.rep_acceleration = sv->representative_acceleration;
  o.line_search = sv->line_search;
  o.project_psd = sv->project_psd;
  o.linear_solver = sv->method;
  o.direct_method = sv->direct;
  o.preconditioner = sv->preconditioner;
  o.preconditioner_tangent = sv->preconditioner_tangent;
  o.krylov_rtol = sv->rtol;
  o.krylov_atol = sv->atol;
  o.krylov_max_iterations = sv->max_iterations;
  o.krylov_stagnation_window = sv->stagnation_window;
  o.schwarz_theta = sv->schwarz_threshold;
  o.schwarz = sv->schwarz;
  o.multigrid = sv->multigrid;
  /* Full cells: the scene's strength, except that 0 keeps the element's rule there (as the
   * scene README documents for strength 0: only cut cells get the strength-0 rule). */
  o.assembly.stiffness_strength = q->stiffness_strength > 0 ? q->stiffness_strength : FCM_DEFAULT;
  o.assembly.mass_strength = q->mass_strength > 0 ? q->mass_strength : FCM_DEFAULT;
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    const fcm__effect_type *t = fcm__scene_effect_type(e->type);
    if (t->configure) t->configure(e, &o);
  }
  return o;
}

/* Schwarz blocks the integrator would build: active cut cells below the threshold. */
static fcm_index count_schwarz_blocks(const fcm_simulation *S, double theta)
{
  fcm_index n = 0;
  if (!S->rules) return 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(S->mesh); c++)
    if (fcm_space_cell_active(S->space, c) && fcm_cell_rules_class(S->rules, c) == FCM_CELL_CUT &&
        fcm_cell_rules_volume_fraction(S->rules, c) < theta)
      n++;
  return n;
}

/* The embedded surface written per frame: the boundary triangles' vertices located once
 * (fcm_embedded_surface_create()), the cut faces added after every cut. */
static fcm_status build_surface(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  FCM_TRY(S->ctx, fcm_embedded_surface_create(S->space, S->geom, &S->surf));
  /* the counters name the boundary only (cut faces come and go with the cuts): 3 points per
   * cut-face triangle */
  const fcm_index nb = fcm_geometry_num_boundary_triangles(S->geom);
  S->c.surface_triangles = nb;
  S->c.surface_points = fcm_embedded_surface_num_points(S->surf) -
                        3 * (fcm_embedded_surface_num_triangles(S->surf) - nb);
cleanup:
  return st;
}

/* The surface of cut effect c: the plane is clipped to the body's bounding box enlarged
 * by 10 % of its diagonal (before the transform). *surf NULL: a plane that misses the box. */
static fcm_status cut_surface(fcm_simulation *S, const fcm_effect_cut *c, fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_surface *raw = NULL;
  *surf = NULL;
  switch (c->kind) {
  case FCM_CUT_PLANE: {
    double lo[3], hi[3], diag = 0.0;
    fcm_geometry_bounding_box(S->geom, lo, hi);
    for (int d = 0; d < 3; d++)
      diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    diag = sqrt(diag);
    for (int d = 0; d < 3; d++)
      lo[d] -= 0.1 * diag, hi[d] += 0.1 * diag;
    st = fcm_surface_create_plane(ctx, c->point, c->normal, lo, hi, &raw);
    if (st == FCM_ERR_GEOMETRY) { /* misses the body: a counted no-op */
      fcm_ctx_error_clear(ctx);
      st = FCM_OK;
      goto cleanup;
    }
    FCM_TRY(ctx, st);
  } break;
  case FCM_CUT_RECTANGLE:
    FCM_TRY(ctx, fcm_surface_create_rectangle(ctx, c->point, c->normal, c->axis, c->size, &raw));
    break;
  case FCM_CUT_DISC:
    FCM_TRY(ctx, fcm_surface_create_disc(ctx, c->point, c->normal, c->radius, c->segments, &raw));
    break;
  case FCM_CUT_MESH:
    FCM_TRY(ctx, fcm_surface_create_from_file(ctx, c->mesh, &raw));
    break;
  }
  if (c->has_transform) {
    FCM_TRY(ctx, fcm_surface_create_transformed(ctx, raw, c->transform, c->offset, surf));
  } else {
    *surf = raw;
    raw = NULL;
  }
cleanup:
  fcm_surface_destroy(&raw);
  return st;
}

/* The space of the rules: a full embedded space; in a distributed run (the rules carry this
 * process's cell mask) a local one, the topology of the process's own cells and one layer of
 * ghosts around them (fcm__space_localize(): every copy an own cell uses has its full row, as
 * the backend's matrix preallocation needs), the numbering the full space's bit for bit. */
static fcm_status create_space(fcm_simulation *S, const fcm_cell_rules *rules, int distributed,
                               fcm_space **out)
{
  fcm_status st = FCM_OK;
  const fcm_space_options o = fcm_space_options_default();
  if (!distributed || !rules->own) return fcm_space_create_embedded(S->ctx, S->mesh, rules, out);
  FCM_TRY(S->ctx, fcm__space_create_local(S->ctx, S->mesh, NULL, rules, &o, NULL, out));
  FCM_TRY(S->ctx, fcm__space_localize(*out, rules->own));
cleanup:
  if (st != FCM_OK) fcm_space_destroy(out);
  return st;
}

fcm_status fcm__sim_apply_cut(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_effect *e = S->cuts[S->cuts_applied];
  fcm_surface *surf = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  /* A distributed run (the integrator has a backend, sim_backend.h): the rules keep the
   * process's cell mask, the new integrator gets the backend again (its cut hook, which
   * agrees first), and fcm__integrator_finish() at the end agrees on the outcome, so a
   * process that fails in the local work meets the others wherever they wait. */
  FCM_TRY(ctx, cut_surface(S, &e->cut, &surf));
  S->cuts_applied++;
  S->c.cuts++;
  if (!surf) {
    S->c.cuts_missed++;
    goto cleanup;
  }
  FCM_TRY(ctx, fcm_cell_rules_create_cut(ctx, S->mesh, S->geom, S->rules, surf, &rules));
  S->c.cut_cells += fcm_cell_rules_get_stats(rules)->num_integrated;
  FCM_TRY(ctx, create_space(S, rules, fcm__integrator_distributed(S->integ, NULL), &space));
  /* missed: no cell got a new piece and no node a new copy (a cut along cell faces adds copies
   * without splitting any cell) */
  if (fcm_cell_rules_num_pieces(rules) == fcm_cell_rules_num_pieces(S->rules) &&
      fcm_space_num_dofs(space) == fcm_space_num_dofs(S->space))
    S->c.cuts_missed++;
  FCM_TRY(ctx, fcm_integrator_create_cut(S->integ, space, &integ));
  /* the new integrator counts from zero: keep the totals so far */
  S->base_factorizations = S->c.factorizations;
  S->base_analyses = S->c.analyses;
  S->base_fallbacks = S->c.direct_fallbacks;
  fcm_integrator_destroy(&S->integ);
  fcm_space_destroy(&S->space);
  fcm_cell_rules_destroy(&S->rules);
  S->integ = integ, S->space = space, S->rules = rules;
  integ = NULL, space = NULL, rules = NULL;
  S->c.num_dofs = fcm_space_num_dofs(S->space);
  S->c.constrained_dofs = fcm_integrator_num_constrained(S->integ);
  S->pieces = fcm_space_num_bodies(S->space);
  S->c.pieces = S->pieces;
  if (S->surf) FCM_TRY(ctx, fcm_embedded_surface_set_space(S->surf, S->space));
cleanup:
  st = fcm__integrator_finish(S->integ, st);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_surface_destroy(&surf);
  return st;
}

/* The scene's cut effects in time order (stable); they need an embedded geometry. */
static fcm_status collect_cuts(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const int n = fcm_scene_count_effects(S->scene, FCM_EFFECT_CUT);
  if (n == 0) return FCM_OK;
  FCM_ALLOC(ctx, (size_t)n, S->cuts);
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    if (e->type != FCM_EFFECT_CUT) continue;
    FCM_CHECK(S->rules, ctx, FCM_ERR_ARG,
              "scene %s: effects[%d].cut needs an embedded geometry (\"geometry\"): cuts split "
              "the embedded body",
              fcm_scene_name(S->scene), k);
    if (e->cut.kind == FCM_CUT_MESH) { /* read it now: a bad file fails before the run */
      fcm_surface *probe = NULL;
      st = fcm_surface_create_from_file(ctx, e->cut.mesh, &probe);
      if (st == FCM_OK) st = fcm__embed_cut_check(ctx, probe, e->cut.mesh);
      fcm_surface_destroy(&probe);
      if (st != FCM_OK) {
        char section[64];
        snprintf(section, sizeof section, "effects[%d].cut.surface.mesh", k);
        name_section(ctx, section);
        goto cleanup;
      }
    }
    int i = S->num_cuts++;
    while (i > 0 && S->cuts[i - 1]->cut.time > e->cut.time) {
      S->cuts[i] = S->cuts[i - 1];
      i--;
    }
    S->cuts[i] = e;
  }
cleanup:
  return st;
}

/* The background mesh and the embedded geometry (S->mesh, S->nn, S->geom; no geometry for a
 * scene without one); errors of the inputs name the scene section they come from. */
static fcm_status build_mesh_geometry(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_scene *scene = S->scene;
  const fcm_scene_background *bg = fcm_scene_get_background(scene);
  const fcm_scene_geometry *g = fcm_scene_get_geometry(scene);
  if (bg->kind == FCM_SCENE_BACKGROUND_GRID && bg->fit) {
    double min[3], max[3];
    fcm_index cells[3];
    st = build_geometry(S, g); /* the parser ensured there is one */
    if (st != FCM_OK) name_section(ctx, geometry_path(g->kind));
    FCM_TRY(ctx, st);
    st = fit_background(S, bg, min, max, cells);
    if (st == FCM_OK) st = fcm_mesh_create_box(ctx, bg->element, min, max, cells, &S->mesh);
    if (st != FCM_OK) name_section(ctx, "background.fit_background");
    FCM_TRY(ctx, st);
  } else if (bg->kind == FCM_SCENE_BACKGROUND_GRID)
    st = fcm_mesh_create_box(ctx, bg->element, bg->min, bg->max, bg->cells, &S->mesh);
  else
    st = fcm_mesh_create_from_gmsh(ctx, bg->mesh, &S->mesh);
  if (st != FCM_OK)
    name_section(ctx, bg->kind == FCM_SCENE_BACKGROUND_GRID ? "background" : "background.mesh");
  FCM_TRY(ctx, st);
  S->nn = fcm_mesh_num_nodes(S->mesh);

  if (g->kind != FCM_SCENE_GEOMETRY_NONE && !S->geom) {
    st = build_geometry(S, g);
    if (st != FCM_OK) name_section(ctx, geometry_path(g->kind));
    FCM_TRY(ctx, st);
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
  FCM_TRY(ctx, build_mesh_geometry(S));
  *mesh = S->mesh;
  *geom = S->geom;
  S->mesh = NULL;
  S->geom = NULL;
cleanup:
  fcm_simulation_destroy(&S);
  return st;
}

fcm_status fcm_simulation_create(fcm_ctx *ctx, const fcm_scene *scene,
                                 const fcm_simulation_options *opts, fcm_simulation **out)
{
  fcm__simulation_config cfg;
  memset(&cfg, 0, sizeof cfg);
  cfg.opts = opts ? *opts : fcm_simulation_options_default();
  return fcm__simulation_create(ctx, scene, &cfg, out);
}

fcm_status fcm__simulation_create(fcm_ctx *ctx, const fcm_scene *scene,
                                  const fcm__simulation_config *cfg, fcm_simulation **out)
{
  fcm_status st = FCM_OK;
  fcm_simulation *S = NULL;
  FCM_CHECK(ctx && scene && cfg && out, ctx, FCM_ERR_ARG, "simulation: NULL argument");
  *out = NULL;
  double t0 = fcm_wtime();
  FCM_ALLOC(ctx, 1, S);
  S->ctx = ctx;
  S->config = cfg->backend ? cfg : NULL;
  S->scene = scene;
  S->opts = cfg->opts;
  FCM_CHECK(S->opts.max_steps >= 1 || S->opts.max_steps == FCM_DEFAULT, ctx, FCM_ERR_ARG,
            "simulation: max_steps = %lld must be >= 1, or FCM_DEFAULT (-1: the scene's)",
            (long long)S->opts.max_steps);
  FCM_CHECK(S->opts.checkpoint_interval >= 0 || S->opts.checkpoint_interval == FCM_DEFAULT, ctx,
            FCM_ERR_ARG,
            "simulation: checkpoint_interval = %d must be >= 0, or FCM_DEFAULT (-1: the scene's)",
            S->opts.checkpoint_interval);
  const fcm_scene_time *tm = fcm_scene_get_time(scene);
  S->num_steps = tm->num_steps;
  if (S->opts.max_steps > 0 && S->opts.max_steps < S->num_steps) S->num_steps = S->opts.max_steps;

  FCM_CHECK(S->opts.rules_progress_interval >= 0.0, ctx, FCM_ERR_ARG,
            "simulation: rules_progress_interval = %g must be >= 0 seconds",
            S->opts.rules_progress_interval);

  FCM_TRY(ctx, build_mesh_geometry(S));
  const fcm_scene_geometry *g = fcm_scene_get_geometry(scene);

  /* cell rules only when the scene embeds a geometry */
  if (g->kind != FCM_SCENE_GEOMETRY_NONE) {
    st = build_rules(S);
    if (st != FCM_OK) fcm__error_prefix(ctx, st == FCM_ERR_GEOMETRY ? "geometry" : "quadrature");
    FCM_TRY(ctx, st);
    const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(S->rules);
    FCM_CHECK(rs->num_uncut + rs->num_cut > 0, ctx, FCM_ERR_GEOMETRY,
              "geometry: every one of the %lld background cells holds less than "
              "quadrature.min_fraction = %g of its volume of the body (embedded volume %g of "
              "%g m^3): the body is too small or thin for the grid; refine the background or "
              "lower quadrature.min_fraction",
              (long long)rs->num_cells, fcm_scene_get_quadrature(scene)->min_fraction,
              rs->embedded_volume, rs->geometry_volume);
    st = create_space(S, S->rules, S->config && S->config->cell_mask, &S->space);
    if (st != FCM_OK) fcm__error_prefix(ctx, "geometry");
    FCM_TRY(ctx, st);
  } else {
    FCM_TRY(ctx, fcm_space_create(ctx, S->mesh, NULL, &S->space));
  }
  S->c.num_dofs = fcm_space_num_dofs(S->space);
  S->c.inverted_first_cell = -1;
  S->c.nonfinite_first_step = -1;

  /* integrator with the scene's effects */
  fcm_integrator_options io = integrator_options(S);
  S->c.inertia = io.kind == FCM_INTEGRATOR_BACKWARD_EULER;
  S->c.damping = io.rayleigh_mass > 0.0 || io.rayleigh_stiffness > 0.0;
  S->c.krylov = io.linear_solver == FCM_LINEAR_CG || io.linear_solver == FCM_LINEAR_MINRES;
  S->c.multigrid = io.linear_solver == FCM_LINEAR_MULTIGRID ||
                   (S->c.krylov && io.preconditioner == FCM_PRECOND_MULTIGRID);
  if (S->c.krylov && io.preconditioner == FCM_PRECOND_SCHWARZ) {
    S->c.schwarz_blocks = count_schwarz_blocks(S, io.schwarz_theta);
    if (S->c.schwarz_blocks == 0) io.preconditioner = FCM_PRECOND_JACOBI; /* nothing to block */
  }
  FCM_TRY(ctx, fcm_integrator_create(ctx, S->space, fcm_scene_get_material(scene), &io, &S->integ));
  for (int k = 0; k < fcm_scene_num_effects(scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(scene, k);
    const fcm__effect_type *t = fcm__scene_effect_type(e->type);
    if (t->apply) FCM_TRY(ctx, t->apply(S, e));
  }
  if (S->config) FCM_TRY(ctx, fcm__integrator_attach_backend(S->integ, S->config->backend));
  FCM_TRY(ctx, fcm_integrator_setup(S->integ));
  {
    fcm_integrator_setup_info si;
    fcm_integrator_get_setup_info(S->integ, &si);
    S->c.mass_assemblies = si.mass_assemblies;
    S->c.body_force_assemblies = si.body_force_assemblies;
    S->c.traction_assemblies = si.traction_assemblies;
    S->c.scale_assemblies = si.scale_assemblies;
    S->c.boundary_points = si.boundary_points;
  }
  S->c.constrained_dofs = fcm_integrator_num_constrained(S->integ);
  if (S->c.inertia) FCM_TRY(ctx, initialize_effects(S));
  S->free_body = S->c.inertia && S->c.constraints == 0 && S->c.body_force_assemblies == 0 &&
                 S->c.traction_assemblies == 0;
  if (S->free_body) FCM_TRY(ctx, center_of_mass(S, NULL, S->com0));
  S->base_dofs = S->c.num_dofs;
  S->base_constrained = S->c.constrained_dofs;
  S->pieces = fcm_space_num_bodies(S->space);
  S->c.pieces = S->pieces;
  FCM_TRY(ctx, collect_cuts(S));
  while (S->cuts_applied < S->num_cuts && S->cuts[S->cuts_applied]->cut.time <= 0.0)
    FCM_TRY(ctx, fcm__sim_apply_cut(S));

  if (S->geom && fcm_scene_get_output(scene)->write_surface) FCM_TRY(ctx, build_surface(S));
  S->c.time_setup = fcm_wtime() - t0;
  S->config = NULL; /* borrowed for the create only */
  *out = S;
  S = NULL;
cleanup:
  fcm_simulation_destroy(&S);
  return st;
}

const fcm_cell_rules *fcm_simulation_cell_rules(const fcm_simulation *sim)
{
  return sim ? sim->rules : NULL;
}

void fcm_simulation_destroy(fcm_simulation **sim)
{
  if (!sim || !*sim) return;
  fcm_simulation *S = *sim;
  fcm_ctx *ctx = S->ctx;
  fcm_pvd_destroy(&S->pvd_bg);
  fcm_pvd_destroy(&S->pvd_surf);
  fcm_embedded_surface_destroy(&S->surf);
  fcm_integrator_destroy(&S->integ);
  fcm_space_destroy(&S->space);
  fcm_cell_rules_destroy(&S->rules);
  fcm_geometry_destroy(&S->geom);
  fcm_mesh_destroy(&S->mesh);
  void *arrays[] = {S->log,          S->frame_time, S->loads,    S->cuts,
                    S->react_effect, S->react_id,   S->react_log};
  for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
    fcm__free(ctx, arrays[k]);
  fcm__free(ctx, S);
  *sim = NULL;
}

/* ---------------------------------------------------------------- stepping */

/* The log's mass and momentum: integrated with the mass rules when the scene built them; a
 * static scene built none (build_rules()) and has no velocity: its mass is the density times
 * the volume of the pieces the space keeps, its momentum zero. */
static fcm_status log_momentum(fcm_simulation *S, fcm__log_row *r)
{
  fcm_status st = FCM_OK;
  const double rho = fcm_scene_get_material(S->scene)->density;
  if (S->rules && !fcm_cell_rules_has_kind(S->rules, FCM_RULE_MASS)) {
    double vol = 0.0;
    for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(S->rules); p++)
      vol += fcm_cell_rules_piece_volume(S->rules, p);
    r->mass = rho * vol;
    r->momentum[0] = r->momentum[1] = r->momentum[2] = 0.0;
    return FCM_OK;
  }
  FCM_TRY(S->ctx,
          fcm_space_momentum(S->space, rho, fcm_integrator_displacement(S->integ),
                             fcm_integrator_velocity(S->integ), &r->mass, r->momentum, NULL));
  { /* a distributed run: this process's cells only, summed over the processes */
    double q[4] = {r->mass, r->momentum[0], r->momentum[1], r->momentum[2]};
    FCM_TRY(S->ctx, fcm__integrator_reduce(S->integ, q, 4));
    r->mass = q[0];
    for (int d = 0; d < 3; d++)
      r->momentum[d] = q[1 + d];
  }
cleanup:
  return st;
}

/* The inversion counters after log row `step` (1-based) r. */
static void count_inversion(fcm_simulation_counters *c, long long step, const fcm__log_row *r)
{
  if (r->inverted <= 0) return;
  if (c->inverted_steps++ == 0) {
    c->inverted_first_step = step;
    c->inverted_first_time = r->time;
    c->inverted_first_cell = (fcm_index)r->inverted_cell;
  }
  if (r->inverted > c->inverted_max) {
    c->inverted_max = (fcm_index)r->inverted;
    c->inverted_max_step = step;
  }
}

/* The frame counters after a frame of the state after step `step` with `nonfinite` NaN or
 * infinite von Mises values. */
static void count_frame(fcm_simulation_counters *c, long long step, fcm_index nonfinite)
{
  c->nonfinite_last = nonfinite;
  if (nonfinite <= 0) return;
  if (c->nonfinite_frames++ == 0) c->nonfinite_first_step = step;
  if (nonfinite > c->nonfinite_max) c->nonfinite_max = nonfinite;
}

void fcm__sim_count_log(fcm_simulation *S)
{
  fcm_simulation_counters *c = &S->c;
  c->inverted_steps = c->inverted_first_step = c->inverted_max_step = 0;
  c->inverted_first_time = 0.0;
  c->inverted_first_cell = -1;
  c->inverted_max = 0;
  c->nonfinite_frames = 0;
  c->nonfinite_last = c->nonfinite_max = 0;
  c->nonfinite_first_step = -1;
  for (long long k = 0; k < S->log_n; k++) {
    count_inversion(c, k + 1, &S->log[k]);
    if (S->log[k].nonfinite >= 0) count_frame(c, k + 1, (fcm_index)S->log[k].nonfinite);
  }
}

/* Force (q[0..3)) and moment about the origin (q[3..6)) of the k-th constraint effect of the
 * log after the step just taken: node constraints from the integrator's residual
 * (fcm_integrator_reaction()); a constraint imposed otherwise (weakly, on the embedded
 * boundary) belongs here too, read through its own call. */
static fcm_status constraint_reaction(fcm_simulation *S, int k, double q[6])
{
  const int id = S->react_id[k];
  return id >= 0 ? fcm_integrator_reaction(S->integ, id, q, q + 3)
                 : fcm_integrator_boundary_reaction(S->integ, -1 - id, q, q + 3);
}

fcm_status fcm_simulation_step(fcm_simulation *S, fcm_step_info *info)
{
  fcm_status st = FCM_OK;
  fcm_step_info si;
  memset(&si, 0, sizeof si);
  FCM_CHECK(S, NULL, FCM_ERR_ARG, "simulation: NULL");
  FCM_CHECK(!fcm_simulation_done(S), S->ctx, FCM_ERR_ARG, "simulation %s: all %lld steps are taken",
            fcm_scene_name(S->scene), S->num_steps);
  /* room for the log row first: a step that is taken is also logged */
  FCM_TRY(S->ctx,
          fcm__sim_grow(S->ctx, (void **)&S->log, &S->log_cap, S->log_n + 1, sizeof *S->log));
  if (S->num_react > 0)
    FCM_TRY(S->ctx, fcm__sim_grow(S->ctx, (void **)&S->react_log, &S->react_cap, S->log_n + 1,
                                  6 * (size_t)S->num_react * sizeof *S->react_log));
  {
    const double t = fcm_integrator_time(S->integ), dt = fcm_scene_get_time(S->scene)->dt;
    while (S->cuts_applied < S->num_cuts && S->cuts[S->cuts_applied]->cut.time <= t + 1e-9 * dt) {
      const double tc = fcm_wtime();
      FCM_TRY(S->ctx, fcm__sim_apply_cut(S));
      S->c.time_steps += fcm_wtime() - tc;
    }
  }
  double t0 = fcm_wtime();
  st = fcm_integrator_step(S->integ, &si);
  double wall = fcm_wtime() - t0;
  S->c.time_steps += wall;
  S->c.newton_iterations += si.newton_iterations;
  S->c.linear_iterations += si.linear_iterations;
  S->c.multigrid_cycles += si.multigrid_cycles;
  S->c.tangent_assemblies += si.tangent_assemblies;
  S->c.factorizations = S->base_factorizations + si.total_factorizations;
  S->c.analyses = S->base_analyses + si.total_analyses;
  S->c.direct_fallbacks = S->base_fallbacks + si.total_direct_fallbacks;
  if (info) *info = si;
  if (st != FCM_OK) {
    fcm__trace(S->ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  S->c.steps++;
  for (int k = 0; k < S->num_react; k++)
    FCM_TRY(S->ctx,
            constraint_reaction(
                S, k, S->react_log + 6 * ((size_t)S->log_n * (size_t)S->num_react + (size_t)k)));
  fcm__log_row *r = &S->log[S->log_n++];
  r->time = si.time;
  r->newton = si.newton_iterations;
  r->linear = si.linear_iterations;
  r->residual = si.residual;
  r->energy = si.total_energy;
  r->wall = wall;
  r->pieces = S->pieces;
  r->inverted = si.inverted_points;
  r->inverted_cell = si.inverted_cell;
  r->nonfinite = -1;
  count_inversion(&S->c, S->c.steps, r);
  FCM_TRY(S->ctx, log_momentum(S, r));
  if (si.inverted_points > 0 && fcm_scene_get_solver(S->scene)->stop_on_inversion) {
    char where[256] = "";
    if (si.inverted_cell >= 0)
      snprintf(where, sizeof where,
               ", the first in cell %lld at X = (%.6g, %.6g, %.6g) with J = %.3g",
               (long long)si.inverted_cell, si.inverted_position[0], si.inverted_position[1],
               si.inverted_position[2], si.inverted_det);
    FCM_CHECK(0, S->ctx, FCM_ERR_GEOMETRY,
              "simulation %s: step %lld (t = %.9g s) ended with %lld inverted quadrature "
              "point%s (J = det F <= 0)%s; stopped because solver.on_inversion is \"stop\" "
              "(\"warn\" goes on and counts them)",
              fcm_scene_name(S->scene), S->c.steps, si.time, (long long)si.inverted_points,
              si.inverted_points == 1 ? "" : "s", where);
  }
cleanup:
  /* distributed: a failure on one process only (outside the integrator's reduces) meets the
   * others here or in their next reduce (FCM_OK without a backend) */
  if (S) st = fcm__integrator_finish(S->integ, st);
  return st;
}

int fcm_simulation_done(const fcm_simulation *S)
{
  return !S || S->c.steps >= S->num_steps;
}
long long fcm_simulation_step_count(const fcm_simulation *S)
{
  return S ? S->c.steps : 0;
}
long long fcm_simulation_num_steps(const fcm_simulation *S)
{
  return S ? S->num_steps : 0;
}
fcm_integrator *fcm_simulation_integrator(fcm_simulation *S)
{
  return S ? S->integ : NULL;
}
const fcm_space *fcm_simulation_space(const fcm_simulation *S)
{
  return S ? S->space : NULL;
}

int fcm_simulation_frame_due(const fcm_simulation *S)
{
  if (!S) return 0;
  int every = fcm_scene_get_output(S->scene)->frame_interval;
  return S->c.steps == 0 || S->c.steps >= S->num_steps || (every > 0 && S->c.steps % every == 0);
}

int fcm_simulation_state_finite(const fcm_simulation *S)
{
  fcm_index n = fcm_integrator_num_dofs(S->integ);
  const double *u = fcm_integrator_displacement(S->integ), *v = fcm_integrator_velocity(S->integ);
  for (fcm_index i = 0; i < n; i++)
    if (!isfinite(u[i]) || !isfinite(v[i])) return 0;
  return 1;
}

void fcm_simulation_get_counters(const fcm_simulation *S, fcm_simulation_counters *c)
{
  if (S && c) *c = S->c;
}

/* ---------------------------------------------------------------- output */

/* Create the PVD index <dir>/<name>_<kind>.pvd; after a restored checkpoint it first lists
 * the frames of the earlier run found in `dir` (<name>_<kind>_NNNN.vtu, NNNN = 0, 1, ...; .pvtu
 * for a distributed run's background). */
static fcm_status open_pvd(fcm_simulation *S, const char *dir, const char *kind, fcm_pvd **pvd)
{
  fcm_status st = FCM_OK;
  char path[4096];
  const char *name = fcm_scene_name(S->scene);
  snprintf(path, sizeof path, "%s/%s_%s.pvd", dir, name, kind);
  FCM_TRY(S->ctx, fcm_pvd_create(S->ctx, path, pvd));
  if (S->restored)
    for (long long k = 0; k < S->c.frames; k++) {
      struct stat sb;
      snprintf(path, sizeof path, "%s/%s_%s_%04lld.%s", dir, name, kind, k,
               /* a distributed run's background frames are .pvtu */
               fcm__integrator_distributed(S->integ, NULL) && strcmp(kind, "background") == 0
                   ? "pvtu"
                   : "vtu");
      if (stat(path, &sb) == 0) FCM_TRY(S->ctx, fcm_pvd_add(*pvd, S->frame_time[k], path));
    }
cleanup:
  return st;
}

/* A distributed run: this process's piece <name>_background_NNNN_<rank>.vtu of the background
 * frame (its own cells: the rules' cell mask, all cells on the root without rules; the node
 * fields from the replicated state, the stresses of its own cells computed here, *nonfinite
 * of them NaN or infinite), then the root's <name>_background_NNNN.pvtu naming the pieces
 * (path). Collective. */
static fcm_status write_background_pieces(fcm_simulation *S, const char *dir, int index,
                                          const double *u, const double *v, int root, char *path,
                                          size_t path_size, fcm_index *nonfinite)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_cell_rules *R = fcm_space_cell_rules(S->space);
  const fcm_index nc = fcm_mesh_num_cells(S->mesh);
  const char *name = fcm_scene_name(S->scene);
  char stem[1024];
  int rank = 0, nprocs = 1;
  fcm__integrator_processes(S->integ, &rank, &nprocs);
  const int ns = snprintf(stem, sizeof stem, "%s_background_%04d", name, index);
  FCM_CHECK(ns > 0 && (size_t)ns < sizeof stem && strlen(dir) + (size_t)ns + 32 < path_size, ctx,
            FCM_ERR_ARG,
            "simulation: write_frame: the output directory or scene name is too long "
            "(%zu + %d characters)",
            strlen(dir), ns);
  unsigned char *keep = fcm__calloc(ctx, (size_t)nc + 1, 1);
  st = keep ? FCM_OK
            : fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
                         "simulation: out of memory (cell mask of %lld cells)", (long long)nc);
  for (fcm_index c = 0; keep && c < nc; c++)
    keep[c] = fcm__cell_rules_owns(R, c) && (R || root);
  snprintf(path, path_size, "%s/%.1023s_%d.vtu", dir, stem, rank);
  if (st == FCM_OK)
    st = fcm__space_write_vtu_piece(S->space, fcm_scene_get_material(S->scene), u, v, keep, rank,
                                    path, nonfinite);
  fcm__free(ctx, keep);
  FCM_TRY(ctx, fcm__integrator_reduce_status(S->integ, st, NULL, 0)); /* agree on st */
  snprintf(path, path_size, "%s/%.1023s.pvtu", dir, stem);
  if (root) FCM_TRY(ctx, fcm__write_pvtu(ctx, path, stem, nprocs, 1, 1));
cleanup:
  return st;
}

fcm_status fcm_simulation_write_frame(fcm_simulation *S, const char *dir, int index)
{
  fcm_status st = FCM_OK;
  char path[4096];
  fcm_ctx *ctx = S ? S->ctx : NULL;
  int root = 1, dist = 0;
  double t0 = fcm_wtime(), time = 0.0;
  fcm_index bad_cells = 0, bad_points = 0; /* NaN or infinite von Mises values written */
  FCM_CHECK(S && dir && index >= 0, ctx, FCM_ERR_ARG,
            "simulation: write_frame needs a directory and index >= 0 (got %d)", index);
  const char *name = fcm_scene_name(S->scene);
  const fcm_scene_output *out = fcm_scene_get_output(S->scene);
  const fcm_material *mat = fcm_scene_get_material(S->scene);
  time = fcm_integrator_time(S->integ);
  const double *u = fcm_integrator_displacement(S->integ), *v = fcm_integrator_velocity(S->integ);
  dist = fcm__integrator_distributed(S->integ, &root);
  /* room for the frame time first: a frame that is written is also counted */
  FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&S->frame_time, &S->frame_cap, S->c.frames + 1,
                             sizeof *S->frame_time));
  /* distributed: every process writes its piece, the root the .pvtu and the PVD */
  if (dist && out->write_background)
    FCM_TRY(ctx, write_background_pieces(S, dir, index, u, v, root, path, sizeof path, &bad_cells));
  else if (out->write_background) {
    snprintf(path, sizeof path, "%s/%s_background_%04d.vtu", dir, name, index);
    FCM_TRY(ctx, fcm__space_write_vtu_counted(S->space, mat, u, v, path, &bad_cells));
  }
  if (out->write_background && root) {
    if (!S->pvd_bg) FCM_TRY(ctx, open_pvd(S, dir, "background", &S->pvd_bg));
    FCM_TRY(ctx, fcm_pvd_add(S->pvd_bg, time, path));
  }
  if (S->surf && root) { /* the surface's fields come from u alone: whole on every process */
    snprintf(path, sizeof path, "%s/%s_surface_%04d.vtu", dir, name, index);
    FCM_TRY(ctx, fcm__embedded_surface_write_vtu_counted(S->surf, mat, u, path, &bad_points));
    if (!S->pvd_surf) FCM_TRY(ctx, open_pvd(S, dir, "surface", &S->pvd_surf));
    FCM_TRY(ctx, fcm_pvd_add(S->pvd_surf, time, path));
  }
cleanup:
  /* distributed: a failure on any process (the root's files included) is returned on every
   * process, and no process counts the frame then */
  if (dist) st = fcm__integrator_finish(S->integ, st);
  if (dist && st == FCM_OK) { /* every process: the pieces' cells and the root's points */
    double q[2] = {(double)bad_cells, (double)bad_points};
    st = fcm__integrator_reduce(S->integ, q, 2);
    bad_cells = (fcm_index)q[0], bad_points = (fcm_index)q[1];
  }
  if (st == FCM_OK) {
    S->frame_time[S->c.frames++] = time;
    S->c.time_output += fcm_wtime() - t0;
    count_frame(&S->c, S->c.steps, bad_cells + bad_points);
    /* the log row of the step this frame shows (none for the initial state) */
    if (S->c.steps > 0 && S->log_n == S->c.steps)
      S->log[S->log_n - 1].nonfinite = bad_cells + bad_points;
  }
  return st;
}

fcm_status fcm_simulation_write_log(fcm_simulation *S, const char *path)
{
  fcm_status st = FCM_OK;
  fcm__atomic_file af;
  memset(&af, 0, sizeof af);
  FCM_CHECK(S && path, S ? S->ctx : NULL, FCM_ERR_ARG, "simulation: write_log needs a path");
  FCM_TRY(S->ctx, fcm__io_atomic_open(S->ctx, path, 0, NULL, &af));
  FCM_TRY(S->ctx, fcm__io_atomic_printf(
                      S->ctx, &af,
                      "step,time,newton_iterations,linear_iterations,residual,energy,pieces,mass,"
                      "momentum_x,momentum_y,momentum_z"));
  for (int k = 0; k < S->num_react; k++) {
    const int i = S->react_effect[k];
    FCM_TRY(S->ctx, fcm__io_atomic_printf(S->ctx, &af,
                                          ",reaction_%d_x,reaction_%d_y,reaction_%d_z,moment_%d_x,"
                                          "moment_%d_y,moment_%d_z",
                                          i, i, i, i, i, i));
  }
  FCM_TRY(S->ctx,
          fcm__io_atomic_printf(S->ctx, &af, ",inverted_points,nonfinite_stresses,wall_time\n"));
  for (long long k = 0; k < S->log_n; k++) {
    const fcm__log_row *r = &S->log[k];
    FCM_TRY(S->ctx,
            fcm__io_atomic_printf(
                S->ctx, &af, "%lld,%.17g,%lld,%lld,%.17g,%.17g,%lld,%.17g,%.17g,%.17g,%.17g", k + 1,
                r->time, r->newton, r->linear, r->residual, r->energy, r->pieces, r->mass,
                r->momentum[0], r->momentum[1], r->momentum[2]));
    for (int j = 0; j < 6 * S->num_react; j++)
      FCM_TRY(S->ctx, fcm__io_atomic_printf(S->ctx, &af, ",%.17g",
                                            S->react_log[(size_t)k * 6 * S->num_react + j]));
    /* counts: nan where not known (no frame after the step; a row of an older checkpoint),
     * as the reactions such a row lacks */
    const long long counts[2] = {r->inverted, r->nonfinite};
    for (int j = 0; j < 2; j++)
      FCM_TRY(S->ctx, counts[j] >= 0 ? fcm__io_atomic_printf(S->ctx, &af, ",%lld", counts[j])
                                     : fcm__io_atomic_printf(S->ctx, &af, ",nan"));
    FCM_TRY(S->ctx, fcm__io_atomic_printf(S->ctx, &af, ",%.6g\n", r->wall));
  }
  FCM_TRY(S->ctx, fcm__io_atomic_commit(S->ctx, &af));
cleanup:
  if (st != FCM_OK && S) fcm__io_atomic_abort(S->ctx, &af);
  return st;
}

/* ---------------------------------------------------------------- summary */

static void line(FILE *f, int on, const char *what, const char *detail)
{
  fprintf(f, "  %-9s %-28s %s\n", on ? "computed" : "skipped", what, detail);
}

/* The multigrid hierarchy of the current integrator: DOFs per level, finest first (the
 * coarsest is solved by CHOLMOD), and the cycle. Nothing before the first solve. */
static void multigrid_line(const fcm_simulation *S, FILE *f)
{
  const fcm_mg *mg = fcm_integrator_multigrid(S->integ);
  const fcm_mg_options *o = &fcm_scene_get_solver(S->scene)->multigrid;
  char b[512];
  int len = 0;
  if (!mg) {
    line(f, 0, "multigrid levels", "(no solve yet)");
    return;
  }
  const int nl = fcm_mg_num_levels(mg);
  len = snprintf(b, sizeof b, "%d, DOFs", nl);
  for (int l = 0; l < nl && len > 0 && (size_t)len < sizeof b; l++) {
    fcm_mg_level_info li;
    if (fcm_mg_get_level_info(mg, l, &li) != FCM_OK) {
      fcm_ctx_error_clear(S->ctx);
      return;
    }
    len += snprintf(b + len, sizeof b - (size_t)len, "%s%lld", l ? " > " : " ", (long long)li.dofs);
  }
  if (len > 0 && (size_t)len < sizeof b)
    snprintf(b + len, sizeof b - (size_t)len, "; %s-cycle, %d+%d smoothing steps%s",
             o->cycle_index == 2 ? "W" : "V", o->pre_smooth, o->post_smooth,
             o->block_smoothing ? " with vertex blocks" : "");
  line(f, 1, "multigrid levels", b);
}

/* The largest displacement of the body: over its quadrature points (authentic points of the
 * stiffness rules) and the embedded-surface points the frames write; beside it, the largest
 * over the DOF vector, which includes the fictitious nodes outside the body. Without an
 * embedded geometry the mesh is the body: its nodes count too. */
static void body_displacement_line(const fcm_simulation *S, FILE *f, double body_points)
{
  const double *u = fcm_integrator_displacement(S->integ);
  const fcm_index n = fcm_integrator_num_dofs(S->integ);
  double body = body_points, dofs = 0.0, *d = NULL;
  if (body_points < 0.0 && fcm_space_max_displacement(S->space, u, &body) != FCM_OK) {
    fcm_ctx_error_clear(S->ctx);
    return;
  }
  fcm_index np = S->surf ? fcm_embedded_surface_num_points(S->surf) : 0;
  if (np > 0 && (d = fcm__malloc(S->ctx, 3 * (size_t)np, sizeof *d)) != NULL &&
      fcm_embedded_surface_eval(S->surf, u, d, NULL) == FCM_OK) {
    for (fcm_index i = 0; i < np; i++)
      body = FCM_MAX(body, sqrt(d[3 * i] * d[3 * i] + d[3 * i + 1] * d[3 * i + 1] +
                                d[3 * i + 2] * d[3 * i + 2]));
  } else {
    np = 0;
    fcm_ctx_error_clear(S->ctx);
  }
  fcm__free(S->ctx, d);
  for (fcm_index i = 0; i + 2 < n; i += 3)
    dofs = FCM_MAX(dofs, sqrt(u[i] * u[i] + u[i + 1] * u[i + 1] + u[i + 2] * u[i + 2]));
  if (!S->rules) { /* no embedding: every node is the body's */
    fprintf(f, "  body      max |u| %.6g m over the body (its nodes and quadrature points)\n",
            FCM_MAX(body, dofs));
    return;
  }
  if (np > 0)
    fprintf(f,
            "  body      max |u| %.6g m over the body (its quadrature points and %lld surface "
            "points); DOF vector, fictitious nodes included: %.6g m\n",
            body, (long long)np, dofs);
  else
    fprintf(f, "  body      max |u| %.6g m over the body's quadrature points; DOF vector: %.6g m\n",
            body, dofs);
}

/* Inverted quadrature points after the steps and NaN or infinite stresses in the frames: the
 * count, the first and the worst (zeros when the body never inverted). */
static void inversion_lines(FILE *f, const fcm_simulation_counters *c)
{
  if (c->inverted_steps == 0 && c->steps == 1) {
    fprintf(f, "  inversion none: no quadrature point with J = det F <= 0 after the step\n");
  } else if (c->inverted_steps == 0) {
    fprintf(f,
            "  inversion none: no quadrature point with J = det F <= 0 after any of the %lld "
            "steps\n",
            c->steps);
  } else {
    char cell[64] = "";
    if (c->inverted_first_cell >= 0)
      snprintf(cell, sizeof cell, ", cell %lld", (long long)c->inverted_first_cell);
    fprintf(f,
            "  inversion WARNING: %lld of %lld steps ended with inverted quadrature points (J = "
            "det F <= 0): first step %lld (t = %.6g s%s), most %lld points (step %lld)\n",
            c->inverted_steps, c->steps, c->inverted_first_step, c->inverted_first_time, cell,
            (long long)c->inverted_max, c->inverted_max_step);
  }
  if (c->frames == 0) return;
  if (c->nonfinite_frames == 0)
    fprintf(f, "  stresses  finite in every frame written (%lld)\n", c->frames);
  else
    fprintf(f,
            "  stresses  WARNING: %lld of %lld frames hold NaN or infinite von Mises values "
            "(points with J <= 0): first the frame after step %lld, most %lld values in one "
            "frame\n",
            c->nonfinite_frames, c->frames, c->nonfinite_first_step, (long long)c->nonfinite_max);
}

/* The summary with the rules' statistics `gs`, the counters `gc`, the body's largest |u| over
 * its quadrature points `body` and the free body's centre of mass `com_now` (NULL: not
 * available) given (a distributed run, gc not NULL: summed over the processes), or taken from
 * this process (gs and gc NULL, body < 0). */
static void summary_view(const fcm_simulation *S, FILE *f, const fcm_cell_rules_stats *gs,
                         const fcm_simulation_counters *gc, double body, const double *com_now)
{
  const fcm_simulation_counters *c = gc ? gc : &S->c;
  char b[512];
  fprintf(f, "simulation %s: %lld of %lld steps, %lld DOFs\n", fcm_scene_name(S->scene), c->steps,
          S->num_steps, (long long)c->num_dofs);
  line(f, c->cell_rules, "embedded cell rules", c->cell_rules ? "" : "(no geometry)");
  if (S->geometry_note[0]) fprintf(f, "  geometry  %s\n", S->geometry_note);
  if (S->rules) {
    const fcm_cell_rules_stats *rs = gs ? gs : fcm_cell_rules_get_stats(S->rules);
    fprintf(f,
            "  cells     %lld: %lld uncut, %lld cut, %lld dropped; cut-cell points stiffness "
            "%lld -> %lld, mass %lld -> %lld (before -> after simplification)\n",
            (long long)rs->num_cells, (long long)rs->num_uncut, (long long)rs->num_cut,
            (long long)rs->num_dropped, (long long)rs->points_initial[FCM_RULE_STIFFNESS],
            (long long)rs->points_simplified[FCM_RULE_STIFFNESS],
            (long long)rs->points_initial[FCM_RULE_MASS],
            (long long)rs->points_simplified[FCM_RULE_MASS]);
    fprintf(f,
            "  volume    embedded %.6g of %.6g m^3 (ratio %.6f), outside the background %.3g, in "
            "dropped cells %.3g\n",
            rs->embedded_volume, rs->geometry_volume, rs->volume_ratio, rs->outside_volume,
            rs->dropped_volume);
    if (rs->outside_volume > 0.0) {
      static const char *const sides[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
      fprintf(f,
              "  outside   body [%g, %g] x [%g, %g] x [%g, %g], background [%g, %g] x [%g, %g] "
              "x [%g, %g]; beyond",
              rs->geometry_lo[0], rs->geometry_hi[0], rs->geometry_lo[1], rs->geometry_hi[1],
              rs->geometry_lo[2], rs->geometry_hi[2], rs->mesh_lo[0], rs->mesh_hi[0],
              rs->mesh_lo[1], rs->mesh_hi[1], rs->mesh_lo[2], rs->mesh_hi[2]);
      for (int k = 0; k < 6; k++)
        if (rs->outside_side_volume[k] > 0.0)
          fprintf(f, " %s %.3g", sides[k], rs->outside_side_volume[k]);
      fputc('\n', f);
    }
    const fcm_scene_quadrature *q = fcm_scene_get_quadrature(S->scene);
    static const char *const kinds[FCM_RULE_KIND_COUNT] = {"stiffness", "mass"};
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const fcm_simplify_decision *d = &rs->decision[k];
      char what[64];
      snprintf(what, sizeof what, "%s simplification", kinds[k]);
      if (!fcm_cell_rules_has_kind(S->rules, (fcm_rule_kind)k))
        snprintf(b, sizeof b, "(no %s rules built)", kinds[k]);
      else if (q->simplify == FCM_CELL_SIMPLIFY_AUTO)
        snprintf(b, sizeof b,
                 "auto: %s for %g expected assemblies; cost model %.3g core-s per point per "
                 "assembly, %.3g core-s simplifying to %.0f points; estimated %.3g core-s "
                 "assembling plain vs %.3g simplifying + assembling",
                 d->simplified ? "on" : "off", d->expected_assemblies, d->point_cost,
                 d->estimated_time, d->estimated_kept, d->cost_plain, d->cost_simplified);
      else
        snprintf(b, sizeof b, "%s (scene), %.3g core-s", fcm_cell_simplify_name(q->simplify),
                 d->time_simplify);
      line(f, d->simplified, what, b);
    }
  }
  if (S->rules) { /* which rule kinds the scene called for, with their stored points */
    const fcm_cell_rules_stats *rs = gs ? gs : fcm_cell_rules_get_stats(S->rules);
    const int mass = (c->rule_kinds & FCM_RULES_MASS) != 0;
    snprintf(b, sizeof b, "stiffness (%lld points)%s",
             (long long)rs->points_total[FCM_RULE_STIFFNESS], mass ? ", mass" : "");
    if (mass)
      snprintf(b + strlen(b), sizeof b - strlen(b), " (%lld points)",
               (long long)rs->points_total[FCM_RULE_MASS]);
    if (c->surface_rules)
      snprintf(b + strlen(b), sizeof b - strlen(b), ", surface (%lld points)",
               (long long)rs->surface_points);
    if (!mass) snprintf(b + strlen(b), sizeof b - strlen(b), "; mass: not needed (static scene)");
    line(f, 1, "rules built", b);
  }
  line(f, c->surface_rules, "surface rules", c->surface_rules ? "" : "(no traction or pressure)");
  line(f, c->inertia, "inertia (backward Euler)", c->inertia ? "" : "(static scene)");
  snprintf(b, sizeof b, "%d", c->mass_assemblies);
  line(f, c->mass_assemblies > 0, "mass assemblies", c->mass_assemblies ? b : "(static scene)");
  snprintf(b, sizeof b, "%d", c->body_force_assemblies);
  line(f, c->body_force_assemblies > 0, "body-force assemblies",
       c->body_force_assemblies ? b : "(no gravity)");
  if (c->scale_assemblies)
    line(f, 1, "force-scale assembly",
         "1 (static, no gravity: body force of rho a_rep for the stopping rule)");
  snprintf(b, sizeof b, "%d", c->traction_assemblies);
  line(f, c->traction_assemblies > 0, "surface-load assemblies",
       c->traction_assemblies ? b : "(no traction or pressure)");
  line(f, c->damping, "Rayleigh damping matrix", c->damping ? "" : "(no damping)");
  snprintf(b, sizeof b, "%d", c->initial_velocity);
  line(f, c->initial_velocity > 0, "initial velocities", c->initial_velocity ? b : "(none)");
  snprintf(b, sizeof b, "%d sets, %lld nodes, %lld DOFs, %lld embedded-boundary points",
           c->constraints, (long long)c->constrained_nodes, (long long)c->constrained_dofs,
           (long long)c->boundary_points);
  line(f, c->constraints > 0, "constraints", c->constraints ? b : "(none)");
  snprintf(b, sizeof b, "%lld blocks", (long long)c->schwarz_blocks);
  line(f, c->schwarz_blocks > 0, "Schwarz blocks",
       c->schwarz_blocks
           ? b
           : (c->krylov ? "(no cell below the threshold, or not asked)" : "(direct solver)"));
  snprintf(b, sizeof b, "%d applied (%d missed the body), %lld cells integrated again, %lld bodies",
           c->cuts, c->cuts_missed, (long long)c->cut_cells, (long long)c->pieces);
  line(f, c->cuts > 0, "cuts", c->cuts ? b : (S->num_cuts ? "(none due yet)" : "(no cut effect)"));
  snprintf(b, sizeof b, "%lld factorizations, %lld analyses, %lld fallbacks", c->factorizations,
           c->analyses, c->direct_fallbacks);
  line(f, 1,
       c->krylov ? "preconditioner setups"
                 : (c->multigrid ? "multigrid setups" : "direct factorizations"),
       b);
  if (c->multigrid) multigrid_line(S, f);
  snprintf(b, sizeof b, "%lld Newton, %lld linear iterations, %lld multigrid cycles, %lld tangents",
           c->newton_iterations, c->linear_iterations, c->multigrid_cycles, c->tangent_assemblies);
  line(f, 1, "iterations", b);
  snprintf(b, sizeof b, "%lld frames, surface %lld points %lld triangles", c->frames,
           (long long)c->surface_points, (long long)c->surface_triangles);
  line(f, c->frames > 0, "output", b);
  inversion_lines(f, c);
  body_displacement_line(S, f, body);
  if (S->free_body) {
    /* com_now: the centre of mass computed by every process (a distributed run: collective,
     * NULL when it failed); else computed here */
    double com[3];
    const int have = gc ? com_now != NULL : fcm_simulation_center_of_mass(S, com) == FCM_OK;
    if (have && gc) memcpy(com, com_now, sizeof com);
    if (have) {
      double d[3] = {com[0] - S->com0[0], com[1] - S->com0[1], com[2] - S->com0[2]};
      fprintf(f, "  centre of mass (free body) at t = 0: (%.9g, %.9g, %.9g) m; drift now %.3e m\n",
              S->com0[0], S->com0[1], S->com0[2], sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
  }
  fprintf(f, "  time [s]  setup %.3f  steps %.3f  output %.3f\n", c->time_setup, c->time_steps,
          c->time_output);
}

void fcm_simulation_summary_view(const fcm_simulation *S, FILE *f)
{
  if (!S || !f) return;
  summary_view(S, f, NULL, NULL, -1.0, NULL);
}

fcm_status fcm__simulation_summary_view_distributed(fcm_simulation *S, FILE *f)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_index nc = fcm_mesh_num_cells(S->mesh);
  const int K = FCM_RULE_KIND_COUNT, nv = 6 * FCM_RULE_KIND_COUNT + 5;
  fcm_cell_rules_stats gs;
  fcm_simulation_counters gc = S->c;
  double *q = NULL, body = 0.0, com[3] = {0, 0, 0};
  int root = 1, com_ok = 0;
  fcm__integrator_distributed(S->integ, &root);
  memset(&gs, 0, sizeof gs);
  /* per kind: points before / after simplification, stabilization, stored, skipped, kept
   * unsimplified; then surface triangles and points, tets, slivers; then each own cell's
   * largest |u| (every process's cells: the point counts are its own cells' only) */
  q = fcm__calloc(ctx, (size_t)nv + (size_t)nc + 1, sizeof *q);
  st = q ? FCM_OK
         : fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
                      "simulation: out of memory (summary of %lld cells)", (long long)nc);
  if (st == FCM_OK && S->rules) {
    gs = *fcm_cell_rules_get_stats(S->rules);
    for (int k = 0; k < K; k++) {
      q[6 * k + 0] = (double)gs.points_initial[k];
      q[6 * k + 1] = (double)gs.points_simplified[k];
      q[6 * k + 2] = (double)gs.points_stabilization[k];
      /* stored points: the cut cells' own ones, plus the uncut cells' (every process counts
       * all of those: the classification is replicated) on the root only */
      q[6 * k + 3] = (double)(root ? gs.points_total[k]
                                   : gs.points_simplified[k] + gs.points_stabilization[k]);
      q[6 * k + 4] = (double)gs.simplify_skipped[k];
      q[6 * k + 5] = (double)gs.simplify_fallbacks[k];
    }
    q[6 * K + 0] = (double)gs.surface_triangles;
    q[6 * K + 1] = (double)gs.surface_points;
    q[6 * K + 2] = (double)gs.num_tets;
    q[6 * K + 3] = (double)gs.num_slivers;
  }
  if (q) q[6 * K + 4] = (double)S->c.boundary_points; /* Nitsche's: own cells' */
  if (st == FCM_OK)
    st = fcm__space_cell_max_displacement(S->space, fcm_integrator_displacement(S->integ), q + nv);
  if (st == FCM_OK) {
    const fcm_cell_rules *R = fcm_space_cell_rules(S->space);
    for (fcm_index c = 0; c < nc; c++) /* another process's cell: its value (no rules: root's) */
      if (!fcm__cell_rules_owns(R, c) || (!R && !root)) q[nv + c] = 0.0;
  }
  FCM_TRY(ctx, fcm__integrator_reduce_status(S->integ, st, q, (fcm_index)nv + nc));
  /* the free body's centre of mass: collective (the partial mass matrix), on every process */
  if (S->free_body) {
    com_ok = center_of_mass(S, fcm_integrator_displacement(S->integ), com) == FCM_OK;
    if (!com_ok) fcm_ctx_error_clear(ctx);
  }
  for (int k = 0; k < K; k++) {
    gs.points_initial[k] = (fcm_index)q[6 * k + 0];
    gs.points_simplified[k] = (fcm_index)q[6 * k + 1];
    gs.points_stabilization[k] = (fcm_index)q[6 * k + 2];
    gs.points_total[k] = (fcm_index)q[6 * k + 3];
    gs.simplify_skipped[k] = (fcm_index)q[6 * k + 4];
    gs.simplify_fallbacks[k] = (fcm_index)q[6 * k + 5];
  }
  /* surface_triangles, num_tets and num_slivers: the classification exchange summed them
   * already (every process's stats hold the totals) */
  gs.surface_points = (fcm_index)q[6 * K + 1];
  gc.boundary_points = (fcm_index)q[6 * K + 4];
  for (fcm_index c = 0; c < nc; c++)
    if (!(q[nv + c] <= body) && body == body) body = q[nv + c]; /* a NaN stays */
  if (f) summary_view(S, f, S->rules ? &gs : NULL, &gc, body, com_ok ? com : NULL);
cleanup:
  fcm__free(ctx, q);
  return st;
}
