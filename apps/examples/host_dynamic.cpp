// host_dynamic: a C++ host program that owns the time loop. An embedded bar, clamped at x = 0,
// swings down under gravity (backward Euler); after step 10 the host cuts it at x = 1.1 with
// fcm_cell_rules_create_cut -> fcm_space_create_embedded -> fcm_integrator_create_cut, and the
// cut-off end falls. Mass and momentum are checked across the cut; the embedded surface (both
// sides of the cut) is written as VTU to [dir]. Build: find_package(fcm) and fcm::fcm, or
//   c++ host_dynamic.cpp $(pkg-config --cflags --libs fcm) -o host_dynamic && ./host_dynamic [dir]
// Exit status 0 when every call succeeded and the checks hold.
#include <fcm/fcm.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace
{

// Print the library's message on failure.
bool ok(fcm_ctx *ctx, fcm_status st, const char *what)
{
  if (st == FCM_OK) return true;
  std::fprintf(stderr, "host_dynamic: %s: %s\n", what, fcm_status_name(st));
  fcm_ctx_error_view(ctx, stderr);
  return false;
}

// The body as the host sees it: rules, space and integrator of the current cut state.
struct Body {
  fcm_cell_rules *rules = nullptr;
  fcm_space *space = nullptr;
  fcm_integrator *integ = nullptr;
  void release()
  {
    fcm_integrator_destroy(&integ);
    fcm_space_destroy(&space);
    fcm_cell_rules_destroy(&rules);
  }
};

bool momentum(fcm_ctx *ctx, const Body &b, double rho, double *m, double p[3])
{
  return ok(ctx,
            fcm_space_momentum(b.space, rho, fcm_integrator_displacement(b.integ),
                               fcm_integrator_velocity(b.integ), m, p, nullptr),
            "momentum");
}

bool run(fcm_ctx *ctx, const std::string &dir)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 0.5, 0.5};
  const fcm_index cells[3] = {8, 2, 2};
  const double blo[3] = {0, 0.05, 0.05}, bhi[3] = {1.8, 0.45, 0.45};
  const fcm_index bcells[3] = {18, 4, 4};
  const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000.0};
  fcm_mesh *mesh = nullptr;
  fcm_geometry *bar = nullptr;
  fcm_surface *cut = nullptr;
  fcm_embedded_surface *surf = nullptr;
  Body body;
  bool good = false;
  do {
    if (!ok(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh), "mesh") ||
        !ok(ctx, fcm_geometry_create_box(ctx, blo, bhi, bcells, &bar), "geometry"))
      break;
    // A dynamic run assembles the mass matrix: ask for both rule kinds.
    fcm_cell_rules_options ro = fcm_cell_rules_options_default();
    ro.kinds = FCM_RULES_STIFFNESS | FCM_RULES_MASS;
    if (!ok(ctx, fcm_cell_rules_create(ctx, mesh, bar, &ro, &body.rules), "rules") ||
        !ok(ctx, fcm_space_create_embedded(ctx, mesh, body.rules, &body.space), "space"))
      break;
    fcm_integrator_options io = fcm_integrator_options_default();
    io.dt = 0.01;
    if (!ok(ctx, fcm_integrator_create(ctx, body.space, &mat, &io, &body.integ), "integrator"))
      break;
    const double g[3] = {0, 0, -9.81}, nlo[3] = {-1, -1, -1}, nhi[3] = {0, 1, 1}; // x = 0 nodes
    fcm_index n = 0;
    if (!ok(ctx, fcm_integrator_add_gravity(body.integ, g, nullptr, nullptr), "gravity") ||
        !ok(ctx, fcm_mesh_nodes_in_box(ctx, mesh, nlo, nhi, 1e-9, 0, nullptr, &n), "nodes"))
      break;
    std::vector<fcm_index> clamp(static_cast<size_t>(n));
    const fcm_motion fixed = fcm_motion_default();
    if (!ok(ctx, fcm_mesh_nodes_in_box(ctx, mesh, nlo, nhi, 1e-9, n, clamp.data(), &n), "nodes") ||
        !ok(ctx, fcm_integrator_add_constraint(body.integ, n, clamp.data(), &fixed, nullptr),
            "clamp") ||
        !ok(ctx, fcm_integrator_setup(body.integ), "setup"))
      break;
    if (!ok(ctx, fcm_embedded_surface_create(body.space, bar, &surf), "surface")) break;
    // The cut: two triangles spanning the plane x = 1.1 across the bar.
    const double x[12] = {1.1, -1, -1, 1.1, 2, -1, 1.1, 2, 2, 1.1, -1, 2};
    const fcm_index tri[6] = {0, 1, 2, 0, 2, 3};
    if (!ok(ctx, fcm_surface_create(ctx, 4, x, 2, tri, &cut), "cut surface")) break;
    bool failed = false;
    for (int step = 1; step <= 20 && !failed; step++) {
      fcm_step_info si;
      double m = 0, p[3];
      failed = !ok(ctx, fcm_integrator_step(body.integ, &si), "step") ||
               !momentum(ctx, body, mat.density, &m, p);
      if (failed) break;
      std::printf("t = %.2f s  Newton %d  bodies %lld  mass %.6g kg  p_z %.4g kg m/s\n",
                  fcm_integrator_time(body.integ), si.newton_iterations,
                  static_cast<long long>(fcm_space_num_bodies(body.space)), m, p[2]);
      if (step != 10) continue;
      // Cut between steps: new rules, a new space, an integrator continuing the old state.
      Body next;
      double m1 = 0, p1[3];
      failed =
          !ok(ctx, fcm_cell_rules_create_cut(ctx, mesh, bar, body.rules, cut, &next.rules),
              "cut rules") ||
          !ok(ctx, fcm_space_create_embedded(ctx, mesh, next.rules, &next.space), "cut space") ||
          !ok(ctx, fcm_integrator_create_cut(body.integ, next.space, &next.integ),
              "cut integrator");
      body.release(); // on failure, `next` holds what was made so far (released below)
      body = next;
      failed = failed || !ok(ctx, fcm_embedded_surface_set_space(surf, body.space), "surface") ||
               !momentum(ctx, body, mat.density, &m1, p1);
      if (failed) break;
      std::printf("cut at t = %.2f s: %lld bodies, mass %.6g -> %.6g kg, p_z %.6g -> %.6g\n",
                  fcm_integrator_time(body.integ),
                  static_cast<long long>(fcm_space_num_bodies(body.space)), m, m1, p[2], p1[2]);
      if (fcm_space_num_bodies(body.space) != 2 || std::fabs(m1 - m) > 1e-10 * m ||
          std::fabs(p1[2] - p[2]) > 1e-9 * (std::fabs(p[2]) + m)) {
        std::fprintf(stderr, "host_dynamic: the cut changed the bodies, mass or momentum\n");
        failed = true;
      }
    }
    // The surface at reference positions with displacement and stresses (Warp By Vector).
    const std::string path = dir + "/host_dynamic_surface.vtu";
    good = !failed && ok(ctx,
                         fcm_embedded_surface_write_vtu(
                             surf, &mat, fcm_integrator_displacement(body.integ), path.c_str()),
                         "write");
  } while (false);
  body.release();
  fcm_embedded_surface_destroy(&surf);
  fcm_surface_destroy(&cut);
  fcm_geometry_destroy(&bar);
  fcm_mesh_destroy(&mesh);
  return good;
}

} // namespace

int main(int argc, char **argv)
{
  fcm_ctx *ctx = nullptr;
  if (fcm_ctx_create(nullptr, &ctx) != FCM_OK) return 1;
  const bool good = run(ctx, argc > 1 ? argv[1] : ".");
  const bool leak = fcm_ctx_live_allocations(ctx) != 0;
  fcm_ctx_destroy(&ctx);
  if (leak) std::fprintf(stderr, "host_dynamic: allocations left\n");
  return good && !leak ? 0 : 1;
}
