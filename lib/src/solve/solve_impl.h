/* solve module internals: what the Krylov, Jacobi and Schwarz files share.
 * Not installed. */
#ifndef FCM_SOLVE_IMPL_H
#define FCM_SOLVE_IMPL_H

#include "core/core_impl.h"
#include "fcm/solve.h"
#include "la/la_impl.h"

/* Rows (or blocks) below this count are processed by one thread. */
#define FCM__SOLVE_PARALLEL_MIN 4096

/* Blocks of an additive Schwarz preconditioner, for smoothers that sweep them one after the
 * other (mg): the number of blocks, and block k's size m, its DOFs and its S_K (symmetric),
 * valid after a successful setup: dense m x m, row major, or for a block smoother
 * (fcm__schwarz_create_blocks()) its lower triangle packed by rows, entry (i, j), j <= i, at
 * FCM__SCHWARZ_PACKED(i, j) (m (m + 1) / 2 doubles: a sweep reads each cache line of the slot,
 * and the slots of a level take half the memory). fcm__schwarz_slot_size(): the doubles of
 * block k's slot. */
#define FCM__SCHWARZ_PACKED(i, j) ((size_t)(i) * ((size_t)(i) + 1) / 2 + (size_t)(j))
fcm_index fcm__schwarz_num_blocks(const fcm_schwarz *P);
/* fcm_schwarz_setup() on a matrix whose pattern is the one of P's last set-up (the same
 * row_ptr and col_idx contents; only the values changed), as the multigrid's levels have
 * between creations: the blocks' entries are taken through the positions found before
 * without reading C's columns again. The same result as fcm_schwarz_setup(). */
fcm_status fcm__schwarz_setup_known(fcm_schwarz *P, const fcm_csr *C);
int fcm__schwarz_block(const fcm_schwarz *P, fcm_index k, const fcm_index **dofs, const double **S);
size_t fcm__schwarz_slot_size(const fcm_schwarz *P, fcm_index k);
/* 1 when block k of a block smoother (fcm__schwarz_create_blocks()) holds, in S's place, the
 * inverse X = L^{-1} of the Cholesky factor C_K = L L^T (its lower triangle, packed), so that
 * S_K = X^T X; 0 when it holds S_K (its lower triangle, packed). */
int fcm__schwarz_block_factor(const fcm_schwarz *P, fcm_index k);
/* The same blocks as arrays, for sweeps that read them in their inner loop: block k's DOFs are
 * dofs[ptr[k] .. ptr[k + 1]), its slot (as fcm__schwarz_block()'s) starts at S + s_off[k]. The
 * arrays stay in place for the life of P (setups rewrite S's values only). */
typedef struct fcm__schwarz_view {
  const fcm_index *ptr, *dofs;
  const size_t *s_off;
  const double *S;
  const unsigned char *factor; /* per block, fcm__schwarz_block_factor() (NULL: all 0) */
} fcm__schwarz_view;
void fcm__schwarz_get_view(const fcm_schwarz *P, fcm__schwarz_view *v);
/* fcm_schwarz_create() for a block smoother: a setup computes the S_K, nothing else (no
 * diagonal outside the blocks); fcm_schwarz_apply() refuses it. */
fcm_status fcm__schwarz_create_blocks(fcm_ctx *ctx, const fcm_csr *C, fcm_index num_blocks,
                                      const fcm_index *block_ptr, const fcm_index *block_dofs,
                                      fcm_schwarz **out);
/* What fcm__schwarz_create_blocks_pattern() may copy positions from: an earlier block
 * smoother `old` (of fcm__schwarz_create_blocks*(), its positions found) on a matrix before a
 * renumbering; row_old: per row of the new matrix its row in old's (-1: none); same: per node
 * k of the new matrix, 1 when its rows 3 k, 3 k + 1, 3 k + 2 are their old rows mapped, column
 * for column in the same order. A block whose DOFs are an old block's mapped one by one, and
 * whose rows are all such, takes that block's positions (the ones a scan finds). */
typedef struct fcm__schwarz_prior {
  const fcm_schwarz *old;
  const fcm_index *row_old;
  const unsigned char *same;
} fcm__schwarz_prior;

/* fcm__schwarz_create_blocks() without its set-up: C's pattern alone is read (the blocks'
 * positions in C's rows are found from it, or copied from prior's: NULL for none); the first
 * fcm_schwarz_setup() sets up the values, with the bits the creation's set-up gives.
 * row_triple (NULL: found from C): per row 3 k, FCM__SCHWARZ_ROWS_SAME when rows 3 k,
 * 3 k + 1, 3 k + 2 hold one pattern, FCM__SCHWARZ_ROWS_NODES when its columns come in whole
 * nodes too (3 G, 3 G + 1, 3 G + 2 one after the other), 0 otherwise (a shortcut not taken:
 * the positions are the same). */
#define FCM__SCHWARZ_ROWS_SAME  1
#define FCM__SCHWARZ_ROWS_NODES 2
fcm_status fcm__schwarz_create_blocks_pattern(fcm_ctx *ctx, const fcm_csr *C, fcm_index num_blocks,
                                              const fcm_index *block_ptr,
                                              const fcm_index *block_dofs,
                                              const unsigned char *row_triple,
                                              const fcm__schwarz_prior *prior, fcm_schwarz **out);
/* The blocks whose positions were copied from the prior's at creation. */
fcm_index fcm__schwarz_carried(const fcm_schwarz *P);
/* 1 when a and b hold the same blocks with the same positions and full flags (both found,
 * no setup since: a setup may scan a block again), else 0. For the tests. */
int fcm__schwarz_same_positions(const fcm_schwarz *a, const fcm_schwarz *b);
/* The positions of P's blocks (*count of them), writable: for the tests' controls. */
int *fcm__schwarz_positions(fcm_schwarz *P, size_t *count);

#endif /* FCM_SOLVE_IMPL_H */
