/* fcm — triangle surface meshes: an indexed triangle mesh (vertices n x 3, triangles
 * m x 3, 0-based) created from arrays or read from OBJ, OFF, STL (ASCII and binary) and
 * PLY (ASCII and binary little endian) files. Polygons are fan-triangulated; STL's
 * per-facet vertices are merged by exact coordinate equality. A surface is immutable
 * after creation; every const accessor is thread safe. A surface keeps its context, which
 * must outlive it. */
#ifndef FCM_SURFACE_H
#define FCM_SURFACE_H

#include "fcm/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A triangle surface mesh (opaque). */
typedef struct fcm_surface fcm_surface;

/** Create a surface by copying caller arrays.
 * @param[in]  num_vertices  number of vertices (> 0); @param[in] coords num_vertices x 3
 * @param[in]  num_triangles number of triangles (> 0); @param[in] tris num_triangles x 3
 *             0-based vertex ids
 * @param[out] surf          the new surface, NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (NULL pointers, counts <= 0, non-finite coordinate,
 *         vertex id out of range, naming the triangle); FCM_ERR_ALLOC. Allocates;
 *         release with fcm_surface_destroy(). Thread safe. */
FCM_API fcm_status fcm_surface_create(fcm_ctx *ctx, fcm_index num_vertices, const double *coords,
                                      fcm_index num_triangles, const fcm_index *tris,
                                      fcm_surface **surf);

/** Read a surface from a file, the format chosen by the extension (case-insensitive):
 * .obj (v and f lines; f a, a/b, a//c, a/b/c and negative relative ids, each referring to
 * a vertex defined above it; vt, vn, g, o, s, usemtl, mtllib and other lines ignored),
 * .off (OFF, COFF, NOFF, CNOFF, STOFF headers; one vertex and one face per line, data
 * after x y z or after the face's ids skipped), .stl (binary when the size is exactly
 * 84 + 50 * count, whatever the header says; else ASCII, one or more solids) and .ply
 * (ascii or binary_little_endian; vertex x y z of any scalar type, face list
 * vertex_indices or vertex_index; other properties and elements skipped by their types).
 * Polygons are fan-triangulated; STL vertices with equal coordinates are merged.
 * Counts in a header are bounded by the file size before anything is allocated.
 * @param[out] surf the new surface, NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (NULL pointers); FCM_ERR_UNSUPPORTED (unknown extension,
 *         big-endian PLY); FCM_ERR_IO (missing or non-regular file); FCM_ERR_FORMAT (any
 *         parse error, out-of-range vertex id, non-finite coordinate, empty mesh: the
 *         message names the file and the line, or the byte offset of binary data, and
 *         what was expected); FCM_ERR_ALLOC. Allocates; release with
 *         fcm_surface_destroy(). Thread safe. */
FCM_API fcm_status fcm_surface_create_from_file(fcm_ctx *ctx, const char *path, fcm_surface **surf);

/** Release a surface and set *surf to NULL; accepts NULL and *surf == NULL. */
FCM_API void fcm_surface_destroy(fcm_surface **surf);

/** Number of vertices (0 for NULL). */
FCM_API fcm_index fcm_surface_num_vertices(const fcm_surface *surf);

/** Number of triangles (0 for NULL). */
FCM_API fcm_index fcm_surface_num_triangles(const fcm_surface *surf);

/** Vertex coordinates, num_vertices x 3 row-major; owned by the surface (NULL for NULL). */
FCM_API const double *fcm_surface_coords(const fcm_surface *surf);

/** Triangles, num_triangles x 3 0-based vertex ids; owned by the surface (NULL for NULL). */
FCM_API const fcm_index *fcm_surface_triangles(const fcm_surface *surf);

/** Axis-aligned bounding box of the vertices: lo[3], hi[3] (written only when surf is
 * not NULL). */
FCM_API void fcm_surface_bounding_box(const fcm_surface *surf, double lo[3], double hi[3]);

#ifdef __cplusplus
}
#endif

#endif
