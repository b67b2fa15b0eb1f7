/* Finite element space: active nodes, DOF numbering, the node graph and scalar
 * CSR pattern built once, per-cell scatter offsets, and the cell colouring. */
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* qsort comparator for fcm_index. */
static int cmp_index(const void *a, const void *b)
{
  fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

/* Node -> elements incidence as CSR: inc_ptr[num_nodes+1], inc (ascending elements). */
static fcm_status build_incidence(fcm_space *s, fcm_index **inc_ptr, fcm_index **inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  fcm_index *ptr = NULL, *list = NULL, *fill = NULL;
  FCM_ALLOC(ctx, s->num_nodes + 1, ptr);
  for (fcm_index e = 0; e < s->num_elems; e++)
    for (int a = 0; a < s->nn; a++)
      ptr[cells[s->elem_cell[e] * s->nn + a] + 1]++;
  for (fcm_index n = 0; n < s->num_nodes; n++)
    ptr[n + 1] += ptr[n];
  FCM_ALLOC(ctx, ptr[s->num_nodes], list);
  FCM_ALLOC(ctx, s->num_nodes, fill);
  for (fcm_index e = 0; e < s->num_elems; e++)
    for (int a = 0; a < s->nn; a++) {
      fcm_index n = cells[s->elem_cell[e] * s->nn + a];
      list[ptr[n] + fill[n]++] = e;
    }
  *inc_ptr = ptr;
  *inc = list;
  ptr = list = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, list);
  fcm__free(ctx, fill);
  return st;
}

/* The elements: one per piece of every active cell (a space without rules: one per active
 * cell, with the standard rule). */
static fcm_status build_elements(fcm_space *s)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_index ne = 0;
  FCM_ALLOC(ctx, s->num_cells + 1, s->cell_elem);
  for (fcm_index c = 0; c < s->num_cells; c++) {
    fcm_index k = s->active[c];
    if (s->rules && s->active[c]) k = fcm_cell_rules_cell_pieces(s->rules, c, NULL);
    s->cell_elem[c + 1] = s->cell_elem[c] + k;
  }
  ne = s->num_elems = s->cell_elem[s->num_cells];
  FCM_ALLOC(ctx, ne + 1, s->elem_cell);
  FCM_ALLOC(ctx, ne + 1, s->elem_piece);
  FCM_ALLOC(ctx, (size_t)ne * s->nn + 1, s->elem_dof);
  for (fcm_index c = 0; c < s->num_cells; c++) {
    fcm_index first = 0;
    if (s->rules) fcm_cell_rules_cell_pieces(s->rules, c, &first);
    for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++) {
      s->elem_cell[e] = c;
      s->elem_piece[e] = s->rules ? first + (e - s->cell_elem[c]) : -1;
    }
  }
cleanup:
  return st;
}

static fcm_index uf_find(fcm_index *uf, fcm_index a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return a;
}

/* Generalized enrichment (Ton-That et al. 2024, XFEM): the elements incident to a node
 * (its support) are grouped into connected components along the links of the cell rules
 * (pieces of face-neighbouring cells that share a face part not lying on a cut); each
 * component gets its own copy of the node. Where every incident cell has one piece, the
 * node has one copy. Copies are numbered node by node, components by their first element;
 * elem_dof gets the copy each element uses. */
static fcm_status build_copies(fcm_space *s, const fcm_index *inc_ptr, const fcm_index *inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  const fcm_index nl = s->rules ? fcm_cell_rules_num_links(s->rules) : 0;
  const fcm_index *links = s->rules ? fcm_cell_rules_links(s->rules) : NULL;
  fcm_index *uf = NULL, *comp = NULL, *pos = NULL, ncopy = 0, maxdeg = 0;
  FCM_ALLOC(ctx, s->num_nodes, s->node_ncopy);
  for (fcm_index n = 0; n < s->num_nodes; n++)
    maxdeg = FCM_MAX(maxdeg, inc_ptr[n + 1] - inc_ptr[n]);
  FCM_ALLOC(ctx, maxdeg + 1, uf);
  FCM_ALLOC(ctx, maxdeg + 1, comp);
  FCM_ALLOC(ctx, s->num_elems + 1, pos);
  for (fcm_index e = 0; e < s->num_elems; e++)
    pos[e] = -1;
  for (fcm_index n = 0; n < s->num_nodes; n++) {
    const fcm_index i0 = inc_ptr[n], deg = inc_ptr[n + 1] - i0;
    s->node_dof[n] = -1;
    if (deg == 0) continue;
    int split = 0;
    for (fcm_index i = 0; i < deg; i++) {
      const fcm_index e = inc[i0 + i], c = s->elem_cell[e];
      /* cuts reach the node's support: a cell split into pieces, a piece with a face on a
       * cut (a cut along cell faces splits no cell but separates them), or a cell a cut
       * passes near: the material of the support can be connected only through cells
       * outside it (around a hole), and a cut elsewhere can sever that; the links are
       * known around every such cell */
      split |=
          s->cell_elem[c + 1] - s->cell_elem[c] > 1 ||
          (s->rules && s->rules->reached && s->rules->reached[c]) ||
          (s->rules && fcm_cell_rules_get_piece_cut_faces(s->rules, s->elem_piece[e], NULL) > 0);
      uf[i] = i;
      pos[e] = i;
    }
    fcm_index k = 1;
    if (split) {
      for (fcm_index i = 0; i < deg; i++) {
        /* links (p, q) with p the piece of this element: binary search for the first */
        const fcm_index p = s->elem_piece[inc[i0 + i]];
        fcm_index lo = 0, hi = nl;
        while (lo < hi) {
          const fcm_index mid = lo + (hi - lo) / 2;
          if (links[2 * mid] < p)
            lo = mid + 1;
          else
            hi = mid;
        }
        for (fcm_index l = lo; l < nl && links[2 * l] == p; l++) {
          /* the element of piece q: pieces and elements of a cell are in the same order */
          const fcm_index q = links[2 * l + 1];
          const fcm_index cq = fcm_cell_rules_piece_cell(s->rules, q);
          fcm_index fq;
          fcm_cell_rules_cell_pieces(s->rules, cq, &fq);
          const fcm_index eq = s->cell_elem[cq] + (q - fq);
          if (pos[eq] < 0) continue; /* not in this node's support */
          const fcm_index ra = uf_find(uf, i), rb = uf_find(uf, pos[eq]);
          if (ra != rb) uf[FCM_MAX(ra, rb)] = FCM_MIN(ra, rb);
        }
      }
      k = 0;
      for (fcm_index i = 0; i < deg; i++) {
        const fcm_index r = uf_find(uf, i);
        comp[i] = r == i ? k++ : comp[r];
      }
    } else {
      for (fcm_index i = 0; i < deg; i++)
        comp[i] = 0;
    }
    s->node_ncopy[n] = k;
    s->node_dof[n] = 3 * ncopy;
    for (fcm_index i = 0; i < deg; i++) {
      const fcm_index e = inc[i0 + i];
      for (int a = 0; a < s->nn; a++)
        if (cells[s->elem_cell[e] * s->nn + a] == n)
          s->elem_dof[e * s->nn + a] = 3 * (ncopy + comp[i]);
      pos[e] = -1;
    }
    ncopy += k;
  }
  s->num_dofs = 3 * ncopy;
cleanup:
  fcm__free(ctx, uf);
  fcm__free(ctx, comp);
  fcm__free(ctx, pos);
  return st;
}

/* The element at local position le (a full space: le itself). */
static fcm_index local_elem(const fcm_space *s, fcm_index le)
{
  return s->local_elem ? s->local_elem[le] : le;
}

/* Copy -> elements incidence over the local topology: for each of the num_local_copies copies,
 * the local positions of the local elements using it at any local node (ascending, each once),
 * as CSR. g2l maps a copy rank to its local position (NULL: the identity, a full space). */
static fcm_status build_copy_incidence(fcm_space *s, const fcm_index *g2l, fcm_index **ptr_out,
                                       fcm_index **list_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_local_copies, nn = s->nn;
  fcm_index *ptr = NULL, *list = NULL, *fill = NULL;
  FCM_ALLOC(ctx, ncopy + 1, ptr);
  FCM_ALLOC(ctx, ncopy + 1, fill);
  for (int pass = 0; pass < 2; pass++) {
    for (fcm_index le = 0; le < s->num_local_elems; le++) {
      const fcm_index *ed = s->elem_dof + local_elem(s, le) * nn;
      for (int a = 0; a < nn; a++) {
        const fcm_index k = g2l ? g2l[ed[a] / 3] : ed[a] / 3;
        int dup = 0; /* an element may use a copy at two local nodes (constrained copies) */
        for (int b = 0; b < a && !dup; b++)
          dup = ed[b] / 3 == ed[a] / 3;
        if (dup) continue;
        if (pass)
          list[ptr[k] + fill[k]++] = le;
        else
          ptr[k + 1]++;
      }
    }
    if (!pass) {
      for (fcm_index k = 0; k < ncopy; k++)
        ptr[k + 1] += ptr[k];
      FCM_ALLOC(ctx, ptr[ncopy] + 1, list);
    }
  }
  *ptr_out = ptr, *list_out = list;
  ptr = list = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, list);
  fcm__free(ctx, fill);
  return st;
}

/* Copy graph over the local topology: for each local copy, the ranks (global) of the copies
 * sharing a local element with it, sorted. */
static fcm_status build_node_graph(fcm_space *s, const fcm_index *g2l, const fcm_index *cptr,
                                   const fcm_index *cinc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_local_copies, nn = s->nn;
  fcm_index *mark = NULL;
  FCM_ALLOC(ctx, ncopy + 1, mark);
  FCM_ALLOC(ctx, ncopy + 1, s->node_ptr);
  for (int pass = 0; pass < 2; pass++) {
    for (fcm_index k = 0; k < ncopy; k++)
      mark[k] = -1;
    for (fcm_index k = 0; k < ncopy; k++) {
      fcm_index cnt = 0, base = pass ? s->node_ptr[k] : 0;
      for (fcm_index i = cptr[k]; i < cptr[k + 1]; i++) {
        const fcm_index e = local_elem(s, cinc[i]);
        for (int b = 0; b < nn; b++) {
          const fcm_index m = s->elem_dof[e * nn + b] / 3, lm = g2l ? g2l[m] : m;
          if (mark[lm] == k) continue;
          mark[lm] = k;
          if (pass) s->node_adj[base + cnt] = m;
          cnt++;
        }
      }
      if (pass)
        qsort(s->node_adj + base, (size_t)cnt, sizeof *s->node_adj, cmp_index);
      else
        s->node_ptr[k + 1] = cnt;
    }
    if (!pass) {
      for (fcm_index k = 0; k < ncopy; k++)
        s->node_ptr[k + 1] += s->node_ptr[k];
      FCM_ALLOC(ctx, s->node_ptr[ncopy] + 1, s->node_adj);
    }
  }
cleanup:
  fcm__free(ctx, mark);
  return st;
}

/* Scalar pattern from the copy graph (the three rows of each local copy; global columns), and
 * the offsets of the local elements (and, for a local space, their copies' local positions). */
static fcm_status build_pattern(fcm_space *s, const fcm_index *g2l)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index nact = s->num_local_copies, nrow = 3 * nact;
  FCM_ALLOC(ctx, nrow + 1, s->row_ptr);
  for (fcm_index k = 0; k < nact; k++) {
    fcm_index deg = s->node_ptr[k + 1] - s->node_ptr[k];
    for (int i = 0; i < 3; i++)
      s->row_ptr[3 * k + i + 1] = s->row_ptr[3 * k + i] + 3 * deg;
  }
  FCM_ALLOC(ctx, s->row_ptr[nrow], s->col_idx);
  for (fcm_index k = 0; k < nact; k++)
    for (int i = 0; i < 3; i++) {
      int *cols = s->col_idx + s->row_ptr[3 * k + i];
      for (fcm_index e = s->node_ptr[k]; e < s->node_ptr[k + 1]; e++)
        for (int j = 0; j < 3; j++)
          *cols++ = (int)(3 * s->node_adj[e] + j);
    }
  FCM_ALLOC(ctx, (size_t)s->num_local_elems * s->nn * s->nn + 1, s->elem_off);
  if (g2l) FCM_ALLOC(ctx, (size_t)s->num_local_elems * s->nn + 1, s->elem_lcopy);
  for (fcm_index el = 0; el < s->num_local_elems; el++) {
    const fcm_index *ed = s->elem_dof + local_elem(s, el) * s->nn;
    int *off = s->elem_off + (size_t)el * s->nn * s->nn;
    for (int a = 0; a < s->nn; a++) {
      fcm_index ka = g2l ? g2l[ed[a] / 3] : ed[a] / 3;
      if (g2l) s->elem_lcopy[(size_t)el * s->nn + a] = (int)ka;
      const fcm_index *row = s->node_adj + s->node_ptr[ka];
      size_t len = (size_t)(s->node_ptr[ka + 1] - s->node_ptr[ka]);
      for (int b = 0; b < s->nn; b++) {
        fcm_index kb = ed[b] / 3;
        const fcm_index *hit = bsearch(&kb, row, len, sizeof *row, cmp_index);
        FCM_ASSERT(hit != NULL, ctx);
        off[a * s->nn + b] = (int)(hit - row);
      }
    }
  }
cleanup:
  return st;
}

/* Greedy colouring of the local elements: an element takes the smallest colour not used by an
 * element sharing a copy (elements sharing a node but using different copies of it may share a
 * colour). color_elems holds local element positions (a full space: element ids). */
static fcm_status build_colors(fcm_space *s, const fcm_index *g2l, const fcm_index *cptr,
                               const fcm_index *cinc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ne = s->num_local_elems;
  int *color = NULL, ncol = 0;
  fcm_index *forbid = NULL, *fill = NULL;
  enum { MAX_COLORS = 4096 };
  FCM_ALLOC(ctx, ne + 1, color);
  FCM_ALLOC(ctx, MAX_COLORS, forbid);
  for (int k = 0; k < MAX_COLORS; k++)
    forbid[k] = -1;
  for (fcm_index e = 0; e < ne; e++)
    color[e] = -1;
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index *ed = s->elem_dof + local_elem(s, e) * s->nn;
    for (int a = 0; a < s->nn; a++) {
      const fcm_index k = g2l ? g2l[ed[a] / 3] : ed[a] / 3;
      for (fcm_index i = cptr[k]; i < cptr[k + 1]; i++)
        if (color[cinc[i]] >= 0) forbid[color[cinc[i]]] = e;
    }
    int k = 0;
    while (k < MAX_COLORS && forbid[k] == e)
      k++;
    FCM_CHECK(k < MAX_COLORS, ctx, FCM_ERR_UNSUPPORTED,
              "space: cell %lld needs more than %d colours (a node shared by too many cells)",
              (long long)s->elem_cell[local_elem(s, e)], MAX_COLORS);
    color[e] = k;
    ncol = FCM_MAX(ncol, k + 1);
  }
  s->num_colors = ncol;
  FCM_ALLOC(ctx, ncol + 1, s->color_ptr);
  for (fcm_index e = 0; e < ne; e++)
    s->color_ptr[color[e] + 1]++;
  for (int k = 0; k < ncol; k++)
    s->color_ptr[k + 1] += s->color_ptr[k];
  FCM_ALLOC(ctx, s->color_ptr[ncol] + 1, s->color_elems);
  FCM_ALLOC(ctx, ncol + 1, fill);
  for (fcm_index e = 0; e < ne; e++)
    s->color_elems[s->color_ptr[color[e]] + fill[color[e]]++] = e;
cleanup:
  fcm__free(ctx, color);
  fcm__free(ctx, forbid);
  fcm__free(ctx, fill);
  return st;
}

/* Release the topology (copy graph, pattern, offsets, colours, local lists). */
static void free_topology(fcm_space *s)
{
  fcm_ctx *ctx = s->ctx;
  void *arrays[] = {s->node_ptr,   s->node_adj,   s->row_ptr,   s->col_idx,
                    s->elem_off,   s->elem_lcopy, s->color_ptr, s->color_elems,
                    s->local_copy, s->local_elem, s->cell_local};
  for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
    fcm__free(ctx, arrays[i]);
  s->node_ptr = s->node_adj = s->row_ptr = s->local_copy = s->local_elem = NULL;
  s->color_ptr = s->color_elems = NULL;
  s->col_idx = s->elem_off = s->elem_lcopy = NULL;
  s->cell_local = NULL;
  s->num_colors = 0;
  s->num_local_copies = s->num_local_elems = 0;
}

/* The topology of the elements of the cells flagged in cell_mask (local; cell_mask NULL: none)
 * or of every element (!local, the full space's): their copies, the copy graph, the pattern,
 * the offsets and the colours. The local copies and elements are listed in ascending order,
 * so a mask of every active cell gives the full space's arrays. */
static fcm_status build_topology(fcm_space *s, int local, const unsigned char *cell_mask)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_dofs / 3;
  fcm_index *g2l = NULL, *cptr = NULL, *cinc = NULL;
  free_topology(s);
  if (local) {
    fcm_index ne = 0, nl = 0;
    FCM_ALLOC(ctx, s->num_cells + 1, s->cell_local);
    for (fcm_index c = 0; c < s->num_cells; c++) {
      s->cell_local[c] = cell_mask && cell_mask[c] != 0 && s->active[c];
      if (s->cell_local[c]) ne += s->cell_elem[c + 1] - s->cell_elem[c];
    }
    FCM_ALLOC(ctx, ne + 1, s->local_elem);
    FCM_ALLOC(ctx, ncopy + 1, g2l); /* transient O(copies): the numbering's size */
    for (fcm_index k = 0; k < ncopy; k++)
      g2l[k] = -1;
    for (fcm_index c = 0; c < s->num_cells; c++) {
      if (!s->cell_local[c]) continue;
      for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++) {
        s->local_elem[s->num_local_elems++] = e;
        for (int a = 0; a < s->nn; a++)
          g2l[s->elem_dof[e * s->nn + a] / 3] = 0;
      }
    }
    for (fcm_index k = 0; k < ncopy; k++)
      nl += g2l[k] == 0;
    FCM_ALLOC(ctx, nl + 1, s->local_copy);
    for (fcm_index k = 0; k < ncopy; k++)
      if (g2l[k] == 0) {
        s->local_copy[s->num_local_copies] = k;
        g2l[k] = s->num_local_copies++;
      }
  } else {
    s->num_local_elems = s->num_elems;
    s->num_local_copies = ncopy;
  }
  FCM_TRY(ctx, build_copy_incidence(s, g2l, &cptr, &cinc));
  FCM_TRY(ctx, build_node_graph(s, g2l, cptr, cinc));
  FCM_TRY(ctx, build_pattern(s, g2l));
  FCM_TRY(ctx, build_colors(s, g2l, cptr, cinc));
cleanup:
  if (st != FCM_OK) free_topology(s);
  fcm__free(ctx, g2l);
  fcm__free(ctx, cptr);
  fcm__free(ctx, cinc);
  return st;
}

void fcm__space_copy_support(const fcm_space *s, double *support)
{
  const fcm_index nn = s->nn;
  memset(support, 0, sizeof *support * (size_t)(s->num_dofs / 3));
  for (fcm_index e = 0; e < s->num_elems; e++) {
    const double v = s->rules ? fcm_cell_rules_piece_volume(s->rules, s->elem_piece[e]) : 1.0;
    for (int a = 0; a < nn; a++)
      support[s->elem_dof[e * nn + a] / 3] += v;
  }
}

/* Koschier et al. 2017, Sec. 6: a copy whose support (the volume of the pieces that use it)
 * is below `ratio` of its node's (the pieces of all the node's elements) barely contributes
 * and makes the system (nearly) singular; it is constrained to move with its piece: its
 * elements use, in its place, the DOFs of the largest-support copy at another node of those
 * elements, so the fragment follows that copy (exact for translations). A fragment the cuts
 * separate completely (every copy its elements use is tiny) has no such copy: all its copies
 * follow one anchor, the largest copy at any of the fragment's nodes, so the fragment moves
 * with (translates as) that copy's body — Koschier's "sticking", of material below `ratio`
 * of its nodes' supports — and never joins two bodies. Unused copies are then removed from
 * the numbering. Counts in s->num_constrained. */
static fcm_status constrain_copies(fcm_space *s, double ratio, const fcm_index *inc_ptr,
                                   const fcm_index *inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  const fcm_index ncopy = s->num_dofs / 3, nn = s->nn;
  double *venr = NULL;
  fcm_index *master = NULL, *renum = NULL, *uf = NULL, *node_of = NULL, *anchor = NULL;
  unsigned char *tiny = NULL;
  FCM_ALLOC(ctx, ncopy + 1, venr);
  FCM_ALLOC(ctx, ncopy + 1, master);
  FCM_ALLOC(ctx, ncopy + 1, tiny);
  FCM_ALLOC(ctx, ncopy + 1, uf);
  FCM_ALLOC(ctx, ncopy + 1, node_of);
  FCM_ALLOC(ctx, ncopy + 1, anchor);
  fcm__space_copy_support(s, venr);
  /* which copies are tiny, each against its own node's support */
  fcm_index ntiny = 0;
  for (fcm_index n = 0; n < s->num_nodes; n++) {
    double vsupp = 0.0;
    for (fcm_index i = inc_ptr[n]; i < inc_ptr[n + 1]; i++)
      vsupp += fcm_cell_rules_piece_volume(s->rules, s->elem_piece[inc[i]]);
    for (fcm_index c = 0; c < s->node_ncopy[n]; c++) {
      const fcm_index k = s->node_dof[n] / 3 + c;
      node_of[k] = n;
      tiny[k] = s->node_ncopy[n] > 1 && venr[k] < ratio * vsupp;
      ntiny += tiny[k];
    }
  }
  for (fcm_index k = 0; k < ncopy; k++)
    master[k] = anchor[k] = -1, uf[k] = k;
  if (ntiny == 0) goto cleanup;
  /* rule 1: the largest non-tiny copy at another node of an element that uses the copy;
   * elements using only tiny copies join them into separated fragments (union-find) */
  for (fcm_index e = 0; e < s->num_elems; e++) {
    const fcm_index *d = s->elem_dof + e * nn;
    int all_tiny = 1;
    for (int a = 0; a < nn; a++)
      all_tiny &= tiny[d[a] / 3];
    for (int a = 0; a < nn; a++) {
      const fcm_index k = d[a] / 3;
      if (!tiny[k]) continue;
      if (all_tiny) {
        const fcm_index ra = uf_find(uf, k), rb = uf_find(uf, d[0] / 3);
        if (ra != rb) uf[FCM_MAX(ra, rb)] = FCM_MIN(ra, rb);
        continue;
      }
      for (int b = 0; b < nn; b++) {
        const fcm_index m = d[b] / 3;
        if (cells[s->elem_cell[e] * nn + b] == node_of[k] || tiny[m]) continue;
        if (master[k] < 0 || venr[m] > venr[master[k]] ||
            (venr[m] == venr[master[k]] && m < master[k]))
          master[k] = m;
      }
    }
  }
  /* rule 2: a fragment none of whose copies found a master follows its anchor */
  for (fcm_index k = 0; k < ncopy; k++) /* fragments with a rule-1 master are not separated */
    if (tiny[k] && master[k] >= 0) anchor[uf_find(uf, k)] = -2;
  for (fcm_index k = 0; k < ncopy; k++) {
    if (!tiny[k]) continue;
    const fcm_index r = uf_find(uf, k), n = node_of[k];
    if (anchor[r] == -2) continue;
    for (fcm_index c = 0; c < s->node_ncopy[n]; c++) {
      const fcm_index m = s->node_dof[n] / 3 + c;
      if (!tiny[m] && (anchor[r] < 0 || venr[m] > venr[anchor[r]])) anchor[r] = m;
    }
  }
  fcm_index count = 0;
  for (fcm_index k = 0; k < ncopy; k++) {
    if (!tiny[k]) continue;
    const fcm_index r = uf_find(uf, k);
    if (master[k] < 0 && anchor[r] >= 0) master[k] = anchor[r];
    count += master[k] >= 0;
  }
  if (count > 0) {
    FCM_ALLOC(ctx, (size_t)s->num_elems * nn + 1, s->elem_con);
    for (fcm_index e = 0; e < s->num_elems; e++)
      for (int a = 0; a < nn; a++) {
        const fcm_index k = s->elem_dof[e * nn + a] / 3;
        if (master[k] < 0) continue;
        s->elem_dof[e * nn + a] = 3 * master[k];
        s->elem_con[e * nn + a] = 1;
      }
    /* renumber the copies still in use, node by node */
    FCM_ALLOC(ctx, ncopy + 1, renum);
    fcm_index next = 0;
    for (fcm_index n = 0; n < s->num_nodes; n++) {
      if (s->node_dof[n] < 0) continue;
      const fcm_index k0 = s->node_dof[n] / 3, nc = s->node_ncopy[n];
      fcm_index kept = 0;
      for (fcm_index c = 0; c < nc; c++) {
        renum[k0 + c] = master[k0 + c] >= 0 ? -1 : next + kept;
        kept += master[k0 + c] < 0;
      }
      s->node_dof[n] = kept ? 3 * next : -1;
      s->node_ncopy[n] = kept;
      next += kept;
    }
    for (fcm_index e = 0; e < s->num_elems; e++)
      for (int a = 0; a < nn; a++)
        s->elem_dof[e * nn + a] = 3 * renum[s->elem_dof[e * nn + a] / 3];
    s->num_dofs = 3 * next;
  }
  s->num_constrained = count;
cleanup:
  fcm__free(ctx, venr);
  fcm__free(ctx, master);
  fcm__free(ctx, renum);
  fcm__free(ctx, tiny);
  fcm__free(ctx, uf);
  fcm__free(ctx, node_of);
  fcm__free(ctx, anchor);
  return st;
}

/* Shared by fcm_space_create(), fcm_space_create_embedded() and fcm__space_create_local()
 * (local != 0: the topology of the cells flagged in cell_mask only). */
static fcm_status space_create(fcm_ctx *ctx, const fcm_mesh *mesh, const unsigned char *cell_active,
                               const fcm_cell_rules *rules, const fcm_space_options *opts,
                               int local, const unsigned char *cell_mask, fcm_space **out)
{
  fcm_status st = FCM_OK;
  fcm_space *s = NULL;
  fcm_index *inc_ptr = NULL, *inc = NULL, nactive_cells = 0;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "space: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(mesh, ctx, FCM_ERR_ARG, "space: mesh is NULL");
  FCM_ALLOC(ctx, 1, s);
  s->ctx = ctx;
  s->mesh = mesh;
  s->rules = rules;
  s->type = fcm_mesh_element_type(mesh);
  s->nn = fcm_mesh_nodes_per_cell(mesh);
  s->num_cells = fcm_mesh_num_cells(mesh);
  s->num_nodes = fcm_mesh_num_nodes(mesh);
  FCM_ALLOC(ctx, s->num_cells, s->active);
  for (fcm_index c = 0; c < s->num_cells; c++) {
    s->active[c] = cell_active ? (cell_active[c] != 0) : 1;
    if (rules) {
      fcm_cell_class cls = fcm_cell_rules_class(rules, c);
      s->active[c] = cls != FCM_CELL_DROPPED;
      fcm_index first = 0;
      const fcm_index np = fcm_cell_rules_cell_pieces(rules, c, &first);
      for (fcm_index p = first; p < first + np && cls == FCM_CELL_CUT; p++)
        for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
          int n = 0;
          if (!fcm_cell_rules_has_kind(rules, (fcm_rule_kind)k)) continue; /* not built */
          FCM_TRY(ctx, fcm_cell_rules_get_piece(rules, p, (fcm_rule_kind)k, &n, NULL, NULL, NULL));
          s->max_cut_points = FCM_MAX(s->max_cut_points, n);
        }
    }
    nactive_cells += s->active[c];
  }
  FCM_CHECK(nactive_cells > 0, ctx, FCM_ERR_ARG, "space: none of the %lld cells is active",
            (long long)s->num_cells);
  FCM_ALLOC(ctx, s->num_nodes, s->node_dof);
  FCM_TRY(ctx, build_elements(s));
  FCM_TRY(ctx, build_incidence(s, &inc_ptr, &inc));
  FCM_TRY(ctx, build_copies(s, inc_ptr, inc));
  if (rules && opts && opts->constrain_ratio > 0.0)
    FCM_TRY(ctx, constrain_copies(s, opts->constrain_ratio, inc_ptr, inc));
  {
    int dummy;
    FCM_TRY(ctx, fcm__index_to_int(ctx, s->num_dofs, "space: number of DOFs", &dummy));
  }
  /* the numbering's incidence is not needed any more: free it before the topology's peak */
  FCM_FREE(ctx, inc_ptr);
  FCM_FREE(ctx, inc);
  s->is_local = local;
  FCM_TRY(ctx, build_topology(s, local, cell_mask));
  FCM_TRY(ctx, fcm_element_standard_rule(ctx, s->type, FCM_RULE_MASS, FCM_DEFAULT, &s->mass_rule));
  *out = s;
  s = NULL;
cleanup:
  fcm__free(ctx, inc_ptr);
  fcm__free(ctx, inc);
  fcm_space_destroy(&s);
  return st;
}

fcm_status fcm_space_create(fcm_ctx *ctx, const fcm_mesh *mesh, const unsigned char *cell_active,
                            fcm_space **out)
{
  return space_create(ctx, mesh, cell_active, NULL, NULL, 0, NULL, out);
}

fcm_space_options fcm_space_options_default(void)
{
  fcm_space_options o;
  memset(&o, 0, sizeof o);
  o.constrain_ratio = 1e-9;
  return o;
}

fcm_status fcm_space_create_embedded(fcm_ctx *ctx, const fcm_mesh *mesh,
                                     const fcm_cell_rules *rules, fcm_space **out)
{
  const fcm_space_options o = fcm_space_options_default();
  return fcm_space_create_embedded_with(ctx, mesh, rules, &o, out);
}

/* The arguments of an embedded space (rules built on this mesh, constrain_ratio in range). */
static fcm_status check_embedded(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_cell_rules *rules,
                                 const fcm_space_options *opts)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(mesh && rules, ctx, FCM_ERR_ARG, "space: mesh or cell rules is NULL");
  FCM_CHECK(fcm_cell_rules_num_cells(rules) == fcm_mesh_num_cells(mesh) &&
                fcm_cell_rules_element_type(rules) == fcm_mesh_element_type(mesh),
            ctx, FCM_ERR_ARG,
            "space: the cell rules (%lld cells) were not built on this mesh (%lld cells)",
            (long long)fcm_cell_rules_num_cells(rules), (long long)fcm_mesh_num_cells(mesh));
  FCM_CHECK(!opts || (isfinite(opts->constrain_ratio) && opts->constrain_ratio >= 0.0 &&
                      opts->constrain_ratio < 0.5),
            ctx, FCM_ERR_ARG, "space: constrain_ratio = %g outside [0, 0.5)",
            opts ? opts->constrain_ratio : 0.0);
cleanup:
  return st;
}

fcm_status fcm_space_create_embedded_with(fcm_ctx *ctx, const fcm_mesh *mesh,
                                          const fcm_cell_rules *rules,
                                          const fcm_space_options *opts, fcm_space **out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "space: output pointer is NULL");
  *out = NULL;
  FCM_TRY(ctx, check_embedded(ctx, mesh, rules, opts));
  FCM_TRY(ctx, space_create(ctx, mesh, NULL, rules, opts, 0, NULL, out));
cleanup:
  return st;
}

fcm_status fcm__space_create_local(fcm_ctx *ctx, const fcm_mesh *mesh,
                                   const unsigned char *cell_active, const fcm_cell_rules *rules,
                                   const fcm_space_options *opts, const unsigned char *cell_mask,
                                   fcm_space **out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "space: output pointer is NULL");
  *out = NULL;
  if (rules) {
    FCM_CHECK(!cell_active, ctx, FCM_ERR_ARG,
              "local space: give the cell rules or cell_active, not both (the rules decide "
              "which cells are active)");
    FCM_TRY(ctx, check_embedded(ctx, mesh, rules, opts));
  }
  FCM_TRY(ctx, space_create(ctx, mesh, cell_active, rules, rules ? opts : NULL, 1, cell_mask, out));
cleanup:
  return st;
}

fcm_status fcm__space_set_local_cells(fcm_space *s, const unsigned char *cell_mask)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  FCM_CHECK(s, ctx, FCM_ERR_ARG, "local space: NULL space");
  FCM_CHECK(s->is_local, ctx, FCM_ERR_ARG,
            "local space: the space is a full space (fcm_space_create*()); only a space of "
            "fcm__space_create_local() takes a cell mask");
  FCM_TRY(ctx, build_topology(s, 1, cell_mask));
cleanup:
  return st;
}

const fcm_cell_rules *fcm_space_cell_rules(const fcm_space *s)
{
  return s->rules;
}

void fcm_space_destroy(fcm_space **sp)
{
  if (!sp || !*sp) return;
  fcm_space *s = *sp;
  fcm_ctx *ctx = s->ctx;
  fcm__free(ctx, s->active);
  fcm__free(ctx, s->node_dof);
  fcm__free(ctx, s->node_ncopy);
  fcm__free(ctx, s->cell_elem);
  fcm__free(ctx, s->elem_cell);
  fcm__free(ctx, s->elem_piece);
  fcm__free(ctx, s->elem_dof);
  fcm__free(ctx, s->elem_con);
  free_topology(s);
  fcm_rule_destroy(&s->mass_rule);
  fcm__free(ctx, s);
  *sp = NULL;
}

fcm_index fcm_space_num_dofs(const fcm_space *s)
{
  return s->num_dofs;
}

fcm_index fcm_space_node_dof(const fcm_space *s, fcm_index node)
{
  return (node < 0 || node >= s->num_nodes) ? -1 : s->node_dof[node];
}

fcm_index fcm_space_node_copies(const fcm_space *s, fcm_index node)
{
  return (node < 0 || node >= s->num_nodes) ? 0 : s->node_ncopy[node];
}

fcm_index fcm_space_num_constrained_copies(const fcm_space *s)
{
  return s->num_constrained;
}

int fcm_space_element_constrained(const fcm_space *s, fcm_index elem)
{
  int n = 0;
  if (!s || !s->elem_con || elem < 0 || elem >= s->num_elems) return 0;
  for (int a = 0; a < s->nn; a++)
    n += s->elem_con[elem * s->nn + a];
  return n;
}

fcm_index fcm_space_num_elements(const fcm_space *s)
{
  return s->num_elems;
}

fcm_index fcm_space_cell_elements(const fcm_space *s, fcm_index cell, fcm_index *first)
{
  if (cell < 0 || cell >= s->num_cells) {
    if (first) *first = 0;
    return 0;
  }
  if (first) *first = s->cell_elem[cell];
  return s->cell_elem[cell + 1] - s->cell_elem[cell];
}

fcm_index fcm_space_element_cell(const fcm_space *s, fcm_index elem)
{
  return (elem < 0 || elem >= s->num_elems) ? -1 : s->elem_cell[elem];
}

const fcm_index *fcm_space_element_dofs(const fcm_space *s, fcm_index elem)
{
  return (elem < 0 || elem >= s->num_elems) ? NULL : s->elem_dof + elem * s->nn;
}

int fcm_space_num_colors(const fcm_space *s)
{
  return s->num_colors;
}

int fcm_space_cell_active(const fcm_space *s, fcm_index cell)
{
  return cell >= 0 && cell < s->num_cells && s->active[cell];
}

const fcm_mesh *fcm_space_mesh(const fcm_space *s)
{
  return s->mesh;
}

fcm_status fcm__space_check_full(const fcm_space *s, const char *what)
{
  if (!s->is_local) return FCM_OK;
  fcm_index nl = 0;
  for (fcm_index c = 0; s->cell_local && c < s->num_cells; c++)
    nl += s->cell_local[c] != 0;
  return fcm__error(s->ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "%s: the space is a local space (its pattern covers the elements of %lld of "
                    "its %lld cells: a distributed run's own and ghost cells); this needs the "
                    "whole pattern: build the space with fcm_space_create() or "
                    "fcm_space_create_embedded()",
                    what, (long long)nl, (long long)s->num_cells);
}

void fcm__space_memory(const fcm_space *s, double *numbering, double *topology)
{
  const double I = (double)sizeof(fcm_index), nn = (double)s->nn;
  const double ne = (double)s->num_elems, nc = (double)s->num_cells, np = (double)s->num_nodes;
  const double nl = (double)s->num_local_copies, nle = (double)s->num_local_elems;
  const double nadj = s->node_ptr ? (double)s->node_ptr[s->num_local_copies] : 0.0;
  if (numbering) /* active, node_dof, node_ncopy, cell_elem, elem_cell, elem_piece, elem_dof,
                   elem_con */
    *numbering = nc + 2.0 * I * np + I * (nc + 1.0) + 2.0 * I * ne + I * nn * ne +
                 (s->elem_con ? nn * ne : 0.0);
  if (topology) /* node_ptr, node_adj, row_ptr, col_idx (9 per graph entry), elem_off, colours,
                   local lists, elem_lcopy */
    *topology = I * (nl + 1.0) + I * nadj + I * (3.0 * nl + 1.0) +
                (double)sizeof(int) * 9.0 * nadj + (double)sizeof(int) * nn * nn * nle +
                I * ((double)s->num_colors + 1.0) + I * nle +
                (s->is_local ? I * (nl + nle) + nc + (double)sizeof(int) * nn * nle : 0.0);
}

fcm_status fcm_space_matrix_create(const fcm_space *s, fcm_csr **A)
{
  fcm_status st = FCM_OK;
  FCM_TRY(s->ctx, fcm__space_check_full(s, "space matrix"));
  FCM_TRY(s->ctx, fcm_csr_create(s->ctx, s->num_dofs, s->num_dofs, s->row_ptr, s->col_idx,
                                 FCM_CSR_SYMMETRIC, A));
cleanup:
  return st;
}

fcm_index fcm__space_elem_local(const fcm_space *s, fcm_index e)
{
  if (e < 0 || e >= s->num_elems) return -1;
  if (!s->local_elem) return s->is_local ? -1 : e; /* a local space without local elements */
  fcm_index lo = 0, hi = s->num_local_elems;
  while (lo < hi) {
    const fcm_index mid = lo + (hi - lo) / 2;
    if (s->local_elem[mid] < e)
      lo = mid + 1;
    else
      hi = mid;
  }
  return (lo < s->num_local_elems && s->local_elem[lo] == e) ? lo : -1;
}

fcm_status fcm__space_matrix_create_rows(const fcm_space *s, fcm_csr **A)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  FCM_CHECK(s && A, ctx, FCM_ERR_ARG, "space matrix (rows): NULL space or output pointer");
  *A = NULL;
  FCM_CHECK(s->row_ptr, ctx, FCM_ERR_ARG,
            "space matrix (rows): the local space has no topology (a failed rebuild)");
  /* the space's pattern, shared (borrowed: the space outlives the matrices made on it) */
  FCM_TRY(ctx,
          fcm__csr_share_pattern(ctx, fcm__space_num_rows(s), s->num_dofs, s->row_ptr, s->col_idx,
                                 s->is_local ? FCM_CSR_GENERAL : FCM_CSR_SYMMETRIC, A));
cleanup:
  return st;
}

fcm_status fcm__space_matrix_apply(const fcm_space *s, const fcm_csr *A, const double *x, double *y)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  fcm_index nr = -1, nc = -1, nnz = -1;
  FCM_CHECK(s && A, ctx, FCM_ERR_ARG, "space matrix apply: NULL space or matrix");
  if (!s->is_local) {
    FCM_TRY(ctx, fcm_csr_apply(A, 1.0, x, 0.0, y));
    goto cleanup;
  }
  const fcm_index nrow = fcm__space_num_rows(s);
  fcm_csr_get_size(A, &nr, &nc, &nnz);
  FCM_CHECK(nr == nrow && nc == s->num_dofs && s->row_ptr && nnz == s->row_ptr[nrow], ctx,
            FCM_ERR_ARG,
            "space matrix apply: matrix is %lld x %lld with %lld entries; the local space's "
            "rows need %lld x %lld (create it with fcm__space_matrix_create_rows)",
            (long long)nr, (long long)nc, (long long)nnz, (long long)nrow, (long long)s->num_dofs);
  FCM_CHECK((x && y) || s->num_dofs == 0, ctx, FCM_ERR_ARG, "space matrix apply: x or y is NULL");
  FCM_CHECK(!x || x != y, ctx, FCM_ERR_ARG,
            "space matrix apply: x and y must not be the same array");
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  for (fcm_index i = 0; i < s->num_dofs; i++)
    y[i] = 0.0;
#pragma omp parallel for schedule(static) if (nnz >= 20000)
  for (fcm_index r = 0; r < nrow; r++) { /* distinct rows write distinct DOFs */
    double sum = 0.0;
    for (fcm_index p = rp[r]; p < rp[r + 1]; p++)
      sum += v[p] * x[ci[p]];
    y[fcm__space_row_dof(s, r)] = 1.0 * sum; /* as fcm_csr_apply(A, 1, x, 0, y) */
  }
cleanup:
  return st;
}

fcm_status fcm__space_localize(fcm_space *s, const unsigned char *own)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  unsigned char *mark = NULL, *mask = NULL;
  FCM_CHECK(s && own, ctx, FCM_ERR_ARG, "localize: NULL space or own-cell flags");
  FCM_CHECK(s->is_local, ctx, FCM_ERR_ARG,
            "localize: the space is a full space (fcm_space_create*()); only a space of "
            "fcm__space_create_local() takes local cells");
  const fcm_index ncopy = s->num_dofs / 3, nn = s->nn;
  FCM_ALLOC(ctx, ncopy + 1, mark);
  FCM_ALLOC(ctx, s->num_cells + 1, mask);
  for (fcm_index c = 0; c < s->num_cells; c++) /* the copies of the own cells' elements */
    if (own[c] && s->active[c])
      for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++)
        for (int a = 0; a < nn; a++)
          mark[s->elem_dof[e * nn + a] / 3] = 1;
  for (fcm_index c = 0; c < s->num_cells; c++) { /* own cells and their ghosts */
    if (!s->active[c]) continue;
    int hit = own[c] != 0;
    for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1] && !hit; e++)
      for (int a = 0; a < nn && !hit; a++)
        hit = mark[s->elem_dof[e * nn + a] / 3];
    mask[c] = (unsigned char)hit;
  }
  FCM_TRY(ctx, fcm__space_set_local_cells(s, mask));
cleanup:
  if (s) {
    fcm__free(ctx, mark);
    fcm__free(ctx, mask);
  }
  return st;
}

fcm_status fcm__space_check_assemble(const fcm_space *s, const char *what)
{
  if (!s) return FCM_ERR_ARG;
  if (!s->is_local) return FCM_OK;
  /* the rules give points to the cells fcm__cell_rules_owns() flags (all, without a mask):
   * each active one must be local, or its elements would scatter into rows the space lacks */
  for (fcm_index c = 0; c < s->num_cells; c++) {
    if (!s->active[c] || !fcm__cell_rules_owns(s->rules, c) || (s->cell_local && s->cell_local[c]))
      continue;
    if (!s->rules || !s->rules->own)
      return fcm__error(s->ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                        "%s: the space is a local space, but its cell rules %s: every active "
                        "cell gets points, and active cell %lld is not a local cell (build the "
                        "rules with fcm_cell_rules_options.cell_mask flagging the own cells)",
                        what,
                        s->rules ? "were built without a cell_mask"
                                 : "are missing (no "
                                   "embedded rules)",
                        (long long)c);
    return fcm__error(s->ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                      "%s: the space's cell rules flag active cell %lld in their cell_mask (it "
                      "gets points), but the local space does not cover it (localize the space "
                      "on the cells the rules flag: fcm__space_localize())",
                      what, (long long)c);
  }
  return FCM_OK;
}

void fcm__eliminate_marked(fcm_csr *A, double *b, const unsigned char *con, const double *g)
{
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  double *v = fcm_csr_values(A);
#pragma omp parallel for schedule(static)
  for (fcm_index i = 0; i < n; i++) {
    if (con[i]) {
      double diag = 1.0;
      for (fcm_index e = rp[i]; e < rp[i + 1]; e++) {
        if (ci[e] == i && v[e] > 0.0) diag = v[e];
        v[e] = 0.0;
      }
      for (fcm_index e = rp[i]; e < rp[i + 1]; e++)
        if (ci[e] == i) v[e] = diag;
      if (b) b[i] = diag * g[i];
    } else {
      double acc = 0.0;
      for (fcm_index e = rp[i]; e < rp[i + 1]; e++)
        if (con[ci[e]]) {
          if (b) acc += v[e] * g[ci[e]];
          v[e] = 0.0;
        }
      if (b) b[i] -= acc;
    }
  }
}

fcm_status fcm_space_apply_dirichlet(const fcm_space *s, fcm_index ncon, const fcm_index *dofs,
                                     const double *values, fcm_csr *A, double *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  unsigned char *con = NULL;
  double *g = NULL;
  fcm_index n = 0, nr, nc;
  FCM_CHECK(A && b && (ncon == 0 || dofs), ctx, FCM_ERR_ARG, "dirichlet: NULL argument");
  fcm_csr_get_size(A, &nr, &nc, NULL);
  FCM_CHECK(nr == nc, ctx, FCM_ERR_ARG, "dirichlet: matrix is %lld x %lld, not square",
            (long long)nr, (long long)nc);
  n = nr;
  FCM_ALLOC(ctx, n, con);
  FCM_ALLOC(ctx, n, g);
  for (fcm_index k = 0; k < ncon; k++) {
    fcm_index d = dofs[k];
    FCM_CHECK(d >= 0 && d < n, ctx, FCM_ERR_ARG,
              "dirichlet: dofs[%lld] = %lld out of range [0, %lld)", (long long)k, (long long)d,
              (long long)n);
    FCM_CHECK(!con[d], ctx, FCM_ERR_ARG, "dirichlet: DOF %lld is constrained twice", (long long)d);
    con[d] = 1;
    g[d] = values ? values[k] : 0.0;
  }
  fcm__eliminate_marked(A, b, con, g);
cleanup:
  fcm__free(ctx, con);
  fcm__free(ctx, g);
  return st;
}

fcm_status fcm_space_transfer(const fcm_space *from, const fcm_space *to, const double *x_from,
                              double *x_to)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to ? to->ctx : NULL;
  FCM_CHECK(from && to && x_from && x_to, ctx, FCM_ERR_ARG, "space transfer: NULL argument");
  FCM_CHECK(from->mesh == to->mesh && from->rules && to->rules, ctx, FCM_ERR_ARG,
            "space transfer: both spaces must be embedded spaces on the same mesh");
  FCM_CHECK(fcm_cell_rules_parent_num_pieces(to->rules) == fcm_cell_rules_num_pieces(from->rules) &&
                fcm_cell_rules_parent_num_pieces(to->rules) > 0,
            ctx, FCM_ERR_ARG,
            "space transfer: the target's cell rules (made from rules with %lld pieces) do not "
            "extend the source's (%lld pieces) by a cut (fcm_cell_rules_create_cut())",
            (long long)fcm_cell_rules_parent_num_pieces(to->rules),
            (long long)fcm_cell_rules_num_pieces(from->rules));
  for (fcm_index e = 0; e < to->num_elems; e++) {
    const fcm_index c = to->elem_cell[e],
                    pp = fcm_cell_rules_piece_parent(to->rules, to->elem_piece[e]);
    fcm_index first = 0;
    fcm_cell_rules_cell_pieces(from->rules, c, &first);
    const fcm_index fe = from->cell_elem[c] + (pp - first);
    FCM_CHECK(pp >= first && fe < from->cell_elem[c + 1], ctx, FCM_ERR_INTERNAL,
              "space transfer: element %lld (cell %lld) has parent piece %lld outside the "
              "cell's pieces in the source",
              (long long)e, (long long)c, (long long)pp);
    for (int a = 0; a < to->nn; a++) {
      const fcm_index d = to->elem_dof[e * to->nn + a];
      /* a constrained copy's place holds the copy it moves with (of another node, or another
       * copy of this one): that copy's own elements set it, from their parents' values */
      if (to->elem_con && to->elem_con[e * to->nn + a]) continue;
      for (int i = 0; i < 3; i++)
        x_to[d + i] = x_from[from->elem_dof[fe * from->nn + a] + i];
    }
  }
cleanup:
  return st;
}
