/* Seed writer for the checkpoint fuzz target: fcm-fuzz-seed-checkpoint OUT_DIR writes
 * checkpoints of the scene in fuzz_ckpt_scene.h after 0, 1, 2 and 4 steps (with frames)
 * as OUT_DIR/ckpt_<steps>_{raw,fix}: the target's mode byte (0 or 1) then the file. */
#include "fuzz_util.h"

#include "fuzz_ckpt_scene.h"

#include <dirent.h>
#include <sys/stat.h>

static int emit(const char *dir, int steps, const char *tmp_ckpt)
{
  FILE *in = fopen(tmp_ckpt, "rb");
  if (!in) return 1;
  static uint8_t buf[1 << 20];
  size_t n = fread(buf, 1, sizeof buf, in);
  fclose(in);
  for (int mode = 0; mode < 2; mode++) {
    char path[4096];
    snprintf(path, sizeof path, "%s/ckpt_%d_%s", dir, steps, mode ? "fix" : "raw");
    FILE *out = fopen(path, "wb");
    if (!out) return 1;
    const uint8_t m = (uint8_t)mode;
    int bad = fwrite(&m, 1, 1, out) != 1 || fwrite(buf, 1, n, out) != n;
    if (fclose(out) != 0 || bad) return 1;
  }
  return 0;
}

int main(int argc, char **argv)
{
  if (argc != 2) {
    fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  fcm_ctx *ctx = fuzz_ctx();
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  int rc = 1;
  char tmp[sizeof fuzz_dir_ + 16], frames[sizeof fuzz_dir_ + 16];
  const char *ckpt = fuzz_write_file(0, "in.ckpt", NULL, 0);
  snprintf(tmp, sizeof tmp, "%s", ckpt);
  snprintf(frames, sizeof frames, "%s/frames", fuzz_dir_);
  if (mkdir(frames, 0700) != 0) goto done;
  if (fcm_scene_create_from_string(ctx, fuzz_ckpt_scene_json, "<fuzz>", &scene) != FCM_OK ||
      fcm_simulation_create(ctx, scene, NULL, &sim) != FCM_OK)
    goto done;
  for (int steps = 0; steps <= 4; steps++) {
    if (steps > 0 && fcm_simulation_step(sim, NULL) != FCM_OK) goto done;
    if (steps % 2 == 0 && fcm_simulation_write_frame(sim, frames, steps / 2) != FCM_OK) goto done;
    if (steps == 3) continue;
    if (fcm_simulation_write_checkpoint(sim, tmp) != FCM_OK || emit(argv[1], steps, tmp)) goto done;
  }
  rc = 0;
done:
  if (rc) fcm_ctx_error_view(ctx, stderr);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  DIR *d = opendir(frames); /* the frame files */
  if (d) {
    struct dirent *e;
    char path[sizeof frames + 300];
    while ((e = readdir(d)) != NULL) {
      if (e->d_name[0] == '.') continue;
      snprintf(path, sizeof path, "%s/%s", frames, e->d_name);
      unlink(path);
    }
    closedir(d);
  }
  rmdir(frames);
  return rc;
}
