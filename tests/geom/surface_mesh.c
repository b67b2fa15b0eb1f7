/* Surface checks (boundary edges, orientation, degenerate triangles, self-intersections),
 * hole filling and tetrahedralization through Gmsh: the tets' volume equals the surface's
 * enclosed volume (divergence theorem) to 1e-12 relative. */
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>

/* The unit cube [0,1]^3: 8 vertices, 12 outward triangles. */
static const double cube_x[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
static const fcm_index cube_t[] = {0, 2, 1, 0, 3, 2, /* z = 0 */ 4, 5, 6, 4, 6, 7, /* z = 1 */
                                   0, 1, 5, 0, 5, 4, /* y = 0 */ 3, 7, 6, 3, 6, 2, /* y = 1 */
                                   0, 4, 7, 0, 7, 3, /* x = 0 */ 1, 2, 6, 1, 6, 5 /* x = 1 */};

/* An icosphere of radius r around c: the icosahedron with each triangle split in 4,
 * `levels` times, the new vertices pushed onto the sphere (midpoints shared). */
#define ICO_MAXV 2562
#define ICO_MAXT 5120
typedef struct ico {
  double x[3 * ICO_MAXV];
  fcm_index t[3 * ICO_MAXT];
  fcm_index nv, nt;
} ico;

static fcm_index ico_mid(ico *s, fcm_index a, fcm_index b, fcm_index *ea, fcm_index *eb,
                         fcm_index *em, fcm_index *ne)
{
  for (fcm_index i = 0; i < *ne; i++)
    if ((ea[i] == a && eb[i] == b) || (ea[i] == b && eb[i] == a)) return em[i];
  double p[3], n = 0;
  for (int d = 0; d < 3; d++)
    p[d] = 0.5 * (s->x[3 * a + d] + s->x[3 * b + d]), n += p[d] * p[d];
  for (int d = 0; d < 3; d++)
    s->x[3 * s->nv + d] = p[d] / sqrt(n);
  ea[*ne] = a, eb[*ne] = b, em[*ne] = s->nv;
  (*ne)++;
  return s->nv++;
}

static void icosphere(ico *s, int levels)
{
  const double g = (1.0 + sqrt(5.0)) / 2.0;
  const double v[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                           {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                           {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  const int f[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                        {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                        {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                        {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  double n = sqrt(1 + g * g);
  s->nv = 12, s->nt = 20;
  for (int i = 0; i < 12; i++)
    for (int d = 0; d < 3; d++)
      s->x[3 * i + d] = v[i][d] / n;
  for (int i = 0; i < 20; i++)
    for (int k = 0; k < 3; k++)
      s->t[3 * i + k] = f[i][k];
  static fcm_index ea[3 * ICO_MAXT], eb[3 * ICO_MAXT], em[3 * ICO_MAXT], nt[3 * ICO_MAXT];
  for (int l = 0; l < levels; l++) {
    fcm_index ne = 0, m = 0;
    for (fcm_index i = 0; i < s->nt; i++) {
      fcm_index a = s->t[3 * i], b = s->t[3 * i + 1], c = s->t[3 * i + 2];
      fcm_index ab = ico_mid(s, a, b, ea, eb, em, &ne), bc = ico_mid(s, b, c, ea, eb, em, &ne),
                ca = ico_mid(s, c, a, ea, eb, em, &ne);
      fcm_index q[12] = {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca};
      for (int k = 0; k < 12; k++)
        nt[3 * m + k] = q[k];
      m += 4;
    }
    s->nt = m;
    for (fcm_index i = 0; i < 3 * m; i++)
      s->t[i] = nt[i];
  }
}

static double report_volume(const fcm_surface *s)
{
  fcm_surface_report r;
  if (fcm_surface_check(s, NULL, &r) != FCM_OK) return NAN;
  return r.signed_volume;
}

/* Mesh `s` and compare the tets' volume with the enclosed volume. */
static void check_volume(fcm_ctx *ctx, const fcm_surface *s, double max_volume)
{
  fcm_surface_mesh_options o = fcm_surface_mesh_options_default();
  o.max_volume = max_volume;
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, s, &o, &g));
  if (!g) return;
  double v = report_volume(s);
  TEST_TRUE(v > 0.0);
  TEST_NEAR(fcm_geometry_volume(g), v, 1e-12, 0.0);
  /* the surface is kept: at least as many nodes as surface vertices, and as many boundary
   * triangles as surface triangles */
  TEST_TRUE(fcm_geometry_num_nodes(g) >= fcm_surface_num_vertices(s));
  TEST_TRUE(fcm_geometry_num_boundary_triangles(g) == fcm_surface_num_triangles(s));
  if (max_volume > 0.0) {
    /* interior points are added: the tets near the (kept, coarse) surface stay large, so
     * the count, not the largest tet, follows the request */
    TEST_TRUE(fcm_geometry_num_nodes(g) > fcm_surface_num_vertices(s));
    TEST_TRUE((double)fcm_geometry_num_cells(g) >= v / (10.0 * max_volume));
  }
  fcm_geometry_destroy(&g);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  static ico sph;
  fcm_surface *cube = NULL, *s = NULL, *s2 = NULL;
  fcm_surface_report r;
  fcm_geometry *g = NULL;

  /* closed, outward cube: every check passes, volume 1, area 6 */
  TEST_OK(ctx, fcm_surface_create(ctx, 8, cube_x, 12, cube_t, &cube));
  TEST_OK(ctx, fcm_surface_check(cube, NULL, &r));
  TEST_TRUE(r.num_boundary_edges == 0 && r.num_nonmanifold_edges == 0 &&
            r.num_inconsistent_edges == 0 && r.num_degenerate == 0 && r.num_intersections == 0);
  TEST_NEAR(r.signed_volume, 1.0, 1e-15, 0.0);
  TEST_NEAR(r.area, 6.0, 1e-15, 0.0);
  TEST_OK(ctx, fcm_surface_report_check(cube, "cube", &r));

  /* inward cube: volume -1, refused, then oriented (every triangle flipped) */
  {
    fcm_index t[36], flipped = 0;
    for (int i = 0; i < 12; i++)
      t[3 * i] = cube_t[3 * i], t[3 * i + 1] = cube_t[3 * i + 2], t[3 * i + 2] = cube_t[3 * i + 1];
    TEST_OK(ctx, fcm_surface_create(ctx, 8, cube_x, 12, t, &s));
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_NEAR(r.signed_volume, -1.0, 1e-15, 0.0);
    TEST_TRUE(r.num_inconsistent_edges == 0);
    TEST_ERR(ctx, fcm_surface_report_check(s, "inward", &r), FCM_ERR_GEOMETRY, "inward");
    TEST_OK(ctx, fcm_surface_create_oriented(ctx, s, &s2, &flipped));
    TEST_TRUE(flipped == 12);
    TEST_NEAR(report_volume(s2), 1.0, 1e-15, 0.0);
    fcm_surface_destroy(&s);
    fcm_surface_destroy(&s2);
    /* one triangle flipped: its 3 edges inconsistent; orienting flips it back */
    for (int i = 0; i < 36; i++)
      t[i] = cube_t[i];
    t[4] = cube_t[5], t[5] = cube_t[4];
    TEST_OK(ctx, fcm_surface_create(ctx, 8, cube_x, 12, t, &s));
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_TRUE(r.num_inconsistent_edges == 3);
    TEST_ERR(ctx, fcm_surface_report_check(s, "one flipped", &r), FCM_ERR_GEOMETRY,
             "inconsistent orientation: 3 edges");
    TEST_OK(ctx, fcm_surface_create_oriented(ctx, s, &s2, &flipped));
    TEST_TRUE(flipped == 1);
    TEST_OK(ctx, fcm_surface_check(s2, NULL, &r));
    TEST_TRUE(r.num_inconsistent_edges == 0);
    TEST_NEAR(r.signed_volume, 1.0, 1e-15, 0.0);
    fcm_surface_destroy(&s);
    fcm_surface_destroy(&s2);
  }

  /* degenerate: a cube triangle replaced by a zero-area one (collinear points) */
  {
    double x[27];
    fcm_index t[39];
    for (int i = 0; i < 24; i++)
      x[i] = cube_x[i];
    x[24] = 0.5, x[25] = 0, x[26] = 0; /* midpoint of edge 0-1 */
    for (int i = 0; i < 36; i++)
      t[i] = cube_t[i];
    t[36] = 0, t[37] = 8, t[38] = 1; /* collinear */
    TEST_OK(ctx, fcm_surface_create(ctx, 9, x, 13, t, &s));
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_TRUE(r.num_degenerate == 1 && r.degenerate[0] == 12);
    fcm_surface_destroy(&s);
  }

  /* non-manifold: a fourth triangle on the cube's edge 0-1 */
  {
    double x[27];
    fcm_index t[39];
    for (int i = 0; i < 24; i++)
      x[i] = cube_x[i];
    x[24] = 0.5, x[25] = -1, x[26] = -1;
    for (int i = 0; i < 36; i++)
      t[i] = cube_t[i];
    t[36] = 0, t[37] = 1, t[38] = 8;
    TEST_OK(ctx, fcm_surface_create(ctx, 9, x, 13, t, &s));
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_TRUE(r.num_nonmanifold_edges == 1);
    TEST_TRUE(r.nonmanifold_edges[0][0] == 0 && r.nonmanifold_edges[0][1] == 1);
    TEST_TRUE(r.num_boundary_edges == 2); /* 1-8 and 8-0 */
    fcm_surface_destroy(&s);
  }

  /* self-intersection: two overlapping cubes (the second shifted by 0.5 in x, y, z) */
  {
    double x[48];
    fcm_index t[72];
    for (int i = 0; i < 24; i++)
      x[i] = cube_x[i], x[24 + i] = cube_x[i] + 0.5;
    for (int i = 0; i < 36; i++)
      t[i] = cube_t[i], t[36 + i] = cube_t[i] + 8;
    TEST_OK(ctx, fcm_surface_create(ctx, 16, x, 24, t, &s));
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_TRUE(r.num_intersections > 0);
    TEST_TRUE(r.intersecting[0][0] < 12 && r.intersecting[0][1] >= 12);
    TEST_ERR(ctx, fcm_surface_report_check(s, "two cubes", &r), FCM_ERR_GEOMETRY,
             "intersects itself");
    fcm_surface_destroy(&s);
    /* apart (shifted by 2): no intersection */
    for (int i = 0; i < 24; i++)
      x[24 + i] = cube_x[i] + 2.0;
    TEST_OK(ctx, fcm_surface_create(ctx, 16, x, 24, t, &s));
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_TRUE(r.num_intersections == 0);
    TEST_NEAR(r.signed_volume, 2.0, 1e-15, 0.0);
    fcm_surface_destroy(&s);
  }

  /* two triangles sharing a vertex: B's far edge through A (x = y = 0.3) or beside it
   * (x = y = -0.3); sharing an edge: folded onto A (third vertex coplanar, same side) or
   * continuing it flat (other side) */
  {
    static const double cases[4][15] = {{0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 1, 0.3, 0.3, -1},
                                        {0, 0, 0, 1, 0, 0, 0, 1, 0, -0.3, -0.3, 1, -0.3, -0.3, -1},
                                        {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.3, 0, 0, 0, 0},
                                        {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, -0.3, 0, 0, 0, 0}};
    static const fcm_index vertex_t[6] = {0, 1, 2, 0, 3, 4}, edge_t[6] = {0, 1, 2, 1, 0, 3};
    static const int expect[4] = {1, 0, 1, 0};
    for (int c = 0; c < 4; c++) {
      TEST_OK(ctx,
              fcm_surface_create(ctx, c < 2 ? 5 : 4, cases[c], 2, c < 2 ? vertex_t : edge_t, &s));
      TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
      if (r.num_intersections != expect[c])
        TEST_FAIL_("case %d: %lld intersections, expected %d", c, (long long)r.num_intersections,
                   expect[c]);
      fcm_surface_destroy(&s);
    }
  }

  /* icosphere: closed, no false intersections among neighbours */
  icosphere(&sph, 2); /* 162 vertices, 320 triangles */
  TEST_OK(ctx, fcm_surface_create(ctx, sph.nv, sph.x, sph.nt, sph.t, &s));
  TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
  TEST_TRUE(r.num_boundary_edges == 0 && r.num_intersections == 0 && r.num_degenerate == 0 &&
            r.num_inconsistent_edges == 0);
  TEST_TRUE(r.signed_volume > 0.0 && r.signed_volume < 4.0 / 3.0 * 3.14159265358979);

  /* tetrahedralization: volume equality (without Gmsh: refused, saying so) */
  if (fcm_surface_meshing_available()) {
    /* Gmsh meshes on one thread and sets OpenMP's thread count to do so: the caller's count
     * comes back (ctest runs this with OMP_NUM_THREADS=3) */
    const int threads = fcm_ctx_num_threads(NULL);
    check_volume(ctx, cube, 0.0);
    check_volume(ctx, cube, 0.001);
    check_volume(ctx, s, 0.0);
    check_volume(ctx, s, 0.01);
    /* no size limit after calls with a limit (no option left over): the cube comes back as
     * its 8 corners */
    TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, cube, NULL, &g));
    TEST_TRUE(g && fcm_geometry_num_nodes(g) == 8);
    fcm_geometry_destroy(&g);
    TEST_TRUE(fcm_ctx_num_threads(NULL) == threads);
  } else {
    TEST_ERR(ctx, fcm_geometry_create_from_surface(ctx, cube, NULL, &g), FCM_ERR_UNSUPPORTED,
             "apt-get install libgmsh-dev");
    TEST_TRUE(g == NULL);
  }
  fcm_surface_destroy(&s);

  /* open cube (the top face's two triangles removed): refused with the boundary edge count,
   * filled (one loop of 4 edges: 2 triangles of area 1), then meshed with volume 1 */
  {
    fcm_index t[30];
    int m = 0;
    for (int i = 0; i < 12; i++) {
      if (i == 2 || i == 3) continue;
      for (int k = 0; k < 3; k++)
        t[3 * m + k] = cube_t[3 * i + k];
      m++;
    }
    fcm_surface_fill_info fi;
    TEST_OK(ctx, fcm_surface_create(ctx, 8, cube_x, 10, t, &s));
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_TRUE(r.num_boundary_edges == 4 && r.num_boundary_loops == 1);
    TEST_ERR(ctx, fcm_surface_report_check(s, "open", &r), FCM_ERR_GEOMETRY,
             "4 boundary edges in 1 loop(s)");
    /* the ids in the message say how they count */
    TEST_ERR(ctx, fcm_surface_report_check(s, "open", &r), FCM_ERR_GEOMETRY,
             "ids count from 0 in the file's order");
    TEST_ERR(ctx, fcm_geometry_create_from_surface(ctx, s, NULL, &g), FCM_ERR_GEOMETRY,
             "not closed: 4 boundary edges");
    TEST_TRUE(g == NULL);
    /* too small a limit: nothing filled */
    fcm_surface_fill_options fo = fcm_surface_fill_options_default();
    fo.max_edges = 3;
    TEST_OK(ctx, fcm_surface_create_filled(ctx, s, &fo, &s2, &fi));
    TEST_TRUE(fi.num_loops == 1 && fi.num_filled == 0 && fi.largest_left == 4);
    fcm_surface_destroy(&s2);
    fo.max_edges = 0;
    fo.max_perimeter = 3.9; /* the loop's perimeter is 4 */
    TEST_OK(ctx, fcm_surface_create_filled(ctx, s, &fo, &s2, &fi));
    TEST_TRUE(fi.num_filled == 0);
    fcm_surface_destroy(&s2);
    TEST_OK(ctx, fcm_surface_create_filled(ctx, s, NULL, &s2, &fi));
    TEST_TRUE(fi.num_loops == 1 && fi.num_filled == 1 && fi.loop_edges[0] == 4);
    TEST_TRUE(fi.triangles_added == 2 && fi.vertices_added == 0 && fi.largest_left == 0);
    TEST_NEAR(fi.area_added, 1.0, 1e-15, 0.0);
    TEST_OK(ctx, fcm_surface_check(s2, NULL, &r));
    TEST_TRUE(r.num_boundary_edges == 0 && r.num_inconsistent_edges == 0 &&
              r.num_intersections == 0);
    TEST_NEAR(r.signed_volume, 1.0, 1e-15, 0.0);
    if (fcm_surface_meshing_available()) check_volume(ctx, s2, 0.0);
    fcm_surface_destroy(&s);
    fcm_surface_destroy(&s2);
  }

  /* sphere with a hole: the triangles with a vertex above z = 0.8 removed; filled by the
   * minimum-area triangulation of the loop (n - 2 triangles, no new vertex) */
  {
    static fcm_index t[3 * ICO_MAXT];
    fcm_index m = 0;
    for (fcm_index i = 0; i < sph.nt; i++) {
      int top = 0;
      for (int k = 0; k < 3; k++)
        top |= sph.x[3 * sph.t[3 * i + k] + 2] > 0.8;
      if (top) continue;
      for (int k = 0; k < 3; k++)
        t[3 * m + k] = sph.t[3 * i + k];
      m++;
    }
    fcm_surface_fill_info fi;
    TEST_TRUE(m < sph.nt);
    TEST_OK(ctx, fcm_surface_create(ctx, sph.nv, sph.x, m, t, &s));
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_TRUE(r.num_boundary_edges > 0 && r.num_boundary_loops == 1);
    TEST_OK(ctx, fcm_surface_create_filled(ctx, s, NULL, &s2, &fi));
    TEST_TRUE(fi.num_filled == 1 && fi.loop_edges[0] == r.num_boundary_edges);
    TEST_TRUE(fi.triangles_added == r.num_boundary_edges - 2 && fi.vertices_added == 0);
    TEST_OK(ctx, fcm_surface_check(s2, NULL, &r));
    TEST_TRUE(r.num_boundary_edges == 0 && r.num_inconsistent_edges == 0 &&
              r.num_intersections == 0 && r.num_degenerate == 0);
    if (fcm_surface_meshing_available()) check_volume(ctx, s2, 0.0);
    fcm_surface_destroy(&s);
    fcm_surface_destroy(&s2);
  }

  /* argument errors */
  TEST_TRUE(fcm_surface_check(NULL, NULL, &r) == FCM_ERR_ARG);
  {
    fcm_surface_mesh_options o = fcm_surface_mesh_options_default();
    o.quality = 2.0;
    TEST_ERR(ctx, fcm_geometry_create_from_surface(ctx, cube, &o, &g), FCM_ERR_ARG,
             "quality = 2 outside [0, 1]");
    fcm_surface_fill_options fo = fcm_surface_fill_options_default();
    fo.max_edges = -1;
    TEST_ERR(ctx, fcm_surface_create_filled(ctx, cube, &fo, &s, NULL), FCM_ERR_ARG,
             "max_edges = -1");
  }
  fcm_surface_destroy(&cube);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
