/* Assembly of linear elasticity on a space: element kernels for stiffness,
 * consistent mass and body force, and the colour-by-colour parallel scatter. */
#include "fem/fem_impl.h"
#include "la/mat3.h"

#include <math.h>
#include <omp.h>
#include <string.h>

fcm_status fcm_elastic_lame(fcm_ctx *ctx, const fcm_elastic *m, double *lambda, double *mu)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(m, ctx, FCM_ERR_ARG, "elastic: material is NULL");
  FCM_CHECK(isfinite(m->young) && m->young > 0.0, ctx, FCM_ERR_ARG,
            "elastic: Young's modulus E = %g must be positive and finite", m->young);
  FCM_CHECK(isfinite(m->poisson) && m->poisson > -1.0 && m->poisson < 0.5, ctx, FCM_ERR_ARG,
            "elastic: Poisson's ratio nu = %g must lie in (-1, 0.5)", m->poisson);
  FCM_CHECK(isfinite(m->density) && m->density >= 0.0, ctx, FCM_ERR_ARG,
            "elastic: density = %g must be non-negative and finite", m->density);
  if (lambda)
    *lambda = m->young * m->poisson / ((1.0 + m->poisson) * (1.0 - 2.0 * m->poisson));
  if (mu) *mu = m->young / (2.0 * (1.0 + m->poisson));
cleanup:
  return st;
}

fcm_assembly_options fcm_assembly_options_default(void)
{
  fcm_assembly_options o = {0, 0};
  return o;
}

/* Shape values and reference gradients of the element tabulated at a rule's points. */
typedef struct tabulation {
  int nq, nn;
  const double *w; /* nq weights (borrowed from the rule) */
  double *N;       /* nq x nn */
  double *dN;      /* nq x nn x 3 */
} tabulation;

fcm_status fcm_element_standard_rule(fcm_ctx *ctx, fcm_element_type type, fcm_integrand integrand,
                                     int strength, fcm_rule **rule)
{
  fcm_status st = FCM_OK;
  const fcm_element_info *info = fcm_element_get_info(type);
  FCM_CHECK(info, ctx, FCM_ERR_ARG, "standard rule: invalid element type %d", (int)type);
  FCM_CHECK(integrand == FCM_INTEGRAND_STIFFNESS || integrand == FCM_INTEGRAND_MASS, ctx,
            FCM_ERR_ARG, "standard rule: invalid integrand %d", (int)integrand);
  if (strength > 0)
    FCM_TRY(ctx, fcm_rule_create(ctx, info->shape, strength, rule));
  else if (info->shape == FCM_SHAPE_HEX) /* order+1 points per direction: strength 2*order+1 */
    FCM_TRY(ctx, fcm_rule_create_computed(ctx, info->shape, 2 * info->order + 1, rule));
  else
    FCM_TRY(ctx, fcm_rule_create(ctx, info->shape,
                                 integrand == FCM_INTEGRAND_MASS ? info->mass_strength
                                                                 : info->stiffness_strength,
                                 rule));
cleanup:
  return st;
}

static fcm_status tabulate(fcm_space *s, fcm_integrand integrand, int strength, fcm_rule **rule,
                           tabulation *t)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  FCM_TRY(ctx, fcm_element_standard_rule(ctx, s->type, integrand, strength, rule));
  t->nq = fcm_rule_num_points(*rule);
  t->nn = s->nn;
  t->w = fcm_rule_weights(*rule);
  FCM_ALLOC(ctx, (size_t)t->nq * t->nn, t->N);
  FCM_ALLOC(ctx, (size_t)t->nq * t->nn * 3, t->dN);
  const double *pts = fcm_rule_points(*rule);
  for (int q = 0; q < t->nq; q++) {
    fcm_element_eval_shape(s->type, pts + 3 * q, t->N + (size_t)q * t->nn);
    fcm_element_eval_grad(s->type, pts + 3 * q, t->dN + (size_t)q * t->nn * 3);
  }
cleanup:
  return st;
}

static void tabulation_free(fcm_ctx *ctx, tabulation *t)
{
  FCM_FREE(ctx, t->N);
  FCM_FREE(ctx, t->dN);
}

/* What a kernel computes for one cell. */
typedef enum kernel_kind { KERNEL_STIFFNESS, KERNEL_MASS, KERNEL_BODY_FORCE } kernel_kind;

typedef struct kernel_data {
  kernel_kind kind;
  double lambda, mu, rho;
  double accel[3];
} kernel_data;

/* Jacobian at tabulated point q: physical gradients g (nn x 3) and det J. */
static double physical_gradients(const tabulation *t, int q, const double *X, double *g)
{
  const double *dN = t->dN + (size_t)q * t->nn * 3;
  double J[9] = {0}, Ji[9] = {0};
  for (int a = 0; a < t->nn; a++)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) J[3 * i + j] += X[3 * a + i] * dN[3 * a + j];
  double det = fcm__mat3_inv(J, Ji);
  if (!(det > 0.0)) return det;
  for (int a = 0; a < t->nn; a++)
    fcm__mat3_tmulv(Ji, dN + 3 * a, g + 3 * a);
  return det;
}

/* Element matrix (3nn x 3nn, row-major) or vector (3nn) of one cell; returns the
 * first non-positive det J met (1 when all are positive). `H` is scratch of
 * (3nn)^2 entries.
 * Stiffness: with v the 3nn-vector of all physical gradients at a point, the
 * sums H = sum_q w_q det J_q v v^T (a symmetric rank-one update per point, the
 * only work that grows with the number of points) give the isotropic element
 * matrix K_(a,i)(b,j) = lambda H_(a,i)(b,j) + mu H_(a,j)(b,i) + mu delta_ij
 * sum_k H_(a,k)(b,k), assembled once per cell. */
static double cell_kernel(const kernel_data *kd, const tabulation *t, const double *X, double *g,
                          double *H, double *Ke)
{
  int nn = t->nn, ndof = 3 * nn;
  double bad = 1.0;
  if (kd->kind == KERNEL_BODY_FORCE)
    memset(Ke, 0, sizeof *Ke * (size_t)ndof);
  else
    memset(H, 0, sizeof *H * (size_t)ndof * ndof);
  for (int q = 0; q < t->nq; q++) {
    double det = physical_gradients(t, q, X, g);
    if (!(det > 0.0)) {
      bad = det;
      break;
    }
    double wd = t->w[q] * det;
    const double *N = t->N + (size_t)q * nn;
    if (kd->kind == KERNEL_STIFFNESS) {
      for (int r = 0; r < ndof; r++) {
        double sr = wd * g[r], *Hr = H + (size_t)r * ndof;
        for (int c = r; c < ndof; c++) Hr[c] += sr * g[c];
      }
    } else if (kd->kind == KERNEL_MASS) {
      double rw = wd * kd->rho;
      for (int a = 0; a < nn; a++) {
        double sa = rw * N[a], *Ha = H + (size_t)a * nn;
        for (int b = a; b < nn; b++) Ha[b] += sa * N[b];
      }
    } else {
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++) Ke[3 * a + i] += wd * kd->rho * kd->accel[i] * N[a];
    }
  }
  if (kd->kind == KERNEL_BODY_FORCE) return bad;
  memset(Ke, 0, sizeof *Ke * (size_t)ndof * ndof);
  if (kd->kind == KERNEL_STIFFNESS) {
    double l = kd->lambda, m = kd->mu;
    for (int r = 0; r < ndof; r++) /* complete H from its upper triangle */
      for (int c = 0; c < r; c++) H[(size_t)r * ndof + c] = H[(size_t)c * ndof + r];
    for (int a = 0; a < nn; a++)
      for (int b = a; b < nn; b++) {
        const double *Hab = H + (size_t)(3 * a) * ndof + 3 * b; /* block (a, b) of H */
        double tr = m * (Hab[0] + Hab[ndof + 1] + Hab[2 * ndof + 2]);
        for (int i = 0; i < 3; i++) {
          double *row = Ke + (size_t)(3 * a + i) * ndof + 3 * b;
          for (int j = 0; j < 3; j++) row[j] = l * Hab[i * ndof + j] + m * Hab[j * ndof + i];
          row[i] += tr;
        }
      }
  } else {
    for (int a = 0; a < nn; a++)
      for (int b = a; b < nn; b++)
        for (int i = 0; i < 3; i++) Ke[(size_t)(3 * a + i) * ndof + 3 * b + i] = H[(size_t)a * nn + b];
  }
  for (int a = 0; a < nn; a++) /* mirror the upper node blocks */
    for (int b = 0; b < a; b++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          Ke[(size_t)(3 * a + i) * ndof + 3 * b + j] = Ke[(size_t)(3 * b + j) * ndof + 3 * a + i];
  return bad;
}

/* Run the kernel over all active cells colour by colour and scatter into the
 * matrix values `vals` (pattern of the space) or the vector `vec`. */
static fcm_status assemble(fcm_space *s, const kernel_data *kd, int strength, double *vals,
                           double *vec)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_rule *rule = NULL;
  tabulation t = {0, 0, NULL, NULL, NULL};
  double *work = NULL;
  int nn = s->nn, ndof = 3 * nn, nthreads = omp_get_max_threads();
  size_t per_thread = (size_t)nn * 3 * 3 + 2 * (size_t)ndof * ndof + (size_t)nn * 3;
  fcm_index bad_cell = -1;
  double bad_det = 1.0;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  FCM_TRY(ctx, tabulate(s, kd->kind == KERNEL_MASS ? FCM_INTEGRAND_MASS : FCM_INTEGRAND_STIFFNESS,
                        strength, &rule, &t));
  FCM_ALLOC(ctx, per_thread * (size_t)nthreads, work);
  for (int color = 0; color < s->num_colors; color++) {
    fcm_index c0 = s->color_ptr[color], c1 = s->color_ptr[color + 1];
#pragma omp parallel num_threads(nthreads)
    {
      double *X = work + per_thread * (size_t)omp_get_thread_num();
      double *Ke = X + (size_t)nn * 3, *H = Ke + (size_t)ndof * ndof;
      double *g = H + (size_t)ndof * ndof;
#pragma omp for schedule(static)
      for (fcm_index k = c0; k < c1; k++) {
        fcm_index c = s->color_cells[k];
        fcm_mesh_cell_coords(s->mesh, c, X);
        double det = cell_kernel(kd, &t, X, g, H, Ke);
        if (!(det > 0.0)) {
#pragma omp critical(fcm_assemble_bad)
          if (bad_cell < 0 || c < bad_cell) bad_cell = c, bad_det = det;
          continue;
        }
        const fcm_index *cn = cells + c * nn;
        const int *off = s->cell_off + (size_t)c * nn * nn;
        for (int a = 0; a < nn; a++) {
          fcm_index da = s->node_dof[cn[a]];
          for (int i = 0; i < 3; i++) {
            if (vec) {
              vec[da + i] += Ke[3 * a + i];
              continue;
            }
            double *dst = vals + s->row_ptr[da + i];
            const double *src = Ke + (size_t)(3 * a + i) * ndof;
            for (int b = 0; b < nn; b++) {
              double *d = dst + 3 * off[a * nn + b];
              d[0] += src[3 * b];
              d[1] += src[3 * b + 1];
              d[2] += src[3 * b + 2];
            }
          }
        }
      }
    }
    FCM_CHECK(bad_cell < 0, ctx, FCM_ERR_GEOMETRY,
              "assembly: cell %lld has det J = %g <= 0 at a quadrature point (inverted or "
              "degenerate %s)",
              (long long)bad_cell, bad_det, fcm_element_get_info(s->type)->name);
  }
cleanup:
  tabulation_free(ctx, &t);
  fcm_rule_destroy(&rule);
  fcm__free(ctx, work);
  return st;
}

/* The matrix must carry this space's pattern. */
static fcm_status check_matrix(const fcm_space *s, const fcm_csr *A)
{
  fcm_status st = FCM_OK;
  fcm_index nr = -1, nc = -1, nnz = -1;
  FCM_CHECK(A, s->ctx, FCM_ERR_ARG, "assembly: matrix is NULL");
  fcm_csr_get_size(A, &nr, &nc, &nnz);
  FCM_CHECK(nr == s->num_dofs && nc == s->num_dofs && nnz == s->row_ptr[s->num_dofs], s->ctx,
            FCM_ERR_ARG,
            "assembly: matrix is %lld x %lld with %lld entries; the space needs %lld x %lld with "
            "%lld (create it with fcm_space_matrix_create)",
            (long long)nr, (long long)nc, (long long)nnz, (long long)s->num_dofs,
            (long long)s->num_dofs, (long long)s->row_ptr[s->num_dofs]);
cleanup:
  return st;
}

fcm_status fcm_assemble_stiffness(fcm_space *s, const fcm_elastic *mat,
                                  const fcm_assembly_options *opts, fcm_csr *A)
{
  fcm_status st = FCM_OK;
  kernel_data kd = {KERNEL_STIFFNESS, 0, 0, 0, {0, 0, 0}};
  fcm_assembly_options o = opts ? *opts : fcm_assembly_options_default();
  FCM_TRY(s->ctx, fcm_elastic_lame(s->ctx, mat, &kd.lambda, &kd.mu));
  FCM_TRY(s->ctx, check_matrix(s, A));
  FCM_TRY(s->ctx, assemble(s, &kd, o.stiffness_strength, fcm_csr_get_values(A), NULL));
cleanup:
  return st;
}

fcm_status fcm_assemble_mass(fcm_space *s, const fcm_elastic *mat,
                             const fcm_assembly_options *opts, fcm_csr *A)
{
  fcm_status st = FCM_OK;
  kernel_data kd = {KERNEL_MASS, 0, 0, 0, {0, 0, 0}};
  fcm_assembly_options o = opts ? *opts : fcm_assembly_options_default();
  FCM_TRY(s->ctx, fcm_elastic_lame(s->ctx, mat, NULL, NULL));
  FCM_TRY(s->ctx, check_matrix(s, A));
  kd.rho = mat->density;
  FCM_TRY(s->ctx, assemble(s, &kd, o.mass_strength, fcm_csr_get_values(A), NULL));
cleanup:
  return st;
}

fcm_status fcm_assemble_body_force(fcm_space *s, const fcm_elastic *mat, const double accel[3],
                                   const fcm_assembly_options *opts, double *f)
{
  fcm_status st = FCM_OK;
  kernel_data kd = {KERNEL_BODY_FORCE, 0, 0, 0, {0, 0, 0}};
  fcm_assembly_options o = opts ? *opts : fcm_assembly_options_default();
  FCM_TRY(s->ctx, fcm_elastic_lame(s->ctx, mat, NULL, NULL));
  FCM_CHECK(f && accel, s->ctx, FCM_ERR_ARG, "body force: NULL vector or acceleration");
  FCM_CHECK(isfinite(accel[0]) && isfinite(accel[1]) && isfinite(accel[2]), s->ctx, FCM_ERR_ARG,
            "body force: acceleration (%g, %g, %g) is not finite", accel[0], accel[1], accel[2]);
  kd.rho = mat->density;
  memcpy(kd.accel, accel, sizeof kd.accel);
  FCM_TRY(s->ctx, assemble(s, &kd, o.stiffness_strength, NULL, f));
cleanup:
  return st;
}

fcm_status fcm_space_eval(const fcm_space *s, fcm_index cell, const double xi[3], const double *u,
                          double value[3])
{
  fcm_status st = FCM_OK;
  double N[FCM_ELEMENT_MAX_NODES];
  FCM_CHECK(cell >= 0 && cell < s->num_cells && s->active[cell], s->ctx, FCM_ERR_ARG,
            "space eval: cell %lld is out of range [0, %lld) or inactive", (long long)cell,
            (long long)s->num_cells);
  fcm_element_eval_shape(s->type, xi, N);
  value[0] = value[1] = value[2] = 0.0;
  {
    const fcm_index *cn = fcm_mesh_cells(s->mesh) + cell * s->nn;
    for (int a = 0; a < s->nn; a++) {
      fcm_index d = s->node_dof[cn[a]];
      for (int i = 0; i < 3; i++) value[i] += N[a] * u[d + i];
    }
  }
cleanup:
  return st;
}
