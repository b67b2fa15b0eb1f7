/* fem assembly, internal part: the assembly workspace's layout, shared by assemble.c and
 * the element-corotated model's store of element matrices (corot_store.c). */
#ifndef FCM_FEM_ASSEMBLE_IMPL_H
#define FCM_FEM_ASSEMBLE_IMPL_H

#include "fem/kernels_impl.h"

/* Shape values and reference gradients (by component, kernels_impl.h) of the element at the
 * standard rule's points. */
typedef struct tabulation {
  fcm_rule *rule;
  cell_rule r;
  double *N, *dT, *dQ;
} tabulation;

/* The element-corotated linear model's linear element stiffness matrices (upper node blocks,
 * cb doubles per element) and mean gradients, built on first use for the elements whose have[e] is
 * 0 and kept across assemblies (and across a cut, for the elements it leaves: corot_store.c). */
typedef struct corot_store {
  double *K;           /* cap x cb, or NULL: element e's at slot[e] */
  unsigned char *have; /* num_elems: K of element e is built */
  size_t cb;
  double lambda, mu; /* the Lame parameters K was built with */
  double *G;         /* cap x 3 nn: the elements' mean shape function gradients, by slot */
  fcm_index built;   /* element matrices built since the workspace's creation */
  /* num_elems: each element's slot in K and G (distinct, below cap). A cut's store keeps each
   * kept element's slot and gives the others free ones, so nothing moves */
  fcm_index *slot;
  fcm_index cap;
} corot_store;

/* Everything an assembly writes besides its outputs. The standard rule of each
 * integrand is tabulated on first use and kept; scratch and per-cell energies are
 * allocated at creation, so repeated assembly allocates nothing. */
struct fcm_assembly_workspace {
  fcm_ctx *ctx;
  const fcm_space *space;
  fcm_assembly_options opts;
  tabulation tab[2];   /* standard rules: [0] stiffness, [1] mass */
  int tabulated[2];    /* tab[i] is built */
  int nthreads;        /* threads the scratch serves (the context's count at creation) */
  double *mem;         /* per-thread element buffers */
  scratch *sc;         /* nthreads views into mem */
  double *cell_energy; /* num_elems: energy per element of the last hyperelastic assembly */
  int *cell_inverted;  /* num_elems: its authentic points with det F <= 0 per element */
  corot_store corot;   /* the element-corotated linear model's element matrices (corot_store.c) */
  int corot_warped; /* 1: that model's tangent is the warped one (fcm__assembly_corot_tangent()) */
};

/* The tabulated standard rule of `kind` (stiffness or mass), built on first use. */
fcm_status fcm__assembly_tabulation(fcm_assembly_workspace *ws, fcm_rule_kind kind,
                                    const tabulation **t);

/* The kernel kd (a linear one) of element e on its rule (t: the tabulated standard rule of
 * the kernel's integrand) into w->Ke / w->fe. */
cell_result fcm__assembly_element_kernel(const fcm_space *s, const tabulation *t,
                                         const kernel_data *kd, fcm_index e, scratch *w);

/* The mean physical gradients gbar (nn x 3, node-major) of element e's shape functions over
 * the authentic points of its stiffness rule (all its points when it has none): F averaged
 * over the element's material is I + sum_a u_a gbar_a^T. */
void fcm__assembly_mean_gradients(const fcm_space *s, const tabulation *t, fcm_index e, scratch *w,
                                  double *gbar);

/* Build the element-corotated model's missing element stiffness matrices for the Lame
 * parameters of mat (all of them when those differ from the kept ones) and point kd's
 * corot_* fields at the store. */
fcm_status fcm__assembly_corot_prepare(fcm_assembly_workspace *ws, const fcm_material_params *mat,
                                       kernel_data *kd);

void fcm__assembly_corot_free(fcm_assembly_workspace *ws);

#endif /* FCM_FEM_ASSEMBLE_IMPL_H */
