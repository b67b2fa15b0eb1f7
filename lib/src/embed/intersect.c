/* Per-background-cell kernels of the embedded quadrature: cell planes and map, clipping
 * of candidate embedded cells into tets, tet rules mapped into the reference cell, and
 * the same path one dimension lower for the embedded boundary.
 *
 * Longva et al. 2020, Sec. 4.5, eq. (11)-(12): a point eta_j of a tet rule with weight
 * l_j on tet Q goes to X = T_Q(eta_j), then xi = T_K^{-1}(X), with reference weight
 * l_j |J_Q| / |J_K(xi)|; exact for degree m when T_K is affine. */
#include "embed/embed_impl.h"
#include "element/element_impl.h"
#include "la/mat3.h"

#include <math.h>
#include <string.h>

void fcm__embed_ws_free(fcm_ctx *ctx, fcm__embed_ws *ws)
{
  if (ws->parts) fcm__embed_parts_free(ctx, ws->parts);
  fcm__free(ctx, ws->parts);
  ws->parts = NULL;
  fcm__geom_idbuf_free(ctx, &ws->cand);
  fcm__embed_surface_ws_free(ctx, ws);
  fcm__free(ctx, ws->tets);
  fcm__free(ctx, ws->vol);
  fcm__free(ctx, ws->spts);
  fcm__free(ctx, ws->sw);
  fcm__free(ctx, ws->snrm);
  fcm__free(ctx, ws->stri);
  ws->tets = ws->vol = ws->spts = ws->sw = ws->snrm = NULL;
  ws->stri = NULL;
  ws->num_tets = ws->tet_cap = ws->num_spts = ws->spt_cap = 0;
}

void fcm__embed_cell_box(const fcm_mesh *mesh, fcm_index id, double clip_rtol,
                         fcm__embed_cell *cell)
{
  cell->type = fcm_mesh_element_type(mesh);
  cell->info = fcm_mesh_get_element_info(mesh);
  cell->id = id;
  fcm_mesh_cell_coords(mesh, id, cell->X);
  const int nc = cell->info->num_corners;
  cell->size = fcm__element_cell_size(nc, cell->X);
  cell->tol = clip_rtol * cell->size;
  for (int d = 0; d < 3; d++) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (int a = 0; a < nc; a++) {
      const double x = cell->X[3 * a + d];
      lo = x < lo ? x : lo, hi = x > hi ? x : hi;
    }
    cell->lo[d] = lo - cell->tol, cell->hi[d] = hi + cell->tol;
  }
}

fcm_status fcm__embed_cell_setup_volume(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_index id,
                                        double clip_rtol, fcm__embed_cell *cell)
{
  fcm_status st = FCM_OK;
  fcm__poly p;
  fcm__embed_cell_box(mesh, id, clip_rtol, cell);
  const int nc = cell->info->num_corners;
  fcm__geom_poly_from_cell_shape(nc == 4 ? FCM_ELEMENT_TET4 : FCM_ELEMENT_HEX8, cell->X, &p);
  cell->volume = fcm__geom_poly_volume(&p);
  FCM_CHECK(cell->volume > 0.0 && isfinite(cell->volume), ctx, FCM_ERR_GEOMETRY,
            "embed: background cell %lld (%s) has corner-polyhedron volume %g (must be positive)",
            (long long)id, cell->info->name, cell->volume);
cleanup:
  return st;
}

fcm_status fcm__embed_cell_setup(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_index id, double clip_rtol,
                                 fcm__embed_cell *cell)
{
  fcm_status st = FCM_OK;
  FCM_TRY(ctx, fcm__embed_cell_setup_volume(ctx, mesh, id, clip_rtol, cell));
  cell->num_planes = fcm__geom_cell_planes(cell->info, cell->X, cell->planes);
  cell->affine = fcm_element_is_affine(cell->type, cell->X, 1e-13);
  if (cell->affine) {
    fcm__element_corner_affine(cell->type, cell->X, cell->A, cell->xi0);
    cell->detA = fcm__mat3_inv(cell->A, cell->Ainv);
    FCM_CHECK(cell->detA > 0.0, ctx, FCM_ERR_GEOMETRY,
              "embed: background cell %lld (%s) has det J = %g (must be positive)", (long long)id,
              cell->info->name, cell->detA);
  }
cleanup:
  return st;
}

fcm_status fcm__embed_to_reference(fcm_ctx *ctx, const fcm__embed_cell *cell, const double x[3],
                                   double xi[3], double *det)
{
  fcm_status st = FCM_OK;
  if (cell->affine) {
    const double r[3] = {x[0] - cell->X[0], x[1] - cell->X[1], x[2] - cell->X[2]};
    double s[3];
    fcm__mat3_mulv(cell->Ainv, r, s);
    for (int d = 0; d < 3; d++)
      xi[d] = cell->xi0[d] + s[d];
    *det = cell->detA;
  } else {
    double J[9];
    FCM_TRY(ctx, fcm_element_inverse_map(ctx, cell->type, cell->X, x, xi));
    *det = fcm_element_jacobian(cell->type, cell->X, xi, J);
    FCM_CHECK(*det > 0.0, ctx, FCM_ERR_GEOMETRY,
              "embed: background cell %lld (%s) has det J = %g at xi = (%g, %g, %g)",
              (long long)cell->id, cell->info->name, *det, xi[0], xi[1], xi[2]);
  }
cleanup:
  return st;
}

static fcm_status grow_tets(fcm_ctx *ctx, fcm__embed_ws *ws, size_t need)
{
  fcm_status st = FCM_OK;
  if (need <= ws->tet_cap) return FCM_OK;
  size_t cap = ws->tet_cap ? ws->tet_cap : 256;
  while (cap < need)
    cap *= 2;
  void *t = ws->tets, *v = ws->vol;
  FCM_TRY(ctx, fcm__resize(ctx, &t, 12 * ws->num_tets, 12 * cap, sizeof(double)));
  ws->tets = t;
  FCM_TRY(ctx, fcm__resize(ctx, &v, ws->num_tets, cap, sizeof(double)));
  ws->vol = v;
  ws->tet_cap = cap;
cleanup:
  return st;
}

/* Thickness scale of an embedded cell with volume `vol` and vertices X (n x 3):
 * 6 |E| / diam(E)^2 (about the smallest height: a regular tet of edge a gives 0.71 a, a
 * flat L x L x t slab tet about t / 2). */
static double cell_thickness(const double *X, int n, double vol)
{
  double d2 = 0.0;
  for (int a = 0; a < n; a++)
    for (int b = a + 1; b < n; b++) {
      const double dx = X[3 * a] - X[3 * b], dy = X[3 * a + 1] - X[3 * b + 1],
                   dz = X[3 * a + 2] - X[3 * b + 2];
      d2 = fmax(d2, dx * dx + dy * dy + dz * dz);
    }
  return d2 > 0.0 ? 6.0 * vol / d2 : 0.0;
}

fcm_status fcm__embed_clip_cell(fcm_ctx *ctx, const fcm_geometry *geom, const fcm__embed_cell *cell,
                                fcm_index e, double clip_rtol, double sliver_rtol,
                                fcm__embed_ws *ws, double *tol, double *vmin)
{
  fcm_status st = FCM_OK;
  double X[24];
  const fcm_index *cv = geom->cells + (size_t)geom->npc * (size_t)e;
  for (int a = 0; a < geom->npc; a++)
    for (int d = 0; d < 3; d++)
      X[3 * a + d] = geom->coords[3 * cv[a] + d];
  fcm__geom_poly_from_cell(geom->type, X, &ws->poly);
  /* the scales of this embedded cell: a thin one gets tolerances of its own size */
  const double vol_e = fabs(fcm__geom_poly_volume(&ws->poly));
  *tol = fmin(cell->tol, clip_rtol * cell_thickness(X, geom->npc, vol_e));
  *vmin = sliver_rtol * fmin(cell->volume, vol_e);
  for (int f = 0; f < cell->num_planes && ws->poly.nf > 0; f++)
    FCM_CHECK(fcm__geom_poly_clip(&ws->poly, cell->planes + f, *tol, &ws->scratch) == 0, ctx,
              FCM_ERR_INTERNAL,
              "embed: clipping embedded cell %lld by background cell %lld exceeded the "
              "polyhedron capacity (%d vertices, %d faces)",
              (long long)(geom->cell_orig ? geom->cell_orig[e] : e), (long long)cell->id,
              FCM__POLY_MAX_VERTS, FCM__POLY_MAX_FACES);
cleanup:
  return st;
}

fcm_status fcm__embed_append_tets(fcm_ctx *ctx, fcm__embed_ws *ws, const fcm__poly *p, double vmin,
                                  double *vsum, double *lost, double *moved, fcm_index *nslivers)
{
  fcm_status st = FCM_OK;
  const int nt = fcm__geom_poly_num_tets(p);
  FCM_TRY(ctx, grow_tets(ctx, ws, ws->num_tets + (size_t)nt));
  double *t = ws->tets + 12 * ws->num_tets, *v = ws->vol + ws->num_tets;
  const int made = fcm__geom_poly_tets(p, t, v);
  int kept = 0;
  double neg = 0.0, sum = 0.0;
  for (int i = 0; i < made; i++) {
    if (!(v[i] > vmin)) {
      (*nslivers)++;
      if (v[i] > 0.0) *lost += v[i];
      if (v[i] < 0.0) neg += v[i];
      continue;
    }
    if (kept != i) {
      memmove(t + 12 * kept, t + 12 * i, 12 * sizeof *t);
      v[kept] = v[i];
    }
    sum += v[i];
    kept++;
  }
  /* A part the tolerances left slightly non-convex (vertices taken as on a plane within the
   * tolerance) can have fan tets of negative volume from every apex (fcm__geom_poly_tets
   * takes the least): they get no points, and the others are scaled so that the part keeps
   * its volume, the signed sum of its tets; what that moves is no more than the negative
   * volume, the tolerance times the part's faces. The exact integral of g over the part is
   * the signed sum over all its tets, so the rule's error is at most 2 |neg| max |g|
   * (*moved). */
  if (neg < 0.0 && sum + neg > 0.0) {
    const double f = (sum + neg) / sum;
    for (int i = 0; i < kept; i++)
      v[i] *= f;
    sum += neg;
    *moved -= neg;
  }
  *vsum += sum;
  ws->num_tets += (size_t)kept;
cleanup:
  return st;
}

fcm_status fcm__embed_cell_tets(fcm_ctx *ctx, const fcm_geometry *geom, const fcm_aabb_tree *tree,
                                const fcm__embed_cell *cell, double clip_rtol, double sliver_rtol,
                                fcm__embed_ws *ws, fcm__embed_counts *counts, double *volume)
{
  fcm_status st = FCM_OK;
  double vsum = 0.0, lost = 0.0, moved = 0.0;
  fcm_index nparts = 0, nslivers = 0;
  ws->num_tets = 0;
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, cell->lo, cell->hi, &ws->cand));
  for (size_t k = 0; k < ws->cand.n; k++) {
    double tol, vmin;
    FCM_TRY(ctx, fcm__embed_clip_cell(ctx, geom, cell, ws->cand.ids[k], clip_rtol, sliver_rtol, ws,
                                      &tol, &vmin));
    if (ws->poly.nf == 0) continue;
    nparts++;
    FCM_TRY(ctx, fcm__embed_append_tets(ctx, ws, &ws->poly, vmin, &vsum, &lost, &moved, &nslivers));
  }
  if (counts) {
    counts->candidates += (fcm_index)ws->cand.n;
    counts->parts += nparts;
  }
  fcm__embed_counts_add_tets(counts, ws->num_tets, nslivers, lost, moved);
  *volume = vsum;
cleanup:
  return st;
}

fcm_status fcm__embed_map_tets(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__embed_ws *ws,
                               const fcm_rule *rule, double *pts, double *w)
{
  fcm_status st = FCM_OK;
  const int nq = fcm_rule_num_points(rule);
  const double *eta = fcm_rule_points(rule), *l = fcm_rule_weights(rule);
  size_t k = 0;
  for (size_t t = 0; t < ws->num_tets; t++) {
    const double *T = ws->tets + 12 * t;
    const double jq = 6.0 * ws->vol[t];
    for (int j = 0; j < nq; j++, k++) {
      const double *e = eta + 3 * j;
      double x[3], det;
      for (int d = 0; d < 3; d++)
        x[d] =
            T[d] + e[0] * (T[3 + d] - T[d]) + e[1] * (T[6 + d] - T[d]) + e[2] * (T[9 + d] - T[d]);
      FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, x, pts + 3 * k, &det));
      w[k] = l[j] * jq / det;
    }
  }
cleanup:
  return st;
}

static fcm_status grow_surface(fcm_ctx *ctx, fcm__embed_ws *ws, size_t need)
{
  fcm_status st = FCM_OK;
  if (need <= ws->spt_cap) return FCM_OK;
  size_t cap = ws->spt_cap ? ws->spt_cap : 256;
  while (cap < need)
    cap *= 2;
  const size_t n = ws->num_spts;
  void *p = ws->spts, *w = ws->sw, *q = ws->snrm, *t = ws->stri;
  FCM_TRY(ctx, fcm__resize(ctx, &p, 3 * n, 3 * cap, sizeof(double)));
  ws->spts = p;
  FCM_TRY(ctx, fcm__resize(ctx, &w, n, cap, sizeof(double)));
  ws->sw = w;
  FCM_TRY(ctx, fcm__resize(ctx, &q, 3 * n, 3 * cap, sizeof(double)));
  ws->snrm = q;
  FCM_TRY(ctx, fcm__resize(ctx, &t, n, cap, sizeof(fcm_index)));
  ws->stri = t;
  ws->spt_cap = cap;
cleanup:
  return st;
}

#define POLYGON_CAP 64

fcm_status fcm__embed_cell_surface(fcm_ctx *ctx, const fcm_geometry *geom,
                                   const fcm_aabb_tree *tri_tree, const fcm__embed_cell *cell,
                                   const struct fcm__parts *P, int piece, double sliver_rtol,
                                   const fcm_rule *tri_rule, fcm__embed_ws *ws,
                                   fcm__embed_counts *counts)
{
  fcm_status st = FCM_OK;
  double cpoly[3 * POLYGON_CAP], poly[3 * POLYGON_CAP], work[3 * POLYGON_CAP];
  const int nq = fcm_rule_num_points(tri_rule);
  const double *eta = fcm_rule_points(tri_rule), *l = fcm_rule_weights(tri_rule);
  const double amin = sliver_rtol * cbrt(cell->volume) * cbrt(cell->volume);
  ws->num_spts = 0;
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, tri_tree, cell->lo, cell->hi, &ws->cand));
  for (size_t k = 0; k < ws->cand.n; k++) {
    const fcm_index tri = ws->cand.ids[k];
    const fcm_index tri_id = geom->tri_orig ? geom->tri_orig[tri] : tri; /* a crop's: original */
    double nrm[3], u[3], v[3];
    for (int a = 0; a < 3; a++)
      for (int d = 0; d < 3; d++)
        poly[3 * a + d] = geom->coords[3 * geom->tris[3 * tri + a] + d];
    for (int d = 0; d < 3; d++)
      u[d] = poly[3 + d] - poly[d], v[d] = poly[6 + d] - poly[d];
    nrm[0] = u[1] * v[2] - u[2] * v[1];
    nrm[1] = u[2] * v[0] - u[0] * v[2];
    nrm[2] = u[0] * v[1] - u[1] * v[0];
    const double len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(len > 0.0)) continue;
    for (int d = 0; d < 3; d++)
      nrm[d] /= len;
    int n = 3;
    for (int f = 0; f < cell->num_planes && n >= 3; f++) {
      const fcm__plane *pl = cell->planes + f;
      const int keep = nrm[0] * pl->n[0] + nrm[1] * pl->n[1] + nrm[2] * pl->n[2] > 0.0;
      n = fcm__geom_polygon_clip(poly, n, POLYGON_CAP, pl, cell->tol, keep, work);
      FCM_CHECK(n >= 0, ctx, FCM_ERR_INTERNAL,
                "embed: clipping boundary triangle %lld by background cell %lld exceeded %d "
                "vertices",
                (long long)tri_id, (long long)cell->id, POLYGON_CAP);
    }
    if (n < 3) continue;
    int kept_any = 0;
    /* whole cell: the clipped polygon once; one piece: its share under each of its parts */
    const size_t nparts = P ? P->n : 1;
    const int nclip = n;
    if (P) memcpy(cpoly, poly, 3 * (size_t)nclip * sizeof *poly);
    for (size_t part = 0; part < nparts; part++) {
      if (P) {
        if (P->piece[part] != piece) continue;
        memcpy(poly, cpoly, 3 * (size_t)nclip * sizeof *poly);
        n = fcm__embed_clip_to_part(P, part, poly, nclip, POLYGON_CAP, nrm, work);
        FCM_CHECK(n >= 0, ctx, FCM_ERR_INTERNAL,
                  "embed: clipping boundary triangle %lld by a piece of background cell %lld "
                  "exceeded %d vertices",
                  (long long)tri_id, (long long)cell->id, POLYGON_CAP);
      }
      for (int i = 1; i + 1 < n; i++) {
        const double *a = poly, *b = poly + 3 * i, *c = poly + 3 * (i + 1);
        double e1[3], e2[3], cr[3];
        for (int d = 0; d < 3; d++)
          e1[d] = b[d] - a[d], e2[d] = c[d] - a[d];
        cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
        cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
        cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
        const double area2 = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
        if (!(0.5 * area2 > amin)) continue;
        kept_any = 1;
        FCM_TRY(ctx, grow_surface(ctx, ws, ws->num_spts + (size_t)nq));
        for (int j = 0; j < nq; j++) {
          const size_t s = ws->num_spts++;
          for (int d = 0; d < 3; d++) {
            ws->spts[3 * s + d] = a[d] + eta[2 * j] * e1[d] + eta[2 * j + 1] * e2[d];
            ws->snrm[3 * s + d] = nrm[d];
          }
          ws->sw[s] = l[j] * area2;
          ws->stri[s] = tri_id;
        }
      }
    }
    counts->surface_triangles += kept_any;
  }
cleanup:
  return st;
}
