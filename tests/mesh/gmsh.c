/* fcm_mesh_create_from_gmsh on files written here: MSH 4.1 and 2.2, Tet4/Tet10/Hex8/Hex20,
 * sparse shuffled node tags, skipped sections and boundary elements, an unused node.
 * Gmsh's mid-edge order comes from the Gmsh manual's edge lists, written out below; the
 * check is geometric: VTK mid-edge node k must be the midpoint of VTK edge k. */
#include "mesh_util.h"

#include <stdio.h>

/* Gmsh mid-edge nodes {node, end a, end b} (Gmsh reference manual, node ordering). */
static const int gmsh_tet10_edges[6][3] = {{4, 0, 1}, {5, 1, 2}, {6, 2, 0},
                                           {7, 0, 3}, {8, 2, 3}, {9, 1, 3}};
static const int gmsh_hex20_edges[12][3] = {{8, 0, 1},  {9, 0, 3},  {10, 0, 4}, {11, 1, 2},
                                            {12, 1, 5}, {13, 2, 3}, {14, 2, 6}, {15, 3, 7},
                                            {16, 4, 5}, {17, 4, 7}, {18, 5, 6}, {19, 6, 7}};

static int gmsh_type_of(fcm_element_type t)
{
  static const int g[4] = {4, 11, 5, 17};
  return g[t];
}

/* gmsh_local[k] = VTK local node at Gmsh local node k, matched by edge end points. */
static void gmsh_from_vtk(fcm_element_type t, int *gmsh_local)
{
  const fcm_element_info *info = fcm_element_get_info(t);
  int nv = 0;
  const int(*vtk)[3] = vtk_mid_edges(t, &nv);
  const int(*gm)[3] = t == FCM_ELEMENT_TET10 ? gmsh_tet10_edges : gmsh_hex20_edges;
  for (int a = 0; a < info->num_corners; a++)
    gmsh_local[a] = a;
  for (int k = 0; k < nv; k++) {
    gmsh_local[gm[k][0]] = -1;
    for (int e = 0; e < nv; e++) {
      int same = (vtk[e][1] == gm[k][1] && vtk[e][2] == gm[k][2]) ||
                 (vtk[e][1] == gm[k][2] && vtk[e][2] == gm[k][1]);
      if (same) gmsh_local[gm[k][0]] = vtk[e][0];
    }
  }
}

/* A mesh to write: nodes (coordinates, tags, file order) and cells in VTK order. */
typedef struct source {
  fcm_element_type type;
  fcm_index nn, nc;
  const double *x;
  const fcm_index *cells;
  long long *tag;   /* tag of node i */
  fcm_index *order; /* file position -> node */
} source;

/* Write `s` as MSH 4.1 or 2.2 with extra sections, boundary elements and one unused node
 * (tag 777777). Returns 0 on success. */
static int write_msh(const char *path, int version, const source *s)
{
  const fcm_element_info *info = fcm_element_get_info(s->type);
  const int npc = info->num_nodes, gt = gmsh_type_of(s->type);
  int gl[FCM_ELEMENT_MAX_NODES];
  gmsh_from_vtk(s->type, gl);
  FILE *fp = fopen(path, "w");
  if (!fp) return 1;
  const long long unused = 777777;
  const fcm_index *c0 = s->cells;
  long long mintag = unused, maxtag = unused;
  for (fcm_index i = 0; i < s->nn; i++) {
    mintag = s->tag[i] < mintag ? s->tag[i] : mintag;
    maxtag = s->tag[i] > maxtag ? s->tag[i] : maxtag;
  }
  const long long nelem = 2 + s->nc; /* one point, one triangle, the cells */
  if (version == 41) {
    fprintf(fp, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    fprintf(fp, "$PhysicalNames\n1\n3 1 \"the solid\"\n$EndPhysicalNames\n");
    fprintf(fp, "$Entities\n1 0 1 1\n1 0 0 0 0 0\n1 0 0 0 1 1 1 0 0\n"
                "1 0 0 0 1 1 1 1 1 1 1\n$EndEntities\n");
    fcm_index half = s->nn / 2;
    fprintf(fp, "$Nodes\n2 %lld %lld %lld\n", (long long)s->nn + 1, mintag, maxtag);
    /* Block 1: surface nodes with parametric (u, v), plus the unused node. */
    fprintf(fp, "2 1 1 %lld\n", (long long)half + 1);
    for (fcm_index p = 0; p < half; p++)
      fprintf(fp, "%lld\n", s->tag[s->order[p]]);
    fprintf(fp, "%lld\n", unused);
    for (fcm_index p = 0; p < half; p++) {
      const double *y = s->x + 3 * s->order[p];
      fprintf(fp, "%.17g %.17g %.17g 0.25 0.5\n", y[0], y[1], y[2]);
    }
    fprintf(fp, "9 9 9 0 0\n");
    fprintf(fp, "3 1 0 %lld\n", (long long)(s->nn - half));
    for (fcm_index p = half; p < s->nn; p++)
      fprintf(fp, "%lld\n", s->tag[s->order[p]]);
    for (fcm_index p = half; p < s->nn; p++) {
      const double *y = s->x + 3 * s->order[p];
      fprintf(fp, "%.17g %.17g %.17g\n", y[0], y[1], y[2]);
    }
    fprintf(fp, "$EndNodes\n");
    /* Element tags 10, 12, 14, ...: a point, a triangle, then the cells in two blocks. */
    fcm_index split = s->nc / 2;
    fprintf(fp, "$Elements\n%d %lld 10 %lld\n", split > 0 ? 4 : 3, nelem, 10 + 2 * (nelem - 1));
    fprintf(fp, "0 1 15 1\n10 %lld\n", s->tag[c0[0]]);
    fprintf(fp, "2 1 2 1\n12 %lld %lld %lld\n", s->tag[c0[0]], s->tag[c0[1]], s->tag[c0[2]]);
    for (int blk = 0; blk < 2; blk++) {
      fcm_index from = blk ? split : 0, to = blk ? s->nc : split;
      if (to == from) continue;
      fprintf(fp, "3 1 %d %lld\n", gt, (long long)(to - from));
      for (fcm_index c = from; c < to; c++) {
        fprintf(fp, "%lld", 14 + 2 * (long long)c);
        for (int k = 0; k < npc; k++)
          fprintf(fp, " %lld", s->tag[s->cells[npc * c + gl[k]]]);
        fprintf(fp, "\n");
      }
    }
    fprintf(fp, "$EndElements\n");
  } else {
    fprintf(fp, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    fprintf(fp, "$PhysicalNames\n1\n3 1 \"the solid\"\n$EndPhysicalNames\n");
    fprintf(fp, "$Nodes\n%lld\n", (long long)s->nn + 1);
    for (fcm_index p = 0; p < s->nn; p++) {
      const double *y = s->x + 3 * s->order[p];
      fprintf(fp, "%lld %.17g %.17g %.17g\n", s->tag[s->order[p]], y[0], y[1], y[2]);
      if (p == s->nn / 2) fprintf(fp, "%lld 9 9 9\n", unused);
    }
    fprintf(fp, "$EndNodes\n$Elements\n%lld\n", nelem);
    fprintf(fp, "3 15 2 0 1 %lld\n", s->tag[c0[0]]);
    fprintf(fp, "5 2 2 0 1 %lld %lld %lld\n", s->tag[c0[0]], s->tag[c0[1]], s->tag[c0[2]]);
    for (fcm_index c = 0; c < s->nc; c++) {
      fprintf(fp, "%lld %d 2 1 1", 100 + 3 * (long long)c, gt);
      for (int k = 0; k < npc; k++)
        fprintf(fp, " %lld", s->tag[s->cells[npc * c + gl[k]]]);
      fprintf(fp, "\n");
    }
    fprintf(fp, "$EndElements\n$NodeData\n1\n\"ignored\"\n0\n0\n$EndNodeData\n");
  }
  return fclose(fp) != 0;
}

/* Read `path` and compare with `s`: same type and counts, same cells (file order) with the
 * same coordinates at every VTK local node, mid-edge nodes at their VTK edges' midpoints. */
static void check_read(fcm_ctx *ctx, const char *path, const source *s)
{
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_mesh_create_from_gmsh(ctx, path, &m));
  if (!m) return;
  const fcm_element_info *info = fcm_element_get_info(s->type);
  const int npc = info->num_nodes;
  TEST_TRUE(fcm_mesh_element_type(m) == s->type);
  TEST_TRUE(fcm_mesh_num_nodes(m) == s->nn); /* the unused node is dropped */
  TEST_TRUE(fcm_mesh_num_cells(m) == s->nc);
  int nmid = 0;
  const int(*mid)[3] = vtk_mid_edges(s->type, &nmid);
  for (fcm_index c = 0; c < s->nc && c < fcm_mesh_num_cells(m); c++) {
    double X[3 * FCM_ELEMENT_MAX_NODES];
    fcm_mesh_cell_coords(m, c, X);
    for (int a = 0; a < npc; a++)
      for (int d = 0; d < 3; d++)
        TEST_TRUE(X[3 * a + d] == s->x[3 * s->cells[npc * c + a] + d]);
    for (int e = 0; e < nmid; e++)
      for (int d = 0; d < 3; d++)
        TEST_NEAR(X[3 * mid[e][0] + d], 0.5 * (X[3 * mid[e][1] + d] + X[3 * mid[e][2] + d]), 0,
                  1e-14);
  }
  TEST_OK(ctx, fcm_mesh_validate(ctx, m, 0, NULL, NULL));
  fcm_mesh_destroy(&m);
}

/* One cell in general position (no two edges share a midpoint). */
static void single_cell(fcm_ctx *ctx, fcm_element_type t)
{
  const double tet[12] = {0.1, -0.2, 0.05, 1.3, 0.1, -0.1, 0.2, 1.1, 0.15, -0.05, 0.3, 0.9};
  const double hex[24] = {0.02, 0.01,  -0.03, 1.1,  -0.05, 0.04,  0.95, 1.03,
                          0.01, -0.04, 0.9,   0.06, 0.03,  -0.02, 1.05, 1.02,
                          0.05, 0.97,  1.07,  1.1,  1.12,  0.01,  0.98, 0.95};
  const fcm_element_info *info = fcm_element_get_info(t);
  const int npc = info->num_nodes, nc = info->num_corners;
  double x[3 * FCM_ELEMENT_MAX_NODES];
  fcm_index cells[FCM_ELEMENT_MAX_NODES], order[FCM_ELEMENT_MAX_NODES];
  long long tag[FCM_ELEMENT_MAX_NODES];
  memcpy(x, is_tet_type(t) ? tet : hex, sizeof *x * 3 * (size_t)nc);
  int nmid = 0;
  const int(*mid)[3] = vtk_mid_edges(t, &nmid);
  for (int e = 0; e < nmid; e++)
    for (int d = 0; d < 3; d++)
      x[3 * mid[e][0] + d] = 0.5 * (x[3 * mid[e][1] + d] + x[3 * mid[e][2] + d]);
  for (int a = 0; a < npc; a++) {
    cells[a] = a;
    order[a] = npc - 1 - a; /* nodes listed in reverse */
    tag[a] = 1000 - 37 * a; /* sparse, descending */
  }
  source s = {t, npc, 1, x, cells, tag, order};
  char path[64];
  for (int v = 0; v < 2; v++) {
    snprintf(path, sizeof path, "mesh_gmsh_cell_%s_v%d.msh", info->name, v ? 22 : 41);
    TEST_TRUE(write_msh(path, v ? 22 : 41, &s) == 0);
    check_read(ctx, path, &s);
    remove(path);
  }
}

/* A 2 x 1 x 2 box mesh written with scattered tags and a scrambled node order. */
static void box(fcm_ctx *ctx, fcm_element_type t)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1.5};
  const fcm_index n[3] = {2, 1, 2};
  fcm_mesh *b = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, t, lo, hi, n, &b));
  if (!b) return;
  const fcm_index nn = fcm_mesh_num_nodes(b);
  long long *tag = malloc(sizeof *tag * (size_t)nn);
  fcm_index *order = malloc(sizeof *order * (size_t)nn);
  for (fcm_index i = 0; i < nn; i++) {
    tag[i] = 5 + 3 * i + (i % 2) * 100000;
    order[i] = (7 * i + 3) % nn; /* a permutation when gcd(7, nn) == 1 */
  }
  if (nn % 7 == 0)
    for (fcm_index i = 0; i < nn; i++)
      order[i] = nn - 1 - i;
  source s = {t, nn, fcm_mesh_num_cells(b), fcm_mesh_coords(b), fcm_mesh_cells(b), tag, order};
  char path[64];
  for (int v = 0; v < 2; v++) {
    snprintf(path, sizeof path, "mesh_gmsh_box_%s_v%d.msh", fcm_element_get_info(t)->name,
             v ? 22 : 41);
    TEST_TRUE(write_msh(path, v ? 22 : 41, &s) == 0);
    check_read(ctx, path, &s);
    fcm_mesh *m = NULL;
    TEST_OK(ctx, fcm_mesh_create_from_gmsh(ctx, path, &m));
    if (m) TEST_TRUE(fcm_mesh_num_boundary_faces(m) == fcm_mesh_num_boundary_faces(b));
    fcm_mesh_destroy(&m);

    /* Allocation failures while reading free everything. */
    if (t == FCM_ELEMENT_HEX20) {
      failing f;
      fcm_ctx *fctx = failing_ctx(&f);
      int ok = 0;
      for (long k = 0; fctx && k < 100 && !ok; k++) {
        f.count = 0;
        f.fail_at = k;
        fcm_status st = fcm_mesh_create_from_gmsh(fctx, path, &m);
        f.fail_at = -1;
        if (st == FCM_OK) {
          ok = 1;
          TEST_TRUE(k > 0 && fcm_mesh_num_cells(m) == s.nc);
          fcm_mesh_destroy(&m);
        } else {
          TEST_TRUE(st == FCM_ERR_ALLOC && m == NULL);
        }
        TEST_TRUE(fcm_ctx_live_allocations(fctx) == 0);
      }
      TEST_TRUE(ok);
      fcm_ctx_destroy(&fctx);
    }
    remove(path);
  }
  free(tag);
  free(order);
  fcm_mesh_destroy(&b);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++) {
    single_cell(ctx, (fcm_element_type)t);
    box(ctx, (fcm_element_type)t);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
