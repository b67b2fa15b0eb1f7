/* Shared helpers of the mesh tests: VTK edge tables written out independently of the
 * element module, cell volume by simple exact rules, face keys, a failing allocator. */
#ifndef FCM_TEST_MESH_UTIL_H
#define FCM_TEST_MESH_UTIL_H

#include "fcm/mesh.h"
#include "test.h"
#include "test_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* VTK mid-edge nodes: {mid, end a, end b}. */
static const int vtk_tet10_edges[6][3] = {{4, 0, 1}, {5, 1, 2}, {6, 2, 0},
                                          {7, 0, 3}, {8, 1, 3}, {9, 2, 3}};
static const int vtk_hex20_edges[12][3] = {{8, 0, 1},  {9, 1, 2},  {10, 2, 3}, {11, 3, 0},
                                           {12, 4, 5}, {13, 5, 6}, {14, 6, 7}, {15, 7, 4},
                                           {16, 0, 4}, {17, 1, 5}, {18, 2, 6}, {19, 3, 7}};

/* Mid-edge table of a quadratic type (count in *n), NULL for linear types. */
static inline const int (*vtk_mid_edges(fcm_element_type t, int *n))[3]
{
  *n = t == FCM_ELEMENT_TET10 ? 6 : t == FCM_ELEMENT_HEX20 ? 12 : 0;
  return t == FCM_ELEMENT_TET10 ? vtk_tet10_edges : t == FCM_ELEMENT_HEX20 ? vtk_hex20_edges : NULL;
}

static inline int is_tet_type(fcm_element_type t)
{
  return t == FCM_ELEMENT_TET4 || t == FCM_ELEMENT_TET10;
}

/* Volume of a cell with an affine (tets) or trilinear-or-affine (hexes) map: one-point
 * rule at the tet centroid (weight 1/6) or the 2x2x2 Gauss rule on [-1,1]^3, both exact
 * for det J of those maps. */
static inline double cell_volume(fcm_element_type t, const double *X)
{
  double J[9];
  if (is_tet_type(t)) {
    const double xi[3] = {0.25, 0.25, 0.25};
    return fcm_element_jacobian(t, X, xi, J) / 6.0;
  }
  const double g = 1.0 / sqrt(3.0);
  double v = 0.0;
  for (int i = 0; i < 8; i++) {
    const double xi[3] = {(i & 1) ? g : -g, (i & 2) ? g : -g, (i & 4) ? g : -g};
    v += fcm_element_jacobian(t, X, xi, J);
  }
  return v;
}

/* Newell area vector of a polygon given by corner coordinates (outward for CCW). */
static inline void polygon_area_vector(int n, const double *P, double a[3])
{
  a[0] = a[1] = a[2] = 0.0;
  for (int k = 0; k < n; k++) {
    const double *p = P + 3 * k, *q = P + 3 * ((k + 1) % n);
    a[0] += 0.5 * (p[1] * q[2] - p[2] * q[1]);
    a[1] += 0.5 * (p[2] * q[0] - p[0] * q[2]);
    a[2] += 0.5 * (p[0] * q[1] - p[1] * q[0]);
  }
}

/* Write a text file; returns 0 on success. */
static inline int write_text(const char *path, const char *text)
{
  FILE *fp = fopen(path, "w");
  if (!fp) return 1;
  int bad = fputs(text, fp) < 0;
  bad |= fclose(fp) != 0;
  return bad;
}

#endif
