/* The checkpoint container shared by every checkpoint writer (scene runs, the PETSc linear
 * driver): a header, typed values in the writer's order and a checksum, written through an
 * atomic file (whole or absent) and read back with every value checked.
 *
 * Layout (host byte order; integers 8 bytes, doubles IEEE 754 binary64):
 *   8 bytes magic (the writer's, e.g. "FCMCKPT\0")
 *   u64 version, u64 byte-order mark 0x0102030405060708
 *   the payload
 *   u64 FNV-1a 64 checksum of every byte before it
 *
 * The reader also recognises the PETSc linear driver's older file (".fcmpk", no header
 * but its magic line, no checksum) so that both readers of linear-driver checkpoints share the
 * detection (fcm__ckpt_reader.legacy_linear). */
#include "io/io_impl.h"

#include <string.h>

#define CKPT_BOM  0x0102030405060708ull
#define FNV_PRIME 0x100000001b3ull

/* The magic line of the linear driver's older format. */
static const char legacy_linear_magic[16] = "fcm-petsc-ck-1\n";

uint64_t fcm__io_fnv(uint64_t h, const void *data, size_t n)
{
  const unsigned char *p = data;
  for (size_t k = 0; k < n; k++) {
    h ^= p[k];
    h *= FNV_PRIME;
  }
  return h;
}

/* ---------------------------------------------------------------- writing */

fcm_status fcm__ckpt_open(fcm_ctx *ctx, const char *path, const char magic[8], uint64_t version,
                          fcm__ckpt_writer *w)
{
  fcm_status st = FCM_OK;
  memset(w, 0, sizeof *w);
  w->ctx = ctx;
  w->hash = FCM__FNV_OFFSET;
  FCM_TRY(ctx, fcm__io_atomic_open(ctx, path, 1, NULL, &w->af));
  FCM_TRY(ctx, fcm__ckpt_put(w, magic, 8));
  FCM_TRY(ctx, fcm__ckpt_put_u64(w, version));
  FCM_TRY(ctx, fcm__ckpt_put_u64(w, CKPT_BOM));
cleanup:
  if (st != FCM_OK) fcm__ckpt_abort(w);
  return st;
}

fcm_status fcm__ckpt_put(fcm__ckpt_writer *w, const void *data, size_t n)
{
  w->hash = fcm__io_fnv(w->hash, data, n);
  return fcm__io_atomic_write(w->ctx, &w->af, data, n);
}

fcm_status fcm__ckpt_put_u64(fcm__ckpt_writer *w, uint64_t x)
{
  return fcm__ckpt_put(w, &x, sizeof x);
}

fcm_status fcm__ckpt_put_i64(fcm__ckpt_writer *w, long long x)
{
  const int64_t v = (int64_t)x;
  return fcm__ckpt_put(w, &v, sizeof v);
}

fcm_status fcm__ckpt_put_f64(fcm__ckpt_writer *w, double x)
{
  return fcm__ckpt_put(w, &x, sizeof x);
}

fcm_status fcm__ckpt_put_f64s(fcm__ckpt_writer *w, const double *x, size_t n)
{
  return n > 0 ? fcm__ckpt_put(w, x, n * sizeof *x) : FCM_OK;
}

fcm_status fcm__ckpt_commit(fcm__ckpt_writer *w)
{
  fcm_status st = FCM_OK;
  const uint64_t sum = w->hash;
  FCM_TRY(w->ctx, fcm__io_atomic_write(w->ctx, &w->af, &sum, sizeof sum));
  FCM_TRY(w->ctx, fcm__io_atomic_commit(w->ctx, &w->af));
cleanup:
  if (st != FCM_OK) fcm__ckpt_abort(w);
  return st;
}

void fcm__ckpt_abort(fcm__ckpt_writer *w)
{
  if (w) fcm__io_atomic_abort(w->ctx, &w->af);
}

/* ---------------------------------------------------------------- reading */

/* Checkpoints above this size are refused before reading (1 TiB). */
#define CKPT_MAX_BYTES ((size_t)1 << 40)

fcm_status fcm__ckpt_read_open(fcm_ctx *ctx, const char *path, const char magic[8],
                               uint64_t max_version, fcm__ckpt_reader *r)
{
  fcm_status st = FCM_OK;
  char *data = NULL;
  size_t size = 0;
  uint64_t version = 0, bom = 0, sum = 0;
  memset(r, 0, sizeof *r);
  r->ctx = ctx;
  r->path = path;
  FCM_TRY(ctx, fcm__file_read_all(ctx, "checkpoint", path, CKPT_MAX_BYTES, &data, &size));
  r->data = (unsigned char *)data;
  r->size = size;
  if (size >= sizeof legacy_linear_magic &&
      !memcmp(data, legacy_linear_magic, sizeof legacy_linear_magic)) {
    r->legacy_linear = 1; /* no version, no checksum: the values are checked as read */
    r->pos = sizeof legacy_linear_magic;
    goto cleanup;
  }
  FCM_CHECK(size >= 8 + sizeof version && !memcmp(data, magic, 8), ctx, FCM_ERR_FORMAT,
            "checkpoint %s: not an fcm checkpoint (no %.8s header)", path, magic);
  r->pos = 8;
  FCM_TRY(ctx, fcm__ckpt_get(r, &version, sizeof version, "the version"));
  FCM_TRY(ctx, fcm__ckpt_get(r, &bom, sizeof bom, "the byte-order mark"));
  FCM_CHECK(bom == CKPT_BOM, ctx, FCM_ERR_FORMAT,
            "checkpoint %s: written on a machine of the other byte order", path);
  FCM_CHECK(version >= 1 && version <= max_version, ctx, FCM_ERR_FORMAT,
            "checkpoint %s: version %llu; this build reads versions 1 to %llu", path,
            (unsigned long long)version, (unsigned long long)max_version);
  FCM_CHECK(size >= r->pos + sizeof sum, ctx, FCM_ERR_FORMAT,
            "checkpoint %s: truncated (%zu bytes): no checksum after the header", path, size);
  memcpy(&sum, r->data + size - sizeof sum, sizeof sum);
  FCM_CHECK(fcm__io_fnv(FCM__FNV_OFFSET, r->data, size - sizeof sum) == sum, ctx, FCM_ERR_FORMAT,
            "checkpoint %s: checksum mismatch (the file is truncated or corrupted)", path);
  r->size = size - sizeof sum;
  r->version = version;
cleanup:
  if (st != FCM_OK) fcm__ckpt_read_close(r);
  return st;
}

void fcm__ckpt_read_close(fcm__ckpt_reader *r)
{
  if (!r) return;
  fcm__free(r->ctx, r->data);
  r->data = NULL;
  r->size = r->pos = 0;
}

fcm_status fcm__ckpt_get(fcm__ckpt_reader *r, void *out, size_t n, const char *what)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(r->pos <= r->size && n <= r->size - r->pos, r->ctx, FCM_ERR_FORMAT,
            "checkpoint %s: truncated (%zu bytes) while reading %s at byte %zu", r->path, r->size,
            what, r->pos);
  memcpy(out, r->data + r->pos, n);
  r->pos += n;
cleanup:
  return st;
}

fcm_status fcm__ckpt_get_u64(fcm__ckpt_reader *r, uint64_t *x, const char *what)
{
  return fcm__ckpt_get(r, x, sizeof *x, what);
}

fcm_status fcm__ckpt_get_i64(fcm__ckpt_reader *r, long long *x, long long lo, long long hi,
                             const char *what)
{
  fcm_status st = FCM_OK;
  int64_t v = 0;
  FCM_TRY(r->ctx, fcm__ckpt_get(r, &v, sizeof v, what));
  FCM_CHECK(v >= lo && v <= hi, r->ctx, FCM_ERR_FORMAT,
            "checkpoint %s: %s = %lld is outside [%lld, %lld]", r->path, what, (long long)v, lo,
            hi);
  *x = (long long)v;
cleanup:
  return st;
}

fcm_status fcm__ckpt_get_f64(fcm__ckpt_reader *r, double *x, const char *what)
{
  return fcm__ckpt_get(r, x, sizeof *x, what);
}

fcm_status fcm__ckpt_need(fcm__ckpt_reader *r, long long count, size_t each, const char *what)
{
  fcm_status st = FCM_OK;
  const size_t left = r->pos <= r->size ? r->size - r->pos : 0;
  FCM_CHECK(count >= 0 && (unsigned long long)count <= left / each, r->ctx, FCM_ERR_FORMAT,
            "checkpoint %s: %lld %s of %zu bytes announced at byte %zu, but only %zu bytes are "
            "left (the file is truncated or corrupted)",
            r->path, count, what, each, r->pos, left);
cleanup:
  return st;
}

fcm_status fcm__ckpt_read_end(fcm__ckpt_reader *r)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(r->pos == r->size, r->ctx, FCM_ERR_FORMAT,
            "checkpoint %s: %zu unexpected trailing bytes", r->path, r->size - r->pos);
cleanup:
  return st;
}

/* ---------------------------------------------------------------- linear-driver records */

fcm_status fcm__ckpt_put_linear(fcm__ckpt_writer *w, const fcm__ckpt_linear *h, const double *u,
                                const double *v)
{
  fcm_status st = FCM_OK;
  FCM_TRY(w->ctx, fcm__ckpt_put_u64(w, FCM__CKPT_SOURCE_LINEAR));
  FCM_TRY(w->ctx, fcm__ckpt_put_i64(w, h->num_dofs));
  FCM_TRY(w->ctx, fcm__ckpt_put_i64(w, h->elements));
  FCM_TRY(w->ctx, fcm__ckpt_put_i64(w, h->steps));
  FCM_TRY(w->ctx, fcm__ckpt_put_i64(w, h->kind));
  FCM_TRY(w->ctx, fcm__ckpt_put_f64(w, h->time));
  FCM_TRY(w->ctx, fcm__ckpt_put_f64(w, h->dt));
  FCM_TRY(w->ctx, fcm__ckpt_put_f64s(w, u, (size_t)h->num_dofs));
  FCM_TRY(w->ctx, fcm__ckpt_put_f64s(w, v, (size_t)h->num_dofs));
cleanup:
  return st;
}

fcm_status fcm__ckpt_get_linear(fcm__ckpt_reader *r, fcm__ckpt_linear *h)
{
  fcm_status st = FCM_OK;
  FCM_TRY(r->ctx, fcm__ckpt_get_i64(r, &h->num_dofs, 0, INT64_MAX, "num_dofs"));
  FCM_TRY(r->ctx, fcm__ckpt_get_i64(r, &h->elements, 0, INT64_MAX, "elements"));
  FCM_TRY(r->ctx, fcm__ckpt_get_i64(r, &h->steps, 0, INT64_MAX, "steps"));
  FCM_TRY(r->ctx, fcm__ckpt_get_i64(r, &h->kind, 0, 1, "the integrator kind"));
  FCM_TRY(r->ctx, fcm__ckpt_get_f64(r, &h->time, "time"));
  FCM_TRY(r->ctx, fcm__ckpt_get_f64(r, &h->dt, "dt"));
  FCM_TRY(r->ctx,
          fcm__ckpt_need(r, h->num_dofs, 2 * sizeof(double), "displacement and velocity values"));
cleanup:
  return st;
}
