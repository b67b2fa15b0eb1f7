/* A refinement indicator for static runs: the jumps of the element-averaged stress between
 * elements sharing a DOF copy (cells sharing a node where no cut separates them), scaled to
 * the cell, for marking cells of an octree mesh to refine. */
#include "fem_impl.h"

#include <math.h>
#include <string.h>

/* The stress averaged over element e's authentic points: the piece of a cell that cuts split. */
static fcm_status piece_stress(const fcm_space *s, const fcm_material *mat, fcm_index e,
                               const double *u, double sig[6])
{
  int nq = 0;
  const double *pts = NULL, *w = NULL;
  const unsigned char *fl = NULL;
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], vol = 0.0;
  fcm_status st =
      fcm_cell_rules_get_piece(s->rules, s->elem_piece[e], FCM_RULE_STIFFNESS, &nq, &pts, &w, &fl);
  for (int k = 0; k < 6; k++)
    sig[k] = 0.0;
  fcm_mesh_cell_coords(s->mesh, s->elem_cell[e], X);
  for (int q = 0; st == FCM_OK && q < nq; q++) {
    if (fl && fl[q]) continue; /* fictitious stabilization points: not the body */
    double sq[6];
    const double wd = w[q] * fabs(fcm_element_jacobian(s->type, X, pts + 3 * q, J));
    st = fcm_space_element_stress(s, mat, e, pts + 3 * q, u, sq, NULL, NULL);
    for (int k = 0; k < 6; k++)
      sig[k] += wd * sq[k];
    vol += wd;
  }
  for (int k = 0; k < 6; k++)
    sig[k] = vol > 0.0 ? sig[k] / vol : 0.0;
  return st;
}

fcm_status fcm_space_stress_jumps(const fcm_space *s, const fcm_material *mat, const double *u,
                                  double *eta)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  double *sig = NULL, *esig = NULL, *range = NULL;
  FCM_CHECK(s && mat && u && eta, ctx, FCM_ERR_ARG,
            "stress_jumps: space, mat, u and eta must not be NULL");
  /* Averages per element (a cut cell's pieces apart) and ranges per DOF copy: elements on the
   * two sides of a cut share no copy, so the stress jump across a crack face, which the
   * enrichment resolves, marks nothing. Without cuts elements are cells and copies nodes. */
  const fcm_index nc = s->num_cells, ne = s->num_elems, nr = s->num_dofs / 3;
  const int npc = s->nn;
  FCM_ALLOC_RAW(ctx, 6 * FCM_MAX(nc, 1), sig);
  FCM_ALLOC_RAW(ctx, 6 * FCM_MAX(ne, 1), esig);
  FCM_ALLOC_RAW(ctx, 12 * FCM_MAX(nr, 1), range);
  FCM_TRY(ctx, fcm_space_cell_stress(s, mat, u, sig, NULL, NULL));
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index c = s->elem_cell[e];
    if (s->cell_elem[c + 1] - s->cell_elem[c] == 1)
      memcpy(esig + 6 * e, sig + 6 * c, 6 * sizeof *sig);
    else
      FCM_TRY(ctx, piece_stress(s, mat, e, u, esig + 6 * e));
  }
  /* per copy and stress component, the smallest and largest average of its elements */
  for (fcm_index r = 0; r < nr; r++)
    for (int k = 0; k < 6; k++)
      range[12 * r + k] = HUGE_VAL, range[12 * r + 6 + k] = -HUGE_VAL;
  for (fcm_index e = 0; e < ne; e++)
    for (int i = 0; i < npc; i++) {
      const fcm_index r = s->elem_dof[(size_t)npc * e + i] / 3;
      if (r < 0 || r >= nr) continue;
      double *g = range + 12 * r;
      for (int k = 0; k < 6; k++)
        g[k] = fmin(g[k], esig[6 * e + k]), g[6 + k] = fmax(g[6 + k], esig[6 * e + k]);
    }
  /* the cell's volume from det J at its reference centroid (exact for affine cells) */
  const fcm_shape shape = fcm_mesh_get_element_info(s->mesh)->shape;
  const double hex_centre[3] = {0.0, 0.0, 0.0}, tet_centre[3] = {0.25, 0.25, 0.25};
  const double *xc = shape == FCM_SHAPE_HEX ? hex_centre : tet_centre;
  for (fcm_index c = 0; c < nc; c++) {
    eta[c] = 0.0;
    if (!s->active[c]) continue;
    double jump = 0.0, X[3 * FCM_ELEMENT_MAX_NODES], J[9];
    for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++)
      for (int i = 0; i < npc; i++) {
        const fcm_index r = s->elem_dof[(size_t)npc * e + i] / 3;
        if (r < 0 || r >= nr) continue;
        for (int k = 0; k < 6; k++)
          jump = fmax(jump, range[12 * r + 6 + k] - range[12 * r + k]);
      }
    fcm_mesh_cell_coords(s->mesh, c, X);
    const double vol = fcm_shape_measure(shape) * fabs(fcm_element_jacobian(s->type, X, xc, J));
    eta[c] = sqrt(vol) * jump;
  }
cleanup:
  if (ctx) {
    fcm__free(ctx, sig);
    fcm__free(ctx, esig);
    fcm__free(ctx, range);
  }
  return st;
}
