/* The hierarchy, the cycle and CG + MG give bitwise the same result for 1 and 2 threads,
 * with every smoother, on the uncut cube (n = 16: colours of more than 256 rows, smoothed
 * in parallel) and on the cut hemisphere; fcm_mg_setup() with the same values reproduces
 * the same iterates; the preconditioner is symmetric (V- and W-cycle, every smoother:
 * v^T M u = u^T M v to 1e-12 relative; also with the one-way block sweeps, and with the
 * one-way pointwise sweeps beside them, two pre- and post-smoothing steps too); argument errors
 * are reported. */
#include "mg_util.h"

#include <omp.h>

/* the block options of solve() and of the symmetry check (fcm_mg_options.blocks, block_sweep) */
static fcm_mg_blocks blocks = FCM_MG_BLOCKS_ALL;
static int block_sweep = 0;
static int point_sweep = 0, smooth_steps = 1; /* fcm_mg_options.point_sweep, pre/post_smooth */

static double *solve(fcm_ctx *ctx, problem *p, fcm_mg_smoother sm, int threads, int resetup)
{
  omp_set_num_threads(threads);
  fcm_mg_options o = fcm_mg_options_default();
  o.smoother = sm;
  o.blocks = blocks;
  o.block_sweep = block_sweep;
  o.point_sweep = point_sweep;
  o.pre_smooth = o.post_smooth = smooth_steps;
  o.omega = sm == FCM_MG_SMOOTHER_JACOBI ? fcm_mg_smoother_omega(sm) : 1.2;
  o.coarse_dofs = 100;
  fcm_mg *mg = NULL;
  double *x = calloc((size_t)p->n, sizeof *x);
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, &o, &mg));
  if (resetup) TEST_OK(ctx, fcm_mg_setup(mg));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = 1e-9;
  fcm_krylov_info ki;
  TEST_OK(ctx,
          fcm_cg_solve(ctx, p->n, fcm_csr_operator, p->A, fcm_mg_operator, mg, p->b, x, &ko, &ki));
  fcm_mg_solve_info si;
  const fcm_status st = fcm_mg_solve(mg, p->b, x, 1e-14, 3, &si); /* 3 more cycles */
  TEST_TRUE(st == FCM_OK || st == FCM_ERR_NOT_CONVERGED);
  fcm_ctx_error_clear(ctx);
  fcm_mg_destroy(&mg);
  return x;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  for (int kind = 0; kind < 2; kind++) {
    problem p;
    if (kind == 0)
      problem_cube(ctx, 16, &p);
    else
      problem_hemisphere(ctx, 8, 1, &p);
    /* symmetry of the preconditioner; SGS also with the one-way block sweeps, all blocks and
     * the vertex blocks alone (sm = FCM_MG_SMOOTHER_COUNT, COUNT + 1), and with the one-way
     * pointwise sweeps beside them, one and two smoothing steps (COUNT + 2, COUNT + 3) */
    for (int sm = 0; sm < FCM_MG_SMOOTHER_COUNT + 4; sm++)
      for (int cyc = 1; cyc <= 2; cyc++) {
        fcm_mg_options o = fcm_mg_options_default();
        o.smoother = sm < FCM_MG_SMOOTHER_COUNT ? (fcm_mg_smoother)sm : FCM_MG_SMOOTHER_SGS;
        o.block_sweep = sm >= FCM_MG_SMOOTHER_COUNT;
        o.blocks = sm == FCM_MG_SMOOTHER_COUNT + 1 ? FCM_MG_BLOCKS_VERTEX : FCM_MG_BLOCKS_ALL;
        o.point_sweep = sm >= FCM_MG_SMOOTHER_COUNT + 2;
        o.pre_smooth = o.post_smooth = sm == FCM_MG_SMOOTHER_COUNT + 3 ? 2 : 1;
        o.omega = sm == FCM_MG_SMOOTHER_JACOBI ? fcm_mg_smoother_omega(sm) : 1.3;
        o.cycle_index = cyc;
        o.coarse_dofs = 100;
        fcm_mg *mg = NULL;
        TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg));
        double *u = calloc((size_t)p.n, sizeof *u), *v = calloc((size_t)p.n, sizeof *v);
        double *Mu = calloc((size_t)p.n, sizeof *u), *Mv = calloc((size_t)p.n, sizeof *v);
        unsigned long long seed = 7;
        for (fcm_index i = 0; i < p.n; i++) {
          seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
          u[i] = (double)(seed >> 11) / 9007199254740992.0 - 0.5;
          seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
          v[i] = (double)(seed >> 11) / 9007199254740992.0 - 0.5;
        }
        TEST_OK(ctx, fcm_mg_operator(mg, u, Mu));
        TEST_OK(ctx, fcm_mg_operator(mg, v, Mv));
        double a = 0.0, b = 0.0, na = 0.0;
        for (fcm_index i = 0; i < p.n; i++)
          a += v[i] * Mu[i], b += u[i] * Mv[i], na += fabs(v[i] * Mu[i]);
        TEST_NEAR(a, b, 0.0, 1e-12 * na);
        if (sm == FCM_MG_SMOOTHER_SGS_COLORED && kind == 0) {
          fcm_mg_level_info li;
          TEST_OK(ctx, fcm_mg_get_level_info(mg, 0, &li));
          TEST_TRUE(li.colors > 0 && li.dofs / li.colors >= 256); /* the parallel path */
        }
        free(u), free(v), free(Mu), free(Mv);
        fcm_mg_destroy(&mg);
      }
    for (int sm = 0; sm < FCM_MG_SMOOTHER_COUNT; sm++) {
      double *x1 = solve(ctx, &p, (fcm_mg_smoother)sm, 1, 0);
      double *x2 = solve(ctx, &p, (fcm_mg_smoother)sm, 2, 0);
      double *x3 = solve(ctx, &p, (fcm_mg_smoother)sm, 2, 1);
      TEST_TRUE(memcmp(x1, x2, sizeof *x1 * (size_t)p.n) == 0);
      TEST_TRUE(memcmp(x1, x3, sizeof *x1 * (size_t)p.n) == 0);
      free(x1), free(x2), free(x3);
    }
    /* the one-way block sweeps (all blocks, then the vertex blocks alone) */
    for (int k = 0; k < 2; k++) {
      blocks = k ? FCM_MG_BLOCKS_VERTEX : FCM_MG_BLOCKS_ALL, block_sweep = 1;
      double *x1 = solve(ctx, &p, FCM_MG_SMOOTHER_SGS, 1, 0);
      double *x2 = solve(ctx, &p, FCM_MG_SMOOTHER_SGS, 2, 0);
      TEST_TRUE(memcmp(x1, x2, sizeof *x1 * (size_t)p.n) == 0);
      free(x1), free(x2);
      blocks = FCM_MG_BLOCKS_ALL, block_sweep = 0;
    }
    /* the one-way pointwise sweeps beside the one-way block sweeps, one and two steps */
    for (int k = 1; k <= 2; k++) {
      block_sweep = point_sweep = 1, smooth_steps = k;
      double *x1 = solve(ctx, &p, FCM_MG_SMOOTHER_SGS, 1, 0);
      double *x2 = solve(ctx, &p, FCM_MG_SMOOTHER_SGS, 2, 0);
      TEST_TRUE(memcmp(x1, x2, sizeof *x1 * (size_t)p.n) == 0);
      free(x1), free(x2);
      block_sweep = point_sweep = 0, smooth_steps = 1;
    }
    if (kind == 0) {
      /* errors */
      fcm_mg *mg = NULL;
      fcm_mg_options o = fcm_mg_options_default();
      o.omega = 2.0;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "omega");
      o = fcm_mg_options_default();
      o.smoother = FCM_MG_SMOOTHER_JACOBI;
      o.omega = 1.5;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "omega");
      o = fcm_mg_options_default();
      o.blocks = FCM_MG_BLOCKS_COUNT;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "blocks");
      o = fcm_mg_options_default();
      o.block_sweep = 2;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "block_sweep");
      o = fcm_mg_options_default();
      o.point_sweep = 2;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "point_sweep");
      o = fcm_mg_options_default();
      o.point_sweep = 1;
      o.smoother = FCM_MG_SMOOTHER_JACOBI;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "SGS smoother");
      o = fcm_mg_options_default();
      o.max_levels = 0;
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg), FCM_ERR_ARG, "max_levels");
      TEST_TRUE(mg == NULL);
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, NULL, NULL, &mg), FCM_ERR_ARG, "NULL");
      /* eliminated rows must not change between create and setup */
      TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, NULL, &mg));
      fcm_index d = 3 * 100; /* an interior DOF: eliminate it */
      fcm_index one[1] = {d};
      double *b = calloc((size_t)p.n, sizeof *b);
      TEST_OK(ctx, fcm_space_apply_dirichlet(p.space, 1, one, NULL, p.A, b));
      TEST_ERR(ctx, fcm_mg_setup(mg), FCM_ERR_ARG, "eliminated");
      free(b);
      fcm_mg_destroy(&mg);
      /* a tetrahedral grid is refused */
      fcm_mesh *m20 = NULL;
      fcm_space *s20 = NULL;
      fcm_csr *A20 = NULL;
      const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
      const fcm_index c[3] = {2, 2, 2};
      fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0, 0.3, 1.0};
      TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_TET10, lo, hi, c, &m20));
      TEST_OK(ctx, fcm_space_create(ctx, m20, NULL, &s20));
      TEST_OK(ctx, fcm_space_matrix_create(s20, &A20));
      TEST_OK(ctx, fcm_assemble_mass(s20, &mat, NULL, A20));
      TEST_ERR(ctx, fcm_mg_create(ctx, s20, A20, NULL, &mg), FCM_ERR_UNSUPPORTED, "Hex8 or Hex20");
      fcm_csr_destroy(&A20);
      fcm_space_destroy(&s20);
      fcm_mesh_destroy(&m20);
    }
    problem_free(&p);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
