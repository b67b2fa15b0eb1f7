/* The scene runner, stepping: one step of the simulation, its row of the per-step log (mass,
 * momentum, reactions, inversions) and the run's state queries. */
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
void fcm__sim_count_frame(fcm_simulation_counters *c, long long step, fcm_index nonfinite)
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
  c->contact_points_max = 0;
  c->contact_min_distance = HUGE_VAL;
  c->contact_energy_max = c->friction_dissipation = 0.0;
  for (long long k = 0; k < S->log_n; k++) {
    const fcm__log_row *r = &S->log[k];
    if (r->contact_points >= 0) { /* rows of this run (checkpoints do not keep them) */
      c->contact_points_max = FCM_MAX(c->contact_points_max, r->contact_points);
      c->contact_min_distance = FCM_MIN(c->contact_min_distance, r->contact_dmin);
      c->contact_energy_max = FCM_MAX(c->contact_energy_max, r->contact_energy);
      c->friction_dissipation += r->friction;
    }
    count_inversion(c, k + 1, &S->log[k]);
    if (S->log[k].nonfinite >= 0) fcm__sim_count_frame(c, k + 1, (fcm_index)S->log[k].nonfinite);
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
      fcm__sim_count_cut(S, fcm_wtime() - tc);
    }
  }
  double t0 = fcm_wtime();
  st = fcm_integrator_step(S->integ, &si);
  double wall = fcm_wtime() - t0;
  S->c.time_steps += wall;
  S->c.newton_iterations += si.newton_iterations;
  S->c.linear_iterations += si.linear_iterations;
  S->c.multigrid_cycles += si.multigrid_cycles;
  S->c.reused_factorizations += si.reused_factorizations;
  S->c.tangent_assemblies += si.tangent_assemblies;
  S->c.time_step_assembly += si.time_assembly;
  S->c.time_step_factor += si.time_factor;
  S->c.time_step_solve += si.time_solve;
  S->c.factorizations = S->base_factorizations + si.total_factorizations;
  S->c.analyses = S->base_analyses + si.total_analyses;
  S->c.direct_fallbacks = S->base_fallbacks + si.total_direct_fallbacks;
  if (info) *info = si;
  if (st != FCM_OK) {
    fcm__trace(S->ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  S->c.steps++;
  /* a run resumed from a checkpoint of this step starts without a kept factorization */
  if (fcm_simulation_checkpoint_due(S)) fcm_integrator_drop_factorization(S->integ);
  const double tlog = fcm_wtime();
  for (int k = 0; k < S->num_react; k++)
    FCM_TRY(S->ctx,
            constraint_reaction(
                S, k, S->react_log + 6 * ((size_t)S->log_n * (size_t)S->num_react + (size_t)k)));
  fcm__log_row *r = &S->log[S->log_n++];
  r->time = si.time;
  r->newton = si.newton_iterations;
  r->linear = si.linear_iterations;
  r->residual = si.residual;
  r->tolerance = si.tolerance;
  r->energy = si.total_energy;
  r->kinetic = si.kinetic_energy;
  r->elastic = si.elastic_energy;
  r->work = si.load_work;
  r->wall = wall;
  r->pieces = S->pieces;
  r->inverted = si.inverted_points;
  r->inverted_cell = si.inverted_cell;
  r->nonfinite = -1;
  r->contact_points = -1;
  r->contact_dmin = r->contact_energy = r->friction = NAN;
  if (S->c.contacts > 0) {
    fcm_contact_stats cs;
    FCM_TRY(S->ctx, fcm_integrator_contact_stats(S->integ, &cs));
    r->contact_points = cs.active_points;
    r->contact_dmin = cs.step_min_distance;
    r->contact_energy = cs.barrier_energy;
    r->friction = cs.friction_dissipation;
    S->c.contact_evaluations = cs.evaluations;
    S->c.contact_points_max = FCM_MAX(S->c.contact_points_max, cs.active_points);
    S->c.contact_min_distance = FCM_MIN(S->c.contact_min_distance, cs.step_min_distance);
    S->c.contact_energy_max = FCM_MAX(S->c.contact_energy_max, cs.barrier_energy);
    S->c.friction_dissipation += cs.friction_dissipation;
  }
  count_inversion(&S->c, S->c.steps, r);
  FCM_TRY(S->ctx, log_momentum(S, r));
  S->c.time_log += fcm_wtime() - tlog;
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

fcm_status fcm_simulation_run(fcm_simulation *S, fcm_simulation_monitor_fn monitor, void *user)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(S, NULL, FCM_ERR_ARG, "simulation: run: NULL simulation");
  const double t0 = fcm_wtime();
  fcm_simulation_step_event ev;
  memset(&ev, 0, sizeof ev);
  ev.first = fcm_simulation_step_count(S);
  ev.num_steps = fcm_simulation_num_steps(S);
  while (!fcm_simulation_done(S)) {
    fcm_step_info si;
    st = fcm_simulation_step(S, &si); /* collective in a distributed run */
    if (st != FCM_OK) return st;
    if (!monitor) continue;
    ev.step = fcm_simulation_step_count(S);
    ev.wall = fcm_wtime() - t0;
    ev.info = &si;
    st = monitor(user, S, &ev);
    if (st != FCM_OK) return st;
  }
cleanup:
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
