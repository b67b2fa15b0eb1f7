/* No per-step waste: after the first step, stepping a simulation makes no
 * allocation through the context's allocator. A small embedded dynamic scene (a Neo-Hookean
 * ball in a 3^3 background grid under gravity, held at its base, a patch of it pulled by a
 * prescribed motion, Rayleigh damping: several Newton iterations per step, the tangent and
 * the damping matrix reassembled every step, the constrained set active) is created, stepped
 * once, and then stepped ten more times with a counting allocator: the count must stay 0,
 * for every solver path named by argv[1]:
 *   direct       CHOLMOD (symbolic analysis once: total_analyses stays 1)
 *   minres-schwarz, cg-jacobi, minres-jacobi, cg-block   Krylov paths
 *   minres-mg, cg-mg, mg   multigrid as the preconditioner or the solver (PSD tangent)
 *   mg-interactive   interactive steps: 2 fixed Newton iterations of 3 fixed V-cycles each,
 *                    warm-started (accepted by the fixed-iteration rule)
 * and each of the ten steps must converge (interactive: be accepted) with at least two Newton
 * iterations (so repeated Newton iterations, line searches and solves are what is counted). Frames,
 * logs and checkpoints are not part of a step and are not written here. With "static" the scene is
 * static instead (two load steps per step, no inertia or damping). Usage: sim_step_alloc SOLVER
 * [ELEMENT] [static]  (ELEMENT: hex8 (default), tet10, hex20) */
#include "fcm/fcm.h"
#include "test.h"
#include "test_alloc.h"

#include <stdio.h>
#include <string.h>

static const char *solver_json(const char *name)
{
  if (!strcmp(name, "direct")) return "{\"method\": \"direct\", \"direct\": \"cholmod\"}";
  if (!strcmp(name, "minres-schwarz"))
    return "{\"method\": \"minres\", \"preconditioner\": \"schwarz\", \"schwarz\": {\"threshold\": "
           "0.5}, \"rtol\": 1e-8, \"max_iterations\": 2000}";
  if (!strcmp(name, "minres-jacobi"))
    return "{\"method\": \"minres\", \"preconditioner\": \"jacobi\", \"rtol\": 1e-8, "
           "\"max_iterations\": 2000}";
  if (!strcmp(name, "cg-jacobi"))
    return "{\"method\": \"cg\", \"preconditioner\": \"jacobi\", \"rtol\": 1e-8, "
           "\"max_iterations\": 2000}";
  if (!strcmp(name, "cg-block"))
    return "{\"method\": \"cg\", \"preconditioner\": \"block_jacobi\", \"rtol\": 1e-8, "
           "\"max_iterations\": 2000}";
  /* multigrid: the hierarchy is built at the first step and kept (the constrained
   * set does not change); later setups recompute its Galerkin matrices in place */
  if (!strcmp(name, "minres-mg"))
    return "{\"method\": \"minres\", \"preconditioner\": \"multigrid\", \"multigrid\": "
           "{\"coarse_dofs\": 20}, \"rtol\": 1e-8, \"max_iterations\": 2000}";
  if (!strcmp(name, "cg-mg"))
    return "{\"method\": \"cg\", \"preconditioner\": \"multigrid\", \"multigrid\": "
           "{\"coarse_dofs\": 20, \"smoother\": \"sgs-colored\"}, \"rtol\": 1e-8, "
           "\"max_iterations\": 2000}";
  if (!strcmp(name, "mg"))
    return "{\"method\": \"multigrid\", \"multigrid\": {\"coarse_dofs\": 20}, \"rtol\": 1e-8, "
           "\"max_iterations\": 2000, \"newton\": {\"project_psd\": true}}";
  if (!strcmp(name, "mg-interactive"))
    return "{\"method\": \"multigrid\", \"fixed_cycles\": 3, \"multigrid\": {\"coarse_dofs\": 20, "
           "\"cycle\": \"v\"}, \"newton\": {\"project_psd\": true, \"fixed_iterations\": 2}}";
  return NULL;
}

int main(int argc, char **argv)
{
  if (argc < 2) return 2;
  const char *solver = solver_json(argv[1]);
  const char *element = argc > 2 ? argv[2] : "hex8";
  const int stat = argc > 3 && !strcmp(argv[3], "static");
  if (!solver) {
    fprintf(stderr, "unknown solver '%s'\n", argv[1]);
    return 2;
  }
  char json[4096];
  snprintf(json, sizeof json,
           "{\"name\": \"step_alloc\","
           " \"background\": {\"element\": \"%s\", \"box\": {\"min\": [-0.6, -0.1, -0.6],"
           " \"max\": [0.6, 1.1, 0.6]}, \"cells\": [3, 3, 3]},"
           " \"geometry\": {\"shape\": \"ball\", \"center\": [0, 0.5, 0], \"radius\": 0.5,"
           " \"resolution\": 4},"
           " \"material\": {\"model\": \"snh\", \"young\": 5e5, \"poisson\": 0.4,"
           " \"density\": 1000},"
           " \"quadrature\": {\"stiffness_strength\": 3,"
           " \"stabilization\": {\"mode\": \"mass_stiffness\", \"alpha\": 1e-8}},"
           " \"solver\": %s,"
           " \"time\": %s,"
           " \"effects\": ["
           "  {\"gravity\": {\"acceleration\": [0, -9.81, 0]}},"
           "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0.06, 0],"
           " \"normal\": [0, -1, 0]}}}},"
           "  {\"motion\": {\"region\": {\"box\": {\"min\": [-0.7, 0.6, -0.7],"
           " \"max\": [0.7, 1.2, 0.7]}}, \"velocity\": [0, 0, 1.0], \"end\": 1}}%s]}",
           element, solver,
           stat ? "{\"static\": true, \"steps\": 20, \"load_steps\": 2}"
                : "{\"dt\": 0.02, \"duration\": 1}",
           stat ? "" : ", {\"damping\": {\"stiffness\": 0.01, \"mass\": 0.1}}");

  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return TEST_RESULT();
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "step_alloc.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_simulation_step(sim, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED || info.reason == FCM_STEP_FIXED_ITERATIONS);
    const long long live = fcm_ctx_live_allocations(ctx);
    long long total = 0;
    for (int k = 0; k < 10; k++) {
      f.count = 0;
      TEST_OK(ctx, fcm_simulation_step(sim, &info));
      if (f.count != 0)
        TEST_FAIL_("%s %s: step %d made %lld allocation(s) through the context", argv[1], element,
                   k + 2, f.count);
      total += f.count;
      const int accepted =
          info.reason == FCM_STEP_CONVERGED ||
          (info.reason == FCM_STEP_FIXED_ITERATIONS && info.newton_iterations == 2);
      if (!accepted || info.newton_iterations < 2 || info.failed_attempts != 0)
        TEST_FAIL_("%s %s: step %d: %s after %d Newton iterations, %d failed attempts "
                   "(the test needs converged steps with repeated Newton iterations)",
                   argv[1], element, k + 2, fcm_step_reason_name(info.reason),
                   info.newton_iterations, info.failed_attempts);
      if (!strcmp(argv[1], "direct") && info.total_analyses != 1)
        TEST_FAIL_("direct: %lld symbolic analyses after step %d, expected 1 (one analysis "
                   "for the whole run)",
                   info.total_analyses, k + 2);
    }
    TEST_TRUE(total == 0);
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == live);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
