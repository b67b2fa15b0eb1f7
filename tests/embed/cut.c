/* Cutting (XFEM) on the quadrature path: material pieces of cells split by cut
 * surfaces. Checked facts: the pieces' volumes add up to the geometry's (a cut never loses
 * or doubles volume), every authentic point of a piece lies on one side of a full planar
 * cut, a cell a plane crosses has two pieces and the other cells one, a cut that ends
 * inside the body separates nothing, pieces connected along the links form the expected
 * number of material components (two halves; the 36 sticks of Ton-That et al. 2024 Fig. 5
 * for a cube of 5 tets and 2x2x2 hexes diced by 10 planes), a cut along cell faces and
 * through nodes is handled, only cells a new cut reaches are integrated again, the cut
 * faces of the pieces cover both sides of the section (area 1 each), and the surface rules
 * of split cells integrate each side's part of the body boundary exactly. */
#include "fcm/embed.h"
#include "test.h"
#include "dice.h"

static fcm_ctx *ctx;

/* Physical integral of 1 and of x_d over piece p (authentic points). */
static void piece_moments(const fcm_mesh *mesh, const fcm_cell_rules *r, fcm_index p, double *vol,
                          double xlo[3], double xhi[3])
{
  int n;
  const double *pts, *w;
  const unsigned char *fl;
  double X[3 * 27], J[9], x[3];
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r, p), X);
  TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, FCM_RULE_STIFFNESS, &n, &pts, &w, &fl));
  *vol = 0.0;
  for (int d = 0; d < 3; d++)
    xlo[d] = HUGE_VAL, xhi[d] = -HUGE_VAL;
  for (int j = 0; j < n; j++) {
    if (fl[j]) continue;
    fcm_element_map(type, X, pts + 3 * j, x);
    *vol += w[j] * fcm_element_jacobian(type, X, pts + 3 * j, J);
    for (int d = 0; d < 3; d++)
      xlo[d] = fmin(xlo[d], x[d]), xhi[d] = fmax(xhi[d], x[d]);
  }
}

static int uf_find(fcm_index *uf, fcm_index a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return (int)a;
}

/* Connected material components: pieces joined along the links; cells with one piece and
 * no link partner next to them count as joined with their face neighbours' single pieces. */
static int components(const fcm_mesh *mesh, const fcm_cell_rules *r)
{
  const fcm_index np = fcm_cell_rules_num_pieces(r), nc = fcm_mesh_num_cells(mesh);
  const int nf = fcm_mesh_get_element_info(mesh)->num_faces;
  const fcm_index *nbr = fcm_mesh_neighbors(mesh), *L = fcm_cell_rules_links(r);
  fcm_index *uf = malloc((size_t)np * sizeof *uf);
  unsigned char *linked = calloc((size_t)np, 1);
  for (fcm_index p = 0; p < np; p++)
    uf[p] = p;
  for (fcm_index l = 0; l < fcm_cell_rules_num_links(r); l++) {
    linked[L[2 * l]] = linked[L[2 * l + 1]] = 1;
    uf[uf_find(uf, L[2 * l])] = uf_find(uf, L[2 * l + 1]);
  }
  for (fcm_index c = 0; c < nc; c++) { /* away from the cuts: one piece per cell */
    fcm_index f0, f1;
    if (fcm_cell_rules_cell_pieces(r, c, &f0) != 1 || linked[f0]) continue;
    for (int f = 0; f < nf; f++) {
      const fcm_index c2 = nbr[nf * c + f];
      if (c2 >= 0 && fcm_cell_rules_cell_pieces(r, c2, &f1) == 1 && !linked[f1])
        uf[uf_find(uf, f0)] = uf_find(uf, f1);
    }
  }
  int k = 0;
  for (fcm_index p = 0; p < np; p++)
    k += uf_find(uf, p) == p;
  free(uf);
  free(linked);
  return k;
}

static double total_volume(const fcm_cell_rules *r)
{
  double v = 0.0;
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(r); p++)
    v += fcm_cell_rules_piece_volume(r, p);
  return v;
}

static fcm_cell_rules_options opts(void)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0;
  return o;
}

/* A unit box body in a 3x3x3 Hex8 grid over [-0.25, 1.25]^3, cut by the plane x = 0.6:
 * the 9 cells of the middle layer split in two, each piece on one side. */
static void plane_cut(fcm_element_type type)
{
  const double lo[3] = {-0.25, -0.25, -0.25}, hi[3] = {1.25, 1.25, 1.25};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 1, 1};
  const fcm_index n[3] = {3, 3, 3}, gn[3] = {3, 3, 3};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_surface *cut = NULL;
  fcm_cell_rules_options o = opts();
  o.surface_strength = 2;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r0));
  const double p0[3] = {0.6, 0.5, 0.5}, nx[3] = {1, 0, 0};
  const double blo[3] = {-0.1, -0.1, -0.1}, bhi[3] = {1.1, 1.1, 1.1};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p0, nx, blo, bhi, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1));
  TEST_TRUE(fcm_cell_rules_num_pieces(r0) == fcm_mesh_num_cells(mesh) || type != FCM_ELEMENT_HEX8);
  TEST_NEAR(total_volume(r1), 1.0, 1e-12, 0);
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r1);
  TEST_NEAR(S->embedded_volume, 1.0, 1e-12, 0);
  int split = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm_index first;
    const fcm_index k = fcm_cell_rules_cell_pieces(r1, c, &first);
    TEST_TRUE(k <= 2);
    split += k == 2;
    for (fcm_index p = first; p < first + k; p++) {
      double v, xl[3], xh[3];
      piece_moments(mesh, r1, p, &v, xl, xh);
      TEST_NEAR(v, fcm_cell_rules_piece_volume(r1, p), 1e-12, 0);
      if (k == 2) TEST_TRUE(xh[0] < 0.6 || xl[0] > 0.6);
    }
    /* split when the uncut material of the cell has points on both sides */
    fcm_index f0;
    if (fcm_cell_rules_cell_pieces(r0, c, &f0) == 1) {
      double v, xl[3], xh[3];
      piece_moments(mesh, r0, f0, &v, xl, xh);
      if (fcm_cell_rules_class(r0, c) == FCM_CELL_UNCUT) { /* catalogue points: the cell */
        double X[3 * 27];
        fcm_mesh_cell_coords(mesh, c, X);
        xl[0] = HUGE_VAL, xh[0] = -HUGE_VAL;
        for (int a = 0; a < fcm_mesh_nodes_per_cell(mesh); a++)
          xl[0] = fmin(xl[0], X[3 * a]), xh[0] = fmax(xh[0], X[3 * a]);
      }
      if (xl[0] < 0.6 && xh[0] > 0.6) TEST_TRUE(k == 2);
    }
  }
  /* the plane crosses 9 Hex8 cells */
  TEST_TRUE(type != FCM_ELEMENT_HEX8 || split == 9);
  TEST_TRUE((int)S->num_split == split);
  /* the cut faces: both sides of the section x = 0.6 of the unit box, area 1 each */
  double area[2] = {0, 0};
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(r1); p++) {
    const double *xi;
    const fcm_index nt = fcm_cell_rules_get_piece_cut_faces(r1, p, &xi);
    double X[3 * 27], v[3][3];
    fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r1, p), X);
    for (fcm_index t = 0; t < nt; t++) {
      for (int k = 0; k < 3; k++)
        fcm_element_map(type, X, xi + 9 * t + 3 * k, v[k]);
      const double a[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
      const double b[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
      const double cx = a[1] * b[2] - a[2] * b[1];
      TEST_NEAR(v[0][0], 0.6, 0, 1e-12); /* on the plane */
      area[cx > 0.0] += 0.5 * fabs(cx);  /* outward +x: the left side's face */
    }
  }
  TEST_NEAR(area[0], 1.0, 1e-12, 0);
  TEST_NEAR(area[1], 1.0, 1e-12, 0);
  /* the boundary of each side: the box's boundary triangles (edges at thirds) that the cut
   * crosses inside a cell are split exactly between the two pieces, so the surface rules
   * (strength 2) integrate 1, x and x^2 over each side's part of the box boundary exactly:
   * x < 0.6: four side faces [0, 0.6] x [0, 1] and the face x = 0; x > 0.6: four side faces
   * [0.6, 1] x [0, 1] and the face x = 1 */
  double sm[2][3] = {{0}};
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(r1); p++) {
    int ns;
    const double *sp, *sw;
    double X[3 * 27], x[3], v, xl[3], xh[3];
    TEST_OK(ctx, fcm_cell_rules_get_piece_surface(r1, p, &ns, &sp, &sw, NULL, NULL));
    fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r1, p), X);
    piece_moments(mesh, r1, p, &v, xl, xh);
    const int right = 0.5 * (xl[0] + xh[0]) > 0.6;
    for (int j = 0; j < ns; j++) {
      fcm_element_map(type, X, sp + 3 * j, x);
      sm[right][0] += sw[j], sm[right][1] += sw[j] * x[0], sm[right][2] += sw[j] * x[0] * x[0];
    }
  }
  TEST_NEAR(sm[0][0], 4 * 0.6 + 1, 1e-12, 0);
  TEST_NEAR(sm[0][1], 4 * 0.18, 1e-12, 0);
  TEST_NEAR(sm[0][2], 4 * 0.072, 1e-12, 0);
  TEST_NEAR(sm[1][0], 4 * 0.4 + 1, 1e-12, 0);
  TEST_NEAR(sm[1][1], 4 * 0.32 + 1, 1e-12, 0);
  TEST_NEAR(sm[1][2], 4 * 0.784 / 3 + 1, 1e-12, 0);
  TEST_TRUE(components(mesh, r1) == 2);
  TEST_TRUE(components(mesh, r0) == 1);
  TEST_TRUE(type != FCM_ELEMENT_HEX8 || S->num_integrated == 9);
  TEST_TRUE(S->num_integrated < fcm_mesh_num_cells(mesh));
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&r1);
  fcm_surface_destroy(&cut);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

/* A rectangle that ends inside the body, and a cut lying in the cell faces x = 0.25 and
 * through the grid nodes: the first separates nothing, the second separates two parts. */
static void partial_and_face_cut(void)
{
  const double lo[3] = {-0.25, -0.25, -0.25}, hi[3] = {1.25, 1.25, 1.25};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 1, 1};
  const fcm_index n[3] = {3, 3, 3}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL, *r2 = NULL;
  fcm_surface *rect = NULL, *face = NULL;
  const fcm_cell_rules_options o = opts();
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r0));
  const double c[3] = {0.6, 0.5, 0.3}, nx[3] = {1, 0, 0}, ay[3] = {0, 1, 0},
               size[2] = {1.4, 0.8}; /* z from -0.1 to 0.7: ends inside */
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, c, nx, ay, size, &rect));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, rect, &r1));
  TEST_NEAR(total_volume(r1), 1.0, 1e-12, 0);
  TEST_TRUE(components(mesh, r1) == 1);
  /* cells below z = 0.25 in the middle layer are split, the ones the cut ends in are not */
  TEST_TRUE(fcm_cell_rules_get_stats(r1)->num_split > 0);
  const double pf[3] = {0.25, 0.5, 0.5}, bl[3] = {-0.1, -0.1, -0.1}, bh[3] = {1.1, 1.1, 1.1};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, pf, nx, bl, bh, &face));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r1, face, &r2));
  TEST_NEAR(total_volume(r2), 1.0, 1e-12, 0);
  TEST_TRUE(components(mesh, r2) == 2);
  TEST_TRUE(fcm_cell_rules_num_cuts(r2) == 2);
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&r1);
  fcm_cell_rules_destroy(&r2);
  fcm_surface_destroy(&rect);
  fcm_surface_destroy(&face);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

/* Ton-That et al. 2024, Fig. 5: the unit cube as the background (5 tets, or one or 2x2x2
 * hexes) and as the body, diced by 5 planes normal to x and 5 normal to y: 36 sticks. */
static void dice(const char *what)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index two[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, dice_mesh(ctx, what, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, two, &g));
  const fcm_cell_rules_options o = opts();
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  if (r) TEST_OK(ctx, dice_cuts(ctx, mesh, g, &r));
  if (r) {
    TEST_NEAR(total_volume(r), 1.0, 1e-12, 0);
    const int k = components(mesh, r);
    if (k != 36) fprintf(stderr, "%s: %d components\n", what, k);
    TEST_TRUE(k == 36);
  }
  fcm_cell_rules_destroy(&r);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

/* Check the cut `cut` of the body of r0: per cell, the pieces' volumes add up to the uncut
 * cell's within 1e-12 and are finite; the number of components. Returns the worst error
 * (HUGE_VAL: not finite or the cut failed) and *comp. */
static int shifted; /* cuts fcm_cell_rules_create_cut() had to shift */

static double check_cut(const fcm_mesh *mesh, const fcm_geometry *g, const fcm_cell_rules *r0,
                        const fcm_surface *cut, int *comp)
{
  fcm_cell_rules *r1 = NULL;
  double worst = HUGE_VAL;
  *comp = 0;
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1));
  if (r1) {
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r1);
    TEST_TRUE(S->num_degenerate == 0 && S->cut_attempts >= 1);
    TEST_TRUE((S->cut_attempts > 1) == (S->cut_shift[0] != 0.0));
    shifted += S->cut_attempts > 1;
    worst = 0.0;
    for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
      fcm_index f0, f1;
      fcm_cell_rules_cell_pieces(r0, c, &f0);
      const fcm_index np = fcm_cell_rules_cell_pieces(r1, c, &f1);
      double v = 0.0;
      for (fcm_index q = f1; q < f1 + np; q++)
        v += fcm_cell_rules_piece_volume(r1, q);
      const double err = fabs(v - fcm_cell_rules_piece_volume(r0, f0));
      worst = isfinite(v) ? fmax(worst, err) : HUGE_VAL;
    }
    *comp = components(mesh, r1);
  }
  fcm_cell_rules_destroy(&r1);
  return worst;
}

/* A V of two half-planes from a ridge along z through (x0, y0), opening towards -x with
 * the half-angle atan(2). */
static void v_cut(double x0, double y0, fcm_surface **cut)
{
  const double a = 4.0 / sqrt(1.25);
  const double v[6][3] = {{x0, y0, -1},
                          {x0, y0, 2},
                          {x0 - 0.5 * a, y0 + a, -1},
                          {x0 - 0.5 * a, y0 + a, 2},
                          {x0 - 0.5 * a, y0 - a, -1},
                          {x0 - 0.5 * a, y0 - a, 2}};
  const fcm_index t[12] = {0, 2, 3, 0, 3, 1, 0, 1, 5, 0, 5, 4};
  TEST_OK(ctx, fcm_surface_create(ctx, 6, &v[0][0], 4, t, cut));
}

static void body(const char *what, fcm_mesh **mesh, fcm_geometry **g, fcm_cell_rules **r0)
{
  const int hex = !strcmp(what, "hex");
  const double lo[3] = {0, 0, 0}, hi[3] = {hex ? 2 : 1, hex ? 2 : 1, 1};
  const fcm_index one[3] = {1, 1, 1}, grid[3] = {2, 2, 1};
  if (hex)
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, grid, mesh));
  else
    TEST_OK(ctx, dice_mesh(ctx, "tet5", mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, one, g));
  const fcm_cell_rules_options o = opts();
  TEST_OK(ctx, fcm_cell_rules_create(ctx, *mesh, *g, &o, r0));
}

/* Near-degenerate planes: through a grid node of a 2 x 2 x 1 Hex8 body and of the cube of 5
 * tets, in five directions (a face normal, tilted by 1e-7, 0.3, and the diagonals), and a V
 * of two half-planes whose ridge passes through the node (its edge planes split too),
 * shifted by 0 and +-1e-15 .. 1e-6. In every case and every cell the pieces' volumes add up to the
 * uncut cell's within 1e-12 (never a lost or doubled volume), every volume is finite, the
 * hex body always falls into exactly two parts, and
 * one cut through a convex body leaves at most two components (a thin slice between the
 * cut and a cell face must not fall apart into several). Before the cut planes classified
 * with the link test's tolerance, 40 of the 170 plane cases failed (a cell lost 1/72 of the
 * body; a slice 1e-11 thick fell into 12 components). */
static void near_cuts(const char *what)
{
  static const double nrm[5][3] = {{1, 0, 0}, {1, 1e-7, 0}, {1, 0.3, 0}, {1, 1, 0}, {1, 1, 1}};
  static const double off[9] = {0, 1e-15, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-6};
  const int hex = !strcmp(what, "hex");
  const double node[3] = {1, hex ? 1 : 0, 0}; /* tet5: the node (1, 0, 0) */
  const double bl[3] = {-1, -1, -1}, bh[3] = {3, 3, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL;
  body(what, &mesh, &g, &r0);
  int bad = 0;
  for (int k = 0; k < 6 && r0; k++)
    for (int j = 0; j < 17; j++) {
      const double dlt = j == 0 ? 0.0 : (j % 2 ? 1 : -1) * off[(j + 1) / 2];
      fcm_surface *cut = NULL;
      if (k < 5) {
        double n[3], ln = 0.0, p[3];
        for (int d = 0; d < 3; d++)
          ln += nrm[k][d] * nrm[k][d];
        for (int d = 0; d < 3; d++)
          n[d] = nrm[k][d] / sqrt(ln), p[d] = node[d] + dlt * n[d];
        TEST_OK(ctx, fcm_surface_create_plane(ctx, p, n, bl, bh, &cut));
      } else {
        v_cut(node[0] + dlt, node[1], &cut);
      }
      int comp = 0;
      const double worst = cut ? check_cut(mesh, g, r0, cut, &comp) : HUGE_VAL;
      /* planes parallel to the cube's face x = 1 or tilted by 1e-7 cut off a slice of the
       * two tets on that face that meets the central tet (which touches the face only along
       * the diagonal) in a needle thinner than the sliver tolerance: the slice's halves in
       * the two face tets are then separate components, rightly. Every cut passes through
       * the hex body's centre node: exactly two bodies there. */
      const int wedge = !hex && k <= 1;
      if (!(worst <= 1e-12) || comp > 2 + wedge || (hex && comp != 2))
        if (bad++ < 10)
          fprintf(stderr, "%s: cut %d, shift %g: volume error %.3g, %d components\n", what, k, dlt,
                  worst, comp);
      fcm_surface_destroy(&cut);
    }
  TEST_TRUE(bad == 0);
  fcm_cell_rules_destroy(&r0);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

static double rnd(unsigned long long *x)
{
  *x = *x * 6364136223846793005ull + 1442695040888963407ull;
  return (double)(*x >> 11) * 0x1.0p-53;
}

/* Random cuts (campaign mode): planes and Vs through random grid nodes, cell centres and
 * edge midpoints of the body, shifted by one of the offsets above, in random directions
 * (half of them snapped to axis-aligned or diagonal ones); each must conserve every cell's
 * volume within 1e-12 with finite volumes. */
static void campaign(const char *what, int n, unsigned seed)
{
  static const double off[9] = {0, 1e-15, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-6};
  const int hex = !strcmp(what, "hex");
  const double bl[3] = {-1, -1, -1}, bh[3] = {3, 3, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL;
  body(what, &mesh, &g, &r0);
  unsigned long long x = seed * 2654435761ull + 1;
  int bad = 0;
  for (int i = 0; i < n && r0; i++) {
    double p[3], d[3];
    for (int k = 0; k < 3; k++) {
      const double ext = k < 2 ? (hex ? 2 : 1) : 1;
      p[k] = floor(rnd(&x) * 5) * 0.25 * ext; /* nodes, midpoints, quarter points */
      d[k] = rnd(&x) - 0.5;
    }
    if (rnd(&x) < 0.5)
      for (int k = 0; k < 3; k++)
        d[k] = floor(rnd(&x) * 3) - 1.0; /* axis-aligned or diagonal */
    if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0) d[0] = 1.0;
    const double s = (rnd(&x) < 0.5 ? -1 : 1) * off[(int)(rnd(&x) * 9)];
    double ln = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int k = 0; k < 3; k++)
      d[k] /= ln, p[k] += s * d[k];
    fcm_surface *cut = NULL;
    const int plane = rnd(&x) < 0.7;
    if (plane)
      TEST_OK(ctx, fcm_surface_create_plane(ctx, p, d, bl, bh, &cut));
    else
      v_cut(p[0], p[1], &cut);
    int comp = 0;
    const double worst = cut ? check_cut(mesh, g, r0, cut, &comp) : HUGE_VAL;
    if (!(worst <= 1e-12) && bad++ < 10)
      fprintf(stderr,
              "%s campaign %d: point (%.17g, %.17g, %.17g) shift %g direction (%.17g, %.17g, "
              "%.17g), %s: volume error %.3g\n",
              what, i, p[0], p[1], p[2], s, d[0], d[1], d[2], plane ? "plane" : "V", worst);
    fcm_surface_destroy(&cut);
  }
  if (bad) fprintf(stderr, "%s campaign: %d of %d cuts failed\n", what, bad, n);
  if (getenv("FCM_TEST_VERBOSE"))
    fprintf(stderr, "%s campaign: %d cuts, %d shifted\n", what, n, shifted);
  shifted = 0;
  TEST_TRUE(bad == 0);
  fcm_cell_rules_destroy(&r0);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

int main(int argc, char **argv)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 2));
  if (argc > 2 && !strcmp(argv[1], "campaign")) { /* embed_cut campaign N [seed] */
    const int n = atoi(argv[2]);
    const unsigned seed = argc > 3 ? (unsigned)atoi(argv[3]) : 1u;
    campaign("hex", n, seed);
    campaign("tet5", n, seed);
    fcm_ctx_destroy(&ctx);
    return TEST_RESULT();
  }
  plane_cut(FCM_ELEMENT_HEX8);
  plane_cut(FCM_ELEMENT_TET4);
  partial_and_face_cut();
  dice("tet5");
  dice("hex1");
  dice("hex8");
  near_cuts("hex");
  near_cuts("tet5");
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
