/* sim: contact with rigid half-space obstacles — the smooth log barrier of incremental
 * potential contact (Li et al. 2020) on the embedded surface's points.
 *
 * A point of area weight w at x = X + sum_a N_a u_a has the distance d = n . (x - p0 - v t) to
 * a plane; the energy gains w kappa b(d), b(d) = -(d - d^)^2 ln(d / d^) on (0, d^), 0 beyond.
 * b'(d) = -2 (d - d^) ln(d / d^) - (d - d^)^2 / d, b''(d) = -2 ln(d / d^) - 4 (d - d^) / d +
 * (d - d^)^2 / d^2 >= 0; the force on DOF (a, i) is w kappa b'(d) N_a n_i and the tangent
 * w kappa b''(d) N_a N_b n_i n_k. d is affine in u, so the largest step fraction that keeps a
 * point in front of a plane is exact: -d / (n . sum_a N_a du_a) where that slope is negative. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"

#include <float.h>
#include <math.h>
#include <string.h>

fcm_contact_options fcm_contact_options_default(void)
{
  fcm_contact_options o;
  memset(&o, 0, sizeof o);
  return o;
}

fcm_status fcm_integrator_add_contact_plane(fcm_integrator *I, const double point[3],
                                            const double normal[3], const double velocity[3],
                                            const fcm_contact_options *opts, int *id)
{
  fcm_status st = FCM_OK;
  sim_contact c;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  const int k = I->num_contacts;
  FCM_CHECK(!I->is_setup, ctx, FCM_ERR_ARG,
            "integrator: contact obstacles must be added before fcm_integrator_setup()");
  FCM_CHECK(point && normal, ctx, FCM_ERR_ARG, "contact plane %d: NULL point or normal", k);
  memset(&c, 0, sizeof c);
  c.opts = opts ? *opts : fcm_contact_options_default();
  {
    double nn = 0.0;
    int fin = 1;
    for (int i = 0; i < 3; i++) {
      fin &= isfinite(point[i]) && isfinite(normal[i]) && (!velocity || isfinite(velocity[i]));
      nn += normal[i] * normal[i];
    }
    FCM_CHECK(fin, ctx, FCM_ERR_ARG, "contact plane %d: point, normal or velocity not finite", k);
    nn = sqrt(nn);
    FCM_CHECK(nn > 0.0 && isfinite(nn), ctx, FCM_ERR_ARG,
              "contact plane %d: normal (%g, %g, %g) has no direction", k, normal[0], normal[1],
              normal[2]);
    for (int i = 0; i < 3; i++) {
      c.point[i] = point[i];
      c.normal[i] = normal[i] / nn;
      c.velocity[i] = velocity ? velocity[i] : 0.0;
    }
  }
  FCM_CHECK(c.opts.distance >= 0.0 && isfinite(c.opts.distance), ctx, FCM_ERR_ARG,
            "contact plane %d: distance = %g must be finite and >= 0 (0: the default)", k,
            c.opts.distance);
  FCM_CHECK(c.opts.stiffness >= 0.0 && isfinite(c.opts.stiffness), ctx, FCM_ERR_ARG,
            "contact plane %d: stiffness = %g must be finite and >= 0 (0: the default)", k,
            c.opts.stiffness);
  FCM_TRY(ctx, fcm__resize(ctx, (void **)&I->contacts, (size_t)I->num_contacts,
                           (size_t)I->num_contacts + 1, sizeof *I->contacts));
  I->contacts[I->num_contacts++] = c;
  /* the barrier's Hessian changes with u: no constant Newton matrix */
  I->linear = 0;
  if (id) *id = k;
cleanup:
  return st;
}

void fcm__sim_contact_free(fcm_integrator *I)
{
  fcm_ctx *ctx = I->ctx;
  sim_cpoints *cp = &I->cp;
  fcm__free(ctx, cp->elem);
  fcm__free(ctx, cp->ptr);
  fcm__free(ctx, cp->lelem);
  fcm__free(ctx, cp->w);
  fcm__free(ctx, cp->X);
  fcm__free(ctx, cp->N);
  fcm__free(ctx, cp->scratch);
  fcm__free(ctx, I->contacts);
  memset(cp, 0, sizeof *cp);
  I->contacts = NULL;
  I->num_contacts = 0;
}

/* The barrier b(d) for threshold dh and its derivatives (d > 0). */
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

/* Current position of point p from the element displacements ue. */
static void point_position(const sim_cpoints *cp, int nn, fcm_index p, const double *ue,
                           double x[3])
{
  const double *N = cp->N + (size_t)p * nn;
  for (int i = 0; i < 3; i++)
    x[i] = cp->X[3 * p + i];
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++)
      x[i] += N[a] * ue[3 * a + i];
}

static double plane_distance(const sim_contact *c, const double x[3], double t)
{
  double d = 0.0;
  for (int i = 0; i < 3; i++)
    d += c->normal[i] * (x[i] - c->point[i] - c->velocity[i] * t);
  return d;
}

static void gather(const fcm_space *s, fcm_index e, const double *x, double *ue)
{
  const fcm_index *ed = s->elem_dof + e * s->nn;
  for (int a = 0; a < s->nn; a++)
    memcpy(ue + 3 * a, x + ed[a], 3 * sizeof(double));
}

/* One pass over the elements' surface points: pass 0 counts, pass 1 stores (sized by pass
 * 0), and the largest extent of a cell with points into cp->h. */
static fcm_status collect(fcm_integrator *I, int pass, fcm_index *np_out, fcm_index *ne_out)
{
  fcm_status st = FCM_OK;
  const fcm_space *s = I->space;
  sim_cpoints *cp = &I->cp;
  const int nn = s->nn;
  fcm_index np = 0, ne = 0;
  for (fcm_index e = 0; e < s->num_elems; e++) {
    int nsp = 0;
    const double *pts = NULL, *wts = NULL, *nrm = NULL;
    double X[3 * FCM_ELEMENT_MAX_NODES], N[FCM_ELEMENT_MAX_NODES];
    FCM_TRY(I->ctx, fcm_cell_rules_get_piece_surface(s->rules, s->elem_piece[e], &nsp, &pts, &wts,
                                                     &nrm, NULL));
    if (nsp == 0) continue;
    fcm_mesh_cell_coords(s->mesh, s->elem_cell[e], X);
    const fcm_index first = np;
    for (int q = 0; q < nsp; q++) {
      if (!(wts[q] > 0.0)) continue;
      if (pass == 1) {
        double x[3] = {0, 0, 0};
        fcm_element_eval_shape(s->type, pts + 3 * q, N);
        for (int a = 0; a < nn; a++)
          for (int i = 0; i < 3; i++)
            x[i] += N[a] * X[3 * a + i];
        cp->w[np] = wts[q];
        memcpy(cp->X + 3 * np, x, sizeof x);
        memcpy(cp->N + (size_t)np * nn, N, sizeof(double) * (size_t)nn);
      }
      np++;
    }
    if (np == first) continue;
    if (pass == 1) {
      cp->elem[ne] = e;
      cp->ptr[ne] = first;
      cp->lelem[ne] = fcm__space_elem_local(s, e);
      for (int i = 0; i < 3; i++) {
        double lo = X[i], hi = X[i];
        for (int a = 1; a < nn; a++) {
          lo = FCM_MIN(lo, X[3 * a + i]);
          hi = FCM_MAX(hi, X[3 * a + i]);
        }
        cp->h = FCM_MAX(cp->h, hi - lo);
      }
    }
    ne++;
  }
cleanup:
  *np_out = np;
  *ne_out = ne;
  return st;
}

fcm_status fcm__sim_contact_check(const fcm_integrator *I, const double *x, double t)
{
  fcm_status st = FCM_OK;
  const sim_cpoints *cp = &I->cp;
  const int nn = I->space->nn;
  double ue[3 * FCM_ELEMENT_MAX_NODES];
  for (fcm_index k = 0; k < cp->nelem; k++) {
    gather(I->space, cp->elem[k], x, ue);
    for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
      double y[3];
      point_position(cp, nn, p, ue, y);
      for (int c = 0; c < I->num_contacts; c++) {
        const double d = plane_distance(&I->contacts[c], y, t);
        FCM_CHECK(d > 0.0, I->ctx, FCM_ERR_ARG,
                  "contact plane %d: the embedded-surface point at (%g, %g, %g) (cell %lld) "
                  "lies at distance %g <= 0 at t = %g: the body starts on or behind the plane",
                  c, y[0], y[1], y[2], (long long)I->space->elem_cell[cp->elem[k]], d, t);
      }
    }
  }
cleanup:
  return st;
}

fcm_status fcm__sim_contact_setup(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_space *s = I->space;
  sim_cpoints *cp = &I->cp;
  const int nn = s->nn, nd = 3 * nn;
  fcm_index np = 0, ne = 0;
  if (I->num_contacts == 0) return FCM_OK;
  FCM_CHECK(!fcm__integrator_distributed(I, NULL), ctx, FCM_ERR_UNSUPPORTED,
            "contact plane 0: contact is not supported with a distributed backend");
  FCM_CHECK(s->rules && fcm_cell_rules_surface_strength(s->rules) >= 0, ctx, FCM_ERR_ARG,
            "contact plane 0: the space has no surface rules (build the cell rules with "
            "surface_strength >= 0)");
  FCM_TRY(ctx, collect(I, 0, &np, &ne));
  FCM_CHECK(np > 0, ctx, FCM_ERR_ARG,
            "contact plane 0: the space has no embedded-surface point to act on");
  cp->np = np;
  cp->nelem = ne;
  FCM_ALLOC(ctx, ne, cp->elem);
  FCM_ALLOC(ctx, ne + 1, cp->ptr);
  FCM_ALLOC(ctx, ne, cp->lelem);
  FCM_ALLOC(ctx, np, cp->w);
  FCM_ALLOC(ctx, 3 * (size_t)np, cp->X);
  FCM_ALLOC(ctx, (size_t)np * nn, cp->N);
  FCM_ALLOC(ctx, (size_t)nd * (nd + 1), cp->scratch);
  FCM_TRY(ctx, collect(I, 1, &np, &ne));
  cp->ptr[ne] = np;
  for (int c = 0; c < I->num_contacts; c++) {
    sim_contact *ct = &I->contacts[c];
    ct->dhat = ct->opts.distance > 0.0 ? ct->opts.distance : 0.1 * cp->h;
    ct->kappa = ct->opts.stiffness > 0.0 ? ct->opts.stiffness : I->mat.young / cp->h;
    FCM_CHECK(ct->dhat > 0.0 && ct->kappa > 0.0 && isfinite(ct->kappa), ctx, FCM_ERR_ARG,
              "contact plane %d: threshold %g or stiffness %g not positive (set distance and "
              "stiffness, or give the material a Young modulus)",
              c, ct->dhat, ct->kappa);
  }
  FCM_TRY(ctx, fcm__sim_contact_check(I, I->u, I->t));
cleanup:
  return st;
}

void fcm__sim_contact_assemble(fcm_integrator *I, const double *x, double *energy, double *force,
                               fcm_csr *T, int *finite)
{
  const fcm_space *s = I->space;
  const sim_cpoints *cp = &I->cp;
  const int nn = s->nn, nd = 3 * nn;
  double *vals = T ? fcm_csr_values(T) : NULL, etot = 0.0;
  double ue[3 * FCM_ELEMENT_MAX_NODES], *fe = cp->scratch, *Ke = fe + nd;
  const double t = I->bc_time;
  for (fcm_index k = 0; k < cp->nelem; k++) {
    int any = 0;
    gather(s, cp->elem[k], x, ue);
    for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
      const double *N = cp->N + (size_t)p * nn, w = cp->w[p];
      double y[3];
      point_position(cp, nn, p, ue, y);
      for (int c = 0; c < I->num_contacts; c++) {
        const sim_contact *ct = &I->contacts[c];
        const double d = plane_distance(ct, y, t), *n = ct->normal;
        double b1, b2;
        if (!(d > 0.0)) {
          *finite = 0;
          return;
        }
        if (d >= ct->dhat) continue;
        if (!any) {
          memset(fe, 0, sizeof(double) * (size_t)nd);
          if (T) memset(Ke, 0, sizeof(double) * (size_t)nd * nd);
          any = 1;
        }
        etot += w * ct->kappa * barrier(d, ct->dhat, &b1, &b2);
        const double c1 = w * ct->kappa * b1, c2 = w * ct->kappa * b2;
        for (int a = 0; a < nn; a++)
          for (int i = 0; i < 3; i++)
            fe[3 * a + i] += c1 * N[a] * n[i];
        if (T)
          for (int a = 0; a < nn; a++)
            for (int i = 0; i < 3; i++) {
              double *row = Ke + (size_t)(3 * a + i) * nd;
              const double ca = c2 * N[a] * n[i];
              for (int b = 0; b < nn; b++)
                for (int m = 0; m < 3; m++)
                  row[3 * b + m] += ca * N[b] * n[m];
            }
      }
    }
    if (!any) continue;
    if (force) {
      const fcm_index *ed = s->elem_dof + cp->elem[k] * nn;
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          force[ed[a] + i] += fe[3 * a + i];
    }
    if (T) fcm__sim_scatter(s, cp->lelem[k], Ke, vals);
  }
  if (!isfinite(etot)) *finite = 0;
  if (energy) *energy += etot;
}

double fcm__sim_contact_step_bound(const fcm_integrator *I, const double *x, const double *dx)
{
  const fcm_space *s = I->space;
  const sim_cpoints *cp = &I->cp;
  const int nn = s->nn;
  double amax = DBL_MAX, ue[3 * FCM_ELEMENT_MAX_NODES], de[3 * FCM_ELEMENT_MAX_NODES];
  for (fcm_index k = 0; k < cp->nelem; k++) {
    gather(s, cp->elem[k], x, ue);
    gather(s, cp->elem[k], dx, de);
    for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
      const double *N = cp->N + (size_t)p * nn;
      double y[3], dy[3] = {0, 0, 0};
      point_position(cp, nn, p, ue, y);
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          dy[i] += N[a] * de[3 * a + i];
      for (int c = 0; c < I->num_contacts; c++) {
        const sim_contact *ct = &I->contacts[c];
        const double d = plane_distance(ct, y, I->bc_time);
        const double slope = ct->normal[0] * dy[0] + ct->normal[1] * dy[1] + ct->normal[2] * dy[2];
        if (!(d > 0.0)) return 0.0;
        if (slope < 0.0) amax = FCM_MIN(amax, -d / slope);
      }
    }
  }
  return amax;
}

void fcm__sim_contact_pull_back(fcm_integrator *I)
{
  for (fcm_index i = 0; i < I->n; i++)
    I->w1[i] = I->u[i] - I->un[i];
  const double amax = fcm__sim_contact_step_bound(I, I->un, I->w1);
  if (amax > 1.0) return;
  for (fcm_index i = 0; i < I->n; i++)
    I->u[i] = I->un[i] + 0.9 * amax * I->w1[i];
  I->contact_pullbacks++;
}

fcm_status fcm_integrator_contact_info(const fcm_integrator *I, int id, double force[3],
                                       double *min_distance, double *dhat, double *kappa)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(I->is_setup, I->ctx, FCM_ERR_ARG, "contact info: the integrator is not set up");
  FCM_CHECK(id >= 0 && id < I->num_contacts, I->ctx, FCM_ERR_ARG,
            "contact info: obstacle %d out of range [0, %d)", id, I->num_contacts);
  {
    const sim_cpoints *cp = &I->cp;
    const sim_contact *ct = &I->contacts[id];
    const int nn = I->space->nn;
    double F[3] = {0, 0, 0}, dmin = DBL_MAX, ue[3 * FCM_ELEMENT_MAX_NODES];
    for (fcm_index k = 0; k < cp->nelem; k++) {
      gather(I->space, cp->elem[k], I->u, ue);
      for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
        double y[3], b1, b2;
        point_position(cp, nn, p, ue, y);
        const double d = plane_distance(ct, y, I->t);
        dmin = FCM_MIN(dmin, d);
        if (!(d > 0.0) || d >= ct->dhat) continue;
        barrier(d, ct->dhat, &b1, &b2);
        for (int i = 0; i < 3; i++)
          F[i] -= cp->w[p] * ct->kappa * b1 * ct->normal[i];
      }
    }
    if (force) memcpy(force, F, sizeof F);
    if (min_distance) *min_distance = dmin;
    if (dhat) *dhat = ct->dhat;
    if (kappa) *kappa = ct->kappa;
  }
cleanup:
  return st;
}

fcm_status fcm_integrator_contact_eval(fcm_integrator *I, const double *u, double t, double *energy,
                                       double *force, fcm_csr *tangent)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  FCM_CHECK(I->is_setup && u, ctx, FCM_ERR_ARG,
            "contact eval: NULL displacement, or the integrator is not set up");
  FCM_TRY(ctx, fcm__sim_check_pattern(I, tangent, "contact eval"));
  FCM_TRY(ctx, fcm__sim_contact_check(I, u, t));
  {
    const double t_saved = I->bc_time;
    int finite = 1;
    double e = 0.0;
    I->bc_time = t;
    fcm__sim_contact_assemble(I, u, &e, force, tangent, &finite);
    I->bc_time = t_saved;
    if (energy) *energy = e;
  }
cleanup:
  return st;
}

fcm_status fcm_integrator_contact_counters(const fcm_integrator *I, long long *filtered,
                                           long long *pullbacks)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  if (filtered) *filtered = I->contact_filtered;
  if (pullbacks) *pullbacks = I->contact_pullbacks;
cleanup:
  return st;
}
