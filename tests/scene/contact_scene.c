/* The contact effect through the scene runner, on apps/scenes/ball_on_floor.json (path in
 * argv[1]): the normalized scene (--print-scene) parses to the same scene; the run keeps every
 * embedded-surface point above the floor at every step; at the end the ball rests on it: the
 * log's centre-of-mass velocity momentum_z / mass is below 1 % of the impact speed and the
 * floor's reaction is m g within 3 %. A contact scene without a geometry, and bad contact keys,
 * are refused, named. */
#include "scene_util.h"

#include <math.h>

static const char no_geometry_json[] =
    "{\"version\": 1, \"name\": \"no_geometry\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
    "   \"cells\": [1, 1, 1]},"
    " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
    " \"time\": {\"dt\": 0.1, \"duration\": 0.1},"
    " \"effects\": [{\"contact\": {\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]}}}]}";

static const char bad_json[] =
    "{\"version\": 1, \"name\": \"bad\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
    "   \"cells\": [1, 1, 1]},"
    " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
    " \"time\": {\"dt\": 0.1, \"duration\": 0.1},"
    " \"effects\": [{\"contact\": {\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]},"
    "   \"distance\": -0.5}}]}";

static const char bad_normal_json[] =
    "{\"version\": 1, \"name\": \"bad\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
    "   \"cells\": [1, 1, 1]},"
    " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
    " \"time\": {\"dt\": 0.1, \"duration\": 0.1},"
    " \"effects\": [{\"contact\": {\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 0]}}}]}";

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  char path[1024];
  TEST_TRUE(argc > 1);
  if (argc < 2) return TEST_RESULT();
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  snprintf(path, sizeof path, "%s/ball_on_floor.json", argv[1]);
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  if (scene) check_normalized(ctx, scene, path);
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim) {
    fcm_integrator *I = fcm_simulation_integrator(sim);
    fcm_simulation_counters c;
    double dmin_all = HUGE_VAL, F[3] = {0, 0, 0};
    while (!fcm_simulation_done(sim)) {
      fcm_step_info si;
      double dmin = 0.0;
      TEST_OK(ctx, fcm_simulation_step(sim, &si));
      if (fcm_ctx_error_status(ctx) != FCM_OK) break;
      TEST_OK(ctx, fcm_integrator_contact_info(I, 0, F, &dmin, NULL, NULL));
      dmin_all = fmin(dmin_all, dmin);
    }
    fcm_simulation_get_counters(sim, &c);
    TEST_TRUE(c.contacts == 1 && c.surface_rules == 1);
    if (!(dmin_all > 0.0)) TEST_FAIL_("a surface point reached distance %.3g", dmin_all);
    /* the log's last row: momentum_z / mass, and the weight m g */
    char dir[] = "/tmp/fcm_contact_XXXXXX", log[1100];
    TEST_TRUE(mkdtemp(dir) != NULL);
    snprintf(log, sizeof log, "%s/log.csv", dir);
    TEST_OK(ctx, fcm_simulation_write_log(sim, log));
    FILE *f = fopen(log, "r");
    char line[4096], last[4096] = "", head[4096] = "";
    TEST_TRUE(f != NULL);
    if (f) {
      if (fgets(head, sizeof head, f))
        while (fgets(line, sizeof line, f))
          memcpy(last, line, sizeof line);
      fclose(f);
    }
    remove(log);
    rmdir(dir);
    /* columns: step,time,newton_iterations,linear_iterations,residual,energy,pieces,mass,
     * momentum_x,momentum_y,momentum_z,... */
    double col[11];
    int got = 0;
    char *p = last;
    for (; got < 11 && p && *p; got++) {
      col[got] = strtod(p, &p);
      if (*p == ',') p++;
    }
    TEST_TRUE(got == 11 && !strncmp(head, "step,time", 9));
    if (got == 11) {
      const double mass = col[7], vz = col[10] / mass, v_impact = sqrt(2.0 * 9.81 * 0.1);
      printf("ball_on_floor: min distance %.4g m, final vz %.3g m/s, reaction %.6g N, m g "
             "%.6g N\n",
             dmin_all, vz, F[2], mass * 9.81);
      if (!(fabs(vz) <= 0.01 * v_impact)) TEST_FAIL_("not at rest: vz = %.3g m/s", vz);
      TEST_NEAR(F[2], mass * 9.81, 0.03, 0.0);
    }
    fcm_simulation_destroy(&sim);
  }
  fcm_scene_destroy(&scene);
  /* refused, named */
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, no_geometry_json, "ng.json", &scene));
  if (scene) {
    TEST_ERR(ctx, fcm_simulation_create(ctx, scene, NULL, &sim), FCM_ERR_ARG, "effects[0]");
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  }
  TEST_ERR(ctx, fcm_scene_create_from_string(ctx, bad_json, "bad.json", &scene), FCM_ERR_ARG,
           "effects[0].contact.distance");
  fcm_scene_destroy(&scene);
  TEST_ERR(ctx, fcm_scene_create_from_string(ctx, bad_normal_json, "bad.json", &scene), FCM_ERR_ARG,
           "effects[0].contact.plane.normal");
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
