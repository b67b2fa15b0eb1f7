/* Surface moments and inside tests on sliver tets (as the fan tets of a cut cell's parts):
 * the exit edge is a segment 1e-8 to 1e-6 of the tet's size long, so cond(A) reaches 1e12, and
 * its line is aimed within 1e-9 to 1e-7 of a far vertex of a closed ball's surface, where the
 * rounding of the map to reference coordinates can move the line across a triangle whose box
 * the physical line misses. Asserts, for 4000 such tets:
 * - every rule is built: the line crossings of the closed surface sum to zero (no triangle the
 *   reference line crosses is left out of the candidates);
 * - the material volume from the rule lies in [0, |tet|] within 1e-6 |tet|;
 * - the inside test on the line from X0 to X3 agrees with the distance to the ball's centre
 *   where the point is clearly inside (< 0.95 R) or outside (> 1.001 R). */
#include "embed/rules_impl.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CHECK_OK(call) TEST_OK(ctx, call)
#define CHECK(cond, ...)                                                                           \
  do {                                                                                             \
    if (!(cond)) TEST_FAIL_(__VA_ARGS__);                                                          \
  } while (0)

enum { NTETS = 4000 };

static double urand(void)
{
  return 2.0 * rand() / RAND_MAX - 1.0;
}

/* A sliver tet whose exit edge (X2 -> X3, from xi = (0, 1, 0) to (0, 0, 1)) is a short
 * segment of length e L near the ball's surface, aimed at a point within 1e-9 to 1e-7 of a
 * far vertex of the ball's surface: the line passes just beside the boxes of some triangles
 * at that vertex, by less than the rounding of the map to reference coordinates. */
static void sliver(const fcm_geometry *g, double R, double *X)
{
  double u[3], n = 0.0;
  for (int d = 0; d < 3; d++)
    u[d] = urand(), n += u[d] * u[d];
  n = sqrt(n);
  const double r = R * (0.9 + 0.2 * (rand() / (double)RAND_MAX));
  const double L = 0.01 + 0.04 * rand() / RAND_MAX,
               e = L * pow(10.0, -8.0 + 2.0 * rand() / RAND_MAX);
  const double delta = pow(10.0, -9.0 + 2.0 * rand() / RAND_MAX);
  const double *v = g->coords + 3 * (rand() % g->num_nodes);
  double P[3], w[3], nw = 0.0;
  for (int d = 0; d < 3; d++) {
    P[d] = r * u[d] / n;
    w[d] = v[d] + delta * urand() - P[d], nw += w[d] * w[d];
  }
  nw = sqrt(nw);
  for (int d = 0; d < 3; d++) {
    X[6 + d] = P[d];
    X[9 + d] = P[d] + e * w[d] / nw;
    X[d] = P[d] + L * urand();
    X[3 + d] = P[d] + L * urand();
  }
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_TRUE(fcm_ctx_create(NULL, &ctx) == FCM_OK);
  const double c0[3] = {0.0, 0.0, 0.0}, R = 0.6;
  fcm_geometry *ball = NULL;
  CHECK_OK(fcm_geometry_create_ball(ctx, c0, R, 5, &ball));
  double *X = malloc(12 * NTETS * sizeof *X);
  fcm_index *cells = malloc(4 * NTETS * sizeof *cells);
  CHECK(X && cells, "out of memory");
  srand(11);
  for (int t = 0; t < NTETS; t++) {
    sliver(ball, R, X + 12 * t);
    double *a = X + 12 * t; /* positive orientation */
    double e1[3], e2[3], e3[3];
    for (int d = 0; d < 3; d++)
      e1[d] = a[3 + d] - a[d], e2[d] = a[6 + d] - a[d], e3[d] = a[9 + d] - a[d];
    const double det = e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) -
                       e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
                       e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]);
    if (det < 0.0) /* X0 <-> X1 keeps the exit edge */
      for (int d = 0; d < 3; d++) {
        const double s = a[d];
        a[d] = a[3 + d], a[3 + d] = s;
      }
    for (int k = 0; k < 4; k++)
      cells[4 * t + k] = 4 * t + k;
  }
  fcm_mesh *mesh = NULL;
  CHECK_OK(fcm_mesh_create(ctx, FCM_ELEMENT_TET4, 4 * NTETS, X, NTETS, cells, &mesh));
  fcm_aabb_tree *tree = NULL;
  double *boxes = NULL;
  fcm_index nb;
  CHECK_OK(fcm__geom_boxes(ctx, ball, 1, &boxes, &nb));
  CHECK_OK(fcm_aabb_tree_create(ctx, nb, boxes, &tree));
  fcm__free(ctx, boxes);
  fcm__moment_quad q;
  memset(&q, 0, sizeof q);
  CHECK_OK(fcm__moment_quad_create(ctx, 0, &q));
  fcm__idbuf buf = {0};
  fcm__crossings cr;
  fcm__srule s;
  memset(&cr, 0, sizeof cr);
  memset(&s, 0, sizeof s);
  int failed = 0, bad_volume = 0, wrong_inside = 0, cut = 0;
  double worst_cond = 0.0;
  for (fcm_index t = 0; t < NTETS; t++) {
    fcm__embed_cell cell;
    CHECK_OK(fcm__embed_cell_setup(ctx, mesh, t, 1e-12, &cell));
    double na = 0.0, ni = 0.0;
    for (int k = 0; k < 9; k++)
      na += cell.A[k] * cell.A[k], ni += cell.Ainv[k] * cell.Ainv[k];
    worst_cond = fmax(worst_cond, sqrt(na * ni));
    if (fcm__embed_moment_rule(ctx, ball, tree, &cell, &q, NULL, &buf, &cr, &s) != FCM_OK) {
      if (failed++ == 0) printf("tet %lld: %s\n", (long long)t, fcm_ctx_error_message(ctx));
      continue;
    }
    double v = 0.0;
    for (size_t i = 0; i < s.n; i++)
      v += s.w[i] * cell.detA;
    if (!(v >= -1e-6 * cell.volume && v <= (1.0 + 1e-6) * cell.volume)) bad_volume++;
    cut += v > 1e-6 * cell.volume && v < (1.0 - 1e-6) * cell.volume;
    /* the line from X0 (xi = 0) to X3 (xi = (0, 0, 1)): inside where clearly so */
    const double z[3] = {0.0, 0.5, 1.0};
    int in[3];
    if (fcm__embed_inside_line(ctx, ball, tree, &cell, 0.0, 0.0, 3, z, in, &buf, &cr) != FCM_OK) {
      failed++;
      continue;
    }
    for (int i = 0; i < 3; i++) {
      double x[3], r = 0.0;
      const double xi[3] = {0.0, 0.0, z[i]};
      fcm_element_map(FCM_ELEMENT_TET4, cell.X, xi, x);
      for (int d = 0; d < 3; d++)
        r += x[d] * x[d];
      r = sqrt(r);
      if (r < 0.95 * R) wrong_inside += in[i] != 1;
      if (r > 1.001 * R) wrong_inside += in[i] != 0;
    }
  }
  printf("%d sliver tets (cond(A) up to %.2e), %d cut by the ball: %d failed, %d volumes out "
         "of [0, |tet|], %d inside tests wrong\n",
         NTETS, worst_cond, cut, failed, bad_volume, wrong_inside);
  CHECK(cut > 100, "only %d sliver tets are cut by the ball", cut);
  CHECK(worst_cond > 1e9, "the slivers are not ill-conditioned (cond %.2e)", worst_cond);
  CHECK(failed == 0, "%d sliver tets: an open-surface error on a closed ball", failed);
  CHECK(bad_volume == 0, "%d sliver tets: material volume out of [0, |tet|]", bad_volume);
  CHECK(wrong_inside == 0, "%d points on the lines X0 -> X3 misclassified", wrong_inside);
  fcm__moment_quad_free(ctx, &q);
  fcm__geom_idbuf_free(ctx, &buf);
  fcm__crossings_free(ctx, &cr);
  fcm__srule_free(ctx, &s);
  fcm_aabb_tree_destroy(&tree);
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&ball);
  free(X);
  free(cells);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
