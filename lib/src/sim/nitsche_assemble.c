/* sim: the per-step terms of the Dirichlet conditions on the embedded boundary (the
 * points and penalties that nitsche.c sets up): the energy, force and tangent of symmetric
 * Nitsche (or a penalty) at the constrained surface points, assembled element by element;
 * the activation of time-windowed constraints; the public evaluation and reaction force;
 * and the scatter of element matrices into the space's pattern, shared with contact.
 *
 * Energy (fcm/sim.h, fcm_boundary_method): with r = P_c (u - g) and t = P(F) N,
 *   Pi(u) = sum_points w ( -t . r + gamma/2 |r|^2 )    (Nitsche; penalty: w gamma/2 |r|^2).
 * Its gradient: f_(a,i) = w ( -S_iL g_aL - p_i t_i N_a + gamma r_i N_a ), S_iL = r_j N_J A_jJiL;
 * its Hessian: w ( -p_i N_a Q_i(b,k) - p_k N_b Q_k(a,i) + gamma p_i d_ik N_a N_b
 *   - dA[r (x) N]_iJkL g_aJ g_bL ), Q_i(b,k) = A_iJkL N_J g_bL (the traction of mode (b,k)),
 * A = dP/dF, dA[D] its derivative along D (central differences; zero for linear elasticity).
 * For linear elasticity this is symmetric Nitsche (Nitsche 1971; Hansbo 2005). */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"
#include "la/mat3.h"
#include "material/material_impl.h"

#include <math.h>
#include <omp.h>
#include <string.h>
void fcm__sim_scatter(const fcm_space *s, fcm_index le, const double *Ke, double *vals)
{
  const int nn = s->nn, nd = 3 * nn;
  const int *off = s->elem_off + (size_t)le * nn * nn;
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++) {
      double *dst = vals + s->row_ptr[fcm__space_elem_row(s, le, a) + i];
      const double *src = Ke + (size_t)(3 * a + i) * nd, *col = Ke + 3 * a + i;
      for (int b = 0; b < nn; b++)
        for (int k = 0; k < 3; k++)
          dst[3 * off[a * nn + b] + k] += 0.5 * (src[3 * b + k] + col[(size_t)(3 * b + k) * nd]);
    }
}

/* Nitsche's force terms of a point beyond the penalty: fe_(a,i) -= w (S_iL g_aL + p_i t_i N_a),
 * S_iL = r_j N_J A_jJiL. */
static void nitsche_force(int nn, const double *G, const double *N, const double nv[3],
                          const int *pc, const double r[3], const double t[3], const double *A,
                          double w, double *fe)
{
  double S[9] = {0}; /* S_iL = r_j N_J A_jJiL */
  for (int j = 0; j < 3; j++)
    for (int J = 0; J < 3; J++) {
      const double c = r[j] * nv[J];
      if (c == 0.0) continue;
      const double *Ar = A + 9 * (3 * j + J);
      for (int m = 0; m < 9; m++)
        S[m] += c * Ar[m];
    }
  for (int a = 0; a < nn; a++) {
    const double *ga = G + 3 * a;
    for (int i = 0; i < 3; i++)
      fe[3 * a + i] -= w * (S[3 * i] * ga[0] + S[3 * i + 1] * ga[1] + S[3 * i + 2] * ga[2] +
                            (pc[i] ? t[i] * N[a] : 0.0));
  }
}

/* Nitsche's symmetric tangent terms of a point: Ke -= w (V Q + Q^T V^T), V_(a,i),i = p_i N_a,
 * with the tractions Q (3 x nd) of the shape modes. */
static void nitsche_tangent(int nn, const double *G, const double *N, const double nv[3],
                            const int *pc, const double *A, double w, double *Ke, double *Q)
{
  const int nd = 3 * nn;
  /* Q_i(b,k) = B_ikL g_bL with B_ikL = A_iJkL N_J */
  double B[27];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      for (int L = 0; L < 3; L++)
        B[9 * i + 3 * k + L] = A[9 * (3 * i) + 3 * k + L] * nv[0] +
                               A[9 * (3 * i + 1) + 3 * k + L] * nv[1] +
                               A[9 * (3 * i + 2) + 3 * k + L] * nv[2];
  for (int i = 0; i < 3; i++)
    for (int b = 0; b < nn; b++) {
      const double *gb = G + 3 * b;
      for (int k = 0; k < 3; k++) {
        const double *Bk = B + 9 * i + 3 * k;
        Q[i * nd + 3 * b + k] = Bk[0] * gb[0] + Bk[1] * gb[1] + Bk[2] * gb[2];
      }
    }
  /* Ke -= w (V Q + Q^T V^T), V_(a,i),i = p_i N_a */
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++) {
      if (!pc[i]) continue;
      const double c = w * N[a];
      const double *Qi = Q + i * nd;
      double *row = Ke + (size_t)(3 * a + i) * nd;
      for (int y = 0; y < nd; y++) {
        row[y] -= c * Qi[y];
        Ke[(size_t)y * nd + 3 * a + i] -= c * Qi[y];
      }
    }
}

/* The tangent term of a point from the material's nonlinearity: Ke_(a,i)(b,k) -=
 * w dA[r (x) N]_iJkL g_aJ g_bL at deformation gradient F, for a residual r of length rn > 0. */
static void material_derivative_term(const fcm_integrator *I, int nn, const double *G,
                                     const double nv[3], const double F[9], const double r[3],
                                     double rn, double w, double *Ke)
{
  const int nd = 3 * nn;
  /* dA along D = r (x) N by central differences, step h along D/|D| (|N| = 1) */
  const double hstep = 1e-5;
  double Fp[9], Fm[9], Ap[81], Am[81];
  for (int i = 0; i < 3; i++)
    for (int J = 0; J < 3; J++) {
      const double d = hstep * r[i] / rn * nv[J];
      Fp[3 * i + J] = F[3 * i + J] + d;
      Fm[3 * i + J] = F[3 * i + J] - d;
    }
  fcm__material_eval(&I->params, Fp, NULL, NULL, Ap);
  fcm__material_eval(&I->params, Fm, NULL, NULL, Am);
  const double sc = w * rn / (2.0 * hstep);
  for (int m = 0; m < 81; m++)
    Ap[m] = sc * (Ap[m] - Am[m]);
  /* C[i][J][k] = dA_iJkL g_bL, then Ke_(a,i)(b,k) -= g_aJ C[i][J][k] */
  for (int b = 0; b < nn; b++) {
    const double *gb = G + 3 * b;
    double C[27];
    for (int m = 0; m < 27; m++)
      C[m] = Ap[3 * m] * gb[0] + Ap[3 * m + 1] * gb[1] + Ap[3 * m + 2] * gb[2];
    for (int a = 0; a < nn; a++) {
      const double *ga = G + 3 * a;
      for (int i = 0; i < 3; i++) {
        double *row = Ke + (size_t)(3 * a + i) * nd + 3 * b;
        for (int k = 0; k < 3; k++)
          row[k] -= ga[0] * C[9 * i + k] + ga[1] * C[9 * i + 3 + k] + ga[2] * C[9 * i + 6 + k];
      }
    }
  }
}

/* The terms of one point into fe / Ke (either may be NULL); returns its energy, NaN when the
 * material gives NaN/Inf. */
static double point_terms(const fcm_integrator *I, fcm_index p, const double *ue, int projected,
                          fcm_index e, double *fe, double *Ke, double *Q)
{
  const sim_bpoints *bp = &I->bp;
  const sim_bcon *bc = &I->bcons[bp->con[p]];
  const int nn = I->space->nn, nd = 3 * nn;
  const int *pc = bc->motion.components;
  const double *N = bp->N + (size_t)p * nn, *G = bp->G + (size_t)p * nd, *nv = bp->nrm + 3 * p;
  const double w = bp->w[p];
  const int nitsche = bc->opts.method == FCM_BOUNDARY_NITSCHE;
  const double gamma = nitsche ? bp->gamma[e] : bc->opts.penalty * I->mat.young / bp->hk[e];
  double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, u[3] = {0, 0, 0}, gv[3], r[3], P[9], A[81];
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++) {
      u[i] += N[a] * ue[3 * a + i];
      for (int j = 0; j < 3; j++)
        F[3 * i + j] += ue[3 * a + i] * G[3 * a + j];
    }
  if (bc->opts.displacement)
    bc->opts.displacement(bc->opts.displacement_user, bp->X + 3 * p, nv, gv);
  else
    fcm_motion_eval(&bc->motion, bp->X + 3 * p, I->bc_time, gv, NULL);
  for (int i = 0; i < 3; i++)
    r[i] = pc[i] ? u[i] - gv[i] : 0.0;
  double energy = 0.5 * gamma * (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  if (fe)
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++)
        fe[3 * a + i] += w * gamma * r[i] * N[a];
  if (Ke)
    for (int a = 0; a < nn; a++)
      for (int b = 0; b < nn; b++)
        for (int i = 0; i < 3; i++)
          if (pc[i]) Ke[(size_t)(3 * a + i) * nd + 3 * b + i] += w * gamma * N[a] * N[b];
  if (!nitsche) return w * energy;
  const int want_A = fe || (Ke && !projected);
  fcm__material_eval(&I->params, F, NULL, P, want_A ? A : NULL);
  double t[3];
  for (int i = 0; i < 3; i++)
    t[i] = P[3 * i] * nv[0] + P[3 * i + 1] * nv[1] + P[3 * i + 2] * nv[2];
  energy -= t[0] * r[0] + t[1] * r[1] + t[2] * r[2];
  if (!isfinite(energy)) return NAN;
  if (fe) nitsche_force(nn, G, N, nv, pc, r, t, A, w, fe);
  if (Ke && !projected) {
    nitsche_tangent(nn, G, N, nv, pc, A, w, Ke, Q);
    const double rn = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!I->linear && rn > 0.0) material_derivative_term(I, nn, G, nv, F, r, rn, w, Ke);
  }
  return w * energy;
}

fcm_status fcm__sim_boundary_assemble(fcm_integrator *I, const double *x, int projected,
                                      double *energy, double *force, fcm_csr *T, int *finite)
{
  const fcm_space *s = I->space;
  const sim_bpoints *bp = &I->bp;
  const int nn = s->nn, nd = 3 * nn;
  const size_t per = (size_t)nd * (nd + 2) + 9 * (size_t)nn;
  double *vals = T ? fcm_csr_values(T) : NULL, etot = 0.0;
  if (I->bcon_active == 0) return FCM_OK;
  /* colour by colour (no two elements of a colour share a DOF copy), in parallel within a
   * colour; energies summed in element order: the result does not depend on the threads */
  for (int c = 0; c < bp->num_colors; c++) {
    const fcm_index j0 = bp->color_ptr[c], j1 = bp->color_ptr[c + 1];
    if (j0 == j1) continue;
#pragma omp parallel num_threads(bp->nthreads) if (j1 - j0 > 1)
    {
      double *ue = bp->scratch + per * (size_t)omp_get_thread_num(), *fe = ue + nd;
      double *Ke = fe + nd, *Q = Ke + (size_t)nd * nd;
#pragma omp for schedule(dynamic, 4)
      for (fcm_index j = j0; j < j1; j++) {
        const fcm_index k = bp->color_k[j], e = bp->elem[k];
        const fcm_index *ed = s->elem_dof + e * nn;
        double ek = 0.0;
        int any = 0;
        for (int a = 0; a < nn; a++)
          memcpy(ue + 3 * a, x + ed[a], 3 * sizeof(double));
        if (force) memset(fe, 0, sizeof(double) * (size_t)nd);
        if (T) memset(Ke, 0, sizeof(double) * (size_t)nd * nd);
        for (fcm_index p = bp->ptr[k]; p < bp->ptr[k + 1]; p++) {
          if (!I->bcon_on[bp->con[p]]) continue;
          any = 1;
          ek += point_terms(I, p, ue, projected, e, force ? fe : NULL, T ? Ke : NULL, Q);
        }
        bp->eelem[k] = ek;
        if (!any || !isfinite(ek)) continue;
        if (force)
          for (int a = 0; a < nn; a++)
            for (int i = 0; i < 3; i++)
              force[ed[a] + i] += fe[3 * a + i];
        if (T) fcm__sim_scatter(s, bp->lelem[k], Ke, vals);
      }
    }
  }
  for (fcm_index k = 0; k < bp->nelem; k++)
    etot += bp->eelem[k];
  if (!isfinite(etot)) *finite = 0;
  if (energy) *energy += etot;
  if (force)
    for (fcm_index i = 0; i < I->n; i++)
      if (!isfinite(force[i])) *finite = 0;
  return FCM_OK;
}

int fcm__sim_boundary_time(fcm_integrator *I, double t)
{
  int changed = 0, active = 0;
  I->bc_time = t;
  for (int k = 0; k < I->num_bcons; k++) {
    const unsigned char on = (unsigned char)fcm_motion_active(&I->bcons[k].motion, t);
    changed |= on != I->bcon_on[k];
    I->bcon_on[k] = on;
    active += on;
  }
  I->bcon_active = active;
  return changed;
}

/* The largest gamma of the k-th element with points (Nitsche's, or a penalty point's). */
fcm_status fcm__sim_check_pattern(const fcm_integrator *I, const fcm_csr *T, const char *who)
{
  fcm_status st = FCM_OK;
  fcm_index nr = -1, nc = -1, nnz = -1;
  if (!T) return FCM_OK;
  fcm_csr_get_size(T, &nr, &nc, &nnz);
  const fcm_index nrow = fcm__space_num_rows(I->space);
  FCM_CHECK(I->space->row_ptr && nr == nrow && nc == I->n && nnz == I->space->row_ptr[nrow], I->ctx,
            FCM_ERR_ARG,
            "%s: the matrix does not have the space's pattern (use "
            "fcm_space_matrix_create(); a distributed run: the integrator's local rows)",
            who);
cleanup:
  return st;
}

fcm_status fcm_integrator_boundary_eval(fcm_integrator *I, const double *u, double t,
                                        double *energy, double *force, fcm_csr *tangent)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  FCM_CHECK(I->is_setup && u, ctx, FCM_ERR_ARG,
            "boundary eval: NULL displacement, or the integrator is not set up");
  FCM_TRY(ctx, fcm__sim_check_pattern(I, tangent, "boundary eval"));
  {
    const double t_saved = I->bc_time;
    int finite = 1;
    double e = 0.0;
    fcm__sim_boundary_time(I, t);
    st = fcm__sim_boundary_assemble(I, u, I->params.project_psd, &e, force, tangent, &finite);
    fcm__sim_boundary_time(I, t_saved);
    FCM_TRY(ctx, st);
    FCM_CHECK(finite, ctx, FCM_ERR_NUMERIC,
              "boundary eval: the material returned NaN or infinity at a boundary point");
    if (energy) *energy = e;
  }
cleanup:
  return st;
}

fcm_status fcm_integrator_boundary_reaction(const fcm_integrator *I, int id, double force[3],
                                            double moment[3])
{
  fcm_status st = FCM_OK;
  double Fr[3] = {0, 0, 0}, Mr[3] = {0, 0, 0};
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(I->is_setup, I->ctx, FCM_ERR_ARG, "boundary reaction: the integrator is not set up");
  FCM_CHECK(id >= 0 && id < I->num_bcons, I->ctx, FCM_ERR_ARG,
            "boundary reaction: constraint %d out of range [0, %d)", id, I->num_bcons);
  {
    const sim_bpoints *bp = &I->bp;
    const sim_bcon *bc = &I->bcons[id];
    const fcm_space *s = I->space;
    const int nn = s->nn, nd = 3 * nn;
    const int nitsche = bc->opts.method == FCM_BOUNDARY_NITSCHE;
    if (!fcm_motion_active(&bc->motion, I->t)) goto cleanup;
    for (fcm_index k = 0; k < bp->nelem; k++) {
      const fcm_index e = bp->elem[k];
      const fcm_index *ed = s->elem_dof + e * nn;
      for (fcm_index p = bp->ptr[k]; p < bp->ptr[k + 1]; p++) {
        if (bp->con[p] != id) continue;
        const double *N = bp->N + (size_t)p * nn, *G = bp->G + (size_t)p * nd;
        const double *X = bp->X + 3 * p, *nv = bp->nrm + 3 * p;
        const double gamma = nitsche ? bp->gamma[e] : bc->opts.penalty * I->mat.young / bp->hk[e];
        double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, u[3] = {0, 0, 0}, gv[3], R[3], P[9];
        for (int a = 0; a < nn; a++)
          for (int i = 0; i < 3; i++) {
            const double ua = I->u[ed[a] + i];
            u[i] += N[a] * ua;
            for (int j = 0; j < 3; j++)
              F[3 * i + j] += ua * G[3 * a + j];
          }
        if (bc->opts.displacement)
          bc->opts.displacement(bc->opts.displacement_user, X, nv, gv);
        else
          fcm_motion_eval(&bc->motion, X, I->t, gv, NULL);
        if (nitsche) fcm__material_eval(&I->params, F, NULL, P, NULL);
        for (int i = 0; i < 3; i++) {
          const double r = bc->motion.components[i] ? u[i] - gv[i] : 0.0;
          const double t = nitsche && bc->motion.components[i]
                               ? P[3 * i] * nv[0] + P[3 * i + 1] * nv[1] + P[3 * i + 2] * nv[2]
                               : 0.0;
          R[i] = bp->w[p] * (t - gamma * r);
          Fr[i] += R[i];
        }
        const double x[3] = {X[0] + u[0], X[1] + u[1], X[2] + u[2]};
        Mr[0] += x[1] * R[2] - x[2] * R[1];
        Mr[1] += x[2] * R[0] - x[0] * R[2];
        Mr[2] += x[0] * R[1] - x[1] * R[0];
      }
    }
  }
cleanup:
  if (st == FCM_OK) { /* partial sums over own cells' points: sum them */
    double q[6] = {Fr[0], Fr[1], Fr[2], Mr[0], Mr[1], Mr[2]};
    st = I->backend.reduce(I->backend.user, FCM_OK, q, 6);
    for (int i = 0; i < 3; i++)
      Fr[i] = q[i], Mr[i] = q[3 + i];
  }
  if (st == FCM_OK) {
    if (force) memcpy(force, Fr, sizeof Fr);
    if (moment) memcpy(moment, Mr, sizeof Mr);
  }
  return st;
}
