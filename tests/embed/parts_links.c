/* The connectivity of the convex parts inside one cell (fcm__embed_parts_components()): the
 * unit Hex8 cell split by cut triangles into parts, whose components are the cell's pieces.
 *   - Four quadrants around the cell's vertical axis, a cut on the plane x = 1/2 below y = 1/2
 *     and one on the plane y = 1/2 right of x = 1/2: the quadrant (x > 1/2, y < 1/2) is cut
 *     off from its two face neighbours and touches the fourth only along the axis (a shared
 *     edge is no link): two pieces, the lone quadrant and the three others.
 *   - A cut across the whole cell on x = 1/2: two pieces; the same plane as two coplanar
 *     triangles sharing an inner edge: two pieces; a cut on the cell's face x = 0: one piece.
 *   - Random cuts (planes through the cell, tilted 1e-12 .. 1e-6 off the cell's and each
 *     other's planes, through its corners, coplanar neighbours, small triangles ending inside
 *     the cell): the components equal those of every pair of touching parts compared face by
 *     face (the definition: parts whose boxes meet share a face of area above 1e-12 h^2 that
 *     does not lie on a cut, or on whose cut triangles both lie on the same side), bit for
 *     bit in their numbering. */
#include "embed/embed_impl.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;
static fcm__embed_cell cell;

/* A triangle list and the parts of the cell split by it (P->tcand: all of them). */
typedef struct scene {
  fcm__cut_tri t[64];
  size_t n;
} scene;

/* The cell: [lo, lo + ext] (coordinates that round, so that planes through the same points in
 * another order differ in their last bits); points are given in the unit cube and mapped. */
static const double cell_lo[3] = {0.13, 0.27, 0.41}, cell_ext[3] = {1.1, 0.9, 1.3};

static void map(const double u[3], double x[3])
{
  for (int d = 0; d < 3; d++)
    x[d] = cell_lo[d] + cell_ext[d] * u[d];
}

static void add_tri(scene *s, const double a[3], const double b[3], const double c[3],
                    const unsigned char inner[3])
{
  static const unsigned char none[3] = {0, 0, 0};
  double x[3][3];
  TEST_TRUE(s->n < 64);
  map(a, x[0]), map(b, x[1]), map(c, x[2]);
  if (fcm__embed_cut_tri_setup(x[0], x[1], x[2], 0, inner ? inner : none, NULL, NULL, s->t + s->n))
    s->n++;
}

/* The parts before the cuts: the cell (mode 0); the six tets around its diagonal from the
 * origin (mode 1); the cell's two halves below and above a tilted plane through its centre,
 * the upper cut off by that plane turned by 1e-13 (mode 2): their shared face lies on two
 * planes that differ in more than their last bits, within the tolerance of each other. */
static int mode;

static void halves(fcm__parts *P, fcm__poly *q)
{
  fcm__poly *w = malloc(sizeof *w);
  TEST_TRUE(w != NULL);
  double c[3], n[3] = {1.0, 0.3, 0.2}, u[3] = {0.5, 0.5, 0.5};
  map(u, c);
  for (int side = 0; side < 2; side++) {
    fcm__plane pl;
    const double t = side ? 1e-13 : 0.0, m[3] = {n[0], n[1] + t, n[2] - t};
    const double len = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]), sg = side ? -1.0 : 1.0;
    for (int d = 0; d < 3; d++)
      pl.n[d] = sg * m[d] / len;
    pl.d = pl.n[0] * c[0] + pl.n[1] * c[1] + pl.n[2] * c[2];
    fcm__geom_poly_from_cell(FCM_ELEMENT_HEX8, cell.X, q);
    TEST_TRUE(fcm__geom_poly_clip(q, &pl, cell.tol, w) == 0 && q->nf > 0);
    TEST_OK(ctx, fcm__embed_parts_put(ctx, P, P->n, q, cell.tol, 0.0, 0));
  }
  free(w);
}

static void split_cell(const scene *s, fcm__parts *P)
{
  static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  fcm__poly *q = malloc(sizeof *q);
  TEST_TRUE(q);
  P->n = 0;
  if (mode == 2) halves(P, q);
  if (mode == 0) {
    fcm__geom_poly_from_cell(FCM_ELEMENT_HEX8, cell.X, q);
    TEST_OK(ctx, fcm__embed_parts_put(ctx, P, 0, q, cell.tol, 0.0, 0));
  }
  for (int t = 0; mode == 1 && t < 6; t++) {
    double X[12] = {0};
    for (int k = 1; k < 4; k++) {
      memcpy(X + 3 * k, X + 3 * (k - 1), 3 * sizeof *X);
      if (k < 3)
        X[3 * k + perm[t][k - 1]] = 1.0;
      else
        X[3 * k] = X[3 * k + 1] = X[3 * k + 2] = 1.0;
    }
    if (t == 1 || t == 2 || t == 5) { /* odd permutations: swap two corners (positive volume) */
      double w[3];
      memcpy(w, X + 3, sizeof w), memcpy(X + 3, X + 6, sizeof w), memcpy(X + 6, w, sizeof w);
    }
    for (int k = 0; k < 4; k++)
      map(X + 3 * k, X + 3 * k);
    fcm__geom_poly_from_cell(FCM_ELEMENT_TET4, X, q);
    TEST_TRUE(fcm__geom_poly_volume(q) > 0.16 * cell_ext[0] * cell_ext[1] * cell_ext[2]);
    TEST_OK(ctx, fcm__embed_parts_put(ctx, P, P->n, q, cell.tol, 0.0, 0));
  }
  free(q);
  P->tcand.n = 0;
  for (size_t k = 0; k < s->n; k++) {
    TEST_OK(ctx, fcm__embed_parts_split(ctx, &cell, s->t + k, P));
    if (P->tcand.n == P->tcand.cap) {
      P->tcand.cap = P->tcand.cap ? 2 * P->tcand.cap : 64;
      P->tcand.ids = realloc(P->tcand.ids, P->tcand.cap * sizeof *P->tcand.ids);
      TEST_TRUE(P->tcand.ids);
    }
    P->tcand.ids[P->tcand.n++] = (fcm_index)k;
  }
}

static int find(int *uf, int a)
{
  while (uf[a] != a)
    a = uf[a];
  return a;
}

/* The definition: every pair of parts whose boxes (widened by the tolerance) meet, every pair
 * of their faces facing each other (normals at more than 120 degrees), each face's vertices
 * within the tolerance of the other's plane, linked as fcm__embed_linked() says. */
static int reference(const scene *s, const fcm__parts *P, int *label)
{
  const double mtol = FCM__EMBED_MATCH_RTOL * cell.size, atol = 1e-12 * cell.size * cell.size;
  int *uf = malloc((P->n + 1) * sizeof *uf), np = 0;
  double xa[3 * FCM__POLY_MAX_FV], xb[3 * FCM__POLY_MAX_FV];
  TEST_TRUE(uf);
  for (size_t i = 0; i < P->n; i++)
    uf[i] = (int)i;
  for (size_t i = 0; i < P->n; i++)
    for (size_t j = i + 1; j < P->n; j++) {
      const fcm__poly *a = P->poly + i, *b = P->poly + j;
      double lo[2][3], hi[2][3];
      for (int w = 0; w < 2; w++) {
        const fcm__poly *p = w ? b : a;
        for (int d = 0; d < 3; d++)
          lo[w][d] = HUGE_VAL, hi[w][d] = -HUGE_VAL;
        for (int v = 0; v < p->nv; v++)
          for (int d = 0; d < 3; d++) {
            lo[w][d] = fmin(lo[w][d], p->x[v][d] - mtol);
            hi[w][d] = fmax(hi[w][d], p->x[v][d] + mtol);
          }
      }
      int apart = 0, linked = 0;
      for (int d = 0; d < 3; d++)
        apart |= lo[0][d] > hi[1][d] || lo[1][d] > hi[0][d];
      for (int fa = 0; fa < a->nf && !apart && !linked; fa++)
        for (int fb = 0; fb < b->nf && !linked; fb++) {
          fcm__plane pa, pb;
          if (!fcm__embed_face_plane(a, fa, &pa) || !fcm__embed_face_plane(b, fb, &pb)) continue;
          if (pa.n[0] * pb.n[0] + pa.n[1] * pb.n[1] + pa.n[2] * pb.n[2] > -0.5) continue;
          const int na = fcm__embed_face_coords(a, fa, xa), nb = fcm__embed_face_coords(b, fb, xb);
          int on = 1;
          for (int k = 0; k < na && on; k++)
            on = fabs(pb.n[0] * xa[3 * k] + pb.n[1] * xa[3 * k + 1] + pb.n[2] * xa[3 * k + 2] -
                      pb.d) <= mtol;
          for (int k = 0; k < nb && on; k++)
            on = fabs(pa.n[0] * xb[3 * k] + pa.n[1] * xb[3 * k + 1] + pa.n[2] * xb[3 * k + 2] -
                      pa.d) <= mtol;
          linked = on && fcm__embed_linked(xa, na, a->x[0], a->nv, xb, nb, b->x[0], b->nv, pb.n,
                                           mtol, atol, s->t, P->tcand.ids, P->tcand.n);
        }
      if (linked) {
        const int ri = find(uf, (int)i), rj = find(uf, (int)j);
        uf[ri > rj ? ri : rj] = ri < rj ? ri : rj;
      }
    }
  for (size_t i = 0; i < P->n; i++) {
    const int r = find(uf, (int)i);
    label[i] = r == (int)i ? np++ : label[r];
  }
  free(uf);
  return np;
}

/* The library's components of s's parts, checked against the definition; returns their count. */
static int components(const scene *s, fcm__parts *P)
{
  split_cell(s, P);
  int *got = malloc((P->n + 1) * sizeof *got), *want = malloc((P->n + 1) * sizeof *want), n = 0;
  TEST_TRUE(got && want);
  TEST_OK(ctx, fcm__embed_parts_components(ctx, &cell, s->t, s->n, P, got, &n));
  const int m = reference(s, P, want);
  if (n != m) TEST_FAIL_("%d components, the pairwise definition gives %d (%zu parts)", n, m, P->n);
  for (size_t i = 0; i < P->n; i++)
    if (got[i] != want[i])
      TEST_FAIL_("part %zu in component %d, the definition's %d", i, got[i], want[i]);
  free(got);
  free(want);
  return n;
}

static void set3(double *x, double a, double b, double c)
{
  x[0] = a, x[1] = b, x[2] = c;
}

static void explicit_cases(fcm__parts *P)
{
  double a[3], b[3], c[3], d[3];
  scene s = {.n = 0};
  /* x = 1/2 for y < 1/2 (an edge along y = 1/2) and y = 1/2 for x > 1/2 (an edge along x = 1/2) */
  set3(a, 0.5, 0.5, -10), set3(b, 0.5, 0.5, 10), set3(c, 0.5, -10, 0);
  add_tri(&s, a, b, c, NULL);
  set3(c, 10, 0.5, 0);
  add_tri(&s, a, b, c, NULL);
  TEST_TRUE(components(&s, P) == 2);
  TEST_TRUE(P->n == 4);
  for (size_t i = 0; i < P->n; i++) { /* the lone part is the quadrant x > 1/2, y < 1/2 */
    double ctr[3] = {0, 0, 0};
    for (int v = 0; v < P->poly[i].nv; v++)
      for (int k = 0; k < 3; k++)
        ctr[k] += (P->poly[i].x[v][k] - cell_lo[k]) / cell_ext[k] / P->poly[i].nv;
    int *label = malloc(P->n * sizeof *label), n;
    TEST_OK(ctx, fcm__embed_parts_components(ctx, &cell, s.t, s.n, P, label, &n));
    int alone = 1;
    for (size_t j = 0; j < P->n; j++)
      alone &= j == i || label[j] != label[i];
    TEST_TRUE(alone == (ctr[0] > 0.5 && ctr[1] < 0.5));
    free(label);
  }
  /* the whole cell cut on x = 1/2: one triangle; two coplanar ones sharing an inner edge */
  s.n = 0;
  set3(a, 0.5, -10, -10), set3(b, 0.5, 10, -10), set3(c, 0.5, 0, 10);
  add_tri(&s, a, b, c, NULL);
  TEST_TRUE(components(&s, P) == 2);
  s.n = 0;
  set3(a, 0.5, -3, -3), set3(b, 0.5, 4, -3), set3(c, 0.5, 4, 4), set3(d, 0.5, -3, 4);
  const unsigned char in0[3] = {0, 0, 1}, in1[3] = {1, 0, 0}; /* edges a-c and c-a */
  add_tri(&s, a, b, c, in0);
  add_tri(&s, c, d, a, in1);
  TEST_TRUE(components(&s, P) == 2);
  /* on the cell's face x = 0: nothing to separate */
  s.n = 0;
  set3(a, 0, -10, -10), set3(b, 0, 10, -10), set3(c, 0, 0, 10);
  add_tri(&s, a, b, c, NULL);
  TEST_TRUE(components(&s, P) == 1);
}

static double urand(unsigned *state)
{
  *state = *state * 1103515245u + 12345u;
  return (double)((*state >> 8) & 0xffffff) / 16777216.0;
}

/* A random triangle on a plane through point p with normal n: large (across the cell), or
 * small (ending inside it); tilt: how far off n the triangle's plane turns. */
static void random_tri(scene *s, const double p[3], const double n[3], double tilt, int small,
                       unsigned *st)
{
  double u[3], v[3], m[3], x[3][3];
  for (int d = 0; d < 3; d++)
    m[d] = n[d] + tilt * (2.0 * urand(st) - 1.0);
  const double a = fabs(m[0]) < 0.6 ? 1.0 : 0.0;
  const double e[3] = {a, 1.0 - a, 0.0};
  u[0] = m[1] * e[2] - m[2] * e[1], u[1] = m[2] * e[0] - m[0] * e[2],
  u[2] = m[0] * e[1] - m[1] * e[0];
  v[0] = m[1] * u[2] - m[2] * u[1], v[1] = m[2] * u[0] - m[0] * u[2],
  v[2] = m[0] * u[1] - m[1] * u[0];
  const double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  const double lv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  const double r = small ? 0.2 + 0.5 * urand(st) : 4.0, ph = 6.283185307179586 * urand(st);
  for (int k = 0; k < 3; k++) {
    const double t = ph + 2.0943951023931957 * k;
    for (int d = 0; d < 3; d++)
      x[k][d] = p[d] + r * (cos(t) * u[d] / lu + sin(t) * v[d] / lv);
  }
  add_tri(s, x[0], x[1], x[2], NULL);
}

static void random_cases(fcm__parts *P, int ncases)
{
  unsigned st = 12345u;
  static const double axes[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  static const double tilts[4] = {0.0, 1e-12, 1e-9, 1e-6};
  int pieces = 0;
  for (int c = 0; c < ncases; c++) {
    scene s = {.n = 0};
    const int ntri = 1 + (int)(urand(&st) * 5);
    for (int k = 0; k < ntri; k++) {
      double p[3], n[3];
      const int kind = (int)(urand(&st) * 4);
      for (int d = 0; d < 3; d++) /* on the grid of halves and quarters, or anywhere */
        p[d] = kind < 2 ? 0.25 * (int)(urand(&st) * 5) : urand(&st);
      const int ax = (int)(urand(&st) * 3);
      for (int d = 0; d < 3; d++)
        n[d] = kind == 3 ? 2.0 * urand(&st) - 1.0 : axes[ax][d];
      random_tri(&s, p, n, tilts[(int)(urand(&st) * 4)], urand(&st) < 0.4, &st);
      if (urand(&st) < 0.2 && s.n > 0 && s.n < 63) { /* a coplanar neighbour across an edge */
        const fcm__cut_tri *t = s.t + s.n - 1;
        double u[3][3];
        for (int v = 0; v < 3; v++)
          for (int d = 0; d < 3; d++)
            u[v][d] = (t->x[v][d] - cell_lo[d]) / cell_ext[d];
        for (int d = 0; d < 3; d++)
          u[2][d] = u[0][d] + u[1][d] - u[2][d];
        add_tri(&s, u[1], u[0], u[2], NULL);
      }
    }
    pieces += components(&s, P);
  }
  if (getenv("FCM_TEST_VERBOSE")) printf("%d random cases, %d pieces in all\n", ncases, pieces);
  TEST_TRUE(pieces > ncases); /* the cuts do separate */
}

int main(int argc, char **argv)
{
  const int ncases = argc > 1 ? atoi(argv[1]) : 400;
  fcm_mesh *mesh = NULL;
  const double lo[3] = {cell_lo[0], cell_lo[1], cell_lo[2]},
               hi[3] = {cell_lo[0] + cell_ext[0], cell_lo[1] + cell_ext[1],
                        cell_lo[2] + cell_ext[2]};
  const fcm_index n[3] = {1, 1, 1};
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm__embed_cell_setup(ctx, mesh, 0, 1e-10, &cell));
  fcm__parts *P = calloc(1, sizeof *P);
  TEST_TRUE(P);
  explicit_cases(P);
  random_cases(P, ncases);
  for (mode = 1; mode <= 2; mode++) {
    scene none = {.n = 0};
    TEST_TRUE(components(&none, P) == 1); /* the parts join through their shared faces */
    random_cases(P, ncases);
  }
  free(P->tcand.ids);
  P->tcand.ids = NULL;
  P->tcand.cap = 0;
  fcm__embed_parts_free(ctx, P);
  free(P);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
