/* VTU writer, bad input: every rejected description fails with FCM_ERR_ARG and a message
 * naming the cell or field and the valid range, and writes no file. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/io.h"
#include "test.h"
#include "vtk_reader.h"

#define DIR "io_vtu_errors.d"
#define OUT DIR "/bad.vtu"

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_vtu *vtu = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_TRUE(vr_mkdir(DIR));
  double x[3 * 5] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  double u[3 * 5] = {0};
  double phi[2] = {1, 1};
  int64_t conn[8] = {0, 1, 2, 3, 1, 2, 3, 4};

  /* create */
  TEST_TRUE(fcm_vtu_create(ctx, NULL) == FCM_ERR_ARG);
  fcm_ctx_error_clear(ctx);
  TEST_TRUE(fcm_vtu_create(NULL, &vtu) == FCM_ERR_ARG && vtu == NULL);
  TEST_OK(ctx, fcm_vtu_create(ctx, &vtu));

  /* Writing before any points are given. */
  TEST_ERR(ctx, fcm_vtu_write(vtu, OUT, NULL), FCM_ERR_ARG, "no points set");

  /* Points, cells: counts and pointers. */
  TEST_ERR(ctx, fcm_vtu_set_points(vtu, -1, x), FCM_ERR_ARG, "number of points -1");
  TEST_ERR(ctx, fcm_vtu_set_points(vtu, 5, NULL), FCM_ERR_ARG, "NULL for 5 points");
  TEST_OK(ctx, fcm_vtu_set_points(vtu, 5, x));
  TEST_ERR(ctx, fcm_vtu_set_cells(vtu, 7, 2, conn), FCM_ERR_ARG, "unknown VTK cell type 7");
  TEST_ERR(ctx, fcm_vtu_set_cells(vtu, 26, 2, conn), FCM_ERR_ARG, "supported: 1, 5, 9, 10");
  TEST_ERR(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_TETRA, -2, conn), FCM_ERR_ARG, "number of cells -2");
  TEST_ERR(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_TETRA, 2, NULL), FCM_ERR_ARG,
           "connectivity is NULL");
  TEST_ERR(ctx, fcm_vtu_set_cells_mixed(vtu, 2, NULL, conn), FCM_ERR_ARG, "NULL for 2 mixed");

  /* Connectivity index out of range: the cell, the node, the value and the range. */
  conn[6] = 5;
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_TETRA, 2, conn));
  TEST_ERR(ctx, fcm_vtu_write(vtu, OUT, NULL), FCM_ERR_ARG,
           "cell 1 (VTK type 10) node 2 is point 5, out of range [0, 5)");
  conn[6] = -1;
  TEST_ERR(ctx, fcm_vtu_write(vtu, OUT, NULL), FCM_ERR_ARG, "point -1, out of range [0, 5)");
  conn[6] = 3;

  /* Mixed: an unknown type is found at write time. */
  int types[2] = {FCM_VTK_TETRA, 11};
  TEST_OK(ctx, fcm_vtu_set_cells_mixed(vtu, 2, types, conn));
  TEST_ERR(ctx, fcm_vtu_write(vtu, OUT, NULL), FCM_ERR_ARG, "cell 1 has unknown VTK cell type 11");
  types[1] = FCM_VTK_QUAD;
  conn[7] = 9;
  TEST_ERR(ctx, fcm_vtu_write(vtu, OUT, NULL), FCM_ERR_ARG,
           "cell 1 (VTK type 9) node 3 is point 9, out of range [0, 5)");
  conn[7] = 4;
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_TETRA, 2, conn));

  /* Vertex cells without connectivity need one cell per point. */
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_VERTEX, 4, NULL));
  TEST_ERR(ctx, fcm_vtu_write(vtu, OUT, NULL), FCM_ERR_ARG,
           "4 vertex cells without connectivity need as many points, have 5");
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_TETRA, 2, conn));

  /* Fields: location, name, components, pointer, duplicates, size mismatch. */
  TEST_ERR(ctx, fcm_vtu_add_field(vtu, (fcm_vtu_location)2, "u", 3, 5, u), FCM_ERR_ARG,
           "location 2");
  TEST_ERR(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "", 3, 5, u), FCM_ERR_ARG,
           "name is NULL, empty");
  TEST_ERR(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "a\nb", 3, 5, u), FCM_ERR_ARG,
           "control characters");
  TEST_ERR(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, NULL, 3, 5, u), FCM_ERR_ARG,
           "name is NULL");
  TEST_ERR(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "u", 2, 5, u), FCM_ERR_ARG,
           "field 'u' has 2 components; supported: 1, 3, 6 or 9");
  TEST_ERR(ctx, fcm_vtu_add_field_int32(vtu, FCM_VTU_CELL_DATA, "k", 1, 2, NULL), FCM_ERR_ARG,
           "field 'k' data is NULL");
  TEST_ERR(ctx, fcm_vtu_add_field_int64(vtu, FCM_VTU_CELL_DATA, "k", 1, -1, NULL), FCM_ERR_ARG,
           "field 'k' has -1 tuples");
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "u", 3, 4, u));
  TEST_ERR(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "u", 1, 5, phi), FCM_ERR_ARG,
           "point field 'u' added twice");
  TEST_ERR(ctx, fcm_vtu_write(vtu, OUT, NULL), FCM_ERR_ARG,
           "point field 'u' has 4 tuples, expected 5 (the number of points)");
  fcm_vtu_clear(vtu);
  TEST_OK(ctx, fcm_vtu_set_points(vtu, 5, x));
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_TETRA, 2, conn));
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "phi", 1, 3, phi));
  TEST_ERR(ctx, fcm_vtu_write(vtu, OUT, NULL), FCM_ERR_ARG,
           "cell field 'phi' has 3 tuples, expected 2 (the number of cells)");

  /* Path. */
  fcm_vtu_clear(vtu);
  TEST_OK(ctx, fcm_vtu_set_points(vtu, 5, x));
  TEST_ERR(ctx, fcm_vtu_write(vtu, "", NULL), FCM_ERR_ARG, "output path is NULL or empty");
  TEST_ERR(ctx, fcm_vtu_write(vtu, NULL, NULL), FCM_ERR_ARG, "output path is NULL or empty");

  /* No failed call left a file or a temporary behind; the valid writer still works. */
  TEST_TRUE(vr_count_entries(DIR, "") == 0);
  TEST_OK(ctx, fcm_vtu_write(vtu, OUT, NULL));
  TEST_TRUE(vr_count_entries(DIR, "") == 1);

  /* NULL objects. */
  TEST_TRUE(fcm_vtu_set_points(NULL, 5, x) == FCM_ERR_ARG);
  TEST_TRUE(fcm_vtu_write(NULL, OUT, NULL) == FCM_ERR_ARG);
  fcm_vtu_clear(NULL);
  fcm_vtu_destroy(&vtu);
  fcm_vtu_destroy(&vtu);
  fcm_vtu_destroy(NULL);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  if (!test_failures_) vr_rmdir(DIR);
  return TEST_RESULT();
}
