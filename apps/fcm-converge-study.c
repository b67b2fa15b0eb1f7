/* fcm-converge: the problems of the convergence study and one run of it — FCM on the exact
 * embedded hemisphere or staircase FEM, linear elasticity, CHOLMOD, L2/H1 errors.
 *
 * Manufactured problem (lib/METHOD.md §10): on the polyhedral domain Omega (the tet mesh
 * of the hemisphere) the exact field is u_i = A_i sin(k_i . x + phi_i); the body force is
 * b = -div sigma(u), the traction on the curved boundary sigma(u) n with n the facet
 * normal (or, method fcm-nitsche, u = u_exact on the curved boundary imposed weakly by
 * symmetric Nitsche through the library's boundary constraints), and u = u_exact at every
 * background node on y = 0 (the flat face lies there).
 * Reference problem (the authors' setup, Longva et al. 2020 §6.6 and the reference
 * implementation notes): body load -5e5 y exp(-1/(1 - 9 r^2)) e_y for 3 r < 1, u = 0 on
 * y = 0, traction free; the reference is boundary-conforming Tet10 on the geometry's own
 * tets (optionally refined), so both live on exactly the same polyhedron. */
#include "fcm-converge-study.h"

#include <fcm/quad.h>
#include <fcm/sim.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---------------------------------------------------------------- manufactured field */

static const double MS_A[3] = {0.010, 0.008, 0.006};
static const double MS_K[3][3] = {{1.5, 1.2, -0.9}, {-1.1, 1.8, 1.0}, {0.8, -1.3, 1.7}};
static const double MS_PHI[3] = {0.3, -0.7, 1.1};

void cv_exact(const double x[3], double u[3], double G[9])
{
  for (int i = 0; i < 3; i++) {
    const double th = MS_K[i][0] * x[0] + MS_K[i][1] * x[1] + MS_K[i][2] * x[2] + MS_PHI[i];
    const double s = sin(th), c = cos(th);
    if (u) u[i] = MS_A[i] * s;
    if (G)
      for (int j = 0; j < 3; j++)
        G[3 * i + j] = MS_A[i] * MS_K[i][j] * c;
  }
}

/* b_j = -[(lambda + mu) d_j div u + mu Lap u_j] */
void cv_exact_body_force(double lambda, double mu, const double x[3], double b[3])
{
  double sn[3];
  for (int i = 0; i < 3; i++)
    sn[i] = sin(MS_K[i][0] * x[0] + MS_K[i][1] * x[1] + MS_K[i][2] * x[2] + MS_PHI[i]);
  for (int j = 0; j < 3; j++) {
    double ddiv = 0.0;
    for (int i = 0; i < 3; i++)
      ddiv -= MS_A[i] * MS_K[i][i] * MS_K[i][j] * sn[i];
    const double k2 = MS_K[j][0] * MS_K[j][0] + MS_K[j][1] * MS_K[j][1] + MS_K[j][2] * MS_K[j][2];
    b[j] = -((lambda + mu) * ddiv - mu * MS_A[j] * k2 * sn[j]);
  }
}

/* sigma(u_exact(x)) n */
static void exact_traction(double lambda, double mu, const double x[3], const double n[3],
                           double t[3])
{
  double G[9];
  cv_exact(x, NULL, G);
  const double tr = G[0] + G[4] + G[8];
  for (int i = 0; i < 3; i++) {
    t[i] = lambda * tr * n[i];
    for (int j = 0; j < 3; j++)
      t[i] += mu * (G[3 * i + j] + G[3 * j + i]) * n[j];
  }
}

/* The authors' localized load (force per volume). */
static void reference_load(const double x[3], double b[3])
{
  const double r2 = x[0] * x[0] + x[2] * x[2];
  b[0] = b[1] = b[2] = 0.0;
  if (9.0 * r2 < 1.0) b[1] = -5e5 * x[1] * exp(-1.0 / (1.0 - 9.0 * r2));
}

/* ---------------------------------------------------------------- small helpers */

static double det3(const double J[9])
{
  return J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) +
         J[2] * (J[3] * J[7] - J[4] * J[6]);
}

/* Ji = J^{-1}; returns det J. */
static double inv3(const double J[9], double Ji[9])
{
  const double d = det3(J);
  Ji[0] = (J[4] * J[8] - J[5] * J[7]) / d;
  Ji[1] = (J[2] * J[7] - J[1] * J[8]) / d;
  Ji[2] = (J[1] * J[5] - J[2] * J[4]) / d;
  Ji[3] = (J[5] * J[6] - J[3] * J[8]) / d;
  Ji[4] = (J[0] * J[8] - J[2] * J[6]) / d;
  Ji[5] = (J[2] * J[3] - J[0] * J[5]) / d;
  Ji[6] = (J[3] * J[7] - J[4] * J[6]) / d;
  Ji[7] = (J[1] * J[6] - J[0] * J[7]) / d;
  Ji[8] = (J[0] * J[4] - J[1] * J[3]) / d;
  return d;
}

static void cross(const double a[3], const double b[3], double c[3])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double a[3], const double b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Barycentric coordinates of x in the tet (a, b, c, d); returns the smallest. */
static double tet_bary(const double *a, const double *b, const double *c, const double *d,
                       const double x[3], double l[4])
{
  double e1[3], e2[3], e3[3], r[3], J[9], Ji[9];
  for (int k = 0; k < 3; k++)
    e1[k] = b[k] - a[k], e2[k] = c[k] - a[k], e3[k] = d[k] - a[k];
  for (int k = 0; k < 3; k++)
    J[3 * k] = e1[k], J[3 * k + 1] = e2[k], J[3 * k + 2] = e3[k];
  if (!(fabs(inv3(J, Ji)) > 0.0)) return -HUGE_VAL;
  for (int k = 0; k < 3; k++)
    r[k] = x[k] - a[k];
  for (int k = 0; k < 3; k++)
    l[k + 1] = Ji[3 * k] * r[0] + Ji[3 * k + 1] * r[1] + Ji[3 * k + 2] * r[2];
  l[0] = 1.0 - l[1] - l[2] - l[3];
  double m = l[0];
  for (int k = 1; k < 4; k++)
    m = fmin(m, l[k]);
  return m;
}

/* Tets (corner ids, stride `stride`) over `coords`, with an AABB tree of their boxes. */
typedef struct tet_index {
  const double *coords;
  const fcm_index *cells;
  int stride;
  fcm_index n;
  fcm_aabb_tree *tree;
  double tol; /* absolute box tolerance of point queries */
} tet_index;

static fcm_status tet_index_create(fcm_ctx *ctx, const double *coords, const fcm_index *cells,
                                   int stride, fcm_index n, tet_index *ti)
{
  fcm_status st = FCM_OK;
  double *boxes = malloc(sizeof *boxes * 6 * (size_t)(n > 0 ? n : 1));
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  ti->coords = coords, ti->cells = cells, ti->stride = stride, ti->n = n, ti->tree = NULL;
  if (!boxes) return FCM_ERR_ALLOC;
  for (fcm_index t = 0; t < n; t++) {
    double *bx = boxes + 6 * t;
    for (int d = 0; d < 3; d++)
      bx[d] = HUGE_VAL, bx[3 + d] = -HUGE_VAL;
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++) {
        const double v = coords[3 * cells[(size_t)stride * t + a] + d];
        bx[d] = fmin(bx[d], v), bx[3 + d] = fmax(bx[3 + d], v);
        lo[d] = fmin(lo[d], v), hi[d] = fmax(hi[d], v);
      }
  }
  ti->tol = 1e-12 * fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  st = fcm_aabb_tree_create(ctx, n, boxes, &ti->tree);
  free(boxes);
  return st;
}

/* The tet containing x (closed, tolerance 1e-10 in barycentric coordinates), else the
 * candidate with the largest smallest coordinate, else -1. */
static fcm_index tet_locate(const tet_index *ti, const double x[3], double l[4])
{
  fcm_index buf[64], *ids = buf, cnt = 0, best = -1;
  double lo[3], hi[3], bl = -HUGE_VAL, lt[4];
  for (int d = 0; d < 3; d++)
    lo[d] = x[d] - ti->tol, hi[d] = x[d] + ti->tol;
  if (fcm_aabb_tree_query(ti->tree, lo, hi, 64, ids, &cnt) != FCM_OK) return -1;
  if (cnt > 64) { /* the buffer's content is unspecified: query again with room for all */
    ids = malloc(sizeof *ids * (size_t)cnt);
    if (!ids || fcm_aabb_tree_query(ti->tree, lo, hi, cnt, ids, &cnt) != FCM_OK) {
      free(ids);
      return -1;
    }
  }
  for (fcm_index k = 0; k < cnt; k++) {
    const fcm_index *c = ti->cells + (size_t)ti->stride * ids[k];
    const double m = tet_bary(ti->coords + 3 * c[0], ti->coords + 3 * c[1], ti->coords + 3 * c[2],
                              ti->coords + 3 * c[3], x, lt);
    if (m > bl) {
      bl = m, best = ids[k];
      memcpy(l, lt, sizeof lt);
      if (m >= -1e-10) break;
    }
  }
  if (ids != buf) free(ids);
  return best;
}

/* ---------------------------------------------------------------- the study */

struct cv_study {
  fcm_ctx *ctx;
  cv_setup s;
  double lambda, mu;
  fcm_geometry *geom;
  tet_index geo_tets; /* point-in-polyhedron for the staircase classification */
  /* curved boundary facets: vertices (9), unit normal (3), cone axis (3), cone cosine */
  fcm_index nfacets;
  double *facets;
  /* reference mode */
  fcm_mesh *ref_mesh;
  fcm_space *ref_space;
  double *ref_u;
  tet_index ref_tets;
  double ref_time;
};

#define FACET_STRIDE 16

static fcm_status build_facets(cv_study *S)
{
  const fcm_index nt = fcm_geometry_num_boundary_triangles(S->geom);
  const fcm_index *tri = fcm_geometry_boundary_triangles(S->geom);
  const double *X = fcm_geometry_coords(S->geom);
  const double yt = 1e-12 * S->s.radius;
  S->facets = malloc(sizeof *S->facets * FACET_STRIDE * (size_t)(nt > 0 ? nt : 1));
  if (!S->facets) return FCM_ERR_ALLOC;
  S->nfacets = 0;
  for (fcm_index t = 0; t < nt; t++) {
    const double *v[3] = {X + 3 * tri[3 * t], X + 3 * tri[3 * t + 1], X + 3 * tri[3 * t + 2]};
    if (fabs(v[0][1]) < yt && fabs(v[1][1]) < yt && fabs(v[2][1]) < yt) continue; /* flat face */
    double *f = S->facets + FACET_STRIDE * S->nfacets++;
    double e1[3], e2[3], n[3], ax[3] = {0, 0, 0};
    for (int a = 0; a < 3; a++)
      for (int d = 0; d < 3; d++)
        f[3 * a + d] = v[a][d], ax[d] += v[a][d] / 3.0;
    for (int d = 0; d < 3; d++)
      e1[d] = v[1][d] - v[0][d], e2[d] = v[2][d] - v[0][d];
    cross(e1, e2, n);
    const double ln = sqrt(dot(n, n)), la = sqrt(dot(ax, ax));
    double cmin = 1.0;
    for (int d = 0; d < 3; d++)
      f[9 + d] = n[d] / ln, f[12 + d] = ax[d] / la;
    for (int a = 0; a < 3; a++)
      cmin = fmin(cmin, dot(v[a], f + 12) / sqrt(dot(v[a], v[a])));
    f[15] = cmin - 1e-9;
  }
  return FCM_OK;
}

/* The ray from the centre (the origin) in the unit direction d meets the true (polyhedral)
 * curved boundary at y = dist d with outward facet normal n; returns 0 (and the sphere's
 * radius and normal) when no facet is met (not expected: the polyhedron is star-shaped). */
static int ray_hit(const cv_study *S, const double d[3], double n[3], double *dist)
{
  for (fcm_index k = 0; k < S->nfacets; k++) {
    const double *f = S->facets + FACET_STRIDE * k;
    if (dot(d, f + 12) < f[15]) continue;
    /* Moller-Trumbore from the origin */
    double e1[3], e2[3], p[3], q[3], tv[3];
    for (int c = 0; c < 3; c++)
      e1[c] = f[3 + c] - f[c], e2[c] = f[6 + c] - f[c], tv[c] = -f[c];
    cross(d, e2, p);
    const double det = dot(e1, p);
    if (fabs(det) < 1e-300) continue;
    const double u = dot(tv, p) / det;
    cross(tv, e1, q);
    const double v = dot(d, q) / det;
    if (u < -1e-12 || v < -1e-12 || u + v > 1.0 + 1e-12) continue;
    memcpy(n, f + 9, 3 * sizeof *n);
    *dist = dot(e2, q) / det;
    return 1;
  }
  memcpy(n, d, 3 * sizeof *n);
  *dist = S->s.radius;
  return 0;
}

/* The staircase FEM's traction at x on a face of unit outward normal nf, per face area.
 * PROJECTED: the true surface load carried to the staircase along rays from the centre,
 *   t(y) |y|^2 (d.nf) / (|x|^2 (d.n)) with y the ray's hit on the true boundary and n its
 *   normal: the solid-angle measure, so the total force equals that on the true surface
 *   (faces seen edge-on get nothing, faces seen from behind subtract).
 * NAIVE: sigma(u_exact(x)) n_true(x) with the staircase face areas (the total force grows
 *   with the staircase's excess area, O(1): such an FEM does not converge).
 * FACE: sigma(u_exact(x)) nf, the exact traction of the staircase domain itself (control). */
static void staircase_load(const cv_study *S, const double x[3], const double nf[3], double t[3])
{
  const double r = sqrt(dot(x, x));
  double d[3], n[3], dist;
  if (S->s.fem_traction == CV_TRACTION_FACE || !(r > 1e-14)) {
    exact_traction(S->lambda, S->mu, x, nf, t);
    return;
  }
  for (int i = 0; i < 3; i++)
    d[i] = x[i] / r;
  ray_hit(S, d, n, &dist);
  if (S->s.fem_traction == CV_TRACTION_NAIVE) {
    exact_traction(S->lambda, S->mu, x, n, t);
    return;
  }
  const double y[3] = {dist * d[0], dist * d[1], dist * d[2]};
  const double J = dist * dist * dot(d, nf) / (r * r * dot(d, n));
  exact_traction(S->lambda, S->mu, y, n, t);
  for (int i = 0; i < 3; i++)
    t[i] *= J;
}

const fcm_geometry *cv_study_geometry(const cv_study *study)
{
  return study->geom;
}

void cv_study_reference_info(const cv_study *study, fcm_index *dofs, double *seconds)
{
  if (dofs) *dofs = study->ref_space ? fcm_space_num_dofs(study->ref_space) : 0;
  if (seconds) *seconds = study->ref_time;
}

fcm_status cv_mesh_create(fcm_ctx *ctx, fcm_element_type type, int res, fcm_mesh **mesh)
{
  const double lo[3] = {-1, 0, -1}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {2 * res, res, 2 * res};
  return fcm_mesh_create_box(ctx, type, lo, hi, n, mesh);
}

/* ---- loads */

typedef struct load_data {
  const cv_study *S;
} load_data;

static void body_force_cb(void *user, const double x[3], const double n[3], double b[3])
{
  const cv_study *S = ((const load_data *)user)->S;
  (void)n;
  if (S->s.problem == CV_MANUFACTURED)
    cv_exact_body_force(S->lambda, S->mu, x, b);
  else
    reference_load(x, b);
}

static void traction_cb(void *user, const double x[3], const double n[3], double t[3])
{
  const cv_study *S = ((const load_data *)user)->S;
  exact_traction(S->lambda, S->mu, x, n, t);
}

/* Nodes of `space` on y = 0 (DOF triplets) and their prescribed values. */
static fcm_status dirichlet_y0(const cv_study *S, const fcm_space *space, fcm_index *ncon,
                               fcm_index **dofs, double **vals)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const double lo[3] = {-HUGE_VAL, 0.0, -HUGE_VAL}, hi[3] = {HUGE_VAL, 0.0, HUGE_VAL};
  fcm_index cnt = 0, *nodes = NULL;
  *dofs = NULL, *vals = NULL, *ncon = 0;
  st = fcm_mesh_nodes_in_box(S->ctx, mesh, lo, hi, 1e-12, 0, NULL, &cnt);
  if (st != FCM_OK) return st;
  nodes = malloc(sizeof *nodes * (size_t)(cnt + 1));
  *dofs = malloc(sizeof **dofs * 3 * (size_t)(cnt + 1));
  *vals = malloc(sizeof **vals * 3 * (size_t)(cnt + 1));
  if (!nodes || !*dofs || !*vals) {
    free(nodes);
    return FCM_ERR_ALLOC;
  }
  st = fcm_mesh_nodes_in_box(S->ctx, mesh, lo, hi, 1e-12, cnt, nodes, &cnt);
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index k = 0; k < cnt && st == FCM_OK; k++) {
    const fcm_index d = fcm_space_node_dof(space, nodes[k]);
    if (d < 0) continue;
    double u[3] = {0, 0, 0};
    if (S->s.problem == CV_MANUFACTURED) cv_exact(X + 3 * nodes[k], u, NULL);
    for (int i = 0; i < 3; i++)
      (*dofs)[*ncon] = d + i, (*vals)[(*ncon)++] = u[i];
  }
  free(nodes);
  return st;
}

/* The staircase FEM's traction (staircase_load) on the faces of the kept cells that border
 * a cell left out (or the background boundary), except those on y = 0. */
static fcm_status staircase_traction(const cv_study *S, const fcm_space *space,
                                     const unsigned char *keep, double *f)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const fcm_element_type type = info->type;
  const int nn = info->num_nodes, nf = info->num_faces;
  const fcm_index nc = fcm_mesh_num_cells(mesh), *nb = fcm_mesh_neighbors(mesh);
  const fcm_index *cn = fcm_mesh_cells(mesh);
  const double *ref = fcm_element_ref_nodes(type);
  const int sstr = S->s.surface_strength >= 0 ? S->s.surface_strength : 2 * info->order + 2;
  fcm_rule *rule = NULL;
  const fcm_shape fshape = info->shape == FCM_SHAPE_HEX ? FCM_SHAPE_QUAD : FCM_SHAPE_TRI;
  st = fcm_rule_create(ctx, fshape, sstr, &rule);
  if (st != FCM_OK) return st;
  const int nq = fcm_rule_num_points(rule);
  const double *qp = fcm_rule_points(rule), *qw = fcm_rule_weights(rule);
  const double yt = 1e-12;
  for (fcm_index c = 0; c < nc; c++) {
    if (!keep[c]) continue;
    double X[3 * FCM_ELEMENT_MAX_NODES], fe[3 * FCM_ELEMENT_MAX_NODES];
    int have_X = 0;
    for (int fc = 0; fc < nf; fc++) {
      const fcm_index o = nb[(size_t)nf * c + fc];
      if (o >= 0 && keep[o]) continue;
      if (!have_X) fcm_mesh_cell_coords(mesh, c, X), have_X = 1;
      const int ncorn = info->face_num_corners[fc];
      const int *fn = info->face_nodes[fc];
      int on_y0 = 1;
      for (int k = 0; k < ncorn; k++)
        on_y0 &= fabs(X[3 * fn[k] + 1]) < yt;
      if (on_y0) continue;
      memset(fe, 0, sizeof(double) * 3 * (size_t)nn);
      for (int q = 0; q < nq; q++) {
        const double s = qp[2 * q], t = qp[2 * q + 1];
        double xi[3] = {0, 0, 0}, ds[3] = {0, 0, 0}, dt[3] = {0, 0, 0};
        if (fshape == FCM_SHAPE_QUAD) {
          const double L[4] = {(1 - s) * (1 - t) / 4, (1 + s) * (1 - t) / 4, (1 + s) * (1 + t) / 4,
                               (1 - s) * (1 + t) / 4};
          const double Ls[4] = {-(1 - t) / 4, (1 - t) / 4, (1 + t) / 4, -(1 + t) / 4};
          const double Lt[4] = {-(1 - s) / 4, -(1 + s) / 4, (1 + s) / 4, (1 - s) / 4};
          for (int k = 0; k < 4; k++)
            for (int d = 0; d < 3; d++) {
              const double r = ref[3 * fn[k] + d];
              xi[d] += L[k] * r, ds[d] += Ls[k] * r, dt[d] += Lt[k] * r;
            }
        } else {
          for (int d = 0; d < 3; d++) {
            const double r0 = ref[3 * fn[0] + d], r1 = ref[3 * fn[1] + d], r2 = ref[3 * fn[2] + d];
            xi[d] = r0 + s * (r1 - r0) + t * (r2 - r0);
            ds[d] = r1 - r0, dt[d] = r2 - r0;
          }
        }
        double J[9], x[3], a[3], b[3], ab[3], n[3], tr[3], N[FCM_ELEMENT_MAX_NODES];
        fcm_element_jacobian(type, X, xi, J);
        fcm_element_map(type, X, xi, x);
        for (int i = 0; i < 3; i++) {
          a[i] = J[3 * i] * ds[0] + J[3 * i + 1] * ds[1] + J[3 * i + 2] * ds[2];
          b[i] = J[3 * i] * dt[0] + J[3 * i + 1] * dt[1] + J[3 * i + 2] * dt[2];
        }
        cross(a, b, ab);
        const double dA = qw[q] * sqrt(dot(ab, ab));
        for (int i = 0; i < 3; i++)
          n[i] = ab[i] / sqrt(dot(ab, ab));
        staircase_load(S, x, n, tr);
        fcm_element_eval_shape(type, xi, N);
        for (int k = 0; k < nn; k++)
          for (int i = 0; i < 3; i++)
            fe[3 * k + i] += dA * N[k] * tr[i];
      }
      for (int k = 0; k < nn; k++) {
        const fcm_index d = fcm_space_node_dof(space, cn[(size_t)nn * c + k]);
        for (int i = 0; i < 3; i++)
          f[d + i] += fe[3 * k + i];
      }
    }
  }
  fcm_rule_destroy(&rule);
  return st;
}

/* ---- reference solution (boundary-conforming Tet10 on the geometry's tets) */

typedef struct edge_key {
  fcm_index a, b;
} edge_key;

static int edge_cmp(const void *p, const void *q)
{
  const edge_key *x = p, *y = q;
  if (x->a != y->a) return x->a < y->a ? -1 : 1;
  return x->b < y->b ? -1 : x->b > y->b;
}

/* Unique edges of Tet4 cells (sorted); `edges` has capacity 6 n. */
static fcm_index unique_edges(fcm_index n, const fcm_index *tets, edge_key *edges)
{
  static const int E[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  fcm_index m = 0;
  for (fcm_index t = 0; t < n; t++)
    for (int e = 0; e < 6; e++) {
      fcm_index a = tets[4 * t + E[e][0]], b = tets[4 * t + E[e][1]];
      edges[m].a = a < b ? a : b, edges[m].b = a < b ? b : a, m++;
    }
  qsort(edges, (size_t)m, sizeof *edges, edge_cmp);
  fcm_index u = 0;
  for (fcm_index k = 0; k < m; k++)
    if (u == 0 || edge_cmp(edges + k, edges + u - 1)) edges[u++] = edges[k];
  return u;
}

static fcm_index edge_id(const edge_key *edges, fcm_index ne, fcm_index a, fcm_index b)
{
  edge_key k = {a < b ? a : b, a < b ? b : a};
  const edge_key *p = bsearch(&k, edges, (size_t)ne, sizeof *edges, edge_cmp);
  return p ? (fcm_index)(p - edges) : -1;
}

static double tet_volume6(const double *X, const fcm_index *t)
{
  double J[9];
  for (int k = 0; k < 3; k++)
    for (int d = 0; d < 3; d++)
      J[3 * d + k] = X[3 * t[k + 1] + d] - X[3 * t[0] + d];
  return det3(J);
}

/* Edge midpoints appended to the nodes: coordinates grow from nv to nv + ne. */
static fcm_status add_midpoints(fcm_index nt, const fcm_index *tets, fcm_index *nv, double **X,
                                edge_key **edges, fcm_index *ne)
{
  *edges = malloc(sizeof **edges * 6 * (size_t)(nt > 0 ? nt : 1));
  if (!*edges) return FCM_ERR_ALLOC;
  *ne = unique_edges(nt, tets, *edges);
  double *Y = realloc(*X, sizeof *Y * 3 * (size_t)(*nv + *ne));
  if (!Y) return FCM_ERR_ALLOC;
  *X = Y;
  for (fcm_index e = 0; e < *ne; e++)
    for (int d = 0; d < 3; d++)
      Y[3 * (*nv + e) + d] = 0.5 * (Y[3 * (*edges)[e].a + d] + Y[3 * (*edges)[e].b + d]);
  return FCM_OK;
}

/* One uniform (red) refinement: every tet into 8, positively oriented. */
static fcm_status refine_tets(fcm_index *nv, double **X, fcm_index *nt, fcm_index **tets)
{
  edge_key *edges = NULL;
  fcm_index ne = 0, n = *nt, v0 = *nv;
  fcm_status st = add_midpoints(n, *tets, nv, X, &edges, &ne);
  fcm_index *T = st == FCM_OK ? malloc(sizeof *T * 32 * (size_t)(n > 0 ? n : 1)) : NULL;
  if (st == FCM_OK && !T) st = FCM_ERR_ALLOC;
  for (fcm_index t = 0; t < n && st == FCM_OK; t++) {
    const fcm_index *c = *tets + 4 * t;
    fcm_index m[4][4];
    for (int i = 0; i < 4; i++)
      for (int j = i + 1; j < 4; j++)
        m[i][j] = m[j][i] = v0 + edge_id(edges, ne, c[i], c[j]);
    const fcm_index sub[8][4] = {
        {c[0], m[0][1], m[0][2], m[0][3]},    {m[0][1], c[1], m[1][2], m[1][3]},
        {m[0][2], m[1][2], c[2], m[2][3]},    {m[0][3], m[1][3], m[2][3], c[3]},
        {m[0][1], m[0][2], m[0][3], m[1][3]}, {m[0][1], m[0][2], m[1][2], m[1][3]},
        {m[0][2], m[0][3], m[1][3], m[2][3]}, {m[0][2], m[1][2], m[1][3], m[2][3]}};
    for (int k = 0; k < 8; k++) {
      fcm_index *o = T + 4 * (8 * t + k);
      memcpy(o, sub[k], sizeof sub[k]);
      if (tet_volume6(*X, o) < 0.0) {
        const fcm_index tmp = o[1];
        o[1] = o[2], o[2] = tmp;
      }
    }
  }
  free(edges);
  if (st == FCM_OK) {
    free(*tets);
    *tets = T;
    *nv += ne;
    *nt = 8 * n;
  } else {
    free(T);
  }
  return st;
}

/* Tet10 mesh on the Tet4 cells (VTK edge order from the element info). */
static fcm_status make_tet10(fcm_ctx *ctx, fcm_index nv, double *X, fcm_index nt,
                             const fcm_index *tets, fcm_mesh **mesh)
{
  const fcm_element_info *info = fcm_element_get_info(FCM_ELEMENT_TET10);
  edge_key *edges = NULL;
  fcm_index ne = 0, v = nv;
  double *Y = malloc(sizeof *Y * 3 * (size_t)(nv > 0 ? nv : 1));
  if (!Y) return FCM_ERR_ALLOC;
  memcpy(Y, X, sizeof *Y * 3 * (size_t)nv);
  fcm_status st = add_midpoints(nt, tets, &v, &Y, &edges, &ne);
  fcm_index *C = st == FCM_OK ? malloc(sizeof *C * 10 * (size_t)(nt > 0 ? nt : 1)) : NULL;
  if (st == FCM_OK && !C) st = FCM_ERR_ALLOC;
  for (fcm_index t = 0; t < nt && st == FCM_OK; t++) {
    const fcm_index *c = tets + 4 * t;
    fcm_index *o = C + 10 * t;
    for (int a = 0; a < 4; a++)
      o[a] = c[a];
    for (int e = 0; e < info->num_edges; e++)
      o[info->edge_nodes[e][2]] =
          nv + edge_id(edges, ne, c[info->edge_nodes[e][0]], c[info->edge_nodes[e][1]]);
  }
  if (st == FCM_OK) st = fcm_mesh_create(ctx, FCM_ELEMENT_TET10, nv + ne, Y, nt, C, mesh);
  free(edges);
  free(Y);
  free(C);
  return st;
}

/* Solve A u = b with CHOLMOD. */
static fcm_status direct_solve(fcm_ctx *ctx, fcm_csr *A, const double *b, double *u)
{
  fcm_direct *solver = NULL;
  fcm_status st = fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &solver);
  if (st == FCM_OK) st = fcm_direct_analyze(solver);
  if (st == FCM_OK) st = fcm_direct_factor(solver, fcm_csr_values(A));
  if (st == FCM_OK) st = fcm_direct_solve(solver, b, u);
  fcm_direct_destroy(&solver);
  return st;
}

/* --boundary nitsche: the exact displacement, prescribed on the curved boundary (the
 * points whose outward normal is not the flat face's -e_y). */
static void exact_displacement_cb(void *user, const double x[3], const double n[3], double u[3])
{
  (void)user, (void)n;
  cv_exact(x, u, NULL);
}

static int curved_cb(void *user, const double X[3], const double n[3])
{
  (void)user, (void)X;
  return n[1] > -0.5;
}

/* Symmetric Nitsche on the curved boundary (fcm_integrator_add_boundary_constraint, the
 * library's estimate of the penalty): the linear problem's matrix N and load -grad Pi(0),
 * from the integrator's boundary terms at u = 0 (Pi is quadratic: K u + N u = f - grad Pi(0)). */
static fcm_status nitsche_terms(const cv_study *S, fcm_space *space, fcm_csr *K, double *f)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_material mat = {FCM_MATERIAL_LINEAR, S->s.young, S->s.poisson, 0.0};
  fcm_integrator_options io = fcm_integrator_options_default();
  fcm_boundary_options bo = fcm_boundary_options_default();
  const fcm_motion m = fcm_motion_default();
  fcm_integrator *I = NULL;
  const fcm_index n = fcm_space_num_dofs(space);
  double *u0 = calloc((size_t)n, sizeof *u0), *g0 = calloc((size_t)n, sizeof *g0);
  if (!u0 || !g0) st = FCM_ERR_ALLOC;
  io.kind = FCM_INTEGRATOR_STATIC;
  io.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
  io.linear_solver = FCM_LINEAR_CG; /* no factorization: only the boundary terms are used */
  io.preconditioner = FCM_PRECOND_JACOBI;
  bo.displacement = exact_displacement_cb;
  if (st == FCM_OK) st = fcm_integrator_create(ctx, space, &mat, &io, &I);
  if (st == FCM_OK) st = fcm_integrator_add_boundary_constraint(I, curved_cb, NULL, &m, &bo, NULL);
  if (st == FCM_OK) st = fcm_integrator_setup(I);
  if (st == FCM_OK) st = fcm_integrator_boundary_eval(I, u0, 0.0, NULL, g0, K);
  if (st == FCM_OK)
    for (fcm_index i = 0; i < n; i++)
      f[i] -= g0[i];
  fcm_integrator_destroy(&I);
  free(u0);
  free(g0);
  return st;
}

/* Assemble K u = f (stiffness, body force, optional embedded traction or Nitsche terms),
 * eliminate the y = 0 nodes; `extra` adds a caller load (the staircase traction) before
 * elimination. */
static fcm_status assemble_system(const cv_study *S, fcm_space *space, int embedded_traction,
                                  const unsigned char *staircase_keep, fcm_csr **K, double **f)
{
  fcm_status st = FCM_OK;
  const fcm_material mat = {FCM_MATERIAL_LINEAR, S->s.young, S->s.poisson, 0.0};
  load_data ld = {S};
  fcm_index ncon = 0, *dofs = NULL;
  double *vals = NULL;
  const fcm_index n = fcm_space_num_dofs(space);
  *K = NULL;
  *f = calloc((size_t)n, sizeof **f);
  if (!*f) return FCM_ERR_ALLOC;
  st = fcm_space_matrix_create(space, K);
  if (st == FCM_OK) st = fcm_assemble_stiffness(space, &mat, NULL, *K);
  if (st == FCM_OK) st = fcm_assemble_body_force_field(space, body_force_cb, &ld, NULL, *f);
  if (st == FCM_OK && embedded_traction == 1 && S->s.problem == CV_MANUFACTURED)
    st = fcm_assemble_surface_traction(space, traction_cb, &ld, *f);
  if (st == FCM_OK && embedded_traction == 2 && S->s.problem == CV_MANUFACTURED)
    st = nitsche_terms(S, space, *K, *f);
  if (st == FCM_OK && staircase_keep && S->s.problem == CV_MANUFACTURED)
    st = staircase_traction(S, space, staircase_keep, *f);
  if (st == FCM_OK) st = dirichlet_y0(S, space, &ncon, &dofs, &vals);
  if (st == FCM_OK) st = fcm_space_apply_dirichlet(space, ncon, dofs, vals, *K, *f);
  free(dofs);
  free(vals);
  return st;
}

static fcm_status reference_create(cv_study *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_index nv = fcm_geometry_num_nodes(S->geom), nt = fcm_geometry_num_cells(S->geom);
  double *X = malloc(sizeof *X * 3 * (size_t)nv), *f = NULL;
  fcm_index *T = malloc(sizeof *T * 4 * (size_t)nt);
  fcm_csr *K = NULL;
  const double t0 = fcm_wtime();
  if (!X || !T) {
    free(X), free(T);
    return FCM_ERR_ALLOC;
  }
  memcpy(X, fcm_geometry_coords(S->geom), sizeof *X * 3 * (size_t)nv);
  memcpy(T, fcm_geometry_cells(S->geom), sizeof *T * 4 * (size_t)nt);
  for (int r = 0; r < S->s.ref_refine && st == FCM_OK; r++)
    st = refine_tets(&nv, &X, &nt, &T);
  if (st == FCM_OK) st = make_tet10(ctx, nv, X, nt, T, &S->ref_mesh);
  free(X), free(T);
  if (st == FCM_OK) st = fcm_space_create(ctx, S->ref_mesh, NULL, &S->ref_space);
  if (st != FCM_OK) return st;
  const fcm_index n = fcm_space_num_dofs(S->ref_space);
  fprintf(stderr, CV_PROG ": reference: Tet10 on %lld tets (%d refinement(s)), %lld DOFs ...\n",
          (long long)nt, S->s.ref_refine, (long long)n);
  S->ref_u = calloc((size_t)n, sizeof *S->ref_u);
  if (!S->ref_u) return FCM_ERR_ALLOC;
  st = assemble_system(S, S->ref_space, 0, NULL, &K, &f);
  if (st == FCM_OK) st = direct_solve(ctx, K, f, S->ref_u);
  fcm_csr_destroy(&K);
  free(f);
  if (st == FCM_OK)
    st = tet_index_create(ctx, fcm_mesh_coords(S->ref_mesh), fcm_mesh_cells(S->ref_mesh), 10,
                          fcm_mesh_num_cells(S->ref_mesh), &S->ref_tets);
  S->ref_time = fcm_wtime() - t0;
  if (st == FCM_OK) fprintf(stderr, CV_PROG ": reference solved in %.1f s\n", S->ref_time);
  return st;
}

/* Reference displacement and gradient at x; returns 0 when x lies in no reference tet. */
static int reference_eval(const cv_study *S, const double x[3], double u[3], double G[9])
{
  double l[4], N[10], dN[30], J[9], Ji[9], X[30];
  const fcm_index t = tet_locate(&S->ref_tets, x, l);
  if (t < 0 || l[0] < -1e-6 || l[1] < -1e-6 || l[2] < -1e-6 || l[3] < -1e-6) return 0;
  const double xi[3] = {l[1], l[2], l[3]};
  fcm_mesh_cell_coords(S->ref_mesh, t, X);
  fcm_element_eval_shape(FCM_ELEMENT_TET10, xi, N);
  fcm_element_eval_grad(FCM_ELEMENT_TET10, xi, dN);
  fcm_element_jacobian(FCM_ELEMENT_TET10, X, xi, J);
  inv3(J, Ji);
  const fcm_index *cn = fcm_mesh_cells(S->ref_mesh) + 10 * t;
  memset(u, 0, 3 * sizeof *u);
  memset(G, 0, 9 * sizeof *G);
  for (int a = 0; a < 10; a++) {
    const double *ua = S->ref_u + fcm_space_node_dof(S->ref_space, cn[a]);
    double g[3];
    for (int j = 0; j < 3; j++)
      g[j] = dN[3 * a] * Ji[j] + dN[3 * a + 1] * Ji[3 + j] + dN[3 * a + 2] * Ji[6 + j];
    for (int i = 0; i < 3; i++) {
      u[i] += N[a] * ua[i];
      for (int j = 0; j < 3; j++)
        G[3 * i + j] += ua[i] * g[j];
    }
  }
  return 1;
}

fcm_status cv_study_create(fcm_ctx *ctx, const cv_setup *setup, cv_study **study)
{
  fcm_status st = FCM_OK;
  const double c[3] = {0, 0, 0};
  cv_study *S = calloc(1, sizeof *S);
  *study = NULL;
  if (!S) return FCM_ERR_ALLOC;
  S->ctx = ctx;
  S->s = *setup;
  const fcm_material mat = {FCM_MATERIAL_LINEAR, setup->young, setup->poisson, 0.0};
  st = fcm_material_lame(ctx, &mat, &S->lambda, &S->mu);
  if (st == FCM_OK)
    st = fcm_geometry_create_hemisphere(ctx, c, setup->radius, setup->geom_n, &S->geom);
  if (st == FCM_OK)
    st = tet_index_create(ctx, fcm_geometry_coords(S->geom), fcm_geometry_cells(S->geom), 4,
                          fcm_geometry_num_cells(S->geom), &S->geo_tets);
  if (st == FCM_OK) st = build_facets(S);
  if (st == FCM_OK && setup->problem == CV_REFERENCE) st = reference_create(S);
  if (st != FCM_OK) {
    cv_study_destroy(&S);
    return st;
  }
  *study = S;
  return st;
}

void cv_study_destroy(cv_study **study)
{
  if (!study || !*study) return;
  cv_study *S = *study;
  fcm_aabb_tree_destroy(&S->geo_tets.tree);
  fcm_aabb_tree_destroy(&S->ref_tets.tree);
  free(S->facets);
  free(S->ref_u);
  fcm_space_destroy(&S->ref_space);
  fcm_mesh_destroy(&S->ref_mesh);
  fcm_geometry_destroy(&S->geom);
  free(S);
  *study = NULL;
}

/* ---------------------------------------------------------------- one run */

/* Wall-clock and process CPU seconds (all threads) at one instant. */
typedef struct stamp {
  double wall, cpu;
} stamp;

static stamp stamp_now(void)
{
  stamp t = {fcm_wtime(), (double)clock() / CLOCKS_PER_SEC};
  return t;
}

/* Seconds since t0 into *wall and *cpu; returns the current stamp. */
static stamp stamp_lap(stamp t0, double *wall, double *cpu)
{
  const stamp t = stamp_now();
  *wall = t.wall - t0.wall;
  *cpu = t.cpu - t0.cpu;
  return t;
}

fcm_status cv_error_rules_create(cv_study *S, const fcm_mesh *mesh, fcm_cell_rules **rules)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_STIFFNESS] = S->s.error_strength;
  o.kinds = FCM_RULES_STIFFNESS; /* errors need no mass rules */
  o.simplify = 0;
  o.stabilization.mode = FCM_STABILIZATION_OFF;
  o.min_fraction = 0.0;
  return fcm_cell_rules_create(S->ctx, mesh, S->geom, &o, rules);
}

/* Centroid of every cell inside the polyhedron (closed test, 1e-10 in barycentric
 * coordinates of the geometry tet that contains it). */
static fcm_status staircase_cells(const cv_study *S, const fcm_mesh *mesh, unsigned char *keep,
                                  fcm_index *nkeep)
{
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const fcm_index nc = fcm_mesh_num_cells(mesh), *cn = fcm_mesh_cells(mesh);
  const double *X = fcm_mesh_coords(mesh);
  const int nn = info->num_nodes, ncorn = info->num_corners;
  fcm_index cnt = 0;
#pragma omp parallel for schedule(static) reduction(+ : cnt)
  for (fcm_index c = 0; c < nc; c++) {
    double x[3] = {0, 0, 0}, l[4];
    for (int a = 0; a < ncorn; a++)
      for (int d = 0; d < 3; d++)
        x[d] += X[3 * cn[(size_t)nn * c + a] + d] / ncorn;
    const fcm_index t = tet_locate(&S->geo_tets, x, l);
    keep[c] = t >= 0 && l[0] >= -1e-10 && l[1] >= -1e-10 && l[2] >= -1e-10 && l[3] >= -1e-10;
    cnt += keep[c];
  }
  *nkeep = cnt;
  return cnt > 0 ? FCM_OK : FCM_ERR_GEOMETRY;
}

/* Per-cell error sums: [0] |e|^2, [1] |grad e|^2, [2] |u|^2, [3] |grad u|^2, [4] volume. */
static int cell_errors(const cv_study *S, const fcm_space *space, const fcm_cell_rules *er,
                       fcm_index c, fcm_index e, const double *u, double acc[5])
{
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const fcm_element_type type = info->type;
  const int nn = info->num_nodes;
  const fcm_index *cn = fcm_mesh_cells(mesh) + (size_t)nn * e;
  double Xc[3 * FCM_ELEMENT_MAX_NODES], Xe[3 * FCM_ELEMENT_MAX_NODES],
      ue[3 * FCM_ELEMENT_MAX_NODES];
  int np = 0;
  const double *pts = NULL, *w = NULL;
  const unsigned char *flags = NULL;
  fcm_cell_rules_get(er, c, FCM_RULE_STIFFNESS, &np, &pts, &w, &flags);
  fcm_mesh_cell_coords(mesh, c, Xc);
  if (e != c) fcm_mesh_cell_coords(mesh, e, Xe);
  for (int a = 0; a < nn; a++)
    memcpy(ue + 3 * a, u + fcm_space_node_dof(space, cn[a]), 3 * sizeof *u);
  for (int q = 0; q < np; q++) {
    if (flags && flags[q]) continue;
    double J[9], Ji[9], x[3], xi[3], N[FCM_ELEMENT_MAX_NODES], dN[3 * FCM_ELEMENT_MAX_NODES];
    const double wq = w[q] * fcm_element_jacobian(type, Xc, pts + 3 * q, J);
    fcm_element_map(type, Xc, pts + 3 * q, x);
    memcpy(xi, pts + 3 * q, sizeof xi);
    if (e != c && fcm_element_inverse_map(NULL, type, Xe, x, xi) != FCM_OK) return 0;
    fcm_element_jacobian(type, e != c ? Xe : Xc, xi, J);
    inv3(J, Ji);
    fcm_element_eval_shape(type, xi, N);
    fcm_element_eval_grad(type, xi, dN);
    double uh[3] = {0, 0, 0}, Gh[9] = {0}, ux[3], Gx[9];
    for (int a = 0; a < nn; a++) {
      double g[3];
      for (int j = 0; j < 3; j++)
        g[j] = dN[3 * a] * Ji[j] + dN[3 * a + 1] * Ji[3 + j] + dN[3 * a + 2] * Ji[6 + j];
      for (int i = 0; i < 3; i++) {
        uh[i] += N[a] * ue[3 * a + i];
        for (int j = 0; j < 3; j++)
          Gh[3 * i + j] += ue[3 * a + i] * g[j];
      }
    }
    if (S->s.problem == CV_MANUFACTURED)
      cv_exact(x, ux, Gx);
    else if (!reference_eval(S, x, ux, Gx))
      return 0;
    for (int i = 0; i < 3; i++) {
      acc[0] += wq * (uh[i] - ux[i]) * (uh[i] - ux[i]);
      acc[2] += wq * ux[i] * ux[i];
    }
    for (int k = 0; k < 9; k++) {
      acc[1] += wq * (Gh[k] - Gx[k]) * (Gh[k] - Gx[k]);
      acc[3] += wq * Gx[k] * Gx[k];
    }
    acc[4] += wq;
  }
  return 1;
}

/* Errors over the cells with error-rule points: FCM cells left out of the space (dropped,
 * phi < min_fraction) are evaluated by extrapolating from an active face neighbour; FEM
 * measures only the part of Omega inside kept cells. */
static fcm_status errors(const cv_study *S, const fcm_space *space, const fcm_cell_rules *er,
                         cv_method method, const double *u, cv_result *r)
{
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const fcm_index nc = fcm_mesh_num_cells(mesh), *nb = fcm_mesh_neighbors(mesh);
  const int nf = fcm_mesh_get_element_info(mesh)->num_faces;
  double *acc = calloc(5 * (size_t)nc, sizeof *acc);
  int bad = 0;
  if (!acc) return FCM_ERR_ALLOC;
#pragma omp parallel for schedule(dynamic, 8) reduction(| : bad)
  for (fcm_index c = 0; c < nc; c++) {
    if (fcm_cell_rules_class(er, c) == FCM_CELL_DROPPED) continue;
    fcm_index e = -1;
    if (fcm_space_cell_active(space, c))
      e = c;
    else if (method != CV_FEM)
      for (int f = 0; f < nf && e < 0; f++) {
        const fcm_index o = nb[(size_t)nf * c + f];
        if (o >= 0 && fcm_space_cell_active(space, o)) e = o;
      }
    if (e < 0) continue;
    if (!cell_errors(S, space, er, c, e, u, acc + 5 * c)) bad = 1;
  }
  double t[5] = {0, 0, 0, 0, 0};
  for (fcm_index c = 0; c < nc; c++)
    for (int k = 0; k < 5; k++)
      t[k] += acc[5 * c + k];
  free(acc);
  r->err_l2 = sqrt(t[0]), r->err_h1 = sqrt(t[1]);
  r->norm_l2 = sqrt(t[2]), r->norm_h1 = sqrt(t[3]);
  r->measured_volume = t[4];
  r->domain_volume = fcm_geometry_volume(S->geom);
  if (bad) {
    fcm_ctx_error_clear(S->ctx);
    return FCM_ERR_NOT_CONVERGED;
  }
  return FCM_OK;
}

fcm_status cv_run(cv_study *S, const fcm_mesh *mesh, const fcm_cell_rules *err_rules,
                  cv_method method, const cv_run_options *ro, cv_result *r)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL;
  double *f = NULL, *u = NULL;
  unsigned char *keep = NULL;
  const int strength = ro && ro->strength >= -1 ? ro->strength : S->s.strength;
  const int simplify = ro && ro->simplify >= 0 ? ro->simplify : S->s.simplify;
  fcm_index nc = fcm_mesh_num_cells(mesh);

  r->element = info->type;
  r->method = method;
  r->failed = 0;
  r->note[0] = '\0';
  stamp t0 = stamp_now();
  if (method == CV_FCM || method == CV_NITSCHE) {
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.strength[FCM_RULE_STIFFNESS] = strength;
    o.kinds = FCM_RULES_STIFFNESS; /* static problem: no mass rules */
    o.surface_strength = S->s.surface_strength >= 0 ? S->s.surface_strength : 2 * info->order + 2;
    o.simplify = simplify;
    o.min_fraction = S->s.min_fraction;
    if (S->s.stab_alpha > 0.0)
      o.stabilization.alpha = S->s.stab_alpha;
    else
      o.stabilization.mode = FCM_STABILIZATION_OFF;
    st = fcm_cell_rules_create(ctx, mesh, S->geom, &o, &rules);
    if (st != FCM_OK) goto done;
    t0 = stamp_lap(t0, &r->t_rules, &r->c_rules);
    const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(rules);
    r->cut_cells = rs->num_cut;
    r->points = rs->points_total[FCM_RULE_STIFFNESS];
    r->strength = fcm_cell_rules_strength(rules, FCM_RULE_STIFFNESS);
    st = fcm_space_create_embedded(ctx, mesh, rules, &space);
    if (st == FCM_OK) st = assemble_system(S, space, method == CV_NITSCHE ? 2 : 1, NULL, &K, &f);
  } else {
    fcm_index nkeep = 0;
    keep = malloc((size_t)nc);
    if (!keep) {
      st = FCM_ERR_ALLOC;
      goto done;
    }
    st = staircase_cells(S, mesh, keep, &nkeep);
    if (st != FCM_OK) goto done;
    t0 = stamp_lap(t0, &r->t_rules, &r->c_rules);
    fcm_rule *std_rule = NULL;
    st = fcm_element_standard_rule(ctx, info->type, FCM_RULE_STIFFNESS, FCM_DEFAULT, &std_rule);
    if (st != FCM_OK) goto done;
    r->points = nkeep * fcm_rule_num_points(std_rule);
    r->strength = fcm_rule_strength(std_rule);
    fcm_rule_destroy(&std_rule);
    r->cut_cells = 0;
    t0 = stamp_now();
    st = fcm_space_create(ctx, mesh, keep, &space);
    if (st == FCM_OK) st = assemble_system(S, space, 0, keep, &K, &f);
  }
  if (st != FCM_OK) goto done;
  stamp_lap(t0, &r->t_assembly, &r->c_assembly);
  r->dofs = fcm_space_num_dofs(space);
  r->active_cells = 0;
  for (fcm_index c = 0; c < nc; c++)
    r->active_cells += fcm_space_cell_active(space, c);
  u = calloc((size_t)r->dofs, sizeof *u);
  if (!u) {
    st = FCM_ERR_ALLOC;
    goto done;
  }
  t0 = stamp_now();
  st = direct_solve(ctx, K, f, u);
  stamp_lap(t0, &r->t_solve, &r->c_solve);
  if (st == FCM_ERR_SINGULAR || st == FCM_ERR_NUMERIC) {
    r->failed = 1;
    snprintf(r->note, sizeof r->note, "solve failed: %s", fcm_ctx_error_message(ctx));
    fcm_ctx_error_clear(ctx);
    st = FCM_OK;
    goto done;
  }
  if (st != FCM_OK) goto done;
  r->t_total = r->t_rules + r->t_assembly + r->t_solve;
  r->c_total = r->c_rules + r->c_assembly + r->c_solve;
  st = errors(S, space, err_rules, method, u, r);
  if (st == FCM_ERR_NOT_CONVERGED) {
    r->failed = 1;
    snprintf(r->note, sizeof r->note, "error evaluation: a point could not be located");
    st = FCM_OK;
  }
done:
  if (r->failed) r->err_l2 = r->err_h1 = NAN;
  free(keep);
  free(u);
  free(f);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  return st;
}

double cv_fit_rate(int n, const double *h, const double *err)
{
  if (n < 2) return NAN;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int k = 0; k < n; k++) {
    const double x = log(h[k]), y = log(err[k]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double d = n * sxx - sx * sx;
  return d > 0.0 ? (n * sxy - sx * sy) / d : NAN;
}
