/* Atomic writes: a missing directory fails with FCM_ERR_IO naming the path and leaves
 * nothing; an existing file is replaced completely; a failure at any byte of a write,
 * or at commit, leaves the previous file byte-identical and no temporary behind. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_impl.h"
#include "test.h"
#include "vtk_reader.h"

#include <errno.h>

#define DIR "io_atomic.d"
#define OUT DIR "/frame.vtu"

static int same_file(const char *path, const unsigned char *want, long want_size)
{
  long size;
  unsigned char *have = vr_slurp(path, &size);
  int same = have && size == want_size && !memcmp(have, want, (size_t)size);
  free(have);
  return same;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_vtu *vtu = NULL;
  fcm_vtu_info info;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_TRUE(vr_mkdir(DIR));

  double x[3 * 8], u[3 * 8];
  int64_t conn[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  for (int i = 0; i < 24; i++) {
    x[i] = (double)((i / 3 >> (i % 3)) & 1); /* unit cube corners in binary order */
    u[i] = 0.1 * i;
  }
  TEST_OK(ctx, fcm_vtu_create(ctx, &vtu));
  TEST_OK(ctx, fcm_vtu_set_points(vtu, 8, x));
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_VERTEX, 8, conn));
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "u", 3, 8, u));

  /* A directory that does not exist: FCM_ERR_IO, the path and the system error. */
  char want[512];
  snprintf(want, sizeof want, "'%s': %s", DIR "/missing/out.vtu", strerror(ENOENT));
  TEST_ERR(ctx, fcm_vtu_write(vtu, DIR "/missing/out.vtu", NULL), FCM_ERR_IO, want);
  TEST_TRUE(vr_count_entries(DIR, "") == 0);

  /* A target that is a directory: everything is written, the rename fails, the
   * temporary goes away and the directory stays. */
  TEST_TRUE(mkdir(DIR "/adir", 0777) == 0);
  TEST_ERR(ctx, fcm_vtu_write(vtu, DIR "/adir", NULL), FCM_ERR_IO, "renaming");
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 0);
  TEST_TRUE(rmdir(DIR "/adir") == 0);

  /* Overwrite: a larger existing file is replaced completely. */
  FILE *f = fopen(OUT, "wb");
  for (int i = 0; i < 100000; i++)
    fputc('#', f);
  fclose(f);
  TEST_OK(ctx, fcm_vtu_write(vtu, OUT, &info));
  long size_a;
  unsigned char *a = vr_slurp(OUT, &size_a);
  TEST_TRUE(a && size_a == info.file_bytes && size_a < 100000);
  vr_doc *d = malloc(sizeof *d);
  d->data = NULL;
  if (!(vr_load(d, OUT) && vr_parse_vtu(d))) TEST_FAIL_("overwritten file: %s", d->error);
  vr_free(d);
  free(d);
  TEST_TRUE(vr_count_entries(DIR, "") == 1);

  /* Simulated failures at every byte of a new write, and at commit. */
  for (int i = 0; i < 24; i++)
    u[i] = -1.0 - i;
  int checked = 0;
  for (long long k = 0; k <= size_a; k++) {
    fcm__io_fault fault = {k, k == size_a};
    fcm_status st = fcm__vtu_write_fault(vtu, OUT, &info, &fault);
    if (st != FCM_ERR_IO || !strstr(fcm_ctx_error_message(ctx), "'" OUT "'"))
      TEST_FAIL_("fault at byte %lld: %s, \"%s\"", k, fcm_status_name(st),
                 fcm_ctx_error_message(ctx));
    fcm_ctx_error_clear(ctx);
    if (!same_file(OUT, a, size_a)) TEST_FAIL_("fault at byte %lld changed the file", k);
    if (vr_count_entries(DIR, "") != 1) TEST_FAIL_("fault at byte %lld left a temporary", k);
    checked++;
  }
  TEST_TRUE(checked == size_a + 1 && size_a > 500);
  fcm__io_fault late = {size_a, 0}; /* the whole file fits: no failure */
  TEST_OK(ctx, fcm__vtu_write_fault(vtu, OUT, &info, &late));
  TEST_TRUE(!same_file(OUT, a, size_a) && info.file_bytes == size_a);

  /* The internal API directly: abort after writing removes the temporary. */
  fcm__atomic_file af;
  TEST_OK(ctx, fcm__io_atomic_open(ctx, DIR "/log.csv", 1, NULL, &af));
  TEST_OK(ctx, fcm__io_atomic_printf(ctx, &af, "step,%s\n", "energy"));
  TEST_TRUE(vr_count_entries(DIR, "log.csv.tmp.") == 1);
  fcm__io_atomic_abort(ctx, &af);
  fcm__io_atomic_abort(ctx, &af); /* idempotent */
  TEST_TRUE(vr_count_entries(DIR, "log.csv") == 0);
  TEST_OK(ctx, fcm__io_atomic_open(ctx, DIR "/log.csv", 1, NULL, &af));
  TEST_OK(ctx, fcm__io_atomic_write_xml(ctx, &af, "a<b&\"c'>"));
  TEST_OK(ctx, fcm__io_atomic_commit(ctx, &af));
  long n;
  unsigned char *text = vr_slurp(DIR "/log.csv", &n);
  const char *esc = "a&lt;b&amp;&quot;c&apos;&gt;";
  TEST_TRUE(text && n == (long)strlen(esc) && !memcmp(text, esc, (size_t)n));
  free(text);

  /* PVD: a failing rewrite keeps the previous index and the entry count. */
  fcm_pvd *pvd = NULL;
  TEST_OK(ctx, fcm_pvd_create(ctx, DIR "/run.pvd", &pvd));
  TEST_OK(ctx, fcm_pvd_add(pvd, 0.0, "f0.vtu"));
  TEST_OK(ctx, fcm_pvd_add(pvd, 0.5, "f1.vtu"));
  long pvd_size;
  unsigned char *pvd_before = vr_slurp(DIR "/run.pvd", &pvd_size);
  for (long long k = 0; k <= pvd_size; k += 7) {
    fcm__io_fault fault = {k, 0};
    TEST_TRUE(fcm__pvd_add_fault(pvd, 1.0, "f2.vtu", &fault) == FCM_ERR_IO);
    TEST_TRUE(fcm_pvd_num_entries(pvd) == 2);
    TEST_TRUE(same_file(DIR "/run.pvd", pvd_before, pvd_size));
  }
  fcm__io_fault at_commit = {-1, 1};
  TEST_ERR(ctx, fcm__pvd_add_fault(pvd, 1.0, "f2.vtu", &at_commit), FCM_ERR_IO, "run.pvd");
  TEST_TRUE(same_file(DIR "/run.pvd", pvd_before, pvd_size) && fcm_pvd_num_entries(pvd) == 2);
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 0);
  TEST_OK(ctx, fcm_pvd_add(pvd, 1.0, "f2.vtu"));
  TEST_TRUE(fcm_pvd_num_entries(pvd) == 3 && !same_file(DIR "/run.pvd", pvd_before, pvd_size));
  free(pvd_before);
  fcm_pvd_destroy(&pvd);

  /* A PVD in a missing directory fails at create. */
  TEST_ERR(ctx, fcm_pvd_create(ctx, DIR "/nope/run.pvd", &pvd), FCM_ERR_IO, DIR "/nope/run.pvd");
  TEST_TRUE(pvd == NULL);

  free(a);
  fcm_vtu_destroy(&vtu);
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  if (!test_failures_) vr_rmdir(DIR);
  return TEST_RESULT();
}
