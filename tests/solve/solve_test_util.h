/* Helpers shared by the solve tests: a reproducible random generator, a failing
 * allocator, the 3-D 7-point Laplacian as CSR with its exact spectrum, and dense
 * matrices built from operators. */
#ifndef FCM_SOLVE_TEST_UTIL_H
#define FCM_SOLVE_TEST_UTIL_H

#include "fcm/fcm.h"
#include "la/la_impl.h"
#include "test.h"
#include "test_alloc.h"

#include <stdint.h>

#define ST_PI 3.14159265358979323846

/* 7-point Laplacian (6 on the diagonal, -1 to grid neighbours) on the N^3 interior
 * points of a grid with homogeneous Dirichlet boundary, minus shift * I, with
 * optional symmetric scaling D A D (d = NULL: none). Point (i,j,k) is row i + N(j + N k). */
static inline fcm_status laplace3d(fcm_ctx *ctx, int N, double shift, const double *d, fcm_csr **A)
{
  fcm_index n = (fcm_index)N * N * N, cap = 7 * n, nt = 0;
  fcm_index *ri = malloc(sizeof *ri * (size_t)cap), *ci = malloc(sizeof *ci * (size_t)cap);
  double *v = malloc(sizeof *v * (size_t)cap);
  for (int k = 0; k < N; k++)
    for (int j = 0; j < N; j++)
      for (int i = 0; i < N; i++) {
        fcm_index r = i + (fcm_index)N * (j + (fcm_index)N * k);
        const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                              {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        ri[nt] = r, ci[nt] = r, v[nt++] = 6.0 - shift;
        for (int q = 0; q < 6; q++) {
          if (nb[q][0] < 0 || nb[q][0] >= N || nb[q][1] < 0 || nb[q][1] >= N || nb[q][2] < 0 ||
              nb[q][2] >= N)
            continue;
          ri[nt] = r, ci[nt] = nb[q][0] + (fcm_index)N * (nb[q][1] + (fcm_index)N * nb[q][2]);
          v[nt++] = -1.0;
        }
      }
  if (d)
    for (fcm_index t = 0; t < nt; t++)
      v[t] *= d[ri[t]] * d[ci[t]];
  fcm_status st = fcm_csr_create_triplets(ctx, n, n, nt, ri, ci, v, FCM_CSR_SYMMETRIC, A);
  free(ri);
  free(ci);
  free(v);
  return st;
}

/* Extreme eigenvalues of the N^3 Laplacian: 6 -+ 6 cos(pi/(N+1)). */
static inline void laplace3d_extremes(int N, double *lmin, double *lmax)
{
  double c = cos(ST_PI / (N + 1));
  *lmin = 6.0 - 6.0 * c;
  *lmax = 6.0 + 6.0 * c;
}

/* Number of distinct eigenvalues of the N^3 Laplacian (sums of three of the 1-D
 * eigenvalues 2 - 2 cos(k pi/(N+1)), k = 1..N): CG and MINRES terminate within that many
 * iterations in exact arithmetic. */
static inline int laplace3d_distinct(int N)
{
  double *s = malloc(sizeof *s * (size_t)(N * N * N));
  int count = 0;
  for (int i = 1; i <= N; i++)
    for (int j = 1; j <= N; j++)
      for (int k = 1; k <= N; k++) {
        double v = 6.0 - 2.0 * (cos(i * ST_PI / (N + 1)) + cos(j * ST_PI / (N + 1)) +
                                cos(k * ST_PI / (N + 1)));
        int seen = 0;
        for (int q = 0; q < count && !seen; q++)
          seen = fabs(s[q] - v) < 1e-9;
        if (!seen) s[count++] = v;
      }
  free(s);
  return count;
}

/* CG iterations sufficient (exact arithmetic) for ||r_k|| <= rtol ||r_0||:
 * ||r_k|| / ||r_0|| <= 2 sqrt(kappa) ((sqrt(kappa) - 1) / (sqrt(kappa) + 1))^k. */
static inline int cg_iteration_bound(double kappa, double rtol)
{
  double s = sqrt(kappa), rho = (s - 1.0) / (s + 1.0);
  return (int)ceil(log(2.0 * s / rtol) / -log(rho));
}

/* Dense column-major n x n matrix of an operator, column j = op(e_j). */
static inline void dense_of(fcm_operator_fn op, void *user, int n, double *M)
{
  double *e = calloc((size_t)n, sizeof *e);
  for (int j = 0; j < n; j++) {
    e[j] = 1.0;
    if (op(user, e, M + (size_t)j * n) != FCM_OK) fprintf(stderr, "dense_of: operator failed\n");
    e[j] = 0.0;
  }
  free(e);
}

/* ||b - A x||_2 / ||b||_2 with A a CSR matrix. */
static inline double true_residual(const fcm_csr *A, const double *b, const double *x, fcm_index n)
{
  double *r = malloc(sizeof *r * (size_t)n), rr = 0.0, bb = 0.0;
  fcm_csr_apply(A, 1.0, x, 0.0, r);
  for (fcm_index i = 0; i < n; i++) {
    rr += (b[i] - r[i]) * (b[i] - r[i]);
    bb += b[i] * b[i];
  }
  free(r);
  return sqrt(rr / bb);
}

static inline double norm2(const double *x, fcm_index n)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += x[i] * x[i];
  return sqrt(s);
}

#endif
