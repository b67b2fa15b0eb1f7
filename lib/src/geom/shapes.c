/* Procedural embedded shapes as Tet4 meshes: box, ball, hemisphere and tube from a
 * mapped Kuhn-split structured grid; hollow ball with holes from a radially extruded
 * cube-sphere surface grid split into prisms and tets. */
#include "geom/geom_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

/* Map from grid reference coordinates p to physical x. */
typedef void (*grid_map)(const double *par, const double p[3], double x[3]);

/* Kuhn split of the unit cube with corners numbered by bits (1: +x, 2: +y, 4: +z):
 * one tet per axis permutation (a, b, c) along the path 0, e_a, e_a + e_b, 7. The
 * orientation is fixed at run time (kuhn_det), the split is the same in every cube,
 * hence conforming. */
static const int kuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                               {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

static int corner_bit(int v, int d)
{
  return (v >> d) & 1;
}

/* Signed volume (times 6) of a Kuhn tet in index space. */
static int kuhn_det(const int t[4])
{
  int e[3][3];
  for (int k = 0; k < 3; k++)
    for (int d = 0; d < 3; d++)
      e[k][d] = corner_bit(t[k + 1], d) - corner_bit(t[0], d);
  return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
         e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

static fcm_status check_counts(fcm_ctx *ctx, const char *who, const fcm_index n[3])
{
  fcm_status st = FCM_OK;
  double cells = 6.0;
  for (int d = 0; d < 3; d++) {
    FCM_CHECK(n[d] >= 1 && n[d] <= 100000, ctx, FCM_ERR_ARG,
              "%s: cells along axis %d = %lld outside [1, 100000]", who, d, (long long)n[d]);
    cells *= (double)n[d];
  }
  FCM_CHECK(cells < 4e9, ctx, FCM_ERR_ARG, "%s: %g tets is too many (limit 4e9)", who, cells);
cleanup:
  return st;
}

/* Kuhn-split grid of n[0] x n[1] x n[2] cubes over [lo, hi] in grid coordinates, the
 * axis `periodic` (or -1) wrapping around, nodes mapped by `map`. */
static fcm_status kuhn_grid(fcm_ctx *ctx, const char *who, const double lo[3], const double hi[3],
                            const fcm_index n[3], int periodic, grid_map map, const double *par,
                            fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  double *x = NULL;
  fcm_index *cells = NULL;
  fcm_index N[3];
  int tets[6][4];
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "%s: output pointer is NULL", who);
  *geom = NULL;
  FCM_TRY(ctx, check_counts(ctx, who, n));
  for (int d = 0; d < 3; d++)
    N[d] = d == periodic ? n[d] : n[d] + 1;
  for (int t = 0; t < 6; t++) {
    memcpy(tets[t], kuhn[t], sizeof tets[t]);
    if (kuhn_det(tets[t]) < 0) {
      const int s = tets[t][1];
      tets[t][1] = tets[t][2], tets[t][2] = s;
    }
  }
  const fcm_index nn = N[0] * N[1] * N[2], ncube = n[0] * n[1] * n[2];
  FCM_ALLOC(ctx, 3 * (size_t)nn, x);
  FCM_ALLOC(ctx, 24 * (size_t)ncube, cells);
  for (fcm_index k = 0; k < N[2]; k++)
    for (fcm_index j = 0; j < N[1]; j++)
      for (fcm_index i = 0; i < N[0]; i++) {
        const fcm_index ijk[3] = {i, j, k};
        double p[3];
        for (int d = 0; d < 3; d++)
          p[d] = ijk[d] == n[d] ? hi[d] : lo[d] + (hi[d] - lo[d]) * (double)ijk[d] / (double)n[d];
        map(par, p, x + 3 * (i + N[0] * (j + N[1] * k)));
      }
  fcm_index *c = cells;
  for (fcm_index k = 0; k < n[2]; k++)
    for (fcm_index j = 0; j < n[1]; j++)
      for (fcm_index i = 0; i < n[0]; i++) {
        fcm_index corner[8];
        for (int v = 0; v < 8; v++) {
          fcm_index q[3] = {i + corner_bit(v, 0), j + corner_bit(v, 1), k + corner_bit(v, 2)};
          if (periodic >= 0 && q[periodic] == n[periodic]) q[periodic] = 0;
          corner[v] = q[0] + N[0] * (q[1] + N[1] * q[2]);
        }
        for (int t = 0; t < 6; t++, c += 4)
          for (int a = 0; a < 4; a++)
            c[a] = corner[tets[t][a]];
      }
  FCM_TRY(ctx,
          fcm__geom_create_take(ctx, who, FCM_ELEMENT_TET4, nn, &x, 6 * ncube, &cells, 1, geom));
cleanup:
  fcm__free(ctx, x);
  fcm__free(ctx, cells);
  return st;
}

static void map_identity(const double *par, const double p[3], double x[3])
{
  (void)par;
  x[0] = p[0], x[1] = p[1], x[2] = p[2];
}

/* par: centre[3], radius. p -> c + R p ((1 - s) + s^2 / |p|), s = max |p_i|. */
static void map_ball(const double *par, const double p[3], double x[3])
{
  const double s = fmax(fabs(p[0]), fmax(fabs(p[1]), fabs(p[2])));
  const double r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  const double f = r > 0.0 ? par[3] * ((1.0 - s) + s * s / r) : 0.0;
  for (int d = 0; d < 3; d++)
    x[d] = par[d] + f * p[d];
}

/* par: centre[3], axis. p = (r, theta, a). */
static void map_tube(const double *par, const double p[3], double x[3])
{
  const int k = (int)par[3], e1 = (k + 1) % 3, e2 = (k + 2) % 3;
  x[e1] = par[e1] + p[0] * cos(p[1]);
  x[e2] = par[e2] + p[0] * sin(p[1]);
  x[k] = par[k] + p[2];
}

fcm_status fcm_geometry_create_box(fcm_ctx *ctx, const double lo[3], const double hi[3],
                                   const fcm_index n[3], fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "geometry box: output pointer is NULL");
  *geom = NULL;
  FCM_CHECK(ctx && lo && hi && n, ctx, FCM_ERR_ARG,
            "geometry box: NULL argument (ctx, lo, hi and n are required)");
  for (int d = 0; d < 3; d++)
    FCM_CHECK(isfinite(lo[d]) && isfinite(hi[d]) && lo[d] < hi[d], ctx, FCM_ERR_ARG,
              "geometry box: axis %d has lo = %g, hi = %g (need finite lo < hi)", d, lo[d], hi[d]);
  FCM_TRY(ctx, kuhn_grid(ctx, "geometry box", lo, hi, n, -1, map_identity, NULL, geom));
cleanup:
  return st;
}

static fcm_status ball_args(fcm_ctx *ctx, const char *who, const double center[3], double radius,
                            int n)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(ctx && center, ctx, FCM_ERR_ARG, "%s: NULL argument (ctx and center are required)",
            who);
  FCM_CHECK(isfinite(center[0]) && isfinite(center[1]) && isfinite(center[2]), ctx, FCM_ERR_ARG,
            "%s: centre is not finite", who);
  FCM_CHECK(isfinite(radius) && radius > 0.0, ctx, FCM_ERR_ARG,
            "%s: radius = %g must be positive and finite", who, radius);
  FCM_CHECK(n >= 1 && n <= 1000, ctx, FCM_ERR_ARG, "%s: resolution n = %d outside [1, 1000]", who,
            n);
cleanup:
  return st;
}

fcm_status fcm_geometry_create_ball(fcm_ctx *ctx, const double center[3], double radius, int n,
                                    fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "geometry ball: output pointer is NULL");
  *geom = NULL;
  FCM_TRY(ctx, ball_args(ctx, "geometry ball", center, radius, n));
  const double par[4] = {center[0], center[1], center[2], radius};
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  const fcm_index cnt[3] = {2 * n, 2 * n, 2 * n};
  FCM_TRY(ctx, kuhn_grid(ctx, "geometry ball", lo, hi, cnt, -1, map_ball, par, geom));
cleanup:
  return st;
}

fcm_status fcm_geometry_create_hemisphere(fcm_ctx *ctx, const double center[3], double radius,
                                          int n, fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "geometry hemisphere: output pointer is NULL");
  *geom = NULL;
  FCM_TRY(ctx, ball_args(ctx, "geometry hemisphere", center, radius, n));
  const double par[4] = {center[0], center[1], center[2], radius};
  const double lo[3] = {-1, 0, -1}, hi[3] = {1, 1, 1};
  const fcm_index cnt[3] = {2 * n, n, 2 * n};
  FCM_TRY(ctx, kuhn_grid(ctx, "geometry hemisphere", lo, hi, cnt, -1, map_ball, par, geom));
cleanup:
  return st;
}

fcm_status fcm_geometry_create_tube(fcm_ctx *ctx, const double center[3], int axis, double r_in,
                                    double r_out, double length, int n_r, int n_theta, int n_axial,
                                    fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  const char *who = "geometry tube";
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "%s: output pointer is NULL", who);
  *geom = NULL;
  FCM_CHECK(ctx && center, ctx, FCM_ERR_ARG, "%s: NULL argument (ctx and center are required)",
            who);
  FCM_CHECK(isfinite(center[0]) && isfinite(center[1]) && isfinite(center[2]), ctx, FCM_ERR_ARG,
            "%s: centre is not finite", who);
  FCM_CHECK(axis >= 0 && axis < 3, ctx, FCM_ERR_ARG, "%s: axis = %d outside [0,3)", who, axis);
  FCM_CHECK(isfinite(r_in) && isfinite(r_out) && r_in > 0.0 && r_in < r_out, ctx, FCM_ERR_ARG,
            "%s: radii r_in = %g, r_out = %g must satisfy 0 < r_in < r_out", who, r_in, r_out);
  FCM_CHECK(isfinite(length) && length > 0.0, ctx, FCM_ERR_ARG,
            "%s: length = %g must be positive and finite", who, length);
  FCM_CHECK(n_r >= 1 && n_r <= 10000 && n_axial >= 1 && n_axial <= 10000, ctx, FCM_ERR_ARG,
            "%s: n_r = %d and n_axial = %d must lie in [1, 10000]", who, n_r, n_axial);
  FCM_CHECK(n_theta >= 6 && n_theta <= 10000, ctx, FCM_ERR_ARG,
            "%s: n_theta = %d outside [6, 10000]", who, n_theta);
  const double par[4] = {center[0], center[1], center[2], (double)axis};
  const double lo[3] = {r_in, 0.0, -0.5 * length}, hi[3] = {r_out, 2.0 * PI, 0.5 * length};
  const fcm_index cnt[3] = {n_r, n_theta, n_axial};
  FCM_TRY(ctx, kuhn_grid(ctx, who, lo, hi, cnt, 1, map_tube, par, geom));
cleanup:
  return st;
}

/* ---------------------------------------------------------------- hollow ball */

static double tet_vol6(const double *a, const double *b, const double *c, const double *d)
{
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return fcm__vec3_det(u, v, w);
}

/* Most shells of a hollow ball (one drop flag per layer lives on the stack). */
#define SHELL_MAX_LAYERS 1000

/* The hollow ball as it is built: a cube surface of n x n quads per face projected
 * equiangularly on the sphere, extruded into `layers` shells between r_in and r_out. */
typedef struct shell {
  const double *center;
  double r_in, r_out, hole_radius;
  int n, layers;
  fcm_index ns;     /* surface nodes */
  fcm_index nq;     /* surface quads: 6 n^2 */
  fcm_index *sid;   /* (n+1)^3 grid node -> surface id, or -1 inside */
  double *dir;      /* ns x 3 unit directions */
  fcm_index *quads; /* nq x 4 surface ids */
  double *x;        /* (layers + 1) ns x 3: node of layer l, surface node s is l ns + s */
} shell;

static fcm_status hollow_ball_args(fcm_ctx *ctx, const char *who, const double center[3],
                                   double r_in, double r_out, double hole_radius, int n, int layers)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(ctx && center, ctx, FCM_ERR_ARG, "%s: NULL argument (ctx and center are required)",
            who);
  FCM_CHECK(isfinite(center[0]) && isfinite(center[1]) && isfinite(center[2]), ctx, FCM_ERR_ARG,
            "%s: centre is not finite", who);
  FCM_CHECK(isfinite(r_in) && isfinite(r_out) && r_in > 0.0 && r_in < r_out, ctx, FCM_ERR_ARG,
            "%s: radii r_in = %g, r_out = %g must satisfy 0 < r_in < r_out", who, r_in, r_out);
  FCM_CHECK(isfinite(hole_radius) && hole_radius >= 0.0 && hole_radius < r_out, ctx, FCM_ERR_ARG,
            "%s: hole radius = %g outside [0, r_out = %g)", who, hole_radius, r_out);
  FCM_CHECK(n >= 1 && n <= 128, ctx, FCM_ERR_ARG, "%s: resolution n = %d outside [1, 128]", who, n);
  FCM_CHECK(layers >= 1 && layers <= SHELL_MAX_LAYERS, ctx, FCM_ERR_ARG,
            "%s: layers = %d outside [1, %d]", who, layers, SHELL_MAX_LAYERS);
cleanup:
  return st;
}

/* Surface ids of the cube grid's boundary nodes and their equiangular directions. */
static fcm_status shell_surface(fcm_ctx *ctx, shell *sh)
{
  fcm_status st = FCM_OK;
  const fcm_index n = sh->n, n1 = n + 1;
  FCM_ALLOC(ctx, (size_t)(n1 * n1 * n1), sh->sid);
  for (fcm_index k = 0; k <= n; k++)
    for (fcm_index j = 0; j <= n; j++)
      for (fcm_index i = 0; i <= n; i++) {
        const int surf = i == 0 || i == n || j == 0 || j == n || k == 0 || k == n;
        sh->sid[i + n1 * (j + n1 * k)] = surf ? sh->ns++ : -1;
      }
  FCM_ALLOC(ctx, 3 * (size_t)sh->ns, sh->dir);
  for (fcm_index k = 0; k <= n; k++)
    for (fcm_index j = 0; j <= n; j++)
      for (fcm_index i = 0; i <= n; i++) {
        const fcm_index s = sh->sid[i + n1 * (j + n1 * k)];
        if (s < 0) continue;
        const fcm_index ijk[3] = {i, j, k};
        double q[3], len = 0.0;
        for (int d = 0; d < 3; d++) {
          const double t = 2.0 * (double)ijk[d] / n - 1.0;
          q[d] = fabs(t) == 1.0 ? t : tan(0.25 * PI * t);
          len += q[d] * q[d];
        }
        len = sqrt(len);
        for (int d = 0; d < 3; d++)
          sh->dir[3 * s + d] = q[d] / len;
      }
cleanup:
  return st;
}

/* Surface quads: for each axis d and side, an n x n patch, as 4 surface ids each. */
static fcm_status shell_quads(fcm_ctx *ctx, shell *sh)
{
  fcm_status st = FCM_OK;
  const fcm_index n = sh->n, n1 = n + 1;
  sh->nq = 6 * n * n;
  FCM_ALLOC(ctx, 4 * (size_t)sh->nq, sh->quads);
  fcm_index q = 0;
  for (int d = 0; d < 3; d++)
    for (int side = 0; side < 2; side++) {
      const int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
      for (fcm_index v = 0; v < n; v++)
        for (fcm_index u = 0; u < n; u++) {
          const fcm_index du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
          for (int a = 0; a < 4; a++) {
            fcm_index ijk[3];
            ijk[d] = side ? n : 0, ijk[d1] = u + du[a], ijk[d2] = v + dv[a];
            sh->quads[4 * q + a] = sh->sid[ijk[0] + n1 * (ijk[1] + n1 * ijk[2])];
          }
          q++;
        }
    }
cleanup:
  return st;
}

/* Nodes of every layer: the directions scaled to the layer's radius. */
static fcm_status shell_nodes(fcm_ctx *ctx, shell *sh)
{
  fcm_status st = FCM_OK;
  const fcm_index ns = sh->ns;
  FCM_ALLOC(ctx, 3 * (size_t)((sh->layers + 1) * ns), sh->x);
  for (int l = 0; l <= sh->layers; l++) {
    const double rho =
        l == sh->layers ? sh->r_out : sh->r_in + (sh->r_out - sh->r_in) * l / sh->layers;
    for (fcm_index s = 0; s < ns; s++)
      for (int d = 0; d < 3; d++)
        sh->x[3 * (l * ns + s) + d] = sh->center[d] + rho * sh->dir[3 * s + d];
  }
cleanup:
  return st;
}

/* Holes: drop[l] = 1 when the hex (quad qv x layer l) has its vertex centroid in one of
 * the three axis cylinders of radius hole_radius; the quads are placed symmetrically, so
 * are the holes. */
static void shell_holes(const shell *sh, const fcm_index *qv, unsigned char *drop)
{
  for (int l = 0; l < sh->layers; l++) {
    const double rho = sh->r_in + (sh->r_out - sh->r_in) * (l + 0.5) / sh->layers;
    double cen[3] = {0, 0, 0};
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        cen[d] += 0.25 * rho * sh->dir[3 * qv[a] + d];
    drop[l] = 0;
    for (int d = 0; d < 3 && sh->hole_radius > 0.0; d++) {
      const double a1 = cen[(d + 1) % 3], a2 = cen[(d + 2) % 3];
      drop[l] |= a1 * a1 + a2 * a2 < sh->hole_radius * sh->hole_radius;
    }
  }
}

/* Tets of the column under quad qv: the quad splits into two triangles along the
 * diagonal through its smallest id; each triangle x layer is a prism of 3 tets by the
 * sorted-id rule, which splits every shared quad side the same way from both prisms.
 * Appends to cells (4 ids per tet, positively oriented) and counts in *nc. */
static void shell_column_tets(const shell *sh, const fcm_index *qv, const unsigned char *drop,
                              fcm_index *cells, fcm_index *nc)
{
  enum { TRIS_PER_QUAD = 2, TETS_PER_PRISM = 3 };
  const fcm_index ns = sh->ns;
  int m = 0; /* corner with the smallest id */
  for (int a = 1; a < 4; a++)
    if (qv[a] < qv[m]) m = a;
  const int base = m % 2;
  const fcm_index tri[TRIS_PER_QUAD][3] = {{qv[base], qv[base + 1], qv[(base + 2) % 4]},
                                           {qv[base], qv[(base + 2) % 4], qv[(base + 3) % 4]}};
  for (int t = 0; t < TRIS_PER_QUAD; t++) {
    fcm_index v[3] = {tri[t][0], tri[t][1], tri[t][2]};
    for (int a = 1; a < 3; a++) /* sort ascending */
      for (int b = a; b > 0 && v[b - 1] > v[b]; b--) {
        const fcm_index s = v[b];
        v[b] = v[b - 1], v[b - 1] = s;
      }
    for (int l = 0; l < sh->layers; l++) {
      if (drop[l]) continue;
      const fcm_index b0 = l * ns + v[0], b1 = l * ns + v[1], b2 = l * ns + v[2];
      const fcm_index t0 = b0 + ns, t1 = b1 + ns, t2 = b2 + ns;
      const fcm_index tt[TETS_PER_PRISM][4] = {
          {b0, b1, b2, t2}, {b0, b1, t1, t2}, {b0, t0, t1, t2}};
      for (int e = 0; e < TETS_PER_PRISM; e++) {
        fcm_index c4[4] = {tt[e][0], tt[e][1], tt[e][2], tt[e][3]};
        const double *x = sh->x;
        if (tet_vol6(x + 3 * c4[0], x + 3 * c4[1], x + 3 * c4[2], x + 3 * c4[3]) < 0.0) {
          const fcm_index s = c4[1];
          c4[1] = c4[2], c4[2] = s;
        }
        memcpy(cells + 4 * *nc, c4, sizeof c4);
        (*nc)++;
      }
    }
  }
}

/* Keep only the nodes the tets use, renumbered in order: *xs (nk x 3) and cells. */
static fcm_status compact_nodes(fcm_ctx *ctx, fcm_index nn, const double *x, fcm_index nc,
                                fcm_index *cells, fcm_index *nk, double **xs)
{
  fcm_status st = FCM_OK;
  fcm_index *used = NULL;
  FCM_ALLOC(ctx, (size_t)nn, used);
  for (fcm_index c = 0; c < 4 * nc; c++)
    used[cells[c]] = 1;
  *nk = 0;
  for (fcm_index a = 0; a < nn; a++)
    used[a] = used[a] ? (*nk)++ : -1;
  FCM_ALLOC(ctx, 3 * (size_t)*nk, *xs);
  for (fcm_index a = 0; a < nn; a++)
    if (used[a] >= 0) memcpy(*xs + 3 * used[a], x + 3 * a, 3 * sizeof *x);
  for (fcm_index c = 0; c < 4 * nc; c++)
    cells[c] = used[cells[c]];
cleanup:
  fcm__free(ctx, used);
  return st;
}

fcm_status fcm_geometry_create_hollow_ball(fcm_ctx *ctx, const double center[3], double r_in,
                                           double r_out, double hole_radius, int n, int layers,
                                           fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  const char *who = "geometry hollow ball";
  shell sh;
  fcm_index *cells = NULL, nc = 0, nk = 0;
  double *xs = NULL;
  memset(&sh, 0, sizeof sh);
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "%s: output pointer is NULL", who);
  *geom = NULL;
  FCM_TRY(ctx, hollow_ball_args(ctx, who, center, r_in, r_out, hole_radius, n, layers));
  sh.center = center;
  sh.r_in = r_in, sh.r_out = r_out, sh.hole_radius = hole_radius;
  sh.n = n, sh.layers = layers;
  FCM_TRY(ctx, shell_surface(ctx, &sh));
  FCM_TRY(ctx, shell_quads(ctx, &sh));
  FCM_TRY(ctx, shell_nodes(ctx, &sh));
  FCM_ALLOC(ctx, 4 * 6 * (size_t)sh.nq * (size_t)layers, cells);
  for (fcm_index q = 0; q < sh.nq; q++) {
    unsigned char drop[SHELL_MAX_LAYERS];
    shell_holes(&sh, sh.quads + 4 * q, drop);
    shell_column_tets(&sh, sh.quads + 4 * q, drop, cells, &nc);
  }
  FCM_TRY(ctx, compact_nodes(ctx, (layers + 1) * sh.ns, sh.x, nc, cells, &nk, &xs));
  FCM_TRY(ctx, fcm__geom_create_take(ctx, who, FCM_ELEMENT_TET4, nk, &xs, nc, &cells, 1, geom));
cleanup:
  fcm__free(ctx, sh.sid);
  fcm__free(ctx, sh.quads);
  fcm__free(ctx, sh.dir);
  fcm__free(ctx, sh.x);
  fcm__free(ctx, cells);
  fcm__free(ctx, xs);
  return st;
}
