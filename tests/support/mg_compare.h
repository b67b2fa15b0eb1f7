/* Shared by the multigrid tests that compare hierarchies bit for bit (tests/mg): the rows a
 * matrix's elimination decoupled, k cycles from a right-hand side, the comparison of two
 * hierarchies (levels, level matrices, inactive rows, cycle output bits) and the reference
 * Galerkin pattern (a dense table). Reads the hierarchy's internals (mg/levels_impl.h). */
#ifndef FCM_TEST_MG_COMPARE_H
#define FCM_TEST_MG_COMPARE_H

#include "mg/levels_impl.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The rows of A (n rows) without an off-diagonal value: those the elimination decoupled
 * (calloc'd, n + 1 bytes). */
static inline unsigned char *mgc_eliminated(const fcm_csr *A, fcm_index n)
{
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  unsigned char *in = calloc((size_t)n + 1, 1);
  for (fcm_index i = 0; i < n; i++) {
    int off = 0;
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      off |= ci[p] != i && v[p] != 0.0;
    in[i] = (unsigned char)!off;
  }
  return in;
}

/* k cycles, the first from b, each next from the last output: k n values into out. */
static inline void mgc_cycles(fcm_ctx *ctx, fcm_mg *mg, const double *b, fcm_index n, int k,
                              double *out)
{
  TEST_OK(ctx, fcm_mg_operator(mg, b, out));
  for (int j = 1; j < k; j++)
    TEST_OK(ctx, fcm_mg_operator(mg, out + (j - 1) * n, out + j * n));
}

/* Same levels, level matrices (pattern and values), inactive rows, and the bits of k cycles
 * from b (n values; finite)? Prints the first level that differs. */
static inline int mgc_same(fcm_ctx *ctx, fcm_mg *a, fcm_mg *b, const double *rhs, fcm_index n,
                           int k)
{
  int same = a->nlev == b->nlev;
  for (int l = 0; same && l < a->nlev; l++) {
    const fcm_csr *A = fcm__mg_level_matrix(&a->lev[l]), *B = fcm__mg_level_matrix(&b->lev[l]);
    fcm_index na = 0, za = 0, nb = 0, zb = 0;
    fcm_csr_get_size(A, &na, NULL, &za);
    fcm_csr_get_size(B, &nb, NULL, &zb);
    same = na == nb && za == zb &&
           !memcmp(fcm_csr_row_ptr(A), fcm_csr_row_ptr(B), sizeof(fcm_index) * (size_t)(na + 1)) &&
           !memcmp(fcm_csr_col_idx(A), fcm_csr_col_idx(B), sizeof(int) * (size_t)za) &&
           !memcmp(fcm_csr_values_read(A), fcm_csr_values_read(B), sizeof(double) * (size_t)za) &&
           !memcmp(a->lev[l].inactive, b->lev[l].inactive, (size_t)na);
    if (!same) printf("  level %d differs\n", l);
  }
  const size_t bytes = sizeof(double) * (size_t)k * (size_t)n;
  double *x1 = malloc(bytes), *x2 = malloc(bytes);
  mgc_cycles(ctx, a, rhs, n, k, x1);
  mgc_cycles(ctx, b, rhs, n, k, x2);
  int finite = 1;
  for (fcm_index i = 0; i < (fcm_index)k * n; i++)
    finite &= isfinite(x1[i]) != 0;
  same = same && finite && memcmp(x1, x2, bytes) == 0;
  free(x1);
  free(x2);
  return same;
}

/* Is level l + 1's pattern exactly the structural pattern of P_l^T A_l P_l with the diagonal?
 * A dense table of the coarse entries reached. */
static inline int mgc_galerkin_exact(const fcm_mg *mg, int l)
{
  const mg_level *L = &mg->lev[l], *C = &mg->lev[l + 1];
  const fcm_csr *A = fcm__mg_level_matrix(L), *Ac = fcm__mg_level_matrix(C);
  const fcm_index *rp = fcm_csr_row_ptr(A), *cp = fcm_csr_row_ptr(Ac);
  const int *ci = fcm_csr_col_idx(A), *cc = fcm_csr_col_idx(Ac);
  const size_t nc = (size_t)C->n;
  unsigned char *hit = calloc(nc * nc + 1, 1);
  for (size_t I = 0; I < nc; I++)
    hit[I * nc + I] = 1;
  for (fcm_index i = 0; i < L->n; i++)
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      for (fcm_index a = L->P_ptr[i]; a < L->P_ptr[i + 1]; a++)
        for (fcm_index b = L->P_ptr[ci[p]]; b < L->P_ptr[ci[p] + 1]; b++)
          hit[(size_t)L->P_col[a] * nc + (size_t)L->P_col[b]] = 1;
  int same = 1;
  for (size_t I = 0; I < nc && same; I++) {
    fcm_index count = 0;
    for (size_t J = 0; J < nc; J++)
      count += hit[I * nc + J];
    same = count == cp[I + 1] - cp[I];
    for (fcm_index q = cp[I]; q < cp[I + 1] && same; q++)
      same = hit[I * nc + (size_t)cc[q]] && (q == cp[I] || cc[q] > cc[q - 1]);
    if (!same) printf("  level %d: coarse row %zu is not P^T A P's\n", l + 1, I);
  }
  free(hit);
  return same;
}

#endif /* FCM_TEST_MG_COMPARE_H */
