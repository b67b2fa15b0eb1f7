/* Matrix values of 8 MiB and more start on a 2 MiB boundary (huge pages), smaller ones on a
 * 64-byte one; both are zeroed, usable over their whole length, counted by the context and
 * released to the allocator that made them (the test allocator's free() aborts on any other
 * pointer), and an allocation failure while creating a large matrix leaks nothing. */
#include "fcm/la.h"
#include "alloc_loop.h"

#include <stdint.h>
#include <stdlib.h>

enum { NBIG = 1200000 }; /* 9.6 MB of values */

typedef struct fixture {
  fcm_ctx *ctx;
  fcm_csr *A;
  fcm_index n;
  fcm_index *rp;
  int *ci;
} fixture;

static fcm_status create(void *u)
{
  fixture *x = u;
  x->A = (fcm_csr *)x;
  fcm_status st = fcm_csr_create(x->ctx, x->n, x->n, x->rp, x->ci, FCM_CSR_SYMMETRIC, &x->A);
  return st != FCM_OK && x->A ? FCM_ERR_INTERNAL : st;
}
static void release(void *u)
{
  fixture *x = u;
  fcm_csr_destroy(&x->A);
}

/* The diagonal matrix diag(1, 2, ..., n) of x's pattern: values zero on creation, y = A 1
 * exact. Returns the values' address. */
static uintptr_t check_diagonal(fixture *x)
{
  TEST_TRUE(create(x) == FCM_OK);
  if (!x->A) return 1;
  double *v = fcm_csr_values(x->A);
  const uintptr_t addr = (uintptr_t)v;
  int zero = 1;
  for (fcm_index i = 0; i < x->n; i++) {
    zero &= v[i] == 0.0;
    v[i] = (double)(i + 1);
  }
  TEST_TRUE(zero);
  double *one = malloc((size_t)x->n * sizeof *one), *y = malloc((size_t)x->n * sizeof *y);
  TEST_TRUE(one && y);
  if (one && y) {
    for (fcm_index i = 0; i < x->n; i++)
      one[i] = 1.0, y[i] = -1.0;
    TEST_TRUE(fcm_csr_apply(x->A, 1.0, one, 0.0, y) == FCM_OK);
    int exact = 1;
    for (fcm_index i = 0; i < x->n; i++)
      exact &= y[i] == (double)(i + 1);
    TEST_TRUE(exact);
  }
  free(one);
  free(y);
  TEST_TRUE(fcm_ctx_live_allocations(x->ctx) > 0);
  release(x);
  return addr;
}

int main(void)
{
  failing f;
  fixture x = {0};
  x.ctx = failing_ctx(&f);
  x.rp = malloc((NBIG + 1) * sizeof *x.rp);
  x.ci = malloc(NBIG * sizeof *x.ci);
  TEST_TRUE(x.ctx && x.rp && x.ci);
  if (!x.ctx || !x.rp || !x.ci) return TEST_RESULT();
  for (int i = 0; i <= NBIG; i++)
    x.rp[i] = i;
  for (int i = 0; i < NBIG; i++)
    x.ci[i] = i;

  x.n = NBIG;
  TEST_TRUE(check_diagonal(&x) % (2u << 20) == 0);
  x.n = 3;
  TEST_TRUE(check_diagonal(&x) % 64 == 0);
  TEST_TRUE(fcm_ctx_live_allocations(x.ctx) == 0);

  x.n = NBIG;
  alloc_loop(x.ctx, &f, "fcm_csr_create (large)", create, release, &x, 3, 100);
  TEST_TRUE(fcm_ctx_live_allocations(x.ctx) == 0);
  fcm_ctx_destroy(&x.ctx);
  free(x.rp);
  free(x.ci);
  return TEST_RESULT();
}
