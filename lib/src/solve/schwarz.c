/* Additive Schwarz preconditioner on blocks of DOFs (cut cells): dense block gather,
 * reflected and clamped eigen-inverse per block, Jacobi on the remaining DOFs.
 *
 * Longva et al. 2020, "Higher-order finite elements for embedded simulation", §5.2,
 * eq. (13)-(14), after de Prenter et al. (2017, 2019): S = sum_K R_K^T S_K R_K + D^{-1},
 * S_K = V diag(s_k) V^T from C_K = R_K C R_K^T = V diag(lambda_k) V^T with
 * s_k = 1/|lambda_k| for |lambda_k| >= eps lambda_max and, below, either 1/(eps lambda_max)
 * (clamp, the authors' code) or eps/lambda_max (eq. 14 as printed); a well-conditioned
 * positive definite block, where neither applies, is inverted through its Cholesky factor
 * (LAPACK's eigensolver takes ~100 us on a 24 x 24 block, the factor a few). The blocks are
 * built in parallel (one block per thread at a time). The apply is one parallel loop over the DOFs
 * without barriers: z_i = r_i / |c_ii| outside the blocks, and inside the sum of the rows
 * for DOF i of the S_K of the blocks holding i (in ascending block order), each z_i summed
 * by one thread, so z = S r does not depend on the number of threads.
 *
 * Created for the multigrid's block smoother (fcm__schwarz_create_blocks()), a setup computes
 * only what the block sweeps read, the S_K: no diagonal outside the blocks, no apply. */
#include "solve/schwarz_impl.h"
#include "core/multiversion.h"

#include <math.h>
#include <omp.h>
#include <string.h>

/* Largest block: m^2 must fit LAPACK's int. */
#define MAX_BLOCK 46340
/* Apply in parallel from this many stored block entries (multiply-adds) on. */
#define APPLY_PARALLEL_WORK 65536
/* DOFs per chunk of the dynamically scheduled apply loop. */
#define APPLY_CHUNK 64
/* The largest eps ||C_K||_F ||C_K^{-1}||_F of a block inverted through its Cholesky factor
 * (cholesky_inverse()): a condition bound 1000 times below the clamping threshold. */
#define SCHWARZ_CHOLESKY_COND 1e-3

fcm_schwarz_options fcm_schwarz_options_default(void)
{
  fcm_schwarz_options o;
  o.epsilon = 1e-13;
  o.clamp = FCM_SCHWARZ_CLAMP;
  return o;
}

void fcm_schwarz_destroy(fcm_schwarz **P)
{
  if (!P || !*P) return;
  fcm_schwarz *p = *P;
  fcm_ctx *ctx = p->ctx;
  fcm__free(ctx, p->block_ptr);
  fcm__free(ctx, p->dofs);
  fcm__free(ctx, p->s_off);
  fcm__free(ctx, p->pos_off);
  fcm__free(ctx, p->S);
  fcm__free(ctx, p->pos);
  fcm__free(ctx, p->full);
  fcm__free(ctx, p->factor);
  fcm__free(ctx, p->inc_ptr);
  fcm__free(ctx, p->inc_blk);
  fcm__free(ctx, p->inc_row);
  fcm__free(ctx, p->inside);
  fcm__free(ctx, p->dinv);
  fcm__free(ctx, p->diag);
  fcm__free(ctx, p->work);
  fcm__free(ctx, p->iwork);
  fcm__free(ctx, p->loc);
  fcm__free(ctx, p);
  *P = NULL;
}

/* The DOF -> (block, row) incidence of the apply (blocks ascending per DOF), and a greedy
 * colouring in block order for the statistics: a block takes the smallest colour not used
 * by an earlier block sharing one of its DOFs. */
static fcm_status incidence_and_colors(fcm_schwarz *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_index n = P->n, nb = P->num_blocks;
  fcm_index *inc_ptr = NULL, *inc = NULL, *fill = NULL, *mark = NULL;
  int *color = NULL;
  FCM_ALLOC(ctx, n + 1, P->inc_ptr);
  FCM_ALLOC(ctx, FCM_MAX(P->block_ptr[nb], 1), P->inc_blk);
  FCM_ALLOC(ctx, FCM_MAX(P->block_ptr[nb], 1), P->inc_row);
  inc_ptr = P->inc_ptr;
  inc = P->inc_blk;
  FCM_ALLOC(ctx, n, fill); /* per DOF */
  FCM_ALLOC(ctx, nb, color);
  FCM_ALLOC(ctx, nb + 1, mark);
  /* DOF -> blocks containing it (ascending) */
  for (fcm_index p = 0; p < P->block_ptr[nb]; p++)
    inc_ptr[P->dofs[p] + 1]++;
  for (fcm_index i = 0; i < n; i++)
    inc_ptr[i + 1] += inc_ptr[i];
  for (fcm_index b = 0; b < nb; b++)
    for (fcm_index p = P->block_ptr[b]; p < P->block_ptr[b + 1]; p++) {
      fcm_index d = P->dofs[p], q = inc_ptr[d] + fill[d]++;
      inc[q] = b;
      P->inc_row[q] = (int)(p - P->block_ptr[b]);
    }
  int ncol = 0;
  for (fcm_index b = 0; b < nb; b++) {
    for (fcm_index p = P->block_ptr[b]; p < P->block_ptr[b + 1]; p++) {
      fcm_index d = P->dofs[p];
      for (fcm_index q = inc_ptr[d]; q < inc_ptr[d + 1] && inc[q] < b; q++)
        mark[color[inc[q]]] = b + 1;
    }
    int c = 0;
    while (mark[c] == b + 1)
      c++;
    color[b] = c;
    ncol = FCM_MAX(ncol, c + 1);
  }
  P->num_colors = ncol;
cleanup:
  fcm__free(ctx, fill);
  fcm__free(ctx, color);
  fcm__free(ctx, mark);
  return st;
}

/* Why one block failed during the parallel setup. */
typedef enum block_fail { FAIL_NONE, FAIL_NONFINITE, FAIL_ZERO, FAIL_LAPACK } block_fail;

typedef struct block_stats {
  fcm_index negative, clamped;
} block_stats;

/* Gather C_K = R_K C R_K^T into a (m x m, column-major) by scanning the block rows: each
 * block row's matrix row is read once, its columns found through loc (DOF -> block index + 1,
 * zero outside the block, left zero on return). Records where each entry lies in its row
 * (pos, its lower triangle packed by rows, -1: not stored) and returns whether all of the
 * lower triangle is stored in *full.
 * 0 when an entry is NaN or infinite. vals and a NULL: the positions from C's pattern only. */
static int gather_scan(const fcm_csr *C, const double *vals, int m, const fcm_index *d, int *loc,
                       int *pos, unsigned char *full, double *a)
{
  const fcm_index *rp = fcm_csr_row_ptr(C);
  const int *ci = fcm_csr_col_idx(C);
  int finite = 1, stored = 0;
  if (a) memset(a, 0, sizeof *a * (size_t)m * (size_t)m);
  for (size_t e = 0; e < FCM__SCHWARZ_PACKED(m, 0); e++)
    pos[e] = -1;
  for (int j = 0; j < m; j++)
    loc[d[j]] = j + 1;
  for (int i = 0; i < m; i++) {
    int *row = pos + FCM__SCHWARZ_PACKED(i, 0);
    for (fcm_index p = rp[d[i]]; p < rp[d[i] + 1]; p++) {
      const int k = loc[ci[p]];
      if (!k) continue;
      if (a) {
        if (k - 1 <= i) finite &= isfinite(vals[p]) != 0;
        a[i + (size_t)(k - 1) * m] = vals[p];
      }
      if (k - 1 > i) continue;
      if (row[k - 1] < 0) stored++;
      row[k - 1] = (int)(p - rp[d[i]]);
    }
  }
  for (int j = 0; j < m; j++)
    loc[d[j]] = 0;
  *full = (size_t)stored == FCM__SCHWARZ_PACKED(m, 0);
  return finite;
}

/* Gather C_K's lower triangle (all that the Cholesky factor and dsyevd read) through the
 * positions of a block whose entries are all stored (pos of gather_scan()), each checked
 * against C's pattern, entry (i, j) into a[(i + j m) stride]: 1 when all finite, 0 when one is
 * NaN or infinite, -1 (a unfinished) when C's pattern has moved an entry. known: C's pattern is
 * the one the positions were found on (fcm__schwarz_setup_known()): its columns are not read
 * again. */
static int gather_known(const fcm_csr *C, const double *vals, int m, const fcm_index *d,
                        const int *pos, double *a, size_t stride, int known)
{
  const fcm_index *rp = fcm_csr_row_ptr(C);
  const int *ci = fcm_csr_col_idx(C);
  int finite = 1;
  for (int i = 0; i < m; i++) {
    const fcm_index r0 = rp[d[i]], len = rp[d[i] + 1] - r0;
    const int *pi = pos + FCM__SCHWARZ_PACKED(i, 0);
    for (int j = 0; j <= i; j++) {
      const fcm_index p = r0 + pi[j];
      if (pi[j] >= len || (!known && ci[p] != d[j])) return -1;
      finite &= isfinite(vals[p]) != 0;
      a[(i + (size_t)j * m) * stride] = vals[p];
    }
  }
  return finite;
}

/* The three stages of cholesky_inverse() work two by two (two rows of L, two columns of X, two
 * entries of S at a time): each entry's sum still runs over k in ascending order, as one chain
 * of dependent operations, and two chains interleaved keep the floating-point units busy. */

/* L of C_K = L L^T (row-major) from the lower triangle of a (column-major), with 1 / L_jj
 * stored on the diagonal: the entries below it are multiplied by it, a division's latency
 * not on each entry's chain; 0 when a pivot is not positive and finite. Rows i and i + 1 go
 * together: at each column j <= i entry (i, j) first (entry (i + 1, i) takes 1 / L_ii, found
 * in the same step). */
static int cholesky_factor(int m, const double *a, double *L)
{
  for (int i = 0; i < m; i += 2) {
    double *Li = L + (size_t)i * m, *Lh = i + 1 < m ? Li + m : NULL;
    for (int j = 0; j <= i; j++) {
      const double *Lj = L + (size_t)j * m;
      double v = a[i + (size_t)j * m], u = Lh ? a[i + 1 + (size_t)j * m] : 0.0;
      int k = 0;
      if (Lh)
        for (; k < j; k++) {
          v -= Li[k] * Lj[k];
          u -= Lh[k] * Lj[k];
        }
      else
        for (; k < j; k++)
          v -= Li[k] * Lj[k];
      if (i > j) {
        Li[j] = v * Lj[j];
      } else {
        if (!(v > 0.0 && isfinite(v))) return 0;
        Li[i] = 1.0 / sqrt(v);
      }
      if (Lh) Lh[j] = u * Lj[j];
    }
    if (Lh) { /* the diagonal of row i + 1 */
      double v = a[i + 1 + (size_t)(i + 1) * m];
      for (int k = 0; k < i + 1; k++)
        v -= Lh[k] * Lh[k];
      if (!(v > 0.0 && isfinite(v))) return 0;
      Lh[i + 1] = 1.0 / sqrt(v);
    }
  }
  return 1;
}

/* X = L^{-1} (lower, row-major; L with 1 / L_ii on its diagonal, cholesky_factor()),
 * columns j and j + 1 together. */
static void cholesky_invert_factor(int m, const double *L, double *X)
{
  for (int j = 0; j < m; j += 2) {
    const int h = j + 1;
    X[(size_t)j * m + j] = L[(size_t)j * m + j];
    if (h < m) {
      X[(size_t)h * m + h] = L[(size_t)h * m + h];
      double v = 0.0;
      v -= L[(size_t)h * m + j] * X[(size_t)j * m + j];
      X[(size_t)h * m + j] = v * L[(size_t)h * m + h];
    }
    for (int i = j + 2; i < m; i++) {
      const double *Li = L + (size_t)i * m;
      double v = 0.0, u = 0.0;
      v -= Li[j] * X[(size_t)j * m + j];
      for (int k = h; k < i; k++) {
        v -= Li[k] * X[(size_t)k * m + j];
        u -= Li[k] * X[(size_t)k * m + h];
      }
      X[(size_t)i * m + j] = v * Li[i];
      X[(size_t)i * m + h] = u * Li[i];
    }
  }
}

/* S = X^T X (upper triangle, mirrored), entries (i, j) and (i, j + 1) together; returns
 * ||S||_F^2 summed in the order of the entries (i, then j ascending). */
static double cholesky_product(int m, const double *X, double *S)
{
  double ns = 0.0;
  for (int i = 0; i < m; i++)
    for (int j = i; j < m; j += 2) {
      double v = 0.0, u = 0.0;
      v += X[(size_t)j * m + i] * X[(size_t)j * m + j];
      if (j + 1 < m) {
        for (int k = j + 1; k < m; k++) {
          v += X[(size_t)k * m + i] * X[(size_t)k * m + j];
          u += X[(size_t)k * m + i] * X[(size_t)k * m + j + 1];
        }
      }
      S[(size_t)i * m + j] = S[(size_t)j * m + i] = v;
      ns += (i == j ? 1.0 : 2.0) * v * v;
      if (j + 1 < m) {
        S[(size_t)i * m + j + 1] = S[(size_t)(j + 1) * m + i] = u;
        ns += 2.0 * u * u;
      }
    }
  return ns;
}

/* The lower triangle of the symmetric m x m T (row major) packed by rows into S. */
static void pack_lower(int m, const double *T, double *S)
{
  for (int i = 0; i < m; i++)
    memcpy(S + FCM__SCHWARZ_PACKED(i, 0), T + (size_t)i * m, sizeof *S * (size_t)(i + 1));
}

/* S_K = C_K^{-1} through the Cholesky factor C_K = L L^T (the lower triangle of a; L and
 * X = L^{-1} row-major in lw, 2 m^2 doubles), when that factor exists and
 * ||C_K||_F ||S_K||_F <= SCHWARZ_CHOLESKY_COND / eps: then every eigenvalue lies in
 * (eps lambda_max / 1000, lambda_max] up to rounding, none is negative or clamped, and the
 * eigen-inverse of build_block() is the same C_K^{-1} (both to rounding of order
 * cond(C_K) times the unit round-off). 0 (S_K not written) otherwise.
 * factor non-NULL (a block smoother, whose slot holds a lower triangle packed by rows and
 * whose sweeps may apply S_K = X^T X as two triangular products): X's triangle into S's slot
 * (*factor = 1) when the bound ||S_K||_F <= ||X||_F^2 already passes the test, which then
 * needs no product; else S_K's lower triangle (*factor = 0). The same blocks take the Cholesky
 * path either way. */
static int cholesky_inverse(int m, const double *a, double eps, double *lw, double *S,
                            unsigned char *factor)
{
  double *L = lw, *X = lw + (size_t)m * m, na = 0.0;
  if (factor) *factor = 0;
  for (int i = 0; i < m; i++)
    for (int j = 0; j <= i; j++) {
      const double v = a[i + (size_t)j * m];
      na += (i == j ? 1.0 : 2.0) * v * v;
    }
  if (!cholesky_factor(m, a, L)) return 0;
  cholesky_invert_factor(m, L, X);
  if (factor) {
    double nx = 0.0;
    for (int i = 0; i < m; i++)
      for (int j = 0; j <= i; j++)
        nx += X[(size_t)i * m + j] * X[(size_t)i * m + j];
    if (isfinite(nx) && sqrt(na) * nx <= SCHWARZ_CHOLESKY_COND / eps) {
      pack_lower(m, X, S);
      *factor = 1;
      return 1;
    }
  }
  double *T = factor ? L : S; /* a packed slot's S_K formed in L's place (L is done with) */
  const double ns = cholesky_product(m, X, T);
  const int ok = isfinite(ns) && sqrt(na) * sqrt(ns) <= SCHWARZ_CHOLESKY_COND / eps;
  if (ok && factor) pack_lower(m, T, S);
  return ok;
}

/* Four blocks of one size at once, one in each lane of a vector: cholesky_factor(),
 * cholesky_invert_factor() and cholesky_inverse()'s test written with vectors of four, each
 * lane the same operations in the same order as one block alone (ISO C evaluation, no
 * contraction), so the same bits; four independent chains of dependent operations per
 * instruction instead of two. Arrays of a batch interleave the lanes: entry e of lane q at
 * 4 e + q. */
typedef double v4d __attribute__((vector_size(4 * sizeof(double)), aligned(sizeof(double))));
#define BATCH 4

/* *r = 1 / sqrt(v) in each lane; bit q of *bad set where v's lane q is not positive and
 * finite. */
static inline __attribute__((always_inline)) void inv_sqrt4(const v4d *v, v4d *r, unsigned *bad)
{
  for (int q = 0; q < BATCH; q++) {
    if (!((*v)[q] > 0.0 && isfinite((*v)[q]))) *bad |= 1u << q;
    (*r)[q] = 1.0 / sqrt((*v)[q]);
  }
}

/* cholesky_factor() of four blocks; the lanes whose factor does not exist in *bad. */
static inline __attribute__((always_inline)) void cholesky_factor4(int m, const v4d *a, v4d *L,
                                                                   unsigned *bad)
{
  const v4d zero = {0.0, 0.0, 0.0, 0.0};
  for (int i = 0; i < m; i += 2) {
    v4d *Li = L + (size_t)i * m, *Lh = i + 1 < m ? Li + m : NULL;
    for (int j = 0; j <= i; j++) {
      const v4d *Lj = L + (size_t)j * m;
      v4d v = a[i + (size_t)j * m], u = Lh ? a[i + 1 + (size_t)j * m] : zero;
      int k = 0;
      if (Lh)
        for (; k < j; k++) {
          v -= Li[k] * Lj[k];
          u -= Lh[k] * Lj[k];
        }
      else
        for (; k < j; k++)
          v -= Li[k] * Lj[k];
      if (i > j)
        Li[j] = v * Lj[j];
      else
        inv_sqrt4(&v, &Li[i], bad);
      if (Lh) Lh[j] = u * Lj[j];
    }
    if (Lh) {
      v4d v = a[i + 1 + (size_t)(i + 1) * m];
      for (int k = 0; k < i + 1; k++)
        v -= Lh[k] * Lh[k];
      inv_sqrt4(&v, &Lh[i + 1], bad);
    }
  }
}

/* cholesky_invert_factor() of four blocks. */
static inline __attribute__((always_inline)) void cholesky_invert_factor4(int m, const v4d *L,
                                                                          v4d *X)
{
  const v4d zero = {0.0, 0.0, 0.0, 0.0};
  for (int j = 0; j < m; j += 2) {
    const int h = j + 1;
    X[(size_t)j * m + j] = L[(size_t)j * m + j];
    if (h < m) {
      X[(size_t)h * m + h] = L[(size_t)h * m + h];
      v4d v = zero;
      v -= L[(size_t)h * m + j] * X[(size_t)j * m + j];
      X[(size_t)h * m + j] = v * L[(size_t)h * m + h];
    }
    for (int i = j + 2; i < m; i++) {
      const v4d *Li = L + (size_t)i * m;
      v4d v = zero, u = zero;
      v -= Li[j] * X[(size_t)j * m + j];
      for (int k = h; k < i; k++) {
        v -= Li[k] * X[(size_t)k * m + j];
        u -= Li[k] * X[(size_t)k * m + h];
      }
      X[(size_t)i * m + j] = v * Li[i];
      X[(size_t)i * m + h] = u * Li[i];
    }
  }
}

/* The block smoother's blocks b .. b + 3 (one size m, all entries stored) by the factor path
 * of cholesky_inverse() at once: each lane's X into its S slot where its factor exists and
 * passes the test with the bound ||S_K||_F <= ||X||_F^2; the lanes done in the result's bits
 * (the others, and all when a gather is not clean, to build_block()). w: 12 m^2
 * doubles of the thread's scratch. Compiled for the CPU's vector width where the build makes
 * per-CPU clones (core/multiversion.h: the same roundings). */
FCM_MULTIVERSION_CLONES
static unsigned build_batch(fcm_schwarz *P, const fcm_csr *C, const double *vals, fcm_index b,
                            int m, double *w, int known)
{
  const size_t mm = (size_t)m * (size_t)m;
  v4d *a = (v4d *)w, *L = a + mm, *X = L + mm;
  for (int q = 0; q < BATCH; q++)
    if (gather_known(C, vals, m, P->dofs + P->block_ptr[b + q], P->pos + P->pos_off[b + q], w + q,
                     BATCH, known) != 1)
      return 0;
  unsigned bad = 0, done = 0;
  cholesky_factor4(m, a, L, &bad);
  if (bad == (1u << BATCH) - 1u) return 0;
  cholesky_invert_factor4(m, L, X);
  v4d na = {0.0, 0.0, 0.0, 0.0}, nx = na;
  for (int i = 0; i < m; i++)
    for (int j = 0; j <= i; j++) {
      const v4d v = a[i + (size_t)j * m];
      na += (i == j ? 1.0 : 2.0) * v * v;
    }
  for (int i = 0; i < m; i++)
    for (int j = 0; j <= i; j++)
      nx += X[(size_t)i * m + j] * X[(size_t)i * m + j];
  const double limit = SCHWARZ_CHOLESKY_COND / P->opts.epsilon;
  for (int q = 0; q < BATCH; q++) {
    if ((bad >> q) & 1u || !(isfinite(nx[q]) && sqrt(na[q]) * nx[q] <= limit)) continue;
    double *S = P->S + P->s_off[b + q];
    for (int i = 0; i < m; i++)
      for (int j = 0; j <= i; j++)
        S[FCM__SCHWARZ_PACKED(i, j)] = X[(size_t)i * m + j][q];
    P->factor[b + q] = 1;
    done |= 1u << q;
  }
  return done;
}

/* Gather C_K, then S_K: by cholesky_inverse() where it applies, else by the symmetric
 * eigendecomposition with reflected and clamped eigenvalues. */
static fcm_status build_block(fcm_schwarz *P, const fcm_csr *C, const double *vals, fcm_index b,
                              int *loc, double *a, double *w, double *lw, int *iw, block_stats *bs,
                              block_fail *fail, int known)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_index *d = P->dofs + P->block_ptr[b];
  const int m = (int)(P->block_ptr[b + 1] - P->block_ptr[b]);
  double *S = P->S + P->s_off[b];
  int *pos = P->pos + P->pos_off[b];
  int finite = P->full[b] ? gather_known(C, vals, m, d, pos, a, 1, known) : -1;
  if (finite < 0) finite = gather_scan(C, vals, m, d, loc, pos, P->full + b, a);
  if (!finite) {
    *fail = FAIL_NONFINITE;
    return FCM_ERR_NUMERIC;
  }
  if (cholesky_inverse(m, a, P->opts.epsilon, lw, S, P->factor ? P->factor + b : NULL)) return st;
  st = fcm__syev_work(ctx, 1, m, a, m, w, lw, P->lwork, iw, P->liwork);
  if (st != FCM_OK) {
    *fail = st == FCM_ERR_ALLOC ? FAIL_NONE : FAIL_LAPACK;
    return st;
  }
  const double lmax = FCM_MAX(fabs(w[0]), fabs(w[m - 1]));
  if (!(lmax > 0.0)) {
    *fail = FAIL_ZERO;
    return FCM_ERR_SINGULAR;
  }
  const double eps = P->opts.epsilon, tau = eps * lmax;
  const double small = P->opts.clamp == FCM_SCHWARZ_PAPER ? eps / lmax : 1.0 / tau;
  for (int k = 0; k < m; k++) {
    double l = fabs(w[k]);
    if (w[k] < 0.0) bs->negative++;
    if (l >= tau) {
      w[k] = 1.0 / l;
    } else {
      w[k] = small;
      bs->clamped++;
    }
  }
  /* S_K = V diag(s) V^T, upper triangle computed, mirrored (packed: the lower triangle) */
  for (int i = 0; i < m; i++)
    for (int j = i; j < m; j++) {
      double s = 0.0;
      for (int k = 0; k < m; k++)
        s += a[i + (size_t)k * m] * w[k] * a[j + (size_t)k * m];
      if (P->blocks_only)
        S[FCM__SCHWARZ_PACKED(j, i)] = s;
      else
        S[(size_t)i * m + j] = S[(size_t)j * m + i] = s;
    }
  return st;
}

/* dinv outside the blocks, the diagonal at its position found at creation (searched again
 * when the matrix's pattern moved it); fallbacks: the negative ones. */
static fcm_status outside_diagonal(fcm_schwarz *P, const fcm_csr *C, const double *vals,
                                   fcm_index *fallbacks)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_index *rp = fcm_csr_row_ptr(C);
  const int *ci = fcm_csr_col_idx(C);
  for (fcm_index i = 0; i < P->n; i++) {
    if (P->inside[i]) {
      P->dinv[i] = 0.0;
      continue;
    }
    fcm_index p = P->diag[i];
    if (p < rp[i] || p >= rp[i + 1] || ci[p] != i) p = P->diag[i] = fcm_csr_position(C, i, i);
    double dii = p >= 0 ? vals[p] : 0.0;
    FCM_CHECK(isfinite(dii), ctx, FCM_ERR_NUMERIC,
              "schwarz: diagonal entry of row %lld (outside all blocks) is %g", (long long)i, dii);
    FCM_CHECK(dii != 0.0, ctx, FCM_ERR_SINGULAR,
              "schwarz: diagonal entry of row %lld (outside all blocks) is zero", (long long)i);
    if (dii < 0.0) (*fallbacks)++;
    P->dinv[i] = 1.0 / fabs(dii);
  }
cleanup:
  return st;
}

/* fcm_schwarz_setup(); known: C's pattern is the one of the last set-up (only values changed). */
static fcm_status setup(fcm_schwarz *P, const fcm_csr *C, int known)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P ? P->ctx : NULL;
  fcm_index nr = -1, nc = -1;
  double t0 = fcm_wtime();
  FCM_CHECK(P && C, ctx, FCM_ERR_ARG, "schwarz_setup: NULL argument");
  fcm_csr_get_size(C, &nr, &nc, NULL);
  FCM_CHECK(nr == P->n && nc == P->n, ctx, FCM_ERR_ARG,
            "schwarz_setup: matrix is %lld x %lld, the preconditioner was created for %lld x %lld",
            (long long)nr, (long long)nc, (long long)P->n, (long long)P->n);
  P->ready = 0;
  const double *vals = fcm_csr_values_read(C);
  fcm_index fallbacks = 0;
  if (!P->blocks_only) FCM_TRY(ctx, outside_diagonal(P, C, vals, &fallbacks));

  const fcm_index nb = P->num_blocks;
  fcm_index bad = -1, negative = 0, clamped = 0;
  fcm_status bad_st = FCM_OK;
  block_fail bad_fail = FAIL_NONE;
#pragma omp parallel num_threads(P->nt) if (nb > 1) reduction(+ : negative, clamped)
  if (nb > 0) {
    const int t = omp_get_thread_num();
    double *a = P->work + P->per_thread * (size_t)t;
    double *w = a + (size_t)P->max_m * (size_t)P->max_m;
    double *lw = w + P->max_m;
    int *iw = P->iwork + P->liwork * (size_t)t;
    int *loc = P->loc + (size_t)P->n * (size_t)t;
    const fcm_index ng = (nb + BATCH - 1) / BATCH;
#pragma omp for schedule(dynamic, 1)
    for (fcm_index g = 0; g < ng; g++) {
      const fcm_index b0 = BATCH * g, b1 = FCM_MIN(nb, b0 + BATCH);
      const int m = (int)(P->block_ptr[b0 + 1] - P->block_ptr[b0]);
      int same = P->factor && b1 - b0 == BATCH;
      for (fcm_index b = b0; same && b < b1; b++)
        same = P->full[b] && P->block_ptr[b + 1] - P->block_ptr[b] == m;
      const unsigned done = same ? build_batch(P, C, vals, b0, m, a + P->scalar_work, known) : 0u;
      for (fcm_index b = b0; b < b1; b++) {
        if ((done >> (b - b0)) & 1u) continue;
        block_stats bs = {0, 0};
        block_fail fail = FAIL_NONE;
        fcm_status s = build_block(P, C, vals, b, loc, a, w, lw, iw, &bs, &fail, known);
        negative += bs.negative;
        clamped += bs.clamped;
        if (s != FCM_OK) {
#pragma omp critical(fcm_schwarz_bad)
          if (bad < 0 || b < bad) {
            bad = b;
            bad_st = s;
            bad_fail = fail;
          }
        }
      }
    }
  }
  if (bad >= 0) {
    const fcm_index *d = P->dofs + P->block_ptr[bad];
    const long long m = (long long)(P->block_ptr[bad + 1] - P->block_ptr[bad]);
    FCM_CHECK(bad_fail != FAIL_NONFINITE, ctx, FCM_ERR_NUMERIC,
              "schwarz: block %lld (%lld DOFs, first DOF %lld) contains NaN or Inf", (long long)bad,
              m, (long long)d[0]);
    FCM_CHECK(bad_fail != FAIL_ZERO, ctx, FCM_ERR_SINGULAR,
              "schwarz: block %lld (%lld DOFs, first DOF %lld) is zero (all eigenvalues 0)",
              (long long)bad, m, (long long)d[0]);
    FCM_CHECK(bad_fail != FAIL_LAPACK, ctx, bad_st,
              "schwarz: eigendecomposition of block %lld (%lld DOFs) failed: %s", (long long)bad, m,
              fcm_status_name(bad_st));
    st = bad_st; /* allocation failure inside dsyevd, already recorded */
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  P->info.negative_eigenvalues = negative;
  P->info.clamped_eigenvalues = clamped;
  P->info.jacobi_fallbacks = fallbacks;
  P->info.setup_time = fcm_wtime() - t0;
  P->ready = 1;
cleanup:
  return st;
}

fcm_status fcm_schwarz_setup(fcm_schwarz *P, const fcm_csr *C)
{
  return setup(P, C, 0);
}

fcm_status fcm__schwarz_setup_known(fcm_schwarz *P, const fcm_csr *C)
{
  return setup(P, C, 1);
}

/* A new P's first values: its set-up, or with values_later its positions alone, copied from
 * prior's blocks where it has them and found from C's pattern elsewhere. */
static fcm_status first_values(fcm_schwarz *P, const fcm_csr *C, int values_later,
                               const unsigned char *tri, const fcm__schwarz_prior *prior)
{
  if (!values_later) return fcm_schwarz_setup(P, C);
  if (prior && prior->old && prior->old->pos && prior->old->blocks_only)
    return fcm__schwarz_positions_from(P, C, tri, prior);
  fcm__schwarz_scan_positions(P, C, tri);
  return FCM_OK;
}

/* fcm_schwarz_create(); blocks_only: for the block smoother (fcm__schwarz_create_blocks()),
 * set up now unless values_later (the positions found from the pattern then). */
static fcm_status create(fcm_ctx *ctx, const fcm_csr *C, fcm_index num_blocks,
                         const fcm_index *block_ptr, const fcm_index *block_dofs,
                         const fcm_schwarz_options *opts, int blocks_only, int values_later,
                         const unsigned char *tri, const fcm__schwarz_prior *prior,
                         fcm_schwarz **out)
{
  fcm_status st = FCM_OK;
  fcm_schwarz *P = NULL;
  fcm_index *stamp = NULL;
  fcm_index nr = -1, nc = -1;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "schwarz_create: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(C, ctx, FCM_ERR_ARG, "schwarz_create: matrix is NULL");
  fcm_csr_get_size(C, &nr, &nc, NULL);
  FCM_CHECK(nr == nc, ctx, FCM_ERR_ARG, "schwarz_create: matrix is %lld x %lld, not square",
            (long long)nr, (long long)nc);
  FCM_CHECK(num_blocks >= 0, ctx, FCM_ERR_ARG, "schwarz_create: num_blocks = %lld must be >= 0",
            (long long)num_blocks);
  FCM_CHECK(num_blocks == 0 || (block_ptr && block_dofs), ctx, FCM_ERR_ARG,
            "schwarz_create: block_ptr or block_dofs is NULL with %lld blocks",
            (long long)num_blocks);
  fcm_schwarz_options o = opts ? *opts : fcm_schwarz_options_default();
  FCM_CHECK(o.epsilon > 0.0 && o.epsilon < 1.0, ctx, FCM_ERR_ARG,
            "schwarz_create: epsilon = %g out of range (0, 1)", o.epsilon);
  FCM_CHECK(o.clamp == FCM_SCHWARZ_CLAMP || o.clamp == FCM_SCHWARZ_PAPER, ctx, FCM_ERR_ARG,
            "schwarz_create: clamp = %d is not FCM_SCHWARZ_CLAMP (%d) or FCM_SCHWARZ_PAPER (%d)",
            (int)o.clamp, (int)FCM_SCHWARZ_CLAMP, (int)FCM_SCHWARZ_PAPER);
  if (num_blocks > 0)
    FCM_CHECK(block_ptr[0] == 0, ctx, FCM_ERR_ARG, "schwarz_create: block_ptr[0] = %lld must be 0",
              (long long)block_ptr[0]);
  int max_m = 0;
  for (fcm_index b = 0; b < num_blocks; b++) {
    fcm_index m = block_ptr[b + 1] - block_ptr[b];
    FCM_CHECK(m >= 1 && m <= MAX_BLOCK, ctx, FCM_ERR_ARG,
              "schwarz_create: block %lld has %lld DOFs, valid range [1, %d]", (long long)b,
              (long long)m, MAX_BLOCK);
    max_m = FCM_MAX(max_m, (int)m);
  }
  /* DOFs in range and distinct within each block */
  FCM_ALLOC(ctx, nr, stamp);
  for (fcm_index b = 0; b < num_blocks; b++)
    for (fcm_index p = block_ptr[b]; p < block_ptr[b + 1]; p++) {
      fcm_index d = block_dofs[p];
      FCM_CHECK(d >= 0 && d < nr, ctx, FCM_ERR_ARG,
                "schwarz_create: block %lld: DOF %lld out of range [0, %lld)", (long long)b,
                (long long)d, (long long)nr);
      FCM_CHECK(stamp[d] != b + 1, ctx, FCM_ERR_ARG,
                "schwarz_create: block %lld lists DOF %lld twice", (long long)b, (long long)d);
      stamp[d] = b + 1;
    }

  FCM_ALLOC(ctx, 1, P);
  P->ctx = ctx;
  P->n = nr;
  P->blocks_only = blocks_only;
  P->opts = o;
  P->num_blocks = num_blocks;
  P->max_m = max_m;
  const fcm_index total = num_blocks > 0 ? block_ptr[num_blocks] : 0;
  FCM_ALLOC(ctx, num_blocks + 1, P->block_ptr);
  FCM_ALLOC(ctx, FCM_MAX(total, 1), P->dofs);
  FCM_ALLOC(ctx, num_blocks + 1, P->s_off);
  FCM_ALLOC(ctx, num_blocks + 1, P->pos_off);
  FCM_ALLOC(ctx, nr, P->inside);
  if (!blocks_only) FCM_ALLOC(ctx, nr, P->dinv);
  for (fcm_index b = 0; b < num_blocks; b++) {
    fcm_index m = block_ptr[b + 1] - block_ptr[b];
    P->block_ptr[b + 1] = block_ptr[b + 1];
    P->s_off[b + 1] =
        P->s_off[b] + (blocks_only ? FCM__SCHWARZ_PACKED(m, 0) : (size_t)m * (size_t)m);
    P->pos_off[b + 1] = P->pos_off[b] + FCM__SCHWARZ_PACKED(m, 0);
  }
  for (fcm_index p = 0; p < total; p++) {
    P->dofs[p] = block_dofs[p];
    P->inside[block_dofs[p]] = 1;
  }
  if (!blocks_only) {
    FCM_ALLOC(ctx, nr, P->diag);
    for (fcm_index i = 0; i < nr; i++)
      P->diag[i] = P->inside[i] ? -1 : fcm_csr_position(C, i, i);
  }
  /* S and pos are written in full by the first setup (below) before anything reads them */
  FCM_ALLOC_RAW(ctx, FCM_MAX(P->s_off[num_blocks], 1), P->S);
  FCM_ALLOC_RAW(ctx, FCM_MAX(P->pos_off[num_blocks], 1), P->pos);
  FCM_ALLOC(ctx, num_blocks + 1, P->full); /* zero: the first setup scans */
  if (blocks_only) FCM_ALLOC(ctx, num_blocks + 1, P->factor);
  if (!blocks_only) FCM_TRY(ctx, incidence_and_colors(P)); /* the apply's */
  /* setup scratch: the eigensolver workspace of the largest need over the block sizes */
  P->nt = fcm_ctx_num_threads(ctx);
  for (fcm_index b = 0, m_prev = -1; b < num_blocks; b++) {
    const fcm_index m = block_ptr[b + 1] - block_ptr[b];
    size_t lw = 0, liw = 0;
    if (m == m_prev) continue;
    m_prev = m;
    FCM_TRY(ctx, fcm__syev_workspace(ctx, 1, (int)m, &lw, &liw));
    P->lwork = FCM_MAX(P->lwork, lw);
    P->liwork = FCM_MAX(P->liwork, liw);
  }
  P->lwork = FCM_MAX(P->lwork, 2 * (size_t)max_m * (size_t)max_m);
  P->per_thread = (size_t)max_m * (size_t)max_m + (size_t)max_m + P->lwork;
  P->scalar_work = P->per_thread;
  if (blocks_only) P->per_thread += 3 * BATCH * (size_t)max_m * (size_t)max_m; /* build_batch() */
  if (num_blocks > 0) {
    FCM_ALLOC(ctx, P->per_thread * (size_t)P->nt, P->work);
    FCM_ALLOC(ctx, P->liwork * (size_t)P->nt, P->iwork);
    FCM_ALLOC(ctx, (size_t)nr * (size_t)P->nt + 1, P->loc);
  }
  P->info.num_blocks = num_blocks;
  P->info.block_dofs = total;
  P->info.max_block_size = max_m;
  P->info.num_colors = P->num_colors;
  for (fcm_index i = 0; i < nr; i++)
    P->info.outside_dofs += !P->inside[i];
  FCM_TRY(ctx, first_values(P, C, values_later, tri, prior));
  *out = P;
  P = NULL;
cleanup:
  fcm__free(ctx, stamp);
  fcm_schwarz_destroy(&P);
  return st;
}

fcm_status fcm_schwarz_create(fcm_ctx *ctx, const fcm_csr *C, fcm_index num_blocks,
                              const fcm_index *block_ptr, const fcm_index *block_dofs,
                              const fcm_schwarz_options *opts, fcm_schwarz **out)
{
  return create(ctx, C, num_blocks, block_ptr, block_dofs, opts, 0, 0, NULL, NULL, out);
}

fcm_status fcm__schwarz_create_blocks(fcm_ctx *ctx, const fcm_csr *C, fcm_index num_blocks,
                                      const fcm_index *block_ptr, const fcm_index *block_dofs,
                                      fcm_schwarz **out)
{
  return create(ctx, C, num_blocks, block_ptr, block_dofs, NULL, 1, 0, NULL, NULL, out);
}

fcm_status fcm__schwarz_create_blocks_pattern(fcm_ctx *ctx, const fcm_csr *C, fcm_index num_blocks,
                                              const fcm_index *block_ptr,
                                              const fcm_index *block_dofs,
                                              const unsigned char *row_triple,
                                              const fcm__schwarz_prior *prior, fcm_schwarz **out)
{
  return create(ctx, C, num_blocks, block_ptr, block_dofs, NULL, 1, 1, row_triple, prior, out);
}

fcm_status fcm_schwarz_apply(const fcm_schwarz *P, const double *r, double *z)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P ? P->ctx : NULL;
  FCM_CHECK(P, ctx, FCM_ERR_ARG, "schwarz_apply: preconditioner is NULL");
  FCM_CHECK(P->ready, ctx, FCM_ERR_ARG, "schwarz_apply: the last setup failed");
  FCM_CHECK(!P->blocks_only, ctx, FCM_ERR_ARG,
            "schwarz_apply: the preconditioner holds a block smoother's blocks only");
  FCM_CHECK((r && z) || P->n == 0, ctx, FCM_ERR_ARG, "schwarz_apply: r or z is NULL");
  FCM_CHECK(!r || r != z, ctx, FCM_ERR_ARG, "schwarz_apply: r and z must be different arrays");
  const fcm_index n = P->n;
  const double *dinv = P->dinv;
  const int par = n >= FCM__SOLVE_PARALLEL_MIN || P->s_off[P->num_blocks] >= APPLY_PARALLEL_WORK;
  /* One loop, no barrier inside: z_i is summed by one thread, in ascending block order. */
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx))                                     \
    schedule(dynamic, APPLY_CHUNK) if (par)
  for (fcm_index i = 0; i < n; i++) {
    double zi = dinv[i] * r[i];
    for (fcm_index q = P->inc_ptr[i]; q < P->inc_ptr[i + 1]; q++) {
      const fcm_index b = P->inc_blk[q];
      const fcm_index *d = P->dofs + P->block_ptr[b];
      const int m = (int)(P->block_ptr[b + 1] - P->block_ptr[b]);
      const double *row = P->S + P->s_off[b] + (size_t)P->inc_row[q] * (size_t)m;
      double s = 0.0;
      for (int j = 0; j < m; j++)
        s += row[j] * r[d[j]];
      zi += s;
    }
    z[i] = zi;
  }
cleanup:
  return st;
}

fcm_index fcm__schwarz_num_blocks(const fcm_schwarz *P)
{
  return P ? P->num_blocks : 0;
}

int fcm__schwarz_block_factor(const fcm_schwarz *P, fcm_index k)
{
  return P->factor ? P->factor[k] : 0;
}

size_t fcm__schwarz_slot_size(const fcm_schwarz *P, fcm_index k)
{
  return P->s_off[k + 1] - P->s_off[k];
}

int fcm__schwarz_block(const fcm_schwarz *P, fcm_index k, const fcm_index **dofs, const double **S)
{
  *dofs = P->dofs + P->block_ptr[k];
  *S = P->S + P->s_off[k];
  return (int)(P->block_ptr[k + 1] - P->block_ptr[k]);
}

void fcm__schwarz_get_view(const fcm_schwarz *P, fcm__schwarz_view *v)
{
  v->ptr = P->block_ptr, v->dofs = P->dofs, v->s_off = P->s_off, v->S = P->S;
  v->factor = P->factor;
}

fcm_status fcm_schwarz_operator(void *user, const double *r, double *z)
{
  return fcm_schwarz_apply((const fcm_schwarz *)user, r, z);
}

void fcm_schwarz_get_info(const fcm_schwarz *P, fcm_schwarz_info *info)
{
  if (!info) return;
  if (!P) {
    memset(info, 0, sizeof *info);
    return;
  }
  *info = P->info;
}
