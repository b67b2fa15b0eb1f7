/* petsc module: the DOFs' global numbering and ownership (PETSc's contiguous blocks per owner),
 * the local topology of the own and ghost cells, and the distributed matrices and vectors
 * (exact preallocation, the rigid-body near-null space). */
#include "petsc/petsc_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Ownership of the DOF copies and the PETSc numbering. */
fcm_status fcm__petsc_number_dofs(fcm_petsc_problem *P)
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
 * using it, so one of this process's own cells uses it. Hence fcm__petsc_create_matrix()
 * preallocates the owned rows exactly as from the full pattern (tests/petsc/ghost.c asserts the
 * rows, and that the own cells alone would miss some). */
fcm_status fcm__petsc_localize_space(fcm_petsc_problem *P)
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

/* The preallocation of fcm__petsc_create_matrix(): the diagonal- and off-block entries of each
 * owned row (dnz, onz: 3 nlocal each, allocated here). Local. */
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
 * owned copy is one of the space's local copies: fcm__petsc_localize_space()). The processes agree
 * on the local preallocation before the collective calls (a failure there is agreed: every process
 * returns it, P->agreed_fail). Collective. */
fcm_status fcm__petsc_create_matrix(fcm_petsc_problem *P, Mat *A)
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

fcm_status fcm__petsc_create_vectors(fcm_petsc_problem *P)
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

/* Coordinates of the owned DOF copies (their node's), block size 3, for the rigid-body modes. */
fcm_status fcm__petsc_near_null_space(fcm_petsc_problem *P, Mat A)
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
