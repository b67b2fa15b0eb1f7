/* sim: the geometry of the contact obstacles — distance, its gradient and Hessian, the first
 * time a straight path meets an obstacle, and the inside test (and the public query
 * fcm_integrator_contact_distance()).
 *
 * Spheres, boxes and triangle surfaces are described in their own frame and placed at time t by
 * a rigid motion x = o + R X (fcm_motion_eval()); a world point y is seen at X = R^T (y - o),
 * distances are invariant, and the world gradient and Hessian are R g and R H R^T.
 *
 * Distances, outside the obstacle (the body's side):
 *   plane   d = n . (y - p(t)), affine: g = n, H = 0
 *   sphere  d = |X - c| - r: g = (X - c) / |X - c|, H = (I - g g^T) / |X - c|
 *   box     d = |X - q|, q the clamp of X to [lo, hi]: g = (X - q) / d, H = (P - g g^T) / d with
 *           P the projector on the axes where X lies outside the box's slab (a face: H = 0)
 *   surface d = min over the triangles of the point-triangle distance |X - q| (q the closest
 *           point): a face region gives g = the unit normal towards X, H = 0; an edge with unit
 *           direction e gives H = (I - e e^T - g g^T) / d; a vertex H = (I - g g^T) / d.
 * Inside a sphere or a box d is negative (minus the depth); a surface's distance is unsigned,
 * and the side comes from a ray's crossing count (the surface is closed). Each H is positive
 * semidefinite with H g = 0. */
#include "sim/sim_impl.h"
#include "la/vec3.h"

#include <float.h>
#include <math.h>
#include <string.h>

void fcm__sim_contact_pose(const sim_contact *c, double t, sim_pose *P)
{
  static const double zero[3] = {0, 0, 0};
  double u0[3], u[3];
  memset(P, 0, sizeof *P);
  if (c->kind == SIM_CONTACT_PLANE || !c->moving) {
    P->R[0] = P->R[4] = P->R[8] = 1.0;
    return;
  }
  fcm_motion_eval(&c->motion, zero, t, u0, NULL);
  memcpy(P->o, u0, sizeof u0);
  for (int j = 0; j < 3; j++) {
    double e[3] = {0, 0, 0};
    e[j] = 1.0;
    fcm_motion_eval(&c->motion, e, t, u, NULL);
    for (int i = 0; i < 3; i++)
      P->R[3 * i + j] = e[i] + u[i] - u0[i];
  }
}

/* World to obstacle frame: X = R^T (y - o); directions: dX = R^T dy. */
static void to_frame(const sim_pose *P, const double y[3], int direction, double X[3])
{
  double r[3];
  for (int i = 0; i < 3; i++)
    r[i] = y[i] - (direction ? 0.0 : P->o[i]);
  for (int j = 0; j < 3; j++)
    X[j] = P->R[j] * r[0] + P->R[3 + j] * r[1] + P->R[6 + j] * r[2];
}

/* Frame to world: g <- R g, H <- R H R^T. */
static void to_world(const sim_pose *P, double g[3], double *H)
{
  double t[3], A[9];
  for (int i = 0; i < 3; i++)
    t[i] = P->R[3 * i] * g[0] + P->R[3 * i + 1] * g[1] + P->R[3 * i + 2] * g[2];
  memcpy(g, t, sizeof t);
  if (!H) return;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double s = 0.0;
      for (int k = 0; k < 3; k++)
        s += P->R[3 * i + k] * H[3 * k + j];
      A[3 * i + j] = s;
    }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double s = 0.0;
      for (int k = 0; k < 3; k++)
        s += A[3 * i + k] * P->R[3 * j + k];
      H[3 * i + j] = s;
    }
}

/* H = (P - g g^T) / d for the projector P (the diagonal of P in p, or the dense P). */
static void curvature(const double *Pm, const double g[3], double d, double *H)
{
  if (!H) return;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      H[3 * i + j] = (Pm[3 * i + j] - g[i] * g[j]) / d;
}

int fcm__sim_point_triangle(const double p[3], const double a[3], const double b[3],
                            const double c[3], double q[3], double e[3])
{
  double ab[3], ac[3], ap[3], bp[3], cp[3], bc[3];
  fcm__vec3_sub(b, a, ab);
  fcm__vec3_sub(c, a, ac);
  fcm__vec3_sub(p, a, ap);
  const double d1 = fcm__vec3_dot(ab, ap), d2 = fcm__vec3_dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    memcpy(q, a, 3 * sizeof *q);
    return 4;
  }
  fcm__vec3_sub(p, b, bp);
  const double d3 = fcm__vec3_dot(ab, bp), d4 = fcm__vec3_dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) {
    memcpy(q, b, 3 * sizeof *q);
    return 5;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3), l = fcm__vec3_norm(ab);
    for (int i = 0; i < 3; i++) {
      q[i] = a[i] + v * ab[i];
      e[i] = ab[i] / l;
    }
    return 1;
  }
  fcm__vec3_sub(p, c, cp);
  const double d5 = fcm__vec3_dot(ab, cp), d6 = fcm__vec3_dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) {
    memcpy(q, c, 3 * sizeof *q);
    return 6;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6), l = fcm__vec3_norm(ac);
    for (int i = 0; i < 3; i++) {
      q[i] = a[i] + w * ac[i];
      e[i] = ac[i] / l;
    }
    return 3;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    fcm__vec3_sub(c, b, bc);
    const double l = fcm__vec3_norm(bc);
    for (int i = 0; i < 3; i++) {
      q[i] = b[i] + w * bc[i];
      e[i] = bc[i] / l;
    }
    return 2;
  }
  const double den = 1.0 / (va + vb + vc), v = vb * den, w = vc * den;
  for (int i = 0; i < 3; i++)
    q[i] = a[i] + v * ab[i] + w * ac[i];
  return 0;
}

void fcm__sim_point_triangle_distance(const double p[3], const double a[3], const double b[3],
                                      const double c[3], double *d, double g[3], double *H,
                                      int *region)
{
  double q[3], e[3] = {0, 0, 0}, Pm[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const int r = fcm__sim_point_triangle(p, a, b, c, q, e);
  fcm__vec3_sub(p, q, g);
  *d = fcm__vec3_norm(g);
  for (int i = 0; i < 3; i++)
    g[i] = *d > 0.0 ? g[i] / *d : 0.0;
  if (region) *region = r;
  if (!H) return;
  if (r == 0 || !(*d > 0.0)) { /* the face: d is affine along its normal */
    memset(H, 0, 9 * sizeof *H);
    return;
  }
  if (r <= 3)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        Pm[3 * i + j] -= e[i] * e[j];
  curvature(Pm, g, *d, H);
}

/* The closest triangle of a surface within `radius` of X (frame coordinates): *d = HUGE_VAL
 * when none. */
static fcm_status surface_distance(fcm_ctx *ctx, const sim_contact *c, const double X[3],
                                   double radius, fcm__idbuf *buf, double *d, double g[3],
                                   double *H)
{
  fcm_status st = FCM_OK;
  double lo[3], hi[3];
  *d = HUGE_VAL;
  for (int i = 0; i < 3; i++) {
    lo[i] = X[i] - radius;
    hi[i] = X[i] + radius;
  }
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, c->tree, lo, hi, buf));
  for (size_t k = 0; k < buf->n; k++) {
    const fcm_index *t = c->tri + 3 * buf->ids[k];
    double dk, gk[3], Hk[9];
    fcm__sim_point_triangle_distance(X, c->xyz + 3 * t[0], c->xyz + 3 * t[1], c->xyz + 3 * t[2],
                                     &dk, gk, H ? Hk : NULL, NULL);
    if (dk < *d && dk <= radius) {
      *d = dk;
      memcpy(g, gk, sizeof gk);
      if (H) memcpy(H, Hk, sizeof Hk);
    }
  }
cleanup:
  return st;
}

fcm_status fcm__sim_contact_distance(fcm_ctx *ctx, const sim_contact *c, const sim_pose *P,
                                     const double y[3], double t, double radius, fcm__idbuf *buf,
                                     double *d, double g[3], double *H)
{
  fcm_status st = FCM_OK;
  double X[3], v[3];
  static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (c->kind == SIM_CONTACT_PLANE) {
    *d = 0.0;
    for (int i = 0; i < 3; i++) {
      *d += c->normal[i] * (y[i] - c->point[i] - c->velocity[i] * t);
      g[i] = c->normal[i];
    }
    if (H) memset(H, 0, 9 * sizeof *H);
    return FCM_OK;
  }
  to_frame(P, y, 0, X);
  switch (c->kind) {
  case SIM_CONTACT_SPHERE: {
    fcm__vec3_sub(X, c->center, v);
    const double l = fcm__vec3_norm(v);
    *d = l - c->radius;
    for (int i = 0; i < 3; i++)
      g[i] = l > 0.0 ? v[i] / l : (i == 2);
    if (H) curvature(I3, g, l > 0.0 ? l : 1.0, H);
    break;
  }
  case SIM_CONTACT_BOX: {
    double Pm[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    int outside = 0;
    for (int i = 0; i < 3; i++) {
      const double q = FCM_MIN(FCM_MAX(X[i], c->lo[i]), c->hi[i]);
      v[i] = X[i] - q;
      if (v[i] != 0.0) Pm[4 * i] = 1.0, outside = 1;
    }
    if (outside) {
      *d = fcm__vec3_norm(v);
      for (int i = 0; i < 3; i++)
        g[i] = v[i] / *d;
      if (H) curvature(Pm, g, *d, H);
    } else { /* inside (or on): minus the depth below the nearest face */
      *d = HUGE_VAL;
      for (int i = 0; i < 3; i++)
        for (int s = 0; s < 2; s++) {
          const double depth = s ? c->hi[i] - X[i] : X[i] - c->lo[i];
          if (depth < *d) {
            *d = depth;
            g[0] = g[1] = g[2] = 0.0;
            g[i] = s ? 1.0 : -1.0;
          }
        }
      *d = -*d;
      if (H) memset(H, 0, 9 * sizeof *H);
    }
    break;
  }
  default:
    FCM_TRY(ctx, surface_distance(ctx, c, X, radius, buf, d, g, H));
    if (*d == HUGE_VAL) return FCM_OK;
    break;
  }
  to_world(P, g, H);
cleanup:
  return st;
}

/* The parameter s in [0, smax] where o + s r crosses the triangle (a, b, c), or HUGE_VAL
 * (Moller-Trumbore; a ray in the triangle's plane does not cross it). */
static double segment_triangle(const double o[3], const double r[3], double smax, const double a[3],
                               const double b[3], const double c[3])
{
  double e1[3], e2[3], pv[3], tv[3], qv[3];
  fcm__vec3_sub(b, a, e1);
  fcm__vec3_sub(c, a, e2);
  fcm__vec3_cross(r, e2, pv);
  const double det = fcm__vec3_dot(e1, pv);
  const double scale = fcm__vec3_norm(e1) * fcm__vec3_norm(e2) * fcm__vec3_norm(r);
  if (!(fabs(det) > 1e-14 * scale)) return HUGE_VAL;
  fcm__vec3_sub(o, a, tv);
  const double u = fcm__vec3_dot(tv, pv) / det;
  if (u < 0.0 || u > 1.0) return HUGE_VAL;
  fcm__vec3_cross(tv, e1, qv);
  const double v = fcm__vec3_dot(r, qv) / det;
  if (v < 0.0 || u + v > 1.0) return HUGE_VAL;
  const double s = fcm__vec3_dot(e2, qv) / det;
  return s >= 0.0 && s <= smax ? s : HUGE_VAL;
}

/* The triangles a segment X -> X + smax dX crosses: the smallest parameter (*first) and their
 * number (*count; pass count NULL to skip counting). */
static fcm_status surface_crossings(fcm_ctx *ctx, const sim_contact *c, const double X[3],
                                    const double dX[3], double smax, fcm__idbuf *buf, double *first,
                                    fcm_index *count)
{
  fcm_status st = FCM_OK;
  double p1[3];
  *first = HUGE_VAL;
  if (count) *count = 0;
  for (int i = 0; i < 3; i++)
    p1[i] = X[i] + smax * dX[i];
  FCM_TRY(ctx, fcm__geom_tree_segment(ctx, c->tree, X, p1, 0.0, buf));
  for (size_t k = 0; k < buf->n; k++) {
    const fcm_index *t = c->tri + 3 * buf->ids[k];
    const double s =
        segment_triangle(X, dX, smax, c->xyz + 3 * t[0], c->xyz + 3 * t[1], c->xyz + 3 * t[2]);
    if (s == HUGE_VAL) continue;
    *first = FCM_MIN(*first, s);
    if (count) (*count)++;
  }
cleanup:
  return st;
}

fcm_status fcm__sim_contact_inside(fcm_ctx *ctx, const sim_contact *c, const sim_pose *P,
                                   const double y[3], double t, fcm__idbuf *buf, int *inside)
{
  fcm_status st = FCM_OK;
  double X[3], first, d, g[3];
  fcm_index count = 0;
  /* a direction unlikely to graze an edge or a vertex of a modelled surface */
  static const double dir[3] = {0.5377304, 0.3180952, 0.7808866};
  if (c->kind != SIM_CONTACT_SURFACE) {
    FCM_TRY(ctx, fcm__sim_contact_distance(ctx, c, P, y, t, 0.0, buf, &d, g, NULL));
    *inside = !(d > 0.0);
    return FCM_OK;
  }
  to_frame(P, y, 0, X);
  double len = 0.0;
  for (int i = 0; i < 3; i++)
    len += (c->hi[i] - c->lo[i]) + fabs(X[i] - 0.5 * (c->lo[i] + c->hi[i]));
  *inside = 0;
  for (int i = 0; i < 3; i++)
    if (X[i] < c->lo[i] || X[i] > c->hi[i]) return FCM_OK;
  FCM_TRY(ctx, surface_crossings(ctx, c, X, dir, 2.0 * len, buf, &first, &count));
  *inside = (int)(count % 2);
cleanup:
  return st;
}

/* The smallest s >= 0 with |o + s r - c| = rad for o outside, or HUGE_VAL. */
static double sphere_hit(const double o[3], const double r[3], const double c[3], double rad)
{
  double m[3];
  fcm__vec3_sub(o, c, m);
  const double a = fcm__vec3_dot(r, r), b = fcm__vec3_dot(m, r),
               cc = fcm__vec3_dot(m, m) - rad * rad;
  if (!(a > 0.0) || b >= 0.0) return HUGE_VAL; /* not approaching the centre */
  const double disc = b * b - a * cc;
  if (disc < 0.0) return HUGE_VAL;
  /* the smaller root, in the cancellation-free form */
  return cc / (-b + sqrt(disc));
}

/* The entry parameter s >= 0 of o + s r into the box, or HUGE_VAL (slabs). */
static double box_hit(const double o[3], const double r[3], const double lo[3], const double hi[3])
{
  double s0 = 0.0, s1 = HUGE_VAL;
  for (int i = 0; i < 3; i++) {
    if (r[i] == 0.0) {
      if (o[i] < lo[i] || o[i] > hi[i]) return HUGE_VAL;
      continue;
    }
    double a = (lo[i] - o[i]) / r[i], b = (hi[i] - o[i]) / r[i];
    if (a > b) {
      const double tmp = a;
      a = b;
      b = tmp;
    }
    s0 = FCM_MAX(s0, a);
    s1 = FCM_MIN(s1, b);
    if (s0 > s1) return HUGE_VAL;
  }
  return s0;
}

fcm_status fcm__sim_contact_toi(fcm_ctx *ctx, const sim_contact *c, const sim_pose *P,
                                const double y[3], const double dy[3], double t, double smax,
                                fcm__idbuf *buf, double *s)
{
  fcm_status st = FCM_OK;
  double X[3], dX[3], d, g[3];
  *s = HUGE_VAL;
  if (c->kind == SIM_CONTACT_PLANE) {
    FCM_TRY(ctx, fcm__sim_contact_distance(ctx, c, P, y, t, 0.0, buf, &d, g, NULL));
    const double slope = fcm__vec3_dot(g, dy);
    if (!(d > 0.0))
      *s = 0.0;
    else if (slope < 0.0)
      *s = -d / slope;
    return FCM_OK;
  }
  to_frame(P, y, 0, X);
  to_frame(P, dy, 1, dX);
  switch (c->kind) {
  case SIM_CONTACT_SPHERE:
    FCM_TRY(ctx, fcm__sim_contact_distance(ctx, c, P, y, t, 0.0, buf, &d, g, NULL));
    *s = d > 0.0 ? sphere_hit(X, dX, c->center, c->radius) : 0.0;
    break;
  case SIM_CONTACT_BOX:
    *s = box_hit(X, dX, c->lo, c->hi);
    break;
  default:
    FCM_TRY(ctx, surface_crossings(ctx, c, X, dX, smax, buf, s, NULL));
    break;
  }
cleanup:
  return st;
}

fcm_status fcm__sim_contact_surface_setup(fcm_ctx *ctx, int k, sim_contact *c)
{
  fcm_status st = FCM_OK;
  fcm_surface *surf = NULL;
  fcm_surface_report rep;
  fcm_surface_check_options so = fcm_surface_check_options_default();
  double *boxes = NULL;
  so.self_intersections = 0;
  FCM_TRY(ctx, fcm_surface_create(ctx, c->nv, c->xyz, c->nt, c->tri, &surf));
  FCM_TRY(ctx, fcm_surface_check(surf, &so, &rep));
  if (rep.num_boundary_edges > 0) {
    const double *a = c->xyz + 3 * rep.boundary_edges[0][0];
    const double *b = c->xyz + 3 * rep.boundary_edges[0][1];
    FCM_CHECK(0, ctx, FCM_ERR_ARG,
              "contact surface %d: not closed: %lld edges belong to one triangle only (%lld "
              "holes), the first between vertices %lld (%g, %g, %g) and %lld (%g, %g, %g); the "
              "inside test needs a closed surface (fill its holes)",
              k, (long long)rep.num_boundary_edges, (long long)rep.num_boundary_loops,
              (long long)rep.boundary_edges[0][0], a[0], a[1], a[2],
              (long long)rep.boundary_edges[0][1], b[0], b[1], b[2]);
  }
  FCM_CHECK(rep.num_nonmanifold_edges == 0, ctx, FCM_ERR_ARG,
            "contact surface %d: %lld edges belong to three or more triangles (the first "
            "between vertices %lld and %lld): the inside test needs a closed manifold surface",
            k, (long long)rep.num_nonmanifold_edges, (long long)rep.nonmanifold_edges[0][0],
            (long long)rep.nonmanifold_edges[0][1]);
  fcm_surface_bounding_box(surf, c->lo, c->hi);
  FCM_ALLOC(ctx, 6 * (size_t)c->nt, boxes);
  for (fcm_index t = 0; t < c->nt; t++)
    for (int i = 0; i < 3; i++) {
      double lo = HUGE_VAL, hi = -HUGE_VAL;
      for (int v = 0; v < 3; v++) {
        const double x = c->xyz[3 * c->tri[3 * t + v] + i];
        lo = FCM_MIN(lo, x);
        hi = FCM_MAX(hi, x);
      }
      boxes[6 * t + i] = lo;
      boxes[6 * t + 3 + i] = hi;
    }
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, c->nt, boxes, &c->tree));
cleanup:
  fcm__free(ctx, boxes);
  fcm_surface_destroy(&surf);
  return st;
}

double fcm__sim_contact_reach(const sim_contact *c, const sim_pose *P, const double y[3])
{
  double X[3], r = 0.0, diag = 0.0;
  to_frame(P, y, 0, X);
  for (int i = 0; i < 3; i++) {
    const double m = 0.5 * (c->lo[i] + c->hi[i]);
    r += (X[i] - m) * (X[i] - m);
    diag += (c->hi[i] - c->lo[i]) * (c->hi[i] - c->lo[i]);
  }
  return sqrt(r) + sqrt(diag);
}

fcm_status fcm_integrator_contact_distance(const fcm_integrator *I, int id, const double x[3],
                                           double t, double *distance, double gradient[3],
                                           double hessian[9])
{
  fcm_status st = FCM_OK;
  fcm__idbuf buf = {NULL, 0, 0};
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  FCM_CHECK(id >= 0 && id < I->num_contacts, ctx, FCM_ERR_ARG,
            "contact distance: obstacle %d out of range [0, %d)", id, I->num_contacts);
  FCM_CHECK(x && distance, ctx, FCM_ERR_ARG, "contact distance: NULL point or distance");
  FCM_CHECK(I->contacts[id].kind != SIM_CONTACT_BODIES, ctx, FCM_ERR_ARG,
            "contact distance: contact %d is between bodies (no obstacle to measure to)", id);
  {
    const sim_contact *ct = &I->contacts[id];
    double g[3], H[9];
    int inside = 0;
    sim_pose P;
    fcm__sim_contact_pose(ct, t, &P);
    FCM_TRY(ctx, fcm__sim_contact_distance(ctx, ct, &P, x, t, fcm__sim_contact_reach(ct, &P, x),
                                           &buf, distance, g, H));
    if (ct->kind == SIM_CONTACT_SURFACE) {
      FCM_TRY(ctx, fcm__sim_contact_inside(ctx, ct, &P, x, t, &buf, &inside));
      if (inside) *distance = -*distance;
    }
    if (gradient) memcpy(gradient, g, sizeof g);
    if (hessian) memcpy(hessian, H, sizeof H);
  }
cleanup:
  if (I) fcm__geom_idbuf_free(I->ctx, &buf);
  return st;
}
