/* Hanging-node constraints of a space on an octree mesh: the matrix T with u = T u_free that
 * makes the field continuous across faces between cells of different levels. With cuts (DOF
 * copies, XFEM), each copy of a hanging node follows the coarse cell's piece of its own material
 * component: the copies of the masters that piece uses. With copies constrained to move with
 * their piece (constrain_ratio), the element DOFs already name, at a constrained slot, the copy
 * it follows: a row reads what its coarse piece's element reads, a master is expanded through
 * what its own source reads, and a constrained hanging copy has left the numbering (no row; its
 * elements read the copy it follows, continuous up to the tiny piece's "sticking"). */
#include "fem_impl.h"

#include <math.h>
#include <stdint.h>

/* Weights below this are the exact zeros of shape functions at the node's position (the
 * reference coordinates are dyadic, so the nonzero ones are dyadic too: 1/2, 1/4, 3/8, ...). */
#define HANG_WEIGHT_EPS 1e-14
/* Longest chain of constraints (a master that hangs on a coarser cell, and so on): one step per
 * level at most, with room to spare; a longer chain is a broken mesh. */
#define HANG_MAX_DEPTH (2 * FCM_OCTREE_MAX_LEVEL + 4)

/* A growing list of (copy, weight). */
typedef struct terms {
  fcm_index *copy;
  double *w;
  size_t n, cap;
} terms;

/* The source of each copy's constraint: elem[r] the element (a piece of an active cell the
 * copy's node hangs on) whose trace gives copy r its value, pair[r] the hanging pair (cell,
 * node) with the node's reference position; elem[r] = -1 for a free copy. */
typedef struct sources {
  fcm_index *elem, *pair;
  fcm_index num;
} sources;

/* Scratch of the per-node component search: the elements around one hanging node. */
typedef struct around {
  fcm_index *el, *uf, *pos; /* pos: num_elems, -1 outside the current set */
  fcm_index n, cap;
} around;

static fcm_status terms_push(fcm_ctx *ctx, terms *t, fcm_index copy, double w)
{
  fcm_status st = FCM_OK;
  if (t->n == t->cap) {
    const size_t cap = t->cap ? 2 * t->cap : 64;
    FCM_TRY(ctx, fcm__resize(ctx, (void **)&t->copy, t->cap, cap, sizeof *t->copy));
    FCM_TRY(ctx, fcm__resize(ctx, (void **)&t->w, t->cap, cap, sizeof *t->w));
    t->cap = cap;
  }
  t->copy[t->n] = copy;
  t->w[t->n++] = w;
cleanup:
  return st;
}

/* Append w x (copy r's value) to t in terms of free copies: a constrained copy is replaced by
 * the copies its source element uses at its cell's nodes, weighted by the cell's shape
 * functions at the node's reference position, recursively. */
static fcm_status expand(const fcm_space *s, const sources *src, fcm_index r, double w, int depth,
                         terms *t)
{
  fcm_status st = FCM_OK;
  if (src->elem[r] < 0) return terms_push(s->ctx, t, r, w);
  FCM_CHECK(depth < HANG_MAX_DEPTH, s->ctx, FCM_ERR_INTERNAL,
            "space_hanging_matrix_create: the constraint of DOF copy %lld chains over more than "
            "%d hanging nodes",
            (long long)r, HANG_MAX_DEPTH);
  double xi[3], N[FCM_ELEMENT_MAX_NODES];
  fcm_mesh_get_hanging(s->mesh, src->pair[r], NULL, NULL, xi);
  fcm_element_eval_shape(s->type, xi, N);
  const fcm_index *ed = s->elem_dof + (size_t)s->nn * (size_t)src->elem[r];
  for (int a = 0; a < s->nn; a++)
    if (fabs(N[a]) > HANG_WEIGHT_EPS)
      FCM_TRY(s->ctx, expand(s, src, ed[a] / 3, w * N[a], depth + 1, t));
cleanup:
  return st;
}

static fcm_index uf_find(fcm_index *uf, fcm_index a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return a;
}

static fcm_status around_add(fcm_ctx *ctx, around *A, fcm_index e)
{
  fcm_status st = FCM_OK;
  if (A->pos[e] >= 0) return FCM_OK;
  if (A->n == A->cap) {
    const fcm_index cap = A->cap ? 2 * A->cap : 64;
    FCM_TRY(ctx, fcm__resize(ctx, (void **)&A->el, (size_t)A->cap, (size_t)cap, sizeof *A->el));
    FCM_TRY(ctx, fcm__resize(ctx, (void **)&A->uf, (size_t)A->cap, (size_t)cap, sizeof *A->uf));
    A->cap = cap;
  }
  A->pos[e] = A->n;
  A->uf[A->n] = A->n;
  A->el[A->n++] = e;
cleanup:
  return st;
}

/* Whether cuts reach the cell of element e (as in the copies' numbering: a cell split into
 * pieces, reached by a cut, or a piece with a face on a cut): the links are known there. */
static int cut_near(const fcm_space *s, fcm_index e)
{
  const fcm_index c = s->elem_cell[e];
  if (!s->rules) return 0;
  return s->cell_elem[c + 1] - s->cell_elem[c] > 1 || (s->rules->reached && s->rules->reached[c]) ||
         fcm_cell_rules_get_piece_cut_faces(s->rules, s->elem_piece[e], NULL) > 0;
}

/* Join the elements of A along the rules' links (every element into one component when no cut
 * is near any of them, as the copies' numbering does). */
static void around_join(const fcm_space *s, around *A)
{
  int split = 0;
  for (fcm_index i = 0; i < A->n && !split; i++)
    split = cut_near(s, A->el[i]);
  if (!split) {
    for (fcm_index i = 0; i < A->n; i++)
      A->uf[i] = 0;
    return;
  }
  const fcm_index nl = fcm_cell_rules_num_links(s->rules);
  const fcm_index *links = fcm_cell_rules_links(s->rules);
  for (fcm_index i = 0; i < A->n; i++) {
    const fcm_index p = s->elem_piece[A->el[i]];
    for (fcm_index l = fcm__lower_bound(links, 2, 0, nl, p); l < nl && links[2 * l] == p; l++) {
      const fcm_index q = links[2 * l + 1], cq = fcm_cell_rules_piece_cell(s->rules, q);
      fcm_index fq = 0;
      fcm_cell_rules_cell_pieces(s->rules, cq, &fq);
      const fcm_index eq = s->cell_elem[cq] + (q - fq);
      if (A->pos[eq] < 0) continue;
      const fcm_index ra = uf_find(A->uf, i), rb = uf_find(A->uf, A->pos[eq]);
      if (ra != rb) A->uf[FCM_MAX(ra, rb)] = FCM_MIN(ra, rb);
    }
  }
}

/* The active hanging pairs by node (pp, pl: CSR over nodes, pairs ascending) and the elements at
 * each node that has such a pair (sp, sl: CSR, entries nn e + a for element e's local node a). */
typedef struct hang_index {
  fcm_index *pp, *pl, *sp, *sl;
} hang_index;

static fcm_status hang_index_build(const fcm_space *s, hang_index *H)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_mesh *mesh = s->mesh;
  const fcm_index nh = fcm_mesh_num_hanging(mesh), nn = s->num_nodes;
  const fcm_index *cells = fcm_mesh_cells(mesh);
  FCM_ALLOC(ctx, (size_t)nn + 2, H->pp);
  FCM_ALLOC(ctx, (size_t)nh + 1, H->pl);
  FCM_ALLOC(ctx, (size_t)nn + 2, H->sp);
  for (int pass = 0; pass < 2; pass++) {
    for (fcm_index i = 0; i < nh; i++) {
      fcm_index c = 0, h = 0;
      fcm_mesh_get_hanging(mesh, i, &c, &h, NULL);
      if (!s->active[c] || s->node_dof[h] < 0) continue;
      if (pass == 0)
        H->pp[h + 2]++;
      else
        H->pl[H->pp[h + 1]++] = i;
    }
    if (pass == 0)
      for (fcm_index n = 0; n < nn; n++)
        H->pp[n + 2] += H->pp[n + 1];
  }
  for (int pass = 0; pass < 2; pass++) {
    for (fcm_index e = 0; e < s->num_elems; e++)
      for (int a = 0; a < s->nn; a++) {
        const fcm_index n = cells[(size_t)s->nn * (size_t)s->elem_cell[e] + (size_t)a];
        if (H->pp[n + 1] == H->pp[n]) continue;
        if (pass == 0)
          H->sp[n + 2]++;
        else
          H->sl[H->sp[n + 1]++] = (fcm_index)s->nn * e + a;
      }
    if (pass == 0) {
      for (fcm_index n = 0; n < nn; n++)
        H->sp[n + 2] += H->sp[n + 1];
      FCM_ALLOC(ctx, (size_t)H->sp[nn + 1] + 1, H->sl);
    }
  }
cleanup:
  return st;
}

static void hang_index_free(fcm_ctx *ctx, hang_index *H)
{
  fcm__free(ctx, H->pp);
  fcm__free(ctx, H->pl);
  fcm__free(ctx, H->sp);
  fcm__free(ctx, H->sl);
}

/* The source of copy r of hanging node h: the first of the node's active pairs whose cell has a
 * piece in the component (uf root `root` of A) of the copy; all the cell's pieces there must use
 * the same copies of the masters (nonzero weights), else the constraint is ambiguous. */
static fcm_status copy_source(const fcm_space *s, const hang_index *H, around *A, fcm_index h,
                              fcm_index r, fcm_index root, sources *src)
{
  fcm_status st = FCM_OK;
  for (fcm_index k = H->pp[h]; k < H->pp[h + 1] && src->elem[r] < 0; k++) {
    fcm_index c = 0;
    double xi[3], N[FCM_ELEMENT_MAX_NODES];
    fcm_mesh_get_hanging(s->mesh, H->pl[k], &c, NULL, xi);
    fcm_element_eval_shape(s->type, xi, N);
    fcm_index first = -1;
    for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++) {
      if (uf_find(A->uf, A->pos[e]) != root) continue;
      if (first < 0) {
        first = e;
        continue;
      }
      const fcm_index *d0 = s->elem_dof + (size_t)s->nn * first,
                      *d1 = s->elem_dof + (size_t)s->nn * e;
      for (int a = 0; a < s->nn; a++)
        FCM_CHECK(fabs(N[a]) <= HANG_WEIGHT_EPS || d0[a] == d1[a], s->ctx, FCM_ERR_UNSUPPORTED,
                  "space_hanging_matrix_create: copy %lld of hanging node %lld joins two pieces "
                  "of cell %lld that use different copies of its node %lld (material the cell "
                  "keeps apart meets around the hanging node): the constraint is ambiguous; "
                  "refine the cell (e.g. along the cut)",
                  (long long)(r - s->node_dof[h] / 3), (long long)h, (long long)c,
                  (long long)fcm_mesh_cells(s->mesh)[(size_t)s->nn * c + a]);
    }
    if (first >= 0) src->elem[r] = first, src->pair[r] = H->pl[k];
  }
cleanup:
  return st;
}

/* The sources of the copies of hanging node h (sources). */
static fcm_status node_sources(const fcm_space *s, const hang_index *H, around *A, fcm_index h,
                               sources *src)
{
  fcm_status st = FCM_OK;
  const fcm_index r0 = s->node_dof[h] / 3, nn = s->nn;
  A->n = 0;
  for (fcm_index k = H->sp[h]; k < H->sp[h + 1]; k++)
    FCM_TRY(s->ctx, around_add(s->ctx, A, H->sl[k] / nn));
  for (fcm_index k = H->pp[h]; k < H->pp[h + 1]; k++) {
    fcm_index c = 0;
    fcm_mesh_get_hanging(s->mesh, H->pl[k], &c, NULL, NULL);
    for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++)
      FCM_TRY(s->ctx, around_add(s->ctx, A, e));
  }
  around_join(s, A);
  for (fcm_index r = r0; r < r0 + s->node_ncopy[h]; r++) {
    fcm_index root = -1;
    /* a slot reading r in place of a constrained copy lies in the tiny piece's component,
     * not in r's own */
    for (fcm_index k = H->sp[h]; k < H->sp[h + 1] && root < 0; k++)
      if (s->elem_dof[H->sl[k]] / 3 == r && !(s->elem_con && s->elem_con[H->sl[k]]))
        root = uf_find(A->uf, A->pos[H->sl[k] / nn]);
    if (root >= 0) FCM_TRY(s->ctx, copy_source(s, H, A, h, r, root, src));
    src->num += src->elem[r] >= 0;
  }
cleanup:
  for (fcm_index i = 0; i < A->n; i++)
    A->pos[A->el[i]] = -1;
  return st;
}

/* The sources of every copy (sources; O(num_nodes + num_elems x nn) scratch). */
static fcm_status constraint_sources(const fcm_space *s, sources *src)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_dofs / 3;
  hang_index H = {0};
  around A = {0};
  FCM_ALLOC_RAW(ctx, FCM_MAX(ncopy, 1), src->elem);
  FCM_ALLOC_RAW(ctx, FCM_MAX(ncopy, 1), src->pair);
  for (fcm_index r = 0; r < ncopy; r++)
    src->elem[r] = src->pair[r] = -1;
  src->num = 0;
  if (fcm_mesh_num_hanging(s->mesh) == 0) return FCM_OK;
  FCM_TRY(ctx, hang_index_build(s, &H));
  FCM_ALLOC_RAW(ctx, FCM_MAX(s->num_elems, 1), A.pos);
  for (fcm_index e = 0; e < s->num_elems; e++)
    A.pos[e] = -1;
  for (fcm_index h = 0; h < s->num_nodes; h++)
    if (H.pp[h + 1] > H.pp[h]) FCM_TRY(ctx, node_sources(s, &H, &A, h, src));
cleanup:
  hang_index_free(ctx, &H);
  fcm__free(ctx, A.el);
  fcm__free(ctx, A.uf);
  fcm__free(ctx, A.pos);
  return st;
}

/* Append copy n's constraint rows (3 per term of its expansion, equal masters merged) to the
 * triplets rows/cols/vals (*ntrip of them, room for *cap). */
static fcm_status constraint_rows(const fcm_space *s, const sources *src, const fcm_index *col,
                                  fcm_index r, terms *t, fcm_index **rows, fcm_index **cols,
                                  double **vals, fcm_index *ntrip, size_t *cap)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  t->n = 0;
  FCM_TRY(ctx, expand(s, src, r, 1.0, 0, t));
  /* merge equal masters (sorted by copy through an insertion sort on pairs) */
  for (size_t i = 1; i < t->n; i++)
    for (size_t j = i; j > 0 && t->copy[j - 1] > t->copy[j]; j--) {
      const fcm_index a = t->copy[j];
      const double w = t->w[j];
      t->copy[j] = t->copy[j - 1], t->w[j] = t->w[j - 1];
      t->copy[j - 1] = a, t->w[j - 1] = w;
    }
  for (size_t i = 0; i < t->n; i++) {
    double w = t->w[i];
    while (i + 1 < t->n && t->copy[i + 1] == t->copy[i])
      w += t->w[++i];
    if (fabs(w) <= HANG_WEIGHT_EPS) continue;
    FCM_CHECK(col[t->copy[i]] >= 0, ctx, FCM_ERR_INTERNAL,
              "space_hanging_matrix_create: master copy %lld of DOF copy %lld is not free",
              (long long)t->copy[i], (long long)r);
    if ((size_t)*ntrip + 3 > *cap) {
      const size_t nc = 2 * *cap + 3;
      FCM_TRY(ctx, fcm__resize(ctx, (void **)rows, *cap, nc, sizeof **rows));
      FCM_TRY(ctx, fcm__resize(ctx, (void **)cols, *cap, nc, sizeof **cols));
      FCM_TRY(ctx, fcm__resize(ctx, (void **)vals, *cap, nc, sizeof **vals));
      *cap = nc;
    }
    for (int d = 0; d < 3; d++) {
      (*rows)[*ntrip] = 3 * r + d;
      (*cols)[*ntrip] = 3 * col[t->copy[i]] + d;
      (*vals)[(*ntrip)++] = w;
    }
  }
cleanup:
  return st;
}

fcm_status fcm_space_hanging_matrix_create(const fcm_space *space, fcm_index *free_dof, fcm_csr **T)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = space ? space->ctx : NULL;
  fcm_index *col = NULL, *rows = NULL, *cols = NULL;
  double *vals = NULL;
  sources src = {0};
  terms t = {0};
  FCM_CHECK(space && T, ctx, FCM_ERR_ARG,
            "space_hanging_matrix_create: space and T must not be NULL");
  *T = NULL;
  const fcm_index nd = space->num_dofs, ncopy = nd / 3;
  FCM_TRY(ctx, constraint_sources(space, &src));
  /* columns: the free copies in DOF order */
  FCM_ALLOC_RAW(ctx, FCM_MAX(ncopy, 1), col);
  fcm_index num_free = 0, ntrip = 0;
  for (fcm_index r = 0; r < ncopy; r++)
    col[r] = src.elem[r] < 0 ? num_free++ : -1;
  FCM_CHECK(3 * num_free <= INT32_MAX, ctx, FCM_ERR_UNSUPPORTED,
            "space_hanging_matrix_create: %lld free DOFs exceed 32-bit column indices",
            (long long)(3 * num_free));
  if (free_dof)
    for (fcm_index i = 0; i < nd; i++)
      free_dof[i] = col[i / 3] >= 0 ? 3 * col[i / 3] + i % 3 : -1;
  /* the free copies' identity rows, then each constrained copy's expansion (3 rows alike) */
  size_t cap = (size_t)nd + 3;
  FCM_ALLOC_RAW(ctx, cap, rows);
  FCM_ALLOC_RAW(ctx, cap, cols);
  FCM_ALLOC_RAW(ctx, cap, vals);
  for (fcm_index r = 0; r < ncopy; r++)
    for (int d = 0; d < 3 && col[r] >= 0; d++) {
      rows[ntrip] = 3 * r + d;
      cols[ntrip] = 3 * col[r] + d;
      vals[ntrip++] = 1.0;
    }
  for (fcm_index r = 0; r < ncopy; r++)
    if (src.elem[r] >= 0)
      FCM_TRY(ctx, constraint_rows(space, &src, col, r, &t, &rows, &cols, &vals, &ntrip, &cap));
  FCM_TRY(ctx, fcm_csr_create_triplets(ctx, nd, 3 * num_free, ntrip, rows, cols, vals,
                                       FCM_CSR_GENERAL, T));
cleanup:
  if (ctx) {
    fcm__free(ctx, src.elem);
    fcm__free(ctx, src.pair);
    fcm__free(ctx, col);
    fcm__free(ctx, rows);
    fcm__free(ctx, cols);
    fcm__free(ctx, vals);
    fcm__free(ctx, t.copy);
    fcm__free(ctx, t.w);
  }
  return st;
}
