/* Geometry error paths: bad arguments of every constructor fail with FCM_ERR_ARG and a
 * message naming the value, leave *geom NULL and leak nothing; a non-convex or inverted
 * hex is FCM_ERR_GEOMETRY naming the cell; a singular transform is rejected. Also the
 * allocation-failure loop (fail the k-th allocation until success) over every
 * constructor: FCM_ERR_ALLOC, *geom NULL, no leak. */
#include "fcm/geom.h"
#include "test.h"
#include "test_alloc.h"

static void arguments(fcm_ctx *ctx)
{
  fcm_geometry *g = (fcm_geometry *)ctx;
  const double c0[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, bad_hi[3] = {1, 0, 1};
  const fcm_index n[3] = {1, 1, 1}, n0[3] = {1, 0, 1};
  const double X[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const fcm_index cells[4] = {0, 1, 2, 3}, bad_cells[4] = {0, 1, 2, 4};
  TEST_ERR(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET10, 4, X, 1, cells, &g), FCM_ERR_ARG,
           "cell type");
  TEST_TRUE(g == NULL);
  TEST_ERR(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, X, 1, bad_cells, &g), FCM_ERR_ARG,
           "node 3 of cell 0 is 4, outside [0,4)");
  TEST_ERR(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, -1, X, 1, cells, &g), FCM_ERR_ARG,
           "num_nodes = -1");
  TEST_ERR(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, NULL, 1, cells, &g), FCM_ERR_ARG,
           "NULL");
  const double Xn[12] = {0, 0, 0, 1, 0, 0, 0, NAN, 0, 0, 0, 1};
  TEST_ERR(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, Xn, 1, cells, &g), FCM_ERR_ARG,
           "coordinate 1 of node 2");
  /* Inverted hex (top and bottom swapped). */
  const double H[24] = {0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const fcm_index hc[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  TEST_ERR(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_HEX8, 8, H, 1, hc, &g), FCM_ERR_GEOMETRY,
           "hex cell 0 is not convex");
  TEST_ERR(ctx, fcm_geometry_create_box(ctx, lo, bad_hi, n, &g), FCM_ERR_ARG,
           "axis 1 has lo = 0, hi = 0");
  TEST_ERR(ctx, fcm_geometry_create_box(ctx, lo, hi, n0, &g), FCM_ERR_ARG,
           "cells along axis 1 = 0");
  TEST_ERR(ctx, fcm_geometry_create_ball(ctx, c0, -1.0, 2, &g), FCM_ERR_ARG, "radius = -1");
  TEST_ERR(ctx, fcm_geometry_create_ball(ctx, c0, 1.0, 0, &g), FCM_ERR_ARG, "n = 0");
  TEST_ERR(ctx, fcm_geometry_create_hemisphere(ctx, NULL, 1.0, 2, &g), FCM_ERR_ARG, "NULL");
  TEST_ERR(ctx, fcm_geometry_create_hollow_ball(ctx, c0, 1.0, 0.5, 0.0, 2, 1, &g), FCM_ERR_ARG,
           "r_in = 1, r_out = 0.5");
  TEST_ERR(ctx, fcm_geometry_create_hollow_ball(ctx, c0, 0.5, 1.0, 1.0, 2, 1, &g), FCM_ERR_ARG,
           "hole radius = 1");
  TEST_ERR(ctx, fcm_geometry_create_hollow_ball(ctx, c0, 0.5, 1.0, 0.1, 2, 0, &g), FCM_ERR_ARG,
           "layers = 0");
  TEST_ERR(ctx, fcm_geometry_create_tube(ctx, c0, 3, 0.5, 1.0, 1.0, 1, 8, 1, &g), FCM_ERR_ARG,
           "axis = 3");
  TEST_ERR(ctx, fcm_geometry_create_tube(ctx, c0, 2, 0.5, 1.0, 1.0, 1, 4, 1, &g), FCM_ERR_ARG,
           "n_theta = 4");
  TEST_ERR(ctx, fcm_geometry_create_tube(ctx, c0, 2, 0.0, 1.0, 1.0, 1, 8, 1, &g), FCM_ERR_ARG,
           "r_in = 0");
  TEST_ERR(ctx, fcm_geometry_create_tube(ctx, c0, 2, 0.5, 1.0, -1.0, 1, 8, 1, &g), FCM_ERR_ARG,
           "length = -1");
  TEST_TRUE(g == NULL);
  fcm_geometry *box = NULL;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n, &box));
  const double A0[9] = {1, 0, 0, 0, 1, 0, 1, 0, 0}, b[3] = {0, 0, 0};
  TEST_ERR(ctx, fcm_geometry_create_transformed(ctx, box, A0, b, &g), FCM_ERR_ARG, "det A = 0");
  TEST_TRUE(g == NULL);
  fcm_geometry_destroy(&box);
  fcm_geometry_destroy(&box);
  fcm_geometry_destroy(NULL);
}

/* Run `call` with the k-th allocation failing, k = 0, 1, ... until it succeeds. */
#define ALLOC_LOOP(f, ctx, call)                                                                   \
  do {                                                                                             \
    int ok_ = 0, fails_ = 0;                                                                       \
    const long long live_ = fcm_ctx_live_allocations(ctx);                                         \
    for (long k_ = 0; k_ < 1000 && !ok_; k_++) {                                                   \
      fcm_geometry *g = (fcm_geometry *)(f);                                                       \
      (f)->count = 0, (f)->fail_at = k_;                                                           \
      fcm_status st_ = (call);                                                                     \
      (f)->fail_at = -1;                                                                           \
      if (st_ == FCM_OK) {                                                                         \
        ok_ = 1;                                                                                   \
        TEST_TRUE(g != NULL);                                                                      \
        fcm_geometry_destroy(&g);                                                                  \
      } else {                                                                                     \
        fails_++;                                                                                  \
        TEST_TRUE(st_ == FCM_ERR_ALLOC && g == NULL);                                              \
      }                                                                                            \
      TEST_TRUE(fcm_ctx_live_allocations(ctx) == live_);                                           \
      fcm_ctx_error_clear(ctx);                                                                    \
    }                                                                                              \
    TEST_TRUE(ok_ &&fails_ >= 3);                                                                  \
  } while (0)

static void allocation_failures(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return;
  const double c0[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {2, 1, 1};
  ALLOC_LOOP(&f, ctx, fcm_geometry_create_box(ctx, lo, hi, n, &g));
  ALLOC_LOOP(&f, ctx, fcm_geometry_create_ball(ctx, c0, 1.0, 1, &g));
  ALLOC_LOOP(&f, ctx, fcm_geometry_create_hemisphere(ctx, c0, 1.0, 1, &g));
  ALLOC_LOOP(&f, ctx, fcm_geometry_create_hollow_ball(ctx, c0, 0.5, 1.0, 0.2, 2, 1, &g));
  ALLOC_LOOP(&f, ctx, fcm_geometry_create_tube(ctx, c0, 1, 0.5, 1.0, 1.0, 1, 6, 1, &g));
  FILE *fp = fopen("geom_err_a.node", "w");
  if (fp) fputs("4 3\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n", fp), fclose(fp);
  fp = fopen("geom_err_a.ele", "w");
  if (fp) fputs("1 4\n0 0 1 2 3\n", fp), fclose(fp);
  ALLOC_LOOP(&f, ctx,
             fcm_geometry_create_from_tetgen(ctx, "geom_err_a.node", "geom_err_a.ele", &g));
  fcm_geometry *box = NULL;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n, &box));
  const double A[9] = {2, 0, 0, 0, 1, 0, 0, 0, 1}, b[3] = {1, 1, 1};
  ALLOC_LOOP(&f, ctx, fcm_geometry_create_transformed(ctx, box, A, b, &g));
  fcm_geometry_destroy(&box);
  fcm_ctx_destroy(&ctx);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  arguments(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  allocation_failures();
  return TEST_RESULT();
}
