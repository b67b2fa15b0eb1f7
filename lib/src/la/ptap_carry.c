/* A Galerkin plan's rows taken over from a prior plan through a cut's renumbering
 * (fcm__ptap_create_from()): only the rows the cut changed are computed. */
#include "la/ptap_impl.h"

#include <stdlib.h>
#include <string.h>

/* What the rows taken over read: the prior, the new A and P, the old plan. */
typedef struct carry_work {
  const fcm__ptap_prior *pr;
  const fcm__ptap *old;
  const fcm_index *Ap, *Pp, *Rp, *APp, *Cp;
  const int *Ac, *Pc, *Rc, *APc;
  int *Cc;
  unsigned char *prow, *keep, *ckeep; /* rows of P, A P and C that are the old ones mapped */
  unsigned char *csame;               /* rows of C taken in the old order (NULL: not wanted) */
  const unsigned char *same3;         /* the new plan's */
  unsigned char *cdup;                /* per group of C's rows: R's rows shifted (their rows of
                                         A P of one pattern): one pattern before the diagonal */
  unsigned char *pnode;               /* per node of P's rows: shifted per component */
  fcm_index n, nc;
} carry_work;

/* Is row i of P the old row mapped (the same positions)? */
static int carry_prow(const carry_work *w, fcm_index i)
{
  const fcm_index io = w->pr->row_old[i];
  if (io < 0) return 0;
  const fcm_index *op = w->old->P_ptr, len = w->Pp[i + 1] - w->Pp[i];
  if (op[io + 1] - op[io] != len) return 0;
  const int *oc = w->old->P_col + op[io], *nc = w->Pc + w->Pp[i];
  for (fcm_index q = 0; q < len; q++)
    if (nc[q] != w->pr->crow_new[oc[q]]) return 0;
  return 1;
}

/* CSR-row mode (A_col set): is row i of A the old row mapped, reaching only rows of P that
 * are (prow)? */
static int carry_arow(const carry_work *w, fcm_index i)
{
  const fcm__ptap_prior *pr = w->pr;
  const fcm_index io = pr->row_old[i], p0 = w->Ap[i], len = w->Ap[i + 1] - p0;
  if (io < 0 || pr->A_ptr[io + 1] - pr->A_ptr[io] != len) return 0;
  const int *ac = w->Ac + p0, *oc = pr->A_col + pr->A_ptr[io];
  for (fcm_index q = 0; q < len; q++)
    if (ac[q] != pr->row_new[oc[q]] || !w->prow[ac[q]]) return 0;
  return 1;
}

/* Copy-graph mode (A_col NULL): are copy k's three rows of A the old copy's rows mapped (the
 * prior's copy_same: its graph rows compared by the caller), reaching only rows of P that are
 * (prow)? */
static int carry_acopy(const carry_work *w, fcm_index k)
{
  const fcm__ptap_prior *pr = w->pr;
  if (!pr->copy_same[k]) return 0;
  for (fcm_index q = pr->G_ptr[k]; q < pr->G_ptr[k + 1]; q++) {
    const fcm_index j = pr->G_adj[q];
    if (!w->prow[3 * j] || !w->prow[3 * j + 1] || !w->prow[3 * j + 2]) return 0;
  }
  return 1;
}

/* Is row I of C the old row mapped: its row of R the old one mapped, every row of A P it
 * reaches taken over (keep)? */
static int carry_crow(const carry_work *w, fcm_index I)
{
  const fcm__ptap_prior *pr = w->pr;
  const fcm_index Io = pr->crow_old[I], len = w->Rp[I + 1] - w->Rp[I];
  if (Io < 0 || w->old->R_ptr[Io + 1] - w->old->R_ptr[Io] != len) return 0;
  const int *oc = w->old->R_col + w->old->R_ptr[Io], *rc = w->Rc + w->Rp[I];
  for (fcm_index q = 0; q < len; q++)
    if (rc[q] != pr->row_new[oc[q]] || !w->keep[rc[q]]) return 0;
  return 1;
}

/* Row I of C taken over: the old row mapped, sorted; 1 when the mapping kept the order. */
static int carry_c_taken(const carry_work *w, fcm_index I, int *out)
{
  const fcm_index Io = w->pr->crow_old[I], *op = fcm_csr_row_ptr(w->pr->C);
  const int *oc = fcm_csr_col_idx(w->pr->C) + op[Io];
  const fcm_index len = op[Io + 1] - op[Io];
  int sorted = 1;
  for (fcm_index q = 0; q < len; q++) {
    out[q] = (int)w->pr->crow_new[oc[q]];
    sorted &= q == 0 || out[q] > out[q - 1];
  }
  if (!sorted) fcm__ptap_sort_ints(out, len);
  return sorted;
}

/* Is row i of A P (stage 0) or of C (stage 1) the row before's columns: A P's rows of a node
 * of one pattern in A, C's rows of R's shifted rows (computed ones, before their diagonal)? */
static int carry_dup(const carry_work *w, int stage, fcm_index i)
{
  if (i % 3 == 0) return 0;
  return stage ? w->cdup[i / 3] && !w->ckeep[i] && !w->ckeep[i - 1] : w->same3[i / 3];
}

/* The rows of A P (stage 0) or of C (stage 1): which are taken over (keep), and their columns
 * into *ptr, *col (new arrays): the rows taken mapped, the rows repeating the row before
 * copied, the others computed together by fcm__ptap_product_pattern() (the plain product's
 * rows: columns first reached, X's row order, then Y's; C's sorted, their diagonal added
 * afterwards as fcm__ptap_create() adds it) by nt threads. */
static fcm_status carry_rows(fcm_ctx *ctx, carry_work *w, int stage, int nt, fcm_index **ptr_out,
                             int **col_out)
{
  fcm_status st = FCM_OK;
  const fcm_index nrow = stage ? w->nc : w->n;
  const fcm_index *Xp = stage ? w->Rp : w->Ap, *Yp = stage ? w->APp : w->Pp;
  const int *Xc = stage ? w->Rc : w->Ac, *Yc = stage ? w->APc : w->Pc;
  unsigned char *keep = stage ? w->ckeep : w->keep;
  fcm_index *ptr = NULL, *from = NULL, *sp = NULL, *cp = NULL, nsub = 0, nx = 0, guess = 0;
  int *col = NULL, *sc = NULL, *cc = NULL;
#pragma omp parallel for num_threads(nt) schedule(dynamic, 255) if (nt > 1 && nrow > 4096)
  for (fcm_index i = 0; i < nrow; i++) /* chunks of whole nodes: row 3 k first */
    keep[i] = (unsigned char)(stage          ? carry_crow(w, i)
                              : w->pr->A_col ? carry_arow(w, i)
                              : i % 3 == 0   ? i + 2 < nrow && carry_acopy(w, i / 3)
                                             : keep[i - 1]);
  /* the rows computed, as the rows of a matrix of X's rows */
  FCM_ALLOC_RAW(ctx, nrow + 1, from); /* every entry written below */
  for (fcm_index i = 0; i < nrow; i++) {
    from[i] = -1;
    if (keep[i] || carry_dup(w, stage, i)) continue;
    from[i] = nsub++;
    nx += Xp[i + 1] - Xp[i];
  }
  {
    /* their entries expected: the old rows' mean and a quarter (the threads' first buffers) */
    const fcm_index *op = stage ? fcm_csr_row_ptr(w->pr->C) : w->old->AP_ptr;
    const fcm_index on = stage ? w->old->nc : w->old->n;
    guess = on > 0 ? 5 * (op[on] / on + 1) * nsub / 4 : 0;
  }
  FCM_ALLOC(ctx, nsub + 1, sp);
  FCM_ALLOC_RAW(ctx, nx + 1, sc); /* every entry written below */
  for (fcm_index i = 0, s = 0; i < nrow; i++) {
    if (from[i] < 0) continue;
    const fcm_index len = Xp[i + 1] - Xp[i];
    memcpy(sc + sp[s], Xc + Xp[i], sizeof *sc * (size_t)len);
    sp[s + 1] = sp[s] + len;
    s++;
  }
  FCM_TRY(ctx, fcm__ptap_product_pattern(ctx, nt, nsub, sp, sc, Yp, Yc, w->nc, stage, NULL,
                                         stage ? NULL : w->pnode, NULL, NULL, guess, &cp, &cc));
  FCM_ALLOC_RAW(ctx, nrow + 1, ptr); /* every entry written below */
  ptr[0] = 0;
  for (fcm_index i = 0; i < nrow; i++) {
    fcm_index len = 0;
    if (from[i] >= 0) {
      len = cp[from[i] + 1] - cp[from[i]];
    } else if (carry_dup(w, stage, i)) {
      len = ptr[i] - ptr[i - 1];
    } else if (stage) {
      const fcm_index *op = fcm_csr_row_ptr(w->pr->C), io = w->pr->crow_old[i];
      len = op[io + 1] - op[io];
    } else {
      const fcm_index *op = w->old->AP_ptr, io = w->pr->row_old[i];
      len = op[io + 1] - op[io];
    }
    ptr[i + 1] = ptr[i] + len;
  }
  FCM_ALLOC_RAW(ctx, ptr[nrow] + 1, col); /* every entry written below */
#pragma omp parallel for num_threads(nt) schedule(dynamic, 255) if (nt > 1 && nrow > 4096)
  for (fcm_index i = 0; i < nrow; i++) { /* the row before in the same chunk */
    int *out = col + ptr[i];
    const fcm_index len = ptr[i + 1] - ptr[i];
    if (from[i] >= 0) {
      memcpy(out, cc + cp[from[i]], sizeof *out * (size_t)len);
    } else if (carry_dup(w, stage, i)) {
      memcpy(out, col + ptr[i - 1], sizeof *out * (size_t)len);
    } else if (stage) {
      const int sorted = carry_c_taken(w, i, out);
      if (w->csame) w->csame[i] = (unsigned char)sorted;
    } else {
      const fcm_index *op = w->old->AP_ptr;
      const int *oc = w->old->AP_col + op[w->pr->row_old[i]];
      const fcm_index *cn = w->pr->crow_new;
      for (fcm_index q = 0; q < len; q++)
        out[q] = (int)cn[oc[q]];
    }
  }
  *ptr_out = ptr, *col_out = col;
  ptr = NULL, col = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, col);
  fcm__free(ctx, from);
  fcm__free(ctx, sp);
  fcm__free(ctx, sc);
  fcm__free(ctx, cp);
  fcm__free(ctx, cc);
  return st;
}

fcm_status fcm__ptap_create_from(fcm_ctx *ctx, const fcm__ptap_prior *prior, const fcm_csr *A,
                                 fcm_index nc, const fcm_index *P_ptr, const int *P_col,
                                 const double *P_val, int with_diagonal, int nt, fcm__ptap **plan,
                                 fcm_csr **C, fcm_index taken[2], unsigned char **c_same)
{
  fcm_status st = FCM_OK;
  fcm__ptap *t = NULL;
  fcm_index *cp = NULL;
  int *cc = NULL;
  unsigned char *ap3 = NULL;
  carry_work w = {.pr = prior, .nc = nc};
  FCM_CHECK(ctx && prior && A && P_ptr && P_ptr[0] == 0 && plan && C && nc >= 0 && nt >= 1, ctx,
            FCM_ERR_ARG,
            "ptap_create_from: NULL argument, P_ptr[0] != 0, nc = %lld < 0 or nt = %d < 1",
            (long long)nc, nt);
  {
    const char *missing = !prior->plan                     ? "plan"
                          : !prior->C                      ? "C"
                          : !prior->A_ptr                  ? "A_ptr"
                          : !prior->A_col && !prior->A_adj ? "A_col or A_adj"
                          : !prior->A_col && (!prior->G_ptr || !prior->G_adj || !prior->copy_same)
                              ? "G_ptr / G_adj / copy_same"
                          : !prior->row_old || !prior->row_new   ? "row_old / row_new"
                          : !prior->crow_old || !prior->crow_new ? "crow_old / crow_new"
                                                                 : NULL;
    FCM_CHECK(!missing, ctx, FCM_ERR_ARG, "ptap_create_from: the prior's %s is NULL", missing);
  }
  *plan = NULL, *C = NULL;
  if (c_same) {
    *c_same = NULL;
    FCM_ALLOC(ctx, nc + 1, w.csame);
  }
  FCM_TRY(ctx, fcm__ptap_begin(ctx, A, nc, P_ptr, P_col, P_val, nt, "ptap_create_from", &t));
  const fcm_index n = t->n;
  w.old = prior->plan, w.n = n;
  w.Ap = fcm_csr_row_ptr(A), w.Ac = fcm_csr_col_idx(A), w.Pp = P_ptr, w.Pc = P_col;
  w.Rp = t->R_ptr, w.Rc = t->R_col;
  FCM_ALLOC(ctx, n + 1, w.prow);
  FCM_ALLOC(ctx, n + 1, w.keep);
  FCM_ALLOC(ctx, nc + 1, w.ckeep);
  FCM_ALLOC(ctx, n / 3 + 1, w.pnode);
  w.same3 = t->same3;
#pragma omp parallel num_threads(nt) if (nt > 1 && n > 4096)
  {
    /* copy-graph mode: A's pattern is the copy graph G (the prior's precondition, which the
     * caller guarantees: fcm__mg_create_pattern_cut() checks that A has its space's pattern),
     * so a copy's three rows hold one pattern */
#pragma omp for schedule(static) nowait
    for (fcm_index g = 0; g < n / 3; g++) {
      t->same3[g] = (unsigned char)(!prior->A_col || fcm__ptap_same_pattern3(3 * g, w.Ap, w.Ac));
      w.pnode[g] = (unsigned char)fcm__ptap_shifted3(3 * g, P_ptr, P_col, NULL, NULL);
    }
#pragma omp for schedule(static)
    for (fcm_index i = 0; i < n; i++)
      w.prow[i] = (unsigned char)carry_prow(&w, i);
  }
  FCM_TRY(ctx, carry_rows(ctx, &w, 0, nt, &t->AP_ptr, &t->AP_col));
  FCM__ALLOC_WITH(fcm__malloc_large, ctx, t->AP_ptr[n] + 1, t->AP_val); /* as in ptap.c */
  FCM_ALLOC(ctx, n / 3 + 1, ap3);
#pragma omp parallel for num_threads(nt) schedule(static) if (nt > 1 && n > 4096)
  for (fcm_index g = 0; g < n / 3; g++)
    ap3[g] = (unsigned char)(t->same3[g] || fcm__ptap_same_pattern3(3 * g, t->AP_ptr, t->AP_col));
  w.APp = t->AP_ptr, w.APc = t->AP_col;
  FCM_ALLOC(ctx, nc / 3 + 1, w.cdup);
  for (fcm_index g = 0; 3 * g + 2 < nc; g++)
    w.cdup[g] = (unsigned char)fcm__ptap_shifted3(3 * g, t->R_ptr, t->R_col, NULL, ap3);
  FCM_TRY(ctx, carry_rows(ctx, &w, 1, nt, &cp, &cc));
  /* the rows taken hold theirs (the prior's plan was made with the same with_diagonal) */
  FCM_TRY(ctx, fcm__ptap_finish(t, A, ap3, with_diagonal, &cp, &cc, C));
  if (taken) {
    taken[0] = taken[1] = 0;
    for (fcm_index i = 0; i < n; i++)
      taken[0] += w.keep[i];
    for (fcm_index I = 0; I < nc; I++)
      taken[1] += w.ckeep[I];
  }
  *plan = t;
  t = NULL;
  if (c_same) *c_same = w.csame, w.csame = NULL;
cleanup:
  fcm__free(ctx, w.csame);
  fcm__free(ctx, cp);
  fcm__free(ctx, cc);
  fcm__free(ctx, w.pnode);
  fcm__free(ctx, ap3);
  fcm__free(ctx, w.prow);
  fcm__free(ctx, w.keep);
  fcm__free(ctx, w.ckeep);
  fcm__free(ctx, w.cdup);
  fcm__ptap_destroy(&t);
  return st;
}
