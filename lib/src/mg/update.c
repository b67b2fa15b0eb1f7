/* A hierarchy created from an earlier one (fcm__mg_create_from()): what fcm_mg_create() would
 * build again with the same result is taken from the earlier hierarchy instead. Each part is
 * kept only when everything it is computed from is the same, compared entry by entry, so the
 * result is the one fcm_mg_create() gives, bit for bit:
 *
 * - the Galerkin product's plan of level l (the patterns of A_l P_l and of A_{l+1}, R_l), the
 *   pattern of A_{l+1}, its diagonal positions and transposed positions: from the pattern of
 *   A_l, P_l (pattern and weights) and the size of level l + 1;
 * - the SGS row slabs and the colours of level l: from the pattern of A_l;
 * - the block smoother of level l (its blocks, positions and scratch; its values are set up
 *   again) and the blocks' slabs: from the blocks and the pattern of A_l;
 * - the coarsest level's symbolic analysis: from the pattern of its matrix.
 *
 * The cells, copies and prolongations are built anew (a few ms: lib/docs/multigrid.md). */
#include "mg/levels_impl.h"

#include <string.h>

/* Do a and b have the same size and pattern? */
static int same_pattern(const fcm_csr *a, const fcm_csr *b)
{
  if (!a || !b) return 0;
  if (a == b) return 1;
  fcm_index na = 0, ma = 0, za = 0, nb = 0, mb = 0, zb = 0;
  fcm_csr_get_size(a, &na, &ma, &za);
  fcm_csr_get_size(b, &nb, &mb, &zb);
  if (na != nb || ma != mb || za != zb) return 0;
  return memcmp(fcm_csr_row_ptr(a), fcm_csr_row_ptr(b), sizeof(fcm_index) * (size_t)(na + 1)) ==
             0 &&
         memcmp(fcm_csr_col_idx(a), fcm_csr_col_idx(b), sizeof(int) * (size_t)za) == 0;
}

/* Do the levels l of o and m have the same prolongation P_l (rows, columns and weights)? */
static int same_prolongation(const mg_level *O, const mg_level *L)
{
  if (O->n != L->n || !O->P_ptr || !L->P_ptr) return 0;
  const fcm_index nz = L->P_ptr[L->n];
  return O->P_ptr[O->n] == nz &&
         memcmp(O->P_ptr, L->P_ptr, sizeof *L->P_ptr * (size_t)(L->n + 1)) == 0 &&
         memcmp(O->P_col, L->P_col, sizeof *L->P_col * (size_t)nz) == 0 &&
         memcmp(O->P_val, L->P_val, sizeof *L->P_val * (size_t)nz) == 0;
}

int fcm__mg_reuse_allowed(const fcm_mg *old, const fcm_mg *m)
{
  if (!old || old->nt != m->nt || old->oct_mesh[1] || m->oct_mesh[1]) return 0;
  const fcm_mg_options *a = &old->opts, *b = &m->opts;
  return a->smoother == b->smoother && a->omega == b->omega && a->pre_smooth == b->pre_smooth &&
         a->post_smooth == b->post_smooth && a->cycle_index == b->cycle_index &&
         a->max_levels == b->max_levels && a->coarse_dofs == b->coarse_dofs &&
         a->block_smoothing == b->block_smoothing && a->blocks == b->blocks &&
         a->block_fraction == b->block_fraction && a->block_sweep == b->block_sweep &&
         a->point_sweep == b->point_sweep && a->coarse_interval == b->coarse_interval;
}

int fcm__mg_level_same(const fcm_mg *old, const fcm_mg *m, int l)
{
  if (!old || l >= old->nlev) return 0;
  const mg_level *O = &old->lev[l], *L = &m->lev[l];
  if (l == 0 && !O->A) return 0; /* detached: its matrix is gone */
  return O->n == L->n && same_pattern(fcm__mg_level_matrix(O), fcm__mg_level_matrix(L));
}

#define MOVE(dst, src) ((dst) = (src), (src) = NULL)

int fcm__mg_keep_plan(fcm_mg *old, fcm_mg *m, int l)
{
  fcm_ctx *ctx = m->ctx;
  if (l + 1 >= old->nlev || !old->lev[l].ptap) return 0;
  mg_level *O = &old->lev[l], *L = &m->lev[l], *OC = &old->lev[l + 1], *C = &m->lev[l + 1];
  if (OC->n != C->n || !OC->Aown || !same_prolongation(O, L)) return 0;
  /* the plan borrows P_l: the old arrays (the same entries) go with it */
  fcm__free(ctx, L->P_ptr);
  fcm__free(ctx, L->P_col);
  fcm__free(ctx, L->P_val);
  MOVE(L->P_ptr, O->P_ptr);
  MOVE(L->P_col, O->P_col);
  MOVE(L->P_val, O->P_val);
  MOVE(L->ptap, O->ptap);
  L->R_ptr = O->R_ptr, L->R_col = O->R_col, L->R_val = O->R_val;
  O->R_ptr = NULL, O->R_col = NULL, O->R_val = NULL;
  MOVE(C->Aown, OC->Aown);
  MOVE(C->diag, OC->diag);
  MOVE(C->dinv, OC->dinv);
  MOVE(C->tpos, OC->tpos);
  m->kept.plans++;
  return 1;
}

void fcm__mg_keep_orders(fcm_mg *old, fcm_mg *m, int l)
{
  mg_level *O = &old->lev[l], *L = &m->lev[l];
  if (O->color_ptr && !L->color_ptr) {
    MOVE(L->color_ptr, O->color_ptr);
    MOVE(L->color_rows, O->color_rows);
    L->ncolor = O->ncolor;
  }
  if (O->rows.ptr && !L->rows.ptr) {
    L->rows = O->rows;
    memset(&O->rows, 0, sizeof O->rows);
    m->kept.row_orders++;
  }
}

int fcm__mg_keep_analysis(fcm_mg *old, fcm_mg *m, int same_coarsest)
{
  if (!same_coarsest || old->nlev != m->nlev || !old->direct) return 0;
  MOVE(m->direct, old->direct);
  m->kept.analysis = 1;
  return 1;
}

fcm_status fcm__mg_keep_blocks(fcm_mg *old, fcm_mg *m, int l, fcm_index nb, const fcm_index *ptr,
                               const fcm_index *dofs, int *kept)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  *kept = 0;
  mg_level *O = &old->lev[l], *L = &m->lev[l];
  if (!O->blk || !O->blocks.ptr || fcm__schwarz_num_blocks(O->blk) != nb) return FCM_OK;
  for (fcm_index k = 0; k < nb; k++) {
    const fcm_index *d = NULL;
    const double *S = NULL;
    const int bm = fcm__schwarz_block(O->blk, k, &d, &S);
    if (bm != ptr[k + 1] - ptr[k] || memcmp(d, dofs + ptr[k], sizeof *d * (size_t)bm) != 0)
      return FCM_OK;
  }
  MOVE(L->blk, O->blk);
  L->blocks = O->blocks;
  memset(&O->blocks, 0, sizeof O->blocks);
  *kept = 1;
  m->kept.block_smoothers++;
  if (!m->values_pending) FCM_TRY(ctx, fcm_schwarz_setup(L->blk, fcm__mg_level_matrix(L)));
cleanup:
  return st;
}

#undef MOVE

void fcm__mg_detach(fcm_mg *m)
{
  if (!m) return;
  m->lev[0].A = NULL;
  m->space = NULL;
}

void fcm__mg_get_kept(const fcm_mg *m, fcm__mg_kept *kept)
{
  memset(kept, 0, sizeof *kept);
  if (m) *kept = m->kept;
}
