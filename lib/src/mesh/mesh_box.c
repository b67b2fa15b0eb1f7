/* Structured box generators (Hex8/Hex20 grids, Tet4/Tet10 Kuhn splits) and the
 * linear-to-quadratic step that adds shared mid-edge nodes. */
#include "mesh_impl.h"

#include <math.h>
#include <string.h>

fcm_status fcm__mesh_add_mid_edge_nodes(fcm_ctx *ctx, fcm_element_type linear_type,
                                        fcm_index num_nodes, const double *coords,
                                        fcm_index num_cells, const fcm_index *cells,
                                        fcm_index *new_num_nodes, double **new_coords,
                                        fcm_index **new_cells)
{
  fcm_status st = FCM_OK;
  fcm_index *slots = NULL, *ends = NULL, *qc = NULL;
  double *qx = NULL;
  size_t cap = 0;
  fcm_element_type qtype = linear_type == FCM_ELEMENT_TET4 ? FCM_ELEMENT_TET10 : FCM_ELEMENT_HEX20;
  FCM_CHECK(linear_type == FCM_ELEMENT_TET4 || linear_type == FCM_ELEMENT_HEX8, ctx, FCM_ERR_ARG,
            "mesh: mid-edge nodes need a tet4 or hex8 mesh, got element type %d", (int)linear_type);
  const fcm_element_info *lin = fcm_element_get_info(linear_type);
  const fcm_element_info *quad = fcm_element_get_info(qtype);
  FCM_CHECK(lin && quad, ctx, FCM_ERR_INTERNAL, "mesh: no element info for %d/%d", (int)linear_type,
            (int)qtype);
  const int nl = lin->num_nodes, nq = quad->num_nodes, ne = quad->num_edges;
  const fcm_index max_edges = num_cells * ne;

  FCM_ALLOC(ctx, num_cells * nq, qc);
  FCM_ALLOC(ctx, 2 * max_edges, ends);
  FCM_TRY(ctx, fcm__mesh_hash_capacity(ctx, max_edges, &cap));
  FCM_ALLOC(ctx, cap, slots);
  for (size_t i = 0; i < cap; i++)
    slots[i] = -1;

  fcm_index num_edges = 0;
  for (fcm_index c = 0; c < num_cells; c++) {
    const fcm_index *lc = cells + (size_t)nl * (size_t)c;
    fcm_index *cq = qc + (size_t)nq * (size_t)c;
    for (int a = 0; a < nl; a++)
      cq[a] = lc[a];
    for (int e = 0; e < ne; e++) {
      fcm_index p = lc[quad->edge_nodes[e][0]], q = lc[quad->edge_nodes[e][1]];
      fcm_index lo = FCM_MIN(p, q), hi = FCM_MAX(p, q);
      size_t h = (size_t)fcm__mesh_mix(fcm__mesh_mix((uint64_t)lo) ^ (uint64_t)hi) & (cap - 1);
      for (;;) {
        fcm_index s = slots[h];
        if (s < 0) {
          s = slots[h] = num_edges++;
          ends[2 * s] = lo;
          ends[2 * s + 1] = hi;
        }
        if (ends[2 * s] == lo && ends[2 * s + 1] == hi) {
          cq[quad->edge_nodes[e][2]] = num_nodes + s;
          break;
        }
        h = (h + 1) & (cap - 1);
      }
    }
  }

  FCM_ALLOC(ctx, 3 * (num_nodes + num_edges), qx);
  if (num_nodes) memcpy(qx, coords, sizeof *qx * 3 * (size_t)num_nodes);
  for (fcm_index s = 0; s < num_edges; s++)
    for (int d = 0; d < 3; d++)
      qx[3 * (num_nodes + s) + d] =
          0.5 * (coords[3 * ends[2 * s] + d] + coords[3 * ends[2 * s + 1] + d]);
  *new_num_nodes = num_nodes + num_edges;
  *new_coords = qx;
  *new_cells = qc;
  qx = NULL;
  qc = NULL;
cleanup:
  fcm__free(ctx, slots);
  fcm__free(ctx, ends);
  fcm__free(ctx, qc);
  fcm__free(ctx, qx);
  return st;
}

fcm_status fcm__mesh_check_grid(fcm_ctx *ctx, const char *who, const double lo[3],
                                const double hi[3], const fcm_index n[3])
{
  fcm_status st = FCM_OK;
  for (int d = 0; d < 3; d++) {
    FCM_CHECK(isfinite(lo[d]) && isfinite(hi[d]) && lo[d] < hi[d], ctx, FCM_ERR_ARG,
              "%s: axis %d: need finite lo < hi, got [%g, %g]", who, d, lo[d], hi[d]);
    FCM_CHECK(n[d] >= 1 && n[d] <= (1 << 20), ctx, FCM_ERR_ARG,
              "%s: axis %d: %lld cells out of range [1, %d]", who, d, (long long)n[d], 1 << 20);
  }
cleanup:
  return st;
}

/* The six Kuhn tetrahedra of the unit cube, as cube corner ids bx + 2 by + 4 bz: for each
 * axis permutation (a, b, c) the path 000 -> e_a -> e_a + e_b -> 111; odd permutations list
 * their two middle vertices swapped so that every tetrahedron is positively oriented. */
static const int kuhn_tets[6][4] = {
    {0, 1, 3, 7}, /* (x, y, z) even */
    {0, 5, 1, 7}, /* (x, z, y) odd */
    {0, 3, 2, 7}, /* (y, x, z) odd */
    {0, 2, 6, 7}, /* (y, z, x) even */
    {0, 4, 5, 7}, /* (z, x, y) even */
    {0, 6, 4, 7}, /* (z, y, x) odd */
};

/* Hexahedron corners in VTK order as cube corner ids. */
static const int hex_corners[8] = {0, 1, 3, 2, 4, 5, 7, 6};

fcm_status fcm_mesh_create_box(fcm_ctx *ctx, fcm_element_type type, const double lo[3],
                               const double hi[3], const fcm_index n[3], fcm_mesh **mesh)
{
  fcm_status st = FCM_OK;
  double *x = NULL, *qx = NULL;
  fcm_index *cells = NULL, *qc = NULL;
  FCM_CHECK(ctx && mesh && lo && hi && n, ctx, FCM_ERR_ARG,
            "mesh_create_box: ctx, lo, hi, n and mesh must not be NULL");
  *mesh = NULL;
  FCM_CHECK(fcm_element_get_info(type), ctx, FCM_ERR_ARG,
            "mesh_create_box: element type %d out of range [0, %d)", (int)type,
            (int)FCM_ELEMENT_COUNT);
  FCM_TRY(ctx, fcm__mesh_check_grid(ctx, "mesh_create_box", lo, hi, n));
  const double total = 6.0 * (double)n[0] * (double)n[1] * (double)n[2];
  FCM_CHECK(total <= 1e12, ctx, FCM_ERR_ARG,
            "mesh_create_box: %lld x %lld x %lld cubes exceed the limit of 1e12 cells",
            (long long)n[0], (long long)n[1], (long long)n[2]);

  const int is_tet = type == FCM_ELEMENT_TET4 || type == FCM_ELEMENT_TET10;
  const fcm_element_type ltype = is_tet ? FCM_ELEMENT_TET4 : FCM_ELEMENT_HEX8;
  const fcm_index p0 = n[0] + 1, p1 = n[1] + 1, p2 = n[2] + 1;
  const fcm_index num_nodes = p0 * p1 * p2;
  const fcm_index num_cubes = n[0] * n[1] * n[2];
  const fcm_index num_cells = is_tet ? 6 * num_cubes : num_cubes;
  const int npc = is_tet ? 4 : 8;

  FCM_ALLOC(ctx, 3 * num_nodes, x);
  for (fcm_index k = 0; k < p2; k++)
    for (fcm_index j = 0; j < p1; j++)
      for (fcm_index i = 0; i < p0; i++) {
        const fcm_index ijk[3] = {i, j, k};
        double *xa = x + 3 * (i + p0 * (j + p1 * k));
        for (int d = 0; d < 3; d++)
          xa[d] = ijk[d] == n[d] ? hi[d] : lo[d] + (hi[d] - lo[d]) * (double)ijk[d] / (double)n[d];
      }

  FCM_ALLOC(ctx, num_cells * npc, cells);
  for (fcm_index k = 0; k < n[2]; k++)
    for (fcm_index j = 0; j < n[1]; j++)
      for (fcm_index i = 0; i < n[0]; i++) {
        fcm_index corner[8];
        for (int b = 0; b < 8; b++)
          corner[b] = (i + (b & 1)) + p0 * ((j + ((b >> 1) & 1)) + p1 * (k + ((b >> 2) & 1)));
        const fcm_index q = i + n[0] * (j + n[1] * k);
        if (is_tet) {
          for (int t = 0; t < 6; t++)
            for (int a = 0; a < 4; a++)
              cells[4 * (6 * q + t) + a] = corner[kuhn_tets[t][a]];
        } else {
          for (int a = 0; a < 8; a++)
            cells[8 * q + a] = corner[hex_corners[a]];
        }
      }

  if (type == ltype) {
    FCM_TRY(ctx, fcm__mesh_create_take(ctx, type, num_nodes, &x, num_cells, &cells, mesh));
  } else {
    fcm_index qn = 0;
    FCM_TRY(ctx, fcm__mesh_add_mid_edge_nodes(ctx, ltype, num_nodes, x, num_cells, cells, &qn, &qx,
                                              &qc));
    FCM_TRY(ctx, fcm__mesh_create_take(ctx, type, qn, &qx, num_cells, &qc, mesh));
  }
cleanup:
  if (ctx) {
    fcm__free(ctx, x);
    fcm__free(ctx, cells);
    fcm__free(ctx, qx);
    fcm__free(ctx, qc);
  }
  return st;
}
