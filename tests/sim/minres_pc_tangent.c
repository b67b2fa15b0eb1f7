/* The tangent the MINRES preconditioner is built from
 * (fcm_integrator_options.preconditioner_tangent, scene key solver.preconditioner_tangent).
 * A Hex20 tube cut by a 1 x 2 x 1 grid is twisted and squeezed for two steps (unprojected
 * Stable Neo-Hookean tangent; the preconditioner, Schwarz with Jacobi outside its blocks, is
 * built from the chosen tangent); asserted:
 * 1. the scene default is "projected", "linear" and "exact" parse, other names are refused
 *    with a message naming the key; the integrator refuses an out-of-range value at setup;
 * 2. with each of the three tangents, MINRES + Schwarz converges every step with every
 *    Newton system solved to its tolerance (no solve stopped early, no projection fallback)
 *    and the displacements agree with the direct solve: the preconditioner changes the
 *    iterations, never the system solved (max |u_minres - u_direct| <= 1e-6 max |u_direct|);
 * 3. "projected" assembles one more tangent per preconditioner setup than "exact" on the same
 *    Newton iterations ("linear" assembles its constant stiffness once, not as a tangent).
 * The conditioning effect itself is asserted by app_condition_claims (claims 5, 6) and
 * sim_minres_scenes. MINRES iterations per tangent are printed with "-v". */
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define STEPS 2

static const char *scene_json(char *buf, size_t n, const char *solver)
{
  snprintf(
      buf, n,
      "{\"name\": \"pc_tangent\",\n"
      " \"background\": {\"element\": \"hex20\", \"box\": {\"min\": [-1, -2, -1], \"max\": [1, 2, "
      "1]}, \"cells\": [1, 2, 1]},\n"
      " \"geometry\": {\"shape\": \"tube\", \"axis\": \"y\", \"inner_radius\": 0.45, "
      "\"outer_radius\": 0.93, \"length\": 3.98},\n"
      " \"material\": {\"model\": \"snh\", \"young\": 5e6, \"poisson\": 0.45},\n"
      " \"solver\": {%s},\n"
      " \"time\": {\"dt\": 0.05, \"duration\": 1},\n"
      " \"effects\": [\n"
      "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, -1.98, 0], \"normal\": [0, -1, "
      "0]}}}},\n"
      "  {\"motion\": {\"region\": {\"half_space\": {\"point\": [0, 1.98, 0], \"normal\": [0, 1, "
      "0]}}, \"rotation\": {\"axis\": [0, 1, 0], \"speed\": 3}, \"velocity\": [0, -1, 0]}}]}\n",
      solver);
  return buf;
}

typedef struct run_out {
  double u[100000];
  fcm_index n;
  long long linear_iterations;
  int newton, tangents, setups, ok;
} run_out;

static void run(fcm_ctx *ctx, const char *solver, run_out *out)
{
  char json[4096];
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  memset(out, 0, sizeof *out);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, scene_json(json, sizeof json, solver), "<test>",
                                            &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  out->ok = sim != NULL;
  for (int k = 0; out->ok && k < STEPS; k++) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_simulation_step(sim, &info));
    if (info.reason != FCM_STEP_CONVERGED || info.inexact_solves || info.projection_fallbacks ||
        info.failed_attempts) {
      TEST_FAIL_("%s: step %d: %s, %d inexact solves, %d projection fallbacks, %d failed "
                 "attempts",
                 solver, k, fcm_step_reason_name(info.reason), info.inexact_solves,
                 info.projection_fallbacks, info.failed_attempts);
      out->ok = 0;
    }
    out->linear_iterations += info.linear_iterations;
    out->newton += info.newton_iterations;
    out->tangents += info.tangent_assemblies;
    out->setups += info.factorizations;
  }
  if (out->ok) {
    const fcm_integrator *I = fcm_simulation_integrator(sim);
    out->n = fcm_integrator_num_dofs(I);
    TEST_TRUE(out->n > 0 && out->n <= 100000);
    if (out->n > 100000)
      out->ok = 0;
    else
      memcpy(out->u, fcm_integrator_displacement(I), sizeof(double) * (size_t)out->n);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

int main(int argc, char **argv)
{
  const int verbose = argc > 1 && !strcmp(argv[1], "-v");
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;

  /* 1. parsing and validation */
  char json[4096];
  fcm_scene *scene = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(
                   ctx, scene_json(json, sizeof json, "\"method\": \"minres\""), "<t>", &scene));
  TEST_TRUE(scene &&
            fcm_scene_get_solver(scene)->preconditioner_tangent == FCM_FICTITIOUS_PROJECTED);
  fcm_scene_destroy(&scene);
  static const char *const names[] = {"projected", "linear", "exact"};
  static const fcm_fictitious_model models[] = {FCM_FICTITIOUS_PROJECTED, FCM_FICTITIOUS_LINEAR,
                                                FCM_FICTITIOUS_EXACT};
  for (int k = 0; k < 3; k++) {
    char solver[128];
    snprintf(solver, sizeof solver, "\"preconditioner_tangent\": \"%s\"", names[k]);
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, scene_json(json, sizeof json, solver), "<t>",
                                              &scene));
    TEST_TRUE(scene && fcm_scene_get_solver(scene)->preconditioner_tangent == models[k]);
    fcm_scene_destroy(&scene);
  }
  TEST_ERR(
      ctx,
      fcm_scene_create_from_string(
          ctx, scene_json(json, sizeof json, "\"preconditioner_tangent\": \"psd\""), "<t>", &scene),
      FCM_ERR_ARG, "preconditioner_tangent");
  TEST_TRUE(scene == NULL);
  {
    fcm_scene *s2 = NULL;
    fcm_simulation *sim = NULL;
    fcm_integrator *I = NULL;
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, scene_json(json, sizeof json, "\"rtol\": 1e-8"),
                                              "<t>", &s2));
    if (s2) TEST_OK(ctx, fcm_simulation_create(ctx, s2, NULL, &sim));
    if (sim) {
      fcm_integrator_options o = fcm_integrator_options_default();
      const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 5e6, 0.45, 1000.0};
      TEST_TRUE(o.preconditioner_tangent == FCM_FICTITIOUS_PROJECTED);
      o.preconditioner_tangent = FCM_FICTITIOUS_MODEL_COUNT;
      TEST_OK(ctx, fcm_integrator_create(ctx, fcm_simulation_space(sim), &mat, &o, &I));
      if (I) TEST_ERR(ctx, fcm_integrator_setup(I), FCM_ERR_ARG, "preconditioner_tangent");
      fcm_integrator_destroy(&I);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&s2);
  }

  /* 2. and 3. */
  static run_out direct, minres[3];
  run(ctx, "\"method\": \"direct\"", &direct);
  for (int k = 0; k < 3; k++) {
    char solver[256];
    snprintf(solver, sizeof solver,
             "\"method\": \"minres\", \"preconditioner\": \"schwarz\", \"rtol\": 1e-10, "
             "\"max_iterations\": 5000, \"preconditioner_tangent\": \"%s\"",
             names[k]);
    run(ctx, solver, &minres[k]);
    if (!direct.ok || !minres[k].ok) continue;
    TEST_TRUE(minres[k].n == direct.n);
    double diff = 0.0, ref = 0.0;
    for (fcm_index i = 0; i < direct.n; i++) {
      diff = fmax(diff, fabs(minres[k].u[i] - direct.u[i]));
      ref = fmax(ref, fabs(direct.u[i]));
    }
    TEST_TRUE(ref > 1e-3); /* the motion deformed the tube */
    if (!(diff <= 1e-6 * ref))
      TEST_FAIL_("%s: max |u_minres - u_direct| = %.3e, max |u_direct| = %.3e", names[k], diff,
                 ref);
    if (verbose)
      printf("%-9s %lld dofs: %d Newton iterations (direct %d), %lld MINRES iterations (%.1f per "
             "Newton iteration), %d tangent assemblies, %d setups, |du|/|u| = %.1e\n",
             names[k], (long long)direct.n, minres[k].newton, direct.newton,
             minres[k].linear_iterations, (double)minres[k].linear_iterations / minres[k].newton,
             minres[k].tangents, minres[k].setups, diff / ref);
  }
  if (minres[0].ok && minres[2].ok && minres[0].newton == minres[2].newton &&
      minres[0].setups == minres[2].setups)
    TEST_TRUE(minres[0].tangents == minres[2].tangents + minres[0].setups);
  if (minres[1].ok && minres[2].ok && minres[1].newton == minres[2].newton &&
      minres[1].setups == minres[2].setups)
    TEST_TRUE(minres[1].tangents == minres[2].tangents);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
