/* Allocation failures in the CSR constructors the other loops do not cover: fcm_csr_create
 * (pattern copied) and fcm_csr_wrap (only the handle). Failing the k-th allocation until
 * success gives FCM_ERR_ALLOC, a NULL matrix and no leak; the wrapped arrays are untouched. */
#include "fcm/la.h"
#include "alloc_loop.h"

typedef struct fixture {
  fcm_ctx *ctx;
  fcm_csr *A;
  fcm_index rp[4];
  int ci[7];
  double v[7];
} fixture;

static fcm_status create(void *u)
{
  fixture *x = u;
  x->A = (fcm_csr *)x;
  fcm_status st = fcm_csr_create(x->ctx, 3, 3, x->rp, x->ci, FCM_CSR_SYMMETRIC, &x->A);
  return st != FCM_OK && x->A ? FCM_ERR_INTERNAL : st;
}
static fcm_status wrap(void *u)
{
  fixture *x = u;
  x->A = (fcm_csr *)x;
  fcm_status st = fcm_csr_wrap(x->ctx, 3, 3, x->rp, x->ci, x->v, FCM_CSR_SYMMETRIC, &x->A);
  return st != FCM_OK && x->A ? FCM_ERR_INTERNAL : st;
}
static void release(void *u)
{
  fixture *x = u;
  fcm_csr_destroy(&x->A);
}

int main(void)
{
  failing f;
  static fixture x = {NULL, NULL, {0, 2, 5, 7}, {0, 1, 0, 1, 2, 1, 2}, {4, -1, -1, 4, -1, -1, 4}};
  x.ctx = failing_ctx(&f);
  TEST_TRUE(x.ctx != NULL);
  if (!x.ctx) return TEST_RESULT();
  alloc_loop(x.ctx, &f, "fcm_csr_create", create, release, &x, 3, 100);
  alloc_loop(x.ctx, &f, "fcm_csr_wrap", wrap, release, &x, 1, 100);
  TEST_TRUE(x.v[0] == 4 && x.v[6] == 4 && x.rp[3] == 7 && x.ci[6] == 2);
  TEST_TRUE(fcm_ctx_live_allocations(x.ctx) == 0);
  fcm_ctx_destroy(&x.ctx);
  return TEST_RESULT();
}
