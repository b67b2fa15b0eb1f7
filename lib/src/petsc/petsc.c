/* petsc: the PETSc + MPI adapter (fcm/petsc.h) — distributed linear elasticity, static and
 * backward Euler, on a partition of the background cells (phase 1), and the integrator's
 * backend for every other scene (phase 2, fcm_petsc_simulation_create()). The only file that
 * sees PETSc.
 *
 * NOTES (issue 14, for the next session) ---------------------------------------------------
 * Done (phase 1):
 * - build: FCM_WITH_PETSC (AUTO/ON/OFF) in CMakeLists.txt, FCM_HAVE_PETSC in fcm/version.h,
 *   fcm.pc (variable petsc, Requires mpi-c) and fcmConfig.cmake (FCM_HAVE_PETSC, MPI::MPI_C);
 *   setup.sh deps --petsc; .ci/run runs the mpi-labelled tests.
 * - partition: PT-Scotch through MatPartitioning on the face graph of the active cells (Debian's
 *   PETSc 3.18 has it), or Morton-ordered (FCM_PETSC_PARTITION_ORDERED, the default since
 *   PT-Scotch's partitions were seen to vary between runs on 2 processes under load, which
 *   broke the bit-identical resume: petsc_checkpoint_np2 failed 2 in 12 runs). Weights: cut
 *   cells 4, uncut 1 (a guess: measure the per-cell rule + assembly cost and weight by it next).
 * - rules: each process builds the rules of its own cells (fcm_cell_rules_options.cell_mask);
 *   the partition comes first, on the candidate cells (box meets a geometry cell's box; weight
 *   4 where it meets a boundary triangle's box too), so one rules build per process.
 * - classification (issue 14 item 2, first half): distributed too. Each cell is intersected by
 *   ONE process (partition_cells(): its owner; the non-candidates, which the rules drop, round
 *   robin), inside the same rules build that maps its own cells' points
 *   (fcm__cell_rules_create_distributed(), embed_impl.h: the cells of P->remote are skipped);
 *   after the per-cell loop the build calls rules_exchange() once: fcm__petsc_agree(), then
 *   MPI_Allgatherv of (class, volume fraction, embedded volume) as 3 doubles per classified
 *   cell in cell order (no ids: P->classifier is replicated), and the counters (candidates,
 *   tets, slivers, ...) summed in process order, so the statistics are the serial ones. The
 *   remote cells get what the unflagged cells of a cell_mask got before (one piece unless
 *   dropped, no points), so classes, fractions, pieces, DOF numbering and the own cells' rules
 *   are the serial build's bit for bit (tests/petsc/classify.c, 1 and 2 processes, four
 *   elements, both partitions, phases 1 and 2). Phase 2 hands the exchange through
 *   fcm__simulation_create_distributed() (run.c build_rules()). A process failing before its
 *   exchange still calls it (fcm__cell_rules_create_distributed() does, on every error path),
 *   and a phase-2 process that fails before the rules build meets it with its final
 * fcm__petsc_agree().
 * - DOFs: global numbering, owner = lowest process among the cells using the DOF copy, the
 *   PETSc index is contiguous per owner; the numbering (fem_impl.h: node_dof, node_ncopy,
 *   elem_*, cell_elem) and the perm / copy_owner (space DOF -> PETSc index, owner) are
 *   REPLICATED: O(nodes + elements nn), measured 22 B/DOF (Hex20) / 39 B/DOF (Hex8, most of a
 *   24^3 grid outside the ball) plus 4-7 B/DOF of the adapter's arrays (petsc_bench).
 * - topology (phase 1): a local space (fcm__space_create_local(), fem_impl.h), the serial
 *   numbering bit for bit with the copy graph, pattern, offsets and colours of the own cells
 *   and their ghosts only (localize_space(): cells with an element using an owned copy; the
 *   comment there proves every owned row complete; tests/petsc/ghost.c). Measured
 *   (petsc_bench, fcm__space_memory()): full space 435 (Hex8) / 827 (Hex20) B/DOF on every
 *   process before; local 224-252 / 424-523 B/DOF per process on 2 processes. create_matrix()
 *   preallocates from the owned local rows (exact: nz_allocated = nz_used, ghost.c).
 * - assembly: own elements only (fcm__assembly_element_linear), MatSetValues ADD_VALUES into a
 *   preallocated MATMPIAIJ (block size 3), VECMPI loads; stiffness, mass, gravity.
 * - constraints: node sets with fcm_motion (no release), symmetric elimination with
 *   MatZeroRowsColumns on a copy of the system matrix (diag = mean diagonal), RHS lifted with the
 *   unmodified matrix every step.
 * - solver: KSP CG + GAMG + MatNullSpaceCreateRigidBody by default (on Hex20 box grids CG + fcm's
 *   multigrid as PCMG, below); options string (scene
 *   solver.petsc_options) then command line; divergence -> FCM_ERR_NOT_CONVERGED with
 *   KSPConvergedReasons[].
 * - errors: every local phase ends in fcm__petsc_agree(): an error on any process is returned on
 * all with the lowest failing process's message (tests/petsc: bad input on one rank, no hang).
 * - output: fcm_petsc_problem_write_frame(): a .pvtu (process 0) naming one piece per process
 *   (its own cells); the node fields come from a VecScatter of the piece's node values (the
 *   DOF copy fcm_space_node_field() shows at each node of an own cell, made at the first
 *   frame: frame_nodes(), frame_scatter()), byte for byte the file written from the gathered
 *   state (ghost.c). Energies are MatMult / VecDot on the distributed vectors (no gather).
 *   Still O(n) per process: fcm_petsc_problem_get_state() (every process: the user asks for
 *   the whole state) and the checkpoint (gathered on process 0 only; read whole by every
 *   process). The integrator
 *   path's background frames are the same (fcm__space_write_vtu_piece() / fcm__write_pvtu(),
 *   fields.c, from fcm_simulation_write_frame()); its surface frames stay serial (process 0).
 * - scenes: fcm_petsc_problem_create_from_scene() (mesh + geometry through
 *   fcm__scene_mesh_geometry() of lib/src/scene/run.c) and fcm-sim --backend petsc
 *   (apps/fcm-sim-petsc.c); the example scene vibrating_beam.json is the dynamic one.
 * Done (phase 2, the integrator on PETSc):
 * - fcm_petsc_simulation_create(): the scene's own fcm_simulation on every process with the
 *   rules masked to the process's cells (the partition as above) and an internal backend set
 *   in the integrator (lib/src/solve/solve_backend.h: reduce / factor / solve / destroy, set by
 *   fcm__integrator_set_backend() from the attach callback of
 *   fcm__simulation_create_distributed(), lib/src/scene/run.c). This problem object P is the
 *   backend (borrowed space, refcount: creator + integrator).
 * - masked rules now also give OTHER processes' UNCUT cells no points in the assembly and in
 *   fcm_space_momentum() (fcm__cell_rules_owns(), embed_impl.h; lib/src/fem/assemble.c): before,
 *   only cut cells were masked (the linear driver never noticed: it loops over own elements).
 * - the integrator sums after each assembly (dense, newton_reduce()): the loads (so fext is
 *   global), energy + force in evaluate(), the mass and damping matrices' products
 *   M (x - u^) and D (x - u_n) there, the representative force M a_rep,
 *   fcm_integrator_energy(), the boundary reactions, the boundary point counts (nitsche.c),
 *   and the log's mass and momentum (run.c); n doubles per sum at most, setup included. The
 *   mass matrix is NOT summed (since session 7, task i14-local2; before: nnz doubles once at
 *   setup): each process keeps its cells' part, and every other use of M sums a product as
 *   scalars (kinetic energy, fcm_integrator_momentum(), the centre of mass of run.c, collective
 *   now: the distributed summary computes it on every process). tests/petsc/newton.c asserts
 *   no sum longer than n in the whole run (fcm_petsc_traffic.reduce_large = 0). A
 *   non-finite value on any process counts as one everywhere; every reduce starts with
 *   fcm__petsc_agree(), so a process that fails outside a reduce ends with one
 *   fcm__petsc_agree() and meets the others wherever they wait (no hang).
 * - sums: MPI_Reduce to process 0 + MPI_Bcast (the same bits everywhere for any count).
 * - the Newton matrix is NOT summed densely (since session 7, task i14-sparse): each process
 *   keeps its PARTIAL matrix (its cells' tangent and boundary terms; the base M/h^2 + D/h of
 *   its partial mass and damping matrices), eliminates the active constraints in it
 *   (newton.c eliminate_partial(): rows and columns zeroed; the lift H_fc inc_c and the
 *   constrained diagonal summed as vectors, n doubles with a predictor, nact without; the
 *   diagonal, the summed one or 1 as fcm__eliminate_marked() takes it, on the owner's row;
 *   the linear reuse path sums H0 inc as an n-vector), and newton_factor() adds it into the
 *   MATMPIAIJ (MatZeroEntries, then MatSetValues ADD_VALUES per CSR row, all-zero rows
 *   skipped, off-process rows through PETSc's stash, MatAssembly). Nothing there needs the
 *   same pattern on every process (each process's matrix needs the entries its cells touch and
 *   the diagonal of its owned DOFs). Determinism: the owner's value comes first, then the
 *   stash's in the order its messages are processed (MatStashScatterGetMesg_BTS: MPI_Waitsome,
 *   arrival order); on 2 processes an entry has at most one sender (same bits every run, the
 *   resume tests hold), on 3+ an entry touched by two other processes may be summed in
 *   another order between runs (round-off). Measured on 3 processes (oversubscribed,
 *   petsc_newton clamped_surface 3 steps, -ksp_type cg -pc_type gamg, 4 runs each): the
 *   final |u| differed between runs in the last 2 digits both with this change and with the
 *   old dense sums (then the matrix was the same bits every run: the KSP / GAMG on 3
 *   processes varies by itself), so bitwise repetition on 3+ processes was not there before
 *   either; on 2 processes 4 of 4 runs were the same bits. Traffic
 *   counters: fcm_petsc_simulation_traffic() (also a "comm" line of the summary);
 *   tests/petsc/newton.c asserts that no sum in the steps is longer than n and that fewer
 *   values than nnz are summed per Newton matrix. Measured (clamped_surface at 16^3 cells,
 *   6597 DOFs, 2 processes, --steps 3 minus --steps 1 = 4 Newton matrices): dense sums per
 *   Newton matrix and process 7.2 MB before, 0.16 MB after (3 n-vectors), plus 0.67 MB stash
 *   from process 1 (process 0 sends none: it owns the shared DOFs); CPU in the sums ~0.036 s
 *   per matrix both ways (waiting in the agreement dominates at this size).
 * - solve: KSP: MUMPS Cholesky/LU when the scene says "direct", else CG/MINRES + GAMG (psd
 *   flag of the integrator); -ksp_type / -pc_type keep the user's choice. KSP divergence
 *   is a soft failure (the integrator halves the step). Direction gathered with a cached
 *   VecScatterCreateToAll.
 * - fcm-sim --backend petsc routes scenes fcm_petsc_problem_supports_scene() rejects to it
 *   (apps/fcm-sim-petsc.c run_newton(); process 0 writes the serial frames, log and
 *   checkpoints).
 * - checkpoints on the phase-2 path: fcm-sim run_newton(): process 0 writes the serial .fcmck,
 *   every process reads it; frames with every process's cell fields
 *   (fcm_simulation_write_frame() collective in a distributed run); the summary over every
 *   process's cells (fcm_petsc_simulation_summary_view()). Bit-identical resume on the same
 *   count needed a zero initial guess in newton_solve() and PCGAMGSetReuseInterpolation(FALSE):
 *   3.18's GAMG reused the previous tangent's interpolation, so a resumed run (fresh KSP)
 *   differed at ~1e-16 on 1 and 2 processes. Tests: petsc_app_newton_resume,
 *   petsc_app_scene_*, petsc_app_summary_*.
 * - cuts: fcm_cell_rules_create_cut() of masked rules keeps the mask (the
 *   same cells get points); every cell, masked or not, is classified, split into pieces and
 *   gets its cut faces (cell_rules.c computes the cut faces before the mask check: the space's
 *   DOF copies depend on them, a cut along cell faces separates cells without splitting any).
 *   fcm_integrator_create_cut() asks the old integrator's backend for a new one
 *   (fcm__backend.cut = newton_setup(): agree, newton_unbuild(), newton_build() for the new
 *   space — numbering, ownership, MATMPIAIJ, vectors, KSP, the scatter made at the first
 *   solve — and one more reference to the same P), before the new integrator's setup (its
 *   mass and load sums). newton_build() checks the replicated topology (DOF and element
 *   counts, a hash of the elements' cells, pieces and DOFs: min = max over the processes,
 *   else FCM_ERR_INTERNAL on every process). The old integrator keeps its reference until
 *   fcm__sim_apply_cut() destroys it; its factor / solve would refuse the rebuilt objects
 *   (size check, P->factored). fcm__sim_apply_cut() ends with fcm__integrator_finish()
 *   (newton_finish(): agree unless a failure was agreed already), so a process that fails in
 *   the local part of a cut meets the others in the hook's agree (tests/petsc/newton_failure.c
 *   case 4). The "cut missed" counters, pieces, DOFs and the rules' classification equal the
 *   serial run's (tests/petsc/newton_setup.c).
 * - quadrature.simplify = "auto": the choice's inputs (per kind: cut-cell points, the modelled
 *   simplification time, points kept; from this process's own cut cells with a mask) are summed
 *   over the processes inside the rules build (fcm__cell_rules_create_reduced(), embed_impl.h:
 *   a reduce callback, here newton_reduce() passed through fcm__simulation_create_distributed()
 *   before the integrator exists; called exactly once per process, also on a failure before
 *   the choice), so every process takes the serial run's choice. The modelled time is summed
 *   in another order than the serial run's (round-off only: a choice exactly at the threshold
 *   could differ). A cut inherits the choice of the rules it extends (no sum needed).
 * - options prefix per problem ("fcm<k>_", k counting the problems
 *   this process made; fcm_petsc_info.options_prefix): insert_options() puts the problem's
 *   string and then a copy of the database's other options (PetscOptionsGetAll: command line,
 *   files, values the program set; not those of other problems' prefixes) under it
 *   (PetscOptionsPrefixPush), then restores the options that name this prefix; the KSP
 *   carries the prefix (both drivers). The prefixed entries stay in
 *   the database after the problem (harmless: no later problem has that prefix; PETSc's
 *   -options_left would list the unused ones). tests/petsc/options.c.
 * - resuming a run with cuts: fcm_simulation_read_checkpoint() (scene/checkpoint.c) reads the
 *   file, then the processes agree on the read and on the number of cuts
 *   (fcm__integrator_reduce_status()) before the cut replay, which is collective; before
 *   (session 6) a file one process could not read left the others waiting in the replay's
 *   newton_setup() (tests/petsc/newton_failure.c case 5).
 * Done (fcm's geometric multigrid as PCMG, pcmg.c):
 * - fcm__petsc_pcmg_setup(): the hierarchy of lib/src/mg (fcm__mg_transfers_create(), the code
 *   fcm_mg_create() runs, without a matrix; the transfers do not depend on the constrained DOFs)
 *   built on every process from the space (replicated numbering; a local space answers the element
 *   queries for every element, so the hierarchy is the same everywhere); one MATMPIAIJ prolongation
 *   per level (bs 3; level 0 rows in P->perm numbering; a coarse copy owned by the owner of the
 *   lowest global finer copy it interpolates to, numbered contiguously per owner; coarse copies no
 *   finer copy interpolates to left out), PCMGSetGalerkin(BOTH), levels Chebyshev (2 steps, PETSc's
 *   eigenvalue estimate) on a PCSHELL applying fcm_schwarz with fcm_mg's block lists (each block
 *   whole on the owner of its lowest DOF: subdomain = owned rows + the blocks' other rows,
 *   MatCreateSubMatrices at each setup, scatter in / add back, i.e. ASM basic), coarsest level
 *   redundant Cholesky (at most min(2000, n/8) DOFs). Options override all of it
 *   (-mg_levels_pc_type replaces the shell; -pc_mg_levels caps the levels, an error if the
 *   hierarchy cannot give them).
 * - phase 1: -pc_type mg, and the default when no -pc_type is given on Hex20 meshes whose
 *   hierarchy builds (box grids; GAMG otherwise, silently). Measured (petsc_bench hex20 12,
 *   rtol 1e-8): 53 iterations on 1 and on 2 processes against GAMG's 691 / 673, solve CPU 149 /
 *   354 us/DOF summed against 658 / 701; pointwise smoothing (-mg_levels_pc_type pbjacobi) 188
 *   iterations; blocks cut at process boundaries (before the subdomains) 80 on 2 processes.
 *   Hex8 (hex8 24): 15 against 24-25 at the same CPU, so GAMG stays the Hex8 default.
 * - phase 2: -pc_type mg in the options: newton_factor() sets the levels once per KSP (PCMG's
 *   level count < 2 means not yet; a cut makes a new KSP); not a default there (GAMG), and not
 *   fit for MINRES on an indefinite tangent (Chebyshev needs SPD).
 * - failures (session 8): fcm__petsc_pcmg_setup() agrees before each collective call
 *   (PCMGSetLevels, each level's MatCreate .. MatAssemblyEnd, PCSetFromOptions) and at the
 *   end; the block smoother's PCSetUp agrees on its local vectors and on its factor and then
 *   fails with a PETSc error carrying the agreed message on every process;
 *   fcm__petsc_pcmg_smoothers_setup() sets the smoothers up right after KSPSetUp (PETSc would
 *   do it lazily inside the cycle, where an agreed failure left the KSP inconsistent);
 *   fcm_petsc_problem_setup() agrees on insert_options() before KSPCreate. Not covered: a
 *   failure inside a PETSc collective call on one process only (PETSc's own allocations).
 * - tests: tests/petsc/pcmg.c (petsc_pcmg_*), petsc_newton_static_snh_mg_*,
 *   tests/petsc/pcmg_failure.c (petsc_pcmg_failure_*: allocation k fails on process 1 only,
 *   swept over the setup and first step; every process fails with the message, none hangs).
 * - not done: the hierarchy and the block lists are replicated (O(DOFs) per process, like the
 *   numbering); its build is sequential on every process; the coarsest Cholesky is redundant
 *   (every process factors <= 2000 DOFs); the Schwarz blocks are dense (memory 15.6 kB/DOF on
 *   Hex20 against 12.0 with GAMG); the iterations still depend on where the cuts lie (20 on the
 *   fcm-scaling ball n = 16, 53 on the bench's n = 12). Reproducibility: the Chebyshev
 *   estimates use PETSc's deterministic "noisy" vector and fcm_schwarz is deterministic, but
 *   the smoother's reverse scatter adds the subdomains' corrections; with 3 or more processes a
 *   row may receive several remote contributions, whose order PETSc does not promise (not
 *   checked; 1 and 2 processes are exact: at most two addends).
 * Not done:
 * - bit-identical resume: PT-Scotch's partition of the same scene on 2 processes differs
 *   between runs now and then (131/133 or 132/132 own elements of slingshot, although
 *   scotch_random_reset() runs before it), hence the Morton default. The round-off differences
 *   of petsc_checkpoint_np2 came from MUMPS, not from fcm: on 2 processes MUMPS adds the
 *   contribution blocks of a front in the order their messages arrive, so two factorizations of
 *   the same matrix differ at ~1e-16 (12 of 12 runs bitwise with CG + GAMG, CG + Jacobi and
 *   -pc_type redundant; 10 of 12 differing with MUMPS Cholesky or LU, with or without
 *   OMP/OpenBLAS threads). The test holds the default solver to bit for bit, MUMPS to 1e-12.
 * - scalability of phase 2: the matrices and the topology are local since session 8 (next
 *   item), but the vectors are still dense sums of n doubles per process (the force per
 *   evaluation, D (x - u_n), the elimination's lift per predictor, the loads, the mass
 *   matrix's products), the state and ~20 work vectors are replicated (168 B/DOF), and
 *   newton_solve() gathers the direction on every process (VecScatterCreateToAll, n doubles).
 *   Next: the integrator's vectors over the space's rows (the local copies: the same index as
 *   the local matrices' rows and as fcm__space_elem_row()), the sums as ghost exchanges (a
 *   VecScatter from the local rows to the MATMPIAIJ's layout, ADD then INSERT back), the dot
 *   products and norms over owned rows then summed, the constraints' lists per process; the
 *   frames, checkpoints, log and the cut's state transfer gather what they need.
 * - phase 2 on a LOCAL space (session 8): run.c creates the simulation's space and every cut's
 *   space with fcm__space_create_local() + fcm__space_localize() (own cells and a ghost layer
 *   on both sides), newton_build() narrows it as phase 1 does (localize_space(): own cells and
 *   the cells using a copy this process owns). M, H, D, H0 are fcm__space_matrix_create_rows()
 *   matrices over the local copies' rows (global columns); assembly, Nitsche's scatter,
 *   eliminate_partial() and newton_factor() go by row (fcm__space_row_dof()); every product
 *   with M / D / H0 is fcm__space_matrix_apply() (an n-vector, zero off the local rows) summed
 *   as before. Measured (FCM_TEST_VERBOSE=1 mpiexec -n P build/petsc_newton DIR SCENE 1 on
 *   apps/scenes/clamped_surface.json with background.cells [16, 16, 16] and
 *   geometry.resolution 24: 6,597 DOFs; bytes per global DOF, largest process): P = 1:
 *   topology 421, 3 matrices 2,454; P = 2: 256 / 1,499; P = 3: 202 / 1,184 (the ghost share
 *   is large on this small grid: 996 and 832 of 1,664 cells on 2 processes). The matrices
 *   share the space's pattern since (fcm__csr_share_pattern(), la_impl.h: values only, 8 B
 *   per entry instead of 12): 3 matrices 989 B/DOF on 2 processes there. Still replicated:
 *   numbering 38 B/DOF, vectors 168 B/DOF, the adapter's per-copy arrays.
 * - cuts keep the partition made at the start (the pieces of a split cell belong to its
 *   owner; cut-heavy regions are not rebalanced) and the cut's classification of every cell
 *   runs on every process (replicated; the first build's is distributed, see above); the cut-cell
 * weight 4 of the partition is not updated for cells a later cut reaches.
 * - the linear driver (phase 1) could now be replaced by the phase-2 path for the scenes both
 *   run (they agree to the KSP tolerance); it is kept: it assembles straight into PETSc and
 *   scales further (no dense sums), and its tests and checkpoints stay.
 * Done (phase 1, the crop): crop_geometry() after the partition: each process's rules build
 *   reads fcm__embed_crop_geometry() (embed/cell_rules.c): the geometry cells whose boxes meet
 *   the kernels' query box (fcm__embed_cell_setup()'s lo/hi, widened by the clipping
 *   tolerance) of every cell it classifies (!P->remote: its own and its round-robin
 *   non-candidates), and the boundary triangles meeting those of its own cells (mask), found
 *   with the same trees as the build, so every candidate is kept; fcm__geom_create_subset()
 *   (geom/geometry.c) keeps them in original order with their original ids (cell_orig,
 *   tri_orig; surface points carry the original triangle ids, intersect.c), the whole
 *   geometry's volume and box, and the whole geometry's outside volume per side of the mesh
 *   box (fcm__embed_outside() takes them from the crop). Bit for bit: the candidates were
 *   already sorted (fcm__geom_tree_query() sorts its ids ascending since the geometry module
 *   was written, so the earlier note's step (1) was not needed and no serial rule changed);
 *   sorted crop ids map to sorted original ids. Not on one process (no gain). The crop is
 *   freed after the rules build; fcm_petsc_info.geometry_* and
 *   fcm_petsc_problem_geometry_kept() report it (tests/petsc/classify.c check_crop(),
 *   tests/embed/crop.c). Measured: mpirun -n 2 petsc_bench hex8 24 24 (663,552 tets): 345,600
 *   cells (15.3 of 24.9 MB) per process, peak RSS 344 vs 384 MB per process without the crop.
 * Not done (phase 1):
 * - every process still reads / generates the WHOLE geometry first (peak memory includes it;
 *   a reader that streams and keeps only the needed part would remove that); the mesh is
 *   replicated; still replicated per cell: class, fraction, pieces (O(cells) bytes: what the
 *   DOF numbering needs).
 * - phase 2 keeps the whole geometry (effects select boundary triangles of it; cuts classify
 *   every cell on every process and need every geometry cell); cropping only its first rules
 *   build would shrink that build's trees, not the geometry (run.c build_rules(), not done).
 * - replicated still (phase 1): the numbering and the adapter's per-copy arrays (perm,
 *   copy_owner, is_con), the mesh (and the whole geometry until the cropped rules build):
 *   about 5 GB per process at 1e8 Hex20 DOFs (README projection). Next: number each process's own
 * copies locally and exchange the ghosts' numbers (PetscSF), with the mesh cropped to own + ghost
 * cells.
 * ------------------------------------------------------------------------------------------ */
#define _GNU_SOURCE /* RTLD_DEFAULT */
#include "petsc/petsc_impl.h"

#include <dlfcn.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---------------------------------------------------------------- errors */

fcm_status fcm__petsc_error(fcm_ctx *ctx, PetscErrorCode ierr, const char *call, const char *file,
                            int line, const char *func)
{
  const char *text = NULL;
  char *specific = NULL;
  PetscErrorMessage((int)ierr, &text, &specific);
  return fcm__error(ctx, FCM_ERR_INTERNAL, file, line, func, "petsc: %s failed: %s%s%s (error %d)",
                    call, text ? text : "unknown error", specific && *specific ? ": " : "",
                    specific ? specific : "", (int)ierr);
}

/* Every process learns whether any failed: on failure somewhere, every process returns the
 * status and message of the lowest failing process (the others record it as their error). */
fcm_status fcm__petsc_agree(fcm_ctx *ctx, MPI_Comm comm, fcm_status st)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int mine = st != FCM_OK ? rank : size, first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return FCM_OK;
  char msg[1024];
  int code = (int)st;
  memset(msg, 0, sizeof msg);
  if (rank == first) snprintf(msg, sizeof msg, "%s", fcm_ctx_error_message(ctx));
  MPI_Bcast(msg, (int)sizeof msg, MPI_CHAR, first, comm);
  MPI_Bcast(&code, 1, MPI_INT, first, comm);
  if (rank == first) {
    if (size > 1) fcm__error_prefix(ctx, "(on this process)");
    return st;
  }
  return fcm__error(ctx, (fcm_status)code, __FILE__, __LINE__, __func__,
                    "process %d of %d failed: %s", first, size, msg);
}

/* fcm__petsc_agree() on P's communicator; a failure is remembered (P->agreed_fail), so that a
 * process that learnt of it here does not start another fcm__petsc_agree() the others never meet.
 */
fcm_status fcm__petsc_problem_agree(fcm_petsc_problem *P, fcm_status st)
{
  st = fcm__petsc_agree(P->ctx, P->comm, st);
  if (st != FCM_OK) P->agreed_fail = 1;
  return st;
}

/* ---------------------------------------------------------------- init */

/* Problems made so far by this process (every process makes them in the same order: the
 * creators are collective), for the options prefixes. */
static unsigned long fcm_petsc_num_problems = 0;

/* A new problem's options prefix "fcm<k>_" (k = 1, 2, ...). */
static void set_prefix(fcm_petsc_problem *P)
{
  snprintf(P->prefix, sizeof P->prefix, "fcm%lu_", ++fcm_petsc_num_problems);
}

static int fcm_petsc_started_mpi = 0;
static int fcm_petsc_pushed_handler = 0; /* fcm_petsc_initialize() pushed PETSc's error handler */

fcm_status fcm_petsc_initialize(fcm_ctx *ctx, int *argc, char ***argv)
{
  fcm_status st = FCM_OK;
  int mpi_on = 0;
  PetscBool on = PETSC_FALSE;
  MPI_Initialized(&mpi_on);
  fcm_petsc_started_mpi = !mpi_on;
  PCALL(ctx, PetscInitialized(&on));
  if (!on) {
    PetscErrorCode ierr = PetscInitialize(argc, argv, NULL, NULL);
    FCM_CHECK(ierr == 0, ctx, FCM_ERR_INTERNAL, "petsc: PetscInitialize failed (error %d)",
              (int)ierr);
    /* PETSc's default handler prints a traceback on stderr at every error; a library prints
     * nothing unasked: the error comes back as the fcm error of the failed call, with PETSc's
     * message (fcm__petsc_error()). A program that initialized PETSc itself keeps its own
     * handler. */
    ierr = PetscPushErrorHandler(PetscReturnErrorHandler, NULL);
    FCM_CHECK(ierr == 0, ctx, FCM_ERR_INTERNAL, "petsc: PetscPushErrorHandler failed (error %d)",
              (int)ierr);
    fcm_petsc_pushed_handler = 1;
  }
cleanup:
  return st;
}

void fcm_petsc_finalize(void)
{
  PetscBool on = PETSC_FALSE;
  if (PetscInitialized(&on) == 0 && on) {
    if (fcm_petsc_pushed_handler) PetscPopErrorHandler();
    fcm_petsc_pushed_handler = 0;
    PetscFinalize();
  }
}

const char *fcm_petsc_partition_name(fcm_petsc_partition p)
{
  switch (p) {
  case FCM_PETSC_PARTITION_AUTO:
    return "auto";
  case FCM_PETSC_PARTITION_PTSCOTCH:
    return "ptscotch";
  case FCM_PETSC_PARTITION_ORDERED:
    return "ordered";
  default:
    return "invalid";
  }
}

fcm_petsc_options fcm_petsc_options_default(void)
{
  fcm_petsc_options o;
  memset(&o, 0, sizeof o);
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = 1.0 / 60.0;
  o.partition = FCM_PETSC_PARTITION_AUTO;
  o.petsc_options = NULL;
  o.rtol = 1e-10;
  o.max_iterations = 10000;
  o.rules = fcm_cell_rules_options_default();
  o.assembly = fcm_assembly_options_default();
  return o;
}

/* ---------------------------------------------------------------- partition */

/* Spread the 21 low bits of x to every third bit. */
static uint64_t spread3(uint64_t x)
{
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

typedef struct keyed {
  uint64_t key;
  fcm_index cell;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
  const keyed *x = a, *y = b;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  return x->cell < y->cell ? -1 : x->cell > y->cell;
}

/* Partition weight of a candidate cell (candidate_cells()): cut cells carry their own rules
 * (intersection, simplification, stabilization: several times an uncut cell's work), so cells
 * that probably are cut weigh FCM_PETSC_CUT_WEIGHT, the others 1 (a heuristic: the rule and
 * assembly costs per cell are not measured per run). */
static int cell_weight(const fcm_petsc_problem *P, fcm_index c)
{
  return P->weight[c];
}

/* ORDERED: active cells along the Morton curve of their centroids, equal contiguous parts. */
static fcm_status partition_ordered(fcm_petsc_problem *P, const unsigned char *active,
                                    fcm_index nact)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_index nc = fcm_mesh_num_cells(P->mesh);
  const int nn = fcm_mesh_nodes_per_cell(P->mesh);
  keyed *k = NULL;
  double *X = NULL, lo[3], hi[3];
  FCM_ALLOC(ctx, nact + 1, k);
  FCM_ALLOC(ctx, 3 * nn, X);
  fcm_mesh_bounding_box(P->mesh, lo, hi);
  fcm_index m = 0;
  for (fcm_index c = 0; c < nc; c++) {
    if (!active[c]) continue;
    double x[3] = {0, 0, 0};
    fcm_mesh_cell_coords(P->mesh, c, X);
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++)
        x[i] += X[3 * a + i] / nn;
    uint64_t key = 0;
    for (int i = 0; i < 3; i++) {
      double s = hi[i] > lo[i] ? (x[i] - lo[i]) / (hi[i] - lo[i]) : 0.0;
      uint64_t q = (uint64_t)(fmin(fmax(s, 0.0), 1.0) * 2097151.0);
      key |= spread3(q) << i;
    }
    k[m].key = key;
    k[m].cell = c;
    m++;
  }
  qsort(k, (size_t)m, sizeof *k, cmp_keyed);
  double wsum = 0.0, w = 0.0;
  for (fcm_index i = 0; i < m; i++)
    wsum += cell_weight(P, k[i].cell);
  for (fcm_index i = 0; i < m; i++) { /* equal weight per process, cut at the mid-weight */
    const double wc = cell_weight(P, k[i].cell);
    const int r = (int)((w + 0.5 * wc) * P->size / wsum);
    P->cell_owner[k[i].cell] = r < P->size ? r : P->size - 1;
    w += wc;
  }
cleanup:
  fcm__free(ctx, k);
  fcm__free(ctx, X);
  return st;
}

/* PT-Scotch draws from a random generator whose state persists between calls, so a second
 * problem in the same run would get another partition (and other rounding). Reset it before
 * each partition when the library PETSc loaded exports SCOTCH_randomReset (looked up at run
 * time: fcm does not link Scotch itself), so equal inputs give equal partitions. */
static void scotch_random_reset(void)
{
  void (*reset)(void) = NULL;
  void *sym = dlsym(RTLD_DEFAULT, "SCOTCH_randomReset");
  memcpy(&reset, &sym, sizeof reset);
  if (reset) reset();
}

/* PTSCOTCH: MatPartitioning of the face graph of the active cells; each process hands a
 * contiguous block of them to PETSc, the result is gathered on every process. */
static fcm_status partition_graph(fcm_petsc_problem *P, const unsigned char *active, fcm_index nact)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_index nc = fcm_mesh_num_cells(P->mesh);
  const int nf = fcm_mesh_get_element_info(P->mesh)->num_faces;
  const fcm_index *nb = fcm_mesh_neighbors(P->mesh);
  fcm_index *act_id = NULL, *act_cell = NULL;
  PetscInt *ia = NULL, *ja = NULL;
  Mat adj = NULL;
  MatPartitioning part = NULL;
  IS is = NULL, isg = NULL;
  const PetscInt *own = NULL;
  FCM_ALLOC(ctx, nc + 1, act_id);
  FCM_ALLOC(ctx, nact + 1, act_cell);
  fcm_index m = 0;
  for (fcm_index c = 0; c < nc; c++) {
    act_id[c] = active[c] ? m : -1;
    if (active[c]) act_cell[m++] = c;
  }
  const fcm_index lo = nact * P->rank / P->size, hi = nact * (P->rank + 1) / P->size;
  const PetscInt ml = (PetscInt)(hi - lo);
  PCALL(ctx, PetscMalloc1(ml + 1, &ia));
  PCALL(ctx, PetscMalloc1(ml * nf + 1, &ja));
  ia[0] = 0;
  for (fcm_index i = lo; i < hi; i++) {
    PetscInt r = (PetscInt)(i - lo), cnt = ia[r];
    const fcm_index c = act_cell[i];
    for (int f = 0; f < nf; f++) {
      fcm_index o = nb[(size_t)nf * c + f];
      if (o >= 0 && active[o]) ja[cnt++] = (PetscInt)act_id[o];
    }
    /* MatCreateMPIAdj wants sorted columns */
    for (PetscInt a = ia[r] + 1; a < cnt; a++)
      for (PetscInt b = a; b > ia[r] && ja[b - 1] > ja[b]; b--) {
        PetscInt t = ja[b];
        ja[b] = ja[b - 1];
        ja[b - 1] = t;
      }
    ia[r + 1] = cnt;
  }
  PCALL(ctx, MatCreateMPIAdj(P->comm, ml, (PetscInt)nact, ia, ja, NULL, &adj));
  ia = ja = NULL; /* owned by adj */
  PCALL(ctx, MatPartitioningCreate(P->comm, &part));
  PCALL(ctx, MatPartitioningSetAdjacency(part, adj));
  {
    PetscInt *vw = NULL; /* vertex weights: freed by the partitioning */
    PCALL(ctx, PetscMalloc1(ml + 1, &vw));
    for (fcm_index i = lo; i < hi; i++)
      vw[i - lo] = cell_weight(P, act_cell[i]);
    PCALL(ctx, MatPartitioningSetVertexWeights(part, vw));
  }
  PCALL(ctx, MatPartitioningSetType(part, MATPARTITIONINGPTSCOTCH));
  PCALL(ctx, MatPartitioningSetFromOptions(part));
  scotch_random_reset();
  PCALL(ctx, MatPartitioningApply(part, &is));
  PCALL(ctx, ISAllGather(is, &isg));
  PCALL(ctx, ISGetIndices(isg, &own));
  for (fcm_index i = 0; i < nact; i++)
    P->cell_owner[act_cell[i]] = (int)own[i];
  PCALL(ctx, ISRestoreIndices(isg, &own));
cleanup:
  PetscFree(ia);
  PetscFree(ja);
  ISDestroy(&is);
  ISDestroy(&isg);
  MatPartitioningDestroy(&part);
  MatDestroy(&adj);
  fcm__free(ctx, act_id);
  fcm__free(ctx, act_cell);
  return st;
}

/* ---------------------------------------------------------------- create */

static fcm_status check_inputs(fcm_petsc_problem *P, const fcm_petsc_options *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  FCM_TRY(ctx, fcm_material_validate(ctx, &P->mat));
  FCM_CHECK(P->mat.model == FCM_MATERIAL_LINEAR, ctx, FCM_ERR_UNSUPPORTED,
            "petsc: material model %d: the PETSc backend solves linear elasticity only (model "
            "linear); use the serial backend for hyperelastic materials",
            (int)P->mat.model);
  FCM_CHECK(o->kind == FCM_INTEGRATOR_STATIC || o->kind == FCM_INTEGRATOR_BACKWARD_EULER, ctx,
            FCM_ERR_ARG, "petsc: kind = %d is neither static (0) nor backward Euler (1)",
            (int)o->kind);
  FCM_CHECK(isfinite(o->dt) && o->dt > 0.0, ctx, FCM_ERR_ARG, "petsc: dt = %g must be > 0", o->dt);
  FCM_CHECK((int)o->partition >= 0 && o->partition < FCM_PETSC_PARTITION_COUNT, ctx, FCM_ERR_ARG,
            "petsc: partition = %d is not a method (0 auto, 1 ptscotch, 2 ordered)",
            (int)o->partition);
  FCM_CHECK(o->rtol > 0.0 && o->rtol < 1.0, ctx, FCM_ERR_ARG, "petsc: rtol = %g outside (0, 1)",
            o->rtol);
  FCM_CHECK(o->max_iterations >= 1, ctx, FCM_ERR_ARG, "petsc: max_iterations = %d must be >= 1",
            o->max_iterations);
  FCM_CHECK(o->rules.simplify != FCM_CELL_SIMPLIFY_AUTO, ctx, FCM_ERR_UNSUPPORTED,
            "petsc: rules.simplify = auto is not supported (the choice would differ between "
            "processes); use on or off");
cleanup:
  return st;
}

static fcm_status rules_exchange(void *user, fcm_status st, unsigned char *cls, double *fraction,
                                 double *volume, fcm__embed_counts *counts);

/* The options of phase 1's rules build: points on the cells flagged in mask. */
static fcm_cell_rules_options rules_options(const fcm_petsc_problem *P, const unsigned char *mask)
{
  fcm_cell_rules_options ro = P->opts.rules;
  ro.kinds =
      FCM_RULES_STIFFNESS | (P->opts.kind == FCM_INTEGRATOR_BACKWARD_EULER ? FCM_RULES_MASS : 0u);
  ro.cell_mask = mask;
  return ro;
}

/* The rules (geometry: points on the cells flagged in `mask` only, each cell classified by one
 * process: P->remote, rules_exchange()) and the space's numbering (fcm__space_create_local(),
 * the serial space's numbering bit for bit; its topology comes after the DOFs' ownership,
 * localize_space()). */
static fcm_status build_space(fcm_petsc_problem *P, const fcm_geometry *geom,
                              const unsigned char *mask)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  if (geom) {
    const fcm_cell_rules_options ro = rules_options(P, mask);
    const fcm__rules_exchange x = {P->remote, rules_exchange, P};
    FCM_TRY(ctx, fcm__cell_rules_create_distributed(ctx, P->mesh, geom, &ro, NULL, &x, &P->rules));
    const fcm_space_options so = fcm_space_options_default(); /* fcm_space_create_embedded()'s */
    FCM_TRY(ctx, fcm__space_create_local(ctx, P->mesh, NULL, P->rules, &so, NULL, &P->space));
  } else {
    FCM_TRY(ctx, fcm__space_create_local(ctx, P->mesh, NULL, NULL, NULL, NULL, &P->space));
  }
cleanup:
  return st;
}

/* Boxes (lo[3], hi[3]) of the n cells (npc nodes each, connectivity conn) of coordinates X. */
static fcm_status cell_boxes(fcm_ctx *ctx, fcm_index n, int npc, const fcm_index *conn,
                             const double *X, double **out)
{
  fcm_status st = FCM_OK;
  double *b = NULL;
  FCM_ALLOC(ctx, 6 * (size_t)n + 1, b);
  for (fcm_index i = 0; i < n; i++) {
    double *bi = b + 6 * i;
    for (int d = 0; d < 3; d++)
      bi[d] = HUGE_VAL, bi[3 + d] = -HUGE_VAL;
    for (int a = 0; a < npc; a++)
      for (int d = 0; d < 3; d++) {
        const double v = X[3 * conn[(size_t)npc * i + a] + d];
        bi[d] = fmin(bi[d], v);
        bi[3 + d] = fmax(bi[3 + d], v);
      }
  }
  *out = b;
cleanup:
  return st;
}

/* P->weight[c]: 0 no candidate, 1 candidate, FCM_PETSC_CUT_WEIGHT candidate whose box also
 * meets a boundary triangle's box. Without a geometry every cell weighs 1. */
static fcm_status candidate_cells(fcm_petsc_problem *P, const fcm_geometry *geom)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_mesh *mesh = P->mesh;
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  double *gb = NULL, *tb = NULL, *cb = NULL;
  fcm_aabb_tree *gt = NULL, *tt = NULL;
  if (!geom) {
    for (fcm_index c = 0; c < nc; c++)
      P->weight[c] = 1;
    return FCM_OK;
  }
  const fcm_index ng = fcm_geometry_num_cells(geom);
  const fcm_index nt = fcm_geometry_num_boundary_triangles(geom);
  FCM_TRY(ctx, cell_boxes(ctx, ng, fcm_geometry_nodes_per_cell(geom), fcm_geometry_cells(geom),
                          fcm_geometry_coords(geom), &gb));
  FCM_TRY(ctx, cell_boxes(ctx, nt, 3, fcm_geometry_boundary_triangles(geom),
                          fcm_geometry_coords(geom), &tb));
  FCM_TRY(ctx, cell_boxes(ctx, nc, fcm_mesh_nodes_per_cell(mesh), fcm_mesh_cells(mesh),
                          fcm_mesh_coords(mesh), &cb));
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, ng, gb, &gt));
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, nt, tb, &tt));
  for (fcm_index c = 0; c < nc; c++) {
    fcm_index hits = 0;
    FCM_TRY(ctx, fcm_aabb_tree_query(gt, cb + 6 * c, cb + 6 * c + 3, 0, NULL, &hits));
    P->weight[c] = 0;
    if (hits == 0) continue;
    FCM_TRY(ctx, fcm_aabb_tree_query(tt, cb + 6 * c, cb + 6 * c + 3, 0, NULL, &hits));
    P->weight[c] = hits > 0 ? FCM_PETSC_CUT_WEIGHT : 1;
  }
cleanup:
  fcm_aabb_tree_destroy(&gt);
  fcm_aabb_tree_destroy(&tt);
  fcm__free(ctx, gb);
  fcm__free(ctx, tb);
  fcm__free(ctx, cb);
  return st;
}

/* The candidate cells (candidate_cells(): those whose box meets the box of a geometry cell,
 * every cell without a geometry, weighted FCM_PETSC_CUT_WEIGHT where the box also meets a
 * boundary triangle's box: likely cut; a superset of the active cells, found without
 * intersecting anything) and their partition: P->cell_owner (-1: no candidate), *mask (this
 * process's cells, allocated), and who classifies each cell in the rules build: its owner, the
 * cells no process owns (which the rules drop, unless the box test missed a cell) round robin
 * (P->classifier, P->remote). Collective; a failure is agreed on (fcm__petsc_problem_agree()). */
static fcm_status partition_cells(fcm_petsc_problem *P, const fcm_geometry *geom,
                                  unsigned char **mask)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_index nc = fcm_mesh_num_cells(P->mesh);
  *mask = fcm__calloc(ctx, (size_t)nc + 1, 1);
  P->cell_owner = fcm__calloc(ctx, (size_t)nc + 1, sizeof *P->cell_owner);
  P->weight = fcm__calloc(ctx, (size_t)nc + 1, 1);
  P->classifier = fcm__calloc(ctx, (size_t)nc + 1, sizeof *P->classifier);
  P->remote = fcm__calloc(ctx, (size_t)nc + 1, 1);
  st = *mask && P->cell_owner && P->weight && P->classifier && P->remote ? FCM_OK : FCM_ERR_ALLOC;
  if (st == FCM_OK) st = candidate_cells(P, geom);
  FCM_TRY(ctx, fcm__petsc_problem_agree(P, st));
  fcm_index ncand = 0;
  for (fcm_index c = 0; c < nc; c++) {
    P->cell_owner[c] = -1;
    ncand += P->weight[c] != 0;
  }
  P->partition = P->opts.partition == FCM_PETSC_PARTITION_AUTO ? FCM_PETSC_PARTITION_ORDERED
                                                               : P->opts.partition;
  if (P->size == 1) {
    for (fcm_index c = 0; c < nc; c++)
      if (P->weight[c]) P->cell_owner[c] = 0;
  } else if (P->partition == FCM_PETSC_PARTITION_PTSCOTCH) {
    st = partition_graph(P, P->weight, ncand);
  } else {
    st = partition_ordered(P, P->weight, ncand);
  }
  FCM_TRY(ctx, fcm__petsc_problem_agree(P, st));
  P->num_classified = nc;
  for (fcm_index c = 0; c < nc; c++) {
    (*mask)[c] = P->cell_owner[c] == P->rank;
    P->classifier[c] = P->cell_owner[c] >= 0 ? P->cell_owner[c] : (int)(c % P->size);
    P->remote[c] = P->classifier[c] != P->rank;
  }
cleanup:
  return st;
}

/* The exchange of the distributed classification (fcm__rules_exchange, embed_impl.h): after
 * an agreement on the status, each process sends (class, volume fraction, embedded volume) of
 * the cells it classified, in cell order, as 3 doubles each (MPI_Allgatherv; every process
 * knows P->classifier, so no cell ids travel), and the counters are summed in process order
 * (the same bits everywhere). */
static fcm_status rules_exchange(void *user, fcm_status st, unsigned char *cls, double *fraction,
                                 double *volume, fcm__embed_counts *counts)
{
  fcm_petsc_problem *P = user;
  fcm_ctx *ctx = P->ctx;
  const double t0 = fcm_wtime();
  const fcm_index nc = P->num_classified;
  enum { NCOUNT = 7 };
  int *cnt = NULL, *displ = NULL;
  double *send = NULL, *recv = NULL, *all = NULL;
  fcm_index mine = 0;
  if (st == FCM_OK)
    FCM_CHECK(3 * nc < (fcm_index)INT32_MAX, ctx, FCM_ERR_UNSUPPORTED,
              "petsc: %lld background cells: the classification exchange (3 doubles a cell, "
              "MPI's int counts) is limited to %d cells",
              (long long)nc, (int)(INT32_MAX / 3));
  if (st == FCM_OK) {
    for (fcm_index c = 0; c < nc; c++)
      mine += P->classifier[c] == P->rank;
    cnt = fcm__calloc(ctx, (size_t)P->size + 1, sizeof *cnt);
    displ = fcm__calloc(ctx, (size_t)P->size + 1, sizeof *displ);
    send = fcm__malloc(ctx, 3 * (size_t)mine + 1, sizeof *send);
    recv = fcm__malloc(ctx, 3 * (size_t)nc + 1, sizeof *recv);
    all = fcm__calloc(ctx, (size_t)NCOUNT * (size_t)P->size + 1, sizeof *all);
    if (!cnt || !displ || !send || !recv || !all) st = FCM_ERR_ALLOC;
  }
cleanup:
  st = fcm__petsc_problem_agree(P, st); /* every process arrives here, failed or not */
  if (st != FCM_OK) goto done;
  for (fcm_index c = 0; c < nc; c++)
    cnt[P->classifier[c]] += 3;
  for (int r = 1; r <= P->size; r++)
    displ[r] = displ[r - 1] + cnt[r - 1];
  fcm_index k = 0;
  for (fcm_index c = 0; c < nc; c++)
    if (P->classifier[c] == P->rank) {
      send[k++] = (double)cls[c];
      send[k++] = fraction[c];
      send[k++] = volume[c];
    }
  int rc = MPI_Allgatherv(send, cnt[P->rank], MPI_DOUBLE, recv, cnt, displ, MPI_DOUBLE, P->comm);
  if (rc == MPI_SUCCESS) {
    for (fcm_index c = 0; c < nc; c++) {
      const int r = P->classifier[c];
      const double *q = recv + displ[r];
      displ[r] += 3;
      if (r == P->rank) continue;
      cls[c] = (unsigned char)q[0];
      fraction[c] = q[1];
      volume[c] = q[2];
    }
    const double local[NCOUNT] = {(double)counts->candidates,
                                  (double)counts->parts,
                                  (double)counts->tets,
                                  (double)counts->slivers,
                                  (double)counts->surface_triangles,
                                  (double)counts->degenerate,
                                  counts->sliver_volume};
    rc = MPI_Allgather(local, NCOUNT, MPI_DOUBLE, all, NCOUNT, MPI_DOUBLE, P->comm);
  }
  if (rc != MPI_SUCCESS) { /* MPI's default handler aborts first; with another one, give up */
    st = fcm__error(ctx, FCM_ERR_INTERNAL, __FILE__, __LINE__, __func__,
                    "petsc: the classification exchange failed (MPI error %d)", rc);
    goto done;
  }
  double sum[NCOUNT] = {0};
  for (int r = 0; r < P->size; r++)
    for (int i = 0; i < NCOUNT; i++)
      sum[i] += all[NCOUNT * r + i];
  counts->candidates = (fcm_index)sum[0];
  counts->parts = (fcm_index)sum[1];
  counts->tets = (fcm_index)sum[2];
  counts->slivers = (fcm_index)sum[3];
  counts->surface_triangles = (fcm_index)sum[4];
  counts->degenerate = (fcm_index)sum[5];
  counts->sliver_volume = sum[6];
done:
  P->time_classify = fcm_wtime() - t0;
  fcm__free(ctx, cnt);
  fcm__free(ctx, displ);
  fcm__free(ctx, send);
  fcm__free(ctx, recv);
  fcm__free(ctx, all);
  return st;
}

/* Ownership of the DOF copies and the PETSc numbering. */
static fcm_status number_dofs(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  const int nn = s->nn;
  PetscInt *count = NULL;
  P->n = s->num_dofs;
  P->ncopy = P->n / 3;
  FCM_CHECK(P->n < (fcm_index)INT32_MAX, ctx, FCM_ERR_UNSUPPORTED,
            "petsc: %lld DOFs exceed PETSc's 32-bit indices (Debian's build); use a PETSc with "
            "--with-64-bit-indices",
            (long long)P->n);
  FCM_ALLOC(ctx, P->ncopy + 1, P->copy_owner);
  FCM_ALLOC(ctx, P->ncopy + 1, P->perm);
  FCM_ALLOC(ctx, P->size + 1, count);
  for (fcm_index k = 0; k < P->ncopy; k++)
    P->copy_owner[k] = P->size;
  P->nelem_own = 0;
  for (fcm_index e = 0; e < s->num_elems; e++) {
    const int r = P->cell_owner[s->elem_cell[e]];
    if (r == P->rank) P->nelem_own++;
    for (int a = 0; a < nn; a++) {
      const fcm_index k = s->elem_dof[e * nn + a] / 3;
      if (r < P->copy_owner[k]) P->copy_owner[k] = r;
    }
  }
  for (fcm_index k = 0; k < P->ncopy; k++) {
    FCM_CHECK(P->copy_owner[k] < P->size, ctx, FCM_ERR_INTERNAL,
              "petsc: DOF copy %lld belongs to no element", (long long)k);
    count[P->copy_owner[k]]++;
  }
  /* exclusive prefix: the first block of each process, then running positions */
  PetscInt acc = 0;
  for (int r = 0; r <= P->size; r++) {
    PetscInt c = count[r];
    count[r] = acc;
    acc += c;
  }
  P->first = count[P->rank];
  P->nlocal = count[P->rank + 1] - count[P->rank];
  for (fcm_index k = 0; k < P->ncopy; k++)
    P->perm[k] = count[P->copy_owner[k]]++;
cleanup:
  fcm__free(ctx, count);
  return st;
}

/* Phase 1: the space's topology for this process's own cells and their ghosts, the cells with
 * an element that uses a DOF copy this process owns (fcm__space_set_local_cells()).
 * Why the graph row of every owned copy k is then the full space's row: the full row lists
 * the copies of the elements that use k. Each of those elements uses a copy this process owns
 * (k), so its cell is flagged, and the local row of k (the copies of the LOCAL elements that
 * use k) is the same set. And k is local: its owner is the lowest process among the cells
 * using it, so one of this process's own cells uses it. Hence create_matrix() preallocates
 * the owned rows exactly as from the full pattern (tests/petsc/ghost.c asserts the rows, and
 * that the own cells alone would miss some). */
static fcm_status localize_space(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  fcm_space *s = P->space;
  const int nn = s->nn;
  unsigned char *mask = NULL;
  FCM_ALLOC(ctx, s->num_cells + 1, mask);
  for (fcm_index e = 0; e < s->num_elems; e++) {
    const fcm_index c = s->elem_cell[e];
    int mine = P->cell_owner[c] == P->rank;
    for (int a = 0; a < nn && !mine; a++)
      mine = P->copy_owner[s->elem_dof[e * nn + a] / 3] == P->rank;
    if (mine) mask[c] = 1;
  }
  FCM_TRY(ctx, fcm__space_set_local_cells(s, mask));
cleanup:
  fcm__free(ctx, mask);
  return st;
}

/* The preallocation of create_matrix(): the diagonal- and off-block entries of each owned
 * row (dnz, onz: 3 nlocal each, allocated here). Local. */
static fcm_status preallocation(fcm_petsc_problem *P, PetscInt **dnz_out, PetscInt **onz_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  PetscInt *dnz = NULL, *onz = NULL, rows = 0;
  const PetscInt nl = 3 * P->nlocal;
  FCM_ALLOC(ctx, nl + 1, dnz);
  FCM_ALLOC(ctx, nl + 1, onz);
  for (fcm_index lk = 0; lk < s->num_local_copies; lk++) {
    const fcm_index k = s->local_copy ? s->local_copy[lk] : lk;
    if (P->copy_owner[k] != P->rank) continue;
    rows++;
    PetscInt d = 0, o = 0;
    for (fcm_index j = s->node_ptr[lk]; j < s->node_ptr[lk + 1]; j++) {
      if (P->copy_owner[s->node_adj[j]] == P->rank)
        d += 3;
      else
        o += 3;
    }
    const PetscInt row = 3 * (P->perm[k] - P->first);
    for (int i = 0; i < 3; i++) {
      dnz[row + i] = d;
      onz[row + i] = o;
    }
  }
  FCM_CHECK(rows == P->nlocal, ctx, FCM_ERR_INTERNAL,
            "petsc: the space's topology has %lld of the %lld DOF copies this process owns",
            (long long)rows, (long long)P->nlocal);
  *dnz_out = dnz;
  *onz_out = onz;
  dnz = onz = NULL;
cleanup:
  fcm__free(ctx, dnz);
  fcm__free(ctx, onz);
  return st;
}

/* A preallocated MATMPIAIJ (block size 3) with the space's pattern on the owned rows (every
 * owned copy is one of the space's local copies: localize_space()). The processes agree on
 * the local preallocation before the collective calls (a failure there is agreed: every
 * process returns it, P->agreed_fail). Collective. */
static fcm_status create_matrix(fcm_petsc_problem *P, Mat *A)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  PetscInt *dnz = NULL, *onz = NULL;
  const PetscInt nl = 3 * P->nlocal;
  FCM_TRY(ctx, fcm__petsc_problem_agree(P, preallocation(P, &dnz, &onz)));
  PCALL(ctx, MatCreate(P->comm, A));
  PCALL(ctx, MatSetSizes(*A, nl, nl, (PetscInt)P->n, (PetscInt)P->n));
  PCALL(ctx, MatSetType(*A, MATMPIAIJ));
  PCALL(ctx, MatSetBlockSize(*A, 3));
  PCALL(ctx, MatMPIAIJSetPreallocation(*A, 0, dnz, 0, onz));
  PCALL(ctx, MatSetOption(*A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PCALL(ctx, MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
cleanup:
  fcm__free(ctx, dnz);
  fcm__free(ctx, onz);
  return st;
}

static fcm_status create_vectors(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  PCALL(ctx, VecCreateMPI(P->comm, 3 * P->nlocal, (PetscInt)P->n, &P->f));
  PCALL(ctx, VecSetBlockSize(P->f, 3));
  Vec *vs[] = {&P->u, &P->v, &P->b, &P->x, &P->g, &P->w};
  for (size_t i = 0; i < sizeof vs / sizeof vs[0]; i++) {
    PCALL(ctx, VecDuplicate(P->f, vs[i]));
    PCALL(ctx, VecSet(*vs[i], 0.0));
  }
  PCALL(ctx, VecSet(P->f, 0.0));
cleanup:
  return st;
}

/* Every active cell of P->space has an owner (a candidate of the partition), inactive ones
 * none: FCM_ERR_INTERNAL naming the first active cell without one (local). */
static fcm_status own_active_cells(fcm_petsc_problem *P)
{
  const fcm_index nc = fcm_mesh_num_cells(fcm_space_mesh(P->space));
  for (fcm_index c = 0; c < nc; c++) {
    if (P->space->active[c] && P->cell_owner[c] < 0)
      return fcm__error(P->ctx, FCM_ERR_INTERNAL, __FILE__, __LINE__, __func__,
                        "petsc: active cell %lld is no candidate (its box meets no geometry "
                        "cell)",
                        (long long)c);
    if (!P->space->active[c]) P->cell_owner[c] = -1;
  }
  return FCM_OK;
}

/* The part of geom this process's rules build reads (fcm__embed_crop_geometry(): the geometry
 * cells meeting the query boxes of the cells it classifies, !P->remote, the boundary triangles
 * meeting those of its own cells, mask), into *crop; the counts, bytes and kept ids go to P.
 * On one process no crop (*crop NULL): the whole geometry is read. Local. */
static fcm_status crop_geometry(fcm_petsc_problem *P, const fcm_geometry *geom,
                                const unsigned char *mask, fcm_geometry **crop)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  unsigned char *classify = NULL;
  *crop = NULL;
  if (!geom) return FCM_OK;
  P->geom_cells = P->geom_cells_kept = fcm_geometry_num_cells(geom);
  P->geom_tris = P->geom_tris_kept = fcm_geometry_num_boundary_triangles(geom);
  P->geom_bytes = P->geom_bytes_kept = fcm__geom_bytes(geom);
  if (P->size == 1) return FCM_OK;
  const fcm_index nc = fcm_mesh_num_cells(P->mesh);
  const fcm_cell_rules_options ro = rules_options(P, mask);
  FCM_ALLOC(ctx, (size_t)nc + 1, classify);
  for (fcm_index c = 0; c < nc; c++)
    classify[c] = !P->remote[c];
  FCM_TRY(ctx, fcm__embed_crop_geometry(ctx, P->mesh, geom, &ro, classify, mask, crop));
  const fcm_geometry *g = *crop;
  P->geom_cells_kept = g->num_cells;
  P->geom_tris_kept = g->num_tris;
  P->geom_bytes_kept = fcm__geom_bytes(g);
  FCM_ALLOC(ctx, (size_t)g->num_cells + 1, P->kept_cells);
  FCM_ALLOC(ctx, (size_t)g->num_tris + 1, P->kept_tris);
  memcpy(P->kept_cells, g->cell_orig, (size_t)g->num_cells * sizeof *P->kept_cells);
  memcpy(P->kept_tris, g->tri_orig, (size_t)g->num_tris * sizeof *P->kept_tris);
cleanup:
  fcm__free(ctx, classify);
  if (st != FCM_OK) fcm_geometry_destroy(crop);
  return st;
}

/* The start of both creators: after their local argument checks (st), allocate the problem
 * (*out, also when the processes then fail: its ctx, comm and single reference set for the
 * destroy), agree on st and the allocation before the first collective call, so bad input or
 * a failed allocation on one process ends them all, then duplicate comm. Collective. */
static fcm_status new_problem(fcm_ctx *ctx, MPI_Comm comm, fcm_status st, fcm_petsc_problem **out)
{
  fcm_petsc_problem *P = NULL;
  if (st == FCM_OK) {
    P = fcm__calloc(ctx, 1, sizeof *P);
    if (!P)
      st = fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__, "petsc: out of memory");
  }
  if (P) {
    P->ctx = ctx;
    P->comm = MPI_COMM_NULL;
    P->refs = 1;
  }
  *out = P;
  FCM_TRY(ctx, fcm__petsc_agree(ctx, comm, st));
  if (MPI_Comm_dup(comm, &P->comm) != MPI_SUCCESS) {
    P->comm = MPI_COMM_NULL;
    FCM_CHECK(0, ctx, FCM_ERR_ARG, "petsc: MPI_Comm_dup failed (invalid communicator?)");
  }
  MPI_Comm_size(P->comm, &P->size);
  MPI_Comm_rank(P->comm, &P->rank);
cleanup:
  return st;
}

fcm_status fcm_petsc_problem_create(fcm_ctx *ctx, MPI_Comm comm, const fcm_mesh *mesh,
                                    const fcm_geometry *geom, const fcm_material *mat,
                                    const fcm_petsc_options *opts, fcm_petsc_problem **out)
{
  fcm_status st = FCM_OK;
  fcm_petsc_problem *P = NULL;
  unsigned char *mask = NULL;
  fcm_geometry *crop = NULL;
  const double t0 = fcm_wtime();
  /* local checks, agreed in new_problem() before the first collective call */
  if (!out)
    st =
        fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__, "petsc: output pointer is NULL");
  else
    *out = NULL;
  if (st == FCM_OK && !(ctx && mesh && mat))
    st = fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "petsc: NULL argument (ctx, mesh, material)");
  FCM_TRY(ctx, new_problem(ctx, comm, st, &P));
  P->mesh = mesh;
  P->mat = *mat;
  P->opts = opts ? *opts : fcm_petsc_options_default();
  if (P->opts.petsc_options) {
    size_t len = strlen(P->opts.petsc_options);
    P->petsc_options = fcm__calloc(ctx, len + 1, 1);
    if (P->petsc_options)
      memcpy(P->petsc_options, P->opts.petsc_options, len);
    else
      st = FCM_ERR_ALLOC;
  }
  P->opts.petsc_options = NULL;
  set_prefix(P);
  if (st == FCM_OK) st = check_inputs(P, &P->opts);
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));

  /* 1., 2. the candidate cells and their partition */
  const double tr = fcm_wtime();
  FCM_TRY(ctx, partition_cells(P, geom, &mask));

  /* 3. the rules, with points on this process's cells only (each cell is classified by one
   * process, the classes gathered on every process), from the part of the geometry they read
   * (the crop), and the space; candidates the rules drop own nothing */
  FCM_TRY(ctx, fcm__petsc_problem_agree(P, crop_geometry(P, geom, mask, &crop)));
  st = build_space(P, crop ? crop : geom, mask);
  fcm_geometry_destroy(&crop);
  if (st == FCM_OK) st = own_active_cells(P);
  FCM_TRY(ctx, P->agreed_fail
                   ? st
                   : fcm__petsc_problem_agree(P, st)); /* the exchange agreed on a failure */
  FCM_FREE(ctx, P->classifier);
  FCM_FREE(ctx, P->remote);
  P->time_rules = fcm_wtime() - tr;
  st = fcm_assembly_workspace_create(P->space, &P->opts.assembly, &P->aws);
  if (st == FCM_OK) st = number_dofs(P);
  if (st == FCM_OK) st = localize_space(P);
  if (st == FCM_OK) {
    P->is_con = fcm__calloc(ctx, (size_t)P->n + 1, 1);
    if (!P->is_con) st = FCM_ERR_ALLOC;
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));

  /* 4. matrices and vectors (collective) */
  st = create_matrix(P, &P->K);
  if (st == FCM_OK && P->opts.kind == FCM_INTEGRATOR_BACKWARD_EULER) st = create_matrix(P, &P->M);
  if (st == FCM_OK) st = create_vectors(P);
  FCM_TRY(ctx, P->agreed_fail ? st : fcm__petsc_problem_agree(P, st)); /* agreed already */
  P->time_setup = fcm_wtime() - t0;
  *out = P;
  P = NULL;
cleanup:
  fcm__free(ctx, mask);
  fcm_geometry_destroy(&crop);
  fcm_petsc_problem_destroy(&P);
  return st;
}

void fcm_petsc_problem_destroy(fcm_petsc_problem **problem)
{
  if (!problem || !*problem) return;
  fcm_petsc_problem *P = *problem;
  fcm_ctx *ctx = P->ctx;
  KSPDestroy(&P->ksp);
  Mat *ms[] = {&P->K, &P->M, &P->S, &P->Se};
  for (size_t i = 0; i < sizeof ms / sizeof ms[0]; i++)
    MatDestroy(ms[i]);
  Vec *vs[] = {&P->f, &P->u, &P->v, &P->b, &P->x, &P->g, &P->w};
  for (size_t i = 0; i < sizeof vs / sizeof vs[0]; i++)
    VecDestroy(vs[i]);
  PetscFree(P->rows);
  VecScatterDestroy(&P->to_all);
  VecDestroy(&P->all);
  VecScatterDestroy(&P->frame_sc);
  VecDestroy(&P->frame_vec);
  fcm__free(ctx, P->frame_nodes);
  fcm_assembly_workspace_destroy(&P->aws);
  if (!P->borrowed_space) fcm_space_destroy(&P->space);
  fcm_cell_rules_destroy(&P->rules);
  void *arrays[] = {P->petsc_options, P->weight,     P->cell_owner, P->copy_owner,
                    P->perm,          P->con_dof,    P->con_node,   P->con_comp,
                    P->con_motion,    P->motions,    P->is_con,     P->classifier,
                    P->remote,        P->kept_cells, P->kept_tris,  P->owned_dof};
  for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
    fcm__free(ctx, arrays[i]);
  if (P->comm != MPI_COMM_NULL) MPI_Comm_free(&P->comm);
  fcm_geometry_destroy(&P->own_geom);
  fcm_mesh_destroy(&P->own_mesh);
  fcm__free(ctx, P);
  *problem = NULL;
}

/* ---------------------------------------------------------------- configuration */

fcm_status fcm_petsc_problem_add_gravity(fcm_petsc_problem *P, const double accel[3])
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  if (P->is_setup)
    st = fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "petsc: add_gravity after setup");
  else if (!accel || !isfinite(accel[0]) || !isfinite(accel[1]) || !isfinite(accel[2]))
    st = fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "petsc: gravity acceleration is NULL or not finite");
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  for (int i = 0; i < 3; i++)
    P->gravity[i] += accel[i];
  P->has_gravity = 1;
cleanup:
  return st;
}

static int finite3(const double x[3])
{
  return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]);
}

/* Check a constraint (local, no change). */
static fcm_status check_constraint(fcm_petsc_problem *P, fcm_index num_nodes,
                                   const fcm_index *nodes, const fcm_motion *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  FCM_CHECK(!P->is_setup, ctx, FCM_ERR_ARG, "petsc: add_constraint after setup");
  FCM_CHECK(m && num_nodes >= 0 && (num_nodes == 0 || nodes), ctx, FCM_ERR_ARG,
            "petsc: constraint: NULL motion or nodes, or num_nodes = %lld < 0",
            (long long)num_nodes);
  FCM_CHECK(finite3(m->velocity) && finite3(m->center) && finite3(m->axis) &&
                isfinite(m->angular_speed) && isfinite(m->start) && !isnan(m->end) &&
                m->end >= m->start,
            ctx, FCM_ERR_ARG, "petsc: constraint: motion with a non-finite member or end < start");
  FCM_CHECK(!m->release, ctx, FCM_ERR_UNSUPPORTED,
            "petsc: constraint: release (a constraint set that changes in time) is not "
            "supported by the PETSc backend");
  for (fcm_index k = 0; k < num_nodes; k++) {
    FCM_CHECK(nodes[k] >= 0 && nodes[k] < s->num_nodes, ctx, FCM_ERR_ARG,
              "petsc: constraint: node %lld (entry %lld) outside [0, %lld)", (long long)nodes[k],
              (long long)k, (long long)s->num_nodes);
    for (fcm_index c = 0; c < s->node_ncopy[nodes[k]]; c++)
      for (int i = 0; i < 3; i++)
        FCM_CHECK(!m->components[i] || !P->is_con[s->node_dof[nodes[k]] + 3 * c + i], ctx,
                  FCM_ERR_ARG,
                  "petsc: constraint %d: component %d of node %lld is constrained already (by "
                  "constraint %d); a DOF may belong to one constraint only",
                  P->num_motions, i, (long long)nodes[k],
                  (int)P->is_con[s->node_dof[nodes[k]] + 3 * c + i] - 1);
  }
cleanup:
  return st;
}

/* Add a validated constraint (local; only allocation can fail). */
static fcm_status apply_constraint(fcm_petsc_problem *P, fcm_index num_nodes,
                                   const fcm_index *nodes, const fcm_motion *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  fcm_index add = 0;
  for (fcm_index k = 0; k < num_nodes; k++)
    add += 3 * s->node_ncopy[nodes[k]];
  FCM_CHECK(fcm__resize(ctx, (void **)&P->motions, (size_t)P->num_motions,
                        (size_t)P->num_motions + 1, sizeof *P->motions) == FCM_OK &&
                fcm__resize(ctx, (void **)&P->con_dof, (size_t)P->ncon, (size_t)(P->ncon + add),
                            sizeof *P->con_dof) == FCM_OK &&
                fcm__resize(ctx, (void **)&P->con_node, (size_t)P->ncon, (size_t)(P->ncon + add),
                            sizeof *P->con_node) == FCM_OK &&
                fcm__resize(ctx, (void **)&P->con_comp, (size_t)P->ncon, (size_t)(P->ncon + add),
                            sizeof *P->con_comp) == FCM_OK &&
                fcm__resize(ctx, (void **)&P->con_motion, (size_t)P->ncon, (size_t)(P->ncon + add),
                            sizeof *P->con_motion) == FCM_OK,
            ctx, FCM_ERR_ALLOC, "petsc: constraint: out of memory");
  P->motions[P->num_motions] = *m;
  for (fcm_index k = 0; k < num_nodes; k++) {
    const fcm_index nd = nodes[k];
    for (fcm_index c = 0; c < s->node_ncopy[nd]; c++)
      for (int i = 0; i < 3; i++) {
        if (!m->components[i]) continue;
        const fcm_index d = s->node_dof[nd] + 3 * c + i;
        if (P->is_con[d]) continue; /* listed twice in this set (others: check_constraint) */
        P->is_con[d] = (unsigned char)(P->num_motions + 1 > 255 ? 255 : P->num_motions + 1);
        P->con_dof[P->ncon] = d;
        P->con_node[P->ncon] = nd;
        P->con_comp[P->ncon] = i;
        P->con_motion[P->ncon] = P->num_motions;
        P->ncon++;
      }
  }
  P->num_motions++;
cleanup:
  return st;
}

fcm_status fcm_petsc_problem_add_constraint(fcm_petsc_problem *P, fcm_index num_nodes,
                                            const fcm_index *nodes, const fcm_motion *motion)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  /* every process checks its input before any changes its state */
  st = check_constraint(P, num_nodes, nodes, motion);
  FCM_TRY(P->ctx, fcm__petsc_agree(P->ctx, P->comm, st));
  st = apply_constraint(P, num_nodes, nodes, motion);
  FCM_TRY(P->ctx, fcm__petsc_agree(P->ctx, P->comm, st));
cleanup:
  return st;
}

/* ---------------------------------------------------------------- setup */

/* Add this process's elements of `form` into A (matrix terms) or f (vector terms). */
static fcm_status assemble_local(fcm_petsc_problem *P, const fcm_linear_form *form, Mat A, Vec f)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  const int nn = s->nn, nd = 3 * nn;
  double *Ke = NULL, *fe = NULL;
  PetscInt *idx = NULL;
  FCM_ALLOC(ctx, (size_t)nd * nd, Ke);
  FCM_ALLOC(ctx, nd, fe);
  FCM_ALLOC(ctx, nd, idx);
  for (fcm_index e = 0; e < s->num_elems; e++) {
    if (P->cell_owner[s->elem_cell[e]] != P->rank) continue;
    FCM_TRY(ctx, fcm__assembly_element_linear(P->aws, form, e, A ? Ke : NULL, f ? fe : NULL));
    for (int a = 0; a < nn; a++) {
      const fcm_index d = s->elem_dof[e * nn + a];
      for (int i = 0; i < 3; i++)
        idx[3 * a + i] = 3 * P->perm[d / 3] + i;
    }
    if (A) PCALL(ctx, MatSetValues(A, nd, idx, nd, idx, Ke, ADD_VALUES));
    if (f) PCALL(ctx, VecSetValues(f, nd, idx, fe, ADD_VALUES));
  }
cleanup:
  fcm__free(ctx, Ke);
  fcm__free(ctx, fe);
  fcm__free(ctx, idx);
  return st;
}

/* The assembly of all terms of this process: local element loops (errors agreed on before
 * the collective MatAssembly). */
static fcm_status assemble_all(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  fcm_linear_form form = fcm_linear_form_default();
  form.material = &P->mat;
  form.term = FCM_LINEAR_STIFFNESS;
  st = assemble_local(P, &form, P->K, NULL);
  if (st == FCM_OK && P->M) {
    form.term = FCM_LINEAR_MASS;
    st = assemble_local(P, &form, P->M, NULL);
  }
  if (st == FCM_OK && P->has_gravity) {
    form.term = FCM_LINEAR_BODY_FORCE;
    form.accel = P->gravity;
    st = assemble_local(P, &form, NULL, P->f);
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  PCALL(ctx, MatAssemblyBegin(P->K, MAT_FINAL_ASSEMBLY));
  PCALL(ctx, MatAssemblyEnd(P->K, MAT_FINAL_ASSEMBLY));
  if (P->M) {
    PCALL(ctx, MatAssemblyBegin(P->M, MAT_FINAL_ASSEMBLY));
    PCALL(ctx, MatAssemblyEnd(P->M, MAT_FINAL_ASSEMBLY));
  }
  PCALL(ctx, VecAssemblyBegin(P->f));
  PCALL(ctx, VecAssemblyEnd(P->f));
cleanup:
  return st;
}

/* Coordinates of the owned DOF copies (their node's), block size 3, for the rigid-body modes. */
static fcm_status near_null_space(fcm_petsc_problem *P, Mat A)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  const double *X = fcm_mesh_coords(P->mesh);
  Vec coords = NULL;
  MatNullSpace nsp = NULL;
  PetscScalar *c = NULL;
  PCALL(ctx, VecDuplicate(P->f, &coords));
  PCALL(ctx, VecGetArray(coords, &c));
  for (fcm_index nd = 0; nd < s->num_nodes; nd++)
    for (fcm_index k = 0; k < s->node_ncopy[nd]; k++) {
      const fcm_index copy = s->node_dof[nd] / 3 + k;
      if (P->copy_owner[copy] != P->rank) continue;
      const PetscInt r = 3 * (P->perm[copy] - P->first);
      for (int i = 0; i < 3; i++)
        c[r + i] = X[3 * nd + i];
    }
  PCALL(ctx, VecRestoreArray(coords, &c));
  c = NULL;
  PCALL(ctx, MatNullSpaceCreateRigidBody(coords, &nsp));
  PCALL(ctx, MatSetNearNullSpace(A, nsp));
cleanup:
  if (c) VecRestoreArray(coords, &c);
  MatNullSpaceDestroy(&nsp);
  VecDestroy(&coords);
  return st;
}

/* 1 when the option name carries a problem's prefix ("-fcm12_ksp_type"). */
static int has_problem_prefix(const char *name)
{
  if (strncmp(name, "-fcm", 4) != 0 || !(name[4] >= '0' && name[4] <= '9')) return 0;
  const char *q = name + 4;
  while (*q >= '0' && *q <= '9')
    q++;
  return *q == '_';
}

/* The options database, scoped to this problem (the KSP carries the prefix P->prefix, and
 * through it the PC and its inner solvers): the problem's string under the prefix, then every
 * option the database held before (the command line, option files, PETSC_OPTIONS, values set
 * by the program) copied under the prefix, so a key both give takes the database's value; last
 * the options that name this problem's prefix themselves ("-fcm2_ksp_type") as they were, so
 * they win over both. Options of other problems' prefixes are not copied: one problem's string
 * never reaches another problem's solver. (Values are split at spaces, as PETSc lists them.) */
static fcm_status insert_options(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  char *all = NULL, **name = NULL, **value = NULL;
  int pushed = 0;
  size_t count = 0;
  PCALL(ctx, PetscOptionsGetAll(NULL, &all));
  {
    const size_t len = strlen(all);
    name = fcm__calloc(ctx, len / 2 + 1, sizeof *name);
    value = fcm__calloc(ctx, len / 2 + 1, sizeof *value);
    FCM_CHECK(name && value, ctx, FCM_ERR_ALLOC, "petsc: out of memory (options)");
    char *save = NULL;
    for (char *tok = strtok_r(all, " \t\n", &save); tok; tok = strtok_r(NULL, " \t\n", &save)) {
      const int is_name = tok[0] == '-' && ((tok[1] >= 'a' && tok[1] <= 'z') ||
                                            (tok[1] >= 'A' && tok[1] <= 'Z') || tok[1] == '_');
      if (is_name)
        name[count++] = tok;
      else if (count > 0 && !value[count - 1])
        value[count - 1] = tok;
    }
  }
  PCALL(ctx, PetscOptionsPrefixPush(NULL, P->prefix));
  pushed = 1;
  if (P->petsc_options && *P->petsc_options)
    PCALL(ctx, PetscOptionsInsertString(NULL, P->petsc_options));
  for (size_t k = 0; k < count; k++)
    if (!has_problem_prefix(name[k])) PCALL(ctx, PetscOptionsSetValue(NULL, name[k], value[k]));
  pushed = 0;
  PCALL(ctx, PetscOptionsPrefixPop(NULL));
  const size_t plen = strlen(P->prefix);
  for (size_t k = 0; k < count; k++)
    if (strncmp(name[k] + 1, P->prefix, plen) == 0)
      PCALL(ctx, PetscOptionsSetValue(NULL, name[k], value[k]));
cleanup:
  if (pushed) PetscOptionsPrefixPop(NULL);
  fcm__free(ctx, name);
  fcm__free(ctx, value);
  PetscFree(all);
  return st;
}

/* 1 when the options database names this problem's PC type (-<prefix>pc_type: the problem's
 * string and the command line are under the prefix after insert_options()). */
static int pc_type_given(const fcm_petsc_problem *P)
{
  char key[64];
  PetscBool has = PETSC_FALSE;
  snprintf(key, sizeof key, "-%spc_type", P->prefix);
  return PetscOptionsHasName(NULL, NULL, key, &has) == 0 && has;
}

fcm_status fcm_petsc_problem_setup(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  const double t0 = fcm_wtime();
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm,
                                P->is_setup ? fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__,
                                                         __func__, "petsc: setup called twice")
                                            : FCM_OK));
  long long ncon_all = 0, ncon = (long long)P->ncon;
  MPI_Allreduce(&ncon, &ncon_all, 1, MPI_LONG_LONG, MPI_MAX, P->comm);
  FCM_TRY(ctx,
          fcm__petsc_agree(ctx, P->comm,
                           P->opts.kind == FCM_INTEGRATOR_STATIC && ncon_all == 0
                               ? fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                                            "petsc: a static problem without any constraint: the "
                                            "body's rigid-body modes are free (K is singular)")
                               : FCM_OK));
  /* 1. assembly */
  const double ta = fcm_wtime();
  FCM_TRY(ctx, assemble_all(P));
  P->time_assembly = fcm_wtime() - ta;
  /* 2. the system matrix S = K (static) or M/h^2 + K, and its eliminated copy */
  PCALL(ctx, MatDuplicate(P->K, MAT_COPY_VALUES, &P->S));
  if (P->M) PCALL(ctx, MatAXPY(P->S, 1.0 / (P->opts.dt * P->opts.dt), P->M, SAME_NONZERO_PATTERN));
  PCALL(ctx, MatDuplicate(P->S, MAT_COPY_VALUES, &P->Se));
  {
    PetscReal dsum = 0.0;
    PCALL(ctx, MatGetDiagonal(P->S, P->w));
    PCALL(ctx, VecNorm(P->w, NORM_1, &dsum));
    P->diag = P->n > 0 ? dsum / (double)P->n : 1.0;
    if (!(P->diag > 0.0)) P->diag = 1.0;
  }
  P->nrows = 0;
  for (fcm_index k = 0; k < P->ncon; k++)
    P->nrows += P->copy_owner[P->con_dof[k] / 3] == P->rank;
  PCALL(ctx, PetscMalloc1(P->nrows + 1, &P->rows));
  P->nrows = 0;
  for (fcm_index k = 0; k < P->ncon; k++) {
    const fcm_index d = P->con_dof[k];
    if (P->copy_owner[d / 3] == P->rank) P->rows[P->nrows++] = 3 * P->perm[d / 3] + d % 3;
  }
  PCALL(ctx, MatZeroRowsColumns(P->Se, P->nrows, P->rows, P->diag, NULL, NULL));
  PCALL(ctx, MatSetOption(P->Se, MAT_SPD, PETSC_TRUE));
  FCM_TRY(ctx, near_null_space(P, P->Se));
  /* 3. the KSP: defaults, then the options database */
  /* local (fcm allocations): agreed before the collective KSPCreate and PCMG setup below */
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, insert_options(P)));
  PCALL(ctx, KSPCreate(P->comm, &P->ksp));
  PCALL(ctx, KSPSetOptionsPrefix(P->ksp, P->prefix));
  PCALL(ctx, KSPSetOperators(P->ksp, P->Se, P->Se));
  PCALL(ctx, KSPSetType(P->ksp, KSPCG));
  {
    PC pc;
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    PCALL(ctx, PCSetType(pc, PCGAMG));
  }
  PCALL(ctx, KSPSetTolerances(P->ksp, P->opts.rtol, PETSC_DEFAULT, PETSC_DEFAULT,
                              P->opts.max_iterations));
  PCALL(ctx, KSPSetFromOptions(P->ksp));
  {
    PC pc;
    PetscBool mg = PETSC_FALSE;
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    PCALL(ctx, PetscObjectTypeCompare((PetscObject)pc, PCMG, &mg));
    /* the default on Hex20 box grids: fcm's geometric multigrid as PCMG (pcmg.c; CG + GAMG
     * needs hundreds of iterations there), GAMG when the mesh is no box grid */
    const int by_default =
        !mg && !pc_type_given(P) && fcm_mesh_element_type(P->mesh) == FCM_ELEMENT_HEX20;
    if (mg || by_default) {
      int levels = 0;
      if (by_default) PCALL(ctx, PCSetType(pc, PCMG));
      FCM_TRY(ctx, fcm__petsc_pcmg_setup(P, pc, P->is_con, by_default, &levels)); /* agreed */
      if (levels == 0) { /* not a box grid: GAMG */
        PCALL(ctx, PCSetType(pc, PCGAMG));
        PCALL(ctx, PCSetFromOptions(pc));
      }
    }
  }
  P->is_setup = 1;
  P->time_setup += fcm_wtime() - t0;
cleanup:
  return st;
}

/* ---------------------------------------------------------------- steps */

/* g: the prescribed values at time t on the owned constrained DOFs, 0 elsewhere. */
static fcm_status constraint_values(fcm_petsc_problem *P, double t)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const double *X = fcm_mesh_coords(P->mesh);
  PCALL(ctx, VecSet(P->g, 0.0));
  for (fcm_index k = 0; k < P->ncon; k++) {
    const fcm_index d = P->con_dof[k];
    if (P->copy_owner[d / 3] != P->rank) continue;
    double u[3];
    fcm_motion_eval(&P->motions[P->con_motion[k]], X + 3 * P->con_node[k], t, u, NULL);
    PCALL(ctx,
          VecSetValue(P->g, 3 * P->perm[d / 3] + P->con_comp[k], u[P->con_comp[k]], INSERT_VALUES));
  }
  PCALL(ctx, VecAssemblyBegin(P->g));
  PCALL(ctx, VecAssemblyEnd(P->g));
cleanup:
  return st;
}

static fcm_status energies(fcm_petsc_problem *P, fcm_petsc_step_info *info)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  PetscScalar e = 0.0;
  PCALL(ctx, MatMult(P->K, P->u, P->w));
  PCALL(ctx, VecDot(P->u, P->w, &e));
  info->elastic_energy = 0.5 * e;
  PCALL(ctx, VecDot(P->f, P->u, &e));
  info->external_work = e;
  info->kinetic_energy = 0.0;
  if (P->M) {
    PCALL(ctx, MatMult(P->M, P->v, P->w));
    PCALL(ctx, VecDot(P->v, P->w, &e));
    info->kinetic_energy = 0.5 * e;
  }
cleanup:
  return st;
}

fcm_status fcm_petsc_problem_step(fcm_petsc_problem *P, fcm_petsc_step_info *info)
{
  fcm_status st = FCM_OK;
  fcm_petsc_step_info si;
  memset(&si, 0, sizeof si);
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm,
                                !P->is_setup ? fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__,
                                                          __func__, "petsc: step before setup")
                                             : FCM_OK));
  const double h = P->opts.dt, t1 = P->t + h;
  double t0 = fcm_wtime();
  /* b = f (+ M/h^2 (u + h v)) - S g, then b = diag g on the constrained rows */
  FCM_TRY(ctx, constraint_values(P, t1));
  PCALL(ctx, VecCopy(P->f, P->b));
  if (P->M) {
    PCALL(ctx, VecWAXPY(P->x, h, P->v, P->u));
    PCALL(ctx, MatMult(P->M, P->x, P->w));
    PCALL(ctx, VecAXPY(P->b, 1.0 / (h * h), P->w));
  }
  PCALL(ctx, MatMult(P->S, P->g, P->w));
  PCALL(ctx, VecAXPY(P->b, -1.0, P->w));
  {
    PetscScalar *bb = NULL;
    const PetscScalar *gg = NULL;
    PCALL(ctx, VecGetArray(P->b, &bb));
    PCALL(ctx, VecGetArrayRead(P->g, &gg));
    for (PetscInt k = 0; k < P->nrows; k++) {
      const PetscInt r = P->rows[k] - 3 * P->first;
      bb[r] = P->diag * gg[r];
    }
    PCALL(ctx, VecRestoreArrayRead(P->g, &gg));
    PCALL(ctx, VecRestoreArray(P->b, &bb));
  }
  si.time_rhs = fcm_wtime() - t0;
  /* solve */
  t0 = fcm_wtime();
  KSPConvergedReason reason;
  PetscInt its = 0;
  PetscReal rnorm = 0.0;
  PCALL(ctx, KSPSolve(P->ksp, P->b, P->x)); /* zero initial guess (preonly needs it) */
  PCALL(ctx, KSPGetConvergedReason(P->ksp, &reason));
  PCALL(ctx, KSPGetIterationNumber(P->ksp, &its));
  PCALL(ctx, KSPGetResidualNorm(P->ksp, &rnorm));
  si.time_solve = fcm_wtime() - t0;
  si.iterations = (int)its;
  si.reason = (int)reason;
  si.residual = rnorm;
  P->total_iterations += its;
  if (reason < 0) {
    KSPType kt = NULL;
    PC pc;
    PCType pt = NULL;
    KSPGetType(P->ksp, &kt);
    KSPGetPC(P->ksp, &pc);
    PCGetType(pc, &pt);
    FCM_CHECK(0, ctx, FCM_ERR_NOT_CONVERGED,
              "petsc: t = %g: KSP %s with PC %s did not converge: %s (KSPConvergedReason %d) "
              "after %d iterations, residual norm %g (rtol %g); change the solver with "
              "-ksp_type / -pc_type or solver.petsc_options",
              t1, kt ? kt : "?", pt ? pt : "?", KSPConvergedReasons[reason], (int)reason, (int)its,
              (double)rnorm, P->opts.rtol);
  }
  /* accept: v = (u1 - u0)/h (dynamic), u = u1 */
  if (P->M) {
    PCALL(ctx, VecWAXPY(P->w, -1.0, P->u, P->x));
    PCALL(ctx, VecScale(P->w, 1.0 / h));
    PCALL(ctx, VecCopy(P->w, P->v));
  }
  PCALL(ctx, VecCopy(P->x, P->u));
  P->t = t1;
  P->steps++;
  si.time = P->t;
  FCM_TRY(ctx, energies(P, &si));
  if (info) *info = si;
cleanup:
  return st;
}

/* ---------------------------------------------------------------- queries */

fcm_index fcm_petsc_problem_num_dofs(const fcm_petsc_problem *P)
{
  return P ? P->n : 0;
}

const fcm_space *fcm_petsc_problem_space(const fcm_petsc_problem *P)
{
  return P ? P->space : NULL;
}

fcm_status fcm_petsc_problem_geometry_kept(const fcm_petsc_problem *P, fcm_index *num_cells,
                                           const fcm_index **cells, fcm_index *num_triangles,
                                           const fcm_index **triangles)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P && num_cells && cells && num_triangles && triangles, P ? P->ctx : NULL, FCM_ERR_ARG,
            "petsc: NULL argument (problem, num_cells, cells, num_triangles, triangles)");
  *num_cells = P->kept_cells ? P->geom_cells_kept : 0;
  *num_triangles = P->kept_tris ? P->geom_tris_kept : 0;
  *cells = P->kept_cells;
  *triangles = P->kept_tris;
cleanup:
  return st;
}

/* The whole vector x in the space's numbering into out (n values) on every process (to_zero:
 * on process 0 only; out is not read elsewhere). O(n) memory and traffic per receiving
 * process: for fcm_petsc_problem_get_state() (every process) and the checkpoint (process 0);
 * frames and energies do without it. Collective. */
static fcm_status gather(fcm_petsc_problem *P, Vec x, double *out, int to_zero)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  VecScatter sc = NULL;
  Vec all = NULL;
  const PetscScalar *a = NULL;
  if (to_zero)
    PCALL(ctx, VecScatterCreateToZero(x, &sc, &all));
  else
    PCALL(ctx, VecScatterCreateToAll(x, &sc, &all));
  PCALL(ctx, VecScatterBegin(sc, x, all, INSERT_VALUES, SCATTER_FORWARD));
  PCALL(ctx, VecScatterEnd(sc, x, all, INSERT_VALUES, SCATTER_FORWARD));
  if (to_zero && P->rank != 0) goto cleanup;
  PCALL(ctx, VecGetArrayRead(all, &a));
  for (fcm_index k = 0; k < P->ncopy; k++)
    for (int i = 0; i < 3; i++)
      out[3 * k + i] = a[3 * P->perm[k] + i];
  PCALL(ctx, VecRestoreArrayRead(all, &a));
cleanup:
  VecScatterDestroy(&sc);
  VecDestroy(&all);
  return st;
}

fcm_status fcm_petsc_problem_get_state(fcm_petsc_problem *P, double *u, double *v)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  if (u) FCM_TRY(P->ctx, gather(P, P->u, u, 0));
  if (v) FCM_TRY(P->ctx, gather(P, P->v, v, 0));
cleanup:
  return st;
}

fcm_status fcm_petsc_problem_get_info(fcm_petsc_problem *P, fcm_petsc_info *info)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P && info, NULL, FCM_ERR_ARG, "petsc: NULL problem or info");
  fcm_ctx *ctx = P->ctx;
  memset(info, 0, sizeof *info);
  info->size = P->size;
  info->rank = P->rank;
  info->partition = P->size == 1 && P->opts.partition == FCM_PETSC_PARTITION_AUTO
                        ? FCM_PETSC_PARTITION_ORDERED
                        : P->partition;
  info->num_dofs = P->n;
  info->local_dofs = 3 * (fcm_index)P->nlocal;
  info->local_elements = P->nelem_own;
  long long ne = (long long)P->nelem_own, mx = 0, mn = 0;
  MPI_Allreduce(&ne, &mx, 1, MPI_LONG_LONG, MPI_MAX, P->comm);
  MPI_Allreduce(&ne, &mn, 1, MPI_LONG_LONG, MPI_MIN, P->comm);
  info->max_local_elements = (fcm_index)mx;
  info->min_local_elements = (fcm_index)mn;
  if (P->M && P->is_setup) { /* 1_x^T M 1_x */
    PetscScalar *a = NULL, m = 0.0;
    PCALL(ctx, VecGetArray(P->x, &a));
    for (PetscInt i = 0; i < 3 * P->nlocal; i++)
      a[i] = i % 3 == 0 ? 1.0 : 0.0;
    PCALL(ctx, VecRestoreArray(P->x, &a));
    PCALL(ctx, MatMult(P->M, P->x, P->w));
    PCALL(ctx, VecDot(P->x, P->w, &m));
    info->mass = m;
  }
  info->time_rules = P->time_rules;
  info->time_assembly = P->time_assembly;
  info->time_setup = P->time_setup;
  PetscLogDouble mem = 0.0;
  PCALL(ctx, PetscMemoryGetCurrentUsage(&mem));
  info->memory_local = mem;
  MPI_Allreduce(&info->memory_local, &info->memory_total, 1, MPI_DOUBLE, MPI_SUM, P->comm);
  if (P->Se) {
    MatInfo mi; /* values and column indices of the stored nonzeros (mi.memory is not kept) */
    PCALL(ctx, MatGetInfo(P->Se, MAT_GLOBAL_SUM, &mi));
    info->matrix_memory = mi.nz_allocated * (double)(sizeof(PetscScalar) + sizeof(PetscInt));
  }
  info->geometry_cells = P->geom_cells;
  info->geometry_triangles = P->geom_tris;
  info->geometry_cells_kept = P->geom_cells_kept;
  info->geometry_triangles_kept = P->geom_tris_kept;
  info->geometry_bytes = P->geom_bytes;
  info->geometry_bytes_kept = P->geom_bytes_kept;
  MPI_Allreduce(&info->geometry_bytes_kept, &info->max_geometry_bytes_kept, 1, MPI_DOUBLE, MPI_MAX,
                P->comm);
  info->steps = P->steps;
  info->total_iterations = P->total_iterations;
  snprintf(info->options_prefix, sizeof info->options_prefix, "%s", P->prefix);
  if (P->ksp) {
    KSPType kt = NULL;
    PCType pt = NULL;
    PC pc;
    PCALL(ctx, KSPGetType(P->ksp, &kt));
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    PCALL(ctx, PCGetType(pc, &pt));
    snprintf(info->ksp_type, sizeof info->ksp_type, "%s", kt ? kt : "");
    snprintf(info->pc_type, sizeof info->pc_type, "%s", pt ? pt : "");
    if (pt && (!strcmp(pt, PCLU) || !strcmp(pt, PCCHOLESKY))) {
      MatSolverType mst = NULL;
      PCALL(ctx, PCFactorGetMatSolverType(pc, &mst));
      snprintf(info->factor_package, sizeof info->factor_package, "%s", mst ? mst : "");
    }
  }
cleanup:
  return st;
}

/* ---------------------------------------------------------------- the integrator's backend */

/* fcm_petsc_simulation_create(): every process runs the scene's ordinary fcm_simulation (its
 * fcm_integrator: Newton, line search, time stepping, every effect) on a space whose rules
 * carry points on the process's own cells; the integrator sums the partial assemblies through
 * newton_reduce() and solves its eliminated Newton system through newton_factor() and
 * newton_solve() (lib/src/solve/solve_backend.h). The problem object P serves as the backend:
 * partition, DOF ownership and numbering, the MATMPIAIJ, the vectors and the KSP. */

static void newton_release(void *user)
{
  fcm_petsc_problem *P = user;
  if (P && --P->refs == 0) fcm_petsc_problem_destroy(&P);
}

/* fcm__petsc_agree(), remembering a failure it reported (every process then knows it). */
static fcm_status newton_agree(fcm_petsc_problem *P, fcm_status st)
{
  return fcm__petsc_problem_agree(P, st);
}

/* Sum over the processes: reduced on process 0 and broadcast, so every process holds the same
 * bits (MPI_Allreduce need not give them for more than two processes). */
static fcm_status newton_reduce(void *user, fcm_status st, double *values, fcm_index count)
{
  fcm_petsc_problem *P = user;
  const double t0 = MPI_Wtime();
  const clock_t c0 = clock();
  st = newton_agree(P, st);
  if (st != FCM_OK) return st;
  P->traffic.reduces++;
  P->traffic.reduce_values += (long long)count;
  P->traffic.reduce_bytes += (long long)count * (long long)sizeof(double);
  P->traffic.reduce_large += P->n > 0 && count > P->n; /* the rules build: no space yet */
  for (fcm_index k = 0; k < count;) {
    const int m = count - k > (1 << 26) ? (1 << 26) : (int)(count - k);
    int rc = MPI_Reduce(P->rank == 0 ? MPI_IN_PLACE : values + k, values + k, m, MPI_DOUBLE,
                        MPI_SUM, 0, P->comm);
    if (rc == MPI_SUCCESS) rc = MPI_Bcast(values + k, m, MPI_DOUBLE, 0, P->comm);
    if (rc != MPI_SUCCESS)
      return fcm__error(P->ctx, FCM_ERR_INTERNAL, __FILE__, __LINE__, __func__,
                        "petsc: MPI_Reduce / MPI_Bcast of %d values failed (error %d)", m, rc);
    k += m;
  }
  P->traffic.time_reduce += MPI_Wtime() - t0;
  P->traffic.cpu_reduce += (double)(clock() - c0) / CLOCKS_PER_SEC;
  return FCM_OK;
}

/* The eliminated Newton matrix into the MATMPIAIJ: each process adds its PARTIAL eliminated
 * matrix H (solve/solve_backend.h) with ADD_VALUES, row by row, skipping the all-zero rows (so a
 * process sends only the rows its cells touch, plus the base on its own rows); the entries of rows
 * another process owns go through PETSc's stash at the assembly. The constrained rows are
 * checked against the contract (zero but for the owner's diagonal). The KSP (CG, or MINRES for a
 * possibly indefinite matrix, unless -ksp_type says otherwise) is set up on the sum.
 * Order of the additions: an entry's own contribution first, then the received ones in the
 * order the stash's messages are processed (MatStashScatterGetMesg_BTS, PETSc 3.18: by
 * MPI_Waitsome, i.e. arrival). With 2 processes every entry has at most one sender, so the
 * sums are the same bits in every run; with 3 or more, an entry that two other processes both
 * touch may be summed in another order from run to run (round-off). */
static fcm_status newton_factor(void *user, const fcm_csr *H, const unsigned char *is_con, int psd,
                                int *failed)
{
  fcm_petsc_problem *P = user;
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_index *rp = fcm_csr_row_ptr(H);
  const int *ci = fcm_csr_col_idx(H);
  const double *hv = fcm_csr_values_read(H);
  PetscInt *cols = NULL;
  fcm_index maxrow = 0, nrows = 0, ncols = 0;
  *failed = 0;
  /* H has the rows of the space's local copies (a local space: own and ghost cells'; a full
   * space: every DOF), global columns */
  fcm_csr_get_size(H, &nrows, &ncols, NULL);
  FCM_CHECK(ncols == P->n && nrows == fcm__space_num_rows(P->space), ctx, FCM_ERR_INTERNAL,
            "petsc: a Newton matrix of %lld x %lld for a backend of %lld DOFs and %lld rows (an "
            "integrator used after a cut replaced it)",
            (long long)nrows, (long long)ncols, (long long)P->n,
            (long long)fcm__space_num_rows(P->space));
  const double t0 = MPI_Wtime();
  const clock_t c0 = clock();
  for (fcm_index i = 0; i < nrows; i++)
    maxrow = FCM_MAX(maxrow, rp[i + 1] - rp[i]);
  cols = fcm__calloc(ctx, (size_t)maxrow + 1, sizeof *cols);
  st = cols ? FCM_OK
            : fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
                         "petsc: out of memory (a row of %lld entries)", (long long)maxrow);
  if (st == FCM_OK) {
    PetscErrorCode ierr = MatZeroEntries(P->S);
    if (ierr) st = fcm__petsc_error(ctx, ierr, "MatZeroEntries", __FILE__, __LINE__, __func__);
  }
  for (fcm_index r = 0; st == FCM_OK && r < nrows; r++) {
    const fcm_index d = fcm__space_row_dof(P->space, r), k = d / 3;
    const int own = P->copy_owner[k] == P->rank;
    const PetscInt row = 3 * P->perm[k] + d % 3;
    const PetscInt len = (PetscInt)(rp[r + 1] - rp[r]);
    const double *v = hv + rp[r];
    int nonzero = 0;
    for (PetscInt j = 0; j < len; j++) {
      const int c = ci[rp[r] + j];
      if (v[j] != 0.0) {
        nonzero = 1;
        if (is_con[d] && (c != d || !own)) {
          st = fcm__error(ctx, FCM_ERR_INTERNAL, __FILE__, __LINE__, __func__,
                          "petsc: the partial Newton matrix has %g at (%lld, %lld) of the "
                          "constrained DOF %lld (only its owner's diagonal may be non-zero)",
                          v[j], (long long)d, (long long)c, (long long)d);
          break;
        }
      }
      cols[j] = 3 * P->perm[c / 3] + c % 3;
    }
    if (st != FCM_OK || !nonzero) continue;
    PetscErrorCode ierr = MatSetValues(P->S, 1, &row, len, cols, v, ADD_VALUES);
    if (ierr) st = fcm__petsc_error(ctx, ierr, "MatSetValues", __FILE__, __LINE__, __func__);
    if (own) {
      P->traffic.matrix_values_local += len;
    } else {
      P->traffic.matrix_values_sent += len;
      P->traffic.matrix_rows_sent++;
      P->traffic.matrix_bytes_sent +=
          (long long)len * (long long)(2 * sizeof(PetscInt) + sizeof(PetscScalar));
    }
  }
  st = newton_agree(P, st);
  if (st != FCM_OK) {
    /* every process is here (the failure is agreed): flush the rows already handed to PETSc's
     * stash, which MatZeroEntries would not clear, so no later matrix receives them */
    if (!MatAssemblyBegin(P->S, MAT_FINAL_ASSEMBLY)) MatAssemblyEnd(P->S, MAT_FINAL_ASSEMBLY);
    goto cleanup;
  }
  PCALL(ctx, MatAssemblyBegin(P->S, MAT_FINAL_ASSEMBLY));
  PCALL(ctx, MatAssemblyEnd(P->S, MAT_FINAL_ASSEMBLY));
  P->traffic.matrices++;
  P->traffic.time_matrix += MPI_Wtime() - t0;
  P->traffic.cpu_matrix += (double)(clock() - c0) / CLOCKS_PER_SEC;
  PCALL(ctx, MatSetOption(P->S, MAT_SPD, psd ? PETSC_TRUE : PETSC_FALSE));
  if (P->direct && !P->pc_type_set) {
    PC pc;
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    PCType cur = NULL;
    PCALL(ctx, PCGetType(pc, &cur));
    const PCType want = psd ? PCCHOLESKY : PCLU;
    if (!cur || strcmp(cur, want) != 0) { /* a new factor PC: MUMPS again, unless the user chose */
      PetscBool has = PETSC_FALSE;
      PCALL(ctx, PCSetType(pc, want));
      PCALL(ctx, PetscOptionsHasName(NULL, P->prefix, "-pc_factor_mat_solver_type", &has));
      if (!has) PCALL(ctx, PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
      PCALL(ctx, PCSetFromOptions(pc));
    }
  } else if (!P->direct && !P->ksp_type_set) {
    PCALL(ctx, KSPSetType(P->ksp, psd ? KSPCG : KSPMINRES));
  }
  {
    /* -pc_type mg: fcm's multigrid levels (pcmg.c), once per KSP (a cut makes a new one); they
     * depend on the space only, not on the constraints or on H */
    PC pc;
    PetscBool mg = PETSC_FALSE;
    PetscInt nl = 0;
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    PCALL(ctx, PetscObjectTypeCompare((PetscObject)pc, PCMG, &mg));
    if (mg) PCALL(ctx, PCMGGetLevels(pc, &nl));
    if (mg && nl < 2) FCM_TRY(ctx, fcm__petsc_pcmg_setup(P, pc, NULL, 0, NULL)); /* agreed */
  }
  PCALL(ctx, KSPSetOperators(P->ksp, P->S, P->S));
  PCALL(ctx, KSPSetUp(P->ksp));
  FCM_TRY(ctx, fcm__petsc_pcmg_smoothers_setup(P)); /* pcmg.c: PCMG's block smoothers, now */
  P->factors++;
  P->factored = 1;
cleanup:
  fcm__free(ctx, cols);
  return st;
}

/* Solve H x = b with the KSP of newton_factor() (zero initial guess); x gathered on every
 * process. A KSP that does not converge is a soft failure (the integrator retries). */
static fcm_status newton_solve(void *user, const double *b, double *x, int *iterations, int *failed)
{
  fcm_petsc_problem *P = user;
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  PetscScalar *bb = NULL;
  const PetscScalar *a = NULL;
  KSPConvergedReason reason;
  PetscInt its = 0;
  *failed = 0;
  *iterations = 0;
  FCM_CHECK(P->factored, ctx, FCM_ERR_INTERNAL,
            "petsc: a solve without a Newton matrix given since the backend was (re)built (an "
            "integrator used after a cut replaced it)");
  PCALL(ctx, VecGetArray(P->b, &bb));
  for (fcm_index k = 0; k < P->ncopy; k++) {
    if (P->copy_owner[k] != P->rank) continue;
    const PetscInt r = 3 * (P->perm[k] - P->first);
    for (int i = 0; i < 3; i++)
      bb[r + i] = b[3 * k + i];
  }
  PCALL(ctx, VecRestoreArray(P->b, &bb));
  bb = NULL;
  /* a zero initial guess also under -ksp_initial_guess_nonzero: the last direction is no state
   * of the run (a checkpoint does not hold it), so a resumed run takes the same iterations */
  PCALL(ctx, VecZeroEntries(P->x));
  PCALL(ctx, KSPSolve(P->ksp, P->b, P->x));
  PCALL(ctx, KSPGetConvergedReason(P->ksp, &reason));
  PCALL(ctx, KSPGetIterationNumber(P->ksp, &its));
  *iterations = (int)its;
  P->total_iterations += its;
  P->steps++;
  if (reason < 0) {
    *failed = 1;
    return FCM_OK;
  }
  if (!P->to_all) PCALL(ctx, VecScatterCreateToAll(P->x, &P->to_all, &P->all));
  PCALL(ctx, VecScatterBegin(P->to_all, P->x, P->all, INSERT_VALUES, SCATTER_FORWARD));
  PCALL(ctx, VecScatterEnd(P->to_all, P->x, P->all, INSERT_VALUES, SCATTER_FORWARD));
  PCALL(ctx, VecGetArrayRead(P->all, &a));
  for (fcm_index k = 0; k < P->ncopy; k++)
    for (int i = 0; i < 3; i++)
      x[3 * k + i] = a[3 * P->perm[k] + i];
  PCALL(ctx, VecRestoreArrayRead(P->all, &a));
cleanup:
  if (bb) VecRestoreArray(P->b, &bb);
  return st;
}

/* A 64-bit FNV-1a hash of n bytes, continuing h. */
static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
  const unsigned char *b = data;
  for (size_t i = 0; i < n; i++)
    h = (h ^ b[i]) * 0x100000001b3ULL;
  return h;
}

/* The space's topology (DOF count, elements, their cells, pieces and DOFs) is replicated: it
 * must be the same on every process (a cut's pieces and DOF copies come from the
 * classification, which every process makes for every cell). FCM_ERR_INTERNAL on every
 * process, naming the counts, when it is not. Collective. */
static fcm_status check_topology(fcm_petsc_problem *P)
{
  const fcm_space *s = P->space;
  uint64_t h = 0xcbf29ce484222325ULL;
  const long long counts[2] = {(long long)s->num_dofs, (long long)s->num_elems};
  h = fnv1a(h, counts, sizeof counts);
  h = fnv1a(h, s->elem_cell, sizeof *s->elem_cell * (size_t)s->num_elems);
  h = fnv1a(h, s->elem_piece, sizeof *s->elem_piece * (size_t)s->num_elems);
  h = fnv1a(h, s->elem_dof, sizeof *s->elem_dof * (size_t)s->num_elems * (size_t)s->nn);
  /* min and max over the processes of (DOFs, elements, hash): min of x and of -x */
  long long mine[6] = {counts[0],  counts[1],  (long long)(h >> 1),
                       -counts[0], -counts[1], -(long long)(h >> 1)};
  long long all[6];
  if (MPI_Allreduce(mine, all, 6, MPI_LONG_LONG, MPI_MIN, P->comm) != MPI_SUCCESS)
    return fcm__error(P->ctx, FCM_ERR_INTERNAL, __FILE__, __LINE__, __func__,
                      "petsc: MPI_Allreduce of the topology check failed");
  if (all[0] != -all[3] || all[1] != -all[4] || all[2] != -all[5])
    return fcm__error(P->ctx, FCM_ERR_INTERNAL, __FILE__, __LINE__, __func__,
                      "petsc: the space's DOF numbering differs between the processes (DOFs "
                      "%lld to %lld, elements %lld to %lld, topology hashes %s; this process: "
                      "%lld DOFs): the replicated classification of the cells (and of a cut's "
                      "pieces) must agree on every process",
                      all[0], -all[3], all[1], -all[4], all[2] != -all[5] ? "differ" : "agree",
                      counts[0]);
  return FCM_OK;
}

/* The backend's PETSc objects and numbering for P->space: number the DOFs, check that every
 * process has the same topology, create the matrix, vectors and KSP. Agrees on st first and
 * on the result last. Collective. */
static fcm_status newton_build(fcm_petsc_problem *P, fcm_status st, const fcm_space *space)
{
  fcm_ctx *ctx = P->ctx;
  st = newton_agree(P, st);
  if (st != FCM_OK) return st; /* another process failed */
  /* the rules build's classification (rules_exchange()) is over */
  FCM_FREE(ctx, P->classifier);
  FCM_FREE(ctx, P->remote);
  P->space = (fcm_space *)space; /* borrowed: P->borrowed_space */
  P->mesh = fcm_space_mesh(space);
  st = own_active_cells(P);
  if (st == FCM_OK) st = number_dofs(P);
  /* the simulation's local space (run.c: own cells and a ghost layer on both sides of the
   * interface) narrowed to what this process needs, as phase 1's: its own cells and the cells
   * using a copy it owns (every owned row complete for create_matrix(), every row its own
   * cells' assembly touches present) */
  if (st == FCM_OK && P->space->is_local) st = localize_space(P);
  if (st == FCM_OK) { /* the integrator's copy of the ownership (fcm__backend.owned) */
    P->owned_dof = fcm__calloc(ctx, (size_t)P->n + 1, 1);
    if (!P->owned_dof)
      st = fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
                      "petsc: out of memory (%lld owned flags)", (long long)P->n);
    for (fcm_index d = 0; st == FCM_OK && d < P->n; d++)
      P->owned_dof[d] = P->copy_owner[d / 3] == P->rank;
  }
  FCM_TRY(ctx, newton_agree(P, st));
  FCM_TRY(ctx, newton_agree(P, check_topology(P)));
  st = create_matrix(P, &P->S); /* agrees on its local part */
  if (st == FCM_OK) st = create_vectors(P);
  if (st == FCM_OK) st = near_null_space(P, P->S);
  /* local (the options database), then KSPCreate: agreed between */
  if (st == FCM_OK) st = newton_agree(P, insert_options(P));
  if (st == FCM_OK) {
    PetscBool has = PETSC_FALSE;
    PC pc;
    PCALL(ctx, KSPCreate(P->comm, &P->ksp));
    PCALL(ctx, KSPSetOptionsPrefix(P->ksp, P->prefix));
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    if (P->direct) { /* the scene's "direct": MUMPS, the PETSc backend's direct option */
      PCALL(ctx, KSPSetType(P->ksp, KSPPREONLY));
      PCALL(ctx, PCSetType(pc, PCCHOLESKY));
      PCALL(ctx, PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    } else {
      PCALL(ctx, KSPSetType(P->ksp, KSPCG));
      PCALL(ctx, PCSetType(pc, PCGAMG));
    }
    PCALL(ctx, KSPSetTolerances(P->ksp, P->opts.rtol, PETSC_DEFAULT, PETSC_DEFAULT,
                                P->opts.max_iterations));
    PCALL(ctx, KSPSetFromOptions(P->ksp));
    PCALL(ctx, PetscOptionsHasName(NULL, P->prefix, "-ksp_type", &has));
    P->ksp_type_set = has == PETSC_TRUE;
    PCALL(ctx, PetscOptionsHasName(NULL, P->prefix, "-pc_type", &has));
    P->pc_type_set = has == PETSC_TRUE;
    /* GAMG (PETSc 3.18) reuses the previous tangent's interpolation by default: the solves
     * would then depend on the run's history, and a resumed run (a fresh KSP) would differ
     * from the uninterrupted one at round-off. A new hierarchy for each tangent, as the serial
     * solvers do, unless -pc_gamg_reuse_interpolation says otherwise (no effect on other PCs). */
    PCALL(ctx, PetscOptionsHasName(NULL, P->prefix, "-pc_gamg_reuse_interpolation", &has));
    if (!has) PCALL(ctx, PCGAMGSetReuseInterpolation(pc, PETSC_FALSE));
  }
cleanup:
  if (P->agreed_fail) return st; /* failed in an agreement above: every process knows */
  return newton_agree(P, st);
}

/* Release what newton_build() made (a cut rebuilds it for the new space). */
static void newton_unbuild(fcm_petsc_problem *P)
{
  fcm_ctx *ctx = P->ctx;
  KSPDestroy(&P->ksp);
  MatDestroy(&P->S);
  Vec *vs[] = {&P->f, &P->u, &P->v, &P->b, &P->x, &P->g, &P->w, &P->all};
  for (size_t i = 0; i < sizeof vs / sizeof vs[0]; i++)
    VecDestroy(vs[i]);
  VecScatterDestroy(&P->to_all);
  fcm__free(ctx, P->copy_owner);
  fcm__free(ctx, P->perm);
  fcm__free(ctx, P->owned_dof);
  P->copy_owner = NULL;
  P->perm = NULL;
  P->owned_dof = NULL;
  P->n = P->ncopy = 0;
  P->nlocal = P->first = 0;
}

static fcm_status newton_setup(void *user, fcm_status st, const fcm_space *space,
                               fcm__backend *out);
static fcm_status newton_finish(void *user, fcm_status st);

/* The backend handed to an integrator: P itself, one more reference. */
static void newton_backend(fcm_petsc_problem *P, fcm__backend *b)
{
  memset(b, 0, sizeof *b);
  b->user = P;
  b->root = P->rank == 0;
  b->rank = P->rank;
  b->nprocs = P->size;
  b->owned = P->owned_dof;
  b->reduce = newton_reduce;
  b->factor = newton_factor;
  b->solve = newton_solve;
  b->destroy = newton_release;
  b->setup = newton_setup;
  b->finish = newton_finish;
  P->refs++;
}

/* fcm__backend.setup: the integrator of the simulation's space (every process reached here
 * unless one failed: the agreement first), and the integrator of a cut's new space, gets this
 * backend, (re)built for its DOF numbering (ownership, PETSc numbering, matrix, vectors, KSP,
 * scatter); the old integrator keeps its reference until it is destroyed, and its factor / solve
 * refuse to run on the rebuilt objects (newton_factor() checks the matrix size, newton_solve() that
 * a matrix was given since). */
static fcm_status newton_setup(void *user, fcm_status st, const fcm_space *space, fcm__backend *out)
{
  fcm_petsc_problem *P = user;
  st = newton_agree(P, st);
  if (st != FCM_OK) return st;
  newton_unbuild(P);
  P->factored = 0;
  st = newton_build(P, FCM_OK, space);
  if (st != FCM_OK) return st;
  newton_backend(P, out);
  return FCM_OK;
}

/* fcm__backend.finish: agree unless a failure was agreed already (on every process). */
static fcm_status newton_finish(void *user, fcm_status st)
{
  fcm_petsc_problem *P = user;
  if (P->agreed_fail) return st;
  return newton_agree(P, st);
}

/* The backend object of a simulation (fcm__petsc_backend_create(), petsc_backend.h): P with the
 * settings the scene's solver section gives, before any space exists. */
fcm_status fcm__petsc_backend_create(fcm_ctx *ctx, MPI_Comm comm, fcm_status st,
                                     const fcm__petsc_backend_options *o, fcm_petsc_problem **out)
{
  fcm_petsc_problem *P = NULL;
  st = new_problem(ctx, comm, st, &P);
  *out = P;
  if (P) P->borrowed_space = 1;
  FCM_TRY(ctx, st);
  P->opts = fcm_petsc_options_default();
  set_prefix(P);
  P->opts.partition = o->partition;
  P->direct = o->direct;
  P->opts.rtol = o->rtol;
  P->opts.max_iterations = o->max_iterations;
  if (o->petsc_options) {
    size_t len = strlen(o->petsc_options);
    P->petsc_options = fcm__calloc(ctx, len + 1, 1);
    if (P->petsc_options)
      memcpy(P->petsc_options, o->petsc_options, len);
    else
      st = FCM_ERR_ALLOC;
  }
  P->mat = o->mat;
  st = newton_agree(P, st);
cleanup:
  return st;
}

fcm_status fcm__petsc_backend_partition(fcm_petsc_problem *P, fcm_status st, const fcm_mesh *mesh,
                                        const fcm_geometry *geom, unsigned char **mask,
                                        fcm__backend *backend, fcm__rules_exchange *exchange)
{
  fcm_ctx *ctx = P->ctx;
  FCM_TRY(ctx, newton_agree(P, st));
  /* the partition of the candidate cells, as fcm_petsc_problem_create() makes it */
  P->mesh = mesh;
  st = partition_cells(P, geom, mask);
  P->mesh = NULL;
  FCM_TRY(ctx, st);
  /* the rules build's classification exchange: each process classifies the cells of
   * P->classifier (rules_exchange()); newton_build() frees both once the space exists */
  exchange->remote = P->remote;
  exchange->exchange = rules_exchange;
  exchange->user = P;
  memset(backend, 0, sizeof *backend);
  backend->user = P;
  backend->root = P->rank == 0;
  backend->rank = P->rank;
  backend->nprocs = P->size;
  backend->reduce = newton_reduce;
  backend->setup = newton_setup;
  backend->finish = newton_finish;
cleanup:
  return st;
}

void fcm__petsc_backend_release(fcm_petsc_problem *P)
{
  newton_release(P);
}

int fcm__petsc_backend_info(const fcm__backend *b, fcm_petsc_traffic *traffic, MPI_Comm *comm)
{
  if (!b || b->reduce != newton_reduce) return 0;
  const fcm_petsc_problem *P = b->user;
  if (traffic) *traffic = P->traffic;
  if (comm) *comm = P->comm;
  return 1;
}

void fcm__petsc_problem_adopt_mesh(fcm_petsc_problem *P, fcm_mesh *mesh)
{
  P->own_mesh = mesh;
}

/* ---------------------------------------------------------------- output */

/* The frames' nodes (local part of the first frame's setup): the nodes of the own cells and,
 * per node, the PETSc block of the DOF copy fcm_space_node_field() shows there
 * (fcm__space_node_field_dofs(): the largest support among the node's copies, which may be a
 * copy no own or ghost cell uses: the scatter fetches it from its owner like any other). */
static fcm_status frame_nodes(fcm_petsc_problem *P, const unsigned char *keep, PetscInt **blocks)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  fcm_index *dofs = NULL;
  FCM_FREE(ctx, P->frame_nodes); /* a failed first frame's */
  FCM_TRY(ctx, fcm__space_piece_nodes(P->space, keep, &P->frame_np, &P->frame_nodes));
  FCM_ALLOC(ctx, P->frame_np + 1, dofs);
  FCM_ALLOC(ctx, P->frame_np + 1, *blocks);
  FCM_TRY(ctx, fcm__space_node_field_dofs(P->space, P->frame_np, P->frame_nodes, dofs));
  for (fcm_index i = 0; i < P->frame_np; i++) {
    FCM_CHECK(dofs[i] >= 0, ctx, FCM_ERR_INTERNAL, "petsc: node %lld of an own cell has no DOF",
              (long long)P->frame_nodes[i]);
    (*blocks)[i] = P->perm[dofs[i] / 3];
  }
cleanup:
  fcm__free(ctx, dofs);
  return st;
}

/* The frames' scatter from the global vectors to frame_vec (3 values per frame node).
 * Collective (VecScatterCreate). */
static fcm_status frame_scatter(fcm_petsc_problem *P, const PetscInt *blocks)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  IS from = NULL;
  VecDestroy(&P->frame_vec); /* a failed first frame's */
  /* the local objects first, agreed, so that no process fails before the collective scatter
   * the others wait in */
  PetscErrorCode ierr =
      ISCreateBlock(PETSC_COMM_SELF, 3, (PetscInt)P->frame_np, blocks, PETSC_COPY_VALUES, &from);
  if (ierr) st = fcm__petsc_error(ctx, ierr, "ISCreateBlock", __FILE__, __LINE__, __func__);
  if (st == FCM_OK) {
    ierr = VecCreateSeq(PETSC_COMM_SELF, 3 * (PetscInt)P->frame_np, &P->frame_vec);
    if (ierr) st = fcm__petsc_error(ctx, ierr, "VecCreateSeq", __FILE__, __LINE__, __func__);
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  PCALL(ctx, VecScatterCreate(P->u, from, P->frame_vec, NULL, &P->frame_sc));
cleanup:
  ISDestroy(&from);
  return st;
}

/* The frame values of x (3 per frame node) into out. Collective. */
static fcm_status frame_values(fcm_petsc_problem *P, Vec x, double *out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const PetscScalar *a = NULL;
  PCALL(ctx, VecScatterBegin(P->frame_sc, x, P->frame_vec, INSERT_VALUES, SCATTER_FORWARD));
  PCALL(ctx, VecScatterEnd(P->frame_sc, x, P->frame_vec, INSERT_VALUES, SCATTER_FORWARD));
  PCALL(ctx, VecGetArrayRead(P->frame_vec, &a));
  for (fcm_index i = 0; i < 3 * P->frame_np; i++)
    out[i] = a[i];
  PCALL(ctx, VecRestoreArrayRead(P->frame_vec, &a));
cleanup:
  return st;
}

/* Each process writes the piece of its own cells from the values of the nodes of those cells
 * alone (frame_setup(): a scatter of O(piece) values, not the whole state). */
fcm_status fcm_petsc_problem_write_frame(fcm_petsc_problem *P, const char *dir, const char *stem)
{
  fcm_status st = FCM_OK;
  double *u = NULL, *v = NULL;
  unsigned char *keep = NULL;
  PetscInt *blocks = NULL;
  char path[4096];
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  FCM_CHECK(dir && stem && *stem, ctx, FCM_ERR_ARG, "petsc: write_frame: NULL directory or stem");
  const fcm_index nc = fcm_mesh_num_cells(P->mesh);
  const int first = !P->frame_sc; /* the same on every process: every frame is collective */
  keep = fcm__calloc(ctx, (size_t)nc + 1, 1);
  st = keep ? FCM_OK : FCM_ERR_ALLOC;
  for (fcm_index c = 0; keep && c < nc; c++)
    keep[c] = P->cell_owner[c] == P->rank;
  if (st == FCM_OK && first) st = frame_nodes(P, keep, &blocks);
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  if (first) FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, frame_scatter(P, blocks)));
  if (st == FCM_OK) {
    u = fcm__calloc(ctx, 3 * (size_t)P->frame_np + 1, sizeof *u);
    v = fcm__calloc(ctx, 3 * (size_t)P->frame_np + 1, sizeof *v);
    if (!u || !v) st = FCM_ERR_ALLOC;
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  FCM_TRY(ctx, frame_values(P, P->u, u)); /* collective */
  FCM_TRY(ctx, frame_values(P, P->v, v));
  snprintf(path, sizeof path, "%s/%s_%d.vtu", dir, stem, P->rank);
  st = fcm__space_write_vtu_piece_values(P->space, keep, P->frame_np, P->frame_nodes, u, v, P->rank,
                                         path);
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  if (P->rank == 0) {
    snprintf(path, sizeof path, "%s/%s.pvtu", dir, stem);
    st = fcm__write_pvtu(ctx, path, stem, P->size, 1, 0);
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
cleanup:
  if (P) {
    fcm__free(P->ctx, u);
    fcm__free(P->ctx, v);
    fcm__free(P->ctx, keep);
    fcm__free(P->ctx, blocks);
  }
  return st;
}

/* ---------------------------------------------------------------- checkpoints */

/* File layout (host byte order, written by process 0): the magic line, then int64 n, elements,
 * steps, kind; double t, dt; n doubles u, n doubles v (the space's DOF numbering, so any
 * process count reads it). */
static const char ckpt_magic[16] = "fcm-petsc-ck-1\n";

fcm_status fcm_petsc_problem_write_checkpoint(fcm_petsc_problem *P, const char *path)
{
  fcm_status st = FCM_OK;
  double *u = NULL, *v = NULL;
  fcm_atomic_file *af = NULL;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  st = path ? FCM_OK
            : fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                         "petsc: checkpoint: NULL path");
  if (st == FCM_OK) { /* the state is gathered on process 0 only (O(n) there) */
    const size_t len = P->rank == 0 ? (size_t)P->n + 1 : 1;
    u = fcm__calloc(ctx, len, sizeof *u);
    v = fcm__calloc(ctx, len, sizeof *v);
    if (!u || !v) st = FCM_ERR_ALLOC;
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  FCM_TRY(ctx, gather(P, P->u, u, 1));
  FCM_TRY(ctx, gather(P, P->v, v, 1));
  if (P->rank == 0) {
    st = fcm_atomic_file_open(ctx, path, &af);
    if (st == FCM_OK) {
      FILE *f = fcm_atomic_file_stream(af);
      const int64_t head[4] = {(int64_t)P->n, (int64_t)P->space->num_elems, (int64_t)P->steps,
                               (int64_t)P->opts.kind};
      const double times[2] = {P->t, P->opts.dt};
      int ok = fwrite(ckpt_magic, 1, sizeof ckpt_magic, f) == sizeof ckpt_magic &&
               fwrite(head, sizeof head, 1, f) == 1 && fwrite(times, sizeof times, 1, f) == 1 &&
               fwrite(u, sizeof *u, (size_t)P->n, f) == (size_t)P->n &&
               fwrite(v, sizeof *v, (size_t)P->n, f) == (size_t)P->n;
      if (!ok) {
        fcm_atomic_file_abort(&af);
        st = fcm__error(ctx, FCM_ERR_IO, __FILE__, __LINE__, __func__,
                        "petsc: checkpoint %s: write failed", path);
      } else {
        st = fcm_atomic_file_commit(&af);
      }
    }
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
cleanup:
  fcm_atomic_file_abort(&af);
  if (P) {
    fcm__free(P->ctx, u);
    fcm__free(P->ctx, v);
  }
  return st;
}

/* Read and check a checkpoint into u, v (n each), *t and *steps (every process reads). */
static fcm_status read_ckpt(fcm_petsc_problem *P, const char *path, double *u, double *v, double *t,
                            long long *steps)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  FILE *f = NULL;
  char magic[sizeof ckpt_magic];
  int64_t head[4];
  double times[2];
  FCM_CHECK(path, ctx, FCM_ERR_ARG, "petsc: checkpoint: NULL path");
  f = fopen(path, "rb");
  FCM_CHECK(f, ctx, FCM_ERR_IO, "petsc: checkpoint %s: cannot open it", path);
  FCM_CHECK(fread(magic, 1, sizeof magic, f) == sizeof magic &&
                memcmp(magic, ckpt_magic, sizeof magic) == 0,
            ctx, FCM_ERR_FORMAT, "petsc: checkpoint %s: not a PETSc-backend checkpoint of fcm",
            path);
  FCM_CHECK(fread(head, sizeof head, 1, f) == 1 && fread(times, sizeof times, 1, f) == 1, ctx,
            FCM_ERR_FORMAT, "petsc: checkpoint %s: truncated header", path);
  FCM_CHECK(head[0] == (int64_t)P->n && head[1] == (int64_t)P->space->num_elems &&
                head[3] == (int64_t)P->opts.kind && times[1] == P->opts.dt && head[2] >= 0,
            ctx, FCM_ERR_ARG,
            "petsc: checkpoint %s is of another problem: %lld DOFs, %lld elements, kind %lld, "
            "dt %g (this one: %lld, %lld, %d, %g)",
            path, (long long)head[0], (long long)head[1], (long long)head[3], times[1],
            (long long)P->n, (long long)P->space->num_elems, (int)P->opts.kind, P->opts.dt);
  FCM_CHECK(fread(u, sizeof *u, (size_t)P->n, f) == (size_t)P->n &&
                fread(v, sizeof *v, (size_t)P->n, f) == (size_t)P->n && fgetc(f) == EOF,
            ctx, FCM_ERR_FORMAT, "petsc: checkpoint %s: truncated or with trailing data", path);
  *t = times[0];
  *steps = (long long)head[2];
cleanup:
  if (f) fclose(f);
  return st;
}

fcm_status fcm_petsc_problem_read_checkpoint(fcm_petsc_problem *P, const char *path)
{
  fcm_status st = FCM_OK;
  double *u = NULL, *v = NULL, t = 0.0;
  long long steps = 0;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  u = fcm__calloc(ctx, (size_t)P->n + 1, sizeof *u);
  v = fcm__calloc(ctx, (size_t)P->n + 1, sizeof *v);
  st = u && v ? FCM_OK : FCM_ERR_ALLOC;
  if (st == FCM_OK)
    st = P->is_setup ? read_ckpt(P, path, u, v, &t, &steps)
                     : fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                                  "petsc: read_checkpoint before setup");
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  {
    PetscScalar *a = NULL, *b = NULL;
    PCALL(ctx, VecGetArray(P->u, &a));
    PCALL(ctx, VecGetArray(P->v, &b));
    for (fcm_index k = 0; k < P->ncopy; k++) {
      if (P->copy_owner[k] != P->rank) continue;
      const PetscInt r = 3 * (P->perm[k] - P->first);
      for (int i = 0; i < 3; i++) {
        a[r + i] = u[3 * k + i];
        b[r + i] = v[3 * k + i];
      }
    }
    PCALL(ctx, VecRestoreArray(P->u, &a));
    PCALL(ctx, VecRestoreArray(P->v, &b));
  }
  P->t = t;
  P->steps = steps;
cleanup:
  if (P) {
    fcm__free(P->ctx, u);
    fcm__free(P->ctx, v);
  }
  return st;
}

long long fcm_petsc_problem_step_count(const fcm_petsc_problem *P)
{
  return P ? P->steps : 0;
}
