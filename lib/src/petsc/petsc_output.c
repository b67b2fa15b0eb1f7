/* petsc module: the linear driver's output: parallel VTU frames (one piece per process) and
 * its checkpoints (io's checkpoint container; the older "fcm-petsc-ck-1" files still load). */
#include "petsc/petsc_impl.h"

#include "io/io_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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

/* The checkpoint container of io (io_impl.h) with the "no scene" source (fcm__ckpt_linear),
 * written by process 0: the space's DOF numbering, so any process count reads it. */
static const char ckpt_magic[8] = FCM__CKPT_MAGIC;

fcm_status fcm_petsc_problem_write_checkpoint(fcm_petsc_problem *P, const char *path)
{
  fcm_status st = FCM_OK;
  double *u = NULL, *v = NULL;
  fcm__ckpt_writer w;
  memset(&w, 0, sizeof w);
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  st = path && path[0] ? FCM_OK
                       : fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                                    "petsc: checkpoint: NULL or empty path");
  if (st == FCM_OK) { /* the state is gathered on process 0 only (O(n) there) */
    const size_t len = P->rank == 0 ? (size_t)P->n + 1 : 1;
    u = fcm__calloc(ctx, len, sizeof *u);
    v = fcm__calloc(ctx, len, sizeof *v);
    if (!u || !v) st = FCM_ERR_ALLOC;
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  FCM_TRY(ctx, fcm__petsc_gather(P, P->u, u, 1));
  FCM_TRY(ctx, fcm__petsc_gather(P, P->v, v, 1));
  if (P->rank == 0) {
    const fcm__ckpt_linear h = {
        (long long)P->n, (long long)P->space->num_elems, P->steps, (long long)P->opts.kind, P->t,
        P->opts.dt};
    st = fcm__ckpt_open(ctx, path, ckpt_magic, FCM__CKPT_VERSION, &w);
    if (st == FCM_OK) st = fcm__ckpt_put_linear(&w, &h, u, v);
    if (st == FCM_OK) st = fcm__ckpt_commit(&w);
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
cleanup:
  fcm__ckpt_abort(&w);
  if (P) {
    fcm__free(P->ctx, u);
    fcm__free(P->ctx, v);
  }
  return st;
}

/* Read and check a checkpoint (the container or the older ".fcmpk") into u, v (n each), *t
 * and *steps (every process reads). */
static fcm_status read_ckpt(fcm_petsc_problem *P, const char *path, double *u, double *v, double *t,
                            long long *steps)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  fcm__ckpt_reader r;
  fcm__ckpt_linear h;
  uint64_t source = FCM__CKPT_SOURCE_LINEAR;
  memset(&r, 0, sizeof r);
  FCM_CHECK(path && path[0], ctx, FCM_ERR_ARG, "petsc: checkpoint: NULL or empty path");
  FCM_TRY(ctx, fcm__ckpt_read_open(ctx, path, ckpt_magic, FCM__CKPT_VERSION, &r));
  if (!r.legacy_linear) FCM_TRY(ctx, fcm__ckpt_get_u64(&r, &source, "the source"));
  FCM_CHECK(source == FCM__CKPT_SOURCE_LINEAR, ctx, FCM_ERR_ARG,
            "petsc: checkpoint %s was written by a scene run, not by the linear driver "
            "(fcm_simulation_read_checkpoint() reads it)",
            path);
  FCM_TRY(ctx, fcm__ckpt_get_linear(&r, &h));
  FCM_CHECK(h.num_dofs == (long long)P->n && h.elements == (long long)P->space->num_elems &&
                h.kind == (long long)P->opts.kind && h.dt == P->opts.dt,
            ctx, FCM_ERR_ARG,
            "petsc: checkpoint %s is of another problem: %lld DOFs, %lld elements, kind %lld, "
            "dt %g (this one: %lld, %lld, %d, %g)",
            path, h.num_dofs, h.elements, h.kind, h.dt, (long long)P->n,
            (long long)P->space->num_elems, (int)P->opts.kind, P->opts.dt);
  FCM_TRY(ctx, fcm__ckpt_get(&r, u, sizeof *u * (size_t)P->n, "the displacement"));
  FCM_TRY(ctx, fcm__ckpt_get(&r, v, sizeof *v * (size_t)P->n, "the velocity"));
  FCM_TRY(ctx, fcm__ckpt_read_end(&r));
  *t = h.time;
  *steps = h.steps;
cleanup:
  fcm__ckpt_read_close(&r);
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
