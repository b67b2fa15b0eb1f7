/* fcm element module, internal part: the per-type shape function kernels the
 * dispatching functions in element.c call, and small shared geometry helpers. */
#ifndef FCM_ELEMENT_IMPL_H
#define FCM_ELEMENT_IMPL_H

#include "fcm/element.h"

/* Shape values N[a] and reference gradients dN[3*a + d] of one element type at
 * the reference point xi (tet.c, hex.c). Straight-line code, no allocation. */
void fcm__element_shape_tet4(const double xi[3], double N[4]);
void fcm__element_grad_tet4(const double xi[3], double dN[12]);
void fcm__element_shape_tet10(const double xi[3], double N[10]);
void fcm__element_grad_tet10(const double xi[3], double dN[30]);
void fcm__element_shape_hex8(const double xi[3], double N[8]);
void fcm__element_grad_hex8(const double xi[3], double dN[24]);
void fcm__element_shape_hex20(const double xi[3], double N[20]);
void fcm__element_grad_hex20(const double xi[3], double dN[60]);

/* J[3*i + j] = sum_a X[3*a + i] dN[3*a + j] for n nodes (reference gradients dN
 * from fcm_element_eval_grad); returns det J. For callers that need both the
 * gradients and the Jacobian at a point without evaluating dN twice. */
double fcm__element_jacobian_from_grad(int n, const double *dN, const double *X, double J[9]);

/* Diagonal of the axis-aligned bounding box of the n nodes X (n x 3): the cell
 * size every relative geometric tolerance of the module refers to. */
double fcm__element_cell_size(int n, const double *X);

/* Affine map x = x0 + A (xi - xi0) through corner 0 and its three neighbours
 * (the corner-based map of the cell): A[3*i + j] = dx_i/dxi_j; xi0 is the
 * reference position of corner 0. The type must be valid. */
void fcm__element_corner_affine(fcm_element_type type, const double *X, double A[9], double xi0[3]);

#endif /* FCM_ELEMENT_IMPL_H */
