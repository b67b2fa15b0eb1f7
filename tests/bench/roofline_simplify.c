/* bench_roofline: simplification of real cut-cell rules at strengths 3, 5, 7, 9, the default
 * fit against the old rank-1 and the blocked elimination. */
#include "roofline.h"
#include "simplify/simplify_impl.h"

/* Simplification of real cut-cell rules: the ball of radius 0.8 (fcm_geometry_create_ball,
 * resolution 6, as tests/embed/bench.c) in a box grid of 8^3 Hex8 cells over [-1,1]^3; the
 * SIMP_CELLS cut cells with volume fraction in [0.25, 0.75] spread over the grid. Per cell:
 * - the volume path's input: the cell's stiffness rule of strength m without simplification
 *   (the geometry's tets clipped by the cell, a tet rule on each; FCM_CELL_MOMENTS_VOLUME);
 * - the surface path's input (FCM_CELL_MOMENTS_AUTO, the default): candidates as that path
 *   picks them (the points of a grid over the material's box in the cell inside the material,
 *   about c(m) M of them (fcm__fit_candidates_per_moment), and up to M points on the material's
 *   boundary: vertices and centroids of
 *   the boundary triangles' parts in the cell; the sets 4, 16, 64 times larger that path
 *   retries on, up to the first that fits) and the material's moments in the basis of the
 *   material's box (here from the volume rule, exact to rounding for a polyhedral body).
 * Rows per strength: "simp_fit_mM" the default path (fcm__simplify_fit on each candidate set in
 * turn until one fits, all of them timed),
 * "simp_elim1_mM" fcm_simplify's elimination one direction at a time (elimination_block = 1,
 * the unblocked path), "simp_elim_mM" the same with the default blocked elimination. Time: mean
 * over the cells of the best of SIMP_REPS calls, the whole call (basis, factorization,
 * elimination or NNLS, re-fit and verification). Flops: the algorithm's arithmetic as the
 * library counts it (fcm_simplify_info.flops: LU, triangular solves and tableau updates;
 * fcm__fit.flops: NNLS gradients, QR updates, solves and residuals), not the basis
 * evaluation and verification. Every rule is checked: no fallback, at most M points, the
 * residual within the default tolerance. The point counts go to stderr. */
enum { SIMP_CELLS = 4, SIMP_REPS = 3, SIMP_GRID = 8 };
/* The surface path's retries: up to SIMP_GRIDS candidate sets, each aiming at SIMP_GROW times
 * as many points as the one before. */
enum { SIMP_GRIDS = 4, SIMP_GROW = 4 };

typedef struct simp_cell {
  int n;                    /* volume rule points */
  double *pts, *w;          /* the volume rule (reference coordinates) */
  int grids;                /* candidate sets the surface path fits on (the last one fits) */
  int nc[SIMP_GRIDS];       /* candidates of each */
  double *cand[SIMP_GRIDS]; /* nc x 3 each */
  double *mom;              /* M moments in the basis of box */
  fcm__cheb_box box;        /* the material's box -> [-1, 1]^3 */
  double atol;              /* absolute moment residual accepted (as the surface path) */
} simp_cell;

typedef struct simp_input {
  int m, cells;
  simp_cell c[SIMP_CELLS];
} simp_input;

static void simp_free(simp_input *in)
{
  for (int k = 0; k < in->cells; k++) {
    free(in->c[k].pts), free(in->c[k].w), free(in->c[k].mom);
    for (int a = 0; a < SIMP_GRIDS; a++)
      free(in->c[k].cand[a]);
  }
  in->cells = 0;
}

/* 1 when x lies in the tet v (4 x 3) up to rounding. */
static int in_tet(const double *v, const double *x)
{
  double a[3][3], r[3];
  for (int d = 0; d < 3; d++) {
    for (int c = 0; c < 3; c++)
      a[d][c] = v[3 * (c + 1) + d] - v[d];
    r[d] = x[d] - v[d];
  }
  const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                     a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                     a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  double l[3];
  for (int c = 0; c < 3; c++) { /* Cramer: column c replaced by r */
    double b[3][3];
    memcpy(b, a, sizeof b);
    for (int d = 0; d < 3; d++)
      b[d][c] = r[d];
    l[c] = (b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
            b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
            b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0])) /
           det;
  }
  const double eps = 1e-12;
  return l[0] >= -eps && l[1] >= -eps && l[2] >= -eps && l[0] + l[1] + l[2] <= 1.0 + eps;
}

/* The geometry's tets that meet the box lo..hi (up to rounding): their ids into near, count
 * returned. */
static fcm_index tets_near(const fcm_geometry *g, const double lo[3], const double hi[3],
                           fcm_index *near)
{
  const double *X = fcm_geometry_coords(g);
  const fcm_index *cells = fcm_geometry_cells(g);
  fcm_index n = 0;
  for (fcm_index t = 0; t < fcm_geometry_num_cells(g); t++) {
    int meets = 1;
    for (int d = 0; d < 3 && meets; d++) {
      double a = 1e30, b = -1e30;
      for (int v = 0; v < 4; v++)
        a = fmin(a, X[3 * cells[4 * t + v] + d]), b = fmax(b, X[3 * cells[4 * t + v] + d]);
      meets = a <= hi[d] + 1e-12 && b >= lo[d] - 1e-12;
    }
    if (meets) near[n++] = t;
  }
  return n;
}

/* 1 when the physical point x lies in one of the geometry's tets near[0..n). */
static int in_geometry(const fcm_geometry *g, fcm_index n, const fcm_index *near, const double *x)
{
  const double *X = fcm_geometry_coords(g);
  const fcm_index *cells = fcm_geometry_cells(g);
  for (fcm_index k = 0; k < n; k++) {
    double v[12];
    for (int a = 0; a < 4; a++)
      memcpy(v + 3 * a, X + 3 * cells[4 * near[k] + a], 3 * sizeof *v);
    if (in_tet(v, x)) return 1;
  }
  return 0;
}

/* The part of boundary triangle tri (node ids into X) in the box lo..hi, clipped plane by
 * plane (Sutherland-Hodgman): its vertices into poly (at most 9), their number returned. */
static int clip_triangle(const double *X, const fcm_index *tri, const double lo[3],
                         const double hi[3], double *poly)
{
  double buf[3 * 9];
  int n = 3;
  for (int a = 0; a < 3; a++)
    memcpy(poly + 3 * a, X + 3 * tri[a], 3 * sizeof *poly);
  for (int pl = 0; pl < 6 && n > 0; pl++) {
    const int d = pl % 3;
    const double s = pl < 3 ? 1.0 : -1.0, c = pl < 3 ? lo[d] : hi[d]; /* s (x_d - c) >= 0 */
    int m = 0;
    for (int i = 0; i < n; i++) {
      const double *p = poly + 3 * i, *q = poly + 3 * ((i + 1) % n);
      const double fp = s * (p[d] - c), fq = s * (q[d] - c);
      if (fp >= 0.0) memcpy(buf + 3 * m++, p, 3 * sizeof *p);
      if ((fp >= 0.0) != (fq >= 0.0) && m < 9) {
        const double u = fp / (fp - fq);
        for (int e = 0; e < 3; e++)
          buf[3 * m + e] = p[e] + u * (q[e] - p[e]);
        buf[3 * m + d] = c;
        m++;
      }
    }
    n = m;
    memcpy(poly, buf, 3 * (size_t)n * sizeof *poly);
  }
  return n;
}

/* Candidate set `a` of one cell (physical box clo..chi, reference [-1, 1]^3) for strength m:
 * the grid over the material's box (reference mbox) inside the geometry, sized for about
 * c(m) M grow of them, and up to M grow boundary points (the vertices and centroids of the
 * boundary triangles' parts in the cell), grow = SIMP_GROW^a. */
static int simp_candidates(const fcm_geometry *g, fcm_index nnear, const fcm_index *near,
                           const double clo[3], const double chi[3], int m, int M, double vol,
                           const double mbox[6], int a, simp_cell *c)
{
  int grow = 1;
  for (int k = 0; k < a; k++)
    grow *= SIMP_GROW;
  M *= grow;
  const double bv = (mbox[3] - mbox[0]) * (mbox[4] - mbox[1]) * (mbox[5] - mbox[2]);
  const double per = fcm__fit_candidates_per_moment(m);
  const int n = (int)fmin(64.0, fmax(2.0, ceil(cbrt(per * M * bv / vol))));
  const fcm_index nt = fcm_geometry_num_boundary_triangles(g);
  const fcm_index *tri = fcm_geometry_boundary_triangles(g);
  const double *X = fcm_geometry_coords(g);
  double *cand = c->cand[a] =
      malloc(3 * ((size_t)(n + 1) * (n + 1) * (n + 1) + (size_t)M) * sizeof *cand);
  double *bnd = malloc(3 * 10 * (size_t)nt * sizeof *bnd);
  if (!cand || !bnd) return free(bnd), 0;
  int nc = 0;
  for (int i = 0; i <= n; i++)
    for (int j = 0; j <= n; j++)
      for (int k = 0; k <= n; k++) {
        const int ijk[3] = {i, j, k};
        double xi[3], x[3];
        for (int d = 0; d < 3; d++) {
          xi[d] = mbox[d] + (mbox[3 + d] - mbox[d]) * ijk[d] / n;
          x[d] = clo[d] + 0.5 * (xi[d] + 1.0) * (chi[d] - clo[d]);
        }
        if (in_geometry(g, nnear, near, x)) memcpy(cand + 3 * (size_t)nc++, xi, sizeof xi);
      }
  size_t nb = 0;
  for (fcm_index t = 0; t < nt; t++) { /* the parts' vertices, then their centroid */
    double poly[3 * 9];
    const int np = clip_triangle(X, tri + 3 * t, clo, chi, poly);
    double cen[3] = {0, 0, 0};
    for (int i = 0; i <= np && np >= 3; i++) {
      const double *x = i < np ? poly + 3 * i : cen;
      for (int d = 0; d < 3; d++) {
        if (i < np) cen[d] += poly[3 * i + d] / np;
        bnd[3 * nb + d] = 2.0 * (x[d] - clo[d]) / (chi[d] - clo[d]) - 1.0;
      }
      nb++;
    }
  }
  const size_t take = nb < (size_t)M ? nb : (size_t)M;
  for (size_t i = 0; i < take; i++)
    memcpy(cand + 3 * (size_t)nc++, bnd + 3 * (i * nb / take), 3 * sizeof *bnd);
  c->nc[a] = nc;
  free(bnd);
  return 1;
}

/* The material's box in the cell lo..hi, in reference coordinates (as the surface path): the
 * boundary triangles' parts in the cell and the cell's corners inside the body. */
static void material_box(const fcm_geometry *g, fcm_index nnear, const fcm_index *near,
                         const double lo[3], const double hi[3], double mbox[6])
{
  const fcm_index *tri = fcm_geometry_boundary_triangles(g);
  const double *X = fcm_geometry_coords(g);
  for (int d = 0; d < 3; d++)
    mbox[d] = 1e30, mbox[3 + d] = -1e30;
  for (int k = 0; k < 8 + fcm_geometry_num_boundary_triangles(g); k++) {
    double poly[3 * 9];
    int np = 1;
    if (k < 8) { /* a corner of the cell */
      for (int d = 0; d < 3; d++)
        poly[d] = (k >> d) & 1 ? hi[d] : lo[d];
      if (!in_geometry(g, nnear, near, poly)) continue;
    } else {
      np = clip_triangle(X, tri + 3 * (k - 8), lo, hi, poly);
    }
    for (int i = 0; i < np; i++)
      for (int d = 0; d < 3; d++) {
        const double xi = 2.0 * (poly[3 * i + d] - lo[d]) / (hi[d] - lo[d]) - 1.0;
        mbox[d] = fmin(mbox[d], xi), mbox[3 + d] = fmax(mbox[3 + d], xi);
      }
  }
}

/* The surface path's fit of one cell: on its candidate sets in turn until one fits (f->ok);
 * f->flops sums the attempts'. */
static int simp_fit(fcm_ctx *ctx, const simp_cell *c, fcm__fit *f)
{
  double flops = 0.0;
  for (int a = 0; a < c->grids; a++) {
    if (fcm__simplify_fit(ctx, &c->box, c->nc[a], c->cand[a], c->mom, 1e-12, c->atol, f)) return 0;
    flops += f->flops;
    if (f->ok) break;
  }
  f->flops = flops;
  return 1;
}

/* The inputs of strength m (see the section comment). */
static int simp_setup(fcm_ctx *ctx, int m, simp_input *in)
{
  int ok = 0;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, centre[3] = {0.013, 0.007, 0.003};
  const fcm_index n3[3] = {SIMP_GRID, SIMP_GRID, SIMP_GRID};
  const int M = fcm__simplify_num_basis(m);
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_index cut[SIMP_GRID * SIMP_GRID * SIMP_GRID], ncut = 0;
  double *work = NULL, *wf = NULL;
  int *idx = NULL;
  fcm_index *near = NULL;
  memset(in, 0, sizeof *in);
  in->m = m;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.kinds = FCM_RULES_STIFFNESS;
  o.strength[FCM_RULE_STIFFNESS] = m;
  o.simplify = FCM_CELL_SIMPLIFY_OFF;
  o.moments = FCM_CELL_MOMENTS_VOLUME;
  o.stabilization.mode = FCM_STABILIZATION_OFF;
  if (fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &mesh) ||
      fcm_geometry_create_ball(ctx, centre, 0.8, 6, &g) ||
      fcm_cell_rules_create(ctx, mesh, g, &o, &rules))
    goto done;
  for (fcm_index k = 0; k < fcm_mesh_num_cells(mesh); k++) {
    const double phi = fcm_cell_rules_volume_fraction(rules, k);
    if (fcm_cell_rules_class(rules, k) == FCM_CELL_CUT && phi >= 0.25 && phi <= 0.75)
      cut[ncut++] = k;
  }
  work = malloc(fcm__simplify_moments_scratch(m) * sizeof *work);
  idx = malloc((size_t)M * sizeof *idx), wf = malloc((size_t)M * sizeof *wf);
  near = malloc((size_t)fcm_geometry_num_cells(g) * sizeof *near);
  if (ncut < SIMP_CELLS || !work || !idx || !wf || !near) goto done;
  for (int k = 0; k < SIMP_CELLS; k++) {
    const fcm_index cell = cut[(size_t)k * (size_t)ncut / SIMP_CELLS];
    simp_cell *c = &in->c[in->cells++];
    int n;
    const double *p, *w;
    double X[8 * 3], clo[3] = {1e30, 1e30, 1e30}, chi[3] = {-1e30, -1e30, -1e30};
    if (fcm_cell_rules_get(rules, cell, FCM_RULE_STIFFNESS, &n, &p, &w, NULL)) goto done;
    c->n = n;
    c->pts = malloc(3 * (size_t)n * sizeof *c->pts), c->w = malloc((size_t)n * sizeof *c->w);
    c->mom = malloc((size_t)M * sizeof *c->mom);
    if (!c->pts || !c->w || !c->mom) goto done;
    memcpy(c->pts, p, 3 * (size_t)n * sizeof *p);
    memcpy(c->w, w, (size_t)n * sizeof *w);
    /* the material's box in reference coordinates */
    fcm_mesh_cell_coords(mesh, cell, X);
    for (int a = 0; a < 8; a++)
      for (int d = 0; d < 3; d++)
        clo[d] = fmin(clo[d], X[3 * a + d]), chi[d] = fmax(chi[d], X[3 * a + d]);
    double mbox[6], vol = 0.0;
    const fcm_index nnear = tets_near(g, clo, chi, near);
    material_box(g, nnear, near, clo, chi, mbox);
    for (int j = 0; j < n; j++) {
      vol += w[j];
      for (int d = 0; d < 3; d++)
        ROOFLINE_CHECK(p[3 * j + d] >= mbox[d] - 1e-12 && p[3 * j + d] <= mbox[3 + d] + 1e-12);
    }
    c->box.m = m, c->box.q = m, c->box.num_basis = M;
    for (int d = 0; d < 3; d++) { /* as the surface path: the material's box -> [-1, 1] */
      c->box.scale[d] = 2.0 / (mbox[3 + d] - mbox[d]);
      c->box.shift[d] = -(mbox[d] + mbox[3 + d]) / (mbox[3 + d] - mbox[d]);
    }
    fcm__simplify_moments(&c->box, n, c->pts, NULL, c->w, c->mom, work);
    c->atol = 1e-14 * (mbox[3] - mbox[0]) * (mbox[4] - mbox[1]) * (mbox[5] - mbox[2]);
    fcm__fit f;
    memset(&f, 0, sizeof f);
    f.idx = idx, f.w = wf;
    for (int a = 0; a < SIMP_GRIDS && !f.ok; a++) { /* the sets until one fits */
      if (!simp_candidates(g, nnear, near, clo, chi, m, M, vol, mbox, a, c)) goto done;
      c->grids = a + 1;
      if (fcm__simplify_fit(ctx, &c->box, c->nc[a], c->cand[a], c->mom, 1e-12, c->atol, &f))
        goto done;
    }
    if (!f.ok) {
      fprintf(stderr, "simplify m = %d: cell %lld: no candidate set fits: %s\n", m, (long long)cell,
              f.message);
      goto done;
    }
  }
  ok = 1;
done:
  if (!ok) fcm_ctx_error_view(ctx, stderr), simp_free(in);
  free(work), free(idx), free(wf), free(near);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  return ok;
}

/* Path 0: the default surface path's fit; 1: elimination one direction at a time; 2: the
 * default (blocked) elimination. */
static int run_simp(fcm_ctx *ctx, int m, int path, bench_result *r)
{
  simp_input in;
  static const char *names[3] = {"fit (NNLS)", "elimination, rank-1", "elimination, blocked"};
  if (!simp_setup(ctx, m, &in)) return 0;
  const int M = fcm__simplify_num_basis(m);
  int ok = 1, *idx = malloc((size_t)M * sizeof *idx);
  double *wf = malloc((size_t)M * sizeof *wf), size = 0, secs = 0, flops = 0, kept = 0, grids = 0;
  fcm_simplify_options so = fcm_simplify_options_default();
  so.method = FCM_SIMPLIFY_ELIMINATE;
  so.elimination_block = path == 1 ? 1 : FCM_DEFAULT;
  for (int k = 0; k < in.cells && ok && idx && wf; k++) {
    const simp_cell *c = &in.c[k];
    double best = 1e30;
    for (int rep = 0; rep < SIMP_REPS && ok; rep++) {
      double t0, fl, res;
      int cnt;
      if (path == 0) {
        fcm__fit f;
        memset(&f, 0, sizeof f);
        f.idx = idx, f.w = wf;
        t0 = roofline_cpu_seconds();
        ok = simp_fit(ctx, c, &f);
        best = fmin(best, roofline_cpu_seconds() - t0);
        ok = ok && f.ok;
        fl = f.flops, cnt = f.count, res = f.residual;
      } else {
        fcm_simplify_result res_;
        fcm_simplify_info info;
        t0 = roofline_cpu_seconds();
        ok = fcm_simplify(ctx, m, c->n, c->pts, c->w, &so, &res_, &info) == FCM_OK;
        best = fmin(best, roofline_cpu_seconds() - t0);
        ok = ok && !info.fallback;
        fl = info.flops, cnt = (int)res_.count, res = info.residual;
        fcm_simplify_result_destroy(&res_);
      }
      ROOFLINE_CHECK(ok && cnt <= M && res <= 1e-12);
      if (rep == 0) {
        size += (double)(path == 0 ? c->nc[c->grids - 1] : c->n) / in.cells;
        grids += (double)c->grids / in.cells;
        flops += fl / in.cells, kept += (double)cnt / in.cells;
      }
    }
    secs += best / in.cells;
  }
  if (ok && path == 0)
    fprintf(stderr,
            "simplify m = %d (M = %d), %s: %.0f candidates (the set that fits; %.2f sets fitted), "
            "%.1f kept (mean of %d cells)\n",
            m, M, names[path], size, grids, kept, in.cells);
  else if (ok)
    fprintf(stderr, "simplify m = %d (M = %d), %s: %.0f points in, %.1f kept (mean of %d cells)\n",
            m, M, names[path], size, kept, in.cells);
  else
    fcm_ctx_error_view(ctx, stderr);
  r->size = size, r->seconds = secs, r->work = flops;
  free(idx), free(wf);
  simp_free(&in);
  return ok;
}

#define SIMP_ROWS(m)                                                                               \
  int run_simp_fit_m##m(fcm_ctx *ctx, int cells, bench_result *r)                                  \
  {                                                                                                \
    (void)cells;                                                                                   \
    return run_simp(ctx, m, 0, r);                                                                 \
  }                                                                                                \
  int run_simp_elim1_m##m(fcm_ctx *ctx, int cells, bench_result *r)                                \
  {                                                                                                \
    (void)cells;                                                                                   \
    return run_simp(ctx, m, 1, r);                                                                 \
  }                                                                                                \
  int run_simp_elim_m##m(fcm_ctx *ctx, int cells, bench_result *r)                                 \
  {                                                                                                \
    (void)cells;                                                                                   \
    return run_simp(ctx, m, 2, r);                                                                 \
  }
SIMP_ROWS(3)
SIMP_ROWS(5)
SIMP_ROWS(7)
SIMP_ROWS(9)
