/* The moment space with a degree cap per variable (fcm_simplify_options.axis_degree): total
 * degree <= m and a, b, c <= q; q = 2, m = 6 is the tensor space Q_2 of a Hex8 mass integrand.
 * Asserts
 * - its size: 27 for (6, 2), 84 for (6, 6) and (6, -1), 105 for (8, 4), 20 for (3, 3);
 * - the capped basis at a point is exactly T_a T_b T_c over the (a, b, c) of the space in
 *   degree order (a descending, then b), the last of Q_2 being T_2 T_2 T_2, and equals the
 *   uncapped basis on the rows fcm__simplify_basis_rows() names (bit for bit);
 * - the blocked basis values and moments (fcm__simplify_basis_points, fcm__simplify_moments,
 *   on a short block and on full ones) agree with the point-wise basis (1e-13);
 * - fcm_simplify() with axis_degree 2 at strength 6 keeps at most 27 points, positive weights,
 *   every monomial of Q_2 (x^2 y^2 z^2 included) within 1e-12 relative, and without the cap at
 *   most 84; an axis_degree outside [0, 20] is FCM_ERR_ARG. */
#include "simplify/simplify_impl.h"
#include "simplify_util.h"

#include <math.h>
#include <string.h>

static double cheb(int k, double s)
{
  double t0 = 1.0, t1 = s;
  if (k == 0) return 1.0;
  for (int i = 2; i <= k; i++) {
    const double t2 = 2.0 * s * t1 - t0;
    t0 = t1, t1 = t2;
  }
  return t1;
}

static void sizes(void)
{
  TEST_TRUE(fcm__simplify_space_size(6, 2) == 27);
  TEST_TRUE(fcm__simplify_space_size(6, 6) == 84);
  TEST_TRUE(fcm__simplify_space_size(6, -1) == 84);
  TEST_TRUE(fcm__simplify_space_size(8, 4) == 105);
  TEST_TRUE(fcm__simplify_space_size(3, 3) == 20);
  TEST_TRUE(fcm__simplify_space_size(2, 2) == 10);
}

static void basis(void)
{
  static double p[3 * 300];
  uint64_t s = 7;
  for (int j = 0; j < 3 * 300; j++)
    p[j] = 0.3 + 0.6 * util_rand(&s);
  fcm__cheb_box top, q2;
  fcm__simplify_box(6, 300, p, &top);
  q2 = top;
  fcm__simplify_box_cap(&q2, 2);
  TEST_TRUE(q2.num_basis == 27 && q2.m == 6 && q2.q == 2 && top.num_basis == 84);
  double phi[84], phit[84];
  int rows[84];
  fcm__simplify_basis_rows(&top, &q2, rows);
  for (int j = 0; j < 300; j += 37) {
    const double *x = p + 3 * j;
    fcm__simplify_basis_eval(&q2, x, phi);
    fcm__simplify_basis_eval(&top, x, phit);
    int i = 0;
    for (int deg = 0; deg <= 6; deg++)
      for (int a = deg; a >= 0; a--)
        for (int b = deg - a; b >= 0; b--) {
          const int c = deg - a - b;
          if (a > 2 || b > 2 || c > 2) continue;
          const double v = cheb(a, q2.scale[0] * x[0] + q2.shift[0]) *
                           cheb(b, q2.scale[1] * x[1] + q2.shift[1]) *
                           cheb(c, q2.scale[2] * x[2] + q2.shift[2]);
          TEST_NEAR(phi[i], v, 0.0, 1e-13);
          TEST_TRUE(phi[i] == phit[rows[i]]);
          i++;
        }
    TEST_TRUE(i == 27);
  }
  /* blocked values and moments, a short block (n = 10) and full ones (n = 300) */
  static double P[27 * 300], work[16384], w[300];
  TEST_TRUE(fcm__simplify_moments_scratch(6) <= sizeof work / sizeof *work);
  for (int j = 0; j < 300; j++)
    w[j] = 0.5 + util_rand(&s);
  const int ns[2] = {10, 300};
  for (int t = 0; t < 2; t++) {
    const int n = ns[t];
    double mom[27], ref[27] = {0};
    fcm__simplify_basis_points(&q2, n, p, P, work);
    fcm__simplify_moments(&q2, n, p, NULL, w, mom, work);
    for (int j = 0; j < n; j++) {
      fcm__simplify_basis_eval(&q2, p + 3 * j, phi);
      for (int i = 0; i < 27; i++) {
        TEST_NEAR(P[27 * (size_t)j + i], phi[i], 0.0, 1e-13);
        ref[i] += w[j] * phi[i];
      }
    }
    for (int i = 0; i < 27; i++)
      TEST_NEAR(mom[i], ref[i], 1e-13, 1e-13);
  }
}

/* Moments of x^a y^b z^c, a, b, c <= 2, of the rule (n points). */
static void q2_moments(int n, const double *x, const double *w, const fcm_index *idx, double *mom,
                       double *absum)
{
  memset(mom, 0, 27 * sizeof *mom);
  memset(absum, 0, 27 * sizeof *absum);
  for (int j = 0; j < n; j++) {
    const double *y = x + 3 * (idx ? idx[j] : j);
    int i = 0;
    for (int a = 0; a <= 2; a++)
      for (int b = 0; b <= 2; b++)
        for (int c = 0; c <= 2; c++, i++) {
          const double t = w[j] * pow(y[0], a) * pow(y[1], b) * pow(y[2], c);
          mom[i] += t, absum[i] += fabs(t);
        }
  }
}

static void simplify(fcm_ctx *ctx)
{
  enum { N = 400 };
  static double x[3 * N], w[N];
  const double lo[3] = {-0.4, 0.1, 0.2};
  util_random_box(3, N, lo, 0.7, 1.0, x, w);
  fcm_simplify_options o = fcm_simplify_options_default();
  TEST_TRUE(o.axis_degree == FCM_DEFAULT);
  for (int cap = 0; cap < 2; cap++) {
    o.axis_degree = cap ? 2 : FCM_DEFAULT;
    fcm_simplify_result res;
    fcm_simplify_info info;
    TEST_OK(ctx, fcm_simplify(ctx, 6, N, x, w, &o, &res, &info));
    TEST_TRUE(info.num_basis == (cap ? 27 : 84) && !info.fallback && !info.skipped);
    TEST_TRUE(res.count >= 1 && res.count <= info.num_basis);
    for (fcm_index j = 0; j < res.count; j++)
      TEST_TRUE(res.weights[j] > 0.0);
    double m0[27], a0[27], m1[27], a1[27];
    q2_moments(N, x, w, NULL, m0, a0);
    q2_moments((int)res.count, x, res.weights, res.indices, m1, a1);
    for (int i = 0; i < 27; i++) /* the last one: x^2 y^2 z^2 */
      TEST_NEAR(m1[i], m0[i], 0.0, 1e-12 * fmax(a0[i], a1[i]));
    fcm_simplify_result_destroy(&res);
  }
  fcm_simplify_result res;
  o.axis_degree = 21;
  TEST_TRUE(fcm_simplify(ctx, 6, N, x, w, &o, &res, NULL) == FCM_ERR_ARG);
  o.axis_degree = -2;
  TEST_TRUE(fcm_simplify(ctx, 6, N, x, w, &o, &res, NULL) == FCM_ERR_ARG);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  sizes();
  basis();
  simplify(ctx);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
