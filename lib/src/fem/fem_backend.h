/* fem module: the interface of a solver backend (internal, no public API), in the spirit of
 * SUNDIALS' SUNLinearSolver and PETSc's KSP types: an object with operations the time
 * integrator (lib/src/sim) calls without knowing which backend it is: sum a partial assembly
 * over the processes, prepare the solves with a Newton matrix, solve, follow a new DOF
 * numbering (a cut), release. Two implementations: the serial backend every integrator starts
 * with (lib/src/sim/integrator_backend.c: one process, whose sums are the values themselves,
 * owning every DOF; no factor and solve of its own: the integrator's options choose its serial
 * direct, Krylov or multigrid solver) and the distributed PETSc adapter (lib/src/petsc). It lives
 * here, below petsc and sim, because its operations are those of a linear solver on a space's DOF
 * numbering (a sparse matrix, vectors, a space): an implementation (the PETSc adapter of
 * lib/src/petsc) then includes nothing of the modules above it, and the layer that chooses the
 * backend (the scene's runner) hands it to the integrator.
 *
 * Contract. Every process runs the same integrator on the same replicated DOF numbering, but
 * its space's cell rules carry points on the process's own cells only, so every assembly
 * (mass, loads, energy, force, tangent, boundary terms) is the process's partial sum. With a
 * distributed backend set:
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
 *   the diagonal of the DOFs it owns.
 *
 * Life cycle. The chooser makes the backend object before any space exists (its reduce may
 * already serve sums then, e.g. the cell rules' simplify = "auto" choice) and hands a borrowed
 * fcm__backend with `user`, `reduce` and `setup` to the integrator of the space
 * (fcm__integrator_attach_backend(), lib/src/sim/sim_backend.h); `setup` gives the integrator
 * its own reference, prepared for its space, and a cut's new integrator gets one the same way
 * from the old integrator's. */
#ifndef FCM_FEM_BACKEND_H
#define FCM_FEM_BACKEND_H

#include "fcm/fem.h"
#include "fcm/la.h"

typedef struct fcm__backend fcm__backend;
struct fcm__backend {
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
   * on those rows only. Required once set up; fcm__integrator_set_backend() copies it. */
  const unsigned char *owned;
  /* Agree on st over the processes (on a failure anywhere every process returns the status
   * and message of the first failing one), then sum values[0 .. count) over the processes in
   * place (the same result, bit for bit, on every process). Collective. */
  fcm_status (*reduce)(void *user, fcm_status st, double *values, fcm_index count);
  /* Prepare the solves with the eliminated Newton matrix (factor and solve are NULL in the
   * serial backend only): the sum over the processes of each
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
  /* The backend of an integrator on `space` (the first one, or the integrator
   * fcm_integrator_create_cut() makes on a cut's new space, whose DOF numbering differs): agree
   * on st first (the status of the new integrator's creation so far on this process; on a
   * failure anywhere every process returns it), then prepare the backend for the space's DOF
   * numbering and fill *out (its own reference: out->destroy releases it). Collective. NULL:
   * an integrator with this backend cannot be cut (FCM_ERR_UNSUPPORTED). */
  fcm_status (*setup)(void *user, fcm_status st, const fcm_space *space, fcm__backend *out);
  /* End a phase with local work between collective calls (a cut): agree on st unless an
   * earlier agreement of this backend already reported a failure (then return st without
   * communicating), so a process that failed outside the collective calls meets the others
   * wherever they wait. NULL: st is returned. Collective. */
  fcm_status (*finish)(void *user, fcm_status st);
};

#endif /* FCM_FEM_BACKEND_H */
