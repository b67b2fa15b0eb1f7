/* Node elimination (fcm_rule_eliminate_nodes) and its orthonormal bases: the basis
 * Gram matrix is the identity and gradients match finite differences; elimination on
 * the line recovers the Gauss rule; on every other shape it returns a smaller exact,
 * positive, interior rule; options, error paths and allocation failure behave. */
#include "fcm/rulegen.h"
#include "moments.h"
#include "quad/rulegen_impl.h"
#include "test_alloc.h"

static const fcm_shape all_shapes[] = {FCM_SHAPE_LINE, FCM_SHAPE_TRI, FCM_SHAPE_QUAD, FCM_SHAPE_TET,
                                       FCM_SHAPE_HEX};

/* Gram matrix of the degree-m basis with a rule exact for 2m: identity to 1e-13;
 * for m <= 8 gradients against central differences at some of the rule's points. */
static void check_basis(fcm_ctx *ctx, fcm_shape shape, int m)
{
  fcm_rule *r = NULL;
  int M = fcm__orthobasis_size(shape, m), dim = mom_dim(shape);
  double *phi = calloc((size_t)M, sizeof *phi), *grad = calloc((size_t)3 * M, sizeof *grad);
  double *pp = calloc((size_t)M, sizeof *pp), *pm = calloc((size_t)M, sizeof *pm);
  double *gram = calloc((size_t)M * M, sizeof *gram), meas = mom_measure(shape);
  double gerr = 0.0, derr = 0.0;
  TEST_OK(ctx, fcm_rule_create_computed(ctx, shape, 2 * m, &r));
  if (!r || !phi || !grad || !pp || !pm || !gram) goto done;
  for (int i = 0; i < fcm_rule_num_points(r); i++) {
    const double *x = fcm_rule_points(r) + (size_t)dim * i;
    double wi = fcm_rule_weights(r)[i] / meas;
    fcm__orthobasis_eval(shape, m, x, phi, grad, M);
    for (int a = 0; a < M; a++)
      for (int b = 0; b < M; b++)
        gram[(size_t)a * M + b] += wi * phi[a] * phi[b];
    if (i % 7 || m > 8) continue; /* differences lose accuracy at high degree */
    for (int k = 0; k < dim; k++) {
      const double h = 1e-6;
      double xp[3] = {0, 0, 0}, xm[3] = {0, 0, 0};
      for (int d = 0; d < dim; d++)
        xp[d] = xm[d] = x[d];
      xp[k] += h;
      xm[k] -= h;
      fcm__orthobasis_eval(shape, m, xp, pp, NULL, M);
      fcm__orthobasis_eval(shape, m, xm, pm, NULL, M);
      for (int j = 0; j < M; j++) {
        double fd = (pp[j] - pm[j]) / (2 * h), g = grad[(size_t)k * M + j];
        derr = fmax(derr, fabs(fd - g) / (1.0 + fabs(g)));
      }
    }
  }
  for (int a = 0; a < M; a++)
    for (int b = 0; b < M; b++)
      gerr = fmax(gerr, fabs(gram[(size_t)a * M + b] - (a == b)));
  if (!(gerr <= 1e-13)) TEST_FAIL_("%s m=%d: |Gram - I| = %.3g", fcm_shape_name(shape), m, gerr);
  if (!(derr <= 1e-6))
    TEST_FAIL_("%s m=%d: gradient vs finite difference %.3g", fcm_shape_name(shape), m, derr);
done:
  fcm_rule_destroy(&r);
  free(phi);
  free(grad);
  free(pp);
  free(pm);
  free(gram);
}

static int binom(int n, int k)
{
  int c = 1;
  for (int i = 1; i <= k; i++)
    c = c * (n - k + i) / i;
  return c;
}

/* Eliminate from the computed rule of strength ms down at strength m and check the result. */
static void check_eliminate(fcm_ctx *ctx, fcm_shape shape, int m, int ms)
{
  fcm_rule *start = NULL, *out = NULL;
  fcm_rulegen_info info;
  int dim = mom_dim(shape);
  TEST_OK(ctx, fcm_rule_create_computed(ctx, shape, ms, &start));
  TEST_OK(ctx, fcm_rule_eliminate_nodes(ctx, start, m, NULL, &info, &out));
  if (start && out) {
    int n = fcm_rule_num_points(out);
    TEST_TRUE(fcm_rule_shape(out) == shape && fcm_rule_strength(out) == m);
    TEST_TRUE(info.initial_points == fcm_rule_num_points(start) && info.num_points == n);
    if (!(n < fcm_rule_num_points(start) && n >= binom(m / 2 + dim, dim)))
      TEST_FAIL_("%s m=%d: %d points from %d (lower bound %d)", fcm_shape_name(shape), m, n,
                 fcm_rule_num_points(start), binom(m / 2 + dim, dim));
    TEST_TRUE(info.residual <= 1e-14 && info.min_weight > 0.0 && info.min_distance >= 1e-9);
    double res = 1.0;
    TEST_OK(ctx, fcm_rule_moment_residual(ctx, out, m, &res));
    TEST_NEAR(res, info.residual, 0.0, 1e-16);
    mom_check_exact(out, m, 1e-13, 1e-14, NULL);
    mom_check_inside_positive(out);
  }
  fcm_rule_destroy(&start);
  fcm_rule_destroy(&out);
}

static int progress_calls;
static void count_progress(void *user, const fcm_rulegen_info *info)
{
  (void)user;
  if (info->num_points > 0) progress_calls++;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_rule *start = NULL, *out = NULL, *gauss = NULL, *bad = NULL;
  fcm_rulegen_info info;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();

  for (size_t s = 0; s < sizeof all_shapes / sizeof all_shapes[0]; s++) {
    check_basis(ctx, all_shapes[s], 7);
    check_basis(ctx, all_shapes[s], mom_dim(all_shapes[s]) == 3 ? 10 : 16);
  }

  /* the line: the unique minimal positive rule of strength 7 is 4-point Gauss */
  TEST_OK(ctx, fcm_rule_create_computed(ctx, FCM_SHAPE_LINE, 15, &start));
  TEST_OK(ctx, fcm_rule_eliminate_nodes(ctx, start, 7, NULL, &info, &out));
  TEST_OK(ctx, fcm_rule_create_gauss_jacobi(ctx, 4, 0.0, 0.0, &gauss));
  if (out && gauss && fcm_rule_num_points(out) == 4) {
    double x[4], w[4];
    for (int i = 0; i < 4; i++)
      x[i] = fcm_rule_points(out)[i], w[i] = fcm_rule_weights(out)[i];
    for (int i = 0; i < 4; i++) /* sort ascending like the Gauss nodes */
      for (int j = i + 1; j < 4; j++)
        if (x[j] < x[i]) {
          double t = x[i];
          x[i] = x[j], x[j] = t, t = w[i], w[i] = w[j], w[j] = t;
        }
    for (int i = 0; i < 4; i++) {
      TEST_NEAR(x[i], fcm_rule_points(gauss)[i], 0.0, 1e-13);
      TEST_NEAR(w[i], fcm_rule_weights(gauss)[i], 1e-13, 0.0);
    }
  } else {
    TEST_FAIL_("line strength 7: %d points, expected 4", out ? fcm_rule_num_points(out) : -1);
  }
  fcm_rule_destroy(&out);
  fcm_rule_destroy(&gauss);
  fcm_rule_destroy(&start);

  check_eliminate(ctx, FCM_SHAPE_TRI, 6, 6);
  check_eliminate(ctx, FCM_SHAPE_QUAD, 5, 7);
  check_eliminate(ctx, FCM_SHAPE_TET, 4, 4);
  check_eliminate(ctx, FCM_SHAPE_HEX, 3, 5);

  /* target_points stops exactly there; the progress callback sees every removal */
  fcm_rulegen_options o = fcm_rulegen_options_default();
  o.target_points = 20;
  o.progress = count_progress;
  TEST_OK(ctx, fcm_rule_create_computed(ctx, FCM_SHAPE_TET, 5, &start));
  TEST_OK(ctx, fcm_rule_eliminate_nodes(ctx, start, 5, &o, &info, &out));
  TEST_TRUE(out && fcm_rule_num_points(out) == 20 && info.removals == progress_calls);
  TEST_TRUE(info.removals >= 1 && progress_calls >= 1);
  if (out) mom_check_exact(out, 5, 1e-13, 1e-14, NULL);
  fcm_rule_destroy(&out);

  /* error paths */
  TEST_ERR(ctx, fcm_rule_eliminate_nodes(ctx, start, 5, NULL, NULL, NULL), FCM_ERR_ARG,
           "output rule pointer is NULL");
  TEST_ERR(ctx, fcm_rule_eliminate_nodes(ctx, NULL, 5, NULL, NULL, &out), FCM_ERR_ARG,
           "start rule is NULL");
  TEST_TRUE(out == NULL);
  TEST_ERR(ctx, fcm_rule_eliminate_nodes(ctx, start, 6, NULL, NULL, &out), FCM_ERR_ARG,
           "strength 6 out of range [0, 5]");
  o = fcm_rulegen_options_default();
  o.tol = 0.0;
  TEST_ERR(ctx, fcm_rule_eliminate_nodes(ctx, start, 5, &o, NULL, &out), FCM_ERR_ARG,
           "tol = 0 out of range");
  o = fcm_rulegen_options_default();
  o.max_batch = 0.9;
  TEST_ERR(ctx, fcm_rule_eliminate_nodes(ctx, start, 5, &o, NULL, &out), FCM_ERR_ARG,
           "max_batch = 0.9 out of range [0, 0.5]");
  {
    int n = fcm_rule_num_points(start);
    double *x = malloc(sizeof(double) * 3 * (size_t)n), *w = malloc(sizeof(double) * (size_t)n);
    if (x && w) {
      memcpy(x, fcm_rule_points(start), sizeof(double) * 3 * (size_t)n);
      memcpy(w, fcm_rule_weights(start), sizeof(double) * (size_t)n);
      w[3] *= 1.001; /* no longer exact */
      TEST_OK(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TET, 5, n, x, w, &bad));
      TEST_ERR(ctx, fcm_rule_eliminate_nodes(ctx, bad, 5, NULL, NULL, &out), FCM_ERR_ARG,
               "start rule is not exact for strength 5");
      double res = 0.0;
      TEST_OK(ctx, fcm_rule_moment_residual(ctx, bad, 5, &res));
      TEST_TRUE(res > 1e-6);
      fcm_rule_destroy(&bad);
      w[3] = -w[3];
      TEST_OK(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TET, 5, n, x, w, &bad));
      TEST_ERR(ctx, fcm_rule_eliminate_nodes(ctx, bad, 5, NULL, NULL, &out), FCM_ERR_ARG,
               "start rule weight 3");
      fcm_rule_destroy(&bad);
      w[3] = -w[3];
      x[0] = -0.25; /* outside the tet */
      TEST_OK(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TET, 5, n, x, w, &bad));
      TEST_ERR(ctx, fcm_rule_eliminate_nodes(ctx, bad, 5, NULL, NULL, &out), FCM_ERR_ARG,
               "start rule point 0 lies -0.25 from the boundary");
      fcm_rule_destroy(&bad);
    } else {
      TEST_FAIL_("out of memory");
    }
    free(x);
    free(w);
  }
  TEST_ERR(ctx, fcm_rule_moment_residual(ctx, start, 41, &info.residual), FCM_ERR_ARG,
           "strength 41 out of range [0, 40]");
  TEST_TRUE(out == NULL);
  fcm_rule_destroy(&start);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);

  /* allocation failure: fail the k-th allocation until the call succeeds */
  failing f;
  ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return TEST_RESULT();
  TEST_OK(ctx, fcm_rule_create_computed(ctx, FCM_SHAPE_TRI, 4, &start));
  int succeeded = 0;
  for (long k = 0; k < 200 && !succeeded && start; k++) {
    f.count = 0;
    f.fail_at = k;
    fcm_status st = fcm_rule_eliminate_nodes(ctx, start, 4, NULL, NULL, &out);
    f.fail_at = -1;
    if (st == FCM_OK) {
      succeeded = 1;
    } else if (st != FCM_ERR_ALLOC || out != NULL) {
      TEST_FAIL_("allocation %ld failed: status %s, out %p", k, fcm_status_name(st), (void *)out);
    }
    fcm_rule_destroy(&out);
    fcm_ctx_error_clear(ctx);
  }
  TEST_TRUE(succeeded);
  fcm_rule_destroy(&start);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
