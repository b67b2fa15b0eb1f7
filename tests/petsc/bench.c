/* Memory and time per DOF of the PETSc backend (labels bench and mpi; not in the default run):
 * a ball (radius 0.45) embedded in an N^3 grid of the unit cube, clamped on its lowest nodes
 * layer, under gravity, static; the default solver (CG + GAMG; on Hex20 CG + fcm's multigrid as
 * PCMG) to rtol 1e-8. Process 0 prints one
 * line: processes, element, DOFs, setup seconds (partition + rules + numbering + assembly +
 * KSP setup) and KSP solve seconds per DOF, peak resident memory summed over the processes per
 * DOF, the matrix's bytes per DOF (nonzeros x 12 bytes), KSP iterations; the geometry each
 * process's rules build read (the crop: cells, boundary triangles, bytes, against the whole);
 * and the topology's bytes per DOF on each process (fcm__space_memory(): the replicated
 * numbering, the local space's copy graph + pattern + offsets + colours against the full
 * space's, which every process held before the local space). Arguments: element, N, [ball
 * resolution, default 4]. Run: mpirun -n P petsc_bench hex8 24 [8]. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/petsc.h"
#include "petsc/petsc_impl.h" /* the problem's space and arrays: topology bytes */
#include "test_mpi.h"

#include <sys/resource.h>

/* CPU seconds of this process (user + system). */
static double cpu_seconds(void)
{
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
         (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_petsc_problem *P = NULL;
  fcm_element_type type;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 3 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const fcm_index N = atoi(argv[2]);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.5, 0.5, 0.5};
  const fcm_index cells[3] = {N, N, N};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  const int res = argc > 3 ? atoi(argv[3]) : 4;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.45, res, &geom));
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_STATIC;
  po.solver.rtol = 1e-8;
  MPI_Barrier(MPI_COMM_WORLD);
  double t0 = MPI_Wtime(), c0 = cpu_seconds();
  TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P));
  /* clamp the nodes with DOFs in the lowest z layer of cells the ball reaches */
  const fcm_space *space = fcm_petsc_problem_space(P);
  const double *X = fcm_mesh_coords(mesh);
  fcm_index nn = fcm_mesh_num_nodes(mesh), *fix = calloc((size_t)nn, sizeof *fix), nfix = 0;
  double zmin = 2.0;
  for (fcm_index k = 0; k < nn; k++)
    if (fcm_space_node_dof(space, k) >= 0 && X[3 * k + 2] < zmin) zmin = X[3 * k + 2];
  for (fcm_index k = 0; k < nn; k++)
    if (fcm_space_node_dof(space, k) >= 0 && X[3 * k + 2] <= zmin + 1e-12) fix[nfix++] = k;
  const double g[3] = {0, 0, -9.81};
  const fcm_motion clamp = fcm_motion_default();
  TEST_OK(ctx, fcm_petsc_problem_add_gravity(P, g));
  TEST_OK(ctx, fcm_petsc_problem_add_constraint(P, nfix, fix, &clamp));
  TEST_OK(ctx, fcm_petsc_problem_setup(P));
  MPI_Barrier(MPI_COMM_WORLD);
  const double t_setup = MPI_Wtime() - t0, c_setup = cpu_seconds() - c0;
  fcm_petsc_step_info si;
  memset(&si, 0, sizeof si);
  t0 = MPI_Wtime(), c0 = cpu_seconds();
  TEST_OK(ctx, fcm_petsc_problem_step(P, &si));
  MPI_Barrier(MPI_COMM_WORLD);
  const double t_solve = MPI_Wtime() - t0, c_solve = cpu_seconds() - c0;
  double cpu[2] = {c_setup, c_solve}, cpu_max[2], cpu_sum[2];
  MPI_Allreduce(cpu, cpu_max, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(cpu, cpu_sum, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  fcm_petsc_info info;
  TEST_OK(ctx, fcm_petsc_problem_get_info(P, &info));
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  double peak_local = 1024.0 * (double)ru.ru_maxrss, peak_all = 0.0; /* Linux: kilobytes */
  MPI_Allreduce(&peak_local, &peak_all, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  const double n = (double)info.num_dofs;
  const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(fcm_space_cell_rules(space));
  /* the rules build per process: intersection (the classification of the cells it classifies,
   * with the mapping and surface rules of its own cut cells) and simplification; resident memory
   * per process */
  double rt[3] = {rs->time_intersect, rs->time_simplify, peak_local}, rt_max[3], rt_min[3];
  MPI_Allreduce(rt, rt_max, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(rt, rt_min, 3, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  if (rank == 0)
    printf("petsc_bench np %d: rules build per process: intersect %.3g..%.3g core-s, simplify + "
           "stabilize %.3g..%.3g core-s (%lld cut cells in all); peak resident %.1f..%.1f MB per "
           "process\n",
           size, rt_min[0], rt_max[0], rt_min[1], rt_max[1], (long long)rs->num_cut,
           rt_min[2] / 1e6, rt_max[2] / 1e6);
  /* the geometry read per process (kept) against the whole (every process reads it here) */
  double gk[3] = {(double)info.geometry_cells_kept, (double)info.geometry_triangles_kept,
                  info.geometry_bytes_kept},
         gk_max[3], gk_min[3];
  MPI_Allreduce(gk, gk_max, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(gk, gk_min, 3, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  if (rank == 0)
    printf("petsc_bench np %d: geometry (ball resolution %d) read by the rules build per "
           "process: cells %.0f..%.0f of %lld, boundary triangles %.0f..%.0f of %lld, %.3g..%.3g "
           "MB of %.3g MB (%.1f..%.1f B/dof of %.1f)\n",
           size, res, gk_min[0], gk_max[0], (long long)info.geometry_cells, gk_min[1], gk_max[1],
           (long long)info.geometry_triangles, gk_min[2] / 1e6, gk_max[2] / 1e6,
           info.geometry_bytes / 1e6, gk_min[2] / n, gk_max[2] / n, info.geometry_bytes / n);
  if (rank == 0)
    printf("petsc_bench np %d: CPU seconds (user + system; busy MPI waits count) per DOF: setup "
           "%.3g us max over processes / %.3g us summed, solve %.3g us max / %.3g us summed\n",
           size, 1e6 * cpu_max[0] / (double)info.num_dofs, 1e6 * cpu_sum[0] / (double)info.num_dofs,
           1e6 * cpu_max[1] / (double)info.num_dofs, 1e6 * cpu_sum[1] / (double)info.num_dofs);
  if (rank == 0)
    printf("petsc_bench np %d %s N %lld: dofs %lld, setup %.3g us/dof (%.3g s: rules %.3g s, "
           "assembly %.3g s on process 0), solve %.3g us/dof (%.3g s, %d %s+%s iterations), "
           "memory %.0f B/dof resident now / %.0f peak (all processes), matrix %.0f B/dof, "
           "elements per process %lld..%lld, partition %s\n",
           size, argv[1], (long long)N, (long long)info.num_dofs, 1e6 * t_setup / n, t_setup,
           info.time_rules, info.time_assembly, 1e6 * t_solve / n, t_solve, si.iterations,
           info.ksp_type, info.pc_type, info.memory_total / n, peak_all / n, info.matrix_memory / n,
           (long long)info.min_local_elements, (long long)info.max_local_elements,
           fcm_petsc_partition_name(info.partition));
  { /* topology bytes per DOF (this process; max and min over the processes) */
    fcm_space *full = NULL;
    double num = 0.0, loc = 0.0, whole = 0.0;
    fcm__space_memory(P->space, &num, &loc);
    if (P->rules)
      TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, P->rules, &full));
    else
      TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &full));
    if (full) fcm__space_memory(full, NULL, &whole);
    fcm_space_destroy(&full);
    /* the adapter's replicated arrays: perm, copy_owner per copy, is_con per DOF, cell_owner
     * and weight per cell */
    const double nc = (double)fcm_mesh_num_cells(mesh);
    const double adapter = (double)(sizeof(PetscInt) + sizeof(int)) * (double)P->ncopy +
                           (double)P->n + (sizeof(int) + 1.0) * nc;
    double mine[2] = {loc, -loc}, ext[2];
    MPI_Allreduce(mine, ext, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    if (rank == 0)
      printf("petsc_bench np %d %s N %lld: topology bytes/DOF per process: numbering %.1f "
             "(replicated) + adapter %.1f (replicated); copy graph + pattern + offsets + "
             "colours: full space %.1f (as if on every process), local space %.1f..%.1f "
             "(own + ghost cells)\n",
             size, argv[1], (long long)N, num / n, adapter / n, whole / n, -ext[1] / n, ext[0] / n);
  }
  TEST_TRUE(si.reason > 0);
  free(fix);
  fcm_petsc_problem_destroy(&P);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
