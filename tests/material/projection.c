/* Positive semi-definite projection of the tangent, run once per model (argv[1]),
 * for four (E, nu) sets and 60 deformation gradients each:
 *  - the projected tangent is symmetric positive semi-definite: its LAPACK eigenvalues
 *    are >= -1e-12 x the largest;
 *  - it equals the reference projection (LAPACK eigen-decomposition of the unprojected
 *    tangent, eigenvalues clamped at 0) to 1e-9 relative; since that projection is
 *    1-Lipschitz, this checks the analytic eigensystem independently;
 *  - Psi and P do not depend on the projection flag, nor on whether the tangent is asked for
 *    in the same call, and the projected tangent not on whether Psi and P are (bitwise: the
 *    assembly evaluates a projected fictitious point in one call);
 *  - the unprojected tangent through the analytic eigensystem equals the closed form
 *    (StVK, SNH) to 1e-10 relative;
 *  - an already positive semi-definite tangent (F = I, a moderate stretch, and for the
 *    linear model every F) is unchanged (1e-12 relative); the premise is checked;
 *  - for the nonlinear models some sampled tangents are indefinite, so the clamp is used. */
#include "la/la_impl.h"
#include "material/material_impl.h"
#include "material_test_util.h"

static fcm_material_params params;

/* Eigenvalues (ascending) and, with V non-NULL, eigenvectors of the symmetric 9x9 A. */
static void eig9(fcm_ctx *ctx, const double A[81], double w[9], double V[81])
{
  double a[81];
  memcpy(a, A, sizeof a);
  TEST_OK(ctx, fcm__syev(ctx, V != NULL, 9, a, 9, w));
  if (V) memcpy(V, a, sizeof a);
}

/* Reference projection: V diag(max(w, 0)) V^T (column-major eigenvectors). */
static void reference_projection(fcm_ctx *ctx, const double D[81], double Dref[81])
{
  double w[9], V[81];
  eig9(ctx, D, w, V);
  for (int x = 0; x < 9; x++)
    for (int y = 0; y < 9; y++) {
      double v = 0.0;
      for (int k = 0; k < 9; k++)
        v += V[9 * k + x] * fmax(w[k], 0.0) * V[9 * k + y];
      Dref[9 * x + y] = v;
    }
}

static double max_diff(const double *a, const double *b, int n)
{
  double m = 0.0;
  for (int i = 0; i < n; i++)
    m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

/* Returns 1 when the unprojected tangent at F is indefinite. */
static int check_projection(fcm_ctx *ctx, int n, const double F[9])
{
  fcm_material_params pp = params;
  pp.project_psd = 1;
  double psi, P[9], D[81], psip, Pp[9], Dp[81], Dref[81], w[9];
  fcm_material_eval(&params, F, &psi, P, D);
  fcm_material_eval(&pp, F, &psip, Pp, Dp);
  TEST_TRUE(psip == psi);
  TEST_TRUE(memcmp(Pp, P, sizeof P) == 0);
  {
    double psi1, P1[9], D1[81];
    fcm_material_eval(&params, F, &psi1, P1, NULL);
    fcm_material_eval(&pp, F, NULL, NULL, D1);
    TEST_TRUE(psi1 == psi && memcmp(P1, P, sizeof P) == 0 && memcmp(D1, Dp, sizeof D1) == 0);
  }
  const double scale = max_abs(D, 81);

  eig9(ctx, Dp, w, NULL);
  if (!(w[0] >= -1e-12 * fabs(w[8])))
    TEST_FAIL_("F #%d (%s): projected tangent has eigenvalue %.3g (largest %.3g)", n,
               f_kind_name[n % F_KINDS], w[0], w[8]);
  for (int x = 0; x < 9; x++)
    for (int y = 0; y < x; y++)
      TEST_NEAR(Dp[9 * x + y], Dp[9 * y + x], 0.0, 1e-12 * scale);

  reference_projection(ctx, D, Dref);
  double err = max_diff(Dp, Dref, 81);
  if (!(err <= 1e-9 * scale))
    TEST_FAIL_("F #%d (%s): projection differs from the LAPACK reference by %.3g (scale %.3g)", n,
               f_kind_name[n % F_KINDS], err, scale);

  if (params.model == FCM_MATERIAL_STVK || params.model == FCM_MATERIAL_STABLE_NEO_HOOKEAN) {
    double Ds[81];
    fcm__material_eval_svd(&params, F, NULL, NULL, Ds);
    err = max_diff(Ds, D, 81);
    if (!(err <= 1e-10 * scale))
      TEST_FAIL_("F #%d (%s): eigensystem tangent differs from the closed form by %.3g", n,
                 f_kind_name[n % F_KINDS], err);
  }
  eig9(ctx, D, w, NULL);
  return w[0] < -1e-8 * fabs(w[8]);
}

/* A positive semi-definite tangent must come back unchanged. */
static void check_unchanged(fcm_ctx *ctx, const double F[9], const char *what)
{
  fcm_material_params pp = params;
  pp.project_psd = 1;
  double D[81], Dp[81], w[9];
  fcm_material_eval(&params, F, NULL, NULL, D);
  fcm_material_eval(&pp, F, NULL, NULL, Dp);
  eig9(ctx, D, w, NULL);
  const double scale = max_abs(D, 81);
  if (!(w[0] >= -1e-12 * w[8])) {
    TEST_FAIL_("%s: test premise broken, tangent has eigenvalue %.3g", what, w[0]);
    return;
  }
  double err = max_diff(Dp, D, 81);
  if (!(err <= 1e-12 * scale))
    TEST_FAIL_("%s: projection changed a PSD tangent by %.3g (scale %.3g)", what, err, scale);
}

int main(int argc, char **argv)
{
  int model = model_from_args(argc, argv);
  if (model < 0) {
    fprintf(stderr, "usage: %s linear|stvk|corotated|snh\n", argv[0]);
    return 2;
  }
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  int indefinite = 0;
  for (int ps = 0; ps < NUM_PARAM_SETS; ps++) {
    fcm_material mat = {(fcm_material_model)model, param_sets[ps][0], param_sets[ps][1], 1.0};
    TEST_OK(ctx, fcm_material_setup(ctx, &mat, &params));
    for (int n = 0; n < 60; n++) {
      double F[9];
      test_F(n, F);
      indefinite += check_projection(ctx, n, F);
      if (model == FCM_MATERIAL_LINEAR) check_unchanged(ctx, F, "linear");
    }
    /* Moderate stretch; for SNH with J = alpha (where lambda'(J - alpha) = 0, so every
     * eigenvalue is positive: SNH's flip modes soften under volume growth). */
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double s[3] = {1.15, 1.25, 1.35}, F[9];
    if (model == FCM_MATERIAL_STABLE_NEO_HOOKEAN)
      s[0] = 1.1, s[1] = 0.95, s[2] = params.snh_alpha / (1.1 * 0.95);
    check_unchanged(ctx, I, "F = I");
    compose_F(s, F);
    check_unchanged(ctx, F, "moderate stretch");
  }
  if (model == FCM_MATERIAL_LINEAR)
    TEST_TRUE(indefinite == 0);
  else
    TEST_TRUE(indefinite >= 10);
  fcm_ctx_destroy(&ctx);
  TEST_TRUE(ctx == NULL);
  return TEST_RESULT();
}
