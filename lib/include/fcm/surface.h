/* fcm — triangle surface meshes: an indexed triangle mesh (vertices n x 3, triangles
 * m x 3, 0-based) created from arrays or read from OBJ, OFF, STL (ASCII and binary) and
 * PLY (ASCII and binary little endian) files. Polygons are fan-triangulated; STL's
 * per-facet vertices are merged by exact coordinate equality. A surface is immutable
 * after creation; every const accessor is thread safe. A surface keeps its context, which
 * must outlive it. */
#ifndef FCM_SURFACE_H
#define FCM_SURFACE_H

#include "fcm/core.h"
#include "fcm/geom.h"

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
 * @return FCM_OK; FCM_ERR_ARG (NULL pointers, counts <= 0, a coordinate that is not
 *         finite or beyond +-1e50 (products of such coordinates overflow), vertex id out of
 *         range, naming the triangle); FCM_ERR_ALLOC. Allocates;
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
 *         what was expected; a coordinate beyond +-1e50, naming the vertex by its id as
 *         the format numbers it, from 1 in OBJ and from 0 in OFF and PLY, or by facet and
 *         corner in STL, and the value); FCM_ERR_ALLOC. Allocates; release with
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

/* ------------------------------------------------------------------ checks */

/** How many problem locations a report keeps (the first ones found, in triangle order). */
#define FCM_SURFACE_REPORT_MAX 4

/** Options of fcm_surface_check(). */
typedef struct fcm_surface_check_options {
  /** A triangle is degenerate when twice its area is <= tol * (its longest edge)^2 (or two
   * of its vertex ids are equal). Default 1e-12; >= 0. */
  double degenerate_tol;
  /** 1 (default): search for self-intersections (triangle pairs that meet other than
   * along a shared edge or at a shared vertex); 0: skip that search. */
  int self_intersections;
} fcm_surface_check_options;

/** Defaults of fcm_surface_check_options. */
FCM_API fcm_surface_check_options fcm_surface_check_options_default(void);

/** What fcm_surface_check() found. Edge lists hold vertex ids (a < b) of the first
 * min(count, FCM_SURFACE_REPORT_MAX) edges found (in vertex order); the intersection
 * search counts every intersecting pair, with a tolerance, so near-touching pairs count. */
typedef struct fcm_surface_report {
  fcm_index num_boundary_edges; /**< edges used by one triangle only (0: closed) */
  fcm_index boundary_edges[FCM_SURFACE_REPORT_MAX][2]; /**< the first ones, vertex ids */
  fcm_index num_boundary_loops;                        /**< chains of boundary edges (holes) */
  fcm_index num_nonmanifold_edges;                     /**< edges used by three or more triangles */
  fcm_index nonmanifold_edges[FCM_SURFACE_REPORT_MAX][2]; /**< the first ones, vertex ids */
  fcm_index num_inconsistent_edges; /**< edges both of whose triangles run them the same way */
  fcm_index inconsistent_edges[FCM_SURFACE_REPORT_MAX][2]; /**< the first ones, vertex ids */
  fcm_index num_degenerate;                     /**< degenerate triangles (see degenerate_tol) */
  fcm_index degenerate[FCM_SURFACE_REPORT_MAX]; /**< their triangle ids */
  fcm_index num_intersections; /**< intersecting triangle pairs (-1: not searched) */
  fcm_index intersecting[FCM_SURFACE_REPORT_MAX][2]; /**< triangle id pairs */
  double signed_volume; /**< sum over triangles of det(a, b, c) / 6 (divergence theorem):
                             the enclosed volume, > 0 when the normals point outward */
  double area;          /**< total triangle area */
} fcm_surface_report;

/** Check a surface for what tetrahedral meshing needs: closed (no boundary edges),
 * manifold, consistently oriented, outward (signed volume > 0), no degenerate triangle,
 * no self-intersection (triangle pairs found through an fcm_aabb_tree; floating-point
 * predicates with a tolerance relative to the pair's size). Cost O(m log m) for m
 * triangles plus the candidate pairs.
 * @param[in] opts NULL for defaults; @param[out] report filled on FCM_OK
 * @return FCM_OK (whatever was found); FCM_ERR_ARG (NULL surf or report, bad option);
 *         FCM_ERR_ALLOC. Allocates workspace only. Thread safe. */
FCM_API fcm_status fcm_surface_check(const fcm_surface *surf, const fcm_surface_check_options *opts,
                                     fcm_surface_report *report);

/** Turn a report into an error: FCM_ERR_GEOMETRY when the surface is open, non-manifold,
 * inconsistently oriented, inward (signed volume <= 0), has degenerate triangles or
 * self-intersections; the message (prefixed by `what`, e.g. a file name; may be NULL)
 * names the first problem with counts, vertex ids and coordinates, and suggests the fix
 * (fill_holes for holes, fcm_surface_create_oriented() for orientation).
 * @return FCM_OK when every check passed; FCM_ERR_ARG (NULL surf or report). */
FCM_API fcm_status fcm_surface_report_check(const fcm_surface *surf, const char *what,
                                            const fcm_surface_report *report);

/** A copy of `src` with consistently oriented triangles (each edge-connected component
 * oriented like its first triangle by a breadth-first walk over manifold edges), then all
 * flipped when the total signed volume is negative: a closed surface comes out with
 * outward normals.
 * @param[out] flipped (may be NULL) number of triangles whose orientation changed
 * @return FCM_OK; FCM_ERR_ARG (NULL); FCM_ERR_ALLOC. Allocates; thread safe. */
FCM_API fcm_status fcm_surface_create_oriented(fcm_ctx *ctx, const fcm_surface *src,
                                               fcm_surface **surf, fcm_index *flipped);

/** How many filled loops fcm_surface_fill_info lists. */
#define FCM_SURFACE_FILL_MAX_LOOPS 16

/** Options of fcm_surface_create_filled(). */
typedef struct fcm_surface_fill_options {
  fcm_index max_edges;  /**< largest loop (in edges) filled; 0 (default): any */
  double max_perimeter; /**< largest loop perimeter filled; 0 (default): any */
} fcm_surface_fill_options;

/** Defaults of fcm_surface_fill_options. */
FCM_API fcm_surface_fill_options fcm_surface_fill_options_default(void);

/** What fcm_surface_create_filled() did. */
typedef struct fcm_surface_fill_info {
  fcm_index num_loops;                              /**< boundary loops found */
  fcm_index num_filled;                             /**< loops closed */
  fcm_index loop_edges[FCM_SURFACE_FILL_MAX_LOOPS]; /**< edges of the first closed loops */
  double loop_area[FCM_SURFACE_FILL_MAX_LOOPS];     /**< area added in each of them */
  fcm_index largest_left; /**< edges of the largest loop left open (0: none left) */
  fcm_index triangles_added, vertices_added;
  double area_added; /**< total area of the added triangles */
} fcm_surface_fill_info;

/** Close the holes of a surface: the boundary edges are chained into loops (at a vertex
 * with several outgoing boundary edges the first unused one is taken). Each loop is
 * triangulated without new vertices by minimum area (dynamic programme of Liepa 2003,
 * loops up to 400 edges), else by the same with a penalty on folds against the
 * neighbouring triangles, else by a fan around a new vertex at the loop's centroid: the
 * first candidate whose triangles meet no other triangle is kept (else the one with the
 * fewest intersections; fcm_surface_check() then reports them). New triangles run
 * like those along the loop. Loops larger than the options allow are left open and
 * counted. A closed surface is copied unchanged.
 * @param[in] opts NULL for defaults; @param[out] info (may be NULL) what was closed
 * @return FCM_OK; FCM_ERR_ARG (NULL, negative option); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_surface_create_filled(fcm_ctx *ctx, const fcm_surface *src,
                                             const fcm_surface_fill_options *opts,
                                             fcm_surface **surf, fcm_surface_fill_info *info);

/** Refinement along a cut surface, an fcm_octree_refine_fn (fcm/mesh.h) with `surface` a
 * const fcm_surface * (a blade: fcm_surface_create_rectangle(), a plane clipped to a box:
 * fcm_surface_create_plane(), a surface read from a file): 1 when some triangle meets the
 * closed box [lo, hi] (exact separating-axis test), else 0; -1 for NULL arguments. Refining
 * before the cut resolves the cut's detail where it will happen. Tests every triangle of the
 * surface (O(triangles) per cell: meant for cut surfaces of few triangles; an embedded
 * body's boundary goes through fcm_geometry_boundary_meets_box(), which searches a tree). No
 * allocation; thread safe. */
FCM_API int fcm_surface_meets_box(const double lo[3], const double hi[3], int level, void *surface);

/* ------------------------------------------------------------------ tetrahedra */

/** Options of fcm_geometry_create_from_surface(). */
typedef struct fcm_surface_mesh_options {
  /** Largest tet volume wanted (sets Gmsh's Mesh.MeshSizeMax to the edge of a regular tet
   * of that volume); 0 (default): no limit, sizes follow the surface's edges. */
  double max_volume;
  /** Target edge length inside (Mesh.MeshSizeMax); 0 (default): none. With max_volume
   * the smaller size wins. */
  double size;
  /** Tets whose quality (Gmsh's gamma, 1 for a regular tet) is below this are optimized
   * (Mesh.OptimizeThreshold), in [0, 1]; default 0.3. */
  double quality;
  /** 1 (default): refuse a surface that fails fcm_surface_check(), reporting why;
   * 0: skip the self-intersection search (the other checks always run). */
  int check_intersections;
  /** 1 (default): orient the surface first (fcm_surface_create_oriented()). */
  int orient;
  /** 1 (default): tetrahedralize the volume (Gmsh). 0: no volume mesh: the geometry is the
   * checked, oriented surface alone (fcm_geometry_num_cells() 0, no Gmsh needed, the set-up
   * costs what the surface costs). The cut-cell rules then come from the surface
   * (FCM_CELL_MOMENTS_AUTO), and so do the pieces of the cells fcm_cell_rules_create_cut()
   * splits; what needs the volume mesh — the VOLUME moments and the distributed backend —
   * refuses such a geometry with FCM_ERR_UNSUPPORTED. max_volume, size and quality are
   * ignored. */
  int volume_mesh;
} fcm_surface_mesh_options;

/** Defaults of fcm_surface_mesh_options. */
FCM_API fcm_surface_mesh_options fcm_surface_mesh_options_default(void);

/** The geometry of the volume a closed triangle surface encloses: tetrahedralized (volume_mesh,
 * the default) or the surface alone (volume_mesh = 0, see fcm_surface_mesh_options). It is
 * tetrahedralized through Gmsh's C API
 * (3D Delaunay with the surface mesh kept: no surface vertex is moved or added, so the
 * tets' volume equals the surface's enclosed volume up to rounding). The surface is
 * checked first (fcm_surface_check(), fcm_surface_report_check()) and oriented.
 * Gmsh keeps global state: calls are serialized by a lock, and Gmsh prints nothing. The same
 * surface and options give the same tets in every call (Gmsh's classic Delaunay mesher),
 * except when the surface is much coarser than the size asked for: that mesher does not
 * refine inside it (its tets average above 4x the requested volume), and Gmsh's HXT, which
 * does, is used instead; HXT may return other tets on a later call in the same process.
 * @param[in] opts NULL for defaults; @param[out] geom the Tet4 geometry, NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (NULL, bad option); FCM_ERR_GEOMETRY (the surface fails a
 *         check, or Gmsh fails: its message is quoted); FCM_ERR_UNSUPPORTED (fcm built
 *         without Gmsh, or the Gmsh library cannot be loaded: the message says how to get
 *         it); FCM_ERR_ALLOC. Allocates. Thread safe (serialized). */
FCM_API fcm_status fcm_geometry_create_from_surface(fcm_ctx *ctx, const fcm_surface *surf,
                                                    const fcm_surface_mesh_options *opts,
                                                    fcm_geometry **geom);

/** 1 when fcm_geometry_create_from_surface() can work: fcm was built with Gmsh's header
 * and the Gmsh library (loaded on first use, soname libgmsh.so.MAJOR.MINOR of that header)
 * loads; else 0. Thread safe. */
FCM_API int fcm_surface_meshing_available(void);

#ifdef __cplusplus
}
#endif

#endif
