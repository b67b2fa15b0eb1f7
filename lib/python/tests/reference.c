/* The C side of the Python package's bit-for-bit tests: the problems the tests also solve
 * through the binding, here through the C API alone; the final displacement is written to
 * <out> as raw native doubles.
 *   python_reference static <out>          an embedded ball under gravity, clamped by
 *                                          Nitsche's method on its lower cap (z < -0.35)
 *   python_reference dynamic <steps> <cut> <out>
 *                                          a bar clamped at x = 0 swinging under gravity,
 *                                          cut at x = 1.1 after step <cut>
 *   python_reference scene <file> <steps> <out>
 *                                          the first <steps> steps of a scene
 * Exit status 0 on success; on failure the library's message on stderr. */
#include <fcm/fcm.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CHECK(call)                                                                                \
  do {                                                                                             \
    if ((call) != FCM_OK) {                                                                        \
      fprintf(stderr, "python_reference: %s failed\n", #call);                                     \
      fcm_ctx_error_view(ctx, stderr);                                                             \
      goto done;                                                                                   \
    }                                                                                              \
  } while (0)

static int write_doubles(const char *path, const double *x, fcm_index n)
{
  FILE *f = fopen(path, "wb");
  if (!f) return 0;
  const int ok = fwrite(x, sizeof *x, (size_t)n, f) == (size_t)n;
  return fclose(f) == 0 && ok;
}

static int lower_cap(void *user, const double X[3], const double normal[3])
{
  (void)user;
  (void)normal;
  return X[2] < -0.35;
}

static int run_static(fcm_ctx *ctx, const char *out)
{
  int ok = 0;
  fcm_mesh *mesh = NULL;
  fcm_geometry *ball = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  const double lo[3] = {-0.6, -0.6, -0.6}, hi[3] = {0.6, 0.6, 0.6}, c[3] = {0, 0, 0};
  const fcm_index n[3] = {6, 6, 6};
  CHECK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  CHECK(fcm_geometry_create_ball(ctx, c, 0.5, 3, &ball));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.kinds = FCM_RULES_STIFFNESS;
  ro.surface_strength = 2;
  CHECK(fcm_cell_rules_create(ctx, mesh, ball, &ro, &rules));
  CHECK(fcm_space_create_embedded(ctx, mesh, rules, &space));
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2e5, 0.4, 1100.0};
  fcm_integrator_options io = fcm_integrator_options_default();
  io.kind = FCM_INTEGRATOR_STATIC;
  io.tolerance_mode = FCM_NEWTON_TOL_REPRESENTATIVE;
  io.dt = 1.0;
  io.load_steps = 2;
  CHECK(fcm_integrator_create(ctx, space, &mat, &io, &integ));
  const double g[3] = {0.0, 0.0, -9.81};
  CHECK(fcm_integrator_add_gravity(integ, g, NULL, NULL));
  const fcm_motion fixed = fcm_motion_default();
  CHECK(fcm_integrator_add_boundary_constraint(integ, lower_cap, NULL, &fixed, NULL, NULL));
  CHECK(fcm_integrator_setup(integ));
  fcm_step_info si;
  CHECK(fcm_integrator_step(integ, &si));
  ok = write_doubles(out, fcm_integrator_displacement(integ), fcm_integrator_num_dofs(integ));
done:
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&mesh);
  return ok;
}

static int run_dynamic(fcm_ctx *ctx, int steps, int cut_after, const char *out)
{
  int ok = 0;
  fcm_mesh *mesh = NULL;
  fcm_geometry *bar = NULL;
  fcm_surface *cut = NULL;
  fcm_cell_rules *rules = NULL, *rules2 = NULL;
  fcm_space *space = NULL, *space2 = NULL;
  fcm_integrator *integ = NULL, *integ2 = NULL;
  fcm_index *clamp = NULL;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 0.5, 0.5};
  const fcm_index cells[3] = {8, 2, 2};
  const double blo[3] = {0, 0.05, 0.05}, bhi[3] = {1.8, 0.45, 0.45};
  const fcm_index bcells[3] = {18, 4, 4};
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000.0};
  CHECK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  CHECK(fcm_geometry_create_box(ctx, blo, bhi, bcells, &bar));
  CHECK(fcm_cell_rules_create(ctx, mesh, bar, NULL, &rules));
  CHECK(fcm_space_create_embedded(ctx, mesh, rules, &space));
  fcm_integrator_options io = fcm_integrator_options_default();
  io.dt = 0.01;
  CHECK(fcm_integrator_create(ctx, space, &mat, &io, &integ));
  const double g[3] = {0, 0, -9.81}, nlo[3] = {-1, -1, -1}, nhi[3] = {0, 1, 1};
  fcm_index n = 0;
  CHECK(fcm_integrator_add_gravity(integ, g, NULL, NULL));
  CHECK(fcm_mesh_nodes_in_box(ctx, mesh, nlo, nhi, 1e-9, 0, NULL, &n));
  clamp = malloc((size_t)n * sizeof *clamp);
  if (!clamp) goto done;
  CHECK(fcm_mesh_nodes_in_box(ctx, mesh, nlo, nhi, 1e-9, n, clamp, &n));
  const fcm_motion fixed = fcm_motion_default();
  CHECK(fcm_integrator_add_constraint(integ, n, clamp, &fixed, NULL));
  CHECK(fcm_integrator_setup(integ));
  const double x[12] = {1.1, -1, -1, 1.1, 2, -1, 1.1, 2, 2, 1.1, -1, 2};
  const fcm_index tri[6] = {0, 1, 2, 0, 2, 3};
  CHECK(fcm_surface_create(ctx, 4, x, 2, tri, &cut));
  for (int step = 1; step <= steps; step++) {
    fcm_step_info si;
    CHECK(fcm_integrator_step(integ, &si));
    if (step != cut_after) continue;
    CHECK(fcm_cell_rules_create_cut(ctx, mesh, bar, rules, cut, &rules2));
    CHECK(fcm_space_create_embedded(ctx, mesh, rules2, &space2));
    CHECK(fcm_integrator_create_cut(integ, space2, &integ2));
    fcm_integrator_destroy(&integ);
    fcm_space_destroy(&space);
    fcm_cell_rules_destroy(&rules);
    integ = integ2, space = space2, rules = rules2;
    integ2 = NULL, space2 = NULL, rules2 = NULL;
  }
  ok = write_doubles(out, fcm_integrator_displacement(integ), fcm_integrator_num_dofs(integ));
done:
  free(clamp);
  fcm_integrator_destroy(&integ2);
  fcm_space_destroy(&space2);
  fcm_cell_rules_destroy(&rules2);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_surface_destroy(&cut);
  fcm_geometry_destroy(&bar);
  fcm_mesh_destroy(&mesh);
  return ok;
}

static int run_scene(fcm_ctx *ctx, const char *file, int steps, const char *out)
{
  int ok = 0;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  double *u = NULL;
  CHECK(fcm_scene_create_from_file(ctx, file, &scene));
  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = steps;
  CHECK(fcm_simulation_create(ctx, scene, &so, &sim));
  CHECK(fcm_simulation_run(sim, NULL, NULL));
  const fcm_integrator *integ = fcm_simulation_integrator(sim);
  const fcm_index n = fcm_integrator_num_dofs(integ);
  u = malloc((size_t)n * sizeof *u);
  if (!u) goto done;
  fcm_integrator_get_state(integ, u, NULL, NULL, NULL);
  ok = write_doubles(out, u, n);
done:
  free(u);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return ok;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  int ok = 0;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  if (argc == 3 && !strcmp(argv[1], "static"))
    ok = run_static(ctx, argv[2]);
  else if (argc == 5 && !strcmp(argv[1], "dynamic"))
    ok = run_dynamic(ctx, atoi(argv[2]), atoi(argv[3]), argv[4]);
  else if (argc == 5 && !strcmp(argv[1], "scene"))
    ok = run_scene(ctx, argv[2], atoi(argv[3]), argv[4]);
  else
    fprintf(stderr, "usage: python_reference static|dynamic|scene ... <out>\n");
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
