/* libFuzzer target: restoring a checkpoint (fcm_simulation_read_checkpoint) into a new
 * simulation of the scene in fuzz_ckpt_scene.h. Input: one mode byte, then the file. With
 * bit 0 of the mode set the target first writes this scene's fingerprint at bytes 24..31
 * and recomputes the trailing FNV-1a checksum, so that mutations reach the fields behind
 * the checksum; with it clear the bytes are restored as they are. After an accepted
 * checkpoint the simulation is replaced (a simulation restores only once). */
#include "fuzz_util.h"

#include "fuzz_ckpt_scene.h"

static fcm_scene *scene_;
static fcm_simulation *sim_;
static uint8_t fingerprint_[8];

static uint64_t fnv1a(const uint8_t *p, size_t n)
{
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t k = 0; k < n; k++) {
    h ^= p[k];
    h *= 0x100000001b3ull;
  }
  return h;
}

static void setup(fcm_ctx *ctx)
{
  if (fcm_scene_create_from_string(ctx, fuzz_ckpt_scene_json, "<fuzz>", &scene_) != FCM_OK ||
      fcm_simulation_create(ctx, scene_, NULL, &sim_) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    abort();
  }
  /* this scene's fingerprint: from a checkpoint of the fresh simulation */
  const char *path = fuzz_write_file(0, "in.ckpt", NULL, 0);
  uint8_t head[32];
  FILE *f = NULL;
  if (fcm_simulation_write_checkpoint(sim_, path) != FCM_OK || !(f = fopen(path, "rb")) ||
      fread(head, 1, sizeof head, f) != sizeof head) {
    fcm_ctx_error_view(ctx, stderr);
    abort();
  }
  fclose(f);
  memcpy(fingerprint_, head + 24, 8);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  fcm_ctx *ctx = fuzz_ctx();
  if (!sim_) setup(ctx);
  long long live = fcm_ctx_live_allocations(ctx);
  if (size < 1) return 0;
  const int fix = data[0] & 1;
  data++, size--;
  uint8_t *buf = malloc(size ? size : 1);
  if (!buf) return 0;
  if (size) memcpy(buf, data, size);
  if (fix && size >= 40) {
    memcpy(buf + 24, fingerprint_, 8);
    uint64_t sum = fnv1a(buf, size - 8);
    memcpy(buf + size - 8, &sum, 8);
  }
  const char *path = fuzz_write_file(0, "in.ckpt", buf, size);
  free(buf);
  fcm_status st = fcm_simulation_read_checkpoint(sim_, path);
  fuzz_check_status(ctx, st);
  fcm_ctx_error_clear(ctx);
  if (st == FCM_OK) {
    /* a restored state is finite (the reader promises it) */
    if (!fcm_simulation_state_finite(sim_)) abort();
    fcm_simulation_destroy(&sim_);
    live = fcm_ctx_live_allocations(ctx);
    if (fcm_simulation_create(ctx, scene_, NULL, &sim_) != FCM_OK) abort();
    return 0;
  }
  fuzz_check_no_live(ctx, live);
  return 0;
}
