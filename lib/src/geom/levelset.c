/* Level-set bodies: marching tetrahedra on the refined Kuhn lattice of the cut cells of a
 * background grid (nodes shared through lattice and edge keys), and built-in implicits. */
#include "geom/geom_impl.h"
#include "fcm/levelset.h"
#include "la/vec3.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

fcm_level_set_options fcm_level_set_options_default(void)
{
  fcm_level_set_options o;
  o.refinement = 4;
  o.estimate_error = 1;
  o.refine_inside = 0;
  o.max_subcells = FCM_LEVEL_SET_MAX_SUBCELLS;
  o.progress = NULL;
  o.progress_user = NULL;
  o.progress_interval = 0.1;
  return o;
}

/* A lattice vertex: global refined lattice indices and the value of phi. */
typedef struct lvert {
  int64_t g[3];
  double phi;
} lvert;

/* A node of an emitted tet: its key (8 x lattice id for a lattice point, 8 x the lower
 * endpoint's id + direction code 1..7 for an edge crossing) and position. */
typedef struct lnode {
  int64_t key;
  double x[3];
  int plane; /* bit 2d (2d+1): the node lies on the box face x_d = lo_d (hi_d) */
} lnode;

typedef struct builder {
  fcm_ctx *ctx;
  fcm_level_set_fn phi;
  void *user;
  double lo[3], hi[3];
  int64_t N[3]; /* refined lattice cells per axis */
  int store;    /* 0: volume only */
  size_t nt, cap;
  lnode *nodes; /* 4 per tet */
  size_t ntri, tcap;
  lnode *tri;     /* boundary triangles: 3 nodes each, outward */
  size_t *towner; /* the tet of each */
  double volume;
  /* progress: sub-cells marched of the total, reported every interval seconds */
  const fcm_level_set_options *opts;
  fcm_index done, total;
  double last;
} builder;

/* Count `n` sub-cells marched and report the progress when the interval has passed. */
static void advance(builder *B, fcm_index n)
{
  B->done += n;
  if (!B->opts->progress) return;
  const double now = fcm_wtime();
  if (now - B->last < B->opts->progress_interval) return;
  B->last = now;
  B->opts->progress(B->done, B->total, B->opts->progress_user);
}

static void lattice_x(const builder *B, const int64_t g[3], double x[3])
{
  for (int d = 0; d < 3; d++)
    x[d] = g[d] == B->N[d] ? B->hi[d]
                           : B->lo[d] + (B->hi[d] - B->lo[d]) * ((double)g[d] / (double)B->N[d]);
}

static int64_t lattice_id(const builder *B, const int64_t g[3])
{
  return g[0] + (B->N[0] + 1) * (g[1] + (B->N[1] + 1) * g[2]);
}

static int lattice_planes(const builder *B, const int64_t g[3])
{
  int m = 0;
  for (int d = 0; d < 3; d++)
    m |= (g[d] == 0) << (2 * d) | (g[d] == B->N[d]) << (2 * d + 1);
  return m;
}

static lnode vertex_node(const builder *B, const lvert *v)
{
  lnode n;
  n.key = 8 * lattice_id(B, v->g);
  lattice_x(B, v->g, n.x);
  n.plane = lattice_planes(B, v->g);
  return n;
}

/* The crossing on the edge between an inside and an outside vertex, computed from the lower
 * endpoint so that every cell sharing the edge gets the same bits. */
static lnode edge_node(const builder *B, const lvert *p, const lvert *q)
{
  const lvert *u = p, *w = q;
  if (q->g[0] <= p->g[0] && q->g[1] <= p->g[1] && q->g[2] <= p->g[2]) u = q, w = p;
  lnode n;
  int code = 0;
  for (int d = 0; d < 3; d++)
    code |= (int)(w->g[d] - u->g[d]) << d;
  n.key = 8 * lattice_id(B, u->g) + code;
  double xu[3], xw[3];
  lattice_x(B, u->g, xu);
  lattice_x(B, w->g, xw);
  const double t = u->phi / (u->phi - w->phi);
  for (int d = 0; d < 3; d++)
    n.x[d] = xu[d] + t * (xw[d] - xu[d]);
  n.plane = lattice_planes(B, u->g) & lattice_planes(B, w->g);
  return n;
}

/* Record boundary triangle (a, b, c) of tet `owner`, turned to face away from o (a point of
 * the tet off the triangle's plane). */
static fcm_status add_tri(builder *B, lnode a, lnode b, lnode c, const double o[3], size_t owner)
{
  fcm_status st = FCM_OK;
  double e1[3], e2[3], e3[3];
  for (int k = 0; k < 3; k++)
    e1[k] = b.x[k] - a.x[k], e2[k] = c.x[k] - a.x[k], e3[k] = o[k] - a.x[k];
  const double det = fcm__vec3_det(e1, e2, e3);
  if (B->ntri == B->tcap) {
    const size_t nc = B->tcap ? 2 * B->tcap : 1024;
    FCM_TRY(B->ctx, fcm__resize(B->ctx, (void **)&B->tri, 3 * B->tcap, 3 * nc, sizeof(lnode)));
    FCM_TRY(B->ctx, fcm__resize(B->ctx, (void **)&B->towner, B->tcap, nc, sizeof(size_t)));
    B->tcap = nc;
  }
  lnode *t = B->tri + 3 * B->ntri;
  t[0] = a, t[1] = det > 0.0 ? c : b, t[2] = det > 0.0 ? b : c;
  B->towner[B->ntri++] = owner;
cleanup:
  return st;
}

/* The iso-surface triangle (a, b, c) of the tet just emitted, facing along grad, the
 * gradient of the linear interpolant of phi (robust where a vertex value is tiny). */
static fcm_status iso_tri(builder *B, lnode a, lnode b, lnode c, const double grad[3])
{
  if (!B->store) return FCM_OK;
  double o[3];
  for (int k = 0; k < 3; k++)
    o[k] = a.x[k] - grad[k];
  return add_tri(B, a, b, c, o, B->nt - 1);
}

/* Gradient of the linear interpolant of phi on the tet v[0..3]. */
static void tet_gradient(const builder *B, const lvert *v[4], double grad[3])
{
  double x[4][3], J[3][3], r[3];
  for (int k = 0; k < 4; k++)
    lattice_x(B, v[k]->g, x[k]);
  for (int k = 0; k < 3; k++) {
    for (int d = 0; d < 3; d++)
      J[k][d] = x[k + 1][d] - x[0][d];
    r[k] = v[k + 1]->phi - v[0]->phi;
  }
  /* J grad = r by Cramer's rule (Kuhn tets are never flat) */
  const double det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                     J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                     J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
  for (int d = 0; d < 3; d++) {
    double M[3][3];
    memcpy(M, J, sizeof M);
    for (int k = 0; k < 3; k++)
      M[k][d] = r[k];
    grad[d] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
               M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
               M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) /
              det;
  }
}

static fcm_status emit(builder *B, lnode a, lnode b, lnode c, lnode d)
{
  fcm_status st = FCM_OK;
  double e1[3], e2[3], e3[3];
  for (int k = 0; k < 3; k++)
    e1[k] = b.x[k] - a.x[k], e2[k] = c.x[k] - a.x[k], e3[k] = d.x[k] - a.x[k];
  const double det = fcm__vec3_det(e1, e2, e3);
  B->volume += fabs(det) / 6.0;
  if (!B->store) return FCM_OK;
  if (B->nt == B->cap) {
    const size_t nc = B->cap ? 2 * B->cap : 1024;
    FCM_TRY(B->ctx, fcm__resize(B->ctx, (void **)&B->nodes, 4 * B->cap, 4 * nc, sizeof(lnode)));
    B->cap = nc;
  }
  lnode *t = B->nodes + 4 * B->nt++;
  t[0] = a, t[1] = b, t[2] = c, t[3] = d;
  /* faces on a face of the box are boundary, turned outward by the face's normal (the
   * tet may be flat: a crossing at a lattice vertex); flat faces are left out */
  for (int f = 0; f < 4; f++) {
    const lnode *p = t + (f + 1) % 4, *q = t + (f + 2) % 4, *r = t + (f + 3) % 4;
    const int m = p->plane & q->plane & r->plane;
    if (!m) continue;
    int bit = 0;
    while (!(m >> bit & 1))
      bit++;
    const int dd = bit / 2, e1i = (dd + 1) % 3, e2i = (dd + 2) % 3;
    const double nd = (q->x[e1i] - p->x[e1i]) * (r->x[e2i] - p->x[e2i]) -
                      (q->x[e2i] - p->x[e2i]) * (r->x[e1i] - p->x[e1i]);
    if (nd == 0.0) continue;
    double o[3]; /* a point on the inner side of the face */
    for (int k = 0; k < 3; k++)
      o[k] = p->x[k];
    o[dd] += bit % 2 ? -1.0 : 1.0;
    FCM_TRY(B->ctx, add_tri(B, *p, *q, *r, o, B->nt - 1));
  }
cleanup:
  return st;
}

static fcm_status emit_prism(builder *B, const lnode p[3], const lnode q[3])
{
  fcm_status st = FCM_OK;
  FCM_TRY(B->ctx, emit(B, p[0], p[1], p[2], q[0]));
  FCM_TRY(B->ctx, emit(B, p[1], p[2], q[0], q[1]));
  FCM_TRY(B->ctx, emit(B, p[2], q[0], q[1], q[2]));
cleanup:
  return st;
}

/* The part of the tet where the linear interpolant of phi is negative. */
static fcm_status march(builder *B, const lvert *v[4])
{
  fcm_status st = FCM_OK;
  int in[4], out[4], ni = 0, no = 0;
  for (int k = 0; k < 4; k++)
    if (v[k]->phi < 0.0)
      in[ni++] = k;
    else
      out[no++] = k;
  if (ni == 0) return FCM_OK;
  double grad[3] = {0, 0, 0};
  if (ni < 4 && B->store) tet_gradient(B, v, grad);
  if (ni == 4) {
    FCM_TRY(B->ctx, emit(B, vertex_node(B, v[0]), vertex_node(B, v[1]), vertex_node(B, v[2]),
                         vertex_node(B, v[3])));
  } else if (ni == 1) {
    const lvert *a = v[in[0]];
    const lnode an = vertex_node(B, a), e0 = edge_node(B, a, v[out[0]]),
                e1 = edge_node(B, a, v[out[1]]), e2 = edge_node(B, a, v[out[2]]);
    FCM_TRY(B->ctx, emit(B, an, e0, e1, e2));
    FCM_TRY(B->ctx, iso_tri(B, e0, e1, e2, grad));
  } else if (ni == 3) {
    const lvert *d = v[out[0]];
    lnode p[3], q[3];
    for (int k = 0; k < 3; k++)
      p[k] = vertex_node(B, v[in[k]]), q[k] = edge_node(B, v[in[k]], d);
    FCM_TRY(B->ctx, emit_prism(B, p, q)); /* the last tet (p2, q0, q1, q2) holds q */
    FCM_TRY(B->ctx, iso_tri(B, q[0], q[1], q[2], grad));
  } else {
    const lvert *a = v[in[0]], *b = v[in[1]], *c = v[out[0]], *d = v[out[1]];
    const lnode p[3] = {vertex_node(B, a), edge_node(B, a, c), edge_node(B, a, d)};
    const lnode q[3] = {vertex_node(B, b), edge_node(B, b, c), edge_node(B, b, d)};
    /* the iso quad (p1, p2, q2, q1) is split by the diagonal p2-q1 of the prism's tets
     * (p1, p2, q0, q1) and (p2, q0, q1, q2) */
    FCM_TRY(B->ctx, emit(B, p[0], p[1], p[2], q[0]));
    FCM_TRY(B->ctx, emit(B, p[1], p[2], q[0], q[1]));
    FCM_TRY(B->ctx, iso_tri(B, p[1], p[2], q[1], grad));
    FCM_TRY(B->ctx, emit(B, p[2], q[0], q[1], q[2]));
    FCM_TRY(B->ctx, iso_tri(B, p[2], q[1], q[2], grad));
  }
cleanup:
  return st;
}

/* The 6 Kuhn tets of a cube with corners c[bits] (bit 0: +x, bit 1: +y, bit 2: +z). */
static fcm_status march_cube(builder *B, const lvert *c[8])
{
  fcm_status st = FCM_OK;
  static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int t = 0; t < 6; t++) {
    const int b1 = 1 << perm[t][0], b2 = b1 | (1 << perm[t][1]);
    const lvert *v[4] = {c[0], c[b1], c[b2], c[7]};
    FCM_TRY(B->ctx, march(B, v));
  }
cleanup:
  return st;
}

typedef enum { CELL_OUTSIDE, CELL_INSIDE, CELL_CUT } cell_kind;

/* 1 when the 8 corners of sub-cube (cx, cy, cz) of the sample block w (m per axis) are
 * inside. */
static int cube_inside(const lvert *w, int m, int cx, int cy, int cz)
{
  for (int k = 0; k < 8; k++)
    if (!(w[(cx + (k & 1)) + m * ((cy + !!(k & 2)) + m * (cz + !!(k & 4)))].phi < 0.0)) return 0;
  return 1;
}

/* Sample cell (ix, iy, iz) at refinement r (B->N = n r) into w ((r+1)^3): its kind, and in
 * *cut (may be NULL) the sub-cubes where phi changes sign at the corners. */
static fcm_status sample_cell(builder *B, const int64_t cell[3], int r, lvert *w, cell_kind *kind,
                              int64_t *cut)
{
  fcm_status st = FCM_OK;
  const int m = r + 1;
  int nin = 0;
  for (int c = 0; c < m; c++)
    for (int b = 0; b < m; b++)
      for (int a = 0; a < m; a++) {
        lvert *v = w + a + m * (b + m * c);
        v->g[0] = cell[0] * r + a, v->g[1] = cell[1] * r + b, v->g[2] = cell[2] * r + c;
        double x[3];
        lattice_x(B, v->g, x);
        v->phi = B->phi(x, B->user);
        FCM_CHECK(isfinite(v->phi), B->ctx, FCM_ERR_GEOMETRY,
                  "level set: phi(%g, %g, %g) = %g is not finite", x[0], x[1], x[2], v->phi);
        nin += v->phi < 0.0;
      }
  const int total = m * m * m;
  *kind = nin == 0 ? CELL_OUTSIDE : nin == total ? CELL_INSIDE : CELL_CUT;
  if (cut) *cut = 0;
  if (cut && *kind == CELL_CUT)
    for (int cz = 0; cz < r; cz++)
      for (int cy = 0; cy < r; cy++)
        for (int cx = 0; cx < r; cx++) {
          int in = 0;
          for (int k = 0; k < 8; k++)
            in += w[(cx + (k & 1)) + m * ((cy + !!(k & 2)) + m * (cz + !!(k & 4)))].phi < 0.0;
          *cut += in > 0 && in < 8;
        }
cleanup:
  return st;
}

/* Sample cell (ix, iy, iz) at refinement r into w and march it; `whole`: a cell with every
 * sample inside becomes the 6 tets of the cell, and the inside sub-cubes of a cut cell are
 * merged into boxes. todo: r^3 bytes of workspace. */
static fcm_status do_cell(builder *B, const int64_t cell[3], int r, int whole, lvert *w,
                          unsigned char *todo, cell_kind *kind)
{
  fcm_status st = FCM_OK;
  const int m = r + 1;
  FCM_TRY(B->ctx, sample_cell(B, cell, r, w, kind, NULL));
  if (*kind == CELL_OUTSIDE) return FCM_OK;
  if (*kind == CELL_INSIDE && whole) {
    const lvert *c[8];
    for (int k = 0; k < 8; k++)
      c[k] = w + (k & 1 ? r : 0) + m * ((k & 2 ? r : 0) + m * (k & 4 ? r : 0));
    return march_cube(B, c);
  }
  /* Sub-cubes with every corner inside: with `whole`, merged greedily into boxes (runs
   * along x, extended along y, then z) that become 6 tets each; the rest is marched. */
  for (int cz = 0; cz < r; cz++)
    for (int cy = 0; cy < r; cy++)
      for (int cx = 0; cx < r; cx++)
        todo[cx + r * (cy + r * cz)] =
            (unsigned char)(1 + (whole && cube_inside(w, m, cx, cy, cz)));
  for (int cz = 0; cz < r; cz++)
    for (int cy = 0; cy < r; cy++)
      for (int cx = 0; cx < r; cx++) {
        const int id = cx + r * (cy + r * cz);
        if (!todo[id]) continue;
        int x1 = cx + 1, y1 = cy + 1, z1 = cz + 1;
        if (todo[id] == 2) {
#define TODO_IN(a, b, c) (todo[(a) + r * ((b) + r * (c))] == 2)
          while (x1 < r && TODO_IN(x1, cy, cz))
            x1++;
          for (int ok = 1; ok && y1 < r; y1 += ok)
            for (int a = cx; ok && a < x1; a++)
              ok = TODO_IN(a, y1, cz);
          for (int ok = 1; ok && z1 < r; z1 += ok)
            for (int b = cy; ok && b < y1; b++)
              for (int a = cx; ok && a < x1; a++)
                ok = TODO_IN(a, b, z1);
#undef TODO_IN
        }
        for (int c = cz; c < z1; c++)
          for (int b = cy; b < y1; b++)
            for (int a = cx; a < x1; a++)
              todo[a + r * (b + r * c)] = 0;
        const lvert *c[8];
        for (int k = 0; k < 8; k++)
          c[k] = w + (k & 1 ? x1 : cx) + m * ((k & 2 ? y1 : cy) + m * (k & 4 ? z1 : cz));
        FCM_TRY(B->ctx, march_cube(B, c));
      }
cleanup:
  return st;
}

typedef struct keyslot {
  int64_t key;
  size_t slot;
} keyslot;

static int cmp_key(const void *a, const void *b)
{
  const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return (x > y) - (x < y);
}

static int cmp_keyslot(const void *a, const void *b)
{
  const keyslot *x = a, *y = b;
  return (x->key > y->key) - (x->key < y->key);
}

fcm_status fcm_geometry_create_from_level_set(fcm_ctx *ctx, fcm_level_set_fn phi, void *user,
                                              const double lo[3], const double hi[3],
                                              const fcm_index n[3],
                                              const fcm_level_set_options *opts,
                                              fcm_geometry **geom, fcm_level_set_info *info)
{
  fcm_status st = FCM_OK;
  builder B = {0};
  lvert *w = NULL;
  unsigned char *kinds = NULL, *todo = NULL;
  keyslot *ks = NULL;
  int64_t *ukeys = NULL;
  fcm_index *tris = NULL, *tri_tet = NULL;
  double *X = NULL;
  fcm_index *cells = NULL;
  fcm_level_set_info inf = {0};
  const fcm_level_set_options o = opts ? *opts : fcm_level_set_options_default();
  FCM_CHECK(ctx && geom, ctx, FCM_ERR_ARG, "level set: NULL argument");
  *geom = NULL;
  if (info) memset(info, 0, sizeof *info);
  FCM_CHECK(phi && lo && hi && n, ctx, FCM_ERR_ARG, "level set: phi, lo, hi or n is NULL");
  FCM_CHECK(o.refinement >= 1 && o.refinement <= 64, ctx, FCM_ERR_ARG,
            "level set: refinement %d outside [1, 64]", o.refinement);
  FCM_CHECK(o.max_subcells >= 0, ctx, FCM_ERR_ARG, "level set: max_subcells = %lld must be >= 0",
            (long long)o.max_subcells);
  FCM_CHECK(o.progress_interval >= 0.0 && isfinite(o.progress_interval), ctx, FCM_ERR_ARG,
            "level set: progress_interval = %g must be finite and >= 0 seconds",
            o.progress_interval);
  double subcells = 1.0;
  for (int d = 0; d < 3; d++) {
    FCM_CHECK(isfinite(lo[d]) && isfinite(hi[d]) && lo[d] < hi[d], ctx, FCM_ERR_ARG,
              "level set: box axis %d: need finite lo < hi, got [%g, %g]", d, lo[d], hi[d]);
    FCM_CHECK(n[d] >= 1 && n[d] <= 10000, ctx, FCM_ERR_ARG,
              "level set: cells on axis %d = %lld outside [1, 10000]", d, (long long)n[d]);
    subcells *= (double)n[d] * 2.0 * o.refinement;
    B.lo[d] = lo[d], B.hi[d] = hi[d];
    inf.h = fmax(inf.h, (hi[d] - lo[d]) / ((double)n[d] * o.refinement));
  }
  FCM_CHECK(subcells <= 2147483648.0, ctx, FCM_ERR_ARG,
            "level set: %lld x %lld x %lld cells at refinement %d (error estimate at %d) give "
            "%.3g sub-cells, more than 2^31",
            (long long)n[0], (long long)n[1], (long long)n[2], o.refinement, 2 * o.refinement,
            subcells);
  if (phi == fcm_implicit_eval) { /* a built-in tree: valid, and resolved by the sampling */
    FCM_TRY(ctx, fcm_implicit_check_spacing(ctx, user, inf.h));
  }
  B.ctx = ctx, B.phi = phi, B.user = user, B.opts = &o, B.last = fcm_wtime();
  const int r = o.refinement;
  const int64_t r3 = (int64_t)r * r * r;
  const size_t ncell = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
  FCM_ALLOC_RAW(ctx, (size_t)(2 * r + 1) * (size_t)(2 * r + 1) * (size_t)(2 * r + 1), w);
  FCM_ALLOC_RAW(ctx, ncell, kinds);
  FCM_ALLOC_RAW(ctx, (size_t)(2 * r) * (size_t)(2 * r) * (size_t)(2 * r), todo);
  for (int d = 0; d < 3; d++)
    B.N[d] = (int64_t)n[d] * r;
  /* Pass 0: classify the cells and count the sub-cells the surface crosses (nothing stored),
   * so that an oversize build is refused before its tets are allocated. */
  size_t ci = 0;
  for (int64_t k = 0; k < n[2]; k++)
    for (int64_t j = 0; j < n[1]; j++)
      for (int64_t i = 0; i < n[0]; i++, ci++) {
        const int64_t cell[3] = {i, j, k};
        cell_kind kind;
        int64_t cut = 0;
        FCM_TRY(ctx, sample_cell(&B, cell, r, w, &kind, &cut));
        kinds[ci] = (unsigned char)kind;
        inf.cells_inside += kind == CELL_INSIDE;
        inf.cells_cut += kind == CELL_CUT;
        inf.cells_outside += kind == CELL_OUTSIDE;
        inf.subcells += cut;
      }
  /* a cell wholly inside becomes 6 tets: counted as one sub-cell (about half the memory of
   * one the surface crosses); refine_inside: every sub-cube of a cut or inside cell is split
   * on its own, counted alike */
  inf.subcells =
      o.refine_inside ? (inf.cells_cut + inf.cells_inside) * r3 : inf.subcells + inf.cells_inside;
  const fcm_index estimate = inf.subcells;
  FCM_CHECK(o.max_subcells == 0 || estimate <= o.max_subcells, ctx, FCM_ERR_UNSUPPORTED,
            "level set: the build would triangulate %lld sub-cells (%lld cut and %lld inside "
            "cells at refinement %d; about %.3g GB at %d kB each), more than max_subcells = %lld "
            "(about %.3g GB); raise max_subcells (0: no limit), or lower the refinement or the "
            "sampling cells",
            (long long)estimate, (long long)inf.cells_cut, (long long)inf.cells_inside, r,
            (double)estimate * FCM_LEVEL_SET_SUBCELL_BYTES / 1e9,
            FCM_LEVEL_SET_SUBCELL_BYTES / 1000, (long long)o.max_subcells,
            (double)o.max_subcells * FCM_LEVEL_SET_SUBCELL_BYTES / 1e9);
  B.total = (inf.cells_cut + (o.refine_inside ? inf.cells_inside : 0)) * r3;
  if (o.estimate_error) B.total += inf.cells_cut * 8 * r3;
  /* Pass 1: refinement r, stored. */
  B.store = 1;
  ci = 0;
  for (int64_t k = 0; k < n[2]; k++)
    for (int64_t j = 0; j < n[1]; j++)
      for (int64_t i = 0; i < n[0]; i++, ci++) {
        if (kinds[ci] == CELL_OUTSIDE) continue;
        const int64_t cell[3] = {i, j, k};
        cell_kind kind;
        FCM_TRY(ctx, do_cell(&B, cell, r, !o.refine_inside, w, todo, &kind));
        kinds[ci] = (unsigned char)kind; /* phi is sampled as in pass 0 */
        if (kind == CELL_CUT || (kind == CELL_INSIDE && o.refine_inside)) advance(&B, r3);
      }
  inf.volume = B.volume;
  FCM_CHECK(B.nt > 0 && B.volume > 0.0, ctx, FCM_ERR_GEOMETRY,
            "level set: the body {phi < 0} has no volume in the box [%g, %g] x [%g, %g] x [%g, "
            "%g] sampled at refinement %d (every sample has phi >= 0)",
            lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], r);
  /* Pass 2 (volume only): the cut cells at refinement 2r, the others as they were. */
  if (o.estimate_error) {
    builder F = B;
    F.store = 0, F.nodes = NULL, F.tri = NULL, F.towner = NULL, F.volume = 0.0;
    for (int d = 0; d < 3; d++)
      F.N[d] = (int64_t)n[d] * 2 * r;
    ci = 0;
    double v_whole = 0.0;
    for (int64_t k = 0; k < n[2]; k++)
      for (int64_t j = 0; j < n[1]; j++)
        for (int64_t i = 0; i < n[0]; i++, ci++) {
          const int64_t cell[3] = {i, j, k};
          cell_kind kind;
          if (kinds[ci] == CELL_CUT) {
            FCM_TRY(ctx, do_cell(&F, cell, 2 * r, 1, w, todo, &kind));
            advance(&F, 8 * r3);
          } else if (kinds[ci] == CELL_INSIDE) {
            v_whole += 1.0;
          }
        }
    B.done = F.done, B.last = F.last;
    double cv = 1.0;
    for (int d = 0; d < 3; d++)
      cv *= (hi[d] - lo[d]) / (double)n[d];
    inf.volume_fine = F.volume + v_whole * cv;
    inf.error_estimate = 4.0 / 3.0 * fabs(inf.volume - inf.volume_fine);
  }
  if (o.progress) o.progress(B.total, B.total, o.progress_user);
  /* Nodes: unique keys. */
  const size_t nv = 4 * B.nt;
  FCM_ALLOC_RAW(ctx, nv, ks);
  for (size_t s = 0; s < nv; s++)
    ks[s].key = B.nodes[s].key, ks[s].slot = s;
  qsort(ks, nv, sizeof *ks, cmp_keyslot);
  FCM_ALLOC_RAW(ctx, nv, cells);
  FCM_ALLOC_RAW(ctx, 3 * nv, X);
  FCM_ALLOC_RAW(ctx, nv, ukeys);
  size_t nn = 0;
  for (size_t s = 0; s < nv; s++) {
    if (s == 0 || ks[s].key != ks[s - 1].key) {
      memcpy(X + 3 * nn, B.nodes[ks[s].slot].x, 3 * sizeof(double));
      ukeys[nn++] = ks[s].key;
    }
    cells[ks[s].slot] = (fcm_index)(nn - 1);
  }
  /* The boundary: the iso-surface and box-face triangles (every node is a tet node). */
  FCM_ALLOC_RAW(ctx, 3 * B.ntri + 1, tris);
  FCM_ALLOC_RAW(ctx, B.ntri + 1, tri_tet);
  for (size_t k = 0; k < 3 * B.ntri; k++) {
    const int64_t *hit = bsearch(&B.tri[k].key, ukeys, nn, sizeof *ukeys, cmp_key);
    tris[k] = (fcm_index)(hit - ukeys);
  }
  for (size_t k = 0; k < B.ntri; k++)
    tri_tet[k] = (fcm_index)B.towner[k];
  inf.num_tets = (fcm_index)B.nt;
  FCM_TRY(ctx, fcm__geom_create_take(ctx, "level set", FCM_ELEMENT_TET4, (fcm_index)nn, &X,
                                     (fcm_index)B.nt, &cells, 0, geom));
  /* Tets were reoriented in place (two nodes swapped): the triangles do not depend on it. */
  fcm__free(ctx, (*geom)->tris);
  fcm__free(ctx, (*geom)->tri_cell);
  (*geom)->tris = tris, (*geom)->tri_cell = tri_tet, (*geom)->num_tris = (fcm_index)B.ntri;
  (*geom)->custom_boundary = 1;
  tris = tri_tet = NULL;
  if (info) *info = inf;
cleanup:
  fcm__free(ctx, B.nodes);
  fcm__free(ctx, B.tri);
  fcm__free(ctx, B.towner);
  fcm__free(ctx, ukeys);
  fcm__free(ctx, tris);
  fcm__free(ctx, tri_tet);
  fcm__free(ctx, w);
  fcm__free(ctx, kinds);
  fcm__free(ctx, todo);
  fcm__free(ctx, ks);
  fcm__free(ctx, X);
  fcm__free(ctx, cells);
  return st;
}

/* ---------------------------------------------------------------- built-in implicits */

static const char *const kind_names[] = {"sphere", "torus",        "box",       "gyroid",
                                         "union",  "intersection", "difference"};

fcm_status fcm_implicit_check(fcm_ctx *ctx, const fcm_implicit_tree *tree)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(tree && tree->nodes, ctx, FCM_ERR_ARG, "implicit: NULL tree or nodes");
  FCM_CHECK(tree->num_nodes >= 1 && tree->num_nodes <= FCM_IMPLICIT_MAX_NODES, ctx, FCM_ERR_ARG,
            "implicit: %d nodes outside [1, %d]", tree->num_nodes, FCM_IMPLICIT_MAX_NODES);
  for (int i = 0; i < tree->num_nodes; i++) {
    const fcm_implicit *q = tree->nodes + i;
    FCM_CHECK((int)q->kind >= 0 && q->kind < FCM_IMPLICIT_KIND_COUNT, ctx, FCM_ERR_ARG,
              "implicit: node %d: kind %d outside [0, %d)", i, (int)q->kind,
              (int)FCM_IMPLICIT_KIND_COUNT);
    const char *nm = kind_names[q->kind];
    switch (q->kind) {
    case FCM_IMPLICIT_TORUS:
      FCM_CHECK(q->axis >= 0 && q->axis < 3, ctx, FCM_ERR_ARG,
                "implicit: node %d (torus): axis %d outside [0, 3)", i, q->axis);
      FCM_CHECK(q->minor_radius > 0 && q->minor_radius <= q->radius, ctx, FCM_ERR_ARG,
                "implicit: node %d (torus): minor_radius %g outside (0, radius = %g]", i,
                q->minor_radius, q->radius);
      /* fall through */
    case FCM_IMPLICIT_SPHERE:
      FCM_CHECK(q->radius > 0 && isfinite(q->radius), ctx, FCM_ERR_ARG,
                "implicit: node %d (%s): radius %g must be positive", i, nm, q->radius);
      for (int d = 0; d < 3; d++)
        FCM_CHECK(isfinite(q->center[d]), ctx, FCM_ERR_ARG,
                  "implicit: node %d (%s): center[%d] = %g is not finite", i, nm, d, q->center[d]);
      break;
    case FCM_IMPLICIT_GYROID:
      FCM_CHECK(q->period > 0 && isfinite(q->period), ctx, FCM_ERR_ARG,
                "implicit: node %d (gyroid): period %g must be positive", i, q->period);
      FCM_CHECK(fabs(q->thickness) < q->period / 4 && (!q->sheet || q->thickness > 0), ctx,
                FCM_ERR_ARG, "implicit: node %d (gyroid): thickness %g outside %s", i, q->thickness,
                q->sheet ? "(0, period / 4)" : "(-period / 4, period / 4)");
      /* fall through */
    case FCM_IMPLICIT_BOX:
      for (int d = 0; d < 3; d++)
        FCM_CHECK(isfinite(q->min[d]) && isfinite(q->max[d]) && q->min[d] < q->max[d], ctx,
                  FCM_ERR_ARG, "implicit: node %d (%s): need min[%d] < max[%d], got %g, %g", i, nm,
                  d, d, q->min[d], q->max[d]);
      break;
    default:
      FCM_CHECK(q->a >= 0 && q->a < i && q->b >= 0 && q->b < i, ctx, FCM_ERR_ARG,
                "implicit: node %d (%s): operands %d, %d must lie in [0, %d)", i, nm, q->a, q->b,
                i);
      break;
    }
  }
cleanup:
  return st;
}

int fcm__implicit_resolved(const fcm_implicit *q, double h, const char **key, char *msg, size_t len)
{
  double size, value;
  const char *why;
  *key = NULL;
  switch (q->kind) {
  case FCM_IMPLICIT_SPHERE:
    *key = "radius", size = value = q->radius;
    why = "a sphere that small is not resolved";
    break;
  case FCM_IMPLICIT_TORUS:
    *key = "minor_radius", size = value = q->minor_radius;
    why = "a tube that thin is not resolved";
    break;
  case FCM_IMPLICIT_BOX: {
    int dd = 0;
    for (int d = 1; d < 3; d++)
      if (q->max[d] - q->min[d] < q->max[dd] - q->min[dd]) dd = d;
    if (q->max[dd] - q->min[dd] >= h) return 1;
    snprintf(msg, len,
             "the side max[%d] - min[%d] = %g is below the sampling spacing h = %g (the largest "
             "sub-cell edge: sampling box side / (cells x refinement)); a box that thin is not "
             "resolved: widen it or sample finer (refinement, cells)",
             dd, dd, q->max[dd] - q->min[dd], h);
    return 0;
  }
  case FCM_IMPLICIT_GYROID:
    if (q->period >= 2.0 * h && (!q->sheet || 2.0 * q->thickness >= h)) return 1;
    if (q->period >= 2.0 * h) {
      *key = "thickness", size = 2.0 * q->thickness, value = q->thickness;
      why = "a sheet's wall is 2 thickness thick: thinner than h, it falls between the samples";
    } else {
      *key = "period", size = 0.5 * q->period, value = q->period;
      why = "a gyroid's channels are half a period wide: a period under two samples only "
            "samples noise";
    }
    break;
  default:
    return 1;
  }
  if (size >= h) return 1;
  snprintf(msg, len,
           "%s = %g is below %sthe sampling spacing h = %g (the largest sub-cell edge: sampling "
           "box side / (cells x refinement)); %s: enlarge it or sample finer (refinement, cells)",
           *key, value,
           size == value         ? ""
           : size == 0.5 * value ? "twice "
                                 : "half ",
           h, why);
  return 0;
}

fcm_status fcm_implicit_check_spacing(fcm_ctx *ctx, const fcm_implicit_tree *tree, double h)
{
  fcm_status st = FCM_OK;
  char msg[512];
  const char *key;
  FCM_TRY(ctx, fcm_implicit_check(ctx, tree));
  FCM_CHECK(h > 0.0 && isfinite(h), ctx, FCM_ERR_ARG,
            "implicit: sampling spacing h = %g must be positive and finite", h);
  for (int i = 0; i < tree->num_nodes; i++)
    FCM_CHECK(fcm__implicit_resolved(tree->nodes + i, h, &key, msg, sizeof msg), ctx, FCM_ERR_ARG,
              "implicit: node %d (%s): %s", i, kind_names[tree->nodes[i].kind], msg);
cleanup:
  return st;
}

static double box_phi(const double *mn, const double *mx, const double x[3])
{
  double v = -HUGE_VAL;
  for (int d = 0; d < 3; d++)
    v = fmax(v, fabs(x[d] - 0.5 * (mn[d] + mx[d])) - 0.5 * (mx[d] - mn[d]));
  return v;
}

double fcm_implicit_eval(const double x[3], void *user)
{
  const fcm_implicit_tree *t = user;
  double v[FCM_IMPLICIT_MAX_NODES];
  for (int i = 0; i < t->num_nodes; i++) {
    const fcm_implicit *q = t->nodes + i;
    double y[3];
    for (int d = 0; d < 3; d++)
      y[d] = x[d] - q->center[d];
    switch (q->kind) {
    case FCM_IMPLICIT_SPHERE:
      v[i] = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]) - q->radius;
      break;
    case FCM_IMPLICIT_TORUS: {
      const int a = q->axis, b = (a + 1) % 3, c = (a + 2) % 3;
      const double rho = sqrt(y[b] * y[b] + y[c] * y[c]) - q->radius;
      v[i] = sqrt(rho * rho + y[a] * y[a]) - q->minor_radius;
      break;
    }
    case FCM_IMPLICIT_BOX:
      v[i] = box_phi(q->min, q->max, x);
      break;
    case FCM_IMPLICIT_GYROID: {
      const double k = 2.0 * 3.14159265358979323846 / q->period;
      const double sx = sin(k * x[0]), cx = cos(k * x[0]), sy = sin(k * x[1]), cy = cos(k * x[1]),
                   sz = sin(k * x[2]), cz = cos(k * x[2]);
      const double g = (sx * cy + sy * cz + sz * cx) / k;
      v[i] = fmax(q->sheet ? fabs(g) - q->thickness : g - q->thickness, box_phi(q->min, q->max, x));
      break;
    }
    case FCM_IMPLICIT_UNION:
      v[i] = fmin(v[q->a], v[q->b]);
      break;
    case FCM_IMPLICIT_INTERSECTION:
      v[i] = fmax(v[q->a], v[q->b]);
      break;
    default:
      v[i] = fmax(v[q->a], -v[q->b]);
      break;
    }
  }
  return v[t->num_nodes - 1];
}
