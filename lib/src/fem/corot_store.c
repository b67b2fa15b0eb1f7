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
  fcm__free(ws->ctx, ws->corot.slot);
  ws->corot.G = NULL;
  ws->corot.K = NULL;
  ws->corot.have = NULL;
  ws->corot.slot = NULL;
  ws->corot.cap = 0;
}

/* A new store, each element at its own slot, with a quarter more slots for the elements of
 * later cuts (fcm__assembly_corot_take()). A slot is read only once its element's matrix is
 * built there (have), so the arrays are not zero filled: the slots no element uses are
 * address space only (fcm__assembly_corot_map() maps them). */
static fcm_status store_alloc(fcm_assembly_workspace *ws)
{
  fcm_status st = FCM_OK;
  const fcm_space *s = ws->space;
  corot_store *c = &ws->corot;
  const fcm_index ne = s->num_elems;
  c->cb = 9 * (size_t)s->nn * (size_t)(s->nn + 1) / 2;
  c->cap = ne + ne / 4 + 1;
  FCM__ALLOC_WITH(fcm__malloc_large, ws->ctx, (size_t)c->cap * c->cb, c->K);
  FCM__ALLOC_WITH(fcm__malloc_large, ws->ctx, (size_t)c->cap * 3 * s->nn, c->G);
  FCM_ALLOC(ws->ctx, (size_t)ne + 1, c->have);
  FCM_ALLOC_RAW(ws->ctx, (size_t)ne + 1, c->slot);
  for (fcm_index e = 0; e < ne; e++)
    c->slot[e] = e;
cleanup:
  return st;
}

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
      memcpy(c->K + (size_t)c->slot[e] * c->cb, w->Ke, sizeof(double) * c->cb);
      fcm__assembly_mean_gradients(s, t, e, w, c->G + (size_t)c->slot[e] * 3 * s->nn);
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
  kd->corot_slot = c->slot;
cleanup:
  return st;
}

fcm_status fcm__assembly_corot_build(fcm_assembly_workspace *ws, const fcm_material_params *mat)
{
  kernel_data kd;
  return fcm__assembly_corot_prepare(ws, mat, &kd);
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
    memcpy(c->K + (size_t)c->slot[e] * c->cb, o->K + (size_t)o->slot[f] * o->cb,
           sizeof(double) * c->cb);
    memcpy(c->G + (size_t)c->slot[e] * g, o->G + (size_t)o->slot[f] * g, sizeof(double) * g);
  }
cleanup:
  return st;
}

/* The slots of ws's elements in old's store: a kept element (same[e] >= 0, built in old) keeps
 * its parent's slot, the others take the free slots in ascending order. 0 (nothing written)
 * when the free slots do not suffice or two elements name one parent. used: old's cap flags,
 * zero. */
static int take_slots(const corot_store *o, fcm_index ne, const fcm_index *same, corot_store *c,
                      unsigned char *used)
{
  fcm_index kept = 0, next = 0;
  for (fcm_index e = 0; e < ne; e++)
    if (same[e] >= 0 && o->have[same[e]]) {
      if (used[o->slot[same[e]]]) return 0; /* two elements would share one matrix */
      used[o->slot[same[e]]] = 1, kept++;
    }
  if (ne > o->cap) return 0; /* ne - kept new slots among the cap - kept free ones */
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index f = same[e];
    c->have[e] = f >= 0 && o->have[f];
    if (c->have[e]) {
      c->slot[e] = o->slot[f];
      continue;
    }
    while (used[next])
      next++;
    c->slot[e] = next++;
  }
  return 1;
}

fcm_status fcm__assembly_corot_take(fcm_assembly_workspace *ws, fcm_assembly_workspace *old,
                                    const fcm_index *same)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws ? ws->ctx : NULL;
  unsigned char *used = NULL;
  FCM_CHECK(ws && old && same, ctx, FCM_ERR_ARG, "corotated_linear: NULL workspace or map");
  corot_store *o = &old->corot, *c = &ws->corot;
  const fcm_index ne = ws->space->num_elems;
  if (!o->K || !o->G || c->K || ws->space->nn != old->space->nn)
    return fcm__assembly_corot_inherit(ws, old, same);
  FCM_ALLOC(ctx, (size_t)o->cap + 1, used);
  FCM_ALLOC(ctx, (size_t)ne + 1, c->have);
  FCM_ALLOC_RAW(ctx, (size_t)ne + 1, c->slot);
  if (!take_slots(o, ne, same, c, used)) { /* full: copied into a new store */
    FCM_FREE(ctx, c->have);
    FCM_FREE(ctx, c->slot);
    FCM_TRY(ctx, fcm__assembly_corot_inherit(ws, old, same));
    goto cleanup;
  }
  c->K = o->K, c->G = o->G, c->cap = o->cap, c->cb = o->cb;
  o->K = NULL, o->G = NULL;
  c->lambda = o->lambda;
  c->mu = o->mu;
cleanup:
  fcm__free(ctx, used);
  return st;
}

void fcm__assembly_corot_give_back(fcm_assembly_workspace *ws, fcm_assembly_workspace *old)
{
  corot_store *c = &ws->corot, *o = &old->corot;
  if (!c->K || o->K || !o->have) return; /* old's store is its own (nothing taken) */
  o->K = c->K, o->G = c->G, c->K = NULL, c->G = NULL;
  memset(o->have, 0, (size_t)old->space->num_elems); /* its slots' matrices may be others' */
}

void fcm__assembly_corot_map(fcm_assembly_workspace *ws)
{
  fcm__large_map(ws->corot.K);
  fcm__large_map(ws->corot.G);
}

fcm_index fcm__assembly_corot_built(const fcm_assembly_workspace *ws)
{
  return ws->corot.built;
}

void fcm__assembly_corot_tangent(fcm_assembly_workspace *ws, int exact)
{
  if (ws) ws->corot_warped = !exact;
}
