/* The PETSc backend reproduces the serial library (label mpi; run on 1 and 2 processes): an
 * embedded box clamped at x = 0 under gravity in a background grid that cuts it on the other
 * five sides, static (K u = f) or three backward Euler steps ((M/h^2 + K) u1 = M/h^2 (u0 + h v0)
 * + f). The reference is the serial pipeline on the same rules options: cell rules of every
 * cell, fcm_assemble_*, symmetric elimination, CHOLMOD; the static case also through the
 * serial fcm_integrator. Asserted on every process: displacement (and velocity) within 1e-8
 * relative of the serial one, elastic energy and the assembled mass 1_x^T M 1_x within 1e-8
 * (partition independence of the global quantities), every element integrated by exactly one
 * process. Arguments: element type, static|dynamic, partition (auto|ordered), optional PETSc
 * options (e.g. a direct solve: "-ksp_type preonly -pc_type cholesky
 * -pc_factor_mat_solver_type mumps"). */
#include "fcm/fcm.h"
#include "fcm/petsc.h"
#include "test_mpi.h"

static const double grav[3] = {0.0, -9.81, 0.0};

static double dist(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += (a[i] - b[i]) * (a[i] - b[i]);
  return sqrt(s);
}

static double norm(fcm_index n, const double *a)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * a[i];
  return sqrt(s);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_petsc_problem *P = NULL;
  fcm_element_type type;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 4 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const int dynamic = strcmp(argv[2], "dynamic") == 0;
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);

  const int quadratic = type == FCM_ELEMENT_HEX20 || type == FCM_ELEMENT_TET10;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  const fcm_index cells[3] = {quadratic ? 4 : 6, quadratic ? 2 : 3, quadratic ? 2 : 3};
  const double glo[3] = {0.0, 0.07, 0.11}, ghi[3] = {1.83, 0.91, 0.94};
  const fcm_index gn[3] = {3, 2, 2};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &geom));
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e6, 0.3, 1000.0};

  /* clamped: the mesh nodes on x = 0 */
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  fcm_index *fix = calloc((size_t)nn, sizeof *fix), nfix = 0;
  for (fcm_index k = 0; k < nn; k++)
    if (X[3 * k] == 0.0) fix[nfix++] = k;
  fcm_motion clamp = fcm_motion_default();

  /* ---- distributed */
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = dynamic ? FCM_INTEGRATOR_BACKWARD_EULER : FCM_INTEGRATOR_STATIC;
  po.dt = 0.01;
  po.solver.rtol = 1e-12;
  po.solver.partition = strcmp(argv[3], "ordered") == 0    ? FCM_PETSC_PARTITION_ORDERED
                        : strcmp(argv[3], "ptscotch") == 0 ? FCM_PETSC_PARTITION_PTSCOTCH
                                                           : FCM_PETSC_PARTITION_AUTO;
  po.solver.petsc_options = argc > 4 ? argv[4] : NULL;
  TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P));
  TEST_OK(ctx, fcm_petsc_problem_add_gravity(P, grav));
  TEST_OK(ctx, fcm_petsc_problem_add_constraint(P, nfix, fix, &clamp));
  TEST_OK(ctx, fcm_petsc_problem_setup(P));
  const int nsteps = dynamic ? 3 : 1;
  const fcm_index n = fcm_petsc_problem_num_dofs(P);
  double *u = calloc((size_t)n, sizeof *u), *v = calloc((size_t)n, sizeof *v);
  double *us = calloc((size_t)n, sizeof *us), *vs = calloc((size_t)n, sizeof *vs);
  double *f = calloc((size_t)n, sizeof *f), *b = calloc((size_t)n, sizeof *b);
  double *w = calloc((size_t)n, sizeof *w), *x = calloc((size_t)n, sizeof *x);
  fcm_petsc_step_info si;
  memset(&si, 0, sizeof si);

  /* ---- serial reference on the same rules options (every cell's rules) */
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.kinds = FCM_RULES_STIFFNESS | (dynamic ? FCM_RULES_MASS : 0u);
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, geom, &ro, &rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  TEST_TRUE(fcm_space_num_dofs(space) == n);
  fcm_csr *K = NULL, *M = NULL, *A = NULL;
  fcm_direct *chol = NULL;
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_space_matrix_create(space, &A));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, K));
  TEST_OK(ctx, fcm_assemble_body_force(space, &mat, grav, NULL, f));
  fcm_index nnz = 0;
  fcm_csr_get_size(K, NULL, NULL, &nnz);
  const double h = po.dt;
  memcpy(fcm_csr_values(A), fcm_csr_values(K), sizeof(double) * (size_t)nnz);
  if (dynamic) {
    TEST_OK(ctx, fcm_space_matrix_create(space, &M));
    TEST_OK(ctx, fcm_assemble_mass(space, &mat, NULL, M));
    for (fcm_index e = 0; e < nnz; e++)
      fcm_csr_values(A)[e] += fcm_csr_values(M)[e] / (h * h);
  }
  fcm_index *cdofs = calloc((size_t)(3 * nfix + 1), sizeof *cdofs), ncon = 0;
  unsigned char *iscon = calloc((size_t)n + 1, 1);
  for (fcm_index k = 0; k < nfix; k++) {
    const fcm_index d = fcm_space_node_dof(space, fix[k]);
    for (int i = 0; d >= 0 && i < 3; i++)
      cdofs[ncon++] = d + i, iscon[d + i] = 1;
  }
  memcpy(b, f, sizeof(double) * (size_t)n);
  TEST_OK(ctx, fcm_space_apply_dirichlet(space, ncon, cdofs, NULL, A, b));
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &chol));
  TEST_OK(ctx, fcm_direct_analyze(chol));
  TEST_OK(ctx, fcm_direct_factor(chol, fcm_csr_values(A)));

  for (int s = 0; s < nsteps; s++) {
    TEST_OK(ctx, fcm_petsc_problem_step(P, &si));
    TEST_TRUE(si.reason > 0);
    TEST_OK(ctx, fcm_petsc_problem_get_state(P, u, v));
    /* serial step */
    memcpy(b, f, sizeof(double) * (size_t)n);
    if (dynamic) {
      for (fcm_index i = 0; i < n; i++)
        w[i] = us[i] + h * vs[i];
      TEST_OK(ctx, fcm_csr_apply(M, 1.0 / (h * h), w, 1.0, b));
    }
    for (fcm_index i = 0; i < n; i++)
      if (iscon[i]) b[i] = 0.0;
    TEST_OK(ctx, fcm_direct_solve(chol, b, x));
    for (fcm_index i = 0; i < n; i++) {
      if (dynamic) vs[i] = (x[i] - us[i]) / h;
      us[i] = x[i];
    }
    const double du = dist(n, u, us) / norm(n, us);
    if (!(du <= 1e-8))
      fprintf(stderr, "rank %d step %d: |u - u_serial| / |u_serial| = %g\n", rank, s, du);
    TEST_TRUE(du <= 1e-8);
    if (dynamic) TEST_TRUE(dist(n, v, vs) <= 1e-8 * norm(n, vs));
  }
  /* global quantities */
  TEST_OK(ctx, fcm_csr_apply(K, 1.0, us, 0.0, w));
  double e = 0.0;
  for (fcm_index i = 0; i < n; i++)
    e += 0.5 * us[i] * w[i];
  TEST_NEAR(si.elastic_energy, e, 1e-8, 0.0);
  fcm_petsc_info info;
  TEST_OK(ctx, fcm_petsc_problem_get_info(P, &info));
  TEST_TRUE(info.size == size && info.rank == rank && info.num_dofs == n);
  TEST_TRUE(info.partition != FCM_PETSC_PARTITION_AUTO);
  long long ne = (long long)info.local_elements, ne_all = 0, nd = info.local_dofs, nd_all = 0;
  MPI_Allreduce(&ne, &ne_all, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&nd, &nd_all, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  TEST_TRUE(ne_all == (long long)fcm_space_num_elements(space));
  TEST_TRUE(nd_all == (long long)n);
  if (size > 1) TEST_TRUE(info.min_local_elements > 0);
  if (dynamic) {
    for (fcm_index i = 0; i < n; i++)
      w[i] = i % 3 == 0 ? 1.0 : 0.0;
    TEST_OK(ctx, fcm_csr_apply(M, 1.0, w, 0.0, x));
    double m = 0.0;
    for (fcm_index i = 0; i < n; i++)
      m += w[i] * x[i];
    TEST_NEAR(info.mass, m, 1e-10, 0.0);
    TEST_TRUE(m > 0.0);
  } else {
    /* the serial integrator (static Newton on the linear material) agrees too */
    fcm_integrator *I = NULL;
    fcm_integrator_options io = fcm_integrator_options_default();
    io.kind = FCM_INTEGRATOR_STATIC;
    io.dt = 1.0;
    io.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    io.newton_tolerance = 1e-12;
    fcm_step_info ii;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &io, &I));
    TEST_OK(ctx, fcm_integrator_add_gravity(I, grav, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(I, nfix, fix, &clamp, NULL));
    TEST_OK(ctx, fcm_integrator_setup(I));
    TEST_OK(ctx, fcm_integrator_step(I, &ii));
    TEST_TRUE(dist(n, u, fcm_integrator_displacement(I)) <= 1e-8 * norm(n, u));
    fcm_integrator_destroy(&I);
  }

  fcm_direct_destroy(&chol);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&M);
  fcm_csr_destroy(&A);
  fcm_petsc_problem_destroy(&P);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  free(fix), free(u), free(v), free(us), free(vs), free(f), free(b), free(w), free(x);
  free(cdofs), free(iscon);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
