/* Assembly on a space: element kernels for linear stiffness, consistent mass,
 * body force, hyperelastic energy/force/tangent and surface traction, on the
 * standard rule of full cells or the per-cell rules of cut cells, scattered
 * colour by colour in parallel (deterministic for any thread count). The space is
 * only read; rules, tabulations and scratch live in an fcm_assembly_workspace. */
#include "embed/embed_impl.h"
#include "fem/assemble_impl.h"
#include "la/mat3.h"

#include <math.h>
#include <omp.h>
#include <string.h>

static fcm_status tabulate(const fcm_space *s, fcm_rule_kind kind, int strength, tabulation *t)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  FCM_TRY(ctx, fcm_element_standard_rule(ctx, s->type, kind, strength, &t->rule));
  int nq = fcm_rule_num_points(t->rule);
  const double *pts = fcm_rule_points(t->rule);
  const size_t rows = 3 * (size_t)fcm__kernel_na(s->nn);
  FCM_ALLOC(ctx, (size_t)nq * s->nn, t->N);
  FCM_ALLOC(ctx, (size_t)nq * rows, t->dT);
  const int qp = (nq + 7) / 8 * 8;
  FCM_ALLOC(ctx, (size_t)qp * 3 * (size_t)s->nn, t->dQ);
  for (int q = 0; q < nq; q++) {
    double dN[3 * FCM_ELEMENT_MAX_NODES];
    fcm_element_eval_shape(s->type, pts + 3 * q, t->N + (size_t)q * s->nn);
    fcm_element_eval_grad(s->type, pts + 3 * q, dN);
    fcm__kernel_rows(s->nn, dN, t->dT + (size_t)q * rows);
    for (int e = 0; e < 3 * s->nn; e++)
      t->dQ[(size_t)e * qp + q] = dN[e];
  }
  t->r.nq = nq;
  t->r.w = fcm_rule_weights(t->rule);
  t->r.N = t->N;
  t->r.dT = t->dT;
  t->r.dQ = t->dQ, t->r.qp = qp;
cleanup:
  return st;
}

static void tabulation_free(fcm_ctx *ctx, tabulation *t)
{
  FCM_FREE(ctx, t->N);
  FCM_FREE(ctx, t->dT);
  FCM_FREE(ctx, t->dQ);
  fcm_rule_destroy(&t->rule);
}

/* The rule of element e: the tabulated standard rule for full cells, else its piece's own
 * points from the embedded rules, evaluated into w->Nb / w->dTb (max_cut_points entries). */
static cell_rule get_cell_rule(const fcm_space *s, const tabulation *t, fcm_rule_kind kind,
                               fcm_index e, scratch *w)
{
  cell_rule r = {0, NULL, w->Nb, w->dTb, NULL, NULL, 0};
  if (!fcm__space_owns(s, s->elem_cell[e])) return r; /* another process's cell */
  if (!s->rules || fcm_cell_rules_class(s->rules, s->elem_cell[e]) == FCM_CELL_UNCUT) return t->r;
  const double *pts = NULL;
  const size_t rows = 3 * (size_t)fcm__kernel_na(s->nn);
  fcm_cell_rules_get_piece(s->rules, s->elem_piece[e], kind, &r.nq, &pts, &r.w, &r.fict);
  for (int q = 0; q < r.nq; q++) {
    fcm_element_eval_shape(s->type, pts + 3 * q, w->Nb + (size_t)q * s->nn);
    fcm_element_eval_grad(s->type, pts + 3 * q, w->g);
    fcm__kernel_rows(s->nn, w->g, w->dTb + (size_t)q * rows);
  }
  return r;
}

/* Add the symmetric element matrix of local element le, given by its upper node blocks Kp
 * (fcm__cell_kernel()), into the values of the space's pattern (its rows: a full space's DOFs,
 * a local space's local copies). Row by row of the element's nodes a: block (a, b) for b >= a,
 * the transpose of block (b, a) for b < a, so each matrix row is swept once (its cache lines
 * while they are in cache). The three rows of a copy share their columns: one offset per node
 * pair places its 3 x 3 block. */
#if defined(__GNUC__) || defined(__clang__)
typedef double v2d __attribute__((vector_size(16)));

/* d[0..3) += (x, y, z): a pair and a single (baseline x86-64 has vectors of 2), each entry
 * summed as alone (same bits). */
static inline void add3(double *d, double x, double y, double z)
{
  v2d t, u = {x, y};
  memcpy(&t, d, sizeof t);
  t += u;
  memcpy(d, &t, sizeof t);
  d[2] += z;
}
#else
static inline void add3(double *d, double x, double y, double z)
{
  d[0] += x, d[1] += y, d[2] += z;
}
#endif

/* Prefetch, for writing and into L2, the entries of node a's three rows that the scatter of
 * local element le adds to: each run of 3 by its first and its last entry, since a quarter of
 * the runs cross a cache line (without the last entry's line those runs stall the scatter;
 * testing for the crossing costs more than the prefetch). Always inlined: as a function of its own
 * GCC finds it free of side effects and drops its calls. */
#if defined(__GNUC__) || defined(__clang__)
#define PREFETCH_INLINE static inline __attribute__((always_inline))
#else
#define PREFETCH_INLINE static inline
#endif
PREFETCH_INLINE void prefetch_rows(const fcm_space *s, fcm_index le, int a, const double *vals)
{
#if defined(__GNUC__) || defined(__clang__)
  const int nn = s->nn;
  const int *oa = s->elem_off + ((size_t)le * nn + a) * nn;
  const fcm_index da = fcm__space_elem_row(s, le, a);
  const double *r0 = vals + s->row_ptr[da], *r1 = vals + s->row_ptr[da + 1];
  const double *r2 = vals + s->row_ptr[da + 2];
  for (int b = 0; b < nn; b++) {
    const int x = 3 * oa[b];
    __builtin_prefetch(r0 + x, 1, 2), __builtin_prefetch(r0 + x + 2, 1, 2);
    __builtin_prefetch(r1 + x, 1, 2), __builtin_prefetch(r1 + x + 2, 1, 2);
    __builtin_prefetch(r2 + x, 1, 2), __builtin_prefetch(r2 + x + 2, 1, 2);
  }
#else
  (void)s, (void)le, (void)a, (void)vals;
#endif
}

/* Prefetch, for reading and into L2, the scatter offsets and row numbers of local element le
 * (`far` in scatter_matrix(), two elements after `next`: when le becomes `next`, its prefetches
 * find them in cache). Always inlined, as prefetch_rows(). */
PREFETCH_INLINE void prefetch_layout(const fcm_space *s, fcm_index le)
{
#if defined(__GNUC__) || defined(__clang__)
  const size_t nn = (size_t)s->nn;
  const char *o = (const char *)(s->elem_off + (size_t)le * nn * nn);
  for (size_t i = 0; i < nn * nn * sizeof(int) + 64; i += 64)
    __builtin_prefetch(o + i, 0, 2);
  const char *d = s->elem_lcopy ? (const char *)(s->elem_lcopy + (size_t)le * nn)
                                : (const char *)(s->elem_dof + (size_t)le * nn);
  for (size_t i = 0; i < nn * sizeof(fcm_index) + 64; i += 64)
    __builtin_prefetch(d + i, 0, 2);
#else
  (void)s, (void)le;
#endif
}

/* Matrices with at least this many bytes of values (beyond a core's L2 cache) have the entries
 * of an element's scatter prefetched SCATTER_AHEAD elements before (scatter_matrix()). */
#define SCATTER_PREFETCH_BYTES (4.0 * 1024 * 1024)
#define SCATTER_AHEAD          1

/* How many elements ahead the scatter into vals (NULL: none) prefetches: 0 below
 * SCATTER_PREFETCH_BYTES. */
static int scatter_ahead(const fcm_space *s, const double *vals)
{
  if (!vals) return 0;
  const double bytes = (double)s->row_ptr[fcm__space_num_rows(s)] * sizeof(double);
  return bytes >= SCATTER_PREFETCH_BYTES ? SCATTER_AHEAD : 0;
}

/* With next >= 0, the entries the scatter of local element `next` will add to are prefetched
 * into L2 row by row along the way: on a matrix far beyond the caches they come from memory
 * while the elements in between are computed, where at next's own scatter they would stall it
 * (a fifth of a Hex20 stiffness assembly of 16^3 cells: lib/docs/performance.md); with
 * far >= 0, the offsets and rows of local element `far` that those prefetches will read. */
static void scatter_matrix(const fcm_space *s, fcm_index le, const double *Kp, double *vals,
                           fcm_index next, fcm_index far, const unsigned char *rows)
{
  const int nn = s->nn;
  if (far >= 0) prefetch_layout(s, far);
  const int *off = s->elem_off + (size_t)le * nn * nn;
  for (int a = 0; a < nn; a++) {
    const fcm_index da = fcm__space_elem_row(s, le, a);
    if (rows && !rows[da / 3]) continue; /* a row the pass leaves as it is */
    double *r0 = vals + s->row_ptr[da], *r1 = vals + s->row_ptr[da + 1];
    double *r2 = vals + s->row_ptr[da + 2];
    if (next >= 0) prefetch_rows(s, next, a, vals);
    const int *oa = off + a * nn;
    /* b < a: the transpose of block (b, a), at 9 (b nn - b (b - 1) / 2 + a - b) */
    const double *k = Kp + 9 * a;
    for (int b = 0; b < a; b++) {
      const int x = 3 * oa[b];
      add3(r0 + x, k[0], k[3], k[6]);
      add3(r1 + x, k[1], k[4], k[7]);
      add3(r2 + x, k[2], k[5], k[8]);
      k += 9 * (nn - b - 1);
    }
    for (int b = a; b < nn; b++, k += 9) { /* b >= a: block (a, b) */
      const int x = 3 * oa[b];
      add3(r0 + x, k[0], k[1], k[2]);
      add3(r1 + x, k[3], k[4], k[5]);
      add3(r2 + x, k[6], k[7], k[8]);
    }
  }
}

/* scatter_matrix() of a mass element given by its packed block (block_pack(): the h of each
 * upper node block h I): the same bits, since the blocks' other six entries are zeros that add
 * nothing to the matrix's (which hold sums of zeros, +0.0, there); only the three diagonal
 * entries of each node pair are added to. rows: as there. */
static void scatter_mass(const fcm_space *s, fcm_index le, const double *blk, double *vals,
                         const unsigned char *rows)
{
  const int nn = s->nn;
  const int *off = s->elem_off + (size_t)le * nn * nn;
  for (int a = 0; a < nn; a++) {
    const fcm_index da = fcm__space_elem_row(s, le, a);
    if (rows && !rows[da / 3]) continue;
    double *r0 = vals + s->row_ptr[da], *r1 = vals + s->row_ptr[da + 1];
    double *r2 = vals + s->row_ptr[da + 2];
    const int *oa = off + a * nn;
    const double *h = blk + a; /* b < a: block (b, a) at b nn - b (b - 1) / 2 + a - b */
    for (int b = 0; b < a; b++) {
      const int x = 3 * oa[b];
      r0[x] += *h, r1[x + 1] += *h, r2[x + 2] += *h;
      h += nn - b - 1;
    }
    for (int b = a; b < nn; b++, h++) { /* b >= a: block (a, b) */
      const int x = 3 * oa[b];
      r0[x] += *h, r1[x + 1] += *h, r2[x + 2] += *h;
    }
  }
}

/* Add the element vector of element e into the global vector (rows non-NULL: at the copies
 * it flags only). */
static void scatter_vector(const fcm_space *s, fcm_index e, const double *fe, double *vec,
                           const unsigned char *rows)
{
  const fcm_index *ed = s->elem_dof + e * s->nn;
  for (int a = 0; a < s->nn; a++)
    for (int i = 0; i < 3 && (!rows || rows[ed[a] / 3]); i++)
      vec[ed[a] + i] += fe[3 * a + i];
}

/* 1 when element e of the full space s uses a copy that rows flags (rows NULL: 1). */
static int touches_rows(const fcm_space *s, fcm_index e, const unsigned char *rows)
{
  if (!rows) return 1;
  const fcm_index *ed = s->elem_dof + e * s->nn;
  for (int a = 0; a < s->nn; a++)
    if (rows[ed[a] / 3]) return 1;
  return 0;
}

/* Per-thread scratch for `nthreads` threads. */
static fcm_status scratch_alloc(const fcm_space *s, int nthreads, double **mem, scratch **sc)
{
  fcm_status st = FCM_OK;
  const size_t mq = (size_t)FCM_MAX(s->max_cut_points, 1);
  const size_t per = fcm__kernel_scratch_size(s->nn, mq);
  FCM_ALLOC(s->ctx, per * (size_t)nthreads, *mem);
  FCM_ALLOC(s->ctx, nthreads, *sc);
  for (int t = 0; t < nthreads; t++)
    fcm__kernel_scratch_init(s->nn, mq, *mem + per * (size_t)t, *sc + t);
cleanup:
  return st;
}

/* ------------------------------------------------------------------ workspace */

fcm_status fcm_assembly_workspace_create(const fcm_space *space, const fcm_assembly_options *opts,
                                         fcm_assembly_workspace **out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = space ? space->ctx : NULL;
  fcm_assembly_workspace *ws = NULL;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "assembly workspace: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(space, ctx, FCM_ERR_ARG, "assembly workspace: space is NULL");
  if (opts)
    FCM_CHECK(opts->fictitious >= FCM_FICTITIOUS_PROJECTED &&
                  opts->fictitious < FCM_FICTITIOUS_MODEL_COUNT,
              ctx, FCM_ERR_ARG,
              "assembly: option fictitious = %d out of range [0, %d) (0 projected, 1 linear, "
              "2 exact)",
              (int)opts->fictitious, (int)FCM_FICTITIOUS_MODEL_COUNT);
  FCM_ALLOC(ctx, 1, ws);
  ws->ctx = ctx;
  ws->space = space;
  ws->opts = opts ? *opts : fcm_assembly_options_default();
  ws->nthreads = fcm_ctx_num_threads(ctx);
  FCM_TRY(ctx, scratch_alloc(space, ws->nthreads, &ws->mem, &ws->sc));
  FCM_ALLOC(ctx, space->num_elems + 1, ws->cell_energy);
  FCM_ALLOC(ctx, space->num_elems + 1, ws->cell_inverted);
  *out = ws;
  ws = NULL;
cleanup:
  fcm_assembly_workspace_destroy(&ws);
  return st;
}

void fcm_assembly_workspace_destroy(fcm_assembly_workspace **wsp)
{
  if (!wsp || !*wsp) return;
  fcm_assembly_workspace *ws = *wsp;
  for (int i = 0; i < 2; i++)
    tabulation_free(ws->ctx, &ws->tab[i]);
  fcm__free(ws->ctx, ws->mem);
  fcm__free(ws->ctx, ws->sc);
  fcm__free(ws->ctx, ws->cell_energy);
  fcm__free(ws->ctx, ws->cell_inverted);
  fcm__assembly_corot_free(ws);
  fcm__free(ws->ctx, ws);
  *wsp = NULL;
}

fcm_status fcm__assembly_tabulation(fcm_assembly_workspace *ws, fcm_rule_kind kind,
                                    const tabulation **t)
{
  fcm_status st = FCM_OK;
  int i = kind == FCM_RULE_MASS ? 1 : 0;
  if (!ws->tabulated[i]) {
    int strength = i ? ws->opts.mass_strength : ws->opts.stiffness_strength;
    tabulation fresh;
    memset(&fresh, 0, sizeof fresh);
    st = tabulate(ws->space, kind, strength, &fresh);
    if (st != FCM_OK) {
      tabulation_free(ws->ctx, &fresh);
      FCM_TRY(ws->ctx, st);
    }
    ws->tab[i] = fresh;
    ws->tabulated[i] = 1;
  }
  *t = &ws->tab[i];
cleanup:
  return st;
}

/* ------------------------------------------------------------------ the parallel pass */

/* What one pass over the cells computes, with the outputs it scatters into. */
typedef struct pass {
  const kernel_data *kd; /* volume kernels */
  const tabulation *tab; /* standard rule of the kernel's integrand (volume kernels) */
  fcm_rule_kind kind;    /* cut-cell rule the kernel integrates with */
  fcm_field_fn traction; /* non-NULL: surface traction on the cut cells' surface rules */
  void *traction_user;
  double *vals, *vec;  /* matrix values (space pattern) and vector, either may be NULL */
  double *cell_energy; /* num_elems, or NULL */
  int *cell_inverted;  /* num_elems, or NULL */
  /* Element blocks (fcm__assembly_linear_blocks()): bs doubles per element; an element e with
   * keep_same[e] >= 0 takes its block from keep_in at that element instead of its kernel;
   * keep_out (may be NULL) receives every element's block */
  int bs;
  const fcm_index *keep_same;
  const double *keep_in;
  double *keep_out;
  /* non-NULL (full space, kept blocks): the copies whose rows (matrix) or entries (vector) the
   * pass sums; an element using none of them only passes its block to keep_out */
  const unsigned char *rows;
} pass;

/* An element block of fcm__assembly_linear_blocks(): a mass matrix's upper node blocks are
 * h I (mass_kernel()): their h, nn (nn + 1) / 2 values; a vector its 3 nn entries. */
static void block_pack(int nn, const pass *ps, const scratch *w, double *blk)
{
  if (ps->vals)
    for (int k = 0; k < ps->bs; k++)
      blk[k] = w->Ke[9 * k];
  else
    memcpy(blk, w->fe, sizeof(double) * 3 * (size_t)nn);
}

/* The inverse of block_pack(): the same Ke / fe the kernel gives, bit for bit. */
static void block_unpack(int nn, const pass *ps, const double *blk, scratch *w)
{
  if (ps->vals) {
    for (int k = 0; k < ps->bs; k++) {
      double *Kp = w->Ke + 9 * k;
      const double h = blk[k];
      Kp[0] = h, Kp[1] = Kp[2] = Kp[3] = 0.0;
      Kp[4] = h, Kp[5] = Kp[6] = Kp[7] = 0.0;
      Kp[8] = h;
    }
  } else {
    memcpy(w->fe, blk, sizeof(double) * 3 * (size_t)nn);
  }
}

static int piece_has_surface(const fcm_space *s, fcm_index e)
{
  int np = 0;
  fcm_cell_rules_get_piece_surface(s->rules, s->elem_piece[e], &np, NULL, NULL, NULL, NULL);
  return np > 0;
}

/* Surface traction of element e into w->fe; returns 0 when it has no surface points. */
static int surface_cell(const fcm_space *s, const pass *ps, fcm_index e, scratch *w)
{
  int np = 0, nn = s->nn;
  const double *pts = NULL, *wts = NULL, *nrm = NULL;
  fcm_cell_rules_get_piece_surface(s->rules, s->elem_piece[e], &np, &pts, &wts, &nrm, NULL);
  if (np == 0) return 0;
  fcm_mesh_cell_coords(s->mesh, s->elem_cell[e], w->X);
  memset(w->fe, 0, sizeof(double) * 3 * (size_t)nn);
  for (int q = 0; q < np; q++) {
    double x[3] = {0, 0, 0}, tq[3] = {0, 0, 0};
    fcm_element_eval_shape(s->type, pts + 3 * q, w->Nb);
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++)
        x[i] += w->Nb[a] * w->X[3 * a + i];
    ps->traction(ps->traction_user, x, nrm + 3 * q, tq);
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++)
        w->fe[3 * a + i] += wts[q] * w->Nb[a] * tq[i];
  }
  return 1;
}

/* Volume kernel of element e into w->Ke / w->fe. */
static cell_result volume_cell(const fcm_space *s, const pass *ps, fcm_index e, scratch *w)
{
  const kernel_data *kd = ps->kd;
  int nn = s->nn;
  fcm_mesh_cell_coords(s->mesh, s->elem_cell[e], w->X);
  if (kd->u) {
    const fcm_index *ed = s->elem_dof + e * nn;
    for (int a = 0; a < nn; a++)
      memcpy(w->ue + 3 * a, kd->u + ed[a], 3 * sizeof(double));
  }
  if (kd->kind == KERNEL_COROT_LINEAR)
    return fcm__corot_kernel(kd, kd->corot_K + (size_t)kd->corot_slot[e] * kd->corot_cb,
                             kd->corot_G + (size_t)kd->corot_slot[e] * 3 * nn, nn, w);
  cell_rule r = get_cell_rule(s, ps->tab, ps->kind, e, w);
  return fcm__cell_kernel(kd, &r, nn, w);
}

void fcm__assembly_mean_gradients(const fcm_space *s, const tabulation *t, fcm_index e, scratch *w,
                                  double *gbar)
{
  const int nn = s->nn;
  const size_t rows = 3 * (size_t)fcm__kernel_na(nn);
  fcm_mesh_cell_coords(s->mesh, s->elem_cell[e], w->X);
  cell_rule r = get_cell_rule(s, t, FCM_RULE_STIFFNESS, e, w);
  memset(gbar, 0, sizeof *gbar * 3 * (size_t)nn);
  for (int all = 0; all < 2; all++) { /* authentic points; without any, all points */
    double vol = 0.0;
    for (int q = 0; q < r.nq; q++) {
      if (!all && r.fict && r.fict[q]) continue;
      const double det = fcm__kernel_point_gradients(nn, w->X, r.dT + q * rows, w->g);
      if (!(det > 0.0)) continue;
      vol += r.w[q] * det;
      for (int k = 0; k < 3 * nn; k++)
        gbar[k] += r.w[q] * det * w->g[k];
    }
    if (vol > 0.0) {
      for (int k = 0; k < 3 * nn; k++)
        gbar[k] /= vol;
      return;
    }
  }
}

cell_result fcm__assembly_element_kernel(const fcm_space *s, const tabulation *t,
                                         const kernel_data *kd, fcm_index e, scratch *w)
{
  pass ps;
  memset(&ps, 0, sizeof ps);
  ps.kd = kd;
  ps.tab = t;
  ps.kind = kd->kind == KERNEL_MASS ? FCM_RULE_MASS : FCM_RULE_STIFFNESS;
  return volume_cell(s, &ps, e, w);
}

/* Element c's kept block (keep_in's block `same`) into keep_out (when given) unless in place;
 * the block. */
static const double *keep_block(const pass *ps, fcm_index c, fcm_index same)
{
  const double *in = ps->keep_in + (size_t)same * ps->bs;
  double *out = ps->keep_out ? ps->keep_out + (size_t)c * ps->bs : NULL;
  if (out && out != in) memcpy(out, in, sizeof(double) * (size_t)ps->bs);
  return out ? out : in;
}

/* Local element le of the pass into the pass's outputs; 0 (with res) when its det J is not
 * positive somewhere or the material returned NaN or infinity: nothing is scattered then.
 * next: an element the thread takes after le (its matrix entries are prefetched), or -1;
 * far: one it takes after next (its scatter offsets are prefetched), or -1. */
static int pass_element(const fcm_space *s, const pass *ps, fcm_index le, fcm_index next,
                        fcm_index far, scratch *w, cell_result *res)
{
  const fcm_index c = fcm__space_local_elem(s, le);
  /* another process's element (a distributed run's ghost): no points, nothing to add */
  if (!fcm__space_owns(s, s->elem_cell[c])) return 1;
  const fcm_index same = ps->keep_same ? ps->keep_same[c] : -1;
  if (same >= 0 && ps->vals && ps->keep_out) { /* a mass block kept: scattered as packed */
    const double *out = keep_block(ps, c, same);
    if (touches_rows(s, c, ps->rows)) scatter_mass(s, le, out, ps->vals, ps->rows);
    return 1;
  }
  if (same >= 0 && !touches_rows(s, c, ps->rows)) {
    keep_block(ps, c, same);
    return 1;
  }
  if (same >= 0) {
    block_unpack(s->nn, ps, ps->keep_in + (size_t)same * ps->bs, w);
    keep_block(ps, c, same);
    /* an element without surface points adds nothing (as surface_cell() says below) */
    if (ps->traction && !piece_has_surface(s, c)) return 1;
  } else if (ps->traction) {
    if (!surface_cell(s, ps, c, w)) {
      if (ps->keep_out)
        memset(ps->keep_out + (size_t)c * ps->bs, 0, sizeof(double) * (size_t)ps->bs);
      return 1;
    }
  } else {
    *res = volume_cell(s, ps, c, w);
    if (!(res->bad_det > 0.0) || res->nonfinite) return 0;
    if (ps->cell_energy) ps->cell_energy[c] = res->energy;
    if (ps->cell_inverted) ps->cell_inverted[c] = res->inverted;
  }
  if (ps->keep_out && same < 0) block_pack(s->nn, ps, w, ps->keep_out + (size_t)c * ps->bs);
  if (ps->vals) scatter_matrix(s, le, w->Ke, ps->vals, next, far, ps->rows);
  if (ps->vec) scatter_vector(s, c, w->fe, ps->vec, ps->rows);
  return 1;
}

/* Run the pass over the local elements (a full space: all) by the space's coloured blocks of
 * neighbouring elements: colour by colour, a block per thread at a time, its elements in
 * order, so each matrix entry receives its terms in the same order for any thread count. Each
 * element's result is scattered (matrix: into the space's rows, vector: at the element's DOFs,
 * energy: at its element id); an element with det J <= 0 or a non-finite material response is
 * not, and the cell of the lowest such element of the colour is reported. */
static fcm_status run_pass(fcm_assembly_workspace *ws, const pass *ps)
{
  fcm_status st = FCM_OK;
  const fcm_space *s = ws->space;
  fcm_ctx *ctx = ws->ctx;
  fcm_index bad_cell = -1;
  double bad_det = 1.0;
  int bad_numeric = 0;
  const int ahead = scatter_ahead(s, ps->vals);
  for (int color = 0; color < s->num_block_colors; color++) {
    const fcm_index b0 = s->block_color_ptr[color], b1 = s->block_color_ptr[color + 1];
#pragma omp parallel num_threads(ws->nthreads)
    {
      scratch *w = ws->sc + omp_get_thread_num();
#pragma omp for schedule(dynamic, 1)
      for (fcm_index k = b0; k < b1; k++) {
        const fcm_index first = s->block_ptr[s->block_list[k]];
        const fcm_index last = s->block_ptr[s->block_list[k] + 1];
        for (fcm_index j = first; j < last; j++) {
          const fcm_index le = s->block_elems[j];
          const fcm_index next = ahead && j + ahead < last ? s->block_elems[j + ahead] : -1;
          const fcm_index far = ahead && j + ahead + 2 < last ? s->block_elems[j + ahead + 2] : -1;
          cell_result res;
          if (pass_element(s, ps, le, next, far, w, &res)) continue;
          const fcm_index c = fcm__space_local_elem(s, le);
#pragma omp critical(fcm_assemble_bad)
          if (bad_cell < 0 || c < bad_cell) {
            bad_cell = c;
            bad_det = res.bad_det;
            bad_numeric = res.nonfinite;
          }
        }
      }
    }
    FCM_CHECK(bad_cell < 0 || !bad_numeric, ctx, FCM_ERR_NUMERIC,
              "assembly: the material returned NaN or infinity in cell %lld (deformation "
              "gradient not finite or outside the model's domain)",
              (long long)s->elem_cell[bad_cell]);
    FCM_CHECK(bad_cell < 0, ctx, FCM_ERR_GEOMETRY,
              "assembly: cell %lld has det J = %g <= 0 at a quadrature point (inverted or "
              "degenerate %s)",
              (long long)s->elem_cell[bad_cell], bad_det, fcm_element_get_info(s->type)->name);
  }
cleanup:
  return st;
}

/* A volume pass of kernel `kd` on the standard rule of its integrand. */
static fcm_status run_volume_pass(fcm_assembly_workspace *ws, const kernel_data *kd, double *vals,
                                  double *vec, double *cell_energy, const pass *keep)
{
  fcm_status st = FCM_OK;
  pass ps;
  if (keep)
    ps = *keep;
  else
    memset(&ps, 0, sizeof ps);
  ps.kind = kd->kind == KERNEL_MASS ? FCM_RULE_MASS : FCM_RULE_STIFFNESS;
  FCM_CHECK(!ws->space->rules || fcm_cell_rules_has_kind(ws->space->rules, ps.kind), ws->ctx,
            FCM_ERR_ARG,
            "assembly: the %s needs %s rules, but the space's cell rules were built without them "
            "(add FCM_RULES_%s to fcm_cell_rules_options.kinds)",
            kd->kind == KERNEL_MASS ? "mass matrix" : "stiffness / force integral",
            fcm_rule_kind_name(ps.kind), ps.kind == FCM_RULE_MASS ? "MASS" : "STIFFNESS");
  FCM_TRY(ws->ctx, fcm__assembly_tabulation(ws, ps.kind, &ps.tab));
  ps.kd = kd;
  ps.vals = vals;
  ps.vec = vec;
  ps.cell_energy = cell_energy;
  ps.cell_inverted = kd->kind == KERNEL_HYPERELASTIC ? ws->cell_inverted : NULL;
  FCM_TRY(ws->ctx, run_pass(ws, &ps));
cleanup:
  return st;
}

/* The matrix must carry this space's pattern over its rows. */
static fcm_status check_matrix(const fcm_space *s, const fcm_csr *A)
{
  fcm_status st = FCM_OK;
  fcm_index nr = -1, nc = -1, nnz = -1;
  const fcm_index rows = fcm__space_num_rows(s);
  FCM_CHECK(A, s->ctx, FCM_ERR_ARG, "assembly: matrix is NULL");
  FCM_CHECK(s->row_ptr, s->ctx, FCM_ERR_ARG,
            "assembly: the local space has no topology (a failed rebuild)");
  fcm_csr_get_size(A, &nr, &nc, &nnz);
  FCM_CHECK(nr == rows && nc == s->num_dofs && nnz == s->row_ptr[rows], s->ctx, FCM_ERR_ARG,
            "assembly: matrix is %lld x %lld with %lld entries; the space needs %lld x %lld with "
            "%lld (create it with %s)",
            (long long)nr, (long long)nc, (long long)nnz, (long long)rows, (long long)s->num_dofs,
            (long long)s->row_ptr[rows],
            s->is_local ? "fcm__space_matrix_create_rows" : "fcm_space_matrix_create");
cleanup:
  return st;
}

/* ------------------------------------------------------------------ entry points */

static fcm_status linear_impl(fcm_assembly_workspace *ws, const fcm_linear_form *form, fcm_csr *A,
                              double *f, const pass *keep);

fcm_status fcm_assembly_workspace_linear(fcm_assembly_workspace *ws, const fcm_linear_form *form,
                                         fcm_csr *A, double *f)
{
  return linear_impl(ws, form, A, f, NULL);
}

fcm_status fcm__assembly_linear_blocks(fcm_assembly_workspace *ws, const fcm_linear_form *form,
                                       fcm_csr *A, double *f, const fcm_index *same,
                                       const double *blocks_in, double *blocks_out)
{
  return fcm__assembly_linear_blocks_rows(ws, form, A, f, same, blocks_in, blocks_out, NULL);
}

fcm_status fcm__assembly_linear_blocks_rows(fcm_assembly_workspace *ws, const fcm_linear_form *form,
                                            fcm_csr *A, double *f, const fcm_index *same,
                                            const double *blocks_in, double *blocks_out,
                                            const unsigned char *rows)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws ? ws->ctx : NULL;
  pass keep;
  memset(&keep, 0, sizeof keep);
  FCM_CHECK(ws && form, ctx, FCM_ERR_ARG, "linear assembly (blocks): NULL workspace or form");
  keep.bs = fcm__assembly_block_size(ws->space, form->term);
  FCM_CHECK(keep.bs > 0, ctx, FCM_ERR_UNSUPPORTED,
            "linear assembly (blocks): term %d has no element blocks to keep (the mass, body "
            "forces and surface traction have)",
            (int)form->term);
  FCM_CHECK(!ws->space->is_local, ctx, FCM_ERR_UNSUPPORTED,
            "linear assembly (blocks): the space is a local space (a distributed run's); "
            "element blocks are kept for a full space only");
  FCM_CHECK(!same || blocks_in, ctx, FCM_ERR_ARG,
            "linear assembly (blocks): elements to take from blocks_in, but blocks_in is NULL");
  keep.keep_same = same;
  keep.keep_in = blocks_in;
  keep.keep_out = blocks_out;
  keep.rows = rows;
  FCM_TRY(ctx, linear_impl(ws, form, A, f, &keep));
cleanup:
  return st;
}

static fcm_status linear_impl(fcm_assembly_workspace *ws, const fcm_linear_form *form, fcm_csr *A,
                              double *f, const pass *keep)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws ? ws->ctx : NULL;
  kernel_data kd;
  memset(&kd, 0, sizeof kd);
  FCM_CHECK(ws && form, ctx, FCM_ERR_ARG, "linear assembly: NULL workspace or form");
  const fcm_space *s = ws->space;
  FCM_TRY(ctx, fcm__space_check_assemble(s, "linear assembly")); /* partial on a local space */
  switch (form->term) {
  case FCM_LINEAR_STIFFNESS:
    kd.kind = KERNEL_STIFFNESS;
    FCM_TRY(ctx, fcm_material_lame(ctx, form->material, &kd.lambda, &kd.mu));
    FCM_TRY(ctx, check_matrix(s, A));
    FCM_TRY(ctx, run_volume_pass(ws, &kd, fcm_csr_values(A), NULL, NULL, keep));
    break;
  case FCM_LINEAR_MASS:
    kd.kind = KERNEL_MASS;
    FCM_TRY(ctx, fcm_material_lame(ctx, form->material, NULL, NULL));
    FCM_TRY(ctx, check_matrix(s, A));
    kd.rho = form->material->density;
    FCM_TRY(ctx, run_volume_pass(ws, &kd, fcm_csr_values(A), NULL, NULL, keep));
    break;
  case FCM_LINEAR_BODY_FORCE: {
    const double *a = form->accel;
    kd.kind = KERNEL_BODY_FORCE;
    FCM_TRY(ctx, fcm_material_lame(ctx, form->material, NULL, NULL));
    FCM_CHECK(f && a, ctx, FCM_ERR_ARG, "body force: NULL vector or acceleration");
    FCM_CHECK(isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]), ctx, FCM_ERR_ARG,
              "body force: acceleration (%g, %g, %g) is not finite", a[0], a[1], a[2]);
    kd.rho = form->material->density;
    memcpy(kd.accel, a, sizeof kd.accel);
    FCM_TRY(ctx, run_volume_pass(ws, &kd, NULL, f, NULL, keep));
  } break;
  case FCM_LINEAR_BODY_FORCE_FIELD:
    kd.kind = KERNEL_BODY_FORCE;
    FCM_CHECK(f && form->field, ctx, FCM_ERR_ARG, "body force field: NULL vector or field");
    kd.field = form->field;
    kd.field_user = form->user;
    FCM_TRY(ctx, run_volume_pass(ws, &kd, NULL, f, NULL, keep));
    break;
  case FCM_LINEAR_SURFACE_TRACTION: {
    pass ps;
    if (keep)
      ps = *keep;
    else
      memset(&ps, 0, sizeof ps);
    FCM_CHECK(f && form->field, ctx, FCM_ERR_ARG, "surface traction: NULL vector or traction");
    FCM_CHECK(s->rules && fcm_cell_rules_surface_strength(s->rules) >= 0, ctx, FCM_ERR_ARG,
              "surface traction: the space has no surface rules (build the cell rules with "
              "surface_strength >= 0)");
    ps.traction = form->field;
    ps.traction_user = form->user;
    ps.vec = f;
    FCM_TRY(ctx, run_pass(ws, &ps));
  } break;
  default:
    FCM_CHECK(0, ctx, FCM_ERR_ARG,
              "linear assembly: term = %d outside [FCM_LINEAR_STIFFNESS, "
              "FCM_LINEAR_SURFACE_TRACTION] = [%d, %d]",
              (int)form->term, (int)FCM_LINEAR_STIFFNESS, (int)FCM_LINEAR_SURFACE_TRACTION);
  }
cleanup:
  return st;
}

fcm_status fcm_assembly_workspace_hyperelastic(fcm_assembly_workspace *ws,
                                               const fcm_material_params *mat, const double *u,
                                               double *energy, double *force, fcm_csr *tangent)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws ? ws->ctx : NULL;
  kernel_data kd;
  memset(&kd, 0, sizeof kd);
  FCM_CHECK(ws, ctx, FCM_ERR_ARG, "hyperelastic: workspace is NULL");
  const fcm_space *s = ws->space;
  FCM_TRY(ctx, fcm__space_check_assemble(s, "hyperelastic assembly"));
  FCM_CHECK(mat && u, ctx, FCM_ERR_ARG, "hyperelastic: NULL material or displacement");
  if (tangent) FCM_TRY(ctx, check_matrix(s, tangent));
  kd.kind = KERNEL_HYPERELASTIC;
  kd.mat = mat;
  kd.u = u;
  kd.want_force = force != NULL;
  kd.want_tangent = tangent != NULL;
  kd.fictitious = ws->opts.fictitious;
  kd.mat_psd = *mat;
  kd.mat_psd.project_psd = 1;
  if (mat->model == FCM_MATERIAL_COROTATED_LINEAR) {
    kd.kind = KERNEL_COROT_LINEAR;
    kd.corot_exact = !mat->project_psd && !ws->corot_warped;
    FCM_TRY(ctx, fcm__assembly_corot_prepare(ws, mat, &kd));
  }
  FCM_TRY(ctx, run_volume_pass(ws, &kd, tangent ? fcm_csr_values(tangent) : NULL, force,
                               ws->cell_energy, NULL));
  if (energy) { /* summed in element order: independent of the thread count */
    double e = 0.0;
    for (fcm_index le = 0; le < s->num_local_elems; le++) /* ascending ids; full space: all */
      e += ws->cell_energy[fcm__space_local_elem(s, le)];
    *energy = e;
  }
cleanup:
  return st;
}

fcm_index fcm__assembly_inverted(const fcm_assembly_workspace *ws, fcm_index *first_elem)
{
  const fcm_space *s = ws->space;
  fcm_index count = 0, first = -1;
  for (fcm_index le = 0; le < s->num_local_elems; le++) { /* ascending element ids */
    const fcm_index e = fcm__space_local_elem(s, le);
    if (ws->cell_inverted[e] > 0 && first < 0) first = e;
    count += ws->cell_inverted[e];
  }
  if (first_elem) *first_elem = first;
  return count;
}

int fcm__assembly_inverted_point(fcm_assembly_workspace *ws, fcm_index elem, const double *u,
                                 double X[3], double *det)
{
  const fcm_space *s = ws->space;
  const int nn = s->nn;
  scratch *w = ws->sc;
  if (!ws->tabulated[0] || elem < 0 || elem >= s->num_elems) return 0;
  fcm_mesh_cell_coords(s->mesh, s->elem_cell[elem], w->X);
  const fcm_index *ed = s->elem_dof + elem * nn;
  for (int a = 0; a < nn; a++)
    memcpy(w->ue + 3 * a, u + ed[a], 3 * sizeof(double));
  cell_rule r = get_cell_rule(s, &ws->tab[0], FCM_RULE_STIFFNESS, elem, w);
  const size_t rows = 3 * (size_t)fcm__kernel_na(nn);
  for (int q = 0; q < r.nq; q++) {
    if (r.fict && r.fict[q]) continue;
    double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (!(fcm__kernel_point_gradients(nn, w->X, r.dT + q * rows, w->g) > 0.0)) continue;
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          F[3 * i + j] += w->ue[3 * a + i] * w->g[3 * a + j];
    const double J = fcm__mat3_det(F);
    if (J > 0.0) continue;
    const double *N = r.N + (size_t)q * nn;
    X[0] = X[1] = X[2] = 0.0;
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++)
        X[i] += N[a] * w->X[3 * a + i];
    *det = J;
    return 1;
  }
  return 0;
}

/* ------------------------------------------------------------------ one element */

fcm_status fcm__assembly_element_linear(fcm_assembly_workspace *ws, const fcm_linear_form *form,
                                        fcm_index elem, double *Ke, double *fe)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = ws ? ws->ctx : NULL;
  kernel_data kd;
  pass ps;
  memset(&kd, 0, sizeof kd);
  memset(&ps, 0, sizeof ps);
  FCM_CHECK(ws && form, ctx, FCM_ERR_ARG, "element assembly: NULL workspace or form");
  const fcm_space *s = ws->space;
  FCM_CHECK(elem >= 0 && elem < s->num_elems, ctx, FCM_ERR_ARG,
            "element assembly: element %lld outside [0, %lld)", (long long)elem,
            (long long)s->num_elems);
  switch (form->term) {
  case FCM_LINEAR_STIFFNESS:
    kd.kind = KERNEL_STIFFNESS;
    FCM_TRY(ctx, fcm_material_lame(ctx, form->material, &kd.lambda, &kd.mu));
    break;
  case FCM_LINEAR_MASS:
    kd.kind = KERNEL_MASS;
    FCM_TRY(ctx, fcm_material_lame(ctx, form->material, NULL, NULL));
    kd.rho = form->material->density;
    break;
  case FCM_LINEAR_BODY_FORCE:
    kd.kind = KERNEL_BODY_FORCE;
    FCM_TRY(ctx, fcm_material_lame(ctx, form->material, NULL, NULL));
    FCM_CHECK(form->accel && isfinite(form->accel[0]) && isfinite(form->accel[1]) &&
                  isfinite(form->accel[2]),
              ctx, FCM_ERR_ARG, "element assembly: body force without a finite acceleration");
    kd.rho = form->material->density;
    memcpy(kd.accel, form->accel, sizeof kd.accel);
    break;
  case FCM_LINEAR_BODY_FORCE_FIELD:
    kd.kind = KERNEL_BODY_FORCE;
    FCM_CHECK(form->field, ctx, FCM_ERR_ARG, "element assembly: body force field is NULL");
    kd.field = form->field;
    kd.field_user = form->user;
    break;
  default:
    FCM_CHECK(0, ctx, FCM_ERR_UNSUPPORTED,
              "element assembly: term = %d (stiffness, mass, body force and body force field "
              "only)",
              (int)form->term);
  }
  ps.kind = kd.kind == KERNEL_MASS ? FCM_RULE_MASS : FCM_RULE_STIFFNESS;
  FCM_CHECK(!s->rules || fcm_cell_rules_has_kind(s->rules, ps.kind), ctx, FCM_ERR_ARG,
            "element assembly: the space's cell rules have no %s rules",
            fcm_rule_kind_name(ps.kind));
  FCM_TRY(ctx, fcm__assembly_tabulation(ws, ps.kind, &ps.tab));
  ps.kd = &kd;
  scratch *w = ws->sc;
  cell_result res = volume_cell(s, &ps, elem, w);
  FCM_CHECK(res.bad_det > 0.0, ctx, FCM_ERR_GEOMETRY,
            "assembly: cell %lld has det J = %g <= 0 at a quadrature point (inverted or "
            "degenerate %s)",
            (long long)s->elem_cell[elem], res.bad_det, fcm_element_get_info(s->type)->name);
  const size_t ndof = 3 * (size_t)s->nn;
  if (Ke && kd.kind != KERNEL_BODY_FORCE) fcm__kernel_unpack(s->nn, w->Ke, Ke);
  if (fe && kd.kind == KERNEL_BODY_FORCE) memcpy(fe, w->fe, sizeof *fe * ndof);
cleanup:
  return st;
}
