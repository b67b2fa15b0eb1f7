/* Static steps refuse a system whose constraints leave a body free to move rigidly, before
 * any solve and with every solver (CHOLMOD, UMFPACK, CG, MINRES, CG + multigrid, multigrid):
 * 1. a Hex8 beam with no constraint, one fixed node, two fixed nodes (one rotation free, the
 *    axis through them named), three nodes held in z only (2 translations and a rotation
 *    free) and a roller that leaves one rotation free: FCM_ERR_SINGULAR with the body, what
 *    holds it and the free modes, no factorization and no iteration, in well under a
 *    second; three non-collinear nodes, a 3-2-1 support and a fixed face solve;
 * 2. an embedded box cut in two at t = 0, one half fixed: the other half (body of 2, its
 *    nodes right of the cut) is named; with both halves fixed the step solves;
 * 3. an embedded box held on its left face by Nitsche's method (no node held): accepted and
 *    solved; held there in z only: refused, 2 translations and 2 rotations free;
 * 4. a moving region released after the first step: the second step is refused;
 * 5. dynamic runs are never refused: a free body under gravity steps;
 * 6. a Krylov solve that stagnates reaches the step's reason: a dynamic step without mass
 *    (density 0, no constraint) under a body-force field fails with
 *    FCM_STEP_LINEAR_SOLVER_STAGNATED and a message naming it for CG (which may break down
 *    first) and MINRES (stagnated); with the stagnation window off MINRES ends with another
 *    reason;
 * 7. allocation failures in a static step (its k-th allocation fails, k = 0, 1, ...):
 *    FCM_ERR_ALLOC, nothing leaked, the state unchanged; in the end the refusal (one fixed
 *    node) or the solve (a fixed face). */
#include "sim_util.h"
#include "alloc_loop.h"

#include <stdio.h>
#include <string.h>

static const char *const solvers[] = {
    "{\"method\": \"direct\", \"direct\": \"cholmod\"}",
    "{\"method\": \"direct\", \"direct\": \"umfpack\"}",
    "{\"method\": \"cg\", \"preconditioner\": \"jacobi\"}",
    "{\"method\": \"minres\", \"preconditioner\": \"schwarz\"}",
    "{\"method\": \"cg\", \"preconditioner\": \"multigrid\"}",
    "{\"method\": \"multigrid\"}",
};
enum { NUM_SOLVERS = sizeof solvers / sizeof solvers[0] };

/* A fixed region: a small box around the point p (components "xyz" when NULL). */
static void fix_point(char *buf, size_t n, double x, double y, double z, const char *comp)
{
  char c[64] = "";
  if (comp) snprintf(c, sizeof c, ", \"components\": \"%s\"", comp);
  snprintf(
      buf, n,
      ", {\"fixed\": {\"region\": {\"box\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}}%s}}",
      x - 0.01, y - 0.01, z - 0.01, x + 0.01, y + 0.01, z + 0.01, c);
}

static const char static2[] = "{\"static\": true, \"steps\": 2}";

/* The beam [0, 2] x [0, 1]^2 in 8 x 4 x 4 Hex8 cells, linear, gravity, with the solver, the
 * time stepping and the extra effects given. */
static void beam(char *buf, size_t n, const char *solver, const char *effects, const char *time)
{
  snprintf(buf, n,
           "{\"version\": 1, \"name\": \"rigid\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           "   \"max\": [2, 1, 1]}, \"cells\": [8, 4, 4]},"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"solver\": %s,"
           " \"time\": %s,"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}%s]}",
           solver, time, effects);
}

/* An embedded box [0.1, 1.9] x [0.1, 0.9]^2 (Tet4 geometry) in 4 x 2 x 2 Hex8 cells over
 * [0, 2] x [0, 1]^2, linear, static, gravity; with surface rules for boundary constraints. */
static void embedded(char *buf, size_t n, const char *solver, const char *effects)
{
  snprintf(buf, n,
           "{\"version\": 1, \"name\": \"rigid_embedded\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           "   \"max\": [2, 1, 1]}, \"cells\": [4, 2, 2]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0.1, 0.1, 0.1], \"max\": [1.9, 0.9, 0.9],"
           "   \"cells\": [4, 2, 2]},"
           " \"quadrature\": {\"surface_strength\": 2},"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"solver\": %s,"
           " \"time\": {\"static\": true, \"steps\": 1},"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}%s]}",
           solver, effects);
}

/* Build the scene and take `steps` steps (stopping at the first failure): the status, the
 * last step's info and the wall time of the last step. */
static fcm_status run(fcm_ctx *ctx, const char *json, int steps, fcm_step_info *info,
                      double *seconds)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  memset(info, 0, sizeof *info);
  *seconds = 0.0;
  fcm_status st = fcm_scene_create_from_string(ctx, json, "rigid.json", &scene);
  if (st == FCM_OK) st = fcm_simulation_create(ctx, scene, NULL, &sim);
  for (int k = 0; st == FCM_OK && k < steps; k++) {
    const double t0 = fcm_wtime();
    st = fcm_simulation_step(sim, info);
    *seconds = fcm_wtime() - t0;
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return st;
}

/* The scene must be refused at its `step`-th step, before any solve, with all the parts. */
static void refused(fcm_ctx *ctx, const char *what, const char *json, int step,
                    const char *const *parts, int nparts)
{
  fcm_step_info info;
  double s = 0.0;
  fcm_status st = run(ctx, json, step, &info, &s);
  const char *msg = fcm_ctx_error_message(ctx);
  if (st != FCM_ERR_SINGULAR || !strstr(msg, "refused before any solve"))
    TEST_FAIL_("%s: %s, \"%s\"", what, fcm_status_name(st), msg);
  for (int k = 0; st == FCM_ERR_SINGULAR && k < nparts; k++)
    if (!strstr(msg, parts[k])) TEST_FAIL_("%s: \"%s\" lacks \"%s\"", what, msg, parts[k]);
  if (info.linear_iterations != 0 || info.factorizations != 0 || info.newton_iterations != 0 ||
      !(s < 1.0))
    TEST_FAIL_("%s: %lld linear iterations, %d factorizations, %d Newton iterations, %.3f s", what,
               info.linear_iterations, info.factorizations, info.newton_iterations, s);
  fcm_ctx_error_clear(ctx);
}

static void accepted(fcm_ctx *ctx, const char *what, const char *json, int steps)
{
  fcm_step_info info;
  double s = 0.0;
  fcm_status st = run(ctx, json, steps, &info, &s);
  if (st != FCM_OK || info.reason != FCM_STEP_CONVERGED)
    TEST_FAIL_("%s: %s (%s)", what, fcm_status_name(st), fcm_ctx_error_message(ctx));
  fcm_ctx_error_clear(ctx);
}

static void test_beam(fcm_ctx *ctx)
{
  char json[4096], e[1024], p1[256], p2[256], p3[256];
  for (int k = 0; k < NUM_SOLVERS; k++) {
    char what[256];
    snprintf(what, sizeof what, "beam, solver %s", solvers[k]);
    beam(json, sizeof json, solvers[k], "", static2);
    const char *none[] = {"body 0 of 1", "held by nothing",
                          "3 rigid-body translations and 3 rotations free"};
    refused(ctx, what, json, 1, none, 3);
    fix_point(p1, sizeof p1, 0, 0, 0, NULL);
    beam(json, sizeof json, solvers[k], p1, static2);
    const char *one[] = {"held by 1 node in all components", "leaves 3 rigid-body rotations free",
                         "[0, 2] x [0, 1] x [0, 1]"};
    refused(ctx, what, json, 1, one, 3);
    fix_point(p2, sizeof p2, 2, 1, 1, NULL);
    snprintf(e, sizeof e, "%s%s", p1, p2);
    beam(json, sizeof json, solvers[k], e, static2);
    const char *two[] = {"held by 2 nodes in all components", "leaves 1 rigid-body rotation free",
                         "about the axis through (1, 0.5, 0.5) along (0.816, 0.408, 0.408)"};
    refused(ctx, what, json, 1, two, 3);
    fix_point(p3, sizeof p3, 0, 1, 0, NULL);
    snprintf(e, sizeof e, "%s%s%s", p1, p2, p3);
    beam(json, sizeof json, solvers[k], e, static2);
    accepted(ctx, what, json, 2);
    /* fixed face */
    beam(json, sizeof json, solvers[k],
         ", {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"
         " \"normal\": [-1, 0, 0]}}}}",
         static2);
    accepted(ctx, what, json, 2);
  }
  /* partial constraints (CG): three nodes in z only; a 3-2-1 support; the same with the last
   * support in y, which leaves the rotation about the x axis free */
  {
    char q1[256], q2[256], q3[256];
    fix_point(q1, sizeof q1, 0, 0, 0, "z");
    fix_point(q2, sizeof q2, 2, 0, 0, "z");
    fix_point(q3, sizeof q3, 0, 1, 0, "z");
    snprintf(e, sizeof e, "%s%s%s", q1, q2, q3);
    beam(json, sizeof json, solvers[2], e, static2);
    const char *z3[] = {"held by 3 nodes in some components",
                        "2 rigid-body translations and 1 rotation free"};
    refused(ctx, "three nodes in z", json, 1, z3, 2);
    fix_point(q2, sizeof q2, 2, 0, 0, "yz");
    snprintf(e, sizeof e, "%s%s%s", p1, q2, q3);
    beam(json, sizeof json, solvers[2], e, static2);
    accepted(ctx, "3-2-1 support", json, 1);
    fix_point(q3, sizeof q3, 0, 1, 0, "y");
    snprintf(e, sizeof e, "%s%s%s", p1, q2, q3);
    beam(json, sizeof json, solvers[2], e, static2);
    const char *roller[] = {"held by 1 node in all components and 2 nodes in some components",
                            "1 rigid-body rotation free (about the axis through (1, 0, 0) along "
                            "(1, 0, 0))"};
    refused(ctx, "3-2-1 support with the last in y", json, 1, roller, 2);
  }
}

static void test_cut(fcm_ctx *ctx)
{
  static const char cut[] = ", {\"cut\": {\"surface\": {\"plane\": {\"point\": [1.05, 0.5, 0.5], "
                            "\"normal\": [1, 0, 0]}}}}";
  static const char left[] = ", {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.3, 0, 0],"
                             " \"normal\": [-1, 0, 0]}}}}";
  static const char right[] = ", {\"fixed\": {\"region\": {\"half_space\": {\"point\": [1.7, 0, 0],"
                              " \"normal\": [1, 0, 0]}}}}";
  char json[4096], e[1024];
  for (int k = 0; k < NUM_SOLVERS; k += 2) { /* CHOLMOD, CG, CG + multigrid */
    snprintf(e, sizeof e, "%s%s", left, cut);
    embedded(json, sizeof json, solvers[k], e);
    /* the free half: the nodes of the cells right of the cut, x in [1, 2] */
    const char *half[] = {"of 2 (background nodes in [1, 2] x", "held by nothing",
                          "3 rigid-body translations and 3 rotations free"};
    refused(ctx, "cut body, one half held", json, 1, half, 3);
    snprintf(e, sizeof e, "%s%s%s", left, right, cut);
    embedded(json, sizeof json, solvers[k], e);
    accepted(ctx, "cut body, both halves held", json, 1);
  }
}

static void test_boundary(fcm_ctx *ctx)
{
  char json[4096];
  static const char face[] = "{\"half_space\": {\"point\": [0.11, 0, 0], \"normal\": [-1, 0, 0]}}";
  char e[512];
  snprintf(e, sizeof e, ", {\"fixed\": {\"boundary\": %s}}", face);
  embedded(json, sizeof json, solvers[0], e);
  accepted(ctx, "Nitsche on a face", json, 1);
  snprintf(e, sizeof e, ", {\"fixed\": {\"boundary\": %s, \"components\": \"z\"}}", face);
  embedded(json, sizeof json, solvers[2], e);
  const char *z[] = {"boundary-constraint points", "2 rigid-body translations and 2 rotations"};
  refused(ctx, "Nitsche on a face in z only", json, 1, z, 2);
}

static void test_release_dynamic(fcm_ctx *ctx)
{
  char json[4096];
  /* held on x = 0 until t = 1.5 (static steps of 1): the second step is refused */
  beam(json, sizeof json, solvers[2],
       ", {\"motion\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"
       " \"normal\": [-1, 0, 0]}}, \"end\": 1.5, \"release\": true}}",
       "{\"static\": true, \"dt\": 1, \"steps\": 2}");
  accepted(ctx, "released region, first step", json, 1);
  const char *rel[] = {"static step to t = 2", "held by nothing"};
  refused(ctx, "released region, second step", json, 2, rel, 2);
  /* dynamic, free: accepted */
  for (int k = 0; k < 3; k++) {
    beam(json, sizeof json, solvers[k], "", "{\"dt\": 0.01, \"steps\": 1}");
    accepted(ctx, "dynamic free body", json, 1);
  }
}

/* b(x) = (0, 0, -1e4 (1 + x)) (N/m^3) */
static void load_field(void *user, const double x[3], const double nrm[3], double b[3])
{
  (void)user;
  (void)nrm;
  b[0] = b[1] = 0.0;
  b[2] = -1e4 * (1.0 + x[0]);
}

static void test_stagnation(fcm_ctx *ctx)
{
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  TEST_OK(ctx, beam_mesh(ctx, FCM_ELEMENT_HEX8, 4, 2.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 0.0}; /* no mass */
  /* The free beam's K is singular only up to round-off: its rigid-mode eigenvalues are
   * round-off sized, not zero. MINRES plateaus at the part of b outside the range until it
   * resolves them and returns a huge iterate the line search refuses; how many iterations that
   * takes depends on the round-off of the assembled K (beyond 50 for some moduli, within it for
   * others). A window of 20 closes on the plateau for every modulus tried (3e5 to 2e6). */
  const int window = 20;
  for (int k = 0; k < 3; k++) {
    fcm_integrator *I = NULL;
    fcm_integrator_options o = fcm_integrator_options_default();
    o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    o.linear_solver = k == 0 ? FCM_LINEAR_CG : FCM_LINEAR_MINRES;
    o.preconditioner = FCM_PRECOND_JACOBI;
    o.max_halvings = 1;
    o.krylov_stagnation_window = k == 2 ? 0 : window;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &I));
    TEST_OK(ctx, fcm_integrator_add_body_force(I, load_field, NULL, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_setup(I));
    fcm_step_info info;
    const double t0 = fcm_wtime();
    fcm_status st = fcm_integrator_step(I, &info);
    const double s = fcm_wtime() - t0;
    const char *msg = fcm_ctx_error_message(ctx);
    if (k < 2) {
      if (st != FCM_ERR_NOT_CONVERGED || info.reason != FCM_STEP_LINEAR_SOLVER_STAGNATED ||
          !strstr(msg, "linear-solver-stagnated") ||
          !strstr(msg, k == 0 ? "stalled or broke down" : "stagnated: the smallest") || !(s < 5.0))
        TEST_FAIL_("solver %d: %s, reason %s, %.2f s, \"%s\"", k, fcm_status_name(st),
                   fcm_step_reason_name(info.reason), s, msg);
    } else {
      TEST_TRUE(st == FCM_ERR_NOT_CONVERGED && info.reason != FCM_STEP_LINEAR_SOLVER_STAGNATED);
    }
    fcm_ctx_error_clear(ctx);
    fcm_integrator_destroy(&I);
  }
  TEST_TRUE(
      !strcmp(fcm_step_reason_name(FCM_STEP_LINEAR_SOLVER_STAGNATED), "linear-solver-stagnated"));
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
}

/* One round of the allocation-failure loop: a static integrator on a Hex8 beam held at `nfix`
 * nodes, set up with the normal allocator, then one step with the round's allocation failing.
 * The step must end with `final` (FCM_OK returned then) or FCM_ERR_ALLOC, the integrator's
 * time and step count unchanged by a failure (FCM_ERR_INTERNAL otherwise). */
typedef struct step_round {
  fcm_ctx *ctx;
  failing *f;
  const fcm_space *space;
  fcm_index nfix;
  const fcm_index *fix;
  fcm_status final;
} step_round;

static fcm_status alloc_step(void *user)
{
  const step_round *r = user;
  fcm_integrator *I = NULL;
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  const double g[3] = {0, 0, -9.81};
  const fcm_motion held = fcm_motion_default();
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_STATIC;
  o.tolerance_mode = FCM_NEWTON_TOL_REPRESENTATIVE;
  o.linear_solver = FCM_LINEAR_CG;
  o.preconditioner = FCM_PRECOND_JACOBI;
  const long long k = r->f->fail_at;
  r->f->fail_at = -1;
  fcm_status st = fcm_integrator_create(r->ctx, r->space, &mat, &o, &I);
  if (st == FCM_OK) st = fcm_integrator_add_gravity(I, g, NULL, NULL);
  if (st == FCM_OK) st = fcm_integrator_add_constraint(I, r->nfix, r->fix, &held, NULL);
  if (st == FCM_OK) st = fcm_integrator_setup(I);
  if (st != FCM_OK) {
    fcm_integrator_destroy(&I);
    return FCM_ERR_INTERNAL;
  }
  r->f->count = 0;
  r->f->fail_at = k;
  st = fcm_integrator_step(I, NULL);
  r->f->fail_at = -1;
  const int state_ok = fcm_integrator_time(I) == (st == FCM_OK ? o.dt : 0.0) &&
                       fcm_integrator_step_count(I) == (st == FCM_OK);
  fcm_integrator_destroy(&I);
  if (!state_ok || (st != r->final && st != FCM_ERR_ALLOC)) {
    TEST_FAIL_("allocation %lld failing: %s (%s), state %d", k, fcm_status_name(st),
               fcm_ctx_error_message(r->ctx), state_ok);
    return FCM_ERR_INTERNAL;
  }
  return st == r->final ? FCM_OK : st;
}

static void test_alloc(void)
{
  failing f = {0, -1};
  fcm_ctx *ctx = failing_ctx(&f);
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  TEST_OK(ctx, beam_mesh(ctx, FCM_ELEMENT_HEX8, 2, 2.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index nface = 0;
  fcm_index *face = plane_nodes(ctx, mesh, 0, 0.0, &nface);
  for (int held = 0; held < 2; held++) {
    /* held at one node the beam's rigid-body check ends the step (FCM_ERR_SINGULAR); at its
     * face the step succeeds. Both allocate: at least one failing round. */
    step_round r = {ctx, &f, space, held ? nface : 1, face, held ? FCM_OK : FCM_ERR_SINGULAR};
    alloc_loop(ctx, &f, held ? "step held at a face" : "step held at one node", alloc_step, NULL,
               &r, 1, 1000);
  }
  free(face);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  test_beam(ctx);
  test_cut(ctx);
  test_boundary(ctx);
  test_release_dynamic(ctx);
  test_stagnation(ctx);
  fcm_ctx_destroy(&ctx);
  test_alloc();
  return TEST_RESULT();
}
