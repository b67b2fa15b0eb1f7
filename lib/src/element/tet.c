/* Shape functions of the linear (Tet4) and quadratic (Tet10) tetrahedra on the
 * unit tetrahedron, in barycentric form, VTK node ordering. */
#include "element/element_impl.h"

/* Barycentric coordinates L0 = 1 - x - y - z, L1 = x, L2 = y, L3 = z with
 * gradients dL0 = (-1,-1,-1), dL1 = e_x, dL2 = e_y, dL3 = e_z. */

void fcm__element_shape_tet4(const double xi[3], double N[4])
{
  N[0] = 1.0 - xi[0] - xi[1] - xi[2];
  N[1] = xi[0];
  N[2] = xi[1];
  N[3] = xi[2];
}

void fcm__element_grad_tet4(const double xi[3], double dN[12])
{
  (void)xi;
  dN[0] = -1.0, dN[1] = -1.0, dN[2] = -1.0;
  dN[3] = 1.0, dN[4] = 0.0, dN[5] = 0.0;
  dN[6] = 0.0, dN[7] = 1.0, dN[8] = 0.0;
  dN[9] = 0.0, dN[10] = 0.0, dN[11] = 1.0;
}

/* Tet10: corners N_i = L_i (2 L_i - 1); mid-edge node on edge (i, j): 4 L_i L_j.
 * Edges in VTK order: 4 (0,1), 5 (1,2), 6 (2,0), 7 (0,3), 8 (1,3), 9 (2,3). */
void fcm__element_shape_tet10(const double xi[3], double N[10])
{
  const double L0 = 1.0 - xi[0] - xi[1] - xi[2], L1 = xi[0], L2 = xi[1], L3 = xi[2];
  N[0] = L0 * (2.0 * L0 - 1.0);
  N[1] = L1 * (2.0 * L1 - 1.0);
  N[2] = L2 * (2.0 * L2 - 1.0);
  N[3] = L3 * (2.0 * L3 - 1.0);
  N[4] = 4.0 * L0 * L1;
  N[5] = 4.0 * L1 * L2;
  N[6] = 4.0 * L2 * L0;
  N[7] = 4.0 * L0 * L3;
  N[8] = 4.0 * L1 * L3;
  N[9] = 4.0 * L2 * L3;
}

/* dN_i = (4 L_i - 1) dL_i at corners; 4 (L_j dL_i + L_i dL_j) at mid-edge nodes. */
void fcm__element_grad_tet10(const double xi[3], double dN[30])
{
  const double L0 = 1.0 - xi[0] - xi[1] - xi[2], L1 = xi[0], L2 = xi[1], L3 = xi[2];
  const double c0 = 1.0 - 4.0 * L0;
  const double f0 = 4.0 * L0, f1 = 4.0 * L1, f2 = 4.0 * L2, f3 = 4.0 * L3;
  /* 0: (4 L0 - 1) (-1,-1,-1) */
  dN[0] = c0, dN[1] = c0, dN[2] = c0;
  /* 1..3 */
  dN[3] = f1 - 1.0, dN[4] = 0.0, dN[5] = 0.0;
  dN[6] = 0.0, dN[7] = f2 - 1.0, dN[8] = 0.0;
  dN[9] = 0.0, dN[10] = 0.0, dN[11] = f3 - 1.0;
  /* 4: 4 L0 L1 */
  dN[12] = f0 - f1, dN[13] = -f1, dN[14] = -f1;
  /* 5: 4 L1 L2 */
  dN[15] = f2, dN[16] = f1, dN[17] = 0.0;
  /* 6: 4 L2 L0 */
  dN[18] = -f2, dN[19] = f0 - f2, dN[20] = -f2;
  /* 7: 4 L0 L3 */
  dN[21] = -f3, dN[22] = -f3, dN[23] = f0 - f3;
  /* 8: 4 L1 L3 */
  dN[24] = f3, dN[25] = 0.0, dN[26] = f1;
  /* 9: 4 L2 L3 */
  dN[27] = 0.0, dN[28] = f3, dN[29] = f2;
}
