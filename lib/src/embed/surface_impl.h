/* embed module, private to the files on a body given by its closed boundary alone: the body
 * and the scratch of its material tests (fcm__material, embed_impl.h), shared by its cells'
 * parts (surface_parts.c) and the cut faces that end at its surface (surface_faces.c). */
#ifndef FCM_EMBED_SURFACE_IMPL_H
#define FCM_EMBED_SURFACE_IMPL_H

#include "embed/embed_impl.h"

/* The area that counts as material on a face, relative to the cell size squared: far above the
 * surface moments' rounding. */
#define FCM__MATERIAL_FACE_AREA_RTOL 1e-9

struct fcm__material {
  const fcm_geometry *geom;
  const fcm_aabb_tree *tree; /* the boundary triangles' */
  fcm__moment_quad q0;       /* degree 0: volumes */
  fcm__idbuf buf;
  fcm__crossings cr;
  fcm__srule sr;
  double *tets, *vol;
  int cap;
  int *edges, *uf; /* fcm__embed_split_lumps(): the boundary's edges in a part, a union-find */
  fcm_index *kept; /* the boundary triangles reaching inside that part */
  double *rep;     /* per kept triangle: a point inside the part on it, its unit normal */
  size_t nkept;
  size_t ecap;
  fcm_status st; /* the first error of fcm__material_on_face() */
  /* fcm__material_face_inside(): polygon slots of FCM__POLY_MAX_VERTS vertices (fp, their
   * vertex counts fpn), the boundary's segments in the face's plane (seg, 6 each) */
  double *fp, *seg;
  int *fpn;
  size_t fcap, scap;
};

/* Tet (c, a, b, e) (12 doubles) as an affine Tet4 cell of cell id: node 0 at xi = 0. */
void fcm__material_tet_cell(const double *T, fcm_index id, fcm__embed_cell *k);

#endif /* FCM_EMBED_SURFACE_IMPL_H */
