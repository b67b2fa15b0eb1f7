/* The face-link shortcut's "full part" flag (fmeta[F i + 4], fcm__embed_part_face_full()): a
 * part the body fills counts as full on a face only where it reaches 4 prism half-heights
 * (4e-6 of the cell size, its diagonal: 4e-6 sqrt 3 = 6.93e-6 in the unit cube) along the
 * face's normal, since a thinner full slab holds less material in the prism than the moment
 * test's threshold. In the unit Hex8 cell, full slabs z in [0, t]: for t = 1e-7 and 6.9e-6 the
 * polygon on the face z = 0 is not flagged, those on the faces x, y = 0, 1 are; for t = 7e-6
 * and 0.5 every polygon is; a part that is not full is never flagged. */
#include "embed/embed_impl.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

/* The flags of the polygons of slab z in [0, t] on the unit cell's faces: *bottom (the face
 * z = 0), *sides (how many of the four side faces are flagged), *nfp polygons. */
static void slab_flags(const fcm__embed_cell *cell, double t, int full, int *bottom, int *sides,
                       int *nfp)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, t};
  const fcm_index n[3] = {1, 1, 1};
  fcm_mesh *slab = NULL;
  double X[24];
  fcm__poly *q = calloc(1, sizeof *q);
  fcm__parts *P = calloc(1, sizeof *P);
  TEST_TRUE(q && P);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &slab));
  *bottom = -1, *sides = 0, *nfp = 0;
  if (!q || !P || !slab) goto done;
  fcm_mesh_cell_coords(slab, 0, X);
  fcm__geom_poly_from_cell(FCM_ELEMENT_HEX8, X, q);
  TEST_OK(ctx, fcm__embed_parts_put(ctx, P, 0, q, 1e-12, 0.0, 0));
  P->mat = (fcm__material *)cell; /* only tested for NULL here: no material is measured */
  P->mvol[0] = full ? -1.0 : 0.5 * t;
  TEST_OK(ctx, fcm__embed_face_polygons(ctx, cell, P));
  *nfp = (int)P->nfp;
  for (size_t i = 0; i < P->nfp; i++) {
    const int *meta = P->fmeta + FCM__EMBED_FMETA * i;
    const double *nrm = cell->planes[meta[0]].n;
    if (fabs(nrm[2]) > 0.5)
      *bottom = meta[4];
    else
      *sides += meta[4];
  }
  P->mat = NULL;
done:
  if (P) fcm__embed_parts_free(ctx, P);
  free(P);
  free(q);
  fcm_mesh_destroy(&slab);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {1, 1, 1};
  fcm_mesh *mesh = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  fcm__embed_cell cell;
  TEST_OK(ctx, fcm__embed_cell_setup(ctx, mesh, 0, 1e-12, &cell));
  const double t[4] = {1e-7, 6.9e-6, 7e-6, 0.5}, depth = 4e-6 * cell.size;
  for (int i = 0; i < 4; i++) {
    int bottom, sides, nfp;
    slab_flags(&cell, t[i], 1, &bottom, &sides, &nfp);
    if (getenv("FCM_TEST_VERBOSE"))
      printf("full slab t = %g: %d polygons, bottom flagged %d, sides flagged %d\n", t[i], nfp,
             bottom, sides);
    TEST_TRUE(nfp == 5);
    TEST_TRUE(bottom == (t[i] >= depth) && (bottom == (i >= 2)));
    TEST_TRUE(sides == 4);
    slab_flags(&cell, t[i], 0, &bottom, &sides, &nfp);
    TEST_TRUE(nfp == 5 && bottom == 0 && sides == 0);
  }
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
