/* bench_roofline: fcm's element kernels (stiffness, tangent and mass assembly) and CSR SpMV,
 * the rows that do not use the BLAS. */
#include "roofline.h"

/* fcm's own assembly kernels and CSR SpMV do not call the BLAS: they are measured once, in a
 * child started with the selected kernel set (kernel set "any" in the table). Each assembly row
 * assembles a box of cells into its matrix, best of 3; size is the number of cells and the
 * flops are the minimal count of the element matrices (kernel_flops()), not counting the
 * scatter; the time per cell is printed below the table. */

typedef enum kernel_row { ROW_STIFFNESS, ROW_SNH, ROW_MASS } kernel_row;

typedef struct assembly_args {
  fcm_assembly_workspace *ws;
  kernel_row kind;
  fcm_material mat;
  fcm_material_params params;
  const double *u;
  fcm_csr *A;
  double *force;
  int ok;
} assembly_args;

static void assembly_once(void *p)
{
  assembly_args *a = p;
  fcm_linear_form form = fcm_linear_form_default();
  form.material = &a->mat;
  if (a->kind == ROW_SNH) {
    a->ok &= fcm_assembly_workspace_hyperelastic(a->ws, &a->params, a->u, NULL, a->force, a->A) ==
             FCM_OK;
    return;
  }
  form.term = a->kind == ROW_MASS ? FCM_LINEAR_MASS : FCM_LINEAR_STIFFNESS;
  a->ok &= fcm_assembly_workspace_linear(a->ws, &form, a->A, NULL) == FCM_OK;
}

/* The minimal flops of one element matrix with nn nodes on nq points (a flop = one add or one
 * multiply, a fused multiply-add is two). Per point: the Jacobian X^T dN (18 nn), its inverse
 * (about 40) and the physical gradients J^-T dN (18 nn), w det J (1).
 * - Stiffness: H = sum_q w_q det J_q g_q g_q^T on its upper triangle, ndof (ndof + 1) / 2 entries
 *   of 2 nq flops, plus w det J g (ndof per point); then per node pair a <= b the 3 x 3 block
 *   lambda H_ab + mu H_ab^T + mu tr(H_ab) I (33 flops).
 * - SNH force + tangent: F = I + sum_a u_a g_a^T (18 nn), the force P g_a (6 per DOF), the
 *   tangent C_b = w det J A g_b (27 entries of 6 flops per node) and per node pair a <= b the
 *   block g_a^T C_b (9 entries of 6 flops); the material's own P and dP/dF are not counted.
 * - Mass: the scalar block sum_q w_q det J_q rho N N^T, nn (nn + 1) / 2 entries of 2 nq flops
 *   (memory-bound: measured in bytes, see run_mass()). */
static double kernel_flops(kernel_row kind, double nn, double nq)
{
  const double ndof = 3 * nn, pairs = nn * (nn + 1) / 2, grad = 36 * nn + 41;
  switch (kind) {
  case ROW_STIFFNESS:
    return nq * (grad + ndof) + ndof * (ndof + 1) / 2 * 2 * nq + 33 * pairs;
  case ROW_SNH:
    return nq * (grad + 18 * nn + 6 * ndof + 162 * nn + 54 * pairs);
  default:
    return nq * (grad + nn) + pairs * 2 * nq;
  }
}

/* Assemble `kind` on a box of n^3 cells of `type` (SNH: at a smooth displacement of about 1 %
 * strain), best of 3 repetitions of the whole assembly; r->work: flops, or for the mass the
 * bytes of the global matrix entries it adds to (8 read + 8 written per element matrix entry). */
static int run_assembly(fcm_ctx *ctx, fcm_element_type type, int n, kernel_row kind,
                        bench_result *r)
{
  int ok = 0;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n3[3] = {n, n, n};
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  double *u = NULL, *force = NULL;
  fcm_rule *rule = NULL;
  assembly_args a;
  memset(&a, 0, sizeof a);
  a.kind = kind;
  a.mat = (fcm_material){kind == ROW_SNH ? FCM_MATERIAL_STABLE_NEO_HOOKEAN : FCM_MATERIAL_LINEAR,
                         1e7, 0.3, 1000};
  a.ok = 1;
  if (fcm_mesh_create_box(ctx, type, lo, hi, n3, &mesh) ||
      fcm_space_create(ctx, mesh, NULL, &space) || fcm_space_matrix_create(space, &a.A) ||
      fcm_assembly_workspace_create(space, NULL, &a.ws) ||
      fcm_material_setup(ctx, &a.mat, &a.params) ||
      fcm_element_standard_rule(ctx, type, kind == ROW_MASS ? FCM_RULE_MASS : FCM_RULE_STIFFNESS,
                                FCM_DEFAULT, &rule))
    goto done;
  const fcm_index ndof = fcm_space_num_dofs(space), nnodes = fcm_mesh_num_nodes(mesh);
  u = calloc((size_t)ndof, sizeof *u), force = calloc((size_t)ndof, sizeof *force);
  if (!u || !force) goto done;
  const double *xyz = fcm_mesh_coords(mesh);
  for (fcm_index i = 0; i < nnodes; i++) {
    const double *x = xyz + 3 * i;
    const fcm_index d = fcm_space_node_dof(space, i);
    for (int k = 0; k < 3; k++)
      u[d + k] = 0.01 * sin(3.0 * x[(k + 1) % 3] + k) * x[k];
  }
  a.u = u, a.force = force;
  assembly_once(&a); /* warm-up: tabulation, pages */
  r->seconds = roofline_best_of(3, assembly_once, &a);
  if (!a.ok) goto done;
  const double cells = (double)fcm_mesh_num_cells(mesh);
  const double nn = fcm_element_get_info(type)->num_nodes, nq = fcm_rule_num_points(rule);
  r->size = cells;
  r->work = kind == ROW_MASS ? cells * 16.0 * 9 * nn * nn : cells * kernel_flops(kind, nn, nq);
  fcm_index nnz = 0;
  fcm_csr_get_size(a.A, NULL, NULL, &nnz);
  double tr = 0.0; /* every kernel row adds positive diagonal entries */
  const fcm_index *rp = fcm_csr_row_ptr(a.A);
  const int *ci = fcm_csr_col_idx(a.A);
  const double *v = fcm_csr_values(a.A);
  for (fcm_index i = 0; i < ndof; i++)
    for (fcm_index k = rp[i]; k < rp[i + 1]; k++)
      if (ci[k] == i) tr += v[k];
  r->check = tr;
  ok = tr > 0.0 && nnz > 0;
done:
  if (!ok) fcm_ctx_error_view(ctx, stderr);
  free(u), free(force);
  fcm_rule_destroy(&rule);
  fcm_assembly_workspace_destroy(&a.ws);
  fcm_csr_destroy(&a.A);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  return ok;
}

/* Box sizes at the default 24: 4,096 to 13,824 cells, matrices of 40 to 190 MB (beyond the
 * last-level cache). */
int run_hex8_stiffness(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_HEX8, cells, ROW_STIFFNESS, r);
}

int run_hex20_stiffness(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_HEX20, (2 * cells + 2) / 3, ROW_STIFFNESS, r);
}

int run_tet10_stiffness(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_TET10, (cells + 1) / 2, ROW_STIFFNESS, r);
}

int run_hex20_snh(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_HEX20, (2 * cells + 2) / 3, ROW_SNH, r);
}

int run_hex20_mass(fcm_ctx *ctx, int cells, bench_result *r)
{
  return run_assembly(ctx, FCM_ELEMENT_HEX20, (2 * cells + 2) / 3, ROW_MASS, r);
}

typedef struct spmv_args {
  const fcm_csr *A;
  const double *x;
  double *y;
  int ok;
} spmv_args;

static void spmv_once(void *p)
{
  spmv_args *s = p;
  s->ok &= fcm_csr_apply(s->A, 1.0, s->x, 0.0, s->y) == FCM_OK;
}

/* y = K x with the Hex8 elasticity matrix of (4 cells / 3)^3 cells (100 MB at the default 24,
 * beyond the last-level cache), best of 10. Bytes: the values (8)
 * and column indices (4) of every entry, the row pointers (8 per row), x read and y written once
 * (8 + 8 per row): the least a CSR SpMV moves. The check: x^T K x > 0. */
int run_spmv(fcm_ctx *ctx, int cells, bench_result *r)
{
  int ok = 0;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index m = 4 * (fcm_index)cells / 3, n3[3] = {m, m, m};
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e7, 0.3, 1000};
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL;
  double *x = NULL, *y = NULL;
  if (fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &mesh) ||
      fcm_space_create(ctx, mesh, NULL, &space) || fcm_space_matrix_create(space, &K) ||
      fcm_assemble_stiffness(space, &mat, NULL, K))
    goto done;
  fcm_index n = 0, nnz = 0;
  fcm_csr_get_size(K, &n, NULL, &nnz);
  x = malloc((size_t)n * sizeof *x), y = malloc((size_t)n * sizeof *y);
  if (!x || !y) goto done;
  for (fcm_index i = 0; i < n; i++)
    x[i] = 1.0 + 0.5 * sin(0.37 * (double)i);
  spmv_args s = {K, x, y, 1};
  spmv_once(&s);
  r->seconds = roofline_best_of(10, spmv_once, &s);
  double xkx = 0.0;
  for (fcm_index i = 0; i < n; i++)
    xkx += x[i] * y[i];
  r->size = (double)n;
  r->work = 12.0 * (double)nnz + 24.0 * (double)n;
  r->check = xkx;
  ok = s.ok && xkx > 0.0;
done:
  if (!ok) fcm_ctx_error_view(ctx, stderr);
  free(x), free(y);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  return ok;
}
