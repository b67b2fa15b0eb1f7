/* fcm-converge: the study's lifetime (geometry, facets, reference solution) and one run
 * of it on one mesh and method (FCM with the embedded or Nitsche boundary, or staircase
 * FEM): the cell rules, assembly and CHOLMOD solve with their wall/CPU timings, the L2 and H1
 * errors against the exact field or the reference solution, and the least-squares rate fit of an
 * error series. The problems themselves (fields, loads, boundary conditions, the discrete system)
 * are defined in fcm-converge-study.c; the reference solution in fcm-converge-reference.c. */
#include "fcm-converge-study-impl.h"

#include <fcm/quad.h>
#include <fcm/sim.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---------------------------------------------------------------- the study */

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
    st = cv_tet_index_create(ctx, fcm_geometry_coords(S->geom), fcm_geometry_cells(S->geom), 4,
                             fcm_geometry_num_cells(S->geom), &S->geo_tets);
  if (st == FCM_OK) st = cv_build_facets(S);
  if (st == FCM_OK && setup->problem == CV_REFERENCE) st = cv_reference_create(S);
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
    const fcm_index t = cv_tet_locate(&S->geo_tets, x, l);
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
    cv_inv3(J, Ji);
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
    else if (!cv_reference_eval(S, x, ux, Gx))
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
    if (st == FCM_OK) st = cv_assemble_system(S, space, method == CV_NITSCHE ? 2 : 1, NULL, &K, &f);
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
    if (st == FCM_OK) st = cv_assemble_system(S, space, 0, keep, &K, &f);
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
  st = cv_direct_solve(ctx, K, f, u);
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
