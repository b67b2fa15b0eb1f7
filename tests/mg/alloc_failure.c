/* Allocation failures in the multigrid: failing the k-th allocation for k = 0, 1, ... of
 * building the hierarchy (cut hemisphere: pieces, links, the grown cell graph), the Galerkin
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

int main(void)
{
  omp_set_num_threads(1); /* the failing allocator counts calls in order */
  fcm_ctx *ctx0 = NULL, *ctx = NULL;
  TEST_OK(ctx0, fcm_ctx_create(NULL, &ctx0));
  problem p;
  problem_hemisphere(ctx0, 6, 1, &p);
  double *x = calloc((size_t)p.n, sizeof *x);
  failing fl = {0, -1};
  ctx = failing_ctx(&fl);
  TEST_TRUE(ctx != NULL);
  long long k;
  for (k = 0;; k++) {
    fl.count = 0;
    fl.fail_at = k;
    fcm_status st = run(ctx, &p, x);
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
  TEST_TRUE(k >= 40); /* the loop did exercise the builders */
  fcm_ctx_destroy(&ctx);
  free(x);
  problem_free(&p);
  TEST_TRUE(fcm_ctx_live_allocations(ctx0) == 0);
  fcm_ctx_destroy(&ctx0);
  return TEST_RESULT();
}
