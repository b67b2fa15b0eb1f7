/* Carry a field onto a refined background: every DOF of the new space takes the old field's
 * value at its node, which reproduces the old field exactly when the new space contains it. */
#include "fem_impl.h"

#include <math.h>
#include <string.h>

fcm_status fcm_space_transfer_refined(const fcm_space *from, const fcm_space *to, const double *u,
                                      double *u_to)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to ? to->ctx : NULL;
  fcm_index *nodes = NULL, *cell = NULL;
  double *X = NULL, *xi = NULL, *val = NULL;
  int *extra = NULL;
  FCM_CHECK(from && to && u && u_to, ctx, FCM_ERR_ARG,
            "transfer_refined: from, to, u and u_to must not be NULL");
  FCM_CHECK(from->type == to->type, ctx, FCM_ERR_ARG,
            "transfer_refined: element types differ (%d, %d)", (int)from->type, (int)to->type);
  for (int k = 0; k < 2; k++) {
    const fcm_space *s = k ? to : from;
    for (fcm_index n = 0; n < s->num_nodes; n++)
      FCM_CHECK(s->node_ncopy[n] <= 1, ctx, FCM_ERR_UNSUPPORTED,
                "transfer_refined: node %lld of the %s space has %lld DOF copies; fields of "
                "enriched (cut) spaces are carried over cuts by fcm_space_transfer()",
                (long long)n, k ? "new" : "old", (long long)s->node_ncopy[n]);
  }
  const fcm_mesh *mesh = to->mesh;
  const double *coords = fcm_mesh_coords(mesh);
  fcm_index num = 0;
  for (fcm_index n = 0; n < to->num_nodes; n++)
    num += to->node_dof[n] >= 0;
  FCM_ALLOC_RAW(ctx, FCM_MAX(num, 1), nodes);
  FCM_ALLOC_RAW(ctx, FCM_MAX(num, 1), cell);
  FCM_ALLOC_RAW(ctx, 3 * FCM_MAX(num, 1), X);
  FCM_ALLOC_RAW(ctx, 3 * FCM_MAX(num, 1), xi);
  FCM_ALLOC_RAW(ctx, 3 * FCM_MAX(num, 1), val);
  FCM_ALLOC_RAW(ctx, FCM_MAX(num, 1), extra);
  num = 0;
  for (fcm_index n = 0; n < to->num_nodes; n++) {
    if (to->node_dof[n] < 0) continue;
    nodes[num] = n;
    memcpy(X + 3 * num, coords + 3 * n, 3 * sizeof *X);
    num++;
  }
  FCM_TRY(ctx, fcm_space_locate(from, num, X, cell, xi, extra));
  for (fcm_index i = 0; i < num; i++)
    FCM_CHECK(!extra[i], ctx, FCM_ERR_ARG,
              "transfer_refined: node %lld of the new space at (%g, %g, %g) lies in no active "
              "cell of the old space; the new background must refine the old one",
              (long long)nodes[i], X[3 * i], X[3 * i + 1], X[3 * i + 2]);
  FCM_TRY(ctx, fcm_space_interpolate(from, num, cell, xi, u, val));
  for (fcm_index i = 0; i < num; i++)
    memcpy(u_to + to->node_dof[nodes[i]], val + 3 * i, 3 * sizeof *val);
cleanup:
  if (ctx) {
    fcm__free(ctx, nodes);
    fcm__free(ctx, cell);
    fcm__free(ctx, X);
    fcm__free(ctx, xi);
    fcm__free(ctx, val);
    fcm__free(ctx, extra);
  }
  return st;
}
