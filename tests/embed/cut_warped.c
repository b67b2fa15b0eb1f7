/* A cut surface of many triangles that are nearly, but not exactly, coplanar: a sheet over the
 * ball (fcm_geometry_create_ball(), as tets and as its boundary alone) on an 8^3 Hex8 grid,
 * triangulated on an M x M grid (triangles about 1.5 cells wide at M = 6, 1.1 at M = 8) and
 * warped by amp sin sin across it. Against the same sheet flat (two triangles: no edge inside
 * the cells). Asserts, on both geometries, for M = 6 and 8 and amp = 1e-3 (1/275 of a cell):
 * - the cut goes through, with no degenerate cell left;
 * - every cell has as many material pieces as under the flat sheet (a warp of 1/275 of a cell
 *   moves no piece across a cell corner here): the sheet separates the material in every cell
 *   it crosses, and no sliver between two neighbouring triangles' planes becomes a piece;
 * - each cell's piece volumes, sorted, are the flat sheet's to 5e-3 of the cell's volume (the
 *   volume the warp moves), and the pieces keep the body's volume to 1e-12.
 * One cell alone (fcm__embed_cell_pieces()), a unit cube crossed by 300 random warped sheets
 * (M = 2 .. 8 squares a side over 1.6 cells, 1 to 8 triangles a cell in a row, amp 1e-3 to
 * 1e-2 at a higher frequency, random offsets and slopes; every second sheet with every second
 * triangle's orientation reversed): where the split keeps the cell's volume to 1e-12 (else it
 * is degenerate, and the rules' build shifts the cut; at most 1 in 20 of the sheets), exactly
 * two pieces of more than 1e-14 of the cell, each on one side of the sheet (every part's centre
 * farther than 3 amp from the smooth sheet on its piece's side). The same for 500 sheets over a
 * wider range (amp 1e-5 to 1e-2, 2 to 11 squares a side; at most 1 in 10 degenerate): there
 * sliver parts thinner than the tolerance touch parts on both sides, and a link through a
 * sliver's face joins the two sides unless a shared face must be wider than the tolerance's
 * band (2 of the 500 without that). `embed_cut_warped study N` counts N sheets over the wider
 * range without asserting (lib/docs/cutting.md). A slab thinner than the tolerance lying on the
 * wall of two folded triangles is split by exactly one of them, into a part on each side.
 * The triangles' columns meet on one wall per shared edge, and a triangle splits by its plane
 * only what lies in its column: with each triangle's own perpendicular edge planes, or its
 * plane extended outside its column, cells hold thin slabs between nearly coplanar planes that
 * the tolerance cannot resolve, and the sheet leaves some cells whole (the ball's cases need
 * the column; the single cell's the shared walls too). */
#include "cut_util.h"
#include "embed/embed_impl.h"

#include <stdio.h>

static fcm_ctx *ctx;

/* The sheet z = 0.013 + 0.1 x + 0.05 y + amp sin(1.3 x + 0.2) sin(1.1 y + 0.4) over
 * [-1.2, 1.2]^2 on an M x M grid of squares, two triangles each. */
static void sheet(int M, double amp, fcm_surface **out)
{
  const fcm_index nv = (fcm_index)(M + 1) * (M + 1), nt = 2 * (fcm_index)M * M;
  double *x = malloc(3 * (size_t)nv * sizeof *x);
  fcm_index *t = malloc(3 * (size_t)nt * sizeof *t), k = 0;
  TEST_TRUE(x && t);
  for (int j = 0; j <= M; j++)
    for (int i = 0; i <= M; i++) {
      const double u = -1.2 + 2.4 * i / M, v = -1.2 + 2.4 * j / M;
      double *p = x + 3 * ((size_t)j * (M + 1) + i);
      p[0] = u, p[1] = v;
      p[2] = 0.013 + 0.1 * u + 0.05 * v + amp * sin(1.3 * u + 0.2) * sin(1.1 * v + 0.4);
    }
  for (int j = 0; j < M; j++)
    for (int i = 0; i < M; i++) {
      const fcm_index a = (fcm_index)j * (M + 1) + i, b = a + 1, c = a + M + 1, d = c + 1;
      t[3 * k] = a, t[3 * k + 1] = b, t[3 * k + 2] = d, k++;
      t[3 * k] = a, t[3 * k + 1] = d, t[3 * k + 2] = c, k++;
    }
  TEST_OK(ctx, fcm_surface_create(ctx, nv, x, nt, t, out));
  free(x);
  free(t);
}

static int cmp_double(const void *a, const void *b)
{
  const double p = *(const double *)a, q = *(const double *)b;
  return (p > q) - (p < q);
}

static double total_volume(const fcm_cell_rules *r)
{
  double v = 0.0;
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(r); p++)
    v += fcm_cell_rules_piece_volume(r, p);
  return v;
}

static void run(const fcm_mesh *mesh, const fcm_geometry *g, const char *what)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0;
  fcm_cell_rules *r0 = NULL, *flat = NULL;
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r0));
  sheet(2, 0.0, &s);
  if (r0 && s) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, s, &flat));
  fcm_surface_destroy(&s);
  if (!flat) {
    fcm_cell_rules_destroy(&r0);
    return;
  }
  const double K = pow(2.2 / 8.0, 3.0);
  for (int M = 6; M <= 8; M += 2) {
    fcm_cell_rules *r = NULL;
    sheet(M, 1e-3, &s);
    if (s) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, s, &r));
    fcm_surface_destroy(&s);
    if (!r) continue;
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
    int wrong = 0;
    double worst = 0.0;
    for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
      fcm_index f0, f1;
      const fcm_index n = fcm_cell_rules_cell_pieces(r, c, &f0),
                      nf = fcm_cell_rules_cell_pieces(flat, c, &f1);
      if (n != nf) {
        printf("%s, M = %d: cell %lld has %lld pieces, %lld under the flat sheet\n", what, M,
               (long long)c, (long long)n, (long long)nf);
        wrong++;
        continue;
      }
      double va[8], vb[8];
      TEST_TRUE(n <= 8);
      for (fcm_index q = 0; q < n && q < 8; q++)
        va[q] = fcm_cell_rules_piece_volume(r, f0 + q),
        vb[q] = fcm_cell_rules_piece_volume(flat, f1 + q);
      qsort(va, (size_t)n, sizeof *va, cmp_double);
      qsort(vb, (size_t)n, sizeof *vb, cmp_double);
      for (fcm_index q = 0; q < n && q < 8; q++)
        worst = fmax(worst, fabs(va[q] - vb[q]) / K);
    }
    printf("%s, M = %d: %lld pieces (flat %lld), %lld degenerate cells, %d cells with other "
           "pieces, piece volumes within %.2e of a cell\n",
           what, M, (long long)fcm_cell_rules_num_pieces(r),
           (long long)fcm_cell_rules_num_pieces(flat), (long long)S->num_degenerate, wrong, worst);
    TEST_TRUE(S->num_degenerate == 0 && S->split_change <= 1e-12);
    TEST_TRUE(wrong == 0);
    TEST_TRUE(worst <= 5e-3);
    TEST_NEAR(total_volume(r), total_volume(r0), 1e-12, 0);
    fcm_cell_rules_destroy(&r);
  }
  fcm_cell_rules_destroy(&flat);
  fcm_cell_rules_destroy(&r0);
}

/* Deterministic uniform numbers in [0, 1). */
static double uniform(unsigned long long *state)
{
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*state >> 11) / 9007199254740992.0;
}

/* The unit cube as the body on one Hex8 cell, and its rules: the cuts of one_cell() through
 * fcm_cell_rules_create_cut(). */
typedef struct unit_body {
  const fcm_mesh *mesh;
  fcm_geometry *box;
  fcm_cell_rules *rules;
  fcm_surface *across; /* the plane x = 0.37, cut after a cut taken in its least change */
  int accepted, wrong; /* cuts taken in the attempt of least change; cuts with other pieces */
} unit_body;

/* The cut s through the unit body: it goes through (the split's volume change is within the
 * tolerance's layer, 1e-9 of the cell, if no shift resolves it), into two pieces, each with its
 * centre (from its rule's first moments) on one side of the sheet, farther than 3 amp from it
 * (height h). After a cut taken so, a plane across it goes through at once, without a
 * degenerate cell (the earlier cut's change is not the new one's). */
static void unit_cut(unit_body *U, const fcm_surface *s, double amp, double (*h)(const double *))
{
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, U->mesh, U->box, U->rules, s, &r));
  if (!r) return;
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  U->accepted += S->num_degenerate > 0;
  TEST_TRUE(S->split_change <= 1e-9);
  if (S->num_degenerate > 0 && U->across) { /* the next cut is judged by its own change */
    fcm_cell_rules *r2 = NULL;
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, U->mesh, U->box, r, U->across, &r2));
    const fcm_cell_rules_stats *S2 = r2 ? fcm_cell_rules_get_stats(r2) : NULL;
    TEST_TRUE(S2 && S2->cut_attempts == 1 && S2->num_degenerate == 0);
    fcm_cell_rules_destroy(&r2);
  }
  const fcm_index np = fcm_cell_rules_num_pieces(r);
  int side = 0, ok = np == 2;
  for (fcm_index p = 0; p < np && ok; p++) {
    double mom[4], c[3];
    piece_monomials(ctx, r, p, FCM_RULE_STIFFNESS, 1, mom);
    for (int d = 0; d < 3; d++) /* the rules' points lie in the reference cell [-1, 1]^3 */
      c[d] = 0.5 * (mom[3 - d] / mom[0] + 1.0);
    const double hc = h(c);
    ok = mom[0] > 1e-14 && fabs(hc) > 3.0 * amp && (hc > 0.0 ? 1 : 2) != side;
    side = hc > 0.0 ? 1 : 2;
  }
  if (!ok) printf("unit body: a cut gives %lld pieces, not one on each side\n", (long long)np);
  U->wrong += !ok;
  fcm_cell_rules_destroy(&r);
}

/* The sheet of one_cell() (its parameters in sheet_p) at point x: the height above it. */
static double sheet_p[5];
static double sheet_height(const double *x)
{
  return x[2] - (sheet_p[0] + sheet_p[1] * x[0] + sheet_p[2] * x[1] +
                 sheet_p[3] * sin(7.3 * x[0] + sheet_p[4]) * sin(6.1 * x[1] + 0.4));
}

/* One random warped sheet over the unit cell: its pieces as the rules' build finds them (and,
 * with U, the cut of the unit body). */
static void one_cell(const fcm__embed_cell *cell, int wide, int flip, unsigned long long *state,
                     int *wrong, int *degenerate, unit_body *U)
{
  const int M = 2 + (int)((wide ? 10 : 7) * uniform(state));
  const double amp = pow(10.0, wide ? -5.0 + 3.0 * uniform(state) : -3.0 + uniform(state)),
               z0 = 0.2 + 0.6 * uniform(state), sx = 0.3 * (uniform(state) - 0.5),
               sy = 0.3 * (uniform(state) - 0.5), ph = uniform(state);
  const fcm_index nv = (fcm_index)(M + 1) * (M + 1), nt = 2 * (fcm_index)M * M;
  double *x = malloc(3 * (size_t)nv * sizeof *x);
  fcm_index *tv = malloc(3 * (size_t)nt * sizeof *tv), k = 0;
  unsigned char *inner = malloc(3 * (size_t)nt);
  fcm_index *ref = malloc((size_t)nt * sizeof *ref);
  fcm__cut_wall *walls = malloc(3 * (size_t)nt * sizeof *walls);
  fcm__cut_tri *T = malloc((size_t)nt * sizeof *T);
  fcm__parts *P = calloc(1, sizeof *P);
  fcm__poly *q = malloc(sizeof *q);
  fcm_surface *s = NULL;
  TEST_TRUE(x && tv && inner && ref && walls && T && P && q);
  for (int j = 0; j <= M; j++)
    for (int i = 0; i <= M; i++) {
      const double u = -0.3 + 1.6 * i / M, v = -0.3 + 1.6 * j / M;
      double *p = x + 3 * ((size_t)j * (M + 1) + i);
      p[0] = u, p[1] = v;
      p[2] = z0 + sx * u + sy * v + amp * sin(7.3 * u + ph) * sin(6.1 * v + 0.4);
    }
  for (int j = 0; j < M; j++)
    for (int i = 0; i < M; i++) {
      const fcm_index a = (fcm_index)j * (M + 1) + i, b = a + 1, c = a + M + 1, d = c + 1;
      tv[3 * k] = a, tv[3 * k + 1] = b, tv[3 * k + 2] = d, k++;
      tv[3 * k] = a, tv[3 * k + 1] = flip ? c : d, tv[3 * k + 2] = flip ? d : c, k++;
    }
  TEST_OK(ctx, fcm_surface_create(ctx, nv, x, nt, tv, &s));
  if (s) TEST_OK(ctx, fcm__embed_cut_inner_edges(ctx, s, inner, ref, walls));
  if (s && U) {
    sheet_p[0] = z0, sheet_p[1] = sx, sheet_p[2] = sy, sheet_p[3] = amp, sheet_p[4] = ph;
    unit_cut(U, s, amp, sheet_height);
  }
  fcm__geom_poly_from_cell(FCM_ELEMENT_HEX8, cell->X, q);
  TEST_OK(ctx, fcm__embed_parts_put(ctx, P, 0, q, cell->tol, 0.0, 0));
  P->tcand.ids = malloc((size_t)nt * sizeof *P->tcand.ids);
  P->tcand.cap = (size_t)nt;
  size_t m = 0;
  for (fcm_index t = 0; t < nt && P->tcand.ids; t++) {
    double r[9];
    for (int i = 0; i < 3; i++)
      memcpy(r + 3 * i, x + 3 * tv[3 * ref[t] + i], 3 * sizeof *r);
    if (!fcm__embed_cut_tri_setup(x + 3 * tv[3 * t], x + 3 * tv[3 * t + 1], x + 3 * tv[3 * t + 2],
                                  0, inner + 3 * t, r, walls + 3 * t, T + m))
      continue;
    int meets = 1;
    for (int d = 0; d < 3; d++)
      meets &= !(T[m].hi[d] < cell->lo[d] || T[m].lo[d] > cell->hi[d]);
    if (meets) P->tcand.ids[P->tcand.n++] = (fcm_index)m;
    m++;
  }
  TEST_OK(ctx, fcm__embed_cell_pieces(ctx, cell, T, 0, P));
  double vol[2] = {0.0, 0.0}, total = 0.0;
  int side[2] = {0, 0}, big = 0, mixed = 0;
  for (size_t i = 0; i < P->n; i++) {
    const fcm__poly *pp = P->poly + i;
    double c[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < pp->nv; a++)
      for (int d = 0; d < 3; d++)
        c[d] += pp->x[a][d] / pp->nv;
    const double v = fcm__geom_poly_volume(pp),
                 h = c[2] - (z0 + sx * c[0] + sy * c[1] +
                             amp * sin(7.3 * c[0] + ph) * sin(6.1 * c[1] + 0.4));
    total += v;
    const int pc = P->piece[i];
    if (pc < 2) vol[pc] += v;
    if (pc < 2 && v > 1e-9 && fabs(h) > 3.0 * amp) {
      const int sg = h > 0.0 ? 1 : 2;
      mixed |= side[pc] && side[pc] != sg;
      side[pc] = sg;
    }
  }
  for (int pc = 0; pc < P->num_pieces; pc++) {
    double v = 0.0;
    for (size_t i = 0; i < P->n; i++)
      v += P->piece[i] == pc ? fcm__geom_poly_volume(P->poly + i) : 0.0;
    big += v > 1e-14;
  }
  /* a split that changes the cell's volume is degenerate: the rules' build shifts the cut */
  const int flagged = !(fabs(total - 1.0) <= 1e-12 && P->split_error <= 1e-12);
  *degenerate += flagged;
  if (!flagged && (big != 2 || mixed)) {
    printf("one cell: M = %d, amp = %.3e: %d pieces above 1e-14, sides %s\n", M, amp, big,
           mixed ? "mixed" : "apart");
    (*wrong)++;
  }
  free(P->tcand.ids);
  P->tcand.ids = NULL;
  fcm__embed_parts_free(ctx, P);
  free(P);
  free(q);
  free(T);
  free(walls);
  free(ref);
  free(inner);
  free(tv);
  free(x);
  fcm_surface_destroy(&s);
}

/* A slab 2e-11 thick (the tolerance is 1e-9) lying on the wall of two triangles folded 2e-2
 * along an edge across the unit cell, crossing the surface: it belongs to one triangle's column
 * (left to neither, it would join the surface's two sides), which splits it by its plane into
 * a part on each side, in either order of the triangles. */
static void flat_on_wall(const fcm__embed_cell *cell)
{
  const double x[12] = {-1.0, 0.5, 0.5, 2.0, 0.5, 0.5, 0.5, -1.0, 0.52, 0.5, 2.0, 0.52};
  const fcm_index tv[6] = {0, 1, 2, 1, 0, 3};
  unsigned char inner[6];
  fcm_index ref[2];
  fcm__cut_wall walls[6];
  fcm__cut_tri T[2];
  fcm_surface *s = NULL;
  fcm__parts *P = calloc(1, sizeof *P);
  fcm__poly *q = malloc(sizeof *q);
  TEST_TRUE(P && q);
  TEST_OK(ctx, fcm_surface_create(ctx, 4, x, 2, tv, &s));
  if (!s || !P || !q) goto done;
  TEST_OK(ctx, fcm__embed_cut_inner_edges(ctx, s, inner, ref, walls));
  TEST_TRUE(walls[0].through && walls[3].through && walls[0].owns + walls[3].owns == 1);
  for (int t = 0; t < 2; t++)
    TEST_TRUE(fcm__embed_cut_tri_setup(x + 3 * tv[3 * t], x + 3 * tv[3 * t + 1],
                                       x + 3 * tv[3 * t + 2], 0, inner + 3 * t, NULL, walls + 3 * t,
                                       T + t));
  for (int order = 0; order < 2; order++) {
    const double lo[3] = {0.2, 0.5 - 1e-11, 0.3}, hi[3] = {0.8, 0.5 + 1e-11, 0.7};
    double X[24];
    for (int c = 0; c < 8; c++) { /* the box's corners in the Hex8 order */
      const int at_hi[3] = {(c & 1) ^ (c >> 1 & 1), c >> 1 & 1, c >> 2};
      for (int d = 0; d < 3; d++)
        X[3 * c + d] = at_hi[d] ? hi[d] : lo[d];
    }
    fcm__geom_poly_from_cell(FCM_ELEMENT_HEX8, X, q);
    const double v0 = fcm__geom_poly_volume(q);
    P->n = 0;
    TEST_OK(ctx, fcm__embed_parts_put(ctx, P, 0, q, cell->tol, 0.0, 0));
    for (int k = 0; k < 2; k++)
      for (size_t i = 0, n0 = P->n; i < n0; i++)
        TEST_OK(ctx, fcm__embed_part_split(ctx, cell, T + (order ? 1 - k : k), P, i));
    fcm__embed_parts_compact(P);
    double v = 0.0;
    int above = 0, below = 0;
    for (size_t i = 0; i < P->n; i++) {
      double zlo = HUGE_VAL, zhi = -HUGE_VAL;
      for (int a = 0; a < P->poly[i].nv; a++)
        zlo = fmin(zlo, P->poly[i].x[a][2]), zhi = fmax(zhi, P->poly[i].x[a][2]);
      above += zlo >= 0.5 - 1e-9 && zhi > 0.6;
      below += zhi <= 0.5 + 1e-9 && zlo < 0.4;
      v += fcm__geom_poly_volume(P->poly + i);
    }
    printf("slab on a wall, order %d: %zu parts, %d above the surface, %d below, volume %.3e "
           "(%.1e off)\n",
           order, P->n, above, below, v, fabs(v - v0) / v0);
    TEST_TRUE(P->n == 2 && above == 1 && below == 1);
    TEST_TRUE(fabs(v - v0) <= 1e-9 * v0);
  }
done:
  fcm__embed_parts_free(ctx, P);
  free(P);
  free(q);
  fcm_surface_destroy(&s);
}

int main(int argc, char **argv)
{
  /* "study N": N sheets of amplitude 1e-5 to 1e-2 and 2 to 11 squares a side, counted only */
  const int study = argc > 2 && strcmp(argv[1], "study") == 0 ? atoi(argv[2]) : 0;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-1.1, -1.1, -1.1}, hi[3] = {1.1, 1.1, 1.1}, c0[3] = {0, 0, 0};
  const fcm_index n[3] = {8, 8, 8};
  fcm_mesh *mesh = NULL;
  fcm_geometry *gv = NULL, *gs = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 1.0, 2, &gv));
  if (gv) surface_of(ctx, gv, &gs);
  if (mesh && gv && !study) run(mesh, gv, "tets");
  if (mesh && gs && !study) run(mesh, gs, "surface");
  fcm_geometry_destroy(&gs);
  fcm_geometry_destroy(&gv);
  fcm_mesh_destroy(&mesh);

  const double ulo[3] = {0, 0, 0}, uhi[3] = {1, 1, 1};
  const fcm_index un[3] = {1, 1, 1};
  fcm__embed_cell cell;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, ulo, uhi, un, &mesh));
  if (mesh) {
    TEST_OK(ctx, fcm__embed_cell_setup(ctx, mesh, 0, 1e-10, &cell));
    if (!study) flat_on_wall(&cell);
    unit_body U = {mesh, NULL, NULL, NULL, 0, 0};
    const fcm_index n1[3] = {1, 1, 1};
    const double ac[3] = {0.37, 0.5, 0.5}, an[3] = {1, 0, 0}, aa[3] = {0, 1, 0}, as[2] = {2, 2};
    TEST_OK(ctx, fcm_surface_create_rectangle(ctx, ac, an, aa, as, &U.across));
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.min_fraction = 0.0;
    TEST_OK(ctx, fcm_geometry_create_box(ctx, ulo, uhi, n1, &U.box));
    if (U.box) TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, U.box, &o, &U.rules));
    for (int wide = study > 0; wide < 2; wide++) {
      unsigned long long state = 1;
      int wrong = 0, degenerate = 0;
      const int ns = study > 0 ? study : wide ? 500 : 300;
      U.accepted = U.wrong = 0;
      for (int k = 0; k < ns; k++)
        one_cell(&cell, wide, k % 2, &state, &wrong, &degenerate,
                 U.rules && wide && k % 4 < 2 ? &U : NULL);
      printf("one cell%s: %d of %d warped sheets degenerate (the split changes the volume: the "
             "cut is shifted), %d of the others with other pieces; cut through the unit body: "
             "%d taken within the tolerance's layer (no shift resolved them), %d with other "
             "pieces\n",
             wide ? ", wide range" : "", degenerate, ns, wrong, U.accepted, U.wrong);
      if (!study) {
        TEST_TRUE(wrong == 0 && U.wrong == 0);
        TEST_TRUE(degenerate <= (wide ? ns / 10 : ns / 20));
        TEST_TRUE(!wide || U.accepted > 0); /* the path taken when no shift resolves a cell */
      }
    }
    fcm_cell_rules_destroy(&U.rules);
    fcm_geometry_destroy(&U.box);
    fcm_surface_destroy(&U.across);
  }
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
