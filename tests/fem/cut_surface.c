/* The embedded surface of a cut body (fcm_embedded_surface_*): a ball of 3,072
 * boundary triangles, cut by one oblique plane, then by a second one crossing it. Every body
 * the cuts separate is moved rigidly (its own rotation and translation, an affine field each
 * element reproduces exactly). Then:
 * - every surface triangle (boundary, split part or cut face) moves with one body: each
 *   vertex's displacement is that body's motion to 1e-12, so every edge keeps its length (to
 *   1e-9 of the mean edge); a triangle whose vertices followed two pieces would stretch;
 * - the boundary triangles and their parts cover the ball's boundary: their area equals the
 *   geometry's to 1e-12 relative;
 * - every boundary triangle or part lies on one side of each cut plane (signed distances
 *   within 1e-9 of the cell size), so the cuts split the triangles they cross;
 * - the boundary triangles no cut reaches are the geometry's own, in their order.
 * - the surface set to each cut space (the second reusing what the first cut found in the
 *   cells the second does not reach) has the bits of one made on that space anew: points,
 *   triangles, flags and the displacements of a field; so has the surface set back to it
 *   from a space of the same rules (every answer taken from what that rebuild kept); so has
 *   a surface whose rebuilds clip no (cell, triangle) pair ahead (each pair it splits is
 *   clipped while the triangles are split): these two on tet4 and tet10.
 * The same for a box cut along cell faces through its boundary vertices, and for a box of 12
 * boundary triangles cut by the ball's planes (far more part points and cut faces than
 * boundary vertices: the surface's arrays grow, in its creation and at each cut).
 * Arguments: tet4 | tet10 | hex8 | hex20. */
#include "fcm/fcm.h"
#include "fem/fem_impl.h"
#include "fem_util.h"
#include "space_bodies.h"

#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

enum { MAX_BODIES = 8 };

static fcm_element_type parse(const char *s)
{
  static const char *names[] = {"tet4", "tet10", "hex8", "hex20"};
  static const fcm_element_type types[] = {FCM_ELEMENT_TET4, FCM_ELEMENT_TET10, FCM_ELEMENT_HEX8,
                                           FCM_ELEMENT_HEX20};
  for (int i = 0; i < 4; i++)
    if (!strcmp(s, names[i])) return types[i];
  return FCM_ELEMENT_COUNT;
}

/* The rigid motion of body b: x -> Q_b x + t_b (rotation about a fixed axis; none when
 * `rotate` is 0). */
static void motion(int b, int rotate, double Q[9], double t[3])
{
  const double ax[3] = {0.2672612419124244, 0.5345224838248488, 0.8017837257372732};
  const double th = rotate ? 0.3 + 0.7 * b : 0.0, c = cos(th), s = sin(th);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      Q[3 * i + j] = (i == j ? c : 0.0) + (1 - c) * ax[i] * ax[j];
  Q[1] -= s * ax[2], Q[2] += s * ax[1];
  Q[3] += s * ax[2], Q[5] -= s * ax[0];
  Q[6] -= s * ax[1], Q[7] += s * ax[0];
  t[0] = 0.5 * b, t[1] = -0.3 * b + 0.1, t[2] = 0.2 * b * b;
}

static void move(const double Q[9], const double t[3], const double *X, double *x)
{
  for (int i = 0; i < 3; i++)
    x[i] = Q[3 * i] * X[0] + Q[3 * i + 1] * X[1] + Q[3 * i + 2] * X[2] + t[i];
}

static double dist(const double *a, const double *b)
{
  return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
              (a[2] - b[2]) * (a[2] - b[2]));
}

static double area(const double *a, const double *b, const double *c)
{
  double u[3], v[3];
  for (int d = 0; d < 3; d++)
    u[d] = b[d] - a[d], v[d] = c[d] - a[d];
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
  return 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* The checks of the header on surface es of space s after `ncut` cuts (planes: point,
 * normal); the bodies rotate too when `rotate` is set. */
static void check(const fcm_space *s, const fcm_embedded_surface *es, const fcm_geometry *ball,
                  int ncut, const double (*pp)[3], const double (*pn)[3], double h, int rotate)
{
  int nb = 0;
  fcm_index *body = space_element_bodies(s, &nb);
  TEST_TRUE(nb == fcm_space_num_bodies(s) && nb >= ncut + 1 && nb <= MAX_BODIES);
  if (nb > MAX_BODIES) nb = MAX_BODIES;
  double Q[MAX_BODIES][9], T[MAX_BODIES][3];
  for (int b = 0; b < nb; b++)
    motion(b, rotate, Q[b], T[b]);
  /* u: each element's DOFs carry its body's motion */
  const fcm_mesh *mesh = fcm_space_mesh(s);
  const int nn = fcm_mesh_nodes_per_cell(mesh);
  const fcm_index *cells = fcm_mesh_cells(mesh);
  const double *XN = fcm_mesh_coords(mesh);
  double *u = calloc((size_t)fcm_space_num_dofs(s), sizeof *u);
  for (fcm_index e = 0; e < fcm_space_num_elements(s); e++) {
    const fcm_index c = fcm_space_element_cell(s, e), *ed = fcm_space_element_dofs(s, e);
    const int b = (int)body[e] < nb ? (int)body[e] : 0;
    for (int a = 0; a < nn; a++) {
      const double *X = XN + 3 * cells[(size_t)nn * c + a];
      double x[3];
      move(Q[b], T[b], X, x);
      for (int d = 0; d < 3; d++)
        u[ed[a] + d] = x[d] - X[d];
    }
  }
  const fcm_index np = fcm_embedded_surface_num_points(es),
                  nt = fcm_embedded_surface_num_triangles(es);
  const double *P = fcm_embedded_surface_points(es);
  const fcm_index *tri = fcm_embedded_surface_triangles(es);
  const int32_t *flag = fcm_embedded_surface_cut_flags(es);
  double *x = malloc(sizeof *x * 3 * (size_t)np);
  int *pb = malloc(sizeof *pb * (size_t)np);
  TEST_OK(ctx, fcm_embedded_surface_eval(es, u, NULL, x));
  /* the body each point follows */
  fcm_index stray = 0;
  for (fcm_index i = 0; i < np; i++) {
    pb[i] = -1;
    for (int b = 0; b < nb && pb[i] < 0; b++) {
      double y[3];
      move(Q[b], T[b], P + 3 * i, y);
      if (dist(y, x + 3 * i) <= 1e-12) pb[i] = b;
    }
    stray += pb[i] < 0;
  }
  TEST_TRUE(stray == 0);
  /* mean edge of the geometry's boundary */
  const fcm_index ngt = fcm_geometry_num_boundary_triangles(ball);
  const fcm_index *gt = fcm_geometry_boundary_triangles(ball);
  const double *GX = fcm_geometry_coords(ball);
  double ag = 0.0, lmean = 0.0;
  for (fcm_index k = 0; k < ngt; k++) {
    const double *a = GX + 3 * gt[3 * k], *b = GX + 3 * gt[3 * k + 1], *c = GX + 3 * gt[3 * k + 2];
    ag += area(a, b, c);
    lmean += (dist(a, b) + dist(b, c) + dist(c, a)) / (3.0 * (double)ngt);
  }
  fcm_index mixed = 0, stretched = 0, sides = 0, kept = 0, order_ok = 1, next = 0;
  double asurf = 0.0, worst = 0.0;
  for (fcm_index k = 0; k < nt; k++) {
    const fcm_index *v = tri + 3 * k;
    mixed += pb[v[0]] != pb[v[1]] || pb[v[0]] != pb[v[2]];
    for (int a = 0; a < 3; a++) {
      const fcm_index i = v[a], j = v[(a + 1) % 3];
      const double dl = fabs(dist(x + 3 * i, x + 3 * j) - dist(P + 3 * i, P + 3 * j));
      worst = fmax(worst, dl / fmax(dist(P + 3 * i, P + 3 * j), lmean));
      stretched += !(dl <= 1e-9 * fmax(dist(P + 3 * i, P + 3 * j), lmean));
    }
    if (flag[v[0]] || flag[v[1]] || flag[v[2]]) continue; /* a cut face */
    asurf += area(P + 3 * v[0], P + 3 * v[1], P + 3 * v[2]);
    for (int c = 0; c < ncut; c++) {
      double lo = HUGE_VAL, hi = -HUGE_VAL;
      for (int a = 0; a < 3; a++) {
        const double *y = P + 3 * v[a];
        const double sd = (y[0] - pp[c][0]) * pn[c][0] + (y[1] - pp[c][1]) * pn[c][1] +
                          (y[2] - pp[c][2]) * pn[c][2];
        lo = fmin(lo, sd), hi = fmax(hi, sd);
      }
      sides += lo < -1e-9 * h && hi > 1e-9 * h;
    }
  }
  /* the boundary triangles kept whole come first: the geometry's, in their order */
  const fcm_index nkept = ngt - fcm_embedded_surface_num_split_triangles(es);
  for (fcm_index k = 0; k < nkept && order_ok; k++) {
    const fcm_index *v = tri + 3 * k;
    while (next < ngt && (memcmp(GX + 3 * gt[3 * next], P + 3 * v[0], 3 * sizeof *P) ||
                          memcmp(GX + 3 * gt[3 * next + 1], P + 3 * v[1], 3 * sizeof *P) ||
                          memcmp(GX + 3 * gt[3 * next + 2], P + 3 * v[2], 3 * sizeof *P)))
      next++;
    order_ok = next++ < ngt;
    kept += order_ok;
  }
  printf("%d cut(s), %s: %d bodies, %lld points, %lld triangles (%lld boundary triangles split), "
         "worst edge change %.3g (of max(edge, mean edge)), area %.17g vs %.17g (%.3g)\n",
         ncut, rotate ? "rotated" : "translated", nb, (long long)np, (long long)nt,
         (long long)fcm_embedded_surface_num_split_triangles(es), worst, asurf, ag,
         fabs(asurf - ag) / ag);
  TEST_TRUE(mixed == 0);
  TEST_TRUE(stretched == 0);
  TEST_TRUE(sides == 0);
  TEST_NEAR(asurf, ag, 0, 1e-12 * ag);
  TEST_TRUE(fcm_embedded_surface_num_split_triangles(es) > 0);
  TEST_TRUE(order_ok && kept == nkept);
  free(u), free(x), free(pb), free(body);
}

/* The surface set to space s after earlier spaces (the second cut's reuses what the first
 * found in the cells it does not reach) has the same bits as one made on s anew. */
static void same_as_new(const fcm_embedded_surface *es, const fcm_space *s, const fcm_geometry *g)
{
  fcm_embedded_surface *fresh = NULL;
  TEST_OK(ctx, fcm_embedded_surface_create(s, g, &fresh));
  if (!fresh) return;
  const fcm_index np = fcm_embedded_surface_num_points(es),
                  nt = fcm_embedded_surface_num_triangles(es);
  TEST_TRUE(np == fcm_embedded_surface_num_points(fresh));
  TEST_TRUE(nt == fcm_embedded_surface_num_triangles(fresh));
  TEST_TRUE(fcm_embedded_surface_num_split_triangles(es) ==
            fcm_embedded_surface_num_split_triangles(fresh));
  if (np == fcm_embedded_surface_num_points(fresh) &&
      nt == fcm_embedded_surface_num_triangles(fresh)) {
    TEST_TRUE(!memcmp(fcm_embedded_surface_points(es), fcm_embedded_surface_points(fresh),
                      3 * (size_t)np * sizeof(double)));
    TEST_TRUE(!memcmp(fcm_embedded_surface_triangles(es), fcm_embedded_surface_triangles(fresh),
                      3 * (size_t)nt * sizeof(fcm_index)));
    TEST_TRUE(!memcmp(fcm_embedded_surface_cut_flags(es), fcm_embedded_surface_cut_flags(fresh),
                      (size_t)np * sizeof(int32_t)));
    /* the elements: the displacement of a field that differs on every DOF */
    const fcm_index n = fcm_space_num_dofs(s);
    double *u = malloc(sizeof *u * (size_t)(n + 1)),
           *d0 = malloc(sizeof *d0 * 3 * (size_t)(np + 1));
    double *d1 = malloc(sizeof *d1 * 3 * (size_t)(np + 1));
    if (u && d0 && d1) {
      for (fcm_index i = 0; i < n; i++)
        u[i] = 1.0 + 0.001 * (double)i;
      TEST_OK(ctx, fcm_embedded_surface_eval(es, u, d0, NULL));
      TEST_OK(ctx, fcm_embedded_surface_eval(fresh, u, d1, NULL));
      TEST_TRUE(!memcmp(d0, d1, 3 * (size_t)np * sizeof *d0));
    }
    free(u), free(d0), free(d1);
  }
  fcm_embedded_surface_destroy(&fresh);
}

/* Cut the body `g` in a 4^3 grid on [-1, 1]^3 by the planes (point pp[k], unit normal pn[k])
 * one after the other, checking the surface after each (the planes moved by the shift the
 * cut may have taken). */
static void run(fcm_element_type type, fcm_geometry *g, int ncut, const double (*pp)[3],
                const double (*pn)[3])
{
  fcm_mesh *mesh = NULL;
  fcm_cell_rules *r[3] = {NULL, NULL, NULL};
  fcm_space *s[3] = {NULL, NULL, NULL}, *free_space = NULL;
  fcm_surface *plane = NULL;
  fcm_embedded_surface *es = NULL, *late = NULL;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  const fcm_index n3[3] = {4, 4, 4};
  const double h = 0.5;
  double at[2][3];
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n3, &mesh));
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.kinds = FCM_RULES_STIFFNESS;
  o.simplify = FCM_CELL_SIMPLIFY_OFF;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r[0], &s[0]));
  TEST_OK(ctx, fcm_embedded_surface_create(s[0], g, &es));
  /* the surface that clips nothing ahead and the surface set back: on the simplices only (the
   * code under test does not depend on the element; the hexahedra's runs are the long ones) */
  const int extra = type == FCM_ELEMENT_TET4 || type == FCM_ELEMENT_TET10;
  if (extra) TEST_OK(ctx, fcm_embedded_surface_create(s[0], g, &late));
  if (!es || (extra && !late)) goto done;
  if (late) late->test_no_preclip = 1;
  /* uncut: the geometry's triangles, nothing split */
  TEST_TRUE(fcm_embedded_surface_num_triangles(es) == fcm_geometry_num_boundary_triangles(g));
  TEST_TRUE(fcm_embedded_surface_num_split_triangles(es) == 0);
  for (int k = 0; k < ncut && k < 2; k++) {
    const double bl[3] = {-1.5, -1.5, -1.5}, bh[3] = {1.5, 1.5, 1.5};
    TEST_OK(ctx, fcm_surface_create_plane(ctx, pp[k], pn[k], bl, bh, &plane));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r[k], plane, &r[k + 1]));
    fcm_surface_destroy(&plane);
    if (!r[k + 1]) goto done;
    for (int d = 0; d < 3; d++)
      at[k][d] = pp[k][d] + fcm_cell_rules_get_stats(r[k + 1])->cut_shift[d];
    /* the default space (tiny copies constrained: exact for translations) and one without
     * the constraint (exact for every rigid motion) */
    fcm_space_options so = fcm_space_options_default();
    so.constrain_ratio = 0.0;
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r[k + 1], &s[k + 1]));
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, r[k + 1], &so, &free_space));
    if (!s[k + 1] || !free_space) goto done;
    TEST_OK(ctx, fcm_embedded_surface_set_space(es, s[k + 1]));
    same_as_new(es, s[k + 1], g);
    if (late) {
      TEST_OK(ctx, fcm_embedded_surface_set_space(late, s[k + 1]));
      same_as_new(late, s[k + 1], g);
    }
    check(s[k + 1], es, g, k + 1, (const double(*)[3])at, pn, h, 0);
    TEST_OK(ctx, fcm_embedded_surface_set_space(es, free_space));
    check(free_space, es, g, k + 1, (const double(*)[3])at, pn, h, 1);
    TEST_OK(ctx, fcm_embedded_surface_set_space(es, s[k + 1]));
    if (extra) same_as_new(es, s[k + 1], g); /* all from what the rebuild on free_space kept */
    fcm_space_destroy(&free_space);
  }
done:
  fcm_embedded_surface_destroy(&es);
  fcm_embedded_surface_destroy(&late);
  fcm_space_destroy(&free_space);
  for (int k = 0; k < 3; k++) {
    fcm_space_destroy(&s[k]);
    fcm_cell_rules_destroy(&r[k]);
  }
  fcm_mesh_destroy(&mesh);
}

int main(int argc, char **argv)
{
  const fcm_element_type type = argc > 1 ? parse(argv[1]) : FCM_ELEMENT_HEX8;
  TEST_TRUE(type != FCM_ELEMENT_COUNT);
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  fcm_geometry *g = NULL;
  /* a ball of 3,072 boundary triangles cut by two oblique planes crossing inside it */
  const double c[3] = {0.031, -0.017, 0.023};
  const double pp[2][3] = {{0.05, 0.02, -0.03}, {-0.04, 0.06, 0.01}};
  const double pn[2][3] = {{0.8164965809277261, 0.4082482904638631, 0.4082482904638631},
                           {-0.2672612419124244, 0.8017837257372732, -0.5345224838248488}};
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.8, 8, &g));
  if (g && type != FCM_ELEMENT_COUNT) run(type, g, 2, pp, pn);
  fcm_geometry_destroy(&g);
  /* a box cut along cell faces x = 0, then y = 0, through boundary vertices: the cells keep
   * one piece each, and the triangles on either side of a vertex on the cut follow theirs */
  const double glo[3] = {-0.7, -0.7, -0.7}, ghi[3] = {0.7, 0.7, 0.7};
  const double fn[2][3] = {{1, 0, 0}, {0, 1, 0}}, fp[2][3] = {{0, 0.1, 0.2}, {0.1, 0, 0.3}};
  const fcm_index gn[3] = {4, 4, 4};
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  if (g && type != FCM_ELEMENT_COUNT) run(type, g, 2, fp, fn);
  fcm_geometry_destroy(&g);
  const fcm_index one[3] = {1, 1, 1};
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, one, &g));
  if (g && type != FCM_ELEMENT_COUNT) run(type, g, 2, pp, pn);
  fcm_geometry_destroy(&g);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
