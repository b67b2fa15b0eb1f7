/* A hierarchy created on a matrix's pattern before its values exist (fcm__mg_create_pattern(),
 * what a cut builds for the step after it) and then set up with the values (fcm_mg_setup())
 * equals the one fcm_mg_create() builds on the same matrix, bit for bit: the levels, every
 * level's matrix (pattern and values), and the output of cycles applied to a vector (memcmp),
 * on the cut hemisphere of mg_util.h with Hex8 and Hex20, V- and W-cycles. The pattern's matrix
 * holds NaN until the setup: a value read at creation would show in the results. Created from an
 * earlier hierarchy on the same pattern it keeps every plan, row order, block smoother and the
 * coarsest analysis and still gives the same bits. Given other Dirichlet rows than the
 * matrix's eliminated ones, the setup refuses (FCM_ERR_ARG: create it again). */
#include "mg/levels_impl.h"
#include "mg_compare.h"
#include "mg_util.h"

#include <math.h>
#include <stdio.h>

/* A matrix of A's pattern, every value NaN. */
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

static void copy_values(const fcm_csr *from, fcm_csr *to)
{
  fcm_index nnz = 0;
  fcm_csr_get_size(from, NULL, NULL, &nnz);
  memcpy(fcm_csr_values(to), fcm_csr_values_read(from), sizeof(double) * (size_t)nnz);
}

static void prepare_case(fcm_ctx *ctx, fcm_element_type type, int cycle_index)
{
  const char *name = type == FCM_ELEMENT_HEX8 ? "hex8" : "hex20";
  problem p;
  problem_hemisphere_of(ctx, type, 8, 1, fcm_space_options_default().constrain_ratio, &p);
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 100;
  o.cycle_index = cycle_index;
  unsigned char *inactive = mgc_eliminated(p.A, p.n);
  fcm_csr *P = nan_copy(ctx, &p);
  fcm_mg *prep = NULL, *fresh = NULL;
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, NULL, p.space, P, inactive, &o, &prep));
  copy_values(p.A, P);
  TEST_OK(ctx, fcm_mg_setup(prep));
  TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &fresh));
  TEST_TRUE(fcm_mg_num_levels(fresh) >= 3);
  int nblk = 0;
  for (int l = 0; l < fresh->nlev; l++)
    nblk += fresh->lev[l].blk != NULL;
  TEST_TRUE(nblk > 0); /* the cut cells' block smoothers are part of the comparison */
  const int same = mgc_same(ctx, prep, fresh, p.b, p.n, 5);
  printf("%s, cycle %d: %d levels, %lld DOFs, %d levels with block smoothers; prepared then set "
         "up %s fcm_mg_create()\n",
         name, cycle_index, fcm_mg_num_levels(fresh), (long long)p.n, nblk,
         same ? "equals" : "DIFFERS from");
  TEST_TRUE(same);

  /* from the earlier hierarchy on the same pattern: everything kept, the same bits */
  fcm_csr *P2 = nan_copy(ctx, &p);
  fcm_mg *again = NULL;
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, &prep, p.space, P2, inactive, &o, &again));
  TEST_TRUE(prep == NULL);
  fcm__mg_kept kept;
  fcm__mg_get_kept(again, &kept);
  TEST_TRUE(kept.plans == fcm_mg_num_levels(again) - 1);
  TEST_TRUE(kept.row_orders == fcm_mg_num_levels(again) - 1);
  TEST_TRUE(kept.block_smoothers == nblk && kept.analysis == 1);
  copy_values(p.A, P2);
  TEST_OK(ctx, fcm_mg_setup(again));
  const int same_again = mgc_same(ctx, again, fresh, p.b, p.n, 5);
  printf("%s, cycle %d: from the earlier hierarchy (kept %d plans, %d block smoothers, analysis "
         "%d): %s\n",
         name, cycle_index, kept.plans, kept.block_smoothers, kept.analysis,
         same_again ? "equals" : "DIFFERS");
  TEST_TRUE(same_again);

  /* another Dirichlet row than the matrix's: the setup refuses */
  fcm_index free_row = 0;
  while (free_row < p.n && inactive[free_row])
    free_row++;
  TEST_TRUE(free_row < p.n);
  inactive[free_row] = 1;
  fcm_mg *wrong = NULL;
  TEST_OK(ctx, fcm__mg_create_pattern(ctx, NULL, p.space, P2, inactive, &o, &wrong));
  TEST_TRUE(fcm_mg_setup(wrong) == FCM_ERR_ARG);
  fcm_ctx_error_clear(ctx);

  fcm_mg_destroy(&wrong);
  fcm_mg_destroy(&again);
  fcm_mg_destroy(&fresh);
  fcm_csr_destroy(&P);
  fcm_csr_destroy(&P2);
  free(inactive);
  problem_free(&p);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  prepare_case(ctx, FCM_ELEMENT_HEX8, 1);
  prepare_case(ctx, FCM_ELEMENT_HEX8, 2);
  prepare_case(ctx, FCM_ELEMENT_HEX20, 1);
  prepare_case(ctx, FCM_ELEMENT_HEX20, 2);
  fcm_ctx_destroy(&ctx);
  printf("ok\n");
  return TEST_RESULT();
}
