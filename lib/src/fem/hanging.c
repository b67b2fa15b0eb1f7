/* Hanging-node constraints of a space on an octree mesh: the matrix T with u = T u_free that
 * makes the field continuous across faces between cells of different levels. */
#include "fem_impl.h"

#include <math.h>
#include <stdint.h>

/* Weights below this are the exact zeros of shape functions at the node's position (the
 * reference coordinates are dyadic, so the nonzero ones are dyadic too: 1/2, 1/4, 3/8, ...). */
#define HANG_WEIGHT_EPS 1e-14
/* Longest chain of constraints (a master that hangs on a coarser cell, and so on): one step per
 * level at most, with room to spare; a longer chain is a broken mesh. */
#define HANG_MAX_DEPTH (2 * FCM_OCTREE_MAX_LEVEL + 4)

/* A growing list of (node, weight). */
typedef struct terms {
  fcm_index *node;
  double *w;
  size_t n, cap;
} terms;

static fcm_status terms_push(fcm_ctx *ctx, terms *t, fcm_index node, double w)
{
  fcm_status st = FCM_OK;
  if (t->n == t->cap) {
    const size_t cap = t->cap ? 2 * t->cap : 64;
    FCM_TRY(ctx, fcm__resize(ctx, (void **)&t->node, t->cap, cap, sizeof *t->node));
    FCM_TRY(ctx, fcm__resize(ctx, (void **)&t->w, t->cap, cap, sizeof *t->w));
    t->cap = cap;
  }
  t->node[t->n] = node;
  t->w[t->n++] = w;
cleanup:
  return st;
}

/* Append w x (node's value) to t in terms of free nodes: a constrained node (src[node] >= 0, the
 * (cell, node) pair whose cell's trace gives its value) is replaced by the cell's nodes weighted
 * by the cell's shape functions at the node's reference position, recursively. */
static fcm_status expand(const fcm_space *s, const fcm_index *src, fcm_index node, double w,
                         int depth, terms *t)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *mesh = s->mesh;
  if (src[node] < 0) return terms_push(s->ctx, t, node, w);
  FCM_CHECK(depth < HANG_MAX_DEPTH, s->ctx, FCM_ERR_INTERNAL,
            "space_hanging_matrix_create: the constraint of node %lld chains over more than %d "
            "hanging nodes",
            (long long)node, HANG_MAX_DEPTH);
  fcm_index cell = 0;
  double xi[3], N[FCM_ELEMENT_MAX_NODES];
  fcm_mesh_get_hanging(mesh, src[node], &cell, NULL, xi);
  fcm_element_eval_shape(s->type, xi, N);
  const fcm_index *cn = fcm_mesh_cells(mesh) + (size_t)s->nn * (size_t)cell;
  for (int a = 0; a < s->nn; a++)
    if (fabs(N[a]) > HANG_WEIGHT_EPS)
      FCM_TRY(s->ctx, expand(s, src, cn[a], w * N[a], depth + 1, t));
cleanup:
  return st;
}

/* src[node]: the first (cell, node) pair of an active cell, -1 for a node no active cell
 * constrains. Refuses what the constraints do not cover: several DOF copies at a constrained
 * node or at a node of its cell (enrichment), copies constrained to move with their piece. */
static fcm_status constraint_sources(const fcm_space *s, fcm_index *src, fcm_index *num)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *mesh = s->mesh;
  *num = 0;
  for (fcm_index n = 0; n < s->num_nodes; n++)
    src[n] = -1;
  for (fcm_index i = 0; i < fcm_mesh_num_hanging(mesh); i++) {
    fcm_index cell = 0, node = 0;
    fcm_mesh_get_hanging(mesh, i, &cell, &node, NULL);
    if (!s->active[cell] || s->node_dof[node] < 0 || src[node] >= 0) continue;
    const fcm_index *cn = fcm_mesh_cells(mesh) + (size_t)s->nn * (size_t)cell;
    FCM_CHECK(s->node_ncopy[node] == 1, s->ctx, FCM_ERR_UNSUPPORTED,
              "space_hanging_matrix_create: hanging node %lld has %lld DOF copies; constraints of "
              "enriched "
              "(cut) nodes on an octree background are not supported",
              (long long)node, (long long)s->node_ncopy[node]);
    for (int a = 0; a < s->nn; a++)
      FCM_CHECK(s->node_ncopy[cn[a]] == 1, s->ctx, FCM_ERR_UNSUPPORTED,
                "space_hanging_matrix_create: node %lld of cell %lld, on which node %lld hangs, "
                "has %lld DOF "
                "copies; constraints of enriched (cut) nodes on an octree background are not "
                "supported",
                (long long)cn[a], (long long)cell, (long long)node,
                (long long)s->node_ncopy[cn[a]]);
    src[node] = i;
    (*num)++;
  }
cleanup:
  return st;
}

fcm_status fcm_space_hanging_matrix_create(const fcm_space *space, fcm_index *free_dof, fcm_csr **T)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = space ? space->ctx : NULL;
  fcm_index *src = NULL, *col = NULL, *rows = NULL, *cols = NULL;
  double *vals = NULL;
  terms t = {0};
  FCM_CHECK(space && T, ctx, FCM_ERR_ARG,
            "space_hanging_matrix_create: space and T must not be NULL");
  *T = NULL;
  FCM_CHECK(!space->elem_con, ctx, FCM_ERR_UNSUPPORTED,
            "space_hanging_matrix_create: %lld DOF copies are constrained to move with their piece "
            "(constrain_ratio); hanging-node constraints do not combine with them",
            (long long)space->num_constrained);
  FCM_ALLOC_RAW(ctx, FCM_MAX(space->num_nodes, 1), src);
  FCM_ALLOC_RAW(ctx, FCM_MAX(space->num_nodes, 1), col);
  fcm_index num_con = 0, num_free = 0, ntrip = 0;
  FCM_TRY(ctx, constraint_sources(space, src, &num_con));
  /* columns: the free nodes' copies in DOF order */
  for (fcm_index n = 0; n < space->num_nodes; n++) {
    col[n] = -1;
    if (space->node_dof[n] < 0 || src[n] >= 0) continue;
    col[n] = num_free;
    num_free += space->node_ncopy[n];
  }
  const fcm_index nd = space->num_dofs;
  FCM_CHECK(3 * num_free <= INT32_MAX, ctx, FCM_ERR_UNSUPPORTED,
            "space_hanging_matrix_create: %lld free DOFs exceed 32-bit column indices",
            (long long)(3 * num_free));
  if (free_dof)
    for (fcm_index i = 0; i < nd; i++)
      free_dof[i] = -1;
  /* the free copies' identity rows, then each constrained node's expansion (3 rows alike) */
  size_t cap = (size_t)nd;
  FCM_ALLOC_RAW(ctx, cap, rows);
  FCM_ALLOC_RAW(ctx, cap, cols);
  FCM_ALLOC_RAW(ctx, cap, vals);
  for (fcm_index n = 0; n < space->num_nodes; n++) {
    if (col[n] < 0) continue;
    for (fcm_index k = 0; k < 3 * space->node_ncopy[n]; k++) {
      rows[ntrip] = space->node_dof[n] + k;
      cols[ntrip] = 3 * col[n] + k;
      vals[ntrip++] = 1.0;
      if (free_dof) free_dof[space->node_dof[n] + k] = 3 * col[n] + k;
    }
  }
  for (fcm_index n = 0; n < space->num_nodes; n++) {
    if (src[n] < 0) continue;
    t.n = 0;
    FCM_TRY(ctx, expand(space, src, n, 1.0, 0, &t));
    /* merge equal masters (sorted by node through an index sort on pairs) */
    for (size_t i = 1; i < t.n; i++)
      for (size_t j = i; j > 0 && t.node[j - 1] > t.node[j]; j--) {
        const fcm_index a = t.node[j];
        const double w = t.w[j];
        t.node[j] = t.node[j - 1], t.w[j] = t.w[j - 1];
        t.node[j - 1] = a, t.w[j - 1] = w;
      }
    for (size_t i = 0; i < t.n; i++) {
      double w = t.w[i];
      while (i + 1 < t.n && t.node[i + 1] == t.node[i])
        w += t.w[++i];
      if (fabs(w) <= HANG_WEIGHT_EPS) continue;
      FCM_CHECK(
          col[t.node[i]] >= 0, ctx, FCM_ERR_INTERNAL,
          "space_hanging_matrix_create: master node %lld of hanging node %lld has no free DOFs",
          (long long)t.node[i], (long long)n);
      if ((size_t)ntrip + 3 > cap) {
        const size_t nc = 2 * cap + 3;
        FCM_TRY(ctx, fcm__resize(ctx, (void **)&rows, cap, nc, sizeof *rows));
        FCM_TRY(ctx, fcm__resize(ctx, (void **)&cols, cap, nc, sizeof *cols));
        FCM_TRY(ctx, fcm__resize(ctx, (void **)&vals, cap, nc, sizeof *vals));
        cap = nc;
      }
      for (int d = 0; d < 3; d++) {
        rows[ntrip] = space->node_dof[n] + d;
        cols[ntrip] = 3 * col[t.node[i]] + d;
        vals[ntrip++] = w;
      }
    }
  }
  FCM_TRY(ctx, fcm_csr_create_triplets(ctx, nd, 3 * num_free, ntrip, rows, cols, vals,
                                       FCM_CSR_GENERAL, T));
cleanup:
  if (ctx) {
    fcm__free(ctx, src);
    fcm__free(ctx, col);
    fcm__free(ctx, rows);
    fcm__free(ctx, cols);
    fcm__free(ctx, vals);
    fcm__free(ctx, t.node);
    fcm__free(ctx, t.w);
  }
  return st;
}
