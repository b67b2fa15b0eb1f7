/* The Galerkin product's plan (ptap.c) shared with the plans taken over from a prior one
 * (ptap_carry.c). */
#ifndef FCM_LA_PTAP_IMPL_H
#define FCM_LA_PTAP_IMPL_H

#include "la/la_impl.h"

struct fcm__ptap {
  fcm_ctx *ctx;
  fcm_index n, nc; /* A is n x n, P n x nc */
  int nt;          /* the most threads fcm__ptap_apply() may use */
  const fcm_index *P_ptr;
  const int *P_col;
  const double *P_val;
  fcm_index *R_ptr; /* R = P^T (nc x n), rows ascending in their columns */
  int *R_col;
  double *R_val;
  fcm_index *AP_ptr; /* A P (n x nc) */
  int *AP_col;
  double *AP_val;
  double *spa;           /* nt dense accumulators of 3 (nc + 1) doubles, zero between products */
  unsigned char *same3;  /* per group g of A's rows 3 g .. 3 g + 2: one pattern (all three) */
  unsigned char *r_kind; /* per group of R's rows: KIND_SHIFTED or KIND_ROWS */
};

/* How a group of three rows of A is multiplied (product_values()). */
enum { KIND_ROWS = 0, KIND_TRIPLE = 1, KIND_SHIFTED = 2 };

/* Sort a[0 .. n) ascending (distinct values). */
void fcm__ptap_sort_ints(int *a, fcm_index n);
/* R = P^T: row J of R lists the rows i of P with a column J, ascending. */
fcm_status fcm__ptap_transpose_pattern(fcm_ctx *ctx, fcm_index n, fcm_index nc,
                                       const fcm_index *P_ptr, const int *P_col,
                                       const double *P_val, fcm_index **R_ptr, int **R_col,
                                       double **R_val);
/* Pattern of C = A B (nrow rows of A, ncol columns of B), each row's columns sorted when
 * `sorted`, else in the order first reached (A's row order, then B's; the same for any thread
 * count); dup (NULL: none) flags the rows whose pattern is the row before's (A's rows and the
 * rows of B they reach giving the same columns in the same order), which are copied instead
 * of computed; bnode (NULL: none) the nodes whose rows of B are shifted per component, the
 * rows of C found a node at a time recorded in `closed` (NULL: not recorded; nrow bytes);
 * bclosed (NULL: none) such rows of B. `guess`: the entries of C expected (0: A's and a
 * quarter), the threads' first buffers. *Cp_out, *Cc_out new arrays. */
fcm_status fcm__ptap_product_pattern(fcm_ctx *ctx, int nt, fcm_index nrow, const fcm_index *Ap,
                                     const int *Ac, const fcm_index *Bp, const int *Bc,
                                     fcm_index ncol, int sorted, const unsigned char *dup,
                                     const unsigned char *bnode, unsigned char *closed,
                                     const unsigned char *bclosed, fcm_index guess,
                                     fcm_index **Cp_out, int **Cc_out);
/* The missing diagonal entries inserted into a square pattern with sorted rows. */
fcm_status fcm__ptap_add_diagonal(fcm_ctx *ctx, fcm_index n, fcm_index **ptr, int **col);
/* Whether rows i, i + 1, i + 2 hold one pattern. */
int fcm__ptap_same_pattern3(fcm_index i, const fcm_index *Ap, const int *Ac);
/* Whether rows i .. i + 2 of A may be multiplied as one row shifted (ptap.c says when). */
int fcm__ptap_shifted3(fcm_index i, const fcm_index *Ap, const int *Ac, const double *Av,
                       const unsigned char *b_same3);

/* A plan's start: A square, P's columns in [0, nc), R = P^T, same3 allocated (unset); `who`
 * names the caller in the messages. */
fcm_status fcm__ptap_begin(fcm_ctx *ctx, const fcm_csr *A, fcm_index nc, const fcm_index *P_ptr,
                           const int *P_col, const double *P_val, int nt, const char *who,
                           fcm__ptap **plan);
/* A plan's end from C's pattern (cp, cc; adopted by *C on success) and A P's groups of one
 * pattern ap3: the diagonal added when asked, the accumulators and R's row kinds. */
fcm_status fcm__ptap_finish(fcm__ptap *t, const fcm_csr *A, const unsigned char *ap3,
                            int with_diagonal, fcm_index **cp, int **cc, fcm_csr **C);

#endif
