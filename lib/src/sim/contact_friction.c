/* sim: lagged, smoothed Coulomb friction on the contact obstacles (Li et al. 2020, IPC §5).
 *
 * At the start of each substep (the state u_n, the obstacle placed at the substep's end) every
 * point in contact with an obstacle of friction coefficient mu > 0 keeps its normal force
 * lambda = w kappa |b'(d)| and an orthonormal tangent basis T (3 x 2) of the plane normal to the
 * distance's gradient. Within the substep the point's slip is the tangential part
 * s = T^T delta of its motion relative to the obstacle, delta = (o0 + R0 R^T (y - o)) - y_n (the
 * point's displacement seen in the obstacle's frame: y - y_n for a static obstacle, y - y_n -
 * v h for a plane moving at v), and the incremental potential gains the dissipation potential
 *
 *     mu lambda f0(|s|),  f0(x) = -x^3 / (3 eps^2) + x^2 / eps + eps / 3  for x < eps,  x beyond,
 *
 * eps = eps_v h: the friction force mu lambda f1(|s|) s / |s| (f1 = f0': 2 x / eps - x^2 / eps^2
 * below eps, 1 beyond) reaches the Coulomb bound mu lambda at slip velocities above eps_v and
 * falls smoothly to 0 with the slip (the smoothing of static friction). With lambda and T held
 * fixed, the potential's Hessian in s is mu lambda [(2 / eps - x / eps^2) I - s s^T / (eps^2 x)]
 * below eps and mu lambda / x (I - s s^T / x^2) beyond: positive semidefinite, exact. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <string.h>

void fcm__sim_tangent_basis(const double g[3], double T[6])
{
  double e[3] = {0, 0, 0}, t1[3], t2[3];
  const int k = fabs(g[0]) <= fabs(g[1]) ? (fabs(g[0]) <= fabs(g[2]) ? 0 : 2)
                                         : (fabs(g[1]) <= fabs(g[2]) ? 1 : 2);
  e[k] = 1.0;
  fcm__vec3_cross(g, e, t1);
  const double l = fcm__vec3_norm(t1);
  for (int i = 0; i < 3; i++)
    t1[i] /= l;
  fcm__vec3_cross(g, t1, t2);
  memcpy(T, t1, sizeof t1);
  memcpy(T + 3, t2, sizeof t2);
}

int fcm__sim_contact_has_friction(const fcm_integrator *I)
{
  for (int c = 0; c < I->num_contacts; c++)
    if (I->contacts[c].opts.friction > 0.0) return 1;
  return 0;
}

/* The normal forces and tangents of every point within d^ of an obstacle with friction at
 * the state x (obstacles placed at the substep's end); *change (may be NULL): the largest
 * change of a normal force over the largest normal force, old or new. */
static fcm_status lag_at(fcm_integrator *I, const double *x, double *change)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_cpoints *cp = &I->cp;
  const int nn = I->space->nn, nc = I->num_contacts;
  double ue[3 * FCM_ELEMENT_MAX_NODES], dmax = 0.0, lmax = 0.0;
  for (fcm_index k = 0; k < cp->nelem; k++) {
    const fcm_index *ed = I->space->elem_dof + cp->elem[k] * nn;
    for (int a = 0; a < nn; a++)
      memcpy(ue + 3 * a, x + ed[a], 3 * sizeof(double));
    for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
      const double *N = cp->N + (size_t)p * nn;
      double y[3];
      for (int i = 0; i < 3; i++)
        y[i] = cp->X[3 * p + i];
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          y[i] += N[a] * ue[3 * a + i];
      for (int c = 0; c < nc; c++) {
        const sim_contact *ct = &I->contacts[c];
        double d, g[3], *L = cp->lag + 7 * ((size_t)p * nc + c), old = L[0];
        if (!(ct->opts.friction > 0.0) || ct->kind == SIM_CONTACT_BODIES) continue;
        memset(L, 0, 7 * sizeof *L);
        FCM_TRY(ctx, fcm__sim_contact_distance(ctx, ct, &cp->pose[c], y, I->bc_time, ct->dhat,
                                               &cp->buf, &d, g, NULL));
        if (d > 0.0 && d < ct->dhat) {
          const double r = d - ct->dhat, b1 = -2.0 * r * log(d / ct->dhat) - r * r / d;
          L[0] = cp->w[p] * ct->kappa * fabs(b1);
          fcm__sim_tangent_basis(g, L + 1);
        }
        dmax = FCM_MAX(dmax, fabs(L[0] - old));
        lmax = FCM_MAX(lmax, FCM_MAX(L[0], old));
      }
    }
  }
  if (change) *change = lmax > 0.0 ? dmax / lmax : 0.0;
cleanup:
  return st;
}

fcm_status fcm__sim_contact_lag(fcm_integrator *I, double h)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_cpoints *cp = &I->cp;
  const int nc = I->num_contacts;
  for (int c = 0; c < nc; c++) /* contact between bodies: who starts near whom */
    if (I->contacts[c].kind == SIM_CONTACT_BODIES)
      FCM_TRY(ctx, fcm__sim_bodies_prepare(I, &I->contacts[c], I->un));
  if (!cp->lag) return FCM_OK;
  cp->t0 = I->bc_time - h;
  cp->hstep = h;
  for (int c = 0; c < nc; c++) {
    fcm__sim_contact_pose(&I->contacts[c], I->bc_time, &cp->pose[c]);
    fcm__sim_contact_pose(&I->contacts[c], cp->t0, &cp->pose0[c]);
  }
  memset(cp->lag, 0, sizeof(double) * 7 * (size_t)cp->np * (size_t)nc);
  FCM_TRY(ctx, lag_at(I, I->un, NULL));
  for (int c = 0; c < nc; c++)
    if (I->contacts[c].kind == SIM_CONTACT_BODIES)
      FCM_TRY(ctx, fcm__sim_bodies_friction_lag(I, &I->contacts[c], I->un, 1, NULL));
cleanup:
  return st;
}

int fcm__sim_contact_updates(const fcm_integrator *I)
{
  int k = 0;
  if (!I->cp.lag || !(I->cp.hstep > 0.0)) return 0; /* no friction, or static */
  for (int c = 0; c < I->num_contacts; c++)
    if (I->contacts[c].opts.friction > 0.0) k = FCM_MAX(k, I->contacts[c].opts.friction_updates);
  return k;
}

fcm_status fcm__sim_contact_relag(fcm_integrator *I, double *change)
{
  fcm_status st = FCM_OK;
  FCM_TRY(I->ctx, lag_at(I, I->u, change));
  for (int c = 0; c < I->num_contacts; c++)
    if (I->contacts[c].kind == SIM_CONTACT_BODIES) {
      double ch = 0.0;
      FCM_TRY(I->ctx, fcm__sim_bodies_friction_lag(I, &I->contacts[c], I->u, 0, &ch));
      *change = FCM_MAX(*change, ch);
    }
  I->cp.relags++;
cleanup:
  return st;
}

/* The slip delta of a point at y (start y0) relative to obstacle c, and its Jacobian J =
 * d delta / d y (row-major). */
static void relative_motion(const sim_cpoints *cp, const sim_contact *ct, int c, const double y[3],
                            const double y0[3], double delta[3], double J[9])
{
  if (ct->kind == SIM_CONTACT_PLANE || !ct->moving) {
    const double hv = ct->kind == SIM_CONTACT_PLANE ? cp->hstep : 0.0;
    for (int i = 0; i < 3; i++) {
      delta[i] = y[i] - y0[i] - hv * ct->velocity[i];
      for (int j = 0; j < 3; j++)
        J[3 * i + j] = i == j;
    }
    return;
  }
  const sim_pose *P = &cp->pose[c], *P0 = &cp->pose0[c];
  double X[3], r[3];
  for (int i = 0; i < 3; i++)
    r[i] = y[i] - P->o[i];
  for (int j = 0; j < 3; j++)
    X[j] = P->R[j] * r[0] + P->R[3 + j] * r[1] + P->R[6 + j] * r[2];
  for (int i = 0; i < 3; i++) {
    delta[i] = P0->o[i] - y0[i];
    for (int j = 0; j < 3; j++) {
      delta[i] += P0->R[3 * i + j] * X[j];
      double s = 0.0; /* (R0 R^T)_ij */
      for (int k = 0; k < 3; k++)
        s += P0->R[3 * i + k] * P->R[3 * j + k];
      J[3 * i + j] = s;
    }
  }
}

double fcm__sim_contact_friction_work(const fcm_integrator *I, fcm_index p, const double y[3],
                                      const double y0[3])
{
  const sim_cpoints *cp = &I->cp;
  const int nc = I->num_contacts;
  double work = 0.0;
  for (int c = 0; c < nc && cp->lag; c++) {
    const sim_contact *ct = &I->contacts[c];
    const double *L = cp->lag + 7 * ((size_t)p * nc + c), *T = L + 1;
    const double eps = ct->opts.friction_velocity * cp->hstep;
    double delta[3], J[9];
    if (!(L[0] > 0.0) || !(eps > 0.0)) continue;
    relative_motion(cp, ct, c, y, y0, delta, J);
    work += fcm__sim_friction_work(ct->opts.friction * L[0], eps, T, delta);
  }
  return work;
}

double fcm__sim_friction_potential(double ml, double eps, const double T[6], const double delta[3],
                                   double G[3], double A[9])
{
  double s[2], gs[2], Hs[4], e;
  s[0] = fcm__vec3_dot(T, delta);
  s[1] = fcm__vec3_dot(T + 3, delta);
  const double x = sqrt(s[0] * s[0] + s[1] * s[1]);
  if (x < eps) {
    const double q = 2.0 / eps - x / (eps * eps); /* f1(x) / x */
    e = ml * (-x * x * x / (3.0 * eps * eps) + x * x / eps + eps / 3.0);
    for (int i = 0; i < 2; i++) {
      gs[i] = ml * q * s[i];
      for (int j = 0; j < 2; j++)
        Hs[2 * i + j] = ml * ((i == j) * q - (x > 0.0 ? s[i] * s[j] / (eps * eps * x) : 0.0));
    }
  } else {
    e = ml * x;
    for (int i = 0; i < 2; i++) {
      gs[i] = ml * s[i] / x;
      for (int j = 0; j < 2; j++)
        Hs[2 * i + j] = ml / x * ((i == j) - s[i] * s[j] / (x * x));
    }
  }
  /* to delta: G = T gs, A = T Hs T^T */
  for (int i = 0; i < 3; i++) {
    G[i] = T[i] * gs[0] + T[3 + i] * gs[1];
    for (int j = 0; j < 3; j++) {
      double v = 0.0;
      for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++)
          v += T[3 * a + i] * Hs[2 * a + b] * T[3 * b + j];
      A[3 * i + j] = v;
    }
  }
  return e;
}

double fcm__sim_friction_work(double ml, double eps, const double T[6], const double delta[3])
{
  const double s0 = fcm__vec3_dot(T, delta), s1 = fcm__vec3_dot(T + 3, delta);
  const double x = sqrt(s0 * s0 + s1 * s1);
  const double f1 = x < eps ? 2.0 * x / eps - x * x / (eps * eps) : 1.0;
  return ml * f1 * x;
}

double fcm__sim_contact_friction(const fcm_integrator *I, fcm_index p, const double y[3],
                                 const double y0[3], double grad[3], double hess[9])
{
  const sim_cpoints *cp = &I->cp;
  const int nc = I->num_contacts;
  double e = 0.0;
  memset(grad, 0, 3 * sizeof *grad);
  memset(hess, 0, 9 * sizeof *hess);
  for (int c = 0; c < nc; c++) {
    const sim_contact *ct = &I->contacts[c];
    const double *L = cp->lag + 7 * ((size_t)p * nc + c), *T = L + 1;
    const double eps = ct->opts.friction_velocity * cp->hstep;
    if (!(L[0] > 0.0) || !(eps > 0.0)) continue;
    double delta[3], J[9], G[3], A[9];
    relative_motion(cp, ct, c, y, y0, delta, J);
    e += fcm__sim_friction_potential(ct->opts.friction * L[0], eps, T, delta, G, A);
    /* to y: J^T G, J^T A J */
    for (int i = 0; i < 3; i++) {
      for (int k = 0; k < 3; k++)
        grad[i] += J[3 * k + i] * G[k];
      for (int j = 0; j < 3; j++) {
        double v = 0.0;
        for (int k = 0; k < 3; k++)
          for (int m = 0; m < 3; m++)
            v += J[3 * k + i] * A[3 * k + m] * J[3 * m + j];
        hess[3 * i + j] += v;
      }
    }
  }
  return e;
}
