/* The multigrid hierarchy on Hex8 and Hex20 box grids (Dick, Georgii, Westermann 2011, Sec. 6):
 * level 0 from the space, coarser levels by merging 2^3 blocks of cells into one coarse cell
 * per connected component, so that separated material is never merged.
 *
 * Dirichlet: eliminated rows (no off-diagonal entry) and coarse DOFs whose coinciding fine
 * DOFs are all inactive stay in P (leaving them out made P rank deficient); coarse ones are
 * decoupled in the Galerkin matrix and get no correction. */
#include "mg/levels_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static fcm_index uf_find(fcm_index *uf, fcm_index a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return a;
}

static void uf_union(fcm_index *uf, fcm_index a, fcm_index b)
{
  a = uf_find(uf, a), b = uf_find(uf, b);
  if (a != b) uf[FCM_MAX(a, b)] = FCM_MIN(a, b);
}

void fcm__mg_level_free(fcm_ctx *ctx, mg_level *L)
{
  fcm__free(ctx, L->ijk);
  fcm__free(ctx, L->corner);
  fcm__free(ctx, L->own);
  fcm__free(ctx, L->adj_ptr);
  fcm__free(ctx, L->adj);
  fcm__free(ctx, L->copy_ijk);
  fcm__free(ctx, L->dof);
  fcm__free(ctx, L->inactive);
  fcm_csr_destroy(&L->Aown);
  fcm__free(ctx, L->diag);
  fcm__free(ctx, L->tpos);
  fcm__free(ctx, L->dinv);
  fcm__free(ctx, L->P_ptr);
  fcm__free(ctx, L->P_col);
  fcm__free(ctx, L->P_val);
  fcm__ptap_destroy(&L->ptap);
  fcm__free(ctx, L->x);
  fcm__free(ctx, L->b);
  fcm__free(ctx, L->r);
  fcm__free(ctx, L->color_ptr);
  fcm__free(ctx, L->color_rows);
  fcm__free(ctx, L->full);
  fcm__free(ctx, L->oct_node);
  fcm__free(ctx, L->oct_body);
  fcm_schwarz_destroy(&L->blk);
  fcm__mg_slabs_free(ctx, &L->rows);
  fcm__mg_slabs_free(ctx, &L->blocks);
  memset(L, 0, sizeof *L);
}

/* Does piece p link to piece q (p < q or q < p) in the sorted link list? */
static int linked(const fcm_index *links, fcm_index nl, fcm_index p, fcm_index q)
{
  const fcm_index a = FCM_MIN(p, q), b = FCM_MAX(p, q);
  fcm_index lo = 0, hi = nl;
  while (lo < hi) {
    const fcm_index mid = lo + (hi - lo) / 2;
    if (links[2 * mid] < a || (links[2 * mid] == a && links[2 * mid + 1] < b))
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < nl && links[2 * lo] == a && links[2 * lo + 1] == b;
}

/* Build the cell graph CSR from an edge list (pairs, both directions added, deduplicated). */
static fcm_status graph_from_edges(fcm_ctx *ctx, fcm_index ncell, fcm_index nedge,
                                   const fcm_index *edges, fcm_index **ptr_out, fcm_index **adj_out)
{
  fcm_status st = FCM_OK;
  fcm_index *ptr = NULL, *adj = NULL, *fill = NULL;
  FCM_ALLOC(ctx, ncell + 1, ptr);
  FCM_ALLOC(ctx, ncell + 1, fill);
  for (fcm_index e = 0; e < nedge; e++)
    ptr[edges[2 * e] + 1]++, ptr[edges[2 * e + 1] + 1]++;
  for (fcm_index c = 0; c < ncell; c++)
    ptr[c + 1] += ptr[c];
  FCM_ALLOC_RAW(ctx, ptr[ncell] + 1, adj); /* every entry written below */
  for (fcm_index e = 0; e < nedge; e++) {
    const fcm_index a = edges[2 * e], b = edges[2 * e + 1];
    adj[ptr[a] + fill[a]++] = b;
    adj[ptr[b] + fill[b]++] = a;
  }
  /* sort and deduplicate each row in place, then compact */
  fcm_index out = 0;
  for (fcm_index c = 0; c < ncell; c++) {
    const fcm_index s = ptr[c], e = ptr[c + 1];
    fcm__insertion_sort(adj + s, e - s); /* a few neighbours */
    ptr[c] = out;
    for (fcm_index i = s; i < e; i++)
      if (i == s || adj[i] != adj[i - 1]) adj[out++] = adj[i];
  }
  ptr[ncell] = out;
  *ptr_out = ptr, *adj_out = adj;
  ptr = adj = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, adj);
  fcm__free(ctx, fill);
  return st;
}

/* Rows of A whose off-diagonal entries are all zero: the eliminated (Dirichlet) ones. */
static void eliminated_rows(const fcm_csr *A, fcm_index n, unsigned char *inactive)
{
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  for (fcm_index i = 0; i < n; i++) {
    int off = 0;
    for (fcm_index p = rp[i]; p < rp[i + 1] && !off; p++)
      off = ci[p] != i && v[p] != 0.0;
    inactive[i] = (unsigned char)!off;
  }
}

/* ------------------------------------------------------------------ level 0 */

/* What the phases of build_level0() share: the mesh, and the grid they find in it. */
typedef struct level0_build {
  fcm_mg *m;
  const fcm_space *sp;
  const fcm_mesh *mesh;
  int hex20, npc;
  mg_level *L0, *L; /* level 0 and the first grid level (the same on Hex8) */
  fcm_index nnode, ncells, nk;
  const fcm_index *cells;
  const fcm_cell_rules *rules;
  const fcm_index *node2;       /* the mesh grid's (mg_grid) */
  const fcm_index *cell_ijk;    /* the mesh grid's */
  const fcm_index *grid;        /* the mesh grid's cell_at */
  const unsigned char *bits_of; /* the mesh grid's */
  fcm_index *copy_node;         /* per space copy: its node */
  fcm_index *cmap;              /* space copy -> grid level copy (-1: none; identity on Hex8) */
  unsigned char *cut;           /* per mesh cell: cut or split */
} level0_build;

/* Grid spacing from cell 0, origin from the bounding box; node positions on the half grid:
 * corners at even, mid-edge nodes at odd coordinates. */
static fcm_status grid_nodes(level0_build *b, mg_grid *mgrid)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  const double *X = fcm_mesh_coords(b->mesh);
  double lo[3], hi[3], h[3];
  fcm_mesh_bounding_box(b->mesh, lo, hi);
  for (int d = 0; d < 3; d++) {
    double mn = INFINITY, mx = -INFINITY;
    for (int a = 0; a < 8; a++) {
      mn = fmin(mn, X[3 * b->cells[a] + d]);
      mx = fmax(mx, X[3 * b->cells[a] + d]);
    }
    h[d] = mx - mn;
    FCM_CHECK(h[d] > 0.0, ctx, FCM_ERR_UNSUPPORTED, "mg: cell 0 has no extent along axis %d", d);
    mgrid->grid[d] = (fcm_index)llround((hi[d] - lo[d]) / h[d]);
  }
  FCM_ALLOC_RAW(ctx, 3 * b->nnode + 1, mgrid->node2); /* every entry written below */
  for (fcm_index n = 0; n < b->nnode; n++)
    for (int d = 0; d < 3; d++) {
      const double t = 2.0 * (X[3 * n + d] - lo[d]) / h[d];
      const fcm_index r = (fcm_index)llround(t);
      FCM_CHECK(fabs(t - (double)r) < 2e-6 && r >= 0 && r <= 2 * mgrid->grid[d], ctx,
                FCM_ERR_UNSUPPORTED,
                "mg: node %lld is not on the grid of spacing %g along axis %d (not a box grid)",
                (long long)n, h[d], d);
      mgrid->node2[3 * n + d] = r;
    }
cleanup:
  return st;
}

/* Cell positions, the cell at each grid position and the corner bits of each local corner
 * node; every cell a grid cube with its nodes in cell 0's order, no two overlapping. */
static fcm_status grid_cells(level0_build *b, mg_grid *mgrid)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  const fcm_index *node2 = mgrid->node2;
  FCM_ALLOC_RAW(ctx, 3 * b->ncells + 1, mgrid->cell_ijk); /* every entry written below */
  const fcm_index gsize = mgrid->grid[0] * mgrid->grid[1] * mgrid->grid[2];
  FCM_ALLOC_RAW(ctx, gsize + 1, mgrid->cell_at);
  fcm_index *cell_ijk = mgrid->cell_ijk, *grid = mgrid->cell_at;
  for (fcm_index g = 0; g < gsize; g++)
    grid[g] = -1;
  for (fcm_index c = 0; c < b->ncells; c++) {
    const fcm_index *cn = b->cells + (fcm_index)b->npc * c;
    for (int d = 0; d < 3; d++) {
      fcm_index mn = node2[3 * cn[0] + d];
      for (int a = 1; a < 8; a++)
        mn = FCM_MIN(mn, node2[3 * cn[a] + d]);
      FCM_CHECK(mn % 2 == 0, ctx, FCM_ERR_UNSUPPORTED,
                "mg: cell %lld does not start at a grid node along axis %d", (long long)c, d);
      cell_ijk[3 * c + d] = mn / 2;
    }
    unsigned seen = 0;
    for (int a = 0; a < 8; a++) {
      int bits = 0;
      for (int d = 0; d < 3; d++) {
        const fcm_index off = node2[3 * cn[a] + d] - 2 * cell_ijk[3 * c + d];
        FCM_CHECK(off == 0 || off == 2, ctx, FCM_ERR_UNSUPPORTED,
                  "mg: cell %lld is not a grid cube (node %d off by %g cells along axis %d)",
                  (long long)c, a, 0.5 * (double)off, d);
        bits |= (int)(off / 2) << d;
      }
      if (c == 0) mgrid->bits_of[a] = (unsigned char)bits;
      FCM_CHECK(bits == mgrid->bits_of[a], ctx, FCM_ERR_UNSUPPORTED,
                "mg: cell %lld orders its nodes unlike cell 0", (long long)c);
      seen |= 1u << bits;
    }
    FCM_CHECK(seen == 0xffu, ctx, FCM_ERR_UNSUPPORTED, "mg: cell %lld is not a grid cube",
              (long long)c);
    const fcm_index g = cell_ijk[3 * c] + mgrid->grid[0] * (cell_ijk[3 * c + 1] +
                                                            mgrid->grid[1] * cell_ijk[3 * c + 2]);
    FCM_CHECK(grid[g] < 0, ctx, FCM_ERR_UNSUPPORTED, "mg: cells %lld and %lld overlap",
              (long long)grid[g], (long long)c);
    grid[g] = c;
  }
cleanup:
  return st;
}

/* The space's copies: their nodes; the grid level's copies (cmap) and their positions. */
static fcm_status grid_copies(level0_build *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  const fcm_space *sp = b->sp;
  mg_level *L = b->L;
  const fcm_index nk = b->nk;
  L->ncell = fcm_space_num_elements(sp);
  FCM_ALLOC(ctx, nk + 1, b->copy_node);
  FCM_ALLOC_RAW(ctx, nk + 1, b->cmap); /* every entry written below */
  fcm_index *copy_node = b->copy_node, *cmap = b->cmap;
  for (fcm_index nd = 0; nd < b->nnode; nd++) {
    const fcm_index k0 = fcm_space_node_dof(sp, nd), nc = fcm_space_node_copies(sp, nd);
    for (fcm_index c = 0; k0 >= 0 && c < nc; c++)
      copy_node[k0 / 3 + c] = nd;
  }
  for (fcm_index k = 0; k < nk; k++)
    cmap[k] = b->hex20 ? -1 : k;
  if (b->hex20) {
    for (fcm_index e = 0; e < L->ncell; e++)
      for (int a = 0; a < 8; a++)
        cmap[fcm_space_element_dofs(sp, e)[a] / 3] = 0;
    L->ncopy = 0;
    for (fcm_index k = 0; k < nk; k++)
      if (cmap[k] == 0) cmap[k] = L->ncopy++;
  } else {
    L->ncopy = nk;
  }
  FCM_ALLOC(ctx, 3 * L->ncopy + 1, L->copy_ijk);
  for (fcm_index k = 0; k < nk; k++)
    for (int d = 0; cmap[k] >= 0 && d < 3; d++) /* mid-edge copies (constraint targets): the */
      L->copy_ijk[3 * cmap[k] + d] = b->node2[3 * copy_node[k] + d] / 2; /* grid node below */
cleanup:
  return st;
}

/* The grid level's cells (the space's elements): positions, corner copies, whether each uses
 * the copy at its own node; the cells that are split or have cut faces. */
static fcm_status grid_elements(level0_build *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  const fcm_space *sp = b->sp;
  mg_level *L = b->L;
  FCM_ALLOC_RAW(ctx, 3 * L->ncell + 1, L->ijk); /* every entry written below (8 corner bits) */
  FCM_ALLOC_RAW(ctx, 8 * L->ncell + 1, L->corner);
  FCM_ALLOC_RAW(ctx, 8 * L->ncell + 1, L->own);
  FCM_ALLOC(ctx, b->ncells + 1, b->cut);
  for (fcm_index e = 0; e < L->ncell; e++) {
    const fcm_index c = fcm_space_element_cell(sp, e);
    const fcm_index *ed = fcm_space_element_dofs(sp, e);
    for (int d = 0; d < 3; d++)
      L->ijk[3 * e + d] = b->cell_ijk[3 * c + d];
    for (int a = 0; a < 8; a++) {
      const fcm_index k = ed[a] / 3;
      const int bits = b->bits_of[a];
      L->corner[8 * e + bits] = b->cmap[k];
      L->own[8 * e + bits] =
          (unsigned char)(b->copy_node[k] == b->cells[(fcm_index)b->npc * c + a]);
    }
    fcm_index first = 0;
    if (fcm_space_cell_elements(sp, c, &first) > 1) b->cut[c] = 1;
    if (b->rules) {
      fcm_index p0 = 0;
      fcm_cell_rules_cell_pieces(b->rules, c, &p0);
      if (fcm_cell_rules_get_piece_cut_faces(b->rules, p0 + (e - first), NULL) > 0) b->cut[c] = 1;
    }
  }
cleanup:
  return st;
}

/* Connectivity: face neighbours (+x, +y, +z) that share the copies of the face, and whose
 * pieces are linked where a cell is cut. */
static fcm_status grid_graph(level0_build *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  const fcm_space *sp = b->sp;
  const fcm_cell_rules *rules = b->rules;
  const fcm_index nl = rules ? fcm_cell_rules_num_links(rules) : 0;
  const fcm_index *links = rules ? fcm_cell_rules_links(rules) : NULL;
  const fcm_index *cell_ijk = b->cell_ijk;
  mg_level *L = b->L;
  /* room for a neighbour along each axis of every element: grown only where cells are split */
  fcm_index *edges = NULL, nedge = 0, cap = 3 * L->ncell + 64;
  FCM_ALLOC_RAW(ctx, 2 * cap, edges); /* read up to nedge, written below */
  for (fcm_index e = 0; e < L->ncell; e++) {
    const fcm_index c = fcm_space_element_cell(sp, e);
    for (int d = 0; d < 3; d++) {
      fcm_index q[3] = {cell_ijk[3 * c], cell_ijk[3 * c + 1], cell_ijk[3 * c + 2]};
      q[d]++;
      if (q[d] >= L->grid[d]) continue;
      const fcm_index c2 = b->grid[q[0] + L->grid[0] * (q[1] + L->grid[1] * q[2])];
      if (c2 < 0) continue;
      fcm_index f1 = 0, f2 = 0;
      fcm_space_cell_elements(sp, c, &f1);
      const fcm_index n2 = fcm_space_cell_elements(sp, c2, &f2);
      for (fcm_index e2 = f2; e2 < f2 + n2; e2++) {
        int share = 0;
        for (int bit = 0; bit < 8 && !share; bit++) {
          if (!(bit >> d & 1)) continue;
          const int b2 = bit & ~(1 << d);
          share = L->own[8 * e + bit] && L->own[8 * e2 + b2] &&
                  L->corner[8 * e + bit] == L->corner[8 * e2 + b2];
        }
        if (!share) continue;
        if ((b->cut[c] || b->cut[c2]) && rules) {
          fcm_index p1 = 0, p2 = 0;
          fcm_cell_rules_cell_pieces(rules, c, &p1);
          fcm_cell_rules_cell_pieces(rules, c2, &p2);
          if (!linked(links, nl, p1 + (e - f1), p2 + (e2 - f2))) continue;
        }
        if (nedge == cap) {
          const fcm_index nc = 2 * cap + 64;
          void *pe = edges;
          FCM_TRY(ctx, fcm__resize(ctx, &pe, (size_t)(2 * cap), (size_t)(2 * nc), sizeof *edges));
          edges = pe, cap = nc;
        }
        edges[2 * nedge] = e, edges[2 * nedge + 1] = e2, nedge++;
      }
    }
  }
  FCM_TRY(ctx, graph_from_edges(ctx, L->ncell, nedge, edges, &L->adj_ptr, &L->adj));
cleanup:
  fcm__free(ctx, edges);
  return st;
}

/* Level 0's DOFs: the space's numbering; inactive: `inactive0`, or the eliminated rows of A
 * (no off-diagonal entry). */
static fcm_status level0_dofs(level0_build *b, const fcm_csr *A, const unsigned char *inactive0)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  mg_level *L0 = b->L0;
  L0->A = A;
  L0->n = 3 * b->nk;
  L0->ncopy = b->nk;
  L0->ncell = b->L->ncell;
  FCM_ALLOC_RAW(ctx, L0->n + 1, L0->dof); /* every entry written below */
  FCM_ALLOC_RAW(ctx, L0->n + 1, L0->inactive);
  for (fcm_index i = 0; i < L0->n; i++)
    L0->dof[i] = i;
  if (inactive0)
    memcpy(L0->inactive, inactive0, (size_t)L0->n);
  else
    eliminated_rows(A, L0->n, L0->inactive);
cleanup:
  return st;
}

/* Hex20: the DOFs of the p-coarse grid level, inactive where the coinciding fine DOF is
 * eliminated, and the prolongation to level 0. */
static fcm_status p_level(level0_build *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  mg_level *L0 = b->L0, *L = b->L;
  L->n = 3 * L->ncopy;
  FCM_ALLOC(ctx, L->n + 1, L->dof);
  FCM_ALLOC(ctx, L->n + 1, L->inactive);
  for (fcm_index i = 0; i < L->n; i++)
    L->dof[i] = i;
  for (fcm_index k = 0; k < b->nk; k++)
    for (int c = 0; b->cmap[k] >= 0 && c < 3; c++)
      L->inactive[3 * b->cmap[k] + c] = L0->inactive[3 * k + c];
  FCM_TRY(ctx, fcm__mg_p_prolongation(ctx, b->sp, L0, L, b->cmap, b->copy_node));
cleanup:
  return st;
}

/* The full cells of the grid level (the block smoother's cells are the others): neither cut
 * nor split, nor on the geometry's boundary. Hands the cut cells to m. */
static fcm_status full_cells(level0_build *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  mg_level *L = b->L;
  for (fcm_index c = 0; b->rules && c < b->ncells; c++)
    if (fcm_cell_rules_class(b->rules, c) == FCM_CELL_CUT) b->cut[c] = 1;
  FCM_ALLOC(ctx, L->ncell + 1, L->full);
  for (fcm_index e = 0; e < L->ncell; e++)
    L->full[e] = (unsigned char)!b->cut[fcm_space_element_cell(b->sp, e)];
  b->m->cut_cell = b->cut;
  b->cut = NULL;
cleanup:
  return st;
}

/* The mesh's grid: m's shared one (fcm__mg_grid_share()), else found (and kept by m). */
static fcm_status mesh_grid(level0_build *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->m->ctx;
  mg_grid *g = NULL; /* a new one, until m holds it */
  if (!b->m->mesh_grid) {
    FCM_ALLOC(ctx, 1, g);
    g->refs = 1;
    g->mesh = b->mesh;
    FCM_TRY(ctx, grid_nodes(b, g));
    FCM_TRY(ctx, grid_cells(b, g));
    b->m->mesh_grid = g;
    g = NULL;
  }
  const mg_grid *mg = b->m->mesh_grid;
  for (int d = 0; d < 3; d++)
    b->L->grid[d] = b->L0->grid[d] = mg->grid[d];
  b->node2 = mg->node2, b->cell_ijk = mg->cell_ijk, b->grid = mg->cell_at, b->bits_of = mg->bits_of;
cleanup:
  fcm__mg_grid_release(ctx, &g);
  return st;
}

void fcm__mg_grid_share(fcm_mg *m, const fcm_mg *from)
{
  if (m->mesh_grid || !from || !from->mesh_grid ||
      from->mesh_grid->mesh != fcm_space_mesh(m->space) || from->oct_mesh[1])
    return;
  mg_grid *g = from->mesh_grid;
#pragma omp atomic update
  g->refs++;
  m->mesh_grid = g;
}

void fcm__mg_grid_release(fcm_ctx *ctx, mg_grid **g)
{
  if (!g || !*g) return;
  int left = 0;
#pragma omp atomic capture
  left = --(*g)->refs;
  if (left == 0) {
    fcm__free(ctx, (*g)->node2);
    fcm__free(ctx, (*g)->cell_ijk);
    fcm__free(ctx, (*g)->cell_at);
    fcm__free(ctx, *g);
  }
  *g = NULL;
}

/* Level 0 is the space. On Hex8 it is also the first grid level: its cells are the space's
 * elements, its copies the space's copies. On Hex20 the first grid level is level 1, the
 * p-coarse Hex8 space on the same grid: the same elements (pieces) with the copies they use
 * at their 8 corners; a copy that some element uses at a corner is a coarse copy and its
 * fine DOFs take its value, a mid-edge copy takes the mean of the corner copies at the ends
 * of its edge in the first element that uses it at its own node (trilinear fields are in
 * the serendipity space, so this is exact for them). */
static fcm_status build_level0(fcm_mg *m, const fcm_csr *A, const unsigned char *inactive0)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_mesh *mesh = fcm_space_mesh(m->space);
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  level0_build b = {.m = m, .sp = m->space, .mesh = mesh, .hex20 = type == FCM_ELEMENT_HEX20};
  FCM_CHECK(type == FCM_ELEMENT_HEX8 || b.hex20, ctx, FCM_ERR_UNSUPPORTED,
            "mg: needs a Hex8 or Hex20 box grid (fcm_mesh_create_box), the mesh has %s elements",
            fcm_element_get_info(type) ? fcm_element_get_info(type)->name : "unknown");
  b.npc = fcm_element_get_info(type)->num_nodes;
  b.L0 = &m->lev[0];
  b.L = b.hex20 ? &m->lev[1] : b.L0;
  b.nnode = fcm_mesh_num_nodes(mesh);
  b.ncells = fcm_mesh_num_cells(mesh);
  b.nk = fcm_space_num_dofs(m->space) / 3;
  b.cells = fcm_mesh_cells(mesh);
  b.rules = fcm_space_cell_rules(m->space);
  FCM_CHECK(b.ncells > 0, ctx, FCM_ERR_ARG, "mg: the mesh has no cells");
  FCM_TRY(ctx, mesh_grid(&b));
  FCM_TRY(ctx, grid_copies(&b));
  FCM_TRY(ctx, grid_elements(&b));
  FCM_TRY(ctx, grid_graph(&b));
  FCM_TRY(ctx, level0_dofs(&b, A, inactive0));
  if (b.hex20) FCM_TRY(ctx, p_level(&b));
  FCM_TRY(ctx, full_cells(&b));
cleanup:
  fcm__free(ctx, b.cut);
  fcm__free(ctx, b.copy_node);
  fcm__free(ctx, b.cmap);
  return st;
}

/* ------------------------------------------------------------------ coarsening */

/* Coarse cells: the components of the cell graph inside each 2^3 block (cid: each fine cell's
 * coarse cell), their positions, and which are full (8 full fine cells). */
static fcm_status coarse_cells(fcm_ctx *ctx, const mg_level *F, mg_level *C, fcm_index **cid_out)
{
  fcm_status st = FCM_OK;
  fcm_index *uf = NULL, *cid = NULL, *cnt = NULL;
  const fcm_index nf = F->ncell;
  for (int d = 0; d < 3; d++)
    C->grid[d] = (F->grid[d] + 1) / 2;
  FCM_ALLOC_RAW(ctx, nf + 1, uf); /* every entry written below */
  FCM_ALLOC_RAW(ctx, nf + 1, cid);
  for (fcm_index c = 0; c < nf; c++)
    uf[c] = c;
  for (fcm_index c = 0; c < nf; c++)
    for (fcm_index i = F->adj_ptr[c]; i < F->adj_ptr[c + 1]; i++) {
      const fcm_index o = F->adj[i];
      int same = 1;
      for (int d = 0; d < 3; d++)
        same &= F->ijk[3 * c + d] / 2 == F->ijk[3 * o + d] / 2;
      if (same) uf_union(uf, c, o);
    }
  fcm_index nc = 0;
  for (fcm_index c = 0; c < nf; c++) {
    const fcm_index r = uf_find(uf, c);
    cid[c] = r == c ? nc++ : cid[r];
  }
  C->ncell = nc;
  FCM_ALLOC(ctx, 3 * nc + 1, C->ijk);
  FCM_ALLOC(ctx, 8 * nc + 1, C->corner);
  FCM_ALLOC(ctx, 8 * nc + 1, C->own);
  for (fcm_index c = 0; c < nf; c++)
    for (int d = 0; d < 3; d++)
      C->ijk[3 * cid[c] + d] = F->ijk[3 * c + d] / 2;
  for (fcm_index i = 0; i < 8 * nc; i++)
    C->own[i] = 1;
  FCM_ALLOC(ctx, nc + 1, C->full);
  FCM_ALLOC(ctx, nc + 1, cnt);
  for (fcm_index c = 0; c < nf; c++)
    cnt[cid[c]] += F->full[c] ? 1 : 9; /* any partial child: > 8 */
  for (fcm_index c = 0; c < nc; c++)
    C->full[c] = (unsigned char)(cnt[c] == 8);
  *cid_out = cid;
  cid = NULL;
cleanup:
  fcm__free(ctx, uf);
  fcm__free(ctx, cid);
  fcm__free(ctx, cnt);
  return st;
}

/* The coarse cell graph: coarse cells joined by a fine edge. */
static fcm_status coarse_graph(fcm_ctx *ctx, const mg_level *F, mg_level *C, const fcm_index *cid)
{
  fcm_status st = FCM_OK;
  fcm_index *edges = NULL, nedge = 0;
  FCM_ALLOC(ctx, F->adj_ptr[F->ncell] + 1, edges);
  for (fcm_index c = 0; c < F->ncell; c++)
    for (fcm_index i = F->adj_ptr[c]; i < F->adj_ptr[c + 1]; i++) {
      const fcm_index a = cid[c], b = cid[F->adj[i]];
      if (a < b) edges[2 * nedge] = a, edges[2 * nedge + 1] = b, nedge++;
    }
  FCM_TRY(ctx, graph_from_edges(ctx, C->ncell, nedge, edges, &C->adj_ptr, &C->adj));
cleanup:
  fcm__free(ctx, edges);
  return st;
}

/* The users of each fine copy (at its own node): coarse cells, CSR over the copies. */
static fcm_status copy_users(fcm_ctx *ctx, const mg_level *F, const fcm_index *cid,
                             fcm_index **cptr_out, fcm_index **cusers_out)
{
  fcm_status st = FCM_OK;
  fcm_index *cptr = NULL, *cusers = NULL, *cfill = NULL;
  const fcm_index nk = F->ncopy, nf = F->ncell;
  FCM_ALLOC(ctx, nk + 1, cptr);
  FCM_ALLOC(ctx, nk + 1, cfill);
  for (fcm_index c = 0; c < nf; c++)
    for (int b = 0; b < 8; b++)
      if (F->own[8 * c + b]) cptr[F->corner[8 * c + b] + 1]++;
  for (fcm_index k = 0; k < nk; k++)
    cptr[k + 1] += cptr[k];
  FCM_ALLOC_RAW(ctx, cptr[nk] + 1, cusers); /* every entry written below */
  for (fcm_index c = 0; c < nf; c++)
    for (int b = 0; b < 8; b++)
      if (F->own[8 * c + b]) {
        const fcm_index k = F->corner[8 * c + b];
        cusers[cptr[k] + cfill[k]++] = cid[c];
      }
  *cptr_out = cptr, *cusers_out = cusers;
  cptr = cusers = NULL;
cleanup:
  fcm__free(ctx, cptr);
  fcm__free(ctx, cusers);
  fcm__free(ctx, cfill);
  return st;
}

/* The coarse copies: the corner slots of the coarse cells, merged where a fine copy used by
 * several coarse cells interpolates from the same coarse node of each; their positions. */
static fcm_status coarse_copies(fcm_ctx *ctx, const mg_level *F, mg_level *C, const fcm_index *cptr,
                                const fcm_index *cusers)
{
  fcm_status st = FCM_OK;
  fcm_index *uf = NULL;
  const fcm_index nc = C->ncell;
  FCM_ALLOC_RAW(ctx, 8 * nc + 1, uf); /* every entry written below */
  for (fcm_index s = 0; s < 8 * nc; s++)
    uf[s] = s;
  for (fcm_index k = 0; k < F->ncopy; k++) {
    if (cptr[k + 1] - cptr[k] < 2) continue;
    const fcm_index c0 = cusers[cptr[k]];
    const fcm_index *pk = F->copy_ijk + 3 * k, *q0 = C->ijk + 3 * c0;
    /* the coarse nodes with nonzero weight: the corner bits of c0 within one fine cell of
     * the copy along every axis (bit 0: node 2 q0, bit 1: node 2 q0 + 2) */
    int along[3];
    for (int d = 0; d < 3; d++) {
      const fcm_index off = pk[d] - 2 * q0[d];
      along[d] = (off >= -1 && off <= 1 ? 1 : 0) | (off >= 1 && off <= 3 ? 2 : 0);
    }
    for (int b = 0; b < 8; b++) {
      if (!(along[0] >> (b & 1) & 1) || !(along[1] >> (b >> 1 & 1) & 1) ||
          !(along[2] >> (b >> 2 & 1) & 1))
        continue;
      /* the same node as a corner of every other user: its slots joined to c0's, the set's
       * root (its smallest slot, as uf_union() links) found once */
      fcm_index r0 = uf_find(uf, 8 * c0 + b);
      for (fcm_index i = cptr[k] + 1; i < cptr[k + 1]; i++) {
        const fcm_index c1 = cusers[i];
        int b1 = 0;
        for (int d = 0; d < 3; d++) {
          const fcm_index off = q0[d] + (b >> d & 1) - C->ijk[3 * c1 + d];
          FCM_CHECK(off == 0 || off == 1, ctx, FCM_ERR_INTERNAL,
                    "mg: copy %lld used by coarse cells %lld and %lld that share no node",
                    (long long)k, (long long)c0, (long long)c1);
          b1 |= (int)off << d;
        }
        const fcm_index s1 = 8 * c1 + b1;
        if (s1 == r0 || uf[s1] == r0) continue; /* joined already (r0 is a root) */
        const fcm_index r1 = uf_find(uf, s1);
        if (r1 == r0) continue;
        uf[FCM_MAX(r0, r1)] = FCM_MIN(r0, r1);
        r0 = FCM_MIN(r0, r1);
      }
    }
  }
  fcm_index ncopy = 0;
  for (fcm_index s = 0; s < 8 * nc; s++) {
    const fcm_index r = uf_find(uf, s);
    C->corner[s] = r == s ? ncopy++ : C->corner[r];
  }
  C->ncopy = ncopy;
  FCM_ALLOC(ctx, 3 * ncopy + 1, C->copy_ijk);
  for (fcm_index s = 0; s < 8 * nc; s++)
    for (int d = 0; d < 3; d++)
      C->copy_ijk[3 * C->corner[s] + d] = C->ijk[3 * (s / 8) + d] + (s % 8 >> d & 1);
cleanup:
  fcm__free(ctx, uf);
  return st;
}

/* Coarse DOFs, all 3 per copy; inactive (Dirichlet) when all fine DOFs at the same point are
 * inactive (eliminated on level 0, inactive on coarser levels): the coarse node lies on the
 * Dirichlet boundary. Inactive DOFs keep their rows and their columns of P (as eliminated rows
 * on level 0 do), so P stays injective and every coarse matrix positive definite; the Galerkin
 * matrix decouples them (off-diagonals zeroed, the diagonal kept: a spring) and the cycle
 * restricts zero to them and prolongates nothing from them. Leaving them out instead made P
 * rank deficient next to a clamped face (a coarse cell whose material lies in the fine layer
 * at the face sees its free fine DOFs on one plane only) and the coarsest CHOLMOD factor
 * fail. */
static fcm_status coarse_dofs(fcm_ctx *ctx, const mg_level *F, mg_level *C,
                              const fcm_index *scal_ptr, const fcm_index *scal_col,
                              const double *scal_w)
{
  fcm_status st = FCM_OK;
  fcm_index *anc = NULL, *anc_in = NULL, *cused = NULL;
  const fcm_index ncopy = C->ncopy;
  FCM_ALLOC(ctx, ncopy + 1, anc);
  FCM_ALLOC(ctx, ncopy + 1, cused);
  FCM_ALLOC(ctx, 3 * ncopy + 1, anc_in);
  for (fcm_index k = 0; k < F->ncopy; k++)
    for (fcm_index p = scal_ptr[k]; p < scal_ptr[k + 1]; p++) {
      cused[scal_col[p]]++;
      if (scal_w[p] != 1.0) continue;
      const fcm_index K = scal_col[p];
      anc[K]++;
      for (int c = 0; c < 3; c++)
        anc_in[3 * K + c] += F->inactive[3 * k + c];
    }
  C->n = 3 * ncopy;
  FCM_ALLOC_RAW(ctx, C->n + 1, C->dof); /* every entry written below */
  FCM_ALLOC_RAW(ctx, C->n + 1, C->inactive);
  for (fcm_index K = 0; K < ncopy; K++)
    for (int c = 0; c < 3; c++) {
      C->dof[3 * K + c] = 3 * K + c;
      /* a corner no fine copy interpolates from (the elements of its cell use copies of
       * other nodes in place of tiny ones there) has an empty column: inactive too */
      C->inactive[3 * K + c] =
          (unsigned char)(cused[K] == 0 || (anc[K] > 0 && anc_in[3 * K + c] == anc[K]));
    }
cleanup:
  fcm__free(ctx, anc);
  fcm__free(ctx, cused);
  fcm__free(ctx, anc_in);
  return st;
}

/* Build level l+1's cells, copies, graph and DOFs and the prolongation P_l. */
static fcm_status coarsen(fcm_mg *m, int l)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_level *F = &m->lev[l], *C = &m->lev[l + 1];
  fcm_index *cid = NULL, *cptr = NULL, *cusers = NULL, *scal_ptr = NULL, *scal_col = NULL;
  double *scal_w = NULL;
  FCM_TRY(ctx, coarse_cells(ctx, F, C, &cid));
  FCM_TRY(ctx, coarse_graph(ctx, F, C, cid));
  FCM_TRY(ctx, copy_users(ctx, F, cid, &cptr, &cusers));
  FCM_TRY(ctx, coarse_copies(ctx, F, C, cptr, cusers));
  FCM_TRY(ctx, fcm__mg_scalar_prolongation(ctx, F, C, cptr, cusers, &scal_ptr, &scal_col, &scal_w));
  FCM_TRY(ctx, coarse_dofs(ctx, F, C, scal_ptr, scal_col, scal_w));
  FCM_TRY(ctx, fcm__mg_dof_prolongation(ctx, F, C, scal_ptr, scal_col, scal_w));
cleanup:
  fcm__free(ctx, cid);
  fcm__free(ctx, cptr);
  fcm__free(ctx, cusers);
  fcm__free(ctx, scal_ptr);
  fcm__free(ctx, scal_col);
  fcm__free(ctx, scal_w);
  return st;
}

/* ------------------------------------------------------------------ the levels */

fcm_status fcm__mg_build_hierarchy(fcm_mg *m, const fcm_csr *A, const unsigned char *inactive0)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_mg_options o = m->opts;
  if (fcm_mesh_num_hanging(fcm_space_mesh(m->space)) > 0)
    return fcm__mg_octree_hierarchy(m, A, inactive0);
  FCM_TRY(ctx, build_level0(m, A, inactive0));
  m->nlev = 1;
  if (m->lev[1].ncell > 0) { /* Hex20: the p-coarse Hex8 level */
    if (o.max_levels >= 2) {
      m->nlev = 2;
    } else { /* the space alone, solved directly */
      fcm__mg_level_free(ctx, &m->lev[1]);
      mg_level *L0 = &m->lev[0];
      FCM_FREE(ctx, L0->P_ptr);
      FCM_FREE(ctx, L0->P_col);
      FCM_FREE(ctx, L0->P_val);
    }
  }
  while (m->nlev < o.max_levels && m->lev[m->nlev - 1].n > o.coarse_dofs) {
    const mg_level *F = &m->lev[m->nlev - 1];
    if (F->grid[0] <= 1 && F->grid[1] <= 1 && F->grid[2] <= 1) break;
    FCM_TRY(ctx, coarsen(m, m->nlev - 1));
    m->nlev++;
    if (m->lev[m->nlev - 1].n == 0 || m->lev[m->nlev - 1].n >= F->n) {
      /* nothing left to correct, or no reduction (separate cells in one block): stop */
      m->nlev--;
      fcm__mg_level_free(ctx, &m->lev[m->nlev]);
      break;
    }
  }
cleanup:
  return st;
}

fcm_status fcm_mg_get_level_info(const fcm_mg *m, int level, fcm_mg_level_info *info)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  fcm_index *uf = NULL;
  FCM_CHECK(m && info && level >= 0 && level < m->nlev, ctx, FCM_ERR_ARG,
            "mg_get_level_info: NULL argument or level %d outside [0, %d)", level, m ? m->nlev : 0);
  const mg_level *L = &m->lev[level];
  info->cells = L->ncell;
  info->copies = L->ncopy;
  info->dofs = L->n;
  info->colors = L->ncolor;
  fcm_csr_get_size(fcm__mg_level_matrix(L), NULL, NULL, &info->nnz);
  for (int d = 0; d < 3; d++)
    info->grid[d] = L->grid[d];
  /* bodies: cells joined through shared copies (Hex20 level 0: the space's elements) */
  FCM_ALLOC(ctx, L->ncell + L->ncopy + 1, uf);
  for (fcm_index i = 0; i < L->ncell + L->ncopy; i++)
    uf[i] = i;
  const fcm_space *sp = L->sp ? L->sp : m->space; /* the Hex20 level 0 or an octree level */
  const int npc = fcm_element_get_info(fcm_mesh_element_type(fcm_space_mesh(sp)))->num_nodes;
  for (fcm_index c = 0; c < L->ncell; c++)
    if (L->corner)
      for (int b = 0; b < 8; b++)
        uf_union(uf, c, L->ncell + L->corner[8 * c + b]);
    else
      for (int a = 0; a < npc; a++)
        uf_union(uf, c, L->ncell + fcm_space_element_dofs(sp, c)[a] / 3);
  fcm_index nb = 0;
  for (fcm_index c = 0; c < L->ncell; c++)
    nb += uf_find(uf, c) == c;
  info->bodies = nb;
cleanup:
  fcm__free(ctx, uf);
  return st;
}
