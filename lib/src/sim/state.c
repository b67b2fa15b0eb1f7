/* sim: the integrator's state and what is read off it — sizes, setup figures, the state's
 * get and set (rigid velocities included), energies, momenta and constraint reactions. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <string.h>

static int finite3(const double a[3])
{
  return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

fcm_index fcm_integrator_num_dofs(const fcm_integrator *I)
{
  return I ? I->n : 0;
}
double fcm_integrator_time(const fcm_integrator *I)
{
  return I ? I->t : 0.0;
}
long long fcm_integrator_step_count(const fcm_integrator *I)
{
  return I ? I->steps : 0;
}
const double *fcm_integrator_displacement(const fcm_integrator *I)
{
  return I ? I->u : NULL;
}
const double *fcm_integrator_velocity(const fcm_integrator *I)
{
  return I ? I->v : NULL;
}
fcm_index fcm_integrator_num_constrained(const fcm_integrator *I)
{
  return I ? I->ncon : 0;
}
/* With a distributed backend: this process's partial mass matrix (fem/fem_backend.h). */
const fcm_csr *fcm_integrator_mass(const fcm_integrator *I)
{
  return I ? I->M : NULL;
}
void fcm_integrator_get_setup_info(const fcm_integrator *I, fcm_integrator_setup_info *info)
{
  if (!info) return;
  memset(info, 0, sizeof *info);
  if (I) *info = I->setup_info;
}

void fcm_integrator_drop_factorization(fcm_integrator *I)
{
  if (!I) return;
  I->kept = 0;
  I->mg_warm = 0; /* the multigrid's warm start too: the next solve starts cold */
}

void fcm_integrator_get_state(const fcm_integrator *I, double *u, double *v, double *t,
                              long long *steps)
{
  if (!I) return;
  if (u) memcpy(u, I->u, sizeof *u * (size_t)I->n);
  if (v) memcpy(v, I->v, sizeof *v * (size_t)I->n);
  if (t) *t = I->t;
  if (steps) *steps = I->steps;
}

fcm_status fcm_integrator_set_state(fcm_integrator *I, const double *u, const double *v, double t,
                                    long long steps)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(isfinite(t) && steps >= 0, I->ctx, FCM_ERR_ARG,
            "integrator: state time %g must be finite and steps %lld >= 0", t, steps);
  for (fcm_index i = 0; i < I->n; i++) {
    FCM_CHECK(!u || isfinite(u[i]), I->ctx, FCM_ERR_ARG, "integrator: u[%lld] = %g is not finite",
              (long long)i, u[i]);
    FCM_CHECK(!v || isfinite(v[i]), I->ctx, FCM_ERR_ARG, "integrator: v[%lld] = %g is not finite",
              (long long)i, v[i]);
  }
  if (u) memcpy(I->u, u, sizeof *u * (size_t)I->n);
  if (v) memcpy(I->v, v, sizeof *v * (size_t)I->n);
  I->t = t;
  I->steps = steps;
  I->a_valid = 0;
  I->reaction_valid = 0;
  if (!I->linear) I->h_state = SIM_H_INVALID; /* a linear system does not depend on u */
  I->kept = 0;
  I->mg_warm = 0;
  if (I->is_setup) {
    if (steps > 0 && I->opts.kind == FCM_INTEGRATOR_STATIC)
      fcm__sim_eval_loads(I, t, I->load_prev);
    else
      memset(I->load_prev, 0, sizeof *I->load_prev * (size_t)I->n);
    fcm__sim_eval_constraints(I, t);
  }
cleanup:
  return st;
}

fcm_status fcm_integrator_set_rigid_velocity(fcm_integrator *I, const double v0[3],
                                             const double omega[3], const double c[3])
{
  fcm_status st = FCM_OK;
  static const double zero[3] = {0, 0, 0};
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  if (!v0) v0 = zero;
  if (!omega) omega = zero;
  if (!c) c = zero;
  FCM_CHECK(finite3(v0) && finite3(omega) && finite3(c), I->ctx, FCM_ERR_ARG,
            "integrator: rigid velocity v0 = (%g, %g, %g), omega = (%g, %g, %g) or centre not "
            "finite",
            v0[0], v0[1], v0[2], omega[0], omega[1], omega[2]);
  {
    const fcm_mesh *mesh = fcm_space_mesh(I->space);
    const double *X = fcm_mesh_coords(mesh);
    fcm_index nn = fcm_mesh_num_nodes(mesh);
    for (fcm_index a = 0; a < nn; a++) {
      const fcm_index d0 = fcm_space_node_dof(I->space, a);
      const fcm_index ncp = fcm_space_node_copies(I->space, a);
      for (fcm_index d = d0; d0 >= 0 && d < d0 + 3 * ncp; d += 3) { /* every copy */
        double r[3];
        for (int i = 0; i < 3; i++)
          r[i] = X[3 * a + i] + I->u[d + i] - c[i];
        I->v[d + 0] = v0[0] + omega[1] * r[2] - omega[2] * r[1];
        I->v[d + 1] = v0[1] + omega[2] * r[0] - omega[0] * r[2];
        I->v[d + 2] = v0[2] + omega[0] * r[1] - omega[1] * r[0];
      }
    }
  }
  I->a_valid = 0; /* the initial acceleration depends on v through the damping */
cleanup:
  return st;
}

fcm_status fcm_integrator_energy(fcm_integrator *I, double *kinetic, double *elastic,
                                 double *external_work)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(I->is_setup, I->ctx, FCM_ERR_ARG, "integrator: energy needs fcm_integrator_setup()");
  {
    fcm_index n = I->n;
    double psi = 0.0, ekin = 0.0, wext = 0.0;
    const int dyn = I->opts.kind == FCM_INTEGRATOR_BACKWARD_EULER;
    st = fcm_assembly_workspace_hyperelastic(I->aws, &I->params, I->u, &psi, NULL, NULL);
    if (st == FCM_OK && dyn) {
      st = fcm__space_matrix_apply(I->space, I->M, I->v, I->w1);
      for (fcm_index i = 0; st == FCM_OK && i < n; i++)
        ekin += 0.5 * I->v[i] * I->w1[i];
    }
    { /* with a backend psi and v^T M v are this process's parts (M is partial): summed */
      double parts[2] = {psi, ekin};
      FCM_TRY(I->ctx, fcm__sim_reduce(I, st, parts, 2, NULL));
      psi = parts[0];
      ekin = parts[1];
    }
    if (dyn) {
      fcm__sim_eval_loads(I, I->t, I->w2);
    } else {
      memcpy(I->w2, I->load_prev, sizeof *I->w2 * (size_t)n);
    }
    for (fcm_index i = 0; i < n; i++)
      wext += I->w2[i] * I->u[i];
    FCM_CHECK(isfinite(ekin) && isfinite(psi) && isfinite(wext), I->ctx, FCM_ERR_NUMERIC,
              "integrator: energy is not finite (kinetic %g, elastic %g, external work %g)", ekin,
              psi, wext);
    if (kinetic) *kinetic = ekin;
    if (elastic) *elastic = psi;
    if (external_work) *external_work = wext;
  }
cleanup:
  return st;
}

fcm_status fcm_integrator_momentum(fcm_integrator *I, double linear[3], double angular[3])
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(I->is_setup, I->ctx, FCM_ERR_ARG, "integrator: momentum needs fcm_integrator_setup()");
  if (!I->M) { /* static: no inertia, no momentum */
    if (linear) memset(linear, 0, 3 * sizeof *linear);
    if (angular) memset(angular, 0, 3 * sizeof *angular);
    goto cleanup;
  }
  st = fcm__space_matrix_apply(I->space, I->M, I->v, I->w1);
  {
    const fcm_mesh *mesh = fcm_space_mesh(I->space);
    const double *X = fcm_mesh_coords(mesh);
    fcm_index nn = st == FCM_OK ? fcm_mesh_num_nodes(mesh) : 0;
    double pl[6] = {0, 0, 0, 0, 0, 0}, *p = pl, *L = pl + 3;
    for (fcm_index a = 0; a < nn; a++) {
      const fcm_index d0 = fcm_space_node_dof(I->space, a);
      const fcm_index ncp = fcm_space_node_copies(I->space, a);
      for (fcm_index d = d0; d0 >= 0 && d < d0 + 3 * ncp; d += 3) { /* every copy */
        const double *q = I->w1 + d;
        double x[3];
        for (int i = 0; i < 3; i++)
          x[i] = X[3 * a + i] + I->u[d + i], p[i] += q[i];
        L[0] += x[1] * q[2] - x[2] * q[1];
        L[1] += x[2] * q[0] - x[0] * q[2];
        L[2] += x[0] * q[1] - x[1] * q[0];
      }
    }
    /* with a backend M is this process's partial mass matrix: p and L (linear in M v) are
     * its parts, summed (6 doubles) */
    FCM_TRY(I->ctx, fcm__sim_reduce(I, st, pl, 6, NULL));
    if (linear) memcpy(linear, p, 3 * sizeof *p);
    if (angular) memcpy(angular, L, 3 * sizeof *L);
  }
cleanup:
  return st;
}

void fcm__sim_store_reactions(fcm_integrator *I)
{
  const double *X = fcm_mesh_coords(fcm_space_mesh(I->space));
  memset(I->reaction, 0, 6 * sizeof *I->reaction * (size_t)I->num_cons);
  for (fcm_index j = 0; j < I->ncon; j++) {
    const int k = I->con_id[j], i = I->con_comp[j];
    if (!I->con_on[k]) continue; /* released: it holds nothing */
    const fcm_index d = I->con_dof[j], base = d - i;
    double *r = I->reaction + 6 * k, f[3] = {0, 0, 0}, x[3];
    f[i] = I->g[d];
    for (int c = 0; c < 3; c++)
      x[c] = X[3 * I->con_node[j] + c] + I->u[base + c];
    r[i] += f[i];
    r[3] += x[1] * f[2] - x[2] * f[1];
    r[4] += x[2] * f[0] - x[0] * f[2];
    r[5] += x[0] * f[1] - x[1] * f[0];
  }
  I->reaction_valid = 1;
}

fcm_status fcm_integrator_reaction(const fcm_integrator *I, int id, double force[3],
                                   double moment[3])
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(id >= 0 && id < I->num_cons, I->ctx, FCM_ERR_ARG,
            "integrator: reaction: constraint %d out of range [0, %d)", id, I->num_cons);
  FCM_CHECK(I->is_setup && I->reaction_valid, I->ctx, FCM_ERR_ARG,
            "integrator: reaction: no step accepted since the setup or the last set_state (the "
            "reaction is that of the last accepted step)");
  if (force) memcpy(force, I->reaction + 6 * id, 3 * sizeof *force);
  if (moment) memcpy(moment, I->reaction + 6 * id + 3, 3 * sizeof *moment);
cleanup:
  return st;
}

int fcm_integrator_num_constraints(const fcm_integrator *I)
{
  return I ? I->num_cons : 0;
}
