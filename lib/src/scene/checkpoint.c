/* Checkpoints of a scene run: save the state a run needs to go on (integrator state bit for
 * bit, per-step log, frame times, cumulative iteration counts) and restore it into a new
 * simulation of the same scene.
 *
 * File layout (host byte order; every integer 8 bytes, doubles IEEE 754 binary64):
 *   "FCMCKPT\0"  magic
 *   u64 version (1), u64 byte-order mark 0x0102030405060708
 *   u64 scene fingerprint (see fingerprint())
 *   i64 num_dofs, i64 steps, f64 time
 *   (version 2) i64 cuts applied (the first k cut effects in time order)
 *   i64 newton_iterations, i64 linear_iterations, i64 tangent_assemblies
 *   i64 frames, then frames x f64 frame time
 *   i64 log rows, then rows x (f64 time, residual, energy, wall; i64 newton, linear;
 *   version 2: i64 pieces; f64 mass, momentum x, y, z;
 *   version 3: 6 x f64 per constraint effect: reaction x, y, z, moment x, y, z;
 *   version 4: i64 inverted quadrature points, i64 cell of the first (-1: none), i64 NaN or
 *   infinite von Mises values of the frame after the step (-1: no frame))
 *   num_dofs x f64 displacement, num_dofs x f64 velocity
 *   u64 FNV-1a 64 checksum of every byte before it
 *
 * Earlier versions' PETSc linear driver wrote a format of its own (".fcmpk"): the 16 bytes
 * "fcm-petsc-ck-1\n\0", i64 num_dofs, elements, steps, integrator kind; f64 time, dt;
 * num_dofs x f64 displacement, num_dofs x f64 velocity (the space's DOF numbering). The reader
 * converts it (read_petsc_v1()). */
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

#define CKPT_MAGIC   "FCMCKPT"
#define CKPT_VERSION 4u
#define CKPT_BOM     0x0102030405060708ull
#define FNV_OFFSET   0xcbf29ce484222325ull
#define FNV_PRIME    0x100000001b3ull

static uint64_t fnv(uint64_t h, const void *data, size_t n)
{
  const unsigned char *p = data;
  for (size_t k = 0; k < n; k++) {
    h ^= p[k];
    h *= FNV_PRIME;
  }
  return h;
}

/* A fingerprint of what the state depends on: the scene summary without its name line,
 * time span, output section and the reaction to inverted points (a resumed run may be longer,
 * write elsewhere or stop where the first run warned), plus the
 * exact bits of the step, the material and the discretization's sizes. It guards against
 * resuming the wrong scene; it is a hash, not a proof. */
static uint64_t fingerprint(const fcm_simulation *S)
{
  uint64_t h = FNV_OFFSET;
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
          h = fnv(h, line, n);
        line += n;
      }
    }
    free(text); /* open_memstream's buffer comes from malloc */
  }
  const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
  const fcm_material *mat = fcm_scene_get_material(S->scene);
  /* sizes before any cut: a restored run re-applies the cuts the checkpoint had */
  int64_t sizes[5] = {(int64_t)S->base_dofs, (int64_t)S->nn, (int64_t)fcm_mesh_num_cells(S->mesh),
                      (int64_t)S->base_constrained, (int64_t)tm->load_steps};
  double reals[4] = {tm->dt, mat->young, mat->poisson, mat->density};
  int flags[2] = {tm->integrator == FCM_INTEGRATOR_STATIC, (int)mat->model};
  h = fnv(h, sizes, sizeof sizes);
  h = fnv(h, reals, sizeof reals);
  h = fnv(h, flags, sizeof flags);
  return h;
}

/* ---------------------------------------------------------------- writing */

typedef struct ckpt_writer {
  fcm_ctx *ctx;
  fcm__atomic_file *af;
  uint64_t hash;
} ckpt_writer;

static fcm_status put(ckpt_writer *w, const void *data, size_t n)
{
  w->hash = fnv(w->hash, data, n);
  return fcm__io_atomic_write(w->ctx, w->af, data, n);
}

static fcm_status put_u64(ckpt_writer *w, uint64_t x)
{
  return put(w, &x, sizeof x);
}
static fcm_status put_i64(ckpt_writer *w, long long x)
{
  int64_t v = (int64_t)x;
  return put(w, &v, sizeof v);
}
static fcm_status put_f64(ckpt_writer *w, double x)
{
  return put(w, &x, sizeof x);
}

fcm_status fcm_simulation_write_checkpoint(fcm_simulation *S, const char *path)
{
  fcm_status st = FCM_OK;
  fcm__atomic_file af;
  memset(&af, 0, sizeof af);
  FCM_CHECK(S && path && path[0], S ? S->ctx : NULL, FCM_ERR_ARG,
            "simulation: write_checkpoint needs a simulation and a path");
  fcm_ctx *ctx = S->ctx;
  ckpt_writer w = {ctx, &af, FNV_OFFSET};
  fcm_index n = fcm_integrator_num_dofs(S->integ);
  double t = 0.0;
  long long steps = 0;
  fcm_integrator_get_state(S->integ, NULL, NULL, &t, &steps);
  /* a run resumed from here starts without a kept factorization: so does this one (with a
   * backend only one process writes, and every process dropped it when the checkpoint was due:
   * their Newton iterations must agree) */
  if (!S->distributed) fcm_integrator_drop_factorization(S->integ);
  FCM_TRY(ctx, fcm__io_atomic_open(ctx, path, 1, NULL, &af));
  {
    char magic[8] = CKPT_MAGIC;
    FCM_TRY(ctx, put(&w, magic, sizeof magic));
  }
  FCM_TRY(ctx, put_u64(&w, CKPT_VERSION));
  FCM_TRY(ctx, put_u64(&w, CKPT_BOM));
  FCM_TRY(ctx, put_u64(&w, fingerprint(S)));
  FCM_TRY(ctx, put_i64(&w, (long long)n));
  FCM_TRY(ctx, put_i64(&w, steps));
  FCM_TRY(ctx, put_f64(&w, t));
  FCM_TRY(ctx, put_i64(&w, S->cuts_applied));
  FCM_TRY(ctx, put_i64(&w, S->c.newton_iterations));
  FCM_TRY(ctx, put_i64(&w, S->c.linear_iterations));
  FCM_TRY(ctx, put_i64(&w, S->c.tangent_assemblies));
  FCM_TRY(ctx, put_i64(&w, S->c.frames));
  for (long long k = 0; k < S->c.frames; k++)
    FCM_TRY(ctx, put_f64(&w, S->frame_time[k]));
  FCM_TRY(ctx, put_i64(&w, S->log_n));
  for (long long k = 0; k < S->log_n; k++) {
    const fcm__log_row *r = &S->log[k];
    FCM_TRY(ctx, put_f64(&w, r->time));
    FCM_TRY(ctx, put_f64(&w, r->residual));
    FCM_TRY(ctx, put_f64(&w, r->energy));
    FCM_TRY(ctx, put_f64(&w, r->wall));
    FCM_TRY(ctx, put_i64(&w, r->newton));
    FCM_TRY(ctx, put_i64(&w, r->linear));
    FCM_TRY(ctx, put_i64(&w, r->pieces));
    FCM_TRY(ctx, put_f64(&w, r->mass));
    for (int d = 0; d < 3; d++)
      FCM_TRY(ctx, put_f64(&w, r->momentum[d]));
    if (S->num_react > 0)
      FCM_TRY(ctx, put(&w, S->react_log + (size_t)k * 6 * (size_t)S->num_react,
                       6 * (size_t)S->num_react * sizeof(double)));
    FCM_TRY(ctx, put_i64(&w, r->inverted));
    FCM_TRY(ctx, put_i64(&w, r->inverted_cell));
    FCM_TRY(ctx, put_i64(&w, r->nonfinite));
  }
  FCM_TRY(ctx, put(&w, fcm_integrator_displacement(S->integ), sizeof(double) * (size_t)n));
  FCM_TRY(ctx, put(&w, fcm_integrator_velocity(S->integ), sizeof(double) * (size_t)n));
  {
    uint64_t sum = w.hash;
    FCM_TRY(ctx, fcm__io_atomic_write(ctx, &af, &sum, sizeof sum));
  }
  FCM_TRY(ctx, fcm__io_atomic_commit(ctx, &af));
cleanup:
  if (st != FCM_OK && S) fcm__io_atomic_abort(S->ctx, &af);
  return st;
}

/* ---------------------------------------------------------------- reading */

typedef struct ckpt_reader {
  fcm_ctx *ctx;
  const char *path;
  const unsigned char *data;
  size_t size, pos;
} ckpt_reader;

static fcm_status get(ckpt_reader *r, void *out, size_t n, const char *what)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(r->pos <= r->size && n <= r->size - r->pos, r->ctx, FCM_ERR_FORMAT,
            "checkpoint %s: truncated (%zu bytes) while reading %s at byte %zu", r->path, r->size,
            what, r->pos);
  memcpy(out, r->data + r->pos, n);
  r->pos += n;
cleanup:
  return st;
}

static fcm_status get_i64(ckpt_reader *r, long long *x, long long lo, long long hi,
                          const char *what)
{
  fcm_status st = FCM_OK;
  int64_t v = 0;
  FCM_TRY(r->ctx, get(r, &v, sizeof v, what));
  FCM_CHECK(v >= lo && v <= hi, r->ctx, FCM_ERR_FORMAT,
            "checkpoint %s: %s = %lld is outside [%lld, %lld]", r->path, what, (long long)v, lo,
            hi);
  *x = (long long)v;
cleanup:
  return st;
}

/* Checkpoints above this size are refused before reading (1 TiB). */
#define CKPT_MAX_BYTES ((size_t)1 << 40)

/* `count` records of `each` bytes must fit in what is left of the file before anything is
 * allocated for them: a count the file cannot hold is a truncated or corrupted file. */
static fcm_status need(ckpt_reader *r, long long count, size_t each, const char *what)
{
  fcm_status st = FCM_OK;
  size_t left = r->pos <= r->size ? r->size - r->pos : 0;
  FCM_CHECK(count >= 0 && (unsigned long long)count <= left / each, r->ctx, FCM_ERR_FORMAT,
            "checkpoint %s: %lld %s of %zu bytes announced at byte %zu, but only %zu bytes are "
            "left (the file is truncated or corrupted)",
            r->path, count, what, each, r->pos, left);
cleanup:
  return st;
}

/* What a checkpoint file holds, read and checked against the simulation (not applied yet). */
typedef struct ckpt_data {
  long long n, steps, frames, rows, cuts, newton, linear, tangents;
  double t;
  double *u, *v, *frame_time, *react;
  fcm__log_row *log;
  long long frame_cap, log_cap, react_cap;
} ckpt_data;

static void ckpt_data_free(fcm_ctx *ctx, ckpt_data *d)
{
  fcm__free(ctx, d->u);
  fcm__free(ctx, d->v);
  fcm__free(ctx, d->frame_time);
  fcm__free(ctx, d->log);
  fcm__free(ctx, d->react);
}

/* The state at the end of a checkpoint: d->n displacement and velocity values, nothing after. */
static fcm_status read_state(ckpt_reader *r, ckpt_data *d)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = r->ctx;
  FCM_TRY(ctx, need(r, d->n, 2 * sizeof(double), "displacement and velocity values"));
  FCM_ALLOC(ctx, d->n, d->u);
  FCM_ALLOC(ctx, d->n, d->v);
  FCM_TRY(ctx, get(r, d->u, sizeof *d->u * (size_t)d->n, "the displacement"));
  FCM_TRY(ctx, get(r, d->v, sizeof *d->v * (size_t)d->n, "the velocity"));
  FCM_CHECK(r->pos == r->size, ctx, FCM_ERR_FORMAT, "checkpoint %s: %zu unexpected trailing bytes",
            r->path, r->size - r->pos);
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

/* The older PETSc linear driver's checkpoint (see the top of the file) in data (size bytes)
 * into *d: the state, time and step count; checked against the scene (DOFs, elements, kind and
 * dt). It holds no log: the rows of its steps carry their time alone (the other columns NaN,
 * the counts 0, the inversions and frames not recorded), and the frames are those its run
 * wrote (steps 0, frame_interval, 2 frame_interval, ... up to its step). */
static const char petsc_v1_magic[16] = "fcm-petsc-ck-1\n";

static fcm_status read_petsc_v1(fcm_simulation *S, const char *path, const unsigned char *data,
                                size_t size, ckpt_data *d)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  ckpt_reader r = {ctx, path, data, size, sizeof petsc_v1_magic};
  long long elems = 0, kind = 0;
  double dt = 0.0;
  const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
  FCM_TRY(ctx, get_i64(&r, &d->n, 0, INT64_MAX, "num_dofs"));
  FCM_TRY(ctx, get_i64(&r, &elems, 0, INT64_MAX, "elements"));
  FCM_TRY(ctx, get_i64(&r, &d->steps, 0, INT64_MAX, "steps"));
  FCM_TRY(ctx, get_i64(&r, &kind, 0, 1, "the integrator kind"));
  FCM_TRY(ctx, get(&r, &d->t, sizeof d->t, "time"));
  FCM_TRY(ctx, get(&r, &dt, sizeof dt, "dt"));
  FCM_CHECK(elems == (long long)fcm_space_num_elements(S->space) &&
                kind == (long long)tm->integrator && dt == tm->dt,
            ctx, FCM_ERR_ARG,
            "checkpoint %s is of another problem: %lld elements, kind %lld, dt %g (scene '%s': "
            "%lld, %d, %g)",
            path, elems, kind, dt, fcm_scene_name(S->scene),
            (long long)fcm_space_num_elements(S->space), (int)tm->integrator, tm->dt);
  FCM_TRY(ctx, check_steps(S, path, d->steps));
  FCM_TRY(ctx, read_state(&r, d));
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
      w->residual = w->energy = w->wall = w->mass = NAN;
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

/* Read and check the whole file `path` into *d (local: no process talks to another). */
static fcm_status read_file(fcm_simulation *S, const char *path, ckpt_data *d)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  unsigned char *data = NULL;
  const size_t nreact = 6 * (size_t)S->num_react;
  size_t size = 0;
  uint64_t ver = 0;
  FCM_TRY(ctx, fcm__file_read_all(ctx, "checkpoint", path, CKPT_MAX_BYTES, (char **)&data, &size));
  ckpt_reader r = {ctx, path, data, size, 0};
  if (size >= sizeof petsc_v1_magic && !memcmp(data, petsc_v1_magic, sizeof petsc_v1_magic)) {
    st = read_petsc_v1(S, path, data, size, d);
    goto cleanup;
  }
  {
    char magic[8];
    uint64_t version = 0, bom = 0, fp = 0, sum = 0;
    FCM_CHECK(size >= sizeof magic + 8 && !memcmp(data, CKPT_MAGIC, sizeof magic), ctx,
              FCM_ERR_FORMAT, "checkpoint %s: not an fcm checkpoint (no FCMCKPT header)", path);
    FCM_TRY(ctx, get(&r, magic, sizeof magic, "the header"));
    FCM_TRY(ctx, get(&r, &version, sizeof version, "the version"));
    FCM_TRY(ctx, get(&r, &bom, sizeof bom, "the byte-order mark"));
    FCM_CHECK(bom == CKPT_BOM, ctx, FCM_ERR_FORMAT,
              "checkpoint %s: written on a machine of the other byte order", path);
    FCM_CHECK(version >= 1 && version <= CKPT_VERSION, ctx, FCM_ERR_FORMAT,
              "checkpoint %s: version %llu; this build reads versions 1 to %u", path,
              (unsigned long long)version, CKPT_VERSION);
    ver = version;
    memcpy(&sum, data + size - sizeof sum, sizeof sum);
    FCM_CHECK(fnv(FNV_OFFSET, data, size - sizeof sum) == sum, ctx, FCM_ERR_FORMAT,
              "checkpoint %s: checksum mismatch (the file is truncated or corrupted)", path);
    r.size = size - sizeof sum;
    FCM_TRY(ctx, get(&r, &fp, sizeof fp, "the fingerprint"));
    FCM_CHECK(fp == fingerprint(S), ctx, FCM_ERR_ARG,
              "checkpoint %s: written by a different scene or discretization than scene '%s' "
              "(only the time span and the output section may change)",
              path, fcm_scene_name(S->scene));
  }
  FCM_TRY(ctx, get_i64(&r, &d->n, 0, INT64_MAX, "num_dofs"));
  FCM_TRY(ctx, get_i64(&r, &d->steps, 0, INT64_MAX, "steps"));
  FCM_TRY(ctx, check_steps(S, path, d->steps));
  FCM_TRY(ctx, get(&r, &d->t, sizeof d->t, "time"));
  if (ver >= 2) FCM_TRY(ctx, get_i64(&r, &d->cuts, S->cuts_applied, S->num_cuts, "cuts applied"));
  FCM_TRY(ctx, get_i64(&r, &d->newton, 0, INT64_MAX, "newton_iterations"));
  FCM_TRY(ctx, get_i64(&r, &d->linear, 0, INT64_MAX, "linear_iterations"));
  FCM_TRY(ctx, get_i64(&r, &d->tangents, 0, INT64_MAX, "tangent_assemblies"));
  FCM_TRY(ctx, get_i64(&r, &d->frames, 0, d->steps + 1, "frames"));
  FCM_TRY(ctx, need(&r, d->frames, sizeof *d->frame_time, "frame times"));
  if (d->frames > 0) {
    FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&d->frame_time, &d->frame_cap, d->frames,
                               sizeof *d->frame_time));
    FCM_TRY(ctx,
            get(&r, d->frame_time, sizeof *d->frame_time * (size_t)d->frames, "the frame times"));
  }
  FCM_TRY(ctx, get_i64(&r, &d->rows, d->steps, d->steps, "log rows (one per step)"));
  const size_t row_bytes = ver >= 2 ? (8 + (ver >= 3 ? nreact : 0)) * sizeof(double) +
                                          (ver >= 4 ? 6 : 3) * sizeof(int64_t)
                                    : 4 * sizeof(double) + 2 * sizeof(int64_t);
  FCM_TRY(ctx, need(&r, d->rows, row_bytes, "log rows"));
  FCM_TRY(ctx, alloc_rows(ctx, d, nreact));
  for (long long k = 0; k < d->rows; k++) {
    fcm__log_row *w = &d->log[k];
    double x[4];
    int64_t i[2];
    FCM_TRY(ctx, get(&r, x, sizeof x, "a log row"));
    FCM_TRY(ctx, get(&r, i, sizeof i, "a log row"));
    w->time = x[0], w->residual = x[1], w->energy = x[2], w->wall = x[3];
    w->newton = (long long)i[0], w->linear = (long long)i[1];
    if (ver >= 2) {
      int64_t pc;
      double e[4];
      FCM_TRY(ctx, get(&r, &pc, sizeof pc, "a log row"));
      FCM_TRY(ctx, get(&r, e, sizeof e, "a log row"));
      w->pieces = (long long)pc, w->mass = e[0];
      memcpy(w->momentum, e + 1, 3 * sizeof *e);
    }
    if (nreact > 0 && ver >= 3) {
      FCM_TRY(ctx, get(&r, d->react + (size_t)k * nreact, nreact * sizeof *d->react, "a log row"));
    } else {
      for (size_t j = 0; j < nreact; j++) /* not recorded by that version */
        d->react[(size_t)k * nreact + j] = NAN;
    }
    w->inverted = w->inverted_cell = w->nonfinite = -1; /* not recorded before version 4 */
    if (ver >= 4) {
      FCM_TRY(ctx, get_i64(&r, &w->inverted, 0, INT64_MAX, "a log row's inverted points"));
      FCM_TRY(ctx, get_i64(&r, &w->inverted_cell, -1, INT64_MAX, "a log row's inverted cell"));
      FCM_TRY(ctx, get_i64(&r, &w->nonfinite, -1, INT64_MAX, "a log row's NaN stresses"));
    }
  }
  FCM_TRY(ctx, read_state(&r, d));
cleanup:
  fcm__free(ctx, data);
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
  FCM_CHECK(S->c.steps == 0 && S->c.frames == 0 && !S->restored, ctx, FCM_ERR_ARG,
            "checkpoint %s: restore into a new simulation (this one has taken %lld steps and "
            "written %lld frames)",
            path, S->c.steps, S->c.frames);
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
  if (!S || S->c.steps == 0) return 0;
  int every = S->opts.checkpoint_interval >= 0
                  ? S->opts.checkpoint_interval
                  : fcm_scene_get_output(S->scene)->checkpoint_interval;
  return every > 0 && S->c.steps % every == 0;
}
