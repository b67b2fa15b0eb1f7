/* Scenes with geometry.surface and background.fit_background: parse errors of the new keys
 * (status, JSON path, message); a cube given as binary STL and an open cube as OBJ (with
 * fill_holes) built and stepped, the fitted grid around the body, the embedded volume equal
 * to the cube's; an open surface without fill_holes refused with its boundary edges. Without a
 * cut the surface alone is the geometry (volume_mesh auto, no Gmsh needed): every cut cell's
 * rules come from the surface moments, none falls back, and the summary says so (and times the
 * set-up's phases and a step's parts, each positive, together within the whole); with
 * "volume_mesh": true the cells are tets; a bad volume_mesh value is refused. */
#include "scene_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>

/* The cube [0,1]^3 shifted by `shift`: 12 outward triangles. */
static const double cube_x[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
static const int cube_t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                             3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
static const double shift[3] = {0.25, 0.375, 0.5}; /* exact in float (STL) */

static int write_stl(const char *path)
{
  unsigned char buf[84 + 50 * 12];
  memset(buf, 0, sizeof buf);
  uint32_t n = 12;
  memcpy(buf + 80, &n, 4); /* little-endian hosts only (x86, arm64) */
  for (int t = 0; t < 12; t++) {
    unsigned char *f = buf + 84 + 50 * t;
    for (int k = 0; k < 3; k++)
      for (int d = 0; d < 3; d++) {
        float v = (float)(cube_x[3 * cube_t[3 * t + k] + d] + shift[d]);
        memcpy(f + 12 + 12 * k + 4 * d, &v, 4);
      }
  }
  return write_bytes(path, (const char *)buf, sizeof buf);
}

/* OBJ of the cube without its top face (triangles 2, 3). */
static int write_open_obj(const char *path)
{
  char text[1024];
  size_t n = 0;
  for (int v = 0; v < 8; v++)
    n += (size_t)snprintf(text + n, sizeof text - n, "v %g %g %g\n", cube_x[3 * v] + shift[0],
                          cube_x[3 * v + 1] + shift[1], cube_x[3 * v + 2] + shift[2]);
  for (int t = 0; t < 12; t++)
    if (t != 2 && t != 3)
      n += (size_t)snprintf(text + n, sizeof text - n, "f %d %d %d\n", cube_t[3 * t] + 1,
                            cube_t[3 * t + 1] + 1, cube_t[3 * t + 2] + 1);
  return write_text(path, text);
}

static void scene_text(char *buf, size_t n, const char *background, const char *geometry)
{
  snprintf(buf, n,
           "{\"version\": 1, \"name\": \"surf\", \"background\": %s, \"geometry\": %s,"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"time\": {\"dt\": 0.01, \"steps\": 2},"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
           "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0.5],"
           "   \"normal\": [0, 0, -1]}}}}]}",
           background, geometry);
}

static const char fit_bg[] =
    "{\"element\": \"hex8\", \"fit_background\": {\"cell_size\": 0.25, \"margin\": 0.1}}";

/* Parse `json` (as dir/scene.json) and expect `code` with `text` in the message. */
static void parse_error(fcm_ctx *ctx, const char *dir, const char *json, fcm_status code,
                        const char *text)
{
  char path[512];
  fcm_scene *s = NULL;
  snprintf(path, sizeof path, "%s/scene.json", dir);
  TEST_TRUE(write_text(path, json) == 0);
  TEST_ERR(ctx, fcm_scene_create_from_file(ctx, path, &s), code, text);
  TEST_TRUE(s == NULL);
}

/* Build a simulation from dir/scene.json, take 2 steps; returns it (NULL on failure). */
static fcm_simulation *build(fcm_ctx *ctx, const char *dir, const char *json, fcm_scene **scene)
{
  char path[512];
  fcm_simulation *sim = NULL;
  snprintf(path, sizeof path, "%s/scene.json", dir);
  TEST_TRUE(write_text(path, json) == 0);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, scene));
  if (!*scene) return NULL;
  TEST_OK(ctx, fcm_simulation_create(ctx, *scene, NULL, &sim));
  for (int k = 0; sim && k < 2; k++) {
    fcm_step_info si;
    TEST_OK(ctx, fcm_simulation_step(sim, &si));
  }
  if (sim) TEST_TRUE(fcm_simulation_state_finite(sim));
  return sim;
}

/* The fitted grid: cubes of 0.25 over the shifted unit cube grown by 0.1 on each side:
 * 1.2 / 0.25 -> 5 cells per axis, centred on the cube: [-0.075, 1.175] + shift. */
static void check_fitted(const fcm_simulation *sim)
{
  const fcm_space *space = fcm_simulation_space(sim);
  const fcm_mesh *mesh = fcm_space_mesh(space);
  double lo[3], hi[3];
  fcm_mesh_bounding_box(mesh, lo, hi);
  TEST_TRUE(fcm_mesh_num_cells(mesh) == 125);
  for (int d = 0; d < 3; d++) {
    TEST_NEAR(lo[d], shift[d] + 0.5 - 0.625, 0, 1e-12);
    TEST_NEAR(hi[d], shift[d] + 0.5 + 0.625, 0, 1e-12);
  }
  const fcm_cell_rules_stats *st = fcm_cell_rules_get_stats(fcm_space_cell_rules(space));
  TEST_NEAR(st->geometry_volume, 1.0, 1e-12, 0);
  TEST_NEAR(st->embedded_volume, 1.0, 1e-10, 0);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  char dir[64], path[512], json[4096];
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  if (!make_temp_dir(dir, sizeof dir)) return 1;
  snprintf(path, sizeof path, "%s/cube.stl", dir);
  TEST_TRUE(write_stl(path) == 0);
  snprintf(path, sizeof path, "%s/open.obj", dir);
  TEST_TRUE(write_open_obj(path) == 0);
  snprintf(path, sizeof path, "%s/model.xyz", dir);
  TEST_TRUE(write_text(path, "1 2 3\n") == 0);

  /* parse errors of the new keys */
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"missing.obj\"}");
  parse_error(ctx, dir, json, FCM_ERR_IO, "geometry.surface: cannot open");
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"model.xyz\"}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "geometry.surface: expected a file ending in .obj");
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"shape\": \"box\"}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "expected exactly one of");
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"radius\": 1}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "geometry.radius");
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"max_volume\": -1}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "geometry.max_volume");
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"quality\": 1.5}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "geometry.quality");
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"volume_mesh\": 2}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "geometry.volume_mesh");
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"fill_holes\": 1}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "geometry.fill_holes");
  scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"max_hole_edges\": 10}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "geometry.max_hole_edges: only used with");
  scene_text(json, sizeof json,
             "{\"element\": \"hex8\", \"fit_background\": {\"cell_size\": 0.25},"
             " \"cells\": [2, 2, 2]}",
             "{\"surface\": \"cube.stl\"}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "background.cells: not allowed with \"fit_background\"");
  scene_text(json, sizeof json,
             "{\"element\": \"hex8\", \"fit_background\": {\"cell_size\": 0.25},"
             " \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}}",
             "{\"surface\": \"cube.stl\"}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "background.box: not allowed with \"fit_background\"");
  scene_text(json, sizeof json, "{\"element\": \"hex8\", \"fit_background\": {\"cell_size\": 0}}",
             "{\"surface\": \"cube.stl\"}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "background.fit_background.cell_size");
  scene_text(json, sizeof json,
             "{\"element\": \"hex8\", \"fit_background\": {\"cell_size\": 1, \"margin\": -1}}",
             "{\"surface\": \"cube.stl\"}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "background.fit_background.margin");
  scene_text(json, sizeof json, "{\"element\": \"hex8\", \"fit_background\": {\"size\": 1}}",
             "{\"surface\": \"cube.stl\"}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "background.fit_background");
  scene_text(json, sizeof json, "{\"fit_background\": {\"cell_size\": 1}}",
             "{\"surface\": \"cube.stl\"}");
  parse_error(ctx, dir, json, FCM_ERR_ARG, "background.element");
  snprintf(json, sizeof json,
           "{\"version\": 1, \"name\": \"surf\", \"background\": %s,"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3,"
           "   \"density\": 1000}, \"time\": {\"dt\": 0.01, \"steps\": 2},"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}]}",
           fit_bg);
  parse_error(ctx, dir, json, FCM_ERR_ARG,
              "background.fit_background: needs an embedded \"geometry\"");

  {
    /* the surface alone (no cut: volume_mesh auto), no Gmsh needed */
    fcm_scene *scene = NULL;
    fcm_simulation *sim = NULL;
    scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\"}");
    sim = build(ctx, dir, json, &scene);
    if (sim) {
      check_fitted(sim);
      const fcm_space *space = fcm_simulation_space(sim);
      const fcm_cell_rules_stats *st = fcm_cell_rules_get_stats(fcm_space_cell_rules(space));
      TEST_TRUE(st->num_cut > 0 && st->num_surface_cells == st->num_cut &&
                st->num_surface_fallbacks == 0);
      /* the set-up's phases: each timed, together within the set-up's time */
      fcm_simulation_counters c;
      fcm_simulation_get_counters(sim, &c);
      TEST_TRUE(c.time_setup_geometry > 0.0 && c.time_setup_rules > 0.0 &&
                c.time_setup_space > 0.0 && c.time_setup_integrator > 0.0);
      TEST_TRUE(c.time_setup_geometry + c.time_setup_rules + c.time_setup_space +
                    c.time_setup_integrator <=
                c.time_setup);
      /* the steps' parts (check_fitted took them): assembly, factorization and solves, each
       * timed, within the steps' time */
      TEST_TRUE(c.time_step_assembly > 0.0 && c.time_step_factor > 0.0 && c.time_step_solve > 0.0);
      TEST_TRUE(c.time_step_assembly + c.time_step_factor + c.time_step_solve <= c.time_steps);
      char *text = NULL;
      size_t len = 0;
      FILE *mf = open_memstream(&text, &len);
      TEST_TRUE(mf != NULL);
      if (mf) {
        fcm_simulation_summary_view(sim, mf);
        fclose(mf);
        TEST_TRUE(text && strstr(text, "cut cells from the boundary surface") &&
                  strstr(text, "0 of them fell back") && strstr(text, "set-up    [s] mesh") &&
                  strstr(text, "step      [s]") && strstr(text, "each: assembly") &&
                  strstr(text, "cells of the surface path are fitted either way"));
        free(text);
      }
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  }

  if (fcm_surface_meshing_available()) {
    fcm_scene *scene = NULL;
    fcm_simulation *sim = NULL;
    /* with a volume mesh: tets, and the same grid and volume */
    scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"volume_mesh\": true}");
    sim = build(ctx, dir, json, &scene);
    if (sim) check_fitted(sim);
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
    /* binary STL cube, fitted grid */
    scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\", \"max_volume\": 0.01}");
    sim = build(ctx, dir, json, &scene);
    if (sim) check_fitted(sim);
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
    /* open OBJ: refused without fill_holes, naming the boundary edges */
    char spath[512];
    snprintf(spath, sizeof spath, "%s/scene.json", dir);
    scene_text(json, sizeof json, fit_bg, "{\"surface\": \"open.obj\"}");
    TEST_TRUE(write_text(spath, json) == 0);
    TEST_OK(ctx, fcm_scene_create_from_file(ctx, spath, &scene));
    TEST_ERR(ctx, fcm_simulation_create(ctx, scene, NULL, &sim), FCM_ERR_GEOMETRY,
             "not closed: 4 boundary edges");
    TEST_TRUE(sim == NULL);
    fcm_scene_destroy(&scene);
    /* with fill_holes: built, the same grid and volume */
    scene_text(json, sizeof json, fit_bg, "{\"surface\": \"open.obj\", \"fill_holes\": true}");
    sim = build(ctx, dir, json, &scene);
    if (sim) check_fitted(sim);
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  } else {
    fcm_scene *scene = NULL;
    fcm_simulation *sim = NULL;
    char spath[512];
    snprintf(spath, sizeof spath, "%s/scene.json", dir);
    scene_text(json, sizeof json, fit_bg, "{\"surface\": \"cube.stl\"}");
    TEST_TRUE(write_text(spath, json) == 0);
    TEST_OK(ctx, fcm_scene_create_from_file(ctx, spath, &scene));
    TEST_ERR(ctx, fcm_simulation_create(ctx, scene, NULL, &sim), FCM_ERR_UNSUPPORTED,
             "built without Gmsh");
    fcm_scene_destroy(&scene);
  }

  const char *const files[] = {"cube.stl", "open.obj", "model.xyz", "scene.json"};
  remove_temp_dir(dir, files, 4);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
