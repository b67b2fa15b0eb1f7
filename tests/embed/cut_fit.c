/* The fitted rules of a cut's pieces on a body given by its boundary surface alone: a faceted
 * ball cut by a tilted plane through its middle (cells the body fills split in two: pieces the
 * body fills, whose candidates need no inside test, beside pieces at the boundary), a plane
 * 1e-4 of a cell off a grid plane and tilted (thin slivers, whose first candidates often miss
 * their moments and whose fits retry on finer ones or fall back to the volume path), a plane
 * cutting a cap near the ball's top (small pieces at the boundary), then a faceted
 * half-cylinder groove into the top (pieces of up to dozens of convex parts, whose retries take
 * a bounded share of their thousands of tet points). For every piece and kind: every monomial
 * of reference coordinates up to the rule's strength as the volume path's (the same ball as
 * tets) to TOL of the reference cell's volume; weights positive and finite; at most
 * M = (m + 1)(m + 2)(m + 3) / 6 points unless the cell fell back to the volume path (counted);
 * every point inside the reference cell, inside the ball and on its piece's side of every plane
 * cut so far. Hex8 and Tet4 backgrounds. */
#include "cut_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

/* Moment agreement relative to the reference cell's volume (as tests/embed/cut_surface.c);
 * positions: inside the cell, the ball and a plane's side to GEOM_TOL (physical, a cell is
 * 0.37 wide). */
#define TOL      1e-12
#define GEOM_TOL 1e-9

enum { MAX_M = 84, NUM_KNIVES = 3 };

typedef struct knife {
  double p[3], n[3];
} knife;

/* The physical point of reference point xi in cell c (an axis-aligned hexahedron on [-1, 1]^3
 * or a tetrahedron on the unit simplex). */
static void to_physical(const fcm_mesh *mesh, fcm_index c, const double xi[3], double x[3])
{
  double X[8 * 3];
  fcm_mesh_cell_coords(mesh, c, X);
  if (fcm_mesh_element_type(mesh) == FCM_ELEMENT_TET4) {
    for (int d = 0; d < 3; d++)
      x[d] =
          X[d] + xi[0] * (X[3 + d] - X[d]) + xi[1] * (X[6 + d] - X[d]) + xi[2] * (X[9 + d] - X[d]);
    return;
  }
  for (int d = 0; d < 3; d++) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (int a = 0; a < 8; a++)
      lo = fmin(lo, X[3 * a + d]), hi = fmax(hi, X[3 * a + d]);
    x[d] = lo + 0.5 * (xi[d] + 1.0) * (hi - lo);
  }
}

/* Signed distance of x to knife K. */
static double side(const knife *K, const double x[3])
{
  const double nn = sqrt(K->n[0] * K->n[0] + K->n[1] * K->n[1] + K->n[2] * K->n[2]);
  return ((x[0] - K->p[0]) * K->n[0] + (x[1] - K->p[1]) * K->n[1] + (x[2] - K->p[2]) * K->n[2]) /
         nn;
}

/* Piece p of cell c, kind k (strength m): positive finite weights, at most M points unless
 * bounded is 0, every point in the reference cell, the ball and on one side of each knife
 * (the side of the piece's centroid, where the knife passes through its cell). Returns the
 * number of points. */
static int check_points(const fcm_mesh *mesh, const fcm_cell_rules *r, fcm_index c, fcm_index p,
                        fcm_rule_kind k, int m, int bounded, const knife *K, int nk,
                        const char *what)
{
  int n;
  const double *xi, *w;
  const unsigned char *fl;
  const int tet = fcm_mesh_element_type(mesh) == FCM_ELEMENT_TET4;
  TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, k, &n, &xi, &w, &fl));
  int na = 0;
  double g[3] = {0, 0, 0}, wsum = 0.0;
  for (int j = 0; j < n; j++) {
    if (fl[j]) continue;
    na++;
    TEST_TRUE_MSG(w[j] > 0.0 && isfinite(w[j]), "%s: cell %lld, %s point %d: weight %.3g", what,
                  (long long)c, k == FCM_RULE_MASS ? "mass" : "stiffness", j, w[j]);
    const double *e = xi + 3 * j;
    const double lo = tet ? -GEOM_TOL : -1.0 - GEOM_TOL, hi = 1.0 + GEOM_TOL;
    int in = e[0] >= lo && e[1] >= lo && e[2] >= lo && e[0] <= hi && e[1] <= hi && e[2] <= hi;
    if (tet) in = in && e[0] + e[1] + e[2] <= 1.0 + GEOM_TOL;
    double x[3];
    to_physical(mesh, c, e, x);
    in = in && x[0] * x[0] + x[1] * x[1] + x[2] * x[2] <= (1.0 + GEOM_TOL) * (1.0 + GEOM_TOL);
    TEST_TRUE_MSG(in, "%s: cell %lld, point (%.6g, %.6g, %.6g) outside the cell or the ball", what,
                  (long long)c, e[0], e[1], e[2]);
    for (int d = 0; d < 3; d++)
      g[d] += w[j] * x[d];
    wsum += w[j];
  }
  const int qa = fcm_cell_rules_axis_degree(r, k); /* M: the size of the rules' moment space */
  int M = 0;
  for (int a = 0; a <= qa; a++)
    for (int b = 0; b <= qa; b++)
      for (int e = 0; e <= qa; e++)
        M += a + b + e <= m;
  TEST_TRUE_MSG(!bounded || na <= M, "%s: cell %lld: %d points, above M = %d", what, (long long)c,
                na, M);
  for (int d = 0; d < 3 && wsum > 0.0; d++)
    g[d] /= wsum;
  for (int q = 0; q < nk && wsum > 0.0; q++) {
    const double sg = side(&K[q], g);
    int lo = 0, hi = 0;
    for (int j = 0; j < n; j++) {
      if (fl[j]) continue;
      double x[3];
      to_physical(mesh, c, xi + 3 * j, x);
      const double s = side(&K[q], x);
      lo |= s<-GEOM_TOL, hi |= s> GEOM_TOL;
    }
    TEST_TRUE_MSG(!(lo && hi) || fabs(sg) <= GEOM_TOL,
                  "%s: cell %lld: a piece's points on both sides of knife %d", what, (long long)c,
                  q);
  }
  return na;
}

/* Every piece of rs (surface path) against its best match in rv (volume path); returns the
 * largest moment difference relative to the reference cell's volume, *unbounded the pieces
 * with more than M points of a kind. */
static double compare(const fcm_mesh *mesh, const fcm_cell_rules *rv, const fcm_cell_rules *rs,
                      const knife *K, int nk, int bounded, const char *what, int *unbounded)
{
  const double vref = fcm_mesh_element_type(mesh) == FCM_ELEMENT_TET4 ? 1.0 / 6.0 : 8.0;
  double worst = 0.0, mv[MAX_M], ms[MAX_M];
  *unbounded = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm_index fv, fs;
    const fcm_index kv = fcm_cell_rules_cell_pieces(rv, c, &fv),
                    ks = fcm_cell_rules_cell_pieces(rs, c, &fs);
    TEST_TRUE_MSG(kv == ks, "%s: cell %lld: %lld pieces on the volume path, %lld on the surface",
                  what, (long long)c, (long long)kv, (long long)ks);
    if (kv != ks || kv == 0) continue;
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const int m = fcm_cell_rules_strength(rs, (fcm_rule_kind)k);
      TEST_TRUE((m + 1) * (m + 2) * (m + 3) / 6 <= MAX_M);
      unsigned char used[64] = {0};
      for (fcm_index q = 0; q < ks; q++) {
        const int na = check_points(mesh, rs, c, fs + q, (fcm_rule_kind)k, m, bounded, K, nk, what);
        /* M: the moments of the rules' space (P_m, or Q_2 for Hex8's mass) */
        const int M = piece_monomials(ctx, rs, fs + q, (fcm_rule_kind)k, m, ms);
        *unbounded += na > M;
        double best = HUGE_VAL;
        int bp = -1;
        for (fcm_index p = 0; p < kv && p < 64; p++) {
          if (used[p]) continue;
          piece_monomials(ctx, rv, fv + p, (fcm_rule_kind)k, m, mv);
          double d = 0.0;
          for (int i = 0; i < M; i++)
            d = fmax(d, fabs(mv[i] - ms[i]) / vref);
          if (d < best) best = d, bp = (int)p;
        }
        if (bp >= 0) used[bp] = 1;
        worst = fmax(worst, best);
        TEST_TRUE_MSG(best <= TOL,
                      "%s: cell %lld piece %lld (%s): moments differ by %.3g of |K_ref|", what,
                      (long long)c, (long long)q, k == FCM_RULE_MASS ? "mass" : "stiffness", best);
      }
    }
  }
  return worst;
}

/* A half-cylinder groove of radius r along x (the lower half of the cylinder about the line
 * y = y0, z = z0), faceted into nseg strips: an open surface that splits the cells it crosses
 * into many parts. */
static void groove(double y0, double z0, double r, int nseg, fcm_surface **cut)
{
  double *x = malloc(6 * (size_t)(nseg + 1) * sizeof *x);
  fcm_index *t = malloc(6 * (size_t)nseg * sizeof *t);
  for (int i = 0; i <= nseg; i++) {
    const double a =
        3.14159265358979323846 * (1.0 + (double)i / nseg); /* pi .. 2 pi: the lower half */
    for (int e = 0; e < 2; e++) {
      double *v = x + 3 * (2 * i + e);
      v[0] = e ? 1.2 : -1.2, v[1] = y0 + r * cos(a), v[2] = z0 + r * sin(a);
    }
  }
  for (int i = 0; i < nseg; i++) {
    const fcm_index a = 2 * i, b = 2 * i + 1, c = 2 * i + 2, d = 2 * i + 3;
    t[6 * i] = a, t[6 * i + 1] = c, t[6 * i + 2] = d;
    t[6 * i + 3] = a, t[6 * i + 4] = d, t[6 * i + 5] = b;
  }
  TEST_OK(ctx, fcm_surface_create(ctx, 2 * (nseg + 1), x, 2 * nseg, t, cut));
  free(x);
  free(t);
}

static void run(fcm_element_type type, int nc)
{
  const char *name = type == FCM_ELEMENT_TET4 ? "tet4" : "hex8";
  const double lo[3] = {-1.1, -1.1, -1.1}, hi[3] = {1.1, 1.1, 1.1}, c0[3] = {0, 0, 0};
  const fcm_index n[3] = {nc, nc, nc};
  const double h = 2.2 / nc;
  fcm_mesh *mesh = NULL;
  fcm_geometry *gv = NULL, *gs = NULL;
  fcm_cell_rules *rv = NULL, *rs = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 1.0, 2, &gv));
  both_paths(ctx, mesh, gv, &gs, &rv, &rs);
  /* a tilted plane through the middle; a plane 1e-4 h beyond the grid plane y = lo + 2 h,
   * tilted by 1e-3; a cap near the top */
  const knife K[NUM_KNIVES] = {{{0.07, 0.03, -0.05}, {1, 0.3, 0.2}},
                               {{0.0, -1.1 + 2.0 * h + 1e-4 * h, 0.0}, {1e-3, 1, 0}},
                               {{0.0, 0.0, 0.86}, {0.1, -0.05, 1}}};
  const char *names[NUM_KNIVES] = {"plane", "sliver plane", "cap"};
  const double blo[3] = {-1.05, -1.05, -1.05}, bhi[3] = {1.05, 1.05, 1.05};
  for (int k = 0; k <= NUM_KNIVES; k++) {
    fcm_surface *cut = NULL;
    fcm_cell_rules *nv = NULL, *ns = NULL;
    if (k < NUM_KNIVES)
      TEST_OK(ctx, fcm_surface_create_plane(ctx, K[k].p, K[k].n, blo, bhi, &cut));
    else
      groove(0.1, 0.95, 0.45, 40, &cut);
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, gv, rv, cut, &nv));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, gs, rs, cut, &ns));
    fcm_surface_destroy(&cut);
    fcm_cell_rules_destroy(&rv);
    fcm_cell_rules_destroy(&rs);
    rv = nv, rs = ns;
    char what[64];
    snprintf(what, sizeof what, "%s, %s", name, k < NUM_KNIVES ? names[k] : "groove");
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(rs);
    int unbounded;
    const double worst =
        compare(mesh, rv, rs, K, k < NUM_KNIVES ? k + 1 : NUM_KNIVES, 0, what, &unbounded);
    /* a piece above M points only in a cell that fell back to the volume path */
    TEST_TRUE_MSG(unbounded <= 2 * FCM_RULE_KIND_COUNT * S->num_surface_fallbacks,
                  "%s: %d pieces' rules above M points, %lld cells on the volume path", what,
                  unbounded, (long long)S->num_surface_fallbacks);
    printf("%s: %lld pieces, %lld cells fitted on surface moments, %lld on the volume path, "
           "%d rules above M points; moments agree to %.2e of |K_ref|\n",
           what, (long long)fcm_cell_rules_num_pieces(rs), (long long)S->num_surface_cells,
           (long long)S->num_surface_fallbacks, unbounded, worst);
  }
  fcm_cell_rules_destroy(&rv);
  fcm_cell_rules_destroy(&rs);
  fcm_geometry_destroy(&gv);
  fcm_geometry_destroy(&gs);
  fcm_mesh_destroy(&mesh);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 2));
  run(FCM_ELEMENT_HEX8, 6);
  run(FCM_ELEMENT_TET4, 4);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
