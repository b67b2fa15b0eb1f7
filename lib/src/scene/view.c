/* The normalized summary of a scene printed by fcm_scene_view(): every section with its
 * defaults filled in and units, then the effects. */
#include "scene/scene_impl.h"

/* ---------------------------------------------------------------- view */

/* " (sgs omega auto (1), 1+1 steps, V-cycle, coarse 2000 DOFs)": omega 0 is the smoother's
 * own (fcm_mg_smoother_omega()), shown with its value; a given omega as it is; then the block
 * and sweep options where they differ from the defaults (so that a checkpoint's fingerprint,
 * which hashes this view, tells runs of different cycles apart, and a scene without them keeps
 * its view) */
static void view_multigrid(FILE *f, const fcm_mg_options *m)
{
  static const char *const blocks[FCM_MG_BLOCKS_COUNT] = {"all", "vertex", "element"};
  fprintf(f, " (%s omega ",
          SCENE_CHOICE_NAME(fcm__scene_smoother_names, fcm__scene_smoother_values, m->smoother));
  if (m->omega == 0.0)
    fprintf(f, "auto (%g)", fcm_mg_smoother_omega(m->smoother));
  else
    fprintf(f, "%g", m->omega);
  fprintf(f, ", %d+%d steps%s, %s-cycle, coarse %lld DOFs", m->pre_smooth, m->post_smooth,
          m->block_smoothing ? " with vertex blocks" : "", m->cycle_index == 2 ? "W" : "V",
          (long long)m->coarse_dofs);
  if (m->block_smoothing && m->blocks != FCM_MG_BLOCKS_ALL && m->blocks >= 0 &&
      m->blocks < FCM_MG_BLOCKS_COUNT)
    fprintf(f, ", %s blocks", blocks[m->blocks]);
  if (m->block_smoothing && m->block_fraction < 1.0)
    fprintf(f, ", blocks at cells with a piece under %g", m->block_fraction);
  if (m->block_smoothing && m->block_sweep) fprintf(f, ", blocks one way");
  if (m->point_sweep) fprintf(f, ", points one way");
  if (m->coarse_interval > 1) fprintf(f, ", coarse values every %d set-ups", m->coarse_interval);
  fprintf(f, ")");
}

static void view_strength(FILE *f, const char *what, int m)
{
  if (m >= 0)
    fprintf(f, " %s %d", what, m);
  else
    fprintf(f, " %s default", what);
}

/* The geometry line after "geometry: ", without the transform. */
static void view_geometry(FILE *f, const fcm_scene_geometry *g)
{
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
            g->center[0], g->center[1], g->center[2], fcm__scene_axis_names[g->axis],
            g->inner_radius, g->outer_radius, g->length, g->radial_cells, g->angular_cells,
            g->axial_cells);
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
            fcm__scene_implicit_names[g->implicit[g->num_implicit - 1].kind], g->refinement,
            g->min[0], g->max[0], g->min[1], g->max[1], g->min[2], g->max[2],
            (long long)g->cells[0], (long long)g->cells[1], (long long)g->cells[2]);
    break;
  default:
    fprintf(f, "tetgen %s, %s", g->mesh, g->ele);
    break;
  }
}

/* The solver line: the linear solver with its preconditioner, then Newton and the threads. */
static void view_solver(FILE *f, const fcm_scene_solver *sv)
{
  const fcm_integrator_options *so = &sv->integrator;
  fprintf(f, "solver: %s",
          SCENE_CHOICE_NAME(fcm__scene_solver_names, fcm__scene_solver_values, so->linear_solver));
  if (so->linear_solver == FCM_LINEAR_DIRECT)
    fprintf(f, " (%s)", fcm__scene_direct_names[so->direct_method]);
  else if (so->linear_solver == FCM_LINEAR_MULTIGRID) {
    view_multigrid(f, &so->multigrid);
    if (so->multigrid_fixed_cycles > 0)
      fprintf(f, ", %d cycles per solve (warm-started, no tolerance)", so->multigrid_fixed_cycles);
    else
      fprintf(f, ", rtol %g, atol %g, at most %d cycles", so->krylov_rtol, so->krylov_atol,
              so->krylov_max_iterations);
  } else {
    fprintf(f, " preconditioner %s (%s tangent)",
            fcm__scene_preconditioner_names[so->preconditioner],
            fcm__scene_tangent_names[so->preconditioner_tangent]);
    if (so->preconditioner == FCM_PRECOND_SCHWARZ)
      fprintf(f, " (threshold %g, epsilon %g, %s)", so->schwarz_theta, so->schwarz.epsilon,
              fcm__scene_clamp_names[so->schwarz.clamp]);
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
          SCENE_CHOICE_NAME(fcm__scene_newton_rule_names, fcm__scene_newton_rule_values,
                            so->tolerance_mode),
          so->newton_tolerance, so->newton_max_iterations, so->line_search ? "on" : "off",
          so->project_psd ? "on" : "off", so->rep_acceleration, sv->threads > 0 ? sv->threads : 0);
  if (so->newton_fixed_iterations > 0)
    fprintf(f,
            "  interactive steps: %d Newton iteration(s) per step, accepted whatever the "
            "residual (reported per step)\n",
            so->newton_fixed_iterations);
}

void fcm_scene_view(const fcm_scene *s, FILE *f)
{
  const fcm_scene_background *b = &s->background;
  const fcm_scene_geometry *g = &s->geometry;
  const fcm_cell_rules_options *q = &s->quadrature.rules;
  const fcm_scene_time *t = &s->time;
  fprintf(f, "scene %s (%s)\n", s->name, s->source);
  if (s->description[0]) fprintf(f, "  %s\n", s->description);
  if (b->kind == FCM_SCENE_BACKGROUND_GRID && b->fit)
    fprintf(f, "background: %s grid of %g m cubes fitted around the geometry, margin %g m\n",
            fcm__scene_element_names[b->element], b->fit_cell_size, b->fit_margin);
  else if (b->kind == FCM_SCENE_BACKGROUND_GRID)
    fprintf(f, "background: %s grid %lld x %lld x %lld over [%g, %g] x [%g, %g] x [%g, %g] m\n",
            fcm__scene_element_names[b->element], (long long)b->cells[0], (long long)b->cells[1],
            (long long)b->cells[2], b->min[0], b->max[0], b->min[1], b->max[1], b->min[2],
            b->max[2]);
  else
    fprintf(f, "background: mesh %s\n", b->mesh);
  if (b->octree) {
    fprintf(f, "  refined as an octree (2:1 balanced):");
    if (b->octree_boundary)
      fprintf(f, " along the embedded boundary to level %d", b->octree_boundary);
    if (b->octree_region)
      fprintf(f, "%s in [%g, %g] x [%g, %g] x [%g, %g] m to level %d",
              b->octree_boundary ? ";" : "", b->octree_region_min[0], b->octree_region_max[0],
              b->octree_region_min[1], b->octree_region_max[1], b->octree_region_min[2],
              b->octree_region_max[2], b->octree_region);
    if (b->octree_cuts)
      fprintf(f, "%s along the cut surfaces to level %d%s",
              b->octree_boundary || b->octree_region ? ";" : "", b->octree_cuts,
              b->octree_cuts_at_cut ? " when the first cut applies (during the run)" : "");
    fprintf(f, "\n");
  }
  fprintf(f, "geometry: ");
  view_geometry(f, g);
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
  fprintf(f, "; moments %s; simplify %s (%s); stabilization %s alpha %g; min fraction %g\n",
          fcm_cell_moments_name(q->moments), fcm_cell_simplify_name(q->simplify),
          fcm__scene_simplify_names[q->simplify_options.method],
          fcm__scene_stabilization_names[q->stabilization.mode], q->stabilization.alpha,
          q->min_fraction);
  view_solver(f, &s->solver);
  fprintf(f, "on inversion: %s\n", fcm__scene_inversion_names[s->solver.stop_on_inversion ? 1 : 0]);
  if (t->integrator == FCM_INTEGRATOR_STATIC)
    fprintf(f, "time: static, %lld step(s) of %g s, %d load step(s) each\n",
            (long long)t->num_steps, t->dt, t->load_steps);
  else {
    char par[64] = ""; /* the scheme's parameter */
    if (t->scheme == FCM_SCHEME_HHT) snprintf(par, sizeof par, " (alpha %g)", t->hht_alpha);
    if (t->scheme == FCM_SCHEME_GENERALIZED_ALPHA)
      snprintf(par, sizeof par, " (rho_inf %g)", t->rho_inf);
    fprintf(f, "time: %s%s, %lld steps of dt = %g s, %g s in all\n",
            fcm_time_scheme_name(t->scheme), par, (long long)t->num_steps, t->dt, t->duration);
  }
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
