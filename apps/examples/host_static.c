/* host_static: an embedded ball under gravity, clamped on its curved lower cap, solved
 * statically by a host program with fcm's C API. The clamp acts on the embedded boundary itself
 * (Nitsche's method on the surface points below z = -0.35), not on background nodes. Writes the
 * background grid and the embedded surface as VTU, both at reference positions with a
 * `displacement` array and the stresses (ParaView: Warp By Vector), and checks the clamp's
 * reaction against the weight.
 *   cc host_static.c $(pkg-config --cflags --libs fcm) -o host_static && ./host_static [dir]
 * (shared libfcm: nothing else to link; the .pc's rpath finds the library at run time)
 * Exit status 0 when the run succeeded and the ball sags under its weight. */
#include <fcm/fcm.h>

#include <stdio.h>
#include <stdlib.h>

#define CHECK(call)                                                                                \
  do {                                                                                             \
    if ((call) != FCM_OK) {                                                                        \
      fprintf(stderr, "host_static: %s failed\n", #call);                                          \
      fcm_ctx_error_view(ctx, stderr);                                                             \
      goto done;                                                                                   \
    }                                                                                              \
  } while (0)

/* The clamped part of the embedded boundary: the lower cap of the ball. */
static int lower_cap(void *user, const double X[3], const double normal[3])
{
  (void)user;
  (void)normal;
  return X[2] < -0.35;
}

int main(int argc, char **argv)
{
  const char *dir = argc > 1 ? argv[1] : ".";
  char path[4096];
  int ok = 0;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *ball = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  fcm_embedded_surface *surf = NULL;
  double *u_surf = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;

  /* Background: 6 x 6 x 6 Hex8 cells over [-0.6, 0.6]^3; body: a ball of radius 0.5. */
  const double lo[3] = {-0.6, -0.6, -0.6}, hi[3] = {0.6, 0.6, 0.6}, c[3] = {0, 0, 0};
  const fcm_index n[3] = {6, 6, 6};
  CHECK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  CHECK(fcm_geometry_create_ball(ctx, c, 0.5, 3, &ball));

  /* Cut-cell rules: a static problem needs stiffness rules only (no mass rules); the clamp
   * on the embedded boundary needs surface rules. */
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.kinds = FCM_RULES_STIFFNESS;
  ro.surface_strength = 2;
  CHECK(fcm_cell_rules_create(ctx, mesh, ball, &ro, &rules));
  fcm_cell_rules_view(rules, stdout);
  CHECK(fcm_space_create_embedded(ctx, mesh, rules, &space));

  /* Soft rubber, static equilibrium under gravity in 2 load steps. */
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2e5, 0.4, 1100.0};
  fcm_integrator_options io = fcm_integrator_options_default();
  io.kind = FCM_INTEGRATOR_STATIC;
  io.tolerance_mode = FCM_NEWTON_TOL_REPRESENTATIVE; /* ||g|| <= 1e-5 ||rho a_rep|| */
  io.dt = 1.0;
  io.load_steps = 2;
  CHECK(fcm_integrator_create(ctx, space, &mat, &io, &integ));
  const double g[3] = {0.0, 0.0, -9.81};
  CHECK(fcm_integrator_add_gravity(integ, g, NULL, NULL));

  /* Clamp the lower cap (u = 0 there) weakly by Nitsche's method (the default method). */
  const fcm_motion fixed = fcm_motion_default();
  int clamp = -1;
  CHECK(fcm_integrator_add_boundary_constraint(integ, lower_cap, NULL, &fixed, NULL, &clamp));
  CHECK(fcm_integrator_setup(integ));
  fcm_step_info si;
  CHECK(fcm_integrator_step(integ, &si));
  printf("static solve: %d Newton iterations, residual %.3g\n", si.newton_iterations, si.residual);
  const double *u = fcm_integrator_displacement(integ);
  double force[3], moment[3], umax = 0.0;
  CHECK(fcm_integrator_boundary_reaction(integ, clamp, force, moment));
  CHECK(fcm_space_max_displacement(space, u, &umax));
  printf("reaction of the clamp (%.4g, %.4g, %.4g) N; largest |u| in the body %.4g m\n", force[0],
         force[1], force[2], umax);

  /* Output: background grid and embedded surface, at reference positions with displacement
   * and stresses. */
  snprintf(path, sizeof path, "%s/host_static_background.vtu", dir);
  CHECK(fcm_space_write_vtu(space, &mat, u, NULL, path));
  CHECK(fcm_embedded_surface_create(space, ball, &surf));
  snprintf(path, sizeof path, "%s/host_static_surface.vtu", dir);
  CHECK(fcm_embedded_surface_write_vtu(surf, &mat, u, path));
  printf("wrote %s/host_static_{background,surface}.vtu\n", dir);

  /* The ball sags (its top moves down), the bottom stays put, the clamp carries the weight. */
  const fcm_index np = fcm_embedded_surface_num_points(surf);
  const double *X = fcm_embedded_surface_points(surf);
  u_surf = malloc(3 * (size_t)np * sizeof *u_surf);
  if (!u_surf) goto done;
  CHECK(fcm_embedded_surface_eval(surf, u, u_surf, NULL));
  double top = 0.0, cap = 0.0;
  for (fcm_index v = 0; v < np; v++) {
    if (X[3 * v + 2] > 0.499) top = u_surf[3 * v + 2];
    if (X[3 * v + 2] < -0.499) cap = u_surf[3 * v + 2];
  }
  const double weight = 1100.0 * 9.81 * fcm_cell_rules_get_stats(rules)->embedded_volume;
  printf("top of the ball moves %.4g m, bottom %.3g m; weight %.4g N\n", top, cap, weight);
  ok = top < 0.0 && umax < 0.5 && cap * cap < 1e-4 * top * top && force[2] > 0.98 * weight &&
       force[2] < 1.02 * weight; /* (no libm needed) */

done:
  free(u_surf);
  fcm_embedded_surface_destroy(&surf);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
