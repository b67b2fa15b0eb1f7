/* A scene's cut makes the cut space's integrator, the output surface split again and the
 * log's mass blocks on two threads when the run has them (scene/run.c): the run gives the
 * bits of the run that makes them one after the other, each with both threads for its loops.
 * A spinning box is cut three times (a plane across it, a second plane crossing the first in
 * cells it split, and a slit from the top ending inside the body) in two runs on two
 * threads, the first making each cut's parts in turn; after every step both have the same
 * DOF count, displacement and velocity bits and the same log mass and momenta (from the mass
 * blocks the cuts kept), and at the end the same output surface (points, elements, reference
 * coordinates, triangles, cut flags), bodies and counters; the second made every cut side by
 * side, the first none. With "multigrid" the box is element-corotated linear and solved by
 * three multigrid V-cycles and one Newton iteration a step (as the interactive scenes): the
 * cut's solver structure is made beside the integrator's values and the surface; after every
 * cut the hierarchy is the structure's of the active set the state holds, and the two runs
 * create the same number of hierarchies. With "fail" (multigrid) the second cut fails at an
 * allocation spread over the cut's allocations (the allocator counts atomically: the parts
 * allocate side by side), and at every allocation from it on, with the parts in turn and
 * side by side: the run goes on with the integrator it had (its storage given back, which
 * allocates nothing), steps to the end and leaks nothing. With
 * "nosurface" (multigrid) the scene writes no output surface: the values and the structure
 * still go side by side.
 * Usage: sim_cut_overlap <element> [threads | multigrid | fail | nosurface] */
#include "fcm/fcm.h"
#include "scene/run_impl.h"
#include "fem/fem_impl.h"
#include "sim/sim_impl.h"
#include "test.h"

#include <stdlib.h>
#include <string.h>

/* Allocator counting its calls atomically and failing call number fail_at (-1: none), or
 * with `every` every call from that one on. */
typedef struct counting {
  long long count, fail_at;
  int every;
} counting;

static void *counting_alloc(void *user, size_t size)
{
  counting *c = user;
  const long long k = __atomic_fetch_add(&c->count, 1, __ATOMIC_RELAXED);
  const long long at = __atomic_load_n(&c->fail_at, __ATOMIC_RELAXED);
  return at >= 0 && (k == at || (c->every && k > at)) ? NULL : malloc(size);
}

static void counting_release(void *user, void *p)
{
  (void)user;
  free(p);
}

static int same_bits(const void *a, const void *b, size_t bytes)
{
  return memcmp(a, b, bytes) == 0;
}

static void scene_json(char *buf, size_t cap, const char *element, int threads, int multigrid,
                       int surface)
{
  snprintf(
      buf, cap,
      "{\"version\": 1, \"name\": \"cut_overlap\","
      " \"background\": {\"element\": \"%s\", \"box\": {\"min\": [-0.25, -0.25, -0.25],"
      "   \"max\": [1.25, 0.75, 0.75]}, \"cells\": [6, 4, 4]},"
      " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1, 0.5, 0.5],"
      "   \"cells\": [4, 2, 2]},"
      " \"material\": {\"model\": \"%s\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000},"
      " \"solver\": {\"threads\": %d%s},"
      " \"time\": {\"dt\": 0.02, \"steps\": 6},"
      " \"output\": {\"background\": false, \"surface\": %s},"
      " \"effects\": [{\"initial_velocity\": {\"angular_velocity\": [0, 0, 4]}},"
      "  {\"cut\": {\"time\": 0.02, \"surface\": {\"plane\": {\"point\": [0.43, 0.25, 0.25],"
      "     \"normal\": [1, 0.1, 0]}}}},"
      "  {\"cut\": {\"time\": 0.06, \"surface\": {\"plane\": {\"point\": [0.5, 0.27, 0.25],"
      "     \"normal\": [0.2, 1, 0.1]}}}},"
      "  {\"cut\": {\"time\": 0.08, \"surface\": {\"rectangle\": {\"center\": [0.77, 0.5, 0.25],"
      "     \"normal\": [1, 0, 0.05], \"axis\": [0, 1, 0], \"size\": [0.5, 0.8]}}}}]}",
      element, multigrid ? "corotated_linear" : "snh", threads,
      multigrid ? ", \"method\": \"multigrid\", \"fixed_cycles\": 3,"
                  " \"multigrid\": {\"coarse_dofs\": 20}, \"newton\": {\"fixed_iterations\": 1}"
                : "",
      surface ? "true" : "false");
}

/* After a cut: the integrator's hierarchy is the structure of the active set its state
 * holds (made beside the values, its constrained DOFs found at the state's time). */
static void check_structure(fcm_simulation *S)
{
  const fcm_integrator *I = fcm_simulation_integrator(S);
  TEST_TRUE(I->mg && I->mg_A == I->H && I->mg_con == I->con_version);
}

/* The second cut failing at its allocation k (parts in turn or side by side): st ALLOC (or OK
 * when the cut made fewer allocations), the run as it was, going on to the end; *allocs: the
 * cut's allocations when k < 0 (none failed). With `every` every allocation from k on fails,
 * the storage's give-back's too: it allocates nothing (the mass matrix assembled again in the
 * old integrator's workspace), so the run goes on all the same. Returns whether the cut
 * failed. */
static int cut_failing(const char *element, int in_turn, long long k, int every, long long *allocs)
{
  counting cnt = {0, -1, every};
  fcm_ctx_options o = fcm_ctx_options_default();
  o.allocator.alloc = counting_alloc;
  o.allocator.release = counting_release;
  o.allocator.user = &cnt;
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  char json[4096];
  int failed = 0;
  TEST_OK(NULL, fcm_ctx_create(&o, &ctx));
  scene_json(json, sizeof json, element, 2, 1, 1);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "cut_overlap.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  sim->cuts_in_turn = in_turn;
  fcm_step_info si;
  /* to the second cut's time (0.06), the first one made */
  while (fcm_integrator_time(fcm_simulation_integrator(sim)) < 0.06 - 1e-9)
    TEST_OK(ctx, fcm_simulation_step(sim, &si));
  TEST_TRUE(sim->cuts_applied == 1);
  const fcm_integrator *before = fcm_simulation_integrator(sim);
  const fcm_index n = fcm_integrator_num_dofs(before);
  __atomic_store_n(&cnt.count, 0, __ATOMIC_RELAXED);
  __atomic_store_n(&cnt.fail_at, k, __ATOMIC_RELAXED);
  const fcm_status st = fcm__sim_apply_cut(sim);
  __atomic_store_n(&cnt.fail_at, -1, __ATOMIC_RELAXED);
  if (allocs) *allocs = cnt.count;
  failed = st != FCM_OK;
  TEST_TRUE(st == FCM_OK || st == FCM_ERR_ALLOC);
  if (failed) { /* the run as it was: the integrator, its space and surface */
    fcm_ctx_error_clear(ctx);
    TEST_TRUE(fcm_simulation_integrator(sim) == before && fcm_integrator_num_dofs(before) == n);
    TEST_TRUE(!before->spent && before->is_setup);
    TEST_TRUE(sim->surf && sim->surf->space == sim->space);
  } else {
    check_structure(sim);
  }
  while (!fcm_simulation_done(sim)) {
    const fcm_status s = fcm_simulation_step(sim, &si);
    TEST_OK(ctx, s);
    if (s != FCM_OK) break;
  }
  TEST_TRUE(fcm_simulation_done(sim));
  if (k < 0) TEST_TRUE(in_turn ? sim->cuts_side_by_side == 0 : sim->cuts_side_by_side == 3);
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  if (ctx) TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return failed;
}

static int fail_main(const char *element)
{
  for (int in_turn = 1; in_turn >= 0; in_turn--) {
    long long allocs = 0;
    cut_failing(element, in_turn, -1, 0, &allocs);
    TEST_TRUE(allocs > 16);
    int fails = 0, tried = 0, every = 0;
    for (long long k = 0; k < allocs; k += allocs / 24 + 1, tried++) {
      fails += cut_failing(element, in_turn, k, 0, NULL);
      every += cut_failing(element, in_turn, k, 1, NULL);
    }
    printf("%s: %d of %d cuts failed at an allocation of %lld, %d with every one from it on\n",
           in_turn ? "in turn" : "side by side", fails, tried, allocs, every);
    TEST_TRUE(in_turn ? fails == tried : fails > tried / 2);
    TEST_TRUE(every == tried);
  }
  return TEST_RESULT();
}

int main(int argc, char **argv)
{
  const char *element = argc > 1 ? argv[1] : "hex8";
  const int threads_mode = argc > 2 && !strcmp(argv[2], "threads");
  const int nosurface = argc > 2 && !strcmp(argv[2], "nosurface");
  const int multigrid = argc > 2 && (!strcmp(argv[2], "multigrid") || nosurface);
  if (argc > 2 && !strcmp(argv[2], "fail")) return fail_main(element);
  if (threads_mode) fcm_blas_set_num_threads(2);
  fcm_ctx *ctx[2] = {NULL, NULL};
  fcm_scene *scene[2] = {NULL, NULL};
  fcm_simulation *sim[2] = {NULL, NULL};
  char json[4096];
  for (int r = 0; r < 2; r++) {
    TEST_OK(NULL, fcm_ctx_create(NULL, &ctx[r]));
    scene_json(json, sizeof json, element, threads_mode ? r + 1 : 2, multigrid, !nosurface);
    TEST_OK(ctx[r], fcm_scene_create_from_string(ctx[r], json, "cut_overlap.json", &scene[r]));
    if (scene[r]) TEST_OK(ctx[r], fcm_simulation_create(ctx[r], scene[r], NULL, &sim[r]));
  }
  for (int r = 0; r < (threads_mode ? 2 : 1); r++)
    if (sim[r]) sim[r]->cuts_in_turn = 1;
  if (!sim[0] || !sim[1]) goto done;
  while (!fcm_simulation_done(sim[0]) && !fcm_simulation_done(sim[1])) {
    fcm_step_info si[2];
    for (int r = 0; r < 2; r++) {
      const int cuts = sim[r]->cuts_applied;
      TEST_OK(ctx[r], fcm_simulation_step(sim[r], &si[r]));
      if (multigrid && sim[r]->cuts_applied > cuts) check_structure(sim[r]);
    }
    const fcm_integrator *I0 = fcm_simulation_integrator(sim[0]),
                         *I1 = fcm_simulation_integrator(sim[1]);
    const fcm_index n = fcm_integrator_num_dofs(I0);
    TEST_TRUE(n == fcm_integrator_num_dofs(I1));
    if (n != fcm_integrator_num_dofs(I1)) goto done;
    TEST_TRUE(si[0].newton_iterations == si[1].newton_iterations);
    TEST_TRUE(same_bits(fcm_integrator_displacement(I0), fcm_integrator_displacement(I1),
                        sizeof(double) * (size_t)n));
    TEST_TRUE(same_bits(fcm_integrator_velocity(I0), fcm_integrator_velocity(I1),
                        sizeof(double) * (size_t)n));
    double q[2][7]; /* the log's mass and momenta, from the mass blocks the cuts kept */
    for (int r = 0; r < 2; r++) {
      const fcm_integrator *I = fcm_simulation_integrator(sim[r]);
      TEST_OK(ctx[r], fcm_space_momentum(fcm_simulation_space(sim[r]), 1000.0,
                                         fcm_integrator_displacement(I), fcm_integrator_velocity(I),
                                         q[r], q[r] + 1, q[r] + 4));
    }
    TEST_TRUE(same_bits(q[0], q[1], sizeof q[0]));
  }
  TEST_TRUE(fcm_simulation_done(sim[0]) && fcm_simulation_done(sim[1]));
  if (nosurface) {
    TEST_TRUE(!sim[0]->surf && !sim[1]->surf);
  } else {
    const fcm_embedded_surface *a = sim[0]->surf, *b = sim[1]->surf;
    TEST_TRUE(a && b);
    if (!a || !b) goto done;
    const fcm_index np = fcm_embedded_surface_num_points(a),
                    nt = fcm_embedded_surface_num_triangles(a);
    TEST_TRUE(np == fcm_embedded_surface_num_points(b) &&
              nt == fcm_embedded_surface_num_triangles(b));
    TEST_TRUE(fcm_embedded_surface_num_split_triangles(a) > 0);
    if (np == fcm_embedded_surface_num_points(b) && nt == fcm_embedded_surface_num_triangles(b)) {
      TEST_TRUE(same_bits(fcm_embedded_surface_points(a), fcm_embedded_surface_points(b),
                          3 * sizeof(double) * (size_t)np));
      TEST_TRUE(same_bits(fcm_embedded_surface_triangles(a), fcm_embedded_surface_triangles(b),
                          3 * sizeof(fcm_index) * (size_t)nt));
      TEST_TRUE(same_bits(fcm_embedded_surface_cut_flags(a), fcm_embedded_surface_cut_flags(b),
                          sizeof(int32_t) * (size_t)np));
      TEST_TRUE(same_bits(a->elem, b->elem, sizeof(fcm_index) * (size_t)np));
      TEST_TRUE(same_bits(a->xi, b->xi, 3 * sizeof(double) * (size_t)np));
    }
  }
  {
    fcm_simulation_counters k0, k1;
    fcm_simulation_get_counters(sim[0], &k0);
    fcm_simulation_get_counters(sim[1], &k1);
    const fcm_simulation_counters *c0 = &k0, *c1 = &k1;
    TEST_TRUE(c0->cuts == 3 && c1->cuts == 3 && c0->cuts_missed == 0 && c1->cuts_missed == 0);
    TEST_TRUE(c0->pieces == c1->pieces && c0->pieces == 4);
    TEST_TRUE(c0->num_dofs == c1->num_dofs && c0->cut_cells == c1->cut_cells);
    TEST_TRUE(c0->newton_iterations == c1->newton_iterations);
    TEST_TRUE(c1->time_cut_integrator > 0.0);
    if (multigrid) {
      TEST_TRUE(c0->time_cut_solver > 0.0 && c1->time_cut_solver > 0.0);
      TEST_TRUE(fcm__sim_mg_creations(fcm_simulation_integrator(sim[0])) ==
                fcm__sim_mg_creations(fcm_simulation_integrator(sim[1])));
    }
    TEST_TRUE(sim[0]->cuts_side_by_side == 0 &&
              sim[1]->cuts_side_by_side == (threads_mode ? 0 : 3));
  }
  if (threads_mode) TEST_TRUE(fcm_blas_set_num_threads(0) == 2); /* restored after each build */
done:
  for (int r = 0; r < 2; r++) {
    fcm_simulation_destroy(&sim[r]);
    fcm_scene_destroy(&scene[r]);
    if (ctx[r]) TEST_TRUE(fcm_ctx_live_allocations(ctx[r]) == 0);
    fcm_ctx_destroy(&ctx[r]);
  }
  return TEST_RESULT();
}
