/* The geometry accessors no program used before: fcm_geometry_nodes_per_cell() equals the
 * cell type's node count; fcm_geometry_boundary_cells() names, for every boundary triangle,
 * a cell that holds all three of its nodes, and on a box of n^3 cubes (6 tets each) every
 * cell of the surface layer owns at least one triangle and no interior cell owns any;
 * fcm_geometry_view() prints the type, the counts and the volume. */
#include "fcm/fcm.h"
#include "test.h"

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {3, 3, 3};
  const fcm_index n[3] = {3, 3, 3};
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n, &g));
  if (!g) return TEST_RESULT();

  const fcm_element_info *info = fcm_element_get_info(fcm_geometry_cell_type(g));
  const int npc = fcm_geometry_nodes_per_cell(g);
  TEST_TRUE(info && npc == info->num_nodes);
  const fcm_index nc = fcm_geometry_num_cells(g), nt = fcm_geometry_num_boundary_triangles(g);
  const fcm_index *cells = fcm_geometry_cells(g), *tri = fcm_geometry_boundary_triangles(g);
  const fcm_index *owner = fcm_geometry_boundary_cells(g);
  const double *X = fcm_geometry_coords(g);
  TEST_TRUE(nc == 6 * 27 && nt == 6 * 9 * 2); /* 9 squares per side, 2 triangles each */
  TEST_NEAR(fcm_geometry_volume(g), 27.0, 1e-14, 0);
  unsigned char *owns = calloc((size_t)nc, 1);
  for (fcm_index t = 0; t < nt; t++) {
    fcm_index c = owner[t];
    TEST_TRUE(c >= 0 && c < nc);
    if (c < 0 || c >= nc) continue;
    owns[c] = 1;
    for (int k = 0; k < 3; k++) {
      int found = 0;
      for (int a = 0; a < npc; a++)
        found |= cells[npc * c + a] == tri[3 * t + k];
      TEST_TRUE(found);
    }
  }
  /* A cell touches the surface when one of its nodes lies on it; such a cell of the Kuhn
   * split owns a face there exactly when three of its nodes do. */
  for (fcm_index c = 0; c < nc; c++) {
    int on_face[6] = {0, 0, 0, 0, 0, 0};
    for (int a = 0; a < npc; a++)
      for (int d = 0; d < 3; d++) {
        const double x = X[3 * cells[npc * c + a] + d];
        on_face[2 * d] += x == lo[d];
        on_face[2 * d + 1] += x == hi[d];
      }
    int boundary = 0;
    for (int f = 0; f < 6; f++)
      boundary |= on_face[f] >= 3;
    TEST_TRUE(owns[c] == boundary);
  }
  free(owns);

  FILE *f = tmpfile();
  TEST_TRUE(f != NULL);
  if (f) {
    char text[1024] = "", want[128];
    fcm_geometry_view(g, f);
    rewind(f);
    size_t got = fread(text, 1, sizeof text - 1, f);
    text[got] = '\0';
    fclose(f);
    snprintf(want, sizeof want, "geometry: %s cells %lld, nodes %lld, volume %.17g,", info->name,
             (long long)nc, (long long)fcm_geometry_num_nodes(g), fcm_geometry_volume(g));
    TEST_TRUE(strstr(text, want) != NULL);
    snprintf(want, sizeof want, "boundary triangles %lld", (long long)nt);
    TEST_TRUE(strstr(text, want) != NULL);
    TEST_TRUE(strstr(text, "bounding box [0, 3] x [0, 3] x [0, 3]") != NULL);
  }
  fcm_geometry_destroy(&g);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
