/* What the README says the built-in scene shows, asserted on its run to the end: the tube,
 * held only at its ends, sags under its own weight (its mid-length cross-section moves down,
 * not sideways) and twists (that cross-section turns about the tube's axis, by less than the
 * end's 3.2 rad). Prints the measured sag, sideways motion and turn (the figures the README
 * quotes), on the whole run of 210 steps. */
#include "scene_util.h"

#include <math.h>

#define RING 32
#define PI   3.14159265358979323846

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  TEST_OK(ctx, fcm_scene_create_default(ctx, &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim) TEST_OK(ctx, fcm_simulation_run(sim, NULL, NULL));
  if (sim && fcm_simulation_done(sim)) {
    /* points on the middle of the wall (radii 0.7 and 0.95) around the tube at y = 0 */
    const double r = 0.825;
    double X[3 * RING], xi[3 * RING], u[3 * RING];
    fcm_index cell[RING];
    for (int k = 0; k < RING; k++) {
      const double a = 2.0 * PI * k / RING;
      X[3 * k] = r * cos(a), X[3 * k + 1] = 0.0, X[3 * k + 2] = r * sin(a);
    }
    const fcm_space *space = fcm_simulation_space(sim);
    const double *dofs = fcm_integrator_displacement(fcm_simulation_integrator(sim));
    TEST_OK(ctx, fcm_space_locate(space, RING, X, cell, xi, NULL));
    TEST_OK(ctx, fcm_space_interpolate(space, RING, cell, xi, dofs, u));
    double mean[3] = {0, 0, 0}, turn = 0.0;
    for (int k = 0; k < RING; k++)
      for (int d = 0; d < 3; d++)
        mean[d] += u[3 * k + d] / RING;
    for (int k = 0; k < RING; k++) { /* the turn about y of each point about the section's centre */
      const double x0 = X[3 * k], z0 = X[3 * k + 2];
      const double x1 = x0 + u[3 * k] - mean[0], z1 = z0 + u[3 * k + 2] - mean[2];
      turn += remainder(atan2(z1, x1) - atan2(z0, x0), 2.0 * PI) / RING;
    }
    printf("mid-length section: sag %.3f m (z), sideways %.3f m (x), along the axis %.3f m, "
           "turn %.3f rad\n",
           -mean[2], mean[0], mean[1], turn);
    TEST_TRUE(mean[2] < -1.0);                       /* it sags, by metres */
    TEST_TRUE(fabs(mean[0]) < 0.2 * fabs(mean[2]));  /* down, not sideways */
    TEST_TRUE(fabs(turn) > 0.3 && fabs(turn) < 3.2); /* it twists, less than the end */
  } else {
    TEST_FAIL_("the built-in scene did not run to the end");
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
