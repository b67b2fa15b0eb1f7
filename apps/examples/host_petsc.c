/* A host program of fcm's PETSc component (fcm/petsc.h; `pkg-config --cflags --libs fcm-petsc`
 * or find_package(fcm COMPONENTS petsc) with fcm::petsc): a block clamped at its base sags under
 * gravity, solved statically by the distributed linear driver on the processes it is started
 * on (`mpiexec -n 2 host_petsc`, or alone). At equilibrium K u = f, so the elastic energy
 * 1/2 u^T K u is half the work f^T u of the load: checked to 1e-6 (the KSP's rtol is 1e-10). */
#include <fcm/petsc.h>

#include <math.h>
#include <stdio.h>

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_petsc_problem *problem = NULL;
  fcm_index base[64], num_base = 0;
  int ok = 0;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  if (fcm_petsc_initialize(ctx, &argc, &argv) != FCM_OK) {
    fprintf(stderr, "host_petsc: %s\n", fcm_ctx_error_message(ctx));
    fcm_ctx_destroy(&ctx);
    return 1;
  }
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 2}, down[3] = {0, 0, -9.81};
  const double base_lo[3] = {0, 0, 0}, base_hi[3] = {1, 1, 0};
  const fcm_index cells[3] = {2, 2, 4};
  const fcm_material steel = {FCM_MATERIAL_LINEAR, 2.0e11, 0.3, 7850.0};
  fcm_petsc_options opts = fcm_petsc_options_default();
  opts.kind = FCM_INTEGRATOR_STATIC;
  const fcm_motion clamp = fcm_motion_default();
  fcm_petsc_step_info info;
  if (fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh) == FCM_OK &&
      fcm_mesh_nodes_in_box(ctx, mesh, base_lo, base_hi, 1e-9, 64, base, &num_base) == FCM_OK &&
      fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, NULL, &steel, &opts, &problem) ==
          FCM_OK &&
      fcm_petsc_problem_add_gravity(problem, down) == FCM_OK &&
      fcm_petsc_problem_add_constraint(problem, num_base, base, &clamp) == FCM_OK &&
      fcm_petsc_problem_setup(problem) == FCM_OK &&
      fcm_petsc_problem_step(problem, &info) == FCM_OK) {
    const double gap = fabs(2.0 * info.elastic_energy - info.external_work);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    ok = info.external_work > 0 && gap <= 1e-6 * info.external_work;
    if (rank == 0)
      printf("host_petsc: %lld DOFs, %d KSP iterations, elastic energy %.6e J, "
             "work of the load %.6e J (ratio %.9f)\n",
             (long long)fcm_petsc_problem_num_dofs(problem), info.iterations, info.elastic_energy,
             info.external_work, info.elastic_energy / info.external_work);
  } else {
    fprintf(stderr, "host_petsc: %s\n", fcm_ctx_error_message(ctx));
  }
  fcm_petsc_problem_destroy(&problem);
  fcm_mesh_destroy(&mesh);
  fcm_petsc_finalize();
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
