/* The scene runner: the run-time hooks of the effect modules (constraints, gravity, surface
 * loads, damping, initial velocities; the table that names them per effect type is in
 * effects.c, fcm__effect_type) and the body's centre of mass. */
#include "scene/run_impl.h"
#include "scene/scene_impl.h"

#include "core/core_impl.h"
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"
#include "sim/sim_backend.h"
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/geom.h"
#include "fcm/surface.h"
#include "fcm/io.h"
#include "fcm/levelset.h"
#include "fcm/voxels.h"
#include "fcm/mesh.h"
#include "io/io_impl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

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

/* A surface load's region as a selection of boundary points (fcm__embed_select_fn). */
static int load_select(void *user, const double x[3], const double n[3])
{
  const fcm_effect *e = user;
  (void)n;
  return fcm_region_contains(
      e->type == FCM_EFFECT_TRACTION ? &e->traction.region : &e->pressure.region, x);
}

/* The share of the boundary that effect e selects (select, user) in cells the rules dropped,
 * where its load or constraint terms are lost: the largest share over the effects into the
 * counters. Clips only the dropped cells, and only when the rules dropped any boundary. */
static fcm_status dropped_share(fcm_simulation *S, const fcm_effect *e, fcm__embed_select_fn select,
                                void *user)
{
  fcm_status st = FCM_OK;
  double kept, dropped;
  if (!S->rules || !(fcm_cell_rules_get_stats(S->rules)->dropped_area > 0.0)) return FCM_OK;
  FCM_TRY(S->ctx, fcm__embed_selected_area(S->ctx, S->mesh, S->geom, S->rules, select, user, &kept,
                                           &dropped));
  const double share = dropped > 0.0 ? dropped / (kept + dropped) : 0.0;
  if (share > S->c.effect_dropped_fraction) {
    S->c.effect_dropped_fraction = share;
    S->c.effect_dropped_index = e->index;
  }
cleanup:
  return st;
}

/* Background nodes of a region: count only (nodes NULL) or fill. A region naming a node out of
 * range or without a node, or whose nodes are all inactive (no active cell uses them: they would
 * hold nothing), is an error; fcm__sim_check_regions() refused those before the set-up already,
 * by the coarse classification of the cells, and this is the exact check. */
static fcm_status region_nodes(fcm_simulation *S, const fcm_region *r, int effect_index,
                               fcm_index *nodes, fcm_index *count)
{
  fcm_status st = FCM_OK;
  fcm_index active = 0, bad = -1;
  const fcm_index n = fcm__sim_select_nodes(S->mesh, r, nodes, &bad);
  FCM_CHECK(bad < 0, S->ctx, FCM_ERR_ARG, "scene %s: effects[%d]: node %lld out of range [0, %lld)",
            fcm_scene_name(S->scene), effect_index, (long long)bad, (long long)S->nn);
  FCM_CHECK(n > 0, S->ctx, FCM_ERR_ARG,
            "scene %s: effects[%d]: the region contains no background-mesh node",
            fcm_scene_name(S->scene), effect_index);
  if (nodes)
    for (fcm_index k = 0; k < n; k++)
      active += fcm_space_node_copies(S->space, nodes[k]) > 0;
  FCM_CHECK(!nodes || active > 0, S->ctx, FCM_ERR_ARG,
            "scene %s: effects[%d]: the region's %lld background-mesh nodes are all inactive (no "
            "cell with material uses them), so it would hold nothing: move it onto the body",
            fcm_scene_name(S->scene), effect_index, (long long)n);
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
    FCM_TRY(S->ctx, dropped_share(S, e, fcm_region_select, (void *)r));
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
  FCM_TRY(S->ctx, dropped_share(S, e, load_select, copy));
cleanup:
  return st;
}

fcm_status fcm__effect_apply_contact(fcm_simulation *S, const fcm_effect *e)
{
  fcm_status st = FCM_OK;
  const fcm_effect_contact *c = &e->contact;
  fcm_surface *surf = NULL;
  FCM_CHECK(S->c.surface_rules, S->ctx, FCM_ERR_ARG,
            "scene %s: effects[%d]: contact needs an embedded geometry with surface rules",
            fcm_scene_name(S->scene), e->index);
  switch (c->obstacle) {
  case FCM_CONTACT_PLANE:
    FCM_TRY(S->ctx, fcm_integrator_add_contact_plane(S->integ, c->point, c->normal, c->velocity,
                                                     &c->options, NULL));
    break;
  case FCM_CONTACT_SPHERE:
    FCM_TRY(S->ctx, fcm_integrator_add_contact_sphere(S->integ, c->center, c->radius, &c->motion,
                                                      &c->options, NULL));
    break;
  case FCM_CONTACT_BOX:
    FCM_TRY(S->ctx, fcm_integrator_add_contact_box(S->integ, c->min, c->max, &c->motion,
                                                   &c->options, NULL));
    break;
  case FCM_CONTACT_BODIES:
    FCM_TRY(S->ctx, fcm_integrator_add_contact_bodies(S->integ, S->geom, &c->options, NULL));
    break;
  default:
    FCM_TRY(S->ctx, fcm_surface_create_from_file(S->ctx, c->mesh, &surf));
    st = fcm_integrator_add_contact_surface(
        S->integ, fcm_surface_num_vertices(surf), fcm_surface_coords(surf),
        fcm_surface_num_triangles(surf), fcm_surface_triangles(surf), &c->motion, &c->options,
        NULL);
    if (st != FCM_OK) {
      char prefix[1200];
      snprintf(prefix, sizeof prefix, "scene %s: effects[%d]: %s", fcm_scene_name(S->scene),
               e->index, c->mesh);
      fcm__error_prefix(S->ctx, prefix);
      goto cleanup;
    }
    break;
  }
  S->c.contacts++;
cleanup:
  fcm_surface_destroy(&surf);
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
 * process's partial mass matrix (fem/fem_backend.h): the sums are its parts, summed over the
 * processes (collective; a local failure meets the others in that sum). */
fcm_status fcm__sim_center_of_mass(const fcm_simulation *S, const double *u, double com[3])
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
  FCM_TRY(S->ctx, fcm__sim_center_of_mass(S, fcm_integrator_displacement(S->integ), com));
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
fcm_status fcm__sim_initialize_effects(fcm_simulation *S)
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
  FCM_TRY(S->ctx, fcm__sim_center_of_mass(S, NULL, init.com));
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
