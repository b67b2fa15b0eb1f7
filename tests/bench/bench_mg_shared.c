/* Benchmark: linear-solve steps of CG + multigrid and of MINRES + Schwarz alone and beside
 * busy-loop processes (shared cores); prints the per-step times and the slowdown loaded / alone.
 *
 * System: the hollow ball of apps/scenes/hollow_ball_multigrid.json (radii 0.75 and 1, three
 * holes of radius 0.3) on a Hex8 grid of n^3 cells of [-1.05, 1.05]^3, the implicit step
 * matrix A = M + dt^2 K (linear elasticity E = 1e7, nu = 0.45, rho = 1000, dt = 0.02), the
 * bottom cap clamped, gravity. A step of each solver is what a Newton iteration of a scene
 * does on new values of the same pattern: CG + multigrid (the scene defaults: W-cycle, SGS,
 * block smoothing) = fcm_mg_setup() + CG to rtol 1e-8; MINRES + Schwarz (cut cells of
 * volume fraction below 0.5) = fcm_schwarz_setup() + MINRES to rtol 1e-8; the hierarchy
 * build (fcm_mg_create(), once per pattern) is timed as its own phase. Each round times every
 * phase alone, then beside `busy` busy-loop child processes (default 8), which are killed
 * afterwards; rounds alternate so a drift of the machine's other load reaches both sides.
 *
 * Usage: bench_mg_shared [n [rounds [busy [mg]]]]   (defaults 36, 3, 8; "mg": the multigrid
 * phases only). Each round also prints the cores that other processes (not this one, not its
 * busy loops) kept busy during its phases, from /proc/stat: a shared machine's other users
 * make both times longer and the ratio meaningless when they come and go.
 * Run it as the programs run (OMP_WAIT_POLICY=passive: ctest sets it). Prints figures and
 * asserts only that every solve converges and that the loaded solves are bitwise equal to
 * the lone ones (the result does not depend on the scheduling). */
#define _GNU_SOURCE /* getloadavg */
#include "../../apps/app_env.h"
#include "fcm/fcm.h"
#include "test.h"

#include <omp.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define MAX_ROUNDS 15
#define MAX_BUSY   64

enum { PH_CREATE, PH_MG, PH_SCHWARZ, PH_COUNT };
static const char *const PH_NAME[PH_COUNT] = {"multigrid hierarchy (fcm_mg_create)",
                                              "CG + multigrid step (setup + solve)",
                                              "MINRES + Schwarz step (setup + solve)"};

typedef struct bench {
  fcm_ctx *ctx;
  fcm_space *space;
  fcm_csr *A;
  double *b;
  fcm_index n;
  fcm_krylov *ws;
  fcm_mg *mg;
  fcm_schwarz *P;
  double *x[PH_COUNT][2]; /* last iterate: alone, loaded */
  int iterations[PH_COUNT][2];
} bench;

static double cpu_seconds(void)
{
  return (double)clock() / CLOCKS_PER_SEC;
}

/* CPU seconds the machine spent busy so far (all processes, /proc/stat), -1 if unknown. */
static double machine_busy(void)
{
  unsigned long long v[8] = {0};
  FILE *f = fopen("/proc/stat", "r");
  if (!f) return -1.0;
  const int got = fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2],
                         &v[3], &v[4], &v[5], &v[6], &v[7]);
  fclose(f);
  if (got != 8) return -1.0;
  /* user nice system idle iowait irq softirq steal: all but idle and iowait */
  return (double)(v[0] + v[1] + v[2] + v[5] + v[6] + v[7]) / (double)sysconf(_SC_CLK_TCK);
}

/* CPU seconds of process `pid` so far (/proc/pid/stat utime + stime), 0 if unknown. */
static double process_cpu(pid_t pid)
{
  char path[64], buf[1024];
  snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
  FILE *f = fopen(path, "r");
  if (!f) return 0.0;
  const size_t len = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[len] = '\0';
  const char *p = strrchr(buf, ')'); /* the command name may hold spaces */
  unsigned long long ut = 0, stime = 0;
  if (!p ||
      sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &ut, &stime) != 2)
    return 0.0;
  return (double)(ut + stime) / (double)sysconf(_SC_CLK_TCK);
}

/* Start `count` busy-loop child processes (they die with this process). */
static int busy_start(int count, pid_t *pids)
{
  for (int k = 0; k < count; k++) {
    pids[k] = fork();
    if (pids[k] == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      for (volatile unsigned long i = 0;; i++) {
      }
    }
    if (pids[k] < 0) return 0;
  }
  return 1;
}

static void busy_stop(int count, pid_t *pids)
{
  for (int k = 0; k < count; k++)
    if (pids[k] > 0) {
      kill(pids[k], SIGKILL);
      waitpid(pids[k], NULL, 0);
      pids[k] = 0;
    }
}

/* One phase; its wall and CPU seconds. */
static void run_phase(bench *B, int ph, int loaded, double *wall, double *cpu)
{
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = 1e-8;
  ko.max_iterations = 20000;
  fcm_krylov_info ki;
  double *x = B->x[ph][loaded];
  memset(x, 0, sizeof *x * (size_t)B->n);
  const double w0 = fcm_wtime(), c0 = cpu_seconds();
  if (ph == PH_CREATE) {
    fcm_mg_destroy(&B->mg);
    TEST_OK(B->ctx, fcm_mg_create(B->ctx, B->space, B->A, NULL, &B->mg));
  } else if (ph == PH_MG) {
    TEST_OK(B->ctx, fcm_mg_setup(B->mg));
    TEST_OK(B->ctx, fcm_krylov_cg(B->ws, fcm_csr_operator, B->A, fcm_mg_operator, B->mg, B->b, x,
                                  &ko, &ki));
  } else {
    TEST_OK(B->ctx, fcm_schwarz_setup(B->P, B->A));
    TEST_OK(B->ctx, fcm_krylov_minres(B->ws, fcm_csr_operator, B->A, fcm_schwarz_operator, B->P,
                                      B->b, x, &ko, &ki));
  }
  *wall = fcm_wtime() - w0;
  *cpu = cpu_seconds() - c0;
  if (ph != PH_CREATE) {
    TEST_TRUE(ki.reason == FCM_KRYLOV_CONVERGED_RTOL);
    B->iterations[ph][loaded] = ki.iterations;
  }
}

static int cmp_double(const void *a, const void *b)
{
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(int k, const double *v)
{
  double s[MAX_ROUNDS];
  memcpy(s, v, sizeof *v * (size_t)k);
  qsort(s, (size_t)k, sizeof *s, cmp_double);
  return k % 2 ? s[k / 2] : 0.5 * (s[k / 2 - 1] + s[k / 2]);
}

static double vmin(int k, const double *v)
{
  double m = v[0];
  for (int i = 1; i < k; i++)
    m = v[i] < m ? v[i] : m;
  return m;
}

static double vmax(int k, const double *v)
{
  double m = v[0];
  for (int i = 1; i < k; i++)
    m = v[i] > m ? v[i] : m;
  return m;
}

/* Clamp every copy of every active node with z <= zmax. */
static void clamp_below(bench *B, const fcm_mesh *mesh, double zmax)
{
  const double lo[3] = {-2, -2, -2}, hi[3] = {2, 2, zmax};
  fcm_index cnt = 0;
  TEST_OK(B->ctx, fcm_mesh_nodes_in_box(B->ctx, mesh, lo, hi, 1e-9, 0, NULL, &cnt));
  fcm_index *nodes = calloc((size_t)cnt + 1, sizeof *nodes);
  fcm_index *dofs = calloc(3 * 8 * (size_t)cnt + 1, sizeof *dofs), nd = 0;
  TEST_OK(B->ctx, fcm_mesh_nodes_in_box(B->ctx, mesh, lo, hi, 1e-9, cnt, nodes, &cnt));
  for (fcm_index i = 0; i < cnt; i++) {
    const fcm_index d0 = fcm_space_node_dof(B->space, nodes[i]);
    const fcm_index nc = fcm_space_node_copies(B->space, nodes[i]);
    for (fcm_index c = 0; d0 >= 0 && c < nc && c < 8; c++)
      for (int d = 0; d < 3; d++)
        dofs[nd++] = d0 + 3 * c + d;
  }
  TEST_OK(B->ctx, fcm_space_apply_dirichlet(B->space, nd, dofs, NULL, B->A, B->b));
  free(nodes);
  free(dofs);
}

int main(int argc, char **argv)
{
  app_env_init_blas(argc, argv); /* the CPU's BLAS kernels, as the programs */
  const int ncell = argc > 1 ? atoi(argv[1]) : 36;
  const int rounds = argc > 2 ? atoi(argv[2]) : 3;
  const int nbusy = argc > 3 ? atoi(argv[3]) : 8;
  const int nph = argc > 4 && !strcmp(argv[4], "mg") ? PH_SCHWARZ : PH_COUNT;
  if (ncell < 4 || ncell > 200 || rounds < 1 || rounds > MAX_ROUNDS || nbusy < 0 ||
      nbusy > MAX_BUSY || (argc > 4 && nph == PH_COUNT)) {
    fprintf(stderr,
            "usage: bench_mg_shared [n in [4, 200] [rounds in [1, %d] [busy in [0, %d] [mg]]]]\n",
            MAX_ROUNDS, MAX_BUSY);
    return 2;
  }
  fcm_blas_set_num_threads(1); /* as the programs: no BLAS threads beside OpenMP's */
  bench B;
  memset(&B, 0, sizeof B);
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_csr *K = NULL;
  TEST_OK(B.ctx, fcm_ctx_create(NULL, &B.ctx));

  const double lo[3] = {-1.05, -1.05, -1.05}, hi[3] = {1.05, 1.05, 1.05}, c[3] = {0, 0, 0};
  const fcm_index cells[3] = {ncell, ncell, ncell};
  TEST_OK(B.ctx, fcm_mesh_create_box(B.ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  TEST_OK(B.ctx, fcm_geometry_create_hollow_ball(B.ctx, c, 0.75, 1.0, 0.3, 16, 2, &geom));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.simplify = FCM_CELL_SIMPLIFY_OFF; /* faster to build; the solvers see the same kind of A */
  TEST_OK(B.ctx, fcm_cell_rules_create(B.ctx, mesh, geom, &ro, &rules));
  TEST_OK(B.ctx, fcm_space_create_embedded(B.ctx, mesh, rules, &B.space));
  B.n = fcm_space_num_dofs(B.space);
  const fcm_index nc = fcm_mesh_num_cells(mesh);

  fcm_material mat = {FCM_MATERIAL_LINEAR, 1e7, 0.45, 1000.0};
  const double dt = 0.02, g[3] = {0, 0, -9.81};
  B.b = calloc((size_t)B.n + 1, sizeof *B.b);
  TEST_OK(B.ctx, fcm_space_matrix_create(B.space, &B.A));
  TEST_OK(B.ctx, fcm_space_matrix_create(B.space, &K));
  TEST_OK(B.ctx, fcm_assemble_mass(B.space, &mat, NULL, B.A));
  TEST_OK(B.ctx, fcm_assemble_stiffness(B.space, &mat, NULL, K));
  TEST_OK(B.ctx, fcm_assemble_body_force(B.space, &mat, g, NULL, B.b));
  fcm_index nnz = 0;
  fcm_csr_get_size(B.A, NULL, NULL, &nnz);
  double *av = fcm_csr_values(B.A);
  const double *kv = fcm_csr_values_read(K);
  for (fcm_index p = 0; p < nnz; p++)
    av[p] += dt * dt * kv[p];
  for (fcm_index i = 0; i < B.n; i++)
    B.b[i] *= dt * dt;
  clamp_below(&B, mesh, -0.8);

  unsigned char *flag = calloc((size_t)nc + 1, 1);
  for (fcm_index k = 0; k < nc; k++)
    flag[k] = fcm_space_cell_active(B.space, k) && fcm_cell_rules_class(rules, k) == FCM_CELL_CUT &&
              fcm_cell_rules_volume_fraction(rules, k) < 0.5;
  fcm_index nb = 0, nd = 0;
  TEST_OK(B.ctx, fcm_space_cell_blocks(B.space, flag, &nb, &nd, NULL, NULL));
  fcm_index *bptr = calloc((size_t)nb + 1, sizeof *bptr),
            *bdofs = calloc((size_t)nd + 1, sizeof *bdofs);
  TEST_OK(B.ctx, fcm_space_cell_blocks(B.space, flag, &nb, &nd, bptr, bdofs));
  TEST_OK(B.ctx, fcm_schwarz_create(B.ctx, B.A, nb, bptr, bdofs, NULL, &B.P));
  TEST_OK(B.ctx, fcm_krylov_create(B.ctx, B.n, &B.ws));
  for (int ph = 0; ph < PH_COUNT; ph++)
    for (int l = 0; l < 2; l++)
      B.x[ph][l] = calloc((size_t)B.n + 1, sizeof *B.x[ph][l]);
  TEST_OK(B.ctx, fcm_mg_create(B.ctx, B.space, B.A, NULL, &B.mg));
  if (TEST_RESULT()) goto done;

  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  const char *pol = getenv("OMP_WAIT_POLICY");
  double load[3] = {-1, -1, -1};
  if (getloadavg(load, 3) < 0) load[0] = -1;
  printf("Shared cores: hollow ball, Hex8 %d^3 cells, %lld DOFs, nnz %lld; multigrid %d levels "
         "(DOFs",
         ncell, (long long)B.n, (long long)nnz, fcm_mg_num_levels(B.mg));
  for (int l = 0; l < fcm_mg_num_levels(B.mg); l++) {
    fcm_mg_level_info li;
    TEST_OK(B.ctx, fcm_mg_get_level_info(B.mg, l, &li));
    printf(" %lld", (long long)li.dofs);
  }
  printf("), Schwarz %lld blocks\n  %d thread(s), %ld core(s), %d busy processes when loaded, "
         "OMP_WAIT_POLICY=%s, load average %.1f before\n",
         (long long)nb, omp_get_max_threads(), cores, nbusy, pol ? pol : "(unset)", load[0]);
  fflush(stdout);

  for (int ph = 0; ph < nph; ph++) { /* warm-up */
    double w, cp;
    run_phase(&B, ph, 0, &w, &cp);
  }
  double wall[PH_COUNT][2][MAX_ROUNDS], cpu[PH_COUNT][2][MAX_ROUNDS], ratio[PH_COUNT][MAX_ROUNDS];
  pid_t pids[MAX_BUSY] = {0};
  double other[2][MAX_ROUNDS]; /* cores used by other processes during the phases */
  for (int r = 0; r < rounds; r++) {
    for (int loaded = 0; loaded < 2; loaded++) {
      if (loaded) {
        TEST_TRUE(busy_start(nbusy, pids));
        const struct timespec settle = {0, 200000000};
        nanosleep(&settle, NULL);
      }
      double kids0 = 0.0, kids1 = 0.0;
      for (int k = 0; loaded && k < nbusy; k++)
        kids0 += process_cpu(pids[k]);
      const double m0 = machine_busy(), c0 = cpu_seconds(), w0 = fcm_wtime();
      for (int ph = 0; ph < nph; ph++)
        run_phase(&B, ph, loaded, &wall[ph][loaded][r], &cpu[ph][loaded][r]);
      const double m1 = machine_busy(), c1 = cpu_seconds(), w1 = fcm_wtime();
      for (int k = 0; loaded && k < nbusy; k++)
        kids1 += process_cpu(pids[k]);
      const double busy_other = (m1 - m0) - (c1 - c0) - (kids1 - kids0);
      other[loaded][r] =
          m0 >= 0.0 && m1 >= 0.0 ? (busy_other > 0.0 ? busy_other : 0.0) / (w1 - w0) : -1.0;
      if (loaded) busy_stop(nbusy, pids);
    }
    printf("  round %d (other processes: %.2f cores alone, %.2f loaded):\n", r + 1, other[0][r],
           other[1][r]);
    for (int ph = 0; ph < nph; ph++) {
      ratio[ph][r] = wall[ph][1][r] / wall[ph][0][r];
      printf("    %-38s alone %7.3f s (%6.3f s CPU), loaded %7.3f s (%6.3f s CPU): %4.1fx",
             PH_NAME[ph], wall[ph][0][r], cpu[ph][0][r], wall[ph][1][r], cpu[ph][1][r],
             ratio[ph][r]);
      if (ph != PH_CREATE) printf(", %d iterations", B.iterations[ph][0]);
      printf("\n");
      if (ph != PH_CREATE) {
        TEST_TRUE(B.iterations[ph][0] == B.iterations[ph][1]);
        TEST_TRUE(memcmp(B.x[ph][0], B.x[ph][1], sizeof *B.x[ph][0] * (size_t)B.n) == 0);
      }
    }
    fflush(stdout);
  }
  /* fair share: beside `busy` processes on C cores each of T <= C threads gets C / (T + busy)
   * of a core instead of a whole one; one thread working while the others sleep, C / (1 + busy) */
  const double T = omp_get_max_threads(), C = cores > 0 ? (double)cores : 1.0;
  const double fair_par = T + nbusy > C ? (T + nbusy) / C : 1.0;
  const double fair_seq = 1.0 + nbusy > C ? (1.0 + nbusy) / C : 1.0;
  printf("  median of %d rounds (min - max of the ratio):\n", rounds);
  for (int ph = 0; ph < nph; ph++)
    printf("    %-38s alone %7.3f s, loaded %7.3f s: slowdown %4.1fx (%.1f - %.1f)\n", PH_NAME[ph],
           median(rounds, wall[ph][0]), median(rounds, wall[ph][1]), median(rounds, ratio[ph]),
           vmin(rounds, ratio[ph]), vmax(rounds, ratio[ph]));
  printf("  fair share: %.1fx for work on %d threads, %.1fx for work on one thread\n", fair_par,
         (int)T, fair_seq);

done:
  for (int ph = 0; ph < PH_COUNT; ph++)
    for (int l = 0; l < 2; l++)
      free(B.x[ph][l]);
  free(flag);
  free(bptr);
  free(bdofs);
  free(B.b);
  fcm_mg_destroy(&B.mg);
  fcm_schwarz_destroy(&B.P);
  fcm_krylov_destroy(&B.ws);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&B.A);
  fcm_space_destroy(&B.space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(B.ctx) == 0);
  fcm_ctx_destroy(&B.ctx);
  return TEST_RESULT();
}
