/* fcm-cut accuracy: Koschier et al. 2017, Table 1 analogue (see fcm-cut.c). Every monomial of
 * degree <= m over each piece of a tet and a hex cell cut by a planar, a kinked and a spherical
 * surface, by the piece's simplified rule, against exact moments computed here independently:
 * the piece is a convex polyhedron (or the cell minus one) clipped from the cell's tets by
 * half-spaces, and each tet's monomials come from the closed form
 * int lambda^alpha = alpha! 3! |T| / (|alpha| + 3)!. */
#include "fcm-cut.h"

#include "cli.h"

#include <fcm/fcm.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The accuracy study's worst error per (surface, element, strength), and its picture. */
static double acc_err[3][2][9];
static int accuracy_png(const char *path, int max_strength);

/* ---------------------------------------------------------------- exact moments */

/* Monomials x^a y^b z^c of degree <= m in graded order; their count. */
static int num_mono(int m)
{
  return (m + 1) * (m + 2) * (m + 3) / 6;
}

static void mono_exp(int m, int *e)
{
  int k = 0;
  for (int d = 0; d <= m; d++)
    for (int a = d; a >= 0; a--)
      for (int b = d - a; b >= 0; b--)
        e[3 * k] = a, e[3 * k + 1] = b, e[3 * k + 2] = d - a - b, k++;
}

static double fact(int n)
{
  double f = 1.0;
  for (int i = 2; i <= n; i++)
    f *= i;
  return f;
}

/* Add the moments of degree <= m of tet v (4 x 3) to mom: x^a y^b z^c is expanded in the
 * barycentric coordinates (x = sum_i lambda_i v_i) and each term lambda^alpha integrates to
 * alpha! 3! |T| / (|alpha| + 3)!. */
static void tet_moments(const double v[4][3], int m, double *mom)
{
  double e1[3], e2[3], e3[3];
  for (int d = 0; d < 3; d++)
    e1[d] = v[1][d] - v[0][d], e2[d] = v[2][d] - v[0][d], e3[d] = v[3][d] - v[0][d];
  const double vol =
      fabs(e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
           e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])) /
      6.0;
  int ex[3 * 165];
  mono_exp(m, ex);
  /* a polynomial in lambda of degree `deg` as coefficients poly[a][b][c] of
   * l0^a l1^b l2^c l3^(deg-a-b-c), degree <= 8 (the zeroing reaches deg + 1 <= 9) */
  static double poly[10][10][10], next[10][10][10];
  for (int k = 0; k < num_mono(m); k++) {
    /* prod_d (sum_i lambda_i v_i[d])^{e_d}, expanded factor by factor */
    poly[0][0][0] = 1.0;
    int deg = 0;
    for (int d = 0; d < 3; d++)
      for (int r = 0; r < ex[3 * k + d]; r++) {
        for (int a = 0; a <= deg + 1; a++)
          for (int b = 0; a + b <= deg + 1; b++)
            for (int c = 0; a + b + c <= deg + 1; c++)
              next[a][b][c] = 0.0;
        for (int a = 0; a <= deg; a++)
          for (int b = 0; a + b <= deg; b++)
            for (int c = 0; a + b + c <= deg; c++) {
              const double p = poly[a][b][c];
              next[a + 1][b][c] += p * v[0][d];
              next[a][b + 1][c] += p * v[1][d];
              next[a][b][c + 1] += p * v[2][d];
              next[a][b][c] += p * v[3][d];
            }
        deg++;
        for (int a = 0; a <= deg; a++)
          for (int b = 0; a + b <= deg; b++)
            for (int c = 0; a + b + c <= deg; c++)
              poly[a][b][c] = next[a][b][c];
      }
    double sum = 0.0;
    for (int a = 0; a <= deg; a++)
      for (int b = 0; a + b <= deg; b++)
        for (int c = 0; a + b + c <= deg; c++)
          sum += poly[a][b][c] * fact(a) * fact(b) * fact(c) * fact(deg - a - b - c);
    mom[k] += sum * 6.0 * vol / fact(deg + 3);
  }
}

/* A list of tets (12 doubles each). */
typedef struct tets {
  double *x;
  int n, cap;
} tets;

static void tets_add(tets *t, const double *a, const double *b, const double *c, const double *d)
{
  if (t->n == t->cap) {
    t->cap = t->cap ? 2 * t->cap : 64;
    t->x = realloc(t->x, sizeof *t->x * 12 * (size_t)t->cap);
    if (!t->x) abort(); /* an app, not the library: out of memory ends it */
  }
  double *p = t->x + 12 * t->n++;
  memcpy(p, a, 3 * sizeof *p), memcpy(p + 3, b, 3 * sizeof *p);
  memcpy(p + 6, c, 3 * sizeof *p), memcpy(p + 9, d, 3 * sizeof *p);
}

/* Keep the parts of the tets in {n.x <= d}: each tet split by explicit cases (0..4 vertices
 * inside), written independently of the library's polyhedron clipper. */
static void tets_clip(tets *t, const double n[3], double d)
{
  tets out = {NULL, 0, 0};
  for (int k = 0; k < t->n; k++) {
    const double *v = t->x + 12 * k;
    double s[4];
    int in[4], nin = 0, ii[4], oo[4], no = 0;
    for (int i = 0; i < 4; i++) {
      s[i] = n[0] * v[3 * i] + n[1] * v[3 * i + 1] + n[2] * v[3 * i + 2] - d;
      in[i] = s[i] <= 0.0;
      if (in[i])
        ii[nin++] = i;
      else
        oo[no++] = i;
    }
    if (nin == 4) {
      tets_add(&out, v, v + 3, v + 6, v + 9);
      continue;
    }
    if (nin == 0) continue;
      /* the point where edge (i, o) meets the plane */
#define CUTP(P, I, O)                                                                              \
  double P[3];                                                                                     \
  do {                                                                                             \
    const double tt = s[I] / (s[I] - s[O]);                                                        \
    for (int dd = 0; dd < 3; dd++)                                                                 \
      P[dd] = v[3 * (I) + dd] + tt * (v[3 * (O) + dd] - v[3 * (I) + dd]);                          \
  } while (0)
    if (nin == 1) {
      const int a = ii[0];
      CUTP(p, a, oo[0]);
      CUTP(q, a, oo[1]);
      CUTP(r, a, oo[2]);
      tets_add(&out, v + 3 * a, p, q, r);
    } else if (nin == 3) { /* the tet minus a corner: a prism in 3 tets */
      const int o = oo[0], a = ii[0], b = ii[1], c = ii[2];
      CUTP(pa, a, o);
      CUTP(pb, b, o);
      CUTP(pc, c, o);
      tets_add(&out, v + 3 * a, v + 3 * b, v + 3 * c, pa);
      tets_add(&out, v + 3 * b, v + 3 * c, pa, pb);
      tets_add(&out, v + 3 * c, pa, pb, pc);
    } else { /* two in, two out: a wedge in 3 tets */
      const int a = ii[0], b = ii[1], c = oo[0], e = oo[1];
      CUTP(ac, a, c);
      CUTP(ae, a, e);
      CUTP(bc, b, c);
      CUTP(be, b, e);
      tets_add(&out, v + 3 * a, v + 3 * b, ac, ae);
      tets_add(&out, v + 3 * b, ac, ae, bc);
      tets_add(&out, v + 3 * b, ae, bc, be);
    }
#undef CUTP
  }
  free(t->x);
  *t = out;
}

static void tets_moments(const tets *t, int m, double *mom)
{
  memset(mom, 0, sizeof *mom * (size_t)num_mono(m));
  for (int k = 0; k < t->n; k++) {
    double v[4][3];
    memcpy(v, t->x + 12 * k, sizeof v);
    tet_moments((const double(*)[3])v, m, mom);
  }
}

/* ---------------------------------------------------------------- accuracy */

typedef struct cut_case {
  const char *name;
  int nplanes;           /* the inner piece: the cell intersected with these half-spaces */
  double planes[256][4]; /* n, d: n.x <= d (the spherical cut has 128) */
} cut_case;

/* The cut surfaces of the accuracy study, as triangle surfaces, and the half-spaces whose
 * intersection with the cell is the piece on their inner side. */
static fcm_status make_cut(fcm_ctx *ctx, int which, int hex, fcm_surface **surf, cut_case *cc)
{
  fcm_status st = FCM_OK;
  const double c = hex ? 0.5 : 0.25; /* cell centre-ish */
  if (which == 0) {                  /* planar */
    const double p[3] = {c + 0.03, c - 0.02, c + 0.01}, n0[3] = {1.0, 0.3, 0.2};
    const double nl = sqrt(n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2]);
    const double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {1.5, 1.5, 1.5};
    cc->name = "planar";
    cc->nplanes = 1;
    for (int d = 0; d < 3; d++)
      cc->planes[0][d] = n0[d] / nl;
    cc->planes[0][3] = (n0[0] * p[0] + n0[1] * p[1] + n0[2] * p[2]) / nl;
    st = fcm_surface_create_plane(ctx, p, n0, lo, hi, surf);
  } else if (which == 1) { /* kinked: two half-planes meeting along a line inside the cell */
    /* the line through (c, y, c - 0.05) along y; planes with normals (1, 0, 0.6) and
     * (-1, 0, 0.6): the piece below both is a wedge */
    const double L = 3.0, z0 = c - 0.05;
    const double x[6][3] = {{c, -L, z0},
                            {c, L, z0},
                            {c + L, L, z0 + L / 0.6},
                            {c + L, -L, z0 + L / 0.6},
                            {c - L, L, z0 + L / 0.6},
                            {c - L, -L, z0 + L / 0.6}};
    const fcm_index tri[12] = {0, 1, 2, 0, 2, 3, 0, 4, 1, 0, 5, 4};
    cc->name = "kinked";
    cc->nplanes = 2;
    const double n1[3] = {1, 0, -0.6}, n2[3] = {-1, 0, -0.6};
    for (int k = 0; k < 2; k++) {
      const double *n = k ? n2 : n1;
      const double nl = sqrt(n[0] * n[0] + n[2] * n[2]);
      for (int d = 0; d < 3; d++)
        cc->planes[k][d] = n[d] / nl;
      cc->planes[k][3] = (n[0] * c + n[2] * z0) / nl;
    }
    st = fcm_surface_create(ctx, 6, &x[0][0], 4, tri, surf);
  } else { /* spherical: an octahedron refined twice and projected: 128 triangles */
    const double ctr[3] = {hex ? 0.2 : 0.05, hex ? 0.3 : 0.08, hex ? 0.1 : 0.04};
    const double R = hex ? 0.62 : 0.33;
    double(*v)[3] = malloc(sizeof *v * 512);
    fcm_index(*t)[3] = malloc(sizeof *t * 512), (*t2)[3] = malloc(sizeof *t2 * 512);
    int nv = 6, nt = 8;
    const double o[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const fcm_index of[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    memcpy(v, o, sizeof o);
    memcpy(t, of, sizeof of);
    for (int level = 0; level < 2; level++) { /* split every triangle in 4 (midpoints) */
      int n2 = 0;
      for (int k = 0; k < nt; k++) {
        fcm_index m[3];
        for (int e = 0; e < 3; e++) {
          const fcm_index a = t[k][e], b = t[k][(e + 1) % 3];
          double p[3], l = 0;
          for (int d = 0; d < 3; d++)
            p[d] = 0.5 * (v[a][d] + v[b][d]), l += p[d] * p[d];
          l = sqrt(l);
          int found = -1;
          for (int q = 0; q < nv && found < 0; q++)
            if (fabs(v[q][0] - p[0] / l) + fabs(v[q][1] - p[1] / l) + fabs(v[q][2] - p[2] / l) <
                1e-12)
              found = q;
          if (found < 0) {
            for (int d = 0; d < 3; d++)
              v[nv][d] = p[d] / l;
            found = nv++;
          }
          m[e] = found;
        }
        const fcm_index nw[4][3] = {{t[k][0], m[0], m[2]},
                                    {m[0], t[k][1], m[1]},
                                    {m[2], m[1], t[k][2]},
                                    {m[0], m[1], m[2]}};
        memcpy(t2 + n2, nw, sizeof nw);
        n2 += 4;
      }
      memcpy(t, t2, sizeof *t * (size_t)n2);
      nt = n2;
    }
    cc->name = "spherical";
    cc->nplanes = nt;              /* 128 <= 256 planes */
    for (int k = 0; k < nt; k++) { /* outward face planes of the (convex) polyhedron */
      double a[3], b[3], n[3];
      for (int d = 0; d < 3; d++)
        a[d] = v[t[k][1]][d] - v[t[k][0]][d], b[d] = v[t[k][2]][d] - v[t[k][0]][d];
      n[0] = a[1] * b[2] - a[2] * b[1], n[1] = a[2] * b[0] - a[0] * b[2],
      n[2] = a[0] * b[1] - a[1] * b[0];
      const double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      double off = 0;
      for (int d = 0; d < 3; d++) {
        cc->planes[k][d] = n[d] / nl;
        off += cc->planes[k][d] * (ctr[d] + R * v[t[k][0]][d]);
      }
      cc->planes[k][3] = off;
    }
    for (int q = 0; q < nv; q++)
      for (int d = 0; d < 3; d++)
        v[q][d] = ctr[d] + R * v[q][d];
    st = fcm_surface_create(ctx, nv, &v[0][0], nt, &t[0][0], surf);
    free(v);
    free(t);
    free(t2);
  }
  return st;
}

/* The cells of the accuracy study: the unit tet, and the unit cube (as 6 Kuhn tets for the
 * exact moments). */
static const double acc_tet[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
static const fcm_index acc_tet_cell[4] = {0, 1, 2, 3};
static const int acc_kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                   {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
static const double acc_cube[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                      {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};

/* What the accuracy study counts over its pieces, and its CSV (NULL: none). */
typedef struct acc_tally {
  FILE *csv;
  double worst;           /* the largest relative moment error */
  long long rows, over_m; /* pieces, and those with more points than moments */
} acc_tally;

/* The study's cell (hex: the unit cube, else the unit tet) as a one-cell mesh and geometry. */
static fcm_status accuracy_cell(fcm_ctx *ctx, int hex, fcm_mesh **mesh, fcm_geometry **geom)
{
  fcm_status st;
  if (hex) {
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const fcm_index one[3] = {1, 1, 1};
    st = fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, one, mesh);
    if (st == FCM_OK) st = fcm_geometry_create_box(ctx, lo, hi, one, geom);
  } else {
    st = fcm_mesh_create(ctx, FCM_ELEMENT_TET4, 4, &acc_tet[0][0], 1, acc_tet_cell, mesh);
    if (st == FCM_OK)
      st = fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, &acc_tet[0][0], 1, acc_tet_cell, geom);
  }
  return st;
}

/* The exact moments up to degree m of the inner piece of the cell (its intersection with the
 * half-spaces of cc) and of the outer piece (the rest). */
static void exact_moments(int hex, const cut_case *cc, int m, double *inner, double *outer)
{
  const int nm = num_mono(m);
  double whole[165];
  tets cellt = {NULL, 0, 0}, in = {NULL, 0, 0};
  if (hex) {
    for (int k = 0; k < 6; k++)
      tets_add(&cellt, acc_cube[acc_kuhn[k][0]], acc_cube[acc_kuhn[k][1]], acc_cube[acc_kuhn[k][2]],
               acc_cube[acc_kuhn[k][3]]);
  } else {
    tets_add(&cellt, acc_tet[0], acc_tet[1], acc_tet[2], acc_tet[3]);
  }
  for (int k = 0; k < cellt.n; k++)
    tets_add(&in, cellt.x + 12 * k, cellt.x + 12 * k + 3, cellt.x + 12 * k + 6,
             cellt.x + 12 * k + 9);
  for (int p = 0; p < cc->nplanes; p++)
    tets_clip(&in, cc->planes[p], cc->planes[p][3]);
  tets_moments(&cellt, m, whole);
  tets_moments(&in, m, inner);
  for (int k = 0; k < nm; k++)
    outer[k] = whole[k] - inner[k];
  free(cellt.x);
  free(in.x);
}

/* Each piece of the cut rules r (strength m) of the study's cell against the exact piece
 * (inner or outer moments) with the nearer volume centroid, into the tally, acc_err and the
 * CSV; *ok = 0 when the cut does not give 2 pieces (the pieces are then skipped). */
static void check_pieces(const fcm_cell_rules *r, const fcm_mesh *mesh, int hex, int which,
                         const cut_case *cc, int m, const double *inner, const double *outer,
                         int *ok, acc_tally *t)
{
  const int nm = num_mono(m);
  double q[165];
  fcm_index first;
  const fcm_index np = fcm_cell_rules_cell_pieces(r, 0, &first);
  if (np != 2) {
    fprintf(stderr, PROG ": accuracy: %s cut of the %s cell gave %lld pieces, not 2\n", cc->name,
            hex ? "hex8" : "tet4", (long long)np);
    *ok = 0;
  }
  double X[24], J[9], x[3];
  fcm_mesh_cell_coords(mesh, 0, X);
  const fcm_element_type type = hex ? FCM_ELEMENT_HEX8 : FCM_ELEMENT_TET4;
  int ex[3 * 165];
  mono_exp(m, ex);
  for (fcm_index p = first; p < first + np && *ok; p++) {
    int n;
    const double *pts, *w;
    const unsigned char *fl;
    fcm_cell_rules_get_piece(r, p, FCM_RULE_STIFFNESS, &n, &pts, &w, &fl);
    memset(q, 0, sizeof q);
    for (int j = 0; j < n; j++) {
      fcm_element_map(type, X, pts + 3 * j, x);
      const double wd = w[j] * fcm_element_jacobian(type, X, pts + 3 * j, J);
      for (int k = 0; k < nm; k++)
        q[k] += wd * pow(x[0], ex[3 * k]) * pow(x[1], ex[3 * k + 1]) * pow(x[2], ex[3 * k + 2]);
    }
    /* centroid distance to the exact pieces' centroids (moments 1..3 / volume) */
    double din = 0, dout = 0;
    for (int d = 1; d <= 3; d++) {
      din += pow(q[d] / q[0] - inner[d] / inner[0], 2);
      dout += pow(q[d] / q[0] - outer[d] / outer[0], 2);
    }
    const double *E = din < dout ? inner : outer;
    double err = 0.0;
    for (int k = 0; k < nm; k++)
      err = fmax(err, fabs(q[k] - E[k]) / fabs(E[k]));
    t->worst = fmax(t->worst, err);
    acc_err[which][hex][m] = fmax(acc_err[which][hex][m], err);
    t->over_m += n > nm;
    t->rows++;
    if (t->csv)
      fprintf(t->csv, "%s,%s,%d,%lld,%d,%.3e\n", cc->name, hex ? "hex8" : "tet4", m,
              (long long)(p - first), n, err);
  }
}

/* One strength m of one cut (surface surf, half-spaces cc) of the study's cell: the cut cell
 * rules without stabilization, checked piece by piece (check_pieces()). */
static fcm_status accuracy_strength(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                    const fcm_surface *surf, int hex, int which, const cut_case *cc,
                                    int m, int *ok, acc_tally *t)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_STIFFNESS] = o.strength[FCM_RULE_MASS] = m;
  o.min_fraction = 0.0;
  o.stabilization.mode = FCM_STABILIZATION_OFF;
  fcm_cell_rules *r0 = NULL, *r = NULL;
  fcm_status st = fcm_cell_rules_create(ctx, mesh, geom, &o, &r0);
  if (st == FCM_OK) st = fcm_cell_rules_create_cut(ctx, mesh, geom, r0, surf, &r);
  fcm_cell_rules_destroy(&r0);
  if (st != FCM_OK) return st;
  double inner[165], outer[165];
  exact_moments(hex, cc, m, inner, outer);
  check_pieces(r, mesh, hex, which, cc, m, inner, outer, ok, t);
  fcm_cell_rules_destroy(&r);
  return FCM_OK;
}

int fcm_cut_accuracy(fcm_ctx *ctx, const char *csvpath, const char *pngpath, int max_strength)
{
  cli_output *out = NULL;
  acc_tally t = {NULL, 0.0, 0, 0};
  int ok = 1;
  if (csvpath) {
    t.csv = cli_output_open(PROG, csvpath, &out);
    if (!t.csv) return 1;
    fprintf(t.csv, "surface,element,strength,piece,points,max_rel_error\n");
  }
  for (int hex = 0; hex < 2 && ok; hex++) {
    fcm_mesh *mesh = NULL;
    fcm_geometry *geom = NULL;
    fcm_status st = accuracy_cell(ctx, hex, &mesh, &geom);
    for (int which = 0; which < 3 && st == FCM_OK && ok; which++) {
      fcm_surface *surf = NULL;
      static cut_case cc;
      st = make_cut(ctx, which, hex, &surf, &cc);
      for (int m = 1; m <= max_strength && st == FCM_OK; m++)
        st = accuracy_strength(ctx, mesh, geom, surf, hex, which, &cc, m, &ok, &t);
      fcm_surface_destroy(&surf);
    }
    if (st != FCM_OK) {
      fcm_cut_report(ctx);
      ok = 0;
    }
    fcm_geometry_destroy(&geom);
    fcm_mesh_destroy(&mesh);
  }
  if (t.csv && ok && !cli_output_commit(PROG, &out)) ok = 0;
  cli_output_abort(&out);
  if (ok && pngpath && !accuracy_png(pngpath, max_strength)) ok = 0;
  if (!ok) return 1;
  const int pass = t.worst <= 1e-12 && t.over_m == 0;
  printf("accuracy: %lld pieces x strengths, largest relative moment error %.2e (claim <= 1e-12: "
         "%s), pieces with more than M points: %lld\n",
         t.rows, t.worst, t.worst <= 1e-12 ? "holds" : "FAILS", t.over_m);
  return pass ? 0 : 1;
}

static int accuracy_png(const char *path, int max_strength)
{
  static char body[16384];
  static const char *const surf[3] = {"planar", "kinked", "spherical"};
  size_t n = 0;
  for (int w = 0; w < 3; w++)
    for (int h = 0; h < 2; h++) {
      n += (size_t)snprintf(body + n, sizeof body - n, "$A%d%d << EOD\n", w, h);
      for (int m = 1; m <= max_strength; m++)
        n += (size_t)snprintf(body + n, sizeof body - n, "%d %.6e\n", m,
                              fmax(acc_err[w][h][m], 1e-17));
      n += (size_t)snprintf(body + n, sizeof body - n, "EOD\n");
    }
  n += (size_t)snprintf(body + n, sizeof body - n,
                        "set logscale y\nset format y '10^{%%L}'\nset grid\nset xtics 1\n"
                        "set key top left font ',10' opaque box maxrows 4\n"
                        "set xlabel 'strength m'\n"
                        "set ylabel 'largest relative moment error over the pieces'\n"
                        "set yrange [1e-17:1e-10]\nset title 'cut-cell pieces: moments of degree "
                        "<= m (Koschier et al. 2017, Table 1)'\n"
                        "plot 1e-12 with lines lc rgb '#888888' dt 2 title 'claim 1e-12'");
  for (int w = 0; w < 3; w++)
    for (int h = 0; h < 2; h++)
      n += (size_t)snprintf(body + n, sizeof body - n,
                            ", $A%d%d with linespoints lw 2 dt %d title '%s, %s'", w, h, h + 1,
                            surf[w], h ? "hex8" : "tet4");
  return cli_gnuplot_png(PROG, "900,600 font ',11'", path, body);
}
