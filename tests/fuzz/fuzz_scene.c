/* libFuzzer target: the scene JSON parser and schema (fcm_scene_create_from_string), and on
 * success the normalized summary (fcm_scene_view) and the accessors. The input is the
 * text; file names in it are resolved against the working directory (the parser only
 * checks that they name regular files). Use with -dict=scene.dict. */
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  fcm_ctx *ctx = fuzz_ctx();
  long long live = fcm_ctx_live_allocations(ctx);
  char *text = malloc(size + 1);
  if (!text) return 0;
  memcpy(text, data, size);
  text[size] = '\0';
  fcm_scene *scene = NULL;
  fcm_status st = fcm_scene_create_from_string(ctx, text, "<fuzz>", &scene);
  fuzz_check_status(ctx, st);
  if (st == FCM_OK) {
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (f) {
      fcm_scene_view(scene, f);
      fclose(f);
    }
    free(buf);
    (void)fcm_scene_num_effects(scene);
    (void)fcm_scene_get_time(scene)->dt;
  }
  fcm_scene_destroy(&scene);
  free(text);
  fuzz_check_no_live(ctx, live);
  return 0;
}
