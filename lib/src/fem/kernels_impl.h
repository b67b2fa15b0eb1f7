/* fem element kernels, internal part: what assemble.c hands the element kernels of kernels.c
 * (one cell's rule, the integrand, per-thread scratch) and what they return. */
#ifndef FCM_FEM_KERNELS_IMPL_H
#define FCM_FEM_KERNELS_IMPL_H

#include "fem/fem_impl.h"
#include "material/material_impl.h"

/* Points per chunk of the linear kernels (gradients of a chunk, then one blocked product) and
 * of the hyperelastic kernel (its tangent's right factor is 3 x 3 QH rows per chunk). */
enum { FCM__KERNEL_QB = 32, FCM__KERNEL_QH = 8 };

/* The points of one cell's rule with the shape functions evaluated there. */
typedef struct cell_rule {
  int nq;
  const double *w;           /* nq weights; det J_K(xi) still to be applied */
  const double *N;           /* nq x nn */
  const double *dN;          /* nq x nn x 3 reference gradients */
  const unsigned char *fict; /* nq flags (1: fictitious stabilization point), or NULL */
} cell_rule;

/* What a kernel computes for one cell. */
typedef enum kernel_kind {
  KERNEL_STIFFNESS,   /* linear elastic K */
  KERNEL_MASS,        /* consistent mass */
  KERNEL_BODY_FORCE,  /* rho * accel, or a force density field */
  KERNEL_HYPERELASTIC /* energy, internal force and tangent at a displacement */
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
} kernel_data;

/* Per-thread scratch of a kernel; ld = fcm__kernel_ld(nn) (the padded row length of the
 * blocked products). */
typedef struct scratch {
  double *X;   /* nn x 3 nodal coordinates */
  double *ue;  /* 3nn cell displacement */
  double *g;   /* nn x 3 physical gradients */
  double *H;   /* ld x ld: the blocked products' sums */
  double *Ke;  /* (3nn)^2 */
  double *fe;  /* 3nn */
  double *Nb;  /* max_cut_points x nn */
  double *dNb; /* max_cut_points x nn x 3 */
  double *G;   /* QB x ld: gradients (or shape values) of a chunk of points, zero padded */
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

/* Padded row length of the blocked products for nn nodes: 3 roundup(nn, 4) rounded up to 16. */
static inline int fcm__kernel_ld(int nn)
{
  return (3 * ((nn + 3) / 4 * 4) + 15) / 16 * 16;
}

/* Doubles of one thread's scratch for nn nodes and mq cut-cell points; fcm__kernel_scratch_init()
 * lays it out from mem. */
size_t fcm__kernel_scratch_size(int nn, size_t mq);
void fcm__kernel_scratch_init(int nn, size_t mq, double *mem, scratch *w);

/* Element matrix w->Ke (3nn x 3nn, row-major) and/or vector w->fe (3nn) of one cell with the
 * nodal coordinates w->X (and displacement w->ue): the kernel of the integrand. fe is zero
 * after a matrix kernel. Built for several instruction sets, selected at run time. */
cell_result fcm__cell_kernel(const kernel_data *kd, const cell_rule *r, int nn, scratch *w);

#endif /* FCM_FEM_KERNELS_IMPL_H */
