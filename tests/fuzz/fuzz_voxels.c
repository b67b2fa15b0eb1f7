/* libFuzzer target: the voxel image readers (fcm_voxel_image_create_from_file). The first
 * byte of the input picks the format (its value mod 2: nrrd, mhd; both with attached data,
 * the MetaImage through ElementDataFile = LOCAL), the rest is the file. A successful read is
 * checked for sizes >= 1; small images are turned into boxes, whose volume must be the
 * selected voxels times the voxel volume. */
#include "fuzz_util.h"
#include "fcm/voxels.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  static const char *const names[2] = {"in.nrrd", "in.mha"};
  if (size == 0) return 0;
  fcm_ctx *ctx = fuzz_ctx();
  long long live = fcm_ctx_live_allocations(ctx);
  const char *path = fuzz_write_file(0, names[data[0] % 2], data + 1, size - 1);
  fcm_voxel_image *img = NULL;
  fcm_geometry *g = NULL;
  fcm_status st = fcm_voxel_image_create_from_file(ctx, path, &img);
  fuzz_check_status(ctx, st);
  if (st == FCM_OK) {
    fcm_index d[3];
    fcm_voxel_image_dims(img, d);
    if (d[0] < 1 || d[1] < 1 || d[2] < 1) abort();
    if (d[0] * d[1] * d[2] <= 4096) {
      fcm_voxel_info info;
      st = fcm_geometry_create_from_voxels(ctx, img, NULL, &g, &info);
      fuzz_check_status(ctx, st);
      if (st == FCM_OK) {
        const double v = (double)info.num_selected * info.voxel_volume;
        if (!(fabs(fcm_geometry_volume(g) - v) <= 1e-9 * v)) abort();
      } else if (st != FCM_ERR_GEOMETRY) {
        abort();
      }
    }
  }
  fcm_geometry_destroy(&g);
  fcm_voxel_image_destroy(&img);
  fuzz_check_no_live(ctx, live);
  return 0;
}
