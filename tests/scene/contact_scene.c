/* The contact effect through the scene runner, on apps/scenes/ball_on_floor.json (path in
 * argv[1]): the normalized scene (--print-scene) parses to the same scene; the run keeps every
 * embedded-surface point above the floor at every step; at the end the ball rests on it: the
 * log's centre-of-mass velocity momentum_z / mass is below 1 % of the impact speed and the
 * floor's reaction is m g within 3 %. apps/scenes/ball_off_wedge.json (a closed OBJ wedge and a
 * floor): every point stays outside the wedge (signed, by a ray test) and above the floor at
 * every step, and the ball touches both. A contact scene without a geometry, bad contact keys
 * (negative threshold, stiffness, friction or friction velocity, a non-positive radius, a box with
 * max <= min, two obstacles in one effect), an open obstacle surface and a body starting inside a
 * sphere, a box or a surface are refused, named. */
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

/* A scene of a ball (radius 0.35 at the origin) with one contact effect `contact` (the
 * object's members). */
static void ball_scene(char *out, size_t len, const char *contact)
{
  snprintf(out, len,
           "{\"version\": 1, \"name\": \"c\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.4, -0.4, -0.4],"
           "   \"max\": [0.4, 0.4, 0.4]}, \"cells\": [4, 4, 4]},"
           " \"geometry\": {\"shape\": \"ball\", \"center\": [0, 0, 0], \"radius\": 0.35},"
           " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3},"
           " \"time\": {\"dt\": 0.02, \"duration\": 0.02},"
           " \"effects\": [{\"contact\": {%s}}]}",
           contact);
}

/* A scene that parses and whose simulation set-up is refused with `want`. */
static void refused_setup(fcm_ctx *ctx, const char *contact, const char *want)
{
  char json[4096];
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  ball_scene(json, sizeof json, contact);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "c.json", &scene));
  if (scene) TEST_ERR(ctx, fcm_simulation_create(ctx, scene, NULL, &sim), FCM_ERR_ARG, want);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

/* A scene refused by the parser with `want`. */
static void refused_parse(fcm_ctx *ctx, const char *contact, const char *want)
{
  char json[4096];
  fcm_scene *scene = NULL;
  ball_scene(json, sizeof json, contact);
  TEST_ERR(ctx, fcm_scene_create_from_string(ctx, json, "c.json", &scene), FCM_ERR_ARG, want);
  fcm_scene_destroy(&scene);
}

/* A static scene: contact is accepted, and a ball beyond the floor's threshold is refused at
 * its first step as a free body, naming the contact. */
static void static_scene(fcm_ctx *ctx)
{
  static const char json[] =
      "{\"version\": 1, \"name\": \"c\","
      " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.4, -0.4, -0.4],"
      "   \"max\": [0.4, 0.4, 0.4]}, \"cells\": [4, 4, 4]},"
      " \"geometry\": {\"shape\": \"ball\", \"center\": [0, 0, 0], \"radius\": 0.35},"
      " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3},"
      " \"time\": {\"static\": true, \"steps\": 1},"
      " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
      "   {\"contact\": {\"plane\": {\"point\": [0, 0, -0.4], \"normal\": [0, 0, 1]},"
      "     \"distance\": 0.01}}]}";
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "c.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim) {
    fcm_step_info si;
    TEST_ERR(ctx, fcm_simulation_step(sim, &si), FCM_ERR_SINGULAR,
             "no surface point within a contact obstacle's threshold");
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

/* ball_off_wedge.json: outside the wedge and above the floor at every step, touching both. */
static void wedge(fcm_ctx *ctx, const char *dir)
{
  char path[1024];
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  snprintf(path, sizeof path, "%s/ball_off_wedge.json", dir);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  if (scene) check_normalized(ctx, scene, path);
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim) {
    fcm_integrator *I = fcm_simulation_integrator(sim);
    double dmin[2] = {HUGE_VAL, HUGE_VAL}, fbig[2] = {0, 0};
    while (!fcm_simulation_done(sim)) {
      fcm_step_info si;
      TEST_OK(ctx, fcm_simulation_step(sim, &si));
      if (fcm_ctx_error_status(ctx) != FCM_OK) break;
      for (int k = 0; k < 2; k++) {
        double F[3], d = 0.0;
        TEST_OK(ctx, fcm_integrator_contact_info(I, k, F, &d, NULL, NULL));
        dmin[k] = fmin(dmin[k], d);
        fbig[k] = fmax(fbig[k], sqrt(F[0] * F[0] + F[1] * F[1] + F[2] * F[2]));
      }
    }
    printf("ball_off_wedge: min distance to the wedge %.4g m, to the floor %.4g m; largest "
           "forces %.4g N and %.4g N\n",
           dmin[0], dmin[1], fbig[0], fbig[1]);
    fcm_simulation_counters c;
    fcm_simulation_get_counters(sim, &c);
    TEST_TRUE(c.contacts == 2 && c.friction_dissipation > 0.0); /* it rolls with friction */
    TEST_NEAR(c.contact_min_distance, fmin(dmin[0], dmin[1]), 1e-12, 0.0);
    for (int k = 0; k < 2; k++) {
      if (!(dmin[k] > 0.0)) TEST_FAIL_("obstacle %d: a surface point reached %.3g", k, dmin[k]);
      if (!(fbig[k] > 0.0)) TEST_FAIL_("obstacle %d: never touched", k);
    }
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  char path[1024];
  TEST_TRUE(argc > 1);
  if (argc < 2) return TEST_RESULT();
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  static_scene(ctx);
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
    /* the counters report the contact: evaluated, the smallest distance the one seen here */
    TEST_TRUE(c.contact_evaluations > 0 && c.contact_points_max > 0);
    TEST_NEAR(c.contact_min_distance, dmin_all, 1e-12, 0.0);
    TEST_TRUE(c.contact_energy_max > 0.0 && c.friction_dissipation == 0.0);
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
    /* a checkpoint keeps the contact columns: the restored run writes the same log */
    {
      char ck[1100], log2[1100];
      snprintf(ck, sizeof ck, "%s/run.fcmck", dir);
      snprintf(log2, sizeof log2, "%s/log2.csv", dir);
      fcm_simulation *back = NULL;
      TEST_OK(ctx, fcm_simulation_write_checkpoint(sim, ck));
      TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &back));
      if (back) TEST_OK(ctx, fcm_simulation_read_checkpoint(back, ck));
      if (back) TEST_OK(ctx, fcm_simulation_write_log(back, log2));
      FILE *a = fopen(log, "r"), *b = fopen(log2, "r");
      int same = a && b, ca = 0, cb = 0;
      while (same && (ca = fgetc(a)) != EOF && (cb = fgetc(b)) != EOF)
        same = ca == cb;
      if (same) same = ca == EOF && fgetc(b) == EOF;
      if (!same) TEST_FAIL_("the log restored from %s differs from the run's", ck);
      if (a) fclose(a);
      if (b) fclose(b);
      fcm_simulation_destroy(&back);
      remove(ck);
      remove(log2);
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
    /* the contact columns close the row: at rest on the floor, points within d^, a positive
     * barrier energy, no friction */
    TEST_TRUE(strstr(head, ",contact_points,contact_min_distance,contact_energy,"
                           "friction_dissipation\n") != NULL);
    {
      double tail[4] = {0, 0, 0, -1};
      char *q = last + strlen(last);
      for (int j = 3; j >= 0 && q > last; j--) {
        while (q > last && q[-1] != ',')
          q--;
        tail[j] = strtod(q, NULL);
        if (q > last) q--;
        *q = '\0';
      }
      TEST_TRUE(tail[0] > 0 && tail[1] > 0.0 && tail[2] > 0.0 && tail[3] == 0.0);
    }
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
  wedge(ctx, argv[1]);
  refused_parse(ctx, "\"sphere\": {\"center\": [0, 0, -1], \"radius\": -0.5}",
                "effects[0].contact.sphere.radius");
  refused_parse(ctx, "\"box\": {\"min\": [0, 0, -1], \"max\": [1, -1, 0]}",
                "effects[0].contact.box.max");
  refused_parse(ctx,
                "\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]},"
                " \"sphere\": {\"center\": [0, 0, -1], \"radius\": 0.5}",
                "expected exactly one obstacle");
  refused_parse(ctx, "\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]}, \"stiffness\": -1",
                "effects[0].contact.stiffness");
  refused_parse(ctx,
                "\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]}, \"friction\": -0.3",
                "effects[0].contact.friction");
  refused_parse(ctx,
                "\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]},"
                " \"friction_velocity\": -1",
                "effects[0].contact.friction_velocity");
  refused_parse(ctx,
                "\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]},"
                " \"friction_updates\": 21",
                "effects[0].contact.friction_updates");
  /* a body starting inside each kind */
  refused_setup(ctx, "\"sphere\": {\"center\": [0, 0, -0.6], \"radius\": 0.3}",
                "contact sphere 0: the body starts in penetration");
  refused_setup(ctx, "\"box\": {\"min\": [-1, -1, -1], \"max\": [1, 1, -0.3]}",
                "contact box 0: the body starts in penetration");
  {
    /* a closed and an open cube surface: the first reaches into the ball, the second lacks a
     * triangle */
    static const char cube[] = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                               "v -1 -1 -0.3\nv 1 -1 -0.3\nv 1 1 -0.3\nv -1 1 -0.3\n"
                               "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
                               "f 3 4 8\nf 3 8 7\nf 2 3 7\nf 2 7 6\nf 1 5 8\n";
    char dir[] = "/tmp/fcm_contact_XXXXXX", closed[1100], open[1100], contact[1300];
    TEST_TRUE(mkdtemp(dir) != NULL);
    snprintf(closed, sizeof closed, "%s/closed.obj", dir);
    snprintf(open, sizeof open, "%s/open.obj", dir);
    FILE *f = fopen(closed, "w"), *g = fopen(open, "w");
    TEST_TRUE(f && g);
    if (f) fprintf(f, "%sf 1 8 4\n", cube), fclose(f);
    if (g) fprintf(g, "%s", cube), fclose(g);
    snprintf(contact, sizeof contact, "\"surface\": {\"mesh\": \"%s\"}", closed);
    refused_setup(ctx, contact, "contact surface 0: the body starts in penetration");
    snprintf(contact, sizeof contact, "\"surface\": {\"mesh\": \"%s\"}", open);
    refused_setup(ctx, contact, "contact surface 0: not closed");
    remove(closed);
    remove(open);
    rmdir(dir);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
