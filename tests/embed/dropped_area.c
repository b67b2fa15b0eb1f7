/* The boundary area in dropped cells (fcm_cell_rules_stats.dropped_area): a box whose face
 * lies 1e-6 h inside a row of cells drops that face with the sliver, whose area is known in
 * closed form; for a ball with a raised min_fraction, dropped_area + embedded_area is the
 * faceted surface's area; nothing is dropped with min_fraction = 0 or counted without
 * surface rules. The area a selection of boundary points takes splits the same way
 * (fcm__embed_selected_area): all of it, and the half-space x > 1 that holds the sliver. */
#include "../geom/exact.h"
#include "embed/embed_impl.h"
#include "fcm/embed.h"
#include "test.h"

#include <string.h>

static fcm_ctx *ctx;

static int select_all(void *user, const double x[3], const double n[3])
{
  (void)user, (void)x, (void)n;
  return 1;
}

/* x[0] > *user */
static int select_beyond(void *user, const double x[3], const double n[3])
{
  (void)n;
  return x[0] > *(const double *)user;
}

/* The selected areas against the statistics: all points, then those beyond x = x0, whose
 * area in kept and dropped cells is expected (atol: absolute tolerance). */
static void selected(const fcm_mesh *mesh, const fcm_geometry *g, double phi, double x0,
                     double kept_x0, double dropped_x0)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.surface_strength = 2;
  o.min_fraction = phi;
  fcm_cell_rules *r = NULL;
  double kept, dropped;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  if (!r) return;
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  TEST_OK(ctx, fcm__embed_selected_area(ctx, mesh, g, r, select_all, NULL, &kept, &dropped));
  TEST_NEAR(kept, S->embedded_area, 1e-14, 0);
  TEST_NEAR(dropped, S->dropped_area, 1e-14, 0);
  TEST_OK(ctx, fcm__embed_selected_area(ctx, mesh, g, r, select_beyond, &x0, &kept, &dropped));
  TEST_NEAR(kept, kept_x0, 1e-12, 0);
  TEST_NEAR(dropped, dropped_x0, 1e-12, 0);
  fcm_cell_rules_destroy(&r);
}

/* Rules with surface strength s (-1: none) and min_fraction phi; their statistics into *S. */
static void stats(const fcm_mesh *mesh, const fcm_geometry *g, int s, double phi,
                  fcm_cell_rules_stats *S)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.surface_strength = s;
  o.min_fraction = phi;
  fcm_cell_rules *r = NULL;
  memset(S, 0, sizeof *S);
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  if (r) *S = *fcm_cell_rules_get_stats(r);
  fcm_cell_rules_destroy(&r);
}

/* The box [a, 1 + eps] x [a, b]^2 in a 2 x 2 x 2 grid of [0, 2]^3 (h = 1): its +x face and
 * eps-wide strips of its four side faces lie in the cells x > 1, whose material fraction
 * (about 0.36 eps) is below the default min_fraction. */
static void sliver_box(fcm_element_type type)
{
  const double eps = 1e-6, a = 0.2, b = 0.8;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 2, 2}, blo[3] = {a, a, a}, bhi[3] = {1 + eps, b, b};
  const fcm_index n[3] = {2, 2, 2}, nb[3] = {2, 1, 1};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules_stats S;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, blo, bhi, nb, &g));
  if (!mesh || !g) goto done;
  const double face = (b - a) * (b - a), strips = 4 * (b - a) * eps;
  stats(mesh, g, 2, 1e-4, &S);
  TEST_NEAR(S.dropped_area, face + strips, 1e-12, 0);
  TEST_NEAR(S.dropped_area + S.embedded_area, exact_boundary_area(g), 1e-12, 0);
  TEST_NEAR(S.dropped_volume, face * eps, 1e-6, 0);
  /* min_fraction = 0 keeps the sliver: all of the area in the rules */
  stats(mesh, g, 2, 0.0, &S);
  TEST_TRUE(S.dropped_area == 0.0);
  TEST_NEAR(S.embedded_area, exact_boundary_area(g), 1e-12, 0);
  /* without surface rules there is nothing to count */
  stats(mesh, g, -1, 1e-4, &S);
  TEST_TRUE(S.dropped_area == 0.0 && S.num_dropped > 0);
  /* beyond x = 1 (the sliver's face and strips): dropped with the default, kept with 0 */
  selected(mesh, g, 1e-4, 1.0, 0.0, face + strips);
  selected(mesh, g, 0.0, 1.0, face + strips, 0.0);
done:
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&g);
}

/* A ball whose corner cells fall below a raised min_fraction. */
static void ball(fcm_element_type type)
{
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c0[3] = {0.05, -0.1, 0.02};
  const fcm_index n[3] = {3, 3, 3};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules_stats S;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.8, 2, &g));
  if (!mesh || !g) goto done;
  stats(mesh, g, 3, 0.05, &S);
  TEST_TRUE(S.dropped_volume > 0.0 && S.dropped_area > 0.0);
  TEST_NEAR(S.dropped_area + S.embedded_area, exact_boundary_area(g), 1e-12, 0);
done:
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&g);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  sliver_box(FCM_ELEMENT_HEX8);
  sliver_box(FCM_ELEMENT_TET4);
  ball(FCM_ELEMENT_HEX8);
  ball(FCM_ELEMENT_TET4);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
