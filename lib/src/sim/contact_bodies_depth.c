/* sim: contact between bodies — the measures of penetration (a sample inside another body, or
 * inside its own with self-contact) and the self-contact statistics. Inside is decided by the
 * parity of a ray's crossings with a body's triangles, the depth is then the distance to the
 * nearest of them. A sample of a body lies on that body's surface, where the parity is
 * undefined: the self measure takes the three interior samples of each triangle moved off it
 * along its outward normal by 1e-7 of the body's size, and the distance to the triangles not
 * excluded from the sample's self-contact (fcm__sim_bodies_excluded()). */
#include "sim/sim_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <string.h>

/* Whether the segment o -> o + r (r the ray, parameter in [0, 1]) crosses triangle (a, b, c)
 * (Moller-Trumbore; a segment in the triangle's plane does not). */
static int crosses(const double o[3], const double r[3], const double *a, const double *b,
                   const double *c)
{
  double e1[3], e2[3], pv[3], tv[3], qv[3];
  fcm__vec3_sub(b, a, e1);
  fcm__vec3_sub(c, a, e2);
  fcm__vec3_cross(r, e2, pv);
  const double det = fcm__vec3_dot(e1, pv);
  if (!(fabs(det) > 1e-14 * fcm__vec3_norm(e1) * fcm__vec3_norm(e2) * fcm__vec3_norm(r))) return 0;
  fcm__vec3_sub(o, a, tv);
  const double u = fcm__vec3_dot(tv, pv) / det;
  if (u < 0.0 || u > 1.0) return 0;
  fcm__vec3_cross(tv, e1, qv);
  const double v = fcm__vec3_dot(r, qv) / det;
  if (v < 0.0 || u + v > 1.0) return 0;
  const double s = fcm__vec3_dot(e2, qv) / det;
  return s >= 0.0 && s <= 1.0;
}

/* The depth of p inside body g (0 outside): the parity of a ray's crossings with g's
 * triangles, and inside, the distance to the nearest of them. */
static fcm_status depth_in(fcm_ctx *ctx, sim_bodies *B, fcm_index g, const double p[3], double len,
                           double *depth)
{
  fcm_status st = FCM_OK;
  static const double dir[3] = {0.5377304, 0.3180952, 0.7808866};
  const sim_bvh_node *root = B->bvh.node + B->bvh.root[g];
  double r[3], lo[3], hi[3];
  int count = 0;
  *depth = 0.0;
  for (int i = 0; i < 3; i++)
    if (p[i] < root->lo[i] || p[i] > root->hi[i]) return FCM_OK;
  for (int i = 0; i < 3; i++) {
    r[i] = len * dir[i];
    lo[i] = FCM_MIN(p[i], p[i] + r[i]);
    hi[i] = FCM_MAX(p[i], p[i] + r[i]);
  }
  B->buf.n = 0;
  FCM_TRY(ctx, fcm__sim_bvh_query(ctx, &B->bvh, g, B->boxes, lo, hi, &B->buf));
  for (size_t k = 0; k < B->buf.n; k++) {
    const fcm_index *tv = B->tri + 3 * B->buf.ids[k];
    count += crosses(p, r, B->y + 3 * tv[0], B->y + 3 * tv[1], B->y + 3 * tv[2]);
  }
  if (count % 2 == 0) return FCM_OK;
  B->buf.n = 0;
  FCM_TRY(ctx, fcm__sim_bvh_query(ctx, &B->bvh, g, B->boxes, root->lo, root->hi, &B->buf));
  *depth = HUGE_VAL;
  for (size_t k = 0; k < B->buf.n; k++) {
    double gr[3], beta[3];
    *depth = FCM_MIN(*depth, fcm__sim_bodies_distance(B, p, B->buf.ids[k], B->y, gr, beta));
  }
cleanup:
  return st;
}

fcm_status fcm__sim_bodies_depth(const fcm_integrator *I, const sim_contact *c, const double *x,
                                 double *depth, double where[3])
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_bodies *B = c->bodies;
  double len = 0.0;
  *depth = 0.0;
  if (!B) return FCM_OK;
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  FCM_TRY(ctx, fcm__sim_bodies_boxes(ctx, B, B->y, NULL, 0, c->dhat));
  for (fcm_index g = 0; g < B->num_bodies; g++) {
    if (B->bvh.root[g] < 0) continue;
    const sim_bvh_node *nd = B->bvh.node + B->bvh.root[g];
    double l = 0.0;
    for (int i = 0; i < 3; i++)
      l += (nd->hi[i] - nd->lo[i]) * (nd->hi[i] - nd->lo[i]);
    len = FCM_MAX(len, 2.0 * sqrt(l) + 1e-12);
  }
  for (fcm_index n = 0; n < B->ns; n++) {
    double p[3];
    const fcm_index own = B->tbody[B->stri[n]];
    fcm__sim_bodies_sample(B, n, B->y, p);
    for (fcm_index g = 0; g < B->num_bodies; g++) {
      double dg = 0.0;
      if (g == own || B->bvh.root[g] < 0) continue;
      FCM_TRY(ctx, depth_in(ctx, B, g, p, len, &dg));
      if (dg > *depth) {
        *depth = dg;
        if (where) memcpy(where, p, sizeof p);
      }
    }
  }
cleanup:
  return st;
}

/* Whether sample n is one of its triangle's interior samples (no barycentric coordinate 1). */
static int interior(const sim_bodies *B, fcm_index n)
{
  const double *l = B->slam + 3 * n;
  return l[0] < 1.0 && l[1] < 1.0 && l[2] < 1.0;
}

/* The depth of sample n (at p) inside its own body g: the parity of a ray's crossings from p
 * moved off its triangle by eps, then the distance to the nearest triangle not excluded. */
static fcm_status self_depth(fcm_ctx *ctx, sim_bodies *B, fcm_index n, const double p[3],
                             double len, double eps, double *depth)
{
  fcm_status st = FCM_OK;
  static const double dir[3] = {0.5377304, 0.3180952, 0.7808866};
  const fcm_index g = B->tbody[B->stri[n]], *tv = B->tri + 3 * B->stri[n];
  const sim_bvh_node *root = B->bvh.node + B->bvh.root[g];
  double e1[3], e2[3], nv[3], o[3], r[3], lo[3], hi[3];
  int count = 0;
  *depth = 0.0;
  fcm__vec3_sub(B->y + 3 * tv[1], B->y + 3 * tv[0], e1);
  fcm__vec3_sub(B->y + 3 * tv[2], B->y + 3 * tv[0], e2);
  fcm__vec3_cross(e1, e2, nv);
  const double l = fcm__vec3_norm(nv);
  if (!(l > 0.0)) return FCM_OK;
  for (int i = 0; i < 3; i++) {
    o[i] = p[i] + eps * nv[i] / l;
    r[i] = len * dir[i];
    lo[i] = FCM_MIN(o[i], o[i] + r[i]);
    hi[i] = FCM_MAX(o[i], o[i] + r[i]);
  }
  B->buf.n = 0;
  FCM_TRY(ctx, fcm__sim_bvh_query(ctx, &B->bvh, g, B->boxes, lo, hi, &B->buf));
  for (size_t k = 0; k < B->buf.n; k++) {
    const fcm_index *q = B->tri + 3 * B->buf.ids[k];
    count += crosses(o, r, B->y + 3 * q[0], B->y + 3 * q[1], B->y + 3 * q[2]);
  }
  if (count % 2 == 0) return FCM_OK;
  B->buf.n = 0;
  FCM_TRY(ctx, fcm__sim_bvh_query(ctx, &B->bvh, g, B->boxes, root->lo, root->hi, &B->buf));
  *depth = HUGE_VAL;
  for (size_t k = 0; k < B->buf.n; k++) {
    double gr[3], beta[3];
    const fcm_index t = B->buf.ids[k];
    if (B->tbody[t] < 0 || fcm__sim_bodies_excluded(B, n, t)) continue;
    *depth = FCM_MIN(*depth, fcm__sim_bodies_distance(B, p, t, B->y, gr, beta));
  }
  if (*depth == HUGE_VAL) *depth = 0.0;
cleanup:
  return st;
}

fcm_status fcm__sim_bodies_self_stats(const fcm_integrator *I, const sim_contact *c,
                                      const double *x, long long *pairs, double *depth,
                                      double where[3])
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_bodies *B = c->bodies;
  const long long tests = B ? B->self_tests : 0;
  *pairs = 0;
  *depth = 0.0;
  if (!B) return FCM_OK;
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  FCM_TRY(ctx, fcm__sim_bodies_boxes(ctx, B, B->y, NULL, 0, c->dhat));
  for (fcm_index n = 0; n < B->ns; n++) {
    const fcm_index own = B->tbody[B->stri[n]];
    const sim_bvh_node *root = B->bvh.node + B->bvh.root[own];
    double p[3], lo[3], hi[3], size = 0.0, dn = 0.0;
    fcm__sim_bodies_sample(B, n, B->y, p);
    for (int i = 0; i < 3; i++) {
      lo[i] = p[i] - c->dhat;
      hi[i] = p[i] + c->dhat;
      size += (root->hi[i] - root->lo[i]) * (root->hi[i] - root->lo[i]);
    }
    size = sqrt(size);
    B->buf.n = 0;
    FCM_TRY(ctx, fcm__sim_bvh_query(ctx, &B->bvh, own, B->boxes, lo, hi, &B->buf));
    for (size_t k = 0; k < B->buf.n; k++) {
      double g[3], beta[3];
      const fcm_index t = B->buf.ids[k];
      if (B->tbody[t] < 0 || fcm__sim_bodies_excluded(B, n, t)) continue;
      if (fcm__sim_bodies_distance(B, p, t, B->y, g, beta) < c->dhat) (*pairs)++;
    }
    if (!interior(B, n)) continue;
    FCM_TRY(ctx, self_depth(ctx, B, n, p, 2.0 * size + 1e-12, 1e-7 * size, &dn));
    if (dn > *depth) {
      *depth = dn;
      if (where) memcpy(where, p, sizeof p);
    }
  }
cleanup:
  /* the measures do not count as the evaluations' tests */
  if (B) B->self_tests = tests;
  return st;
}

long long fcm__sim_bodies_self_tests(const sim_contact *c)
{
  return c->bodies ? c->bodies->self_tests : 0;
}

fcm_status fcm__sim_bodies_support(const fcm_integrator *I, const sim_contact *c, const double *x,
                                   void (*fn)(void *user, fcm_index elem_a, const double ya[3],
                                              fcm_index elem_b, const double yb[3],
                                              const double g[3]),
                                   void *user)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_bodies *B = c->bodies;
  const double first = fcm__sim_bodies_blind_start(I, c);
  if (!B) return FCM_OK;
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  FCM_TRY(ctx, fcm__sim_bodies_boxes(ctx, B, B->y, NULL, 0, c->dhat));
  for (fcm_index n = 0; n < B->ns; n++) {
    const fcm_index own = B->tbody[B->stri[n]], *sv = B->tri + 3 * B->stri[n];
    const double *l = B->slam + 3 * n;
    double p[3];
    /* not the bodies the sample ignores (the barrier does not hold them) */
    FCM_TRY(ctx, fcm__sim_bodies_near(ctx, B, n, c->dhat, 0, p));
    for (size_t k = 0; k < B->buf.n; k++) {
      const fcm_index t = B->buf.ids[k], *tv = B->tri + 3 * t;
      double g[3], beta[3], q[3];
      if (B->tbody[t] < 0 || B->tbody[t] == own) continue;
      const double d = fcm__sim_bodies_distance(B, p, t, B->y, g, beta);
      if (!(d < c->dhat) || !(d >= (B->prepared ? 0.0 : first)) || !(d > 0.0)) continue;
      for (int i = 0; i < 3; i++)
        q[i] = p[i] - d * g[i];
      /* an element of each side: the node of the largest weight */
      const int js = l[0] >= l[1] ? (l[0] >= l[2] ? 0 : 2) : (l[1] >= l[2] ? 1 : 2);
      const int jt =
          beta[0] >= beta[1] ? (beta[0] >= beta[2] ? 0 : 2) : (beta[1] >= beta[2] ? 1 : 2);
      fn(user, B->velem[sv[js]], p, B->velem[tv[jt]], q, g);
    }
  }
cleanup:
  return st;
}
