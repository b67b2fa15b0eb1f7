/* Convergence toward a corner singularity, adaptive against uniform: linear
 * elasticity on the unit cube, Hex8, with the manufactured solution u = c r^alpha (r the
 * distance to the corner 0; alpha = 0.2: grad u ~ r^-0.8), its body force and Dirichlet data on
 * the whole boundary. Uniform grids n = 2..24 against octrees grown from the 2^3 grid by the
 * stress-jump indicator (fcm_space_stress_jumps(), Doerfler marking: the largest indicators
 * holding half of sum eta^2), solved through the hanging-node constraints (T^T K T). Prints
 * the DOFs of the reduced system (hanging nodes eliminated, boundary DOFs included), cells and
 * the relative H1-seminorm error of each, and for every uniform grid the DOFs and cells the
 * adaptive sequence needs for the same error (log-log interpolation between its steps). */
#include "fem/fem_impl.h"
#include "../fem/fem_util.h"

#include <stdlib.h>

static const double alpha = 0.2, cvec[3] = {1.0, -0.5, 0.3};
static const double E = 1.0, nu = 0.3;

static void exact(const double x[3], double u[3])
{
  const double r = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  const double p = pow(r, alpha);
  for (int i = 0; i < 3; i++)
    u[i] = cvec[i] * p;
}

/* b = -(mu c lap(phi) + (lam + mu) H c), phi = r^alpha, H its Hessian. */
static void body_force(void *user, const double x[3], const double normal[3], double b[3])
{
  (void)user, (void)normal;
  const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const double r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2], r = sqrt(r2);
  const double q = alpha * pow(r, alpha - 2.0),
               xc = x[0] * cvec[0] + x[1] * cvec[1] + x[2] * cvec[2];
  for (int i = 0; i < 3; i++) {
    const double Hc = q * (cvec[i] + (alpha - 2.0) * x[i] * xc / r2);
    b[i] = -(mu * cvec[i] * q * (alpha + 1.0) + (lam + mu) * Hc);
  }
}

/* Relative H1-seminorm error of u (DOFs of s) against the exact field, 4^3 Gauss points per
 * (box) cell. */
static double h1_error(const fcm_space *s, const double *u)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const int npc = fcm_mesh_nodes_per_cell(m);
  const double *X = fcm_mesh_coords(m);
  static const double g[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                              0.8611363115940526};
  static const double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                              0.3478548451374538};
  double err = 0.0, ref = 0.0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(m); c++) {
    const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
    double lo[3], h[3];
    for (int d = 0; d < 3; d++)
      lo[d] = X[3 * cn[0] + d], h[d] = X[3 * cn[6] + d] - lo[d];
    for (int q = 0; q < 64; q++) {
      const double xi[3] = {g[q % 4], g[(q / 4) % 4], g[q / 16]};
      const double wq = w[q % 4] * w[(q / 4) % 4] * w[q / 16] * h[0] * h[1] * h[2] / 8.0;
      double dN[3 * 8], x[3], Gh[9] = {0};
      fcm_element_eval_grad(FCM_ELEMENT_HEX8, xi, dN);
      for (int d = 0; d < 3; d++)
        x[d] = lo[d] + 0.5 * (xi[d] + 1.0) * h[d];
      for (int a = 0; a < npc; a++)
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < 3; j++)
            Gh[3 * i + j] += u[fcm_space_node_dof(s, cn[a]) + i] * dN[3 * a + j] * 2.0 / h[j];
      const double r = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
      const double dphi = alpha * pow(r, alpha - 2.0);
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
          const double ge = cvec[i] * dphi * x[j];
          err += wq * (Gh[3 * i + j] - ge) * (Gh[3 * i + j] - ge);
          ref += wq * ge * ge;
        }
    }
  }
  return sqrt(err / ref);
}

/* Solve on mesh m; the free DOFs, the error and (eta != NULL) the indicator per cell. */
static void solve(fcm_ctx *ctx, const fcm_mesh *m, fcm_index *nfree, double *error, double *eta)
{
  fcm_space *s = NULL;
  fcm_csr *K = NULL, *T = NULL, *Kr = NULL;
  TEST_OK(ctx, fcm_space_create(ctx, m, NULL, &s));
  const fcm_index n = fcm_space_num_dofs(s);
  fcm_index *free_dof = malloc(sizeof *free_dof * (size_t)n), nr = 0;
  TEST_OK(ctx, fcm_space_hanging_matrix_create(s, free_dof, &T));
  TEST_OK(ctx, fcm_space_matrix_create(s, &K));
  fcm_material mat = {FCM_MATERIAL_LINEAR, E, nu, 1.0};
  TEST_OK(ctx, fcm_assemble_stiffness(s, &mat, NULL, K));
  TEST_OK(ctx, fcm_csr_create_ptap(ctx, K, T, &Kr));
  fcm_csr_get_size(Kr, &nr, NULL, NULL);
  double *f = calloc((size_t)n, sizeof *f), *b = calloc((size_t)nr, sizeof *b);
  double *g = calloc((size_t)nr, sizeof *g), *v = calloc((size_t)nr, sizeof *v);
  double *u = calloc((size_t)n, sizeof *u);
  unsigned char *con = calloc((size_t)nr, 1);
  TEST_OK(ctx, fcm_assemble_body_force_field(s, body_force, NULL, NULL, f));
  const fcm_index *tp = fcm_csr_row_ptr(T);
  const int *tc = fcm_csr_col_idx(T);
  const double *tv = fcm_csr_values_read(T);
  for (fcm_index i = 0; i < n; i++)
    for (fcm_index p = tp[i]; p < tp[i + 1]; p++)
      b[tc[p]] += tv[p] * f[i];
  const double *X = fcm_mesh_coords(m);
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(m); a++) {
    const fcm_index d0 = fcm_space_node_dof(s, a);
    int bnd = 0;
    for (int d = 0; d < 3; d++)
      bnd |= X[3 * a + d] == 0.0 || X[3 * a + d] == 1.0;
    if (!bnd || free_dof[d0] < 0) continue;
    double ue[3];
    exact(X + 3 * a, ue);
    for (int i = 0; i < 3; i++)
      con[free_dof[d0 + i]] = 1, g[free_dof[d0 + i]] = ue[i];
  }
  fcm__eliminate_marked(Kr, b, con, g);
  TEST_OK(ctx, direct_solve(ctx, Kr, b, v));
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, v, 0.0, u));
  *nfree = nr;
  *error = h1_error(s, u);
  if (eta) TEST_OK(ctx, fcm_space_stress_jumps(s, &mat, u, eta));
  free(f), free(b), free(g), free(v), free(u), free(con), free(free_dof);
  fcm_csr_destroy(&Kr);
  fcm_csr_destroy(&T);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&s);
}

static int by_eta_desc(const void *a, const void *b)
{
  const double x = *(const double *)a, y = *(const double *)b;
  return (x < y) - (x > y);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  static const int sizes[] = {2, 4, 6, 8, 12, 16, 20, 24};
  double un[8], ue[8];
  printf("uniform   n  free DOFs  cells  H1 error\n");
  for (int k = 0; k < 8; k++) {
    fcm_mesh *m = NULL;
    const fcm_index n3[3] = {sizes[k], sizes[k], sizes[k]};
    fcm_index nf = 0;
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &m));
    solve(ctx, m, &nf, &ue[k], NULL);
    un[k] = (double)nf;
    printf("        %3d  %9lld  %5lld  %.4e\n", sizes[k], (long long)nf,
           (long long)fcm_mesh_num_cells(m), ue[k]);
    fcm_mesh_destroy(&m);
  }
  printf("adaptive step  free DOFs  cells  max level  H1 error\n");
  fcm_mesh *m = NULL;
  const fcm_index n2[3] = {2, 2, 2};
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, FCM_ELEMENT_HEX8, lo, hi, n2, NULL, &m));
  double a_err[12], a_dofs[12], a_cells[12];
  for (int step = 0; step < 12; step++) {
    const fcm_index nc = fcm_mesh_num_cells(m);
    double *eta = calloc((size_t)nc, sizeof *eta), *sorted = calloc((size_t)nc, sizeof *sorted);
    fcm_index nf = 0;
    solve(ctx, m, &nf, &a_err[step], eta);
    a_dofs[step] = (double)nf, a_cells[step] = (double)nc;
    printf("         %4d  %9lld  %5lld  %9d  %.4e\n", step, (long long)nf, (long long)nc,
           fcm_mesh_max_level(m), a_err[step]);
    /* Doerfler: the largest indicators holding half of sum eta^2 */
    double total = 0.0, acc = 0.0, cut = HUGE_VAL;
    for (fcm_index c = 0; c < nc; c++)
      sorted[c] = eta[c] * eta[c], total += sorted[c];
    qsort(sorted, (size_t)nc, sizeof *sorted, by_eta_desc);
    for (fcm_index c = 0; c < nc && acc < 0.5 * total; c++)
      acc += sorted[c], cut = sorted[c];
    unsigned char *flags = calloc((size_t)nc, 1);
    for (fcm_index c = 0; c < nc; c++)
      flags[c] = eta[c] * eta[c] >= cut;
    fcm_mesh *next = NULL;
    if (step < 11) TEST_OK(ctx, fcm_mesh_create_refined(ctx, m, flags, &next));
    free(eta), free(sorted), free(flags);
    if (next) fcm_mesh_destroy(&m), m = next;
  }
  fcm_mesh_destroy(&m);
  /* the adaptive DOFs and cells at each uniform grid's error */
  printf(
      "uniform n  error       uniform DOFs  adaptive DOFs  ratio  uniform cells  adaptive cells  "
      "ratio\n");
  for (int k = 1; k < 8; k++) {
    int j = 0;
    while (j < 10 && a_err[j + 1] > ue[k])
      j++;
    const double t = log(ue[k] / a_err[j]) / log(a_err[j + 1] / a_err[j]);
    const double dofs = a_dofs[j] * pow(a_dofs[j + 1] / a_dofs[j], t);
    const double cells = a_cells[j] * pow(a_cells[j + 1] / a_cells[j], t);
    const double ucells = (double)sizes[k] * sizes[k] * sizes[k];
    printf("%9d  %.4e  %12.0f  %13.0f  %5.1f  %13.0f  %14.0f  %5.1f\n", sizes[k], ue[k], un[k],
           dofs, un[k] / dofs, ucells, cells, ucells / cells);
    if (k == 7) TEST_TRUE(un[k] >= 4.0 * dofs);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
