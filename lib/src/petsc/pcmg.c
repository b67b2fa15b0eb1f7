/* petsc/pcmg: fcm's geometric multigrid hierarchy (lib/src/mg, cut-aware 2x2x2 coarsening of
 * Hex8 / Hex20 box grids, Hex20 first to the Hex8 space of the same elements) as the levels of
 * PETSc's PCMG.
 *
 * Every process builds the whole hierarchy's prolongations (fcm__mg_transfers_create(): the
 * topology is replicated, as the space and the DOF numbering are) and inserts the rows it owns
 * into one MATMPIAIJ per level (block size 3). Numbering and ownership:
 * - level 0 (the finest) is the problem's PETSc numbering (3 perm[copy] + component, rows
 *   owned by the copy's owner);
 * - a coarse copy is owned by the owner of the finer copy with the lowest global index among
 *   the finer copies it interpolates to (weight != 0); the coarse copies are numbered owner by
 *   owner (contiguous per process), by fcm's coarse copy index within one owner;
 * - a coarse copy no finer copy interpolates to is left out (its Galerkin row would be zero).
 * The fine constrained rows (eliminated symmetrically, diagonal kept) stay in P, so P stays
 * injective (as in fcm_mg_create()) and every Galerkin matrix P^T A P is positive definite;
 * the coarse levels then see the Dirichlet rows as springs of the eliminated diagonal rather
 * than decoupling them as fcm_mg does.
 * PETSc numbers its levels from the coarsest (0) to the finest; fcm from the finest. */
#include "fcm/solve.h"
#include "mg/mg_impl.h"
#include "petsc/petsc_impl.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Set `-<prefix><name> value` unless the database has the key already. */
static fcm_status default_option(fcm_ctx *ctx, const char *prefix, const char *name,
                                 const char *value)
{
  fcm_status st = FCM_OK;
  char key[128];
  PetscBool has = PETSC_FALSE;
  snprintf(key, sizeof key, "-%s%s", prefix, name);
  PCALL(ctx, PetscOptionsHasName(NULL, NULL, key, &has));
  if (!has) PCALL(ctx, PetscOptionsSetValue(NULL, key, value));
cleanup:
  return st;
}

/* ---------------------------------------------------------------- block smoother */

/* The default smoother's PC on a level: fcm's additive Schwarz (fcm_schwarz: clamped
 * eigen-inverses of dense blocks, the inverse diagonal elsewhere) with the blocks of fcm_mg's
 * block smoothing. Each block goes to one process, the owner of its lowest-numbered DOF, whole:
 * the process works on its owned rows and the other processes' rows of its blocks (the
 * subdomain `is`, sorted global indices), whose matrix it extracts at each setup
 * (MatCreateSubMatrices); apply: gather r on the subdomain, z_sub = S r_sub, add z_sub back into
 * z (ASM's "basic" form, so the smoother is symmetric). */
typedef struct block_pc {
  fcm_ctx *ctx;
  int *agreed_fail; /* the problem's (P->agreed_fail): set when a setup agreed on a failure */
  PetscInt n;       /* subdomain size */
  IS is;            /* the subdomain's global rows, sorted */
  fcm_index nb;
  fcm_index *ptr, *dofs; /* blocks in subdomain numbering */
  Mat *sub;              /* the subdomain matrix (1) */
  Vec xs, ys;            /* subdomain vectors (sequential) */
  VecScatter sc;         /* level vector -> subdomain */
  fcm_schwarz *S;
} block_pc;

static PetscErrorCode block_pc_error(const block_pc *b)
{
  SETERRQ(PETSC_COMM_SELF, PETSC_ERR_LIB, "fcm block smoother: %s", fcm_ctx_error_message(b->ctx));
}

/* The local part of the first setup: the subdomain vectors (sequential). */
static fcm_status block_pc_vectors(block_pc *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->ctx;
  PCALL(ctx, VecCreateSeq(PETSC_COMM_SELF, b->n, &b->xs));
  PCALL(ctx, VecDuplicate(b->xs, &b->ys));
cleanup:
  if (st) {
    VecDestroy(&b->xs);
    VecDestroy(&b->ys);
  }
  return st;
}

/* The local part of every setup: fcm_schwarz on the subdomain matrix Ad (sequential). */
static fcm_status block_pc_factor(block_pc *b, Mat Ad)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = b->ctx;
  const PetscInt *ia = NULL, *ja = NULL;
  const PetscScalar *v = NULL;
  PetscInt n = 0;
  PetscBool done = PETSC_FALSE;
  fcm_index *rp = NULL;
  int *ci = NULL;
  fcm_csr *C = NULL;
  fcm_schwarz_destroy(&b->S); /* no stale smoother if this setup fails */
  PCALL(ctx, MatGetRowIJ(Ad, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
  FCM_CHECK(done && n == b->n, ctx, FCM_ERR_INTERNAL,
            "petsc: fcm block smoother: the subdomain matrix has %d rows, the subdomain %d", (int)n,
            (int)b->n);
  FCM_ALLOC(ctx, n + 1, rp);
  FCM_ALLOC(ctx, ia[n] + 1, ci);
  for (PetscInt i = 0; i <= n; i++)
    rp[i] = ia[i];
  for (PetscInt p = 0; p < ia[n]; p++)
    ci[p] = (int)ja[p];
  FCM_TRY(ctx, fcm_csr_create(ctx, n, n, rp, ci, FCM_CSR_GENERAL, &C));
  PCALL(ctx, MatSeqAIJGetArrayRead(Ad, &v));
  memcpy(fcm_csr_values(C), v, sizeof *v * (size_t)ia[n]);
  MatSeqAIJRestoreArrayRead(Ad, &v);
  FCM_TRY(ctx, fcm_schwarz_create(ctx, C, b->nb, b->ptr, b->dofs, NULL, &b->S));
cleanup:
  if (done) MatRestoreRowIJ(Ad, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done);
  fcm_csr_destroy(&C);
  fcm__free(ctx, rp);
  fcm__free(ctx, ci);
  return st;
}

/* PCSetUp of the shell (inside KSPSetUp / PCSetUp of PCMG: collective). Its collective calls
 * (MatCreateSubMatrices, VecScatterCreate) are met by every process: each local part before
 * one ends in fcm__petsc_agree(), so a failure on one process only (an allocation, ...) is
 * returned as a PETSc error on every process, with the failing process's message (the others
 * name it), and no process waits in a collective call the failing one never makes. The apply
 * fails only on arguments (the setup was agreed): no agreement there. */
static PetscErrorCode block_pc_setup(PC pc)
{
  block_pc *b = NULL;
  Mat A = NULL;
  PetscCall(PCShellGetContext(pc, &b));
  PetscCall(PCGetOperators(pc, NULL, &A));
  const MPI_Comm comm = PetscObjectComm((PetscObject)pc);
  fcm_status st = FCM_OK;
  PetscCall(MatCreateSubMatrices(A, 1, &b->is, &b->is,
                                 b->sub ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX, &b->sub));
  if (!b->sc) {
    st = fcm__petsc_agree(b->ctx, comm, b->xs ? FCM_OK : block_pc_vectors(b));
    if (st) {
      *b->agreed_fail = 1;
      return block_pc_error(b);
    }
    Vec x = NULL;
    PetscCall(MatCreateVecs(A, &x, NULL));
    PetscCall(VecScatterCreate(x, b->is, b->xs, NULL, &b->sc));
    PetscCall(VecDestroy(&x));
  }
  st = fcm__petsc_agree(b->ctx, comm, block_pc_factor(b, b->sub[0]));
  if (st) {
    *b->agreed_fail = 1;
    return block_pc_error(b);
  }
  return 0;
}

static PetscErrorCode block_pc_apply(PC pc, Vec x, Vec y)
{
  block_pc *b = NULL;
  const PetscScalar *xa = NULL;
  PetscScalar *ya = NULL;
  PetscCall(PCShellGetContext(pc, &b));
  PetscCall(VecScatterBegin(b->sc, x, b->xs, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(b->sc, x, b->xs, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGetArrayRead(b->xs, &xa));
  PetscCall(VecGetArray(b->ys, &ya));
  const fcm_status st = fcm_schwarz_apply(b->S, xa, ya);
  PetscCall(VecRestoreArray(b->ys, &ya));
  PetscCall(VecRestoreArrayRead(b->xs, &xa));
  if (st) return block_pc_error(b);
  PetscCall(VecSet(y, 0.0));
  PetscCall(VecScatterBegin(b->sc, b->ys, y, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecScatterEnd(b->sc, b->ys, y, ADD_VALUES, SCATTER_REVERSE));
  return 0;
}

static void block_pc_free(block_pc *b)
{
  if (!b) return;
  fcm_schwarz_destroy(&b->S);
  if (b->sub) MatDestroySubMatrices(1, &b->sub);
  VecDestroy(&b->xs);
  VecDestroy(&b->ys);
  VecScatterDestroy(&b->sc);
  ISDestroy(&b->is);
  fcm__free(b->ctx, b->ptr);
  fcm__free(b->ctx, b->dofs);
  fcm__free(b->ctx, b);
}

static PetscErrorCode block_pc_destroy(PC pc)
{
  block_pc *b = NULL;
  PetscCall(PCShellGetContext(pc, &b));
  block_pc_free(b);
  return 0;
}

static int cmp_petscint(const void *a, const void *b)
{
  const PetscInt x = *(const PetscInt *)a, y = *(const PetscInt *)b;
  return (x > y) - (x < y);
}

/* Position of g in the sorted a[0..n). */
static PetscInt find_sorted(const PetscInt *a, PetscInt n, PetscInt g)
{
  PetscInt lo = 0, hi = n;
  while (lo < hi) {
    const PetscInt mid = lo + (hi - lo) / 2;
    if (a[mid] < g)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* The level's smoother PC becomes the block smoother of the level's blocks (T, level l, in
 * fcm's level numbering): gidx / owner of the level's copies, first its first owned block row,
 * nloc the owned copies. */
static fcm_status block_pc_set(fcm_petsc_problem *P, PC spc, const fcm__mg_transfers *T, int l,
                               const PetscInt *gidx, const int *owner, PetscInt first,
                               PetscInt nloc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  PetscInt *rows = NULL;
  block_pc *b = fcm__calloc(ctx, 1, sizeof *b);
  FCM_CHECK(b, ctx, FCM_ERR_ALLOC, "petsc: out of memory (block smoother)");
  b->ctx = ctx;
  b->agreed_fail = &P->agreed_fail;
  const fcm_index nb = T->num_blocks[l], *bp = T->block_ptr[l], *bd = T->block_dofs[l];
  /* this process's blocks: those whose lowest global DOF it owns */
  FCM_ALLOC(ctx, nb + 1, b->ptr);
  FCM_ALLOC(ctx, bp[nb] + 1, b->dofs);
  FCM_ALLOC(ctx, 3 * nloc + bp[nb] + 1, rows);
  PetscInt nr = 0;
  for (PetscInt i = 0; i < 3 * nloc; i++)
    rows[nr++] = 3 * first + i;
  fcm_index q = 0;
  for (fcm_index k = 0; k < nb; k++) {
    PetscInt low = -1;
    int who = -1;
    for (fcm_index p = bp[k]; p < bp[k + 1]; p++) {
      const fcm_index K = bd[p] / 3;
      if (gidx[K] < 0) continue;
      const PetscInt g = 3 * gidx[K] + bd[p] % 3;
      if (low < 0 || g < low) low = g, who = owner[K];
    }
    if (who != P->rank) continue;
    for (fcm_index p = bp[k]; p < bp[k + 1]; p++) {
      const fcm_index K = bd[p] / 3;
      if (gidx[K] < 0) continue;
      const PetscInt g = 3 * gidx[K] + bd[p] % 3;
      b->dofs[q++] = g; /* global for now */
      if (owner[K] != P->rank) rows[nr++] = g;
    }
    b->ptr[++b->nb] = q;
  }
  qsort(rows, (size_t)nr, sizeof *rows, cmp_petscint);
  PetscInt nu = 0;
  for (PetscInt i = 0; i < nr; i++)
    if (i == 0 || rows[i] != rows[nu - 1]) rows[nu++] = rows[i];
  b->n = nu;
  for (fcm_index p = 0; p < q; p++)
    b->dofs[p] = find_sorted(rows, nu, (PetscInt)b->dofs[p]);
  PCALL(ctx, ISCreateGeneral(PETSC_COMM_SELF, nu, rows, PETSC_COPY_VALUES, &b->is));
  PCALL(ctx, PCSetType(spc, PCSHELL));
  PCALL(ctx, PCShellSetContext(spc, b));
  PCALL(ctx, PCShellSetName(spc, "fcm vertex/cell block Schwarz (fcm_schwarz)"));
  PCALL(ctx, PCShellSetSetUp(spc, block_pc_setup));
  PCALL(ctx, PCShellSetApply(spc, block_pc_apply));
  PCALL(ctx, PCShellSetDestroy(spc, block_pc_destroy));
  b = NULL;
cleanup:
  block_pc_free(b);
  fcm__free(ctx, rows);
  return st;
}

fcm_status fcm__petsc_pcmg_smoothers_setup(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  PC pc = NULL;
  PetscBool mg = PETSC_FALSE;
  PetscInt nl = 0;
  PCALL(ctx, KSPGetPC(P->ksp, &pc));
  PCALL(ctx, PetscObjectTypeCompare((PetscObject)pc, PCMG, &mg));
  if (!mg) goto cleanup;
  PCALL(ctx, PCMGGetLevels(pc, &nl));
  for (PetscInt l = 1; l < nl; l++) { /* PETSc's level 0 is the coarsest (no smoother) */
    KSP sk = NULL;
    PC spc = NULL;
    PetscBool shell = PETSC_FALSE;
    PCALL(ctx, PCMGGetSmoother(pc, l, &sk));
    PCALL(ctx, KSPGetPC(sk, &spc));
    PCALL(ctx, PetscObjectTypeCompare((PetscObject)spc, PCSHELL, &shell));
    /* a no-op when the level's matrix did not change since the last setup; else
     * block_pc_setup(), agreed (the same on every process: the levels are) */
    if (shell) PCALL(ctx, PCSetUp(spc));
  }
cleanup:
  return st;
}

int fcm__petsc_pcmg_grid(const fcm_space *space)
{
  const fcm_element_type t = fcm_mesh_element_type(fcm_space_mesh(space));
  return t == FCM_ELEMENT_HEX8 || t == FCM_ELEMENT_HEX20;
}

/* -pc_mg_levels under P's prefix, if given: *max_levels (local). */
static fcm_status levels_option(fcm_petsc_problem *P, int *max_levels)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  PetscInt lv = 0;
  PetscBool has = PETSC_FALSE;
  char key[64];
  snprintf(key, sizeof key, "-%spc_mg_levels", P->prefix);
  PCALL(ctx, PetscOptionsGetInt(NULL, NULL, key, &lv, &has));
  if (has) {
    FCM_CHECK(lv >= 1 && lv <= 32, ctx, FCM_ERR_ARG,
              "petsc: -pc_mg_levels %d outside [1, 32] (fcm's multigrid levels)", (int)lv);
    *max_levels = (int)lv;
  }
cleanup:
  return st;
}

/* The coarse copies of level l + 1 (local): each owned by the owner of the lowest global finer
 * copy it interpolates to (minf: that finer copy; -1: none, the copy is left out), numbered
 * contiguously per owner (gidx_c; -1 left out); this process's count and first index. count:
 * P->size + 1 scratch. */
static void coarse_numbering(const fcm_petsc_problem *P, const fcm__mg_transfers *T, int l,
                             const PetscInt *gidx, const int *owner, PetscInt *count,
                             fcm_index *minf, int *owner_c, PetscInt *gidx_c, PetscInt *nloc_c,
                             PetscInt *first_c)
{
  const fcm_index nf = T->n[l] / 3, nc = T->n[l + 1] / 3;
  const fcm_index *pp = T->P_ptr[l];
  const int *pc_ = T->P_col[l];
  const double *pv = T->P_val[l];
  for (fcm_index K = 0; K < nc; K++)
    minf[K] = -1, owner_c[K] = -1;
  for (fcm_index k = 0; k < nf; k++) {
    if (gidx[k] < 0) continue;
    for (fcm_index p = pp[3 * k]; p < pp[3 * k + 1]; p++) {
      const fcm_index K = pc_[p] / 3;
      if (pv[p] == 0.0) continue;
      if (minf[K] < 0 || gidx[k] < gidx[minf[K]]) minf[K] = k;
    }
  }
  memset(count, 0, sizeof *count * (size_t)(P->size + 1));
  for (fcm_index K = 0; K < nc; K++)
    if (minf[K] >= 0) owner_c[K] = owner[minf[K]], count[owner_c[K] + 1]++;
  for (int r = 0; r < P->size; r++)
    count[r + 1] += count[r];
  *nloc_c = count[P->rank + 1] - count[P->rank];
  *first_c = count[P->rank];
  for (fcm_index K = 0; K < nc; K++)
    gidx_c[K] = minf[K] >= 0 ? count[owner_c[K]]++ : -1;
}

/* The preallocation of level l's prolongation (local): per owned row its entries in the
 * diagonal block (dnz, zeroed by the caller) and the others (onz); returns the widest row. */
static int prolongation_counts(const fcm_petsc_problem *P, const fcm__mg_transfers *T, int l,
                               const PetscInt *gidx, const int *owner, const PetscInt *gidx_c,
                               PetscInt first, PetscInt first_c, PetscInt nloc_c, PetscInt *dnz,
                               PetscInt *onz)
{
  const fcm_index nf = T->n[l] / 3;
  const fcm_index *pp = T->P_ptr[l];
  const int *pc_ = T->P_col[l];
  int width = 0;
  for (fcm_index k = 0; k < nf; k++) {
    if (gidx[k] < 0 || owner[k] != P->rank) continue;
    for (int c = 0; c < 3; c++) {
      const PetscInt r = 3 * (gidx[k] - first) + c;
      for (fcm_index p = pp[3 * k + c]; p < pp[3 * k + c + 1]; p++) {
        const PetscInt J = gidx_c[pc_[p] / 3];
        if (J < 0) continue;
        if (J >= first_c && J < first_c + nloc_c)
          dnz[r]++;
        else
          onz[r]++;
      }
      width = FCM_MAX(width, (int)(pp[3 * k + c + 1] - pp[3 * k + c]));
    }
  }
  return width;
}

/* The owned rows of level l's prolongation into Pm (local: MatSetValues; cols and vals hold
 * the widest row). */
static fcm_status prolongation_fill(const fcm_petsc_problem *P, const fcm__mg_transfers *T, int l,
                                    const PetscInt *gidx, const int *owner, const PetscInt *gidx_c,
                                    PetscInt *cols, PetscScalar *vals, Mat Pm)
{
  fcm_status st = FCM_OK;
  const fcm_index nf = T->n[l] / 3;
  const fcm_index *pp = T->P_ptr[l];
  const int *pc_ = T->P_col[l];
  const double *pv = T->P_val[l];
  for (fcm_index k = 0; k < nf; k++) {
    if (gidx[k] < 0 || owner[k] != P->rank) continue;
    for (int c = 0; c < 3; c++) {
      const PetscInt row = 3 * gidx[k] + c;
      PetscInt m = 0;
      for (fcm_index p = pp[3 * k + c]; p < pp[3 * k + c + 1]; p++) {
        const PetscInt J = gidx_c[pc_[p] / 3];
        if (J < 0) continue;
        cols[m] = 3 * J + pc_[p] % 3;
        vals[m++] = pv[p];
      }
      PCALL(P->ctx, MatSetValues(Pm, 1, &row, m, cols, vals, INSERT_VALUES));
    }
  }
cleanup:
  return st;
}

/* Distributed failures: every call here that communicates (PCMGSetLevels, the
 * prolongations' MatCreate .. MatAssemblyEnd, PCSetFromOptions) is preceded by an agreement
 * (AGREE: fcm__petsc_problem_agree()) ending the local work before it, and every exit passes
 * through one agreement (cleanup) unless a failure was agreed already. A process failing in a
 * local part (an allocation, a local PETSc call) jumps to cleanup, whose agreement meets the
 * one the others wait in before their next collective call: every process returns the failing
 * process's status and message, none is left in a collective call. The collective calls are
 * made by every process in the same order (the hierarchy is the same everywhere). */
#define AGREE()                                                                                    \
  do {                                                                                             \
    st = fcm__petsc_problem_agree(P, st);                                                          \
    if (st) {                                                                                      \
      agreed = 1;                                                                                  \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)

/* The setup stays one function (about 150 lines) on purpose: its agreements (AGREE) and the
 * collective calls between them must come in the same order on every process, and reading them
 * in one place shows that they do; the local work of each level is in the helpers above. */
fcm_status fcm__petsc_pcmg_setup(fcm_petsc_problem *P, PC pc, const unsigned char *constrained,
                                 int optional, int *num_levels)
{
  fcm_status st = FCM_OK;
  int agreed = 0; /* a failure was agreed (every process knows it) */
  fcm_ctx *ctx = P->ctx;
  fcm__mg_transfers *T = NULL;
  PetscInt *gidx = NULL, *gidx_c = NULL, *dnz = NULL, *onz = NULL, *cols = NULL;
  int *owner = NULL, *owner_c = NULL;
  fcm_index *minf = NULL;
  PetscInt *count = NULL;
  PetscScalar *vals = NULL;
  Mat Pm = NULL;
  int max_levels = 20;
  const char *prefix = P->prefix;
  if (num_levels) *num_levels = 0;
  FCM_TRY(ctx, levels_option(P, &max_levels));
  if (optional && !fcm__petsc_pcmg_grid(P->space)) goto cleanup;
  if (!fcm__petsc_pcmg_grid(P->space)) {
    const fcm_element_type t = fcm_mesh_element_type(fcm_space_mesh(P->space));
    const fcm_element_info *info = fcm_element_get_info(t);
    st = fcm__error(ctx, FCM_ERR_UNSUPPORTED, __FILE__, __LINE__, __func__,
                    "petsc: -pc_type mg uses fcm's geometric multigrid, which needs a Hex8 or "
                    "Hex20 box grid; the mesh has %s elements (use -pc_type gamg)",
                    info ? info->name : "unknown");
    goto cleanup;
  }
  /* the coarsest level: at most 2000 DOFs (a redundant Cholesky on every process), and an
   * eighth of the space's at most, so that a small space gets two levels too */
  const fcm_index n0 = fcm_space_num_dofs(P->space);
  const fcm_index coarse = FCM_MIN(2000, FCM_MAX(1, n0 / 8));
  st = fcm__mg_transfers_create(ctx, P->space, constrained, max_levels, coarse, &T);
  if (optional && st == FCM_ERR_UNSUPPORTED) { /* not a box grid: the caller keeps its PC */
    fcm_ctx_error_clear(ctx);
    st = FCM_OK;
    goto cleanup;
  }
  if (st == FCM_ERR_UNSUPPORTED) {
    char why[256];
    snprintf(why, sizeof why, "%s", fcm_ctx_error_message(ctx));
    st = fcm__error(ctx, st, __FILE__, __LINE__, __func__,
                    "petsc: -pc_type mg uses fcm's geometric multigrid, which needs a Hex8 or "
                    "Hex20 box grid (fcm_mesh_create_box()): %s (use -pc_type gamg)",
                    why);
  }
  if (st) goto cleanup;
  const int L = T->num_levels;
  if (optional && L < 2) goto cleanup;
  FCM_CHECK(L >= 2, ctx, FCM_ERR_ARG,
            "petsc: fcm's multigrid has a single level here (%lld DOFs, max_levels %d): use a "
            "direct solver or more levels",
            (long long)T->n[0], max_levels);
  /* level 0: the problem's numbering */
  FCM_ALLOC(ctx, P->ncopy + 1, gidx);
  FCM_ALLOC(ctx, P->ncopy + 1, owner);
  for (fcm_index k = 0; k < P->ncopy; k++)
    gidx[k] = P->perm[k], owner[k] = P->copy_owner[k];
  PetscInt nloc = P->nlocal, first = P->first;
  FCM_ALLOC(ctx, P->size + 1, count);
  AGREE();
  PCALL(ctx, PCMGSetLevels(pc, L, NULL));
  int blocks = 1; /* the default smoother's PC unless the options name one */
  {
    char key[64];
    PetscBool has = PETSC_FALSE;
    snprintf(key, sizeof key, "-%smg_levels_pc_type", prefix);
    PCALL(ctx, PetscOptionsHasName(NULL, NULL, key, &has));
    blocks = !has;
  }
  for (int l = 0; l + 1 < L; l++) {
    const fcm_index nc = T->n[l + 1] / 3;
    /* owners and numbering of the coarse copies */
    FCM_ALLOC(ctx, nc + 1, minf);
    FCM_ALLOC(ctx, nc + 1, owner_c);
    FCM_ALLOC(ctx, nc + 1, gidx_c);
    PetscInt nloc_c = 0, first_c = 0;
    coarse_numbering(P, T, l, gidx, owner, count, minf, owner_c, gidx_c, &nloc_c, &first_c);
    /* the matrix: owned rows */
    FCM_ALLOC(ctx, 3 * nloc + 1, dnz);
    FCM_ALLOC(ctx, 3 * nloc + 1, onz);
    const int width =
        prolongation_counts(P, T, l, gidx, owner, gidx_c, first, first_c, nloc_c, dnz, onz);
    FCM_ALLOC(ctx, width + 1, cols);
    FCM_ALLOC(ctx, width + 1, vals);
    AGREE(); /* the level's local part (and the finer level's smoother) */
    PCALL(ctx, MatCreate(P->comm, &Pm));
    PCALL(ctx, MatSetSizes(Pm, 3 * nloc, 3 * nloc_c, PETSC_DETERMINE, PETSC_DETERMINE));
    PCALL(ctx, MatSetType(Pm, MATMPIAIJ));
    PCALL(ctx, MatSetBlockSizes(Pm, 3, 3));
    PCALL(ctx, MatMPIAIJSetPreallocation(Pm, 0, dnz, 0, onz));
    FCM_TRY(ctx, prolongation_fill(P, T, l, gidx, owner, gidx_c, cols, vals, Pm));
    PCALL(ctx, MatAssemblyBegin(Pm, MAT_FINAL_ASSEMBLY));
    PCALL(ctx, MatAssemblyEnd(Pm, MAT_FINAL_ASSEMBLY));
    PCALL(ctx, PCMGSetInterpolation(pc, L - 1 - l, Pm)); /* PETSc's level: from the coarsest */
    MatDestroy(&Pm);                                     /* PCMG holds it */
    if (blocks) {
      KSP sk;
      PC spc;
      PCALL(ctx, PCMGGetSmoother(pc, L - 1 - l, &sk));
      PCALL(ctx, KSPGetPC(sk, &spc));
      FCM_TRY(ctx, block_pc_set(P, spc, T, l, gidx, owner, first, nloc));
    }
    /* the coarse level becomes the fine one */
    FCM_FREE(ctx, gidx);
    FCM_FREE(ctx, owner);
    gidx = gidx_c, owner = owner_c, gidx_c = NULL, owner_c = NULL;
    nloc = nloc_c, first = first_c;
    FCM_FREE(ctx, minf);
    FCM_FREE(ctx, dnz);
    FCM_FREE(ctx, onz);
    FCM_FREE(ctx, cols);
    FCM_FREE(ctx, vals);
  }
  PCALL(ctx, PCMGSetGalerkin(pc, PC_MG_GALERKIN_BOTH));
  /* defaults the options database overrides (read at the PC's setup): Chebyshev with fcm's block
   * Schwarz (block_pc) on every level, a redundant Cholesky on the coarsest */
  FCM_TRY(ctx, default_option(ctx, prefix, "mg_levels_ksp_type", "chebyshev"));
  FCM_TRY(ctx, default_option(ctx, prefix, "mg_coarse_ksp_type", "preonly"));
  FCM_TRY(ctx, default_option(ctx, prefix, "mg_coarse_pc_type", "redundant"));
  FCM_TRY(ctx, default_option(ctx, prefix, "mg_coarse_redundant_pc_type", "cholesky"));
  /* the rest of the user's -pc_mg_* options (cycle type, ...) on the new levels (collective:
   * -pc_mg_levels makes new levels) */
  AGREE();
  PCALL(ctx, PCSetFromOptions(pc));
  {
    PetscInt nl = 0;
    PCALL(ctx, PCMGGetLevels(pc, &nl));
    FCM_CHECK(nl == L, ctx, FCM_ERR_ARG,
              "petsc: -pc_mg_levels asks for %d levels, fcm's multigrid hierarchy has %d here",
              (int)nl, L);
  }
  if (num_levels) *num_levels = L;
cleanup:
  if (!agreed) st = fcm__petsc_problem_agree(P, st); /* meets the others' next agreement */
  if (st && num_levels) *num_levels = 0;
  MatDestroy(&Pm);
  fcm__mg_transfers_destroy(ctx, &T);
  fcm__free(ctx, gidx);
  fcm__free(ctx, gidx_c);
  fcm__free(ctx, owner);
  fcm__free(ctx, owner_c);
  fcm__free(ctx, minf);
  fcm__free(ctx, dnz);
  fcm__free(ctx, onz);
  fcm__free(ctx, cols);
  fcm__free(ctx, vals);
  fcm__free(ctx, count);
  return st;
}

#undef AGREE
