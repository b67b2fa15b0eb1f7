/* The multigrid's prolongations: Hex20's p-level (serendipity mid-edge nodes from their edge's
 * ends) and the per-component trilinear prolongation between grid levels (restriction = P^T,
 * held by the Galerkin product). */
#include "mg/levels_impl.h"

#include <stdlib.h>
#include <string.h>

/* P (F->n x ncoarse) from per-row lists of (column, weight) pairs, at most `width` per row
 * (column -1: none). */
static fcm_status transfer_from_rows(fcm_ctx *ctx, mg_level *F, int width, const fcm_index *col,
                                     const double *w)
{
  fcm_status st = FCM_OK;
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
cleanup:
  return st;
}

fcm_status fcm__mg_p_prolongation(fcm_ctx *ctx, const fcm_space *sp, mg_level *L0,
                                  const mg_level *L, const fcm_index *cmap,
                                  const fcm_index *copy_node)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *mesh = fcm_space_mesh(sp);
  const fcm_element_info *info = fcm_element_get_info(fcm_mesh_element_type(mesh));
  const fcm_index *cells = fcm_mesh_cells(mesh), nk = L0->ncopy;
  const int npc = info->num_nodes;
  fcm_index *pcol = NULL;
  double *pw = NULL;
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
  FCM_TRY(ctx, transfer_from_rows(ctx, L0, 2, pcol, pw));
cleanup:
  fcm__free(ctx, pcol);
  fcm__free(ctx, pw);
  return st;
}

fcm_status fcm__mg_scalar_prolongation(fcm_ctx *ctx, const mg_level *F, const mg_level *C,
                                       const fcm_index *cptr, const fcm_index *cusers,
                                       fcm_index **scal_ptr, fcm_index **scal_col, double **scal_w)
{
  fcm_status st = FCM_OK;
  const fcm_index nk = F->ncopy;
  FCM_ALLOC(ctx, nk + 1, *scal_ptr);
  FCM_ALLOC_RAW(ctx, 8 * nk + 1, *scal_col); /* read up to scal_ptr[nk], written below */
  FCM_ALLOC_RAW(ctx, 8 * nk + 1, *scal_w);
  fcm_index *sp = *scal_ptr, *sc = *scal_col;
  double *sw = *scal_w;
  for (fcm_index k = 0; k < nk; k++) {
    fcm_index cnt = sp[k];
    if (cptr[k + 1] > cptr[k]) {
      const fcm_index c0 = cusers[cptr[k]];
      /* the weights along each axis of the corner bit 0 (node 2 q) and 1 (node 2 q + 2) */
      double along[3][2];
      for (int d = 0; d < 3; d++)
        for (int t = 0; t < 2; t++) {
          const fcm_index off = F->copy_ijk[3 * k + d] - 2 * (C->ijk[3 * c0 + d] + t);
          along[d][t] = off == 0 ? 1.0 : (off == -1 || off == 1) ? 0.5 : 0.0;
        }
      for (int b = 0; b < 8; b++) {
        const double w = 1.0 * along[0][b & 1] * along[1][b >> 1 & 1] * along[2][b >> 2 & 1];
        if (w == 0.0) continue;
        sc[cnt] = C->corner[8 * c0 + b];
        sw[cnt++] = w;
      }
    }
    sp[k + 1] = cnt;
  }
cleanup:
  return st;
}

fcm_status fcm__mg_dof_prolongation(fcm_ctx *ctx, mg_level *F, const mg_level *C,
                                    const fcm_index *scal_ptr, const fcm_index *scal_col,
                                    const double *scal_w)
{
  fcm_status st = FCM_OK;
  FCM_ALLOC(ctx, F->n + 1, F->P_ptr);
  /* rows of P are filled copy by copy, which is row order for rows f ascending with k:
   * level 0 rows are 3k + c; coarse rows are numbered copy by copy too */
  for (int pass = 0; pass < 2; pass++) {
    fcm_index cnt = 0;
    for (fcm_index k = 0; k < F->ncopy; k++)
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
      FCM_ALLOC_RAW(ctx, F->P_ptr[F->n] + 1, F->P_col); /* every entry written by pass 1 */
      FCM_ALLOC_RAW(ctx, F->P_ptr[F->n] + 1, F->P_val);
    }
  }
cleanup:
  return st;
}
