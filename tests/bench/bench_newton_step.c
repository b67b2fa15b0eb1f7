/* Benchmark: one Newton step of the twisted-cylinder FCM problem (Longva et al. 2020, §6.2,
 * Table 1: Hex20, 2016 elements, 11,572 nodes, 359 ms per step on 28 cores with MKL's direct
 * solver). Times assembly (mass, hyperelastic force + tangent), Schwarz setup, MINRES+Schwarz,
 * and CHOLMOD analyze/factor/solve side by side; asserts only that both solves agree.
 *
 * Setup (the authors' cylinder-shell example, Longva et al. 2020 §6.2): background
 * [-1,1]x[-8,8]x[-1,1] with 7x56x7 Hex20 cells (res 7, h = 2/7); embedded tube r in [0.7, 1] around
 * the y axis, length 16 (the radii are our choice: they leave exactly the paper's 2016 active
 * cells); Stable Neo-Hookean E = 5e6, nu = 0.48, rho = 1000; dt = 1/60; default stabilization (mass
 * and stiffness, alpha 1e-6) and simplified cut-cell rules. State: a twist u = R(k (y + 8)) X - X
 * about the y axis, k = 0.1 rad per unit length, zero velocity, gravity -9.81 e_z; the ends
 * y = +-8 are held. Step: A = M + dt^2 K(u) (unprojected tangent), b = -dt^2 (f_int(u) - f_ext),
 * Dirichlet rows eliminated. Usage: bench_newton_step [nosimplify]
 *
 * bench_newton_step shared [nosimplify]: the same system, then MINRES + Schwarz (rtol 1e-8,
 * 3 solves a round) alone and beside 3 busy-loop processes per core, in alternating
 * rounds, and the slowdown loaded / alone (a fair share of the cores makes it 4x on 2
 * cores: 8 runnable processes instead of the 2 threads). Run it with the wait policy to
 * measure (the programs use OMP_WAIT_POLICY=passive, apps/app_env.h). Asserts that every
 * solve converges and that the loaded solves are bitwise equal to the lone ones. */
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

#define NREP 3

/* Wall-clock and process CPU seconds (all threads): on a busy machine the wall time of a
 * phase grows with the load, its CPU time much less. */
typedef struct stamp {
  double wall, cpu;
} stamp;

static stamp now(void)
{
  stamp s = {fcm_wtime(), (double)clock() / CLOCKS_PER_SEC};
  return s;
}

/* Keep the smaller (wall, cpu) of `best` and the interval since `t0`. */
static void keep_min(stamp *best, stamp t0)
{
  stamp t = now();
  if (t.wall - t0.wall < best->wall) {
    best->wall = t.wall - t0.wall;
    best->cpu = t.cpu - t0.cpu;
  }
}

static const stamp FAR = {1e30, 1e30};

/* ---- shared cores ---- */

#define SHARED_ROUNDS 3
#define SHARED_SOLVES 3
#define SPIN_PER_CORE 3

/* Start `count` busy-loop child processes (they die with this process). */
static int spin_start(int count, pid_t *pids)
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

static void spin_stop(int count, pid_t *pids)
{
  for (int k = 0; k < count; k++)
    if (pids[k] > 0) {
      kill(pids[k], SIGKILL);
      waitpid(pids[k], NULL, 0);
      pids[k] = 0;
    }
}

/* SHARED_SOLVES MINRES solves from x = 0; the time of all, the last iterate in x. */
static stamp solves(fcm_ctx *ctx, fcm_krylov *ws, fcm_csr *A, fcm_schwarz *P, const double *b,
                    double *x, fcm_index n, int *iterations)
{
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.max_iterations = 20000;
  ko.rtol = 1e-8;
  fcm_krylov_info ki;
  stamp t0 = now(), t;
  for (int k = 0; k < SHARED_SOLVES; k++) {
    memset(x, 0, sizeof *x * (size_t)n);
    TEST_OK(ctx,
            fcm_krylov_minres(ws, fcm_csr_operator, A, fcm_schwarz_operator, P, b, x, &ko, &ki));
    TEST_TRUE(ki.reason == FCM_KRYLOV_CONVERGED_RTOL);
  }
  *iterations = ki.iterations;
  t = now();
  t.wall -= t0.wall;
  t.cpu -= t0.cpu;
  return t;
}

static int cmp_double(const void *a, const void *b)
{
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static void shared_cores(fcm_ctx *ctx, fcm_csr *A, fcm_schwarz *P, const double *b, fcm_index n)
{
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  const int nspin = (int)(SPIN_PER_CORE * (cores > 0 ? cores : 1));
  const char *pol = getenv("OMP_WAIT_POLICY"), *spc = getenv("GOMP_SPINCOUNT");
  double load[3] = {-1, -1, -1};
  fcm_krylov *ws = NULL;
  pid_t *pids = calloc((size_t)nspin, sizeof *pids);
  double *x0 = calloc((size_t)n, sizeof *x0), *x1 = calloc((size_t)n, sizeof *x1);
  double ra[SHARED_ROUNDS], rl[SHARED_ROUNDS], ca[SHARED_ROUNDS], cl[SHARED_ROUNDS];
  int it0 = 0, it1 = 0;
  TEST_OK(ctx, fcm_krylov_create(ctx, n, &ws));
  if (getloadavg(load, 3) < 0) load[0] = -1;
  printf("Shared cores: MINRES + Schwarz (rtol 1e-8) on the twisted-tube Newton system, %lld "
         "DOFs,\n  %d thread(s), %ld core(s), OMP_WAIT_POLICY=%s GOMP_SPINCOUNT=%s, load average "
         "%.1f before\n",
         (long long)n, omp_get_max_threads(), cores, pol ? pol : "(unset)", spc ? spc : "(unset)",
         load[0]);
  (void)solves(ctx, ws, A, P, b, x0, n, &it0); /* warm-up */
  for (int r = 0; r < SHARED_ROUNDS; r++) {
    stamp t = solves(ctx, ws, A, P, b, x0, n, &it0);
    ra[r] = t.wall;
    ca[r] = t.cpu;
    TEST_TRUE(spin_start(nspin, pids));
    struct timespec settle = {0, 200000000};
    nanosleep(&settle, NULL);
    t = solves(ctx, ws, A, P, b, x1, n, &it1);
    spin_stop(nspin, pids);
    rl[r] = t.wall;
    cl[r] = t.cpu;
    TEST_TRUE(it1 == it0 && memcmp(x0, x1, sizeof *x0 * (size_t)n) == 0);
    printf("  round %d: %d solves of %d iterations: alone %.3f s wall (%.3f s CPU), beside %d "
           "busy loops %.3f s wall (%.3f s CPU): slowdown %.1fx\n",
           r + 1, SHARED_SOLVES, it0, ra[r], ca[r], nspin, rl[r], cl[r], rl[r] / ra[r]);
  }
  qsort(ra, SHARED_ROUNDS, sizeof *ra, cmp_double);
  qsort(rl, SHARED_ROUNDS, sizeof *rl, cmp_double);
  const double med_a = ra[SHARED_ROUNDS / 2], med_l = rl[SHARED_ROUNDS / 2];
  /* fair share: the team of T threads gets T cores / (T + spinners) of the machine */
  const double T = omp_get_max_threads(), C = cores > 0 ? (double)cores : 1.0;
  const double fair = (T < C ? T : C) * (T + nspin) / (T * C);
  printf("  median: alone %.3f s, loaded %.3f s: slowdown %.1fx (fair share %.1fx; target <= "
         "6x)\n",
         med_a, med_l, med_l / med_a, fair);
  fcm_krylov_destroy(&ws);
  free(pids);
  free(x0);
  free(x1);
}

int main(int argc, char **argv)
{
  const int shared = argc > 1 && !strcmp(argv[1], "shared");
  const int simplify = !(argc > 1 + shared && !strcmp(argv[1 + shared], "nosimplify"));
  app_env_init_blas(argc, argv); /* the CPU's BLAS kernels, as the programs */
  fcm_blas_set_num_threads(1);   /* as the programs: no BLAS threads spinning beside OpenMP's */
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *tube = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_csr *A = NULL, *K = NULL;
  fcm_schwarz *P = NULL;
  fcm_krylov *ws = NULL;
  fcm_direct *chol = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));

  const double lo[3] = {-1, -8, -1}, hi[3] = {1, 8, 1}, center[3] = {0, 0, 0};
  const fcm_index cells[3] = {7, 56, 7};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX20, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_tube(ctx, center, 1, 0.7, 1.0, 16.0, 2, 32, 28, &tube));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.simplify = simplify;
  stamp t_rules = FAR, t0 = now();
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, tube, &ro, &rules));
  keep_min(&t_rules, t0);
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(rules);
  const fcm_index n = fcm_space_num_dofs(space), nc = fcm_mesh_num_cells(mesh);
  fcm_index active = 0;
  for (fcm_index c = 0; c < nc; c++)
    active += fcm_space_cell_active(space, c);

  /* the twisted state */
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  double *u = calloc((size_t)n, sizeof *u), *fint = calloc((size_t)n, sizeof *fint),
         *fext = calloc((size_t)n, sizeof *fext), *b = calloc((size_t)n, sizeof *b),
         *x1 = calloc((size_t)n, sizeof *x1), *x2 = calloc((size_t)n, sizeof *x2),
         *r = calloc((size_t)n, sizeof *r);
  for (fcm_index a = 0; a < nn; a++) {
    fcm_index d = fcm_space_node_dof(space, a);
    if (d < 0) continue;
    const double th = 0.1 * (X[3 * a + 1] + 8.0), c = cos(th), s = sin(th);
    const double x = X[3 * a], z = X[3 * a + 2];
    u[d] = c * x + s * z - x;
    u[d + 2] = -s * x + c * z - z;
  }
  fcm_material m = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 5e6, 0.48, 1000.0};
  fcm_material_params mp;
  TEST_OK(ctx, fcm_material_setup(ctx, &m, &mp));
  fcm_material el = {FCM_MATERIAL_LINEAR, 5e6, 0.48, 1000.0};
  const double dt = 1.0 / 60.0, g[3] = {0, 0, -9.81};
  TEST_OK(ctx, fcm_space_matrix_create(space, &A));
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  fcm_index nnz = 0;
  fcm_csr_get_size(A, NULL, NULL, &nnz);

  /* assembly: best of NREP */
  stamp tm = FAR, th = FAR;
  const int nrep = shared ? 1 : NREP;
  for (int rep = 0; rep < nrep; rep++) {
    fcm_csr_set_zero(A);
    fcm_csr_set_zero(K);
    memset(fint, 0, sizeof *fint * (size_t)n);
    memset(fext, 0, sizeof *fext * (size_t)n);
    t0 = now();
    TEST_OK(ctx, fcm_assemble_mass(space, &el, NULL, A));
    TEST_OK(ctx, fcm_assemble_body_force(space, &el, g, NULL, fext));
    keep_min(&tm, t0);
    t0 = now();
    TEST_OK(ctx, fcm_assemble_hyperelastic(space, &mp, u, NULL, NULL, fint, K));
    keep_min(&th, t0);
  }
  stamp t_bc = FAR;
  t0 = now();
  double *av = fcm_csr_values(A);
  const double *kv = fcm_csr_values(K);
  for (fcm_index p = 0; p < nnz; p++)
    av[p] += dt * dt * kv[p];
  for (fcm_index i = 0; i < n; i++)
    b[i] = -dt * dt * (fint[i] - fext[i]);
  const double plo[3] = {-HUGE_VAL, -8, -HUGE_VAL}, phi[3] = {HUGE_VAL, -8, HUGE_VAL};
  const double qlo[3] = {-HUGE_VAL, 8, -HUGE_VAL}, qhi[3] = {HUGE_VAL, 8, HUGE_VAL};
  fcm_index n1 = 0, n2 = 0;
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-9, 0, NULL, &n1));
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, qlo, qhi, 1e-9, 0, NULL, &n2));
  fcm_index *nodes = calloc((size_t)(n1 + n2), sizeof *nodes),
            *fix = calloc(3 * (size_t)(n1 + n2), sizeof *fix), nfix = 0;
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, 1e-9, n1, nodes, &n1));
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, mesh, qlo, qhi, 1e-9, n2, nodes + n1, &n2));
  for (fcm_index k = 0; k < n1 + n2; k++) {
    fcm_index d = fcm_space_node_dof(space, nodes[k]);
    for (int i = 0; d >= 0 && i < 3; i++)
      fix[nfix++] = d + i;
  }
  TEST_OK(ctx, fcm_space_apply_dirichlet(space, nfix, fix, NULL, A, b));
  keep_min(&t_bc, t0);

  /* Schwarz: cut cells with volume fraction below 0.5 */
  unsigned char *flag = calloc((size_t)nc, 1);
  for (fcm_index c = 0; c < nc; c++)
    flag[c] = fcm_cell_rules_class(rules, c) == FCM_CELL_CUT &&
              fcm_cell_rules_volume_fraction(rules, c) < 0.5;
  stamp t_create = FAR, t_setup = FAR;
  t0 = now();
  fcm_index nb = 0, nd = 0;
  TEST_OK(ctx, fcm_space_cell_blocks(space, flag, &nb, &nd, NULL, NULL));
  fcm_index *bptr = calloc((size_t)nb + 1, sizeof *bptr),
            *bdofs = calloc((size_t)nd + 1, sizeof *bdofs);
  TEST_OK(ctx, fcm_space_cell_blocks(space, flag, &nb, &nd, bptr, bdofs));
  TEST_OK(ctx, fcm_schwarz_create(ctx, A, nb, bptr, bdofs, NULL, &P));
  keep_min(&t_create, t0);
  for (int rep = 0; rep < nrep; rep++) {
    t0 = now();
    TEST_OK(ctx, fcm_schwarz_setup(P, A));
    keep_min(&t_setup, t0);
  }
  fcm_schwarz_info si;
  fcm_schwarz_get_info(P, &si);
  if (shared) {
    shared_cores(ctx, A, P, b, n);
    goto done;
  }

  /* MINRES + Schwarz at the paper's CG tolerance 1e-5 and at rtol 1e-8 */
  TEST_OK(ctx, fcm_krylov_create(ctx, n, &ws));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.max_iterations = 20000;
  ko.check_true_residual = 1;
  fcm_krylov_info ki8, ki5;
  stamp t_m5 = FAR, t_m8 = FAR;
  ko.rtol = 1e-5;
  t0 = now();
  TEST_OK(ctx,
          fcm_krylov_minres(ws, fcm_csr_operator, A, fcm_schwarz_operator, P, b, x2, &ko, &ki5));
  keep_min(&t_m5, t0);
  ko.rtol = 1e-8;
  t0 = now();
  TEST_OK(ctx,
          fcm_krylov_minres(ws, fcm_csr_operator, A, fcm_schwarz_operator, P, b, x1, &ko, &ki8));
  keep_min(&t_m8, t0);

  /* CHOLMOD (UMFPACK if A is not positive definite) */
  fcm_direct_method method = FCM_DIRECT_CHOLMOD;
  stamp ta = FAR, tf = FAR, ts = FAR;
  TEST_OK(ctx, fcm_direct_create(ctx, method, A, &chol));
  t0 = now();
  TEST_OK(ctx, fcm_direct_analyze(chol));
  keep_min(&ta, t0);
  for (int rep = 0; rep < NREP; rep++) {
    t0 = now();
    fcm_status st = fcm_direct_factor(chol, av);
    keep_min(&tf, t0);
    if (st == FCM_ERR_SINGULAR && method == FCM_DIRECT_CHOLMOD) {
      printf("CHOLMOD: A is not positive definite, UMFPACK instead\n");
      fcm_ctx_error_clear(ctx);
      fcm_direct_destroy(&chol);
      method = FCM_DIRECT_UMFPACK;
      TEST_OK(ctx, fcm_direct_create(ctx, method, A, &chol));
      ta = tf = FAR;
      t0 = now();
      TEST_OK(ctx, fcm_direct_analyze(chol));
      keep_min(&ta, t0);
      rep = -1;
      continue;
    }
    TEST_TRUE(st == FCM_OK);
  }
  for (int rep = 0; rep < NREP; rep++) {
    t0 = now();
    TEST_OK(ctx, fcm_direct_solve(chol, b, x2));
    keep_min(&ts, t0);
  }
  fcm_direct_info di;
  fcm_direct_get_info(chol, &di);

  /* checks: direct residual, MINRES converged and close to the direct solution */
  double rn = 0, bn = 0, dn = 0, xn = 0;
  TEST_OK(ctx, fcm_csr_apply(A, 1.0, x2, 0.0, r));
  for (fcm_index i = 0; i < n; i++) {
    rn += (r[i] - b[i]) * (r[i] - b[i]);
    bn += b[i] * b[i];
    dn += (x1[i] - x2[i]) * (x1[i] - x2[i]);
    xn += x2[i] * x2[i];
  }
  const double direct_res = sqrt(rn / bn), diff = sqrt(dn / xn);
  TEST_TRUE(bn > 0 && direct_res < 1e-10);
  TEST_TRUE(ki8.reason == FCM_KRYLOV_CONVERGED_RTOL && ki5.reason == FCM_KRYLOV_CONVERGED_RTOL);
  TEST_TRUE(diff < 1e-4);

  printf("Newton step, twisted tube (Longva Table 1 setting), Hex20, %d thread(s)\n",
         omp_get_max_threads());
  printf("  background cells %lld (active %lld: cut %lld, uncut %lld), DOFs %lld, nnz %lld\n",
         (long long)nc, (long long)active, (long long)rs->num_cut, (long long)rs->num_uncut,
         (long long)n, (long long)nnz);
  printf("  cell rules %.2f s wall / %.2f s CPU (simplification %s; %lld stiffness / %lld mass "
         "points in cut cells), once per geometry\n",
         t_rules.wall, t_rules.cpu, simplify ? "on" : "off",
         (long long)rs->points_simplified[FCM_RULE_STIFFNESS],
         (long long)rs->points_simplified[FCM_RULE_MASS]);
  printf("  %-42s %9s %9s\n", "phase (best of 3 where repeated)", "wall ms", "CPU ms");
#define ROW(name, t) printf("  %-42s %9.1f %9.1f", name, 1e3 * (t).wall, 1e3 * (t).cpu)
  ROW("assembly: mass + gravity", tm);
  printf("\n");
  ROW("assembly: hyperelastic force + tangent", th);
  printf("\n");
  ROW("A = M + dt^2 K, rhs, Dirichlet", t_bc);
  printf("\n");
  ROW("Schwarz create (blocks, colouring, setup)", t_create);
  printf("\n");
  ROW("Schwarz setup (eigen-inverse blocks)", t_setup);
  printf("   %lld blocks of <= %d DOFs\n", (long long)si.num_blocks, si.max_block_size);
  ROW("MINRES + Schwarz, rtol 1e-5", t_m5);
  printf("   %d iterations, true residual %.1e\n", ki5.iterations, ki5.true_residual);
  ROW("MINRES + Schwarz, rtol 1e-8", t_m8);
  printf("   %d iterations, true residual %.1e\n", ki8.iterations, ki8.true_residual);
  ROW(method == FCM_DIRECT_CHOLMOD ? "CHOLMOD analyze (once per pattern)"
                                   : "UMFPACK analyze (once per pattern)",
      ta);
  printf("\n");
  ROW("  factor", tf);
  printf("   factor nnz %.3g, %.2f GFLOP/s (wall)\n", di.factor_nnz,
         di.factor_flops / tf.wall * 1e-9);
  ROW("  solve", ts);
  printf("\n");
  const stamp step_d = {tm.wall + th.wall + t_bc.wall + tf.wall + ts.wall,
                        tm.cpu + th.cpu + t_bc.cpu + tf.cpu + ts.cpu};
  const stamp step_i = {tm.wall + th.wall + t_bc.wall + t_setup.wall + t_m8.wall,
                        tm.cpu + th.cpu + t_bc.cpu + t_setup.cpu + t_m8.cpu};
  ROW("step, direct: assembly + factor + solve", step_d);
  printf("\n");
  ROW("step, MINRES+Schwarz 1e-8: assembly+setup+solve", step_i);
  printf("\n");
#undef ROW
  printf("  paper (Table 1, Hex20 res 7): 359 ms per time step on 28 cores, MKL direct solver\n");
  printf("  MINRES (1e-8) vs direct solution: relative difference %.1e\n", diff);
done:

  free(u);
  free(fint);
  free(fext);
  free(b);
  free(x1);
  free(x2);
  free(r);
  free(nodes);
  free(fix);
  free(flag);
  free(bptr);
  free(bdofs);
  fcm_direct_destroy(&chol);
  fcm_krylov_destroy(&ws);
  fcm_schwarz_destroy(&P);
  fcm_csr_destroy(&A);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&tube);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
