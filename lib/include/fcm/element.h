/* fcm — reference elements Tet4, Tet10, Hex8, Hex20: shape functions, geometric
 * map, Jacobian, inverse map, face and edge tables. Node ordering is VTK's.
 *
 *  Tet (unit tet: (0,0,0) (1,0,0) (0,1,0) (0,0,1))     Hex ([-1,1]^3)
 *
 *         3                                             7-----14-----6
 *        /|\          Tet10 mid-edge nodes:            /|           /|
 *       / | \           4:(0,1)  5:(1,2)  6:(2,0)     15 19        13 18
 *      7  8  9          7:(0,3)  8:(1,3)  9:(2,3)    /  |         /  |
 *     /   |   \                                     4-----12-----5   |
 *    0 -6-|----2        Hex20 mid-edge nodes:       |   3-----10-|---2
 *     \   |   /          8:(0,1)  9:(1,2) 10:(2,3)  16 /         17 /
 *      4  |  5          11:(3,0) 12:(4,5) 13:(5,6)  | 11         | 9
 *       \ | /           14:(6,7) 15:(7,4) 16:(0,4)  |/           |/
 *         1             17:(1,5) 18:(2,6) 19:(3,7)  0-----8------1
 *
 * Hex corners: 0 (-1,-1,-1) 1 (1,-1,-1) 2 (1,1,-1) 3 (-1,1,-1), 4..7 the same at zeta = +1.
 * Arrays of nodal coordinates are num_nodes x 3, row-major (X[3*a + d]). */
#ifndef FCM_ELEMENT_H
#define FCM_ELEMENT_H

#include "fcm/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Reference shapes of elements and quadrature rules. */
typedef enum fcm_shape {
  FCM_SHAPE_LINE = 0, /**< [-1, 1] */
  FCM_SHAPE_TRI,      /**< unit triangle (0,0) (1,0) (0,1) */
  FCM_SHAPE_QUAD,     /**< [-1, 1]^2 */
  FCM_SHAPE_TET,      /**< unit tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,1) */
  FCM_SHAPE_HEX,      /**< [-1, 1]^3 */
  FCM_SHAPE_COUNT
} fcm_shape;

/** Name ("line", "tri", "quad", "tet", "hex"), or "unknown". */
FCM_API const char *fcm_shape_name(fcm_shape shape);
/** Spatial dimension of the shape (1, 2 or 3); 0 for an invalid shape. */
FCM_API int fcm_shape_dim(fcm_shape shape);
/** Measure of the reference shape (2, 1/2, 4, 1/6, 8); 0 for an invalid shape. */
FCM_API double fcm_shape_measure(fcm_shape shape);

/** The element types. */
typedef enum fcm_element_type {
  FCM_ELEMENT_TET4 = 0,
  FCM_ELEMENT_TET10,
  FCM_ELEMENT_HEX8,
  FCM_ELEMENT_HEX20, /**< 20-node serendipity */
  FCM_ELEMENT_COUNT
} fcm_element_type;

#define FCM_ELEMENT_MAX_NODES      20
#define FCM_ELEMENT_MAX_FACES      6
#define FCM_ELEMENT_MAX_FACE_NODES 8
#define FCM_ELEMENT_MAX_EDGES      12

/** Static description of an element type (immutable, shared, thread safe). */
typedef struct fcm_element_info {
  fcm_element_type type;
  const char *name;    /**< "tet4", "tet10", "hex8", "hex20" */
  fcm_shape shape;     /**< FCM_SHAPE_TET or FCM_SHAPE_HEX */
  int num_nodes;       /**< 4, 10, 8, 20 */
  int num_corners;     /**< 4 or 8 */
  int order;           /**< 1 (linear) or 2 (quadratic) */
  int complete_degree; /**< largest k with all polynomials of total degree <= k in the space */
  int max_degree;      /**< largest total degree of a function in the space (Hex8: 3, Hex20: 4) */
  int vtk_cell_type;   /**< VTK cell type id: 10, 24, 12, 25 */
  int stiffness_strength; /**< default quadrature strength for stiffness and force */
  int mass_strength;      /**< default strength for the consistent mass (degree of N_i N_j) */
  int mass_axis_degree;   /**< the default degree cap in each reference variable of the cut-cell
                               mass rules' moment space (fcm_cell_rules_options.axis_degree):
                               Hex8 2 (N_i N_j is trilinear times trilinear, in Q_2 ⊂ P_6: 27
                               moments instead of 84); mass_strength for the others (no cap) */
  int num_faces;          /**< 4 or 6 */
  /** Nodes of each face, corners first in counter-clockwise order seen from
   * outside (outward normal by the right-hand rule), then mid-edge nodes. */
  int face_num_nodes[FCM_ELEMENT_MAX_FACES];
  int face_num_corners[FCM_ELEMENT_MAX_FACES];
  int face_nodes[FCM_ELEMENT_MAX_FACES][FCM_ELEMENT_MAX_FACE_NODES];
  int num_edges; /**< 6 or 12 */
  /** Edge endpoints and mid-edge node (-1 for linear elements). */
  int edge_nodes[FCM_ELEMENT_MAX_EDGES][3];
} fcm_element_info;

/** Description of `type`, or NULL when `type` is not a valid element type. */
FCM_API const fcm_element_info *fcm_element_get_info(fcm_element_type type);

/** Find a type by name ("tet4", "Tet10", "HEX20", ...; case-insensitive).
 * @return FCM_OK or FCM_ERR_ARG (unknown name; *type unchanged). No allocation. */
FCM_API fcm_status fcm_element_type_from_name(const char *name, fcm_element_type *type);

/** Reference coordinates of the nodes (num_nodes x 3, row-major), or NULL. */
FCM_API const double *fcm_element_ref_nodes(fcm_element_type type);

/** Shape function values N[a] at reference point xi (N has num_nodes entries).
 * The type must be valid. No allocation; thread safe. */
FCM_API void fcm_element_eval_shape(fcm_element_type type, const double xi[3], double *N);

/** Reference gradients dN[3*a + d] = dN_a/dxi_d at xi. No allocation; thread safe. */
FCM_API void fcm_element_eval_grad(fcm_element_type type, const double xi[3], double *dN);

/** Geometric map x = sum_a N_a(xi) X_a for nodal coordinates X (num_nodes x 3). */
FCM_API void fcm_element_map(fcm_element_type type, const double *X, const double xi[3],
                             double x[3]);

/** Jacobian J[3*i + j] = dx_i/dxi_j of the geometric map at xi; returns det J. */
FCM_API double fcm_element_jacobian(fcm_element_type type, const double *X, const double xi[3],
                                    double J[9]);

/** Whether the geometric map of this cell is affine (constant Jacobian), within
 * a relative tolerance `rtol` of the cell size: always for Tet4; for Tet10 when
 * the mid-edge nodes are edge midpoints; for Hex8/Hex20 when the cell is a
 * parallelepiped (with mid-edge nodes at midpoints for Hex20). */
FCM_API int fcm_element_is_affine(fcm_element_type type, const double *X, double rtol);

/** Inverse map: find xi with x(xi) = x. Closed form for affine cells
 * (fcm_element_is_affine with rtol 1e-13); otherwise Newton from the reference
 * centroid with a backtracking (Armijo) line search.
 * @param[in]  ctx  error messages go here (may be NULL)
 * @param[in]  X    nodal coordinates, num_nodes x 3
 * @param[in]  x    physical point (may lie outside the cell)
 * @param[out] xi   reference coordinates
 * @return FCM_OK; FCM_ERR_ARG (invalid type, NULL or non-finite arguments);
 *         FCM_ERR_GEOMETRY when the cell is degenerate or the Jacobian is singular on the path;
 *         FCM_ERR_NOT_CONVERGED when |x(xi) - x| <= 1e-13 * cell size is not reached
 *         in 50 iterations (xi then holds the last iterate). No allocation. */
FCM_API fcm_status fcm_element_inverse_map(fcm_ctx *ctx, fcm_element_type type, const double *X,
                                           const double x[3], double xi[3]);

#ifdef __cplusplus
}
#endif
#endif /* FCM_ELEMENT_H */
