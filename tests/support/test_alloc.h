/* Shared test helpers: a reproducible random generator and a failing allocator
 * for allocation-failure loops (fail the k-th allocation, k = 0, 1, 2, ...). */
#ifndef FCM_TEST_ALLOC_H
#define FCM_TEST_ALLOC_H

#include "fcm/core.h"

#include <stdint.h>
#include <stdlib.h>

/* xorshift64*: uniform doubles in [-1, 1). */
typedef struct rng {
  uint64_t s;
} rng;

static inline double rng_uniform(rng *r)
{
  r->s ^= r->s >> 12;
  r->s ^= r->s << 25;
  r->s ^= r->s >> 27;
  uint64_t x = r->s * 2685821657736338717ULL;
  return (double)(x >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

/* Allocator counting its calls and failing call number fail_at (0-based after
 * count was reset); fail_at = -1: never. */
typedef struct failing {
  long long count, fail_at;
} failing;

static inline void *failing_alloc(void *user, size_t size)
{
  failing *f = user;
  long long k = f->count++;
  if (f->fail_at >= 0 && k == f->fail_at) return NULL;
  return malloc(size);
}

static inline void failing_release(void *user, void *p)
{
  (void)user;
  free(p);
}

/* failing_alloc() for allocations from several threads: the count taken atomically, so that
 * exactly one allocation, whichever thread makes it, is the fail_at-th. */
static inline void *failing_alloc_atomic(void *user, size_t size)
{
  failing *f = user;
  const long long k = __atomic_fetch_add(&f->count, 1, __ATOMIC_RELAXED);
  if (f->fail_at >= 0 && k == f->fail_at) return NULL;
  return malloc(size);
}

/* A context whose allocator is `f` through `alloc` (failing_alloc or failing_alloc_atomic;
 * f->fail_at = -1 until the loop arms it). */
static inline fcm_ctx *failing_ctx_with(failing *f, void *(*alloc)(void *, size_t))
{
  fcm_ctx_options o = fcm_ctx_options_default();
  o.allocator.alloc = alloc;
  o.allocator.release = failing_release;
  o.allocator.user = f;
  f->count = 0;
  f->fail_at = -1;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(&o, &ctx) != FCM_OK) return NULL;
  return ctx;
}

/* A context whose allocator is `f` (f->fail_at = -1 until the loop arms it). */
static inline fcm_ctx *failing_ctx(failing *f)
{
  return failing_ctx_with(f, failing_alloc);
}

#endif
