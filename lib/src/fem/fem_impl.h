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
  fcm_index *node_dof;   /* num_nodes: first DOF of the node's first copy, or -1 */
  fcm_index *node_ncopy; /* num_nodes: copies of the node (0 inactive, 1, or more when cuts
                            separate its support: generalized enrichment, XFEM) */
  fcm_index num_dofs;    /* 3 x copies; a node's copies have consecutive DOFs */
  /* Elements: the material pieces of the active cells (one per cell without cuts), in cell
   * order: element e lies in cell elem_cell[e], integrates with the rules of piece
   * elem_piece[e] (-1: standard rule) and has the DOFs elem_dof[nn e + a] .. + 2 at its
   * local node a (the copy of that node whose support component holds the piece). Cell c
   * has elements [cell_elem[c], cell_elem[c + 1]). */
  fcm_index num_elems;
  fcm_index *elem_cell, *elem_piece, *elem_dof, *cell_elem;
  fcm_index num_constrained; /* copies constrained to move with their piece (Koschier) */
  /* Copy graph (by copy rank k = DOF / 3): node_ptr[k]..node_ptr[k+1] are the ranks of the
   * copies sharing an element with copy k (itself included), sorted. */
  fcm_index *node_ptr;
  fcm_index *node_adj;
  /* Scalar CSR pattern: the three rows of node k each hold 3 columns per neighbour. */
  fcm_index *row_ptr; /* num_dofs + 1 */
  int *col_idx;
  /* Per element, nn x nn offsets: the position of copy b in copy a's row of the copy
   * graph, so entry (3ka+i, 3kb+j) lives at row_ptr[3ka+i] + 3 off[a][b] + j. */
  int *elem_off;
  /* Elements grouped by colour (no two share a copy): color_ptr[c]..color_ptr[c+1] index
   * color_elems. */
  int num_colors;
  fcm_index *color_ptr;
  fcm_index *color_elems;
  /* Embedded case: per-cell rules of cut cells (borrowed) and the most points any cut
   * cell has in either rule. Nothing here changes after creation: assembly scratch lives
   * in fcm_assembly_workspace (assemble.c). */
  const fcm_cell_rules *rules;
  int max_cut_points;
  fcm_rule *mass_rule; /* the standard mass rule of full cells (fcm_space_momentum()) */
};

/* The elimination of fcm_space_apply_dirichlet() on a square A (n x n) with the constrained
 * DOFs already marked: con[i] = 1 for a constrained DOF i (n flags) and g[i] its prescribed
 * value (read only where con[i] = 1); b == NULL: the matrix only (g unused). Allocates
 * nothing: the integrator calls it every Newton iteration with its own marks. (space.c) */
void fcm__eliminate_marked(fcm_csr *A, double *b, const unsigned char *con, const double *g);

/* Physical shape-function gradients g (nn x 3) at a point from the reference ones dN (nn x 3)
 * and the nodal coordinates X (nn x 3); returns det J (not positive: g is not written). */
double fcm__fem_gradients(int nn, const double *X, const double *dN, double *g);

/* The support of every DOF copy (num_dofs / 3 entries): the summed volume of the pieces
 * (elements) that use it, 1 per element without rules. Used to pick a node's largest copy
 * and to find the tiny copies Koschier's constraint moves. */
void fcm__space_copy_support(const fcm_space *s, double *support);

/* One element's linear term (stiffness, mass, body force or body-force field of `form`):
 * the 3nn x 3nn matrix into Ke (row-major, local DOF 3a + i: node a of the cell, component
 * i) for matrix terms, the 3nn vector into fe for force terms; the other output is not
 * written (either may be NULL). Serial (the workspace's first scratch); allocates only the
 * tabulated standard rule on its first use. For the distributed assembly of the PETSc
 * adapter, which adds the elements of its own cells into a distributed matrix.
 * @return FCM_OK, FCM_ERR_ARG (NULL, element out of range, bad material, rules without the
 * kind), FCM_ERR_UNSUPPORTED (another term), FCM_ERR_GEOMETRY (det J <= 0), FCM_ERR_ALLOC.
 * (assemble.c) */
fcm_status fcm__assembly_element_linear(fcm_assembly_workspace *ws, const fcm_linear_form *form,
                                        fcm_index elem, double *Ke, double *fe);

/* One process's piece of a parallel frame (.pvtu + one .vtu per process, written atomically):
 * the cells c with keep[c] != 0 (keep NULL: all) with their nodes renumbered, the point fields
 * displacement, velocity (v may be NULL) of the DOF vectors u, v (replicated) and node_index
 * (the mesh's node), the cell fields process (= rank), cell_index (the mesh's cell), active,
 * volume_fraction and, with mat, stress, von_mises, strain_energy_density (computed here:
 * the kept cells must have their points on this process). Not collective. (fields.c) */
fcm_status fcm__space_write_vtu_piece(const fcm_space *s, const fcm_material *mat, const double *u,
                                      const double *v, const unsigned char *keep, int rank,
                                      const char *path);

/* The .pvtu index (written atomically) of the pieces <stem>_0.vtu .. <stem>_<nprocs-1>.vtu that
 * fcm__space_write_vtu_piece() wrote with the same velocity / mat choice. (fields.c) */
fcm_status fcm__write_pvtu(fcm_ctx *ctx, const char *path, const char *stem, int nprocs,
                           int with_velocity, int with_stress);

/* fcm_space_max_displacement() per cell: the largest |u| over each cell's authentic points
 * (0 for a cell without points). */
fcm_status fcm__space_cell_max_displacement(const fcm_space *s, const double *u, double *cell_max);

#endif /* FCM_FEM_IMPL_H */
