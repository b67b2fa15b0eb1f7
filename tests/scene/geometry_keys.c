/* The geometry keys "voxels" and "level_set": an implicit tree parses into nodes with their
 * operands and defaults (CSG arrays fold left), the sampling box defaults to the background
 * grid, voxel options (labels, merge) are kept; bad input fails naming the JSON path (nested
 * operands included) and the valid range; implicit features below the sampling spacing are
 * refused while parsing, naming the key, the value and the spacing; max_subcells is kept and
 * a build above it stops naming it; a scene with each geometry builds and the
 * embedded volume equals what the geometry reports. */
#include "scene_util.h"

#include "fcm/simulation.h"

#define BG                                                                                         \
  "\"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, "    \
  "\"cells\": [4, 4, 4]}"
#define REST                                                                                       \
  "\"material\": {\"young\": 1e6, \"poisson\": 0.3}, \"output\": {\"directory\": \"out\"}, "       \
  "\"time\": {\"static\": true, \"steps\": 1}, \"effects\": [{\"gravity\": {}}]"

static fcm_scene *parse(fcm_ctx *ctx, const char *geometry, fcm_status expect, const char *msg)
{
  char text[4096];
  fcm_scene *s = NULL;
  snprintf(text, sizeof text, "{" BG ", \"geometry\": %s, " REST "}", geometry);
  if (expect == FCM_OK) {
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, text, "t.json", &s));
    if (s) check_normalized(ctx, s, geometry); /* every geometry kind round-trips */
  } else
    TEST_ERR(ctx, fcm_scene_create_from_string(ctx, text, "t.json", &s), expect, msg);
  return s;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  char dir[256];
  if (!enter_temp_dir(dir, sizeof dir)) return TEST_RESULT();

  /* ((a ∪ b ∪ c) − d): sphere, torus, gyroid, box */
  fcm_scene *s = parse(ctx,
                       "{\"level_set\": {\"difference\": [{\"union\": ["
                       "{\"sphere\": {\"center\": [0.5, 0.5, 0.5], \"radius\": 0.3}},"
                       "{\"torus\": {\"major_radius\": 0.3, \"minor_radius\": 0.1, \"axis\": "
                       "\"x\"}},"
                       "{\"gyroid\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1], \"period\": 0.5}}]},"
                       "{\"box\": {\"min\": [0.4, 0.4, 0.4], \"max\": [0.6, 0.6, 0.6]}}]}, "
                       "\"refinement\": 3}",
                       FCM_OK, NULL);
  if (s) {
    const fcm_scene_geometry *g = fcm_scene_get_geometry(s);
    TEST_TRUE(g->kind == FCM_SCENE_GEOMETRY_LEVEL_SET && g->num_implicit == 7);
    TEST_TRUE(g->refinement == 3 && !g->has_box && g->cells[0] == 4 && g->max[2] == 1);
    const fcm_implicit *q = g->implicit;
    if (g->num_implicit == 7) {
      TEST_TRUE(q[0].kind == FCM_IMPLICIT_SPHERE && q[0].radius == 0.3 && q[0].center[1] == 0.5);
      TEST_TRUE(q[1].kind == FCM_IMPLICIT_TORUS && q[1].axis == 0 && q[1].minor_radius == 0.1);
      TEST_TRUE(q[2].kind == FCM_IMPLICIT_UNION && q[2].a == 0 && q[2].b == 1);
      TEST_TRUE(q[3].kind == FCM_IMPLICIT_GYROID && q[3].sheet == 1 && q[3].thickness == 0.05);
      TEST_TRUE(q[4].kind == FCM_IMPLICIT_UNION && q[4].a == 2 && q[4].b == 3);
      TEST_TRUE(q[5].kind == FCM_IMPLICIT_BOX && q[5].max[0] == 0.6);
      TEST_TRUE(q[6].kind == FCM_IMPLICIT_DIFFERENCE && q[6].a == 4 && q[6].b == 5);
      fcm_implicit_tree t = {7, q};
      TEST_OK(ctx, fcm_implicit_check(ctx, &t));
      const double centre[3] = {0.5, 0.5, 0.5}, shell[3] = {0.5, 0.5, 0.75};
      TEST_TRUE(fcm_implicit_eval(centre, &t) > 0); /* the box is removed */
      TEST_TRUE(fcm_implicit_eval(shell, &t) < 0);  /* in the sphere */
    }
    fcm_scene_destroy(&s);
  }
  /* a level set and a voxel body build; the embedded volume is the geometry's */
  write_text("v.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\n"
                       "spacings: 0.25 0.25 0.25\nspace origin: (0.375,0.375,0.375)\n"
                       "encoding: ascii\n\n1 2 2 1 0 1 2 2\n");
  const char *built[2] = {"{\"level_set\": {\"sphere\": {\"center\": [0.5, 0.5, 0.5], "
                          "\"radius\": 0.35}}, \"refinement\": 2}",
                          "{\"voxels\": \"v.nrrd\", \"labels\": [2, 1], \"merge\": false}"};
  for (int k = 0; k < 2; k++) {
    s = parse(ctx, built[k], FCM_OK, NULL);
    fcm_simulation *sim = NULL;
    if (s) TEST_OK(ctx, fcm_simulation_create(ctx, s, NULL, &sim));
    if (sim) {
      const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(fcm_simulation_cell_rules(sim));
      TEST_NEAR(S->embedded_volume, S->geometry_volume, 1e-12, 0);
      if (k == 1) TEST_NEAR(S->geometry_volume, 7 * 0.25 * 0.25 * 0.25, 1e-14, 0);
      if (k == 0) TEST_NEAR(S->geometry_volume, 4.0 / 3 * 3.14159265 * 0.042875, 0.1, 0);
    }
    if (k == 1 && s) {
      const fcm_scene_geometry *g = fcm_scene_get_geometry(s);
      TEST_TRUE(g->num_labels == 2 && g->labels[0] == 2 && g->merge == 0);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&s);
  }

  /* errors, with their JSON paths */
  parse(ctx, "{\"level_set\": {\"cone\": {}}}", FCM_ERR_ARG,
        "geometry.level_set: unknown implicit \"cone\"");
  parse(ctx, "{\"level_set\": {\"union\": [{\"sphere\": {\"radius\": 1}}]}}", FCM_ERR_ARG,
        "geometry.level_set.union: expected an array of at least 2 implicits");
  parse(ctx,
        "{\"level_set\": {\"difference\": [{\"sphere\": {\"radius\": 1}}, "
        "{\"sphere\": {\"radius\": -1}}]}}",
        FCM_ERR_ARG, "geometry.level_set.difference[1].sphere.radius");
  parse(ctx, "{\"level_set\": {\"torus\": {\"major_radius\": 1, \"minor_radius\": 2}}}",
        FCM_ERR_ARG, "geometry.level_set.torus.minor_radius");
  parse(ctx, "{\"level_set\": {\"sphere\": {\"radius\": 1, \"centre\": [0, 0, 0]}}}", FCM_ERR_ARG,
        "centre");
  parse(ctx,
        "{\"level_set\": {\"gyroid\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1], \"period\": 0.4, "
        "\"thickness\": 0.2}}}",
        FCM_ERR_ARG, "geometry.level_set.gyroid.thickness");
  parse(ctx, "{\"level_set\": {\"sphere\": {\"radius\": 1}}, \"min\": [0, 0, 0]}", FCM_ERR_ARG,
        "needs all of \"min\", \"max\" and \"cells\"");
  parse(ctx, "{\"level_set\": {\"sphere\": {\"radius\": 1}}, \"transform\": {\"scale\": 2}}",
        FCM_ERR_ARG, "give \"min\", \"max\" and \"cells\"");
  parse(ctx, "{\"level_set\": {\"sphere\": {\"radius\": 1}}, \"refinement\": 0}", FCM_ERR_ARG,
        "geometry.refinement");
  /* features below the sampling spacing (here h = 1 / (4 x 4) = 0.0625), named by their
   * JSON path, refused while parsing; the spacing follows the refinement and the box */
  parse(ctx,
        "{\"level_set\": {\"union\": [{\"sphere\": {\"radius\": 0.5}}, {\"torus\": "
        "{\"major_radius\": 0.3, \"minor_radius\": 0.05}}]}, \"refinement\": 4}",
        FCM_ERR_ARG,
        "geometry.level_set.union[1].torus.minor_radius: minor_radius = 0.05 is below the "
        "sampling spacing h = 0.0625");
  parse(ctx,
        "{\"level_set\": {\"gyroid\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1], \"period\": 1e-9, "
        "\"type\": \"solid\"}}, \"refinement\": 64}",
        FCM_ERR_ARG,
        "geometry.level_set.gyroid.period: period = 1e-09 is below twice the sampling spacing "
        "h = 0.00390625");
  parse(ctx,
        "{\"level_set\": {\"gyroid\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1], \"period\": 0.5, "
        "\"thickness\": 0.02}}, \"refinement\": 3}",
        FCM_ERR_ARG, "geometry.level_set.gyroid.thickness: thickness = 0.02 is below half the");
  parse(ctx,
        "{\"level_set\": {\"difference\": [{\"sphere\": {\"radius\": 0.5}}, {\"box\": "
        "{\"min\": [0, 0, 0], \"max\": [1, 0.01, 1]}}]}}",
        FCM_ERR_ARG,
        "geometry.level_set.difference[1].box: the side max[1] - min[1] = 0.01 is below the "
        "sampling spacing h = 0.0625");
  s = parse(ctx,
            "{\"level_set\": {\"sphere\": {\"radius\": 0.06}}, \"refinement\": 3, \"min\": [0, 0, "
            "0], \"max\": [0.5, 0.5, 0.5], \"cells\": [3, 3, 3]}",
            FCM_OK, NULL); /* h = 0.5 / 9 < 0.06 on its own box (0.083 on the background) */
  if (s) TEST_TRUE(fcm_scene_get_geometry(s)->max_subcells == FCM_LEVEL_SET_MAX_SUBCELLS);
  fcm_scene_destroy(&s);
  /* max_subcells: kept, 0 allowed, negative refused; a build above it stops naming it */
  s = parse(ctx,
            "{\"level_set\": {\"sphere\": {\"center\": [0.5, 0.5, 0.5], \"radius\": 0.3}}, "
            "\"max_subcells\": 0}",
            FCM_OK, NULL);
  if (s) TEST_TRUE(fcm_scene_get_geometry(s)->max_subcells == 0);
  fcm_scene_destroy(&s);
  parse(ctx, "{\"level_set\": {\"sphere\": {\"radius\": 1}}, \"max_subcells\": -1}", FCM_ERR_ARG,
        "geometry.max_subcells");
  parse(ctx, "{\"voxels\": \"v.nrrd\", \"max_subcells\": 10}", FCM_ERR_ARG, "max_subcells");
  s = parse(ctx,
            "{\"level_set\": {\"sphere\": {\"center\": [0.5, 0.5, 0.5], \"radius\": 0.3}}, "
            "\"max_subcells\": 5}",
            FCM_OK, NULL);
  if (s) {
    fcm_simulation *sim = NULL;
    TEST_ERR(ctx, fcm_simulation_create(ctx, s, NULL, &sim), FCM_ERR_UNSUPPORTED,
             "geometry.level_set: level set: the build would triangulate");
    TEST_TRUE(sim == NULL);
  }
  fcm_scene_destroy(&s);
  parse(ctx, "{\"voxels\": \"v.nrrd\", \"labels\": [1], \"threshold\": 2}", FCM_ERR_ARG,
        "either \"labels\" or \"threshold\"");
  parse(ctx, "{\"voxels\": \"missing.nrrd\"}", FCM_ERR_IO, "missing.nrrd");
  parse(ctx, "{\"voxels\": \"v.nrrd\", \"refinement\": 2}", FCM_ERR_ARG, "refinement");
  parse(ctx, "{\"voxels\": \"v.nrrd\", \"level_set\": {}}", FCM_ERR_ARG, "exactly one of");
  /* with fit_background the level set needs its own sampling box; given one, it builds */
  {
#define FIT_HEAD                                                                                   \
  "{\"background\": {\"element\": \"hex8\", \"fit_background\": {\"cell_size\": 0.25}}, "          \
  "\"geometry\": {\"level_set\": {\"sphere\": {\"radius\": 0.5}}"
    TEST_ERR(ctx, fcm_scene_create_from_string(ctx, FIT_HEAD "}, " REST "}", "t.json", &s),
             FCM_ERR_ARG, "not fit_background");
    TEST_OK(ctx, fcm_scene_create_from_string(ctx,
                                              FIT_HEAD ", \"min\": [-1, -1, -1], \"max\": [1, 1, "
                                                       "1], \"cells\": [4, 4, 4]}, " REST "}",
                                              "t.json", &s));
#undef FIT_HEAD
    fcm_simulation *sim = NULL;
    if (s) TEST_OK(ctx, fcm_simulation_create(ctx, s, NULL, &sim));
    if (sim) {
      const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(fcm_simulation_cell_rules(sim));
      TEST_TRUE(S->outside_volume == 0.0 && S->embedded_volume > 0.4);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&s);
  }
  remove("v.nrrd");
  TEST_TRUE(chdir("/") == 0 && rmdir(dir) == 0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
