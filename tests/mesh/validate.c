/* fcm_mesh_validate (det J > 0 at corners and given points) and the convexity query
 * (planar faces, straight edges, convex) on box meshes with deliberately broken cells. */
#include "mesh_util.h"

/* A copy of box(type, [lo, hi], n) whose arrays `edit` may change before it is built. */
typedef struct editable {
  fcm_index nn, nc;
  int npc;
  double *x;
  fcm_index *cells;
} editable;

static int make_editable(fcm_ctx *ctx, fcm_element_type t, double lo, double hi,
                         const fcm_index n[3], editable *e)
{
  const double l3[3] = {lo, lo, lo}, h3[3] = {hi, hi, hi};
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, t, l3, h3, n, &m));
  if (!m) return 1;
  e->nn = fcm_mesh_num_nodes(m);
  e->nc = fcm_mesh_num_cells(m);
  e->npc = fcm_mesh_nodes_per_cell(m);
  e->x = malloc(sizeof *e->x * 3 * (size_t)e->nn);
  e->cells = malloc(sizeof *e->cells * (size_t)(e->nc * e->npc));
  memcpy(e->x, fcm_mesh_coords(m), sizeof *e->x * 3 * (size_t)e->nn);
  memcpy(e->cells, fcm_mesh_cells(m), sizeof *e->cells * (size_t)(e->nc * e->npc));
  fcm_mesh_destroy(&m);
  return 0;
}

static fcm_mesh *build(fcm_ctx *ctx, fcm_element_type t, const editable *e)
{
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_mesh_create(ctx, t, e->nn, e->x, e->nc, e->cells, &m));
  return m;
}

static void free_editable(editable *e)
{
  free(e->x);
  free(e->cells);
}

static void test_inverted(fcm_ctx *ctx)
{
  const fcm_index n2[3] = {2, 2, 2}, n1[3] = {1, 1, 1};
  editable e;
  double min_det = 0;
  /* Hex8 grid of unit cubes: det J = (1/2)^3 everywhere; swap bottom and top of cell 5. */
  if (make_editable(ctx, FCM_ELEMENT_HEX8, 0, 2, n2, &e)) return;
  fcm_mesh *m = build(ctx, FCM_ELEMENT_HEX8, &e);
  TEST_OK(ctx, fcm_mesh_validate(ctx, m, 0, NULL, &min_det));
  TEST_NEAR(min_det, 0.125, 1e-14, 0);
  fcm_mesh_destroy(&m);
  for (int a = 0; a < 4; a++) {
    fcm_index t = e.cells[8 * 5 + a];
    e.cells[8 * 5 + a] = e.cells[8 * 5 + a + 4];
    e.cells[8 * 5 + a + 4] = t;
  }
  m = build(ctx, FCM_ELEMENT_HEX8, &e);
  TEST_ERR(ctx, fcm_mesh_validate(ctx, m, 0, NULL, &min_det), FCM_ERR_GEOMETRY,
           "hex8 cell 5 has det J = -0.125 (must be > 0) at corner 0");
  TEST_NEAR(min_det, -0.125, 1e-14, 0);
  unsigned char flags[8];
  fcm_index bad = 0;
  TEST_OK(ctx, fcm_mesh_convex_cells(ctx, m, 1e-10, flags, &bad));
  TEST_TRUE(bad == 1 && flags[5] == 0 && flags[4] == 1);
  fcm_mesh_destroy(&m);
  free_editable(&e);

  /* Tet4: Kuhn tets of a unit cube have det J = +-1; swap two nodes of cell 3. */
  if (make_editable(ctx, FCM_ELEMENT_TET4, 0, 1, n1, &e)) return;
  fcm_index t = e.cells[4 * 3 + 1];
  e.cells[4 * 3 + 1] = e.cells[4 * 3 + 2];
  e.cells[4 * 3 + 2] = t;
  m = build(ctx, FCM_ELEMENT_TET4, &e);
  TEST_ERR(ctx, fcm_mesh_validate(ctx, m, 0, NULL, &min_det), FCM_ERR_GEOMETRY,
           "tet4 cell 3 has det J = -1 (must be > 0)");
  TEST_NEAR(min_det, -1.0, 1e-14, 0);
  TEST_TRUE(fcm_mesh_cell_is_convex(m, 3, 1e-10) == 0);
  TEST_TRUE(fcm_mesh_cell_is_convex(m, 2, 1e-10) == 1);
  fcm_mesh_destroy(&m);
  free_editable(&e);
}

/* Hex20 on [-1, 1]^3 (identity map) with mid-edge node 8 (edge 0-1) moved by d = (0, D, D):
 * J = I + d (grad N_8)^T, so det J = 1 + grad N_8 . d. At the corners grad N_8 has no y or
 * z part (det J = 1); at the edge midpoint (0, -1, -1) it is (0, -1/2, -1/2): det J = 1 - D. */
static void test_interior_point(fcm_ctx *ctx)
{
  const fcm_index n1[3] = {1, 1, 1};
  const double D = 1.5;
  editable e;
  if (make_editable(ctx, FCM_ELEMENT_HEX20, -1, 1, n1, &e)) return;
  const fcm_index node8 = e.cells[8];
  e.x[3 * node8 + 1] += D;
  e.x[3 * node8 + 2] += D;
  fcm_mesh *m = build(ctx, FCM_ELEMENT_HEX20, &e);
  double min_det = 0;
  TEST_OK(ctx, fcm_mesh_validate(ctx, m, 0, NULL, &min_det));
  TEST_NEAR(min_det, 1.0, 1e-14, 0);
  const double pts[6] = {0.5, 0.5, 0.5, 0.0, -1.0, -1.0};
  TEST_ERR(ctx, fcm_mesh_validate(ctx, m, 2, pts, &min_det), FCM_ERR_GEOMETRY,
           "hex20 cell 0 has det J = -0.5 (must be > 0) at point 1, reference point (0, -1, -1)");
  TEST_NEAR(min_det, 1.0 - D, 1e-14, 0);
  TEST_TRUE(fcm_mesh_cell_is_convex(m, 0, 1e-10) == 0); /* a curved edge */

  /* Argument errors. */
  const double bad[3] = {0, NAN, 0};
  TEST_ERR(ctx, fcm_mesh_validate(ctx, m, -1, pts, NULL), FCM_ERR_ARG, "num_points = -1");
  TEST_ERR(ctx, fcm_mesh_validate(ctx, m, 1, NULL, NULL), FCM_ERR_ARG, "num_points = 1");
  TEST_ERR(ctx, fcm_mesh_validate(ctx, m, 1, bad, NULL), FCM_ERR_ARG,
           "coordinate 1 of reference point 0 is nan");
  TEST_ERR(ctx, fcm_mesh_validate(ctx, NULL, 0, NULL, NULL), FCM_ERR_ARG, "mesh must not be NULL");
  TEST_ERR(ctx, fcm_mesh_convex_cells(ctx, m, -1.0, NULL, NULL), FCM_ERR_ARG,
           "rtol = -1 must be finite and >= 0");
  fcm_mesh_destroy(&m);
  free_editable(&e);
}

static int convex_after(fcm_ctx *ctx, fcm_element_type t, const editable *e0, fcm_index node,
                        const double dx[3])
{
  editable e = *e0;
  e.x = malloc(sizeof *e.x * 3 * (size_t)e.nn);
  memcpy(e.x, e0->x, sizeof *e.x * 3 * (size_t)e.nn);
  for (int d = 0; d < 3; d++)
    e.x[3 * node + d] += dx[d];
  fcm_mesh *m = build(ctx, t, &e);
  int c = m ? fcm_mesh_cell_is_convex(m, 0, 1e-10) : -1;
  fcm_mesh_destroy(&m);
  free(e.x);
  return c;
}

static void test_convexity(fcm_ctx *ctx)
{
  const fcm_index n1[3] = {1, 1, 1}, n3[3] = {3, 1, 1};
  const double zero[3] = {0, 0, 0};
  editable e;

  /* Hex8 unit cube; corner 6 lifted out of the top face's plane. */
  if (make_editable(ctx, FCM_ELEMENT_HEX8, 0, 1, n1, &e)) return;
  const double up[3] = {0, 0, 0.01};
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_HEX8, &e, e.cells[6], zero) == 1);
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_HEX8, &e, e.cells[6], up) == 0);
  /* Shearing the top face (corners 4..7) keeps every face planar: a parallelepiped. */
  for (int a = 4; a < 8; a++)
    e.x[3 * e.cells[a]] += 0.3;
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_HEX8, &e, e.cells[6], zero) == 1);
  free_editable(&e);

  /* Hex20: straight edges with midpoints (convex), a mid-edge node off the edge (not), one
   * moved along the edge inside the middle half (convex) or beyond it (not). */
  if (make_editable(ctx, FCM_ELEMENT_HEX20, 0, 1, n1, &e)) return;
  const double off[3] = {0, 0.01, 0}, along_in[3] = {0.1, 0, 0}, along_out[3] = {0.3, 0, 0};
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_HEX20, &e, e.cells[8], zero) == 1);
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_HEX20, &e, e.cells[8], off) == 0);
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_HEX20, &e, e.cells[8], along_in) == 1);
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_HEX20, &e, e.cells[8], along_out) == 0);
  free_editable(&e);

  /* Tet4 is convex whatever its corners; Tet10 needs straight edges. */
  if (make_editable(ctx, FCM_ELEMENT_TET4, 0, 1, n1, &e)) return;
  const double odd[3] = {0.3, -0.2, 0.1};
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_TET4, &e, e.cells[0], odd) == 1);
  free_editable(&e);
  if (make_editable(ctx, FCM_ELEMENT_TET10, 0, 1, n1, &e)) return;
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_TET10, &e, e.cells[5], zero) == 1);
  TEST_TRUE(convex_after(ctx, FCM_ELEMENT_TET10, &e, e.cells[5], odd) == 0);
  free_editable(&e);

  /* Flags per cell: in a row of three cubes, warp the corner (3, 1, 1) of the last one. */
  if (make_editable(ctx, FCM_ELEMENT_HEX8, 0, 1, n3, &e)) return;
  for (fcm_index a = 0; a < e.nn; a++)
    e.x[3 * a] *= 3; /* box [0,3] x [0,1]^2 */
  e.x[3 * e.cells[8 * 2 + 6] + 2] += 0.2;
  fcm_mesh *m = build(ctx, FCM_ELEMENT_HEX8, &e);
  unsigned char flags[3] = {7, 7, 7};
  fcm_index bad = -1;
  TEST_OK(ctx, fcm_mesh_convex_cells(ctx, m, 1e-10, flags, &bad));
  TEST_TRUE(flags[0] == 1 && flags[1] == 1 && flags[2] == 0 && bad == 1);
  fcm_mesh_destroy(&m);
  free_editable(&e);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  test_inverted(ctx);
  test_interior_point(ctx);
  test_convexity(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
