/* Material conformance, run once per model (argv[1] = "linear", "stvk", "corotated",
 * "snh"), for four (E, nu) sets and 60 deformation gradients each (generic, inverted,
 * near-singular with smallest singular value 1e-6, rotations, repeated singular values,
 * large stretch):
 *  - P equals the central difference of Psi and dP/dF the central difference of P,
 *    to 1e-6 relative (max-norm, scale max(|P|, mu) resp. max(|dPdF|, mu));
 *  - the tangent has major symmetry dP_ij/dF_kl = dP_kl/dF_ij (1e-12 relative);
 *  - any subset of outputs (NULL for the others) gives bitwise the same values;
 *  - P(I) = 0, and for the rotation-invariant models P(R) = 0 (1e-12 relative),
 *    Psi(R) = Psi(I) and frame indifference P(QF) = Q P(F);
 *  - the tangent at F = I equals the small-strain tensor of the textbook Lame
 *    parameters of (E, nu) (catches a wrong Lame or SNH conversion); at a rotation R
 *    it is that tensor rotated, dP(R)[dF] = R C[R^T dF];
 *  - Psi(I) = 0, for SNH the documented constant lambda'/2 (1 - alpha)^2 - mu'/2 log 4. */
#include "material/material_impl.h"
#include "material_test_util.h"

static fcm_material_params params;
static double mu_ref, lambda_ref;

/* Max-norm relative error of a against b with the given scale floor. */
static void check_close(const char *what, int n, const double *a, const double *b, int len,
                        double rel, double floor)
{
  double err = 0.0, scale = fmax(max_abs(b, len), floor);
  for (int i = 0; i < len; i++)
    err = fmax(err, fabs(a[i] - b[i]));
  if (!(err <= rel * scale))
    TEST_FAIL_("%s, F #%d (%s): max error %.3g > %.1g x scale %.3g", what, n,
               f_kind_name[n % F_KINDS], err, rel, scale);
}

static void check_fd(int n, const double F[9])
{
  const double h = 1e-5;
  double psi, P[9], D[81], Pfd[9], Dfd[81];
  fcm_material_eval(&params, F, &psi, P, D);
  for (int x = 0; x < 9; x++) {
    double Fp[9], Fm[9], psip, psim, Pp[9], Pm[9];
    memcpy(Fp, F, sizeof Fp);
    memcpy(Fm, F, sizeof Fm);
    Fp[x] += h, Fm[x] -= h;
    fcm_material_eval(&params, Fp, &psip, Pp, NULL);
    fcm_material_eval(&params, Fm, &psim, Pm, NULL);
    Pfd[x] = (psip - psim) / (2.0 * h);
    for (int y = 0; y < 9; y++)
      Dfd[9 * y + x] = (Pp[y] - Pm[y]) / (2.0 * h);
  }
  check_close("P vs FD of Psi", n, P, Pfd, 9, 1e-6, params.mu);
  check_close("dPdF vs FD of P", n, D, Dfd, 81, 1e-6, params.mu);

  const double dmax = max_abs(D, 81);
  for (int x = 0; x < 9; x++)
    for (int y = 0; y < x; y++)
      TEST_NEAR(D[9 * x + y], D[9 * y + x], 0.0, 1e-12 * dmax);

  /* Subsets of outputs: bitwise identical. */
  double psi1, P1[9], D1[81];
  fcm_material_eval(&params, F, &psi1, NULL, NULL);
  fcm_material_eval(&params, F, NULL, P1, NULL);
  fcm_material_eval(&params, F, NULL, NULL, D1);
  fcm_material_eval(&params, F, NULL, NULL, NULL);
  TEST_TRUE(psi1 == psi);
  TEST_TRUE(memcmp(P1, P, sizeof P) == 0);
  TEST_TRUE(memcmp(D1, D, sizeof D) == 0);
}

/* B = Q A (3x3). */
static void rotate_left(const double Q[9], const double A[9], double B[9])
{
  fcm__mat3_mul(Q, A, B);
}

static void check_rest_and_invariance(int model)
{
  const int invariant = model != FCM_MATERIAL_LINEAR;
  const double stress_scale = params.mu + fabs(params.lambda);
  const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double psi0, P[9], D[81], C[81];
  fcm_material_eval(&params, I, &psi0, P, D);
  for (int i = 0; i < 9; i++)
    TEST_NEAR(P[i], 0.0, 0.0, 1e-12 * stress_scale);

  /* Energy at rest, from (E, nu) and the lib/METHOD.md §8 constants written out here. */
  double psi_rest = 0.0;
  if (model == FCM_MATERIAL_STABLE_NEO_HOOKEAN) {
    double ms = 4.0 * mu_ref / 3.0, ls = lambda_ref + 5.0 * mu_ref / 6.0;
    double alpha = 1.0 + 3.0 * ms / (4.0 * ls);
    psi_rest = 0.5 * ls * (1.0 - alpha) * (1.0 - alpha) - 0.5 * ms * log(4.0);
  }
  TEST_NEAR(psi0, psi_rest, 1e-12, 1e-14 * stress_scale);

  /* Linearization at rest: the small-strain tensor of the textbook Lame parameters. */
  linear_tangent(mu_ref, lambda_ref, C);
  for (int i = 0; i < 81; i++)
    TEST_NEAR(D[i], C[i], 0.0, 1e-12 * stress_scale);
  if (!invariant) return;

  for (int r = 0; r < 20; r++) {
    double R[9], psi, PR[9], DR[81];
    random_rotation(R);
    fcm_material_eval(&params, R, &psi, PR, DR);
    for (int i = 0; i < 9; i++)
      TEST_NEAR(PR[i], 0.0, 0.0, 1e-12 * stress_scale);
    TEST_NEAR(psi, psi0, 0.0, 1e-12 * stress_scale);
    /* dP(R)[dF] = R C[R^T dF]: entry (ij, kl) = sum_ab R_ia C_(aj)(bl) R_kb. */
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        for (int k = 0; k < 3; k++)
          for (int l = 0; l < 3; l++) {
            double v = 0.0;
            for (int a = 0; a < 3; a++)
              for (int b = 0; b < 3; b++)
                v += R[3 * i + a] * C[9 * (3 * a + j) + 3 * b + l] * R[3 * k + b];
            TEST_NEAR(DR[9 * (3 * i + j) + 3 * k + l], v, 0.0, 1e-11 * stress_scale);
          }
  }
  /* Frame indifference at random F: P(QF) = Q P(F), Psi(QF) = Psi(F). */
  for (int n = 0; n < 30; n++) {
    double F[9], Q[9], QF[9], psi, psiq, PF[9], PQ[9], QP[9];
    test_F(n, F);
    random_rotation(Q);
    rotate_left(Q, F, QF);
    fcm_material_eval(&params, F, &psi, PF, NULL);
    fcm_material_eval(&params, QF, &psiq, PQ, NULL);
    rotate_left(Q, PF, QP);
    double scale = fmax(max_abs(PF, 9), params.mu);
    for (int i = 0; i < 9; i++)
      TEST_NEAR(PQ[i], QP[i], 0.0, 1e-11 * scale);
    TEST_NEAR(psiq, psi, 1e-11, 1e-11 * params.mu);
  }
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
  int counts[F_KINDS] = {0}, inverted = 0;
  for (int ps = 0; ps < NUM_PARAM_SETS; ps++) {
    fcm_material mat = {(fcm_material_model)model, param_sets[ps][0], param_sets[ps][1], 1000.0};
    TEST_OK(ctx, fcm_material_setup(ctx, &mat, &params));
    textbook_lame(mat.young, mat.poisson, &mu_ref, &lambda_ref);
    for (int n = 0; n < 60; n++) {
      double F[9];
      counts[test_F(n, F)]++;
      if (fcm__mat3_det(F) < 0.0) inverted++;
      check_fd(n, F);
    }
    check_rest_and_invariance(model);
  }
  /* The sample is what the header promises (>= 50 per model and set, every kind). */
  for (int k = 0; k < F_KINDS; k++)
    TEST_TRUE(counts[k] >= 8 * NUM_PARAM_SETS);
  TEST_TRUE(inverted >= 15 * NUM_PARAM_SETS);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
