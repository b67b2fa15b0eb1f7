/* Conformance suite run once per element type (argv[1] = "tet4", "tet10", "hex8",
 * "hex20"): shape functions, polynomial space, map, inverse map, face/edge tables. */
#include "fcm/element.h"
#include "la/mat3.h"
#include "la/vec3.h"
#include "test.h"

#include <stdint.h>

#define NPTS      64    /* random points per check */
#define FD_H      1e-5  /* central difference step */
#define FD_RTOL   1e-7  /* tolerance of gradients against finite differences */
#define EXACT_TOL 1e-13 /* identities that hold up to round-off */
#define ROUNDTRIP 1e-12 /* inverse map round trip */

static const fcm_element_info *info;
static fcm_element_type type;
static int nn;
static const double *ref;

/* ---------------------------------------------------------------- helpers */

static uint64_t rng_state = 0x9e3779b97f4a7c15u;
static double urand(void) /* uniform in [0, 1) (xorshift64*) */
{
  rng_state ^= rng_state >> 12, rng_state ^= rng_state << 25, rng_state ^= rng_state >> 27;
  return (double)((rng_state * 2685821657736338717u) >> 11) * 0x1.0p-53;
}

/* Random point of the reference element, shrunk about the centroid by `scale`
 * (scale > 1 gives points outside the element). */
static void random_point(double scale, double xi[3])
{
  if (info->shape == FCM_SHAPE_HEX) {
    for (int d = 0; d < 3; d++)
      xi[d] = scale * (2.0 * urand() - 1.0);
    return;
  }
  double l[4], s = 0.0; /* barycentric coordinates of a uniform point */
  for (int k = 0; k < 4; k++)
    l[k] = -log(1.0 - urand()), s += l[k];
  for (int d = 0; d < 3; d++)
    xi[d] = 0.25 + scale * (l[d + 1] / s - 0.25);
}

static void centroid(double c[3])
{
  const double v = info->shape == FCM_SHAPE_HEX ? 0.0 : 0.25;
  c[0] = c[1] = c[2] = v;
}

/* ---------------------------------------------------------------- shape functions */

static void check_info(void)
{
  fcm_element_type t = FCM_ELEMENT_COUNT;
  TEST_TRUE(info->type == type);
  TEST_TRUE(fcm_shape_dim(info->shape) == 3);
  TEST_TRUE(info->num_corners == (info->shape == FCM_SHAPE_TET ? 4 : 8));
  TEST_TRUE(info->num_nodes == info->num_corners + (info->order == 2 ? info->num_edges : 0));
  TEST_TRUE(ref != NULL);
  /* name round trip, case-insensitive */
  char upper[16] = {0};
  for (int k = 0; info->name[k] && k < 15; k++)
    upper[k] =
        (char)(info->name[k] >= 'a' && info->name[k] <= 'z' ? info->name[k] - 32 : info->name[k]);
  TEST_TRUE(fcm_element_type_from_name(upper, &t) == FCM_OK && t == type);
  /* the consistent mass integrand N_i N_j has twice the largest degree */
  TEST_TRUE(info->mass_strength == 2 * info->max_degree);
  TEST_TRUE(info->complete_degree <= info->order && info->order <= info->max_degree);
}

static void check_partition_and_kronecker(void)
{
  double N[FCM_ELEMENT_MAX_NODES], dN[3 * FCM_ELEMENT_MAX_NODES], xi[3];
  for (int p = 0; p < NPTS; p++) {
    random_point(p < NPTS / 2 ? 1.0 : 1.5, xi);
    fcm_element_eval_shape(type, xi, N);
    fcm_element_eval_grad(type, xi, dN);
    double s = 0.0, g[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < nn; a++) {
      s += N[a];
      for (int d = 0; d < 3; d++)
        g[d] += dN[3 * a + d];
    }
    TEST_NEAR(s, 1.0, 0.0, EXACT_TOL);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(g[d], 0.0, 0.0, EXACT_TOL);
  }
  for (int a = 0; a < nn; a++) {
    fcm_element_eval_shape(type, ref + 3 * a, N);
    for (int b = 0; b < nn; b++)
      TEST_NEAR(N[b], a == b ? 1.0 : 0.0, 0.0, EXACT_TOL);
  }
}

static void check_gradients_fd(void)
{
  double dN[3 * FCM_ELEMENT_MAX_NODES], Np[FCM_ELEMENT_MAX_NODES], Nm[FCM_ELEMENT_MAX_NODES];
  double xi[3], xp[3], xm[3];
  for (int p = 0; p < NPTS; p++) {
    random_point(1.2, xi);
    fcm_element_eval_grad(type, xi, dN);
    for (int d = 0; d < 3; d++) {
      for (int e = 0; e < 3; e++)
        xp[e] = xm[e] = xi[e];
      xp[d] += FD_H, xm[d] -= FD_H;
      fcm_element_eval_shape(type, xp, Np);
      fcm_element_eval_shape(type, xm, Nm);
      for (int a = 0; a < nn; a++)
        TEST_NEAR(dN[3 * a + d], (Np[a] - Nm[a]) / (2.0 * FD_H), FD_RTOL, FD_RTOL);
    }
  }
}

/* ---------------------------------------------------------------- polynomial space */

typedef struct {
  int e[3];
} mono;

static double mono_eval(mono m, const double x[3])
{
  return pow(x[0], m.e[0]) * pow(x[1], m.e[1]) * pow(x[2], m.e[2]);
}

static void mono_grad(mono m, const double x[3], double g[3])
{
  for (int d = 0; d < 3; d++) {
    if (m.e[d] == 0) {
      g[d] = 0.0;
      continue;
    }
    mono q = m;
    q.e[d]--;
    g[d] = m.e[d] * mono_eval(q, x);
  }
}

/* The basis of the element's space, built from its definition (independent of
 * the shape function code): P_k on tets; Q1 on Hex8; serendipity S_2 on Hex20,
 * which is P_2 plus the monomials of degree 3 and 4 with superlinear degree <= 2
 * (at most one exponent equal to 2, all others <= 1). */
static int space_basis(mono *m)
{
  int n = 0;
  for (int a = 0; a <= 4; a++)
    for (int b = 0; b <= 4; b++)
      for (int c = 0; c <= 4; c++) {
        const int deg = a + b + c, sq = (a == 2) + (b == 2) + (c == 2);
        const int lin = (a <= 1) && (b <= 1) && (c <= 1);
        int in = 0;
        switch (type) {
        case FCM_ELEMENT_TET4:
          in = deg <= 1;
          break;
        case FCM_ELEMENT_TET10:
          in = deg <= 2;
          break;
        case FCM_ELEMENT_HEX8:
          in = lin;
          break;
        case FCM_ELEMENT_HEX20:
          in = deg <= 2 || (a <= 2 && b <= 2 && c <= 2 && sq <= 1);
          break;
        default:
          break;
        }
        if (in) m[n++] = (mono){{a, b, c}};
      }
  return n;
}

/* Largest interpolation error of monomial m (value and gradient) at random points. */
static double interpolation_error(mono m)
{
  double N[FCM_ELEMENT_MAX_NODES], dN[3 * FCM_ELEMENT_MAX_NODES], xi[3], v[FCM_ELEMENT_MAX_NODES];
  double err = 0.0;
  for (int a = 0; a < nn; a++)
    v[a] = mono_eval(m, ref + 3 * a);
  for (int p = 0; p < NPTS; p++) {
    random_point(1.0, xi);
    fcm_element_eval_shape(type, xi, N);
    fcm_element_eval_grad(type, xi, dN);
    double u = 0.0, g[3] = {0.0, 0.0, 0.0}, ge[3];
    for (int a = 0; a < nn; a++) {
      u += N[a] * v[a];
      for (int d = 0; d < 3; d++)
        g[d] += dN[3 * a + d] * v[a];
    }
    mono_grad(m, xi, ge);
    err = fmax(err, fabs(u - mono_eval(m, xi)));
    for (int d = 0; d < 3; d++)
      err = fmax(err, fabs(g[d] - ge[d]));
  }
  return err;
}

static void check_polynomial_space(void)
{
  mono m[64];
  const int n = space_basis(m);
  /* as many independent monomials as nodes: the space is exactly their span */
  TEST_TRUE(n == nn);
  int maxdeg = 0;
  for (int k = 0; k < n; k++) {
    const double err = interpolation_error(m[k]);
    if (!(err <= 1e-12))
      TEST_FAIL_("%s: monomial x^%d y^%d z^%d not reproduced (error %.3g)", info->name, m[k].e[0],
                 m[k].e[1], m[k].e[2], err);
    maxdeg =
        m[k].e[0] + m[k].e[1] + m[k].e[2] > maxdeg ? m[k].e[0] + m[k].e[1] + m[k].e[2] : maxdeg;
  }
  TEST_TRUE(maxdeg == info->max_degree);
  /* completeness: all of P_k in the space for k = complete_degree, not for k + 1 */
  const int k = info->complete_degree;
  for (int a = 0; a <= k; a++)
    for (int b = 0; a + b <= k; b++)
      for (int c = 0; a + b + c <= k; c++)
        TEST_TRUE(interpolation_error((mono){{a, b, c}}) <= 1e-12);
  /* a monomial outside the space must fail: the check is able to fail */
  TEST_TRUE(interpolation_error((mono){{k + 1, 0, 0}}) > 1e-3);
  if (type == FCM_ELEMENT_HEX20) TEST_TRUE(interpolation_error((mono){{2, 2, 0}}) > 1e-3);
}

/* ---------------------------------------------------------------- geometry */

/* Affine image of the reference nodes (rotation, stretch, shear, far-away offset)
 * and, with `distort` > 0, nodes perturbed by up to distort x cell size. */
static const double cell_A[9] = {1.3, 0.2, -0.1, 0.25, 0.9, 0.15, -0.2, 0.1, 1.1};
static const double cell_c[3] = {12.5, -3.0, 7.25};

static void affine(const double xi[3], double x[3])
{
  fcm__mat3_mulv(cell_A, xi, x);
  for (int d = 0; d < 3; d++)
    x[d] += cell_c[d];
}

static void make_cell(double distort, double *X)
{
  for (int a = 0; a < nn; a++) {
    affine(ref + 3 * a, X + 3 * a);
    for (int d = 0; d < 3; d++)
      X[3 * a + d] += distort > 0.0 ? distort * (2.0 * urand() - 1.0) : 0.0;
  }
}

static void check_map_and_jacobian(void)
{
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], x[3], xp[3], xm[3], xi[3], a[3], b[3];
  /* reference cell: identity map */
  for (int p = 0; p < 8; p++) {
    random_point(1.0, xi);
    fcm_element_map(type, ref, xi, x);
    const double det = fcm_element_jacobian(type, ref, xi, J);
    TEST_NEAR(det, 1.0, 0.0, EXACT_TOL);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(x[d], xi[d], 0.0, EXACT_TOL);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        TEST_NEAR(J[3 * i + j], i == j, 0.0, EXACT_TOL);
  }
  /* distorted cell: map interpolates the nodes; Jacobian against central differences */
  make_cell(0.05 * (info->shape == FCM_SHAPE_HEX ? 2.0 : 1.0), X);
  for (int k = 0; k < nn; k++) {
    fcm_element_map(type, X, ref + 3 * k, x);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(x[d], X[3 * k + d], 1e-14, 0.0);
  }
  for (int p = 0; p < NPTS; p++) {
    random_point(1.0, xi);
    const double det = fcm_element_jacobian(type, X, xi, J);
    TEST_TRUE(det > 0.0);
    TEST_NEAR(det, fcm__mat3_det(J), 1e-13, 0.0);
    for (int j = 0; j < 3; j++) {
      for (int e = 0; e < 3; e++)
        a[e] = b[e] = xi[e];
      a[j] += FD_H, b[j] -= FD_H;
      fcm_element_map(type, X, a, xp);
      fcm_element_map(type, X, b, xm);
      for (int i = 0; i < 3; i++)
        TEST_NEAR(J[3 * i + j], (xp[i] - xm[i]) / (2.0 * FD_H), FD_RTOL, FD_RTOL);
    }
  }
}

/* x = map(xi) at random xi, then xi = inverse(x); with `exact_affine` x comes
 * from the affine map the cell was made with (round-off free far outside). */
static void roundtrip(const double *X, double scale, int npts, int exact_affine)
{
  double xi[3], x[3], eta[3];
  for (int p = 0; p < npts; p++) {
    random_point(scale, xi);
    if (exact_affine)
      affine(xi, x);
    else
      fcm_element_map(type, X, xi, x);
    fcm_status st = fcm_element_inverse_map(NULL, type, X, x, eta);
    TEST_TRUE(st == FCM_OK);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(eta[d], xi[d], 0.0, ROUNDTRIP);
  }
}

static void check_inverse_map(void)
{
  double X[3 * FCM_ELEMENT_MAX_NODES], c[3], x[3], eta[3];
  /* affine cell: the closed-form path, also far outside the element */
  make_cell(0.0, X);
  TEST_TRUE(fcm_element_is_affine(type, X, 1e-12));
  roundtrip(X, 1.0, NPTS, 0);
  roundtrip(X, 10.0, NPTS, 1);
  for (int k = 0; k < nn; k++) {
    TEST_TRUE(fcm_element_inverse_map(NULL, type, X, X + 3 * k, eta) == FCM_OK);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(eta[d], ref[3 * k + d], 0.0, ROUNDTRIP);
  }
  /* distorted (non-affine except Tet4): Newton, inside and slightly outside */
  make_cell(info->shape == FCM_SHAPE_HEX ? 0.15 : 0.08, X);
  TEST_TRUE(fcm_element_is_affine(type, X, 1e-6) == (type == FCM_ELEMENT_TET4));
  roundtrip(X, 1.0, NPTS, 0);
  roundtrip(X, 1.2, NPTS, 0);
  centroid(c);
  fcm_element_map(type, X, c, x);
  TEST_TRUE(fcm_element_inverse_map(NULL, type, X, x, eta) == FCM_OK);
  for (int d = 0; d < 3; d++)
    TEST_NEAR(eta[d], c[d], 0.0, ROUNDTRIP);
  /* affine corners but curved edges (quadratic elements): not affine */
  if (info->order == 2) {
    make_cell(0.0, X);
    X[3 * (nn - 1)] += 0.05;
    TEST_TRUE(!fcm_element_is_affine(type, X, 1e-6));
    roundtrip(X, 1.0, 16, 0);
  }
}

/* ---------------------------------------------------------------- faces and edges */

static int edge_index(int a, int b) /* index in the edge table, or -1 */
{
  for (int e = 0; e < info->num_edges; e++) {
    const int *en = info->edge_nodes[e];
    if ((en[0] == a && en[1] == b) || (en[0] == b && en[1] == a)) return e;
  }
  return -1;
}

static void check_faces(void)
{
  double c[3];
  centroid(c);
  TEST_TRUE(info->num_faces == (info->shape == FCM_SHAPE_TET ? 4 : 6));
  TEST_TRUE(info->num_edges == (info->shape == FCM_SHAPE_TET ? 6 : 12));
  TEST_TRUE(info->num_corners - info->num_edges + info->num_faces == 2); /* Euler */
  int directed[FCM_ELEMENT_MAX_EDGES][2] = {{0}}; /* uses of each edge as (a->b), (b->a) */
  for (int f = 0; f < info->num_faces; f++) {
    const int nc = info->face_num_corners[f], nf = info->face_num_nodes[f];
    const int *fn = info->face_nodes[f];
    TEST_TRUE(nc == (info->shape == FCM_SHAPE_TET ? 3 : 4));
    TEST_TRUE(nf == (info->order == 2 ? 2 * nc : nc));
    for (int k = nf; k < FCM_ELEMENT_MAX_FACE_NODES; k++)
      TEST_TRUE(fn[k] == -1);
    for (int k = 0; k < nf; k++)
      if (fn[k] < 0 || fn[k] >= nn || (k < nc && fn[k] >= info->num_corners)) {
        TEST_FAIL_("%s face %d: node %d invalid", info->name, f, fn[k]);
        return;
      }
    /* normal by the right-hand rule from the corner cycle (Newell's formula) */
    double n[3] = {0.0, 0.0, 0.0}, t[3];
    for (int k = 0; k < nc; k++) {
      fcm__vec3_cross(ref + 3 * fn[k], ref + 3 * fn[(k + 1) % nc], t);
      for (int d = 0; d < 3; d++)
        n[d] += t[d];
    }
    const double *p0 = ref + 3 * fn[0];
    double v[3];
    fcm__vec3_sub(p0, c, v);
    TEST_TRUE(fcm__vec3_dot(n, v) > 0.1); /* outward */
    /* exactly the face nodes lie on the face plane; every other node inside */
    for (int a = 0; a < nn; a++) {
      int on = 0;
      for (int k = 0; k < nf; k++)
        on |= fn[k] == a;
      fcm__vec3_sub(ref + 3 * a, p0, v);
      const double s = fcm__vec3_dot(n, v);
      if (on)
        TEST_NEAR(s, 0.0, 0.0, EXACT_TOL); /* coplanar */
      else
        TEST_TRUE(s < -0.1);
    }
    /* convex, counter-clockwise corner cycle: every corner turns the same way */
    for (int k = 0; k < nc; k++) {
      double e1[3], e2[3];
      fcm__vec3_sub(ref + 3 * fn[(k + 1) % nc], ref + 3 * fn[k], e1);
      fcm__vec3_sub(ref + 3 * fn[(k + 2) % nc], ref + 3 * fn[(k + 1) % nc], e2);
      fcm__vec3_cross(e1, e2, t);
      TEST_TRUE(fcm__vec3_dot(t, n) > 0.0);
    }
    /* face edges are element edges; node nc + k is the mid-edge node of (k, k+1) */
    for (int k = 0; k < nc; k++) {
      const int a = fn[k], b = fn[(k + 1) % nc], e = edge_index(a, b);
      TEST_TRUE(e >= 0);
      if (e < 0) continue;
      directed[e][info->edge_nodes[e][0] == a ? 0 : 1]++;
      if (info->order == 2) {
        TEST_TRUE(fn[nc + k] == info->edge_nodes[e][2]);
        for (int d = 0; d < 3; d++)
          TEST_NEAR(ref[3 * fn[nc + k] + d], 0.5 * (ref[3 * a + d] + ref[3 * b + d]), 0.0, 0.0);
      }
    }
  }
  /* closed, consistently oriented surface: each edge once in each direction */
  for (int e = 0; e < info->num_edges; e++)
    TEST_TRUE(directed[e][0] == 1 && directed[e][1] == 1);
}

static void check_edges(void)
{
  int seen[FCM_ELEMENT_MAX_NODES] = {0};
  for (int e = 0; e < info->num_edges; e++) {
    const int a = info->edge_nodes[e][0], b = info->edge_nodes[e][1], m = info->edge_nodes[e][2];
    TEST_TRUE(a >= 0 && a < info->num_corners && b >= 0 && b < info->num_corners && a != b);
    TEST_TRUE(edge_index(a, b) == e); /* no duplicates */
    if (info->order == 1) {
      TEST_TRUE(m == -1);
      continue;
    }
    TEST_TRUE(m >= info->num_corners && m < nn);
    if (m < info->num_corners || m >= nn) continue;
    seen[m]++;
    TEST_TRUE(m == info->num_corners + e); /* VTK: mid-edge nodes in edge order */
    for (int d = 0; d < 3; d++)
      TEST_NEAR(ref[3 * m + d], 0.5 * (ref[3 * a + d] + ref[3 * b + d]), 0.0, 0.0);
  }
  for (int m = info->num_corners; m < nn; m++)
    TEST_TRUE(seen[m] == 1);
  /* an edge joins corners differing in exactly one coordinate (hex) / any pair (tet) */
  for (int e = 0; e < info->num_edges; e++) {
    const double *pa = ref + 3 * info->edge_nodes[e][0], *pb = ref + 3 * info->edge_nodes[e][1];
    int diff = 0;
    for (int d = 0; d < 3; d++)
      diff += pa[d] != pb[d];
    TEST_TRUE(info->shape == FCM_SHAPE_TET || diff == 1);
  }
}

int main(int argc, char **argv)
{
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) {
    fprintf(stderr, "usage: %s tet4|tet10|hex8|hex20\n", argv[0]);
    return 2;
  }
  info = fcm_element_get_info(type);
  nn = info->num_nodes;
  ref = fcm_element_ref_nodes(type);
  check_info();
  check_partition_and_kronecker();
  check_gradients_fd();
  check_polynomial_space();
  check_map_and_jacobian();
  check_inverse_map();
  check_faces();
  check_edges();
  return TEST_RESULT();
}
