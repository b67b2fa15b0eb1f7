/* The cut-aware multigrid in scene runs, as the preconditioner of CG and MINRES
 * ("preconditioner": "multigrid") and as the linear solver ("method": "multigrid").
 * Modes (argv[1]):
 *   agree       embedded Hex8 bodies, each run with the direct solver and with CG+MG,
 *               MINRES+MG and MG alone (linear rtol 1e-11, Newton rtol 1e-9 relative):
 *               max |u - u_direct| <= 1e-6 max |u_direct| over the DOF vector after the run,
 *               every step converged. Scenes: static linear with a clamped region (eliminated
 *               rows), static linear held by Nitsche on the embedded boundary (no eliminated
 *               row), the clamped one on a Hex20 grid (the p-level first), dynamic stable
 * neo-Hookean (PSD tangent) with a motion released after the first step (the eliminated rows
 * change: the hierarchy is built again), and the same dynamic scene with the exact tangent solved
 * by MINRES+MG (the multigrid built on the PSD tangent preconditions the indefinite system). Also:
 * the hierarchy has at least 2 levels; the cycles are counted (MG alone: cycles = linear
 * iterations; CG/MINRES: at least one cycle per iteration). cut         a slab clamped at x = 0 cut
 * by a plane during the run (XFEM on a Hex8 grid: the new space gets a new hierarchy): the same
 * agreement; two bodies after the cut. iterations  one static step on a 16 x 8 x 8 grid: CG+MG
 * takes at most a fifth of the iterations of CG+Jacobi to the same tolerance, and both agree.
 *   errors      bad multigrid options are refused naming the field and the range: the scene
 *               parser (path solver.multigrid.<key>, solver.method / solver.preconditioner for
 *               the background; hex20 and block_smoothing accepted), the integrator's setup
 * (multigrid.<member>), a Tet4 space (FCM_ERR_UNSUPPORTED at the first step, naming the option),
 * and a singular system (a static body without constraints) fails the step softly with
 *               "linear-solver-failed" and the state unchanged. */
#include "scene_util.h"

#include "../sim/sim_util.h"

/* A 2 x 1 x 1 m embedded box on an nx x ny x nz Hex8 grid over [0, 2.25] x [-0.125, 1.125]^2
 * (cut cells on every side). */
static const char *grid_element = "hex8"; /* of the background grid in scene_json() */

static void scene_json(char *buf, size_t cap, int n, const char *material, const char *time,
                       const char *solver, const char *effects)
{
  snprintf(buf, cap,
           "{\"version\": 1, \"name\": \"mg\","
           " \"background\": {\"element\": \"%s\", \"box\": {\"min\": [-0.03, -0.11, -0.07],"
           "   \"max\": [2.22, 1.015, 1.055]}, \"cells\": [%d, %d, %d]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [2, 0.9, 0.95],"
           "   \"cells\": [4, 2, 2]},"
           " \"material\": %s,"
           " \"time\": %s,"
           " \"solver\": %s,"
           " \"output\": {\"background\": false, \"surface\": false},"
           " \"effects\": [%s]}",
           grid_element, 2 * n, n, n, material, time, solver, effects);
}

static const char linear_material[] =
    "{\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000}";
static const char snh_material[] =
    "{\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000}";

typedef struct run_out {
  int ok;
  fcm_index n;
  double *u;
  long long linear, cycles, newton;
  int levels;
  fcm_index level0_dofs;
  fcm_index pieces;
} run_out;

/* Run the scene to its end; u copied out. */
static run_out run(fcm_ctx *ctx, const char *json)
{
  run_out r;
  memset(&r, 0, sizeof r);
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "mg.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim) {
    r.ok = 1;
    while (!fcm_simulation_done(sim)) {
      fcm_step_info si;
      fcm_status st = fcm_simulation_step(sim, &si);
      TEST_OK(ctx, st);
      if (st != FCM_OK) {
        r.ok = 0;
        break;
      }
      TEST_TRUE(si.reason == FCM_STEP_CONVERGED);
      TEST_TRUE(si.inexact_solves == 0);
    }
    fcm_simulation_counters c;
    fcm_simulation_get_counters(sim, &c);
    r.linear = c.linear_iterations;
    r.cycles = c.multigrid_cycles;
    r.newton = c.newton_iterations;
    r.pieces = c.pieces;
    fcm_integrator *I = fcm_simulation_integrator(sim);
    r.n = fcm_integrator_num_dofs(I);
    r.u = malloc(sizeof *r.u * (size_t)r.n);
    memcpy(r.u, fcm_integrator_displacement(I), sizeof *r.u * (size_t)r.n);
    const fcm_mg *mg = fcm_integrator_multigrid(I);
    r.levels = mg ? fcm_mg_num_levels(mg) : 0;
    if (mg) {
      fcm_mg_level_info li;
      TEST_OK(ctx, fcm_mg_get_level_info(mg, 0, &li));
      r.level0_dofs = li.dofs;
    }
    if (getenv("FCM_TEST_VERBOSE")) fcm_simulation_summary_view(sim, stderr);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return r;
}

static double max_abs(fcm_index n, const double *a)
{
  double m = 0.0;
  for (fcm_index i = 0; i < n; i++)
    m = fmax(m, fabs(a[i]));
  return m;
}

/* Run `ref_solver` and each of `solvers` on one scene; compare the displacements. */
static void agree(fcm_ctx *ctx, const char *label, int n, const char *material, const char *time,
                  const char *ref_solver, const char *const *solvers, int num_solvers,
                  const char *effects, fcm_index pieces)
{
  static char json[8192];
  scene_json(json, sizeof json, n, material, time, ref_solver, effects);
  run_out ref = run(ctx, json);
  TEST_TRUE(ref.ok && ref.cycles == 0);
  TEST_TRUE(pieces == 0 || ref.pieces == pieces);
  const double scale = ref.u ? max_abs(ref.n, ref.u) : 0.0;
  TEST_TRUE(scale > 0.0);
  for (int k = 0; k < num_solvers && ref.ok; k++) {
    scene_json(json, sizeof json, n, material, time, solvers[k], effects);
    run_out r = run(ctx, json);
    TEST_TRUE(r.ok);
    if (r.ok && r.n == ref.n) {
      double d = 0.0;
      for (fcm_index i = 0; i < r.n; i++)
        d = fmax(d, fabs(r.u[i] - ref.u[i]));
      if (!(d <= 1e-6 * scale))
        TEST_FAIL_("%s, solver %s: max |u - u_direct| = %.3g > 1e-6 x %.3g", label, solvers[k], d,
                   scale);
      if (getenv("FCM_TEST_VERBOSE"))
        fprintf(stderr,
                "%s %s: diff %.3g of %.3g; %lld Newton, %lld linear, %lld cycles, %d levels\n",
                label, solvers[k], d, scale, r.newton, r.linear, r.cycles, r.levels);
      TEST_TRUE(r.levels >= 2);
      TEST_TRUE(r.level0_dofs == r.n);
      TEST_TRUE(r.cycles > 0);
      if (strstr(solvers[k], "\"method\": \"multigrid\""))
        TEST_TRUE(r.cycles == r.linear);
      else
        TEST_TRUE(r.cycles >= r.linear);
      TEST_TRUE(r.pieces == ref.pieces);
    } else {
      TEST_FAIL_("%s, solver %s: run failed or %lld DOFs vs %lld", label, solvers[k],
                 (long long)r.n, (long long)ref.n);
    }
    free(r.u);
  }
  free(ref.u);
}

#define TIGHT_NEWTON "\"newton\": {\"rule\": \"relative\", \"rtol\": 1e-9%s}"
#define MG_OPTS      "\"multigrid\": {\"coarse_dofs\": 100}"

static void mode_agree(fcm_ctx *ctx)
{
  const char *static_time = "{\"static\": true, \"steps\": 1, \"load_steps\": 2}";
  const char *clamp = "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
                      " {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.01, 0, 0],"
                      "   \"normal\": [-1, 0, 0]}}}}";
  const char *nitsche = "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
                        " {\"fixed\": {\"boundary\": {\"half_space\": {\"point\": [0.02, 0, 0],"
                        "   \"normal\": [-1, 0, 0]}}}}";
  char ref[512], s[4][512];
  const char *sv[4] = {s[0], s[1], s[2], s[3]};
  /* static, linear: project_psd changes nothing */
  snprintf(ref, sizeof ref, "{\"method\": \"direct\", " TIGHT_NEWTON "}", "");
  snprintf(s[0], sizeof s[0],
           "{\"method\": \"cg\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS
           ", " TIGHT_NEWTON "}",
           "");
  snprintf(s[1], sizeof s[1],
           "{\"method\": \"minres\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS
           ", " TIGHT_NEWTON "}",
           "");
  snprintf(s[2], sizeof s[2],
           "{\"method\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS ", " TIGHT_NEWTON "}", "");
  snprintf(
      s[3], sizeof s[3],
      "{\"method\": \"multigrid\", \"rtol\": 1e-11, \"multigrid\": {\"coarse_dofs\": 100,"
      " \"smoother\": \"sgs-colored\", \"cycle\": \"w\", \"pre_smooth\": 2, \"post_smooth\": 1},"
      " " TIGHT_NEWTON "}",
      "");
  agree(ctx, "static clamped", 4, linear_material, static_time, ref, sv, 4, clamp, 0);
  agree(ctx, "static nitsche", 4, linear_material, static_time, ref, sv, 3, nitsche, 0);
  grid_element = "hex20"; /* the p-level Hex20 -> Hex8 first */
  agree(ctx, "static clamped hex20", 2, linear_material, static_time, ref, sv, 3, clamp, 0);
  grid_element = "hex8";

  /* dynamic, stable neo-Hookean with PSD tangents (SPD Newton matrices: MG alone applies); a
   * motion of the far end released after the first step changes the eliminated rows */
  const char *dyn_time = "{\"dt\": 0.02, \"steps\": 3}";
  const char *dyn = "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
                    " {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.01, 0, 0],"
                    "   \"normal\": [-1, 0, 0]}}}},"
                    " {\"motion\": {\"region\": {\"half_space\": {\"point\": [2.1, 0, 0],"
                    "   \"normal\": [1, 0, 0]}}, \"velocity\": [0, 0, 1], \"end\": 0.02,"
                    "   \"release\": true}}";
  const char *psd = ", \"project_psd\": true";
  snprintf(ref, sizeof ref, "{\"method\": \"direct\", " TIGHT_NEWTON "}", psd);
  snprintf(s[0], sizeof s[0],
           "{\"method\": \"cg\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS
           ", " TIGHT_NEWTON "}",
           psd);
  snprintf(s[1], sizeof s[1],
           "{\"method\": \"minres\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS
           ", " TIGHT_NEWTON "}",
           psd);
  snprintf(s[2], sizeof s[2],
           "{\"method\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS ", " TIGHT_NEWTON "}", psd);
  agree(ctx, "dynamic psd", 4, snh_material, dyn_time, ref, sv, 3, dyn, 0);

  /* the exact (indefinite) tangent: MINRES preconditioned by MG on the projected tangent */
  snprintf(ref, sizeof ref, "{\"method\": \"direct\", " TIGHT_NEWTON "}", "");
  snprintf(s[0], sizeof s[0],
           "{\"method\": \"minres\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS
           ", " TIGHT_NEWTON "}",
           "");
  agree(ctx, "dynamic exact", 4, snh_material, dyn_time, ref, sv, 1, dyn, 0);
}

/* A slab clamped at x = 0 cut at t = 0.03 by a plane through its middle (z = 0.45). */
static void mode_cut(fcm_ctx *ctx)
{
  const char *time = "{\"dt\": 0.02, \"steps\": 3}";
  const char *effects = "{\"gravity\": {}},"
                        " {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.01, 0, 0],"
                        "   \"normal\": [-1, 0, 0]}}}},"
                        " {\"cut\": {\"time\": 0.03, \"surface\": {\"plane\": {\"point\": [1, 0.5,"
                        "   0.45], \"normal\": [0, 0.1, 1]}}}}";
  const char *psd = ", \"project_psd\": true";
  char ref[512], s[3][512];
  const char *sv[3] = {s[0], s[1], s[2]};
  snprintf(ref, sizeof ref, "{\"method\": \"direct\", " TIGHT_NEWTON "}", psd);
  snprintf(s[0], sizeof s[0],
           "{\"method\": \"cg\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS
           ", " TIGHT_NEWTON "}",
           psd);
  snprintf(s[1], sizeof s[1],
           "{\"method\": \"minres\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS
           ", " TIGHT_NEWTON "}",
           psd);
  snprintf(s[2], sizeof s[2],
           "{\"method\": \"multigrid\", \"rtol\": 1e-11, " MG_OPTS ", " TIGHT_NEWTON "}", psd);
  /* the cut separates the slab: two bodies at the end in every run */
  agree(ctx, "cut", 4, snh_material, time, ref, sv, 3, effects, 2);
}

static void mode_iterations(fcm_ctx *ctx)
{
  const char *time = "{\"static\": true, \"steps\": 1}";
  const char *clamp = "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
                      " {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.01, 0, 0],"
                      "   \"normal\": [-1, 0, 0]}}}}";
  static char json[8192];
  scene_json(json, sizeof json, 8, linear_material, time,
             "{\"method\": \"cg\", \"preconditioner\": \"jacobi\", \"rtol\": 1e-8,"
             " \"max_iterations\": 20000}",
             clamp);
  run_out jac = run(ctx, json);
  scene_json(json, sizeof json, 8, linear_material, time,
             "{\"method\": \"cg\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-8,"
             " \"multigrid\": {\"coarse_dofs\": 500}}",
             clamp);
  run_out mg = run(ctx, json);
  TEST_TRUE(jac.ok && mg.ok);
  if (getenv("FCM_TEST_VERBOSE"))
    fprintf(stderr, "CG+Jacobi %lld iterations, CG+MG %lld iterations (%lld cycles, %d levels)\n",
            jac.linear, mg.linear, mg.cycles, mg.levels);
  TEST_TRUE(jac.newton == 1 && mg.newton == 1); /* linear: one Newton update each */
  TEST_TRUE(mg.levels >= 3);
  TEST_TRUE(mg.linear > 0 && 5 * mg.linear <= jac.linear);
  if (jac.ok && mg.ok && jac.n == mg.n) {
    double d = 0.0;
    for (fcm_index i = 0; i < mg.n; i++)
      d = fmax(d, fabs(mg.u[i] - jac.u[i]));
    TEST_TRUE(d <= 1e-5 * max_abs(jac.n, jac.u));
  }
  free(jac.u);
  free(mg.u);
}

/* A scene with `solver` must fail with FCM_ERR_ARG and a message with each of the parts. */
static void bad(fcm_ctx *ctx, const char *element, const char *solver, const char *part1,
                const char *part2)
{
  static char json[8192];
  snprintf(json, sizeof json,
           "{\"version\": 1, \"background\": {\"element\": \"%s\", \"box\": {\"min\": [0, 0, 0],"
           " \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
           " \"solver\": %s, \"time\": {\"static\": true},"
           " \"effects\": [{\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"
           " \"normal\": [-1, 0, 0]}}}}]}",
           element, solver);
  fcm_scene *scene = NULL;
  fcm_status st = fcm_scene_create_from_string(ctx, json, "bad.json", &scene);
  const char *msg = fcm_ctx_error_message(ctx);
  if (getenv("FCM_TEST_VERBOSE")) fprintf(stderr, "%s\n", msg);
  if (st != FCM_ERR_ARG || !strstr(msg, part1) || (part2 && !strstr(msg, part2)))
    TEST_FAIL_("solver %s on %s: got %s \"%s\", expected FCM_ERR_ARG with \"%s\" and \"%s\"",
               solver, element, fcm_status_name(st), msg, part1, part2 ? part2 : "");
  fcm_ctx_error_clear(ctx);
  fcm_scene_destroy(&scene);
}

static void good(fcm_ctx *ctx, const char *element, const char *solver, int smoother, double omega)
{
  static char json[8192];
  snprintf(json, sizeof json,
           "{\"version\": 1, \"background\": {\"element\": \"%s\", \"box\": {\"min\": [0, 0, 0],"
           " \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
           " \"solver\": %s, \"time\": {\"static\": true}, \"effects\": []}",
           element, solver);
  fcm_scene *scene = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "good.json", &scene));
  if (scene) {
    const fcm_integrator_options *s = &fcm_scene_get_solver(scene)->integrator;
    TEST_TRUE((int)s->multigrid.smoother == smoother);
    TEST_NEAR(s->multigrid.omega, omega, 0.0, 0.0);
  }
  fcm_scene_destroy(&scene);
}

/* Host API: a static clamped beam on a box mesh of `type`. */
static fcm_status host_run(fcm_ctx *ctx, fcm_element_type type, const fcm_integrator_options *o,
                           int clamp, int steps, fcm_step_info *info, int *setup_status)
{
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_integrator *I = NULL;
  fcm_index *nodes = NULL, count = 0;
  fcm_status st = FCM_OK;
  double *u0 = NULL;
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e6, 0.3, 1000.0};
  *setup_status = FCM_OK;
  if ((st = beam_mesh(ctx, type, 8, 4.0, &mesh)) != FCM_OK) goto done;
  if ((st = fcm_space_create(ctx, mesh, NULL, &space)) != FCM_OK) goto done;
  if ((st = fcm_integrator_create(ctx, space, &mat, o, &I)) != FCM_OK) goto done;
  double g[3] = {0, 0, -9.81};
  if ((st = fcm_integrator_add_gravity(I, g, NULL, NULL)) != FCM_OK) goto done;
  if (clamp) {
    nodes = plane_nodes(ctx, mesh, 0, 0.0, &count);
    fcm_motion m = fcm_motion_default();
    if ((st = fcm_integrator_add_constraint(I, count, nodes, &m, NULL)) != FCM_OK) goto done;
  }
  if ((*setup_status = st = fcm_integrator_setup(I)) != FCM_OK) goto done;
  fcm_index n = fcm_integrator_num_dofs(I);
  u0 = malloc(sizeof *u0 * (size_t)n);
  memcpy(u0, fcm_integrator_displacement(I), sizeof *u0 * (size_t)n);
  for (int k = 0; k < steps && st == FCM_OK; k++)
    st = fcm_integrator_step(I, info);
  if (st == FCM_ERR_NOT_CONVERGED) /* a failed step leaves the state alone */
    TEST_TRUE(vec_dist(n, u0, fcm_integrator_displacement(I)) == 0.0 &&
              fcm_integrator_step_count(I) == 0);
done:
  free(u0);
  free(nodes);
  fcm_integrator_destroy(&I);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  return st;
}

static void mode_errors(fcm_ctx *ctx)
{
  /* scene parser */
  bad(ctx, "hex8",
      "{\"method\": \"cg\", \"preconditioner\": \"multigrid\","
      " \"multigrid\": {\"smoother\": \"gs\"}}",
      "solver.multigrid.smoother", "sgs-colored");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"omega\": 2}}",
      "solver.multigrid.omega", "[0, 2)");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"omega\": -0.5}}",
      "solver.multigrid.omega", "[0, 2)");
  bad(ctx, "hex8",
      "{\"method\": \"multigrid\", \"multigrid\": {\"smoother\": \"jacobi\","
      " \"omega\": 1.2}}",
      "solver.multigrid.omega", "(0, 1]");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"pre_smooth\": -1}}",
      "solver.multigrid.pre_smooth", "[0, 100]");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"post_smooth\": 101}}",
      "solver.multigrid.post_smooth", "[0, 100]");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"cycle\": \"f\"}}",
      "solver.multigrid.cycle", "\"w\"");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"coarse_dofs\": 0}}",
      "solver.multigrid.coarse_dofs", "1");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"levels\": 3}}",
      "solver.multigrid", "levels");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": []}", "solver.multigrid", "object");
  bad(ctx, "hex8",
      "{\"method\": \"multigrid\", \"multigrid\": {\"pre_smooth\": 0, \"post_smooth\": 0}}",
      "solver.multigrid", "at least one smoothing step");
  bad(ctx, "hex8",
      "{\"method\": \"cg\", \"preconditioner\": \"multigrid\", \"multigrid\": {\"post_smooth\": "
      "2}}",
      "solver.multigrid", "must be equal");
  bad(ctx, "hex8",
      "{\"method\": \"minres\", \"preconditioner\": \"multigrid\", \"multigrid\": {\"pre_smooth\": "
      "3}}",
      "solver.multigrid", "\"minres\"");
  bad(ctx, "tet10", "{\"method\": \"multigrid\"}", "solver.method", "\"hex20\"");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"block_smoothing\": 1}}",
      "solver.multigrid.block_smoothing", "true");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"blocks\": \"cells\"}}",
      "solver.multigrid.blocks", "\"vertex\"");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"block_sweep\": 1}}",
      "solver.multigrid.block_sweep", "\"one_way\"");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"point_sweep\": \"one\"}}",
      "solver.multigrid.point_sweep", "\"one_way\"");
  bad(ctx, "hex8",
      "{\"method\": \"multigrid\", \"multigrid\": {\"point_sweep\": \"one_way\", "
      "\"smoother\": \"jacobi\"}}",
      "solver.multigrid.point_sweep", "\"sgs\"");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"coarse_interval\": 0}}",
      "solver.multigrid.coarse_interval", "1");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"block_fraction\": 0}}",
      "solver.multigrid.block_fraction", "(0, 1]");
  bad(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"block_fraction\": 1.5}}",
      "solver.multigrid.block_fraction", "(0, 1]");
  bad(ctx, "tet4", "{\"method\": \"minres\", \"preconditioner\": \"multigrid\"}",
      "solver.preconditioner", "\"tet4\"");
  bad(ctx, "hex8", "{\"method\": \"mg\"}", "solver.method", "\"multigrid\"");
  /* accepted: defaults, the Jacobi default omega, an unsymmetric cycle for the solver, the
   * options unused by another method, the underscore spelling */
  good(ctx, "hex8", "{\"method\": \"multigrid\"}", FCM_MG_SMOOTHER_SGS, 0.0);
  good(ctx, "hex8", "{\"method\": \"multigrid\", \"multigrid\": {\"smoother\": \"jacobi\"}}",
       FCM_MG_SMOOTHER_JACOBI, 0.0);
  good(ctx, "hex8",
       "{\"method\": \"multigrid\", \"multigrid\": {\"pre_smooth\": 2, \"post_smooth\": 0,"
       " \"smoother\": \"sgs_colored\", \"omega\": 1.5}}",
       FCM_MG_SMOOTHER_SGS_COLORED, 1.5);
  good(ctx, "tet4", "{\"method\": \"direct\", \"preconditioner\": \"multigrid\"}",
       FCM_MG_SMOOTHER_SGS, 0.0);
  good(ctx, "hex20",
       "{\"method\": \"cg\", \"preconditioner\": \"multigrid\", \"multigrid\": "
       "{\"block_smoothing\": false, \"smoother\": \"jacobi\", \"omega\": 0.5}}",
       FCM_MG_SMOOTHER_JACOBI, 0.5);

  /* the view (and so a checkpoint's fingerprint) names the block and sweep options that
   * differ from the defaults, and a scene without them keeps its view */
  for (int k = 0; k < 2; k++) {
    fcm_scene *sc = NULL;
    char j[1024], text[4096] = "";
    snprintf(j, sizeof j,
             "{\"version\": 1, \"background\": {\"element\": \"hex8\", \"box\": {\"min\": "
             "[0, 0, 0], \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]}, \"material\": {\"model\": "
             "\"linear\", \"young\": 1e6, \"poisson\": 0.3}, \"solver\": {\"method\": "
             "\"multigrid\"%s}, \"time\": {\"static\": true}, \"effects\": []}",
             k ? ", \"multigrid\": {\"blocks\": \"element\", \"block_fraction\": 0.5, "
                 "\"block_sweep\": \"one_way\", \"point_sweep\": \"one_way\", "
                 "\"coarse_interval\": 4}"
               : "");
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, j, "view.json", &sc));
    FILE *f = tmpfile();
    if (sc && f) {
      fcm_scene_view(sc, f);
      rewind(f);
      text[fread(text, 1, sizeof text - 1, f)] = '\0';
    }
    if (f) fclose(f);
    static const char *const words[] = {"element blocks", "a piece under 0.5", "blocks one way",
                                        "points one way", "every 4 set-ups"};
    for (size_t w = 0; w < sizeof words / sizeof *words; w++)
      TEST_TRUE(!strstr(text, words[w]) == !k);
    TEST_TRUE(strstr(text, "V-cycle") || strstr(text, "W-cycle"));
    fcm_scene_destroy(&sc);
  }
  {
    fcm_scene *sc = NULL;
    const char *j = "{\"version\": 1, \"background\": {\"element\": \"hex20\", \"box\": "
                    "{\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
                    " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
                    " \"solver\": {\"method\": \"multigrid\", \"multigrid\": {\"block_smoothing\":"
                    " false, \"cycle\": \"w\", \"coarse_dofs\": 77, \"pre_smooth\": 3,"
                    " \"blocks\": \"element\", \"block_fraction\": 0.25, \"block_sweep\":"
                    " \"one_way\", \"point_sweep\": \"one_way\", \"coarse_interval\": 4}},"
                    " \"time\": {\"static\": true}, \"effects\": []}";
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, j, "hex20.json", &sc));
    if (sc) {
      const fcm_mg_options *m = &fcm_scene_get_solver(sc)->integrator.multigrid;
      TEST_TRUE(m->block_smoothing == 0 && m->cycle_index == 2 && m->coarse_dofs == 77 &&
                m->pre_smooth == 3 && m->post_smooth == 1 && m->blocks == FCM_MG_BLOCKS_ELEMENT &&
                m->block_fraction == 0.25 && m->block_sweep == 1 && m->point_sweep == 1 &&
                m->coarse_interval == 4);
    }
    fcm_scene_destroy(&sc);
  }

  /* integrator setup */
  fcm_step_info info;
  int setup = 0;
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_STATIC;
  o.tolerance_mode = FCM_NEWTON_TOL_REPRESENTATIVE;
  o.preconditioner = FCM_PRECOND_JACOBI;
  o.dt = 1.0;
  o.linear_solver = FCM_LINEAR_MULTIGRID;
  o.multigrid.omega = 2.5;
  TEST_TRUE(host_run(ctx, FCM_ELEMENT_HEX8, &o, 1, 1, &info, &setup) == FCM_ERR_ARG &&
            setup == FCM_ERR_ARG && strstr(fcm_ctx_error_message(ctx), "multigrid.omega") &&
            strstr(fcm_ctx_error_message(ctx), "(0, 2)"));
  fcm_ctx_error_clear(ctx);
  o.multigrid = fcm_mg_options_default();
  o.linear_solver = FCM_LINEAR_CG;
  o.preconditioner = FCM_PRECOND_MULTIGRID;
  o.multigrid.post_smooth = 2;
  TEST_TRUE(host_run(ctx, FCM_ELEMENT_HEX8, &o, 1, 1, &info, &setup) == FCM_ERR_ARG &&
            strstr(fcm_ctx_error_message(ctx), "multigrid.pre_smooth") &&
            strstr(fcm_ctx_error_message(ctx), "must be equal"));
  fcm_ctx_error_clear(ctx);
  o.multigrid = fcm_mg_options_default();
  o.multigrid.smoother = FCM_MG_SMOOTHER_COUNT;
  TEST_TRUE(host_run(ctx, FCM_ELEMENT_HEX8, &o, 1, 1, &info, &setup) == FCM_ERR_ARG &&
            strstr(fcm_ctx_error_message(ctx), "multigrid.smoother"));
  fcm_ctx_error_clear(ctx);
  o.multigrid = fcm_mg_options_default();
  o.linear_solver = (fcm_linear_solver)4;
  TEST_TRUE(host_run(ctx, FCM_ELEMENT_HEX8, &o, 1, 1, &info, &setup) == FCM_ERR_ARG &&
            strstr(fcm_ctx_error_message(ctx), "linear_solver = 4 outside [0, 3]"));
  fcm_ctx_error_clear(ctx);
  o.linear_solver = FCM_LINEAR_CG;
  o.preconditioner = (fcm_preconditioner)5;
  TEST_TRUE(host_run(ctx, FCM_ELEMENT_HEX8, &o, 1, 1, &info, &setup) == FCM_ERR_ARG &&
            strstr(fcm_ctx_error_message(ctx), "preconditioner = 5 outside [0, 4]"));
  fcm_ctx_error_clear(ctx);
  /* the options are not checked when no multigrid is used */
  o.preconditioner = FCM_PRECOND_JACOBI;
  o.multigrid.omega = -1.0;
  TEST_OK(ctx, host_run(ctx, FCM_ELEMENT_HEX8, &o, 1, 1, &info, &setup));
  o.multigrid = fcm_mg_options_default();

  /* a Tet4 space: the first step refuses it (a hard error naming the option) */
  o.linear_solver = FCM_LINEAR_MULTIGRID;
  TEST_TRUE(host_run(ctx, FCM_ELEMENT_TET4, &o, 1, 1, &info, &setup) == FCM_ERR_UNSUPPORTED &&
            setup == FCM_OK &&
            strstr(fcm_ctx_error_message(ctx), "integrator: linear_solver multigrid") &&
            strstr(fcm_ctx_error_message(ctx), "Hex8"));
  fcm_ctx_error_clear(ctx);
  o.linear_solver = FCM_LINEAR_MINRES;
  o.preconditioner = FCM_PRECOND_MULTIGRID;
  TEST_TRUE(host_run(ctx, FCM_ELEMENT_TET4, &o, 1, 1, &info, &setup) == FCM_ERR_UNSUPPORTED &&
            strstr(fcm_ctx_error_message(ctx), "integrator: preconditioner multigrid"));
  fcm_ctx_error_clear(ctx);

  /* Hex8 host run: MG alone solves the clamped beam (no halving) */
  o.linear_solver = FCM_LINEAR_MULTIGRID;
  o.multigrid.coarse_dofs = 20;
  TEST_OK(ctx, host_run(ctx, FCM_ELEMENT_HEX8, &o, 1, 1, &info, &setup));
  TEST_TRUE(info.reason == FCM_STEP_CONVERGED && info.halvings == 0 &&
            info.multigrid_cycles == info.linear_iterations && info.multigrid_cycles > 0);
  /* a static body without any constraint: K is singular (rigid modes), refused before the
   * multigrid is built or cycled, with no attempt */
  o.max_halvings = 1;
  TEST_TRUE(host_run(ctx, FCM_ELEMENT_HEX8, &o, 0, 1, &info, &setup) == FCM_ERR_SINGULAR &&
            strstr(fcm_ctx_error_message(ctx), "refused before any solve") &&
            info.linear_iterations == 0 && info.factorizations == 0);
  fcm_ctx_error_clear(ctx);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  const char *mode = argc > 1 ? argv[1] : "errors";
  if (!strcmp(mode, "agree"))
    mode_agree(ctx);
  else if (!strcmp(mode, "cut"))
    mode_cut(ctx);
  else if (!strcmp(mode, "iterations"))
    mode_iterations(ctx);
  else if (!strcmp(mode, "errors"))
    mode_errors(ctx);
  else
    TEST_FAIL_("unknown mode %s", mode);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
