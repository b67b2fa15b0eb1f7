/* Allocation failures in the scene runner: for every public entry point that allocates
 * (fcm_simulation_create, _step, _write_frame, _write_log, _write_checkpoint,
 * _center_of_mass, _summary_view and fcm_scene_create_from_file / _create_default), failing
 * the k-th allocation for k = 0, 1, ... until the call succeeds returns FCM_ERR_ALLOC (the
 * context says so too), a NULL output, leaks nothing, leaves no temporary and no partial
 * file in the output directory, and a failing step leaves the simulation where it was (same
 * step count, state and log). Scenes: an embedded body with gravity, damping, a traction and
 * a clamp solved directly; the same with MINRES and Schwarz blocks; a static one; a free
 * spinning body (its summary computes the centre of mass). Argument "full": all four scenes
 * (slow); without: the first and the last. */
#include "scene_util.h"
#include "output_check.h"

#include <omp.h>
#include <sys/stat.h>
#include <unistd.h>

#define DIR "scene_alloc_sim.d"

#define BODY(extra_solver, time, damping)                                                          \
  "{\"version\": 1, \"name\": \"as\","                                                             \
  " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"                         \
  "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"                                           \
  " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.5, 0.5],"              \
  "   \"cells\": [3, 1, 1]},"                                                                      \
  " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000},"      \
  " \"solver\": {\"threads\": 1" extra_solver "},"                                                 \
  " \"time\": " time ","                                                                           \
  " \"output\": {\"frame_interval\": 1, \"checkpoint_interval\": 1},"                              \
  " \"effects\": [{\"gravity\": {}}," damping                                                      \
  "  {\"traction\": {\"region\": {\"box\": {\"min\": [1.1, -1, -1], \"max\": [1.3, 1, 1]}},"       \
  "   \"value\": [0, 0, -100]}},"                                                                  \
  "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"                             \
  "   \"normal\": [-1, 0, 0]}}}}]}"

#define DAMPING "{\"damping\": {\"mass\": 0.1, \"stiffness\": 0.01}},"

static const char *scenes[] = {
    BODY("", "{\"dt\": 0.02, \"steps\": 70}", DAMPING),
    BODY(", \"method\": \"minres\", \"preconditioner\": \"schwarz\","
         " \"schwarz\": {\"threshold\": 1}",
         "{\"dt\": 0.02, \"steps\": 4}", DAMPING),
    BODY("", "{\"static\": true, \"dt\": 0.25, \"steps\": 4}", ""),
    /* a free body: its summary prints the drift of the centre of mass */
    "{\"version\": 1, \"name\": \"as\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
    "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.5, 0.5],"
    "   \"cells\": [3, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"solver\": {\"threads\": 1},"
    " \"time\": {\"dt\": 0.01, \"steps\": 4},"
    " \"effects\": [{\"initial_velocity\": {\"angular_velocity\": [0, 0, 3]}}]}"};

enum { OP_CREATE, OP_STEP, OP_FRAME, OP_LOG, OP_CHECKPOINT, OP_COM, OP_SUMMARY, OP_COUNT };
static const char *op_names[] = {"create",     "step",           "write_frame", "write_log",
                                 "checkpoint", "center_of_mass", "summary_view"};

/* Everything the failing call must not change. */
typedef struct snapshot {
  long long steps, frames;
  double t;
  double u[4096], v[4096];
} snapshot;

static void snap(fcm_simulation *sim, snapshot *s)
{
  fcm_integrator *I = fcm_simulation_integrator(sim);
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  s->frames = c.frames;
  memset(s->u, 0, sizeof s->u);
  memset(s->v, 0, sizeof s->v);
  if (fcm_integrator_num_dofs(I) <= 4096) fcm_integrator_get_state(I, s->u, s->v, &s->t, &s->steps);
}

static fcm_status op(int which, fcm_simulation *sim, int *frame)
{
  double com[3];
  switch (which) {
  case OP_STEP:
    return fcm_simulation_step(sim, NULL);
  case OP_FRAME:
    return fcm_simulation_write_frame(sim, DIR, (*frame)++);
  case OP_LOG:
    return fcm_simulation_write_log(sim, DIR "/as_log.csv");
  case OP_CHECKPOINT:
    return fcm_simulation_write_checkpoint(sim, DIR "/as_checkpoint.fcmck");
  case OP_COM:
    return fcm_simulation_center_of_mass(sim, com);
  default:
    return FCM_ERR_INTERNAL;
  }
}

/* The loop for operation `which` of scene `s`: each round creates the simulation with no
 * failure, takes `pre` steps and writes `pre_frames` frames and a log, then fails the k-th
 * allocation of the operation. Returns the number of failing rounds. */
static int loop(fcm_ctx *ctx, failing *f, const fcm_scene *scene, int s, int which, int pre,
                int pre_frames)
{
  const long long live = fcm_ctx_live_allocations(ctx);
  const int failures0 = test_failures_;
  int ok = 0, failures = 0;
  for (long long k = 0; k < 100000 && !ok; k++) {
    fcm_simulation *sim = NULL;
    int frame = 0;
    fcm_status st = FCM_OK;
    vr_mkdir(DIR);
    f->fail_at = -1;
    if (which == OP_CREATE) {
      sim = (fcm_simulation *)f; /* must come back NULL on failure */
      f->count = 0;
      f->fail_at = k;
      st = fcm_simulation_create(ctx, scene, NULL, &sim);
      f->fail_at = -1;
      if (st != FCM_OK && sim != NULL) {
        TEST_FAIL_("scene %d create, allocation %lld failing: sim not NULL", s, k);
        sim = NULL;
      }
    } else {
      TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
      if (!sim) return failures;
      for (int p = 0; p < pre; p++)
        TEST_OK(ctx, fcm_simulation_step(sim, NULL));
      for (int p = 0; p < pre_frames; p++)
        TEST_OK(ctx, fcm_simulation_write_frame(sim, DIR, frame++));
      TEST_OK(ctx, fcm_simulation_write_log(sim, DIR "/as_log.csv"));
      static snapshot before, after;
      snap(sim, &before);
      f->count = 0;
      f->fail_at = k;
      if (which == OP_SUMMARY) {
        FILE *null = fopen("/dev/null", "w");
        fcm_simulation_summary_view(sim, null);
        if (null) fclose(null);
        st = fcm_ctx_error_status(ctx);
        if (f->count <= k) st = FCM_OK; /* no allocation failed: done */
      } else {
        st = op(which, sim, &frame);
      }
      f->fail_at = -1;
      if (st != FCM_OK) {
        snap(sim, &after);
        if (memcmp(&before, &after, sizeof before))
          TEST_FAIL_("scene %d %s, allocation %lld failing: the simulation changed", s,
                     op_names[which], k);
        /* and it carries on where it was */
        if (which == OP_STEP) {
          TEST_OK(ctx, fcm_simulation_step(sim, NULL));
          TEST_TRUE(fcm_simulation_step_count(sim) == pre + 1);
        }
      }
    }
    if (st == FCM_OK) {
      ok = 1;
    } else {
      failures++;
      if (st != FCM_ERR_ALLOC ||
          (which != OP_SUMMARY && fcm_ctx_error_status(ctx) != FCM_ERR_ALLOC))
        TEST_FAIL_("scene %d %s, allocation %lld failing: %s (%s)", s, op_names[which], k,
                   fcm_status_name(st), fcm_ctx_error_message(ctx));
    }
    fcm_ctx_error_clear(ctx);
    /* no temporary, and whatever was written is whole */
    oc_counts c = oc_check_dir(DIR, ctx, which == OP_CHECKPOINT ? scene : NULL);
    if (c.tmp || c.bad)
      TEST_FAIL_("scene %d %s, allocation %lld failing: %d temporaries, %d bad files (%s)", s,
                 op_names[which], k, c.tmp, c.bad, c.first_error);
    fcm_simulation_destroy(&sim);
    if (fcm_ctx_live_allocations(ctx) != live) {
      TEST_FAIL_("scene %d %s, allocation %lld failing: %lld allocations leaked", s,
                 op_names[which], k, fcm_ctx_live_allocations(ctx) - live);
      break;
    }
    if (test_failures_ > failures0 + 5) break;
  }
  if (!ok) TEST_FAIL_("scene %d %s: never succeeded", s, op_names[which]);
  return failures;
}

int main(int argc, char **argv)
{
  /* quick (default): the direct embedded scene and the free body; full: all four */
  const int full = argc > 1 && !strcmp(argv[1], "full");
  /* the quick and the full test run in parallel: each in a working directory of its own */
  const char *wd = full ? "scene_alloc_sim_full.wd" : "scene_alloc_sim_quick.wd";
  mkdir(wd, 0755);
  if (chdir(wd) != 0) {
    TEST_FAIL_("cannot enter the working directory %s", wd);
    return TEST_RESULT();
  }
  omp_set_num_threads(1); /* the failing allocator counts calls in order */
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return TEST_RESULT();
  for (int s = 0; s < 4; s++) {
    if (!full && (s == 1 || s == 2)) continue;
    /* the scene itself, parsed from a file with failing allocations */
    char path[256];
    snprintf(path, sizeof path, "scene_alloc_sim_%d.json", s);
    TEST_TRUE(write_text(path, scenes[s]) == 0);
    int ok = 0, failures = 0;
    for (long k = 0; k < 1000 && !ok; k++) {
      fcm_scene *sc = (fcm_scene *)&f;
      f.count = 0;
      f.fail_at = k;
      fcm_status st = fcm_scene_create_from_file(ctx, path, &sc);
      f.fail_at = -1;
      if (st == FCM_OK) {
        ok = 1;
        fcm_scene_destroy(&sc);
      } else {
        failures++;
        if (st != FCM_ERR_ALLOC || sc != NULL)
          TEST_FAIL_("scene file %d, allocation %ld failing: %s", s, k, fcm_status_name(st));
      }
      fcm_ctx_error_clear(ctx);
      TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    }
    TEST_TRUE(ok && failures >= 5);
    remove(path);

    fcm_scene *scene = NULL;
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, scenes[s], "alloc_simulation.json", &scene));
    if (!scene) continue;
    int n[OP_COUNT];
    for (int w = 0; w < OP_COUNT; w++) {
      if (s == 2 && w == OP_COM) continue; /* static: no mass matrix */
      double t0 = fcm_wtime();
      n[w] = loop(ctx, &f, scene, s, w, w == OP_STEP ? 1 : 2, 1);
      if (getenv("VERBOSE"))
        fprintf(stderr, "scene %d %s: %d failing allocations, %.2f s\n", s, op_names[w], n[w],
                fcm_wtime() - t0);
      if (w == OP_CREATE && n[w] < 20) TEST_FAIL_("scene %d: create failed only %d times", s, n[w]);
      if ((w == OP_FRAME || w == OP_CHECKPOINT || w == OP_LOG) && n[w] < 1)
        TEST_FAIL_("scene %d %s: no allocation to fail", s, op_names[w]);
    }
    if (s == 0) {
      /* the 65th step and frame outgrow the first 64 rows of the log and frame times */
      loop(ctx, &f, scene, s, OP_STEP, 64, 1);
      loop(ctx, &f, scene, s, OP_FRAME, 2, 64);
    }
    fcm_scene_destroy(&scene);
  }
  /* the built-in scene */
  {
    int ok = 0, failures = 0;
    for (long k = 0; k < 1000 && !ok; k++) {
      fcm_scene *sc = (fcm_scene *)&f;
      f.count = 0;
      f.fail_at = k;
      fcm_status st = fcm_scene_create_default(ctx, &sc);
      f.fail_at = -1;
      if (st == FCM_OK) {
        ok = 1;
        fcm_scene_destroy(&sc);
      } else {
        failures++;
        if (st != FCM_ERR_ALLOC || sc != NULL)
          TEST_FAIL_("default scene, allocation %ld failing: %s", k, fcm_status_name(st));
      }
      fcm_ctx_error_clear(ctx);
      TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    }
    TEST_TRUE(ok && failures >= 5);
  }
  vr_rmdir(DIR);
  fcm_ctx_destroy(&ctx);
  if (chdir("..") == 0) rmdir(wd);
  return TEST_RESULT();
}
