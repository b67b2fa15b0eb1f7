/* The inside test of points in a background cell's columns on the geometry's own tree of its
 * boundary triangles: fcm__embed_inside_column() (the winding number of a Hex8 cell's clear top
 * or bottom face, plus the crossings of the cell's own triangles, kept between calls) and
 * fcm__embed_inside_line() (the triangles along the shorter half of the line through the
 * points), against fcm__embed_inside_line() on a tree of the same boxes built here (the whole
 * line, whose crossings must sum to zero) with a fresh scratch. Grids of
 * Hex8 and Tet4 cells over a faceted ball and a hollow ball with holes (two nested surfaces,
 * winding numbers 0 and 1 in the shell, the holes open to the outside), each cell's columns
 * through its corners, edges, faces and interior, their points in no particular order and on
 * the cell's faces, and single points. Asserts
 * - the same answer for every point from the three, whatever the cell and the calls before (the
 *   column cache reused from cell to cell, the clear boxes of the single points kept);
 * - every answer 0 or 1, and on the ball the answer of the geometry itself where the point lies
 *   farther than 1e-9 from its surface: inside the sphere the triangles' planes bound, or
 *   outside the sphere through its vertices (points on both sides of the middle, so that the
 *   line's upper and lower halves both answer);
 * - both of the column's paths taken: Hex8 cells with a clear face (the cache) and cells
 *   without (the line query). */
#include "embed/embed_impl.h"
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

/* The ball's own answer at x: 1 inside the largest sphere about c within every triangle's
 * plane, 0 outside the sphere through the vertices, -1 between (not decided here). */
typedef struct ball_ref {
  double c[3], r_in, r_out;
} ball_ref;

static void ball_ref_init(const fcm_geometry *g, const double c[3], ball_ref *b)
{
  memcpy(b->c, c, sizeof b->c);
  b->r_in = HUGE_VAL, b->r_out = 0.0;
  for (fcm_index t = 0; t < g->num_tris; t++) {
    const double *p = g->coords + 3 * g->tris[3 * t], *q = g->coords + 3 * g->tris[3 * t + 1],
                 *s = g->coords + 3 * g->tris[3 * t + 2];
    const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]},
                 v[3] = {s[0] - p[0], s[1] - p[1], s[2] - p[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                         u[0] * v[1] - u[1] * v[0]};
    const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double d = fabs(n[0] * (p[0] - c[0]) + n[1] * (p[1] - c[1]) + n[2] * (p[2] - c[2])) / nn;
    b->r_in = fmin(b->r_in, d);
    for (int a = 0; a < 3; a++) {
      const double *x = g->coords + 3 * g->tris[3 * t + a];
      const double e[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
      b->r_out = fmax(b->r_out, sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]));
    }
  }
}

static int ball_answer(const ball_ref *b, const double x[3])
{
  const double e[3] = {x[0] - b->c[0], x[1] - b->c[1], x[2] - b->c[2]};
  const double r = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  return r < b->r_in - 1e-9 ? 1 : r > b->r_out + 1e-9 ? 0 : -1;
}

typedef struct tally {
  long points, checked, cells, cached, cells_up, cells_down;
} tally;

/* The physical point of reference point xi of an affine cell. */
static void physical(const fcm__embed_cell *cell, const double xi[3], double x[3])
{
  for (int i = 0; i < 3; i++) {
    x[i] = cell->X[i];
    for (int j = 0; j < 3; j++)
      x[i] += cell->A[3 * i + j] * (xi[j] - cell->xi0[j]);
  }
}

/* One column (a, b) with points z (n): the column test with the kept scratch against the line
 * test with a fresh one, and against the ball's answer. */
typedef struct trees {
  const fcm_aabb_tree *own; /* the geometry's: shorter half lines, column caches */
  fcm_aabb_tree *whole;     /* the same boxes, another tree: whole lines */
} trees;

static void column(fcm_ctx *ctx, const fcm_geometry *g, const trees *tr,
                   const fcm__embed_cell *cell, double a, double b, int n, const double *z,
                   fcm__idbuf *buf, fcm__crossings *cr, const ball_ref *ref, const char *what,
                   tally *t)
{
  int in_col[8], in_half[8], in_line[8];
  fcm__idbuf fbuf = {NULL, 0, 0};
  fcm__crossings fresh, fresh2;
  memset(&fresh, 0, sizeof fresh);
  memset(&fresh2, 0, sizeof fresh2);
  CHECK_OK(fcm__embed_inside_column(ctx, g, tr->own, cell, a, b, n, z, in_col, buf, cr));
  CHECK_OK(fcm__embed_inside_line(ctx, g, tr->own, cell, a, b, n, z, in_half, &fbuf, &fresh2));
  CHECK_OK(fcm__embed_inside_line(ctx, g, tr->whole, cell, a, b, n, z, in_line, &fbuf, &fresh));
  for (int i = 0; i < n; i++) {
    const double xi[3] = {a, b, z[i]};
    double x[3];
    physical(cell, xi, x);
    t->points++;
    CHECK(in_col[i] == in_line[i] && in_half[i] == in_line[i],
          "%s, cell %lld, point (%g, %g, %g) of %d: the column test says %d, the half line %d, "
          "the whole line %d",
          what, (long long)cell->id, a, b, z[i], n, in_col[i], in_half[i], in_line[i]);
    CHECK(in_line[i] == 0 || in_line[i] == 1, "%s, cell %lld: winding number %d at (%g, %g, %g)",
          what, (long long)cell->id, in_line[i], x[0], x[1], x[2]);
    const int want = ref ? ball_answer(ref, x) : -1;
    if (want < 0) continue;
    t->checked++;
    CHECK(in_line[i] == want,
          "%s, cell %lld: the point (%g, %g, %g) is %s the ball, the test says %d", what,
          (long long)cell->id, x[0], x[1], x[2], want ? "inside" : "outside", in_line[i]);
  }
  fcm__geom_idbuf_free(ctx, &fbuf);
  fcm__crossings_free(ctx, &fresh);
  fcm__crossings_free(ctx, &fresh2);
}

static void run(fcm_ctx *ctx, const fcm_geometry *g, fcm_element_type type, const ball_ref *ref,
                const char *what)
{
  const double lo[3] = {-1.05, -0.95, -1.1}, hi[3] = {1.0, 1.0, 0.9};
  const fcm_index n[3] = {6, 7, 6};
  const int hex = type == FCM_ELEMENT_HEX8;
  fcm_mesh *mesh = NULL;
  trees tr = {NULL, NULL};
  double *boxes = NULL;
  fcm_index nb;
  fcm__idbuf buf = {NULL, 0, 0};
  fcm__crossings cr;
  tally t = {0, 0, 0, 0, 0, 0};
  memset(&cr, 0, sizeof cr);
  CHECK_OK(fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  CHECK_OK(fcm__geom_boxes(ctx, g, 1, &boxes, &nb));
  CHECK_OK(fcm_aabb_tree_create(ctx, nb, boxes, &tr.whole));
  CHECK_OK(fcm__geom_tree(ctx, g, 1, &tr.own));
  /* columns through corners, edges, faces and the inside; points unordered, on the faces too */
  const double ab[] = {-1.0, -0.55, 0.0, 0.37, 1.0};
  const double zs[6] = {0.25, -1.0, 0.8, -0.6, 1.0, -0.1};
  const double tz[6] = {0.25, 0.0, 0.6, 0.1, 1.0, 0.4};
  unsigned seed = 12345u;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm__embed_cell cell;
    CHECK_OK(fcm__embed_cell_setup(ctx, mesh, c, 1e-12, &cell));
    t.cells++;
    for (int i = 0; i < 5; i++)
      for (int j = 0; j < 5; j++) {
        double a = ab[i], b = ab[j];
        if (!hex) { /* the unit tet: a, b, z >= 0, a + b + z <= 1 */
          a = 0.5 * (a + 1.0), b = 0.5 * (b + 1.0) * (1.0 - a);
          double z[6];
          for (int k = 0; k < 6; k++)
            z[k] = tz[k] * (1.0 - a - b);
          column(ctx, g, &tr, &cell, a, b, 6, z, &buf, &cr, ref, what, &t);
          continue;
        }
        column(ctx, g, &tr, &cell, a, b, 6, zs, &buf, &cr, ref, what, &t);
      }
    if (hex && cr.col_tree == tr.own && cr.col_face) {
      t.cached++;
      t.cells_up += cr.col_face > 0;
      t.cells_down += cr.col_face < 0;
    }
    for (int k = 0; k < 12; k++) { /* single points, as a fit's piece points */
      double xi[3];
      for (int d = 0; d < 3; d++) {
        seed = seed * 1103515245u + 12345u;
        xi[d] = (double)(seed >> 8) / (double)(1u << 24);
      }
      if (hex)
        for (int d = 0; d < 3; d++)
          xi[d] = 2.0 * xi[d] - 1.0;
      else if (xi[0] + xi[1] + xi[2] > 1.0)
        for (int d = 0; d < 3; d++)
          xi[d] /= 3.0;
      column(ctx, g, &tr, &cell, xi[0], xi[1], 1, xi + 2, &buf, &cr, ref, what, &t);
    }
  }
  printf("  %-32s %s: %ld cells, %ld points (%ld against the ball's own answer); the column "
         "cache in %ld cells (%ld top, %ld bottom face)\n",
         what, hex ? "Hex8" : "Tet4", t.cells, t.points, t.checked, t.cached, t.cells_up,
         t.cells_down);
  if (ref) CHECK(4 * t.checked > t.points, "%s: few points decided by the ball itself", what);
  if (hex) {
    CHECK(t.cells_up > 0 && t.cells_down > 0,
          "%s: the cache took %ld top and %ld bottom faces: a path is not exercised", what,
          t.cells_up, t.cells_down);
    CHECK(t.cached < t.cells, "%s: every cell cached: the line path is not exercised", what);
  }
  fcm__geom_idbuf_free(ctx, &buf);
  fcm__crossings_free(ctx, &cr);
  fcm_aabb_tree_destroy(&tr.whole);
  fcm__free(ctx, boxes);
  fcm_mesh_destroy(&mesh);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_TRUE(fcm_ctx_create(NULL, &ctx) == FCM_OK);
  const double c0[3] = {0.03, -0.02, 0.01};
  fcm_geometry *ball = NULL, *hollow = NULL;
  ball_ref ref;
  CHECK_OK(fcm_geometry_create_ball(ctx, c0, 0.8, 4, &ball));
  CHECK_OK(fcm_geometry_create_hollow_ball(ctx, c0, 0.35, 0.85, 0.15, 4, 2, &hollow));
  ball_ref_init(ball, c0, &ref);
  run(ctx, ball, FCM_ELEMENT_HEX8, &ref, "ball");
  run(ctx, ball, FCM_ELEMENT_TET4, &ref, "ball");
  run(ctx, hollow, FCM_ELEMENT_HEX8, NULL, "hollow ball with holes");
  run(ctx, hollow, FCM_ELEMENT_TET4, NULL, "hollow ball with holes");
  fcm_geometry_destroy(&ball);
  fcm_geometry_destroy(&hollow);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
