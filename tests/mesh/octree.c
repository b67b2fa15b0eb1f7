/* Octree backgrounds (Hex8 and Hex20): cells refined toward a sphere surface and a region,
 * balanced 2:1 across faces and edges (checked on every pair of touching cells from their
 * coordinates alone), volumes summing to the box with every sample point in exactly one cell,
 * boundary faces covering exactly the box surface, cell sizes matching their levels, hanging
 * nodes lying on their cells, and bad input refused. */
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double sphere(const double x[3], void *user)
{
  (void)user;
  return sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 0.55;
}

static int near_corner(const double lo[3], const double hi[3], int level, void *user)
{
  (void)level, (void)user;
  return hi[0] > 0.8 && hi[1] > 0.8 && lo[2] < 0.1;
}

/* Cell c's box from its corner nodes 0 and 6 (VTK: (-1,-1,-1) and (1,1,1)). */
static void cell_box(const fcm_mesh *m, fcm_index c, double lo[3], double hi[3])
{
  const int npc = fcm_mesh_nodes_per_cell(m);
  const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
  const double *X = fcm_mesh_coords(m);
  for (int d = 0; d < 3; d++)
    lo[d] = X[3 * cn[0] + d], hi[d] = X[3 * cn[6] + d];
}

static int failing(const double lo[3], const double hi[3], int level, void *user)
{
  (void)lo, (void)hi, (void)user;
  return level == 1 ? -1 : 1;
}

static unsigned long long seed = 7;
static double urand01(void)
{
  seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(seed >> 11) / 9007199254740992.0;
}

/* The geometric checks of an octree mesh over the unit box (criteria of check(): with_levels,
 * the levels those criteria give). */
static void check_mesh(fcm_ctx *ctx, const fcm_mesh *m, fcm_element_type type, int with_levels)
{
  const fcm_index nc = fcm_mesh_num_cells(m);
  double *B = malloc(sizeof *B * 6 * (size_t)nc);
  double vol = 0.0;
  int seen[FCM_OCTREE_MAX_LEVEL + 1] = {0};
  for (fcm_index c = 0; c < nc; c++) {
    cell_box(m, c, B + 6 * c, B + 6 * c + 3);
    const int l = fcm_mesh_cell_level(m, c);
    TEST_TRUE(l >= 0 && l <= FCM_OCTREE_MAX_LEVEL);
    seen[l] = 1;
    double v = 1.0;
    for (int d = 0; d < 3; d++) {
      const double h = B[6 * c + 3 + d] - B[6 * c + d];
      TEST_NEAR(h, 0.5 / (double)(1 << l), 1e-14, 0.0); /* size matches the level */
      v *= h;
    }
    vol += v;
  }
  if (with_levels) TEST_TRUE(seen[1] && seen[2] && seen[3] && seen[4]);
  TEST_NEAR(vol, 1.0, 1e-13, 0.0);
  /* cells near the sphere are at level >= 3; the region corner is refined */
  for (fcm_index c = 0; c < nc; c++) {
    const double *b = B + 6 * c;
    double x[3] = {0.5 * (b[0] + b[3]), 0.5 * (b[1] + b[4]), 0.5 * (b[2] + b[5])};
    if (fabs(sphere(x, NULL)) < 1e-3) TEST_TRUE(fcm_mesh_cell_level(m, c) >= 3);
  }
  /* every random point lies in exactly one cell (no gaps, no overlaps) */
  for (int s = 0; s < 2000; s++) {
    const double x[3] = {urand01(), urand01(), urand01()};
    int inside = 0;
    for (fcm_index c = 0; c < nc; c++) {
      const double *b = B + 6 * c;
      inside +=
          x[0] > b[0] && x[0] < b[3] && x[1] > b[1] && x[1] < b[4] && x[2] > b[2] && x[2] < b[5];
    }
    TEST_TRUE(inside == 1);
  }
  /* 2:1 balance: cells whose closed boxes share a face or an edge (a contact of dimension
   * >= 1) differ by at most one level */
  int worst = 0;
  for (fcm_index a = 0; a < nc; a++)
    for (fcm_index b = a + 1; b < nc; b++) {
      int dim = 0, touch = 1;
      for (int d = 0; d < 3; d++) {
        const double ov =
            fmin(B[6 * a + 3 + d], B[6 * b + 3 + d]) - fmax(B[6 * a + d], B[6 * b + d]);
        touch &= ov > -1e-12;
        dim += ov > 1e-12;
      }
      if (touch && dim >= 1) {
        const int dl = abs(fcm_mesh_cell_level(m, a) - fcm_mesh_cell_level(m, b));
        worst = dl > worst ? dl : worst;
      }
    }
  TEST_TRUE(worst == 1);
  /* boundary faces: exactly the box surface (area 6); faces against other levels are
   * marked non-conforming, never -1 */
  const fcm_element_info *info = fcm_mesh_get_element_info(m);
  const fcm_index nb = fcm_mesh_num_boundary_faces(m), *bf = fcm_mesh_boundary_faces(m);
  const fcm_index *nbr = fcm_mesh_neighbors(m);
  double area = 0.0;
  for (fcm_index i = 0; i < nb; i++) {
    const double *b = B + 6 * bf[2 * i];
    const int f = (int)bf[2 * i + 1];
    double a = 1.0;
    int on = 0;
    for (int d = 0; d < 3; d++) {
      const double h = b[3 + d] - b[d];
      /* the face's own axis is the one along which its corners agree */
      const double *X = fcm_mesh_coords(m);
      const fcm_index *cn = fcm_mesh_cells(m) + (size_t)info->num_nodes * bf[2 * i];
      int flat = 1;
      for (int k = 1; k < 4; k++)
        flat &= X[3 * cn[info->face_nodes[f][k]] + d] == X[3 * cn[info->face_nodes[f][0]] + d];
      if (flat) {
        const double x = X[3 * cn[info->face_nodes[f][0]] + d];
        on = x == 0.0 || x == 1.0;
      } else {
        a *= h;
      }
    }
    TEST_TRUE(on);
    area += a;
  }
  TEST_NEAR(area, 6.0, 1e-13, 0.0);
  fcm_index nonconf = 0;
  for (fcm_index i = 0; i < nc * info->num_faces; i++)
    nonconf += nbr[i] == FCM_MESH_NEIGHBOR_NONCONFORMING;
  TEST_TRUE(nonconf > 0);
  /* hanging pairs: the node is where the cell's map puts xi, on the cell's boundary, and not
   * one of the cell's nodes */
  for (fcm_index i = 0; i < fcm_mesh_num_hanging(m); i++) {
    fcm_index c = 0, node = 0;
    double xi[3], X[3 * 20], x[3];
    fcm_mesh_get_hanging(m, i, &c, &node, xi);
    fcm_mesh_cell_coords(m, c, X);
    fcm_element_map(type, X, xi, x);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(x[d], fcm_mesh_coords(m)[3 * node + d], 0.0, 1e-15);
    TEST_TRUE(fabs(xi[0]) == 1 || fabs(xi[1]) == 1 || fabs(xi[2]) == 1);
    for (int a = 0; a < info->num_nodes; a++)
      TEST_TRUE(fcm_mesh_cells(m)[(size_t)info->num_nodes * c + a] != node);
  }
  TEST_OK(ctx, fcm_mesh_validate(ctx, m, 0, NULL, NULL));
  free(B);
}

static int check(fcm_element_type type)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {2, 2, 2};
  fcm_octree_options o = fcm_octree_options_default();
  o.surface = sphere;
  o.surface_level = 3;
  o.region_level = 1;
  o.region_lo[0] = o.region_lo[1] = o.region_lo[2] = 0.9;
  o.region_hi[0] = o.region_hi[1] = o.region_hi[2] = 1.0;
  o.refine = near_corner;
  o.refine_level = 4;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n, &o, &m));
  TEST_TRUE(fcm_mesh_is_octree(m));
  TEST_TRUE(fcm_mesh_max_level(m) == 4);
  TEST_TRUE(fcm_mesh_num_hanging(m) > 0);
  check_mesh(ctx, m, type, 1);
  { /* the summary reports the cells per level */
    FILE *f = tmpfile();
    char text[1024] = {0};
    fcm_mesh_view(m, f);
    rewind(f);
    TEST_TRUE(fread(text, 1, sizeof text - 1, f) > 0);
    fclose(f);
    TEST_TRUE(strstr(text, "cells per level: 0: ") != NULL && strstr(text, ", 4: ") != NULL);
  }
  /* refine further: cells with centre x < 0.3 are split and the result checked alike */
  const fcm_index nc = fcm_mesh_num_cells(m);
  unsigned char *flags = calloc((size_t)nc, 1);
  fcm_index nflag = 0;
  for (fcm_index c = 0; c < nc; c++) {
    double blo[3], bhi[3];
    cell_box(m, c, blo, bhi);
    nflag += flags[c] = 0.5 * (blo[0] + bhi[0]) < 0.3;
  }
  fcm_mesh *m2 = NULL;
  TEST_OK(ctx, fcm_mesh_create_refined(ctx, m, flags, &m2));
  TEST_TRUE(fcm_mesh_num_cells(m2) >= nc + 7 * nflag);
  check_mesh(ctx, m2, type, 0);
  for (fcm_index c = 0; c < nc; c++) { /* every flagged cell's region is one level finer */
    if (!flags[c]) continue;
    double blo[3], bhi[3];
    cell_box(m, c, blo, bhi);
    for (fcm_index c2 = 0; c2 < fcm_mesh_num_cells(m2); c2++) {
      double lo2[3], hi2[3];
      cell_box(m2, c2, lo2, hi2);
      int inside = 1;
      for (int d = 0; d < 3; d++)
        inside &= lo2[d] >= blo[d] && hi2[d] <= bhi[d];
      if (inside) TEST_TRUE(fcm_mesh_cell_level(m2, c2) > fcm_mesh_cell_level(m, c));
    }
  }
  free(flags);
  fcm_mesh_destroy(&m2);
  fcm_mesh_destroy(&m);

  /* no criteria: the box grid, node for node */
  fcm_mesh *box = NULL;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n, NULL, &m));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &box));
  TEST_TRUE(fcm_mesh_num_cells(m) == 8 && fcm_mesh_num_hanging(m) == 0);
  TEST_TRUE(fcm_mesh_num_nodes(m) == fcm_mesh_num_nodes(box));
  {
    unsigned char none[8] = {0};
    fcm_mesh *r = NULL;
    TEST_ERR(ctx, fcm_mesh_create_refined(ctx, box, none, &r), FCM_ERR_UNSUPPORTED,
             "only octree meshes are refined");
    TEST_TRUE(r == NULL);
  }
  TEST_TRUE(fcm_mesh_num_boundary_faces(m) == fcm_mesh_num_boundary_faces(box));
  fcm_mesh_destroy(&m);
  fcm_mesh_destroy(&box);

  /* bad input */
  o = fcm_octree_options_default();
  o.region_level = FCM_OCTREE_MAX_LEVEL + 1;
  TEST_ERR(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n, &o, &m), FCM_ERR_ARG,
           "region_level = 13 out of range [0, 12]");
  TEST_TRUE(m == NULL);
  o = fcm_octree_options_default();
  o.surface_level = 2;
  TEST_ERR(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n, &o, &m), FCM_ERR_ARG,
           "needs a surface level set");
  o = fcm_octree_options_default();
  o.refine = failing;
  o.refine_level = 3;
  TEST_ERR(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n, &o, &m), FCM_ERR_ARG,
           "refine callback failed (returned -1) on the level 1 cell");
  TEST_TRUE(m == NULL);
  TEST_ERR(ctx, fcm_mesh_create_octree(ctx, FCM_ELEMENT_TET4, lo, hi, n, NULL, &m),
           FCM_ERR_UNSUPPORTED, "octree refinement needs hexahedra");
  TEST_ERR(ctx, fcm_mesh_create_octree(ctx, FCM_ELEMENT_TET10, lo, hi, n, NULL, &m),
           FCM_ERR_UNSUPPORTED, "tet10");
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return 0;
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  check(type);
  return TEST_RESULT();
}
