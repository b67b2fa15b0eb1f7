/* fcm — embedded geometry: a mesh of convex cells (Tet4, or convex Hex8 with planar
 * faces; VTK node order, see fcm/element.h) that the background mesh integrates over.
 * Readers (Gmsh MSH, TetGen .node/.ele), procedural shapes (box, ball, hemisphere,
 * hollow ball with holes, tube) as Tet4 meshes of controllable resolution, boundary
 * triangles, and an axis-aligned bounding-box (AABB) tree.
 *
 * Storage: coordinates num_nodes x 3 (row-major); connectivity num_cells x npc
 * (npc = 4 or 8, 0-based node ids). A geometry is immutable after creation; every
 * const accessor is thread safe. */
#ifndef FCM_GEOM_H
#define FCM_GEOM_H

#include "fcm/core.h"
#include "fcm/element.h"

#ifdef __cplusplus
extern "C" {
#endif

/** An embedded geometry (opaque). */
typedef struct fcm_geometry fcm_geometry;

/** Create a geometry by copying caller arrays.
 * @param[in]  type      FCM_ELEMENT_TET4 or FCM_ELEMENT_HEX8 (every cell)
 * @param[in]  num_nodes number of nodes (>= 0); @param[in] coords num_nodes x 3, copied
 * @param[in]  num_cells number of cells (>= 0); @param[in] cells num_cells x npc ids, copied
 * @param[out] geom      the new geometry, NULL on failure
 * A negatively oriented tet is reoriented (two nodes swapped); zero-volume tets are kept
 * (they contribute nothing). Hex8 cells must be convex with planar faces (relative
 * tolerance 1e-10 of the cell's bounding-box diagonal) and positively oriented.
 * @return FCM_OK; FCM_ERR_ARG (NULL pointers, other types, negative counts, a coordinate
 *         that is not finite or beyond +-1e50 (products of such coordinates overflow),
 *         node id out of range); FCM_ERR_GEOMETRY (non-convex or inverted
 *         hex, naming the cell); FCM_ERR_ALLOC. Allocates; release with
 *         fcm_geometry_destroy(). Thread safe. */
FCM_API fcm_status fcm_geometry_create(fcm_ctx *ctx, fcm_element_type type, fcm_index num_nodes,
                                       const double *coords, fcm_index num_cells,
                                       const fcm_index *cells, fcm_geometry **geom);

/** Read a Gmsh MSH file (as fcm_mesh_create_from_gmsh()) whose volume elements are Tet4
 * or Hex8. @return as fcm_mesh_create_from_gmsh(), plus FCM_ERR_UNSUPPORTED for Tet10 and
 * Hex20 files and the errors of fcm_geometry_create(). Allocates; thread safe. */
FCM_API fcm_status fcm_geometry_create_from_gmsh(fcm_ctx *ctx, const char *path,
                                                 fcm_geometry **geom);

/** Read a TetGen mesh: `node_path` (.node: header "count 3 attributes markers", then
 * "index x y z [attributes] [marker]") and `ele_path` (.ele: header "count 4 attributes",
 * then "index n0 n1 n2 n3 [attributes]"). Indices start at 0 or 1 (the first point's
 * index sets the base for both files) and are consecutive; '#' starts a comment.
 * @return FCM_OK; FCM_ERR_IO (cannot open/read); FCM_ERR_FORMAT ("path:line: ..." for
 *         malformed content, bad counts, node index out of range, a coordinate beyond
 *         +-1e50 naming the point's index and the value); FCM_ERR_UNSUPPORTED
 *         (dimension other than 3, 10-node tetrahedra); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_geometry_create_from_tetgen(fcm_ctx *ctx, const char *node_path,
                                                   const char *ele_path, fcm_geometry **geom);

/** Box [lo, hi] as n[0] x n[1] x n[2] cubes, each split into 6 tets around its
 * lo -> hi diagonal (Kuhn split, conforming). 6 n0 n1 n2 tets.
 * @return FCM_OK, FCM_ERR_ARG (lo[d] >= hi[d], non-finite, n[d] < 1, count overflow),
 *         FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_geometry_create_box(fcm_ctx *ctx, const double lo[3], const double hi[3],
                                           const fcm_index n[3], fcm_geometry **geom);

/** Ball of `radius` around `center`: the Kuhn-split grid of [-1,1]^3 with 2n cubes per
 * axis (n = cubes per radius, 48 n^3 tets) mapped by p -> center + radius p ((1-s) + s^2/|p|),
 * s = max|p_i|: the grid's outer faces land on the sphere, the core stays a cube. The
 * volume is that of an inscribed polyhedron, converging like O(n^-2) to 4/3 pi r^3.
 * @return FCM_OK, FCM_ERR_ARG (radius <= 0 or not finite, n < 1 or n > 1000), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_geometry_create_ball(fcm_ctx *ctx, const double center[3], double radius,
                                            int n, fcm_geometry **geom);

/** Half of the ball of fcm_geometry_create_ball() with y >= center[1]: its flat face lies
 * exactly on the plane y = center[1] (the map keeps p_y = 0 fixed). 24 n^3 tets.
 * @return as fcm_geometry_create_ball(). Allocates. */
FCM_API fcm_status fcm_geometry_create_hemisphere(fcm_ctx *ctx, const double center[3],
                                                  double radius, int n, fcm_geometry **geom);

/** Hollow ball r_in <= |x - center| <= r_out with three cylindrical holes of radius
 * `hole_radius` along the coordinate axes through the centre (0: no holes). The shell is
 * an equiangular cube-sphere surface grid (n x n quads on each of 6 patches, each split
 * in 2 triangles) extruded radially in `layers` layers; each prism is split in 3 tets
 * (36 n^2 layers tets). Holes are approximated by removing every hexahedron (quad x layer,
 * 6 tets) whose vertex centroid lies in a hole: a staircase surface at the grid resolution.
 * @return FCM_OK, FCM_ERR_ARG (0 < r_in < r_out finite, 0 <= hole_radius < r_out,
 *         1 <= n <= 128, 1 <= layers <= 1000), FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_geometry_create_hollow_ball(fcm_ctx *ctx, const double center[3],
                                                   double r_in, double r_out, double hole_radius,
                                                   int n, int layers, fcm_geometry **geom);

/** Tube (hollow cylinder) r_in <= r <= r_out around the line through `center` along axis
 * `axis` (0, 1, 2), of `length` centred on `center`: the Kuhn-split grid of n_r x n_theta x
 * n_axial cubes in (r, theta, a) (theta periodic) mapped to x. 6 n_r n_theta n_axial tets.
 * @return FCM_OK, FCM_ERR_ARG (axis outside [0,3), 0 < r_in < r_out, length > 0, n_r,
 *         n_axial in [1, 10^4], n_theta in [6, 10^4]), FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_geometry_create_tube(fcm_ctx *ctx, const double center[3], int axis,
                                            double r_in, double r_out, double length, int n_r,
                                            int n_theta, int n_axial, fcm_geometry **geom);

/** Copy of `src` with every node mapped by x -> A x + b (A row-major 3x3). When det A < 0
 * the cells are reoriented. @return FCM_OK, FCM_ERR_ARG (NULL, non-finite, |det A| not
 * positive), FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_geometry_create_transformed(fcm_ctx *ctx, const fcm_geometry *src,
                                                   const double A[9], const double b[3],
                                                   fcm_geometry **geom);

/** Destroy a geometry; accepts NULL and `*geom == NULL`, sets `*geom = NULL`. */
FCM_API void fcm_geometry_destroy(fcm_geometry **geom);

/** Accessors (geom must not be NULL); pointers stay valid for the life of the geometry. */
FCM_API fcm_element_type fcm_geometry_cell_type(const fcm_geometry *geom);
FCM_API int fcm_geometry_nodes_per_cell(const fcm_geometry *geom);
FCM_API fcm_index fcm_geometry_num_nodes(const fcm_geometry *geom);
FCM_API fcm_index fcm_geometry_num_cells(const fcm_geometry *geom);
FCM_API const double *fcm_geometry_coords(const fcm_geometry *geom);
FCM_API const fcm_index *fcm_geometry_cells(const fcm_geometry *geom);
/** Sum of the cell volumes. */
FCM_API double fcm_geometry_volume(const fcm_geometry *geom);
/** Bounding box of the nodes (lo = +inf, hi = -inf when empty). */
FCM_API void fcm_geometry_bounding_box(const fcm_geometry *geom, double lo[3], double hi[3]);

/** Boundary of the geometry as triangles: the cell faces not shared with another cell
 * (matched by their corner nodes; a face met an even number of times is interior). Hex
 * faces give two triangles each. Ordered by (cell, local face); each triangle's nodes
 * run counter-clockwise seen from outside (outward normal by the right-hand rule).
 * fcm_geometry_boundary_triangles: num x 3 node ids; fcm_geometry_boundary_cells: num
 * owning cells. */
FCM_API fcm_index fcm_geometry_num_boundary_triangles(const fcm_geometry *geom);
FCM_API const fcm_index *fcm_geometry_boundary_triangles(const fcm_geometry *geom);
FCM_API const fcm_index *fcm_geometry_boundary_cells(const fcm_geometry *geom);

/** Refinement along the embedded boundary, an fcm_octree_refine_fn (fcm/mesh.h) with
 * `geometry` a const fcm_geometry *: 1 when some boundary triangle meets the closed box
 * [lo, hi] (exact separating-axis test; the cells the cut-cell rules see as cut, and cells
 * the surface only touches), else 0; -1 for NULL arguments or when the triangle search
 * tree cannot be allocated (the error is recorded on the geometry's context). Set
 * refine = fcm_geometry_boundary_meets_box, refine_user = geometry and refine_level in
 * fcm_octree_options. Builds the geometry's triangle tree on its first use (kept by the
 * geometry); allocates a small query buffer. Thread safe. */
FCM_API int fcm_geometry_boundary_meets_box(const double lo[3], const double hi[3], int level,
                                            void *geometry);

/** Print type, counts, volume, bounding box and boundary size to `stream`. */
FCM_API void fcm_geometry_view(const fcm_geometry *geom, FILE *stream);

/** A static bounding-volume hierarchy over axis-aligned boxes (opaque). */
typedef struct fcm_aabb_tree fcm_aabb_tree;

/** Build a tree over n boxes (boxes: n x 6, row i = lo[3], hi[3], copied): median splits
 * along the longest axis of the box centres, at most 4 boxes per leaf, O(n log n).
 * @return FCM_OK, FCM_ERR_ARG (n < 0, NULL with n > 0, NaN or lo > hi), FCM_ERR_ALLOC.
 * Allocates; release with fcm_aabb_tree_destroy(). Thread safe. */
FCM_API fcm_status fcm_aabb_tree_create(fcm_ctx *ctx, fcm_index n, const double *boxes,
                                        fcm_aabb_tree **tree);

/** Destroy a tree; accepts NULL and sets `*tree = NULL`. */
FCM_API void fcm_aabb_tree_destroy(fcm_aabb_tree **tree);

/** Boxes intersecting the closed box [lo, hi].
 * @param[in]  capacity length of `ids`; @param[out] ids all matches ascending when
 *             count <= capacity (otherwise its content is unspecified; may be NULL when 0)
 * @param[out] count    number of matches
 * @return FCM_OK, FCM_ERR_ARG (NULL, NaN), FCM_ERR_ALLOC (workspace). Thread safe. */
FCM_API fcm_status fcm_aabb_tree_query(const fcm_aabb_tree *tree, const double lo[3],
                                       const double hi[3], fcm_index capacity, fcm_index *ids,
                                       fcm_index *count);

#ifdef __cplusplus
}
#endif
#endif /* FCM_GEOM_H */
