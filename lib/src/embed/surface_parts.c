/* Cut cells of a body given by its closed boundary alone (no volume mesh). The convex parts of
 * such a cell are the cell itself split by the cut triangles (pieces.c); the material of a part
 * is the body inside it, measured exactly by the surface moments (surface_moments.c) on the
 * tets of a fan of the part: each tet is an affine Tet4 cell of its own, and the moments cost
 * what the boundary triangles meeting it cost. A part without material is dropped, and two
 * parts (of one cell, or of two cells across a face) join only where the overlap of their
 * faces holds material: the body's volume in a thin prism on the overlap. So the pieces are
 * the components of the material as the volume mesh's parts give them. A part that holds two
 * separate lumps of the body is replaced by its pieces inside the body (split by the boundary
 * triangles), which join only within a lump. The parts' cut faces, which end at the body's
 * surface: surface_faces.c. */
#include "embed/surface_impl.h"
#include "element/element_impl.h"
#include "la/mat3.h"
#include "la/vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The prism's half-height on a face, relative to the cell size: far above the surface moments'
 * rounding (1e-15 of the prism). */
#define PRISM_RTOL 1e-6

/* A part whose material is within this fraction of its volume lies wholly inside the body. */
#define FULL_RTOL 1e-12

fcm_status fcm__material_create(fcm_ctx *ctx, const fcm_geometry *geom, fcm__material **out)
{
  fcm_status st = FCM_OK;
  fcm__material *m = NULL;
  FCM_ALLOC(ctx, 1, m);
  m->geom = geom;
  FCM_TRY(ctx, fcm__geom_tree(ctx, geom, 1, &m->tree));
  FCM_TRY(ctx, fcm__moment_quad_create(ctx, 0, &m->q0));
  *out = m;
  m = NULL;
cleanup:
  fcm__material_destroy(ctx, &m);
  return st;
}

void fcm__material_destroy(fcm_ctx *ctx, fcm__material **pm)
{
  if (!pm || !*pm) return;
  fcm__material *m = *pm;
  fcm__moment_quad_free(ctx, &m->q0);
  fcm__geom_idbuf_free(ctx, &m->buf);
  fcm__crossings_free(ctx, &m->cr);
  fcm__srule_free(ctx, &m->sr);
  fcm__free(ctx, m->tets);
  fcm__free(ctx, m->vol);
  fcm__free(ctx, m->edges);
  fcm__free(ctx, m->uf);
  fcm__free(ctx, m->kept);
  fcm__free(ctx, m->rep);
  fcm__free(ctx, m->fp);
  fcm__free(ctx, m->fpn);
  fcm__free(ctx, m->seg);
  fcm__free(ctx, m);
  *pm = NULL;
}

fcm_status fcm__material_status(fcm__material *m)
{
  const fcm_status st = m->st;
  m->st = FCM_OK;
  return st;
}

void fcm__material_tet_cell(const double *T, fcm_index id, fcm__embed_cell *k)
{
  k->type = FCM_ELEMENT_TET4;
  k->info = fcm_element_get_info(FCM_ELEMENT_TET4);
  k->id = id;
  memcpy(k->X, T, 12 * sizeof *T);
  k->num_planes = 0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      k->A[3 * i + j] = T[3 * (j + 1) + i] - T[i];
  k->xi0[0] = k->xi0[1] = k->xi0[2] = 0.0;
  k->detA = fcm__mat3_inv(k->A, k->Ainv);
  k->affine = 1;
  k->size = fcm__element_cell_size(4, T);
  k->tol = 0.0;
  k->volume = fabs(k->detA) / 6.0;
  for (int d = 0; d < 3; d++) {
    k->lo[d] = HUGE_VAL, k->hi[d] = -HUGE_VAL;
    for (int a = 0; a < 4; a++)
      k->lo[d] = fmin(k->lo[d], T[3 * a + d]), k->hi[d] = fmax(k->hi[d], T[3 * a + d]);
  }
}

/* The body's signed rule of degree q->m on each of the nt tets (tets, vol) inside cell (which
 * names the errors), summed into *volume; appended to out (cell's reference coordinates) when
 * out is given. */
static fcm_status tets_material(fcm_ctx *ctx, fcm__material *m, const double *tets,
                                const double *vol, int nt, const fcm__moment_quad *q,
                                const fcm__embed_cell *cell, fcm__srule *out, double *volume)
{
  fcm_status st = FCM_OK;
  double sum = 0.0, apex[3];
  int winding = FCM__WINDING_UNKNOWN; /* about the clear tets with vertex 0 at apex */
  for (int t = 0; t < nt; t++) {
    if (vol[t] == 0.0) continue;
    fcm__embed_cell k;
    fcm__material_tet_cell(tets + 12 * t, cell->id, &k);
    /* a fan tet flat to rounding (near-coplanar vertices of a part) holds no material that
     * counts, and its map to the unit tet is too ill-conditioned for the line crossings */
    if (!fcm__embed_cell_solid(&k)) continue;
    int clear;
    FCM_TRY(ctx, fcm__embed_cell_clear(ctx, m->geom, m->tree, &k, &m->buf, &clear));
    if (clear) {
      /* wholly inside or outside: as every clear tet sharing its vertex 0 (a fan's apex) */
      if (winding != FCM__WINDING_UNKNOWN && memcmp(apex, k.X, sizeof apex))
        winding = FCM__WINDING_UNKNOWN;
      memcpy(apex, k.X, sizeof apex);
      FCM_TRY(ctx, fcm__embed_moment_rule_clear(ctx, m->geom, m->tree, &k, q, NULL, &m->buf, &m->cr,
                                                &winding, &m->sr));
    } else {
      FCM_TRY(ctx, fcm__embed_moment_rule_kept(ctx, m->geom, m->tree, &k, q, NULL, &m->buf, &m->cr,
                                               &m->sr));
    }
    if (out) FCM_TRY(ctx, fcm__srule_room(ctx, out, m->sr.n));
    for (size_t i = 0; i < m->sr.n; i++) {
      const double w = m->sr.w[i] * k.detA;
      sum += w;
      if (!out) continue;
      double x[3], det = cell->detA;
      fcm__mat3_mulv(k.A, m->sr.x + 3 * i, x);
      for (int d = 0; d < 3; d++)
        x[d] += k.X[d];
      if (cell->affine)
        fcm__embed_to_reference_affine(cell, x, out->x + 3 * out->n);
      else
        FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, x, out->x + 3 * out->n, &det));
      out->w[out->n++] = w / det;
    }
  }
  *volume = sum;
cleanup:
  return st;
}

/* The body's signed rule of degree q->m on the affine cell k alone, into m->sr (k's reference
 * coordinates), and its volume, as tets_material() takes each tet's. */
static fcm_status one_cell_material(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *k,
                                    const fcm__moment_quad *q, double *volume)
{
  fcm_status st = FCM_OK;
  double sum = 0.0;
  int clear, winding = FCM__WINDING_UNKNOWN;
  FCM_TRY(ctx, fcm__embed_cell_clear(ctx, m->geom, m->tree, k, &m->buf, &clear));
  if (clear)
    FCM_TRY(ctx, fcm__embed_moment_rule_clear(ctx, m->geom, m->tree, k, q, NULL, &m->buf, &m->cr,
                                              &winding, &m->sr));
  else
    FCM_TRY(ctx, fcm__embed_moment_rule_kept(ctx, m->geom, m->tree, k, q, NULL, &m->buf, &m->cr,
                                             &m->sr));
  for (size_t i = 0; i < m->sr.n; i++)
    sum += m->sr.w[i] * k->detA;
  *volume = sum;
cleanup:
  return st;
}

/* tets_material() on the box lo..hi of cell's reference coordinates as one Hex8 cell: one
 * moment rule instead of one per fan tet (a box of 6 faces has 12), each boundary triangle
 * clipped once, one exit facet and edge. */
static fcm_status box_material(fcm_ctx *ctx, fcm__material *m, const double lo[3],
                               const double hi[3], const fcm__moment_quad *q,
                               const fcm__embed_cell *cell, fcm__srule *out, double *volume)
{
  fcm_status st = FCM_OK;
  fcm__embed_cell k;
  double c[3], h[3];
  (void)fcm__embed_box_cell(cell, lo, hi, &k); /* not flat: fcm__embed_part_box() */
  for (int d = 0; d < 3; d++)
    c[d] = 0.5 * (lo[d] + hi[d]), h[d] = 0.5 * (hi[d] - lo[d]);
  FCM_TRY(ctx, one_cell_material(ctx, m, &k, q, volume));
  if (!out) goto cleanup;
  FCM_TRY(ctx, fcm__srule_room(ctx, out, m->sr.n));
  for (size_t i = 0; i < m->sr.n; i++) {
    const double *e = m->sr.x + 3 * i;
    double *x = out->x + 3 * out->n;
    for (int d = 0; d < 3; d++)
      x[d] = c[d] + h[d] * e[d];
    out->w[out->n++] = m->sr.w[i] * k.detA / cell->detA;
  }
cleanup:
  return st;
}

/* Room for nt tets in m. */
static fcm_status tets_room(fcm_ctx *ctx, fcm__material *m, int nt)
{
  fcm_status st = FCM_OK;
  if (nt <= m->cap) return FCM_OK;
  void *t = m->tets, *v = m->vol;
  FCM_TRY(ctx, fcm__resize(ctx, &t, 0, 12 * (size_t)nt, sizeof(double)));
  m->tets = t;
  FCM_TRY(ctx, fcm__resize(ctx, &v, 0, (size_t)nt, sizeof(double)));
  m->vol = v;
  m->cap = nt;
cleanup:
  return st;
}

fcm_status fcm__material_poly(fcm_ctx *ctx, fcm__material *m, const fcm__poly *p,
                              const fcm__moment_quad *q, const fcm__embed_cell *cell,
                              fcm__srule *out, double *volume)
{
  fcm_status st = FCM_OK;
  int is_box = 0;
  double lo[3], hi[3];
  *volume = 0.0;
  if (p->nf == 0) return FCM_OK;
  if (cell->info->num_corners == 8)
    FCM_TRY(ctx, fcm__embed_part_box(ctx, cell, p, lo, hi, &is_box));
  if (is_box) return box_material(ctx, m, lo, hi, q ? q : &m->q0, cell, out, volume);
  FCM_TRY(ctx, tets_room(ctx, m, fcm__geom_poly_num_tets(p)));
  const int nt = fcm__geom_poly_tets(p, m->tets, m->vol);
  FCM_TRY(ctx, tets_material(ctx, m, m->tets, m->vol, nt, q ? q : &m->q0, cell, out, volume));
cleanup:
  return st;
}

fcm_status fcm__material_cell(fcm_ctx *ctx, fcm__material *m, const fcm__moment_quad *q,
                              const fcm__embed_cell *cell, fcm__srule *out, double *volume)
{
  fcm_status st = FCM_OK;
  double sum = 0.0;
  FCM_TRY(ctx, fcm__embed_moment_rule(ctx, m->geom, m->tree, cell, q ? q : &m->q0, NULL, &m->buf,
                                      &m->cr, &m->sr));
  if (out) FCM_TRY(ctx, fcm__srule_room(ctx, out, m->sr.n));
  for (size_t i = 0; i < m->sr.n; i++) {
    sum += m->sr.w[i];
    if (!out) continue;
    memcpy(out->x + 3 * out->n, m->sr.x + 3 * i, 3 * sizeof(double));
    out->w[out->n++] = m->sr.w[i];
  }
  *volume = sum * cell->detA;
cleanup:
  return st;
}

/* The answer of fcm__material_on_face() for the prism made of the nt tets (the tets of one
 * orientation, half-height h) without their moments, where no boundary triangle's box meets
 * the prism's box: then the body fills it or misses it, and one inside test decides. *sure:
 * 1 covered, -1 not, 0 undecided here (a triangle near the prism, or the area within a factor
 * two of atol, where the moments' rounding could decide otherwise). id: the cell, which names
 * the errors. */
static fcm_status prism_clear(fcm_ctx *ctx, fcm__material *m, const double *tets, int nt, double h,
                              double atol, fcm_index id, int *sure)
{
  fcm_status st = FCM_OK;
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  double v = 0.0;
  fcm__embed_cell k;
  int in = 0, first = -1;
  *sure = 0;
  for (int i = 0; i < 4 * nt; i++)
    for (int d = 0; d < 3; d++)
      lo[d] = fmin(lo[d], tets[3 * i + d]), hi[d] = fmax(hi[d], tets[3 * i + d]);
  const double w = 1e-9 * (hi[0] - lo[0] + hi[1] - lo[1] + hi[2] - lo[2]);
  for (int d = 0; d < 3; d++)
    lo[d] -= w, hi[d] += w;
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, m->tree, lo, hi, &m->buf));
  if (m->buf.n > 0) goto cleanup;
  for (int t = 0; t < nt; t++) { /* the tets tets_material() would count */
    fcm__material_tet_cell(tets + 12 * t, id, &k);
    if (!fcm__embed_cell_solid(&k)) continue;
    if (first < 0) first = t;
    v += fabs(k.detA) / 6.0;
  }
  if (first < 0) {
    *sure = -1;
    goto cleanup;
  }
  const double a = v / (2.0 * h);
  if (!(a > 2.0 * atol)) goto cleanup;
  const double z = 0.25;
  fcm__material_tet_cell(tets + 12 * first, id, &k);
  FCM_TRY(ctx, fcm__embed_inside_line(ctx, m->geom, m->tree, &k, 0.25, 0.25, 1, &z, &in, &m->buf,
                                      &m->cr));
  *sure = in != 0 ? 1 : -1; /* -1 inside a tet of negative orientation */
cleanup:
  return st;
}

/* The polygon (n vertices x 3, in place, room for n + 6) clipped to the box lo..hi; its count. */
static int polygon_in_box(double *x, int n, const double lo[3], const double hi[3])
{
  double y[3 * (FCM__POLY_MAX_VERTS + 6)];
  for (int f = 0; f < 6 && n > 0; f++) {
    const int d = f % 3;
    const double s = f < 3 ? 1.0 : -1.0, b = f < 3 ? hi[d] : -lo[d]; /* keep s x_d <= b */
    int k = 0;
    for (int i = 0; i < n; i++) {
      const double *p = x + 3 * i, *q = x + 3 * ((i + 1) % n);
      const double vp = s * p[d] - b, vq = s * q[d] - b;
      if (vp <= 0.0) memcpy(y + 3 * k++, p, 3 * sizeof *p);
      if ((vp <= 0.0) != (vq <= 0.0)) {
        const double t = vp / (vp - vq);
        for (int e = 0; e < 3; e++)
          y[3 * k + e] = p[e] + t * (q[e] - p[e]);
        k++;
      }
    }
    memcpy(x, y, 3 * (size_t)k * sizeof *x);
    n = k;
  }
  return n;
}

/* The squared distance from p to the triangle (a, b, c) (Ericson, Real-Time Collision
 * Detection, 5.1.5: the closest point by the Voronoi regions of the vertices and edges). */
static double tri_dist2(const double p[3], const double a[3], const double b[3], const double c[3])
{
  double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
  for (int d = 0; d < 3; d++)
    ab[d] = b[d] - a[d], ac[d] = c[d] - a[d], ap[d] = p[d] - a[d], bp[d] = p[d] - b[d],
    cp[d] = p[d] - c[d];
  const double d1 = fcm__vec3_dot(ab, ap), d2 = fcm__vec3_dot(ac, ap);
  const double d3 = fcm__vec3_dot(ab, bp), d4 = fcm__vec3_dot(ac, bp);
  const double d5 = fcm__vec3_dot(ab, cp), d6 = fcm__vec3_dot(ac, cp);
  const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  double u = 0.0, v = 0.0; /* q = a + u ab + v ac */
  if (d1 <= 0.0 && d2 <= 0.0)
    u = v = 0.0;
  else if (d3 >= 0.0 && d4 <= d3)
    u = 1.0, v = 0.0;
  else if (d6 >= 0.0 && d5 <= d6)
    u = 0.0, v = 1.0;
  else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
    u = d1 / (d1 - d3), v = 0.0;
  else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
    u = 0.0, v = d2 / (d2 - d6);
  else if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6)); /* on edge bc */
    u = 1.0 - w, v = w;
  } else {
    const double den = 1.0 / (va + vb + vc);
    u = vb * den, v = vc * den;
  }
  for (int d = 0; d < 3; d++)
    q[d] = a[d] + u * ab[d] + v * ac[d] - p[d];
  return fcm__vec3_dot(q, q);
}

/* The area of the planar polygon x (n vertices). */
static double polygon_area(const double *x, int n)
{
  double a[3] = {0.0, 0.0, 0.0};
  for (int i = 1; i + 1 < n; i++) {
    double e1[3], e2[3], t[3];
    for (int d = 0; d < 3; d++)
      e1[d] = x[3 * i + d] - x[d], e2[d] = x[3 * (i + 1) + d] - x[d];
    fcm__vec3_cross(e1, e2, t);
    for (int d = 0; d < 3; d++)
      a[d] += 0.5 * t[d];
  }
  return fcm__vec3_norm(a);
}

/* The area of the polygon x (n vertices) whose prism (half-height h along the unit normal nrm)
 * lies in the box of half-width g about p; y: scratch of n + 6 vertices. */
static double area_in_box(const double *x, int n, const double p[3], double g, const double nrm[3],
                          double h, double *y)
{
  double lo[3], hi[3];
  for (int d = 0; d < 3; d++) {
    const double w = g - h * fabs(nrm[d]);
    if (!(w > 0.0)) return 0.0;
    lo[d] = p[d] - w, hi[d] = p[d] + w;
  }
  memcpy(y, x, 3 * (size_t)n * sizeof *x);
  return polygon_area(y, polygon_in_box(y, n, lo, hi));
}

/* Points tried by prism_near(): the polygon's vertex mean, then its fan triangles'. */
enum { NEAR_POINTS = 4 };

/* Where boundary triangles come near the prism (prism_clear() undecided): about a point p of
 * the polygon, the box inscribed in the ball that reaches the nearest boundary triangle (of
 * those whose boxes meet a box about the polygon; those beyond it are farther than its faces)
 * holds no boundary, so when the body holds p it fills the box, and the prism over the polygon's
 * part whose prism stays in the box is material. Where that part's area is above twice atol the
 * moments would find the overlap covered (their rounding is far below the factor two): *sure = 1.
 * Tried at NEAR_POINTS points; else *sure = 0 (the moments decide). x: the polygon (n vertices),
 * nrm its unit normal, h the prism's half-height. */
static fcm_status prism_near(fcm_ctx *ctx, fcm__material *m, const double *x, int n,
                             const double nrm[3], double h, double atol, fcm_index id, int *sure)
{
  fcm_status st = FCM_OK;
  double c[NEAR_POINTS][3], g[NEAR_POINTS], r = 0.0, lo[3], hi[3];
  double y[3 * (FCM__POLY_MAX_VERTS + 6)];
  const fcm_geometry *G = m->geom;
  *sure = 0;
  if (n > FCM__POLY_MAX_VERTS) return FCM_OK;
  const int np = FCM_MIN(NEAR_POINTS, n - 1);
  memset(c, 0, sizeof c);
  for (int i = 0; i < n; i++)
    for (int d = 0; d < 3; d++)
      c[0][d] += x[3 * i + d] / n;
  for (int j = 1; j < np; j++)
    for (int d = 0; d < 3; d++)
      c[j][d] = (x[d] + x[3 * j + d] + x[3 * (j + 1) + d]) / 3.0;
  for (int i = 0; i < n; i++)
    for (int d = 0; d < 3; d++)
      r = fmax(r, fabs(x[3 * i + d] - c[0][d]) + h);
  for (int d = 0; d < 3; d++)
    lo[d] = c[0][d] - r, hi[d] = c[0][d] + r;
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, m->tree, lo, hi, &m->buf));
  for (int j = 0; j < np; j++) {
    /* the triangles not queried lie farther than the query box's nearest face */
    double q = r;
    for (int d = 0; d < 3; d++)
      q = fmin(q, r - fabs(c[j][d] - c[0][d]));
    double dd = q * q; /* the squared distance to the nearest boundary triangle, at most q^2 */
    for (size_t k = 0; k < m->buf.n; k++) {
      const fcm_index *t = G->tris + 3 * m->buf.ids[k];
      dd = fmin(dd,
                tri_dist2(c[j], G->coords + 3 * t[0], G->coords + 3 * t[1], G->coords + 3 * t[2]));
    }
    /* the box inscribed in the ball of that radius, its rounding (1e-9 of it) left out */
    g[j] = (1.0 - 1e-9) * sqrt(dd / 3.0);
  }
  for (int j = 0; j < np && !*sure; j++) {
    if (!(g[j] > 0.0) || !(area_in_box(x, n, c[j], g[j], nrm, h, y) > 2.0 * atol)) continue;
    double T[12]; /* the body's winding number at c[j]: a small tet with its corner there */
    for (int v = 0; v < 4; v++)
      for (int d = 0; d < 3; d++)
        T[3 * v + d] = c[j][d] + (v == d + 1 ? 0.5 * g[j] : 0.0);
    fcm__embed_cell kc;
    fcm__material_tet_cell(T, id, &kc);
    const double z = 0.0;
    int in = 0;
    FCM_TRY(ctx, fcm__embed_inside_line(ctx, m->geom, m->tree, &kc, 0.0, 0.0, 1, &z, &in, &m->buf,
                                        &m->cr));
    *sure = in != 0;
  }
cleanup:
  return st;
}

int fcm__material_on_face(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                          const double *x, int n, const double nrm[3], double h, double atol)
{
  fcm_status st = FCM_OK;
  double v = 0.0;
  if (n < 3) return 0;
  FCM_TRY(ctx, tets_room(ctx, m, 3 * (n - 2)));
  /* the prism on each fan triangle (p, q, r): three tets of one orientation */
  for (int k = 1; k + 1 < n; k++) {
    const double *c[3] = {x, x + 3 * k, x + 3 * (k + 1)};
    double lo[3][3], up[3][3];
    for (int a = 0; a < 3; a++)
      for (int d = 0; d < 3; d++)
        lo[a][d] = c[a][d] - h * nrm[d], up[a][d] = c[a][d] + h * nrm[d];
    const double *tv[3][4] = {
        {lo[0], lo[1], lo[2], up[0]}, {lo[1], lo[2], up[0], up[1]}, {lo[2], up[0], up[1], up[2]}};
    for (int t = 0; t < 3; t++) {
      double *T = m->tets + 12 * (3 * (k - 1) + t);
      for (int a = 0; a < 4; a++)
        memcpy(T + 3 * a, tv[t][a], 3 * sizeof *T);
      m->vol[3 * (k - 1) + t] = 1.0;
    }
  }
  int sure = 0;
  FCM_TRY(ctx, prism_clear(ctx, m, m->tets, 3 * (n - 2), h, atol, cell->id, &sure));
  if (!sure && m->buf.n > 0) FCM_TRY(ctx, prism_near(ctx, m, x, n, nrm, h, atol, cell->id, &sure));
  if (sure) return sure > 0;
  fcm__embed_cell k;
  if (fcm__embed_prism_cell(x, n, nrm, h, cell->id, &k))
    FCM_TRY(ctx, one_cell_material(ctx, m, &k, &m->q0, &v));
  else
    FCM_TRY(ctx, tets_material(ctx, m, m->tets, m->vol, 3 * (n - 2), &m->q0, cell, NULL, &v));
cleanup:
  if (st != FCM_OK) {
    if (m->st == FCM_OK) m->st = st;
    return 1;
  }
  return fabs(v) / (2.0 * h) > atol;
}

int fcm__embed_overlap_material(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                                const double *a, int na, const double *b, int nb,
                                const double nb_normal[3])
{
  return fcm__embed_overlap_material_full(ctx, m, cell, a, na, b, nb, nb_normal, 0);
}

int fcm__embed_overlap_material_full(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                                     const double *a, int na, const double *b, int nb,
                                     const double nb_normal[3], int full)
{
  const double size = cell->size, atol = FCM__MATERIAL_FACE_AREA_RTOL * size * size;
  double x[3 * FCM__POLY_MAX_VERTS];
  int n = 0;
  fcm__embed_overlap(a, na, b, nb, nb_normal, FCM__EMBED_MATCH_RTOL * size, x, &n);
  if (full && n >= 3 && polygon_area(x, n) > 4.0 * atol) return 1;
  return fcm__material_on_face(ctx, m, cell, x, n, nb_normal, PRISM_RTOL * size, atol);
}

/* Split the parts of Q by the boundary triangles ids (n; all that reach inside the parts), each
 * part only by the triangles that meet it, and drop the pieces outside the body: no boundary
 * triangle crosses them, one point decides. */
static fcm_status body_split(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                             const fcm_index *ids, size_t n, fcm__parts *Q)
{
  fcm_status st = FCM_OK;
  const fcm_geometry *g = m->geom;
  static const unsigned char outer[3] = {0, 0, 0};
  for (size_t k = 0; k < n && Q->n > 0; k++) { /* before m->buf serves the inside tests */
    const fcm_index *tv = g->tris + 3 * ids[k];
    fcm__cut_tri t;
    if (!fcm__embed_cut_tri_setup(g->coords + 3 * tv[0], g->coords + 3 * tv[1],
                                  g->coords + 3 * tv[2], 0, outer, NULL, NULL, &t))
      continue;
    double x[3 * FCM__POLY_MAX_VERTS], work[3 * FCM__POLY_MAX_VERTS];
    const size_t n0 = Q->n;
    for (size_t j = 0; j < n0; j++) {
      for (int a = 0; a < 3; a++)
        memcpy(x + 3 * a, g->coords + 3 * tv[a], 3 * sizeof *x);
      const int m3 = fcm__embed_clip_to_part(Q, j, x, 3, FCM__POLY_MAX_VERTS, t.plane.n, work);
      if (m3 >= 3 || m3 < 0) /* meets the part (or overflowed: split to be safe) */
        FCM_TRY(ctx, fcm__embed_part_split(ctx, cell, &t, Q, j));
    }
    fcm__embed_parts_compact(Q);
  }
  for (size_t i = 0; i < Q->n; i++) {
    fcm__poly *q = Q->poly + i;
    double c[3] = {0.0, 0.0, 0.0}, xi[3], det;
    int in;
    for (int a = 0; a < q->nv; a++)
      for (int d = 0; d < 3; d++)
        c[d] += q->x[a][d] / q->nv;
    FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, c, xi, &det));
    FCM_TRY(ctx, fcm__embed_inside_line(ctx, g, m->tree, cell, xi[0], xi[1], 1, xi + 2, &in,
                                        &m->buf, &m->cr));
    if (in != 1) q->nv = q->nf = 0;
  }
  fcm__embed_parts_compact(Q);
cleanup:
  return st;
}

fcm_status fcm__embed_piece_body_tets(fcm_ctx *ctx, const fcm__embed_cell *cell, fcm__parts *P,
                                      int piece, fcm__embed_ws *ws, double *volume)
{
  fcm_status st = FCM_OK;
  fcm__parts *Q = NULL;
  double lost = 0.0, moved = 0.0; /* not in the statistics */
  fcm_index nslivers = 0;
  *volume = 0.0;
  ws->num_tets = 0;
  FCM_ALLOC(ctx, 1, Q);
  FCM_TRY(ctx, fcm__embed_parts_copy(ctx, P, piece, Q));
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, P->mat->tree, cell->lo, cell->hi, &P->mat->buf));
  FCM_TRY(ctx, body_split(ctx, P->mat, cell, P->mat->buf.ids, P->mat->buf.n, Q));
  /* the tets above their parts' sliver volume; a piece kept for its material (above the
   * pieces' sliver volume) can hold none, when its every tet is below: then all of them */
  for (int slivers = 0; slivers < 2 && ws->num_tets == 0; slivers++)
    for (size_t i = 0; i < Q->n; i++)
      FCM_TRY(ctx, fcm__embed_append_tets(ctx, ws, Q->poly + i, slivers ? 0.0 : Q->vmin[i], volume,
                                          &lost, &moved, &nslivers));
cleanup:
  if (Q) fcm__embed_parts_free(ctx, Q);
  fcm__free(ctx, Q);
  return st;
}

static int cmp_edge(const void *a, const void *b)
{
  const int *p = a, *q = b;
  if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
  return (p[1] > q[1]) - (p[1] < q[1]);
}

static int lump_find(int *uf, int a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return a;
}

/* Whether segment a b meets the inside of the convex part with planes pl (np), farther than
 * tol from its faces: the middle of its clipped share decides (that share is convex). */
static int segment_inside(const double *a, const double *b, const fcm__plane *pl, int np,
                          double tol)
{
  double t0 = 0.0, t1 = 1.0, e[3], x[3];
  for (int d = 0; d < 3; d++)
    e[d] = b[d] - a[d];
  for (int f = 0; f < np && t0 <= t1; f++) {
    const double s0 = fcm__vec3_dot(pl[f].n, a) - pl[f].d, ds = fcm__vec3_dot(pl[f].n, e);
    if (ds == 0.0) {
      if (s0 > 0.0) return 0;
    } else if (ds > 0.0) {
      t1 = fmin(t1, -s0 / ds);
    } else {
      t0 = fmax(t0, -s0 / ds);
    }
  }
  if (!(t0 <= t1)) return 0;
  for (int d = 0; d < 3; d++)
    x[d] = a[d] + 0.5 * (t0 + t1) * e[d];
  for (int f = 0; f < np; f++)
    if (!(fcm__vec3_dot(pl[f].n, x) - pl[f].d < -tol)) return 0;
  return 1;
}

/* Whether the closed segment p q meets triangle (a, b, c) (a relative slack of 1e-9 counts a
 * near miss as a hit). */
static int segment_hits_triangle(const double *p, const double *q, const double *a, const double *b,
                                 const double *c)
{
  const double eps = 1e-9;
  double e1[3], e2[3], dir[3], h[3], sa[3], qv[3];
  for (int d = 0; d < 3; d++)
    e1[d] = b[d] - a[d], e2[d] = c[d] - a[d], dir[d] = q[d] - p[d], sa[d] = p[d] - a[d];
  fcm__vec3_cross(dir, e2, h);
  const double det = fcm__vec3_dot(e1, h);
  if (det == 0.0) return 1; /* parallel: counted as a hit (only costs the split) */
  const double u = fcm__vec3_dot(sa, h) / det;
  if (u < -eps || u > 1.0 + eps) return 0;
  fcm__vec3_cross(sa, e1, qv);
  const double v = fcm__vec3_dot(dir, qv) / det;
  if (v < -eps || u + v > 1.0 + eps) return 0;
  const double t = fcm__vec3_dot(e2, qv) / det;
  return t >= -eps && t <= 1.0 + eps;
}

/* Whether the polyline x[0 .. 3] meets none of the kept triangles but skip0 on its first leg
 * and skip1 on its last. */
static int path_clear(const fcm__material *m, int nk, const double x[4][3], int skip0, int skip1)
{
  const fcm_geometry *g = m->geom;
  for (int t = 0; t < nk; t++) {
    const fcm_index *tv = g->tris + 3 * m->kept[t];
    const double *a = g->coords + 3 * tv[0], *b = g->coords + 3 * tv[1], *c = g->coords + 3 * tv[2];
    for (int l = 0; l < 3; l++) {
      if ((l == 0 && t == skip0) || (l == 2 && t == skip1)) continue;
      if (segment_hits_triangle(x[l], x[l + 1], a, b, c)) return 0;
    }
  }
  return 1;
}

/* Twice the area of boundary triangle t of g. */
static double tri_area2(const fcm_geometry *g, fcm_index t)
{
  const fcm_index *tv = g->tris + 3 * t;
  double u[3], v[3], n[3];
  for (int d = 0; d < 3; d++) {
    u[d] = g->coords[3 * tv[1] + d] - g->coords[3 * tv[0] + d];
    v[d] = g->coords[3 * tv[2] + d] - g->coords[3 * tv[0] + d];
  }
  fcm__vec3_cross(u, v, n);
  return sqrt(fcm__vec3_dot(n, n));
}

/* Join the components of the kept triangles (m->uf) whose material a path inside the body and
 * the part (its planes pl, np of them) links: from a point of one triangle a short step
 * inwards, straight to such a point of the other's, crossing no boundary triangle. Up to 4
 * triangles of each component try. */
static void join_through_body(fcm__material *m, const fcm__plane *pl, int np, int nk, double tol)
{
  enum { TRIES = 4 };
  int *tried = m->edges; /* per component root (the edges are no longer needed) */
  for (int t = 0; t < nk; t++)
    tried[t] = 0;
  for (int s = 0; s < nk; s++) {
    if (tried[lump_find(m->uf, s)]++ >= TRIES) continue;
    for (int t = s + 1; t < nk; t++) {
      if (lump_find(m->uf, s) == lump_find(m->uf, t)) continue;
      double x[4][3];
      const double *cs = m->rep + 6 * s, *ct = m->rep + 6 * t;
      const double hs = 1e-4 * sqrt(tri_area2(m->geom, m->kept[s])),
                   ht = 1e-4 * sqrt(tri_area2(m->geom, m->kept[t]));
      for (int d = 0; d < 3; d++) {
        x[0][d] = cs[d], x[1][d] = cs[d] - hs * cs[3 + d];
        x[3][d] = ct[d], x[2][d] = ct[d] - ht * ct[3 + d];
      }
      if (!(fcm__embed_planes_excess(pl, np, x[1]) < -tol &&
            fcm__embed_planes_excess(pl, np, x[2]) < -tol))
        continue;
      if (path_clear(m, nk, (const double(*)[3])x, s, t))
        m->uf[lump_find(m->uf, s)] = lump_find(m->uf, t);
    }
  }
}

/* Whether part i of P holds at most one lump of the body: the boundary triangles that reach
 * inside it (into m->kept), joined through their shared edges where these do and through
 * paths inside the body (join_through_body()), form at most one component.
 * (Every lump of a part not wholly inside the body is bounded by one of these triangles, and
 * the material along one component of them is one lump.) A false 0 only costs the split. */
static fcm_status one_lump(fcm_ctx *ctx, fcm__material *m, const fcm__embed_cell *cell,
                           const fcm__parts *P, size_t i, const double lo[3], const double hi[3],
                           int *one)
{
  fcm_status st = FCM_OK;
  const fcm_geometry *g = m->geom;
  const double tol = FCM__EMBED_MATCH_RTOL * cell->size;
  fcm__plane pl[FCM__POLY_MAX_FACES];
  const int np = fcm__embed_part_planes(P, i, pl);
  double x[3 * FCM__POLY_MAX_VERTS], work[3 * FCM__POLY_MAX_VERTS];
  *one = 1;
  m->nkept = 0;
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, m->tree, lo, hi, &m->buf));
  if (3 * m->buf.n > m->ecap) {
    void *e = m->edges, *u = m->uf;
    FCM_TRY(ctx, fcm__resize(ctx, &e, 0, 9 * m->buf.n, sizeof(int)));
    m->edges = e;
    FCM_TRY(ctx, fcm__resize(ctx, &u, 0, 3 * m->buf.n, sizeof(int)));
    m->uf = u;
    void *k = m->kept;
    FCM_TRY(ctx, fcm__resize(ctx, &k, 0, 3 * m->buf.n, sizeof(fcm_index)));
    m->kept = k;
    void *r = m->rep;
    FCM_TRY(ctx, fcm__resize(ctx, &r, 0, 18 * m->buf.n, sizeof(double)));
    m->rep = r;
    m->ecap = 3 * m->buf.n;
  }
  int nk = 0, ne = 0; /* triangles reaching inside the part; their edges (a < b, triangle) */
  for (size_t k = 0; k < m->buf.n; k++) {
    const fcm_index *tv = g->tris + 3 * m->buf.ids[k];
    double u[3], v[3], nrm[3], c[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < 3; a++)
      memcpy(x + 3 * a, g->coords + 3 * tv[a], 3 * sizeof *x);
    for (int d = 0; d < 3; d++)
      u[d] = x[3 + d] - x[d], v[d] = x[6 + d] - x[d];
    fcm__vec3_cross(u, v, nrm);
    const int n =
        fcm__embed_clip_to_planes(pl, np, P->tol[i], x, 3, FCM__POLY_MAX_VERTS, nrm, work);
    if (n < 3) continue;
    for (int a = 0; a < n; a++)
      for (int d = 0; d < 3; d++)
        c[d] += x[3 * a + d] / n;
    if (!(fcm__embed_planes_excess(pl, np, c) < -tol)) continue;
    for (int a = 0; a < 3; a++, ne++) {
      const int p = (int)tv[a], q = (int)tv[(a + 1) % 3];
      m->edges[3 * ne] = FCM_MIN(p, q), m->edges[3 * ne + 1] = FCM_MAX(p, q);
      m->edges[3 * ne + 2] = nk;
    }
    const double ln = sqrt(fcm__vec3_dot(nrm, nrm));
    for (int d = 0; d < 3; d++)
      m->rep[6 * nk + d] = c[d], m->rep[6 * nk + 3 + d] = nrm[d] / ln;
    m->uf[nk] = nk;
    m->kept[nk++] = m->buf.ids[k];
  }
  m->nkept = (size_t)nk;
  if (nk < 2) goto cleanup;
  qsort(m->edges, (size_t)ne, 3 * sizeof(int), cmp_edge);
  for (int e = 0; e + 1 < ne; e++) {
    const int *a = m->edges + 3 * e, *b = a + 3;
    if (a[0] != b[0] || a[1] != b[1]) continue;
    if (!segment_inside(g->coords + 3 * (size_t)a[0], g->coords + 3 * (size_t)a[1], pl, np, tol))
      continue;
    m->uf[lump_find(m->uf, a[2])] = lump_find(m->uf, b[2]);
  }
  join_through_body(m, pl, np, nk, tol);
  for (int t = 1; t < nk && *one; t++)
    *one = lump_find(m->uf, t) == lump_find(m->uf, 0);
cleanup:
  return st;
}

fcm_status fcm__embed_split_lumps(fcm_ctx *ctx, const fcm__embed_cell *cell, fcm__parts *P)
{
  fcm_status st = FCM_OK;
  fcm__parts *Q = NULL; /* no material of its own: its parts join through any shared face */
  int *label = NULL, nc;
  if (!P->mat) return FCM_OK;
  const size_t n0 = P->n;
  for (size_t i = 0; i < n0; i++) {
    if (fcm__embed_part_full(P, i)) continue;
    const fcm__poly *p = P->poly + i;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int a = 0; a < p->nv; a++)
      for (int d = 0; d < 3; d++)
        lo[d] = fmin(lo[d], p->x[a][d]), hi[d] = fmax(hi[d], p->x[a][d]);
    int one;
    FCM_TRY(ctx, one_lump(ctx, P->mat, cell, P, i, lo, hi, &one));
    if (one) continue;
    if (!Q) FCM_ALLOC(ctx, 1, Q);
    Q->n = 0;
    FCM_TRY(ctx, fcm__embed_parts_put(ctx, Q, 0, p, P->tol[i], P->vmin[i], 0));
    FCM_TRY(ctx, body_split(ctx, P->mat, cell, P->mat->kept, P->mat->nkept, Q));
    if (Q->n < 2) continue;
    fcm__free(ctx, label);
    label = NULL;
    FCM_ALLOC(ctx, Q->n, label);
    FCM_TRY(ctx, fcm__embed_parts_components(ctx, cell, NULL, 0, Q, label, &nc));
    if (nc < 2) continue;
    /* the lumps' pieces replace the part, each wholly inside the body */
    const double tol = P->tol[i], vmin = P->vmin[i];
    const int parent = P->parent[i];
    for (size_t j = 0; j < Q->n; j++) {
      const size_t slot = j == 0 ? i : P->n;
      FCM_TRY(ctx, fcm__embed_parts_put(ctx, P, slot, Q->poly + j, tol, vmin, parent));
      P->mvol[slot] = fcm__geom_poly_volume(Q->poly + j);
    }
    P->whole = 0;
  }
cleanup:
  if (Q) fcm__embed_parts_free(ctx, Q);
  fcm__free(ctx, Q);
  fcm__free(ctx, label);
  return st;
}

int fcm__embed_part_full(const fcm__parts *P, size_t i)
{
  return P->mvol[i] < 0.0 || P->mvol[i] >= (1.0 - FULL_RTOL) * fcm__geom_poly_volume(P->poly + i);
}

int fcm__embed_part_face_full(const fcm__parts *P, size_t i, const double nrm[3], double size)
{
  return fcm__embed_part_face_deep(P, i, fcm__embed_part_full(P, i), nrm, size);
}

int fcm__embed_part_face_deep(const fcm__parts *P, size_t i, int full, const double nrm[3],
                              double size)
{
  if (!full) return 0;
  const fcm__poly *p = P->poly + i;
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (int a = 0; a < p->nv; a++) {
    const double s = fcm__vec3_dot(nrm, p->x[a]);
    lo = fmin(lo, s), hi = fmax(hi, s);
  }
  return hi - lo >= 4.0 * PRISM_RTOL * size;
}

fcm_status fcm__embed_drop_dry(fcm_ctx *ctx, const fcm__embed_cell *cell, fcm__parts *P,
                               double *whole_mvol)
{
  fcm_status st = FCM_OK;
  if (!P->mat) return FCM_OK;
  for (size_t i = 0; i < P->n; i++) {
    if (P->mvol[i] != 0.0) { /* known; or a piece of a part wholly inside the body */
      if (P->mvol[i] < 0.0) P->mvol[i] = fcm__geom_poly_volume(P->poly + i);
      continue;
    }
    if (P->whole && whole_mvol && !isnan(*whole_mvol))
      P->mvol[i] = *whole_mvol; /* measured so at an earlier cut */
    else if (P->whole && cell->affine)
      FCM_TRY(ctx, fcm__material_cell(ctx, P->mat, NULL, cell, NULL, P->mvol + i));
    else
      FCM_TRY(ctx, fcm__material_poly(ctx, P->mat, P->poly + i, NULL, cell, NULL, P->mvol + i));
    if (P->whole && whole_mvol) *whole_mvol = P->mvol[i];
    if (!(P->mvol[i] > P->vmin[i])) P->poly[i].nv = P->poly[i].nf = 0;
  }
  fcm__embed_parts_compact(P);
cleanup:
  return st;
}
