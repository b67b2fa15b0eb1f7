/* Node elimination: shrink a positive interior quadrature rule by removing its
 * least significant points and restoring exactness by moving the others.
 *
 * After Xiao & Gimbutas, "A numerical algorithm for the construction of efficient
 * quadrature rules in two and higher dimensions", CAMWA 59 (2010), §3: with an
 * orthonormal basis phi_j (rulegen_impl.h, phi_0 = 1 for the uniform probability
 * measure) the moment equations are r_j = sum_i w_i phi_j(x_i) - delta_j0 = 0 in
 * the unknowns (x_i, w_i). A point's significance is w_i sum_j phi_j(x_i)^2; the
 * least significant point is removed and r = 0 is restored by Levenberg–Marquardt
 * steps on the column-scaled Jacobian, solved through the smaller of the two Gram
 * matrices (J J^T + mu I or J^T J + mu I, Cholesky). Steps are cut back so that
 * weights stay positive and points keep a margin from the boundary. A removal is
 * kept only when max_j |r_j| <= tol; otherwise the next candidate is tried. While
 * the unknowns greatly outnumber the equations, several points go at once. */
#include "quad/quad_impl.h"
#include "quad/rulegen_impl.h"
#include "la/la_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

fcm_rulegen_options fcm_rulegen_options_default(void)
{
  fcm_rulegen_options o;
  memset(&o, 0, sizeof o);
  o.tol = 1e-14;
  o.max_iterations = 60;
  o.max_candidates = 12;
  o.target_points = 0;
  o.max_batch = 0.05;
  o.margin = 1e-9;
  return o;
}

static int is_simplex(fcm_shape shape)
{
  return shape == FCM_SHAPE_TRI || shape == FCM_SHAPE_TET;
}

double fcm__rulegen_min_distance(fcm_shape shape, int n, const double *x)
{
  int d = fcm_shape_dim(shape);
  double dmin = HUGE_VAL;
  for (int i = 0; i < n; i++) {
    const double *p = x + (size_t)d * i;
    if (is_simplex(shape)) {
      double s = 0.0;
      for (int k = 0; k < d; k++) {
        dmin = FCM_MIN(dmin, p[k]);
        s += p[k];
      }
      dmin = FCM_MIN(dmin, (1.0 - s) / sqrt((double)d));
    } else {
      for (int k = 0; k < d; k++)
        dmin = FCM_MIN(dmin, 1.0 - fabs(p[k]));
    }
  }
  return dmin;
}

/* Workspace of one elimination. Points are n x d row-major; weights are
 * normalized to sum 1 (the basis is orthonormal for the probability measure).
 * The Jacobian is M x n(d+1), column-major: for point i the columns i(d+1)+k,
 * k < d, hold w_i dphi/dx_k and column i(d+1)+d holds phi(x_i). */
/* Points held fixed per step before falling back to a shortened step. */
#define FREEZE_MAX 16

typedef struct ws {
  fcm_ctx *ctx;
  fcm_shape shape;
  int m, d, nc, M, cap;
  const fcm_rulegen_options *opts;
  double *J, *J2; /* current and trial Jacobian */
  double *Js;     /* column-scaled Jacobian of the last factorization */
  double *K, *Kf; /* Gram matrix and its damped Cholesky factor */
  double *r, *r2; /* residuals (M) */
  double *y, *dlt, *scale;
  double *x2, *w2; /* trial state inside the solver */
  char *frozen;    /* points held fixed in the current step */
  long long iterations;
} ws;

/* Jacobian and residual at (x, w); returns ||r||_2 in *f and max |r_j| in *rinf. */
static void build(const ws *s, int n, const double *x, const double *w, double *J, double *r,
                  double *f, double *rinf)
{
  const int M = s->M, d = s->d, nc = s->nc;
  const int par = (size_t)M * n > 20000; /* threads only pay off on large rules */
  const int nt = fcm_ctx_num_threads(s->ctx);
#pragma omp parallel for num_threads(nt) schedule(static) if (par)
  for (int i = 0; i < n; i++) {
    double *col = J + (size_t)M * nc * i;
    fcm__orthobasis_eval(s->shape, s->m, x + (size_t)d * i, col + (size_t)M * d, col, M);
    for (int k = 0; k < d; k++)
      for (int j = 0; j < M; j++)
        col[(size_t)k * M + j] *= w[i];
  }
  double f2 = 0.0, ri = 0.0;
#pragma omp parallel for num_threads(nt) schedule(static) reduction(+ : f2) reduction(max : ri) if (par)
  for (int j = 0; j < M; j++) {
    long double acc = 0.0L;
    for (int i = 0; i < n; i++)
      acc += (long double)w[i] * J[(size_t)M * (nc * i + d) + j];
    r[j] = (double)(acc - (j == 0 ? 1.0L : 0.0L));
    f2 += r[j] * r[j];
    ri = FCM_MAX(ri, fabs(r[j]));
  }
  *f = sqrt(f2);
  *rinf = ri;
}

/* Largest tau keeping point i's weight positive and the point at least `margin`
 * inside along (x_i, w_i) + tau * dlt_i (HUGE_VAL when unbounded). */
static double point_step(const ws *s, const double *p, double wi, const double *dp)
{
  const int d = s->d;
  const double margin = s->opts->margin;
  double tmax = HUGE_VAL;
  if (dp[d] < 0.0) tmax = wi / -dp[d];
  if (is_simplex(s->shape)) {
    double sum = 0.0, dsum = 0.0;
    for (int k = 0; k < d; k++) {
      if (dp[k] < 0.0) tmax = FCM_MIN(tmax, FCM_MAX(p[k] - margin, 0.0) / -dp[k]);
      sum += p[k];
      dsum += dp[k];
    }
    double g = (1.0 - sum) / sqrt((double)d) - margin, dg = -dsum / sqrt((double)d);
    if (dg < 0.0) tmax = FCM_MIN(tmax, FCM_MAX(g, 0.0) / -dg);
  } else {
    for (int k = 0; k < d; k++) { /* 1 - x_k >= margin and 1 + x_k >= margin */
      if (dp[k] > 0.0) tmax = FCM_MIN(tmax, FCM_MAX(1.0 - p[k] - margin, 0.0) / dp[k]);
      if (dp[k] < 0.0) tmax = FCM_MIN(tmax, FCM_MAX(1.0 + p[k] - margin, 0.0) / -dp[k]);
    }
  }
  return tmax;
}

/* Largest tau over all points; *block receives the point that limits it. */
static double max_step(const ws *s, int n, const double *x, const double *w, const double *dlt,
                       int *block)
{
  double tmax = HUGE_VAL;
  *block = -1;
  for (int i = 0; i < n; i++) {
    double t = point_step(s, x + (size_t)s->d * i, w[i], dlt + (size_t)s->nc * i);
    if (t < tmax) {
      tmax = t;
      *block = i;
    }
  }
  return tmax;
}

/* Solve for the step with the current factorization: dlt (unscaled) from the
 * residual r, the scaled Jacobian Js and the damped Gram factor Kf. */
static fcm_status solve_step(ws *s, int n, const double *r)
{
  fcm_status st = FCM_OK;
  const int M = s->M, nc = s->nc, nv = n * nc;
  const int under = nv >= M, sz = under ? M : nv;
  if (under) {
    for (int j = 0; j < M; j++)
      s->y[j] = -r[j];
    FCM_TRY(s->ctx, fcm__potrs(s->ctx, sz, 1, s->Kf, sz, s->y, sz));
    fcm__gemv('T', M, nv, 1.0, s->Js, M, s->y, 0.0, s->dlt);
    for (int i = 0; i < n; i++)
      if (s->frozen[i])
        for (int k = 0; k < nc; k++)
          s->dlt[nc * i + k] = 0.0;
  } else {
    fcm__gemv('T', M, nv, -1.0, s->Js, M, r, 0.0, s->dlt);
    for (int i = 0; i < n; i++)
      if (s->frozen[i])
        for (int k = 0; k < nc; k++)
          s->dlt[nc * i + k] = 0.0;
    FCM_TRY(s->ctx, fcm__potrs(s->ctx, sz, 1, s->Kf, sz, s->dlt, sz));
  }
  for (int c = 0; c < nv; c++)
    s->dlt[c] /= s->scale[c];
cleanup:
  return st;
}

/* Trial state (x, w) + tau dlt into (x2, w2), its Jacobian into J2 and residual r2. */
static void trial(ws *s, int n, const double *x, const double *w, double tau, double *f2,
                  double *rinf2)
{
  const int d = s->d, nc = s->nc;
  for (int i = 0; i < n; i++) {
    for (int k = 0; k < d; k++)
      s->x2[(size_t)d * i + k] = x[(size_t)d * i + k] + tau * s->dlt[(size_t)nc * i + k];
    s->w2[i] = w[i] + tau * s->dlt[(size_t)nc * i + d];
  }
  build(s, n, s->x2, s->w2, s->J2, s->r2, f2, rinf2);
}

/* Make the trial state current. */
static void accept(ws *s, int n, double *x, double *w)
{
  double *t;
  memcpy(x, s->x2, sizeof(double) * (size_t)s->d * n);
  memcpy(w, s->w2, sizeof(double) * (size_t)n);
  t = s->J, s->J = s->J2, s->J2 = t;
  t = s->r, s->r = s->r2, s->r2 = t;
}

/* The scaled Jacobian s->Js (one factor for all coordinate columns, one for all weight
 * columns: per-column scaling would let tiny-weight points fly to the boundary; s->scale)
 * and its Gram matrix s->K (J J^T when the system is underdetermined, else J^T J); returns
 * the mean of K's diagonal. */
static double scaled_gram(ws *s, int n)
{
  const int M = s->M, d = s->d, nc = s->nc, nv = n * nc;
  const int under = nv >= M, sz = under ? M : nv;
  double sx = 0.0, sw = 0.0;
  for (int c = 0; c < nv; c++) {
    const double *col = s->J + (size_t)M * c;
    double nrm = 0.0;
    for (int j = 0; j < M; j++)
      nrm += col[j] * col[j];
    if (c % nc == d)
      sw += nrm;
    else
      sx += nrm;
  }
  sx = sx > 0.0 ? sqrt(sx / (n * d)) : 1.0;
  sw = sw > 0.0 ? sqrt(sw / n) : 1.0;
  for (int c = 0; c < nv; c++) {
    const double *col = s->J + (size_t)M * c;
    double *out = s->Js + (size_t)M * c;
    s->scale[c] = (c % nc == d) ? sw : sx;
    for (int j = 0; j < M; j++)
      out[j] = col[j] / s->scale[c];
  }
  if (under)
    fcm__gemm('N', 'T', M, M, nv, 1.0, s->Js, M, s->Js, M, 0.0, s->K, sz);
  else
    fcm__gemm('T', 'N', nv, nv, M, 1.0, s->Js, M, s->Js, M, 0.0, s->K, sz);
  double diag = 0.0;
  for (int k = 0; k < sz; k++)
    diag += s->K[(size_t)k * sz + k];
  return diag / sz;
}

/* Levenberg–Marquardt on (x, w) with n points, in place. *converged = 1 when
 * max |r_j| <= tol was reached (then s->J, s->r hold the final state). With
 * tol < 0 it only polishes: up to max_iter decreasing steps. After a full step
 * the factorization is reused for chord steps while they contract the residual
 * by 4 or more; otherwise the Jacobian and its Gram matrix are refreshed. */
static fcm_status lm_solve(ws *s, int n, double *x, double *w, double tol, int max_iter,
                           int *converged, double *rinf_out)
{
  fcm_status st = FCM_OK;
  const int M = s->M, nc = s->nc, nv = n * nc;
  const int under = nv >= M, sz = under ? M : nv;
  double f, rinf, lambda = 1e-8;
  int slow = 0, have_factor = 0;
  *converged = 0;
  build(s, n, x, w, s->J, s->r, &f, &rinf);
  for (int it = 0;; it++) {
    if (tol >= 0.0 && rinf <= tol) {
      *converged = 1;
      break;
    }
    if (it >= max_iter || !isfinite(f)) break;
    s->iterations++;
    if (have_factor) { /* chord step with the previous factorization */
      int block;
      FCM_TRY(s->ctx, solve_step(s, n, s->r));
      if (max_step(s, n, x, w, s->dlt, &block) >= 1.0) {
        double f2, rinf2;
        trial(s, n, x, w, 1.0, &f2, &rinf2);
        if (f2 < 0.25 * f) {
          accept(s, n, x, w);
          f = f2;
          rinf = rinf2;
          continue;
        }
      }
      have_factor = 0;
    }
    const double diag = scaled_gram(s, n);
    int accepted = 0, nfrozen = 0;
    memset(s->frozen, 0, (size_t)n);
    while (!accepted) {
      if (lambda > 1e8) goto cleanup; /* stuck: not converged */
      memcpy(s->Kf, s->K, sizeof(double) * (size_t)sz * sz);
      for (int k = 0; k < sz; k++)
        s->Kf[(size_t)k * sz + k] += lambda * diag;
      fcm_status fst = fcm__potrf(s->ctx, sz, s->Kf, sz);
      if (fst == FCM_ERR_SINGULAR) { /* rounding made the damped Gram indefinite */
        fcm_ctx_error_clear(s->ctx);
        lambda *= 10.0;
        continue;
      }
      FCM_TRY(s->ctx, fst);
      FCM_TRY(s->ctx, solve_step(s, n, s->r));
      int block;
      double tau = max_step(s, n, x, w, s->dlt, &block);
      if (tau < 1.0 && block >= 0 && nfrozen < FREEZE_MAX && nfrozen < n - 1) {
        /* a point would leave the domain (or its weight vanish): hold it fixed
         * for this step and let the others absorb the correction */
        const double *jb = s->Js + (size_t)M * nc * block;
        s->frozen[block] = 1;
        nfrozen++;
        if (under) {
          fcm__gemm('N', 'T', M, M, nc, -1.0, jb, M, jb, M, 1.0, s->K, sz);
        } else {
          for (int k = nc * block; k < nc * block + nc; k++) {
            for (int l = 0; l < sz; l++)
              s->K[(size_t)k * sz + l] = s->K[(size_t)l * sz + k] = 0.0;
            s->K[(size_t)k * sz + k] = diag;
          }
        }
        continue;
      }
      tau = tau >= 1.0 ? 1.0 : 0.9 * tau;
      if (tau < 1e-12) {
        lambda *= 10.0;
        continue;
      }
      double f2, rinf2;
      trial(s, n, x, w, tau, &f2, &rinf2);
      if (f2 < f) {
        accepted = 1;
        slow = (f2 > 0.5 * f) ? slow + 1 : 0;
        have_factor = tau == 1.0;
        accept(s, n, x, w);
        f = f2;
        rinf = rinf2;
        lambda = FCM_MAX(lambda / 10.0, 1e-10);
      } else {
        lambda *= 10.0;
      }
    }
    if (tol >= 0.0 && slow >= 6) break; /* a failing attempt stalls */
  }
cleanup:
  *rinf_out = rinf;
  return st;
}

typedef struct sig_entry {
  double s;
  int i;
} sig_entry;

static int sig_cmp(const void *a, const void *b)
{
  const sig_entry *p = a, *q = b;
  return (p->s > q->s) - (p->s < q->s);
}

/* Significance of every point from the current Jacobian, sorted ascending. */
static void significance(const ws *s, int n, const double *w, sig_entry *sig)
{
  for (int i = 0; i < n; i++) {
    const double *phi = s->J + (size_t)s->M * (s->nc * i + s->d);
    double t = 0.0;
    for (int j = 0; j < s->M; j++)
      t += phi[j] * phi[j];
    sig[i].s = w[i] * t;
    sig[i].i = i;
  }
  qsort(sig, (size_t)n, sizeof *sig, sig_cmp);
}

/* Copy (x, w) without the points marked in `drop` into (xt, wt); returns the count. */
static int copy_without(int d, int n, const double *x, const double *w, const char *drop,
                        double *xt, double *wt)
{
  int k = 0;
  for (int i = 0; i < n; i++) {
    if (drop[i]) continue;
    memcpy(xt + (size_t)d * k, x + (size_t)d * i, sizeof(double) * (size_t)d);
    wt[k++] = w[i];
  }
  return k;
}

static void fill_info(fcm_rulegen_info *info, const ws *s, int n, const double *x, const double *w,
                      double rinf, double t0)
{
  double wmin = HUGE_VAL;
  for (int i = 0; i < n; i++)
    wmin = FCM_MIN(wmin, w[i]);
  info->num_points = n;
  info->iterations = s->iterations;
  info->residual = rinf;
  info->min_weight = n > 0 ? wmin * n : 0.0;
  info->min_distance = fcm__rulegen_min_distance(s->shape, n, x);
  info->seconds = fcm_wtime() - t0;
}

static void ws_free(ws *s)
{
  fcm_ctx *ctx = s->ctx;
  fcm__free(ctx, s->J);
  fcm__free(ctx, s->J2);
  fcm__free(ctx, s->Js);
  fcm__free(ctx, s->K);
  fcm__free(ctx, s->Kf);
  fcm__free(ctx, s->r);
  fcm__free(ctx, s->r2);
  fcm__free(ctx, s->y);
  fcm__free(ctx, s->dlt);
  fcm__free(ctx, s->scale);
  fcm__free(ctx, s->x2);
  fcm__free(ctx, s->w2);
  fcm__free(ctx, s->frozen);
}

/* The workspace of rules of up to n0 points (s->ctx, M, nc, d set). */
static fcm_status ws_alloc(ws *s, int n0)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const size_t nvmax = (size_t)n0 * s->nc, szmax = FCM_MIN((size_t)s->M, nvmax);
  FCM_ALLOC(ctx, (size_t)s->M * nvmax, s->J);
  FCM_ALLOC(ctx, (size_t)s->M * nvmax, s->J2);
  FCM_ALLOC(ctx, (size_t)s->M * nvmax, s->Js);
  FCM_ALLOC(ctx, szmax * szmax, s->K);
  FCM_ALLOC(ctx, szmax * szmax, s->Kf);
  FCM_ALLOC(ctx, s->M, s->r);
  FCM_ALLOC(ctx, s->M, s->r2);
  FCM_ALLOC(ctx, FCM_MAX((size_t)s->M, nvmax), s->y);
  FCM_ALLOC(ctx, nvmax, s->dlt);
  FCM_ALLOC(ctx, nvmax, s->scale);
  FCM_ALLOC(ctx, (size_t)n0 * s->d, s->x2);
  FCM_ALLOC(ctx, n0, s->w2);
  FCM_ALLOC(ctx, n0, s->frozen);
cleanup:
  return st;
}

/* Scratch of the elimination: trial rules (xt, wt), the points by significance, the points
 * dropped in a trial. */
typedef struct trial_buf {
  double *xt, *wt;
  sig_entry *sig;
  char *drop;
} trial_buf;

/* Remove the least significant points while the rest still integrate the moments: batches
 * of up to opts->max_batch of the points (grown after a success, halved after a failure), then
 * one point at a time among the opts->max_candidates least significant; until
 * opts->target_points, one point, or no candidate succeeds. *n, x, w: the rule, in place;
 * *rinf: the last solve's residual. */
static fcm_status remove_points(ws *s, int *n_io, double *x, double *w, trial_buf *t,
                                fcm_rulegen_info *info, double t0, double *rinf)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_rulegen_options *opts = s->opts;
  const int nfloor = (int)ceil(1.25 * s->M / s->nc);
  int n = *n_io, converged = 0;
  int batch = FCM_MAX(1, (int)(opts->max_batch * n));
  for (;;) {
    if (opts->target_points > 0 && n <= opts->target_points) break;
    if (n <= 1) break;
    int b = 1;
    if (opts->max_batch > 0.0 && n > nfloor) {
      b = FCM_MIN(batch, FCM_MAX(1, (int)(opts->max_batch * n)));
      b = FCM_MAX(1, FCM_MIN(b, n - nfloor));
    }
    if (opts->target_points > 0) b = FCM_MIN(b, n - opts->target_points);
    int done = 0;
    if (b > 1) {
      memset(t->drop, 0, (size_t)n);
      for (int c = 0; c < b; c++)
        t->drop[t->sig[c].i] = 1;
      int nt = copy_without(s->d, n, x, w, t->drop, t->xt, t->wt);
      FCM_TRY(ctx,
              lm_solve(s, nt, t->xt, t->wt, opts->tol, opts->max_iterations, &converged, rinf));
      if (converged) {
        n = nt;
        done = 1;
        batch = FCM_MAX(1, batch + batch / 2);
      } else {
        info->failed_attempts++;
        batch = b / 2;
        continue;
      }
    } else {
      int tries = FCM_MIN(opts->max_candidates, n);
      for (int c = 0; c < tries && !done; c++) {
        memset(t->drop, 0, (size_t)n);
        t->drop[t->sig[c].i] = 1;
        int nt = copy_without(s->d, n, x, w, t->drop, t->xt, t->wt);
        FCM_TRY(ctx,
                lm_solve(s, nt, t->xt, t->wt, opts->tol, opts->max_iterations, &converged, rinf));
        if (converged) {
          n = nt;
          done = 1;
        } else {
          info->failed_attempts++;
        }
      }
      if (!done) break;
    }
    memcpy(x, t->xt, sizeof(double) * (size_t)n * s->d);
    memcpy(w, t->wt, sizeof(double) * (size_t)n);
    significance(s, n, w, t->sig);
    info->removals++;
    if (opts->progress) {
      fill_info(info, s, n, x, w, *rinf, t0);
      opts->progress(opts->progress_user, info);
    }
  }
cleanup:
  *n_io = n;
  return st;
}

/* Final polish: a few more steps on (x, w), kept when they lower the max residual (*rinf:
 * the residual of the rule kept). */
static fcm_status final_polish(ws *s, int n, double *x, double *w, trial_buf *t, double *rinf)
{
  fcm_status st = FCM_OK;
  double r0, f0, rp;
  int converged = 0;
  build(s, n, x, w, s->J, s->r, &f0, &r0);
  memcpy(t->xt, x, sizeof(double) * (size_t)n * s->d);
  memcpy(t->wt, w, sizeof(double) * (size_t)n);
  FCM_TRY(s->ctx, lm_solve(s, n, t->xt, t->wt, -1.0, 4, &converged, &rp));
  if (rp < r0) {
    memcpy(x, t->xt, sizeof(double) * (size_t)n * s->d);
    memcpy(w, t->wt, sizeof(double) * (size_t)n);
    r0 = rp;
  }
  *rinf = r0;
cleanup:
  return st;
}

fcm_status fcm__rulegen_eliminate(fcm_ctx *ctx, fcm_shape shape, int m, int n0, const double *x0,
                                  const double *w0, const fcm_rulegen_options *opts,
                                  fcm_rulegen_info *info, int *n_out, double **x_out,
                                  double **w_out)
{
  fcm_status st = FCM_OK;
  ws s;
  double *x = NULL, *w = NULL;
  trial_buf t = {NULL, NULL, NULL, NULL};
  const double t0 = fcm_wtime(), meas = fcm_shape_measure(shape);
  int n = n0, converged = 0;
  double rinf = 0.0;
  memset(&s, 0, sizeof s);
  memset(info, 0, sizeof *info);
  *n_out = 0;
  *x_out = *w_out = NULL;
  s.ctx = ctx;
  s.shape = shape;
  s.m = m;
  s.d = fcm_shape_dim(shape);
  s.nc = s.d + 1;
  s.M = fcm__orthobasis_size(shape, m);
  s.cap = n0;
  s.opts = opts;
  FCM_CHECK(s.d > 0 && s.M > 0 && n0 > 0, ctx, FCM_ERR_ARG,
            "node elimination: shape %d, strength %d, %d points unsupported", (int)shape, m, n0);
  FCM_TRY(ctx, ws_alloc(&s, n0));
  FCM_ALLOC(ctx, (size_t)n0 * s.d, x);
  FCM_ALLOC(ctx, n0, w);
  FCM_ALLOC(ctx, (size_t)n0 * s.d, t.xt);
  FCM_ALLOC(ctx, n0, t.wt);
  FCM_ALLOC(ctx, n0, t.sig);
  FCM_ALLOC(ctx, n0, t.drop);
  memcpy(x, x0, sizeof(double) * (size_t)n0 * s.d);
  for (int i = 0; i < n0; i++)
    w[i] = w0[i] / meas;
  info->initial_points = n0;
  /* polish the start rule in the basis of this strength */
  FCM_TRY(ctx, lm_solve(&s, n, x, w, opts->tol, opts->max_iterations, &converged, &rinf));
  FCM_CHECK(converged, ctx, FCM_ERR_NOT_CONVERGED,
            "node elimination: start rule (%d points) reaches moment residual %.3g, not %.3g", n,
            rinf, opts->tol);
  significance(&s, n, w, t.sig);
  FCM_TRY(ctx, remove_points(&s, &n, x, w, &t, info, t0, &rinf));
  FCM_TRY(ctx, final_polish(&s, n, x, w, &t, &rinf));
  fill_info(info, &s, n, x, w, rinf, t0);
  for (int i = 0; i < n; i++)
    w[i] *= meas;
  *n_out = n;
  *x_out = x;
  *w_out = w;
  x = w = NULL;
cleanup:
  ws_free(&s);
  fcm__free(ctx, x);
  fcm__free(ctx, w);
  fcm__free(ctx, t.xt);
  fcm__free(ctx, t.wt);
  fcm__free(ctx, t.sig);
  fcm__free(ctx, t.drop);
  return st;
}

double fcm__rulegen_residual(fcm_ctx *ctx, fcm_shape shape, int m, int n, const double *x,
                             const double *w)
{
  int M = fcm__orthobasis_size(shape, m), d = fcm_shape_dim(shape);
  double meas = fcm_shape_measure(shape), rmax = 0.0;
  double *phi = fcm__calloc(ctx, (size_t)M, sizeof *phi);
  long double *acc = fcm__calloc(ctx, (size_t)M, sizeof *acc);
  if (!phi || !acc) {
    fcm__free(ctx, phi);
    fcm__free(ctx, acc);
    return -1.0;
  }
  for (int i = 0; i < n; i++) {
    fcm__orthobasis_eval(shape, m, x + (size_t)d * i, phi, NULL, M);
    for (int j = 0; j < M; j++)
      acc[j] += (long double)(w[i] / meas) * phi[j];
  }
  for (int j = 0; j < M; j++)
    rmax = FCM_MAX(rmax, fabs((double)(acc[j] - (j == 0 ? 1.0L : 0.0L))));
  fcm__free(ctx, phi);
  fcm__free(ctx, acc);
  return rmax;
}

static int shape_supported(fcm_shape shape)
{
  return fcm_shape_dim(shape) > 0;
}

fcm_status fcm_rule_moment_residual(fcm_ctx *ctx, const fcm_rule *rule, int strength,
                                    double *residual)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(rule && residual, ctx, FCM_ERR_ARG, "moment residual: %s is NULL",
            rule ? "residual" : "rule");
  FCM_CHECK(shape_supported(rule->shape), ctx, FCM_ERR_ARG, "moment residual: shape %d unsupported",
            (int)rule->shape);
  FCM_CHECK(strength >= 0 && strength <= FCM__ORTHOBASIS_MAX_DEGREE, ctx, FCM_ERR_ARG,
            "moment residual: strength %d out of range [0, %d]", strength,
            FCM__ORTHOBASIS_MAX_DEGREE);
  *residual =
      fcm__rulegen_residual(ctx, rule->shape, strength, rule->n, rule->points, rule->weights);
  FCM_CHECK(*residual >= 0.0, ctx, FCM_ERR_ALLOC, "moment residual: out of memory");
cleanup:
  return st;
}

fcm_status fcm_rule_eliminate_nodes(fcm_ctx *ctx, const fcm_rule *start, int strength,
                                    const fcm_rulegen_options *opts, fcm_rulegen_info *info,
                                    fcm_rule **out)
{
  fcm_status st = FCM_OK;
  fcm_rulegen_options o = opts ? *opts : fcm_rulegen_options_default();
  fcm_rulegen_info inf;
  fcm_rule *r = NULL;
  double *x = NULL, *w = NULL;
  int n = 0;
  memset(&inf, 0, sizeof inf);
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "node elimination: output rule pointer is NULL");
  *out = NULL;
  FCM_CHECK(start, ctx, FCM_ERR_ARG, "node elimination: start rule is NULL");
  FCM_CHECK(shape_supported(start->shape), ctx, FCM_ERR_ARG,
            "node elimination: shape %d unsupported", (int)start->shape);
  FCM_CHECK(strength >= 0 && strength <= FCM_MIN(start->strength, FCM__ORTHOBASIS_MAX_DEGREE), ctx,
            FCM_ERR_ARG,
            "node elimination: strength %d out of range [0, %d] (start rule "
            "strength %d)",
            strength, FCM_MIN(start->strength, FCM__ORTHOBASIS_MAX_DEGREE), start->strength);
  FCM_CHECK(start->n > 0, ctx, FCM_ERR_ARG, "node elimination: start rule has no points");
  FCM_CHECK(o.tol > 0.0 && o.tol < 1.0, ctx, FCM_ERR_ARG,
            "node elimination: tol = %g out of range (0, 1)", o.tol);
  FCM_CHECK(o.max_iterations >= 1 && o.max_candidates >= 1 && o.target_points >= 0, ctx,
            FCM_ERR_ARG,
            "node elimination: max_iterations = %d, max_candidates = %d must be "
            ">= 1 and target_points = %d >= 0",
            o.max_iterations, o.max_candidates, o.target_points);
  FCM_CHECK(o.max_batch >= 0.0 && o.max_batch <= 0.5, ctx, FCM_ERR_ARG,
            "node elimination: max_batch = %g out of range [0, 0.5]", o.max_batch);
  FCM_CHECK(o.margin >= 0.0 && o.margin <= 0.1, ctx, FCM_ERR_ARG,
            "node elimination: margin = %g out of range [0, 0.1]", o.margin);
  for (int i = 0; i < start->n; i++) {
    double di = fcm__rulegen_min_distance(start->shape, 1, start->points + (size_t)start->dim * i);
    FCM_CHECK(start->weights[i] > 0.0, ctx, FCM_ERR_ARG,
              "node elimination: start rule weight %d = %g is not positive", i, start->weights[i]);
    FCM_CHECK(di >= o.margin, ctx, FCM_ERR_ARG,
              "node elimination: start rule point %d lies %g from the boundary, margin is %g", i,
              di, o.margin);
  }
  double res =
      fcm__rulegen_residual(ctx, start->shape, strength, start->n, start->points, start->weights);
  FCM_CHECK(res >= 0.0, ctx, FCM_ERR_ALLOC, "node elimination: out of memory");
  FCM_CHECK(res <= 1e-8, ctx, FCM_ERR_ARG,
            "node elimination: start rule is not exact for strength %d (moment residual %.3g)",
            strength, res);
  FCM_TRY(ctx, fcm__rulegen_eliminate(ctx, start->shape, strength, start->n, start->points,
                                      start->weights, &o, &inf, &n, &x, &w));
  FCM_TRY(ctx, fcm__quad_rule_alloc(ctx, start->shape, strength, n, FCM_RULE_COMPUTED, &r));
  memcpy(r->points, x, sizeof(double) * (size_t)n * r->dim);
  memcpy(r->weights, w, sizeof(double) * (size_t)n);
  snprintf(r->description, sizeof r->description,
           "node elimination from %d points (%.60s), residual %.1e", start->n, start->description,
           inf.residual);
  *out = r;
  r = NULL;
cleanup:
  if (info) *info = inf;
  fcm_rule_destroy(&r);
  fcm__free(ctx, x);
  fcm__free(ctx, w);
  return st;
}
