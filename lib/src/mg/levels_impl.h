/* mg module, private to its files: the levels of the hierarchy, the solver object and the calls
 * between creation and setup (mg.c), the hierarchy (hierarchy.c), the prolongations
 * (transfer.c), the smoothers (smoothers.c, sweeps.c) and the cycle (cycle.c).
 *
 * Data per grid level l (level 0 on Hex8, levels >= 1 on Hex20, whose level 0 has only its
 * DOFs, matrix and prolongation): cells (the first grid level: the space's elements) with a
 * grid position and 8 corner copies (corner bits dx + 2 dy + 4 dz), copies with a node grid
 * position, the connectivity of the cells (face neighbours), and for l < L-1 the DOF
 * prolongation P_l from level l+1.
 * DOFs: copy k, component c is row 3k + c of the level matrix on every level (level 0: the
 * space's numbering); inactive rows are the Dirichlet ones. */
#ifndef FCM_MG_LEVELS_IMPL_H
#define FCM_MG_LEVELS_IMPL_H

#include "core/core_impl.h"
#include "fcm/mg.h"
#include "la/la_impl.h"
#include "mg/mg_impl.h"
#include "solve/solve_impl.h"

#include <omp.h>
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
  int first;             /* the colour swept first */
  fcm_index *ptr;        /* nslab + 1 offsets into item */
  fcm_index *item;       /* the items, slab after slab, ascending within a slab */
  double *mid;           /* per slab: the midpoint of its work within its colour's, in [0, 1] */
  unsigned char *triple; /* row orders: per row i, nonzero when i = 3k starts its copy's three
                            rows and they share one column pattern (fcm__mg_row_dot3()):
                            FCM__MG_TRIPLE, or FCM__MG_TRIPLE_NODES when the columns come in
                            whole nodes */
  fcm_index lead, tail;  /* row orders of three slabs, the thin middle one swept first: the
                            first rows of slab 0, coupled with no row of slab 1, that a team of
                            two sweeps forward beside slab 1's forward sweep (lead) and backward
                            beside its backward sweep (tail); whole copies, 0: none */
} slab_order;

/* Does thread t of nt run slab s? The slabs of one colour go to the threads in contiguous
 * runs of about equal work (a slab to the thread whose share holds its work's midpoint).
 * Affects the schedule only: the slabs of one colour are independent. */
static inline int fcm__mg_slab_mine(const slab_order *S, fcm_index s, int t, int nt)
{
  const int owner = (int)(S->mid[s] * nt);
  return (owner < nt ? owner : nt - 1) == t;
}

/* Levels with at least this many stored entries share their work between the threads. */
#define MG_PARALLEL_NNZ 32768

/* The most levels a hierarchy has (fcm_mg_options.max_levels <= it). */
#define MG_MAX_LEVELS 32

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
  int *tpos;               /* levels >= 1: per stored entry (i, j) with j > i, the position of
                              (j, i), for the symmetrization of every Galerkin product */
  double *dinv;            /* 1 / a_ii */
  /* prolongation from level l+1 (n x n_coarse) */
  fcm_index *P_ptr;
  int *P_col;
  double *P_val;
  /* the Galerkin product A_{l+1} = P^T A_l P and the restriction R = P^T it holds */
  fcm__ptap *ptap;
  const fcm_index *R_ptr;
  const int *R_col;
  const double *R_val;
  double *x, *b, *r; /* work vectors (x, b unused on level 0) */
  int ncolor;        /* SGS_COLORED: rows by colour, CSR over colours */
  fcm_index *color_ptr, *color_rows;
  unsigned char *full; /* grid levels: per cell, 1 when it is all material (uncut, and on
                          coarse levels made of 8 such cells) */
  fcm_schwarz *blk;    /* block smoother (block_smoothing): the level's blocks */
  slab_order rows;     /* SGS: the rows in slabs (levels but the coarsest) */
  slab_order blocks;   /* the blocks of blk in slabs */
  const fcm_space *sp; /* octree hierarchies: the level's space (level 0: the given one;
                          coarser: owned by fcm_mg), whose DOF numbering the level has */
  fcm_index *oct_node; /* octree levels with separated bodies: per copy its node of sp's mesh */
  fcm_index *oct_body; /* and its body (the prolongations' check reads them) */
} mg_level;

/* A box grid mesh's cells on the grid, as level 0 of a grid hierarchy finds them (the mesh
 * alone decides them): shared, by reference count, by the hierarchies carried over cuts on the
 * same mesh (fcm__mg_create_pattern_cut()), so that a cut does not find them again. */
typedef struct mg_grid {
  int refs;
  const fcm_mesh *mesh;
  fcm_index grid[3];        /* cells along each axis */
  fcm_index *node2;         /* 3 per mesh node: position on the half grid */
  fcm_index *cell_ijk;      /* 3 per mesh cell: grid position */
  fcm_index *cell_at;       /* per grid position: the mesh cell there, -1: none */
  unsigned char bits_of[8]; /* corner bits of each local corner node */
} mg_grid;

struct fcm_mg {
  fcm_ctx *ctx;
  const fcm_space *space;
  fcm_mg_options opts;
  int nlev;
  mg_level lev[MG_MAX_LEVELS];
  fcm_direct *direct;
  unsigned char *cut_cell; /* per mesh cell: cut by the geometry or a cut surface, or split */
  fcm_index blk_max;       /* largest block of the block smoothers */
  int nt;                  /* threads at creation: the most any parallel region uses */
  double *blk_r, *blk_dx;  /* blk_max entries each, per thread */
  fcm_mesh
      *oct_mesh[MG_MAX_LEVELS]; /* octree hierarchies: the coarser octrees of levels 1, 2, ... */
  fcm_space *oct_space[MG_MAX_LEVELS]; /* and their spaces */
  fcm__mg_kept kept;  /* what fcm__mg_create_from() took from the earlier hierarchy */
  int values_pending; /* created on a pattern (fcm__mg_create_pattern()): no value set up yet */
  long long setups;   /* fcm_mg_setup() calls since the creation (coarse_interval) */
  int setup_failed;   /* the last fcm_mg_setup() failed: the levels' values are not one set */
  /* the space whose pattern level 0's matrix had at creation (fcm__mg_pattern_of()), NULL
   * for none; kept by fcm__mg_detach(), only compared */
  const fcm_space *pattern_of;
  mg_grid *mesh_grid;       /* grid hierarchies: the mesh's grid (shared, fcm__mg_grid_release()) */
  struct mg_beside *beside; /* level 0's smoothers still being made by a task of the team the
                               creation ran in (fcm__mg_create_pattern_cut_beside()), NULL
                               once fcm__mg_join() completed them */
};

/* Threads of a parallel region: the context's now, at most those of the creation (scratch). */
static inline int fcm__mg_team(const fcm_mg *m)
{
  const int t = fcm_ctx_num_threads(m->ctx);
  return t < m->nt ? t : m->nt;
}

static inline const fcm_csr *fcm__mg_level_matrix(const mg_level *L)
{
  return L->A ? L->A : L->Aown;
}

/* sum_p v[p] x[ci[p]] over p in [p0, p1) in four interleaved partial sums: the smoothers'
 * and residuals' time is these sums, and one sequential chain of additions would wait on each
 * addition. */
static inline __attribute__((always_inline)) double
fcm__mg_row_dot(const double *v, const int *ci, fcm_index p0, fcm_index p1, const double *x)
{
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  fcm_index p = p0;
  for (; p + 4 <= p1; p += 4) {
    s0 += v[p] * x[ci[p]];
    s1 += v[p + 1] * x[ci[p + 1]];
    s2 += v[p + 2] * x[ci[p + 2]];
    s3 += v[p + 3] * x[ci[p + 3]];
  }
  for (; p < p1; p++)
    s0 += v[p] * x[ci[p]];
  return (s0 + s1) + (s2 + s3);
}

/* The sums of fcm__mg_row_dot() over three rows of one column pattern, stored one after
 * the other from p0 (len entries each): each row's the same operations in the same order, so
 * the same bits, with each x[ci[p]] and ci[p] read once for the three. */
typedef double fcm__mg_v2d __attribute__((vector_size(16)));

static inline fcm__mg_v2d fcm__mg_load2(const double *p)
{
  fcm__mg_v2d r;
  memcpy(&r, p, sizeof r);
  return r;
}

/* The four columns from j on, whose x are x01 and x23, added into the three rows' sums. */
#define FCM__MG_DOT3_STEP(j, x01, x23)                                                             \
  do {                                                                                             \
    a01 += fcm__mg_load2(va + (j)) * (x01);                                                        \
    a23 += fcm__mg_load2(va + (j) + 2) * (x23);                                                    \
    b01 += fcm__mg_load2(vb + (j)) * (x01);                                                        \
    b23 += fcm__mg_load2(vb + (j) + 2) * (x23);                                                    \
    c01 += fcm__mg_load2(vc + (j)) * (x01);                                                        \
    c23 += fcm__mg_load2(vc + (j) + 2) * (x23);                                                    \
  } while (0)

/* nodes: the columns come in whole nodes (3 k, 3 k + 1, 3 k + 2, one after the other; the row
 * order's triple flag FCM__MG_TRIPLE_NODES): four nodes' twelve columns take four column
 * indices and their x in pairs of neighbours, the same operations on the same values. */
static inline __attribute__((always_inline)) void fcm__mg_row_dot3(const double *v, const int *ci,
                                                                   fcm_index p0, fcm_index len,
                                                                   int nodes, const double *x,
                                                                   double out[3])
{
  /* lanes (s0, s1) and (s2, s3) of each row's four partial sums: two-wide operations keep
   * the twelve sums in registers (twelve scalars and the x's spill) */
  const double *va = v + p0, *vb = va + len, *vc = vb + len;
  const int *c = ci + p0;
  fcm__mg_v2d a01 = {0.0, 0.0}, a23 = a01, b01 = a01, b23 = a01, c01 = a01, c23 = a01;
  fcm_index j = 0;
  if (nodes)
    for (; j + 12 <= len; j += 12) {
      const double *x0 = x + c[j], *x1 = x + c[j + 3], *x2 = x + c[j + 6], *x3 = x + c[j + 9];
      const fcm__mg_v2d u0 = {x0[2], x1[0]}, u1 = {x2[2], x3[0]};
      FCM__MG_DOT3_STEP(j, fcm__mg_load2(x0), u0);
      FCM__MG_DOT3_STEP(j + 4, fcm__mg_load2(x1 + 1), fcm__mg_load2(x2));
      FCM__MG_DOT3_STEP(j + 8, u1, fcm__mg_load2(x3 + 1));
    }
  for (; j + 4 <= len; j += 4) {
    const fcm__mg_v2d x01 = {x[c[j]], x[c[j + 1]]}, x23 = {x[c[j + 2]], x[c[j + 3]]};
    a01 += fcm__mg_load2(va + j) * x01;
    a23 += fcm__mg_load2(va + j + 2) * x23;
    b01 += fcm__mg_load2(vb + j) * x01;
    b23 += fcm__mg_load2(vb + j + 2) * x23;
    c01 += fcm__mg_load2(vc + j) * x01;
    c23 += fcm__mg_load2(vc + j + 2) * x23;
  }
  double a0 = a01[0], b0 = b01[0], c0 = c01[0];
  for (; j < len; j++) {
    const double xj = x[c[j]];
    a0 += va[j] * xj;
    b0 += vb[j] * xj;
    c0 += vc[j] * xj;
  }
  out[0] = (a0 + a01[1]) + (a23[0] + a23[1]);
  out[1] = (b0 + b01[1]) + (b23[0] + b23[1]);
  out[2] = (c0 + c01[1]) + (c23[0] + c23[1]);
}

#undef FCM__MG_DOT3_STEP

/* slab_order.triple: rows i .. i + 2 share one pattern (FCM__MG_TRIPLE), whose columns come in
 * whole nodes too (FCM__MG_TRIPLE_NODES, fcm__mg_row_dot3()'s nodes). */
#define FCM__MG_TRIPLE       1
#define FCM__MG_TRIPLE_NODES 2
/* the flags are the block smoothers' hints to fcm__schwarz_create_blocks_pattern() */
_Static_assert(FCM__MG_TRIPLE == FCM__SCHWARZ_ROWS_SAME &&
                   FCM__MG_TRIPLE_NODES == FCM__SCHWARZ_ROWS_NODES,
               "row flags");

/* Whether rows i, i + 1, i + 2 may be summed by fcm__mg_row_dot3() (triple: the level's row
 * order's flags, NULL: none may). */
static inline int fcm__mg_is_triple(const unsigned char *triple, fcm_index i, fcm_index n)
{
  return triple && i + 2 < n && triple[i];
}

/* ---- hierarchy.c */

/* The levels of m (m->ctx, space, opts set): cells, copies, DOFs, inactive rows and the
 * prolongations. Level 0's inactive rows are `inactive0` (n bytes, the space's numbering) or,
 * when it is NULL, the eliminated rows of A; A (NULL with inactive0) is level 0's matrix. No
 * matrix is read beyond that: the prolongations depend on the space and the inactive rows. */
fcm_status fcm__mg_build_hierarchy(fcm_mg *m, const fcm_csr *A, const unsigned char *inactive0);

/* m shares `from`'s mesh grid (from: NULL or a hierarchy alive while m is made) when it is
 * made on m's mesh; build_hierarchy() then takes it instead of finding it. */
void fcm__mg_grid_share(fcm_mg *m, const fcm_mg *from);

/* Drop a reference to *g (NULL: none), freeing it with the last one; *g = NULL. */
void fcm__mg_grid_release(fcm_ctx *ctx, mg_grid **g);

/* ---- octree.c */

/* The levels of m on a space whose mesh is an octree with hanging nodes (as
 * fcm__mg_build_hierarchy()): the octree coarsened level by level (each coarser space nested
 * in the finer one, its hanging DOFs inactive), then the box-grid hierarchy of the uniform
 * grid the truncations reach. Level 0's inactive rows include the hanging DOFs. */
fcm_status fcm__mg_octree_hierarchy(fcm_mg *m, const fcm_csr *A, const unsigned char *inactive0);

/* Free everything a level holds and zero it. */
void fcm__mg_level_free(fcm_ctx *ctx, mg_level *L);

/* ---- transfer.c */

/* Hex20: the prolongation P_0 from the p-coarse Hex8 level L (copies `cmap` of the space's
 * copies, -1 where no element uses a copy at a corner; `copy_node`: each space copy's node)
 * to level 0: a corner copy from itself, a mid-edge copy the mean of its edge's ends in the
 * first element that uses it at its own node. */
fcm_status fcm__mg_p_prolongation(fcm_ctx *ctx, const fcm_space *sp, mg_level *L0,
                                  const mg_level *L, const fcm_index *cmap,
                                  const fcm_index *copy_node);

/* The trilinear weights of each fine copy k of F from the corners of the first coarse cell of
 * C that uses it (cusers[cptr[k]]; none when no cell does): CSR over the fine copies
 * (scal_ptr, F->ncopy + 1), coarse copies and weights. */
fcm_status fcm__mg_scalar_prolongation(fcm_ctx *ctx, const mg_level *F, const mg_level *C,
                                       const fcm_index *cptr, const fcm_index *cusers,
                                       fcm_index **scal_ptr, fcm_index **scal_col, double **scal_w);

/* P_l (F->n x C->n): the scalar weights for each component of the active DOFs. */
fcm_status fcm__mg_dof_prolongation(fcm_ctx *ctx, mg_level *F, const mg_level *C,
                                    const fcm_index *scal_ptr, const fcm_index *scal_col,
                                    const double *scal_w);

/* ---- smoothers.c */

void fcm__mg_slabs_free(fcm_ctx *ctx, slab_order *S);

/* The rows of a level in slabs (FCM_MG_SMOOTHER_SGS). */
fcm_status fcm__mg_row_slabs(fcm_mg *m, mg_level *L);

/* The rows of a level grouped by colour (FCM_MG_SMOOTHER_SGS_COLORED). */
fcm_status fcm__mg_level_colors(fcm_mg *m, mg_level *L);

/* The blocks of level l (< nlev - 1) in its DOF numbering: level 0's vertex and cut element
 * blocks, a coarser level's corner blocks. CSR over the blocks, allocated here. */
fcm_status fcm__mg_level_blocks(fcm_mg *m, int l, fcm_index *nb, fcm_index **ptr, fcm_index **dofs);

struct mg_carry;

/* The block smoother of level l (< nlev - 1), from its level matrix (its row order made
 * before, fcm__mg_row_slabs(), with the SGS smoother); with `old` (NULL: none) and same[l]
 * (level l's pattern is old's) old's block smoother where its blocks are old's
 * (fcm__mg_keep_blocks()); with `carry` (NULL: none; its maps made), the blocks that are the
 * old hierarchy's mapped copy their positions (fcm__mg_carry_blocks_prior()). *bmax: its
 * largest block, *carried: its blocks carried. With old NULL it writes level l's fields
 * only (fcm__mg_keep_blocks() counts in m and moves old's). */
fcm_status fcm__mg_level_block_smoother(fcm_mg *m, fcm_mg *old, const unsigned char *same,
                                        const struct mg_carry *carry, int l, fcm_index *bmax,
                                        fcm_index *carried);

/* The block smoothers of the levels from `first` on but the coarsest
 * (fcm__mg_level_block_smoother()), m->blk_max and m->kept.carried_blocks counted. */
fcm_status fcm__mg_block_smoothers_create(fcm_mg *m, fcm_mg *old, const unsigned char *same,
                                          const struct mg_carry *carry, int first);

/* The block sweeps' buffers, m->blk_max entries per thread (after every block smoother). */
fcm_status fcm__mg_block_buffers(fcm_mg *m);

/* ---- sweeps.c */

/* One smoothing step with the pointwise smoother of m's options, by the team of the enclosing
 * parallel region (no barrier at the end); post: 0 before the coarse correction, 1 after it
 * (the direction of a one-way step, point_sweep; consecutive one-way steps need a barrier
 * between them). */
void fcm__mg_smooth(const fcm_mg *m, mg_level *L, const double *b, double *x, int post);

/* A symmetric block Gauss-Seidel sweep over the level's blocks, by the team of the enclosing
 * parallel region (no barrier at the end). */
void fcm__mg_block_smooth(const fcm_mg *m, const mg_level *L, const double *b, double *x, int post);

/* ---- update.c: the parts fcm__mg_create_from() takes from an earlier hierarchy `old` (each
 * moved out of old, which is destroyed afterwards) */

/* May m (options set, hierarchy built) take anything from old (NULL: no)? The same options
 * and thread count, neither an octree hierarchy. */
int fcm__mg_reuse_allowed(const fcm_mg *old, const fcm_mg *m);

/* Has level l of m the size and matrix pattern of old's level l (level 0: old not detached)? */
int fcm__mg_level_same(const fcm_mg *old, const fcm_mg *m, int l);

/* With level l's pattern the same as old's: take old's Galerkin plan of level l, P_l and level
 * l + 1's matrix (pattern), diagonal and transposed positions when P_l and the size of level
 * l + 1 are old's (1), else nothing (0). */
int fcm__mg_keep_plan(fcm_mg *old, fcm_mg *m, int l);

/* With level l's pattern the same as old's: take old's row slabs and colours of level l. */
void fcm__mg_keep_orders(fcm_mg *old, fcm_mg *m, int l);

/* With the coarsest pattern the same as old's (same_coarsest) and as many levels: take old's
 * coarsest solver with its symbolic analysis (1), else nothing (0). */
int fcm__mg_keep_analysis(fcm_mg *old, fcm_mg *m, int same_coarsest);

/* With level l's pattern the same as old's: when its blocks (nb, ptr, dofs) are old's, take
 * old's block smoother and block slabs and set the smoother up on the level matrix
 * (*kept = 1), else nothing (*kept = 0). @return FCM_OK or the setup's failure. */
fcm_status fcm__mg_keep_blocks(fcm_mg *old, fcm_mg *m, int l, fcm_index nb, const fcm_index *ptr,
                               const fcm_index *dofs, int *kept);

/* ---- carry.c: a hierarchy carried over a cut (fcm__mg_create_pattern_cut()) */

/* The hierarchy before the cut (read only) and, per level l < nlev, the maps between its
 * rows and the new hierarchy's: row_old[l] (new rows) the old row, row_new[l] (old rows) the
 * new row, -1 for none; injective, each the other's inverse. graph: the copy graphs of the
 * spaces before and after the cut (level 0's patterns). */
typedef struct mg_carry {
  const fcm_mg *old;
  const fcm_space *old_space;
  int nlev;
  fcm_index *row_old[MG_MAX_LEVELS], *row_new[MG_MAX_LEVELS];
  const fcm_index *graph[4];               /* fcm__space_cut_copy_map()'s */
  unsigned char *crow_same[MG_MAX_LEVELS]; /* level l >= 1: its rows that are the old ones
                                              mapped in the same order (the plans' c_same) */
  unsigned char *copy_same; /* level 0, per copy: its three rows the old copy's mapped, column
                               for column in the same order (the copy graphs compared) */
} mg_carry;

/* Level 0's smoothers made beside the rest of a cut's creation (create_beside()): what their
 * task reads and reports, the hierarchy's (m->beside) until fcm__mg_join(). */
typedef struct mg_beside {
  mg_carry carry; /* the cut's maps, which the coarser levels' patterns read too */
  fcm__loop loop; /* iteration 0: the coarser levels; 1: level 0 (its error comes second) */
  fcm_index bmax, carried;
  double seconds; /* the task's wall time */
} mg_beside;

/* The space when A has the space's pattern (row_ptr and col_idx the space's arrays, shared,
 * or the same values: fcm_space_matrix_create()), else NULL. O(1) when shared, else one
 * comparison of the pattern. */
const fcm_space *fcm__mg_pattern_of(const fcm_space *space, const fcm_csr *A);

/* The maps of c (old, old_space set) for m (hierarchy built); nlev 0, no error, where the
 * carry's preconditions fail (fcm__mg_create_pattern_cut()): an octree hierarchy, old not
 * made on old_space's pattern, m not on its space's, the spaces not a full cut pair.
 * @return FCM_OK, FCM_ERR_ALLOC, FCM_ERR_INTERNAL. */
fcm_status fcm__mg_carry_maps(fcm_mg *m, mg_carry *c);

/* What level l's block smoother may copy positions from (*has = 1: *pr set, *rows_same
 * allocated: per copy of m's level l, its three rows of the level matrix are the old copy's
 * rows mapped, in the same order; on level 0 the two spaces' copy graphs compared, on the
 * coarser levels the plans' c_same), or *has = 0 where c (NULL: none) has nothing: no maps or
 * no old block smoother with positions on that level. @return FCM_OK or FCM_ERR_ALLOC. */
fcm_status fcm__mg_carry_blocks_prior(const fcm_mg *m, const mg_carry *c, int l,
                                      fcm__schwarz_prior *pr, unsigned char **rows_same, int *has);

/* Level 0's row order flags (triple, n bytes) from the space's copy graph, where level 0's
 * matrix has the space's pattern (m->pattern_of, a full space): a copy's three rows hold
 * three columns for each copy of its graph row, itself among them, so each is
 * FCM__MG_TRIPLE_NODES, as fcm__mg_row_slabs() finds them from the rows. 1 when written, 0
 * (triple unfinished) where that does not apply. */
int fcm__mg_space_triples(const fcm_mg *m, unsigned char *triple);

/* Level 0's diagonal positions (diag, n entries) from the space's copy graph where level 0's
 * matrix has the space's pattern, as fcm__mg_space_triples() reads it: copy k's row 3 k + c
 * holds its diagonal at 3 q + c, q the place of k in its graph row (each row's length
 * checked, 3 per graph entry). 1 when written, 0 (diag unfinished) where that does not apply
 * or a check fails. */
int fcm__mg_space_diag(const fcm_mg *m, fcm_index *diag);

/* Level 0's rows' reach (reach, n entries: the larger of the row and its last column) from
 * the space's copy graph, as fcm__mg_space_diag() reads it. 1 when written, 0 (reach
 * unfinished) where that does not apply or a row's length is not 3 per graph entry. */
int fcm__mg_space_reach(const fcm_mg *m, fcm_index *reach);

/* The prior of level l's Galerkin plan (1), or 0 where c (NULL: none) has none. */
int fcm__mg_carry_prior(const fcm_mg *m, const mg_carry *c, int l, fcm__ptap_prior *pr);

void fcm__mg_carry_free(fcm_ctx *ctx, mg_carry *c);

#endif /* FCM_MG_LEVELS_IMPL_H */
