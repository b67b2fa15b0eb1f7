/* Convex clipping: the unit cube cut by x+y+z <= s has the analytic volume; a body cut by
 * a plane and by its opposite splits volume and first moments exactly; a tet clipped by a
 * rotated box's planes reproduces the moments of the independent polytope integration;
 * on-plane vertices, coplanar faces and tolerance cases give the unchanged body or
 * nothing; polygons clip like polyhedra, with coplanar triangles kept by orientation; a
 * sliver with a flat flap splits into halves that add up to it; a tiny face found on a
 * plane leaves the cross-section around it closed. */
#include "geom/geom_impl.h"
#include "exact.h"
#include "test.h"

static fcm__poly P, S; /* ~25 kB each */

static void unit_cube(fcm__poly *p)
{
  static const double X[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                               0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  fcm__geom_poly_from_cell(FCM_ELEMENT_HEX8, X, p);
}

static fcm__plane plane(double nx, double ny, double nz, double d)
{
  const double l = sqrt(nx * nx + ny * ny + nz * nz);
  fcm__plane pl = {{nx / l, ny / l, nz / l}, d / l};
  return pl;
}

/* Moments of degree <= 1 (volume, first moments) of p from its fan tets. */
static void poly_moments(const fcm__poly *p, double mom[4])
{
  static double tets[12 * 4096], vol[4096];
  const int nt = fcm__geom_poly_tets(p, tets, vol);
  mom[0] = mom[1] = mom[2] = mom[3] = 0.0;
  for (int t = 0; t < nt; t++) {
    double v[4][3];
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        v[a][d] = tets[12 * t + 3 * a + d];
    TEST_TRUE(vol[t] >= -1e-15); /* fan tets of a convex body are positively oriented */
    double m[4] = {0, 0, 0, 0};
    exact_tet_add(v, 1, m);
    for (int k = 0; k < 4; k++)
      mom[k] += m[k];
  }
}

static void cube_corner_volumes(void)
{
  /* {x+y+z <= s} ∩ [0,1]^3: s^3/6 for s <= 1, (s^3 - 3 (s-1)^3)/6 for 1 <= s <= 2. */
  const double s_list[] = {0.1, 0.5, 1.0, 1.3, 1.5, 2.0, 2.5, 3.0};
  for (size_t i = 0; i < sizeof s_list / sizeof s_list[0]; i++) {
    const double s = s_list[i];
    double exact = s <= 1 ? s * s * s / 6 : s <= 2 ? (s * s * s - 3 * pow(s - 1, 3)) / 6 : 0.0;
    if (s > 2) exact = (s * s * s - 3 * pow(s - 1, 3) + 3 * pow(s - 2, 3)) / 6;
    if (s >= 3) exact = 1.0;
    unit_cube(&P);
    const fcm__plane pl = plane(1, 1, 1, s);
    TEST_TRUE(fcm__geom_poly_clip(&P, &pl, 1e-12, &S) == 0);
    TEST_NEAR(fcm__geom_poly_volume(&P), exact, 1e-14, 1e-15);
  }
}

static void complementary_splits(void)
{
  unsigned long long rng = 42;
  for (int trial = 0; trial < 200; trial++) {
    double v[4][3], full[4], a[4], b[4];
    for (int k = 0; k < 4; k++)
      for (int d = 0; d < 3; d++)
        v[k][d] = exact_rand(&rng);
    double X[12];
    for (int k = 0; k < 4; k++)
      for (int d = 0; d < 3; d++)
        X[3 * k + d] = v[k][d];
    if ((v[1][0] - v[0][0]) * ((v[2][1] - v[0][1]) * (v[3][2] - v[0][2]) -
                               (v[2][2] - v[0][2]) * (v[3][1] - v[0][1])) -
            (v[1][1] - v[0][1]) * ((v[2][0] - v[0][0]) * (v[3][2] - v[0][2]) -
                                   (v[2][2] - v[0][2]) * (v[3][0] - v[0][0])) +
            (v[1][2] - v[0][2]) * ((v[2][0] - v[0][0]) * (v[3][1] - v[0][1]) -
                                   (v[2][1] - v[0][1]) * (v[3][0] - v[0][0])) <
        0)
      for (int d = 0; d < 3; d++) { /* orient positively */
        const double sw = X[3 + d];
        X[3 + d] = X[6 + d], X[6 + d] = sw;
      }
    const int cube = trial % 2;
    if (cube)
      unit_cube(&P);
    else
      fcm__geom_poly_from_cell(FCM_ELEMENT_TET4, X, &P);
    poly_moments(&P, full);
    const double nx = exact_rand(&rng) - 0.5, ny = exact_rand(&rng) - 0.5,
                 nz = exact_rand(&rng) - 0.5;
    const fcm__plane p1 = plane(nx, ny, nz, 0.5 * (nx + ny + nz) + 0.2 * (exact_rand(&rng) - 0.5));
    const fcm__plane p2 = {{-p1.n[0], -p1.n[1], -p1.n[2]}, -p1.d};
    fcm__poly Q = P;
    TEST_TRUE(fcm__geom_poly_clip(&P, &p1, 1e-12, &S) == 0);
    TEST_TRUE(fcm__geom_poly_clip(&Q, &p2, 1e-12, &S) == 0);
    poly_moments(&P, a);
    poly_moments(&Q, b);
    for (int k = 0; k < 4; k++)
      TEST_NEAR(a[k] + b[k], full[k], 1e-13, 1e-15);
  }
}

/* A random positively oriented tet clipped by the 6 planes of a rotated box: moments up
 * to degree 4 against exact_polytope_add on the same half-spaces. */
static void tet_box_moments(void)
{
  unsigned long long rng = 7;
  for (int trial = 0; trial < 50; trial++) {
    double v[4][3], X[12], R[9], t[3], lo[3], hi[3];
    for (int k = 0; k < 4; k++)
      for (int d = 0; d < 3; d++)
        v[k][d] = 2 * exact_rand(&rng) - 1;
    exact_rotation(exact_rand(&rng), exact_rand(&rng), exact_rand(&rng), R);
    for (int d = 0; d < 3; d++)
      lo[d] = -0.2 - 0.5 * exact_rand(&rng), hi[d] = 0.2 + 0.5 * exact_rand(&rng),
      t[d] = 0.4 * exact_rand(&rng) - 0.2;
    exact_plane pl[10];
    exact_tet_planes(v, pl);
    exact_box_planes(R, t, lo, hi, pl + 4);
    for (int k = 0; k < 4; k++)
      for (int d = 0; d < 3; d++)
        X[3 * k + d] = v[k][d];
    fcm__geom_poly_from_cell(FCM_ELEMENT_TET4, X, &P);
    if (fcm__geom_poly_volume(&P) < 0) { /* orient positively */
      for (int d = 0; d < 3; d++) {
        const double s = X[3 + d];
        X[3 + d] = X[6 + d], X[6 + d] = s;
      }
      fcm__geom_poly_from_cell(FCM_ELEMENT_TET4, X, &P);
    }
    for (int f = 0; f < 6; f++) {
      const fcm__plane q = {{pl[4 + f].n[0], pl[4 + f].n[1], pl[4 + f].n[2]}, pl[4 + f].d};
      TEST_TRUE(fcm__geom_poly_clip(&P, &q, 1e-13, &S) == 0);
    }
    double exact[EXACT_MAX_MONO] = {0}, got[EXACT_MAX_MONO] = {0};
    exact_polytope_add(pl, 10, 4, 1e-13, exact);
    static double tets[12 * 4096], vol[4096];
    const int nt = fcm__geom_poly_tets(&P, tets, vol);
    for (int k = 0; k < nt; k++) {
      double w[4][3];
      for (int a = 0; a < 4; a++)
        for (int d = 0; d < 3; d++)
          w[a][d] = tets[12 * k + 3 * a + d];
      exact_tet_add(w, 4, got);
    }
    for (int k = 0; k < exact_num_mono(4); k++)
      TEST_NEAR(got[k], exact[k], 1e-12, 1e-14);
  }
}

static void degenerate_planes(void)
{
  /* Plane through the cube's face x = 1: inside keeps the cube, outside removes it. */
  unit_cube(&P);
  fcm__plane pl = plane(1, 0, 0, 1);
  TEST_TRUE(fcm__geom_poly_clip(&P, &pl, 1e-12, &S) == 0);
  TEST_NEAR(fcm__geom_poly_volume(&P), 1.0, 1e-15, 0);
  TEST_TRUE(P.nv == 8 && P.nf == 6);
  pl = plane(-1, 0, 0, -1); /* keep x >= 1: only the face, no volume */
  TEST_TRUE(fcm__geom_poly_clip(&P, &pl, 1e-12, &S) == 0);
  TEST_TRUE(P.nf == 0 && fcm__geom_poly_volume(&P) == 0.0);
  /* Within the tolerance counts as on the plane. */
  unit_cube(&P);
  pl = plane(1, 0, 0, 1 - 1e-14);
  TEST_TRUE(fcm__geom_poly_clip(&P, &pl, 1e-12, &S) == 0);
  TEST_TRUE(P.nv == 8 && P.nf == 6);
  /* Diagonal plane x = y through 4 vertices: exactly half, every new vertex an old one. */
  unit_cube(&P);
  pl = plane(1, -1, 0, 0);
  TEST_TRUE(fcm__geom_poly_clip(&P, &pl, 1e-12, &S) == 0);
  TEST_NEAR(fcm__geom_poly_volume(&P), 0.5, 1e-15, 0);
  TEST_TRUE(P.nv == 6 && P.nf == 5); /* a triangular prism */
  /* Plane through one vertex only, cube otherwise inside: unchanged. */
  unit_cube(&P);
  pl = plane(1, 1, 1, 3);
  TEST_TRUE(fcm__geom_poly_clip(&P, &pl, 1e-12, &S) == 0);
  TEST_TRUE(P.nv == 8 && P.nf == 6);
  /* Plane cutting a sliver of relative volume ~1e-12 from a corner. */
  unit_cube(&P);
  const double s = cbrt(6e-12);
  pl = plane(-1, -1, -1, -s); /* keep x+y+z >= s */
  TEST_TRUE(fcm__geom_poly_clip(&P, &pl, 1e-15, &S) == 0);
  TEST_NEAR(fcm__geom_poly_volume(&P), 1.0 - s * s * s / 6, 1e-15, 0);
  /* Degenerate plane (zero normal) never clips. */
  unit_cube(&P);
  const fcm__plane zero = {{0, 0, 0}, 0};
  TEST_TRUE(fcm__geom_poly_clip(&P, &zero, 1e-12, &S) == 0 && P.nf == 6);
}

static void cell_planes_outward(void)
{
  /* Planes of a tet4 and hex8 cell: every corner inside, face centroids on the plane. */
  const fcm_element_type types[2] = {FCM_ELEMENT_TET4, FCM_ELEMENT_HEX8};
  for (int i = 0; i < 2; i++) {
    const fcm_element_info *info = fcm_element_get_info(types[i]);
    const double *ref = fcm_element_ref_nodes(types[i]);
    double X[24];
    for (int a = 0; a < info->num_corners; a++) /* a sheared, translated copy */
      X[3 * a] = 2 * ref[3 * a] + 0.3 * ref[3 * a + 1] + 5, X[3 * a + 1] = ref[3 * a + 1] - 1,
            X[3 * a + 2] = 0.5 * ref[3 * a + 2] + 0.1 * ref[3 * a];
    fcm__plane pl[6];
    TEST_TRUE(fcm__geom_cell_planes(info, X, pl) == info->num_faces);
    for (int f = 0; f < info->num_faces; f++) {
      TEST_NEAR(pl[f].n[0] * pl[f].n[0] + pl[f].n[1] * pl[f].n[1] + pl[f].n[2] * pl[f].n[2], 1,
                1e-15, 0);
      for (int a = 0; a < info->num_corners; a++) {
        const double s =
            pl[f].n[0] * X[3 * a] + pl[f].n[1] * X[3 * a + 1] + pl[f].n[2] * X[3 * a + 2] - pl[f].d;
        int on = 0;
        for (int k = 0; k < info->face_num_corners[f]; k++)
          on |= info->face_nodes[f][k] == a;
        TEST_TRUE(on ? fabs(s) < 1e-14 : s < -0.1);
      }
    }
  }
}

static void polygon_clipping(void)
{
  double x[3 * 16], w[3 * 16];
  const double tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  /* Triangle cut by x <= 0.5: area 1/2 - 1/8. */
  memcpy(x, tri, sizeof tri);
  fcm__plane pl = plane(1, 0, 0, 0.5);
  int n = fcm__geom_polygon_clip(x, 3, 16, &pl, 1e-12, 1, w);
  TEST_TRUE(n == 4);
  double area = 0;
  for (int i = 1; i + 1 < n; i++) {
    const double *a = x, *b = x + 3 * i, *c = x + 3 * i + 3;
    area += 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
  }
  TEST_NEAR(area, 0.375, 1e-15, 0);
  /* Flat on the plane z = 0: kept or dropped as asked. */
  memcpy(x, tri, sizeof tri);
  pl = plane(0, 0, 1, 0);
  TEST_TRUE(fcm__geom_polygon_clip(x, 3, 16, &pl, 1e-12, 1, w) == 3);
  TEST_TRUE(fcm__geom_polygon_clip(x, 3, 16, &pl, 1e-12, 0, w) == 0);
  /* Entirely outside, touching at a vertex: empty. */
  memcpy(x, tri, sizeof tri);
  pl = plane(-1, 0, 0, 0); /* keep x >= 0... all inside */
  TEST_TRUE(fcm__geom_polygon_clip(x, 3, 16, &pl, 1e-12, 1, w) == 3);
  pl = plane(1, 0, 0, 0); /* keep x <= 0: one vertex on, others outside */
  TEST_TRUE(fcm__geom_polygon_clip(x, 3, 16, &pl, 1e-12, 1, w) == 0);
}

/* A sliver left by a cut 1e-8 off a cell face (Tet4 cell of a hollow ball): the part lies
 * between the face x = 1 and the cut plane, one of its cap's fan triangles (vertices 1, 3, 2,
 * vertex 3 taken as on the cut within the tolerance) lies over the face: a flat flap on a tet.
 * Split by a second plane, the two halves must add up to the part: a cap ordered by angle
 * around its centroid would cross itself here (its vertices are nearly collinear) and gain
 * 0.2 % (3.7e-14). Rounding bounds what a sliver's volume can be computed to (coordinates of size
 * 1 and faces of area 0.03): the halves must add up to 1e-14 of the cell's volume |K|. */
static void flap_split(void)
{
  static const double x[5][3] = {{1, 1, 1.7},
                                 {1, 0.73212159734443727, 1.6467156727579007},
                                 {1, 0.83924932511994499, 1.5},
                                 {1, 0.79289321881345254, 1.5},
                                 {1.0000000021505346, 1, 1.6999999995722319}};
  static const int fn[5] = {3, 3, 4, 3, 3};
  static const int fv[5][4] = {{2, 0, 4}, {0, 1, 4}, {3, 1, 0, 2}, {1, 3, 2}, {1, 2, 4}};
  const fcm__plane cut = {{1, -9.5163874887839802e-09, -3.0721924980980246e-09},
                          0.99999998741142004};
  const fcm__plane fp[5] = {
      {{-0.12365765749806541, 0.77345743712449044, -0.62166902504379773}, -0.40703756294803117},
      {{0.19148045395532326, -0.19148045395532307, 0.96263724813977913}, 1.6364833218376247},
      {{-1, 0, 0}, -1},
      cut,
      cut};
  P.nv = 5, P.nf = 5;
  memcpy(P.x, x, sizeof x);
  for (int f = 0; f < 5; f++) {
    P.fn[f] = fn[f];
    memcpy(P.fv[f], fv[f], (size_t)fn[f] * sizeof fv[f][0]);
    P.fp[f] = fp[f];
  }
  const double whole = fcm__geom_poly_volume(&P), tol = 8.660254037844386e-10;
  const double K = 0.25 * 0.25 * 0.25 / 6.0; /* the Tet4 cell, h = 0.25 */
  TEST_TRUE(whole > 1e-11);
  fcm__poly Q = P;
  const fcm__plane y = {{0, 1, 0}, 0.74999999261465145}, ny = {{0, -1, 0}, -y.d};
  TEST_TRUE(fcm__geom_poly_clip(&P, &y, tol, &S) == 0);
  TEST_TRUE(fcm__geom_poly_clip(&Q, &ny, tol, &S) == 0);
  const double a = fcm__geom_poly_volume(&P), b = fcm__geom_poly_volume(&Q);
  TEST_TRUE(a > 0.0 && b > 0.0);
  TEST_NEAR(a + b, whole, 0.0, 1e-14 * K);
  double ma[4], mb[4];
  poly_moments(&P, ma);
  poly_moments(&Q, mb);
  TEST_NEAR(ma[0] + mb[0], whole, 0.0, 1e-14 * K);
}

/* A tet clipped by a Kuhn cell's planes with a tolerance (1.4e-13) about as large as the
 * distances between three vertices that the first plane leaves near a cell corner: the third
 * plane finds that tiny triangle on it, and the cross-section around it must still be closed
 * (a clip taking the tiny face for the whole cap loses 17 % of the volume). Moments of degree <= 1
 * against the independent polytope integration. */
static void tiny_face_on_plane(void)
{
  double v[4][3] = {{-0.49999900000000003, 0.49999999999990002, -0.99999999900000003},
                    {-0.5, -0.49999999999990002, -0.50000000000010003},
                    {0.11489263943640204, -0.49999999899999997, 1.0000000000000001e-15},
                    {-0.499999999999999, -0.45073224645856347, 0}};
  double K[4][3] = {{-1, -1, -1}, {0, -1, -1}, {0, 0, -1}, {0, 0, 0}};
  double X[12], Y[12];
  for (int k = 0; k < 4; k++)
    for (int d = 0; d < 3; d++)
      X[3 * k + d] = v[k][d], Y[3 * k + d] = K[k][d];
  fcm__geom_poly_from_cell(FCM_ELEMENT_TET4, X, &P);
  TEST_TRUE(fcm__geom_poly_volume(&P) > 0.0);
  fcm__plane cp[4];
  fcm__geom_cell_planes(fcm_element_get_info(FCM_ELEMENT_TET4), Y, cp);
  for (int f = 0; f < 4; f++)
    TEST_TRUE(fcm__geom_poly_clip(&P, cp + f, 1.357e-13, &S) == 0);
  exact_plane pl[8];
  exact_tet_planes(v, pl);
  exact_tet_planes(K, pl + 4);
  double exact[EXACT_MAX_MONO] = {0}, got[4];
  exact_polytope_add(pl, 8, 1, 1e-13, exact);
  poly_moments(&P, got);
  for (int k = 0; k < 4; k++)
    TEST_NEAR(got[k], exact[k], 1e-12, 1e-14);
}

int main(void)
{
  cube_corner_volumes();
  complementary_splits();
  tet_box_moments();
  degenerate_planes();
  cell_planes_outward();
  polygon_clipping();
  flap_split();
  tiny_face_on_plane();
  return TEST_RESULT();
}
