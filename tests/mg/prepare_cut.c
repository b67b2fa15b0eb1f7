/* The hierarchy a cut prepares (fcm__mg_create_pattern() from the hierarchy before the cut,
 * detached, on the new matrix's pattern, then fcm_mg_setup() with the values) after each cut of
 * a sequence equals the one fcm_mg_create() builds on the new space and matrix, bit for bit
 * (every level's matrix, pattern and values, its inactive rows, and two cycles, memcmp), and
 * its structure equals references computed here the plain way, independently of the
 * creation's shortcuts (a node's repeated rows copied, sorted rows' last columns, level 0's
 * diagonal positions from the copy graph, the block
 * positions read once for a node's three rows, storage taken from the earlier hierarchy):
 * each coarse level's pattern is the structural pattern of P^T A P with the diagonal (a dense
 * table), the rows' groups of three of one pattern are those a full comparison finds, and the
 * row and block slabs are sound (fcm__mg_slabs_check()). The embedded hemisphere of mg_util.h,
 * Hex8 and Hex20, V- and W-cycles, cut three times (partial planes: the first splits the top,
 * the second crosses it, the third cuts off a corner). */
#include "mg/levels_impl.h"
#include "mg_compare.h"
#include "mg_util.h"

#include <math.h>
#include <stdio.h>

/* A matrix of A's pattern, every value NaN (a value read before the setup shows). */
static fcm_csr *nan_copy(fcm_ctx *ctx, const problem *p)
{
  fcm_csr *P = NULL;
  fcm_index nnz = 0;
  TEST_OK(ctx, fcm_space_matrix_create(p->space, &P));
  fcm_csr_get_size(P, NULL, NULL, &nnz);
  double *v = fcm_csr_values(P);
  for (fcm_index k = 0; k < nnz; k++)
    v[k] = NAN;
  return P;
}

/* Are the row order's groups of three (triple) those a full comparison of the rows finds, and
 * flagged FCM__MG_TRIPLE_NODES exactly where their columns come in whole nodes? */
static int triples_exact(const fcm_mg *mg, int l)
{
  const mg_level *L = &mg->lev[l];
  if (!L->rows.triple) return 1;
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  int same = 1, groups = 0;
  for (fcm_index i = 0; i + 2 < L->n && same; i += 3) {
    const fcm_index len = rp[i + 1] - rp[i];
    int t = rp[i + 2] - rp[i + 1] == len && rp[i + 3] - rp[i + 2] == len, own = 0;
    for (fcm_index q = 0; t && q < len; q++) {
      t = ci[rp[i] + q] == ci[rp[i + 1] + q] && ci[rp[i] + q] == ci[rp[i + 2] + q];
      if (ci[rp[i] + q] == i)
        own = q + 2 < len && ci[rp[i] + q + 1] == i + 1 && ci[rp[i] + q + 2] == i + 2;
    }
    t = t && own;
    groups += t;
    int nodes = t && len % 3 == 0;
    for (fcm_index q = rp[i]; nodes && q < rp[i + 1]; q += 3)
      nodes = ci[q] % 3 == 0 && ci[q + 1] == ci[q] + 1 && ci[q + 2] == ci[q] + 2;
    t = !t ? 0 : nodes ? FCM__MG_TRIPLE_NODES : FCM__MG_TRIPLE;
    same = L->rows.triple[i] == t;
    if (!same)
      printf("  level %d: rows %lld..+2 flagged %d, are %d\n", l, (long long)i, L->rows.triple[i],
             t);
  }
  return same && groups > 0;
}

/* Are level l's diagonal positions those a plain search of each row finds? Level 0's (from the
 * space's copy graph, fcm__mg_space_diag(), which must apply to a matrix of the space's pattern)
 * also found again by it, and the rows' reach of fcm__mg_space_reach() their last columns. */
static int diag_exact(const fcm_mg *mg, int l)
{
  const mg_level *L = &mg->lev[l];
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  int same = 1;
  for (fcm_index i = 0; i < L->n && same; i++) {
    fcm_index p = rp[i];
    while (p < rp[i + 1] && ci[p] != i)
      p++;
    same = p < rp[i + 1] && L->diag[i] == p;
    if (!same)
      printf("  level %d: row %lld's diagonal at %lld, is at %lld\n", l, (long long)i,
             (long long)L->diag[i], (long long)p);
  }
  if (l == 0 && same) {
    fcm_index *d = malloc(sizeof *d * (size_t)(L->n + 1));
    TEST_TRUE(d != NULL);
    same = fcm__mg_space_diag(mg, d) && memcmp(d, L->diag, sizeof *d * (size_t)L->n) == 0;
    if (!same) printf("  level 0: the copy graph's diagonal positions differ or do not apply\n");
    /* the rows' reach (row slabs): the larger of the row and its last column */
    same = same && fcm__mg_space_reach(mg, d);
    for (fcm_index i = 0; i < L->n && same; i++) {
      const fcm_index want = rp[i + 1] > rp[i] ? FCM_MAX(i, (fcm_index)ci[rp[i + 1] - 1]) : i;
      same = d[i] == want;
      if (!same)
        printf("  level 0: row %lld reaches %lld, the copy graph says %lld\n", (long long)i,
               (long long)want, (long long)d[i]);
    }
    free(d);
  }
  return same;
}

/* The space and clamped matrix of `rules` (mesh and geometry borrowed from base). */
static void problem_on(fcm_ctx *ctx, const problem *base, const fcm_cell_rules *rules, problem *p)
{
  memset(p, 0, sizeof *p);
  p->mesh = base->mesh;
  TEST_OK(ctx, fcm_space_create_embedded(ctx, p->mesh, rules, &p->space));
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

/* The hierarchy prepared from *old (consumed; detached) on p's pattern, then set up, against
 * fcm_mg_create() and the references. Returns the prepared one and its pattern matrix. */
static fcm_mg *prepare_and_compare(fcm_ctx *ctx, fcm_mg **old, const problem *p,
                                   const fcm_mg_options *o, const char *what, fcm_csr **pattern)
{
  fcm_mg *prep = NULL, *fresh = NULL;
  unsigned char *inactive = mgc_eliminated(p->A, p->n);
  *pattern = nan_copy(ctx, p);
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, old, p->space, *pattern, inactive, o, &prep));
  TEST_TRUE(*old == NULL);
  memcpy(fcm_csr_values(*pattern), fcm_csr_values_read(p->A),
         sizeof(double) * (size_t)fcm_csr_row_ptr(p->A)[p->n]);
  TEST_OK(ctx, fcm_mg_setup(prep));
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, o, &fresh));
  const int same = mgc_same(ctx, prep, fresh, p->b, p->n, 2);
  int exact = 1, nblk = 0;
  for (int l = 0; l + 1 < prep->nlev; l++) {
    fcm_index row_slabs = 0, block_slabs = 0;
    exact &= mgc_galerkin_exact(prep, l) && triples_exact(prep, l) && diag_exact(prep, l);
    TEST_OK(ctx, fcm__mg_slabs_check(prep, l, &row_slabs, &block_slabs));
    nblk += prep->lev[l].blk != NULL;
  }
  printf("%s: %d levels, %lld DOFs, %d levels with block smoothers; prepared from the hierarchy "
         "before %s fcm_mg_create(), structure %s the references\n",
         what, fcm_mg_num_levels(prep), (long long)p->n, nblk, same ? "equals" : "DIFFERS from",
         exact ? "equals" : "DIFFERS from");
  TEST_TRUE(fcm_mg_num_levels(prep) >= 3 && nblk > 0);
  TEST_TRUE(same);
  TEST_TRUE(exact);
  fcm_mg_destroy(&fresh);
  free(inactive);
  return prep;
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
    snprintf(what, sizeof what, "%s, cycle %d, before the cuts", name, c + 1);
    mg[c] = prepare_and_compare(ctx, &mg[c], &base, &o[c], what, &pattern[c]);
  }
  const double pt[3][3] = {{0.05, 0, 0}, {0, 0, 0.13}, {0.5, 0.5, 0.5}};
  const double nrm[3][3] = {{1, 0, 0}, {0, 0.2, 1}, {1, 1, 1}};
  const double blo[3][3] = {{-0.1, 0.4, -2}, {-2, 0.6, -0.5}, {-2, -2, -2}};
  const double bhi[3][3] = {{0.2, 2, 2}, {2, 2, 0.5}, {2, 2, 2}};
  const fcm_cell_rules *prev = base.rules0;
  fcm_cell_rules *rules[3] = {NULL, NULL, NULL};
  problem cur;
  memset(&cur, 0, sizeof cur);
  for (int k = 0; k < 3; k++) {
    fcm_surface *s = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, pt[k], nrm[k], blo[k], bhi[k], &s));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, base.mesh, base.geom, prev, s, &rules[k]));
    fcm_surface_destroy(&s);
    prev = rules[k];
    for (int c = 0; c < 2; c++) { /* as a cut: the old matrix and space go first */
      fcm__mg_detach(mg[c]);
      fcm_csr_destroy(&pattern[c]);
    }
    problem_drop(&cur);
    problem next;
    problem_on(ctx, &base, rules[k], &next);
    for (int c = 0; c < 2; c++) {
      snprintf(what, sizeof what, "%s, cycle %d, cut %d", name, c + 1, k + 1);
      mg[c] = prepare_and_compare(ctx, &mg[c], &next, &o[c], what, &pattern[c]);
    }
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
  fcm_ctx_destroy(&ctx);
  printf("ok\n");
  return TEST_RESULT();
}
