/* The octree refinement criteria along triangle surfaces (fcm_surface_meets_box(),
 * fcm_geometry_boundary_meets_box()): exact triangle-box overlap on cases a bounding-box test gets
 * wrong, closed boxes (touching counts), and on random triangles and boxes no miss of a sampled
 * point of the triangle inside the box and no hit farther than the sampling spacing from it. */
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>

static unsigned long long seed = 3;
static double urand01(void)
{
  seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(seed >> 11) / 9007199254740992.0;
}

/* Distance from the closest of 61 x 61 barycentric samples of triangle v to the box. */
static double sampled_distance(const double v[9], const double lo[3], const double hi[3])
{
  double best = HUGE_VAL;
  for (int i = 0; i <= 60; i++)
    for (int j = 0; i + j <= 60; j++) {
      const double a = i / 60.0, b = j / 60.0;
      double d2 = 0.0;
      for (int d = 0; d < 3; d++) {
        const double x = (1 - a - b) * v[d] + a * v[3 + d] + b * v[6 + d];
        const double o = x < lo[d] ? lo[d] - x : x > hi[d] ? x - hi[d] : 0.0;
        d2 += o * o;
      }
      best = fmin(best, sqrt(d2));
    }
  return best;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_surface *tri = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const fcm_index t[3] = {0, 1, 2};
  TEST_OK(ctx, fcm_surface_create(ctx, 3, v, 1, t, &tri));
  const double lo1[3] = {0.6, 0.6, -0.1}, hi1[3] = {0.9, 0.9, 0.1}; /* boxes overlap, not it */
  TEST_TRUE(fcm_surface_meets_box(lo1, hi1, 0, tri) == 0);
  const double lo2[3] = {0.3, 0.3, -0.1}, hi2[3] = {0.45, 0.45, 0.1};
  TEST_TRUE(fcm_surface_meets_box(lo2, hi2, 0, tri) == 1);
  const double lo3[3] = {0.2, 0.2, 0.0}, hi3[3] = {0.3, 0.3, 0.5}; /* touches its plane */
  TEST_TRUE(fcm_surface_meets_box(lo3, hi3, 0, tri) == 1);
  const double lo4[3] = {0.2, 0.2, 1e-9}, hi4[3] = {0.3, 0.3, 0.5};
  TEST_TRUE(fcm_surface_meets_box(lo4, hi4, 0, tri) == 0);
  TEST_TRUE(fcm_surface_meets_box(NULL, hi4, 0, tri) == -1);
  fcm_surface_destroy(&tri);

  int hits = 0, misses = 0;
  for (int k = 0; k < 400; k++) {
    double w[9], lo[3], hi[3];
    for (int i = 0; i < 9; i++)
      w[i] = urand01();
    for (int d = 0; d < 3; d++) {
      lo[d] = 0.8 * urand01();
      hi[d] = lo[d] + 0.05 + 0.2 * urand01();
    }
    TEST_OK(ctx, fcm_surface_create(ctx, 3, w, 1, t, &tri));
    const int r = fcm_surface_meets_box(lo, hi, 0, tri);
    const double dist = sampled_distance(w, lo, hi);
    if (dist == 0.0) TEST_TRUE(r == 1);
    if (r == 1) TEST_TRUE(dist <= 0.03); /* the samples are 1/60 of an edge (< sqrt 3) apart */
    hits += r == 1, misses += r == 0;
    fcm_surface_destroy(&tri);
  }
  TEST_TRUE(hits > 20 && misses > 20);

  /* the geometry's boundary: a ball's cells are crossed where the sphere passes */
  fcm_geometry *ball = NULL;
  const double c[3] = {0, 0, 0};
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 1.0, 2, &ball));
  const double in_lo[3] = {-0.2, -0.2, -0.2}, in_hi[3] = {0.2, 0.2, 0.2};
  const double at_lo[3] = {0.9, -0.1, -0.1}, at_hi[3] = {1.1, 0.1, 0.1};
  const double out_lo[3] = {1.2, 1.2, 1.2}, out_hi[3] = {1.5, 1.5, 1.5};
  TEST_TRUE(fcm_geometry_boundary_meets_box(in_lo, in_hi, 0, ball) == 0);
  TEST_TRUE(fcm_geometry_boundary_meets_box(at_lo, at_hi, 0, ball) == 1);
  TEST_TRUE(fcm_geometry_boundary_meets_box(out_lo, out_hi, 0, ball) == 0);
  TEST_TRUE(fcm_geometry_boundary_meets_box(in_lo, in_hi, 0, NULL) == -1);
  fcm_geometry_destroy(&ball);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
