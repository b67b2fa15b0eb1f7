/* fem module internals: the space layout shared by space.c, assemble.c and locate.c
 * (immutable after fcm_space_create). */
#ifndef FCM_FEM_IMPL_H
#define FCM_FEM_IMPL_H

#include "core/core_impl.h"
#include "fcm/fem.h"

struct fcm_space {
  fcm_ctx *ctx;
  const fcm_mesh *mesh;
  fcm_element_type type;
  int nn; /* nodes per cell */
  fcm_index num_cells;
  fcm_index num_nodes;
  unsigned char *active; /* num_cells */
  fcm_index *node_dof;   /* num_nodes: first DOF or -1 */
  fcm_index num_dofs;
  /* Node graph of active nodes (by active rank): node_ptr[k]..node_ptr[k+1] are
   * the ranks of the nodes sharing a cell with node k (itself included), sorted. */
  fcm_index *node_ptr;
  fcm_index *node_adj;
  /* Scalar CSR pattern: the three rows of node k each hold 3 columns per neighbour. */
  fcm_index *row_ptr; /* num_dofs + 1 */
  int *col_idx;
  /* Per cell, nn x nn offsets: the position of neighbour b in node a's row of the node
   * graph, so entry (3ka+i, 3kb+j) lives at row_ptr[3ka+i] + 3 off[a][b] + j. */
  int *cell_off;
  /* Cells grouped by colour: color_ptr[c]..color_ptr[c+1] index color_cells. */
  int num_colors;
  fcm_index *color_ptr;
  fcm_index *color_cells;
  /* Embedded case: per-cell rules of cut cells (borrowed) and the most points any cut
   * cell has in either rule. Nothing here changes after creation: assembly scratch lives
   * in fcm_assembly_workspace (assemble.c). */
  const fcm_cell_rules *rules;
  int max_cut_points;
};

/* The elimination of fcm_space_apply_dirichlet() on a square A (n x n) with the constrained
 * DOFs already marked: con[i] = 1 for a constrained DOF i (n flags) and g[i] its prescribed
 * value (read only where con[i] = 1); b == NULL: the matrix only (g unused). Allocates
 * nothing: the integrator calls it every Newton iteration with its own marks. (space.c) */
void fcm__eliminate_marked(fcm_csr *A, double *b, const unsigned char *con, const double *g);

#endif /* FCM_FEM_IMPL_H */
