/* fcm_mg_options.block_fraction on the hemisphere with the XFEM plane cut (Hex8): the finest
 * level's element blocks are those of the elements of the cut cells one of whose pieces holds
 * less than the fraction of its cell, counted here from the pieces' volumes and the cell's box
 * (1, the default: every cut cell); a smaller fraction gives fewer blocks; CG with one
 * V-cycle of the smaller block set still converges to CHOLMOD's solution, in at most 1.5 times
 * the iterations of the full set plus 2; the vertex blocks follow the same cells; a fraction
 * outside (0, 1] is refused. */
#include "mg/levels_impl.h"
#include "mg_util.h"
#include "solve/solve_impl.h"

#include <stdio.h>

/* Elements of the cut cells (m->cut_cell: cut by the geometry or the plane, or split) one of
 * whose pieces has less than theta of its cell's volume (the box's). */
static fcm_index expected_blocks(const fcm_mg *m, const problem *p, double theta)
{
  const fcm_cell_rules *R = fcm_space_cell_rules(p->space);
  const fcm_index nc = fcm_mesh_num_cells(p->mesh);
  fcm_index count = 0;
  for (fcm_index c = 0; c < nc; c++) {
    if (!m->cut_cell[c]) continue;
    double X[24], lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    fcm_mesh_cell_coords(p->mesh, c, X);
    for (int a = 0; a < 8; a++)
      for (int d = 0; d < 3; d++)
        lo[d] = fmin(lo[d], X[3 * a + d]), hi[d] = fmax(hi[d], X[3 * a + d]);
    const double vol = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    fcm_index p0 = 0;
    const fcm_index np = fcm_cell_rules_cell_pieces(R, c, &p0);
    int small = 0;
    for (fcm_index q = p0; q < p0 + np; q++)
      small |= fcm_cell_rules_piece_volume(R, q) < theta * vol * (1.0 - 1e-12);
    fcm_index e0 = 0;
    if (small || theta >= 1.0) count += fcm_space_cell_elements(p->space, c, &e0);
  }
  return count;
}

/* CG + one V-cycle of options o from zero: the iterations and the solution (malloc'd). */
static double *cg_mg(fcm_ctx *ctx, const problem *p, const fcm_mg_options *o, int *iters)
{
  fcm_mg *mg = NULL;
  double *x = calloc((size_t)p->n, sizeof *x);
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, o, &mg));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = 1e-10;
  fcm_krylov_info ki;
  TEST_OK(ctx,
          fcm_cg_solve(ctx, p->n, fcm_csr_operator, p->A, fcm_mg_operator, mg, p->b, x, &ko, &ki));
  *iters = ki.iterations;
  fcm_mg_destroy(&mg);
  return x;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  problem p;
  problem_hemisphere(ctx, 16, 1, &p);
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 50;
  o.cycle_index = 1;
  o.blocks = FCM_MG_BLOCKS_ELEMENT;
  static const double thetas[] = {1.0, 0.5, 0.2};
  fcm_index counts[3] = {0, 0, 0};
  int iters[3] = {0, 0, 0};
  double *ref = calloc((size_t)p.n, sizeof *ref);
  direct_solve(ctx, p.A, p.b, ref);
  double refmax = 0.0;
  for (fcm_index i = 0; i < p.n; i++)
    refmax = fmax(refmax, fabs(ref[i]));
  double *x[3] = {NULL, NULL, NULL};
  for (int k = 0; k < 3; k++) {
    o.block_fraction = thetas[k];
    fcm_mg *mg = NULL;
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg));
    if (!mg) continue;
    counts[k] = fcm__schwarz_num_blocks(mg->lev[0].blk);
    TEST_TRUE(counts[k] == expected_blocks(mg, &p, thetas[k]));
    fcm_mg_destroy(&mg);
    x[k] = cg_mg(ctx, &p, &o, &iters[k]);
    double err = 0.0;
    for (fcm_index i = 0; i < p.n; i++)
      err = fmax(err, fabs(x[k][i] - ref[i]));
    TEST_TRUE(err <= 1e-6 * refmax);
    if (getenv("FCM_TEST_VERBOSE"))
      printf("block_fraction %g: %lld element blocks, CG + MG %d iterations, max error %.2e\n",
             thetas[k], (long long)counts[k], iters[k], err);
  }
  TEST_TRUE(counts[1] < counts[0] && counts[2] <= counts[1] && counts[2] > 0);
  TEST_TRUE(iters[1] <= 1.5 * iters[0] + 2 && iters[2] <= 1.5 * iters[0] + 2);
  /* the vertex blocks follow the same cells: fewer with the smaller fraction */
  {
    fcm_index nv[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
      fcm_mg_options v = o;
      v.blocks = FCM_MG_BLOCKS_VERTEX;
      v.block_fraction = thetas[k];
      fcm_mg *mg = NULL;
      TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &v, &mg));
      if (mg) nv[k] = fcm__schwarz_num_blocks(mg->lev[0].blk);
      fcm_mg_destroy(&mg);
    }
    TEST_TRUE(nv[1] > 0 && nv[1] < nv[0]);
  }
  /* outside (0, 1]: refused */
  static const double bad[] = {0.0, -0.5, 1.5, NAN};
  for (int k = 0; k < 4; k++) {
    fcm_mg_options b = o;
    b.block_fraction = bad[k];
    fcm_mg *mg = NULL;
    TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.A, &b, &mg), FCM_ERR_ARG, "block_fraction");
    TEST_TRUE(mg == NULL);
  }
  for (int k = 0; k < 3; k++)
    free(x[k]);
  free(ref);
  problem_free(&p);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
