/* A cut keeps what it does not change. A box body in a 4^3 Hex8 grid over the unit cube, cut in
 * sequence by two tilted planes through it, a plane that crosses cells beside the body without
 * touching its material, and a plane along a grid plane (it separates cells without splitting
 * any). Checked after every cut:
 *   - every piece's stiffness and mass rules integrate every monomial up to their strength
 *     over the piece to within 1e-11 h^3 of the exact integral over the polytope cell ∩ body ∩
 *     the half-spaces of the cuts on the piece's side (tests/geom/exact.h, independent of the
 *     library's clipping), with positive weights and at most M authentic points;
 *   - against fcm_cell_rules_create_cut() without its shortcuts (every reached cell integrated,
 *     every link tested): the same classes, pieces, links and cut faces, bit for bit, and each
 *     cell's rules either bit-identical to that reference or, in a cell the statistics count as
 *     kept, bit-identical to the rules being extended;
 *   - the plane beside the body and the plane along the grid plane integrate no cell, keep the
 *     cells they reach, and leave every rule bit-identical; the latter gives the pieces along
 *     it cut faces and leaves no link across it.
 * With the argument "auto", the same under FCM_CELL_SIMPLIFY_AUTO (which finishes the cut cells
 * after all are built: the kept ones must not be finished again); the bound of M authentic
 * points holds where it simplified. */
#include "embed/embed_impl.h"
#include "fcm/fcm.h"
#include "../geom/exact.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define H    0.25
#define ATOL (1e-11 * H * H * H)

static fcm_ctx *ctx;
static int auto_mode; /* FCM_CELL_SIMPLIFY_AUTO (argument "auto"); else ON */

typedef struct cut_plane {
  double p[3], n[3];
} cut_plane;

static const double body_lo[3] = {0.13, 0.11, 0.17}, body_hi[3] = {0.87, 0.83, 0.91};

/* Monomial integrals (degree <= m) of the authentic points of piece p's rule of kind k into
 * mom, the centroid of the stiffness rule into ctr; checks weights and the point count. */
static void piece_integrals(const fcm_mesh *mesh, const fcm_cell_rules *r, fcm_index p,
                            fcm_rule_kind k, int m, double *mom, double ctr[3])
{
  int n, authentic = 0;
  const double *pts, *w;
  const unsigned char *fl;
  double X[3 * 8], J[9], x[3], v[EXACT_MAX_MONO];
  const int M = exact_num_mono(m);
  fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r, p), X);
  TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, k, &n, &pts, &w, &fl));
  memset(mom, 0, (size_t)M * sizeof *mom);
  for (int j = 0; j < n; j++) {
    if (fl[j]) continue;
    authentic++;
    TEST_TRUE(w[j] > 0.0 && isfinite(w[j]));
    fcm_element_map(FCM_ELEMENT_HEX8, X, pts + 3 * j, x);
    const double wj = w[j] * fcm_element_jacobian(FCM_ELEMENT_HEX8, X, pts + 3 * j, J);
    exact_eval(m, x, v);
    for (int i = 0; i < M; i++)
      mom[i] += wj * v[i];
  }
  /* at most M where simplified (AUTO may leave them as built) */
  TEST_TRUE(authentic <= M || (auto_mode && !fcm_cell_rules_get_stats(r)->decision[k].simplified));
  for (int d = 0; d < 3; d++)
    ctr[d] = mom[1 + d] / mom[0]; /* degree-1 monomials follow 1 (exact_exponents) */
}

/* Every piece of r against the exact moments of its polytope (cuts[0 .. ncuts)). */
static void check_exact(const fcm_mesh *mesh, const fcm_cell_rules *r, const cut_plane *cuts,
                        int ncuts)
{
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(r); p++) {
    const fcm_index c = fcm_cell_rules_piece_cell(r, p);
    double X[3 * 8], ctr[3], mom[EXACT_MAX_MONO], ex[EXACT_MAX_MONO];
    fcm_mesh_cell_coords(mesh, c, X);
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const int m = fcm_cell_rules_strength(r, (fcm_rule_kind)k);
      piece_integrals(mesh, r, p, (fcm_rule_kind)k, m, mom, ctr);
      exact_plane pl[12 + 8];
      int np = 0;
      for (int d = 0; d < 3; d++) /* the cell (corners 0 and 6 of the hex) and the body */
        for (int q = 0; q < 4; q++) {
          const double bound = q == 0   ? X[d]
                               : q == 1 ? X[18 + d]
                               : q == 2 ? body_lo[d]
                                        : body_hi[d];
          const double sign = q % 2 ? 1.0 : -1.0; /* lower bounds: -x_d <= -bound */
          for (int i = 0; i < 3; i++)
            pl[np].n[i] = i == d ? sign : 0.0;
          pl[np++].d = sign * bound;
        }
      for (int j = 0; j < ncuts; j++) { /* the side of each cut the piece's centroid is on */
        const cut_plane *cp = cuts + j;
        const double s = (ctr[0] - cp->p[0]) * cp->n[0] + (ctr[1] - cp->p[1]) * cp->n[1] +
                                     (ctr[2] - cp->p[2]) * cp->n[2] >
                                 0.0
                             ? -1.0
                             : 1.0;
        for (int i = 0; i < 3; i++)
          pl[np].n[i] = s * cp->n[i];
        pl[np++].d = s * (cp->n[0] * cp->p[0] + cp->n[1] * cp->p[1] + cp->n[2] * cp->p[2]);
      }
      memset(ex, 0, sizeof ex);
      exact_polytope_add(pl, np, m, 1e-13, ex);
      const int q = fcm_cell_rules_axis_degree(r, (fcm_rule_kind)k);
      for (int i = 0; i < exact_num_mono(m); i++)
        if (exact_in_axis(i, q)) TEST_NEAR(mom[i], ex[i], 0.0, ATOL);
    }
  }
}

/* Bit equality of the volume and surface rules of piece p of a and piece q of b. */
static int same_rules(const fcm_cell_rules *a, fcm_index p, const fcm_cell_rules *b, fcm_index q)
{
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    int na, nb;
    const double *xa, *xb, *wa, *wb;
    const unsigned char *fa, *fb;
    TEST_OK(ctx, fcm_cell_rules_get_piece(a, p, (fcm_rule_kind)k, &na, &xa, &wa, &fa));
    TEST_OK(ctx, fcm_cell_rules_get_piece(b, q, (fcm_rule_kind)k, &nb, &xb, &wb, &fb));
    if (na != nb) return 0;
    if (na && (memcmp(xa, xb, 3 * (size_t)na * sizeof *xa) ||
               memcmp(wa, wb, (size_t)na * sizeof *wa) || memcmp(fa, fb, (size_t)na)))
      return 0;
  }
  int na, nb;
  const double *xa, *xb, *wa, *wb, *ua, *ub;
  const fcm_index *ta, *tb;
  TEST_OK(ctx, fcm_cell_rules_get_piece_surface(a, p, &na, &xa, &wa, &ua, &ta));
  TEST_OK(ctx, fcm_cell_rules_get_piece_surface(b, q, &nb, &xb, &wb, &ub, &tb));
  return na == nb && (na == 0 || (!memcmp(xa, xb, 3 * (size_t)na * sizeof *xa) &&
                                  !memcmp(wa, wb, (size_t)na * sizeof *wa) &&
                                  !memcmp(ta, tb, (size_t)na * sizeof *ta)));
}

/* Every cell of r has the pieces of prev with bit-identical rules. */
static int all_same(const fcm_cell_rules *r, const fcm_cell_rules *prev)
{
  for (fcm_index c = 0; c < r->num_cells; c++) {
    const fcm_index p0 = r->piece_off[c], q0 = prev->piece_off[c];
    if (r->piece_off[c + 1] - p0 != prev->piece_off[c + 1] - q0 || r->cls[c] != prev->cls[c] ||
        r->fraction[c] != prev->fraction[c])
      return 0;
    for (fcm_index i = 0; i < r->piece_off[c + 1] - p0; i++)
      if (!same_rules(r, p0 + i, prev, q0 + i)) return 0;
  }
  return 1;
}

/* r (with its shortcuts) against ref (without), both extending prev. */
static void check_reference(const fcm_cell_rules *r, const fcm_cell_rules *ref,
                            const fcm_cell_rules *prev)
{
  TEST_TRUE(r->num_pieces == ref->num_pieces && r->num_links == ref->num_links);
  if (r->num_pieces != ref->num_pieces) return;
  TEST_TRUE(
      !memcmp(r->piece_off, ref->piece_off, (size_t)(r->num_cells + 1) * sizeof *r->piece_off));
  TEST_TRUE(!memcmp(r->cls, ref->cls, (size_t)r->num_cells));
  if (r->num_links == ref->num_links)
    TEST_TRUE(!memcmp(r->links, ref->links, 2 * (size_t)r->num_links * sizeof *r->links));
  TEST_TRUE(
      !memcmp(r->piece_parent, ref->piece_parent, (size_t)r->num_pieces * sizeof *r->piece_parent));
  fcm_index kept = 0;
  for (fcm_index c = 0; c < r->num_cells; c++) {
    const fcm_index p0 = r->piece_off[c], np = r->piece_off[c + 1] - p0;
    int as_ref = 1, as_prev = np == prev->piece_off[c + 1] - prev->piece_off[c];
    for (fcm_index i = 0; i < np; i++) {
      as_ref &= same_rules(r, p0 + i, ref, p0 + i);
      as_prev = as_prev && same_rules(r, p0 + i, prev, prev->piece_off[c] + i);
      const double *xa, *xb;
      const fcm_index na = fcm_cell_rules_get_piece_cut_faces(r, p0 + i, &xa),
                      nb = fcm_cell_rules_get_piece_cut_faces(ref, p0 + i, &xb);
      TEST_TRUE(na == nb && (na == 0 || !memcmp(xa, xb, 9 * (size_t)na * sizeof *xa)));
    }
    TEST_TRUE(as_ref || as_prev);
    kept += !as_ref;
  }
  TEST_TRUE(kept <= fcm_cell_rules_get_stats(r)->num_kept);
}

/* A cell the cuts do not reach (r->reached) is one whose box of the reach test (its corners'
 * box widened by the clip tolerance, then by twice the match tolerance of its size) meets no
 * cut triangle's box, and the face polygons the rules keep of such cells lie in that box with
 * the match tolerance around them: the links' queries of those polygons find no triangle
 * without being made. Returns the unreached cells with kept face polygons. */
static fcm_index check_unreached(const fcm_mesh *mesh, const fcm_cell_rules *r, double clip_rtol)
{
  fcm_index polys = 0;
  for (fcm_index c = 0; c < r->num_cells; c++) {
    if (r->reached[c]) continue;
    fcm__embed_cell cell;
    fcm__embed_cell_box(mesh, c, clip_rtol, &cell);
    const double w = 2.0 * FCM__EMBED_MATCH_RTOL * cell.size, m = w / 2.0;
    for (fcm_index t = 0; t < r->num_cut_tris; t++) {
      int meets = 1;
      for (int d = 0; d < 3; d++)
        meets = meets && r->cut_tris[t].lo[d] <= cell.hi[d] + w &&
                r->cut_tris[t].hi[d] >= cell.lo[d] - w;
      TEST_TRUE(!meets);
    }
    if (!r->face_nfp || r->face_nfp[c] <= 0) continue;
    size_t x = 0;
    for (int i = 0; i < r->face_nfp[c]; i++) {
      const int *meta = r->face_meta[c] + FCM__EMBED_FMETA * i;
      for (int k = 0; k < meta[2]; k++)
        for (int d = 0; d < 3; d++) {
          const double v = r->face_x[c][3 * (x + (size_t)k) + d];
          TEST_TRUE(v - m >= cell.lo[d] - w && v + m <= cell.hi[d] + w);
        }
      x += (size_t)(meta[2] + meta[3]);
    }
    polys++;
  }
  return polys;
}

int main(int argc, char **argv)
{
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  /* "auto": FCM_CELL_SIMPLIFY_AUTO, which finishes the cut cells after they are all built */
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  auto_mode = argc > 1 && !strcmp(argv[1], "auto");
  if (auto_mode) o.simplify = FCM_CELL_SIMPLIFY_AUTO;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, blo[3] = {-0.1, -0.1, -0.1},
               bhi[3] = {1.1, 1.1, 1.1};
  const fcm_index n[3] = {4, 4, 4}, nb[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r = NULL;
  fcm_index unreached = 0; /* unreached cells with kept face polygons, over the cuts */
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, body_lo, body_hi, nb, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  check_exact(mesh, r, NULL, 0);
  const cut_plane cuts[4] = {{{0.52, 0.47, 0.5}, {1.0, 0.31, 0.17}},
                             {{0.45, 0.52, 0.5}, {0.2, 1.0, -0.4}},
                             {{0.9, 0.5, 0.5}, {1.0, 0.0, 0.0}},
                             {{0.5, 0.5, 0.5}, {0.0, 1.0, 0.0}}};
  for (int j = 0; j < 4; j++) {
    fcm_surface *s = NULL;
    fcm_cell_rules *next = NULL, *ref = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, cuts[j].p, cuts[j].n, blo, bhi, &s));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r, s, &next));
    TEST_OK(ctx, fcm__cell_rules_create_cut_keep(ctx, mesh, g, r, s, 0, &ref));
    fcm_surface_destroy(&s);
    if (!next || !ref) break;
    const fcm_cell_rules_stats *st = fcm_cell_rules_get_stats(next);
    TEST_TRUE(st->cut_attempts == 1);
    if (getenv("FCM_TEST_VERBOSE"))
      printf("cut %d: %lld integrated, %lld kept, %lld split, %lld pieces, %lld links\n", j,
             (long long)st->num_integrated, (long long)st->num_kept, (long long)st->num_split,
             (long long)st->num_material_pieces, (long long)st->num_links);
    check_exact(mesh, next, cuts, j + 1);
    check_reference(next, ref, r);
    unreached += check_unreached(mesh, next, o.clip_rtol);
    if (j < 2) TEST_TRUE(st->num_split > 0 && st->num_integrated > 0);
    if (j >= 2) { /* beside the body, along a grid plane: nothing changes */
      TEST_TRUE(st->num_integrated == 0 && st->num_kept > 0);
      TEST_TRUE(all_same(next, r));
    }
    if (j == 3) { /* cut faces along y = 0.5, no link across it */
      fcm_index faces = 0;
      for (fcm_index p = 0; p < next->num_pieces; p++)
        faces += fcm_cell_rules_get_piece_cut_faces(next, p, NULL) -
                 fcm_cell_rules_get_piece_cut_faces(r, p, NULL);
      TEST_TRUE(faces > 0);
      for (fcm_index l = 0; l < next->num_links; l++) {
        double ya, yb, X[24];
        fcm_mesh_cell_coords(mesh, next->piece_cell[next->links[2 * l]], X);
        ya = X[1] + 0.5 * H;
        fcm_mesh_cell_coords(mesh, next->piece_cell[next->links[2 * l + 1]], X);
        yb = X[1] + 0.5 * H;
        TEST_TRUE((ya - 0.5) * (yb - 0.5) > 0.0);
      }
    }
    fcm_cell_rules_destroy(&ref);
    fcm_cell_rules_destroy(&r);
    r = next;
  }
  TEST_TRUE(unreached > 0);
  fcm_cell_rules_destroy(&r);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
