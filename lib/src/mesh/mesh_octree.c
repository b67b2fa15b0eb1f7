/* Octree backgrounds: a box grid whose cells are split into eight by refinement criteria,
 * balanced 2:1 across faces and edges, written out as a Hex8/Hex20 mesh with its hanging nodes.
 *
 * Dick, Georgii and Westermann (2011, §3 and §5) refine a coarse hexahedral grid adaptively
 * along the cutting surface and keep neighbouring cells within one level of each other. Here a
 * cell at level L of the grid cell (i, j, k) is the integer box [x, x + 1]^3 on the lattice of
 * spacing h / 2^L; nodes are keyed by integer positions on the lattice of half the finest
 * spacing (Hex20's mid-edge nodes included), so that a node shared by cells of different sizes
 * is one node. A node that lies on the boundary of a cell without being one of its nodes hangs
 * on that cell's face or edge; each such (cell, node) pair is recorded with the node's exact
 * reference coordinates in the cell, from which the fem module builds the constraints. */
#include "mesh_impl.h"

#include <math.h>
#include <string.h>

/* A leaf of the octree: level and integer position on that level's lattice. */
typedef struct leaf {
  int64_t x[3];
  int level;
} leaf;

/* Open-addressing table of 4-component integer keys -> ids. */
typedef struct keytab {
  fcm_index *slot;
  int64_t *keys; /* 4 per id */
  size_t cap;
  fcm_index count, max;
} keytab;

static fcm_status keytab_init(fcm_ctx *ctx, keytab *t, fcm_index max)
{
  fcm_status st = FCM_OK;
  FCM_TRY(ctx, fcm__mesh_hash_capacity(ctx, max, &t->cap));
  FCM_ALLOC(ctx, t->cap, t->slot);
  FCM_ALLOC(ctx, 4 * (size_t)FCM_MAX(max, 1), t->keys);
  for (size_t i = 0; i < t->cap; i++)
    t->slot[i] = -1;
  t->count = 0;
  t->max = max;
cleanup:
  return st;
}

static void keytab_free(fcm_ctx *ctx, keytab *t)
{
  FCM_FREE(ctx, t->slot);
  FCM_FREE(ctx, t->keys);
}

/* The id of key k; a new id when `insert` (the table must have room), else -1 when absent. */
static fcm_index keytab_get(keytab *t, const int64_t k[4], int insert)
{
  uint64_t h = 0x9e3779b97f4a7c15ULL;
  for (int d = 0; d < 4; d++)
    h = fcm__mesh_mix(h ^ (uint64_t)k[d]);
  for (size_t i = (size_t)h & (t->cap - 1);; i = (i + 1) & (t->cap - 1)) {
    const fcm_index s = t->slot[i];
    if (s < 0) {
      if (!insert || t->count >= t->max) return -1;
      t->slot[i] = t->count;
      memcpy(t->keys + 4 * t->count, k, 4 * sizeof *k);
      return t->count++;
    }
    if (memcmp(t->keys + 4 * s, k, 4 * sizeof *k) == 0) return s;
  }
}

/* The octree while it is built. */
typedef struct octree {
  fcm_ctx *ctx;
  const fcm_octree_options *o;
  double lo[3], hi[3];
  int64_t n[3];
  leaf *leaves;
  fcm_index num;
} octree;

static void leaf_box(const octree *T, const leaf *l, double blo[3], double bhi[3])
{
  for (int d = 0; d < 3; d++) {
    const double m = (double)T->n[d] * ldexp(1.0, l->level);
    blo[d] = T->lo[d] + (T->hi[d] - T->lo[d]) * ((double)l->x[d] / m);
    bhi[d] = l->x[d] + 1 == (int64_t)m
                 ? T->hi[d]
                 : T->lo[d] + (T->hi[d] - T->lo[d]) * ((double)(l->x[d] + 1) / m);
  }
}

/* Replace every flagged leaf by its eight children (in place in the order: the tree's depth-first
 * order is kept, so neighbouring cells stay near each other in the cell numbering). */
static fcm_status split_flagged(octree *T, const unsigned char *flag, fcm_index nflag)
{
  fcm_status st = FCM_OK;
  leaf *next = NULL;
  FCM_CHECK(T->num + 7 * nflag <= FCM_OCTREE_MAX_CELLS, T->ctx, FCM_ERR_ARG,
            "mesh_create_octree: refinement needs %lld cells, more than the limit of %lld",
            (long long)(T->num + 7 * nflag), (long long)FCM_OCTREE_MAX_CELLS);
  FCM_ALLOC_RAW(T->ctx, T->num + 7 * nflag, next);
  fcm_index m = 0;
  for (fcm_index c = 0; c < T->num; c++) {
    const leaf *l = T->leaves + c;
    if (!flag[c]) {
      next[m++] = *l;
      continue;
    }
    for (int b = 0; b < 8; b++) {
      leaf *ch = next + m++;
      ch->level = l->level + 1;
      for (int d = 0; d < 3; d++)
        ch->x[d] = 2 * l->x[d] + ((b >> d) & 1);
    }
  }
  fcm__free(T->ctx, T->leaves);
  T->leaves = next;
  T->num = m;
  next = NULL;
cleanup:
  fcm__free(T->ctx, next);
  return st;
}

/* Whether the level set changes sign over the 27 points of the 3 x 3 x 3 grid of the box (a
 * zero value counts as both signs). */
static int levelset_crosses(fcm_octree_levelset_fn phi, void *user, const double blo[3],
                            const double bhi[3])
{
  int neg = 0, pos = 0;
  for (int p = 0; p < 27; p++) {
    double x[3];
    const int ijk[3] = {p % 3, (p / 3) % 3, p / 9};
    for (int d = 0; d < 3; d++)
      x[d] = blo[d] + 0.5 * ijk[d] * (bhi[d] - blo[d]);
    const double v = phi(x, user);
    neg |= !(v > 0);
    pos |= !(v < 0);
    if (neg && pos) return 1;
  }
  return 0;
}

/* Whether some criterion asks to split leaf l: 1 or 0, negative when the callback failed. */
static int wants_split(const octree *T, const leaf *l)
{
  const fcm_octree_options *o = T->o;
  double blo[3], bhi[3];
  leaf_box(T, l, blo, bhi);
  if (l->level < o->region_level) {
    int meets = 1;
    for (int d = 0; d < 3; d++)
      meets &= blo[d] <= o->region_hi[d] && bhi[d] >= o->region_lo[d];
    if (meets) return 1;
  }
  if (o->surface && l->level < o->surface_level &&
      levelset_crosses(o->surface, o->surface_user, blo, bhi))
    return 1;
  if (o->refine && l->level < o->refine_level) return o->refine(blo, bhi, l->level, o->refine_user);
  return 0;
}

/* Apply the criteria level by level until no leaf asks to be split. */
static fcm_status refine(octree *T)
{
  fcm_status st = FCM_OK;
  unsigned char *flag = NULL;
  for (;;) {
    FCM_ALLOC(T->ctx, T->num, flag);
    fcm_index nflag = 0;
    for (fcm_index c = 0; c < T->num; c++) {
      const int w = wants_split(T, T->leaves + c);
      if (w < 0) {
        double blo[3], bhi[3];
        leaf_box(T, T->leaves + c, blo, bhi);
        FCM_CHECK(0, T->ctx, FCM_ERR_ARG,
                  "mesh_create_octree: the refine callback failed (returned %d) on the level %d "
                  "cell [%g, %g] x [%g, %g] x [%g, %g]",
                  w, T->leaves[c].level, blo[0], bhi[0], blo[1], bhi[1], blo[2], bhi[2]);
      }
      nflag += flag[c] = (unsigned char)(w > 0);
    }
    if (nflag == 0) break;
    FCM_TRY(T->ctx, split_flagged(T, flag, nflag));
    FCM_FREE(T->ctx, flag);
  }
cleanup:
  fcm__free(T->ctx, flag);
  return st;
}

/* 2:1 balance across faces and edges: a leaf at level L >= 2 needs the cells across each of its
 * faces and edges to be of level L - 1 or finer; a coarser leaf there is split, and the sweep
 * repeats until nothing changes (each sweep only splits, so it ends within max_level sweeps of
 * the deepest level). */
static fcm_status balance(octree *T)
{
  fcm_status st = FCM_OK;
  keytab tab = {0};
  unsigned char *flag = NULL;
  for (;;) {
    FCM_TRY(T->ctx, keytab_init(T->ctx, &tab, T->num));
    for (fcm_index c = 0; c < T->num; c++) {
      const leaf *l = T->leaves + c;
      const int64_t k[4] = {l->level, l->x[0], l->x[1], l->x[2]};
      keytab_get(&tab, k, 1);
    }
    FCM_ALLOC(T->ctx, T->num, flag);
    fcm_index nflag = 0;
    for (fcm_index c = 0; c < T->num; c++) {
      const leaf *l = T->leaves + c;
      if (l->level < 2) continue;
      for (int dir = 0; dir < 27; dir++) {
        const int off[3] = {dir % 3 - 1, (dir / 3) % 3 - 1, dir / 9 - 1};
        const int nz = (off[0] != 0) + (off[1] != 0) + (off[2] != 0);
        if (nz == 0 || nz == 3) continue; /* faces and edges only */
        int64_t p[3];
        int inside = 1;
        for (int d = 0; d < 3; d++) {
          p[d] = l->x[d] + off[d];
          inside &= p[d] >= 0 && p[d] < (T->n[d] << l->level);
        }
        if (!inside) continue;
        for (int lv = l->level - 1; lv >= 0; lv--) {
          const int sh = l->level - lv;
          const int64_t k[4] = {lv, p[0] >> sh, p[1] >> sh, p[2] >> sh};
          const fcm_index s = keytab_get(&tab, k, 0);
          if (s < 0) continue;
          if (lv < l->level - 1 && !flag[s]) {
            flag[s] = 1;
            nflag++;
          }
          break;
        }
      }
    }
    keytab_free(T->ctx, &tab);
    if (nflag == 0) break;
    FCM_TRY(T->ctx, split_flagged(T, flag, nflag));
    FCM_FREE(T->ctx, flag);
  }
cleanup:
  keytab_free(T->ctx, &tab);
  fcm__free(T->ctx, flag);
  return st;
}

/* The mesh arrays of the leaves: nodes keyed by their positions on the lattice of half the
 * finest spacing (node_key: 4 per node, the last 0), cells in leaf order. */
static fcm_status build_nodes(const octree *T, const fcm_element_info *info, int finest,
                              keytab *nodes, fcm_index **cells_out)
{
  fcm_status st = FCM_OK;
  fcm_index *cells = NULL;
  const int npc = info->num_nodes;
  const double *ref = fcm_element_ref_nodes(info->type);
  FCM_TRY(T->ctx, keytab_init(T->ctx, nodes, T->num * npc));
  FCM_ALLOC_RAW(T->ctx, T->num * npc, cells);
  for (fcm_index c = 0; c < T->num; c++) {
    const leaf *l = T->leaves + c;
    const int64_t s = (int64_t)1 << (finest - l->level + 1);
    for (int a = 0; a < npc; a++) {
      int64_t k[4] = {0, 0, 0, 0};
      for (int d = 0; d < 3; d++)
        k[d] = l->x[d] * s + (int64_t)(ref[3 * a + d] + 1.0) * (s / 2);
      cells[(size_t)npc * c + a] = keytab_get(nodes, k, 1);
    }
  }
  *cells_out = cells;
  cells = NULL;
cleanup:
  fcm__free(T->ctx, cells);
  return st;
}

/* The (cell, hanging node, reference coordinates) triples: for each leaf coarser than the finest
 * level, the nodes at the points of its boundary on the grid of a quarter (Hex20) or half (Hex8)
 * of its size that are not its own nodes. */
static fcm_status find_hanging(const octree *T, const fcm_element_info *info, int finest,
                               keytab *nodes, const fcm_index *cells, fcm_mesh *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = T->ctx;
  const int npc = info->num_nodes, g = info->order == 2 ? 4 : 2;
  size_t cap = 0, num = 0;
  for (int pass = 0; pass < 2; pass++) {
    num = 0;
    for (fcm_index c = 0; c < T->num; c++) {
      const leaf *l = T->leaves + c;
      if (l->level >= finest) continue;
      const int64_t s = (int64_t)1 << (finest - l->level + 1), q = s / g;
      const fcm_index *own = cells + (size_t)npc * c;
      for (int p = 0; p < (g + 1) * (g + 1) * (g + 1); p++) {
        const int ijk[3] = {p % (g + 1), (p / (g + 1)) % (g + 1), p / ((g + 1) * (g + 1))};
        int on_boundary = 0;
        for (int d = 0; d < 3; d++)
          on_boundary |= ijk[d] == 0 || ijk[d] == g;
        if (!on_boundary) continue;
        int64_t k[4] = {0, 0, 0, 0};
        for (int d = 0; d < 3; d++)
          k[d] = l->x[d] * s + ijk[d] * q;
        const fcm_index node = keytab_get(nodes, k, 0);
        if (node < 0) continue;
        int mine = 0;
        for (int a = 0; a < npc && !mine; a++)
          mine = own[a] == node;
        if (mine) continue;
        if (pass == 1) {
          m->hang_cell[num] = c;
          m->hang_node[num] = node;
          for (int d = 0; d < 3; d++)
            m->hang_xi[3 * num + d] = 2.0 * ijk[d] / g - 1.0;
        }
        num++;
      }
    }
    if (pass == 0) {
      cap = num;
      FCM_ALLOC_RAW(ctx, FCM_MAX(cap, 1), m->hang_cell);
      FCM_ALLOC_RAW(ctx, FCM_MAX(cap, 1), m->hang_node);
      FCM_ALLOC_RAW(ctx, 3 * FCM_MAX(cap, 1), m->hang_xi);
    }
  }
  m->num_hanging = (fcm_index)num;
cleanup:
  return st;
}

/* Faces that met no partner in the mesh's corner matching and do not lie on the box surface
 * face finer (or coarser) cells: mark them FCM_MESH_NEIGHBOR_NONCONFORMING and keep only the
 * box surface in the boundary-face list. */
static fcm_status mark_nonconforming(fcm_mesh *m, const double lo[3], const double hi[3])
{
  fcm_status st = FCM_OK;
  const fcm_element_info *info = m->info;
  const int nf = info->num_faces;
  fcm_index nb = 0;
  for (fcm_index i = 0; i < m->num_cells * nf; i++) {
    if (m->neighbors[i] != -1) continue;
    const fcm_index c = i / nf;
    const int f = (int)(i % nf);
    int on_box = 0;
    for (int d = 0; d < 3 && !on_box; d++) {
      int at_lo = 1, at_hi = 1;
      for (int k = 0; k < info->face_num_corners[f]; k++) {
        const double x = m->coords[3 * m->cells[(size_t)m->npc * c + info->face_nodes[f][k]] + d];
        at_lo &= x == lo[d];
        at_hi &= x == hi[d];
      }
      on_box = at_lo || at_hi;
    }
    if (on_box) {
      m->boundary[2 * nb] = c;
      m->boundary[2 * nb + 1] = f;
      nb++;
    } else {
      m->neighbors[i] = FCM_MESH_NEIGHBOR_NONCONFORMING;
    }
  }
  m->num_boundary = nb;
  return st;
}

fcm_octree_options fcm_octree_options_default(void)
{
  fcm_octree_options o;
  memset(&o, 0, sizeof o);
  return o;
}

static fcm_status check_options(fcm_ctx *ctx, const fcm_octree_options *o)
{
  fcm_status st = FCM_OK;
  const int levels[3] = {o->region_level, o->surface_level, o->refine_level};
  static const char *names[3] = {"region_level", "surface_level", "refine_level"};
  for (int i = 0; i < 3; i++)
    FCM_CHECK(levels[i] >= 0 && levels[i] <= FCM_OCTREE_MAX_LEVEL, ctx, FCM_ERR_ARG,
              "mesh_create_octree: %s = %d out of range [0, %d]", names[i], levels[i],
              FCM_OCTREE_MAX_LEVEL);
  for (int d = 0; d < 3 && o->region_level > 0; d++)
    FCM_CHECK(o->region_lo[d] <= o->region_hi[d], ctx, FCM_ERR_ARG,
              "mesh_create_octree: region axis %d: lo = %g > hi = %g (or NaN); need lo <= hi", d,
              o->region_lo[d], o->region_hi[d]);
  FCM_CHECK(o->surface_level == 0 || o->surface, ctx, FCM_ERR_ARG,
            "mesh_create_octree: surface_level = %d needs a surface level set", o->surface_level);
  FCM_CHECK(o->refine_level == 0 || o->refine, ctx, FCM_ERR_ARG,
            "mesh_create_octree: refine_level = %d needs a refine callback", o->refine_level);
cleanup:
  return st;
}

/* Balance the leaves and write them out as the mesh (cells in leaf order), with the octree's
 * own data: levels, lattice positions, box, hanging pairs, non-conforming faces. */
static fcm_status finish(octree *T, fcm_element_type type, fcm_mesh **mesh)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = T->ctx;
  keytab nodes = {0};
  fcm_index *cells = NULL;
  double *x = NULL;
  fcm_mesh *m = NULL;
  FCM_TRY(ctx, balance(T));
  int finest = 0;
  for (fcm_index c = 0; c < T->num; c++)
    finest = FCM_MAX(finest, T->leaves[c].level);
  const fcm_element_info *info = fcm_element_get_info(type);
  FCM_TRY(ctx, build_nodes(T, info, finest, &nodes, &cells));
  FCM_ALLOC_RAW(ctx, 3 * FCM_MAX(nodes.count, 1), x);
  for (fcm_index a = 0; a < nodes.count; a++)
    for (int d = 0; d < 3; d++) {
      const int64_t N = T->n[d] << (finest + 1), k = nodes.keys[4 * a + d];
      x[3 * a + d] = k == N ? T->hi[d] : T->lo[d] + (T->hi[d] - T->lo[d]) * ((double)k / (double)N);
    }
  FCM_TRY(ctx, fcm__mesh_create_take(ctx, type, nodes.count, &x, T->num, &cells, &m));
  FCM_ALLOC_RAW(ctx, FCM_MAX(T->num, 1), m->cell_level);
  FCM_ALLOC_RAW(ctx, 3 * FCM_MAX(T->num, 1), m->cell_pos);
  for (fcm_index c = 0; c < T->num; c++) {
    m->cell_level[c] = (unsigned char)T->leaves[c].level;
    for (int d = 0; d < 3; d++)
      m->cell_pos[3 * c + d] = T->leaves[c].x[d];
  }
  for (int d = 0; d < 3; d++) {
    m->box_lo[d] = T->lo[d];
    m->box_hi[d] = T->hi[d];
    m->box_n[d] = T->n[d];
  }
  m->max_level = finest;
  FCM_TRY(ctx, find_hanging(T, info, finest, &nodes, m->cells, m));
  FCM_TRY(ctx, mark_nonconforming(m, T->lo, T->hi));
  *mesh = m;
  m = NULL;
cleanup:
  fcm_mesh_destroy(&m);
  keytab_free(ctx, &nodes);
  fcm__free(ctx, cells);
  fcm__free(ctx, x);
  return st;
}

fcm_status fcm_mesh_create_octree(fcm_ctx *ctx, fcm_element_type type, const double lo[3],
                                  const double hi[3], const fcm_index n[3],
                                  const fcm_octree_options *opts, fcm_mesh **mesh)
{
  fcm_status st = FCM_OK;
  const fcm_octree_options defaults = fcm_octree_options_default();
  octree T = {0};
  FCM_CHECK(ctx && mesh && lo && hi && n, ctx, FCM_ERR_ARG,
            "mesh_create_octree: ctx, lo, hi, n and mesh must not be NULL");
  *mesh = NULL;
  FCM_CHECK(type == FCM_ELEMENT_HEX8 || type == FCM_ELEMENT_HEX20, ctx, FCM_ERR_UNSUPPORTED,
            "mesh_create_octree: element type %s: octree refinement needs hexahedra (hex8 or "
            "hex20)",
            fcm_element_get_info(type) ? fcm_element_get_info(type)->name : "(invalid)");
  T.ctx = ctx;
  T.o = opts ? opts : &defaults;
  FCM_TRY(ctx, check_options(ctx, T.o));
  FCM_TRY(ctx, fcm__mesh_check_grid(ctx, "mesh_create_octree", lo, hi, n));
  for (int d = 0; d < 3; d++) {
    T.lo[d] = lo[d];
    T.hi[d] = hi[d];
    T.n[d] = n[d];
  }
  const double base = (double)n[0] * (double)n[1] * (double)n[2];
  FCM_CHECK(base <= (double)FCM_OCTREE_MAX_CELLS, ctx, FCM_ERR_ARG,
            "mesh_create_octree: %lld x %lld x %lld cells exceed the limit of %lld",
            (long long)n[0], (long long)n[1], (long long)n[2], (long long)FCM_OCTREE_MAX_CELLS);
  T.num = n[0] * n[1] * n[2];
  FCM_ALLOC_RAW(ctx, T.num, T.leaves);
  for (fcm_index q = 0; q < T.num; q++) {
    T.leaves[q].level = 0;
    T.leaves[q].x[0] = q % n[0];
    T.leaves[q].x[1] = (q / n[0]) % n[1];
    T.leaves[q].x[2] = q / (n[0] * n[1]);
  }
  FCM_TRY(ctx, refine(&T));
  FCM_TRY(ctx, finish(&T, type, mesh));
cleanup:
  if (ctx) fcm__free(ctx, T.leaves);
  return st;
}

fcm_status fcm_mesh_create_refined(fcm_ctx *ctx, const fcm_mesh *mesh, const unsigned char *flags,
                                   fcm_mesh **out)
{
  fcm_status st = FCM_OK;
  const fcm_octree_options none = fcm_octree_options_default();
  octree T = {0};
  unsigned char *split = NULL;
  FCM_CHECK(ctx && mesh && flags && out, ctx, FCM_ERR_ARG,
            "mesh_create_refined: ctx, mesh, flags and out must not be NULL");
  *out = NULL;
  FCM_CHECK(mesh->cell_level, ctx, FCM_ERR_UNSUPPORTED,
            "mesh_create_refined: the %s mesh was not made by fcm_mesh_create_octree(); only "
            "octree meshes are refined",
            mesh->info->name);
  T.ctx = ctx;
  T.o = &none;
  T.num = mesh->num_cells;
  for (int d = 0; d < 3; d++) {
    T.lo[d] = mesh->box_lo[d];
    T.hi[d] = mesh->box_hi[d];
    T.n[d] = mesh->box_n[d];
  }
  FCM_ALLOC_RAW(ctx, FCM_MAX(T.num, 1), T.leaves);
  FCM_ALLOC(ctx, FCM_MAX(T.num, 1), split);
  fcm_index nflag = 0;
  for (fcm_index c = 0; c < T.num; c++) {
    T.leaves[c].level = mesh->cell_level[c];
    for (int d = 0; d < 3; d++)
      T.leaves[c].x[d] = mesh->cell_pos[3 * c + d];
    if (!flags[c]) continue;
    FCM_CHECK(mesh->cell_level[c] < FCM_OCTREE_MAX_LEVEL, ctx, FCM_ERR_ARG,
              "mesh_create_refined: cell %lld is at level %d already, the deepest "
              "(FCM_OCTREE_MAX_LEVEL); it cannot be split",
              (long long)c, (int)mesh->cell_level[c]);
    split[c] = 1;
    nflag++;
  }
  if (nflag) FCM_TRY(ctx, split_flagged(&T, split, nflag));
  FCM_TRY(ctx, finish(&T, mesh->type, out));
cleanup:
  if (ctx) {
    fcm__free(ctx, T.leaves);
    fcm__free(ctx, split);
  }
  return st;
}

int fcm_mesh_is_octree(const fcm_mesh *mesh)
{
  return mesh->cell_level != NULL;
}

int fcm_mesh_cell_level(const fcm_mesh *mesh, fcm_index cell)
{
  return mesh->cell_level ? mesh->cell_level[cell] : 0;
}

int fcm_mesh_max_level(const fcm_mesh *mesh)
{
  return mesh->max_level;
}

fcm_index fcm_mesh_num_hanging(const fcm_mesh *mesh)
{
  return mesh->num_hanging;
}

void fcm_mesh_get_hanging(const fcm_mesh *mesh, fcm_index i, fcm_index *cell, fcm_index *node,
                          double xi[3])
{
  if (cell) *cell = mesh->hang_cell[i];
  if (node) *node = mesh->hang_node[i];
  if (xi)
    for (int d = 0; d < 3; d++)
      xi[d] = mesh->hang_xi[3 * i + d];
}
