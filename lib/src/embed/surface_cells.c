/* The surface path of a background cell (FCM_CELL_MOMENTS_AUTO / SURFACE): its material
 * volume from the exact surface moments (surface_moments.c), and for a cut cell a positive
 * rule of at most M points per kind, fitted on candidate points inside the material to those
 * moments (fcm__simplify_fit). The candidates are the points of a grid over the material's
 * bounding box in the cell, fine enough that about c(m) x M of them fall inside the material
 * (fcm__fit_candidates_per_moment: 2 up to strength 5, more above, where fewer fail), and
 * points on the material's boundary; a fit that fails is retried with GROW times as many, up
 * to ATTEMPTS grids in all. The moments of a small piece with a sharp
 * corner (the tip of a body's acute vertex in a cell) sit close to the corner, which only a
 * fine grid's points reach. */
#include "embed/rules_impl.h"
#include "la/mat3.h"
#include "simplify/simplify_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdint.h>
#include <string.h>

/* The most parts of a piece that box_piece_rule() takes (8 points each). */
#define FCM__BOX_PIECE_PARTS 3

/* Boundary points kept per moment, the finer grid's factor on a retry, the largest grid per
 * axis, the piece's points (of each set of piece_candidates()) per boundary point on a retry
 * before the last, which takes them all. */
enum { BOUNDARY_PER_MOMENT = 1, GROW = 4, ATTEMPTS = 4, GRID_MAX = 64, PIECE_PER_BOUNDARY = 2 };

/* Absolute moment residual accepted, per unit of the material box's reference volume: ten times
 * the moments' own rounding. */
#define MOMENT_ATOL 1e-14

/* A cut piece filling less of its box than this takes the volume path without a fit: the
 * finest grid (GRID_MAX^3) puts fewer than 2e-3 x 65^3 = 550 candidates in it, below the last
 * attempts' targets, and such pieces (thin slanted slabs between a blade and the body's
 * surface) often fail every attempt: on Dick's Bunny 3 row all six below 2e-3 did, at 12 to
 * 22 ms each (the fullest of them filling 1.2e-3; every piece above it fitted, the emptiest
 * 2.1e-3). The volume path gives them exact rules from the piece's tets, at a fraction of a
 * millisecond for such a slab. With the stiffness on the mass space every kind's rule is exact
 * for its integrand, so which exact rule a piece gets changes its results at round-off only, and
 * the slabs up to PIECE_MIN_FILL_EXACT take the volume path too: on Dick's row 10 pieces filling
 * 2.1e-3 to 1e-2 of their box, whose fits took 2 ms each. (With the default strength-2 stiffness
 * another rule moves the results by its quadrature error.) */
#define PIECE_MIN_FILL       2e-3
#define PIECE_MIN_FILL_EXACT 1e-2

static fcm_status ws_surface(fcm_ctx *ctx, fcm__embed_ws *ws)
{
  fcm_status st = FCM_OK;
  if (!ws->sr) FCM_ALLOC(ctx, 1, ws->sr);
  if (!ws->cr) FCM_ALLOC(ctx, 1, ws->cr);
  if (!ws->bnd) FCM_ALLOC(ctx, 1, ws->bnd);
cleanup:
  return st;
}

fcm_status fcm__embed_surface_volume(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                                     double *vol, double box[6])
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  int touched;
  FCM_TRY(ctx, ws_surface(ctx, ws));
  FCM_TRY(ctx, fcm__embed_material_box(ctx, B->geom, B->tri_tree, cell, &ws->cand, ws->cr, ws->bnd,
                                       box, &touched));
  FCM_TRY(ctx, fcm__embed_moment_rule(ctx, B->geom, B->tri_tree, cell, &B->mq, touched ? box : NULL,
                                      &ws->cand, ws->cr, ws->sr));
  double s = 0.0;
  for (size_t i = 0; i < ws->sr->n; i++)
    s += ws->sr->w[i];
  *vol = s * cell->detA;
cleanup:
  return st;
}

/* Whether the reference point xi lies in piece ws->cand_piece of ws->cand_parts (in one of
 * its parts, within the part's tolerance): 0 outside, 2 in a part the body fills, 1 in
 * another; 1 without a piece to test. A part's plane that puts the point outside moves to the
 * front of its planes: the next point (of the same grid column, mostly) likely lies beyond it
 * too, and the order of the tests does not change their conjunction. */
static int in_piece(const fcm__embed_cell *cell, fcm__embed_ws *ws, const double xi[3])
{
  if (!ws->cand_parts) return 1;
  const double s[3] = {xi[0] - cell->xi0[0], xi[1] - cell->xi0[1], xi[2] - cell->xi0[2]};
  double x[3];
  fcm__mat3_mulv(cell->A, s, x);
  for (int d = 0; d < 3; d++)
    x[d] += cell->X[d];
  int found = 0;
  for (size_t k = 0; k < ws->cand_npl;) { /* per part: faces c, tolerance, full, c planes */
    const size_t c = (size_t)ws->cand_pl[k];
    const double tol = ws->cand_pl[k + 1];
    double *pl = ws->cand_pl + k + 3;
    size_t f = 0;
    while (f < c &&
           pl[4 * f] * x[0] + pl[4 * f + 1] * x[1] + pl[4 * f + 2] * x[2] - pl[4 * f + 3] <= tol)
      f++;
    if (f == c) {
      if (ws->cand_pl[k + 2] != 0.0) return 2;
      found = 1;
    } else if (f > 0) {
      double t[4];
      memcpy(t, pl, sizeof t);
      memcpy(pl, pl + 4 * f, sizeof t);
      memcpy(pl + 4 * f, t, sizeof t);
    }
    k += 3 + 4 * c;
  }
  return found;
}

/* The tet rule whose points piece_candidates() takes: the strongest built. */
static const fcm_rule *piece_rule(const build *B)
{
  const fcm_rule *r = NULL;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    if (B->tet_rule[k] && (!r || fcm_rule_num_points(B->tet_rule[k]) > fcm_rule_num_points(r)))
      r = B->tet_rule[k];
  return r;
}

/* How many points piece_candidates() may add. */
static size_t piece_points(const build *B, const fcm__embed_ws *ws)
{
  const fcm__parts *P = ws->cand_parts;
  size_t n = 0;
  for (size_t j = 0; P && j < P->n; j++)
    if (P->piece[j] == ws->cand_piece) n += (size_t)fcm__geom_poly_num_tets(P->poly + j);
  return n * (size_t)fcm_rule_num_points(piece_rule(B)) + ws->sr->n;
}

/* Candidates of a small or thin piece that the grid misses, those inside the body: the points
 * of a tet rule on the tets of a fan of each of its parts (a positive rule of the part) and
 * the points of its signed rule inside the piece (they lie on columns through the material);
 * of each set at most cap, spread over it (a piece of many parts has 10^5 tet points, and each
 * point outside a part the body fills costs a line query). */
static fcm_status piece_candidates(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                                   size_t cap, int *count)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm__parts *P = ws->cand_parts;
  const fcm_rule *rule = piece_rule(B);
  const int nq = fcm_rule_num_points(rule);
  const double *eta = fcm_rule_points(rule);
  const size_t all = piece_points(B, ws) - ws->sr->n, keep = FCM_MIN(all, cap);
  double *tets = NULL, *vol = NULL;
  size_t g = 0; /* the tet points' running number, of all */
  int most = 0; /* the most fan tets of the piece's parts (each written before it is read) */
  for (size_t j = 0; j < P->n; j++)
    if (P->piece[j] == ws->cand_piece) most = FCM_MAX(most, fcm__geom_poly_num_tets(P->poly + j));
  FCM_ALLOC_RAW(ctx, 12 * (size_t)most + 12, tets);
  FCM_ALLOC_RAW(ctx, (size_t)most + 1, vol);
  for (size_t j = 0; j < P->n && keep > 0; j++) {
    if (P->piece[j] != ws->cand_piece) continue;
    const int nt = fcm__geom_poly_tets(P->poly + j, tets, vol), full = fcm__embed_part_full(P, j);
    for (int t = 0; t < nt; t++) {
      const double *T = tets + 12 * t;
      for (int q = 0; q < nq; q++, g++) {
        if (!(vol[t] > 0.0) || (g + 1) * keep / all == g * keep / all) continue;
        const double *e = eta + 3 * q;
        double x[3], det;
        int in = 1;
        for (int d = 0; d < 3; d++)
          x[d] =
              T[d] + e[0] * (T[3 + d] - T[d]) + e[1] * (T[6 + d] - T[d]) + e[2] * (T[9 + d] - T[d]);
        double *xi = ws->cand_x + 3 * (size_t)*count;
        FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, x, xi, &det));
        if (P->whole || !full)
          FCM_TRY(ctx, fcm__embed_inside_column(ctx, B->geom, B->tri_tree, cell, xi[0], xi[1], 1,
                                                xi + 2, &in, &ws->cand, ws->cr));
        *count += in == 1;
      }
    }
  }
  const size_t nsr = FCM_MIN(ws->sr->n, cap);
  for (size_t l = 0; l < nsr; l++) {
    const size_t i = l * ws->sr->n / nsr;
    double *xi = ws->cand_x + 3 * (size_t)*count;
    int in = 1;
    memcpy(xi, ws->sr->x + 3 * i, 3 * sizeof *xi);
    const int where = in_piece(cell, ws, xi);
    if (!where) continue; /* (the signed rule's points of other pieces) */
    if (where == 1)
      FCM_TRY(ctx, fcm__embed_inside_column(ctx, B->geom, B->tri_tree, cell, xi[0], xi[1], 1,
                                            xi + 2, &in, &ws->cand, ws->cr));
    *count += in == 1;
  }
cleanup:
  fcm__free(ctx, tets);
  fcm__free(ctx, vol);
  return st;
}

/* Room for `need` candidates in ws->cand_x and ws->cand_in. */
static fcm_status cand_room(fcm_ctx *ctx, fcm__embed_ws *ws, size_t need)
{
  fcm_status st = FCM_OK;
  if (need > ws->cand_cap) {
    void *x = ws->cand_x, *in = ws->cand_in;
    FCM_TRY(ctx, fcm__resize(ctx, &x, 3 * ws->cand_cap, 3 * need, sizeof(double)));
    ws->cand_x = x;
    FCM_TRY(ctx, fcm__resize(ctx, &in, ws->cand_cap, need, sizeof(int)));
    ws->cand_in = in;
    ws->cand_cap = need;
  }
cleanup:
  return st;
}

/* Candidates into ws->cand_x (*count of them): the points of an (n + 1)^3 grid over box, its
 * faces included, that lie inside the reference cell and the body, up to nbnd of the
 * vertices and centroids of the boundary triangles' parts in the cell (ws->bnd), and with
 * extra > 0 up to extra of each of piece_candidates()' sets. Points on the material's boundary
 * let the fit reach moments that interior points alone cannot (a measure's spread). */
static fcm_status grid_candidates(const build *B, const fcm__embed_cell *cell, fcm__embed_ws *ws,
                                  const double box[6], int n, int nbnd, size_t extra, int *count)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const int tet = cell->info->shape == FCM_SHAPE_TET, np = n + 1;
  const size_t nx = extra ? piece_points(B, ws) : 0;
  const size_t need = (size_t)np * (size_t)np * (size_t)np + ws->bnd->n + nx;
  double h[3], *z = NULL;
  int *where = NULL;
  *count = 0;
  FCM_TRY(ctx, cand_room(ctx, ws, need));
  FCM_ALLOC(ctx, (size_t)np, z);
  FCM_ALLOC(ctx, (size_t)np, where);
  for (int d = 0; d < 3; d++)
    h[d] = (box[3 + d] - box[d]) / n;
  for (int k = 0; k < np; k++)
    z[k] = k == n ? box[5] : box[2] + k * h[2];
  for (int i = 0; i < np; i++)
    for (int j = 0; j < np; j++) {
      const double a = i == n ? box[3] : box[0] + i * h[0], b = j == n ? box[4] : box[1] + j * h[1];
      if (tet && a + b + z[0] > 1.0) continue;
      /* the column's points in the piece first: the body's line query only where one of them
       * lies in a part the body does not fill */
      int query = 0, any = 0;
      for (int k = 0; k < np; k++) {
        const double x[3] = {a, b, z[k]};
        where[k] = tet && a + b + z[k] > 1.0 ? 0 : in_piece(cell, ws, x);
        query |= where[k] == 1, any |= where[k] != 0;
      }
      if (!any) continue;
      if (query)
        FCM_TRY(ctx, fcm__embed_inside_column(ctx, B->geom, B->tri_tree, cell, a, b, np, z,
                                              ws->cand_in, &ws->cand, ws->cr));
      for (int k = 0; k < np; k++) {
        if (!where[k] || (query && ws->cand_in[k] != 1)) continue;
        double *x = ws->cand_x + 3 * (size_t)(*count)++;
        x[0] = a, x[1] = b, x[2] = z[k];
      }
    }
  /* at most nb of them, spread over the list (a finely triangulated surface has many) */
  const size_t nb = FCM_MIN(ws->bnd->n, (size_t)nbnd);
  for (size_t i = 0; i < nb; i++) {
    const size_t j = i * ws->bnd->n / nb;
    memcpy(ws->cand_x + 3 * (size_t)*count, ws->bnd->x + 3 * j, 3 * sizeof(double));
    *count += in_piece(cell, ws, ws->cand_x + 3 * (size_t)*count) != 0;
  }
  if (nx) FCM_TRY(ctx, piece_candidates(B, cell, ws, extra, count));
cleanup:
  fcm__free(ctx, z);
  fcm__free(ctx, where);
  return st;
}

/* Grid size that puts about `target` points inside material of reference volume v in box. */
static int grid_size(const double box[6], double v, double target)
{
  const double bv = (box[3] - box[0]) * (box[4] - box[1]) * (box[5] - box[2]);
  const double n = cbrt(target * bv / fmax(v, 1e-300));
  return (int)fmin(GRID_MAX, fmax(2.0, ceil(n)));
}

/* The limit fcm_cell_rules_options.max_rule_memory on the fit's peak: the signed rule (32
 * bytes a point), the candidate grid (28 bytes a point) and the fit's moment matrices (three of
 * M x candidates doubles). */
static fcm_status check_fit_memory(const build *B, const fcm__embed_cell *cell,
                                   const fcm__embed_ws *ws, int n, int M)
{
  fcm_status st = FCM_OK;
  const double limit = B->o->max_rule_memory,
               grid = (double)(n + 1) * (n + 1) * (n + 1) + (double)ws->bnd->n;
  const double need = 32.0 * (double)ws->sr->n + 28.0 * grid + 24.0 * M * grid;
  FCM_CHECK(limit <= 0.0 || need <= limit, B->ctx, FCM_ERR_UNSUPPORTED,
            "embed: background cell %lld: fitting its rules on %zu surface-moment points and "
            "%.0f candidates needs about %.3g GiB, above the limit of %.3g GiB "
            "(fcm_cell_rules_options.max_rule_memory; scene key quadrature.max_rule_memory_gib): "
            "raise the limit or lower the rule strengths",
            (long long)cell->id, ws->sr->n, grid, need / GIB, limit / GIB);
cleanup:
  return st;
}

/* The moment basis of strength m, degree <= q in each variable, on the material's box mapped
 * to [-1, 1]: a basis that the small material of a sliver cell does not make singular. */
static void fit_box(const double box[6], int m, int q, fcm__cheb_box *cb)
{
  cb->m = m;
  fcm__simplify_box_cap(cb, q);
  for (int d = 0; d < 3; d++) {
    const double a = box[d], b = box[3 + d];
    cb->scale[d] = 2.0 / (b - a);
    cb->shift[d] = -(a + b) / (b - a);
  }
}

/* Fit kind k's rule on the candidates (count of them) into o; *ok = 0 when they cannot carry
 * the moments. P: the candidates' basis in top's space, which holds kind k's (top->num_basis
 * rows, ld the same), of which the fit takes the rows of its own basis
 * (fcm__simplify_basis_rows(): the values do not depend on the space, bit for bit). */
static fcm_status fit_kind(const build *B, const fcm__embed_ws *ws, const double box[6], int count,
                           int k, const double *P, const fcm__cheb_box *top, piece_out *o, int *ok,
                           char *why, size_t why_len)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  fcm__cheb_box cb;
  fcm__fit f;
  double *mom = NULL, *work = NULL, *Pk = NULL;
  int *rows = NULL;
  memset(&f, 0, sizeof f);
  fit_box(box, B->space_m[k], B->space_q[k], &cb);
  const int M = cb.num_basis, Ptop = top->num_basis;
  const size_t ns = B->stabilize[k] ? (size_t)fcm_rule_num_points(B->full_rule[k]) : 0;
  FCM_ALLOC(ctx, (size_t)M, mom);
  FCM_ALLOC(ctx, fcm__simplify_moments_scratch(cb.m), work);
  FCM_ALLOC(ctx, (size_t)M, f.idx);
  FCM_ALLOC(ctx, (size_t)M, f.w);
  if (M < Ptop && count > 0) {
    FCM_ALLOC(ctx, (size_t)M, rows);
    fcm__simplify_basis_rows(top, &cb, rows);
    FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)count, Pk);
    for (int j = 0; j < count; j++)
      for (int i = 0; i < M; i++)
        Pk[(size_t)j * M + i] = P[(size_t)j * Ptop + rows[i]];
  }
  fcm__simplify_moments(&cb, (int)ws->sr->n, ws->sr->x, NULL, ws->sr->w, mom, work);
  /* the moments' rounding: about 1e-15 of the material box's reference volume */
  const double bv = (box[3] - box[0]) * (box[4] - box[1]) * (box[5] - box[2]);
  FCM_TRY(ctx, fcm__simplify_fit_basis(ctx, M, count, Pk ? Pk : P, mom,
                                       B->o->simplify_options.residual_tol, MOMENT_ATOL * bv, &f));
  *ok = f.ok;
  if (!f.ok) {
    snprintf(why, why_len,
             "%s rules of strength %d (degree <= %d per variable) on %d candidates: %s",
             fcm_rule_kind_name(k), cb.m, cb.q, count, f.message);
    goto cleanup;
  }
  fcm__free(ctx, o->pts[k]);
  fcm__free(ctx, o->w[k]);
  fcm__free(ctx, o->flag[k]);
  o->pts[k] = o->w[k] = NULL;
  o->flag[k] = NULL;
  FCM_ALLOC(ctx, 3 * ((size_t)f.count + ns), o->pts[k]);
  FCM_ALLOC(ctx, (size_t)f.count + ns, o->w[k]);
  FCM_ALLOC(ctx, (size_t)f.count + ns, o->flag[k]);
  for (int i = 0; i < f.count; i++) {
    memcpy(o->pts[k] + 3 * i, ws->cand_x + 3 * (size_t)f.idx[i], 3 * sizeof(double));
    o->w[k][i] = f.w[i];
  }
  o->n[k] = o->nsimp[k] = f.count;
  o->ninit[k] = count;
  o->residual[k] = f.residual;
cleanup:
  fcm__free(ctx, mom);
  fcm__free(ctx, work);
  fcm__free(ctx, Pk);
  fcm__free(ctx, rows);
  fcm__free(ctx, f.idx);
  fcm__free(ctx, f.w);
  return st;
}

/* Room for n points of kind k's rule in o, its previous arrays freed. */
static fcm_status kind_alloc(fcm_ctx *ctx, piece_out *o, int k, size_t n)
{
  fcm_status st = FCM_OK;
  fcm__free(ctx, o->pts[k]);
  fcm__free(ctx, o->w[k]);
  fcm__free(ctx, o->flag[k]);
  o->pts[k] = o->w[k] = NULL;
  o->flag[k] = NULL;
  FCM_ALLOC(ctx, 3 * n, o->pts[k]);
  FCM_ALLOC(ctx, n, o->w[k]);
  FCM_ALLOC(ctx, n, o->flag[k]);
cleanup:
  return st;
}

/* Kind k's rule as kind j's, fitted on the same candidates in the same space: the same
 * moments and basis give the same fit. */
static fcm_status copy_kind(const build *B, int j, int k, piece_out *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const size_t n = (size_t)o->n[j],
               ns = B->stabilize[k] ? (size_t)fcm_rule_num_points(B->full_rule[k]) : 0;
  FCM_TRY(ctx, kind_alloc(ctx, o, k, n + ns));
  memcpy(o->pts[k], o->pts[j], 3 * n * sizeof(double));
  memcpy(o->w[k], o->w[j], n * sizeof(double));
  o->n[k] = o->nsimp[k] = o->n[j];
  o->ninit[k] = o->ninit[j];
  o->residual[k] = o->residual[j];
cleanup:
  return st;
}

fcm_status fcm__embed_surface_piece_fit(const build *B, const fcm__embed_cell *cell,
                                        fcm__embed_ws *ws, const double mbox[6], double vol,
                                        piece_out *o, int *ok, char *why, size_t why_len)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  double box[6], *P = NULL, *work = NULL;
  int mmax = 0;
  memcpy(box, mbox, sizeof box);
  *ok = 0;
  for (int d = 0; d < 3; d++)
    if (!(box[d] < box[3 + d])) goto cleanup; /* flat material: leave it to the volume path */
  /* built or not, as the moments' degree; the candidates follow the size of the total-degree
   * space whatever a kind's cap per variable (a smaller grid for a tensor space would change the
   * other kind's rules fitted on the same candidates), or with the stiffness on the mass space
   * (one space for both kinds) that space's own size (B->grid_M) */
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    mmax = FCM_MAX(mmax, B->fit_strength[k]);
  const int Mmax = FCM_MAX(1, B->grid_M);
  const double vref = vol / cell->detA;
  int todo[FCM_RULE_KIND_COUNT], left = 0;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    left += todo[k] = B->tet_rule[k] != NULL;
  /* each kind on the first grid, then the kinds that failed on the finer ones: a kind's rules
   * do not depend on the other kind. A grid capped at GRID_MAX with all the boundary points
   * and the piece's points gives the candidates of the attempt before, on which the kinds left
   * failed: the attempts end there. */
  int last_n = -1, last_nb = -1;
  size_t last_x = 0;
  for (int attempt = 0, grow = 1; attempt < ATTEMPTS && left > 0; attempt++, grow *= GROW) {
    const double target = fcm__fit_candidates_per_moment(mmax) * Mmax * grow;
    const int n = grid_size(box, vref, target), nbnd = BOUNDARY_PER_MOMENT * Mmax * grow;
    const int nb = (int)FCM_MIN(ws->bnd->n, (size_t)nbnd);
    const size_t extra = attempt == 0 || !ws->cand_parts ? 0
                         : attempt == ATTEMPTS - 1       ? SIZE_MAX
                                                         : (size_t)PIECE_PER_BOUNDARY * nbnd;
    const size_t xkey = extra ? FCM_MIN(extra, piece_points(B, ws)) : 0; /* what extra takes */
    int count;
    if (attempt > 0 && n == last_n && nb == last_nb && xkey == last_x) break;
    last_n = n, last_nb = nb, last_x = xkey;
    FCM_TRY(ctx, check_fit_memory(B, cell, ws, n, Mmax));
    FCM_TRY(ctx, grid_candidates(B, cell, ws, box, n, nbnd, extra, &count));
    /* the kinds' bases on the candidates, evaluated once in the space of the highest strength
     * and per-variable degree left, which holds every kind's */
    int mtop = 0, qtop = 0;
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
      if (todo[k]) mtop = FCM_MAX(mtop, B->space_m[k]), qtop = FCM_MAX(qtop, B->space_q[k]);
    fcm__cheb_box cb;
    fit_box(box, mtop, qtop, &cb);
    fcm__free(ctx, P);
    P = NULL;
    if (count > 0) {
      FCM_ALLOC_RAW(ctx, (size_t)cb.num_basis * (size_t)count, P);
      FCM_ALLOC_RAW(ctx, fcm__simplify_moments_scratch(mtop), work);
      fcm__simplify_basis_points(&cb, count, ws->cand_x, P, work);
      fcm__free(ctx, work);
      work = NULL;
    }
    int fitted[FCM_RULE_KIND_COUNT] = {0}; /* on this grid */
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      if (!todo[k]) continue;
      int done, same = -1;
      for (int j = 0; j < k; j++)
        if (fitted[j] && B->space_m[j] == B->space_m[k] && B->space_q[j] == B->space_q[k]) same = j;
      if (same >= 0) {
        FCM_TRY(ctx, copy_kind(B, same, k, o));
        done = 1;
      } else {
        FCM_TRY(ctx, fit_kind(B, ws, box, count, k, P, &cb, o, &done, why, why_len));
      }
      if (done) todo[k] = 0, left--, fitted[k] = 1;
    }
  }
  *ok = left == 0;
cleanup:
  fcm__free(ctx, P);
  fcm__free(ctx, work);
  o->fitted = (unsigned char)*ok;
  if (!*ok) /* leave no kind half fitted: the volume path starts from an empty piece */
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      fcm__free(ctx, o->pts[k]);
      fcm__free(ctx, o->w[k]);
      fcm__free(ctx, o->flag[k]);
      o->pts[k] = o->w[k] = NULL;
      o->flag[k] = NULL;
      o->n[k] = o->ninit[k] = o->nsimp[k] = 0;
    }
  return st;
}

void fcm__embed_surface_ws_free(fcm_ctx *ctx, fcm__embed_ws *ws)
{
  if (ws->sr) fcm__srule_free(ctx, ws->sr);
  if (ws->cr) fcm__crossings_free(ctx, ws->cr);
  if (ws->bnd) fcm__srule_free(ctx, ws->bnd);
  fcm__free(ctx, ws->sr);
  fcm__free(ctx, ws->cr);
  fcm__free(ctx, ws->bnd);
  fcm__free(ctx, ws->cand_x);
  fcm__free(ctx, ws->cand_in);
  fcm__free(ctx, ws->cand_pl);
  ws->cand_pl = NULL;
  ws->cand_npl = ws->cand_plcap = 0;
  ws->sr = NULL, ws->cr = NULL, ws->bnd = NULL, ws->cand_x = NULL, ws->cand_in = NULL;
  ws->cand_cap = 0;
}

/* The points of the strongest built tet rule on the fan tets of the convex polyhedron p,
 * appended to s (reference coordinates of cell): the exact rule of a part the body fills. */
static fcm_status full_part_rule(const build *B, const fcm__embed_cell *cell, const fcm__poly *p,
                                 fcm__srule *s)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_rule *rule = piece_rule(B);
  const int nq = fcm_rule_num_points(rule), nt0 = fcm__geom_poly_num_tets(p);
  const double *eta = fcm_rule_points(rule), *l = fcm_rule_weights(rule);
  double *tets = NULL, *vol = NULL;
  FCM_ALLOC(ctx, 12 * (size_t)nt0 + 12, tets);
  FCM_ALLOC(ctx, (size_t)nt0 + 1, vol);
  const int nt = fcm__geom_poly_tets(p, tets, vol);
  FCM_TRY(ctx, fcm__srule_room(ctx, s, (size_t)nt * nq));
  for (int t = 0; t < nt; t++) {
    const double *T = tets + 12 * t;
    for (int q = 0; q < nq; q++) {
      const double *e = eta + 3 * q;
      double x[3], det = cell->detA;
      for (int d = 0; d < 3; d++)
        x[d] =
            T[d] + e[0] * (T[3 + d] - T[d]) + e[1] * (T[6 + d] - T[d]) + e[2] * (T[9 + d] - T[d]);
      if (cell->affine)
        fcm__embed_to_reference_affine(cell, x, s->x + 3 * s->n);
      else
        FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, x, s->x + 3 * s->n, &det));
      s->w[s->n++] = l[q] * 6.0 * vol[t] / det;
    }
  }
cleanup:
  fcm__free(ctx, tets);
  fcm__free(ctx, vol);
  return st;
}

/* The rules of a piece whose parts the body fills and which are boxes in reference
 * coordinates, without a fit: the 2-point Gauss rule per axis on each box (8 points, positive,
 * inside), exact for degree 3 in each variable, so on every kind's space when no kind's space
 * holds a degree above 3 in a variable and the points fit in each kind's M. Taken only with the
 * stiffness on the mass space, where every kind's rule is exact for its integrand: another exact
 * rule changes the results at round-off. *ok = 0: not such a piece (o untouched). */
static fcm_status box_piece_rule(const build *B, const fcm__embed_cell *cell, const fcm__parts *P,
                                 int piece, piece_out *o, int *ok)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  double lo[FCM__BOX_PIECE_PARTS][3], hi[FCM__BOX_PIECE_PARTS][3];
  int nb = 0;
  *ok = 0;
  if (!B->o->stiffness_on_mass_space || P->whole || cell->info->num_corners != 8) return FCM_OK;
  for (size_t j = 0; j < P->n; j++) {
    if (P->piece[j] != piece) continue;
    int is_box;
    if (nb == FCM__BOX_PIECE_PARTS || !fcm__embed_part_full(P, j)) return FCM_OK;
    FCM_TRY(ctx, fcm__embed_part_box(ctx, cell, P->poly + j, lo[nb], hi[nb], &is_box));
    if (!is_box) return FCM_OK;
    nb++;
  }
  if (nb == 0) return FCM_OK;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!B->tet_rule[k]) continue;
    fcm__cheb_box cb;
    const double unit[6] = {-1, -1, -1, 1, 1, 1};
    fit_box(unit, B->space_m[k], B->space_q[k], &cb);
    if (FCM_MIN(B->space_m[k], B->space_q[k]) > 3 || 8 * nb > cb.num_basis) return FCM_OK;
  }
  const double g = 1.0 / sqrt(3.0);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!B->tet_rule[k]) continue;
    const size_t n = 8 * (size_t)nb,
                 ns = B->stabilize[k] ? (size_t)fcm_rule_num_points(B->full_rule[k]) : 0;
    FCM_TRY(ctx, kind_alloc(ctx, o, k, n + ns));
    for (int b = 0; b < nb; b++) {
      double c[3], h[3];
      for (int d = 0; d < 3; d++)
        c[d] = 0.5 * (lo[b][d] + hi[b][d]), h[d] = 0.5 * (hi[b][d] - lo[b][d]);
      for (int i = 0; i < 8; i++) {
        double *x = o->pts[k] + 3 * (8 * (size_t)b + (size_t)i);
        for (int d = 0; d < 3; d++)
          x[d] = c[d] + ((i >> d) & 1 ? g : -g) * h[d];
        o->w[k][8 * b + i] = h[0] * h[1] * h[2];
      }
    }
    o->n[k] = o->nsimp[k] = o->ninit[k] = (int)n;
    o->residual[k] = 0.0;
  }
  o->fitted = 1;
  *ok = 1;
cleanup:
  return st;
}

fcm_status fcm__embed_surface_cut_piece(const build *B, const fcm__embed_cell *cell,
                                        fcm__embed_ws *ws, fcm__parts *P, int piece, piece_out *o,
                                        int *fell_back)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  double mbox[6], box[6], v;
  int touched, ok = 0;
  char why[256] = "";
  *fell_back = 0;
  FCM_CHECK(cell->affine, ctx, FCM_ERR_UNSUPPORTED,
            "embed: background cell %lld, which a cut reaches, is not affine: the pieces of a "
            "body without a volume mesh take their moments from its surface, which needs an "
            "affine cell",
            (long long)cell->id);
  FCM_TRY(ctx, box_piece_rule(B, cell, P, piece, o, &ok));
  if (ok) return FCM_OK;
  FCM_TRY(ctx, ws_surface(ctx, ws));
  FCM_TRY(ctx, fcm__embed_material_box(ctx, B->geom, B->tri_tree, cell, &ws->cand, ws->cr, ws->bnd,
                                       mbox, &touched));
  for (int d = 0; d < 3; d++)
    box[d] = HUGE_VAL, box[3 + d] = -HUGE_VAL;
  ws->sr->n = 0;
  ws->cand_npl = 0;
  for (size_t j = 0; j < P->n; j++) {
    if (P->piece[j] != piece) continue;
    for (int a = 0; a < P->poly[j].nv; a++) {
      double xi[3], det;
      FCM_TRY(ctx, fcm__embed_to_reference(ctx, cell, P->poly[j].x[a], xi, &det));
      for (int d = 0; d < 3; d++)
        box[d] = fmin(box[d], xi[d]), box[3 + d] = fmax(box[3 + d], xi[d]);
    }
    if (P->whole)
      FCM_TRY(ctx, fcm__material_cell(ctx, P->mat, &B->mq, cell, ws->sr, &v));
    else if (fcm__embed_part_full(P, j)) /* wholly inside the body: a tet rule on its fan */
      FCM_TRY(ctx, full_part_rule(B, cell, P->poly + j, ws->sr));
    else
      FCM_TRY(ctx, fcm__material_poly(ctx, P->mat, P->poly + j, &B->mq, cell, ws->sr, &v));
    fcm__plane pl[FCM__POLY_MAX_FACES];
    const int c = fcm__embed_part_planes(P, j, pl);
    if (ws->cand_npl + 3 + 4 * (size_t)c > ws->cand_plcap) {
      size_t cap = ws->cand_plcap ? 2 * ws->cand_plcap : 1024;
      while (cap < ws->cand_npl + 3 + 4 * (size_t)c)
        cap *= 2;
      void *q = ws->cand_pl;
      FCM_TRY(ctx, fcm__resize(ctx, &q, ws->cand_npl, cap, sizeof(double)));
      ws->cand_pl = q;
      ws->cand_plcap = cap;
    }
    ws->cand_pl[ws->cand_npl++] = c;
    ws->cand_pl[ws->cand_npl++] = P->tol[j];
    ws->cand_pl[ws->cand_npl++] = !P->whole && fcm__embed_part_full(P, j);
    for (int f = 0; f < c; f++) {
      memcpy(ws->cand_pl + ws->cand_npl, pl[f].n, 3 * sizeof(double));
      ws->cand_pl[ws->cand_npl + 3] = pl[f].d;
      ws->cand_npl += 4;
    }
  }
  for (int d = 0; d < 3 && touched; d++) /* the material's own box where the surface bounds it */
    box[d] = fmax(box[d], mbox[d]), box[3 + d] = fmin(box[3 + d], mbox[3 + d]);
  ws->cand_parts = P, ws->cand_piece = piece;
  const double fill =
      o->volume / cell->detA / ((box[3] - box[0]) * (box[4] - box[1]) * (box[5] - box[2]));
  const double min_fill = B->o->stiffness_on_mass_space ? PIECE_MIN_FILL_EXACT : PIECE_MIN_FILL;
  if (fill < min_fill)
    snprintf(why, sizeof why, "it fills %.3g of its box, below %g", fill, min_fill);
  else
    st = fcm__embed_surface_piece_fit(B, cell, ws, box, o->volume, o, &ok, why, sizeof why);
  ws->cand_parts = NULL;
  FCM_TRY(ctx, st);
  if (!ok) { /* a thin or small piece: its parts split by the boundary triangles, the volume path */
    FCM_TRY(ctx, fcm__embed_piece_body_tets(ctx, cell, P, piece, ws, &v));
    FCM_CHECK(ws->num_tets > 0, ctx, FCM_ERR_GEOMETRY,
              "embed: background cell %lld, piece %d: no positive rule on points inside the piece "
              "carries its surface moments (volume %.3g; %s), and splitting it by the boundary "
              "triangles leaves no material",
              (long long)cell->id, piece, o->volume, why);
    FCM_TRY(ctx, fcm__embed_map_piece(B, cell, ws, o));
    *fell_back = 1;
  }
cleanup:
  return st;
}
