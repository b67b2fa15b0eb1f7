/* A hierarchy carried over a cut (fcm__mg_create_pattern_cut(): the Galerkin plans' rows the
 * cut left taken from the hierarchy before it, which is only read) equals, after each cut of a
 * sequence of three, the one fcm_mg_create() builds on the new space and matrix bit for bit
 * (every level's pattern, values and inactive rows, and two cycles, memcmp); each coarse
 * pattern is the structural pattern of P^T A P with the diagonal (a dense table); most rows
 * were taken (the counts of fcm__mg_get_kept()), and the coarsest analysis took the old
 * ordering only where the coarsest pattern is the old one's (and did in some cuts); a
 * hierarchy on a pattern refuses a cycle before its set-up. The cut spaces take the old space's
 * pattern (fcm__space_create_cut_take()) and the old level-0 matrix is gone before the carry, as in
 * an integrator's cut. Before each cut, a carry whose allocations fail (several places) returns
 * FCM_ERR_ALLOC, leaks nothing and leaves the old hierarchy as it was (its cycles' bits). A
 * carry whose preconditions fail (the old hierarchy made on another space, or on a matrix
 * not of its space's pattern; the new matrix not of its space's pattern) takes nothing and
 * gives the plain hierarchy, without an error. Made beside (in a team of two, level 0's smoothers
 * left to a task that the other thread may run, completed by fcm__mg_join() after the barrier)
 * the carry is the same hierarchy, and its allocation failures, in either part, are reported
 * (by the creation or the join) and leak nothing. The embedded hemisphere of mg_util.h, Hex8
 * and Hex20, V- and W-cycles (the W-cycle's finest blocks only at the cells with a piece under
 * half the cell: fcm_mg_options.block_fraction 0.5). A carried hierarchy takes the old one's
 * Galerkin storage where it fits (fcm__mg_take_scratch(), as an integrator's cut does) before
 * its set-up, with the same bits; on one pattern a hierarchy takes every product's scratch and
 * every coarse matrix's values from another one set up before (the arrays' addresses), with
 * the same bits as a plain creation's; one set up already, or NULL, takes nothing. */
#include "fem/fem_impl.h"
#include "mg/levels_impl.h"
#include "mg_compare.h"
#include "mg_util.h"
#include "test_alloc.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>

/* The space of `rules` made by a cut of `from` (its pattern taken), its clamped matrix. */
static void problem_cut(fcm_ctx *ctx, const problem *base, const fcm_cell_rules *rules,
                        fcm_space *from, problem *p)
{
  memset(p, 0, sizeof *p);
  p->mesh = base->mesh;
  fcm_space_options so = fcm_space_options_default();
  TEST_OK(ctx, fcm__space_create_cut_take(ctx, p->mesh, rules, &so, from, &p->space));
  finish_space(ctx, p, 0);
  const double flo[3] = {-2, 0, -2}, fhi[3] = {2, 0, 2};
  clamp_box(ctx, p, flo, fhi);
}

static void problem_drop(problem *p)
{
  fcm_csr_destroy(&p->A);
  fcm_space_destroy(&p->space);
  free(p->b);
  memset(p, 0, sizeof *p);
}

/* The carry made beside (fcm__mg_create_pattern_cut_beside()) by one thread of a team of two,
 * the other free to run level 0's task, joined after the team's barrier: pending at the
 * return wherever there is an old hierarchy (a team of two formed), complete after the join;
 * the block smoothers' positions those of a plain creation on every level. */
static fcm_mg *beside_carry(fcm_ctx *ctx, const fcm_mg *old, const fcm_space *prev,
                            const fcm_space *space, const fcm_csr *pattern,
                            const unsigned char *inactive, const fcm_mg_options *o)
{
  fcm_mg *bes = NULL, *plain = NULL;
  fcm_status sb = FCM_OK;
  int pending = 0, team = 0;
#pragma omp parallel num_threads(2)
#pragma omp single
  {
    team = omp_get_num_threads();
    sb = fcm__mg_create_pattern_cut_beside(ctx, old, prev, space, pattern, inactive, o, &bes);
    pending = sb == FCM_OK && bes->beside != NULL;
  }
  TEST_OK(ctx, sb);
  TEST_TRUE(pending == (old != NULL && team == 2));
  double seconds = -1.0;
  TEST_OK(ctx, fcm__mg_join(bes, &seconds));
  TEST_TRUE(bes->beside == NULL && (pending ? seconds > 0.0 : seconds == 0.0));
  TEST_OK(ctx, fcm__mg_join(bes, NULL)); /* a complete hierarchy: nothing to do */
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, NULL, space, pattern, inactive, o, &plain));
  TEST_TRUE(plain->nlev == bes->nlev && plain->blk_max == bes->blk_max);
  for (int l = 0; l + 1 < bes->nlev && l + 1 < plain->nlev; l++)
    TEST_TRUE(fcm__schwarz_same_positions(bes->lev[l].blk, plain->lev[l].blk));
  fcm_mg_destroy(&plain);
  return bes;
}

/* Carries whose coarsest analysis took the old hierarchy's ordering. */
static int orderings_taken;

/* Two hierarchies on p's pattern: the second takes the first's Galerkin storage after the
 * first's set-up (every array: the same sizes), and both set up equal `ref` bit for bit. */
static void same_pattern_take(fcm_ctx *ctx, const problem *p, const fcm_csr *pattern,
                              const unsigned char *inactive, const fcm_mg_options *o, fcm_mg *ref)
{
  fcm_mg *a = NULL, *b = NULL;
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, NULL, p->space, pattern, inactive, o, &a));
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, NULL, p->space, pattern, inactive, o, &b));
  if (!a || !b) goto done;
  TEST_OK(ctx, fcm_mg_setup(a));
  TEST_TRUE(a->nlev == b->nlev && a->nlev >= 2);
  TEST_TRUE(fcm__mg_take_scratch(a, b) == 0); /* a is set up: it takes nothing */
  TEST_TRUE(fcm__mg_take_scratch(NULL, a) == 0 && fcm__mg_take_scratch(b, NULL) == 0);
  TEST_TRUE(fcm__mg_take_scratch(b, b) == 0);
  const void *ap[MG_MAX_LEVELS], *cv[MG_MAX_LEVELS];
  for (int l = 0; l + 1 < a->nlev; l++) {
    ap[l] = fcm__ptap_scratch(a->lev[l].ptap);
    cv[l] = fcm_csr_values_read(a->lev[l + 1].Aown);
  }
  TEST_TRUE(fcm__mg_take_scratch(b, a) == 2 * (a->nlev - 1));
  for (int l = 0; l + 1 < b->nlev; l++) {
    TEST_TRUE(fcm__ptap_scratch(b->lev[l].ptap) == ap[l] && !fcm__ptap_scratch(a->lev[l].ptap));
    TEST_TRUE(fcm_csr_values_read(b->lev[l + 1].Aown) == cv[l]);
  }
  fcm_mg_destroy(&a); /* all it can do now */
  TEST_OK(ctx, fcm_mg_setup(b));
  TEST_TRUE(mgc_same(ctx, b, ref, p->b, p->n, 2));
done:
  fcm_mg_destroy(&a);
  fcm_mg_destroy(&b);
}

/* Arrays the carried hierarchies took from the old ones (fcm__mg_take_scratch()). */
static int scratch_taken;

/* The hierarchy carried from old (NULL: none; on prev's space) to p's pattern, then set up,
 * against fcm_mg_create() and the reference pattern; *pattern: its level-0 matrix. */
static fcm_mg *carry_and_compare(fcm_ctx *ctx, fcm_mg *old, const fcm_space *prev, const problem *p,
                                 const fcm_mg_options *o, const char *what, fcm_csr **pattern)
{
  fcm_mg *prep = NULL, *fresh = NULL;
  unsigned char *inactive = mgc_eliminated(p->A, p->n);
  TEST_OK(ctx, fcm_space_matrix_create(p->space, pattern));
  TEST_OK(ctx, fcm__mg_create_pattern_cut(ctx, old, prev, p->space, *pattern, inactive, o, &prep));
  { /* the block smoothers' positions, copied or scanned, those a creation without old finds */
    fcm_mg *plain = NULL;
    TEST_OK(ctx, fcm__mg_create_pattern(ctx, NULL, p->space, *pattern, inactive, o, &plain));
    TEST_TRUE(plain->nlev == prep->nlev);
    /* the mesh grid: the old hierarchy's shared (one mesh), the one a creation finds */
    const mg_grid *g = prep->mesh_grid, *h = plain->mesh_grid;
    TEST_TRUE(g && h && g != h && h->refs == 1 && g->mesh == h->mesh);
    TEST_TRUE(old ? g == old->mesh_grid && g->refs >= 2 : g->refs == 1);
    if (g && h) {
      const fcm_index nn = fcm_mesh_num_nodes(h->mesh), nc = fcm_mesh_num_cells(h->mesh);
      TEST_TRUE(memcmp(g->grid, h->grid, sizeof g->grid) == 0 &&
                memcmp(g->bits_of, h->bits_of, sizeof g->bits_of) == 0 &&
                memcmp(g->node2, h->node2, sizeof *g->node2 * 3 * (size_t)nn) == 0 &&
                memcmp(g->cell_ijk, h->cell_ijk, sizeof *g->cell_ijk * 3 * (size_t)nc) == 0 &&
                memcmp(g->cell_at, h->cell_at,
                       sizeof *g->cell_at * (size_t)(h->grid[0] * h->grid[1] * h->grid[2])) == 0);
    }
    for (int l = 0; l + 1 < prep->nlev && l + 1 < plain->nlev; l++)
      TEST_TRUE(fcm__schwarz_same_positions(prep->lev[l].blk, plain->lev[l].blk));
    size_t np = 0;
    int *pos = fcm__schwarz_positions(prep->lev[0].blk, &np);
    TEST_TRUE(np > 0);
    if (np > 0) { /* the control: one position off is seen */
      pos[np / 2] += 1;
      TEST_TRUE(!fcm__schwarz_same_positions(prep->lev[0].blk, plain->lev[0].blk));
      pos[np / 2] -= 1;
    }
    fcm_mg_destroy(&plain);
  }
  fcm_mg *bes = beside_carry(ctx, old, prev, p->space, *pattern, inactive, o);
  memcpy(fcm_csr_values(*pattern), fcm_csr_values_read(p->A),
         sizeof(double) * (size_t)fcm_csr_row_ptr(p->A)[p->n]);
  { /* no cycle before the values are set up */
    double *x = calloc((size_t)p->n + 1, sizeof *x);
    TEST_TRUE(x != NULL);
    if (x) TEST_ERR(ctx, fcm_mg_cycle(prep, p->b, x), FCM_ERR_ARG, "no values yet");
    if (x) TEST_ERR(ctx, fcm_mg_solve(prep, p->b, x, 1e-8, 2, NULL), FCM_ERR_ARG, "no values yet");
    free(x);
  }
  /* as an integrator's cut: the old hierarchy is destroyed after this (its patterns are still
   * compared below) */
  if (old) scratch_taken += fcm__mg_take_scratch(prep, old);
  TEST_OK(ctx, fcm_mg_setup(prep));
  TEST_OK(ctx, fcm_mg_setup(bes));
  TEST_TRUE(mgc_same(ctx, prep, bes, p->b, p->n, 2));
  fcm_mg_destroy(&bes);
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, o, &fresh));
  if (!old) same_pattern_take(ctx, p, *pattern, inactive, o, fresh);
  const int same = mgc_same(ctx, prep, fresh, p->b, p->n, 2);
  int exact = 1;
  fcm_index coarse_rows = 0;
  for (int l = 0; l + 1 < prep->nlev; l++) {
    fcm_index row_slabs = 0, block_slabs = 0;
    exact &= mgc_galerkin_exact(prep, l);
    TEST_OK(ctx, fcm__mg_slabs_check(prep, l, &row_slabs, &block_slabs));
    coarse_rows += prep->lev[l + 1].n;
  }
  fcm__mg_kept k;
  fcm__mg_get_kept(prep, &k);
  if (getenv("FCM_TEST_VERBOSE"))
    printf("%s: %d levels, %lld DOFs; plans carried %d, rows of A P taken %lld of %lld, coarse "
           "rows %lld of %lld, blocks' positions copied %lld (level 0 has %lld), coarsest "
           "ordering %s; %s fcm_mg_create(), structure %s the references\n",
           what, fcm_mg_num_levels(prep), (long long)p->n, k.carried_plans,
           (long long)k.carried_ap_rows,
           (long long)(coarse_rows - prep->lev[prep->nlev - 1].n + p->n),
           (long long)k.carried_coarse_rows, (long long)coarse_rows, (long long)k.carried_blocks,
           (long long)fcm__schwarz_num_blocks(prep->lev[0].blk),
           k.carried_ordering ? "taken" : "found", same ? "equals" : "DIFFERS from",
           exact ? "equals" : "DIFFERS from");
  TEST_TRUE(fcm_mg_num_levels(prep) >= 3);
  { /* the coarsest analysis took the old ordering only where the coarsest patterns agree */
    const int lc = prep->nlev - 1;
    const int same_coarsest = old && old->nlev == prep->nlev && fcm__mg_level_same(old, prep, lc);
    TEST_TRUE(k.carried_ordering <= same_coarsest); /* CHOLMOD may postorder it otherwise */
    orderings_taken += k.carried_ordering;
  }
  TEST_TRUE(same);
  TEST_TRUE(exact);
  if (old) { /* rows taken on every level both have (the body is small: a cut reaches much) */
    TEST_TRUE(k.carried_plans == FCM_MIN(old->nlev, prep->nlev) - 1);
    TEST_TRUE(k.carried_ap_rows > p->n / 3);
    TEST_TRUE(k.carried_coarse_rows > coarse_rows / 5);
    TEST_TRUE(k.carried_blocks > fcm__schwarz_num_blocks(prep->lev[0].blk) / 3);
  } else {
    TEST_TRUE(k.carried_blocks == 0);
  }
  fcm_mg_destroy(&fresh);
  free(inactive);
  return prep;
}

/* A carry made beside by one thread of a team of two while the other waits, without a task
 * scheduling point, until the creation has returned: level 0's task then runs at the team's
 * barrier (libgomp runs no other task at the creation's own task loops), after the coarser
 * levels, so that the allocations come in one order, the creation's then the task's.
 * *at_return: the allocations counted when the creation returned; *team: the team's threads
 * (with one, the task runs in the creation). */
static fcm_status held_beside(fcm_ctx *ctx, failing *fl, const fcm_mg *old, const problem *cur,
                              const problem *next, const fcm_mg_options *o,
                              const unsigned char *inactive, fcm_mg **mg, long long *at_return,
                              int *team)
{
  fcm_status st = FCM_OK;
  int done = 0;
#pragma omp parallel num_threads(2)
  {
#pragma omp single nowait
    {
      *team = omp_get_num_threads();
      st = fcm__mg_create_pattern_cut_beside(ctx, old, cur->space, next->space, next->A, inactive,
                                             o, mg);
      *at_return = __atomic_load_n(&fl->count, __ATOMIC_RELAXED);
#pragma omp atomic write
      done = 1;
    }
    for (int d = 0; !d;) {
#pragma omp atomic read
      d = done;
    }
  }
  return st;
}

/* Allocations made to fail in each of the two parts of a carry made beside. */
enum { BESIDE_FAILURES = 12 };

/* Carries made beside (held_beside(), joined after the barrier) whose allocations fail, at
 * places spread over the creation's and over level 0's task's: FCM_ERR_ALLOC from the
 * creation for the first, from the join for the second (the creation then succeeds, its task
 * pending), nothing leaked (the failed hierarchy destroyed). */
static void failing_besides(const fcm_mg *old, const problem *cur, const problem *next,
                            const fcm_mg_options *o, const unsigned char *inactive)
{
  failing fl = {0, -1};
  fcm_ctx *fctx = failing_ctx_with(&fl, failing_alloc_atomic); /* the two threads allocate */
  TEST_TRUE(fctx != NULL);
  if (!fctx) return;
  fcm_mg *mg = NULL;
  long long made = 0;
  int team = 0;
  TEST_OK(fctx, held_beside(fctx, &fl, old, cur, next, o, inactive, &mg, &made, &team));
  if (team < 2) { /* no team to leave the task to: nothing to test here */
    fcm_mg_destroy(&mg);
    fcm_ctx_destroy(&fctx);
    return;
  }
  TEST_TRUE(mg && mg->beside != NULL); /* the task was left pending */
  TEST_OK(fctx, fcm__mg_join(mg, NULL));
  const long long total = fl.count;
  TEST_TRUE(made > 1 && total > made + 1); /* both parts allocate */
  fcm_mg_destroy(&mg);
  const long long live = fcm_ctx_live_allocations(fctx);
  int in_create = 0, in_join = 0;
  for (int part = 0; part < 2; part++)
    for (int q = 0; q < BESIDE_FAILURES; q++) {
      const long long lo = part ? made : 0, n = part ? total - made : made;
      long long at = 0;
      fl.count = 0, fl.fail_at = lo + q * n / BESIDE_FAILURES;
      fcm_status st = held_beside(fctx, &fl, old, cur, next, o, inactive, &mg, &at, &team);
      if (part == 0) {
        in_create += st == FCM_ERR_ALLOC && mg == NULL;
      } else if (st == FCM_OK) {
        st = fcm__mg_join(mg, NULL);
        in_join += st == FCM_ERR_ALLOC;
        fcm_mg_destroy(&mg);
      }
      fl.fail_at = -1;
      fcm_ctx_error_clear(fctx);
      TEST_TRUE(fcm_ctx_live_allocations(fctx) == live);
    }
  TEST_TRUE(in_create == BESIDE_FAILURES);
  TEST_TRUE(in_join == BESIDE_FAILURES);
  fcm_ctx_destroy(&fctx);
}

/* Carries from old whose allocations fail at several places: FCM_ERR_ALLOC, nothing leaked,
 * old's cycles as before. */
static void failing_carries(fcm_ctx *ctx, fcm_mg *old, const problem *cur, const problem *next,
                            const fcm_mg_options *o)
{
  failing fl = {0, -1};
  fcm_ctx *fctx = failing_ctx(&fl);
  TEST_TRUE(fctx != NULL);
  const size_t bytes = sizeof(double) * 2 * (size_t)cur->n;
  double *x0 = malloc(bytes), *x1 = malloc(bytes);
  mgc_cycles(ctx, old, cur->b, cur->n, 2, x0);
  unsigned char *inactive = mgc_eliminated(next->A, next->n);
  fcm_mg *mg = NULL;
  /* the number of allocations of a carry that succeeds */
  TEST_OK(fctx, fcm__mg_create_pattern_cut(fctx, old, cur->space, next->space, next->A, inactive, o,
                                           &mg));
  const long long total = fl.count;
  fcm_mg_destroy(&mg);
  const long long live = fcm_ctx_live_allocations(fctx);
  int failures = 0;
  for (int q = 0; q < 6; q++) {
    fl.count = 0, fl.fail_at = q * total / 6 + 1;
    const fcm_status st =
        fcm__mg_create_pattern_cut(fctx, old, cur->space, next->space, next->A, inactive, o, &mg);
    fl.fail_at = -1;
    failures += st == FCM_ERR_ALLOC && mg == NULL;
    fcm_ctx_error_clear(fctx);
    TEST_TRUE(fcm_ctx_live_allocations(fctx) == live);
  }
  TEST_TRUE(failures == 6);
  failing_besides(old, cur, next, o, inactive);
  mgc_cycles(ctx, old, cur->b, cur->n, 2, x1);
  TEST_TRUE(memcmp(x0, x1, bytes) == 0);
  free(inactive);
  free(x0);
  free(x1);
  fcm_ctx_destroy(&fctx);
}

/* A without its stored zeros off the diagonal (the clamped rows' and columns'): the same
 * operator on a pattern that is not the space's. The assembled values are exactly symmetric,
 * so an entry goes with its transpose and the pattern stays symmetric. */
static fcm_csr *zeros_dropped(fcm_ctx *ctx, const fcm_csr *A)
{
  fcm_index n = 0, nnz = 0, m = 0;
  fcm_csr *B = NULL;
  fcm_csr_get_size(A, &n, NULL, &nnz);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  fcm_index *ri = malloc(sizeof *ri * (size_t)(nnz + 1)),
            *cj = malloc(sizeof *cj * (size_t)(nnz + 1));
  double *w = malloc(sizeof *w * (size_t)(nnz + 1));
  for (fcm_index i = 0; i < n; i++)
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      if (ci[p] == i || v[p] != 0.0) ri[m] = i, cj[m] = ci[p], w[m++] = v[p];
  TEST_TRUE(m < nnz);
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, n, n, m, ri, cj, w, FCM_CSR_SYMMETRIC, &B));
  free(ri);
  free(cj);
  free(w);
  return B;
}

/* Hierarchies of cur's numbering that must not be carried: made on another space of cur's
 * rules (olds[0], its pattern) and on cur's space with a matrix of another pattern (olds[1]). Made
 * before the cut takes cur's pattern; mats[] their matrices, spaces[0] the other space. */
static void uncarriable(fcm_ctx *ctx, const problem *cur, const fcm_cell_rules *rules,
                        const fcm_mg_options *o, fcm_mg *olds[2], fcm_csr *mats[2],
                        fcm_space **other)
{
  fcm_space_options so = fcm_space_options_default();
  unsigned char *inactive = mgc_eliminated(cur->A, cur->n);
  TEST_OK(ctx, fcm_space_create_embedded_with(ctx, cur->mesh, rules, &so, other));
  TEST_TRUE(fcm_space_num_dofs(*other) == cur->n);
  TEST_OK(ctx, fcm_space_matrix_create(*other, &mats[0]));
  mats[1] = zeros_dropped(ctx, cur->A);
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, NULL, *other, mats[0], inactive, o, &olds[0]));
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, NULL, cur->space, mats[1], inactive, o, &olds[1]));
  free(inactive);
}

/* Carries whose preconditions fail: from olds[] (uncarriable()), and from `old` (carriable)
 * onto next's matrix on another pattern. Each gives fcm_mg_create()'s hierarchy on its
 * matrix with nothing taken, and no error. */
static void plain_carries(fcm_ctx *ctx, fcm_mg *const olds[2], const fcm_mg *old,
                          const problem *cur, const problem *next, const fcm_mg_options *o)
{
  unsigned char *inactive = mgc_eliminated(next->A, next->n);
  fcm_csr *dropped = zeros_dropped(ctx, next->A);
  fcm_mg *fresh[2] = {NULL, NULL};
  TEST_OK(ctx, fcm_mg_create(ctx, next->space, next->A, o, &fresh[0]));
  TEST_OK(ctx, fcm_mg_create(ctx, next->space, dropped, o, &fresh[1]));
  for (int q = 0; q < 3; q++) {
    fcm_mg *mg = NULL;
    fcm_csr *A = q < 2 ? next->A : dropped;
    TEST_OK(ctx, fcm__mg_create_pattern_cut(ctx, q < 2 ? olds[q] : old, cur->space, next->space, A,
                                            inactive, o, &mg));
    TEST_OK(ctx, fcm_mg_setup(mg));
    fcm__mg_kept k;
    fcm__mg_get_kept(mg, &k);
    TEST_TRUE(k.carried_plans == 0 && k.carried_ap_rows == 0 && k.carried_coarse_rows == 0 &&
              k.carried_blocks == 0);
    TEST_TRUE(mgc_same(ctx, mg, fresh[q == 2], next->b, next->n, 2));
    fcm_mg_destroy(&mg);
  }
  fcm_mg_destroy(&fresh[0]);
  fcm_mg_destroy(&fresh[1]);
  fcm_csr_destroy(&dropped);
  free(inactive);
}

/* The cut sequence on `type`, a V-cycle and a W-cycle hierarchy carried along it. */
static void cut_sequence(fcm_ctx *ctx, fcm_element_type type)
{
  const char *name = type == FCM_ELEMENT_HEX8 ? "hex8" : "hex20";
  problem base;
  problem_hemisphere_of(ctx, type, 8, 0, fcm_space_options_default().constrain_ratio, &base);
  fcm_mg_options o[2] = {fcm_mg_options_default(), fcm_mg_options_default()};
  fcm_mg *mg[2] = {NULL, NULL};
  fcm_csr *pattern[2] = {NULL, NULL};
  char what[96];
  for (int c = 0; c < 2; c++) {
    o[c].coarse_dofs = 100;
    o[c].cycle_index = c + 1;
    o[c].block_fraction = c ? 0.5 : 1.0; /* the blocks of the cells with a small piece */
    snprintf(what, sizeof what, "%s, cycle %d, before the cuts", name, c + 1);
    mg[c] = carry_and_compare(ctx, NULL, NULL, &base, &o[c], what, &pattern[c]);
  }
  const double pt[3][3] = {{0.05, 0, 0}, {0, 0, 0.13}, {0.5, 0.5, 0.5}};
  const double nrm[3][3] = {{1, 0, 0}, {0, 0.2, 1}, {1, 1, 1}};
  const double blo[3][3] = {{-0.1, 0.4, -2}, {-2, 0.6, -0.5}, {-2, -2, -2}};
  const double bhi[3][3] = {{0.2, 2, 2}, {2, 2, 0.5}, {2, 2, 2}};
  const fcm_cell_rules *prev = base.rules0;
  fcm_cell_rules *rules[3] = {NULL, NULL, NULL};
  problem cur = base; /* the base's space and matrix first, then each cut's */
  int cur_is_base = 1;
  for (int k = 0; k < 3; k++) {
    fcm_surface *s = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, pt[k], nrm[k], blo[k], bhi[k], &s));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, base.mesh, base.geom, prev, s, &rules[k]));
    fcm_surface_destroy(&s);
    fcm_mg *olds[2] = {NULL, NULL};
    fcm_csr *mats[2] = {NULL, NULL};
    fcm_space *other = NULL;
    if (k == 0) uncarriable(ctx, &cur, prev, &o[0], olds, mats, &other);
    prev = rules[k];
    problem next;
    problem_cut(ctx, &base, rules[k], cur.space, &next);
    failing_carries(ctx, mg[0], &cur, &next, &o[0]);
    if (k == 0) plain_carries(ctx, olds, mg[0], &cur, &next, &o[0]);
    for (int q = 0; q < 2; q++) {
      fcm_mg_destroy(&olds[q]);
      fcm_csr_destroy(&mats[q]);
    }
    fcm_space_destroy(&other);
    for (int c = 0; c < 2; c++) { /* as a cut: the old level-0 matrix goes first */
      fcm__mg_detach(mg[c]);
      fcm_csr_destroy(&pattern[c]);
      fcm_mg *carried = NULL;
      snprintf(what, sizeof what, "%s, cycle %d, cut %d", name, c + 1, k + 1);
      carried = carry_and_compare(ctx, mg[c], cur.space, &next, &o[c], what, &pattern[c]);
      fcm_mg_destroy(&mg[c]);
      mg[c] = carried;
    }
    fcm__space_cut_keep(next.space); /* the cut holds: the old space is destroyed next */
    if (cur_is_base) {
      base.space = NULL, base.A = NULL, base.b = NULL; /* now cur's, dropped below */
      cur_is_base = 0;
    }
    problem_drop(&cur);
    cur = next;
  }
  for (int c = 0; c < 2; c++) {
    fcm_mg_destroy(&mg[c]);
    fcm_csr_destroy(&pattern[c]);
  }
  problem_drop(&cur);
  for (int k = 0; k < 3; k++)
    fcm_cell_rules_destroy(&rules[k]);
  problem_free(&base);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  cut_sequence(ctx, FCM_ELEMENT_HEX8);
  cut_sequence(ctx, FCM_ELEMENT_HEX20);
  TEST_TRUE(orderings_taken >= 2); /* the first cut of each element keeps the coarsest pattern */
  if (getenv("FCM_TEST_VERBOSE"))
    printf("Galerkin arrays the carried hierarchies took from the old ones: %d\n", scratch_taken);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
