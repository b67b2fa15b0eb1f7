/* Allocation failures in the multigrid: failing the k-th allocation for k = 0, 1, ... of
 * building the hierarchy (cut hemisphere on Hex8 and Hex20 grids: pieces, links, the grown
 * cell graph, the p-level, the block smoother; the hemisphere on a Hex8 octree: the coarser
 * octrees, their spaces and constraints, the nested prolongations), the Galerkin
 * patterns, the level info, a CG + MG solve, and a hierarchy created from another
 * (fcm__mg_create_from() on Hex8, keeping everything, then detached) gives FCM_ERR_ALLOC and
 * leaks nothing, until
 * everything succeeds. */
#include "mg/mg_impl.h"
#include "mg_util.h"
#include "alloc_loop.h"

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

/* A hierarchy created from another on the same space and matrix (keeping every part), then
 * from that one detached. */
static fcm_status run_from(fcm_ctx *ctx, problem *p)
{
  fcm_status st = FCM_OK;
  fcm_mg *old = NULL, *mg = NULL;
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 10;
  if ((st = fcm_mg_create(ctx, p->space, p->A, &o, &old))) goto done;
  if ((st = fcm__mg_create_from(ctx, &old, p->space, p->A, &o, &mg))) goto done;
  if (old) st = FCM_ERR_INTERNAL;
  old = mg, mg = NULL;
  fcm__mg_detach(old);
  if ((st = fcm__mg_create_from(ctx, &old, p->space, p->A, &o, &mg))) goto done;
done:
  fcm_mg_destroy(&old);
  fcm_mg_destroy(&mg);
  return st;
}

typedef struct mg_round {
  fcm_ctx *ctx;
  problem *p;
  double *x;
} mg_round;

static fcm_status run_round(void *user)
{
  mg_round *r = user;
  return run(r->ctx, r->p, r->x);
}

static fcm_status run_from_round(void *user)
{
  mg_round *r = user;
  return run_from(r->ctx, r->p);
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
    mg_round r = {ctx, &p, x};
    /* at least 40 failing rounds: the loop did exercise the builders */
    alloc_loop(ctx, &fl, t ? "hex20 hierarchy" : "hex8 hierarchy", run_round, NULL, &r, 40,
               1000000);
    free(x);
    problem_free(&p);
  }
  {
    /* a smaller Hex8 hemisphere: each round builds three hierarchies (the parts kept are the
     * same kinds on Hex20) */
    problem p;
    problem_hemisphere_of(ctx0, FCM_ELEMENT_HEX8, 4, 1, fcm_space_options_default().constrain_ratio,
                          &p);
    mg_round r = {ctx, &p, NULL};
    alloc_loop(ctx, &fl, "hex8 hierarchy from another", run_from_round, NULL, &r, 40, 1000000);
    problem_free(&p);
  }
  {
    oct_problem op;
    oct_problem_create(ctx0, FCM_ELEMENT_HEX8, 4, 2, &op);
    problem p = {.space = op.space, .A = op.A, .b = op.b, .n = op.n};
    double *x = calloc((size_t)p.n, sizeof *x);
    mg_round r = {ctx, &p, x};
    alloc_loop(ctx, &fl, "octree hierarchy", run_round, NULL, &r, 40, 1000000);
    free(x);
    oct_free(&op);
  }
  fcm_ctx_destroy(&ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx0) == 0);
  fcm_ctx_destroy(&ctx0);
  return TEST_RESULT();
}
