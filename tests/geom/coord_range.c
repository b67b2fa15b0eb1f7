/* Coordinates out of range: a vertex beyond +-1e50 (where products of coordinates in volumes
 * and normals overflow) is refused as such by every reader, naming the file, the vertex as
 * the format numbers it (OBJ from 1, OFF and PLY from 0, STL by facet and corner, TetGen
 * from its own base, Gmsh by tag) and the value, instead of surfacing as degenerate triangles
 * or non-finite volumes later; the array constructors of surfaces, geometries and meshes
 * refuse it too. At the limit the computations stay finite: a cube with corners at +-1e50
 * passes the surface check with its exact volume, and a tet that size has its volume. */
#include "fcm/geom.h"
#include "fcm/mesh.h"
#include "fcm/surface.h"
#include "test.h"

#include <stdint.h>
#include <stdio.h>

#define RANGE "outside the supported range [-1e50, 1e50]"

static void write_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (f) fputs(text, f), fclose(f);
}

static void surfaces(fcm_ctx *ctx)
{
  static const struct {
    const char *path, *text, *msg;
  } cases[] = {
      {"cr_far.obj", "v 0 0 0\nv 1 0 0\nv 0 1e308 0\nf 1 2 3\n",
       "cr_far.obj: vertex 3 (1-based, as the file's faces number them): coordinate y = 1e+308 "
       "is " RANGE},
      {"cr_far.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 0 -2e100\n3 0 1 2\n",
       "cr_far.off: vertex 2 (0-based, as the file's faces number them): coordinate z = -2e+100 "
       "is " RANGE},
      {"cr_far.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
       "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1.5e101 0 0\n0 1 0\n3 0 1 2\n",
       "cr_far.ply: vertex 1 (0-based, as the file's faces number them): coordinate x = 1.5e+101 "
       "is " RANGE},
      {"cr_far.stl",
       "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
       "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
       "vertex 0 1 1e300\nendloop\nendfacet\nendsolid s\n",
       "cr_far.stl: facet 1 (counted from 0), corner 2: coordinate z = 1e+300 is " RANGE},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    fcm_surface *s = NULL;
    write_file(cases[k].path, cases[k].text);
    TEST_ERR(ctx, fcm_surface_create_from_file(ctx, cases[k].path, &s), FCM_ERR_FORMAT,
             cases[k].msg);
    TEST_TRUE(s == NULL);
    remove(cases[k].path);
  }
  /* arrays */
  const double x[9] = {0, 0, 0, 1, 0, 0, 0, 1, -3e100};
  const fcm_index t[3] = {0, 1, 2};
  fcm_surface *s = NULL;
  TEST_ERR(ctx, fcm_surface_create(ctx, 3, x, 1, t, &s), FCM_ERR_ARG,
           "coordinate 2 of vertex 2 (0-based) is -3e+100, " RANGE);
  /* the cube [-1e50, 1e50]^3: finite area and volume, no degenerate triangle */
  const double L = 1e50;
  double c[24];
  for (int i = 0; i < 8; i++)
    for (int d = 0; d < 3; d++)
      c[3 * i + d] = (i >> d & 1) ? L : -L;
  static const fcm_index q[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                     {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                     {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  TEST_OK(ctx, fcm_surface_create(ctx, 8, c, 12, &q[0][0], &s));
  if (s) {
    fcm_surface_report r;
    TEST_OK(ctx, fcm_surface_check(s, NULL, &r));
    TEST_TRUE(r.num_degenerate == 0 && r.num_intersections == 0 && r.num_boundary_edges == 0);
    TEST_NEAR(r.signed_volume, 8 * L * L * L, 1e-12, 0);
    TEST_NEAR(r.area, 24 * L * L, 1e-12, 0);
    TEST_OK(ctx, fcm_surface_report_check(s, "cube", &r));
  }
  fcm_surface_destroy(&s);
}

static void volumes(fcm_ctx *ctx)
{
  /* TetGen: the point's index in the file's own base */
  write_file("cr_far.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 4e150\n");
  write_file("cr_far.ele", "1 4 0\n1 1 2 3 4\n");
  fcm_geometry *g = NULL;
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "cr_far.node", "cr_far.ele", &g),
           FCM_ERR_FORMAT,
           "cr_far.node:5: point 4 (1-based, as the file numbers them): coordinate z = 4e+150 "
           "is " RANGE);
  write_file("cr_far.node", "4 3\n0 0 0 0\n1 -1e101 0 0\n2 0 1 0\n3 0 0 1\n");
  write_file("cr_far.ele", "1 4\n0 0 1 2 3\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "cr_far.node", "cr_far.ele", &g),
           FCM_ERR_FORMAT, "cr_far.node:3: point 1 (0-based, as the file numbers them): ");
  remove("cr_far.node");
  remove("cr_far.ele");
  /* Gmsh: the node tag */
  write_file("cr_far.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n"
                           "2 1 0 0\n3 0 1 0\n17 0 0 1e200\n$EndNodes\n$Elements\n1\n"
                           "1 4 2 0 1 1 2 3 17\n$EndElements\n");
  TEST_ERR(ctx, fcm_geometry_create_from_gmsh(ctx, "cr_far.msh", &g), FCM_ERR_FORMAT,
           "cr_far.msh:9: node tag 17 (Gmsh tags, from 1): coordinate z = 1e+200 is " RANGE);
  fcm_mesh *m = NULL;
  TEST_ERR(ctx, fcm_mesh_create_from_gmsh(ctx, "cr_far.msh", &m), FCM_ERR_FORMAT, "node tag 17");
  remove("cr_far.msh");
  /* arrays, with a tet at the limit: its volume is finite and exact */
  const double L = 1e50;
  double x[12] = {0, 0, 0, L, 0, 0, 0, L, 0, 0, 0, L};
  const fcm_index cell[4] = {0, 1, 2, 3};
  TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, x, 1, cell, &g));
  if (g) TEST_NEAR(fcm_geometry_volume(g), L * L * L / 6, 1e-12, 0);
  fcm_geometry_destroy(&g);
  TEST_OK(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_TET4, 4, x, 1, cell, &m));
  fcm_mesh_destroy(&m);
  x[4] = 1.01 * L;
  TEST_ERR(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, x, 1, cell, &g), FCM_ERR_ARG,
           "coordinate 1 of node 1 (0-based) is 1.01e+50, " RANGE);
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_TET4, 4, x, 1, cell, &m), FCM_ERR_ARG,
           "mesh: coordinate 1 of node 1 (0-based) is 1.01e+50, " RANGE);
  TEST_TRUE(g == NULL && m == NULL);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  surfaces(ctx);
  volumes(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
