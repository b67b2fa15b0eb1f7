/* Refinement during a run (fcm_integrator_create_refined()), Hex8 and Hex20: a spinning body
 * held at its face x = 0 falls under gravity for 3 steps of generalized-alpha on an octree
 * refined in a corner; then the cells near the held face are split once more and the run
 * continues on the refined space.
 * - the total mass (1ᵀ M 1 / 3), the linear and angular momentum and the kinetic energy after
 *   the refinement equal those before to 1e-12 relative (the fields are reproduced exactly and
 *   the mass rule integrates the products exactly);
 * - the displacement, velocity and acceleration of the new space evaluated at every old node
 *   equal the old values there (1e-12 of the largest), and the new fields are continuous
 *   (u = T u_free, 1e-13);
 * - time, step count and load work carried; the held face's new nodes are held: more DOFs held
 *   than before, and after 2 more steps every node of the face is still at rest (exactly 0);
 * - refused: a NULL argument, an integrator not set up, a space of another element type, an
 *   integrator on a cut space (a box body cut through by a plane: DOF copies);
 * - allocation failures (Hex8; the k-th failing, k = 0, 1, ...): FCM_ERR_ALLOC, no output, no
 *   leak. */
#include "alloc_loop.h"
#include "sim_util.h"

#include <string.h>

static fcm_status base_mesh(fcm_ctx *ctx, fcm_element_type type, fcm_mesh **mesh)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1.0, 0.5, 0.5};
  const fcm_index cells[3] = {2, 1, 1};
  fcm_octree_options o = fcm_octree_options_default();
  o.region_level = 1;
  o.region_hi[0] = o.region_hi[1] = o.region_hi[2] = 0.1;
  return fcm_mesh_create_octree(ctx, type, lo, hi, cells, &o, mesh);
}

/* The cells meeting x <= 0.3 split once more. */
static fcm_status refined_mesh(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_mesh **out)
{
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  unsigned char *flags = calloc((size_t)nc, 1);
  double X[3 * FCM_ELEMENT_MAX_NODES];
  for (fcm_index c = 0; c < nc; c++) {
    fcm_mesh_cell_coords(mesh, c, X);
    double xmin = X[0];
    for (int a = 1; a < fcm_mesh_nodes_per_cell(mesh); a++)
      xmin = fmin(xmin, X[3 * a]);
    flags[c] = xmin <= 0.3;
  }
  fcm_status st = fcm_mesh_create_refined(ctx, mesh, flags, out);
  free(flags);
  return st;
}

/* Relative continuity defect of a field: max |T u_free - u| / max |u|. */
static double jump(fcm_ctx *ctx, const fcm_space *space, const double *u)
{
  fcm_csr *T = NULL;
  const fcm_index n = fcm_space_num_dofs(space);
  fcm_index *free_dof = malloc(sizeof *free_dof * (size_t)n), nf = 0;
  TEST_OK(ctx, fcm_space_hanging_matrix_create(space, free_dof, &T));
  fcm_csr_get_size(T, NULL, &nf, NULL);
  double *uf = calloc((size_t)nf + 1, sizeof *uf), *Tu = calloc((size_t)n, sizeof *Tu);
  for (fcm_index d = 0; d < n; d++)
    if (free_dof[d] >= 0) uf[free_dof[d]] = u[d];
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, uf, 0.0, Tu));
  double dmax = 0.0, umax = 0.0;
  for (fcm_index d = 0; d < n; d++)
    dmax = fmax(dmax, fabs(Tu[d] - u[d])), umax = fmax(umax, fabs(u[d]));
  free(uf), free(Tu), free(free_dof);
  fcm_csr_destroy(&T);
  return umax > 0.0 ? dmax / umax : 0.0;
}

/* Total mass: 1ᵀ M 1 / 3 (M holds rho N_a N_b on each of the three components). */
static double total_mass(const fcm_integrator *integ)
{
  const fcm_csr *M = fcm_integrator_mass(integ);
  fcm_index nnz = 0;
  fcm_csr_get_size(M, NULL, NULL, &nnz);
  const double *val = fcm_csr_values_read(M);
  double m = 0.0;
  for (fcm_index k = 0; k < nnz; k++)
    m += val[k];
  return m / 3.0;
}

/* max over the old nodes of |new field there - old field| / max |old field|. */
static double at_old_nodes(fcm_ctx *ctx, const fcm_space *from, const double *x_old,
                           const fcm_space *to, const double *x_new)
{
  const fcm_mesh *mesh = fcm_space_mesh(from);
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  double *X = malloc(sizeof *X * 3 * (size_t)nn), *xi = malloc(sizeof *xi * 3 * (size_t)nn);
  double *val = malloc(sizeof *val * 3 * (size_t)nn);
  fcm_index *cell = malloc(sizeof *cell * (size_t)nn), *node = malloc(sizeof *node * (size_t)nn);
  fcm_index num = 0;
  for (fcm_index a = 0; a < nn; a++) {
    if (fcm_space_node_dof(from, a) < 0) continue;
    memcpy(X + 3 * num, fcm_mesh_coords(mesh) + 3 * a, 3 * sizeof *X);
    node[num++] = a;
  }
  TEST_OK(ctx, fcm_space_locate(to, num, X, cell, xi, NULL));
  TEST_OK(ctx, fcm_space_interpolate(to, num, cell, xi, x_new, val));
  double err = 0.0, scale = 0.0;
  for (fcm_index i = 0; i < num; i++)
    for (int c = 0; c < 3; c++) {
      const double o = x_old[fcm_space_node_dof(from, node[i]) + c];
      err = fmax(err, fabs(val[3 * i + c] - o));
      scale = fmax(scale, fabs(o));
    }
  free(X), free(xi), free(val), free(cell), free(node);
  return scale > 0.0 ? err / scale : err;
}

static void check_conserved(fcm_ctx *ctx, fcm_integrator *a, fcm_integrator *b)
{
  double pa[3], pb[3], La[3], Lb[3], ka = 0.0, kb = 0.0;
  TEST_OK(ctx, fcm_integrator_momentum(a, pa, La));
  TEST_OK(ctx, fcm_integrator_momentum(b, pb, Lb));
  TEST_OK(ctx, fcm_integrator_energy(a, &ka, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_energy(b, &kb, NULL, NULL));
  const double ma = total_mass(a), mb = total_mass(b);
  double sp = 0.0, sL = 0.0, dp = 0.0, dL = 0.0;
  for (int i = 0; i < 3; i++) {
    sp = fmax(sp, fabs(pa[i])), sL = fmax(sL, fabs(La[i]));
    dp = fmax(dp, fabs(pb[i] - pa[i])), dL = fmax(dL, fabs(Lb[i] - La[i]));
  }
  printf("  mass %.15g -> %.15g (rel %.1e); momentum rel %.1e; angular rel %.1e; kinetic "
         "%.15g -> %.15g (rel %.1e)\n",
         ma, mb, fabs(mb - ma) / ma, dp / sp, dL / sL, ka, kb, fabs(kb - ka) / ka);
  TEST_NEAR(mb, ma, 1e-12, 0.0);
  TEST_NEAR(mb, 800.0 * 0.25, 1e-12, 0.0);
  TEST_TRUE(sp > 0.0 && dp <= 1e-12 * sp);
  TEST_TRUE(sL > 0.0 && dL <= 1e-12 * sL);
  TEST_NEAR(kb, ka, 1e-12, 0.0);
}

static void run(fcm_ctx *ctx, fcm_element_type type)
{
  fcm_mesh *mesh = NULL, *fine = NULL;
  fcm_space *space = NULL, *fspace = NULL;
  fcm_integrator *integ = NULL, *next = NULL;
  TEST_OK(ctx, base_mesh(ctx, type, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.35, 800.0};
  const double g[3] = {0.0, 0.0, -9.81};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.02;
  o.scheme = FCM_SCHEME_GENERALIZED_ALPHA;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, g, NULL, NULL));
  const double *X = fcm_mesh_coords(mesh);
  fcm_index *face = malloc(sizeof *face * (size_t)fcm_mesh_num_nodes(mesh)), nf = 0;
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++)
    if (X[3 * a] == 0.0) face[nf++] = a;
  fcm_motion hold = fcm_motion_default();
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nf, face, &hold, NULL));
  free(face);
  /* refusals: not set up; NULL */
  TEST_OK(ctx, refined_mesh(ctx, mesh, &fine));
  TEST_OK(ctx, fcm_space_create(ctx, fine, NULL, &fspace));
  TEST_ERR(ctx, fcm_integrator_create_refined(integ, fspace, &next), FCM_ERR_ARG, "set up");
  TEST_TRUE(next == NULL);
  TEST_ERR(ctx, fcm_integrator_create_refined(integ, NULL, &next), FCM_ERR_ARG, "NULL");
  TEST_TRUE(fcm_integrator_create_refined(NULL, fspace, &next) == FCM_ERR_ARG);
  TEST_OK(ctx, fcm_integrator_setup(integ));
  const double v0[3] = {0.3, -0.2, 0.1}, omega[3] = {1.0, 2.0, 3.0}, c[3] = {0.2, 0.1, 0.4};
  TEST_OK(ctx, fcm_integrator_set_rigid_velocity(integ, v0, omega, c));
  for (int s = 0; s < 3; s++)
    TEST_OK(ctx, fcm_integrator_step(integ, NULL));
  printf("%s: %lld cells (%lld hanging pairs) -> %lld cells (%lld)\n",
         fcm_element_get_info(type)->name, (long long)fcm_mesh_num_cells(mesh),
         (long long)fcm_mesh_num_hanging(mesh), (long long)fcm_mesh_num_cells(fine),
         (long long)fcm_mesh_num_hanging(fine));
  TEST_TRUE(fcm_mesh_num_cells(fine) > fcm_mesh_num_cells(mesh));

  TEST_OK(ctx, fcm_integrator_create_refined(integ, fspace, &next));
  TEST_TRUE(fcm_integrator_time(next) == fcm_integrator_time(integ));
  TEST_TRUE(fcm_integrator_step_count(next) == 3);
  TEST_TRUE(fcm_integrator_load_work(next) == fcm_integrator_load_work(integ));
  fcm_integrator_setup_info si;
  fcm_integrator_get_setup_info(next, &si);
  TEST_TRUE(si.refine_extrapolated == 0);
  check_conserved(ctx, integ, next);
  const fcm_index n0 = fcm_space_num_dofs(space), n1 = fcm_space_num_dofs(fspace);
  double *a0 = malloc(sizeof *a0 * (size_t)n0), *a1 = malloc(sizeof *a1 * (size_t)n1);
  TEST_TRUE(fcm_integrator_get_acceleration(integ, a0) == 1);
  TEST_TRUE(fcm_integrator_get_acceleration(next, a1) == 1);
  const double eu = at_old_nodes(ctx, space, fcm_integrator_displacement(integ), fspace,
                                 fcm_integrator_displacement(next));
  const double ev = at_old_nodes(ctx, space, fcm_integrator_velocity(integ), fspace,
                                 fcm_integrator_velocity(next));
  const double ea = at_old_nodes(ctx, space, a0, fspace, a1);
  printf("  at the old nodes: u %.1e, v %.1e, a %.1e; continuity u %.1e, v %.1e; held DOFs %lld "
         "-> %lld\n",
         eu, ev, ea, jump(ctx, fspace, fcm_integrator_displacement(next)),
         jump(ctx, fspace, fcm_integrator_velocity(next)),
         (long long)fcm_integrator_num_constrained(integ),
         (long long)fcm_integrator_num_constrained(next));
  TEST_TRUE(eu <= 1e-12 && ev <= 1e-12 && ea <= 1e-12);
  TEST_TRUE(jump(ctx, fspace, fcm_integrator_displacement(next)) <= 1e-13);
  TEST_TRUE(jump(ctx, fspace, fcm_integrator_velocity(next)) <= 1e-13);
  TEST_TRUE(fcm_integrator_num_constrained(next) > fcm_integrator_num_constrained(integ));
  free(a0), free(a1);

  /* the run goes on; the held face stays at rest, its new nodes too */
  for (int s = 0; s < 2; s++)
    TEST_OK(ctx, fcm_integrator_step(next, NULL));
  TEST_TRUE(fcm_integrator_step_count(next) == 5);
  const double *Xf = fcm_mesh_coords(fine), *u = fcm_integrator_displacement(next);
  double umax = 0.0, uface = 0.0;
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(fine); a++)
    for (int i = 0; i < 3; i++) {
      const double ui = fabs(u[fcm_space_node_dof(fspace, a) + i]);
      umax = fmax(umax, ui);
      if (Xf[3 * a] == 0.0) uface = fmax(uface, ui);
    }
  TEST_TRUE(umax > 1e-3 && uface == 0.0);

  /* a space of another element type */
  fcm_mesh *other = NULL;
  fcm_space *ospace = NULL;
  fcm_integrator *bad = NULL;
  TEST_OK(ctx,
          base_mesh(ctx, type == FCM_ELEMENT_HEX8 ? FCM_ELEMENT_HEX20 : FCM_ELEMENT_HEX8, &other));
  TEST_OK(ctx, fcm_space_create(ctx, other, NULL, &ospace));
  TEST_ERR(ctx, fcm_integrator_create_refined(next, ospace, &bad), FCM_ERR_ARG, "element type");
  TEST_TRUE(bad == NULL);
  fcm_space_destroy(&ospace);
  fcm_mesh_destroy(&other);

  fcm_integrator_destroy(&next);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&fspace);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&fine);
  fcm_mesh_destroy(&mesh);
}

typedef struct refine_case {
  fcm_ctx *ctx;
  const fcm_integrator *old;
  const fcm_space *space;
  fcm_integrator *out;
} refine_case;

static fcm_status refine_call(void *user)
{
  refine_case *c = user;
  c->out = (fcm_integrator *)c; /* must be reset to NULL on failure */
  fcm_status st = fcm_integrator_create_refined(c->old, c->space, &c->out);
  return st != FCM_OK && c->out ? FCM_ERR_INTERNAL : st;
}

static void refine_release(void *user)
{
  fcm_integrator_destroy(&((refine_case *)user)->out);
}

/* The allocation loop on a failing context, and the refusal of a cut space. */
static void alloc_and_cut(fcm_element_type type)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return;
  fcm_mesh *mesh = NULL, *fine = NULL;
  fcm_space *space = NULL, *fspace = NULL, *cspace = NULL;
  fcm_integrator *integ = NULL, *cinteg = NULL, *bad = NULL;
  fcm_geometry *body = NULL;
  fcm_cell_rules *rules = NULL, *cut = NULL;
  fcm_surface *plane = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.35, 800.0};
  const double g[3] = {0.0, 0.0, -9.81};
  TEST_OK(ctx, base_mesh(ctx, type, &mesh));
  TEST_OK(ctx, refined_mesh(ctx, mesh, &fine));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  TEST_OK(ctx, fcm_space_create(ctx, fine, NULL, &fspace));
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, NULL, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, g, NULL, NULL));
  const fcm_index held[2] = {0, 1};
  const fcm_motion hold = fcm_motion_default();
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, 2, held, &hold, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  refine_case c = {ctx, integ, fspace, NULL};
  if (type == FCM_ELEMENT_HEX8) /* the same code for Hex20, only slower */
    alloc_loop(ctx, &f, "integrator_create_refined", refine_call, refine_release, &c, 10, 4000);

  const double lo[3] = {0, 0, 0}, hi[3] = {1.0, 0.5, 0.5}, clo[3] = {-1, -1, -1};
  const double chi[3] = {2, 2, 2}, p[3] = {0.43, 0.25, 0.25}, n[3] = {1, 0.2, 0.1};
  const fcm_index nb[3] = {1, 1, 1};
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, nb, &body));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, body, NULL, &rules));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, n, clo, chi, &plane));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, body, rules, plane, &cut));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, cut, &cspace));
  TEST_TRUE(cspace && fcm_space_num_bodies(cspace) == 2);
  TEST_OK(ctx, fcm_integrator_create(ctx, cspace, &mat, NULL, &cinteg));
  TEST_OK(ctx, fcm_integrator_setup(cinteg));
  TEST_ERR(ctx, fcm_integrator_create_refined(cinteg, fspace, &bad), FCM_ERR_UNSUPPORTED,
           "before the first cut");
  TEST_TRUE(bad == NULL);
  fcm_integrator_destroy(&cinteg);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&cspace);
  fcm_space_destroy(&fspace);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&cut);
  fcm_cell_rules_destroy(&rules);
  fcm_surface_destroy(&plane);
  fcm_geometry_destroy(&body);
  fcm_mesh_destroy(&fine);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  run(ctx, type);
  alloc_and_cut(type);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
