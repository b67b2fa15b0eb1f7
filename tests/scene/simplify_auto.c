/* quadrature.simplify: true, false and "auto" parse to ON, OFF and AUTO (bad values are
 * rejected in tests/scene/errors.c); with "auto" the run summary reports the choice per rule
 * kind with its inputs, every pass over the points counted: stiffness 3 force + tangent
 * assemblies per step, one body-force assembly per gravity effect and space, and the stresses
 * of every frame (the first, then every frame_interval-th step and the last); mass (dynamic
 * only: a static scene builds no mass rules) the mass matrix and the log's mass blocks of each
 * space; every cut makes a new space. With 300 steps the Hex8 stiffness rules of a ball pay
 * back (break-even below 1 assembly in `fcm-converge payoff`). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void scene_json(char *buf, size_t n, const char *simplify, int dynamic, int steps,
                       const char *cut)
{
  snprintf(buf, n,
           "{\"version\": 1, \"name\": \"auto\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-1, -1, -1],"
           "   \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
           " \"geometry\": {\"shape\": \"ball\", \"center\": [0.05, 0.02, 0.01], \"radius\": 0.8,"
           "   \"resolution\": 2},"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"quadrature\": {\"simplify\": %s, \"mass_strength\": 3},"
           " \"time\": {\"static\": %s, \"steps\": %d, \"dt\": 0.01},"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
           "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [-0.5, 0, 0],"
           "    \"normal\": [-1, 0, 0]}}}}%s],"
           " \"output\": {\"frame_interval\": 4}}",
           simplify, dynamic ? "false" : "true", steps, cut);
}

/* The run summary after creating the simulation (no step taken). */
static char *summary(fcm_ctx *ctx, const char *json, fcm_cell_simplify expect)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  char *text = NULL;
  size_t len = 0;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "auto.json", &scene));
  if (!scene) return NULL;
  TEST_TRUE(fcm_scene_get_quadrature(scene)->rules.simplify == expect);
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  FILE *f = open_memstream(&text, &len);
  if (sim && f) fcm_simulation_summary_view(sim, f);
  if (f) fclose(f);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return text;
}

/* Whether the summary line holding `head` contains `what` (want 1) or not (want 0). */
static int line_check(const char *text, const char *head, const char *what, int want)
{
  const char *l = text ? strstr(text, head) : NULL;
  const char *e = l ? strchr(l, '\n') : NULL;
  int ok = 0;
  if (l && e) {
    char line[1024];
    const size_t n = (size_t)(e - l) < sizeof line - 1 ? (size_t)(e - l) : sizeof line - 1;
    memcpy(line, l, n);
    line[n] = '\0';
    ok = (strstr(line, what) != NULL) == want;
  }
  if (!ok)
    fprintf(stderr, "the line '%s' %s '%s' in the summary:\n%s", head, want ? "lacks" : "has", what,
            text ? text : "");
  return ok;
}

static int line_has(const char *text, const char *head, const char *what)
{
  return line_check(text, head, what, 1);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  char json[2048];
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));

  scene_json(json, sizeof json, "true", 1, 2, "");
  char *s = summary(ctx, json, FCM_CELL_SIMPLIFY_ON);
  TEST_TRUE(line_has(s, "computed  stiffness simplification", " on (scene), "));
  TEST_TRUE(line_has(s, "computed  mass simplification", " on (scene), "));
  free(s);
  scene_json(json, sizeof json, "false", 1, 2, "");
  s = summary(ctx, json, FCM_CELL_SIMPLIFY_OFF);
  TEST_TRUE(line_has(s, "skipped   stiffness simplification", " off (scene), "));
  TEST_TRUE(line_has(s, "skipped   mass simplification", " off (scene), "));
  free(s);

  /* static, 2 steps: 3 x 2 force + tangent, 1 body force, frames after steps 0 and 2; no mass
   * rules at all */
  scene_json(json, sizeof json, "\"auto\"", 0, 2, "");
  s = summary(ctx, json, FCM_CELL_SIMPLIFY_AUTO);
  TEST_TRUE(line_has(s, "stiffness simplification", " auto: "));
  TEST_TRUE(line_has(s, "stiffness simplification",
                     " for 9 expected passes (force + tangent 6, body forces 1, frames' "
                     "stresses 2) over "));
  TEST_TRUE(line_has(s, "skipped   mass simplification", "(no mass rules built)"));
  free(s);

  /* dynamic, 300 steps: 900 force + tangent, 1 body force, 76 frames (0, 4, ..., 300) pay
   * back; the mass matrix and the log's blocks once each */
  scene_json(json, sizeof json, "\"auto\"", 1, 300, "");
  s = summary(ctx, json, FCM_CELL_SIMPLIFY_AUTO);
  TEST_TRUE(line_has(s, "computed  stiffness simplification",
                     " auto: on for 977 expected passes (force + tangent 900, body forces 1, "
                     "frames' stresses 76) over "));
  TEST_TRUE(line_has(s, "mass simplification",
                     " for 2 expected passes (mass matrix 1, the log's mass blocks 1) over "));
  TEST_TRUE(line_check(s, "mass simplification", "estimated 0 core-s plain", 0));
  free(s);

  /* dynamic, 10 steps, two cuts: three spaces integrate the body forces, the mass matrix and
   * the log's mass blocks */
  scene_json(json, sizeof json, "\"auto\"", 1, 10,
             ", {\"cut\": {\"time\": 0.05, \"surface\": {\"plane\": {\"point\": [0.1, 0, 0], "
             "\"normal\": [1, 0, 0]}}}}, {\"cut\": {\"time\": 0.07, \"surface\": {\"plane\": "
             "{\"point\": [0, 0.2, 0], \"normal\": [0, 1, 0]}}}}");
  s = summary(ctx, json, FCM_CELL_SIMPLIFY_AUTO);
  TEST_TRUE(line_has(s, "stiffness simplification",
                     " for 37 expected passes (force + tangent 30, body forces 3, frames' "
                     "stresses 4) over "));
  TEST_TRUE(line_has(s, "mass simplification",
                     " for 6 expected passes (mass matrix 3, the log's mass blocks 3) over "));
  free(s);

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
