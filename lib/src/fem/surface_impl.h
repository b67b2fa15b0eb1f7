/* fem module, private to the embedded surface's two files: surface.c builds the surface
 * (its points, their elements, the cut faces) and surface_split.c splits the boundary
 * triangles the cuts cross into the cut cells' parts, keeping what it found for the next
 * cut. The surface's struct is in fem_impl.h (fields.c writes the surface too). */
#ifndef FCM_FEM_SURFACE_IMPL_H
#define FCM_FEM_SURFACE_IMPL_H

#include "embed/embed_impl.h"
#include "fem/fem_impl.h"

/* The element of cell c integrating rules piece p; -1 when none does. */
static inline fcm_index fcm__surface_piece_element(const fcm_space *s, fcm_index c, fcm_index p)
{
  if (p < 0) return -1;
  for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++)
    if (s->elem_piece[e] == p) return e;
  return -1;
}

/* qsort() order of pairs of indices: by the first, then by the second. */
static inline int fcm__surface_cmp_pair(const void *a, const void *b)
{
  const fcm_index *x = a, *y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return (x[1] > y[1]) - (x[1] < y[1]);
}

/* The search tree of the mesh's cells (es->cell_tree), and a millionth of the mesh's size
 * (es->cell_pad): made once a surface. (surface.c) */
fcm_status fcm__surface_cell_tree(fcm_embedded_surface *es);

/* With cuts in the space's rules: the elements of the boundary vertices in cells of several
 * elements (es->elem), which boundary triangles are replaced by their parts (split, nbt flags
 * zeroed by the caller) and those parts, cell by cell: polygon k of *polys came from triangle
 * (*src)[k] and lies in cell (*pcell)[k] (*src and *pcell allocated here, set on success).
 * Leaves the rules' parts in es->finder (fcm__embed_finder_release() frees them) and keeps what
 * it found for the next call, whose rules may extend these. (surface_split.c) */
fcm_status fcm__surface_split(fcm_embedded_surface *es, unsigned char *split,
                              fcm__embed_polys *polys, fcm_index **src, fcm_index **pcell);

/* Forget what the last fcm__surface_split() kept. (surface_split.c) */
void fcm__surface_cache_clear(fcm_embedded_surface *es);

#endif /* FCM_FEM_SURFACE_IMPL_H */
