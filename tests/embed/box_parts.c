/* Cut pieces made of boxes of their cell's reference coordinates (cuts along the grid's axes,
 * as Dick's blades cut a box grid). A hollow ball with a hole, given by its surface alone, in a
 * Hex8 grid of unequal cell sides sheared in x by y (affine parallelepiped cells, so a box of
 * the reference coordinates is not a box of x), cut by a plane along the grid's x = const
 * reference planes, a rectangle along its y = const planes that ends inside cells (a crack tip:
 * pieces of four box parts, more points than M, which are fitted) and, in a second run, also by
 * a tilted plane (parts that are not boxes). With the stiffness on the mass space, a piece the body
 * fills made of boxes takes the 2-point Gauss rule on each (no fit), and a box part at the body's
 * surface takes its material moments as one Hex8 cell of its own (fcm__material_poly). The
 * reference: the volume path unsimplified at mass strength 6 on the ball's tets. Asserts
 * - every cut piece's stiffness tensor (sum w det J dN_a/dxi_i dN_b/dxi_j) and 8 x 8 mass
 *   matrix equal the reference's within 1e-12 of their largest entries, positive weights,
 *   at most 27 points, every point in the cell and on one side of each cut;
 * - Gauss box rules occur (8 points per box, on one or more boxes) and pieces fitted on the
 *   surface moments occur too; no Gauss rule without the stiffness on the mass space;
 * - a weight of the Gauss rule off by a factor (the control: 1 + 1e-6 on one piece's rule)
 *   breaks the mass check, so the check tells an exact rule from a wrong one;
 * - the face overlaps' material test (fcm__material_on_face) on parallelograms across the
 *   ball's surfaces, whose prism is one Hex8 cell, answers as on the same polygon given with
 *   a fifth vertex on an edge (its prism's fan tets), with a threshold of 0.3 of the area
 *   (so the moments decide where the surface crosses), both answers occurring. */
#include "embed/embed_impl.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

enum { NS = 8 * 8 * 9, MAXCUT = 3 };
static const double shear = 0.3; /* x += shear y */

typedef struct cut {
  double p[3], n[3], lo[3], hi[3];
} cut;

static const cut cuts[MAXCUT] = {
    /* x - shear y = 0.13: the sheared grid's reference plane (between grid planes) */
    {{0.13, 0.0, 0.0}, {1.0, -shear, 0.0}, {-3, -3, -3}, {3, 3, 3}},
    /* y = 0.17 for z < 0.33: ends inside cells, along the grid's reference planes */
    {{0.0, 0.17, 0.0}, {0.0, 1.0, 0.0}, {-3, -3, -3}, {3, 3, 0.33}},
    /* tilted */
    {{0.05, -0.3, 0.1}, {0.3, 0.2, 1.0}, {-3, -3, -3}, {3, 3, 3}},
};

/* The signed distance of y from cut k's plane. */
static double plane_side(int k, const double y[3])
{
  const cut *c = cuts + k;
  const double nn = sqrt(c->n[0] * c->n[0] + c->n[1] * c->n[1] + c->n[2] * c->n[2]);
  double s = 0.0;
  for (int d = 0; d < 3; d++)
    s += (y[d] - c->p[d]) * c->n[d] / nn;
  return s;
}

/* Whether the kind-k rule of piece p is the 2-point Gauss rule on boxes (each 8 consecutive
 * points two values per axis, equal weights); *boxes: how many. */
static int gauss_boxes(const fcm_cell_rules *r, fcm_index p, int *boxes)
{
  int n;
  const double *x, *w;
  const unsigned char *fl;
  TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, FCM_RULE_STIFFNESS, &n, &x, &w, &fl));
  while (n > 0 && fl[n - 1])
    n--;
  *boxes = n / 8;
  if (n == 0 || n % 8) return 0;
  for (int b = 0; b < n / 8; b++) {
    const double *y = x + 24 * b;
    for (int i = 0; i < 8; i++) {
      if (w[8 * b + i] != w[8 * b]) return 0;
      for (int d = 0; d < 3; d++)
        if (y[3 * i + d] != y[3 * ((i >> d) & 1 ? 7 : 0) + d]) return 0;
    }
    for (int d = 0; d < 3; d++)
      if (!(y[d] < y[21 + d])) return 0;
  }
  return 1;
}

/* Piece p's stiffness tensor S and mass matrix Mm from its kind rule's authentic points (the
 * weights times scale, for the control); checks weights, the count and the sides of the cuts. */
static void piece_tensors(const fcm_mesh *mesh, const fcm_cell_rules *r, fcm_index p, int kind,
                          int ncut, int max_points, double scale, double S[NS], double Mm[64])
{
  int n, na = 0, side[MAXCUT] = {0, 0, 0};
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
    for (int k = 0; k < ncut; k++) {
      const double s = plane_side(k, y);
      const int sd = s > 1e-12 ? 1 : s < -1e-12 ? -1 : 0;
      /* the rectangle's plane: no side in the cells about its end (z = 0.33) */
      if (k == 1 && y[2] > 0.33 - 0.4) continue;
      TEST_TRUE(!sd || !side[k] || sd == side[k]);
      if (sd) side[k] = sd;
    }
    const double wd = scale * w[j] * fcm_element_jacobian(FCM_ELEMENT_HEX8, X, e, J);
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

static double rel_error(const double *A, const double *B, int n)
{
  double d = 0.0, s = 0.0;
  for (int i = 0; i < n; i++)
    d = fmax(d, fabs(A[i] - B[i])), s = fmax(s, fabs(B[i]));
  return d / s;
}

typedef struct tally {
  fcm_index pieces, gauss, gauss_multi, fitted;
  double worst_s, worst_m, control; /* control: the mass error of the perturbed Gauss rule */
} tally;

/* Rules r against ref piece by piece (pieces matched within their cell by the smallest mass
 * matrix difference). */
static void compare(const fcm_mesh *mesh, const fcm_cell_rules *r, const fcm_cell_rules *ref,
                    int ncut, tally *t)
{
  static double S[NS], Sr[NS];
  memset(t, 0, sizeof *t);
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
      int nb;
      const int gauss = gauss_boxes(r, f + i, &nb);
      piece_tensors(mesh, r, f + i, FCM_RULE_MASS, ncut, 27, 1.0, S, M);
      for (fcm_index j = 0; j < kr; j++) {
        piece_tensors(mesh, ref, fr + j, FCM_RULE_MASS, 0, 1 << 30, 1.0, Sr, Mr);
        const double e = rel_error(M, Mr, 64);
        if (e < best) best = e, bj = j;
      }
      piece_tensors(mesh, ref, fr + bj, FCM_RULE_MASS, 0, 1 << 30, 1.0, Sr, Mr);
      piece_tensors(mesh, r, f + i, FCM_RULE_STIFFNESS, ncut, 27, 1.0, S, M);
      const double es = rel_error(S, Sr, NS);
      if (gauss && t->control == 0.0) {
        piece_tensors(mesh, r, f + i, FCM_RULE_MASS, ncut, 27, 1.0 + 1e-6, S, M);
        t->control = rel_error(M, Mr, 64);
      }
      if (es > 1e-12 || best > 1e-12)
        printf("  cell %lld piece %lld (%s): stiffness off by %.3g, mass by %.3g\n", (long long)c,
               (long long)i, gauss ? "Gauss boxes" : "fitted", es, best);
      t->worst_s = fmax(t->worst_s, es), t->worst_m = fmax(t->worst_m, best);
      t->pieces++;
      t->gauss += gauss;
      t->gauss_multi += gauss && nb > 1;
      t->fitted += !gauss;
    }
  }
}

/* Rules of g cut by the first ncut cuts. */
static fcm_cell_rules *cut_rules(const fcm_mesh *mesh, const fcm_geometry *g, fcm_cell_moments mp,
                                 int simplify, int ms, int shared, int ncut)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.moments = mp;
  o.simplify = simplify ? FCM_CELL_SIMPLIFY_ON : FCM_CELL_SIMPLIFY_OFF;
  o.strength[FCM_RULE_MASS] = ms;
  o.stiffness_on_mass_space = shared;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  for (int k = 0; k < ncut && r; k++) {
    fcm_surface *s = NULL;
    fcm_cell_rules *next = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, cuts[k].p, cuts[k].n, cuts[k].lo, cuts[k].hi, &s));
    if (s) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r, s, &next));
    fcm_surface_destroy(&s);
    fcm_cell_rules_destroy(&r);
    r = next;
  }
  return r;
}

/* The box grid over lo..hi with x sheared by y. */
static fcm_mesh *sheared_grid(void)
{
  const double lo[3] = {-1.2, -1.1, -1.1}, hi[3] = {1.1, 1.2, 1.15};
  const fcm_index n[3] = {7, 8, 6};
  fcm_mesh *box = NULL, *mesh = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &box));
  if (!box) return NULL;
  const fcm_index nn = fcm_mesh_num_nodes(box);
  double *x = malloc(3 * (size_t)nn * sizeof *x);
  TEST_TRUE(x != NULL);
  if (x) {
    memcpy(x, fcm_mesh_coords(box), 3 * (size_t)nn * sizeof *x);
    for (fcm_index i = 0; i < nn; i++)
      x[3 * i] += shear * x[3 * i + 1];
    TEST_OK(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, nn, x, fcm_mesh_num_cells(box),
                                 fcm_mesh_cells(box), &mesh));
  }
  free(x);
  fcm_mesh_destroy(&box);
  return mesh;
}

/* fcm__material_on_face() on parallelograms (a Hex8 prism) against the same polygons with a
 * fifth vertex on their first edge (the fan's tets), on planes z = const across g. */
static void overlap_prisms(const fcm_geometry *g)
{
  fcm__material *m = NULL;
  fcm_mesh *one = NULL;
  fcm__embed_cell cell;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, nrm[3] = {0.0, 0.0, 1.0};
  const fcm_index n1[3] = {1, 1, 1};
  long tests = 0, covered = 0, differ = 0;
  TEST_OK(ctx, fcm__material_create(ctx, g, &m));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n1, &one));
  if (!m || !one) goto done;
  TEST_OK(ctx, fcm__embed_cell_setup(ctx, one, 0, 1e-12, &cell));
  const double sz = 0.17, h = 1e-6;
  for (int iz = 0; iz < 5; iz++)
    for (int iy = 0; iy < 14; iy++)
      for (int ix = 0; ix < 14; ix++) {
        const double z = -0.8 + 0.37 * iz, x0 = -1.15 + 0.165 * ix, y0 = -1.12 + 0.163 * iy;
        const double e1[3] = {sz, 0.0, 0.0}, e2[3] = {0.3 * sz, sz, 0.0};
        double p[4][3], q[5][3];
        for (int d = 0; d < 3; d++) {
          p[0][d] = (d == 0 ? x0 : d == 1 ? y0 : z);
          p[1][d] = p[0][d] + e1[d];
          p[2][d] = p[0][d] + e1[d] + e2[d];
          p[3][d] = p[0][d] + e2[d];
        }
        memcpy(q[0], p[0], sizeof p[0]);
        for (int d = 0; d < 3; d++)
          q[1][d] = 0.5 * (p[0][d] + p[1][d]);
        memcpy(q[2], p[1], 3 * sizeof p[0]);
        const double atol = 0.3 * sz * sz;
        const int a = fcm__material_on_face(ctx, m, &cell, &p[0][0], 4, nrm, h, atol);
        const int b = fcm__material_on_face(ctx, m, &cell, &q[0][0], 5, nrm, h, atol);
        TEST_OK(ctx, fcm__material_status(m));
        tests++;
        covered += a;
        differ += a != b;
      }
  printf("face overlaps: %ld parallelograms, %ld covered, %ld answers differ from the fan's\n",
         tests, covered, differ);
  TEST_TRUE(differ == 0 && covered > 0 && covered < tests);
done:
  fcm__material_destroy(ctx, &m);
  fcm_mesh_destroy(&one);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const double c0[3] = {0.05, -0.03, 0.02};
  fcm_geometry *tets = NULL, *surf = NULL;
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_geometry_create_hollow_ball(ctx, c0, 0.25, 1.0, 0.15, 4, 3, &tets));
  if (!tets) return TEST_RESULT();
  TEST_OK(ctx, fcm_surface_create(ctx, fcm_geometry_num_nodes(tets), fcm_geometry_coords(tets),
                                  fcm_geometry_num_boundary_triangles(tets),
                                  fcm_geometry_boundary_triangles(tets), &s));
  fcm_surface_mesh_options mo = fcm_surface_mesh_options_default();
  mo.volume_mesh = 0;
  TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, s, &mo, &surf));
  fcm_surface_destroy(&s);
  fcm_mesh *mesh = sheared_grid();
  if (!mesh || !surf) return TEST_RESULT();
  overlap_prisms(surf);
  for (int ncut = 2; ncut <= 3; ncut++) {
    fcm_cell_rules *ref = cut_rules(mesh, tets, FCM_CELL_MOMENTS_VOLUME, 0, 6, 0, ncut);
    fcm_cell_rules *rs = cut_rules(mesh, surf, FCM_CELL_MOMENTS_SURFACE, 1, FCM_DEFAULT, 1, ncut);
    fcm_cell_rules *p2 = cut_rules(mesh, surf, FCM_CELL_MOMENTS_SURFACE, 1, FCM_DEFAULT, 0, ncut);
    if (ref && rs && p2) {
      tally t;
      compare(mesh, rs, ref, ncut, &t);
      printf("%d cuts: %lld cut pieces, %lld Gauss box rules (%lld on several boxes), %lld "
             "fitted; stiffness error %.3g, mass error %.3g of the largest entry; the perturbed "
             "Gauss rule's mass error %.3g\n",
             ncut, (long long)t.pieces, (long long)t.gauss, (long long)t.gauss_multi,
             (long long)t.fitted, t.worst_s, t.worst_m, t.control);
      TEST_TRUE(t.worst_s <= 1e-12 && t.worst_m <= 1e-12);
      TEST_TRUE(t.gauss > 0 && t.fitted > 0);
      TEST_TRUE(t.control > 1e-8);
      fcm_index g2 = 0;
      for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(p2); p++) {
        int nb;
        g2 += fcm_cell_rules_class(p2, fcm_cell_rules_piece_cell(p2, p)) == FCM_CELL_CUT &&
              gauss_boxes(p2, p, &nb);
      }
      printf("  without the option: %lld Gauss box rules\n", (long long)g2);
      TEST_TRUE(g2 == 0);
    }
    fcm_cell_rules_destroy(&ref);
    fcm_cell_rules_destroy(&rs);
    fcm_cell_rules_destroy(&p2);
  }
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&surf);
  fcm_geometry_destroy(&tets);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
