/* Material error paths and defined behaviour on bad input: invalid parameters give
 * FCM_ERR_ARG with a message naming the value and the range; model names map both
 * ways; the setup derives the textbook Lame parameters and the lib/METHOD.md §8 SNH constants;
 * a NaN or infinite F (and an invalid model in the parameters) yields NaN in every
 * requested output for every model, with and without projection, while a finite
 * degenerate F (zero, rank one, -I) gives finite outputs; nothing allocates. */
#include "material_test_util.h"

static int all_nan(double psi, const double *P, const double *D)
{
  int ok = isnan(psi);
  for (int i = 0; i < 9; i++)
    ok = ok && isnan(P[i]);
  for (int i = 0; i < 81; i++)
    ok = ok && isnan(D[i]);
  return ok;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  fcm_material_params p;
  const fcm_material good = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 3e6, 0.4, 1000.0};

  /* Validation. */
  TEST_OK(ctx, fcm_material_validate(ctx, &good));
  fcm_material m = good;
  m.young = -1.0;
  TEST_ERR(ctx, fcm_material_validate(ctx, &m), FCM_ERR_ARG, "E = -1 must be positive");
  m.young = NAN;
  TEST_ERR(ctx, fcm_material_setup(ctx, &m, &p), FCM_ERR_ARG, "E = nan");
  m.young = INFINITY;
  TEST_ERR(ctx, fcm_material_validate(ctx, &m), FCM_ERR_ARG, "finite");
  m = good, m.poisson = 0.5;
  TEST_ERR(ctx, fcm_material_validate(ctx, &m), FCM_ERR_ARG, "nu = 0.5 must lie in (-1, 0.5)");
  m.poisson = -1.0;
  TEST_ERR(ctx, fcm_material_validate(ctx, &m), FCM_ERR_ARG, "nu = -1 must lie in (-1, 0.5)");
  m = good, m.density = -3.0;
  TEST_ERR(ctx, fcm_material_validate(ctx, &m), FCM_ERR_ARG, "density = -3 must be non-negative");
  m = good, m.model = (fcm_material_model)7;
  TEST_ERR(ctx, fcm_material_validate(ctx, &m), FCM_ERR_ARG, "model = 7 out of range [0, 5)");
  m.model = (fcm_material_model)-1;
  TEST_ERR(ctx, fcm_material_setup(ctx, &m, &p), FCM_ERR_ARG, "model = -1");
  TEST_ERR(ctx, fcm_material_validate(ctx, NULL), FCM_ERR_ARG, "NULL");
  TEST_ERR(ctx, fcm_material_setup(ctx, &good, NULL), FCM_ERR_ARG, "NULL");
  TEST_TRUE(fcm_material_validate(NULL, &m) == FCM_ERR_ARG); /* no context: still safe */

  /* A failed setup leaves params unchanged. */
  memset(&p, 0x5a, sizeof p);
  fcm_material_params before = p;
  m = good, m.poisson = 0.7;
  TEST_ERR(ctx, fcm_material_setup(ctx, &m, &p), FCM_ERR_ARG, "nu = 0.7");
  TEST_TRUE(memcmp(&p, &before, sizeof p) == 0);

  /* Setup: textbook Lame parameters, lib/METHOD.md §8 SNH constants, projection off. */
  TEST_OK(ctx, fcm_material_setup(ctx, &good, &p));
  double mu, lambda;
  textbook_lame(3e6, 0.4, &mu, &lambda);
  TEST_NEAR(p.mu, mu, 1e-15, 0.0);
  TEST_NEAR(p.lambda, lambda, 1e-15, 0.0);
  TEST_NEAR(p.snh_mu, 4.0 * mu / 3.0, 1e-15, 0.0);
  TEST_NEAR(p.snh_lambda, lambda + 5.0 * mu / 6.0, 1e-15, 0.0);
  TEST_NEAR(p.snh_alpha, 1.0 + 3.0 * p.snh_mu / (4.0 * p.snh_lambda), 1e-15, 0.0);
  TEST_TRUE(p.density == 1000.0 && p.project_psd == 0 && p.model == good.model);

  /* Names. */
  fcm_material_model model = FCM_MATERIAL_LINEAR;
  const char *names[] = {"linear", "stvk", "corotated", "snh", "corotated_linear"};
  for (int k = 0; k < FCM_MATERIAL_COUNT; k++) {
    TEST_TRUE(strcmp(fcm_material_model_name((fcm_material_model)k), names[k]) == 0);
    TEST_OK(ctx, fcm_material_model_parse(ctx, names[k], &model));
    TEST_TRUE(model == (fcm_material_model)k);
  }
  TEST_TRUE(fcm_material_model_parse(ctx, "stable_neo_hookean", &model) == FCM_OK &&
            model == FCM_MATERIAL_STABLE_NEO_HOOKEAN);
  TEST_TRUE(fcm_material_model_name(FCM_MATERIAL_COUNT) == NULL);
  TEST_TRUE(fcm_material_model_name((fcm_material_model)-2) == NULL);
  model = FCM_MATERIAL_STVK;
  TEST_ERR(ctx, fcm_material_model_parse(ctx, "neohookean", &model), FCM_ERR_ARG,
           "unknown model \"neohookean\" (valid: linear, stvk");
  TEST_TRUE(model == FCM_MATERIAL_STVK);
  TEST_ERR(ctx, fcm_material_model_parse(ctx, "SNH", &model), FCM_ERR_ARG, "\"SNH\"");
  TEST_ERR(ctx, fcm_material_model_parse(ctx, NULL, &model), FCM_ERR_ARG, "NULL");
  TEST_ERR(ctx, fcm_material_model_parse(ctx, "snh", NULL), FCM_ERR_ARG, "NULL");

  /* Non-finite F: every requested output NaN, every model, with and without projection. */
  const double bad[3] = {NAN, INFINITY, -INFINITY};
  for (int k = 0; k < FCM_MATERIAL_COUNT; k++)
    for (int proj = 0; proj < 2; proj++)
      for (int b = 0; b < 3; b++)
        for (int pos = 0; pos < 9; pos += 4) {
          fcm_material mk = good;
          mk.model = (fcm_material_model)k;
          TEST_OK(ctx, fcm_material_setup(ctx, &mk, &p));
          p.project_psd = proj;
          double F[9] = {1.1, 0.1, 0, 0.2, 0.9, 0, 0, 0.3, 1.0}, psi = 0.0, P[9] = {0}, D[81] = {0};
          F[pos] = bad[b];
          fcm_material_eval(&p, F, &psi, P, D);
          if (!all_nan(psi, P, D))
            TEST_FAIL_("model %s, projection %d, F[%d] = %g: outputs not all NaN", names[k], proj,
                       pos, bad[b]);
          fcm_material_eval(&p, F, NULL, NULL, NULL); /* nothing requested: no crash */
        }
  /* Finite but degenerate F (collapsed, rank one, F = -I where the corotated R is not
   * differentiable): finite outputs for every model, with and without projection. */
  {
    const double degenerate[3][9] = {
        {0}, {1, 2, 3, 2, 4, 6, -1, -2, -3}, {-1, 0, 0, 0, -1, 0, 0, 0, -1}};
    for (int k = 0; k < FCM_MATERIAL_COUNT; k++)
      for (int proj = 0; proj < 2; proj++)
        for (int d = 0; d < 3; d++) {
          fcm_material mk = good;
          mk.model = (fcm_material_model)k;
          TEST_OK(ctx, fcm_material_setup(ctx, &mk, &p));
          p.project_psd = proj;
          double psi, P[9], D[81];
          int finite = 1;
          fcm_material_eval(&p, degenerate[d], &psi, P, D);
          finite = isfinite(psi);
          for (int i = 0; i < 9; i++)
            finite = finite && isfinite(P[i]);
          for (int i = 0; i < 81; i++)
            finite = finite && isfinite(D[i]);
          if (!finite)
            TEST_FAIL_("model %s, projection %d, degenerate F #%d: non-finite output", names[k],
                       proj, d);
        }
  }
  /* Invalid model in hand-made params: NaN, no crash. */
  TEST_OK(ctx, fcm_material_setup(ctx, &good, &p));
  p.model = (fcm_material_model)99;
  {
    const double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double psi, P[9], D[81];
    for (int proj = 0; proj < 2; proj++) {
      p.project_psd = proj;
      fcm_material_eval(&p, F, &psi, P, D);
      TEST_TRUE(all_nan(psi, P, D));
    }
  }

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
