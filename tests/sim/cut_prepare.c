/* A cut builds the multigrid solver's new hierarchy itself (fcm_integrator_prepare_solver(),
 * called by fcm_integrator_create_cut()) and the step after it only sets up its values. An
 * embedded box under gravity, its base held, with FCM_LINEAR_MULTIGRID (V- and W-cycles, three
 * levels and more), is stepped and cut by a plane; the cut's integrator holds a hierarchy before
 * any step and timed its structure (setup_info.solver_seconds), and is compared with one built
 * from scratch on the same space and state (its hierarchy made by its first step): three steps
 * give the same displacement and velocity bits and Newton and cycle counts, and the step after
 * the cut creates no hierarchy (total_multigrid_creations stays 1). When a constraint is
 * released between the cut and the next step, the step finds another active set and builds the
 * hierarchy again (from the prepared one), with the same bits. The direct solver's analysis
 * stays the cut's too (the step after it analyses nothing). Each allocation of the preparation
 * failed in turn returns FCM_ERR_ALLOC and leaks nothing. Usage: sim_cut_prepare <element> */
#include "sim_util.h"
#include "test_alloc.h"

#include <string.h>

static fcm_ctx *ctx;
static failing counter = {0, -1}; /* the context's allocator, counting */

/* Fail the k-th allocation of fcm_integrator_prepare_solver() on an integrator without a
 * hierarchy, k = 0, 1, ... until it succeeds: FCM_ERR_ALLOC, no hierarchy, nothing leaked;
 * a call once it is built allocates nothing. */
static void prepare_alloc_failures(fcm_integrator *I)
{
  const long long live = fcm_ctx_live_allocations(ctx);
  fcm_status st = FCM_ERR_ALLOC;
  long long k = 0;
  for (; st != FCM_OK && k < 100000; k++) {
    counter.count = 0, counter.fail_at = k;
    st = fcm_integrator_prepare_solver(I);
    if (st != FCM_OK) {
      TEST_TRUE(st == FCM_ERR_ALLOC);
      TEST_TRUE(fcm_integrator_multigrid(I) == NULL);
      TEST_TRUE(fcm_ctx_live_allocations(ctx) == live);
      fcm_ctx_error_clear(ctx);
    }
  }
  counter.fail_at = -1;
  TEST_OK(ctx, st);
  TEST_TRUE(fcm_integrator_multigrid(I) != NULL);
  const long long before = counter.count = 0;
  TEST_OK(ctx, fcm_integrator_prepare_solver(I));
  TEST_TRUE(counter.count == before);
  printf("  prepare_solver: each of its %lld allocations failed in turn: FCM_ERR_ALLOC, nothing "
         "leaked\n",
         k - 1);
}

static const fcm_material mat = {FCM_MATERIAL_LINEAR, 2.0e4, 0.3, 1000.0};
static const double gravity[3] = {0.0, -9.81, 0.0};

/* The held base (y <= 0.05) and, with release_at > 0, a held top corner released then. */
static void add_effects(fcm_integrator *I, const fcm_mesh *mesh, double release_at)
{
  const double lo[3] = {-10, -10, -10}, hi[3] = {10, 0.05, 10};
  TEST_OK(ctx, fcm_integrator_add_gravity(I, gravity, NULL, NULL));
  TEST_OK(ctx, hold_box(ctx, I, mesh, lo, hi));
  if (release_at > 0.0) {
    const double clo[3] = {0.7, 0.45, -10}, chi[3] = {10, 10, 10};
    fcm_index count = 0;
    TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, clo, chi, 0.0, 0, NULL, &count));
    fcm_index *nodes = malloc(sizeof *nodes * (size_t)(count + 1));
    TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, clo, chi, 0.0, count, nodes, &count));
    TEST_TRUE(count > 0);
    fcm_motion m = fcm_motion_default();
    m.end = release_at;
    m.release = 1;
    TEST_OK(ctx, fcm_integrator_add_constraint(I, count, nodes, &m, NULL));
    free(nodes);
  }
}

/* The integrator of `space` built from scratch in the state old's cut leaves. */
static fcm_integrator *rebuild(const fcm_integrator *old, const fcm_space *old_space,
                               const fcm_space *space, const fcm_mesh *mesh,
                               const fcm_integrator_options *o, double release_at)
{
  fcm_integrator *I = NULL;
  const fcm_index n = fcm_space_num_dofs(space), n0 = fcm_integrator_num_dofs(old);
  double *u = malloc(sizeof *u * (size_t)n), *v = malloc(sizeof *v * (size_t)n);
  double *u0 = malloc(sizeof *u0 * (size_t)n0), *v0 = malloc(sizeof *v0 * (size_t)n0), t = 0.0;
  long long steps = 0;
  fcm_integrator_get_state(old, u0, v0, &t, &steps);
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, o, &I));
  add_effects(I, mesh, release_at);
  TEST_OK(ctx, fcm_integrator_setup(I));
  TEST_OK(ctx, fcm_space_transfer(old_space, space, u0, u));
  TEST_OK(ctx, fcm_space_transfer(old_space, space, v0, v));
  TEST_OK(ctx, fcm_integrator_set_state(I, u, v, t, steps));
  free(u), free(v), free(u0), free(v0);
  return I;
}

/* Steps the cut's integrator `a` and the rebuild `b`: the same bits and counts; the step after
 * the cut creates `a_creations` hierarchies in all (1: the prepared one only). */
static void step_both(fcm_integrator *a, fcm_integrator *b, int steps, long long a_creations)
{
  const fcm_index n = fcm_integrator_num_dofs(a);
  for (int s = 0; s < steps; s++) {
    fcm_step_info ia, ib;
    TEST_OK(ctx, fcm_integrator_step(a, &ia));
    TEST_OK(ctx, fcm_integrator_step(b, &ib));
    TEST_TRUE(ia.reason == FCM_STEP_CONVERGED && ib.reason == FCM_STEP_CONVERGED);
    TEST_TRUE(ia.newton_iterations == ib.newton_iterations);
    TEST_TRUE(ia.multigrid_cycles == ib.multigrid_cycles && ia.multigrid_cycles > 0);
    TEST_TRUE(ia.total_multigrid_creations == a_creations);
    TEST_TRUE(ib.total_multigrid_creations == 1);
    if (s == 0)
      printf("  step after the cut: %d Newton iterations, %lld cycles, hierarchies created %lld "
             "(the rebuild's %lld)\n",
             ia.newton_iterations, (long long)ia.multigrid_cycles, ia.total_multigrid_creations,
             ib.total_multigrid_creations);
  }
  TEST_TRUE(memcmp(fcm_integrator_displacement(a), fcm_integrator_displacement(b),
                   sizeof(double) * (size_t)n) == 0);
  TEST_TRUE(memcmp(fcm_integrator_velocity(a), fcm_integrator_velocity(b),
                   sizeof(double) * (size_t)n) == 0);
}

/* Step, cut, compare with a rebuild; release_at > 0: a constraint released before the step
 * after the cut. */
static void cut_case(fcm_element_type type, fcm_linear_solver solver, int cycle_index, int release)
{
  const double lo[3] = {-0.3, -0.3, -0.3}, hi[3] = {1.3, 0.9, 0.9};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  const fcm_index nc[3] = {8, 6, 6}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules[2] = {NULL, NULL};
  fcm_space *space[2] = {NULL, NULL};
  fcm_integrator *I = NULL, *cut = NULL, *ref = NULL;
  fcm_surface *plane = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[0], &space[0]));
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.01;
  o.linear_solver = solver;
  o.multigrid.coarse_dofs = 60;
  o.multigrid.cycle_index = cycle_index;
  o.cut_reuse = FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_ORDERING;
  const double release_at = release ? 0.025 : 0.0; /* between the cut (t = 0.02) and t = 0.03 */
  TEST_OK(ctx, fcm_integrator_create(ctx, space[0], &mat, &o, &I));
  add_effects(I, mesh, release_at);
  TEST_OK(ctx, fcm_integrator_setup(I));
  for (int s = 0; s < 2; s++) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
  }
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &plane));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[0], plane, &rules[1]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[1], &space[1]));
  TEST_OK(ctx, fcm_integrator_create_cut(I, space[1], &cut));
  ref = rebuild(I, space[0], space[1], mesh, &o, release_at);
  fcm_integrator_setup_info si;
  fcm_integrator_get_setup_info(cut, &si);
  printf("%s, %s, cycle %d%s: %lld -> %lld DOFs, solver structure %.4f s\n",
         type == FCM_ELEMENT_HEX8 ? "hex8" : "hex20",
         solver == FCM_LINEAR_MULTIGRID ? "multigrid" : "direct", cycle_index,
         release ? ", a constraint released before the next step" : "",
         (long long)fcm_space_num_dofs(space[0]), (long long)fcm_space_num_dofs(space[1]),
         si.solver_seconds);
  TEST_TRUE(si.solver_seconds > 0.0);
  if (solver == FCM_LINEAR_MULTIGRID) {
    const fcm_mg *mg = fcm_integrator_multigrid(cut);
    TEST_TRUE(mg != NULL);
    TEST_TRUE(fcm_mg_num_levels(mg) >= 3);
    TEST_TRUE(fcm_integrator_multigrid(ref) == NULL);
    step_both(cut, ref, 3, release ? 2 : 1);
    if (cycle_index == 2) { /* a new integrator on the cut space, prepared under failures */
      fcm_integrator *J = rebuild(I, space[0], space[1], mesh, &o, 0.0);
      prepare_alloc_failures(J);
      fcm_integrator_destroy(&J);
    }
  } else {
    fcm_step_info ia;
    TEST_OK(ctx, fcm_integrator_step(cut, &ia));
    TEST_TRUE(ia.total_analyses == 1 && ia.total_multigrid_creations == 0);
  }
  fcm_surface_destroy(&plane);
  fcm_integrator_destroy(&ref);
  fcm_integrator_destroy(&cut);
  fcm_integrator_destroy(&I);
  for (int k = 0; k < 2; k++) {
    fcm_space_destroy(&space[k]);
    fcm_cell_rules_destroy(&rules[k]);
  }
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  ctx = failing_ctx(&counter);
  TEST_TRUE(ctx != NULL);
  cut_case(type, FCM_LINEAR_MULTIGRID, 1, 0);
  cut_case(type, FCM_LINEAR_MULTIGRID, 2, 0);
  cut_case(type, FCM_LINEAR_MULTIGRID, 1, 1);
  cut_case(type, FCM_LINEAR_DIRECT, 1, 0);
  fcm_ctx_destroy(&ctx);
  printf("ok\n");
  return TEST_RESULT();
}
