/* fcm — scenes on the PETSc + MPI backend (built when the library has it: FCM_HAVE_PETSC in
 * fcm/version.h). The scene runner's calls that build a distributed run from a scene
 * (fcm/scene.h): the PETSc linear driver's problem (fcm/petsc.h) and a scene's ordinary
 * simulation (fcm/simulation.h) whose integrator sums and solves through the PETSc backend. They
 * belong to the scene module (lib/src/scene/run_petsc.c), above the adapter of fcm/petsc.h. */
#ifndef FCM_SCENE_PETSC_H
#define FCM_SCENE_PETSC_H

#include <stdio.h>

#include "fcm/petsc.h"
#include "fcm/scene.h"
#include "fcm/simulation.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A problem from a scene (fcm/scene.h), set up and ready to step: the background mesh and the
 * geometry built as fcm_simulation_create() builds them (on every process), the rules and
 * assembly options, time kind and step, gravity and the fixed and motion effects on node
 * regions, solver.rtol / max_iterations and solver.petsc_options. Whatever the backend cannot
 * run yet — a non-linear material, quadrature.simplify = auto, effects other than gravity,
 * fixed and motion on node regions (boundary constraints, tractions, pressure, damping,
 * initial velocities, cuts), a motion with release — is FCM_ERR_UNSUPPORTED naming it, never
 * run differently. Collective. @return as fcm_petsc_problem_create() and _setup(). */
FCM_API fcm_status fcm_petsc_problem_create_from_scene(fcm_ctx *ctx, MPI_Comm comm,
                                                       const fcm_scene *scene,
                                                       fcm_petsc_partition partition,
                                                       fcm_petsc_problem **problem);

/** 1 when fcm_petsc_problem_create_from_scene() runs `scene` (linear material, the effects it
 * lists), 0 otherwise (then fcm_petsc_simulation_create() is the way; also 0 for NULL).
 * Local, no error recorded in ctx. */
FCM_API int fcm_petsc_problem_supports_scene(fcm_ctx *ctx, const fcm_scene *scene);

/** A scene's ordinary simulation (fcm/simulation.h) on the processes of comm, for every
 * material and effect the serial runner has, cuts included (phase 2: Newton on PETSc). Every
 * process runs the scene's fcm_integrator — Newton, line search, time stepping, constraints
 * on nodes and on the embedded boundary (Nitsche / penalty), gravity, tractions, pressure,
 * damping, initial velocities — on the same DOF numbering, but the cut-cell rules carry points
 * on the process's own cells only (the cells are partitioned as fcm_petsc_problem_create()
 * partitions them), so each assembly is a partial sum; the integrator sums them over the
 * processes after every assembly (so every process takes the same decisions and holds the
 * same state), and each Newton system goes to a PETSc KSP on a MATMPIAIJ of the owned rows
 * (defaults: CG, or MINRES when the tangent may be indefinite, with GAMG and the rigid-body
 * near-null space; solver.rtol / max_iterations; solver.petsc_options, then the command line,
 * override them). A KSP that does not converge is the integrator's linear-solver failure
 * (the step is retried as in the serial runner).
 *
 * The simulation is used as any other: fcm_simulation_step() is collective; the state, the
 * log rows (energies, mass, momentum, reactions) and the counters are the same on every
 * process, so one process (rank 0) writes the log and the checkpoints with the serial
 * writers (fcm_simulation_write_checkpoint(); every process of any count, and the serial
 * runner, resumes from it with fcm_simulation_read_checkpoint()); fcm_simulation_write_frame()
 * is collective (each process writes the piece of its own cells, rank 0 the .pvtu), and
 * fcm_petsc_simulation_summary_view() is the summary over every process's cells. A resumed run
 * on the same process count repeats the uninterrupted one bit for bit when the KSP does (CG /
 * MINRES with GAMG, Jacobi, ...: the initial guess is always zero and GAMG builds a new
 * hierarchy per tangent); MUMPS on more than one process is not bitwise reproducible between
 * runs (its parallel factorization), on one process it is.
 * Cuts: every process splits every cell the cut reaches (the same pieces and DOF copies
 * everywhere, checked: FCM_ERR_INTERNAL on every process if the topologies differ), builds its
 * own cells' points, and the new integrator gets the backend again, rebuilt for the new DOF
 * count. quadrature.simplify = auto: the choice's inputs are summed over the processes, so it
 * is the serial run's. Memory, stated plainly: each process holds the space's topology and the
 * mass, Newton and damping matrices of its own cells and one layer of ghost cells only (they
 * shrink as processes are added), but the DOF numbering, the state and about twenty work
 * vectors are replicated: about 0.2 kB per DOF of the whole body on every process, which
 * bounds the body at a few times 1e7 DOFs on nodes of 18 GB, whatever the process count
 * (the linear driver, fcm_petsc_problem_create(), replicates about 0.05 kB/DOF). The sums are of
 * DOF vectors and scalars (no matrix is summed: each process adds its partial Newton matrix into
 * the MATMPIAIJ), the direction is gathered on every process; the rules, the element integration,
 * the matrices and the solve are what is distributed. Collective.
 * @param[in] partition the cell partition method (AUTO: Morton-ordered)
 * @param[in] opts      simulation options (NULL: defaults)
 * A scene without an embedded geometry (plain FEM on the background mesh) runs too: its space
 * integrates this process's cells only.
 * @return FCM_OK; the errors of fcm_simulation_create(); FCM_ERR_INTERNAL
 * (PETSc or MPI failed: its message). On every process when any failed. */
FCM_API fcm_status fcm_petsc_simulation_create(fcm_ctx *ctx, MPI_Comm comm, const fcm_scene *scene,
                                               fcm_petsc_partition partition,
                                               const fcm_simulation_options *opts,
                                               fcm_simulation **out);

/** fcm_simulation_summary_view() of a simulation of fcm_petsc_simulation_create(), over the
 * whole body: the cut-cell point counts (before / after simplification, stored, surface) are
 * summed over the processes and the largest |u| over the body's quadrature points is taken
 * over every process's cells (each process's rules carry its own cells' points only, so the
 * plain summary on one process counts that process's cells). Collective; prints to f on the
 * processes where f is not NULL (typically rank 0 only).
 * @return FCM_OK; FCM_ERR_ARG (NULL simulation, or not a distributed one); FCM_ERR_ALLOC;
 * FCM_ERR_INTERNAL (MPI). On every process when any failed. */
FCM_API fcm_status fcm_petsc_simulation_summary_view(fcm_simulation *sim, FILE *f);

/** This process's communication counters of the integrator's backend (fcm_petsc_traffic).
 * Local. @return FCM_OK; FCM_ERR_ARG (NULL argument, or not a simulation of
 * fcm_petsc_simulation_create()). */
FCM_API fcm_status fcm_petsc_simulation_traffic(const fcm_simulation *sim, fcm_petsc_traffic *out);

#ifdef __cplusplus
}
#endif
#endif /* FCM_SCENE_PETSC_H */
