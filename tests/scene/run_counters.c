/* fcm_simulation runs only what a scene asks for: the counters of small scenes (static
 * without gravity, dynamic linear with gravity, Krylov with and without Schwarz blocks),
 * prescribed values met, frames and log written, a region without nodes rejected. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static fcm_simulation *run(fcm_ctx *ctx, const char *json, fcm_scene **scene, int steps)
{
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "test.json", scene));
  if (!*scene) return NULL;
  TEST_OK(ctx, fcm_simulation_create(ctx, *scene, NULL, &sim));
  for (int k = 0; sim && k < steps; k++) {
    fcm_step_info si;
    TEST_OK(ctx, fcm_simulation_step(sim, &si));
    TEST_TRUE(si.reason == FCM_STEP_CONVERGED);
  }
  if (sim) TEST_TRUE(fcm_simulation_state_finite(sim));
  return sim;
}

/* Static linear bar, no gravity: one end fixed, the other pulled by a motion. */
static const char static_json[] =
    "{\"version\": 1, \"name\": \"static_pull\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [2, 1, 1]},"
    "   \"cells\": [4, 2, 2]},"
    " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"static\": true, \"steps\": 2, \"dt\": 1},"
    " \"effects\": ["
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, 0]}}}},"
    "  {\"motion\": {\"region\": {\"half_space\": {\"point\": [2, 0, 0], \"normal\": [1, 0, 0]}},"
    "    \"velocity\": [0.01, 0, 0]}}]}";

/* Dynamic linear block under gravity, clamped at x = 0, direct solver. */
static const char dynamic_json[] =
    "{\"version\": 1, \"name\": \"dyn\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [2, 1, 1]},"
    "   \"cells\": [4, 2, 2]},"
    " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"solver\": {\"method\": \"direct\"},"
    " \"time\": {\"dt\": 0.01, \"steps\": 4},"
    " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, "
    "0]}}}}]}";

/* Embedded box in a 3 x 1 x 1 grid over [0, 1.5] x [0, 0.5]^2; MAX sets the cut. */
static void embedded_json(char *buf, size_t n, double max_x, const char *name)
{
  snprintf(buf, n,
           "{\"version\": 1, \"name\": \"%s\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [%.17g, 0.5, 0.5],"
           "   \"cells\": [3, 1, 1]},"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"solver\": {\"method\": \"cg\", \"preconditioner\": \"schwarz\","
           "   \"schwarz\": {\"threshold\": 0.5}, \"rtol\": 1e-10, \"max_iterations\": 2000},"
           " \"time\": {\"static\": true, \"steps\": 1},"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
           "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"
           "    \"normal\": [-1, 0, 0]}}}}]}",
           name, max_x);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  fcm_scene *scene = NULL;
  fcm_simulation_counters c;

  /* static, no gravity: no inertia, no body force, no surface loads, no cell rules */
  fcm_simulation *sim = run(ctx, static_json, &scene, 2);
  if (sim) {
    fcm_simulation_get_counters(sim, &c);
    TEST_TRUE(c.inertia == 0);
    TEST_TRUE(c.mass_assemblies == 0 && c.scale_assemblies == 0);
    TEST_TRUE(fcm_integrator_mass(fcm_simulation_integrator(sim)) == NULL);
    TEST_TRUE(c.body_force_assemblies == 0);
    TEST_TRUE(c.traction_assemblies == 0);
    TEST_TRUE(c.cell_rules == 0 && c.surface_rules == 0);
    TEST_TRUE(c.damping == 0 && c.initial_velocity == 0);
    TEST_TRUE(c.schwarz_blocks == 0 && c.krylov == 0);
    TEST_TRUE(c.constraints == 2);
    /* 5 x 3 x 3 grid nodes: 9 on each end face, 3 components each */
    TEST_TRUE(c.constrained_nodes == 18 && c.constrained_dofs == 54);
    TEST_TRUE(c.steps == 2 && fcm_simulation_done(sim));
    /* the pulled face sits at its prescribed displacement 0.01 t (t = 2) */
    const fcm_space *sp = fcm_simulation_space(sim);
    const fcm_mesh *mesh = fcm_space_mesh(sp);
    const double *u = fcm_integrator_displacement(fcm_simulation_integrator(sim));
    const double *X = fcm_mesh_coords(mesh);
    for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++)
      if (X[3 * a] > 2 - 1e-12) TEST_NEAR(u[fcm_space_node_dof(sp, a)], 0.02, 1e-9, 1e-12);
    /* taking more steps than the scene has is an error */
    TEST_ERR(ctx, fcm_simulation_step(sim, NULL), FCM_ERR_ARG, "steps are taken");
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);

  /* dynamic, gravity, linear, constant dt, fixed constraint: mass once, one body-force
   * pass, the Newton matrix analyzed and factored once for all steps */
  sim = run(ctx, dynamic_json, &scene, 4);
  if (sim) {
    fcm_simulation_get_counters(sim, &c);
    TEST_TRUE(c.inertia == 1 && c.mass_assemblies == 1 && c.scale_assemblies == 0);
    TEST_TRUE(c.body_force_assemblies == 1 && c.traction_assemblies == 0);
    /* no contact effect: no contact term evaluated, nothing reported */
    TEST_TRUE(c.contacts == 0 && c.contact_evaluations == 0 && c.contact_points_max == 0);
    TEST_TRUE(c.contact_min_distance == HUGE_VAL && c.friction_dissipation == 0.0);
    TEST_TRUE(c.steps == 4);
    TEST_TRUE(c.analyses == 1);
    TEST_TRUE(c.factorizations == 1);
    /* gravity pulls the free end down */
    double lin[3];
    TEST_OK(ctx, fcm_integrator_momentum(fcm_simulation_integrator(sim), lin, NULL));
    TEST_TRUE(lin[2] < 0.0);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);

  /* Krylov + Schwarz: the box fills [0, 1.2]: cell 2 has volume fraction 0.4 < 0.5, the
   * only block; filling exactly [0, 1] leaves only uncut cells: no block, no Schwarz */
  char json[4096];
  embedded_json(json, sizeof json, 1.2, "cut");
  sim = run(ctx, json, &scene, 1);
  if (sim) {
    fcm_simulation_get_counters(sim, &c);
    TEST_TRUE(c.cell_rules == 1 && c.surface_rules == 0 && c.krylov == 1);
    TEST_TRUE(c.schwarz_blocks == 1);
    TEST_TRUE(c.inertia == 0 && c.body_force_assemblies == 1);
    TEST_TRUE(c.mass_assemblies == 0 && c.scale_assemblies == 0);
    TEST_TRUE(c.surface_triangles > 0 && c.surface_points > 0);

    /* frames and log */
    char dir[] = "/tmp/fcm-run-counters-XXXXXX", path[4096];
    if (mkdtemp(dir)) {
      TEST_OK(ctx, fcm_simulation_write_frame(sim, dir, 0));
      TEST_OK(ctx, fcm_simulation_write_log(
                       sim, (snprintf(path, sizeof path, "%s/log.csv", dir), path)));
      const char *files[] = {"cut_background_0000.vtu", "cut_surface_0000.vtu",
                             "cut_background.pvd", "cut_surface.pvd", "log.csv"};
      for (int k = 0; k < 5; k++) {
        struct stat sb;
        snprintf(path, sizeof path, "%s/%s", dir, files[k]);
        TEST_TRUE(stat(path, &sb) == 0 && sb.st_size > 0);
        remove(path);
      }
      fcm_simulation_get_counters(sim, &c);
      TEST_TRUE(c.frames == 1);
      rmdir(dir);
    } else {
      TEST_TRUE(!"mkdtemp failed");
    }
    /* writing into a missing directory fails with the path named */
    TEST_ERR(ctx, fcm_simulation_write_frame(sim, "/nonexistent-fcm-dir", 1), FCM_ERR_IO,
             "/nonexistent-fcm-dir");
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);

  embedded_json(json, sizeof json, 1.0, "aligned");
  sim = run(ctx, json, &scene, 1);
  if (sim) {
    fcm_simulation_get_counters(sim, &c);
    TEST_TRUE(c.cell_rules == 1 && c.krylov == 1 && c.schwarz_blocks == 0);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);

  /* initial spin about the centre of mass of an embedded hemisphere (off the grid's
   * centre): the linear momentum of omega x (X - c) vanishes exactly when c is the centre
   * of mass of the same mass matrix */
  static const char spin_json[] =
      "{\"version\": 1, \"name\": \"spin\","
      " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-1, -1, -1],"
      "   \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
      " \"geometry\": {\"shape\": \"hemisphere\", \"center\": [0.1, -0.4, 0.2],"
      "   \"radius\": 0.5, \"resolution\": 2},"
      " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3,"
      "   \"density\": 1000},"
      " \"time\": {\"dt\": 0.01, \"steps\": 1},"
      " \"effects\": [{\"initial_velocity\": {\"angular_velocity\": [1, 2, 3]}}]}";
  sim = run(ctx, spin_json, &scene, 0);
  if (sim) {
    fcm_simulation_get_counters(sim, &c);
    TEST_TRUE(c.initial_velocity == 1 && c.body_force_assemblies == 0 && c.constraints == 0);
    double lin[3], mass = 1000 * 2.0 / 3.0 * 3.14159265358979 * 0.125, scale = mass * 3.7 * 0.5;
    TEST_OK(ctx, fcm_integrator_momentum(fcm_simulation_integrator(sim), lin, NULL));
    for (int d = 0; d < 3; d++)
      TEST_NEAR(lin[d], 0.0, 0.0, 1e-10 * scale);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);

  /* a region without any background node is an error naming the effect */
  static const char empty_json[] =
      "{\"version\": 1, \"name\": \"empty\","
      " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
      "   \"cells\": [1, 1, 1]},"
      " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1},"
      " \"time\": {\"static\": true, \"steps\": 1},"
      " \"effects\": [{\"gravity\": {}},"
      "  {\"fixed\": {\"region\": {\"box\": {\"min\": [5, 5, 5], \"max\": [6, 6, 6]}}}}]}";
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, empty_json, "empty.json", &scene));
  if (scene)
    TEST_ERR(ctx, fcm_simulation_create(ctx, scene, NULL, &sim), FCM_ERR_ARG,
             "effects[1]: the fixed region (box [5, 5, 5] to [6, 6, 6]) contains no "
             "background-mesh node");
  TEST_TRUE(sim == NULL);
  fcm_scene_destroy(&scene);

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
