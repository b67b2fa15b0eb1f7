/* The element-corotated linear model in the integrator: an embedded box under gravity, its
 * base held, is stepped (every step converges, the body sags), then cut by a plane. The cut
 * integrator (FCM_CUT_REUSE_BLOCKS) keeps the element stiffness matrices of the elements the
 * cut leaves and integrates only the others again; three steps after the cut give the same
 * displacement bits as an integrator built from scratch on the cut space. The interactive
 * option (one Newton iteration) runs the model too. The tangent: under gravity the steps stay
 * on the warped R K R^T (the same bits as with project_psd); a static step that shears the box
 * by about a fifth turns the exact Hessian on after its first iteration and Newton ends
 * quadratically (its last residual below ten times the square of the one before, relative to
 * the first), on the PSD tangent linearly and in more iterations.
 * Usage: sim_corot_linear <element> */
#include "fem/fem_impl.h"
#include "sim/sim_impl.h"
#include "sim_util.h"

#include <string.h>

static fcm_ctx *ctx;
static const fcm_material mat = {FCM_MATERIAL_COROTATED_LINEAR, 2.0e4, 0.3, 1000.0};
static const double gravity[3] = {0.0, -9.81, 0.0};

static fcm_status hold_base(fcm_integrator *I, const fcm_mesh *mesh)
{
  const double lo[3] = {-10, -10, -10}, hi[3] = {10, 0.05, 10};
  return hold_box(ctx, I, mesh, lo, hi);
}

/* The residuals a monitor saw, relative to the first. */
typedef struct trace {
  int n;
  double r[64];
} trace;

static void record(void *user, const fcm_newton_event *ev)
{
  trace *t = user;
  if (t->n < 64) t->r[t->n++] = ev->residual;
}

/* Whether the residuals end quadratically: after the first one below 1e-4 of the first, the
 * next is below 10 times its square (or at rounding, 1e-12). */
static int quadratic_end(const trace *t)
{
  for (int k = 1; k + 1 < t->n; k++) {
    const double a = t->r[k] / t->r[0], b = t->r[k + 1] / t->r[0];
    if (a < 1e-4) return b <= 10.0 * a * a || b <= 1e-12;
  }
  return 0;
}

/* One static step of the box sheared sideways by its weight; the Newton residuals into t. */
static void shear_step(const fcm_space *space, const fcm_mesh *mesh, int project, trace *t)
{
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_STATIC;
  o.newton_tolerance = 1e-11;
  o.project_psd = project;
  o.monitor = record;
  o.monitor_user = t;
  t->n = 0;
  fcm_integrator *I = NULL;
  const double side[3] = {-3.0, 0.0, 0.0}; /* rho g H / G about 0.23: a large shear */
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, side, NULL, NULL));
  TEST_OK(ctx, hold_base(I, mesh));
  TEST_OK(ctx, fcm_integrator_setup(I));
  fcm_step_info info;
  TEST_OK(ctx, fcm_integrator_step(I, &info));
  TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  const double *u = fcm_integrator_displacement(I);
  double ux = 0.0;
  for (fcm_index d = 0; d < fcm_integrator_num_dofs(I); d += 3)
    ux = fmin(ux, u[d]);
  printf("shear, %s tangent: %d Newton iterations, min u_x = %.4g, residuals",
         project ? "PSD" : "default", t->n - 1, ux);
  for (int k = 0; k < t->n; k++)
    printf(" %.2e", t->r[k] / t->r[0]);
  printf("\n");
  fcm_integrator_destroy(&I);
}

static fcm_integrator *make(const fcm_space *space, const fcm_mesh *mesh,
                            const fcm_integrator_options *o)
{
  fcm_integrator *I = NULL;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, gravity, NULL, NULL));
  TEST_OK(ctx, hold_base(I, mesh));
  return I;
}

static void steps(fcm_integrator *I, int k, int converged)
{
  for (int s = 0; s < k; s++) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    if (converged) TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  }
}

/* The lowest y displacement of the DOFs (the sag under gravity: negative). */
static double min_uy(const fcm_integrator *I)
{
  const double *u = fcm_integrator_displacement(I);
  double m = 0.0;
  for (fcm_index d = 1; d < fcm_integrator_num_dofs(I); d += 3)
    m = fmin(m, u[d]);
  return m;
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-0.3, -0.3, -0.3}, hi[3] = {1.3, 0.9, 0.9};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  const fcm_index nc[3] = {4, 3, 3}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules = NULL, *cut_rules = NULL;
  fcm_space *space = NULL, *cut_space = NULL;
  fcm_integrator *I = NULL, *C = NULL, *R = NULL, *F = NULL;
  fcm_surface *cut = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.01;
  o.cut_reuse = FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_ORDERING;
  I = make(space, mesh, &o);
  TEST_OK(ctx, fcm_integrator_setup(I));
  steps(I, 3, 1);
  printf("sag after 3 steps: %.4g\n", min_uy(I));
  TEST_TRUE(min_uy(I) < -1e-5);
  {
    /* small strains: Newton contracts well on the warped tangent and stays on it, the same
     * bits as with project_psd */
    fcm_integrator_options op = o;
    op.project_psd = 1;
    fcm_integrator *P = make(space, mesh, &op);
    TEST_OK(ctx, fcm_integrator_setup(P));
    steps(P, 3, 1);
    const size_t bytes = sizeof(double) * (size_t)fcm_integrator_num_dofs(I);
    TEST_TRUE(memcmp(fcm_integrator_displacement(P), fcm_integrator_displacement(I), bytes) == 0);
    fcm_integrator_destroy(&P);
  }

  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules, cut, &cut_rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, cut_rules, &cut_space));
  TEST_OK(ctx, fcm_integrator_create_cut(I, cut_space, &C));
  if (C) {
    /* the reference: built from scratch, from the same transferred state and ordering */
    const fcm_index n = fcm_space_num_dofs(cut_space), ne = fcm_space_num_elements(cut_space);
    double *u = malloc(sizeof *u * (size_t)n), *v = malloc(sizeof *v * (size_t)n);
    R = make(cut_space, mesh, &o);
    if (C->cut_ordering) TEST_OK(ctx, fcm__integrator_set_ordering(R, C->cut_ordering));
    TEST_OK(ctx, fcm_integrator_setup(R));
    TEST_OK(ctx, fcm_space_transfer(space, cut_space, I->u, u));
    TEST_OK(ctx, fcm_space_transfer(space, cut_space, I->v, v));
    TEST_OK(ctx, fcm_integrator_set_state(R, u, v, I->t, I->steps));
    steps(C, 1, 1);
    const fcm_index built = fcm__assembly_corot_built(C->aws);
    printf("cut: %lld elements, %lld element matrices built again\n", (long long)ne,
           (long long)built);
    TEST_TRUE(built > 0 && built < ne);
    steps(R, 1, 1);
    TEST_TRUE(fcm__assembly_corot_built(R->aws) == ne);
    steps(C, 2, 1);
    steps(R, 2, 1);
    TEST_TRUE(memcmp(C->u, R->u, sizeof *u * (size_t)n) == 0);
    TEST_TRUE(memcmp(C->v, R->v, sizeof *v * (size_t)n) == 0);
    free(u);
    free(v);
  }
  /* the interactive option: one Newton iteration a step */
  fcm_integrator_options oi = o;
  oi.newton_fixed_iterations = 1;
  F = make(space, mesh, &oi);
  TEST_OK(ctx, fcm_integrator_setup(F));
  steps(F, 3, 0);
  TEST_TRUE(min_uy(F) < -1e-5 && isfinite(min_uy(F)));

  /* a large static shear: the default tangent turns exact after the first iteration and
   * Newton ends quadratically; on the PSD one it does not */
  trace te, tp;
  shear_step(space, mesh, 0, &te);
  shear_step(space, mesh, 1, &tp);
  TEST_TRUE(te.n >= 3 && tp.n >= 3);
  if (te.n >= 3 && tp.n >= 3) {
    TEST_TRUE(quadratic_end(&te) && !quadratic_end(&tp));
    TEST_TRUE(tp.n >= te.n + 3);
  }

  fcm_integrator_destroy(&I);
  fcm_integrator_destroy(&C);
  fcm_integrator_destroy(&R);
  fcm_integrator_destroy(&F);
  fcm_surface_destroy(&cut);
  fcm_space_destroy(&space);
  fcm_space_destroy(&cut_space);
  fcm_cell_rules_destroy(&rules);
  fcm_cell_rules_destroy(&cut_rules);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
