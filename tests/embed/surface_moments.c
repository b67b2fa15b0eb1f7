/* Moments of the material in a cell from the boundary surface alone (surface_moments.c)
 * against the clipped volume mesh, on Hex8 and Tet4 grids, for a ball, a hollow ball with
 * holes, a rotated ball and a box whose faces lie on grid planes and through cell corners.
 * Asserts
 * - per cell: every monomial xi^a, |a| <= m, integrated by the signed rule equals the tets'
 *   initial rule within 1e-12 of the reference cell's volume;
 * - the cells' volumes add up to the geometry's volume within 1e-12;
 * - the inside test: random points against the point-in-tet oracle; points on the box's
 *   faces and edges inside or outside consistently (winding number 0 or 1, never 2 or -1);
 * - an open surface (one triangle missing) is reported as FCM_ERR_GEOMETRY;
 * - the geometry's search trees are built by its first rules build and reused by the next ones
 *   (the same trees, and the same rules). */
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

enum { M_DEG = 4 };

typedef struct fixture {
  fcm_aabb_tree *cells, *tris;
  fcm_rule *tet_rule;
  fcm__moment_quad q;
  fcm__embed_ws ws;
  fcm__idbuf buf;
  fcm__crossings cr;
  fcm__srule s;
} fixture;

static fcm_status trees(fcm_ctx *ctx, const fcm_geometry *g, fixture *f)
{
  fcm_status st = FCM_OK;
  double *boxes = NULL;
  fcm_index n;
  FCM_TRY(ctx, fcm__geom_boxes(ctx, g, 0, &boxes, &n));
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, n, boxes, &f->cells));
  fcm__free(ctx, boxes);
  boxes = NULL;
  FCM_TRY(ctx, fcm__geom_boxes(ctx, g, 1, &boxes, &n));
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, n, boxes, &f->tris));
cleanup:
  fcm__free(ctx, boxes);
  return st;
}

static void release(fcm_ctx *ctx, fixture *f)
{
  fcm_aabb_tree_destroy(&f->cells);
  fcm_aabb_tree_destroy(&f->tris);
  fcm__embed_ws_free(ctx, &f->ws);
  fcm__geom_idbuf_free(ctx, &f->buf);
  fcm__crossings_free(ctx, &f->cr);
  fcm__srule_free(ctx, &f->s);
}

/* sum_i w_i xi_i^a for every exponent |a| <= M_DEG, in a fixed order. */
static int monomials(size_t n, const double *x, const double *w, double *mom)
{
  int k = 0;
  for (int d = 0; d <= M_DEG; d++)
    for (int a = d; a >= 0; a--)
      for (int b = d - a; b >= 0; b--, k++) {
        const int c = d - a - b;
        double s = 0.0;
        for (size_t i = 0; i < n; i++)
          s += w[i] * pow(x[3 * i], a) * pow(x[3 * i + 1], b) * pow(x[3 * i + 2], c);
        mom[k] = s;
      }
  return k;
}

/* Compare both paths on every cell of mesh; returns the embedded volume by the surface path. */
static double compare(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *g, fixture *f,
                      const char *what)
{
  double vol = 0.0, worst = 0.0;
  fcm_index cut = 0;
  double *pts = NULL, *w = NULL;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm__embed_cell cell;
    fcm__embed_counts counts;
    double v_old, m_old[64], m_new[64];
    int touched;
    double box[6];
    memset(&counts, 0, sizeof counts);
    CHECK_OK(fcm__embed_cell_setup(ctx, mesh, c, 1e-12, &cell));
    CHECK_OK(fcm__embed_cell_tets(ctx, g, f->cells, &cell, 1e-12, 1e-14, &f->ws, &counts, &v_old));
    const size_t n = f->ws.num_tets * (size_t)fcm_rule_num_points(f->tet_rule);
    pts = realloc(pts, 3 * (n + 1) * sizeof *pts);
    w = realloc(w, (n + 1) * sizeof *w);
    CHECK(pts && w, "out of memory");
    CHECK_OK(fcm__embed_map_tets(ctx, &cell, &f->ws, f->tet_rule, pts, w));
    const int nm = monomials(n, pts, w, m_old);
    CHECK_OK(fcm__embed_material_box(ctx, g, f->tris, &cell, &f->buf, &f->cr, NULL, box, &touched));
    CHECK_OK(fcm__embed_moment_rule(ctx, g, f->tris, &cell, &f->q, NULL, &f->buf, &f->cr, &f->s));
    double m_box[64];
    if (touched) { /* antiderivatives from the material box's lower corner: the same moments */
      CHECK_OK(fcm__embed_moment_rule(ctx, g, f->tris, &cell, &f->q, box, &f->buf, &f->cr, &f->s));
      monomials(f->s.n, f->s.x, f->s.w, m_box);
      CHECK_OK(fcm__embed_moment_rule(ctx, g, f->tris, &cell, &f->q, NULL, &f->buf, &f->cr, &f->s));
    }
    monomials(f->s.n, f->s.x, f->s.w, m_new);
    const double ref = cell.info->shape == FCM_SHAPE_TET ? 1.0 / 6.0 : 8.0;
    for (int k = 0; k < nm; k++) {
      worst = fmax(worst, fabs(m_new[k] - m_old[k]) / ref);
      if (touched) worst = fmax(worst, fabs(m_box[k] - m_old[k]) / ref);
    }
    cut += touched;
    vol += m_new[0] * cell.detA;
  }
  free(pts);
  free(w);
  printf("  %-28s %lld cut cells, worst moment difference %.2e |K|\n", what, (long long)cut, worst);
  CHECK(cut > 0, "%s: no cell is cut", what);
  CHECK(worst <= 1e-12, "%s: surface moments differ from the tets' by %.3e |K|", what, worst);
  return vol;
}

static void run(fcm_ctx *ctx, fcm_element_type type, fcm_geometry *g, const char *what)
{
  fixture f;
  memset(&f, 0, sizeof f);
  const double lo[3] = {-1.05, -0.95, -1.1}, hi[3] = {1.1, 1.0, 0.9};
  const fcm_index n[3] = {5, 4, 6};
  fcm_mesh *mesh = NULL;
  CHECK_OK(fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  CHECK_OK(trees(ctx, g, &f));
  CHECK_OK(fcm_rule_create(ctx, FCM_SHAPE_TET, M_DEG, &f.tet_rule));
  CHECK_OK(fcm__moment_quad_create(ctx, M_DEG, &f.q));
  const double vol = compare(ctx, mesh, g, &f, what);
  CHECK(fabs(vol - g->volume) <= 1e-12 * g->volume, "%s: volume %.16g, geometry's %.16g", what, vol,
        g->volume);
  fcm__moment_quad_free(ctx, &f.q);
  fcm_rule_destroy(&f.tet_rule);
  release(ctx, &f);
  fcm_mesh_destroy(&mesh);
}

/* Point in one of g's tets (barycentric coordinates, no tolerance). */
static int in_tets(const fcm_geometry *g, const double p[3])
{
  for (fcm_index e = 0; e < g->num_cells; e++) {
    const double *x[4];
    for (int a = 0; a < 4; a++)
      x[a] = g->coords + 3 * g->cells[4 * e + a];
    double A[9], r[3];
    for (int i = 0; i < 3; i++) {
      for (int j = 0; j < 3; j++)
        A[3 * i + j] = x[j + 1][i] - x[0][i];
      r[i] = p[i] - x[0][i];
    }
    const double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                       A[2] * (A[3] * A[7] - A[4] * A[6]);
    double l[3];
    for (int k = 0; k < 3; k++) { /* Cramer */
      double B[9];
      memcpy(B, A, sizeof B);
      for (int i = 0; i < 3; i++)
        B[3 * i + k] = r[i];
      l[k] = (B[0] * (B[4] * B[8] - B[5] * B[7]) - B[1] * (B[3] * B[8] - B[5] * B[6]) +
              B[2] * (B[3] * B[7] - B[4] * B[6])) /
             det;
    }
    if (l[0] > 0 && l[1] > 0 && l[2] > 0 && l[0] + l[1] + l[2] < 1) return 1;
  }
  return 0;
}

static void inside_tests(fcm_ctx *ctx, fcm_geometry *ball, fcm_geometry *box)
{
  fixture f;
  memset(&f, 0, sizeof f);
  const double lo[3] = {-1.05, -0.95, -1.1}, hi[3] = {1.1, 1.0, 0.9};
  const fcm_index n[3] = {3, 3, 3};
  fcm_mesh *mesh = NULL;
  CHECK_OK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  CHECK_OK(trees(ctx, ball, &f));
  srand(7);
  int wrong = 0, total = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm__embed_cell cell;
    CHECK_OK(fcm__embed_cell_setup(ctx, mesh, c, 1e-12, &cell));
    for (int k = 0; k < 20; k++) {
      const double a = 2.0 * rand() / RAND_MAX - 1.0, b = 2.0 * rand() / RAND_MAX - 1.0;
      const double z[3] = {2.0 * rand() / RAND_MAX - 1.0, -0.3, 0.8};
      int in[3];
      CHECK_OK(fcm__embed_inside_line(ctx, ball, f.tris, &cell, a, b, 3, z, in, &f.buf, &f.cr));
      for (int i = 0; i < 3; i++) {
        const double xi[3] = {a, b, z[i]};
        double x[3];
        fcm_element_map(FCM_ELEMENT_HEX8, cell.X, xi, x);
        wrong += in[i] != in_tets(ball, x);
        total++;
      }
    }
  }
  CHECK(wrong == 0, "inside test: %d of %d points misclassified", wrong, total);
  release(ctx, &f);
  /* the box [-0.5, 0.5]^3 in a grid of unit cells with corners at +-0.5: lines along faces */
  memset(&f, 0, sizeof f);
  CHECK_OK(trees(ctx, box, &f));
  fcm_mesh_destroy(&mesh);
  const double blo[3] = {-1.5, -1.5, -1.5}, bhi[3] = {1.5, 1.5, 1.5};
  CHECK_OK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, blo, bhi, n, &mesh));
  fcm__embed_cell cell;
  CHECK_OK(fcm__embed_cell_setup(ctx, mesh, 13, 1e-12, &cell)); /* the middle cell */
  const double grid[5] = {-1.0, -0.5, 0.0, 0.5, 1.0};
  for (int i = 0; i < 5; i++)
    for (int j = 0; j < 5; j++) {
      int in[5];
      CHECK_OK(fcm__embed_inside_line(ctx, box, f.tris, &cell, grid[i], grid[j], 5, grid, in,
                                      &f.buf, &f.cr));
      for (int k = 0; k < 5; k++)
        CHECK(in[k] == 0 || in[k] == 1, "box: winding number %d at (%g, %g, %g)", in[k], grid[i],
              grid[j], grid[k]);
      const int strictly = fabs(grid[i]) < 1 && fabs(grid[j]) < 1;
      if (strictly)
        CHECK(in[2] == 1, "box: centre line point (%g, %g, 0) outside", grid[i], grid[j]);
    }
  /* an open surface: move a triangle of the top face to the end and leave it out */
  release(ctx, &f);
  memset(&f, 0, sizeof f);
  fcm_index top = -1;
  for (fcm_index t = 0; t < box->num_tris && top < 0; t++) {
    int up = 1;
    for (int v = 0; v < 3; v++)
      up &= box->coords[3 * box->tris[3 * t + v] + 2] == 0.5;
    if (up) top = t;
  }
  CHECK(top >= 0, "box: no triangle on the top face");
  fcm_index *last = box->tris + 3 * (box->num_tris - 1), keep[3];
  double cen[3] = {0, 0, 0};
  for (int v = 0; v < 3; v++) {
    keep[v] = box->tris[3 * top + v];
    box->tris[3 * top + v] = last[v];
    last[v] = keep[v];
    for (int d = 0; d < 3; d++)
      cen[d] += box->coords[3 * keep[v] + d] / 3.0;
  }
  box->num_tris--;
  CHECK_OK(trees(ctx, box, &f));
  int in;
  const double z0 = 0.0;
  CHECK(fcm__embed_inside_line(ctx, box, f.tris, &cell, cen[0] / 0.5, cen[1] / 0.5, 1, &z0, &in,
                               &f.buf, &f.cr) == FCM_ERR_GEOMETRY,
        "open surface: a line through the hole is not reported");
  box->num_tris++;
  release(ctx, &f);
  fcm_mesh_destroy(&mesh);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_TRUE(fcm_ctx_create(NULL, &ctx) == FCM_OK);
  const double c0[3] = {0.03, -0.02, 0.01};
  fcm_geometry *ball = NULL, *hollow = NULL, *rot = NULL, *box = NULL;
  CHECK_OK(fcm_geometry_create_ball(ctx, c0, 0.8, 4, &ball));
  CHECK_OK(fcm_geometry_create_hollow_ball(ctx, c0, 0.35, 0.85, 0.15, 4, 2, &hollow));
  const double t = 0.4, A[9] = {cos(t),       -sin(t),      0,  sin(t) * 0.6, cos(t) * 0.6, -0.8,
                                sin(t) * 0.8, cos(t) * 0.8, 0.6},
               b[3] = {0.05, 0.0, -0.03};
  CHECK_OK(fcm_geometry_create_transformed(ctx, ball, A, b, &rot));
  /* box faces on grid planes: the Hex8 grid below has planes at x = -1.05 + 0.43 k */
  const double blo[3] = {-1.05 + 0.43, -0.95 + 0.4875, -1.1 + 2.0 / 6.0},
               bhi[3] = {-1.05 + 3 * 0.43, -0.95 + 3 * 0.4875, -1.1 + 5 * 2.0 / 6.0};
  const fcm_index bn[3] = {2, 3, 2};
  CHECK_OK(fcm_geometry_create_box(ctx, blo, bhi, bn, &box));
  const fcm_element_type types[2] = {FCM_ELEMENT_HEX8, FCM_ELEMENT_TET4};
  for (int i = 0; i < 2; i++) {
    printf("%s cells\n", i ? "Tet4" : "Hex8");
    run(ctx, types[i], ball, "ball");
    run(ctx, types[i], hollow, "hollow ball with holes");
    run(ctx, types[i], rot, "rotated ball");
    run(ctx, types[i], box, "box on grid planes");
  }
  { /* the trees: built once per geometry */
    const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    const fcm_index n[3] = {3, 3, 3};
    fcm_mesh *mesh = NULL;
    fcm_cell_rules *r1 = NULL, *r2 = NULL;
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    CHECK_OK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
    CHECK(ball->trees[0] == NULL && ball->trees[1] == NULL, "trees before any rules build");
    CHECK_OK(fcm_cell_rules_create(ctx, mesh, ball, &o, &r1));
    const fcm_aabb_tree *t0 = ball->trees[0], *t1 = ball->trees[1];
    CHECK(t0 && t1, "the first rules build made no trees");
    CHECK_OK(fcm_cell_rules_create(ctx, mesh, ball, &o, &r2));
    CHECK(ball->trees[0] == t0 && ball->trees[1] == t1, "the second rules build made new trees");
    if (r1 && r2) {
      const fcm_cell_rules_stats *s1 = fcm_cell_rules_get_stats(r1),
                                 *s2 = fcm_cell_rules_get_stats(r2);
      CHECK(s1->embedded_volume == s2->embedded_volume && s1->num_cut == s2->num_cut,
            "the rules differ between the builds");
    }
    fcm_cell_rules_destroy(&r1);
    fcm_cell_rules_destroy(&r2);
    fcm_mesh_destroy(&mesh);
  }
  fcm_geometry *ubox = NULL;
  const double ulo[3] = {-0.5, -0.5, -0.5}, uhi[3] = {0.5, 0.5, 0.5};
  const fcm_index un[3] = {2, 2, 2};
  CHECK_OK(fcm_geometry_create_box(ctx, ulo, uhi, un, &ubox));
  inside_tests(ctx, ball, ubox);
  fcm_geometry_destroy(&ubox);
  fcm_geometry_destroy(&ball);
  fcm_geometry_destroy(&hollow);
  fcm_geometry_destroy(&rot);
  fcm_geometry_destroy(&box);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
