/* Hex8's cut-cell stiffness rules on the mass rules' space (fcm_cell_rules_options
 * .stiffness_on_mass_space: Q_2, 27 moments, which holds the products of the trilinear shape
 * functions' gradients). A hollow ball with a hole in a Hex8 grid of unequal cell sides, cut
 * by a tilted plane and then by a plane parallel to it 2e-3 away (thin slanted slabs between
 * them, which take the volume path without a fit), built by the surface path (the ball given
 * by its surface alone) and by the volume path with simplification; the reference: the volume
 * path unsimplified with the mass strength 6 (every polynomial of total degree <= 6 exact on
 * every tet of every piece), whose mass rules integrate the stiffness integrand exactly.
 * Asserts
 * - every cut piece's stiffness rule: positive weights, at most 27 authentic points, every
 *   point in the cell and on its piece's side of each cut;
 * - every piece's stiffness tensor S[a][b][i][j] = sum w det J dN_a/dxi_i dN_b/dxi_j (the
 *   element stiffness of an affine cell, whatever the material) equals the reference's within
 *   1e-12 of its largest entry, and so does its 8 x 8 mass matrix;
 * - the surface path fits once for both kinds: each piece's stiffness rule is its mass rule,
 *   bit for bit (authentic points);
 * - some pieces of the second cut took the volume path (the thin slabs) and are exact too;
 * - the control: the default stiffness rules (strength 2, 10 moments) miss the stiffness
 *   tensor by more than 1e-8 on some piece, so the check tells P_2 from Q_2;
 * - the option's range is checked (2 is refused). */
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

enum { NCUT = 2, NS = 8 * 8 * 9 };
static const double cut_p[NCUT][3] = {{0.07, -0.04, 0.03}, {0.07, -0.04, 0.03}};
static const double cut_n[3] = {1.0, 0.37, -0.21};
static const double cut_gap = 2e-3; /* the second plane: moved this far along cut_n */

/* The signed distance of y from cut k's plane. */
static double plane_side(int k, const double y[3])
{
  const double nn = sqrt(cut_n[0] * cut_n[0] + cut_n[1] * cut_n[1] + cut_n[2] * cut_n[2]);
  double s = -(k ? cut_gap : 0.0);
  for (int d = 0; d < 3; d++)
    s += (y[d] - cut_p[k][d]) * cut_n[d] / nn;
  return s;
}

/* Piece p's stiffness tensor S and mass matrix Mm from its kind-k rule's authentic points;
 * checks weights, the point count against max_points and that every point lies in the cell
 * and on one side of each cut. */
static void piece_tensors(const fcm_mesh *mesh, const fcm_cell_rules *r, fcm_index p, int kind,
                          int max_points, double S[NS], double Mm[64])
{
  int n, na = 0, side[NCUT] = {0, 0};
  const double *x, *w;
  const unsigned char *fl;
  double X[24], J[9], N[8], dN[24], y[3];
  fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r, p), X);
  TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, kind, &n, &x, &w, &fl));
  memset(S, 0, NS * sizeof *S);
  memset(Mm, 0, 64 * sizeof *Mm);
  for (int j = 0; j < n; j++) {
    if (fl[j]) continue;
    na++;
    const double *e = x + 3 * j;
    TEST_TRUE(isfinite(w[j]) && w[j] > 0.0);
    for (int d = 0; d < 3; d++)
      TEST_TRUE(fabs(e[d]) <= 1.0 + 1e-12);
    fcm_element_map(FCM_ELEMENT_HEX8, X, e, y);
    for (int k = 0; k < NCUT; k++) {
      const double s = plane_side(k, y);
      const int sd = s > 1e-12 ? 1 : s < -1e-12 ? -1 : 0;
      TEST_TRUE(!sd || !side[k] || sd == side[k]);
      if (sd) side[k] = sd;
    }
    const double wd = w[j] * fcm_element_jacobian(FCM_ELEMENT_HEX8, X, e, J);
    fcm_element_eval_shape(FCM_ELEMENT_HEX8, e, N);
    fcm_element_eval_grad(FCM_ELEMENT_HEX8, e, dN);
    for (int a = 0; a < 8; a++)
      for (int b = 0; b < 8; b++) {
        Mm[8 * a + b] += wd * N[a] * N[b];
        for (int i = 0; i < 3; i++)
          for (int l = 0; l < 3; l++)
            S[9 * (8 * a + b) + 3 * i + l] += wd * dN[3 * a + i] * dN[3 * b + l];
      }
  }
  TEST_TRUE(na >= 1 && na <= max_points);
}

/* Largest difference of two arrays relative to the largest entry of the second. */
static double rel_error(const double *A, const double *B, int n)
{
  double d = 0.0, s = 0.0;
  for (int i = 0; i < n; i++)
    d = fmax(d, fabs(A[i] - B[i])), s = fmax(s, fabs(B[i]));
  return d / s;
}

/* Whether piece p's stiffness rule is its mass rule (authentic points, bit for bit). */
static int same_rules(const fcm_cell_rules *r, fcm_index p)
{
  int n[2], m[2] = {0, 0};
  const double *x[2], *w[2];
  const unsigned char *f[2];
  for (int k = 0; k < 2; k++) {
    TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, k ? FCM_RULE_MASS : FCM_RULE_STIFFNESS, n + k,
                                          x + k, w + k, f + k));
    while (m[k] < n[k] && !f[k][m[k]])
      m[k]++;
  }
  return m[0] == m[1] && !memcmp(x[0], x[1], 3 * (size_t)m[0] * sizeof(double)) &&
         !memcmp(w[0], w[1], (size_t)m[0] * sizeof(double));
}

/* Rules r against ref piece by piece (pieces matched within their cell by the smallest mass
 * matrix difference; the reference's stiffness from its exact mass rule); returns the largest
 * relative stiffness error; with exact set asserts it and the mass matrix's (1e-12). */
static double compare(const fcm_mesh *mesh, const fcm_cell_rules *r, const fcm_cell_rules *ref,
                      int max_points, int exact, const char *what)
{
  static double S[NS], Sr[NS];
  double worst = 0.0, worst_mass = 0.0;
  fcm_index pieces = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    if (fcm_cell_rules_class(r, c) != FCM_CELL_CUT) continue;
    fcm_index f, fr;
    const fcm_index k = fcm_cell_rules_cell_pieces(r, c, &f),
                    kr = fcm_cell_rules_cell_pieces(ref, c, &fr);
    TEST_TRUE(k == kr && fcm_cell_rules_class(ref, c) == FCM_CELL_CUT);
    if (k != kr) continue;
    for (fcm_index i = 0; i < k; i++) {
      double M[64], Mr[64], best = HUGE_VAL;
      fcm_index bj = 0;
      piece_tensors(mesh, r, f + i, FCM_RULE_MASS, max_points, S, M);
      for (fcm_index j = 0; j < kr; j++) {
        piece_tensors(mesh, ref, fr + j, FCM_RULE_MASS, 1 << 30, Sr, Mr);
        const double e = rel_error(M, Mr, 64);
        if (e < best) best = e, bj = j;
      }
      piece_tensors(mesh, ref, fr + bj, FCM_RULE_MASS, 1 << 30, Sr, Mr);
      piece_tensors(mesh, r, f + i, FCM_RULE_STIFFNESS, max_points, S, M);
      const double es = rel_error(S, Sr, NS);
      worst = fmax(worst, es), worst_mass = fmax(worst_mass, best);
      pieces++;
      if (!exact) continue;
      if (es > 1e-12 || best > 1e-12)
        printf("%s: cell %lld piece %lld: stiffness off by %.3g, mass by %.3g\n", what,
               (long long)c, (long long)i, es, best);
      TEST_TRUE(es <= 1e-12 && best <= 1e-12);
    }
  }
  TEST_TRUE(pieces > 0);
  printf("%s: %lld cut pieces, stiffness error %.3g, mass error %.3g of the largest entry\n", what,
         (long long)pieces, worst, worst_mass);
  return worst;
}

/* Rules of g cut by the two planes (the option and the mass strength ms as given). */
static fcm_cell_rules *cut_rules(const fcm_mesh *mesh, const fcm_geometry *g, fcm_cell_moments mp,
                                 int simplify, int ms, int shared)
{
  const double blo[3] = {-2, -2, -2}, bhi[3] = {2, 2, 2};
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.moments = mp;
  o.simplify = simplify ? FCM_CELL_SIMPLIFY_ON : FCM_CELL_SIMPLIFY_OFF;
  o.strength[FCM_RULE_MASS] = ms;
  o.stiffness_on_mass_space = shared;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  for (int k = 0; k < NCUT && r; k++) {
    const double nn = sqrt(cut_n[0] * cut_n[0] + cut_n[1] * cut_n[1] + cut_n[2] * cut_n[2]);
    double p[3];
    for (int d = 0; d < 3; d++)
      p[d] = cut_p[k][d] + (k ? cut_gap : 0.0) * cut_n[d] / nn;
    fcm_surface *s = NULL;
    fcm_cell_rules *cut = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, p, cut_n, blo, bhi, &s));
    if (s) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r, s, &cut));
    fcm_surface_destroy(&s);
    fcm_cell_rules_destroy(&r);
    r = cut;
    if (r) TEST_TRUE(fcm_cell_rules_get_stats(r)->num_split > 0);
  }
  return r;
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

  { /* the option's range */
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    fcm_cell_rules *r = NULL;
    TEST_TRUE(o.stiffness_on_mass_space == 0);
    o.stiffness_on_mass_space = 2;
    TEST_TRUE(fcm_cell_rules_create(ctx, mesh, surf, &o, &r) == FCM_ERR_ARG);
    TEST_TRUE(r == NULL);
  }
  fcm_cell_rules *ref = cut_rules(mesh, tets, FCM_CELL_MOMENTS_VOLUME, 0, 6, 0);
  fcm_cell_rules *rs = cut_rules(mesh, surf, FCM_CELL_MOMENTS_SURFACE, 1, FCM_DEFAULT, 1);
  fcm_cell_rules *rv = cut_rules(mesh, tets, FCM_CELL_MOMENTS_VOLUME, 1, FCM_DEFAULT, 1);
  fcm_cell_rules *p2 = cut_rules(mesh, surf, FCM_CELL_MOMENTS_SURFACE, 1, FCM_DEFAULT, 0);
  if (ref && rs && rv && p2) {
    const fcm_cell_rules_stats *st = fcm_cell_rules_get_stats(rs);
    printf("surface path: %lld volume-path pieces\n", (long long)st->num_surface_fallbacks);
    TEST_TRUE(st->num_surface_fallbacks > 0);
    fcm_index same = 0, np = fcm_cell_rules_num_pieces(rs);
    for (fcm_index p = 0; p < np; p++)
      same += fcm_cell_rules_class(rs, fcm_cell_rules_piece_cell(rs, p)) != FCM_CELL_CUT ||
              same_rules(rs, p);
    printf("surface path: %lld of %lld pieces with the stiffness rule the mass rule\n",
           (long long)same, (long long)np);
    TEST_TRUE(same == np);
    compare(mesh, rs, ref, 27, 1, "surface path, stiffness on Q2");
    compare(mesh, rv, ref, 27, 1, "volume path, stiffness on Q2");
    TEST_TRUE(compare(mesh, p2, ref, 27, 0, "surface path, stiffness on P2 (control)") > 1e-8);
  }
  fcm_cell_rules_destroy(&ref);
  fcm_cell_rules_destroy(&rs);
  fcm_cell_rules_destroy(&rv);
  fcm_cell_rules_destroy(&p2);
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&surf);
  fcm_geometry_destroy(&tets);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
