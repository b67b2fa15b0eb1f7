/* Allocation failures in the multigrid: failing the k-th allocation for k = 0, 1, ... of
 * building the hierarchy (cut hemisphere on Hex8 and Hex20 grids: pieces, links, the grown
 * cell graph, the p-level, the block smoother), the Galerkin
 * patterns, the level info and a CG + MG solve gives FCM_ERR_ALLOC and leaks nothing, until
 * everything succeeds. */
#include "mg_util.h"
#include "test_alloc.h"

#include <omp.h>

static fcm_status run(fcm_ctx *ctx, problem *p, double *x)
{
  fcm_status st = FCM_OK;
  fcm_mg *mg = NULL;
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 10;
  if ((st = fcm_mg_create(ctx, p->space, p->A, &o, &mg))) goto done;
  fcm_mg_level_info li;
  if ((st = fcm_mg_get_level_info(mg, fcm_mg_num_levels(mg) - 1, &li))) goto done;
  memset(x, 0, sizeof *x * (size_t)p->n);
  if ((st = fcm_cg_solve(ctx, p->n, fcm_csr_operator, p->A, fcm_mg_operator, mg, p->b, x, NULL,
                         NULL)))
    goto done;
  if ((st = fcm_mg_setup(mg))) goto done;
done:
  fcm_mg_destroy(&mg);
  return st;
}

/* The failing-allocation loop on one problem; returns the number of failures survived. */
static long long loop(fcm_ctx *ctx, failing *fl, problem *p, double *x)
{
  long long k;
  for (k = 0;; k++) {
    fl->count = 0;
    fl->fail_at = k;
    fcm_status st = run(ctx, p, x);
    if (fcm_ctx_live_allocations(ctx) != 0)
      TEST_FAIL_("failing allocation %lld: %lld allocations leaked", k,
                 fcm_ctx_live_allocations(ctx));
    if (st == FCM_OK) break;
    if (st != FCM_ERR_ALLOC) {
      TEST_FAIL_("failing allocation %lld: %s (%s)", k, fcm_status_name(st),
                 fcm_ctx_error_message(ctx));
      break;
    }
    fcm_ctx_error_clear(ctx);
  }
  fl->fail_at = -1;
  return k;
}

int main(void)
{
  omp_set_num_threads(1); /* the failing allocator counts calls in order */
  fcm_ctx *ctx0 = NULL, *ctx = NULL;
  TEST_OK(ctx0, fcm_ctx_create(NULL, &ctx0));
  failing fl = {0, -1};
  ctx = failing_ctx(&fl);
  TEST_TRUE(ctx != NULL);
  /* Hex8 (pieces, links, the grown cell graph, the block smoother) and Hex20 (the p-level) */
  for (int t = 0; t < 2; t++) {
    problem p;
    problem_hemisphere_of(ctx0, t ? FCM_ELEMENT_HEX20 : FCM_ELEMENT_HEX8, t ? 4 : 6, 1,
                          fcm_space_options_default().constrain_ratio, &p);
    double *x = calloc((size_t)p.n, sizeof *x);
    TEST_TRUE(loop(ctx, &fl, &p, x) >= 40); /* the loop did exercise the builders */
    free(x);
    problem_free(&p);
  }
  fcm_ctx_destroy(&ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx0) == 0);
  fcm_ctx_destroy(&ctx0);
  return TEST_RESULT();
}
