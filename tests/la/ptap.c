/* The sparse triple product C = P^T A P (fcm__ptap) against a dense product on random sparse
 * matrices (general and symmetric A, P with empty rows and columns): C's pattern holds every
 * structurally nonzero entry (and the diagonal when asked), sorted (and symmetric for a
 * symmetric A; and A of 3 x 3 blocks, whose three rows of a node share a pattern, with P random
 * or a vector field's, each node's weights for its three components), its values
 * match to rounding, new
 * values of A give the new product, the threaded product (2 threads, pattern and values) is
 * bitwise the serial one; argument errors; allocation failures. */
#include "alloc_loop.h"
#include "la/la_impl.h"
#include "test.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* A random sparse n x m matrix as CSR arrays (sorted columns), with `per_row` tries per row;
 * rows with an index divisible by `empty_every` (> 0) stay empty. */
typedef struct sparse {
  fcm_index n, m;
  fcm_index *ptr;
  int *col;
  double *val;
} sparse;

static void sparse_random(rng *r, fcm_index n, fcm_index m, int per_row, int empty_every, sparse *S)
{
  S->n = n, S->m = m;
  S->ptr = calloc((size_t)n + 1, sizeof *S->ptr);
  S->col = malloc(((size_t)n * (size_t)per_row + 1) * sizeof *S->col);
  S->val = malloc(((size_t)n * (size_t)per_row + 1) * sizeof *S->val);
  unsigned char *seen = calloc((size_t)m, 1);
  fcm_index q = 0;
  for (fcm_index i = 0; i < n; i++) {
    if (empty_every <= 0 || i % empty_every != 0)
      for (int t = 0; t < per_row; t++) {
        const fcm_index j = (fcm_index)((rng_uniform(r) + 1.0) * 0.5 * (double)m) % m;
        seen[j] = 1;
      }
    for (fcm_index j = 0; j < m; j++)
      if (seen[j]) {
        S->col[q] = (int)j;
        S->val[q++] = rng_uniform(r);
        seen[j] = 0;
      }
    S->ptr[i + 1] = q;
  }
  free(seen);
}

/* S of a node's three components: entry (I, J) of the random n/3 x m/3 node matrix at
 * (3 I + c, 3 J + c), c = 0, 1, 2 (a vector field's prolongation). */
static void sparse_random_nodes(rng *r, fcm_index n, fcm_index m, int per_row, int empty_every,
                                sparse *S)
{
  sparse N;
  sparse_random(r, n / 3, m / 3, per_row, empty_every, &N);
  S->n = n, S->m = m;
  S->ptr = calloc((size_t)n + 1, sizeof *S->ptr);
  S->col = malloc((3 * (size_t)N.ptr[N.n] + 1) * sizeof *S->col);
  S->val = malloc((3 * (size_t)N.ptr[N.n] + 1) * sizeof *S->val);
  fcm_index q = 0;
  for (fcm_index i = 0; i < n; i++) {
    for (fcm_index p = N.ptr[i / 3]; p < N.ptr[i / 3 + 1]; p++) {
      S->col[q] = 3 * N.col[p] + (int)(i % 3);
      S->val[q++] = N.val[p];
    }
    S->ptr[i + 1] = q;
  }
  free(N.ptr), free(N.col), free(N.val);
}

static void sparse_free(sparse *S)
{
  free(S->ptr), free(S->col), free(S->val);
}

/* Dense row-major copy. */
static double *dense_of(const fcm_index *ptr, const int *col, const double *val, fcm_index n,
                        fcm_index m)
{
  double *D = calloc((size_t)(n * m) + 1, sizeof *D);
  for (fcm_index i = 0; i < n; i++)
    for (fcm_index p = ptr[i]; p < ptr[i + 1]; p++)
      D[i * m + col[p]] = val[p];
  return D;
}

/* A random n x n matrix with `per_row` entries per row and every diagonal entry; symmetric
 * (both triangles, a_ij = a_ji) or general. */
static fcm_csr *matrix_random(fcm_ctx *ctx, rng *r, fcm_index n, int per_row, int symmetric)
{
  const fcm_index cap = n * (2 * per_row + 1);
  fcm_index *ti = malloc((size_t)cap * sizeof *ti), *tj = malloc((size_t)cap * sizeof *tj);
  double *tv = malloc((size_t)cap * sizeof *tv);
  fcm_index t = 0;
  for (fcm_index i = 0; i < n; i++) {
    ti[t] = tj[t] = i, tv[t++] = 4.0 + rng_uniform(r);
    for (int k = 0; k < per_row; k++) {
      const fcm_index j = (fcm_index)((rng_uniform(r) + 1.0) * 0.5 * (double)n) % n;
      const double v = rng_uniform(r);
      ti[t] = i, tj[t] = j, tv[t++] = v;
      if (symmetric) ti[t] = j, tj[t] = i, tv[t++] = v;
    }
  }
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, n, n, t, ti, tj, tv,
                                       symmetric ? FCM_CSR_SYMMETRIC : FCM_CSR_GENERAL, &A));
  free(ti), free(tj), free(tv);
  return A;
}

/* A random symmetric n x n matrix (n divisible by 3) of full 3 x 3 blocks, as a vector
 * field's: rows 3 I, 3 I + 1, 3 I + 2 share one pattern (the product's three-row path). */
static fcm_csr *matrix_random_blocked(fcm_ctx *ctx, rng *r, fcm_index n, int per_row)
{
  const fcm_index nn = n / 3, cap = 18 * nn * (per_row + 1);
  fcm_index *ti = malloc((size_t)cap * sizeof *ti), *tj = malloc((size_t)cap * sizeof *tj);
  double *tv = malloc((size_t)cap * sizeof *tv);
  fcm_index t = 0;
  for (fcm_index I = 0; I < nn; I++)
    for (int k = 0; k <= per_row; k++) {
      const fcm_index J = k == 0 ? I : (fcm_index)((rng_uniform(r) + 1.0) * 0.5 * (double)nn) % nn;
      for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
          const double v = k == 0 && a == b ? 8.0 + rng_uniform(r) : rng_uniform(r);
          ti[t] = 3 * I + a, tj[t] = 3 * J + b, tv[t++] = v;
          ti[t] = 3 * J + b, tj[t] = 3 * I + a, tv[t++] = v;
        }
    }
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, n, n, t, ti, tj, tv, FCM_CSR_SYMMETRIC, &A));
  free(ti), free(tj), free(tv);
  return A;
}

/* max |C - P^T A P| over all entries (0 outside C's pattern must be exact), against the scale
 * of the dense product's terms; diagonal entries must be stored when with_diagonal. */
static void check_dense(const fcm_csr *A, const sparse *P, const fcm_csr *C, int with_diagonal)
{
  const fcm_index n = P->n, nc = P->m;
  double *Ad = dense_of(fcm_csr_row_ptr(A), fcm_csr_col_idx(A), fcm_csr_values_read(A), n, n);
  double *Pd = dense_of(P->ptr, P->col, P->val, n, nc);
  double *AP = calloc((size_t)(n * nc) + 1, sizeof *AP);
  double *APa = calloc((size_t)(n * nc) + 1, sizeof *APa); /* with |.|: the scale */
  for (fcm_index i = 0; i < n; i++)
    for (fcm_index k = 0; k < n; k++)
      if (Ad[i * n + k] != 0.0)
        for (fcm_index j = 0; j < nc; j++) {
          AP[i * nc + j] += Ad[i * n + k] * Pd[k * nc + j];
          APa[i * nc + j] += fabs(Ad[i * n + k] * Pd[k * nc + j]);
        }
  double *Cd = dense_of(fcm_csr_row_ptr(C), fcm_csr_col_idx(C), fcm_csr_values_read(C), nc, nc);
  unsigned char *stored = calloc((size_t)(nc * nc) + 1, 1);
  const fcm_index *cp = fcm_csr_row_ptr(C);
  const int *cc = fcm_csr_col_idx(C);
  for (fcm_index I = 0; I < nc; I++)
    for (fcm_index p = cp[I]; p < cp[I + 1]; p++) {
      /* C's pattern is taken unchecked: its rows must be strictly increasing, in range */
      TEST_TRUE(cc[p] >= 0 && cc[p] < nc && (p == cp[I] || cc[p] > cc[p - 1]));
      stored[I * nc + cc[p]] = 1;
    }
  if (fcm_csr_get_kind(A) == FCM_CSR_SYMMETRIC) /* and symmetric with A's */
    for (fcm_index I = 0; I < nc; I++)
      for (fcm_index J = 0; J < nc; J++)
        TEST_TRUE(stored[I * nc + J] == stored[J * nc + I]);
  for (fcm_index I = 0; I < nc; I++) {
    if (with_diagonal) TEST_TRUE(stored[I * nc + I]);
    for (fcm_index J = 0; J < nc; J++) {
      double s = 0.0, sa = 0.0;
      for (fcm_index i = 0; i < n; i++)
        if (Pd[i * nc + I] != 0.0) {
          s += Pd[i * nc + I] * AP[i * nc + J];
          sa += fabs(Pd[i * nc + I]) * APa[i * nc + J];
        }
      if (!stored[I * nc + J]) {
        if (sa != 0.0) TEST_FAIL_("C(%lld, %lld) = %g not stored", (long long)I, (long long)J, s);
      } else {
        TEST_NEAR(Cd[I * nc + J], s, 0.0, 1e-13 * (sa + 1.0));
      }
    }
  }
  free(Ad), free(Pd), free(AP), free(APa), free(Cd), free(stored);
}

/* One case: dense check with 1 thread, new values, bitwise equality of 1 and 2 threads. */
static void check_case(fcm_ctx *ctx, rng *r, fcm_index n, fcm_index nc, int symmetric,
                       int with_diagonal)
{
  sparse P;
  /* symmetric == 2: A of 3 x 3 blocks (matrix_random_blocked()); 3: and P of a vector
   * field's (sparse_random_nodes()) */
  if (symmetric == 3)
    sparse_random_nodes(r, n, nc, 3, 7, &P);
  else
    sparse_random(r, n, nc, 3, 7, &P);
  fcm_csr *A =
      symmetric >= 2 ? matrix_random_blocked(ctx, r, n, 3) : matrix_random(ctx, r, n, 4, symmetric);
  fcm__ptap *plan1 = NULL, *plan2 = NULL;
  fcm_csr *C1 = NULL, *C2 = NULL;
  TEST_OK(ctx, fcm__ptap_create(ctx, A, nc, P.ptr, P.col, P.val, with_diagonal, 1, &plan1, &C1));
  TEST_OK(ctx, fcm__ptap_create(ctx, A, nc, P.ptr, P.col, P.val, with_diagonal, 2, &plan2, &C2));
  if (!plan1 || !plan2) goto done;
  TEST_TRUE(fcm_csr_get_kind(C1) == fcm_csr_get_kind(A));
  fcm_index nnz1 = 0, nnz2 = 0;
  fcm_csr_get_size(C1, NULL, NULL, &nnz1);
  fcm_csr_get_size(C2, NULL, NULL, &nnz2);
  TEST_TRUE(nnz1 == nnz2);
  TEST_TRUE(
      memcmp(fcm_csr_row_ptr(C1), fcm_csr_row_ptr(C2), sizeof(fcm_index) * (size_t)(nc + 1)) == 0);
  TEST_TRUE(memcmp(fcm_csr_col_idx(C1), fcm_csr_col_idx(C2), sizeof(int) * (size_t)nnz1) == 0);
  /* R = P^T */
  const fcm_index *rp = NULL;
  const int *rc = NULL;
  const double *rv = NULL;
  fcm__ptap_transpose(plan1, &rp, &rc, &rv);
  for (fcm_index J = 0; J < nc; J++)
    for (fcm_index q = rp[J]; q < rp[J + 1]; q++) {
      const fcm_index i = rc[q];
      TEST_TRUE(q == rp[J] || rc[q - 1] < i);
      int found = 0;
      for (fcm_index p = P.ptr[i]; p < P.ptr[i + 1]; p++)
        found |= P.col[p] == J && P.val[p] == rv[q];
      TEST_TRUE(found);
    }
  for (int round = 0; round < 2; round++) {
    if (round == 1) { /* new values on the same pattern (kept symmetric) */
      fcm_index nnz = 0;
      fcm_csr_get_size(A, NULL, NULL, &nnz);
      double *v = fcm_csr_values(A);
      const fcm_index *ap = fcm_csr_row_ptr(A);
      const int *ac = fcm_csr_col_idx(A);
      for (fcm_index i = 0; i < n; i++)
        for (fcm_index p = ap[i]; p < ap[i + 1]; p++)
          if (!symmetric || ac[p] >= i) {
            v[p] = 2.0 * rng_uniform(r);
            if (symmetric) v[fcm_csr_position(A, ac[p], i)] = v[p];
          }
    }
    fcm__ptap_apply(plan1, A, C1, 1);
    fcm__ptap_apply(plan2, A, C2, 2);
    check_dense(A, &P, C1, with_diagonal);
    TEST_TRUE(memcmp(fcm_csr_values_read(C1), fcm_csr_values_read(C2),
                     sizeof(double) * (size_t)nnz1) == 0);
  }
done:
  fcm__ptap_destroy(&plan1);
  fcm__ptap_destroy(&plan2);
  TEST_TRUE(plan1 == NULL);
  fcm_csr_destroy(&C1);
  fcm_csr_destroy(&C2);
  fcm_csr_destroy(&A);
  sparse_free(&P);
}

typedef struct alloc_case {
  fcm_ctx *ctx;
  fcm_csr *A;
  const sparse *P;
  fcm__ptap *plan;
  fcm_csr *C;
} alloc_case;

static fcm_status alloc_call_ptap(void *user)
{
  alloc_case *c = user;
  const fcm_status st = fcm__ptap_create(c->ctx, c->A, c->P->m, c->P->ptr, c->P->col, c->P->val, 1,
                                         2, &c->plan, &c->C);
  if (st != FCM_OK && (c->plan || c->C)) return FCM_ERR_INTERNAL;
  return st;
}

static void alloc_release_ptap(void *user)
{
  alloc_case *c = user;
  fcm__ptap_destroy(&c->plan);
  fcm_csr_destroy(&c->C);
}

int main(void)
{
  omp_set_num_threads(2);
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {0x9e3779b97f4a7c15ULL};
  check_case(ctx, &r, 40, 12, 1, 1);
  check_case(ctx, &r, 40, 12, 0, 0);
  check_case(ctx, &r, 700, 150, 1, 1); /* rows enough for both threads' chunks */
  check_case(ctx, &r, 700, 150, 0, 1);
  check_case(ctx, &r, 42, 12, 2, 1);
  check_case(ctx, &r, 699, 150, 2, 1);
  check_case(ctx, &r, 42, 12, 3, 1);
  check_case(ctx, &r, 699, 150, 3, 1);
  {
    sparse P;
    sparse_random(&r, 20, 5, 2, 0, &P);
    fcm_csr *A = matrix_random(ctx, &r, 20, 3, 1), *B = NULL, *C = NULL;
    fcm__ptap *plan = NULL;
    P.col[1] = 5; /* out of range */
    TEST_ERR(ctx, fcm__ptap_create(ctx, A, 5, P.ptr, P.col, P.val, 1, 1, &plan, &C), FCM_ERR_ARG,
             "outside [0, 5)");
    TEST_TRUE(plan == NULL && C == NULL);
    P.col[1] = 0;
    TEST_ERR(ctx, fcm__ptap_create(ctx, A, 5, P.ptr, P.col, P.val, 1, 0, &plan, &C), FCM_ERR_ARG,
             "nt = 0");
    {
      const fcm_index ti[1] = {0}, tj[1] = {1};
      const double tv[1] = {1.0};
      TEST_OK(ctx, fcm_csr_create_triplets(ctx, 20, 21, 1, ti, tj, tv, FCM_CSR_GENERAL, &B));
      TEST_ERR(ctx, fcm__ptap_create(ctx, B, 5, P.ptr, P.col, P.val, 1, 1, &plan, &C), FCM_ERR_ARG,
               "not square");
      fcm_csr_destroy(&B);
    }
    fcm_csr_destroy(&A);
    sparse_free(&P);
  }
  fcm_ctx_destroy(&ctx);
  {
    failing f;
    fcm_ctx *fctx = failing_ctx(&f);
    TEST_TRUE(fctx != NULL);
    sparse P;
    sparse_random(&r, 60, 15, 3, 5, &P);
    alloc_case c = {fctx, matrix_random(fctx, &r, 60, 3, 1), &P, NULL, NULL};
    alloc_loop(fctx, &f, "ptap_create", alloc_call_ptap, alloc_release_ptap, &c, 8, 200);
    fcm_csr_destroy(&c.A);
    sparse_free(&P);
    fcm_ctx_destroy(&fctx);
  }
  return TEST_RESULT();
}
