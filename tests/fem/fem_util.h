/* Shared helpers of the fem tests: meshes with distorted interiors, a direct
 * solve of A u = b, and the linear elastic material used throughout. */
#ifndef FCM_TEST_FEM_UTIL_H
#define FCM_TEST_FEM_UTIL_H

#include "fcm/fcm.h"
#include "test.h"

/* Deterministic uniform random number in [-1, 1). */
static inline double urand(unsigned long long *s)
{
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 4503599627370496.0 - 1.0;
}

/* Box mesh of `type` on [0,1]^3 with n^3 cells; with `amp` > 0 the interior
 * corner nodes are moved by up to amp * h in each direction and the mid-edge
 * nodes are put back on the midpoints of their (straight) edges. */
static inline fcm_status distorted_box(fcm_ctx *ctx, fcm_element_type type, fcm_index n, double amp,
                                       fcm_mesh **out)
{
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  fcm_index cells[3] = {n, n, n};
  fcm_mesh *box = NULL;
  fcm_status st = fcm_mesh_create_box(ctx, type, lo, hi, cells, &box);
  if (st != FCM_OK || amp <= 0.0) {
    *out = box;
    return st;
  }
  fcm_index nn = fcm_mesh_num_nodes(box), nc = fcm_mesh_num_cells(box);
  const fcm_element_info *info = fcm_mesh_get_element_info(box);
  int npc = info->num_nodes;
  double *X = malloc(sizeof *X * 3 * (size_t)nn);
  unsigned char *corner = calloc((size_t)nn, 1);
  memcpy(X, fcm_mesh_coords(box), sizeof *X * 3 * (size_t)nn);
  const fcm_index *cn = fcm_mesh_cells(box);
  for (fcm_index c = 0; c < nc; c++)
    for (int a = 0; a < info->num_corners; a++)
      corner[cn[c * npc + a]] = 1;
  unsigned long long seed = 12345;
  double h = 1.0 / (double)n;
  for (fcm_index i = 0; i < nn; i++) {
    int interior = 1;
    for (int d = 0; d < 3; d++)
      if (X[3 * i + d] < 1e-12 || X[3 * i + d] > 1 - 1e-12) interior = 0;
    if (interior && corner[i])
      for (int d = 0; d < 3; d++)
        X[3 * i + d] += amp * h * urand(&seed);
  }
  if (info->order == 2)
    for (fcm_index c = 0; c < nc; c++)
      for (int e = 0; e < info->num_edges; e++) {
        const int *en = info->edge_nodes[e];
        for (int d = 0; d < 3; d++)
          X[3 * cn[c * npc + en[2]] + d] =
              0.5 * (X[3 * cn[c * npc + en[0]] + d] + X[3 * cn[c * npc + en[1]] + d]);
      }
  st = fcm_mesh_create(ctx, type, nn, X, nc, cn, out);
  free(X);
  free(corner);
  fcm_mesh_destroy(&box);
  return st;
}

/* Solve A u = b with CHOLMOD. */
static inline fcm_status direct_solve(fcm_ctx *ctx, fcm_csr *A, const double *b, double *u)
{
  fcm_direct *solver = NULL;
  fcm_status st = fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &solver);
  if (st == FCM_OK) st = fcm_direct_analyze(solver);
  if (st == FCM_OK) st = fcm_direct_factor(solver, fcm_csr_values(A));
  if (st == FCM_OK) st = fcm_direct_solve(solver, b, u);
  fcm_direct_destroy(&solver);
  return st;
}

#endif
