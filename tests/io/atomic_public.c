/* The public atomic-file API (fcm_atomic_file_*): data written to the stream reaches the
 * target only at commit; an abort, or a write error on the stream, leaves the previous file
 * byte-identical and no temporary behind (FCM_ERR_IO naming the path); a missing directory
 * fails at open with the path in the message; NULL arguments are refused; no allocation is
 * left behind. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/io.h"
#include "test.h"
#include "vtk_reader.h"

#include <dirent.h>

#define WORK "io_atomic_public.d"
#define OUT  WORK "/table.csv"

static int entries(void)
{
  int n = 0;
  DIR *d = opendir(WORK);
  if (!d) return -1;
  for (struct dirent *e; (e = readdir(d));)
    n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
  closedir(d);
  return n;
}

static int file_is(const char *want)
{
  long size = 0;
  unsigned char *have = vr_slurp(OUT, &size);
  int same = have && size == (long)strlen(want) && !memcmp(have, want, (size_t)size);
  free(have);
  return same;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_atomic_file *f = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_TRUE(vr_mkdir(WORK));
  remove(OUT);

  TEST_OK(ctx, fcm_atomic_file_open(ctx, OUT, &f));
  TEST_TRUE(f && fcm_atomic_file_stream(f));
  fprintf(fcm_atomic_file_stream(f), "a,b\n1,2\n");
  TEST_TRUE(entries() == 1 && !file_is("a,b\n1,2\n")); /* only the temporary so far */
  TEST_OK(ctx, fcm_atomic_file_commit(&f));
  TEST_TRUE(f == NULL && file_is("a,b\n1,2\n") && entries() == 1);

  /* abort: previous file intact, temporary gone */
  TEST_OK(ctx, fcm_atomic_file_open(ctx, OUT, &f));
  fprintf(fcm_atomic_file_stream(f), "partial");
  fcm_atomic_file_abort(&f);
  TEST_TRUE(f == NULL && file_is("a,b\n1,2\n") && entries() == 1);
  fcm_atomic_file_abort(&f); /* harmless on NULL */
  fcm_atomic_file_abort(NULL);

  /* a write error on the stream (reading a write-only stream sets it) fails the commit */
  TEST_OK(ctx, fcm_atomic_file_open(ctx, OUT, &f));
  FILE *s = fcm_atomic_file_stream(f);
  fprintf(s, "broken");
  (void)fgetc(s);
  TEST_TRUE(ferror(s));
  TEST_TRUE(fcm_atomic_file_commit(&f) == FCM_ERR_IO && f == NULL);
  TEST_TRUE(strstr(fcm_ctx_error_message(ctx), OUT) != NULL);
  TEST_TRUE(file_is("a,b\n1,2\n") && entries() == 1);
  fcm_ctx_error_clear(ctx);

  /* a missing directory, NULL arguments */
  TEST_TRUE(fcm_atomic_file_open(ctx, WORK "/missing/x.csv", &f) == FCM_ERR_IO && f == NULL);
  TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "missing/x.csv") != NULL);
  TEST_TRUE(fcm_atomic_file_open(ctx, "", &f) == FCM_ERR_ARG && f == NULL);
  TEST_TRUE(fcm_atomic_file_open(ctx, OUT, NULL) == FCM_ERR_ARG);
  TEST_TRUE(fcm_atomic_file_commit(NULL) == FCM_ERR_ARG);
  TEST_TRUE(fcm_atomic_file_stream(NULL) == NULL);
  TEST_TRUE(entries() == 1);

  remove(OUT);
  remove(WORK);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
