/* fcm — distributed assembly and linear solves on PETSc + MPI (optional: built when the
 * CMake option FCM_WITH_PETSC finds PETSc; FCM_HAVE_PETSC in fcm/version.h says whether it
 * was). The serial library stays the default and keeps every feature; this module runs
 * linear elasticity (static, and backward Euler in time) with the work distributed over
 * the processes of an MPI communicator:
 *
 * - the background cells are partitioned (PT-Scotch through PETSc's MatPartitioning, or a
 *   Morton-ordered space-filling-curve split), each process builds the cut-cell rules of its
 *   own cells only (fcm_cell_rules_options.cell_mask) and integrates its own elements into a
 *   preallocated MATMPIAIJ and VECMPI; DOFs are numbered globally, each DOF owned by the
 *   lowest process among the cells that use it (ghosts: the other processes add into its
 *   rows through MatSetValues);
 * - each linear solve is a PETSc KSP configured from the options database: defaults CG with
 *   GAMG and the rigid-body near-null space (the linear driver on a Hex20 box grid: CG with
 *   fcm's geometric multigrid of fcm/mg.h as PCMG; -pc_type mg selects it on Hex8 box grids
 *   and on the integrator path too, and is FCM_ERR_UNSUPPORTED on other meshes),
 *   overridden by the options string of the options
 *   (a scene's solver.petsc_options) and then by the command line (-ksp_type, -pc_type, ...:
 *   the command line wins, the ecosystem's convention). Each problem reads them under its own
 *   options prefix (fcm_petsc_info.options_prefix), so one problem's string never reaches
 *   another problem's solver; the command line reaches every problem ("-fcm2_ksp_type ..."
 *   the second one alone).
 *
 * Phase 1 (stated plainly): the mesh, the geometry and the DOF numbering (O(nodes + elements)
 * integers) are replicated on every process; the sparsity pattern is held per process for its
 * own and ghost cells only; the heavy part — simplification and stabilization of the
 * cut-cell rules, element integration, matrix and vector rows, the solve — is distributed. Every
 * function is collective over the communicator; an error on any process (bad input on one of them
 * included) is returned on every process, with the failing process's message, so that all of them
 * stop together. */
#ifndef FCM_PETSC_H
#define FCM_PETSC_H

#include <mpi.h>

#include "fcm/core.h"
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/geom.h"
#include "fcm/material.h"
#include "fcm/mesh.h"
#include "fcm/motion.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Initialize PETSc (and MPI when not initialized yet) with the program's arguments, which
 * go into the options database (PetscInitialize). Call once before anything else here. When
 * this call initializes PETSc, it also replaces PETSc's error handler, which prints a
 * traceback on stderr at every error, by one that prints nothing (PetscReturnErrorHandler):
 * a failed PETSc call is an fcm error carrying PETSc's message. A program that initialized
 * PETSc itself keeps its own handler.
 * @return FCM_OK, FCM_ERR_INTERNAL (PETSc failed: the message says so; ctx may be NULL). */
FCM_API fcm_status fcm_petsc_initialize(fcm_ctx *ctx, int *argc, char ***argv);

/** Finalize PETSc (and MPI when fcm_petsc_initialize() started it). */
FCM_API void fcm_petsc_finalize(void);

/** How the background cells are distributed over the processes. */
typedef enum fcm_petsc_partition {
  FCM_PETSC_PARTITION_AUTO = 0,     /**< ORDERED: deterministic, so a resumed run on the
                                         same process count is bit-identical (PT-Scotch's
                                         partitions vary between runs on a loaded machine,
                                         and with them the sums' round-off) */
  FCM_PETSC_PARTITION_PTSCOTCH = 1, /**< MatPartitioning (type ptscotch, or the option
                                         -mat_partitioning_type) of the face graph of the
                                         active cells; cut cells weigh 4, uncut cells 1 */
  FCM_PETSC_PARTITION_ORDERED = 2,  /**< active cells sorted along a Morton (Z-order) curve
                                         of their centroids, cut into contiguous parts of
                                         equal weight (as PTSCOTCH) */
  FCM_PETSC_PARTITION_COUNT
} fcm_petsc_partition;

/** Static name of a partition method ("auto", "ptscotch", "ordered"; "invalid"). */
FCM_API const char *fcm_petsc_partition_name(fcm_petsc_partition partition);

/** The settings of the backend's distribution and linear solves, one struct for both drivers:
 * the linear driver's (fcm_petsc_options.solver) and the integrator's backend (a scene's
 * solver section: "petsc_options", "krylov.rtol", "krylov.max_iterations" give them;
 * fcm_petsc_simulation_create() of fcm/scene_petsc.h). Initialize with
 * fcm_petsc_solver_options_default(). */
typedef struct fcm_petsc_solver_options {
  fcm_petsc_partition partition; /**< the cell partition method (default AUTO) */
  const char *petsc_options;     /**< NULL (default) or PETSc options ("-ksp_type minres
                                      -pc_type jacobi"), read at setup by this problem's
                                      solver only (under its options prefix) and under the
                                      command line (which wins for a key both set); copied */
  double rtol;                   /**< KSP relative tolerance in (0, 1) (default 1e-10; the
                                      option -ksp_rtol overrides it) */
  int max_iterations;            /**< KSP iteration limit >= 1 (default 10000) */
} fcm_petsc_solver_options;

/** The defaults listed on each member. */
FCM_API fcm_petsc_solver_options fcm_petsc_solver_options_default(void);

/** Options of fcm_petsc_problem_create(); initialize with fcm_petsc_options_default(). */
typedef struct fcm_petsc_options {
  fcm_integrator_kind kind;        /**< STATIC: K u = f; BACKWARD_EULER (default):
                                        (M/h^2 + K) u1 = M/h^2 (u0 + h v0) + f,
                                        v1 = (u1 - u0)/h, the serial integrator's step for a
                                        linear material */
  double dt;                       /**< time step h > 0 (default 1/60) */
  fcm_petsc_solver_options solver; /**< partition and KSP settings (default
                                        fcm_petsc_solver_options_default()) */
  fcm_cell_rules_options rules;    /**< the cut-cell rules (kinds and cell_mask are set by
                                        the problem; simplify must not be AUTO); default
                                        fcm_cell_rules_options_default() */
  fcm_assembly_options assembly;   /**< rule strengths on full cells (default element
                                        defaults) */
} fcm_petsc_options;

/** The defaults listed on each member. */
FCM_API fcm_petsc_options fcm_petsc_options_default(void);

/** A distributed linear-elastic problem (opaque). */
typedef struct fcm_petsc_problem fcm_petsc_problem;

/** Partition the cells, build the rules of this process's cells, the (replicated) space, the
 * global DOF numbering and the preallocated distributed matrices. Collective.
 * @param[in] comm the processes (duplicated)
 * @param[in] mesh background mesh, the same on every process; borrowed (outlives the problem)
 * @param[in] geom embedded geometry (the same on every process), or NULL for a plain space on
 *                 every cell; only read during the call
 * @param[in] mat  linear material (model FCM_MATERIAL_LINEAR: other models are
 *                 FCM_ERR_UNSUPPORTED), copied
 * @param[in] opts NULL for defaults
 * @return FCM_OK; FCM_ERR_ARG (NULL, bad option or material: named); FCM_ERR_UNSUPPORTED;
 * errors of the rules and the space; FCM_ERR_INTERNAL (PETSc failed: its message). On every
 * process when any failed. */
FCM_API fcm_status fcm_petsc_problem_create(fcm_ctx *ctx, MPI_Comm comm, const fcm_mesh *mesh,
                                            const fcm_geometry *geom, const fcm_material *mat,
                                            const fcm_petsc_options *opts,
                                            fcm_petsc_problem **problem);

/** Destroy (collective); accepts NULL and `*problem == NULL`, sets `*problem = NULL`. */
FCM_API void fcm_petsc_problem_destroy(fcm_petsc_problem **problem);

/** Add a uniform acceleration (gravity): body force rho a. Before setup. Collective.
 * @return FCM_OK, FCM_ERR_ARG (non-finite, after setup). */
FCM_API fcm_status fcm_petsc_problem_add_gravity(fcm_petsc_problem *problem, const double accel[3]);

/** Prescribe `motion` (fcm_motion of fcm/sim.h; `release` is FCM_ERR_UNSUPPORTED) on the DOFs
 * of `num_nodes` mesh nodes (nodes without DOFs are skipped), as
 * fcm_integrator_add_constraint(). Before setup. Collective.
 * @return FCM_OK, FCM_ERR_ARG (node out of range, DOF constrained twice, bad motion). */
FCM_API fcm_status fcm_petsc_problem_add_constraint(fcm_petsc_problem *problem, fcm_index num_nodes,
                                                    const fcm_index *nodes,
                                                    const fcm_motion *motion);

/** Assemble K (and M for BACKWARD_EULER) and the loads over this process's elements, eliminate
 * the constrained DOFs (symmetrically: the system matrix keeps its symmetry) and set up the
 * KSP (the options database is read here). Collective.
 * @return FCM_OK; FCM_ERR_ARG (second call, a static problem without constraints: its rigid
 * modes are free); FCM_ERR_GEOMETRY (det J <= 0 in a cell); FCM_ERR_INTERNAL (PETSc). */
FCM_API fcm_status fcm_petsc_problem_setup(fcm_petsc_problem *problem);

/** What one step did. */
typedef struct fcm_petsc_step_info {
  double time;           /**< time after the step */
  int iterations;        /**< KSP iterations */
  int reason;            /**< KSPConvergedReason (> 0: converged) */
  double residual;       /**< final residual norm the KSP reports */
  double time_rhs;       /**< seconds: right-hand side and constraint values */
  double time_solve;     /**< seconds: KSPSolve (the first includes the preconditioner) */
  double kinetic_energy; /**< 1/2 v^T M v (0 for STATIC) */
  double elastic_energy; /**< 1/2 u^T K u */
  double external_work;  /**< f^T u */
} fcm_petsc_step_info;

/** Advance one step of dt (STATIC: solve the equilibrium again at t + dt, the same for
 * constant loads and constraints). A KSP that does not converge is FCM_ERR_NOT_CONVERGED
 * with the KSPConvergedReason's name, the iterations and the residual; the state is then
 * unchanged. Collective. @param[out] info may be NULL. */
FCM_API fcm_status fcm_petsc_problem_step(fcm_petsc_problem *problem, fcm_petsc_step_info *info);

/** Number of DOFs (the serial space's, fcm_space_num_dofs()). */
FCM_API fcm_index fcm_petsc_problem_num_dofs(const fcm_petsc_problem *problem);

/** The problem's space: the DOF numbering of the serial library (every accessor of
 * fcm/fem.h that reads DOFs and elements works on it), but its sparsity pattern covers only
 * this process's own and ghost cells, so fcm_space_matrix_create() and the fcm_assemble_*()
 * functions refuse it (FCM_ERR_ARG); only this process's cut cells carry quadrature points. */
FCM_API const fcm_space *fcm_petsc_problem_space(const fcm_petsc_problem *problem);

/** The original ids (ascending) of the geometry cells and boundary triangles this process's
 * rules build read (the crop, see fcm_petsc_info.geometry_cells_kept): borrowed arrays valid
 * as long as the problem; counts 0 and NULL arrays when nothing was cropped (one process, no
 * geometry: the whole geometry was read). Local. */
FCM_API fcm_status fcm_petsc_problem_geometry_kept(const fcm_petsc_problem *problem,
                                                   fcm_index *num_cells, const fcm_index **cells,
                                                   fcm_index *num_triangles,
                                                   const fcm_index **triangles);

/** Gather the displacement and velocity (either may be NULL) in the space's DOF numbering
 * (num_dofs each) on every process. Collective. @return FCM_OK, FCM_ERR_INTERNAL. */
FCM_API fcm_status fcm_petsc_problem_get_state(fcm_petsc_problem *problem, double *u, double *v);

/** Write the current state as a parallel VTU: every process writes its piece
 * <dir>/<stem>_<rank>.vtu (its own cells, their nodes at reference positions; point data
 * `displacement` and `velocity` — fcm_space_node_field() of the gathered state —, cell data
 * `process` and `volume_fraction`), process 0 the index <dir>/<stem>.pvtu naming the pieces
 * (ParaView opens it; a PVD may index it). Files are written atomically; the directory must
 * exist. Collective. @return FCM_OK, FCM_ERR_ARG, FCM_ERR_IO (naming the path), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_petsc_problem_write_frame(fcm_petsc_problem *problem, const char *dir,
                                                 const char *stem);

/** Save the run: process 0 writes the gathered displacement and velocity (the space's DOF
 * numbering), the time, the step count and a fingerprint (DOFs, elements, kind, dt) to `path`
 * atomically, in the checkpoint container of the scene runs (fcm_simulation_write_checkpoint():
 * magic, version, byte-order mark, checksum) with no scene as its source;
 * fcm_simulation_read_checkpoint() also reads it into the simulation of the same scene, serial
 * or distributed, and converts it. Collective.
 * @return FCM_OK, FCM_ERR_ARG, FCM_ERR_IO, FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_petsc_problem_write_checkpoint(fcm_petsc_problem *problem, const char *path);

/** Continue a run: every process reads `path` (a shared file system) into a problem set up from
 * the same inputs; any process count reads it. Resumed on the same process count the steps are
 * bit for bit those of the uninterrupted run; on another count they agree to the solver's
 * tolerance (the partition, hence the rounding, differs). Reads the files of
 * fcm_petsc_problem_write_checkpoint() and those of its older format (".fcmpk"). Collective.
 * @return FCM_OK; FCM_ERR_IO (cannot open); FCM_ERR_FORMAT (not a checkpoint, truncated,
 * corrupted: the checksum); FCM_ERR_ARG (before setup, another problem: the fingerprints named;
 * a scene run's checkpoint). */
FCM_API fcm_status fcm_petsc_problem_read_checkpoint(fcm_petsc_problem *problem, const char *path);

/** Steps taken (restored by fcm_petsc_problem_read_checkpoint()). */
FCM_API long long fcm_petsc_problem_step_count(const fcm_petsc_problem *problem);

/** Facts about the distribution and the run so far. */
typedef struct fcm_petsc_info {
  int size, rank;                /**< processes and this one */
  fcm_petsc_partition partition; /**< the method used (never AUTO) */
  fcm_index num_dofs;            /**< global DOFs */
  fcm_index local_dofs;          /**< DOFs (matrix rows) this process owns */
  fcm_index local_elements;      /**< elements this process integrates */
  fcm_index max_local_elements;  /**< the largest count over the processes */
  fcm_index min_local_elements;  /**< the smallest count */
  double mass;                   /**< 1^T M 1 over the x components (the assembled mass,
                                      stabilization included; 0 for STATIC) */
  double time_rules;             /**< seconds (this process): the cut-cell rules */
  double time_assembly;          /**< seconds (this process): element integration + MatAssembly */
  double time_setup;             /**< seconds: the whole create + setup */
  double memory_local;           /**< bytes resident on this process (PetscMemoryGetCurrentUsage) */
  double memory_total;           /**< summed over the processes */
  double matrix_memory;          /**< bytes of the system matrix's stored nonzeros over all
                                      processes (values and column indices, MatGetInfo) */
  /* The embedded geometry (fcm_petsc_problem_create(); 0 without one): with more than one
   * process each reads only the part its rules build needs (the crop: the geometry cells whose
   * boxes meet the clipping boxes of the background cells it classifies, the boundary
   * triangles meeting those of the cells it owns), so the kept counts are this process's; on
   * one process the whole geometry is read (kept = whole). */
  fcm_index geometry_cells;          /**< cells of the whole geometry */
  fcm_index geometry_triangles;      /**< boundary triangles of the whole geometry */
  fcm_index geometry_cells_kept;     /**< geometry cells this process's rules build read */
  fcm_index geometry_triangles_kept; /**< boundary triangles it read */
  double geometry_bytes;             /**< bytes of the whole geometry's arrays */
  double geometry_bytes_kept;        /**< bytes of the part kept (this process) */
  double max_geometry_bytes_kept;    /**< the largest geometry_bytes_kept over the processes */
  long long steps, total_iterations;
  char options_prefix[32]; /**< this problem's PETSc options prefix ("fcm1_", "fcm2_",
                                ...: one per problem, numbered in the order this process
                                made them); "-fcm2_ksp_type gmres" on the command line
                                reaches that problem's solver only */
  char ksp_type[32];       /**< the KSP's type ("cg", "minres", ...; "" before setup) */
  char pc_type[32];        /**< its PC's type ("gamg", "cholesky", ...; "" before setup) */
  char factor_package[32]; /**< the package of an LU / Cholesky PC ("mumps", "petsc",
                                ...), else "" */
} fcm_petsc_info;

/** Fill `info` (collective: the sums and extremes are reduced). */
FCM_API fcm_status fcm_petsc_problem_get_info(fcm_petsc_problem *problem, fcm_petsc_info *info);

/** What the integrator's backend of a simulation of fcm_petsc_simulation_create() has
 * communicated on THIS process so far (over every cut's rebuilt backend). Two channels:
 * - the dense sums (MPI_Reduce to process 0 + MPI_Bcast) of the partial quantities every
 *   process holds in full: scalars (energies, the agreement on finiteness), the internal force
 *   and the elimination's lift, the mass and damping matrices' products (n doubles each),
 *   the loads and M a_rep at setup (the mass matrix stays partial: no matrix is summed);
 * - the Newton matrices: each process adds its own partial matrix (its cells' tangent and
 *   base M/h^2 + D/h) into the distributed MATMPIAIJ with ADD_VALUES;
 *   entries of rows other processes own travel through PETSc's stash (row and column index and
 *   value per entry: matrix_bytes_sent counts 2 sizeof(PetscInt) + sizeof(PetscScalar) each).
 * Times are this process's: wall seconds (waits included) and CPU seconds (clock()). */
typedef struct fcm_petsc_traffic {
  long long reduces;              /**< dense sums */
  long long reduce_values;        /**< doubles this process handed to them */
  long long reduce_bytes;         /**< 8 per value (sent to the reduce; as many come back) */
  long long reduce_large;         /**< sums of more values than the space has DOFs (a
                                       matrix; none since the mass matrix stays partial) */
  long long matrices;             /**< Newton matrices given to the backend (factorizations) */
  long long matrix_values_local;  /**< entries added to rows this process owns */
  long long matrix_values_sent;   /**< entries added to other processes' rows (stash) */
  long long matrix_rows_sent;     /**< rows of those (all-zero rows are not sent) */
  long long matrix_bytes_sent;    /**< stash payload of those entries (see above) */
  double time_reduce, cpu_reduce; /**< seconds in the dense sums */
  double time_matrix, cpu_matrix; /**< seconds adding the matrices (MatSetValues, assembly) */
} fcm_petsc_traffic;

#ifdef __cplusplus
}
#endif
#endif /* FCM_PETSC_H */
