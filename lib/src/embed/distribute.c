/* Distributed cut-cell rules: the classes of the cells other processes classify, handed
 * over by an exchange, and the geometry cropped to a process's cells. */
#include "embed/rules_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The remote cells' class, fraction and volume from the exchange (x) into R and out; *exchanged
 * is set once the exchange ran (whatever its outcome). */
fcm_status fcm__embed_exchange_classes(const build *B, fcm_cell_rules *R,
                                       const fcm__rules_exchange *x, cell_out *out, cell_sums *sums,
                                       int *exchanged)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index nc = R->num_cells;
  double *volume = fcm__calloc(ctx, (size_t)nc + 1, sizeof *volume);
  st = volume ? FCM_OK : FCM_ERR_ALLOC;
  if (st != FCM_OK) fcm__error(ctx, st, __FILE__, __LINE__, __func__, "embed: out of memory");
  for (fcm_index c = 0; volume && c < nc; c++)
    if (!x->remote[c]) volume[c] = out[c].volume;
  *exchanged = 1;
  st = x->exchange(x->user, st, st == FCM_OK ? R->cls : NULL, st == FCM_OK ? R->fraction : NULL,
                   st == FCM_OK ? volume : NULL, st == FCM_OK ? &sums->counts : NULL);
  FCM_TRY(ctx, st);
  for (fcm_index c = 0; c < nc; c++) {
    if (!x->remote[c]) continue;
    const int cls = R->cls[c];
    const double phi = R->fraction[c], v = volume[c];
    FCM_CHECK((cls == FCM_CELL_UNCUT || cls == FCM_CELL_CUT || cls == FCM_CELL_DROPPED) &&
                  phi >= 0.0 && phi <= 1.0 && v >= 0.0 && isfinite(v),
              ctx, FCM_ERR_INTERNAL,
              "embed: the classification handed over for cell %lld is invalid (class %d, "
              "fraction %g, volume %g)",
              (long long)c, cls, phi, v);
    /* as process_cell() leaves an unflagged cell: at most one piece (no cuts), no points */
    out[c].volume = v;
    FCM_TRY(ctx, fcm__embed_cell_out_pieces(ctx, out + c, cls == FCM_CELL_DROPPED ? 0 : 1));
    if (out[c].np == 1) {
      out[c].pc[0].volume = v;
      out[c].pc[0].parent = 0;
    }
  }
cleanup:
  fcm__free(ctx, volume);
  return st;
}

fcm_status fcm__embed_crop_geometry(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                    const fcm_cell_rules_options *opts,
                                    const unsigned char *classify, const unsigned char *surface,
                                    fcm_geometry **out)
{
  fcm_status st = FCM_OK;
  const fcm_aabb_tree *tree = NULL, *tri_tree = NULL; /* the geometry's own */
  unsigned char *keep_cell = NULL, *keep_tri = NULL;
  fcm__idbuf ids = {NULL, 0, 0};
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "embed crop: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(ctx && mesh && geom && opts && classify, ctx, FCM_ERR_ARG,
            "embed crop: NULL argument (ctx, mesh, geometry, options, classify)");
  FCM_TRY(ctx, fcm__embed_check_options(ctx, opts, 1));
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  FCM_TRY(ctx, fcm__geom_tree(ctx, geom, 0, &tree));
  FCM_TRY(ctx, fcm__geom_tree(ctx, geom, 1, &tri_tree));
  FCM_ALLOC(ctx, (size_t)geom->num_cells + 1, keep_cell);
  FCM_ALLOC(ctx, (size_t)geom->num_tris + 1, keep_tri);
  /* the surface path reads lines through the whole body: it needs every boundary triangle */
  if (opts->moments != FCM_CELL_MOMENTS_VOLUME && opts->simplify != FCM_CELL_SIMPLIFY_OFF)
    memset(keep_tri, 1, (size_t)geom->num_tris);
  for (fcm_index c = 0; c < nc; c++) {
    const int cls = classify[c] != 0, srf = surface && surface[c] && opts->surface_strength >= 0;
    if (!cls && !srf) continue;
    fcm__embed_cell cell; /* the box the kernels query: the corners' widened by cell.tol */
    FCM_TRY(ctx, fcm__embed_check_convex(ctx, mesh, c, opts));
    FCM_TRY(ctx, fcm__embed_cell_setup(ctx, mesh, c, opts->clip_rtol, &cell));
    if (cls) {
      FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, cell.lo, cell.hi, &ids));
      for (size_t k = 0; k < ids.n; k++)
        keep_cell[ids.ids[k]] = 1;
    }
    if (srf) {
      FCM_TRY(ctx, fcm__geom_tree_query(ctx, tri_tree, cell.lo, cell.hi, &ids));
      for (size_t k = 0; k < ids.n; k++)
        keep_tri[ids.ids[k]] = 1;
    }
  }
  FCM_TRY(ctx, fcm__geom_create_subset(ctx, geom, keep_cell, keep_tri, out));
  /* the whole geometry's volume beyond each side of the mesh box (fcm__embed_outside()) */
  fcm_geometry *g = *out;
  fcm_mesh_bounding_box(mesh, g->outside_mesh_lo, g->outside_mesh_hi);
  FCM_TRY(ctx, fcm__embed_outside_sides(ctx, g->outside_mesh_lo, g->outside_mesh_hi, geom,
                                        g->outside_side));
  g->has_outside = 1;
cleanup:
  if (st != FCM_OK) fcm_geometry_destroy(out);
  fcm__free(ctx, keep_cell);
  fcm__free(ctx, keep_tri);
  fcm__geom_idbuf_free(ctx, &ids);
  return st;
}
