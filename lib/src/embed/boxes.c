/* Boxes and parallelepipeds as affine Hex8 cells of their own: a cut cell's part that is a box
 * of the cell's reference coordinates (a cut along the grid's axes), and the thin prism on a
 * face overlap that is a parallelogram. The surface moments (surface_moments.c) on one such
 * cell replace those on the fan tets of the box or the prism (surface_parts.c). */
#include "embed/embed_impl.h"
#include "element/element_impl.h"
#include "la/mat3.h"

#include <math.h>

/* A part's box in reference coordinates within this fraction of the reference cell's size (2):
 * see fcm__embed_part_box(). */
#define BOX_RTOL 1e-13

fcm_status fcm__embed_part_box(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__poly *p,
                               double lo[3], double hi[3], int *is_box)
{
  fcm_status st = FCM_OK;
  double xi[8][3], det;
  unsigned seen = 0;
  *is_box = 0;
  if (p->nv != 8 || p->nf != 6 || !cell->affine) return FCM_OK;
  for (int d = 0; d < 3; d++)
    lo[d] = HUGE_VAL, hi[d] = -HUGE_VAL;
  for (int a = 0; a < 8; a++) {
    FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, p->x[a], xi[a], &det));
    for (int d = 0; d < 3; d++)
      lo[d] = fmin(lo[d], xi[a][d]), hi[d] = fmax(hi[d], xi[a][d]);
  }
  const double tol = 2.0 * BOX_RTOL;
  for (int d = 0; d < 3; d++)
    if (!(hi[d] - lo[d] > 2.0 * tol)) return FCM_OK;
  for (int a = 0; a < 8; a++) {
    unsigned corner = 0;
    for (int d = 0; d < 3; d++) {
      if (xi[a][d] - lo[d] <= tol) continue;
      if (hi[d] - xi[a][d] > tol) return FCM_OK;
      corner |= 1u << d;
    }
    seen |= 1u << corner;
  }
  if (seen == 0xffu) { /* a flat box keeps its fan tets, which skip flat ones */
    fcm__embed_cell k;
    *is_box = fcm__embed_box_cell(cell, lo, hi, &k);
  }
cleanup:
  return st;
}

/* The affine Hex8 cell k's map (A, X and the box set): its inverse, size and volume; 1, or 0
 * when k is flat. */
static int finish_cell(fcm__embed_cell *k)
{
  k->detA = fcm__mat3_inv(k->A, k->Ainv);
  k->affine = 1;
  k->size = fcm__element_cell_size(8, k->X);
  k->tol = 0.0;
  k->volume = fabs(k->detA) * 8.0;
  return fcm__embed_cell_solid(k);
}

/* The box lo..hi of cell's reference coordinates (cell affine) as an affine Hex8 cell of its
 * own: its reference cube's point eta is cell's c + h eta (c, h: the box's centre and half
 * sides). */
int fcm__embed_box_cell(const fcm__embed_cell *cell, const double lo[3], const double hi[3],
                        fcm__embed_cell *k)
{
  static const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                   {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  double h[3];
  k->type = FCM_ELEMENT_HEX8;
  k->info = fcm_element_get_info(FCM_ELEMENT_HEX8);
  k->id = cell->id;
  k->num_planes = 0;
  for (int d = 0; d < 3; d++)
    h[d] = 0.5 * (hi[d] - lo[d]);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      k->A[3 * i + j] = cell->A[3 * i + j] * h[j];
  for (int d = 0; d < 3; d++) {
    k->xi0[d] = -1.0;
    k->lo[d] = HUGE_VAL, k->hi[d] = -HUGE_VAL;
  }
  for (int a = 0; a < 8; a++) { /* the corners, VTK order */
    const double xi[3] = {corner[a][0] ? hi[0] : lo[0], corner[a][1] ? hi[1] : lo[1],
                          corner[a][2] ? hi[2] : lo[2]};
    const double r[3] = {xi[0] - cell->xi0[0], xi[1] - cell->xi0[1], xi[2] - cell->xi0[2]};
    double *x = k->X + 3 * a;
    fcm__mat3_mulv(cell->A, r, x);
    for (int d = 0; d < 3; d++) {
      x[d] += cell->X[d];
      k->lo[d] = fmin(k->lo[d], x[d]), k->hi[d] = fmax(k->hi[d], x[d]);
    }
  }
  return finish_cell(k);
}

/* The prism of half-height h along the unit normal nrm on the polygon x (n vertices) as one
 * affine Hex8 cell k, when the polygon is a parallelogram (4 vertices, x0 + x2 = x1 + x3 within
 * 1e-12 of its extent) and the prism not flat: then 1; else 0 (its fan's tets instead). */
int fcm__embed_prism_cell(const double *x, int n, const double nrm[3], double h, fcm_index id,
                          fcm__embed_cell *k)
{
  double ext = 0.0;
  if (n != 4) return 0;
  for (int i = 1; i < 4; i++)
    for (int d = 0; d < 3; d++)
      ext = fmax(ext, fabs(x[3 * i + d] - x[d]));
  for (int d = 0; d < 3; d++)
    if (!(fabs(x[d] + x[6 + d] - x[3 + d] - x[9 + d]) <= 1e-12 * ext)) return 0;
  k->type = FCM_ELEMENT_HEX8;
  k->info = fcm_element_get_info(FCM_ELEMENT_HEX8);
  k->id = id;
  k->num_planes = 0;
  for (int d = 0; d < 3; d++) {
    k->A[3 * d] = 0.5 * (x[3 + d] - x[d]);
    k->A[3 * d + 1] = 0.5 * (x[9 + d] - x[d]);
    k->A[3 * d + 2] = h * nrm[d];
    k->xi0[d] = -1.0;
    k->lo[d] = HUGE_VAL, k->hi[d] = -HUGE_VAL;
  }
  for (int a = 0; a < 8; a++) { /* VTK order: the polygon below, then above */
    const double s = a < 4 ? -h : h;
    for (int d = 0; d < 3; d++) {
      const double v = x[3 * (a % 4) + d] + s * nrm[d];
      k->X[3 * a + d] = v;
      k->lo[d] = fmin(k->lo[d], v), k->hi[d] = fmax(k->hi[d], v);
    }
  }
  return finish_cell(k);
}
