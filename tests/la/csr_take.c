/* A matrix on a shared pattern takes another's values storage (fcm__csr_share_pattern_from())
 * when it fits: a large array (8 MiB or more) has a quarter more room than asked, so a matrix
 * up to that size, and at least half of it, lands on the same storage, zero filled again, and
 * the giver is left without values; a larger or a much smaller matrix gets storage of its own
 * and the giver keeps its values. The context counts one allocation per array throughout. A
 * matrix's room mapped (fcm__csr_map_room(), for an integrator whose storage a cut takes): its
 * last page is resident before anything writes it, and its values are kept. */
#define _DEFAULT_SOURCE /* mincore */
#include "la/la_impl.h"
#include "test.h"

#include <stdint.h>
#include <stdlib.h>
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

enum { NBIG = 1100000 }; /* 8.8 MB of values: room for 1,375,000 */

static fcm_ctx *ctx;
static fcm_index *rp;
static int *ci;

/* The diagonal matrix of order n on the shared pattern (rp, ci), given give's storage. */
static fcm_csr *diagonal(fcm_index n, fcm_csr *give)
{
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm__csr_share_pattern_from(ctx, n, n, rp, ci, FCM_CSR_SYMMETRIC, give, &A));
  return A;
}

/* Values zero, then diag(1, ..., n); y = A 1 exact. */
static void check_values(fcm_csr *A, fcm_index n)
{
  double *v = fcm_csr_values(A);
  int zero = 1;
  for (fcm_index i = 0; i < n; i++) {
    zero &= v[i] == 0.0;
    v[i] = (double)(i + 1);
  }
  TEST_TRUE(zero);
  double *one = malloc((size_t)n * sizeof *one), *y = malloc((size_t)n * sizeof *y);
  for (fcm_index i = 0; i < n; i++)
    one[i] = 1.0, y[i] = -1.0;
  TEST_OK(ctx, fcm_csr_apply(A, 1.0, one, 0.0, y));
  int exact = 1;
  for (fcm_index i = 0; i < n; i++)
    exact &= y[i] == (double)(i + 1);
  TEST_TRUE(exact);
  free(one);
  free(y);
}

/* 1 when the page holding the last byte of the room of n values at v (a quarter more than n
 * from FCM__LARGE_MIN on) is resident; 1 where residency cannot be asked. */
static int room_resident(const double *v, size_t n)
{
#if defined(__linux__)
  const size_t bytes = n * sizeof *v, room = bytes >= FCM__LARGE_MIN ? bytes + bytes / 4 : bytes;
  const uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE);
  const uintptr_t last = ((uintptr_t)v + room - 1) / page * page;
  unsigned char in = 0;
  if (mincore((void *)last, (size_t)page, &in) != 0) return 1;
  return in & 1;
#else
  (void)v, (void)n;
  return 1;
#endif
}

int main(void)
{
  const fcm_index nmax = 2 * NBIG;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rp = malloc((size_t)(nmax + 1) * sizeof *rp);
  ci = malloc((size_t)nmax * sizeof *ci);
  for (fcm_index i = 0; i <= nmax; i++)
    rp[i] = i;
  for (fcm_index i = 0; i < nmax; i++)
    ci[i] = (int)i;
  const long long live0 = fcm_ctx_live_allocations(ctx);

  /* 10 % larger: taken, zero again, the giver without values */
  fcm_csr *A = diagonal(NBIG, NULL);
  fcm__csr_map_room(A);
  TEST_TRUE(room_resident(fcm_csr_values_read(A), NBIG));
  check_values(A, NBIG); /* zero after the mapping, then 1 .. n */
  fcm__csr_map_room(A);  /* once per array: the values stay */
  int same = 1;
  for (fcm_index i = 0; i < NBIG; i++)
    same &= fcm_csr_values_read(A)[i] == (double)(i + 1);
  TEST_TRUE(same);
  const double *va = fcm_csr_values_read(A);
  const fcm_index n1 = NBIG + NBIG / 10;
  fcm_csr *B = diagonal(n1, A);
  TEST_TRUE(fcm_csr_values_read(B) == va && fcm_csr_values_read(A) == NULL);
  check_values(B, n1);
  fcm_csr_destroy(&A);                                   /* a giver can be destroyed */
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == live0 + 2); /* B's handle and values */

  /* B's room is A's (1,375,000): a matrix of 1,400,000 does not fit, B keeps its values */
  const double *vb = fcm_csr_values_read(B);
  fcm_csr *C = diagonal(1400000, B);
  TEST_TRUE(fcm_csr_values_read(C) != vb && fcm_csr_values_read(B) == vb);
  check_values(C, 1400000);
  /* a matrix of less than half of C's room (1,750,000) gets its own */
  const double *vc = fcm_csr_values_read(C);
  fcm_csr *D = diagonal(800000, C);
  TEST_TRUE(fcm_csr_values_read(D) != vc && fcm_csr_values_read(C) == vc);
  check_values(D, 800000);
  /* B's values unchanged by the refusals */
  int kept = 1;
  for (fcm_index i = 0; i < n1; i++)
    kept &= vb[i] == (double)(i + 1);
  TEST_TRUE(kept);
  /* a small matrix (no room beyond its size) gives nothing to a larger one */
  fcm_csr *S = diagonal(1000, NULL), *T = diagonal(1001, S);
  TEST_TRUE(fcm_csr_values_read(S) != NULL && fcm_csr_values_read(T) != fcm_csr_values_read(S));
  fcm_csr *U = diagonal(1000, S); /* the same size fits */
  TEST_TRUE(fcm_csr_values_read(S) == NULL);
  check_values(U, 1000);
  fcm_csr *list[] = {B, C, D, S, T, U};
  for (size_t k = 0; k < sizeof list / sizeof list[0]; k++)
    fcm_csr_destroy(&list[k]);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == live0);
  free(rp);
  free(ci);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
