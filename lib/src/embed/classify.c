/* The per-cell work of the cut-cell rules build: intersect each background cell with the
 * geometry, split it into material pieces where cuts reach it, classify it (uncut, cut,
 * dropped) and hand its cut pieces to the rule building; all cells in parallel. */
#include "embed/rules_impl.h"
#include "fcm/la.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static void piece_out_free(fcm_ctx *ctx, piece_out *o)
{
  for (int k = 0; k < FCM_RULE_KIND_COUNT && !o->borrowed; k++) {
    fcm__free(ctx, o->pts[k]);
    fcm__free(ctx, o->w[k]);
    fcm__free(ctx, o->flag[k]);
  }
  if (!o->borrowed) {
    fcm__free(ctx, o->spts);
    fcm__free(ctx, o->sw);
    fcm__free(ctx, o->snrm);
    fcm__free(ctx, o->stri);
  }
  if (!o->cf_borrowed) fcm__free(ctx, o->cfxi);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    o->pts[k] = o->w[k] = NULL;
    o->flag[k] = NULL;
  }
  o->spts = o->sw = o->snrm = o->cfxi = NULL;
  o->stri = NULL;
  o->borrowed = o->cf_borrowed = 0;
}

void fcm__embed_cell_out_free(fcm_ctx *ctx, cell_out *o)
{
  if (o->pc)
    for (int i = 0; i < o->np; i++)
      piece_out_free(ctx, o->pc + i);
  if (o->pc != &o->one) fcm__free(ctx, o->pc);
  o->pc = NULL;
  o->np = 0;
  fcm__free(ctx, o->fmeta);
  fcm__free(ctx, o->fx);
  o->fmeta = NULL;
  o->fx = NULL;
}

/* Room for np pieces in o (inline for one). */
fcm_status fcm__embed_cell_out_pieces(fcm_ctx *ctx, cell_out *o, int np)
{
  fcm_status st = FCM_OK;
  o->np = np;
  if (np <= 1) {
    o->pc = &o->one;
  } else {
    FCM_ALLOC(ctx, (size_t)np, o->pc);
  }
cleanup:
  return st;
}

/* The rules of cell c from the previous rules object (a cell no new cut reaches), borrowed: the
 * pieces' arrays point into it, read only (the gathering copies them once, from there), and
 * the pieces are marked copied (finished already, never finished again). */
static void copy_cell(const build *B, fcm_index c, cell_out *o)
{
  const fcm_cell_rules *Q = B->prev;
  const fcm_index p0 = Q->piece_off[c], np = Q->piece_off[c + 1] - p0;
  for (fcm_index i = 0; i < np; i++) {
    piece_out *po = o->pc + i;
    const fcm_index p = p0 + i;
    po->volume = Q->piece_volume[p];
    po->component = Q->piece_component[p];
    po->copied = 1;
    po->borrowed = po->cf_borrowed = 1;
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const size_t a = (size_t)Q->off[k][p], n = (size_t)Q->off[k][p + 1] - a;
      if (n) {
        po->pts[k] = Q->points[k] + 3 * a;
        po->w[k] = Q->weights[k] + a;
        po->flag[k] = Q->flags[k] + a;
      }
      po->n[k] = po->ninit[k] = po->nsimp[k] = (int)n;
    }
    const size_t a = (size_t)Q->soff[p], n = (size_t)Q->soff[p + 1] - a;
    if (n) {
      po->spts = Q->spoints + 3 * a;
      po->sw = Q->sweights + a;
      po->snrm = Q->snormals + 3 * a;
      po->stri = Q->stris + a;
    }
    po->ns = (int)n;
    const size_t c0 = (size_t)Q->cfoff[p], nc = (size_t)Q->cfoff[p + 1] - c0;
    if (nc) po->cfxi = Q->cfxi + 9 * c0;
    po->ncf = (int)nc;
  }
}

/* A dropped cell's share of the embedded surface into o->dropped_area: the area its surface
 * rule would have had (the same clipping, so that the kept and dropped cells' areas add up to
 * the surface's). Only when surface rules are built; the cell's own points are not kept. */
static fcm_status dropped_area(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                               cell_out *o)
{
  fcm_status st = FCM_OK;
  fcm__embed_counts none;
  memset(&none, 0, sizeof none);
  o->dropped_area = 0.0;
  if (!B->tri_rule) return FCM_OK;
  FCM_TRY(B->ctx, fcm__embed_cell_surface(B->ctx, B->geom, B->tri_tree, cell, NULL, 0,
                                          B->o->sliver_rtol, B->tri_rule, ws, &none));
  for (size_t j = 0; j < ws->num_spts; j++)
    o->dropped_area += ws->sw[j];
  ws->num_spts = 0;
cleanup:
  return st;
}

/* Keep cell c as the rules being extended have it (the new cut leaves it unchanged): its
 * class, fraction, pieces and rules bit for bit, cut faces included. */
static fcm_status keep_cell(const build *B, fcm_cell_rules *R, const fcm__embed_cell *cell,
                            cell_out *o)
{
  fcm_status st = FCM_OK;
  const fcm_cell_rules *Q = B->prev;
  const fcm_index c = cell->id;
  R->cls[c] = Q->cls[c];
  R->fraction[c] = Q->fraction[c];
  o->volume = Q->fraction[c] * cell->volume;
  FCM_TRY(B->ctx,
          fcm__embed_cell_out_pieces(B->ctx, o, (int)(Q->piece_off[c + 1] - Q->piece_off[c])));
  for (int i = 0; i < o->np; i++)
    o->pc[i].parent = i;
  copy_cell(B, c, o);
cleanup:
  return st;
}

/* Whether the new cut's triangles leave the material pieces of a cell they reach as the rules
 * being extended have them: as many pieces, every kept piece i made of parts of the earlier
 * piece i only (their component under the earlier cuts, P->parent, is that piece's) and no
 * part of an earlier piece left out (in no kept piece: a sliver the cut took off). Each piece
 * is then the earlier one's material whole, whatever the new triangles did inside it (divided
 * parts that stay together, a crack ending in the cell, a cut along its faces or through
 * empty space): its rules stay exact and are kept (its cut faces are made again). */
static int pieces_unchanged(const build *B, fcm_index c, const fcm__parts *P)
{
  const fcm_cell_rules *Q = B->prev;
  const fcm_index p0 = Q->piece_off[c], had = Q->piece_off[c + 1] - p0;
  if (P->num_pieces != had) return 0;
  for (size_t j = 0; j < P->n; j++) {
    const int i = P->piece[j];
    if (i >= 0 && Q->piece_component[p0 + i] != P->parent[j]) return 0;
    for (fcm_index q = 0; i < 0 && q < had; q++)
      if (Q->piece_component[p0 + q] == P->parent[j]) return 0;
  }
  return 1;
}

/* Renumber the labels (P->piece, *count of them) so that labels whose parts keep no more than
 * vmin of volume (all slivers, or flat on a cut) are removed: those parts get -1. vol gets the
 * volume of each remaining label and was[i] the label that remaining label i had. */
static fcm_status drop_empty(const build *B, fcm__embed_ws *ws, double vmin, int *label, int *count,
                             double *vol, int *was, cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  fcm__parts *P = ws->parts;
  int kept = 0, *renum = NULL;
  FCM_ALLOC(ctx, (size_t)*count + 1, renum);
  for (int i = 0; i < *count; i++) {
    double v = 0.0;
    for (size_t j = 0; P->mat && j < P->n; j++) /* a surface body: its material in the parts */
      v += label[j] == i ? P->mvol[j] : 0.0;
    if (!P->mat)
      FCM_TRY(ctx, fcm__embed_piece_tets(ctx, P, label, i, ws, sums ? &sums->counts : NULL, &v));
    renum[i] = v > vmin ? kept : -1;
    if (v > vmin) vol[kept] = v, was[kept++] = i;
  }
  for (size_t j = 0; j < P->n; j++)
    label[j] = label[j] >= 0 ? renum[label[j]] : -1;
  *count = kept;
cleanup:
  fcm__free(ctx, renum);
  return st;
}

/* *m = max(*m, v), a NaN kept (undetermined). */
static void keep_largest(double *m, double v)
{
  if (isnan(v) || v > *m) *m = v;
}

/* The convex parts and material pieces of a cell that cuts reach (or that lies next to
 * such a cell): parts, split, grouped; empty pieces (all slivers) are removed. On return
 * P->piece numbers the pieces with volume, -1 for parts of removed ones; vol[i] is the
 * volume of piece i (P->num_pieces of them) and comp[i] its number among all the
 * components; P->parent numbers the components under the earlier cuts only, empty ones
 * included (the numbering of the pieces of the rules being extended, before their empty
 * components were dropped: a component can lose its last volume to the new cut). */
static fcm_status cell_pieces(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                              cell_sums *sums, double **vol, int **comp)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  fcm__parts *P = ws->parts;
  double *known = B->cell_mvol ? B->cell_mvol + cell->id : NULL; /* one writer per cell */
  FCM_TRY(ctx, fcm__embed_cell_parts(ctx, B->geom, B->tree, cell, opt->clip_rtol, opt->sliver_rtol,
                                     ws, P, known, &sums->counts));
  FCM_TRY(ctx, fcm__embed_cut_candidates(ctx, B->cut_tree, cell, &P->tcand));
  if (P->tcand.n > 0) {
    FCM_TRY(ctx, fcm__embed_cell_pieces(ctx, cell, B->cut_tris, B->first_new, P));
    sums->counts.degenerate += !(P->split_error <= DEGENERATE_RTOL * cell->volume);
    keep_largest(&sums->counts.split_change, P->split_error / cell->volume);
  }
  FCM_ALLOC(ctx, (size_t)P->num_pieces + 1, *vol);
  if (B->prev) {
    /* a piece in an earlier piece that the build that made it removed (no more than a sliver)
     * holds no more volume than that one, up to rounding at the threshold: removed too, so
     * that every kept piece lies in a kept earlier one */
    const fcm_index p0 = B->prev->piece_off[cell->id], had = B->prev->piece_off[cell->id + 1] - p0;
    for (size_t j = 0; j < P->n; j++) {
      int found = 0;
      for (fcm_index q = 0; q < had && !found; q++)
        found = B->prev->piece_component[p0 + q] == P->parent[j];
      if (!found) P->piece[j] = -1;
    }
  }
  /* a piece is kept when it holds more than a sliver of the cell (a piece flat on a cut
   * carries no material and would tie the nodes of both sides together) */
  FCM_ALLOC(ctx, (size_t)P->num_pieces + 1, *comp);
  FCM_TRY(ctx, drop_empty(B, ws, opt->sliver_rtol * cell->volume, P->piece, &P->num_pieces, *vol,
                          *comp, sums));
cleanup:
  return st;
}

/* The piece of the rules being extended that holds each piece of o (its own index without
 * them), and each piece's component number (pcomp; 0 without pieces). */
static fcm_status piece_parents(const build *B, fcm_index c, const fcm__parts *P, const int *pcomp,
                                int integrate, cell_out *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  for (int i = 0; i < o->np; i++) {
    o->pc[i].parent = i;
    o->pc[i].component = P ? pcomp[i] : 0;
    if (P && B->prev && integrate) {
      /* the component under the earlier cuts of the piece's first part, and the earlier
       * piece numbered so (not its rank among the components that keep volume now) */
      const fcm_index p0 = B->prev->piece_off[c], had = B->prev->piece_off[c + 1] - p0;
      size_t j = 0;
      while (j < P->n && P->piece[j] != i)
        j++;
      const int comp = j < P->n ? P->parent[j] : -1;
      o->pc[i].parent = -1;
      for (fcm_index q = 0; q < had && comp >= 0; q++)
        if (B->prev->piece_component[p0 + q] == comp) o->pc[i].parent = (int)q;
      FCM_CHECK(o->pc[i].parent >= 0, ctx, FCM_ERR_INTERNAL,
                "embed: piece %d of cell %lld lies in no piece of the rules being extended (%lld "
                "pieces there)",
                i, (long long)c, (long long)had);
    }
  }
cleanup:
  return st;
}

/* The triangles of each piece of o on the cuts (its sides of them), in reference
 * coordinates. */
static fcm_status piece_cut_faces(const build *B, const fcm__embed_cell *cell, fcm__parts *P,
                                  cell_out *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  for (int i = 0; i < o->np; i++) {
    double *phys = NULL;
    int nt = 0;
    FCM_TRY(ctx, fcm__embed_cut_faces(ctx, cell, B->cut_tris, P, i, &phys, &nt));
    o->pc[i].cfxi = phys;
    o->pc[i].ncf = nt;
    for (int k = 0; k < 3 * nt; k++) {
      double xi[3], det;
      FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, phys + 3 * k, xi, &det));
      memcpy(phys + 3 * k, xi, sizeof xi);
    }
  }
cleanup:
  return st;
}

/* A region cell after its pieces (P) were made: kept (*kept = 1) when the new cut does not reach
 * it (its face polygons were wanted for the links only) or reaches it without changing its
 * pieces (pieces_unchanged(); its cut faces are then made again). */
static fcm_status keep_region_cell(const build *B, fcm_cell_rules *R, const fcm__embed_cell *cell,
                                   fcm__parts *P, int integrate, cell_out *o, int *kept)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index c = cell->id;
  const fcm_index had = B->prev ? B->prev->piece_off[c + 1] - B->prev->piece_off[c] : 0;
  *kept = 0;
  FCM_CHECK(integrate || had == 0 || had == P->num_pieces, ctx, FCM_ERR_INTERNAL,
            "embed: cell %lld, which the new cut does not reach, now has %d pieces instead of "
            "%lld",
            (long long)c, P->num_pieces, (long long)had);
  if (integrate && !(B->prev && B->keep && pieces_unchanged(B, c, P))) return FCM_OK;
  /* finished already: AUTO skips these pieces (copied) */
  FCM_TRY(ctx, keep_cell(B, R, cell, o));
  for (int i = 0; integrate && i < o->np; i++) {
    if (!o->pc[i].cf_borrowed) fcm__free(ctx, o->pc[i].cfxi);
    o->pc[i].cfxi = NULL;
    o->pc[i].ncf = 0;
    o->pc[i].cf_borrowed = 0;
  }
  if (integrate && P->tcand.n > 0) FCM_TRY(ctx, piece_cut_faces(B, cell, P, o));
  *kept = 1;
cleanup:
  return st;
}

/* The surface moments' rounding is about 1e-15 |K| whatever the material's size: a cell whose
 * surface-moment volume is below this fraction of its own takes the volume path (when the
 * geometry has cells), whose accuracy follows the material's size. */
#define SURFACE_MIN_FRACTION 1e-9

/* FCM_CELL_MOMENTS_AUTO takes the surface path for a cell when the tets of the volume mesh
 * that may meet it carry more initial points, summed over the kinds, than both 20 M
 * (the volume path then costs more than the surface path's few M candidates, and its rules
 * more to simplify) and 0.05 M^3 (the surface fit's SVD and LP grow like M^3: measured on one
 * core, 70 ms a cell at M = 165 against 0.3 us an initial point of the volume path), M and
 * M^3 summed over the kinds too. */
static int surface_pays(const build *B, size_t candidates)
{
  double points = 0.0, M = 0.0, M3 = 0.0;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) { /* built or not: a kind's rules do not
                                                      depend on the other kind's */
    const double m = B->fit_M[k];
    points += (double)candidates * B->fit_tet_points[k];
    M += m, M3 += m * m * m;
  }
  return points > 20.0 * M && points > 0.05 * M3;
}

/* Without a volume mesh: a cell with less material than this (rounding) holds none. */
#define SURFACE_EMPTY_FRACTION 1e-13

/* A cut cell on the surface path: its one piece fitted on the surface moments, or, when the
 * fit fails, built by the volume path (FCM_CELL_MOMENTS_AUTO) or refused (SURFACE). The volume
 * path starts from the volume mesh's tets in the cell, or without one from the cell split by
 * the body's boundary triangles into parts wholly inside or outside the body (as a cut piece
 * whose fit fails). */
static fcm_status surface_rules(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                                const double box[6], cell_out *o, cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  int ok;
  double vol;
  char why[256] = "";
  FCM_TRY(ctx,
          fcm__embed_surface_piece_fit(B, cell, ws, box, o->volume, o->pc, &ok, why, sizeof why));
  sums->counts.surface_cells++;
  if (ok) goto cleanup;
  sums->counts.surface_fallbacks++;
  FCM_CHECK(B->o->moments != FCM_CELL_MOMENTS_SURFACE, ctx, FCM_ERR_NUMERIC,
            "embed: background cell %lld: no positive rule of at most M points on candidates "
            "inside the material carries its surface moments (volume fraction %.3g; %s); "
            "moments = auto would fall back to the volume path",
            (long long)cell->id, o->volume / cell->volume, why);
  if (B->geom->num_cells > 0) {
    FCM_TRY(ctx, fcm__embed_cell_tets(ctx, B->geom, B->tree, cell, B->o->clip_rtol,
                                      B->o->sliver_rtol, ws, &sums->counts, &vol));
  } else {
    double mvol = o->volume; /* the surface moments' */
    if (!ws->parts) FCM_ALLOC(ctx, 1, ws->parts);
    FCM_TRY(ctx, fcm__embed_cell_parts(ctx, B->geom, B->tree, cell, B->o->clip_rtol,
                                       B->o->sliver_rtol, ws, ws->parts, &mvol, NULL));
    ws->num_tets = 0;
    if (ws->parts->n > 0)
      FCM_TRY(ctx, fcm__embed_piece_body_tets(ctx, cell, ws->parts, 0, ws, &vol));
  }
  FCM_CHECK(ws->num_tets > 0, ctx, FCM_ERR_NUMERIC,
            "embed: background cell %lld: the fit on its surface moments failed (%s) and the "
            "volume path finds no material in it (volume fraction %.3g by the surface)",
            (long long)cell->id, why, o->volume / cell->volume);
  FCM_TRY(ctx, fcm__embed_map_piece(B, cell, ws, o->pc));
cleanup:
  return st;
}

/* Cell c of process_cell() whose rules are copied from the rules being extended, with its face
 * polygons where kept_faces (a region cell the new cut does not reach); own: as there. No clock
 * is read: a copied cell's time is not counted. */
static fcm_status copy_prev_cell(const build *B, fcm_cell_rules *R, fcm_index c, int own,
                                 int kept_faces, fcm__embed_ws *ws, cell_out *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  fcm__embed_cell cell;
  double *known = R->cell_volume ? R->cell_volume + c : NULL; /* one writer per cell */
  /* a cell whose rules are copied needs its volume only (kept from an earlier cut), but a
   * dropped one its surface share where surface rules are built */
  if (own && B->prev->cls[c] == FCM_CELL_DROPPED && B->tri_rule) {
    FCM_TRY(ctx, fcm__embed_cell_setup(ctx, B->mesh, c, opt->clip_rtol, &cell));
  } else if (known && !isnan(*known)) {
    cell.id = c;
    cell.volume = *known;
  } else {
    FCM_TRY(ctx, fcm__embed_cell_setup_volume(ctx, B->mesh, c, opt->clip_rtol, &cell));
  }
  if (known) *known = cell.volume;
  FCM_TRY(ctx, keep_cell(B, R, &cell, o));
  if (kept_faces)
    FCM_TRY(ctx, fcm__embed_copy_face_polygons(ctx, B->prev, c, &o->fmeta, &o->fx, &o->nfp));
  o->fp_keep = (unsigned char)kept_faces;
  if (own && R->cls[c] == FCM_CELL_DROPPED) FCM_TRY(ctx, dropped_area(B, &cell, ws, o));
cleanup:
  return st;
}

/* Whether cell c, which the new cut does not reach, is copied from the rules extended: it
 * needs no work outside the region, where its links with every region neighbour are kept, or
 * where it has no pieces (the links skip such a cell: its face polygons would be read by no cut
 * until one reaches it and makes them again); *kept_faces: a region cell with the face
 * polygons the earlier cut kept. */
static int copied_cell(const build *B, fcm_index c, int *kept_faces)
{
  const int no_work = !B->region[c] || (B->same_links && B->same_links[c]) ||
                      (B->keep && B->prev && B->prev->piece_off[c + 1] == B->prev->piece_off[c]);
  *kept_faces = !no_work && B->keep && B->prev->face_nfp && B->prev->face_nfp[c] >= 0;
  return no_work || *kept_faces;
}

/* Intersect, classify and build the rules of background cell c into o (the thread's own
 * buffers); R->cls[c] and R->fraction[c] are written here (one writer per cell). Cells the
 * cuts reach are split into material pieces first; each piece then takes the
 * path of a cut cell. */
static fcm_status process_cell(const build *B, fcm_cell_rules *R, fcm_index c, fcm__embed_ws *ws,
                               cell_out *o, cell_sums *sums)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_cell_rules_options *opt = B->o;
  fcm__embed_cell cell;
  double vol = 0.0, *pvol = NULL;
  int *pcomp = NULL;
  fcm__parts *P = NULL;
  const int integrate = !B->rebuild || B->rebuild[c];
  const int own = !opt->cell_mask || opt->cell_mask[c]; /* 0: classified, no points */
  double sbox[6];
  int kept_faces = 0;
  if (!integrate && copied_cell(B, c, &kept_faces))
    return copy_prev_cell(B, R, c, own, kept_faces, ws, o);
  const double t0 = fcm_wtime();
  FCM_TRY(ctx, fcm__embed_cell_setup(ctx, B->mesh, c, opt->clip_rtol, &cell));
  if (R->cell_volume) R->cell_volume[c] = cell.volume;
  if (B->prev) FCM_TRY(ctx, fcm__embed_check_convex(ctx, B->mesh, c, opt));
  int surface = B->surface && cell.affine && !(B->cut_tree && B->region[c]);
  if (surface && opt->moments == FCM_CELL_MOMENTS_AUTO && B->geom->num_cells > 0) {
    /* auto: the surface path where the volume path would start from many points */
    FCM_TRY(ctx, fcm__geom_tree_query(ctx, B->tree, cell.lo, cell.hi, &ws->cand));
    surface = surface_pays(B, ws->cand.n);
  }
  if (B->cut_tree && B->region[c]) {
    if (!ws->parts) FCM_ALLOC(ctx, 1, ws->parts);
    P = ws->parts;
    FCM_TRY(ctx, cell_pieces(B, &cell, ws, sums, &pvol, &pcomp));
    for (int i = 0; i < P->num_pieces; i++)
      vol += pvol[i];
    FCM_TRY(ctx, fcm__embed_face_polygons(ctx, &cell, P));
    if (P->nfp > 0) {
      FCM_ALLOC(ctx, FCM__EMBED_FMETA * P->nfp, o->fmeta);
      FCM_ALLOC(ctx, 3 * P->nfx, o->fx);
      memcpy(o->fmeta, P->fmeta, FCM__EMBED_FMETA * P->nfp * sizeof(int));
      memcpy(o->fx, P->fx, 3 * P->nfx * sizeof(double));
      o->nfp = (int)P->nfp;
    }
    int kept;
    FCM_TRY(ctx, keep_region_cell(B, R, &cell, P, integrate, o, &kept));
    o->fp_keep = (unsigned char)(kept && !integrate); /* parts split in one pass */
    if (kept) {
      if (own && R->cls[c] == FCM_CELL_DROPPED) FCM_TRY(ctx, dropped_area(B, &cell, ws, o));
      sums->counts.kept += integrate;
      sums->time_intersect += fcm_wtime() - t0;
      goto cleanup;
    }
  } else if (surface) {
    FCM_TRY(ctx, fcm__embed_surface_volume(B, &cell, ws, &vol, sbox));
    surface = !(vol < SURFACE_MIN_FRACTION * cell.volume) || B->geom->num_cells == 0;
    if (vol < SURFACE_EMPTY_FRACTION * cell.volume) vol = 0.0;
  }
  if (!surface && !P) {
    FCM_TRY(ctx, fcm__embed_cell_tets(ctx, B->geom, B->tree, &cell, opt->clip_rtol,
                                      opt->sliver_rtol, ws, &sums->counts, &vol));
  }
  const int np = P ? P->num_pieces : surface ? vol > 0.0 : ws->num_tets > 0;
  /* |K ∩ Ω| <= |K|: the clipped volumes can sum to |K| (1 + 1e-12) through rounding. A cut
   * cell has phi < uncut_fraction <= 1, so its rule needs no rescaling; only the recorded
   * fraction and volume are clamped. A cell split into several pieces is cut whatever its
   * fraction. */
  const double phi = fmin(vol / cell.volume, 1.0);
  fcm_cell_class cls = FCM_CELL_CUT;
  if (phi < opt->min_fraction || np == 0)
    cls = FCM_CELL_DROPPED;
  else if (phi >= opt->uncut_fraction && np == 1)
    cls = FCM_CELL_UNCUT;
  R->cls[c] = (unsigned char)cls;
  R->fraction[c] = phi;
  o->volume = phi * cell.volume;
  FCM_TRY(ctx, fcm__embed_cell_out_pieces(ctx, o, cls == FCM_CELL_DROPPED ? 0 : np));
  if (o->np == 1) o->pc[0].volume = o->volume;
  FCM_TRY(ctx, piece_parents(B, c, P, pcomp, integrate, o));
  for (int i = 0; P && i < o->np && o->np > 1; i++)
    o->pc[i].volume = pvol[i];
  /* the pieces' sides of the cuts: on every cell, masked or not (the space's DOF copies
   * depend on them: a cut along cell faces separates cells without splitting any) */
  if (P && P->tcand.n > 0 && cls != FCM_CELL_DROPPED) FCM_TRY(ctx, piece_cut_faces(B, &cell, P, o));
  if (!own) { /* classification, piece volumes and cut faces only (cell_mask) */
    sums->time_intersect += fcm_wtime() - t0;
    goto cleanup;
  }
  if (cls == FCM_CELL_DROPPED) FCM_TRY(ctx, dropped_area(B, &cell, ws, o));
  if (cls == FCM_CELL_CUT && surface) FCM_TRY(ctx, surface_rules(B, &cell, ws, sbox, o, sums));
  if (cls == FCM_CELL_CUT && !surface) {
    for (int i = 0; i < o->np; i++) {
      double v;
      if (P && P->mat) {
        int fell;
        FCM_TRY(ctx, fcm__embed_surface_cut_piece(B, &cell, ws, P, i, o->pc + i, &fell));
        sums->counts.surface_cells++;
        sums->counts.surface_fallbacks += fell;
        continue;
      }
      if (P) FCM_TRY(ctx, fcm__embed_piece_tets(ctx, P, P->piece, i, ws, NULL, &v));
      FCM_TRY(ctx, fcm__embed_map_piece(B, &cell, ws, o->pc + i));
    }
  }
  if (B->tri_rule && cls != FCM_CELL_DROPPED) {
    for (int i = 0; i < o->np; i++) { /* split cells: each piece its exact share */
      if (i == 0 || o->np > 1)
        FCM_TRY(ctx, fcm__embed_cell_surface(ctx, B->geom, B->tri_tree, &cell, o->np > 1 ? P : NULL,
                                             i, opt->sliver_rtol, B->tri_rule, ws, &sums->counts));
      FCM_TRY(ctx, fcm__embed_surface_piece(B, &cell, ws, o->pc + i));
    }
  }
  sums->time_intersect += fcm_wtime() - t0;
  if (cls == FCM_CELL_CUT && opt->simplify != FCM_CELL_SIMPLIFY_AUTO) {
    const int on = opt->simplify == FCM_CELL_SIMPLIFY_ON;
    const int simp[FCM_RULE_KIND_COUNT] = {on, on};
    for (int i = 0; i < o->np; i++)
      FCM_TRY(ctx, fcm__embed_finish_cell(B, o->pc + i, simp, sums));
  }
cleanup:
  fcm__free(ctx, pvol);
  fcm__free(ctx, pcomp);
  return st;
}

/* One cell of fcm__embed_run_cells() on the calling thread (its workspace *ws made by its
 * first cell), with the progress report. */
static void run_cell(const build *B, fcm_cell_rules *R, fcm_index c, fcm__embed_ws **ws,
                     cell_out *out, cell_sums *mine, fcm__loop *loop,
                     const fcm_cell_rules_options *opt, fcm_index *done, double *last)
{
  fcm_ctx *ctx = B->ctx;
  const fcm_index nc = R->num_cells;
  memset(out + c, 0, sizeof *out); /* first touched here, by the thread that builds it */
  if (fcm__loop_skip(loop, c)) return;
  fcm__loop_iter it;
  fcm__loop_enter(loop, &it, c);
  fcm_status s = FCM_OK;
  if (!*ws) { /* the thread's workspace, made by its first cell */
    *ws = fcm__calloc(ctx, 1, sizeof **ws);
    if (!*ws) s = FCM_ERR_ALLOC;
  }
  const int remote = B->remote && B->remote[c]; /* classified by another process */
  if (s == FCM_OK && !remote) s = process_cell(B, R, c, *ws, out + c, mine);
  fcm__loop_leave(loop, &it, s);
  if (opt->progress) { /* counted by all threads, reported by the calling one */
#pragma omp atomic
    (*done)++;
    if (omp_get_thread_num() == 0 && fcm_wtime() - *last >= opt->progress_interval) {
      fcm_index now;
#pragma omp atomic read
      now = *done;
      opt->progress(now, nc, opt->progress_user);
      *last = fcm_wtime();
    }
  }
}

/* Phase 2: every cell in parallel into its own cell_out (out not zeroed before: each entry is
 * zeroed here, whatever the outcome); thread sums into *sums. An error is that of the lowest
 * failing cell, whatever the thread count. */
fcm_status fcm__embed_run_cells(const build *B, fcm_cell_rules *R, int nthreads, cell_out *out,
                                cell_sums *sums, const fcm_cell_rules_options *opt)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index nc = R->num_cells;
  fcm_index done = 0, first = nc;
  int ran = 0; /* the loops ran: every entry of out zeroed */
  double last = fcm_wtime();
  fcm__loop loop;
  fcm_index *order = NULL; /* a cut: the cells it integrates again first (the threads' shares
                              end together), one at a time, then the others, whose rules are
                              copied, in chunks (one cell is less work than taking it) */
  if (B->rebuild) {
    FCM_ALLOC(ctx, (size_t)nc + 1, order);
    fcm_index n = 0;
    for (int pass = 0; pass < 2; pass++) {
      for (fcm_index c = 0; c < nc; c++)
        if ((B->rebuild[c] != 0) == (pass == 0)) order[n++] = c;
      if (pass == 0) first = n;
    }
  }
  fcm__loop_begin(ctx, &loop);
  memset(sums, 0, sizeof *sums);
  /* the cells' dense solves run inside the threads: BLAS threads of their own would fight
   * them for the cores (4 times slower on 2 cores), so one BLAS thread for the loop; with one
   * thread too, since a threaded BLAS product may round differently and the rules must not
   * depend on the thread count */
  const int blas_threads = fcm_blas_set_num_threads(1);
#pragma omp parallel num_threads(nthreads)
  {
    cell_sums mine;
    memset(&mine, 0, sizeof mine);
    fcm__embed_ws *ws = NULL;
#pragma omp for schedule(dynamic, 1) nowait
    for (fcm_index i = 0; i < first; i++)
      run_cell(B, R, order ? order[i] : i, &ws, out, &mine, &loop, opt, &done, &last);
#pragma omp for schedule(dynamic, 64)
    for (fcm_index i = first; i < nc; i++)
      run_cell(B, R, order[i], &ws, out, &mine, &loop, opt, &done, &last);
    if (ws) fcm__embed_ws_free(ctx, ws);
    fcm__free(ctx, ws);
#pragma omp critical(fcm_embed_sum)
    {
      sums->counts.candidates += mine.counts.candidates;
      sums->counts.parts += mine.counts.parts;
      sums->counts.tets += mine.counts.tets;
      sums->counts.slivers += mine.counts.slivers;
      sums->counts.surface_triangles += mine.counts.surface_triangles;
      sums->counts.sliver_volume += mine.counts.sliver_volume;
      sums->counts.moved_volume += mine.counts.moved_volume;
      sums->counts.degenerate += mine.counts.degenerate;
      keep_largest(&sums->counts.split_change, mine.counts.split_change);
      sums->counts.surface_cells += mine.counts.surface_cells;
      sums->counts.surface_fallbacks += mine.counts.surface_fallbacks;
      sums->counts.kept += mine.counts.kept;
      sums->time_intersect += mine.time_intersect;
      sums->time_simplify += mine.time_simplify;
    }
  }
  ran = 1;
  if (blas_threads > 1) fcm_blas_set_num_threads(blas_threads);
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
  if (opt->progress) opt->progress(nc, nc, opt->progress_user);
cleanup:
  if (!ran) memset(out, 0, (size_t)nc * sizeof *out);
  fcm__free(ctx, order);
  return st;
}
