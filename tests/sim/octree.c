/* The integrators on octree backgrounds (Hex8, Hex20): the hanging DOFs follow their masters
 * (u = T u_free) inside Newton's method.
 * - static patch test: a linear body on an octree refined to level 2 in a corner region, every
 *   boundary node that does not hang prescribed to an affine field (the hanging ones follow
 *   their masters): the solution is that field at every node, hanging ones included, to 1e-12,
 *   with the direct solver, CG + Jacobi, CG + multigrid and the multigrid solver (the
 *   hierarchy coarsening the octree: at least 3 levels);
 * - a constraint holding a hanging node without its masters is refused; a face pulled at a
 *   constant velocity carries its hanging nodes along exactly;
 * - dynamics: a free Stable Neo-Hookean body spinning under gravity on the same octree, with
 *   backward Euler, Newmark and generalized-alpha: the change of the total momentum equals the
 *   impulse of gravity, m g t, to 1e-10 relative, and the displacement (and the second-order
 *   schemes' acceleration, whose initial value solves the constrained mass system) stays
 *   continuous (equal to T of its free entries, 1e-13);
 * - an octree without refinement runs like the uniform grid of fcm_mesh_create_box(), node by
 *   node (matched by coordinates) to 1e-13 relative (the node and cell numbering differ, so the
 *   sums run in another order). */
#include "sim_util.h"

static void affine(const double x[3], double u[3])
{
  static const double A[9] = {1e-3, 2e-3, -1e-3, 0.5e-3, -2e-3, 1.5e-3, 3e-3, 1e-3, 2.5e-3};
  static const double c[3] = {0.1, -0.2, 0.3};
  for (int i = 0; i < 3; i++)
    u[i] = c[i] + A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2];
}

static fcm_status octree(fcm_ctx *ctx, fcm_element_type type, int level, fcm_mesh **mesh)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1.0, 0.5, 0.5};
  const fcm_index cells[3] = {2, 1, 1};
  fcm_octree_options o = fcm_octree_options_default();
  o.region_level = level;
  o.region_lo[0] = o.region_lo[1] = o.region_lo[2] = 0.0;
  o.region_hi[0] = o.region_hi[1] = o.region_hi[2] = 0.1;
  return fcm_mesh_create_octree(ctx, type, lo, hi, cells, &o, mesh);
}

/* 1 for the nodes that hang on some cell. */
static unsigned char *hanging_nodes(const fcm_mesh *mesh)
{
  unsigned char *h = calloc((size_t)fcm_mesh_num_nodes(mesh), 1);
  for (fcm_index i = 0; i < fcm_mesh_num_hanging(mesh); i++) {
    fcm_index cell, node;
    double xi[3];
    fcm_mesh_get_hanging(mesh, i, &cell, &node, xi);
    h[node] = 1;
  }
  return h;
}

static int on_boundary(const double x[3])
{
  const double hi[3] = {1.0, 0.5, 0.5};
  for (int d = 0; d < 3; d++)
    if (x[d] == 0.0 || x[d] == hi[d]) return 1;
  return 0;
}

static void static_patch(fcm_ctx *ctx, fcm_element_type type, const char *name,
                         fcm_linear_solver solver, fcm_preconditioner pc)
{
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  TEST_OK(ctx, octree(ctx, type, 2, &mesh));
  TEST_TRUE(fcm_mesh_num_hanging(mesh) > 0);
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_material mat = {FCM_MATERIAL_LINEAR, 2.0e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_STATIC;
  o.dt = 1.0;
  o.linear_solver = solver;
  o.preconditioner = pc;
  o.krylov_rtol = 1e-14;
  o.multigrid.coarse_dofs = 30; /* coarsen the octree to its base grid */
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  unsigned char *hang = hanging_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  fcm_index held = 0, held_hanging = 0;
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++) {
    if (!on_boundary(X + 3 * a)) continue;
    if (hang[a]) {
      held_hanging++;
      continue;
    }
    fcm_motion m = fcm_motion_default();
    affine(X + 3 * a, m.velocity); /* u = velocity t, reached at t = dt = 1 */
    m.end = 1.0;
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, 1, &a, &m, NULL));
    held++;
  }
  TEST_TRUE(held > 0 && held_hanging > 0); /* hanging nodes on the boundary follow */
  TEST_OK(ctx, fcm_integrator_setup(integ));
  fcm_step_info info;
  TEST_OK(ctx, fcm_integrator_step(integ, &info));
  TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  const int mg = solver == FCM_LINEAR_MULTIGRID || pc == FCM_PRECOND_MULTIGRID;
  /* the multigrid: the octree's levels 2, 1 and the base grid */
  if (mg) TEST_TRUE(fcm_mg_num_levels(fcm_integrator_multigrid(integ)) >= 3);
  const double *u = fcm_integrator_displacement(integ);
  double err = 0.0;
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++) {
    double ue[3];
    affine(X + 3 * a, ue);
    const fcm_index d = fcm_space_node_dof(space, a);
    for (int i = 0; i < 3; i++)
      err = fmax(err, fabs(u[d + i] - ue[i]));
  }
  printf("%s %s: %lld hanging pairs, affine patch error %.3e\n", name,
         solver == FCM_LINEAR_DIRECT      ? "direct"
         : solver == FCM_LINEAR_MULTIGRID ? "multigrid"
         : pc == FCM_PRECOND_MULTIGRID    ? "cg + multigrid"
                                          : "cg + jacobi",
         (long long)fcm_mesh_num_hanging(mesh), err);
  TEST_TRUE(err <= 1e-12);
  fcm_integrator_destroy(&integ);

  /* a hanging node held alone: its masters are free */
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  fcm_index h = 0;
  while (!hang[h])
    h++;
  fcm_motion m = fcm_motion_default();
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, 1, &h, &m, NULL));
  TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_UNSUPPORTED, "hangs on a coarser cell");
  fcm_integrator_destroy(&integ);
  /* the cell-based preconditioners do not apply the constraints yet */
  o.linear_solver = FCM_LINEAR_CG;
  o.preconditioner = FCM_PRECOND_BLOCK_JACOBI;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_UNSUPPORTED, "block Jacobi");
  fcm_integrator_destroy(&integ);
  free(hang);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
}

/* max |u - T u_free| / max |u| over the DOFs (u = T u_free for a continuous field); 1 for u = 0. */
static double jump(fcm_ctx *ctx, const fcm_space *space, const double *u)
{
  fcm_csr *T = NULL;
  const fcm_index n = fcm_space_num_dofs(space);
  fcm_index *free_dof = malloc(sizeof *free_dof * (size_t)n), nf = 0;
  TEST_OK(ctx, fcm_space_hanging_matrix_create(space, free_dof, &T));
  fcm_csr_get_size(T, NULL, &nf, NULL);
  double *uf = calloc((size_t)nf, sizeof *uf), *Tu = calloc((size_t)n, sizeof *Tu);
  for (fcm_index d = 0; d < n; d++)
    if (free_dof[d] >= 0) uf[free_dof[d]] = u[d];
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, uf, 0.0, Tu));
  double dmax = 0.0, umax = 0.0;
  for (fcm_index d = 0; d < n; d++)
    dmax = fmax(dmax, fabs(Tu[d] - u[d])), umax = fmax(umax, fabs(u[d]));
  free(uf), free(Tu), free(free_dof);
  fcm_csr_destroy(&T);
  return umax > 0.0 ? dmax / umax : 1.0;
}

/* A spinning body falling under gravity for `steps` steps of `scheme` on `mesh`; its
 * displacement and velocity into u, v (num_dofs each, allocated). Checks the momentum against
 * the impulse and the continuity of the fields. */
static void fall(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_time_scheme scheme, int steps, double **u,
                 double **v)
{
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.35, 800.0};
  const double mass = 800.0 * 0.25, g[3] = {0.0, 0.0, -9.81};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.02;
  o.scheme = scheme;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  const double v0[3] = {0.3, -0.2, 0.1}, omega[3] = {1.0, 2.0, 3.0}, c[3] = {0.2, 0.1, 0.4};
  TEST_OK(ctx, fcm_integrator_set_rigid_velocity(integ, v0, omega, c));
  double p0[3], p[3];
  TEST_OK(ctx, fcm_integrator_momentum(integ, p0, NULL));
  /* p = m (v0 + omega x (centre of mass - c)) */
  const double r[3] = {0.5 - c[0], 0.25 - c[1], 0.25 - c[2]};
  const double vc[3] = {v0[0] + omega[1] * r[2] - omega[2] * r[1],
                        v0[1] + omega[2] * r[0] - omega[0] * r[2],
                        v0[2] + omega[0] * r[1] - omega[1] * r[0]};
  for (int i = 0; i < 3; i++)
    TEST_NEAR(p0[i], mass * vc[i], 0.0, 1e-12 * mass);
  int newton = 0;
  for (int s = 1; s <= steps; s++) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    newton += info.newton_iterations;
    TEST_OK(ctx, fcm_integrator_momentum(integ, p, NULL));
    const double t = fcm_integrator_time(integ), scale = mass * (1.0 + 9.81 * t);
    for (int i = 0; i < 3; i++)
      TEST_NEAR(p[i] - p0[i], mass * g[i] * t, 0.0, 1e-10 * scale);
  }
  TEST_TRUE(newton > steps); /* the spin deforms the body: Newton works */
  const double *ui = fcm_integrator_displacement(integ);
  TEST_TRUE(jump(ctx, space, ui) <= 1e-13); /* continuous: u = T u_free */
  if (scheme != FCM_SCHEME_BACKWARD_EULER) {
    double *a = malloc(sizeof *a * (size_t)fcm_space_num_dofs(space));
    TEST_TRUE(a && fcm_integrator_get_acceleration(integ, a) == 1);
    /* a = (u - u~) / (beta h^2) - ...: the round-off of the continuous u, amplified by
     * 1 / (beta h^2) = 1e4 */
    if (a) TEST_TRUE(jump(ctx, space, a) <= 1e-11);
    free(a);
  }
  *u = malloc(sizeof **u * 3 * (size_t)fcm_mesh_num_nodes(mesh));
  *v = malloc(sizeof **v * 3 * (size_t)fcm_mesh_num_nodes(mesh));
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++) /* in node order */
    for (int i = 0; i < 3; i++) {
      (*u)[3 * a + i] = ui[fcm_space_node_dof(space, a) + i];
      (*v)[3 * a + i] = fcm_integrator_velocity(integ)[fcm_space_node_dof(space, a) + i];
    }
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
}

/* The face x = 0 pulled at a constant velocity (one constraint holding all its nodes, hanging ones
 * included: they follow their masters) for 4 backward Euler steps from an initial velocity that
 * jumps at the hanging nodes: every node of the face, the hanging ones too, is at velocity t
 * (1e-12), and the displacement is continuous after every step. */
static void pulled_face(fcm_ctx *ctx, const fcm_mesh *mesh)
{
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.35, 800.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.02;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  unsigned char *hang = hanging_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  fcm_index *face = malloc(sizeof *face * (size_t)nn), nf = 0, nh = 0;
  for (fcm_index a = 0; a < nn; a++)
    if (X[3 * a] == 0.0) face[nf++] = a, nh += hang[a];
  TEST_TRUE(nh > 0);
  fcm_motion m = fcm_motion_default();
  m.velocity[0] = -0.5, m.velocity[2] = 0.25;
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nf, face, &m, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  /* an initial velocity that jumps at the hanging nodes: the first step's guess is made
   * continuous, and so is every displacement after it */
  const fcm_index n = fcm_space_num_dofs(space);
  double *u0 = calloc((size_t)n, sizeof *u0), *v0 = calloc((size_t)n, sizeof *v0);
  for (fcm_index d = 0; d < n; d++)
    v0[d] = 0.1 * sin(1.7 * (double)d);
  TEST_OK(ctx, fcm_integrator_set_state(integ, u0, v0, 0.0, 0));
  for (int s = 0; s < 4; s++) {
    TEST_OK(ctx, fcm_integrator_step(integ, NULL));
    TEST_TRUE(jump(ctx, space, fcm_integrator_displacement(integ)) <= 1e-13);
  }
  free(u0), free(v0);
  const double t = fcm_integrator_time(integ), *u = fcm_integrator_displacement(integ);
  double err = 0.0;
  for (fcm_index k = 0; k < nf; k++)
    for (int i = 0; i < 3; i++)
      err = fmax(err, fabs(u[fcm_space_node_dof(space, face[k]) + i] - m.velocity[i] * t));
  TEST_TRUE(err <= 1e-12);
  free(face), free(hang);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL, *box = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  static_patch(ctx, type, argv[1], FCM_LINEAR_DIRECT, FCM_PRECOND_JACOBI);
  static_patch(ctx, type, argv[1], FCM_LINEAR_CG, FCM_PRECOND_JACOBI);
  static_patch(ctx, type, argv[1], FCM_LINEAR_CG, FCM_PRECOND_MULTIGRID);
  static_patch(ctx, type, argv[1], FCM_LINEAR_MULTIGRID, FCM_PRECOND_JACOBI);

  double *u = NULL, *v = NULL, *ub = NULL, *vb = NULL;
  TEST_OK(ctx, octree(ctx, type, 2, &mesh));
  const fcm_time_scheme schemes[3] = {FCM_SCHEME_BACKWARD_EULER, FCM_SCHEME_NEWMARK,
                                      FCM_SCHEME_GENERALIZED_ALPHA};
  for (int k = 0; k < 3; k++) {
    fall(ctx, mesh, schemes[k], 5, &u, &v);
    free(u), free(v);
  }
  pulled_face(ctx, mesh);
  fcm_mesh_destroy(&mesh);

  /* no refinement: the uniform grid's run */
  const double lo[3] = {0, 0, 0}, hi[3] = {1.0, 0.5, 0.5};
  const fcm_index cells[3] = {2, 1, 1};
  TEST_OK(ctx, octree(ctx, type, 0, &mesh));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &box));
  TEST_TRUE(fcm_mesh_num_nodes(mesh) == fcm_mesh_num_nodes(box));
  fall(ctx, mesh, FCM_SCHEME_BACKWARD_EULER, 5, &u, &v);
  fall(ctx, box, FCM_SCHEME_BACKWARD_EULER, 5, &ub, &vb);
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh), *Xb = fcm_mesh_coords(box);
  double du = 0.0, umax = 0.0;
  int identical = 1;
  for (fcm_index a = 0; a < nn; a++) {
    fcm_index b = 0;
    while (b < nn && (X[3 * a] != Xb[3 * b] || X[3 * a + 1] != Xb[3 * b + 1] ||
                      X[3 * a + 2] != Xb[3 * b + 2]))
      b++;
    TEST_TRUE(b < nn);
    if (b == nn) break;
    for (int i = 0; i < 3; i++) {
      du = fmax(du, fabs(u[3 * a + i] - ub[3 * b + i]));
      du = fmax(du, fabs(v[3 * a + i] - vb[3 * b + i]));
      umax = fmax(umax, fmax(fabs(ub[3 * b + i]), fabs(vb[3 * b + i])));
      identical &= u[3 * a + i] == ub[3 * b + i] && v[3 * a + i] == vb[3 * b + i];
    }
  }
  printf("unrefined octree against the uniform grid: max difference %.3e of %.3e (%s)\n", du, umax,
         identical ? "bitwise equal" : "round-off");
  TEST_TRUE(du <= 1e-13 * umax);
  free(u), free(v), free(ub), free(vb);
  fcm_mesh_destroy(&box);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
