/* Benchmark: what a host's cut costs in either frame (figures in lib/docs/cutting.md,
 * "Cutting from a host program"). Dick's Bunny 3 row of fcm-cutbench (a body surface, by
 * default the generated apps/scenes/models/cutbench_body.obj, on a Hex8 grid of 6.33 mm there,
 * scaled with the body's box for another,
 * corotated linear, gravity, the body's lowest tenth in y held; the interactive solver set),
 * two steps, then one blade: a rectangle of (M + 1)^2 vertices on the plane x through the body's
 * middle, over its upper 60 % in y and past its sides in z. Timed, the best
 * of NREP fresh runs: fcm_simulation_rest_positions() of the blade's vertices, and
 * fcm_simulation_cut() with the blade at rest (FCM_CUT_FRAME_REFERENCE) and, on a second
 * simulation in the same state, where the tool is (FCM_CUT_FRAME_DEFORMED), both with
 * host_cuts, and at rest on a third without it (every element integrated again), with their
 * phases. Asserts that both cuts changed the body and that host_cuts changes nothing but time.
 * Usage: bench_cut_frame BODY.obj [M] (default M = 10). */
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define NREP 3

static fcm_ctx *ctx;
static char json[4096];
static fcm_scene *scenes[3 * NREP]; /* read by their simulations for their life */
static int num_scenes;

static fcm_simulation *bunny(int host_cuts)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "bench_cut_frame.json", &scene));
  fcm_simulation_options so = fcm_simulation_options_default();
  so.host_cuts = host_cuts;
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, &so, &sim));
  if (num_scenes < 3 * NREP)
    scenes[num_scenes++] = scene;
  else
    fcm_scene_destroy(&scene);
  for (int k = 0; sim && k < 2; k++)
    TEST_OK(ctx, fcm_simulation_step(sim, NULL));
  return sim;
}

int main(int argc, char **argv)
{
  if (argc < 2) {
    fprintf(stderr, "usage: bench_cut_frame BODY.obj [M]\n");
    return 2;
  }
  const int M = argc > 2 ? atoi(argv[2]) : 10;
  TEST_TRUE(fcm_ctx_create(NULL, &ctx) == FCM_OK && M >= 1 && M <= 200);
  /* the body's box: its lowest tenth held, the blade placed on it */
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  fcm_surface *body = NULL;
  TEST_OK(ctx, fcm_surface_create_from_file(ctx, argv[1], &body));
  if (!body) return 1;
  fcm_surface_bounding_box(body, lo, hi);
  fcm_surface_destroy(&body);
  /* the row's cells (6.33 mm on the generated body, whose box has a diagonal of 0.2498 m),
   * scaled with the body's box */
  const double h = 0.00632898 *
                   sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2])) /
                   0.2498;
  snprintf(
      json, sizeof json,
      "{\"version\": 1, \"name\": \"bench_cut_frame\","
      " \"background\": {\"element\": \"hex8\", \"fit_background\": {\"cell_size\": %.17g, "
      "\"margin\": %.17g}},"
      " \"geometry\": {\"surface\": \"%s\", \"fill_holes\": true},"
      " \"material\": {\"model\": \"corotated_linear\", \"young\": 1e5, \"poisson\": 0.4,"
      "  \"density\": 1000},"
      " \"quadrature\": {\"stiffness_on_mass_space\": true},"
      " \"solver\": {\"method\": \"multigrid\", \"fixed_cycles\": 3, \"multigrid\": {\"cycle\": "
      "\"v\", \"blocks\": \"element\", \"block_fraction\": 0.5, \"block_sweep\": \"one_way\","
      " \"point_sweep\": \"one_way\", \"coarse_interval\": 4}, \"newton\": "
      "{\"fixed_iterations\": 1, \"project_psd\": true}},"
      " \"time\": {\"dt\": 0.01, \"steps\": 9}, \"output\": {\"frame_interval\": 1000},"
      " \"effects\": [{\"gravity\": {\"acceleration\": [0, -9.81, 0]}},"
      "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, %.17g, 0], \"normal\": "
      "[0, -1, 0]}}}}]}",
      h, 0.5 * h, argv[1], lo[1] + 0.1 * (hi[1] - lo[1]));
  /* the blade: the plane x through the box's middle, over its upper 60 % and beyond its sides */
  const int nv = (M + 1) * (M + 1), nt = 2 * M * M;
  double *v = malloc(3 * (size_t)nv * sizeof *v), *rest = malloc(3 * (size_t)nv * sizeof *rest);
  fcm_index *tri = malloc(3 * (size_t)nt * sizeof *tri);
  fcm_surface *blade = NULL;
  for (int i = 0; v && i <= M; i++)
    for (int j = 0; j <= M; j++) {
      double *p = v + 3 * (i * (M + 1) + j);
      const double hy = hi[1] - lo[1], hz = hi[2] - lo[2];
      p[0] = 0.5 * (lo[0] + hi[0]) + 1e-3 * (hi[0] - lo[0]);
      p[1] = lo[1] + 0.4 * hy + 0.7 * hy * i / M;
      p[2] = lo[2] - 0.1 * hz + 1.2 * hz * j / M;
    }
  for (int i = 0, k = 0; tri && i < M; i++)
    for (int j = 0; j < M; j++, k++) {
      const fcm_index a = i * (M + 1) + j, b = a + 1, c = a + M + 1, d = c + 1;
      const fcm_index q[6] = {a, b, d, a, d, c};
      for (int r = 0; r < 6; r++)
        tri[6 * k + r] = q[r];
    }
  if (v && tri) TEST_OK(ctx, fcm_surface_create(ctx, nv, v, nt, tri, &blade));
  double best_pull = 1e300, best_ref = 1e300, best_def = 1e300, best_all = 1e300;
  fcm_cut_info ref = {0}, def = {0}, all = {0};
  fcm_index elements = 0;
  for (int rep = 0; rep < NREP && blade && rest; rep++) {
    fcm_simulation *a = bunny(1), *b = bunny(1), *c = bunny(0);
    if (!a || !b || !c) {
      fcm_simulation_destroy(&a);
      fcm_simulation_destroy(&b);
      fcm_simulation_destroy(&c);
      break;
    }
    elements = fcm_space_num_elements(fcm_simulation_space(b));
    double t0 = fcm_wtime();
    TEST_OK(ctx, fcm_simulation_rest_positions(b, nv, v, rest));
    const double pull = fcm_wtime() - t0;
    fcm_cut_info ia, ib, ic;
    TEST_OK(ctx, fcm_simulation_cut(a, blade, FCM_CUT_FRAME_REFERENCE, &ia));
    TEST_OK(ctx, fcm_simulation_cut(b, blade, FCM_CUT_FRAME_DEFORMED, &ib));
    TEST_OK(ctx, fcm_simulation_cut(c, blade, FCM_CUT_FRAME_REFERENCE, &ic));
    TEST_TRUE(!ia.missed && !ib.missed && ic.dofs_after == ia.dofs_after);
    if (pull < best_pull) best_pull = pull;
    if (ia.seconds < best_ref) best_ref = ia.seconds, ref = ia;
    if (ib.seconds < best_def) best_def = ib.seconds, def = ib;
    if (ic.seconds < best_all) best_all = ic.seconds, all = ic;
    fcm_simulation_destroy(&a);
    fcm_simulation_destroy(&b);
    fcm_simulation_destroy(&c);
  }
  if (elements == 0) {
    fprintf(stderr, "bench_cut_frame: no run went through\n");
    TEST_TRUE(0);
  } else {
    printf("Bunny 3 row after two steps, %lld elements; a blade of %d vertices, %d triangles; "
           "best of %d\n",
           (long long)elements, nv, nt, NREP);
    printf("  fcm_simulation_rest_positions() of its vertices: %.4f s\n", best_pull);
    const fcm_cut_info *c[3] = {&ref, &def, &all};
    const char *name[3] = {"reference frame", "deformed frame ", "reference frame, host_cuts 0"};
    for (int k = 0; k < 3; k++)
      printf("  cut, %s: %.4f s (rules %.4f, space %.4f, integrator %.4f, solver %.4f), "
             "%lld cells, %lld -> %lld DOFs\n",
             name[k], c[k]->seconds, c[k]->seconds_rules, c[k]->seconds_space,
             c[k]->seconds_integrator, c[k]->seconds_solver, (long long)c[k]->cells_integrated,
             (long long)c[k]->dofs_before, (long long)c[k]->dofs_after);
  }
  fcm_surface_destroy(&blade);
  while (num_scenes > 0)
    fcm_scene_destroy(&scenes[--num_scenes]);
  free(v), free(rest), free(tri);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
