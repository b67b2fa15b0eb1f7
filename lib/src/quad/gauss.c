/* Gauss–Jacobi rules on [-1, 1] for the weight (1-x)^alpha (1+x)^beta, and the
 * public fcm_rule_create_gauss_jacobi() built on them.
 *
 * Golub & Welsch (Math. Comp. 23, 1969): the nodes are the eigenvalues of the
 * symmetric tridiagonal Jacobi matrix with diagonal a_k and off-diagonal
 * sqrt(b_k) of the monic three-term recurrence p_{k+1} = (x - a_k) p_k - b_k p_{k-1}
 * (LAPACK dstev); the weights are mu0 times the squared first eigenvector
 * components. Each node is then polished by Newton steps on the orthonormal
 * polynomial q_n and the weight recomputed from the Christoffel function
 * w_i = 1 / sum_{k<n} q_k(x_i)^2: this brings the weights from ~1e-13 to ~1e-14
 * relative accuracy at n = 30 (the eigenvector weights lose accuracy where they
 * are small). For alpha = beta the rule is made exactly symmetric. */
#include "quad_impl.h"

#include "la/la_impl.h"

#include <math.h>
#include <stdio.h>

/* Recurrence coefficients a_k (k >= 0) and b_k (k >= 1) of the monic Jacobi
 * polynomials. The general formulas are 0/0 at k = 0 when alpha + beta = 0 and
 * at k = 1 when alpha + beta = -1; those terms use the cancelled forms. */
static double coef_a(int k, double al, double be)
{
  if (k == 0) return (be - al) / (al + be + 2.0);
  double s = 2.0 * k + al + be;
  return (be - al) * (be + al) / (s * (s + 2.0));
}

static double coef_b(int k, double al, double be)
{
  if (k == 1)
    return 4.0 * (1.0 + al) * (1.0 + be) / ((2.0 + al + be) * (2.0 + al + be) * (3.0 + al + be));
  double s = 2.0 * k + al + be;
  return 4.0 * k * (k + al) * (k + be) * (k + al + be) / (s * s * (s + 1.0) * (s - 1.0));
}

/* log Gamma(x) for x > 0 without lgamma(), which writes the global signgam (not
 * thread safe): shift to x >= 15, then Stirling's series (truncation < 1e-16). */
static double log_gamma(double x)
{
  double shift = 0.0;
  while (x < 15.0) {
    shift += log(x);
    x += 1.0;
  }
  double r = 1.0 / x, r2 = r * r;
  double series =
      r * (1.0 / 12 - r2 * (1.0 / 360 - r2 * (1.0 / 1260 - r2 * (1.0 / 1680 - r2 / 1188))));
  return (x - 0.5) * log(x) - x + 0.91893853320467274178 + series - shift;
}

/* Total mass mu0 = int_{-1}^{1} (1-x)^alpha (1+x)^beta dx
 *                = 2^(alpha+beta+1) Gamma(alpha+1) Gamma(beta+1) / Gamma(alpha+beta+2),
 * through tgamma while the Gamma values stay far from overflow. */
static double weight_mass(double al, double be)
{
  if (al + be + 2.0 < 150.0)
    return pow(2.0, al + be + 1.0) * tgamma(al + 1.0) * tgamma(be + 1.0) / tgamma(al + be + 2.0);
  return exp((al + be + 1.0) * log(2.0) + log_gamma(al + 1.0) + log_gamma(be + 1.0) -
             log_gamma(al + be + 2.0));
}

/* Orthonormal recurrence sb[k+1] q_{k+1} = (x - a_k) q_k - sb[k] q_{k-1}, q_0 = q0:
 * q_n(x), q_n'(x) and sum_{k<n} q_k(x)^2. */
static void eval_orthonormal(int n, const double *a, const double *sb, double q0, double x,
                             double *qn, double *dqn, double *sumsq)
{
  double qm = 0.0, q = q0, dm = 0.0, d = 0.0, s = 0.0;
  for (int k = 0; k < n; k++) {
    s += q * q;
    double qp = ((x - a[k]) * q - sb[k] * qm) / sb[k + 1];
    double dp = (q + (x - a[k]) * d - sb[k] * dm) / sb[k + 1];
    qm = q;
    q = qp;
    dm = d;
    d = dp;
  }
  *qn = q;
  *dqn = d;
  *sumsq = s;
}

fcm_status fcm__quad_gauss_jacobi(fcm_ctx *ctx, int n, double alpha, double beta, double *x,
                                  double *w)
{
  fcm_status st = FCM_OK;
  double *work = NULL, *a, *sb, *e, *z;
  double mu0, q0;
  FCM_CHECK(n >= 1 && n <= FCM__GAUSS_JACOBI_MAX_POINTS, ctx, FCM_ERR_ARG,
            "Gauss-Jacobi rule: n = %d points out of range [1, %d]", n,
            FCM__GAUSS_JACOBI_MAX_POINTS);
  FCM_CHECK(isfinite(alpha) && alpha > -1.0, ctx, FCM_ERR_ARG,
            "Gauss-Jacobi rule: alpha = %g must be finite and > -1", alpha);
  FCM_CHECK(isfinite(beta) && beta > -1.0, ctx, FCM_ERR_ARG,
            "Gauss-Jacobi rule: beta = %g must be finite and > -1", beta);
  mu0 = weight_mass(alpha, beta);
  FCM_CHECK(isfinite(mu0) && mu0 > 0.0 && isfinite(1.0 / sqrt(mu0)), ctx, FCM_ERR_ARG,
            "Gauss-Jacobi rule: weight mass %g for alpha = %g, beta = %g is not representable "
            "(alpha + beta too large)",
            mu0, alpha, beta);
  q0 = 1.0 / sqrt(mu0);

  /* work: a[n], sb[n+1], e[n], z[n*n] */
  FCM_ALLOC(ctx, (size_t)n * (size_t)n + 3 * (size_t)n + 1, work);
  a = work;
  sb = a + n;
  e = sb + n + 1;
  z = e + n;
  sb[0] = 0.0;
  for (int k = 0; k < n; k++) {
    a[k] = coef_a(k, alpha, beta);
    sb[k + 1] = sqrt(coef_b(k + 1, alpha, beta));
  }
  for (int k = 0; k < n; k++) {
    x[k] = a[k];
    e[k] = k + 1 < n ? sb[k + 1] : 0.0;
  }
  FCM_TRY(ctx, fcm__stev(ctx, n, x, e, z, n));

  for (int i = 0; i < n; i++) {
    /* Newton on q_n, accepting a step only while it stays well inside the gap to
     * the neighbouring eigenvalues (it is ~1e-16 in practice). */
    double lo = i > 0 ? x[i - 1] : -1.0, hi = i + 1 < n ? x[i + 1] : 1.0;
    double xi = x[i], qn, dq, ss;
    for (int it = 0; it < 3; it++) {
      eval_orthonormal(n, a, sb, q0, xi, &qn, &dq, &ss);
      if (!(dq != 0.0)) break;
      double dx = qn / dq, xn = xi - dx;
      if (!(fabs(dx) < 0.25 * (xi - lo) && fabs(dx) < 0.25 * (hi - xi))) break;
      xi = xn;
      if (fabs(dx) <= 2e-16 * fabs(xi)) break;
    }
    eval_orthonormal(n, a, sb, q0, xi, &qn, &dq, &ss);
    /* z holds the Golub–Welsch weight as a fallback should the sum be unusable */
    w[i] = ss > 0.0 && isfinite(ss) ? 1.0 / ss : mu0 * z[(size_t)i * n] * z[(size_t)i * n];
    e[i] = xi; /* keep the unpolished neighbours for the gap test of the next node */
  }
  for (int i = 0; i < n; i++)
    x[i] = e[i];

  if (alpha == beta) {
    for (int i = 0; i < n / 2; i++) {
      int j = n - 1 - i;
      double xs = 0.5 * (x[j] - x[i]), ws = 0.5 * (w[i] + w[j]);
      x[i] = -xs;
      x[j] = xs;
      w[i] = w[j] = ws;
    }
    if (n % 2) x[n / 2] = 0.0;
  }
  for (int i = 0; i < n; i++)
    FCM_CHECK(isfinite(x[i]) && isfinite(w[i]) && w[i] > 0.0 && x[i] > -1.0 && x[i] < 1.0, ctx,
              FCM_ERR_NUMERIC,
              "Gauss-Jacobi rule (n = %d, alpha = %g, beta = %g): node %d = %g, weight %g not "
              "finite, positive and inside (-1, 1)",
              n, alpha, beta, i, x[i], w[i]);
cleanup:
  fcm__free(ctx, work);
  return st;
}

fcm_status fcm_rule_create_gauss_jacobi(fcm_ctx *ctx, int n, double alpha, double beta,
                                        fcm_rule **rule)
{
  fcm_status st = FCM_OK;
  fcm_rule *r = NULL;
  FCM_CHECK(rule, ctx, FCM_ERR_ARG, "Gauss-Jacobi rule: output pointer is NULL");
  *rule = NULL;
  FCM_CHECK(ctx, ctx, FCM_ERR_ARG, "Gauss-Jacobi rule: context is NULL");
  FCM_CHECK(n >= 1 && n <= FCM__GAUSS_JACOBI_MAX_POINTS, ctx, FCM_ERR_ARG,
            "Gauss-Jacobi rule: n = %d points out of range [1, %d]", n,
            FCM__GAUSS_JACOBI_MAX_POINTS);
  FCM_TRY(ctx, fcm__quad_rule_alloc(ctx, FCM_SHAPE_LINE, 2 * n - 1, n, FCM_RULE_COMPUTED, &r));
  FCM_TRY(ctx, fcm__quad_gauss_jacobi(ctx, n, alpha, beta, r->points, r->weights));
  if (alpha == 0.0 && beta == 0.0)
    snprintf(r->description, sizeof r->description, "Gauss-Legendre %d", n);
  else
    snprintf(r->description, sizeof r->description, "Gauss-Jacobi %d (alpha %.17g, beta %.17g)", n,
             alpha, beta);
  *rule = r;
  r = NULL;
cleanup:
  fcm_rule_destroy(&r);
  return st;
}
