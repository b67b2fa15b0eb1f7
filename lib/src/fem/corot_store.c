/* The element-corotated linear model's store of element matrices: each element's linear
 * stiffness K_e = int B^T D B on its own rule (a cut cell's piece rule with its fictitious
 * points, as the linear stiffness assembly integrates it) and its shape functions' mean
 * gradients over its material (corot.c), built once and kept in the
 * assembly workspace; a cut's workspace takes the matrices of the elements the cut leaves as
 * they were from the workspace before the cut and builds only the others. */
#include "fem/assemble_impl.h"

#include <omp.h>
#include <string.h>

void fcm__assembly_corot_free(fcm_assembly_workspace *ws)
{
  fcm__free_large(ws->ctx, ws->corot.K);
  fcm__free(ws->ctx, ws->corot.have);
  fcm__free_large(ws->ctx, ws->corot.G);
  ws->corot.G = NULL;
  ws->corot.K = NULL;
  ws->corot.have = NULL;
}

/* Allocate the store (nothing built): large arrays, with room for a cut's successor to take
 * them (fcm__assembly_corot_take()). */
static fcm_status store_alloc(fcm_assembly_workspace *ws)
{
  fcm_status st = FCM_OK;
  const fcm_space *s = ws->space;
  corot_store *c = &ws->corot;
  c->cb = 9 * (size_t)s->nn * (size_t)(s->nn + 1) / 2;
  FCM__ALLOC_WITH(fcm__calloc_large, ws->ctx, (size_t)s->num_elems * c->cb + 1, c->K);
  FCM__ALLOC_WITH(fcm__calloc_large, ws->ctx, (size_t)s->num_elems * 3 * s->nn + 1, c->G);
  FCM_ALLOC(ws->ctx, (size_t)s->num_elems + 1, c->have);
cleanup:
  return st;
}

/* Build the missing element matrices in parallel (each element writes its own slot). */
static fcm_status store_build(fcm_assembly_workspace *ws, const tabulation *t)
{
  fcm_status st = FCM_OK;
  const fcm_space *s = ws->space;
  corot_store *c = &ws->corot;
  kernel_data kd;
  memset(&kd, 0, sizeof kd);
  kd.kind = KERNEL_STIFFNESS;
  kd.lambda = c->lambda;
  kd.mu = c->mu;
  fcm_index bad = -1, built = 0;
  double bad_det = 1.0;
#pragma omp parallel num_threads(ws->nthreads) reduction(+ : built)
  {
    scratch *w = ws->sc + omp_get_thread_num();
#pragma omp for schedule(dynamic, 64)
    for (fcm_index e = 0; e < s->num_elems; e++) {
      if (c->have[e]) continue;
      cell_result res = fcm__assembly_element_kernel(s, t, &kd, e, w);
      if (!(res.bad_det > 0.0)) {
#pragma omp critical(fcm_corot_bad)
        if (bad < 0 || e < bad) bad = e, bad_det = res.bad_det;
        continue;
      }
      memcpy(c->K + (size_t)e * c->cb, w->Ke, sizeof(double) * c->cb);
      fcm__assembly_mean_gradients(s, t, e, w, c->G + (size_t)e * 3 * s->nn);
      c->have[e] = 1;
      built++;
    }
  }
  c->built += built;
  FCM_CHECK(bad < 0, ws->ctx, FCM_ERR_GEOMETRY,
            "assembly: cell %lld has det J = %g <= 0 at a quadrature point (inverted or "
            "degenerate %s)",
            (long long)s->elem_cell[bad], bad_det, fcm_element_get_info(s->type)->name);
cleanup:
  return st;
}

fcm_status fcm__assembly_corot_prepare(fcm_assembly_workspace *ws, const fcm_material_params *mat,
                                       kernel_data *kd)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws->ctx;
  corot_store *c = &ws->corot;
  const tabulation *t = NULL;
  FCM_CHECK(isfinite(mat->lambda) && isfinite(mat->mu) && mat->mu > 0.0, ctx, FCM_ERR_ARG,
            "corotated_linear: Lame parameters lambda = %g, mu = %g (mu must be positive and "
            "both finite; use fcm_material_setup())",
            mat->lambda, mat->mu);
  FCM_TRY(ctx, fcm__assembly_tabulation(ws, FCM_RULE_STIFFNESS, &t));
  if (!c->K) FCM_TRY(ctx, store_alloc(ws));
  if (c->lambda != mat->lambda || c->mu != mat->mu) { /* other parameters: rebuild all */
    memset(c->have, 0, (size_t)ws->space->num_elems);
    c->lambda = mat->lambda;
    c->mu = mat->mu;
  }
  FCM_TRY(ctx, store_build(ws, t));
  kd->corot_K = c->K;
  kd->corot_cb = c->cb;
  kd->corot_G = c->G;
cleanup:
  return st;
}

fcm_status fcm__assembly_corot_inherit(fcm_assembly_workspace *ws,
                                       const fcm_assembly_workspace *old, const fcm_index *same)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws ? ws->ctx : NULL;
  FCM_CHECK(ws && old && same, ctx, FCM_ERR_ARG, "corotated_linear: NULL workspace or map");
  const corot_store *o = &old->corot;
  if (!o->K || ws->space->nn != old->space->nn) return FCM_OK; /* nothing kept to take */
  corot_store *c = &ws->corot;
  if (!c->K) FCM_TRY(ctx, store_alloc(ws));
  c->lambda = o->lambda;
  c->mu = o->mu;
  const size_t g = 3 * (size_t)ws->space->nn;
  for (fcm_index e = 0; e < ws->space->num_elems; e++) {
    const fcm_index f = same[e];
    c->have[e] = f >= 0 && o->have[f];
    if (!c->have[e]) continue;
    memcpy(c->K + (size_t)e * c->cb, o->K + (size_t)f * o->cb, sizeof(double) * c->cb);
    memcpy(c->G + (size_t)e * g, o->G + (size_t)f * g, sizeof(double) * g);
  }
cleanup:
  return st;
}

fcm_status fcm__assembly_corot_take(fcm_assembly_workspace *ws, fcm_assembly_workspace *old,
                                    const fcm_index *same)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws ? ws->ctx : NULL;
  FCM_CHECK(ws && old && same, ctx, FCM_ERR_ARG, "corotated_linear: NULL workspace or map");
  corot_store *o = &old->corot, *c = &ws->corot;
  const fcm_index ne = ws->space->num_elems;
  const size_t g = 3 * (size_t)ws->space->nn;
  int in_order = o->K && !c->K && ws->space->nn == old->space->nn;
  for (fcm_index e = 0, last = -1; in_order && e < ne; e++) {
    const fcm_index f = same[e];
    if (f < 0 || !o->have[f]) continue;
    in_order = f <= e && f > last; /* moved up only, so that a pass downwards moves each once */
    last = f;
  }
  void *kf = in_order ? o->K : NULL, *gf = o->G;
  double *K = fcm__large_take(&kf, (size_t)ne * o->cb + 1, sizeof *K), *G = NULL;
  if (!K) return fcm__assembly_corot_inherit(ws, old, same); /* nothing taken */
  FCM_ALLOC(ctx, (size_t)ne + 1, c->have);
  G = fcm__large_take(&gf, (size_t)ne * g + 1, sizeof *G); /* else copied into a new one */
  if (!G) FCM__ALLOC_WITH(fcm__calloc_large, ctx, (size_t)ne * g + 1, G);
  const double *Gf = gf ? o->G : G; /* where the kept mean gradients are */
  c->K = K, c->G = G, o->K = NULL;
  if (!gf) o->G = NULL;
  c->cb = o->cb;
  c->lambda = o->lambda;
  c->mu = o->mu;
  for (fcm_index e = ne - 1; e >= 0; e--) {
    const fcm_index f = same[e];
    c->have[e] = f >= 0 && o->have[f];
    if (!c->have[e]) continue;
    if (f != e) memcpy(K + (size_t)e * c->cb, K + (size_t)f * c->cb, sizeof(double) * c->cb);
    if (f != e || Gf != G) memcpy(G + (size_t)e * g, Gf + (size_t)f * g, sizeof(double) * g);
  }
cleanup:
  return st;
}

void fcm__assembly_corot_give_back(fcm_assembly_workspace *ws, fcm_assembly_workspace *old)
{
  corot_store *c = &ws->corot, *o = &old->corot;
  if (!c->K || o->K || !o->have) return; /* old's store is its own (nothing taken) */
  o->K = c->K, c->K = NULL;
  if (!o->G) o->G = c->G, c->G = NULL; /* else old's mean gradients were copied, not moved */
  memset(o->have, 0, (size_t)old->space->num_elems);
}

fcm_index fcm__assembly_corot_built(const fcm_assembly_workspace *ws)
{
  return ws->corot.built;
}
