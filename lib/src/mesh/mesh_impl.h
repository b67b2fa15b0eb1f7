/* fcm mesh, internal part: the mesh struct and helpers shared by the mesh
 * sources (generators and readers hand over arrays they allocated). */
#ifndef FCM_MESH_IMPL_H
#define FCM_MESH_IMPL_H

#include "core/core_impl.h"
#include "fcm/mesh.h"

#include <stdint.h>

struct fcm_mesh {
  fcm_ctx *ctx;
  fcm_element_type type;
  const fcm_element_info *info;
  int npc; /* nodes per cell */
  fcm_index num_nodes;
  fcm_index num_cells;
  double *coords;       /* num_nodes x 3 */
  fcm_index *cells;     /* num_cells x npc */
  fcm_index *neighbors; /* num_cells x info->num_faces, -1 on the boundary */
  fcm_index num_boundary;
  fcm_index *boundary; /* num_boundary x 2: (cell, local face) */
  /* Octree meshes (mesh_octree.c); NULL / 0 for every other mesh. */
  unsigned char *cell_level; /* num_cells: refinement level of each cell */
  int64_t *cell_pos;         /* num_cells x 3: position on the lattice of its level */
  double box_lo[3], box_hi[3];
  fcm_index box_n[3];    /* the box grid the octree refines */
  int max_level;         /* deepest level */
  fcm_index num_hanging; /* (cell, node) pairs: node on cell's boundary, not its node */
  fcm_index *hang_cell, *hang_node;
  double *hang_xi; /* num_hanging x 3: the node's reference coordinates in the cell (exact) */
};

/* Create a mesh that takes ownership of `*coords` and `*cells` (allocated with
 * fcm__calloc on ctx): on return, success or failure, both are NULL (freed on
 * failure). Validates like fcm_mesh_create(). */
fcm_status fcm__mesh_create_take(fcm_ctx *ctx, fcm_element_type type, fcm_index num_nodes,
                                 double **coords, fcm_index num_cells, fcm_index **cells,
                                 fcm_mesh **mesh);

/* Turn a linear mesh (Tet4 or Hex8 arrays) into its quadratic version (Tet10 or
 * Hex20): one new node at the midpoint of every edge, shared between cells, numbered
 * after the existing nodes in the order the edges are first met. Allocates
 * *new_coords and *new_cells on ctx; the inputs are not modified. */
fcm_status fcm__mesh_add_mid_edge_nodes(fcm_ctx *ctx, fcm_element_type linear_type,
                                        fcm_index num_nodes, const double *coords,
                                        fcm_index num_cells, const fcm_index *cells,
                                        fcm_index *new_num_nodes, double **new_coords,
                                        fcm_index **new_cells);

/* The box grid arguments of the structured generators: per axis finite lo < hi and
 * 1 <= n <= 2^20 cells; FCM_ERR_ARG naming `who` and the axis otherwise. (mesh_box.c) */
fcm_status fcm__mesh_check_grid(fcm_ctx *ctx, const char *who, const double lo[3],
                                const double hi[3], const fcm_index n[3]);

/* Group the faces of `num_cells` cells of type `info` (connectivity `cells`, num_nodes
 * ids per cell) by their corner node sets: the one face matcher of the library (mesh
 * adjacency, geometry boundary). Faces are numbered c * num_faces + f; for each face i,
 * first[i] is the lowest face id of its group and next[i] the next higher one, or -1.
 * A face with first[i] == i and next[i] == -1 is met once: a boundary face. `first` and
 * `next` hold num_cells * num_faces entries. Allocates a hash table of O(faces). */
fcm_status fcm__mesh_match_faces(fcm_ctx *ctx, const fcm_element_info *info, const fcm_index *cells,
                                 fcm_index num_cells, fcm_index *first, fcm_index *next);

/* Smallest power of two >= 2n (at least 16): capacity of an open-addressing table. */
fcm_status fcm__mesh_hash_capacity(fcm_ctx *ctx, fcm_index n, size_t *cap);

/* 64-bit mixing (splitmix64 finalizer) for the hash tables. */
static inline uint64_t fcm__mesh_mix(uint64_t h)
{
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebULL;
  h ^= h >> 31;
  return h;
}

#endif /* FCM_MESH_IMPL_H */
