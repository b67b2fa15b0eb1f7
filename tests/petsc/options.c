/* Each problem of the PETSc backend reads its PETSc options under its own prefix (label mpi, 1
 * and 2 processes):
 * - linear driver: three problems made in sequence in one process, with the options strings
 *   "-ksp_type minres -pc_type jacobi", none, and "-ksp_type gmres", have the KSP / PC types
 *   minres / jacobi, cg / gamg (the defaults: nothing of the first leaked) and gmres / gamg;
 *   their prefixes are fcm1_, fcm2_, fcm3_ (fcm_petsc_info.options_prefix), and every one
 *   solves (the solution agrees with the first problem's to 1e-6 relative);
 * - the command line wins: run with "-ksp_type bcgs" every problem's KSP is bcgs (the PCs
 *   stay each problem's own); with "-fcm2_pc_type jacobi" only the second problem's PC is
 *   jacobi; arguments: the expected KSP types of the three problems, then the expected PC
 *   types, then PETSc options;
 * - the integrator's path (fcm_petsc_simulation_create()): a scene whose solver.petsc_options
 *   make every linear solve fail (Richardson without preconditioner, one iteration) fails
 *   its step, and the same scene without options made after it in the same process steps
 *   (before the prefixes, the first scene's options stayed in the global database);
 * - a PETSc error (an unknown PC type in a problem's options) is an fcm error naming the type,
 *   and nothing is printed on stderr meanwhile (fcm_petsc_initialize() replaced PETSc's
 *   traceback handler). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "test_mpi.h"

#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char scene_fmt[] =
    "{\"version\": 1, \"name\": \"options_%d\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, -0.25, -0.25],"
    "   \"max\": [2.5, 1.25, 1.25]}, \"cells\": [5, 3, 3]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [2, 1, 1],"
    "   \"cells\": [2, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"static\": true, \"steps\": 1},"
    " \"solver\": {\"method\": \"cg\"%s},"
    " \"effects\": [{\"gravity\": {\"acceleration\": [0, -9.81, 0]}},"
    "   {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, "
    "0]}}}}]}";

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  TEST_TRUE(argc >= 7);
  const char *want_ksp[3] = {argv[1], argv[2], argv[3]};
  const char *want_pc[3] = {argv[4], argv[5], argv[6]};
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  const fcm_index cells[3] = {4, 2, 2};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  const double g[3] = {0, -9.81, 0};
  fcm_index fix[64], nfix = 0;
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index k = 0; k < fcm_mesh_num_nodes(mesh); k++)
    if (X[3 * k] == 0.0) fix[nfix++] = k;
  const fcm_motion clamp = fcm_motion_default();

  /* 1. three linear problems in sequence */
  const char *strings[3] = {"-ksp_type minres -pc_type jacobi", NULL, "-ksp_type gmres"};
  const fcm_index n = 3 * fcm_mesh_num_nodes(mesh);
  double *u[3] = {NULL, NULL, NULL};
  for (int k = 0; k < 3; k++) {
    fcm_petsc_problem *P = NULL;
    fcm_petsc_options po = fcm_petsc_options_default();
    po.kind = FCM_INTEGRATOR_STATIC;
    po.solver.rtol = 1e-10;
    po.solver.petsc_options = strings[k];
    TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, NULL, &mat, &po, &P));
    TEST_OK(ctx, fcm_petsc_problem_add_gravity(P, g));
    TEST_OK(ctx, fcm_petsc_problem_add_constraint(P, nfix, fix, &clamp));
    TEST_OK(ctx, fcm_petsc_problem_setup(P));
    fcm_petsc_step_info si;
    TEST_OK(ctx, fcm_petsc_problem_step(P, &si));
    TEST_TRUE(si.reason > 0 && si.iterations >= 1);
    fcm_petsc_info info;
    TEST_OK(ctx, fcm_petsc_problem_get_info(P, &info));
    char prefix[32];
    snprintf(prefix, sizeof prefix, "fcm%d_", k + 1);
    TEST_TRUE(strcmp(info.options_prefix, prefix) == 0);
    if (strcmp(info.ksp_type, want_ksp[k]) || strcmp(info.pc_type, want_pc[k]))
      fprintf(stderr, "problem %d: KSP %s PC %s, expected %s %s\n", k + 1, info.ksp_type,
              info.pc_type, want_ksp[k], want_pc[k]);
    TEST_TRUE(strcmp(info.ksp_type, want_ksp[k]) == 0);
    TEST_TRUE(strcmp(info.pc_type, want_pc[k]) == 0);
    TEST_TRUE(fcm_petsc_problem_num_dofs(P) == n);
    u[k] = calloc((size_t)n, sizeof *u[k]);
    TEST_TRUE(u[k] != NULL);
    TEST_OK(ctx, fcm_petsc_problem_get_state(P, u[k], NULL));
    fcm_petsc_problem_destroy(&P);
  }
  double d1 = 0.0, d2 = 0.0, nu = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    d1 += (u[1][i] - u[0][i]) * (u[1][i] - u[0][i]);
    d2 += (u[2][i] - u[0][i]) * (u[2][i] - u[0][i]);
    nu += u[0][i] * u[0][i];
  }
  TEST_TRUE(nu > 0.0);
  TEST_TRUE(sqrt(d1) <= 1e-6 * sqrt(nu) && sqrt(d2) <= 1e-6 * sqrt(nu));
  for (int k = 0; k < 3; k++)
    free(u[k]);

  /* 2. the integrator's path: failing options on one scene do not reach the next one */
  for (int k = 0; k < 2; k++) {
    char json[2048];
    snprintf(json, sizeof json, scene_fmt, k,
             k == 0 ? ", \"petsc_options\": \"-ksp_type richardson -pc_type none -ksp_max_it 1\""
                    : "");
    fcm_scene *scene = NULL;
    fcm_simulation *sim = NULL;
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "options.json", &scene));
    TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                             NULL, &sim));
    fcm_step_info si;
    const fcm_status s = fcm_simulation_step(sim, &si);
    if (k == 0) {
      TEST_TRUE(s != FCM_OK);
      fcm_ctx_error_clear(ctx);
    } else {
      if (s != FCM_OK) fprintf(stderr, "second scene: %s\n", fcm_ctx_error_message(ctx));
      TEST_TRUE(s == FCM_OK);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  }

  /* 3. a PETSc error: an fcm error with PETSc's message, nothing on stderr */
  {
    fcm_petsc_problem *P = NULL;
    fcm_petsc_options po = fcm_petsc_options_default();
    po.kind = FCM_INTEGRATOR_STATIC;
    po.solver.petsc_options = "-pc_type no_such_pc";
    TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, NULL, &mat, &po, &P));
    TEST_OK(ctx, fcm_petsc_problem_add_gravity(P, g));
    TEST_OK(ctx, fcm_petsc_problem_add_constraint(P, nfix, fix, &clamp));
    char path[] = "/tmp/fcm_petsc_stderr_XXXXXX";
    const int fd = mkstemp(path);
    TEST_TRUE(fd >= 0);
    fflush(stderr);
    const int saved = dup(2);
    TEST_TRUE(saved >= 0);
    if (fd >= 0 && saved >= 0) dup2(fd, 2);
    const fcm_status s = fcm_petsc_problem_setup(P);
    fflush(stderr);
    if (fd >= 0 && saved >= 0) dup2(saved, 2);
    struct stat sb;
    TEST_TRUE(fd >= 0 && fstat(fd, &sb) == 0 && sb.st_size == 0);
    if (fd >= 0) {
      close(fd);
      unlink(path);
    }
    if (saved >= 0) close(saved);
    TEST_TRUE(s == FCM_ERR_INTERNAL);
    if (s != FCM_OK && !strstr(fcm_ctx_error_message(ctx), "no_such_pc"))
      fprintf(stderr, "message: %s\n", fcm_ctx_error_message(ctx));
    TEST_TRUE(s != FCM_OK && strstr(fcm_ctx_error_message(ctx), "no_such_pc") != NULL);
    fcm_ctx_error_clear(ctx);
    fcm_petsc_problem_destroy(&P);
  }

  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
