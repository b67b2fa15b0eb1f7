/* Shared checks of the quad tests: exact monomial integrals on the reference
 * shapes from closed formulas, and the rule checks (exactness, positivity, interior). */
#ifndef FCM_TEST_QUAD_MOMENTS_H
#define FCM_TEST_QUAD_MOMENTS_H

#include "fcm/quad.h"
#include "test.h"

#define MOM_MAX_DEGREE 44

/* k! in double for k <= MOM_MAX_DEGREE + 3: each step is one rounding, so the
 * relative error is below (k + 1) * 2^-53 < 1.1e-14. */
static inline double mom_factorial(int k)
{
  double f = 1.0;
  for (int i = 2; i <= k; i++)
    f *= i;
  return f;
}

/* Reference measures, written out: line 2, tri 1/2, quad 4, tet 1/6, hex 8. */
static inline double mom_measure(fcm_shape s)
{
  switch (s) {
  case FCM_SHAPE_LINE:
    return 2.0;
  case FCM_SHAPE_TRI:
    return 0.5;
  case FCM_SHAPE_QUAD:
    return 4.0;
  case FCM_SHAPE_TET:
    return 1.0 / 6.0;
  case FCM_SHAPE_HEX:
    return 8.0;
  default:
    return 0.0;
  }
}

static inline int mom_dim(fcm_shape s)
{
  return s == FCM_SHAPE_LINE ? 1 : (s == FCM_SHAPE_TRI || s == FCM_SHAPE_QUAD) ? 2 : 3;
}

/* int_{-1}^{1} x^a dx */
static inline double mom_line(int a)
{
  return a % 2 ? 0.0 : 2.0 / (a + 1);
}

/* Exact integral of x^e0 y^e1 z^e2 over the reference shape:
 * line/quad/hex products of 1-D integrals; unit triangle e0! e1! / (e0+e1+2)!;
 * unit tet e0! e1! e2! / (e0+e1+e2+3)!. */
static inline double mom_exact(fcm_shape s, const int e[3])
{
  switch (s) {
  case FCM_SHAPE_LINE:
    return mom_line(e[0]);
  case FCM_SHAPE_QUAD:
    return mom_line(e[0]) * mom_line(e[1]);
  case FCM_SHAPE_HEX:
    return mom_line(e[0]) * mom_line(e[1]) * mom_line(e[2]);
  case FCM_SHAPE_TRI:
    return mom_factorial(e[0]) * mom_factorial(e[1]) / mom_factorial(e[0] + e[1] + 2);
  case FCM_SHAPE_TET:
    return mom_factorial(e[0]) * mom_factorial(e[1]) * mom_factorial(e[2]) /
           mom_factorial(e[0] + e[1] + e[2] + 3);
  default:
    return NAN;
  }
}

/* Worst errors seen by mom_check_exact over all calls. */
typedef struct mom_stats {
  double max_rel;  /* relative error on monomials with non-zero integral */
  double max_zero; /* |Q| / measure on monomials with zero integral */
} mom_stats;

/* Integrate every monomial of total degree <= deg with `rule` (points n x dim,
 * powers by repeated multiplication, Neumaier-compensated sums so the test's own
 * rounding stays far below the tolerances) and compare with mom_exact:
 * relative error <= rtol, or |Q| <= ztol * measure when the exact value is 0.
 * Returns the number of failing monomials (each reported once, up to 5). */
static inline int mom_check_exact(const fcm_rule *rule, int deg, double rtol, double ztol,
                                  mom_stats *stats)
{
  fcm_shape s = fcm_rule_shape(rule);
  int dim = mom_dim(s), n = fcm_rule_num_points(rule), fails = 0;
  const double *p = fcm_rule_points(rule), *w = fcm_rule_weights(rule);
  int m1 = deg + 1, m2 = dim > 1 ? m1 : 1, m3 = dim > 2 ? m1 : 1;
  size_t nm = (size_t)m1 * m2 * m3;
  double *sum = calloc(nm, sizeof *sum), *comp = calloc(nm, sizeof *comp);
  double pw[3][MOM_MAX_DEGREE + 1];
  if (!sum || !comp || deg > MOM_MAX_DEGREE) {
    TEST_FAIL_("mom_check_exact: out of memory or degree %d too large", deg);
    free(sum);
    free(comp);
    return 1;
  }
  for (int i = 0; i < n; i++) {
    for (int d = 0; d < 3; d++) {
      pw[d][0] = 1.0;
      for (int a = 1; a <= deg; a++)
        pw[d][a] = d < dim ? pw[d][a - 1] * p[i * dim + d] : 0.0;
    }
    for (int a = 0; a < m1; a++) {
      double ta = w[i] * pw[0][a];
      for (int b = 0; b < m2 && a + b <= deg; b++) {
        double tb = ta * pw[1][b];
        double *sr = sum + ((size_t)a * m2 + b) * m3, *cr = comp + ((size_t)a * m2 + b) * m3;
        for (int c = 0; c < m3 && a + b + c <= deg; c++) {
          double t = tb * pw[2][c], s0 = sr[c], s1 = s0 + t;
          cr[c] += fabs(s0) >= fabs(t) ? (s0 - s1) + t : (t - s1) + s0;
          sr[c] = s1;
        }
      }
    }
  }
  for (int a = 0; a < m1; a++)
    for (int b = 0; b < m2 && a + b <= deg; b++)
      for (int c = 0; c < m3 && a + b + c <= deg; c++) {
        size_t idx = ((size_t)a * m2 + b) * m3 + c;
        int e[3] = {a, b, c};
        double q = sum[idx] + comp[idx], ex = mom_exact(s, e), err;
        int bad;
        if (ex != 0.0) {
          err = fabs(q - ex) / fabs(ex);
          bad = !(err <= rtol);
          if (stats && err > stats->max_rel) stats->max_rel = err;
        } else {
          err = fabs(q) / mom_measure(s);
          bad = !(err <= ztol);
          if (stats && err > stats->max_zero) stats->max_zero = err;
        }
        if (bad && fails++ < 5)
          TEST_FAIL_("%s rule strength %d (%s): monomial (%d,%d,%d) gives %.17g, exact %.17g, "
                     "error %.3g > %g",
                     fcm_shape_name(s), fcm_rule_strength(rule), fcm_rule_description(rule), a, b,
                     c, q, ex, err, ex != 0.0 ? rtol : ztol);
      }
  free(sum);
  free(comp);
  return fails;
}

/* All weights finite and > 0, all points finite and strictly inside the shape
 * (quad/hex/line: |x_d| < 1; tri/tet: every barycentric coordinate > 0). */
static inline int mom_check_inside_positive(const fcm_rule *rule)
{
  fcm_shape s = fcm_rule_shape(rule);
  int dim = mom_dim(s), n = fcm_rule_num_points(rule), fails = 0;
  const double *p = fcm_rule_points(rule), *w = fcm_rule_weights(rule);
  for (int i = 0; i < n; i++) {
    const double *x = p + (size_t)i * dim;
    int ok = isfinite(w[i]) && w[i] > 0.0;
    if (s == FCM_SHAPE_TRI || s == FCM_SHAPE_TET) {
      double rest = 1.0;
      for (int d = 0; d < dim; d++) {
        ok = ok && x[d] > 0.0;
        rest -= x[d];
      }
      ok = ok && rest > 0.0;
    } else {
      for (int d = 0; d < dim; d++)
        ok = ok && fabs(x[d]) < 1.0;
    }
    if (!ok && fails++ < 5)
      TEST_FAIL_("%s rule strength %d: point %d (%g, %g, %g) weight %g not inside / positive",
                 fcm_shape_name(s), fcm_rule_strength(rule), i, x[0], dim > 1 ? x[1] : 0.0,
                 dim > 2 ? x[2] : 0.0, w[i]);
  }
  return fails;
}

#endif
