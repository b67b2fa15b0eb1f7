/* The embedded problem both codes of the deal.II interop example solve, in one place (C and
 * C++): the kinked body and the manufactured solution of linear elasticity with a mass term.
 *
 * Body: a box with an inclined corner cut, the affine image X = c + A p of the parameter set
 * p = (s, t, r) in [0, 1]^3 with s + t + r <= 2.2, inside the unit cube with every face
 * inclined to the grid: its twelve edges and ten corners (kinks of the boundary) lie inside
 * cells, where a level set of the body is not smooth. Convex, so the dual problems are regular
 * and the rates in L2 are the optimal ones. Tetrahedra: a fan from the corner p = 0 over the
 * triangles of the faces that do not hold it (three pentagons and the cut triangle).
 *
 * Problem: -div sigma(u) + rho u = f in the body, sigma(u) n = g on its whole boundary
 * (no Dirichlet condition: the mass term makes it definite), sigma = lambda tr(eps) I +
 * 2 mu eps, with the exact solution u_i = sin(k_i . x). */
#ifndef FCM_EXAMPLE_KINKED_PROBLEM_H
#define FCM_EXAMPLE_KINKED_PROBLEM_H

#include <math.h>
#include <stddef.h>

#define KINKED_CUT   2.2 /* the corner cut: s + t + r <= KINKED_CUT */
#define KINKED_NODES 10  /* 7 corners of the cube and 3 points of the cut */
#define KINKED_TETS  10  /* 3 pentagons x 3 triangles + the cut triangle */
/* parameter volume: the cube less the corner tetrahedron of legs 3 - KINKED_CUT */
#define KINKED_VOLUME_P (1.0 - (3.0 - KINKED_CUT) * (3.0 - KINKED_CUT) * (3.0 - KINKED_CUT) / 6.0)

/* Material of both codes: E, nu (lambda, mu as fcm_material_lame() derives them), rho. */
#define KINKED_YOUNG   1.0
#define KINKED_POISSON 0.3
#define KINKED_DENSITY 1.0

static const double kinked_c[3] = {0.08, 0.09, 0.15};
static const double kinked_A[9] = {0.70, 0.04, 0.06, 0.10, 0.72, 0.05, 0.06, -0.04, 0.70};

/* Wave vectors of the exact solution's components (rows). */
static const double kinked_k[9] = {2.6, 1.8, 1.2, 1.6, 3.0, 1.4, 1.0, 1.2, 3.4};

static inline double kinked_lambda(void)
{
  return KINKED_YOUNG * KINKED_POISSON / ((1.0 + KINKED_POISSON) * (1.0 - 2.0 * KINKED_POISSON));
}

static inline double kinked_mu(void)
{
  return KINKED_YOUNG / (2.0 * (1.0 + KINKED_POISSON));
}

/* Nodes (KINKED_NODES x 3) and tetrahedra (KINKED_TETS x 4; fcm reorients negative ones). */
static inline void kinked_body(double *xyz, long long *tets)
{
  const double e = KINKED_CUT - 2.0; /* where the cut meets the edges at the corner (1,1,1) */
  const double p[KINKED_NODES][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1},
                                     {1, 0, 1}, {0, 1, 1}, {1, 1, e}, {1, e, 1}, {e, 1, 1}};
  /* the faces without node 0, each fanned from its first node */
  static const int faces[4][5] = {{1, 2, 7, 8, 5}, {3, 6, 9, 7, 2}, {4, 5, 8, 9, 6}, {7, 9, 8}};
  static const int sides[4] = {5, 5, 5, 3};
  for (int v = 0; v < KINKED_NODES; v++)
    for (int d = 0; d < 3; d++)
      xyz[3 * v + d] = kinked_c[d] + kinked_A[3 * d] * p[v][0] + kinked_A[3 * d + 1] * p[v][1] +
                       kinked_A[3 * d + 2] * p[v][2];
  long long *t = tets;
  for (int f = 0; f < 4; f++)
    for (int k = 1; k + 1 < sides[f]; k++, t += 4) {
      t[0] = 0;
      t[1] = faces[f][0];
      t[2] = faces[f][k];
      t[3] = faces[f][k + 1];
    }
}

/* The body's volume: KINKED_VOLUME_P det A. */
static inline double kinked_volume(void)
{
  const double *a = kinked_A;
  return KINKED_VOLUME_P *
         (a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
          a[2] * (a[3] * a[7] - a[4] * a[6]));
}

/* The exact solution u(x) and its gradient G[i][j] = d u_i / d x_j (either may be NULL). */
static inline void kinked_exact(const double x[3], double u[3], double G[9])
{
  for (int i = 0; i < 3; i++) {
    const double *k = kinked_k + 3 * i, ph = k[0] * x[0] + k[1] * x[1] + k[2] * x[2];
    if (u) u[i] = sin(ph);
    if (G)
      for (int j = 0; j < 3; j++)
        G[3 * i + j] = k[j] * cos(ph);
  }
}

/* The body force f = -div sigma(u) + rho u = (lambda + mu) sum_j k_jj k_j sin(k_j . x)
 * + (mu |k_i|^2 + rho) sin(k_i . x), component i. */
static inline void kinked_force(const double x[3], double f[3])
{
  const double lm = kinked_lambda() + kinked_mu();
  double s[3];
  for (int j = 0; j < 3; j++) {
    const double *k = kinked_k + 3 * j;
    s[j] = sin(k[0] * x[0] + k[1] * x[1] + k[2] * x[2]);
  }
  for (int i = 0; i < 3; i++) {
    const double *k = kinked_k + 3 * i;
    f[i] = (kinked_mu() * (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]) + KINKED_DENSITY) * s[i];
    for (int j = 0; j < 3; j++)
      f[i] += lm * kinked_k[3 * j + j] * kinked_k[3 * j + i] * s[j];
  }
}

/* The traction g = sigma(u) n at x with the unit outward normal n. */
static inline void kinked_traction(const double x[3], const double n[3], double g[3])
{
  double G[9];
  kinked_exact(x, NULL, G);
  const double div = G[0] + G[4] + G[8], lambda = kinked_lambda(), mu = kinked_mu();
  for (int i = 0; i < 3; i++) {
    g[i] = lambda * div * n[i];
    for (int j = 0; j < 3; j++)
      g[i] += mu * (G[3 * i + j] + G[3 * j + i]) * n[j];
  }
}

#endif
