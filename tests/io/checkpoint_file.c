/* The checkpoint container (io/checkpoint_file.c): typed values read back bit for bit after
 * the header and before the checksum; the byte layout as documented; every truncation and
 * every single-byte corruption of the file refused with FCM_ERR_FORMAT naming the file (the
 * checksum covers every byte; the header is checked before it); a version above the reader's,
 * another magic and the other byte order refused; an aborted write leaves the previous file
 * byte-identical and nothing else behind; the linear driver's older file recognised. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_impl.h"
#include "test.h"
#include "vtk_reader.h"

#include <dirent.h>
#include <math.h>

#define CKDIR "io_checkpoint_file.d"
#define OUT   CKDIR "/a.ck"

static const char magic[8] = "TESTCKP";

static void write_file(const char *path, const unsigned char *b, long n)
{
  FILE *f = fopen(path, "wb");
  TEST_TRUE(f && fwrite(b, 1, (size_t)n, f) == (size_t)n);
  if (f) fclose(f);
}

/* Files in CKDIR (the temporaries are hidden: count every entry but . and ..). */
static int dir_entries(void)
{
  DIR *d = opendir(CKDIR);
  int n = 0;
  for (struct dirent *e; d && (e = readdir(d));)
    n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
  if (d) closedir(d);
  return n;
}

/* Read OUT as written by main(): FCM_OK with every value equal, or the reader's status. */
static fcm_status read_back(fcm_ctx *ctx, const double *x, int check)
{
  fcm__ckpt_reader r;
  fcm_status st = fcm__ckpt_read_open(ctx, OUT, magic, 3, &r);
  uint64_t u = 0;
  long long i = 0;
  double d = 0.0, y[5];
  if (st == FCM_OK) st = fcm__ckpt_get_u64(&r, &u, "u");
  if (st == FCM_OK) st = fcm__ckpt_get_i64(&r, &i, -10, 10, "i");
  if (st == FCM_OK) st = fcm__ckpt_get_f64(&r, &d, "d");
  if (st == FCM_OK) st = fcm__ckpt_need(&r, 5, sizeof(double), "values");
  if (st == FCM_OK) st = fcm__ckpt_get(&r, y, sizeof y, "values");
  if (st == FCM_OK) st = fcm__ckpt_read_end(&r);
  if (st == FCM_OK && check) {
    TEST_TRUE(r.version == 3 && !r.legacy_linear);
    TEST_TRUE(u == 0xfedcba9876543210ull && i == -7 && d == 0.1);
    TEST_TRUE(!memcmp(y, x, sizeof y));
  }
  fcm__ckpt_read_close(&r);
  return st;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_TRUE(vr_mkdir(CKDIR));
  const double x[5] = {1.0, -0.0, 1e-300, NAN, 3.0 / 7.0};

  fcm__ckpt_writer w;
  TEST_OK(ctx, fcm__ckpt_open(ctx, OUT, magic, 3, &w));
  TEST_OK(ctx, fcm__ckpt_put_u64(&w, 0xfedcba9876543210ull));
  TEST_OK(ctx, fcm__ckpt_put_i64(&w, -7));
  TEST_OK(ctx, fcm__ckpt_put_f64(&w, 0.1));
  TEST_OK(ctx, fcm__ckpt_put_f64s(&w, x, 5));
  TEST_OK(ctx, fcm__ckpt_commit(&w));
  TEST_OK(ctx, read_back(ctx, x, 1));

  /* the layout: magic, version, byte-order mark, the values, FNV-1a of what precedes */
  long size = 0;
  unsigned char *b = vr_slurp(OUT, &size);
  TEST_TRUE(b && size == 8 * 3 + 8 * 3 + 8 * 5 + 8);
  if (!b || size != 96) return TEST_RESULT();
  uint64_t version, bom, sum, h = 0xcbf29ce484222325ull;
  memcpy(&version, b + 8, 8);
  memcpy(&bom, b + 16, 8);
  memcpy(&sum, b + size - 8, 8);
  for (long k = 0; k < size - 8; k++)
    h = (h ^ b[k]) * 0x100000001b3ull;
  TEST_TRUE(!memcmp(b, magic, 8) && version == 3 && bom == 0x0102030405060708ull && sum == h);
  TEST_TRUE(fcm__io_fnv(FCM__FNV_OFFSET, b, (size_t)size - 8) == h);

  /* every truncation: a format error naming the file */
  int refused = 0;
  for (long n = 0; n < size; n++) {
    write_file(OUT, b, n);
    fcm_status st = read_back(ctx, x, 0);
    refused += st == FCM_ERR_FORMAT && strstr(fcm_ctx_error_message(ctx), OUT) != NULL;
  }
  TEST_TRUE(refused == size);
  /* every single-byte corruption: a format error */
  refused = 0;
  for (long k = 0; k < size; k++) {
    b[k] ^= 0x20;
    write_file(OUT, b, size);
    b[k] ^= 0x20;
    refused += read_back(ctx, x, 0) == FCM_ERR_FORMAT;
  }
  TEST_TRUE(refused == size);
  /* trailing bytes (resealed): refused by read_end; a later version; the other byte order */
  {
    unsigned char c[104];
    memcpy(c, b, 88);
    memset(c + 88, 0, 8);
    uint64_t s2 = fcm__io_fnv(FCM__FNV_OFFSET, c, 96);
    memcpy(c + 96, &s2, 8);
    write_file(OUT, c, 104);
    TEST_ERR(ctx, read_back(ctx, x, 0), FCM_ERR_FORMAT, "trailing");
    memcpy(c, b, 96);
    const uint64_t v4 = 4, swapped = 0x0807060504030201ull;
    memcpy(c + 8, &v4, 8);
    s2 = fcm__io_fnv(FCM__FNV_OFFSET, c, 88);
    memcpy(c + 88, &s2, 8);
    write_file(OUT, c, 96);
    TEST_ERR(ctx, read_back(ctx, x, 0), FCM_ERR_FORMAT, "version 4");
    memcpy(c, b, 96);
    memcpy(c + 16, &swapped, 8);
    write_file(OUT, c, 96);
    TEST_ERR(ctx, read_back(ctx, x, 0), FCM_ERR_FORMAT, "byte order");
    write_file(OUT, b, size);
    fcm__ckpt_reader r;
    TEST_ERR(ctx, fcm__ckpt_read_open(ctx, OUT, "OTHERCK", 3, &r), FCM_ERR_FORMAT, "OTHERCK");
    fcm__ckpt_read_close(&r);
  }
  /* an integer out of its range names it */
  TEST_OK(ctx, fcm__ckpt_open(ctx, OUT, magic, 3, &w));
  TEST_OK(ctx, fcm__ckpt_put_u64(&w, 1));
  TEST_OK(ctx, fcm__ckpt_put_i64(&w, 11));
  TEST_OK(ctx, fcm__ckpt_commit(&w));
  TEST_ERR(ctx, read_back(ctx, x, 0), FCM_ERR_FORMAT, "i = 11 is outside [-10, 10]");

  /* an aborted write: the previous file stays, no temporary is left */
  write_file(OUT, b, size);
  TEST_OK(ctx, fcm__ckpt_open(ctx, OUT, magic, 3, &w));
  TEST_OK(ctx, fcm__ckpt_put_i64(&w, 1));
  TEST_TRUE(dir_entries() == 2);
  fcm__ckpt_abort(&w);
  TEST_TRUE(dir_entries() == 1);
  TEST_OK(ctx, read_back(ctx, x, 1));
  /* an unwritable path: FCM_ERR_IO naming it */
  TEST_ERR(ctx, fcm__ckpt_open(ctx, CKDIR "/no-such-dir/a.ck", magic, 3, &w), FCM_ERR_IO,
           "no-such-dir");

  /* the linear driver's older file: recognised, its values read after the magic line */
  {
    unsigned char c[16 + 48 + 16];
    const int64_t head[4] = {1, 2, 3, 1};
    const double times[2] = {0.5, 0.25}, uv[2] = {1.5, -2.5};
    memcpy(c, "fcm-petsc-ck-1\n", 16);
    memcpy(c + 16, head, sizeof head);
    memcpy(c + 48, times, sizeof times);
    memcpy(c + 64, uv, sizeof uv);
    write_file(OUT, c, sizeof c);
    fcm__ckpt_reader r;
    fcm__ckpt_linear lin;
    double a[2];
    TEST_OK(ctx, fcm__ckpt_read_open(ctx, OUT, magic, 3, &r));
    TEST_TRUE(r.legacy_linear);
    TEST_OK(ctx, fcm__ckpt_get_linear(&r, &lin));
    TEST_OK(ctx, fcm__ckpt_get(&r, a, sizeof a, "state"));
    TEST_OK(ctx, fcm__ckpt_read_end(&r));
    TEST_TRUE(lin.num_dofs == 1 && lin.elements == 2 && lin.steps == 3 && lin.kind == 1 &&
              lin.time == 0.5 && lin.dt == 0.25 && a[0] == 1.5 && a[1] == -2.5);
    fcm__ckpt_read_close(&r);
    write_file(OUT, c, sizeof c - 1);
    TEST_OK(ctx, fcm__ckpt_read_open(ctx, OUT, magic, 3, &r));
    TEST_ERR(ctx, fcm__ckpt_get_linear(&r, &lin), FCM_ERR_FORMAT, "truncated");
    fcm__ckpt_read_close(&r);
  }

  free(b);
  remove(OUT);
  TEST_TRUE(rmdir(CKDIR) == 0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
