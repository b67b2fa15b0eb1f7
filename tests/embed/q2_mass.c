/* Hex8's cut-cell mass rules on the tensor space Q_2 (27 moments, the space of N_i N_j) by
 * default. A hollow ball with a hole in a Hex8 grid of unequal cell sides, cut by a tilted
 * plane through it, built by the surface path (the ball given by its surface alone) and by the
 * volume path with simplification; the reference: the volume path unsimplified with the mass
 * strength 6 given explicitly (every polynomial of total degree <= 6 exact on every tet of
 * every piece). Asserts
 * - the default mass rules report strength 6 and degree 2 per variable, the stiffness rules
 *   strength 2 without a cap; an explicit mass strength gives P_strength (degree cap = strength);
 * - every cut piece's mass rule: positive weights, at most 27 authentic points, every point in
 *   the cell and on its piece's side of the cut;
 * - every moment of Q_2 (x^a y^b z^c, a, b, c <= 2, in reference coordinates) of every cut
 *   piece equals the reference's within 1e-12 relative (sum of |terms|), and the piece's 8 x 8
 *   consistent mass matrix (sum w det J N_i N_j) the reference's within 1e-12 of its largest
 *   entry;
 * - the stiffness rules do not depend on the mass rules' space: with the mass on Q_2 they are
 *   bit for bit those built with the mass strength 6 given (P_6), the candidates being the same,
 *   but on the pieces where P_6's mass fit fell back to the volume path (at most as many);
 * - the control: rules of total degree 4 (35 functions, which hold the first 27 of P_6 by
 *   degree but not x^2 y^2 z^2) miss the mass matrix by more than 1e-8 on some piece, so the
 *   check above tells a wrong space from Q_2. */
#include "fcm/fcm.h"
#include "../geom/exact.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

static const double cut_p[3] = {0.07, -0.04, 0.03}, cut_n[3] = {1.0, 0.37, -0.21};

/* The 27 Q_2 moments (reference coordinates) and the mass matrix of piece p's authentic mass
 * points; checks weights, the point count against max_points and that every point lies in the
 * cell and on one side of the cut plane. Returns the number of authentic points. */
static int piece_mass(const fcm_mesh *mesh, const fcm_cell_rules *r, fcm_index p, int max_points,
                      double q2[27], double Mm[64], double *absum)
{
  int n, na = 0, side = 0;
  const double *x, *w;
  const unsigned char *fl;
  double X[24], J[9], N[8], y[3];
  fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r, p), X);
  TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, FCM_RULE_MASS, &n, &x, &w, &fl));
  memset(q2, 0, 27 * sizeof *q2);
  memset(Mm, 0, 64 * sizeof *Mm);
  memset(absum, 0, 27 * sizeof *absum);
  for (int j = 0; j < n; j++) {
    if (fl[j]) continue;
    na++;
    const double *e = x + 3 * j;
    TEST_TRUE(isfinite(w[j]) && w[j] > 0.0);
    for (int d = 0; d < 3; d++)
      TEST_TRUE(fabs(e[d]) <= 1.0 + 1e-12);
    fcm_element_map(FCM_ELEMENT_HEX8, X, e, y);
    const double s =
        (y[0] - cut_p[0]) * cut_n[0] + (y[1] - cut_p[1]) * cut_n[1] + (y[2] - cut_p[2]) * cut_n[2];
    const int sd = s > 1e-12 ? 1 : s < -1e-12 ? -1 : 0;
    TEST_TRUE(!sd || !side || sd == side);
    if (sd) side = sd;
    int i = 0;
    for (int a = 0; a <= 2; a++)
      for (int b = 0; b <= 2; b++)
        for (int c = 0; c <= 2; c++, i++) {
          const double t = w[j] * pow(e[0], a) * pow(e[1], b) * pow(e[2], c);
          q2[i] += t, absum[i] += fabs(t);
        }
    const double wd = w[j] * fcm_element_jacobian(FCM_ELEMENT_HEX8, X, e, J);
    fcm_element_eval_shape(FCM_ELEMENT_HEX8, e, N);
    for (int a = 0; a < 8; a++)
      for (int b = 0; b < 8; b++)
        Mm[8 * a + b] += wd * N[a] * N[b];
  }
  TEST_TRUE(na >= 1 && na <= max_points);
  return na;
}

/* Largest difference of two mass matrices relative to the largest entry of the second. */
static double mass_error(const double *A, const double *B)
{
  double d = 0.0, s = 0.0;
  for (int i = 0; i < 64; i++)
    d = fmax(d, fabs(A[i] - B[i])), s = fmax(s, fabs(B[i]));
  return d / s;
}

/* Rules r against ref piece by piece (pieces matched within their cell by the smallest mass
 * matrix difference); returns the largest relative mass matrix error; with exact set asserts
 * the Q_2 moments and mass matrices (1e-12). */
static double compare(const fcm_mesh *mesh, const fcm_cell_rules *r, const fcm_cell_rules *ref,
                      int max_points, int exact, const char *what)
{
  double worst = 0.0;
  fcm_index pieces = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    if (fcm_cell_rules_class(r, c) != FCM_CELL_CUT) continue;
    fcm_index f, fr;
    const fcm_index k = fcm_cell_rules_cell_pieces(r, c, &f),
                    kr = fcm_cell_rules_cell_pieces(ref, c, &fr);
    TEST_TRUE(k == kr && fcm_cell_rules_class(ref, c) == FCM_CELL_CUT);
    if (k != kr) continue;
    for (fcm_index i = 0; i < k; i++) {
      double q[27], M[64], aq[27], qr[27], Mr[64], ar[27];
      piece_mass(mesh, r, f + i, max_points, q, M, aq);
      double best = HUGE_VAL;
      fcm_index bj = 0;
      for (fcm_index j = 0; j < kr; j++) {
        piece_mass(mesh, ref, fr + j, 1 << 30, qr, Mr, ar);
        const double e = mass_error(M, Mr);
        if (e < best) best = e, bj = j;
      }
      piece_mass(mesh, ref, fr + bj, 1 << 30, qr, Mr, ar);
      worst = fmax(worst, best);
      pieces++;
      if (!exact) continue;
      for (int m = 0; m < 27; m++)
        TEST_NEAR(q[m], qr[m], 0.0, 1e-12 * fmax(aq[m], ar[m]));
      if (best > 1e-12)
        printf("%s: cell %lld piece %lld: mass matrix off by %.3g of its largest entry\n", what,
               (long long)c, (long long)i, best);
      TEST_TRUE(best <= 1e-12);
    }
  }
  TEST_TRUE(pieces > 0);
  printf("%s: %lld cut pieces, mass matrix error %.3g of the largest entry\n", what,
         (long long)pieces, worst);
  return worst;
}

/* The pieces whose stiffness rules differ between a and b (bit for bit); -1 when the pieces
 * differ. */
static int stiffness_differences(const fcm_cell_rules *a, const fcm_cell_rules *b)
{
  int diff = 0;
  if (fcm_cell_rules_num_pieces(a) != fcm_cell_rules_num_pieces(b)) return -1;
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(a); p++) {
    int na, nb;
    const double *xa, *wa, *xb, *wb;
    const unsigned char *fa, *fb;
    TEST_OK(ctx, fcm_cell_rules_get_piece(a, p, FCM_RULE_STIFFNESS, &na, &xa, &wa, &fa));
    TEST_OK(ctx, fcm_cell_rules_get_piece(b, p, FCM_RULE_STIFFNESS, &nb, &xb, &wb, &fb));
    diff += na != nb || (na && (memcmp(xa, xb, 3 * (size_t)na * sizeof *xa) ||
                                memcmp(wa, wb, (size_t)na * sizeof *wa)));
  }
  return diff;
}

/* Rules of g (mass strength ms, FCM_DEFAULT: the element's) cut by the plane. */
static fcm_cell_rules *cut_rules(const fcm_mesh *mesh, const fcm_geometry *g, fcm_cell_moments mp,
                                 int simplify, int ms)
{
  const double blo[3] = {-2, -2, -2}, bhi[3] = {2, 2, 2};
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.moments = mp;
  o.simplify = simplify ? FCM_CELL_SIMPLIFY_ON : FCM_CELL_SIMPLIFY_OFF;
  o.strength[FCM_RULE_MASS] = ms;
  fcm_cell_rules *r = NULL, *cut = NULL;
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, cut_p, cut_n, blo, bhi, &s));
  if (r && s) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r, s, &cut));
  fcm_surface_destroy(&s);
  fcm_cell_rules_destroy(&r);
  if (cut) TEST_TRUE(fcm_cell_rules_get_stats(cut)->num_split > 0);
  return cut;
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const double c0[3] = {0.05, -0.03, 0.02};
  fcm_geometry *tets = NULL, *surf = NULL;
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_geometry_create_hollow_ball(ctx, c0, 0.5, 1.0, 0.3, 4, 2, &tets));
  if (!tets) return TEST_RESULT();
  TEST_OK(ctx, fcm_surface_create(ctx, fcm_geometry_num_nodes(tets), fcm_geometry_coords(tets),
                                  fcm_geometry_num_boundary_triangles(tets),
                                  fcm_geometry_boundary_triangles(tets), &s));
  fcm_surface_mesh_options mo = fcm_surface_mesh_options_default();
  mo.volume_mesh = 0;
  TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, s, &mo, &surf));
  fcm_surface_destroy(&s);
  const double lo[3] = {-1.1, -1.1, -1.1}, hi[3] = {1.1, 1.2, 1.1};
  const fcm_index n[3] = {4, 5, 3};
  fcm_mesh *mesh = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  if (!mesh || !surf) return TEST_RESULT();

  fcm_cell_rules *ref = cut_rules(mesh, tets, FCM_CELL_MOMENTS_VOLUME, 0, 6);
  fcm_cell_rules *rs = cut_rules(mesh, surf, FCM_CELL_MOMENTS_SURFACE, 1, FCM_DEFAULT);
  fcm_cell_rules *rv = cut_rules(mesh, tets, FCM_CELL_MOMENTS_VOLUME, 1, FCM_DEFAULT);
  fcm_cell_rules *p6 = cut_rules(mesh, surf, FCM_CELL_MOMENTS_SURFACE, 1, 6);
  fcm_cell_rules *p4 = cut_rules(mesh, surf, FCM_CELL_MOMENTS_SURFACE, 1, 4);
  if (ref && rs && rv && p6 && p4) {
    TEST_TRUE(fcm_cell_rules_strength(rs, FCM_RULE_MASS) == 6);
    TEST_TRUE(fcm_cell_rules_axis_degree(rs, FCM_RULE_MASS) == 2);
    TEST_TRUE(fcm_cell_rules_axis_degree(rv, FCM_RULE_MASS) == 2);
    TEST_TRUE(fcm_cell_rules_strength(rs, FCM_RULE_STIFFNESS) == 2);
    TEST_TRUE(fcm_cell_rules_axis_degree(rs, FCM_RULE_STIFFNESS) == 2);
    TEST_TRUE(fcm_cell_rules_axis_degree(p6, FCM_RULE_MASS) == 6);
    TEST_TRUE(fcm_cell_rules_axis_degree(ref, FCM_RULE_MASS) == 6);
    TEST_TRUE(fcm_cell_rules_axis_degree(p4, FCM_RULE_MASS) == 4);
    TEST_TRUE(fcm_cell_rules_get_stats(rs)->num_surface_fallbacks == 0);
    /* the same but where P_6's mass fit fell back to the volume path (both kinds) */
    const int d = stiffness_differences(rs, p6);
    printf("stiffness rules: %d pieces differ, %lld P6 fallbacks\n", d,
           (long long)fcm_cell_rules_get_stats(p6)->num_surface_fallbacks);
    TEST_TRUE(d >= 0 && d <= fcm_cell_rules_get_stats(p6)->num_surface_fallbacks);
    compare(mesh, rs, ref, 27, 1, "surface path, Q2");
    compare(mesh, rv, ref, 27, 1, "volume path, Q2");
    compare(mesh, p6, ref, 84, 1, "surface path, P6");
    TEST_TRUE(compare(mesh, p4, ref, 35, 0, "surface path, P4 (control)") > 1e-8);
  }
  fcm_cell_rules_destroy(&ref);
  fcm_cell_rules_destroy(&rs);
  fcm_cell_rules_destroy(&rv);
  fcm_cell_rules_destroy(&p6);
  fcm_cell_rules_destroy(&p4);
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&surf);
  fcm_geometry_destroy(&tets);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
