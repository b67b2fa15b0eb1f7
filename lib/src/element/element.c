/* Element type tables (nodes, faces, edges, degrees, quadrature strengths),
 * reference shapes, and the dispatching evaluation, map and Jacobian functions. */
#include "element/element_impl.h"
#include "core/core_impl.h"
#include "la/mat3.h"

#include <math.h>

/* ---------------------------------------------------------------- shapes */

const char *fcm_shape_name(fcm_shape shape)
{
  switch (shape) {
  case FCM_SHAPE_LINE:
    return "line";
  case FCM_SHAPE_TRI:
    return "tri";
  case FCM_SHAPE_QUAD:
    return "quad";
  case FCM_SHAPE_TET:
    return "tet";
  case FCM_SHAPE_HEX:
    return "hex";
  default:
    return "unknown";
  }
}

int fcm_shape_dim(fcm_shape shape)
{
  switch (shape) {
  case FCM_SHAPE_LINE:
    return 1;
  case FCM_SHAPE_TRI:
  case FCM_SHAPE_QUAD:
    return 2;
  case FCM_SHAPE_TET:
  case FCM_SHAPE_HEX:
    return 3;
  default:
    return 0;
  }
}

double fcm_shape_measure(fcm_shape shape)
{
  switch (shape) {
  case FCM_SHAPE_LINE:
    return 2.0;
  case FCM_SHAPE_TRI:
    return 0.5;
  case FCM_SHAPE_QUAD:
    return 4.0;
  case FCM_SHAPE_TET:
    return 1.0 / 6.0;
  case FCM_SHAPE_HEX:
    return 8.0;
  default:
    return 0.0;
  }
}

/* ---------------------------------------------------------------- tables */

/* Faces follow VTK's vtkTetra / vtkHexahedron face lists, which are outward
 * oriented; mid-edge nodes follow the corner cycle: node nc + k lies on the
 * face edge (corner k, corner k+1 mod nc). Unused entries are -1. */
#define TET_FACES_ .num_faces = 4, .face_num_corners = {3, 3, 3, 3}, .num_edges = 6

#define HEX_FACES_ .num_faces = 6, .face_num_corners = {4, 4, 4, 4, 4, 4}, .num_edges = 12

static const fcm_element_info infos[FCM_ELEMENT_COUNT] = {
    [FCM_ELEMENT_TET4] =
        {.type = FCM_ELEMENT_TET4,
         .name = "tet4",
         .shape = FCM_SHAPE_TET,
         .num_nodes = 4,
         .num_corners = 4,
         .order = 1,
         .complete_degree = 1,
         .max_degree = 1,
         .vtk_cell_type = 10,
         .stiffness_strength = 2,
         .mass_strength = 2,
         .mass_axis_degree = 2,
         TET_FACES_,
         .face_num_nodes = {3, 3, 3, 3},
         .face_nodes = {{0, 1, 3, -1, -1, -1, -1, -1},
                        {1, 2, 3, -1, -1, -1, -1, -1},
                        {2, 0, 3, -1, -1, -1, -1, -1},
                        {0, 2, 1, -1, -1, -1, -1, -1}},
         .edge_nodes = {{0, 1, -1}, {1, 2, -1}, {2, 0, -1}, {0, 3, -1}, {1, 3, -1}, {2, 3, -1}}},
    [FCM_ELEMENT_TET10] = {.type = FCM_ELEMENT_TET10,
                           .name = "tet10",
                           .shape = FCM_SHAPE_TET,
                           .num_nodes = 10,
                           .num_corners = 4,
                           .order = 2,
                           .complete_degree = 2,
                           .max_degree = 2,
                           .vtk_cell_type = 24,
                           .stiffness_strength = 3,
                           .mass_strength = 4,
                           .mass_axis_degree = 4,
                           TET_FACES_,
                           .face_num_nodes = {6, 6, 6, 6},
                           .face_nodes = {{0, 1, 3, 4, 8, 7, -1, -1},
                                          {1, 2, 3, 5, 9, 8, -1, -1},
                                          {2, 0, 3, 6, 7, 9, -1, -1},
                                          {0, 2, 1, 6, 5, 4, -1, -1}},
                           .edge_nodes =
                               {{0, 1, 4}, {1, 2, 5}, {2, 0, 6}, {0, 3, 7}, {1, 3, 8}, {2, 3, 9}}},
    [FCM_ELEMENT_HEX8] = {.type = FCM_ELEMENT_HEX8,
                          .name = "hex8",
                          .shape = FCM_SHAPE_HEX,
                          .num_nodes = 8,
                          .num_corners = 8,
                          .order = 1,
                          .complete_degree = 1,
                          .max_degree = 3,
                          .vtk_cell_type = 12,
                          .stiffness_strength = 2,
                          .mass_strength = 6,
                          .mass_axis_degree = 2,
                          HEX_FACES_,
                          .face_num_nodes = {4, 4, 4, 4, 4, 4},
                          .face_nodes = {{0, 4, 7, 3, -1, -1, -1, -1},
                                         {1, 2, 6, 5, -1, -1, -1, -1},
                                         {0, 1, 5, 4, -1, -1, -1, -1},
                                         {3, 7, 6, 2, -1, -1, -1, -1},
                                         {0, 3, 2, 1, -1, -1, -1, -1},
                                         {4, 5, 6, 7, -1, -1, -1, -1}},
                          .edge_nodes = {{0, 1, -1},
                                         {1, 2, -1},
                                         {2, 3, -1},
                                         {3, 0, -1},
                                         {4, 5, -1},
                                         {5, 6, -1},
                                         {6, 7, -1},
                                         {7, 4, -1},
                                         {0, 4, -1},
                                         {1, 5, -1},
                                         {2, 6, -1},
                                         {3, 7, -1}}},
    [FCM_ELEMENT_HEX20] = {.type = FCM_ELEMENT_HEX20,
                           .name = "hex20",
                           .shape = FCM_SHAPE_HEX,
                           .num_nodes = 20,
                           .num_corners = 8,
                           .order = 2,
                           .complete_degree = 2,
                           .max_degree = 4,
                           .vtk_cell_type = 25,
                           .stiffness_strength = 4,
                           .mass_strength = 8,
                           .mass_axis_degree = 8,
                           HEX_FACES_,
                           .face_num_nodes = {8, 8, 8, 8, 8, 8},
                           .face_nodes = {{0, 4, 7, 3, 16, 15, 19, 11},
                                          {1, 2, 6, 5, 9, 18, 13, 17},
                                          {0, 1, 5, 4, 8, 17, 12, 16},
                                          {3, 7, 6, 2, 19, 14, 18, 10},
                                          {0, 3, 2, 1, 11, 10, 9, 8},
                                          {4, 5, 6, 7, 12, 13, 14, 15}},
                           .edge_nodes = {{0, 1, 8},
                                          {1, 2, 9},
                                          {2, 3, 10},
                                          {3, 0, 11},
                                          {4, 5, 12},
                                          {5, 6, 13},
                                          {6, 7, 14},
                                          {7, 4, 15},
                                          {0, 4, 16},
                                          {1, 5, 17},
                                          {2, 6, 18},
                                          {3, 7, 19}}},
};

static const double tet_nodes[10 * 3] = {
    0.0, 0.0, 0.0, /* 0 */
    1.0, 0.0, 0.0, /* 1 */
    0.0, 1.0, 0.0, /* 2 */
    0.0, 0.0, 1.0, /* 3 */
    0.5, 0.0, 0.0, /* 4 (0,1) */
    0.5, 0.5, 0.0, /* 5 (1,2) */
    0.0, 0.5, 0.0, /* 6 (2,0) */
    0.0, 0.0, 0.5, /* 7 (0,3) */
    0.5, 0.0, 0.5, /* 8 (1,3) */
    0.0, 0.5, 0.5, /* 9 (2,3) */
};

static const double hex_nodes[20 * 3] = {
    -1.0, -1.0, -1.0, /* 0 */
    1.0,  -1.0, -1.0, /* 1 */
    1.0,  1.0,  -1.0, /* 2 */
    -1.0, 1.0,  -1.0, /* 3 */
    -1.0, -1.0, 1.0,  /* 4 */
    1.0,  -1.0, 1.0,  /* 5 */
    1.0,  1.0,  1.0,  /* 6 */
    -1.0, 1.0,  1.0,  /* 7 */
    0.0,  -1.0, -1.0, /* 8 (0,1) */
    1.0,  0.0,  -1.0, /* 9 (1,2) */
    0.0,  1.0,  -1.0, /* 10 (2,3) */
    -1.0, 0.0,  -1.0, /* 11 (3,0) */
    0.0,  -1.0, 1.0,  /* 12 (4,5) */
    1.0,  0.0,  1.0,  /* 13 (5,6) */
    0.0,  1.0,  1.0,  /* 14 (6,7) */
    -1.0, 0.0,  1.0,  /* 15 (7,4) */
    -1.0, -1.0, 0.0,  /* 16 (0,4) */
    1.0,  -1.0, 0.0,  /* 17 (1,5) */
    1.0,  1.0,  0.0,  /* 18 (2,6) */
    -1.0, 1.0,  0.0,  /* 19 (3,7) */
};

static int valid_type(fcm_element_type type)
{
  return (unsigned)type < (unsigned)FCM_ELEMENT_COUNT;
}

const fcm_element_info *fcm_element_get_info(fcm_element_type type)
{
  return valid_type(type) ? &infos[type] : NULL;
}

static int lower(int c)
{
  return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c;
}

static int same_name(const char *a, const char *b)
{
  for (; *a && *b; a++, b++)
    if (lower((unsigned char)*a) != lower((unsigned char)*b)) return 0;
  return *a == *b;
}

fcm_status fcm_element_type_from_name(const char *name, fcm_element_type *type)
{
  if (!name || !type) return FCM_ERR_ARG;
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++) {
    if (same_name(name, infos[t].name)) {
      *type = (fcm_element_type)t;
      return FCM_OK;
    }
  }
  return FCM_ERR_ARG;
}

const double *fcm_element_ref_nodes(fcm_element_type type)
{
  switch (type) {
  case FCM_ELEMENT_TET4:
  case FCM_ELEMENT_TET10:
    return tet_nodes;
  case FCM_ELEMENT_HEX8:
  case FCM_ELEMENT_HEX20:
    return hex_nodes;
  default:
    return NULL;
  }
}

/* ---------------------------------------------------------------- evaluation */

void fcm_element_eval_shape(fcm_element_type type, const double xi[3], double *N)
{
  switch (type) {
  case FCM_ELEMENT_TET4:
    fcm__element_shape_tet4(xi, N);
    break;
  case FCM_ELEMENT_TET10:
    fcm__element_shape_tet10(xi, N);
    break;
  case FCM_ELEMENT_HEX8:
    fcm__element_shape_hex8(xi, N);
    break;
  case FCM_ELEMENT_HEX20:
    fcm__element_shape_hex20(xi, N);
    break;
  default:
    break;
  }
}

void fcm_element_eval_grad(fcm_element_type type, const double xi[3], double *dN)
{
  switch (type) {
  case FCM_ELEMENT_TET4:
    fcm__element_grad_tet4(xi, dN);
    break;
  case FCM_ELEMENT_TET10:
    fcm__element_grad_tet10(xi, dN);
    break;
  case FCM_ELEMENT_HEX8:
    fcm__element_grad_hex8(xi, dN);
    break;
  case FCM_ELEMENT_HEX20:
    fcm__element_grad_hex20(xi, dN);
    break;
  default:
    break;
  }
}

/* x = sum_a N_a X_a; called with a literal n so that the loop is unrolled. */
static inline void combine(int n, const double *N, const double *X, double x[3])
{
  double x0 = 0.0, x1 = 0.0, x2 = 0.0;
  for (int a = 0; a < n; a++) {
    x0 += N[a] * X[3 * a];
    x1 += N[a] * X[3 * a + 1];
    x2 += N[a] * X[3 * a + 2];
  }
  x[0] = x0, x[1] = x1, x[2] = x2;
}

/* J[3*i + j] = sum_a X[3*a + i] dN[3*a + j]; returns det J. */
static inline double jacobian(int n, const double *dN, const double *X, double J[9])
{
  double j0 = 0.0, j1 = 0.0, j2 = 0.0, j3 = 0.0, j4 = 0.0, j5 = 0.0, j6 = 0.0, j7 = 0.0, j8 = 0.0;
  for (int a = 0; a < n; a++) {
    const double g0 = dN[3 * a], g1 = dN[3 * a + 1], g2 = dN[3 * a + 2];
    const double p0 = X[3 * a], p1 = X[3 * a + 1], p2 = X[3 * a + 2];
    j0 += p0 * g0, j1 += p0 * g1, j2 += p0 * g2;
    j3 += p1 * g0, j4 += p1 * g1, j5 += p1 * g2;
    j6 += p2 * g0, j7 += p2 * g1, j8 += p2 * g2;
  }
  J[0] = j0, J[1] = j1, J[2] = j2, J[3] = j3, J[4] = j4, J[5] = j5, J[6] = j6, J[7] = j7, J[8] = j8;
  return fcm__mat3_det(J);
}

/* Tet10 Jacobian without forming dN (see tet.c, f_i = 4 L_i, c0 = 1 - 4 L0):
 * dx/dxi   = c0 X0 + (f1-1) X1 + (f0-f1) X4 + f2 (X5-X6) + f3 (X8-X7)
 * dx/deta  = c0 X0 + (f2-1) X2 + (f0-f2) X6 + f1 (X5-X4) + f3 (X9-X7)
 * dx/dzeta = c0 X0 + (f3-1) X3 + (f0-f3) X7 + f1 (X8-X4) + f2 (X9-X6) */
static double jacobian_tet10(const double *X, const double xi[3], double J[9])
{
  const double L0 = 1.0 - xi[0] - xi[1] - xi[2];
  const double f0 = 4.0 * L0, f1 = 4.0 * xi[0], f2 = 4.0 * xi[1], f3 = 4.0 * xi[2];
  const double c0 = 1.0 - f0;
  for (int i = 0; i < 3; i++) {
    const double *P = X + i; /* P[3*a] = component i of node a */
    const double x0 = c0 * P[0], x4 = P[12], x5 = P[15], x6 = P[18], x7 = P[21], x8 = P[24],
                 x9 = P[27];
    J[3 * i + 0] = x0 + (f1 - 1.0) * P[3] + (f0 - f1) * x4 + f2 * (x5 - x6) + f3 * (x8 - x7);
    J[3 * i + 1] = x0 + (f2 - 1.0) * P[6] + (f0 - f2) * x6 + f1 * (x5 - x4) + f3 * (x9 - x7);
    J[3 * i + 2] = x0 + (f3 - 1.0) * P[9] + (f0 - f3) * x7 + f1 * (x8 - x4) + f2 * (x9 - x6);
  }
  return fcm__mat3_det(J);
}

/* Hex8 Jacobian from edge differences (xm = 1 - xi, xp = 1 + xi, ...):
 * dx/dxi = [ym zm (X1-X0) + yp zm (X2-X3) + ym zp (X5-X4) + yp zp (X6-X7)] / 8, etc. */
static double jacobian_hex8(const double *X, const double xi[3], double J[9])
{
  const double xm = 1.0 - xi[0], xp = 1.0 + xi[0];
  const double ym = 1.0 - xi[1], yp = 1.0 + xi[1];
  const double zm = 0.125 * (1.0 - xi[2]), zp = 0.125 * (1.0 + xi[2]);
  const double ymzm = ym * zm, ypzm = yp * zm, ymzp = ym * zp, ypzp = yp * zp;
  const double xmzm = xm * zm, xpzm = xp * zm, xmzp = xm * zp, xpzp = xp * zp;
  const double xmym = 0.125 * xm * ym, xpym = 0.125 * xp * ym, xpyp = 0.125 * xp * yp,
               xmyp = 0.125 * xm * yp;
  for (int i = 0; i < 3; i++) {
    const double *P = X + i;
    const double p0 = P[0], p1 = P[3], p2 = P[6], p3 = P[9], p4 = P[12], p5 = P[15], p6 = P[18],
                 p7 = P[21];
    J[3 * i + 0] = ymzm * (p1 - p0) + ypzm * (p2 - p3) + ymzp * (p5 - p4) + ypzp * (p6 - p7);
    J[3 * i + 1] = xmzm * (p3 - p0) + xpzm * (p2 - p1) + xmzp * (p7 - p4) + xpzp * (p6 - p5);
    J[3 * i + 2] = xmym * (p4 - p0) + xpym * (p5 - p1) + xpyp * (p6 - p2) + xmyp * (p7 - p3);
  }
  return fcm__mat3_det(J);
}

double fcm__element_jacobian_from_grad(int n, const double *dN, const double *X, double J[9])
{
  return jacobian(n, dN, X, J);
}

void fcm_element_map(fcm_element_type type, const double *X, const double xi[3], double x[3])
{
  double N[FCM_ELEMENT_MAX_NODES];
  switch (type) {
  case FCM_ELEMENT_TET4: /* X0 + xi (X1 - X0) + eta (X2 - X0) + zeta (X3 - X0) */
    for (int i = 0; i < 3; i++)
      x[i] =
          X[i] + xi[0] * (X[3 + i] - X[i]) + xi[1] * (X[6 + i] - X[i]) + xi[2] * (X[9 + i] - X[i]);
    break;
  case FCM_ELEMENT_TET10:
    fcm__element_shape_tet10(xi, N);
    combine(10, N, X, x);
    break;
  case FCM_ELEMENT_HEX8: { /* trilinear: weights of the bottom and top faces */
    const double xm = 1.0 - xi[0], xp = 1.0 + xi[0], ym = 1.0 - xi[1], yp = 1.0 + xi[1];
    const double zm = 0.125 * (1.0 - xi[2]), zp = 0.125 * (1.0 + xi[2]);
    const double w0 = xm * ym, w1 = xp * ym, w2 = xp * yp, w3 = xm * yp;
    for (int i = 0; i < 3; i++) {
      const double *P = X + i;
      x[i] = zm * (w0 * P[0] + w1 * P[3] + w2 * P[6] + w3 * P[9]) +
             zp * (w0 * P[12] + w1 * P[15] + w2 * P[18] + w3 * P[21]);
    }
  } break;
  case FCM_ELEMENT_HEX20:
    fcm__element_shape_hex20(xi, N);
    combine(20, N, X, x);
    break;
  default:
    break;
  }
}

double fcm_element_jacobian(fcm_element_type type, const double *X, const double xi[3], double J[9])
{
  double dN[3 * FCM_ELEMENT_MAX_NODES];
  switch (type) {
  case FCM_ELEMENT_TET4:
    /* constant: the columns are the edge vectors from node 0 */
    for (int i = 0; i < 3; i++) {
      J[3 * i + 0] = X[3 + i] - X[i];
      J[3 * i + 1] = X[6 + i] - X[i];
      J[3 * i + 2] = X[9 + i] - X[i];
    }
    return fcm__mat3_det(J);
  case FCM_ELEMENT_TET10:
    return jacobian_tet10(X, xi, J);
  case FCM_ELEMENT_HEX8:
    return jacobian_hex8(X, xi, J);
  case FCM_ELEMENT_HEX20:
    fcm__element_grad_hex20(xi, dN);
    return jacobian(20, dN, X, J);
  default:
    return 0.0;
  }
}

/* ---------------------------------------------------------------- geometry helpers */

double fcm__element_cell_size(int n, const double *X)
{
  double lo[3] = {X[0], X[1], X[2]}, hi[3] = {X[0], X[1], X[2]};
  for (int a = 1; a < n; a++) {
    for (int d = 0; d < 3; d++) {
      const double v = X[3 * a + d];
      lo[d] = v < lo[d] ? v : lo[d];
      hi[d] = v > hi[d] ? v : hi[d];
    }
  }
  const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
  return sqrt(dx * dx + dy * dy + dz * dz);
}

void fcm__element_corner_affine(fcm_element_type type, const double *X, double A[9], double xi0[3])
{
  /* Neighbours of corner 0 along xi, eta, zeta and the reference edge length. */
  const int tet = (type == FCM_ELEMENT_TET4 || type == FCM_ELEMENT_TET10);
  const int nb[3] = {1, tet ? 2 : 3, tet ? 3 : 4};
  const double s = tet ? 1.0 : 0.5;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      A[3 * i + j] = s * (X[3 * nb[j] + i] - X[i]);
  const double r = tet ? 0.0 : -1.0;
  xi0[0] = r, xi0[1] = r, xi0[2] = r;
}

int fcm_element_is_affine(fcm_element_type type, const double *X, double rtol)
{
  if (!valid_type(type)) return 0;
  if (type == FCM_ELEMENT_TET4) return 1;
  const int n = infos[type].num_nodes;
  const double *ref = fcm_element_ref_nodes(type);
  double A[9], xi0[3];
  fcm__element_corner_affine(type, X, A, xi0);
  const double tol = rtol * fcm__element_cell_size(n, X);
  for (int a = 1; a < n; a++) {
    const double d0 = ref[3 * a] - xi0[0], d1 = ref[3 * a + 1] - xi0[1],
                 d2 = ref[3 * a + 2] - xi0[2];
    double dev = 0.0;
    for (int i = 0; i < 3; i++) {
      const double e = X[i] + A[3 * i] * d0 + A[3 * i + 1] * d1 + A[3 * i + 2] * d2 - X[3 * a + i];
      dev += e * e;
    }
    if (!(sqrt(dev) <= tol)) return 0;
  }
  return 1;
}
