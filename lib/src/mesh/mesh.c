/* Background mesh object: creation from arrays (validated, copied or taken over),
 * accessors, face adjacency and boundary faces, node queries, view. */
#include "mesh_impl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

fcm_status fcm__mesh_hash_capacity(fcm_ctx *ctx, fcm_index n, size_t *cap)
{
  fcm_status st = FCM_OK;
  size_t c = 16;
  FCM_CHECK(n >= 0 && (uint64_t)n <= SIZE_MAX / 8, ctx, FCM_ERR_ALLOC,
            "mesh: hash table for %lld entries overflows size_t", (long long)n);
  while (c < 2 * (size_t)n)
    c *= 2;
  *cap = c;
cleanup:
  return st;
}

/* Sorted corner node ids of local face f of cell c; key[3] = -1 for triangles. */
static void face_key(const fcm_element_info *info, const fcm_index *cells, fcm_index c, int f,
                     fcm_index key[4])
{
  int nc = info->face_num_corners[f];
  const fcm_index *cell = cells + (size_t)info->num_nodes * (size_t)c;
  key[3] = -1;
  for (int k = 0; k < nc; k++) {
    fcm_index v = cell[info->face_nodes[f][k]];
    int j = k;
    while (j > 0 && key[j - 1] > v) {
      key[j] = key[j - 1];
      j--;
    }
    key[j] = v;
  }
}

static uint64_t key_hash(const fcm_index key[4])
{
  uint64_t h = 0x9e3779b97f4a7c15ULL;
  for (int k = 0; k < 4; k++)
    h = fcm__mesh_mix(h ^ (uint64_t)key[k]);
  return h;
}

static void format_key(const fcm_index key[4], char *buf, size_t len)
{
  if (key[3] < 0)
    snprintf(buf, len, "%lld %lld %lld", (long long)key[0], (long long)key[1], (long long)key[2]);
  else
    snprintf(buf, len, "%lld %lld %lld %lld", (long long)key[0], (long long)key[1],
             (long long)key[2], (long long)key[3]);
}

/* Faces are matched by their sorted corners in an open-addressing table holding, per
 * distinct key, the first face id (c * num_faces + f), the key hash and the group's
 * last face; a stored face's key is recomputed from the connectivity only when the
 * hashes agree. */
fcm_status fcm__mesh_match_faces(fcm_ctx *ctx, const fcm_element_info *info, const fcm_index *cells,
                                 fcm_index num_cells, fcm_index *first, fcm_index *next)
{
  fcm_status st = FCM_OK;
  fcm_index *slots = NULL, *tails = NULL;
  uint64_t *hashes = NULL;
  const int nf = info->num_faces;
  const fcm_index nfaces = num_cells * nf;
  size_t cap = 0;
  FCM_TRY(ctx, fcm__mesh_hash_capacity(ctx, nfaces, &cap));
  FCM_ALLOC(ctx, cap, slots);
  FCM_ALLOC(ctx, cap, tails);
  FCM_ALLOC(ctx, cap, hashes);
  for (size_t i = 0; i < cap; i++)
    slots[i] = -1;
  for (fcm_index i = 0; i < nfaces; i++) {
    fcm_index key[4], other[4];
    face_key(info, cells, i / nf, (int)(i % nf), key);
    const uint64_t kh = key_hash(key);
    size_t h = (size_t)kh & (cap - 1);
    next[i] = -1;
    for (;;) {
      fcm_index s = slots[h];
      if (s < 0) { /* a new key: i heads its group */
        slots[h] = tails[h] = first[i] = i;
        hashes[h] = kh;
        break;
      }
      if (hashes[h] == kh) face_key(info, cells, s / nf, (int)(s % nf), other);
      if (hashes[h] == kh && memcmp(key, other, sizeof key) == 0) {
        first[i] = s;
        next[tails[h]] = i;
        tails[h] = i;
        break;
      }
      h = (h + 1) & (cap - 1);
    }
  }
cleanup:
  fcm__free(ctx, slots);
  fcm__free(ctx, tails);
  fcm__free(ctx, hashes);
  return st;
}

/* Neighbours across faces (a face met twice) and the boundary faces (met once); a face
 * met a third time is an error naming the three cells. */
static fcm_status build_adjacency(fcm_mesh *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  fcm_index *first = NULL, *next = NULL;
  const int nf = m->info->num_faces;
  const fcm_index nfaces = m->num_cells * nf;

  FCM_ALLOC(ctx, nfaces, m->neighbors);
  FCM_ALLOC(ctx, nfaces, first);
  FCM_ALLOC(ctx, nfaces, next);
  FCM_TRY(ctx, fcm__mesh_match_faces(ctx, m->info, m->cells, m->num_cells, first, next));
  for (fcm_index i = 0; i < nfaces; i++)
    m->neighbors[i] = -1;
  for (fcm_index i = 0; i < nfaces; i++) {
    const fcm_index s = first[i];
    if (s == i) continue;
    if (next[s] != i) { /* the third face of its group */
      fcm_index key[4];
      char buf[96];
      face_key(m->info, m->cells, i / nf, (int)(i % nf), key);
      format_key(key, buf, sizeof buf);
      FCM_CHECK(0, ctx, FCM_ERR_GEOMETRY,
                "mesh: face with corner nodes (%s) is shared by more than two cells "
                "(%lld, %lld, %lld); a conforming mesh has at most two",
                buf, (long long)(s / nf), (long long)(next[s] / nf), (long long)(i / nf));
    }
    m->neighbors[s] = i / nf;
    m->neighbors[i] = s / nf;
  }

  m->num_boundary = 0;
  for (fcm_index i = 0; i < nfaces; i++)
    m->num_boundary += m->neighbors[i] < 0;
  FCM_ALLOC(ctx, 2 * m->num_boundary, m->boundary);
  for (fcm_index i = 0, b = 0; i < nfaces; i++) {
    if (m->neighbors[i] >= 0) continue;
    m->boundary[2 * b] = i / nf;
    m->boundary[2 * b + 1] = i % nf;
    b++;
  }
cleanup:
  fcm__free(ctx, first);
  fcm__free(ctx, next);
  return st;
}

/* Argument and connectivity checks shared by the create functions. */
static fcm_status check_arrays(fcm_ctx *ctx, const fcm_element_info *info, fcm_index num_nodes,
                               const double *coords, fcm_index num_cells, const fcm_index *cells)
{
  fcm_status st = FCM_OK;
  const fcm_index max_n = (fcm_index)(SIZE_MAX / (sizeof(fcm_index) * 2 * FCM_ELEMENT_MAX_NODES));
  FCM_CHECK(num_nodes >= 0 && num_nodes <= max_n, ctx, FCM_ERR_ARG,
            "mesh: num_nodes = %lld out of range [0, %lld]", (long long)num_nodes,
            (long long)max_n);
  FCM_CHECK(num_cells >= 0 && num_cells <= max_n, ctx, FCM_ERR_ARG,
            "mesh: num_cells = %lld out of range [0, %lld]", (long long)num_cells,
            (long long)max_n);
  FCM_CHECK(coords || num_nodes == 0, ctx, FCM_ERR_ARG, "mesh: coords is NULL with %lld nodes",
            (long long)num_nodes);
  FCM_CHECK(cells || num_cells == 0, ctx, FCM_ERR_ARG, "mesh: cells is NULL with %lld cells",
            (long long)num_cells);
  for (fcm_index i = 0; i < 3 * num_nodes; i++)
    FCM_CHECK(fabs(coords[i]) <= FCM__COORD_MAX, ctx, FCM_ERR_ARG,
              "mesh: coordinate %d of node %lld (0-based) is %g, outside " FCM__COORD_RANGE,
              (int)(i % 3), (long long)(i / 3), coords[i]);
  const int npc = info->num_nodes;
  for (fcm_index c = 0; c < num_cells; c++) {
    const fcm_index *cell = cells + (size_t)npc * (size_t)c;
    for (int a = 0; a < npc; a++) {
      FCM_CHECK(cell[a] >= 0 && cell[a] < num_nodes, ctx, FCM_ERR_ARG,
                "mesh: %s cell %lld, local node %d: node id %lld out of range [0, %lld)",
                info->name, (long long)c, a, (long long)cell[a], (long long)num_nodes);
      for (int b = 0; b < a; b++)
        FCM_CHECK(cell[b] != cell[a], ctx, FCM_ERR_ARG,
                  "mesh: %s cell %lld repeats node %lld at local nodes %d and %d; the nodes of "
                  "a cell must be distinct",
                  info->name, (long long)c, (long long)cell[a], b, a);
    }
  }
cleanup:
  return st;
}

fcm_status fcm__mesh_create_take(fcm_ctx *ctx, fcm_element_type type, fcm_index num_nodes,
                                 double **coords, fcm_index num_cells, fcm_index **cells,
                                 fcm_mesh **out)
{
  fcm_status st = FCM_OK;
  fcm_mesh *m = NULL;
  const fcm_element_info *info = fcm_element_get_info(type);
  FCM_CHECK(info, ctx, FCM_ERR_ARG, "mesh: element type %d out of range [0, %d)", (int)type,
            (int)FCM_ELEMENT_COUNT);
  FCM_TRY(ctx, check_arrays(ctx, info, num_nodes, *coords, num_cells, *cells));
  FCM_ALLOC(ctx, 1, m);
  m->ctx = ctx;
  m->type = type;
  m->info = info;
  m->npc = info->num_nodes;
  m->num_nodes = num_nodes;
  m->num_cells = num_cells;
  m->coords = *coords;
  m->cells = *cells;
  *coords = NULL;
  *cells = NULL;
  FCM_TRY(ctx, build_adjacency(m));
  *out = m;
  m = NULL;
cleanup:
  fcm_mesh_destroy(&m);
  FCM_FREE(ctx, *coords);
  FCM_FREE(ctx, *cells);
  return st;
}

fcm_status fcm_mesh_create(fcm_ctx *ctx, fcm_element_type type, fcm_index num_nodes,
                           const double *coords, fcm_index num_cells, const fcm_index *cells,
                           fcm_mesh **mesh)
{
  fcm_status st = FCM_OK;
  double *xc = NULL;
  fcm_index *cc = NULL;
  FCM_CHECK(ctx && mesh, ctx, FCM_ERR_ARG, "mesh: ctx and mesh must not be NULL");
  *mesh = NULL;
  const fcm_element_info *info = fcm_element_get_info(type);
  FCM_CHECK(info, ctx, FCM_ERR_ARG, "mesh: element type %d out of range [0, %d)", (int)type,
            (int)FCM_ELEMENT_COUNT);
  FCM_TRY(ctx, check_arrays(ctx, info, num_nodes, coords, num_cells, cells));
  FCM_ALLOC(ctx, 3 * num_nodes, xc);
  FCM_ALLOC(ctx, num_cells * info->num_nodes, cc);
  if (num_nodes) memcpy(xc, coords, sizeof *xc * 3 * (size_t)num_nodes);
  if (num_cells) memcpy(cc, cells, sizeof *cc * (size_t)info->num_nodes * (size_t)num_cells);
  FCM_TRY(ctx, fcm__mesh_create_take(ctx, type, num_nodes, &xc, num_cells, &cc, mesh));
cleanup:
  if (ctx) {
    fcm__free(ctx, xc);
    fcm__free(ctx, cc);
  }
  return st;
}

void fcm_mesh_destroy(fcm_mesh **mesh)
{
  if (!mesh || !*mesh) return;
  fcm_mesh *m = *mesh;
  fcm_ctx *ctx = m->ctx;
  fcm__free(ctx, m->coords);
  fcm__free(ctx, m->cells);
  fcm__free(ctx, m->neighbors);
  fcm__free(ctx, m->boundary);
  fcm__free(ctx, m->cell_level);
  fcm__free(ctx, m->cell_pos);
  fcm__free(ctx, m->hang_cell);
  fcm__free(ctx, m->hang_node);
  fcm__free(ctx, m->hang_xi);
  fcm__free(ctx, m);
  *mesh = NULL;
}

fcm_element_type fcm_mesh_element_type(const fcm_mesh *mesh)
{
  return mesh->type;
}
const fcm_element_info *fcm_mesh_get_element_info(const fcm_mesh *mesh)
{
  return mesh->info;
}
int fcm_mesh_nodes_per_cell(const fcm_mesh *mesh)
{
  return mesh->npc;
}
fcm_index fcm_mesh_num_nodes(const fcm_mesh *mesh)
{
  return mesh->num_nodes;
}
fcm_index fcm_mesh_num_cells(const fcm_mesh *mesh)
{
  return mesh->num_cells;
}
const double *fcm_mesh_coords(const fcm_mesh *mesh)
{
  return mesh->coords;
}
const fcm_index *fcm_mesh_cells(const fcm_mesh *mesh)
{
  return mesh->cells;
}
const fcm_index *fcm_mesh_neighbors(const fcm_mesh *mesh)
{
  return mesh->neighbors;
}
fcm_index fcm_mesh_num_boundary_faces(const fcm_mesh *mesh)
{
  return mesh->num_boundary;
}
const fcm_index *fcm_mesh_boundary_faces(const fcm_mesh *mesh)
{
  return mesh->boundary;
}

void fcm_mesh_cell_coords(const fcm_mesh *mesh, fcm_index cell, double *X)
{
  const fcm_index *nodes = mesh->cells + (size_t)mesh->npc * (size_t)cell;
  for (int a = 0; a < mesh->npc; a++)
    for (int d = 0; d < 3; d++)
      X[3 * a + d] = mesh->coords[3 * nodes[a] + d];
}

void fcm_mesh_bounding_box(const fcm_mesh *mesh, double lo[3], double hi[3])
{
  for (int d = 0; d < 3; d++) {
    lo[d] = HUGE_VAL;
    hi[d] = -HUGE_VAL;
  }
  for (fcm_index a = 0; a < mesh->num_nodes; a++)
    for (int d = 0; d < 3; d++) {
      lo[d] = FCM_MIN(lo[d], mesh->coords[3 * a + d]);
      hi[d] = FCM_MAX(hi[d], mesh->coords[3 * a + d]);
    }
}

fcm_status fcm_mesh_nodes_in_box(fcm_ctx *ctx, const fcm_mesh *mesh, const double lo[3],
                                 const double hi[3], double tol, fcm_index capacity,
                                 fcm_index *nodes, fcm_index *count)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(mesh && lo && hi && count, ctx, FCM_ERR_ARG,
            "mesh_nodes_in_box: mesh, lo, hi and count must not be NULL");
  FCM_CHECK(capacity >= 0 && (nodes || capacity == 0), ctx, FCM_ERR_ARG,
            "mesh_nodes_in_box: capacity = %lld needs a non-NULL nodes array (capacity >= 0)",
            (long long)capacity);
  FCM_CHECK(tol >= 0 && isfinite(tol), ctx, FCM_ERR_ARG,
            "mesh_nodes_in_box: tol = %g must be finite and >= 0", tol);
  for (int d = 0; d < 3; d++)
    FCM_CHECK(lo[d] <= hi[d], ctx, FCM_ERR_ARG,
              "mesh_nodes_in_box: axis %d: lo = %g > hi = %g (or NaN); need lo <= hi", d, lo[d],
              hi[d]);
  fcm_index n = 0;
  for (fcm_index a = 0; a < mesh->num_nodes; a++) {
    const double *x = mesh->coords + 3 * a;
    int in = 1;
    for (int d = 0; d < 3; d++)
      in &= x[d] >= lo[d] - tol && x[d] <= hi[d] + tol;
    if (!in) continue;
    if (n < capacity) nodes[n] = a;
    n++;
  }
  *count = n;
cleanup:
  return st;
}

void fcm_mesh_view(const fcm_mesh *mesh, FILE *stream)
{
  if (!mesh || !stream) return;
  double lo[3], hi[3];
  fcm_mesh_bounding_box(mesh, lo, hi);
  fprintf(stream, "mesh: %s, %lld nodes, %lld cells, %lld boundary faces\n", mesh->info->name,
          (long long)mesh->num_nodes, (long long)mesh->num_cells, (long long)mesh->num_boundary);
  fprintf(stream, "  bounding box [%g, %g] x [%g, %g] x [%g, %g]\n", lo[0], hi[0], lo[1], hi[1],
          lo[2], hi[2]);
  if (!mesh->cell_level) return;
  fcm_index per_level[FCM_OCTREE_MAX_LEVEL + 1] = {0};
  for (fcm_index c = 0; c < mesh->num_cells; c++)
    per_level[mesh->cell_level[c]]++;
  fprintf(stream, "  octree: %lld hanging (cell, node) pairs; cells per level:",
          (long long)mesh->num_hanging);
  for (int l = 0; l <= mesh->max_level; l++)
    fprintf(stream, " %d: %lld%s", l, (long long)per_level[l], l < mesh->max_level ? "," : "\n");
}
