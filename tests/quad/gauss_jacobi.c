/* Gauss–Jacobi rules on [-1, 1]: for several (alpha, beta) and n = 1..30 the
 * n-point rule integrates x^k (1-x)^alpha (1+x)^beta exactly for k <= 2n-1, and
 * not for k = 2n (checked for n <= 8, where the error is measurable); alpha = 150
 * exercises the overflow-safe weight mass. Nodes ascending and interior, weights
 * positive; closed-form nodes and weights of Gauss–Chebyshev (both kinds) and
 * small Gauss–Legendre rules; Legendre symmetry up to n = 200. `--report` prints
 * the worst errors.
 *
 * Exact moments I_k = int (1-x)^a (1+x)^b x^k dx come from the recurrence
 * (a+b+2+k) I_{k+1} = (b-a) I_k + k I_{k-1}, I_0 = 2^(a+b+1) B(a+1, b+1),
 * obtained by integrating d/dx[(1-x)^(a+1) (1+x)^(b+1) x^k] = 0 over [-1, 1]. Its
 * two terms never cancel: for b >= a every I_k > 0, for a > b the sign of I_k is
 * (-1)^k, and (a+b+2+k)|I_{k+1}| = |b-a||I_k| + k|I_{k-1}| either way; so the
 * relative error grows only like k ulp. For k <= 8 it is cross-checked against
 * the binomial expansion x^k = ((1+x) - 1)^k and Beta functions. */
#include "fcm/quad.h"
#include "test.h"

#define NMAX 30
#define KMAX (2 * NMAX + 1)
#define RTOL 1e-13
#define ZTOL 1e-14

/* int_{-1}^{1} (1-x)^a (1+x)^b dx = 2^(a+b+1) B(a+1, b+1); for integer a through
 * B(a+1, b+1) = prod_{i=1..a} i/(b+i) / (a+b+1), which stays finite where the
 * Gamma values overflow (a = 150). */
static double beta_int(double a, double b)
{
  if (a == floor(a)) {
    double p = 1.0;
    for (int i = 1; i <= (int)a; i++)
      p *= i / (b + i);
    return pow(2.0, a + b + 1.0) * p / (a + b + 1.0);
  }
  return pow(2.0, a + b + 1.0) * tgamma(a + 1.0) * tgamma(b + 1.0) / tgamma(a + b + 2.0);
}

static void exact_moments(double a, double b, int kmax, double *I)
{
  I[0] = beta_int(a, b);
  I[1] = (b - a) / (a + b + 2.0) * I[0];
  for (int k = 1; k < kmax; k++)
    I[k + 1] = ((b - a) * I[k] + k * I[k - 1]) / (a + b + 2.0 + k);
}

static double binomial_moment(double a, double b, int k)
{
  double s = 0.0, c = 1.0; /* c = C(k, j) */
  for (int j = 0; j <= k; j++) {
    s += c * ((k - j) % 2 ? -1.0 : 1.0) * beta_int(a, b + j);
    c = c * (k - j) / (j + 1);
  }
  return s;
}

int main(int argc, char **argv)
{
  int report = argc > 1 && !strcmp(argv[1], "--report");
  const double pairs[][2] = {{0, 0},     {1, 0},      {2, 0}, {0.5, -0.5}, {-0.5, -0.5},
                             {0.5, 0.5}, {-0.3, 1.7}, {0, 1}, {150, 0.5}};
  const int npairs = (int)(sizeof pairs / sizeof pairs[0]);
  const double pi = 3.14159265358979323846;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));

  for (int p = 0; p < npairs; p++) {
    double a = pairs[p][0], b = pairs[p][1], I[KMAX + 1], max_rel = 0.0, max_zero = 0.0;
    exact_moments(a, b, KMAX, I);
    for (int k = 0; k <= 8; k++)
      TEST_NEAR(I[k], binomial_moment(a, b, k), 1e-11, 1e-13);
    for (int n = 1; n <= NMAX; n++) {
      fcm_rule *r = NULL;
      TEST_OK(ctx, fcm_rule_create_gauss_jacobi(ctx, n, a, b, &r));
      if (!r) continue;
      const double *x = fcm_rule_points(r), *w = fcm_rule_weights(r);
      TEST_TRUE(fcm_rule_num_points(r) == n && fcm_rule_strength(r) == 2 * n - 1);
      TEST_TRUE(fcm_rule_shape(r) == FCM_SHAPE_LINE);
      TEST_TRUE(
          strstr(fcm_rule_description(r), a == 0 && b == 0 ? "Gauss-Legendre" : "Gauss-Jacobi"));
      for (int i = 0; i < n; i++) {
        TEST_TRUE(x[i] > -1.0 && x[i] < 1.0 && w[i] > 0.0);
        if (i > 0) TEST_TRUE(x[i] > x[i - 1]);
      }
      for (int k = 0; k <= 2 * n; k++) {
        double q = 0.0;
        for (int i = 0; i < n; i++)
          q += w[i] * pow(x[i], k);
        if (k == 2 * n) { /* one degree too many: not exact; the error exceeds 1e-9 for
                           * n <= 8 unless the weight is as concentrated as (1-x)^150 */
          if (n <= 8 && a < 10 && !(fabs(q - I[k]) > 1e-9 * fabs(I[k])))
            TEST_FAIL_("(%g,%g) n=%d: x^%d unexpectedly exact", a, b, n, k);
        } else if (a == b && k % 2) {
          double z = fabs(q) / I[0];
          max_zero = fmax(max_zero, z);
          if (!(z <= ZTOL)) TEST_FAIL_("(%g,%g) n=%d: odd moment %d = %.3g", a, b, n, k, q);
        } else {
          double rel = fabs(q - I[k]) / fabs(I[k]);
          max_rel = fmax(max_rel, rel);
          if (!(rel <= RTOL))
            TEST_FAIL_("(%g,%g) n=%d: moment %d = %.17g, exact %.17g, rel err %.3g", a, b, n, k, q,
                       I[k], rel);
        }
      }
      fcm_rule_destroy(&r);
    }
    if (report)
      printf("alpha %4g beta %4g n=1..%d: max rel moment error %.2e, max |odd moment|/mu0 %.2e\n",
             a, b, NMAX, max_rel, max_zero);
  }

  /* closed forms: Chebyshev first kind (-1/2,-1/2) x_i = -cos((2i+1)pi/(2n)), w = pi/n;
   * second kind (1/2,1/2) x_i = -cos((i+1)pi/(n+1)), w_i = pi/(n+1) sin^2((i+1)pi/(n+1)) */
  double max_cheb = 0.0;
  for (int n = 1; n <= NMAX; n++) {
    fcm_rule *r1 = NULL, *r2 = NULL;
    TEST_OK(ctx, fcm_rule_create_gauss_jacobi(ctx, n, -0.5, -0.5, &r1));
    TEST_OK(ctx, fcm_rule_create_gauss_jacobi(ctx, n, 0.5, 0.5, &r2));
    if (!r1 || !r2) break;
    for (int i = 0; i < n; i++) {
      double x1 = -cos((2 * i + 1) * pi / (2 * n)), t = (i + 1) * pi / (n + 1);
      double x2 = -cos(t), w2 = pi / (n + 1) * sin(t) * sin(t);
      TEST_NEAR(fcm_rule_points(r1)[i], x1, 0.0, 1e-15);
      TEST_NEAR(fcm_rule_weights(r1)[i], pi / n, 1e-13, 0.0);
      TEST_NEAR(fcm_rule_points(r2)[i], x2, 0.0, 1e-15);
      TEST_NEAR(fcm_rule_weights(r2)[i], w2, 1e-13, 0.0);
      max_cheb = fmax(max_cheb, fabs(fcm_rule_weights(r1)[i] - pi / n) / (pi / n));
      max_cheb = fmax(max_cheb, fabs(fcm_rule_weights(r2)[i] - w2) / w2);
    }
    fcm_rule_destroy(&r1);
    fcm_rule_destroy(&r2);
  }
  if (report) printf("Gauss-Chebyshev n=1..%d: max rel weight error %.2e\n", NMAX, max_cheb);

  /* small Gauss–Legendre rules in closed form */
  {
    fcm_rule *r = NULL;
    TEST_OK(ctx, fcm_rule_create_gauss_jacobi(ctx, 1, 0, 0, &r));
    if (r) {
      TEST_NEAR(fcm_rule_points(r)[0], 0.0, 0.0, 1e-16);
      TEST_NEAR(fcm_rule_weights(r)[0], 2.0, 1e-15, 0.0);
    }
    fcm_rule_destroy(&r);
    TEST_OK(ctx, fcm_rule_create_gauss_jacobi(ctx, 3, 0, 0, &r));
    if (r) {
      const double *x = fcm_rule_points(r), *w = fcm_rule_weights(r);
      TEST_NEAR(x[0], -sqrt(0.6), 1e-15, 0.0);
      TEST_NEAR(x[1], 0.0, 0.0, 1e-16);
      TEST_NEAR(x[2], sqrt(0.6), 1e-15, 0.0);
      TEST_NEAR(w[0], 5.0 / 9.0, 1e-15, 0.0);
      TEST_NEAR(w[1], 8.0 / 9.0, 1e-15, 0.0);
      TEST_NEAR(w[2], 5.0 / 9.0, 1e-15, 0.0);
    }
    fcm_rule_destroy(&r);
  }

  /* Legendre symmetry x_i = -x_{n-1-i}, w_i = w_{n-1-i}, and exactness, up to n = 200 */
  double max_big = 0.0;
  for (int n = 1; n <= 200; n += (n < 40 ? 1 : 40)) {
    fcm_rule *r = NULL;
    TEST_OK(ctx, fcm_rule_create_gauss_jacobi(ctx, n, 0, 0, &r));
    if (!r) break;
    const double *x = fcm_rule_points(r), *w = fcm_rule_weights(r);
    for (int i = 0; i < n; i++) {
      TEST_NEAR(x[i], -x[n - 1 - i], 0.0, 1e-15);
      TEST_NEAR(w[i], w[n - 1 - i], 1e-15, 0.0);
    }
    for (int k = 0; k < 2 * n; k += 2) {
      double q = 0.0;
      for (int i = 0; i < n; i++)
        q += w[i] * pow(x[i], k);
      max_big = fmax(max_big, fabs(q - 2.0 / (k + 1)) / (2.0 / (k + 1)));
      TEST_NEAR(q, 2.0 / (k + 1), 1e-12, 0.0);
    }
    fcm_rule_destroy(&r);
  }
  if (report) printf("Gauss-Legendre n<=200: max rel even-moment error %.2e\n", max_big);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
