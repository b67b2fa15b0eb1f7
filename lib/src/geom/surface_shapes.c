/* Procedural triangle surfaces, the cut surfaces of scenes: a plane clipped to a box, a
 * rectangle, a disc, and an affine image of any surface. */
#include "geom/geom_impl.h"
#include "geom/surface_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

static int finite3(const double *v)
{
  return v && isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* Unit normal n of `normal` and an orthonormal in-plane pair (u, v = n x u); u follows
 * `axis` projected onto the plane when given, else any direction. 0 when normal (or the
 * projected axis) has no length. */
static int plane_frame(const double normal[3], const double *axis, double n[3], double u[3],
                       double v[3])
{
  const double ln = sqrt(fcm__vec3_dot(normal, normal));
  if (!(ln > 0.0)) return 0;
  for (int d = 0; d < 3; d++)
    n[d] = normal[d] / ln;
  double a[3];
  if (axis) {
    memcpy(a, axis, sizeof a);
  } else {
    a[0] = fabs(n[0]) < 0.6 ? 1.0 : 0.0;
    a[1] = fabs(n[0]) < 0.6 ? 0.0 : 1.0;
    a[2] = 0.0;
  }
  const double an = fcm__vec3_dot(a, n);
  for (int d = 0; d < 3; d++)
    u[d] = a[d] - an * n[d];
  const double lu = sqrt(fcm__vec3_dot(u, u));
  if (!(lu > 1e-12 * (axis ? sqrt(fcm__vec3_dot(a, a)) : 1.0))) return 0;
  for (int d = 0; d < 3; d++)
    u[d] /= lu;
  fcm__vec3_cross(n, u, v);
  return 1;
}

/* A fan around vertex 0 (the centre) over the ring 1..m (closed when `closed`). */
static fcm_status fan_surface(fcm_ctx *ctx, int m, const double *x, int closed, fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  fcm_index tris[3 * 256];
  const int nt = closed ? m : m - 1;
  for (int k = 0; k < nt; k++) {
    tris[3 * k] = 0;
    tris[3 * k + 1] = 1 + k;
    tris[3 * k + 2] = 1 + (k + 1) % m;
  }
  FCM_TRY(ctx, fcm_surface_create(ctx, m + 1, x, nt, tris, surf));
cleanup:
  return st;
}

fcm_status fcm_surface_create_plane(fcm_ctx *ctx, const double point[3], const double normal[3],
                                    const double lo[3], const double hi[3], fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  double n[3], u[3], v[3], x[3 * (FCM__POLY_MAX_VERTS + 1)], work[3 * FCM__POLY_MAX_VERTS];
  FCM_CHECK(surf, ctx, FCM_ERR_ARG, "plane surface: output pointer is NULL");
  *surf = NULL;
  FCM_CHECK(finite3(point) && finite3(normal) && finite3(lo) && finite3(hi), ctx, FCM_ERR_ARG,
            "plane surface: point, normal and box must be given and finite");
  FCM_CHECK(plane_frame(normal, NULL, n, u, v), ctx, FCM_ERR_ARG,
            "plane surface: the normal (%g, %g, %g) has no length", normal[0], normal[1],
            normal[2]);
  for (int d = 0; d < 3; d++)
    FCM_CHECK(lo[d] < hi[d], ctx, FCM_ERR_ARG,
              "plane surface: box lo[%d] = %g must be below hi[%d] = %g", d, lo[d], d, hi[d]);
  /* A square in the plane around the box centre's projection, larger than the box, clipped
   * by the box's six faces. */
  double c[3], diag = 0.0;
  for (int d = 0; d < 3; d++) {
    c[d] = 0.5 * (lo[d] + hi[d]);
    diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
  }
  diag = sqrt(diag);
  const double off = fcm__vec3_dot(n, c) - fcm__vec3_dot(n, point);
  double *ring = x + 3;
  for (int k = 0; k < 4; k++) {
    const double su = (k == 0 || k == 3) ? -diag : diag, sv = k < 2 ? -diag : diag;
    for (int d = 0; d < 3; d++)
      ring[3 * k + d] = c[d] - off * n[d] + su * u[d] + sv * v[d];
  }
  int m = 4;
  for (int f = 0; f < 6 && m > 0; f++) {
    fcm__plane pl = {{0, 0, 0}, 0};
    const int d = f / 2;
    pl.n[d] = f % 2 ? 1.0 : -1.0;
    pl.d = f % 2 ? hi[d] : -lo[d];
    m = fcm__geom_polygon_clip(ring, m, FCM__POLY_MAX_VERTS, &pl, 0.0, 0, work);
  }
  FCM_CHECK(m >= 3, ctx, FCM_ERR_GEOMETRY,
            "plane surface: the plane through (%g, %g, %g) with normal (%g, %g, %g) misses the "
            "box [%g, %g] x [%g, %g] x [%g, %g]",
            point[0], point[1], point[2], normal[0], normal[1], normal[2], lo[0], hi[0], lo[1],
            hi[1], lo[2], hi[2]);
  for (int d = 0; d < 3; d++) {
    x[d] = 0.0;
    for (int k = 0; k < m; k++)
      x[d] += ring[3 * k + d] / m;
  }
  FCM_TRY(ctx, fan_surface(ctx, m, x, 1, surf));
cleanup:
  return st;
}

fcm_status fcm_surface_create_rectangle(fcm_ctx *ctx, const double center[3],
                                        const double normal[3], const double axis[3],
                                        const double size[2], fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  double n[3], u[3], v[3], x[12];
  const fcm_index tris[6] = {0, 1, 2, 0, 2, 3};
  FCM_CHECK(surf, ctx, FCM_ERR_ARG, "rectangle surface: output pointer is NULL");
  *surf = NULL;
  FCM_CHECK(finite3(center) && finite3(normal) && finite3(axis) && size, ctx, FCM_ERR_ARG,
            "rectangle surface: center, normal, axis and size must be given and finite");
  FCM_CHECK(isfinite(size[0]) && isfinite(size[1]) && size[0] > 0.0 && size[1] > 0.0, ctx,
            FCM_ERR_ARG, "rectangle surface: size = [%g, %g] must be two finite values > 0",
            size[0], size[1]);
  FCM_CHECK(plane_frame(normal, axis, n, u, v), ctx, FCM_ERR_ARG,
            "rectangle surface: the normal (%g, %g, %g) has no length or the axis (%g, %g, %g) "
            "is parallel to it",
            normal[0], normal[1], normal[2], axis[0], axis[1], axis[2]);
  for (int k = 0; k < 4; k++) {
    const double su = (k == 0 || k == 3) ? -0.5 : 0.5, sv = k < 2 ? -0.5 : 0.5;
    for (int d = 0; d < 3; d++)
      x[3 * k + d] = center[d] + su * size[0] * u[d] + sv * size[1] * v[d];
  }
  FCM_TRY(ctx, fcm_surface_create(ctx, 4, x, 2, tris, surf));
cleanup:
  return st;
}

fcm_status fcm_surface_create_disc(fcm_ctx *ctx, const double center[3], const double normal[3],
                                   double radius, int segments, fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  double n[3], u[3], v[3], x[3 * 257];
  FCM_CHECK(surf, ctx, FCM_ERR_ARG, "disc surface: output pointer is NULL");
  *surf = NULL;
  FCM_CHECK(finite3(center) && finite3(normal), ctx, FCM_ERR_ARG,
            "disc surface: center and normal must be given and finite");
  FCM_CHECK(isfinite(radius) && radius > 0.0, ctx, FCM_ERR_ARG,
            "disc surface: radius = %g must be finite and > 0", radius);
  FCM_CHECK(segments >= 3 && segments <= 256, ctx, FCM_ERR_ARG,
            "disc surface: segments = %d outside [3, 256]", segments);
  FCM_CHECK(plane_frame(normal, NULL, n, u, v), ctx, FCM_ERR_ARG,
            "disc surface: the normal (%g, %g, %g) has no length", normal[0], normal[1], normal[2]);
  memcpy(x, center, 3 * sizeof *x);
  for (int k = 0; k < segments; k++) {
    const double t = 2.0 * PI * k / segments;
    for (int d = 0; d < 3; d++)
      x[3 + 3 * k + d] = center[d] + radius * (cos(t) * u[d] + sin(t) * v[d]);
  }
  FCM_TRY(ctx, fan_surface(ctx, segments, x, 1, surf));
cleanup:
  return st;
}

fcm_status fcm_surface_create_transformed(fcm_ctx *ctx, const fcm_surface *src, const double A[9],
                                          const double b[3], fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  double *x = NULL;
  FCM_CHECK(surf, ctx, FCM_ERR_ARG, "transformed surface: output pointer is NULL");
  *surf = NULL;
  FCM_CHECK(src && A && b, ctx, FCM_ERR_ARG, "transformed surface: NULL argument");
  for (int k = 0; k < 9; k++)
    FCM_CHECK(isfinite(A[k]), ctx, FCM_ERR_ARG, "transformed surface: A[%d] = %g not finite", k,
              A[k]);
  FCM_CHECK(finite3(b), ctx, FCM_ERR_ARG, "transformed surface: b not finite");
  const double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                     A[2] * (A[3] * A[7] - A[4] * A[6]);
  FCM_CHECK(fabs(det) > 0.0, ctx, FCM_ERR_ARG, "transformed surface: det A = %g is not invertible",
            det);
  const fcm_index nv = src->num_vertices;
  FCM_ALLOC_RAW(ctx, 3 * (size_t)nv, x);
  for (fcm_index i = 0; i < nv; i++) {
    const double *p = src->coords + 3 * i;
    for (int r = 0; r < 3; r++)
      x[3 * i + r] = A[3 * r] * p[0] + A[3 * r + 1] * p[1] + A[3 * r + 2] * p[2] + b[r];
  }
  FCM_TRY(ctx, fcm_surface_create(ctx, nv, x, src->num_triangles, src->tris, surf));
cleanup:
  fcm__free(ctx, x);
  return st;
}
