/* A cut space patched from the space before the cut (fcm__space_create_cut()) equals the space
 * built anew on the same rules, every array bit for bit. An embedded box is cut three times (a
 * plane, a partial rectangle from the top face ending inside the body, a plane across the first
 * into cells already cut), each cut space patched from the patched one before it; once with the
 * default constraint ratio and once with a large one that constrains tiny copies (Koschier). The
 * patch must take graph rows from the space before the cut (a tenth at least: not rebuild them),
 * and a space before the cut with one stale offset, two cells of its block order or two blocks
 * of different colours swapped, gives a different space (the offsets, the blocks and their
 * colours are taken where neither space has constrained copies, and the comparison sees them).
 * No piece counts as copied (fcm__cell_rules_piece_copied()) from rules its rules do not extend
 * (the same cut made again, the grandparent, the parent built anew: pieces alike; the parent made
 * with other bits), and the elements a cut leaves against the last are those a bitwise
 * comparison finds.
 * The spaces (and a local space) made on 1, 2 and 3 threads are the same bit for bit.
 * Usage: fem_cut_space <element> */
#include "fem/fem_impl.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;
static int block_colors_swapped; /* patches made from a space with two block colours swapped */

/* 1 when the n items of size sz at a and b hold the same bits. */
static int same(const void *a, const void *b, size_t n, size_t sz)
{
  return n == 0 || (a && b && memcmp(a, b, n * sz) == 0);
}

/* Every array of the two full spaces: numbering, graph, pattern, offsets, colours, blocks. */
static int same_space(const fcm_space *a, const fcm_space *b)
{
  const size_t I = sizeof(fcm_index), nn = (size_t)a->nn;
  const size_t nc = (size_t)a->num_cells, np = (size_t)a->num_nodes, ne = (size_t)a->num_elems;
  const size_t ncopy = (size_t)a->num_dofs / 3, nb = (size_t)a->num_blocks;
  if (a->nn != b->nn || a->num_dofs != b->num_dofs || a->num_elems != b->num_elems ||
      a->num_constrained != b->num_constrained || a->num_colors != b->num_colors ||
      a->num_block_colors != b->num_block_colors || a->max_cut_points != b->max_cut_points ||
      !a->elem_con != !b->elem_con || a->num_local_copies != b->num_local_copies ||
      a->num_local_elems != b->num_local_elems || a->num_blocks != b->num_blocks ||
      a->num_block_cells != b->num_block_cells)
    return 0;
  int ok = same(a->active, b->active, nc, 1) && same(a->node_dof, b->node_dof, np, I) &&
           same(a->node_ncopy, b->node_ncopy, np, I) &&
           same(a->cell_elem, b->cell_elem, nc + 1, I) && same(a->elem_cell, b->elem_cell, ne, I) &&
           same(a->elem_piece, b->elem_piece, ne, I) && same(a->elem_dof, b->elem_dof, ne * nn, I);
  ok = ok && (!a->elem_con || same(a->elem_con, b->elem_con, ne * nn, 1));
  ok = ok && same(a->node_ptr, b->node_ptr, ncopy + 1, I) &&
       same(a->node_adj, b->node_adj, (size_t)a->node_ptr[ncopy], I);
  ok = ok && same(a->row_ptr, b->row_ptr, 3 * ncopy + 1, I) &&
       same(a->col_idx, b->col_idx, (size_t)a->row_ptr[3 * ncopy], sizeof(int));
  ok = ok && same(a->elem_off, b->elem_off, ne * nn * nn, sizeof(int));
  ok = ok && same(a->color_ptr, b->color_ptr, (size_t)a->num_colors + 1, I) &&
       same(a->color_elems, b->color_elems, ne, I);
  ok = ok && same(a->block_color_ptr, b->block_color_ptr, (size_t)a->num_block_colors + 1, I) &&
       same(a->block_list, b->block_list, nb, I) && same(a->block_elems, b->block_elems, ne, I) &&
       same(a->block_ptr, b->block_ptr, nb + 1, I) &&
       same(a->block_cells, b->block_cells, (size_t)a->num_block_cells, I);
  return ok && !a->local_elem && !b->local_elem && !a->elem_lcopy && !b->elem_lcopy;
}

/* 1 when piece p of r and piece q of s hold the same bits: every volume rule kind's points,
 * weights and flags, and the surface rule's points, weights and normals. */
static int same_piece_bits(const fcm_cell_rules *r, fcm_index p, const fcm_cell_rules *s,
                           fcm_index q)
{
  int ok = 1;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    int na = 0, nb = 0;
    const double *xa = NULL, *xb = NULL, *wa = NULL, *wb = NULL;
    const unsigned char *fa = NULL, *fb = NULL;
    if (fcm_cell_rules_has_kind(r, (fcm_rule_kind)k) !=
        fcm_cell_rules_has_kind(s, (fcm_rule_kind)k))
      return 0;
    if (!fcm_cell_rules_has_kind(r, (fcm_rule_kind)k)) continue;
    fcm_cell_rules_get_piece(r, p, (fcm_rule_kind)k, &na, &xa, &wa, &fa);
    fcm_cell_rules_get_piece(s, q, (fcm_rule_kind)k, &nb, &xb, &wb, &fb);
    ok = ok && na == nb && same(xa, xb, 3 * (size_t)na, sizeof *xa) &&
         same(wa, wb, (size_t)na, sizeof *wa) && same(fa, fb, (size_t)na, 1);
  }
  int na = 0, nb = 0;
  const double *xa = NULL, *xb = NULL, *wa = NULL, *wb = NULL, *ma = NULL, *mb = NULL;
  fcm_cell_rules_get_piece_surface(r, p, &na, &xa, &wa, &ma, NULL);
  fcm_cell_rules_get_piece_surface(s, q, &nb, &xb, &wb, &mb, NULL);
  return ok && na == nb && same(xa, xb, 3 * (size_t)na, sizeof *xa) &&
         same(wa, wb, (size_t)na, sizeof *wa) && same(ma, mb, 3 * (size_t)na, sizeof *ma);
}

/* The elements the cut left (fcm__space_cut_same_elements()) with the pieces the cut copied
 * taken as such (fcm__cell_rules_piece_copied()) are those found by comparing every piece's
 * bits; every copied piece holds its parent's bits, some do, and none is copied from the rules
 * themselves (other rules they do not extend: run_copied()). Returns the elements the cut
 * left. */
static fcm_index check_same_elements(const fcm_space *from, const fcm_space *to)
{
  fcm_cell_rules *r = (fcm_cell_rules *)to->rules;
  const fcm_index ne = to->num_elems;
  fcm_index *fast = malloc(sizeof *fast * (size_t)ne + 1),
            *slow = malloc(sizeof *slow * (size_t)ne + 1);
  fcm_index nfast = -1, nslow = -2, copied = 0;
  TEST_OK(ctx, fcm__space_cut_same_elements(from, to, fast, &nfast));
  unsigned char *flags = r->piece_copied;
  r->piece_copied = NULL; /* compared bit for bit */
  TEST_OK(ctx, fcm__space_cut_same_elements(from, to, slow, &nslow));
  r->piece_copied = flags;
  TEST_TRUE(nfast == nslow && same(fast, slow, (size_t)ne, sizeof *fast));
  TEST_TRUE(flags != NULL);
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(r); p++) {
    TEST_TRUE(!fcm__cell_rules_piece_copied(r, p, r));
    if (!fcm__cell_rules_piece_copied(r, p, from->rules)) continue;
    TEST_TRUE(same_piece_bits(r, p, from->rules, fcm_cell_rules_piece_parent(r, p)));
    copied += fcm_cell_rules_class(r, fcm_cell_rules_piece_cell(r, p)) == FCM_CELL_CUT;
  }
  TEST_TRUE(copied > 0 && nfast > 0 && nfast < ne);
  free(fast);
  free(slow);
  return nfast;
}

/* The three cuts on the box, each space patched from the last; ratio: the constraint ratio.
 * Returns the constrained copies of the last space. */
static fcm_index run(const fcm_mesh *mesh, const fcm_geometry *g, double ratio)
{
  fcm_space_options so = fcm_space_options_default();
  so.constrain_ratio = ratio;
  fcm_cell_rules *rules[4] = {NULL, NULL, NULL, NULL};
  fcm_space *space[4] = {NULL, NULL, NULL, NULL};
  fcm_index constrained = 0;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, rules[0], &so, &space[0]));
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  const double c2[3] = {0.73, 0.55, 0.3}, n2[3] = {1.0, 0.0, 0.1}, a2[3] = {0.0, 1.0, 0.0},
               size2[2] = {0.5, 2.0};
  const double p3[3] = {0.5, 0.33, 0.3}, n3[3] = {0.04, 1.0, 0.02};
  for (int k = 1; k <= 3 && space[k - 1]; k++) {
    fcm_surface *cut = NULL;
    fcm_space *fresh = NULL;
    if (k == 1) TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &cut));
    if (k == 2) TEST_OK(ctx, fcm_surface_create_rectangle(ctx, c2, n2, a2, size2, &cut));
    if (k == 3) TEST_OK(ctx, fcm_surface_create_plane(ctx, p3, n3, box_lo, box_hi, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &rules[k]));
    fcm_surface_destroy(&cut);
    if (!rules[k]) break;
    TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[k], &so, space[k - 1], &space[k]));
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, rules[k], &so, &fresh));
    if (space[k] && fresh) {
      const fcm_index rows = space[k]->num_dofs / 3;
      printf("ratio %g cut %d: %lld -> %lld DOFs, %lld constrained, %lld of %lld rows kept\n",
             ratio, k, (long long)space[k - 1]->num_dofs, (long long)space[k]->num_dofs,
             (long long)space[k]->num_constrained, (long long)space[k]->cut_kept_rows,
             (long long)rows);
      TEST_TRUE(space[k]->num_dofs > space[k - 1]->num_dofs);
      TEST_TRUE(same_space(space[k], fresh));
      check_same_elements(space[k - 1], space[k]);
      /* the patch took rows away from the cut and made the cut's own anew */
      TEST_TRUE(space[k]->cut_kept_rows >= rows / 10 && space[k]->cut_kept_rows < rows);
      TEST_TRUE(fresh->cut_kept_rows == 0);
      constrained = space[k]->num_constrained;
      /* a stale offset of a kept element in the space before the cut shows in the patch */
      int *off = space[k - 1]->elem_off;
      const fcm_index ne = space[k - 1]->num_elems;
      fcm_index e0 = -1;
      double best = HUGE_VAL, X[3 * FCM_ELEMENT_MAX_NODES];
      for (fcm_index e = 0; e < ne; e++) { /* the element nearest the origin, far from the cuts */
        fcm_mesh_cell_coords(mesh, space[k - 1]->elem_cell[e], X);
        if (X[0] + X[1] + X[2] < best) best = X[0] + X[1] + X[2], e0 = e;
      }
      TEST_TRUE(e0 >= 0);
      if (e0 >= 0) {
        fcm_space *stale = NULL;
        const int nn2 = space[k - 1]->nn * space[k - 1]->nn, keep = off[e0 * nn2 + 1];
        off[e0 * nn2 + 1] = keep + 1;
        TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[k], &so, space[k - 1], &stale));
        TEST_TRUE(stale && !same_space(stale, fresh));
        off[e0 * nn2 + 1] = keep;
        fcm_space_destroy(&stale);
      }
      /* the blocks and their colours are taken from the space before the cut where neither
       * space has constrained copies (the active cells are the same): two of its block cells
       * swapped, or two blocks of different colours, show in the patch */
      const int keep = !space[k - 1]->elem_con && !space[k]->elem_con;
      TEST_TRUE(space[k]->blocks_kept == keep && !fresh->blocks_kept);
      fcm_space *swapped = NULL;
      if (keep) {
        fcm_index *order = space[k - 1]->block_cells, *bl = space[k - 1]->block_list;
        const fcm_index nbc = space[k - 1]->num_block_cells, c0 = order[0], c1 = order[nbc - 1];
        order[0] = c1, order[nbc - 1] = c0;
        TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[k], &so, space[k - 1], &swapped));
        TEST_TRUE(swapped && !same(swapped->block_elems, fresh->block_elems,
                                   (size_t)fresh->num_elems, sizeof(fcm_index)));
        order[0] = c0, order[nbc - 1] = c1;
        fcm_space_destroy(&swapped);
        if (space[k - 1]->num_block_colors > 1) { /* the tets' boxes have several blocks */
          const fcm_index i1 = space[k - 1]->block_color_ptr[1], b0 = bl[0], b1 = bl[i1];
          bl[0] = b1, bl[i1] = b0;
          TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[k], &so, space[k - 1], &swapped));
          TEST_TRUE(swapped && !same_space(swapped, fresh));
          bl[0] = b0, bl[i1] = b1;
          fcm_space_destroy(&swapped);
          block_colors_swapped++;
        }
      }
      /* the colours of the elements away from the cut are taken too: the first elements of
       * colours 0 and 1 (at the corner at the origin) swapped show in the patch; the third cut
       * runs along the body within reach of every element */
      fcm_index *ce = space[k - 1]->color_elems, *cp = space[k - 1]->color_ptr;
      TEST_TRUE(space[k - 1]->num_colors > 1);
      if (k < 3 && space[k - 1]->num_colors > 1) {
        const fcm_index c0 = ce[cp[0]], c1 = ce[cp[1]];
        ce[cp[0]] = c1, ce[cp[1]] = c0;
        TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[k], &so, space[k - 1], &swapped));
        TEST_TRUE(swapped && !same(swapped->color_elems, fresh->color_elems,
                                   (size_t)fresh->num_elems, sizeof(fcm_index)));
        ce[cp[0]] = c0, ce[cp[1]] = c1;
        fcm_space_destroy(&swapped);
      }
    }
    fcm_space_destroy(&fresh);
  }
  /* an unrelated space before (the rules of the same cut, not their parent): built anew */
  if (space[2] && rules[3]) {
    fcm_space *s = NULL, *fresh = NULL;
    TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[2], &so, space[2], &s));
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, rules[2], &so, &fresh));
    TEST_TRUE(s && fresh && s->cut_kept_rows == 0 && same_space(s, fresh));
    fcm_space_destroy(&s);
    fcm_space_destroy(&fresh);
  }
  for (int k = 3; k >= 0; k--) {
    fcm_space_destroy(&space[k]);
    fcm_cell_rules_destroy(&rules[k]);
  }
  return constrained;
}

/* The chain of cut spaces made with fcm__space_create_cut_take(): each the fresh space's bits,
 * its columns in the block of the space before it where they fit (that space has none then and
 * makes no matrix), and a cut space destroyed before it keeps its block gives it back with the
 * columns as they were. Returns the cuts whose space took the block. */
static int run_take(const fcm_mesh *mesh, const fcm_geometry *g)
{
  const fcm_space_options so = fcm_space_options_default();
  fcm_cell_rules *rules[4] = {NULL, NULL, NULL, NULL};
  fcm_space *space[4] = {NULL, NULL, NULL, NULL};
  int taken = 0;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, rules[0], &so, &space[0]));
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  const double c2[3] = {0.73, 0.55, 0.3}, n2[3] = {1.0, 0.0, 0.1}, a2[3] = {0.0, 1.0, 0.0},
               size2[2] = {0.5, 2.0};
  const double p3[3] = {0.5, 0.33, 0.3}, n3[3] = {0.04, 1.0, 0.02};
  for (int k = 1; k <= 3 && space[k - 1]; k++) {
    fcm_surface *cut = NULL;
    fcm_space *fresh = NULL, *gone = NULL, *prev = space[k - 1];
    if (k == 1) TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &cut));
    if (k == 2) TEST_OK(ctx, fcm_surface_create_rectangle(ctx, c2, n2, a2, size2, &cut));
    if (k == 3) TEST_OK(ctx, fcm_surface_create_plane(ctx, p3, n3, box_lo, box_hi, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &rules[k]));
    fcm_surface_destroy(&cut);
    if (!rules[k]) break;
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, rules[k], &so, &fresh));
    const int *block = prev->col_idx;
    const size_t nnz = (size_t)prev->row_ptr[prev->num_dofs];
    int *cols = malloc(sizeof *cols * (nnz + 1));
    memcpy(cols, block, sizeof *cols * nnz);
    /* a cut space destroyed (a failed cut): the block and its columns back */
    TEST_OK(ctx, fcm__space_create_cut_take(ctx, mesh, rules[k], &so, prev, &gone));
    TEST_TRUE(gone && same_space(gone, fresh));
    const int took = gone && gone->col_from == prev;
    if (took) TEST_TRUE(gone->col_idx == block && prev->col_idx == NULL);
    fcm_space_destroy(&gone);
    TEST_TRUE(prev->col_idx == block && same(prev->col_idx, cols, nnz, sizeof *cols));
    /* the cut space kept */
    TEST_OK(ctx, fcm__space_create_cut_take(ctx, mesh, rules[k], &so, prev, &space[k]));
    if (space[k] && fresh) {
      TEST_TRUE(same_space(space[k], fresh));
      TEST_TRUE((space[k]->col_idx == block) == took);
      if (took) {
        fcm_csr *A = NULL;
        TEST_ERR(ctx, fcm_space_matrix_create(prev, &A), FCM_ERR_ARG, "pattern went to");
        TEST_TRUE(A == NULL);
        taken++;
      }
      fcm__space_cut_keep(space[k]);
      printf("take cut %d: %lld -> %lld DOFs, block %s\n", k, (long long)prev->num_dofs,
             (long long)space[k]->num_dofs, took ? "taken" : "new");
    }
    free(cols);
    fcm_space_destroy(&fresh);
  }
  for (int k = 3; k >= 0; k--) {
    fcm_space_destroy(&space[k]);
    fcm_cell_rules_destroy(&rules[k]);
  }
  return taken;
}

/* The local topology's arrays of two local spaces (copies, elements, graph, pattern, offsets,
 * colours). */
static int same_local(const fcm_space *a, const fcm_space *b)
{
  const size_t I = sizeof(fcm_index), nn = (size_t)a->nn;
  const size_t nl = (size_t)a->num_local_copies, nle = (size_t)a->num_local_elems;
  if (a->num_local_copies != b->num_local_copies || a->num_local_elems != b->num_local_elems ||
      a->num_colors != b->num_colors || a->num_dofs != b->num_dofs || !a->node_ptr || !b->node_ptr)
    return 0;
  return same(a->local_copy, b->local_copy, nl, I) && same(a->local_elem, b->local_elem, nle, I) &&
         same(a->node_ptr, b->node_ptr, nl + 1, I) &&
         same(a->node_adj, b->node_adj, (size_t)a->node_ptr[nl], I) &&
         same(a->row_ptr, b->row_ptr, 3 * nl + 1, I) &&
         same(a->col_idx, b->col_idx, (size_t)a->row_ptr[3 * nl], sizeof(int)) &&
         same(a->elem_off, b->elem_off, nle * nn * nn, sizeof(int)) &&
         same(a->elem_lcopy, b->elem_lcopy, nle * nn, sizeof(int)) &&
         same(a->color_ptr, b->color_ptr, (size_t)a->num_colors + 1, I) &&
         same(a->color_elems, b->color_elems, nle, I);
}

/* The spaces of the three cuts (each patched from the last; ratio: the constraint ratio) and a
 * local space of the last cut's rules made on 1, 2 and 3 threads are the same bit for bit.
 * Returns the cut spaces compared. */
static int run_threads(const fcm_mesh *mesh, const fcm_geometry *g, double ratio)
{
  fcm_space_options so = fcm_space_options_default();
  so.constrain_ratio = ratio;
  fcm_cell_rules *rules[4] = {NULL, NULL, NULL, NULL};
  fcm_space *space[3][4] = {{NULL}}, *local[3] = {NULL, NULL, NULL};
  int compared = 0;
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  const double c2[3] = {0.73, 0.55, 0.3}, n2[3] = {1.0, 0.0, 0.1}, a2[3] = {0.0, 1.0, 0.0},
               size2[2] = {0.5, 2.0};
  const double p3[3] = {0.5, 0.33, 0.3}, n3[3] = {0.04, 1.0, 0.02};
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  for (int k = 1; k <= 3 && rules[k - 1]; k++) {
    fcm_surface *cut = NULL;
    if (k == 1) TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &cut));
    if (k == 2) TEST_OK(ctx, fcm_surface_create_rectangle(ctx, c2, n2, a2, size2, &cut));
    if (k == 3) TEST_OK(ctx, fcm_surface_create_plane(ctx, p3, n3, box_lo, box_hi, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &rules[k]));
    fcm_surface_destroy(&cut);
  }
  const fcm_index ncells = fcm_mesh_num_cells(mesh);
  unsigned char *mask = calloc((size_t)ncells, 1);
  for (fcm_index c = 0; mask && c < ncells; c += 2) /* every other cell: a local space */
    mask[c] = 1;
  for (int t = 0; t < 3; t++) {
    TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, t + 1));
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, rules[0], &so, &space[t][0]));
    for (int k = 1; k <= 3 && rules[k] && space[t][k - 1]; k++)
      TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[k], &so, space[t][k - 1], &space[t][k]));
    if (rules[3])
      TEST_OK(ctx, fcm__space_create_local(ctx, mesh, NULL, rules[3], &so, mask, &local[t]));
  }
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, FCM_DEFAULT));
  for (int t = 1; t < 3; t++) {
    for (int k = 0; k <= 3; k++) {
      TEST_TRUE(space[0][k] && space[t][k] && same_space(space[0][k], space[t][k]));
      compared += k > 0 && space[0][k] && space[t][k];
    }
    TEST_TRUE(local[0] && local[t] && same_local(local[0], local[t]));
  }
  TEST_TRUE(space[0][3] && space[0][3]->cut_kept_rows > 0); /* the patch was exercised */
  for (int t = 0; t < 3; t++) {
    fcm_space_destroy(&local[t]);
    for (int k = 3; k >= 0; k--)
      fcm_space_destroy(&space[t][k]);
  }
  for (int k = 3; k >= 0; k--)
    fcm_cell_rules_destroy(&rules[k]);
  free(mask);
  return compared;
}

/* No piece counts as copied from rules its rules do not extend (fcm__cell_rules_piece_copied()
 * names the rules extended), though their pieces hold the same bits: over the three cuts, not
 * from the same cut made again on the parent (its pieces bit for bit the cut's), not from the
 * grandparent, not from the parent built anew (its bits the parent's) nor from rules of the same
 * pieces with other bits (the parent's chain made with a stiffness strength one lower). The
 * elements the cut left, found from a space on the latter (fcm__space_cut_same_elements()),
 * are those found by comparing every piece's bits, though some of them hold pieces copied from
 * the parent: taken as copied, they would be kept. Returns the cuts checked. */
static int run_copied(const fcm_mesh *mesh, const fcm_geometry *g, fcm_element_type type)
{
  const fcm_space_options so = fcm_space_options_default();
  /* stiffness rules only (the mass rules' fits would take most of the time) */
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.kinds = FCM_RULES_STIFFNESS;
  fcm_cell_rules_options other = ro;
  other.strength[FCM_RULE_STIFFNESS] = fcm_element_get_info(type)->stiffness_strength - 1;
  fcm_cell_rules *rules[4] = {NULL}, *alike[4] = {NULL}, *twin[4] = {NULL}, *anew = NULL,
                 *anew_cut = NULL;
  fcm_space *space[4] = {NULL}, *alike_space[4] = {NULL};
  int checked = 0;
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  const double c2[3] = {0.73, 0.55, 0.3}, n2[3] = {1.0, 0.0, 0.1}, a2[3] = {0.0, 1.0, 0.0},
               size2[2] = {0.5, 2.0};
  const double p3[3] = {0.5, 0.33, 0.3}, n3[3] = {0.04, 1.0, 0.02};
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &ro, &rules[0]));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &other, &alike[0]));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &ro, &anew));
  for (int k = 1; k <= 3 && rules[k - 1] && alike[k - 1]; k++) {
    fcm_surface *cut = NULL;
    if (k == 1) TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &cut));
    if (k == 2) TEST_OK(ctx, fcm_surface_create_rectangle(ctx, c2, n2, a2, size2, &cut));
    if (k == 3) TEST_OK(ctx, fcm_surface_create_plane(ctx, p3, n3, box_lo, box_hi, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &rules[k]));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &twin[k]));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, alike[k - 1], cut, &alike[k]));
    if (k == 1 && anew) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, anew, cut, &anew_cut));
    fcm_surface_destroy(&cut);
  }
  for (int k = 0; k <= 3; k++) {
    if (rules[k]) TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, rules[k], &so, &space[k]));
    if (alike[k])
      TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, alike[k], &so, &alike_space[k]));
  }
  for (int k = 1; k <= 3 && rules[k] && twin[k] && alike[k] && space[k] && alike_space[k - 1];
       k++) {
    const fcm_cell_rules *r = rules[k], *parent = rules[k - 1];
    const fcm_index np = fcm_cell_rules_num_pieces(r);
    fcm_index copied = 0, twin_alike = 0;
    TEST_TRUE(fcm_cell_rules_num_pieces(twin[k]) == np &&
              fcm_cell_rules_num_pieces(alike[k - 1]) == fcm_cell_rules_num_pieces(parent));
    for (fcm_index p = 0; p < np; p++) {
      const int c = fcm__cell_rules_piece_copied(r, p, parent);
      copied += c;
      /* the same cut made again on the parent: the same pieces, the same bits, copied from
       * the parent alike, but neither copied from the other */
      twin_alike += same_piece_bits(r, p, twin[k], p);
      TEST_TRUE(fcm__cell_rules_piece_copied(twin[k], p, parent) == c);
      TEST_TRUE(!fcm__cell_rules_piece_copied(r, p, twin[k]) &&
                !fcm__cell_rules_piece_copied(twin[k], p, r));
      TEST_TRUE(!fcm__cell_rules_piece_copied(r, p, alike[k - 1]));
      if (k >= 2) TEST_TRUE(!fcm__cell_rules_piece_copied(r, p, rules[k - 2]));
      if (k == 1 && anew_cut) { /* the parent built anew: its own cut copies from it */
        TEST_TRUE(!fcm__cell_rules_piece_copied(r, p, anew));
        TEST_TRUE(fcm__cell_rules_piece_copied(anew_cut, p, anew) == c);
        TEST_TRUE(same_piece_bits(parent, fcm_cell_rules_piece_parent(r, p), anew,
                                  fcm_cell_rules_piece_parent(r, p)));
      }
    }
    TEST_TRUE(copied > 0 && twin_alike == np);
    /* a space on rules with the parent's pieces but not its bits: only the uncut elements and
     * the cut pieces whose bits happen to agree are left, as a bitwise comparison finds */
    const fcm_space *from = alike_space[k - 1], *to = space[k];
    const fcm_index ne = to->num_elems;
    fcm_index *fast = malloc(sizeof *fast * (size_t)ne + 1),
              *slow = malloc(sizeof *slow * (size_t)ne + 1);
    fcm_index nfast = -1, nslow = -2, wrong = 0;
    TEST_OK(ctx, fcm__space_cut_same_elements(from, to, fast, &nfast));
    fcm_cell_rules *rw = (fcm_cell_rules *)r;
    unsigned char *flags = rw->piece_copied;
    rw->piece_copied = NULL; /* compared bit for bit */
    TEST_OK(ctx, fcm__space_cut_same_elements(from, to, slow, &nslow));
    rw->piece_copied = flags;
    TEST_TRUE(nfast == nslow && same(fast, slow, (size_t)ne, sizeof *fast));
    for (fcm_index e = 0; e < ne; e++) { /* copied cut pieces the bitwise comparison rejects */
      const fcm_index p = to->elem_piece[e];
      wrong += fcm_cell_rules_class(r, to->elem_cell[e]) == FCM_CELL_CUT &&
               fcm__cell_rules_piece_copied(r, p, parent) && slow[e] < 0;
    }
    TEST_TRUE(wrong > 0 && nslow > 0);
    printf("copied cut %d: %lld of %lld pieces copied; from other bits %lld of %lld elements "
           "left, %lld copied cut pieces not\n",
           k, (long long)copied, (long long)np, (long long)nslow, (long long)ne, (long long)wrong);
    free(fast);
    free(slow);
    checked++;
  }
  for (int k = 3; k >= 0; k--) {
    fcm_space_destroy(&space[k]);
    fcm_space_destroy(&alike_space[k]);
    fcm_cell_rules_destroy(&rules[k]);
    fcm_cell_rules_destroy(&alike[k]);
    fcm_cell_rules_destroy(&twin[k]);
  }
  fcm_cell_rules_destroy(&anew_cut);
  fcm_cell_rules_destroy(&anew);
  return checked;
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-0.3, -0.3, -0.3}, hi[3] = {1.3, 0.9, 0.9};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  const fcm_index nc[3] = {10, 8, 8}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  run(mesh, g, fcm_space_options_default().constrain_ratio);
  TEST_TRUE(run(mesh, g, 0.2) > 0); /* tiny copies constrained */
  /* the tets' active cells make several blocks (the hexahedra's fit in one) */
  if (fcm_element_get_info(type)->num_corners == 4) TEST_TRUE(block_colors_swapped > 0);
  TEST_TRUE(run_take(mesh, g) >= 2); /* the third cut adds more than the room */
  TEST_TRUE(run_copied(mesh, g, type) == 3);
  TEST_TRUE(run_threads(mesh, g, fcm_space_options_default().constrain_ratio) == 6);
  TEST_TRUE(run_threads(mesh, g, 0.2) == 6);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
