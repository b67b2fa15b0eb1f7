/* fcm-converge: what the study's source files share beyond the app's interface
 * fcm-converge-study.h: the study's state and the helpers one file defines for another.
 * fcm-converge-study.c holds the problems; fcm-converge-reference.c the reference solution
 * and point location in tets (it uses the problems); fcm-converge-run.c the study's
 * lifetime, one run and its errors (it uses both). */
#ifndef FCM_CONVERGE_STUDY_IMPL_H
#define FCM_CONVERGE_STUDY_IMPL_H

#include "fcm-converge-study.h"

#include <fcm/quad.h>

/* Tets (corner ids, stride `stride`) over `coords`, with an AABB tree of their boxes. */
typedef struct tet_index {
  const double *coords;
  const fcm_index *cells;
  int stride;
  fcm_index n;
  fcm_aabb_tree *tree;
  double tol; /* absolute box tolerance of point queries */
} tet_index;

struct cv_study {
  fcm_ctx *ctx;
  cv_setup s;
  double lambda, mu;
  fcm_geometry *geom;
  tet_index geo_tets; /* point-in-polyhedron for the staircase classification */
  /* curved boundary facets: vertices (9), unit normal (3), cone axis (3), cone cosine */
  fcm_index nfacets;
  double *facets;
  /* reference mode */
  fcm_mesh *ref_mesh;
  fcm_space *ref_space;
  double *ref_u;
  tet_index ref_tets;
  double ref_time;
};

/* The curved boundary facets of S->geom into S->facets (fcm-converge-study.c). */
fcm_status cv_build_facets(cv_study *S);

/* Ji = J^{-1}; returns det J. */
double cv_inv3(const double J[9], double Ji[9]);

/* Tets (corner ids, stride `stride`) over `coords`, with an AABB tree of their boxes. */
fcm_status cv_tet_index_create(fcm_ctx *ctx, const double *coords, const fcm_index *cells,
                               int stride, fcm_index n, tet_index *ti);

/* The tet containing x (closed, tolerance 1e-10 in barycentric coordinates), else the
 * candidate with the largest smallest coordinate, else -1. */
fcm_index cv_tet_locate(const tet_index *ti, const double x[3], double l[4]);

/* Assemble K u = f (stiffness, body force; embedded_traction 1: the exact traction on the
 * embedded boundary, 2: Nitsche terms; staircase_keep: the staircase traction), with the
 * y = 0 nodes eliminated. */
fcm_status cv_assemble_system(const cv_study *S, fcm_space *space, int embedded_traction,
                              const unsigned char *staircase_keep, fcm_csr **K, double **f);

/* Solve A u = b with CHOLMOD. */
fcm_status cv_direct_solve(fcm_ctx *ctx, fcm_csr *A, const double *b, double *u);

/* Build the reference solution into S (reference problem). */
fcm_status cv_reference_create(cv_study *S);

/* Reference displacement and gradient at x; returns 0 when x lies in no reference tet. */
int cv_reference_eval(const cv_study *S, const double x[3], double u[3], double G[9]);

#endif /* FCM_CONVERGE_STUDY_IMPL_H */
