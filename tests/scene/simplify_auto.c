/* quadrature.simplify: true, false and "auto" parse to ON, OFF and AUTO (bad values are
 * rejected in tests/scene/errors.c); with "auto" the run summary reports the choice per rule
 * kind with its inputs: a static scene expects 1 stiffness assembly per step and no mass
 * assembly (no mass rules are built); a dynamic one 3 stiffness assemblies per step and 1
 * mass assembly; with 300 steps the Hex8 stiffness rules of a ball pay back (break-even below
 * 1 assembly in `fcm-converge payoff`). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void scene_json(char *buf, size_t n, const char *simplify, int dynamic, int steps)
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
           "    \"normal\": [-1, 0, 0]}}}}]}",
           simplify, dynamic ? "false" : "true", steps);
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

  scene_json(json, sizeof json, "true", 1, 2);
  char *s = summary(ctx, json, FCM_CELL_SIMPLIFY_ON);
  TEST_TRUE(line_has(s, "computed  stiffness simplification", " on (scene), "));
  TEST_TRUE(line_has(s, "computed  mass simplification", " on (scene), "));
  free(s);
  scene_json(json, sizeof json, "false", 1, 2);
  s = summary(ctx, json, FCM_CELL_SIMPLIFY_OFF);
  TEST_TRUE(line_has(s, "skipped   stiffness simplification", " off (scene), "));
  TEST_TRUE(line_has(s, "skipped   mass simplification", " off (scene), "));
  free(s);

  /* static, 2 steps: 3 x 2 stiffness assemblies expected; no mass rules at all */
  scene_json(json, sizeof json, "\"auto\"", 0, 2);
  s = summary(ctx, json, FCM_CELL_SIMPLIFY_AUTO);
  TEST_TRUE(line_has(s, "stiffness simplification", " auto: "));
  TEST_TRUE(line_has(s, "stiffness simplification", " for 6 expected assemblies; "));
  TEST_TRUE(line_has(s, "skipped   mass simplification", "(no mass rules built)"));
  free(s);

  /* dynamic, 300 steps: 900 stiffness assemblies pay back; 1 mass assembly expected */
  scene_json(json, sizeof json, "\"auto\"", 1, 300);
  s = summary(ctx, json, FCM_CELL_SIMPLIFY_AUTO);
  TEST_TRUE(
      line_has(s, "computed  stiffness simplification", " auto: on for 900 expected assemblies; "));
  TEST_TRUE(line_has(s, "stiffness simplification", " core-s simplifying to "));
  TEST_TRUE(line_has(s, "mass simplification", " for 1 expected assemblies; "));
  TEST_TRUE(line_check(s, "mass simplification", "estimated 0 core-s assembling plain", 0));
  free(s);

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
