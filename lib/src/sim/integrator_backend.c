/* sim module: the integrator's side of a solver backend (fcm__backend, fem/fem_backend.h):
 * the serial backend every integrator starts with, attaching a distributed one, and the sums
 * and agreements the integrator and its callers make through it (sim/sim_backend.h). */
#include "sim/sim_impl.h"

#include <string.h>

/* The serial backend's reduce: one process holds the whole sum, and its status is everyone's. */
static fcm_status serial_reduce(void *user, fcm_status st, double *values, fcm_index count)
{
  (void)user;
  (void)values;
  (void)count;
  return st;
}

static fcm_status serial_setup(void *user, fcm_status st, const fcm_space *space,
                               fcm__backend *out);

/* The serial backend: one process (the root, rank 0 of 1) owning every DOF; no factor and
 * solve of its own: the integrator's options choose its serial solver (linsolve.c). */
static void serial_backend(fcm__backend *b, const unsigned char *owned)
{
  memset(b, 0, sizeof *b);
  b->root = 1;
  b->rank = 0;
  b->nprocs = 1;
  b->owned = owned;
  b->reduce = serial_reduce;
  b->setup = serial_setup;
}

/* A cut's new integrator keeps the serial backend it starts with (fcm__integrator_set_backend()
 * takes this one as set). */
static fcm_status serial_setup(void *user, fcm_status st, const fcm_space *space, fcm__backend *out)
{
  (void)user;
  (void)space;
  serial_backend(out, NULL);
  return st;
}

static int is_serial(const fcm__backend *b)
{
  return b->reduce == serial_reduce;
}

/* The status a reduce returned from `in`: a failure is traced where the reduce reports it (a
 * distributed backend's agreed one, also this process's own; the serial backend only hands
 * the caller's own back, traced where it arose). */
static fcm_status reduced(fcm_integrator *I, fcm_status in, fcm_status st)
{
  if (st != FCM_OK && (st != in || !is_serial(&I->backend)))
    fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return st;
}

fcm_status fcm__sim_serial_backend(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  FCM_ALLOC(I->ctx, (size_t)I->n + 1, I->owned);
  memset(I->owned, 1, (size_t)I->n + 1);
  serial_backend(&I->backend, I->owned);
cleanup:
  return st;
}

fcm_status fcm__integrator_set_backend(fcm_integrator *I, const fcm__backend *b)
{
  fcm_status st = FCM_OK;
  if (!I || !b) {
    if (b && b->destroy) b->destroy(b->user);
    FCM_CHECK(0, I ? I->ctx : NULL, FCM_ERR_ARG, "integrator: NULL integrator or backend");
  }
  if (is_serial(b)) return FCM_OK; /* the one every integrator starts with */
  if (I->is_setup || !is_serial(&I->backend) || !b->reduce || !b->factor || !b->solve ||
      !b->owned) {
    if (b->destroy) b->destroy(b->user);
    FCM_CHECK(0, I->ctx, FCM_ERR_ARG,
              "integrator: a backend needs reduce, factor, solve and the owned DOFs, and is set "
              "once, before fcm_integrator_setup()");
  }
  memcpy(I->owned, b->owned, (size_t)I->n);
  I->backend = *b;
  I->backend.owned = I->owned;
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
  return I && !is_serial(&I->backend) ? &I->backend : NULL;
}

int fcm__integrator_distributed(const fcm_integrator *I, int *root)
{
  if (root) *root = I ? I->backend.root : 1;
  return I && !is_serial(&I->backend);
}

void fcm__integrator_processes(const fcm_integrator *I, int *rank, int *nprocs)
{
  *rank = I ? I->backend.rank : 0;
  *nprocs = I ? I->backend.nprocs : 1;
}

fcm_status fcm__integrator_reduce(fcm_integrator *I, double *values, fcm_index count)
{
  return fcm__integrator_reduce_status(I, FCM_OK, values, count);
}

fcm_status fcm__integrator_reduce_status(fcm_integrator *I, fcm_status st, double *values,
                                         fcm_index count)
{
  if (!I) return st;
  return reduced(I, st, I->backend.reduce(I->backend.user, st, values, count));
}

fcm_status fcm__integrator_finish(fcm_integrator *I, fcm_status st)
{
  if (!I || !I->backend.finish) return st;
  st = I->backend.finish(I->backend.user, st);
  if (st != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return st;
}

fcm_status fcm__sim_reduce(fcm_integrator *I, fcm_status st, double *scalars, int ns, double *vec)
{
  const fcm__backend *b = &I->backend;
  fcm_status out = b->reduce(b->user, st, scalars, ns);
  if (out == FCM_OK && vec) out = b->reduce(b->user, FCM_OK, vec, I->n);
  return reduced(I, st, out);
}
