/* fcm-condition: one system of the conditioning study — rules, space, A = M + dt^2 K(u) with
 * the clamped DOFs eliminated, the preconditioners, the dense spectrum of S A and a MINRES
 * solve (see fcm-condition.c for the experiment). */
#include "fcm-condition-study.h"

#include <fcm/dense.h>
#include <fcm/embed.h>
#include <fcm/geom.h>
#include <fcm/la.h>
#include <fcm/material.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const prec_names[PREC_COUNT] = {"none", "jacobi", "schwarz", "schwarz-paper", "exact"};
const char *const tangent_model_names[FCM_FICTITIOUS_MODEL_COUNT + 1] = {"projected", "linear",
                                                                         "exact", NULL};

/* ---------------------------------------------------------------- one system */

/* The reduced system of one (element, fraction, stabilization) case. */
typedef struct linsys {
  fcm_mesh *mesh; /* borrowed */
  fcm_geometry *geom;
  fcm_cell_rules *rules;
  fcm_space *space;
  fcm_csr *A;     /* full M + dt^2 K */
  fcm_csr *Af;    /* reduced to the free DOFs */
  fcm_csr *Pf;    /* the preconditioners' matrix M + dt^2 K_pc reduced, NULL: Af */
  fcm_index *map; /* full DOF -> reduced index, or -1 */
  fcm_index n;    /* reduced size */
  double phi_min;
} linsys;

static void system_free(linsys *s)
{
  fcm_csr_destroy(&s->Af);
  fcm_csr_destroy(&s->Pf);
  fcm_csr_destroy(&s->A);
  fcm_space_destroy(&s->space);
  fcm_cell_rules_destroy(&s->rules);
  fcm_geometry_destroy(&s->geom);
  free(s->map);
  s->map = NULL;
}

#define TRY(call)                                                                                  \
  do {                                                                                             \
    st = (call);                                                                                   \
    if (st != FCM_OK) goto done;                                                                   \
  } while (0)

static fcm_status alloc_fail(fcm_ctx *ctx)
{
  (void)ctx;
  fprintf(stderr, PROG ": out of memory\n");
  return FCM_ERR_ALLOC;
}

/* B reduced to the free DOFs of s (s->map, s->n): a new symmetric CSR matrix. */
static fcm_status reduce(fcm_ctx *ctx, const linsys *s, fcm_csr *B, fcm_csr **Bf)
{
  fcm_status st = FCM_OK;
  fcm_index *rp = NULL, nnz;
  int *ci = NULL;
  const fcm_index nd = fcm_space_num_dofs(s->space);
  fcm_csr_get_size(B, NULL, NULL, &nnz);
  const fcm_index *arp = fcm_csr_row_ptr(B);
  const int *aci = fcm_csr_col_idx(B);
  const double *av = fcm_csr_values(B);
  if (!(rp = malloc(sizeof *rp * (size_t)(s->n + 1))) || !(ci = malloc(sizeof *ci * (size_t)nnz))) {
    st = alloc_fail(ctx);
    goto done;
  }
  fcm_index q = 0;
  rp[0] = 0;
  for (fcm_index i = 0; i < nd; i++) {
    if (s->map[i] < 0) continue;
    for (fcm_index p = arp[i]; p < arp[i + 1]; p++)
      if (s->map[aci[p]] >= 0) ci[q++] = (int)s->map[aci[p]];
    rp[s->map[i] + 1] = q;
  }
  TRY(fcm_csr_create(ctx, s->n, s->n, rp, ci, FCM_CSR_SYMMETRIC, Bf));
  double *fv = fcm_csr_values(*Bf);
  q = 0;
  for (fcm_index i = 0; i < nd; i++) {
    if (s->map[i] < 0) continue;
    for (fcm_index p = arp[i]; p < arp[i + 1]; p++)
      if (s->map[aci[p]] >= 0) fv[q++] = av[p];
  }
done:
  free(rp);
  free(ci);
  return st;
}

/* Build rules, space, A = M + dt^2 K(u) and the reduced matrix. */
static fcm_status system_build(fcm_ctx *ctx, const config *c, fcm_mesh *mesh, double phi,
                               double alpha, linsys *s, double *t_rules)
{
  fcm_status st = FCM_OK;
  fcm_csr *K = NULL, *P = NULL;
  double *u = NULL;
  fcm_index *fixed = NULL;
  memset(s, 0, sizeof *s);
  s->mesh = mesh;
  const double eps = cbrt(phi);
  const double lo[3] = {0, 0, 0}, hi[3] = {1 + eps / 3, 1 + eps / 3, 1 + eps / 3};
  const fcm_index one[3] = {1, 1, 1};
  TRY(fcm_geometry_create_box(ctx, lo, hi, one, &s->geom));

  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.min_fraction = 0.0;  /* keep every non-empty cell, however small */
  ro.sliver_rtol = 1e-20; /* the corner pieces have ~phi/24 of the cell volume */
  ro.simplify = c->simplify;
  ro.strength[FCM_RULE_STIFFNESS] = c->stiffness_strength;
  ro.stabilization.mode = alpha > 0.0 ? c->stab_mode : FCM_STABILIZATION_OFF;
  if (alpha > 0.0) ro.stabilization.alpha = alpha;
  double t0 = fcm_wtime();
  TRY(fcm_cell_rules_create(ctx, mesh, s->geom, &ro, &s->rules));
  *t_rules = fcm_wtime() - t0;
  TRY(fcm_space_create_embedded(ctx, mesh, s->rules, &s->space));

  const fcm_index nc = fcm_mesh_num_cells(mesh);
  s->phi_min = 1.0;
  for (fcm_index k = 0; k < nc; k++) {
    double f = fcm_cell_rules_volume_fraction(s->rules, k);
    if (f > 0.0 && f < s->phi_min) s->phi_min = f;
  }

  /* u(X) = X_1 (1, 1, -1) at the nodes */
  const fcm_index nd = fcm_space_num_dofs(s->space), nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  if (!(u = calloc((size_t)nd, sizeof *u))) {
    st = alloc_fail(ctx);
    goto done;
  }
  for (fcm_index a = 0; a < nn; a++) {
    fcm_index d = fcm_space_node_dof(s->space, a);
    if (d < 0) continue;
    u[d] = c->u_scale * X[3 * a];
    u[d + 1] = c->u_scale * X[3 * a];
    u[d + 2] = -c->u_scale * X[3 * a];
  }
  fcm_material m = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, c->young, c->poisson, c->density};
  fcm_material_params mp;
  TRY(fcm_material_setup(ctx, &m, &mp));
  mp.project_psd = c->project; /* default 0: the unprojected tangent */
  fcm_material el = {FCM_MATERIAL_LINEAR, c->young, c->poisson, c->density};
  TRY(fcm_space_matrix_create(s->space, &s->A));
  TRY(fcm_space_matrix_create(s->space, &K));
  TRY(fcm_assemble_mass(s->space, &el, NULL, s->A));
  fcm_assembly_options ao = fcm_assembly_options_default();
  ao.fictitious = (fcm_fictitious_model)c->fictitious;
  TRY(fcm_assemble_hyperelastic(s->space, &mp, u, &ao, NULL, NULL, K));
  fcm_index nnz;
  fcm_csr_get_size(s->A, NULL, NULL, &nnz);
  double *av = fcm_csr_values(s->A);
  const double *kv = fcm_csr_values(K);
  for (fcm_index p = 0; p < nnz; p++)
    av[p] += c->dt * c->dt * kv[p];

  /* eliminate the DOFs of the nodes on X = 0 */
  const double plo[3] = {0, -HUGE_VAL, -HUGE_VAL}, phi_[3] = {0, HUGE_VAL, HUGE_VAL};
  fcm_index nfix = 0;
  TRY(fcm_mesh_nodes_in_box(ctx, mesh, plo, phi_, 1e-12, 0, NULL, &nfix));
  if (!(fixed = malloc(sizeof *fixed * (size_t)(nfix + 1))) ||
      !(s->map = malloc(sizeof *s->map * (size_t)nd))) {
    st = alloc_fail(ctx);
    goto done;
  }
  TRY(fcm_mesh_nodes_in_box(ctx, mesh, plo, phi_, 1e-12, nfix, fixed, &nfix));
  for (fcm_index i = 0; i < nd; i++)
    s->map[i] = 0;
  for (fcm_index k = 0; k < nfix; k++) {
    fcm_index d = fcm_space_node_dof(s->space, fixed[k]);
    if (d >= 0) s->map[d] = s->map[d + 1] = s->map[d + 2] = -1;
  }
  s->n = 0;
  for (fcm_index i = 0; i < nd; i++)
    s->map[i] = s->map[i] < 0 ? -1 : s->n++;
  TRY(reduce(ctx, s, s->A, &s->Af));
  /* the preconditioners' operator, unless A's tangent is PSD already */
  if (c->pc_tangent != FCM_FICTITIOUS_EXACT && !c->project) {
    fcm_csr_destroy(&K);
    TRY(fcm_space_matrix_create(s->space, &P));
    TRY(fcm_space_matrix_create(s->space, &K));
    TRY(fcm_assemble_mass(s->space, &el, NULL, P));
    if (c->pc_tangent == FCM_FICTITIOUS_LINEAR) {
      TRY(fcm_assemble_stiffness(s->space, &el, NULL, K));
    } else {
      fcm_material_params pp = mp;
      pp.project_psd = 1;
      TRY(fcm_assemble_hyperelastic(s->space, &pp, u, &ao, NULL, NULL, K));
    }
    double *pv = fcm_csr_values(P);
    const double *k2 = fcm_csr_values(K);
    for (fcm_index p = 0; p < nnz; p++)
      pv[p] += c->dt * c->dt * k2[p];
    TRY(reduce(ctx, s, P, &s->Pf));
  }
done:
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&P);
  free(u);
  free(fixed);
  return st;
}

/* Schwarz on the reduced matrix: one block per cut cell with phi < theta, holding the free
 * DOFs of its nodes. */
static fcm_status schwarz_build(fcm_ctx *ctx, const config *c, const linsys *s,
                                fcm_schwarz_clamp clamp, fcm_schwarz **P)
{
  fcm_status st = FCM_OK;
  const fcm_index nc = fcm_mesh_num_cells(s->mesh);
  const int npc = fcm_mesh_nodes_per_cell(s->mesh);
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  fcm_index *ptr = malloc(sizeof *ptr * (size_t)(nc + 1)),
            *dofs = malloc(sizeof *dofs * (size_t)(nc * 3 * npc + 1));
  fcm_index nb = 0, q = 0;
  if (!ptr || !dofs) {
    st = alloc_fail(ctx);
    goto done;
  }
  ptr[0] = 0;
  for (fcm_index k = 0; k < nc; k++) {
    if (fcm_cell_rules_class(s->rules, k) != FCM_CELL_CUT ||
        !(fcm_cell_rules_volume_fraction(s->rules, k) < c->theta))
      continue;
    fcm_index q0 = q;
    for (int a = 0; a < npc; a++) {
      fcm_index d = fcm_space_node_dof(s->space, cells[k * npc + a]);
      for (int i = 0; d >= 0 && i < 3; i++)
        if (s->map[d + i] >= 0) dofs[q++] = s->map[d + i];
    }
    if (q > q0) ptr[++nb] = q;
  }
  fcm_schwarz_options so = fcm_schwarz_options_default();
  so.epsilon = c->epsilon;
  so.clamp = clamp;
  TRY(fcm_schwarz_create(ctx, s->Pf ? s->Pf : s->Af, nb, ptr, dofs, &so, P));
done:
  free(ptr);
  free(dofs);
  return st;
}

/* S = P^-1 applied through the Cholesky factor of P (PREC_EXACT). */
static fcm_status direct_operator(void *user, const double *r, double *z)
{
  return fcm_direct_solve(user, r, z);
}

/* kappa of S A for one preconditioner, and a MINRES solve of A x = A 1. */
static fcm_status measure(fcm_ctx *ctx, const config *c, const linsys *s, int prec,
                          const double *Ad, double *Sd, double *Bd, double *w, result *r)
{
  fcm_status st = FCM_OK;
  fcm_jacobi *J = NULL;
  fcm_schwarz *P = NULL;
  fcm_direct *D = NULL;
  fcm_krylov *ws = NULL;
  double *e = NULL, *b = NULL, *x = NULL;
  const fcm_index n = s->n;
  const size_t nn = (size_t)n * (size_t)n;
  int ni = (int)n;
  fcm_operator_fn Sop = NULL;
  void *Suser = NULL;
  r->blocks = r->clamped = 0;
  if (prec == PREC_JACOBI) {
    TRY(fcm_jacobi_create(ctx, s->Pf ? s->Pf : s->Af, FCM_JACOBI_SCALAR, &J));
    Sop = fcm_jacobi_operator;
    Suser = J;
  } else if (prec == PREC_SCHWARZ || prec == PREC_SCHWARZ_PAPER) {
    TRY(schwarz_build(ctx, c, s, prec == PREC_SCHWARZ ? FCM_SCHWARZ_CLAMP : FCM_SCHWARZ_PAPER, &P));
    fcm_schwarz_info si;
    fcm_schwarz_get_info(P, &si);
    r->blocks = si.num_blocks;
    r->clamped = si.clamped_eigenvalues;
    Sop = fcm_schwarz_operator;
    Suser = P;
  } else if (prec == PREC_EXACT) { /* P is SPD: fcm-condition refuses --pc-tangent exact */
    const fcm_csr *Pm = s->Pf ? s->Pf : s->Af;
    TRY(fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, Pm, &D));
    TRY(fcm_direct_analyze(D));
    TRY(fcm_direct_factor(D, fcm_csr_values_read(Pm)));
    Sop = direct_operator;
    Suser = D;
  }

  /* spectrum */
  if (!Sop) {
    TRY(fcm_dense_spectrum_eval(ctx, ni, Ad, NULL, w, NULL));
  } else {
    if (!(e = calloc((size_t)n, sizeof *e))) {
      st = alloc_fail(ctx);
      goto done;
    }
    for (fcm_index j = 0; j < n; j++) { /* S column by column */
      e[j] = 1.0;
      TRY(Sop(Suser, e, Sd + (size_t)j * n));
      e[j] = 0.0;
    }
    int diagonal = 1; /* Jacobi, or Schwarz without blocks */
    for (fcm_index j = 0; j < n && diagonal; j++)
      for (fcm_index i = 0; i < n; i++)
        if (i != j && Sd[i + (size_t)j * n] != 0.0) {
          diagonal = 0;
          break;
        }
    if (diagonal) { /* diagonal S: scale A symmetrically, no Cholesky needed */
      for (fcm_index j = 0; j < n; j++)
        for (fcm_index i = 0; i < n; i++)
          Bd[i + (size_t)j * n] =
              sqrt(Sd[i + (size_t)i * n] * Sd[j + (size_t)j * n]) * Ad[i + (size_t)j * n];
      TRY(fcm_dense_spectrum_eval(ctx, ni, Bd, NULL, w, NULL));
    } else {
      for (size_t p = 0; p < nn; p++) /* symmetrize the rounding (block sums, solves) */
        Bd[p] = Sd[p];
      for (fcm_index j = 0; j < n; j++)
        for (fcm_index i = 0; i < n; i++)
          Sd[i + (size_t)j * n] = 0.5 * (Bd[i + (size_t)j * n] + Bd[j + (size_t)i * n]);
      TRY(fcm_dense_spectrum_eval(ctx, ni, Ad, Sd, w, NULL));
    }
  }
  double lmin = HUGE_VAL, lmax = 0.0;
  r->negative = 0;
  for (fcm_index k = 0; k < n; k++) {
    double l = fabs(w[k]);
    if (l < lmin) lmin = l;
    if (l > lmax) lmax = l;
    if (w[k] < 0.0) r->negative++;
  }
  r->lmin_abs = lmin;
  r->lmax_abs = lmax;
  r->kappa = lmin > 0.0 ? lmax / lmin : HUGE_VAL;

  /* MINRES on A x = A 1 */
  if (!(b = malloc(sizeof *b * (size_t)n)) || !(x = calloc((size_t)n, sizeof *x))) {
    st = alloc_fail(ctx);
    goto done;
  }
  for (fcm_index i = 0; i < n; i++)
    x[i] = 1.0;
  TRY(fcm_csr_apply(s->Af, 1.0, x, 0.0, b));
  for (fcm_index i = 0; i < n; i++)
    x[i] = 0.0;
  TRY(fcm_krylov_create(ctx, n, &ws));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = c->rtol;
  ko.max_iterations = c->minres_max;
  ko.check_true_residual = 1;
  fcm_krylov_info ki;
  st = fcm_krylov_minres(ws, fcm_csr_operator, s->Af, Sop, Suser, b, x, &ko, &ki);
  if (st == FCM_ERR_NOT_CONVERGED || st == FCM_ERR_NUMERIC) { /* a result, not a failure */
    fcm_ctx_error_clear(ctx);
    st = FCM_OK;
  }
  TRY(st);
  r->iterations = ki.iterations;
  r->reason = ki.reason;
  r->true_residual = ki.true_residual;
done:
  fcm_jacobi_destroy(&J);
  fcm_schwarz_destroy(&P);
  fcm_direct_destroy(&D);
  fcm_krylov_destroy(&ws);
  free(e);
  free(b);
  free(x);
  return st;
}

/* All preconditioners for one (element, fraction, alpha); appends to res. */
fcm_status condition_run_case(fcm_ctx *ctx, const config *c, fcm_mesh *mesh, double phi,
                              double alpha, result *res, int *nres)
{
  fcm_status st = FCM_OK;
  linsys s;
  double *Ad = NULL, *Sd = NULL, *Bd = NULL, *w = NULL, t_rules = 0.0;
  const double t0 = fcm_wtime();
  const char *ename = fcm_element_get_info(fcm_mesh_element_type(mesh))->name;
  st = system_build(ctx, c, mesh, phi, alpha, &s, &t_rules);
  if (st != FCM_OK) goto done;
  const fcm_index n = s.n;
  const size_t nn = (size_t)n * (size_t)n;
  if (!(Ad = calloc(nn, sizeof *Ad)) || !(Sd = calloc(nn, sizeof *Sd)) ||
      !(Bd = calloc(nn, sizeof *Bd)) || !(w = calloc((size_t)n, sizeof *w))) {
    st = alloc_fail(ctx);
    goto done;
  }
  {
    const fcm_index *rp = fcm_csr_row_ptr(s.Af);
    const int *ci = fcm_csr_col_idx(s.Af);
    const double *v = fcm_csr_values(s.Af);
    for (fcm_index i = 0; i < n; i++)
      for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
        Ad[i + (size_t)ci[p] * n] = v[p];
  }
  const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(s.rules);
  fprintf(stderr, "[%s phi=%-7.2g alpha=%-5.2g] %lld dofs, %lld cut cells, rules %.2f s%s", ename,
          phi, alpha, (long long)n, (long long)rs->num_cut, t_rules,
          rs->simplify_fallbacks[0] + rs->simplify_fallbacks[1] > 0 ? " (simplify fallbacks)" : "");
  for (int k = 0; k < c->num_precs; k++) {
    result *r = &res[*nres];
    memset(r, 0, sizeof *r);
    r->element = fcm_mesh_element_type(mesh);
    r->prec = c->precs[k];
    r->alpha = alpha;
    r->phi_nominal = phi;
    r->phi_min = s.phi_min;
    r->dofs = n;
    TRY(measure(ctx, c, &s, c->precs[k], Ad, Sd, Bd, w, r));
    fprintf(stderr, ", %s %.2e/%d", prec_names[r->prec], r->kappa, r->iterations);
    (*nres)++;
  }
  fprintf(stderr, " (%.1f s)\n", fcm_wtime() - t0);
done:
  system_free(&s);
  free(Ad);
  free(Sd);
  free(Bd);
  free(w);
  return st;
}
