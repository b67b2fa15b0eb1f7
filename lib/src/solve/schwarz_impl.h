/* The additive Schwarz preconditioner's layout, shared by its files: schwarz.c (creation,
 * set-up, apply) and schwarz_positions.c (where the blocks' entries lie in the matrix's rows,
 * found from its pattern or copied from an earlier smoother's over a renumbering). */
#ifndef FCM_SCHWARZ_IMPL_H
#define FCM_SCHWARZ_IMPL_H

#include "solve/solve_impl.h"

/* Blocks above which the scan of their positions is shared by the threads. */
#define SCAN_PARALLEL_BLOCKS 256

struct fcm_schwarz {
  fcm_ctx *ctx;
  fcm_index n;
  fcm_schwarz_options opts;
  fcm_index num_blocks;
  fcm_index *block_ptr;  /* num_blocks + 1 */
  fcm_index *dofs;       /* block_ptr[num_blocks] */
  size_t *s_off;         /* num_blocks + 1 offsets into S */
  double *S;             /* S_K: m x m each (symmetric); a block smoother's (blocks_only) the
                            lower triangle packed by rows (FCM__SCHWARZ_PACKED) */
  size_t *pos_off;       /* num_blocks + 1 offsets into pos */
  int *pos;              /* m (m + 1) / 2 each, packed by rows (FCM__SCHWARZ_PACKED(i, j),
                            j <= i): where C_K's entry (i, j) lies in C's row dofs[i] (-1:
                            none); the lower triangle is all the gathers read */
  unsigned char *full;   /* num_blocks: every entry of C_K's lower triangle is stored (pos
                            holds them all) */
  unsigned char *factor; /* blocks_only, num_blocks: S's slot holds X = L^{-1} of the Cholesky
                            factor C_K = L L^T (its lower triangle), S_K = X^T X */
  int max_m;
  int num_colors;        /* of the block graph (statistics only; 0 when blocks_only) */
  fcm_index *inc_ptr;    /* n + 1: DOF i is row inc_row[q] of block inc_blk[q], q in range
                            (NULL when blocks_only, as inc_blk, inc_row and dinv) */
  fcm_index *inc_blk;    /* block_ptr[num_blocks], ascending blocks per DOF */
  int *inc_row;          /* block_ptr[num_blocks] */
  unsigned char *inside; /* n: DOF belongs to a block */
  double *dinv;          /* n: 1/|c_ii| outside the blocks, 0 inside */
  fcm_index *diag;       /* n: position of c_ii in C at creation outside the blocks (-1: none) */
  int blocks_only;       /* the block smoother's: the S_K only (no dinv, no apply) */
  fcm_index carried;     /* blocks whose positions were copied from a prior's */
  fcm_schwarz_info info;
  int ready;
  /* Setup scratch, allocated at creation so a setup allocates nothing: per thread (nt of
   * them) a max_m^2 block, max_m eigenvalues and lwork doubles of eigensolver workspace, at
   * least the 2 max_m^2 of the Cholesky path (per_thread doubles in all), liwork ints, and
   * n ints of the gather's DOF map (zero between blocks). */
  int nt;
  size_t per_thread, lwork, liwork;
  size_t scalar_work; /* the per-thread doubles build_block() uses; build_batch()'s after them */
  double *work;
  int *iwork;
  int *loc;
};

/* Every block's positions (pos, full) from C's pattern alone (tri: C's rows' flags
 * FCM__SCHWARZ_ROWS_*, or NULL). */
void fcm__schwarz_scan_positions(fcm_schwarz *P, const fcm_csr *C, const unsigned char *tri);
/* fcm__schwarz_scan_positions(), the positions of the blocks that are pr->old's blocks mapped
 * copied from them (P->carried counts them). */
fcm_status fcm__schwarz_positions_from(fcm_schwarz *P, const fcm_csr *C, const unsigned char *tri,
                                       const fcm__schwarz_prior *pr);

#endif /* FCM_SCHWARZ_IMPL_H */
