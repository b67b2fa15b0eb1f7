/* The built-in default scene is the example apps/scenes/twisting_cylinder.json byte for
 * byte (argv[1]: that file), parses from its string and from a file, is the twisting
 * cylinder it documents (Hex20, tube inside the grid, ends moved and twisted), and stays
 * small enough to run in well under a minute. */
#include "scene_util.h"

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  const char *json = fcm_scene_default_json();
  TEST_TRUE(json != NULL);
  if (argc > 1) {
    FILE *f = fopen(argv[1], "rb");
    TEST_TRUE(f != NULL);
    if (f) {
      static char file[1 << 16];
      size_t n = fread(file, 1, sizeof file - 1, f);
      fclose(f);
      file[n] = '\0';
      TEST_TRUE(n > 0 && n == strlen(json) && !strcmp(file, json));
    }
  } else {
    TEST_FAIL_("usage: %s apps/scenes/twisting_cylinder.json", argv[0]);
  }

  fcm_scene *a = NULL, *b = NULL;
  TEST_OK(ctx, fcm_scene_create_default(ctx, &a));
  char dir[64], path[128];
  if (make_temp_dir(dir, sizeof dir)) {
    snprintf(path, sizeof path, "%s/default.json", dir);
    TEST_TRUE(write_text(path, json) == 0);
    TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &b));
    TEST_TRUE(remove(path) == 0 && remove(dir) == 0);
  }
  if (a && b) {
    TEST_TRUE(!strcmp(fcm_scene_name(a), "twisting_cylinder") &&
              !strcmp(fcm_scene_name(b), "twisting_cylinder"));
    TEST_TRUE(!strcmp(fcm_scene_source(a), "<default>"));
    TEST_TRUE(fcm_scene_num_effects(a) == fcm_scene_num_effects(b));
    TEST_TRUE(fcm_scene_get_time(a)->num_steps == fcm_scene_get_time(b)->num_steps);

    const fcm_scene_background *bg = fcm_scene_get_background(a);
    const fcm_scene_geometry *g = fcm_scene_get_geometry(a);
    const fcm_scene_time *t = fcm_scene_get_time(a);
    TEST_TRUE(bg->kind == FCM_SCENE_BACKGROUND_GRID && bg->element == FCM_ELEMENT_HEX20);
    TEST_TRUE(g->kind == FCM_SCENE_GEOMETRY_TUBE && g->axis == 1);
    /* The tube lies inside the background box (radius across, length along y). */
    TEST_TRUE(g->outer_radius <= bg->max[0] && -g->outer_radius >= bg->min[0]);
    TEST_TRUE(g->outer_radius <= bg->max[2] && -g->outer_radius >= bg->min[2]);
    TEST_TRUE(g->length / 2 <= bg->max[1] && -g->length / 2 >= bg->min[1]);
    TEST_OK(ctx, fcm_material_validate(ctx, fcm_scene_get_material(a)));
    /* Small enough for a demo (lib/docs/performance.md): at most 150 background cells and
     * 250 steps. */
    TEST_TRUE(bg->cells[0] * bg->cells[1] * bg->cells[2] <= 150);
    TEST_TRUE(t->num_steps >= 10 && t->num_steps <= 250);
    /* One end pushed along the axis, the other twisted about it. */
    TEST_TRUE(fcm_scene_count_effects(a, FCM_EFFECT_MOTION) == 2);
    int pushed = 0, twisted = 0;
    for (int i = 0; i < fcm_scene_num_effects(a); i++) {
      const fcm_effect *e = fcm_scene_get_effect(a, i);
      if (e->type != FCM_EFFECT_MOTION) continue;
      pushed += e->motion.motion.velocity[1] != 0.0;
      twisted += e->motion.motion.angular_speed != 0.0 && e->motion.motion.axis[1] == 1.0;
      TEST_TRUE(e->motion.motion.end < t->duration);
    }
    TEST_TRUE(pushed == 1 && twisted == 1);

    FILE *f = tmpfile();
    TEST_TRUE(f != NULL);
    if (f) {
      fcm_scene_view(a, f);
      TEST_TRUE(ftell(f) > 200);
      fclose(f);
    }
  }
  fcm_scene_destroy(&a);
  fcm_scene_destroy(&b);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
