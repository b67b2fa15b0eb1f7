/* Locating points and interpolating the discrete field, for every element type:
 * located points map back to themselves, a field in the element space is
 * reproduced exactly, and points in inactive cells or outside the mesh are
 * extrapolated from the nearest active cell (exact for linear fields). The same located on a
 * tree over all the mesh's cells (fcm__space_locate_in(), the embedded surface's) gives the
 * same cells, xi and flags bit for bit, also for the mesh's nodes (on faces and edges shared
 * by several cells: the first in cell order). */
#include "fem/fem_impl.h"
#include "fem_util.h"

#include <string.h>

static void field(const double x[3], int quadratic, double u[3])
{
  u[0] = 1.0 + 2 * x[0] - x[1] + 0.5 * x[2];
  u[1] = -0.3 + x[1] + 0.25 * x[2];
  u[2] = 0.7 - x[0] + 3 * x[2];
  if (quadratic) u[0] += x[0] * x[1] - 0.5 * x[2] * x[2], u[2] += x[1] * x[1];
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const fcm_element_info *info = fcm_element_get_info(type);
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, distorted_box(ctx, type, 3, 0.2, &mesh));
  /* deactivate the cells touching the corner (1,1,1) region: cells whose nodes all have x > 0.6 */
  fcm_index nc = fcm_mesh_num_cells(mesh), nn = fcm_mesh_num_nodes(mesh);
  unsigned char *act = malloc((size_t)nc);
  const double *Xn = fcm_mesh_coords(mesh);
  for (fcm_index c = 0; c < nc; c++) {
    double xmin = 1e9;
    for (int a = 0; a < info->num_nodes; a++)
      xmin = fmin(xmin, Xn[3 * fcm_mesh_cells(mesh)[c * info->num_nodes + a]]);
    act[c] = xmin < 0.6;
  }
  TEST_OK(ctx, fcm_space_create(ctx, mesh, act, &space));
  fcm_index ndof = fcm_space_num_dofs(space);
  double *u = calloc((size_t)ndof, sizeof *u);
  /* quadratic fields are in the space only where the map is affine (tets) */
  int quad = info->complete_degree >= 2 && info->shape == FCM_SHAPE_TET;
  int affine = info->shape == FCM_SHAPE_TET;
  for (fcm_index i = 0; i < nn; i++) {
    fcm_index d = fcm_space_node_dof(space, i);
    if (d >= 0) field(Xn + 3 * i, quad, u + d);
  }
  enum { NP = 400 };
  double *P = malloc(sizeof *P * 3 * NP), *xi = malloc(sizeof *xi * 3 * NP),
         *val = malloc(sizeof *val * 3 * NP);
  fcm_index *cell = malloc(sizeof *cell * NP);
  int *ex = malloc(sizeof *ex * NP);
  unsigned long long seed = 7;
  for (int i = 0; i < NP; i++)
    for (int d = 0; d < 3; d++)
      P[3 * i + d] = 0.5 + 0.499 * urand(&seed);
  P[0] = 1.3, P[1] = -0.2, P[2] = 0.5; /* outside the mesh */
  TEST_OK(ctx, fcm_space_locate(space, NP, P, cell, xi, ex));
  TEST_OK(ctx, fcm_space_interpolate(space, NP, cell, xi, u, val));
  int inside = 0, outside = 0;
  for (int i = 0; i < NP; i++) {
    double Xc[3 * FCM_ELEMENT_MAX_NODES], x[3], ue[3];
    TEST_TRUE(fcm_space_cell_active(space, cell[i]));
    fcm_mesh_cell_coords(mesh, cell[i], Xc);
    fcm_element_map(type, Xc, xi + 3 * i, x);
    /* extrapolation from a curved cell is approximate: check it where the map is affine */
    if (!ex[i] || affine)
      for (int d = 0; d < 3; d++)
        TEST_NEAR(x[d], P[3 * i + d], 0.0, 1e-10);
    for (int d = 0; d < 3; d++)
      TEST_TRUE(isfinite(val[3 * i + d]));
    /* inside: the field of the space is exact; extrapolated: exact for linear fields */
    if (!ex[i] || (affine && !quad)) {
      field(P + 3 * i, quad, ue);
      for (int d = 0; d < 3; d++)
        TEST_NEAR(val[3 * i + d], ue[d], 0.0, 1e-10);
    }
    if (ex[i])
      outside++;
    else
      inside++;
    int in_inactive_region = 1; /* deep in the deactivated corner */
    for (int d = 0; d < 3; d++)
      in_inactive_region &= P[3 * i + d] > 0.7 && P[3 * i + d] < 1.0;
    if (in_inactive_region && P[3 * i] > 0.95) TEST_TRUE(ex[i]);
  }
  TEST_TRUE(ex[0] && inside > 100 && outside > 5);
  { /* on a tree of every cell's node bounds; the points, then the mesh's nodes */
    double *boxes = malloc(sizeof *boxes * 6 * (size_t)nc), Xc[3 * FCM_ELEMENT_MAX_NODES];
    for (fcm_index c = 0; c < nc; c++) {
      double *b = boxes + 6 * c;
      fcm_mesh_cell_coords(mesh, c, Xc);
      for (int d = 0; d < 3; d++)
        b[d] = HUGE_VAL, b[3 + d] = -HUGE_VAL;
      for (int a = 0; a < info->num_nodes; a++)
        for (int d = 0; d < 3; d++)
          b[d] = fmin(b[d], Xc[3 * a + d]), b[3 + d] = fmax(b[3 + d], Xc[3 * a + d]);
    }
    fcm_aabb_tree *tree = NULL;
    TEST_OK(ctx, fcm_aabb_tree_create(ctx, nc, boxes, &tree));
    for (int pass = 0; pass < 2 && tree; pass++) {
      const fcm_index n = pass ? nn : NP;
      const double *Q = pass ? Xn : P;
      fcm_index *c0 = malloc(sizeof *c0 * (size_t)n), *c1 = malloc(sizeof *c1 * (size_t)n);
      double *x0 = malloc(sizeof *x0 * 3 * (size_t)n), *x1 = malloc(sizeof *x1 * 3 * (size_t)n);
      int *e0 = malloc(sizeof *e0 * (size_t)n), *e1 = malloc(sizeof *e1 * (size_t)n);
      TEST_OK(ctx, fcm_space_locate(space, n, Q, c0, x0, e0));
      TEST_OK(ctx, fcm__space_locate_in(space, tree, n, Q, c1, x1, e1));
      TEST_TRUE(!memcmp(c0, c1, sizeof *c0 * (size_t)n));
      TEST_TRUE(!memcmp(x0, x1, sizeof *x0 * 3 * (size_t)n));
      TEST_TRUE(!memcmp(e0, e1, sizeof *e0 * (size_t)n));
      free(c0), free(c1), free(x0), free(x1), free(e0), free(e1);
    }
    fcm_aabb_tree_destroy(&tree);
    /* a tree of other items than the mesh's cells */
    TEST_OK(ctx, fcm_aabb_tree_create(ctx, nc - 1, boxes, &tree));
    if (tree)
      TEST_ERR(ctx, fcm__space_locate_in(space, tree, NP, P, cell, xi, ex), FCM_ERR_ARG, "tree");
    fcm_aabb_tree_destroy(&tree);
    free(boxes);
  }
  cell[3] = -1;
  TEST_ERR(ctx, fcm_space_interpolate(space, NP, cell, xi, u, val), FCM_ERR_ARG, "point 3");
  free(act), free(u), free(P), free(xi), free(val), free(cell), free(ex);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
