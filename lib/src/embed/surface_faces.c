/* The cut faces of a body given by its closed boundary alone: a face of a part on a cut, where
 * the body does not fill the part, is split along the lines where the boundary triangles near
 * it cross its plane, and only the polygons inside the body are kept, so that the cut face ends
 * at the body's surface (fcm__material_face_inside()). */
#include "embed/surface_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <string.h>

/* How far into its part a cut face's polygon is probed for the body where a boundary triangle
 * lies in the face's plane, relative to the cell size: ten times the cuts' tolerance (1e-9),
 * within which a triangle counts as in the plane. */
#define FACE_PROBE_RTOL 1e-8

/* Room for `slots` polygons in m->fp (the first `used` kept) and `segs` segments in m->seg. */
static fcm_status face_room(fcm_ctx *ctx, fcm__material *m, size_t used, size_t slots, size_t segs)
{
  fcm_status st = FCM_OK;
  enum { SLOT = 3 * FCM__POLY_MAX_VERTS };
  if (slots > m->fcap) {
    size_t cap = m->fcap ? 2 * m->fcap : 16;
    while (cap < slots)
      cap *= 2;
    void *q = m->fp;
    FCM_TRY(ctx, fcm__resize(ctx, &q, SLOT * used, SLOT * cap, sizeof(double)));
    m->fp = q;
    q = m->fpn;
    FCM_TRY(ctx, fcm__resize(ctx, &q, used, cap, sizeof(int)));
    m->fpn = q;
    m->fcap = cap;
  }
  if (segs > m->scap) {
    size_t cap = m->scap ? 2 * m->scap : 64;
    while (cap < segs)
      cap *= 2;
    void *q = m->seg;
    FCM_TRY(ctx, fcm__resize(ctx, &q, 0, 6 * cap, sizeof(double)));
    m->seg = q;
    m->scap = cap;
  }
cleanup:
  return st;
}

/* Where boundary triangle (a, b, c) crosses the plane nrm . y = d: its segment (p, q); 0 when
 * it does not cross it along a segment longer than tol (vertices within tol of the plane count
 * as on it; a triangle in the plane crosses nothing, and sets *flat). */
static int tri_segment(const double *a, const double *b, const double *c, const double nrm[3],
                       double d, double tol, double p[3], double q[3], int *flat)
{
  const double *v[3] = {a, b, c};
  double s[3], pt[3][3];
  int np = 0, on = 0, pos = 0, neg = 0;
  for (int i = 0; i < 3; i++) {
    s[i] = fcm__vec3_dot(nrm, v[i]) - d;
    on += fabs(s[i]) <= tol;
    pos += s[i] > tol;
    neg += s[i] < -tol;
  }
  if (on == 3) *flat = 1;
  if (on == 3 || (on + pos == 3 && on < 2) || (on + neg == 3 && on < 2)) return 0;
  for (int i = 0; i < 3; i++) {
    const int j = (i + 1) % 3;
    if (fabs(s[i]) <= tol) memcpy(pt[np++], v[i], sizeof pt[0]);
    if ((s[i] > tol && s[j] < -tol) || (s[i] < -tol && s[j] > tol)) {
      const double t = s[i] / (s[i] - s[j]);
      for (int k = 0; k < 3; k++)
        pt[np][k] = v[i][k] + t * (v[j][k] - v[i][k]);
      np++;
    }
  }
  if (np != 2) return 0;
  memcpy(p, pt[0], sizeof pt[0]);
  memcpy(q, pt[1], sizeof pt[1]);
  double e[3];
  fcm__vec3_sub(q, p, e);
  return fcm__vec3_dot(e, e) > tol * tol;
}

/* Whether the segment (p, q) in the plane of the convex polygon y (n vertices, counter-clockwise
 * about nrm) runs through its inside farther than tol, so that its line splits it. */
static int segment_splits(const double *y, int n, const double nrm[3], const double p[3],
                          const double q[3], double tol)
{
  double u[3], t0 = 0.0, t1 = 1.0;
  fcm__vec3_sub(q, p, u);
  const double len = sqrt(fcm__vec3_dot(u, u));
  for (int i = 0; i < n && t0 < t1; i++) {
    const double *a = y + 3 * i, *b = y + 3 * ((i + 1) % n);
    double e[3], w[3], r[3];
    fcm__vec3_sub(b, a, e);
    fcm__vec3_cross(nrm, e, w); /* inward, as long as the edge */
    const double el = sqrt(fcm__vec3_dot(w, w));
    if (!(el > 0.0)) continue;
    fcm__vec3_sub(p, a, r);
    /* inside by more than tol: w . (p + t u - a) > tol |w| */
    const double f = fcm__vec3_dot(w, r) - tol * el, g = fcm__vec3_dot(w, u);
    if (g == 0.0) {
      if (f <= 0.0) return 0;
    } else if (g > 0.0) {
      t0 = fmax(t0, -f / g);
    } else {
      t1 = fmin(t1, -f / g);
    }
  }
  return (t1 - t0) * len > tol;
}

/* Twice the area of the planar polygon y (n vertices) along nrm. */
static double polygon_area2(const double *y, int n, const double nrm[3])
{
  double a = 0.0;
  for (int i = 1; i + 1 < n; i++) {
    double e[3], f[3], c[3];
    fcm__vec3_sub(y + 3 * i, y, e);
    fcm__vec3_sub(y + 3 * (i + 1), y, f);
    fcm__vec3_cross(e, f, c);
    a += fcm__vec3_dot(c, nrm);
  }
  return a;
}

fcm_status fcm__material_face_inside(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                                     const double *x, int n, fcm__tribuf *b)
{
  fcm_status st = FCM_OK;
  enum { SLOT = 3 * FCM__POLY_MAX_VERTS };
  const fcm_geometry *G = m->geom;
  const double tol = FCM__EMBED_MATCH_RTOL * cell->size,
               amin = FCM__MATERIAL_FACE_AREA_RTOL * cell->size * cell->size;
  double nrm[3] = {0.0, 0.0, 0.0}, lo[3], hi[3], work[SLOT];
  if (n < 3) return FCM_OK;
  if (n > FCM__POLY_MAX_VERTS) return fcm__embed_tris_fan(ctx, b, x, n); /* beyond a slot */
  for (int i = 0; i < n; i++) { /* Newell's normal: x's own orientation */
    const double *a = x + 3 * i, *c = x + 3 * ((i + 1) % n);
    nrm[0] += (a[1] - c[1]) * (a[2] + c[2]);
    nrm[1] += (a[2] - c[2]) * (a[0] + c[0]);
    nrm[2] += (a[0] - c[0]) * (a[1] + c[1]);
  }
  const double nn = sqrt(fcm__vec3_dot(nrm, nrm));
  if (!(nn > 0.0)) return FCM_OK;
  for (int d = 0; d < 3; d++)
    nrm[d] /= nn;
  double d0 = 0.0;
  for (int i = 0; i < n; i++)
    d0 += fcm__vec3_dot(nrm, x + 3 * i) / n;
  for (int d = 0; d < 3; d++) {
    lo[d] = hi[d] = x[d];
    for (int i = 1; i < n; i++)
      lo[d] = fmin(lo[d], x[3 * i + d]), hi[d] = fmax(hi[d], x[3 * i + d]);
    lo[d] -= 2.0 * tol, hi[d] += 2.0 * tol;
  }
  /* the boundary's segments in the plane (the query's ids are read before the inside tests,
   * which take the buffer) */
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, m->tree, lo, hi, &m->buf));
  FCM_TRY(ctx, face_room(ctx, m, 0, 1, m->buf.n));
  size_t ns = 0;
  int flat = 0; /* a boundary triangle lies in the plane */
  for (size_t k = 0; k < m->buf.n; k++) {
    const fcm_index *t = G->tris + 3 * m->buf.ids[k];
    ns += (size_t)tri_segment(G->coords + 3 * t[0], G->coords + 3 * t[1], G->coords + 3 * t[2], nrm,
                              d0, tol, m->seg + 6 * ns, m->seg + 6 * ns + 3, &flat);
  }
  /* x split along each segment's line where the segment runs through a polygon: no segment
   * crosses the polygons left, each lies wholly inside the body or wholly outside */
  memcpy(m->fp, x, 3 * (size_t)n * sizeof *x);
  m->fpn[0] = n;
  size_t np = 1;
  for (size_t k = 0; k < ns; k++) {
    const double *p = m->seg + 6 * k, *q = p + 3;
    double u[3];
    fcm__plane pl;
    fcm__vec3_sub(q, p, u);
    fcm__vec3_cross(nrm, u, pl.n);
    const double l = sqrt(fcm__vec3_dot(pl.n, pl.n));
    for (int d = 0; d < 3; d++)
      pl.n[d] /= l;
    pl.d = fcm__vec3_dot(pl.n, p);
    const fcm__plane opp = {{-pl.n[0], -pl.n[1], -pl.n[2]}, -pl.d};
    for (size_t j = 0, n0 = np; j < n0; j++) {
      double *y = m->fp + SLOT * j;
      if (!segment_splits(y, m->fpn[j], nrm, p, q, tol)) continue;
      FCM_TRY(ctx, face_room(ctx, m, np, np + 1, 0));
      y = m->fp + SLOT * j;
      double *z = m->fp + SLOT * np;
      memcpy(z, y, 3 * (size_t)m->fpn[j] * sizeof *y);
      const int a = fcm__geom_polygon_clip(y, m->fpn[j], FCM__POLY_MAX_VERTS, &pl, tol, 0, work);
      const int c = fcm__geom_polygon_clip(z, m->fpn[j], FCM__POLY_MAX_VERTS, &opp, tol, 0, work);
      /* no split after all (or a slot's capacity): a clip that left fewer than 3 vertices
       * did not touch its polygon, so y is whole, or z still holds it */
      if (a < 3) continue;
      if (c < 3) {
        memcpy(y, z, 3 * (size_t)m->fpn[j] * sizeof *y);
        continue;
      }
      m->fpn[j] = a;
      m->fpn[np++] = c;
    }
  }
  /* the polygons the body holds: the winding number at each one's vertex centroid; where the
   * body's surface lies in the face's plane, moved FACE_PROBE_RTOL of the cell into the part
   * (against x's outward normal), so that the polygon goes to the side the body is on */
  const double probe = flat ? FACE_PROBE_RTOL * cell->size : 0.0;
  for (size_t j = 0; j < np; j++) {
    const double *y = m->fp + SLOT * j;
    const int k = m->fpn[j];
    if (!(polygon_area2(y, k, nrm) > 2.0 * amin)) continue;
    double c[3] = {0.0, 0.0, 0.0}, T[12];
    for (int i = 0; i < k; i++)
      for (int d = 0; d < 3; d++)
        c[d] += y[3 * i + d] / k;
    for (int d = 0; d < 3; d++)
      c[d] -= probe * nrm[d];
    for (int v = 0; v < 4; v++) /* a small tet with its corner there */
      for (int d = 0; d < 3; d++)
        T[3 * v + d] = c[d] + (v == d + 1 ? 0.25 * cell->size : 0.0);
    fcm__embed_cell kc;
    fcm__material_tet_cell(T, cell->id, &kc);
    const double z = 0.0;
    int in = 0;
    FCM_TRY(ctx,
            fcm__embed_inside_line(ctx, G, m->tree, &kc, 0.0, 0.0, 1, &z, &in, &m->buf, &m->cr));
    if (in) FCM_TRY(ctx, fcm__embed_tris_fan(ctx, b, y, k));
  }
cleanup:
  return st;
}
