/* Shared helpers of the sim tests: a small beam on a box mesh, node sets on planes, vector
 * norms and a Newton-residual recorder for the monitor callback. */
#ifndef FCM_TEST_SIM_UTIL_H
#define FCM_TEST_SIM_UTIL_H

#include "fcm/fcm.h"
#include "fcm/sim.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* A beam [0, lx] x [0, 1] x [0, 1] of nx x 1 x 1 cubes (nx cells of `type`, tets split). */
static inline fcm_status beam_mesh(fcm_ctx *ctx, fcm_element_type type, fcm_index nx, double lx,
                                   fcm_mesh **mesh)
{
  double lo[3] = {0, 0, 0}, hi[3] = {lx, 1, 1};
  fcm_index n[3] = {nx, 1, 1};
  return fcm_mesh_create_box(ctx, type, lo, hi, n, mesh);
}

/* Nodes with coordinate `axis` equal to `value` (tolerance 1e-9); malloc'ed list. */
static inline fcm_index *plane_nodes(fcm_ctx *ctx, const fcm_mesh *mesh, int axis, double value,
                                     fcm_index *count)
{
  double lo[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, hi[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
  lo[axis] = hi[axis] = value;
  fcm_index c = 0;
  if (fcm_mesh_nodes_in_box(ctx, mesh, lo, hi, 1e-9, 0, NULL, &c) != FCM_OK) return NULL;
  fcm_index *nodes = malloc(sizeof *nodes * (size_t)(c > 0 ? c : 1));
  if (fcm_mesh_nodes_in_box(ctx, mesh, lo, hi, 1e-9, c, nodes, &c) != FCM_OK) {
    free(nodes);
    return NULL;
  }
  *count = c;
  return nodes;
}

static inline double vec_norm(fcm_index n, const double *a)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * a[i];
  return sqrt(s);
}

static inline double vec_dist(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += (a[i] - b[i]) * (a[i] - b[i]);
  return sqrt(s);
}

/* Records the monitor events of the current step. */
typedef struct newton_log {
  int count;
  double residual[256], alpha[256], tolerance[256];
  int iteration[256];
} newton_log;

static inline void newton_log_fn(void *user, const fcm_newton_event *ev)
{
  newton_log *log = user;
  if (log->count < 256) {
    log->residual[log->count] = ev->residual;
    log->alpha[log->count] = ev->step_length;
    log->tolerance[log->count] = ev->tolerance;
    log->iteration[log->count] = ev->iteration;
    log->count++;
  }
}

/* An embedded problem: the mesh, the geometry, its cell rules and the space (owned; freed by
 * problem_free() in reverse order; NULL members are skipped). */
typedef struct problem {
  fcm_ctx *ctx;
  fcm_mesh *mesh;
  fcm_geometry *geom;
  fcm_cell_rules *rules;
  fcm_space *space;
} problem;

static inline void problem_free(problem *p)
{
  fcm_space_destroy(&p->space);
  fcm_cell_rules_destroy(&p->rules);
  fcm_geometry_destroy(&p->geom);
  fcm_mesh_destroy(&p->mesh);
}

/* An embedded ball of radius r at c on a box mesh of nc^3 Hex8 cells over [0, 1]^3, with
 * surface rules (the points contact acts on). */
static inline fcm_status ball_problem(problem *p, const double c[3], double r, fcm_index nc)
{
  fcm_status st;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index cells[3] = {nc, nc, nc};
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  st = fcm_geometry_create_ball(p->ctx, c, r, 3, &p->geom);
  if (st == FCM_OK) st = fcm_mesh_create_box(p->ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &p->mesh);
  ro.surface_strength = 4;
  ro.min_fraction = 1e-4;
  if (st == FCM_OK) st = fcm_cell_rules_create(p->ctx, p->mesh, p->geom, &ro, &p->rules);
  if (st == FCM_OK) st = fcm_space_create_embedded(p->ctx, p->mesh, p->rules, &p->space);
  return st;
}

/* The tets of the boxes A and B (n cubes per axis each) merged into one geometry. */
static inline fcm_status merged_boxes(fcm_ctx *ctx, const double alo[3], const double ahi[3],
                                      const double blo[3], const double bhi[3],
                                      const fcm_index n[3], fcm_geometry **out)
{
  fcm_geometry *a = NULL, *b = NULL;
  fcm_status st = fcm_geometry_create_box(ctx, alo, ahi, n, &a);
  if (st == FCM_OK) st = fcm_geometry_create_box(ctx, blo, bhi, n, &b);
  if (st == FCM_OK) {
    const fcm_index na = fcm_geometry_num_nodes(a), nb = fcm_geometry_num_nodes(b);
    const fcm_index ca = fcm_geometry_num_cells(a), cb = fcm_geometry_num_cells(b);
    double *x = malloc(sizeof(double) * 3 * (size_t)(na + nb));
    fcm_index *c = malloc(sizeof(fcm_index) * 4 * (size_t)(ca + cb));
    memcpy(x, fcm_geometry_coords(a), sizeof(double) * 3 * (size_t)na);
    memcpy(x + 3 * na, fcm_geometry_coords(b), sizeof(double) * 3 * (size_t)nb);
    memcpy(c, fcm_geometry_cells(a), sizeof(fcm_index) * 4 * (size_t)ca);
    for (fcm_index k = 0; k < 4 * cb; k++)
      c[4 * ca + k] = fcm_geometry_cells(b)[k] + na;
    st = fcm_geometry_create(ctx, FCM_ELEMENT_TET4, na + nb, x, ca + cb, c, out);
    free(x), free(c);
  }
  fcm_geometry_destroy(&a);
  fcm_geometry_destroy(&b);
  return st;
}

/* Holds (fixed at rest) every node of mesh in the box [lo, hi]. */
static inline fcm_status hold_box(fcm_ctx *ctx, fcm_integrator *I, const fcm_mesh *mesh,
                                  const double lo[3], const double hi[3])
{
  fcm_index count = 0;
  fcm_status st = fcm_mesh_nodes_in_box(ctx, mesh, lo, hi, 0.0, 0, NULL, &count);
  if (st != FCM_OK) return st;
  fcm_index *nodes = malloc(sizeof *nodes * (size_t)(count + 1));
  st = fcm_mesh_nodes_in_box(ctx, mesh, lo, hi, 0.0, count, nodes, &count);
  fcm_motion m = fcm_motion_default();
  if (st == FCM_OK) st = fcm_integrator_add_constraint(I, count, nodes, &m, NULL);
  free(nodes);
  return st;
}

/* The cut tests' corotated integrator (Hex8 chains): material mat, gravity along -y, the nodes
 * below y = 0.05 held, one Newton iteration of 3 multigrid cycles a step, dt 0.01 s, cuts
 * taking what cut_reuse (FCM_CUT_REUSE_*) says; set up. */
static inline fcm_integrator *cut_chain_integrator(fcm_ctx *ctx, const fcm_space *space,
                                                   const fcm_mesh *mesh, const fcm_material *mat,
                                                   int cut_reuse)
{
  static const double gravity[3] = {0.0, -9.81, 0.0};
  fcm_integrator *I = NULL;
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.01;
  o.cut_reuse = cut_reuse;
  o.linear_solver = FCM_LINEAR_MULTIGRID;
  o.multigrid_fixed_cycles = 3;
  o.newton_fixed_iterations = 1;
  const double lo[3] = {-10, -10, -10}, hi[3] = {10, 0.05, 10};
  TEST_OK(ctx, fcm_integrator_create(ctx, space, mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, gravity, NULL, NULL));
  TEST_OK(ctx, hold_box(ctx, I, mesh, lo, hi));
  TEST_OK(ctx, fcm_integrator_setup(I));
  return I;
}

/* Central differences (step eps) of fcm_integrator_contact_eval() at u (restored on return)
 * and time t along d against its force f0 and Newton matrix T there (T may be NULL): the
 * relative errors of the energy's difference against f0 . d and of the force's against T d
 * (0 when T is NULL). */
static inline void contact_fd(fcm_ctx *ctx, fcm_integrator *I, fcm_index n, double *u,
                              const double *d, double t, double eps, const double *f0,
                              const fcm_csr *T, double *err_energy, double *err_tangent)
{
  double *fp = calloc((size_t)n, sizeof *fp), *fm = calloc((size_t)n, sizeof *fm);
  double *Td = calloc((size_t)n, sizeof *Td), ep = 0.0, em = 0.0, fd = 0.0, num = 0.0, den = 0.0;
  for (fcm_index i = 0; i < n; i++)
    u[i] += eps * d[i];
  TEST_OK(ctx, fcm_integrator_contact_eval(I, u, t, &ep, fp, NULL));
  for (fcm_index i = 0; i < n; i++)
    u[i] -= 2.0 * eps * d[i];
  TEST_OK(ctx, fcm_integrator_contact_eval(I, u, t, &em, fm, NULL));
  for (fcm_index i = 0; i < n; i++) {
    u[i] += eps * d[i];
    fd += f0[i] * d[i];
  }
  *err_energy = fabs((ep - em) / (2.0 * eps) - fd) / fabs(fd);
  *err_tangent = 0.0;
  if (T) {
    TEST_OK(ctx, fcm_csr_apply(T, 1.0, d, 0.0, Td));
    for (fcm_index i = 0; i < n; i++) {
      const double x = (fp[i] - fm[i]) / (2.0 * eps);
      num += (x - Td[i]) * (x - Td[i]);
      den += Td[i] * Td[i];
    }
    *err_tangent = den > 0.0 ? sqrt(num / den) : HUGE_VAL;
  }
  free(fp), free(fm), free(Td);
}

/* At u (force f0, Newton matrix T there): along three random directions (rnd() in each
 * entry) the force against central differences of the energy (relative 1e-6) and d^T T d >= 0,
 * then T symmetric (1e-12); `what` and `pairs` label the printed lines. */
static inline void contact_fd_directions(fcm_ctx *ctx, fcm_integrator *I, fcm_index n, double *u,
                                         const double *f0, const fcm_csr *T, double e, int trial,
                                         const char *what, long long pairs, double (*rnd)(void))
{
  double *d = calloc((size_t)n, sizeof *d), *Td = calloc((size_t)n, sizeof *Td);
  for (int dir = 0; dir < 3; dir++) {
    double ee = 0.0, et = 0.0, dTd = 0.0, dn = 0.0;
    for (fcm_index i = 0; i < n; i++)
      d[i] = rnd();
    contact_fd(ctx, I, n, u, d, 0.0, 1e-7, f0, NULL, &ee, &et);
    TEST_OK(ctx, fcm_csr_apply(T, 1.0, d, 0.0, Td));
    for (fcm_index i = 0; i < n; i++)
      dTd += d[i] * Td[i], dn += d[i] * d[i];
    printf("fd trial %d dir %d: energy %.6g J, %lld %s, relative error of the force %.3g, "
           "d^T T d / |d|^2 = %.4g\n",
           trial, dir, e, pairs, what, ee, dTd / dn);
    if (!(ee <= 1e-6)) TEST_FAIL_("force against differences: relative error %.3g", ee);
    if (!(dTd >= 0.0)) TEST_FAIL_("Newton matrix not positive semidefinite: %.3g", dTd);
  }
  double asym = 1.0;
  TEST_OK(ctx, fcm_csr_asymmetry(T, &asym));
  TEST_TRUE(asym <= 1e-12);
  free(d), free(Td);
}

/* The time of one fcm_integrator_contact_eval() (energy, force, Newton matrix T) at u and t
 * per embedded-surface point of the rules, printed (not asserted: lib/docs/contact.md). */
static inline void contact_eval_cost(fcm_ctx *ctx, fcm_integrator *I, const problem *p,
                                     const double *u, double t, double *f, fcm_csr *T,
                                     const char *what)
{
  fcm_index np = 0;
  double e = 0.0;
  for (fcm_index cell = 0; cell < fcm_mesh_num_cells(p->mesh); cell++) {
    int q = 0;
    TEST_OK(ctx, fcm_cell_rules_get_surface(p->rules, cell, &q, NULL, NULL, NULL, NULL));
    np += q;
  }
  const int reps = 100;
  const double t0 = fcm_wtime();
  for (int k = 0; k < reps; k++)
    TEST_OK(ctx, fcm_integrator_contact_eval(I, u, t, &e, f, T));
  const double dt = (fcm_wtime() - t0) / reps;
  printf("%s: contact eval (energy, force, Newton matrix): %lld surface points, %.3g s per call, "
         "%.3g us per point\n",
         what, (long long)np, dt, 1e6 * dt / (double)(np > 0 ? np : 1));
}

#endif
