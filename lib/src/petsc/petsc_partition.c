/* petsc module: the partition of the background cells (Morton order or PT-Scotch, weighted by
 * the candidate cells), the classification exchange of the distributed rules build, and the
 * rules and space of each process's own cells (with the geometry cropped to what they read). */
#define _GNU_SOURCE /* RTLD_DEFAULT */
#include "petsc/petsc_impl.h"

#include <dlfcn.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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
    k[m].key = fcm__morton_key(x, lo, hi);
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
 * process: P->remote, fcm__petsc_rules_exchange()) and the space's numbering
 * (fcm__space_create_local(), the serial space's numbering bit for bit; its topology comes after
 * the DOFs' ownership, fcm__petsc_localize_space()). */
fcm_status fcm__petsc_build_space(fcm_petsc_problem *P, const fcm_geometry *geom,
                                  const unsigned char *mask)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  if (geom) {
    const fcm_cell_rules_options ro = rules_options(P, mask);
    const fcm__rules_exchange x = {P->remote, fcm__petsc_rules_exchange, P};
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
fcm_status fcm__petsc_partition_cells(fcm_petsc_problem *P, const fcm_geometry *geom,
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
  P->partition = P->opts.solver.partition == FCM_PETSC_PARTITION_AUTO ? FCM_PETSC_PARTITION_ORDERED
                                                                      : P->opts.solver.partition;
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
fcm_status fcm__petsc_rules_exchange(void *user, fcm_status st, unsigned char *cls,
                                     double *fraction, double *volume, fcm__embed_counts *counts)
{
  fcm_petsc_problem *P = user;
  fcm_ctx *ctx = P->ctx;
  const double t0 = fcm_wtime();
  const fcm_index nc = P->num_classified;
  enum { NCOUNT = 8 };
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
                                  counts->sliver_volume,
                                  counts->moved_volume};
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
  counts->moved_volume = sum[7];
done:
  P->time_classify = fcm_wtime() - t0;
  fcm__free(ctx, cnt);
  fcm__free(ctx, displ);
  fcm__free(ctx, send);
  fcm__free(ctx, recv);
  fcm__free(ctx, all);
  return st;
}

/* Every active cell of P->space has an owner (a candidate of the partition), inactive ones
 * none: FCM_ERR_INTERNAL naming the first active cell without one (local). */
fcm_status fcm__petsc_own_active_cells(fcm_petsc_problem *P)
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
fcm_status fcm__petsc_crop_geometry(fcm_petsc_problem *P, const fcm_geometry *geom,
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
