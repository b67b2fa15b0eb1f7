/* The multigrid cycle: V- and W-cycles as a solver (fcm_mg_solve) and as a symmetric
 * preconditioner (fcm_mg_operator), with the coarsest level solved directly.
 *
 * The cycle runs each level's work in two parallel regions (smoothing, residual and
 * restriction; prolongation and smoothing), so a thread never idles through a long
 * sequential stretch and then waits to be woken: on shared cores a woken thread may wait a
 * whole time slice for a core. The functions below run inside such a region (or in a team of
 * one, when the level is too small to share) and end without a barrier unless said. */
#include "core/multiversion.h"
#include "mg/levels_impl.h"

#include <math.h>
#include <string.h>

/* Pre-smoothing, then r = b - A x and the coarse right-hand side R r (coarse guess 0). */
FCM_MULTIVERSION_CLONES
static void pre_smooth(const fcm_mg *m, mg_level *L, mg_level *C, const double *b, double *x)
{
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  const fcm_index n = L->n, nc = C->n;
  for (int s = 0; s < m->opts.pre_smooth; s++) {
    if (s > 0 && m->opts.point_sweep) {
#pragma omp barrier
    }
    fcm__mg_smooth(m, L, b, x, 0);
  }
  if (L->blk && m->opts.pre_smooth > 0) {
#pragma omp barrier
    fcm__mg_block_smooth(m, L, b, x, 0);
  }
#pragma omp barrier
  const unsigned char *triple = L->rows.triple;
#pragma omp for schedule(static)
  for (fcm_index k = 0; k < (n + 2) / 3; k++) {
    const fcm_index i = 3 * k;
    if (fcm__mg_is_triple(triple, i, n)) {
      double s[3];
      fcm__mg_row_dot3(v, ci, rp[i], rp[i + 1] - rp[i], triple[i] == FCM__MG_TRIPLE_NODES, x, s);
      for (int c = 0; c < 3; c++)
        L->r[i + c] = b[i + c] - s[c];
    } else {
      for (fcm_index j = i; j < i + 3 && j < n; j++)
        L->r[j] = b[j] - fcm__mg_row_dot(v, ci, rp[j], rp[j + 1], x);
    }
  }
#pragma omp for schedule(static)
  for (fcm_index J = 0; J < nc; J++) {
    C->b[J] = C->inactive[J]
                  ? 0.0
                  : fcm__mg_row_dot(L->R_val, L->R_col, L->R_ptr[J], L->R_ptr[J + 1], L->r);
    C->x[J] = 0.0;
  }
}

/* x += P x_c (nothing from the coarse Dirichlet DOFs), then post-smoothing. */
static void post_smooth(const fcm_mg *m, mg_level *L, const mg_level *C, const double *b, double *x)
{
  const fcm_index n = L->n;
#pragma omp for schedule(static)
  for (fcm_index i = 0; i < n; i++) {
    double sum = 0.0;
    for (fcm_index p = L->P_ptr[i]; p < L->P_ptr[i + 1]; p++) {
      const fcm_index J = L->P_col[p];
      if (!C->inactive[J]) sum += L->P_val[p] * C->x[J];
    }
    x[i] += sum;
  }
  if (L->blk && m->opts.post_smooth > 0) {
    fcm__mg_block_smooth(m, L, b, x, 1);
#pragma omp barrier
  }
  for (int s = 0; s < m->opts.post_smooth; s++) {
    if (s > 0 && m->opts.point_sweep) {
#pragma omp barrier
    }
    fcm__mg_smooth(m, L, b, x, 1);
  }
}

static fcm_status cycle(fcm_mg *m, int l, const double *b, double *x)
{
  fcm_status st = FCM_OK;
  mg_level *L = &m->lev[l];
  if (l == m->nlev - 1) {
    return fcm_direct_solve(m->direct, b, x); /* level 0 too when there is one level */
  }
  mg_level *C = &m->lev[l + 1];
  fcm_index nnz = 0;
  fcm_csr_get_size(fcm__mg_level_matrix(L), NULL, NULL, &nnz);
  const int par = nnz >= MG_PARALLEL_NNZ;
#pragma omp parallel num_threads(fcm__mg_team(m)) if (par)
  pre_smooth(m, L, C, b, x);
  const int gamma = l + 2 == m->nlev ? 1 : m->opts.cycle_index; /* the coarsest is exact */
  for (int g = 0; g < gamma; g++)
    if ((st = cycle(m, l + 1, C->b, C->x))) return st;
#pragma omp parallel num_threads(fcm__mg_team(m)) if (par)
  post_smooth(m, L, C, b, x);
  return st;
}

fcm_status fcm_mg_cycle(fcm_mg *m, const double *b, double *x)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  FCM_CHECK(m && b && x && b != x, ctx, FCM_ERR_ARG, "mg_cycle: NULL or overlapping argument");
  FCM_CHECK(!m->setup_failed, ctx, FCM_ERR_ARG,
            "mg_cycle: the last fcm_mg_setup() failed, so the levels' values are not one set: "
            "set the hierarchy up again");
  FCM_CHECK(!m->values_pending, ctx, FCM_ERR_ARG,
            "mg_cycle: the hierarchy was created on a pattern and has no values yet: call "
            "fcm_mg_setup() first");
  FCM_TRY(ctx, cycle(m, 0, b, x));
cleanup:
  return st;
}

fcm_status fcm_mg_operator(void *user, const double *r, double *z)
{
  fcm_mg *m = user;
  if (m && z) memset(z, 0, sizeof *z * (size_t)m->lev[0].n);
  return fcm_mg_cycle(m, r, z);
}

/* r = b - A x on rows [i0, i1) (a copy's three rows of one pattern together: three chains of
 * additions side by side, each x read once for the three), each row's sum term by term in
 * its row order as fcm_csr_apply() forms it, so r_i = b_i + (-1 (A x)_i) bit for bit. */
FCM_MULTIVERSION_CLONES
static void residual_rows(const fcm_csr *A, const unsigned char *triple, fcm_index i0, fcm_index i1,
                          const double *b, const double *x, double *r)
{
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  for (fcm_index i = i0; i < i1;) {
    if (i % 3 == 0 && i + 2 < i1 && fcm__mg_is_triple(triple, i, n)) {
      const fcm_index len = rp[i + 1] - rp[i];
      const double *va = v + rp[i], *vb = va + len, *vc = vb + len;
      const int *c = ci + rp[i];
      double s0 = 0.0, s1 = 0.0, s2 = 0.0;
      for (fcm_index p = 0; p < len; p++) {
        const double xp = x[c[p]];
        s0 += va[p] * xp;
        s1 += vb[p] * xp;
        s2 += vc[p] * xp;
      }
      r[i] = b[i] + -1.0 * s0;
      r[i + 1] = b[i + 1] + -1.0 * s1;
      r[i + 2] = b[i + 2] + -1.0 * s2;
      i += 3;
      continue;
    }
    double s = 0.0;
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      s += v[p] * x[ci[p]];
    r[i] = b[i] + -1.0 * s;
    i++;
  }
}

void fcm__mg_residual(const fcm_mg *m, const double *b, const double *x, double *r)
{
  const mg_level *L = &m->lev[0];
  const fcm_csr *A = fcm__mg_level_matrix(L);
  fcm_index nnz = 0;
  fcm_csr_get_size(A, NULL, NULL, &nnz);
  const fcm_index ng = (L->n + 2) / 3;
#pragma omp parallel num_threads(fcm__mg_team(m)) if (nnz >= MG_PARALLEL_NNZ)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const fcm_index g0 = ng * t / nt, g1 = ng * (t + 1) / nt;
    residual_rows(A, L->rows.triple, 3 * g0, FCM_MIN(3 * g1, L->n), b, x, r);
  }
}

static double norm2(fcm_index n, const double *v)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += v[i] * v[i];
  return sqrt(s);
}

fcm_status fcm_mg_solve(fcm_mg *m, const double *b, double *x, double rtol, int max_cycles,
                        fcm_mg_solve_info *info)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  fcm_mg_solve_info inf = {0, 0, 0.0, 0.0};
  FCM_CHECK(m && b && x && b != x, ctx, FCM_ERR_ARG, "mg_solve: NULL or overlapping argument");
  FCM_CHECK(rtol >= 0.0 && max_cycles >= 0, ctx, FCM_ERR_ARG,
            "mg_solve: rtol = %g must be >= 0 and max_cycles = %d >= 0", rtol, max_cycles);
  FCM_CHECK(!m->setup_failed, ctx, FCM_ERR_ARG,
            "mg_solve: the last fcm_mg_setup() failed, so the levels' values are not one set: "
            "set the hierarchy up again");
  FCM_CHECK(!m->values_pending, ctx, FCM_ERR_ARG,
            "mg_solve: the hierarchy was created on a pattern and has no values yet: call "
            "fcm_mg_setup() first");
  mg_level *L = &m->lev[0];
  const fcm_index n = L->n;
  const double bn = norm2(n, b);
  double r1 = 0.0, rk = 0.0;
  for (;;) {
    fcm_csr_apply(L->A, -1.0, x, 0.0, L->b); /* L->b is free on level 0 */
    for (fcm_index i = 0; i < n; i++)
      L->b[i] += b[i];
    rk = norm2(n, L->b);
    FCM_CHECK(isfinite(rk), ctx, FCM_ERR_NUMERIC, "mg_solve: residual is %g after %d cycles", rk,
              inf.cycles);
    inf.relative_residual = bn > 0.0 ? rk / bn : 0.0;
    if (inf.cycles == 1) r1 = rk;
    if (rk <= rtol * bn) {
      inf.converged = 1;
      break;
    }
    if (inf.cycles >= max_cycles) break;
    FCM_TRY(ctx, cycle(m, 0, b, x));
    inf.cycles++;
  }
  if (inf.cycles >= 2 && r1 > 0.0) inf.convergence_factor = pow(rk / r1, 1.0 / (inf.cycles - 1));
  FCM_CHECK(inf.converged, ctx, FCM_ERR_NOT_CONVERGED,
            "mg_solve: relative residual %g after %d cycles, rtol %g", inf.relative_residual,
            inf.cycles, rtol);
cleanup:
  if (info) *info = inf;
  return st;
}
