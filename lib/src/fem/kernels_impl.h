/* fem element kernels, internal part: what assemble.c hands the element kernels of kernels.c
 * (one cell's rule, the integrand, per-thread scratch) and what they return. */
#ifndef FCM_FEM_KERNELS_IMPL_H
#define FCM_FEM_KERNELS_IMPL_H

#include "fem/fem_impl.h"
#include "material/material_impl.h"

/* Points per chunk of the linear kernels (gradients of a chunk, then one blocked product) and
 * of the hyperelastic kernel (its tangent's right factor is 3 x 3 QH rows per chunk). */
enum { FCM__KERNEL_QB = 32, FCM__KERNEL_QH = 8 };

/* Nodes of the by-component tables (reference gradients, coordinates, physical gradients): nn
 * rounded up to 4, the entries beyond nn zero, so that their loops run in whole vectors of 4. */
static inline int fcm__kernel_na(int nn)
{
  return (nn + 3) / 4 * 4;
}

/* The points of one cell's rule with the shape functions evaluated there. */
typedef struct cell_rule {
  int nq;
  const double *w;           /* nq weights; det J_K(xi) still to be applied */
  const double *N;           /* nq x nn */
  const double *dT;          /* nq x 3 x na reference gradients by component (fcm__kernel_rows()) */
  const unsigned char *fict; /* nq flags (1: fictitious stabilization point), or NULL */
  /* NULL, or the reference gradients point-minor (a standard rule's, tabulated once):
   * dQ[(3 a + k) qp + q] = dN_ak at point q, qp = nq rounded up to 8, zero for q >= nq; the
   * kernels then compute the Jacobians of 8 points at a time in the vector lanes */
  const double *dQ;
  int qp;
} cell_rule;

/* The reference gradients dN (nn x 3, node-major, as fcm_element_eval_grad() gives them) of one
 * point as the rows of a cell_rule's dT: dT[k na + a] = dN[3 a + k], zero for a >= nn. */
static inline void fcm__kernel_rows(int nn, const double *dN, double *dT)
{
  const int na = fcm__kernel_na(nn);
  for (int k = 0; k < 3; k++)
    for (int a = 0; a < na; a++)
      dT[k * na + a] = a < nn ? dN[3 * a + k] : 0.0;
}

/* What a kernel computes for one cell. */
typedef enum kernel_kind {
  KERNEL_STIFFNESS,    /* linear elastic K */
  KERNEL_MASS,         /* consistent mass */
  KERNEL_BODY_FORCE,   /* rho * accel, or a force density field */
  KERNEL_HYPERELASTIC, /* energy, internal force and tangent at a displacement */
  KERNEL_COROT_LINEAR  /* the same of the element-corotated linear model (corot.c) */
} kernel_kind;

typedef struct kernel_data {
  kernel_kind kind;
  double lambda, mu, rho;
  double accel[3];
  fcm_field_fn field; /* body force density b(X) (per volume), replaces rho*accel */
  void *field_user;
  const fcm_material_params *mat;
  const double *u; /* displacement per DOF */
  int want_force, want_tangent;
  fcm_fictitious_model fictitious; /* model at fictitious points (hyperelastic) */
  fcm_material_params mat_psd;     /* *mat with project_psd = 1 */
  /* KERNEL_COROT_LINEAR: the elements' linear stiffness matrices (upper node blocks, cb
   * doubles each) and mean shape function gradients (3 nn each), element e's at its slot
   * corot_slot[e] of the store */
  const double *corot_K;
  size_t corot_cb;
  const double *corot_G;
  const fcm_index *corot_slot;
  int corot_exact; /* the tangent: 1 the energy's exact Hessian, 0 the warped R K R^T */
} kernel_data;

/* Per-thread scratch of a kernel; ld = fcm__kernel_ld(nn) (the padded row length of the
 * blocked products). */
typedef struct scratch {
  double *X;   /* nn x 3 nodal coordinates */
  double *ue;  /* 3nn cell displacement */
  double *g;   /* nn x 3 physical gradients (node-major); a point's reference gradients while a
                * cut cell's rule is evaluated (assemble.c) */
  double *XT;  /* 3 x na: X by component, zero padded */
  double *UT;  /* 3 x na: ue by component, zero padded */
  double *FT;  /* 3 x na: the hyperelastic internal force by component */
  double *H;   /* ld x ld: the blocked products' sums */
  double *Ke;  /* the element matrix: 9 nn (nn + 1) / 2 upper node blocks (fcm__cell_kernel()) */
  double *fe;  /* 3nn */
  double *Nb;  /* max_cut_points x nn */
  double *dTb; /* max_cut_points x 3 x na: a cut cell's reference gradients by component */
  double *G;   /* QB x ld: gradients by component (or shape values) of a chunk of points */
  double *WG;  /* QB x ld: the same times w det J (3 QH x ld for the hyperelastic kernel) */
  double *wd;  /* QB: w det J of the chunk's points */
  double *B;   /* 3 x 3 QH x ld: the hyperelastic tangent's right factors of a chunk */
} scratch;

/* Outcome of a cell kernel. */
typedef struct cell_result {
  double energy;
  double bad_det; /* 1 when every det J > 0, else the first offending value */
  int nonfinite;  /* the material returned NaN/Inf */
  int inverted;   /* hyperelastic: authentic points with det F <= 0 */
} cell_result;

/* Padded row length of the blocked products for nn nodes: 3 na rounded up to 16. */
static inline int fcm__kernel_ld(int nn)
{
  return (3 * fcm__kernel_na(nn) + 15) / 16 * 16;
}

/* Doubles of one thread's scratch for nn nodes and mq cut-cell points; fcm__kernel_scratch_init()
 * lays it out from mem. */
size_t fcm__kernel_scratch_size(int nn, size_t mq);
void fcm__kernel_scratch_init(int nn, size_t mq, double *mem, scratch *w);

/* Element matrix w->Ke and/or vector w->fe (3nn) of one cell with the nodal coordinates w->X
 * (and displacement w->ue): the kernel of the integrand. The element matrices are symmetric:
 * w->Ke holds their upper node blocks, block (a, b) for a <= b (row-major 3 x 3, entry [3i + j]
 * = K_(a,i)(b,j)) at 9 (a nn - a (a - 1) / 2 + b - a), in the order of a, then b
 * (fcm__kernel_unpack() spreads them into the full matrix); the diagonal blocks are exactly
 * symmetric (fcm__kernel_symmetrize()). fe is zero after a matrix kernel.
 * Built for several instruction sets, selected at run time. */
cell_result fcm__cell_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w);

/* The element-corotated linear kernel (corot.c): energy, force w->fe (when kd->want_force) and
 * tangent w->Ke (upper node blocks, when kd->want_tangent) of the element with the nodal
 * coordinates w->X and displacement w->ue, its linear stiffness Kp (upper node blocks) and
 * the mean physical gradients gbar (nn x 3) of its shape functions over its material. */
cell_result fcm__corot_kernel(const kernel_data *kd, const double *Kp, const double *gbar, int nn,
                              scratch *w);

/* Make the diagonal node blocks (a, a) of the upper node blocks Kp exactly symmetric: each pair
 * of entries (i, j), (j, i) becomes their mean. The kernels compute K_(a,i)(a,j) and
 * K_(a,j)(a,i) apart: the compiler fuses different products of the two (kernels.c is built with
 * -ffp-contract=fast), and the hyperelastic and corotated kernels sum them in different orders,
 * so the two can differ in the last bits; a symmetric matrix's values must not, since solvers
 * read one triangle or both. */
void fcm__kernel_symmetrize(int nn, double *Kp);

/* The full element matrix Ke (3nn x 3nn, row-major) from its upper node blocks Kp. */
void fcm__kernel_unpack(int nn, const double *Kp, double *Ke);

/* Physical gradients g (nn x 3, node-major) at one point from the nodal coordinates X and the
 * point's rows dT of a cell_rule; returns det J (not positive: g is not written). */
double fcm__kernel_point_gradients(int nn, const double *X, const double *dT, double *g);

#endif /* FCM_FEM_KERNELS_IMPL_H */
