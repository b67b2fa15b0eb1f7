/* Triangle surface meshes: creation from arrays, the shared builder (growing vertex and
 * triangle arrays, fan triangulation, exact-coordinate vertex merging) and the
 * dispatch by file extension. The format readers are in surface_read.c. */
#include "geom/surface_impl.h"

#include <math.h>
#include <string.h>

/* ---- builder ---- */

static fcm_status grow(fcm_ctx *ctx, void **p, size_t *cap, size_t need, size_t size)
{
  fcm_status st = FCM_OK;
  if (need <= *cap) return FCM_OK;
  size_t ncap = *cap ? *cap : 64;
  while (ncap < need)
    ncap *= 2;
  FCM_TRY(ctx, fcm__resize(ctx, p, *cap, ncap, size));
  *cap = ncap;
cleanup:
  return st;
}

fcm_status fcm__sbuild_vertex(fcm__sbuild *B, const double p[3])
{
  fcm_status st = FCM_OK;
  for (int k = 0; k < 3; k++) {
    if (fabs(p[k]) <= FCM__COORD_MAX) continue;
    if (B->soup)
      FCM_CHECK(0, B->ctx, FCM_ERR_FORMAT,
                "surface: %s: facet %zu (counted from 0), corner %zu: coordinate %c = %g is "
                "outside " FCM__COORD_RANGE,
                B->path, B->nv / 3, B->nv % 3, "xyz"[k], p[k]);
    FCM_CHECK(0, B->ctx, FCM_ERR_FORMAT,
              "surface: %s: vertex %zu (%d-based, as the file's faces number them): coordinate "
              "%c = %g is outside " FCM__COORD_RANGE,
              B->path, B->nv + (size_t)B->base, B->base, "xyz"[k], p[k]);
  }
  FCM_TRY(B->ctx, grow(B->ctx, (void **)&B->x, &B->capv, B->nv + 1, 3 * sizeof(double)));
  for (int k = 0; k < 3; k++)
    B->x[3 * B->nv + (size_t)k] = p[k];
  B->nv++;
cleanup:
  return st;
}

fcm_status fcm__sbuild_triangle(fcm__sbuild *B, fcm_index a, fcm_index b, fcm_index c)
{
  fcm_status st = FCM_OK;
  FCM_TRY(B->ctx, grow(B->ctx, (void **)&B->t, &B->capt, B->nt + 1, 3 * sizeof(fcm_index)));
  B->t[3 * B->nt] = a, B->t[3 * B->nt + 1] = b, B->t[3 * B->nt + 2] = c;
  B->nt++;
cleanup:
  return st;
}

static uint64_t hash_point(const double p[3])
{
  uint64_t h = 1469598103934665603ull;
  for (int k = 0; k < 3; k++) {
    double v = p[k] + 0.0; /* -0.0 and 0.0 are equal: hash them alike */
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    h = (h ^ u) * 1099511628211ull;
    h ^= h >> 29;
  }
  return h;
}

/* Merge equal vertices of an STL-style soup: B->x holds 3 vertices per triangle. */
fcm_status fcm__sbuild_merge(fcm__sbuild *B)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  size_t cap = 16, n = B->nv, m = 0;
  fcm_index *slot = NULL, *map = NULL;
  while (cap < 2 * n)
    cap *= 2;
  FCM_ALLOC_RAW(ctx, cap, slot);
  FCM_ALLOC_RAW(ctx, n ? n : 1, map);
  for (size_t i = 0; i < cap; i++)
    slot[i] = -1;
  for (size_t i = 0; i < n; i++) {
    const double *p = B->x + 3 * i;
    size_t h = (size_t)hash_point(p) & (cap - 1);
    while (slot[h] >= 0) {
      const double *q = B->x + 3 * (size_t)slot[h];
      if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) break;
      h = (h + 1) & (cap - 1);
    }
    if (slot[h] < 0) { /* new vertex: compact in place (m <= i) */
      memmove(B->x + 3 * m, p, 3 * sizeof(double));
      slot[h] = (fcm_index)m++;
    }
    map[i] = slot[h];
  }
  for (size_t i = 0; i < 3 * B->nt; i++)
    B->t[i] = map[B->t[i]];
  B->nv = m;
cleanup:
  FCM_FREE(ctx, slot);
  FCM_FREE(ctx, map);
  return st;
}

void fcm__sbuild_free(fcm__sbuild *B)
{
  FCM_FREE(B->ctx, B->x);
  FCM_FREE(B->ctx, B->t);
  B->nv = B->nt = B->capv = B->capt = 0;
}

/* ---- the surface ---- */

static fcm_status surface_new(fcm_ctx *ctx, fcm_index nv, const double *coords, fcm_index nt,
                              const fcm_index *tris, fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  fcm_surface *s = NULL;
  FCM_ALLOC(ctx, 1, s);
  s->ctx = ctx;
  FCM_ALLOC_RAW(ctx, 3 * (size_t)nv, s->coords);
  FCM_ALLOC_RAW(ctx, 3 * (size_t)nt, s->tris);
  memcpy(s->coords, coords, 3 * (size_t)nv * sizeof(double));
  memcpy(s->tris, tris, 3 * (size_t)nt * sizeof(fcm_index));
  s->num_vertices = nv, s->num_triangles = nt;
  for (int k = 0; k < 3; k++)
    s->lo[k] = INFINITY, s->hi[k] = -INFINITY;
  for (fcm_index i = 0; i < nv; i++)
    for (int k = 0; k < 3; k++) {
      double v = coords[3 * i + k];
      if (v < s->lo[k]) s->lo[k] = v;
      if (v > s->hi[k]) s->hi[k] = v;
    }
  *surf = s;
  s = NULL;
cleanup:
  fcm_surface_destroy(&s);
  return st;
}

fcm_status fcm_surface_create(fcm_ctx *ctx, fcm_index num_vertices, const double *coords,
                              fcm_index num_triangles, const fcm_index *tris, fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(surf, ctx, FCM_ERR_ARG, "surface: output pointer is NULL");
  *surf = NULL;
  FCM_CHECK(ctx && coords && tris, ctx, FCM_ERR_ARG,
            "surface: NULL argument (ctx, coords and tris are required)");
  FCM_CHECK(num_vertices > 0 && num_triangles > 0, ctx, FCM_ERR_ARG,
            "surface: %lld vertices and %lld triangles (both must be > 0)", (long long)num_vertices,
            (long long)num_triangles);
  for (fcm_index i = 0; i < 3 * num_vertices; i++)
    FCM_CHECK(fabs(coords[i]) <= FCM__COORD_MAX, ctx, FCM_ERR_ARG,
              "surface: coordinate %d of vertex %lld (0-based) is %g, outside " FCM__COORD_RANGE,
              (int)(i % 3), (long long)(i / 3), coords[i]);
  for (fcm_index i = 0; i < 3 * num_triangles; i++)
    FCM_CHECK(tris[i] >= 0 && tris[i] < num_vertices, ctx, FCM_ERR_ARG,
              "surface: triangle %lld has vertex id %lld outside [0, %lld)", (long long)(i / 3),
              (long long)tris[i], (long long)num_vertices);
  FCM_TRY(ctx, surface_new(ctx, num_vertices, coords, num_triangles, tris, surf));
cleanup:
  return st;
}

static int ext_is(const char *path, const char *ext)
{
  size_t n = strlen(path), e = strlen(ext);
  if (n < e) return 0;
  for (size_t i = 0; i < e; i++) {
    char c = path[n - e + i];
    if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
    if (c != ext[i]) return 0;
  }
  return 1;
}

fcm_status fcm_surface_create_from_file(fcm_ctx *ctx, const char *path, fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  fcm__sbuild B = {0};
  char *buf = NULL;
  size_t len = 0;
  FCM_CHECK(surf, ctx, FCM_ERR_ARG, "surface: output pointer is NULL");
  *surf = NULL;
  FCM_CHECK(ctx && path, ctx, FCM_ERR_ARG, "surface: NULL argument (ctx and path are required)");
  fcm__surface_reader *read = ext_is(path, ".obj")   ? fcm__surface_read_obj
                              : ext_is(path, ".off") ? fcm__surface_read_off
                              : ext_is(path, ".stl") ? fcm__surface_read_stl
                              : ext_is(path, ".ply") ? fcm__surface_read_ply
                                                     : NULL;
  FCM_CHECK(read, ctx, FCM_ERR_UNSUPPORTED,
            "surface: %s: unknown file extension (supported: .obj, .off, .stl, .ply)", path);
  FCM_TRY(ctx, fcm__file_read_all(ctx, "surface", path, FCM__SURFACE_MAX_BYTES, &buf, &len));
  B.ctx = ctx, B.path = path;
  FCM_TRY(ctx, read(&B, buf, len));
  FCM_CHECK(B.nv > 0 && B.nt > 0, ctx, FCM_ERR_FORMAT,
            "surface: %s: empty mesh (%zu vertices, %zu triangles)", path, B.nv, B.nt);
  FCM_TRY(ctx, surface_new(ctx, (fcm_index)B.nv, B.x, (fcm_index)B.nt, B.t, surf));
cleanup:
  fcm__free(ctx, buf);
  fcm__sbuild_free(&B);
  return st;
}

void fcm_surface_destroy(fcm_surface **surf)
{
  if (!surf || !*surf) return;
  fcm_surface *s = *surf;
  fcm__free(s->ctx, s->coords);
  fcm__free(s->ctx, s->tris);
  fcm__free(s->ctx, s);
  *surf = NULL;
}

fcm_index fcm_surface_num_vertices(const fcm_surface *surf)
{
  return surf ? surf->num_vertices : 0;
}

fcm_index fcm_surface_num_triangles(const fcm_surface *surf)
{
  return surf ? surf->num_triangles : 0;
}

const double *fcm_surface_coords(const fcm_surface *surf)
{
  return surf ? surf->coords : NULL;
}

const fcm_index *fcm_surface_triangles(const fcm_surface *surf)
{
  return surf ? surf->tris : NULL;
}

void fcm_surface_bounding_box(const fcm_surface *surf, double lo[3], double hi[3])
{
  if (!surf) return;
  for (int k = 0; k < 3; k++) {
    if (lo) lo[k] = surf->lo[k];
    if (hi) hi[k] = surf->hi[k];
  }
}
