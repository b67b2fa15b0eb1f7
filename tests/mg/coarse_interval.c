/* fcm_mg_options.coarse_interval = 3 on the cut hemisphere (Hex8, V-cycle): the set-ups
 * between the coarser levels' updates keep levels >= 1 as they were (their matrices bit for
 * bit) while level 0's diagonal follows the new values; the third set-up after the creation
 * computes every level again, and then equals a hierarchy created on those values with the
 * default coarse_interval 1 (the level matrices and a cycle bit for bit); the lagged
 * hierarchy still solves (CG + MG to 1e-9); after a failed set-up the cycle refuses and the
 * next set-up computes every level; a single level is factored at every set-up;
 * coarse_interval 0 is refused. */
#include "mg/levels_impl.h"
#include "mg_util.h"

#include <math.h>

/* Whether the values of level l >= 1 of a and b are the same bits. */
static int same_level(const fcm_mg *a, const fcm_mg *b, int l)
{
  fcm_index na = 0, nb = 0;
  fcm_csr_get_size(a->lev[l].Aown, NULL, NULL, &na);
  fcm_csr_get_size(b->lev[l].Aown, NULL, NULL, &nb);
  return na == nb && memcmp(fcm_csr_values_read(a->lev[l].Aown),
                            fcm_csr_values_read(b->lev[l].Aown), sizeof(double) * (size_t)na) == 0;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  problem p;
  problem_hemisphere(ctx, 12, 1, &p);
  fcm_index nnz = 0;
  fcm_csr_get_size(p.A, NULL, NULL, &nnz);
  double *v0 = malloc(sizeof *v0 * (size_t)nnz);
  memcpy(v0, fcm_csr_values_read(p.A), sizeof *v0 * (size_t)nnz);
  fcm_mg_options o = fcm_mg_options_default();
  o.cycle_index = 1;
  o.coarse_dofs = 100;
  o.coarse_interval = 3;
  fcm_mg *lag = NULL, *first = NULL, *fresh = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &lag)); /* set-up 1: every level */
  TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &first));
  if (!lag || !first) goto done;
  TEST_TRUE(fcm_mg_num_levels(lag) >= 3);
  const fcm_index n0 = lag->lev[0].n;
  double *d0 = malloc(sizeof *d0 * (size_t)n0);
  for (int k = 1; k <= 2; k++) { /* set-ups 2 and 3: level 0 alone */
    memcpy(d0, lag->lev[0].dinv, sizeof *d0 * (size_t)n0);
    scale_symmetric(p.A, v0, 0.05 * k);
    TEST_OK(ctx, fcm_mg_setup(lag));
    for (int l = 1; l < fcm_mg_num_levels(lag); l++)
      TEST_TRUE(same_level(lag, first, l));
    TEST_TRUE(memcmp(d0, lag->lev[0].dinv, sizeof *d0 * (size_t)n0) != 0);
    double *x = calloc((size_t)p.n, sizeof *x);
    fcm_krylov_options ko = fcm_krylov_options_default();
    ko.rtol = 1e-9;
    fcm_krylov_info ki;
    TEST_OK(ctx,
            fcm_cg_solve(ctx, p.n, fcm_csr_operator, p.A, fcm_mg_operator, lag, p.b, x, &ko, &ki));
    printf("set-up %d, coarse levels lagged: CG + MG %d iterations\n", k + 1, ki.iterations);
    free(x);
  }
  scale_symmetric(p.A, v0, 0.2);
  TEST_OK(ctx, fcm_mg_setup(lag)); /* set-up 4: every level again */
  o.coarse_interval = 1;
  TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &fresh));
  if (fresh) {
    int same = 1;
    for (int l = 1; l < fcm_mg_num_levels(lag); l++)
      same = same && same_level(lag, fresh, l);
    TEST_TRUE(same && !same_level(lag, first, 1));
    double *y1 = calloc((size_t)p.n, sizeof *y1), *y2 = calloc((size_t)p.n, sizeof *y2);
    TEST_OK(ctx, fcm_mg_operator(lag, p.b, y1));
    TEST_OK(ctx, fcm_mg_operator(fresh, p.b, y2));
    TEST_TRUE(memcmp(y1, y2, sizeof *y1 * (size_t)p.n) == 0);
    free(y1), free(y2);
  }
  free(d0);
  /* a failed set-up (a diagonal entry NaN) leaves the levels mixed: the cycle refuses until a
   * set-up succeeds, and that one (the second since set-up 4, not a third) computes every
   * level: a fresh hierarchy's bits */
  if (fresh) {
    double *v = fcm_csr_values(p.A), keep = v[lag->lev[0].diag[0]];
    v[lag->lev[0].diag[0]] = NAN;
    TEST_ERR(ctx, fcm_mg_setup(lag), FCM_ERR_NUMERIC, "diagonal");
    double *y = calloc((size_t)p.n, sizeof *y), *y2 = calloc((size_t)p.n, sizeof *y2);
    TEST_ERR(ctx, fcm_mg_cycle(lag, p.b, y), FCM_ERR_ARG, "set the hierarchy up again");
    v[lag->lev[0].diag[0]] = keep;
    scale_symmetric(p.A, v0, 0.3);
    TEST_OK(ctx, fcm_mg_setup(lag));
    fcm_mg_destroy(&fresh);
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &fresh));
    TEST_OK(ctx, fcm_mg_operator(lag, p.b, y));
    TEST_OK(ctx, fcm_mg_operator(fresh, p.b, y2));
    TEST_TRUE(memcmp(y, y2, sizeof *y * (size_t)p.n) == 0);
    free(y), free(y2);
  }
  /* a single level is the finest: factored at every set-up whatever coarse_interval says */
  {
    fcm_mg *one = NULL, *one_fresh = NULL;
    o.coarse_dofs = 10 * p.n;
    o.coarse_interval = 2;
    scale_symmetric(p.A, v0, 0.0);
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &one));
    if (one) {
      TEST_TRUE(fcm_mg_num_levels(one) == 1);
      scale_symmetric(p.A, v0, 0.4);
      TEST_OK(ctx, fcm_mg_setup(one)); /* set-up 2: not a coarse one */
      TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &one_fresh));
      double *y = calloc((size_t)p.n, sizeof *y), *y2 = calloc((size_t)p.n, sizeof *y2);
      TEST_OK(ctx, fcm_mg_operator(one, p.b, y));
      if (one_fresh) TEST_OK(ctx, fcm_mg_operator(one_fresh, p.b, y2));
      TEST_TRUE(memcmp(y, y2, sizeof *y * (size_t)p.n) == 0);
      free(y), free(y2);
    }
    fcm_mg_destroy(&one);
    fcm_mg_destroy(&one_fresh);
    o.coarse_dofs = 100;
  }
  {
    fcm_mg *bad = NULL;
    o.coarse_interval = 0;
    TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &bad), FCM_ERR_ARG, "coarse_interval");
  }
done:
  fcm_mg_destroy(&lag);
  fcm_mg_destroy(&first);
  fcm_mg_destroy(&fresh);
  free(v0);
  problem_free(&p);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
