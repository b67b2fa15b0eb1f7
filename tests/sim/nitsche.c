/* Boundary constraints on the embedded boundary (Nitsche, penalty): modes by argument.
 *   patch <element>  an affine displacement imposed by Nitsche on the whole boundary of an
 *                    embedded box is reproduced exactly (linear elasticity, no stabilization:
 *                    its O(alpha) term is not consistent with a non-zero stress); so is a
 *                    stretch imposed on the normal component of each face only (rollers:
 *                    component masks, a prescribed displacement field)
 *   rigid            a finite rigid motion imposed on the whole boundary of a Stable
 *                    Neo-Hookean ball (Nitsche, penalty) is the static solution at every node
 *   tangent          exactly symmetric Newton matrix of the boundary terms, and finite differences
 *                    of energy -> force -> tangent (Stable Neo-Hookean, u != g on the boundary);
 *                    energy and force bitwise the same again and with one thread
 *   penalty          the penalty estimate of a cut cell stays bounded as its volume fraction
 *                    goes to 0 with stabilization, and grows like 1/phi without
 *   solvers          a hanging ball clamped on a curved cap: direct, CG and MINRES (Jacobi,
 *                    Schwarz) agree,
 *                    static and dynamic; the clamp holds (|u| small on the cap)
 *   errors           bad options and a region selecting nothing are named */
#include "sim_util.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static fcm_status problem_build(problem *p, fcm_element_type type, const fcm_index cells[3],
                                const double mlo[3], const double mhi[3], fcm_geometry *geom,
                                int stabilize, double min_fraction)
{
  fcm_status st;
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  p->geom = geom;
  st = fcm_mesh_create_box(p->ctx, type, mlo, mhi, cells, &p->mesh);
  if (st != FCM_OK) return st;
  ro.surface_strength = 4;
  ro.min_fraction = min_fraction;
  if (!stabilize) ro.stabilization.mode = FCM_STABILIZATION_OFF;
  st = fcm_cell_rules_create(p->ctx, p->mesh, p->geom, &ro, &p->rules);
  if (st != FCM_OK) return st;
  return fcm_space_create_embedded(p->ctx, p->mesh, p->rules, &p->space);
}

static fcm_integrator_options static_options(void)
{
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_STATIC;
  o.dt = 1.0;
  o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
  o.newton_tolerance = 1e-11;
  return o;
}

/* u = (a x, b y, c z), user = (a, b, c). */
static void stretch_field(void *user, const double x[3], const double n[3], double u[3])
{
  const double *s = user;
  (void)n;
  for (int i = 0; i < 3; i++)
    u[i] = s[i] * x[i];
}

/* Points whose normal is +-e_d, user = &d. */
static int facing(void *user, const double X[3], const double n[3])
{
  (void)X;
  return fabs(n[*(const int *)user]) > 0.99;
}

static const int axes[3] = {0, 1, 2};

static int patch(fcm_ctx *ctx, fcm_element_type type)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_geometry *g = NULL;
  fcm_integrator *I = NULL;
  const double lo[3] = {0.13, 0.21, 0.17}, hi[3] = {0.88, 0.79, 0.91};
  const double mlo[3] = {0, 0, 0}, mhi[3] = {1, 1, 1};
  const fcm_index n[3] = {2, 1, 1}, cells[3] = {3, 3, 3};
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  fcm_integrator_options o = static_options();
  /* an affine field: the rotation of fcm_motion (R - I)(X - c) with a translation, t = 1 */
  fcm_motion m = fcm_motion_default();
  m.velocity[0] = 0.01, m.velocity[1] = -0.02, m.velocity[2] = 0.015;
  m.axis[0] = 1, m.axis[1] = 2, m.axis[2] = 3;
  m.center[0] = 0.4, m.center[1] = 0.5, m.center[2] = 0.45;
  m.angular_speed = 0.05;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n, &g));
  TEST_OK(ctx, problem_build(&p, type, cells, mlo, mhi, g, 0, 0.0));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_boundary_constraint(I, NULL, NULL, &m, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  fcm_step_info info;
  TEST_OK(ctx, fcm_integrator_step(I, &info));
  {
    const double *u = fcm_integrator_displacement(I), *X = fcm_mesh_coords(p.mesh);
    double err = 0.0, scale = 0.0;
    for (fcm_index a = 0; a < fcm_mesh_num_nodes(p.mesh); a++) {
      fcm_index d = fcm_space_node_dof(p.space, a);
      if (d < 0) continue;
      double ue[3];
      fcm_motion_eval(&m, X + 3 * a, 1.0, ue, NULL);
      for (int i = 0; i < 3; i++) {
        err = fmax(err, fabs(u[d + i] - ue[i]));
        scale = fmax(scale, fabs(ue[i]));
      }
    }
    if (!(err <= 1e-10 * scale)) TEST_FAIL_("patch: max nodal error %.3g (scale %.3g)", err, scale);
    fcm_integrator_setup_info si;
    fcm_integrator_get_setup_info(I, &si);
    TEST_TRUE(si.boundary_points > 0);
    TEST_TRUE(si.boundary_penalty_max > 0.0 && isfinite(si.boundary_penalty_max));
  }
  fcm_integrator_destroy(&I);
  /* rollers: the normal component of the stretch u = (a x, b y, c z) only, on each face
   * (constraint d holds component d on the faces with normal +-e_d; the stretch's stress is
   * diagonal, so the free tangential components are traction free): the stretch again */
  static const double stretch[3] = {0.01, -0.02, 0.015};
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  for (int d = 0; d < 3; d++) {
    fcm_motion md = fcm_motion_default();
    fcm_boundary_options bo = fcm_boundary_options_default();
    md.components[0] = md.components[1] = md.components[2] = 0;
    md.components[d] = 1;
    bo.displacement = stretch_field;
    bo.displacement_user = (void *)stretch;
    TEST_OK(ctx,
            fcm_integrator_add_boundary_constraint(I, facing, (void *)&axes[d], &md, &bo, NULL));
  }
  TEST_OK(ctx, fcm_integrator_setup(I));
  TEST_OK(ctx, fcm_integrator_step(I, &info));
  {
    const double *u = fcm_integrator_displacement(I), *X = fcm_mesh_coords(p.mesh);
    double err = 0.0;
    for (fcm_index a = 0; a < fcm_mesh_num_nodes(p.mesh); a++) {
      fcm_index d = fcm_space_node_dof(p.space, a);
      if (d < 0) continue;
      for (int i = 0; i < 3; i++)
        err = fmax(err, fabs(u[d + i] - stretch[i] * X[3 * a + i]));
    }
    if (!(err <= 1e-10 * 0.02)) TEST_FAIL_("patch, rollers: max nodal error %.3g", err);
  }
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* A finite rigid motion (rotation 0.45 rad and a translation) imposed by Nitsche on the whole
 * boundary of an embedded ball of Stable Neo-Hookean material, stabilization on: P(R) = 0 and
 * the field is in the space, so the static solution is that motion at every node to Newton's
 * tolerance (consistency of the hyperelastic formulation, and Newton converging with it);
 * dynamic: prescribing the same motion over a step from rest moves the body along. */
static int rigid(fcm_ctx *ctx, fcm_boundary_method method)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_geometry *g = NULL;
  fcm_integrator *I = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, mlo[3] = {0, 0, 0}, mhi[3] = {1, 1, 1};
  const fcm_index cells[3] = {3, 3, 3};
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.4, 1000.0};
  fcm_integrator_options o = static_options();
  fcm_boundary_options bo = fcm_boundary_options_default();
  fcm_motion m = fcm_motion_default();
  m.axis[0] = 1, m.axis[1] = -1, m.axis[2] = 2;
  m.center[0] = m.center[1] = m.center[2] = 0.5;
  m.angular_speed = 0.45;
  m.velocity[0] = 0.05, m.velocity[2] = -0.03;
  bo.method = method;
  o.load_steps = 3;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.4, 3, &g));
  TEST_OK(ctx, problem_build(&p, FCM_ELEMENT_HEX8, cells, mlo, mhi, g, 1, 1e-4));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_boundary_constraint(I, NULL, NULL, &m, &bo, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  fcm_step_info info;
  TEST_OK(ctx, fcm_integrator_step(I, &info));
  TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  {
    const double *u = fcm_integrator_displacement(I), *X = fcm_mesh_coords(p.mesh);
    double err = 0.0, scale = 0.0;
    for (fcm_index a = 0; a < fcm_mesh_num_nodes(p.mesh); a++) {
      fcm_index d = fcm_space_node_dof(p.space, a);
      if (d < 0) continue;
      double ue[3];
      fcm_motion_eval(&m, X + 3 * a, 1.0, ue, NULL);
      for (int i = 0; i < 3; i++) {
        err = fmax(err, fabs(u[d + i] - ue[i]));
        scale = fmax(scale, fabs(ue[i]));
      }
    }
    /* Nitsche: consistent, exact; penalty: the rigid motion makes no stress either, so it
     * is exact too (the penalty's inconsistency needs a non-zero traction) */
    if (!(err <= 1e-8 * scale)) TEST_FAIL_("rigid: max nodal error %.3g (scale %.3g)", err, scale);
  }
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* Points of the ball's surface below the plane z = c_z - 0.3 r: a curved cap. */
static int below(void *user, const double X[3], const double n[3])
{
  (void)n;
  return X[2] <= *(const double *)user;
}

static double dotn(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * b[i];
  return s;
}

static int tangent(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_geometry *g = NULL;
  fcm_integrator *I = NULL;
  fcm_csr *T = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, mlo[3] = {0, 0, 0}, mhi[3] = {1, 1, 1};
  const fcm_index cells[3] = {4, 4, 4};
  double zcut = 0.5 - 0.3 * 0.37;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.35, 1000.0};
  fcm_integrator_options o = static_options();
  fcm_motion m = fcm_motion_default();
  m.angular_speed = 0.2, m.axis[0] = 1, m.axis[2] = 0, m.center[0] = 0.5, m.center[1] = 0.5;
  m.center[2] = 0.5, m.velocity[2] = 0.01;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.37, 3, &g));
  TEST_OK(ctx, problem_build(&p, FCM_ELEMENT_HEX8, cells, mlo, mhi, g, 1, 1e-4));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_boundary_constraint(I, below, &zcut, &m, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  const fcm_index n = fcm_integrator_num_dofs(I);
  double *u = calloc((size_t)n, sizeof *u), *d = calloc((size_t)n, sizeof *d);
  double *f0 = calloc((size_t)n, sizeof *f0), *fp = calloc((size_t)n, sizeof *fp);
  double *fm = calloc((size_t)n, sizeof *fm), *Td = calloc((size_t)n, sizeof *Td);
  srand(7);
  for (fcm_index i = 0; i < n; i++) {
    u[i] = 0.02 * ((double)rand() / RAND_MAX - 0.5);
    d[i] = (double)rand() / RAND_MAX - 0.5;
  }
  double *u0 = malloc(sizeof *u0 * (size_t)n); /* the evaluation point, kept bit for bit */
  memcpy(u0, u, sizeof *u0 * (size_t)n);
  TEST_OK(ctx, fcm_space_matrix_create(p.space, &T));
  double e0 = 0.0, ep = 0.0, em = 0.0, t = 1.0;
  TEST_OK(ctx, fcm_integrator_boundary_eval(I, u, t, &e0, f0, T));
  double asym = 1.0;
  TEST_OK(ctx, fcm_csr_asymmetry(T, &asym));
  if (!(asym == 0.0)) TEST_FAIL_("tangent: relative asymmetry %.3g", asym);
  /* energy -> force, force -> tangent, central differences in direction d */
  const double eps = 1e-6;
  for (fcm_index i = 0; i < n; i++)
    u[i] += eps * d[i];
  TEST_OK(ctx, fcm_integrator_boundary_eval(I, u, t, &ep, fp, NULL));
  for (fcm_index i = 0; i < n; i++)
    u[i] -= 2.0 * eps * d[i];
  TEST_OK(ctx, fcm_integrator_boundary_eval(I, u, t, &em, fm, NULL));
  for (fcm_index i = 0; i < n; i++)
    u[i] += eps * d[i];
  const double de = (ep - em) / (2.0 * eps), fd = dotn(n, f0, d);
  TEST_NEAR(de, fd, 1e-6, 1e-12 * fabs(e0));
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, d, 0.0, Td));
  double num = 0.0, den = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    double x = (fp[i] - fm[i]) / (2.0 * eps);
    num += (x - Td[i]) * (x - Td[i]);
    den += Td[i] * Td[i];
  }
  if (!(sqrt(num) <= 1e-6 * sqrt(den)))
    TEST_FAIL_("tangent: |dF/du d - T d| / |T d| = %.3g", sqrt(num / den));
  TEST_TRUE(den > 0.0);
  /* colour-parallel assembly, energies summed in element order: a second evaluation is
   * bitwise the same, and so is one with a single thread when the penalties (LAPACK, whose
   * BLAS may split its work by thread count) came out bitwise equal; else within 1e-12 */
  {
    fcm_integrator *I1 = NULL;
    const int threads = omp_get_max_threads();
    double e1 = 0.0, e2 = 0.0, *f1 = calloc((size_t)n, sizeof *f1);
    double *f2 = calloc((size_t)n, sizeof *f2);
    TEST_OK(ctx, fcm_integrator_boundary_eval(I, u0, t, &e2, f2, NULL));
    omp_set_num_threads(1);
    TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I1));
    TEST_OK(ctx, fcm_integrator_add_boundary_constraint(I1, below, &zcut, &m, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_setup(I1));
    TEST_OK(ctx, fcm_integrator_boundary_eval(I1, u0, t, &e1, f1, NULL));
    omp_set_num_threads(threads);
    int same_gamma = 1;
    for (fcm_index el = 0; el < fcm_space_num_elements(p.space); el++)
      same_gamma &=
          fcm_integrator_boundary_penalty(I1, el) == fcm_integrator_boundary_penalty(I, el);
    const double rt = same_gamma ? 0.0 : 1e-12;
    TEST_TRUE(e2 == e0);
    TEST_NEAR(e1, e0, rt, 0.0);
    double fn = 0.0;
    for (fcm_index i = 0; i < n; i++)
      fn = fmax(fn, fabs(f0[i]));
    for (fcm_index i = 0; i < n; i++) {
      if (f2[i] != f0[i] || !(fabs(f1[i] - f0[i]) <= rt * fn)) {
        TEST_FAIL_("force[%lld] %.17g, again %.17g, with one thread %.17g (%d threads, penalties "
                   "%s)",
                   (long long)i, f0[i], f2[i], f1[i], threads, same_gamma ? "equal" : "differ");
        break;
      }
    }
    free(f1);
    free(f2);
    fcm_integrator_destroy(&I1);
  }
  free(u), free(u0), free(d), free(f0), free(fp), free(fm), free(Td);
  fcm_csr_destroy(&T);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* Penalty (dimensionless gamma h / E) of the thin cut cell of a box that reaches
 * `d` into the second of two cells. */
static double thin_cell_penalty(fcm_ctx *ctx, double d, int stabilize)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_geometry *g = NULL;
  fcm_integrator *I = NULL;
  const double lo[3] = {0.1, 0.1, 0.1}, hi[3] = {0.5 + d, 0.9, 0.9};
  const double mlo[3] = {0, 0, 0}, mhi[3] = {1, 1, 1};
  const fcm_index n[3] = {1, 1, 1}, cells[3] = {2, 1, 1};
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  fcm_integrator_options o = static_options();
  fcm_motion m = fcm_motion_default();
  double gm = NAN;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n, &g));
  TEST_OK(ctx, problem_build(&p, FCM_ELEMENT_HEX8, cells, mlo, mhi, g, stabilize, 0.0));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_boundary_constraint(I, NULL, NULL, &m, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  fcm_index first = -1;
  if (fcm_space_cell_elements(p.space, 1, &first) == 1)
    gm = fcm_integrator_boundary_penalty(I, first) * cbrt(0.5) / mat.young;
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return gm;
}

static int penalty(fcm_ctx *ctx)
{
  const double alpha = fcm_stabilization_options_default().alpha;
  double prev = 0.0, g[4];
  const double ds[4] = {1e-3, 1e-5, 1e-7, 1e-9};
  for (int k = 0; k < 4; k++) {
    g[k] = thin_cell_penalty(ctx, ds[k], 1);
    TEST_TRUE(isfinite(g[k]) && g[k] > 0.0);
    /* bounded: at most about 1/alpha times a full cell's O(1) value */
    if (!(g[k] <= 100.0 / alpha)) TEST_FAIL_("penalty: gamma h/E = %.3g at d = %g", g[k], ds[k]);
    TEST_TRUE(g[k] >= prev * 0.5);
    prev = g[k];
  }
  /* saturated (about 1/alpha): a 100 times thinner slice raises it by less than 2 (while it
   * grew 100-fold from d = 1e-3 to 1e-5, where phi >> alpha) */
  if (!(g[3] <= 2.0 * g[2] && g[1] >= 50.0 * g[0]))
    TEST_FAIL_("penalty: gamma h/E = %.3g %.3g %.3g %.3g for d = 1e-3 ... 1e-9", g[0], g[1], g[2],
               g[3]);
  /* without stabilization it grows like 1/phi */
  double a = thin_cell_penalty(ctx, 1e-2, 0), b = thin_cell_penalty(ctx, 1e-4, 0);
  if (!(b > 20.0 * a)) TEST_FAIL_("penalty without stabilization: %.3g -> %.3g only", a, b);
  return 0;
}

static int solve_ball(fcm_ctx *ctx, const problem *p, fcm_integrator_kind kind,
                      fcm_linear_solver solver, fcm_preconditioner pc, double *u_out, double zcut)
{
  fcm_integrator *I = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2e5, 0.3, 1000.0};
  fcm_integrator_options o = static_options();
  const double grav[3] = {0, 0, -9.81};
  o.kind = kind;
  o.dt = kind == FCM_INTEGRATOR_STATIC ? 1.0 : 0.01;
  o.linear_solver = solver;
  o.reuse_factorization = 0; /* full Newton on every solver: their results are compared */
  o.preconditioner = pc;
  o.krylov_rtol = 1e-12;
  o.krylov_max_iterations = 5000;
  o.newton_tolerance = 1e-10;
  fcm_motion m = fcm_motion_default();
  TEST_OK(ctx, fcm_integrator_create(ctx, p->space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, grav, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_boundary_constraint(I, below, &zcut, &m, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  fcm_step_info info;
  for (int s = 0; s < 2; s++)
    TEST_OK(ctx, fcm_integrator_step(I, &info));
  if (kind == FCM_INTEGRATOR_STATIC) { /* the reaction balances the weight (force, moment) */
    const fcm_index n = fcm_integrator_num_dofs(I);
    const double *X = fcm_mesh_coords(fcm_space_mesh(p->space)),
                 *u = fcm_integrator_displacement(I);
    double *f = calloc((size_t)n, sizeof *f), W[3] = {0, 0, 0}, MW[3] = {0, 0, 0}, R[3], MR[3];
    TEST_OK(ctx, fcm_assemble_body_force(p->space, &mat, grav, NULL, f));
    for (fcm_index a = 0; a < fcm_mesh_num_nodes(fcm_space_mesh(p->space)); a++) {
      const fcm_index d = fcm_space_node_dof(p->space, a);
      if (d < 0) continue;
      const double x[3] = {X[3 * a] + u[d], X[3 * a + 1] + u[d + 1], X[3 * a + 2] + u[d + 2]};
      for (int i = 0; i < 3; i++)
        W[i] += f[d + i];
      MW[0] += x[1] * f[d + 2] - x[2] * f[d + 1];
      MW[1] += x[2] * f[d] - x[0] * f[d + 2];
      MW[2] += x[0] * f[d + 1] - x[1] * f[d];
    }
    TEST_OK(ctx, fcm_integrator_boundary_reaction(I, 0, R, MR));
    for (int i = 0; i < 3; i++)
      TEST_NEAR(R[i], -W[i], 0.0, 1e-6 * fabs(W[2]));
    /* the moment of the nodal loads about the origin is that of the weight up to the
     * deformation's O(|u|) shift of the nodal lever arms */
    for (int i = 0; i < 3; i++)
      TEST_NEAR(MR[i], -MW[i], 0.0, 1e-3 * fabs(W[2]));
    free(f);
  }
  memcpy(u_out, fcm_integrator_displacement(I), sizeof *u_out * (size_t)fcm_integrator_num_dofs(I));
  fcm_integrator_destroy(&I);
  return 0;
}

static int solvers(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_geometry *g = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, mlo[3] = {0, 0, 0}, mhi[3] = {1, 1, 1};
  const fcm_index cells[3] = {4, 4, 4};
  double zcut = 0.5 - 0.25;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.37, 3, &g));
  TEST_OK(ctx, problem_build(&p, FCM_ELEMENT_HEX8, cells, mlo, mhi, g, 1, 1e-4));
  const fcm_index n = fcm_space_num_dofs(p.space);
  double *ud = calloc((size_t)n, sizeof *ud), *uk = calloc((size_t)n, sizeof *uk);
  for (int kind = 0; kind < 2; kind++) {
    fcm_integrator_kind k = kind ? FCM_INTEGRATOR_BACKWARD_EULER : FCM_INTEGRATOR_STATIC;
    solve_ball(ctx, &p, k, FCM_LINEAR_DIRECT, FCM_PRECOND_JACOBI, ud, zcut);
    double un = 0.0;
    for (fcm_index i = 0; i < n; i++)
      un = fmax(un, fabs(ud[i]));
    TEST_TRUE(un > 0.0 && isfinite(un));
    for (int s = 1; s <= 3; s++) { /* CG + Jacobi, MINRES + Jacobi, MINRES + Schwarz */
      solve_ball(ctx, &p, k, s == 1 ? FCM_LINEAR_CG : FCM_LINEAR_MINRES,
                 s == 3 ? FCM_PRECOND_SCHWARZ : FCM_PRECOND_JACOBI, uk, zcut);
      double e = 0.0;
      for (fcm_index i = 0; i < n; i++)
        e = fmax(e, fabs(uk[i] - ud[i]));
      if (!(e <= 1e-6 * un))
        TEST_FAIL_("solvers: kind %d solver %d differs from direct by %.3g (|u| %.3g)", kind, s, e,
                   un);
    }
  }
  free(ud), free(uk);
  problem_free(&p);
  return 0;
}

static int errors(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_geometry *g = NULL;
  fcm_integrator *I = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, mlo[3] = {0, 0, 0}, mhi[3] = {1, 1, 1};
  const fcm_index cells[3] = {2, 2, 2};
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  fcm_integrator_options o = static_options();
  fcm_motion m = fcm_motion_default();
  fcm_boundary_options bo = fcm_boundary_options_default();
  double znone = -1.0;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.37, 2, &g));
  TEST_OK(ctx, problem_build(&p, FCM_ELEMENT_HEX8, cells, mlo, mhi, g, 1, 1e-4));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  bo.nitsche_safety = 1.0;
  TEST_ERR(ctx, fcm_integrator_add_boundary_constraint(I, NULL, NULL, &m, &bo, NULL), FCM_ERR_ARG,
           "nitsche_safety");
  bo = fcm_boundary_options_default();
  bo.penalty = -1.0;
  TEST_ERR(ctx, fcm_integrator_add_boundary_constraint(I, NULL, NULL, &m, &bo, NULL), FCM_ERR_ARG,
           "penalty");
  bo = fcm_boundary_options_default();
  bo.method = (fcm_boundary_method)7;
  TEST_ERR(ctx, fcm_integrator_add_boundary_constraint(I, NULL, NULL, &m, &bo, NULL), FCM_ERR_ARG,
           "method");
  TEST_ERR(ctx, fcm_integrator_add_boundary_constraint(I, NULL, NULL, NULL, NULL, NULL),
           FCM_ERR_ARG, "NULL motion");
  TEST_OK(ctx, fcm_integrator_add_boundary_constraint(I, below, &znone, &m, NULL, NULL));
  TEST_ERR(ctx, fcm_integrator_setup(I), FCM_ERR_ARG, "selects no embedded-boundary point");
  fcm_integrator_destroy(&I);
  TEST_TRUE(strcmp(fcm_boundary_method_name(FCM_BOUNDARY_PENALTY), "penalty") == 0);
  problem_free(&p);
  /* a plain (non-embedded) space has no surface rules */
  {
    fcm_mesh *mesh = NULL;
    fcm_space *sp = NULL;
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, mlo, mhi, cells, &mesh));
    TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &sp));
    TEST_OK(ctx, fcm_integrator_create(ctx, sp, &mat, &o, &I));
    TEST_OK(ctx, fcm_integrator_add_boundary_constraint(I, NULL, NULL, &m, NULL, NULL));
    TEST_ERR(ctx, fcm_integrator_setup(I), FCM_ERR_ARG, "no surface rules");
    fcm_integrator_destroy(&I);
    fcm_space_destroy(&sp);
    fcm_mesh_destroy(&mesh);
  }
  return 0;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  const char *mode = argc > 1 ? argv[1] : "patch";
  if (!strcmp(mode, "patch")) {
    fcm_element_type type = FCM_ELEMENT_HEX8;
    if (argc > 2 && fcm_element_type_from_name(argv[2], &type) != FCM_OK) return 2;
    patch(ctx, type);
  } else if (!strcmp(mode, "rigid")) {
    rigid(ctx, FCM_BOUNDARY_NITSCHE);
    rigid(ctx, FCM_BOUNDARY_PENALTY);
  } else if (!strcmp(mode, "tangent")) {
    tangent(ctx);
  } else if (!strcmp(mode, "penalty")) {
    penalty(ctx);
  } else if (!strcmp(mode, "solvers")) {
    solvers(ctx);
  } else if (!strcmp(mode, "errors")) {
    errors(ctx);
  } else {
    return 2;
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
