/* Level-set bodies: the volume error of a sphere falls as O(h^2) in the refinement (fitted
 * rate in [1.7, 2.3]) and the reported Richardson estimate tracks the true error; the boundary
 * triangles (iso-surface and box faces) are closed and outward (they enclose the volume) and lie on
 * their tets; a box aligned with the lattice is exact; CSG: the union of disjoint spheres has the
 * sum of their volumes, a difference removes the inner ball, an intersection with a half space
 * halves a ball; the torus and gyroid evaluate sensibly; bad trees and arguments fail;
 * features below the sampling spacing are refused at once; the sub-cell limit refuses a build
 * before it allocates, and the documented bytes per sub-cell bound a build; progress ends at
 * its total. */
#include "fcm/levelset.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>

static const double PI = 3.14159265358979323846;

/* The boundary triangles enclose the geometry's volume (divergence theorem: sum of
 * det(a, b, c) / 6; closed and outward) and each lies on a face of its own tet. */
static void check_boundary(const fcm_geometry *g, const char *what)
{
  const double *X = fcm_geometry_coords(g);
  const fcm_index *t = fcm_geometry_boundary_triangles(g), *own = fcm_geometry_boundary_cells(g);
  const fcm_index *cells = fcm_geometry_cells(g);
  double vol = 0;
  int foreign = 0;
  for (fcm_index k = 0; k < fcm_geometry_num_boundary_triangles(g); k++) {
    const double *a = X + 3 * t[3 * k], *b = X + 3 * t[3 * k + 1], *c = X + 3 * t[3 * k + 2];
    vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
            a[2] * (b[0] * c[1] - b[1] * c[0])) /
           6.0;
    int in = 0;
    for (int j = 0; j < 3; j++)
      for (int v = 0; v < 4; v++)
        in += cells[4 * own[k] + v] == t[3 * k + j];
    foreign += in != 3;
  }
  if (!(fabs(vol - fcm_geometry_volume(g)) <= 1e-12 * fcm_geometry_volume(g)))
    TEST_FAIL_("%s: boundary encloses %.17g, geometry volume %.17g", what, vol,
               fcm_geometry_volume(g));
  if (foreign) TEST_FAIL_("%s: %d boundary triangles not on their tet", what, foreign);
}

static fcm_geometry *build(fcm_ctx *ctx, const fcm_implicit *nodes, int num, const double lo[3],
                           const double hi[3], fcm_index n, int r, fcm_level_set_info *info)
{
  fcm_implicit_tree t = {num, nodes};
  fcm_geometry *g = NULL;
  const fcm_index nn[3] = {n, n, n};
  fcm_level_set_options o = fcm_level_set_options_default();
  o.refinement = r;
  TEST_OK(ctx, fcm_implicit_check(ctx, &t));
  TEST_OK(ctx,
          fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &t, lo, hi, nn, &o, &g, info));
  return g;
}

static void sphere_rate(fcm_ctx *ctx)
{
  const double R = 0.71, exact = 4.0 / 3.0 * PI * R * R * R;
  fcm_implicit s = {0};
  s.kind = FCM_IMPLICIT_SPHERE, s.radius = R, s.center[0] = 0.013, s.center[1] = -0.021;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  static const int refinement[4] = {2, 3, 4, 6};
  double err[4], h[4];
  for (int l = 0; l < 4; l++) {
    fcm_level_set_info info;
    fcm_geometry *g = build(ctx, &s, 1, lo, hi, 4, refinement[l], &info);
    if (!g) return;
    err[l] = fabs(fcm_geometry_volume(g) - exact);
    h[l] = info.h;
    TEST_NEAR(info.volume, fcm_geometry_volume(g), 1e-12, 0);
    check_boundary(g, "sphere");
    TEST_TRUE(info.cells_inside + info.cells_cut + info.cells_outside == 64);
    TEST_TRUE(info.num_tets == fcm_geometry_num_cells(g));
    TEST_NEAR(h[l], 2.0 / (4.0 * refinement[l]), 1e-15, 0);
    /* the estimate is within a factor 2 of the true error */
    TEST_TRUE(info.error_estimate > 0.5 * err[l] && info.error_estimate < 2.0 * err[l]);
    /* the inscribed PL body of a convex function lies inside the sphere */
    TEST_TRUE(fcm_geometry_volume(g) < exact);
    if (l == 3) TEST_TRUE(err[l] / exact < 1e-2);
    fcm_geometry_destroy(&g);
  }
  /* least-squares slope of log err against log h */
  double mx = 0, my = 0, sxx = 0, sxy = 0;
  for (int l = 0; l < 4; l++)
    mx += log(h[l]) / 4, my += log(err[l]) / 4;
  for (int l = 0; l < 4; l++)
    sxx += (log(h[l]) - mx) * (log(h[l]) - mx), sxy += (log(h[l]) - mx) * (log(err[l]) - my);
  const double rate = sxy / sxx;
  if (!(rate > 1.7 && rate < 2.3))
    TEST_FAIL_("sphere volume error rate %g outside [1.7, 2.3]", rate);
}

static void csg(fcm_ctx *ctx)
{
  const double lo[3] = {-2, -1, -1}, hi[3] = {2, 1, 1};
  fcm_level_set_info info;
  /* a box: faces between lattice planes (phi = 0 on a lattice plane would make the
   * interpolant vanish on whole tets); the error is at its edges, O(h^2) */
  fcm_implicit b = {0};
  b.kind = FCM_IMPLICIT_BOX;
  const double bmin[3] = {-1.1, -0.45, -0.3}, bmax[3] = {0.9, 0.55, 0.7};
  memcpy(b.min, bmin, sizeof bmin), memcpy(b.max, bmax, sizeof bmax);
  fcm_geometry *g = build(ctx, &b, 1, lo, hi, 8, 4, &info);
  if (g) TEST_NEAR(fcm_geometry_volume(g), 2.0 * 1.0 * 1.0, 2e-2, 0);
  fcm_geometry_destroy(&g);
  /* union of two disjoint spheres = sum of the single volumes */
  fcm_implicit u[3] = {{0}};
  u[0].kind = u[1].kind = FCM_IMPLICIT_SPHERE;
  u[0].radius = 0.6, u[0].center[0] = -1;
  u[1].radius = 0.4, u[1].center[0] = 1.05;
  u[2].kind = FCM_IMPLICIT_UNION, u[2].a = 0, u[2].b = 1;
  double v0 = 0, v1 = 0;
  if ((g = build(ctx, &u[0], 1, lo, hi, 8, 4, &info))) v0 = fcm_geometry_volume(g);
  fcm_geometry_destroy(&g);
  if ((g = build(ctx, &u[1], 1, lo, hi, 8, 4, &info))) v1 = fcm_geometry_volume(g);
  fcm_geometry_destroy(&g);
  if ((g = build(ctx, u, 3, lo, hi, 8, 4, &info))) {
    TEST_NEAR(fcm_geometry_volume(g), v0 + v1, 1e-12, 0);
    TEST_NEAR(fcm_geometry_volume(g), 4.0 / 3.0 * PI * (0.216 + 0.064), 2e-2, 0);
  }
  fcm_geometry_destroy(&g);
  /* shell: big minus small ball; intersection with the half space x < 0 via a box */
  fcm_implicit d[5] = {{0}};
  d[0].kind = d[1].kind = FCM_IMPLICIT_SPHERE;
  d[0].radius = 0.9, d[1].radius = 0.5;
  d[2].kind = FCM_IMPLICIT_DIFFERENCE, d[2].a = 0, d[2].b = 1;
  d[3].kind = FCM_IMPLICIT_BOX;
  d[3].min[0] = -3, d[3].min[1] = -3, d[3].min[2] = -3, d[3].max[1] = 3, d[3].max[2] = 3;
  d[4].kind = FCM_IMPLICIT_INTERSECTION, d[4].a = 2, d[4].b = 3;
  const double shell = 4.0 / 3.0 * PI * (0.729 - 0.125);
  if ((g = build(ctx, d, 3, lo, hi, 8, 6, &info))) {
    TEST_NEAR(fcm_geometry_volume(g), shell, 1e-2, 0);
    TEST_NEAR(info.volume_fine, shell, 3e-3, 0);
  }
  fcm_geometry_destroy(&g);
  if ((g = build(ctx, d, 5, lo, hi, 8, 6, &info))) {
    TEST_NEAR(fcm_geometry_volume(g), shell / 2, 1e-2, 0);
    check_boundary(g, "half shell");
    /* a mirror keeps the surface, turned */
    const double A[9] = {-1, 0, 0, 0, 2, 0, 0, 0, 1}, off[3] = {1, 2, 3};
    fcm_geometry *m = NULL;
    TEST_OK(ctx, fcm_geometry_create_transformed(ctx, g, A, off, &m));
    if (m) {
      TEST_TRUE(fcm_geometry_num_boundary_triangles(m) == fcm_geometry_num_boundary_triangles(g));
      TEST_NEAR(fcm_geometry_volume(m), 2 * fcm_geometry_volume(g), 1e-12, 0);
      check_boundary(m, "half shell mirrored");
    }
    fcm_geometry_destroy(&m);
  }
  fcm_geometry_destroy(&g);
  /* a ball half outside the sampling box: cut off flat by the box face */
  fcm_implicit hb = {0};
  hb.kind = FCM_IMPLICIT_SPHERE, hb.radius = 0.8, hb.center[0] = 2.0;
  if ((g = build(ctx, &hb, 1, lo, hi, 8, 4, &info))) {
    TEST_NEAR(fcm_geometry_volume(g), 2.0 / 3.0 * PI * 0.512, 2e-2, 0);
    check_boundary(g, "ball cut by the box");
  }
  fcm_geometry_destroy(&g);
  /* torus: 2 pi^2 R r^2 */
  fcm_implicit t = {0};
  t.kind = FCM_IMPLICIT_TORUS, t.radius = 0.6, t.minor_radius = 0.25, t.axis = 0;
  if ((g = build(ctx, &t, 1, lo, hi, 8, 6, &info)))
    TEST_NEAR(fcm_geometry_volume(g), 2 * PI * PI * 0.6 * 0.0625, 2e-2, 0);
  fcm_geometry_destroy(&g);
  /* gyroid solid at level 0 fills half of a box of whole periods (g is odd under a shift of
   * half a period); the sheet is thin and lies inside the box */
  fcm_implicit gy = {0};
  gy.kind = FCM_IMPLICIT_GYROID, gy.period = 1, gy.thickness = 0, gy.sheet = 0;
  const double glo[3] = {0, 0, 0}, ghi[3] = {2, 2, 2};
  memcpy(gy.min, glo, sizeof glo), memcpy(gy.max, ghi, sizeof ghi);
  if ((g = build(ctx, &gy, 1, glo, ghi, 8, 4, &info))) {
    TEST_NEAR(fcm_geometry_volume(g), 4.0, 3e-2, 0);
    check_boundary(g, "gyroid solid (box faces)");
  }
  fcm_geometry_destroy(&g);
  gy.sheet = 1, gy.thickness = 0.05;
  if ((g = build(ctx, &gy, 1, glo, ghi, 8, 4, &info))) {
    TEST_TRUE(fcm_geometry_volume(g) > 0.5 && fcm_geometry_volume(g) < 4.0);
    TEST_TRUE(info.cells_cut > 0);
  }
  fcm_geometry_destroy(&g);
  /* refine_inside: same volume, conforming (no inside whole cells) */
  fcm_implicit big = {0};
  big.kind = FCM_IMPLICIT_SPHERE, big.radius = 0.95;
  fcm_implicit_tree tr = {1, &big};
  fcm_level_set_options o = fcm_level_set_options_default();
  const fcm_index n4[3] = {4, 4, 4};
  const double clo[3] = {-1, -1, -1}, chi[3] = {1, 1, 1};
  fcm_geometry *g2 = NULL;
  TEST_OK(ctx, fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &tr, clo, chi, n4, &o, &g,
                                                  &info));
  o.refine_inside = 1;
  TEST_OK(ctx, fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &tr, clo, chi, n4, &o,
                                                  &g2, NULL));
  if (g && g2) {
    TEST_TRUE(info.cells_inside == 8);
    TEST_NEAR(fcm_geometry_volume(g), fcm_geometry_volume(g2), 1e-12, 0);
    TEST_TRUE(fcm_geometry_num_cells(g2) > fcm_geometry_num_cells(g));
    check_boundary(g, "ball, whole cells");
    check_boundary(g2, "ball, refine_inside");
    /* the same surface either way: the iso-surface only */
    TEST_TRUE(fcm_geometry_num_boundary_triangles(g2) == fcm_geometry_num_boundary_triangles(g));
  }
  fcm_geometry_destroy(&g);
  fcm_geometry_destroy(&g2);
}

/* Allocation through a counting allocator: live and peak bytes (a size header per block). */
static size_t live_bytes, peak_bytes;

static void *count_alloc(void *user, size_t n)
{
  (void)user;
  size_t *p = malloc(n + 16);
  if (!p) return NULL;
  p[0] = n;
  live_bytes += n;
  if (live_bytes > peak_bytes) peak_bytes = live_bytes;
  return (char *)p + 16;
}

static void count_release(void *user, void *q)
{
  (void)user;
  if (!q) return;
  size_t *p = (size_t *)((char *)q - 16);
  live_bytes -= p[0];
  free(p);
}

/* The sub-cells a build at refinement r triangulates, counted here from the samples: the
 * sub-cubes of n^3 cells on [lo, hi]^3 whose corners have both signs, plus one per cell whose
 * samples are all inside. */
static fcm_index count_subcells(const fcm_implicit_tree *t, double lo, double hi, int n, int r)
{
  const int N = n * r, m = r + 1;
  fcm_index count = 0;
  double *w = malloc(sizeof *w * (size_t)(m * m * m));
  if (!w) return -1;
  for (int k = 0; k < n; k++)
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++) {
        int nin = 0;
        for (int c = 0; c < m; c++)
          for (int b = 0; b < m; b++)
            for (int a = 0; a < m; a++) {
              const int g[3] = {i * r + a, j * r + b, k * r + c};
              double x[3];
              for (int d = 0; d < 3; d++)
                x[d] = g[d] == N ? hi : lo + (hi - lo) * ((double)g[d] / (double)N);
              w[a + m * (b + m * c)] = fcm_implicit_eval(x, (void *)t);
              nin += w[a + m * (b + m * c)] < 0;
            }
        if (nin == m * m * m) count++;
        if (nin == 0 || nin == m * m * m) continue;
        for (int c = 0; c < r; c++)
          for (int b = 0; b < r; b++)
            for (int a = 0; a < r; a++) {
              int in = 0;
              for (int q = 0; q < 8; q++)
                in += w[(a + (q & 1)) + m * ((b + !!(q & 2)) + m * (c + !!(q & 4)))] < 0;
              count += in > 0 && in < 8;
            }
      }
  free(w);
  return count;
}

/* Progress calls: monotone, the last at done == total. */
typedef struct progress_log {
  int calls, monotone;
  fcm_index last_done, last_total;
} progress_log;

static void on_progress(fcm_index done, fcm_index total, void *user)
{
  progress_log *p = user;
  p->monotone &= done >= p->last_done && done <= total && (p->calls == 0 || total == p->last_total);
  p->calls++, p->last_done = done, p->last_total = total;
}

/* The sampling must resolve every feature: a feature below the spacing h is refused naming
 * the node, the member, its value and h; at h it passes. The gyroid of period 1e-9 at
 * refinement 64 on a 4^3 grid (16.7 million sub-cells of noise) is refused at once. */
static void spacing(fcm_ctx *ctx)
{
  const double h = 0.1;
  fcm_implicit q[3] = {{0}};
  fcm_implicit_tree t = {1, q};
  q[0].kind = FCM_IMPLICIT_SPHERE, q[0].radius = 0.1;
  TEST_OK(ctx, fcm_implicit_check_spacing(ctx, &t, h));
  q[0].radius = 0.05;
  TEST_ERR(ctx, fcm_implicit_check_spacing(ctx, &t, h), FCM_ERR_ARG,
           "node 0 (sphere): radius = 0.05 is below the sampling spacing h = 0.1");
  q[0].kind = FCM_IMPLICIT_TORUS, q[0].radius = 1, q[0].minor_radius = 0.09;
  TEST_ERR(ctx, fcm_implicit_check_spacing(ctx, &t, h), FCM_ERR_ARG,
           "node 0 (torus): minor_radius = 0.09 is below the sampling spacing h = 0.1");
  q[0].minor_radius = 0.1;
  TEST_OK(ctx, fcm_implicit_check_spacing(ctx, &t, h));
  q[0].kind = FCM_IMPLICIT_BOX;
  for (int d = 0; d < 3; d++)
    q[0].min[d] = 0, q[0].max[d] = 1;
  q[0].max[1] = 0.08;
  TEST_ERR(ctx, fcm_implicit_check_spacing(ctx, &t, h), FCM_ERR_ARG,
           "node 0 (box): the side max[1] - min[1] = 0.08 is below the sampling spacing h = 0.1");
  q[0].max[1] = 0.1;
  TEST_OK(ctx, fcm_implicit_check_spacing(ctx, &t, h));
  q[0].kind = FCM_IMPLICIT_GYROID, q[0].period = 0.2, q[0].sheet = 0, q[0].thickness = 0;
  TEST_OK(ctx, fcm_implicit_check_spacing(ctx, &t, h)); /* two samples per period */
  q[0].period = 0.19;
  TEST_ERR(ctx, fcm_implicit_check_spacing(ctx, &t, h), FCM_ERR_ARG,
           "node 0 (gyroid): period = 0.19 is below twice the sampling spacing h = 0.1");
  q[0].period = 1, q[0].sheet = 1, q[0].thickness = 0.04; /* a wall 0.08 thick */
  TEST_ERR(ctx, fcm_implicit_check_spacing(ctx, &t, h), FCM_ERR_ARG,
           "node 0 (gyroid): thickness = 0.04 is below half the sampling spacing h = 0.1");
  q[0].thickness = 0.05;
  TEST_OK(ctx, fcm_implicit_check_spacing(ctx, &t, h));
  /* in a tree: the node that fails is named; CSG nodes have no feature of their own */
  q[1].kind = FCM_IMPLICIT_SPHERE, q[1].radius = 0.01;
  q[2].kind = FCM_IMPLICIT_DIFFERENCE, q[2].a = 0, q[2].b = 1;
  t.num_nodes = 3;
  TEST_ERR(ctx, fcm_implicit_check_spacing(ctx, &t, h), FCM_ERR_ARG, "node 1 (sphere): radius");
  q[1].radius = 0.5;
  TEST_OK(ctx, fcm_implicit_check_spacing(ctx, &t, h));
  TEST_ERR(ctx, fcm_implicit_check_spacing(ctx, &t, 0.0), FCM_ERR_ARG, "h = 0 must be positive");
  q[2].b = 2;
  TEST_ERR(ctx, fcm_implicit_check_spacing(ctx, &t, h), FCM_ERR_ARG, "operands 0, 2");
  /* the build checks a built-in tree before sampling anything */
  fcm_implicit gy = {0};
  gy.kind = FCM_IMPLICIT_GYROID, gy.period = 1e-9;
  for (int d = 0; d < 3; d++)
    gy.min[d] = 0, gy.max[d] = 1;
  fcm_implicit_tree tg = {1, &gy};
  fcm_level_set_options o = fcm_level_set_options_default();
  o.refinement = 64;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n4[3] = {4, 4, 4};
  fcm_geometry *g = NULL;
  const double t0 = fcm_wtime();
  TEST_ERR(
      ctx,
      fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &tg, lo, hi, n4, &o, &g, NULL),
      FCM_ERR_ARG,
      "node 0 (gyroid): period = 1e-09 is below twice the sampling spacing h = 0.00390625");
  TEST_TRUE(fcm_wtime() - t0 < 0.5 && g == NULL);
}

/* The sub-cell limit: the estimate is the count of crossed sub-cells plus inside cells; a
 * build one above the limit is refused before it allocates anything of its size, naming the
 * estimate, the limit and the option; at the limit it builds within
 * FCM_LEVEL_SET_SUBCELL_BYTES per sub-cell; progress ends at done == total, the sub-cells of
 * the build and of the error estimate. */
static void subcell_limit(void)
{
  fcm_ctx_options co = fcm_ctx_options_default();
  co.allocator.alloc = count_alloc, co.allocator.release = count_release;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(&co, &ctx));
  if (!ctx) return;
  fcm_implicit s = {0};
  s.kind = FCM_IMPLICIT_SPHERE, s.radius = 0.7, s.center[0] = 0.05;
  fcm_implicit_tree t = {1, &s};
  const int n = 6, r = 4;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  const fcm_index nn[3] = {n, n, n};
  const fcm_index expect = count_subcells(&t, -1, 1, n, r);
  fcm_level_set_options o = fcm_level_set_options_default();
  fcm_level_set_info info;
  fcm_geometry *g = NULL;
  o.refinement = r;
  o.max_subcells = expect - 1;
  const size_t base = live_bytes;
  peak_bytes = live_bytes;
  char msg[200];
  snprintf(msg, sizeof msg, "level set: the build would triangulate %lld sub-cells",
           (long long)expect);
  TEST_ERR(
      ctx,
      fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &t, lo, hi, nn, &o, &g, &info),
      FCM_ERR_UNSUPPORTED, msg);
  snprintf(msg, sizeof msg, "more than max_subcells = %lld (", (long long)(expect - 1));
  TEST_ERR(ctx,
           fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &t, lo, hi, nn, &o, &g, NULL),
           FCM_ERR_UNSUPPORTED, msg);
  TEST_TRUE(g == NULL && live_bytes == base);
  TEST_TRUE(peak_bytes - base < 64 * 1024); /* the samples of one cell and the cell kinds */
  progress_log pl = {0, 1, 0, 0};
  o.max_subcells = expect;
  o.progress = on_progress, o.progress_user = &pl, o.progress_interval = 0;
  peak_bytes = live_bytes;
  TEST_OK(ctx, fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &t, lo, hi, nn, &o, &g,
                                                  &info));
  if (g) {
    TEST_TRUE(info.subcells == expect);
    TEST_TRUE((double)(peak_bytes - base) <= (double)FCM_LEVEL_SET_SUBCELL_BYTES * expect);
    const fcm_index total = info.cells_cut * r * r * r * 9; /* r^3 + (2r)^3 per cut cell */
    TEST_TRUE(pl.calls >= 2 && pl.monotone && pl.last_done == total && pl.last_total == total);
  }
  fcm_geometry_destroy(&g);
  /* 0: no limit */
  o.max_subcells = 0, o.progress = NULL;
  TEST_OK(ctx,
          fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &t, lo, hi, nn, &o, &g, NULL));
  fcm_geometry_destroy(&g);
  o.max_subcells = -1;
  TEST_ERR(ctx,
           fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &t, lo, hi, nn, &o, &g, NULL),
           FCM_ERR_ARG, "max_subcells = -1 must be >= 0");
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
}

static double nan_phi(const double x[3], void *user)
{
  (void)user;
  return x[0] > 0.5 ? NAN : -1.0;
}
static double outside_phi(const double x[3], void *user)
{
  (void)x, (void)user;
  return 1.0;
}

static void errors(fcm_ctx *ctx)
{
  fcm_implicit q[2] = {{0}};
  fcm_implicit_tree t = {2, q};
  q[0].kind = FCM_IMPLICIT_SPHERE, q[0].radius = 1;
  q[1].kind = FCM_IMPLICIT_UNION, q[1].a = 0, q[1].b = 1;
  TEST_ERR(ctx, fcm_implicit_check(ctx, &t), FCM_ERR_ARG, "node 1 (union): operands 0, 1");
  q[1].kind = FCM_IMPLICIT_TORUS, q[1].radius = 1, q[1].minor_radius = 2;
  TEST_ERR(ctx, fcm_implicit_check(ctx, &t), FCM_ERR_ARG, "minor_radius 2 outside (0, radius");
  q[0].radius = -1, t.num_nodes = 1;
  TEST_ERR(ctx, fcm_implicit_check(ctx, &t), FCM_ERR_ARG, "radius -1 must be positive");
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, bad[3] = {1, 1, 0};
  const fcm_index n[3] = {2, 2, 2};
  fcm_geometry *g = NULL;
  fcm_level_set_options o = fcm_level_set_options_default();
  TEST_ERR(ctx, fcm_geometry_create_from_level_set(ctx, nan_phi, NULL, lo, hi, n, NULL, &g, NULL),
           FCM_ERR_GEOMETRY, "is not finite");
  TEST_ERR(ctx,
           fcm_geometry_create_from_level_set(ctx, outside_phi, NULL, lo, hi, n, NULL, &g, NULL),
           FCM_ERR_GEOMETRY, "has no volume in the box");
  TEST_ERR(ctx,
           fcm_geometry_create_from_level_set(ctx, outside_phi, NULL, lo, bad, n, NULL, &g, NULL),
           FCM_ERR_ARG, "box axis 2");
  o.refinement = 65;
  TEST_ERR(ctx, fcm_geometry_create_from_level_set(ctx, outside_phi, NULL, lo, hi, n, &o, &g, NULL),
           FCM_ERR_ARG, "refinement 65 outside [1, 64]");
  TEST_TRUE(g == NULL);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  sphere_rate(ctx);
  csg(ctx);
  errors(ctx);
  spacing(ctx);
  subcell_limit();
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
