/* Cutting a body given by its boundary surface alone (no volume mesh): the same body as a
 * volume geometry (the ball of fcm_geometry_create_ball(), its boundary triangles as the
 * surface) is cut by the same knives, and the two cut-cell rules must agree: every cell has as
 * many pieces, the pieces match one to one, and each matched pair integrates every monomial of
 * reference coordinates up to the rule's strength alike to TOL of the reference cell's volume
 * (both rules are exact for those moments up to their fits' residuals); the pieces form as
 * many material components along the links, and matched pieces have the same cut faces (area,
 * vector area, first moment of area to FACE_TOL): a cut face ends at the body's surface on
 * both paths, and the links between pieces of neighbouring cells join the matched pieces alike.
 * Knives: a tilted plane through the whole body (its
 * edges run outside the body in cells the body reaches: material must not join around them), a
 * rectangle ending inside the body (a crack), a V of two half-planes (non-planar) and a second
 * plane crossing the first one in cells it already split, a square cutting off a cap of the
 * ball whose edges end outside the ball in cells that hold material on both sides, and a
 * square in the air beside the ball, in cells its surface crosses (no cell integrated again,
 * no cut face added). Hex8 and Tet4
 * backgrounds (argument "quadratic": Hex20 and Tet10). A U-shaped body of tets (two prongs
 * joined by a base) whose two prongs lie in one background cell, apart there, is cut across
 * both prongs: the part of the cell beyond the cut holds two separate lumps of the body, which
 * the volume path keeps as two pieces; so must the surface path. A third plane, on the base's
 * face between the prongs, cuts both prongs off the base there: the cell below it is cut again,
 * the one above keeps its pieces (two lumps of one part), and their links must join each
 * lump to its own prong; the cut face on the base's face belongs to the base alone. After
 * each of the U's cuts the embedded surfaces of both paths' spaces move their common points
 * with corresponding bodies (same_surface_bodies()). A finer
 * ball in one cell, cut through, splits one cut face into a hundred polygons. */
#include "cut_util.h"
#include "fcm/fem.h"
#include "space_bodies.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

/* Agreement of matched pieces' moments, relative to the reference cell's volume: the fits of
 * both paths reach 1e-14 relative residual of their moments (set below), the surface moments'
 * rounding is about 1e-15. */
#define TOL 1e-12

/* Agreement of matched pieces' cut faces (area, vector area, first moment of area), relative
 * to the reference cell's volume: both are exact polygons of the same body, split at the
 * cuts' tolerance (1e-9 of the cell size). */
#define FACE_TOL 1e-8

enum { MAX_M = 455 }; /* monomials of degree <= 12 */

static int uf_find(fcm_index *uf, fcm_index a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return (int)a;
}

/* Material components: pieces joined along the links, single pieces of cells without links
 * joined with their face neighbours' (as tests/embed/cut.c counts them). */
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
  for (fcm_index c = 0; c < nc; c++) {
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

/* The cut faces of piece p (reference coordinates): their area, vector area and first moment
 * of area, f[0], f[1 .. 3], f[4 .. 6]. */
static void face_moments(const fcm_cell_rules *r, fcm_index p, double f[7])
{
  const double *xi = NULL;
  const fcm_index n = fcm_cell_rules_get_piece_cut_faces(r, p, &xi);
  memset(f, 0, 7 * sizeof *f);
  for (fcm_index t = 0; t < n; t++) {
    const double *a = xi + 9 * t, *b = a + 3, *c = a + 6;
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double w[3] = {0.5 * (u[1] * v[2] - u[2] * v[1]), 0.5 * (u[2] * v[0] - u[0] * v[2]),
                         0.5 * (u[0] * v[1] - u[1] * v[0])};
    const double area = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    f[0] += area;
    for (int d = 0; d < 3; d++) {
      f[1 + d] += w[d];
      f[4 + d] += area * (a[d] + b[d] + c[d]) / 3.0;
    }
  }
}

/* The rules of the volume path (rv) and the surface path (rs) agree; returns the largest
 * moment difference relative to the reference cell's volume. The pieces' cut faces agree too:
 * the volume path's are the faces of its parts clipped to the body's tets, the surface path's
 * the faces of its parts (which reach beyond the body) cut down to the body. */
static double compare(const fcm_mesh *mesh, const fcm_cell_rules *rv, const fcm_cell_rules *rs,
                      const char *what)
{
  const fcm_index npv = fcm_cell_rules_num_pieces(rv);
  fcm_index *map = malloc(((size_t)npv + 1) * sizeof *map); /* volume piece -> surface piece */
  for (fcm_index p = 0; p < npv; p++)
    map[p] = -1;
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  const double vref = type == FCM_ELEMENT_TET4 || type == FCM_ELEMENT_TET10 ? 1.0 / 6.0 : 8.0;
  double worst = 0.0, mv[MAX_M], ms[MAX_M];
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    fcm_index fv, fs;
    const fcm_index kv = fcm_cell_rules_cell_pieces(rv, c, &fv),
                    ks = fcm_cell_rules_cell_pieces(rs, c, &fs);
    TEST_TRUE_MSG(kv == ks, "%s: cell %lld has %lld pieces on the volume path, %lld on the surface",
                  what, (long long)c, (long long)kv, (long long)ks);
    if (kv != ks) continue;
    TEST_TRUE(fcm_cell_rules_class(rv, c) == fcm_cell_rules_class(rs, c));
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const int m = fcm_cell_rules_strength(rv, (fcm_rule_kind)k);
      TEST_TRUE((m + 1) * (m + 2) * (m + 3) / 6 <= MAX_M);
      unsigned char used[64] = {0};
      int match[64];
      for (fcm_index p = fv; p < fv + kv; p++) {
        const int M = piece_monomials(ctx, rv, p, (fcm_rule_kind)k, m, mv);
        double best = HUGE_VAL;
        int bq = -1;
        for (fcm_index q = 0; q < ks && q < 64; q++) {
          if (used[q]) continue;
          piece_monomials(ctx, rs, fs + q, (fcm_rule_kind)k, m, ms);
          double d = 0.0;
          for (int i = 0; i < M; i++)
            d = fmax(d, fabs(mv[i] - ms[i]) / vref);
          if (d < best) best = d, bq = (int)q;
        }
        if (bq >= 0) used[bq] = 1;
        if (p - fv < 64) match[p - fv] = bq;
        if (k == FCM_RULE_MASS && bq >= 0) map[p] = fs + bq;
        worst = fmax(worst, best);
        TEST_TRUE_MSG(best <= TOL,
                      "%s: cell %lld piece %lld (%s): moments differ by %.3g of the "
                      "reference volume",
                      what, (long long)c, (long long)(p - fv),
                      k == FCM_RULE_MASS ? "mass" : "stiffness", best);
      }
      for (fcm_index p = fv; k == FCM_RULE_MASS && p < fv + kv && p - fv < 64; p++) {
        if (match[p - fv] < 0) continue;
        double a[7], b[7], d = 0.0;
        face_moments(rv, p, a);
        face_moments(rs, fs + match[p - fv], b);
        for (int i = 0; i < 7; i++)
          d = fmax(d, fabs(a[i] - b[i]));
        TEST_TRUE_MSG(d <= FACE_TOL * vref,
                      "%s: cell %lld piece %lld: cut faces differ by %.3g (area %.6g on the "
                      "volume path, %.6g on the surface)",
                      what, (long long)c, (long long)(p - fv), d, a[0], b[0]);
      }
    }
  }
  TEST_TRUE_MSG(components(mesh, rv) == components(mesh, rs),
                "%s: %d components on the volume "
                "path, %d on the surface",
                what, components(mesh, rv), components(mesh, rs));
  /* the same links between the matched pieces */
  const fcm_index nlv = fcm_cell_rules_num_links(rv), nls = fcm_cell_rules_num_links(rs);
  const fcm_index *Lv = fcm_cell_rules_links(rv), *Ls = fcm_cell_rules_links(rs);
  TEST_TRUE_MSG(nlv == nls, "%s: %lld links on the volume path, %lld on the surface", what,
                (long long)nlv, (long long)nls);
  for (fcm_index l = 0; l < nlv; l++) {
    const fcm_index a = map[Lv[2 * l]], b = map[Lv[2 * l + 1]];
    const fcm_index p = a < b ? a : b, q = a < b ? b : a;
    int found = 0;
    for (fcm_index m = 0; m < nls && !found && p >= 0; m++)
      found = Ls[2 * m] == p && Ls[2 * m + 1] == q;
    TEST_TRUE_MSG(found,
                  "%s: the volume path links pieces %lld and %lld (cells %lld and %lld), the "
                  "surface path not their matches",
                  what, (long long)Lv[2 * l], (long long)Lv[2 * l + 1],
                  (long long)fcm_cell_rules_piece_cell(rv, Lv[2 * l]),
                  (long long)fcm_cell_rules_piece_cell(rv, Lv[2 * l + 1]));
  }
  free(map);
  return worst;
}

/* A V of two half-planes from a ridge along z through (x0, y0), opening towards -x. */
static void v_cut(double x0, double y0, fcm_surface **cut)
{
  const double v[6][3] = {{x0, y0, -2},           {x0, y0, 2},
                          {x0 - 1.5, y0 + 2, -2}, {x0 - 1.5, y0 + 2, 2},
                          {x0 - 1.5, y0 - 2, -2}, {x0 - 1.5, y0 - 2, 2}};
  const fcm_index t[12] = {0, 2, 3, 0, 3, 1, 0, 1, 5, 0, 5, 4};
  TEST_OK(ctx, fcm_surface_create(ctx, 6, &v[0][0], 4, t, cut));
}

static void run(fcm_element_type type)
{
  const char *name = type == FCM_ELEMENT_TET4    ? "tet4"
                     : type == FCM_ELEMENT_TET10 ? "tet10"
                     : type == FCM_ELEMENT_HEX20 ? "hex20"
                                                 : "hex8";
  const double lo[3] = {-1.1, -1.1, -1.1}, hi[3] = {1.1, 1.1, 1.1}, c0[3] = {0, 0, 0};
  const fcm_index n[3] = {4, 4, 4};
  fcm_mesh *mesh = NULL;
  fcm_geometry *gv = NULL, *gs = NULL;
  fcm_cell_rules *rv = NULL, *rs = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 1.0, 2, &gv));
  both_paths(ctx, mesh, gv, &gs, &rv, &rs);
  fcm_surface *knife[6] = {NULL, NULL, NULL, NULL, NULL, NULL};
  const double p0[3] = {0.13, 0.05, -0.02}, n0[3] = {1, 0.3, 0.2};
  const double blo[3] = {-1.05, -1.05, -1.05}, bhi[3] = {1.05, 1.05, 1.05};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p0, n0, blo, bhi, &knife[0]));
  const double rc[3] = {-0.3, 0.1, 0.55}, rn[3] = {0.1, 0.2, 1}, ra[3] = {1, 0, 0},
               rsz[2] = {1.2, 0.9};
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, rc, rn, ra, rsz, &knife[1]));
  v_cut(0.45, -0.1, &knife[2]);
  const double p3[3] = {0.0, 0.07, 0.0}, n3[3] = {0.15, 1, -0.25};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p3, n3, blo, bhi, &knife[3]));
  /* the cap z > 0.8 cut off by a square whose edges end outside the ball in cells that hold
   * material on both sides of it */
  const double qc[3] = {0.02, -0.03, 0.8}, qn[3] = {0.05, 0.02, 1}, qa[3] = {1, 0.1, 0},
               qsz[2] = {1.4, 1.4};
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, qc, qn, qa, qsz, &knife[4]));
  /* a square in the air beside the ball (|x| > 1.1 on it) in cells the ball's surface
   * crosses: it splits their parts, but gives no piece a face (the body is not there) */
  const double ac[3] = {0.78, 0.78, -0.27}, an[3] = {1, 1, 0}, aa[3] = {0, 0, 1},
               asz[2] = {0.2, 0.2};
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, ac, an, aa, asz, &knife[5]));
  const char *names[6] = {"plane", "crack", "V", "crossing plane", "cap", "square in the air"};
  for (int k = 0; k < 6; k++) {
    fcm_index faces_before = 0, faces_after = 0;
    for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(rs); p++)
      faces_before += fcm_cell_rules_get_piece_cut_faces(rs, p, NULL);
    fcm_cell_rules *nv = NULL, *ns = NULL;
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, gv, rv, knife[k], &nv));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, gs, rs, knife[k], &ns));
    fcm_cell_rules_destroy(&rv);
    fcm_cell_rules_destroy(&rs);
    rv = nv, rs = ns;
    char what[64];
    snprintf(what, sizeof what, "%s, %s", name, names[k]);
    const double worst = compare(mesh, rv, rs, what);
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(rs);
    for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(rs); p++)
      faces_after += fcm_cell_rules_get_piece_cut_faces(rs, p, NULL);
    if (k == 5)
      TEST_TRUE_MSG(S->num_integrated == 0 && faces_after == faces_before,
                    "%s: %lld cells integrated again, %lld cut-face triangles before, %lld after",
                    what, (long long)S->num_integrated, (long long)faces_before,
                    (long long)faces_after);
    printf("%s: %lld pieces, %d components, %lld cells fitted on surface moments (%lld pieces "
           "split by the boundary instead), moments agree to %.2e of |K_ref|\n",
           what, (long long)fcm_cell_rules_num_pieces(rs), components(mesh, rs),
           (long long)S->num_surface_cells, (long long)S->num_surface_fallbacks, worst);
  }
  for (int k = 0; k < 6; k++)
    fcm_surface_destroy(&knife[k]);
  fcm_cell_rules_destroy(&rv);
  fcm_cell_rules_destroy(&rs);
  fcm_geometry_destroy(&gv);
  fcm_geometry_destroy(&gs);
  fcm_mesh_destroy(&mesh);
}

/* The embedded surfaces of the two paths' cut spaces (tiny copies not constrained), each body
 * translated along x by its own number: a point of both surfaces (the same coordinates, on no
 * cut face, farther than 1e-6 from the plane of every knife so far: nk planes through kp with
 * normals kn) follows bodies that correspond one to one between the two spaces, so the
 * boundary of each lump goes with that lump's piece on both paths. */
static void same_surface_bodies(const fcm_mesh *mesh, const fcm_geometry *gv,
                                const fcm_cell_rules *rv, const fcm_geometry *gs,
                                const fcm_cell_rules *rs, int nk, const double (*kp)[3],
                                const double (*kn)[3], const char *what)
{
  enum { MAX_BODIES = 64 };
  fcm_space_options so = fcm_space_options_default();
  so.constrain_ratio = 0.0;
  fcm_space *sp[2] = {NULL, NULL};
  fcm_embedded_surface *es[2] = {NULL, NULL};
  double *disp[2] = {NULL, NULL};
  int nb[2] = {0, 0};
  const int nn = fcm_mesh_nodes_per_cell(mesh);
  for (int k = 0; k < 2; k++) {
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, k ? rs : rv, &so, &sp[k]));
    TEST_OK(ctx, fcm_embedded_surface_create(sp[k], k ? gs : gv, &es[k]));
    if (!es[k]) goto done;
    fcm_index *body = space_element_bodies(sp[k], &nb[k]);
    double *u = calloc((size_t)fcm_space_num_dofs(sp[k]), sizeof *u);
    for (fcm_index e = 0; e < fcm_space_num_elements(sp[k]); e++) {
      const fcm_index *ed = fcm_space_element_dofs(sp[k], e);
      for (int a = 0; a < nn; a++)
        u[ed[a]] = (double)(body[e] + 1);
    }
    disp[k] = malloc(3 * (size_t)fcm_embedded_surface_num_points(es[k]) * sizeof *disp[k]);
    TEST_OK(ctx, fcm_embedded_surface_eval(es[k], u, disp[k], NULL));
    free(u);
    free(body);
  }
  TEST_TRUE_MSG(nb[0] == nb[1] && nb[0] < MAX_BODIES,
                "%s: %d bodies on the volume path, %d on the surface", what, nb[0], nb[1]);
  int map[MAX_BODIES], inv[MAX_BODIES];
  for (int b = 0; b < MAX_BODIES; b++)
    map[b] = inv[b] = -1;
  fcm_index matched = 0, crossed = 0;
  const fcm_index n0 = fcm_embedded_surface_num_points(es[0]),
                  n1 = fcm_embedded_surface_num_points(es[1]);
  const double *P0 = fcm_embedded_surface_points(es[0]), *P1 = fcm_embedded_surface_points(es[1]);
  const int32_t *f0 = fcm_embedded_surface_cut_flags(es[0]),
                *f1 = fcm_embedded_surface_cut_flags(es[1]);
  for (fcm_index i = 0; i < n0; i++) {
    const double *x = P0 + 3 * i;
    int near = f0[i] != 0;
    for (int c = 0; c < nk && !near; c++) {
      const double nl = sqrt(kn[c][0] * kn[c][0] + kn[c][1] * kn[c][1] + kn[c][2] * kn[c][2]);
      near = fabs((x[0] - kp[c][0]) * kn[c][0] + (x[1] - kp[c][1]) * kn[c][1] +
                  (x[2] - kp[c][2]) * kn[c][2]) <= 1e-6 * nl;
    }
    if (near) continue;
    fcm_index j = 0;
    while (j < n1 && (f1[j] || memcmp(P1 + 3 * j, x, 3 * sizeof *x)))
      j++;
    if (j == n1) continue;
    const double d0 = disp[0][3 * i], d1 = disp[1][3 * j];
    const int b0 = fabs(d0) < MAX_BODIES + 1.0 ? (int)lround(d0) - 1 : -1,
              b1 = fabs(d1) < MAX_BODIES + 1.0 ? (int)lround(d1) - 1 : -1;
    TEST_TRUE_MSG(fabs(d0 - (b0 + 1)) <= 1e-9 && fabs(d1 - (b1 + 1)) <= 1e-9 && b0 >= 0 &&
                      b0 < nb[0] && b1 >= 0 && b1 < nb[1],
                  "%s: point %lld follows no one body (%.17g, %.17g)", what, (long long)i, d0, d1);
    if (!(b0 >= 0 && b0 < MAX_BODIES && b1 >= 0 && b1 < MAX_BODIES)) continue;
    matched++;
    if (map[b0] < 0 && inv[b1] < 0) map[b0] = b1, inv[b1] = b0;
    crossed += map[b0] != b1;
  }
  TEST_TRUE_MSG(matched > 0 && crossed == 0,
                "%s: of %lld surface points of both paths, %lld follow bodies that do not "
                "correspond",
                what, (long long)matched, (long long)crossed);
done:
  for (int k = 0; k < 2; k++) {
    fcm_embedded_surface_destroy(&es[k]);
    fcm_space_destroy(&sp[k]);
    free(disp[k]);
  }
}

/* The box [0.03, 3.01] x [0.02, 2.04] x [0.01, 0.97] of 3 x 2 x 1 Kuhn-split cubes without
 * cube (1, 1, 0): a U with prongs along y from y = 1.03 at x < 1.02 and x > 2.02. */
static void u_body(fcm_geometry **gv)
{
  const double lo[3] = {0.03, 0.02, 0.01}, hi[3] = {3.01, 2.04, 0.97};
  const fcm_index n[3] = {3, 2, 1};
  fcm_geometry *box = NULL;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n, &box));
  const fcm_index nc = fcm_geometry_num_cells(box), *cv = fcm_geometry_cells(box);
  const double *x = fcm_geometry_coords(box);
  fcm_index *kept = malloc(4 * (size_t)nc * sizeof *kept), m = 0;
  for (fcm_index c = 0; c < nc; c++) {
    double g[3] = {0, 0, 0};
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        g[d] += x[3 * cv[4 * c + a] + d] / 4.0;
    if (g[0] > 1.02 && g[0] < 2.02 && g[1] > 1.03) continue; /* the gap between the prongs */
    memcpy(kept + 4 * m++, cv + 4 * c, 4 * sizeof *kept);
  }
  TEST_OK(ctx,
          fcm_geometry_create(ctx, FCM_ELEMENT_TET4, fcm_geometry_num_nodes(box), x, m, kept, gv));
  free(kept);
  fcm_geometry_destroy(&box);
}

/* The U cut by a plane across both prongs, then by a crack ending between the prongs (across
 * the first prong only), in a background of 1 x 2 x 1 cells whose upper cell holds both
 * prongs' ends. */
static void run_u(fcm_element_type type)
{
  const char *name = type == FCM_ELEMENT_TET4 ? "U, tet4" : "U, hex8";
  const double lo[3] = {-0.41, -0.37, -0.33}, hi[3] = {3.43, 2.63, 1.29};
  const fcm_index n[3] = {1, 2, 1};
  fcm_mesh *mesh = NULL;
  fcm_geometry *gv = NULL, *gs = NULL;
  fcm_cell_rules *rv = NULL, *rs = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  u_body(&gv);
  both_paths(ctx, mesh, gv, &gs, &rv, &rs);
  fcm_surface *knife[3] = {NULL, NULL, NULL};
  const double p0[3] = {1.5, 1.75, 0.5}, n0[3] = {-0.08, 1, 0.15};
  const double blo[3] = {-0.2, -0.2, -0.2}, bhi[3] = {3.2, 2.3, 1.2};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p0, n0, blo, bhi, &knife[0]));
  const double rc[3] = {0.6, 1.45, 0.5}, rn[3] = {0.05, 1, 0.1}, ra[3] = {1, 0, 0},
               rsz[2] = {1.8, 2.0};
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, rc, rn, ra, rsz, &knife[1]));
  /* the plane y = 1.03 of the base's face between the prongs: the cell holds the base below
   * it and the prongs above, and its cut face between the prongs lies on the body's surface,
   * on the base's side only */
  const double p2[3] = {1.5, 1.03, 0.5}, n2[3] = {0, 1, 0};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p2, n2, blo, bhi, &knife[2]));
  const char *names[3] = {"plane across both prongs", "crack across one prong",
                          "plane on the base's face"};
  const double kp[3][3] = {{p0[0], p0[1], p0[2]}, {rc[0], rc[1], rc[2]}, {p2[0], p2[1], p2[2]}},
               kn[3][3] = {{n0[0], n0[1], n0[2]}, {rn[0], rn[1], rn[2]}, {n2[0], n2[1], n2[2]}};
  for (int k = 0; k < 3; k++) {
    fcm_cell_rules *nv = NULL, *ns = NULL;
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, gv, rv, knife[k], &nv));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, gs, rs, knife[k], &ns));
    fcm_cell_rules_destroy(&rv);
    fcm_cell_rules_destroy(&rs);
    rv = nv, rs = ns;
    char what[64];
    snprintf(what, sizeof what, "%s, %s", name, names[k]);
    const double worst = compare(mesh, rv, rs, what);
    same_surface_bodies(mesh, gv, rv, gs, rs, k + 1, kp, kn, what);
    printf("%s: %lld pieces (volume path %lld), %d components, moments agree to %.2e of "
           "|K_ref|\n",
           what, (long long)fcm_cell_rules_num_pieces(rs), (long long)fcm_cell_rules_num_pieces(rv),
           components(mesh, rs), worst);
  }
  for (int k = 0; k < 3; k++)
    fcm_surface_destroy(&knife[k]);
  fcm_cell_rules_destroy(&rv);
  fcm_cell_rules_destroy(&rs);
  fcm_geometry_destroy(&gv);
  fcm_geometry_destroy(&gs);
  fcm_mesh_destroy(&mesh);
}

/* A finer ball (4 cubes per radius) in one Hex8 cell (or the six Tet4 cells of one cube), cut
 * through by a tilted plane: a cut face of the Hex8 cell meets about a hundred boundary
 * segments and is split into as many polygons, more than the split's first buffers hold (16
 * polygons, 64 segments), which grow as it goes (the faces' agreement with the volume path
 * checks what the growth copies). */
static void run_fine(fcm_element_type type)
{
  const char *name = type == FCM_ELEMENT_TET4 ? "fine ball, tet4" : "fine ball, hex8";
  const double lo[3] = {-1.1, -1.1, -1.1}, hi[3] = {1.1, 1.1, 1.1}, c0[3] = {0, 0, 0};
  const fcm_index n[3] = {1, 1, 1};
  fcm_mesh *mesh = NULL;
  fcm_geometry *gv = NULL, *gs = NULL;
  fcm_cell_rules *rv = NULL, *rs = NULL, *nv = NULL, *ns = NULL;
  fcm_surface *knife = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 1.0, 4, &gv));
  both_paths(ctx, mesh, gv, &gs, &rv, &rs);
  const double p0[3] = {0.04, -0.03, 0.02}, n0[3] = {0.2, 1, 0.35};
  const double blo[3] = {-1.05, -1.05, -1.05}, bhi[3] = {1.05, 1.05, 1.05};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p0, n0, blo, bhi, &knife));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, gv, rv, knife, &nv));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, gs, rs, knife, &ns));
  const double worst = compare(mesh, nv, ns, name);
  printf("%s, plane: %lld pieces, %d components, moments agree to %.2e of |K_ref|\n", name,
         (long long)fcm_cell_rules_num_pieces(ns), components(mesh, ns), worst);
  fcm_surface_destroy(&knife);
  fcm_cell_rules_destroy(&nv);
  fcm_cell_rules_destroy(&ns);
  fcm_cell_rules_destroy(&rv);
  fcm_cell_rules_destroy(&rs);
  fcm_geometry_destroy(&gv);
  fcm_geometry_destroy(&gs);
  fcm_mesh_destroy(&mesh);
}

int main(int argc, char **argv)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 2));
  if (argc > 1 && !strcmp(argv[1], "quadratic")) { /* embed_cut_surface_quadratic (slow) */
    run(FCM_ELEMENT_HEX20);
    run(FCM_ELEMENT_TET10);
  } else {
    run(FCM_ELEMENT_HEX8);
    run(FCM_ELEMENT_TET4);
    run_u(FCM_ELEMENT_HEX8);
    run_u(FCM_ELEMENT_TET4);
    run_fine(FCM_ELEMENT_HEX8);
    run_fine(FCM_ELEMENT_TET4);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
