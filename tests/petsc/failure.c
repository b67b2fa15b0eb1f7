/* Errors of the PETSc backend end every process together, with the message (label mpi, run on
 * 1 and 2 processes under a timeout: a process left waiting in a collective call would hang
 * the test until the timeout fails it):
 * - bad input on ONE process (the last one passes a negative Young's modulus): create fails
 *   on every process with FCM_ERR_ARG, the others' message names the failing process and
 *   carries its message;
 * - a node out of range on process 0 only (add_constraint): FCM_ERR_ARG everywhere;
 * - an unsupported material (hyperelastic) and a static problem without constraints: named;
 * - a KSP that cannot converge (CG without preconditioner, 2 iterations):
 *   FCM_ERR_NOT_CONVERGED on every process with the KSPConvergedReason's name. */
#include "fcm/fcm.h"
#include "fcm/petsc.h"
#include "test_mpi.h"

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_petsc_problem *P = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  const fcm_index cells[3] = {4, 2, 2};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  const fcm_material good = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  fcm_material bad = good;
  if (rank == size - 1) bad.young = -1.0;
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_STATIC;

  /* 1. bad material on the last process only */
  fcm_status s = fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, NULL, &bad, &po, &P);
  TEST_TRUE(s == FCM_ERR_ARG && P == NULL);
  TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "Young's modulus") != NULL);
  if (rank != size - 1) TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "process 1 of 2 failed"));
  fcm_ctx_error_clear(ctx);

  /* 2. unsupported material, everywhere */
  fcm_material snh = good;
  snh.model = FCM_MATERIAL_STABLE_NEO_HOOKEAN;
  TEST_ERR(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, NULL, &snh, &po, &P),
           FCM_ERR_UNSUPPORTED, "linear elasticity only");

  /* 3. a node out of range on process 0 only */
  TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, NULL, &good, &po, &P));
  fcm_index nodes[2] = {0, rank == 0 ? 100000 : 1};
  fcm_motion clamp = fcm_motion_default();
  TEST_ERR(ctx, fcm_petsc_problem_add_constraint(P, 2, nodes, &clamp), FCM_ERR_ARG, "node");
  /* 4. static without constraints (the failed call above added none anywhere): K is singular */
  TEST_ERR(ctx, fcm_petsc_problem_setup(P), FCM_ERR_ARG, "rigid-body");
  fcm_petsc_problem_destroy(&P);

  /* 5. a KSP that cannot converge; its reason is named on every process */
  po.solver.petsc_options = "-ksp_type cg -pc_type none -ksp_max_it 2";
  const double g[3] = {0, -9.81, 0};
  fcm_index fix[25], nfix = 0;
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index k = 0; k < fcm_mesh_num_nodes(mesh); k++)
    if (X[3 * k] == 0.0) fix[nfix++] = k;
  TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, NULL, &good, &po, &P));
  TEST_OK(ctx, fcm_petsc_problem_add_gravity(P, g));
  TEST_OK(ctx, fcm_petsc_problem_add_constraint(P, nfix, fix, &clamp));
  TEST_OK(ctx, fcm_petsc_problem_setup(P));
  fcm_petsc_step_info si;
  TEST_ERR(ctx, fcm_petsc_problem_step(P, &si), FCM_ERR_NOT_CONVERGED, "DIVERGED_ITS");
  fcm_petsc_problem_destroy(&P);

  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
