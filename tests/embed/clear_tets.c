/* The material rule of a convex part from the surface moments of its fan tets
 * (fcm__material_poly): a tet that no boundary triangle comes near (fcm__embed_cell_clear)
 * takes the winding number found for the first such tet of its fan (they share the apex)
 * instead of a line query of its own (fcm__embed_moment_rule_clear), and a tet near it takes
 * its corner's from a clear box kept from earlier tests (fcm__embed_moment_rule_kept). Parts: every
 * cell of a Hex8 grid over a ball and over a hollow ball with holes, whole and cut into two by an
 * oblique plane. Asserts
 * - per part: the rule (points, weights, in the cell's reference coordinates) and the volume
 *   are the bits of the reference path, fcm__embed_moment_rule() on every fan tet; but a part
 *   that is a box of the cell's reference coordinates (the whole cells) is one Hex8 cell of
 *   its own: its monomial moments up to the degree within 1e-12 of the reference cell's volume
 *   of the reference's (both kinds of parts occur);
 * - per whole cell: the volume equals the cell's own surface moments (fcm__material_cell)
 *   within 1e-12 of the cell's volume, and the two halves of a cut cell add up to it;
 * - the shortcut is taken (more than a fifth of the tets are clear) and not everywhere (some
 *   tets are near the boundary), so both paths are exercised;
 * - the inside test of single points (fcm__embed_inside_line) with a scratch that keeps clear
 *   boxes answers as with a fresh scratch each time, on points of every part's fan tets (as a
 *   fit's candidates), and takes a kept box's answer for more than half of them. */
#include "embed/embed_impl.h"
#include "element/element_impl.h"
#include "la/mat3.h"
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

enum { DEGREE = 3 };

/* Tet T (12 doubles) as an affine Tet4 cell, as surface_parts.c makes its fan tets. */
static void tet_cell(const double *T, fcm_index id, fcm__embed_cell *k)
{
  memset(k, 0, sizeof *k);
  k->type = FCM_ELEMENT_TET4;
  k->info = fcm_element_get_info(FCM_ELEMENT_TET4);
  k->id = id;
  memcpy(k->X, T, 12 * sizeof *T);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      k->A[3 * i + j] = T[3 * (j + 1) + i] - T[i];
  k->detA = fcm__mat3_inv(k->A, k->Ainv);
  k->affine = 1;
  k->size = fcm__element_cell_size(4, T);
  k->volume = fabs(k->detA) / 6.0;
  for (int d = 0; d < 3; d++) {
    k->lo[d] = HUGE_VAL, k->hi[d] = -HUGE_VAL;
    for (int a = 0; a < 4; a++)
      k->lo[d] = fmin(k->lo[d], T[3 * a + d]), k->hi[d] = fmax(k->hi[d], T[3 * a + d]);
  }
}

typedef struct tally {
  long tets, clear, parts, boxes;
  double worst_box; /* box parts: the moments' largest difference / |reference cell| */
  double worst;     /* whole cells: |material_poly - material_cell| / |K| */
} tally;

/* The reference: every fan tet's own moment rule, mapped to the cell as fcm__material_poly
 * maps it; the volume into *volume. Counts the clear tets. */
static void reference(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                      const fcm__poly *p, const fcm__moment_quad *q, const fcm__embed_cell *cell,
                      fcm__srule *out, double *volume, tally *t)
{
  static double tets[12 * FCM__POLY_MAX_FACES * FCM__POLY_MAX_FV];
  static double vol[FCM__POLY_MAX_FACES * FCM__POLY_MAX_FV];
  fcm__idbuf buf = {NULL, 0, 0};
  fcm__crossings cr;
  fcm__srule s = {NULL, NULL, 0, 0};
  double sum = 0.0;
  memset(&cr, 0, sizeof cr);
  out->n = 0;
  const int nt = p->nf ? fcm__geom_poly_tets(p, tets, vol) : 0;
  for (int i = 0; i < nt; i++) {
    if (vol[i] == 0.0) continue;
    fcm__embed_cell k;
    tet_cell(tets + 12 * i, cell->id, &k);
    if (!(fabs(k.detA) > 1e-12 * k.size * k.size * k.size && isfinite(k.detA))) continue;
    int clear;
    CHECK_OK(fcm__embed_cell_clear(ctx, g, tree, &k, &buf, &clear));
    t->tets++;
    t->clear += clear;
    CHECK_OK(fcm__embed_moment_rule(ctx, g, tree, &k, q, NULL, &buf, &cr, &s));
    CHECK_OK(fcm__srule_room(ctx, out, s.n));
    for (size_t j = 0; j < s.n; j++) {
      const double w = s.w[j] * k.detA;
      double x[3], det;
      sum += w;
      fcm__mat3_mulv(k.A, s.x + 3 * j, x);
      for (int d = 0; d < 3; d++)
        x[d] += k.X[d];
      CHECK_OK(fcm__embed_to_reference(ctx, cell, x, out->x + 3 * out->n, &det));
      out->w[out->n++] = w / det;
    }
  }
  *volume = sum;
  fcm__geom_idbuf_free(ctx, &buf);
  fcm__crossings_free(ctx, &cr);
  fcm__srule_free(ctx, &s);
}

/* Inside tests of points spread over the fan tets of p (cell's reference coordinates), with
 * the kept scratch cr against a fresh one each time. */
static void inside_points(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                          const fcm__poly *p, const fcm__embed_cell *cell, fcm__crossings *cr,
                          long *points, long *kept, const char *what)
{
  static double tets[12 * FCM__POLY_MAX_FACES * FCM__POLY_MAX_FV];
  static double vol[FCM__POLY_MAX_FACES * FCM__POLY_MAX_FV];
  static const double bary[5][4] = {{0.25, 0.25, 0.25, 0.25},
                                    {0.55, 0.15, 0.15, 0.15},
                                    {0.15, 0.55, 0.15, 0.15},
                                    {0.15, 0.15, 0.55, 0.15},
                                    {0.15, 0.15, 0.15, 0.55}};
  fcm__idbuf buf = {NULL, 0, 0};
  const int nt = p->nf ? fcm__geom_poly_tets(p, tets, vol) : 0;
  for (int i = 0; i < nt; i++)
    for (int j = 0; j < 5; j++) {
      double x[3] = {0, 0, 0}, xi[3], det;
      for (int a = 0; a < 4; a++)
        for (int d = 0; d < 3; d++)
          x[d] += bary[j][a] * tets[12 * i + 3 * a + d];
      int in_box = 0, in_kept = -1, in_fresh = -2;
      for (int k = 0; k < cr->nclear && cr->tree == tree; k++) {
        const fcm__clear_box *c = cr->clear + k;
        in_box |= c->lo[0] <= x[0] && x[0] <= c->hi[0] && c->lo[1] <= x[1] && x[1] <= c->hi[1] &&
                  c->lo[2] <= x[2] && x[2] <= c->hi[2];
      }
      fcm__crossings fresh;
      memset(&fresh, 0, sizeof fresh);
      CHECK_OK(fcm__embed_to_reference(ctx, cell, x, xi, &det));
      CHECK_OK(
          fcm__embed_inside_line(ctx, g, tree, cell, xi[0], xi[1], 1, xi + 2, &in_kept, &buf, cr));
      CHECK_OK(fcm__embed_inside_line(ctx, g, tree, cell, xi[0], xi[1], 1, xi + 2, &in_fresh, &buf,
                                      &fresh));
      fcm__crossings_free(ctx, &fresh);
      CHECK(in_kept == in_fresh, "%s, cell %lld: inside test %d with kept boxes, %d without", what,
            (long long)cell->id, in_kept, in_fresh);
      ++*points;
      *kept += in_box;
    }
  fcm__geom_idbuf_free(ctx, &buf);
}

/* The largest difference of the monomial moments xi^a eta^b zeta^c (a + b + c <= DEGREE) of
 * two signed rules. */
static double moment_error(const fcm__srule *a, const fcm__srule *b)
{
  double worst = 0.0;
  for (int i = 0; i <= DEGREE; i++)
    for (int j = 0; i + j <= DEGREE; j++)
      for (int k = 0; i + j + k <= DEGREE; k++) {
        double ma = 0.0, mb = 0.0;
        for (size_t n = 0; n < a->n; n++)
          ma += a->w[n] * pow(a->x[3 * n], i) * pow(a->x[3 * n + 1], j) * pow(a->x[3 * n + 2], k);
        for (size_t n = 0; n < b->n; n++)
          mb += b->w[n] * pow(b->x[3 * n], i) * pow(b->x[3 * n + 1], j) * pow(b->x[3 * n + 2], k);
        worst = fmax(worst, fabs(ma - mb));
      }
  return worst;
}

/* Part p of cell: fcm__material_poly against the reference, bit for bit; a part that is a box
 * of the cell's reference coordinates (a whole cell here) takes it as one Hex8 cell: its
 * moments within 1e-12 of the reference cell's volume. */
static double compare_part(fcm_ctx *ctx, fcm__material *m, const fcm_geometry *g,
                           const fcm_aabb_tree *tree, const fcm__poly *p, const fcm__moment_quad *q,
                           const fcm__embed_cell *cell, fcm__srule *a, fcm__srule *b, tally *t,
                           const char *what)
{
  double va = 0.0, vb = 0.0;
  a->n = 0;
  double lo[3], hi[3];
  int box;
  CHECK_OK(fcm__material_poly(ctx, m, p, q, cell, a, &va));
  reference(ctx, g, tree, p, q, cell, b, &vb, t);
  t->parts++;
  CHECK_OK(fcm__embed_part_box(ctx, cell, p, lo, hi, &box));
  if (box) { /* one Hex8 cell's moment rule on the box: the same moments, other rounding */
    t->boxes++;
    t->worst_box = fmax(t->worst_box, moment_error(a, b) / 8.0);
    CHECK(fabs(va - vb) <= 1e-12 * cell->volume, "%s, cell %lld: box volume %.17g, fan %.17g", what,
          (long long)cell->id, va, vb);
    return va;
  }
  CHECK(a->n == b->n, "%s, cell %lld: %zu rule points, the reference %zu", what,
        (long long)cell->id, a->n, b->n);
  CHECK(memcmp(&va, &vb, sizeof va) == 0, "%s, cell %lld: volume %.17g, the reference %.17g", what,
        (long long)cell->id, va, vb);
  if (a->n == b->n && a->n > 0) {
    CHECK(!memcmp(a->x, b->x, 3 * a->n * sizeof *a->x), "%s, cell %lld: rule points differ", what,
          (long long)cell->id);
    CHECK(!memcmp(a->w, b->w, a->n * sizeof *a->w), "%s, cell %lld: rule weights differ", what,
          (long long)cell->id);
  }
  return va;
}

static void run(fcm_ctx *ctx, const fcm_geometry *g, const char *what)
{
  const double lo[3] = {-1.05, -0.95, -1.1}, hi[3] = {1.0, 1.0, 0.9};
  const fcm_index n[3] = {5, 6, 5};
  fcm_mesh *mesh = NULL;
  fcm__material *m = NULL;
  fcm__moment_quad q;
  fcm__srule a = {NULL, NULL, 0, 0}, b = {NULL, NULL, 0, 0};
  fcm__crossings cr;
  long points = 0, kept = 0;
  fcm_aabb_tree *tree = NULL;
  double *boxes = NULL;
  fcm_index nb;
  tally t = {0, 0, 0, 0, 0.0, 0.0};
  memset(&q, 0, sizeof q);
  memset(&cr, 0, sizeof cr);
  CHECK_OK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  CHECK_OK(fcm__material_create(ctx, g, &m));
  CHECK_OK(fcm__moment_quad_create(ctx, DEGREE, &q));
  CHECK_OK(fcm__geom_boxes(ctx, g, 1, &boxes, &nb));
  CHECK_OK(fcm_aabb_tree_create(ctx, nb, boxes, &tree));
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm__embed_cell cell;
    double X[3 * 8], vcell = 0.0;
    static fcm__poly p, half, scratch;
    CHECK_OK(fcm__embed_cell_setup(ctx, mesh, c, 1e-12, &cell));
    fcm_mesh_cell_coords(mesh, c, X);
    fcm__geom_poly_from_cell(FCM_ELEMENT_HEX8, X, &p);
    const double whole = compare_part(ctx, m, g, tree, &p, &q, &cell, &a, &b, &t, what);
    CHECK_OK(fcm__material_cell(ctx, m, NULL, &cell, NULL, &vcell));
    const double err = fabs(whole - vcell) / cell.volume;
    t.worst = fmax(t.worst, err);
    /* two halves by an oblique plane through the cell's centre */
    double ctr[3] = {0, 0, 0};
    for (int i = 0; i < 8; i++)
      for (int d = 0; d < 3; d++)
        ctr[d] += X[3 * i + d] / 8.0;
    const double nrm[3] = {0.48, -0.6, 0.64};
    double halves = 0.0;
    for (int side = 0; side < 2; side++) {
      fcm__plane pl;
      const double sg = side ? -1.0 : 1.0;
      for (int d = 0; d < 3; d++)
        pl.n[d] = sg * nrm[d];
      pl.d = sg * (nrm[0] * ctr[0] + nrm[1] * ctr[1] + nrm[2] * ctr[2]);
      half = p;
      CHECK(fcm__geom_poly_clip(&half, &pl, 1e-12 * cell.size, &scratch) == 0,
            "%s, cell %lld: clipping failed", what, (long long)c);
      halves += compare_part(ctx, m, g, tree, &half, &q, &cell, &a, &b, &t, what);
      inside_points(ctx, g, tree, &half, &cell, &cr, &points, &kept, what);
    }
    t.worst = fmax(t.worst, fabs(halves - vcell) / cell.volume);
  }
  printf("  %-24s %ld parts, %ld fan tets, %ld clear (%.0f %%), worst volume difference %.2e "
         "|K|\n",
         what, t.parts, t.tets, t.clear, 100.0 * (double)t.clear / (double)(t.tets ? t.tets : 1),
         t.worst);
  printf("  %-24s %ld box parts, moments within %.2e of the fan's\n", "", t.boxes, t.worst_box);
  CHECK(t.boxes > 0 && t.boxes < t.parts, "%s: %ld of %ld parts are boxes", what, t.boxes, t.parts);
  CHECK(t.worst_box <= 1e-12, "%s: box parts' moments off by %.3e", what, t.worst_box);
  CHECK(t.worst <= 1e-12, "%s: the parts' volumes differ from the cells' by %.3e |K|", what,
        t.worst);
  CHECK(5 * t.clear > t.tets, "%s: only %ld of %ld tets clear: the shortcut is not exercised", what,
        t.clear, t.tets);
  CHECK(t.clear < t.tets, "%s: every tet clear: the reference path is not exercised", what);
  printf("  %-24s %ld inside tests, %ld in a kept clear box\n", "", points, kept);
  CHECK(2 * kept > points, "%s: %ld of %ld points in a kept box: the shortcut is not exercised",
        what, kept, points);
  CHECK(kept < points, "%s: every point in a kept box", what);
  fcm__crossings_free(ctx, &cr);
  fcm__srule_free(ctx, &a);
  fcm__srule_free(ctx, &b);
  fcm__moment_quad_free(ctx, &q);
  fcm__material_destroy(ctx, &m);
  fcm_aabb_tree_destroy(&tree);
  fcm__free(ctx, boxes);
  fcm_mesh_destroy(&mesh);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_TRUE(fcm_ctx_create(NULL, &ctx) == FCM_OK);
  const double c0[3] = {0.03, -0.02, 0.01};
  fcm_geometry *ball = NULL, *hollow = NULL;
  CHECK_OK(fcm_geometry_create_ball(ctx, c0, 0.8, 4, &ball));
  CHECK_OK(fcm_geometry_create_hollow_ball(ctx, c0, 0.35, 0.85, 0.15, 4, 2, &hollow));
  run(ctx, ball, "ball");
  run(ctx, hollow, "hollow ball with holes");
  fcm_geometry_destroy(&ball);
  fcm_geometry_destroy(&hollow);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
