/* Concurrency: eight cells simplified at once from OpenMP threads (both paths, one with a
 * forced GLPK fatal error in the middle) give exactly the results of serial calls: GLPK's
 * environment is per thread and fcm keeps no global state. */
#include "simplify/simplify_impl.h"
#include "simplify_util.h"

#include <omp.h>

enum { CELLS = 8 };

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  const int m = 4, M = util_num_basis(m), n = 12 * M;
  double *pts = malloc(3 * (size_t)n * CELLS * sizeof *pts);
  double *w = malloc((size_t)n * CELLS * sizeof *w);
  fcm_simplify_result serial[CELLS], parallel[CELLS];
  fcm_status st[CELLS];
  for (int c = 0; c < CELLS; c++) {
    const double lo[3] = {-1.0 + 0.1 * c, -1.0, -0.5};
    util_random_box(40 + (uint64_t)c, n, lo, 1.0, 1.0, pts + 3 * (size_t)n * c, w + (size_t)n * c);
  }
  /* Cell c uses the LP path when c is even; cell 5 is forced into a GLPK fatal error. */
  for (int pass = 0; pass < 2; pass++) {
    fcm_simplify_result *out = pass ? parallel : serial;
#pragma omp parallel for schedule(dynamic, 1) num_threads(pass ? 4 : 1)
    for (int c = 0; c < CELLS; c++) {
      fcm_simplify_options o = fcm_simplify_options_default();
      o.method = c % 2 ? FCM_SIMPLIFY_RECOMBINE : FCM_SIMPLIFY_LP;
      st[c] = fcm__simplify_hooked(ctx, m, n, pts + 3 * (size_t)n * c, w + (size_t)n * c, &o,
                                   c == 5 ? 2 : 0, &out[c], NULL);
    }
    for (int c = 0; c < CELLS; c++)
      TEST_TRUE(st[c] == FCM_OK);
  }
  for (int c = 0; c < CELLS; c++) {
    TEST_TRUE(serial[c].count == parallel[c].count);
    TEST_TRUE(c != 5 || serial[c].count == n); /* the forced cell fell back */
    for (int k = 0; k < serial[c].count && k < parallel[c].count; k++)
      TEST_TRUE(serial[c].indices[k] == parallel[c].indices[k] &&
                serial[c].weights[k] == parallel[c].weights[k]);
    if (c != 5)
      util_check("parallel", m, n, pts + 3 * (size_t)n * c, w + (size_t)n * c, &parallel[c], M,
                 1e-12);
    fcm_simplify_result_destroy(&serial[c]);
    fcm_simplify_result_destroy(&parallel[c]);
  }
  free(pts);
  free(w);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
