/* Allocation failures in the io writers: failing the k-th allocation for k = 0, 1, ...
 * gives FCM_ERR_ALLOC, leaks nothing, leaves no temporary and never a partial file. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/io.h"
#include "test.h"
#include "test_alloc.h"
#include "vtk_reader.h"

#define DIR "io_alloc_failure.d"

/* The whole output sequence of one frame: 0 or the failing status. */
static fcm_status run(fcm_ctx *ctx)
{
  static double x[3 * 4] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  static double u[3 * 4] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  static int64_t conn[4] = {0, 1, 2, 3};
  static int32_t cls[1] = {2};
  /* A long name makes the header formatting allocate. */
  char name[700];
  memset(name, 'n', sizeof name - 1);
  name[sizeof name - 1] = 0;
  fcm_status st = FCM_OK;
  fcm_vtu *vtu = NULL;
  fcm_pvd *pvd = NULL;
  if ((st = fcm_vtu_create(ctx, &vtu))) goto done;
  if ((st = fcm_vtu_set_points(vtu, 4, x))) goto done;
  if ((st = fcm_vtu_set_cells(vtu, FCM_VTK_TETRA, 1, conn))) goto done;
  if ((st = fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "u", 3, 4, u))) goto done;
  if ((st = fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, name, 3, 4, u))) goto done;
  if ((st = fcm_vtu_add_field_int32(vtu, FCM_VTU_CELL_DATA, "class", 1, 1, cls))) goto done;
  if ((st = fcm_vtu_add_field_int64(vtu, FCM_VTU_CELL_DATA, "id", 1, 1, conn))) goto done;
  if ((st = fcm_vtu_write(vtu, DIR "/a.vtu", NULL))) goto done;
  if ((st = fcm_pvd_create(ctx, DIR "/a.pvd", &pvd))) goto done;
  if ((st = fcm_pvd_add(pvd, 0.0, DIR "/a.vtu"))) goto done;
  if ((st = fcm_pvd_add(pvd, 1.0, DIR "/a.vtu"))) goto done;
done:
  fcm_pvd_destroy(&pvd);
  fcm_vtu_destroy(&vtu);
  return st;
}

int main(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  TEST_TRUE(vr_mkdir(DIR));

  long long k = 0;
  for (;; k++) {
    f.count = 0;
    f.fail_at = k;
    fcm_status st = run(ctx);
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 0);
    if (st == FCM_OK) break;
    if (st != FCM_ERR_ALLOC) {
      TEST_FAIL_("failing allocation %lld: %s (%s)", k, fcm_status_name(st),
                 fcm_ctx_error_message(ctx));
      break;
    }
    fcm_ctx_error_clear(ctx);
    /* Whatever exists is complete. */
    vr_doc *d = malloc(sizeof *d);
    if (vr_load(d, DIR "/a.vtu") && !vr_parse_vtu(d))
      TEST_FAIL_("failing allocation %lld: a.vtu %s", k, d->error);
    vr_free(d);
    if (vr_load(d, DIR "/a.pvd") && !vr_parse_xml(d))
      TEST_FAIL_("failing allocation %lld: a.pvd %s", k, d->error);
    vr_free(d);
    free(d);
    vr_mkdir(DIR);
    if (k > 1000) {
      TEST_FAIL_("no success after %lld failing allocations", k);
      break;
    }
  }
  TEST_TRUE(k >= 15); /* every step allocates: the loop really exercised them */

  /* the public atomic file: open allocates; a failing open leaves NULL and nothing on disk */
  vr_mkdir(DIR);
  int opened = 0, failures = 0;
  for (k = 0; k < 100 && !opened; k++) {
    fcm_atomic_file *af = (fcm_atomic_file *)&f;
    f.count = 0;
    f.fail_at = k;
    fcm_status st = fcm_atomic_file_open(ctx, DIR "/table.csv", &af);
    f.fail_at = -1;
    if (st == FCM_OK) {
      opened = 1;
      fputs("a,b\n1,2\n", fcm_atomic_file_stream(af));
      TEST_OK(ctx, fcm_atomic_file_commit(&af));
    } else {
      failures++;
      if (st != FCM_ERR_ALLOC || af != NULL)
        TEST_FAIL_("atomic file open, failing allocation %lld: %s", k, fcm_status_name(st));
      TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 0 && vr_count_entries(DIR, "table") == 0);
      fcm_ctx_error_clear(ctx);
    }
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  }
  TEST_TRUE(opened && failures >= 2);
  TEST_TRUE(vr_count_entries(DIR, "table.csv") == 1 && vr_count_entries(DIR, ".tmp.") == 0);
  fcm_ctx_destroy(&ctx);
  if (!test_failures_) vr_rmdir(DIR);
  return TEST_RESULT();
}
