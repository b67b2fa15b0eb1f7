/* Matrix-free Krylov solvers: preconditioned conjugate gradients and MINRES with
 * operator and preconditioner callbacks, on a reusable workspace.
 *
 * MINRES follows Paige and Saunders (1975), SIAM J. Numer. Anal. 12(4), in the form of
 * their reference implementation (SOL minres.m): preconditioned Lanczos with the
 * unpreconditioned vectors r1, r2 and y = S r2, a QR factorization of the tridiagonal by
 * Givens rotations, and the three-term update of the search directions w. The monitored
 * quantity phibar_k = ||b - A x_k||_S is non-increasing by construction. */
#include "solve/solve_impl.h"

#include <math.h>
#include <omp.h>
#include <string.h>

/* Vectors shorter than this are processed by one thread. */
#define VEC_PARALLEL 16384
/* Dot products sum fixed chunks (in parallel) and then the chunk sums in order. */
#define DOT_CHUNK 2048
#define NUM_VECS  7

struct fcm_krylov {
  fcm_ctx *ctx;
  fcm_index n;
  double *vecs;    /* NUM_VECS x n */
  double *partial; /* one sum per DOT_CHUNK entries */
  fcm_index num_chunks;
  double *history; /* workspace-owned history, history_capacity entries */
  int history_capacity;
};

const char *fcm_krylov_reason_name(fcm_krylov_reason reason)
{
  switch (reason) {
  case FCM_KRYLOV_NONE:
    return "none";
  case FCM_KRYLOV_CONVERGED_RTOL:
    return "converged-rtol";
  case FCM_KRYLOV_CONVERGED_ATOL:
    return "converged-atol";
  case FCM_KRYLOV_MAX_ITERATIONS:
    return "max-iterations";
  case FCM_KRYLOV_BREAKDOWN:
    return "breakdown";
  case FCM_KRYLOV_INDEFINITE_PRECONDITIONER:
    return "indefinite-preconditioner";
  case FCM_KRYLOV_NAN:
    return "nan";
  case FCM_KRYLOV_CALLBACK_ERROR:
    return "callback-error";
  case FCM_KRYLOV_STAGNATED:
    return "stagnated";
  }
  return "unknown";
}

fcm_krylov_options fcm_krylov_options_default(void)
{
  fcm_krylov_options o;
  memset(&o, 0, sizeof o);
  o.rtol = 1e-8;
  o.atol = 0.0;
  o.max_iterations = 1000;
  o.norm = FCM_KRYLOV_NORM_DEFAULT;
  return o;
}

fcm_status fcm_csr_operator(void *user, const double *x, double *y)
{
  return fcm_csr_apply((const fcm_csr *)user, 1.0, x, 0.0, y);
}

fcm_status fcm_krylov_create(fcm_ctx *ctx, fcm_index n, fcm_krylov **out)
{
  fcm_status st = FCM_OK;
  fcm_krylov *ws = NULL;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "krylov_create: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(n >= 0, ctx, FCM_ERR_ARG, "krylov_create: size n = %lld must be non-negative",
            (long long)n);
  FCM_ALLOC(ctx, 1, ws);
  ws->ctx = ctx;
  ws->n = n;
  ws->num_chunks = FCM_MAX((n + DOT_CHUNK - 1) / DOT_CHUNK, 1);
  FCM_ALLOC(ctx, (size_t)NUM_VECS * (size_t)n, ws->vecs);
  FCM_ALLOC(ctx, ws->num_chunks, ws->partial);
  *out = ws;
  ws = NULL;
cleanup:
  fcm_krylov_destroy(&ws);
  return st;
}

void fcm_krylov_destroy(fcm_krylov **ws)
{
  if (!ws || !*ws) return;
  fcm_ctx *ctx = (*ws)->ctx;
  fcm__free(ctx, (*ws)->vecs);
  fcm__free(ctx, (*ws)->partial);
  fcm__free(ctx, (*ws)->history);
  fcm__free(ctx, *ws);
  *ws = NULL;
}

/* ---- vector kernels: parallel over entries, dot products in a fixed order ---- */

/* The threads of a region: the context's count (the results do not depend on it). */
#define THREADS(ws) fcm_ctx_num_threads((ws)->ctx)

static double dot(const fcm_krylov *ws, const double *x, const double *y)
{
  const fcm_index n = ws->n, nc = ws->num_chunks;
  double *part = ws->partial;
  if (nc == 1) {
    double s = 0.0;
    for (fcm_index i = 0; i < n; i++)
      s += x[i] * y[i];
    return s;
  }
#pragma omp parallel for num_threads(THREADS(ws)) schedule(static) if (n >= VEC_PARALLEL)
  for (fcm_index c = 0; c < nc; c++) {
    fcm_index i0 = c * DOT_CHUNK, i1 = FCM_MIN(i0 + DOT_CHUNK, n);
    double s = 0.0;
    for (fcm_index i = i0; i < i1; i++)
      s += x[i] * y[i];
    part[c] = s;
  }
  double s = 0.0;
  for (fcm_index c = 0; c < nc; c++)
    s += part[c];
  return s;
}

/* ---- team kernels: called by every thread of a parallel region (or by one thread outside
 * any), with orphaned worksharing, so that one region holds several vector operations.
 * A team dot product sums the same fixed chunks as dot() into ws->partial, then (after the
 * loop's barrier) every thread adds the chunk sums in order itself: the value is the same
 * in all threads and bitwise equal to dot(). At most one team dot per region (the region's
 * closing barrier keeps the next region's chunk writes from racing with the reads). ---- */

/* Chunk c of the n entries. */
#define CHUNK_RANGE(c, n, i0, i1)                                                                  \
  const fcm_index i0 = (c)*DOT_CHUNK, i1 = FCM_MIN(i0 + DOT_CHUNK, (n))

static double team_sum(const fcm_krylov *ws)
{
  double s = 0.0;
  for (fcm_index c = 0; c < ws->num_chunks; c++)
    s += ws->partial[c];
  return s;
}

/* In a team: if c1 != 0, y += c1 r; then return v^T y. */
static double team_axpy_dot(const fcm_krylov *ws, double c1, const double *r, const double *v,
                            double *y)
{
  const fcm_index n = ws->n;
#pragma omp for schedule(static)
  for (fcm_index c = 0; c < ws->num_chunks; c++) {
    CHUNK_RANGE(c, n, i0, i1);
    double s = 0.0;
    if (c1 != 0.0)
      for (fcm_index i = i0; i < i1; i++)
        y[i] += c1 * r[i];
    for (fcm_index i = i0; i < i1; i++)
      s += v[i] * y[i];
    ws->partial[c] = s;
  }
  return team_sum(ws);
}

/* In a team: if copy_y, y = r; then return r^T y. */
static double team_copy_dot(const fcm_krylov *ws, int copy_y, const double *r, double *y)
{
  const fcm_index n = ws->n;
#pragma omp for schedule(static)
  for (fcm_index c = 0; c < ws->num_chunks; c++) {
    CHUNK_RANGE(c, n, i0, i1);
    double s = 0.0;
    if (copy_y)
      for (fcm_index i = i0; i < i1; i++)
        y[i] = r[i];
    for (fcm_index i = i0; i < i1; i++)
      s += r[i] * y[i];
    ws->partial[c] = s;
  }
  return team_sum(ws);
}

/* y = x */
static void copy(fcm_index n, const double *x, double *y)
{
  if (n > 0 && x != y) memcpy(y, x, (size_t)n * sizeof *x);
}

/* r = b - r */
static void rsub(const fcm_krylov *ws, const double *b, double *r)
{
  const fcm_index n = ws->n;
#pragma omp parallel for num_threads(THREADS(ws)) schedule(static) if (n >= VEC_PARALLEL)
  for (fcm_index i = 0; i < n; i++)
    r[i] = b[i] - r[i];
}

static int all_zero(fcm_index n, const double *x)
{
  for (fcm_index i = 0; i < n; i++)
    if (x[i] != 0.0) return 0;
  return 1;
}

/* ---- shared driver ---- */

typedef enum method { METHOD_CG, METHOD_MINRES } method;

static const char *method_name(method m)
{
  return m == METHOD_CG ? "cg" : "minres";
}

/* State shared by both methods during one solve. */
typedef struct solve {
  fcm_krylov *ws;
  fcm_ctx *ctx;
  method m;
  fcm_operator_fn A, S;
  void *A_user, *S_user;
  const double *b;
  double *x;
  fcm_krylov_options o;
  double *hist;
  int hist_cap;
  double tol;             /* max(rtol ||b||, atol) */
  double best, best_mark; /* smallest monitored residual so far, and at the last checkpoint */
  fcm_krylov_info info;
} solve;

/* Apply a callback, counting it; on failure the reason records it and the status
 * (already recorded in ctx by the callback) is propagated with a traceback frame. */
#define CALL(sv, fn, user, in, out, counter)                                                       \
  do {                                                                                             \
    (counter)++;                                                                                   \
    st = (fn)((user), (in), (out));                                                                \
    if (st != FCM_OK) {                                                                            \
      (sv)->info.reason = FCM_KRYLOV_CALLBACK_ERROR;                                               \
      fcm__trace((sv)->ctx, __FILE__, __LINE__, __func__);                                         \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)
#define APPLY_A(sv, in, out)                                                                       \
  CALL(sv, (sv)->A, (sv)->A_user, in, out, (sv)->info.operator_applications)
#define APPLY_S(sv, in, out)                                                                       \
  CALL(sv, (sv)->S, (sv)->S_user, in, out, (sv)->info.preconditioner_applications)

/* Record the residual of iteration `it` (1-based) and test convergence. */
static int converged(solve *sv, int it, double rnorm)
{
  sv->info.residual_norm = rnorm;
  sv->info.relative_residual = rnorm / sv->info.rhs_norm;
  if (it > 0 && it <= sv->hist_cap) {
    sv->hist[it - 1] = sv->info.relative_residual;
    sv->info.history_length = it;
  }
  if (!(rnorm <= sv->tol)) return 0;
  sv->info.reason = rnorm <= sv->o.rtol * sv->info.rhs_norm ? FCM_KRYLOV_CONVERGED_RTOL
                                                            : FCM_KRYLOV_CONVERGED_ATOL;
  return 1;
}

/* The stagnation rule (fcm_krylov_options.stagnation_window = W > 0): at every W-th
 * iteration the smallest monitored residual so far must have dropped by STAGNATION_DECREASE
 * since the previous checkpoint (iteration 0 the first); otherwise the solve stops as
 * stagnated. Steady convergence too slow for that (a factor below 1 - 2e-5 per iteration
 * for W = 50) could not meet a tolerance in any practical number of iterations; what the
 * rule catches is a plateau: a singular system whose right-hand side leaves its range (the
 * residual cannot go below the part outside), where CG's iterate then grows without bound
 * and MINRES's stalls. */
#define STAGNATION_DECREASE 1e-3

static int stagnated(solve *sv, int it, double rnorm)
{
  if (it == 0 || rnorm < sv->best) sv->best = rnorm;
  if (it == 0) sv->best_mark = rnorm;
  const int W = sv->o.stagnation_window;
  if (W <= 0 || it == 0 || it % W != 0) return 0;
  if (sv->best <= (1.0 - STAGNATION_DECREASE) * sv->best_mark) {
    sv->best_mark = sv->best;
    return 0;
  }
  sv->info.reason = FCM_KRYLOV_STAGNATED;
  return 1;
}

static fcm_status check_options(fcm_ctx *ctx, const char *name, const fcm_krylov_options *o)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(o->rtol >= 0.0 && isfinite(o->rtol), ctx, FCM_ERR_ARG,
            "%s: rtol = %g must be finite and >= 0", name, o->rtol);
  FCM_CHECK(o->atol >= 0.0 && isfinite(o->atol), ctx, FCM_ERR_ARG,
            "%s: atol = %g must be finite and >= 0", name, o->atol);
  FCM_CHECK(o->max_iterations >= 0, ctx, FCM_ERR_ARG, "%s: max_iterations = %d must be >= 0", name,
            o->max_iterations);
  FCM_CHECK(o->stagnation_window >= 0, ctx, FCM_ERR_ARG,
            "%s: stagnation_window = %d must be >= 0 (0: off)", name, o->stagnation_window);
  FCM_CHECK(o->norm >= FCM_KRYLOV_NORM_DEFAULT && o->norm <= FCM_KRYLOV_NORM_PRECONDITIONED, ctx,
            FCM_ERR_ARG, "%s: norm = %d out of range [%d, %d]", name, (int)o->norm,
            (int)FCM_KRYLOV_NORM_DEFAULT, (int)FCM_KRYLOV_NORM_PRECONDITIONED);
  FCM_CHECK(!o->record_history || !o->history || o->history_capacity > 0, ctx, FCM_ERR_ARG,
            "%s: history buffer given with history_capacity = %d (must be > 0)", name,
            o->history_capacity);
cleanup:
  return st;
}

/* ---- conjugate gradients ---- */

static fcm_status run_cg(solve *sv)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = sv->ctx;
  fcm_krylov *ws = sv->ws;
  const fcm_index n = ws->n;
  const double *b = sv->b;
  double *x = sv->x;
  double *r = ws->vecs, *z = ws->vecs + n, *p = ws->vecs + 2 * n, *q = ws->vecs + 3 * n;
  const int prec_norm = sv->o.norm == FCM_KRYLOV_NORM_PRECONDITIONED && sv->S;
  const int maxit = sv->o.max_iterations;
  const int x0_zero = all_zero(n, x);
  double rho = 0.0, rr, rnorm;
  int k = 0;
  if (!sv->S) z = r; /* identity: z aliases r */

  if (x0_zero) {
    copy(n, b, r);
  } else {
    APPLY_A(sv, x, r);
    rsub(ws, b, r);
  }
  rr = dot(ws, r, r);
  if (!isfinite(rr)) goto nan;
  if (prec_norm && !x0_zero) {
    /* ||b||_S (with x0 = 0 it is ||r0||_S, computed below) */
    APPLY_S(sv, b, z);
    double bsb = dot(ws, b, z);
    if (!isfinite(bsb)) goto nan;
    if (!(bsb > 0.0)) {
      rho = bsb;
      goto indefinite;
    }
    sv->info.rhs_norm = sqrt(bsb);
  }
  for (;;) {
    /* r is the residual of iteration k */
    if (!prec_norm) {
      rnorm = sqrt(rr);
      if (k == 0) {
        sv->info.initial_residual = rnorm / sv->info.rhs_norm;
        sv->tol = FCM_MAX(sv->o.rtol * sv->info.rhs_norm, sv->o.atol);
      }
      if (converged(sv, k, rnorm) || stagnated(sv, k, rnorm)) goto finish;
      if (k == maxit) goto maxed;
    }
    if (sv->S) APPLY_S(sv, r, z);
    double rho_new = sv->S ? dot(ws, r, z) : rr;
    if (!isfinite(rho_new)) goto nan;
    if (!(rho_new > 0.0) && (rho_new < 0.0 || (prec_norm ? dot(ws, r, r) : rr) > 0.0)) {
      rho = rho_new; /* r^T S r < 0, or = 0 for r != 0 */
      goto indefinite;
    }
    if (prec_norm) {
      rnorm = sqrt(rho_new);
      if (k == 0) {
        if (sv->info.rhs_norm < 0.0) sv->info.rhs_norm = rnorm; /* x0 = 0: ||b||_S = ||r0||_S */
        sv->info.initial_residual = rnorm / sv->info.rhs_norm;
        sv->tol = FCM_MAX(sv->o.rtol * sv->info.rhs_norm, sv->o.atol);
      }
      if (converged(sv, k, rnorm) || stagnated(sv, k, rnorm)) goto finish;
      if (k == maxit) goto maxed;
    }
    if (k == 0) {
      copy(n, z, p);
    } else {
      double beta = rho_new / rho;
#pragma omp parallel for num_threads(THREADS(ws)) schedule(static) if (n >= VEC_PARALLEL)
      for (fcm_index i = 0; i < n; i++)
        p[i] = z[i] + beta * p[i];
    }
    rho = rho_new;
    APPLY_A(sv, p, q);
    double pq = dot(ws, p, q);
    if (!isfinite(pq)) goto nan;
    if (!(pq > 0.0)) {
      sv->info.reason = FCM_KRYLOV_BREAKDOWN;
      FCM_CHECK(0, ctx, FCM_ERR_NOT_CONVERGED,
                "cg: breakdown in iteration %d: p^T A p = %.3e <= 0 (operator not positive "
                "definite, or singular with b outside its range; use minres for indefinite "
                "systems)",
                k + 1, pq);
    }
    double alpha = rho / pq;
#pragma omp parallel for num_threads(THREADS(ws)) schedule(static) if (n >= VEC_PARALLEL)
    for (fcm_index i = 0; i < n; i++) {
      x[i] += alpha * p[i];
      r[i] -= alpha * q[i];
    }
    k++;
    sv->info.iterations = k;
    if (!prec_norm) { /* the preconditioned norm needs no ||r||_2 */
      rr = dot(ws, r, r);
      if (!isfinite(rr)) goto nan;
    }
  }

indefinite:
  sv->info.reason = FCM_KRYLOV_INDEFINITE_PRECONDITIONER;
  FCM_CHECK(0, ctx, FCM_ERR_NOT_CONVERGED,
            "cg: preconditioner is not positive definite (r^T S r = %.3e at iteration %d)", rho, k);
maxed:
  sv->info.reason = FCM_KRYLOV_MAX_ITERATIONS;
  goto finish;
nan:
  sv->info.reason = FCM_KRYLOV_NAN;
  FCM_CHECK(0, ctx, FCM_ERR_NUMERIC,
            "cg: NaN or Inf at iteration %d (in x0, the operator or "
            "the preconditioner)",
            k);
finish:
cleanup:
  return st;
}

/* ---- MINRES (Paige and Saunders) ---- */

/* The scalars of one MINRES iteration before and after the new Lanczos beta. */
typedef struct mr_in {
  double beta, dbar, epsln, cs, sn, phibar, alfa;
} mr_in;
typedef struct mr_out {
  double betasq, beta, dbar, epsln, cs, sn, phibar; /* the new state */
  double oldeps, delta, gamma, ig, phi, ib;         /* for the vector update */
  int ok;                                           /* betasq > 0 and gamma > 0 */
} mr_out;

/* Apply the previous rotation, then the new one that annihilates beta = sqrt(betasq).
 * A pure function, so that every thread of a team computes the same values. */
static mr_out mr_rotate(const mr_in *in, double betasq)
{
  mr_out o;
  o.betasq = betasq;
  o.beta = betasq >= 0.0 ? sqrt(betasq) : 0.0;
  o.oldeps = in->epsln;
  o.delta = in->cs * in->dbar + in->sn * in->alfa;
  const double gbar = in->sn * in->dbar - in->cs * in->alfa;
  o.epsln = in->sn * o.beta;
  o.dbar = -in->cs * o.beta;
  o.gamma = hypot(gbar, o.beta);
  o.cs = gbar / o.gamma;
  o.sn = o.beta / o.gamma;
  o.phi = o.cs * in->phibar;
  o.phibar = o.sn * in->phibar;
  o.ig = 1.0 / o.gamma;
  o.ib = 1.0 / o.beta;
  o.ok = isfinite(betasq) && betasq > 0.0 && o.gamma > 0.0;
  return o;
}

/* How the start of MINRES ended. */
typedef enum mr_start { MR_ITERATE, MR_DONE, MR_NAN, MR_INDEFINITE } mr_start;

/* The start of MINRES: r1 = b - A x (x0_zero: b), y = S r1, *betasq = r1^T S r1 and *beta1
 * its root, the norm of b (||b||_S with a preconditioner), the tolerance and the initial
 * residual; *how: MR_ITERATE, MR_DONE (converged or stagnated at the start), MR_NAN or
 * MR_INDEFINITE (r^T S r <= 0 with r != 0; *betasq the offending value). w is scratch. */
static fcm_status minres_start(solve *sv, double *r1, double *y, double *w, int x0_zero,
                               double *betasq, double *beta1, mr_start *how)
{
  fcm_status st = FCM_OK;
  fcm_krylov *ws = sv->ws;
  const fcm_index n = ws->n;
  const double *b = sv->b;
  if (x0_zero) {
    copy(n, b, r1);
  } else {
    APPLY_A(sv, sv->x, r1);
    rsub(ws, b, r1);
  }
  const double rr = dot(ws, r1, r1);
  *how = MR_NAN;
  if (!isfinite(rr)) goto cleanup;
  if (sv->S) {
    APPLY_S(sv, r1, y);
    *betasq = dot(ws, r1, y);
  } else {
    copy(n, r1, y);
    *betasq = rr;
  }
  if (!isfinite(*betasq)) goto cleanup;
  *how = MR_INDEFINITE;
  if (*betasq < 0.0 || (*betasq == 0.0 && rr > 0.0)) goto cleanup;
  if (sv->S) {
    if (x0_zero) {
      sv->info.rhs_norm = sqrt(*betasq);
    } else {
      APPLY_S(sv, b, w); /* ||b||_S; w is free until the iteration starts */
      double bsb = dot(ws, b, w);
      *how = MR_NAN;
      if (!isfinite(bsb)) goto cleanup;
      *how = MR_INDEFINITE;
      if (!(bsb > 0.0)) {
        *betasq = bsb;
        goto cleanup;
      }
      sv->info.rhs_norm = sqrt(bsb);
    }
  }
  sv->tol = FCM_MAX(sv->o.rtol * sv->info.rhs_norm, sv->o.atol);
  *beta1 = sqrt(*betasq);
  sv->info.initial_residual = *beta1 / sv->info.rhs_norm;
  *how = converged(sv, 0, *beta1) || stagnated(sv, 0, *beta1) ? MR_DONE : MR_ITERATE;
cleanup:
  return st;
}

/* The Lanczos step of MINRES iteration k: y = A v - (beta/oldb) r1 - (alfa/beta) r2 with
 * alfa = v^T (A v - (beta/oldb) r1), one parallel region after the operator. */
static fcm_status lanczos_step(solve *sv, int k, double beta, double oldb, const double *r1,
                               const double *r2, const double *v, double *y, double *alfa)
{
  fcm_status st = FCM_OK;
  fcm_krylov *ws = sv->ws;
  const fcm_index n = ws->n;
  const int par = n >= VEC_PARALLEL;
  double alfa_out = 0.0;
  APPLY_A(sv, v, y);
  const double c1 = k >= 2 ? -beta / oldb : 0.0;
#pragma omp parallel num_threads(THREADS(ws)) if (par)
  {
    const double a = team_axpy_dot(ws, c1, r1, v, y);
    const double c2 = -a / beta;
#pragma omp for schedule(static)
    for (fcm_index i = 0; i < n; i++)
      y[i] += c2 * r2[i];
#pragma omp master
    alfa_out = a;
  }
  *alfa = alfa_out;
cleanup:
  return st;
}

static fcm_status run_minres(solve *sv)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = sv->ctx;
  fcm_krylov *ws = sv->ws;
  const fcm_index n = ws->n;
  double *x = sv->x;
  double *r1 = ws->vecs, *r2 = ws->vecs + n, *y = ws->vecs + 2 * n, *v = ws->vecs + 3 * n;
  double *w = ws->vecs + 4 * n, *w1 = ws->vecs + 5 * n, *w2 = ws->vecs + 6 * n, *tmp;
  const int maxit = sv->o.max_iterations;
  const int x0_zero = all_zero(n, x);
  double betasq = 0.0, beta1 = 0.0;
  double oldb = 0.0, beta, dbar = 0.0, epsln = 0.0, phibar, cs = -1.0, sn = 0.0;
  int k = 0;
  const int par = n >= VEC_PARALLEL;

  mr_start how = MR_ITERATE;
  FCM_TRY(ctx, minres_start(sv, r1, y, w, x0_zero, &betasq, &beta1, &how));
  if (how == MR_NAN) goto nan;
  if (how == MR_INDEFINITE) goto indefinite;
  if (how == MR_DONE) goto finish;
  if (maxit == 0) goto maxed;

  beta = phibar = beta1;
  /* w = w2 = 0, r2 = r1, v = y / beta */
  {
    const double ib = 1.0 / beta;
#pragma omp parallel for num_threads(THREADS(ws)) schedule(static) if (par)
    for (fcm_index i = 0; i < n; i++) {
      w[i] = w2[i] = 0.0;
      r2[i] = r1[i];
      v[i] = ib * y[i];
    }
  }
  /* Each iteration: the operator, one parallel region (Lanczos orthogonalization), the
   * preconditioner, one parallel region (its dot product, the rotations — computed by
   * every thread alike —, the update of w and x and the next v). */
  for (k = 1; k <= maxit; k++) {
    double alfa = 0.0;
    FCM_TRY(ctx, lanczos_step(sv, k, beta, oldb, r1, r2, v, y, &alfa));
    if (!isfinite(alfa)) goto nan;
    tmp = r1;
    r1 = r2;
    r2 = y;
    y = tmp;
    if (sv->S) APPLY_S(sv, r2, y);
    /* w = (v - oldeps w1 - delta w2) / gamma, x += phi w, next v = y / beta (rotated
     * pointers: w takes the oldest direction's storage) */
    tmp = w1;
    w1 = w2;
    w2 = w;
    w = tmp;
    const mr_in in = {beta, dbar, epsln, cs, sn, phibar, alfa};
    mr_out out;
    int updated = 0;
#pragma omp parallel num_threads(THREADS(ws)) if (par)
    {
      const double bsq = team_copy_dot(ws, !sv->S, r2, y);
      const mr_out o = mr_rotate(&in, bsq);
      if (o.ok) {
#pragma omp for schedule(static)
        for (fcm_index i = 0; i < n; i++) {
          w[i] = (v[i] - o.oldeps * w1[i] - o.delta * w2[i]) * o.ig;
          x[i] += o.phi * w[i];
          v[i] = o.ib * y[i];
        }
      }
#pragma omp master
      {
        out = o;
        updated = o.ok;
      }
    }
    betasq = out.betasq;
    if (!isfinite(betasq)) goto nan;
    /* r2^T S r2 < 0, or = 0 for r2 != 0 (r2 = 0: the Krylov space is exhausted) */
    if (!(betasq > 0.0) && (betasq < 0.0 || dot(ws, r2, r2) > 0.0)) goto indefinite;
    if (!(out.gamma > 0.0)) {
      sv->info.reason = FCM_KRYLOV_BREAKDOWN;
      FCM_CHECK(0, ctx, FCM_ERR_NOT_CONVERGED,
                "minres: breakdown in iteration %d: the Lanczos tridiagonal is singular "
                "(b not in the range of A?)",
                k);
    }
    if (!updated) /* betasq = 0 with r2 = 0: the last update (phibar becomes 0) */
      for (fcm_index i = 0; i < n; i++) {
        w[i] = (v[i] - out.oldeps * w1[i] - out.delta * w2[i]) * out.ig;
        x[i] += out.phi * w[i];
      }
    oldb = beta;
    beta = out.beta;
    dbar = out.dbar;
    epsln = out.epsln;
    cs = out.cs;
    sn = out.sn;
    phibar = out.phibar;
    sv->info.iterations = k;
    if (!isfinite(phibar)) goto nan;
    if (converged(sv, k, phibar) || stagnated(sv, k, phibar)) goto finish;
  }
maxed:
  sv->info.reason = FCM_KRYLOV_MAX_ITERATIONS;
  goto finish;
indefinite:
  sv->info.reason = FCM_KRYLOV_INDEFINITE_PRECONDITIONER;
  FCM_CHECK(0, ctx, FCM_ERR_NOT_CONVERGED,
            "minres: preconditioner is not positive definite (r^T S r = %.3e at iteration %d)",
            betasq, k);
nan:
  sv->info.reason = FCM_KRYLOV_NAN;
  FCM_CHECK(0, ctx, FCM_ERR_NUMERIC,
            "minres: NaN or Inf at iteration %d (in x0, the operator "
            "or the preconditioner)",
            k);
finish:
cleanup:
  return st;
}

/* Argument checks, history, the method, the true-residual check, the final status. */
static fcm_status krylov_solve(fcm_krylov *ws, method m, fcm_operator_fn A, void *A_user,
                               fcm_operator_fn S, void *S_user, const double *b, double *x,
                               const fcm_krylov_options *opts, fcm_krylov_info *info)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws ? ws->ctx : NULL;
  const char *name = method_name(m);
  solve sv;
  memset(&sv, 0, sizeof sv);
  sv.info.true_residual = -1.0;
  double t0 = fcm_wtime();
  FCM_CHECK(ws, ctx, FCM_ERR_ARG, "%s: workspace is NULL", name);
  const fcm_index n = ws->n;
  FCM_CHECK(A, ctx, FCM_ERR_ARG, "%s: operator callback is NULL", name);
  FCM_CHECK((b && x) || n == 0, ctx, FCM_ERR_ARG, "%s: b or x is NULL (n = %lld)", name,
            (long long)n);
  FCM_CHECK(!b || b != x, ctx, FCM_ERR_ARG, "%s: b and x must be different arrays", name);
  sv.o = opts ? *opts : fcm_krylov_options_default();
  FCM_TRY(ctx, check_options(ctx, name, &sv.o));
  FCM_CHECK(m != METHOD_MINRES || !S || sv.o.norm != FCM_KRYLOV_NORM_UNPRECONDITIONED, ctx,
            FCM_ERR_ARG,
            "minres: with a preconditioner only the preconditioned residual norm is monitored "
            "(norm = FCM_KRYLOV_NORM_UNPRECONDITIONED given; use check_true_residual)");
  sv.ws = ws;
  sv.ctx = ctx;
  sv.m = m;
  sv.A = A;
  sv.A_user = A_user;
  sv.S = S;
  sv.S_user = S_user;
  sv.b = b;
  sv.x = x;
  if (sv.o.record_history) {
    if (sv.o.history) {
      sv.hist = sv.o.history;
      sv.hist_cap = sv.o.history_capacity;
    } else {
      if (ws->history_capacity < sv.o.max_iterations) {
        FCM_TRY(ctx, fcm__resize(ctx, (void **)&ws->history, (size_t)ws->history_capacity,
                                 (size_t)sv.o.max_iterations, sizeof *ws->history));
        ws->history_capacity = sv.o.max_iterations;
      }
      sv.hist = ws->history;
      sv.hist_cap = sv.o.max_iterations;
    }
    sv.info.history = sv.hist;
  }

  double bb = n > 0 ? dot(ws, b, b) : 0.0;
  if (!isfinite(bb)) {
    sv.info.reason = FCM_KRYLOV_NAN;
    FCM_CHECK(0, ctx, FCM_ERR_NUMERIC, "%s: the right-hand side b contains NaN or Inf", name);
  }
  if (bb == 0.0) {
    /* b = 0: x = 0 is the exact solution */
    if (n > 0) memset(x, 0, (size_t)n * sizeof *x);
    sv.info.reason = FCM_KRYLOV_CONVERGED_ATOL;
    if (sv.o.check_true_residual) sv.info.true_residual = 0.0;
    goto cleanup;
  }
  /* ||b||: the 2-norm, or (preconditioned norm) filled in by the method */
  const int prec = S && (m == METHOD_MINRES || sv.o.norm == FCM_KRYLOV_NORM_PRECONDITIONED);
  sv.info.rhs_norm = prec ? -1.0 : sqrt(bb);
  FCM_TRY(ctx, m == METHOD_CG ? run_cg(&sv) : run_minres(&sv));
  if (sv.o.check_true_residual) {
    double *t = ws->vecs; /* the methods are done with their vectors */
    APPLY_A(&sv, x, t);
    rsub(ws, b, t);
    sv.info.true_residual = sqrt(dot(ws, t, t) / bb);
  }
  if (sv.info.reason == FCM_KRYLOV_MAX_ITERATIONS)
    FCM_CHECK(0, ctx, FCM_ERR_NOT_CONVERGED,
              "%s: not converged in max_iterations = %d: relative residual %.3e > rtol = %.3e "
              "(atol = %.3e)",
              name, sv.o.max_iterations, sv.info.relative_residual, sv.o.rtol, sv.o.atol);
  if (sv.info.reason == FCM_KRYLOV_STAGNATED)
    FCM_CHECK(0, ctx, FCM_ERR_NOT_CONVERGED,
              "%s: stagnated: the smallest residual dropped by less than %g %% in the last %d "
              "iterations (smallest relative residual %.3e, %.3e after %d iterations, rtol = "
              "%.3e): the operator is singular, or nearly so, and b is not in its range",
              name, 100.0 * STAGNATION_DECREASE, sv.o.stagnation_window, sv.best / sv.info.rhs_norm,
              sv.info.relative_residual, sv.info.iterations, sv.o.rtol);
cleanup:
  if (sv.info.rhs_norm < 0.0) sv.info.rhs_norm = 0.0;
  sv.info.time = fcm_wtime() - t0;
  if (info) *info = sv.info;
  return st;
}

fcm_status fcm_krylov_cg(fcm_krylov *ws, fcm_operator_fn A, void *A_user, fcm_operator_fn S,
                         void *S_user, const double *b, double *x, const fcm_krylov_options *opts,
                         fcm_krylov_info *info)
{
  return krylov_solve(ws, METHOD_CG, A, A_user, S, S_user, b, x, opts, info);
}

fcm_status fcm_krylov_minres(fcm_krylov *ws, fcm_operator_fn A, void *A_user, fcm_operator_fn S,
                             void *S_user, const double *b, double *x,
                             const fcm_krylov_options *opts, fcm_krylov_info *info)
{
  return krylov_solve(ws, METHOD_MINRES, A, A_user, S, S_user, b, x, opts, info);
}

static fcm_status one_shot(fcm_ctx *ctx, method m, fcm_index n, fcm_operator_fn A, void *A_user,
                           fcm_operator_fn S, void *S_user, const double *b, double *x,
                           const fcm_krylov_options *opts, fcm_krylov_info *info)
{
  fcm_status st = FCM_OK;
  fcm_krylov *ws = NULL;
  FCM_CHECK(!opts || !opts->record_history || opts->history, ctx, FCM_ERR_ARG,
            "%s_solve: record_history needs a caller buffer (opts.history) here; use "
            "fcm_krylov_create for a workspace-owned history",
            method_name(m));
  FCM_TRY(ctx, fcm_krylov_create(ctx, n, &ws));
  FCM_TRY(ctx, krylov_solve(ws, m, A, A_user, S, S_user, b, x, opts, info));
cleanup:
  fcm_krylov_destroy(&ws);
  return st;
}

fcm_status fcm_cg_solve(fcm_ctx *ctx, fcm_index n, fcm_operator_fn A, void *A_user,
                        fcm_operator_fn S, void *S_user, const double *b, double *x,
                        const fcm_krylov_options *opts, fcm_krylov_info *info)
{
  return one_shot(ctx, METHOD_CG, n, A, A_user, S, S_user, b, x, opts, info);
}

fcm_status fcm_minres_solve(fcm_ctx *ctx, fcm_index n, fcm_operator_fn A, void *A_user,
                            fcm_operator_fn S, void *S_user, const double *b, double *x,
                            const fcm_krylov_options *opts, fcm_krylov_info *info)
{
  return one_shot(ctx, METHOD_MINRES, n, A, A_user, S, S_user, b, x, opts, info);
}
