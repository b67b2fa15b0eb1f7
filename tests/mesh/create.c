/* fcm_mesh_create: copies of caller arrays, accessors, face adjacency and boundary
 * faces of small hand-made meshes, argument errors, allocation failures. */
#include "alloc_loop.h"
#include "mesh_util.h"

/* Two unit cubes side by side along x: nodes (i, j, k), i in 0..2, j, k in 0..1. */
static void two_cubes(double *x, fcm_index *cells)
{
  for (int k = 0; k < 2; k++)
    for (int j = 0; j < 2; j++)
      for (int i = 0; i < 3; i++) {
        double *p = x + 3 * (i + 3 * (j + 2 * k));
        p[0] = i, p[1] = j, p[2] = k;
      }
  for (int c = 0; c < 2; c++) {
    const int b = c; /* node id of corner (c, 0, 0) */
    const fcm_index v[8] = {b, b + 1, b + 4, b + 3, b + 6, b + 7, b + 10, b + 9};
    memcpy(cells + 8 * c, v, sizeof v);
  }
}

static void test_two_cubes(fcm_ctx *ctx)
{
  double x[36];
  fcm_index cells[16];
  fcm_mesh *m = NULL;
  two_cubes(x, cells);
  TEST_OK(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, 12, x, 2, cells, &m));
  if (!m) return;
  /* The mesh owns copies: changing the caller arrays does not change it. */
  x[0] = 99.0;
  cells[0] = 5;
  TEST_TRUE(fcm_mesh_element_type(m) == FCM_ELEMENT_HEX8);
  TEST_TRUE(fcm_mesh_nodes_per_cell(m) == 8);
  TEST_TRUE(fcm_mesh_num_nodes(m) == 12 && fcm_mesh_num_cells(m) == 2);
  TEST_TRUE(fcm_mesh_coords(m)[0] == 0.0 && fcm_mesh_cells(m)[0] == 0);
  TEST_TRUE(fcm_mesh_get_element_info(m) == fcm_element_get_info(FCM_ELEMENT_HEX8));

  double X[24];
  fcm_mesh_cell_coords(m, 1, X);
  TEST_NEAR(X[3 * 6 + 0], 2.0, 0, 0); /* corner 6 of cell 1 is (2, 1, 1) */
  TEST_NEAR(X[3 * 6 + 1], 1.0, 0, 0);
  TEST_NEAR(X[3 * 6 + 2], 1.0, 0, 0);
  TEST_NEAR(cell_volume(FCM_ELEMENT_HEX8, X), 1.0, 1e-14, 0);

  /* Exactly one face pair is shared: the face of cell 0 at x = 1 and of cell 1 at x = 1. */
  const fcm_element_info *info = fcm_mesh_get_element_info(m);
  const fcm_index *nb = fcm_mesh_neighbors(m);
  int shared = 0;
  for (int c = 0; c < 2; c++)
    for (int f = 0; f < 6; f++) {
      fcm_index o = nb[6 * c + f];
      if (o < 0) continue;
      shared++;
      TEST_TRUE(o == 1 - c);
      /* Every corner of the shared face lies on x = 1. */
      fcm_mesh_cell_coords(m, c, X);
      for (int k = 0; k < 4; k++)
        TEST_NEAR(X[3 * info->face_nodes[f][k]], 1.0, 0, 0);
    }
  TEST_TRUE(shared == 2);
  TEST_TRUE(fcm_mesh_num_boundary_faces(m) == 10);
  const fcm_index *bf = fcm_mesh_boundary_faces(m);
  for (fcm_index i = 0; i < fcm_mesh_num_boundary_faces(m); i++) {
    TEST_TRUE(nb[6 * bf[2 * i] + bf[2 * i + 1]] == -1);
    if (i > 0) TEST_TRUE(6 * bf[2 * i] + bf[2 * i + 1] > 6 * bf[2 * i - 2] + bf[2 * i - 1]);
  }
  double lo[3], hi[3];
  fcm_mesh_bounding_box(m, lo, hi);
  TEST_TRUE(lo[0] == 0 && lo[1] == 0 && lo[2] == 0 && hi[0] == 2 && hi[1] == 1 && hi[2] == 1);
  fcm_mesh_destroy(&m);
  TEST_TRUE(m == NULL);
  fcm_mesh_destroy(&m);
  fcm_mesh_destroy(NULL);
}

static void test_tets(fcm_ctx *ctx)
{
  /* Two tets sharing the face (0, 1, 2): apexes above and below. */
  const double x[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1};
  const fcm_index cells[8] = {0, 1, 2, 3, 0, 2, 1, 4};
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_TET4, 5, x, 2, cells, &m));
  if (!m) return;
  const fcm_index *nb = fcm_mesh_neighbors(m);
  int shared = 0;
  for (int i = 0; i < 8; i++)
    shared += nb[i] >= 0;
  TEST_TRUE(shared == 2);
  TEST_TRUE(fcm_mesh_num_boundary_faces(m) == 6);
  fcm_mesh_destroy(&m);

  /* A third tet on the same triangle makes the mesh non-manifold. */
  const double x3[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 1, 1, 1};
  const fcm_index c3[12] = {0, 1, 2, 3, 0, 2, 1, 4, 0, 1, 2, 5};
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_TET4, 6, x3, 3, c3, &m), FCM_ERR_GEOMETRY,
           "shared by more than two cells (0, 1, 2)");
  TEST_TRUE(m == NULL);

  /* An empty mesh is valid. */
  TEST_OK(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_TET10, 0, NULL, 0, NULL, &m));
  if (m) TEST_TRUE(fcm_mesh_num_boundary_faces(m) == 0 && fcm_mesh_num_cells(m) == 0);
  fcm_mesh_destroy(&m);
}

static void test_errors(fcm_ctx *ctx)
{
  double x[36];
  fcm_index cells[16];
  fcm_mesh *m = (fcm_mesh *)&x; /* must be reset to NULL on failure */
  two_cubes(x, cells);
  TEST_ERR(ctx, fcm_mesh_create(ctx, (fcm_element_type)7, 12, x, 2, cells, &m), FCM_ERR_ARG,
           "element type 7 out of range [0, 4)");
  TEST_TRUE(m == NULL);
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, -1, x, 2, cells, &m), FCM_ERR_ARG,
           "num_nodes = -1 out of range");
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, 12, NULL, 2, cells, &m), FCM_ERR_ARG,
           "coords is NULL");
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, 12, x, 2, NULL, &m), FCM_ERR_ARG,
           "cells is NULL");
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, 12, x, 2, cells, NULL), FCM_ERR_ARG,
           "must not be NULL");
  cells[13] = 12;
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, 12, x, 2, cells, &m), FCM_ERR_ARG,
           "hex8 cell 1, local node 5: node id 12 out of range [0, 12)");
  cells[13] = cells[12];
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, 12, x, 2, cells, &m), FCM_ERR_ARG,
           "hex8 cell 1 repeats node 7 at local nodes 4 and 5");
  two_cubes(x, cells);
  x[3 * 4 + 1] = NAN;
  TEST_ERR(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, 12, x, 2, cells, &m), FCM_ERR_ARG,
           "coordinate 1 of node 4 (0-based) is nan");
  TEST_TRUE(m == NULL);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
}

typedef struct two_cubes_case {
  fcm_ctx *ctx;
  double x[36];
  fcm_index cells[16];
  fcm_mesh *m;
} two_cubes_case;

static fcm_status create_two_cubes(void *user)
{
  two_cubes_case *c = user;
  fcm_status st = fcm_mesh_create(c->ctx, FCM_ELEMENT_HEX8, 12, c->x, 2, c->cells, &c->m);
  if (st == FCM_OK) TEST_TRUE(fcm_mesh_num_boundary_faces(c->m) == 10);
  return st != FCM_OK && c->m ? FCM_ERR_INTERNAL : st;
}

static void destroy_two_cubes(void *user)
{
  fcm_mesh_destroy(&((two_cubes_case *)user)->m);
}

static void test_alloc_failure(void)
{
  failing f;
  two_cubes_case c = {failing_ctx(&f), {0}, {0}, NULL};
  TEST_TRUE(c.ctx != NULL);
  if (!c.ctx) return;
  two_cubes(c.x, c.cells);
  alloc_loop(c.ctx, &f, "fcm_mesh_create", create_two_cubes, destroy_two_cubes, &c, 1, 50);
  fcm_ctx_destroy(&c.ctx);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  test_two_cubes(ctx);
  test_tets(ctx);
  test_errors(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  test_alloc_failure();
  return TEST_RESULT();
}
