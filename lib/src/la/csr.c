/* Compressed sparse row matrices: creation from a pattern, from triplets or
 * around caller arrays, validation, lookup and the OpenMP matrix-vector product. */
#include "la/la_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Rows with fewer non-zeros in total than this are multiplied serially. */
#define CSR_PARALLEL_NNZ 32768

static const char *kind_name(fcm_csr_kind kind)
{
  return kind == FCM_CSR_SYMMETRIC ? "symmetric" : "general";
}

/* Position of col in the sorted row, or -1. */
static fcm_index row_find(const fcm_csr *A, fcm_index row, int col)
{
  fcm_index lo = A->row_ptr[row], hi = A->row_ptr[row + 1];
  while (lo < hi) {
    fcm_index mid = lo + (hi - lo) / 2;
    if (A->col_idx[mid] < col)
      lo = mid + 1;
    else
      hi = mid;
  }
  return (lo < A->row_ptr[row + 1] && A->col_idx[lo] == col) ? lo : -1;
}

/* Sizes, kind and the arrays before anything is allocated. */
static fcm_status check_header(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                               const fcm_index *row_ptr, fcm_csr_kind kind)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(nrows >= 0 && ncols >= 0, ctx, FCM_ERR_ARG,
            "csr: size %lld x %lld must be non-negative", (long long)nrows, (long long)ncols);
  FCM_CHECK(ncols <= INT_MAX, ctx, FCM_ERR_UNSUPPORTED,
            "csr: ncols = %lld exceeds the column index range [0, %d]", (long long)ncols, INT_MAX);
  FCM_CHECK(kind == FCM_CSR_GENERAL || kind == FCM_CSR_SYMMETRIC, ctx, FCM_ERR_ARG,
            "csr: kind = %d is not FCM_CSR_GENERAL or FCM_CSR_SYMMETRIC", (int)kind);
  FCM_CHECK(kind != FCM_CSR_SYMMETRIC || nrows == ncols, ctx, FCM_ERR_ARG,
            "csr: a symmetric matrix must be square, got %lld x %lld", (long long)nrows,
            (long long)ncols);
  FCM_CHECK(row_ptr, ctx, FCM_ERR_ARG, "csr: row_ptr is NULL");
  FCM_CHECK(row_ptr[0] == 0, ctx, FCM_ERR_ARG, "csr: row_ptr[0] = %lld must be 0",
            (long long)row_ptr[0]);
  for (fcm_index i = 0; i < nrows; i++)
    FCM_CHECK(row_ptr[i + 1] >= row_ptr[i], ctx, FCM_ERR_ARG,
              "csr: row_ptr[%lld] = %lld is less than row_ptr[%lld] = %lld", (long long)(i + 1),
              (long long)row_ptr[i + 1], (long long)i, (long long)row_ptr[i]);
cleanup:
  return st;
}

/* Column indices in range and strictly increasing; symmetric pattern if asked. */
static fcm_status check_columns(fcm_ctx *ctx, const fcm_csr *A)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(A->col_idx || A->nnz == 0, ctx, FCM_ERR_ARG, "csr: col_idx is NULL with nnz = %lld",
            (long long)A->nnz);
  for (fcm_index i = 0; i < A->nrows; i++) {
    for (fcm_index p = A->row_ptr[i]; p < A->row_ptr[i + 1]; p++) {
      int c = A->col_idx[p];
      FCM_CHECK(c >= 0 && c < A->ncols, ctx, FCM_ERR_ARG,
                "csr: row %lld: column index %d out of range [0, %lld)", (long long)i, c,
                (long long)A->ncols);
      FCM_CHECK(p == A->row_ptr[i] || c > A->col_idx[p - 1], ctx, FCM_ERR_ARG,
                "csr: row %lld: column %d follows column %d (indices must be strictly "
                "increasing)",
                (long long)i, c, A->col_idx[p - 1]);
    }
  }
  if (A->kind == FCM_CSR_SYMMETRIC) {
    for (fcm_index i = 0; i < A->nrows; i++)
      for (fcm_index p = A->row_ptr[i]; p < A->row_ptr[i + 1]; p++)
        FCM_CHECK(row_find(A, A->col_idx[p], (int)i) >= 0, ctx, FCM_ERR_ARG,
                  "csr: symmetric pattern has entry (%lld, %d) but not (%d, %lld); store both "
                  "triangles",
                  (long long)i, A->col_idx[p], A->col_idx[p], (long long)i);
  }
cleanup:
  return st;
}

/* Handle with the arrays still unset. */
static fcm_status new_handle(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols, fcm_index nnz,
                             fcm_csr_kind kind, fcm_csr **out)
{
  fcm_status st = FCM_OK;
  fcm_csr *A = NULL;
  FCM_ALLOC(ctx, 1, A);
  A->ctx = ctx;
  A->nrows = nrows;
  A->ncols = ncols;
  A->nnz = nnz;
  A->kind = kind;
  *out = A;
cleanup:
  return st;
}

fcm_status fcm_csr_create(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols, const fcm_index *row_ptr,
                          const int *col_idx, fcm_csr_kind kind, fcm_csr **out)
{
  fcm_status st = FCM_OK;
  fcm_csr *A = NULL;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "csr_create: output pointer is NULL");
  *out = NULL;
  FCM_TRY(ctx, check_header(ctx, nrows, ncols, row_ptr, kind));
  FCM_CHECK(col_idx || row_ptr[nrows] == 0, ctx, FCM_ERR_ARG,
            "csr_create: col_idx is NULL with nnz = %lld", (long long)row_ptr[nrows]);
  FCM_TRY(ctx, new_handle(ctx, nrows, ncols, row_ptr[nrows], kind, &A));
  A->owned = 1;
  FCM_ALLOC(ctx, nrows + 1, A->own_row_ptr);
  FCM_ALLOC(ctx, A->nnz, A->own_col_idx);
  FCM__ALLOC_WITH(fcm__calloc_large, ctx, A->nnz, A->values);
  memcpy(A->own_row_ptr, row_ptr, (size_t)(nrows + 1) * sizeof *row_ptr);
  if (A->nnz) memcpy(A->own_col_idx, col_idx, (size_t)A->nnz * sizeof *col_idx);
  A->row_ptr = A->own_row_ptr;
  A->col_idx = A->own_col_idx;
  FCM_TRY(ctx, check_columns(ctx, A));
  *out = A;
  A = NULL;
cleanup:
  fcm_csr_destroy(&A);
  return st;
}

fcm_status fcm__csr_adopt_pattern(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                  fcm_index **row_ptr, int **col_idx, fcm_csr_kind kind,
                                  fcm_csr **out)
{
  fcm_status st = FCM_OK;
  fcm_csr *A = NULL;
  FCM_CHECK(out && row_ptr && *row_ptr && col_idx && *col_idx, ctx, FCM_ERR_ARG,
            "csr_adopt_pattern: NULL argument");
  *out = NULL;
  FCM_TRY(ctx, check_header(ctx, nrows, ncols, *row_ptr, kind));
  FCM_TRY(ctx, new_handle(ctx, nrows, ncols, (*row_ptr)[nrows], kind, &A));
  A->owned = 1;
  A->row_ptr = A->own_row_ptr = *row_ptr;
  A->col_idx = A->own_col_idx = *col_idx;
  *row_ptr = NULL, *col_idx = NULL;
  FCM__ALLOC_WITH(fcm__malloc_large, ctx, A->nnz, A->values);
  *out = A;
  A = NULL;
cleanup:
  if (row_ptr && col_idx && *row_ptr && *col_idx) {
    fcm__free(ctx, *row_ptr);
    fcm__free(ctx, *col_idx);
    *row_ptr = NULL, *col_idx = NULL;
  }
  fcm_csr_destroy(&A);
  return st;
}

fcm_status fcm__csr_share_pattern(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                  const fcm_index *row_ptr, const int *col_idx, fcm_csr_kind kind,
                                  fcm_csr **out)
{
  return fcm__csr_share_pattern_from(ctx, nrows, ncols, row_ptr, col_idx, kind, NULL, out);
}

/* fcm__calloc_large_from() on the values of `give` (owned by it, else none to take). */
static double *values_from(fcm_ctx *ctx, fcm_csr *give, fcm_index nnz)
{
  void *from = give && give->owned ? give->values : NULL;
  double *v = fcm__calloc_large_from(ctx, &from, (size_t)nnz, sizeof *v);
  if (give && give->owned && !from) give->values = NULL; /* taken */
  return v;
}

void fcm__csr_map_room(fcm_csr *A)
{
  if (A && A->owned) fcm__large_map(A->values);
}

int fcm__csr_take_values(fcm_csr *A, fcm_csr *give)
{
  if (!A || !give || A == give || !A->owned || !give->owned || !give->values) return 0;
  void *from = give->values;
  double *v = fcm__large_take(&from, (size_t)A->nnz, sizeof *v);
  if (!v) return 0;
  fcm__free_large(A->ctx, A->values);
  A->values = v;
  give->values = NULL;
  return 1;
}

int fcm__csr_give_back(fcm_csr *from, fcm_csr *to)
{
  if (!from || !to || !from->owned || !to->owned || !from->values || to->values) return 0;
  to->values = from->values;
  from->values = NULL;
  return 1;
}

fcm_status fcm__csr_share_pattern_from(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                       const fcm_index *row_ptr, const int *col_idx,
                                       fcm_csr_kind kind, fcm_csr *give, fcm_csr **out)
{
  return fcm__csr_share_pattern_keep(ctx, nrows, ncols, row_ptr, col_idx, kind, give, out, NULL);
}

fcm_status fcm__csr_share_pattern_keep(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                       const fcm_index *row_ptr, const int *col_idx,
                                       fcm_csr_kind kind, fcm_csr *give, fcm_csr **out, int *taken)
{
  fcm_status st = FCM_OK;
  fcm_csr *A = NULL;
  if (taken) *taken = 0;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "csr_share_pattern: output pointer is NULL");
  *out = NULL;
  FCM_TRY(ctx, check_header(ctx, nrows, ncols, row_ptr, kind));
  FCM_CHECK(col_idx || row_ptr[nrows] == 0, ctx, FCM_ERR_ARG,
            "csr_share_pattern: col_idx is NULL with nnz = %lld", (long long)row_ptr[nrows]);
  FCM_TRY(ctx, new_handle(ctx, nrows, ncols, row_ptr[nrows], kind, &A));
  A->owned = 1; /* the values; the pattern is borrowed (own_row_ptr / own_col_idx NULL) */
  if (taken && give && give->owned) { /* the contents kept */
    void *from = give->values;
    A->values = fcm__large_take(&from, (size_t)A->nnz, sizeof *A->values);
    if (A->values) give->values = NULL, *taken = 1;
  }
  if (!A->values) A->values = values_from(ctx, give, A->nnz);
  if (!A->values) {
    st = FCM_ERR_ALLOC;
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  A->row_ptr = row_ptr;
  A->col_idx = col_idx;
  *out = A;
  A = NULL;
cleanup:
  fcm_csr_destroy(&A);
  return st;
}

fcm_status fcm_csr_wrap(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols, const fcm_index *row_ptr,
                        const int *col_idx, double *values, fcm_csr_kind kind, fcm_csr **out)
{
  fcm_status st = FCM_OK;
  fcm_csr *A = NULL;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "csr_wrap: output pointer is NULL");
  *out = NULL;
  FCM_TRY(ctx, check_header(ctx, nrows, ncols, row_ptr, kind));
  FCM_CHECK(values || row_ptr[nrows] == 0, ctx, FCM_ERR_ARG,
            "csr_wrap: values is NULL with nnz = %lld", (long long)row_ptr[nrows]);
  FCM_TRY(ctx, new_handle(ctx, nrows, ncols, row_ptr[nrows], kind, &A));
  A->owned = 0;
  /* Borrowed: the pattern is only read. */
  A->row_ptr = row_ptr;
  A->col_idx = col_idx;
  A->values = values;
  FCM_TRY(ctx, check_columns(ctx, A));
  *out = A;
  A = NULL;
cleanup:
  fcm_csr_destroy(&A);
  return st;
}

typedef struct entry {
  int col;
  double val;
} entry;

static int entry_cmp(const void *a, const void *b)
{
  int ca = ((const entry *)a)->col, cb = ((const entry *)b)->col;
  return (ca > cb) - (ca < cb);
}

fcm_status fcm_csr_create_triplets(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols, fcm_index ntrip,
                                   const fcm_index *rows, const fcm_index *cols, const double *vals,
                                   fcm_csr_kind kind, fcm_csr **out)
{
  fcm_status st = FCM_OK;
  fcm_index *start = NULL, *fill = NULL, *rp = NULL;
  entry *ent = NULL;
  int *ci = NULL;
  fcm_csr *A = NULL;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "csr_create_triplets: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(nrows >= 0 && ncols >= 0 && ntrip >= 0, ctx, FCM_ERR_ARG,
            "csr_create_triplets: nrows = %lld, ncols = %lld, ntrip = %lld must be non-negative",
            (long long)nrows, (long long)ncols, (long long)ntrip);
  FCM_CHECK(ncols <= INT_MAX, ctx, FCM_ERR_UNSUPPORTED,
            "csr_create_triplets: ncols = %lld exceeds the column index range [0, %d]",
            (long long)ncols, INT_MAX);
  FCM_CHECK(ntrip == 0 || (rows && cols), ctx, FCM_ERR_ARG,
            "csr_create_triplets: rows or cols is NULL with ntrip = %lld", (long long)ntrip);
  for (fcm_index t = 0; t < ntrip; t++)
    FCM_CHECK(rows[t] >= 0 && rows[t] < nrows && cols[t] >= 0 && cols[t] < ncols, ctx, FCM_ERR_ARG,
              "csr_create_triplets: triplet %lld at (%lld, %lld) is outside %lld x %lld",
              (long long)t, (long long)rows[t], (long long)cols[t], (long long)nrows,
              (long long)ncols);

  /* Bucket the triplets by row, sort each row, merge duplicates. */
  FCM_ALLOC(ctx, nrows + 1, start);
  FCM_ALLOC(ctx, nrows + 1, fill);
  FCM_ALLOC(ctx, ntrip, ent);
  for (fcm_index t = 0; t < ntrip; t++)
    start[rows[t] + 1]++;
  for (fcm_index i = 0; i < nrows; i++)
    start[i + 1] += start[i];
  memcpy(fill, start, (size_t)(nrows + 1) * sizeof *fill);
  for (fcm_index t = 0; t < ntrip; t++) {
    entry *e = &ent[fill[rows[t]]++];
    e->col = (int)cols[t];
    e->val = vals ? vals[t] : 0.0;
  }
  FCM_ALLOC(ctx, nrows + 1, rp);
  fcm_index nnz = 0;
  for (fcm_index i = 0; i < nrows; i++) {
    entry *row = ent + start[i];
    size_t len = (size_t)(start[i + 1] - start[i]);
    if (len > 1) qsort(row, len, sizeof *row, entry_cmp);
    for (size_t k = 0; k < len; k++) {
      if (k > 0 && row[k].col == ent[nnz - 1].col) {
        ent[nnz - 1].val += row[k].val;
      } else {
        ent[nnz++] = row[k];
      }
    }
    rp[i + 1] = nnz;
  }
  FCM_ALLOC(ctx, nnz, ci);
  for (fcm_index p = 0; p < nnz; p++)
    ci[p] = ent[p].col;
  FCM_TRY(ctx, fcm_csr_create(ctx, nrows, ncols, rp, ci, kind, &A));
  for (fcm_index p = 0; p < nnz; p++)
    A->values[p] = ent[p].val;
  *out = A;
  A = NULL;
cleanup:
  fcm__free(ctx, start);
  fcm__free(ctx, fill);
  fcm__free(ctx, ent);
  fcm__free(ctx, rp);
  fcm__free(ctx, ci);
  fcm_csr_destroy(&A);
  return st;
}

void fcm_csr_destroy(fcm_csr **A)
{
  if (!A || !*A) return;
  fcm_ctx *ctx = (*A)->ctx;
  fcm__free(ctx, (*A)->own_row_ptr);
  fcm__free(ctx, (*A)->own_col_idx);
  if ((*A)->owned) fcm__free_large(ctx, (*A)->values);
  fcm__free(ctx, *A);
  *A = NULL;
}

void fcm_csr_get_size(const fcm_csr *A, fcm_index *nrows, fcm_index *ncols, fcm_index *nnz)
{
  if (nrows) *nrows = A ? A->nrows : 0;
  if (ncols) *ncols = A ? A->ncols : 0;
  if (nnz) *nnz = A ? A->nnz : 0;
}

fcm_csr_kind fcm_csr_get_kind(const fcm_csr *A)
{
  return A ? A->kind : FCM_CSR_GENERAL;
}

const fcm_index *fcm_csr_row_ptr(const fcm_csr *A)
{
  return A ? A->row_ptr : NULL;
}

const int *fcm_csr_col_idx(const fcm_csr *A)
{
  return A ? A->col_idx : NULL;
}

double *fcm_csr_values(fcm_csr *A)
{
  return A ? A->values : NULL;
}

const double *fcm_csr_values_read(const fcm_csr *A)
{
  return A ? A->values : NULL;
}

fcm_index fcm_csr_position(const fcm_csr *A, fcm_index row, fcm_index col)
{
  if (!A || row < 0 || row >= A->nrows || col < 0 || col >= A->ncols) return -1;
  return row_find(A, row, (int)col);
}

void fcm_csr_set_zero(fcm_csr *A)
{
  if (A && A->nnz) memset(A->values, 0, (size_t)A->nnz * sizeof *A->values);
}

fcm_status fcm_csr_apply(const fcm_csr *A, double alpha, const double *x, double beta, double *y)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = A ? A->ctx : NULL;
  FCM_CHECK(A, ctx, FCM_ERR_ARG, "csr_apply: matrix is NULL");
  FCM_CHECK((x || A->ncols == 0) && (y || A->nrows == 0), ctx, FCM_ERR_ARG,
            "csr_apply: x or y is NULL for a %lld x %lld matrix", (long long)A->nrows,
            (long long)A->ncols);
  FCM_CHECK(!x || x != y, ctx, FCM_ERR_ARG, "csr_apply: x and y must not be the same array");
  const fcm_index n = A->nrows;
  const fcm_index *rp = A->row_ptr;
  const int *ci = A->col_idx;
  const double *v = A->values;
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx))                                     \
    schedule(static) if (A->nnz >= CSR_PARALLEL_NNZ)
  for (fcm_index i = 0; i < n; i++) {
    double s = 0.0;
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      s += v[p] * x[ci[p]];
    y[i] = (beta == 0.0) ? alpha * s : alpha * s + beta * y[i];
  }
cleanup:
  return st;
}

void fcm__csr_apply_rows(const fcm_csr *A, const double *x, double *y, const unsigned char *rows3)
{
  const fcm_index *rp = A->row_ptr;
  const int *ci = A->col_idx;
  const double *v = A->values;
  for (fcm_index i = 0; i < A->nrows; i++) {
    if (!rows3[i / 3]) continue;
    double s = 0.0; /* fcm_csr_apply()'s sum, term by term */
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      s += v[p] * x[ci[p]];
    y[i] = s;
  }
}

fcm_status fcm_csr_asymmetry(const fcm_csr *A, double *rel_asymmetry)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = A ? A->ctx : NULL;
  double amax = 0.0, dmax = 0.0;
  FCM_CHECK(A && rel_asymmetry, ctx, FCM_ERR_ARG, "csr_get_asymmetry: NULL argument");
  FCM_CHECK(A->nrows == A->ncols, ctx, FCM_ERR_ARG,
            "csr_get_asymmetry: %s matrix is %lld x %lld, not square", kind_name(A->kind),
            (long long)A->nrows, (long long)A->ncols);
  for (fcm_index i = 0; i < A->nrows; i++) {
    for (fcm_index p = A->row_ptr[i]; p < A->row_ptr[i + 1]; p++) {
      fcm_index q = row_find(A, A->col_idx[p], (int)i);
      double mirror = q >= 0 ? A->values[q] : 0.0;
      amax = FCM_MAX(amax, fabs(A->values[p]));
      dmax = FCM_MAX(dmax, fabs(A->values[p] - mirror));
    }
  }
  *rel_asymmetry = amax > 0.0 ? dmax / amax : 0.0;
cleanup:
  return st;
}
