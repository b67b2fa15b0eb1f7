/* sim module: the integrator's side of a solver backend (internal). The interface itself and
 * its contract (partial assemblies summed, partial Newton matrices handed to the backend) are
 * lib/src/fem/fem_backend.h. Every integrator starts with the serial backend (one process:
 * its sums are the values themselves, it owns every DOF, and the integrator's options choose
 * the linear solver); the layer that chooses a distributed backend (the scene's runner)
 * attaches it here before the integrator's setup. */
#ifndef FCM_SIM_BACKEND_H
#define FCM_SIM_BACKEND_H

#include "core/core_impl.h"
#include "fcm/la.h"
#include "fcm/sim.h"
#include "fem/fem_backend.h"

/* Set the distributed backend of an integrator that is not set up yet (before
 * fcm_integrator_setup(): the setup sums the loads and M a_rep; the mass matrix stays
 * partial). The integrator owns b->user from now on (b->destroy at fcm_integrator_destroy()),
 * also when this fails. FCM_ERR_ARG after setup or when a distributed backend is set already.
 * A serial backend (the serial one's setup, for a cut of a serial integrator) leaves the
 * integrator with the serial backend it has. */
fcm_status fcm__integrator_set_backend(fcm_integrator *I, const fcm__backend *b);

/* Attach a backend to an integrator that is not set up yet: from->setup (from borrowed: the
 * chooser's object) prepares it for the integrator's space and gives the integrator its own
 * reference, set as by fcm__integrator_set_backend(). FCM_ERR_ARG (no setup operation, after
 * setup). Collective. */
fcm_status fcm__integrator_attach_backend(fcm_integrator *I, const fcm__backend *from);

/* Sum values[0 .. count) over the processes of the integrator's backend, in place (a partial
 * quantity of the space, e.g. the log's mass and momentum); the serial backend leaves them.
 * Collective. */
fcm_status fcm__integrator_reduce(fcm_integrator *I, double *values, fcm_index count);
/* The same after a local phase that ended with st: the processes agree on it first (a failure
 * anywhere is returned everywhere, values untouched and may then be NULL). Collective; the
 * serial backend returns st. */
fcm_status fcm__integrator_reduce_status(fcm_integrator *I, fcm_status st, double *values,
                                         fcm_index count);

/* The integrator's distributed backend (NULL with the serial one). */
FCM_COMPONENT_API const fcm__backend *fcm__integrator_backend(const fcm_integrator *I);

/* Whether the integrator runs on a distributed backend (0: the serial one); *root (may be
 * NULL): 1 on the backend's root process (the serial backend's one process is the root). */
FCM_COMPONENT_API int fcm__integrator_distributed(const fcm_integrator *I, int *root);

/* The backend's rank and process count (0 and 1 with the serial backend). */
void fcm__integrator_processes(const fcm_integrator *I, int *rank, int *nprocs);

/* The backend's finish (see fcm__backend.finish, fem/fem_backend.h) on st; st when it has
 * none (the serial backend). Collective. */
fcm_status fcm__integrator_finish(fcm_integrator *I, fcm_status st);

/* A cut's integrator (fcm_integrator_create_cut()) in stages, for a caller that runs the two
 * middle ones side by side: fcm__integrator_cut_begin() creates the integrator with old's
 * effects, constraints and backend and the setup's first stage (the constraints' DOFs, the
 * storage taken from old, the Newton matrix's pattern); then, independent of each other,
 * fcm__integrator_cut_values() (the rest of the setup: mass matrix, loads, linear solver;
 * the state transferred) and fcm__integrator_cut_structure() (the linear solver's structure,
 * fcm__sim_prepare_solver_cut(): it reads of the new integrator only what the first stage
 * wrote, the values job none of what it writes); fcm__integrator_cut_end() last, always. Each
 * stage's loops give the bits they give on any thread count; the result is
 * fcm_integrator_create_cut()'s bit for bit. With `beside` set (the stages run as parts of one
 * parallel region, whose barrier comes before fcm__integrator_cut_end()) the structure job
 * may return with a task of its own pending (fcm__mg_create_pattern_cut_beside()), which a
 * thread of the team runs when it is free, and which the end completes. */
typedef struct fcm__integrator_cut {
  const fcm_integrator *old;
  fcm_integrator *integ; /* the new integrator (NULL: not created) */
  fcm_integrator *giver; /* old when it gives its storage (FCM_CUT_REUSE_STORAGE) */
  unsigned char *con;    /* the structure's constrained DOFs (NULL: no structure) */
  double seconds[2];     /* wall seconds: [0] begin, values and end, [1] the structure (its
                            task's too when it runs beside) */
  int beside;            /* the caller's: the structure job may leave a task to the team */
} fcm__integrator_cut;

/* The first stage into *cut (set whatever happens; fcm__integrator_cut_end() must follow). */
FCM_COMPONENT_API fcm_status fcm__integrator_cut_begin(const fcm_integrator *old,
                                                       const fcm_space *space,
                                                       fcm__integrator_cut *cut);
/* The values job, after a successful begin. */
FCM_COMPONENT_API fcm_status fcm__integrator_cut_values(fcm__integrator_cut *cut);
/* The structure job, after a successful begin; beside the values job or before or after it. */
FCM_COMPONENT_API fcm_status fcm__integrator_cut_structure(fcm__integrator_cut *cut);
/* After the structure job run `beside`, past the team's barrier: its pending task completed
 * (fcm__sim_join_solver(): its error, with the solver's prefix) and its time added to
 * seconds[1]; FCM_OK at once when nothing is pending. fcm__integrator_cut_end() does it too
 * when the stages succeeded and it was not done. */
FCM_COMPONENT_API fcm_status fcm__integrator_cut_join(fcm__integrator_cut *cut);
/* Whether the structure job has work (the multigrid solver's hierarchy; else it returns at
 * once), after a successful begin. */
FCM_COMPONENT_API int fcm__integrator_cut_has_structure(const fcm__integrator_cut *cut);
/* The end, st the outcome of the stages run (FCM_OK: every one succeeded): on FCM_OK *integ
 * the new integrator and a giver spent; else everything of the new integrator freed, the
 * storage given back to old (fcm__sim_cut_give_back(): old goes on) and *integ NULL. Returns
 * st. */
FCM_COMPONENT_API fcm_status fcm__integrator_cut_end(fcm__integrator_cut *cut, fcm_status st,
                                                     fcm_integrator **integ);

#endif /* FCM_SIM_BACKEND_H */
