/* Reactions of constraints (fcm_integrator_reaction()). An embedded beam, clamped at one end
 * by the background nodes of a half-space (fictitious nodes included), hangs under gravity:
 * internal forces of an objective material add up to zero force and zero moment, so in
 * equilibrium the reaction is minus the assembled weight (sum of f_ext, which is rho g times
 * the embedded volume up to the stabilization's share) and its moment minus the weight's
 * moment sum (X + u) x f_ext (1e-9). Dynamics (backward Euler): the reaction is the change
 * of momentum per step minus the weight, R = (p_{n+1} - p_n)/h - W (1e-9). Two constraints
 * each report their own share and the shares add up. */
#include "sim_util.h"

static const double grav[3] = {0.0, 0.0, -9.81};

static void cross_add(const double x[3], const double f[3], double m[3])
{
  m[0] += x[1] * f[2] - x[2] * f[1];
  m[1] += x[2] * f[0] - x[0] * f[2];
  m[2] += x[0] * f[1] - x[1] * f[0];
}

/* Background nodes with x < xmax (malloc'ed). */
static fcm_index *nodes_below(const fcm_mesh *mesh, double xmax, fcm_index *count)
{
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  fcm_index *list = malloc(sizeof *list * (size_t)nn), n = 0;
  for (fcm_index a = 0; a < nn; a++)
    if (X[3 * a] < xmax) list[n++] = a;
  *count = n;
  return list;
}

/* Total load and its moment sum over all DOF copies of (X + u) x f. */
static void load_totals(const fcm_space *space, const double *f, const double *u, double F[3],
                        double M[3])
{
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const double *X = fcm_mesh_coords(mesh);
  F[0] = F[1] = F[2] = M[0] = M[1] = M[2] = 0.0;
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++) {
    const fcm_index d0 = fcm_space_node_dof(space, a);
    for (fcm_index k = 0; d0 >= 0 && k < fcm_space_node_copies(space, a); k++) {
      const fcm_index d = d0 + 3 * k;
      double x[3];
      for (int i = 0; i < 3; i++)
        x[i] = X[3 * a + i] + u[d + i], F[i] += f[d + i];
      cross_add(x, f + d, M);
    }
  }
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *beam = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-0.3, -0.2, -0.15}, hi[3] = {2.3, 0.7, 0.65};
  const fcm_index cells[3] = {8, 3, 3};
  const double glo[3] = {0, 0, 0}, ghi[3] = {2, 0.5, 0.5};
  const fcm_index gcells[3] = {4, 1, 1};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gcells, &beam));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, beam, &ro, &rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  if (!space) return TEST_RESULT();
  TEST_TRUE(fcm_cell_rules_get_stats(rules)->num_cut > 0);
  const fcm_index n = fcm_space_num_dofs(space);
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2.0e6, 0.3, 800.0};
  double *f = calloc((size_t)n, sizeof *f);
  TEST_OK(ctx, fcm_assemble_body_force(space, &mat, grav, NULL, f));
  fcm_index nfix = 0, nmid = 0;
  fcm_index *fix = nodes_below(mesh, 0.1, &nfix);
  /* a second set: the nodes in the slab 1.0 < x < 1.4 (fixed in z only) */
  fcm_index *mid = malloc(sizeof *mid * (size_t)fcm_mesh_num_nodes(mesh));
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++)
    if (X[3 * a] > 1.0 && X[3 * a] < 1.4) mid[nmid++] = a;

  /* 1. static: reaction = -sum f_ext, moment = -sum (X + u) x f_ext */
  for (int two = 0; two < 2; two++) {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.kind = FCM_INTEGRATOR_STATIC;
    o.dt = 1.0;
    o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    o.newton_tolerance = 1e-12;
    fcm_motion fixed = fcm_motion_default(), zonly = fcm_motion_default();
    zonly.components[0] = zonly.components[1] = 0;
    int id0 = -1, id1 = -1;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, &id0));
    if (two) TEST_OK(ctx, fcm_integrator_add_constraint(integ, nmid, mid, &zonly, &id1));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    TEST_TRUE(fcm_integrator_num_constraints(integ) == 1 + two);
    double R[3], Mo[3];
    TEST_ERR(ctx, fcm_integrator_reaction(integ, 0, R, Mo), FCM_ERR_ARG, "no step accepted");
    TEST_ERR(ctx, fcm_integrator_reaction(integ, 2, R, Mo), FCM_ERR_ARG, "out of range");
    TEST_OK(ctx, fcm_integrator_step(integ, NULL));
    const double *u = fcm_integrator_displacement(integ);
    double F[3], M[3], Rs[3] = {0, 0, 0}, Ms[3] = {0, 0, 0};
    load_totals(space, f, u, F, M);
    for (int k = 0; k < 1 + two; k++) {
      TEST_OK(ctx, fcm_integrator_reaction(integ, k, R, Mo));
      for (int i = 0; i < 3; i++)
        Rs[i] += R[i], Ms[i] += Mo[i];
      if (k == 1) TEST_TRUE(R[0] == 0.0 && R[1] == 0.0 && R[2] > 0.0); /* z only, upward */
    }
    const double W = fabs(F[2]), Wm = fabs(M[0]) + fabs(M[1]) + fabs(M[2]);
    for (int i = 0; i < 3; i++) {
      TEST_NEAR(Rs[i], -F[i], 0, 1e-9 * W);
      TEST_NEAR(Ms[i], -M[i], 0, 1e-9 * Wm);
    }
    /* the weight: rho g |body| up to the stabilization's share (alpha of the fictitious part) */
    TEST_NEAR(Rs[2], 800.0 * 9.81 * 0.5, 1e-3, 0);
    if (two) { /* the clamp alone is not the whole weight */
      TEST_OK(ctx, fcm_integrator_reaction(integ, id0, R, NULL));
      TEST_TRUE(R[2] < Rs[2] && R[2] > 0.0);
    }
    /* set_state forgets it */
    TEST_OK(ctx, fcm_integrator_set_state(integ, NULL, NULL, 1.0, 1));
    TEST_ERR(ctx, fcm_integrator_reaction(integ, 0, R, Mo), FCM_ERR_ARG, "no step accepted");
    fcm_integrator_destroy(&integ);
  }

  /* 2. dynamics: R = (p_{n+1} - p_n)/h - W */
  {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
    o.dt = 0.01;
    o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    o.newton_tolerance = 1e-12;
    fcm_motion fixed = fcm_motion_default();
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    double p0[3], p1[3], R[3], F[3], M[3];
    for (int step = 0; step < 3; step++) {
      TEST_OK(ctx, fcm_integrator_momentum(integ, p0, NULL));
      TEST_OK(ctx, fcm_integrator_step(integ, NULL));
      TEST_OK(ctx, fcm_integrator_momentum(integ, p1, NULL));
      TEST_OK(ctx, fcm_integrator_reaction(integ, 0, R, NULL));
      load_totals(space, f, fcm_integrator_displacement(integ), F, M);
      const double scale = fabs(F[2]) + fabs(p1[2] - p0[2]) / o.dt;
      for (int i = 0; i < 3; i++)
        TEST_NEAR(R[i], (p1[i] - p0[i]) / o.dt - F[i], 0, 1e-9 * scale);
      if (step == 0) TEST_TRUE(fabs(p1[2] - p0[2]) / o.dt > 1e-3 * fabs(F[2])); /* not static */
    }
    fcm_integrator_destroy(&integ);
  }
  free(f), free(fix), free(mid);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&beam);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
