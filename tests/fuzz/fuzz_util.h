/* Shared helpers of the libFuzzer targets: a context whose allocator refuses single
 * allocations above a cap (so that a header count the reader trusts becomes FCM_ERR_ALLOC
 * instead of an out-of-memory abort of the fuzzer; FCM_FUZZ_ALLOC_CAP_MB, default 64, 0 =
 * no cap), a per-process scratch directory removed at exit (in FCM_FUZZ_DIR, else /dev/shm,
 * else TMPDIR, else /tmp), and writing the input to a file in it (the readers take file
 * names). Every input must leave no live allocation behind, and every failure a message. */
#ifndef FCM_FUZZ_UTIL_H
#define FCM_FUZZ_UTIL_H

#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static size_t fuzz_cap_bytes_ = (size_t)64 << 20;
static char fuzz_dir_[4096];

static inline void *fuzz_alloc_(void *user, size_t size)
{
  (void)user;
  if (fuzz_cap_bytes_ && size > fuzz_cap_bytes_) return NULL;
  return malloc(size);
}

static inline void fuzz_release_(void *user, void *p)
{
  (void)user;
  free(p);
}

static inline void fuzz_remove_dir_(void)
{
  static const char *const names[] = {"in.msh", "in.node", "in.ele", "in.ckpt",
                                      "in.obj", "in.off",  "in.stl", "in.ply"};
  char path[sizeof fuzz_dir_ + 16];
  for (size_t k = 0; k < sizeof names / sizeof *names; k++) {
    snprintf(path, sizeof path, "%s/%s", fuzz_dir_, names[k]);
    unlink(path);
  }
  rmdir(fuzz_dir_);
}

/* A context with the capped allocator, created once per process (errors are recorded in
 * it and cleared per input). Also creates the scratch directory. Aborts on failure: the
 * harness cannot run without them. */
static inline fcm_ctx *fuzz_ctx(void)
{
  static fcm_ctx *ctx = NULL;
  if (ctx) return ctx;
  const char *cap = getenv("FCM_FUZZ_ALLOC_CAP_MB");
  if (cap && *cap) fuzz_cap_bytes_ = (size_t)strtoull(cap, NULL, 10) << 20;
  /* one thread unless asked otherwise: libFuzzer runs one input at a time */
  setenv("OMP_NUM_THREADS", "1", 0);
  setenv("OMP_WAIT_POLICY", "passive", 0);
  setenv("OPENBLAS_NUM_THREADS", "1", 0);
  /* scratch in memory when possible: file writes to a disk dominate the run time */
  const char *tmp = getenv("FCM_FUZZ_DIR");
  if (!tmp || !*tmp) tmp = access("/dev/shm", W_OK | X_OK) == 0 ? "/dev/shm" : getenv("TMPDIR");
  snprintf(fuzz_dir_, sizeof fuzz_dir_, "%s/fcm-fuzz-XXXXXX", tmp && *tmp ? tmp : "/tmp");
  if (!mkdtemp(fuzz_dir_)) {
    perror("fcm fuzz: mkdtemp");
    abort();
  }
  atexit(fuzz_remove_dir_);
  fcm_ctx_options o = fcm_ctx_options_default();
  o.allocator.alloc = fuzz_alloc_;
  o.allocator.release = fuzz_release_;
  if (fcm_ctx_create(&o, &ctx) != FCM_OK) abort();
  return ctx;
}

/* Write data[0, size) to <scratch>/name; the path is returned in a static buffer per name
 * slot (slot 0 or 1). */
static inline const char *fuzz_write_file(int slot, const char *name, const uint8_t *data,
                                          size_t size)
{
  static char path[2][sizeof fuzz_dir_ + 16];
  snprintf(path[slot], sizeof path[slot], "%s/%s", fuzz_dir_, name);
  FILE *f = fopen(path[slot], "wb");
  if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0) {
    perror("fcm fuzz: writing the input file");
    abort();
  }
  return path[slot];
}

/* Every object created for an input must be destroyed again (a leak through the ctx
 * allocator that LeakSanitizer would not see as such, since the ctx lives on). */
static inline void fuzz_check_no_live(fcm_ctx *ctx, long long before)
{
  if (fcm_ctx_live_allocations(ctx) != before) {
    fprintf(stderr, "fcm fuzz: %lld allocation(s) left live after the input\n",
            fcm_ctx_live_allocations(ctx) - before);
    abort();
  }
  fcm_ctx_error_clear(ctx);
}

/* A failure must come with a message in the context (errors are never silent). With
 * FCM_FUZZ_VERBOSE set, print the outcome (to see why a seed is refused). */
static inline void fuzz_check_status(fcm_ctx *ctx, fcm_status st)
{
  if (getenv("FCM_FUZZ_VERBOSE"))
    fprintf(stderr, "fcm fuzz: %s %s\n", fcm_status_name(st), fcm_ctx_error_message(ctx));
  if (st != FCM_OK && (fcm_ctx_error_status(ctx) != st || !fcm_ctx_error_message(ctx)[0])) {
    fprintf(stderr, "fcm fuzz: %s returned without a matching message in the context\n",
            fcm_status_name(st));
    abort();
  }
}

#endif
