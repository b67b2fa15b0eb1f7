/* Octree refinement along triangle surfaces: the cells an embedded geometry's boundary or a
 * cut surface crosses, as refine callbacks of fcm_mesh_create_octree(). */
#include "geom_impl.h"
#include "surface_impl.h"

#include <math.h>

/* Whether the triangle v (3 x 3, relative to the box centre) meets the closed box of half
 * sizes h: no separating axis among the box axes, the triangle's normal and the nine cross
 * products of box axes and triangle edges (Akenine-Moeller's test). */
static int triangle_meets_box(double v[3][3], const double h[3])
{
  for (int d = 0; d < 3; d++) {
    const double lo = fmin(v[0][d], fmin(v[1][d], v[2][d]));
    const double hi = fmax(v[0][d], fmax(v[1][d], v[2][d]));
    if (lo > h[d] || hi < -h[d]) return 0;
  }
  double e[3][3];
  for (int k = 0; k < 3; k++)
    for (int d = 0; d < 3; d++)
      e[k][d] = v[(k + 1) % 3][d] - v[k][d];
  double axes[10][3];
  axes[0][0] = e[0][1] * e[1][2] - e[0][2] * e[1][1]; /* normal */
  axes[0][1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
  axes[0][2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
  for (int k = 0; k < 3; k++)
    for (int d = 0; d < 3; d++) { /* unit vector u_d x e_k */
      double *a = axes[1 + 3 * k + d];
      a[d] = 0.0;
      a[(d + 1) % 3] = -e[k][(d + 2) % 3];
      a[(d + 2) % 3] = e[k][(d + 1) % 3];
    }
  for (int i = 0; i < 10; i++) {
    const double *a = axes[i];
    const double r = h[0] * fabs(a[0]) + h[1] * fabs(a[1]) + h[2] * fabs(a[2]);
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (int k = 0; k < 3; k++) {
      const double p = a[0] * v[k][0] + a[1] * v[k][1] + a[2] * v[k][2];
      lo = fmin(lo, p), hi = fmax(hi, p);
    }
    if (lo > r || hi < -r) return 0;
  }
  return 1;
}

/* Whether triangle t (vertex ids into coords) meets the closed box of centre c, half sizes h. */
static int triangle_id_meets_box(const double *coords, const fcm_index *t, const double c[3],
                                 const double h[3])
{
  double v[3][3];
  for (int k = 0; k < 3; k++)
    for (int d = 0; d < 3; d++)
      v[k][d] = coords[3 * t[k] + d] - c[d];
  return triangle_meets_box(v, h);
}

int fcm_geometry_boundary_meets_box(const double lo[3], const double hi[3], int level,
                                    void *geometry)
{
  const fcm_geometry *g = geometry;
  const fcm_aabb_tree *tree = NULL;
  fcm__idbuf buf = {NULL, 0, 0};
  int meets = 0;
  (void)level;
  if (!g || !lo || !hi) return -1;
  if (fcm__geom_tree(g->ctx, g, 1, &tree) != FCM_OK) return -1;
  if (fcm__geom_tree_query(g->ctx, tree, lo, hi, &buf) != FCM_OK) {
    fcm__geom_idbuf_free(g->ctx, &buf);
    return -1;
  }
  double c[3], h[3];
  for (int d = 0; d < 3; d++)
    c[d] = 0.5 * (lo[d] + hi[d]), h[d] = 0.5 * (hi[d] - lo[d]);
  for (size_t i = 0; i < buf.n && !meets; i++)
    meets = triangle_id_meets_box(g->coords, g->tris + 3 * buf.ids[i], c, h);
  fcm__geom_idbuf_free(g->ctx, &buf);
  return meets;
}

int fcm_surface_meets_box(const double lo[3], const double hi[3], int level, void *surface)
{
  const fcm_surface *s = surface;
  (void)level;
  if (!s || !lo || !hi) return -1;
  double c[3], h[3];
  for (int d = 0; d < 3; d++) {
    if (s->lo[d] > hi[d] || s->hi[d] < lo[d]) return 0;
    c[d] = 0.5 * (lo[d] + hi[d]), h[d] = 0.5 * (hi[d] - lo[d]);
  }
  for (fcm_index i = 0; i < s->num_triangles; i++)
    if (triangle_id_meets_box(s->coords, s->tris + 3 * i, c, h)) return 1;
  return 0;
}
