/* Allocation-failure torture for fcm_mesh_create_box: failing the k-th allocation
 * (k = 0, 1, ... until success) returns FCM_ERR_ALLOC, leaves *mesh NULL and leaks
 * nothing, for every element type. */
#include "mesh_util.h"

int main(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return TEST_RESULT();
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
  const fcm_index n[3] = {2, 2, 3};
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++) {
    int ok = 0, failures = 0;
    for (long k = 0; k < 100 && !ok; k++) {
      fcm_mesh *m = (fcm_mesh *)&f; /* must be reset to NULL on failure */
      f.count = 0;
      f.fail_at = k;
      fcm_status st = fcm_mesh_create_box(ctx, (fcm_element_type)t, lo, hi, n, &m);
      f.fail_at = -1;
      if (st == FCM_OK) {
        ok = 1;
        TEST_TRUE(m && fcm_mesh_num_cells(m) == (t <= FCM_ELEMENT_TET10 ? 72 : 12));
        fcm_mesh_destroy(&m);
      } else {
        failures++;
        TEST_TRUE(st == FCM_ERR_ALLOC && m == NULL);
        TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_ERR_ALLOC);
      }
      TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
      fcm_ctx_error_clear(ctx);
    }
    TEST_TRUE(ok);
    /* Every allocation up to success was a distinct failure point. */
    TEST_TRUE(failures >= 4);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
