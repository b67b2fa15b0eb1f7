/* Boundary in dropped cells made visible: a box whose +x face lies 1e-6 h beyond a grid plane
 * leaves that face in cells below the default min_fraction. A traction on the whole boundary loses
 * that part: the counters hold the dropped area (the face and the eps-wide strips of the
 * side faces, in closed form) and the traction's share; the rules' phase end and the run
 * summary say so, naming quadrature.min_fraction. With the face 0.5 h beyond the plane nothing
 * is dropped and none of it appears. */
#include "scene_util.h"

#include <math.h>
#include <stdio.h>

/* The words of the cell rules' phase end. */
static void on_phase(const fcm_setup_phase_event *ev, void *user)
{
  if (ev->finished && ev->phase == FCM_SETUP_CELL_RULES)
    snprintf(user, 512, "%s", ev->what ? ev->what : "");
}

static char *summary_text(fcm_simulation *sim)
{
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  if (f) {
    fcm_simulation_summary_view(sim, f);
    fclose(f);
  }
  return text;
}

/* The scene with the body's +x face at x = xmax; its counters into *c, the rules' phase end
 * into words, the summary (malloc'ed) into *text. */
static void run(fcm_ctx *ctx, double xmax, fcm_simulation_counters *c, char words[512], char **text)
{
  char json[2048];
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  snprintf(json, sizeof json,
           "{\"version\": 1, \"name\": \"dropped\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           "   \"max\": [2, 1, 1]}, \"cells\": [2, 1, 1]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0.2, 0.2, 0.2],"
           "   \"max\": [%.17g, 0.8, 0.8]},"
           " \"material\": {\"model\": \"linear\", \"young\": 1e5, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"solver\": {\"threads\": 1}, \"time\": {\"static\": true, \"steps\": 1},"
           " \"effects\": [{\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.1, 0, 0],"
           "   \"normal\": [-1, 0, 0]}}}},"
           "  {\"traction\": {\"region\": {\"box\": {\"min\": [-1, -1, -1], \"max\": [3, 2, 2]}},"
           "   \"value\": [10, 0, 0]}}]}",
           xmax);
  memset(c, 0, sizeof *c);
  words[0] = '\0';
  *text = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "<dropped>", &scene));
  fcm_simulation_options o = fcm_simulation_options_default();
  o.setup_phase = on_phase;
  o.setup_phase_user = words;
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, &o, &sim));
  if (sim) {
    fcm_simulation_get_counters(sim, c);
    *text = summary_text(sim);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  fcm_simulation_counters c;
  char words[512], *text = NULL;
  const double eps = 1e-6, side = 0.6, face = side * side, strips = 4 * side * eps;
  run(ctx, 1 + eps, &c, words, &text);
  TEST_NEAR(c.dropped_area, face + strips, 1e-12, 0);
  TEST_NEAR(c.boundary_area, 2 * face + 4 * side * (0.8 + eps), 1e-12, 0);
  /* the traction acts on the whole boundary: it loses the dropped area's share */
  TEST_TRUE(c.effect_dropped_index == 1);
  TEST_NEAR(c.effect_dropped_fraction, (face + strips) / c.boundary_area, 1e-12, 0);
  TEST_TRUE(strstr(words, "of the boundary area") != NULL);
  TEST_TRUE(text && strstr(text, "in dropped cells (volume fraction below "
                                 "quadrature.min_fraction = 0.0001)") != NULL);
  TEST_TRUE(text && strstr(text, "effects[1] (traction) loses") != NULL);
  free(text);
  run(ctx, 1.5, &c, words, &text);
  TEST_TRUE(c.dropped_area == 0.0 && c.effect_dropped_fraction == 0.0 && c.boundary_area > 0.0);
  TEST_TRUE(words[0] != '\0' && strstr(words, "of the boundary area") == NULL);
  TEST_TRUE(text && strstr(text, "quadrature.min_fraction") == NULL);
  free(text);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
