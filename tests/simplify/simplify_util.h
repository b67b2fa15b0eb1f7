/* Helpers of the simplification tests: input rules (random positive rules in a box,
 * unions of conical rules on red-refined sub-tets of the unit tet) and the checks every
 * simplified rule must pass (subset, count <= M, weights > 0, monomial moments). */
#ifndef FCM_TEST_SIMPLIFY_UTIL_H
#define FCM_TEST_SIMPLIFY_UTIL_H

#include "fcm/quad.h"
#include "fcm/simplify.h"
#include "test.h"

#include <stdint.h>

/* Deterministic uniform numbers in [0, 1) (xorshift64*). */
static inline double util_rand(uint64_t *s)
{
  *s ^= *s >> 12;
  *s ^= *s << 25;
  *s ^= *s >> 27;
  return (double)((*s * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
}

static inline int util_num_basis(int m)
{
  return (m + 1) * (m + 2) * (m + 3) / 6;
}

/* n random points in the box lo + [0, size]^3 with weights in [0.1, 1.1) * wscale. */
static inline void util_random_box(uint64_t seed, int n, const double lo[3], double size,
                                   double wscale, double *pts, double *w)
{
  uint64_t s = seed * 0x9E3779B97F4A7C15ULL + 1;
  for (int j = 0; j < n; j++) {
    for (int d = 0; d < 3; d++)
      pts[3 * j + d] = lo[d] + size * util_rand(&s);
    w[j] = wscale * (0.1 + util_rand(&s));
  }
}

/* Red refinement of tets (4 x 3 vertex coordinates each): 8 children per tet. */
static inline int util_red_refine(int ntets, const double *tets, double *out)
{
  for (int t = 0; t < ntets; t++) {
    const double *v = tets + 12 * t;
    double p[10][3]; /* 0-3 vertices, 4: 01, 5: 02, 6: 03, 7: 12, 8: 13, 9: 23 */
    static const int e[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        p[a][d] = v[3 * a + d];
    for (int k = 0; k < 6; k++)
      for (int d = 0; d < 3; d++)
        p[4 + k][d] = 0.5 * (p[e[k][0]][d] + p[e[k][1]][d]);
    static const int child[8][4] = {{0, 4, 5, 6}, {4, 1, 7, 8}, {5, 7, 2, 9}, {6, 8, 9, 3},
                                    {4, 5, 6, 8}, {4, 5, 7, 8}, {5, 6, 8, 9}, {5, 7, 8, 9}};
    for (int c = 0; c < 8; c++)
      for (int a = 0; a < 4; a++)
        for (int d = 0; d < 3; d++)
          out[12 * (8 * t + c) + 3 * a + d] = p[child[c][a]][d];
  }
  return 8 * ntets;
}

/* The conical rule of strength m mapped onto every sub-tet of the unit tet after r red
 * refinements; with radius > 0, only sub-tets whose centroid lies within that distance of
 * the origin (a sphere-cut cell). Returns the point count; *pts and *w are malloc'ed. */
static inline int util_tet_union(fcm_ctx *ctx, int m, int r, double radius, double **pts,
                                 double **w)
{
  fcm_rule *rule = NULL;
  int ntets = 1, n = 0;
  double *tets = malloc(12 * sizeof *tets), *next = NULL;
  static const double unit[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  memcpy(tets, unit, sizeof unit);
  for (int k = 0; k < r; k++) {
    next = malloc(12 * 8 * (size_t)ntets * sizeof *next);
    ntets = util_red_refine(ntets, tets, next);
    free(tets);
    tets = next;
  }
  TEST_OK(ctx, fcm_rule_create_computed(ctx, FCM_SHAPE_TET, m, &rule));
  const int q = fcm_rule_num_points(rule);
  const double *rp = fcm_rule_points(rule), *rw = fcm_rule_weights(rule);
  *pts = malloc(3 * (size_t)ntets * (size_t)q * sizeof **pts);
  *w = malloc((size_t)ntets * (size_t)q * sizeof **w);
  for (int t = 0; t < ntets; t++) {
    const double *v = tets + 12 * t;
    double J[3][3], c[3];
    for (int d = 0; d < 3; d++) {
      for (int a = 0; a < 3; a++)
        J[d][a] = v[3 * (a + 1) + d] - v[d];
      c[d] = 0.25 * (v[d] + v[3 + d] + v[6 + d] + v[9 + d]);
    }
    if (radius > 0 && c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > radius * radius) continue;
    const double det = fabs(J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                            J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                            J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]));
    for (int j = 0; j < q; j++) {
      for (int d = 0; d < 3; d++)
        (*pts)[3 * n + d] =
            v[d] + J[d][0] * rp[3 * j] + J[d][1] * rp[3 * j + 1] + J[d][2] * rp[3 * j + 2];
      (*w)[n++] = det * rw[j];
    }
  }
  fcm_rule_destroy(&rule);
  free(tets);
  return n;
}

/* Checks on a simplified rule: at most M (and at most max_count) points, a strictly
 * ascending subset of the input, weights > 0, and every monomial f = x^a y^b z^c with
 * a+b+c <= m integrated like the input rule: |mu - mu0| <= rtol * sum_j w0_j * max_B |f|,
 * B the bounding box of the input points. That scale bounds |mu0| for every positive rule
 * on B; it is the one the box-scaled Chebyshev residual controls (a monomial's Chebyshev
 * coefficients on B sum to at most max_B |f| in magnitude), whereas sum w0 |f| can be
 * 1e-5 of it (x^4 y^3 z^3 on the unit tet) and would ask for more than double precision. */
static inline void util_check(const char *label, int m, int n, const double *pts, const double *w0,
                              const fcm_simplify_result *res, int max_count, double rtol)
{
  const int M = util_num_basis(m), failures_before = test_failures_;
  if (res->count < 1 || res->count > M || res->count > max_count) {
    TEST_FAIL_("%s: %lld points, expected 1..min(M = %d, %d)", label, (long long)res->count, M,
               max_count);
    return;
  }
  for (fcm_index c = 0; c < res->count; c++) {
    const fcm_index i = res->indices[c];
    if (i < 0 || i >= n || (c > 0 && i <= res->indices[c - 1]))
      TEST_FAIL_("%s: index %lld = %lld not an ascending subset of [0, %d)", label, (long long)c,
                 (long long)i, n);
    if (!(res->weights[c] > 0.0) || !isfinite(res->weights[c]))
      TEST_FAIL_("%s: weight %lld = %g not positive", label, (long long)c, res->weights[c]);
  }
  if (test_failures_ > failures_before) return;
  double far[3] = {0, 0, 0}, mass = 0.0, worst = 0.0; /* max_B |x_d| per axis */
  for (int j = 0; j < n; j++) {
    for (int d = 0; d < 3; d++)
      far[d] = fmax(far[d], fabs(pts[3 * j + d]));
    mass += w0[j];
  }
  for (int a = 0; a <= m; a++)
    for (int b = 0; a + b <= m; b++)
      for (int c = 0; a + b + c <= m; c++) {
        double mu0 = 0.0, mu = 0.0;
        for (int j = 0; j < n; j++)
          mu0 += w0[j] * pow(pts[3 * j], a) * pow(pts[3 * j + 1], b) * pow(pts[3 * j + 2], c);
        for (fcm_index k = 0; k < res->count; k++) {
          const double *x = pts + 3 * res->indices[k];
          mu += res->weights[k] * pow(x[0], a) * pow(x[1], b) * pow(x[2], c);
        }
        const double scale = mass * pow(far[0], a) * pow(far[1], b) * pow(far[2], c);
        const double err = fabs(mu - mu0) / scale;
        worst = err > worst ? err : worst;
        if (!(err <= rtol))
          TEST_FAIL_("%s: moment x^%d y^%d z^%d = %.17g, input %.17g (relative %.3g > %.3g)", label,
                     a, b, c, mu, mu0, err, rtol);
      }
  if (getenv("FCM_TEST_VERBOSE")) fprintf(stderr, "%s: worst monomial error %.3g\n", label, worst);
}

#endif
