/* Geometry readers: TetGen .node/.ele (0- and 1-based, comments, attributes, markers) and
 * Gmsh MSH (tet4 and hex8) give the written nodes and cells (negatively oriented tets
 * reoriented, volume = sum of |tet volumes|); malformed files fail with the file name and
 * line; 10-node tets, 2-D files and tet10 MSH files are rejected as unsupported. */
#include "fcm/geom.h"
#include "test.h"

#include <stdio.h>

static fcm_ctx *ctx;

static void write_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (!f) return;
  fputs(text, f);
  fclose(f);
}

static const double P[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};

/* Two tets: (0,1,2,3) positive, (2,1,3,4) negative as written (volume 1/6 + 1/3). */
static void check_two_tets(const fcm_geometry *g)
{
  TEST_TRUE(fcm_geometry_num_nodes(g) == 5 && fcm_geometry_num_cells(g) == 2);
  TEST_TRUE(fcm_geometry_cell_type(g) == FCM_ELEMENT_TET4);
  const double *x = fcm_geometry_coords(g);
  for (int a = 0; a < 5; a++)
    for (int d = 0; d < 3; d++)
      TEST_TRUE(x[3 * a + d] == P[a][d]);
  const fcm_index *c = fcm_geometry_cells(g);
  TEST_TRUE(c[0] == 0 && c[1] == 1 && c[2] == 2 && c[3] == 3);
  /* The second tet is reoriented by swapping its nodes 1 and 2. */
  TEST_TRUE(c[4] == 2 && c[5] == 3 && c[6] == 1 && c[7] == 4);
  TEST_NEAR(fcm_geometry_volume(g), 1.0 / 6 + 1.0 / 3, 1e-15, 0);
  TEST_TRUE(fcm_geometry_num_boundary_triangles(g) == 6);
}

static void tetgen_ok(void)
{
  write_file("geom_rd_a.node", "# TetGen node file\n"
                               "5 3 1 1  # count dim attributes markers\n"
                               "0 0 0 0  7.5 1\n"
                               "1 1 0 0  7.5 0\n\n"
                               "2 0 1 0  7.5 1\n"
                               "3 0 0 1  7.5 1\n"
                               "4 1 1 1  7.5 1\n");
  write_file("geom_rd_a.ele", "2 4 1\n0 0 1 2 3 9\n1 2 1 3 4 9\n# end\n");
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_a.node", "geom_rd_a.ele", &g));
  if (g) check_two_tets(g);
  fcm_geometry_destroy(&g);
  /* 1-based, no optional header fields, commas allowed. */
  write_file("geom_rd_b.node", "5 3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0,0,1\n5 1 1 1\n");
  write_file("geom_rd_b.ele", "2 4\n1 1 2 3 4\n2 3 2 4 5\n");
  TEST_OK(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_b.node", "geom_rd_b.ele", &g));
  if (g) check_two_tets(g);
  fcm_geometry_destroy(&g);
}

static void tetgen_errors(void)
{
  fcm_geometry *g = (fcm_geometry *)&ctx;
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_missing.node", "x.ele", &g),
           FCM_ERR_IO, "geom_rd_missing.node");
  TEST_TRUE(g == NULL);
  write_file("geom_rd_e.ele", "2 4\n1 1 2 3 4\n2 2 3 4 5\n");
  write_file("geom_rd_2d.node", "3 2 0 0\n1 0 0\n2 1 0\n3 0 1\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_2d.node", "geom_rd_e.ele", &g),
           FCM_ERR_UNSUPPORTED, "dimension 2");
  write_file("geom_rd_e.node", "5 3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n");
  write_file("geom_rd_10.ele", "1 10\n1 1 2 3 4 5 5 5 5 5 5\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_e.node", "geom_rd_10.ele", &g),
           FCM_ERR_UNSUPPORTED, "10-node");
  write_file("geom_rd_idx.ele", "2 4\n1 1 2 3 4\n2 2 3 4 6\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_e.node", "geom_rd_idx.ele", &g),
           FCM_ERR_FORMAT, "geom_rd_idx.ele:3: node index = 6 outside [1, 5]");
  write_file("geom_rd_short.ele", "3 4\n1 1 2 3 4\n2 2 3 4 5\n# the third is missing\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_e.node", "geom_rd_short.ele", &g),
           FCM_ERR_FORMAT, "end of the file");
  write_file("geom_rd_gap.node", "3 3\n1 0 0 0\n3 1 0 0\n4 0 1 0\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_gap.node", "geom_rd_e.ele", &g),
           FCM_ERR_FORMAT, "geom_rd_gap.node:3: point index = 3 outside [2, 2]");
  write_file("geom_rd_nan.node", "2 3\n0 0 0 0\n1 0 abc 0\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_nan.node", "geom_rd_e.ele", &g),
           FCM_ERR_FORMAT, "geom_rd_nan.node:3: expected a finite coordinate, got \"abc\"");
  write_file("geom_rd_extra.node", "1 3 0 0\n0 0 0 0 5\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_extra.node", "geom_rd_e.ele", &g),
           FCM_ERR_FORMAT, "geom_rd_extra.node:2: expected \"index x y z\"");
  write_file("geom_rd_empty.node", "# nothing\n");
  TEST_ERR(ctx, fcm_geometry_create_from_tetgen(ctx, "geom_rd_empty.node", "geom_rd_e.ele", &g),
           FCM_ERR_FORMAT, "header");
  TEST_TRUE(g == NULL);
}

static void gmsh(void)
{
  write_file("geom_rd_tet.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n"
                                "$EndNodes\n$Elements\n3\n"
                                "1 2 2 0 1 1 2 3\n"
                                "2 4 2 0 1 1 2 3 4\n3 4 2 0 1 3 2 4 5\n$EndElements\n");
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_geometry_create_from_gmsh(ctx, "geom_rd_tet.msh", &g));
  if (g) check_two_tets(g);
  fcm_geometry_destroy(&g);
  /* One hex8 (a frustum with planar faces). */
  write_file("geom_rd_hex.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n"
                                "1 0 0 0\n2 2 0 0\n3 2 2 0\n4 0 2 0\n"
                                "5 0.5 0.5 1\n6 1.5 0.5 1\n7 1.5 1.5 1\n8 0.5 1.5 1\n"
                                "$EndNodes\n$Elements\n1\n1 5 2 0 1 1 2 3 4 5 6 7 8\n"
                                "$EndElements\n");
  TEST_OK(ctx, fcm_geometry_create_from_gmsh(ctx, "geom_rd_hex.msh", &g));
  if (g) {
    TEST_TRUE(fcm_geometry_cell_type(g) == FCM_ELEMENT_HEX8);
    TEST_NEAR(fcm_geometry_volume(g), (4.0 + 1.0 + 2.0) / 3.0, 1e-15, 0); /* frustum */
    TEST_TRUE(fcm_geometry_num_boundary_triangles(g) == 12);
  }
  fcm_geometry_destroy(&g);
  /* A warped hex (top face not planar) is rejected, naming the cell. */
  write_file("geom_rd_warp.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n"
                                 "1 0 0 0\n2 2 0 0\n3 2 2 0\n4 0 2 0\n"
                                 "5 0 0 1\n6 2 0 1\n7 2 2 1.5\n8 0 2 1\n"
                                 "$EndNodes\n$Elements\n1\n1 5 2 0 1 1 2 3 4 5 6 7 8\n"
                                 "$EndElements\n");
  TEST_ERR(ctx, fcm_geometry_create_from_gmsh(ctx, "geom_rd_warp.msh", &g), FCM_ERR_GEOMETRY,
           "hex cell 0 is not convex");
  write_file("geom_rd_t10.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n10\n"
                                "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 .5 0 0\n6 .5 .5 0\n"
                                "7 0 .5 0\n8 0 0 .5\n9 0 .5 .5\n10 .5 0 .5\n$EndNodes\n"
                                "$Elements\n1\n1 11 2 0 1 1 2 3 4 5 6 7 8 9 10\n$EndElements\n");
  TEST_ERR(ctx, fcm_geometry_create_from_gmsh(ctx, "geom_rd_t10.msh", &g), FCM_ERR_UNSUPPORTED,
           "tet10");
  TEST_ERR(ctx, fcm_geometry_create_from_gmsh(ctx, "geom_rd_none.msh", &g), FCM_ERR_IO,
           "geom_rd_none.msh");
  TEST_TRUE(g == NULL);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  tetgen_ok();
  tetgen_errors();
  gmsh();
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
