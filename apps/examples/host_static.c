/* host_static: an embedded ball under gravity, clamped on its lower cap, solved statically by a
 * host program with fcm's C API. Writes the background grid and the embedded surface as VTU,
 * both at reference positions with a `displacement` array (ParaView: Warp By Vector).
 *   cc host_static.c $(pkg-config --cflags --libs fcm) -o host_static && ./host_static [dir]
 * (shared libfcm: nothing else to link; the .pc's rpath finds the library at run time)
 * Exit status 0 when the run succeeded and the ball sags under its weight. */
#include <fcm/fcm.h>

#include <math.h> /* HUGE_VAL */
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
  fcm_vtu *vtu = NULL;
  fcm_index *clamped = NULL, *cell = NULL, ncl = 0;
  double *u_node = NULL, *xi = NULL, *u_surf = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;

  /* Background: 6 x 6 x 6 Hex8 cells over [-0.6, 0.6]^3; body: a ball of radius 0.5. */
  const double lo[3] = {-0.6, -0.6, -0.6}, hi[3] = {0.6, 0.6, 0.6}, c[3] = {0, 0, 0};
  const fcm_index n[3] = {6, 6, 6};
  CHECK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  CHECK(fcm_geometry_create_ball(ctx, c, 0.5, 3, &ball));

  /* Cut-cell rules: a static problem needs stiffness rules only (no mass rules). */
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.kinds = FCM_RULES_STIFFNESS;
  CHECK(fcm_cell_rules_create(ctx, mesh, ball, &ro, &rules));
  fcm_cell_rules_view(rules, stdout);
  CHECK(fcm_space_create_embedded(ctx, mesh, rules, &space));

  /* Soft rubber, static equilibrium under gravity in 2 load steps. */
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2e5, 0.4, 1100.0};
  fcm_integrator_options io = fcm_integrator_options_default();
  io.kind = FCM_INTEGRATOR_STATIC;
  io.dt = 1.0;
  io.load_steps = 2;
  CHECK(fcm_integrator_create(ctx, space, &mat, &io, &integ));
  const double g[3] = {0.0, 0.0, -9.81};
  CHECK(fcm_integrator_add_gravity(integ, g, NULL, NULL));

  /* Clamp: the background nodes of the bottom layer (z <= -0.4) hold the lower cap. */
  const double blo[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, bhi[3] = {HUGE_VAL, HUGE_VAL, -0.4};
  CHECK(fcm_mesh_nodes_in_box(ctx, mesh, blo, bhi, 1e-9, 0, NULL, &ncl));
  clamped = malloc((size_t)ncl * sizeof *clamped);
  if (!clamped) goto done;
  CHECK(fcm_mesh_nodes_in_box(ctx, mesh, blo, bhi, 1e-9, ncl, clamped, &ncl));
  const fcm_motion fixed = fcm_motion_default();
  CHECK(fcm_integrator_add_constraint(integ, ncl, clamped, &fixed, NULL));
  CHECK(fcm_integrator_setup(integ));
  fcm_step_info si;
  CHECK(fcm_integrator_step(integ, &si));
  printf("static solve: %d Newton iterations, residual %.3g\n", si.newton_iterations, si.residual);

  /* Background VTU: node displacement (first DOF copy; nodes without DOFs stay at 0). */
  const double *u = fcm_integrator_displacement(integ);
  const fcm_index nn = fcm_mesh_num_nodes(mesh), nc = fcm_mesh_num_cells(mesh);
  u_node = calloc(3 * (size_t)nn, sizeof *u_node);
  if (!u_node) goto done;
  for (fcm_index a = 0; a < nn; a++) {
    const fcm_index d = fcm_space_node_dof(space, a);
    for (int k = 0; d >= 0 && k < 3; k++)
      u_node[3 * a + k] = u[d + k];
  }
  CHECK(fcm_vtu_create(ctx, &vtu));
  CHECK(fcm_vtu_set_points(vtu, nn, fcm_mesh_coords(mesh)));
  CHECK(fcm_vtu_set_cells(vtu, fcm_mesh_get_element_info(mesh)->vtk_cell_type, nc,
                          fcm_mesh_cells(mesh)));
  CHECK(fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "displacement", 3, nn, u_node));
  snprintf(path, sizeof path, "%s/host_static_background.vtu", dir);
  CHECK(fcm_vtu_write(vtu, path, NULL));

  /* Surface VTU: the ball's boundary triangles, displacement interpolated at the vertices. */
  const fcm_index nv = fcm_geometry_num_nodes(ball);
  const fcm_index nt = fcm_geometry_num_boundary_triangles(ball);
  cell = malloc((size_t)nv * sizeof *cell);
  xi = malloc(3 * (size_t)nv * sizeof *xi);
  u_surf = malloc(3 * (size_t)nv * sizeof *u_surf);
  if (!cell || !xi || !u_surf) goto done;
  CHECK(fcm_space_locate(space, nv, fcm_geometry_coords(ball), cell, xi, NULL));
  CHECK(fcm_space_interpolate(space, nv, cell, xi, u, u_surf));
  fcm_vtu_clear(vtu);
  CHECK(fcm_vtu_set_points(vtu, nv, fcm_geometry_coords(ball)));
  CHECK(fcm_vtu_set_cells(vtu, FCM_VTK_TRIANGLE, nt, fcm_geometry_boundary_triangles(ball)));
  CHECK(fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "displacement", 3, nv, u_surf));
  snprintf(path, sizeof path, "%s/host_static_surface.vtu", dir);
  CHECK(fcm_vtu_write(vtu, path, NULL));

  /* The ball sags: its top moves down, and no point of the body moves up noticeably. */
  double top = 0.0, umax2 = 0.0; /* (no libm needed: squared lengths) */
  for (fcm_index v = 0; v < nv; v++) {
    const double *X = fcm_geometry_coords(ball) + 3 * v, *uv = u_surf + 3 * v;
    const double u2 = uv[0] * uv[0] + uv[1] * uv[1] + uv[2] * uv[2];
    if (X[2] > 0.499) top = uv[2];
    if (!(u2 <= umax2)) umax2 = u2; /* NaN propagates */
  }
  printf("top of the ball moves %.4g m; largest surface displacement^2 %.4g m^2\n", top, umax2);
  printf("wrote %s/host_static_{background,surface}.vtu\n", dir);
  ok = top < 0.0 && umax2 < 0.25;

done:
  free(clamped);
  free(u_node);
  free(cell);
  free(xi);
  free(u_surf);
  fcm_vtu_destroy(&vtu);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
