/* fem: DOF blocks of flagged cells (the cut-cell blocks of the additive Schwarz
 * preconditioner are built here, above the solvers, which only see DOF lists). */
#include "fem/fem_impl.h"

fcm_status fcm_space_cell_blocks(const fcm_space *space, const unsigned char *cell_flag,
                                 fcm_index *num_blocks, fcm_index *num_dofs, fcm_index *block_ptr,
                                 fcm_index *block_dofs)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = space ? space->ctx : NULL;
  FCM_CHECK(space && cell_flag && num_blocks && num_dofs, ctx, FCM_ERR_ARG,
            "space_cell_blocks: space, cell_flag, num_blocks or num_dofs is NULL");
  FCM_CHECK(!block_ptr == !block_dofs, ctx, FCM_ERR_ARG,
            "space_cell_blocks: give both block_ptr and block_dofs, or neither (counts only)");
  const int npc = space->nn;
  fcm_index nb = 0, nd = 0;
  for (fcm_index c = 0; c < space->num_cells; c++) {
    if (!cell_flag[c]) continue;
    FCM_CHECK(space->active[c], ctx, FCM_ERR_ARG,
              "space_cell_blocks: cell %lld is flagged but inactive (it has no DOFs)",
              (long long)c);
    for (fcm_index e = space->cell_elem[c]; e < space->cell_elem[c + 1]; e++) {
      if (block_ptr) block_ptr[nb] = nd;
      const fcm_index *ed = space->elem_dof + e * npc;
      for (int a = 0; a < npc; a++) {
        int dup = 0; /* a constrained tiny copy: the element uses another node's copy */
        for (int b = 0; b < a && !dup; b++)
          dup = ed[b] == ed[a];
        for (int i = 0; !dup && i < 3; i++, nd++)
          if (block_dofs) block_dofs[nd] = ed[a] + i;
      }
      nb++;
    }
  }
  if (block_ptr) block_ptr[nb] = nd;
  *num_blocks = nb;
  *num_dofs = nd;
cleanup:
  return st;
}
