/* sim: Newton's direction with the contact between bodies — the pairs' coupling, which the
 * space's matrix pattern cannot hold, through preconditioned conjugate gradients.
 *
 * The Newton matrix H holds, for each pair within d^, the block-diagonal bound
 * m sum_e G_e G_e^T of its positive semidefinite part c2 G G^T (contact_bodies.c). The direction
 * H d = b is refined towards (H - C_bd + C) d = b: C - C_bd applied matrix-free over the pairs
 * recorded at H's assembly, H's factorization (fcm__sim_solve()) as the preconditioner. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <string.h>

/* The direction's refinement: preconditioned CG iterations at most, relative residual. */
#define SIM_REFINE_MAX  200
#define SIM_REFINE_RTOL 1e-10

/* out += (C - C_bd) v over the recorded pairs: C = sum c2 G G^T couples the pieces, C_bd the
 * block-diagonal bound the Newton matrix holds (m sum_e G_e G_e^T); constrained DOFs (mask)
 * neither take nor give. */
static void coupling_apply(const fcm_integrator *I, const sim_bodies *B, const double *v,
                           double *out)
{
  const fcm_space *s = I->space;
  const int nn = s->nn;
  for (size_t k = 0; k < B->npairs; k++) {
    const sim_pair *q = B->pairs + k;
    fcm_index node[6], elem[6];
    double coef[6], Gv[6], tot = 0.0;
    int ne = 0, which[6];
    for (int j = 0; j < 3; j++) {
      node[j] = B->tri[3 * B->stri[q->n] + j];
      coef[j] = B->slam[3 * q->n + j];
      node[3 + j] = B->tri[3 * q->t + j];
      coef[3 + j] = -q->beta[j];
    }
    for (int m = 0; m < 6; m++) {
      const fcm_index e = B->velem[node[m]];
      int w = -1;
      which[m] = -1;
      if (coef[m] == 0.0) continue; /* as pair_terms: its element is not counted */
      for (int j = 0; j < ne; j++)
        if (elem[j] == e) w = j;
      if (w < 0) {
        w = ne;
        elem[ne] = e;
        Gv[ne++] = 0.0;
      }
      which[m] = w;
      const fcm_index *ed = s->elem_dof + e * nn;
      const double *N = B->vN + (size_t)node[m] * nn;
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          if (!I->is_con[ed[a] + i]) Gv[w] += coef[m] * N[a] * q->g[i] * v[ed[a] + i];
    }
    for (int j = 0; j < ne; j++)
      tot += Gv[j];
    for (int m = 0; m < 6; m++) {
      if (which[m] < 0) continue;
      const fcm_index *ed = s->elem_dof + B->velem[node[m]] * nn;
      const double *N = B->vN + (size_t)node[m] * nn;
      const double c = q->c2 * coef[m] * (tot - ne * Gv[which[m]]);
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          if (!I->is_con[ed[a] + i]) out[ed[a] + i] += c * N[a] * q->g[i];
    }
  }
}

static double dotv(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * b[i];
  return s;
}

fcm_status fcm__sim_bodies_refine(fcm_integrator *I, const double *b, double *d,
                                  fcm_step_reason *reason, int *its, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  sim_bodies *B = NULL;
  const fcm_index n = I->n;
  for (int c = 0; c < I->num_contacts; c++)
    if (I->contacts[c].bodies) B = I->contacts[c].bodies;
  if (!B || B->npairs == 0 || I->hP || !I->H) return FCM_OK;
  double *r = B->w1, *z = B->w2, *p = B->w3, *q = B->w4;
  const double bn = sqrt(dotv(n, b, b));
  /* r = b - A d, A = H + C - C_bd */
  FCM_TRY(I->ctx, fcm_csr_apply(I->H, -1.0, d, 0.0, r));
  memset(q, 0, sizeof(double) * (size_t)n);
  coupling_apply(I, B, d, q);
  for (fcm_index i = 0; i < n; i++)
    r[i] += b[i] - q[i];
  FCM_TRY(I->ctx, fcm__sim_solve(I, r, z, reason, its, stats));
  if (*reason != FCM_STEP_NONE) return FCM_OK;
  memcpy(p, z, sizeof(double) * (size_t)n);
  double rz = dotv(n, r, z);
  for (int k = 0; k < SIM_REFINE_MAX && sqrt(dotv(n, r, r)) > SIM_REFINE_RTOL * bn; k++) {
    int its1 = 0;
    FCM_TRY(I->ctx, fcm_csr_apply(I->H, 1.0, p, 0.0, q));
    coupling_apply(I, B, p, q);
    const double pq = dotv(n, p, q);
    if (!(pq > 0.0)) break;
    const double alpha = rz / pq;
    for (fcm_index i = 0; i < n; i++) {
      d[i] += alpha * p[i];
      r[i] -= alpha * q[i];
    }
    FCM_TRY(I->ctx, fcm__sim_solve(I, r, z, reason, &its1, stats));
    *its += its1 + 1;
    if (*reason != FCM_STEP_NONE) return FCM_OK;
    const double rz1 = dotv(n, r, z);
    for (fcm_index i = 0; i < n; i++)
      p[i] = z[i] + rz1 / rz * p[i];
    rz = rz1;
  }
cleanup:
  return st;
}
