/* sim: lagged, smoothed Coulomb friction between bodies (and, with self-contact, within one) —
 * the potential of contact_friction.c on the slip of a sample relative to a triangle.
 *
 * At the start of each substep (state u_n) every pair (sample n, triangle t) within d^ that the
 * barrier acts on keeps its normal force lambda = w kappa |b'(d)|, the closest point's
 * barycentric coordinates beta and an orthonormal basis T of the plane normal to the
 * distance's gradient. Within the substep the slip is the sample's motion relative to the
 * triangle's point beta, delta = (p - p_n) - sum_k beta_k (z_k - z_k,n), linear in the DOFs
 * with the coefficients of the barrier's gradient (lam_j for the sample's nodes, -beta_k for
 * the triangle's), and the potential is mu lambda f0(|T^T delta|)
 * (fcm__sim_friction_potential()). The pairs that start inside a cut (the penalty's) take no
 * friction. */
#include "sim/sim_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <string.h>

void fcm__sim_bodies_slip(const sim_bodies *B, const sim_fpair *q, double delta[3])
{
  const fcm_index *sv = B->tri + 3 * B->stri[q->n], *tv = B->tri + 3 * q->t;
  const double *l = B->slam + 3 * q->n;
  for (int i = 0; i < 3; i++) {
    double d = 0.0;
    for (int k = 0; k < 3; k++)
      d += l[k] * (B->y[3 * sv[k] + i] - B->y0[3 * sv[k] + i]) -
           q->beta[k] * (B->y[3 * tv[k] + i] - B->y0[3 * tv[k] + i]);
    delta[i] = d;
  }
}

static fcm_status push(fcm_ctx *ctx, sim_bodies *B, const sim_fpair *q)
{
  fcm_status st = FCM_OK;
  if (B->nfp == B->cap_fp) {
    const size_t cap = B->cap_fp ? 2 * B->cap_fp : 64;
    void *grown = B->fp;
    FCM_TRY(ctx, fcm__resize(ctx, &grown, B->cap_fp, cap, sizeof *B->fp));
    B->fp = grown;
    B->cap_fp = cap;
  }
  B->fp[B->nfp++] = *q;
cleanup:
  return st;
}

fcm_status fcm__sim_bodies_friction_lag(fcm_integrator *I, sim_contact *c, const double *x,
                                        int start, double *change)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_bodies *B = c->bodies;
  double old = 0.0, sum = 0.0;
  if (change) *change = 0.0;
  if (!B || !(c->opts.friction > 0.0)) return FCM_OK;
  if (!B->y0) FCM_ALLOC(ctx, 3 * (size_t)B->nv + 1, B->y0);
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  if (start) memcpy(B->y0, B->y, sizeof(double) * 3 * (size_t)B->nv);
  FCM_TRY(ctx, fcm__sim_bodies_boxes(ctx, B, B->y, NULL, 0, c->dhat));
  for (size_t k = 0; k < B->nfp; k++)
    old += B->fp[k].lambda;
  B->nfp = 0;
  for (fcm_index n = 0; n < B->ns; n++) {
    double p[3];
    FCM_TRY(ctx, fcm__sim_bodies_near(ctx, B, n, c->dhat, 0, p));
    for (size_t k = 0; k < B->buf.n; k++) {
      sim_fpair q;
      double g[3];
      q.n = n;
      q.t = B->buf.ids[k];
      if (!fcm__sim_bodies_target(B, n, q.t)) continue;
      const double d = fcm__sim_bodies_distance(B, p, q.t, B->y, g, q.beta);
      if (!(d > 0.0 && d < c->dhat)) continue;
      const double r = d - c->dhat, b1 = -2.0 * r * log(d / c->dhat) - r * r / d;
      q.lambda = B->sw[n] * c->kappa * fabs(b1);
      fcm__sim_tangent_basis(g, q.T);
      sum += q.lambda;
      FCM_TRY(ctx, push(ctx, B, &q));
    }
  }
  if (change) *change = FCM_MAX(old, sum) > 0.0 ? fabs(sum - old) / FCM_MAX(old, sum) : 0.0;
cleanup:
  return st;
}

double fcm__sim_bodies_friction_work(const fcm_integrator *I, const sim_contact *c, const double *x)
{
  sim_bodies *B = c->bodies;
  const double eps = c->opts.friction_velocity * I->cp.hstep;
  double work = 0.0, delta[3];
  if (!B || !B->y0 || !(c->opts.friction > 0.0) || !(eps > 0.0)) return 0.0;
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  for (size_t k = 0; k < B->nfp; k++) {
    fcm__sim_bodies_slip(B, B->fp + k, delta);
    work += fcm__sim_friction_work(c->opts.friction * B->fp[k].lambda, eps, B->fp[k].T, delta);
  }
  return work;
}
