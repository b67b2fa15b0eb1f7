/* Non-negative least squares (fcm__simplify_nnls) and the moment fit built on it
 * (fcm__simplify_fit): a tall system's unique non-negative solution is recovered; a wide
 * consistent one is solved with at most M positive weights; an inconsistent one ends at the
 * nearest point of the columns' cone (a known one, and the KKT conditions on random ones, also
 * on a matrix large enough for NNLS to price a shortlist of columns, and where the one column
 * that lowers the residual has a gradient that cancels in single precision);
 * NNLS's early stop on a proof that no x >= 0 reaches b never stops a solvable system and stops
 * only unsolvable ones; the fit reproduces the moments of a positive rule among its candidates
 * to 1e-12 and reports a tolerance below rounding (through its LP path) and moments no positive
 * combination of the candidates can carry (proved by a separating polynomial); NNLS's own
 * products A^T x (double, and single precision on rows padded to 16) agree with the sums
 * they compute to the rounding of those sums, on shapes with every remainder of their blocks;
 * its largest cosine is that of one running maximum. */
#include "simplify/simplify_impl.h"
#include "simplify_util.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* max_i |(A x - b)_i|, A M x k */
static double resid(int M, int k, const double *A, const double *x, const double *b)
{
  double m = 0.0;
  for (int i = 0; i < M; i++) {
    double s = -b[i];
    for (int j = 0; j < k; j++)
      s += A[i + (size_t)j * M] * x[j];
    m = fmax(m, fabs(s));
  }
  return m;
}

/* Random A (M x k, entries in [-1, 1), first row 1) and b = A x* for x* >= 0 with npos
 * positive entries (the first npos of a random order). */
static void consistent(uint64_t seed, int M, int k, int npos, double *A, double *xs, double *b)
{
  uint64_t s = seed * 0x9E3779B97F4A7C15ULL + 7;
  for (int j = 0; j < k; j++)
    for (int i = 0; i < M; i++)
      A[i + (size_t)j * M] = i == 0 ? 1.0 : 2.0 * util_rand(&s) - 1.0;
  memset(xs, 0, (size_t)k * sizeof *xs);
  for (int c = 0; c < npos; c++) {
    int j = (int)(util_rand(&s) * k);
    while (xs[j] > 0.0)
      j = (j + 1) % k;
    xs[j] = 0.5 + util_rand(&s);
  }
  for (int i = 0; i < M; i++) {
    b[i] = 0.0;
    for (int j = 0; j < k; j++)
      b[i] += A[i + (size_t)j * M] * xs[j];
  }
}

static void tall_unique(fcm_ctx *ctx)
{
  enum { M = 30, K = 20 };
  double A[M * K], xs[K], b[M], x[K];
  fcm__nnls_report rep;
  for (uint64_t seed = 1; seed <= 5; seed++) {
    consistent(seed, M, K, 12, A, xs, b); /* A has full column rank: x* is the one solution */
    TEST_OK(ctx, fcm__simplify_nnls(ctx, M, K, A, b, 1e-13, 0.0, x, &rep));
    TEST_TRUE(rep.ok && rep.residual <= 1e-13);
    for (int j = 0; j < K; j++)
      TEST_NEAR(x[j], xs[j], 0.0, 1e-10);
  }
}

static void wide_consistent(fcm_ctx *ctx)
{
  enum { M = 35, K = 200 };
  static double A[M * K];
  double xs[K], b[M], x[K];
  fcm__nnls_report rep;
  for (uint64_t seed = 11; seed <= 15; seed++) {
    consistent(seed, M, K, 60, A, xs, b);
    const double stop = 1e-12 * b[0];
    TEST_OK(ctx, fcm__simplify_nnls(ctx, M, K, A, b, stop, 0.0, x, &rep));
    TEST_TRUE(rep.ok);
    int npos = 0;
    for (int j = 0; j < K; j++) {
      TEST_TRUE(x[j] >= 0.0);
      npos += x[j] > 0.0;
    }
    TEST_TRUE(npos == rep.passive && npos <= M);
    TEST_TRUE(resid(M, K, A, x, b) <= stop);
  }
}

/* Columns (1, 0) and (1, 1), b = (0, 1) outside their cone: the nearest point of the cone is
 * (1/2, 1/2) on the second column, residual 1/2 in each entry. */
static void known_optimum(fcm_ctx *ctx)
{
  const double A[4] = {1.0, 0.0, 1.0, 1.0}, b[2] = {0.0, 1.0};
  double x[2];
  fcm__nnls_report rep;
  TEST_OK(ctx, fcm__simplify_nnls(ctx, 2, 2, A, b, 1e-12, 0.0, x, &rep));
  TEST_TRUE(!rep.ok && rep.optimal);
  TEST_NEAR(x[0], 0.0, 0.0, 0.0);
  TEST_NEAR(x[1], 0.5, 0.0, 1e-15);
  TEST_NEAR(rep.residual, 0.5, 0.0, 1e-15);
}

/* The KKT conditions of min ||A x - b||, x >= 0 at x (A M x k, M <= 128): x >= 0 and
 * g = A^T (b - A x) within tol of 0 where x > 0 and <= tol where x = 0. */
static void check_kkt(int M, int k, const double *A, const double *b, const double *x, double tol)
{
  double r[128];
  TEST_TRUE(M <= 128);
  for (int i = 0; i < M && i < 128; i++) {
    r[i] = b[i];
    for (int j = 0; j < k; j++)
      r[i] -= A[i + (size_t)j * M] * x[j];
  }
  for (int j = 0; j < k && M <= 128; j++) {
    double g = 0.0;
    for (int i = 0; i < M; i++)
      g += A[i + (size_t)j * M] * r[i];
    TEST_TRUE(x[j] >= 0.0);
    if (x[j] > 0.0)
      TEST_NEAR(g, 0.0, 0.0, tol);
    else
      TEST_TRUE(g <= tol);
  }
}

/* Random inconsistent problems: the result satisfies the KKT conditions of min ||A x - b||,
 * x >= 0: g = A^T (b - A x) is 0 where x > 0 and <= 0 where x = 0 (to rounding). */
static void kkt(fcm_ctx *ctx)
{
  enum { M = 20, K = 40 };
  double A[M * K], b[M], x[K];
  fcm__nnls_report rep;
  int infeasible = 0;
  for (uint64_t seed = 21; seed <= 30; seed++) {
    uint64_t s = seed;
    for (int i = 0; i < M * K; i++)
      A[i] = 2.0 * util_rand(&s) - 1.0;
    for (int i = 0; i < M; i++)
      b[i] = 2.0 * util_rand(&s) - 1.0;
    TEST_OK(ctx, fcm__simplify_nnls(ctx, M, K, A, b, 1e-13, 0.0, x, &rep));
    if (rep.ok) {
      TEST_TRUE(resid(M, K, A, x, b) <= 1e-13);
      continue;
    }
    TEST_TRUE(rep.optimal);
    infeasible++;
    check_kkt(M, K, A, b, x, 1e-12);
  }
  TEST_TRUE(infeasible >= 3); /* the KKT branch was exercised */
}

/* A matrix above the size at which NNLS prices a shortlist of columns between full gradients
 * (1 MiB; here 128 x 1,100): a consistent system is still solved with at most M positive
 * weights, and on an inconsistent one (b_0 < 0 against a first row of ones) the optimum it
 * declares satisfies the KKT conditions over every column, not only the shortlist's. */
static void shortlist(fcm_ctx *ctx)
{
  enum { M = 128, K = 1100 };
  static double A[M * K], xs[K], b[M], x[K];
  fcm__nnls_report rep;
  for (uint64_t seed = 41; seed <= 42; seed++) {
    consistent(seed, M, K, 400, A, xs, b);
    const double stop = 1e-12 * b[0];
    TEST_OK(ctx, fcm__simplify_nnls(ctx, M, K, A, b, stop, 0.0, x, &rep));
    int npos = 0;
    for (int j = 0; j < K; j++) {
      TEST_TRUE(x[j] >= 0.0);
      npos += x[j] > 0.0;
    }
    TEST_TRUE(rep.ok && npos <= M && resid(M, K, A, x, b) <= stop);

    b[0] = -0.5 * b[0]; /* no x >= 0 has a negative sum */
    TEST_OK(ctx, fcm__simplify_nnls(ctx, M, K, A, b, 1e-13, 0.0, x, &rep));
    TEST_TRUE(!rep.ok && rep.optimal);
    check_kkt(M, K, A, b, x, 1e-10);
  }
}

/* A gradient that cancels in single precision (NNLS prices in float when A has more columns
 * than rows): b = (1, 1), columns -e_1, -e_2 and a = (1, -1 + 1e-9), whose gradient a^T b =
 * 1e-9 is the only positive one and is 0 in float (-1 + 1e-9 rounds to -1). The optimum puts
 * the weight a^T b / a^T a = 5e-10 on a; declaring x = 0 optimal breaks the KKT conditions. */
static void cancelling(fcm_ctx *ctx)
{
  const double A[2 * 3] = {-1.0, 0.0, 0.0, -1.0, 1.0, -1.0 + 1e-9}, b[2] = {1.0, 1.0};
  double x[3];
  fcm__nnls_report rep;
  TEST_OK(ctx, fcm__simplify_nnls(ctx, 2, 3, A, b, 1e-13, 0.0, x, &rep));
  TEST_TRUE(!rep.ok && rep.optimal);
  check_kkt(2, 3, A, b, x, 1e-12);
  TEST_NEAR(x[2], (A[4] * b[0] + A[5] * b[1]) / (A[4] * A[4] + A[5] * A[5]), 1e-6, 0.0);
}

/* The infeasibility certificate (reach > 0): it never stops a system that some x >= 0 solves to
 * within reach (b = A x* + e, |e_i| <= reach / 2, x* on many columns or on a few, b then on a
 * low-dimensional face of the cone), in double and single pricing (k <= M, k > M); on systems
 * no x >= 0 solves (a negative sum against a first row of ones, random right-hand sides), when
 * it stops, the optimum found without it misses b by more than reach, and it stops no later. */
static void certificate(fcm_ctx *ctx)
{
  enum { M = 35, K = 200 };
  static double A[M * K], xs[K], b[M], x[K];
  fcm__nnls_report rep, opt;
  const int ks[3] = {K, M, 20}, nps[3] = {60, 3, 10};
  for (uint64_t seed = 51; seed <= 58; seed++)
    for (int c = 0; c < 3; c++) {
      const int k = ks[c];
      consistent(seed, M, k, nps[c], A, xs, b);
      uint64_t s = seed;
      const double reach = 1e-9 * b[0];
      for (int i = 0; i < M; i++)
        b[i] += reach * (util_rand(&s) - 0.5);
      TEST_OK(ctx, fcm__simplify_nnls(ctx, M, k, A, b, 1e-13 * b[0], reach, x, &rep));
      TEST_TRUE(!rep.infeasible && resid(M, k, A, x, b) <= reach);
    }
  int stopped = 0;
  for (uint64_t seed = 61; seed <= 70; seed++) {
    const int k = seed % 2 ? K : M;
    consistent(seed, M, k, 25, A, xs, b);
    uint64_t s = seed;
    if (seed % 4 < 2)
      b[0] = -0.5 * b[0]; /* no x >= 0 has a negative sum */
    else
      for (int i = 1; i < M; i++)
        b[i] = 2.0 * k * (util_rand(&s) - 0.5);
    const double reach = 1e-9 * fabs(b[0]);
    TEST_OK(ctx, fcm__simplify_nnls(ctx, M, k, A, b, 1e-13, 0.0, x, &opt));
    TEST_OK(ctx, fcm__simplify_nnls(ctx, M, k, A, b, 1e-13, reach, x, &rep));
    if (!rep.infeasible) continue;
    stopped++;
    TEST_TRUE(!opt.ok && opt.residual > reach && rep.iterations <= opt.iterations);
  }
  TEST_TRUE(stopped >= 5);
}

/* The fit on random candidates in [0, 1]^3 (basis on that box): the moments of a positive
 * rule on 50 of them are reproduced by at most M positive weights; the moments of points with
 * x > 0.6 cannot be carried by candidates with x < 0.5 (the first moment in x alone forbids). */
static void fit(fcm_ctx *ctx)
{
  enum { N = 300, NS = 50 };
  static double pts[3 * N], w[N];
  const double lo[3] = {0, 0, 0};
  for (int m = 2; m <= 6; m += 2) {
    fcm__cheb_box box;
    box.m = m;
    box.q = m;
    box.num_basis = fcm__simplify_num_basis(m);
    for (int d = 0; d < 3; d++)
      box.scale[d] = 2.0, box.shift[d] = -1.0;
    const int M = box.num_basis;
    static double work[16384];
    double b[84], mom[84];
    int idx[84];
    double fw[84];
    TEST_TRUE(M <= 84 && fcm__simplify_moments_scratch(m) <= 16384);
    util_random_box((uint64_t)m, N, lo, 1.0, 1.0, pts, w);
    fcm__simplify_moments(&box, NS, pts, NULL, w, b, work); /* the first NS candidates' rule */
    fcm__fit f = {0, 0, idx, fw, 0.0, 0.0, ""};
    TEST_OK(ctx, fcm__simplify_fit(ctx, &box, N, pts, b, 1e-12, 1e-14, &f));
    TEST_TRUE(f.ok && f.count >= 1 && f.count <= M && f.residual <= 1e-12);
    double err = 0.0, bmax = 0.0;
    for (int c = 0; c < f.count; c++)
      TEST_TRUE(fw[c] > 0.0 && idx[c] >= 0 && idx[c] < N && (c == 0 || idx[c] > idx[c - 1]));
    fcm__simplify_moments(&box, f.count, pts, idx, fw, mom, work);
    for (int i = 0; i < M; i++)
      err = fmax(err, fabs(mom[i] - b[i])), bmax = fmax(bmax, fabs(b[i]));
    TEST_TRUE(err <= 1e-12 * bmax);
    /* a tolerance below rounding: NNLS stops at its optimum short of it, the SVD + LP path
     * runs, and the failure says by how much the residual misses */
    TEST_OK(ctx, fcm__simplify_fit(ctx, &box, N, pts, b, 1e-19, 1e-21, &f));
    TEST_TRUE(!f.ok && strstr(f.message, "above 1e-19") != NULL);

    for (int j = 0; j < N; j++) /* candidates in x < 0.5, the rule's points moved to x > 0.6 */
      pts[3 * j] = j < NS ? 0.6 + 0.4 * pts[3 * j] : 0.5 * pts[3 * j];
    fcm__simplify_moments(&box, NS, pts, NULL, w, b, work);
    TEST_OK(ctx, fcm__simplify_fit(ctx, &box, N - NS, pts + 3 * NS, b, 1e-12, 1e-14, &f));
    TEST_TRUE(!f.ok && strstr(f.message, "no positive combination") != NULL);
    TEST_TRUE(strstr(f.message, "separating polynomial") != NULL); /* proved, not run out */
  }
}

/* fcm__fit_dgemv_t against the sums in long double: |error| <= m eps sum_i |a_i x_i| (any
 * summation order), for m rows of every remainder modulo 8 and n of every remainder modulo 8;
 * fcm__fit_sgemv_rows (A by rows) against the plain loop over the rows in order, bit for bit,
 * for n of every remainder modulo 8 and of 32 (its lanes sum no two columns' terms together). */
static void products(void)
{
  enum { LDA = 70, NMAX = 19, LDR = 75 };
  uint64_t s = 12345;
  double A[LDA * NMAX], x[LDA], y[NMAX];
  float Ar[LDA * LDR], xf[LDA], yf[LDR];
  for (int e = 0; e < LDA * NMAX; e++)
    A[e] = 2.0 * util_rand(&s) - 1.0;
  for (int e = 0; e < LDA * LDR; e++)
    Ar[e] = (float)(2.0 * util_rand(&s) - 1.0);
  for (int i = 0; i < LDA; i++)
    x[i] = 2.0 * util_rand(&s) - 1.0, xf[i] = (float)x[i];
  int bad = 0, sbad = 0;
  for (int m = 1; m <= 64; m++) {
    for (int n = 0; n <= NMAX; n += 1) {
      fcm__fit_dgemv_t(m, n, A, LDA, x, y);
      for (int j = 0; j < n; j++) {
        long double t = 0.0L, mag = 0.0L;
        for (int i = 0; i < m; i++)
          t += (long double)A[j * LDA + i] * x[i], mag += fabsl((long double)A[j * LDA + i] * x[i]);
        bad += !(fabsl((long double)y[j] - t) <= m * DBL_EPSILON * mag + 1e-300);
      }
    }
    for (int n = 0; n <= LDR; n += m % 7 + 1) {
      fcm__fit_sgemv_rows(m, n, Ar, LDR, xf, yf);
      for (int j = 0; j < n; j++) {
        volatile float t = 0.0f; /* one rounding per product and per sum, in order */
        for (int i = 0; i < m; i++) {
          volatile float p = Ar[i * LDR + j] * xf[i];
          t = t + p;
        }
        sbad += memcmp(&yf[j], (const void *)&t, sizeof t) != 0;
      }
    }
  }
  TEST_TRUE(bad == 0);
  TEST_TRUE(sbad == 0);
}

/* fcm__nnls_top_cosine() against one running maximum over the columns in order: the same value,
 * bit for bit, on every count of columns 0..40 (every remainder of the chains) and k = 190, with
 * values drawn from a few levels (ties in different chains), negative ones, zeros of both
 * signs, NaNs and columns marked passive. */
static void scans(void)
{
  enum { KMAX = 190, IT = 7 };
  uint64_t s = 4242;
  double g[KMAX], inv[KMAX];
  int pas[KMAX], bad = 0, found = 0;
  for (int rep = 0; rep < 400; rep++) {
    const int k = rep % 41 == 40 ? KMAX : rep % 41;
    for (int j = 0; j < k; j++) {
      const double u = util_rand(&s);
      g[j] = u < 0.05 ? NAN : u < 0.1 ? -0.0 : u < 0.15 ? 0.0 : (double)(int)(8.0 * u) - 2.0;
      inv[j] = util_rand(&s) < 0.5 ? 1.0 : 0.5;
      pas[j] = util_rand(&s) < 0.2 ? IT : -1;
    }
    double top = 0.0;
    for (int j = 0; j < k; j++) {
      const double c = g[j] * inv[j];
      if (pas[j] != IT && c > top) top = c;
    }
    const double got = fcm__nnls_top_cosine(k, g, inv, pas, IT);
    bad += memcmp(&got, &top, sizeof got) != 0;
    found += top > 0.0;
  }
  TEST_TRUE(bad == 0);
  TEST_TRUE(found > 100); /* the control: most scans have a positive largest */
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  tall_unique(ctx);
  wide_consistent(ctx);
  known_optimum(ctx);
  kkt(ctx);
  shortlist(ctx);
  cancelling(ctx);
  certificate(ctx);
  fit(ctx);
  products();
  scans();
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
