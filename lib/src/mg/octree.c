/* The multigrid hierarchy on octree backgrounds with hanging nodes (Dick, Georgii, Westermann
 * 2011, Sec. 5: coarsening the octree level by level).
 *
 * Level 0 is the space on the octree; its operator is the constrained one the integrators
 * solve, P^T K P + I_h (lib/docs/octree.md): the hanging DOFs are decoupled identity rows. The
 * next coarser level is the same octree without its finest level (every family of eight leaves
 * of the deepest level replaced by its parent; the truncation of a 2:1-balanced octree is
 * balanced), its cells active where a finer active cell lies, its hanging nodes constrained as
 * on level 0. The spaces are nested, so the prolongation is exact: a fine DOF takes the coarse
 * conforming field (its hanging DOFs from their masters) at its node; the fine hanging DOFs get
 * no correction (empty rows: they follow their masters), the coarse hanging DOFs take part in
 * nothing (empty columns, marked inactive, decoupled in the Galerkin matrix). Once the truncated
 * octree has no hanging node it is a uniform grid, and the hierarchy of box grids (hierarchy.c)
 * continues from its space. */
#include "mg/levels_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A cell of the tree: its level and its integer position on that level's lattice. */
typedef struct oct_key {
  long long lvl, i, j, k;
  fcm_index cell; /* a mesh cell with this key, where needed (not compared) */
} oct_key;

static int cmp_key(const void *pa, const void *pb)
{
  const oct_key *a = pa, *b = pb;
  if (a->lvl != b->lvl) return (a->lvl > b->lvl) - (a->lvl < b->lvl);
  if (a->i != b->i) return (a->i > b->i) - (a->i < b->i);
  if (a->j != b->j) return (a->j > b->j) - (a->j < b->j);
  return (a->k > b->k) - (a->k < b->k);
}

/* The base grid of an octree mesh: its box, the cells per axis and the base cell size. */
typedef struct oct_base {
  double lo[3], hi[3], h0[3];
  fcm_index n[3];
} oct_base;

static void base_of(const fcm_mesh *mesh, oct_base *g)
{
  const double *X = fcm_mesh_coords(mesh);
  const fcm_index *cn = fcm_mesh_cells(mesh);
  const double s = ldexp(1.0, fcm_mesh_cell_level(mesh, 0));
  fcm_mesh_bounding_box(mesh, g->lo, g->hi);
  for (int d = 0; d < 3; d++) {
    double mn = INFINITY, mx = -INFINITY;
    for (int a = 0; a < 8; a++)
      mn = fmin(mn, X[3 * cn[a] + d]), mx = fmax(mx, X[3 * cn[a] + d]);
    g->h0[d] = (mx - mn) * s;
    g->n[d] = (fcm_index)llround((g->hi[d] - g->lo[d]) / g->h0[d]);
  }
}

/* The key of a cell (lo corner `x`, level `lvl`). */
static oct_key key_at(const oct_base *g, const double x[3], int lvl)
{
  const double s = ldexp(1.0, lvl);
  oct_key key = {lvl, 0, 0, 0, -1};
  key.i = llround((x[0] - g->lo[0]) / g->h0[0] * s);
  key.j = llround((x[1] - g->lo[1]) / g->h0[1] * s);
  key.k = llround((x[2] - g->lo[2]) / g->h0[2] * s);
  return key;
}

static oct_key cell_key(const fcm_mesh *mesh, const oct_base *g, fcm_index c)
{
  const double *X = fcm_mesh_coords(mesh);
  const fcm_index *cn = fcm_mesh_cells(mesh) + (fcm_index)fcm_mesh_nodes_per_cell(mesh) * c;
  double x[3] = {INFINITY, INFINITY, INFINITY};
  for (int a = 0; a < 8; a++)
    for (int d = 0; d < 3; d++)
      x[d] = fmin(x[d], X[3 * cn[a] + d]);
  return key_at(g, x, fcm_mesh_cell_level(mesh, c));
}

static oct_key ancestor(oct_key key, long long lvl)
{
  const long long s = key.lvl - lvl;
  oct_key a = {lvl, key.i >> s, key.j >> s, key.k >> s, -1};
  return a;
}

/* The split cells of the fine tree (sorted, unique), which the truncation keeps split. */
typedef struct trunc_user {
  const oct_base *g;
  const oct_key *split;
  fcm_index nsplit;
} trunc_user;

static int trunc_refine(const double lo[3], const double hi[3], int level, void *user)
{
  (void)hi;
  const trunc_user *u = user;
  const oct_key key = key_at(u->g, lo, level);
  return bsearch(&key, u->split, (size_t)u->nsplit, sizeof key, cmp_key) != NULL;
}

/* The octree of `fine` without its deepest level, and for every fine cell its coarse cell. */
static fcm_status truncate_mesh(fcm_ctx *ctx, const fcm_mesh *fine, fcm_mesh **coarse,
                                fcm_index *parent)
{
  fcm_status st = FCM_OK;
  oct_base g;
  oct_key *split = NULL, *ckeys = NULL;
  const fcm_index nf = fcm_mesh_num_cells(fine);
  const int lmax = fcm_mesh_max_level(fine);
  fcm_index ns = 0;
  base_of(fine, &g);
  /* the cells the truncation splits (levels below lmax - 1): each cell's ancestor of level
   * min(its level, lmax - 1) - 1, then level by level from the deepest the parents of those
   * found (fewer than nf distinct) */
  FCM_ALLOC(ctx, 2 * (size_t)nf + 1, split);
  for (fcm_index c = 0; c < nf; c++) {
    const oct_key key = cell_key(fine, &g, c);
    const long long a = (key.lvl < lmax - 1 ? key.lvl : lmax - 1) - 1;
    if (a >= 0) split[ns++] = ancestor(key, a);
  }
  fcm_index nu = 0;
  for (long long lvl = lmax - 1; lvl >= 0; lvl--) {
    qsort(split, (size_t)ns, sizeof *split, cmp_key);
    nu = 0;
    for (fcm_index i = 0; i < ns; i++)
      if (nu == 0 || cmp_key(&split[i], &split[nu - 1]) != 0) split[nu++] = split[i];
    ns = nu;
    for (fcm_index i = 0; i < nu && lvl >= 1; i++)
      if (split[i].lvl == lvl) split[ns++] = ancestor(split[i], lvl - 1);
  }
  trunc_user u = {&g, split, nu};
  fcm_octree_options o = fcm_octree_options_default();
  o.refine = trunc_refine;
  o.refine_user = &u;
  o.refine_level = lmax - 1;
  FCM_TRY(ctx,
          fcm_mesh_create_octree(ctx, fcm_mesh_element_type(fine), g.lo, g.hi, g.n, &o, coarse));
  /* every fine cell lies in a coarse leaf: its ancestor at level <= lmax - 1 (the truncation
   * of a balanced tree is balanced, so balancing split nothing more); the coarse keys sorted
   * with their cells */
  const fcm_index nc = fcm_mesh_num_cells(*coarse);
  FCM_ALLOC(ctx, nc + 1, ckeys);
  for (fcm_index c = 0; c < nc; c++) {
    ckeys[c] = cell_key(*coarse, &g, c);
    ckeys[c].cell = c;
  }
  qsort(ckeys, (size_t)nc, sizeof *ckeys, cmp_key);
  for (fcm_index c = 0; c < nf; c++) {
    oct_key key = cell_key(fine, &g, c);
    if (key.lvl > lmax - 1) key = ancestor(key, lmax - 1);
    const oct_key *hit = bsearch(&key, ckeys, (size_t)nc, sizeof key, cmp_key);
    FCM_CHECK(hit, ctx, FCM_ERR_INTERNAL, "mg: octree cell %lld has no cell in the coarser octree",
              (long long)c);
    parent[c] = hit->cell;
  }
cleanup:
  fcm__free(ctx, split);
  fcm__free(ctx, ckeys);
  if (st != FCM_OK) fcm_mesh_destroy(coarse);
  return st;
}

/* The hanging-node constraints of a level's space: T (num_dofs x num_free, u = T u_free), the
 * column of each free DOF (-1: hanging) and the DOF of each column. */
typedef struct level_cons {
  fcm_csr *T;
  fcm_index *free_dof, *col_dof;
} level_cons;

static void cons_free(fcm_ctx *ctx, level_cons *c)
{
  fcm_csr_destroy(&c->T);
  fcm__free(ctx, c->free_dof);
  fcm__free(ctx, c->col_dof);
  memset(c, 0, sizeof *c);
}

static fcm_status cons_create(fcm_ctx *ctx, const fcm_space *sp, level_cons *c)
{
  fcm_status st = FCM_OK;
  const fcm_index n = fcm_space_num_dofs(sp);
  fcm_index nfree = 0;
  FCM_ALLOC(ctx, n + 1, c->free_dof);
  FCM_TRY(ctx, fcm_space_hanging_matrix_create(sp, c->free_dof, &c->T));
  fcm_csr_get_size(c->T, NULL, &nfree, NULL);
  FCM_ALLOC(ctx, nfree + 1, c->col_dof);
  for (fcm_index d = 0; d < n; d++)
    if (c->free_dof[d] >= 0) c->col_dof[c->free_dof[d]] = d;
cleanup:
  return st;
}

static int cmp_entry(const void *pa, const void *pb)
{
  const double *a = pa, *b = pb; /* (column, weight) pairs, columns exact in a double */
  return (a[0] > b[0]) - (a[0] < b[0]);
}

/* What the prolongation from a coarse octree level to the finer one works with. */
typedef struct oct_transfer {
  const fcm_space *sf, *sc;
  const level_cons *cf, *cc;
  fcm_index *node; /* the fine nodes with free DOFs */
  fcm_index *cell; /* their coarse cells */
  double *xi;      /* their reference coordinates there (exact dyadic values) */
  fcm_index nnode;
  double *buf;      /* (column, weight) pairs of one row */
  fcm_index bufmax; /* pairs it holds */
} oct_transfer;

/* The entries of row 3 node_dof + c of P (the coarse conforming field at the node): sorted,
 * merged, zeros dropped; the count. Coarse hanging DOFs are replaced by their masters. */
static fcm_index transfer_row(const oct_transfer *t, fcm_index i, int c)
{
  const fcm_mesh *cm = fcm_space_mesh(t->sc);
  const fcm_element_type type = fcm_mesh_element_type(cm);
  const int npc = fcm_mesh_nodes_per_cell(cm);
  const fcm_index *cn = fcm_mesh_cells(cm) + (fcm_index)npc * t->cell[i];
  const fcm_index *tp = fcm_csr_row_ptr(t->cc->T);
  const int *tc = fcm_csr_col_idx(t->cc->T);
  const double *tv = fcm_csr_values_read(t->cc->T);
  double N[27];
  fcm_index q = 0;
  fcm_element_eval_shape(type, t->xi + 3 * i, N);
  for (int a = 0; a < npc; a++) {
    if (N[a] == 0.0) continue;
    const fcm_index J = fcm_space_node_dof(t->sc, cn[a]) + c;
    if (t->cc->free_dof[J] >= 0) {
      t->buf[2 * q] = (double)J, t->buf[2 * q + 1] = N[a], q++;
      continue;
    }
    for (fcm_index p = tp[J]; p < tp[J + 1]; p++)
      t->buf[2 * q] = (double)t->cc->col_dof[tc[p]], t->buf[2 * q + 1] = N[a] * tv[p], q++;
  }
  qsort(t->buf, (size_t)q, 2 * sizeof *t->buf, cmp_entry);
  fcm_index nq = 0;
  for (fcm_index p = 0; p < q; p++)
    if (nq > 0 && t->buf[2 * nq - 2] == t->buf[2 * p])
      t->buf[2 * nq - 1] += t->buf[2 * p + 1];
    else
      t->buf[2 * nq] = t->buf[2 * p], t->buf[2 * nq + 1] = t->buf[2 * p + 1], nq++;
  fcm_index out = 0;
  for (fcm_index p = 0; p < nq; p++)
    if (t->buf[2 * p + 1] != 0.0)
      t->buf[2 * out] = t->buf[2 * p], t->buf[2 * out + 1] = t->buf[2 * p + 1], out++;
  return out;
}

/* The fine nodes with free DOFs (unless t->node lists them already), their coarse cells and
 * reference coordinates there (the nodes of nested octrees sit at dyadic reference points:
 * snapped to multiples of 1/4). */
static fcm_status transfer_points(fcm_ctx *ctx, oct_transfer *t)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *fm = fcm_space_mesh(t->sf);
  const fcm_index nn = fcm_mesh_num_nodes(fm);
  const double *X = fcm_mesh_coords(fm);
  double *P = NULL;
  int *extra = NULL;
  const int select = !t->node;
  if (select) FCM_ALLOC(ctx, nn + 1, t->node);
  for (fcm_index v = 0; select && v < nn; v++) {
    const fcm_index d = fcm_space_node_dof(t->sf, v);
    int any = 0;
    for (fcm_index k = 0; d >= 0 && k < fcm_space_node_copies(t->sf, v); k++)
      any |= t->cf->free_dof[d + 3 * k] >= 0;
    if (any) t->node[t->nnode++] = v;
  }
  FCM_ALLOC(ctx, 3 * t->nnode + 1, P);
  FCM_ALLOC(ctx, 3 * t->nnode + 1, t->xi);
  FCM_ALLOC(ctx, t->nnode + 1, t->cell);
  FCM_ALLOC(ctx, t->nnode + 1, extra);
  for (fcm_index i = 0; i < t->nnode; i++)
    memcpy(P + 3 * i, X + 3 * t->node[i], 3 * sizeof *P);
  FCM_TRY(ctx, fcm_space_locate(t->sc, t->nnode, P, t->cell, t->xi, extra));
  for (fcm_index i = 0; i < t->nnode; i++) {
    FCM_CHECK(!extra[i], ctx, FCM_ERR_INTERNAL,
              "mg: octree node %lld at (%g, %g, %g) lies in no active cell of the coarser level",
              (long long)t->node[i], P[3 * i], P[3 * i + 1], P[3 * i + 2]);
    for (int d = 0; d < 3; d++) {
      const double r = 0.25 * nearbyint(4.0 * t->xi[3 * i + d]);
      FCM_CHECK(fabs(r - t->xi[3 * i + d]) < 1e-8, ctx, FCM_ERR_INTERNAL,
                "mg: octree node %lld has reference coordinate %.17g in its coarser cell, not "
                "a multiple of 1/4 (the octrees are not nested)",
                (long long)t->node[i], t->xi[3 * i + d]);
      t->xi[3 * i + d] = r;
    }
  }
cleanup:
  fcm__free(ctx, P);
  fcm__free(ctx, extra);
  return st;
}

/* P_l (F->n x C->n) from the coarse octree level to the fine one, and the coarse inactive
 * DOFs: those whose coinciding fine DOF is inactive (the Dirichlet boundary) and those no
 * fine DOF interpolates from (the coarse hanging DOFs, replaced by their masters). */
static fcm_status octree_prolongation(fcm_ctx *ctx, oct_transfer *t, mg_level *F, mg_level *C)
{
  fcm_status st = FCM_OK;
  unsigned char *used = NULL;
  FCM_TRY(ctx, transfer_points(ctx, t));
  {
    const fcm_index *tp = fcm_csr_row_ptr(t->cc->T);
    fcm_index tmax = 1;
    for (fcm_index J = 0; J < C->n; J++)
      tmax = FCM_MAX(tmax, tp[J + 1] - tp[J]);
    t->bufmax = 27 * tmax;
    FCM_ALLOC(ctx, 2 * t->bufmax + 1, t->buf);
  }
  FCM_ALLOC(ctx, C->n + 1, used);
  FCM_ALLOC(ctx, F->n + 1, F->P_ptr);
  for (fcm_index i = 0; i < t->nnode; i++)
    for (fcm_index r = fcm_space_node_dof(t->sf, t->node[i]),
                   r1 = r + 3 * fcm_space_node_copies(t->sf, t->node[i]);
         r < r1; r++)
      if (t->cf->free_dof[r] >= 0) F->P_ptr[r + 1] = transfer_row(t, i, (int)(r % 3));
  for (fcm_index r = 0; r < F->n; r++)
    F->P_ptr[r + 1] += F->P_ptr[r];
  FCM_ALLOC(ctx, F->P_ptr[F->n] + 1, F->P_col);
  FCM_ALLOC(ctx, F->P_ptr[F->n] + 1, F->P_val);
  for (fcm_index i = 0; i < t->nnode; i++)
    for (fcm_index r = fcm_space_node_dof(t->sf, t->node[i]),
                   r1 = r + 3 * fcm_space_node_copies(t->sf, t->node[i]);
         r < r1; r++) {
      if (t->cf->free_dof[r] < 0) continue;
      const fcm_index q = transfer_row(t, i, (int)(r % 3));
      for (fcm_index p = 0; p < q; p++) {
        const fcm_index J = (fcm_index)t->buf[2 * p];
        F->P_col[F->P_ptr[r] + p] = (int)J;
        F->P_val[F->P_ptr[r] + p] = t->buf[2 * p + 1];
        used[J] = 1;
      }
    }
  /* the coinciding fine DOF of each coarse DOF: the fine row whose only entry is that column
   * with weight 1 */
  for (fcm_index r = 0; r < F->n; r++)
    if (F->P_ptr[r + 1] - F->P_ptr[r] == 1 && F->P_val[F->P_ptr[r]] == 1.0 && F->inactive[r])
      C->inactive[F->P_col[F->P_ptr[r]]] = 1;
  for (fcm_index J = 0; J < C->n; J++)
    if (!used[J]) C->inactive[J] = 1;
cleanup:
  fcm__free(ctx, used);
  return st;
}

/* Level 0 on the octree space: its DOFs, the inactive ones (inactive0, or the eliminated rows
 * of A, and the hanging DOFs, which A must have eliminated: it is P^T K P + I_h) and the cut
 * cells of its block smoother. */
static fcm_status octree_level0(fcm_mg *m, const fcm_csr *A, const unsigned char *inactive0,
                                const level_cons *cf)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  mg_level *L0 = &m->lev[0];
  const fcm_space *sp = m->space;
  const fcm_mesh *mesh = fcm_space_mesh(sp);
  const fcm_index nn = fcm_mesh_num_nodes(mesh), nc = fcm_mesh_num_cells(mesh);
  const fcm_cell_rules *rules = fcm_space_cell_rules(sp);
  fcm_index nk = 0;
  for (fcm_index v = 0; v < nn; v++)
    nk += fcm_space_node_copies(sp, v);
  oct_base g;
  base_of(mesh, &g);
  for (int d = 0; d < 3; d++) /* the lattice of the finest cells */
    L0->grid[d] = g.n[d] << fcm_mesh_max_level(mesh);
  L0->A = A;
  L0->n = fcm_space_num_dofs(sp);
  L0->ncopy = nk;
  L0->ncell = fcm_space_num_elements(sp);
  FCM_ALLOC(ctx, L0->n + 1, L0->dof);
  FCM_ALLOC(ctx, L0->n + 1, L0->inactive);
  for (fcm_index i = 0; i < L0->n; i++)
    L0->dof[i] = i;
  if (inactive0) {
    memcpy(L0->inactive, inactive0, (size_t)L0->n);
  } else {
    const fcm_index *rp = fcm_csr_row_ptr(A);
    const int *ci = fcm_csr_col_idx(A);
    const double *v = fcm_csr_values_read(A);
    for (fcm_index i = 0; i < L0->n; i++) {
      int off = 0;
      for (fcm_index p = rp[i]; p < rp[i + 1] && !off; p++)
        off = ci[p] != i && v[p] != 0.0;
      L0->inactive[i] = (unsigned char)!off;
      FCM_CHECK(!off || cf->free_dof[i] >= 0, ctx, FCM_ERR_ARG,
                "mg_create: row %lld of A belongs to a hanging DOF and is coupled; on an octree "
                "A must be the constrained operator P^T K P + I_h (hanging rows and columns "
                "the identity's)",
                (long long)i);
    }
  }
  for (fcm_index i = 0; i < L0->n; i++)
    if (cf->free_dof[i] < 0) L0->inactive[i] = 1;
  FCM_ALLOC(ctx, nc + 1, m->cut_cell);
  for (fcm_index c = 0; rules && c < nc; c++)
    m->cut_cell[c] = (unsigned char)(fcm_cell_rules_class(rules, c) == FCM_CELL_CUT);
cleanup:
  return st;
}

/* The octree of level l without its deepest level: the coarse mesh and space of level l + 1
 * (owned by m, cells active where an active finer cell lies) and its constraints. */
static fcm_status coarse_space(fcm_mg *m, int l, level_cons *cc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_space *sf = l == 0 ? m->space : m->lev[l].sp;
  const fcm_mesh *fm = fcm_space_mesh(sf);
  const fcm_index nf = fcm_mesh_num_cells(fm);
  fcm_index *parent = NULL;
  unsigned char *active = NULL;
  mg_level *C = &m->lev[l + 1];
  FCM_ALLOC(ctx, nf + 1, parent);
  FCM_TRY(ctx, truncate_mesh(ctx, fm, &m->oct_mesh[l + 1], parent));
  const fcm_mesh *cm = m->oct_mesh[l + 1];
  FCM_ALLOC(ctx, fcm_mesh_num_cells(cm) + 1, active);
  for (fcm_index c = 0; c < nf; c++)
    if (fcm_space_cell_active(sf, c)) active[parent[c]] = 1;
  FCM_TRY(ctx, fcm_space_create(ctx, cm, active, &m->oct_space[l + 1]));
  C->sp = m->oct_space[l + 1];
  FCM_TRY(ctx, cons_create(ctx, C->sp, cc));
  oct_base g;
  base_of(cm, &g);
  for (int d = 0; d < 3; d++) /* the lattice of the finest cells */
    C->grid[d] = g.n[d] << fcm_mesh_max_level(cm);
cleanup:
  fcm__free(ctx, parent);
  fcm__free(ctx, active);
  return st;
}

static void transfer_free(fcm_ctx *ctx, oct_transfer *t)
{
  fcm__free(ctx, t->node);
  fcm__free(ctx, t->cell);
  fcm__free(ctx, t->xi);
  fcm__free(ctx, t->buf);
}

/* The octree of level l's space without its deepest level, as level l + 1: the coarse mesh and
 * space (owned by m), its constraints, its DOFs and P_l. */
static fcm_status octree_coarsen(fcm_mg *m, int l, const level_cons *cf, level_cons *cc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  oct_transfer t = {.sf = l == 0 ? m->space : m->lev[l].sp, .cf = cf, .cc = cc};
  mg_level *F = &m->lev[l], *C = &m->lev[l + 1];
  FCM_TRY(ctx, coarse_space(m, l, cc));
  t.sc = C->sp;
  C->n = fcm_space_num_dofs(t.sc);
  C->ncopy = C->n / 3;
  C->ncell = fcm_space_num_elements(t.sc);
  FCM_ALLOC(ctx, C->n + 1, C->dof);
  FCM_ALLOC(ctx, C->n + 1, C->inactive);
  for (fcm_index i = 0; i < C->n; i++)
    C->dof[i] = i;
  FCM_TRY(ctx, octree_prolongation(ctx, &t, F, C));
cleanup:
  transfer_free(ctx, &t);
  return st;
}

/* Level l is a uniform grid (its octree has no hanging node): the box-grid hierarchy of its
 * space (hierarchy.c) from there on, its levels moved into m. */
static fcm_status uniform_rest(fcm_mg *m, int l)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  fcm_mg *u = NULL;
  u = fcm__calloc(ctx, 1, sizeof *u);
  FCM_CHECK(u, ctx, FCM_ERR_ALLOC, "mg_create: out of memory");
  u->ctx = ctx;
  u->space = m->lev[l].sp;
  u->opts = m->opts;
  u->opts.max_levels = m->opts.max_levels - l;
  u->nt = m->nt;
  FCM_TRY(ctx, fcm__mg_build_hierarchy(u, NULL, m->lev[l].inactive));
  FCM_CHECK(u->lev[0].n == m->lev[l].n, ctx, FCM_ERR_INTERNAL,
            "mg: the uniform level has %lld DOFs, its space %lld", (long long)u->lev[0].n,
            (long long)m->lev[l].n);
  const fcm_space *sp = m->lev[l].sp;
  fcm__mg_level_free(ctx, &m->lev[l]);
  for (int k = 0; k < u->nlev; k++) {
    m->lev[l + k] = u->lev[k];
    memset(&u->lev[k], 0, sizeof u->lev[k]);
  }
  m->lev[l].sp = sp;
  m->nlev = l + u->nlev;
cleanup:
  fcm_mg_destroy(&u);
  return st;
}

/* ---- separated bodies (cuts): coarse copies per body on the octree levels
 *
 * A level's copies that the next coarser level interpolates to: per copy its mesh node, its
 * body and its first row (-1: a hanging copy, which takes no correction). The coarse level has
 * one copy per (free coarse node, body) pair that some fine copy of that body reads: the
 * prolongation gives a fine copy the coarse conforming field of its own body, so bodies the
 * cuts separate stay apart on every octree level (with one DOF per node they would share the
 * coarse DOFs where they come closer than a coarse cell). */
typedef struct oct_copies {
  fcm_index n, nbody;
  fcm_index *node, *body, *row;
} oct_copies;

static void copies_free(fcm_ctx *ctx, oct_copies *c)
{
  fcm__free(ctx, c->node);
  fcm__free(ctx, c->body);
  fcm__free(ctx, c->row);
  memset(c, 0, sizeof *c);
}

static fcm_index find_root(fcm_index *uf, fcm_index a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return a;
}

/* Level 0's copies: the space's, with the bodies its elements join (copies shared by an
 * element are in one body). */
static fcm_status level0_copies(fcm_ctx *ctx, const fcm_space *sp, const level_cons *cf,
                                oct_copies *out)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *mesh = fcm_space_mesh(sp);
  const fcm_index nk = fcm_space_num_dofs(sp) / 3, nn = fcm_mesh_num_nodes(mesh);
  const int npc = fcm_mesh_nodes_per_cell(mesh);
  fcm_index *uf = NULL;
  FCM_ALLOC(ctx, nk + 1, uf);
  FCM_ALLOC(ctx, nk + 1, out->node);
  FCM_ALLOC(ctx, nk + 1, out->body);
  FCM_ALLOC(ctx, nk + 1, out->row);
  out->n = nk;
  for (fcm_index k = 0; k < nk; k++)
    uf[k] = k, out->body[k] = -1;
  for (fcm_index e = 0; e < fcm_space_num_elements(sp); e++) {
    const fcm_index *ed = fcm_space_element_dofs(sp, e);
    for (int a = 1; a < npc; a++) {
      const fcm_index r0 = find_root(uf, ed[0] / 3), r1 = find_root(uf, ed[a] / 3);
      if (r0 != r1) uf[FCM_MAX(r0, r1)] = FCM_MIN(r0, r1);
    }
  }
  for (fcm_index k = 0; k < nk; k++) {
    const fcm_index r = find_root(uf, k);
    out->body[k] = r == k ? out->nbody++ : out->body[r];
    out->row[k] = cf->free_dof[3 * k] >= 0 ? 3 * k : -1;
  }
  for (fcm_index v = 0; v < nn; v++)
    for (fcm_index k = 0, d = fcm_space_node_dof(sp, v); d >= 0 && k < fcm_space_node_copies(sp, v);
         k++)
      out->node[d / 3 + k] = v;
cleanup:
  fcm__free(ctx, uf);
  return st;
}

/* (coarse node, body) pairs, sorted; the index of one (binary search), -1 when absent. */
static int cmp_pair(const void *pa, const void *pb)
{
  const fcm_index *a = pa, *b = pb;
  if (a[0] != b[0]) return (a[0] > b[0]) - (a[0] < b[0]);
  return (a[1] > b[1]) - (a[1] < b[1]);
}

static fcm_index pair_index(const fcm_index *pairs, fcm_index np, fcm_index node, fcm_index body)
{
  const fcm_index key[2] = {node, body};
  const fcm_index *hit = bsearch(key, pairs, (size_t)np, 2 * sizeof *pairs, cmp_pair);
  return hit ? (fcm_index)(hit - pairs) / 2 : -1;
}

/* The coarse copies: the (free coarse node, body) pairs the fine free copies read (t located
 * their nodes; at[v] is node v's position in t->node); sc_node[J / 3] the coarse node of DOF J. */
static fcm_status coarse_pairs(fcm_ctx *ctx, const oct_transfer *t, const oct_copies *fc,
                               const fcm_index *at, const fcm_index *sc_node, fcm_index **pairs,
                               fcm_index *np)
{
  fcm_status st = FCM_OK;
  size_t n = 0, cap = 0;
  fcm_index *p = NULL;
  for (fcm_index k = 0; k < fc->n; k++) {
    if (fc->row[k] < 0) continue;
    const fcm_index q = transfer_row(t, at[fc->node[k]], 0);
    for (fcm_index e = 0; e < q; e++) {
      if (n == cap) {
        const size_t nc = cap ? 2 * cap : 1024;
        void *v = p;
        FCM_TRY(ctx, fcm__resize(ctx, &v, 2 * cap, 2 * nc, sizeof *p));
        p = v, cap = nc;
      }
      p[2 * n] = sc_node[(fcm_index)t->buf[2 * e] / 3], p[2 * n + 1] = fc->body[k];
      n++;
    }
  }
  if (n) qsort(p, n, 2 * sizeof *p, cmp_pair);
  size_t u = 0;
  for (size_t i = 0; i < n; i++)
    if (u == 0 || cmp_pair(p + 2 * (u - 1), p + 2 * i) != 0)
      p[2 * u] = p[2 * i], p[2 * u + 1] = p[2 * i + 1], u++;
  *pairs = p, *np = (fcm_index)u;
  p = NULL;
cleanup:
  fcm__free(ctx, p);
  return st;
}

/* The first pair of coarse node `node` (np when none). */
static fcm_index first_pair(const fcm_index *pairs, fcm_index np, fcm_index node)
{
  return fcm__lower_bound(pairs, 2, 0, np, node);
}

/* The coarse level's cells for its statistics (fcm_mg_get_level_info(): bodies): one per
 * (active coarse cell, body at one of its corners), with its 8 corner copies (a corner without
 * a copy of that body takes one that has: the cell's body is joined all the same). */
static fcm_status coarse_cells(fcm_ctx *ctx, mg_level *C, const fcm_index *pairs, fcm_index np)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *cm = fcm_space_mesh(C->sp);
  const int npc = fcm_mesh_nodes_per_cell(cm);
  const fcm_index *cells = fcm_mesh_cells(cm);
  size_t n = 0, cap = 0;
  fcm_index *corner = NULL;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(cm); c++) {
    if (!fcm_space_cell_active(C->sp, c)) continue;
    const fcm_index *cn = cells + (size_t)npc * c;
    const size_t n0 = n;
    for (int a = 0; a < 8; a++)
      for (fcm_index q = first_pair(pairs, np, cn[a]); q < np && pairs[2 * q] == cn[a]; q++) {
        const fcm_index b = pairs[2 * q + 1];
        int seen = 0;
        for (size_t i = n0; i < n && !seen; i++)
          seen = pairs[2 * corner[8 * i] + 1] == b;
        if (seen) continue;
        if (n == cap) {
          const size_t nc = cap ? 2 * cap : 256;
          void *v = corner;
          FCM_TRY(ctx, fcm__resize(ctx, &v, 8 * cap, 8 * nc, sizeof *corner));
          corner = v, cap = nc;
        }
        for (int k = 0; k < 8; k++) {
          const fcm_index K = pair_index(pairs, np, cn[k], b);
          corner[8 * n + k] = K >= 0 ? K : q;
        }
        n++;
      }
  }
  C->ncell = (fcm_index)n;
  C->corner = corner;
  corner = NULL;
cleanup:
  fcm__free(ctx, corner);
  return st;
}

/* P_l on the coarse pairs: a fine free copy takes the coarse conforming field of its body. */
static fcm_status pair_prolongation(fcm_ctx *ctx, const oct_transfer *t, const oct_copies *fc,
                                    const fcm_index *at, const fcm_index *sc_node,
                                    const fcm_index *pairs, fcm_index np, mg_level *F, mg_level *C)
{
  fcm_status st = FCM_OK;
  FCM_ALLOC(ctx, F->n + 1, F->P_ptr);
  for (fcm_index k = 0; k < fc->n; k++)
    for (int c = 0; c < 3 && fc->row[k] >= 0; c++)
      F->P_ptr[fc->row[k] + c + 1] = transfer_row(t, at[fc->node[k]], c);
  for (fcm_index r = 0; r < F->n; r++)
    F->P_ptr[r + 1] += F->P_ptr[r];
  FCM_ALLOC(ctx, F->P_ptr[F->n] + 1, F->P_col);
  FCM_ALLOC(ctx, F->P_ptr[F->n] + 1, F->P_val);
  for (fcm_index k = 0; k < fc->n; k++)
    for (int c = 0; c < 3 && fc->row[k] >= 0; c++) {
      const fcm_index r = fc->row[k] + c, q = transfer_row(t, at[fc->node[k]], c);
      for (fcm_index e = 0; e < q; e++) {
        const fcm_index K =
            pair_index(pairs, np, sc_node[(fcm_index)t->buf[2 * e] / 3], fc->body[k]);
        FCM_CHECK(K >= 0, ctx, FCM_ERR_INTERNAL, "mg: octree copy %lld reads no coarse copy",
                  (long long)k);
        F->P_col[F->P_ptr[r] + e] = (int)(3 * K + c);
        F->P_val[F->P_ptr[r] + e] = t->buf[2 * e + 1];
      }
    }
  /* a coarse copy whose coinciding fine row is inactive (the Dirichlet boundary) is too */
  for (fcm_index r = 0; r < F->n; r++)
    if (F->P_ptr[r + 1] - F->P_ptr[r] == 1 && F->P_val[F->P_ptr[r]] == 1.0 && F->inactive[r])
      C->inactive[F->P_col[F->P_ptr[r]]] = 1;
cleanup:
  return st;
}

/* Level l + 1 of a hierarchy with separated bodies: the truncated octree with a copy per (free
 * node, body) pair, P_l, and the coarse copies (*out) for the next coarsening. */
static fcm_status octree_coarsen_bodies(fcm_mg *m, int l, const level_cons *cf, level_cons *cc,
                                        const oct_copies *fc, oct_copies *out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  oct_transfer t = {.sf = l == 0 ? m->space : m->lev[l].sp, .cf = cf, .cc = cc};
  mg_level *F = &m->lev[l], *C = &m->lev[l + 1];
  fcm_index *at = NULL, *sc_node = NULL, *pairs = NULL, np = 0;
  FCM_TRY(ctx, coarse_space(m, l, cc));
  t.sc = C->sp;
  const fcm_index nn = fcm_mesh_num_nodes(fcm_space_mesh(t.sf));
  FCM_ALLOC(ctx, nn + 1, at);
  FCM_ALLOC(ctx, nn + 1, t.node);
  for (fcm_index v = 0; v < nn; v++)
    at[v] = -1;
  for (fcm_index k = 0; k < fc->n; k++)
    if (fc->row[k] >= 0 && at[fc->node[k]] < 0)
      at[fc->node[k]] = t.nnode, t.node[t.nnode++] = fc->node[k];
  FCM_TRY(ctx, transfer_points(ctx, &t));
  {
    const fcm_index *tp = fcm_csr_row_ptr(cc->T), nr = fcm_space_num_dofs(t.sc);
    fcm_index tmax = 1;
    for (fcm_index J = 0; J < nr; J++)
      tmax = FCM_MAX(tmax, tp[J + 1] - tp[J]);
    t.bufmax = 27 * tmax;
    FCM_ALLOC(ctx, 2 * t.bufmax + 1, t.buf);
    FCM_ALLOC(ctx, nr / 3 + 1, sc_node);
    const fcm_mesh *cm = fcm_space_mesh(t.sc);
    for (fcm_index v = 0; v < fcm_mesh_num_nodes(cm); v++)
      if (fcm_space_node_dof(t.sc, v) >= 0) sc_node[fcm_space_node_dof(t.sc, v) / 3] = v;
  }
  FCM_TRY(ctx, coarse_pairs(ctx, &t, fc, at, sc_node, &pairs, &np));
  C->ncopy = np;
  C->n = 3 * np;
  FCM_ALLOC(ctx, C->n + 1, C->dof);
  FCM_ALLOC(ctx, C->n + 1, C->inactive);
  for (fcm_index i = 0; i < C->n; i++)
    C->dof[i] = i;
  FCM_TRY(ctx, pair_prolongation(ctx, &t, fc, at, sc_node, pairs, np, F, C));
  FCM_TRY(ctx, coarse_cells(ctx, C, pairs, np));
  out->n = np, out->nbody = fc->nbody;
  FCM_ALLOC(ctx, np + 1, out->node);
  FCM_ALLOC(ctx, np + 1, out->body);
  FCM_ALLOC(ctx, np + 1, out->row);
  for (fcm_index k = 0; k < np; k++)
    out->node[k] = pairs[2 * k], out->body[k] = pairs[2 * k + 1], out->row[k] = 3 * k;
cleanup:
  transfer_free(ctx, &t);
  fcm__free(ctx, at);
  fcm__free(ctx, sc_node);
  fcm__free(ctx, pairs);
  return st;
}

/* Level L's copies' nodes and bodies, kept with the level. */
static fcm_status keep_copies(fcm_ctx *ctx, mg_level *L, const oct_copies *c)
{
  fcm_status st = FCM_OK;
  FCM_ALLOC(ctx, c->n + 1, L->oct_node);
  FCM_ALLOC(ctx, c->n + 1, L->oct_body);
  memcpy(L->oct_node, c->node, (size_t)c->n * sizeof *c->node);
  memcpy(L->oct_body, c->body, (size_t)c->n * sizeof *c->body);
cleanup:
  return st;
}

/* The octree levels of a space with separated bodies (octree_coarsen_bodies()) down to the
 * uniform grid, which stays the coarsest level (the box-grid hierarchy works on spaces with
 * their own cuts; this level's copies come from the finer one). */
static fcm_status bodies_hierarchy(fcm_mg *m, level_cons *cf, oct_copies *fc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  level_cons cc = {0};
  oct_copies next = {0};
  FCM_TRY(ctx, keep_copies(ctx, &m->lev[0], fc));
  for (int l = 0;; l++) {
    const fcm_space *sf = l == 0 ? m->space : m->lev[l].sp;
    if (l + 1 >= m->opts.max_levels || m->lev[l].n <= m->opts.coarse_dofs) break;
    if (fcm_mesh_num_hanging(fcm_space_mesh(sf)) == 0) break;
    FCM_TRY(ctx, octree_coarsen_bodies(m, l, cf, &cc, fc, &next));
    m->nlev = l + 2;
    FCM_TRY(ctx, keep_copies(ctx, &m->lev[l + 1], &next));
    cons_free(ctx, cf);
    *cf = cc;
    memset(&cc, 0, sizeof cc);
    copies_free(ctx, fc);
    *fc = next;
    memset(&next, 0, sizeof next);
  }
cleanup:
  cons_free(ctx, &cc);
  copies_free(ctx, &next);
  return st;
}

fcm_status fcm__mg_octree_hierarchy(fcm_mg *m, const fcm_csr *A, const unsigned char *inactive0)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  level_cons cf = {0}, cc = {0};
  oct_copies fc = {0};
  int l = 0;
  FCM_TRY(ctx, cons_create(ctx, m->space, &cf));
  FCM_TRY(ctx, octree_level0(m, A, inactive0, &cf));
  m->nlev = 1;
  FCM_TRY(ctx, level0_copies(ctx, m->space, &cf, &fc));
  if (fc.nbody > 1) {
    FCM_TRY(ctx, bodies_hierarchy(m, &cf, &fc));
    goto cleanup;
  }
  for (;;) {
    const fcm_space *sf = l == 0 ? m->space : m->lev[l].sp;
    if (l + 1 >= m->opts.max_levels || m->lev[l].n <= m->opts.coarse_dofs) break;
    if (fcm_mesh_num_hanging(fcm_space_mesh(sf)) == 0) {
      FCM_TRY(ctx, uniform_rest(m, l));
      break;
    }
    FCM_TRY(ctx, octree_coarsen(m, l, &cf, &cc));
    m->nlev = ++l + 1;
    cons_free(ctx, &cf);
    cf = cc;
    memset(&cc, 0, sizeof cc);
  }
cleanup:
  cons_free(ctx, &cf);
  cons_free(ctx, &cc);
  copies_free(ctx, &fc);
  return st;
}
