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

/** A plane cut clipped to a box: the polygon where the plane through `point` with normal
 * `normal` meets the box [lo, hi], fan-triangulated from its centroid (3 to 6 triangles).
 * Give a box somewhat larger than the body so that the polygon's edges lie outside it.
 * @return FCM_OK; FCM_ERR_ARG (NULL, non-finite, zero normal, lo[d] >= hi[d]);
 *         FCM_ERR_GEOMETRY (the plane misses the box); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_surface_create_plane(fcm_ctx *ctx, const double point[3],
                                            const double normal[3], const double lo[3],
                                            const double hi[3], fcm_surface **surf);

/** A rectangle (two triangles) centred at `center` in the plane with normal `normal`; its
 * first side (length size[0]) runs along `axis` projected onto the plane, the second
 * (size[1]) along normal x axis. A partial cut: it may end inside a body.
 * @return FCM_OK; FCM_ERR_ARG (NULL, non-finite, sizes <= 0, zero normal, axis parallel to
 *         the normal); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_surface_create_rectangle(fcm_ctx *ctx, const double center[3],
                                                const double normal[3], const double axis[3],
                                                const double size[2], fcm_surface **surf);

/** A disc of `radius` around `center` with normal `normal`: a fan of `segments` triangles
 * (in [3, 256]) from the centre to a regular polygon inscribed in the circle.
 * @return FCM_OK; FCM_ERR_ARG (NULL, non-finite, radius <= 0, segments out of range, zero
 *         normal); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_surface_create_disc(fcm_ctx *ctx, const double center[3],
                                           const double normal[3], double radius, int segments,
                                           fcm_surface **surf);

/** Copy of `src` with every vertex mapped by x -> A x + b (A row-major 3x3, invertible).
 * @return FCM_OK; FCM_ERR_ARG (NULL, non-finite, det A = 0); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_surface_create_transformed(fcm_ctx *ctx, const fcm_surface *src,
                                                  const double A[9], const double b[3],
                                                  fcm_surface **surf);

#ifdef __cplusplus
}
#endif

#endif
