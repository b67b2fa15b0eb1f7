/* Cuts near grid planes and body faces (XFEM): planes tilted 1e-12 .. 1e-5 off the planes of
 * the background grid and of the body's faces, through grid nodes, edge midpoints, face
 * centres and body vertices, shifted by 0 .. 1e-6 h along their normal, on all four
 * background elements and four bodies (a tet-meshed box, a box of one hexahedron, a ring
 * and a hollow ball), applied once and repeatedly (parallel planes 1e-12 .. 1e-6 apart,
 * crossing planes). Checked in every case, after every cut:
 *   - the cut succeeds (no error, in particular no internal one);
 *   - every background cell keeps its material: the volumes of its pieces add up to its
 *     volume before the cut within 1e-12 of that volume + 1e-13 |K| (pieces flat on a cut,
 *     at most the sliver volume 1e-14 |K| each, are dropped);
 *   - every body of the space (elements joined through shared DOF copies) lies on one side
 *     of every cut plane: its authentic stiffness points are within THICK of that side
 *     (fragments whose copies are all tiny move with the largest copies at their nodes,
 *     fcm_space_options.constrain_ratio: their elements are left out);
 *   - the number of bodies is that of an independent reference: the convex bodies are
 *     split into tets by the planes without any tolerance (vertex signs), each sign vector
 *     with volume is one region; a region extending more than THICK from each plane and
 *     holding more than 8e-9 h^3 (the small-copy constraint's share of a node's support) must
 *     be a body of its own, of its volume within what the cuts' tolerance moves; the others are
 *     thin: their material may form bodies of its own (dust, each no larger than the thin
 *     regions together), join a neighbour or be dropped as slivers. The ring and the
 *     hollow ball are cut by planes that leave material thicker than THICK on both sides,
 *     whose regions are connected: one or two planes through the ring's axis or the hollow
 *     ball's centre give 2 or 4 bodies, a plane across the ring's tube 2.
 * THICK = 1e-6 h (1000 times the cuts' tolerance, 1e-9 of the cell diagonal).
 * The catalogue ("catalogue") holds three configurations that once failed, with their exact
 * body counts: a plane tilted 1e-7 off a grid plane across a box (2 bodies), two parallel
 * planes 1e-7 apart near a face of the box (2, then 3, no error), a grid plane through a
 * ring (2), and two and three crossing planes whose slivers fold over within the tolerance
 * (per-cell volumes).
 * Usage: embed_cut_families catalogue | campaign N [seed] [verbose] [element]
 *                          | one BODY ELEMENT px py pz nx ny nz [px py pz nx ny nz ...]
 *   campaign: N random cases per background element (each body and family in turn);
 *   element (0 .. 3, as below): only that element's cases, the same ones as in the whole
 *   campaign (the earlier elements' cases are drawn, not run), so the four can run at once;
 *   one: the cuts given (BODY 0 tet box, 1 hex box, 2 ring, 3 hollow ball; ELEMENT 0 tet4,
 *   1 tet10, 2 hex8, 3 hex20; the expected count of a hole body is 2 per plane). */
#include "fcm/fcm.h"
#include "test.h"
#include "la/vec3.h"
#include "space_bodies.h"

#define MAX_PLANES 3
#define NELEM      4

static fcm_ctx *ctx;
static int verbose;

static const fcm_element_type elements[NELEM] = {FCM_ELEMENT_TET4, FCM_ELEMENT_TET10,
                                                 FCM_ELEMENT_HEX8, FCM_ELEMENT_HEX20};

static const char *ename(fcm_element_type type)
{
  return fcm_element_get_info(type)->name;
}

/* ---------------------------------------------------------------- random numbers */

static unsigned long long rng_state;

static double urand(void) /* [0, 1) */
{
  rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(rng_state >> 11) / 9007199254740992.0;
}

static int irand(int n)
{
  return (int)(urand() * n) % n;
}

/* ---------------------------------------------------------------- geometry helpers */

static void normalize(double v[3])
{
  const double l = sqrt(fcm__vec3_dot(v, v));
  for (int d = 0; d < 3; d++)
    v[d] /= l;
}

typedef struct plane {
  double p[3], n[3]; /* a point and the unit normal */
} plane;

static double side(const plane *pl, const double x[3])
{
  return (x[0] - pl->p[0]) * pl->n[0] + (x[1] - pl->p[1]) * pl->n[1] + (x[2] - pl->p[2]) * pl->n[2];
}

/* The axis direction e_axis tilted by the angle eps towards a random direction normal to it. */
static void tilted(int axis, double eps, double n[3])
{
  double t[3] = {urand() - 0.5, urand() - 0.5, urand() - 0.5};
  t[axis] = 0.0;
  if (fcm__vec3_dot(t, t) == 0.0) t[(axis + 1) % 3] = 1.0;
  normalize(t);
  for (int d = 0; d < 3; d++)
    n[d] = (d == axis ? cos(eps) : 0.0) + sin(eps) * t[d];
  normalize(n);
  if (urand() < 0.5)
    for (int d = 0; d < 3; d++)
      n[d] = -n[d];
}

/* ---------------------------------------------------------------- the reference regions */

/* Regions of a convex body (the box [lo, hi] as 6 Kuhn tets) cut by planes: per sign vector
 * its volume and, per plane, the largest distance of its points from that plane. */
typedef struct regions {
  const plane *pl;
  int np;
  double vol[1 << MAX_PLANES];
  double thick[1 << MAX_PLANES][MAX_PLANES];
} regions;

static double tet_volume(double T[4][3])
{
  double a[3], b[3], c[3], x[3];
  for (int d = 0; d < 3; d++)
    a[d] = T[1][d] - T[0][d], b[d] = T[2][d] - T[0][d], c[d] = T[3][d] - T[0][d];
  fcm__vec3_cross(a, b, x);
  return fabs(fcm__vec3_dot(x, c)) / 6.0;
}

static void lerp(const double a[3], double sa, const double b[3], double sb, double out[3])
{
  const double t = sa / (sa - sb);
  for (int d = 0; d < 3; d++)
    out[d] = a[d] + t * (b[d] - a[d]);
}

static void split_tet(regions *R, double T[4][3], int k, int code);

static void put_tet(regions *R, const double *a, const double *b, const double *c, const double *e,
                    int k, int code)
{
  double T[4][3];
  memcpy(T[0], a, sizeof T[0]);
  memcpy(T[1], b, sizeof T[1]);
  memcpy(T[2], c, sizeof T[2]);
  memcpy(T[3], e, sizeof T[3]);
  split_tet(R, T, k, code);
}

/* Tet T on the sides `code` of planes 0 .. k-1: split by plane k (vertex signs decide, no
 * tolerance), or record it when k == np. */
static void split_tet(regions *R, double T[4][3], int k, int code)
{
  if (k == R->np) {
    const double v = tet_volume(T);
    if (!(v > 0.0)) return;
    R->vol[code] += v;
    for (int j = 0; j < R->np; j++)
      for (int a = 0; a < 4; a++)
        R->thick[code][j] = fmax(R->thick[code][j], fabs(side(R->pl + j, T[a])));
    return;
  }
  double s[4];
  int pos[4], neg[4], np = 0, nn = 0;
  for (int a = 0; a < 4; a++) {
    s[a] = side(R->pl + k, T[a]);
    if (s[a] > 0.0)
      pos[np++] = a;
    else
      neg[nn++] = a;
  }
  const int up = code | 1 << k;
  if (np == 0 || nn == 0) {
    split_tet(R, T, k + 1, np ? up : code);
    return;
  }
  if (np == 1 || nn == 1) { /* one vertex alone: a tet on its side, a prism on the other */
    const int a = np == 1 ? pos[0] : neg[0];
    const int *o = np == 1 ? neg : pos;
    const int ca = np == 1 ? up : code, co = np == 1 ? code : up;
    double p[3][3];
    for (int i = 0; i < 3; i++)
      lerp(T[a], s[a], T[o[i]], s[o[i]], p[i]);
    put_tet(R, T[a], p[0], p[1], p[2], k + 1, ca);
    put_tet(R, T[o[0]], T[o[1]], T[o[2]], p[0], k + 1, co);
    put_tet(R, T[o[1]], T[o[2]], p[0], p[1], k + 1, co);
    put_tet(R, T[o[2]], p[0], p[1], p[2], k + 1, co);
    return;
  }
  /* two and two: a wedge on each side */
  const int a = pos[0], b = pos[1], c = neg[0], e = neg[1];
  double pac[3], pae[3], pbc[3], pbe[3];
  lerp(T[a], s[a], T[c], s[c], pac);
  lerp(T[a], s[a], T[e], s[e], pae);
  lerp(T[b], s[b], T[c], s[c], pbc);
  lerp(T[b], s[b], T[e], s[e], pbe);
  put_tet(R, T[a], pac, pae, T[b], k + 1, up);
  put_tet(R, pac, pae, T[b], pbc, k + 1, up);
  put_tet(R, pae, T[b], pbc, pbe, k + 1, up);
  put_tet(R, T[c], pac, pbc, T[e], k + 1, code);
  put_tet(R, pac, pbc, T[e], pae, k + 1, code);
  put_tet(R, pbc, T[e], pae, pbe, k + 1, code);
}

/* Regions of the box [lo, hi] cut by the planes: the volumes of those extending more than
 * `thick` from every plane and holding more than vmin (*definite of them, in dvol) and the
 * total volume of the others (*thin_volume, *thin of them). */
static void box_regions(const double lo[3], const double hi[3], const plane *pl, int np,
                        double thick, double vmin, double *dvol, int *definite, int *thin,
                        double *thin_volume)
{
  static const int kuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                 {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  regions R;
  memset(&R, 0, sizeof R);
  R.pl = pl;
  R.np = np;
  for (int t = 0; t < 6; t++) {
    double T[4][3];
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        T[a][d] = kuhn[t][a] >> d & 1 ? hi[d] : lo[d];
    split_tet(&R, T, 0, 0);
  }
  *definite = *thin = 0;
  *thin_volume = 0.0;
  for (int c = 0; c < 1 << np; c++) {
    if (!(R.vol[c] > 0.0)) continue;
    int ok = R.vol[c] > vmin;
    for (int j = 0; j < np; j++)
      ok &= R.thick[c][j] > thick;
    if (ok)
      dvol[(*definite)++] = R.vol[c];
    else
      (*thin)++, *thin_volume += R.vol[c];
  }
}

static int cmp_desc(const void *a, const void *b)
{
  const double x = *(const double *)a, y = *(const double *)b;
  return (x < y) - (x > y);
}

/* ---------------------------------------------------------------- bodies */

typedef struct body {
  const char *name;
  int convex;          /* the box [lo, hi] */
  double lo[3], hi[3]; /* convex: the box; else: the body's centre in lo */
  double mlo[3], mhi[3];
  fcm_index cells[3];
  fcm_geometry *g;
} body;

static double ring_phi(const double x[3], void *user)
{
  (void)user;
  const double r = sqrt(x[0] * x[0] + x[1] * x[1]) - 0.9;
  return sqrt(r * r + x[2] * x[2]) - 0.36;
}

static void make_bodies(body *B)
{
  /* a tet-meshed box (2 x 2 x 2 cubes, Kuhn split) in a 2 x 2 x 2 grid over [0, 2]^3 */
  B[0] = (body){"tet box", 1,         {0.13, 0.21, 0.07}, {1.77, 1.83, 1.91},
                {0, 0, 0}, {2, 2, 2}, {2, 2, 2},          NULL};
  const fcm_index gn[3] = {2, 2, 2};
  TEST_OK(ctx, fcm_geometry_create_box(ctx, B[0].lo, B[0].hi, gn, &B[0].g));
  /* the same box as one hexahedron, in a 3 x 3 x 3 grid over [0, 2]^3 */
  B[1] = (body){"hex box", 1,         {0.13, 0.21, 0.07}, {1.77, 1.83, 1.91},
                {0, 0, 0}, {2, 2, 2}, {3, 3, 3},          NULL};
  double X[24];
  for (int a = 0; a < 8; a++) { /* VTK order: the bottom face counter-clockwise, then the top */
    static const int bit[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                  {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (int d = 0; d < 3; d++)
      X[3 * a + d] = bit[a][d] ? B[1].hi[d] : B[1].lo[d];
  }
  const fcm_index hexc[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_HEX8, 8, X, 1, hexc, &B[1].g));
  /* the ring: a level-set torus (axis z, radii 0.9 and 0.36) in a 6^3 grid over [-1.4, 1.4]^3 */
  B[2] =
      (body){"ring", 0, {0, 0, 0}, {0, 0, 0}, {-1.4, -1.4, -1.4}, {1.4, 1.4, 1.4}, {6, 6, 6}, NULL};
  fcm_level_set_options lo = fcm_level_set_options_default();
  lo.estimate_error = 0;
  TEST_OK(ctx, fcm_geometry_create_from_level_set(ctx, ring_phi, NULL, B[2].mlo, B[2].mhi,
                                                  B[2].cells, &lo, &B[2].g, NULL));
  /* the hollow ball (radii 0.5 and 0.9 around (1, 1, 1), holes along the axes) in a 4^3 grid
   * over [0, 2]^3 */
  B[3] = (body){"hollow ball", 0, {1, 1, 1}, {0, 0, 0}, {0, 0, 0}, {2, 2, 2}, {4, 4, 4}, NULL};
  TEST_OK(ctx, fcm_geometry_create_hollow_ball(ctx, B[3].lo, 0.5, 0.9, 0.15, 4, 2, &B[3].g));
}

/* ---------------------------------------------------------------- one case */

typedef struct setup {
  fcm_mesh *mesh;
  fcm_cell_rules *rules; /* uncut */
} setup;

static void setup_create(const body *b, fcm_element_type type, setup *S)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0;
  o.simplify = FCM_CELL_SIMPLIFY_OFF;
  o.strength[FCM_RULE_STIFFNESS] = 1;
  o.strength[FCM_RULE_MASS] = 1;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, b->mlo, b->mhi, b->cells, &S->mesh));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, S->mesh, b->g, &o, &S->rules));
}

static void setup_destroy(setup *S)
{
  fcm_cell_rules_destroy(&S->rules);
  fcm_mesh_destroy(&S->mesh);
}

static long long cases_run, cuts_applied, shifted, thin_regions, dust_bodies, stuck;

/* Cases and failed cases per element and family (the campaign's summary). */
#define NFAM 8
static const char *const families[NFAM] = {"grid plane",
                                           "body face",
                                           "parallel planes",
                                           "crossing planes",
                                           "plane through the axis",
                                           "two planes through the axis",
                                           "tube plane",
                                           "other"};
static long long fam_cases[NELEM][NFAM], fam_failed[NELEM][NFAM];

static void count_case(fcm_element_type type, const char *what, int failed)
{
  int t = 0, f = 0;
  while (t < NELEM - 1 && elements[t] != type)
    t++;
  while (f < NFAM - 1 && strcmp(families[f], what))
    f++;
  fam_cases[t][f]++;
  fam_failed[t][f] += failed;
}

/* The side range [*lo, *hi] of plane pl over the authentic stiffness points of piece p. */
static void piece_range(const fcm_mesh *mesh, const fcm_cell_rules *r, fcm_index p, const plane *pl,
                        double *lo, double *hi)
{
  int n;
  const double *pts, *w;
  const unsigned char *fl;
  double X[3 * 27], x[3];
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r, p), X);
  *lo = HUGE_VAL, *hi = -HUGE_VAL;
  TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, FCM_RULE_STIFFNESS, &n, &pts, &w, &fl));
  for (int q = 0; q < n; q++) {
    if (fl[q]) continue;
    fcm_element_map(type, X, pts + 3 * q, x);
    *lo = fmin(*lo, side(pl, x)), *hi = fmax(*hi, side(pl, x));
  }
}

/* Apply the cuts pl[0 .. np) one after the other to setup S and check every cut. */
/* 1: the cases are drawn (the same random sequence) but not run */
static int dry;

static void run_case(const body *b, fcm_element_type type, const setup *S, const plane *given,
                     int np, const char *what)
{
  if (dry) return;
  plane pl[MAX_PLANES];
  memcpy(pl, given, (size_t)np * sizeof *pl);
  const double h = (b->mhi[0] - b->mlo[0]) / (double)b->cells[0], thick = 1e-6 * h;
  const fcm_cell_rules *prev = S->rules;
  fcm_cell_rules *owned = NULL;
  const fcm_index ncell = fcm_mesh_num_cells(S->mesh);
  double blo[3], bhi[3], diag = 0.0;
  fcm_geometry_bounding_box(b->g, blo, bhi);
  for (int d = 0; d < 3; d++)
    diag += (bhi[d] - blo[d]) * (bhi[d] - blo[d]);
  diag = sqrt(diag);
  for (int d = 0; d < 3; d++)
    blo[d] -= 0.1 * diag, bhi[d] += 0.1 * diag;
  cases_run++;
  const int failures0 = test_failures_;
  for (int k = 0; k < np; k++) {
    fcm_surface *cut = NULL;
    fcm_cell_rules *next = NULL;
    fcm_space *sp = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, pl[k].p, pl[k].n, blo, bhi, &cut));
    const fcm_status st = fcm_cell_rules_create_cut(ctx, S->mesh, b->g, prev, cut, &next);
    fcm_surface_destroy(&cut);
    if (st != FCM_OK) {
      TEST_FAIL_("%s on %s (%s), cut %d of %d: %s", what, b->name, ename(type), k + 1, np,
                 fcm_ctx_error_message(ctx));
      fcm_ctx_error_clear(ctx);
      break;
    }
    cuts_applied++;
    /* a cut the tolerances cannot resolve is moved by the library (stats.cut_shift): the
     * reference follows it */
    const fcm_cell_rules_stats *cs = fcm_cell_rules_get_stats(next);
    shifted += cs->cut_attempts > 1;
    for (int d = 0; d < 3; d++)
      pl[k].p[d] += cs->cut_shift[d];
    /* every cell keeps its material */
    double X[3 * 27];
    for (fcm_index c = 0; c < ncell; c++) {
      fcm_index f0, f1;
      const fcm_index n0 = fcm_cell_rules_cell_pieces(prev, c, &f0);
      const fcm_index n1 = fcm_cell_rules_cell_pieces(next, c, &f1);
      double v0 = 0.0, v1 = 0.0;
      for (fcm_index p = f0; p < f0 + n0; p++)
        v0 += fcm_cell_rules_piece_volume(prev, p);
      for (fcm_index p = f1; p < f1 + n1; p++)
        v1 += fcm_cell_rules_piece_volume(next, p);
      fcm_mesh_cell_coords(S->mesh, c, X);
      double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
      for (int a = 0; a < fcm_mesh_nodes_per_cell(S->mesh); a++)
        for (int d = 0; d < 3; d++)
          lo[d] = fmin(lo[d], X[3 * a + d]), hi[d] = fmax(hi[d], X[3 * a + d]);
      const double K = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
      if (!(fabs(v1 - v0) <= 1e-12 * v0 + 1e-13 * K))
        TEST_FAIL_("%s on %s (%s), cut %d: cell %lld holds %.17g instead of %.17g (error %.3g)",
                   what, b->name, ename(type), k + 1, (long long)c, v1, v0, fabs(v1 - v0));
    }
    /* bodies: one side of every plane each, as many as the reference */
    TEST_OK(ctx, fcm_space_create_embedded(ctx, S->mesh, next, &sp));
    int nb = 0;
    fcm_index *eb = sp ? space_element_bodies(sp, &nb) : NULL;
    double(*range)[MAX_PLANES][2] = calloc((size_t)nb + 1, sizeof *range);
    for (int i = 0; i < nb; i++)
      for (int j = 0; j <= k; j++)
        range[i][j][0] = HUGE_VAL, range[i][j][1] = -HUGE_VAL;
    for (fcm_index c = 0; sp && c < ncell; c++) {
      fcm_index fe, fp;
      const fcm_index ne = fcm_space_cell_elements(sp, c, &fe);
      fcm_cell_rules_cell_pieces(next, c, &fp);
      for (fcm_index j = 0; j < ne; j++) {
        /* a fragment all of whose copies are tiny moves with the largest copies at its nodes
         * (fcm_space_options.constrain_ratio): it belongs to no side of its own */
        if (fcm_space_element_constrained(sp, fe + j) > 0) {
          stuck++;
          continue;
        }
        for (int i = 0; i <= k; i++) {
          double lo, hi, *r = range[eb[fe + j]][i];
          piece_range(S->mesh, next, fp + j, pl + i, &lo, &hi);
          r[0] = fmin(r[0], lo), r[1] = fmax(r[1], hi);
        }
      }
    }
    if (verbose > 2 && sp) { /* copies shared by elements on opposite sides of the last plane */
      const fcm_index ne = fcm_space_num_elements(sp);
      const int nn = fcm_mesh_nodes_per_cell(S->mesh);
      double *elo = malloc((size_t)ne * sizeof *elo), *ehi = malloc((size_t)ne * sizeof *ehi);
      for (fcm_index c = 0; c < ncell; c++) {
        fcm_index fe, fp;
        const fcm_index nce = fcm_space_cell_elements(sp, c, &fe);
        fcm_cell_rules_cell_pieces(next, c, &fp);
        for (fcm_index j = 0; j < nce; j++)
          piece_range(S->mesh, next, fp + j, pl + k, elo + fe + j, ehi + fe + j);
      }
      for (fcm_index e = 0; e < ne; e++)
        for (fcm_index f = e + 1; f < ne; f++) {
          if (!((elo[e] > 0.0 && ehi[f] < 0.0) || (ehi[e] < 0.0 && elo[f] > 0.0))) continue;
          const fcm_index *de = fcm_space_element_dofs(sp, e), *df = fcm_space_element_dofs(sp, f);
          for (int a = 0; a < nn; a++)
            for (int b2 = 0; b2 < nn; b2++)
              if (de[a] == df[b2])
                printf("  elements %lld (cell %lld, %.3g .. %.3g) and %lld (cell %lld, %.3g .. "
                       "%.3g) share DOF %lld (local nodes %d, %d)\n",
                       (long long)e, (long long)fcm_space_element_cell(sp, e), elo[e], ehi[e],
                       (long long)f, (long long)fcm_space_element_cell(sp, f), elo[f], ehi[f],
                       (long long)de[a], a, b2);
        }
      free(elo);
      free(ehi);
    }
    if (verbose > 2) { /* links joining pieces on opposite sides of the last plane */
      const fcm_index *L = fcm_cell_rules_links(next);
      for (fcm_index l = 0; l < fcm_cell_rules_num_links(next); l++) {
        double r[2][2];
        for (int e = 0; e < 2; e++)
          piece_range(S->mesh, next, L[2 * l + e], pl + k, &r[e][0], &r[e][1]);
        if ((r[0][0] > 0.0 && r[1][1] < 0.0) || (r[0][1] < 0.0 && r[1][0] > 0.0))
          printf("  link %lld - %lld joins sides (%.3g .. %.3g) and (%.3g .. %.3g)\n",
                 (long long)L[2 * l], (long long)L[2 * l + 1], r[0][0], r[0][1], r[1][0], r[1][1]);
      }
    }
    if (verbose > 2 && sp)
      for (fcm_index c = 0; c < ncell; c++) {
        fcm_index fe, fp;
        const fcm_index ne = fcm_space_cell_elements(sp, c, &fe);
        fcm_cell_rules_cell_pieces(next, c, &fp);
        for (fcm_index j = 0; j < ne; j++) {
          double lo, hi;
          piece_range(S->mesh, next, fp + j, pl + k, &lo, &hi);
          printf("  cell %lld piece %lld volume %.3g body %lld side %.3g .. %.3g\n", (long long)c,
                 (long long)(fp + j), fcm_cell_rules_piece_volume(next, fp + j),
                 (long long)eb[fe + j], lo, hi);
        }
      }
    for (int i = 0; i < nb; i++)
      for (int j = 0; j <= k; j++)
        if (range[i][j][0] < -thick && range[i][j][1] > thick)
          TEST_FAIL_("%s on %s (%s), cut %d: body %d spans plane %d (%.3g .. %.3g)", what, b->name,
                     ename(type), k + 1, i, j + 1, range[i][j][0], range[i][j][1]);
    /* the reference: the definite regions, each one body of its volume; the bodies beyond them
     * are dust: material of the thin regions (a cut thinner than the cuts' resolution), each
     * no larger than the thin regions together */
    int definite = 0, thin = 0;
    double dvol[1 << MAX_PLANES], thin_volume = 0.0;
    if (b->convex) {
      /* a region of less than the constraint's share of a node's support (1e-9 of up to 8
       * cells) may be a fragment that moves with its neighbour: not necessarily a body */
      box_regions(b->lo, b->hi, pl, k + 1, thick, 8e-9 * h * h * h, dvol, &definite, &thin,
                  &thin_volume);
    } else { /* the planes through the centre leave 2 and 4 bodies, the tube plane 2 */
      definite = !strcmp(what, "tube plane") ? 2 : 1 << (k + 1);
    }
    double *bvol = calloc((size_t)nb + 1, sizeof *bvol);
    for (fcm_index c = 0; sp && c < ncell; c++) {
      fcm_index fe, fp;
      const fcm_index ne = fcm_space_cell_elements(sp, c, &fe);
      fcm_cell_rules_cell_pieces(next, c, &fp);
      for (fcm_index j = 0; j < ne; j++)
        bvol[eb[fe + j]] += fcm_cell_rules_piece_volume(next, fp + j);
    }
    qsort(bvol, (size_t)nb, sizeof *bvol, cmp_desc);
    qsort(dvol, (size_t)(b->convex ? definite : 0), sizeof *dvol, cmp_desc);

    /* the cuts lie where the vertices within their tolerance (1e-9 of the cell diagonal) of
     * them are taken as on them: each cut moves material by at most that times its section */
    double bd2 = 0.0, blo2[3], bhi2[3];
    fcm_geometry_bounding_box(b->g, blo2, bhi2);
    for (int d = 0; d < 3; d++)
      bd2 += (bhi2[d] - blo2[d]) * (bhi2[d] - blo2[d]);
    const double moved = (k + 1) * 2.0 * 1e-9 * sqrt(3.0) * h * bd2;
    const double dust = thin_volume + moved;
    if (verbose > 2) {
      printf("  bodies:");
      for (int i = 0; i < nb; i++)
        printf(" %.6g", bvol[i]);
      printf("\n  regions:");
      for (int i = 0; i < (b->convex ? definite : 0); i++)
        printf(" %.6g", dvol[i]);
      printf(" (thin %.3g, moved %.3g)\n", thin_volume, moved);
    }
    /* the largest bodies are the definite regions (convex bodies: of their volumes, largest
     * first), the others dust */
    int ok = nb >= definite;
    for (int i = 0; ok && i < definite; i++)
      ok = b->convex ? fabs(bvol[i] - dvol[i]) <= dust + 1e-12 * dvol[i] : bvol[i] > dust;
    for (int i = definite; ok && i < nb; i++)
      ok = bvol[i] <= dust;
    if (!ok)
      TEST_FAIL_("%s on %s (%s), cut %d of %d: %d bodies (the largest %.17g, the %d-th %.17g), "
                 "expected %d regions (the largest %.17g, the last %.17g) and dust of at most "
                 "%.3g",
                 what, b->name, ename(type), k + 1, np, nb, nb > 0 ? bvol[0] : 0.0, definite,
                 nb >= definite && definite > 0 ? bvol[definite - 1] : 0.0, definite,
                 b->convex && definite > 0 ? dvol[0] : 0.0,
                 b->convex && definite > 0 ? dvol[definite - 1] : 0.0, dust);
    thin_regions += thin;
    dust_bodies += nb > definite ? nb - definite : 0;
    free(bvol);
    if (verbose > 1)
      printf("%s on %s (%s) cut %d: %d bodies (reference %d + %d thin), %d attempts\n", what,
             b->name, ename(type), k + 1, nb, definite, thin,
             fcm_cell_rules_get_stats(next)->cut_attempts);
    free(range);
    free(eb);
    fcm_space_destroy(&sp);
    fcm_cell_rules_destroy(&owned);
    owned = next;
    prev = next;
  }
  fcm_cell_rules_destroy(&owned);
  count_case(type, what, test_failures_ > failures0);
  if (test_failures_ > failures0)
    for (int k = 0; k < np; k++)
      fprintf(stderr, "  plane %d: point (%.17g, %.17g, %.17g) normal (%.17g, %.17g, %.17g)\n",
              k + 1, pl[k].p[0], pl[k].p[1], pl[k].p[2], pl[k].n[0], pl[k].n[1], pl[k].n[2]);
}

/* ---------------------------------------------------------------- families */

static const double tilts[] = {0.0, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5};
#define NTILT ((int)(sizeof tilts / sizeof tilts[0]))

static double rand_tilt(void)
{
  return tilts[irand(NTILT)];
}

static double rand_shift(double h) /* 0 or +-10^-12 .. 10^-6 h */
{
  if (urand() < 0.3) return 0.0;
  return (urand() < 0.5 ? -1.0 : 1.0) * pow(10.0, -12.0 + 6.0 * urand()) * h;
}

/* A point of the grid near which planes pass: a node, an edge midpoint or a face centre of a
 * cell, chosen inside the box [lo, hi] of the body (axis `axis` coordinate on a grid plane). */
static void grid_point(const body *b, int axis, const double lo[3], const double hi[3], double p[3])
{
  const double h = (b->mhi[0] - b->mlo[0]) / (double)b->cells[0];
  const int kind = irand(3); /* 0 node, 1 edge midpoint, 2 face centre */
  for (int d = 0; d < 3; d++) {
    const int i0 = (int)ceil((lo[d] - b->mlo[d]) / h), i1 = (int)floor((hi[d] - b->mlo[d]) / h);
    const int i = i1 >= i0 ? i0 + irand(i1 - i0 + 1) : i0;
    double x = b->mlo[d] + i * h;
    if (d != axis && ((kind == 1 && d == (axis + 1) % 3) || kind == 2) && x + 0.5 * h < hi[d])
      x += 0.5 * h;
    p[d] = x;
  }
}

/* One random case of the convex bodies: 1 to 3 cuts of the families. */
static void convex_case(const body *b, fcm_element_type type, const setup *S)
{
  plane pl[MAX_PLANES];
  const double h = (b->mhi[0] - b->mlo[0]) / (double)b->cells[0];
  const int family = irand(4), np = family == 3 ? 2 + irand(2) : 1 + irand(2);
  const char *what = "";
  for (int k = 0; k < np; k++) {
    const int axis = irand(3);
    const double eps = rand_tilt(), sh = rand_shift(h);
    switch (family) {
    case 0: /* near a grid plane through a node, an edge midpoint or a face centre */
      what = "grid plane";
      grid_point(b, axis, b->lo, b->hi, pl[k].p);
      break;
    case 1: /* near a face of the body, through one of its vertices */
      what = "body face";
      for (int d = 0; d < 3; d++)
        pl[k].p[d] = urand() < 0.5 ? b->lo[d] : b->hi[d];
      break;
    case 2: /* parallel planes 1e-12 .. 1e-6 apart near a body face or a grid plane */
      what = "parallel planes";
      if (k == 0) {
        if (urand() < 0.5)
          for (int d = 0; d < 3; d++)
            pl[k].p[d] = urand() < 0.5 ? b->lo[d] : b->hi[d];
        else
          grid_point(b, axis, b->lo, b->hi, pl[k].p);
        tilted(axis, eps, pl[k].n);
        for (int d = 0; d < 3; d++)
          pl[k].p[d] += sh * pl[k].n[d];
      } else {
        pl[k] = pl[k - 1];
        const double gap = pow(10.0, -12.0 + 6.0 * urand()) * h;
        for (int d = 0; d < 3; d++)
          pl[k].p[d] -= gap * pl[k].n[d];
      }
      continue;
    default: /* crossing knives: near-grid planes on different axes */
      what = "crossing planes";
      grid_point(b, (axis + k) % 3, b->lo, b->hi, pl[k].p);
      tilted((axis + k) % 3, eps, pl[k].n);
      for (int d = 0; d < 3; d++)
        pl[k].p[d] += sh * pl[k].n[d];
      continue;
    }
    tilted(axis, eps, pl[k].n);
    for (int d = 0; d < 3; d++)
      pl[k].p[d] += sh * pl[k].n[d];
  }
  run_case(b, type, S, pl, np, what);
}

/* One random case of the ring or the hollow ball: one or two planes through the axis or the
 * centre, near grid planes; or (ring) one plane across the tube near a grid plane z = c. */
static void hole_case(const body *b, fcm_element_type type, const setup *S)
{
  plane pl[2];
  const double h = (b->mhi[0] - b->mlo[0]) / (double)b->cells[0];
  const double *c = b->lo; /* the centre */
  if (!strcmp(b->name, "ring") && urand() < 0.3) {
    /* z = c near a node or an edge midpoint, |c| <= h / 2 (both sides thicker than 0.1) */
    const double zc = (irand(3) - 1) * 0.5 * h;
    pl[0].p[0] = pl[0].p[1] = 0.0;
    tilted(2, rand_tilt(), pl[0].n);
    pl[0].p[2] = zc + rand_shift(h) * pl[0].n[2];
    run_case(b, type, S, pl, 1, "tube plane");
    return;
  }
  const int np = 1 + irand(2), axis0 = irand(2);
  for (int k = 0; k < np; k++) {
    const int axis = (axis0 + k) % 2;
    tilted(axis, rand_tilt(), pl[k].n);
    const double sh = rand_shift(h);
    /* through the centre, or through the nodes or edge midpoints next to it: planes within
     * h / 2 of the axis, which the ring's hole (radius 0.54) and the ball's cavity (0.5)
     * keep apart from the material's boundary */
    const double off = irand(2) * 0.5 * h * (urand() < 0.5 ? -1 : 1);
    for (int d = 0; d < 3; d++)
      pl[k].p[d] = c[d] + (d == axis ? off : 0.0) + sh * pl[k].n[d];
  }
  run_case(b, type, S, pl, np, np == 1 ? "plane through the axis" : "two planes through the axis");
}

/* ---------------------------------------------------------------- the catalogue */

static void catalogue(body *B)
{
  for (int t = 0; t < NELEM; t++) {
    setup S;
    /* a plane tilted 1e-7 off the grid plane z = 1 across the box: 2 bodies */
    setup_create(&B[0], elements[t], &S);
    const plane d1 = {{1.5, 2, 1}, {1e-7, 0, 1}};
    plane p1 = d1;
    normalize(p1.n);
    run_case(&B[0], elements[t], &S, &p1, 1, "tilted grid plane");
    /* two parallel planes 1e-7 apart near the face y = 1.83: 2, then 3 bodies, no error */
    plane p2[2] = {
        {{0.13, 1.8299999, 1.91000000000001}, {0, -0.99999999999999512, 9.9999999999999506e-08}},
        {{0.13, 1.829999999999, 1.91}, {0, -0.99999999999999512, 9.9999999999999506e-08}}};
    normalize(p2[0].n);
    normalize(p2[1].n);
    run_case(&B[0], elements[t], &S, p2, 2, "parallel planes near a face");
    /* a plane 1e-8 off a grid plane, then a plane nearly parallel to it crossing it in the
     * box: a sliver part whose faces on the two planes fold over (negative fan tets) */
    plane p5[2] = {
        {{1, 1, 1}, {1, 1.7149840491529018e-09, 9.8518439751729277e-09}},
        {{0.99999999242917037, 1.5, 1.5}, {-1, 9.1202170900265598e-12, -4.1014192946817134e-12}}};
    run_case(&B[0], elements[t], &S, p5, 2, "crossing planes 1e-8 apart");
    /* three crossing near-grid planes meeting in a sliver of the same kind */
    plane p6[3] = {
        {{1, 1, 1}, {-7.9983454556696551e-08, -6.0022054256554901e-08, -0.999999999999995}},
        {{1, 1, 1}, {-8.7445113917872581e-07, 0.99999999999950007, -4.8511360029244238e-07}},
        {{1.5, 1, 0.99999999718382615}, {-7.9157074915949725e-10, -6.1107753114893059e-10, -1}}};
    run_case(&B[0], elements[t], &S, p6, 3, "crossing planes");
    setup_destroy(&S);
    /* a grid plane and a tilted plane through the ring: 2 bodies */
    setup_create(&B[2], elements[t], &S);
    plane p3 = {{0, 0, 0}, {1, 0, 0}};
    run_case(&B[2], elements[t], &S, &p3, 1, "plane through the axis");
    plane p4 = {{0, 0, 0}, {0.984807753012208, 0.17364817766693, 0.05}};
    normalize(p4.n);
    run_case(&B[2], elements[t], &S, &p4, 1, "plane through the axis");
    setup_destroy(&S);
  }
}

int main(int argc, char **argv)
{
  if (argc < 2) {
    fprintf(stderr, "usage: %s catalogue | campaign N [seed] [verbose] [element]\n", argv[0]);
    return 2;
  }
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  body B[4];
  make_bodies(B);
  if (!strcmp(argv[1], "catalogue")) {
    catalogue(B);
  } else if (!strcmp(argv[1], "one") && argc >= 10 && (argc - 4) % 6 == 0) {
    const int b = atoi(argv[2]), t = atoi(argv[3]), np = (argc - 4) / 6;
    plane pl[MAX_PLANES];
    for (int k = 0; k < np && k < MAX_PLANES; k++)
      for (int d = 0; d < 3; d++) {
        pl[k].p[d] = atof(argv[4 + 6 * k + d]);
        pl[k].n[d] = atof(argv[7 + 6 * k + d]);
      }
    setup S;
    verbose = 3;
    setup_create(&B[b], elements[t], &S);
    run_case(&B[b], elements[t], &S, pl, np < MAX_PLANES ? np : MAX_PLANES, "given planes");
    setup_destroy(&S);
  } else {
    const int n = argc > 2 ? atoi(argv[2]) : 100;
    rng_state = argc > 3 ? strtoull(argv[3], NULL, 10) : 1;
    verbose = argc > 4 ? atoi(argv[4]) : 0;
    const int only = argc > 5 ? atoi(argv[5]) : -1; /* one element's cases (0 .. 3) */
    for (int t = 0; t < NELEM && (only < 0 || t <= only); t++) {
      setup S[4];
      dry = only >= 0 && t < only;
      for (int b = 0; b < 4 && !dry; b++)
        setup_create(&B[b], elements[t], &S[b]);
      for (int i = 0; i < n; i++) {
        const int b = i % 4;
        if (B[b].convex)
          convex_case(&B[b], elements[t], &S[b]);
        else
          hole_case(&B[b], elements[t], &S[b]);
      }
      for (int b = 0; b < 4 && !dry; b++)
        setup_destroy(&S[b]);
    }
    dry = 0;
    if (verbose) {
      printf("%-28s", "family");
      for (int t = 0; t < NELEM; t++)
        printf(" %14s", ename(elements[t]));
      printf("\n");
      for (int f = 0; f < NFAM; f++) {
        long long any = 0;
        for (int t = 0; t < NELEM; t++)
          any += fam_cases[t][f];
        if (!any) continue;
        printf("%-28s", families[f]);
        for (int t = 0; t < NELEM; t++)
          printf(" %7lld (%4lld)", fam_cases[t][f], fam_failed[t][f]);
        printf("\n");
      }
      printf("(cases, failed in parentheses)\n");
    }
    if (verbose)
      printf("%lld cases, %lld cuts, %lld shifted, %lld thin reference regions, %lld dust "
             "bodies, %lld constrained fragments\n",
             cases_run, cuts_applied, shifted, thin_regions, dust_bodies, stuck);
  }
  for (int b = 0; b < 4; b++)
    fcm_geometry_destroy(&B[b].g);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
