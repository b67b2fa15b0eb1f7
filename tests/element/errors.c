/* Error paths of the element module: unknown names and types, degenerate cells
 * and bad arguments of the inverse map, each with its status and message. */
#include "fcm/element.h"
#include "test.h"

/* Reference nodes of `type` scaled by (sx, sy, sz), nodes jittered by `jitter`
 * in x and y (deterministically); z is multiplied by sz (0 flattens the cell). */
static void make_cell(fcm_element_type type, double sz, double jitter, double *X)
{
  const fcm_element_info *info = fcm_element_get_info(type);
  const double *ref = fcm_element_ref_nodes(type);
  for (int a = 0; a < info->num_nodes; a++) {
    X[3 * a + 0] = ref[3 * a + 0] + jitter * sin(1.7 * a + 0.3);
    X[3 * a + 1] = ref[3 * a + 1] + jitter * cos(2.3 * a + 0.1);
    X[3 * a + 2] = sz * ref[3 * a + 2];
  }
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  double X[3 * FCM_ELEMENT_MAX_NODES], xi[3];
  const double x[3] = {0.1, 0.2, 0.0};

  /* names and types */
  fcm_element_type t = FCM_ELEMENT_HEX8;
  TEST_TRUE(fcm_element_type_from_name("hex27", &t) == FCM_ERR_ARG);
  TEST_TRUE(fcm_element_type_from_name("", &t) == FCM_ERR_ARG);
  TEST_TRUE(fcm_element_type_from_name("tet", &t) == FCM_ERR_ARG);
  TEST_TRUE(fcm_element_type_from_name("tet100", &t) == FCM_ERR_ARG);
  TEST_TRUE(fcm_element_type_from_name(NULL, &t) == FCM_ERR_ARG);
  TEST_TRUE(t == FCM_ELEMENT_HEX8); /* unchanged */
  TEST_TRUE(fcm_element_type_from_name("Tet10", &t) == FCM_OK && t == FCM_ELEMENT_TET10);
  TEST_TRUE(fcm_element_type_from_name("hex8", NULL) == FCM_ERR_ARG);
  TEST_TRUE(fcm_element_get_info(FCM_ELEMENT_COUNT) == NULL);
  TEST_TRUE(fcm_element_get_info((fcm_element_type)-1) == NULL);
  TEST_TRUE(fcm_element_get_info((fcm_element_type)1000) == NULL);
  TEST_TRUE(fcm_element_ref_nodes(FCM_ELEMENT_COUNT) == NULL);
  TEST_TRUE(fcm_element_is_affine(FCM_ELEMENT_COUNT, X, 1e-12) == 0);

  /* shapes: dimensions and measures of the reference domains */
  TEST_TRUE(strcmp(fcm_shape_name(FCM_SHAPE_COUNT), "unknown") == 0);
  TEST_TRUE(strcmp(fcm_shape_name(FCM_SHAPE_HEX), "hex") == 0);
  TEST_TRUE(fcm_shape_dim(FCM_SHAPE_COUNT) == 0 && fcm_shape_measure(FCM_SHAPE_COUNT) == 0.0);
  TEST_TRUE(fcm_shape_dim(FCM_SHAPE_LINE) == 1 && fcm_shape_dim(FCM_SHAPE_QUAD) == 2);
  TEST_NEAR(fcm_shape_measure(FCM_SHAPE_TET), 1.0 / 6.0, 1e-15, 0.0);
  TEST_NEAR(fcm_shape_measure(FCM_SHAPE_TRI), 0.5, 1e-15, 0.0);
  TEST_NEAR(fcm_shape_measure(FCM_SHAPE_HEX), 8.0, 1e-15, 0.0);

  /* inverse map: invalid type and arguments */
  make_cell(FCM_ELEMENT_HEX8, 1.0, 0.0, X);
  TEST_ERR(ctx, fcm_element_inverse_map(ctx, FCM_ELEMENT_COUNT, X, x, xi), FCM_ERR_ARG,
           "out of range");
  TEST_ERR(ctx, fcm_element_inverse_map(ctx, FCM_ELEMENT_HEX8, NULL, x, xi), FCM_ERR_ARG, "NULL");
  const double bad[3] = {0.0, NAN, 0.0};
  TEST_ERR(ctx, fcm_element_inverse_map(ctx, FCM_ELEMENT_HEX8, X, bad, xi), FCM_ERR_ARG,
           "not finite");
  X[5] = INFINITY;
  TEST_ERR(ctx, fcm_element_inverse_map(ctx, FCM_ELEMENT_HEX8, X, x, xi), FCM_ERR_GEOMETRY,
           "cell size");

  /* flat parallelepiped (affine, closed-form path): singular */
  make_cell(FCM_ELEMENT_HEX8, 0.0, 0.0, X);
  TEST_TRUE(fcm_element_is_affine(FCM_ELEMENT_HEX8, X, 1e-12));
  TEST_ERR(ctx, fcm_element_inverse_map(ctx, FCM_ELEMENT_HEX8, X, x, xi), FCM_ERR_GEOMETRY,
           "hex8 inverse map: degenerate affine cell");
  /* flat, non-affine hexahedra (Newton path): singular Jacobian */
  const fcm_element_type flat[2] = {FCM_ELEMENT_HEX8, FCM_ELEMENT_HEX20};
  for (int k = 0; k < 2; k++) {
    make_cell(flat[k], 0.0, 0.1, X);
    TEST_TRUE(!fcm_element_is_affine(flat[k], X, 1e-6));
    fcm_status st = fcm_element_inverse_map(ctx, flat[k], X, x, xi);
    TEST_TRUE(st == FCM_ERR_GEOMETRY || st == FCM_ERR_NOT_CONVERGED);
    TEST_TRUE(strstr(fcm_ctx_error_message(ctx), fcm_element_get_info(flat[k])->name) != NULL);
    TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "x = (0.1, 0.2, 0)") != NULL);
    fcm_ctx_error_clear(ctx);
  }
  /* inverted hexahedron (corner 6 pulled through the cell) and a point outside
   * the image of its map: Newton's line search stalls at a local minimum of |r| */
  make_cell(FCM_ELEMENT_HEX8, 1.0, 0.0, X);
  X[18] = X[19] = X[20] = -0.9;
  const double far[3] = {10.0, 2.0, 1.0};
  TEST_ERR(ctx, fcm_element_inverse_map(ctx, FCM_ELEMENT_HEX8, X, far, xi), FCM_ERR_NOT_CONVERGED,
           "hex8 inverse map: no convergence for x = (10, 2, 1)");
  /* all nodes coincide: zero cell size */
  for (int a = 0; a < 10; a++)
    X[3 * a] = X[3 * a + 1] = X[3 * a + 2] = 1.0;
  TEST_ERR(ctx, fcm_element_inverse_map(ctx, FCM_ELEMENT_TET10, X, x, xi), FCM_ERR_GEOMETRY,
           "tet10 inverse map: cell size 0");
  /* a flat tet (all nodes in a plane) */
  make_cell(FCM_ELEMENT_TET4, 0.0, 0.0, X);
  TEST_ERR(ctx, fcm_element_inverse_map(ctx, FCM_ELEMENT_TET4, X, x, xi), FCM_ERR_GEOMETRY,
           "tet4 inverse map: degenerate");
  /* a NULL context is allowed */
  TEST_TRUE(fcm_element_inverse_map(NULL, FCM_ELEMENT_TET4, X, x, xi) == FCM_ERR_GEOMETRY);

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
