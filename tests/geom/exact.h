/* Exact integrals for the geom and embed tests, independent of the library's clipping
 * and quadrature: monomials over a tetrahedron by expanding x = sum_i lambda_i v_i in
 * barycentric coordinates (int_T lambda^alpha = 6|T| alpha! / (|alpha|+3)!), and over a
 * convex polytope given by half-spaces (vertices by enumerating plane triples, faces by
 * angular sorting, fan tets from the vertex centroid). Monomials x^a y^b z^c with
 * a+b+c <= m are numbered by exact_index(). */
#ifndef FCM_TEST_GEOM_EXACT_H
#define FCM_TEST_GEOM_EXACT_H

#include "fcm/geom.h"

#include <math.h>
#include <string.h>

#define EXACT_MAX_DEG  12
#define EXACT_MAX_MONO 455 /* (12+3 choose 3) */

/* Number of monomials of total degree <= m. */
static inline int exact_num_mono(int m)
{
  return (m + 1) * (m + 2) * (m + 3) / 6;
}

/* Exponents of monomial k in the order: degree ascending, then a descending, b descending. */
static inline void exact_exponents(int m, int k, int e[3])
{
  int i = 0;
  e[0] = e[1] = e[2] = 0;
  for (int d = 0; d <= m; d++)
    for (int a = d; a >= 0; a--)
      for (int b = d - a; b >= 0; b--) {
        if (i == k) {
          e[0] = a, e[1] = b, e[2] = d - a - b;
          return;
        }
        i++;
      }
}

/* Number of x^e0 y^e1 z^e2 in that order (independent of m). */
static inline int exact_index(const int e[3])
{
  const int d = e[0] + e[1] + e[2];
  return d * (d + 1) * (d + 2) / 6 + (d - e[0]) * (d - e[0] + 1) / 2 + (d - e[0] - e[1]);
}

/* Whether monomial k (exact_index() order) has degree <= q in each variable: in the space of
 * rules exact on total degree m with the per-variable cap q (fcm_cell_rules_axis_degree()). */
static inline int exact_in_axis(int k, int q)
{
  int e[3];
  exact_exponents(EXACT_MAX_DEG, k, e);
  return e[0] <= q && e[1] <= q && e[2] <= q;
}

/* Values of every monomial of degree <= m at x into v. */
static inline void exact_eval(int m, const double x[3], double *v)
{
  double px[EXACT_MAX_DEG + 1][3];
  int i = 0;
  for (int d = 0; d < 3; d++) {
    px[0][d] = 1.0;
    for (int k = 1; k <= m; k++)
      px[k][d] = px[k - 1][d] * x[d];
  }
  for (int d = 0; d <= m; d++)
    for (int a = d; a >= 0; a--)
      for (int b = d - a; b >= 0; b--)
        v[i++] = px[a][0] * px[b][1] * px[d - a - b][2];
}

static inline double exact_fact(int k)
{
  double f = 1.0;
  for (int i = 2; i <= k; i++)
    f *= i;
  return f;
}

/* Integrals of all monomials of degree <= m over the tet (v0..v3, any orientation),
 * added to out[exact_num_mono(m)]. Each monomial's barycentric expansion is its parent's
 * (one exponent lower) times one linear form sum_i lambda_i v_i[dim]; coefficients of a
 * homogeneous polynomial of degree d in (l0..l3) are stored at (a0, a1, a2), a3 = d - sum. */
static inline void exact_tet_add(double v[4][3], int m, double *out)
{
  static double poly[EXACT_MAX_MONO]
                    [(EXACT_MAX_DEG + 1) * (EXACT_MAX_DEG + 1) * (EXACT_MAX_DEG + 1)];
  const int S = m + 1, nm = exact_num_mono(m);
  const double u[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
  const double w[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
  const double z[3] = {v[3][0] - v[0][0], v[3][1] - v[0][1], v[3][2] - v[0][2]};
  const double vol = fabs(u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) +
                          u[2] * (w[0] * z[1] - w[1] * z[0])) /
                     6.0;
  for (int k = 0; k < nm; k++) {
    int e[3];
    exact_exponents(m, k, e);
    const int d = e[0] + e[1] + e[2];
    double *p = poly[k];
    memset(p, 0, (size_t)(S * S * S) * sizeof *p);
    if (d == 0) {
      p[0] = 1.0;
    } else {
      int pe[3] = {e[0], e[1], e[2]}, dim = e[0] ? 0 : (e[1] ? 1 : 2);
      pe[dim]--;
      const double *pp = poly[exact_index(pe)];
      const double s[4] = {v[0][dim], v[1][dim], v[2][dim], v[3][dim]};
      for (int a0 = 0; a0 < d; a0++)
        for (int a1 = 0; a0 + a1 < d; a1++)
          for (int a2 = 0; a0 + a1 + a2 < d; a2++) {
            const double c = pp[(a0 * S + a1) * S + a2];
            if (c == 0.0) continue;
            p[((a0 + 1) * S + a1) * S + a2] += c * s[0];
            p[(a0 * S + a1 + 1) * S + a2] += c * s[1];
            p[(a0 * S + a1) * S + a2 + 1] += c * s[2];
            p[(a0 * S + a1) * S + a2] += c * s[3];
          }
    }
    double sum = 0.0;
    for (int a0 = 0; a0 <= d; a0++)
      for (int a1 = 0; a0 + a1 <= d; a1++)
        for (int a2 = 0; a0 + a1 + a2 <= d; a2++)
          sum += p[(a0 * S + a1) * S + a2] * exact_fact(a0) * exact_fact(a1) * exact_fact(a2) *
                 exact_fact(d - a0 - a1 - a2);
    out[k] += 6.0 * vol * sum / exact_fact(d + 3);
  }
}

/* A half-space n.x <= d (n need not be unit). */
typedef struct exact_plane {
  double n[3], d;
} exact_plane;

#define EXACT_MAX_PV 256

/* Integrals of all monomials of degree <= m over the polytope {x : n_i.x <= d_i}, added to
 * out. Returns the polytope's vertex count (0: empty or flat). `tol` is an absolute
 * tolerance for "on a plane". */
static inline int exact_polytope_add(const exact_plane *pl, int np, int m, double tol, double *out)
{
  double V[EXACT_MAX_PV][3];
  int nv = 0;
  for (int i = 0; i < np; i++)
    for (int j = i + 1; j < np; j++)
      for (int k = j + 1; k < np; k++) {
        const double *a = pl[i].n, *b = pl[j].n, *c = pl[k].n;
        const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                           a[2] * (b[0] * c[1] - b[1] * c[0]);
        const double na = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        const double nb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        const double nc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        if (fabs(det) < 1e-12 * na * nb * nc) continue;
        /* Cramer: x = (d_i (b x c) + d_j (c x a) + d_k (a x b)) / det */
        double x[3];
        const double bc[3] = {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2],
                              b[0] * c[1] - b[1] * c[0]};
        const double ca[3] = {c[1] * a[2] - c[2] * a[1], c[2] * a[0] - c[0] * a[2],
                              c[0] * a[1] - c[1] * a[0]};
        const double ab[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                              a[0] * b[1] - a[1] * b[0]};
        for (int d = 0; d < 3; d++)
          x[d] = (pl[i].d * bc[d] + pl[j].d * ca[d] + pl[k].d * ab[d]) / det;
        int ok = 1;
        for (int q = 0; q < np && ok; q++) {
          const double nq =
              sqrt(pl[q].n[0] * pl[q].n[0] + pl[q].n[1] * pl[q].n[1] + pl[q].n[2] * pl[q].n[2]);
          ok = pl[q].n[0] * x[0] + pl[q].n[1] * x[1] + pl[q].n[2] * x[2] - pl[q].d <= tol * nq;
        }
        if (!ok) continue;
        int dup = 0;
        for (int q = 0; q < nv && !dup; q++)
          dup = fabs(V[q][0] - x[0]) + fabs(V[q][1] - x[1]) + fabs(V[q][2] - x[2]) <= 3 * tol;
        if (!dup && nv < EXACT_MAX_PV) memcpy(V[nv++], x, sizeof x);
      }
  if (nv < 4) return 0;
  double c[3] = {0, 0, 0};
  for (int q = 0; q < nv; q++)
    for (int d = 0; d < 3; d++)
      c[d] += V[q][d] / nv;
  for (int i = 0; i < np; i++) {
    const double *n = pl[i].n;
    const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    int ids[EXACT_MAX_PV], k = 0;
    for (int q = 0; q < nv; q++)
      if (fabs(n[0] * V[q][0] + n[1] * V[q][1] + n[2] * V[q][2] - pl[i].d) <= tol * nn)
        ids[k++] = q;
    if (k < 3) continue;
    /* Skip a plane whose face was already handled (duplicate planes). */
    int seen = 0;
    for (int j = 0; j < i && !seen; j++) {
      const double *n2 = pl[j].n;
      const double n2n = sqrt(n2[0] * n2[0] + n2[1] * n2[1] + n2[2] * n2[2]);
      const double cosang = (n[0] * n2[0] + n[1] * n2[1] + n[2] * n2[2]) / (nn * n2n);
      seen = cosang > 1.0 - 1e-12 && fabs(pl[j].d / n2n - pl[i].d / nn) <= tol;
    }
    if (seen) continue;
    double fc[3] = {0, 0, 0}, u[3], w[3], ang[EXACT_MAX_PV];
    for (int q = 0; q < k; q++)
      for (int d = 0; d < 3; d++)
        fc[d] += V[ids[q]][d] / k;
    for (int d = 0; d < 3; d++)
      u[d] = V[ids[0]][d] - fc[d];
    const double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int d = 0; d < 3; d++)
      u[d] /= lu;
    w[0] = (n[1] * u[2] - n[2] * u[1]) / nn;
    w[1] = (n[2] * u[0] - n[0] * u[2]) / nn;
    w[2] = (n[0] * u[1] - n[1] * u[0]) / nn;
    for (int q = 0; q < k; q++) {
      double r[3];
      for (int d = 0; d < 3; d++)
        r[d] = V[ids[q]][d] - fc[d];
      ang[q] =
          atan2(r[0] * w[0] + r[1] * w[1] + r[2] * w[2], r[0] * u[0] + r[1] * u[1] + r[2] * u[2]);
    }
    for (int q = 1; q < k; q++)
      for (int r = q; r > 0 && ang[r - 1] > ang[r]; r--) {
        const double ta = ang[r];
        const int ti = ids[r];
        ang[r] = ang[r - 1], ids[r] = ids[r - 1];
        ang[r - 1] = ta, ids[r - 1] = ti;
      }
    for (int q = 1; q + 1 < k; q++) {
      double T[4][3];
      memcpy(T[0], c, sizeof c);
      memcpy(T[1], V[ids[0]], sizeof T[1]);
      memcpy(T[2], V[ids[q]], sizeof T[2]);
      memcpy(T[3], V[ids[q + 1]], sizeof T[3]);
      exact_tet_add(T, m, out);
    }
  }
  return nv;
}

/* Outward half-spaces of a tet (v0..v3, any orientation) into pl[4]. */
static inline void exact_tet_planes(double v[4][3], exact_plane *pl)
{
  static const int f[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (int i = 0; i < 4; i++) {
    const double *a = v[f[i][0]], *b = v[f[i][1]], *c = v[f[i][2]], *o = v[i];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double s = n[0] * (o[0] - a[0]) + n[1] * (o[1] - a[1]) + n[2] * (o[2] - a[2]);
    if (s > 0) n[0] = -n[0], n[1] = -n[1], n[2] = -n[2]; /* point away from vertex i */
    const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int d = 0; d < 3; d++)
      pl[i].n[d] = n[d] / len;
    pl[i].d = (pl[i].n[0] * a[0] + pl[i].n[1] * a[1] + pl[i].n[2] * a[2]);
  }
}

/* Outward half-spaces of the box R [lo, hi] + t (R a rotation, row-major) into pl[6]. */
static inline void exact_box_planes(const double R[9], const double t[3], const double lo[3],
                                    const double hi[3], exact_plane *pl)
{
  for (int d = 0; d < 3; d++) {
    const double col[3] = {R[d], R[3 + d], R[6 + d]}; /* image of e_d */
    const double ct = col[0] * t[0] + col[1] * t[1] + col[2] * t[2];
    for (int i = 0; i < 3; i++)
      pl[2 * d].n[i] = col[i], pl[2 * d + 1].n[i] = -col[i];
    pl[2 * d].d = hi[d] + ct;
    pl[2 * d + 1].d = -lo[d] - ct;
  }
}

/* A deterministic pseudo-random rotation from three numbers in [0,1) (unit quaternion). */
static inline void exact_rotation(double u1, double u2, double u3, double R[9])
{
  const double pi = 3.14159265358979323846;
  const double a = sqrt(1 - u1), b = sqrt(u1);
  const double q0 = a * sin(2 * pi * u2), q1 = a * cos(2 * pi * u2), q2 = b * sin(2 * pi * u3),
               q3 = b * cos(2 * pi * u3);
  R[0] = 1 - 2 * (q2 * q2 + q3 * q3), R[1] = 2 * (q1 * q2 - q0 * q3),
  R[2] = 2 * (q1 * q3 + q0 * q2);
  R[3] = 2 * (q1 * q2 + q0 * q3), R[4] = 1 - 2 * (q1 * q1 + q3 * q3),
  R[5] = 2 * (q2 * q3 - q0 * q1);
  R[6] = 2 * (q1 * q3 - q0 * q2), R[7] = 2 * (q2 * q3 + q0 * q1),
  R[8] = 1 - 2 * (q1 * q1 + q2 * q2);
}

/* Small deterministic generator (xorshift64*), uniform in [0, 1). */
static inline double exact_rand(unsigned long long *s)
{
  *s ^= *s >> 12, *s ^= *s << 25, *s ^= *s >> 27;
  return (double)((*s * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
}

/* Exact moments of degree <= m (exact_num_mono(m) entries, set) of a Tet4 geometry: the sum
 * over its tets. */
static inline void exact_geometry_moments(const fcm_geometry *g, int m, double *mom)
{
  const double *x = fcm_geometry_coords(g);
  const fcm_index *c = fcm_geometry_cells(g);
  memset(mom, 0, (size_t)exact_num_mono(m) * sizeof *mom);
  for (fcm_index k = 0; k < fcm_geometry_num_cells(g); k++) {
    double v[4][3];
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        v[a][d] = x[3 * c[4 * k + a] + d];
    exact_tet_add(v, m, mom);
  }
}

/* The area of the geometry's boundary triangles. */
static inline double exact_boundary_area(const fcm_geometry *g)
{
  const double *x = fcm_geometry_coords(g);
  const fcm_index *t = fcm_geometry_boundary_triangles(g);
  double area = 0.0;
  for (fcm_index k = 0; k < fcm_geometry_num_boundary_triangles(g); k++) {
    const double *a = x + 3 * t[3 * k], *b = x + 3 * t[3 * k + 1], *c = x + 3 * t[3 * k + 2];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    area += 0.5 * hypot(hypot(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2]),
                        u[0] * v[1] - u[1] * v[0]);
  }
  return area;
}

#endif /* FCM_TEST_GEOM_EXACT_H */
