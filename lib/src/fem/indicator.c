/* A refinement indicator for static runs: the jumps of the cell-averaged stress between cells
 * sharing a node, scaled to the cell, for marking cells of an octree mesh to refine. */
#include "fem_impl.h"

#include <math.h>

fcm_status fcm_space_stress_jumps(const fcm_space *s, const fcm_material *mat, const double *u,
                                  double *eta)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  double *sig = NULL, *range = NULL;
  FCM_CHECK(s && mat && u && eta, ctx, FCM_ERR_ARG,
            "stress_jumps: space, mat, u and eta must not be NULL");
  const fcm_index nc = s->num_cells, nn = s->num_nodes;
  const int npc = s->nn;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  FCM_ALLOC_RAW(ctx, 6 * FCM_MAX(nc, 1), sig);
  FCM_ALLOC_RAW(ctx, 12 * FCM_MAX(nn, 1), range);
  FCM_TRY(ctx, fcm_space_cell_stress(s, mat, u, sig, NULL, NULL));
  /* per node and stress component, the smallest and largest average of its active cells */
  for (fcm_index a = 0; a < nn; a++)
    for (int k = 0; k < 6; k++)
      range[12 * a + k] = HUGE_VAL, range[12 * a + 6 + k] = -HUGE_VAL;
  for (fcm_index c = 0; c < nc; c++) {
    if (!s->active[c]) continue;
    for (int i = 0; i < npc; i++) {
      double *r = range + 12 * cells[(size_t)npc * c + i];
      for (int k = 0; k < 6; k++)
        r[k] = fmin(r[k], sig[6 * c + k]), r[6 + k] = fmax(r[6 + k], sig[6 * c + k]);
    }
  }
  /* the cell's volume from det J at its reference centroid (exact for affine cells) */
  const fcm_shape shape = fcm_mesh_get_element_info(s->mesh)->shape;
  const double hex_centre[3] = {0.0, 0.0, 0.0}, tet_centre[3] = {0.25, 0.25, 0.25};
  const double *xc = shape == FCM_SHAPE_HEX ? hex_centre : tet_centre;
  for (fcm_index c = 0; c < nc; c++) {
    eta[c] = 0.0;
    if (!s->active[c]) continue;
    double jump = 0.0, X[3 * FCM_ELEMENT_MAX_NODES], J[9];
    for (int i = 0; i < npc; i++) {
      const double *r = range + 12 * cells[(size_t)npc * c + i];
      for (int k = 0; k < 6; k++)
        jump = fmax(jump, r[6 + k] - r[k]);
    }
    fcm_mesh_cell_coords(s->mesh, c, X);
    const double vol = fcm_shape_measure(shape) * fabs(fcm_element_jacobian(s->type, X, xc, J));
    eta[c] = sqrt(vol) * jump;
  }
cleanup:
  if (ctx) {
    fcm__free(ctx, sig);
    fcm__free(ctx, range);
  }
  return st;
}
