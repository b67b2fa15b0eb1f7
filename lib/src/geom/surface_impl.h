/* fcm geom, internal part of the triangle surfaces: the surface struct, the builder the
 * format readers fill, and the readers (surface_read.c). */
#ifndef FCM_SURFACE_IMPL_H
#define FCM_SURFACE_IMPL_H

#include "core/core_impl.h"
#include "fcm/surface.h"

#include <stddef.h>
#include <stdint.h>

/* Files above this size are refused before reading (4 GiB). */
#define FCM__SURFACE_MAX_BYTES ((size_t)1 << 32)

struct fcm_surface {
  fcm_ctx *ctx;
  fcm_index num_vertices, num_triangles;
  double *coords;  /* num_vertices x 3 */
  fcm_index *tris; /* num_triangles x 3 */
  double lo[3], hi[3];
};

/* Growing vertex and triangle arrays a reader appends to. */
typedef struct fcm__sbuild {
  fcm_ctx *ctx;
  const char *path;
  double *x;    /* nv x 3 */
  fcm_index *t; /* nt x 3 */
  size_t nv, nt, capv, capt;
  int base; /* the first vertex id of the format (OBJ 1, the others 0), for messages */
  int soup; /* 1: 3 vertices per facet, no ids (STL): messages name facet and corner */
} fcm__sbuild;

/* Append a vertex; a coordinate beyond FCM__COORD_MAX is refused (FCM_ERR_FORMAT) naming the
 * file, the vertex (its id as the format numbers them, or facet and corner) and the value. */
fcm_status fcm__sbuild_vertex(fcm__sbuild *B, const double p[3]);
fcm_status fcm__sbuild_triangle(fcm__sbuild *B, fcm_index a, fcm_index b, fcm_index c);
/* Merge vertices with exactly equal coordinates (renumbering the triangles). */
fcm_status fcm__sbuild_merge(fcm__sbuild *B);
void fcm__sbuild_free(fcm__sbuild *B);

/* A reader parses buf[0..len) (NUL-terminated at len, writable) into B. */
typedef fcm_status fcm__surface_reader(fcm__sbuild *B, char *buf, size_t len);
fcm__surface_reader fcm__surface_read_obj, fcm__surface_read_off, fcm__surface_read_stl,
    fcm__surface_read_ply;

#endif
