/* Moment basis of the simplification: tensor Chebyshev polynomials of total degree
 * <= m on the bounding box of the points (Longva et al. 2020 §4.4.3, eq. 9), optionally only
 * those of degree <= q in each variable (the tensor space Q_q when m >= 3q: a Hex8 cell's
 * consistent mass integrand N_i N_j is in Q_2, 27 functions against P_6's 84). */
#include "la/la_impl.h"
#include "simplify/simplify_impl.h"

#include <float.h>
#include <math.h>

enum { AXIS = FCM_SIMPLIFY_MAX_STRENGTH + 1 }; /* pair table stride */

int fcm__simplify_num_basis(int m)
{
  return (m + 1) * (m + 2) * (m + 3) / 6;
}

/* The degree cap of box in each variable: q, at most m. */
static int axis_cap(const fcm__cheb_box *box)
{
  return box->q < 0 || box->q > box->m ? box->m : box->q;
}

int fcm__simplify_space_size(int m, int q)
{
  if (q < 0 || q >= m) return fcm__simplify_num_basis(m);
  int n = 0;
  for (int a = 0; a <= q; a++)
    for (int b = 0; b <= q; b++)
      for (int c = 0; c <= q; c++)
        n += a + b + c <= m;
  return n;
}

void fcm__simplify_box_cap(fcm__cheb_box *box, int q)
{
  box->q = q < 0 || q > box->m ? box->m : q;
  box->num_basis = fcm__simplify_space_size(box->m, box->q);
}

/* Whether (a, b, c) of total degree <= m is in box's space. */
static int in_space(int q, int a, int b, int c)
{
  return a <= q && b <= q && c <= q;
}

void fcm__simplify_basis_rows(const fcm__cheb_box *top, const fcm__cheb_box *sub, int *rows)
{
  const int qt = axis_cap(top), qs = axis_cap(sub);
  int i = 0, j = 0;
  for (int deg = 0; deg <= top->m; deg++)
    for (int a = deg; a >= 0; a--)
      for (int b = deg - a; b >= 0; b--) {
        if (!in_space(qt, a, b, deg - a - b)) continue;
        if (deg <= sub->m && in_space(qs, a, b, deg - a - b)) rows[j++] = i;
        i++;
      }
}

/* The pairs (a, b), a, b <= q, a + b <= m, numbered by a + b, then b: pid[a * AXIS + b];
 * returns their number. */
static int pair_table(int m, int q, int *pid)
{
  int n = 0;
  for (int s = 0; s <= m && s <= 2 * q; s++)
    for (int b = s > q ? s - q : 0; b <= s && b <= q; b++)
      pid[(s - b) * AXIS + b] = n++;
  return n;
}
void fcm__simplify_box(int m, int n, const double *points, fcm__cheb_box *box)
{
  box->m = m;
  box->q = m;
  box->num_basis = fcm__simplify_num_basis(m);
  for (int d = 0; d < 3; d++) {
    double lo = points[d], hi = points[d];
    for (int j = 1; j < n; j++) {
      const double v = points[3 * j + d];
      lo = v < lo ? v : lo;
      hi = v > hi ? v : hi;
    }
    const double c = 0.5 * (lo + hi), l = 0.5 * (hi - lo);
    /* An extent at rounding level carries no geometry: constant along that axis. */
    if (l <= 64.0 * DBL_EPSILON * fmax(1.0, fmax(fabs(lo), fabs(hi)))) {
      box->scale[d] = 0.0;
      box->shift[d] = 1.0;
    } else {
      box->scale[d] = 1.0 / l;
      box->shift[d] = -c / l;
    }
  }
}

void fcm__simplify_basis_eval(const fcm__cheb_box *box, const double *x, double *phi)
{
  double t[3][FCM_SIMPLIFY_MAX_STRENGTH + 1];
  const int m = box->m, q = axis_cap(box);
  for (int d = 0; d < 3; d++) {
    const double s = box->scale[d] * x[d] + box->shift[d];
    t[d][0] = 1.0;
    if (q >= 1) t[d][1] = s;
    for (int k = 2; k <= q; k++)
      t[d][k] = 2.0 * s * t[d][k - 1] - t[d][k - 2];
  }
  int i = 0;
  for (int deg = 0; deg <= m; deg++)
    for (int a = deg; a >= 0; a--)
      for (int b = deg - a; b >= 0; b--)
        if (in_space(q, a, b, deg - a - b)) phi[i++] = t[0][a] * t[1][b] * t[2][deg - a - b];
}

/* One block of bn <= FCM__MOMENT_BLOCK points (idx[j0 + p], or j0 + p): per axis the
 * Chebyshev values T_k, k <= q, points innermost, with w (NULL: 1) folded into the z factor,
 * and the products T_a(x) T_b(y) of the pairs of pair_table(), at txy + pid[a * AXIS + b] B. */
static void tabulate_block(const fcm__cheb_box *box, const int *pid, int j0, int bn,
                           const double *points, const int *idx, const double *w, double *tx,
                           double *ty, double *tzw, double *txy)
{
  enum { B = FCM__MOMENT_BLOCK };
  const int m = box->m, q = axis_cap(box);
  /* Chebyshev values per axis, points innermost; the weight goes into the z factor. */
  for (int p = 0; p < bn; p++) {
    const double *x = points + 3 * (size_t)(idx ? idx[j0 + p] : j0 + p);
    tx[p] = 1.0;
    ty[p] = 1.0;
    tzw[p] = w ? w[j0 + p] : 1.0;
    if (q >= 1) {
      tx[B + p] = box->scale[0] * x[0] + box->shift[0];
      ty[B + p] = box->scale[1] * x[1] + box->shift[1];
      tzw[B + p] = box->scale[2] * x[2] + box->shift[2]; /* the argument for now */
    }
  }
  for (int k = 2; k <= q; k++) {
    double *restrict xk = tx + (size_t)k * B, *restrict yk = ty + (size_t)k * B;
    const double *x1 = tx + (size_t)(k - 1) * B, *x2 = tx + (size_t)(k - 2) * B;
    const double *y1 = ty + (size_t)(k - 1) * B, *y2 = ty + (size_t)(k - 2) * B;
    for (int p = 0; p < bn; p++) {
      xk[p] = 2.0 * tx[B + p] * x1[p] - x2[p];
      yk[p] = 2.0 * ty[B + p] * y1[p] - y2[p];
    }
  }
  /* z: the recurrence on the unweighted values, then times the weight. */
  if (q >= 1) {
    double *restrict z1 = tzw + B;
    for (int p = 0; p < bn; p++) {
      const double s = z1[p];
      double t0 = 1.0, t1 = s;
      z1[p] = tzw[p] * s;
      for (int k = 2; k <= q; k++) {
        const double t2 = 2.0 * s * t1 - t0;
        tzw[(size_t)k * B + p] = tzw[p] * t2;
        t0 = t1;
        t1 = t2;
      }
    }
  }
  /* T_a(x) T_b(y) for a + b <= m, a, b <= q. */
  for (int s = 0; s <= m && s <= 2 * q; s++)
    for (int b = s > q ? s - q : 0; b <= s && b <= q; b++) {
      double *restrict o = txy + (size_t)pid[(s - b) * AXIS + b] * B;
      const double *xa = tx + (size_t)(s - b) * B, *yb = ty + (size_t)b * B;
      for (int p = 0; p < bn; p++)
        o[p] = xa[p] * yb[p];
    }
}

size_t fcm__simplify_moments_scratch(int m)
{
  const size_t pairs = (size_t)(m + 1) * (size_t)(m + 2) / 2, nz = (size_t)m + 1;
  return (2 * nz + pairs + nz) * FCM__MOMENT_BLOCK + pairs * nz;
}

void fcm__simplify_moments(const fcm__cheb_box *box, int n, const double *points, const int *idx,
                           const double *w, double *mom, double *work)
{
  enum { B = FCM__MOMENT_BLOCK };
  int pid[AXIS * AXIS];
  const int m = box->m, q = axis_cap(box), pairs = pair_table(m, q, pid), nz = q + 1;
  double *tx = work, *ty = tx + (size_t)nz * B, *txy = ty + (size_t)nz * B;
  double *tzw = txy + (size_t)pairs * B, *c = tzw + (size_t)nz * B;
  for (size_t i = 0; i < (size_t)pairs * (size_t)nz; i++)
    c[i] = 0.0;
  for (int j0 = 0; j0 < n; j0 += B) {
    const int bn = n - j0 < B ? n - j0 : B;
    tabulate_block(box, pid, j0, bn, points, idx, w, tx, ty, tzw, txy);
    /* C(pair, c) += sum_p T_a T_b(p) w T_c(p): one matrix product per block (it also forms the
     * products of degree above m, cheaper there than skipping them); short blocks (small
     * recombination clusters) by dot products, below the cost of a BLAS call. */
    if (bn >= FCM__MOMENT_GEMM_MIN) {
      fcm__gemm('T', 'N', pairs, nz, bn, 1.0, txy, B, tzw, B, 1.0, c, pairs);
    } else {
      for (int s = 0; s <= m && s <= 2 * q; s++)
        for (int k = 0; k <= m - s && k <= q; k++)
          for (int b = s > q ? s - q : 0; b <= s && b <= q; b++) {
            const int pr = pid[(s - b) * AXIS + b];
            const double *o = txy + (size_t)pr * B, *z = tzw + (size_t)k * B;
            double d[4] = {0.0, 0.0, 0.0, 0.0}; /* four partial sums: no serial add chain */
            int p = 0;
            for (; p + 4 <= bn; p += 4)
              for (int l = 0; l < 4; l++)
                d[l] += o[p + l] * z[p + l];
            for (; p < bn; p++)
              d[0] += o[p] * z[p];
            c[pr + (size_t)k * (size_t)pairs] += (d[0] + d[1]) + (d[2] + d[3]);
          }
    }
  }
  /* The basis order of fcm__simplify_basis_eval: degree, a descending, b descending. */
  int i = 0;
  for (int deg = 0; deg <= m; deg++)
    for (int a = deg; a >= 0; a--)
      for (int b = deg - a; b >= 0; b--)
        if (in_space(q, a, b, deg - a - b))
          mom[i++] = c[pid[a * AXIS + b] + (size_t)(deg - a - b) * (size_t)pairs];
}

void fcm__simplify_basis_points(const fcm__cheb_box *box, int n, const double *points, double *phi,
                                double *work)
{
  enum { B = FCM__MOMENT_BLOCK };
  int pid[AXIS * AXIS];
  const int m = box->m, q = axis_cap(box), M = box->num_basis, pairs = pair_table(m, q, pid),
            nz = q + 1;
  double *tx = work, *ty = tx + (size_t)nz * B, *txy = ty + (size_t)nz * B;
  double *tz = txy + (size_t)pairs * B;
  for (int j0 = 0; j0 < n; j0 += B) {
    const int bn = n - j0 < B ? n - j0 : B;
    tabulate_block(box, pid, j0, bn, points, NULL, NULL, tx, ty, tz, txy);
    int i = 0;
    for (int deg = 0; deg <= m; deg++)
      for (int a = deg; a >= 0; a--)
        for (int b = deg - a; b >= 0; b--) {
          if (!in_space(q, a, b, deg - a - b)) continue;
          const double *o = txy + (size_t)pid[a * AXIS + b] * B;
          const double *z = tz + (size_t)(deg - a - b) * B;
          double *out = phi + (size_t)j0 * (size_t)M + i++;
          for (int p = 0; p < bn; p++)
            out[(size_t)p * (size_t)M] = o[p] * z[p];
        }
  }
}
