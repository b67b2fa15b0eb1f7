/* sim module: the integrator's side of a distributed solver backend (fcm__backend,
 * fem/fem_backend.h): attaching it, and the sums and agreements the integrator and its
 * callers make through it (sim/sim_backend.h). */
#include "sim/sim_impl.h"

#include <string.h>

fcm_status fcm__integrator_set_backend(fcm_integrator *I, const fcm__backend *b)
{
  fcm_status st = FCM_OK;
  if (!I || !b) {
    if (b && b->destroy) b->destroy(b->user);
    FCM_CHECK(0, I ? I->ctx : NULL, FCM_ERR_ARG, "integrator: NULL integrator or backend");
  }
  if (I->is_setup || I->has_backend || !b->reduce || !b->factor || !b->solve || !b->owned) {
    if (b->destroy) b->destroy(b->user);
    FCM_CHECK(0, I->ctx, FCM_ERR_ARG,
              "integrator: a backend needs reduce, factor, solve and the owned DOFs, and is set "
              "once, before fcm_integrator_setup()");
  }
  I->owned = fcm__calloc(I->ctx, (size_t)I->n + 1, 1);
  if (!I->owned) {
    if (b->destroy) b->destroy(b->user);
    FCM_CHECK(0, I->ctx, FCM_ERR_ALLOC, "integrator: out of memory (%lld owned flags)",
              (long long)I->n);
  }
  memcpy(I->owned, b->owned, (size_t)I->n);
  I->backend = *b;
  I->backend.owned = I->owned;
  I->has_backend = 1;
cleanup:
  return st;
}

fcm_status fcm__integrator_attach_backend(fcm_integrator *I, const fcm__backend *from)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I ? I->ctx : NULL;
  FCM_CHECK(I && from && from->setup, ctx, FCM_ERR_ARG,
            "integrator: NULL integrator, or a backend without a setup operation");
  fcm__backend b;
  memset(&b, 0, sizeof b);
  FCM_TRY(ctx, from->setup(from->user, FCM_OK, I->space, &b));
  FCM_TRY(ctx, fcm__integrator_set_backend(I, &b));
cleanup:
  return st;
}

const fcm__backend *fcm__integrator_backend(const fcm_integrator *I)
{
  return I && I->has_backend ? &I->backend : NULL;
}

int fcm__integrator_distributed(const fcm_integrator *I, int *root)
{
  const int dist = I && I->has_backend;
  if (root) *root = dist ? I->backend.root : 1;
  return dist;
}

void fcm__integrator_processes(const fcm_integrator *I, int *rank, int *nprocs)
{
  const int dist = I && I->has_backend;
  *rank = dist ? I->backend.rank : 0;
  *nprocs = dist ? I->backend.nprocs : 1;
}

fcm_status fcm__integrator_reduce(fcm_integrator *I, double *values, fcm_index count)
{
  return fcm__integrator_reduce_status(I, FCM_OK, values, count);
}

fcm_status fcm__integrator_reduce_status(fcm_integrator *I, fcm_status st, double *values,
                                         fcm_index count)
{
  if (!I || !I->has_backend) return st;
  st = I->backend.reduce(I->backend.user, st, values, count);
  if (st != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return st;
}

fcm_status fcm__integrator_finish(fcm_integrator *I, fcm_status st)
{
  if (!I || !I->has_backend || !I->backend.finish) return st;
  st = I->backend.finish(I->backend.user, st);
  if (st != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return st;
}

fcm_status fcm__sim_reduce(fcm_integrator *I, fcm_status st, double *scalars, int ns, double *vec)
{
  if (!I->has_backend) return st;
  const fcm__backend *b = &I->backend;
  st = b->reduce(b->user, st, scalars, ns);
  if (st == FCM_OK && vec) st = b->reduce(b->user, FCM_OK, vec, I->n);
  if (st != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return st;
}
