/* Benchmark: the space and integrator part of a cut (figures in lib/docs/cutting.md, "Cut
 * latency: space and integrator"). A Hex8 grid around a ball of radius 1 (the Kuhn-split ball of
 * fcm_geometry_create_ball(), n = 8), Stable Neo-Hookean (E = 1e5, nu = 0.4, rho = 1000),
 * gravity, dt = 0.01, the default direct CHOLMOD solver; one step, then one plane cut across the
 * ball (off the grid planes). Timed, the best of NREP: the cut's rules (for scale; not this
 * part), the new space (fcm_space_create_embedded()), the new integrator
 * (fcm_integrator_create_cut(): pattern, mass and load assembly, analysis, state transfer) with
 * cut_reuse 0 (everything anew), FCM_CUT_REUSE_BLOCKS (the elements the cut left keep their
 * mass and load blocks) and BLOCKS | ORDERING (CHOLMOD's ordering extended, no AMD / METIS),
 * the analysis alone and the factor's fill and flops of each ordering, the momentum's mass
 * blocks anew and kept, the mass matrix and gravity load alone anew and kept, and the first
 * step after the cut with each ordering. Asserts only that
 * the three integrators hold the same mass matrix bits.
 * Usage: bench_cut_update [cells across the ball ...] (default 22 and 34: about 5k and 20k
 * active cells). */
#include "fem/fem_impl.h"
#include "sim/sim_impl.h"
#include "fcm/fcm.h"
#include "test.h"

#include <stdlib.h>
#include <string.h>

#define NREP 3

static fcm_ctx *ctx;
static const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.4, 1000.0};

static fcm_integrator *base_integrator(fcm_space *s, int reuse)
{
  fcm_integrator *I = NULL;
  fcm_integrator_options o = fcm_integrator_options_default();
  const double grav[3] = {0.0, -9.81, 0.0};
  o.dt = 0.01;
  o.cut_reuse = reuse;
  TEST_OK(ctx, fcm_integrator_create(ctx, s, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, grav, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  fcm_step_info info;
  TEST_OK(ctx, fcm_integrator_step(I, &info));
  return I;
}

static void run(int across)
{
  const double h = 2.2 / across, c[3] = {0.0, 0.0, 0.0};
  const double lo[3] = {-1.1, -1.1, -1.1}, hi[3] = {1.1, 1.1, 1.1};
  const fcm_index n[3] = {across, across, across};
  fcm_geometry *g = NULL;
  fcm_mesh *mesh = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_space *s0 = NULL, *s1 = NULL;
  fcm_surface *cut = NULL;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 1.0, 8, &g));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &r0));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r0, &s0));
  const int modes[3] = {0, FCM_CUT_REUSE_BLOCKS, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_ORDERING};
  fcm_integrator *base[3];
  for (int m = 0; m < 3; m++)
    base[m] = base_integrator(s0, modes[m]);
  const double p[3] = {0.13 * h / 0.1, 0.0, 0.0}, nrm[3] = {1.0, 0.1, 0.05};
  const double bl[3] = {-2, -2, -2}, bh[3] = {2, 2, 2};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nrm, bl, bh, &cut));
  double t_rules = 1e30, t_space = 1e30, t_integ[3] = {1e30, 1e30, 1e30};
  double t_an[3] = {1e30, 1e30, 1e30}, t_step[3] = {1e30, 1e30, 1e30}, fl[3] = {0}, lnz[3] = {0};
  double t_factor[3] = {1e30, 1e30, 1e30}, t_log_new = 1e30, t_log_kept = 1e30;
  double t_asm_new = 1e30, t_asm_kept = 1e30;
  fcm_index kept = 0;
  for (int rep = 0; rep < NREP; rep++) {
    fcm_cell_rules_destroy(&r1);
    fcm_space_destroy(&s1);
    double t = fcm_wtime();
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1));
    t_rules = fmin(t_rules, fcm_wtime() - t);
    t = fcm_wtime();
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r1, &s1));
    t_space = fmin(t_space, fcm_wtime() - t);
    fcm_integrator *I[3] = {NULL, NULL, NULL};
    for (int m = 0; m < 3; m++) {
      t = fcm_wtime();
      TEST_OK(ctx, fcm_integrator_create_cut(base[m], s1, &I[m]));
      t_integ[m] = fmin(t_integ[m], fcm_wtime() - t);
      fcm_direct_info di;
      fcm_direct_get_info(I[m]->chol, &di);
      t_an[m] = fmin(t_an[m], di.time_analyze);
      lnz[m] = di.factor_nnz;
      fl[m] = di.factor_flops;
      fcm_integrator_setup_info si;
      fcm_integrator_get_setup_info(I[m], &si);
      if (m == 1) kept = si.cut_kept_elements;
    }
    fcm_index nnz = 0;
    fcm_csr_get_size(I[0]->M, NULL, NULL, &nnz);
    for (int m = 1; m < 3; m++)
      TEST_TRUE(memcmp(fcm_csr_values_read(I[0]->M), fcm_csr_values_read(I[m]->M),
                       sizeof(double) * (size_t)nnz) == 0);
    for (int m = 0; m < 3; m++) {
      fcm_step_info info;
      t = fcm_wtime();
      TEST_OK(ctx, fcm_integrator_step(I[m], &info));
      t_step[m] = fmin(t_step[m], fcm_wtime() - t);
      fcm_direct_info di;
      fcm_direct_get_info(I[m]->chol, &di);
      if (di.factorizations > 0)
        t_factor[m] = fmin(t_factor[m], di.time_factor / (double)di.factorizations);
      fcm_integrator_destroy(&I[m]);
    }
    /* the mass matrix and the gravity load alone: every element anew, and kept */
    {
      fcm_assembly_workspace *ws = NULL;
      fcm_csr *M = NULL;
      const fcm_index ne = fcm_space_num_elements(s1), nd = fcm_space_num_dofs(s1);
      const int bm = fcm__assembly_block_size(s1, FCM_LINEAR_MASS),
                bf = fcm__assembly_block_size(s1, FCM_LINEAR_BODY_FORCE);
      double *f = calloc((size_t)nd, sizeof *f), *om = malloc(sizeof *om * (size_t)ne * bm),
             *of = malloc(sizeof *of * (size_t)ne * bf);
      fcm_index *same = malloc(sizeof *same * (size_t)ne);
      const double accel[3] = {0.0, -9.81, 0.0};
      fcm_linear_form fm = fcm_linear_form_default(), ff = fcm_linear_form_default();
      fm.term = FCM_LINEAR_MASS;
      fm.material = ff.material = &mat;
      ff.term = FCM_LINEAR_BODY_FORCE;
      ff.accel = accel;
      TEST_OK(ctx, fcm_assembly_workspace_create(s1, NULL, &ws));
      TEST_OK(ctx, fcm_space_matrix_create(s1, &M));
      t = fcm_wtime();
      TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &fm, M, NULL));
      TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &ff, NULL, f));
      t_asm_new = fmin(t_asm_new, fcm_wtime() - t);
      t = fcm_wtime();
      TEST_OK(ctx, fcm__space_cut_same_elements(s0, s1, same, NULL));
      TEST_OK(ctx, fcm__assembly_linear_blocks(ws, &fm, M, NULL, same, base[1]->blk_mass, om));
      TEST_OK(ctx, fcm__assembly_linear_blocks(ws, &ff, NULL, f, same, base[1]->loads[0].blk, of));
      t_asm_kept = fmin(t_asm_kept, fcm_wtime() - t);
      free(f);
      free(om);
      free(of);
      free(same);
      fcm_csr_destroy(&M);
      fcm_assembly_workspace_destroy(&ws);
    }
    /* the momentum's blocks: every element anew, and kept over the cut */
    fcm_space *a = NULL, *b = NULL;
    TEST_OK(ctx, fcm_space_momentum(s0, 1.0, NULL, NULL, NULL, NULL, NULL));
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r1, &a));
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r1, &b));
    t = fcm_wtime();
    TEST_OK(ctx, fcm_space_momentum(a, 1.0, NULL, NULL, NULL, NULL, NULL));
    t_log_new = fmin(t_log_new, fcm_wtime() - t);
    t = fcm_wtime();
    fcm_index *same = malloc(sizeof *same * (size_t)fcm_space_num_elements(b));
    TEST_OK(ctx, fcm__space_cut_same_elements(s0, b, same, NULL));
    TEST_OK(ctx, fcm__space_momentum_blocks_from(b, s0, same));
    t_log_kept = fmin(t_log_kept, fcm_wtime() - t);
    free(same);
    fcm_space_destroy(&a);
    fcm_space_destroy(&b);
  }
  fcm_index active = 0;
  for (fcm_index k = 0; k < fcm_mesh_num_cells(mesh); k++)
    active += fcm_space_cell_active(s1, k);
  printf("grid %d^3 (h %.4f): %lld active cells, %lld elements, DOFs %lld -> %lld, %lld of the "
         "elements kept\n",
         across, h, (long long)active, (long long)fcm_space_num_elements(s1),
         (long long)fcm_space_num_dofs(s0), (long long)fcm_space_num_dofs(s1), (long long)kept);
  printf("  cut rules (for scale)          %8.4f s\n", t_rules);
  printf("  space                          %8.4f s\n", t_space);
  const char *name[3] = {"anew", "blocks kept", "blocks + ordering kept"};
  for (int m = 0; m < 3; m++)
    printf("  integrator, %-22s %8.4f s (analysis %.4f s; factor nnz %.4g, %.3g flop, %.4f s; "
           "first step %.4f s)\n",
           name[m], t_integ[m], t_an[m], lnz[m], fl[m], t_factor[m], t_step[m]);
  printf("  mass matrix + gravity load alone: anew %.4f s, kept %.4f s\n", t_asm_new, t_asm_kept);
  printf("  momentum blocks: anew %.4f s, kept %.4f s\n", t_log_new, t_log_kept);
  printf("  space + integrator: anew %.4f s, blocks kept %.4f s, blocks + ordering %.4f s\n",
         t_space + t_integ[0] + t_log_new, t_space + t_integ[1] + t_log_kept,
         t_space + t_integ[2] + t_log_kept);
  fcm_cell_rules_destroy(&r1);
  fcm_space_destroy(&s1);
  for (int m = 0; m < 3; m++)
    fcm_integrator_destroy(&base[m]);
  fcm_surface_destroy(&cut);
  fcm_space_destroy(&s0);
  fcm_cell_rules_destroy(&r0);
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&g);
}

int main(int argc, char **argv)
{
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (argc > 1)
    for (int k = 1; k < argc; k++)
      run(atoi(argv[k]));
  else {
    run(22);
    run(34);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
