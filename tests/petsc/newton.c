/* Example scenes through the integrator on PETSc (fcm_petsc_simulation_create(); label mpi, 1
 * and 2 processes) against the serial fcm_simulation of the same scene, step by step:
 * - the displacement and velocity after the steps equal the serial ones to `tol` relative
 *   (norm of the difference over the norm of the serial state), and are bit for bit the same
 *   on every process;
 * - each step's energies (kinetic, elastic, external work, total) equal the serial ones to
 *   tol relative to the step's energy scale;
 * - the log (fcm_simulation_write_log(), written by process 0 for both runs): the time and
 *   the pieces exactly, energy, mass, momentum and the reactions of every constraint to tol
 *   relative to the largest value of the column (reactions, moments, momentum: of all
 *   columns of the kind; momentum at least the mass times the largest speed);
 * - the distributed run's linear solves went through PETSc (iterations counted) while the
 *   serial one's matrices were never factored by PETSc (nothing more to check there);
 * - the Newton matrices were not summed densely (fcm_petsc_simulation_traffic()): during the
 *   steps no dense sum carried more values than the space has DOFs, fewer values per Newton
 *   matrix were summed than the matrix has nonzeros (one dense tangent sum alone would be
 *   that many), entries were added into the distributed matrix and, on 2 processes
 *   that both have cells, entries of rows another process owns went through PETSc's stash;
 * - no matrix was summed densely in the whole run, setup included: no dense sum carried more
 *   values than the space has DOFs (the mass matrix stays partial, its products are summed),
 *   and the setup (rules, mass, loads, representative force) summed fewer values in all than
 *   the matrix has nonzeros (one dense mass matrix sum alone would be that many).
 * Arguments: scenes directory, scene file, steps, [tol (default 1e-8)], then PETSc options.
 * The KSP runs to rtol 1e-12 (-ksp_rtol, as a user would set it). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "fem/fem_impl.h" /* fcm__space_memory(): the topology's bytes (FCM_TEST_VERBOSE) */
#include "log_compare.h"
#include "sim/sim_impl.h" /* the integrator's matrices and vectors (FCM_TEST_VERBOSE) */
#include "test_mpi.h"

#include <petscsys.h>
#include <unistd.h>

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *ser = NULL, *par = NULL;
  char path[4096];
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 4) return 2;
  int steps = atoi(argv[3]);
  const double tol = argc > 4 ? atof(argv[4]) : 1e-8;
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  snprintf(path, sizeof path, "%s/%s", argv[1], argv[2]);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  if (PetscOptionsSetValue(NULL, "-ksp_rtol", "1e-12")) TEST_TRUE(0);

  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = steps;
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, &so, &ser));
  TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                           &so, &par));
  if (!ser || !par) {
    fcm_simulation_destroy(&ser);
    fcm_scene_destroy(&scene);
    fcm_ctx_destroy(&ctx);
    fcm_petsc_finalize();
    return 1;
  }
  if (fcm_simulation_num_steps(ser) < steps) steps = (int)fcm_simulation_num_steps(ser);
  fcm_integrator *is = fcm_simulation_integrator(ser), *ip = fcm_simulation_integrator(par);
  const fcm_index n = fcm_integrator_num_dofs(is);
  TEST_TRUE(fcm_integrator_num_dofs(ip) == n);
  long long linear = 0;
  fcm_petsc_traffic t0, t1;
  TEST_OK(ctx, fcm_petsc_simulation_traffic(par, &t0));
  for (int s = 0; s < steps && !test_failures_; s++) {
    fcm_step_info a, b;
    TEST_OK(ctx, fcm_simulation_step(ser, &a));
    TEST_OK(ctx, fcm_simulation_step(par, &b));
    TEST_NEAR(b.time, a.time, 1e-12, 0.0);
    const double scale =
        fabs(a.kinetic_energy) + fabs(a.elastic_energy) + fabs(a.external_work) + 1e-300;
    TEST_TRUE(fabs(a.kinetic_energy - b.kinetic_energy) <= tol * scale);
    TEST_TRUE(fabs(a.elastic_energy - b.elastic_energy) <= tol * scale);
    TEST_TRUE(fabs(a.external_work - b.external_work) <= tol * scale);
    TEST_TRUE(fabs(a.total_energy - b.total_energy) <= tol * scale);
    if (rank == 0 && getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr, "step %d: newton %d / %d, linear %lld, E %.12g / %.12g\n", s + 1,
              a.newton_iterations, b.newton_iterations, b.linear_iterations, a.total_energy,
              b.total_energy);
    linear += b.linear_iterations;
  }
  TEST_TRUE(linear > 0); /* the solves went through the KSP */
  TEST_OK(ctx, fcm_petsc_simulation_traffic(par, &t1));
  {
    fcm_csr *A = NULL;
    fcm_index nnz = 0;
    TEST_OK(ctx, fcm_space_matrix_create(fcm_simulation_space(ser), &A));
    fcm_csr_get_size(A, NULL, NULL, &nnz);
    fcm_csr_destroy(&A);
    const long long matrices = t1.matrices - t0.matrices;
    const long long values = t1.reduce_values - t0.reduce_values;
    /* [0]: stash values of all processes; [1]: processes that added no entry at all; [2]:
     * entries added to own rows in the steps, all processes */
    long long mine2[3] = {t1.matrix_values_sent,
                          t1.matrix_values_local + t1.matrix_values_sent == 0,
                          t1.matrix_values_local - t0.matrix_values_local},
              all2[3] = {0, 0, 0};
    MPI_Allreduce(mine2, all2, 3, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    const long long all_sent = all2[0];
    if (rank == 0 && getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr,
              "traffic: %lld DOFs, %lld nonzeros; setup: %lld sums of %lld values; steps: %lld "
              "matrices, %lld sums of %lld values (%.1f per matrix), stash %lld values (all "
              "processes)\n",
              (long long)n, (long long)nnz, t0.reduces, t0.reduce_values, matrices,
              t1.reduces - t0.reduces, values, matrices ? (double)values / (double)matrices : 0.0,
              all_sent);
    TEST_TRUE(nnz > n);
    TEST_TRUE(matrices > 0);
    TEST_TRUE(t1.reduce_large == t0.reduce_large); /* no matrix summed in the steps */
    TEST_TRUE(t1.reduce_large == 0);               /* nor at setup (the mass matrix) */
    TEST_TRUE(t0.reduce_values < (long long)nnz);
    TEST_TRUE(values < matrices * (long long)nnz);
    /* the entries went through the distributed matrix: onto owned rows and, when every
     * process has cells of the (connected) body, across processes through the stash */
    TEST_TRUE(all2[2] > 0);
    if (size > 1 && all2[1] == 0) TEST_TRUE(all_sent > 0);
    if (size == 1) TEST_TRUE(t1.matrix_values_sent == 0);
  }
  {
    /* the distributed integrator's space is local (its own cells and a layer of ghosts): its
     * matrices hold the rows of the local copies only; on 2+ processes with a body spread
     * over them, each process holds fewer rows and entries than the whole pattern, and the
     * processes' rows cover every DOF */
    const fcm_space *sp = fcm_simulation_space(par), *ss = fcm_simulation_space(ser);
    const fcm_integrator *ig = ip;
    fcm_index rows = -1, cols = -1, nnzp = 0, nnzs = 0;
    TEST_TRUE(sp->is_local && !ss->is_local);
    fcm_csr_get_size(ig->H, &rows, &cols, &nnzp);
    fcm_csr_get_size(is->H, NULL, NULL, &nnzs);
    TEST_TRUE(rows == fcm__space_num_rows(sp) && cols == n);
    TEST_TRUE(rows <= n && nnzp <= nnzs);
    unsigned char *has = calloc((size_t)n + 1, 1);
    TEST_TRUE(has != NULL);
    for (fcm_index r = 0; has && r < rows; r++)
      has[fcm__space_row_dof(sp, r)] = 1;
    if (has) MPI_Allreduce(MPI_IN_PLACE, has, (int)n, MPI_UNSIGNED_CHAR, MPI_MAX, MPI_COMM_WORLD);
    fcm_index covered = 0;
    for (fcm_index i = 0; has && i < n; i++)
      covered += has[i];
    free(has);
    TEST_TRUE(covered == n);
    if (getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr, "process %d: %lld of %lld rows, %lld of %lld entries, %lld of %lld cells\n",
              rank, (long long)rows, (long long)n, (long long)nnzp, (long long)nnzs,
              (long long)sp->num_local_elems, (long long)ss->num_elems);
    /* the rows and entries summed over the processes fall short of every process holding
     * the whole pattern (on small grids one process's own and ghost cells may still cover
     * all cells; the others then hold less) */
    long long mine3[3] = {rows, nnzp, rows > 0}, all3[3];
    MPI_Allreduce(mine3, all3, 3, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    if (size > 1 && all3[2] == size) {
      TEST_TRUE(all3[0] < (long long)size * n);
      TEST_TRUE(all3[1] < (long long)size * nnzs);
    }
    if (size == 1) TEST_TRUE(rows == n && nnzp == nnzs);
  }
  if (fcm_integrator_mass(is)) {
    /* the uses of the (partial, in the distributed run) mass matrix outside the steps, at the
     * final state: momentum, centre of mass and kinetic energy equal the serial ones */
    double ps[3], ls[3], pp[3], lp[3], cs[3], cp[3], es[3], ep[3];
    TEST_OK(ctx, fcm_integrator_momentum(is, ps, ls));
    TEST_OK(ctx, fcm_integrator_momentum(ip, pp, lp));
    TEST_OK(ctx, fcm_simulation_center_of_mass(ser, cs));
    TEST_OK(ctx, fcm_simulation_center_of_mass(par, cp));
    TEST_OK(ctx, fcm_integrator_energy(is, &es[0], &es[1], &es[2]));
    TEST_OK(ctx, fcm_integrator_energy(ip, &ep[0], &ep[1], &ep[2]));
    /* scales: sum |(M v)_i| bounds |p|; times 2 R (R: the largest |X| coordinate plus the
     * largest |u|) bounds |L|; R bounds the centre of mass */
    const fcm_space *sp = fcm_simulation_space(ser);
    const fcm_mesh *mesh = fcm_space_mesh(sp);
    const double *X = fcm_mesh_coords(mesh), *u = fcm_integrator_displacement(is);
    double *w = calloc((size_t)n + 1, sizeof *w), sw = 0.0, R = 0.0;
    TEST_TRUE(w != NULL);
    if (w) {
      TEST_OK(ctx,
              fcm_csr_apply(fcm_integrator_mass(is), 1.0, fcm_integrator_velocity(is), 0.0, w));
      for (fcm_index i = 0; i < n; i++)
        sw += fabs(w[i]);
    }
    free(w);
    for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++)
      for (int d = 0; d < 3; d++)
        R = fmax(R, fabs(X[3 * a + d]));
    double umax = 0.0;
    for (fcm_index i = 0; i < n; i++)
      umax = fmax(umax, fabs(u[i]));
    R += umax;
    TEST_TRUE(sw > 0.0 && R > 0.0);
    for (int d = 0; d < 3; d++) {
      TEST_TRUE(fabs(pp[d] - ps[d]) <= tol * sw);
      TEST_TRUE(fabs(lp[d] - ls[d]) <= tol * sw * 2.0 * R);
      TEST_TRUE(fabs(cp[d] - cs[d]) <= tol * R);
    }
    const double escale = fabs(es[0]) + fabs(es[1]) + fabs(es[2]) + 1e-300;
    TEST_TRUE(es[0] > 0.0);
    for (int k = 0; k < 3; k++)
      TEST_TRUE(fabs(ep[k] - es[k]) <= tol * escale);
    if (rank == 0 && getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr,
              "final: p (%g %g %g) / (%g %g %g), kinetic %.12g / %.12g, com x %.12g / %.12g\n",
              ps[0], ps[1], ps[2], pp[0], pp[1], pp[2], es[0], ep[0], cs[0], cp[0]);
  }
  if (getenv("FCM_TEST_VERBOSE")) {
    /* the integrator path's memory per process in bytes per DOF (largest over the processes):
     * the space's numbering and topology (fcm__space_memory()), the integrator's matrices
     * (values over the local rows, 8 per nonzero; they share the space's pattern), its
     * n-vectors (u, v, load_prev, the 17 work vectors of setup_storage(), one per load) */
    const fcm_integrator *ig = ip; /* (I: complex.h's) */
    fcm_index nnzp = 0, rows = 0;
    fcm_csr_get_size(ig->H, &rows, NULL, &nnzp);
    const fcm_csr *mats[] = {ig->M, ig->H, ig->D, ig->H0, ig->Hpc, ig->K0};
    int nmat = 0;
    for (size_t k = 0; k < sizeof mats / sizeof mats[0]; k++)
      nmat += mats[k] != NULL;
    double num = 0.0, top = 0.0, mine[4], all[4];
    fcm__space_memory(fcm_simulation_space(par), &num, &top);
    mine[0] = num / (double)n;
    mine[1] = top / (double)n;
    mine[2] = (double)nmat * 8.0 * (double)nnzp / (double)n;
    mine[3] = 8.0 * (20.0 + (double)ig->num_loads);
    MPI_Allreduce(mine, all, 4, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    if (rank == 0)
      fprintf(stderr,
              "memory per process (largest), B/DOF: numbering %.0f, topology %.0f, %d "
              "matrices %.0f (%.0f each), vectors %.0f\n",
              all[0], all[1], nmat, all[2], nmat ? all[2] / nmat : 0.0, all[3]);
  }
  compare_runs(ctx, ser, par, steps, tol, rank);

  fcm_simulation_destroy(&ser);
  fcm_simulation_destroy(&par);
  fcm_scene_destroy(&scene);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
