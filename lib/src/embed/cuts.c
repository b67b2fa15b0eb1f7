/* Cut surfaces in the cut-cell rules: the cells the cuts reach and their region, and the
 * links between the material pieces of face-neighbouring cells. */
#include "embed/rules_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cmp_link(const void *a, const void *b)
{
  const fcm_index *x = a, *y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return (x[1] > y[1]) - (x[1] < y[1]);
}

/* A pair of region cells that the new cut does not reach, both in the region of the rules
 * being extended: their pieces are those rules' pieces, their face polygons too, and the new
 * triangles lie beyond the link tests' reach (a triangle within it would be a candidate of
 * the cells), so the tests give what they gave there and their links are those rules' links. */
static int links_kept(const build *B, fcm_index a, fcm_index b)
{
  return B->keep && B->prev_region && !B->rebuild[a] && !B->rebuild[b] && B->prev_region[a] &&
         B->prev_region[b];
}

/* B->same_links: the region cells whose links with every face neighbour in the region are
 * kept (links_kept()): they need no face polygons. */
static fcm_status same_links(build *B)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *mesh = B->mesh;
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  const int nf = fcm_mesh_get_element_info(mesh)->num_faces;
  const fcm_index *nbr = fcm_mesh_neighbors(mesh);
  FCM_ALLOC(B->ctx, (size_t)nc + 1, B->same_links);
  for (fcm_index c = 0; c < nc; c++) {
    int same = B->region[c] && links_kept(B, c, c);
    for (int f = 0; f < nf && same; f++) {
      const fcm_index c2 = nbr[(size_t)nf * c + f];
      same = c2 < 0 || !B->region[c2] || links_kept(B, c, c2);
    }
    B->same_links[c] = (unsigned char)same;
  }
cleanup:
  return st;
}

/* A face between cells of different octree levels: face ff of the finer cell lies inside face
 * fc of the coarser one (a quarter of it under 2:1 balance). */
typedef struct nc_pair {
  fcm_index fine, coarse;
  int ff, fc;
} nc_pair;

static int cmp_nc_pair(const void *a, const void *b)
{
  const nc_pair *x = a, *y = b;
  if (x->fine != y->fine) return x->fine < y->fine ? -1 : 1;
  return (x->ff > y->ff) - (x->ff < y->ff);
}

/* Face fc of the coarse cell whose plane holds face ff of the fine cell, and that contains the
 * centre of that face, or -1. */
static int nc_match(const fcm__embed_cell *fine, int ff, const fcm__embed_cell *coarse)
{
  const fcm__plane *pf = fine->planes + ff;
  const double tol = FCM__EMBED_MATCH_RTOL * fine->size;
  double x[3], s = pf->d;
  for (int d = 0; d < 3; d++)
    x[d] = 0.5 * (fine->lo[d] + fine->hi[d]);
  for (int d = 0; d < 3; d++)
    s -= pf->n[d] * x[d];
  for (int d = 0; d < 3; d++) {
    x[d] += s * pf->n[d];
    if (x[d] < coarse->lo[d] || x[d] > coarse->hi[d]) return -1;
  }
  for (int g = 0; g < coarse->num_planes; g++) {
    const fcm__plane *pc = coarse->planes + g;
    if (pc->n[0] * pf->n[0] + pc->n[1] * pf->n[1] + pc->n[2] * pf->n[2] > -0.5) continue;
    if (fabs(pc->d + pf->d) <= tol) return g;
  }
  return -1;
}

/* The non-conforming face pairs of an octree mesh (none without hanging nodes), one per face of
 * a finer cell, sorted: found through the hanging pairs, since every such face has a corner
 * hanging on the coarser cell (the coarse face's centre). */
static fcm_status nc_pairs(const build *B, nc_pair **out, size_t *np)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_mesh *mesh = B->mesh;
  const fcm_index nc = fcm_mesh_num_cells(mesh), nn = fcm_mesh_num_nodes(mesh);
  const fcm_index nh = fcm_mesh_num_hanging(mesh);
  const int npc = fcm_mesh_nodes_per_cell(mesh), nf = fcm_mesh_get_element_info(mesh)->num_faces;
  const fcm_index *cells = fcm_mesh_cells(mesh), *nbr = fcm_mesh_neighbors(mesh);
  fcm_index *ptr = NULL, *inc = NULL;
  nc_pair *p = NULL;
  size_t n = 0, cap = 0;
  *out = NULL, *np = 0;
  if (nh == 0) return FCM_OK;
  FCM_ALLOC(ctx, (size_t)nn + 2, ptr);
  for (size_t i = 0; i < (size_t)nc * (size_t)npc; i++)
    ptr[cells[i] + 2]++;
  for (fcm_index k = 0; k < nn; k++)
    ptr[k + 2] += ptr[k + 1];
  FCM_ALLOC(ctx, (size_t)nc * (size_t)npc + 1, inc);
  for (size_t i = 0; i < (size_t)nc * (size_t)npc; i++)
    inc[ptr[cells[i] + 1]++] = (fcm_index)(i / (size_t)npc);
  for (fcm_index i = 0; i < nh; i++) {
    fcm_index c2 = 0, h = 0;
    fcm_mesh_get_hanging(mesh, i, &c2, &h, NULL);
    fcm__embed_cell coarse;
    FCM_TRY(ctx, fcm__embed_cell_setup(ctx, mesh, c2, B->o->clip_rtol, &coarse));
    for (fcm_index k = ptr[h]; k < ptr[h + 1]; k++) {
      const fcm_index c = inc[k];
      fcm__embed_cell fine;
      int setup = 0;
      for (int f = 0; f < nf; f++) {
        if (nbr[(size_t)nf * c + f] != FCM_MESH_NEIGHBOR_NONCONFORMING) continue;
        if (!setup) FCM_TRY(ctx, fcm__embed_cell_setup(ctx, mesh, c, B->o->clip_rtol, &fine));
        setup = 1;
        const int g = nc_match(&fine, f, &coarse);
        if (g < 0) continue;
        if (n == cap) {
          const size_t ncap = cap ? 2 * cap : 64;
          void *q = p;
          FCM_TRY(ctx, fcm__resize(ctx, &q, cap, ncap, sizeof *p));
          p = q, cap = ncap;
        }
        p[n++] = (nc_pair){c, c2, f, g};
      }
    }
  }
  if (n) qsort(p, n, sizeof *p, cmp_nc_pair);
  size_t u = 0;
  for (size_t i = 0; i < n; i++)
    if (u == 0 || cmp_nc_pair(p + u - 1, p + i) != 0) p[u++] = p[i];
  *out = p, *np = u;
  p = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, inc);
  fcm__free(ctx, p);
  return st;
}

/* Cells whose links across a non-conforming face are not the extended rules' need their face
 * polygons (B->same_links cleared). */
static fcm_status nc_same_links(build *B)
{
  fcm_status st = FCM_OK;
  nc_pair *p = NULL;
  size_t np = 0;
  FCM_TRY(B->ctx, nc_pairs(B, &p, &np));
  for (size_t i = 0; i < np; i++) {
    const fcm_index a = FCM_MIN(p[i].fine, p[i].coarse), b = FCM_MAX(p[i].fine, p[i].coarse);
    if (!B->region[a] || !B->region[b] || links_kept(B, a, b)) continue;
    B->same_links[a] = B->same_links[b] = 0;
  }
cleanup:
  fcm__free(B->ctx, p);
  return st;
}

/* reached_cells(): the bits of a cell the cuts reach */
enum { REACH = 1, REACH_EARLIER = 2, REACH_NEW = 4 };

/* Whether cell c's corners lie beyond the box lo..hi (all the cut triangles' boxes) along
 * some axis by more than the widening of its box in fcm__embed_cut_candidates() (the cell's
 * clip tolerance and twice the match tolerance of its size, the diagonal of its corners' box,
 * at most the sum of its sides), with a factor two and a margin above the rounding: then no
 * cut triangle's box meets the widened cell box, and the cell needs neither its box's size
 * nor a query of the tree. */
static int far_from_cuts(const fcm_mesh *mesh, int corners, double clip_rtol, fcm_index c,
                         const double lo[3], const double hi[3])
{
  const fcm_index *nodes = fcm_mesh_cells(mesh) + (size_t)fcm_mesh_nodes_per_cell(mesh) * c;
  const double *X = fcm_mesh_coords(mesh);
  double a[3], b[3];
  for (int d = 0; d < 3; d++)
    a[d] = b[d] = X[3 * nodes[0] + d];
  for (int k = 1; k < corners; k++)
    for (int d = 0; d < 3; d++) {
      const double x = X[3 * nodes[k] + d];
      a[d] = x < a[d] ? x : a[d], b[d] = x > b[d] ? x : b[d];
    }
  const double ext = (b[0] - a[0]) + (b[1] - a[1]) + (b[2] - a[2]);
  const double grow = 2.0 * (clip_rtol + 2.0 * FCM__EMBED_MATCH_RTOL) * ext;
  for (int d = 0; d < 3; d++) {
    const double m = grow + 1e-12 * (fabs(a[d]) + fabs(b[d]));
    if (a[d] - m > hi[d] || b[d] + m < lo[d]) return 1;
  }
  return 0;
}

/* Per cell, in parallel, into hit: 0 where no cut triangle's box meets the cell's (widened by
 * twice the match tolerance), else REACH, with REACH_EARLIER when a triangle before first_new
 * does, REACH_NEW when one from first_new on does. */
static fcm_status reached_cells(const build *B, fcm_index first_new, unsigned char *hit)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index nc = fcm_mesh_num_cells(B->mesh);
  const int corners = fcm_mesh_get_element_info(B->mesh)->num_corners;
  double lo[3], hi[3];
  if (!fcm__geom_tree_bounds(B->cut_tree, lo, hi)) return FCM_OK; /* no triangle: none reached */
  fcm__loop loop;
  fcm__loop_begin(ctx, &loop);
#pragma omp parallel num_threads(fcm_ctx_num_threads(ctx))
  {
    fcm__idbuf ids = {NULL, 0, 0};
#pragma omp for schedule(static)
    for (fcm_index c = 0; c < nc; c++) {
      if (far_from_cuts(B->mesh, corners, B->o->clip_rtol, c, lo, hi)) continue;
      if (fcm__loop_skip(&loop, c)) continue;
      fcm__loop_iter it;
      fcm__loop_enter(&loop, &it, c);
      fcm__embed_cell cell; /* its box only: the checks of its set-up come with its own work */
      fcm__embed_cell_box(B->mesh, c, B->o->clip_rtol, &cell);
      const fcm_status s = fcm__embed_cut_candidates(ctx, B->cut_tree, &cell, &ids);
      if (s == FCM_OK && ids.n > 0) /* ids ascending: the earlier cuts' triangles first */
        hit[c] = (unsigned char)(REACH | (ids.ids[0] < first_new ? REACH_EARLIER : 0) |
                                 (ids.ids[ids.n - 1] >= first_new ? REACH_NEW : 0));
      fcm__loop_leave(&loop, &it, s);
    }
    fcm__geom_idbuf_free(ctx, &ids);
  }
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
cleanup:
  return st;
}

/* Phase 1c (cuts only): the tree of R's cut triangles, the region (cells sharing a node with
 * a cell the cuts reach) and, when extending `prev` by the triangles from first_new on,
 * the cells to integrate (those the new triangles reach). */
fcm_status fcm__embed_cut_setup(build *B, fcm_cell_rules *R, fcm_index first_new)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_mesh *mesh = B->mesh;
  const fcm_index nc = fcm_mesh_num_cells(mesh), nn = fcm_mesh_num_nodes(mesh);
  const int npc = fcm_mesh_nodes_per_cell(mesh);
  const fcm_index *cells = fcm_mesh_cells(mesh);
  double *boxes = NULL;
  unsigned char *node_hit = NULL; /* 1: a cell the cuts reach holds the node; 2: the earlier */
  FCM_ALLOC(ctx, 6 * (size_t)R->num_cut_tris + 6, boxes);
  for (fcm_index t = 0; t < R->num_cut_tris; t++) {
    memcpy(boxes + 6 * t, R->cut_tris[t].lo, 3 * sizeof(double));
    memcpy(boxes + 6 * t + 3, R->cut_tris[t].hi, 3 * sizeof(double));
  }
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, R->num_cut_tris, boxes, &B->cut_tree));
  B->cut_tris = R->cut_tris;
  FCM_ALLOC(ctx, (size_t)nc + 1, B->region);
  FCM_ALLOC(ctx, (size_t)nn + 1, node_hit);
  fcm__free(ctx, R->reached);
  R->reached = NULL;
  FCM_ALLOC(ctx, (size_t)nc + 1, R->reached);
  if (B->prev) FCM_ALLOC(ctx, (size_t)nc + 1, B->rebuild);
  if (B->geom->num_cells == 0) { /* the whole cells' material, kept from cut to cut */
    fcm__free(ctx, R->cell_mvol);
    R->cell_mvol = NULL;
    FCM_ALLOC(ctx, (size_t)nc + 1, R->cell_mvol);
    for (fcm_index c = 0; c < nc; c++)
      R->cell_mvol[c] = B->prev && B->prev->cell_mvol ? B->prev->cell_mvol[c] : NAN;
    B->cell_mvol = R->cell_mvol;
  }
  fcm__free(ctx, R->cell_volume);
  R->cell_volume = NULL;
  FCM_ALLOC(ctx, (size_t)nc + 1, R->cell_volume);
  for (fcm_index c = 0; c < nc; c++)
    R->cell_volume[c] = B->prev && B->prev->cell_volume ? B->prev->cell_volume[c] : NAN;
  if (B->prev && first_new > 0) FCM_ALLOC(ctx, (size_t)nc + 1, B->prev_region);
  FCM_TRY(ctx, reached_cells(B, first_new, R->reached));
  for (fcm_index c = 0; c < nc; c++) {
    const unsigned char h = R->reached[c];
    if (!h) continue;
    for (int a = 0; a < npc; a++)
      node_hit[cells[(size_t)npc * c + a]] |= (unsigned char)(h & REACH_EARLIER ? 3 : 1);
    if (B->rebuild && h & REACH_NEW) B->rebuild[c] = 1;
    R->reached[c] = 1;
  }
  for (fcm_index c = 0; c < nc; c++)
    for (int a = 0; a < npc; a++) {
      const unsigned char h = node_hit[cells[(size_t)npc * c + a]];
      B->region[c] |= h != 0;
      if (B->prev_region) B->prev_region[c] |= (h & 2) != 0;
    }
  if (B->prev_region && B->keep) FCM_TRY(ctx, same_links(B));
  if (B->same_links) FCM_TRY(ctx, nc_same_links(B));
cleanup:
  fcm__free(ctx, boxes);
  fcm__free(ctx, node_hit);
  return st;
}

/* Whether the earlier pieces qa of cell ca and qb of cell cb (ca < cb, face neighbours) were
 * linked in the rules being extended: a cut only separates, so pieces whose parents it had
 * separated stay apart, whatever the face tests on the new, smaller pieces say (near a cut
 * within the tolerances those can differ). Cells outside the earlier region had one piece
 * each, linked to its neighbours'. */
static int earlier_link(const build *B, fcm_index ca, fcm_index cb, int qa, int qb)
{
  if (!B->prev_region || !B->prev_region[ca] || !B->prev_region[cb]) return 1;
  const fcm_cell_rules *Q = B->prev;
  const fcm_index key[2] = {Q->piece_off[ca] + qa, Q->piece_off[cb] + qb};
  return bsearch(key, Q->links, (size_t)Q->num_links, 2 * sizeof *Q->links, cmp_link) != NULL;
}

/* Append the link (pa, pb) to *links (*nl of them, room for *cap). */
static fcm_status push_link(fcm_ctx *ctx, fcm_index pa, fcm_index pb, fcm_index **links, size_t *nl,
                            size_t *cap)
{
  fcm_status st = FCM_OK;
  if (*nl + 1 > *cap) { /* a cell's list holds a few links: grown from 8, not zeroed */
    const size_t ncap = *cap ? 2 * *cap : 8;
    fcm_index *q = NULL;
    FCM_ALLOC_RAW(ctx, 2 * ncap, q);
    if (*nl) memcpy(q, *links, 2 * *nl * sizeof *q);
    fcm__free(ctx, *links);
    *links = q;
    *cap = ncap;
  }
  (*links)[2 * *nl] = pa, (*links)[2 * *nl + 1] = pb;
  (*nl)++;
cleanup:
  return st;
}

/* The links between the pieces of cells ca < cb that the rules being extended have
 * (links_kept()), renumbered as R's pieces (the cells kept theirs, in the same order). */
static fcm_status copy_links(const build *B, const fcm_cell_rules *R, fcm_index ca, fcm_index cb,
                             fcm_index **links, size_t *nl, size_t *cap)
{
  fcm_status st = FCM_OK;
  const fcm_cell_rules *Q = B->prev;
  const fcm_index qa0 = Q->piece_off[ca], qb0 = Q->piece_off[cb], qb1 = Q->piece_off[cb + 1];
  const fcm_index l0 = fcm__lower_bound(Q->links, 2, 0, Q->num_links, qa0); /* ca's first */
  for (fcm_index l = l0; l < Q->num_links && Q->links[2 * l] < Q->piece_off[ca + 1]; l++) {
    const fcm_index qa = Q->links[2 * l], qb = Q->links[2 * l + 1];
    if (qb < qb0 || qb >= qb1) continue;
    FCM_TRY(B->ctx, push_link(B->ctx, R->piece_off[ca] + (qa - qa0), R->piece_off[cb] + (qb - qb0),
                              links, nl, cap));
  }
cleanup:
  return st;
}

/* Whether the box lo..hi lies in the box of `cell` that reached_cells() queries
 * (fcm__embed_cut_candidates()): a query of lo..hi then finds a subset of what that one finds. */
static int within_reach_box(const fcm__embed_cell *cell, const double lo[3], const double hi[3])
{
  const double w = 2.0 * FCM__EMBED_MATCH_RTOL * cell->size;
  for (int d = 0; d < 3; d++)
    if (!(lo[d] >= cell->lo[d] - w && hi[d] <= cell->hi[d] + w)) return 0;
  return 1;
}

/* The links across one face shared by cells c (its face f) and c2 (its face f2), `cell` set
 * up for c: a polygon of a piece of c on the face overlaps a polygon of a piece of c2 on its
 * face with positive area, wider than the tolerance's band (fcm__embed_linked()), the overlap does
 * not lie on a cut triangle, their parents were linked (earlier_link()) and, without a volume mesh
 * (`mat`), the overlap holds material. The overlap test does not need equal faces, so a fine face
 * inside a coarse one (an octree's non-conforming face) is tested alike. Each link is stored from
 * the piece of the lower-numbered cell. */
static fcm_status face_links(const build *B, const fcm_cell_rules *R, const cell_out *out,
                             const fcm__embed_cell *cell, fcm_index c, int f, fcm_index c2, int f2,
                             fcm__material *mat, fcm__idbuf *tc, fcm_index **links, size_t *nl,
                             size_t *cap)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index ca = FCM_MIN(c, c2), cb = FCM_MAX(c, c2);
  if (links_kept(B, ca, cb)) return copy_links(B, R, ca, cb, links, nl, cap);
  const double mtol = FCM__EMBED_MATCH_RTOL * cell->size, atol = 1e-12 * cell->size * cell->size;
  const double *nf = cell->planes[f].n; /* the polygons of c2 face out of c2: normal -n_f */
  const double nbn[3] = {-nf[0], -nf[1], -nf[2]};
  const cell_out *oa = out + c, *ob = out + c2;
  const size_t nl0 = *nl; /* the links of this pair of cells start here */
  size_t xa = 0;
  for (int i = 0; i < oa->nfp; i++) {
    const int *ma = oa->fmeta + FCM__EMBED_FMETA * i;
    const double *A = oa->fx + 3 * xa;
    xa += (size_t)(ma[2] + ma[3]);
    if (ma[0] != f || ma[1] < 0) continue;
    size_t xb = 0;
    int queried = 0; /* tc holds the cut triangles near polygon i */
    for (int j = 0; j < ob->nfp; j++) {
      const int *mb = ob->fmeta + FCM__EMBED_FMETA * j;
      const double *Bx = ob->fx + 3 * xb;
      xb += (size_t)(mb[2] + mb[3]);
      if (mb[0] != f2 || mb[1] < 0) continue;
      const int qa = c < c2 ? ma[1] : mb[1], qb = c < c2 ? mb[1] : ma[1];
      const fcm_index pa = R->piece_off[ca] + qa, pb = R->piece_off[cb] + qb;
      int known = 0;
      for (size_t l = *nl; l-- > nl0 && !known;)
        known = (*links)[2 * l] == pa && (*links)[2 * l + 1] == pb;
      if (known) continue;
      if (!queried) {
        double lo[3], hi[3];
        for (int d = 0; d < 3; d++) {
          lo[d] = HUGE_VAL, hi[d] = -HUGE_VAL;
          for (int k = 0; k < ma[2]; k++)
            lo[d] = fmin(lo[d], A[3 * k + d] - mtol), hi[d] = fmax(hi[d], A[3 * k + d] + mtol);
        }
        if (R->reached[c] || !within_reach_box(cell, lo, hi))
          FCM_TRY(ctx, fcm__geom_tree_query(ctx, B->cut_tree, lo, hi, tc));
        else
          tc->n = 0; /* no triangle meets the larger box of cell c (reached_cells()) */
        queried = 1;
      }
      if (!fcm__embed_linked(A, ma[2], A + 3 * ma[2], ma[3], Bx, mb[2], Bx + 3 * mb[2], mb[3], nbn,
                             mtol, atol, B->cut_tris, tc->ids, tc->n))
        continue;
      if (!earlier_link(B, ca, cb, out[ca].pc[qa].parent, out[cb].pc[qb].parent)) continue;
      if (mat && !fcm__embed_overlap_material_full(ctx, mat, cell, A, ma[2], Bx, mb[2], nbn,
                                                   ma[4] || mb[4]))
        continue;
      if (mat) FCM_TRY(ctx, fcm__material_status(mat));
      FCM_TRY(ctx, push_link(ctx, pa, pb, links, nl, cap));
    }
  }
cleanup:
  return st;
}

/* The links across every non-conforming face of an octree mesh (face_links() from the fine
 * cell's side). */
static fcm_status nc_links(const build *B, const fcm_cell_rules *R, const cell_out *out,
                           fcm__material *mat, fcm__idbuf *tc, fcm_index **links, size_t *nl,
                           size_t *cap)
{
  fcm_status st = FCM_OK;
  nc_pair *p = NULL;
  size_t np = 0;
  FCM_TRY(B->ctx, nc_pairs(B, &p, &np));
  for (size_t i = 0; i < np; i++) {
    const fcm_index c = p[i].fine, c2 = p[i].coarse;
    if (!B->region[c] || !B->region[c2] || out[c].np == 0 || out[c2].np == 0) continue;
    fcm__embed_cell cell;
    FCM_TRY(B->ctx, fcm__embed_cell_setup(B->ctx, B->mesh, c, B->o->clip_rtol, &cell));
    FCM_TRY(B->ctx, face_links(B, R, out, &cell, c, p[i].ff, c2, p[i].fc, mat, tc, links, nl, cap));
  }
cleanup:
  fcm__free(B->ctx, p);
  return st;
}

/* The links of region cell c with its face neighbours of higher number into the cell's own
 * list (links, nl, cap). */
static fcm_status cell_links(const build *B, const fcm_cell_rules *R, const cell_out *out,
                             fcm_index c, fcm__material *mat, fcm__idbuf *tc, fcm_index **links,
                             size_t *nl, size_t *cap)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *mesh = B->mesh;
  const int nf = fcm_mesh_get_element_info(mesh)->num_faces;
  const fcm_index *nbr = fcm_mesh_neighbors(mesh);
  fcm__embed_cell cell;
  int set_up = 0; /* the cell is set up for the first pair whose links are not kept */
  for (int f = 0; f < nf; f++) {
    const fcm_index c2 = nbr[(size_t)nf * c + f];
    if (c2 <= c || !B->region[c2] || out[c2].np == 0) continue;
    int f2 = 0;
    while (f2 < nf && nbr[(size_t)nf * c2 + f2] != c)
      f2++;
    if (f2 == nf) continue;
    if (links_kept(B, c, c2)) {
      FCM_TRY(B->ctx, copy_links(B, R, c, c2, links, nl, cap));
      continue;
    }
    if (!set_up) FCM_TRY(B->ctx, fcm__embed_cell_setup(B->ctx, mesh, c, B->o->clip_rtol, &cell));
    set_up = 1;
    FCM_TRY(B->ctx, face_links(B, R, out, &cell, c, f, c2, f2, mat, tc, links, nl, cap));
  }
cleanup:
  return st;
}

/* Each region cell's links (cell_links()), in parallel: the cells' lists, each sorted, in cell
 * order, in *links (*nl of them): sorted, and the same on any number of threads. */
static fcm_status region_links(const build *B, const fcm_cell_rules *R, const cell_out *out,
                               fcm_index **links, size_t *nl, size_t *cap)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index nc = R->num_cells;
  fcm_index **cl = NULL; /* per cell: its links (NULL: none) */
  size_t *cn = NULL, total = 0;
  fcm__loop loop;
  FCM_ALLOC(ctx, (size_t)nc + 1, cl);
  FCM_ALLOC(ctx, (size_t)nc + 1, cn);
  fcm__loop_begin(ctx, &loop);
#pragma omp parallel num_threads(fcm_ctx_num_threads(ctx))
  {
    fcm__material *mat = NULL; /* no volume mesh: links only where the overlap holds material */
    fcm__idbuf tc = {NULL, 0, 0};
    int made = 0;
#pragma omp for schedule(dynamic, 4)
    for (fcm_index c = 0; c < nc; c++) {
      if (!B->region[c] || out[c].np == 0 || fcm__loop_skip(&loop, c)) continue;
      fcm__loop_iter it;
      fcm__loop_enter(&loop, &it, c);
      fcm_status s = FCM_OK;
      if (!made && B->geom->num_cells == 0) s = fcm__material_create(ctx, B->geom, &mat);
      made = s == FCM_OK;
      size_t ccap = 0;
      if (s == FCM_OK) s = cell_links(B, R, out, c, mat, &tc, cl + c, cn + c, &ccap);
      /* sorted here: each link starts at a piece of c, so the lists in cell order are sorted */
      if (s == FCM_OK && cn[c] > 1) qsort(cl[c], cn[c], 2 * sizeof *cl[c], cmp_link);
      fcm__loop_leave(&loop, &it, s);
    }
    fcm__geom_idbuf_free(ctx, &tc);
    fcm__material_destroy(ctx, &mat);
  }
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
  for (fcm_index c = 0; c < nc; c++)
    total += cn[c];
  if (total > 0) {
    FCM_ALLOC(ctx, 2 * total, *links);
    *cap = total;
  }
  for (fcm_index c = 0; c < nc; c++)
    if (cn[c]) {
      memcpy(*links + 2 * *nl, cl[c], 2 * cn[c] * sizeof **links);
      *nl += cn[c];
    }
cleanup:
  for (fcm_index c = 0; cl && c < nc; c++)
    fcm__free(ctx, cl[c]);
  fcm__free(ctx, cl);
  fcm__free(ctx, cn);
  return st;
}

/* The coordinates in a face polygon list (nfp polygons, meta): each polygon's and its part's
 * vertices, 3 each. */
static size_t face_coords(const int *meta, int nfp)
{
  size_t n = 0;
  for (int i = 0; i < nfp; i++)
    n += (size_t)(meta[FCM__EMBED_FMETA * i + 2] + meta[FCM__EMBED_FMETA * i + 3]);
  return 3 * n;
}

fcm_status fcm__embed_copy_face_polygons(fcm_ctx *ctx, const fcm_cell_rules *Q, fcm_index c,
                                         int **meta, double **x, int *nfp)
{
  fcm_status st = FCM_OK;
  const int n = Q->face_nfp[c];
  *meta = NULL, *x = NULL;
  *nfp = n <= 0 ? n : 0; /* n once the copies are made */
  if (n <= 0) return FCM_OK;
  const size_t nx = face_coords(Q->face_meta[c], n);
  FCM__ALLOC_WITH(fcm__malloc, ctx, FCM__EMBED_FMETA * (size_t)n, *meta);
  FCM__ALLOC_WITH(fcm__malloc, ctx, nx, *x);
  memcpy(*meta, Q->face_meta[c], FCM__EMBED_FMETA * (size_t)n * sizeof **meta);
  memcpy(*x, Q->face_x[c], nx * sizeof **x);
  *nfp = n;
cleanup:
  return st;
}

fcm_status fcm__embed_keep_face_polygons(const build *B, fcm_cell_rules *R, cell_out *out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  const fcm_index nc = R->num_cells;
  const fcm_cell_rules *Q = B->prev;
  if (!B->keep || !B->rebuild) return FCM_OK;
  FCM_ALLOC(ctx, (size_t)nc + 1, R->face_nfp);
  FCM_ALLOC(ctx, (size_t)nc + 1, R->face_meta);
  FCM_ALLOC(ctx, (size_t)nc + 1, R->face_x);
  for (fcm_index c = 0; c < nc; c++) {
    cell_out *o = out + c;
    R->face_nfp[c] = -1;
    if (o->fp_keep) { /* moved: out no longer frees them */
      R->face_nfp[c] = o->nfp;
      R->face_meta[c] = o->fmeta, R->face_x[c] = o->fx;
      o->fmeta = NULL, o->fx = NULL;
    } else if (!B->rebuild[c] && Q->face_nfp && Q->face_nfp[c] >= 0) {
      FCM_TRY(ctx, fcm__embed_copy_face_polygons(ctx, Q, c, R->face_meta + c, R->face_x + c,
                                                 R->face_nfp + c));
    }
  }
cleanup:
  return st;
}

/* Phase 3b (cuts only): the links between pieces of face-neighbouring region cells: a
 * polygon of one cell's piece on the shared face overlaps a polygon of the other cell's
 * piece with positive area, and the overlap does not lie on a cut triangle, and
 * their parents were linked (earlier_link()). */
fcm_status fcm__embed_gather_links(const build *B, fcm_cell_rules *R, const cell_out *out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  fcm_index *links = NULL;
  size_t nl = 0, cap = 0;
  fcm__idbuf tc = {NULL, 0, 0};
  fcm__material *mat = NULL;
  FCM_TRY(ctx, region_links(B, R, out, &links, &nl, &cap));
  if (B->geom->num_cells == 0 && fcm_mesh_num_hanging(B->mesh) > 0)
    FCM_TRY(ctx, fcm__material_create(ctx, B->geom, &mat));
  const size_t sorted = nl; /* region_links() gives them sorted */
  FCM_TRY(ctx, nc_links(B, R, out, mat, &tc, &links, &nl, &cap));
  if (nl > sorted) qsort(links, nl, 2 * sizeof *links, cmp_link);
  R->links = links;
  R->num_links = (fcm_index)nl;
  links = NULL;
cleanup:
  fcm__free(ctx, links);
  fcm__geom_idbuf_free(ctx, &tc);
  fcm__material_destroy(ctx, &mat);
  return st;
}
