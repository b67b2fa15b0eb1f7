/* sim: the check, before a static solve, that the active constraints hold every body's
 * rigid-body modes — a static Newton matrix has no mass, so a body free to move rigidly makes
 * it singular whatever the solver, and the step is refused with the body and the free modes.
 *
 * A body is a set of elements joined through shared DOF copies (fcm_space_num_bodies(); cuts
 * separate bodies). Its six rigid modes give every copy of node X the displacement
 * t + w x (X - c); the isoparametric elements reproduce that field exactly, so its strain is
 * zero and the material stiffness (stabilization points included) does not see it. What
 * holds a mode: a constrained DOF where the mode moves (component i at node X: the row
 * (e_i, (e_m x (X - c))_i for m = x, y, z)), and an embedded-boundary point of a boundary
 * constraint (Nitsche or penalty: the same row at the point, whose energy there is
 * gamma/2 |P_c u|^2 > 0 for a moving rigid mode), and an embedded-surface point within the
 * threshold d^ of a contact obstacle at the step's start (the row of its distance's gradient g,
 * (g, y x g): the barrier's Newton matrix w kappa b''(d) g g^T > 0 holds the modes that move it
 * along g; a body beyond every threshold is not held by the obstacles), and a sample within d^
 * of another body's triangle (contact between bodies) once that body is held in all its modes
 * (the same row; body_pair_rows()). The modes that no row holds
 * are the null space of the 6 x 6 Gram matrix of the rows: a body is free when that matrix is
 * singular (eigenvalues below RIGID_TOL of the largest; exactly collinear points give
 * rounding-level values, about 1e-16). Partial constraints (some components only) are covered by
 * the same rank. A copy the space's small-copy constraint moved onto another node's copy
 * (fcm_space_options.constrain_ratio) follows translations exactly but not rotations: a body
 * with such an element has only its translations checked (its rotations meet a stiffness of
 * that fragment, tiny but not zero). So a refused system is singular — a free mode is an
 * exact null vector of the eliminated Newton matrix at rest — or within RIGID_TOL of it. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* A rigid mode counts as free when the rows hold it less than this fraction of the best held
 * mode (Gram eigenvalues, so the squared ratio of the rows' singular values). */
#define RIGID_TOL 1e-12

/* What one body gathers: its Gram matrix (column-major, 6 x 6: translations x, y, z, then
 * rotations about x, y, z), the bounding box of its nodes, counts for the message. */
typedef struct rigid_body {
  double G[36];
  double lo[3], hi[3];
  fcm_index rows[3];    /* constrained rows per component (translations held: rows > 0) */
  fcm_index full, part; /* nodes held in all / in some components */
  fcm_index bpoints;    /* boundary-constraint points */
  fcm_index cpoints;    /* surface points within the barrier's reach of a contact obstacle */
  fcm_index ppoints;    /* surface points within the barrier's reach of a held body */
  int tied;             /* an element uses another node's copy (translations only) */
} rigid_body;

/* Add the row of component i at the point X (body centre c, scale L) to the body. */
static void add_row(rigid_body *b, int i, const double X[3], const double c[3], double L)
{
  double r[6] = {0, 0, 0, 0, 0, 0}, y[3];
  for (int d = 0; d < 3; d++)
    y[d] = (X[d] - c[d]) / L;
  r[i] = 1.0;
  /* (e_m x y)_i for m = x, y, z */
  const int j = (i + 1) % 3, k = (i + 2) % 3;
  r[3 + j] = y[k];  /* (e_j x y)_i = y_k for (i, j, k) cyclic */
  r[3 + k] = -y[j]; /* (e_k x y)_i = -y_j */
  for (int p = 0; p < 6; p++)
    for (int q = 0; q < 6; q++)
      b->G[p + 6 * q] += r[p] * r[q];
  b->rows[i]++;
}

/* Add the row of the direction g (unit) at the point X: the rigid mode's velocity along g,
 * (g, y x g) with y = (X - c) / L (a contact barrier's stiffness acts along its distance's
 * gradient). */
static void add_direction_row(rigid_body *b, const double g[3], const double X[3],
                              const double c[3], double L)
{
  double r[6], y[3];
  for (int d = 0; d < 3; d++)
    y[d] = (X[d] - c[d]) / L;
  r[0] = g[0], r[1] = g[1], r[2] = g[2];
  r[3] = y[1] * g[2] - y[2] * g[1];
  r[4] = y[2] * g[0] - y[0] * g[2];
  r[5] = y[0] * g[1] - y[1] * g[0];
  for (int p = 0; p < 6; p++)
    for (int q = 0; q < 6; q++)
      b->G[p + 6 * q] += r[p] * r[q];
  for (int i = 0; i < 3; i++)
    if (fabs(g[i]) > 1e-9) b->rows[i]++;
}

static void centre_scale(const rigid_body *b, double c[3], double *L)
{
  double d2 = 0.0;
  for (int d = 0; d < 3; d++) {
    c[d] = 0.5 * (b->lo[d] + b->hi[d]);
    d2 += (b->hi[d] - b->lo[d]) * (b->hi[d] - b->lo[d]);
  }
  *L = d2 > 0.0 ? 0.5 * sqrt(d2) : 1.0;
}

/* "3 rigid-body translations and 1 rotation", "2 rigid-body rotations", ... */
static void free_modes(char *buf, size_t n, int ft, int fr)
{
  if (ft > 0 && fr > 0)
    snprintf(buf, n, "%d rigid-body translation%s and %d rotation%s", ft, ft > 1 ? "s" : "", fr,
             fr > 1 ? "s" : "");
  else if (ft > 0)
    snprintf(buf, n, "%d rigid-body translation%s", ft, ft > 1 ? "s" : "");
  else
    snprintf(buf, n, "%d rigid-body rotation%s", fr, fr > 1 ? "s" : "");
}

/* "1 node in all components, 2 nodes in some components and 5 boundary-constraint points",
 * or "nothing (...)". */
static void held_by(char *buf, size_t n, const rigid_body *b)
{
  int len = 0;
  buf[0] = '\0';
  if (b->full > 0)
    len += snprintf(buf + len, n - (size_t)len, "%lld node%s in all components", (long long)b->full,
                    b->full > 1 ? "s" : "");
  if (b->part > 0)
    len += snprintf(buf + len, n - (size_t)len, "%s%lld node%s in some components",
                    len ? (b->bpoints ? ", " : " and ") : "", (long long)b->part,
                    b->part > 1 ? "s" : "");
  if (b->bpoints > 0)
    len += snprintf(buf + len, n - (size_t)len, "%s%lld boundary-constraint point%s",
                    len ? " and " : "", (long long)b->bpoints, b->bpoints > 1 ? "s" : "");
  if (b->cpoints > 0)
    len += snprintf(buf + len, n - (size_t)len,
                    "%s%lld surface point%s within a contact "
                    "obstacle's threshold",
                    len ? " and " : "", (long long)b->cpoints, b->cpoints > 1 ? "s" : "");
  if (b->ppoints > 0)
    len += snprintf(buf + len, n - (size_t)len,
                    "%s%lld surface point%s within the threshold of a held body",
                    len ? " and " : "", (long long)b->ppoints, b->ppoints > 1 ? "s" : "");
  if (len == 0)
    snprintf(buf, n,
             "nothing (no constrained node, no boundary-constraint point, no surface point "
             "within a contact obstacle's threshold)");
}

/* Free modes of body b: *ft free translations, *fr free rotations; for a single free
 * rotation, its axis (a point p and the unit direction a). */
static fcm_status body_free_modes(fcm_ctx *ctx, const rigid_body *b, int *ft, int *fr, double p[3],
                                  double a[3])
{
  fcm_status st = FCM_OK;
  double G[36], w[6], c[3], L;
  *ft = (b->rows[0] == 0) + (b->rows[1] == 0) + (b->rows[2] == 0);
  *fr = 0;
  if (b->tied) return FCM_OK; /* rotations not exact null vectors: translations only */
  memcpy(G, b->G, sizeof G);
  FCM_TRY(ctx, fcm__syev(ctx, 1, 6, G, 6, w));
  int nfree = 0;
  for (int q = 0; q < 6; q++)
    nfree += !(w[q] > RIGID_TOL * w[5]);
  *fr = nfree - *ft > 0 ? nfree - *ft : 0;
  if (*ft == 0 && *fr == 1) {
    /* the null vector (t, w/L): the field t + w x (X - c) vanishes on the axis through
     * p = c + (w x t) / |w|^2 along w */
    const double *v = G; /* eigenvector of the smallest eigenvalue */
    double om[3], t[3], wn = 0.0;
    centre_scale(b, c, &L);
    for (int d = 0; d < 3; d++) {
      t[d] = v[d];
      om[d] = v[3 + d] / L;
      wn += om[d] * om[d];
    }
    const double cr[3] = {om[1] * t[2] - om[2] * t[1], om[2] * t[0] - om[0] * t[2],
                          om[0] * t[1] - om[1] * t[0]};
    int big = 0; /* the sign of an eigenvector is arbitrary: its largest component positive */
    for (int d = 1; d < 3; d++)
      if (fabs(om[d]) > fabs(om[big])) big = d;
    if (om[big] < 0.0)
      for (int d = 0; d < 3; d++)
        om[d] = -om[d], t[d] = -t[d];
    for (int d = 0; d < 3; d++) {
      p[d] = wn > 0.0 ? c[d] + cr[d] / wn : c[d];
      a[d] = wn > 0.0 ? om[d] / sqrt(wn) : 0.0;
      if (fabs(p[d]) < 1e-12 * (L + fabs(c[d]))) p[d] = 0.0; /* rounding, for the message */
      if (fabs(a[d]) < 1e-12) a[d] = 0.0;
    }
  }
cleanup:
  return st;
}

/* What the check builds: the bodies (element -> body, copy -> node and body) and their data. */
/* A pair of surface points of two bodies within the threshold of the contact between bodies. */
typedef struct rigid_pair {
  fcm_index a, b;
  double ya[3], yb[3], g[3];
} rigid_pair;

typedef struct rigid_work {
  fcm_index *elem_body, *copy_node, *copy_body, nb;
  unsigned char *held; /* per copy: its constrained components */
  rigid_body *B;
  double *sum; /* with a backend: the summed boundary parts, 40 per body */
  rigid_pair *pairs;
  size_t npairs, cap_pairs;
  int failed; /* out of memory while collecting the pairs */
  fcm_ctx *ctx;
} rigid_work;

/* Local phase: the bodies, their bounding boxes and tied elements, and the rows of this
 * process's boundary-constraint points (a distributed run's own cells hold them). */
static fcm_status local_rows(fcm_integrator *I, rigid_work *w)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_space *s = I->space;
  const fcm_mesh *mesh = fcm_space_mesh(s);
  const double *X = fcm_mesh_coords(mesh);
  const fcm_index *cells = fcm_mesh_cells(mesh), ncopy = s->num_dofs / 3;
  const int nn = s->nn;
  FCM_ALLOC(ctx, s->num_elems + 1, w->elem_body);
  FCM_ALLOC(ctx, ncopy + 1, w->copy_node);
  FCM_ALLOC(ctx, ncopy + 1, w->copy_body);
  FCM_ALLOC(ctx, ncopy + 1, w->held);
  FCM_TRY(ctx, fcm__space_body_labels(s, w->elem_body, &w->nb));
  FCM_ALLOC(ctx, w->nb + 1, w->B);
  FCM_ALLOC(ctx, 40 * (size_t)w->nb + 1, w->sum);
  rigid_body *B = w->B;
  for (fcm_index node = 0; node < s->num_nodes; node++)
    for (fcm_index c = 0; s->node_dof[node] >= 0 && c < s->node_ncopy[node]; c++)
      w->copy_node[s->node_dof[node] / 3 + c] = node;
  for (fcm_index b = 0; b < w->nb; b++)
    for (int d = 0; d < 3; d++) {
      B[b].lo[d] = HUGE_VAL;
      B[b].hi[d] = -HUGE_VAL;
    }
  for (fcm_index k = 0; k < ncopy; k++)
    w->copy_body[k] = -1;
  for (fcm_index e = 0; e < s->num_elems; e++)
    for (int a = 0; a < nn; a++) {
      const fcm_index k = s->elem_dof[e * nn + a] / 3, b = w->elem_body[e];
      w->copy_body[k] = b;
      if (w->copy_node[k] != cells[s->elem_cell[e] * nn + a]) B[b].tied = 1;
      for (int d = 0; d < 3; d++) {
        const double x = X[3 * w->copy_node[k] + d];
        B[b].lo[d] = x < B[b].lo[d] ? x : B[b].lo[d];
        B[b].hi[d] = x > B[b].hi[d] ? x : B[b].hi[d];
      }
    }
  const sim_bpoints *bp = &I->bp;
  if (I->bcon_active > 0)
    for (fcm_index k = 0; k < bp->nelem; k++) {
      rigid_body *b = &B[w->elem_body[bp->elem[k]]];
      double c[3], L;
      centre_scale(b, c, &L);
      for (fcm_index p = bp->ptr[k]; p < bp->ptr[k + 1]; p++) {
        if (!I->bcon_on[bp->con[p]]) continue;
        const int *comp = I->bcons[bp->con[p]].motion.components;
        for (int i = 0; i < 3; i++)
          if (comp[i]) add_row(b, i, bp->X + 3 * p, c, L);
        b->bpoints++;
      }
    }
cleanup:
  return st;
}

/* Agree on the local phase's status and sum the boundary parts over the processes of the
 * backend (36 + 4 values per body; the body numbering is the same everywhere; the serial
 * backend's sums are the parts themselves). Collective: every process calls it, whatever its
 * local status. */
static fcm_status sum_boundary(fcm_integrator *I, fcm_status st, rigid_work *w)
{
  double *v = w->sum;
  if (st == FCM_OK)
    for (fcm_index b = 0; b < w->nb; b++) {
      memcpy(v + 40 * b, w->B[b].G, sizeof w->B[b].G);
      for (int i = 0; i < 3; i++)
        v[40 * b + 36 + i] = (double)w->B[b].rows[i];
      v[40 * b + 39] = (double)w->B[b].bpoints;
    }
  st = fcm__integrator_reduce_status(I, st, st == FCM_OK ? v : NULL, st == FCM_OK ? 40 * w->nb : 0);
  if (st != FCM_OK) return st;
  for (fcm_index b = 0; b < w->nb; b++) {
    memcpy(w->B[b].G, v + 40 * b, sizeof w->B[b].G);
    for (int i = 0; i < 3; i++)
      w->B[b].rows[i] = (fcm_index)v[40 * b + 36 + i];
    w->B[b].bpoints = (fcm_index)v[40 * b + 39];
  }
  return FCM_OK;
}

/* The rows of the active constrained DOFs (the same on every process) and the held counts. */
static void node_rows(fcm_integrator *I, rigid_work *w)
{
  const double *X = fcm_mesh_coords(fcm_space_mesh(I->space));
  const fcm_index ncopy = I->space->num_dofs / 3;
  for (fcm_index j = 0; j < I->nact; j++) {
    const fcm_index dof = I->act_dof[j], k = dof / 3;
    if (w->copy_body[k] < 0) continue; /* a copy no element uses holds nothing */
    rigid_body *b = &w->B[w->copy_body[k]];
    double c[3], L;
    centre_scale(b, c, &L);
    add_row(b, (int)(dof % 3), X + 3 * w->copy_node[k], c, L);
    w->held[k]++;
  }
  for (fcm_index k = 0; k < ncopy; k++)
    if (w->held[k] > 0 && w->copy_body[k] >= 0) {
      if (w->held[k] == 3)
        w->B[w->copy_body[k]].full++;
      else
        w->B[w->copy_body[k]].part++;
    }
}

/* A surface point within d^ of a contact obstacle (fcm__sim_contact_support()): the
 * barrier's Newton matrix w kappa b''(d) g g^T holds the modes that move the point along g. */
static void contact_row(void *user, fcm_index elem, const double y[3], const double g[3])
{
  rigid_work *w = user;
  rigid_body *b = &w->B[w->elem_body[elem]];
  double c[3], L;
  centre_scale(b, c, &L);
  add_direction_row(b, g, y, c, L);
  b->cpoints++;
}

static void pair_row(void *user, fcm_index ea, const double ya[3], fcm_index eb, const double yb[3],
                     const double g[3])
{
  rigid_work *w = user;
  if (w->npairs == w->cap_pairs) {
    const size_t cap = w->cap_pairs ? 2 * w->cap_pairs : 64;
    void *grown = w->pairs;
    if (w->failed || fcm__resize(w->ctx, &grown, w->cap_pairs, cap, sizeof *w->pairs) != FCM_OK) {
      w->failed = 1;
      return;
    }
    w->pairs = grown;
    w->cap_pairs = cap;
  }
  rigid_pair *q = w->pairs + w->npairs++;
  q->a = w->elem_body[ea];
  q->b = w->elem_body[eb];
  memcpy(q->ya, ya, sizeof q->ya);
  memcpy(q->yb, yb, sizeof q->yb);
  memcpy(q->g, g, sizeof q->g);
}

/* Whether body b's modes are all held by its rows so far. */
static fcm_status body_held(fcm_ctx *ctx, const rigid_body *b, int *held)
{
  int ft = 0, fr = 0;
  double p[3], a[3];
  fcm_status st = body_free_modes(ctx, b, &ft, &fr, p, a);
  *held = st == FCM_OK && ft + fr == 0;
  return st;
}

/* Contact between bodies: a pair within d^ couples two bodies through the barrier's
 * w kappa b''(d) G G^T, so a body held in all six modes holds its partner along g at the pair's
 * point, as an obstacle would. In passes: the bodies held so far (pass 0: by constraints and
 * obstacles) hold their partners; a partner then held in all its modes holds its own partners
 * at the next pass. Each pair adds its row once, in the pass after its holding side became
 * held. */
static fcm_status body_pair_rows(fcm_integrator *I, rigid_work *w)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  int *when = NULL, held = 0;
  const sim_contact *bc = NULL;
  for (int c = 0; c < I->num_contacts; c++)
    if (I->contacts[c].kind == SIM_CONTACT_BODIES) bc = &I->contacts[c];
  if (!bc || w->nb < 2) return FCM_OK;
  w->ctx = ctx;
  FCM_TRY(ctx, fcm__sim_bodies_support(I, bc, I->u, pair_row, w));
  FCM_CHECK(!w->failed, ctx, FCM_ERR_ALLOC, "integrator: out of memory (rigid-mode check)");
  FCM_ALLOC(ctx, (size_t)w->nb, when);
  for (fcm_index b = 0; b < w->nb; b++) {
    FCM_TRY(ctx, body_held(ctx, &w->B[b], &held));
    when[b] = held ? 0 : -1;
  }
  for (int pass = 1; pass <= w->nb; pass++) {
    int any = 0;
    for (size_t k = 0; k < w->npairs; k++) {
      const rigid_pair *q = w->pairs + k;
      for (int side = 0; side < 2; side++) {
        const fcm_index from = side ? q->a : q->b, to = side ? q->b : q->a;
        if (from == to || when[from] != pass - 1 || when[to] >= 0) continue;
        double c[3], L;
        centre_scale(&w->B[to], c, &L);
        add_direction_row(&w->B[to], q->g, side ? q->yb : q->ya, c, L);
        w->B[to].ppoints++;
      }
    }
    for (fcm_index b = 0; b < w->nb; b++) {
      if (when[b] >= 0) continue;
      FCM_TRY(ctx, body_held(ctx, &w->B[b], &held));
      if (held) when[b] = pass, any = 1;
    }
    if (!any) break;
  }
cleanup:
  fcm__free(ctx, when);
  return st;
}

fcm_status fcm__sim_check_rigid_modes(fcm_integrator *I, double t)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  rigid_work w;
  memset(&w, 0, sizeof w);
  st = local_rows(I, &w);
  st = sum_boundary(I, st, &w);
  FCM_TRY(ctx, st);
  node_rows(I, &w);
  if (I->num_contacts > 0) FCM_TRY(ctx, fcm__sim_contact_support(I, I->u, t, contact_row, &w));
  if (I->num_contacts > 0) FCM_TRY(ctx, body_pair_rows(I, &w));
  fcm_index bad = -1, nbad = 0;
  int ft = 0, fr = 0;
  double p[3] = {0, 0, 0}, a[3] = {0, 0, 0};
  for (fcm_index b = 0; b < w.nb; b++) {
    int t_free = 0, r_free = 0;
    double pb[3] = {0, 0, 0}, ab[3] = {0, 0, 0};
    FCM_TRY(ctx, body_free_modes(ctx, &w.B[b], &t_free, &r_free, pb, ab));
    if (t_free + r_free == 0) continue;
    if (nbad++ == 0) {
      bad = b;
      ft = t_free;
      fr = r_free;
      memcpy(p, pb, sizeof p);
      memcpy(a, ab, sizeof a);
    }
  }
  if (bad >= 0) {
    const rigid_body *b = &w.B[bad];
    char modes[96], held_s[256], axis[192] = "", more[96] = "";
    free_modes(modes, sizeof modes, ft, fr);
    held_by(held_s, sizeof held_s, b);
    if (ft == 0 && fr == 1)
      snprintf(axis, sizeof axis,
               " (about the axis through (%.6g, %.6g, %.6g) along (%.3g, %.3g, %.3g))", p[0], p[1],
               p[2], a[0], a[1], a[2]);
    if (nbad > 1)
      snprintf(more, sizeof more, " (%lld of the %lld bodies are free)", (long long)nbad,
               (long long)w.nb);
    FCM_CHECK(0, ctx, FCM_ERR_SINGULAR,
              "integrator: static step to t = %g refused before any solve: the system is "
              "singular: body %lld of %lld (background nodes in [%.6g, %.6g] x [%.6g, %.6g] x "
              "[%.6g, %.6g]) is held by %s, which leaves %s free%s%s, and a static step has no "
              "inertia to hold them. Fix 3 non-collinear points of every body in all "
              "components (fixed or motion regions), hold part of its surface (a boundary "
              "constraint), start it within the threshold of contact obstacles that hold it, "
              "or run it dynamically",
              t, (long long)bad, (long long)w.nb, b->lo[0], b->hi[0], b->lo[1], b->hi[1], b->lo[2],
              b->hi[2], held_s, modes, axis, more);
  }
cleanup:
  fcm__free(ctx, w.elem_body);
  fcm__free(ctx, w.copy_node);
  fcm__free(ctx, w.copy_body);
  fcm__free(ctx, w.held);
  fcm__free(ctx, w.B);
  fcm__free(ctx, w.sum);
  fcm__free(ctx, w.pairs);
  return st;
}
