/* The scene's solver and quadrature sections embed the library's option structs: a scene that
 * gives none of their keys carries exactly fcm_integrator_options_default() and
 * fcm_cell_rules_options_default(), member by member (a member added to either struct must be
 * added here), a scene that writes every key with the value the library's default has parses
 * to the same structs, and one that names a multigrid smoother alone keeps the default relaxation
 * omega = 0, the smoother's own (fcm_mg_smoother_omega(), resolved by fcm_mg_create()), while a
 * written omega is kept as written. The element-corotated model's quadrature default differs
 * (stiffness rules on the mass space). */
#include "fcm/fcm.h"
#include "test.h"

#define SAME(a, b, m) TEST_TRUE((a)->m == (b)->m)

static void same_mg(const fcm_mg_options *a, const fcm_mg_options *b)
{
  SAME(a, b, smoother);
  SAME(a, b, omega);
  SAME(a, b, pre_smooth);
  SAME(a, b, post_smooth);
  SAME(a, b, cycle_index);
  SAME(a, b, max_levels);
  SAME(a, b, coarse_dofs);
  SAME(a, b, block_smoothing);
  SAME(a, b, blocks);
  SAME(a, b, block_fraction);
  SAME(a, b, block_sweep);
  SAME(a, b, point_sweep);
  SAME(a, b, coarse_interval);
}

static void same_integrator(const fcm_integrator_options *a, const fcm_integrator_options *b)
{
  SAME(a, b, kind);
  SAME(a, b, dt);
  SAME(a, b, load_steps);
  SAME(a, b, max_halvings);
  SAME(a, b, newton_max_iterations);
  SAME(a, b, tolerance_mode);
  SAME(a, b, newton_tolerance);
  SAME(a, b, newton_atol);
  SAME(a, b, rep_acceleration);
  SAME(a, b, line_search);
  SAME(a, b, armijo);
  SAME(a, b, backtrack);
  SAME(a, b, max_backtracks);
  SAME(a, b, project_psd);
  SAME(a, b, reuse_factorization);
  SAME(a, b, reuse_contraction);
  SAME(a, b, newton_fixed_iterations);
  SAME(a, b, linear_solver);
  SAME(a, b, direct_method);
  SAME(a, b, preconditioner);
  SAME(a, b, preconditioner_tangent);
  SAME(a, b, krylov_rtol);
  SAME(a, b, krylov_atol);
  SAME(a, b, krylov_max_iterations);
  SAME(a, b, krylov_stagnation_window);
  SAME(a, b, multigrid_fixed_cycles);
  SAME(a, b, schwarz_theta);
  SAME(a, b, schwarz.epsilon);
  SAME(a, b, schwarz.clamp);
  same_mg(&a->multigrid, &b->multigrid);
  SAME(a, b, rayleigh_mass);
  SAME(a, b, rayleigh_stiffness);
  SAME(a, b, assembly.stiffness_strength);
  SAME(a, b, assembly.mass_strength);
  SAME(a, b, assembly.fictitious);
  SAME(a, b, monitor);
  SAME(a, b, monitor_user);
}

static void same_rules(const fcm_cell_rules_options *a, const fcm_cell_rules_options *b)
{
  SAME(a, b, kinds);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    SAME(a, b, strength[k]);
    SAME(a, b, expected_assemblies[k]);
    SAME(a, b, point_cost[k]);
  }
  SAME(a, b, surface_strength);
  SAME(a, b, min_fraction);
  SAME(a, b, uncut_fraction);
  SAME(a, b, clip_rtol);
  SAME(a, b, sliver_rtol);
  SAME(a, b, convex_rtol);
  SAME(a, b, simplify);
  SAME(a, b, simplify_options.method);
  SAME(a, b, simplify_options.rank_tol);
  SAME(a, b, simplify_options.residual_tol);
  SAME(a, b, simplify_options.lp_iteration_limit);
  SAME(a, b, simplify_options.lp_time_limit);
  SAME(a, b, max_rule_memory);
  SAME(a, b, stabilization.mode);
  SAME(a, b, stabilization.alpha);
  SAME(a, b, progress);
  SAME(a, b, progress_user);
  SAME(a, b, progress_interval);
  SAME(a, b, cell_mask);
}

/* The sections of `json` against the library's defaults, the multigrid smoother `smoother`
 * with the relaxation omega (0: the default, the smoother's own). */
static void check_smoother(fcm_ctx *ctx, const char *json, fcm_mg_smoother smoother, double omega)
{
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "defaults.json", &s));
  if (!s) return;
  fcm_integrator_options io = fcm_integrator_options_default();
  io.multigrid.smoother = smoother;
  io.multigrid.omega = omega;
  const fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  same_integrator(&fcm_scene_get_solver(s)->integrator, &io);
  same_rules(&fcm_scene_get_quadrature(s)->rules, &ro);
  TEST_TRUE(fcm_scene_get_solver(s)->threads == FCM_DEFAULT);
  TEST_TRUE(fcm_scene_get_solver(s)->petsc_options == NULL);
  TEST_TRUE(fcm_scene_get_solver(s)->stop_on_inversion == 0);
  fcm_scene_destroy(&s);
}

static void check(fcm_ctx *ctx, const char *json)
{
  check_smoother(ctx, json, fcm_integrator_options_default().multigrid.smoother, 0.0);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return 1;
  static const char *const head =
      "{\"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
      " \"cells\": [2, 2, 2]}, \"material\": {\"young\": 1e6, \"poisson\": 0.3}";
  char json[4096];
  snprintf(json, sizeof json, "%s}", head);
  check(ctx, json);
  /* Every solver and quadrature key at the value the README gives as its default. */
  snprintf(json, sizeof json,
           "%s, \"quadrature\": {\"simplify\": true, \"simplify_method\": \"auto\","
           " \"stabilization\": {\"mode\": \"mass_stiffness\", \"alpha\": 1e-6},"
           " \"min_fraction\": 1e-4, \"max_rule_memory_gib\": 4},"
           " \"solver\": {\"method\": \"direct\", \"direct\": \"cholmod\","
           " \"preconditioner\": \"schwarz\", \"preconditioner_tangent\": \"projected\","
           " \"schwarz\": {\"threshold\": 0.5, \"epsilon\": 1e-13, \"clamp\": \"clamp\"},"
           " \"multigrid\": {\"smoother\": \"sgs\", \"omega\": 0, \"pre_smooth\": 1,"
           " \"post_smooth\": 1, \"cycle\": \"w\", \"coarse_dofs\": 2000,"
           " \"block_smoothing\": true},"
           " \"rtol\": 1e-8, \"atol\": 0, \"max_iterations\": 1000, \"stagnation_window\": 50,"
           " \"fixed_cycles\": 0,"
           " \"newton\": {\"rule\": \"auto\", \"rtol\": 1e-5, \"max_iterations\": 100,"
           " \"line_search\": true, \"project_psd\": false, \"reuse_factorization\": true,"
           " \"reuse_contraction\": 0.25, \"fixed_iterations\": 0,"
           " \"representative_acceleration\": 9.81},"
           " \"threads\": 0, \"on_inversion\": \"warn\"}}",
           head);
  check(ctx, json);
  /* The library's default relaxation is "the smoother's own" (0), so choosing the smoother
   * alone keeps it; damped Jacobi's own differs from the Gauss-Seidel one. A written value is
   * kept. */
  TEST_TRUE(fcm_integrator_options_default().multigrid.omega == 0.0);
  TEST_TRUE(fcm_mg_smoother_omega(FCM_MG_SMOOTHER_JACOBI) <
            fcm_mg_smoother_omega(FCM_MG_SMOOTHER_SGS));
  snprintf(json, sizeof json, "%s, \"solver\": {\"multigrid\": {\"smoother\": \"jacobi\"}}}", head);
  check_smoother(ctx, json, FCM_MG_SMOOTHER_JACOBI, 0.0);
  snprintf(json, sizeof json,
           "%s, \"solver\": {\"multigrid\": {\"smoother\": \"jacobi\", \"omega\": %.17g}}}", head,
           fcm_mg_smoother_omega(FCM_MG_SMOOTHER_JACOBI));
  check_smoother(ctx, json, FCM_MG_SMOOTHER_JACOBI, fcm_mg_smoother_omega(FCM_MG_SMOOTHER_JACOBI));
  snprintf(json, sizeof json, "%s, \"solver\": {\"multigrid\": {\"smoother\": \"sgs_colored\"}}}",
           head);
  check_smoother(ctx, json, FCM_MG_SMOOTHER_SGS_COLORED, 0.0);
  /* The element-corotated model integrates the stiffness once: its default fits the cut
   * cells' stiffness rules on the mass space; a written false is kept. */
  static const char *const corot =
      "{\"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
      " \"cells\": [2, 2, 2]}, \"material\": {\"model\": \"corotated_linear\", \"young\": 1e6,"
      " \"poisson\": 0.3}";
  for (int written = -1; written <= 1; written++) {
    if (written < 0)
      snprintf(json, sizeof json, "%s}", corot);
    else
      snprintf(json, sizeof json, "%s, \"quadrature\": {\"stiffness_on_mass_space\": %s}}", corot,
               written ? "true" : "false");
    fcm_scene *s = NULL;
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "corotated.json", &s));
    if (s) TEST_TRUE(fcm_scene_get_quadrature(s)->rules.stiffness_on_mass_space == (written != 0));
    fcm_scene_destroy(&s);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
