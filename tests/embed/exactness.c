/* Cut-cell rules are exact: for random rotated and translated convex polyhedra (boxes as
 * one hex8 cell or as 6 tets, random tets, frusta) cut by a 2x2x2 background grid of Hex8
 * or Tet4 cells, every monomial of degree <= m (m = 1..10) integrates over K ∩ P to the
 * value of an independent exact formula (tests/geom/exact.h), per cell. Argument "initial"
 * (no simplification) or "simplified" (then also: count <= M, weights > 0, every point
 * inside the geometry and the cell). "simplified" is the quick run: each shape at a quarter
 * of the strengths m <= 8, mass rules at strength 1; "simplified-full" (label slow) checks
 * every shape at every m = 1..10 for both kinds.
 * Usage: embed_exactness hex|tet initial|simplified|simplified-full [verbose] */
#include "fcm/embed.h"
#include "../geom/exact.h"
#include "test.h"

#define NTRIAL       2
#define MMAX         10
#define REDUCED_MMAX 8

static fcm_ctx *ctx;
static int simplified;
static double worst_err;
static int verbose;
static int reduced;

/* Geometry under test: its cells' outward planes for the exact integrals. */
typedef struct shape {
  fcm_geometry *g;
  int ncell;
  exact_plane pl[8][6];
  int npl[8];
} shape;

static void tet_shape(shape *s, unsigned long long *rng)
{
  double v[4][3];
  for (int a = 0; a < 4; a++)
    for (int d = 0; d < 3; d++)
      v[a][d] = 1.6 * exact_rand(rng) - 0.8;
  const fcm_index cells[4] = {0, 1, 2, 3};
  TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, &v[0][0], 1, cells, &s->g));
  s->ncell = 1;
  s->npl[0] = 4;
  exact_tet_planes(v, s->pl[0]);
}

/* Rotated box R [lo, hi] + t, as one hex8 (as_hex) or as the 6-tet Kuhn split. */
static void box_shape(shape *s, unsigned long long *rng, int as_hex)
{
  double R[9], t[3], lo[3], hi[3];
  exact_rotation(exact_rand(rng), exact_rand(rng), exact_rand(rng), R);
  for (int d = 0; d < 3; d++) {
    const double h = 0.3 + 0.6 * exact_rand(rng);
    lo[d] = -h, hi[d] = h;
    t[d] = exact_rand(rng) - 0.5;
  }
  fcm_geometry *unit = NULL;
  if (as_hex) {
    double X[24];
    static const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                     {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (int a = 0; a < 8; a++)
      for (int d = 0; d < 3; d++)
        X[3 * a + d] = corner[a][d] ? hi[d] : lo[d];
    const fcm_index cells[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_HEX8, 8, X, 1, cells, &unit));
  } else {
    const fcm_index n[3] = {1, 1, 1};
    TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n, &unit));
  }
  TEST_OK(ctx, fcm_geometry_create_transformed(ctx, unit, R, t, &s->g));
  fcm_geometry_destroy(&unit);
  /* The box as one polytope: the sum over its tets equals the integral over the box. */
  s->ncell = 1;
  s->npl[0] = 6;
  exact_box_planes(R, t, lo, hi, s->pl[0]);
}

/* A frustum: square base of half-width b at z = -h, top half-width a at z = +h (planar
 * faces, convex, not a parallelepiped), rotated and translated. */
static void frustum_shape(shape *s, unsigned long long *rng)
{
  double R[9], t[3], X[24], Y[24];
  exact_rotation(exact_rand(rng), exact_rand(rng), exact_rand(rng), R);
  for (int d = 0; d < 3; d++)
    t[d] = 0.6 * exact_rand(rng) - 0.3;
  const double b = 0.5 + 0.3 * exact_rand(rng), a = 0.2 + 0.2 * exact_rand(rng), h = 0.6;
  static const int sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int k = 0; k < 4; k++) {
    X[3 * k] = sx[k] * b, X[3 * k + 1] = sy[k] * b, X[3 * k + 2] = -h;
    X[3 * (k + 4)] = sx[k] * a, X[3 * (k + 4) + 1] = sy[k] * a, X[3 * (k + 4) + 2] = h;
  }
  for (int p = 0; p < 8; p++)
    for (int i = 0; i < 3; i++)
      Y[3 * p + i] =
          R[3 * i] * X[3 * p] + R[3 * i + 1] * X[3 * p + 1] + R[3 * i + 2] * X[3 * p + 2] + t[i];
  const fcm_index cells[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_HEX8, 8, Y, 1, cells, &s->g));
  /* Planes in the local frame, then rotated: bottom, top, 4 slanted sides. */
  const double slope = (b - a) / (2 * h); /* side: |x| <= b - slope (z + h) */
  double ln[6][3] = {{0, 0, -1},     {0, 0, 1},     {1, 0, slope},
                     {-1, 0, slope}, {0, 1, slope}, {0, -1, slope}};
  double ld[6] = {h, h, b - slope * h, b - slope * h, b - slope * h, b - slope * h};
  for (int f = 0; f < 6; f++) {
    double n[3];
    for (int i = 0; i < 3; i++)
      n[i] = R[3 * i] * ln[f][0] + R[3 * i + 1] * ln[f][1] + R[3 * i + 2] * ln[f][2];
    s->pl[0][f].n[0] = n[0], s->pl[0][f].n[1] = n[1], s->pl[0][f].n[2] = n[2];
    s->pl[0][f].d = ld[f] + n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
  }
  s->ncell = 1;
  s->npl[0] = 6;
}

/* Outward planes of background cell c from its corners (independent of the library). */
static int cell_planes(fcm_element_type type, const double *X, exact_plane *pl)
{
  if (type == FCM_ELEMENT_TET4) {
    double v[4][3];
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        v[a][d] = X[3 * a + d];
    exact_tet_planes(v, pl);
    return 4;
  }
  /* Axis-aligned hex from the box generator: corners 0 (lo) and 6 (hi). */
  for (int d = 0; d < 3; d++) {
    for (int i = 0; i < 3; i++)
      pl[2 * d].n[i] = i == d, pl[2 * d + 1].n[i] = -(i == d);
    pl[2 * d].d = X[18 + d];
    pl[2 * d + 1].d = -X[d];
  }
  return 6;
}

static int inside_planes(const exact_plane *pl, int np, const double x[3], double tol)
{
  for (int i = 0; i < np; i++)
    if (pl[i].n[0] * x[0] + pl[i].n[1] * x[1] + pl[i].n[2] * x[2] - pl[i].d > tol) return 0;
  return 1;
}

/* Strengths to check for shape number `which`: all, or (reduced runs of the simplified
 * rules, whose LPs dominate the time) only m = which (mod 4) + 4 k <= REDUCED_MMAX. */
static int check_strength(int m, int which)
{
  return !reduced || (m % 4 == which % 4 && m <= REDUCED_MMAX);
}

static void check_shape(const fcm_mesh *mesh, shape *s, int which)
{
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  const int nmono = exact_num_mono(MMAX);
  double X[24], J[9], x[3], vals[EXACT_MAX_MONO];
  static double exact[64][EXACT_MAX_MONO], kvol[64];
  exact_plane pl[14];
  /* Exact integrals per background cell, once for all strengths. */
  for (fcm_index c = 0; c < nc; c++) {
    fcm_mesh_cell_coords(mesh, c, X);
    memset(exact[c], 0, sizeof exact[c]);
    const int nk = cell_planes(type, X, pl);
    double kv[EXACT_MAX_MONO] = {0};
    exact_polytope_add(pl, nk, 0, 1e-13, kv);
    kvol[c] = kv[0];
    for (int e = 0; e < s->ncell; e++) {
      memcpy(pl + nk, s->pl[e], (size_t)s->npl[e] * sizeof pl[0]);
      exact_polytope_add(pl, nk + s->npl[e], MMAX, 1e-13, exact[c]);
    }
  }
  for (int m = 1; m <= MMAX; m++) {
    if (!check_strength(m, which)) continue;
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.strength[FCM_RULE_STIFFNESS] = m;
    o.strength[FCM_RULE_MASS] = reduced ? 1 : m;
    o.simplify = simplified;
    o.stabilization.mode = FCM_STABILIZATION_OFF;
    fcm_cell_rules *r = NULL;
    TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, s->g, &o, &r));
    if (!r) return;
    if (verbose) {
      const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
      fprintf(stderr, "m %2d: cut %lld, points %lld -> %lld, simplify %.3f s, intersect %.3f s\n",
              m, (long long)S->num_cut, (long long)S->points_initial[0],
              (long long)S->points_simplified[0], S->time_simplify, S->time_intersect);
    }
    (void)nmono;
    for (fcm_index c = 0; c < nc; c++) {
      const fcm_cell_class cls = fcm_cell_rules_class(r, c);
      const double vol = exact[c][0];
      if (cls == FCM_CELL_DROPPED) {
        TEST_TRUE(vol < (1e-4 + 1e-12) * kvol[c]);
        continue;
      }
      fcm_mesh_cell_coords(mesh, c, X);
      const int nk = cell_planes(type, X, pl);
      for (int kind = 0; kind < FCM_RULE_KIND_COUNT; kind++) {
        const int mk = fcm_cell_rules_strength(r, (fcm_rule_kind)kind);
        const int M = (mk + 1) * (mk + 2) * (mk + 3) / 6, nm = exact_num_mono(mk);
        int n;
        const double *p, *w;
        const unsigned char *f;
        TEST_OK(ctx, fcm_cell_rules_get(r, c, (fcm_rule_kind)kind, &n, &p, &w, &f));
        double got[EXACT_MAX_MONO] = {0};
        for (int j = 0; j < n; j++) {
          fcm_element_map(type, X, p + 3 * j, x);
          const double det = fcm_element_jacobian(type, X, p + 3 * j, J);
          exact_eval(mk, x, vals);
          for (int k = 0; k < nm; k++)
            got[k] += w[j] * det * vals[k];
          TEST_TRUE(w[j] > 0.0 && f[j] == 0);
          if (cls == FCM_CELL_CUT && simplified) {
            /* Kept points are input points: inside the geometry and the cell. */
            int in_geom = 0;
            for (int e = 0; e < s->ncell && !in_geom; e++)
              in_geom = inside_planes(s->pl[e], s->npl[e], x, 1e-12);
            TEST_TRUE(in_geom);
            TEST_TRUE(inside_planes(pl, nk, x, 1e-12));
          }
        }
        if (cls == FCM_CELL_CUT && simplified) TEST_TRUE(n <= M);
        /* Uncut cells use the full cell's rule: the exact value is the cell's integral,
         * which equals K ∩ P up to (1 - phi) <= 1e-12. */
        for (int k = 0; k < nm; k++) {
          const double err = fabs(got[k] - exact[c][k]) / kvol[c];
          worst_err = fmax(worst_err, err);
          if (!(err <= (simplified ? 1e-11 : 1e-12))) {
            int e[3];
            exact_exponents(mk, k, e);
            TEST_FAIL_("m %d cell %lld kind %d x^%d y^%d z^%d: rule %.17g exact %.17g (n %d, "
                       "class %d)",
                       m, (long long)c, kind, e[0], e[1], e[2], got[k], exact[c][k], n, (int)cls);
          }
        }
      }
    }
    fcm_cell_rules_destroy(&r);
  }
}

int main(int argc, char **argv)
{
  const int hex = argc > 1 && strcmp(argv[1], "hex") == 0;
  simplified = argc > 2 && strcmp(argv[2], "simplified") == 0;
  /* "simplified": each shape at a quarter of the strengths; "simplified-full": all. */
  reduced = simplified && strcmp(argv[2], "simplified-full") != 0;
  simplified |= argc > 2 && strcmp(argv[2], "simplified-full") == 0;
  verbose = argc > 3;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  fcm_mesh *mesh = NULL;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {2, 2, 2};
  TEST_OK(ctx,
          fcm_mesh_create_box(ctx, hex ? FCM_ELEMENT_HEX8 : FCM_ELEMENT_TET4, lo, hi, n, &mesh));
  unsigned long long rng = hex ? 0x1234567ULL : 0x7654321ULL;
  for (int trial = 0; trial < NTRIAL; trial++) {
    for (int kind = 0; kind < 4; kind++) {
      shape s;
      memset(&s, 0, sizeof s);
      if (kind == 0)
        tet_shape(&s, &rng);
      else if (kind == 3)
        frustum_shape(&s, &rng);
      else
        box_shape(&s, &rng, kind == 1);
      if (s.g) check_shape(mesh, &s, 4 * trial + kind);
      fcm_geometry_destroy(&s.g);
    }
  }
  if (verbose) fprintf(stderr, "worst relative error %.3g\n", worst_err);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
