/* Modified Newton on a kept factorization (fcm_integrator_options.reuse_factorization): a
 * clamped Stable Neo-Hookean beam swinging under gravity for 20 dynamic steps reaches, step by
 * step, the same states as full Newton to the Newton tolerance, with far fewer
 * factorizations and tangent assemblies; every iteration solved with the kept factorization
 * either contracts the residual by reuse_contraction or makes the next iteration factor anew
 * (a contraction no iteration reaches leaves at most one kept solve per factorization); static
 * steps, the fixed-iteration rule and the Krylov solvers never reuse; out-of-range options are
 * refused at setup. */
#include "sim_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { STEPS = 20 };

typedef struct totals {
  long long factorizations, reused, tangents, newton;
} totals;

static fcm_integrator_options options(int reuse, double contraction)
{
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.01;
  o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
  o.newton_tolerance = 1e-10;
  o.reuse_factorization = reuse;
  o.reuse_contraction = contraction;
  return o;
}

/* The beam clamped at x = 0 under gravity (0, 0, gz), set up. */
static fcm_integrator *make(fcm_ctx *ctx, const fcm_space *space, const fcm_material *mat,
                            fcm_index nfix, const fcm_index *fix, const fcm_integrator_options *o,
                            double gz)
{
  fcm_integrator *integ = NULL;
  const double g[3] = {0.0, 0.0, gz};
  fcm_motion fixed = fcm_motion_default();
  TEST_OK(ctx, fcm_integrator_create(ctx, space, mat, o, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  return integ;
}

/* STEPS steps from rest under gravity; the states after each step into U (STEPS x n). */
static void run(fcm_ctx *ctx, const fcm_space *space, const fcm_material *mat, fcm_index nfix,
                const fcm_index *fix, fcm_integrator_options o, double gz, double *U, totals *t)
{
  newton_log log;
  memset(t, 0, sizeof *t);
  o.monitor = newton_log_fn;
  o.monitor_user = &log;
  fcm_integrator *integ = make(ctx, space, mat, nfix, fix, &o, gz);
  if (!integ) return;
  const fcm_index n = fcm_integrator_num_dofs(integ);
  for (int s = 0; s < STEPS; s++) {
    fcm_step_info info;
    log.count = 0;
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED && info.halvings == 0);
    /* converged: the last residual within the tolerance */
    TEST_TRUE(log.count >= 2 && log.residual[log.count - 1] <= log.tolerance[log.count - 1]);
    t->factorizations += info.factorizations;
    t->reused += info.reused_factorizations;
    t->tangents += info.tangent_assemblies;
    t->newton += info.newton_iterations;
    TEST_TRUE(info.reused_factorizations <= info.newton_iterations);
    memcpy(U + (size_t)s * (size_t)n, fcm_integrator_displacement(integ), sizeof *U * (size_t)n);
  }
  fcm_integrator_destroy(&integ);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, beam_mesh(ctx, type, 4, 4.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index nfix = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix);
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e6, 0.3, 1000.0};
  const fcm_index n = fcm_space_num_dofs(space);
  double *Uf = malloc(sizeof *Uf * (size_t)n * STEPS), *Uk = malloc(sizeof *Uk * (size_t)n * STEPS),
         *Us = malloc(sizeof *Us * (size_t)n * STEPS);
  TEST_TRUE(Uf && Uk && Us);
  totals full, kept, strict;
  run(ctx, space, &mat, nfix, fix, options(0, 0.25), -9.81, Uf, &full);
  run(ctx, space, &mat, nfix, fix, options(1, 0.25), -9.81, Uk, &kept);
  run(ctx, space, &mat, nfix, fix, options(1, 1e-9), -9.81, Us, &strict);
  printf("full Newton: %lld iterations, %lld factorizations, %lld tangents\n", full.newton,
         full.factorizations, full.tangents);
  printf("kept factorization: %lld iterations (%lld on a kept one), %lld factorizations, %lld "
         "tangents\n",
         kept.newton, kept.reused, kept.factorizations, kept.tangents);
  printf("contraction 1e-9: %lld iterations (%lld on a kept one), %lld factorizations\n",
         strict.newton, strict.reused, strict.factorizations);
  /* the same states to the Newton tolerance (relative 1e-10 of the residual; the states agree
   * to a few orders of magnitude more than that) */
  for (int s = 0; s < STEPS; s++) {
    const double *a = Uf + (size_t)s * (size_t)n, *b = Uk + (size_t)s * (size_t)n,
                 *c = Us + (size_t)s * (size_t)n;
    const double scale = vec_norm(n, a);
    TEST_TRUE(scale > 0.0);
    TEST_TRUE(vec_dist(n, a, b) <= 1e-7 * scale);
    TEST_TRUE(vec_dist(n, a, c) <= 1e-7 * scale);
  }
  TEST_TRUE(full.reused == 0 && full.factorizations == full.newton);
  TEST_TRUE(kept.reused > 0 && 3 * kept.factorizations <= full.factorizations);
  /* kept across steps, not only within one */
  TEST_TRUE(kept.factorizations < STEPS / 2);
  TEST_TRUE(kept.tangents < full.tangents);
  /* a contraction no iteration reaches: each kept solve is followed by a new factorization */
  TEST_TRUE(strict.reused > 0 && strict.reused <= strict.factorizations);

  /* no backtracking and no halving allowed, ten times the gravity: every step still converges
   * on full steps with the kept factorization in use */
  {
    fcm_integrator_options o = options(1, 0.25);
    totals nb;
    o.max_backtracks = 0;
    o.max_halvings = 0;
    run(ctx, space, &mat, nfix, fix, o, -98.1, Us, &nb);
    TEST_TRUE(nb.reused > 0);
  }

  /* the fixed-iteration rule never reuses: each step's one iteration assembles and factors
   * anew, so reuse_factorization changes no bit of the run */
  {
    fcm_integrator_options o = options(1, 0.25);
    o.newton_fixed_iterations = 1;
    fcm_integrator *on = make(ctx, space, &mat, nfix, fix, &o, -9.81);
    o.reuse_factorization = 0;
    fcm_integrator *off = make(ctx, space, &mat, nfix, fix, &o, -9.81);
    for (int s = 0; on && off && s < STEPS; s++) {
      fcm_step_info a, b;
      TEST_OK(ctx, fcm_integrator_step(on, &a));
      TEST_OK(ctx, fcm_integrator_step(off, &b));
      TEST_TRUE(a.reason == FCM_STEP_FIXED_ITERATIONS && a.newton_iterations == 1);
      TEST_TRUE(a.reused_factorizations == 0 && a.factorizations == 1 && a.tangent_assemblies == 1);
      TEST_TRUE(a.residual == b.residual);
      TEST_TRUE(!memcmp(fcm_integrator_displacement(on), fcm_integrator_displacement(off),
                        sizeof(double) * (size_t)n));
    }
    fcm_integrator_destroy(&on);
    fcm_integrator_destroy(&off);
  }
  /* static steps (no mass to keep the iterates close) never reuse */
  {
    fcm_integrator_options o = options(1, 0.25);
    fcm_step_info info;
    o.kind = FCM_INTEGRATOR_STATIC;
    o.dt = 1.0;
    o.load_steps = 2;
    fcm_integrator *integ = make(ctx, space, &mat, nfix, fix, &o, -9.81);
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED && info.reused_factorizations == 0);
    fcm_integrator_destroy(&integ);
  }
  /* a Krylov solver never reuses */
  {
    fcm_integrator_options o = options(1, 0.25);
    fcm_step_info info;
    o.linear_solver = FCM_LINEAR_MINRES;
    fcm_integrator *integ = make(ctx, space, &mat, nfix, fix, &o, -9.81);
    for (int s = 0; s < 3; s++) {
      TEST_OK(ctx, fcm_integrator_step(integ, &info));
      TEST_TRUE(info.reused_factorizations == 0);
    }
    fcm_integrator_destroy(&integ);
  }
  /* options out of range */
  {
    const double bad_c[] = {0.0, 1.0, -0.5, NAN};
    const int bad_r[] = {-1, 2};
    for (size_t i = 0; i < sizeof bad_c / sizeof *bad_c; i++) {
      fcm_integrator *integ = NULL;
      fcm_integrator_options o = options(1, bad_c[i]);
      TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
      TEST_TRUE(fcm_integrator_setup(integ) == FCM_ERR_ARG);
      TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "reuse_contraction") != NULL);
      fcm_ctx_error_clear(ctx);
      fcm_integrator_destroy(&integ);
    }
    for (size_t i = 0; i < sizeof bad_r / sizeof *bad_r; i++) {
      fcm_integrator *integ = NULL;
      fcm_integrator_options o = options(bad_r[i], 0.25);
      TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
      TEST_TRUE(fcm_integrator_setup(integ) == FCM_ERR_ARG);
      TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "reuse_factorization") != NULL);
      fcm_ctx_error_clear(ctx);
      fcm_integrator_destroy(&integ);
    }
  }
  free(Uf);
  free(Uk);
  free(Us);
  free(fix);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
