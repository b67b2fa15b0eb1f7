/* fcm-converge: the problems of the convergence study — the curved boundary facets of the
 * geometry, the fields, loads and boundary conditions, and the discrete system (linear
 * elasticity) that every run and the reference solution assemble and solve with CHOLMOD.
 * The study's lifetime, one run and its errors are in fcm-converge-run.c; the reference
 * solution in fcm-converge-reference.c.
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
#include "fcm-converge-study-impl.h"

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

/* ---------------------------------------------------------------- curved boundary facets */

#define FACET_STRIDE 16

fcm_status cv_build_facets(cv_study *S)
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

/* Solve A u = b with CHOLMOD. */
fcm_status cv_direct_solve(fcm_ctx *ctx, fcm_csr *A, const double *b, double *u)
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
fcm_status cv_assemble_system(const cv_study *S, fcm_space *space, int embedded_traction,
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
