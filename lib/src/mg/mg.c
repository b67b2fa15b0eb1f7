/* Cut-aware geometric multigrid on Hex8 and Hex20 box grids (Dick, Georgii, Westermann 2011,
 * Sec. 6), with a vertex-block smoother at cut cells (de Prenter et al. 2020): options,
 * creation (the hierarchy, the Galerkin patterns, the coarsest factor, the smoothers' orders),
 * setup for new matrix values (Galerkin values P^T A P, the coarsest factor), destruction,
 * and the hierarchy's transfers without a matrix (fcm__mg_transfers, for PETSc's PCMG).
 *
 * The hierarchy (hierarchy.c) merges 2^3 blocks of cells per connected component, on Hex20
 * after a p-level to the Hex8 space of the same elements; the prolongations (transfer.c) are
 * trilinear per component, restriction = P^T; the coarse matrices are Galerkin products
 * (fcm__ptap, la), pattern once, values again in fcm_mg_setup(); CHOLMOD solves the coarsest
 * level. Smoothers (smoothers.c, their sweeps in sweeps.c): SGS in slab order (default), SGS
 * in multicolour order and damped Jacobi, plus block Gauss-Seidel (block_smoothing); the cycle
 * (cycle.c): V- or W-cycle as a solver and as a symmetric CG preconditioner. Every part is
 * deterministic for any thread count. Convergence and thread measurements:
 * lib/docs/multigrid_threads.md. */
#include "mg/levels_impl.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

double fcm_mg_smoother_omega(fcm_mg_smoother smoother)
{
  return smoother == FCM_MG_SMOOTHER_JACOBI ? 0.6 : 1.0;
}

fcm_mg_options fcm_mg_options_default(void)
{
  fcm_mg_options o;
  o.smoother = FCM_MG_SMOOTHER_SGS;
  o.omega = 0.0; /* the smoother's own, resolved by fcm_mg_create() */
  o.pre_smooth = 1;
  o.post_smooth = 1;
  o.cycle_index = 2;
  o.max_levels = 20;
  o.coarse_dofs = 2000;
  o.block_smoothing = 1;
  o.blocks = FCM_MG_BLOCKS_ALL;
  o.block_fraction = 1.0;
  o.block_sweep = 0;
  o.point_sweep = 0;
  o.coarse_interval = 1;
  return o;
}

void fcm_mg_destroy(fcm_mg **mg)
{
  if (!mg || !*mg) return;
  fcm_mg *m = *mg;
  if (m->beside) { /* level 0's task created by this thread waited for, then dropped */
#pragma omp taskwait
    fcm__mg_carry_free(m->ctx, &m->beside->carry);
    fcm__free(m->ctx, m->beside);
  }
  for (int l = 0; l < MG_MAX_LEVELS; l++)
    fcm__mg_level_free(m->ctx, &m->lev[l]);
  fcm_direct_destroy(&m->direct);
  for (int l = 0; l < MG_MAX_LEVELS; l++) {
    fcm_space_destroy(&m->oct_space[l]);
    fcm_mesh_destroy(&m->oct_mesh[l]);
  }
  fcm__free(m->ctx, m->cut_cell);
  fcm__mg_grid_release(m->ctx, &m->mesh_grid);
  fcm__free(m->ctx, m->blk_r);
  fcm__free(m->ctx, m->blk_dx);
  fcm__free(m->ctx, m);
  *mg = NULL;
}

/* ------------------------------------------------------------------ Galerkin product */

/* Values of A_{l+1} = R_l A_l P_l (fcm__ptap), symmetrized, its constrained rows and columns
 * decoupled, and the diagonal inverses of level l+1; rows in parallel (each entry is computed
 * by one thread in a fixed order: the result does not depend on the thread count). */
static fcm_status galerkin_values(fcm_mg *m, int l)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_level *F = &m->lev[l], *C = &m->lev[l + 1];
  const fcm_csr *A = fcm__mg_level_matrix(F);
  double *v = fcm_csr_values(C->Aown);
  const fcm_index *cp = fcm_csr_row_ptr(C->Aown);
  const int *cc = fcm_csr_col_idx(C->Aown);
  fcm_index nnz = 0, bad = C->n;
  fcm_csr_get_size(A, NULL, NULL, &nnz);
  const int nt = nnz >= MG_PARALLEL_NNZ ? fcm__mg_team(m) : 1;
  fcm__ptap_apply(F->ptap, A, C->Aown, nt);
#pragma omp parallel num_threads(nt) if (nt > 1)
  {
    /* symmetrize: the pair (i, j), (j, i) with i < j by row i's thread alone */
#pragma omp for schedule(dynamic, 64)
    for (fcm_index i = 0; i < C->n; i++) {
      for (fcm_index p = cp[i]; p < cp[i + 1]; p++) {
        const fcm_index j = cc[p];
        if (j <= i) continue;
        const fcm_index q = C->tpos[p];
        const double s = 0.5 * (v[p] + v[q]);
        v[p] = v[q] = s;
      }
    }
    /* decouple the constrained rows and columns, then the diagonal inverses */
#pragma omp for schedule(static) reduction(min : bad)
    for (fcm_index i = 0; i < C->n; i++) {
      for (fcm_index p = cp[i]; p < cp[i + 1]; p++)
        if (cc[p] != i && (C->inactive[i] || C->inactive[cc[p]])) v[p] = 0.0;
      if (C->inactive[i] && !(v[C->diag[i]] > 0.0)) v[C->diag[i]] = 1.0; /* decoupled anyway */
      const double d = v[C->diag[i]];
      if (!(isfinite(d) && d > 0.0) && i < bad) bad = i;
      C->dinv[i] = 1.0 / d;
    }
  }
  FCM_CHECK(bad == C->n, ctx, FCM_ERR_NUMERIC,
            "mg: level %d, row %lld: Galerkin diagonal %g is not positive (is A positive "
            "definite?)",
            l + 1, (long long)bad, bad < C->n ? v[C->diag[bad]] : 0.0);
cleanup:
  return st;
}

/* The positions of the diagonal entries of the level matrix (FCM_ERR_ARG naming a row that has
 * none); allocates diag and dinv. */
static fcm_status level_diag(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_csr *A = fcm__mg_level_matrix(L);
  if (!L->diag) FCM_ALLOC(ctx, L->n + 1, L->diag);
  if (!L->dinv) FCM_ALLOC(ctx, L->n + 1, L->dinv);
  const fcm_index n = L->n;
  fcm_index bad = n; /* the first row without one */
  if (L == &m->lev[0] && fcm__mg_space_diag(m, L->diag)) goto cleanup;
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static)                             \
    reduction(min                                                                                  \
              : bad) if (n > 4096)
  for (fcm_index i = 0; i < n; i++) {
    L->diag[i] = fcm_csr_position(A, i, i);
    if (L->diag[i] < 0 && i < bad) bad = i;
  }
  FCM_CHECK(bad == n, ctx, FCM_ERR_ARG, "mg: row %lld has no diagonal entry", (long long)bad);
cleanup:
  return st;
}

/* Level 0's rows checked against the eliminated rows of the creation (a row is eliminated
 * when its off-diagonal entries are all zero) and its diagonal inverses, in one pass over the
 * matrix by the team. */
static fcm_status level0_values(fcm_mg *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_level *L = &m->lev[0];
  const fcm_index *rp = fcm_csr_row_ptr(L->A);
  const int *ci = fcm_csr_col_idx(L->A);
  const double *v = fcm_csr_values_read(L->A);
  const fcm_index n = L->n;
  fcm_index bad = n, bad_diag = n; /* the first row whose elimination changed, the first
                                      non-positive diagonal */
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static)                             \
    reduction(min                                                                                  \
              : bad, bad_diag) if (n > 4096)
  for (fcm_index i = 0; i < n; i++) {
    int off = 0;
    for (fcm_index p = rp[i]; p < rp[i + 1] && !off; p++)
      off = ci[p] != i && v[p] != 0.0;
    if (off != !L->inactive[i] && i < bad) bad = i;
    const double d = v[L->diag[i]];
    if (!(isfinite(d) && d > 0.0) && i < bad_diag) bad_diag = i;
    L->dinv[i] = 1.0 / d;
  }
  FCM_CHECK(bad == n, ctx, FCM_ERR_ARG,
            "mg_setup: row %lld is %s now but was %s at creation (the eliminated rows "
            "must not change: create the multigrid again)",
            (long long)bad, L->inactive[bad] ? "coupled" : "eliminated",
            L->inactive[bad] ? "eliminated" : "coupled");
  FCM_CHECK(bad_diag == n, ctx, FCM_ERR_NUMERIC,
            "mg: diagonal entry of row %lld is %g (A must be positive definite)",
            (long long)bad_diag, v[L->diag[bad_diag]]);
cleanup:
  return st;
}

/* ------------------------------------------------------------------ create / setup */

/* The Galerkin product's plan and pattern of level l + 1 (from level l's matrix pattern and
 * P_l), with every diagonal entry (rows of empty columns); the restriction R_l = P_l^T the
 * plan holds. */
static fcm_status galerkin_pattern(fcm_mg *m, int l, mg_carry *carry)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_level *L = &m->lev[l], *C = &m->lev[l + 1];
  const fcm_csr *A = fcm__mg_level_matrix(L);
  fcm_index nnz = 0, *next = NULL, taken[2] = {0, 0};
  fcm_csr_get_size(A, NULL, NULL, &nnz);
  const int nt = nnz >= MG_PARALLEL_NNZ ? fcm__mg_team(m) : 1;
  fcm__ptap_prior prior;
  if (fcm__mg_carry_prior(m, carry, l, &prior)) {
    FCM_TRY(ctx, fcm__ptap_create_from(ctx, &prior, A, C->n, L->P_ptr, L->P_col, L->P_val, 1, nt,
                                       &L->ptap, &C->Aown, taken, &carry->crow_same[l + 1]));
    m->kept.carried_plans++;
    m->kept.carried_ap_rows += taken[0];
    m->kept.carried_coarse_rows += taken[1];
  } else {
    FCM_TRY(ctx, fcm__ptap_create(ctx, A, C->n, L->P_ptr, L->P_col, L->P_val, 1, nt, &L->ptap,
                                  &C->Aown));
  }
  fcm__ptap_transpose(L->ptap, &L->R_ptr, &L->R_col, &L->R_val);
  FCM_TRY(ctx, level_diag(m, C));
  {
    /* the transposed positions, found once: every setup symmetrizes with them. Row by row,
     * the entries (j, i) with i < j come in ascending i, as row j stores them (the pattern of
     * R A P is symmetric, A's being so): next[j] walks row j's lower triangle along, which
     * each row's count checks (it ends on the diagonal). */
    const fcm_index *cp = fcm_csr_row_ptr(C->Aown);
    const int *cc = fcm_csr_col_idx(C->Aown);
    FCM_CHECK(cp[C->n] <= INT_MAX, ctx, FCM_ERR_UNSUPPORTED,
              "mg: level %d: %lld entries do not fit the transposed positions' 32-bit range", l + 1,
              (long long)cp[C->n]);
    FCM_ALLOC_RAW(ctx, cp[C->n] + 1, C->tpos); /* every entry written below */
    FCM_ALLOC_RAW(ctx, C->n + 1, next);
    memcpy(next, cp, sizeof *next * (size_t)C->n);
    int *tpos = C->tpos;
    for (fcm_index i = 0; i < C->n; i++)
      for (fcm_index p = cp[i]; p < cp[i + 1]; p++) {
        const fcm_index j = cc[p];
        tpos[p] = j > i ? (int)next[j]++ : -1;
      }
    for (fcm_index j = 0; j < C->n; j++)
      FCM_CHECK(next[j] == C->diag[j], ctx, FCM_ERR_INTERNAL,
                "mg: level %d: row %lld of the Galerkin pattern has %lld entries left of the "
                "diagonal, its column %lld above",
                l + 1, (long long)j, (long long)(C->diag[j] - cp[j]), (long long)(next[j] - cp[j]));
  }
cleanup:
  fcm__free(ctx, next);
  return st;
}

/* The options resolved (omega) and validated. */
static fcm_status check_options(fcm_ctx *ctx, const fcm_mg_options *opts, fcm_mg_options *out)
{
  fcm_status st = FCM_OK;
  fcm_mg_options o = opts ? *opts : fcm_mg_options_default();
  FCM_CHECK(o.smoother >= 0 && o.smoother < FCM_MG_SMOOTHER_COUNT, ctx, FCM_ERR_ARG,
            "mg_create: smoother = %d is not a fcm_mg_smoother", (int)o.smoother);
  if (o.omega == 0.0) o.omega = fcm_mg_smoother_omega(o.smoother);
  FCM_CHECK(isfinite(o.omega) && o.omega > 0.0 &&
                (o.smoother != FCM_MG_SMOOTHER_JACOBI ? o.omega < 2.0 : o.omega <= 1.0),
            ctx, FCM_ERR_ARG, "mg_create: omega = %g outside %s, or 0 (the smoother's own)",
            o.omega, o.smoother != FCM_MG_SMOOTHER_JACOBI ? "(0, 2) (SGS)" : "(0, 1] (Jacobi)");
  FCM_CHECK(o.pre_smooth >= 0 && o.post_smooth >= 0, ctx, FCM_ERR_ARG,
            "mg_create: pre_smooth = %d, post_smooth = %d must be >= 0", o.pre_smooth,
            o.post_smooth);
  FCM_CHECK(o.cycle_index == 1 || o.cycle_index == 2, ctx, FCM_ERR_ARG,
            "mg_create: cycle_index = %d is neither 1 (V-cycle) nor 2 (W-cycle)", o.cycle_index);
  FCM_CHECK(o.max_levels >= 1 && o.max_levels <= MG_MAX_LEVELS, ctx, FCM_ERR_ARG,
            "mg_create: max_levels = %d outside [1, %d]", o.max_levels, MG_MAX_LEVELS);
  FCM_CHECK(o.coarse_dofs >= 1, ctx, FCM_ERR_ARG, "mg_create: coarse_dofs = %lld must be >= 1",
            (long long)o.coarse_dofs);
  FCM_CHECK(o.blocks >= 0 && o.blocks < FCM_MG_BLOCKS_COUNT, ctx, FCM_ERR_ARG,
            "mg_create: blocks = %d is not a fcm_mg_blocks", (int)o.blocks);
  FCM_CHECK(isfinite(o.block_fraction) && o.block_fraction > 0.0 && o.block_fraction <= 1.0, ctx,
            FCM_ERR_ARG, "mg_create: block_fraction = %g outside (0, 1]", o.block_fraction);
  FCM_CHECK(o.block_sweep == 0 || o.block_sweep == 1, ctx, FCM_ERR_ARG,
            "mg_create: block_sweep = %d is neither 0 (symmetric) nor 1 (one way)", o.block_sweep);
  FCM_CHECK(o.point_sweep == 0 || o.point_sweep == 1, ctx, FCM_ERR_ARG,
            "mg_create: point_sweep = %d is neither 0 (symmetric) nor 1 (one way)", o.point_sweep);
  FCM_CHECK(o.coarse_interval >= 1, ctx, FCM_ERR_ARG,
            "mg_create: coarse_interval = %d must be >= 1", o.coarse_interval);
  FCM_CHECK(o.point_sweep == 0 || o.smoother == FCM_MG_SMOOTHER_SGS, ctx, FCM_ERR_ARG,
            "mg_create: point_sweep = 1 (one way) needs the SGS smoother (smoother = %d)",
            (int)o.smoother);
  *out = o;
cleanup:
  return st;
}

/* Level L's smoothing order: its rows' colours or slabs (the smoother's), unless kept. */
static fcm_status level_orders(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  if (m->opts.smoother == FCM_MG_SMOOTHER_SGS_COLORED && !L->color_ptr)
    FCM_TRY(m->ctx, fcm__mg_level_colors(m, L));
  if (m->opts.smoother == FCM_MG_SMOOTHER_SGS && !L->rows.ptr)
    FCM_TRY(m->ctx, fcm__mg_row_slabs(m, L));
cleanup:
  return st;
}

/* Level 0's smoothing order and block smoother (block_smoothing) of a cut's hierarchy;
 * *bmax, *carried as fcm__mg_level_block_smoother() gives them (0 without blocks). */
static fcm_status level0_smoothers(fcm_mg *m, const mg_carry *carry, fcm_index *bmax,
                                   fcm_index *carried)
{
  fcm_status st = FCM_OK;
  *bmax = *carried = 0;
  FCM_TRY(m->ctx, level_orders(m, &m->lev[0]));
  if (m->opts.block_smoothing)
    FCM_TRY(m->ctx, fcm__mg_level_block_smoother(m, NULL, NULL, carry, 0, bmax, carried));
cleanup:
  return st;
}

/* The largest coarsest level ordered by coarsest_node_ordering(): twice the default
 * coarse_dofs. Above, the factor's size (each set-up factors it again, and METIS's can be
 * smaller than AMD's) outweighs the ordering's time, and CHOLMOD's best of AMD and METIS is
 * kept (lib/docs/cutting.md, "The coarsest ordering"). */
enum { NODE_ORDER_MAX = 4000 };

/* The coarsest level's ordering where it is small (at most NODE_ORDER_MAX DOFs):
 * AMD on the graph of its copies (a copy's DOFs together), given to the analysis in place of
 * CHOLMOD's own AMD and METIS on the DOFs (lib/docs/cutting.md, "The coarsest ordering").
 * None where the level is larger, or a DOF is in no copy: CHOLMOD orders it then. perm: room
 * for the level's n DOFs. */
static fcm_status coarsest_node_ordering(fcm_mg *m, const fcm_csr *A, fcm_index *perm)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const mg_level *L = &m->lev[m->nlev - 1];
  fcm_index *group = NULL;
  if (L->n > NODE_ORDER_MAX || !L->dof) goto cleanup;
  FCM_ALLOC_RAW(ctx, (size_t)L->n, group);
  for (fcm_index i = 0; i < L->n; i++)
    group[i] = -1;
  for (fcm_index k = 0; k < L->ncopy; k++)
    for (int c = 0; c < 3; c++)
      if (L->dof[3 * k + c] >= 0) group[L->dof[3 * k + c]] = k;
  for (fcm_index i = 0; i < L->n; i++)
    if (group[i] < 0) goto cleanup;
  FCM_TRY(ctx, fcm__amd_group_ordering(ctx, A, L->ncopy, group, perm));
  FCM_TRY(ctx, fcm__direct_set_ordering(m->direct, perm));
cleanup:
  fcm__free(ctx, group);
  return st;
}

/* The coarsest level's solver and symbolic analysis. A cut whose coarsest pattern is that of
 * the hierarchy before it (carry->old, read only) gives the analysis the old one's ordering,
 * so that CHOLMOD only postorders it: on the same pattern the ordering would be found again,
 * postordered already. The ordering the analysis ends with is compared with the one it was
 * given; where they differ, the analysis is made again without it, so that the factor is a
 * plain creation's bit for bit either way. */
static fcm_status coarsest_analysis(fcm_mg *m, const mg_carry *carry)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const int lc = m->nlev - 1;
  const fcm_csr *A = fcm__mg_level_matrix(&m->lev[lc]);
  const fcm_index n = m->lev[lc].n;
  const fcm_mg *old = carry ? carry->old : NULL;
  fcm_index *perm = NULL;
  const int given = old && lc > 0 && n > 0 && old->nlev == m->nlev && old->direct &&
                    fcm__mg_level_same(old, m, lc);
  FCM_ALLOC_RAW(ctx, 2 * (size_t)n + 1, perm);
  FCM_TRY(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &m->direct));
  if (given) {
    FCM_TRY(ctx, fcm__direct_get_ordering(old->direct, perm));
    FCM_TRY(ctx, fcm__direct_set_ordering(m->direct, perm));
  } else {
    FCM_TRY(ctx, coarsest_node_ordering(m, A, perm));
  }
  FCM_TRY(ctx, fcm_direct_analyze(m->direct));
  if (given) {
    FCM_TRY(ctx, fcm__direct_get_ordering(m->direct, perm + n));
    if (memcmp(perm, perm + n, sizeof *perm * (size_t)n) == 0) {
      m->kept.carried_ordering = 1;
    } else {
      fcm_direct_destroy(&m->direct);
      FCM_TRY(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &m->direct));
      FCM_TRY(ctx, coarsest_node_ordering(m, A, perm));
      FCM_TRY(ctx, fcm_direct_analyze(m->direct));
    }
  }
cleanup:
  fcm__free(ctx, perm);
  return st;
}

/* The levels' Galerkin plans and patterns, the row orders of the levels from `first` on and
 * the coarsest analysis (keeping old's where fcm__mg_create_from() may; same[l]: level l's
 * pattern is old's). */
static fcm_status create_patterns(fcm_mg *m, fcm_mg *old, mg_carry *carry, unsigned char *same,
                                  int first)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  int kept_above = 0; /* the plan of the finer level was kept: this level's pattern is old's */
  for (int l = 0; l < m->nlev; l++) {
    mg_level *L = &m->lev[l];
    FCM_ALLOC(ctx, L->n + 1, L->x);
    FCM_ALLOC(ctx, L->n + 1, L->b);
    FCM_ALLOC(ctx, L->n + 1, L->r);
    same[l] = (unsigned char)(old && (kept_above || fcm__mg_level_same(old, m, l)));
    kept_above = l + 1 < m->nlev && same[l] && fcm__mg_keep_plan(old, m, l);
    /* nothing of old's level l is taken now: its memory goes before this level's arrays
     * are allocated (the allocator may give it back to them) */
    if (old && !same[l] && l < old->nlev) fcm__mg_level_free(ctx, &old->lev[l]);
    if (l + 1 < m->nlev && !kept_above) FCM_TRY(ctx, galerkin_pattern(m, l, carry));
    if (same[l]) fcm__mg_keep_orders(old, m, l);
  }
  for (int l = first; l + 1 < m->nlev; l++)
    FCM_TRY(ctx, level_orders(m, &m->lev[l]));
  if (!(old && fcm__mg_keep_analysis(old, m, same[m->nlev - 1]))) {
    if (old) fcm_direct_destroy(&old->direct); /* not taken: freed first, as above */
    FCM_TRY(ctx, coarsest_analysis(m, carry));
  }
cleanup:
  return st;
}

/* A cut's patterns and smoothers (mg_create() from a carry, nothing of an old hierarchy kept,
 * the values pending): level 0's smoothing order and block smoother read only level 0's
 * pattern and diagonal, its grid and the carry's maps, and write level 0's own fields, so
 * they are made as a task beside the coarser levels' patterns, orders and smoothers and the
 * coarsest analysis. A thread of the team the cut runs on takes it when it is free
 * (scene/run.c cut_parts()). With `defer` inside an active parallel region this thread
 * returns once its own part is done, leaving the task to whichever thread gets to it first
 * and its completion to fcm__mg_join() after the team's barrier (the maps move into the
 * hierarchy, since the task may outlive this frame); otherwise this thread waits for the task
 * or runs it. The same bits either way; an error is the coarser levels' before level 0's. */
static fcm_status create_beside(fcm_mg *m, mg_carry *carry, unsigned char *same, int defer)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_beside *b = fcm__calloc(ctx, 1, sizeof *b);
  FCM_CHECK(b, ctx, FCM_ERR_ALLOC, "mg_create: out of memory");
  b->carry = *carry;
  memset(carry, 0, sizeof *carry);
  m->beside = b;
  fcm__loop_begin(ctx, &b->loop);
#pragma omp task default(none) firstprivate(m, b)
  {
    const double t0 = fcm_wtime();
    fcm__loop_iter it;
    fcm__loop_enter(&b->loop, &it, 1);
    fcm__loop_leave(&b->loop, &it, level0_smoothers(m, &b->carry, &b->bmax, &b->carried));
    b->seconds = fcm_wtime() - t0;
  }
  {
    fcm__loop_iter it;
    fcm__loop_enter(&b->loop, &it, 0);
    fcm_status s = create_patterns(m, NULL, &b->carry, same, 1);
    if (s == FCM_OK && m->opts.block_smoothing)
      s = fcm__mg_block_smoothers_create(m, NULL, same, &b->carry, 1);
    fcm__loop_leave(&b->loop, &it, s);
    if (s == FCM_OK && defer && omp_in_parallel()) return FCM_OK;
  }
#pragma omp taskwait
  FCM_TRY(ctx, fcm__mg_join(m, NULL));
cleanup:
  return st;
}

fcm_status fcm__mg_join(fcm_mg *m, double *seconds)
{
  fcm_status st = FCM_OK;
  if (seconds) *seconds = 0.0;
  if (!m || !m->beside) return FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_beside *b = m->beside;
  m->beside = NULL;
  if (seconds) *seconds = b->seconds;
  st = fcm__loop_end(&b->loop, NULL);
  if (st == FCM_OK) {
    m->blk_max = FCM_MAX(m->blk_max, b->bmax);
    m->kept.carried_blocks += b->carried;
    if (m->opts.block_smoothing) st = fcm__mg_block_buffers(m);
  }
  fcm__mg_carry_free(ctx, &b->carry);
  fcm__free(ctx, b);
  return st;
}

/* fcm_mg_create(), keeping the parts of old (NULL: none) fcm__mg_create_from() may; with
 * `inactive` (fcm__mg_create_pattern()) on A's pattern alone, level 0's Dirichlet rows given,
 * the values left to fcm_mg_setup(). */
static fcm_status mg_create(fcm_ctx *ctx, fcm_mg *old, mg_carry *carry, const fcm_space *space,
                            const fcm_csr *A, const unsigned char *inactive,
                            const fcm_mg_options *opts, int defer, fcm_mg **mg)
{
  fcm_status st = FCM_OK;
  fcm_mg *m = NULL;
  unsigned char same[MG_MAX_LEVELS] = {0};
  FCM_CHECK(ctx && space && A && mg, ctx, FCM_ERR_ARG, "mg_create: NULL argument");
  *mg = NULL;
  fcm_mg_options o;
  FCM_TRY(ctx, check_options(ctx, opts, &o));
  fcm_index nr = 0, nc = 0;
  fcm_csr_get_size(A, &nr, &nc, NULL);
  FCM_CHECK(nr == fcm_space_num_dofs(space) && nc == nr, ctx, FCM_ERR_ARG,
            "mg_create: A is %lld x %lld, the space has %lld DOFs", (long long)nr, (long long)nc,
            (long long)fcm_space_num_dofs(space));
  FCM_CHECK(fcm_csr_get_kind(A) == FCM_CSR_SYMMETRIC, ctx, FCM_ERR_ARG,
            "mg_create: A must be an FCM_CSR_SYMMETRIC matrix");
  m = fcm__calloc(ctx, 1, sizeof *m);
  FCM_CHECK(m, ctx, FCM_ERR_ALLOC, "mg_create: out of memory");
  m->ctx = ctx;
  m->space = space;
  m->opts = o;
  m->nt = fcm_ctx_num_threads(ctx);
  m->values_pending = inactive != NULL;
  m->pattern_of = fcm__mg_pattern_of(space, A);
  if (carry) fcm__mg_grid_share(m, carry->old); /* a cut keeps the mesh */
  FCM_TRY(ctx, fcm__mg_build_hierarchy(m, A, inactive));
  if (!fcm__mg_reuse_allowed(old, m)) old = NULL;
  FCM_TRY(ctx, level_diag(m, &m->lev[0]));
  if (carry && carry->old) FCM_TRY(ctx, fcm__mg_carry_maps(m, carry));
  if (carry && carry->old && !old && m->values_pending && m->nlev > 1) {
    FCM_TRY(ctx, create_beside(m, carry, same, defer)); /* the buffers at its join */
  } else {
    FCM_TRY(ctx, create_patterns(m, old, carry, same, 0));
    if (!m->values_pending) FCM_TRY(ctx, fcm_mg_setup(m));
    if (o.block_smoothing) { /* set up as created, or by the fcm_mg_setup() to come */
      FCM_TRY(ctx, fcm__mg_block_smoothers_create(m, old, same, carry, 0));
      FCM_TRY(ctx, fcm__mg_block_buffers(m));
    }
  }
  *mg = m;
  m = NULL;
cleanup:
  fcm_mg_destroy(&m);
  return st;
}

int fcm__mg_take_scratch(fcm_mg *m, fcm_mg *old)
{
  if (!m || !old || m == old || !m->values_pending) return 0;
  int taken = 0;
  for (int l = 0; l + 1 < m->nlev && l + 1 < old->nlev; l++) {
    taken += fcm__ptap_take_scratch(m->lev[l].ptap, old->lev[l].ptap);
    taken += fcm__csr_take_values(m->lev[l + 1].Aown, old->lev[l + 1].Aown);
  }
  return taken;
}

fcm_status fcm_mg_create(fcm_ctx *ctx, const fcm_space *space, const fcm_csr *A,
                         const fcm_mg_options *opts, fcm_mg **mg)
{
  return mg_create(ctx, NULL, NULL, space, A, NULL, opts, 0, mg);
}

fcm_status fcm__mg_create_from(fcm_ctx *ctx, fcm_mg **old, const fcm_space *space, const fcm_csr *A,
                               const fcm_mg_options *opts, fcm_mg **mg)
{
  const fcm_status st = mg_create(ctx, old ? *old : NULL, NULL, space, A, NULL, opts, 0, mg);
  if (old) fcm_mg_destroy(old);
  return st;
}

fcm_status fcm__mg_create_pattern(fcm_ctx *ctx, fcm_mg **old, const fcm_space *space,
                                  const fcm_csr *A, const unsigned char *inactive,
                                  const fcm_mg_options *opts, fcm_mg **mg)
{
  fcm_status st = FCM_OK;
  if (mg) *mg = NULL;
  FCM_CHECK(ctx && space && A && inactive && mg, ctx, FCM_ERR_ARG,
            "mg_create_pattern: NULL argument");
  FCM_CHECK(fcm_mesh_num_hanging(fcm_space_mesh(space)) == 0, ctx, FCM_ERR_UNSUPPORTED,
            "mg_create_pattern: an octree mesh's hierarchy needs the matrix values (use "
            "fcm_mg_create())");
  st = mg_create(ctx, old ? *old : NULL, NULL, space, A, inactive, opts, 0, mg);
cleanup:
  if (old) fcm_mg_destroy(old);
  return st;
}

static fcm_status create_pattern_cut(fcm_ctx *ctx, const fcm_mg *old, const fcm_space *old_space,
                                     const fcm_space *space, const fcm_csr *A,
                                     const unsigned char *inactive, const fcm_mg_options *opts,
                                     int defer, fcm_mg **mg)
{
  fcm_status st = FCM_OK;
  mg_carry carry;
  memset(&carry, 0, sizeof carry);
  if (mg) *mg = NULL;
  FCM_CHECK(ctx && space && A && inactive && mg && (!old || old_space), ctx, FCM_ERR_ARG,
            "mg_create_pattern_cut: NULL argument (old_space is needed with old)");
  FCM_CHECK(fcm_mesh_num_hanging(fcm_space_mesh(space)) == 0, ctx, FCM_ERR_UNSUPPORTED,
            "mg_create_pattern_cut: an octree mesh's hierarchy needs the matrix values (use "
            "fcm_mg_create())");
  carry.old = old, carry.old_space = old_space;
  st = mg_create(ctx, NULL, &carry, space, A, inactive, opts, defer, mg);
cleanup:
  fcm__mg_carry_free(ctx, &carry); /* what the hierarchy did not take (create_beside()) */
  return st;
}

fcm_status fcm__mg_create_pattern_cut(fcm_ctx *ctx, const fcm_mg *old, const fcm_space *old_space,
                                      const fcm_space *space, const fcm_csr *A,
                                      const unsigned char *inactive, const fcm_mg_options *opts,
                                      fcm_mg **mg)
{
  return create_pattern_cut(ctx, old, old_space, space, A, inactive, opts, 0, mg);
}

fcm_status fcm__mg_create_pattern_cut_beside(fcm_ctx *ctx, const fcm_mg *old,
                                             const fcm_space *old_space, const fcm_space *space,
                                             const fcm_csr *A, const unsigned char *inactive,
                                             const fcm_mg_options *opts, fcm_mg **mg)
{
  return create_pattern_cut(ctx, old, old_space, space, A, inactive, opts, 1, mg);
}

/* Level l's block smoother on its matrix's values: after a set-up of this hierarchy (or its
 * creation with values) the positions of the blocks' entries were checked against the pattern,
 * which a set-up keeps (the Galerkin plans rely on it too), so they are not checked again; nor
 * after a creation on the pattern (values_pending), which found them from this level's
 * pattern (scanned, or carried where a block and its rows are the old ones mapped: the same
 * positions). check: after a failed set-up. */
static fcm_status setup_blocks(fcm_mg *m, int l, int check)
{
  const fcm_csr *A = fcm__mg_level_matrix(&m->lev[l]);
  return check ? fcm_schwarz_setup(m->lev[l].blk, A) : fcm__schwarz_setup_known(m->lev[l].blk, A);
}

fcm_status fcm_mg_setup(fcm_mg *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  FCM_CHECK(m, ctx, FCM_ERR_ARG, "mg_setup: NULL argument");
  /* the first set-up (after a creation on a pattern or a failed set-up) computes every level,
   * after a failed one checking the blocks' positions (setup_blocks()); the coarser levels
   * then at every coarse_interval-th; a single level is the finest, factored at every set-up */
  const int first = m->values_pending || m->setup_failed, check = m->setup_failed;
  const int coarse = first || m->nlev == 1 || m->setups % m->opts.coarse_interval == 0;
  m->setup_failed = 1; /* until this one succeeds: the levels' values may be mixed */
  FCM_TRY(ctx, level0_values(m));
  for (int l = 0; l + 1 < m->nlev && (l == 0 || coarse); l++) {
    if (m->lev[l].blk) FCM_TRY(ctx, setup_blocks(m, l, check));
    if (coarse) FCM_TRY(ctx, galerkin_values(m, l));
  }
  if (coarse)
    FCM_TRY(ctx, fcm_direct_factor(
                     m->direct, fcm_csr_values_read(fcm__mg_level_matrix(&m->lev[m->nlev - 1]))));
  m->values_pending = 0;
  m->setup_failed = 0;
  m->setups++;
cleanup:
  return st;
}

int fcm_mg_num_levels(const fcm_mg *m)
{
  return m ? m->nlev : 0;
}

/* ------------------------------------------------------------------ transfers only */

void fcm__mg_transfers_destroy(fcm_ctx *ctx, fcm__mg_transfers **tp)
{
  if (!tp || !*tp) return;
  fcm__mg_transfers *t = *tp;
  for (int l = 0; l < t->num_levels; l++) {
    if (t->inactive) fcm__free(ctx, t->inactive[l]);
    if (l + 1 < t->num_levels && t->P_ptr && t->P_col && t->P_val) {
      fcm__free(ctx, t->P_ptr[l]);
      fcm__free(ctx, t->P_col[l]);
      fcm__free(ctx, t->P_val[l]);
    }
  }
  for (int l = 0; l < t->num_levels && t->block_ptr && t->block_dofs; l++) {
    fcm__free(ctx, t->block_ptr[l]);
    fcm__free(ctx, t->block_dofs[l]);
  }
  fcm__free(ctx, t->num_blocks);
  fcm__free(ctx, t->block_ptr);
  fcm__free(ctx, t->block_dofs);
  fcm__free(ctx, t->n);
  fcm__free(ctx, t->P_ptr);
  fcm__free(ctx, t->P_col);
  fcm__free(ctx, t->P_val);
  fcm__free(ctx, t->inactive);
  fcm__free(ctx, t);
  *tp = NULL;
}

fcm_status fcm__mg_transfers_create(fcm_ctx *ctx, const fcm_space *space,
                                    const unsigned char *constrained, int max_levels,
                                    fcm_index coarse_dofs, fcm__mg_transfers **out)
{
  fcm_status st = FCM_OK;
  fcm_mg *m = NULL;
  fcm__mg_transfers *t = NULL;
  unsigned char *none = NULL;
  FCM_CHECK(ctx && space && out, ctx, FCM_ERR_ARG, "mg_transfers: NULL argument");
  *out = NULL;
  FCM_CHECK(max_levels >= 1 && max_levels <= MG_MAX_LEVELS, ctx, FCM_ERR_ARG,
            "mg_transfers: max_levels = %d outside [1, %d]", max_levels, MG_MAX_LEVELS);
  FCM_CHECK(coarse_dofs >= 1, ctx, FCM_ERR_ARG, "mg_transfers: coarse_dofs = %lld must be >= 1",
            (long long)coarse_dofs);
  const fcm_index n0 = fcm_space_num_dofs(space);
  if (!constrained) {
    none = fcm__calloc(ctx, (size_t)n0 + 1, 1);
    FCM_CHECK(none, ctx, FCM_ERR_ALLOC, "mg_transfers: out of memory");
  }
  m = fcm__calloc(ctx, 1, sizeof *m);
  FCM_CHECK(m, ctx, FCM_ERR_ALLOC, "mg_transfers: out of memory");
  m->ctx = ctx;
  m->space = space;
  m->opts = fcm_mg_options_default();
  m->opts.max_levels = max_levels;
  m->opts.coarse_dofs = coarse_dofs;
  m->nt = fcm_ctx_num_threads(ctx);
  FCM_TRY(ctx, fcm__mg_build_hierarchy(m, NULL, constrained ? constrained : none));
  t = fcm__calloc(ctx, 1, sizeof *t);
  FCM_CHECK(t, ctx, FCM_ERR_ALLOC, "mg_transfers: out of memory");
  const int L = m->nlev;
  t->num_levels = L;
  FCM_ALLOC(ctx, L, t->n);
  FCM_ALLOC(ctx, L, t->P_ptr);
  FCM_ALLOC(ctx, L, t->P_col);
  FCM_ALLOC(ctx, L, t->P_val);
  FCM_ALLOC(ctx, L, t->inactive);
  FCM_ALLOC(ctx, L, t->num_blocks);
  FCM_ALLOC(ctx, L, t->block_ptr);
  FCM_ALLOC(ctx, L, t->block_dofs);
  for (int l = 0; l + 1 < L; l++)
    FCM_TRY(ctx,
            fcm__mg_level_blocks(m, l, &t->num_blocks[l], &t->block_ptr[l], &t->block_dofs[l]));
  for (int l = 0; l < L; l++) { /* move the arrays: m keeps NULL */
    mg_level *V = &m->lev[l];
    t->n[l] = V->n;
    t->inactive[l] = V->inactive, V->inactive = NULL;
    if (l + 1 < L) {
      t->P_ptr[l] = V->P_ptr, V->P_ptr = NULL;
      t->P_col[l] = V->P_col, V->P_col = NULL;
      t->P_val[l] = V->P_val, V->P_val = NULL;
    }
  }
  *out = t;
  t = NULL;
cleanup:
  fcm__mg_transfers_destroy(ctx, &t);
  fcm_mg_destroy(&m);
  fcm__free(ctx, none);
  return st;
}
