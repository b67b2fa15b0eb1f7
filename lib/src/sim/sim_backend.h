/* sim module: the integrator's distributed backend (internal; the PETSc adapter of
 * lib/src/petsc sets it, no public API). Every process runs the same integrator on the same
 * replicated DOF numbering, but its space's cell rules carry points on the process's own
 * cells only, so every assembly (mass, loads, energy, force, tangent, boundary terms) is the
 * process's partial sum. With a backend set:
 * - the integrator sums the partial scalars and vectors over the processes right after each
 *   assembly (reduce: energies, the internal force, the loads, the mass and damping matrices'
 *   products; n doubles at most), so the Newton loop, line search, stopping rules, reactions
 *   and energies see the global values and every process takes the same decisions;
 * - no matrix is summed: the mass matrix M stays this process's PARTIAL one (its cells'
 *   part, fcm_integrator_mass()); every use sums a product (M (x - u^) in the energy and
 *   gradient, M a_rep, the kinetic energy, momentum and centre of mass as scalars);
 * - the Newton matrix is NOT summed either: each process keeps its PARTIAL matrix (its cells'
 *   tangent and the base M/h^2 + D/h of its partial M and D; D = alpha_M M + beta_K K+ is
 *   partial the same way), eliminates the constrained DOFs
 *   in it (their rows and columns zeroed; the diagonal, from the summed tangent's diagonal,
 *   on the owned rows only; the right-hand side's lift H_fc inc_c summed as an n-vector) and
 *   hands it to the backend (factor), which adds the partial matrices of all processes into
 *   its distributed matrix; the partial matrices sum to the serial run's eliminated matrix
 *   (up to the order of the additions). Nothing in this path needs every process to have the
 *   same matrix pattern: each process's matrix needs only the entries its cells touch and
 *   the diagonal of the DOFs it owns. */
#ifndef FCM_SIM_BACKEND_H
#define FCM_SIM_BACKEND_H

#include "fcm/la.h"
#include "fcm/sim.h"

typedef struct fcm__sim_backend fcm__sim_backend;
struct fcm__sim_backend {
  void *user;
  /* 1 on exactly one process: the replicated terms of a summed quantity that every process
   * would otherwise count (fcm__integrator_distributed(); e.g. the run summary's uncut-cell
   * points) are counted there only */
  int root;
  /* This process's number (0 .. nprocs-1) and the process count: the pieces of a parallel
   * frame (fcm_simulation_write_frame()) are named by them. */
  int rank, nprocs;
  /* n (the space's DOFs): 1 on the DOFs whose rows of the distributed Newton matrix this
   * process owns (every DOF on exactly one process): the terms of the Newton matrix that are
   * no partial sums (the eliminated rows' diagonal, from the summed tangent diagonal) are put
   * on those rows only. Required; fcm__integrator_set_backend() copies it. */
  const unsigned char *owned;
  /* Agree on st over the processes (on a failure anywhere every process returns the status
   * and message of the first failing one), then sum values[0 .. count) over the processes in
   * place (the same result, bit for bit, on every process). Collective. */
  fcm_status (*reduce)(void *user, fcm_status st, double *values, fcm_index count);
  /* Prepare the solves with the eliminated Newton matrix: the sum over the processes of each
   * process's PARTIAL eliminated matrix H (see above; the backend adds them). H has the rows
   * of the integrator's space (fcm__space_num_rows(): a distributed run's local space has the
   * rows of its local copies only, row r being DOF fcm__space_row_dof(space, r)) and a column
   * per DOF. is_con (n, by DOF): the constrained DOFs, whose rows and columns of H are zero
   * except the diagonal on the owning process; psd: the sum is positive definite (CG) or may
   * be indefinite (MINRES).
   * *failed = 1: a soft failure (the step is retried). Collective. */
  fcm_status (*factor)(void *user, const fcm_csr *H, const unsigned char *is_con, int psd,
                       int *failed);
  /* Solve H x = b (b the same on every process; x returned on every process). *failed = 1: no
   * usable solution (soft). Collective. */
  fcm_status (*solve)(void *user, const double *b, double *x, int *iterations, int *failed);
  /* Release `user` (called by fcm_integrator_destroy()); may be NULL. */
  void (*destroy)(void *user);
  /* The backend of the integrator fcm_integrator_create_cut() makes on a cut's new `space`
   * (its DOF numbering differs): agree on st first (the status of the new integrator's
   * creation so far on this process; on a failure anywhere every process returns it), then
   * fill *out (its own reference: out->destroy releases it). Collective. NULL: an integrator
   * with this backend cannot be cut (FCM_ERR_UNSUPPORTED). */
  fcm_status (*cut)(void *user, fcm_status st, const fcm_space *space, fcm__sim_backend *out);
  /* End a phase with local work between collective calls (a cut): agree on st unless an
   * earlier agreement of this backend already reported a failure (then return st without
   * communicating), so a process that failed outside the collective calls meets the others
   * wherever they wait. NULL: st is returned. Collective. */
  fcm_status (*finish)(void *user, fcm_status st);
};

/* Set the backend of an integrator that is not set up yet (before fcm_integrator_setup():
 * the setup sums the loads and M a_rep; the mass matrix stays partial). The integrator owns b->user
 * from now on (b->destroy at fcm_integrator_destroy()), also when this fails. FCM_ERR_ARG after
 * setup. */
fcm_status fcm__integrator_set_backend(fcm_integrator *I, const fcm__sim_backend *b);

/* Sum values[0 .. count) over the processes of the integrator's backend, in place (a partial
 * quantity of the space, e.g. the log's mass and momentum); FCM_OK without a backend.
 * Collective with a backend. */
fcm_status fcm__integrator_reduce(fcm_integrator *I, double *values, fcm_index count);
/* The same after a local phase that ended with st: the processes agree on it first (a failure
 * anywhere is returned everywhere, values untouched and may then be NULL). Collective with a
 * backend; st itself without one. */
fcm_status fcm__integrator_reduce_status(fcm_integrator *I, fcm_status st, double *values,
                                         fcm_index count);

/* The integrator's backend (NULL without one). */
const fcm__sim_backend *fcm__integrator_backend(const fcm_integrator *I);

/* Whether the integrator runs on a distributed backend (0: serial); *root (may be NULL): 1 on
 * the backend's root process, and 1 without a backend. */
int fcm__integrator_distributed(const fcm_integrator *I, int *root);

/* The backend's rank and process count (0 and 1 without a backend). */
void fcm__integrator_processes(const fcm_integrator *I, int *rank, int *nprocs);

/* The backend's finish (see fcm__sim_backend.finish) on st; st without a backend. Collective
 * with a backend. */
fcm_status fcm__integrator_finish(fcm_integrator *I, fcm_status st);

#endif /* FCM_SIM_BACKEND_H */
