/* Allocation-failure torture: with an allocator that fails the k-th allocation
 * (k = 0, 1, 2, ... until the call succeeds), fcm_simplify on both paths and on the
 * fallback path returns FCM_ERR_ALLOC (never a fallback rule), leaves the result empty
 * and frees everything it allocated. */
#include "simplify/simplify_impl.h"
#include "simplify_util.h"
#include "alloc_loop.h"

typedef struct simplify_case {
  fcm_ctx *ctx;
  int m, M, n, variant;
  const double *pts, *w;
} simplify_case;

/* One round: on success the fallback flag and (both paths) the rule are checked; a failure
 * leaves the result empty. */
static fcm_status simplify_round(void *user)
{
  simplify_case *c = user;
  fcm_simplify_options o = fcm_simplify_options_default();
  o.method = c->variant == 1 ? FCM_SIMPLIFY_RECOMBINE : FCM_SIMPLIFY_LP;
  fcm_simplify_result res;
  fcm_simplify_info info;
  fcm_status st =
      fcm__simplify_hooked(c->ctx, c->m, c->n, c->pts, c->w, &o, c->variant == 2, &res, &info);
  if (st == FCM_OK) {
    TEST_TRUE(info.fallback == (c->variant == 2));
    if (c->variant < 2) util_check("after failures", c->m, c->n, c->pts, c->w, &res, c->M, 1e-12);
    fcm_simplify_result_destroy(&res);
  } else if (res.count != 0 || res.indices != NULL || res.weights != NULL) {
    return FCM_ERR_INTERNAL;
  }
  return st;
}

int main(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return TEST_RESULT();

  const int m = 2, M = util_num_basis(m), n = 9 * M; /* two recombination rounds */
  const double lo[3] = {-1, -1, -1};
  double *pts = malloc(3 * (size_t)n * sizeof *pts), *w = malloc((size_t)n * sizeof *w);
  util_random_box(5, n, lo, 2.0, 1.0, pts, w);

  simplify_case c = {ctx, m, M, n, 0, pts, w};
  for (int variant = 0; variant < 3; variant++) {
    char name[32];
    snprintf(name, sizeof name, "variant %d", variant);
    c.variant = variant;
    const long failures = alloc_loop(ctx, &f, name, simplify_round, NULL, &c, 8, 2000);
    if (getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr, "variant %d: %ld failing allocations\n", variant, failures);
  }
  free(pts);
  free(w);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
