/* The step's numeric paths of the multigrid against plain references, bit for bit, on the uncut
 * cube and the cut hemisphere (Hex8), with one and two threads:
 * - the Galerkin product's values (fcm__ptap_apply(): a node's 3 x 3 block of A times one
 *   value of P where A's rows come in whole nodes and P's rows of a node are one row shifted
 *   per component) against A P and R (A P) formed entry by entry, each entry's terms in A's
 *   row order, then R's (the order the plan promises); most of A's groups take the node path;
 * - level 0's residual (fcm__mg_residual(): three rows of one pattern side by side) against
 *   b + fcm_csr_apply(A, -1, x, 0, .).
 * The values are scaled per entry so that a term out of order would change the rounding. */
#include "la/ptap_impl.h"
#include "mg/levels_impl.h"
#include "mg_util.h"

#include <math.h>

/* C = R (A P) entry by entry in the plan's order, dense rows of nc (the plan's R). */
static double *reference_ptap(const fcm_csr *A, const fcm__ptap *t)
{
  const fcm_index n = t->n, nc = t->nc;
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  double *AP = calloc((size_t)n * (size_t)nc, sizeof *AP);
  double *C = calloc((size_t)nc * (size_t)nc, sizeof *C);
  for (fcm_index i = 0; i < n; i++)
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      for (fcm_index q = t->P_ptr[ci[p]]; q < t->P_ptr[ci[p] + 1]; q++)
        AP[(size_t)i * (size_t)nc + (size_t)t->P_col[q]] += v[p] * t->P_val[q];
  for (fcm_index I = 0; I < nc; I++)
    for (fcm_index p = t->R_ptr[I]; p < t->R_ptr[I + 1]; p++)
      for (fcm_index J = 0; J < nc; J++)
        C[(size_t)I * (size_t)nc + (size_t)J] +=
            t->R_val[p] * AP[(size_t)t->R_col[p] * (size_t)nc + (size_t)J];
  free(AP);
  return C;
}

static void check_ptap(fcm_ctx *ctx, const fcm_csr *A, const mg_level *L, fcm_index nc, int nt)
{
  fcm_csr *C = NULL;
  fcm__ptap *t = NULL;
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  TEST_OK(ctx, fcm__ptap_create(ctx, A, nc, L->P_ptr, L->P_col, L->P_val, 1, nt, &t, &C));
  if (!t) goto done;
  fcm_index nodes = 0, shifted = 0;
  for (fcm_index g = 0; 3 * g + 2 < n; g++)
    nodes += t->a_kind[g] == KIND_NODES;
  for (fcm_index g = 0; 3 * g + 2 < nc; g++)
    shifted += t->r_kind[g] == KIND_SHIFTED || t->r_kind[g] == KIND_SHIFTED_NODES;
  fcm__ptap_apply(t, A, C, nt);
  double *ref = reference_ptap(A, t);
  const fcm_index *cp = fcm_csr_row_ptr(C);
  const int *cc = fcm_csr_col_idx(C);
  const double *cv = fcm_csr_values_read(C);
  fcm_index differ = 0, nonzero = 0;
  for (fcm_index I = 0; I < nc; I++)
    for (fcm_index p = cp[I]; p < cp[I + 1]; p++) {
      const double r = ref[(size_t)I * (size_t)nc + (size_t)cc[p]];
      differ += memcmp(&r, &cv[p], sizeof r) != 0;
      nonzero += r != 0.0;
    }
  printf("ptap %lld -> %lld, %d threads: %lld of %lld groups of A by nodes, %lld of R shifted, "
         "%lld entries (%lld nonzero) differ from the reference in %lld\n",
         (long long)n, (long long)nc, nt, (long long)nodes, (long long)(n / 3), (long long)shifted,
         (long long)cp[nc], (long long)nonzero, (long long)differ);
  TEST_TRUE(differ == 0 && nonzero > 0);
  TEST_TRUE(3 * nodes >= n / 2);
  free(ref);
done:
  fcm__ptap_destroy(&t);
  fcm_csr_destroy(&C);
}

static void check_residual(fcm_ctx *ctx, const fcm_mg *mg, const fcm_csr *A, int nt)
{
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  double *b = malloc(sizeof *b * (size_t)n), *x = malloc(sizeof *x * (size_t)n);
  double *r = malloc(sizeof *r * (size_t)n), *y = malloc(sizeof *y * (size_t)n);
  for (fcm_index i = 0; i < n; i++) {
    b[i] = sin(0.37 * (double)i);
    x[i] = 1e-3 * cos(0.11 * (double)i) + 1e-2;
  }
  fcm__mg_residual(mg, b, x, r);
  TEST_OK(ctx, fcm_csr_apply(A, -1.0, x, 0.0, y));
  fcm_index differ = 0, triples = 0;
  for (fcm_index i = 0; i < n; i++) {
    y[i] += b[i];
    differ += memcmp(&r[i], &y[i], sizeof *r) != 0;
  }
  for (fcm_index i = 0; mg->lev[0].rows.triple && i < n; i++)
    triples += mg->lev[0].rows.triple[i] != 0;
  printf("residual, %d threads: %lld rows, %lld copies of three rows together, %lld differ\n", nt,
         (long long)n, (long long)triples, (long long)differ);
  TEST_TRUE(differ == 0 && 3 * triples >= n / 2);
  free(b);
  free(x);
  free(r);
  free(y);
}

static void check(fcm_ctx *ctx, const problem *p)
{
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 100;
  fcm_mg *mg = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, &o, &mg));
  if (!mg) return;
  TEST_TRUE(fcm_mg_num_levels(mg) >= 2);
  fcm_index nnz = 0;
  fcm_csr_get_size(p->A, NULL, NULL, &nnz);
  double *v = fcm_csr_values(p->A);
  for (fcm_index q = 0; q < nnz; q++) /* every entry its own rounding */
    v[q] *= 1.0 + 1e-3 * sin(0.7 * (double)q);
  for (int nt = 1; nt <= 2; nt++) {
    TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, nt));
    check_ptap(ctx, p->A, &mg->lev[0], mg->lev[1].n, nt);
    check_residual(ctx, mg, p->A, nt);
  }
  fcm_mg_destroy(&mg);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  problem p;
  problem_cube(ctx, 8, &p);
  check(ctx, &p);
  problem_free(&p);
  problem_hemisphere(ctx, 12, 1, &p);
  check(ctx, &p);
  problem_free(&p);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
