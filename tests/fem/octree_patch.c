/* Patch tests across hanging nodes, Hex8 and Hex20 on an octree background refined toward a
 * sphere (levels 0..3, chains of constraints at 2:1), and the stress-jump indicator on their
 * solutions (zero for the affine field, its definition for the quadratic one):
 * - continuity: a random field u = T u_free, evaluated on both sides of every face and edge at
 *   sample points, agrees to rounding (without the constraints it jumps);
 * - affine displacement with affine Dirichlet data: the constrained static solve
 *   T^T K T u_free = 0 reproduces it at every node, hanging ones included, to 1e-12;
 * - Hex20: a quadratic displacement with its constant body force (the serendipity space holds
 *   every quadratic) is reproduced exactly too. */
#include "fem_util.h"
#include "fem/fem_impl.h"

static double sphere(const double x[3], void *user)
{
  (void)user;
  return sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 0.6;
}

static const double lam_mu[2] = {2.0e5 * 0.3 / (1.3 * 0.4), 2.0e5 / 2.6}; /* E 2e5, nu 0.3 */

static void affine(const double x[3], double u[3])
{
  static const double A[9] = {1e-3, 2e-3, -1e-3, 0.5e-3, -2e-3, 1.5e-3, 3e-3, 1e-3, 2.5e-3};
  static const double c[3] = {0.1, -0.2, 0.3};
  for (int i = 0; i < 3; i++)
    u[i] = c[i] + A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2];
}

/* u = a (x^2, y z, 0) + affine: -div sigma = -a ((2 lam + 4 mu), 0, (lam + mu)). */
static const double qa = 1e-3;
static void quadratic(const double x[3], double u[3])
{
  affine(x, u);
  u[0] += qa * x[0] * x[0];
  u[1] += qa * x[1] * x[2];
}

/* The field at physical point x of axis-aligned cell c (nodal DOF values u). */
static void eval_in_cell(const fcm_space *s, fcm_index c, const double *u, const double x[3],
                         double out[3])
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const int npc = fcm_mesh_nodes_per_cell(m);
  const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
  const double *X = fcm_mesh_coords(m);
  double xi[3], N[20];
  for (int d = 0; d < 3; d++) {
    const double lo = X[3 * cn[0] + d], hi = X[3 * cn[6] + d];
    xi[d] = 2.0 * (x[d] - lo) / (hi - lo) - 1.0;
  }
  fcm_element_eval_shape(fcm_mesh_element_type(m), xi, N);
  out[0] = out[1] = out[2] = 0.0;
  for (int a = 0; a < npc; a++)
    for (int i = 0; i < 3; i++)
      out[i] += N[a] * u[fcm_space_node_dof(s, cn[a]) + i];
}

/* Largest jump of u between the cells whose closed boxes hold the sample points on the faces
 * and edges of every cell (5 x 5 points per face). */
static double max_jump(const fcm_space *s, const double *u)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const fcm_index nc = fcm_mesh_num_cells(m);
  const int npc = fcm_mesh_nodes_per_cell(m);
  const double *X = fcm_mesh_coords(m);
  double jump = 0.0;
  for (fcm_index c = 0; c < nc; c++) {
    const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
    double lo[3], hi[3];
    for (int d = 0; d < 3; d++)
      lo[d] = X[3 * cn[0] + d], hi[d] = X[3 * cn[6] + d];
    for (int p = 0; p < 125; p++) {
      const int ijk[3] = {p % 5, (p / 5) % 5, p / 25};
      if (ijk[0] % 4 && ijk[1] % 4 && ijk[2] % 4) continue; /* boundary points only */
      double x[3], u0[3];
      for (int d = 0; d < 3; d++)
        x[d] = lo[d] + 0.25 * ijk[d] * (hi[d] - lo[d]) +
               0.013 * (ijk[d] % 4 ? 1 : 0) * (hi[d] - lo[d]);
      eval_in_cell(s, c, u, x, u0);
      for (fcm_index c2 = 0; c2 < nc; c2++) {
        if (c2 == c) continue;
        const fcm_index *cm = fcm_mesh_cells(m) + (size_t)npc * c2;
        int in = 1;
        for (int d = 0; d < 3; d++)
          in &= x[d] >= X[3 * cm[0] + d] - 1e-14 && x[d] <= X[3 * cm[6] + d] + 1e-14;
        if (!in) continue;
        double u1[3];
        eval_in_cell(s, c2, u, x, u1);
        for (int i = 0; i < 3; i++)
          jump = fmax(jump, fabs(u1[i] - u0[i]));
      }
    }
  }
  return jump;
}

/* The stress of the quadratic field at x, components in any fixed order. */
static void quadratic_stress(const double x[3], double sig[6])
{
  const double lam = lam_mu[0], mu = lam_mu[1];
  double G[9], e[6]; /* grad u by central differences is exact for a quadratic: use it */
  for (int j = 0; j < 3; j++) {
    double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]}, up[3], um[3];
    xp[j] += 0.5, xm[j] -= 0.5;
    quadratic(xp, up), quadratic(xm, um);
    for (int i = 0; i < 3; i++)
      G[3 * i + j] = up[i] - um[i];
  }
  e[0] = G[0], e[1] = G[4], e[2] = G[8];
  e[3] = 0.5 * (G[1] + G[3]), e[4] = 0.5 * (G[5] + G[7]), e[5] = 0.5 * (G[2] + G[6]);
  const double tr = e[0] + e[1] + e[2];
  for (int k = 0; k < 6; k++)
    sig[k] = 2.0 * mu * e[k] + (k < 3 ? lam * tr : 0.0);
}

/* eta of fcm_space_stress_jumps() against its definition for the quadratic field. */
static void check_jumps(const fcm_mesh *m, const double *eta)
{
  const fcm_index nc = fcm_mesh_num_cells(m), nn = fcm_mesh_num_nodes(m);
  const int npc = fcm_mesh_nodes_per_cell(m);
  const double *X = fcm_mesh_coords(m);
  double *lo = malloc(sizeof *lo * 6 * (size_t)nn), *hi = malloc(sizeof *hi * 6 * (size_t)nn);
  for (fcm_index i = 0; i < 6 * nn; i++)
    lo[i] = HUGE_VAL, hi[i] = -HUGE_VAL;
  for (int pass = 0; pass < 2; pass++)
    for (fcm_index c = 0; c < nc; c++) {
      const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
      double xc[3], sig[6], h = 0.0, jump = 0.0;
      for (int d = 0; d < 3; d++)
        xc[d] = 0.5 * (X[3 * cn[0] + d] + X[3 * cn[6] + d]);
      h = X[3 * cn[6]] - X[3 * cn[0]];
      quadratic_stress(xc, sig);
      for (int a = 0; a < npc; a++)
        for (int k = 0; k < 6; k++) {
          double *l = lo + 6 * cn[a] + k, *g = hi + 6 * cn[a] + k;
          if (pass == 0)
            *l = fmin(*l, sig[k]), *g = fmax(*g, sig[k]);
          else
            jump = fmax(jump, *g - *l);
        }
      if (pass == 1) TEST_NEAR(eta[c], sqrt(h * h * h) * jump, 1e-8, 1e-9);
    }
  free(lo), free(hi);
}

/* Solve T^T K T v = T^T f with the exact field prescribed at the free DOFs of boundary nodes;
 * return the largest nodal error of u = T v against the exact field. */
static double constrained_solve(fcm_ctx *ctx, const fcm_space *s, const fcm_csr *K,
                                const fcm_csr *T, const fcm_index *free_dof, const double *f,
                                void (*exact)(const double *, double *), double *u_out)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const double *X = fcm_mesh_coords(m);
  fcm_index n = 0, nr = 0;
  fcm_csr_get_size(T, &n, &nr, NULL);
  fcm_csr *Kr = NULL;
  TEST_OK(ctx, fcm_csr_create_ptap(ctx, K, T, &Kr));
  double *b = calloc((size_t)nr, sizeof *b), *v = calloc((size_t)nr, sizeof *v);
  double *g = calloc((size_t)nr, sizeof *g), *u = calloc((size_t)n, sizeof *u);
  unsigned char *con = calloc((size_t)nr, 1);
  const fcm_index *tp = fcm_csr_row_ptr(T);
  const int *tc = fcm_csr_col_idx(T);
  const double *tv = fcm_csr_values((fcm_csr *)T);
  for (fcm_index i = 0; i < n; i++) /* b = T^T f */
    for (fcm_index p = tp[i]; p < tp[i + 1]; p++)
      b[tc[p]] += tv[p] * f[i];
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(m); a++) {
    const fcm_index d0 = fcm_space_node_dof(s, a);
    if (d0 < 0 || free_dof[d0] < 0) continue;
    int boundary = 0;
    for (int d = 0; d < 3; d++)
      boundary |= X[3 * a + d] == 0.0 || X[3 * a + d] == 1.0;
    if (!boundary) continue;
    double ue[3];
    exact(X + 3 * a, ue);
    for (int i = 0; i < 3; i++) {
      con[free_dof[d0 + i]] = 1;
      g[free_dof[d0 + i]] = ue[i];
    }
  }
  fcm__eliminate_marked(Kr, b, con, g);
  TEST_OK(ctx, direct_solve(ctx, Kr, b, v));
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, v, 0.0, u));
  double err = 0.0;
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(m); a++) {
    double ue[3];
    exact(X + 3 * a, ue);
    for (int i = 0; i < 3; i++)
      err = fmax(err, fabs(u[fcm_space_node_dof(s, a) + i] - ue[i]));
  }
  memcpy(u_out, u, sizeof *u * (size_t)n);
  free(b), free(v), free(g), free(u), free(con);
  fcm_csr_destroy(&Kr);
  return err;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL, *T = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index cells[3] = {2, 2, 2};
  fcm_octree_options o = fcm_octree_options_default();
  o.surface = sphere;
  o.surface_level = 3;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, cells, &o, &mesh));
  TEST_TRUE(fcm_mesh_max_level(mesh) == 3);
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  const fcm_index n = fcm_space_num_dofs(space);
  fcm_index *free_dof = calloc((size_t)n, sizeof *free_dof);
  TEST_OK(ctx, fcm_space_hanging_matrix_create(space, free_dof, &T));
  fcm_index nr = 0, nrows = 0;
  fcm_csr_get_size(T, &nrows, &nr, NULL);
  TEST_TRUE(nrows == n && nr < n && nr > 0);

  /* the mesh has chains: a hanging node on a cell one of whose nodes hangs too */
  unsigned char *hangs = calloc((size_t)fcm_mesh_num_nodes(mesh), 1);
  for (fcm_index i = 0; i < fcm_mesh_num_hanging(mesh); i++) {
    fcm_index node = 0;
    fcm_mesh_get_hanging(mesh, i, NULL, &node, NULL);
    hangs[node] = 1;
  }
  int chains = 0;
  for (fcm_index i = 0; i < fcm_mesh_num_hanging(mesh); i++) {
    fcm_index c = 0;
    fcm_mesh_get_hanging(mesh, i, &c, NULL, NULL);
    for (int a = 0; a < fcm_mesh_nodes_per_cell(mesh); a++)
      chains |= hangs[fcm_mesh_cells(mesh)[(size_t)fcm_mesh_nodes_per_cell(mesh) * c + a]];
  }
  TEST_TRUE(chains);
  free(hangs);

  /* continuity of u = T v for a random v; the unconstrained field (hanging values random too)
   * jumps */
  double *v = calloc((size_t)nr, sizeof *v), *u = calloc((size_t)n, sizeof *u);
  unsigned long long seed = 99;
  for (fcm_index i = 0; i < nr; i++)
    v[i] = urand(&seed);
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, v, 0.0, u));
  TEST_NEAR(max_jump(space, u), 0.0, 0.0, 1e-13);
  for (fcm_index i = 0; i < n; i++)
    if (free_dof[i] < 0) u[i] = urand(&seed);
  TEST_TRUE(max_jump(space, u) > 1e-3);
  /* the constraint rows sum to one (constants are reproduced) */
  for (fcm_index i = 0; i < nr; i++)
    v[i] = 1.0;
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, v, 0.0, u));
  for (fcm_index i = 0; i < n; i++)
    TEST_NEAR(u[i], 1.0, 0.0, 1e-14);

  /* patch tests */
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  fcm_material mat = {FCM_MATERIAL_LINEAR, 2.0e5, 0.3, 1.0};
  TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, K));
  double *f = calloc((size_t)n, sizeof *f);
  double *us = calloc((size_t)n, sizeof *us),
         *eta = calloc((size_t)fcm_mesh_num_cells(mesh), sizeof *eta);
  TEST_NEAR(constrained_solve(ctx, space, K, T, free_dof, f, affine, us), 0.0, 0.0, 1e-12);
  /* the stress-jump indicator vanishes for the constant stress of an affine field (|sigma| ~
   * E |grad u| = 600) */
  TEST_OK(ctx, fcm_space_stress_jumps(space, &mat, us, eta));
  double eta_max = 0.0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++)
    eta_max = fmax(eta_max, eta[c]);
  TEST_NEAR(eta_max, 0.0, 0.0, 1e-9 * 600.0);
  if (type == FCM_ELEMENT_HEX20) {
    const double lam = lam_mu[0], mu = lam_mu[1];
    const double accel[3] = {-qa * (2 * lam + 4 * mu), 0.0, -qa * (lam + mu)};
    TEST_OK(ctx, fcm_assemble_body_force(space, &mat, accel, NULL, f));
    TEST_NEAR(constrained_solve(ctx, space, K, T, free_dof, f, quadratic, us), 0.0, 0.0, 1e-12);
    /* its stress is linear in x: the cell averages are the values at the centres, and the
     * indicator is sqrt(|c|) x the largest jump of those over the cells at c's nodes */
    TEST_OK(ctx, fcm_space_stress_jumps(space, &mat, us, eta));
    check_jumps(mesh, eta);
  }

  free(f), free(v), free(u), free(free_dof), free(us), free(eta);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&T);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
