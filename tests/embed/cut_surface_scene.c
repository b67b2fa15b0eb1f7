/* A scene that cuts a body given as a surface file (a faceted ball, OBJ) runs without a volume
 * mesh: with "volume_mesh" "auto" the set-up skips Gmsh (its phase takes no time), the cut
 * cells' pieces are fitted on surface moments, and after a tilted plane cut and three steps
 * under gravity the DOFs, the centre of mass and the largest displacement equal those of the
 * volume path ("volume_mesh": true, "moments": "volume", when fcm has Gmsh) to CTOL and UTOL.
 * On both paths a blade in the air beside the ball, in cells the ball's surface crosses, then
 * misses: the run keeps its rules and integrator (the surface path's cut faces end at the
 * body, so the blade gives the pieces none). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/scene.h"
#include "fcm/simulation.h"
#include "fcm/surface.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The centre of mass is an exact integral of the state (rules exact for the integrands of
 * degree <= 4 and 6 set below): 1e-12 of the body's size. The largest displacement of a node
 * differs by what the paths' rules differ in beyond those degrees: 0.17 % here, 0.34 % for the
 * same scene without the cut (the set-up's surface and volume paths): 1 %. */
#define CTOL 1e-12
#define UTOL 1e-2

static fcm_ctx *ctx;

/* The boundary of fcm_geometry_create_ball(n = 2) as an OBJ file. */
static int write_ball(const char *path)
{
  const double c[3] = {0, 0, 0};
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 1.0, 2, &g));
  if (!g) return -1;
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  const double *x = fcm_geometry_coords(g);
  const fcm_index *t = fcm_geometry_boundary_triangles(g);
  for (fcm_index v = 0; v < fcm_geometry_num_nodes(g); v++)
    fprintf(f, "v %.17g %.17g %.17g\n", x[3 * v], x[3 * v + 1], x[3 * v + 2]);
  for (fcm_index k = 0; k < fcm_geometry_num_boundary_triangles(g); k++)
    fprintf(f, "f %lld %lld %lld\n", (long long)t[3 * k] + 1, (long long)t[3 * k + 1] + 1,
            (long long)t[3 * k + 2] + 1);
  fclose(f);
  fcm_geometry_destroy(&g);
  return 0;
}

/* Run the scene with the given geometry and quadrature members: 3 steps; the largest
 * displacement, the centre of mass and whether Gmsh ran. */
static int run(const char *dir, const char *geometry, const char *quadrature, double *umax,
               double com[3], int *meshed, int *surface_cells, fcm_index *dofs)
{
  char json[2048], path[600];
  snprintf(
      json, sizeof json,
      "{\"version\": 1, \"name\": \"cutsurf\", \"background\": {\"element\": \"hex8\","
      " \"box\": {\"min\": [-1.1, -1.1, -1.1], \"max\": [1.1, 1.1, 1.1]}, \"cells\": [5, 5, 5]},"
      " \"geometry\": {\"surface\": \"%s/ball.obj\"%s}, \"quadrature\": {\"stiffness_strength\": "
      "4, \"mass_strength\": 6%s},"
      " \"material\": {\"model\": \"linear\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000},"
      " \"time\": {\"dt\": 0.01, \"steps\": 3},"
      " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
      "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, -0.7], \"normal\": [0, 0, "
      "-1]}}}},"
      "  %s]}",
      dir, geometry, quadrature,
      "{\"cut\": {\"surface\": {\"plane\": {\"point\": [0.1, 0.05, 0], \"normal\": [0.3, 1, "
      "0.2]}}}}");
  snprintf(path, sizeof path, "%s/scene.json", dir);
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  fputs(json, f);
  fclose(f);
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  int ok = sim != NULL;
  for (int k = 0; ok && k < (3); k++) {
    fcm_step_info si;
    TEST_OK(ctx, fcm_simulation_step(sim, &si));
  }
  if (ok) {
    fcm_simulation_counters c;
    fcm_simulation_get_counters(sim, &c);
    *meshed = c.time_setup_phase[FCM_SETUP_VOLUME_MESH] > 0.0;
    const fcm_space *space = fcm_simulation_space(sim);
    *surface_cells = (int)fcm_cell_rules_get_stats(fcm_space_cell_rules(space))->num_surface_cells;
    TEST_TRUE(fcm_simulation_state_finite(sim));
    *dofs = fcm_space_num_dofs(space);
    TEST_OK(ctx, fcm_simulation_center_of_mass(sim, com));
    TEST_OK(ctx, fcm_space_max_displacement(
                     space, fcm_integrator_displacement(fcm_simulation_integrator(sim)), umax));
    /* a square in the air beside the ball (|x| > 1.1 on it), in cells the ball's surface
     * crosses: it meets no material, so the run keeps its rules and integrator */
    const double ac[3] = {0.78, 0.78, -0.27}, an[3] = {1, 1, 0}, aa[3] = {0, 0, 1},
                 asz[2] = {0.2, 0.2};
    fcm_surface *air = NULL;
    fcm_cut_info info;
    const fcm_integrator *I = fcm_simulation_integrator(sim);
    const fcm_cell_rules *R = fcm_simulation_cell_rules(sim);
    TEST_OK(ctx, fcm_surface_create_rectangle(ctx, ac, an, aa, asz, &air));
    TEST_OK(ctx, fcm_simulation_cut(sim, air, FCM_CUT_FRAME_REFERENCE, &info));
    if (!(info.missed && info.cells_integrated == 0 && fcm_simulation_integrator(sim) == I &&
          fcm_simulation_cell_rules(sim) == R))
      TEST_FAIL_("a blade in the air: missed %d, %lld cells integrated again, integrator %s",
                 info.missed, (long long)info.cells_integrated,
                 fcm_simulation_integrator(sim) == I ? "kept" : "made again");
    fcm_surface_destroy(&air);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return ok ? 0 : -1;
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 2));
  char dir[] = "/tmp/fcm_cut_surface_sceneXXXXXX", obj[600], scene[600];
  TEST_TRUE(mkdtemp(dir) != NULL);
  snprintf(obj, sizeof obj, "%s/ball.obj", dir);
  snprintf(scene, sizeof scene, "%s/scene.json", dir);
  TEST_TRUE(write_ball(obj) == 0);
  double us = 0.0, uv = 0.0, cs[3] = {0, 0, 0}, cv[3] = {0, 0, 0};
  int meshed = -1, fitted = 0;
  fcm_index ns = 0, nv = -1;
  if (run(dir, "", "", &us, cs, &meshed, &fitted, &ns) == 0) {
    TEST_TRUE(meshed == 0);
    TEST_TRUE(fitted > 0);
    TEST_TRUE(us > 0.0);
    printf("surface path: no volume mesh, %d cells fitted on surface moments, max |u| %.6e\n",
           fitted, us);
  }
  if (fcm_surface_meshing_available() &&
      run(dir, ", \"volume_mesh\": true", ", \"moments\": \"volume\"", &uv, cv, &meshed, &fitted,
          &nv) == 0) {
    TEST_TRUE(meshed == 1);
    TEST_TRUE(ns == nv);
    TEST_NEAR(us, uv, UTOL, 0);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(cs[d], cv[d], 0, CTOL);
    printf("volume path: max |u| %.6e, |difference| %.2e; centre of mass difference %.2e\n", uv,
           fabs(us - uv),
           fmax(fabs(cs[0] - cv[0]), fmax(fabs(cs[1] - cv[1]), fabs(cs[2] - cv[2]))));
  }
  remove(obj);
  remove(scene);
  rmdir(dir);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
