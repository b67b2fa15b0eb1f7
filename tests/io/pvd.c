/* PVD index: valid (balanced, parsable) after create and after each addition; after
 * three frames it lists three DataSets with the exact times and the file names made
 * relative to the index's directory. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/io.h"
#include "test.h"
#include "vtk_reader.h"

#define DIR "io_pvd.d"
#define PVD DIR "/run.pvd"

/* Parse the index and compare its entries with times[0..n) and files[0..n). */
static void check_index(int n, const double *times, const char *const *files)
{
  char buf[256];
  vr_doc *d = malloc(sizeof *d);
  if (!vr_load(d, PVD) || !vr_parse_xml(d)) {
    TEST_FAIL_("%s: %s", PVD, d->error);
  } else {
    const vr_tag *f = vr_find(d, "VTKFile", "", 0);
    TEST_TRUE(f && vr_attr(f, "type", buf, sizeof buf) && !strcmp(buf, "Collection"));
    TEST_TRUE(vr_find(d, "Collection", "VTKFile", 0) != NULL);
    int count = 0;
    while (vr_find(d, "DataSet", NULL, count))
      count++;
    TEST_TRUE(count == n);
    for (int i = 0; i < n && i < count; i++) {
      const vr_tag *t = vr_find(d, "DataSet", "Collection", i);
      TEST_TRUE(t != NULL);
      if (!t) continue;
      TEST_TRUE(vr_attr(t, "timestep", buf, sizeof buf));
      double time = strtod(buf, NULL);
      if (memcmp(&time, &times[i], sizeof time))
        TEST_FAIL_("entry %d: timestep %s, expected %.17g", i, buf, times[i]);
      TEST_TRUE(vr_attr(t, "file", buf, sizeof buf) && !strcmp(buf, files[i]));
    }
  }
  vr_free(d);
  free(d);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_pvd *pvd = NULL;
  fcm_vtu *vtu = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_TRUE(vr_mkdir(DIR));

  /* Times that need all 17 digits; the second file name needs XML escapes. */
  const double times[3] = {0.0, 0.1, 1.0 / 3.0};
  const char *given[3] = {DIR "/f_0.vtu", DIR "/f&<1>.vtu", "elsewhere/f_2.vtu"};
  const char *rel[3] = {"f_0.vtu", "f&<1>.vtu", "elsewhere/f_2.vtu"};

  TEST_OK(ctx, fcm_pvd_create(ctx, PVD, &pvd));
  TEST_TRUE(fcm_pvd_num_entries(pvd) == 0);
  check_index(0, times, rel);

  double x[3] = {1, 2, 3};
  TEST_OK(ctx, fcm_vtu_create(ctx, &vtu));
  TEST_OK(ctx, fcm_vtu_set_points(vtu, 1, x));
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_VERTEX, 1, NULL));
  for (int i = 0; i < 3; i++) {
    if (i < 2) TEST_OK(ctx, fcm_vtu_write(vtu, given[i], NULL));
    TEST_OK(ctx, fcm_pvd_add(pvd, times[i], given[i]));
    TEST_TRUE(fcm_pvd_num_entries(pvd) == i + 1);
    check_index(i + 1, times, rel); /* valid after every step */
  }

  /* With xmllint on the machine, a real XML parser agrees (optional). */
  if (access("/usr/bin/xmllint", X_OK) == 0)
    TEST_TRUE(system("/usr/bin/xmllint --noout " PVD) == 0);

  /* Bad entries change nothing. */
  TEST_ERR(ctx, fcm_pvd_add(pvd, NAN, "f.vtu"), FCM_ERR_ARG, "time nan is not finite");
  TEST_ERR(ctx, fcm_pvd_add(pvd, INFINITY, "f.vtu"), FCM_ERR_ARG, "not finite");
  TEST_ERR(ctx, fcm_pvd_add(pvd, 2.0, ""), FCM_ERR_ARG, "data file name is NULL, empty");
  TEST_ERR(ctx, fcm_pvd_add(pvd, 2.0, NULL), FCM_ERR_ARG, "data file name");
  TEST_ERR(ctx, fcm_pvd_add(pvd, 2.0, "a\tb.vtu"), FCM_ERR_ARG, "control characters");
  TEST_TRUE(fcm_pvd_num_entries(pvd) == 3);
  check_index(3, times, rel);
  TEST_TRUE(fcm_pvd_add(NULL, 0.0, "f.vtu") == FCM_ERR_ARG);
  TEST_TRUE(fcm_pvd_num_entries(NULL) == 0);

  /* Many entries (array growth), then a fresh index at the same path starts empty. */
  for (int i = 3; i < 40; i++)
    TEST_OK(ctx, fcm_pvd_add(pvd, i, "g.vtu"));
  TEST_TRUE(fcm_pvd_num_entries(pvd) == 40);
  fcm_pvd_destroy(&pvd);
  TEST_TRUE(pvd == NULL);
  TEST_OK(ctx, fcm_pvd_create(ctx, PVD, &pvd));
  check_index(0, times, rel);
  fcm_pvd_destroy(&pvd);
  fcm_pvd_destroy(NULL);

  TEST_ERR(ctx, fcm_pvd_create(ctx, "", &pvd), FCM_ERR_ARG, "index path");
  TEST_TRUE(fcm_pvd_create(ctx, PVD, NULL) == FCM_ERR_ARG);

  fcm_vtu_destroy(&vtu);
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  if (!test_failures_) vr_rmdir(DIR);
  return TEST_RESULT();
}
