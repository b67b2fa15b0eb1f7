/* The Gauss rules of the surface moments (fcm__moment_quad: per level of the divergence
 * theorem's antiderivatives, on [0, 1], and a triangle rule) and the signed rules' storage
 * (fcm__srule), which surface_moments.c fills. */
#include "embed/embed_impl.h"

#include <string.h>

static fcm_status unit_gauss(fcm_ctx *ctx, int degree, int *n, double **t, double **a)
{
  fcm_status st = FCM_OK;
  fcm_rule *g = NULL;
  FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_LINE, degree, &g));
  *n = fcm_rule_num_points(g);
  FCM_ALLOC(ctx, (size_t)*n, *t);
  FCM_ALLOC(ctx, (size_t)*n, *a);
  for (int i = 0; i < *n; i++) { /* [-1, 1] -> [0, 1] */
    (*t)[i] = 0.5 * (fcm_rule_points(g)[i] + 1.0);
    (*a)[i] = 0.5 * fcm_rule_weights(g)[i];
  }
cleanup:
  fcm_rule_destroy(&g);
  return st;
}

fcm_status fcm__moment_quad_create(fcm_ctx *ctx, int m, fcm__moment_quad *q)
{
  fcm_status st = FCM_OK;
  fcm_rule *tri = NULL;
  memset(q, 0, sizeof *q);
  q->m = m;
  for (int l = 0; l < 3; l++)
    FCM_TRY(ctx, unit_gauss(ctx, m + l, q->ng + l, q->gt + l, q->ga + l));
  FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_TRI, m + 1, &tri));
  q->nt = fcm_rule_num_points(tri);
  FCM_ALLOC(ctx, 2 * (size_t)q->nt, q->tx);
  FCM_ALLOC(ctx, (size_t)q->nt, q->tw);
  memcpy(q->tx, fcm_rule_points(tri), 2 * (size_t)q->nt * sizeof *q->tx);
  memcpy(q->tw, fcm_rule_weights(tri), (size_t)q->nt * sizeof *q->tw);
cleanup:
  fcm_rule_destroy(&tri);
  if (st != FCM_OK) fcm__moment_quad_free(ctx, q);
  return st;
}

void fcm__moment_quad_free(fcm_ctx *ctx, fcm__moment_quad *q)
{
  for (int l = 0; l < 3; l++) {
    fcm__free(ctx, q->gt[l]);
    fcm__free(ctx, q->ga[l]);
    q->gt[l] = q->ga[l] = NULL;
  }
  fcm__free(ctx, q->tx);
  fcm__free(ctx, q->tw);
  q->tx = q->tw = NULL;
}

void fcm__srule_free(fcm_ctx *ctx, fcm__srule *s)
{
  fcm__free(ctx, s->x);
  fcm__free(ctx, s->w);
  s->x = s->w = NULL;
  s->n = s->cap = 0;
}

fcm_status fcm__srule_room(fcm_ctx *ctx, fcm__srule *s, size_t more)
{
  fcm_status st = FCM_OK;
  if (s->n + more <= s->cap) return FCM_OK;
  size_t cap = s->cap ? s->cap : 1024;
  while (cap < s->n + more)
    cap *= 2;
  void *x = s->x, *w = s->w;
  FCM_TRY(ctx, fcm__resize(ctx, &x, 3 * s->n, 3 * cap, sizeof(double)));
  s->x = x;
  FCM_TRY(ctx, fcm__resize(ctx, &w, s->n, cap, sizeof(double)));
  s->w = w;
  s->cap = cap;
cleanup:
  return st;
}
