/* petsc module: the integrator's backend (fcm__backend, fem/fem_backend.h) and what the
 * layer that chooses it calls (petsc_backend.h): the sums over the processes, each process's
 * partial Newton matrix added into a MATMPIAIJ and solved with a KSP, the rebuild for a cut's
 * new space. */
#include "petsc/petsc_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* fcm_petsc_simulation_create(): every process runs the scene's ordinary fcm_simulation (its
 * fcm_integrator: Newton, line search, time stepping, every effect) on a space whose rules
 * carry points on the process's own cells; the integrator sums the partial assemblies through
 * newton_reduce() and solves its eliminated Newton system through newton_factor() and
 * newton_solve() (lib/src/fem/fem_backend.h). The problem object P serves as the backend:
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
 * matrix H (fem/fem_backend.h) with ADD_VALUES, row by row, skipping the all-zero rows (so a
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
  /* the rules build's classification (fcm__petsc_rules_exchange()) is over */
  FCM_FREE(ctx, P->classifier);
  FCM_FREE(ctx, P->remote);
  P->space = (fcm_space *)space; /* borrowed: P->borrowed_space */
  P->mesh = fcm_space_mesh(space);
  st = fcm__petsc_own_active_cells(P);
  if (st == FCM_OK) st = fcm__petsc_number_dofs(P);
  /* the simulation's local space (run.c: own cells and a ghost layer on both sides of the
   * interface) narrowed to what this process needs, as phase 1's: its own cells and the cells
   * using a copy it owns (every owned row complete for fcm__petsc_create_matrix(), every row its
   * own cells' assembly touches present) */
  if (st == FCM_OK && P->space->is_local) st = fcm__petsc_localize_space(P);
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
  st = fcm__petsc_create_matrix(P, &P->S); /* agrees on its local part */
  if (st == FCM_OK) st = fcm__petsc_create_vectors(P);
  if (st == FCM_OK) st = fcm__petsc_near_null_space(P, P->S);
  /* local (the options database), then KSPCreate: agreed between */
  if (st == FCM_OK) st = newton_agree(P, fcm__petsc_insert_options(P));
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
    PCALL(ctx, KSPSetTolerances(P->ksp, P->opts.solver.rtol, PETSC_DEFAULT, PETSC_DEFAULT,
                                P->opts.solver.max_iterations));
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
  st = fcm__petsc_new_problem(ctx, comm, st, &P);
  *out = P;
  if (P) P->borrowed_space = 1;
  FCM_TRY(ctx, st);
  P->opts = fcm_petsc_options_default();
  fcm__petsc_set_prefix(P);
  P->direct = o->direct;
  st = fcm__petsc_adopt_solver(P, &o->solver);
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
  st = fcm__petsc_partition_cells(P, geom, mask);
  P->mesh = NULL;
  FCM_TRY(ctx, st);
  /* the rules build's classification exchange: each process classifies the cells of
   * P->classifier (fcm__petsc_rules_exchange()); newton_build() frees both once the space exists */
  exchange->remote = P->remote;
  exchange->exchange = fcm__petsc_rules_exchange;
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
