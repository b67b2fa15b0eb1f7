/* Cut-aware geometric multigrid on Hex8 and Hex20 box grids (Dick, Georgii, Westermann 2011,
 * Sec. 6), with a vertex-block smoother at cut cells (de Prenter et al. 2020).
 *
 * NOTES (state of issue 13, for whoever continues):
 * - Done: hierarchy for Hex8 box grids (any cell count, dropped cells, XFEM pieces), per
 *   component trilinear prolongation, restriction = P^T, Galerkin RAP (sparse, pattern once,
 *   values again in fcm_mg_setup()), CHOLMOD on the coarsest level, smoothers SGS
 *   (default; in slab order, two threads), SGS in multicolour order (colour-parallel) and
 *   damped Jacobi, all deterministic for any thread count; V- and W-cycles as solver
 *   (fcm_mg_solve) and as a symmetric CG preconditioner (fcm_mg_operator); the W-cycle is
 *   the default. Hex20: a p-level to the Hex8 space of the same elements (build_level0).
 *   Block smoothing (block_smoothers_create, block_smooth): level 0 vertex blocks (de
 *   Prenter) plus the element blocks of cut cells, coarser levels the corner DOFs of cells
 *   that are not all material. Measured: Hex20 embedded hemisphere 0.96 per V-cycle without
 *   blocks (two-grid on the p-level alone 0.955, more pointwise sweeps did not help, element
 *   blocks alone 0.64-0.84), 0.07-0.32 with vertex blocks; hollow ball with holes (Hex8)
 *   0.40-0.85 growing with n with level 0 blocks only, V 0.28-0.43 with coarse blocks, W
 *   0.17-0.23 flat (n = 8 ... 48). Used by the scenes (sim/linsolve.c) and
 *   apps/fcm-scaling.c. Tests in tests/mg/.
 * - fcm__mg_transfers_create() (mg_impl.h): the hierarchy's prolongations and block lists
 *   without a matrix (build_hierarchy(), the code fcm_mg_create() runs), for PETSc's PCMG
 *   (lib/src/petsc/pcmg.c).
 * - Known: with XFEM cuts the V-cycle factor depends on where the cut lies in the grid
 *   (0.1 to 0.45 measured for n = 4 ... 64 with block smoothing, not growing with n), also
 *   for a cut through the whole body, so not the cut's end; Dick et al. report 0.75 cut.
 *   fcm_mg_setup() needs the same eliminated rows.
 * - Threads: each level's cycle work runs in two parallel regions (pre_smooth(),
 *   post_smooth()), the sweeps in slab orders (slab_order: the pointwise SGS in two thick
 *   row ranges and the thin one between them, the block sweep in up to 16 slabs), the
 *   Galerkin product and its pattern by rows. Still sequential: the hierarchy's grid build
 *   (build_hierarchy(), about 2% of fcm_mg_create()), the coarsest factorization and solve,
 *   the thin slab of each SGS sweep, Hex20's finest pointwise sweeps (numbered corners
 *   first: one slab). Measured with tests/bench/bench_mg_shared.c (lib/docs/
 *   multigrid_threads.md).
 * - Dirichlet: eliminated rows (no off-diagonal entry) and coarse DOFs whose coinciding
 *   fine DOFs are all inactive stay in P (leaving them out made P rank deficient); coarse
 *   ones are decoupled in the Galerkin matrix and get no correction.
 *
 * Data per grid level l (level 0 on Hex8, levels >= 1 on Hex20, whose level 0 has only its
 * DOFs, matrix and prolongation): cells (the first grid level: the space's elements) with a
 * grid position and 8 corner copies (corner bits dx + 2 dy + 4 dz), copies with a node grid
 * position, the connectivity of the cells (face neighbours), and for l < L-1 the DOF
 * prolongation P_l from level l+1.
 * DOFs: copy k, component c is row 3k + c of the level matrix on every level (level 0: the
 * space's numbering); inactive rows are the Dirichlet ones. */
#include "core/core_impl.h"
#include "fcm/mg.h"
#include "mg/mg_impl.h"
#include "solve/solve_impl.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Two-colour slab order of the items of a graph (the rows of a level matrix, or the blocks of
 * its block smoother; two items are adjacent when the update of one reads what the other
 * writes): a sequence of the items cut into consecutive slabs such that slabs s and s + 2 hold
 * no adjacent items, so the slabs of one colour (slab index parity) are independent. A
 * Gauss-Seidel sweep in the order "the slabs of colour `first`, then those of the other
 * colour, each slab's items in sequence" is one sequential sweep in a fixed order, whose slabs
 * of one colour may run in parallel. The order depends on the pattern only, so the iterates
 * do not depend on the thread count. */
typedef struct slab_order {
  fcm_index nslab;
  int first;       /* the colour swept first */
  fcm_index *ptr;  /* nslab + 1 offsets into item */
  fcm_index *item; /* the items, slab after slab, ascending within a slab */
  double *mid;     /* per slab: the midpoint of its work within its colour's, in [0, 1] */
} slab_order;

/* Levels with at least this many stored entries share their work between the threads. */
#define MG_PARALLEL_NNZ 32768

typedef struct mg_level {
  fcm_index grid[3];  /* cells per axis */
  fcm_index ncell;    /* cells (level 0: elements) */
  fcm_index *ijk;     /* 3 per cell */
  fcm_index *corner;  /* 8 copies per cell (corner bits dx + 2 dy + 4 dz) */
  unsigned char *own; /* level 0: the element uses the copy at its own node (1 on coarse) */
  fcm_index *adj_ptr; /* cell graph (connected face neighbours), CSR */
  fcm_index *adj;
  fcm_index ncopy;
  fcm_index *copy_ijk;     /* 3 per copy: node grid position */
  fcm_index *dof;          /* 3 per copy: row or -1 */
  unsigned char *inactive; /* per row: eliminated (level 0) */
  fcm_index n;             /* rows */
  const fcm_csr *A;        /* level 0: borrowed */
  fcm_csr *Aown;           /* levels >= 1 */
  fcm_index *diag;         /* position of a_ii */
  double *dinv;            /* 1 / a_ii */
  /* prolongation from level l+1 (n x n_coarse) and its transpose */
  fcm_index *P_ptr, *R_ptr;
  int *P_col, *R_col;
  double *P_val, *R_val;
  /* A P (n x n_coarse) pattern and values, for the Galerkin product */
  fcm_index *AP_ptr;
  int *AP_col;
  double *AP_val;
  double *x, *b, *r; /* work vectors (x, b unused on level 0) */
  int ncolor;        /* SGS_COLORED: rows by colour, CSR over colours */
  fcm_index *color_ptr, *color_rows;
  unsigned char *full; /* grid levels: per cell, 1 when it is all material (uncut, and on
                          coarse levels made of 8 such cells) */
  fcm_schwarz *blk;    /* block smoother (block_smoothing): the level's blocks */
  slab_order rows;     /* SGS: the rows in slabs (levels but the coarsest) */
  slab_order blocks;   /* the blocks of blk in slabs */
} mg_level;

struct fcm_mg {
  fcm_ctx *ctx;
  const fcm_space *space;
  fcm_mg_options opts;
  int nlev;
  mg_level lev[32];
  fcm_direct *direct;
  double *spa;             /* dense accumulators, spa_len per thread */
  unsigned char *cut_cell; /* per mesh cell: cut by the geometry or a cut surface, or split */
  fcm_index blk_max;       /* largest block of the block smoothers */
  int nt;                  /* threads at creation: the most any parallel region uses */
  double *blk_r, *blk_dx;  /* blk_max entries each, per thread */
  fcm_index spa_len;       /* entries of one thread's dense accumulator */
};

/* Threads of a parallel region: the caller's, at most those of the creation (scratch). */
static int team(const fcm_mg *m)
{
  const int t = omp_get_max_threads();
  return t < m->nt ? t : m->nt;
}

fcm_mg_options fcm_mg_options_default(void)
{
  fcm_mg_options o;
  o.smoother = FCM_MG_SMOOTHER_SGS;
  o.omega = 1.0;
  o.pre_smooth = 1;
  o.post_smooth = 1;
  o.cycle_index = 2;
  o.max_levels = 20;
  o.coarse_dofs = 2000;
  o.block_smoothing = 1;
  return o;
}

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

static int cmp_index(const void *a, const void *b)
{
  const fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

static int cmp_int(const void *a, const void *b)
{
  const int x = *(const int *)a, y = *(const int *)b;
  return (x > y) - (x < y);
}

/* Pairs of fcm_index, lexicographically. */
static int cmp_pair(const void *a, const void *b)
{
  const fcm_index *x = a, *y = b;
  return x[0] != y[0] ? (x[0] > y[0]) - (x[0] < y[0]) : (x[1] > y[1]) - (x[1] < y[1]);
}

static void slabs_free(fcm_ctx *ctx, slab_order *S)
{
  fcm__free(ctx, S->ptr);
  fcm__free(ctx, S->item);
  fcm__free(ctx, S->mid);
  memset(S, 0, sizeof *S);
}

static void level_free(fcm_ctx *ctx, mg_level *L)
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
  fcm__free(ctx, L->dinv);
  fcm__free(ctx, L->P_ptr);
  fcm__free(ctx, L->P_col);
  fcm__free(ctx, L->P_val);
  fcm__free(ctx, L->R_ptr);
  fcm__free(ctx, L->R_col);
  fcm__free(ctx, L->R_val);
  fcm__free(ctx, L->AP_ptr);
  fcm__free(ctx, L->AP_col);
  fcm__free(ctx, L->AP_val);
  fcm__free(ctx, L->x);
  fcm__free(ctx, L->b);
  fcm__free(ctx, L->r);
  fcm__free(ctx, L->color_ptr);
  fcm__free(ctx, L->color_rows);
  fcm__free(ctx, L->full);
  fcm_schwarz_destroy(&L->blk);
  slabs_free(ctx, &L->rows);
  slabs_free(ctx, &L->blocks);
  memset(L, 0, sizeof *L);
}

void fcm_mg_destroy(fcm_mg **mg)
{
  if (!mg || !*mg) return;
  fcm_mg *m = *mg;
  for (int l = 0; l < 32; l++)
    level_free(m->ctx, &m->lev[l]);
  fcm_direct_destroy(&m->direct);
  fcm__free(m->ctx, m->cut_cell);
  fcm__free(m->ctx, m->blk_r);
  fcm__free(m->ctx, m->blk_dx);
  fcm__free(m->ctx, m->spa);
  fcm__free(m->ctx, m);
  *mg = NULL;
}

/* ------------------------------------------------------------------ level 0 */

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
  FCM_ALLOC(ctx, ptr[ncell] + 1, adj);
  for (fcm_index e = 0; e < nedge; e++) {
    const fcm_index a = edges[2 * e], b = edges[2 * e + 1];
    adj[ptr[a] + fill[a]++] = b;
    adj[ptr[b] + fill[b]++] = a;
  }
  /* sort and deduplicate each row in place, then compact */
  fcm_index out = 0;
  for (fcm_index c = 0; c < ncell; c++) {
    const fcm_index s = ptr[c], e = ptr[c + 1];
    qsort(adj + s, (size_t)(e - s), sizeof *adj, cmp_index);
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

/* P (F->n x C->n) from per-row lists of (column, weight) pairs, at most `width` per row
 * (column -1: none), and R = P^T. */
static fcm_status transfer_from_rows(fcm_ctx *ctx, mg_level *F, fcm_index ncoarse, int width,
                                     const fcm_index *col, const double *w)
{
  fcm_status st = FCM_OK;
  fcm_index *fill = NULL;
  FCM_ALLOC(ctx, F->n + 1, F->P_ptr);
  for (fcm_index i = 0; i < F->n; i++) {
    fcm_index c = 0;
    for (int j = 0; j < width; j++)
      c += col[(fcm_index)width * i + j] >= 0;
    F->P_ptr[i + 1] = F->P_ptr[i] + c;
  }
  const fcm_index nnz = F->P_ptr[F->n];
  FCM_ALLOC(ctx, nnz + 1, F->P_col);
  FCM_ALLOC(ctx, nnz + 1, F->P_val);
  for (fcm_index i = 0, q = 0; i < F->n; i++)
    for (int j = 0; j < width; j++)
      if (col[(fcm_index)width * i + j] >= 0) {
        F->P_col[q] = (int)col[(fcm_index)width * i + j];
        F->P_val[q++] = w[(fcm_index)width * i + j];
      }
  FCM_ALLOC(ctx, ncoarse + 2, F->R_ptr);
  FCM_ALLOC(ctx, nnz + 1, F->R_col);
  FCM_ALLOC(ctx, nnz + 1, F->R_val);
  FCM_ALLOC(ctx, ncoarse + 1, fill);
  for (fcm_index p = 0; p < nnz; p++)
    F->R_ptr[F->P_col[p] + 1]++;
  for (fcm_index J = 0; J < ncoarse; J++)
    F->R_ptr[J + 1] += F->R_ptr[J];
  for (fcm_index i = 0; i < F->n; i++)
    for (fcm_index p = F->P_ptr[i]; p < F->P_ptr[i + 1]; p++) {
      const fcm_index J = F->P_col[p];
      F->R_col[F->R_ptr[J] + fill[J]] = (int)i;
      F->R_val[F->R_ptr[J] + fill[J]++] = F->P_val[p];
    }
cleanup:
  fcm__free(ctx, fill);
  return st;
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
  const fcm_space *sp = m->space;
  const fcm_mesh *mesh = fcm_space_mesh(sp);
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  const int hex20 = type == FCM_ELEMENT_HEX20;
  mg_level *L0 = &m->lev[0], *L = hex20 ? &m->lev[1] : L0; /* L: the first grid level */
  const fcm_index nnode = fcm_mesh_num_nodes(mesh), ncells = fcm_mesh_num_cells(mesh);
  const fcm_index *cells = fcm_mesh_cells(mesh);
  const double *X = fcm_mesh_coords(mesh);
  const fcm_cell_rules *rules = fcm_space_cell_rules(sp);
  const fcm_index nl = rules ? fcm_cell_rules_num_links(rules) : 0;
  const fcm_index *links = rules ? fcm_cell_rules_links(rules) : NULL;
  fcm_index *node2 = NULL, *cell_ijk = NULL, *grid = NULL, *edges = NULL, *copy_node = NULL,
            *cmap = NULL, *pcol = NULL;
  double *pw = NULL;
  unsigned char *cut = NULL;
  fcm_index nedge = 0, cap = 0;
  FCM_CHECK(type == FCM_ELEMENT_HEX8 || hex20, ctx, FCM_ERR_UNSUPPORTED,
            "mg: needs a Hex8 or Hex20 box grid (fcm_mesh_create_box), the mesh has %s elements",
            fcm_element_get_info(type) ? fcm_element_get_info(type)->name : "unknown");
  const int npc = fcm_element_get_info(type)->num_nodes;
  FCM_CHECK(ncells > 0, ctx, FCM_ERR_ARG, "mg: the mesh has no cells");
  /* grid spacing from cell 0, origin from the bounding box */
  double lo[3], hi[3], h[3];
  fcm_mesh_bounding_box(mesh, lo, hi);
  for (int d = 0; d < 3; d++) {
    double mn = INFINITY, mx = -INFINITY;
    for (int a = 0; a < 8; a++) {
      mn = fmin(mn, X[3 * cells[a] + d]);
      mx = fmax(mx, X[3 * cells[a] + d]);
    }
    h[d] = mx - mn;
    FCM_CHECK(h[d] > 0.0, ctx, FCM_ERR_UNSUPPORTED, "mg: cell 0 has no extent along axis %d", d);
    L->grid[d] = (fcm_index)llround((hi[d] - lo[d]) / h[d]);
  }
  if (hex20) L0->grid[0] = L->grid[0], L0->grid[1] = L->grid[1], L0->grid[2] = L->grid[2];
  /* node positions on the half grid: corners at even, mid-edge nodes at odd coordinates */
  FCM_ALLOC(ctx, 3 * nnode + 1, node2);
  for (fcm_index n = 0; n < nnode; n++)
    for (int d = 0; d < 3; d++) {
      const double t = 2.0 * (X[3 * n + d] - lo[d]) / h[d];
      const fcm_index r = (fcm_index)llround(t);
      FCM_CHECK(fabs(t - (double)r) < 2e-6 && r >= 0 && r <= 2 * L->grid[d], ctx,
                FCM_ERR_UNSUPPORTED,
                "mg: node %lld is not on the grid of spacing %g along axis %d (not a box grid)",
                (long long)n, h[d], d);
      node2[3 * n + d] = r;
    }
  /* cell positions and the corner bits of each local corner node */
  FCM_ALLOC(ctx, 3 * ncells + 1, cell_ijk);
  const fcm_index gsize = L->grid[0] * L->grid[1] * L->grid[2];
  FCM_ALLOC(ctx, gsize + 1, grid);
  for (fcm_index g = 0; g < gsize; g++)
    grid[g] = -1;
  unsigned char bits_of[8] = {0};
  for (fcm_index c = 0; c < ncells; c++) {
    const fcm_index *cn = cells + (fcm_index)npc * c;
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
      if (c == 0) bits_of[a] = (unsigned char)bits;
      FCM_CHECK(bits == bits_of[a], ctx, FCM_ERR_UNSUPPORTED,
                "mg: cell %lld orders its nodes unlike cell 0", (long long)c);
      seen |= 1u << bits;
    }
    FCM_CHECK(seen == 0xffu, ctx, FCM_ERR_UNSUPPORTED, "mg: cell %lld is not a grid cube",
              (long long)c);
    const fcm_index g =
        cell_ijk[3 * c] + L->grid[0] * (cell_ijk[3 * c + 1] + L->grid[1] * cell_ijk[3 * c + 2]);
    FCM_CHECK(grid[g] < 0, ctx, FCM_ERR_UNSUPPORTED, "mg: cells %lld and %lld overlap",
              (long long)grid[g], (long long)c);
    grid[g] = c;
  }
  /* the space's copies: their nodes; the grid level's copies (cmap: space copy -> grid
   * level copy, -1 for copies no element uses at a corner; the identity on Hex8) */
  const fcm_index nk = fcm_space_num_dofs(sp) / 3;
  L->ncell = fcm_space_num_elements(sp);
  FCM_ALLOC(ctx, nk + 1, copy_node);
  FCM_ALLOC(ctx, nk + 1, cmap);
  for (fcm_index nd = 0; nd < nnode; nd++) {
    const fcm_index k0 = fcm_space_node_dof(sp, nd), nc = fcm_space_node_copies(sp, nd);
    for (fcm_index c = 0; k0 >= 0 && c < nc; c++)
      copy_node[k0 / 3 + c] = nd;
  }
  for (fcm_index k = 0; k < nk; k++)
    cmap[k] = hex20 ? -1 : k;
  if (hex20) {
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
      L->copy_ijk[3 * cmap[k] + d] = node2[3 * copy_node[k] + d] / 2; /* grid node below */
  /* elements */
  FCM_ALLOC(ctx, 3 * L->ncell + 1, L->ijk);
  FCM_ALLOC(ctx, 8 * L->ncell + 1, L->corner);
  FCM_ALLOC(ctx, 8 * L->ncell + 1, L->own);
  FCM_ALLOC(ctx, ncells + 1, cut);
  for (fcm_index e = 0; e < L->ncell; e++) {
    const fcm_index c = fcm_space_element_cell(sp, e);
    const fcm_index *ed = fcm_space_element_dofs(sp, e);
    for (int d = 0; d < 3; d++)
      L->ijk[3 * e + d] = cell_ijk[3 * c + d];
    for (int a = 0; a < 8; a++) {
      const fcm_index k = ed[a] / 3;
      const int b = bits_of[a];
      L->corner[8 * e + b] = cmap[k];
      L->own[8 * e + b] = (unsigned char)(copy_node[k] == cells[(fcm_index)npc * c + a]);
    }
    fcm_index first = 0;
    if (fcm_space_cell_elements(sp, c, &first) > 1) cut[c] = 1;
    if (rules) {
      fcm_index p0 = 0;
      fcm_cell_rules_cell_pieces(rules, c, &p0);
      if (fcm_cell_rules_get_piece_cut_faces(rules, p0 + (e - first), NULL) > 0) cut[c] = 1;
    }
  }
  /* connectivity: face neighbours (+x, +y, +z) */
  for (fcm_index e = 0; e < L->ncell; e++) {
    const fcm_index c = fcm_space_element_cell(sp, e);
    for (int d = 0; d < 3; d++) {
      fcm_index q[3] = {cell_ijk[3 * c], cell_ijk[3 * c + 1], cell_ijk[3 * c + 2]};
      q[d]++;
      if (q[d] >= L->grid[d]) continue;
      const fcm_index c2 = grid[q[0] + L->grid[0] * (q[1] + L->grid[1] * q[2])];
      if (c2 < 0) continue;
      fcm_index f1 = 0, f2 = 0;
      fcm_space_cell_elements(sp, c, &f1);
      const fcm_index n2 = fcm_space_cell_elements(sp, c2, &f2);
      for (fcm_index e2 = f2; e2 < f2 + n2; e2++) {
        int share = 0;
        for (int b = 0; b < 8 && !share; b++) {
          if (!(b >> d & 1)) continue;
          const int b2 = b & ~(1 << d);
          share = L->own[8 * e + b] && L->own[8 * e2 + b2] &&
                  L->corner[8 * e + b] == L->corner[8 * e2 + b2];
        }
        if (!share) continue;
        if ((cut[c] || cut[c2]) && rules) {
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
  /* level 0 DOFs: the space's numbering; eliminated rows (no off-diagonal entry) */
  L0->A = A;
  L0->n = 3 * nk;
  L0->ncopy = nk;
  L0->ncell = L->ncell;
  FCM_ALLOC(ctx, L0->n + 1, L0->dof);
  FCM_ALLOC(ctx, L0->n + 1, L0->inactive);
  for (fcm_index i = 0; i < L0->n; i++)
    L0->dof[i] = i;
  if (inactive0)
    memcpy(L0->inactive, inactive0, (size_t)L0->n);
  else
    eliminated_rows(A, L0->n, L0->inactive);
  if (hex20) {
    /* the grid level's DOFs: inactive where the coinciding fine DOF is eliminated */
    L->n = 3 * L->ncopy;
    FCM_ALLOC(ctx, L->n + 1, L->dof);
    FCM_ALLOC(ctx, L->n + 1, L->inactive);
    for (fcm_index i = 0; i < L->n; i++)
      L->dof[i] = i;
    for (fcm_index k = 0; k < nk; k++)
      for (int c = 0; cmap[k] >= 0 && c < 3; c++)
        L->inactive[3 * cmap[k] + c] = L0->inactive[3 * k + c];
    /* prolongation: a corner copy from itself, a mid-edge copy from its edge's ends */
    const fcm_element_info *info = fcm_element_get_info(type);
    FCM_ALLOC(ctx, 2 * L0->n + 1, pcol);
    FCM_ALLOC(ctx, 2 * L0->n + 1, pw);
    for (fcm_index i = 0; i < 2 * L0->n; i++)
      pcol[i] = -1;
    for (fcm_index k = 0; k < nk; k++)
      for (int c = 0; cmap[k] >= 0 && c < 3; c++)
        pcol[2 * (3 * k + c)] = 3 * cmap[k] + c, pw[2 * (3 * k + c)] = 1.0;
    for (fcm_index e = 0; e < L->ncell; e++) {
      const fcm_index *ed = fcm_space_element_dofs(sp, e);
      const fcm_index *cn = cells + (fcm_index)npc * fcm_space_element_cell(sp, e);
      for (int j = 0; j < info->num_edges; j++) {
        const int a = info->edge_nodes[j][2];
        const fcm_index k = ed[a] / 3;
        if (cmap[k] >= 0 || copy_node[k] != cn[a] || pcol[6 * k] >= 0) continue;
        for (int c = 0; c < 3; c++)
          for (int t = 0; t < 2; t++) {
            pcol[2 * (3 * k + c) + t] = 3 * cmap[ed[info->edge_nodes[j][t]] / 3] + c;
            pw[2 * (3 * k + c) + t] = 0.5;
          }
      }
    }
    FCM_TRY(ctx, transfer_from_rows(ctx, L0, L->n, 2, pcol, pw));
  }
  /* cells of the geometry's boundary too are not full: the block smoother's cells */
  for (fcm_index c = 0; rules && c < ncells; c++)
    if (fcm_cell_rules_class(rules, c) == FCM_CELL_CUT) cut[c] = 1;
  FCM_ALLOC(ctx, L->ncell + 1, L->full);
  for (fcm_index e = 0; e < L->ncell; e++)
    L->full[e] = (unsigned char)!cut[fcm_space_element_cell(sp, e)];
  m->cut_cell = cut;
  cut = NULL;
cleanup:
  fcm__free(ctx, node2);
  fcm__free(ctx, cell_ijk);
  fcm__free(ctx, grid);
  fcm__free(ctx, edges);
  fcm__free(ctx, cut);
  fcm__free(ctx, copy_node);
  fcm__free(ctx, cmap);
  fcm__free(ctx, pcol);
  fcm__free(ctx, pw);
  return st;
}

/* ------------------------------------------------------------------ coarsening */

/* Build level l+1's cells, copies, graph and DOFs and the prolongation P_l. */
static fcm_status coarsen(fcm_mg *m, int l)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_level *F = &m->lev[l], *C = &m->lev[l + 1];
  fcm_index *uf = NULL, *cid = NULL, *edges = NULL, *cptr = NULL, *cusers = NULL, *cfill = NULL,
            *scal_ptr = NULL, *scal_col = NULL, *anc = NULL, *anc_in = NULL, *cused = NULL;
  double *scal_w = NULL;
  const fcm_index nf = F->ncell;
  for (int d = 0; d < 3; d++)
    C->grid[d] = (F->grid[d] + 1) / 2;
  /* 1. coarse cells: components of the graph inside each block */
  FCM_ALLOC(ctx, nf + 1, uf);
  FCM_ALLOC(ctx, nf + 1, cid);
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
  /* full: 8 full fine cells */
  FCM_ALLOC(ctx, nc + 1, C->full);
  {
    fcm_index *cnt = NULL;
    FCM_ALLOC(ctx, nc + 1, cnt);
    for (fcm_index c = 0; c < nf; c++)
      cnt[cid[c]] += F->full[c] ? 1 : 9; /* any partial child: > 8 */
    for (fcm_index c = 0; c < nc; c++)
      C->full[c] = (unsigned char)(cnt[c] == 8);
    fcm__free(ctx, cnt);
  }
  /* 2. coarse graph */
  fcm_index nedge = 0;
  FCM_ALLOC(ctx, F->adj_ptr[nf] + 1, edges);
  for (fcm_index c = 0; c < nf; c++)
    for (fcm_index i = F->adj_ptr[c]; i < F->adj_ptr[c + 1]; i++) {
      const fcm_index a = cid[c], b = cid[F->adj[i]];
      if (a < b) edges[2 * nedge] = a, edges[2 * nedge + 1] = b, nedge++;
    }
  FCM_TRY(ctx, graph_from_edges(ctx, nc, nedge, edges, &C->adj_ptr, &C->adj));
  /* 3. users of each fine copy (at its own node): coarse cells, deduplicated */
  const fcm_index nk = F->ncopy;
  FCM_ALLOC(ctx, nk + 1, cptr);
  FCM_ALLOC(ctx, nk + 1, cfill);
  for (fcm_index c = 0; c < nf; c++)
    for (int b = 0; b < 8; b++)
      if (F->own[8 * c + b]) cptr[F->corner[8 * c + b] + 1]++;
  for (fcm_index k = 0; k < nk; k++)
    cptr[k + 1] += cptr[k];
  FCM_ALLOC(ctx, cptr[nk] + 1, cusers);
  for (fcm_index c = 0; c < nf; c++)
    for (int b = 0; b < 8; b++)
      if (F->own[8 * c + b]) {
        const fcm_index k = F->corner[8 * c + b];
        cusers[cptr[k] + cfill[k]++] = cid[c];
      }
  /* 4. corner slots of coarse cells, merged through shared fine copies */
  fcm__free(ctx, uf);
  uf = NULL;
  FCM_ALLOC(ctx, 8 * nc + 1, uf);
  for (fcm_index s = 0; s < 8 * nc; s++)
    uf[s] = s;
  for (fcm_index k = 0; k < nk; k++) {
    if (cptr[k + 1] - cptr[k] < 2) continue;
    const fcm_index c0 = cusers[cptr[k]];
    /* the coarse nodes with nonzero weight: corner bits of c0 */
    for (int b = 0; b < 8; b++) {
      int ok = 1;
      for (int d = 0; d < 3 && ok; d++) {
        const fcm_index p = F->copy_ijk[3 * k + d], q = 2 * (C->ijk[3 * c0 + d] + (b >> d & 1));
        ok = p == q || p == q - 1 || p == q + 1;
      }
      if (!ok) continue;
      for (fcm_index i = cptr[k] + 1; i < cptr[k + 1]; i++) {
        const fcm_index c1 = cusers[i];
        /* the same node as a corner of c1 */
        int b1 = 0;
        for (int d = 0; d < 3; d++) {
          const fcm_index q = C->ijk[3 * c0 + d] + (b >> d & 1), off = q - C->ijk[3 * c1 + d];
          FCM_CHECK(off == 0 || off == 1, ctx, FCM_ERR_INTERNAL,
                    "mg: copy %lld used by coarse cells %lld and %lld that share no node",
                    (long long)k, (long long)c0, (long long)c1);
          b1 |= (int)off << d;
        }
        uf_union(uf, 8 * c0 + b, 8 * c1 + b1);
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
  /* 5. scalar prolongation: row k from the first user's corners */
  FCM_ALLOC(ctx, nk + 1, scal_ptr);
  FCM_ALLOC(ctx, 8 * nk + 1, scal_col);
  FCM_ALLOC(ctx, 8 * nk + 1, scal_w);
  for (fcm_index k = 0; k < nk; k++) {
    fcm_index cnt = scal_ptr[k];
    if (cptr[k + 1] > cptr[k]) {
      const fcm_index c0 = cusers[cptr[k]];
      for (int b = 0; b < 8; b++) {
        double w = 1.0;
        for (int d = 0; d < 3; d++) {
          const fcm_index p = F->copy_ijk[3 * k + d], q = 2 * (C->ijk[3 * c0 + d] + (b >> d & 1));
          w *= p == q ? 1.0 : (p == q - 1 || p == q + 1) ? 0.5 : 0.0;
        }
        if (w == 0.0) continue;
        scal_col[cnt] = C->corner[8 * c0 + b];
        scal_w[cnt++] = w;
      }
    }
    scal_ptr[k + 1] = cnt;
  }
  /* 6. coarse DOFs, all 3 per copy; inactive (Dirichlet) when all fine DOFs at the same
   * point are inactive (eliminated on level 0, inactive on coarser levels): the coarse node
   * lies on the Dirichlet boundary. Inactive DOFs keep their rows and their columns of P
   * (as eliminated rows on level 0 do), so P stays injective and every coarse matrix
   * positive definite; the Galerkin matrix decouples them (off-diagonals zeroed, the
   * diagonal kept: a spring) and the cycle restricts zero to them and prolongates nothing
   * from them. Leaving them out instead made P rank deficient next to a clamped face (a
   * coarse cell whose material lies in the fine layer at the face sees its free fine DOFs
   * on one plane only) and the coarsest CHOLMOD factor fail. */
  FCM_ALLOC(ctx, ncopy + 1, anc);
  FCM_ALLOC(ctx, ncopy + 1, cused);
  FCM_ALLOC(ctx, 3 * ncopy + 1, anc_in);
  for (fcm_index k = 0; k < nk; k++)
    for (fcm_index p = scal_ptr[k]; p < scal_ptr[k + 1]; p++) {
      cused[scal_col[p]]++;
      if (scal_w[p] != 1.0) continue;
      const fcm_index K = scal_col[p];
      anc[K]++;
      for (int c = 0; c < 3; c++)
        anc_in[3 * K + c] += F->inactive[3 * k + c];
    }
  C->n = 3 * ncopy;
  FCM_ALLOC(ctx, C->n + 1, C->dof);
  FCM_ALLOC(ctx, C->n + 1, C->inactive);
  for (fcm_index K = 0; K < ncopy; K++)
    for (int c = 0; c < 3; c++) {
      C->dof[3 * K + c] = 3 * K + c;
      /* a corner no fine copy interpolates from (the elements of its cell use copies of
       * other nodes in place of tiny ones there) has an empty column: inactive too */
      C->inactive[3 * K + c] =
          (unsigned char)(cused[K] == 0 || (anc[K] > 0 && anc_in[3 * K + c] == anc[K]));
    }
  const fcm_index n = C->n;
  /* 7. DOF prolongation (F->n x C->n) and its transpose */
  FCM_ALLOC(ctx, F->n + 1, F->P_ptr);
  for (int pass = 0; pass < 2; pass++) {
    fcm_index cnt = 0;
    for (fcm_index k = 0; k < nk; k++)
      for (int c = 0; c < 3; c++) {
        const fcm_index f = F->dof[3 * k + c];
        if (f < 0) continue;
        for (fcm_index p = scal_ptr[k]; p < scal_ptr[k + 1]; p++) {
          const fcm_index J = C->dof[3 * scal_col[p] + c];
          if (J < 0) continue;
          if (pass) {
            F->P_col[cnt] = (int)J;
            F->P_val[cnt] = scal_w[p];
          } else {
            F->P_ptr[f + 1]++;
          }
          cnt++;
        }
      }
    if (!pass) {
      for (fcm_index i = 0; i < F->n; i++)
        F->P_ptr[i + 1] += F->P_ptr[i];
      FCM_ALLOC(ctx, F->P_ptr[F->n] + 1, F->P_col);
      FCM_ALLOC(ctx, F->P_ptr[F->n] + 1, F->P_val);
    }
  }
  /* rows of P were filled copy by copy, which is row order for rows f ascending with k:
   * level 0 rows are 3k + c; coarse rows are numbered copy by copy too */
  {
    const fcm_index nnz = F->P_ptr[F->n];
    FCM_ALLOC(ctx, n + 2, F->R_ptr);
    FCM_ALLOC(ctx, nnz + 1, F->R_col);
    FCM_ALLOC(ctx, nnz + 1, F->R_val);
    for (fcm_index p = 0; p < nnz; p++)
      F->R_ptr[F->P_col[p] + 1]++;
    for (fcm_index J = 0; J < n; J++)
      F->R_ptr[J + 1] += F->R_ptr[J];
    fcm__free(ctx, cfill);
    cfill = NULL;
    FCM_ALLOC(ctx, n + 1, cfill);
    for (fcm_index i = 0; i < F->n; i++)
      for (fcm_index p = F->P_ptr[i]; p < F->P_ptr[i + 1]; p++) {
        const fcm_index J = F->P_col[p];
        F->R_col[F->R_ptr[J] + cfill[J]] = (int)i;
        F->R_val[F->R_ptr[J] + cfill[J]++] = F->P_val[p];
      }
  }
cleanup:
  fcm__free(ctx, uf);
  fcm__free(ctx, cid);
  fcm__free(ctx, edges);
  fcm__free(ctx, cptr);
  fcm__free(ctx, cusers);
  fcm__free(ctx, cfill);
  fcm__free(ctx, scal_ptr);
  fcm__free(ctx, scal_col);
  fcm__free(ctx, scal_w);
  fcm__free(ctx, anc);
  fcm__free(ctx, cused);
  fcm__free(ctx, anc_in);
  return st;
}

/* ------------------------------------------------------------------ Galerkin product */

/* Symbolic C = A B (rows of A, columns of B: ncol), sorted columns; rows shared by up to nt
 * threads (each row's columns are found and sorted by one thread). */
static fcm_status spgemm_symbolic(fcm_ctx *ctx, int nt, fcm_index nrow, const fcm_index *Ap,
                                  const int *Ac, const fcm_index *Bp, const int *Bc, fcm_index ncol,
                                  fcm_index **Cp_out, int **Cc_out)
{
  fcm_status st = FCM_OK;
  fcm_index *Cp = NULL, *mark = NULL;
  int *Cc = NULL;
  FCM_ALLOC(ctx, nrow + 1, Cp);
  FCM_ALLOC_RAW(ctx, (size_t)nt * (size_t)ncol + 1, mark); /* per thread: ncol entries */
  for (size_t j = 0; j < (size_t)nt * (size_t)ncol; j++)
    mark[j] = -1;
  for (int pass = 0; pass < 2; pass++) {
#pragma omp parallel num_threads(nt) if (nrow > 4096)
    {
      fcm_index *mk = mark + (size_t)omp_get_thread_num() * (size_t)ncol;
#pragma omp for schedule(dynamic, 256)
      for (fcm_index i = 0; i < nrow; i++) {
        fcm_index cnt = 0, base = pass ? Cp[i] : 0;
        for (fcm_index p = Ap[i]; p < Ap[i + 1]; p++) {
          const fcm_index k = Ac[p];
          for (fcm_index q = Bp[k]; q < Bp[k + 1]; q++) {
            const fcm_index j = Bc[q];
            if (mk[j] == i + pass * nrow) continue;
            mk[j] = i + pass * nrow;
            if (pass) Cc[base + cnt] = (int)j;
            cnt++;
          }
        }
        if (pass)
          qsort(Cc + base, (size_t)cnt, sizeof *Cc, cmp_int);
        else
          Cp[i + 1] = cnt;
      }
    }
    if (!pass) {
      for (fcm_index i = 0; i < nrow; i++)
        Cp[i + 1] += Cp[i];
      FCM_ALLOC(ctx, Cp[nrow] + 1, Cc);
    }
  }
  *Cp_out = Cp, *Cc_out = Cc;
  Cp = NULL, Cc = NULL;
cleanup:
  fcm__free(ctx, Cp);
  fcm__free(ctx, Cc);
  fcm__free(ctx, mark);
  return st;
}

/* Insert the missing diagonal entries into a square pattern (rows sorted), in place by
 * reallocation. */
static fcm_status add_diagonal(fcm_ctx *ctx, fcm_index n, fcm_index **ptr, int **col)
{
  fcm_status st = FCM_OK;
  fcm_index *p = *ptr, *np = NULL;
  int *c = *col, *nc = NULL;
  fcm_index missing = 0;
  for (fcm_index i = 0; i < n; i++) {
    int has = 0;
    for (fcm_index q = p[i]; q < p[i + 1] && !has; q++)
      has = c[q] == i;
    missing += !has;
  }
  if (missing == 0) goto cleanup;
  FCM_ALLOC(ctx, n + 1, np);
  FCM_ALLOC(ctx, p[n] + missing + 1, nc);
  fcm_index out = 0;
  for (fcm_index i = 0; i < n; i++) {
    int done = 0;
    for (fcm_index q = p[i]; q < p[i + 1]; q++) {
      if (!done && c[q] > i) nc[out++] = (int)i, done = 1;
      if (c[q] == i) done = 1;
      nc[out++] = c[q];
    }
    if (!done) nc[out++] = (int)i;
    np[i + 1] = out;
  }
  fcm__free(ctx, p);
  fcm__free(ctx, c);
  *ptr = np, *col = nc;
  np = NULL, nc = NULL;
cleanup:
  fcm__free(ctx, np);
  fcm__free(ctx, nc);
  return st;
}

/* Numeric C = A B on C's pattern, rows shared by the threads of the enclosing region (ends
 * with a barrier); spa: the calling thread's ncol doubles (zero on entry and exit). */
static void spgemm_numeric(fcm_index nrow, const fcm_index *Ap, const int *Ac, const double *Av,
                           const fcm_index *Bp, const int *Bc, const double *Bv,
                           const fcm_index *Cp, const int *Cc, double *Cv, double *spa)
{
#pragma omp for schedule(dynamic, 64)
  for (fcm_index i = 0; i < nrow; i++) {
    for (fcm_index p = Ap[i]; p < Ap[i + 1]; p++) {
      const fcm_index k = Ac[p];
      const double a = Av[p];
      for (fcm_index q = Bp[k]; q < Bp[k + 1]; q++)
        spa[Bc[q]] += a * Bv[q];
    }
    for (fcm_index p = Cp[i]; p < Cp[i + 1]; p++) {
      Cv[p] = spa[Cc[p]];
      spa[Cc[p]] = 0.0;
    }
  }
}

static const fcm_csr *level_matrix(const mg_level *L)
{
  return L->A ? L->A : L->Aown;
}

/* Values of A_{l+1} = R_l A_l P_l (symmetrized), diagonal inverses of level l+1; rows in
 * parallel (each entry is computed by one thread in a fixed order: the result does not depend
 * on the thread count). */
static fcm_status galerkin_values(fcm_mg *m, int l)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_level *F = &m->lev[l], *C = &m->lev[l + 1];
  const fcm_csr *A = level_matrix(F);
  double *v = fcm_csr_values(C->Aown);
  const fcm_index *cp = fcm_csr_row_ptr(C->Aown);
  const int *cc = fcm_csr_col_idx(C->Aown);
  fcm_index nnz = 0, bad = C->n;
  fcm_csr_get_size(A, NULL, NULL, &nnz);
#pragma omp parallel num_threads(team(m)) if (nnz >= MG_PARALLEL_NNZ)
  {
    double *spa = m->spa + (size_t)omp_get_thread_num() * (size_t)m->spa_len;
    spgemm_numeric(F->n, fcm_csr_row_ptr(A), fcm_csr_col_idx(A), fcm_csr_values_read(A), F->P_ptr,
                   F->P_col, F->P_val, F->AP_ptr, F->AP_col, F->AP_val, spa);
    spgemm_numeric(C->n, F->R_ptr, F->R_col, F->R_val, F->AP_ptr, F->AP_col, F->AP_val, cp, cc, v,
                   spa);
    /* symmetrize: the pair (i, j), (j, i) with i < j by row i's thread alone */
#pragma omp for schedule(dynamic, 64)
    for (fcm_index i = 0; i < C->n; i++) {
      for (fcm_index p = cp[i]; p < cp[i + 1]; p++) {
        const fcm_index j = cc[p];
        if (j <= i) continue;
        const fcm_index q = fcm_csr_position(C->Aown, j, i);
        const double s = 0.5 * (v[p] + v[q]);
        v[p] = v[q] = s;
      }
    }
    /* decouple the constrained rows and columns, then the diagonal inverses */
#pragma omp for schedule(static) reduction(min : bad)
    for (fcm_index i = 0; i < C->n; i++) {
      for (fcm_index p = cp[i]; p < cp[i + 1]; p++)
        if (cc[p] != i && (C->inactive[i] || C->inactive[cc[p]])) v[p] = 0.0;
      if (C->inactive[i] && !(v[C->diag[i]] > 0.0)) v[C->diag[i]] = 1.0; /* decoupled anyway */
      const double d = v[C->diag[i]];
      if (!(isfinite(d) && d > 0.0) && i < bad) bad = i;
      C->dinv[i] = 1.0 / d;
    }
  }
  FCM_CHECK(bad == C->n, ctx, FCM_ERR_NUMERIC,
            "mg: level %d, row %lld: Galerkin diagonal %g is not positive (is A positive "
            "definite?)",
            l + 1, (long long)bad, bad < C->n ? v[C->diag[bad]] : 0.0);
cleanup:
  return st;
}

static fcm_status level_diag(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_csr *A = level_matrix(L);
  if (!L->diag) FCM_ALLOC(ctx, L->n + 1, L->diag);
  if (!L->dinv) FCM_ALLOC(ctx, L->n + 1, L->dinv);
  for (fcm_index i = 0; i < L->n; i++) {
    L->diag[i] = fcm_csr_position(A, i, i);
    FCM_CHECK(L->diag[i] >= 0, ctx, FCM_ERR_ARG, "mg: row %lld has no diagonal entry",
              (long long)i);
  }
cleanup:
  return st;
}

static fcm_status level0_dinv(fcm_mg *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_level *L = &m->lev[0];
  const double *v = fcm_csr_values_read(L->A);
  for (fcm_index i = 0; i < L->n; i++) {
    const double d = v[L->diag[i]];
    FCM_CHECK(isfinite(d) && d > 0.0, ctx, FCM_ERR_NUMERIC,
              "mg: diagonal entry of row %lld is %g (A must be positive definite)", (long long)i,
              d);
    L->dinv[i] = 1.0 / d;
  }
cleanup:
  return st;
}

/* Greedy colouring of the rows of the level matrix in row order (a row takes the smallest
 * colour no coupled row before it has), then the rows grouped by colour, ascending. */
static fcm_status level_colors(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_csr *A = level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  int *col = NULL, maxc = 0;
  fcm_index *seen = NULL, *fill = NULL;
  FCM_ALLOC(ctx, L->n + 1, col);
  fcm_index maxdeg = 0;
  for (fcm_index i = 0; i < L->n; i++)
    maxdeg = FCM_MAX(maxdeg, rp[i + 1] - rp[i]);
  FCM_ALLOC(ctx, maxdeg + 2, seen); /* seen[c] == i + 1: colour c taken for row i */
  for (fcm_index i = 0; i < L->n; i++) {
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      if (ci[p] < i && col[ci[p]] <= maxdeg) seen[col[ci[p]]] = i + 1;
    int c = 0;
    while (seen[c] == i + 1)
      c++;
    col[i] = c;
    maxc = FCM_MAX(maxc, c + 1);
  }
  L->ncolor = maxc;
  FCM_ALLOC(ctx, maxc + 1, L->color_ptr);
  FCM_ALLOC(ctx, L->n + 1, L->color_rows);
  FCM_ALLOC(ctx, maxc + 1, fill);
  for (fcm_index i = 0; i < L->n; i++)
    L->color_ptr[col[i] + 1]++;
  for (int c = 0; c < maxc; c++)
    L->color_ptr[c + 1] += L->color_ptr[c];
  for (fcm_index i = 0; i < L->n; i++)
    L->color_rows[L->color_ptr[col[i]] + fill[col[i]]++] = i;
cleanup:
  fcm__free(ctx, col);
  fcm__free(ctx, seen);
  fcm__free(ctx, fill);
  return st;
}

/* ------------------------------------------------------------------ slab orders */

/* Block slabs: a few per thread and colour on common core counts, so that whole slabs balance
 * the threads' work; fewer when the coupling reaches far in the sequence. */
#define MG_SLABS 16

/* The slab order (see slab_order) of n items with per-item work (>= 0), in the sequence `seq`
 * (n items; NULL: ascending), given reach[t] >= t: the furthest sequence position of an item
 * adjacent (symmetrically) to the item at position t. Cut so that slab s + 2 starts past
 * every position that slab s reaches. thick = 0: slabs of at least total / MG_SLABS work
 * each, colour 0 first. thick > 0: `thick` slabs of about equal work (colour 0) separated by
 * thin slabs just wide enough to keep them apart (colour 1, swept first), or one slab when
 * the thin ones would hold more than a quarter of the work or reach the end (coupling that
 * reaches far in the sequence). */
static fcm_status slabs_create(fcm_ctx *ctx, fcm_index n, const fcm_index *seq,
                               const fcm_index *reach, const double *work, int thick, slab_order *S)
{
  fcm_status st = FCM_OK;
  fcm_index *cut = NULL;
  slabs_free(ctx, S);
  FCM_ALLOC_RAW(ctx, n + 2, cut);
  double total = 0.0;
  for (fcm_index t = 0; t < n; t++)
    total += work[t];
  /* cut[s]: the first position of slab s; far: 1 + the reach of the slab before the last */
  const double target = thick > 0 ? total / thick : total / MG_SLABS;
  fcm_index ns = 0, t = 0, far = 0;
  double wthin = 0.0;
  cut[0] = 0;
  while (t < n) {
    const int thin = thick > 0 && ns % 2 == 1;
    double acc = 0.0;
    fcm_index reach_s = t;
    do {
      acc += work[seq ? seq[t] : t];
      reach_s = FCM_MAX(reach_s, reach[t]);
      t++;
    } while (t < n && ((!thin && acc < target) || t < far));
    if (thin) wthin += acc;
    cut[++ns] = t;
    far = reach_s + 1; /* the slab after the next starts past all this slab reaches */
  }
  if (thick > 0 && (ns == 2 || wthin > 0.25 * total)) ns = 1, cut[1] = n;
  S->nslab = ns;
  S->first = thick > 0 && ns > 1;
  FCM_ALLOC_RAW(ctx, ns + 1, S->ptr);
  FCM_ALLOC(ctx, ns + 1, S->mid);
  FCM_ALLOC_RAW(ctx, n + 1, S->item);
  for (fcm_index k = 0; k <= ns; k++)
    S->ptr[k] = cut[k];
  for (fcm_index q = 0; q < n; q++)
    S->item[q] = seq ? seq[q] : q;
  for (fcm_index k = 0; k < ns; k++)
    for (fcm_index q = cut[k]; q < cut[k + 1]; q++)
      S->mid[k] += work[S->item[q]]; /* the slab's work, for now */
  for (int c = 0; c < 2; c++) {
    double tot = 0.0, before = 0.0;
    for (fcm_index k = c; k < ns; k += 2)
      tot += S->mid[k];
    for (fcm_index k = c; k < ns; k += 2) {
      const double w = S->mid[k];
      S->mid[k] = tot > 0.0 ? (before + 0.5 * w) / tot : 0.0;
      before += w;
    }
  }
cleanup:
  if (st) slabs_free(ctx, S);
  fcm__free(ctx, cut);
  return st;
}

/* The rows of a level in slabs, in row order: two thick slabs and the thin one between them
 * (adjacency: the level matrix's pattern, work: stored entries). Pointwise Gauss-Seidel is
 * sensitive to its order (the Hex8 cube's V-cycle factor 0.29 -> 0.32 with 16 slabs, the
 * hemisphere's 0.15 -> 0.23, Hex20 0.33 -> 0.55), much less so with one thin slab swept
 * first (0.29, 0.18, 0.33): the pointwise sweeps share two threads. Hex20's finest level
 * numbers the corner nodes before the mid-edge nodes; its rows couple far apart in row order
 * and stay in one slab (sequential). */
#define MG_ROW_SLABS_THICK 2

static fcm_status row_slabs(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_csr *A = level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  double *work = NULL;
  fcm_index *reach = NULL;
  FCM_ALLOC_RAW(ctx, L->n + 1, work);
  FCM_ALLOC_RAW(ctx, L->n + 1, reach);
  for (fcm_index i = 0; i < L->n; i++) {
    work[i] = (double)(rp[i + 1] - rp[i]);
    reach[i] = i;
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      reach[i] = FCM_MAX(reach[i], ci[p]);
  }
  FCM_TRY(ctx, slabs_create(ctx, L->n, NULL, reach, work, MG_ROW_SLABS_THICK, &L->rows));
cleanup:
  fcm__free(ctx, work);
  fcm__free(ctx, reach);
  return st;
}

/* The blocks of a level's block smoother in slabs, in the sequence of their first DOFs (ties
 * by index), so that it follows the rows. Blocks j and k are adjacent when a DOF of one couples
 * with (or is) a DOF of the other, i.e. when one's update reads what the other writes; work:
 * the residual's and the block product's entries. */
static fcm_status block_slabs(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_csr *A = level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const fcm_index nb = fcm__schwarz_num_blocks(L->blk), n = L->n;
  fcm_index *pairs = NULL, *seq = NULL, *last = NULL, *reach = NULL;
  double *work = NULL;
  FCM_ALLOC_RAW(ctx, 2 * nb + 1, pairs);
  for (fcm_index k = 0; k < nb; k++) {
    const fcm_index *d = NULL;
    const double *S = NULL;
    const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
    fcm_index first = n;
    for (int i = 0; i < bm; i++)
      first = FCM_MIN(first, d[i]);
    pairs[2 * k] = first, pairs[2 * k + 1] = k;
  }
  if (nb > 0) qsort(pairs, (size_t)nb, 2 * sizeof *pairs, cmp_pair);
  FCM_ALLOC_RAW(ctx, nb + 1, seq);
  FCM_ALLOC_RAW(ctx, nb + 1, reach);
  FCM_ALLOC_RAW(ctx, nb + 1, work);
  FCM_ALLOC_RAW(ctx, n + 1, last);
  for (fcm_index i = 0; i < n; i++)
    last[i] = -1;
  for (fcm_index t = 0; t < nb; t++) { /* last[i]: the last position of a block holding row i */
    const fcm_index *d = NULL;
    const double *S = NULL;
    seq[t] = pairs[2 * t + 1];
    const int bm = fcm__schwarz_block(L->blk, seq[t], &d, &S);
    for (int i = 0; i < bm; i++)
      last[d[i]] = t;
  }
#pragma omp parallel for num_threads(team(m)) schedule(static) if (nb > 1024)
  for (fcm_index t = 0; t < nb; t++) {
    const fcm_index *d = NULL;
    const double *S = NULL;
    const fcm_index k = seq[t];
    const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
    fcm_index r = t, entries = 0;
    for (int i = 0; i < bm; i++) {
      entries += rp[d[i] + 1] - rp[d[i]];
      for (fcm_index p = rp[d[i]]; p < rp[d[i] + 1]; p++)
        r = FCM_MAX(r, last[ci[p]]);
    }
    reach[t] = r;
    work[k] = (double)entries + (double)bm * (double)bm;
  }
  FCM_TRY(ctx, slabs_create(ctx, nb, seq, reach, work, 0, &L->blocks));
cleanup:
  fcm__free(ctx, pairs);
  fcm__free(ctx, seq);
  fcm__free(ctx, last);
  fcm__free(ctx, reach);
  fcm__free(ctx, work);
  return st;
}

/* Does thread t of nt run slab s? The slabs of one colour go to the threads in contiguous
 * runs of about equal work (a slab to the thread whose share holds its work's midpoint).
 * Affects the schedule only: the slabs of one colour are independent. */
static int slab_mine(const slab_order *S, fcm_index s, int t, int nt)
{
  const int owner = (int)(S->mid[s] * nt);
  return (owner < nt ? owner : nt - 1) == t;
}

/* ------------------------------------------------------------------ create / setup */

/* Block smoothers (block_smoothing). Level 0: one block per grid vertex of the cut cells
 * (de Prenter et al. 2020): the DOFs of the copies whose support lies in the vertex's patch
 * of 8 cells, the vertex's own and (Hex20) those of the mid-edge nodes of the edges at the
 * vertex, all copies together; then one block per element of a cut cell (all its DOFs).
 * Coarser levels: one block per coarse cell that is not all material (its 8 corner copies).
 * Each block is inverted by the clamped eigen-inverse of fcm_schwarz (Longva et al. 2020,
 * §5.2). Vertex blocks resolve the nearly dependent functions of one vertex's patch (Hex20:
 * 0.96 -> 0.2-0.3 per V-cycle), element blocks those of the corners of a sliver cell (Hex8
 * hollow ball), coarse blocks the same on the Galerkin levels, where thin walls become
 * cells with little material (the hollow ball's V-cycle grew with n without them). */
/* Level 0: the vertex blocks, then the element blocks of the cut cells. */
static fcm_status blocks_level0(fcm_mg *m, fcm_index *nb_out, fcm_index **ptr_out,
                                fcm_index **dofs_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_space *sp = m->space;
  const fcm_mesh *mesh = fcm_space_mesh(sp);
  const fcm_element_info *info = fcm_element_get_info(fcm_mesh_element_type(mesh));
  const int npc = info->num_nodes, mid = npc > 8;
  const fcm_index *cells = fcm_mesh_cells(mesh), nnode = fcm_mesh_num_nodes(mesh);
  const fcm_index ne = fcm_space_num_elements(sp);
  fcm_index nb = 0, np = 0, nu = 0, neb = 0, ned = 0, *ptr = NULL, *dofs = NULL, *pairs = NULL;
  unsigned char *mark = NULL;
  FCM_ALLOC(ctx, nnode + 1, mark);
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index c = fcm_space_element_cell(sp, e);
    if (!m->cut_cell[c]) continue;
    for (int a = 0; a < 8; a++)
      mark[cells[(fcm_index)npc * c + a]] = 1;
  }
  FCM_ALLOC(ctx, 2 * (size_t)ne * 8 * (mid ? 4 : 1) + 1, pairs);
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index c = fcm_space_element_cell(sp, e), *ed = fcm_space_element_dofs(sp, e);
    for (int a = 0; a < 8; a++) {
      const fcm_index v = cells[(fcm_index)npc * c + a];
      if (!mark[v]) continue;
      pairs[2 * np] = v, pairs[2 * np + 1] = ed[a] / 3, np++;
      for (int j = 0; mid && j < info->num_edges; j++)
        if (info->edge_nodes[j][0] == a || info->edge_nodes[j][1] == a)
          pairs[2 * np] = v, pairs[2 * np + 1] = ed[info->edge_nodes[j][2]] / 3, np++;
    }
  }
  if (np > 0) qsort(pairs, (size_t)np, 2 * sizeof *pairs, cmp_pair);
  for (fcm_index i = 0; i < np; i++)
    if (i == 0 || pairs[2 * i] != pairs[2 * nu - 2] || pairs[2 * i + 1] != pairs[2 * nu - 1])
      pairs[2 * nu] = pairs[2 * i], pairs[2 * nu + 1] = pairs[2 * i + 1], nu++;
  for (fcm_index i = 0; i < nu; i++)
    nb += i == 0 || pairs[2 * i] != pairs[2 * i - 2];
  FCM_TRY(ctx, fcm_space_cell_blocks(sp, m->cut_cell, &neb, &ned, NULL, NULL));
  FCM_ALLOC(ctx, nb + neb + 1, ptr);
  FCM_ALLOC(ctx, 3 * nu + ned + 1, dofs);
  for (fcm_index i = 0, k = 0; i < nu; i++) {
    if (i > 0 && pairs[2 * i] != pairs[2 * i - 2]) ptr[++k] = 3 * i;
    for (int d = 0; d < 3; d++)
      dofs[3 * i + d] = 3 * pairs[2 * i + 1] + d;
  }
  ptr[nb] = 3 * nu;
  FCM_TRY(ctx, fcm_space_cell_blocks(sp, m->cut_cell, &neb, &ned, ptr + nb, dofs + 3 * nu));
  for (fcm_index k = nb; k <= nb + neb; k++) /* offsets after the vertex blocks */
    ptr[k] += 3 * nu;
  *nb_out = nb + neb, *ptr_out = ptr, *dofs_out = dofs;
  ptr = dofs = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, dofs);
  fcm__free(ctx, pairs);
  fcm__free(ctx, mark);
  return st;
}

/* A coarse level: the cells that are not all material, their distinct corner copies. */
static fcm_status blocks_coarse(fcm_mg *m, const mg_level *L, fcm_index *nb_out,
                                fcm_index **ptr_out, fcm_index **dofs_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  fcm_index nb = 0, *ptr = NULL, *dofs = NULL;
  for (fcm_index c = 0; c < L->ncell; c++)
    nb += !L->full[c];
  FCM_ALLOC(ctx, nb + 1, ptr);
  FCM_ALLOC(ctx, 24 * nb + 1, dofs);
  fcm_index k = 0, q = 0;
  for (fcm_index c = 0; c < L->ncell; c++) {
    if (L->full[c]) continue;
    const fcm_index q0 = q;
    for (int b = 0; b < 8; b++) {
      const fcm_index K = L->corner[8 * c + b];
      int dup = 0;
      for (fcm_index t = q0; t < q && !dup; t += 3)
        dup = dofs[t] == 3 * K;
      for (int d = 0; !dup && d < 3; d++)
        dofs[q++] = 3 * K + d;
    }
    ptr[++k] = q;
  }
  *nb_out = nb, *ptr_out = ptr, *dofs_out = dofs;
  ptr = dofs = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, dofs);
  return st;
}

/* The block smoothers of every level but the coarsest, from the current level matrices. */
/* The blocks of level l (< nlev - 1) in its DOF numbering: level 0's vertex and cut element
 * blocks, a coarser level's corner blocks. */
static fcm_status level_blocks(fcm_mg *m, int l, fcm_index *nb, fcm_index **ptr, fcm_index **dofs)
{
  return l == 0 ? blocks_level0(m, nb, ptr, dofs) : blocks_coarse(m, &m->lev[l], nb, ptr, dofs);
}

static fcm_status block_smoothers_create(fcm_mg *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  fcm_index nb = 0, *ptr = NULL, *dofs = NULL;
  for (int l = 0; l + 1 < m->nlev; l++) {
    mg_level *L = &m->lev[l];
    FCM_TRY(ctx, level_blocks(m, l, &nb, &ptr, &dofs));
    for (fcm_index k = 0; k < nb; k++)
      m->blk_max = FCM_MAX(m->blk_max, ptr[k + 1] - ptr[k]);
    if (nb > 0) {
      FCM_TRY(ctx, fcm_schwarz_create(ctx, level_matrix(L), nb, ptr, dofs, NULL, &L->blk));
      FCM_TRY(ctx, block_slabs(m, L));
    }
    FCM_FREE(ctx, ptr);
    FCM_FREE(ctx, dofs);
  }
  FCM_ALLOC(ctx, (size_t)m->nt * (size_t)m->blk_max + 1, m->blk_r);
  FCM_ALLOC(ctx, (size_t)m->nt * (size_t)m->blk_max + 1, m->blk_dx);
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, dofs);
  return st;
}

/* The levels of m (m->ctx, space, opts set): cells, copies, DOFs, inactive rows and the
 * prolongations. Level 0's inactive rows are `inactive0` (n bytes, the space's numbering) or,
 * when it is NULL, the eliminated rows of A; A (NULL with inactive0) is level 0's matrix. No
 * matrix is read beyond that: the prolongations depend on the space and the inactive rows. */
static fcm_status build_hierarchy(fcm_mg *m, const fcm_csr *A, const unsigned char *inactive0)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_mg_options o = m->opts;
  FCM_TRY(ctx, build_level0(m, A, inactive0));
  if (A) FCM_TRY(ctx, level_diag(m, &m->lev[0]));
  m->nlev = 1;
  if (m->lev[1].ncell > 0) { /* Hex20: the p-coarse Hex8 level */
    if (o.max_levels >= 2) {
      m->nlev = 2;
    } else { /* the space alone, solved directly */
      level_free(ctx, &m->lev[1]);
      mg_level *L0 = &m->lev[0];
      fcm__free(ctx, L0->P_ptr), fcm__free(ctx, L0->P_col), fcm__free(ctx, L0->P_val);
      fcm__free(ctx, L0->R_ptr), fcm__free(ctx, L0->R_col), fcm__free(ctx, L0->R_val);
      L0->P_ptr = L0->R_ptr = NULL, L0->P_col = L0->R_col = NULL, L0->P_val = L0->R_val = NULL;
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
      level_free(ctx, &m->lev[m->nlev]);
      break;
    }
  }
cleanup:
  return st;
}

fcm_status fcm_mg_create(fcm_ctx *ctx, const fcm_space *space, const fcm_csr *A,
                         const fcm_mg_options *opts, fcm_mg **mg)
{
  fcm_status st = FCM_OK;
  fcm_mg *m = NULL;
  FCM_CHECK(ctx && space && A && mg, ctx, FCM_ERR_ARG, "mg_create: NULL argument");
  *mg = NULL;
  fcm_mg_options o = opts ? *opts : fcm_mg_options_default();
  FCM_CHECK(o.smoother >= 0 && o.smoother < FCM_MG_SMOOTHER_COUNT, ctx, FCM_ERR_ARG,
            "mg_create: smoother = %d is not a fcm_mg_smoother", (int)o.smoother);
  FCM_CHECK(isfinite(o.omega) && o.omega > 0.0 &&
                (o.smoother != FCM_MG_SMOOTHER_JACOBI ? o.omega < 2.0 : o.omega <= 1.0),
            ctx, FCM_ERR_ARG, "mg_create: omega = %g outside %s", o.omega,
            o.smoother != FCM_MG_SMOOTHER_JACOBI ? "(0, 2) (SGS)" : "(0, 1] (Jacobi)");
  FCM_CHECK(o.pre_smooth >= 0 && o.post_smooth >= 0, ctx, FCM_ERR_ARG,
            "mg_create: pre_smooth = %d, post_smooth = %d must be >= 0", o.pre_smooth,
            o.post_smooth);
  FCM_CHECK(o.cycle_index == 1 || o.cycle_index == 2, ctx, FCM_ERR_ARG,
            "mg_create: cycle_index = %d is neither 1 (V-cycle) nor 2 (W-cycle)", o.cycle_index);
  FCM_CHECK(o.max_levels >= 1 && o.max_levels <= 32, ctx, FCM_ERR_ARG,
            "mg_create: max_levels = %d outside [1, 32]", o.max_levels);
  FCM_CHECK(o.coarse_dofs >= 1, ctx, FCM_ERR_ARG, "mg_create: coarse_dofs = %lld must be >= 1",
            (long long)o.coarse_dofs);
  fcm_index nr = 0, nc = 0;
  fcm_csr_get_size(A, &nr, &nc, NULL);
  FCM_CHECK(nr == fcm_space_num_dofs(space) && nc == nr, ctx, FCM_ERR_ARG,
            "mg_create: A is %lld x %lld, the space has %lld DOFs", (long long)nr, (long long)nc,
            (long long)fcm_space_num_dofs(space));
  FCM_CHECK(fcm_csr_get_kind(A) == FCM_CSR_SYMMETRIC, ctx, FCM_ERR_ARG,
            "mg_create: A must be an FCM_CSR_SYMMETRIC matrix");
  m = fcm__calloc(ctx, 1, sizeof *m);
  FCM_CHECK(m, ctx, FCM_ERR_ALLOC, "mg_create: out of memory");
  m->ctx = ctx;
  m->space = space;
  m->opts = o;
  m->nt = FCM_MAX(omp_get_max_threads(), 1);
  FCM_TRY(ctx, build_hierarchy(m, A, NULL));
  /* work arrays and Galerkin patterns */
  fcm_index maxn = 0;
  for (int l = 0; l < m->nlev; l++)
    maxn = FCM_MAX(maxn, m->lev[l].n);
  m->spa_len = maxn + 1;
  FCM_ALLOC(ctx, (size_t)m->nt * (size_t)m->spa_len, m->spa);
  for (int l = 0; l < m->nlev; l++) {
    mg_level *L = &m->lev[l];
    FCM_ALLOC(ctx, L->n + 1, L->x);
    FCM_ALLOC(ctx, L->n + 1, L->b);
    FCM_ALLOC(ctx, L->n + 1, L->r);
    if (l + 1 < m->nlev) {
      mg_level *C = &m->lev[l + 1];
      const fcm_csr *Af = level_matrix(L);
      FCM_TRY(ctx, spgemm_symbolic(ctx, team(m), L->n, fcm_csr_row_ptr(Af), fcm_csr_col_idx(Af),
                                   L->P_ptr, L->P_col, C->n, &L->AP_ptr, &L->AP_col));
      FCM_ALLOC(ctx, L->AP_ptr[L->n] + 1, L->AP_val);
      fcm_index *cp = NULL;
      int *cc = NULL;
      FCM_TRY(ctx, spgemm_symbolic(ctx, team(m), C->n, L->R_ptr, L->R_col, L->AP_ptr, L->AP_col,
                                   C->n, &cp, &cc));
      st = add_diagonal(ctx, C->n, &cp, &cc); /* rows of empty columns */
      if (st == FCM_OK) st = fcm_csr_create(ctx, C->n, C->n, cp, cc, FCM_CSR_SYMMETRIC, &C->Aown);
      fcm__free(ctx, cp);
      fcm__free(ctx, cc);
      FCM_TRY(ctx, st);
      FCM_TRY(ctx, level_diag(m, C));
    }
  }
  if (o.smoother == FCM_MG_SMOOTHER_SGS_COLORED)
    for (int l = 0; l + 1 < m->nlev; l++)
      if (!m->lev[l].color_ptr) FCM_TRY(ctx, level_colors(m, &m->lev[l]));
  if (o.smoother == FCM_MG_SMOOTHER_SGS)
    for (int l = 0; l + 1 < m->nlev; l++)
      FCM_TRY(ctx, row_slabs(m, &m->lev[l]));
  {
    mg_level *Lc = &m->lev[m->nlev - 1];
    FCM_TRY(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, level_matrix(Lc), &m->direct));
    FCM_TRY(ctx, fcm_direct_analyze(m->direct));
  }
  FCM_TRY(ctx, fcm_mg_setup(m));
  if (o.block_smoothing) FCM_TRY(ctx, block_smoothers_create(m)); /* set up as created */
  *mg = m;
  m = NULL;
cleanup:
  fcm_mg_destroy(&m);
  return st;
}

fcm_status fcm_mg_setup(fcm_mg *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  FCM_CHECK(m, ctx, FCM_ERR_ARG, "mg_setup: NULL argument");
  {
    mg_level *L = &m->lev[0];
    const fcm_index *rp = fcm_csr_row_ptr(L->A);
    const int *ci = fcm_csr_col_idx(L->A);
    const double *v = fcm_csr_values_read(L->A);
    const fcm_index n = L->n;
    fcm_index bad = n; /* the first row whose elimination changed */
#pragma omp parallel for num_threads(team(m)) schedule(static) reduction(min : bad) if (n > 4096)
    for (fcm_index i = 0; i < n; i++) {
      int off = 0;
      for (fcm_index p = rp[i]; p < rp[i + 1] && !off; p++)
        off = ci[p] != i && v[p] != 0.0;
      if (off != !L->inactive[i] && i < bad) bad = i;
    }
    FCM_CHECK(bad == n, ctx, FCM_ERR_ARG,
              "mg_setup: row %lld is %s now but was %s at creation (the eliminated rows "
              "must not change: create the multigrid again)",
              (long long)bad, L->inactive[bad] ? "coupled" : "eliminated",
              L->inactive[bad] ? "eliminated" : "coupled");
  }
  FCM_TRY(ctx, level0_dinv(m));
  for (int l = 0; l + 1 < m->nlev; l++) {
    if (m->lev[l].blk) FCM_TRY(ctx, fcm_schwarz_setup(m->lev[l].blk, level_matrix(&m->lev[l])));
    FCM_TRY(ctx, galerkin_values(m, l));
  }
  FCM_TRY(ctx,
          fcm_direct_factor(m->direct, fcm_csr_values_read(level_matrix(&m->lev[m->nlev - 1]))));
cleanup:
  return st;
}

/* ------------------------------------------------------------------ cycle */

/* The cycle runs each level's work in two parallel regions (smoothing, residual and
 * restriction; prolongation and smoothing), so a thread never idles through a long
 * sequential stretch and then waits to be woken: on shared cores a woken thread may wait a
 * whole time slice for a core. The functions below run inside such a region (or in a team of
 * one, when the level is too small to share) and end without a barrier unless said. */

/* What a slab sweep works on: the level, omega (pointwise), b, x and the thread's block
 * scratch (r, dx). */
typedef struct sweep_args {
  const mg_level *L;
  double w;
  const double *b;
  double *x;
  double *r, *dx;
} sweep_args;

/* One symmetric Gauss-Seidel sweep in the slab order S (forward, then backward) by the team
 * of the enclosing region: the slabs of the colour swept first, forward; a barrier; each
 * thread's slabs of the other colour forward and at once backward (they touch no other slab
 * of their colour); a barrier; the first colour's slabs backward. The same threads run the
 * same slabs of the first colour at the start and at the end, so repeated sweeps need no
 * barrier between them; no barrier at the end. slab(a, s, back) sweeps slab s. */
static void symmetric_sweep(const slab_order *S,
                            void (*slab)(const sweep_args *a, fcm_index s, int back),
                            const sweep_args *a)
{
  const int t = omp_get_thread_num(), nt = omp_get_num_threads();
  const int c0 = S->first, c1 = 1 - S->first;
  for (fcm_index k = c0; k < S->nslab; k += 2)
    if (slab_mine(S, k, t, nt)) slab(a, k, 0);
#pragma omp barrier
  for (fcm_index k = c1; k < S->nslab; k += 2)
    if (slab_mine(S, k, t, nt)) {
      slab(a, k, 0);
      slab(a, k, 1);
    }
#pragma omp barrier
  for (fcm_index k = c0; k < S->nslab; k += 2)
    if (slab_mine(S, k, t, nt)) slab(a, k, 1);
}

/* Gauss-Seidel over the rows of slab s, forward (ascending) or backward. */
static void sgs_slab(const sweep_args *a, fcm_index s, int back)
{
  const mg_level *L = a->L;
  const double w = a->w, *b = a->b;
  double *x = a->x;
  const fcm_csr *A = level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  const fcm_index q0 = L->rows.ptr[s], q1 = L->rows.ptr[s + 1];
  for (fcm_index t = 0; t < q1 - q0; t++) {
    const fcm_index i = L->rows.item[back ? q1 - 1 - t : q0 + t];
    double sum = b[i];
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      sum -= v[p] * x[ci[p]];
    x[i] += w * sum * L->dinv[i];
  }
}

/* One smoothing step. SGS: a forward then a backward sweep, S = (I - B^-1 A)(I - F^-1 A),
 * which is A-self-adjoint (B = F^T); pre- and post-smoothing both apply S, so the cycle is
 * symmetric (post-smoothing must be the adjoint of pre-smoothing: backward-then-forward
 * would not be). SGS runs in the slab order of the rows (symmetric_sweep()), the coloured
 * SGS colour after colour (a barrier each), Jacobi in two loops over the rows. */
static void smooth(const fcm_mg *m, mg_level *L, const double *b, double *x)
{
  const fcm_csr *A = level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  const double w = m->opts.omega;
  const fcm_index n = L->n;
  if (m->opts.smoother == FCM_MG_SMOOTHER_JACOBI) {
#pragma omp for schedule(static)
    for (fcm_index i = 0; i < n; i++) {
      double sum = 0.0;
      for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
        sum += v[p] * x[ci[p]];
      L->r[i] = b[i] - sum;
    }
#pragma omp for schedule(static)
    for (fcm_index i = 0; i < n; i++)
      x[i] += w * L->r[i] * L->dinv[i];
    return;
  }
  if (m->opts.smoother == FCM_MG_SMOOTHER_SGS_COLORED) {
    for (int t = 0; t < 2 * L->ncolor; t++) {
      const int c = t < L->ncolor ? t : 2 * L->ncolor - 1 - t;
      const fcm_index r0 = L->color_ptr[c], r1 = L->color_ptr[c + 1];
#pragma omp for schedule(static)
      for (fcm_index q = r0; q < r1; q++) {
        const fcm_index i = L->color_rows[q];
        double sum = b[i];
        for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
          sum -= v[p] * x[ci[p]];
        x[i] += w * sum * L->dinv[i];
      }
    }
    return;
  }
  const sweep_args a = {L, w, b, x, NULL, NULL};
  symmetric_sweep(&L->rows, sgs_slab, &a);
}

/* Block Gauss-Seidel over the blocks of slab s, forward or backward: x_K += S_K (b - A x)_K,
 * block after block. */
static void block_slab(const sweep_args *a, fcm_index s, int back)
{
  const mg_level *L = a->L;
  const double *b = a->b;
  double *x = a->x, *r = a->r, *dx = a->dx;
  const fcm_csr *A = level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  const fcm_index q0 = L->blocks.ptr[s], q1 = L->blocks.ptr[s + 1];
  for (fcm_index t = 0; t < q1 - q0; t++) {
    const fcm_index k = L->blocks.item[back ? q1 - 1 - t : q0 + t];
    const fcm_index *d = NULL;
    const double *S = NULL;
    const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
    for (int i = 0; i < bm; i++) {
      double sum = b[d[i]];
      for (fcm_index p = rp[d[i]]; p < rp[d[i] + 1]; p++)
        sum -= v[p] * x[ci[p]];
      r[i] = sum;
    }
    for (int i = 0; i < bm; i++) {
      double sum = 0.0;
      for (int j = 0; j < bm; j++)
        sum += S[(size_t)i * (size_t)bm + (size_t)j] * r[j];
      dx[i] = sum;
    }
    for (int i = 0; i < bm; i++)
      x[d[i]] += dx[i];
  }
}

/* A symmetric block Gauss-Seidel sweep over the level's blocks (forward, then backward) in
 * the slab order of the blocks (symmetric_sweep()). */
static void block_smooth(const fcm_mg *m, const mg_level *L, const double *b, double *x)
{
  const size_t t = (size_t)omp_get_thread_num();
  const sweep_args a = {
      L, 0.0, b, x, m->blk_r + t * (size_t)m->blk_max, m->blk_dx + t * (size_t)m->blk_max};
  symmetric_sweep(&L->blocks, block_slab, &a);
}

/* Pre-smoothing, then r = b - A x and the coarse right-hand side R r (coarse guess 0). */
static void pre_smooth(const fcm_mg *m, mg_level *L, mg_level *C, const double *b, double *x)
{
  const fcm_csr *A = level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  const fcm_index n = L->n, nc = C->n;
  for (int s = 0; s < m->opts.pre_smooth; s++)
    smooth(m, L, b, x);
  if (L->blk && m->opts.pre_smooth > 0) {
#pragma omp barrier
    block_smooth(m, L, b, x);
  }
#pragma omp barrier
#pragma omp for schedule(static)
  for (fcm_index i = 0; i < n; i++) {
    double sum = 0.0;
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      sum += v[p] * x[ci[p]];
    L->r[i] = b[i] - sum;
  }
#pragma omp for schedule(static)
  for (fcm_index J = 0; J < nc; J++) {
    double sum = 0.0;
    for (fcm_index p = L->R_ptr[J]; p < L->R_ptr[J + 1]; p++)
      sum += L->R_val[p] * L->r[L->R_col[p]];
    C->b[J] = C->inactive[J] ? 0.0 : sum;
    C->x[J] = 0.0;
  }
}

/* x += P x_c (nothing from the coarse Dirichlet DOFs), then post-smoothing. */
static void post_smooth(const fcm_mg *m, mg_level *L, const mg_level *C, const double *b, double *x)
{
  const fcm_index n = L->n;
#pragma omp for schedule(static)
  for (fcm_index i = 0; i < n; i++) {
    double sum = 0.0;
    for (fcm_index p = L->P_ptr[i]; p < L->P_ptr[i + 1]; p++) {
      const fcm_index J = L->P_col[p];
      if (!C->inactive[J]) sum += L->P_val[p] * C->x[J];
    }
    x[i] += sum;
  }
  if (L->blk && m->opts.post_smooth > 0) {
    block_smooth(m, L, b, x);
#pragma omp barrier
  }
  for (int s = 0; s < m->opts.post_smooth; s++)
    smooth(m, L, b, x);
}

static fcm_status cycle(fcm_mg *m, int l, const double *b, double *x)
{
  fcm_status st = FCM_OK;
  mg_level *L = &m->lev[l];
  if (l == m->nlev - 1) {
    return fcm_direct_solve(m->direct, b, x); /* level 0 too when there is one level */
  }
  mg_level *C = &m->lev[l + 1];
  fcm_index nnz = 0;
  fcm_csr_get_size(level_matrix(L), NULL, NULL, &nnz);
  const int par = nnz >= MG_PARALLEL_NNZ;
#pragma omp parallel num_threads(team(m)) if (par)
  pre_smooth(m, L, C, b, x);
  const int gamma = l + 2 == m->nlev ? 1 : m->opts.cycle_index; /* the coarsest is exact */
  for (int g = 0; g < gamma; g++)
    if ((st = cycle(m, l + 1, C->b, C->x))) return st;
#pragma omp parallel num_threads(team(m)) if (par)
  post_smooth(m, L, C, b, x);
  return st;
}

fcm_status fcm_mg_cycle(fcm_mg *m, const double *b, double *x)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  FCM_CHECK(m && b && x && b != x, ctx, FCM_ERR_ARG, "mg_cycle: NULL or overlapping argument");
  FCM_TRY(ctx, cycle(m, 0, b, x));
cleanup:
  return st;
}

fcm_status fcm_mg_operator(void *user, const double *r, double *z)
{
  fcm_mg *m = user;
  if (m && z) memset(z, 0, sizeof *z * (size_t)m->lev[0].n);
  return fcm_mg_cycle(m, r, z);
}

static double norm2(fcm_index n, const double *v)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += v[i] * v[i];
  return sqrt(s);
}

fcm_status fcm_mg_solve(fcm_mg *m, const double *b, double *x, double rtol, int max_cycles,
                        fcm_mg_solve_info *info)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  fcm_mg_solve_info inf = {0, 0, 0.0, 0.0};
  FCM_CHECK(m && b && x && b != x, ctx, FCM_ERR_ARG, "mg_solve: NULL or overlapping argument");
  FCM_CHECK(rtol >= 0.0 && max_cycles >= 0, ctx, FCM_ERR_ARG,
            "mg_solve: rtol = %g must be >= 0 and max_cycles = %d >= 0", rtol, max_cycles);
  mg_level *L = &m->lev[0];
  const fcm_index n = L->n;
  const double bn = norm2(n, b);
  double r1 = 0.0, rk = 0.0;
  for (;;) {
    fcm_csr_apply(L->A, -1.0, x, 0.0, L->b); /* L->b is free on level 0 */
    for (fcm_index i = 0; i < n; i++)
      L->b[i] += b[i];
    rk = norm2(n, L->b);
    FCM_CHECK(isfinite(rk), ctx, FCM_ERR_NUMERIC, "mg_solve: residual is %g after %d cycles", rk,
              inf.cycles);
    inf.relative_residual = bn > 0.0 ? rk / bn : 0.0;
    if (inf.cycles == 1) r1 = rk;
    if (rk <= rtol * bn) {
      inf.converged = 1;
      break;
    }
    if (inf.cycles >= max_cycles) break;
    FCM_TRY(ctx, cycle(m, 0, b, x));
    inf.cycles++;
  }
  if (inf.cycles >= 2 && r1 > 0.0) inf.convergence_factor = pow(rk / r1, 1.0 / (inf.cycles - 1));
  FCM_CHECK(inf.converged, ctx, FCM_ERR_NOT_CONVERGED,
            "mg_solve: relative residual %g after %d cycles, rtol %g", inf.relative_residual,
            inf.cycles, rtol);
cleanup:
  if (info) *info = inf;
  return st;
}

int fcm_mg_num_levels(const fcm_mg *m)
{
  return m ? m->nlev : 0;
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
  fcm_csr_get_size(level_matrix(L), NULL, NULL, &info->nnz);
  for (int d = 0; d < 3; d++)
    info->grid[d] = L->grid[d];
  /* bodies: cells joined through shared copies (Hex20 level 0: the space's elements) */
  FCM_ALLOC(ctx, L->ncell + L->ncopy + 1, uf);
  for (fcm_index i = 0; i < L->ncell + L->ncopy; i++)
    uf[i] = i;
  const int npc = fcm_element_get_info(fcm_mesh_element_type(fcm_space_mesh(m->space)))->num_nodes;
  for (fcm_index c = 0; c < L->ncell; c++)
    if (L->corner)
      for (int b = 0; b < 8; b++)
        uf_union(uf, c, L->ncell + L->corner[8 * c + b]);
    else
      for (int a = 0; a < npc; a++)
        uf_union(uf, c, L->ncell + fcm_space_element_dofs(m->space, c)[a] / 3);
  fcm_index nb = 0;
  for (fcm_index c = 0; c < L->ncell; c++)
    nb += uf_find(uf, c) == c;
  info->bodies = nb;
cleanup:
  fcm__free(ctx, uf);
  return st;
}

/* ------------------------------------------------------------------ transfers only */

void fcm__mg_transfers_destroy(fcm_ctx *ctx, fcm__mg_transfers **tp)
{
  if (!tp || !*tp) return;
  fcm__mg_transfers *t = *tp;
  for (int l = 0; l < t->num_levels; l++) {
    if (t->inactive) fcm__free(ctx, t->inactive[l]);
    if (l + 1 < t->num_levels && t->P_ptr && t->P_col && t->P_val) {
      fcm__free(ctx, t->P_ptr[l]);
      fcm__free(ctx, t->P_col[l]);
      fcm__free(ctx, t->P_val[l]);
    }
  }
  for (int l = 0; l < t->num_levels && t->block_ptr && t->block_dofs; l++) {
    fcm__free(ctx, t->block_ptr[l]);
    fcm__free(ctx, t->block_dofs[l]);
  }
  fcm__free(ctx, t->num_blocks);
  fcm__free(ctx, t->block_ptr);
  fcm__free(ctx, t->block_dofs);
  fcm__free(ctx, t->n);
  fcm__free(ctx, t->P_ptr);
  fcm__free(ctx, t->P_col);
  fcm__free(ctx, t->P_val);
  fcm__free(ctx, t->inactive);
  fcm__free(ctx, t);
  *tp = NULL;
}

fcm_status fcm__mg_transfers_create(fcm_ctx *ctx, const fcm_space *space,
                                    const unsigned char *constrained, int max_levels,
                                    fcm_index coarse_dofs, fcm__mg_transfers **out)
{
  fcm_status st = FCM_OK;
  fcm_mg *m = NULL;
  fcm__mg_transfers *t = NULL;
  unsigned char *none = NULL;
  FCM_CHECK(ctx && space && out, ctx, FCM_ERR_ARG, "mg_transfers: NULL argument");
  *out = NULL;
  FCM_CHECK(max_levels >= 1 && max_levels <= 32, ctx, FCM_ERR_ARG,
            "mg_transfers: max_levels = %d outside [1, 32]", max_levels);
  FCM_CHECK(coarse_dofs >= 1, ctx, FCM_ERR_ARG, "mg_transfers: coarse_dofs = %lld must be >= 1",
            (long long)coarse_dofs);
  const fcm_index n0 = fcm_space_num_dofs(space);
  if (!constrained) {
    none = fcm__calloc(ctx, (size_t)n0 + 1, 1);
    FCM_CHECK(none, ctx, FCM_ERR_ALLOC, "mg_transfers: out of memory");
  }
  m = fcm__calloc(ctx, 1, sizeof *m);
  FCM_CHECK(m, ctx, FCM_ERR_ALLOC, "mg_transfers: out of memory");
  m->ctx = ctx;
  m->space = space;
  m->opts = fcm_mg_options_default();
  m->opts.max_levels = max_levels;
  m->opts.coarse_dofs = coarse_dofs;
  m->nt = FCM_MAX(omp_get_max_threads(), 1);
  FCM_TRY(ctx, build_hierarchy(m, NULL, constrained ? constrained : none));
  t = fcm__calloc(ctx, 1, sizeof *t);
  FCM_CHECK(t, ctx, FCM_ERR_ALLOC, "mg_transfers: out of memory");
  const int L = m->nlev;
  t->num_levels = L;
  FCM_ALLOC(ctx, L, t->n);
  FCM_ALLOC(ctx, L, t->P_ptr);
  FCM_ALLOC(ctx, L, t->P_col);
  FCM_ALLOC(ctx, L, t->P_val);
  FCM_ALLOC(ctx, L, t->inactive);
  FCM_ALLOC(ctx, L, t->num_blocks);
  FCM_ALLOC(ctx, L, t->block_ptr);
  FCM_ALLOC(ctx, L, t->block_dofs);
  for (int l = 0; l + 1 < L; l++)
    FCM_TRY(ctx, level_blocks(m, l, &t->num_blocks[l], &t->block_ptr[l], &t->block_dofs[l]));
  for (int l = 0; l < L; l++) { /* move the arrays: m keeps NULL */
    mg_level *V = &m->lev[l];
    t->n[l] = V->n;
    t->inactive[l] = V->inactive, V->inactive = NULL;
    if (l + 1 < L) {
      t->P_ptr[l] = V->P_ptr, V->P_ptr = NULL;
      t->P_col[l] = V->P_col, V->P_col = NULL;
      t->P_val[l] = V->P_val, V->P_val = NULL;
    }
  }
  *out = t;
  t = NULL;
cleanup:
  fcm__mg_transfers_destroy(ctx, &t);
  fcm_mg_destroy(&m);
  fcm__free(ctx, none);
  return st;
}

/* ------------------------------------------------------------------ slab check */

/* Slab of each item (-1: none; FCM_ERR_INTERNAL when an item is listed twice). */
static fcm_status slab_of_items(fcm_ctx *ctx, const slab_order *S, fcm_index n, int level,
                                const char *what, fcm_index **out)
{
  fcm_status st = FCM_OK;
  fcm_index *of = NULL;
  FCM_ALLOC_RAW(ctx, n + 1, of);
  for (fcm_index i = 0; i < n; i++)
    of[i] = -1;
  for (fcm_index k = 0; k < S->nslab; k++)
    for (fcm_index q = S->ptr[k]; q < S->ptr[k + 1]; q++) {
      const fcm_index i = S->item[q];
      FCM_CHECK(i >= 0 && i < n && of[i] < 0, ctx, FCM_ERR_INTERNAL,
                "mg: level %d: %s %lld listed twice or out of range [0, %lld) (slab %lld)", level,
                what, (long long)i, (long long)n, (long long)k);
      of[i] = k;
    }
  *out = of;
  of = NULL;
cleanup:
  fcm__free(ctx, of);
  return st;
}

fcm_status fcm__mg_slabs_check(const fcm_mg *m, int level, fcm_index *row_slabs,
                               fcm_index *block_slabs)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  fcm_index *rs = NULL, *bs = NULL, *rb_ptr = NULL, *rb = NULL, *fill = NULL;
  FCM_CHECK(m && level >= 0 && level + 1 < m->nlev, ctx, FCM_ERR_ARG,
            "mg_slabs_check: NULL argument or level %d outside [0, %d)", level,
            m ? m->nlev - 1 : 0);
  const mg_level *L = &m->lev[level];
  const fcm_csr *A = level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const fcm_index n = L->n;
  if (row_slabs) *row_slabs = L->rows.nslab;
  if (block_slabs) *block_slabs = L->blocks.nslab;
  if (L->rows.nslab > 0) {
    FCM_TRY(ctx, slab_of_items(ctx, &L->rows, n, level, "row", &rs));
    for (fcm_index i = 0; i < n; i++) {
      FCM_CHECK(rs[i] >= 0, ctx, FCM_ERR_INTERNAL, "mg: level %d: row %lld in no slab", level,
                (long long)i);
      for (fcm_index p = rp[i]; p < rp[i + 1]; p++) {
        const fcm_index j = ci[p];
        FCM_CHECK(rs[j] == rs[i] || (rs[j] - rs[i]) % 2 != 0, ctx, FCM_ERR_INTERNAL,
                  "mg: level %d: rows %lld and %lld are coupled but lie in slabs %lld and %lld "
                  "of one colour",
                  level, (long long)i, (long long)j, (long long)rs[i], (long long)rs[j]);
      }
    }
  }
  if (L->blocks.nslab > 0) {
    const fcm_index nb = fcm__schwarz_num_blocks(L->blk);
    FCM_TRY(ctx, slab_of_items(ctx, &L->blocks, nb, level, "block", &bs));
    /* the blocks of each row */
    FCM_ALLOC(ctx, n + 1, rb_ptr);
    FCM_ALLOC(ctx, n + 1, fill);
    for (fcm_index k = 0; k < nb; k++) {
      const fcm_index *d = NULL;
      const double *S = NULL;
      const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
      FCM_CHECK(bs[k] >= 0, ctx, FCM_ERR_INTERNAL, "mg: level %d: block %lld in no slab", level,
                (long long)k);
      for (int i = 0; i < bm; i++)
        rb_ptr[d[i] + 1]++;
    }
    for (fcm_index i = 0; i < n; i++)
      rb_ptr[i + 1] += rb_ptr[i];
    FCM_ALLOC(ctx, rb_ptr[n] + 1, rb);
    for (fcm_index k = 0; k < nb; k++) {
      const fcm_index *d = NULL;
      const double *S = NULL;
      const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
      for (int i = 0; i < bm; i++)
        rb[rb_ptr[d[i]] + fill[d[i]]++] = k;
    }
    for (fcm_index k = 0; k < nb; k++) {
      const fcm_index *d = NULL;
      const double *S = NULL;
      const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
      for (int i = 0; i < bm; i++)
        for (fcm_index p = rp[d[i]]; p < rp[d[i] + 1]; p++)
          for (fcm_index q = rb_ptr[ci[p]]; q < rb_ptr[ci[p] + 1]; q++) {
            const fcm_index j = rb[q];
            FCM_CHECK(bs[j] == bs[k] || (bs[j] - bs[k]) % 2 != 0, ctx, FCM_ERR_INTERNAL,
                      "mg: level %d: blocks %lld and %lld touch (DOFs %lld, %lld) but lie in "
                      "slabs %lld and %lld of one colour",
                      level, (long long)k, (long long)j, (long long)d[i], (long long)ci[p],
                      (long long)bs[k], (long long)bs[j]);
          }
    }
  }
cleanup:
  fcm__free(ctx, rs);
  fcm__free(ctx, bs);
  fcm__free(ctx, rb_ptr);
  fcm__free(ctx, rb);
  fcm__free(ctx, fill);
  return st;
}
