/* libFuzzer target: the Gmsh MSH reader, as a background mesh (fcm_mesh_create_from_gmsh)
 * and as an embedded geometry (fcm_geometry_create_from_gmsh). The input is the file. */
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  fcm_ctx *ctx = fuzz_ctx();
  long long live = fcm_ctx_live_allocations(ctx);
  const char *path = fuzz_write_file(0, "in.msh", data, size);
  fcm_mesh *mesh = NULL;
  fcm_status st = fcm_mesh_create_from_gmsh(ctx, path, &mesh);
  fuzz_check_status(ctx, st);
  if (st == FCM_OK) {
    /* touch what the reader produced: every cell's nodes are in range */
    const fcm_index nn = fcm_mesh_num_nodes(mesh), *cells = fcm_mesh_cells(mesh);
    const fcm_index n = fcm_mesh_num_cells(mesh) * fcm_mesh_nodes_per_cell(mesh);
    for (fcm_index k = 0; k < n; k++)
      if (cells[k] < 0 || cells[k] >= nn) abort();
  }
  fcm_mesh_destroy(&mesh);
  fcm_ctx_error_clear(ctx);
  fcm_geometry *geom = NULL;
  st = fcm_geometry_create_from_gmsh(ctx, path, &geom);
  fuzz_check_status(ctx, st);
  if (st == FCM_OK) (void)fcm_geometry_volume(geom);
  fcm_geometry_destroy(&geom);
  fuzz_check_no_live(ctx, live);
  return 0;
}
