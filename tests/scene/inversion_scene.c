/* Inversion through the scene runner: a soft embedded block held at its base whose top is
 * driven down through the base (static, 4 steps). With "warn" every step is taken; the
 * counters (steps with inverted points, the first with its time and cell, the worst) are those
 * of the steps' fcm_step_info; each frame's nonfinite count (counters and the log) equals the
 * NaN von Mises values read back from its background and surface files; a checkpoint restores
 * the same counters (recounted from its log). With "stop" the first inverted step is taken and
 * logged, then reported as FCM_ERR_GEOMETRY naming the step, time, count and cell; a gentle
 * push counts nothing. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"
#include "../io/vtk_reader.h"

#include <stdint.h>

#define DIR "scene_inversion_frames"

static void scene_json(char *buf, size_t cap, double speed, const char *solver)
{
  snprintf(buf, cap,
           "{\"version\": 1, \"name\": \"squash\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           " \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0.1, 0.1, 0], \"max\": [0.9, 0.9, 1]},"
           " \"material\": {\"model\": \"snh\", \"young\": 1e4, \"poisson\": 0.3},"
           " %s \"time\": {\"static\": true, \"dt\": 0.25, \"steps\": 4},"
           " \"effects\": ["
           "  {\"fixed\": {\"region\": {\"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 0]}}}},"
           "  {\"motion\": {\"region\": {\"box\": {\"min\": [0, 0, 1], \"max\": [1, 1, 1]}},"
           "   \"velocity\": [0, 0, %g]}}]}",
           solver, -speed);
}

/* NaN or infinite values of a VTU's data array (-1: unreadable). */
static long nonfinite_in(const char *path, const char *parent, const char *name)
{
  vr_doc d;
  long k = -1;
  if (!vr_load(&d, path)) return -1;
  const vr_tag *t = vr_parse_vtu(&d) ? vr_data_array(&d, parent, name) : NULL;
  if (t) {
    uint64_t bytes = 0;
    const unsigned char *p = vr_array(&d, t, &bytes);
    k = 0;
    for (uint64_t i = 0; i < bytes / sizeof(double); i++) {
      double v;
      memcpy(&v, p + i * sizeof v, sizeof v);
      k += !isfinite(v);
    }
  }
  vr_free(&d);
  return k;
}

static void warn_run(fcm_ctx *ctx)
{
  char json[4096], path[256];
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL, *back = NULL;
  scene_json(json, sizeof json, 1.3, "");
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "squash.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  TEST_TRUE(vr_mkdir(DIR));
  fcm_simulation_counters c;
  long long steps = 0, first = 0, worst = 0, frames_bad = 0;
  fcm_index most = 0, first_cell = -1, most_bad = 0;
  double first_time = 0.0;
  TEST_OK(ctx, fcm_simulation_write_frame(sim, DIR, 0));
  for (int k = 1; !fcm_simulation_done(sim); k++) {
    fcm_step_info si;
    TEST_OK(ctx, fcm_simulation_step(sim, &si));
    if (si.inverted_points > 0) {
      if (steps++ == 0) first = k, first_time = si.time, first_cell = si.inverted_cell;
      if (si.inverted_points > most) most = si.inverted_points, worst = k;
      TEST_TRUE(si.inverted_cell >= 0 && si.inverted_det <= 0.0);
    }
    TEST_OK(ctx, fcm_simulation_write_frame(sim, DIR, k));
    fcm_simulation_get_counters(sim, &c);
    snprintf(path, sizeof path, DIR "/squash_background_%04d.vtu", k);
    const long cells = nonfinite_in(path, "CellData", "von_mises");
    snprintf(path, sizeof path, DIR "/squash_surface_%04d.vtu", k);
    const long points = nonfinite_in(path, "PointData", "von_mises");
    TEST_TRUE(cells >= 0 && points >= 0 && c.nonfinite_last == cells + points);
    /* an inverted cell average is NaN: a frame after an inverted step holds NaN */
    TEST_TRUE((si.inverted_points > 0) == (cells > 0));
    frames_bad += c.nonfinite_last > 0;
    if (c.nonfinite_last > most_bad) most_bad = c.nonfinite_last;
  }
  fcm_simulation_get_counters(sim, &c);
  TEST_TRUE(steps > 0 && first > 1); /* the first step only compresses */
  TEST_TRUE(c.inverted_steps == steps && c.inverted_first_step == first);
  TEST_TRUE(c.inverted_first_time == first_time && c.inverted_first_cell == first_cell);
  TEST_TRUE(c.inverted_max == most && c.inverted_max_step == worst);
  TEST_TRUE(c.nonfinite_frames == frames_bad && c.nonfinite_max == most_bad);
  TEST_TRUE(c.nonfinite_first_step == first);
  /* a checkpoint carries the log's counts: the restored counters are the same */
  TEST_OK(ctx, fcm_simulation_write_checkpoint(sim, DIR "/squash.fcmck"));
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &back));
  if (back) {
    fcm_simulation_counters b;
    TEST_OK(ctx, fcm_simulation_read_checkpoint(back, DIR "/squash.fcmck"));
    fcm_simulation_get_counters(back, &b);
    TEST_TRUE(b.inverted_steps == c.inverted_steps && b.inverted_first_step == first);
    TEST_TRUE(b.inverted_first_time == first_time && b.inverted_first_cell == first_cell);
    TEST_TRUE(b.inverted_max == most && b.inverted_max_step == worst);
    TEST_TRUE(b.nonfinite_frames == frames_bad && b.nonfinite_max == most_bad);
    TEST_TRUE(b.nonfinite_first_step == first && b.nonfinite_last == c.nonfinite_last);
  }
done:
  vr_rmdir(DIR);
  fcm_simulation_destroy(&back);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

/* "stop": the first inverted step is taken, logged and refused; a gentle push never is. */
static void stop_run(fcm_ctx *ctx, double speed)
{
  char json[4096], text[512];
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  scene_json(json, sizeof json, speed, "\"solver\": {\"on_inversion\": \"stop\"},");
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "squash.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  fcm_status st = FCM_OK;
  fcm_step_info si;
  while (st == FCM_OK && !fcm_simulation_done(sim))
    st = fcm_simulation_step(sim, &si);
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  if (speed < 1.0) {
    TEST_TRUE(st == FCM_OK && c.steps == 4 && c.inverted_steps == 0 && c.inverted_max == 0);
    TEST_TRUE(c.inverted_first_step == 0 && c.inverted_first_cell == -1);
    goto done;
  }
  TEST_TRUE(st == FCM_ERR_GEOMETRY && si.inverted_points > 0 && si.inverted_cell >= 0);
  TEST_TRUE(c.steps > 1 && c.steps < 4 && c.inverted_steps == 1);
  TEST_TRUE(c.inverted_first_step == c.steps && c.inverted_max == si.inverted_points);
  TEST_TRUE(fcm_integrator_time(fcm_simulation_integrator(sim)) == si.time);
  snprintf(text, sizeof text,
           "simulation squash: step %lld (t = %.9g s) ended with %lld inverted quadrature points "
           "(J = det F <= 0), the first in cell %lld at X = (",
           c.steps, si.time, (long long)si.inverted_points, (long long)si.inverted_cell);
  TEST_TRUE(strstr(fcm_ctx_error_message(ctx), text) != NULL);
  TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "solver.on_inversion is \"stop\"") != NULL);
  fcm_ctx_error_clear(ctx);
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  warn_run(ctx);
  stop_run(ctx, 1.3);
  stop_run(ctx, 0.2);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
