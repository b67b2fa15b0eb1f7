/* Problems shared by the multigrid tests: static linear elasticity on Hex8 box grids of an
 * uncut cube (clamped at x = 0), an embedded hemisphere (clamped on its flat face y = 0, its
 * curved surface cutting cells; optionally an XFEM plane cut through its upper part) and two
 * disjoint balls (K + M, no boundary condition). */
#ifndef FCM_MG_TEST_UTIL_H
#define FCM_MG_TEST_UTIL_H

#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct problem {
  fcm_mesh *mesh;
  fcm_geometry *geom;
  fcm_cell_rules *rules, *rules0;
  fcm_space *space;
  fcm_csr *A;
  double *b;
  fcm_index n;
} problem;

static inline void problem_free(problem *p)
{
  fcm_csr_destroy(&p->A);
  fcm_space_destroy(&p->space);
  fcm_cell_rules_destroy(&p->rules);
  fcm_cell_rules_destroy(&p->rules0);
  fcm_geometry_destroy(&p->geom);
  fcm_mesh_destroy(&p->mesh);
  free(p->b);
  memset(p, 0, sizeof *p);
}

/* x = A^-1 b by CHOLMOD. */
static inline void direct_solve(fcm_ctx *ctx, const fcm_csr *A, const double *b, double *x)
{
  fcm_direct *d = NULL;
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &d));
  TEST_OK(ctx, fcm_direct_analyze(d));
  TEST_OK(ctx, fcm_direct_factor(d, fcm_csr_values_read(A)));
  TEST_OK(ctx, fcm_direct_solve(d, b, x));
  fcm_direct_destroy(&d);
}

/* Clamp every copy of every active node in the box [lo, hi]. */
static inline void clamp_box(fcm_ctx *ctx, problem *p, const double lo[3], const double hi[3])
{
  fcm_index cnt = 0;
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, p->mesh, lo, hi, 1e-9, 0, NULL, &cnt));
  fcm_index *nodes = calloc((size_t)cnt + 1, sizeof *nodes);
  fcm_index *dofs = calloc(3 * (size_t)cnt * 8 + 1, sizeof *dofs), nd = 0;
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, p->mesh, lo, hi, 1e-9, cnt, nodes, &cnt));
  for (fcm_index i = 0; i < cnt; i++) {
    const fcm_index d0 = fcm_space_node_dof(p->space, nodes[i]);
    const fcm_index nc = fcm_space_node_copies(p->space, nodes[i]);
    for (fcm_index c = 0; d0 >= 0 && c < nc && c < 8; c++)
      for (int d = 0; d < 3; d++)
        dofs[nd++] = d0 + 3 * c + d;
  }
  TEST_OK(ctx, fcm_space_apply_dirichlet(p->space, nd, dofs, NULL, p->A, p->b));
  free(nodes);
  free(dofs);
}

static inline void finish_space(fcm_ctx *ctx, problem *p, int with_mass)
{
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e5, 0.3, 1000.0};
  const double g[3] = {0.0, -9.81, 0.0};
  p->n = fcm_space_num_dofs(p->space);
  p->b = calloc((size_t)p->n + 1, sizeof *p->b);
  TEST_OK(ctx, fcm_space_matrix_create(p->space, &p->A));
  TEST_OK(ctx, fcm_assemble_stiffness(p->space, &mat, NULL, p->A));
  if (with_mass) {
    fcm_material m2 = mat;
    m2.density = 1.0e4; /* a strong mass term: K + M is positive definite */
    TEST_OK(ctx, fcm_assemble_mass(p->space, &m2, NULL, p->A));
  }
  TEST_OK(ctx, fcm_assemble_body_force(p->space, &mat, g, NULL, p->b));
}

/* Unit cube, n^3 cells of `type` (Hex8 or Hex20), clamped at x = 0, gravity. */
static inline void problem_cube_of(fcm_ctx *ctx, fcm_element_type type, fcm_index n, problem *p)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index cells[3] = {n, n, n};
  memset(p, 0, sizeof *p);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &p->mesh));
  TEST_OK(ctx, fcm_space_create(ctx, p->mesh, NULL, &p->space));
  finish_space(ctx, p, 0);
  const double flo[3] = {0, -1, -1}, fhi[3] = {0, 2, 2};
  clamp_box(ctx, p, flo, fhi);
}

/* The Hex8 cube. */
static inline void problem_cube(fcm_ctx *ctx, fcm_index n, problem *p)
{
  problem_cube_of(ctx, FCM_ELEMENT_HEX8, n, p);
}

/* Hemisphere of radius 1 on y = 0 (cells of `type`: Hex8 or Hex20) in [-1.1, 1.1] x [0, 1.1] x
 * [-1.1, 1.1] with n x n/2 x n cells (n even), clamped at y = 0; cut = 1: a vertical plane cut x =
 * 0.05 through the upper part y > 0.4 (it separates the top into two halves joined below); cut = 2:
 * the same plane through the whole body (two bodies, each clamped); ratio: the space's
 * constrain_ratio (copies of smaller support move with their piece). */
static inline void problem_hemisphere_of(fcm_ctx *ctx, fcm_element_type type, fcm_index n, int cut,
                                         double ratio, problem *p)
{
  const double lo[3] = {-1.1, 0, -1.1}, hi[3] = {1.1, 1.1, 1.1}, c[3] = {0, 0, 0};
  const fcm_index cells[3] = {n, n / 2, n};
  memset(p, 0, sizeof *p);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &p->mesh));
  TEST_OK(ctx, fcm_geometry_create_hemisphere(ctx, c, 1.0, 4, &p->geom));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.simplify = FCM_CELL_SIMPLIFY_OFF; /* faster; the solver sees the same kind of matrix */
  TEST_OK(ctx, fcm_cell_rules_create(ctx, p->mesh, p->geom, &ro, &p->rules0));
  if (cut) {
    fcm_surface *s = NULL;
    const double q[3] = {0.05, 0.0, 0.0}, nx[3] = {1, 0, 0};
    const double bl[3] = {-0.1, cut == 2 ? -1.0 : 0.4, -2.0}, bh[3] = {0.2, 2.0, 2.0};
    TEST_OK(ctx, fcm_surface_create_plane(ctx, q, nx, bl, bh, &s));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, p->mesh, p->geom, p->rules0, s, &p->rules));
    fcm_surface_destroy(&s);
  }
  fcm_space_options so = fcm_space_options_default();
  so.constrain_ratio = ratio;
  TEST_OK(ctx, fcm_space_create_embedded_with(ctx, p->mesh, p->rules ? p->rules : p->rules0, &so,
                                              &p->space));
  finish_space(ctx, p, 0);
  const double flo[3] = {-2, 0, -2}, fhi[3] = {2, 0, 2};
  clamp_box(ctx, p, flo, fhi);
}

/* The Hex8 grid of problem_hemisphere_of(). */
static inline void problem_hemisphere_with(fcm_ctx *ctx, fcm_index n, int cut, double ratio,
                                           problem *p)
{
  problem_hemisphere_of(ctx, FCM_ELEMENT_HEX8, n, cut, ratio, p);
}

/* As problem_hemisphere_with() with the default constrain_ratio (1e-9). */
static inline void problem_hemisphere(fcm_ctx *ctx, fcm_index n, int cut, problem *p)
{
  problem_hemisphere_with(ctx, n, cut, fcm_space_options_default().constrain_ratio, p);
}

/* Two balls of radius 0.3 (resolution 3) at c1 and c2 as one geometry. */
static inline void two_balls(fcm_ctx *ctx, const double c1[3], const double c2[3],
                             fcm_geometry **geom)
{
  fcm_geometry *b1 = NULL, *b2 = NULL;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c1, 0.3, 3, &b1));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c2, 0.3, 3, &b2));
  const fcm_index n1 = fcm_geometry_num_nodes(b1), n2 = fcm_geometry_num_nodes(b2);
  const fcm_index e1 = fcm_geometry_num_cells(b1), e2 = fcm_geometry_num_cells(b2);
  double *X = malloc(sizeof *X * 3 * (size_t)(n1 + n2));
  fcm_index *T = malloc(sizeof *T * 4 * (size_t)(e1 + e2));
  memcpy(X, fcm_geometry_coords(b1), sizeof *X * 3 * (size_t)n1);
  memcpy(X + 3 * n1, fcm_geometry_coords(b2), sizeof *X * 3 * (size_t)n2);
  memcpy(T, fcm_geometry_cells(b1), sizeof *T * 4 * (size_t)e1);
  for (fcm_index i = 0; i < 4 * e2; i++)
    T[4 * e1 + i] = fcm_geometry_cells(b2)[i] + n1;
  TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, n1 + n2, X, e1 + e2, T, geom));
  free(X);
  free(T);
  fcm_geometry_destroy(&b1);
  fcm_geometry_destroy(&b2);
}

/* Two balls of radius 0.3 at (0.5, 0.5, 0.5) and (1.5, 0.5, 0.5) in [0, 2] x [0, 1]^2 with
 * 2n x n x n cells of `type`; A = K + M. */
static inline void problem_balls_of(fcm_ctx *ctx, fcm_element_type type, fcm_index n, problem *p)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  const double c1[3] = {0.5, 0.5, 0.5}, c2[3] = {1.5, 0.5, 0.5};
  const fcm_index cells[3] = {2 * n, n, n};
  memset(p, 0, sizeof *p);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &p->mesh));
  two_balls(ctx, c1, c2, &p->geom);
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.simplify = FCM_CELL_SIMPLIFY_OFF; /* faster; the solver sees the same kind of matrix */
  TEST_OK(ctx, fcm_cell_rules_create(ctx, p->mesh, p->geom, &ro, &p->rules0));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, p->mesh, p->rules0, &p->space));
  finish_space(ctx, p, 1);
}

/* The balls on a Hex8 grid. */
static inline void problem_balls(fcm_ctx *ctx, fcm_index n, problem *p)
{
  problem_balls_of(ctx, FCM_ELEMENT_HEX8, n, p);
}

/* Hollow ball (radii 0.5 and 0.9, three holes of radius 0.25 along the axes) in [-1, 1]^3
 * with n^3 cells of `type`, clamped where y <= -0.5 (its bottom cap), gravity. */
static inline void problem_hollow_of(fcm_ctx *ctx, fcm_element_type type, fcm_index n, problem *p)
{
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c[3] = {0, 0, 0};
  const fcm_index cells[3] = {n, n, n};
  memset(p, 0, sizeof *p);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &p->mesh));
  TEST_OK(ctx, fcm_geometry_create_hollow_ball(ctx, c, 0.5, 0.9, 0.25, 16, 3, &p->geom));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.simplify = FCM_CELL_SIMPLIFY_OFF;
  ro.kinds = FCM_RULES_STIFFNESS;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, p->mesh, p->geom, &ro, &p->rules0));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, p->mesh, p->rules0, &p->space));
  finish_space(ctx, p, 0);
  const double flo[3] = {-2, -2, -2}, fhi[3] = {2, -0.5, 2};
  clamp_box(ctx, p, flo, fhi);
}

/* ---- octree backgrounds */

typedef struct oct_problem {
  fcm_mesh *mesh;
  fcm_geometry *geom;
  fcm_cell_rules *rules;
  fcm_space *space;
  fcm_csr *K, *P, *A;
  fcm_index *free_dof;
  double *b;
  fcm_index n;
} oct_problem;

static inline void oct_free(oct_problem *p)
{
  fcm_csr_destroy(&p->A);
  fcm_csr_destroy(&p->P);
  fcm_csr_destroy(&p->K);
  fcm_space_destroy(&p->space);
  fcm_cell_rules_destroy(&p->rules);
  fcm_geometry_destroy(&p->geom);
  fcm_mesh_destroy(&p->mesh);
  free(p->free_dof);
  free(p->b);
  memset(p, 0, sizeof *p);
}

/* P (n x n) of an octree problem: the row of a free DOF is that DOF, the row of a hanging DOF its
 * masters' weights. */
static inline void square_constraints(fcm_ctx *ctx, oct_problem *p)
{
  fcm_csr *T = NULL;
  p->free_dof = calloc((size_t)p->n + 1, sizeof *p->free_dof);
  TEST_OK(ctx, fcm_space_hanging_matrix_create(p->space, p->free_dof, &T));
  fcm_index nfree = 0, nnz = 0;
  fcm_csr_get_size(T, NULL, &nfree, &nnz);
  fcm_index *col_dof = calloc((size_t)nfree + 1, sizeof *col_dof);
  fcm_index *rows = calloc((size_t)nnz + 1, sizeof *rows);
  fcm_index *cols = calloc((size_t)nnz + 1, sizeof *cols);
  for (fcm_index d = 0; d < p->n; d++)
    if (p->free_dof[d] >= 0) col_dof[p->free_dof[d]] = d;
  const fcm_index *rp = fcm_csr_row_ptr(T);
  const int *ci = fcm_csr_col_idx(T);
  for (fcm_index r = 0; r < p->n; r++)
    for (fcm_index e = rp[r]; e < rp[r + 1]; e++)
      rows[e] = r, cols[e] = col_dof[ci[e]];
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, p->n, p->n, nnz, rows, cols, fcm_csr_values_read(T),
                                       FCM_CSR_GENERAL, &p->P));
  free(col_dof), free(rows), free(cols);
  fcm_csr_destroy(&T);
}

/* The octree over `cells` of [lo, hi] refined along p->geom's boundary to `depth`, its cell
 * rules and embedded space. */
static inline void oct_problem_embed(fcm_ctx *ctx, fcm_element_type type, const double lo[3],
                                     const double hi[3], const fcm_index cells[3], int depth,
                                     oct_problem *p)
{
  fcm_octree_options oo = fcm_octree_options_default();
  oo.refine = fcm_geometry_boundary_meets_box;
  oo.refine_user = p->geom;
  oo.refine_level = depth;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, cells, &oo, &p->mesh));
  TEST_TRUE(fcm_mesh_max_level(p->mesh) == depth && fcm_mesh_num_hanging(p->mesh) > 0);
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.simplify = FCM_CELL_SIMPLIFY_OFF;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, p->mesh, p->geom, &ro, &p->rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, p->mesh, p->rules, &p->space));
}

/* Linear elasticity under gravity (with_mass: K + M, a strong mass term) as the integrators
 * solve it: A = P^T K P + I_h (P the square hanging-node matrix: free rows the identity's,
 * hanging rows their masters' weights; I_h the identity on the hanging DOFs), b = P^T f. */
static inline void oct_problem_assemble(fcm_ctx *ctx, oct_problem *p, int with_mass)
{
  p->n = fcm_space_num_dofs(p->space);
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e5, 0.3, 1000.0};
  const double g[3] = {0.0, -9.81, 0.0};
  double *f = calloc((size_t)p->n + 1, sizeof *f);
  TEST_OK(ctx, fcm_space_matrix_create(p->space, &p->K));
  TEST_OK(ctx, fcm_assemble_stiffness(p->space, &mat, NULL, p->K));
  if (with_mass) {
    fcm_material m2 = mat;
    m2.density = 1.0e4;
    TEST_OK(ctx, fcm_assemble_mass(p->space, &m2, NULL, p->K));
  }
  TEST_OK(ctx, fcm_assemble_body_force(p->space, &mat, g, NULL, f));
  square_constraints(ctx, p);
  /* A = P^T K P + I_h, b = P^T f */
  TEST_OK(ctx, fcm_csr_create_ptap(ctx, p->K, p->P, &p->A));
  double *av = fcm_csr_values(p->A);
  for (fcm_index d = 0; d < p->n; d++)
    if (p->free_dof[d] < 0) {
      const fcm_index q = fcm_csr_position(p->A, d, d);
      TEST_TRUE(q >= 0);
      if (q >= 0) av[q] = 1.0;
    }
  p->b = calloc((size_t)p->n + 1, sizeof *p->b);
  {
    const fcm_index *rp = fcm_csr_row_ptr(p->P);
    const int *ci = fcm_csr_col_idx(p->P);
    const double *pv = fcm_csr_values_read(p->P);
    for (fcm_index r = 0; r < p->n; r++)
      for (fcm_index e = rp[r]; e < rp[r + 1]; e++)
        p->b[ci[e]] += pv[e] * f[r];
  }
  free(f);
}

/* The hemisphere of problem_hemisphere_of() on an octree over the n x n/2 x n grid (n even),
 * refined along its boundary to `depth` (oct_problem_assemble(), no mass), the free DOFs on
 * y = 0 clamped. */
static inline void oct_problem_create(fcm_ctx *ctx, fcm_element_type type, fcm_index n, int depth,
                                      oct_problem *p)
{
  const double lo[3] = {-1.1, 0, -1.1}, hi[3] = {1.1, 1.1, 1.1}, c[3] = {0, 0, 0};
  const fcm_index cells[3] = {n, n / 2, n};
  memset(p, 0, sizeof *p);
  TEST_OK(ctx, fcm_geometry_create_hemisphere(ctx, c, 1.0, 4, &p->geom));
  oct_problem_embed(ctx, type, lo, hi, cells, depth, p);
  oct_problem_assemble(ctx, p, 0);
  /* clamp the free DOFs on y = 0 (the hanging ones there follow their clamped masters) */
  const double flo[3] = {-2, 0, -2}, fhi[3] = {2, 0, 2};
  fcm_index cnt = 0, nd = 0;
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, p->mesh, flo, fhi, 1e-9, 0, NULL, &cnt));
  fcm_index *nodes = calloc((size_t)cnt + 1, sizeof *nodes);
  fcm_index *dofs = calloc(3 * (size_t)cnt + 1, sizeof *dofs);
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, p->mesh, flo, fhi, 1e-9, cnt, nodes, &cnt));
  for (fcm_index i = 0; i < cnt; i++) {
    const fcm_index d0 = fcm_space_node_dof(p->space, nodes[i]);
    for (int d = 0; d0 >= 0 && d < 3; d++)
      if (p->free_dof[d0 + d] >= 0) dofs[nd++] = d0 + d;
  }
  TEST_TRUE(nd > 0);
  TEST_OK(ctx, fcm_space_apply_dirichlet(p->space, nd, dofs, NULL, p->A, p->b));
  free(nodes);
  free(dofs);
}

/* v_ij = s_i s_j a_ij with s_i = 1 + amp sin(i): the same pattern, eliminated rows stay
 * eliminated (their couplings stay zero), positive definite when A is. */
static inline void scale_symmetric(fcm_csr *A, const double *v0, double amp)
{
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  double *v = fcm_csr_values(A);
  for (fcm_index i = 0; i < n; i++)
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      v[p] = (1.0 + amp * sin((double)i)) * (1.0 + amp * sin((double)ci[p])) * v0[p];
}

#endif /* FCM_MG_TEST_UTIL_H */
