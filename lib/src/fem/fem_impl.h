/* fem module internals: the space layout shared by the module's files (space.c with
 * numbering.c and topology.c, assemble.c, eval.c, locate.c, fields.c; immutable after
 * fcm_space_create, except for the momentum's cache, fcm__space_mass_cache). */
#ifndef FCM_FEM_IMPL_H
#define FCM_FEM_IMPL_H

#include "core/core_impl.h"
#include "embed/embed_impl.h"
#include "fcm/fem.h"

#include <stdint.h>

/* What fcm_space_momentum() keeps between calls (eval.c), owned by the space: the mass block
 * of every element, built by its first call over the authentic points of the mass rules and
 * freed with the space. The space's rules and numbering never change, so the blocks stay
 * valid for its life; a cut makes a new space, with a new cache. Allocated with the space
 * (empty) so that a const space can fill it; filled under an OpenMP critical section. */
typedef struct fcm__space_mass_cache {
  /* num_elems x nn (nn + 1) / 2: per element, sum over its authentic mass points of
   * w det J N_a N_b (unit density), the upper triangle a <= b row by row; NULL until built */
  double *blocks;
} fcm__space_mass_cache;

/* Cells per block of assembly's visiting order (block_ptr, block_color_ptr, block_list). */
enum { FCM__SPACE_BLOCK = 128 };

struct fcm_space {
  fcm_ctx *ctx;
  const fcm_mesh *mesh;
  fcm_element_type type;
  int nn; /* nodes per cell */
  fcm_index num_cells;
  fcm_index num_nodes;
  unsigned char *active; /* num_cells */
  fcm_index *node_dof;   /* num_nodes: first DOF of the node's first copy, or -1 */
  fcm_index *node_ncopy; /* num_nodes: copies of the node (0 inactive, 1, or more when cuts
                            separate its support: generalized enrichment, XFEM) */
  fcm_index num_dofs;    /* 3 x copies; a node's copies have consecutive DOFs */
  /* Elements: the material pieces of the active cells (one per cell without cuts), in cell
   * order: element e lies in cell elem_cell[e], integrates with the rules of piece
   * elem_piece[e] (-1: standard rule) and has the DOFs elem_dof[nn e + a] .. + 2 at its
   * local node a (the copy of that node whose support component holds the piece). Cell c
   * has elements [cell_elem[c], cell_elem[c + 1]). */
  fcm_index num_elems;
  fcm_index *elem_cell, *elem_piece, *elem_dof, *cell_elem;
  fcm_index num_constrained; /* copies constrained to move with their piece (Koschier) */
  /* elem_con[nn e + a] = 1 where element e uses at local node a, in place of a constrained
   * copy, the copy it moves with (possibly another copy of the same node); NULL when no copy
   * is constrained */
  unsigned char *elem_con;
  /* Everything above is the numbering: O(nodes + elements x nn), the same on every process of
   * a distributed run. The topology below covers the LOCAL elements and copies. A full space
   * (fcm_space_create*(), is_local = 0): every element and copy, local position = element id /
   * copy rank (local_elem, local_copy, cell_local NULL). A local space
   * (fcm__space_create_local()): the elements of the flagged cells (cell_local[c] != 0),
   * local_elem[le] their ids and local_copy[lk] the ranks of the copies they use, both
   * ascending; a copy's graph row lists the copies sharing a LOCAL element with it, so it is
   * the full row exactly when every element using the copy is local. */
  int is_local;
  unsigned char *cell_local; /* num_cells (local space), NULL (full space) */
  /* A local space without rules: the cells whose points this process integrates (its own
   * cells, fcm__space_localize()); NULL otherwise (the rules' cell mask says it:
   * fcm__space_owns()) */
  unsigned char *own;
  fcm_index num_local_elems;  /* full space: num_elems */
  fcm_index *local_elem;      /* num_local_elems, NULL (full space) */
  fcm_index num_local_copies; /* full space: num_dofs / 3 */
  fcm_index *local_copy;      /* num_local_copies, NULL (full space) */
  /* Copy graph (by local copy position k): node_ptr[k]..node_ptr[k+1] are the ranks (global)
   * of the copies sharing a local element with copy k (itself included), sorted. */
  fcm_index *node_ptr; /* num_local_copies + 1 */
  fcm_index *node_adj;
  /* Scalar CSR pattern: the three rows 3k..3k+2 of local copy k each hold 3 columns (global
   * DOFs) per neighbour. A full space's is the n x n pattern. */
  fcm_index *row_ptr; /* 3 num_local_copies + 1 */
  int *col_idx;
  /* col_idx's block holds col_cap entries (room for a later cut's pattern to take it over:
   * fcm__space_create_cut_take()); col_from: the space whose block this one took, until
   * fcm__space_cut_keep() (NULL otherwise) */
  size_t col_cap;
  struct fcm_space *col_from;
  /* Per local element le, nn x nn offsets: the position of copy b in copy a's row of the copy
   * graph, so entry (3ka+i, 3kb+j) lives at row_ptr[3ka+i] + 3 off[a][b] + j (ka the local
   * position of copy a). */
  int *elem_off; /* num_local_elems x nn x nn */
  /* Per local element le of a LOCAL space, the local positions ka of the copies it uses at its
   * nn nodes (fcm__space_elem_row() = 3 ka); NULL for a full space (ka = elem_dof / 3). */
  int *elem_lcopy; /* num_local_elems x nn (local space), NULL (full space) */
  /* Local elements grouped by colour (no two share a copy): color_ptr[c]..color_ptr[c+1]
   * index color_elems, which holds LOCAL element positions le (element local_elem[le]); for a
   * full space le is the element id (sim/nitsche.c groups its boundary elements by them
   * through fcm__space_elem_local()). */
  int num_colors;
  fcm_index *color_ptr;
  fcm_index *color_elems;
  /* Assembly's visiting order: block_cells lists the cells with local elements (a full
   * space: the active cells) in the Morton order of their centres; block b holds the cells
   * [b B, min((b + 1) B, num_block_cells)) of it (B = FCM__SPACE_BLOCK), a compact cluster,
   * and their local elements block_elems[block_ptr[b] .. block_ptr[b + 1]) (cell by cell, each
   * cell's elements ascending). The blocks are coloured so that no two of a colour share a mesh
   * node of their cells (or the node of a copy a constrained element uses in another node's
   * place): block_color_ptr[c]..block_color_ptr[c+1] index block_list, the blocks of colour c
   * ascending. One thread assembles a whole block, so neighbouring cells follow each other and
   * their matrix rows are still in cache (assemble.c). The blocks and their colours depend on
   * the active cells alone (and the constrained elements' copies): a cut, which adds elements
   * to the cells it reaches, changes neither, so every element away from the cut keeps its
   * place in the visit. */
  int num_block_colors;
  /* Copy graph rows fcm__space_build_topology_cut() took from the space before the cut (0: the
   * topology was built anew) */
  fcm_index cut_kept_rows;
  fcm_index *block_color_ptr;
  fcm_index *block_list;
  fcm_index *block_elems; /* num_local_elems */
  fcm_index num_blocks, num_block_cells;
  fcm_index *block_ptr;   /* num_blocks + 1 */
  fcm_index *block_cells; /* num_block_cells */
  /* 1 when fcm__space_build_topology_cut() took block_cells and the block colours from the
   * space before the cut */
  int blocks_kept;
  /* Embedded case: per-cell rules of cut cells (borrowed) and the most points any cut
   * cell has in either rule. Nothing here changes after creation: assembly scratch lives
   * in fcm_assembly_workspace (assemble.c). */
  const fcm_cell_rules *rules;
  int max_cut_points;
  fcm_rule *mass_rule; /* the standard mass rule of full cells (fcm_space_momentum()) */
  fcm__space_mass_cache *mass_cache; /* fcm_space_momentum()'s element mass blocks */
  /* A space patched from the one before its cut (fcm__space_build_topology_cut()): per copy k,
   * the copy p of cut_from whose matrix rows and vector entries receive exactly the terms of
   * k's, element by element (each element of k the child of one of p's, at the same nodes), in
   * the same order of the assembly's visit (blocks by colour, then within a block), and whose
   * rows map entry by entry onto k's; -1 otherwise. Where the elements' terms are the same
   * bits, k's rows and entries are then p's bits (fcm__space_cut_rows()). NULL when the
   * topology was built anew. cut_from is compared only, never read through (it may be gone);
   * cut_from_dofs and cut_from_elems are its sizes, checked beside it. */
  fcm_index *cut_row_from;
  const struct fcm_space *cut_from;
  fcm_index cut_from_dofs, cut_from_elems;
};

/* A space whose numbering (node_dof, node_ncopy, elements, cell_elem, num_dofs, constrained
 * copies: every array above the topology in struct fcm_space) is fcm_space_create()'s
 * (rules NULL; cell_active as there) or fcm_space_create_embedded_with()'s (rules given,
 * cell_active NULL; opts NULL: no constrained copies, as there) bit for bit, but whose copy
 * graph, pattern, offsets and colours cover only the elements of the active cells flagged in
 * cell_mask (num_cells flags; NULL: none, the numbering alone). For a distributed run: each
 * process flags its own cells and their ghosts (cells sharing a DOF copy with a copy it owns),
 * which makes the graph row of every owned copy the full space's row; the topology then costs
 * O(local elements + their copies' nonzeros) instead of O(DOFs + nonzeros). The numbering's
 * build allocates O(nodes + elements x nn) scratch, as fcm_space_create() does.
 *
 * What a local space does: every accessor and every function that reads only the numbering
 * (fcm_space_node_dof / _node_copies / _element_dofs / _cell_elements / _transfer /
 * _cell_blocks / _node_field / _cell_stress / _max_displacement / _momentum / _locate /
 * _interpolate / _eval / _num_bodies / _write_vtu, fcm__space_write_vtu_piece(),
 * fcm__assembly_element_linear(), fcm_assembly_workspace_create()) works on every element as
 * on the full space (the element's points come from the rules, which a cell_mask of the rules
 * restricts independently); fcm_space_num_colors() counts the colours of the local elements,
 * and the colour lists hold local element positions. Whatever needs the whole pattern refuses
 * it with FCM_ERR_ARG (fcm__space_check_full()): fcm_space_matrix_create(); the integrator's
 * setup refuses a local space without a distributed backend (integrator.c). Assembly over the local
 * rows: fcm__space_matrix_create_rows() (3 num_local_copies rows, global columns: row_ptr / col_idx
 * as they are), filled by fcm_assembly_workspace_linear() / _hyperelastic() (and the one-shot
 * fcm_assemble_*() given such a matrix) when fcm__space_check_assemble() passes: the rules'
 * cell_mask gives points to local cells only (the own cells; ghosts get none), so each process adds
 * its own elements' terms (PARTIAL rows: summed over the processes they are the full rows); vectors
 * stay num_dofs long (global DOFs), energies per element id. fcm__space_localize() picks the own
 * cells and their ghosts. The values of a matrix over the rows go into a MATMPIAIJ with
 * ADD_VALUES (fcm__space_row_dof() names each row's DOF); fcm__space_matrix_apply() multiplies.
 * @return FCM_OK, FCM_ERR_ARG (as fcm_space_create*(); rules and cell_active both given),
 * FCM_ERR_ALLOC, FCM_ERR_UNSUPPORTED (colours). (space.c) */
FCM_COMPONENT_API fcm_status fcm__space_create_local(fcm_ctx *ctx, const fcm_mesh *mesh,
                                                     const unsigned char *cell_active,
                                                     const fcm_cell_rules *rules,
                                                     const fcm_space_options *opts,
                                                     const unsigned char *cell_mask,
                                                     fcm_space **out);

/* fcm_space_create_embedded_with(ctx, mesh, rules, opts, out) after a cut: rules made by
 * fcm_cell_rules_create_cut() from the rules of `from` (a full space on the same mesh), whose
 * topology the new space patches where the cut left it (fcm__space_build_topology_cut()). The
 * same space bit for bit (every array); with from NULL or local the space is built anew, and
 * otherwise from must be the space on the rules the cut started from (another space on rules
 * with as many pieces fails with FCM_ERR_INTERNAL). `from` is only read and may be destroyed
 * afterwards. @return as
 * fcm_space_create_embedded_with(). (space.c) */
FCM_COMPONENT_API fcm_status fcm__space_create_cut(fcm_ctx *ctx, const fcm_mesh *mesh,
                                                   const fcm_cell_rules *rules,
                                                   const fcm_space_options *opts,
                                                   const fcm_space *from, fcm_space **out);

/* fcm__space_create_cut() that also takes from's columns block (the pattern's col_idx, never
 * read by the patch) for its own pattern where it fits (a cut adds a few per cent of the
 * entries; a block has a quarter more room than its first pattern): no first touch of new
 * pages. from then has no pattern: no matrix may be made on it, and the matrices made on it
 * before (which borrow its pattern) may not be used, until fcm__space_cut_give_back(*out) (or
 * destroying *out) gives it back; after fcm__space_cut_keep(*out) from can only be destroyed.
 * from must outlive *out until one of the two (the give-back writes into from). The same
 * space bit for bit. (space.c) */
FCM_COMPONENT_API fcm_status fcm__space_create_cut_take(fcm_ctx *ctx, const fcm_mesh *mesh,
                                                        const fcm_cell_rules *rules,
                                                        const fcm_space_options *opts,
                                                        fcm_space *from, fcm_space **out);

/* Rebuild the topology of a local space for the cells flagged in cell_mask (NULL: none); the
 * numbering is unchanged. On failure the space has no local elements (and the error). FCM_ERR_ARG
 * for a full space. (space.c) */
FCM_COMPONENT_API fcm_status fcm__space_set_local_cells(fcm_space *s,
                                                        const unsigned char *cell_mask);

/* FCM_OK for a full space; for a local one FCM_ERR_ARG with "<what>: the space is a local
 * space ..." recorded. (space.c) */
fcm_status fcm__space_check_full(const fcm_space *s, const char *what);

/* The Morton (Z-curve) key of point x on a 2^21 grid over the box [lo, hi] in each direction
 * (coordinates clamped to the box; a flat direction counts as 0): sorting by it keeps points
 * near each other in space near each other in the order. */
FCM_COMPONENT_API uint64_t fcm__morton_key(const double x[3], const double lo[3],
                                           const double hi[3]);

/* ---- After a cut (cut_update.c): `to` is a space on the cell rules that
 * fcm_cell_rules_create_cut() made from `from`'s rules (fcm_space_transfer()'s conditions). */

/* FCM_OK when `to` is `from` after a cut (both embedded on the same mesh, to's rules made from
 * from's by fcm_cell_rules_create_cut()); else FCM_ERR_ARG "<what>: ...". */
fcm_status fcm__space_check_cut_pair(const fcm_space *from, const fcm_space *to, const char *what);

/* The element of `from` holding the parent piece of element e of `to` (the same cell), -1 when
 * the parent piece is not among the cell's pieces in `from` (not a cut pair). */
fcm_index fcm__space_cut_parent_elem(const fcm_space *from, const fcm_space *to, fcm_index e);

/* parent[k] (num_dofs(to) / 3 entries): the copy of `from` whose values copy k of `to`
 * inherits, the copy its elements' parent elements use at the same node (the first such
 * element in element order); -1 for none (a cut space has none). No allocation.
 * @return FCM_OK, FCM_ERR_ARG (NULL, not a cut pair), FCM_ERR_INTERNAL. */
fcm_status fcm__space_cut_parents(const fcm_space *from, const fcm_space *to, fcm_index *parent);

/* fcm__space_cut_parents() that also gives parent_elem[e] (num_elems(to) entries; may be NULL):
 * fcm__space_cut_parent_elem(from, to, e), looked up once per element. */
fcm_status fcm__space_cut_parents_with(const fcm_space *from, const fcm_space *to,
                                       fcm_index *parent, fcm_index *parent_elem);

/* same[e] (num_elems(to) entries): the element of `from` that element e of `to` integrates
 * exactly as (same cell and class; an uncut cell, or the same points, weights and flags of
 * every rule kind and the same surface rule, compared bit by bit, as its parent piece's), -1
 * where the cut changed it; *num_same (may be NULL) counts the former. Whatever the assembly
 * computes from an element's rule and cell alone (fcm__assembly_linear_blocks()) is then
 * the same for both. Reads the rules of the cut cells once; no allocation.
 * @return FCM_OK, FCM_ERR_ARG (NULL, not a cut pair). */
fcm_status fcm__space_cut_same_elements(const fcm_space *from, const fcm_space *to, fcm_index *same,
                                        fcm_index *num_same);

/* The ordering of to's DOFs (perm, num_dofs(to) entries, perm[k] the DOF eliminated k-th)
 * extended from old_perm, an ordering of from's DOFs: each old DOF's place goes to the same
 * component of its children (the copies of `to` with it as parent, ascending), a split copy's
 * new DOFs beside the ones they split from; DOFs without a parent last, ascending. Allocates
 * O(copies) scratch. @return FCM_OK, FCM_ERR_ARG (NULL, not a cut pair, old_perm not a
 * permutation of from's DOFs), FCM_ERR_ALLOC, FCM_ERR_INTERNAL. */
fcm_status fcm__space_cut_ordering(const fcm_space *from, const fcm_space *to,
                                   const fcm_index *old_perm, fcm_index *perm);

/* What a hierarchy carried over a cut reads of the spaces (mg/carry.c): old_copy[k]
 * (num_dofs(to) / 3 entries) the copy of `from` of which copy k of `to` is the only child
 * (fcm__space_cut_parents()), -1 where k has no parent or its parent has other children;
 * graphs: from's copy graph (node_ptr, node_adj: the columns of its matrices' rows, a copy at
 * a time) and to's, borrowed while the spaces live. Both spaces full. Allocates O(copies of
 * from) scratch. @return FCM_OK, FCM_ERR_ARG (NULL, not a cut pair, a local space),
 * FCM_ERR_ALLOC, FCM_ERR_INTERNAL. */
FCM_COMPONENT_API fcm_status fcm__space_cut_copy_map(const fcm_space *from, const fcm_space *to,
                                                     fcm_index *old_copy,
                                                     const fcm_index *graphs[4]);

/* ---- Matrices over a space's rows (a local space: its local copies' rows, global columns).
 * A full space: rows are DOFs, local element positions are element ids, every function below
 * is the full space's own (same arrays, same bits). */

/* 1 when this process integrates the points of cell c: the cells the rules' cell mask flags
 * (fcm__cell_rules_owns()), or for a local space without rules its own cells
 * (fcm__space_localize()); every cell of a full space without a mask. */
static inline int fcm__space_owns(const fcm_space *s, fcm_index c)
{
  return s->rules ? fcm__cell_rules_owns(s->rules, c) : !s->own || s->own[c];
}

/* Rows of the space's matrices: 3 num_local_copies (a full space: num_dofs). */
static inline fcm_index fcm__space_num_rows(const fcm_space *s)
{
  return 3 * s->num_local_copies;
}

/* The DOF of row r of a matrix over the space's rows (a full space: r). */
static inline fcm_index fcm__space_row_dof(const fcm_space *s, fcm_index r)
{
  return s->local_copy ? 3 * s->local_copy[r / 3] + r % 3 : r;
}

/* The element id of local element position le (a full space: le). */
static inline fcm_index fcm__space_local_elem(const fcm_space *s, fcm_index le)
{
  return s->local_elem ? s->local_elem[le] : le;
}

/* The local position of element e, -1 when e is not a local element (binary search of the
 * ascending local_elem; a full space: e, -1 outside [0, num_elems)). (space.c) */
fcm_index fcm__space_elem_local(const fcm_space *s, fcm_index e);

/* The first row (3 x local copy position) of the copy that local element le uses at node a
 * (a full space: elem_dof[le nn + a]). Rows r..r+2 are its three components. */
static inline fcm_index fcm__space_elem_row(const fcm_space *s, fcm_index le, int a)
{
  return s->elem_lcopy ? 3 * (fcm_index)s->elem_lcopy[(size_t)le * s->nn + a]
                       : s->elem_dof[le * s->nn + a];
}

/* A matrix over the space's rows: fcm__space_num_rows(s) x num_dofs with the space's pattern
 * (row_ptr / col_idx as they are: global columns; SHARED with the space, not copied: the
 * space must outlive the matrix; values of its own), FCM_CSR_GENERAL for a local space; a
 * full space: fcm_space_matrix_create()'s size, kind and pattern (square, FCM_CSR_SYMMETRIC).
 * Assembly (fcm_assembly_workspace_linear() / _hyperelastic()) adds into it.
 * @return FCM_OK, FCM_ERR_ARG (NULL), FCM_ERR_ALLOC. (space.c) */
fcm_status fcm__space_matrix_create_rows(const fcm_space *s, fcm_csr **A);

/* fcm__space_matrix_create_rows() whose values take give's storage where it is large enough
 * (fcm__csr_share_pattern_from(): give, or NULL, is then left without values). (space.c) */
fcm_status fcm__space_matrix_create_rows_from(const fcm_space *s, fcm_csr *give, fcm_csr **A);
/* The same, whose values, when taken from give, keep give's contents (*taken 1; the caller
 * writes every entry: fcm__space_cut_rows()); else zero (*taken 0). (space.c) */
fcm_status fcm__space_matrix_create_rows_keep(const fcm_space *s, fcm_csr *give, fcm_csr **A,
                                              int *taken);
/* fcm__space_matrix_create_rows_from() whose values, when taken from give, are left as give
 * held them (not zeroed; new values are zero). Contract: the caller writes every entry before
 * any read (the Newton matrix: fcm__sim_set_base() writes it whole each step). (space.c) */
fcm_status fcm__space_matrix_create_rows_unzeroed(const fcm_space *s, fcm_csr *give, fcm_csr **A);

/* y (num_dofs) = A x for A of fcm__space_matrix_create_rows() (x: num_dofs); y is zero on the
 * DOFs with no row. A full space: fcm_csr_apply(A, 1, x, 0, y) exactly (same bits). Each row is
 * summed serially (threads over rows): independent of the thread count. No allocation.
 * @return FCM_OK, FCM_ERR_ARG (NULL, x == y, A not of the space's rows). (space.c) */
fcm_status fcm__space_matrix_apply(const fcm_space *s, const fcm_csr *A, const double *x,
                                   double *y);

/* Make a local space's topology that of the cells flagged in `own` (num_cells flags; only
 * active cells count) and of every active cell with an element sharing a DOF copy with an
 * element of a flagged cell (one layer of ghosts, found through the copies: every row of a copy
 * used by an own cell is then the full space's row). A space without rules (plain FEM on the
 * background mesh) keeps a copy of `own` as the cells whose points this process integrates
 * (fcm__space_owns(): the ghosts get none, as the rules' cell mask gives an embedded space's
 * ghosts none). FCM_ERR_ARG for a full space or NULL arguments. Calls fcm__space_set_local_cells()
 * (on its failure the space has no local elements). Allocates O(num_cells + num_dofs/3) flags while
 * it runs. (space.c) */
fcm_status fcm__space_localize(fcm_space *s, const unsigned char *own);

/* FCM_OK when assembling on s gives right (partial) results: a full space, or a local space
 * whose rules were built with a cell mask (fcm__cell_rules_owns()) that flags no active cell
 * outside the local cells (so every element with points is a local element and scatters
 * into rows it has; rules without a mask, or no rules, flag every cell: such a local space
 * passes only when all its active cells are local). Else FCM_ERR_ARG "<what>: ..." naming the
 * first such cell and, without a mask, that the mask is missing. (space.c) */
fcm_status fcm__space_check_assemble(const fcm_space *s, const char *what);

/* Bytes of the space's arrays: the numbering (replicated in a distributed run) and the
 * topology (copy graph, pattern, offsets, colours, local lists). Either may be NULL. The
 * momentum's mass blocks (built on demand) are not counted: fcm__space_mass_cache_bytes(). */
void fcm__space_memory(const fcm_space *s, double *numbering, double *topology);

/* Bytes of the mass blocks fcm_space_momentum() has built (0 before its first call). (eval.c) */
double fcm__space_mass_cache_bytes(const fcm_space *s);

/* Build the mass blocks of fcm_space_momentum() on s (nothing when built already), copying
 * those of the elements with same[e] >= 0 from from's blocks at element same[e]
 * (fcm__space_cut_same_elements(): they integrate alike; every block is integrated when from's
 * are not built). The blocks are then those fcm_space_momentum()'s first call would build, bit
 * for bit. Not thread safe against a concurrent first fcm_space_momentum() on s.
 * @return FCM_OK, FCM_ERR_ARG (NULL, different elements), the errors of the integration,
 * FCM_ERR_ALLOC. (eval.c) */
fcm_status fcm__space_momentum_blocks_from(const fcm_space *s, const fcm_space *from,
                                           const fcm_index *same);

/* Free the mass blocks of fcm_space_momentum() and the cache itself. (eval.c) */
void fcm__space_mass_cache_free(fcm_space *s);

/* The elimination of fcm_space_apply_dirichlet() on a square A (n x n) with the constrained
 * DOFs already marked: con[i] = 1 for a constrained DOF i (n flags) and g[i] its prescribed
 * value (read only where con[i] = 1); b == NULL: the matrix only (g unused). Allocates
 * nothing: the integrator calls it every Newton iteration with its own marks. (space.c) */
void fcm__eliminate_marked(fcm_csr *A, double *b, const unsigned char *con, const double *g);

/* The bodies of the space (fcm_space_num_bodies()): elem_body[e] (num_elems entries) the body
 * of element e, bodies numbered 0 .. *num_bodies - 1 in the order of their first element
 * (elements joined through shared DOF copies; every copy lies in exactly one body). Reads only
 * the numbering (a local space as the full one). Allocates O(num_dofs / 3) scratch.
 * @return FCM_OK, FCM_ERR_ALLOC. (locate.c) */
fcm_status fcm__space_body_labels(const fcm_space *s, fcm_index *elem_body, fcm_index *num_bodies);

/* fcm_space_locate() with a tree over all the mesh's cells (item c: cell c, its box the bounds
 * of its nodes, as fcm_aabb_tree_create() got them), of which the space's active cells are
 * searched: the same cells, xi and flags as fcm_space_locate() (a box query's items come
 * ascending), without its tree over the active cells. The tree is borrowed.
 * @return as fcm_space_locate(); FCM_ERR_ARG for a tree of another count of cells or a
 * space whose elements have other nodes than the mesh's cells. (locate.c) */
fcm_status fcm__space_locate_in(const fcm_space *s, const fcm_aabb_tree *cells, fcm_index n,
                                const double *X, fcm_index *cell, double *xi, int *extrapolated);

/* Physical shape-function gradients g (nn x 3) at a point from the reference ones dN (nn x 3)
 * and the nodal coordinates X (nn x 3); returns det J (not positive: g is not written). */
double fcm__fem_gradients(int nn, const double *X, const double *dN, double *g);

/* ---- creating a space, phase after phase (space.c drives) */

/* The elements: one per material piece of each active cell (cell_elem, elem_cell, elem_piece;
 * one per cell without rules). (numbering.c) */
fcm_status fcm__space_build_elements(fcm_space *s);

/* The elements at each node: CSR over the nodes (*inc_ptr, *inc allocated). (numbering.c) */
fcm_status fcm__space_build_incidence(fcm_space *s, fcm_index **inc_ptr, fcm_index **inc);

/* Sort list[0..n) ascending (a few entries: insertion sort; more: qsort). */
void fcm__space_sort_indices(fcm_index *list, fcm_index n);

/* The copies of each node (generalized enrichment) and elem_dof. (numbering.c) */
fcm_status fcm__space_build_copies(fcm_space *s, const fcm_index *inc_ptr, const fcm_index *inc);

/* Koschier's constraint of the copies whose support is below `ratio` of their node's;
 * renumbers without the unused copies. (numbering.c) */
fcm_status fcm__space_constrain_copies(fcm_space *s, double ratio, const fcm_index *inc_ptr,
                                       const fcm_index *inc);

/* The topology (copy graph, pattern, offsets, colours) of every element (!local) or of the
 * elements of the cells flagged in cell_mask (local); replaces any earlier one.
 * (topology.c) */
fcm_status fcm__space_build_topology(fcm_space *s, int local, const unsigned char *cell_mask);

/* Assembly's blocks of s (block_cells, block_ptr, block_elems) and their colours, the local
 * elements (and, for a local space, local_elem and cell_local) made; with `from` (a full space
 * before the cut of the full space s, NULL otherwise) the cells' order and the colours are taken
 * from it where both have the same active cells and neither constrained copies: the same
 * arrays as built anew. @return FCM_OK, FCM_ERR_ALLOC, FCM_ERR_UNSUPPORTED (colours),
 * FCM_ERR_INTERNAL. (visit.c) */
fcm_status fcm__space_build_blocks(fcm_space *s, const fcm_space *from);

/* fcm__space_build_topology(s, 0, NULL) for a cut space s (full) from `from`, the full space
 * before the cut (s's rules made from from's by fcm_cell_rules_create_cut()): the graph rows
 * of the copies the cut left as they were (same elements, each the only child of its parent)
 * are from's rows mapped to the children, the offsets of their elements from's; the rest and
 * the colours are made as there. The same arrays bit for bit. Anything else (from NULL or
 * local, not a cut pair): fcm__space_build_topology(s, 0, NULL). (topology.c) */
fcm_status fcm__space_build_topology_cut(fcm_space *s, const fcm_space *from, fcm_space *give);

/* The columns block s took from the space before the cut (fcm__space_create_cut_take()) back
 * to that space, its pattern written again (the same bits); nothing when s took none. A
 * failed cut calls it before anything uses the old space's matrices again; destroying s does
 * it too. (topology.c) */
FCM_COMPONENT_API void fcm__space_cut_give_back(fcm_space *s);

/* The cut succeeded: s keeps the columns block it took (the space before the cut has none and
 * is only destroyed). (topology.c) */
FCM_COMPONENT_API void fcm__space_cut_keep(fcm_space *s);

/* Release the topology. (topology.c) */
void fcm__space_free_topology(fcm_space *s);

/* The support of every DOF copy (num_dofs / 3 entries): the summed volume of the pieces
 * (elements) that use it, 1 per element without rules. Used to pick a node's largest copy
 * and to find the tiny copies Koschier's constraint moves. */
void fcm__space_copy_support(const fcm_space *s, double *support);

/* One element's linear term (stiffness, mass, body force or body-force field of `form`):
 * the 3nn x 3nn matrix into Ke (row-major, local DOF 3a + i: node a of the cell, component
 * i) for matrix terms, the 3nn vector into fe for force terms; the other output is not
 * written (either may be NULL). Serial (the workspace's first scratch); allocates only the
 * tabulated standard rule on its first use. For the distributed assembly of the PETSc
 * adapter, which adds the elements of its own cells into a distributed matrix.
 * @return FCM_OK, FCM_ERR_ARG (NULL, element out of range, bad material, rules without the
 * kind), FCM_ERR_UNSUPPORTED (another term), FCM_ERR_GEOMETRY (det J <= 0), FCM_ERR_ALLOC.
 * (assemble.c) */
FCM_COMPONENT_API fcm_status fcm__assembly_element_linear(fcm_assembly_workspace *ws,
                                                          const fcm_linear_form *form,
                                                          fcm_index elem, double *Ke, double *fe);

/* Doubles per element that fcm__assembly_linear_blocks() keeps for `term`: nn (nn + 1) / 2
 * for the mass (its upper node blocks are multiples of the identity), 3 nn for the force
 * terms, 0 for the stiffness (not kept). */
int fcm__assembly_block_size(const fcm_space *s, fcm_linear_term term);

/* fcm__assembly_linear_blocks() summing only the rows (matrix) or entries (vector) of the
 * copies rows flags (NULL: all): the others are left as they are, and an element that uses
 * none of the flagged copies and takes its block from blocks_in only passes it to blocks_out.
 * The flagged rows receive the same terms in the same order as in a whole assembly. (assemble.c) */
fcm_status fcm__assembly_linear_blocks_rows(fcm_assembly_workspace *ws, const fcm_linear_form *form,
                                            fcm_csr *A, double *f, const fcm_index *same,
                                            const double *blocks_in, double *blocks_out,
                                            const unsigned char *rows);

/* fcm_assembly_workspace_linear() (mass, body force, body-force field, surface traction; a full
 * space) keeping element blocks: element e with same[e] >= 0 (same NULL: none) takes its block
 * from blocks_in at element same[e] (blocks of fcm__assembly_block_size() doubles, from an
 * earlier call on a space where that element integrated alike: fcm__space_cut_same_elements())
 * instead of integrating; every element's block goes to blocks_out (may be NULL; num_elems
 * blocks). The blocks are scattered exactly as the kernels' results in the same visiting order:
 * A and f equal fcm_assembly_workspace_linear()'s bit for bit when the kept blocks are.
 * @return as fcm_assembly_workspace_linear(); FCM_ERR_UNSUPPORTED (stiffness, a local space).
 * (assemble.c) */
fcm_status fcm__assembly_linear_blocks(fcm_assembly_workspace *ws, const fcm_linear_form *form,
                                       fcm_csr *A, double *f, const fcm_index *same,
                                       const double *blocks_in, double *blocks_out);

/* The element-corotated linear model (FCM_MATERIAL_COROTATED_LINEAR) keeps each element's linear
 * stiffness matrix in the workspace; after a cut, ws (on the cut space) takes those of the
 * elements with same[e] >= 0 (fcm__space_cut_same_elements()) from old (on the space before
 * the cut) instead of integrating them again at its first hyperelastic assembly. Nothing to
 * take (old has none, another element type): FCM_OK, nothing taken.
 * @return FCM_OK, FCM_ERR_ARG (NULL), FCM_ERR_ALLOC. (corot_store.c) */
fcm_status fcm__assembly_corot_inherit(fcm_assembly_workspace *ws,
                                       const fcm_assembly_workspace *old, const fcm_index *same);

/* The corotated linear model's kept element stiffnesses of ws's elements not built yet, for
 * mat (all of them again for other Lamé parameters), so that the first assembly finds them:
 * what fcm_assembly_workspace_hyperelastic() builds when it meets them first, the same bits.
 * (corot_store.c) */
fcm_status fcm__assembly_corot_build(fcm_assembly_workspace *ws, const fcm_material_params *mat);

/* As fcm__assembly_corot_inherit(), on old's storage where its free slots hold ws's new
 * elements (the store has a quarter more slots than its first elements): each kept element
 * keeps its slot (its matrix is neither moved nor copied), the others take the free slots;
 * old is left without a store (ws has taken it: old's workspace can only be destroyed). Else
 * as fcm__assembly_corot_inherit(), old untouched. (corot_store.c) */
fcm_status fcm__assembly_corot_take(fcm_assembly_workspace *ws, fcm_assembly_workspace *old,
                                    const fcm_index *same);

/* The store ws took from old (fcm__assembly_corot_take()) back to old after a failed cut, none
 * of its matrices counted as built (their slots may hold others'): old builds them again at its
 * next use, the same bits. Nothing taken: nothing done. (corot_store.c) */
void fcm__assembly_corot_give_back(fcm_assembly_workspace *ws, fcm_assembly_workspace *old);

/* The tangent of the corotated linear model's later assemblies through ws: exact = 1 (the
 * default), the energy's exact Hessian unless the material asks for a positive semi-definite
 * one (project_psd); exact = 0, the warped R K R^T either way. (corot_store.c) */
void fcm__assembly_corot_tangent(fcm_assembly_workspace *ws, int exact);

/* The store's free slots mapped (fcm__large_map()): a later cut's new elements write them
 * without the first touch of fresh pages. For a workspace whose store a cut will take. */
void fcm__assembly_corot_map(fcm_assembly_workspace *ws);

/* Element stiffness matrices of the corotated linear model that the hyperelastic assemblies
 * through ws have integrated since its creation (kept ones taken over a cut not counted).
 * (corot_store.c) */
FCM_COMPONENT_API fcm_index fcm__assembly_corot_built(const fcm_assembly_workspace *ws);

/* The authentic quadrature points (fictitious stabilization points of cut cells left out) with
 * J = det F <= 0 in the last hyperelastic assembly through ws
 * (fcm_assembly_workspace_hyperelastic(), any of its outputs), summed over the local elements (a
 * local space: this process's elements); *first_elem (may be NULL): the lowest element holding one,
 * -1 when none. 0 before any hyperelastic assembly. O(local elements), no allocation. (assemble.c)
 */
fcm_index fcm__assembly_inverted(const fcm_assembly_workspace *ws, fcm_index *first_elem);

/* The first authentic point of element elem (in its rule's order) with J = det F <= 0 at the
 * displacement u: its reference position X and J; returns 1, or 0 when it has none (or no
 * hyperelastic assembly ran yet). Serial (the workspace's first scratch); no allocation.
 * (assemble.c) */
int fcm__assembly_inverted_point(fcm_assembly_workspace *ws, fcm_index elem, const double *u,
                                 double X[3], double *det);

/* One process's piece of a parallel frame (.pvtu + one .vtu per process, written atomically):
 * the cells c with keep[c] != 0 (keep NULL: all) with their nodes renumbered, the point fields
 * displacement, velocity (v may be NULL) of the DOF vectors u, v (replicated) and node_index
 * (the mesh's node), the cell fields process (= rank), cell_index (the mesh's cell), active,
 * volume_fraction and, with mat, stress, von_mises, strain_energy_density (computed here:
 * the kept cells must have their points on this process); *nonfinite (may be NULL): the kept
 * cells whose von_mises is NaN or infinite (0 without mat). Not collective. (fields.c) */
fcm_status fcm__space_write_vtu_piece(const fcm_space *s, const fcm_material *mat, const double *u,
                                      const double *v, const unsigned char *keep, int rank,
                                      const char *path, fcm_index *nonfinite);

/* The embedded surface (surface.c and surface_split.c build it, fields.c writes it). Points: the
 * boundary vertices [0, nb), then the vertices of the parts of the boundary triangles the cuts
 * split, then three per cut-face triangle. Triangles: the boundary triangles no cut splits (in
 * their order), the parts of the split ones (fans of their polygons), the cut faces. */
struct fcm_embedded_surface {
  fcm_ctx *ctx;
  const fcm_space *space;
  const fcm_mesh *mesh;     /* of the space (a replaced space may be gone already) */
  const fcm_geometry *geom; /* borrowed: the cuts' pieces are made again from it */
  fcm_index nb, nbt;        /* boundary vertices and triangles (fixed) */
  fcm_index *tri0;          /* nbt x 3: the boundary triangles (vertex ids) */
  fcm_index np, nt;         /* all points and triangles */
  fcm_index num_split;      /* boundary triangles replaced by their parts */
  double *X, *xi;           /* np x 3: reference positions, reference coordinates in the cell */
  fcm_index *cell, *elem, *tri;
  int32_t *flag;
  fcm_index cap_p, cap_t;
  struct fcm__embed_finder *finder; /* during a rebuild with cuts: the cut cells' pieces */
  /* the mesh's cells' boxes (item c: cell c), made when the surface locates its vertices,
   * and a millionth of the mesh's largest extent */
  fcm_aabb_tree *cell_tree;
  double cell_pad;
  /* tests: the rebuild clips no pair ahead (split_triangles() clips every pair it splits) */
  int test_no_preclip;
  /* What the last rebuild with cuts found, for the next one on rules that extend its rules
   * by further cuts (surface_split.c: cells no new cut triangle reaches keep their answers):
   * those rules' cut triangles (copied), pieces per cell (piece_off, num cells + 1), the
   * piece of each boundary vertex in a cell of several pieces (vpiece, nb; -3: not looked
   * up), and the parts of each (cell, triangle) pair clipped (pairs sorted, 2 x npairs;
   * pair k's polygons [poff[k], poff[k + 1]) of polys). */
  struct fcm__cut_tri *prev_tris;
  fcm_index prev_ntris, prev_ncells;
  double prev_rtol[2]; /* the rules' clip_rtol and sliver_rtol */
  fcm_index *prev_piece_off, *vpiece, *pairs;
  unsigned char *cross;        /* nbt: whether a cut triangle of those rules crosses triangle t */
  size_t npairs, *poff, *xoff; /* xoff: pair k's first polygon vertex */
  fcm__embed_polys polys;
  /* 3 per vertex of polys: its reference coordinates in its pair's cell (NaN: not mapped) */
  double *pxi;
  /* The cells each boundary triangle's box meets (the geometry's and mesh's, fixed), found
   * when first needed: triangle t's tc_n[t] cells from tc_ids[tc_first[t]] (tc_first[t] < 0:
   * not yet; NULL: none found yet), tc_len of tc_cap used. */
  fcm_index *tc_first, *tc_ids;
  int *tc_n;
  size_t tc_len, tc_cap;
  /* The last rebuild's cut-face points (cf_np of them, in cell order, room for cf_cap): their
   * cells, reference coordinates and positions (the mesh's element type is the spaces'). */
  fcm_index *cf_cell, cf_np, cf_cap;
  double *cf_xi, *cf_X;
  double *tarea; /* nbt zeros: room to add up each split triangle's parts' area */
};

/* fcm_space_write_vtu() and fcm_embedded_surface_write_vtu() that also count, in *nonfinite
 * (may be NULL), the von_mises values they wrote that are NaN or infinite (cells, surface
 * points; 0 without mat): the stresses of points with J = det F <= 0. (fields.c) */
fcm_status fcm__space_write_vtu_counted(const fcm_space *s, const fcm_material *mat,
                                        const double *u, const double *v, const char *path,
                                        fcm_index *nonfinite);
fcm_status fcm__embedded_surface_write_vtu_counted(const fcm_embedded_surface *es,
                                                   const fcm_material *mat, const double *u,
                                                   const char *path, fcm_index *nonfinite);

/* The mesh nodes of the cells with keep[c] != 0 (keep NULL: all), ascending, each once, in
 * *nodes (allocated with the space's context; free with fcm__free()), their count in *num.
 * O(kept cells) memory. (fields.c) */
FCM_COMPONENT_API fcm_status fcm__space_piece_nodes(const fcm_space *s, const unsigned char *keep,
                                                    fcm_index *num, fcm_index **nodes);

/* dofs[i]: the first DOF fcm_space_node_field() reads at node nodes[i] (-1: an inactive node),
 * for n nodes: the copy of the largest support when a node has several. Allocates the copies'
 * supports (O(DOFs) doubles) when some node has two copies. (fields.c) */
FCM_COMPONENT_API fcm_status fcm__space_node_field_dofs(const fcm_space *s, fcm_index n,
                                                        const fcm_index *nodes, fcm_index *dofs);

/* fcm__space_write_vtu_piece() without stress, from the node values of the piece only: nodes
 * as fcm__space_piece_nodes() lists them for keep, nu / nv 3 values per listed node (the
 * values fcm_space_node_field() would give there; nv NULL: no velocity). The same file as
 * fcm__space_write_vtu_piece() with mat NULL and those values, without any DOF vector.
 * (fields.c) */
FCM_COMPONENT_API fcm_status fcm__space_write_vtu_piece_values(const fcm_space *s,
                                                               const unsigned char *keep,
                                                               fcm_index np, const fcm_index *nodes,
                                                               const double *nu, const double *nv,
                                                               int rank, const char *path);

/* The .pvtu index (written atomically) of the pieces <stem>_0.vtu .. <stem>_<nprocs-1>.vtu that
 * fcm__space_write_vtu_piece() wrote with the same velocity / mat choice. (fields.c) */
FCM_COMPONENT_API fcm_status fcm__write_pvtu(fcm_ctx *ctx, const char *path, const char *stem,
                                             int nprocs, int with_velocity, int with_stress);

/* fcm_space_max_displacement() per cell: the largest |u| over each cell's authentic points
 * (0 for a cell without points). */
fcm_status fcm__space_cell_max_displacement(const fcm_space *s, const double *u, double *cell_max);

#endif /* FCM_FEM_IMPL_H */
