/* Shared by the cutting tests: the unit cube as a background of 5 positively oriented Tet4
 * cells, or of n^3 Hex8 cells, and the 10 planes of Ton-That et al. 2024, Fig. 5 (5 normal to
 * x, 5 normal to y) that dice it into 36 sticks, added to cell rules one cut at a time. */
#ifndef FCM_TEST_DICE_H
#define FCM_TEST_DICE_H

#include "fcm/fcm.h"

#include <string.h>

/* "tet5": the cube of 5 tets; "hex1", "hex8": 1 or 2 x 2 x 2 hexes. */
static inline fcm_status dice_mesh(fcm_ctx *ctx, const char *what, fcm_mesh **mesh)
{
  static const double cube[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  static const fcm_index five[5][4] = {
      {0, 1, 3, 4}, {1, 2, 3, 6}, {1, 4, 5, 6}, {3, 4, 6, 7}, {1, 3, 4, 6}};
  if (strcmp(what, "tet5")) {
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const fcm_index n = strcmp(what, "hex1") ? 2 : 1, cells[3] = {n, n, n};
    return fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, mesh);
  }
  fcm_index cells[20];
  for (int t = 0; t < 5; t++) { /* orient positively */
    const double *a = cube[five[t][0]], *b = cube[five[t][1]], *c = cube[five[t][2]],
                 *d = cube[five[t][3]];
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++)
      u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = d[k] - a[k];
    const double det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                       u[2] * (v[0] * w[1] - v[1] * w[0]);
    for (int k = 0; k < 4; k++)
      cells[4 * t + k] = five[t][k];
    if (det < 0) cells[4 * t + 1] = five[t][2], cells[4 * t + 2] = five[t][1];
  }
  return fcm_mesh_create(ctx, FCM_ELEMENT_TET4, 8, &cube[0][0], 5, cells, mesh);
}

/* Replace *rules by the rules after the 10 dicing cuts (on failure *rules is NULL). */
static inline fcm_status dice_cuts(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *g,
                                   fcm_cell_rules **rules)
{
  static const double at[5] = {0.13, 0.31, 0.5, 0.67, 0.86};
  const double bl[3] = {-0.1, -0.1, -0.1}, bh[3] = {1.1, 1.1, 1.1};
  fcm_status st = FCM_OK;
  for (int k = 0; k < 10 && st == FCM_OK; k++) {
    double p[3] = {0.5, 0.5, 0.5}, nrm[3] = {0, 0, 0};
    p[k / 5] = at[k % 5];
    nrm[k / 5] = 1.0;
    fcm_surface *s = NULL;
    fcm_cell_rules *next = NULL;
    st = fcm_surface_create_plane(ctx, p, nrm, bl, bh, &s);
    if (st == FCM_OK) st = fcm_cell_rules_create_cut(ctx, mesh, g, *rules, s, &next);
    fcm_surface_destroy(&s);
    fcm_cell_rules_destroy(rules);
    *rules = next;
  }
  return st;
}

#endif
