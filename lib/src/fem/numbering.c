/* The DOF numbering of a space: its elements (one per material piece of a cell), the elements
 * at each node, the copies of each node (one per connected component of its support,
 * generalized enrichment) and the constraint of tiny copies (Koschier et al. 2017). */
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Node -> elements incidence as CSR: inc_ptr[num_nodes+1], inc (ascending elements). The
 * threads count and place the elements in any order; each list is then sorted. */
fcm_status fcm__space_build_incidence(fcm_space *s, fcm_index **inc_ptr, fcm_index **inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  const int nt = fcm_ctx_num_threads(ctx);
  fcm_index *ptr = NULL, *list = NULL, *fill = NULL;
  FCM_ALLOC(ctx, s->num_nodes + 1, ptr);
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index e = 0; e < s->num_elems; e++)
    for (int a = 0; a < s->nn; a++) {
#pragma omp atomic
      ptr[cells[s->elem_cell[e] * s->nn + a] + 1]++;
    }
  for (fcm_index n = 0; n < s->num_nodes; n++)
    ptr[n + 1] += ptr[n];
  FCM_ALLOC_RAW(ctx, ptr[s->num_nodes] + 1, list);
  FCM_ALLOC_RAW(ctx, s->num_nodes + 1, fill);
  memcpy(fill, ptr, sizeof *fill * (size_t)s->num_nodes);
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index e = 0; e < s->num_elems; e++)
    for (int a = 0; a < s->nn; a++) {
      const fcm_index n = cells[s->elem_cell[e] * s->nn + a];
      fcm_index at;
#pragma omp atomic capture
      at = fill[n]++;
      list[at] = e;
    }
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index n = 0; n < s->num_nodes; n++)
    fcm__space_sort_indices(list + ptr[n], ptr[n + 1] - ptr[n]);
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
fcm_status fcm__space_build_elements(fcm_space *s)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_index ne = 0;
  const int nt = fcm_ctx_num_threads(ctx);
  FCM_ALLOC(ctx, s->num_cells + 1, s->cell_elem);
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index c = 0; c < s->num_cells; c++) {
    fcm_index k = s->active[c];
    if (s->rules && s->active[c]) k = fcm_cell_rules_cell_pieces(s->rules, c, NULL);
    s->cell_elem[c + 1] = k;
  }
  for (fcm_index c = 0; c < s->num_cells; c++)
    s->cell_elem[c + 1] += s->cell_elem[c];
  ne = s->num_elems = s->cell_elem[s->num_cells];
  /* every entry is written below (elem_dof: at each of an element's nodes, by
   * fcm__space_build_copies()) */
  FCM_ALLOC_RAW(ctx, ne + 1, s->elem_cell);
  FCM_ALLOC_RAW(ctx, ne + 1, s->elem_piece);
  FCM_ALLOC_RAW(ctx, (size_t)ne * s->nn + 1, s->elem_dof);
#pragma omp parallel for num_threads(nt) schedule(static)
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

/* The position of element e in the ascending list sup[0..deg) (a node's support), -1: none. */
static fcm_index support_pos(const fcm_index *sup, fcm_index deg, fcm_index e)
{
  const fcm_index lo = fcm__lower_bound(sup, 1, 0, deg, e);
  return lo < deg && sup[lo] == e ? lo : -1;
}

/* The copies of the node whose support (ascending elements) is sup[0..deg): their number, and
 * in comp[i] the copy (component) of element sup[i]; uf: deg entries of scratch. */
static fcm_index node_components(const fcm_space *s, const fcm_index *link_ptr,
                                 const fcm_index *links, const fcm_index *sup, fcm_index deg,
                                 fcm_index *uf, fcm_index *comp)
{
  if (deg == 0) return 0;
  int split = 0;
  for (fcm_index i = 0; i < deg; i++) {
    const fcm_index e = sup[i], c = s->elem_cell[e];
    /* cuts reach the node's support: a cell split into pieces, a piece with a face on a
     * cut (a cut along cell faces splits no cell but separates them), or a cell a cut
     * passes near: the material of the support can be connected only through cells
     * outside it (around a hole), and a cut elsewhere can sever that; the links are
     * known around every such cell */
    split |= s->cell_elem[c + 1] - s->cell_elem[c] > 1 ||
             (s->rules && s->rules->reached && s->rules->reached[c]) ||
             (s->rules && fcm_cell_rules_get_piece_cut_faces(s->rules, s->elem_piece[e], NULL) > 0);
    uf[i] = i;
  }
  if (!split) {
    for (fcm_index i = 0; i < deg; i++)
      comp[i] = 0;
    return 1;
  }
  for (fcm_index i = 0; i < deg; i++) {
    /* links (p, q) with p the piece of this element */
    const fcm_index p = s->elem_piece[sup[i]];
    for (fcm_index l = link_ptr[p]; l < link_ptr[p + 1]; l++) {
      /* the element of piece q: pieces and elements of a cell are in the same order */
      const fcm_index q = links[2 * l + 1];
      const fcm_index cq = fcm_cell_rules_piece_cell(s->rules, q);
      fcm_index fq;
      fcm_cell_rules_cell_pieces(s->rules, cq, &fq);
      const fcm_index j = support_pos(sup, deg, s->cell_elem[cq] + (q - fq));
      if (j < 0) continue; /* not in this node's support */
      const fcm_index ra = uf_find(uf, i), rb = uf_find(uf, j);
      if (ra != rb) uf[FCM_MAX(ra, rb)] = FCM_MIN(ra, rb);
    }
  }
  fcm_index k = 0;
  for (fcm_index i = 0; i < deg; i++) {
    const fcm_index r = uf_find(uf, i);
    comp[i] = r == i ? k++ : comp[r];
  }
  return k;
}

/* Generalized enrichment (Ton-That et al. 2024, XFEM): the elements incident to a node
 * (its support) are grouped into connected components along the links of the cell rules
 * (pieces of face-neighbouring cells that share a face part not lying on a cut); each
 * component gets its own copy of the node. Where every incident cell has one piece, the
 * node has one copy. Copies are numbered node by node, components by their first element;
 * elem_dof gets the copy each element uses. The nodes' components are found by the threads
 * (comp: the component of every incidence entry), then numbered in node order. */
fcm_status fcm__space_build_copies(fcm_space *s, const fcm_index *inc_ptr, const fcm_index *inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  const fcm_index nl = s->rules ? fcm_cell_rules_num_links(s->rules) : 0;
  const fcm_index *links = s->rules ? fcm_cell_rules_links(s->rules) : NULL;
  const fcm_index npieces = s->rules ? fcm_cell_rules_num_pieces(s->rules) : 0;
  const fcm_index nnodes = s->num_nodes;
  const int nt = fcm_ctx_num_threads(ctx);
  fcm_index *uf = NULL, *comp = NULL, *link_ptr = NULL, ncopy = 0, maxdeg = 0;
  FCM_ALLOC(ctx, nnodes, s->node_ncopy);
  /* links (p, q) sorted by p: those of piece p are [link_ptr[p], link_ptr[p + 1]) */
  FCM_ALLOC(ctx, npieces + 1, link_ptr);
  for (fcm_index p = 0, l = 0; p <= npieces; p++) {
    while (l < nl && links[2 * l] < p)
      l++;
    link_ptr[p] = l;
  }
#pragma omp parallel for num_threads(nt) schedule(static) reduction(max : maxdeg)
  for (fcm_index n = 0; n < nnodes; n++)
    maxdeg = FCM_MAX(maxdeg, inc_ptr[n + 1] - inc_ptr[n]);
  FCM_ALLOC_RAW(ctx, (size_t)nt * (size_t)(maxdeg + 1), uf);
  FCM_ALLOC_RAW(ctx, inc_ptr[nnodes] + 1, comp);
#pragma omp parallel num_threads(nt)
  {
    fcm_index *u = uf + (size_t)omp_get_thread_num() * (size_t)(maxdeg + 1);
#pragma omp for schedule(dynamic, 512)
    for (fcm_index n = 0; n < nnodes; n++)
      s->node_ncopy[n] = node_components(s, link_ptr, links, inc + inc_ptr[n],
                                         inc_ptr[n + 1] - inc_ptr[n], u, comp + inc_ptr[n]);
  }
  for (fcm_index n = 0; n < nnodes; n++) {
    s->node_dof[n] = inc_ptr[n + 1] > inc_ptr[n] ? 3 * ncopy : -1;
    ncopy += s->node_ncopy[n];
  }
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index n = 0; n < nnodes; n++)
    for (fcm_index i = inc_ptr[n]; i < inc_ptr[n + 1]; i++) {
      const fcm_index e = inc[i];
      for (int a = 0; a < s->nn; a++)
        if (cells[s->elem_cell[e] * s->nn + a] == n)
          s->elem_dof[e * s->nn + a] = s->node_dof[n] + 3 * comp[i];
    }
  s->num_dofs = 3 * ncopy;
cleanup:
  fcm__free(ctx, uf);
  fcm__free(ctx, comp);
  fcm__free(ctx, link_ptr);
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

/* The copies' work arrays of fcm__space_constrain_copies(). */
typedef struct copy_work {
  double *venr;        /* a copy's support volume */
  fcm_index *master;   /* the copy it follows (-1: none) */
  fcm_index *uf;       /* union-find of the tiny copies' fragments */
  fcm_index *node_of;  /* a copy's node */
  fcm_index *anchor;   /* a fragment's anchor copy (-1: none, -2: not separated) */
  unsigned char *tiny; /* the copy's support is below ratio of its node's */
} copy_work;

/* Which copies are tiny, each against its own node's support; a copy's support (as
 * fcm__space_copy_support(): its elements' volumes in ascending order) from its node's
 * elements, every copy being one node's before the constraint. Returns their count. */
static fcm_index tiny_copies(const fcm_space *s, double ratio, const fcm_index *inc_ptr,
                             const fcm_index *inc, copy_work *w)
{
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  const fcm_index nn = s->nn;
  fcm_index ntiny = 0;
#pragma omp parallel for num_threads(fcm_ctx_num_threads(s->ctx)) schedule(static) \
    reduction(+ : ntiny)
  for (fcm_index n = 0; n < s->num_nodes; n++) {
    double vsupp = 0.0;
    for (fcm_index c = 0; c < s->node_ncopy[n]; c++)
      w->venr[s->node_dof[n] / 3 + c] = 0.0;
    for (fcm_index i = inc_ptr[n]; i < inc_ptr[n + 1]; i++) {
      const fcm_index e = inc[i];
      const double v = fcm_cell_rules_piece_volume(s->rules, s->elem_piece[e]);
      int a = 0;
      while (a < nn - 1 && cells[s->elem_cell[e] * nn + a] != n)
        a++;
      w->venr[s->elem_dof[e * nn + a] / 3] += v;
      vsupp += v;
    }
    for (fcm_index c = 0; c < s->node_ncopy[n]; c++) {
      const fcm_index k = s->node_dof[n] / 3 + c;
      w->node_of[k] = n;
      w->tiny[k] = s->node_ncopy[n] > 1 && w->venr[k] < ratio * vsupp;
      ntiny += w->tiny[k];
    }
  }
  return ntiny;
}

/* Each tiny copy's master (w->master; -1: none). Rule 1: the largest non-tiny copy at another
 * node of an element that uses the copy; elements using only tiny copies join them into
 * separated fragments (union-find). Rule 2: a fragment none of whose copies found a master
 * follows its anchor, the largest non-tiny copy at the node of one of its copies. Returns the
 * number of copies with a master. */
static fcm_index copy_masters(const fcm_space *s, copy_work *w)
{
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  const fcm_index ncopy = s->num_dofs / 3, nn = s->nn;
  unsigned char *tiny = w->tiny;
  fcm_index *master = w->master, *uf = w->uf, *anchor = w->anchor;
  const double *venr = w->venr;
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
        if (cells[s->elem_cell[e] * nn + b] == w->node_of[k] || tiny[m]) continue;
        if (master[k] < 0 || venr[m] > venr[master[k]] ||
            (venr[m] == venr[master[k]] && m < master[k]))
          master[k] = m;
      }
    }
  }
  for (fcm_index k = 0; k < ncopy; k++) /* fragments with a rule-1 master are not separated */
    if (tiny[k] && master[k] >= 0) anchor[uf_find(uf, k)] = -2;
  for (fcm_index k = 0; k < ncopy; k++) {
    if (!tiny[k]) continue;
    const fcm_index r = uf_find(uf, k), n = w->node_of[k];
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
  return count;
}

/* The elements' DOFs of the copies with a master (master) moved to it and flagged
 * (s->elem_con), the copies still in use renumbered node by node. */
static fcm_status follow_masters(fcm_space *s, const fcm_index *master)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_dofs / 3, nn = s->nn;
  fcm_index *renum = NULL;
  FCM_ALLOC(ctx, (size_t)s->num_elems * nn + 1, s->elem_con);
  for (fcm_index e = 0; e < s->num_elems; e++)
    for (int a = 0; a < nn; a++) {
      const fcm_index k = s->elem_dof[e * nn + a] / 3;
      if (master[k] < 0) continue;
      s->elem_dof[e * nn + a] = 3 * master[k];
      s->elem_con[e * nn + a] = 1;
    }
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
cleanup:
  fcm__free(ctx, renum);
  return st;
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
fcm_status fcm__space_constrain_copies(fcm_space *s, double ratio, const fcm_index *inc_ptr,
                                       const fcm_index *inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_dofs / 3;
  copy_work w;
  memset(&w, 0, sizeof w);
  FCM_ALLOC(ctx, ncopy + 1, w.venr);
  FCM_ALLOC(ctx, ncopy + 1, w.master);
  FCM_ALLOC(ctx, ncopy + 1, w.tiny);
  FCM_ALLOC(ctx, ncopy + 1, w.uf);
  FCM_ALLOC(ctx, ncopy + 1, w.node_of);
  FCM_ALLOC(ctx, ncopy + 1, w.anchor);
  const fcm_index ntiny = tiny_copies(s, ratio, inc_ptr, inc, &w);
  for (fcm_index k = 0; k < ncopy; k++)
    w.master[k] = w.anchor[k] = -1, w.uf[k] = k;
  const fcm_index count = ntiny > 0 ? copy_masters(s, &w) : 0;
  if (count > 0) FCM_TRY(ctx, follow_masters(s, w.master));
  s->num_constrained = count;
cleanup:
  fcm__free(ctx, w.venr);
  fcm__free(ctx, w.master);
  fcm__free(ctx, w.tiny);
  fcm__free(ctx, w.uf);
  fcm__free(ctx, w.node_of);
  fcm__free(ctx, w.anchor);
  return st;
}
