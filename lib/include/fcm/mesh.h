/* fcm — background meshes: nodes and cells of one element type (Tet4, Tet10, Hex8,
 * Hex20; VTK node order, see fcm/element.h), face adjacency and boundary faces,
 * structured box generators, the Gmsh MSH reader, and geometric checks.
 *
 * Storage: coordinates num_nodes x 3 (row-major, coords[3*a + d]); connectivity
 * num_cells x nodes_per_cell (cells[npc*c + a], 0-based node ids). A mesh is
 * immutable after creation; every const accessor is thread safe. */
#ifndef FCM_MESH_H
#define FCM_MESH_H

#include "fcm/core.h"
#include "fcm/element.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A background mesh (opaque). */
typedef struct fcm_mesh fcm_mesh;

/** Create a mesh by copying caller arrays; builds the face adjacency and the
 * boundary-face list (hash of sorted face corners, O(num_cells)).
 * @param[in]  ctx       context (allocation, errors)
 * @param[in]  type      element type of every cell
 * @param[in]  num_nodes number of nodes (>= 0); @param[in] coords num_nodes x 3, copied
 * @param[in]  num_cells number of cells (>= 0); @param[in] cells num_cells x nodes_per_cell
 *                       node ids in [0, num_nodes), VTK order, copied
 * @param[out] mesh      the new mesh, NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (NULL pointers, bad type, negative counts, a coordinate that
 *         is not finite or beyond +-1e50 (products of such coordinates overflow), node id
 *         out of range, node repeated within a cell); FCM_ERR_GEOMETRY (a face shared by
 *         more than two cells); FCM_ERR_ALLOC.
 * Allocates; release with fcm_mesh_destroy(). Thread safe. */
FCM_API fcm_status fcm_mesh_create(fcm_ctx *ctx, fcm_element_type type, fcm_index num_nodes,
                                   const double *coords, fcm_index num_cells,
                                   const fcm_index *cells, fcm_mesh **mesh);

/** Structured grid of n[0] x n[1] x n[2] cubes over the box [lo, hi].
 * Hex8/Hex20: one hexahedron per cube. Tet4/Tet10: each cube split into 6 tetrahedra
 * around its diagonal lo-corner -> hi-corner (Kuhn/Freudenthal split, the same in every
 * cube, hence conforming). Numbering: grid corner (i,j,k) is node i + (n0+1)(j + (n1+1)k);
 * cube (i,j,k) is q = i + n0 (j + n1 k); hex cell q, or tet cells 6q..6q+5. Quadratic
 * types add one node at the midpoint of every edge, numbered after the corners in the
 * order edges are first met (cells ascending, local edges ascending); neighbours share it.
 * @param[in] lo, hi box corners (lo[d] < hi[d], finite); @param[in] n cells per axis (>= 1)
 * @param[out] mesh  the new mesh, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (bad type, box or counts, count overflow), FCM_ERR_ALLOC.
 * Allocates; release with fcm_mesh_destroy(). Thread safe. */
FCM_API fcm_status fcm_mesh_create_box(fcm_ctx *ctx, fcm_element_type type, const double lo[3],
                                       const double hi[3], const fcm_index n[3], fcm_mesh **mesh);

/** Deepest refinement level of an octree mesh (the box grid is level 0). */
#define FCM_OCTREE_MAX_LEVEL 12
/** Most cells an octree mesh may have. */
#define FCM_OCTREE_MAX_CELLS ((fcm_index)1 << 30)
/** fcm_mesh_neighbors() entry of a face that meets cells of another level (an octree
 * mesh's face against four finer faces, or a quarter of a coarser one): interior, not
 * boundary, with no single cell across. */
#define FCM_MESH_NEIGHBOR_NONCONFORMING (-2)

/** Scalar level set phi(x) (the refinement surface is phi = 0); same signature as
 * fcm_level_set_fn of fcm/levelset.h. */
typedef double (*fcm_octree_levelset_fn)(const double x[3], void *user);
/** Refinement predicate: 1 to split the cell [lo, hi] of `level` into eight, 0 to keep it,
 * negative when it failed (fcm_mesh_create_octree() then fails with FCM_ERR_ARG naming the
 * cell; the callback records its own error where it can). */
typedef int (*fcm_octree_refine_fn)(const double lo[3], const double hi[3], int level, void *user);

/** Refinement criteria of fcm_mesh_create_octree(). A cell is split while one criterion
 * asks for it and the cell is coarser than that criterion's level (0: criterion off; each
 * level in [0, FCM_OCTREE_MAX_LEVEL]); the criteria combine by "or". */
typedef struct fcm_octree_options {
  int region_level;    /**< cells meeting the closed box [region_lo, region_hi] */
  double region_lo[3]; /**< region box, lo <= hi per axis */
  double region_hi[3];
  int surface_level;              /**< cells the surface phi = 0 crosses: phi changes sign (or is 0)
                                       over the 3 x 3 x 3 corner, edge, face and centre points */
  fcm_octree_levelset_fn surface; /**< the level set (called serially) */
  void *surface_user;
  int refine_level;            /**< cells the callback flags: along an embedded boundary
                                    fcm_geometry_boundary_meets_box() (fcm/geom.h), along a
                                    cut surface fcm_surface_meets_box() (fcm/surface.h) */
  fcm_octree_refine_fn refine; /**< called serially */
  void *refine_user;
} fcm_octree_options;

/** All criteria off: the box grid itself. */
FCM_API fcm_octree_options fcm_octree_options_default(void);

/** Octree background: the box grid of fcm_mesh_create_box() (n[0] x n[1] x n[2] cubes over
 * [lo, hi]) with cells split into eight by the criteria of `opts`, then balanced 2:1 across
 * faces and edges (cells sharing a face or an edge differ by at most one level; balancing
 * only splits). Cells are hexahedra of the given type in the depth-first order of the tree;
 * nodes are shared wherever cells of any levels meet at the same point, so the cells of
 * different sizes are joined through hanging nodes: a node on a face or edge of a coarser
 * cell that is not a node of that cell (fcm_mesh_get_hanging()); the fem module constrains
 * them (fcm_space_hanging_matrix_create() in fcm/fem.h). Faces against finer cells have the
 * neighbour FCM_MESH_NEIGHBOR_NONCONFORMING; the boundary faces are the box surface.
 * @param[in]  type  FCM_ELEMENT_HEX8 or FCM_ELEMENT_HEX20
 * @param[in]  opts  criteria (NULL: none); callbacks are called serially
 * @param[out] mesh  the new mesh, NULL on failure
 * @return FCM_OK; FCM_ERR_UNSUPPORTED (a tetrahedral type); FCM_ERR_ARG (NULL, box or counts
 *         as fcm_mesh_create_box(), a level beyond FCM_OCTREE_MAX_LEVEL, more than
 *         FCM_OCTREE_MAX_CELLS cells, a criterion level without its function, a failing
 *         refine callback); FCM_ERR_ALLOC.
 * Allocates; release with fcm_mesh_destroy(). Thread safe (the callbacks permitting). */
FCM_API fcm_status fcm_mesh_create_octree(fcm_ctx *ctx, fcm_element_type type, const double lo[3],
                                          const double hi[3], const fcm_index n[3],
                                          const fcm_octree_options *opts, fcm_mesh **mesh);

/** Refine an octree mesh further: split the cells with flags[c] != 0 into eight (an error
 * indicator's marks, cells with a small volume fraction, cut cells of a rules build, ...),
 * balance 2:1 again and write the new mesh (cells in the tree's depth-first order: unsplit
 * cells keep their relative order). The input is unchanged.
 * @param[in]  mesh  made by fcm_mesh_create_octree() or this function
 * @param[in]  flags num_cells entries
 * @param[out] out   the new mesh, NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (NULL, a flagged cell at FCM_OCTREE_MAX_LEVEL, more than
 *         FCM_OCTREE_MAX_CELLS cells); FCM_ERR_UNSUPPORTED (not an octree mesh: a box grid of
 *         fcm_mesh_create_box(), a Gmsh mesh, a tetrahedral mesh); FCM_ERR_ALLOC.
 * Allocates; release with fcm_mesh_destroy(). Thread safe. */
FCM_API fcm_status fcm_mesh_create_refined(fcm_ctx *ctx, const fcm_mesh *mesh,
                                           const unsigned char *flags, fcm_mesh **out);

/** Whether the mesh was made by fcm_mesh_create_octree(). */
FCM_API int fcm_mesh_is_octree(const fcm_mesh *mesh);
/** Refinement level of `cell` (0 for a mesh that is not an octree). */
FCM_API int fcm_mesh_cell_level(const fcm_mesh *mesh, fcm_index cell);
/** Deepest level of any cell (0 for a mesh that is not an octree). */
FCM_API int fcm_mesh_max_level(const fcm_mesh *mesh);
/** Number of (cell, hanging node) pairs of an octree mesh (0 for other meshes). */
FCM_API fcm_index fcm_mesh_num_hanging(const fcm_mesh *mesh);
/** Pair i in [0, fcm_mesh_num_hanging()): `node` lies on a face or edge of `cell` without
 * being one of its nodes; xi are its reference coordinates in the cell (exact: multiples of
 * 1/2 for Hex8, 1/4 for Hex20). A node may be listed with several cells (all around an
 * edge). Outputs may be NULL. No allocation; thread safe. */
FCM_API void fcm_mesh_get_hanging(const fcm_mesh *mesh, fcm_index i, fcm_index *cell,
                                  fcm_index *node, double xi[3]);

/** Read a Gmsh MSH file, ASCII version 4.1 or 2.x (2.0, 2.1, 2.2). Volume elements of
 * Gmsh types 4 (tet4), 11 (tet10), 5 (hex8) and 17 (hex20) become the cells, in file
 * order, reordered from Gmsh's to VTK's node order; lower-dimensional elements (points,
 * lines, triangles, quadrangles, ...) and unknown sections are skipped. Node tags may be
 * sparse and unordered; nodes not used by any volume element are dropped, the others
 * keep their file order.
 * @param[in]  path file name; @param[out] mesh the new mesh, NULL on failure
 * @return FCM_OK; FCM_ERR_IO (cannot open/read the file); FCM_ERR_FORMAT (malformed
 *         content or unknown version: the message says "path:line: expected ..."; a
 *         coordinate beyond +-1e50, naming the node tag and the value);
 *         FCM_ERR_UNSUPPORTED (binary file, other volume element types, mixed volume
 *         types, no volume elements); FCM_ERR_GEOMETRY, FCM_ERR_ALLOC as fcm_mesh_create().
 * Allocates; release with fcm_mesh_destroy(). Thread safe (numbers are parsed with
 * strtod, i.e. in the C locale's number format). */
FCM_API fcm_status fcm_mesh_create_from_gmsh(fcm_ctx *ctx, const char *path, fcm_mesh **mesh);

/** Destroy a mesh; accepts NULL and `*mesh == NULL`, sets `*mesh = NULL`. */
FCM_API void fcm_mesh_destroy(fcm_mesh **mesh);

/** Accessors (mesh must not be NULL). Pointers stay valid for the life of the mesh.
 * fcm_mesh_coords: num_nodes x 3; fcm_mesh_cells: num_cells x nodes_per_cell. */
FCM_API fcm_element_type fcm_mesh_element_type(const fcm_mesh *mesh);
FCM_API const fcm_element_info *fcm_mesh_get_element_info(const fcm_mesh *mesh);
FCM_API int fcm_mesh_nodes_per_cell(const fcm_mesh *mesh);
FCM_API fcm_index fcm_mesh_num_nodes(const fcm_mesh *mesh);
FCM_API fcm_index fcm_mesh_num_cells(const fcm_mesh *mesh);
FCM_API const double *fcm_mesh_coords(const fcm_mesh *mesh);
FCM_API const fcm_index *fcm_mesh_cells(const fcm_mesh *mesh);

/** Gather the nodal coordinates of `cell` (in [0, num_cells)) into X (nodes_per_cell x 3),
 * ready for fcm_element_map()/fcm_element_jacobian(). No allocation; thread safe. */
FCM_API void fcm_mesh_cell_coords(const fcm_mesh *mesh, fcm_index cell, double *X);

/** Face adjacency: num_cells x num_faces (num_faces of the element info: 4 or 6);
 * entry [nf*c + f] is the cell across local face f of cell c, or -1 on the boundary, or
 * FCM_MESH_NEIGHBOR_NONCONFORMING (octree meshes: cells of another level across).
 * Faces are matched by their corner nodes. */
FCM_API const fcm_index *fcm_mesh_neighbors(const fcm_mesh *mesh);

/** Number of boundary faces (faces with no neighbour). */
FCM_API fcm_index fcm_mesh_num_boundary_faces(const fcm_mesh *mesh);

/** Boundary faces as pairs (cell, local face): entries [2*i] and [2*i + 1], ordered by
 * cell then local face. The face's nodes (corners, then mid-edge nodes for quadratic
 * types) are cells[npc*cell + info->face_nodes[face][k]], k < info->face_num_nodes[face];
 * for a positively oriented cell their corners run counter-clockwise seen from outside. */
FCM_API const fcm_index *fcm_mesh_boundary_faces(const fcm_mesh *mesh);

/** Axis-aligned bounding box of all nodes (lo = +inf, hi = -inf for an empty mesh). */
FCM_API void fcm_mesh_bounding_box(const fcm_mesh *mesh, double lo[3], double hi[3]);

/** Nodes inside the closed box [lo - tol, hi + tol] (all three axes). A plane such as
 * x = 0 is the box lo = (0, -HUGE_VAL, -HUGE_VAL), hi = (0, HUGE_VAL, HUGE_VAL).
 * @param[in]  lo, hi   box corners (lo[d] <= hi[d]; infinities allowed, no NaN)
 * @param[in]  tol      absolute tolerance >= 0
 * @param[in]  capacity length of `nodes`; @param[out] nodes the first min(count, capacity)
 *                      matching ids, ascending (may be NULL when capacity is 0)
 * @param[out] count    the number of matching nodes (call with capacity 0 to size `nodes`)
 * @return FCM_OK or FCM_ERR_ARG. No allocation; thread safe. */
FCM_API fcm_status fcm_mesh_nodes_in_box(fcm_ctx *ctx, const fcm_mesh *mesh, const double lo[3],
                                         const double hi[3], double tol, fcm_index capacity,
                                         fcm_index *nodes, fcm_index *count);

/** Check that det J > 0 at every corner of every cell and at `num_points` caller-supplied
 * reference points (e.g. a quadrature rule's points: fcm_rule_points()).
 * @param[in]  points  num_points x 3 reference coordinates (NULL when num_points is 0)
 * @param[out] min_det smallest det J met (may be NULL); on failure the failing value
 * @return FCM_OK; FCM_ERR_GEOMETRY naming the first failing cell, the point and det J
 *         (the check stops there); FCM_ERR_ARG. No allocation; thread safe. */
FCM_API fcm_status fcm_mesh_validate(fcm_ctx *ctx, const fcm_mesh *mesh, int num_points,
                                     const double *points, double *min_det);

/** Whether `cell` is a convex polyhedron with planar faces and straight edges, the shape
 * cut-cell quadrature needs. Tolerances are rtol * (diagonal of the cell's bounding box):
 * every face's corners lie within it of the face plane (Newell normal through the corner
 * centroid); every corner of the cell lies on the inner side of every face plane (outward
 * normals from the element's face order, so an inverted cell is not convex); for Tet10 and
 * Hex20 each mid-edge node lies within it of the straight edge, strictly inside the middle
 * half of the edge (so the edge map is one-to-one). Returns 1 or 0; no allocation. */
FCM_API int fcm_mesh_cell_is_convex(const fcm_mesh *mesh, fcm_index cell, double rtol);

/** fcm_mesh_cell_is_convex() for every cell.
 * @param[in]  rtol          relative tolerance (>= 0, e.g. 1e-10)
 * @param[out] is_convex     num_cells flags (1 convex, 0 not); may be NULL
 * @param[out] num_nonconvex number of cells flagged 0; may be NULL
 * @return FCM_OK or FCM_ERR_ARG. No allocation; thread safe. */
FCM_API fcm_status fcm_mesh_convex_cells(fcm_ctx *ctx, const fcm_mesh *mesh, double rtol,
                                         unsigned char *is_convex, fcm_index *num_nonconvex);

/** Print type, counts, bounding box and boundary-face count to `stream`. */
FCM_API void fcm_mesh_view(const fcm_mesh *mesh, FILE *stream);

#ifdef __cplusplus
}
#endif
#endif /* FCM_MESH_H */
