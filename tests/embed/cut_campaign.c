/* Degenerate cuts and a random cut campaign: embedded geometry cut by the background cell
 * planes of a 2x2x2 grid over [-1,1]^3 (Hex8 cells, and Tet4 cells of the Kuhn split) in
 * degenerate ways, checked per cell against a reference for K ∩ P independent of the
 * library's clipping (the geometry's tets split at each cell plane into tets, by vertex
 * signs without tolerance, then the closed-form tet moments of tests/geom/exact.h) and
 * globally against the closed-form moments of the geometry:
 *   - volume and first moments of the stiffness rule's authentic points within 1e-12 h^3
 *     (moments: 1e-12 h^4; h the longest edge of the cell's bounding box, 1 here: the scale
 *     of the clipping tolerance, clip_rtol h), per cell, for the initial rules; within
 *     2e-12 for the simplified ones (the simplification's accepted residual); the sum over
 *     cells within that times the number of cut cells of the geometry's exact values;
 *   - every point and weight finite, weights > 0, volume fractions in [0, 1 + 1e-11];
 *   - at most M = (m+1)(m+2)(m+3)/6 authentic points in a cut cell after simplification,
 *     except in cells the statistics count as simplification fallbacks.
 * The catalogue ("catalogue"): a vertex at a grid node, an edge along a grid line, a face in
 * a grid plane, a tet equal to a Tet4 cell, a hex equal to a Hex8 cell, a box whose faces are
 * grid planes, vertices at 1e-16 .. 1e-3 on either side of a plane, slivers of relative
 * thickness 1e-15 .. 1e-3 crossing a plane, a tet on the outer boundary. The campaign
 * ("campaign N"): N random tets with most coordinates snapped to the planes -1, -1/2, 0, 1/2,
 * 1 (plus an offset of 0 or +-1e-15 .. 1e-6) and random rotated boxes (hex8 geometry), each
 * with rules of strength 1 .. 3, initial and simplified, min_fraction 0 (no volume may go).
 * Usage: embed_cut_campaign catalogue | campaign N [seed] [verbose] [first]
 *   verbose 1 names every case, 2 also prints its tets; first: the cases before it are drawn
 *   (the same sequence) but not checked, so `campaign K+1 seed 2 K` repeats case K alone. */
#include "fcm/embed.h"
#include "../geom/exact.h"
#include "test.h"

#define NCELL_MAX 48
#define RTOL      1e-12
/* fcm_simplify accepts a relative moment residual of 1e-12 of the largest reference-cell
 * moment (residual_tol); measured in physical moments per h^3 that reaches 1.4e-12 */
#define RTOL_SIMPLIFIED 2e-12

static fcm_ctx *ctx;
static int verbose;
static double worst_cell, worst_sum, worst_phi;
static long long cases, cut_cells, fallbacks;

typedef struct geom_case {
  fcm_geometry *g;
  double tet[6][4][3]; /* the geometry as tets, for the reference */
  int ntet;
  double moments[4]; /* exact volume and first moments of the geometry */
  const char *what;
} geom_case;

/* Outward planes and volume of background cell c. */
static int cell_planes(fcm_element_type type, const double *X, exact_plane *pl, double *vol)
{
  double m[EXACT_MAX_MONO] = {0};
  int np;
  if (type == FCM_ELEMENT_TET4) {
    double v[4][3];
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        v[a][d] = X[3 * a + d];
    exact_tet_planes(v, pl);
    exact_tet_add(v, 0, m);
    np = 4;
  } else {
    for (int d = 0; d < 3; d++) {
      for (int i = 0; i < 3; i++)
        pl[2 * d].n[i] = i == d, pl[2 * d + 1].n[i] = -(i == d);
      pl[2 * d].d = X[18 + d];
      pl[2 * d + 1].d = -X[d];
    }
    m[0] = (X[18] - X[0]) * (X[19] - X[1]) * (X[20] - X[2]);
    np = 6;
  }
  *vol = m[0];
  return np;
}

/* The reference: volume and first moments of tet T ∩ {n_k.x <= d_k, k >= from}, by
 * splitting T at each plane into tets (no tolerance: vertex signs decide; an intersection
 * point is a + s_a / (s_a - s_b) (b - a)) and the closed form of exact_tet_add(). */
static void ref_clip(double T[4][3], const exact_plane *pl, int np, int from, double out[4])
{
  if (from == np) {
    double m[EXACT_MAX_MONO] = {0};
    exact_tet_add(T, 1, m);
    for (int k = 0; k < 4; k++)
      out[k] += m[k];
    return;
  }
  const exact_plane *P = &pl[from];
  double s[4];
  int in[4], out_[4], ni = 0, no = 0;
  for (int a = 0; a < 4; a++) {
    s[a] = P->n[0] * T[a][0] + P->n[1] * T[a][1] + P->n[2] * T[a][2] - P->d;
    if (s[a] <= 0)
      in[ni++] = a;
    else
      out_[no++] = a;
  }
  if (no == 0) {
    ref_clip(T, pl, np, from + 1, out);
    return;
  }
  if (ni == 0) return;
#define CUT(x, a, b)                                                                               \
  do {                                                                                             \
    const double t_ = s[a] / (s[a] - s[b]);                                                        \
    for (int d_ = 0; d_ < 3; d_++)                                                                 \
      (x)[d_] = T[a][d_] + t_ * (T[b][d_] - T[a][d_]);                                             \
  } while (0)
  double Q[4][3];
  if (ni == 1) {
    memcpy(Q[0], T[in[0]], sizeof Q[0]);
    for (int k = 0; k < 3; k++)
      CUT(Q[1 + k], in[0], out_[k]);
    ref_clip(Q, pl, np, from + 1, out);
    return;
  }
  /* a prism a0 a1 a2 / b0 b1 b2 (edges a_k b_k) as three tets */
  double A[3][3], B[3][3];
  if (ni == 3) {
    for (int k = 0; k < 3; k++) {
      memcpy(A[k], T[in[k]], sizeof A[k]);
      CUT(B[k], in[k], out_[0]);
    }
  } else {
    memcpy(A[0], T[in[0]], sizeof A[0]);
    CUT(A[1], in[0], out_[0]);
    CUT(A[2], in[0], out_[1]);
    memcpy(B[0], T[in[1]], sizeof B[0]);
    CUT(B[1], in[1], out_[0]);
    CUT(B[2], in[1], out_[1]);
  }
#undef CUT
  const double *split[3][4] = {
      {A[0], A[1], A[2], B[2]}, {A[0], A[1], B[1], B[2]}, {A[0], B[0], B[1], B[2]}};
  for (int t = 0; t < 3; t++) {
    for (int a = 0; a < 4; a++)
      memcpy(Q[a], split[t][a], sizeof Q[a]);
    ref_clip(Q, pl, np, from + 1, out);
  }
}

/* Check the rules of `gc` in `mesh` at stiffness strength m (simplified, min_fraction 0). */
static void check(const fcm_mesh *mesh, const geom_case *gc, int m, int simplify)
{
  const double tol = simplify ? RTOL_SIMPLIFIED : RTOL;
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_STIFFNESS] = m;
  o.strength[FCM_RULE_MASS] = m > 1 ? m - 1 : 1;
  o.min_fraction = 0.0;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1));
  o.simplify = simplify;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, gc->g, &o, &r));
  if (!r) return;
  cases++;
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  TEST_TRUE(isfinite(S->embedded_volume) && isfinite(S->max_residual[0]));
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], x[3], sum[4] = {0, 0, 0, 0};
  int ncut = 0, over_m[FCM_RULE_KIND_COUNT] = {0, 0};
  for (fcm_index c = 0; c < nc; c++) {
    fcm_mesh_cell_coords(mesh, c, X);
    exact_plane pl[6];
    double kvol = 0.0, exact[4] = {0, 0, 0, 0}, got[4] = {0, 0, 0, 0};
    const int nk = cell_planes(type, X, pl, &kvol);
    (void)kvol;
    /* the scale of the clipping tolerances: snapping a vertex within clip_rtol h of a plane
     * moves volume ~ clip_rtol h^3, whatever |K| (a Tet4 cell is 1/6 of its cube) */
    double h = 0.0;
    for (int d = 0; d < 3; d++) {
      double lo = X[d], hi = X[d];
      for (int a = 1; a < fcm_mesh_nodes_per_cell(mesh); a++)
        lo = fmin(lo, X[3 * a + d]), hi = fmax(hi, X[3 * a + d]);
      h = fmax(h, hi - lo);
    }
    for (int t = 0; t < gc->ntet; t++) {
      double T[4][3];
      memcpy(T, gc->tet[t], sizeof T);
      ref_clip(T, pl, nk, 0, exact);
    }
    const fcm_cell_class cls = fcm_cell_rules_class(r, c);
    const double phi = fcm_cell_rules_volume_fraction(r, c);
    TEST_TRUE(isfinite(phi) && phi >= 0.0 && phi <= 1.0 + 1e-11);
    worst_phi = fmax(worst_phi, phi - 1.0);
    ncut += cls == FCM_CELL_CUT;
    for (int kind = 0; kind < FCM_RULE_KIND_COUNT; kind++) {
      const int mk = fcm_cell_rules_strength(r, (fcm_rule_kind)kind);
      const int M = (mk + 1) * (mk + 2) * (mk + 3) / 6;
      int n, authentic = 0;
      const double *p, *w;
      const unsigned char *f;
      TEST_OK(ctx, fcm_cell_rules_get(r, c, (fcm_rule_kind)kind, &n, &p, &w, &f));
      if (cls == FCM_CELL_DROPPED) TEST_TRUE(n == 0);
      for (int j = 0; j < n; j++) {
        const int ok = isfinite(p[3 * j]) && isfinite(p[3 * j + 1]) && isfinite(p[3 * j + 2]) &&
                       isfinite(w[j]) && w[j] > 0.0;
        if (!ok)
          TEST_FAIL_("%s m %d cell %lld kind %d point %d: w %g", gc->what, m, (long long)c, kind, j,
                     w[j]);
        if (f[j]) continue; /* stabilization */
        authentic++;
        if (kind != FCM_RULE_STIFFNESS) continue;
        fcm_element_map(type, X, p + 3 * j, x);
        const double wd = w[j] * fcm_element_jacobian(type, X, p + 3 * j, J);
        got[0] += wd, got[1] += wd * x[0], got[2] += wd * x[1], got[3] += wd * x[2];
      }
      if (simplify && cls == FCM_CELL_CUT && authentic > M) {
        over_m[kind]++;
        if (verbose)
          fprintf(stderr, "%s m %d cell %lld kind %d: %d points > M = %d (fallback)\n", gc->what, m,
                  (long long)c, kind, authentic, M);
      }
    }
    /* exact[] is ordered 1, x, y, z (degree ascending) */
    for (int k = 0; k < 4; k++) {
      const double err = fabs(got[k] - exact[k]) / (h * h * h * (k ? h : 1.0));
      sum[k] += got[k];
      worst_cell = fmax(worst_cell, err);
      if (!(err <= tol))
        TEST_FAIL_("%s m %d cell %lld (class %d, phi %.17g) moment %d: rule %.17g exact %.17g "
                   "(error %.3g h^3)",
                   gc->what, m, (long long)c, (int)cls, phi, k, got[k], exact[k], err);
    }
  }
  cut_cells += ncut;
  /* more than M points only where the simplification fell back, and counted as such */
  for (int kind = 0; kind < FCM_RULE_KIND_COUNT; kind++) {
    fallbacks += over_m[kind];
    if (over_m[kind] > S->simplify_fallbacks[kind])
      TEST_FAIL_("%s m %d kind %d: %d cut cells with more than M points, %lld fallbacks counted",
                 gc->what, m, kind, over_m[kind], (long long)S->simplify_fallbacks[kind]);
  }
  for (int k = 0; k < 4; k++) {
    const double err = fabs(sum[k] - gc->moments[k]);
    worst_sum = fmax(worst_sum, err / (ncut > 0 ? ncut : 1));
    if (!(err <= tol * (ncut > 0 ? ncut : 1)))
      TEST_FAIL_("%s m %d: moment %d summed over cells %.17g, exact %.17g (error %.3g, %d cut)",
                 gc->what, m, k, sum[k], gc->moments[k], err, ncut);
  }
  fcm_cell_rules_destroy(&r);
}

/* ---------------------------------------------------------------- geometries */

/* One tet; oriented positively (vertices 2 and 3 swapped when needed). 0 on success. */
static int make_tet(geom_case *gc, double v[4][3], const char *what)
{
  const double u[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
  const double w[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
  const double z[3] = {v[3][0] - v[0][0], v[3][1] - v[0][1], v[3][2] - v[0][2]};
  const double det = u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) +
                     u[2] * (w[0] * z[1] - w[1] * z[0]);
  if (det < 0)
    for (int d = 0; d < 3; d++) {
      const double t = v[2][d];
      v[2][d] = v[3][d], v[3][d] = t;
    }
  const fcm_index cells[4] = {0, 1, 2, 3};
  gc->g = NULL;
  if (fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, &v[0][0], 1, cells, &gc->g) != FCM_OK) {
    fcm_ctx_error_clear(ctx);
    return 1;
  }
  memcpy(gc->tet[0], v, sizeof gc->tet[0]);
  gc->ntet = 1;
  double m[EXACT_MAX_MONO] = {0};
  exact_tet_add(v, 1, m);
  memcpy(gc->moments, m, sizeof gc->moments);
  gc->what = what;
  return 0;
}

/* The box R [lo, hi] + t as one hex8 geometry cell. */
static int make_box(geom_case *gc, const double R[9], const double t[3], const double lo[3],
                    const double hi[3], const char *what)
{
  static const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                   {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  double X[24];
  for (int a = 0; a < 8; a++) {
    double y[3];
    for (int d = 0; d < 3; d++)
      y[d] = corner[a][d] ? hi[d] : lo[d];
    for (int i = 0; i < 3; i++)
      X[3 * a + i] = R[3 * i] * y[0] + R[3 * i + 1] * y[1] + R[3 * i + 2] * y[2] + t[i];
  }
  const fcm_index cells[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  gc->g = NULL;
  if (fcm_geometry_create(ctx, FCM_ELEMENT_HEX8, 8, X, 1, cells, &gc->g) != FCM_OK) {
    fcm_ctx_error_clear(ctx);
    return 1;
  }
  /* the Kuhn split around the diagonal corner 0 -> corner 6 */
  static const int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                 {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  for (int k = 0; k < 6; k++)
    for (int a = 0; a < 4; a++)
      memcpy(gc->tet[k][a], X + 3 * kuhn[k][a], sizeof gc->tet[k][a]);
  gc->ntet = 6;
  const double vol = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  double c[3];
  for (int d = 0; d < 3; d++)
    c[d] = 0.5 * (lo[d] + hi[d]);
  gc->moments[0] = vol;
  for (int i = 0; i < 3; i++)
    gc->moments[1 + i] = vol * (R[3 * i] * c[0] + R[3 * i + 1] * c[1] + R[3 * i + 2] * c[2] + t[i]);
  gc->what = what;
  return 0;
}

static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

static void run_case(fcm_mesh *const meshes[2], geom_case *gc, int mmax)
{
  if (verbose) fprintf(stderr, "%s\n", gc->what);
  for (int k = 0; k < 2; k++)
    for (int m = 1; m <= mmax; m++)
      for (int simplify = 0; simplify < 2; simplify++)
        check(meshes[k], gc, m, simplify);
  fcm_geometry_destroy(&gc->g);
}

static void tet_case(fcm_mesh *const meshes[2], double v[4][3], const char *what)
{
  geom_case gc;
  if (make_tet(&gc, v, what)) {
    TEST_FAIL_("%s: geometry refused: %s", what, fcm_ctx_error_message(ctx));
    return;
  }
  run_case(meshes, &gc, 3);
}

/* ---------------------------------------------------------------- the catalogue */

static void catalogue(fcm_mesh *const meshes[2])
{
  const double zero[3] = {0, 0, 0};
  geom_case gc;
  /* a vertex at the grid node where all interior planes meet, the rest in three octants */
  double a[4][3] = {{0, 0, 0}, {0.7, 0.2, 0.3}, {-0.3, 0.6, 0.1}, {0.2, -0.4, 0.8}};
  tet_case(meshes, a, "vertex at the central node");
  /* an edge along the grid line y = z = 0, through the node */
  double b[4][3] = {{-0.6, 0, 0}, {0.8, 0, 0}, {0.1, 0.7, -0.2}, {0.2, -0.3, 0.6}};
  tet_case(meshes, b, "edge along a grid line");
  /* a face in the grid plane z = 0, the tet on one side, then on both sides of y = 0 */
  double c[4][3] = {{-0.5, -0.5, 0}, {0.7, -0.4, 0}, {0.1, 0.8, 0}, {0.1, 0.1, 0.9}};
  tet_case(meshes, c, "face in a grid plane");
  /* all four vertices at grid nodes (spanning several cells, faces along Kuhn planes) */
  double d[4][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {1, 1, 1}};
  tet_case(meshes, d, "vertices at grid nodes");
  double e[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}};
  tet_case(meshes, e, "a Tet4 cell of the Kuhn split, exactly");
  double f[4][3] = {{1, 1, 1}, {-1, 1, 1}, {1, -1, 1}, {1, 1, -1}};
  tet_case(meshes, f, "a corner tet on the outer boundary");
  /* boxes: equal to a Hex8 cell, faces on grid planes over several cells, inside a cell */
  const double lo1[3] = {0, 0, 0}, hi1[3] = {1, 1, 1};
  const double lo2[3] = {-1, -0.5, 0}, hi2[3] = {0.5, 1, 1};
  const double lo3[3] = {-1, -1, -1}, hi3[3] = {1, 1, 1};
  if (!make_box(&gc, identity, zero, lo1, hi1, "a Hex8 cell, exactly")) run_case(meshes, &gc, 3);
  if (!make_box(&gc, identity, zero, lo2, hi2, "a box with faces on grid planes"))
    run_case(meshes, &gc, 3);
  if (!make_box(&gc, identity, zero, lo3, hi3, "the whole background, exactly"))
    run_case(meshes, &gc, 2);
  /* a vertex at eps on either side of the plane x = 0, eps = 1e-16 .. 1e-3 */
  static char names[64][96];
  int nn = 0;
  for (int s = -1; s <= 1; s += 2)
    for (int k = 3; k <= 16; k++) {
      const double eps = s * pow(10.0, -k);
      double v[4][3] = {{eps, 0.1, 0.2}, {0.8, -0.3, 0.1}, {0.6, 0.7, -0.4}, {0.5, 0.2, 0.9}};
      snprintf(names[nn], sizeof names[nn], "vertex at x = %.0e", eps);
      tet_case(meshes, v, names[nn++]);
    }
  /* slivers crossing the plane z = 0: a flat tet of thickness t straddling it */
  for (int k = 3; k <= 15; k += 2) {
    const double t = pow(10.0, -k);
    double v[4][3] = {
        {-0.6, -0.5, -0.3 * t}, {0.7, -0.4, 0.6 * t}, {0.1, 0.8, -0.5 * t}, {0.2, 0.1, 0.7 * t}};
    snprintf(names[nn], sizeof names[nn], "sliver of thickness %.0e across z = 0", t);
    tet_case(meshes, v, names[nn++]);
  }
  /* a tiny tet at the central node, edge length 1e-5 .. 1e-2 */
  for (int k = 2; k <= 5; k++) {
    const double h = pow(10.0, -k);
    double v[4][3] = {
        {-h, -h, -h}, {h, -0.5 * h, 0.2 * h}, {0.3 * h, h, -0.4 * h}, {0.1 * h, 0.2 * h, h}};
    snprintf(names[nn], sizeof names[nn], "tet of size %.0e at the central node", h);
    tet_case(meshes, v, names[nn++]);
  }
}

/* ---------------------------------------------------------------- the campaign */

static double snapped(unsigned long long *rng)
{
  static const double planes[5] = {-1, -0.5, 0, 0.5, 1};
  static const double offsets[8] = {0, 0, 0, 1e-15, 1e-13, 1e-11, 1e-9, 1e-6};
  const double u = exact_rand(rng);
  double x;
  if (u < 0.65) {
    x = planes[(int)(5 * exact_rand(rng))];
    const double off = offsets[(int)(8 * exact_rand(rng))];
    x += exact_rand(rng) < 0.5 ? off : -off;
  } else {
    x = 2 * exact_rand(rng) - 1;
  }
  return fmin(1.0, fmax(-1.0, x));
}

static void campaign(fcm_mesh *const meshes[2], long long first, long long n,
                     unsigned long long seed)
{
  unsigned long long rng = seed;
  char name[96];
  for (long long i = 0; i < n; i++) {
    geom_case gc;
    const int m = 1 + (int)(i % 3);
    if (i % 4 != 3) {
      double v[4][3];
      for (int a = 0; a < 4; a++)
        for (int d = 0; d < 3; d++)
          v[a][d] = snapped(&rng);
      double mom[EXACT_MAX_MONO] = {0};
      exact_tet_add(v, 0, mom);
      if (mom[0] < 1e-6) continue; /* flat draws: the catalogue has the slivers */
      snprintf(name, sizeof name, "random tet %lld (seed %llu)", i, seed);
      if (make_tet(&gc, v, name)) {
        TEST_FAIL_("%s: geometry refused: %s", name, fcm_ctx_error_message(ctx));
        continue;
      }
    } else {
      /* a random box; rotated unless i % 8 == 7 (then axis-aligned, faces near planes) */
      double R[9], t[3], lo[3], hi[3];
      if (i % 8 == 7) {
        memcpy(R, identity, sizeof R);
        for (int d = 0; d < 3; d++) {
          lo[d] = snapped(&rng), hi[d] = snapped(&rng);
          if (hi[d] < lo[d]) {
            const double s = lo[d];
            lo[d] = hi[d], hi[d] = s;
          }
          t[d] = 0.0;
        }
        if ((hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) < 1e-6) continue;
      } else {
        exact_rotation(exact_rand(&rng), exact_rand(&rng), exact_rand(&rng), R);
        for (int d = 0; d < 3; d++) {
          const double h = 0.05 + 0.5 * exact_rand(&rng);
          lo[d] = -h, hi[d] = h;
          t[d] = 0.6 * (2 * exact_rand(&rng) - 1);
        }
        /* keep it inside the background: shrink until the corners are */
        for (int d = 0; d < 3; d++) {
          double reach = 0;
          for (int k = 0; k < 3; k++)
            reach += fabs(R[3 * d + k]) * hi[k];
          if (fabs(t[d]) + reach > 1.0) t[d] = copysign(fmax(0.0, 1.0 - reach), t[d]);
          if (reach > 1.0) goto skip;
        }
      }
      snprintf(name, sizeof name, "random box %lld (seed %llu)", i, seed);
      if (make_box(&gc, R, t, lo, hi, name)) {
        TEST_FAIL_("%s: geometry refused: %s", name, fcm_ctx_error_message(ctx));
        continue;
      }
    }
    if (i < first) { /* drawn (the same sequence), not checked */
      fcm_geometry_destroy(&gc.g);
      continue;
    }
    if (verbose) {
      fprintf(stderr, "%s\n", gc.what);
      if (verbose > 1)
        for (int t = 0; t < gc.ntet; t++)
          for (int a = 0; a < 4; a++)
            fprintf(stderr, "  tet %d vertex %d: %.17g %.17g %.17g\n", t, a, gc.tet[t][a][0],
                    gc.tet[t][a][1], gc.tet[t][a][2]);
    }
    for (int k = 0; k < 2; k++)
      for (int simplify = 0; simplify < 2; simplify++)
        check(meshes[k], &gc, m, simplify);
    fcm_geometry_destroy(&gc.g);
  skip:;
  }
}

int main(int argc, char **argv)
{
  if (argc < 2 || (strcmp(argv[1], "catalogue") && strcmp(argv[1], "campaign"))) {
    fprintf(stderr, "usage: %s catalogue | campaign N [seed] [verbose] [first]\n", argv[0]);
    return 2;
  }
  const int is_campaign = strcmp(argv[1], "campaign") == 0;
  const long long n = is_campaign && argc > 2 ? atoll(argv[2]) : 0;
  const unsigned long long seed = is_campaign && argc > 3 ? strtoull(argv[3], NULL, 10) : 19;
  verbose = argc > (is_campaign ? 4 : 2) ? (is_campaign ? atoi(argv[4]) : 1) : 0;
  const long long first = is_campaign && argc > 5 ? atoll(argv[5]) : 0;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  const fcm_index cells[3] = {2, 2, 2};
  fcm_mesh *meshes[2] = {NULL, NULL};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &meshes[0]));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_TET4, lo, hi, cells, &meshes[1]));
  if (meshes[0] && meshes[1]) {
    if (is_campaign)
      campaign(meshes, first, n, seed ? seed : 19);
    else
      catalogue(meshes);
  }
  if (verbose)
    fprintf(stderr,
            "%lld rule sets, %lld cut cells: worst per-cell error %.3g h^3, worst summed error "
            "%.3g per cut cell, largest phi - 1 %.3g, %lld simplification fallbacks with > M "
            "points\n",
            cases, cut_cells, worst_cell, worst_sum, worst_phi, fallbacks);
  fcm_mesh_destroy(&meshes[0]);
  fcm_mesh_destroy(&meshes[1]);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
