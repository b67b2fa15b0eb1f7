/* AABB tree: a static bounding-volume hierarchy over boxes, built by median splits
 * along the longest axis of the box centres; box and segment queries for candidate search. */
#include "geom/geom_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEAF_SIZE 4
#define MAX_DEPTH 128

/* Centre coordinate of item `id` along `axis` (times 2). */
static double centre(const double *boxes, fcm_index id, int axis)
{
  return boxes[6 * id + axis] + boxes[6 * id + 3 + axis];
}

static int less(const double *boxes, int axis, fcm_index a, fcm_index b)
{
  const double ca = centre(boxes, a, axis), cb = centre(boxes, b, axis);
  return ca < cb || (ca == cb && a < b);
}

/* Reorder perm[0..n) so that perm[k] is the k-th smallest (Hoare selection). */
static void select_kth(const double *boxes, int axis, fcm_index *perm, fcm_index n, fcm_index k)
{
  fcm_index lo = 0, hi = n - 1;
  while (hi > lo) {
    /* Median of three as pivot, deterministic. */
    const fcm_index mid = lo + (hi - lo) / 2;
    fcm_index a = perm[lo], b = perm[mid], c = perm[hi], piv;
    if (less(boxes, axis, a, b))
      piv = less(boxes, axis, b, c) ? b : (less(boxes, axis, a, c) ? c : a);
    else
      piv = less(boxes, axis, a, c) ? a : (less(boxes, axis, b, c) ? c : b);
    fcm_index i = lo, j = hi;
    while (i <= j) {
      while (less(boxes, axis, perm[i], piv))
        i++;
      while (less(boxes, axis, piv, perm[j]))
        j--;
      if (i <= j) {
        const fcm_index t = perm[i];
        perm[i] = perm[j], perm[j] = t;
        i++, j--;
      }
    }
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      return;
  }
}

static void node_box(fcm_aabb_tree *t, fcm__aabb_node *nd, fcm_index first, fcm_index count)
{
  for (int d = 0; d < 3; d++)
    nd->lo[d] = HUGE_VAL, nd->hi[d] = -HUGE_VAL;
  for (fcm_index s = first; s < first + count; s++) {
    const double *b = t->boxes + 6 * t->perm[s];
    for (int d = 0; d < 3; d++) {
      nd->lo[d] = b[d] < nd->lo[d] ? b[d] : nd->lo[d];
      nd->hi[d] = b[3 + d] > nd->hi[d] ? b[3 + d] : nd->hi[d];
    }
  }
}

static void build(fcm_aabb_tree *t, fcm_index node, fcm_index first, fcm_index count)
{
  fcm__aabb_node *nd = t->nodes + node;
  node_box(t, nd, first, count);
  if (count <= LEAF_SIZE) {
    nd->first = first, nd->count = count;
    return;
  }
  double clo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, chi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (fcm_index s = first; s < first + count; s++)
    for (int d = 0; d < 3; d++) {
      const double c = centre(t->boxes, t->perm[s], d);
      clo[d] = c < clo[d] ? c : clo[d];
      chi[d] = c > chi[d] ? c : chi[d];
    }
  int axis = 0;
  for (int d = 1; d < 3; d++)
    if (chi[d] - clo[d] > chi[axis] - clo[axis]) axis = d;
  const fcm_index half = count / 2;
  select_kth(t->boxes, axis, t->perm + first, count, half);
  const fcm_index left = t->num_nodes;
  t->num_nodes += 2;
  nd->first = left, nd->count = 0;
  build(t, left, first, half);
  build(t, left + 1, first + half, count - half);
}

fcm_status fcm_aabb_tree_create(fcm_ctx *ctx, fcm_index n, const double *boxes,
                                fcm_aabb_tree **tree)
{
  fcm_status st = FCM_OK;
  fcm_aabb_tree *t = NULL;
  FCM_CHECK(tree, ctx, FCM_ERR_ARG, "aabb tree: output pointer is NULL");
  *tree = NULL;
  FCM_CHECK(ctx, ctx, FCM_ERR_ARG, "aabb tree: ctx is NULL");
  FCM_CHECK(n >= 0 && (n == 0 || boxes), ctx, FCM_ERR_ARG,
            "aabb tree: n = %lld must be >= 0 with a non-NULL box array", (long long)n);
  for (fcm_index i = 0; i < n; i++)
    for (int d = 0; d < 3; d++)
      FCM_CHECK(boxes[6 * i + d] <= boxes[6 * i + 3 + d], ctx, FCM_ERR_ARG,
                "aabb tree: box %lld has lo[%d] = %g > hi[%d] = %g (or NaN)", (long long)i, d,
                boxes[6 * i + d], d, boxes[6 * i + 3 + d]);
  FCM_ALLOC(ctx, 1, t);
  t->ctx = ctx;
  t->num_items = n;
  FCM_ALLOC(ctx, 2 * (size_t)n + 1, t->nodes);
  FCM_ALLOC(ctx, n, t->perm);
  FCM_ALLOC(ctx, 6 * (size_t)n, t->boxes);
  for (fcm_index i = 0; i < 6 * n; i++)
    t->boxes[i] = boxes[i];
  for (fcm_index i = 0; i < n; i++)
    t->perm[i] = i;
  if (n > 0) {
    t->num_nodes = 1;
    build(t, 0, 0, n);
    /* the boxes in slot order too: a leaf's are contiguous */
    FCM_ALLOC(ctx, 6 * (size_t)n, t->slot_boxes);
    for (fcm_index s = 0; s < n; s++)
      memcpy(t->slot_boxes + 6 * s, t->boxes + 6 * t->perm[s], 6 * sizeof(double));
  }
  *tree = t;
  t = NULL;
cleanup:
  fcm_aabb_tree_destroy(&t);
  return st;
}

void fcm_aabb_tree_destroy(fcm_aabb_tree **tree)
{
  if (!tree || !*tree) return;
  fcm_aabb_tree *t = *tree;
  fcm__free(t->ctx, t->nodes);
  fcm__free(t->ctx, t->perm);
  fcm__free(t->ctx, t->boxes);
  fcm__free(t->ctx, t->slot_boxes);
  fcm__free(t->ctx, t);
  *tree = NULL;
}

static int overlaps(const double *alo, const double *ahi, const double lo[3], const double hi[3])
{
  return alo[0] <= hi[0] && lo[0] <= ahi[0] && alo[1] <= hi[1] && lo[1] <= ahi[1] &&
         alo[2] <= hi[2] && lo[2] <= ahi[2];
}

static int cmp_index(const void *a, const void *b)
{
  const fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

/* What a traversal looks for: a box (lo, hi) or a segment (p0 + t d, t in [0, 1]) against
 * boxes widened by pad. */
typedef struct probe {
  int segment;
  double lo[3], hi[3];
  double p0[3], d[3], pad;
} probe;

/* The segment's slab test with plain comparisons (fmin and fmax are library calls here, and
 * a segment query visits many nodes): no operand is NaN, so the result is theirs. */
static inline int probe_meets(const probe *q, const double *blo, const double *bhi, int segment)
{
  if (!segment) return overlaps(blo, bhi, q->lo, q->hi);
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 3; k++) {
    const double lo = blo[k] - q->pad, hi = bhi[k] + q->pad;
    if (q->d[k] == 0.0) {
      if (q->p0[k] < lo || q->p0[k] > hi) return 0;
      continue;
    }
    const double a = (lo - q->p0[k]) / q->d[k], b = (hi - q->p0[k]) / q->d[k];
    const double amin = a < b ? a : b, bmax = a < b ? b : a;
    if (amin > t0) t0 = amin;
    if (bmax < t1) t1 = bmax;
    if (t0 > t1) return 0;
  }
  return 1;
}

/* The ids ascending (distinct ids: any sort gives the same order), without qsort's call per
 * comparison: a quicksort on the median of three, insertion below 24 ids, qsort for a range
 * that went deeper than twice log2 n (no quadratic case). */
static void sort_ids(fcm_index *ids, size_t n)
{
  int limit = 0;
  for (size_t m = n; m > 1; m >>= 1)
    limit += 2;
  while (n > 24) {
    if (limit-- == 0) {
      qsort(ids, n, sizeof *ids, cmp_index);
      return;
    }
    fcm_index *a = ids, *m = ids + n / 2, *z = ids + n - 1, t;
    if (*m < *a) t = *m, *m = *a, *a = t;
    if (*z < *m) {
      t = *z, *z = *m, *m = t;
      if (*m < *a) t = *m, *m = *a, *a = t;
    }
    const fcm_index piv = *m;
    size_t i = 0, j = n - 1;
    for (;;) { /* Hoare: [0, j] <= piv <= [j + 1, n) */
      while (ids[i] < piv)
        i++;
      while (ids[j] > piv)
        j--;
      if (i >= j) break;
      t = ids[i], ids[i] = ids[j], ids[j] = t;
      i++, j--;
    }
    const size_t left = j + 1; /* the smaller side recursively, the larger in the loop */
    if (left < n - left) {
      sort_ids(ids, left);
      ids += left, n -= left;
    } else {
      sort_ids(ids + left, n - left);
      n = left;
    }
  }
  fcm__insertion_sort(ids, (fcm_index)n);
}

/* The items whose boxes q meets, ascending, into buf. Children are tested before they are
 * pushed, and a leaf's boxes are read in slot order (t->slot_boxes); the set found,
 * sorted, does not depend on the order of the visit. segment: q->segment, a constant at each
 * call so that the test is not chosen per box. */
static inline fcm_status traverse_probe(fcm_ctx *ctx, const fcm_aabb_tree *t, const probe *q,
                                        fcm__idbuf *buf, int segment)
{
  fcm_status st = FCM_OK;
  fcm_index stack[MAX_DEPTH];
  int top = 0;
  buf->n = 0;
  if (t->num_items == 0 || !probe_meets(q, t->nodes[0].lo, t->nodes[0].hi, segment)) goto cleanup;
  stack[top++] = 0;
  while (top > 0) {
    const fcm__aabb_node *nd = t->nodes + stack[--top];
    if (nd->count == 0) {
      FCM_CHECK(top + 2 <= MAX_DEPTH, ctx, FCM_ERR_INTERNAL, "aabb tree: depth exceeds %d",
                MAX_DEPTH);
      const fcm__aabb_node *l = t->nodes + nd->first;
      if (probe_meets(q, l[1].lo, l[1].hi, segment)) stack[top++] = nd->first + 1;
      if (probe_meets(q, l[0].lo, l[0].hi, segment)) stack[top++] = nd->first;
      continue;
    }
    if (buf->n + (size_t)nd->count > buf->cap) {
      size_t cap = buf->cap ? 2 * buf->cap : 64;
      while (cap < buf->n + (size_t)nd->count)
        cap *= 2;
      void *grown = buf->ids;
      FCM_TRY(ctx, fcm__resize(ctx, &grown, buf->cap, cap, sizeof *buf->ids));
      buf->ids = grown;
      buf->cap = cap;
    }
    const double *b = t->slot_boxes + 6 * nd->first;
    for (fcm_index s = nd->first; s < nd->first + nd->count; s++, b += 6)
      if (probe_meets(q, b, b + 3, segment)) buf->ids[buf->n++] = t->perm[s];
  }
  sort_ids(buf->ids, buf->n);
cleanup:
  return st;
}

static fcm_status traverse(fcm_ctx *ctx, const fcm_aabb_tree *t, const probe *q, fcm__idbuf *buf)
{
  return q->segment ? traverse_probe(ctx, t, q, buf, 1) : traverse_probe(ctx, t, q, buf, 0);
}

int fcm__geom_tree_bounds(const fcm_aabb_tree *t, double lo[3], double hi[3])
{
  if (t->num_items == 0) return 0;
  memcpy(lo, t->nodes[0].lo, 3 * sizeof(double));
  memcpy(hi, t->nodes[0].hi, 3 * sizeof(double));
  return 1;
}

fcm_status fcm__geom_tree_query(fcm_ctx *ctx, const fcm_aabb_tree *t, const double lo[3],
                                const double hi[3], fcm__idbuf *buf)
{
  probe q;
  memset(&q, 0, sizeof q);
  memcpy(q.lo, lo, sizeof q.lo);
  memcpy(q.hi, hi, sizeof q.hi);
  return traverse(ctx, t, &q, buf);
}

fcm_status fcm__geom_tree_segment(fcm_ctx *ctx, const fcm_aabb_tree *t, const double p0[3],
                                  const double p1[3], double pad, fcm__idbuf *buf)
{
  probe q;
  memset(&q, 0, sizeof q);
  q.segment = 1;
  q.pad = pad;
  for (int k = 0; k < 3; k++)
    q.p0[k] = p0[k], q.d[k] = p1[k] - p0[k];
  return traverse(ctx, t, &q, buf);
}

void fcm__geom_idbuf_free(fcm_ctx *ctx, fcm__idbuf *buf)
{
  fcm__free(ctx, buf->ids);
  buf->ids = NULL;
  buf->n = buf->cap = 0;
}

fcm_status fcm_aabb_tree_query(const fcm_aabb_tree *tree, const double lo[3], const double hi[3],
                               fcm_index capacity, fcm_index *ids, fcm_index *count)
{
  fcm_status st = FCM_OK;
  fcm__idbuf buf = {NULL, 0, 0};
  fcm_ctx *ctx = tree ? tree->ctx : NULL;
  FCM_CHECK(tree && lo && hi && count, ctx, FCM_ERR_ARG,
            "aabb tree query: NULL argument (tree, lo, hi and count are required)");
  FCM_CHECK(capacity >= 0 && (capacity == 0 || ids), ctx, FCM_ERR_ARG,
            "aabb tree query: capacity = %lld must be >= 0 with a non-NULL ids array",
            (long long)capacity);
  for (int d = 0; d < 3; d++)
    FCM_CHECK(!isnan(lo[d]) && !isnan(hi[d]), ctx, FCM_ERR_ARG,
              "aabb tree query: box coordinate %d is NaN", d);
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, lo, hi, &buf));
  *count = (fcm_index)buf.n;
  if ((fcm_index)buf.n <= capacity)
    for (size_t i = 0; i < buf.n; i++)
      ids[i] = buf.ids[i];
cleanup:
  fcm__geom_idbuf_free(ctx, &buf);
  return st;
}
