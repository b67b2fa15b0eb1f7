/* The pointwise sweeps by a team of two (sweeps.c): a row order of three slabs, the thin one
 * swept first, has a lead of whole copies from row 0 whose rows reach no row of the thin slab
 * or beyond, at most the work that balances the threads; SGS steps by two threads, several in
 * a row without a barrier between them, give bit for bit the iterate of one thread, on the
 * uncut cube and on the cut hemisphere (Hex8), on every level where the lead applies; the
 * block slabs of each colour go to one of the two threads each. */
#include "mg/levels_impl.h"
#include "mg_util.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>

/* lead's invariants on the row order of L; 1 when the split path applies with two threads */
static int check_lead(const mg_level *L, int l)
{
  const slab_order *S = &L->rows;
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  if (S->nslab != 3 || S->first != 1) {
    TEST_TRUE(S->lead == 0 && S->tail == 0);
    return 0;
  }
  double w[3] = {0.0, 0.0, 0.0}, lead_work = 0.0;
  for (int k = 0; k < 3; k++)
    for (fcm_index q = S->ptr[k]; q < S->ptr[k + 1]; q++)
      w[k] += (double)(rp[S->item[q] + 1] - rp[S->item[q]]);
  TEST_TRUE(S->ptr[0] == 0 && S->lead == S->tail && S->lead % 3 == 0);
  TEST_TRUE(S->lead >= 0 && S->lead <= S->ptr[1]);
  for (fcm_index i = 0; i < S->lead; i++) {
    TEST_TRUE(S->item[i] == i);
    lead_work += (double)(rp[i + 1] - rp[i]);
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      if (ci[p] >= S->ptr[1]) {
        TEST_FAIL_("level %d: row %lld of the lead couples with row %d (thin slab from %lld)", l,
                   (long long)i, ci[p], (long long)S->ptr[1]);
        return 0;
      }
  }
  TEST_TRUE(lead_work <= fmin(w[1], w[0] - w[2]) || S->lead == 0);
  printf("level %d: %lld rows, slabs of %lld / %lld / %lld rows, work %.0f / %.0f / %.0f, "
         "lead %lld rows (work %.0f)\n",
         l, (long long)L->n, (long long)S->ptr[1], (long long)(S->ptr[2] - S->ptr[1]),
         (long long)(S->ptr[3] - S->ptr[2]), w[0], w[1], w[2], (long long)S->lead, lead_work);
  return S->lead > 0 && fcm__mg_slab_mine(S, 0, 0, 2) && fcm__mg_slab_mine(S, 1, 1, 2) &&
         fcm__mg_slab_mine(S, 2, 1, 2);
}

/* Three SGS steps on level l by a team of nt, from x0 into x. */
static void smooth(const fcm_mg *mg, int l, int nt, const double *b, const double *x0, double *x)
{
  mg_level *L = (mg_level *)&mg->lev[l];
  memcpy(x, x0, sizeof *x * (size_t)L->n);
#pragma omp parallel num_threads(nt)
  {
    TEST_TRUE(omp_get_num_threads() == nt);
    for (int s = 0; s < 3; s++)
      fcm__mg_smooth(mg, L, b, x, 0);
  }
}

static int check(fcm_ctx *ctx, const problem *p)
{
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 100;
  fcm_mg *mg = NULL;
  int split = 0;
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, &o, &mg));
  if (!mg) return 0;
  for (int l = 0; l + 1 < mg->nlev; l++) {
    const mg_level *L = &mg->lev[l];
    const fcm_index n = L->n;
    const int applies = check_lead(L, l);
    split += applies;
    double *b = malloc(sizeof *b * (size_t)n), *x0 = malloc(sizeof *x0 * (size_t)n);
    double *x1 = malloc(sizeof *x1 * (size_t)n), *x2 = malloc(sizeof *x2 * (size_t)n);
    for (fcm_index i = 0; i < n; i++) {
      b[i] = sin(0.37 * (double)i);
      x0[i] = 1e-3 * cos(0.11 * (double)i);
    }
    smooth(mg, l, 1, b, x0, x1);
    smooth(mg, l, 2, b, x0, x2);
    double move = 0.0;
    for (fcm_index i = 0; i < n; i++)
      move = fmax(move, fabs(x1[i] - x0[i]));
    TEST_TRUE(move > 0.0);
    if (memcmp(x1, x2, sizeof *x1 * (size_t)n))
      TEST_FAIL_("level %d (split %d): two threads' SGS iterate differs from one thread's", l,
                 applies);
    /* every block slab has one owner of the two threads */
    const slab_order *B = &L->blocks;
    for (fcm_index s = 0; s < B->nslab; s++) {
      TEST_TRUE(B->mid[s] >= 0.0 && B->mid[s] < 1.0);
      TEST_TRUE(fcm__mg_slab_mine(B, s, 0, 2) + fcm__mg_slab_mine(B, s, 1, 2) == 1);
    }
    free(b), free(x0), free(x1), free(x2);
  }
  fcm_mg_destroy(&mg);
  return split;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  omp_set_dynamic(0);
  problem p;
  problem_cube(ctx, 16, &p);
  TEST_TRUE(check(ctx, &p) >= 1); /* level 0 at least takes the split path */
  problem_free(&p);
  problem_hemisphere(ctx, 16, 1, &p);
  TEST_TRUE(check(ctx, &p) >= 1);
  problem_free(&p);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
