/* fcm's geometric multigrid as PETSc's PCMG (label mpi; 1 and 2 processes). A ball of radius
 * 0.45 embedded in an N^3 grid of the unit cube (cut cells all around it, small cut fractions
 * included), clamped on its lowest layer of nodes, under gravity, static; rtol 1e-10.
 * Asserted on every process:
 * - with -pc_type mg the displacement equals the serial CHOLMOD solution (every cell's rules,
 *   symmetric elimination) to 1e-8 relative, and CG needs at most `max_its` iterations (a
 *   wrong prolongation or level numbering cannot reach 1e-10 that fast; the bound is the
 *   argument: Hex8 32, Hex20 40 in tests.cmake, measured 22 / 26 and 27 / 34 on 1 / 2
 *   processes);
 * - CG + GAMG (the option -pc_type gamg) needs more than `gamg_ratio` times as many
 *   iterations on the same problem (the reason for the multigrid: argument, 0 to skip);
 * - -pc_type mg on a Tet4 mesh of the same box and on a Hex8 mesh with one node moved off the
 *   grid fails at setup with FCM_ERR_UNSUPPORTED on every process (no hang), the message
 *   naming the box grid.
 * Arguments: element (hex8|hex20), N, max_its, gamg_ratio. */
#include "fcm/fcm.h"
#include "fcm/petsc.h"
#include "clamp_util.h"
#include "test_mpi.h"

static const double grav[3] = {0.0, 0.0, -9.81};
static const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};

static double dist(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += (a[i] - b[i]) * (a[i] - b[i]);
  return sqrt(s);
}

/* Set up and solve with `options`; the displacement into u, the iterations returned
 * (-1 on a failure, the status in *st). */
static int solve(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom, const char *options,
                 double *u, fcm_status *st)
{
  fcm_petsc_problem *P = NULL;
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_STATIC;
  po.solver.rtol = 1e-10;
  po.solver.petsc_options = options;
  po.solver.partition = FCM_PETSC_PARTITION_ORDERED;
  fcm_index nfix = 0, *fix = NULL;
  fcm_petsc_step_info si;
  memset(&si, 0, sizeof si);
  int its = -1;
  const fcm_motion clamp = fcm_motion_default();
  *st = fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P);
  if (*st) goto done;
  fix = clamped(mesh, fcm_petsc_problem_space(P), &nfix);
  if ((*st = fcm_petsc_problem_add_gravity(P, grav))) goto done;
  if ((*st = fcm_petsc_problem_add_constraint(P, nfix, fix, &clamp))) goto done;
  if ((*st = fcm_petsc_problem_setup(P))) goto done;
  if ((*st = fcm_petsc_problem_step(P, &si))) goto done;
  if (u && (*st = fcm_petsc_problem_get_state(P, u, NULL))) goto done;
  its = si.iterations;
done:
  free(fix);
  fcm_petsc_problem_destroy(&P);
  return its;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL, *tet = NULL, *bent = NULL;
  fcm_geometry *geom = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_csr *A = NULL;
  fcm_direct *chol = NULL;
  fcm_element_type type;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 5 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const fcm_index N = atoi(argv[2]);
  const int max_its = atoi(argv[3]);
  const double gamg_ratio = atof(argv[4]);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.5, 0.5, 0.5};
  const fcm_index cells[3] = {N, N, N};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.45, 4, &geom));

  /* serial reference: CHOLMOD on every cell's rules */
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.kinds = FCM_RULES_STIFFNESS;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, geom, &ro, &rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  const fcm_index n = fcm_space_num_dofs(space);
  double *b = calloc((size_t)n, sizeof *b), *x = calloc((size_t)n, sizeof *x);
  double *u = calloc((size_t)n, sizeof *u);
  TEST_OK(ctx, fcm_space_matrix_create(space, &A));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, A));
  TEST_OK(ctx, fcm_assemble_body_force(space, &mat, grav, NULL, b));
  fcm_index nfix = 0, *fix = clamped(mesh, space, &nfix), ncon = 0;
  fcm_index *cdofs = calloc((size_t)(3 * nfix + 1), sizeof *cdofs);
  for (fcm_index k = 0; k < nfix; k++) {
    const fcm_index d = fcm_space_node_dof(space, fix[k]);
    for (int i = 0; d >= 0 && i < 3; i++)
      cdofs[ncon++] = d + i;
  }
  TEST_OK(ctx, fcm_space_apply_dirichlet(space, ncon, cdofs, NULL, A, b));
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &chol));
  TEST_OK(ctx, fcm_direct_analyze(chol));
  TEST_OK(ctx, fcm_direct_factor(chol, fcm_csr_values(A)));
  TEST_OK(ctx, fcm_direct_solve(chol, b, x));

  /* PCMG */
  fcm_status st = FCM_OK;
  const int its_mg = solve(ctx, mesh, geom, "-pc_type mg", u, &st);
  TEST_OK(ctx, st);
  double nx = 0.0;
  for (fcm_index i = 0; i < n; i++)
    nx += x[i] * x[i];
  const double rel = dist(n, u, x) / sqrt(nx);
  if (rank == 0)
    printf("pcmg %s N %lld: %lld DOFs, PCMG %d iterations, |u - u_cholmod| / |u| = %.3g\n", argv[1],
           (long long)N, (long long)n, its_mg, rel);
  TEST_TRUE(rel <= 1e-8);
  TEST_TRUE(its_mg >= 1 && its_mg <= max_its);
  if (gamg_ratio > 0.0) {
    const int its_gamg = solve(ctx, mesh, geom, "-pc_type gamg", NULL, &st);
    TEST_OK(ctx, st);
    if (rank == 0) printf("pcmg %s N %lld: GAMG %d iterations\n", argv[1], (long long)N, its_gamg);
    TEST_TRUE(its_gamg > gamg_ratio * its_mg);
  }

  /* not a box grid: a clear error on every process */
  const fcm_index tc[3] = {3, 3, 3};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_TET4, lo, hi, tc, &tet));
  TEST_TRUE(solve(ctx, tet, NULL, "-pc_type mg", NULL, &st) < 0);
  TEST_TRUE(st == FCM_ERR_UNSUPPORTED);
  TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "box grid") != NULL);
  fcm_ctx_error_clear(ctx);
  {
    const fcm_index nn = fcm_mesh_num_nodes(mesh), nc = fcm_mesh_num_cells(mesh);
    double *X = malloc(sizeof *X * 3 * (size_t)nn);
    memcpy(X, fcm_mesh_coords(mesh), sizeof *X * 3 * (size_t)nn);
    for (fcm_index k = 0; k < nn; k++) /* an interior node off the grid */
      if (fabs(X[3 * k] - 0.5) < 0.26 && fabs(X[3 * k + 1] - 0.5) < 0.26 &&
          fabs(X[3 * k + 2] - 0.5) < 0.26) {
        X[3 * k] += 0.1 / (double)N;
        break;
      }
    TEST_OK(ctx, fcm_mesh_create(ctx, type, nn, X, nc, fcm_mesh_cells(mesh), &bent));
    free(X);
    TEST_TRUE(solve(ctx, bent, NULL, "-pc_type mg", NULL, &st) < 0);
    TEST_TRUE(st == FCM_ERR_UNSUPPORTED);
    TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "box grid") != NULL);
    fcm_ctx_error_clear(ctx);
  }

  free(b), free(x), free(u), free(fix), free(cdofs);
  fcm_direct_destroy(&chol);
  fcm_csr_destroy(&A);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&bent);
  fcm_mesh_destroy(&tet);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
