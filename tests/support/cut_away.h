/* Shared by the tests of what a cut keeps (tests/fem, tests/sim): the copies of a cut space
 * away from the cut, found from the cells alone. Reads the space's internals (fem/fem_impl.h). */
#ifndef FCM_TEST_CUT_AWAY_H
#define FCM_TEST_CUT_AWAY_H

#include "fem/fem_impl.h"
#include "test.h"

#include <stdlib.h>

/* The copies of `to` away from the cut from `from` (flags in away, ncopy entries): no element
 * using the copy lies in a cell touching a node of a cell the cut reached (a cell with other
 * elements, or an element integrated otherwise: fcm__space_cut_same_elements()). Found from
 * the cells alone, not from the space's cut_row_from or the integrator's rows. Their count. */
static inline fcm_index cut_away_copies(fcm_ctx *ctx, const fcm_space *from, const fcm_space *to,
                                        unsigned char *away)
{
  const fcm_index *cells = fcm_mesh_cells(to->mesh), ne = to->num_elems, ncopy = to->num_dofs / 3;
  const int nn = to->nn;
  fcm_index *same = malloc(sizeof *same * (size_t)(ne + 1)), count = 0;
  unsigned char *near = calloc((size_t)fcm_mesh_num_nodes(to->mesh) + 1, 1);
  TEST_OK(ctx, fcm__space_cut_same_elements(from, to, same, NULL));
  for (fcm_index k = 0; k < ncopy; k++)
    away[k] = 1;
  for (fcm_index c = 0; c < to->num_cells; c++) {
    int reached =
        to->cell_elem[c + 1] - to->cell_elem[c] != from->cell_elem[c + 1] - from->cell_elem[c];
    for (fcm_index e = to->cell_elem[c]; e < to->cell_elem[c + 1]; e++)
      reached |= same[e] < 0;
    for (int a = 0; a < nn && reached; a++)
      near[cells[c * nn + a]] = 1;
  }
  for (fcm_index e = 0; e < ne; e++) {
    int touch = 0;
    for (int a = 0; a < nn; a++)
      touch |= near[cells[to->elem_cell[e] * nn + a]];
    for (int a = 0; a < nn && touch; a++)
      away[to->elem_dof[e * nn + a] / 3] = 0;
  }
  for (fcm_index k = 0; k < ncopy; k++)
    count += away[k];
  free(same);
  free(near);
  return count;
}

#endif /* FCM_TEST_CUT_AWAY_H */
