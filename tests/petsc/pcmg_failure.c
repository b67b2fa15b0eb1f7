/* fcm's multigrid as PCMG (pcmg.c) when ONE process fails locally (label mpi, 2 and 3
 * processes, under a timeout: a process left waiting in a collective call hangs the test until
 * the timeout fails it). Every process has a context whose allocator counts its calls; on
 * process 1 only, allocation k of the setup and first step of a static problem with
 * -pc_type mg fails (fcm_petsc_problem_setup(): the assembly, fcm__petsc_pcmg_setup() with
 * its hierarchy, per-level numbering, prolongations and block smoother lists;
 * fcm_petsc_problem_step(): the block smoothers' setup inside KSPSolve, PCSHELL), for every
 * k = 0, 1, ... until the round succeeds. Asserted in every failing round, on every process:
 * - the setup or the step fails on every process (none succeeds, none hangs);
 * - the message carries the failing allocation's ("out of memory"); on the other processes
 *   it names process 1;
 * - no allocation of the context leaks once the problem is destroyed.
 * Over the sweep: some rounds fail inside the block smoothers' setup (message "fcm block
 * smoother", on every process) and some in fcm__petsc_pcmg_setup() before it, so both were
 * reached; the number of failing rounds equals process 1's allocation count in the successful
 * round over the stride (every allocation was failed once with stride 1); the successful
 * round's displacement is the same bits as that of a run with no failing allocator armed (1e-8
 * relative on 3 processes, where PETSc's sums may vary between runs).
 * The same for the integrator on PETSc (phase 2: fcm_petsc_simulation_create(), -ksp_type cg
 * -pc_type mg): allocation k of the first step (assembly, Newton matrices, newton_factor():
 * fcm__petsc_pcmg_setup() at the first, the block smoothers' setup at every one) failing on
 * process 1: the step fails on every process with the message (the others naming process 1),
 * no leak; the successful round's energy is the unarmed run's.
 * And the creation of the integrator on PETSc itself (mode "create": the arguments and the
 * first allocation, the rules build, the local space, newton_build()'s numbering, matrix
 * preallocation and options): allocation k of fcm_petsc_simulation_create() failing on
 * process 1 fails the creation on every process with the message, none hangs, nothing leaks;
 * the round that succeeds counts process 1's allocations exactly (stride 1: every one failed
 * once). Before the agreements in create_matrix() and before MPI_Comm_dup, allocations there
 * hung the other process in MatCreate / MPI_Comm_dup.
 * Arguments: element (hex8|hex20), N (cells per side of the unit cube, a ball of radius 0.45
 * embedded), [stride: k = 0, stride, 2 stride, ... (default 1)]; or: scene <scene file>
 * [stride]; or: create <scene file> [stride]. */
#define _POSIX_C_SOURCE 200809L /* open_memstream */
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "clamp_util.h"
#include "test_mpi.h"
#include "test_alloc.h"

#include <petscsys.h>

#include <string.h>

static const double grav[3] = {0.0, 0.0, -9.81};
static const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};

/* One round: the problem made with no failure, then setup and one step with allocation
 * `fail_at` (of this process's context, counted from the setup on) failing (-1: none). The
 * displacement into u (n values) when u is not NULL and the round succeeds; this process's
 * allocations in setup + step into *count. */
static fcm_status round_(fcm_ctx *ctx, failing *f, long long fail_at, const fcm_mesh *mesh,
                         const fcm_geometry *geom, double *u, long long *count)
{
  fcm_petsc_problem *P = NULL;
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_STATIC;
  po.solver.rtol = 1e-10;
  po.solver.petsc_options = "-pc_type mg";
  po.solver.partition = FCM_PETSC_PARTITION_ORDERED;
  fcm_index nfix = 0, *fix = NULL;
  fcm_petsc_step_info si;
  const fcm_motion clamp = fcm_motion_default();
  fcm_status st = fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P);
  if (st) goto done;
  fix = clamped(mesh, fcm_petsc_problem_space(P), &nfix);
  if ((st = fcm_petsc_problem_add_gravity(P, grav))) goto done;
  if ((st = fcm_petsc_problem_add_constraint(P, nfix, fix, &clamp))) goto done;
  f->count = 0;
  f->fail_at = fail_at;
  st = fcm_petsc_problem_setup(P);
  if (!st) st = fcm_petsc_problem_step(P, &si);
  f->fail_at = -1;
  *count = f->count;
  if (!st && u) st = fcm_petsc_problem_get_state(P, u, NULL);
done:
  f->fail_at = -1;
  free(fix);
  fcm_petsc_problem_destroy(&P);
  return st;
}

/* The checks of a round in which allocation k failed on process 1 (process 0 on one
 * process), `what` naming the sweep: every process failed (all_failed of them), the message
 * carries the allocation's failure and, on the other processes, names the failing one; once
 * the error is cleared, no allocation beyond `live` is left. Read the message before. */
static void check_failed_round(fcm_ctx *ctx, const char *what, long long k, int all_failed,
                               long long live)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int bad = size > 1 ? 1 : 0;
  char other[64];
  snprintf(other, sizeof other, "process %d of %d failed", bad, size);
  const char *msg = fcm_ctx_error_message(ctx);
  if (all_failed != size)
    TEST_FAIL_("%s: allocation %lld failing on process %d: %d of %d processes failed; this one: "
               "%s",
               what, k, bad, all_failed, size, msg);
  if (!strstr(msg, "out of memory") || (rank != bad && !strstr(msg, other)))
    TEST_FAIL_("%s: allocation %lld failing on process %d: message on process %d: %s", what, k, bad,
               rank, msg);
  fcm_ctx_error_clear(ctx);
  if (fcm_ctx_live_allocations(ctx) != live)
    TEST_FAIL_("%s: allocation %lld failing on process %d: %lld allocations leaked", what, k, bad,
               fcm_ctx_live_allocations(ctx) - live);
}

/* Phase 2 (the integrator on PETSc, -ksp_type cg -pc_type mg: newton_factor() sets the levels
 * up at the first Newton matrix): the simulation of `scene` made with no failure, then its
 * first step with allocation `fail_at` failing (-1: none); this process's allocations in the
 * step into *count, its energy into *energy. */
static fcm_status round_scene(fcm_ctx *ctx, failing *f, long long fail_at, const fcm_scene *scene,
                              long long *count, double *energy)
{
  fcm_simulation *sim = NULL;
  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = 1;
  fcm_step_info si;
  fcm_status st = fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene,
                                              FCM_PETSC_PARTITION_ORDERED, &so, &sim);
  if (st) goto done;
  f->count = 0;
  f->fail_at = fail_at;
  st = fcm_simulation_step(sim, &si);
  f->fail_at = -1;
  *count = f->count;
  if (!st) *energy = si.total_energy;
done:
  f->fail_at = -1;
  fcm_simulation_destroy(&sim);
  return st;
}

static int scene_main(fcm_ctx *ctx, failing *f, const char *path, long long stride)
{
  fcm_scene *scene = NULL;
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int bad = size > 1 ? 1 : 0;
  if (PetscOptionsSetValue(NULL, "-ksp_type", "cg") || PetscOptionsSetValue(NULL, "-pc_type", "mg"))
    return 1;
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  long long count = 0, failures = 0, count_ok = -1, in_smoother = 0;
  double e0 = 0.0, e = 0.0;
  TEST_OK(ctx, round_scene(ctx, f, -1, scene, &count, &e0));
  if (getenv("FCM_TEST_VERBOSE") && rank == bad)
    fprintf(stderr, "scene: %lld allocations in the step on process %d, energy %a\n", count, bad,
            e0);
  const long long live = fcm_ctx_live_allocations(ctx);
  for (long long k = 0; k < 1000000 && !test_failures_; k += stride) {
    const fcm_status st = round_scene(ctx, f, rank == bad ? k : -1, scene, &count, &e);
    int mine[2] = {st == FCM_OK, st != FCM_OK}, all[2] = {0, 0};
    MPI_Allreduce(mine, all, 2, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    if (all[0] == size) {
      count_ok = count;
      TEST_TRUE(e == e0);
      break;
    }
    failures++;
    const char *msg = fcm_ctx_error_message(ctx);
    if (getenv("FCM_TEST_VERBOSE") && rank == 0) fprintf(stderr, "%lld: %s\n", k, msg);
    in_smoother += strstr(msg, "fcm block smoother") != NULL;
    check_failed_round(ctx, "scene", k, all[1], live);
  }
  long long cnt = rank == bad ? count_ok : 0, cnt_all = 0;
  MPI_Allreduce(&cnt, &cnt_all, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
  if (rank == 0)
    printf("pcmg_failure scene on %d processes: %lld failing rounds (%lld in the block smoothers' "
           "setup), %lld allocations in the step on process %d\n",
           size, failures, in_smoother, cnt_all, bad);
  TEST_TRUE(cnt_all > 0);
  TEST_TRUE(failures == (cnt_all + stride - 1) / stride);
  TEST_TRUE(in_smoother > 0);
  fcm_scene_destroy(&scene);
  return 0;
}

/* Mode "create": allocation k of fcm_petsc_simulation_create() failing on process 1. */
static int create_main(fcm_ctx *ctx, failing *f, const char *path, long long stride)
{
  fcm_scene *scene = NULL;
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int bad = size > 1 ? 1 : 0;
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  const long long live = fcm_ctx_live_allocations(ctx);
  long long failures = 0, count_ok = -1;
  for (long long k = 0; k < 10000000 && !test_failures_; k += stride) {
    fcm_simulation *sim = NULL;
    f->count = 0;
    f->fail_at = rank == bad ? k : -1;
    const fcm_status st = fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene,
                                                      FCM_PETSC_PARTITION_ORDERED, NULL, &sim);
    f->fail_at = -1;
    const long long count = f->count;
    fcm_simulation_destroy(&sim);
    int mine[2] = {st == FCM_OK, st != FCM_OK}, all[2] = {0, 0};
    MPI_Allreduce(mine, all, 2, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    if (all[0] == size) {
      count_ok = count;
      break;
    }
    failures++;
    check_failed_round(ctx, "create", k, all[1], live);
  }
  long long cnt = rank == bad ? count_ok : 0, cnt_all = 0;
  MPI_Allreduce(&cnt, &cnt_all, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
  if (rank == 0)
    printf("pcmg_failure create on %d processes: %lld failing rounds, %lld allocations in the "
           "creation on process %d\n",
           size, failures, cnt_all, bad);
  TEST_TRUE(cnt_all > 0);
  TEST_TRUE(failures == (cnt_all + stride - 1) / stride);
  fcm_scene_destroy(&scene);
  return 0;
}

int main(int argc, char **argv)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_element_type type;
  if (!ctx) return 1;
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc >= 3 && (strcmp(argv[1], "scene") == 0 || strcmp(argv[1], "create") == 0)) {
    if (argv[1][0] == 's')
      scene_main(ctx, &f, argv[2], argc > 3 ? atoll(argv[3]) : 1);
    else
      create_main(ctx, &f, argv[2], argc > 3 ? atoll(argv[3]) : 1);
    fcm_ctx_destroy(&ctx);
    return test_mpi_result();
  }
  if (argc < 3 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const fcm_index N = atoi(argv[2]);
  const long long stride = argc > 3 ? atoll(argv[3]) : 1;
  if (stride < 1) return 2;
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int bad = size > 1 ? 1 : 0; /* the failing process */
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.5, 0.5, 0.5};
  const fcm_index cells[3] = {N, N, N};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.45, 4, &geom));

  /* the reference: no allocation fails */
  long long count = 0;
  double *u0 = NULL, *u = NULL;
  fcm_index n = 0;
  {
    fcm_petsc_problem *P = NULL;
    fcm_petsc_options po = fcm_petsc_options_default();
    TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P));
    n = fcm_petsc_problem_num_dofs(P);
    fcm_petsc_problem_destroy(&P);
  }
  u0 = calloc((size_t)n + 1, sizeof *u0);
  u = calloc((size_t)n + 1, sizeof *u);
  TEST_OK(ctx, round_(ctx, &f, -1, mesh, geom, u0, &count));
  if (rank == 0 && getenv("FCM_TEST_VERBOSE")) { /* FNV-1a of the bits (compare builds) */
    unsigned long long h = 14695981039346656037ULL;
    const unsigned char *p = (const unsigned char *)u0;
    for (size_t i = 0; i < sizeof *u0 * (size_t)n; i++)
      h = (h ^ p[i]) * 1099511628211ULL;
    fprintf(stderr, "reference displacement: hash %016llx\n", h);
  }

  const long long live = fcm_ctx_live_allocations(ctx);
  long long failures = 0, in_smoother = 0, before_smoother = 0, count_ok = -1;
  for (long long k = 0; k < 100000 && !test_failures_; k += stride) {
    const fcm_status st = round_(ctx, &f, rank == bad ? k : -1, mesh, geom, u, &count);
    /* [0]: processes that succeeded, [1]: processes that failed */
    int mine[2] = {st == FCM_OK, st != FCM_OK}, all[2] = {0, 0};
    MPI_Allreduce(mine, all, 2, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    if (all[0] == size) { /* every allocation of the failing process was failed once */
      count_ok = count;
      if (size <= 2) { /* the same bits (on 3 processes PETSc's sums vary between runs) */
        TEST_TRUE(memcmp(u, u0, sizeof *u * (size_t)n) == 0);
      } else {
        double d = 0.0, a = 0.0;
        for (fcm_index i = 0; i < n; i++)
          d += (u[i] - u0[i]) * (u[i] - u0[i]), a += u0[i] * u0[i];
        TEST_TRUE(d <= 1e-16 * a);
      }
      break;
    }
    failures++;
    const char *msg = fcm_ctx_error_message(ctx);
    if (getenv("FCM_TEST_VERBOSE") && rank == 0) fprintf(stderr, "%lld: %s\n", k, msg);
    if (rank == bad) { /* where it failed: the message, the traceback */
      char *view = NULL;
      size_t len = 0;
      FILE *mem = open_memstream(&view, &len);
      if (mem) {
        fcm_ctx_error_view(ctx, mem);
        fclose(mem);
      }
      if (strstr(msg, "fcm block smoother"))
        in_smoother++;
      else if (view && strstr(view, "fcm__petsc_pcmg_setup"))
        before_smoother++;
      free(view);
    }
    check_failed_round(ctx, "setup", k, all[1], live);
  }
  /* the successful round's allocation count on the failing process: every one failed once */
  long long cnt[3] = {rank == bad ? count_ok : 0, in_smoother, before_smoother}, cnt_all[3];
  MPI_Allreduce(cnt, cnt_all, 3, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
  in_smoother = cnt_all[1], before_smoother = cnt_all[2];
  if (rank == 0)
    printf("pcmg_failure %s N %lld on %d processes: %lld DOFs, %lld failing rounds (%lld in the "
           "block smoothers' setup, %lld in pcmg.c before it), %lld allocations in setup + step "
           "on process %d\n",
           argv[1], (long long)N, size, (long long)n, failures, in_smoother, before_smoother,
           cnt_all[0], bad);
  TEST_TRUE(cnt_all[0] > 0);
  TEST_TRUE(failures == (cnt_all[0] + stride - 1) / stride);
  TEST_TRUE(in_smoother > 0);
  TEST_TRUE(before_smoother > 0);

  free(u0), free(u);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
