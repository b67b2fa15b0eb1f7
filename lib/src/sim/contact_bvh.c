/* sim: a bounding-volume hierarchy of axis-aligned boxes with one subtree per group (the
 * contact between bodies: a group is a body, so a query skips a body's own triangles and those
 * it ignores without descending), built by median splits and refitted to moved boxes.
 *
 * The nodes are stored in preorder: a node's left child follows it and its right child comes
 * later, so a refit visits the nodes backwards and finds both children up to date. A refit keeps
 * the topology: its boxes stay exact (each node holds the union of its items' current boxes),
 * only the tree's quality degrades as the items move apart; the caller rebuilds it once per
 * substep and refits it at every evaluation within. */
#include "sim/sim_impl.h"

#include <math.h>
#include <string.h>

#define LEAF_SIZE 4

static fcm_status push_node(fcm_ctx *ctx, sim_bvh *T, fcm_index *id)
{
  fcm_status st = FCM_OK;
  if (T->nnodes == T->cap) {
    const fcm_index cap = T->cap ? 2 * T->cap : 64;
    void *grown = T->node;
    FCM_TRY(ctx, fcm__resize(ctx, &grown, (size_t)T->cap, (size_t)cap, sizeof *T->node));
    T->node = grown;
    T->cap = cap;
  }
  *id = T->nnodes++;
  memset(T->node + *id, 0, sizeof *T->node);
cleanup:
  return st;
}

static double centre(const double *boxes, fcm_index item, int axis)
{
  return 0.5 * (boxes[6 * item + axis] + boxes[6 * item + 3 + axis]);
}

/* Reorder perm[lo, hi) so that the element of rank k along `axis` is at k, smaller or equal
 * ones before it and larger or equal ones after (quickselect, Lomuto's partition). */
static void select_rank(fcm_index *perm, fcm_index lo, fcm_index hi, fcm_index k,
                        const double *boxes, int axis)
{
  while (hi - lo > 1) {
    const fcm_index mid = lo + (hi - lo) / 2;
    fcm_index t = perm[mid], store = lo;
    perm[mid] = perm[hi - 1];
    perm[hi - 1] = t;
    const double pv = centre(boxes, t, axis);
    for (fcm_index i = lo; i < hi - 1; i++)
      if (centre(boxes, perm[i], axis) < pv) {
        t = perm[i];
        perm[i] = perm[store];
        perm[store++] = t;
      }
    t = perm[store];
    perm[store] = perm[hi - 1];
    perm[hi - 1] = t;
    if (k == store) return;
    if (k < store)
      hi = store;
    else
      lo = store + 1;
  }
}

static void box_union(double *lo, double *hi, const double *b)
{
  for (int i = 0; i < 3; i++) {
    lo[i] = FCM_MIN(lo[i], b[i]);
    hi[i] = FCM_MAX(hi[i], b[3 + i]);
  }
}

/* The subtree over perm[first, first + count). */
static fcm_status build_range(fcm_ctx *ctx, sim_bvh *T, const double *boxes, fcm_index first,
                              fcm_index count, int depth)
{
  fcm_status st = FCM_OK;
  fcm_index id;
  double clo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, chi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  FCM_TRY(ctx, push_node(ctx, T, &id));
  if (count <= LEAF_SIZE || depth >= 60) {
    T->node[id].first = first;
    T->node[id].count = count;
    return FCM_OK;
  }
  for (fcm_index k = first; k < first + count; k++)
    for (int i = 0; i < 3; i++) {
      const double c = centre(boxes, T->perm[k], i);
      clo[i] = FCM_MIN(clo[i], c);
      chi[i] = FCM_MAX(chi[i], c);
    }
  int axis = 0;
  for (int i = 1; i < 3; i++)
    if (chi[i] - clo[i] > chi[axis] - clo[axis]) axis = i;
  const fcm_index half = count / 2;
  select_rank(T->perm, first, first + count, first + half, boxes, axis);
  FCM_TRY(ctx, build_range(ctx, T, boxes, first, half, depth + 1));
  const fcm_index right = T->nnodes;
  FCM_TRY(ctx, build_range(ctx, T, boxes, first + half, count - half, depth + 1));
  T->node[id].right = right;
cleanup:
  return st;
}

fcm_status fcm__sim_bvh_build(fcm_ctx *ctx, sim_bvh *T, fcm_index n, const fcm_index *group,
                              fcm_index num_groups, const double *boxes)
{
  fcm_status st = FCM_OK;
  fcm_index *count = NULL;
  T->nnodes = 0;
  if (T->num_groups < num_groups || !T->root) {
    fcm__free(ctx, T->root);
    T->root = NULL;
    FCM_ALLOC(ctx, (size_t)num_groups + 1, T->root);
  }
  T->num_groups = num_groups;
  fcm__free(ctx, T->perm);
  T->perm = NULL;
  FCM_ALLOC(ctx, (size_t)n + 1, T->perm);
  FCM_ALLOC(ctx, (size_t)num_groups + 2, count);
  for (fcm_index k = 0; k < n; k++)
    if (group[k] >= 0) count[group[k] + 1]++;
  for (fcm_index g = 0; g < num_groups; g++)
    count[g + 1] += count[g];
  for (fcm_index k = 0; k < n; k++)
    if (group[k] >= 0) T->perm[count[group[k]]++] = k;
  for (fcm_index g = 0, first = 0; g < num_groups; g++) { /* count[g]: the end of group g */
    const fcm_index m = count[g] - first;
    T->root[g] = m > 0 ? T->nnodes : -1;
    if (m > 0) FCM_TRY(ctx, build_range(ctx, T, boxes, first, m, 0));
    first = count[g];
  }
  fcm__sim_bvh_refit(T, boxes);
cleanup:
  fcm__free(ctx, count);
  return st;
}

void fcm__sim_bvh_refit(sim_bvh *T, const double *boxes)
{
  for (fcm_index id = T->nnodes - 1; id >= 0; id--) {
    sim_bvh_node *nd = T->node + id;
    for (int i = 0; i < 3; i++) {
      nd->lo[i] = HUGE_VAL;
      nd->hi[i] = -HUGE_VAL;
    }
    if (nd->count > 0) {
      for (fcm_index k = nd->first; k < nd->first + nd->count; k++)
        box_union(nd->lo, nd->hi, boxes + 6 * T->perm[k]);
    } else {
      const sim_bvh_node *l = T->node + id + 1, *r = T->node + nd->right;
      double b[6];
      memcpy(b, l->lo, 3 * sizeof(double));
      memcpy(b + 3, l->hi, 3 * sizeof(double));
      box_union(nd->lo, nd->hi, b);
      memcpy(b, r->lo, 3 * sizeof(double));
      memcpy(b + 3, r->hi, 3 * sizeof(double));
      box_union(nd->lo, nd->hi, b);
    }
  }
}

static int meets(const double *lo, const double *hi, const double qlo[3], const double qhi[3])
{
  return lo[0] <= qhi[0] && qlo[0] <= hi[0] && lo[1] <= qhi[1] && qlo[1] <= hi[1] &&
         lo[2] <= qhi[2] && qlo[2] <= hi[2];
}

fcm_status fcm__sim_bvh_query(fcm_ctx *ctx, const sim_bvh *T, fcm_index g, const double *boxes,
                              const double lo[3], const double hi[3], fcm__idbuf *buf)
{
  fcm_status st = FCM_OK;
  fcm_index stack[128];
  int top = 0;
  if (g < 0 || g >= T->num_groups || T->root[g] < 0) return FCM_OK;
  stack[top++] = T->root[g];
  while (top > 0) {
    const sim_bvh_node *nd = T->node + stack[--top];
    if (!meets(nd->lo, nd->hi, lo, hi)) continue;
    if (nd->count == 0) {
      FCM_CHECK(top + 2 <= 128, ctx, FCM_ERR_INTERNAL, "contact bodies: tree deeper than 64");
      stack[top++] = nd->right;
      stack[top++] = (fcm_index)(nd - T->node) + 1;
      continue;
    }
    for (fcm_index k = nd->first; k < nd->first + nd->count; k++) {
      const fcm_index id = T->perm[k];
      if (!meets(boxes + 6 * id, boxes + 6 * id + 3, lo, hi)) continue;
      if (buf->n == buf->cap) {
        const size_t cap = buf->cap ? 2 * buf->cap : 64;
        void *grown = buf->ids;
        FCM_TRY(ctx, fcm__resize(ctx, &grown, buf->cap, cap, sizeof *buf->ids));
        buf->ids = grown;
        buf->cap = cap;
      }
      buf->ids[buf->n++] = id;
    }
  }
cleanup:
  return st;
}

void fcm__sim_bvh_free(fcm_ctx *ctx, sim_bvh *T)
{
  fcm__free(ctx, T->node);
  fcm__free(ctx, T->perm);
  fcm__free(ctx, T->root);
  memset(T, 0, sizeof *T);
}
