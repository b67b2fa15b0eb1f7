/* The direct path refuses numerically singular systems with FCM_ERR_SINGULAR and
 * the likely cause, instead of returning a solution.
 * 1. fcm_direct (CHOLMOD) on [[1, 1], [1, 1 + d]]: d = 1e-14 (pivot 1e-14 of its diagonal)
 *    is refused as numerically singular, with no failed column (the factor completed) and
 *    the hint in the message; d = 1e-6 (ill-conditioned, kappa ~ 4e6, but regular) solves
 *    to the exact answer; the backward error of a good solve is at rounding level.
 * 2. fcm_simulation: a static body with no Dirichlet constraint (free rigid modes: refused
 *    before the solve, tests/sim/rigid_modes.c) and a Hex8 background at stiffness quadrature
 *    strength 1 (hourglass modes: refused by the factorization) fail with FCM_ERR_SINGULAR
 *    naming the cause; the same scenes well posed (fixed face, default strength) converge.
 * 3. No false positive on a stabilized FCM system with tiny cut cells: an embedded box whose
 *    last cells are cut at volume fractions 1e-6 and 1e-12 (kept: min_fraction 0), static
 *    and dynamic, with the default stabilization (alpha 1e-6), solves with CHOLMOD. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void test_direct(fcm_ctx *ctx)
{
  const double ds[2] = {1e-14, 1e-6};
  for (int k = 0; k < 2; k++) {
    const fcm_index ti[4] = {0, 0, 1, 1}, tj[4] = {0, 1, 0, 1};
    const double tv[4] = {1.0, 1.0, 1.0, 1.0 + ds[k]};
    fcm_csr *A = NULL;
    fcm_direct *s = NULL;
    TEST_OK(ctx, fcm_csr_create_triplets(ctx, 2, 2, 4, ti, tj, tv, FCM_CSR_SYMMETRIC, &A));
    TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &s));
    TEST_OK(ctx, fcm_direct_analyze(s));
    fcm_direct_info info;
    if (k == 0) {
      TEST_ERR(ctx, fcm_direct_factor(s, fcm_csr_values(A)), FCM_ERR_SINGULAR,
               "likely causes: rigid-body modes");
      fcm_direct_get_info(s, &info);
      TEST_TRUE(info.failed_column == -1);
      TEST_TRUE(info.min_pivot_ratio > 0 && info.min_pivot_ratio < 1e-12);
    } else {
      TEST_OK(ctx, fcm_direct_factor(s, fcm_csr_values(A)));
      /* x = (1, 1): b = (2, 2 + d) */
      double b[2] = {2.0, 2.0 + ds[k]}, x[2];
      TEST_OK(ctx, fcm_direct_solve(s, b, x));
      TEST_NEAR(x[0], 1.0, 1e-9, 0);
      TEST_NEAR(x[1], 1.0, 1e-9, 0);
      fcm_direct_get_info(s, &info);
      TEST_TRUE(info.min_pivot_ratio > 1e-7 && info.min_pivot_ratio < 2e-6);
      TEST_TRUE(info.backward_error < 1e-15);
    }
    fcm_direct_destroy(&s);
    fcm_csr_destroy(&A);
  }
}

/* A beam [0, 2] x [0, 1]^2 of 4 x 2 x 2 cells of `element`, static linear, with gravity. */
static void beam_json(char *buf, size_t n, const char *element, int fixed, int strength)
{
  char quad[128] = "";
  if (strength > 0)
    snprintf(quad, sizeof quad, " \"quadrature\": {\"stiffness_strength\": %d},", strength);
  snprintf(
      buf, n,
      "{\"version\": 1, \"name\": \"singular\","
      " \"background\": {\"element\": \"%s\", \"box\": {\"min\": [0, 0, 0], \"max\": [2, 1, 1]},"
      "   \"cells\": [4, 2, 2]},%s"
      " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
      " \"solver\": {\"method\": \"direct\", \"direct\": \"cholmod\"},"
      " \"time\": {\"static\": true, \"steps\": 1},"
      " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}%s]}",
      element, quad,
      fixed ? ", {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"
              " \"normal\": [-1, 0, 0]}}}}"
            : "");
}

/* Step the scene once: the status and the step's reason. */
static fcm_status step(fcm_ctx *ctx, const char *json, fcm_step_reason *reason)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  fcm_status st = fcm_scene_create_from_string(ctx, json, "singular.json", &scene);
  if (st == FCM_OK) st = fcm_simulation_create(ctx, scene, NULL, &sim);
  fcm_step_info si;
  memset(&si, 0, sizeof si);
  if (st == FCM_OK) st = fcm_simulation_step(sim, &si);
  *reason = si.reason;
  if (st == FCM_OK && !fcm_simulation_state_finite(sim)) st = FCM_ERR_NUMERIC;
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return st;
}

static void test_sim(fcm_ctx *ctx)
{
  char json[4096];
  fcm_step_reason reason;
  static const char *const elements[2] = {"hex20", "tet10"};
  for (int e = 0; e < 2; e++) {
    beam_json(json, sizeof json, elements[e], 0, 0); /* free body */
    TEST_ERR(ctx, step(ctx, json, &reason), FCM_ERR_SINGULAR, "refused before any solve");
    beam_json(json, sizeof json, elements[e], 1, 1); /* one point per cell: hourglass modes */
    TEST_ERR(ctx, step(ctx, json, &reason), FCM_ERR_SINGULAR, "quadrature rule too weak");
    beam_json(json, sizeof json, elements[e], 1, 0); /* well posed */
    TEST_OK(ctx, step(ctx, json, &reason));
    TEST_TRUE(reason == FCM_STEP_CONVERGED);
  }
}

/* Embedded box [0, 1 + c] x [0, 0.5]^2 in a 3 x 1 x 1 grid of 0.5-cells: the third cell is
 * cut at volume fraction c / 0.5. */
static void test_small_cut(fcm_ctx *ctx)
{
  const double fractions[2] = {1e-6, 1e-12};
  for (int f = 0; f < 2; f++)
    for (int dyn = 0; dyn < 2; dyn++)
      for (int el = 0; el < 2; el++) {
        char json[4096];
        snprintf(
            json, sizeof json,
            "{\"version\": 1, \"name\": \"small_cut\","
            " \"background\": {\"element\": \"%s\", \"box\": {\"min\": [0, 0, 0],"
            "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"
            " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [%.17g, 0.5, 0.5],"
            "   \"cells\": [3, 1, 1]},"
            " \"quadrature\": {\"min_fraction\": 0},"
            " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.45,"
            "   \"density\": 1000},"
            " \"solver\": {\"method\": \"direct\", \"direct\": \"cholmod\"},"
            " \"time\": %s,"
            " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
            "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"
            "    \"normal\": [-1, 0, 0]}}}}]}",
            el ? "hex20" : "hex8", 1.0 + 0.5 * fractions[f],
            dyn ? "{\"dt\": 0.01, \"steps\": 1}" : "{\"static\": true, \"steps\": 1}");
        fcm_step_reason reason;
        fcm_status st = step(ctx, json, &reason);
        if (st != FCM_OK || reason != FCM_STEP_CONVERGED)
          TEST_FAIL_("small cut %g %s %s: %s (%s)", fractions[f], el ? "hex20" : "hex8",
                     dyn ? "dynamic" : "static", fcm_status_name(st), fcm_ctx_error_message(ctx));
        fcm_ctx_error_clear(ctx);
      }
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  test_direct(ctx);
  test_sim(ctx);
  test_small_cut(ctx);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
