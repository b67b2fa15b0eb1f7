/* sim: contact between the bodies and cut pieces of one space — the log barrier of
 * contact.c between the sample points of each piece's surface and the triangles of the others.
 *
 * The surface is the embedded surface of the space (fcm_embedded_surface_create(): the
 * geometry's boundary triangles split by the cuts, and both sides of each cut face), each of
 * its points ("nodes") moving with the element that holds it: y_v = X_v + sum_a N_a(X_v) u_a.
 * A triangle is the flat triangle through its three deformed nodes. A piece is a body of the
 * space (fcm__space_body_labels(): elements joined through shared DOF copies); a triangle
 * belongs to the body of its nodes' elements. Without self-contact a sample never sees the
 * triangles of its own body; with it (fcm_contact_options.self_contact) it sees those farther
 * than rho = 2 d^ from it in the reference state (fcm__sim_bodies_excluded()), and the step
 * filter bounds these pairs by the relative motion of the triangle's nodes to the sample.
 *
 * Samples: every node (the vertices) and the three interior points of each triangle's
 * three-point rule (barycentric (2/3, 1/6, 1/6) and its permutations), a sample being a
 * barycentric combination p = sum_j lam_j y_(t_j) of its triangle's nodes. Weights: each
 * triangle's area A goes half to its interior points (A / 6 each) and half to its vertices
 * (A / 6 each), so the weights add up to the surface's area.
 *
 * A pair (sample p, triangle T of another body) at the point-triangle distance
 * d = |p - q|, q = sum_k beta_k z_k the closest point of T (z_k its deformed nodes), adds
 * w kappa b(d) (contact.c's barrier). By the envelope theorem the gradient of d is
 * g = (p - q) / d with respect to p and -beta_k g with respect to z_k in every region (face,
 * edge, vertex), so the force on the DOF (a, i) of node v's element is
 * w kappa b'(d) c_v N_a(X_v) g_i with c_v = lam_j for the sample's nodes and -beta_k for the
 * triangle's: exact. The pair's Newton matrix keeps w kappa b''(d) G G^T (G = dd/du; the
 * part of the exact Hessian without the distance's curvature, positive semidefinite as for
 * the obstacles). G spans the elements of up to six nodes in different pieces, whose DOFs the
 * space's matrix pattern does not couple; the Newton matrix therefore gets the block-diagonal
 * bound m sum_e G_e G_e^T >= G G^T (m the number of distinct elements, Cauchy-Schwarz), which
 * fits the pattern, and Newton's direction is refined by preconditioned conjugate gradients on
 * the coupled matrix (the pairs recorded at the matrix's assembly, applied matrix-free; the
 * factorization of the assembled matrix preconditions).
 *
 * Broad phase: a bounding-volume hierarchy with one subtree per body (contact_bvh.c), built
 * again at each substep's start and refitted to the deformed triangles at every evaluation;
 * each sample queries the box of radius d^ about it in the subtrees of the bodies whose boxes
 * come within d^ of its own body's box.
 *
 * Step filter (no sample crosses a triangle): along x + alpha dx the distance of a pair is at
 * least d - alpha (|dp| + max_k |dz_k|), the triangle's points moving by at most its nodes'
 * largest motion, so alpha < d / (|dp| + max_k |dz_k|) keeps it positive (conservative).
 *
 * The faces of a cut start in contact (both sides of a cut face coincide), and so do pieces
 * that touch at a cut's start: at the first substep every sample records the bodies within d^
 * of it (at most SIM_BLIND); the barrier ignores them until it is d^ away from them at a
 * substep's start, from then on they repel it. Until then a penalty w kappa s^2 / 2 acts on
 * the signed gap s < 0 below each such body's closest triangle, lagged at the substep's start
 * (the triangle, the closest point's barycentric coordinates and the outward normal fixed, so
 * s is linear in the DOFs). */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/vec3.h"

#include <float.h>
#include <math.h>
#include <string.h>

#define SIM_BLIND 8
/* The direction's refinement: preconditioned CG iterations at most, relative residual. */
#define SIM_REFINE_MAX  200
#define SIM_REFINE_RTOL 1e-10

static const double rule3[3][3] = {
    {2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}};

void fcm__sim_bodies_free(fcm_ctx *ctx, sim_contact *c)
{
  sim_bodies *B = c->bodies;
  if (!B) return;
  fcm_embedded_surface_destroy(&B->es);
  fcm__free(ctx, B->velem);
  fcm__free(ctx, B->eptr);
  fcm__free(ctx, B->enode);
  fcm__free(ctx, B->vw);
  fcm__free(ctx, B->vX);
  fcm__free(ctx, B->vN);
  fcm__free(ctx, B->tbody);
  fcm__free(ctx, B->stri);
  fcm__free(ctx, B->slam);
  fcm__free(ctx, B->sw);
  fcm__free(ctx, B->blind);
  fcm__free(ctx, B->lag_t);
  fcm__free(ctx, B->lag);
  fcm__free(ctx, B->y);
  fcm__free(ctx, B->dy);
  fcm__free(ctx, B->boxes);
  fcm__free(ctx, B->Ke);
  fcm__sim_bvh_free(ctx, &B->bvh);
  fcm__free(ctx, B->near_ptr);
  fcm__free(ctx, B->near);
  fcm__free(ctx, B->pairs);
  fcm__free(ctx, B->w1);
  fcm__free(ctx, B->w2);
  fcm__free(ctx, B->w3);
  fcm__free(ctx, B->w4);
  fcm__free(ctx, B->y0);
  fcm__free(ctx, B->fp);
  fcm__geom_idbuf_free(ctx, &B->buf);
  fcm__free(ctx, B);
  c->bodies = NULL;
}

static double tri_area(const double *a, const double *b, const double *c)
{
  double u[3], v[3], n[3];
  fcm__vec3_sub(b, a, u);
  fcm__vec3_sub(c, a, v);
  fcm__vec3_cross(u, v, n);
  return 0.5 * fcm__vec3_norm(n);
}

/* The nodes grouped by element (eptr, enode) and their weights against the obstacles (vw):
 * the area about them of the cut-face triangles, 1e-3 of their area (area) elsewhere. */
static fcm_status obstacle_nodes(fcm_integrator *I, sim_bodies *B, const double *area)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_index ne = I->space->num_elems;
  FCM_ALLOC(ctx, (size_t)ne + 2, B->eptr);
  FCM_ALLOC(ctx, (size_t)B->nv + 1, B->enode);
  FCM_ALLOC(ctx, (size_t)B->nv + 1, B->vw);
  for (fcm_index t = 0; t < B->nt; t++) {
    const fcm_index *tv = B->tri + 3 * t;
    if (B->tbody[t] < 0) continue;
    const double A = tri_area(B->vX + 3 * tv[0], B->vX + 3 * tv[1], B->vX + 3 * tv[2]);
    for (int k = 0; k < 3; k++)
      if (B->es->flag[tv[k]]) B->vw[tv[k]] += A / 3.0;
  }
  for (fcm_index v = 0; v < B->nv; v++) {
    if (!(B->vw[v] > 0.0)) B->vw[v] = 1e-3 * area[v];
    if (B->vw[v] > 0.0 && B->velem[v] >= 0) B->eptr[B->velem[v] + 2]++;
  }
  for (fcm_index e = 0; e < ne; e++)
    B->eptr[e + 2] += B->eptr[e + 1];
  for (fcm_index v = 0; v < B->nv; v++)
    if (B->vw[v] > 0.0 && B->velem[v] >= 0) B->enode[B->eptr[B->velem[v] + 1]++] = v;
cleanup:
  return st;
}

fcm_index fcm__sim_bodies_element_nodes(const fcm_integrator *I, fcm_index e, double *w, double *X,
                                        double *N)
{
  const int nn = I->space->nn;
  for (int c = 0; c < I->num_contacts; c++) {
    const sim_bodies *B = I->contacts[c].bodies;
    if (!B || !B->eptr) continue;
    const fcm_index n = B->eptr[e + 1] - B->eptr[e];
    for (fcm_index k = 0; w && k < n; k++) {
      const fcm_index v = B->enode[B->eptr[e] + k];
      w[k] = B->vw[v];
      memcpy(X + 3 * k, B->vX + 3 * v, 3 * sizeof(double));
      memcpy(N + (size_t)k * nn, B->vN + (size_t)v * nn, sizeof(double) * (size_t)nn);
    }
    return n;
  }
  return 0;
}

/* The nodes' elements, shape values and bodies, the triangles' bodies and the samples. */
static fcm_status build_samples(fcm_integrator *I, sim_bodies *B)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_space *s = I->space;
  const int nn = s->nn;
  const fcm_embedded_surface *es = B->es;
  fcm_index *ebody = NULL, nb = 0;
  double *vw = NULL;
  B->nv = es->np;
  B->nt = es->nt;
  B->tri = es->tri;
  FCM_ALLOC(ctx, (size_t)s->num_elems + 1, ebody);
  FCM_TRY(ctx, fcm__space_body_labels(s, ebody, &nb));
  B->num_bodies = nb;
  FCM_ALLOC(ctx, (size_t)B->nv + 1, B->velem);
  FCM_ALLOC(ctx, 3 * (size_t)B->nv + 1, B->vX);
  FCM_ALLOC(ctx, (size_t)B->nv * nn + 1, B->vN);
  FCM_ALLOC(ctx, (size_t)B->nv + 1, vw);
  FCM_ALLOC(ctx, (size_t)B->nt + 1, B->tbody);
  for (fcm_index v = 0; v < B->nv; v++) {
    B->velem[v] = es->elem[v];
    memcpy(B->vX + 3 * v, es->X + 3 * v, 3 * sizeof(double));
    fcm_element_eval_shape(s->type, es->xi + 3 * v, B->vN + (size_t)v * nn);
  }
  B->ns = 0;
  for (fcm_index t = 0; t < B->nt; t++) {
    const fcm_index *tv = B->tri + 3 * t;
    const double A = tri_area(B->vX + 3 * tv[0], B->vX + 3 * tv[1], B->vX + 3 * tv[2]);
    int ok = A > 0.0;
    for (int k = 0; k < 3; k++)
      ok &= B->velem[tv[k]] >= 0;
    B->tbody[t] = ok ? ebody[B->velem[tv[0]]] : -1;
    if (!ok) continue;
    for (int k = 0; k < 3; k++)
      vw[tv[k]] += A / 6.0;
    B->ns += 3;
  }
  for (fcm_index v = 0; v < B->nv; v++)
    B->ns += vw[v] > 0.0;
  FCM_TRY(ctx, obstacle_nodes(I, B, vw));
  FCM_ALLOC(ctx, (size_t)B->ns + 1, B->stri);
  FCM_ALLOC(ctx, 3 * (size_t)B->ns + 1, B->slam);
  FCM_ALLOC(ctx, (size_t)B->ns + 1, B->sw);
  {
    fcm_index n = 0;
    for (fcm_index t = 0; t < B->nt; t++) {
      const fcm_index *tv = B->tri + 3 * t;
      if (B->tbody[t] < 0) continue;
      const double A = tri_area(B->vX + 3 * tv[0], B->vX + 3 * tv[1], B->vX + 3 * tv[2]);
      for (int q = 0; q < 3; q++, n++) {
        B->stri[n] = t;
        memcpy(B->slam + 3 * n, rule3[q], sizeof rule3[q]);
        B->sw[n] = A / 6.0;
      }
      for (int k = 0; k < 3; k++) { /* each vertex once, with its first triangle */
        if (!(vw[tv[k]] > 0.0)) continue;
        B->stri[n] = t;
        B->slam[3 * n + k] = 1.0;
        B->sw[n] = vw[tv[k]];
        vw[tv[k]] = 0.0;
        n++;
      }
    }
  }
cleanup:
  fcm__free(ctx, ebody);
  fcm__free(ctx, vw);
  return st;
}

fcm_status fcm__sim_bodies_setup(fcm_integrator *I, sim_contact *c)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const int nn = I->space->nn;
  sim_bodies *B = NULL;
  fcm__sim_bodies_free(ctx, c);
  FCM_ALLOC(ctx, 1, B);
  c->bodies = B;
  B->self = c->opts.self_contact;
  FCM_TRY(ctx, fcm_embedded_surface_create(I->space, c->geom, &B->es));
  FCM_TRY(ctx, build_samples(I, B));
  FCM_ALLOC(ctx, (size_t)B->ns * SIM_BLIND + 1, B->blind);
  FCM_ALLOC(ctx, (size_t)B->ns * SIM_BLIND + 1, B->lag_t);
  FCM_ALLOC(ctx, (size_t)B->ns * SIM_BLIND * 6 + 1, B->lag);
  for (fcm_index k = 0; k < B->ns * SIM_BLIND; k++)
    B->blind[k] = -1;
  FCM_ALLOC(ctx, 3 * (size_t)B->nv + 1, B->y);
  FCM_ALLOC(ctx, 3 * (size_t)B->nv + 1, B->dy);
  FCM_ALLOC(ctx, 6 * (size_t)B->nt + 1, B->boxes);
  FCM_ALLOC(ctx, (size_t)9 * nn * nn, B->Ke);
  FCM_ALLOC(ctx, (size_t)B->num_bodies + 1, B->near_ptr);
  FCM_ALLOC(ctx, (size_t)B->num_bodies * B->num_bodies + 1, B->near);
  FCM_ALLOC(ctx, (size_t)I->n + 1, B->w1);
  FCM_ALLOC(ctx, (size_t)I->n + 1, B->w2);
  FCM_ALLOC(ctx, (size_t)I->n + 1, B->w3);
  FCM_ALLOC(ctx, (size_t)I->n + 1, B->w4);
cleanup:
  return st;
}

/* The nodes' positions X + u (x NULL: the motion dx only, into out). */
void fcm__sim_bodies_positions(const fcm_space *s, const sim_bodies *B, const double *x, int motion,
                               double *out)
{
  const int nn = s->nn;
  for (fcm_index v = 0; v < B->nv; v++) {
    const fcm_index *ed = s->elem_dof + B->velem[v] * nn;
    const double *N = B->vN + (size_t)v * nn;
    double *y = out + 3 * v;
    for (int i = 0; i < 3; i++)
      y[i] = motion ? 0.0 : B->vX[3 * v + i];
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++)
        y[i] += N[a] * x[ed[a] + i];
  }
}

/* The triangles' boxes at the node positions y, swept over y + s dy for s in [0, 2] when dy
 * is given; then the tree built again (rebuild) or refitted to them. */
/* For each body the other bodies whose boxes come within pad of its box (near_ptr, near). */
static void near_bodies(sim_bodies *B, double pad)
{
  const fcm_index nb = B->num_bodies;
  fcm_index m = 0;
  for (fcm_index g = 0; g < nb; g++) {
    B->near_ptr[g] = m;
    if (B->bvh.root[g] < 0) continue;
    const sim_bvh_node *a = B->bvh.node + B->bvh.root[g];
    for (fcm_index h = 0; h < nb; h++) {
      if (h == g || B->bvh.root[h] < 0) continue;
      const sim_bvh_node *b = B->bvh.node + B->bvh.root[h];
      int meet = 1;
      for (int i = 0; i < 3; i++)
        meet &= a->lo[i] - pad <= b->hi[i] && b->lo[i] <= a->hi[i] + pad;
      if (meet) B->near[m++] = h;
    }
  }
  B->near_ptr[nb] = m;
}

fcm_status fcm__sim_bodies_boxes(fcm_ctx *ctx, sim_bodies *B, const double *y, const double *dy,
                                 int rebuild, double pad)
{
  fcm_status st = FCM_OK;
  for (fcm_index t = 0; t < B->nt; t++) {
    const fcm_index *tv = B->tri + 3 * t;
    for (int i = 0; i < 3; i++) {
      double lo = HUGE_VAL, hi = -HUGE_VAL;
      for (int k = 0; k < 3; k++) {
        const double a = y[3 * tv[k] + i], b = dy ? a + 2.0 * dy[3 * tv[k] + i] : a;
        lo = FCM_MIN(lo, FCM_MIN(a, b));
        hi = FCM_MAX(hi, FCM_MAX(a, b));
      }
      B->boxes[6 * t + i] = lo;
      B->boxes[6 * t + 3 + i] = hi;
    }
  }
  B->builds++;
  if (rebuild || !B->built) {
    B->built = 1;
    FCM_TRY(ctx, fcm__sim_bvh_build(ctx, &B->bvh, B->nt, B->tbody, B->num_bodies, B->boxes));
  } else {
    fcm__sim_bvh_refit(&B->bvh, B->boxes);
  }
  near_bodies(B, pad);
cleanup:
  return st;
}

/* Sample n's position (and motion, when dy is given) from the node arrays. */
void fcm__sim_bodies_sample(const sim_bodies *B, fcm_index n, const double *y, double p[3])
{
  const fcm_index *tv = B->tri + 3 * B->stri[n];
  const double *l = B->slam + 3 * n;
  for (int i = 0; i < 3; i++)
    p[i] = l[0] * y[3 * tv[0] + i] + l[1] * y[3 * tv[1] + i] + l[2] * y[3 * tv[2] + i];
}

static int is_blind(const sim_bodies *B, fcm_index n, fcm_index body)
{
  const fcm_index *bl = B->blind + (size_t)n * SIM_BLIND;
  for (int k = 0; k < SIM_BLIND; k++)
    if (bl[k] == body) return 1;
  return 0;
}

int fcm__sim_bodies_excluded(sim_bodies *B, fcm_index n, fcm_index t)
{
  double X[3], g[3], beta[3];
  B->self_tests++;
  if (t == B->stri[n]) return 1;
  fcm__sim_bodies_sample(B, n, B->vX, X);
  return fcm__sim_bodies_distance(B, X, t, B->vX, g, beta) < B->rho;
}

/* Whether triangle t is a target of sample n: with area; of another body not ignored, or of its
 * own body with self-contact and beyond the reference exclusion. */
int fcm__sim_bodies_target(sim_bodies *B, fcm_index n, fcm_index t)
{
  const fcm_index bt = B->tbody[t], own = B->tbody[B->stri[n]];
  if (bt < 0) return 0;
  if (bt == own) return B->self && !fcm__sim_bodies_excluded(B, n, t);
  return !is_blind(B, n, bt);
}

/* The triangles of the bodies sample n sees (not its own, not ignored; all bodies but its own
 * when all is set) whose boxes meet [lo, hi], into B->buf. */
fcm_status fcm__sim_bodies_candidates(fcm_ctx *ctx, sim_bodies *B, fcm_index n, const double lo[3],
                                      const double hi[3], int all)
{
  fcm_status st = FCM_OK;
  const fcm_index own = B->tbody[B->stri[n]];
  B->buf.n = 0;
  for (fcm_index k = B->near_ptr[own]; k < B->near_ptr[own + 1]; k++) {
    const fcm_index g = B->near[k], r = B->bvh.root[g];
    const sim_bvh_node *nd = B->bvh.node + r; /* the body's box first: most miss it */
    if (nd->lo[0] > hi[0] || lo[0] > nd->hi[0] || nd->lo[1] > hi[1] || lo[1] > nd->hi[1] ||
        nd->lo[2] > hi[2] || lo[2] > nd->hi[2])
      continue;
    if (!all && is_blind(B, n, g)) continue;
    FCM_TRY(ctx, fcm__sim_bvh_query(ctx, &B->bvh, g, B->boxes, lo, hi, &B->buf));
  }
  if (B->self) FCM_TRY(ctx, fcm__sim_bvh_query(ctx, &B->bvh, own, B->boxes, lo, hi, &B->buf));
cleanup:
  return st;
}

/* Sample n's point p in the positions B->y and the candidates within r of it (as
 * fcm__sim_bodies_candidates() on the box of half-width r about p). */
fcm_status fcm__sim_bodies_near(fcm_ctx *ctx, sim_bodies *B, fcm_index n, double r, int all,
                                double p[3])
{
  double lo[3], hi[3];
  fcm__sim_bodies_sample(B, n, B->y, p);
  for (int i = 0; i < 3; i++) {
    lo[i] = p[i] - r;
    hi[i] = p[i] + r;
  }
  return fcm__sim_bodies_candidates(ctx, B, n, lo, hi, all);
}

/* The distance of p to triangle t at the node positions y, the unit gradient g and the
 * closest point's barycentric coordinates beta. */
double fcm__sim_bodies_distance(const sim_bodies *B, const double p[3], fcm_index t,
                                const double *y, double g[3], double beta[3])
{
  const fcm_index *tv = B->tri + 3 * t;
  const double *a = y + 3 * tv[0], *b = y + 3 * tv[1], *c = y + 3 * tv[2];
  double q[3], e[3], v0[3], v1[3], v2[3];
  fcm__sim_point_triangle(p, a, b, c, q, e);
  fcm__vec3_sub(b, a, v0);
  fcm__vec3_sub(c, a, v1);
  fcm__vec3_sub(q, a, v2);
  const double d00 = fcm__vec3_dot(v0, v0), d01 = fcm__vec3_dot(v0, v1),
               d11 = fcm__vec3_dot(v1, v1), d20 = fcm__vec3_dot(v2, v0),
               d21 = fcm__vec3_dot(v2, v1), den = d00 * d11 - d01 * d01;
  beta[1] = den > 0.0 ? (d11 * d20 - d01 * d21) / den : 0.0;
  beta[2] = den > 0.0 ? (d00 * d21 - d01 * d20) / den : 0.0;
  beta[0] = 1.0 - beta[1] - beta[2];
  fcm__vec3_sub(p, q, g);
  const double d = fcm__vec3_norm(g);
  for (int i = 0; i < 3; i++)
    g[i] = d > 0.0 ? g[i] / d : 0.0;
  return d;
}

/* For each body sample n ignores: its closest triangle among the candidates in B->buf, the
 * closest point's barycentric coordinates and the triangle's unit outward normal (lag_t, lag;
 * -1 when none is within reach). */
static void lag_blind(sim_bodies *B, fcm_index n, const double p[3])
{
  const fcm_index *bl = B->blind + (size_t)n * SIM_BLIND;
  for (int k = 0; k < SIM_BLIND; k++) {
    fcm_index *lt = B->lag_t + (size_t)n * SIM_BLIND + k;
    double *L = B->lag + 6 * ((size_t)n * SIM_BLIND + k), best = HUGE_VAL;
    *lt = -1;
    if (bl[k] < 0) continue;
    for (size_t j = 0; j < B->buf.n; j++) {
      const fcm_index t = B->buf.ids[j];
      double g[3], beta[3];
      if (B->tbody[t] != bl[k]) continue;
      const double d = fcm__sim_bodies_distance(B, p, t, B->y, g, beta);
      if (d >= best) continue;
      best = d;
      *lt = t;
      memcpy(L, beta, sizeof beta);
    }
    if (*lt < 0) continue;
    const fcm_index *tv = B->tri + 3 * *lt;
    double e1[3], e2[3];
    fcm__vec3_sub(B->y + 3 * tv[1], B->y + 3 * tv[0], e1);
    fcm__vec3_sub(B->y + 3 * tv[2], B->y + 3 * tv[0], e2);
    fcm__vec3_cross(e1, e2, L + 3);
    const double l = fcm__vec3_norm(L + 3);
    for (int i = 0; i < 3; i++)
      L[3 + i] = l > 0.0 ? L[3 + i] / l : 0.0;
  }
}

double fcm__sim_bodies_blind_start(const fcm_integrator *I, const sim_contact *c)
{
  return I->opts.kind == FCM_INTEGRATOR_STATIC ? 1e-9 * c->dhat : c->dhat;
}

fcm_status fcm__sim_bodies_prepare(fcm_integrator *I, sim_contact *c, const double *x)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_bodies *B = c->bodies;
  unsigned char *near = NULL;
  /* the pieces a sample ignores from the first substep: those within d^ of it; a static solve,
   * which has no inertia to land a piece from afar, ignores only those within 1e-9 d^ (the
   * sides of a cut) and lets the barrier hold the others at once */
  const double first = fcm__sim_bodies_blind_start(I, c);
  if (!B) return FCM_OK;
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  FCM_TRY(ctx, fcm__sim_bodies_boxes(ctx, B, B->y, NULL, 1, c->dhat));
  FCM_ALLOC(ctx, (size_t)B->num_bodies + 1, near);
  for (fcm_index n = 0; n < B->ns; n++) {
    fcm_index *bl = B->blind + (size_t)n * SIM_BLIND;
    const fcm_index own = B->tbody[B->stri[n]];
    double p[3], g[3], beta[3];
    if (B->prepared) {
      int any = 0;
      for (int k = 0; k < SIM_BLIND; k++)
        any |= bl[k] >= 0;
      if (!any) continue;
    }
    FCM_TRY(ctx, fcm__sim_bodies_near(ctx, B, n, c->dhat, 1, p));
    for (size_t k = 0; k < B->buf.n; k++) {
      const fcm_index t = B->buf.ids[k], bt = B->tbody[t];
      if (bt < 0 || bt == own || near[bt]) continue;
      if (fcm__sim_bodies_distance(B, p, t, B->y, g, beta) < (B->prepared ? c->dhat : first))
        near[bt] = 1;
    }
    if (!B->prepared) { /* the bodies it starts near */
      int m = 0;
      for (size_t k = 0; k < B->buf.n; k++) {
        const fcm_index bt = B->tbody[B->buf.ids[k]];
        if (bt >= 0 && near[bt] && m < SIM_BLIND && !is_blind(B, n, bt)) bl[m++] = bt;
      }
    } else { /* the bodies it left */
      for (int k = 0; k < SIM_BLIND; k++)
        if (bl[k] >= 0 && !near[bl[k]]) bl[k] = -1;
    }
    lag_blind(B, n, p);
    for (size_t k = 0; k < B->buf.n; k++)
      if (B->tbody[B->buf.ids[k]] >= 0) near[B->tbody[B->buf.ids[k]]] = 0;
  }
  B->prepared = 1;
cleanup:
  fcm__free(ctx, near);
  return st;
}

/* Pair (sample n, triangle t) at distance d with gradient g, closest barycentrics beta: the
 * force c1 G and the Newton matrix bound of c2 G G^T added. */
static void pair_terms(const fcm_integrator *I, sim_bodies *B, fcm_index n, fcm_index t,
                       const double g[3], const double beta[3], double c1, double c2, double *force,
                       double *vals)
{
  const fcm_space *s = I->space;
  const int nn = s->nn, nd = 3 * nn;
  fcm_index node[6], elem[6];
  double coef[6];
  int ne = 0;
  for (int k = 0; k < 3; k++) {
    node[k] = B->tri[3 * B->stri[n] + k];
    coef[k] = B->slam[3 * n + k];
    node[3 + k] = B->tri[3 * t + k];
    coef[3 + k] = -beta[k];
  }
  for (int m = 0; m < 6; m++) {
    if (coef[m] == 0.0) continue;
    const fcm_index e = B->velem[node[m]];
    const fcm_index *ed = s->elem_dof + e * nn;
    const double *N = B->vN + (size_t)node[m] * nn;
    int seen = 0;
    for (int k = 0; k < ne; k++)
      seen |= elem[k] == e;
    if (!seen) elem[ne++] = e;
    if (force)
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          force[ed[a] + i] += c1 * coef[m] * N[a] * g[i];
  }
  if (!vals) return;
  for (int k = 0; k < ne; k++) {
    double G[3 * FCM_ELEMENT_MAX_NODES];
    memset(G, 0, sizeof(double) * (size_t)nd);
    for (int m = 0; m < 6; m++) {
      if (coef[m] == 0.0 || B->velem[node[m]] != elem[k]) continue;
      const double *N = B->vN + (size_t)node[m] * nn;
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          G[3 * a + i] += coef[m] * N[a] * g[i];
    }
    const double f = ne * c2;
    for (int r = 0; r < nd; r++)
      for (int q = 0; q < nd; q++)
        B->Ke[(size_t)r * nd + q] = f * G[r] * G[q];
    fcm__sim_scatter(s, fcm__space_elem_local(s, elem[k]), B->Ke, vals);
  }
}

/* The barrier b(d) for threshold dh and its derivatives (contact.c's). */
static double barrier(double d, double dh, double *b1, double *b2)
{
  if (d >= dh) {
    *b1 = *b2 = 0.0;
    return 0.0;
  }
  const double r = d - dh, l = log(d / dh);
  *b1 = -2.0 * r * l - r * r / d;
  *b2 = -2.0 * l - 4.0 * r / d + r * r / (d * d);
  return -r * r * l;
}

static fcm_status record(fcm_ctx *ctx, sim_bodies *B, fcm_index n, fcm_index t, const double g[3],
                         const double beta[3], double c2)
{
  fcm_status st = FCM_OK;
  if (B->npairs == B->cap_pairs) {
    const size_t cap = B->cap_pairs ? 2 * B->cap_pairs : 256;
    void *grown = B->pairs;
    FCM_TRY(ctx, fcm__resize(ctx, &grown, B->cap_pairs, cap, sizeof *B->pairs));
    B->pairs = grown;
    B->cap_pairs = cap;
  }
  sim_pair *q = B->pairs + B->npairs++;
  q->n = n;
  q->t = t;
  memcpy(q->g, g, sizeof q->g);
  memcpy(q->beta, beta, sizeof q->beta);
  q->c2 = c2;
cleanup:
  return st;
}

/* The penalty that keeps sample n at p out of the bodies it ignores: with the triangle, the
 * closest point's beta and the outward normal nv lagged at the substep's start, the signed gap
 * s = nv . (p - sum_k beta_k z_k) is linear in the DOFs, and s < 0 adds w kappa s^2 / 2 (its
 * force exact, its Newton matrix w kappa G G^T, G = ds/du, through the pairs' path). */
static fcm_status lagged_terms(const fcm_integrator *I, const sim_contact *c, fcm_index n,
                               const double p[3], double *etot, double *force, double *vals)
{
  fcm_status st = FCM_OK;
  sim_bodies *B = c->bodies;
  for (int k = 0; k < SIM_BLIND; k++) {
    const fcm_index t = B->lag_t[(size_t)n * SIM_BLIND + k];
    if (B->blind[(size_t)n * SIM_BLIND + k] < 0 || t < 0) continue;
    const double *L = B->lag + 6 * ((size_t)n * SIM_BLIND + k);
    const fcm_index *tv = B->tri + 3 * t;
    double s = 0.0;
    for (int i = 0; i < 3; i++)
      s += L[3 + i] * (p[i] - L[0] * B->y[3 * tv[0] + i] - L[1] * B->y[3 * tv[1] + i] -
                       L[2] * B->y[3 * tv[2] + i]);
    if (!(s < 0.0)) continue;
    const double wk = B->sw[n] * c->kappa;
    *etot += 0.5 * wk * s * s;
    pair_terms(I, B, n, t, L + 3, L, wk * s, wk, force, vals);
    if (vals) FCM_TRY(I->ctx, record(I->ctx, B, n, t, L + 3, L, wk));
  }
cleanup:
  return st;
}

/* The eigenpairs of the symmetric 2 x 2 matrix [a b; b d]: values sig, unit vectors e (2 x 2,
 * column-major). */
static void eig2(double a, double b, double d, double sig[2], double e[4])
{
  const double m = 0.5 * (a + d), r = sqrt(0.25 * (a - d) * (a - d) + b * b);
  sig[0] = m + r;
  sig[1] = m - r;
  if (!(fabs(b) > 1e-14 * (fabs(a) + fabs(d)))) {
    const int k = a >= d ? 0 : 1;
    sig[0] = k ? d : a, sig[1] = k ? a : d;
    e[0] = k ? 0.0 : 1.0, e[1] = k ? 1.0 : 0.0;
  } else {
    const double l = sqrt(b * b + (sig[0] - a) * (sig[0] - a));
    e[0] = b / l, e[1] = (sig[0] - a) / l;
  }
  e[2] = -e[1], e[3] = e[0];
}

/* The lagged friction of the pairs at the node positions B->y (fcm__sim_bodies_slip()): the
 * potential mu lambda f0(|T^T delta|), its force exact, its Hessian A = T Hs T^T (positive
 * semidefinite, in the tangent plane) through the pairs' path as its two eigenpairs
 * sigma v v^T, v = T e, like a barrier pair's c2 g g^T. */
static fcm_status friction_terms(const fcm_integrator *I, const sim_contact *c, double *etot,
                                 double *force, double *vals)
{
  fcm_status st = FCM_OK;
  sim_bodies *B = c->bodies;
  const double eps = c->opts.friction_velocity * I->cp.hstep;
  if (!(c->opts.friction > 0.0) || !(eps > 0.0)) return FCM_OK;
  for (size_t k = 0; k < B->nfp; k++) {
    const sim_fpair *q = B->fp + k;
    double delta[3], G[3], A[9], Hs[4], sig[2], e[4];
    fcm__sim_bodies_slip(B, q, delta);
    *etot += fcm__sim_friction_potential(c->opts.friction * q->lambda, eps, q->T, delta, G, A);
    const double gn = fcm__vec3_norm(G);
    if (force && gn > 0.0) {
      const double gu[3] = {G[0] / gn, G[1] / gn, G[2] / gn};
      pair_terms(I, B, q->n, q->t, gu, q->beta, gn, 0.0, force, NULL);
    }
    if (!vals) continue;
    for (int a = 0; a < 2; a++) /* Hs = T^T A T */
      for (int b = 0; b < 2; b++) {
        double v = 0.0;
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < 3; j++)
            v += q->T[3 * a + i] * A[3 * i + j] * q->T[3 * b + j];
        Hs[2 * a + b] = v;
      }
    eig2(Hs[0], 0.5 * (Hs[1] + Hs[2]), Hs[3], sig, e);
    for (int m = 0; m < 2; m++) {
      double v[3];
      if (!(sig[m] > 0.0)) continue;
      for (int i = 0; i < 3; i++)
        v[i] = q->T[i] * e[2 * m] + q->T[3 + i] * e[2 * m + 1];
      pair_terms(I, B, q->n, q->t, v, q->beta, 0.0, sig[m], NULL, vals);
      FCM_TRY(I->ctx, record(I->ctx, B, q->n, q->t, v, q->beta, sig[m]));
    }
  }
cleanup:
  return st;
}

void fcm__sim_bodies_assemble(fcm_integrator *I, sim_contact *c, const double *x, double *energy,
                              double *force, fcm_csr *T, int *finite)
{
  sim_bodies *B = c->bodies;
  double *vals = T ? fcm_csr_values(T) : NULL, etot = 0.0;
  if (!B) return;
  if (!B->prepared && fcm__sim_bodies_prepare(I, c, x) != FCM_OK) {
    *finite = 0;
    return;
  }
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  if (fcm__sim_bodies_boxes(I->ctx, B, B->y, NULL, 0, c->dhat) != FCM_OK) {
    *finite = 0;
    return;
  }
  if (vals) B->npairs = 0;
  for (fcm_index n = 0; n < B->ns; n++) {
    double p[3];
    if (fcm__sim_bodies_near(I->ctx, B, n, c->dhat, 0, p) != FCM_OK) {
      *finite = 0;
      return;
    }
    for (size_t k = 0; k < B->buf.n; k++) {
      const fcm_index t = B->buf.ids[k];
      double g[3], beta[3], b1, b2;
      if (!fcm__sim_bodies_target(B, n, t)) continue;
      const double d = fcm__sim_bodies_distance(B, p, t, B->y, g, beta);
      if (!(d > 0.0)) {
        *finite = 0;
        return;
      }
      if (d >= c->dhat) continue;
      const double wk = B->sw[n] * c->kappa;
      etot += wk * barrier(d, c->dhat, &b1, &b2);
      pair_terms(I, B, n, t, g, beta, wk * b1, wk * b2, force, vals);
      if (vals && record(I->ctx, B, n, t, g, beta, wk * b2) != FCM_OK) {
        *finite = 0;
        return;
      }
    }
    if (lagged_terms(I, c, n, p, &etot, force, vals) != FCM_OK) {
      *finite = 0;
      return;
    }
  }
  if (friction_terms(I, c, &etot, force, vals) != FCM_OK) *finite = 0;
  if (!isfinite(etot)) *finite = 0;
  if (energy) *energy += etot;
  /* pieces in contact: a factorization kept from another iterate lacks their coupling (and
   * its refinement the pairs), so Newton factors anew */
  if (etot > 0.0) I->kept = 0;
}

double fcm__sim_bodies_step_bound(fcm_integrator *I, sim_contact *c, const double *x,
                                  const double *dx)
{
  sim_bodies *B = c->bodies;
  double amax = DBL_MAX, M = 0.0;
  if (!B) return amax;
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  fcm__sim_bodies_positions(I->space, B, dx, 1, B->dy);
  for (fcm_index v = 0; v < B->nv; v++)
    M = FCM_MAX(M, fcm__vec3_norm(B->dy + 3 * v));
  if (M == 0.0) return amax;
  if (fcm__sim_bodies_boxes(I->ctx, B, B->y, B->dy, 0, 0.0) != FCM_OK) return 0.0;
  for (fcm_index n = 0; n < B->ns; n++) {
    double p[3], dp[3], lo[3], hi[3];
    fcm__sim_bodies_sample(B, n, B->y, p);
    fcm__sim_bodies_sample(B, n, B->dy, dp);
    const double mp = fcm__vec3_norm(dp);
    /* fractions beyond 2 never limit a step (the filter takes 0.9 of at most 1): the swept
     * boxes over [0, 2] of the sample and the triangles */
    for (int i = 0; i < 3; i++) {
      lo[i] = FCM_MIN(p[i], p[i] + 2.0 * dp[i]);
      hi[i] = FCM_MAX(p[i], p[i] + 2.0 * dp[i]);
    }
    if (fcm__sim_bodies_candidates(I->ctx, B, n, lo, hi, 0) != FCM_OK) return 0.0;
    for (size_t k = 0; k < B->buf.n; k++) {
      const fcm_index t = B->buf.ids[k], *tv = B->tri + 3 * t;
      double g[3], beta[3], mt = 0.0, rel = 0.0, dr[3];
      if (!fcm__sim_bodies_target(B, n, t)) continue;
      const double d = fcm__sim_bodies_distance(B, p, t, B->y, g, beta);
      if (!(d > 0.0)) return 0.0;
      if (B->tbody[t] == B->tbody[B->stri[n]]) {
        /* one body: in the sample's frame the triangle's points move by at most its nodes'
         * largest motion relative to the sample, so a rigid motion never limits the step */
        for (int j = 0; j < 3; j++) {
          fcm__vec3_sub(B->dy + 3 * tv[j], dp, dr);
          rel = FCM_MAX(rel, fcm__vec3_norm(dr));
        }
        if (rel > 0.0) amax = FCM_MIN(amax, d / rel);
        continue;
      }
      for (int j = 0; j < 3; j++)
        mt = FCM_MAX(mt, fcm__vec3_norm(B->dy + 3 * tv[j]));
      if (mp + mt > 0.0) amax = FCM_MIN(amax, d / (mp + mt));
    }
  }
  return amax;
}

fcm_status fcm__sim_bodies_stats(const fcm_integrator *I, const sim_contact *c, const double *x,
                                 long long *pairs, double *min_distance, double *energy)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_bodies *B = c->bodies;
  *pairs = 0;
  *min_distance = HUGE_VAL;
  *energy = 0.0;
  if (!B) return FCM_OK;
  fcm__sim_bodies_positions(I->space, B, x, 0, B->y);
  FCM_TRY(ctx, fcm__sim_bodies_boxes(ctx, B, B->y, NULL, 0, c->dhat));
  for (fcm_index n = 0; n < B->ns; n++) {
    double p[3];
    FCM_TRY(ctx, fcm__sim_bodies_near(ctx, B, n, c->dhat, 0, p));
    for (size_t k = 0; k < B->buf.n; k++) {
      const fcm_index t = B->buf.ids[k];
      double g[3], beta[3], b1, b2;
      if (!fcm__sim_bodies_target(B, n, t)) continue;
      const double d = fcm__sim_bodies_distance(B, p, t, B->y, g, beta);
      *min_distance = FCM_MIN(*min_distance, d);
      if (!(d > 0.0) || d >= c->dhat) continue;
      (*pairs)++;
      *energy += B->sw[n] * c->kappa * barrier(d, c->dhat, &b1, &b2);
    }
    FCM_TRY(ctx, lagged_terms(I, c, n, p, energy, NULL, NULL));
  }
cleanup:
  return st;
}

long long fcm__sim_bodies_builds(const sim_contact *c)
{
  return c->bodies ? c->bodies->builds : 0;
}

fcm_index fcm__sim_bodies_samples(const sim_contact *c, fcm_index *triangles)
{
  if (triangles) *triangles = c->bodies ? c->bodies->nt : 0;
  return c->bodies ? c->bodies->ns : 0;
}
