/* fcm's side of the deal.II interop example: the kinked body of kinked_problem.h in an N^3 grid
 * of Hex8 cells over the unit cube; the cut-cell rules written for deal.II
 * (fcm_cell_rules_write()) and the same problem solved with fcm's own assembly on those rules
 * (stiffness + mass, body force, traction from the surface rules; full cells use the catalogue
 * rules of the same strengths, as the file does). Writes DIR/rules_N.fcmr and DIR/fcm_N.txt (one
 * line per active node: x y z u_x u_y u_z).
 *   fcm_kinked N DIR [STRENGTH [MASS_STRENGTH]]     (defaults 4 and 6: exact for Q1)
 * Exit status 0 on success. */
#include "kinked_problem.h"

#include <fcm/fcm.h>

#include <stdio.h>
#include <stdlib.h>

#define CHECK(call)                                                                                \
  do {                                                                                             \
    if ((call) != FCM_OK) {                                                                        \
      fprintf(stderr, "fcm_kinked: %s failed\n", #call);                                           \
      fcm_ctx_error_view(ctx, stderr);                                                             \
      goto done;                                                                                   \
    }                                                                                              \
  } while (0)

static void force(void *user, const double x[3], const double normal[3], double value[3])
{
  (void)user;
  (void)normal;
  kinked_force(x, value);
}

static void traction(void *user, const double x[3], const double normal[3], double value[3])
{
  (void)user;
  kinked_traction(x, normal, value);
}

/* The kinked body as an fcm geometry. */
static fcm_status body(fcm_ctx *ctx, fcm_geometry **g)
{
  double xyz[3 * KINKED_NODES];
  long long t[4 * KINKED_TETS];
  fcm_index tets[4 * KINKED_TETS];
  kinked_body(xyz, t);
  for (int i = 0; i < 4 * KINKED_TETS; i++)
    tets[i] = (fcm_index)t[i];
  return fcm_geometry_create(ctx, FCM_ELEMENT_TET4, KINKED_NODES, xyz, KINKED_TETS, tets, g);
}

/* Active nodes' coordinates and displacements, one line each. */
static int write_solution(const fcm_space *space, const fcm_mesh *mesh, const double *u,
                          const char *path)
{
  FILE *f = fopen(path, "w");
  if (!f) return 0;
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index n = 0; n < fcm_mesh_num_nodes(mesh); n++) {
    const fcm_index d = fcm_space_node_dof(space, n);
    if (d >= 0)
      fprintf(f, "%.17g %.17g %.17g %.17g %.17g %.17g\n", X[3 * n], X[3 * n + 1], X[3 * n + 2],
              u[d], u[d + 1], u[d + 2]);
  }
  return fclose(f) == 0;
}

int main(int argc, char **argv)
{
  if (argc < 3) {
    fprintf(stderr, "usage: fcm_kinked N DIR [STRENGTH [MASS_STRENGTH]]\n");
    return 2;
  }
  const int n = atoi(argv[1]), m = argc > 3 ? atoi(argv[3]) : 4, mm = argc > 4 ? atoi(argv[4]) : 6;
  if (n < 1 || n > 256 || m < 1 || m > 20 || mm < 1 || mm > 20) {
    fprintf(stderr, "fcm_kinked: N in [1, 256], strengths in [1, 20]\n");
    return 2;
  }
  char path[4096];
  int ok = 0;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_csr *A = NULL;
  fcm_direct *solver = NULL;
  double *b = NULL, *u = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index cells[3] = {n, n, n};
  CHECK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  CHECK(body(ctx, &g));

  /* the rules, and the file deal.II reads */
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.strength[FCM_RULE_STIFFNESS] = m;
  ro.strength[FCM_RULE_MASS] = mm;
  ro.surface_strength = m;
  /* keep every cell with material: a dropped cell would take its part of the boundary, and of
   * the traction, with it (a consistency error that stalls the rates); the stabilization points
   * (default alpha 1e-6) keep the small ones well conditioned */
  ro.min_fraction = 0.0;
  CHECK(fcm_cell_rules_create(ctx, mesh, g, &ro, &rules));
  snprintf(path, sizeof path, "%s/rules_%d.fcmr", argv[2], n);
  fcm_cell_rules_write_options wo = fcm_cell_rules_write_options_default();
  wo.description = "fcm_kinked: the kinked body of the deal.II interop example";
  CHECK(fcm_cell_rules_write(rules, mesh, path, &wo));

  /* (K + M) u = f + g with fcm's assembly; full cells with the file's catalogue rules */
  CHECK(fcm_space_create_embedded(ctx, mesh, rules, &space));
  const fcm_index nd = fcm_space_num_dofs(space);
  const fcm_material mat = {FCM_MATERIAL_LINEAR, KINKED_YOUNG, KINKED_POISSON, KINKED_DENSITY};
  fcm_assembly_options ao = fcm_assembly_options_default();
  ao.stiffness_strength = m;
  ao.mass_strength = mm;
  CHECK(fcm_space_matrix_create(space, &A));
  CHECK(fcm_assemble_stiffness(space, &mat, &ao, A));
  CHECK(fcm_assemble_mass(space, &mat, &ao, A));
  b = calloc((size_t)nd, sizeof *b);
  u = calloc((size_t)nd, sizeof *u);
  if (!b || !u) goto done;
  CHECK(fcm_assemble_body_force_field(space, force, NULL, &ao, b));
  CHECK(fcm_assemble_surface_traction(space, traction, NULL, b));
  CHECK(fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &solver));
  CHECK(fcm_direct_analyze(solver));
  CHECK(fcm_direct_factor(solver, fcm_csr_values(A)));
  CHECK(fcm_direct_solve(solver, b, u));
  snprintf(path, sizeof path, "%s/fcm_%d.txt", argv[2], n);
  if (!write_solution(space, mesh, u, path)) {
    fprintf(stderr, "fcm_kinked: cannot write %s\n", path);
    goto done;
  }
  const fcm_cell_rules_stats *st = fcm_cell_rules_get_stats(rules);
  printf("fcm_kinked: N = %d: %lld cut cells, %lld DOFs, body volume %.15g (exact %.15g)\n", n,
         (long long)st->num_cut, (long long)nd, st->embedded_volume, kinked_volume());
  ok = 1;
done:
  free(b);
  free(u);
  fcm_direct_destroy(&solver);
  fcm_csr_destroy(&A);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
