/* Benchmark of the material kernels (label "bench"): nanoseconds per evaluation of
 * Psi + P, Psi + P + dP/dF, and with the tangent projected to PSD, for every model,
 * through the public fcm_material_eval() and the inlined fcm__material_eval(); and,
 * for comparison, the generic route (LAPACK dsyevd of the 9x9 tangent, clamp, rebuild). */
#include "la/la_impl.h"
#include "material/material_impl.h"
#include "material_test_util.h"

#define NF   64
#define REPS 200000

static volatile double sink; /* keeps the loops from being optimized away */

static double time_eval(const fcm_material_params *p, double F[NF][9], int tangent, int inl)
{
  double best = INFINITY, s = 0.0, psi, P[9], D[81];
  for (int trial = 0; trial < 3; trial++) { /* best of three: the machine may be shared */
    double t0 = fcm_wtime();
    for (int r = 0; r < REPS; r++) {
      const double *f = F[r % NF];
      if (inl)
        fcm__material_eval(p, f, &psi, P, tangent ? D : NULL);
      else
        fcm_material_eval(p, f, &psi, P, tangent ? D : NULL);
      s += psi + P[r % 9] + (tangent ? D[r % 81] : 0.0);
    }
    best = fmin(best, 1e9 * (fcm_wtime() - t0) / REPS);
  }
  sink = s;
  return best;
}

/* The generic projection of an SNH tangent: fcm__syev + clamp + V diag V^T. */
static double time_lapack(const fcm_material_params *p, double F[NF][9])
{
  fcm_ctx *ctx = NULL;
  double best = INFINITY, s = 0.0, D[81], w[9];
  const int reps = REPS / 10;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return NAN;
  for (int trial = 0; trial < 3; trial++) {
    double t0 = fcm_wtime();
    for (int r = 0; r < reps; r++) {
      fcm_material_eval(p, F[r % NF], NULL, NULL, D);
      if (fcm__syev(ctx, 1, 9, D, 9, w) != FCM_OK) return NAN;
      double Dp[81];
      for (int x = 0; x < 9; x++)
        for (int y = x; y < 9; y++) {
          double v = 0.0;
          for (int k = 0; k < 9; k++)
            v += D[9 * k + x] * fmax(w[k], 0.0) * D[9 * k + y];
          Dp[9 * x + y] = Dp[9 * y + x] = v;
        }
      s += Dp[r % 81];
    }
    best = fmin(best, 1e9 * (fcm_wtime() - t0) / reps);
  }
  fcm_ctx_destroy(&ctx);
  sink = s;
  return best;
}

int main(void)
{
  static double F[NF][9];
  for (int n = 0; n < NF; n++)
    test_F(n, F[n]);
  printf("%-10s %-7s %10s %12s %14s\n", "model", "call", "psi+P", "+tangent", "+projection");
  for (int m = 0; m < FCM_MATERIAL_COUNT; m++) {
    fcm_material mat = {(fcm_material_model)m, 3e6, 0.4, 1000.0};
    fcm_material_params p, pp;
    if (fcm_material_setup(NULL, &mat, &p) != FCM_OK) return 1;
    pp = p;
    pp.project_psd = 1;
    for (int inl = 0; inl < 2; inl++)
      printf("%-10s %-7s %10.1f %12.1f %14.1f\n", fcm_material_model_name(mat.model),
             inl ? "inline" : "public", time_eval(&p, F, 0, inl), time_eval(&p, F, 1, inl),
             time_eval(&pp, F, 1, inl));
    if (m == FCM_MATERIAL_STABLE_NEO_HOOKEAN)
      printf("%-10s %-7s %10s %12s %14.1f\n", "snh", "lapack", "", "", time_lapack(&p, F));
  }
  return 0;
}
