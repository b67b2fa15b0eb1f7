/* The scene runner, summary: what the run built and did, in words
 * (fcm_simulation_summary_view()), and its distributed form summed over the processes. */
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
#include <sys/resource.h>
#include <sys/stat.h>

static void line(FILE *f, int on, const char *what, const char *detail)
{
  fprintf(f, "  %-9s %-28s %s\n", on ? "computed" : "skipped", what, detail);
}

/* The multigrid hierarchy of the current integrator: DOFs per level, finest first (the
 * coarsest is solved by CHOLMOD), and the cycle. Nothing before the first solve. */
static void multigrid_line(const fcm_simulation *S, FILE *f)
{
  const fcm_mg *mg = fcm_integrator_multigrid(S->integ);
  const fcm_mg_options *o = &fcm_scene_get_solver(S->scene)->integrator.multigrid;
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
    snprintf(b + len, sizeof b - (size_t)len, "; %s-cycle, %d+%d smoothing steps%s, %s omega %g",
             o->cycle_index == 2 ? "W" : "V", o->pre_smooth, o->post_smooth,
             o->block_smoothing ? " with vertex blocks" : "",
             SCENE_CHOICE_NAME(fcm__scene_smoother_names, fcm__scene_smoother_values, o->smoother),
             o->omega != 0.0 ? o->omega : fcm_mg_smoother_omega(o->smoother));
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

/* What quadrature.simplify = "auto" decided for kind k and why: the passes expected (by
 * source), the cut-cell points of a pass plain and simplified, and the modelled costs. */
static void auto_line(const fcm__auto_uses *u, fcm_rule_kind k, const fcm_simplify_decision *d,
                      fcm_index plain, char *b, size_t size)
{
  char uses[160];
  if (k == FCM_RULE_STIFFNESS)
    snprintf(uses, sizeof uses, "force + tangent %g, body forces %g, frames' stresses %g", u->steps,
             u->loads, u->frames);
  else
    snprintf(uses, sizeof uses, "mass matrix %g, the log's mass blocks %g", u->matrix, u->momentum);
  snprintf(b, size,
           "auto: %s for %g expected passes (%s) over %lld cut-cell points, %.0f simplified; "
           "cost model %.3g core-s per point per pass, %.3g core-s simplifying; estimated %.3g "
           "core-s plain vs %.3g simplifying + passes",
           d->simplified ? "on" : "off", d->expected_assemblies, uses, (long long)plain,
           d->estimated_kept, d->point_cost, d->estimated_time, d->cost_plain, d->cost_simplified);
}

/* The summary's lines of the cell rules the set-up built: cells, volumes, what lies outside the
 * background, the simplification of each kind and the rules built (gs: the statistics to show,
 * NULL: the set-up's, S->setup_stats; the cuts have lines of their own, cut_lines()). */
static void rules_lines(const fcm_simulation *S, FILE *f, const fcm_cell_rules_stats *gs,
                        const fcm_simulation_counters *c)
{
  char b[768];
  if (S->rules) {
    const fcm_cell_rules_stats *rs = gs ? gs : &S->setup_stats;
    fprintf(f,
            "  cells     %lld: %lld uncut, %lld cut, %lld dropped; cut-cell points stiffness "
            "%lld -> %lld, mass %lld -> %lld (before -> after simplification)\n",
            (long long)rs->num_cells, (long long)rs->num_uncut, (long long)rs->num_cut,
            (long long)rs->num_dropped, (long long)rs->points_initial[FCM_RULE_STIFFNESS],
            (long long)rs->points_simplified[FCM_RULE_STIFFNESS],
            (long long)rs->points_initial[FCM_RULE_MASS],
            (long long)rs->points_simplified[FCM_RULE_MASS]);
    if (rs->num_surface_cells > 0)
      fprintf(f,
              "  moments   %lld cut cells from the boundary surface (candidates -> fitted points "
              "above), %lld of them fell back to the volume mesh\n",
              (long long)rs->num_surface_cells, (long long)rs->num_surface_fallbacks);
    fprintf(f,
            "  volume    embedded %.6g of %.6g m^3 (ratio %.6f), outside the background %.3g, in "
            "dropped cells %.3g\n",
            rs->embedded_volume, rs->geometry_volume, rs->volume_ratio, rs->outside_volume,
            rs->dropped_volume);
    if (c->dropped_area > 0.0) { /* boundary no surface rule carries */
      fprintf(f,
              "  boundary  %.6g m^2, of it %.3g m^2 (%.3g%%) in dropped cells (volume fraction "
              "below quadrature.min_fraction = %g): no load or boundary constraint acts there",
              c->boundary_area, c->dropped_area, 100.0 * c->dropped_area / c->boundary_area,
              fcm_scene_get_quadrature(S->scene)->rules.min_fraction);
      if (c->effect_dropped_fraction > 0.0)
        fprintf(f, "; effects[%d] (%s) loses %.3g%% of its boundary", c->effect_dropped_index,
                fcm_effect_type_name(fcm_scene_get_effect(S->scene, c->effect_dropped_index)->type),
                100.0 * c->effect_dropped_fraction);
      fputc('\n', f);
    }
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
    const fcm_cell_rules_options *q = &fcm_scene_get_quadrature(S->scene)->rules;
    static const char *const kinds[FCM_RULE_KIND_COUNT] = {"stiffness", "mass"};
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const fcm_simplify_decision *d = &rs->decision[k];
      char what[64];
      snprintf(what, sizeof what, "%s simplification", kinds[k]);
      if (!fcm_cell_rules_has_kind(S->rules, (fcm_rule_kind)k))
        snprintf(b, sizeof b, "(no %s rules built)", kinds[k]);
      else {
        if (q->simplify == FCM_CELL_SIMPLIFY_AUTO)
          auto_line(&S->auto_uses, (fcm_rule_kind)k, d, rs->points_initial[k], b, sizeof b);
        else
          snprintf(b, sizeof b, "%s (scene), %.3g core-s", fcm_cell_simplify_name(q->simplify),
                   d->time_simplify);
        const long long fitted = (long long)(rs->num_surface_cells - rs->num_surface_fallbacks);
        if (fitted > 0) /* their candidates are no rule: the fit is not optional */
          snprintf(b + strlen(b), sizeof b - strlen(b),
                   "; this decides for the volume path's cells only, the %lld cells of the "
                   "surface path are fitted either way",
                   fitted);
      }
      line(f, d->simplified, what, b);
    }
  }
  if (S->rules) { /* which rule kinds the scene called for, with their stored points */
    const fcm_cell_rules_stats *rs = gs ? gs : &S->setup_stats;
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
}

/* One line per cut applied: the cells it integrated again, their points before and after
 * simplification (cs: per cut, stiffness and mass, initial then simplified; NULL: this
 * process's, S->cut_stats) and its time. */
static void cut_lines(const fcm_simulation *S, FILE *f, const fcm_index *cs)
{
  for (int k = 0; k < S->c.cuts && S->cut_stats; k++) {
    const fcm_cell_rules_stats *r = &S->cut_stats[k];
    fcm_index p[4] = {r->points_initial[FCM_RULE_STIFFNESS], r->points_initial[FCM_RULE_MASS],
                      r->points_simplified[FCM_RULE_STIFFNESS],
                      r->points_simplified[FCM_RULE_MASS]};
    if (cs) memcpy(p, cs + 4 * k, sizeof p);
    if (r->num_cells == 0) {
      fprintf(f, "  cut %-5d t = %g s: missed the body's box\n", k + 1, S->cut_at[k]);
      continue;
    }
    fprintf(f,
            "  cut %-5d t = %g s: %lld cells integrated again, %lld split; their points "
            "stiffness %lld -> %lld, mass %lld -> %lld; %.3f s (rules %.3f s, solver %.3f s)\n",
            k + 1, S->cut_at[k], (long long)r->num_integrated, (long long)r->num_split,
            (long long)p[0], (long long)p[2], (long long)p[1], (long long)p[3], S->cut_time[k],
            r->time_total, S->cut_solver[k]);
  }
}

/* The process's peak resident set size in bytes (getrusage(); Linux reports kilobytes), 0
 * when unknown. */
static double peak_rss(void)
{
  struct rusage ru;
  if (getrusage(RUSAGE_SELF, &ru) != 0) return 0.0;
  return 1024.0 * (double)ru.ru_maxrss;
}

/* Bytes the set-up's cut-cell rules held at their peak, from their statistics: each cut cell's
 * pieces keep the arrays of their initial points (stabilization included) until the rules are
 * gathered into one array per kind, which then holds the final points: 33 bytes a point (3
 * coordinates, weight, flag) in both. The simplification's own work space (per cell, see
 * fcm_cell_rules_options.max_rule_memory) and the geometry are not included. */
static double rules_memory(const fcm_cell_rules_stats *rs)
{
  double points = 0.0;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    points += (double)rs->points_initial[k] + (double)rs->points_simplified[k] +
              2.0 * (double)rs->points_stabilization[k];
  return 33.0 * points;
}

/* One line of the set-up's phases first..last (those that ran) within their part `what` of
 * `total` seconds; "other": the part's time outside them. */
static void phase_line(const fcm_simulation *S, FILE *f, const fcm_simulation_counters *c,
                       const char *what, fcm_setup_phase first, fcm_setup_phase last, double total)
{
  char b[512];
  int any = 0;
  for (int p = (int)first; p <= (int)last; p++)
    any |= (S->phases_run >> p) & 1u;
  if (!any) return;
  int len = snprintf(b, sizeof b, "            [s] %s:", what);
  double sum = 0.0;
  const char *sep = " ";
  for (int p = (int)first; p <= (int)last && len > 0 && (size_t)len < sizeof b; p++) {
    if (!(S->phases_run & (1u << p))) continue;
    len += snprintf(b + len, sizeof b - (size_t)len, "%s%s %.3f", sep,
                    fcm_setup_phase_name((fcm_setup_phase)p), c->time_setup_phase[p]);
    sum += c->time_setup_phase[p];
    sep = ", ";
  }
  if (len > 0 && (size_t)len < sizeof b)
    snprintf(b + len, sizeof b - (size_t)len, ", other %.3f", fmax(0.0, total - sum));
  fprintf(f, "%s\n", b);
}

/* The set-up's time: its four parts and the rest, then the phases of each part that has
 * several, and the cell rules' own parts from their statistics (wall seconds; per-cell work
 * also in core-seconds). */
static void setup_lines(const fcm_simulation *S, FILE *f, const fcm_simulation_counters *c)
{
  const double rest = fmax(0.0, c->time_setup - c->time_setup_geometry - c->time_setup_rules -
                                    c->time_setup_space - c->time_setup_integrator);
  fprintf(f,
          "  set-up    [s] mesh and geometry %.3f, cell rules %.3f, space %.3f, integrator %.3f, "
          "the rest %.3f\n",
          c->time_setup_geometry, c->time_setup_rules, c->time_setup_space,
          c->time_setup_integrator, rest);
  phase_line(S, f, c, "mesh and geometry", FCM_SETUP_READ, FCM_SETUP_BACKGROUND,
             c->time_setup_geometry);
  if (c->cell_rules) {
    const fcm_cell_rules_stats *rs = &S->setup_stats;
    const double cells = fmax(0.0, rs->time_total - rs->time_setup - rs->time_gather);
    fprintf(f,
            "            [s] cell rules: index and tet rules %.3f, cells %.3f (classification, "
            "clipping and rules %.3g core-s, simplification %.3g core-s; %d threads), gathering "
            "%.3f, other %.3f\n",
            rs->time_setup, cells, rs->time_intersect, rs->time_simplify, rs->num_threads,
            rs->time_gather, fmax(0.0, c->time_setup_rules - rs->time_total));
  }
  phase_line(S, f, c, "the rest", FCM_SETUP_LOG, FCM_SETUP_OUTPUT_SURFACE, rest);
}

/* The summary with the rules' statistics `gs`, the cuts' point counts `cs` (cut_lines()), the
 * counters `gc`, the body's largest |u| over its quadrature points `body`, the free body's
 * centre of mass `com_now` (NULL: not available) and the peak resident memory `rss` given (a
 * distributed run, gc not NULL: summed over the processes), or taken from this process (gs, cs
 * and gc NULL, body < 0). */
/* The octree background's cells per level and hanging pairs (nothing for a uniform grid). */
static void octree_line(const fcm_simulation *S, FILE *f)
{
  if (!S->mesh || !fcm_mesh_is_octree(S->mesh)) return;
  long long per_level[FCM_OCTREE_MAX_LEVEL + 1] = {0};
  const int top = fcm_mesh_max_level(S->mesh);
  char b[512];
  int len = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(S->mesh); c++)
    per_level[fcm_mesh_cell_level(S->mesh, c)]++;
  len += snprintf(b + len, sizeof b - (size_t)len,
                  "%lld cells, per level 0..%d:", (long long)fcm_mesh_num_cells(S->mesh), top);
  for (int l = 0; l <= top && len < (int)sizeof b; l++)
    len += snprintf(b + len, sizeof b - (size_t)len, " %lld", per_level[l]);
  if (len < (int)sizeof b)
    len += snprintf(b + len, sizeof b - (size_t)len, "; %lld hanging (cell, node) pairs",
                    (long long)fcm_mesh_num_hanging(S->mesh));
  if (S->refined && len < (int)sizeof b) /* "cuts": {"when": "cut"} */
    snprintf(b + len, sizeof b - (size_t)len,
             "; refined along the cuts at t = %g s, before the first cut: %lld -> %lld cells "
             "(%.2f s)",
             S->refined_at, (long long)S->refine_cells[0], (long long)S->refine_cells[1],
             S->refine_seconds);
  line(f, 1, "octree background", b);
}

static void summary_view(const fcm_simulation *S, FILE *f, const fcm_cell_rules_stats *gs,
                         const fcm_index *cs, const fcm_simulation_counters *gc, double body,
                         const double *com_now, double rss)
{
  const fcm_simulation_counters *c = gc ? gc : &S->c;
  char b[512];
  fprintf(f, "simulation %s: %lld of %lld steps, %lld DOFs\n", fcm_scene_name(S->scene), c->steps,
          S->num_steps, (long long)c->num_dofs);
  line(f, c->cell_rules, "embedded cell rules", c->cell_rules ? "" : "(no geometry)");
  if (S->geometry_note[0]) fprintf(f, "  geometry  %s\n", S->geometry_note);
  octree_line(S, f);
  rules_lines(S, f, gs, c);
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
  if (c->contacts > 0 && c->contact_min_distance < HUGE_VAL)
    snprintf(b, sizeof b,
             "%d obstacle%s; up to %lld point-obstacle pairs within the threshold, smallest "
             "distance %.3g m, barrier energy up to %.3g J, friction work %.3g J; %lld "
             "evaluations",
             c->contacts, c->contacts == 1 ? "" : "s", c->contact_points_max,
             c->contact_min_distance, c->contact_energy_max, c->friction_dissipation,
             c->contact_evaluations);
  else
    snprintf(b, sizeof b, "%d obstacle%s", c->contacts, c->contacts == 1 ? "" : "s");
  line(f, c->contacts > 0, "contact obstacles", c->contacts ? b : "(no contact effect)");
  snprintf(b, sizeof b, "%lld blocks", (long long)c->schwarz_blocks);
  line(f, c->schwarz_blocks > 0, "Schwarz blocks",
       c->schwarz_blocks
           ? b
           : (c->krylov ? "(no cell below the threshold, or not asked)" : "(direct solver)"));
  snprintf(b, sizeof b, "%d applied (%d missed the body), %lld cells integrated again, %lld bodies",
           c->cuts, c->cuts_missed, (long long)c->cut_cells, (long long)c->pieces);
  line(f, c->cuts > 0, "cuts", c->cuts ? b : (S->num_cuts ? "(none due yet)" : "(no cut effect)"));
  cut_lines(S, f, cs);
  if (c->reused_factorizations > 0)
    snprintf(b, sizeof b,
             "%lld factorizations, %lld analyses, %lld fallbacks; %lld Newton iterations solved "
             "with a kept one",
             c->factorizations, c->analyses, c->direct_fallbacks, c->reused_factorizations);
  else
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
  fprintf(f,
          "  time [s]  setup %.3f  steps %.3f (integrator %.3f, cuts %.3f)  log %.3f  output "
          "%.3f\n",
          c->time_setup, c->time_steps, c->time_steps - c->time_cuts, c->time_cuts, c->time_log,
          c->time_output);
  if (c->steps > 0) {
    const double a = c->time_step_assembly, fa = c->time_step_factor, so = c->time_step_solve,
                 per = 1.0 / (double)c->steps;
    fprintf(f,
            "  step      [s] %.4f each: assembly %.4f, factorization %.4f, solves %.4f, the rest "
            "%.4f\n",
            (c->time_steps - c->time_cuts) * per, a * per, fa * per, so * per,
            (c->time_steps - c->time_cuts - a - fa - so) * per);
  }
  setup_lines(S, f, c);
  if (rss > 0.0 && S->rules)
    fprintf(f,
            "  memory    peak resident %.1f MiB%s; the set-up's cut-cell rules held about %.1f MiB "
            "(every cut cell's initial points until they are gathered, then the final ones)\n",
            rss / (1024.0 * 1024.0), gc ? " (summed over the processes)" : "",
            rules_memory(gs ? gs : &S->setup_stats) / (1024.0 * 1024.0));
  else if (rss > 0.0)
    fprintf(f, "  memory    peak resident %.1f MiB%s\n", rss / (1024.0 * 1024.0),
            gc ? " (summed over the processes)" : "");
}

void fcm_simulation_summary_view(const fcm_simulation *S, FILE *f)
{
  if (!S || !f) return;
  summary_view(S, f, NULL, NULL, NULL, -1.0, NULL, peak_rss());
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
  fcm_index *cs = NULL;
  int root = 1, com_ok = 0;
  const fcm_index ncut = 4 * (fcm_index)S->c.cuts; /* after the cells: the cuts' points */
  fcm__integrator_distributed(S->integ, &root);
  memset(&gs, 0, sizeof gs);
  /* per kind: points before / after simplification, stabilization, stored, skipped, kept
   * unsimplified; then surface triangles and points, tets, slivers; then each own cell's
   * largest |u| (every process's cells: the point counts are its own cells' only); then the
   * cuts' points (cut_lines()) and the process's peak resident memory */
  q = fcm__calloc(ctx, (size_t)(nv + nc + ncut) + 1, sizeof *q);
  cs = q ? fcm__calloc(ctx, (size_t)ncut + 1, sizeof *cs) : NULL;
  st = cs ? FCM_OK
          : fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
                       "simulation: out of memory (summary of %lld cells)", (long long)nc);
  if (st == FCM_OK && S->rules) {
    gs = S->setup_stats;
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
  for (int k = 0; cs && k < S->c.cuts; k++) {
    const fcm_cell_rules_stats *r = &S->cut_stats[k];
    double *qc = q + nv + nc + 4 * k;
    qc[0] = (double)r->points_initial[FCM_RULE_STIFFNESS];
    qc[1] = (double)r->points_initial[FCM_RULE_MASS];
    qc[2] = (double)r->points_simplified[FCM_RULE_STIFFNESS];
    qc[3] = (double)r->points_simplified[FCM_RULE_MASS];
  }
  if (q) q[nv + nc + ncut] = peak_rss();
  if (st == FCM_OK)
    st = fcm__space_cell_max_displacement(S->space, fcm_integrator_displacement(S->integ), q + nv);
  if (st == FCM_OK) {
    const fcm_cell_rules *R = fcm_space_cell_rules(S->space);
    for (fcm_index c = 0; c < nc; c++) /* another process's cell: its value (no rules: root's) */
      if (!fcm__cell_rules_owns(R, c) || (!R && !root)) q[nv + c] = 0.0;
  }
  FCM_TRY(ctx, fcm__integrator_reduce_status(S->integ, st, q, (fcm_index)nv + nc + ncut + 1));
  for (fcm_index i = 0; i < ncut; i++)
    cs[i] = (fcm_index)q[nv + nc + i];
  /* the free body's centre of mass: collective (the partial mass matrix), on every process */
  if (S->free_body) {
    com_ok = fcm__sim_center_of_mass(S, fcm_integrator_displacement(S->integ), com) == FCM_OK;
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
  if (f)
    summary_view(S, f, S->rules ? &gs : NULL, cs, &gc, body, com_ok ? com : NULL,
                 q[nv + nc + ncut]);
cleanup:
  fcm__free(ctx, cs);
  fcm__free(ctx, q);
  return st;
}
