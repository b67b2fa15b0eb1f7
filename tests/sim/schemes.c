/* The time schemes on an undamped linear cantilever (Hex8 box beam 4 x 1 x 1, clamped at x = 0),
 * started in its lowest mode phi (inverse iteration on the assembled K and M, pure to 1e-9), so
 * that every step acts on one modal coordinate like a single-DOF oscillator of frequency omega:
 *  - convergence: u(1 s) against the exact phi cos(omega t), dt = 1/10 .. 1/80; the fitted
 *    order is 1 for backward Euler and 2 for Newmark, HHT and generalized-alpha;
 *  - dissipation: the one-step map of the modal coordinate (x, h v, h^2 a), measured from three
 *    steps from (phi, 0, 0), (0, phi, 0), (0, 0, phi), equals the amplification matrix of
 *    Chung and Hulbert (1993) at Omega = omega h (computed here from their formulas) to 1e-7,
 *    and its spectral radius at Omega = 1e4 is rho_inf (generalized-alpha with rho_inf = 0, 0.5,
 *    0.8, 1), (1 + alpha)/(1 - alpha) (HHT) and 1 (Newmark);
 *  - energy: from the static deflection, Newmark keeps kinetic + elastic energy over 1000 steps
 *    to 1e-6 (relative), also under gravity switched on at t = 0 with the load work (kinetic +
 *    elastic - load work stays 0 to 1e-6 of the elastic energy), while backward Euler loses more
 *    than 1 % of it;
 *  - bad options are refused naming the field and its range.
 * `schemes report` prints the measured figures (lib/docs/time_integration.md). */
#include <complex.h>
#undef I /* complex.h's; the imaginary unit is _Complex_I below */
#include "sim_util.h"

#include <string.h>

static int report;

typedef struct beam {
  fcm_ctx *ctx;
  fcm_mesh *mesh;
  fcm_space *space;
  fcm_index n, nfix;
  fcm_index *fix;
  fcm_material mat;
  double *u0;   /* static deflection under gravity */
  double *phi;  /* lowest mode (max |phi| = 0.01) */
  double omega; /* its angular frequency */
} beam;

static const double grav[3] = {0.0, 0.0, -9.81};

static fcm_integrator_options options(fcm_time_scheme scheme, double param, double dt)
{
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_DYNAMIC;
  o.scheme = scheme;
  if (scheme == FCM_SCHEME_HHT) o.hht_alpha = param;
  if (scheme == FCM_SCHEME_GENERALIZED_ALPHA) o.rho_inf = param;
  o.dt = dt;
  /* linear: two full Newton updates solve each step to round-off (the second corrects the
   * first's), also where dt is so large that a relative stopping rule would be too loose */
  o.newton_fixed_iterations = 2;
  o.newton_tolerance = 1e-15; /* never met early: both updates run */
  o.line_search = 0;
  o.max_halvings = 0;
  return o;
}

static fcm_integrator *make(beam *b, const fcm_integrator_options *o, int gravity)
{
  fcm_integrator *I = NULL;
  fcm_motion fixed = fcm_motion_default();
  TEST_OK(b->ctx, fcm_integrator_create(b->ctx, b->space, &b->mat, o, &I));
  if (gravity) TEST_OK(b->ctx, fcm_integrator_add_gravity(I, grav, NULL, NULL));
  TEST_OK(b->ctx, fcm_integrator_add_constraint(I, b->nfix, b->fix, &fixed, NULL));
  TEST_OK(b->ctx, fcm_integrator_setup(I));
  return I;
}

/* The lowest mode: inverse iteration phi <- K^-1 M phi on the free DOFs (the clamped ones zero),
 * from the static deflection; omega^2 its Rayleigh quotient. */
static void lowest_mode(beam *b)
{
  fcm_csr *K = NULL, *M = NULL;
  fcm_direct *chol = NULL;
  const fcm_index n = b->n;
  fcm_index *dofs = calloc((size_t)n, sizeof *dofs), nc = 0;
  double *zero = calloc((size_t)n, sizeof *zero), *f = calloc((size_t)n, sizeof *f);
  double *x = calloc((size_t)n, sizeof *x);
  TEST_OK(b->ctx, fcm_space_matrix_create(b->space, &K));
  TEST_OK(b->ctx, fcm_space_matrix_create(b->space, &M));
  TEST_OK(b->ctx, fcm_assemble_stiffness(b->space, &b->mat, NULL, K));
  TEST_OK(b->ctx, fcm_assemble_mass(b->space, &b->mat, NULL, M));
  for (fcm_index k = 0; k < b->nfix; k++)
    for (int i = 0; i < 3; i++)
      dofs[nc++] = fcm_space_node_dof(b->space, b->fix[k]) + i;
  TEST_OK(b->ctx, fcm_space_apply_dirichlet(b->space, nc, dofs, zero, K, f));
  TEST_OK(b->ctx, fcm_direct_create(b->ctx, FCM_DIRECT_CHOLMOD, K, &chol));
  TEST_OK(b->ctx, fcm_direct_analyze(chol));
  TEST_OK(b->ctx, fcm_direct_factor(chol, fcm_csr_values(K)));
  memcpy(b->phi, b->u0, sizeof *x * (size_t)n);
  for (int it = 0; it < 12; it++) {
    TEST_OK(b->ctx, fcm_csr_apply(M, 1.0, b->phi, 0.0, f));
    for (fcm_index k = 0; k < nc; k++)
      f[dofs[k]] = 0.0;
    TEST_OK(b->ctx, fcm_direct_solve(chol, f, x));
    double mx = 0.0;
    for (fcm_index i = 0; i < n; i++)
      mx = fmax(mx, fabs(x[i]));
    for (fcm_index i = 0; i < n; i++)
      b->phi[i] = 0.01 * x[i] / mx;
  }
  double kk = 0.0, mm = 0.0;
  TEST_OK(b->ctx, fcm_csr_apply(M, 1.0, b->phi, 0.0, f));
  for (fcm_index i = 0; i < n; i++)
    mm += b->phi[i] * f[i];
  fcm_csr_destroy(&K);
  TEST_OK(b->ctx, fcm_space_matrix_create(b->space, &K));
  TEST_OK(b->ctx, fcm_assemble_stiffness(b->space, &b->mat, NULL, K));
  TEST_OK(b->ctx, fcm_csr_apply(K, 1.0, b->phi, 0.0, f));
  for (fcm_index i = 0; i < n; i++)
    kk += b->phi[i] * f[i];
  b->omega = sqrt(kk / mm);
  fcm_direct_destroy(&chol);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&M);
  free(dofs), free(zero), free(f), free(x);
}

/* The modal coordinate of u: (phi . u) / (phi . phi). */
static double modal(const beam *b, const double *u)
{
  double pu = 0.0, pp = 0.0;
  for (fcm_index i = 0; i < b->n; i++)
    pu += b->phi[i] * u[i], pp += b->phi[i] * b->phi[i];
  return pu / pp;
}

static void convergence(beam *b, fcm_time_scheme scheme, double param, double lo, double hi)
{
  const int base = 10, levels = 4;
  double x[4], y[4];
  const double exact = cos(b->omega);
  for (int l = 0; l < levels; l++) {
    const int steps = base << l;
    fcm_integrator_options o = options(scheme, param, 1.0 / steps);
    fcm_integrator *I = make(b, &o, 0);
    TEST_OK(b->ctx, fcm_integrator_set_state(I, b->phi, NULL, 0.0, 0));
    for (int k = 0; k < steps; k++)
      TEST_OK(b->ctx, fcm_integrator_step(I, NULL));
    const double *u = fcm_integrator_displacement(I);
    double e = 0.0, r = 0.0;
    for (fcm_index i = 0; i < b->n; i++)
      e += pow(u[i] - exact * b->phi[i], 2), r += b->phi[i] * b->phi[i];
    x[l] = log(1.0 / steps);
    y[l] = log(sqrt(e / r));
    fcm_integrator_destroy(&I);
  }
  double mx = 0, my = 0, sxy = 0, sxx = 0;
  for (int l = 0; l < levels; l++)
    mx += x[l] / levels, my += y[l] / levels;
  for (int l = 0; l < levels; l++)
    sxy += (x[l] - mx) * (y[l] - my), sxx += (x[l] - mx) * (x[l] - mx);
  const double rate = sxy / sxx;
  if (report)
    printf("convergence,%s,%g,omega,%.6f,rate,%.4f,error_dt_1/10,%.3e,error_dt_1/80,%.3e\n",
           fcm_time_scheme_name(scheme), param, b->omega, rate, exp(y[0]), exp(y[levels - 1]));
  TEST_TRUE(rate >= lo && rate <= hi);
}

/* Newmark: 1000 steps; kinetic + elastic (+ the load work with gravity) kept. */
static void energy(beam *b, fcm_time_scheme scheme, int gravity, double *drift_out)
{
  fcm_integrator_options o = options(scheme, 0.0, 0.01);
  fcm_integrator *I = make(b, &o, gravity);
  double e0 = 0.0, scale = 0.0, drift = 0.0, last = 0.0;
  if (!gravity) {
    TEST_OK(b->ctx, fcm_integrator_set_state(I, b->u0, NULL, 0.0, 0));
    TEST_OK(b->ctx, fcm_integrator_energy(I, NULL, &e0, NULL));
    scale = e0;
  }
  for (int k = 0; k < 1000; k++) {
    fcm_step_info si;
    TEST_OK(b->ctx, fcm_integrator_step(I, &si));
    const double e = si.kinetic_energy + si.elastic_energy - si.load_work;
    TEST_TRUE(si.load_work == fcm_integrator_load_work(I));
    if (gravity) scale = fmax(scale, si.elastic_energy);
    drift = fmax(drift, fabs(e - e0));
    last = e;
  }
  TEST_TRUE(scale > 0.0);
  *drift_out = drift / scale;
  if (scheme == FCM_SCHEME_BACKWARD_EULER) *drift_out = (e0 - last) / scale;
  if (report)
    printf("energy,%s,%s,relative_change,%.3e\n", fcm_time_scheme_name(scheme),
           gravity ? "gravity" : "free", *drift_out);
  fcm_integrator_destroy(&I);
}

/* Chung and Hulbert's amplification matrix of (x, h v, h^2 a) for an undamped oscillator at
 * Omega = omega h: (1 - am) A1 + am A0 + Omega^2 ((1 - af) X1 + af X0) = 0 with Newmark's
 * X1 = X0 + V0 + (1/2 - beta) A0 + beta A1, V1 = V0 + (1 - gamma) A0 + gamma A1. */
static void amplification(double am, double af, double W, double A[3][3])
{
  const double beta = 0.25 * (1.0 - am + af) * (1.0 - am + af), gamma = 0.5 - am + af;
  const double den = (1.0 - am) + W * W * (1.0 - af) * beta;
  for (int j = 0; j < 3; j++) {
    double s0[3] = {0, 0, 0};
    s0[j] = 1.0;
    const double a1 =
        -(am * s0[2] + W * W * (s0[0] + (1.0 - af) * (s0[1] + (0.5 - beta) * s0[2]))) / den;
    A[0][j] = s0[0] + s0[1] + (0.5 - beta) * s0[2] + beta * a1;
    A[1][j] = s0[1] + (1.0 - gamma) * s0[2] + gamma * a1;
    A[2][j] = a1;
  }
}

/* Spectral radius of a 3 x 3 matrix: the largest root modulus of its characteristic polynomial
 * (Durand-Kerner iteration). */
static double spectral_radius(double A[3][3])
{
  const double c2 = A[0][0] + A[1][1] + A[2][2];
  const double c1 = A[0][0] * A[1][1] - A[0][1] * A[1][0] + A[0][0] * A[2][2] - A[0][2] * A[2][0] +
                    A[1][1] * A[2][2] - A[1][2] * A[2][1];
  const double c0 = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                    A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                    A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
  const double complex z0 = 0.4 + 0.9 * _Complex_I;
  double complex z[3] = {z0, z0 * z0, z0 * z0 * z0};
  for (int it = 0; it < 2000; it++)
    for (int k = 0; k < 3; k++) {
      double complex p = ((z[k] - c2) * z[k] + c1) * z[k] - c0, q = 1.0;
      for (int j = 0; j < 3; j++)
        if (j != k) q *= z[k] - z[j];
      if (q != 0.0) z[k] -= p / q;
    }
  return fmax(cabs(z[0]), fmax(cabs(z[1]), cabs(z[2])));
}

/* The measured one-step map of the modal coordinate at Omega = W against the formula, and its
 * spectral radius. */
static double dissipation(beam *b, fcm_time_scheme scheme, double param, double W)
{
  const double h = W / b->omega;
  fcm_integrator_options o = options(scheme, param, h);
  const fcm_index n = b->n;
  double *zero = calloc((size_t)n, sizeof *zero), *a = calloc((size_t)n, sizeof *a);
  double Am[3][3], Aa[3][3], err = 0.0, big = 0.0;
  for (int j = 0; j < 3; j++) {
    /* the unit state j of (x, h v, h^2 a), started as u = phi, v = phi or a = phi, i.e. with
     * the coordinate c = 1, h or h^2 */
    const double c = j == 0 ? 1.0 : j == 1 ? h : h * h;
    fcm_integrator *I = make(b, &o, 0);
    TEST_OK(b->ctx,
            fcm_integrator_set_state(I, j == 0 ? b->phi : zero, j == 1 ? b->phi : zero, 0.0, 0));
    TEST_OK(b->ctx, fcm_integrator_set_acceleration(I, j == 2 ? b->phi : zero));
    TEST_OK(b->ctx, fcm_integrator_step(I, NULL));
    TEST_TRUE(fcm_integrator_get_acceleration(I, a) == 1);
    Am[0][j] = modal(b, fcm_integrator_displacement(I)) / c;
    Am[1][j] = h * modal(b, fcm_integrator_velocity(I)) / c;
    Am[2][j] = h * h * modal(b, a) / c;
    fcm_integrator_destroy(&I);
  }
  double am = 0.0, af = 0.0;
  if (scheme == FCM_SCHEME_GENERALIZED_ALPHA)
    am = (2.0 * param - 1.0) / (param + 1.0), af = param / (param + 1.0);
  if (scheme == FCM_SCHEME_HHT) af = -param;
  amplification(am, af, W, Aa);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      err = fmax(err, fabs(Am[i][j] - Aa[i][j])), big = fmax(big, fabs(Aa[i][j]));
  const double rho = spectral_radius(Am);
  if (report)
    printf("dissipation,%s,%g,Omega,%g,spectral_radius,%.6f,formula,%.6f,map_error,%.2e\n",
           fcm_time_scheme_name(scheme), param, W, rho, spectral_radius(Aa), err / big);
  TEST_TRUE(err <= 1e-7 * big);
  TEST_NEAR(rho, spectral_radius(Aa), 0.0, 1e-6);
  free(zero), free(a);
  return rho;
}

/* Hyperelastic (stable Neo-Hookean): released from a tenth of the linear static deflection
 * (0.38 m at the tip of the 4 m beam), 100 steps of 0.01 s through the ordinary Newton
 * iteration (line search, representative tolerance 1e-8). Returns
 * the largest relative change of kinetic + elastic energy (Psi(0) subtracted) and the last one;
 * every step converges and the initial acceleration solve serves the nonlinear material. */
static void hyperelastic(beam *b, fcm_time_scheme scheme, double param, double *max_change,
                         double *end_change)
{
  fcm_material snh = b->mat;
  snh.model = FCM_MATERIAL_STABLE_NEO_HOOKEAN;
  fcm_integrator_options o = options(scheme, param, 0.01);
  o.newton_fixed_iterations = 0;
  o.line_search = 1;
  o.newton_tolerance = 1e-8;
  o.max_halvings = 4;
  fcm_integrator *I = NULL;
  fcm_motion fixed = fcm_motion_default();
  double *u = calloc((size_t)b->n, sizeof *u), psi0 = 0.0, e0 = 0.0;
  TEST_OK(b->ctx, fcm_integrator_create(b->ctx, b->space, &snh, &o, &I));
  TEST_OK(b->ctx, fcm_integrator_add_constraint(I, b->nfix, b->fix, &fixed, NULL));
  TEST_OK(b->ctx, fcm_integrator_setup(I));
  TEST_OK(b->ctx, fcm_integrator_energy(I, NULL, &psi0, NULL)); /* Psi(I) of snh is not 0 */
  for (fcm_index i = 0; i < b->n; i++)
    u[i] = 0.1 * b->u0[i];
  TEST_OK(b->ctx, fcm_integrator_set_state(I, u, NULL, 0.0, 0));
  TEST_OK(b->ctx, fcm_integrator_energy(I, NULL, &e0, NULL));
  e0 -= psi0;
  *max_change = *end_change = 0.0;
  for (int k = 0; k < 100; k++) {
    fcm_step_info si;
    fcm_status st = fcm_integrator_step(I, &si);
    TEST_OK(b->ctx, st);
    if (st != FCM_OK) break;
    const double e = si.kinetic_energy + si.elastic_energy - psi0;
    *max_change = fmax(*max_change, fabs(e - e0) / e0);
    *end_change = (e - e0) / e0;
  }
  if (report)
    printf("hyperelastic,%s,%g,max_relative_energy_change,%.3e,end,%.3e\n",
           fcm_time_scheme_name(scheme), param, *max_change, *end_change);
  free(u);
  fcm_integrator_destroy(&I);
}

static void bad_options(beam *b)
{
  fcm_integrator *I = NULL;
  fcm_integrator_options o = options(FCM_SCHEME_HHT, -0.5, 0.01);
  TEST_OK(b->ctx, fcm_integrator_create(b->ctx, b->space, &b->mat, &o, &I));
  TEST_ERR(b->ctx, fcm_integrator_setup(I), FCM_ERR_ARG, "hht_alpha = -0.5 outside [-1/3, 0]");
  fcm_integrator_destroy(&I);
  o = options(FCM_SCHEME_GENERALIZED_ALPHA, 1.5, 0.01);
  TEST_OK(b->ctx, fcm_integrator_create(b->ctx, b->space, &b->mat, &o, &I));
  TEST_ERR(b->ctx, fcm_integrator_setup(I), FCM_ERR_ARG, "rho_inf = 1.5 outside [0, 1]");
  fcm_integrator_destroy(&I);
  o = options((fcm_time_scheme)7, 0.0, 0.01);
  TEST_OK(b->ctx, fcm_integrator_create(b->ctx, b->space, &b->mat, &o, &I));
  TEST_ERR(b->ctx, fcm_integrator_setup(I), FCM_ERR_ARG, "scheme = 7 outside [0, 3]");
  fcm_integrator_destroy(&I);
  TEST_TRUE(!strcmp(fcm_time_scheme_name(FCM_SCHEME_GENERALIZED_ALPHA), "generalized_alpha"));
}

int main(int argc, char **argv)
{
  beam b;
  memset(&b, 0, sizeof b);
  report = argc > 1 && !strcmp(argv[1], "report");
  TEST_OK(b.ctx, fcm_ctx_create(NULL, &b.ctx));
  TEST_OK(b.ctx, beam_mesh(b.ctx, FCM_ELEMENT_HEX8, 4, 4.0, &b.mesh));
  TEST_OK(b.ctx, fcm_space_create(b.ctx, b.mesh, NULL, &b.space));
  b.n = fcm_space_num_dofs(b.space);
  b.fix = plane_nodes(b.ctx, b.mesh, 0, 0.0, &b.nfix);
  b.mat = (fcm_material){FCM_MATERIAL_LINEAR, 1.0e6, 0.3, 1000.0};
  b.u0 = calloc((size_t)b.n, sizeof *b.u0);
  { /* the static deflection under gravity */
    fcm_integrator_options o = options(FCM_SCHEME_BACKWARD_EULER, 0.0, 1.0);
    o.kind = FCM_INTEGRATOR_STATIC;
    fcm_integrator *I = make(&b, &o, 1);
    TEST_OK(b.ctx, fcm_integrator_step(I, NULL));
    memcpy(b.u0, fcm_integrator_displacement(I), sizeof *b.u0 * (size_t)b.n);
    fcm_integrator_destroy(&I);
  }
  bad_options(&b);

  b.phi = calloc((size_t)b.n, sizeof *b.phi);
  lowest_mode(&b);
  convergence(&b, FCM_SCHEME_BACKWARD_EULER, 0.0, 0.9, 1.1);
  convergence(&b, FCM_SCHEME_NEWMARK, 0.0, 1.9, 2.1);
  convergence(&b, FCM_SCHEME_HHT, -0.1, 1.9, 2.1);
  convergence(&b, FCM_SCHEME_GENERALIZED_ALPHA, 0.5, 1.9, 2.1);

  double drift = 0.0;
  energy(&b, FCM_SCHEME_NEWMARK, 0, &drift);
  TEST_TRUE(drift <= 1e-6);
  energy(&b, FCM_SCHEME_NEWMARK, 1, &drift);
  TEST_TRUE(drift <= 1e-6);
  energy(&b, FCM_SCHEME_BACKWARD_EULER, 0, &drift);
  TEST_TRUE(drift > 0.01);

  const double rhos[] = {0.0, 0.5, 0.8, 1.0};
  for (int k = 0; k < 4; k++) {
    TEST_NEAR(dissipation(&b, FCM_SCHEME_GENERALIZED_ALPHA, rhos[k], 1e4), rhos[k], 0.0, 5e-3);
    dissipation(&b, FCM_SCHEME_GENERALIZED_ALPHA, rhos[k], 1.0);
  }
  TEST_NEAR(dissipation(&b, FCM_SCHEME_HHT, -0.3, 1e4), 0.7 / 1.3, 0.0, 5e-3);
  dissipation(&b, FCM_SCHEME_HHT, -0.3, 1.0);
  TEST_NEAR(dissipation(&b, FCM_SCHEME_NEWMARK, 0.0, 1e4), 1.0, 0.0, 1e-6);
  TEST_NEAR(dissipation(&b, FCM_SCHEME_NEWMARK, 0.0, 1.0), 1.0, 0.0, 1e-9);

  /* hyperelastic: Newmark keeps the energy to O(dt^2), generalized-alpha with rho_inf = 0 and
   * backward Euler dissipate it */
  double nm_max = 0.0, nm_end = 0.0, ga_max = 0.0, ga_end = 0.0, be_max = 0.0, be_end = 0.0;
  hyperelastic(&b, FCM_SCHEME_NEWMARK, 0.0, &nm_max, &nm_end);
  hyperelastic(&b, FCM_SCHEME_GENERALIZED_ALPHA, 0.0, &ga_max, &ga_end);
  hyperelastic(&b, FCM_SCHEME_BACKWARD_EULER, 0.0, &be_max, &be_end);
  TEST_TRUE(nm_max < 2e-3);
  TEST_TRUE(ga_end < 0.0 && be_end < ga_end);

  free(b.fix), free(b.u0), free(b.phi);
  fcm_space_destroy(&b.space);
  fcm_mesh_destroy(&b.mesh);
  fcm_ctx_destroy(&b.ctx);
  return TEST_RESULT();
}
