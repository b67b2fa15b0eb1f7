/* State transfer across sequences of cuts: a spinning free body is cut again and again
 * (fcm_cell_rules_create_cut -> fcm_space_create_embedded_with -> fcm_space_transfer of the
 * displacement and the velocity), and after every cut
 *   - the volumes of the pieces each earlier piece was split into add up to its volume to
 *     1e-12 of its cell's (the pieces are those of their parents: fcm_cell_rules_piece_parent);
 *   - displacement and velocity at every mass-rule point of every piece equal (to 1e-12 of
 *     their largest DOF value) the fields of its parent piece at that point before the cut;
 *   - mass, linear and angular momentum (fcm_space_momentum) equal those before the cut to
 *     1e-12 relative, the momenta up to what the rules of parts the cut tolerances left
 *     slightly non-convex may move (fcm_cell_rules_stats.moved_volume: their negative fan tets
 *     get no points, the others are scaled to keep the volume, so a function g is integrated
 *     with an error of at most 2 moved max |g|; |v| <= lambda max |v_a|, |x| <= lambda
 *     max |x_a| with lambda = max sum_a |N_a| over the cell, and both the parent's and the
 *     pieces' rules count: moved over every build so far).
 * Each cut is carried by two spaces: without the constraint of tiny DOF copies
 * (constrain_ratio 0), where all of this holds everywhere, and with the default constraint,
 * where an element that uses a constrained copy's place (fcm_space_element_constrained())
 * moves with the copy it follows, so its field changes at the cut (by design): its points
 * are left out of the field check, and the momenta must match once the change over those
 * elements' points is taken off (that change must stay below 100 x constrain_ratio of the
 * momenta; its largest value is reported by `verbose`).
 * Between cuts every DOF gets a random offset, so the copies of a node differ (a state
 * after some steps) and a piece given another piece's values shows.
 * The planes (2 x 2 x 2 cells over the body [0, 2]^3): random; near cell planes (x_d = 0,
 * 1, 2 and the Tet4 cells' diagonal planes x_d - x_e = k, through a node, an edge midpoint
 * or a face-diagonal midpoint, tilted by 1e-12 .. 1e-5 in a random direction, or not);
 * crossing knives (through a line of the previous cut, turned by 1e-6 .. 1 rad); a plane
 * pair whose second cut leaves slivers of the first without volume (Tet4/Tet10: the other
 * pieces of their cells must keep their own parents, not the slivers'); and three grazing
 * planes whose third cut's face tests would link a wedge cut off by the first to the body
 * again (Hex8/Hex20: a cut only separates).
 * Usage: fem_transfer <element> [<sequences> [<seed> [<verbose>]]]
 *   without <sequences> (or 0): the fixed sequences and one sequence of 2, 5 and 10 cuts
 *   mixing the three kinds of plane (<seed>, default 5), every cut must be accepted;
 *   with <sequences> > 0: for each kind and the mix, that many sequences of each length on two
 *   bodies (the box [0, 2]^3 and a box inside it); a cut whose pieces are wrong (refused as
 *   still degenerate after its shifts, FCM_ERR_GEOMETRY; pieces whose volumes do not add up
 *   to their parents'; FCM_ERR_INTERNAL "lies in no piece of the rules being extended") ends
 *   its sequence and is counted; everything else fails. <verbose> 1 lists those cuts with the
 *   sequence's planes and prints a summary, 2 prints every cut. */
#include "fcm/fcm.h"
#include "fem_util.h"
#include "la/vec3.h"

#define MAX_CUTS 10
#define RTOL     1e-12

static fcm_ctx *ctx;
static int verbose;
static double worst_m, worst_p, worst_L, worst_field, worst_vol, worst_con, worst_moved;
static double lambda; /* max over the reference cell of sum_a |N_a| */
static long long cuts_done, points_checked, constrained_elems, geometry_failures;

typedef struct plane {
  double p[3], n[3];
} plane;

typedef enum family { FAM_RANDOM, FAM_GRID, FAM_CROSS, FAM_MIXED, FAM_COUNT } family;
static const char *family_name[FAM_COUNT] = {"random", "grid", "cross", "mixed"};

static void normalize(double v[3])
{
  const double s = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int i = 0; i < 3; i++)
    v[i] /= s;
}

/* A random unit vector perpendicular to the unit vector n. */
static void perpendicular(const double n[3], unsigned long long *seed, double w[3])
{
  double r[3];
  do {
    for (int i = 0; i < 3; i++)
      r[i] = urand(seed);
    const double d = r[0] * n[0] + r[1] * n[1] + r[2] * n[2];
    for (int i = 0; i < 3; i++)
      w[i] = r[i] - d * n[i];
  } while (fcm__vec3_norm(w) < 0.1);
  normalize(w);
}

/* A plane near a plane of cell faces of the 2 x 2 x 2 grid over [0, 2]^3: x_d = 0, 1 or 2,
 * or a diagonal plane x_d - x_e = k of the Tet4 cells; through a node, an edge midpoint or
 * the midpoint of a face diagonal on it; tilted by 10^[-12, -5) in a random direction four
 * times in five. */
static plane grid_plane(unsigned long long *seed)
{
  plane pl;
  for (int i = 0; i < 3; i++) /* a node */
    pl.p[i] = floor(1.5 * (urand(seed) + 1.0));
  const int d = (int)floor(1.5 * (urand(seed) + 1.0)), e = (d + 1) % 3;
  const double half = pl.p[e] < 2.0 ? 0.5 : -0.5;
  memset(pl.n, 0, sizeof pl.n);
  if (urand(seed) < -0.2) { /* x_d - x_e = p_d - p_e */
    pl.n[d] = 1.0, pl.n[e] = -1.0;
    if (urand(seed) < 0.0 && pl.p[d] + half >= 0.0 && pl.p[d] + half <= 2.0)
      pl.p[d] += half, pl.p[e] += half;
  } else { /* x_d = p_d */
    pl.n[d] = 1.0;
    if (urand(seed) < 0.0) pl.p[e] += half;
  }
  normalize(pl.n);
  if (urand(seed) > -0.6) {
    double w[3];
    const double tilt = pow(10.0, -12.0 + 3.5 * (urand(seed) + 1.0));
    perpendicular(pl.n, seed, w);
    for (int i = 0; i < 3; i++)
      pl.n[i] += tilt * w[i];
  }
  return pl;
}

/* A plane through a random point of the body's middle with a random normal. */
static plane random_plane(unsigned long long *seed)
{
  plane pl;
  for (int i = 0; i < 3; i++)
    pl.p[i] = 1.0 + 0.7 * urand(seed);
  do {
    for (int i = 0; i < 3; i++)
      pl.n[i] = urand(seed);
  } while (fcm__vec3_norm(pl.n) < 0.1);
  normalize(pl.n);
  return pl;
}

/* A knife crossing the previous one: through a point of the previous plane near the
 * body's middle, its normal turned by 10^[-6, 0) rad. */
static plane cross_plane(const plane *prev, unsigned long long *seed)
{
  plane pl;
  double w[3], t[3];
  perpendicular(prev->n, seed, w);
  perpendicular(prev->n, seed, t);
  const double ang = pow(10.0, -3.0 * (urand(seed) + 1.0)), s = 0.5 * urand(seed);
  const double off = prev->n[0] * (1.0 - prev->p[0]) + prev->n[1] * (1.0 - prev->p[1]) +
                     prev->n[2] * (1.0 - prev->p[2]);
  for (int i = 0; i < 3; i++) {
    pl.p[i] = 1.0 - off * prev->n[i] + s * t[i];
    pl.n[i] = cos(ang) * prev->n[i] + sin(ang) * w[i];
  }
  return pl;
}

/* The element of space s that holds piece `piece` of its rules (a cell's elements and
 * pieces are in the same order). */
static fcm_index piece_element(const fcm_space *s, fcm_index piece)
{
  const fcm_cell_rules *r = fcm_space_cell_rules(s);
  const fcm_index c = fcm_cell_rules_piece_cell(r, piece);
  fcm_index pfirst, efirst;
  fcm_cell_rules_cell_pieces(r, c, &pfirst);
  fcm_space_cell_elements(s, c, &efirst);
  return efirst + (piece - pfirst);
}

/* The largest difference (relative to scale) between the fields u1, v1 of s1 and u0, v0 of
 * s0 over every mass-rule point of every piece of s1 and its parent, over the elements of s1
 * that use no constrained copy's place; dcon[0..6) gets the change of the linear and angular
 * momentum over the authentic points of the others. */
static double compare_fields(const fcm_space *s0, const fcm_space *s1, const double *u0,
                             const double *v0, const double *u1, const double *v1, double scale,
                             double rho, double dcon[6])
{
  const fcm_mesh *mesh = fcm_space_mesh(s1);
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const fcm_cell_rules *r1 = fcm_space_cell_rules(s1);
  double worst = 0.0;
  memset(dcon, 0, 6 * sizeof *dcon);
  for (fcm_index e = 0; e < fcm_space_num_elements(s1); e++) {
    const fcm_index c = fcm_space_element_cell(s1, e);
    fcm_index pfirst, efirst;
    fcm_cell_rules_cell_pieces(r1, c, &pfirst);
    fcm_space_cell_elements(s1, c, &efirst);
    const fcm_index piece = pfirst + (e - efirst);
    const fcm_index e0 = piece_element(s0, fcm_cell_rules_piece_parent(r1, piece));
    TEST_TRUE(fcm_space_element_cell(s0, e0) == c);
    const int con = fcm_space_element_constrained(s1, e) > 0;
    int nq = 0;
    const double *pts, *w;
    const unsigned char *fl;
    TEST_OK(ctx, fcm_cell_rules_get_piece(r1, piece, FCM_RULE_MASS, &nq, &pts, &w, &fl));
    double X[3 * FCM_ELEMENT_MAX_NODES], J[9];
    fcm_mesh_cell_coords(mesh, c, X);
    for (int q = 0; q < nq; q++) {
      double a[3], b[3], x[3], y[3];
      TEST_OK(ctx, fcm_space_element_eval(s1, e, pts + 3 * q, u1, a));
      TEST_OK(ctx, fcm_space_element_eval(s0, e0, pts + 3 * q, u0, b));
      TEST_OK(ctx, fcm_space_element_eval(s1, e, pts + 3 * q, v1, x));
      TEST_OK(ctx, fcm_space_element_eval(s0, e0, pts + 3 * q, v0, y));
      points_checked++;
      if (!con) {
        for (int i = 0; i < 3; i++)
          worst = fmax(worst, fmax(fabs(a[i] - b[i]), fabs(x[i] - y[i])) / scale);
        continue;
      }
      if (fl && fl[q]) continue; /* a stabilization point: not the body */
      double N[FCM_ELEMENT_MAX_NODES], xa[3] = {0, 0, 0}, xb[3];
      fcm_element_eval_shape(info->type, pts + 3 * q, N);
      for (int k = 0; k < info->num_nodes; k++)
        for (int i = 0; i < 3; i++)
          xa[i] += N[k] * X[3 * k + i];
      for (int i = 0; i < 3; i++)
        xb[i] = xa[i] + b[i], xa[i] += a[i];
      const double wd = rho * w[q] * fcm_element_jacobian(info->type, X, pts + 3 * q, J);
      for (int i = 0; i < 3; i++) {
        const int j = (i + 1) % 3, k = (i + 2) % 3;
        dcon[i] += wd * (x[i] - y[i]);
        dcon[3 + i] += wd * ((xa[j] * x[k] - xa[k] * x[j]) - (xb[j] * y[k] - xb[k] * y[j]));
      }
    }
    constrained_elems += con;
  }
  return worst;
}

/* The largest difference between an earlier piece's volume and the sum of its pieces'
 * volumes, relative to its cell's volume. */
static double compare_volumes(const fcm_mesh *mesh, const fcm_cell_rules *r0,
                              const fcm_cell_rules *r1)
{
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const fcm_index np0 = fcm_cell_rules_num_pieces(r0);
  double *sum = calloc((size_t)np0 + 1, sizeof *sum), worst = 0.0;
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(r1); p++)
    sum[fcm_cell_rules_piece_parent(r1, p)] += fcm_cell_rules_piece_volume(r1, p);
  for (fcm_index p = 0; p < np0; p++) {
    double X[3 * FCM_ELEMENT_MAX_NODES], J[9];
    const double xi[3] = {0.25, 0.25, 0.25}; /* affine cells: one point gives |K| */
    fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r0, p), X);
    const double K = fcm_element_jacobian(info->type, X, xi, J) *
                     (info->shape == FCM_SHAPE_TET ? 1.0 / 6.0 : 8.0);
    worst = fmax(worst, fabs(sum[p] - fcm_cell_rules_piece_volume(r0, p)) / K);
  }
  free(sum);
  return worst;
}

/* The state of one space along a sequence. */
typedef struct track {
  double ratio; /* constrain_ratio */
  fcm_space *s;
  double *u, *v;
} track;

static void track_free(track *t)
{
  fcm_space_destroy(&t->s);
  free(t->u), free(t->v);
  t->u = t->v = NULL;
}

/* Spin and flight about the body's middle, and a small displacement, on space t->s. */
static void initial_state(const fcm_mesh *mesh, track *t)
{
  const double w0[3] = {0.3, -0.2, 0.1}, om[3] = {0.5, 0.2, -0.4}, ctr[3] = {1, 1, 1};
  const fcm_index nd = fcm_space_num_dofs(t->s);
  const double *X = fcm_mesh_coords(mesh);
  t->u = calloc((size_t)nd, sizeof *t->u);
  t->v = calloc((size_t)nd, sizeof *t->v);
  for (fcm_index k = 0; k < fcm_mesh_num_nodes(mesh); k++) {
    const fcm_index d = fcm_space_node_dof(t->s, k);
    if (d < 0) continue;
    const double x[3] = {X[3 * k] - ctr[0], X[3 * k + 1] - ctr[1], X[3 * k + 2] - ctr[2]};
    t->v[d] = w0[0] + om[1] * x[2] - om[2] * x[1];
    t->v[d + 1] = w0[1] + om[2] * x[0] - om[0] * x[2];
    t->v[d + 2] = w0[2] + om[0] * x[1] - om[1] * x[0];
    for (int i = 0; i < 3; i++)
      t->u[d + i] = 0.01 * x[(i + 1) % 3] * x[i];
  }
}

static void print_planes(const plane *pl, int n)
{
  for (int k = 0; k < n; k++)
    fprintf(stderr, "  cut %d: point %.17g %.17g %.17g normal %.17g %.17g %.17g\n", k, pl[k].p[0],
            pl[k].p[1], pl[k].p[2], pl[k].n[0], pl[k].n[1], pl[k].n[2]);
}

/* lambda for element type `type`, from a 21^3 grid over the reference cell (its corners
 * included, where the largest values of these polynomials' sums lie) with a 1 % margin. */
static double shape_lambda(fcm_element_type type)
{
  const fcm_element_info *info = fcm_element_get_info(type);
  const int tet = info->shape == FCM_SHAPE_TET, n = 20;
  double best = 0.0;
  for (int i = 0; i <= n; i++)
    for (int j = 0; j <= n; j++)
      for (int k = 0; k <= n; k++) {
        double xi[3] = {(double)i / n, (double)j / n, (double)k / n}, N[FCM_ELEMENT_MAX_NODES];
        if (tet && i + j + k > n) continue;
        for (int d = 0; d < 3 && !tet; d++)
          xi[d] = 2.0 * xi[d] - 1.0;
        fcm_element_eval_shape(type, xi, N);
        double sum = 0.0;
        for (int a = 0; a < info->num_nodes; a++)
          sum += fabs(N[a]);
        best = fmax(best, sum);
      }
  return 1.01 * best;
}

/* Carry track t over the cut that made rules r1 (a space of r1, fcm_space_transfer), check,
 * and give every DOF a random offset; 1 on a failed check. */
static int carry(const fcm_mesh *mesh, const fcm_cell_rules *r1, track *t, double rho, double moved,
                 unsigned long long *seed)
{
  fcm_space_options so = fcm_space_options_default();
  so.constrain_ratio = t->ratio;
  fcm_space *s1 = NULL;
  TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, r1, &so, &s1));
  if (!s1) return 1;
  const fcm_index nd0 = fcm_space_num_dofs(t->s), nd1 = fcm_space_num_dofs(s1);
  double *u1 = malloc(sizeof *u1 * (size_t)nd1), *v1 = malloc(sizeof *v1 * (size_t)nd1);
  for (fcm_index i = 0; i < nd1; i++)
    u1[i] = v1[i] = NAN; /* the transfer must set every DOF */
  TEST_OK(ctx, fcm_space_transfer(t->s, s1, t->u, u1));
  TEST_OK(ctx, fcm_space_transfer(t->s, s1, t->v, v1));
  double m0, m1, p0[3], p1[3], L0[3], L1[3], dcon[6], scale = 0.0;
  TEST_OK(ctx, fcm_space_momentum(t->s, rho, t->u, t->v, &m0, p0, L0));
  TEST_OK(ctx, fcm_space_momentum(s1, rho, u1, v1, &m1, p1, L1));
  double vmax = 0.0, xmax = 0.0; /* bounds of |v| and |x + u| at the nodes */
  for (fcm_index i = 0; i < nd0; i++) {
    scale = fmax(scale, fmax(fabs(t->u[i]), fabs(t->v[i])));
    vmax = fmax(vmax, sqrt(3.0) * fabs(t->v[i]));
  }
  for (fcm_index k = 0; k < fcm_mesh_num_nodes(mesh); k++) {
    const fcm_index d = fcm_space_node_dof(t->s, k);
    if (d < 0) continue;
    double x[3];
    for (int i = 0; i < 3; i++)
      x[i] = fabs(fcm_mesh_coords(mesh)[3 * k + i]) + scale;
    xmax = fmax(xmax, fcm__vec3_norm(x));
  }
  const double df = compare_fields(t->s, s1, t->u, t->v, u1, v1, scale, rho, dcon);
  double dp[3], dL[3];
  for (int i = 0; i < 3; i++)
    dp[i] = p1[i] - p0[i] - dcon[i], dL[i] = L1[i] - L0[i] - dcon[3 + i];
  const double em = fabs(m1 - m0) / m0, ep = fcm__vec3_norm(dp) / fcm__vec3_norm(p0),
               eL = fcm__vec3_norm(dL) / fcm__vec3_norm(L0);
  /* what the rules of non-convex parts may move, relative */
  const double mp = 2.0 * rho * moved * lambda * vmax / fcm__vec3_norm(p0),
               mL = 2.0 * rho * moved * lambda * lambda * vmax * xmax / fcm__vec3_norm(L0);
  const double ec = fmax(fcm__vec3_norm(dcon) / fcm__vec3_norm(p0),
                         fcm__vec3_norm(dcon + 3) / fcm__vec3_norm(L0));
  worst_m = fmax(worst_m, em), worst_p = fmax(worst_p, ep), worst_L = fmax(worst_L, eL);
  worst_field = fmax(worst_field, df), worst_con = fmax(worst_con, ec);
  /* the constrained elements are tiny: their share stays below 100 x constrain_ratio */
  const int bad =
      !(em <= RTOL && ep <= RTOL + mp && eL <= RTOL + mL && df <= RTOL && ec <= 100.0 * t->ratio);
  if (bad || verbose > 1)
    fprintf(stderr,
            "  ratio %g: mass %.2e p %.2e (allowed %.2e) L %.2e (%.2e) field %.2e (constrained "
            "elements: momenta %.2e); %lld bodies, %lld constrained copies\n",
            t->ratio, em, ep, RTOL + mp, eL, RTOL + mL, df, ec, (long long)fcm_space_num_bodies(s1),
            (long long)fcm_space_num_constrained_copies(s1));
  /* a state after some steps: the copies of a node differ */
  for (fcm_index i = 0; i < nd1; i++)
    u1[i] += 1e-3 * urand(seed), v1[i] += 0.1 * urand(seed);
  track_free(t);
  t->s = s1, t->u = u1, t->v = v1;
  return bad;
}

/* One sequence: body `body` (0: [0, 2]^3, 1: a box inside it) cut by pl[0 .. ncut). */
static void sequence(fcm_element_type type, int body, const plane *pl, int ncut, int strict,
                     unsigned long long seed, const char *what)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 2, 2}, bl[3] = {-0.2, -0.2, -0.2},
               bh[3] = {2.2, 2.2, 2.2};
  const double ilo[3] = {0.13, 0.21, 0.07}, ihi[3] = {1.77, 1.83, 1.91};
  const fcm_index n[3] = {2, 2, 2}, gn[3] = {1, 1, 1};
  const double rho = 1000.0;
  unsigned long long state = seed; /* the offsets between cuts */
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  track t[2] = {{0.0, NULL, NULL, NULL},
                {fcm_space_options_default().constrain_ratio, NULL, NULL, NULL}};
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.simplify = FCM_CELL_SIMPLIFY_OFF; /* exact moments: the momenta compare to rounding */
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, body ? ilo : lo, body ? ihi : hi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r0));
  double moved = r0 ? fcm_cell_rules_get_stats(r0)->moved_volume : 0.0; /* over every build */
  for (int k = 0; k < 2 && r0; k++) {
    fcm_space_options so = fcm_space_options_default();
    so.constrain_ratio = t[k].ratio;
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, r0, &so, &t[k].s));
    if (t[k].s) initial_state(mesh, t + k);
  }
  for (int k = 0; k < ncut && t[0].s && t[1].s; k++) {
    fcm_surface *cut = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, pl[k].p, pl[k].n, bl, bh, &cut));
    const fcm_status st = fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1);
    fcm_surface_destroy(&cut);
    /* the pieces themselves: the cut refused as degenerate, or volume lost or gained */
    const double dv = st == FCM_OK ? compare_volumes(mesh, r0, r1) : 0.0;
    worst_vol = fmax(worst_vol, dv);
    const int geometry = st == FCM_ERR_GEOMETRY || (st == FCM_OK && !(dv <= RTOL)) ||
                         (st == FCM_ERR_INTERNAL &&
                          strstr(fcm_ctx_error_message(ctx), "lies in no piece of the rules"));
    if (st != FCM_OK || geometry) {
      geometry_failures += geometry;
      if (strict || !geometry || verbose) {
        fprintf(stderr, "%s %s body %d seed %llu cut %d: %s\n",
                fcm_mesh_get_element_info(mesh)->name, what, body, seed, k,
                st != FCM_OK ? fcm_ctx_error_message(ctx) : "the pieces' volumes changed");
        print_planes(pl, k + 1);
      }
      TEST_TRUE(!strict && geometry);
      fcm_ctx_error_clear(ctx);
      break;
    }
    if (verbose > 1)
      fprintf(stderr, "%s %s body %d seed %llu cut %d: pieces %lld, volumes %.2e\n",
              fcm_mesh_get_element_info(mesh)->name, what, body, seed, k,
              (long long)fcm_cell_rules_num_pieces(r1), dv);
    int bad = 0;
    moved += fcm_cell_rules_get_stats(r1)->moved_volume;
    worst_moved = fmax(worst_moved, fcm_cell_rules_get_stats(r1)->moved_volume);
    for (int i = 0; i < 2; i++)
      bad |= carry(mesh, r1, t + i, rho, moved, &state);
    if (bad) {
      fprintf(stderr, "%s %s body %d seed %llu cut %d: mass, momenta or field not carried\n",
              fcm_mesh_get_element_info(mesh)->name, what, body, seed, k);
      print_planes(pl, k + 1);
    }
    TEST_TRUE(!bad);
    cuts_done++;
    fcm_cell_rules_destroy(&r0);
    r0 = r1, r1 = NULL;
  }
  track_free(t), track_free(t + 1);
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&r1);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

/* n planes of family f (the mix cycles random, near cell planes, crossing). */
static void make_planes(family f, int n, unsigned long long *seed, plane *pl)
{
  for (int k = 0; k < n; k++) {
    family fk = f == FAM_MIXED ? (family)(k % 3) : f;
    if (fk == FAM_CROSS && k == 0) fk = FAM_RANDOM;
    pl[k] = fk == FAM_GRID     ? grid_plane(seed)
            : fk == FAM_RANDOM ? random_plane(seed)
                               : cross_plane(&pl[k - 1], seed);
  }
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc < 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const int is_long = argc > 2 && atoi(argv[2]) > 0;
  const int nseq = is_long ? atoi(argv[2]) : 1;
  const unsigned long long seed0 = argc > 3 ? strtoull(argv[3], NULL, 10) : 5;
  verbose = argc > 4 ? atoi(argv[4]) : 0;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  lambda = shape_lambda(type);
  static const int lengths[3] = {2, 5, 10};
  const double s3 = 1.0 / sqrt(3.0);
  const plane pair[2] = {
      {{2, 1.0000000000000011, 0.5}, {0, -1, -1e-7}},
      {{1.9999999999942264, 0.99999994226497313, 0.50000000057735028}, {-s3, -s3, -s3}}};
  sequence(type, 0, pair, 2, 1, 0, "pair");
  /* a wedge 1e-8 thin cut off the face x = 2, a cut in the face z = 2, and a plane through
   * the edge y = 0, z = 2 */
  const double r2 = sqrt(0.5);
  const plane graze[3] = {{{2, 0, 2}, {1, 4.5125305655318385e-09, 2.3493527504796945e-09}},
                          {{0, 1, 2}, {0, 0, 1}},
                          {{2, 0, 2}, {0, r2, -r2}}};
  sequence(type, 0, graze, 3, 1, 0, "graze");
  /* on the inner box: the plane x = y, then two planes near x = z through a node of the cell
   * [1, 2]^3, 6e-9 rad apart; the second splits the cell's parts along a fold thinner than
   * the cut tolerance: parts slightly non-convex, whose rules move volume (Hex8: 1.2e-11,
   * the momenta change by 2e-12 relative) */
  const plane fold[3] = {
      {{1.5, 1.5, 0}, {0.70710678118654746, -0.70710678118654746, 0}},
      {{1.5, 1, 1.5}, {-0.7071067816432004, 9.4823565240232284e-10, 0.70710678072989452}},
      {{1.5, 1, 1.5}, {-0.70710678633360546, -5.7148448234775054e-09, 0.70710677603948946}}};
  worst_moved = 0.0;
  sequence(type, 1, fold, 3, 1, 0, "fold");
  if (type == FCM_ELEMENT_HEX8) TEST_TRUE(worst_moved > 0.0); /* the case still shows */
  for (int f = is_long ? 0 : FAM_MIXED; f < FAM_COUNT; f++)
    for (int q = 0; q < nseq; q++)
      for (int l = 0; l < 3; l++)
        for (int body = 0; body < 1 + is_long; body++) {
          unsigned long long seed =
                                 seed0 * 1000003ULL + (unsigned long long)(1000 * f + 10 * q + l),
                             s = seed;
          plane pl[MAX_CUTS];
          make_planes((family)f, lengths[l], &s, pl);
          sequence(type, body, pl, lengths[l], !is_long, seed, family_name[f]);
        }
  if (verbose)
    fprintf(stderr,
            "%s: %lld cuts (%lld sequences ended by the pieces), %lld points; largest relative "
            "change: mass %.2e, "
            "p %.2e, L %.2e, field %.2e, piece volumes %.2e; %lld constrained elements "
            "(momenta %.2e); largest moved volume %.2e\n",
            argv[1], cuts_done, geometry_failures, points_checked, worst_m, worst_p, worst_L,
            worst_field, worst_vol, constrained_elems, worst_con, worst_moved);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
