/* The scene runner builds only the rule kinds a scene calls for: a static embedded scene
 * builds stiffness (and surface, with a traction) rules but no mass rules: zero mass points
 * in the statistics, the counter and the summary say so, the log's mass is still the body's;
 * the same scene run dynamically builds mass rules and assembles the mass matrix. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A box [0, 0.9] x [0, 0.5]^2 embedded in a 3 x 1 x 1 grid over [0, 1.5] x [0, 0.5]^2 (cut
 * cells at x = 0.9), clamped at x = 0, gravity and a traction on its end face. */
static void scene_json(char *buf, size_t n, int dynamic)
{
  snprintf(buf, n,
           "{\"version\": 1, \"name\": \"kinds\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.9, 0.5, 0.5],"
           "   \"cells\": [3, 1, 1]},"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"solver\": {\"method\": \"direct\"},"
           " \"time\": {%s},"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
           "  {\"traction\": {\"region\": {\"half_space\": {\"point\": [0.85, 0, 0],"
           "    \"normal\": [1, 0, 0]}}, \"value\": [0, 0, -10]}},"
           "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"
           "    \"normal\": [-1, 0, 0]}}}}]}",
           dynamic ? "\"dt\": 0.01, \"steps\": 2" : "\"static\": true, \"steps\": 1");
}

static void run(fcm_ctx *ctx, int dynamic)
{
  char json[2048], summary[8192] = "";
  scene_json(json, sizeof json, dynamic);
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "kinds.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  while (!fcm_simulation_done(sim)) {
    fcm_step_info si;
    fcm_status st = fcm_simulation_step(sim, &si);
    TEST_OK(ctx, st);
    if (st != FCM_OK) goto done;
  }
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  const fcm_cell_rules *r = fcm_simulation_cell_rules(sim);
  TEST_TRUE(r != NULL);
  if (!r) goto done;
  const fcm_cell_rules_stats *s = fcm_cell_rules_get_stats(r);
  TEST_TRUE(s->num_cut > 0);
  TEST_TRUE(s->points_total[FCM_RULE_STIFFNESS] > 0 && s->surface_points > 0);
  TEST_TRUE(c.cell_rules == 1 && c.surface_rules == 1);
  if (dynamic) {
    TEST_TRUE(c.rule_kinds == FCM_RULES_ALL && s->kinds == FCM_RULES_ALL);
    TEST_TRUE(s->points_total[FCM_RULE_MASS] > 0 && s->points_initial[FCM_RULE_MASS] > 0);
    TEST_TRUE(c.mass_assemblies == 1);
  } else {
    TEST_TRUE(c.rule_kinds == FCM_RULES_STIFFNESS && s->kinds == FCM_RULES_STIFFNESS);
    TEST_TRUE(s->points_total[FCM_RULE_MASS] == 0 && s->points_initial[FCM_RULE_MASS] == 0);
    TEST_TRUE(!fcm_cell_rules_has_kind(r, FCM_RULE_MASS));
    TEST_TRUE(c.mass_assemblies == 0);
  }
  /* the summary names what was built */
  FILE *f = tmpfile();
  TEST_TRUE(f != NULL);
  if (f) {
    fcm_simulation_summary_view(sim, f);
    rewind(f);
    size_t got = fread(summary, 1, sizeof summary - 1, f);
    summary[got] = '\0';
    fclose(f);
  }
  TEST_TRUE(strstr(summary, "rules built") != NULL);
  TEST_TRUE(strstr(summary, "surface (") != NULL);
  if (dynamic)
    TEST_TRUE(strstr(summary, ", mass (") != NULL && !strstr(summary, "mass: not needed"));
  else
    TEST_TRUE(strstr(summary, "mass: not needed (static scene)") != NULL);
  if (test_failures_) fputs(summary, stderr);
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

/* The log's mass in a static scene (no mass rules: density x piece volumes) equals the mass
 * the dynamic scene integrates with its mass rules: 1000 x 0.9 x 0.5 x 0.5. */
static void log_mass(fcm_ctx *ctx, int dynamic, double *mass)
{
  char json[2048], path[] = "/tmp/fcm_rule_kinds_XXXXXX";
  scene_json(json, sizeof json, dynamic);
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  *mass = -1.0;
  int fd = mkstemp(path);
  TEST_TRUE(fd >= 0);
  if (fd < 0) return;
  close(fd);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "kinds.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim) TEST_OK(ctx, fcm_simulation_step(sim, NULL));
  if (sim) TEST_OK(ctx, fcm_simulation_write_log(sim, path));
  FILE *f = fopen(path, "r");
  char line[4096];
  if (f && fgets(line, sizeof line, f)) { /* header: find the mass column */
    int col = -1, i = 0;
    for (char *t = strtok(line, ",\n"); t; t = strtok(NULL, ",\n"), i++)
      if (!strcmp(t, "mass")) col = i;
    TEST_TRUE(col >= 0);
    if (col >= 0 && fgets(line, sizeof line, f)) {
      i = 0;
      for (char *t = strtok(line, ",\n"); t; t = strtok(NULL, ",\n"), i++)
        if (i == col) *mass = strtod(t, NULL);
    }
  }
  if (f) fclose(f);
  remove(path);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  run(ctx, 0);
  run(ctx, 1);
  double ms, md;
  log_mass(ctx, 0, &ms);
  log_mass(ctx, 1, &md);
  TEST_NEAR(ms, 1000.0 * 0.9 * 0.5 * 0.5, 1e-12, 0.0);
  TEST_NEAR(md, 1000.0 * 0.9 * 0.5 * 0.5, 1e-12, 0.0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
