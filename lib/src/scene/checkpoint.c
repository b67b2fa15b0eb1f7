/* Checkpoints of a scene run: save the state a run needs to go on (integrator state bit for
 * bit, per-step log, frame times, cumulative iteration counts) and restore it into a new
 * simulation of the same scene.
 *
 * The file is the checkpoint container of io (io/checkpoint_file.c: magic "FCMCKPT\0",
 * u64 version, u64 byte-order mark, the payload, u64 FNV-1a 64 checksum), version 7; earlier
 * versions still load (1 to 5 for backward Euler and static scenes only: they hold no
 * acceleration, so a scene with another time scheme refuses them). Payload (every integer 8 bytes,
 * doubles IEEE 754 binary64): u64 scene fingerprint (see fingerprint(); never 0, the word of a file
 * without a scene) i64 num_dofs, i64 steps, f64 time (version 2) i64 cuts applied (the first k cut
 * effects in time order) i64 newton_iterations, i64 linear_iterations, i64 tangent_assemblies i64
 * frames, then frames x f64 frame time i64 log rows, then rows x (f64 time, residual, energy, wall;
 * i64 newton, linear; version 2: i64 pieces; f64 mass, momentum x, y, z; version 3: 6 x f64 per
 * constraint effect: reaction x, y, z, moment x, y, z; version 4: i64 inverted quadrature points,
 * i64 cell of the first (-1: none), i64 NaN or infinite von Mises values of the frame after the
 * step (-1: no frame); version 5: f64 the Newton stopping rule's tolerance; version 6: f64 kinetic
 * energy, elastic energy, load work; version 7: i64 contact points (-1: not known), f64 smallest
 * contact distance, contact energy, friction dissipation) (version 6) i64 time scheme
 * (fcm_time_scheme), f64 HHT alpha, f64 rho_inf, f64 load work, i64 1 when the acceleration follows
 * (else 0) num_dofs x f64 displacement, num_dofs x f64 velocity, (version 6, when flagged) num_dofs
 * x f64 acceleration
 *
 * The PETSc linear driver (fcm_petsc_problem_write_checkpoint()) writes the same container
 * with the "no scene" source word 0 and its counts (io_impl.h, fcm__ckpt_linear); earlier
 * versions of it wrote a format of their own (".fcmpk": the 16 bytes "fcm-petsc-ck-1\n\0" then
 * the same counts and state, no checksum). The reader converts both (read_linear()). */
#define _POSIX_C_SOURCE 200809L
#include "scene/run_impl.h"

#include "core/core_impl.h"
#include "io/io_impl.h"
#include "sim/sim_backend.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define CKPT_VERSION FCM__CKPT_VERSION

static const char ckpt_magic[8] = FCM__CKPT_MAGIC;

/* A fingerprint of what the state depends on: the scene summary without its name line,
 * time span, output section and the reaction to inverted points (a resumed run may be longer,
 * write elsewhere or stop where the first run warned), plus the
 * exact bits of the step, the material and the discretization's sizes. It guards against
 * resuming the wrong scene; it is a hash, not a proof. */
static uint64_t fingerprint(const fcm_simulation *S)
{
  uint64_t h = FCM__FNV_OFFSET;
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  if (f) {
    fcm_scene_view(S->scene, f);
    if (fclose(f) == 0 && text) {
      const char *line = text;
      while (*line) {
        const char *nl = strchr(line, '\n');
        size_t n = nl ? (size_t)(nl - line) + 1 : strlen(line);
        if (strncmp(line, "scene ", 6) && strncmp(line, "time:", 5) &&
            strncmp(line, "output:", 7) && strncmp(line, "on inversion:", 13))
          h = fcm__io_fnv(h, line, n);
        line += n;
      }
    }
    free(text); /* open_memstream's buffer comes from malloc */
  }
  const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
  const fcm_material *mat = fcm_scene_get_material(S->scene);
  /* sizes before any cut and any refinement during the run: a restored run re-applies the
   * cuts the checkpoint had (and the refinement before the first) */
  int64_t sizes[5] = {(int64_t)S->base_dofs, (int64_t)S->base_nodes, (int64_t)S->base_cells,
                      (int64_t)S->base_constrained, (int64_t)tm->load_steps};
  double reals[4] = {tm->dt, mat->young, mat->poisson, mat->density};
  int flags[2] = {tm->integrator == FCM_INTEGRATOR_STATIC, (int)mat->model};
  h = fcm__io_fnv(h, sizes, sizeof sizes);
  h = fcm__io_fnv(h, reals, sizeof reals);
  h = fcm__io_fnv(h, flags, sizeof flags);
  return h != FCM__CKPT_SOURCE_LINEAR ? h : h + 1; /* that word marks a file without a scene */
}

/* ---------------------------------------------------------------- writing */

fcm_status fcm_simulation_write_checkpoint(fcm_simulation *S, const char *path)
{
  fcm_status st = FCM_OK;
  fcm__ckpt_writer w;
  double *acc = NULL;
  memset(&w, 0, sizeof w);
  FCM_CHECK(S && path && path[0], S ? S->ctx : NULL, FCM_ERR_ARG,
            "simulation: write_checkpoint needs a simulation and a path");
  fcm_ctx *ctx = S->ctx;
  FCM_CHECK(S->api_cuts == 0, ctx, FCM_ERR_UNSUPPORTED,
            "checkpoint %s: the run was cut by fcm_simulation_cut() (%d times), whose blades the "
            "scene does not hold: a resumed run could not repeat those cuts",
            path, S->api_cuts);
  fcm_index n = fcm_integrator_num_dofs(S->integ);
  double t = 0.0;
  long long steps = 0;
  fcm_integrator_get_state(S->integ, NULL, NULL, &t, &steps);
  /* a run resumed from here starts without a kept factorization: so does this one (with a
   * backend only one process writes, and every process dropped it when the checkpoint was due:
   * their Newton iterations must agree) */
  if (!S->distributed) fcm_integrator_drop_factorization(S->integ);
  FCM_TRY(ctx, fcm__ckpt_open(ctx, path, ckpt_magic, CKPT_VERSION, &w));
  FCM_TRY(ctx, fcm__ckpt_put_u64(&w, fingerprint(S)));
  FCM_TRY(ctx, fcm__ckpt_put_i64(&w, (long long)n));
  FCM_TRY(ctx, fcm__ckpt_put_i64(&w, steps));
  FCM_TRY(ctx, fcm__ckpt_put_f64(&w, t));
  FCM_TRY(ctx, fcm__ckpt_put_i64(&w, S->cuts_applied));
  FCM_TRY(ctx, fcm__ckpt_put_i64(&w, S->c.newton_iterations));
  FCM_TRY(ctx, fcm__ckpt_put_i64(&w, S->c.linear_iterations));
  FCM_TRY(ctx, fcm__ckpt_put_i64(&w, S->c.tangent_assemblies));
  FCM_TRY(ctx, fcm__ckpt_put_i64(&w, S->c.frames));
  FCM_TRY(ctx, fcm__ckpt_put_f64s(&w, S->frame_time, (size_t)S->c.frames));
  FCM_TRY(ctx, fcm__ckpt_put_i64(&w, S->log_n));
  for (long long k = 0; k < S->log_n; k++) {
    const fcm__log_row *r = &S->log[k];
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, r->time));
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, r->residual));
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, r->energy));
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, r->wall));
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, r->newton));
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, r->linear));
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, r->pieces));
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, r->mass));
    FCM_TRY(ctx, fcm__ckpt_put_f64s(&w, r->momentum, 3));
    if (S->num_react > 0)
      FCM_TRY(ctx, fcm__ckpt_put_f64s(&w, S->react_log + (size_t)k * 6 * (size_t)S->num_react,
                                      6 * (size_t)S->num_react));
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, r->inverted));
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, r->inverted_cell));
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, r->nonfinite));
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, r->tolerance));
    const double e[3] = {r->kinetic, r->elastic, r->work};
    FCM_TRY(ctx, fcm__ckpt_put_f64s(&w, e, 3));
    const double c[3] = {r->contact_dmin, r->contact_energy, r->friction};
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, r->contact_points));
    FCM_TRY(ctx, fcm__ckpt_put_f64s(&w, c, 3));
  }
  {
    const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
    FCM_ALLOC(ctx, n, acc);
    const int known = fcm_integrator_get_acceleration(S->integ, acc);
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, (long long)tm->scheme));
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, tm->hht_alpha));
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, tm->rho_inf));
    FCM_TRY(ctx, fcm__ckpt_put_f64(&w, fcm_integrator_load_work(S->integ)));
    FCM_TRY(ctx, fcm__ckpt_put_i64(&w, known));
    FCM_TRY(ctx, fcm__ckpt_put_f64s(&w, fcm_integrator_displacement(S->integ), (size_t)n));
    FCM_TRY(ctx, fcm__ckpt_put_f64s(&w, fcm_integrator_velocity(S->integ), (size_t)n));
    if (known) FCM_TRY(ctx, fcm__ckpt_put_f64s(&w, acc, (size_t)n));
  }
  FCM_TRY(ctx, fcm__ckpt_commit(&w));
cleanup:
  if (st != FCM_OK) fcm__ckpt_abort(&w);
  if (S) fcm__free(S->ctx, acc);
  return st;
}

/* ---------------------------------------------------------------- reading */

/* What a checkpoint file holds, read and checked against the simulation (not applied yet). */
typedef struct ckpt_data {
  long long n, steps, frames, rows, cuts, newton, linear, tangents;
  double t, work;                         /* work: the load work (version 6; 0 before) */
  double *u, *v, *a, *frame_time, *react; /* a: the acceleration, NULL when not recorded */
  fcm__log_row *log;
  long long frame_cap, log_cap, react_cap;
} ckpt_data;

static void ckpt_data_free(fcm_ctx *ctx, ckpt_data *d)
{
  fcm__free(ctx, d->u);
  fcm__free(ctx, d->v);
  fcm__free(ctx, d->a);
  fcm__free(ctx, d->frame_time);
  fcm__free(ctx, d->log);
  fcm__free(ctx, d->react);
}

/* The state at the end of a checkpoint: d->n displacement and velocity values (and acceleration
 * values when `acc`), nothing after. */
static fcm_status read_state(fcm__ckpt_reader *r, ckpt_data *d, int acc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = r->ctx;
  FCM_TRY(ctx, fcm__ckpt_need(r, d->n, (2 + (acc != 0)) * sizeof(double),
                              "displacement, velocity (and acceleration) values"));
  FCM_ALLOC(ctx, d->n, d->u);
  FCM_ALLOC(ctx, d->n, d->v);
  FCM_TRY(ctx, fcm__ckpt_get(r, d->u, sizeof *d->u * (size_t)d->n, "the displacement"));
  FCM_TRY(ctx, fcm__ckpt_get(r, d->v, sizeof *d->v * (size_t)d->n, "the velocity"));
  if (acc) {
    FCM_ALLOC(ctx, d->n, d->a);
    FCM_TRY(ctx, fcm__ckpt_get(r, d->a, sizeof *d->a * (size_t)d->n, "the acceleration"));
  }
  FCM_TRY(ctx, fcm__ckpt_read_end(r));
cleanup:
  return st;
}

/* Room for d->rows log rows and their nreact reaction values each. */
static fcm_status alloc_rows(fcm_ctx *ctx, ckpt_data *d, size_t nreact)
{
  fcm_status st = FCM_OK;
  if (d->rows > 0)
    FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&d->log, &d->log_cap, d->rows, sizeof *d->log));
  if (d->rows > 0 && nreact > 0)
    FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&d->react, &d->react_cap, d->rows,
                               nreact * sizeof *d->react));
cleanup:
  return st;
}

/* A checkpoint's step count against the steps this run takes. */
static fcm_status check_steps(const fcm_simulation *S, const char *path, long long steps)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(steps <= S->num_steps, S->ctx, FCM_ERR_ARG,
            "checkpoint %s: step %lld is beyond the %lld steps this run takes (extend "
            "time.duration or --steps)",
            path, steps, S->num_steps);
cleanup:
  return st;
}

/* A checkpoint of the PETSc linear driver (the container's "no scene" source or the older
 * ".fcmpk", see the top of the file), the reader after its source word or magic line, into *d:
 * the state, time and step count; checked against the scene (DOFs, elements, kind and dt). It
 * holds no log: the rows of its steps carry their time alone (the other columns NaN, the
 * counts 0, the inversions and frames not recorded), and the frames are those its run wrote
 * (steps 0, frame_interval, 2 frame_interval, ... up to its step). */
static fcm_status read_linear(fcm_simulation *S, fcm__ckpt_reader *r, ckpt_data *d)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const char *path = r->path;
  fcm__ckpt_linear h;
  const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
  FCM_TRY(ctx, fcm__ckpt_get_linear(r, &h));
  d->n = h.num_dofs, d->steps = h.steps, d->t = h.time;
  FCM_CHECK(h.elements == (long long)fcm_space_num_elements(S->space) &&
                h.kind == (long long)tm->integrator && h.dt == tm->dt,
            ctx, FCM_ERR_ARG,
            "checkpoint %s is of another problem: %lld elements, kind %lld, dt %g (scene '%s': "
            "%lld, %d, %g)",
            path, h.elements, h.kind, h.dt, fcm_scene_name(S->scene),
            (long long)fcm_space_num_elements(S->space), (int)tm->integrator, tm->dt);
  FCM_TRY(ctx, check_steps(S, path, d->steps));
  FCM_CHECK(tm->scheme == FCM_SCHEME_BACKWARD_EULER, ctx, FCM_ERR_ARG,
            "checkpoint %s of the PETSc linear driver (backward Euler) cannot resume scene '%s' "
            "with time.integrator \"%s\"",
            path, fcm_scene_name(S->scene), fcm_time_scheme_name(tm->scheme));
  FCM_TRY(ctx, read_state(r, d, 0));
  {
    const int every = fcm_scene_get_output(S->scene)->frame_interval;
    const long long interval = every > 0 ? every : 1;
    const size_t nreact = 6 * (size_t)S->num_react;
    d->frames = d->steps / interval + 1;
    FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&d->frame_time, &d->frame_cap, d->frames,
                               sizeof *d->frame_time));
    for (long long k = 0; k < d->frames; k++)
      d->frame_time[k] = (double)(k * interval) * tm->dt;
    d->rows = d->steps;
    FCM_TRY(ctx, alloc_rows(ctx, d, nreact));
    for (long long k = 0; k < d->rows; k++) {
      fcm__log_row *w = &d->log[k];
      memset(w, 0, sizeof *w);
      w->time = (double)(k + 1) * tm->dt;
      w->residual = w->tolerance = w->energy = w->wall = w->mass = NAN;
      w->kinetic = w->elastic = w->work = NAN;
      w->contact_points = -1;
      w->contact_dmin = w->contact_energy = w->friction = NAN;
      w->momentum[0] = w->momentum[1] = w->momentum[2] = NAN;
      w->pieces = (long long)S->pieces;
      w->inverted = w->inverted_cell = w->nonfinite = -1;
      for (size_t j = 0; j < nreact; j++)
        d->react[(size_t)k * nreact + j] = NAN;
    }
  }
cleanup:
  return st;
}

/* Version 6: the time scheme and its parameters (the scene's, else refused: they are not part of
 * the fingerprint), the load work and whether the acceleration follows the state. An older
 * version holds none of them: a scene whose scheme needs the acceleration refuses it. */
static fcm_status read_scheme(fcm_simulation *S, fcm__ckpt_reader *r, ckpt_data *d, int *acc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
  const int dynamic = tm->integrator != FCM_INTEGRATOR_STATIC;
  long long scheme = 0, known = 0;
  double alpha = 0.0, rho = 0.0;
  *acc = 0;
  FCM_CHECK(r->version >= 6 || !dynamic || tm->scheme == FCM_SCHEME_BACKWARD_EULER, ctx,
            FCM_ERR_ARG,
            "checkpoint %s: version %llu holds no acceleration; time.integrator \"%s\" of scene "
            "'%s' needs version 6 or later (run it again from the start)",
            r->path, (unsigned long long)r->version, fcm_time_scheme_name(tm->scheme),
            fcm_scene_name(S->scene));
  if (r->version < 6) return FCM_OK;
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &scheme, 0, FCM_SCHEME_COUNT - 1, "the time scheme"));
  FCM_TRY(ctx, fcm__ckpt_get_f64(r, &alpha, "the HHT alpha"));
  FCM_TRY(ctx, fcm__ckpt_get_f64(r, &rho, "rho_inf"));
  FCM_TRY(ctx, fcm__ckpt_get_f64(r, &d->work, "the load work"));
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &known, 0, 1, "the acceleration flag"));
  FCM_CHECK(!dynamic ||
                (scheme == (long long)tm->scheme && alpha == tm->hht_alpha && rho == tm->rho_inf),
            ctx, FCM_ERR_ARG,
            "checkpoint %s: written with time.integrator \"%s\" (alpha %g, rho_inf %g), scene "
            "'%s' has \"%s\" (alpha %g, rho_inf %g)",
            r->path, fcm_time_scheme_name((fcm_time_scheme)scheme), alpha, rho,
            fcm_scene_name(S->scene), fcm_time_scheme_name(tm->scheme), tm->hht_alpha, tm->rho_inf);
  *acc = (int)known;
cleanup:
  return st;
}

/* The sections of a scene run's checkpoint (version ver), the reader after the fingerprint. */
static fcm_status read_scene(fcm_simulation *S, fcm__ckpt_reader *r, ckpt_data *d)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const char *path = r->path;
  const uint64_t ver = r->version;
  const size_t nreact = 6 * (size_t)S->num_react;
  int acc = 0;
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &d->n, 0, INT64_MAX, "num_dofs"));
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &d->steps, 0, INT64_MAX, "steps"));
  FCM_TRY(ctx, check_steps(S, path, d->steps));
  FCM_TRY(ctx, fcm__ckpt_get(r, &d->t, sizeof d->t, "time"));
  if (ver >= 2)
    FCM_TRY(ctx, fcm__ckpt_get_i64(r, &d->cuts, S->cuts_applied, S->num_cuts, "cuts applied"));
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &d->newton, 0, INT64_MAX, "newton_iterations"));
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &d->linear, 0, INT64_MAX, "linear_iterations"));
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &d->tangents, 0, INT64_MAX, "tangent_assemblies"));
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &d->frames, 0, d->steps + 1, "frames"));
  FCM_TRY(ctx, fcm__ckpt_need(r, d->frames, sizeof *d->frame_time, "frame times"));
  if (d->frames > 0) {
    FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&d->frame_time, &d->frame_cap, d->frames,
                               sizeof *d->frame_time));
    FCM_TRY(ctx, fcm__ckpt_get(r, d->frame_time, sizeof *d->frame_time * (size_t)d->frames,
                               "the frame times"));
  }
  FCM_TRY(ctx, fcm__ckpt_get_i64(r, &d->rows, d->steps, d->steps, "log rows (one per step)"));
  const size_t row_bytes =
      ver >= 2 ? (8 + (ver >= 3 ? nreact : 0) + (ver >= 5) + 3 * (ver >= 6) + 3 * (ver >= 7)) *
                         sizeof(double) +
                     ((ver >= 4 ? 6 : 3) + (ver >= 7)) * sizeof(int64_t)
               : 4 * sizeof(double) + 2 * sizeof(int64_t);
  FCM_TRY(ctx, fcm__ckpt_need(r, d->rows, row_bytes, "log rows"));
  FCM_TRY(ctx, alloc_rows(ctx, d, nreact));
  for (long long k = 0; k < d->rows; k++) {
    fcm__log_row *w = &d->log[k];
    double x[4];
    int64_t i[2];
    FCM_TRY(ctx, fcm__ckpt_get(r, x, sizeof x, "a log row"));
    FCM_TRY(ctx, fcm__ckpt_get(r, i, sizeof i, "a log row"));
    w->time = x[0], w->residual = x[1], w->energy = x[2], w->wall = x[3];
    w->newton = (long long)i[0], w->linear = (long long)i[1];
    if (ver >= 2) {
      int64_t pc;
      double e[4];
      FCM_TRY(ctx, fcm__ckpt_get(r, &pc, sizeof pc, "a log row"));
      FCM_TRY(ctx, fcm__ckpt_get(r, e, sizeof e, "a log row"));
      w->pieces = (long long)pc, w->mass = e[0];
      memcpy(w->momentum, e + 1, 3 * sizeof *e);
    }
    if (nreact > 0 && ver >= 3) {
      FCM_TRY(ctx, fcm__ckpt_get(r, d->react + (size_t)k * nreact, nreact * sizeof *d->react,
                                 "a log row"));
    } else {
      for (size_t j = 0; j < nreact; j++) /* not recorded by that version */
        d->react[(size_t)k * nreact + j] = NAN;
    }
    w->inverted = w->inverted_cell = w->nonfinite = -1; /* not recorded before version 4 */
    if (ver >= 4) {
      FCM_TRY(ctx, fcm__ckpt_get_i64(r, &w->inverted, 0, INT64_MAX, "a log row's inverted points"));
      FCM_TRY(ctx,
              fcm__ckpt_get_i64(r, &w->inverted_cell, -1, INT64_MAX, "a log row's inverted cell"));
      FCM_TRY(ctx, fcm__ckpt_get_i64(r, &w->nonfinite, -1, INT64_MAX, "a log row's NaN stresses"));
    }
    w->tolerance = NAN; /* not recorded before version 5 */
    if (ver >= 5) FCM_TRY(ctx, fcm__ckpt_get(r, &w->tolerance, sizeof w->tolerance, "a log row"));
    double e[3] = {NAN, NAN, NAN}; /* not recorded before version 6 */
    if (ver >= 6) FCM_TRY(ctx, fcm__ckpt_get(r, e, sizeof e, "a log row"));
    w->kinetic = e[0], w->elastic = e[1], w->work = e[2];
    w->contact_points = -1; /* not recorded before version 7 */
    w->contact_dmin = w->contact_energy = w->friction = NAN;
    if (ver >= 7) {
      double c[3];
      FCM_TRY(ctx, fcm__ckpt_get_i64(r, &w->contact_points, -1, INT64_MAX,
                                     "a log row's contact points"));
      FCM_TRY(ctx, fcm__ckpt_get(r, c, sizeof c, "a log row"));
      w->contact_dmin = c[0], w->contact_energy = c[1], w->friction = c[2];
    }
  }
  FCM_TRY(ctx, read_scheme(S, r, d, &acc));
  FCM_TRY(ctx, read_state(r, d, acc));
cleanup:
  return st;
}

/* Read and check the whole file `path` into *d (local: no process talks to another). */
static fcm_status read_file(fcm_simulation *S, const char *path, ckpt_data *d)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm__ckpt_reader r;
  uint64_t fp = 0;
  st = fcm__ckpt_read_open(ctx, path, ckpt_magic, CKPT_VERSION, &r);
  if (st == FCM_OK && r.legacy_linear) st = read_linear(S, &r, d);
  if (st != FCM_OK || r.legacy_linear) goto cleanup;
  FCM_TRY(ctx, fcm__ckpt_get_u64(&r, &fp, "the fingerprint"));
  if (fp == FCM__CKPT_SOURCE_LINEAR) {
    st = read_linear(S, &r, d);
    goto cleanup;
  }
  FCM_CHECK(fp == fingerprint(S), ctx, FCM_ERR_ARG,
            "checkpoint %s: written by a different scene or discretization than scene '%s' "
            "(only the time span and the output section may change)",
            path, fcm_scene_name(S->scene));
  st = read_scene(S, &r, d);
cleanup:
  fcm__ckpt_read_close(&r);
  return st;
}

fcm_status fcm_simulation_check_checkpoint(fcm_ctx *ctx, const char *path)
{
  fcm_status st = FCM_OK;
  fcm__ckpt_reader r;
  FCM_CHECK(path, ctx, FCM_ERR_ARG, "checkpoint: NULL path");
  FCM_TRY(ctx, fcm__ckpt_read_open(ctx, path, ckpt_magic, CKPT_VERSION, &r));
  fcm__ckpt_read_close(&r);
cleanup:
  return st;
}

fcm_status fcm_simulation_read_checkpoint(fcm_simulation *S, const char *path)
{
  fcm_status st = FCM_OK;
  ckpt_data d;
  memset(&d, 0, sizeof d);
  FCM_CHECK(S && path && path[0], S ? S->ctx : NULL, FCM_ERR_ARG,
            "simulation: read_checkpoint needs a simulation and a path");
  fcm_ctx *ctx = S->ctx;
  FCM_CHECK(S->c.steps == 0 && S->c.frames == 0 && S->api_cuts == 0 && !S->restored, ctx,
            FCM_ERR_ARG,
            "checkpoint %s: restore into a new simulation (this one has taken %lld steps, "
            "been cut %d times by fcm_simulation_cut() and written %lld frames)",
            path, S->c.steps, S->api_cuts, S->c.frames);
  st = read_file(S, path, &d);
  /* On a distributed backend (sim_backend.h) the cut replay below is collective: the
   * processes agree on the read first (a file one process cannot read fails every process
   * with its message, no process waits in a cut the others never start) and on the number
   * of cuts to replay (files that differ between the processes are refused). The counts c_p
   * are equal iff N sum c_p^2 = (sum c_p)^2 (Cauchy-Schwarz): every process tests the same
   * sums (exact: small integers), so every process takes the same decision. */
  if (fcm__integrator_distributed(S->integ, NULL)) {
    int rank = 0, nprocs = 1;
    fcm__integrator_processes(S->integ, &rank, &nprocs);
    double c[3] = {(double)d.cuts, (double)d.cuts * (double)d.cuts, 1.0};
    FCM_TRY(ctx, fcm__integrator_reduce_status(S->integ, st, c, 3));
    FCM_CHECK(c[2] * c[1] == c[0] * c[0], ctx, FCM_ERR_ARG,
              "checkpoint %s: the processes read different numbers of cuts (this one %lld, "
              "%g in all over %d processes): every process must read the same file",
              path, d.cuts, c[0], nprocs);
  }
  FCM_TRY(ctx, st);
  /* The file is whole: re-apply the cuts it had (the state lives on the cut space). */
  while (S->cuts_applied < d.cuts)
    FCM_TRY(ctx, fcm__sim_apply_cut(S));
  {
    const fcm_index ndof = fcm_integrator_num_dofs(S->integ);
    FCM_CHECK(d.n == ndof, ctx, FCM_ERR_ARG, "checkpoint %s: %lld DOFs, the simulation has %lld",
              path, d.n, (long long)ndof);
  }
  /* Everything read and checked: apply (set_state validates finiteness first). */
  FCM_TRY(ctx, fcm_integrator_set_state(S->integ, d.u, d.v, d.t, d.steps));
  FCM_TRY(ctx, fcm_integrator_set_acceleration(S->integ, d.a)); /* NULL: solved for */
  FCM_TRY(ctx, fcm_integrator_set_load_work(S->integ, d.work));
  S->c.steps = d.steps;
  S->c.newton_iterations = d.newton;
  S->c.linear_iterations = d.linear;
  S->c.tangent_assemblies = d.tangents;
  S->c.frames = d.frames;
  fcm__free(ctx, S->frame_time);
  S->frame_time = d.frame_time, S->frame_cap = d.frame_cap, d.frame_time = NULL;
  fcm__free(ctx, S->log);
  S->log = d.log, S->log_cap = d.log_cap, S->log_n = d.rows, d.log = NULL;
  fcm__free(ctx, S->react_log);
  S->react_log = d.react, S->react_cap = d.react_cap, d.react = NULL;
  fcm__sim_count_log(S);
  S->restored = 1;
cleanup:
  if (S) ckpt_data_free(S->ctx, &d);
  return st;
}

int fcm_simulation_checkpoint_due(const fcm_simulation *S)
{
  if (!S || S->c.steps == 0 || S->api_cuts > 0) return 0; /* such a run cannot be saved */
  int every = S->opts.checkpoint_interval >= 0
                  ? S->opts.checkpoint_interval
                  : fcm_scene_get_output(S->scene)->checkpoint_interval;
  return every > 0 && S->c.steps % every == 0;
}
