/* Moment fitting: a positive rule of at most M points chosen among candidate points, whose
 * moments equal given ones (computed elsewhere, e.g. exactly from a boundary surface).
 * Non-negative least squares on the candidates' moment matrix P (M x n) finds them first: its
 * positive weights sit on independent columns, at most M. Only when it stops short of the
 * tolerance without proving the moments out of reach, P is reduced to its row space by a thin
 * SVD, P = U S V^T, and one LP finds a vertex of {w >= 0 : V_r^T w = S_r^-1 U_r^T b}, which has
 * at most r <= M positive entries; its weights are verified (and re-fitted on their support by
 * least squares when the vertex misses the tolerance) against P w = b. */
#include "core/multiversion.h"
#include "la/la_impl.h"
#include "simplify/simplify_impl.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* Singular values of the candidates' moment matrix below this fraction of the largest are
 * dropped: the moments given carry rounding, and dividing it by a tiny singular value would
 * make the LP's right-hand side noise. What is dropped is checked by the residual. */
#define FIT_RANK_TOL 1e-11

/* An NNLS minimum residual (relative, as fit_residual()) above which the LP is not tried: the
 * LP differs from NNLS only by the moments it drops with the singular values below
 * FIT_RANK_TOL, which change the residual by about that much. */
#define FIT_INFEASIBLE 1e-8

/* The NNLS polish works on at most this many columns (5 M for M <= 84, strength 6). */
#define FCM__FIT_MAX_PASSIVE 420

/* The larger of a and b, a when b is NaN: a comparison the compiler keeps in the loop, where
 * fmax() is a library call (NNLS's per-column scans spent 5 % of the fit in it). */
static inline double max2(double a, double b)
{
  return b > a ? b : a;
}

/* max_i |(P_S w)_i - b_i| / max(max_i |b_i|, atol / tol) over the support S (columns idx of P,
 * ld M): relative to the moments, or to the floor below which they are rounding. */
static double fit_residual(int M, const double *P, int count, const int *idx, const double *w,
                           const double *b, double floor)
{
  double num = 0.0, den = 0.0;
  for (int i = 0; i < M; i++) {
    double s = 0.0;
    for (int c = 0; c < count; c++)
      s += P[i + (size_t)idx[c] * (size_t)M] * w[c];
    num = fmax(num, fabs(s - b[i]));
    den = fmax(den, fabs(b[i]));
  }
  den = fmax(den, floor);
  const double r = den > 0.0 ? num / den : num;
  return isnan(r) ? INFINITY : r;
}

/* Least squares on the support; 1 when the weights come out positive and verify. */
static fcm_status refit(fcm_ctx *ctx, int M, const double *P, fcm__fit *f, const double *b,
                        double tol, double floor, int *ok)
{
  fcm_status st = FCM_OK;
  const int k = f->count, ld = FCM_MAX(M, k);
  double *A = NULL, *x = NULL;
  *ok = 0;
  FCM_ALLOC(ctx, (size_t)M * (size_t)k, A);
  FCM_ALLOC(ctx, (size_t)ld, x);
  for (int c = 0; c < k; c++)
    memcpy(A + (size_t)c * (size_t)M, P + (size_t)f->idx[c] * (size_t)M, (size_t)M * sizeof *A);
  memcpy(x, b, (size_t)M * sizeof *x);
  st = fcm__lstsq(ctx, M, k, 1, A, M, x, ld, -1.0, NULL);
  if (st == FCM_ERR_ALLOC) goto cleanup;
  if (st != FCM_OK) { /* a failed least-squares solve is a failed re-fit, not an error */
    st = FCM_OK;
    goto cleanup;
  }
  for (int c = 0; c < k; c++)
    if (!(x[c] > 0.0) || !isfinite(x[c])) goto cleanup;
  const double r = fit_residual(M, P, k, f->idx, x, b, floor);
  if (r <= tol) {
    memcpy(f->w, x, (size_t)k * sizeof *x);
    f->residual = r;
    *ok = 1;
  }
cleanup:
  fcm__free(ctx, A);
  fcm__free(ctx, x);
  return st;
}

/* ---- non-negative least squares (Lawson and Hanson 1974, ch. 23) ----
 * The passive columns' QR factorization A_P = Q R is kept up to date, a Householder reflection
 * per added column (applied to Q once per iteration for all its columns, nnls_flush()) and
 * Givens rotations per removed one: a step costs O(M^2) besides the gradient A^T r (O(M k),
 * priced in single precision, NNLS_SINGLE_TRUST), where a fresh least-squares solve would cost
 * O(M k^2). */

/* A column whose part orthogonal to the passive columns is below this fraction of its norm is
 * numerically in their span and not added: its weight would be rounding over that fraction. */
#define NNLS_DEP_TOL 1e-10

/* A column enters the passive set only when its gradient a_j^T r exceeds this fraction of
 * ||a_j|| ||r||: below it, r is orthogonal to a_j up to rounding. */
#define NNLS_GRAD_TOL 1e-12

/* Columns an outer iteration adds at most (deviation maximization; Dessole, Dell'Orto and
 * Marcuzzi 2023): besides the steepest, the columns whose cosine with the residual is at least
 * NNLS_BATCH_TAU of the steepest's and whose cosine with each column added before in the same
 * iteration is below NNLS_BATCH_DELTA in magnitude. Each gradient A^T r (2 M k flops, the
 * main cost when k >> M) then serves several columns. */
#define NNLS_BATCH       16
#define NNLS_BATCH_TAU   0.8
#define NNLS_BATCH_DELTA 0.5

/* Partial pricing: when the candidates' matrix A is larger than NNLS_SHORTLIST_BYTES (about a
 * core's L2 cache; the gradient then streams A from memory), a full gradient keeps the columns
 * not passive whose cosine with the residual is above NNLS_SHORTLIST_KEEP of the largest as a
 * shortlist (copied together), and the next NNLS_REFRESH - 1 iterations price only those. An
 * iteration whose shortlist offers no column prices all of them, so optimality is only ever
 * declared on the full gradient. At m = 9 (M = 220, 1,300 candidates) 1.3x; at m <= 7, whose
 * matrices fit the cache, the copy costs what the shorter gradients save. */
#define NNLS_SHORTLIST_BYTES (1024.0 * 1024.0)
#define NNLS_SHORTLIST_KEEP  0.25
#define NNLS_REFRESH         8

/* Pricing in single precision: the full gradient A^T r is computed from a float copy of A (half
 * the bytes the gradient streams, its main cost) when A has more columns than rows. Its error is
 * below M eps_float ||a_j|| ||r|| (a cosine of about 1e-5 at M = 220), so a column whose cosine
 * with the residual comes out above NNLS_SINGLE_TRUST is a column of positive gradient; below
 * it, and before optimality is declared, the gradient is computed again in double. Which column
 * enters may differ from double pricing among near ties; every weight, the residual and the
 * optimality test stay in double. */
#define NNLS_SINGLE_TRUST 1e-3

typedef struct nnls_qr {
  int M, np, kcols; /* rows, passive columns, columns of A */
  double *Q;        /* M x M orthogonal, times the pending reflections (nref) */
  double *R;        /* M x M, upper triangular in its first np columns */
  double *qtb;      /* Q^T b */
  double *dinv;     /* 1 / R_jj of the passive columns (the back substitutions multiply) */
  double *v;        /* 2 M scratch */
  int *pos;         /* the passive columns of A, in R's column order */
  double flops;     /* of the QR updates, solves and residuals */
  /* The Householder reflections H_i = I - beta_i v_i v_i^T of the columns added since Q was last
   * brought up to date (nnls_flush()): v_i in column i of V (M x NNLS_BATCH, zero above row
   * at[i]); W (2 M x NNLS_BATCH) and T (NNLS_BATCH^2) scratch for their blocked product. */
  int nref, at[NNLS_BATCH];
  double beta[NNLS_BATCH], *V, *W, *T;
} nnls_qr;

/* Q <- Q H_1 ... H_nref (the pending reflections, see nnls_qr) as one blocked product: with
 * V's columns from row at[0] on, H_1 ... H_n = I - V T V^T (T upper triangular, LAPACK's dlarft),
 * so Q's columns from at[0] on take Q_p - (Q_p V) T V^T: two passes over Q instead of three per
 * reflection. */
static void nnls_flush(nnls_qr *s)
{
  const int M = s->M, n = s->nref, off = n > 0 ? s->at[0] : 0, m = M - off;
  if (n == 0) return;
  double *T = s->T, *W = s->W, *W2 = s->W + (size_t)M * NNLS_BATCH;
  const double *V = s->V + off;
  /* T (n x n, column-major): T_ii = beta_i, T[0:i, i] = -beta_i T[0:i, 0:i] (V_:,0:i^T v_i) */
  memset(T, 0, (size_t)n * (size_t)n * sizeof *T);
  for (int i = 0; i < n; i++) {
    double y[NNLS_BATCH];
    const double *vi = V + (size_t)i * (size_t)M;
    for (int j = 0; j < i; j++) {
      const double *vj = V + (size_t)j * (size_t)M;
      y[j] = fcm__fit_dot(m - (s->at[i] - off), vj + s->at[i] - off, vi + s->at[i] - off);
    }
    for (int j = 0; j < i; j++) {
      double t = 0.0;
      for (int l = j; l < i; l++)
        t += T[j + (size_t)l * n] * y[l];
      T[j + (size_t)i * n] = -s->beta[i] * t;
    }
    T[i + (size_t)i * n] = s->beta[i];
  }
  double *Qp = s->Q + (size_t)off * (size_t)M;
  fcm__gemm('N', 'N', M, n, m, 1.0, Qp, M, V, M, 0.0, W, M);
  fcm__gemm('N', 'N', M, n, n, 1.0, W, M, T, n, 0.0, W2, M);
  fcm__gemm('N', 'T', M, m, n, -1.0, W2, M, V, M, 1.0, Qp, M);
  s->flops += 4.0 * M * m * n + 2.0 * M * n * n + 2.0 * m * n * n;
  s->nref = 0;
}

/* Append column t (a, of norm anorm) when it is independent of the passive columns and the
 * least-squares weight it would get with them is positive; *added says whether it was. */
static void nnls_add(nnls_qr *s, int t, const double *a, double anorm, int *added)
{
  const int M = s->M, np = s->np, m = M - np;
  double *q = s->R + (size_t)np * (size_t)M, *v = s->v;
  *added = 0;
  if (np == M) return; /* the passive columns span everything */
  if (s->nref == NNLS_BATCH) nnls_flush(s);
  /* q = Q^T a, as R's next column, with Q's pending reflections applied to it in their order;
   * the basis' values are O(1): its norm needs no scaling */
  fcm__fit_dgemv_t(M, M, s->Q, M, a, q);
  for (int i = 0; i < s->nref; i++) {
    const double *vi = s->V + (size_t)i * (size_t)M;
    const double d = s->beta[i] * fcm__fit_dot(M - s->at[i], vi + s->at[i], q + s->at[i]);
    for (int r = s->at[i]; r < M; r++)
      q[r] -= d * vi[r];
    s->flops += 4.0 * (M - s->at[i]);
  }
  s->flops += 2.0 * M * M + 6.0 * m;
  const double nu = sqrt(fcm__fit_dot(m, q + np, q + np));
  if (!(nu > NNLS_DEP_TOL * anorm)) return;
  /* H = I - beta v v^T on rows np.. with H q = alpha e_np */
  const double alpha = q[np] >= 0.0 ? -nu : nu;
  for (int i = 0; i < m; i++)
    v[i] = q[np + i];
  v[0] -= alpha;
  const double vv = fcm__fit_dot(m, v, v), vb = fcm__fit_dot(m, v, s->qtb + np);
  const double beta = 2.0 / vv;
  if (!((s->qtb[np] - beta * vb * v[0]) / alpha > 0.0)) return; /* its weight would be <= 0 */
  for (int i = 0; i < m; i++)
    s->qtb[np + i] -= beta * vb * v[i];
  /* Q <- Q H later, with the others of this iteration (nnls_flush()) */
  double *vn = s->V + (size_t)s->nref * (size_t)M;
  memset(vn, 0, (size_t)np * sizeof *vn);
  memcpy(vn + np, v, (size_t)m * sizeof *vn);
  s->at[s->nref] = np, s->beta[s->nref++] = beta;
  s->flops += 2.0 * m;
  q[np] = alpha;
  s->dinv[np] = 1.0 / alpha;
  for (int i = np + 1; i < M; i++)
    q[i] = 0.0;
  s->pos[np] = t;
  s->np++;
  *added = 1;
}

/* The Givens rotation G_l (cosine and sine into s->v, s->v + M) that zeroes entry l + 1 of R's
 * column rl, whose entry l is a after the rotations before; rl and 1 / R_ll updated. */
static inline void nnls_givens(nnls_qr *s, int l, double a, double *rl)
{
  double *cs = s->v, *sn = s->v + s->M;
  const double b = rl[l + 1], h = sqrt(a * a + b * b);
  cs[l] = h > 0.0 ? a / h : 1.0, sn[l] = h > 0.0 ? b / h : 0.0;
  rl[l] = cs[l] * a + sn[l] * b, rl[l + 1] = 0.0;
  s->dinv[l] = 1.0 / rl[l];
}

/* Remove the passive column at position p (and its value in xp) and restore R's triangle. */
FCM_MULTIVERSION_CLONES static void nnls_remove(nnls_qr *s, int p, double *xp)
{
  const int M = s->M;
  double *R = s->R, *Q = s->Q;
  for (int j = p; j + 1 < s->np; j++) {
    memcpy(R + (size_t)j * (size_t)M, R + (size_t)(j + 1) * (size_t)M, (size_t)(j + 2) * sizeof *R);
    s->pos[j] = s->pos[j + 1];
    xp[j] = xp[j + 1];
  }
  s->np--;
  s->flops += 6.0 * (s->np - p) * (s->np - p + 2 * M) / 2.0;
  /* Givens rotations G_j on rows j, j + 1 (j = p..np - 1: R is Hessenberg from p on), applied
   * to R column by column (contiguous), each column getting G_p.. in turn; their cosines and
   * sines kept in v for Q^T b and Q. R's entries are those of the candidates' moments, O(1)
   * against the range of double: no hypot() needed. */
  double *cs = s->v, *sn = s->v + M;
  int l = p;
  /* two columns at a time, the entry a rotation passes on kept in a register: two independent
   * chains of rotations (the same operations as one column after the other) */
  for (; l + 1 < s->np; l += 2) {
    double *ra = R + (size_t)l * M, *rb = ra + M, ta = ra[p], tb = rb[p];
    for (int j = p; j < l; j++) {
      const double c = cs[j], sj = sn[j], ua = ra[j + 1], ub = rb[j + 1];
      ra[j] = c * ta + sj * ua, rb[j] = c * tb + sj * ub;
      ta = c * ua - sj * ta, tb = c * ub - sj * tb;
    }
    nnls_givens(s, l, ta, ra);
    const double ub = rb[l + 1];
    rb[l] = cs[l] * tb + sn[l] * ub, tb = cs[l] * ub - sn[l] * tb;
    nnls_givens(s, l + 1, tb, rb);
  }
  if (l < s->np) {
    double *rl = R + (size_t)l * M, t = rl[p];
    for (int j = p; j < l; j++) {
      const double u = rl[j + 1];
      rl[j] = cs[j] * t + sn[j] * u, t = cs[j] * u - sn[j] * t;
    }
    nnls_givens(s, l, t, rl);
  }
  for (int j = p; j < s->np; j++) {
    const double c = cs[j], sj = sn[j], t0 = s->qtb[j], t1 = s->qtb[j + 1];
    s->qtb[j] = c * t0 + sj * t1, s->qtb[j + 1] = c * t1 - sj * t0;
    double *q0 = Q + (size_t)j * M, *q1 = q0 + M;
    for (int i = 0; i < M; i++) {
      const double u0 = q0[i], u1 = q1[i];
      q0[i] = c * u0 + sj * u1, q1[i] = c * u1 - sj * u0;
    }
  }
}

/* z = R^-1 (Q^T b) on the passive set (back substitution). */
FCM_MULTIVERSION_CLONES static void nnls_solve(nnls_qr *s, double *z)
{
  const int np = s->np, M = s->M;
  s->flops += (double)np * np;
  memcpy(z, s->qtb, (size_t)np * sizeof *z);
  /* by blocks of 4 columns of R (contiguous), z read and written once per block: at these
   * sizes faster than a BLAS call */
  const double *R = s->R;
  int j = np - 1;
  for (; j >= 3; j -= 4) {
    const double *restrict r0 = R + (size_t)(j - 3) * M, *restrict r1 = r0 + M,
                           *restrict r2 = r1 + M, *restrict r3 = r2 + M;
    const double *d = s->dinv; /* multiplications: the divisions' latency chained the block */
    const double z3 = z[j] * d[j];
    const double z2 = (z[j - 1] - z3 * r3[j - 1]) * d[j - 1];
    const double z1 = (z[j - 2] - z3 * r3[j - 2] - z2 * r2[j - 2]) * d[j - 2];
    const double z0 = (z[j - 3] - z3 * r3[j - 3] - z2 * r2[j - 3] - z1 * r1[j - 3]) * d[j - 3];
    z[j] = z3, z[j - 1] = z2, z[j - 2] = z1, z[j - 3] = z0;
    for (int i = 0; i < j - 3; i++)
      z[i] -= z3 * r3[i] + z2 * r2[i] + z1 * r1[i] + z0 * r0[i];
  }
  for (; j >= 0; j--) {
    const double *restrict rj = R + (size_t)j * (size_t)M;
    const double zj = z[j] * s->dinv[j];
    z[j] = zj;
    for (int i = 0; i < j; i++)
      z[i] -= zj * rj[i];
  }
}

/* r = b - A x for x = xp on the passive set, from A (exact) or from the factorization; its
 * largest entry (returned) and 2-norm (*rn). */
FCM_MULTIVERSION_CLONES static double nnls_residual(nnls_qr *s, const double *A, const double *b,
                                                    const double *xp, int exact, double *r,
                                                    double *rn)
{
  const int M = s->M;
  s->flops += 2.0 * M * (exact ? s->np : M - s->np) + 3.0 * M;
  if (exact) {
    memcpy(r, b, (size_t)M * sizeof *r);
    for (int q = 0; q < s->np; q++)
      for (int i = 0; i < M; i++)
        r[i] -= A[i + (size_t)s->pos[q] * (size_t)M] * xp[q];
  } else {
    memset(r, 0, (size_t)M * sizeof *r);
    fcm__gemv('N', M, M - s->np, 1.0, s->Q + (size_t)s->np * (size_t)M, M, s->qtb + s->np, 0.0, r);
  }
  double rmax = 0.0, n2 = 0.0;
  for (int i = 0; i < M; i++)
    rmax = max2(rmax, fabs(r[i])), n2 += r[i] * r[i];
  *rn = sqrt(n2);
  return rmax;
}

/* After the steepest column (the last passive one) entered: up to NNLS_BATCH - 1 more, in the
 * order of their cosine with the residual (g[j] inv[j] = cos(a_j, r) ||r||), each at least
 * NNLS_BATCH_TAU of the steepest's and of cosine below NNLS_BATCH_DELTA with the columns added in
 * this iteration (deviation maximization); at most 4 NNLS_BATCH tried (a selection sort each).
 * order: k ints of scratch. */
FCM_MULTIVERSION_CLONES static void nnls_more(nnls_qr *s, const double *A, const double *norm,
                                              const double *inv, const double *g, int it, int *seen,
                                              const int *pas, int *order)
{
  const int M = s->M, first = s->pos[s->np - 1];
  const double floor = NNLS_BATCH_TAU * g[first] * inv[first];
  int nc = 0, chosen[NNLS_BATCH], nch = 1;
  chosen[0] = first;
  const int k = s->kcols;
  for (int j = 0; j < k; j++) { /* without a branch: which columns pass is unpredictable */
    order[nc] = j;
    nc += (seen[j] != it) & (pas[j] != it) & (g[j] * inv[j] >= floor);
  }
  for (int a = 0; a < nc && a < 4 * NNLS_BATCH && nch < NNLS_BATCH && s->np < M; a++) {
    /* the steepest of the rest: a partial selection sort (few are taken) */
    int b = a;
    for (int c = a + 1; c < nc; c++)
      if (g[order[c]] * inv[order[c]] > g[order[b]] * inv[order[b]]) b = c;
    const int j = order[b];
    order[b] = order[a], order[a] = j;
    seen[j] = it;
    const double *aj = A + (size_t)j * (size_t)M;
    int apart = 1;
    for (int c = 0; c < nch && apart; c++) {
      const double *ac = A + (size_t)chosen[c] * (size_t)M;
      const double d = fcm__fit_dot(M, aj, ac);
      apart = fabs(d) * inv[j] * inv[chosen[c]] < NNLS_BATCH_DELTA;
    }
    s->flops += 2.0 * M * nch;
    if (!apart) continue;
    int added;
    nnls_add(s, j, aj, norm[j], &added);
    if (added) chosen[nch++] = j;
  }
}

/* After a full gradient g: the shortlist (see NNLS_SHORTLIST_BYTES) into AL (columns) and
 * lidx (their indices), its length returned. pas[j] == it: j is passive. */
static int nnls_shortlist(int M, int k, const double *A, const double *inv, const int *pas, int it,
                          const double *g, double *AL, int *lidx)
{
  double top = 0.0;
  int nl = 0;
  for (int j = 0; j < k; j++)
    if (pas[j] != it) top = max2(top, g[j] * inv[j]);
  const double keep = NNLS_SHORTLIST_KEEP * top;
  for (int j = 0; j < k; j++)
    if (pas[j] != it && g[j] > 0.0 && g[j] * inv[j] > keep) {
      memcpy(AL + (size_t)nl * (size_t)M, A + (size_t)j * (size_t)M, (size_t)M * sizeof *AL);
      lidx[nl++] = j;
    }
  return nl;
}

/* Farkas certificate that no x >= 0 has max_i |(A x - b)_i| <= reach, from the residual r of a
 * full gradient g (computed with absolute error at most err ||a_j|| per column): with row 0 of A
 * positive (inv0[j] = 1 / A_0j; the constant function's moments), y = r - gamma e_0 and gamma =
 * max_j (g_j + err ||a_j||) / A_0j make every a_j^T y <= 0, so any x >= 0 with A x = b + e gives
 * b^T y = sum_j x_j a_j^T y - e^T y <= ||e||_inf ||y||_1: b^T y > reach ||y||_1 rules out every
 * such x. 1 when it does (with a margin for the rounding of b^T y). */
static int nnls_farkas(int M, int k, const double *b, const double *r, const double *g,
                       const double *norm, const double *inv0, double err, double reach)
{
  /* four chains side by side, as fcm__nnls_top_cosine() */
  double c[4] = {-INFINITY, -INFINITY, -INFINITY, -INFINITY};
  int j = 0;
  for (; j + 4 <= k; j += 4)
    for (int l = 0; l < 4; l++)
      c[l] = max2(c[l], (g[j + l] + err * norm[j + l]) * inv0[j + l]);
  for (; j < k; j++)
    c[0] = max2(c[0], (g[j] + err * norm[j]) * inv0[j]);
  const double gamma = max2(max2(c[0], c[1]), max2(c[2], c[3]));
  double by = -gamma * b[0], mag = fabs(gamma * b[0]), y1 = fabs(r[0] - gamma);
  for (int i = 0; i < M; i++)
    by += b[i] * r[i], mag += fabs(b[i] * r[i]);
  for (int i = 1; i < M; i++)
    y1 += fabs(r[i]);
  return by - 4.0 * (M + 2) * DBL_EPSILON * mag > reach * y1;
}

/* The least-squares weights z of the passive set with the columns np0.. added this iteration:
 * while one of those is <= 0, the last of them leaves (the first one's weight is positive when
 * it is the only one: nnls_add checked). */
static void nnls_keep_positive(nnls_qr *s, int np0, double *z)
{
  for (;;) {
    nnls_solve(s, z);
    int bad = 0;
    for (int q = np0; q < s->np && !bad; q++)
      bad = !(z[q] > 0.0);
    if (!bad || s->np <= np0 + 1) return;
    s->np--; /* the last column: R's triangle and Q need no rotation */
  }
}

/* The inner loop of Lawson and Hanson: move xp towards the passive set's least-squares
 * solution (in z on entry), dropping the columns whose weight reaches 0 on the way, until it
 * is positive. */
static void nnls_inner(nnls_qr *s, double *xp, double *z)
{
  for (int inner = 0; inner <= s->M && s->np > 0; inner++) {
    if (inner > 0) nnls_solve(s, z); /* the first: nnls_keep_positive() solved */
    double alpha = 2.0;
    int at = -1;
    for (int q = 0; q < s->np; q++)
      if (!(z[q] > 0.0)) {
        const double d = xp[q] - z[q], a = d > 0.0 ? xp[q] / d : 0.0;
        if (a < alpha) alpha = a, at = q;
      }
    if (at < 0) {
      memcpy(xp, z, (size_t)s->np * sizeof *xp);
      return;
    }
    for (int q = 0; q < s->np; q++)
      xp[q] += alpha * (z[q] - xp[q]);
    xp[at] = 0.0;
    for (int q = s->np - 1; q >= 0; q--)
      if (!(xp[q] > 0.0)) nnls_remove(s, q, xp);
  }
}

/* NNLS's arrays besides the QR factorization (nnls_qr): per column of A its gradient g, norm and
 * inverse norm, the iteration that tried it last (seen) and that found it passive (pas); the
 * residual r, the passive weights xp and their least-squares solution z; the single-precision
 * copies for pricing (Af, rf, gf; NULL when k <= M); the shortlist (AL, gl, lidx; NULL below
 * NNLS_SHORTLIST_BYTES) and inv0 (1 / A_0j for the certificate; NULL without one). */
typedef struct nnls_work {
  double *r, *g, *norm, *inv, *xp, *z, *inv0, *AL, *gl;
  int *seen, *pas, *order, *lidx;
  float *Af, *rf, *gf;
  int nl, last_full; /* the shortlist's length (-1: none yet), the last full gradient's iteration */
} nnls_work;

/* Allocate and start NNLS on A (M x k) and b: Q = I, Q^T b = b, the column norms; with reach > 0
 * and row 0 of A positive, inv0 for the certificate. */
static fcm_status nnls_start(fcm_ctx *ctx, int M, int k, const double *A, const double *b,
                             double reach, nnls_qr *s, nnls_work *w)
{
  fcm_status st = FCM_OK;
  s->M = M, s->kcols = k;
  w->nl = -1;
  FCM_ALLOC(ctx, (size_t)M * (size_t)M, s->Q);
  FCM_ALLOC(ctx, (size_t)M * (size_t)M, s->R);
  FCM_ALLOC(ctx, (size_t)M, s->qtb);
  FCM_ALLOC(ctx, (size_t)M, s->dinv);
  FCM_ALLOC(ctx, 2 * (size_t)M, s->v);
  FCM_ALLOC_RAW(ctx, (size_t)M * NNLS_BATCH, s->V);
  FCM_ALLOC_RAW(ctx, 2 * (size_t)M * NNLS_BATCH, s->W);
  FCM_ALLOC_RAW(ctx, (size_t)NNLS_BATCH * NNLS_BATCH, s->T);
  FCM_ALLOC(ctx, (size_t)M, s->pos);
  FCM_ALLOC(ctx, (size_t)M, w->r);
  FCM_ALLOC(ctx, (size_t)k, w->g);
  FCM_ALLOC(ctx, (size_t)k, w->norm);
  FCM_ALLOC(ctx, (size_t)k, w->inv);
  FCM_ALLOC(ctx, (size_t)M, w->xp);
  FCM_ALLOC(ctx, (size_t)M, w->z);
  FCM_ALLOC(ctx, (size_t)k, w->seen);
  FCM_ALLOC(ctx, (size_t)k, w->pas);
  FCM_ALLOC(ctx, (size_t)k, w->order);
  if ((double)M * k * sizeof *A > NNLS_SHORTLIST_BYTES) {
    FCM_ALLOC(ctx, (size_t)k, w->lidx);
    FCM_ALLOC(ctx, (size_t)k, w->gl);
    FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)k, w->AL);
  }
  if (k > M) { /* by rows, the candidates side by side (fcm__fit_sgemv_rows()) */
    FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)k, w->Af);
    FCM_ALLOC(ctx, (size_t)M, w->rf);
    FCM_ALLOC_RAW(ctx, (size_t)k, w->gf);
    for (size_t j = 0; j < (size_t)k; j++)
      for (size_t i = 0; i < (size_t)M; i++)
        w->Af[i * (size_t)k + j] = (float)A[j * (size_t)M + i];
  }
  for (int i = 0; i < M; i++)
    s->Q[i + (size_t)i * (size_t)M] = 1.0;
  memcpy(s->qtb, b, (size_t)M * sizeof *b);
  for (int j = 0; j < k; j++) {
    double t = 0.0;
    for (int i = 0; i < M; i++)
      t += A[i + (size_t)j * (size_t)M] * A[i + (size_t)j * (size_t)M];
    w->norm[j] = sqrt(t);
    w->inv[j] = w->norm[j] > 0.0 ? 1.0 / w->norm[j] : 0.0;
    w->seen[j] = w->pas[j] = -1; /* the iteration that tried j last, that found it passive */
  }
  if (reach > 0.0) { /* the infeasibility certificate needs row 0 positive (nnls_farkas()) */
    FCM_ALLOC(ctx, (size_t)k, w->inv0);
    for (int j = 0; j < k && w->inv0; j++)
      if (A[(size_t)j * (size_t)M] > 0.0) {
        w->inv0[j] = 1.0 / A[(size_t)j * (size_t)M];
      } else {
        fcm__free(ctx, w->inv0);
        w->inv0 = NULL;
      }
  }
cleanup:
  return st;
}

/* Free what nnls_start() allocated (also after it failed part-way). */
static void nnls_end(fcm_ctx *ctx, nnls_qr *s, nnls_work *w)
{
  void *p[] = {s->Q,     s->R,    s->qtb,  s->dinv, s->v,    s->V,  s->W, s->T,    s->pos,
               w->r,     w->g,    w->norm, w->inv,  w->inv0, w->xp, w->z, w->seen, w->pas,
               w->order, w->lidx, w->gl,   w->AL,   w->Af,   w->rf, w->gf};
  for (size_t i = 0; i < sizeof p / sizeof p[0]; i++)
    fcm__free(ctx, p[i]);
}

/* Four chains side by side, whose latency one running maximum paid in full at every column. A
 * maximum is exact, so the chains give the value the one chain gives (NaNs left out alike, as
 * max2() leaves them out). */
double fcm__nnls_top_cosine(int k, const double *g, const double *inv, const int *pas, int it)
{
  double c[4] = {0.0, 0.0, 0.0, 0.0};
  int j = 0;
  for (; j + 4 <= k; j += 4)
    for (int l = 0; l < 4; l++)
      c[l] = pas[j + l] != it ? max2(c[l], g[j + l] * inv[j + l]) : c[l];
  for (; j < k; j++)
    c[0] = pas[j] != it ? max2(c[0], g[j] * inv[j]) : c[0];
  return max2(max2(c[0], c[1]), max2(c[2], c[3]));
}

/* The gradient g = A^T r of iteration it (residual norm rn): in full (*single: from the float
 * copy, falling back to double near optimality) or on the shortlist (g 0 elsewhere). Returns a
 * full gradient's error per unit ||a_j|| (for the certificate), -1 for the shortlist's. */
static double nnls_price(nnls_qr *s, nnls_work *w, const double *A, int it, int full, int *single,
                         double rn)
{
  const int M = s->M, k = s->kcols;
  double *g = w->g;
  if (full && *single) {
    for (int i = 0; i < M; i++)
      w->rf[i] = (float)w->r[i];
    fcm__fit_sgemv_rows(M, k, w->Af, k, w->rf, w->gf);
    const float *gf = w->gf;
    for (int j = 0; j < k; j++)
      g[j] = (double)gf[j];
    const double top = fcm__nnls_top_cosine(k, g, w->inv, w->pas, it);
    s->flops += 2.0 * M * k + 2.0 * k;
    if (top > NNLS_SINGLE_TRUST * rn) {
      w->last_full = it;
      if (w->AL) w->nl = nnls_shortlist(M, k, A, w->inv, w->pas, it, g, w->AL, w->lidx);
      return 2.0 * (M + 2) * FLT_EPSILON * rn;
    }
    *single = 0; /* near optimality: price in double */
  }
  if (full) {
    fcm__fit_dgemv_t(M, k, A, M, w->r, g);
    s->flops += 2.0 * M * k + 2.0 * k;
    w->last_full = it;
    if (w->AL) w->nl = nnls_shortlist(M, k, A, w->inv, w->pas, it, g, w->AL, w->lidx);
    return 2.0 * (M + 2) * DBL_EPSILON * rn;
  }
  fcm__fit_dgemv_t(M, w->nl, w->AL, M, w->r, w->gl);
  s->flops += 2.0 * M * w->nl + 2.0 * w->nl;
  memset(g, 0, (size_t)k * sizeof *g);
  const int *lidx = w->lidx;
  const double *gl = w->gl;
  for (int c = 0; c < w->nl; c++)
    g[lidx[c]] = gl[c];
  return -1.0;
}

enum { NNLS_ADDED, NNLS_OPTIMAL, NNLS_INFEASIBLE };

/* Iteration it's entering column: price (the shortlist when it is current), stop on a
 * certificate (reach) or at optimality, else add the steepest column that can enter (re-priced
 * in full and in double before optimality is declared). */
static int nnls_enter(nnls_qr *s, nnls_work *w, const double *A, const double *b, double reach,
                      int it, double rn)
{
  const int k = s->kcols;
  int full = !w->AL || w->nl <= 0 || it - w->last_full >= NNLS_REFRESH, single = w->Af != NULL;
  for (;;) {
    const double gerr = nnls_price(s, w, A, it, full, &single, rn);
    if (gerr >= 0.0 && w->inv0 &&
        nnls_farkas(s->M, k, b, w->r, w->g, w->norm, w->inv0, gerr, reach))
      return NNLS_INFEASIBLE; /* out of reach: the way on to optimality cannot change that */
    const double *g = w->g, *inv = w->inv;
    const int *seen = w->seen, *pas = w->pas;
    for (;;) { /* the steepest column that can enter */
      int t = -1;
      double best = NNLS_GRAD_TOL * rn; /* the cosine of a_j and r, times ||r|| */
      for (int j = 0; j < k; j++) {
        const double c = g[j] * inv[j];
        if (c > best && seen[j] != it && pas[j] != it) best = c, t = j;
      }
      if (t < 0 && (!full || single)) { /* none on the shortlist or priced in single */
        full = 1, single = 0;
        break;
      }
      if (t < 0) return NNLS_OPTIMAL; /* no column lowers the residual */
      w->seen[t] = it;
      int added;
      nnls_add(s, t, A + (size_t)t * (size_t)s->M, w->norm[t], &added);
      if (added) return NNLS_ADDED;
    }
  }
}

fcm_status fcm__simplify_nnls(fcm_ctx *ctx, int M, int k, const double *A, const double *b,
                              double stop, double reach, double *x, fcm__nnls_report *rep)
{
  fcm_status st = FCM_OK;
  nnls_qr s;
  nnls_work w;
  memset(&s, 0, sizeof s);
  memset(&w, 0, sizeof w);
  memset(rep, 0, sizeof *rep);
  rep->residual = INFINITY;
  FCM_TRY(ctx, nnls_start(ctx, M, k, A, b, reach, &s, &w));
  int exact = 0;
  for (int it = 0; it < 3 * k + M; it++) {
    const int np0 = s.np;
    /* r = b - A x: xp being the passive set's least-squares solution, r = Q_2 Q_2^T b with
     * Q_2 = Q's last M - np columns (cheaper near the end); confirmed from A and x when small */
    double rn, rmax = nnls_residual(&s, A, b, w.xp, exact, w.r, &rn);
    if (rmax <= stop && !exact) exact = 1, rmax = nnls_residual(&s, A, b, w.xp, exact, w.r, &rn);
    rep->residual = rmax, rep->iterations = it;
    if (rmax <= stop) {
      rep->ok = 1;
      break;
    }
    for (int q = 0; q < s.np; q++)
      w.pas[s.pos[q]] = it;
    const int how = nnls_enter(&s, &w, A, b, reach, it, rn);
    if (how == NNLS_INFEASIBLE) rep->infeasible = 1;
    if (how == NNLS_OPTIMAL) rep->optimal = 1;
    if (how != NNLS_ADDED) break;
    nnls_more(&s, A, w.norm, w.inv, w.g, it, w.seen, w.pas, w.order);
    nnls_flush(&s);
    for (int q = np0; q < s.np; q++)
      w.xp[q] = 0.0;
    nnls_keep_positive(&s, np0, w.z);
    nnls_inner(&s, w.xp, w.z);
  }
  rep->passive = s.np;
  rep->flops = s.flops + 2.0 * M * k; /* and the column norms */
  memset(x, 0, (size_t)k * sizeof *x);
  for (int q = 0; q < s.np; q++)
    x[s.pos[q]] = w.xp[q];
cleanup:
  nnls_end(ctx, &s, &w);
  return st;
}

/* The NNLS residual (of the moments scaled by scale) at which fit_residual() is half of tol. */
static double nnls_stop(int M, const double *b, double scale, double tol, double floor)
{
  double bmax = 0.0;
  for (int i = 0; i < M; i++)
    bmax = fmax(bmax, fabs(b[i]));
  return 0.5 * tol * scale * fmax(bmax, floor);
}

/* After a failed re-fit: NNLS on the vertex's support and up to 4 M other candidates spread
 * over the list (a degenerate vertex has fewer than M positive weights, which no re-fit on
 * its support can make exact). */
static fcm_status polish(fcm_ctx *ctx, int M, int n, const double *P, fcm__fit *f, const double *b,
                         double scale, double tol, double floor, int *ok)
{
  fcm_status st = FCM_OK;
  const int extra = FCM_MIN(n, 4 * M), k0 = f->count;
  int *sel = NULL, k = 0;
  unsigned char *in = NULL;
  double *A = NULL, *x = NULL, *bs = NULL;
  *ok = 0;
  FCM_ALLOC(ctx, (size_t)(k0 + extra), sel);
  FCM_ALLOC(ctx, (size_t)n, in);
  for (int c = 0; c < k0; c++)
    sel[k++] = f->idx[c], in[f->idx[c]] = 1;
  for (int i = 0; i < extra; i++) {
    const int j = (int)(((long long)i * n) / extra);
    if (!in[j]) sel[k++] = j, in[j] = 1;
  }
  FCM_ALLOC(ctx, (size_t)M * (size_t)k, A);
  FCM_ALLOC(ctx, (size_t)k, x);
  FCM_ALLOC(ctx, (size_t)M, bs);
  for (int c = 0; c < k; c++)
    memcpy(A + (size_t)c * (size_t)M, P + (size_t)sel[c] * (size_t)M, (size_t)M * sizeof *A);
  for (int i = 0; i < M; i++)
    bs[i] = scale * b[i];
  fcm__nnls_report nr;
  FCM_TRY(ctx,
          fcm__simplify_nnls(ctx, M, k, A, bs, nnls_stop(M, b, scale, tol, floor), 0.0, x, &nr));
  int count = 0, idx[FCM__FIT_MAX_PASSIVE];
  double w[FCM__FIT_MAX_PASSIVE];
  for (int c = 0; c < k; c++)
    if (x[c] > 0.0 && count < M) idx[count] = sel[c], w[count++] = x[c] / scale;
  const double r = fit_residual(M, P, count, idx, w, b, floor);
  if (count > 0 && count <= M && r <= tol) {
    /* ascending candidate order, as the LP's support */
    for (int a = 1; a < count; a++)
      for (int c = a; c > 0 && idx[c - 1] > idx[c]; c--) {
        const int ti = idx[c];
        const double tw = w[c];
        idx[c] = idx[c - 1], w[c] = w[c - 1];
        idx[c - 1] = ti, w[c - 1] = tw;
      }
    memcpy(f->idx, idx, (size_t)count * sizeof *idx);
    memcpy(f->w, w, (size_t)count * sizeof *w);
    f->count = count;
    f->residual = r;
    *ok = 1;
  }
cleanup:
  fcm__free(ctx, sel);
  fcm__free(ctx, in);
  fcm__free(ctx, A);
  fcm__free(ctx, x);
  fcm__free(ctx, bs);
  return st;
}

/* NNLS on all candidates, f filled when its weights verify (f->ok). */
static fcm_status nnls_fit(fcm_ctx *ctx, int M, int n, const double *P, const double *b,
                           double scale, double tol, double floor, double *x, fcm__fit *f,
                           fcm__nnls_report *nr)
{
  fcm_status st = FCM_OK;
  double *bs = NULL;
  FCM_ALLOC(ctx, (size_t)M, bs);
  for (int i = 0; i < M; i++)
    bs[i] = scale * b[i];
  /* a certificate that no positive combination verifies (to tol) ends a hopeless run early */
  const double stop = nnls_stop(M, b, scale, tol, floor);
  FCM_TRY(ctx, fcm__simplify_nnls(ctx, M, n, P, bs, stop, 2.0 * stop, x, nr));
  f->flops += nr->flops;
  if (!nr->ok) goto cleanup;
  f->count = 0;
  for (int j = 0; j < n; j++)
    if (x[j] > 0.0) f->idx[f->count] = j, f->w[f->count++] = x[j] / scale;
  f->residual = fit_residual(M, P, f->count, f->idx, f->w, b, floor);
  f->ok = f->residual <= tol;
  if (!f->ok) f->count = 0, f->residual = INFINITY;
cleanup:
  fcm__free(ctx, bs);
  return st;
}

fcm_status fcm__simplify_fit(fcm_ctx *ctx, const fcm__cheb_box *box, int n, const double *pts,
                             const double *b, double tol, double atol, fcm__fit *f)
{
  fcm_status st = FCM_OK;
  const int M = box->num_basis;
  double *P = NULL, *work = NULL;
  if (n < 1) return fcm__simplify_fit_basis(ctx, M, n, NULL, b, tol, atol, f);
  FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)n, P);
  FCM_ALLOC_RAW(ctx, fcm__simplify_moments_scratch(box->m), work);
  fcm__simplify_basis_points(box, n, pts, P, work);
  FCM_TRY(ctx, fcm__simplify_fit_basis(ctx, M, n, P, b, tol, atol, f));
cleanup:
  fcm__free(ctx, P);
  fcm__free(ctx, work);
  return st;
}

fcm_status fcm__simplify_fit_basis(fcm_ctx *ctx, int M, int n, const double *P, const double *b,
                                   double tol, double atol, fcm__fit *f)
{
  fcm_status st = FCM_OK;
  const int k = FCM_MIN(M, n);
  double *G = NULL, *s = NULL, *u = NULL, *vt = NULL, *rhs = NULL, *x = NULL;
  fcm__lp_report rep;
  f->count = 0;
  f->ok = 0;
  f->residual = INFINITY;
  f->flops = 0.0;
  f->message[0] = '\0';
  if (n < 1) {
    snprintf(f->message, sizeof f->message, "no candidate points");
    return FCM_OK;
  }
  FCM_ALLOC(ctx, (size_t)n, x);
  /* weights of mean 1 (the LP's tolerances are absolute): b scaled by n / b_0, b_0 being the
   * measure's total (the basis' first function is 1) */
  const double scale = b[0] > 0.0 ? n / b[0] : 1.0, floor = atol / tol;
  fcm__nnls_report nr;
  FCM_TRY(ctx, nnls_fit(ctx, M, n, P, b, scale, tol, floor, x, f, &nr));
  if (f->ok) goto cleanup;
  /* the moments are farther from the candidates' cone than the LP's rank cut could explain, or
   * proved beyond tol of it */
  const double nnls_rel = 0.5 * tol * nr.residual / nnls_stop(M, b, scale, tol, floor);
  if (nr.infeasible) {
    snprintf(f->message, sizeof f->message,
             "no positive combination of the %d candidates within the tolerance: a separating "
             "polynomial proves it (NNLS residual %.3g when found)",
             n, nnls_rel);
    goto cleanup;
  }
  if (nr.optimal && nnls_rel > FIT_INFEASIBLE) {
    snprintf(f->message, sizeof f->message,
             "no positive combination of the %d candidates: the nearest (NNLS) leaves a "
             "moment residual of %.3g",
             n, nnls_rel);
    goto cleanup;
  }
  FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)n, G);
  memcpy(G, P, (size_t)M * (size_t)n * sizeof *G);
  FCM_ALLOC(ctx, (size_t)k, s);
  FCM_ALLOC(ctx, (size_t)M * (size_t)k, u);
  FCM_ALLOC(ctx, (size_t)k * (size_t)n, vt);
  st = fcm__gesvd(ctx, M, n, G, M, s, u, M, vt, k);
  if (st == FCM_ERR_ALLOC) goto cleanup;
  if (st != FCM_OK || !(s[0] > 0.0) || !isfinite(s[0])) {
    st = FCM_OK;
    snprintf(f->message, sizeof f->message, "SVD of the candidates' moment matrix failed");
    goto cleanup;
  }
  int r = 0;
  while (r < k && s[r] > FIT_RANK_TOL * s[0])
    r++;
  FCM_ALLOC(ctx, (size_t)r, rhs);
  for (int i = 0; i < r; i++) {
    double t = 0.0;
    for (int j = 0; j < M; j++)
      t += u[j + (size_t)i * (size_t)M] * b[j];
    rhs[i] = scale * t / s[i];
  }
  const fcm__lp_params prm = {20 * M + 1000, 0.0, 0};
  FCM_TRY(ctx, fcm__simplify_lp_solve(ctx, r, n, vt, k, rhs, &prm, x, &rep));
  if (!rep.ok) {
    snprintf(f->message, sizeof f->message,
             "no positive combination of the %d candidates (NNLS residual %.3g): %.100s", n,
             nnls_rel, rep.message);
    goto cleanup;
  }
  for (int j = 0; j < n; j++)
    if (x[j] > 0.0) {
      if (f->count == M) {
        snprintf(f->message, sizeof f->message, "LP vertex has more than M = %d points", M);
        goto cleanup;
      }
      f->idx[f->count] = j;
      f->w[f->count++] = x[j] / scale;
    }
  f->residual = fit_residual(M, P, f->count, f->idx, f->w, b, floor);
  if (f->residual <= tol) {
    f->ok = 1;
  } else {
    int ok;
    FCM_TRY(ctx, refit(ctx, M, P, f, b, tol, floor, &ok));
    if (!ok && M <= FCM__FIT_MAX_PASSIVE / 5)
      FCM_TRY(ctx, polish(ctx, M, n, P, f, b, scale, tol, floor, &ok));
    f->ok = ok;
    if (!ok)
      snprintf(f->message, sizeof f->message, "moment residual %.3g above %.3g (rank %d of %d)",
               f->residual, tol, r, M);
  }
cleanup:
  fcm__free(ctx, G);
  fcm__free(ctx, s);
  fcm__free(ctx, u);
  fcm__free(ctx, vt);
  fcm__free(ctx, rhs);
  fcm__free(ctx, x);
  return st;
}
