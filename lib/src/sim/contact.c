/* sim: contact with rigid obstacles (planes, spheres, boxes, closed triangle surfaces) — the
 * smooth log barrier of incremental potential contact (Li et al. 2020) on the embedded
 * surface's points.
 *
 * A point of area weight w at x = X + sum_a N_a u_a has the distance d(x) to an obstacle
 * (contact_obstacle.c: gradient g, Hessian H); the energy gains w kappa b(d),
 * b(d) = -(d - d^)^2 ln(d / d^) on (0, d^), 0 beyond. b'(d) = -2 (d - d^) ln(d / d^) -
 * (d - d^)^2 / d <= 0, b''(d) = -2 ln(d / d^) - 4 (d - d^) / d + (d - d^)^2 / d^2 >= 0; the
 * force on DOF (a, i) is w kappa b'(d) N_a g_i. The step filter is the first parameter where a
 * point's straight path x + s dx meets the obstacle (exact: the obstacles do not move within a
 * Newton iteration, evaluated at the substep's end). */
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

static const char *kind_name(sim_contact_kind k)
{
  static const char *const names[] = {"plane", "sphere", "box", "surface", "bodies"};
  return names[k];
}

/* Validate the options and the motion, then append c (its surface arrays, when any, are
 * owned by the integrator from here on, also on failure). */
static fcm_status add_obstacle(fcm_integrator *I, sim_contact *c, const fcm_contact_options *opts,
                               const fcm_motion *motion, int *id)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const int k = I->num_contacts;
  const char *kn = kind_name(c->kind);
  c->opts = opts ? *opts : fcm_contact_options_default();
  FCM_CHECK(!I->is_setup, ctx, FCM_ERR_ARG,
            "integrator: contact obstacles must be added before fcm_integrator_setup()");
  FCM_CHECK(c->opts.distance >= 0.0 && isfinite(c->opts.distance), ctx, FCM_ERR_ARG,
            "contact %s %d: distance = %g must be finite and >= 0 (0: the default)", kn, k,
            c->opts.distance);
  FCM_CHECK(c->opts.stiffness >= 0.0 && isfinite(c->opts.stiffness), ctx, FCM_ERR_ARG,
            "contact %s %d: stiffness = %g must be finite and >= 0 (0: the default)", kn, k,
            c->opts.stiffness);
  FCM_CHECK(c->opts.friction >= 0.0 && isfinite(c->opts.friction), ctx, FCM_ERR_ARG,
            "contact %s %d: friction = %g must be finite and >= 0 (0: frictionless)", kn, k,
            c->opts.friction);
  FCM_CHECK(c->opts.friction_velocity >= 0.0 && isfinite(c->opts.friction_velocity), ctx,
            FCM_ERR_ARG,
            "contact %s %d: friction_velocity = %g must be finite and >= 0 (0: the default)", kn, k,
            c->opts.friction_velocity);
  FCM_CHECK(c->opts.friction_updates >= 0 && c->opts.friction_updates <= 20, ctx, FCM_ERR_ARG,
            "contact %s %d: friction_updates = %d must be in [0, 20]", kn, k,
            c->opts.friction_updates);
  FCM_CHECK(c->opts.self_contact == 0 ||
                (c->opts.self_contact == 1 && c->kind == SIM_CONTACT_BODIES),
            ctx, FCM_ERR_ARG,
            "contact %s %d: self_contact = %d must be 0 or 1, and 1 only for contact between "
            "bodies",
            kn, k, c->opts.self_contact);
  if (c->opts.friction_velocity == 0.0) c->opts.friction_velocity = 1e-3;
  c->motion = fcm_motion_default();
  if (motion) {
    const fcm_motion *m = motion;
    int fin = isfinite(m->angular_speed) && !isnan(m->start) && !isnan(m->end);
    for (int i = 0; i < 3; i++)
      fin &= isfinite(m->velocity[i]) && isfinite(m->center[i]) && isfinite(m->axis[i]);
    FCM_CHECK(fin, ctx, FCM_ERR_ARG,
              "contact %s %d: motion: velocity, centre, axis, angular speed or window not "
              "finite",
              kn, k);
    FCM_CHECK(m->end >= m->start, ctx, FCM_ERR_ARG,
              "contact %s %d: motion: end = %g before start = %g", kn, k, m->end, m->start);
    FCM_CHECK(m->angular_speed == 0.0 || m->axis[0] != 0.0 || m->axis[1] != 0.0 ||
                  m->axis[2] != 0.0,
              ctx, FCM_ERR_ARG, "contact %s %d: motion: a rotation about a zero axis", kn, k);
    c->motion = *m;
    c->motion.release = 0;
    c->motion.components[0] = c->motion.components[1] = c->motion.components[2] = 1;
    c->moving = m->angular_speed != 0.0 || m->velocity[0] != 0.0 || m->velocity[1] != 0.0 ||
                m->velocity[2] != 0.0;
  }
  if (c->kind == SIM_CONTACT_SURFACE) FCM_TRY(ctx, fcm__sim_contact_surface_setup(ctx, k, c));
  FCM_TRY(ctx, fcm__resize(ctx, (void **)&I->contacts, (size_t)I->num_contacts,
                           (size_t)I->num_contacts + 1, sizeof *I->contacts));
  I->contacts[I->num_contacts++] = *c;
  memset(c, 0, sizeof *c);
  /* the barrier's Hessian changes with u: no constant Newton matrix */
  I->linear = 0;
  if (id) *id = k;
cleanup:
  if (st != FCM_OK) {
    fcm_aabb_tree_destroy(&c->tree);
    fcm__free(ctx, c->xyz);
    fcm__free(ctx, c->tri);
  }
  return st;
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
  FCM_CHECK(point && normal, ctx, FCM_ERR_ARG, "contact plane %d: NULL point or normal", k);
  memset(&c, 0, sizeof c);
  c.kind = SIM_CONTACT_PLANE;
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
  FCM_TRY(ctx, add_obstacle(I, &c, opts, NULL, id));
cleanup:
  return st;
}

fcm_status fcm_integrator_add_contact_sphere(fcm_integrator *I, const double center[3],
                                             double radius, const fcm_motion *motion,
                                             const fcm_contact_options *opts, int *id)
{
  fcm_status st = FCM_OK;
  sim_contact c;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  const int k = I->num_contacts;
  FCM_CHECK(center, ctx, FCM_ERR_ARG, "contact sphere %d: NULL centre", k);
  FCM_CHECK(isfinite(center[0]) && isfinite(center[1]) && isfinite(center[2]), ctx, FCM_ERR_ARG,
            "contact sphere %d: centre (%g, %g, %g) not finite", k, center[0], center[1],
            center[2]);
  FCM_CHECK(radius > 0.0 && isfinite(radius), ctx, FCM_ERR_ARG,
            "contact sphere %d: radius = %g must be finite and > 0", k, radius);
  memset(&c, 0, sizeof c);
  c.kind = SIM_CONTACT_SPHERE;
  memcpy(c.center, center, sizeof c.center);
  c.radius = radius;
  FCM_TRY(ctx, add_obstacle(I, &c, opts, motion, id));
cleanup:
  return st;
}

fcm_status fcm_integrator_add_contact_box(fcm_integrator *I, const double lo[3], const double hi[3],
                                          const fcm_motion *motion, const fcm_contact_options *opts,
                                          int *id)
{
  fcm_status st = FCM_OK;
  sim_contact c;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  const int k = I->num_contacts;
  FCM_CHECK(lo && hi, ctx, FCM_ERR_ARG, "contact box %d: NULL min or max corner", k);
  for (int i = 0; i < 3; i++)
    FCM_CHECK(isfinite(lo[i]) && isfinite(hi[i]) && lo[i] < hi[i], ctx, FCM_ERR_ARG,
              "contact box %d: min[%d] = %g must be finite and below max[%d] = %g", k, i, lo[i], i,
              hi[i]);
  memset(&c, 0, sizeof c);
  c.kind = SIM_CONTACT_BOX;
  memcpy(c.lo, lo, sizeof c.lo);
  memcpy(c.hi, hi, sizeof c.hi);
  FCM_TRY(ctx, add_obstacle(I, &c, opts, motion, id));
cleanup:
  return st;
}

fcm_status fcm_integrator_add_contact_surface(fcm_integrator *I, fcm_index num_vertices,
                                              const double *coords, fcm_index num_triangles,
                                              const fcm_index *tris, const fcm_motion *motion,
                                              const fcm_contact_options *opts, int *id)
{
  fcm_status st = FCM_OK;
  sim_contact c;
  fcm_ctx *ctx = I ? I->ctx : NULL;
  memset(&c, 0, sizeof c);
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  const int k = I->num_contacts;
  FCM_CHECK(coords && tris && num_vertices >= 4 && num_triangles >= 4, ctx, FCM_ERR_ARG,
            "contact surface %d: %lld vertices and %lld triangles (NULL arrays, or fewer than a "
            "tetrahedron's 4 and 4)",
            k, (long long)num_vertices, (long long)num_triangles);
  c.kind = SIM_CONTACT_SURFACE;
  c.nv = num_vertices;
  c.nt = num_triangles;
  FCM_ALLOC(ctx, 3 * (size_t)num_vertices, c.xyz);
  FCM_ALLOC(ctx, 3 * (size_t)num_triangles, c.tri);
  memcpy(c.xyz, coords, 3 * sizeof(double) * (size_t)num_vertices);
  memcpy(c.tri, tris, 3 * sizeof(fcm_index) * (size_t)num_triangles);
  /* add_obstacle owns the arrays from here on */
  return add_obstacle(I, &c, opts, motion, id);
cleanup:
  fcm__free(ctx, c.xyz);
  fcm__free(ctx, c.tri);
  return st;
}

fcm_status fcm_integrator_add_contact_bodies(fcm_integrator *I, const fcm_geometry *geom,
                                             const fcm_contact_options *opts, int *id)
{
  fcm_status st = FCM_OK;
  sim_contact c;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  const int k = I->num_contacts;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "contact bodies %d: NULL geometry", k);
  for (int j = 0; j < I->num_contacts; j++)
    FCM_CHECK(I->contacts[j].kind != SIM_CONTACT_BODIES, ctx, FCM_ERR_ARG,
              "contact bodies %d: contact between bodies is already on (contact %d)", k, j);
  memset(&c, 0, sizeof c);
  c.kind = SIM_CONTACT_BODIES;
  c.geom = geom;
  FCM_TRY(ctx, add_obstacle(I, &c, opts, NULL, id));
cleanup:
  return st;
}

fcm_status fcm__sim_contact_copy(fcm_integrator *I, const sim_contact *c)
{
  switch (c->kind) {
  case SIM_CONTACT_BODIES:
    return fcm_integrator_add_contact_bodies(I, c->geom, &c->opts, NULL);
  case SIM_CONTACT_PLANE:
    return fcm_integrator_add_contact_plane(I, c->point, c->normal, c->velocity, &c->opts, NULL);
  case SIM_CONTACT_SPHERE:
    return fcm_integrator_add_contact_sphere(I, c->center, c->radius, &c->motion, &c->opts, NULL);
  case SIM_CONTACT_BOX:
    return fcm_integrator_add_contact_box(I, c->lo, c->hi, &c->motion, &c->opts, NULL);
  default:
    return fcm_integrator_add_contact_surface(I, c->nv, c->xyz, c->nt, c->tri, &c->motion, &c->opts,
                                              NULL);
  }
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
  fcm__free(ctx, cp->pose);
  fcm__free(ctx, cp->pose0);
  fcm__free(ctx, cp->lag);
  fcm__geom_idbuf_free(ctx, &cp->buf);
  for (int k = 0; k < I->num_contacts; k++) {
    sim_contact *c = &I->contacts[k];
    fcm__sim_bodies_free(ctx, c);
    fcm_aabb_tree_destroy(&c->tree);
    fcm__free(ctx, c->xyz);
    fcm__free(ctx, c->tri);
  }
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
    const fcm_index nextra = fcm__sim_bodies_element_nodes(I, e, NULL, NULL, NULL);
    if (nsp == 0 && nextra == 0) continue;
    fcm_mesh_cell_coords(s->mesh, s->elem_cell[e], X);
    const fcm_index first = np;
    /* contact between bodies: its surface's nodes in e too (the cut faces have no rule) */
    if (pass == 1)
      fcm__sim_bodies_element_nodes(I, e, cp->w + np, cp->X + 3 * np, cp->N + (size_t)np * nn);
    np += nextra;
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

/* Every obstacle's placement at time t into cp->pose. */
static void poses(fcm_integrator *I, double t)
{
  for (int c = 0; c < I->num_contacts; c++)
    fcm__sim_contact_pose(&I->contacts[c], t, &I->cp.pose[c]);
}

fcm_status fcm__sim_contact_check(fcm_integrator *I, const double *x, double t)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_cpoints *cp = &I->cp;
  const int nn = I->space->nn;
  double ue[3 * FCM_ELEMENT_MAX_NODES];
  poses(I, t);
  for (fcm_index k = 0; k < cp->nelem; k++) {
    gather(I->space, cp->elem[k], x, ue);
    for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
      double y[3], d, g[3];
      int inside = 0;
      point_position(cp, nn, p, ue, y);
      for (int c = 0; c < I->num_contacts; c++) {
        const sim_contact *ct = &I->contacts[c];
        if (ct->kind == SIM_CONTACT_BODIES) continue;
        FCM_TRY(ctx, fcm__sim_contact_inside(ctx, ct, &cp->pose[c], y, t, &cp->buf, &inside));
        if (!inside) continue;
        FCM_TRY(ctx, fcm__sim_contact_distance(ctx, ct, &cp->pose[c], y, t,
                                               fcm__sim_contact_reach(ct, &cp->pose[c], y),
                                               &cp->buf, &d, g, NULL));
        FCM_CHECK(0, ctx, FCM_ERR_ARG,
                  "contact %s %d: the body starts in penetration: the embedded-surface point "
                  "at (%g, %g, %g) (cell %lld) lies at distance %g <= 0 at t = %g (%g m %s the "
                  "obstacle)",
                  kind_name(ct->kind), c, y[0], y[1], y[2],
                  (long long)I->space->elem_cell[cp->elem[k]], -fabs(d), t, fabs(d),
                  ct->kind == SIM_CONTACT_PLANE ? "behind" : "inside");
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
  const char *kn = kind_name(I->contacts[0].kind);
  for (int c = 0; c < I->num_contacts; c++) /* the surface first: its nodes join the points */
    if (I->contacts[c].kind == SIM_CONTACT_BODIES)
      FCM_TRY(ctx, fcm__sim_bodies_setup(I, &I->contacts[c]));
  FCM_CHECK(!fcm__integrator_distributed(I, NULL), ctx, FCM_ERR_UNSUPPORTED,
            "contact %s 0: contact is not supported with a distributed backend", kn);
  FCM_CHECK(s->rules && fcm_cell_rules_surface_strength(s->rules) >= 0, ctx, FCM_ERR_ARG,
            "contact %s 0: the space has no surface rules (build the cell rules with "
            "surface_strength >= 0)",
            kn);
  FCM_TRY(ctx, collect(I, 0, &np, &ne));
  FCM_CHECK(np > 0, ctx, FCM_ERR_ARG,
            "contact %s 0: the space has no embedded-surface point to act on", kn);
  cp->np = np;
  cp->nelem = ne;
  FCM_ALLOC(ctx, ne, cp->elem);
  FCM_ALLOC(ctx, ne + 1, cp->ptr);
  FCM_ALLOC(ctx, ne, cp->lelem);
  FCM_ALLOC(ctx, np, cp->w);
  FCM_ALLOC(ctx, 3 * (size_t)np, cp->X);
  FCM_ALLOC(ctx, (size_t)np * nn, cp->N);
  FCM_ALLOC(ctx, (size_t)nd * (nd + 1), cp->scratch);
  FCM_ALLOC(ctx, I->num_contacts, cp->pose);
  if (fcm__sim_contact_has_friction(I)) {
    FCM_ALLOC(ctx, I->num_contacts, cp->pose0);
    FCM_ALLOC(ctx, 7 * (size_t)np * (size_t)I->num_contacts, cp->lag);
  }
  FCM_TRY(ctx, collect(I, 1, &np, &ne));
  cp->ptr[ne] = np;
  for (int c = 0; c < I->num_contacts; c++) {
    sim_contact *ct = &I->contacts[c];
    ct->dhat = ct->opts.distance > 0.0 ? ct->opts.distance : 0.1 * cp->h;
    if (ct->bodies) ct->bodies->rho = 2.0 * ct->dhat;
    ct->kappa = ct->opts.stiffness > 0.0 ? ct->opts.stiffness : I->mat.young / cp->h;
    FCM_CHECK(ct->dhat > 0.0 && ct->kappa > 0.0 && isfinite(ct->kappa), ctx, FCM_ERR_ARG,
              "contact %s %d: threshold %g or stiffness %g not positive (set distance and "
              "stiffness, or give the material a Young modulus)",
              kind_name(ct->kind), c, ct->dhat, ct->kappa);
  }
  FCM_TRY(ctx, fcm__sim_contact_check(I, I->u, I->t));
cleanup:
  return st;
}

/* A point's force g (3) and Newton matrix H (3 x 3) added to the element's fe and Ke (zeroed
 * first when *any is 0) through its shape values N. */
static void add_point(const double *N, int nn, const double g[3], const double H[9], double *fe,
                      double *Ke, int *any)
{
  const int nd = 3 * nn;
  if (!*any) {
    memset(fe, 0, sizeof(double) * (size_t)nd);
    if (Ke) memset(Ke, 0, sizeof(double) * (size_t)nd * nd);
    *any = 1;
  }
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++)
      fe[3 * a + i] += N[a] * g[i];
  if (Ke)
    for (int a = 0; a < nn; a++)
      for (int i = 0; i < 3; i++) {
        double *row = Ke + (size_t)(3 * a + i) * nd;
        for (int b = 0; b < nn; b++)
          for (int m = 0; m < 3; m++)
            row[3 * b + m] += N[a] * N[b] * H[3 * i + m];
      }
}

/* The barrier terms of one point at y (area weight w, shape values N) added to fe and Ke;
 * returns 0 when the point is on or behind an obstacle, or a query failed. The Newton matrix
 * keeps w kappa b''(d) g g^T: the PSD part of the point's exact 3 x 3 Hessian
 * w kappa (b'' g g^T + b' H) (H g = 0 and H is PSD while b' <= 0, so that is its projection;
 * exact for planes and the faces of boxes and surfaces). */
static int point_terms(fcm_integrator *I, const double y[3], double w, const double *N, int nn,
                       double *fe, double *Ke, int *any, double *etot)
{
  const double t = I->bc_time;
  for (int c = 0; c < I->num_contacts; c++) {
    const sim_contact *ct = &I->contacts[c];
    double d, g[3], b1, b2, f[3], H[9];
    if (ct->kind == SIM_CONTACT_BODIES) continue;
    if (fcm__sim_contact_distance(I->ctx, ct, &I->cp.pose[c], y, t, ct->dhat, &I->cp.buf, &d, g,
                                  NULL) != FCM_OK)
      return 0;
    if (!(d > 0.0)) return 0;
    if (d >= ct->dhat) continue;
    *etot += w * ct->kappa * barrier(d, ct->dhat, &b1, &b2);
    const double c1 = w * ct->kappa * b1, c2 = w * ct->kappa * b2;
    for (int i = 0; i < 3; i++) {
      f[i] = c1 * g[i];
      for (int m = 0; m < 3; m++)
        H[3 * i + m] = c2 * g[i] * g[m];
    }
    add_point(N, nn, f, H, fe, Ke, any);
  }
  return 1;
}

/* The friction of point p at y (element start displacements u0) added to fe and Ke. */
static void friction_terms(const fcm_integrator *I, fcm_index p, const double y[3],
                           const double *u0, int nn, double *fe, double *Ke, int *any, double *etot)
{
  const sim_cpoints *cp = &I->cp;
  double y0[3], g[3], H[9];
  point_position(cp, nn, p, u0, y0);
  const double e = fcm__sim_contact_friction(I, p, y, y0, g, H);
  if (e == 0.0 && g[0] == 0.0 && g[1] == 0.0 && g[2] == 0.0) return;
  *etot += e;
  add_point(cp->N + (size_t)p * nn, nn, g, H, fe, Ke, any);
}

void fcm__sim_contact_assemble(fcm_integrator *I, const double *x, double *energy, double *force,
                               fcm_csr *T, int *finite)
{
  const fcm_space *s = I->space;
  const sim_cpoints *cp = &I->cp;
  const int nn = s->nn, nd = 3 * nn;
  double *vals = T ? fcm_csr_values(T) : NULL, etot = 0.0;
  double ue[3 * FCM_ELEMENT_MAX_NODES], u0[3 * FCM_ELEMENT_MAX_NODES];
  double *fe = cp->scratch, *Ke = T ? fe + nd : NULL;
  I->contact_evals++;
  if (cp->swallowed) {
    *finite = 0;
    return;
  }
  poses(I, I->bc_time);
  for (fcm_index k = 0; k < cp->nelem; k++) {
    int any = 0;
    gather(s, cp->elem[k], x, ue);
    if (cp->lag) gather(s, cp->elem[k], I->un, u0);
    for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
      double y[3];
      point_position(cp, nn, p, ue, y);
      if (!point_terms(I, y, cp->w[p], cp->N + (size_t)p * nn, nn, fe, Ke, &any, &etot)) {
        *finite = 0;
        return;
      }
      if (cp->lag) friction_terms(I, p, y, u0, nn, fe, Ke, &any, &etot);
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
  for (int c = 0; c < I->num_contacts && *finite; c++)
    if (I->contacts[c].kind == SIM_CONTACT_BODIES)
      fcm__sim_bodies_assemble(I, &I->contacts[c], x, &etot, force, T, finite);
  if (!isfinite(etot)) *finite = 0;
  if (energy) *energy += etot;
}

double fcm__sim_contact_step_bound(fcm_integrator *I, const double *x, const double *dx)
{
  const fcm_space *s = I->space;
  sim_cpoints *cp = &I->cp;
  const int nn = s->nn;
  double amax = DBL_MAX, ue[3 * FCM_ELEMENT_MAX_NODES], de[3 * FCM_ELEMENT_MAX_NODES];
  poses(I, I->bc_time);
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
        double sc = HUGE_VAL;
        if (I->contacts[c].kind == SIM_CONTACT_BODIES) continue;
        /* fractions beyond 1 / 0.9 never limit a step: the segment's search stops at 2 */
        if (fcm__sim_contact_toi(I->ctx, &I->contacts[c], &cp->pose[c], y, dy, I->bc_time, 2.0,
                                 &cp->buf, &sc) != FCM_OK)
          return 0.0;
        if (!(sc > 0.0)) return 0.0;
        amax = FCM_MIN(amax, sc);
      }
    }
  }
  for (int c = 0; c < I->num_contacts; c++)
    if (I->contacts[c].kind == SIM_CONTACT_BODIES)
      amax = FCM_MIN(amax, fcm__sim_bodies_step_bound(I, &I->contacts[c], x, dx));
  return amax;
}

/* Whether a moving surface obstacle holds a point of x at time bc_time: such a point lies
 * beyond the reach of the barrier, so the energy alone would not see it. */
static int swallowed(fcm_integrator *I, const double *x)
{
  sim_cpoints *cp = &I->cp;
  const int nn = I->space->nn;
  double ue[3 * FCM_ELEMENT_MAX_NODES];
  int any = 0;
  for (int c = 0; c < I->num_contacts; c++)
    any |= I->contacts[c].kind == SIM_CONTACT_SURFACE && I->contacts[c].moving;
  if (!any) return 0;
  poses(I, I->bc_time);
  for (fcm_index k = 0; k < cp->nelem; k++) {
    gather(I->space, cp->elem[k], x, ue);
    for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
      double y[3];
      point_position(cp, nn, p, ue, y);
      for (int c = 0; c < I->num_contacts; c++) {
        const sim_contact *ct = &I->contacts[c];
        int in = 0;
        if (ct->kind != SIM_CONTACT_SURFACE || !ct->moving) continue;
        if (fcm__sim_contact_inside(I->ctx, ct, &cp->pose[c], y, I->bc_time, &cp->buf, &in) !=
                FCM_OK ||
            in)
          return 1;
      }
    }
  }
  return 0;
}

void fcm__sim_contact_pull_back(fcm_integrator *I)
{
  I->cp.swallowed = swallowed(I, I->un);
  if (I->cp.swallowed) return;
  for (fcm_index i = 0; i < I->n; i++)
    I->w1[i] = I->u[i] - I->un[i];
  const double amax = fcm__sim_contact_step_bound(I, I->un, I->w1);
  if (amax > 1.0) return;
  for (fcm_index i = 0; i < I->n; i++)
    I->u[i] = I->un[i] + 0.9 * amax * I->w1[i];
  I->contact_pullbacks++;
}

/* Every embedded-surface point within d^ of an obstacle at the state x and time t: its
 * element, position and the distance's gradient, for the static rigid-mode check (the
 * barrier's Newton matrix holds the point along that gradient). */
fcm_status fcm__sim_contact_support(fcm_integrator *I, const double *x, double t,
                                    void (*fn)(void *user, fcm_index elem, const double y[3],
                                               const double g[3]),
                                    void *user)
{
  fcm_status st = FCM_OK;
  fcm__idbuf buf = {NULL, 0, 0};
  const sim_cpoints *cp = &I->cp;
  const int nn = I->space->nn;
  double ue[3 * FCM_ELEMENT_MAX_NODES];
  for (fcm_index k = 0; k < cp->nelem; k++) {
    gather(I->space, cp->elem[k], x, ue);
    for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
      double y[3], d, g[3];
      point_position(cp, nn, p, ue, y);
      for (int c = 0; c < I->num_contacts; c++) {
        const sim_contact *ct = &I->contacts[c];
        sim_pose P;
        if (ct->kind == SIM_CONTACT_BODIES) continue;
        fcm__sim_contact_pose(ct, t, &P);
        FCM_TRY(I->ctx,
                fcm__sim_contact_distance(I->ctx, ct, &P, y, t, ct->dhat, &buf, &d, g, NULL));
        if (d > 0.0 && d < ct->dhat) fn(user, cp->elem[k], y, g);
      }
    }
  }
cleanup:
  fcm__geom_idbuf_free(I->ctx, &buf);
  return st;
}

/* The smallest signed distance to any obstacle or other body at the state just accepted,
 * folded into the step's running minimum (the last substep's state is the current one, which
 * fcm_integrator_contact_stats() measures itself). */
fcm_status fcm__sim_contact_track(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  double dmin = HUGE_VAL;
  for (int c = 0; c < I->num_contacts; c++) {
    double d = HUGE_VAL;
    FCM_TRY(I->ctx, fcm_integrator_contact_info(I, c, NULL, &d, NULL, NULL));
    dmin = FCM_MIN(dmin, d);
  }
  I->contact_dmin_inner = I->contact_inner_states > 0 ? FCM_MIN(I->contact_dmin_inner, dmin) : dmin;
  I->contact_inner_states++;
cleanup:
  return st;
}

fcm_status fcm_integrator_contact_info(const fcm_integrator *I, int id, double force[3],
                                       double *min_distance, double *dhat, double *kappa)
{
  fcm_status st = FCM_OK;
  fcm__idbuf buf = {NULL, 0, 0};
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  FCM_CHECK(I->is_setup, ctx, FCM_ERR_ARG, "contact info: the integrator is not set up");
  FCM_CHECK(id >= 0 && id < I->num_contacts, ctx, FCM_ERR_ARG,
            "contact info: obstacle %d out of range [0, %d)", id, I->num_contacts);
  if (I->contacts[id].kind == SIM_CONTACT_BODIES) { /* no net force: the pieces push each other */
    long long pairs = 0;
    double dmin = HUGE_VAL, e = 0.0;
    FCM_TRY(ctx, fcm__sim_bodies_stats(I, &I->contacts[id], I->u, &pairs, &dmin, &e));
    if (force) force[0] = force[1] = force[2] = 0.0;
    if (min_distance) *min_distance = dmin;
    if (dhat) *dhat = I->contacts[id].dhat;
    if (kappa) *kappa = I->contacts[id].kappa;
    return FCM_OK;
  }
  {
    const sim_cpoints *cp = &I->cp;
    const sim_contact *ct = &I->contacts[id];
    const int nn = I->space->nn;
    double F[3] = {0, 0, 0}, dmin = DBL_MAX, ue[3 * FCM_ELEMENT_MAX_NODES];
    sim_pose P;
    fcm__sim_contact_pose(ct, I->t, &P);
    for (fcm_index k = 0; k < cp->nelem; k++) {
      gather(I->space, cp->elem[k], I->u, ue);
      for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
        double y[3], d, g[3], b1, b2;
        point_position(cp, nn, p, ue, y);
        /* a surface's search reaches as far as the smallest distance so far */
        const double reach = ct->kind != SIM_CONTACT_SURFACE ? 0.0
                             : dmin < DBL_MAX                ? FCM_MAX(dmin, ct->dhat)
                                                             : fcm__sim_contact_reach(ct, &P, y);
        FCM_TRY(ctx, fcm__sim_contact_distance(ctx, ct, &P, y, I->t, reach, &buf, &d, g, NULL));
        if (ct->kind == SIM_CONTACT_SURFACE) { /* signed: a point inside counts as below 0 */
          int in = 0;
          FCM_TRY(ctx, fcm__sim_contact_inside(ctx, ct, &P, y, I->t, &buf, &in));
          if (in) {
            FCM_TRY(ctx, fcm__sim_contact_distance(ctx, ct, &P, y, I->t,
                                                   fcm__sim_contact_reach(ct, &P, y), &buf, &d, g,
                                                   NULL));
            d = -d;
          }
        }
        dmin = FCM_MIN(dmin, d);
        if (!(d > 0.0) || d >= ct->dhat) continue;
        barrier(d, ct->dhat, &b1, &b2);
        for (int i = 0; i < 3; i++)
          F[i] -= cp->w[p] * ct->kappa * b1 * g[i];
      }
    }
    if (force) memcpy(force, F, sizeof F);
    if (min_distance) *min_distance = dmin;
    if (dhat) *dhat = ct->dhat;
    if (kappa) *kappa = ct->kappa;
  }
cleanup:
  if (I) fcm__geom_idbuf_free(I->ctx, &buf);
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
    const int sw = I->cp.swallowed;
    int finite = 1;
    double e = 0.0;
    I->bc_time = t;
    I->cp.swallowed = 0;
    fcm__sim_contact_assemble(I, u, &e, force, tangent, &finite);
    I->bc_time = t_saved;
    I->cp.swallowed = sw;
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

fcm_status fcm_integrator_contact_stats(const fcm_integrator *I, fcm_contact_stats *out)
{
  fcm_status st = FCM_OK;
  fcm__idbuf buf = {NULL, 0, 0};
  FCM_CHECK(I && out, I ? I->ctx : NULL, FCM_ERR_ARG, "contact stats: NULL integrator or stats");
  fcm_ctx *ctx = I->ctx;
  memset(out, 0, sizeof *out);
  out->evaluations = I->contact_evals;
  out->friction_updates = I->cp.relags;
  out->min_distance = out->step_min_distance = HUGE_VAL;
  if (!I->is_setup || I->num_contacts == 0) return FCM_OK;
  {
    const sim_cpoints *cp = &I->cp;
    const int nn = I->space->nn;
    double ue[3 * FCM_ELEMENT_MAX_NODES], u0[3 * FCM_ELEMENT_MAX_NODES];
    for (int c = 0; c < I->num_contacts; c++) {
      double dmin = HUGE_VAL;
      FCM_TRY(ctx, fcm_integrator_contact_info(I, c, NULL, &dmin, NULL, NULL));
      out->min_distance = FCM_MIN(out->min_distance, dmin);
    }
    out->step_min_distance = out->min_distance;
    if (I->contact_inner_states > 0)
      out->step_min_distance = FCM_MIN(out->step_min_distance, I->contact_dmin_inner);
    for (fcm_index k = 0; k < cp->nelem; k++) {
      gather(I->space, cp->elem[k], I->u, ue);
      if (cp->lag) gather(I->space, cp->elem[k], I->un, u0);
      for (fcm_index p = cp->ptr[k]; p < cp->ptr[k + 1]; p++) {
        double y[3], d, g[3], b1, b2;
        point_position(cp, nn, p, ue, y);
        for (int c = 0; c < I->num_contacts; c++) {
          const sim_contact *ct = &I->contacts[c];
          sim_pose P;
          if (ct->kind == SIM_CONTACT_BODIES) continue;
          fcm__sim_contact_pose(ct, I->t, &P);
          FCM_TRY(ctx,
                  fcm__sim_contact_distance(ctx, ct, &P, y, I->t, ct->dhat, &buf, &d, g, NULL));
          if (!(d > 0.0) || d >= ct->dhat) continue;
          out->active_points++;
          out->barrier_energy += cp->w[p] * ct->kappa * barrier(d, ct->dhat, &b1, &b2);
        }
        if (cp->lag) {
          double y0[3];
          point_position(cp, nn, p, u0, y0);
          out->friction_dissipation += fcm__sim_contact_friction_work(I, p, y, y0);
        }
      }
    }
    for (int c = 0; c < I->num_contacts; c++) {
      long long pairs = 0;
      double dmin = HUGE_VAL, e = 0.0;
      if (I->contacts[c].kind != SIM_CONTACT_BODIES) continue;
      FCM_TRY(ctx, fcm__sim_bodies_stats(I, &I->contacts[c], I->u, &pairs, &dmin, &e));
      out->active_points += pairs;
      out->body_pairs += pairs;
      out->barrier_energy += e;
      out->tree_builds += fcm__sim_bodies_builds(&I->contacts[c]);
      FCM_TRY(ctx, fcm__sim_bodies_depth(I, &I->contacts[c], I->u, &out->body_depth, NULL));
      if (I->contacts[c].opts.self_contact) {
        FCM_TRY(ctx, fcm__sim_bodies_self_stats(I, &I->contacts[c], I->u, &out->self_pairs,
                                                &out->self_depth, NULL));
        out->body_depth = FCM_MAX(out->body_depth, out->self_depth);
      }
      out->self_tests += fcm__sim_bodies_self_tests(&I->contacts[c]);
      out->friction_dissipation += fcm__sim_bodies_friction_work(I, &I->contacts[c], I->u);
    }
  }
cleanup:
  if (I) fcm__geom_idbuf_free(I->ctx, &buf);
  return st;
}
