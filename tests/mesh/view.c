/* fcm_mesh_view() prints the element type, the node, cell and boundary-face counts and the
 * bounding box of the mesh (checked on box grids of each element type). */
#include "fcm/fcm.h"
#include "test.h"

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-1, 0, 2}, hi[3] = {1, 0.5, 3};
  const fcm_index n[3] = {2, 1, 3};
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++) {
    fcm_mesh *m = NULL;
    TEST_OK(ctx, fcm_mesh_create_box(ctx, (fcm_element_type)t, lo, hi, n, &m));
    if (!m) continue;
    FILE *f = tmpfile();
    TEST_TRUE(f != NULL);
    if (f) {
      char text[1024] = "", want[256];
      fcm_mesh_view(m, f);
      rewind(f);
      size_t got = fread(text, 1, sizeof text - 1, f);
      text[got] = '\0';
      fclose(f);
      snprintf(want, sizeof want, "mesh: %s, %lld nodes, %lld cells, %lld boundary faces",
               fcm_mesh_get_element_info(m)->name, (long long)fcm_mesh_num_nodes(m),
               (long long)fcm_mesh_num_cells(m), (long long)fcm_mesh_num_boundary_faces(m));
      TEST_TRUE(strstr(text, want) != NULL);
      TEST_TRUE(strstr(text, "bounding box [-1, 1] x [0, 0.5] x [2, 3]") != NULL);
    }
    fcm_mesh_destroy(&m);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
