/* Convex polyhedron and polygon clipping by half-spaces with one classification per
 * vertex and plane, and fan tetrahedralization of the result.
 *
 * Longva et al. 2020, Sec. 4.5: the intersection of a convex embedded cell with a
 * convex background cell is clipped plane by plane; each vertex is classified against
 * a plane once (with a tolerance relative to the cell size) and that sign decides every
 * face it belongs to, so neighbouring faces agree on the topology. New vertices are
 * made only on edges with ends strictly on opposite sides, hence t = s_a / (s_a - s_b)
 * is well conditioned. The cap face is bounded by the kept faces' edges on the plane,
 * chained into cycles. */
#include "geom/geom_impl.h"
#include "la/vec3.h"

#include <float.h>
#include <math.h>
#include <string.h>

void fcm__geom_poly_from_cell(fcm_element_type type, const double *X, fcm__poly *p)
{
  fcm__geom_poly_from_cell_shape(type, X, p);
  fcm__geom_cell_planes(fcm_element_get_info(type), X, p->fp);
}

void fcm__geom_poly_from_cell_shape(fcm_element_type type, const double *X, fcm__poly *p)
{
  const fcm_element_info *info = fcm_element_get_info(type);
  p->nv = info->num_corners;
  for (int a = 0; a < p->nv; a++)
    for (int d = 0; d < 3; d++)
      p->x[a][d] = X[3 * a + d];
  p->nf = info->num_faces;
  for (int f = 0; f < p->nf; f++) {
    p->fn[f] = info->face_num_corners[f];
    for (int k = 0; k < p->fn[f]; k++)
      p->fv[f][k] = info->face_nodes[f][k];
  }
}

int fcm__geom_cell_planes(const fcm_element_info *info, const double *X, fcm__plane *planes)
{
  for (int f = 0; f < info->num_faces; f++) {
    const int nc = info->face_num_corners[f];
    double n[3] = {0, 0, 0}, c[3] = {0, 0, 0};
    for (int k = 0; k < nc; k++) {
      const double *a = X + 3 * info->face_nodes[f][k];
      const double *b = X + 3 * info->face_nodes[f][(k + 1) % nc];
      n[0] += (a[1] - b[1]) * (a[2] + b[2]); /* Newell's method */
      n[1] += (a[2] - b[2]) * (a[0] + b[0]);
      n[2] += (a[0] - b[0]) * (a[1] + b[1]);
      for (int d = 0; d < 3; d++)
        c[d] += a[d] / nc;
    }
    const double len = sqrt(fcm__vec3_dot(n, n));
    fcm__plane *pl = planes + f;
    if (len > 0.0) {
      for (int d = 0; d < 3; d++)
        pl->n[d] = n[d] / len;
      pl->d = fcm__vec3_dot(pl->n, c);
    } else {
      pl->n[0] = pl->n[1] = pl->n[2] = 0.0;
      pl->d = 0.0;
    }
  }
  return info->num_faces;
}

/* Find or make the vertex on edge (a, b) of the input; cache entries are (min, max, id). */
static int edge_vertex(const fcm__poly *in, const double *s, int a, int b, int (*cache)[3],
                       int *ncache, fcm__poly *out)
{
  const int lo = a < b ? a : b, hi = a < b ? b : a;
  for (int k = 0; k < *ncache; k++)
    if (cache[k][0] == lo && cache[k][1] == hi) return cache[k][2];
  if (out->nv >= FCM__POLY_MAX_VERTS || *ncache >= FCM__POLY_MAX_VERTS) return -1;
  /* Interpolate from the lower-index end so both faces get the same point. */
  const double t = s[lo] / (s[lo] - s[hi]);
  const int id = out->nv++;
  for (int d = 0; d < 3; d++)
    out->x[id][d] = in->x[lo][d] + t * (in->x[hi][d] - in->x[lo][d]);
  cache[*ncache][0] = lo, cache[*ncache][1] = hi, cache[*ncache][2] = id;
  (*ncache)++;
  return id;
}

/* Order the on-plane vertices `ids` (k of them) counter-clockwise around n: the cap of a
 * convex part whose boundary edges could not be chained. */
static void sort_cap(const fcm__poly *p, const double n[3], int *ids, int k)
{
  double c[3] = {0, 0, 0}, u[3], v[3], ang[FCM__POLY_MAX_VERTS];
  for (int i = 0; i < k; i++)
    for (int d = 0; d < 3; d++)
      c[d] += p->x[ids[i]][d] / k;
  /* u: any unit vector orthogonal to n; v = n x u. */
  const double ax[3] = {fabs(n[0]) < 0.6 ? 1.0 : 0.0, fabs(n[0]) < 0.6 ? 0.0 : 1.0, 0.0};
  fcm__vec3_cross(n, ax, u);
  const double lu = sqrt(fcm__vec3_dot(u, u));
  for (int d = 0; d < 3; d++)
    u[d] /= lu;
  fcm__vec3_cross(n, u, v);
  for (int i = 0; i < k; i++) {
    double r[3];
    for (int d = 0; d < 3; d++)
      r[d] = p->x[ids[i]][d] - c[d];
    ang[i] = atan2(fcm__vec3_dot(r, v), fcm__vec3_dot(r, u));
  }
  for (int i = 1; i < k; i++) { /* insertion sort: k is small */
    const double a = ang[i];
    const int id = ids[i];
    int j = i;
    while (j > 0 && (ang[j - 1] > a || (ang[j - 1] == a && ids[j - 1] > id))) {
      ang[j] = ang[j - 1], ids[j] = ids[j - 1];
      j--;
    }
    ang[j] = a, ids[j] = id;
  }
}

/* Rotate the cycle ids (k vertices) to start at its lexicographically smallest vertex: the
 * two halves of a split share the cap's vertices bitwise and traverse them in opposite
 * directions; starting both at the same vertex gives both the same fan triangles, so their
 * volumes add up exactly even where vertices within the tolerance of the plane make the cap
 * slightly non-planar. */
static void start_at_smallest(const fcm__poly *p, int *ids, int k)
{
  int first = 0;
  for (int i = 1; i < k; i++) {
    const double *a = p->x[ids[i]], *b = p->x[ids[first]];
    if (a[0] < b[0] || (a[0] == b[0] && (a[1] < b[1] || (a[1] == b[1] && a[2] < b[2])))) first = i;
  }
  int rot[FCM__POLY_MAX_VERTS];
  for (int i = 0; i < k; i++)
    rot[i] = ids[(first + i) % k];
  memcpy(ids, rot, (size_t)k * sizeof *ids);
}

#define CAP_EDGES (4 * FCM__POLY_MAX_VERTS)

/* The cap's boundary as cycles of output vertices, counter-clockwise seen from outside the
 * kept part: every edge of the first nf faces of `out` with both ends on the plane (on[]) is
 * an edge of the cap, traversed the other way. Chaining these edges instead of sorting the
 * on-plane vertices by angle keeps the cap right where the tolerances left the part
 * slightly non-convex (a flat flap on a cut lying over the part's face). The kept faces that
 * lie on the plane count too: their edges, reversed, cancel the others' along them, so the
 * cap covers what those faces do not (nothing when one of them is the whole cross-section).
 * The closed walks are split where they touch themselves; walks of two vertices (no area)
 * are dropped. cyc gets the cycles one after another, len
 * their lengths. Returns their count, or -1 when the edges do not chain (a vertex with more
 * edges in than out, or too many edges). */
static int cap_cycles(const fcm__poly *out, int nf, const unsigned char *on, int *cyc, int *len)
{
  int from[CAP_EDGES], to[CAP_EDGES], ne = 0, deg[FCM__POLY_MAX_VERTS] = {0};
  unsigned char used[CAP_EDGES] = {0};
  for (int f = 0; f < nf; f++)
    for (int j = 0; j < out->fn[f]; j++) {
      const int u = out->fv[f][j], v = out->fv[f][(j + 1) % out->fn[f]];
      if (!on[u] || !on[v]) continue;
      if (ne == CAP_EDGES) return -1;
      from[ne] = v, to[ne] = u, ne++;
      deg[v]++, deg[u]--;
    }
  for (int i = 0; i < out->nv; i++)
    if (deg[i] != 0) return -1;
  /* an edge and its reverse (an edge of a kept face lying on the plane, or an edge on the
   * plane that both its faces keep) bound no area: both go */
  for (int a = 0; a < ne; a++)
    for (int b = a + 1; b < ne && !used[a]; b++)
      if (!used[b] && from[b] == to[a] && to[b] == from[a]) used[a] = used[b] = 1;
  int ncyc = 0, total = 0, walk[CAP_EDGES + 1];
  for (int e0 = 0; e0 < ne; e0++) {
    if (used[e0]) continue;
    int n = 0, e = e0;
    walk[n++] = from[e0];
    for (;;) {
      used[e] = 1;
      const int v = to[e];
      int at = -1; /* where the walk was at v before */
      for (int k = 0; k < n && at < 0; k++)
        if (walk[k] == v) at = k;
      if (at >= 0) {
        if (n - at >= 3) {
          memcpy(cyc + total, walk + at, (size_t)(n - at) * sizeof *walk);
          len[ncyc++] = n - at, total += n - at;
        }
        n = at + 1;
        if (at == 0) break;
      } else {
        walk[n++] = v;
      }
      e = -1;
      for (int k = 0; k < ne && e < 0; k++)
        if (!used[k] && from[k] == v) e = k;
      if (e < 0) return -1;
    }
  }
  return ncyc;
}

/* Append the cap cycle ids (k vertices) of plane pl to out as one face, or as its fan
 * triangles when a vertex of it was taken as on the plane but lies off it beyond rounding
 * (off[]): such a cap is not quite planar, and its planar triangles let a later split cut
 * every face into pieces that add up to it exactly; the two halves of this split get the
 * same triangles (start_at_smallest). Returns -1 on overflow. */
static int store_cap(fcm__poly *out, const fcm__plane *pl, int *ids, int k,
                     const unsigned char *off)
{
  int bent = 0;
  for (int j = 0; j < k; j++)
    bent |= off[ids[j]];
  start_at_smallest(out, ids, k);
  const int ntri = bent ? k - 2 : 1;
  if (k > FCM__POLY_MAX_FV || out->nf + ntri > FCM__POLY_MAX_FACES) return -1;
  for (int j = 0; j < ntri; j++) {
    if (ntri > 1) {
      out->fn[out->nf] = 3;
      out->fv[out->nf][0] = ids[0];
      out->fv[out->nf][1] = ids[j + 1];
      out->fv[out->nf][2] = ids[j + 2];
    } else {
      out->fn[out->nf] = k;
      memcpy(out->fv[out->nf], ids, (size_t)k * sizeof ids[0]);
    }
    out->fp[out->nf] = *pl;
    out->nf++;
  }
  return 0;
}

void fcm__geom_poly_copy(fcm__poly *dst, const fcm__poly *src)
{
  dst->nv = src->nv, dst->nf = src->nf;
  memcpy(dst->x, src->x, (size_t)src->nv * sizeof src->x[0]);
  for (int f = 0; f < src->nf; f++) {
    dst->fn[f] = src->fn[f];
    memcpy(dst->fv[f], src->fv[f], (size_t)src->fn[f] * sizeof src->fv[f][0]);
  }
  memcpy(dst->fp, src->fp, (size_t)src->nf * sizeof src->fp[0]);
}

int fcm__geom_poly_clip(fcm__poly *p, const fcm__plane *pl, double tol, fcm__poly *out)
{
  double s[FCM__POLY_MAX_VERTS];
  int sg[FCM__POLY_MAX_VERTS], newid[FCM__POLY_MAX_VERTS], cache[FCM__POLY_MAX_VERTS][3];
  int ncache = 0, any_in = 0, any_out = 0, cap_face = 0;
  unsigned char on[FCM__POLY_MAX_VERTS]; /* by output vertex: on the plane */
  if (p->nf == 0) return 0;
  if (pl->n[0] == 0.0 && pl->n[1] == 0.0 && pl->n[2] == 0.0) return 0;
  for (int i = 0; i < p->nv; i++) {
    s[i] = fcm__vec3_dot(pl->n, p->x[i]) - pl->d;
    sg[i] = s[i] > tol ? 1 : (s[i] < -tol ? -1 : 0);
    any_out |= sg[i] > 0;
    any_in |= sg[i] < 0;
  }
  if (!any_out) return 0; /* entirely inside (on-plane vertices kept) */
  if (!any_in) {          /* outside, or flat on the plane */
    p->nv = p->nf = 0;
    return 0;
  }
  out->nv = out->nf = 0;
  for (int i = 0; i < p->nv; i++) {
    newid[i] = -1;
    if (sg[i] <= 0) {
      newid[i] = out->nv++;
      memcpy(out->x[newid[i]], p->x[i], sizeof out->x[0]);
      on[newid[i]] = sg[i] == 0;
    }
  }
  for (int f = 0; f < p->nf; f++) {
    const int fn = p->fn[f];
    int cyc[FCM__POLY_MAX_FV], nc = 0, all_on = 1, inside = 0;
    for (int k = 0; k < fn; k++) {
      const int a = p->fv[f][k], b = p->fv[f][(k + 1) % fn];
      all_on &= sg[a] == 0;
      inside |= sg[a] < 0;
      if (sg[a] <= 0) {
        if (nc >= FCM__POLY_MAX_FV) goto overflow;
        cyc[nc++] = newid[a];
      }
      if (sg[a] * sg[b] < 0) {
        const int e = edge_vertex(p, s, a, b, cache, &ncache, out);
        if (e < 0 || nc >= FCM__POLY_MAX_FV) goto overflow;
        on[e] = 1;
        cyc[nc++] = e;
      }
    }
    cap_face |= all_on; /* kept: its edges close the cap's edges on it */
    /* a face with vertices outside and none inside keeps only on-plane vertices: what is
     * left of it lies in the cap (kept, it would be a second face on the cap's vertices) */
    if (!all_on && !inside) continue;
    if (nc >= 3) {
      if (out->nf >= FCM__POLY_MAX_FACES) goto overflow;
      out->fn[out->nf] = nc;
      memcpy(out->fv[out->nf], cyc, (size_t)nc * sizeof cyc[0]);
      out->fp[out->nf] = p->fp[f];
      out->nf++;
    }
  }
  const int nfaces_kept = out->nf;
  {
    double scale = fabs(pl->d);
    for (int i = 0; i < p->nv; i++)
      for (int d = 0; d < 3; d++)
        scale = fmax(scale, fabs(p->x[i][d]));
    /* off[id]: a kept vertex taken as on the plane within the tolerance but off it beyond
     * rounding */
    unsigned char off[FCM__POLY_MAX_VERTS] = {0};
    for (int i = 0; i < p->nv; i++)
      if (sg[i] == 0) off[newid[i]] = fabs(s[i]) > 16.0 * DBL_EPSILON * scale;
    int cyc[CAP_EDGES], len[CAP_EDGES];
    const int ncyc = cap_cycles(out, nfaces_kept, on, cyc, len);
    if (ncyc >= 0) {
      for (int c = 0, at = 0; c < ncyc; at += len[c++])
        if (store_cap(out, pl, cyc + at, len[c], off) < 0) goto overflow;
    } else if (!cap_face) {
      /* edges that do not chain into cycles (a part the tolerances left out of shape): the
       * on-plane vertices ordered by angle, the cap of the convex part it should be */
      int ids[FCM__POLY_MAX_VERTS], k = 0;
      for (int id = 0; id < out->nv; id++)
        if (on[id]) ids[k++] = id;
      if (k >= 3) {
        sort_cap(out, pl->n, ids, k);
        if (store_cap(out, pl, ids, k, off) < 0) goto overflow;
      }
    }
  }
  if (out->nf < 4) out->nv = out->nf = 0; /* fewer than 4 faces: no volume */
  fcm__geom_poly_copy(p, out);
  return 0;
overflow:
  p->nv = p->nf = 0;
  return -1;
}

int fcm__geom_poly_num_tets(const fcm__poly *p)
{
  int n = 0;
  for (int f = 0; f < p->nf; f++)
    n += p->fn[f] - 2;
  return n;
}

/* The fan of p's face triangles (each face fanned from its first vertex) from apex c, skipping
 * the triangles that have vertex `skip` (-1: none) as a corner: their tets have no volume.
 * Writes the tets and signed volumes (when tets is not NULL); returns their count, and in
 * *neg the sum of the negative volumes. */
static int fan_tets(const fcm__poly *p, const double c[3], int skip, double *tets, double *vol,
                    double *neg)
{
  int nt = 0;
  *neg = 0.0;
  for (int f = 0; f < p->nf; f++) {
    const int ia = p->fv[f][0];
    const double *a = p->x[ia];
    for (int k = 1; k + 1 < p->fn[f]; k++) {
      const int ib = p->fv[f][k], ie = p->fv[f][k + 1];
      if (ia == skip || ib == skip || ie == skip) continue;
      const double *b = p->x[ib], *e = p->x[ie];
      double ra[3], rb[3], re[3], cr[3];
      for (int d = 0; d < 3; d++)
        ra[d] = a[d] - c[d], rb[d] = b[d] - c[d], re[d] = e[d] - c[d];
      fcm__vec3_cross(ra, rb, cr);
      const double v = fcm__vec3_dot(cr, re) / 6.0;
      if (v < 0.0) *neg += v;
      if (tets) {
        double *t = tets + 12 * nt;
        for (int d = 0; d < 3; d++)
          t[d] = c[d], t[3 + d] = a[d], t[6 + d] = b[d], t[9 + d] = e[d];
        vol[nt] = v;
      }
      nt++;
    }
  }
  return nt;
}

int fcm__geom_poly_tets(const fcm__poly *p, double *tets, double *vol)
{
  double c[3] = {0, 0, 0}, neg;
  if (p->nf == 0) return 0;
  for (int i = 0; i < p->nv; i++)
    for (int d = 0; d < 3; d++)
      c[d] += p->x[i][d];
  for (int d = 0; d < 3; d++)
    c[d] /= p->nv;
  const int nt = fan_tets(p, c, -1, tets, vol, &neg);
  double total = 0.0;
  for (int k = 0; k < nt; k++)
    total += fabs(vol[k]);
  if (neg >= -64.0 * DBL_EPSILON * total) return nt; /* none beyond rounding */
  /* A part that the tolerances left slightly non-convex (vertices within the tolerance of a
   * plane taken as on it: a sliver whose faces are not quite planar) can give tets of
   * negative volume from its centroid. Every apex gives the same total (the faces' triangles
   * are the same), so take the vertex whose fan has the least negative volume, none if it can. */
  int best = -1;
  double best_neg = neg;
  for (int a = 0; a < p->nv && best_neg < 0.0; a++) {
    fan_tets(p, p->x[a], a, NULL, NULL, &neg);
    if (neg > best_neg) best = a, best_neg = neg;
  }
  if (best < 0) return nt;
  return fan_tets(p, p->x[best], best, tets, vol, &neg);
}

double fcm__geom_poly_volume(const fcm__poly *p)
{
  double c[3] = {0, 0, 0}, v = 0.0;
  if (p->nf == 0) return 0.0;
  for (int i = 0; i < p->nv; i++)
    for (int d = 0; d < 3; d++)
      c[d] += p->x[i][d] / p->nv;
  for (int f = 0; f < p->nf; f++) {
    const double *a = p->x[p->fv[f][0]];
    for (int k = 1; k + 1 < p->fn[f]; k++) {
      const double *b = p->x[p->fv[f][k]], *e = p->x[p->fv[f][k + 1]];
      double ra[3], rb[3], re[3], cr[3];
      for (int d = 0; d < 3; d++)
        ra[d] = a[d] - c[d], rb[d] = b[d] - c[d], re[d] = e[d] - c[d];
      fcm__vec3_cross(ra, rb, cr);
      v += fcm__vec3_dot(cr, re) / 6.0;
    }
  }
  return v;
}

int fcm__geom_polygon_clip(double *x, int n, int cap, const fcm__plane *pl, double tol,
                           int keep_coplanar, double *work)
{
  double s[FCM__POLY_MAX_VERTS];
  int sg[FCM__POLY_MAX_VERTS], any_in = 0, any_out = 0, m = 0;
  if (n < 3) return 0;
  if (n > FCM__POLY_MAX_VERTS) return -1;
  if (pl->n[0] == 0.0 && pl->n[1] == 0.0 && pl->n[2] == 0.0) return n;
  for (int i = 0; i < n; i++) {
    s[i] = fcm__vec3_dot(pl->n, x + 3 * i) - pl->d;
    sg[i] = s[i] > tol ? 1 : (s[i] < -tol ? -1 : 0);
    any_out |= sg[i] > 0;
    any_in |= sg[i] < 0;
  }
  if (!any_out && !any_in) return keep_coplanar ? n : 0;
  if (!any_out) return n;
  if (!any_in) return 0;
  for (int i = 0; i < n; i++) {
    const int j = (i + 1) % n;
    if (sg[i] <= 0) {
      if (m >= cap) return -1;
      memcpy(work + 3 * m++, x + 3 * i, 3 * sizeof *x);
    }
    if (sg[i] * sg[j] < 0) {
      /* Interpolate from the lower-index end, as fcm__geom_poly_clip does. */
      const int lo = i < j ? i : j, hi = i < j ? j : i;
      const double t = s[lo] / (s[lo] - s[hi]);
      if (m >= cap) return -1;
      for (int d = 0; d < 3; d++)
        work[3 * m + d] = x[3 * lo + d] + t * (x[3 * hi + d] - x[3 * lo + d]);
      m++;
    }
  }
  if (m < 3) return 0;
  memcpy(x, work, (size_t)(3 * m) * sizeof *x);
  return m;
}
