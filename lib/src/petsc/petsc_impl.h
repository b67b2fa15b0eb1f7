/* petsc module (internal): the problem object both drivers share, the PETSc call macro and
 * the cross-process agreement. Only lib/src/petsc/ includes this (PETSc is touched in this
 * module only). */
#ifndef FCM_PETSC_IMPL_H
#define FCM_PETSC_IMPL_H

#include "fcm/petsc.h"

#include "core/core_impl.h"
#include "petsc/petsc_backend.h"
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"

#include <petscksp.h>
#include <petscmat.h>

#define FCM_PETSC_CUT_WEIGHT 4

struct fcm_petsc_problem {
  fcm_ctx *ctx;
  MPI_Comm comm;
  int size, rank;
  const fcm_mesh *mesh;
  fcm_material mat;
  fcm_petsc_options opts;
  char *petsc_options; /* copy */
  char prefix[32];     /* the KSP's options prefix, unique per problem ("fcm1_", ...) */
  fcm_petsc_partition partition;
  fcm_cell_rules *rules; /* this process's cells carry points */
  fcm_space *space;      /* phase 1: a local space (numbering replicated, topology of own +
                            ghost cells: localize_space()); phase 2: the simulation's (full) */
  fcm_assembly_workspace *aws;
  fcm_index n;           /* global DOFs */
  fcm_index ncopy;       /* n / 3 */
  int *cell_owner;       /* num_cells (-1: inactive) */
  unsigned char *weight; /* num_cells: partition weight of the candidate cells (0: none) */
  /* distributed classification (the rules build, rules_exchange()): the process that
   * intersects each cell (its owner; the cells no process owns round robin) and whether that
   * is another one; both freed after the build */
  int *classifier;
  unsigned char *remote;
  fcm_index num_classified; /* cells of the mesh partitioned (the length of both) */
  double time_classify;     /* seconds of this process in the rules build's exchange (waits) */
  int *copy_owner;          /* ncopy */
  PetscInt *perm;           /* ncopy: PETSc block index of each copy */
  PetscInt nlocal;          /* owned copies */
  PetscInt first;           /* first owned PETSc block index */
  fcm_index nelem_own;
  /* constraints: DOFs (space numbering), motion of each, node of each */
  fcm_index ncon;
  fcm_index *con_dof, *con_node;
  int *con_comp;
  int *con_motion;
  fcm_motion *motions;
  int num_motions;
  unsigned char *is_con; /* n */
  double gravity[3];
  int has_gravity;
  int is_setup;
  /* PETSc objects */
  Mat K, M, S, Se; /* stiffness, mass (dynamic), system, system eliminated */
  Vec f, u, v, b, x, g, w;
  KSP ksp;
  PetscInt *rows; /* owned constrained rows (PETSc indices) */
  PetscInt nrows;
  double diag;
  double t;
  long long steps, total_iterations;
  double time_rules, time_assembly, time_setup;
  /* the geometry the rules build read (phase 1 on several processes: the crop,
   * crop_geometry()): whole and kept counts, bytes; the kept cells' and triangles' original
   * ids (fcm_petsc_problem_geometry_kept(); NULL without a crop) */
  fcm_index geom_cells, geom_tris, geom_cells_kept, geom_tris_kept;
  double geom_bytes, geom_bytes_kept;
  fcm_index *kept_cells, *kept_tris;
  fcm_mesh *own_mesh; /* built from a scene (fcm_petsc_problem_create_from_scene) */
  fcm_geometry *own_geom;
  /* the integrator's backend (fcm_petsc_simulation_create()): the space is the simulation's
   * (borrowed, not destroyed); refs: the creator and the integrator; agreed_fail: an agree()
   * of this backend reported a failure (so this process must not start another one) */
  int borrowed_space;
  int refs;
  int agreed_fail;
  int ksp_type_set;  /* -ksp_type in the options database: keep it (else CG / MINRES) */
  int pc_type_set;   /* -pc_type in the options database: keep it */
  int direct;        /* the scene asks for a direct solver: MUMPS (Cholesky / LU) */
  long long factors; /* matrices given to the KSP */
  int factored;      /* a matrix was given to the KSP since the last (re)build (cuts) */
  VecScatter to_all;
  Vec all;
  fcm_petsc_traffic traffic; /* the integrator's backend (fcm_petsc_simulation_traffic()) */
  unsigned char *owned_dof;  /* n: 1 on the DOFs whose rows this process owns (newton_build) */
  /* phase-1 frames (fcm_petsc_problem_write_frame(), made at the first): the piece's nodes
   * (of the own cells, ascending) and a scatter of their node-field DOFs into frame_vec */
  fcm_index frame_np;
  fcm_index *frame_nodes;
  VecScatter frame_sc;
  Vec frame_vec;
};

/* A PETSc call: on failure, record its message as FCM_ERR_INTERNAL. */
#define PCALL(ctx, call)                                                                           \
  do {                                                                                             \
    PetscErrorCode ierr_ = (call);                                                                 \
    if (ierr_) {                                                                                   \
      st = fcm__petsc_error((ctx), ierr_, #call, __FILE__, __LINE__, __func__);                    \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)

/* The message of a failed PETSc call as FCM_ERR_INTERNAL (PCALL). */
fcm_status fcm__petsc_error(fcm_ctx *ctx, PetscErrorCode ierr, const char *call, const char *file,
                            int line, const char *func);

/* fcm__petsc_agree() on P's communicator; a failure is remembered (P->agreed_fail), so that a
 * process that learnt of it there does not start another agreement the others never meet. */
fcm_status fcm__petsc_problem_agree(fcm_petsc_problem *P, fcm_status st);

/* The shared steps of the two drivers, by file. */

/* petsc_init.c: P's options prefix ("fcm<k>_", k counting the problems this process made). */
void fcm__petsc_set_prefix(fcm_petsc_problem *P);

/* petsc_init.c: check the solver settings o (partition, rtol, max_iterations: the message names
 * the bad one) and make them P's (P->opts.solver), its options string copied into
 * P->petsc_options (P->opts.solver.petsc_options is then NULL). Local. */
fcm_status fcm__petsc_adopt_solver(fcm_petsc_problem *P, const fcm_petsc_solver_options *o);

/* petsc_partition.c: the candidate cells of geom (mesh P->mesh) partitioned over the processes
 * (P->cell_owner, P->weight, P->classifier, P->remote); *mask: this process's cells. Collective. */
fcm_status fcm__petsc_partition_cells(fcm_petsc_problem *P, const fcm_geometry *geom,
                                      unsigned char **mask);
/* petsc_partition.c: the classification exchange of the distributed rules build
 * (fcm__rules_exchange.exchange; user: P). Collective. */
fcm_status fcm__petsc_rules_exchange(void *user, fcm_status st, unsigned char *cls,
                                     double *fraction, double *volume, fcm__embed_counts *counts);
/* petsc_partition.c: the rules of the cells flagged in mask and the space's numbering. */
fcm_status fcm__petsc_build_space(fcm_petsc_problem *P, const fcm_geometry *geom,
                                  const unsigned char *mask);
/* petsc_partition.c: the part of geom this process's rules build reads (*crop NULL: all). */
fcm_status fcm__petsc_crop_geometry(fcm_petsc_problem *P, const fcm_geometry *geom,
                                    const unsigned char *mask, fcm_geometry **crop);
/* petsc_partition.c: check that every active cell of P->space has an owner and no inactive
 * one has (FCM_ERR_INTERNAL naming the first; local). */
fcm_status fcm__petsc_own_active_cells(fcm_petsc_problem *P);

/* petsc_numbering.c: the owner and PETSc index of every DOF copy (P->copy_owner, P->perm,
 * P->nlocal, P->first). Collective. */
fcm_status fcm__petsc_number_dofs(fcm_petsc_problem *P);
/* petsc_numbering.c: P->space narrowed to the own cells and those using an owned copy. */
fcm_status fcm__petsc_localize_space(fcm_petsc_problem *P);
/* petsc_numbering.c: a preallocated MATMPIAIJ (block size 3) of the owned rows. Collective. */
fcm_status fcm__petsc_create_matrix(fcm_petsc_problem *P, Mat *A);
/* petsc_numbering.c: the distributed vectors (P->f, u, v, b, x, g, w). Collective. */
fcm_status fcm__petsc_create_vectors(fcm_petsc_problem *P);
/* petsc_numbering.c: the rigid-body modes as A's near-null space. Collective. */
fcm_status fcm__petsc_near_null_space(fcm_petsc_problem *P, Mat A);

/* petsc_linear.c: a new problem on (a duplicate of) comm, st agreed first (see there). */
fcm_status fcm__petsc_new_problem(fcm_ctx *ctx, MPI_Comm comm, fcm_status st,
                                  fcm_petsc_problem **out);
/* petsc_linear.c: the problem's options string and the database's options under its prefix. */
fcm_status fcm__petsc_insert_options(fcm_petsc_problem *P);
/* petsc_linear.c: the distributed x in the space's numbering into out (n doubles) on every
 * process (to_zero: on process 0 only). Collective. */
fcm_status fcm__petsc_gather(fcm_petsc_problem *P, Vec x, double *out, int to_zero);

/* 1 when fcm's geometric multigrid may apply to the space: Hex8 or Hex20 elements (whether the
 * mesh is a box grid is found by fcm__petsc_pcmg_setup()). pcmg.c. */
int fcm__petsc_pcmg_grid(const fcm_space *space);

/* pc (of P's KSP, type PCMG) gets fcm's multigrid hierarchy (lib/src/mg) as its levels: the
 * prolongations as MATMPIAIJ (block size 3) in P's numbering, Galerkin coarse operators, and
 * defaults the options database overrides (Chebyshev + point-block Jacobi smoothers, redundant
 * Cholesky on the coarsest level); then PCSetFromOptions. constrained: P->n bytes in the space's
 * numbering (nonzero: an eliminated row), or NULL. optional: a space the hierarchy cannot be
 * built for (not a Hex8 / Hex20 box grid, a single level) is FCM_OK with *num_levels = 0 and pc
 * untouched (the caller's default applies). num_levels (may be NULL): the levels made.
 * @return FCM_OK, FCM_ERR_UNSUPPORTED (not a Hex8 / Hex20 box grid: named), FCM_ERR_ARG
 * (-pc_mg_levels that the hierarchy cannot give), FCM_ERR_ALLOC, FCM_ERR_INTERNAL (PETSc).
 * Collective on P->comm and agreed here (fcm__petsc_problem_agree()): a failure on one process
 * only (an allocation, ...) is returned on every process with its message, none waits in a
 * collective call. The levels' block smoothers (PCSHELL) agree in their setup (inside
 * KSPSetUp / PCSetUp, collective): a local failure there is a PETSc error on every process,
 * whose message carries the failing process's (P->agreed_fail set). pcmg.c. */
fcm_status fcm__petsc_pcmg_setup(fcm_petsc_problem *P, PC pc, const unsigned char *constrained,
                                 int optional, int *num_levels);

/* After KSPSetUp of P->ksp (PCMG with fcm's block smoothers; a no-op for any other PC): the
 * levels' block smoothers set up now (PCSetUp), each whose Galerkin matrix changed. PCSetUp_MG
 * sets a level's PC up at the first setup only; after that PETSc sets it up lazily inside
 * the next cycle, in a smoother's nested KSPSolve, which a failure there (agreed, on every
 * process) leaves inconsistent (seen: a crash in KSPDestroy). Collective; the same status on
 * every process. pcmg.c. */
fcm_status fcm__petsc_pcmg_smoothers_setup(fcm_petsc_problem *P);

#endif /* FCM_PETSC_IMPL_H */
