/* What a cut leaves of a space: the parent of every DOF copy of the cut space (the copy of the
 * space before the cut whose values it inherits, as fcm_space_transfer() copies them), the
 * elements the cut leaves as they were (same cell, same rules: their element blocks stay
 * valid) and the fill-reducing ordering of the cut space's DOFs extended from the old
 * space's. */
#include "fem/fem_impl.h"

#include <string.h>

fcm_status fcm__space_check_cut_pair(const fcm_space *from, const fcm_space *to, const char *what)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to ? to->ctx : NULL;
  FCM_CHECK(from && to, ctx, FCM_ERR_ARG, "%s: NULL space", what);
  FCM_CHECK(from->mesh == to->mesh && from->rules && to->rules, ctx, FCM_ERR_ARG,
            "%s: both spaces must be embedded spaces on the same mesh", what);
  FCM_CHECK(fcm_cell_rules_parent_num_pieces(to->rules) == fcm_cell_rules_num_pieces(from->rules) &&
                fcm_cell_rules_parent_num_pieces(to->rules) > 0,
            ctx, FCM_ERR_ARG,
            "%s: the target's cell rules (made from rules with %lld pieces) do not extend the "
            "source's (%lld pieces) by a cut (fcm_cell_rules_create_cut())",
            what, (long long)fcm_cell_rules_parent_num_pieces(to->rules),
            (long long)fcm_cell_rules_num_pieces(from->rules));
cleanup:
  return st;
}

fcm_index fcm__space_cut_parent_elem(const fcm_space *from, const fcm_space *to, fcm_index e)
{
  const fcm_index c = to->elem_cell[e],
                  pp = fcm_cell_rules_piece_parent(to->rules, to->elem_piece[e]);
  fcm_index first = 0;
  fcm_cell_rules_cell_pieces(from->rules, c, &first);
  const fcm_index fe = from->cell_elem[c] + (pp - first);
  return pp >= first && fe < from->cell_elem[c + 1] ? fe : -1;
}

fcm_status fcm__space_cut_parents(const fcm_space *from, const fcm_space *to, fcm_index *parent)
{
  return fcm__space_cut_parents_with(from, to, parent, NULL);
}

fcm_status fcm__space_cut_parents_with(const fcm_space *from, const fcm_space *to,
                                       fcm_index *parent, fcm_index *parent_elem)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to ? to->ctx : NULL;
  FCM_TRY(ctx, fcm__space_check_cut_pair(from, to, "cut parents"));
  FCM_CHECK(parent, ctx, FCM_ERR_ARG, "cut parents: parent is NULL");
  const fcm_index nn = to->nn, ne = to->num_elems;
  const int nt = fcm_ctx_num_threads(ctx);
  fcm_index bad = ne;
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index k = 0; k < to->num_dofs / 3; k++)
    parent[k] = -1;
  if (parent_elem) {
    /* the parent elements by the threads (the first element without one, if any, reported) */
#pragma omp parallel for num_threads(nt) schedule(static) reduction(min : bad)
    for (fcm_index e = 0; e < ne; e++) {
      parent_elem[e] = fcm__space_cut_parent_elem(from, to, e);
      if (parent_elem[e] < 0) bad = FCM_MIN(bad, e);
    }
  }
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index fe =
        parent_elem ? (e < bad ? parent_elem[e] : -1) : fcm__space_cut_parent_elem(from, to, e);
    FCM_CHECK(fe >= 0, ctx, FCM_ERR_INTERNAL,
              "cut parents: element %lld (cell %lld) has its parent piece outside the cell's "
              "pieces in the source",
              (long long)e, (long long)to->elem_cell[e]);
    for (int a = 0; a < nn; a++) {
      const fcm_index k = to->elem_dof[e * nn + a] / 3;
      /* a constrained place holds another copy, which its own elements name */
      if ((to->elem_con && to->elem_con[e * nn + a]) || parent[k] >= 0) continue;
      parent[k] = from->elem_dof[fe * from->nn + a] / 3;
    }
  }
cleanup:
  return st;
}

/* 1 when arrays a and b of n items of size sz hold the same bits (both NULL when n is 0). */
static int same_bits(const void *a, const void *b, size_t n, size_t sz)
{
  return n == 0 || (a && b && memcmp(a, b, n * sz) == 0);
}

/* 1 when piece p of rules r and piece q of rules s integrate alike: the same points, weights
 * and flags of every rule kind both have, and the same surface rule. */
static int same_piece(const fcm_cell_rules *r, fcm_index p, const fcm_cell_rules *s, fcm_index q)
{
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    const fcm_rule_kind kind = (fcm_rule_kind)k;
    if (fcm_cell_rules_has_kind(r, kind) != fcm_cell_rules_has_kind(s, kind)) return 0;
    if (!fcm_cell_rules_has_kind(r, kind)) continue;
    int na = 0, nb = 0;
    const double *xa = NULL, *xb = NULL, *wa = NULL, *wb = NULL;
    const unsigned char *fa = NULL, *fb = NULL;
    fcm_cell_rules_get_piece(r, p, kind, &na, &xa, &wa, &fa);
    fcm_cell_rules_get_piece(s, q, kind, &nb, &xb, &wb, &fb);
    if (na != nb || !same_bits(xa, xb, 3 * (size_t)na, sizeof *xa) ||
        !same_bits(wa, wb, (size_t)na, sizeof *wa) || !same_bits(fa, fb, (size_t)na, sizeof *fa))
      return 0;
  }
  int na = 0, nb = 0;
  const double *xa = NULL, *xb = NULL, *wa = NULL, *wb = NULL, *ma = NULL, *mb = NULL;
  fcm_cell_rules_get_piece_surface(r, p, &na, &xa, &wa, &ma, NULL);
  fcm_cell_rules_get_piece_surface(s, q, &nb, &xb, &wb, &mb, NULL);
  return na == nb && same_bits(xa, xb, 3 * (size_t)na, sizeof *xa) &&
         same_bits(wa, wb, (size_t)na, sizeof *wa) && same_bits(ma, mb, 3 * (size_t)na, sizeof *ma);
}

fcm_status fcm__space_cut_same_elements(const fcm_space *from, const fcm_space *to, fcm_index *same,
                                        fcm_index *num_same)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to ? to->ctx : NULL;
  fcm_index count = 0;
  FCM_TRY(ctx, fcm__space_check_cut_pair(from, to, "cut elements"));
  FCM_CHECK(same, ctx, FCM_ERR_ARG, "cut elements: same is NULL");
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx)) schedule(dynamic, 64) \
    reduction(+ : count)
  for (fcm_index e = 0; e < to->num_elems; e++) {
    const fcm_index c = to->elem_cell[e];
    const fcm_cell_class ct = fcm_cell_rules_class(to->rules, c),
                         cf = fcm_cell_rules_class(from->rules, c);
    const fcm_index fe = fcm__space_cut_parent_elem(from, to, e);
    same[e] = -1;
    if (ct != cf || fe < 0) continue;
    /* an uncut cell integrates with the standard rule in both; a cut one with its piece's */
    /* a piece the cut copied from its parent has its parent's bits (no need to compare) */
    const fcm_index p = to->elem_piece[e], q = from->elem_piece[fe];
    if (ct == FCM_CELL_UNCUT ||
        (fcm__cell_rules_piece_copied(to->rules, p, from->rules) &&
         fcm_cell_rules_piece_parent(to->rules, p) == q) ||
        same_piece(to->rules, p, from->rules, q)) {
      same[e] = fe;
      count++;
    }
  }
  if (num_same) *num_same = count;
cleanup:
  return st;
}

fcm_status fcm__space_cut_ordering(const fcm_space *from, const fcm_space *to,
                                   const fcm_index *old_perm, fcm_index *perm)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to ? to->ctx : NULL;
  fcm_index *parent = NULL, *child_ptr = NULL, *child = NULL;
  FCM_TRY(ctx, fcm__space_check_cut_pair(from, to, "cut ordering"));
  FCM_CHECK(old_perm && perm, ctx, FCM_ERR_ARG, "cut ordering: NULL ordering");
  const fcm_index nold = from->num_dofs / 3, nnew = to->num_dofs / 3;
  FCM_ALLOC(ctx, nnew + 1, parent);
  FCM_ALLOC(ctx, nold + 2, child_ptr);
  FCM_ALLOC(ctx, nnew + 1, child);
  FCM_TRY(ctx, fcm__space_cut_parents(from, to, parent));
  /* the children of each old copy, ascending (counting sort over the parents) */
  for (fcm_index k = 0; k < nnew; k++)
    if (parent[k] >= 0) child_ptr[parent[k] + 2]++;
  for (fcm_index k = 0; k < nold; k++)
    child_ptr[k + 2] += child_ptr[k + 1];
  for (fcm_index k = 0; k < nnew; k++)
    if (parent[k] >= 0) child[child_ptr[parent[k] + 1]++] = k;
  /* each old DOF's place in the old ordering goes to its children's same component, in
   * ascending order; copies without a parent (none in a cut space) go last */
  fcm_index next = 0;
  for (fcm_index q = 0; q < 3 * nold; q++) {
    const fcm_index d = old_perm[q];
    FCM_CHECK(d >= 0 && d < 3 * nold, ctx, FCM_ERR_ARG,
              "cut ordering: old_perm[%lld] = %lld outside [0, %lld)", (long long)q, (long long)d,
              (long long)(3 * nold));
    for (fcm_index p = child_ptr[d / 3]; p < child_ptr[d / 3 + 1]; p++) {
      const fcm_index nd = 3 * child[p] + d % 3;
      FCM_CHECK(next < 3 * nnew, ctx, FCM_ERR_ARG,
                "cut ordering: old_perm places more than the new space's %lld DOFs: it is not "
                "a permutation of the old space's DOFs",
                (long long)(3 * nnew));
      perm[next++] = nd;
    }
  }
  for (fcm_index k = 0; k < nnew && next + 3 <= 3 * nnew; k++)
    if (parent[k] < 0)
      for (int i = 0; i < 3; i++)
        perm[next++] = 3 * k + i;
  FCM_CHECK(next == 3 * nnew, ctx, FCM_ERR_ARG,
            "cut ordering: old_perm places %lld of the new space's %lld DOFs: it is not a "
            "permutation of the old space's DOFs",
            (long long)next, (long long)(3 * nnew));
cleanup:
  fcm__free(ctx, parent);
  fcm__free(ctx, child_ptr);
  fcm__free(ctx, child);
  return st;
}

fcm_status fcm__space_cut_copy_map(const fcm_space *from, const fcm_space *to, fcm_index *old_copy,
                                   const fcm_index *graphs[4])
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to ? to->ctx : NULL;
  fcm_index *children = NULL;
  FCM_TRY(ctx, fcm__space_check_cut_pair(from, to, "cut copy map"));
  FCM_CHECK(old_copy && graphs, ctx, FCM_ERR_ARG, "cut copy map: NULL output");
  FCM_CHECK(!from->local_elem && !to->local_elem && from->node_ptr && from->node_adj &&
                to->node_ptr && to->node_adj,
            ctx, FCM_ERR_ARG,
            "cut copy map: both spaces must be full spaces with their copy graphs");
  const fcm_index nold = from->num_dofs / 3, nnew = to->num_dofs / 3;
  FCM_ALLOC(ctx, nold + 1, children);
  FCM_TRY(ctx, fcm__space_cut_parents(from, to, old_copy));
  for (fcm_index k = 0; k < nnew; k++)
    if (old_copy[k] >= 0) children[old_copy[k]]++;
  for (fcm_index k = 0; k < nnew; k++)
    if (old_copy[k] >= 0 && children[old_copy[k]] != 1) old_copy[k] = -1;
  graphs[0] = from->node_ptr, graphs[1] = from->node_adj;
  graphs[2] = to->node_ptr, graphs[3] = to->node_adj;
cleanup:
  fcm__free(ctx, children);
  return st;
}
