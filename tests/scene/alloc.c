/* Allocation-failure torture: parsing the scene that sets every key (and the default
 * scene) with the k-th allocation failing, k = 0, 1, ... until success, returns
 * FCM_ERR_ALLOC, a NULL scene and no leak (the JSON tree, allocated by cJSON with malloc,
 * is checked by LeakSanitizer in the sanitizer build). */
#include "scene_util.h"

static void torture(fcm_ctx *ctx, failing *f, const char *json, int min_failures)
{
  int ok = 0, failures = 0;
  for (long k = 0; k < 1000 && !ok; k++) {
    fcm_scene *s = (fcm_scene *)f; /* must be reset to NULL on failure */
    f->count = 0;
    f->fail_at = k;
    fcm_status st = fcm_scene_create_from_string(ctx, json, "alloc.json", &s);
    f->fail_at = -1;
    if (st == FCM_OK) {
      ok = 1;
      TEST_TRUE(s != NULL && fcm_scene_num_effects(s) > 0);
      fcm_scene_destroy(&s);
    } else {
      failures++;
      TEST_TRUE(st == FCM_ERR_ALLOC && s == NULL);
      TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_ERR_ALLOC);
    }
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    fcm_ctx_error_clear(ctx);
  }
  TEST_TRUE(ok);
  TEST_TRUE(failures >= min_failures);
}

int main(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return TEST_RESULT();
  /* The full scene owns the scene struct, source, directory, name, description, output
   * directory, effect array and node list: at least 8 allocations. */
  torture(ctx, &f, full_scene_json, 8);
  torture(ctx, &f, fcm_scene_default_json(), 5);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
