/* Assembly's visiting order and its blocked element kernels, on a distorted box of many element
 * blocks (tests/fem/block_order <el>):
 * - the coloured blocks cover every element once, and no two blocks of a colour share a DOF
 *   copy (so they can be assembled in parallel);
 * - stiffness, mass and the Stable Neo-Hookean force and tangent are bitwise the same with 1, 2
 *   and 3 threads (for Hex20 on a matrix large enough for the scatter's prefetching);
 * - the blocked stiffness and mass element matrices of a distorted cell equal the sum over the
 *   rule's points of the per-point formulas to 1e-13 (relative to the largest entry: the sums
 *   only run in another order). */
#include "fem/fem_impl.h"
#include "fem_util.h"

#include <omp.h>
#include <string.h>

/* The blocks: each element once, in its cell's block, the blocks of a colour pairwise without
 * a shared copy; the blocks are runs of FCM__SPACE_BLOCK cells. */
static void check_blocks(const fcm_space *s)
{
  const fcm_index ne = s->num_local_elems, nb = s->num_blocks;
  TEST_TRUE(nb == (s->num_block_cells + FCM__SPACE_BLOCK - 1) / FCM__SPACE_BLOCK);
  TEST_TRUE(s->num_block_colors >= 1 && s->block_color_ptr[s->num_block_colors] == nb);
  TEST_TRUE(nb >= 8); /* the box is large enough to have blocks to run in parallel */
  TEST_TRUE(s->block_ptr[0] == 0 && s->block_ptr[nb] == ne);
  unsigned char *seen = calloc((size_t)nb, 1);
  fcm_index *owner = malloc(sizeof *owner * (size_t)(s->num_dofs / 3));
  for (int c = 0; c < s->num_block_colors; c++) {
    for (fcm_index k = 0; k < s->num_dofs / 3; k++)
      owner[k] = -1;
    for (fcm_index i = s->block_color_ptr[c]; i < s->block_color_ptr[c + 1]; i++) {
      const fcm_index b = s->block_list[i];
      TEST_TRUE(b >= 0 && b < nb && !seen[b]);
      seen[b] = 1;
      for (fcm_index j = s->block_ptr[b]; j < s->block_ptr[b + 1]; j++) {
        const fcm_index e = s->local_elem ? s->local_elem[s->block_elems[j]] : s->block_elems[j];
        int in_block = 0; /* the element's cell is one of the block's */
        for (fcm_index q = b * FCM__SPACE_BLOCK;
             q < FCM_MIN(s->num_block_cells, (b + 1) * FCM__SPACE_BLOCK); q++)
          in_block |= s->block_cells[q] == s->elem_cell[e];
        TEST_TRUE(in_block);
        for (int a = 0; a < s->nn; a++) {
          const fcm_index k = s->elem_dof[e * s->nn + a] / 3;
          TEST_TRUE(owner[k] < 0 || owner[k] == b);
          owner[k] = b;
        }
      }
    }
  }
  for (fcm_index b = 0; b < nb; b++)
    TEST_TRUE(seen[b]);
  unsigned char *once = calloc((size_t)ne, 1); /* block_elems: each element exactly once */
  for (fcm_index j = 0; j < ne; j++) {
    const fcm_index e = s->block_elems[j];
    TEST_TRUE(e >= 0 && e < ne && !once[e]);
    if (e >= 0 && e < ne) once[e] = 1;
  }
  free(seen), free(owner), free(once);
}

/* Stiffness + mass into A and SNH force + tangent into T, f with `threads` threads. */
static void assemble_all(fcm_ctx *ctx, const fcm_space *s, int threads, const double *u, fcm_csr *A,
                         fcm_csr *T, double *f)
{
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000};
  fcm_material_params p;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, threads));
  TEST_OK(ctx, fcm_material_setup(ctx, &mat, &p));
  fcm_index nnz = 0;
  fcm_csr_get_size(A, NULL, NULL, &nnz);
  memset(fcm_csr_values(A), 0, sizeof(double) * (size_t)nnz);
  memset(fcm_csr_values(T), 0, sizeof(double) * (size_t)nnz);
  memset(f, 0, sizeof *f * (size_t)fcm_space_num_dofs(s));
  TEST_OK(ctx, fcm_assemble_stiffness(s, &mat, NULL, A));
  TEST_OK(ctx, fcm_assemble_mass(s, &mat, NULL, A));
  TEST_OK(ctx, fcm_assemble_hyperelastic(s, &p, u, NULL, NULL, f, T));
}

/* The element matrices of element `e` against the per-point formulas: stiffness
 * K_(a,i)(b,j) = sum_q w det J (lambda g_ai g_bj + mu g_aj g_bi + mu delta_ij g_a . g_b) and mass
 * M_(a,i)(b,j) = sum_q w det J rho N_a N_b delta_ij. */
static void check_element(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_space *s,
                          fcm_element_type type, fcm_index e)
{
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 2e6, 0.27, 800};
  double lambda = 0, mu = 0;
  TEST_OK(ctx, fcm_material_lame(ctx, &mat, &lambda, &mu));
  const int nn = fcm_element_get_info(type)->num_nodes, ndof = 3 * nn;
  double X[3 * FCM_ELEMENT_MAX_NODES], N[FCM_ELEMENT_MAX_NODES], dN[3 * FCM_ELEMENT_MAX_NODES];
  double *Ke = calloc((size_t)ndof * ndof, sizeof *Ke), *Kr = calloc((size_t)ndof * ndof, 8);
  fcm_mesh_cell_coords(mesh, e, X);
  fcm_assembly_workspace *ws = NULL;
  TEST_OK(ctx, fcm_assembly_workspace_create(s, NULL, &ws));
  for (int kind = 0; kind < 2; kind++) { /* 0 stiffness, 1 mass */
    fcm_linear_form form = fcm_linear_form_default();
    form.term = kind ? FCM_LINEAR_MASS : FCM_LINEAR_STIFFNESS;
    form.material = &mat;
    TEST_OK(ctx, fcm__assembly_element_linear(ws, &form, e, Ke, NULL));
    fcm_rule *rule = NULL;
    TEST_OK(ctx, fcm_element_standard_rule(ctx, type, kind ? FCM_RULE_MASS : FCM_RULE_STIFFNESS,
                                           FCM_DEFAULT, &rule));
    memset(Kr, 0, sizeof *Kr * (size_t)ndof * ndof);
    for (int q = 0; q < fcm_rule_num_points(rule); q++) {
      const double *xi = fcm_rule_points(rule) + 3 * q;
      double J[9] = {0}, g[3 * FCM_ELEMENT_MAX_NODES];
      fcm_element_eval_shape(type, xi, N);
      fcm_element_eval_grad(type, xi, dN);
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 9; i++)
          J[i] += X[3 * a + i / 3] * dN[3 * a + i % 3];
      const double det = J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) +
                         J[2] * (J[3] * J[7] - J[4] * J[6]);
      const double Ji[9] = {(J[4] * J[8] - J[5] * J[7]) / det, (J[2] * J[7] - J[1] * J[8]) / det,
                            (J[1] * J[5] - J[2] * J[4]) / det, (J[5] * J[6] - J[3] * J[8]) / det,
                            (J[0] * J[8] - J[2] * J[6]) / det, (J[2] * J[3] - J[0] * J[5]) / det,
                            (J[3] * J[7] - J[4] * J[6]) / det, (J[1] * J[6] - J[0] * J[7]) / det,
                            (J[0] * J[4] - J[1] * J[3]) / det};
      for (int a = 0; a < nn; a++) /* g_a = J^-T dN_a */
        for (int j = 0; j < 3; j++)
          g[3 * a + j] = Ji[j] * dN[3 * a] + Ji[3 + j] * dN[3 * a + 1] + Ji[6 + j] * dN[3 * a + 2];
      const double wd = fcm_rule_weights(rule)[q] * det;
      for (int a = 0; a < nn; a++)
        for (int b = 0; b < nn; b++) {
          const double *ga = g + 3 * a, *gb = g + 3 * b;
          const double dot = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
          for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
              Kr[(size_t)(3 * a + i) * ndof + 3 * b + j] +=
                  kind ? (i == j ? wd * mat.density * N[a] * N[b] : 0.0)
                       : wd * (lambda * ga[i] * gb[j] + mu * ga[j] * gb[i] +
                               (i == j ? mu * dot : 0.0));
        }
    }
    double big = 0.0, diff = 0.0;
    for (int k = 0; k < ndof * ndof; k++)
      big = fmax(big, fabs(Kr[k])), diff = fmax(diff, fabs(Ke[k] - Kr[k]));
    TEST_TRUE(big > 0.0);
    TEST_NEAR(diff / big, 0.0, 0.0, 1e-13);
    fcm_rule_destroy(&rule);
  }
  fcm_assembly_workspace_destroy(&ws);
  free(Ke), free(Kr);
}

int main(int argc, char **argv)
{
  fcm_element_type type = FCM_ELEMENT_HEX20;
  if (argc > 1 && fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const int tet = fcm_element_get_info(type)->num_corners == 4;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *A[3] = {NULL, NULL, NULL}, *T[3] = {NULL, NULL, NULL};
  omp_set_dynamic(0);
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, distorted_box(ctx, type, tet ? 6 : 10, 0.2, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  check_blocks(space);
  const fcm_index n = fcm_space_num_dofs(space);
  double *u = calloc((size_t)n, sizeof *u), *f[3];
  unsigned long long seed = 7;
  for (fcm_index i = 0; i < n; i++)
    u[i] = 0.02 * urand(&seed);
  fcm_index nnz = 0;
  for (int t = 0; t < 3; t++) {
    f[t] = calloc((size_t)n, sizeof *f[t]);
    TEST_OK(ctx, fcm_space_matrix_create(space, &A[t]));
    TEST_OK(ctx, fcm_space_matrix_create(space, &T[t]));
    assemble_all(ctx, space, t + 1, u, A[t], T[t], f[t]);
  }
  fcm_csr_get_size(A[0], NULL, NULL, &nnz);
  /* the scatter prefetches the entries of later elements on matrices of 4 MiB of values and
   * more: the Hex20 box's (18 MB) runs that path */
  if (type == FCM_ELEMENT_HEX20) TEST_TRUE((double)nnz * sizeof(double) >= 4.0 * 1024 * 1024);
  for (int t = 1; t < 3; t++) {
    TEST_TRUE(memcmp(fcm_csr_values(A[t]), fcm_csr_values(A[0]), sizeof(double) * nnz) == 0);
    TEST_TRUE(memcmp(fcm_csr_values(T[t]), fcm_csr_values(T[0]), sizeof(double) * nnz) == 0);
    TEST_TRUE(memcmp(f[t], f[0], sizeof(double) * (size_t)n) == 0);
  }
  check_element(ctx, mesh, space, type, fcm_mesh_num_cells(mesh) / 2 + 1);
  for (int t = 0; t < 3; t++) {
    fcm_csr_destroy(&A[t]);
    fcm_csr_destroy(&T[t]);
    free(f[t]);
  }
  free(u);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
