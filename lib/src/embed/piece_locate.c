/* Pieces of output points: where points and triangles of the embedded geometry's boundary lie
 * among the material pieces of cut-cell rules. The parts of a cell are made again by the
 * calls the rules' build makes (fcm__embed_cell_parts, fcm__embed_cell_pieces, on the same
 * geometry, tolerances and cut triangles), so the components come out the same and in the
 * same order; the rules record each piece's component number (piece_component), which maps
 * them back to the rules' pieces. A boundary polygon clipped to a part (as the surface rules
 * clip, fcm__embed_clip_to_part) then goes to the piece whose material it bounds. */
#include "embed/rules_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define POLYGON_CAP 64

/* Polygons of no more area than this x the cell size squared are left out: a polygon clipped
 * to a part it only touches (along an edge, or on the far side of a cut) has none. */
#define AREA_RTOL 1e-12

struct fcm__embed_finder {
  fcm_ctx *ctx;
  const fcm_mesh *mesh;
  const fcm_geometry *geom;
  const fcm_aabb_tree *tree; /* boxes of the geometry's cells (the geometry's own tree) */
  const fcm_cell_rules *R;   /* NULL until set */
  fcm_aabb_tree *cut_tree;   /* boxes of R's cut triangles (NULL: none) */
  double on_cut;             /* a point this close to a cut triangle lies on it */
  fcm__idbuf cand;
  fcm__embed_ws ws;
  fcm__parts *P;     /* the parts of `cell` when has_parts */
  fcm_index cell;    /* the cell C describes (-1: none) */
  int has_parts;     /* P holds cell's parts and pieces */
  fcm__embed_cell C; /* planes, size and map of `cell` */
  fcm_index *piece;  /* per component of `cell`: R's piece (-1: the build dropped it) */
  size_t piece_cap;
};

void fcm__embed_polys_free(fcm_ctx *ctx, fcm__embed_polys *p)
{
  fcm__free(ctx, p->x);
  fcm__free(ctx, p->nv);
  fcm__free(ctx, p->piece);
  memset(p, 0, sizeof *p);
}

fcm_status fcm__embed_finder_create(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                    fcm__embed_finder **out)
{
  fcm_status st = FCM_OK;
  fcm__embed_finder *f = NULL;
  FCM_CHECK(mesh && geom && out, ctx, FCM_ERR_ARG, "embed finder: NULL mesh, geometry or output");
  *out = NULL;
  FCM_ALLOC(ctx, 1, f);
  f->ctx = ctx, f->mesh = mesh, f->geom = geom, f->cell = -1;
  { /* twice the cuts' tolerance of a cell of the mean size: the bounding box's volume per cell */
    const double *X = fcm_mesh_coords(mesh);
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (fcm_index i = 0; i < fcm_mesh_num_nodes(mesh); i++)
      for (int d = 0; d < 3; d++)
        lo[d] = fmin(lo[d], X[3 * i + d]), hi[d] = fmax(hi[d], X[3 * i + d]);
    const double v = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    const double side = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    const double nc = (double)FCM_MAX(fcm_mesh_num_cells(mesh), 1);
    f->on_cut = 2.0 * FCM__EMBED_MATCH_RTOL * (v > 0.0 ? cbrt(v / nc) : side / nc);
  }
  FCM_TRY(ctx, fcm__geom_tree(ctx, geom, 0, &f->tree));
  *out = f;
  f = NULL;
cleanup:
  fcm__embed_finder_destroy(&f);
  return st;
}

void fcm__embed_finder_destroy(fcm__embed_finder **finder)
{
  if (!finder || !*finder) return;
  fcm__embed_finder *f = *finder;
  fcm__embed_finder_release(f);
  fcm__free(f->ctx, f);
  *finder = NULL;
}

fcm_status fcm__embed_finder_set_rules(fcm__embed_finder *f, const fcm_cell_rules *R)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = f->ctx;
  double *boxes = NULL;
  FCM_CHECK(R && R->num_cells == fcm_mesh_num_cells(f->mesh), ctx, FCM_ERR_ARG,
            "embed finder: rules of %lld cells on a mesh of %lld",
            (long long)(R ? R->num_cells : -1), (long long)fcm_mesh_num_cells(f->mesh));
  fcm_aabb_tree_destroy(&f->cut_tree);
  f->R = NULL;
  f->cell = -1;
  f->has_parts = 0;
  if (R->num_cut_tris > 0) {
    FCM_ALLOC_RAW(ctx, 6 * (size_t)R->num_cut_tris, boxes);
    for (fcm_index t = 0; t < R->num_cut_tris; t++) {
      memcpy(boxes + 6 * t, R->cut_tris[t].lo, 3 * sizeof(double));
      memcpy(boxes + 6 * t + 3, R->cut_tris[t].hi, 3 * sizeof(double));
    }
    FCM_TRY(ctx, fcm_aabb_tree_create(ctx, R->num_cut_tris, boxes, &f->cut_tree));
  }
  f->R = R;
cleanup:
  fcm__free(ctx, boxes);
  return st;
}

/* Make cell c the current one: its planes and, when `parts` is set, its parts and pieces as
 * the rules' build made them (the same calls; the triangles split in ascending order either
 * way, so the first cut's index does not matter). */
static fcm_status load_cell(fcm__embed_finder *f, fcm_index c, int parts)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = f->ctx;
  const fcm_cell_rules *R = f->R;
  FCM_CHECK(R && c >= 0 && c < R->num_cells, ctx, FCM_ERR_ARG,
            "embed finder: cell %lld out of range [0, %lld) or no rules set", (long long)c,
            (long long)(R ? R->num_cells : 0));
  if (f->cell != c) {
    f->cell = -1;
    f->has_parts = 0;
    FCM_TRY(ctx, fcm__embed_cell_setup(ctx, f->mesh, c, R->opts.clip_rtol, &f->C));
    f->cell = c;
  }
  if (!parts || f->has_parts) goto cleanup;
  if (!f->P) FCM_ALLOC(ctx, 1, f->P);
  fcm__parts *P = f->P;
  double whole_mvol = R->cell_mvol ? R->cell_mvol[c] : NAN; /* R's stays as it is */
  FCM_TRY(ctx, fcm__embed_cell_parts(ctx, f->geom, f->tree, &f->C, R->opts.clip_rtol,
                                     R->opts.sliver_rtol, &f->ws, P, &whole_mvol, NULL));
  P->tcand.n = 0;
  if (f->cut_tree) FCM_TRY(ctx, fcm__embed_cut_candidates(ctx, f->cut_tree, &f->C, &P->tcand));
  if (P->tcand.n > 0) FCM_TRY(ctx, fcm__embed_cell_pieces(ctx, &f->C, R->cut_tris, 0, P));
  const size_t ncomp = (size_t)P->num_pieces;
  if (ncomp + 1 > f->piece_cap) {
    void *q = f->piece;
    FCM_TRY(ctx, fcm__resize(ctx, &q, 0, ncomp + 1, sizeof(fcm_index)));
    f->piece = q;
    f->piece_cap = ncomp + 1;
  }
  for (size_t k = 0; k < ncomp; k++)
    f->piece[k] = -1;
  for (fcm_index p = R->piece_off[c]; p < R->piece_off[c + 1]; p++) {
    const int comp = R->piece_component[p];
    if (comp >= 0 && (size_t)comp < ncomp) f->piece[comp] = p;
  }
  f->has_parts = 1;
cleanup:
  return st;
}

/* R's piece of part i of the current cell (-1: none). */
static fcm_index part_piece(const fcm__embed_finder *f, size_t i)
{
  const int comp = f->P->piece[i];
  return comp >= 0 && comp < f->P->num_pieces ? f->piece[comp] : -1;
}

fcm_status fcm__embed_finder_crosses(fcm__embed_finder *f, const double x[9], int *crosses)
{
  fcm_status st = FCM_OK;
  double lo[3], hi[3];
  *crosses = 0;
  if (!f->cut_tree) return FCM_OK;
  const double tol = f->on_cut;
  for (int d = 0; d < 3; d++) {
    lo[d] = fmin(x[d], fmin(x[3 + d], x[6 + d])) - tol;
    hi[d] = fmax(x[d], fmax(x[3 + d], x[6 + d])) + tol;
  }
  FCM_TRY(f->ctx, fcm__geom_tree_query(f->ctx, f->cut_tree, lo, hi, &f->cand));
  for (size_t k = 0; k < f->cand.n && !*crosses; k++) {
    const fcm__cut_tri *t = f->R->cut_tris + f->cand.ids[k];
    double s[3], smin = HUGE_VAL, smax = -HUGE_VAL;
    for (int a = 0; a < 3; a++) {
      s[a] = fcm__vec3_dot(t->plane.n, x + 3 * a) - t->plane.d;
      smin = fmin(smin, s[a]), smax = fmax(smax, s[a]);
    }
    if (smin < 0.0 && smax > 0.0) { /* across the plane: unless wholly beside the triangle */
      int beside = 0;
      for (int e = 0; e < 3 && !beside; e++) {
        if (t->inner[e]) continue;
        beside = 1;
        for (int a = 0; a < 3 && beside; a++)
          beside = fcm__vec3_dot(t->edge[e].n, x + 3 * a) - t->edge[e].d > 0.0;
      }
      *crosses = !beside;
    }
    /* a vertex on the triangle (a cut through a vertex, e.g. along a cell face, where the
     * pieces on its two sides may lie in cells of one piece each) */
    for (int a = 0; a < 3 && !*crosses; a++) {
      int on = fabs(s[a]) <= tol;
      for (int e = 0; e < 3 && on; e++)
        on = fcm__vec3_dot(t->edge[e].n, x + 3 * a) - t->edge[e].d <= tol;
      *crosses = on;
    }
  }
cleanup:
  return st;
}

fcm_status fcm__embed_finder_near_cut(fcm__embed_finder *f, const double x[3], double w, int *near)
{
  fcm_status st = FCM_OK;
  double lo[3], hi[3];
  *near = 0;
  if (!f->cut_tree) return FCM_OK;
  for (int d = 0; d < 3; d++)
    lo[d] = x[d] - w, hi[d] = x[d] + w;
  FCM_TRY(f->ctx, fcm__geom_tree_query(f->ctx, f->cut_tree, lo, hi, &f->cand));
  for (size_t k = 0; k < f->cand.n && !*near; k++) {
    const fcm__cut_tri *t = f->R->cut_tris + f->cand.ids[k];
    int on = fabs(fcm__vec3_dot(t->plane.n, x) - t->plane.d) <= w;
    for (int e = 0; e < 3 && on; e++)
      on = fcm__vec3_dot(t->edge[e].n, x) - t->edge[e].d <= w;
    *near = on;
  }
cleanup:
  return st;
}

void fcm__embed_finder_release(fcm__embed_finder *f)
{
  if (!f) return;
  fcm_aabb_tree_destroy(&f->cut_tree);
  fcm__geom_idbuf_free(f->ctx, &f->cand);
  fcm__embed_ws_free(f->ctx, &f->ws);
  memset(&f->ws, 0, sizeof f->ws);
  if (f->P) fcm__embed_parts_free(f->ctx, f->P);
  fcm__free(f->ctx, f->P);
  fcm__free(f->ctx, f->piece);
  f->P = NULL, f->piece = NULL, f->piece_cap = 0;
  f->R = NULL, f->cell = -1, f->has_parts = 0;
}

fcm_status fcm__embed_finder_point(fcm__embed_finder *f, fcm_index c, const double x[3],
                                   fcm_index *piece)
{
  fcm_status st = FCM_OK;
  *piece = -1;
  FCM_TRY(f->ctx, load_cell(f, c, 1));
  const double tol = FCM__EMBED_MATCH_RTOL * f->C.size;
  for (size_t i = 0; i < f->P->n; i++) {
    const fcm_index p = part_piece(f, i);
    if (p < 0 || p == *piece || !(fcm__embed_part_excess(f->P, i, x) <= tol)) continue;
    if (*piece != -1) {
      *piece = -2;
      break;
    }
    *piece = p;
  }
cleanup:
  return st;
}

/* Area of polygon x (n vertices). */
static double polygon_area(const double *x, int n)
{
  double a[3] = {0, 0, 0};
  for (int k = 0; k < n; k++) {
    const double *p = x + 3 * k, *q = x + 3 * ((k + 1) % n);
    a[0] += (p[1] - q[1]) * (p[2] + q[2]);
    a[1] += (p[2] - q[2]) * (p[0] + q[0]);
    a[2] += (p[0] - q[0]) * (p[1] + q[1]);
  }
  return 0.5 * sqrt(fcm__vec3_dot(a, a));
}

fcm_status fcm__embed_polys_push(fcm_ctx *ctx, fcm__embed_polys *out, const double *x, int n,
                                 fcm_index piece)
{
  fcm_status st = FCM_OK;
  if (out->n + 1 > out->cap) {
    const size_t cap = out->cap ? 2 * out->cap : 64;
    void *a = out->nv, *b = out->piece;
    FCM_TRY(ctx, fcm__resize(ctx, &a, out->n, cap, sizeof(int)));
    out->nv = a;
    FCM_TRY(ctx, fcm__resize(ctx, &b, out->n, cap, sizeof(fcm_index)));
    out->piece = b;
    out->cap = cap;
  }
  if (out->nx + (size_t)n > out->capx) {
    size_t cap = out->capx ? 2 * out->capx : 256;
    while (cap < out->nx + (size_t)n)
      cap *= 2;
    void *a = out->x;
    FCM_TRY(ctx, fcm__resize(ctx, &a, 3 * out->nx, 3 * cap, sizeof(double)));
    out->x = a;
    out->capx = cap;
  }
  memcpy(out->x + 3 * out->nx, x, 3 * (size_t)n * sizeof *x);
  out->nv[out->n] = n;
  out->piece[out->n] = piece;
  out->n++;
  out->nx += (size_t)n;
cleanup:
  return st;
}

fcm_status fcm__embed_finder_clip(fcm__embed_finder *f, fcm_index c, const double x[9],
                                  fcm__embed_polys *out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = f->ctx;
  double cpoly[3 * POLYGON_CAP], poly[3 * POLYGON_CAP], work[3 * POLYGON_CAP], nrm[3], u[3], v[3];
  FCM_TRY(ctx, load_cell(f, c, 0));
  const fcm_cell_rules *R = f->R;
  const fcm_index np = R->piece_off[c + 1] - R->piece_off[c];
  const double amin = AREA_RTOL * f->C.size * f->C.size;
  for (int d = 0; d < 3; d++)
    u[d] = x[3 + d] - x[d], v[d] = x[6 + d] - x[d];
  fcm__vec3_cross(u, v, nrm);
  const double len = sqrt(fcm__vec3_dot(nrm, nrm));
  if (!(len > 0.0)) goto cleanup;
  for (int d = 0; d < 3; d++)
    nrm[d] /= len;
  memcpy(cpoly, x, 9 * sizeof *x);
  int n = 3;
  for (int k = 0; k < f->C.num_planes && n >= 3; k++) {
    const fcm__plane *pl = f->C.planes + k;
    n = fcm__geom_polygon_clip(cpoly, n, POLYGON_CAP, pl, f->C.tol, fcm__vec3_dot(nrm, pl->n) > 0.0,
                               work);
  }
  FCM_CHECK(n >= 0, ctx, FCM_ERR_INTERNAL,
            "embed finder: clipping a boundary triangle by background cell %lld exceeded %d "
            "vertices",
            (long long)c, POLYGON_CAP);
  if (n < 3) goto cleanup;
  if (np < 2) {
    if (polygon_area(cpoly, n) > amin)
      FCM_TRY(ctx, fcm__embed_polys_push(ctx, out, cpoly, n, np ? R->piece_off[c] : -1));
    goto cleanup;
  }
  FCM_TRY(ctx, load_cell(f, c, 1));
  for (size_t i = 0; i < f->P->n; i++) {
    memcpy(poly, cpoly, 3 * (size_t)n * sizeof *poly);
    const int m = fcm__embed_clip_to_part_flat(f->P, i, poly, n, POLYGON_CAP, nrm,
                                               FCM__EMBED_MATCH_RTOL * f->C.size, work);
    FCM_CHECK(m >= 0, ctx, FCM_ERR_INTERNAL,
              "embed finder: clipping a boundary triangle by a part of background cell %lld "
              "exceeded %d vertices",
              (long long)c, POLYGON_CAP);
    if (m >= 3 && polygon_area(poly, m) > amin)
      FCM_TRY(ctx, fcm__embed_polys_push(ctx, out, poly, m, part_piece(f, i)));
  }
cleanup:
  return st;
}
