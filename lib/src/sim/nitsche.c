/* sim: Dirichlet conditions on the embedded boundary — symmetric Nitsche (or a penalty) on
 * the surface quadrature points of the cell rules: the boundary options, the registration
 * of a constraint, and the setup that collects the constrained points per element, groups
 * the elements by colour and estimates each element's penalty. The energy, its gradient and
 * Hessian, evaluated at every step, are in nitsche_assemble.c.
 *
 * The penalty of an element: safety x lambda_max of T v = lambda K v (Griebel and Schweitzer
 * 2003; the eigenvalue estimate of Embar, Dolbow and Harari 2010, with the FCM stabilization
 * points in K as in de Prenter et al. 2018), T the traction energy of the element's
 * constrained points, K its linear-elastic stiffness at rest; rigid modes are lifted
 * (B = K + s R R^T). */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"
#include "la/mat3.h"
#include "material/material_impl.h"

#include <math.h>
#include <omp.h>
#include <string.h>

const char *fcm_boundary_method_name(fcm_boundary_method method)
{
  switch (method) {
  case FCM_BOUNDARY_NITSCHE:
    return "nitsche";
  case FCM_BOUNDARY_PENALTY:
    return "penalty";
  default:
    return "invalid";
  }
}

fcm_boundary_options fcm_boundary_options_default(void)
{
  fcm_boundary_options o;
  memset(&o, 0, sizeof o);
  o.method = FCM_BOUNDARY_NITSCHE;
  o.nitsche_safety = 2.0;
  o.penalty = 1e3;
  return o;
}

fcm_status fcm_integrator_add_boundary_constraint(fcm_integrator *I, fcm_boundary_select_fn select,
                                                  void *user, const fcm_motion *motion,
                                                  const fcm_boundary_options *opts, int *id)
{
  fcm_status st = FCM_OK;
  sim_bcon b;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  const int k = I->num_bcons;
  FCM_CHECK(!I->is_setup, ctx, FCM_ERR_ARG,
            "integrator: boundary constraints must be added before fcm_integrator_setup()");
  FCM_CHECK(motion, ctx, FCM_ERR_ARG, "boundary constraint %d: NULL motion", k);
  memset(&b, 0, sizeof b);
  b.select = select;
  b.select_user = user;
  b.motion = *motion;
  b.opts = opts ? *opts : fcm_boundary_options_default();
  {
    const fcm_motion *m = motion;
    int fin = 1;
    for (int i = 0; i < 3; i++)
      fin &= isfinite(m->velocity[i]) && isfinite(m->center[i]) && isfinite(m->axis[i]);
    FCM_CHECK(fin && isfinite(m->angular_speed), ctx, FCM_ERR_ARG,
              "boundary constraint %d: velocity, center, axis or angular_speed not finite", k);
    FCM_CHECK(isfinite(m->start) && !isnan(m->end) && m->end >= m->start, ctx, FCM_ERR_ARG,
              "boundary constraint %d: end = %g must be >= start = %g (start finite)", k, m->end,
              m->start);
    double an = sqrt(m->axis[0] * m->axis[0] + m->axis[1] * m->axis[1] + m->axis[2] * m->axis[2]);
    if (an > 0.0)
      for (int i = 0; i < 3; i++)
        b.motion.axis[i] = m->axis[i] / an;
    FCM_CHECK(m->components[0] || m->components[1] || m->components[2], ctx, FCM_ERR_ARG,
              "boundary constraint %d: motion.components constrains no component", k);
  }
  FCM_CHECK(b.opts.method >= 0 && b.opts.method < FCM_BOUNDARY_METHOD_COUNT, ctx, FCM_ERR_ARG,
            "boundary constraint %d: method = %d outside [0, 1] (nitsche, penalty)", k,
            (int)b.opts.method);
  FCM_CHECK(b.opts.nitsche_safety > 1.0 && isfinite(b.opts.nitsche_safety), ctx, FCM_ERR_ARG,
            "boundary constraint %d: nitsche_safety = %g must be finite and > 1", k,
            b.opts.nitsche_safety);
  FCM_CHECK(b.opts.penalty > 0.0 && isfinite(b.opts.penalty), ctx, FCM_ERR_ARG,
            "boundary constraint %d: penalty = %g must be finite and > 0", k, b.opts.penalty);
  FCM_TRY(ctx, fcm__resize(ctx, (void **)&I->bcons, (size_t)I->num_bcons, (size_t)I->num_bcons + 1,
                           sizeof *I->bcons));
  I->bcons[I->num_bcons++] = b;
  if (id) *id = k;
cleanup:
  return st;
}

static double element_max_penalty(const fcm_integrator *I, fcm_index k);

void fcm__sim_boundary_free(fcm_integrator *I)
{
  fcm_ctx *ctx = I->ctx;
  sim_bpoints *bp = &I->bp;
  fcm__free(ctx, bp->elem);
  fcm__free(ctx, bp->lelem);
  fcm__free(ctx, bp->ptr);
  fcm__free(ctx, bp->con);
  fcm__free(ctx, bp->color_ptr);
  fcm__free(ctx, bp->color_k);
  double **v[] = {&bp->w,     &bp->X,  &bp->nrm,     &bp->N,    &bp->G,
                  &bp->gamma, &bp->hk, &bp->scratch, &bp->eelem};
  for (size_t k = 0; k < sizeof v / sizeof v[0]; k++)
    FCM_FREE(ctx, *v[k]);
  fcm__free(ctx, I->bcons);
  fcm__free(ctx, I->bcon_on);
  memset(bp, 0, sizeof *bp);
}

/* Physical gradients g (nn x 3) at reference point xi of a cell with nodes X; det J. */
static double gradients(fcm_element_type type, int nn, const double *X, const double xi[3],
                        double *g)
{
  double dN[3 * FCM_ELEMENT_MAX_NODES];
  fcm_element_eval_grad(type, xi, dN);
  return fcm__fem_gradients(nn, X, dN, g);
}

/* The boundary constraint that holds a point: the first that selects it, or -1. */
static int point_owner(const fcm_integrator *I, const double X[3], const double n[3])
{
  for (int k = 0; k < I->num_bcons; k++) {
    const sim_bcon *b = &I->bcons[k];
    if (!b->select || b->select(b->select_user, X, n)) return k;
  }
  return -1;
}

/* Traction of the shape mode (b, k) at a point, linear elasticity at rest: row i of
 * C (3 x 3nn) = p_i (lambda g_bk N_i + mu (d_ik g_b . N + N_k g_bi)). */
static void traction_modes(int nn, const double *g, const double *N, const int *pc, double lambda,
                           double mu, double *C)
{
  const int nd = 3 * nn;
  for (int b = 0; b < nn; b++) {
    const double *gb = g + 3 * b, gn = gb[0] * N[0] + gb[1] * N[1] + gb[2] * N[2];
    for (int k = 0; k < 3; k++)
      for (int i = 0; i < 3; i++)
        C[i * nd + 3 * b + k] =
            pc[i] ? lambda * gb[k] * N[i] + mu * ((i == k ? gn : 0.0) + N[k] * gb[i]) : 0.0;
  }
}

/* The volume rule the assembly integrates element e with (stabilization included): the
 * stiffness rule of its cut piece, or the standard rule full of an uncut cell. */
static fcm_status element_volume_rule(fcm_integrator *I, fcm_index e, const fcm_rule *full, int *nq,
                                      const double **pts, const double **wts)
{
  fcm_status st = FCM_OK;
  const fcm_space *s = I->space;
  if (s->rules && fcm_cell_rules_class(s->rules, s->elem_cell[e]) != FCM_CELL_UNCUT) {
    FCM_TRY(I->ctx, fcm_cell_rules_get_piece(s->rules, s->elem_piece[e], FCM_RULE_STIFFNESS, nq,
                                             pts, wts, NULL));
  } else {
    *nq = fcm_rule_num_points(full);
    *pts = fcm_rule_points(full);
    *wts = fcm_rule_weights(full);
  }
cleanup:
  return st;
}

/* |K| of the cell with nodes X: the standard rule full integrates 1 exactly. */
static double cell_volume(fcm_element_type type, const double *X, const fcm_rule *full)
{
  double vol = 0.0;
  const int fq = fcm_rule_num_points(full);
  for (int q = 0; q < fq; q++) {
    double J[9];
    vol +=
        fcm_rule_weights(full)[q] * fcm_element_jacobian(type, X, fcm_rule_points(full) + 3 * q, J);
  }
  return vol;
}

/* The largest safety factor of the Nitsche points [p0, p1) (0 when there are none). */
static double nitsche_safety(const fcm_integrator *I, fcm_index p0, fcm_index p1)
{
  double safety = 0.0;
  for (fcm_index p = p0; p < p1; p++) {
    const sim_bcon *bc = &I->bcons[I->bp.con[p]];
    if (bc->opts.method == FCM_BOUNDARY_NITSCHE) safety = FCM_MAX(safety, bc->opts.nitsche_safety);
  }
  return safety;
}

/* Add to K (nd x nd) the linear-elastic stiffness at rest of cell `cell` with nodes X, over
 * the volume rule (nq, pts, wts). */
static fcm_status elastic_stiffness(const fcm_integrator *I, fcm_index cell, const double *X,
                                    int nq, const double *pts, const double *wts, double *K)
{
  fcm_status st = FCM_OK;
  const fcm_space *s = I->space;
  const int nn = s->nn, nd = 3 * nn;
  const double lambda = I->params.lambda, mu = I->params.mu;
  double g[3 * FCM_ELEMENT_MAX_NODES];
  for (int q = 0; q < nq; q++) {
    double det = gradients(s->type, nn, X, pts + 3 * q, g);
    FCM_CHECK(det > 0.0, I->ctx, FCM_ERR_GEOMETRY,
              "boundary constraint: cell %lld has det J = %g <= 0 at a quadrature point",
              (long long)cell, det);
    const double wd = wts[q] * det;
    for (int a = 0; a < nn; a++)
      for (int bb = 0; bb < nn; bb++) {
        const double *ga = g + 3 * a, *gb = g + 3 * bb;
        const double dd = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < 3; j++)
            K[(size_t)(3 * a + i) * nd + 3 * bb + j] +=
                wd * (lambda * ga[i] * gb[j] + mu * ga[j] * gb[i] + (i == j ? mu * dd : 0.0));
      }
  }
cleanup:
  return st;
}

/* Add to T (nd x nd) the traction energy sum w C^T C of the Nitsche points [p0, p1); C
 * (3 x nd) is workspace. */
static void traction_energy(const fcm_integrator *I, fcm_index p0, fcm_index p1, double *C,
                            double *T)
{
  const int nn = I->space->nn, nd = 3 * nn;
  const double lambda = I->params.lambda, mu = I->params.mu;
  for (fcm_index p = p0; p < p1; p++) {
    const sim_bcon *bc = &I->bcons[I->bp.con[p]];
    if (bc->opts.method != FCM_BOUNDARY_NITSCHE) continue;
    traction_modes(nn, I->bp.G + (size_t)p * nd, I->bp.nrm + 3 * p, bc->motion.components, lambda,
                   mu, C);
    for (int x = 0; x < nd; x++)
      for (int y = 0; y < nd; y++)
        T[(size_t)x * nd + y] +=
            I->bp.w[p] * (C[x] * C[y] + C[nd + x] * C[nd + y] + C[2 * nd + x] * C[2 * nd + y]);
  }
}

/* Rigid modes (translations, rotations about the centroid) of the cell with nodes X,
 * orthonormalized into R (6 x nd); K and T vanish on them, so K + s R R^T (s the mean
 * diagonal of K) is positive definite and has the same eigenvalues on their complement. */
static void lift_rigid_modes(int nn, const double *X, double *R, double *K)
{
  const int nd = 3 * nn;
  double c[3] = {0, 0, 0}, tr = 0.0;
  for (int a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++)
      c[i] += X[3 * a + i] / nn;
  for (int a = 0; a < nn; a++) {
    double r[3] = {X[3 * a] - c[0], X[3 * a + 1] - c[1], X[3 * a + 2] - c[2]};
    for (int i = 0; i < 3; i++) {
      R[(size_t)i * nd + 3 * a + i] = 1.0;
      /* rotation about axis i: e_i x r */
      double *Ri = R + (size_t)(3 + i) * nd + 3 * a;
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      Ri[k] = r[j];
      Ri[j] = -r[k];
    }
  }
  for (int pass = 0; pass < 2; pass++) /* modified Gram-Schmidt, twice */
    for (int m = 0; m < 6; m++) {
      double *rm = R + (size_t)m * nd;
      for (int l = 0; l < m; l++) {
        const double *rl = R + (size_t)l * nd;
        double d = 0.0;
        for (int x = 0; x < nd; x++)
          d += rm[x] * rl[x];
        for (int x = 0; x < nd; x++)
          rm[x] -= d * rl[x];
      }
      double nrm = 0.0;
      for (int x = 0; x < nd; x++)
        nrm += rm[x] * rm[x];
      nrm = sqrt(nrm);
      for (int x = 0; x < nd; x++)
        rm[x] /= nrm;
    }
  for (int x = 0; x < nd; x++)
    tr += K[(size_t)x * nd + x];
  const double sc = tr / nd;
  for (int m = 0; m < 6; m++)
    for (int x = 0; x < nd; x++)
      for (int y = 0; y < nd; y++)
        K[(size_t)x * nd + y] += sc * R[(size_t)m * nd + x] * R[(size_t)m * nd + y];
}

/* Penalties of element e from its points [p0, p1): Nitsche's eigenvalue estimate over its
 * Nitsche points (0 when it has none) into *gamma, and the cell size h_K (the penalty method's
 * gamma is penalty E / h_K) into *hk. */
static fcm_status element_penalty(fcm_integrator *I, fcm_index e, fcm_index p0, fcm_index p1,
                                  const fcm_rule *full, double *gamma, double *hk)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_space *s = I->space;
  const int nn = s->nn, nd = 3 * nn;
  double *K = NULL, *T = NULL, *C = NULL, *R = NULL, *ev = NULL;
  double X[3 * FCM_ELEMENT_MAX_NODES];
  const fcm_index cell = s->elem_cell[e];
  fcm_mesh_cell_coords(s->mesh, cell, X);
  int nq = 0;
  const double *pts = NULL, *wts = NULL;
  FCM_TRY(ctx, element_volume_rule(I, e, full, &nq, &pts, &wts));
  *hk = cbrt(fabs(cell_volume(s->type, X, full)));
  *gamma = 0.0;
  const double safety = nitsche_safety(I, p0, p1);
  if (safety == 0.0) goto cleanup;
  FCM_ALLOC(ctx, (size_t)nd * nd, K);
  FCM_ALLOC(ctx, (size_t)nd * nd, T);
  FCM_ALLOC(ctx, (size_t)3 * nd, C);
  FCM_ALLOC(ctx, (size_t)6 * nd, R);
  FCM_ALLOC(ctx, nd, ev);
  FCM_TRY(ctx, elastic_stiffness(I, cell, X, nq, pts, wts, K));
  traction_energy(I, p0, p1, C, T);
  lift_rigid_modes(nn, X, R, K);
  {
    fcm_status s2 = fcm__sygv(ctx, nd, T, nd, K, nd, ev);
    if (s2 == FCM_ERR_SINGULAR) {
      fcm_ctx_error_clear(ctx);
      FCM_CHECK(0, ctx, FCM_ERR_NUMERIC,
                "boundary constraint: the Nitsche penalty of cell %lld (volume fraction %g) "
                "cannot be estimated: its stiffness is singular beyond the rigid-body modes "
                "(enable the stabilization of the cell rules, or raise min_fraction)",
                (long long)cell, s->rules ? fcm_cell_rules_volume_fraction(s->rules, cell) : 1.0);
    }
    FCM_TRY(ctx, s2);
  }
  *gamma = safety * FCM_MAX(ev[nd - 1], 0.0);
  FCM_CHECK(isfinite(*gamma), ctx, FCM_ERR_NUMERIC,
            "boundary constraint: the Nitsche penalty of cell %lld is not finite", (long long)cell);
cleanup:
  fcm__free(ctx, K);
  fcm__free(ctx, T);
  fcm__free(ctx, C);
  fcm__free(ctx, R);
  fcm__free(ctx, ev);
  return st;
}

/* One pass over the elements' surface points: pass 0 counts the points each constraint
 * selects into count, pass 1 stores them (bp, sized by pass 0); *np_out and *ne_out get the
 * numbers of selected points and of elements with any. */
static fcm_status collect_points(fcm_integrator *I, int pass, fcm_index *count, fcm_index *np_out,
                                 fcm_index *ne_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_space *s = I->space;
  sim_bpoints *bp = &I->bp;
  const int nn = s->nn, nd = 3 * nn;
  fcm_index np = 0, ne = 0;
  for (fcm_index e = 0; e < s->num_elems; e++) {
    int nsp = 0;
    const double *pts = NULL, *wts = NULL, *nrm = NULL;
    double X[3 * FCM_ELEMENT_MAX_NODES], N[FCM_ELEMENT_MAX_NODES];
    FCM_TRY(ctx, fcm_cell_rules_get_piece_surface(s->rules, s->elem_piece[e], &nsp, &pts, &wts,
                                                  &nrm, NULL));
    if (nsp == 0) continue;
    fcm_mesh_cell_coords(s->mesh, s->elem_cell[e], X);
    const fcm_index first = np;
    for (int q = 0; q < nsp; q++) {
      double x[3] = {0, 0, 0};
      fcm_element_eval_shape(s->type, pts + 3 * q, N);
      for (int a = 0; a < nn; a++)
        for (int i = 0; i < 3; i++)
          x[i] += N[a] * X[3 * a + i];
      const int k = point_owner(I, x, nrm + 3 * q);
      if (k < 0 || !(wts[q] > 0.0)) continue;
      if (pass == 1) {
        bp->con[np] = k;
        bp->w[np] = wts[q];
        memcpy(bp->X + 3 * np, x, sizeof x);
        memcpy(bp->nrm + 3 * np, nrm + 3 * q, 3 * sizeof(double));
        memcpy(bp->N + (size_t)np * nn, N, sizeof(double) * (size_t)nn);
        double det = gradients(s->type, nn, X, pts + 3 * q, bp->G + (size_t)np * nd);
        FCM_CHECK(det > 0.0, ctx, FCM_ERR_GEOMETRY,
                  "boundary constraint %d: cell %lld has det J = %g <= 0 at a boundary point", k,
                  (long long)s->elem_cell[e], det);
      } else {
        count[k]++;
      }
      np++;
    }
    if (np > first) {
      if (pass == 1) {
        bp->elem[ne] = e;
        bp->ptr[ne] = first;
      }
      ne++;
    }
  }
cleanup:
  *np_out = np;
  *ne_out = ne;
  return st;
}

/* After the counting pass: every constraint must select a point (over all processes when a
 * backend distributes the run); allocate the point arrays for np points on ne elements. */
static fcm_status size_points(fcm_integrator *I, fcm_index *count, fcm_index np, fcm_index ne)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_bpoints *bp = &I->bp;
  const int nn = I->space->nn, nd = 3 * nn;
  for (int k0 = 0; k0 < I->num_bcons; k0 += 64) { /* this process's cells' points: all */
    double c[64];
    const int m = I->num_bcons - k0 < 64 ? I->num_bcons - k0 : 64;
    for (int k = 0; k < m; k++)
      c[k] = (double)count[k0 + k];
    FCM_TRY(ctx, fcm__integrator_reduce(I, c, m));
    for (int k = 0; k < m; k++)
      count[k0 + k] = (fcm_index)c[k];
  }
  for (int k = 0; k < I->num_bcons; k++)
    FCM_CHECK(count[k] > 0, ctx, FCM_ERR_ARG,
              "boundary constraint %d selects no embedded-boundary point (check its region "
              "against the body's surface)",
              k);
  bp->np = np;
  bp->nelem = ne;
  FCM_ALLOC(ctx, ne, bp->elem);
  FCM_ALLOC(ctx, ne + 1, bp->lelem);
  FCM_ALLOC(ctx, ne + 1, bp->ptr);
  FCM_ALLOC(ctx, np, bp->con);
  FCM_ALLOC(ctx, np, bp->w);
  FCM_ALLOC(ctx, 3 * (size_t)np, bp->X);
  FCM_ALLOC(ctx, 3 * (size_t)np, bp->nrm);
  FCM_ALLOC(ctx, (size_t)np * nn, bp->N);
  FCM_ALLOC(ctx, (size_t)np * nd, bp->G);
  bp->nthreads = fcm_ctx_num_threads(ctx);
  FCM_ALLOC(ctx, ((size_t)nd * (nd + 2) + 9 * (size_t)nn) * (size_t)bp->nthreads, bp->scratch);
  FCM_ALLOC(ctx, ne + 1, bp->eelem);
cleanup:
  return st;
}

/* The elements with points grouped by the space's colours (parallel assembly); a local
 * space's colours list local positions (fem_impl.h), and its elements with points (those of
 * the process's own cells) are local. */
static fcm_status group_by_colour(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_space *s = I->space;
  sim_bpoints *bp = &I->bp;
  fcm_index *ecol = NULL;
  for (fcm_index k = 0; k < bp->nelem; k++) {
    bp->lelem[k] = fcm__space_elem_local(s, bp->elem[k]);
    FCM_CHECK(bp->lelem[k] >= 0, ctx, FCM_ERR_INTERNAL,
              "boundary constraint: cell %lld has boundary points but is no local cell of the "
              "space",
              (long long)s->elem_cell[bp->elem[k]]);
  }
  FCM_ALLOC(ctx, s->num_local_elems + 1, ecol);
  for (int c = 0; c < s->num_colors; c++)
    for (fcm_index j = s->color_ptr[c]; j < s->color_ptr[c + 1]; j++)
      ecol[s->color_elems[j]] = c;
  bp->num_colors = s->num_colors;
  FCM_ALLOC(ctx, (size_t)s->num_colors + 1, bp->color_ptr);
  FCM_ALLOC(ctx, (size_t)bp->nelem + 1, bp->color_k);
  for (fcm_index k = 0; k < bp->nelem; k++)
    bp->color_ptr[ecol[bp->lelem[k]] + 1]++;
  for (int c = 0; c < s->num_colors; c++)
    bp->color_ptr[c + 1] += bp->color_ptr[c];
  for (fcm_index k = 0; k < bp->nelem; k++) /* ascending k within a colour */
    bp->color_k[bp->color_ptr[ecol[bp->lelem[k]]]++] = k;
  for (int c = s->num_colors; c > 0; c--)
    bp->color_ptr[c] = bp->color_ptr[c - 1];
  bp->color_ptr[0] = 0;
cleanup:
  fcm__free(ctx, ecol);
  return st;
}

/* The penalties of the elements with points, and the largest in the setup info. */
static fcm_status boundary_penalties(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  sim_bpoints *bp = &I->bp;
  fcm_rule *full = NULL;
  FCM_TRY(ctx, fcm_element_standard_rule(ctx, I->space->type, FCM_RULE_STIFFNESS,
                                         I->opts.assembly.stiffness_strength, &full));
  I->setup_info.boundary_points = bp->np;
  for (fcm_index k = 0; k < bp->nelem; k++) {
    const fcm_index e = bp->elem[k];
    FCM_TRY(ctx,
            element_penalty(I, e, bp->ptr[k], bp->ptr[k + 1], full, &bp->gamma[e], &bp->hk[e]));
    I->setup_info.boundary_penalty_max = FCM_MAX(
        I->setup_info.boundary_penalty_max, element_max_penalty(I, k) * bp->hk[e] / I->mat.young);
  }
cleanup:
  fcm_rule_destroy(&full);
  return st;
}

fcm_status fcm__sim_boundary_setup(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_space *s = I->space;
  sim_bpoints *bp = &I->bp;
  fcm_index *count = NULL;
  if (I->num_bcons == 0) return FCM_OK;
  FCM_CHECK(s->rules && fcm_cell_rules_surface_strength(s->rules) >= 0, ctx, FCM_ERR_ARG,
            "boundary constraint 0: the space has no surface rules (build the cell rules with "
            "surface_strength >= 0)");
  FCM_ALLOC(ctx, I->num_bcons, I->bcon_on);
  FCM_ALLOC(ctx, I->num_bcons, count);
  FCM_ALLOC(ctx, s->num_elems + 1, bp->gamma);
  FCM_ALLOC(ctx, s->num_elems + 1, bp->hk);
  /* count the selected points per element, then store them */
  for (int pass = 0; pass < 2; pass++) {
    fcm_index np = 0, ne = 0;
    FCM_TRY(ctx, collect_points(I, pass, count, &np, &ne));
    if (pass == 0)
      FCM_TRY(ctx, size_points(I, count, np, ne));
    else
      bp->ptr[ne] = np;
  }
  FCM_TRY(ctx, group_by_colour(I));
  FCM_TRY(ctx, boundary_penalties(I));
cleanup:
  fcm__free(ctx, count);
  return st;
}

static double element_max_penalty(const fcm_integrator *I, fcm_index k)
{
  const sim_bpoints *bp = &I->bp;
  const fcm_index e = bp->elem[k];
  double g = bp->gamma[e];
  for (fcm_index p = bp->ptr[k]; p < bp->ptr[k + 1]; p++) {
    const sim_bcon *bc = &I->bcons[bp->con[p]];
    if (bc->opts.method == FCM_BOUNDARY_PENALTY)
      g = FCM_MAX(g, bc->opts.penalty * I->mat.young / bp->hk[e]);
  }
  return g;
}

double fcm_integrator_boundary_penalty(const fcm_integrator *I, fcm_index elem)
{
  if (!I || !I->bp.gamma || elem < 0 || elem >= I->space->num_elems) return 0.0;
  const sim_bpoints *bp = &I->bp;
  /* elements with points are sorted */
  const fcm_index lo = fcm__lower_bound(bp->elem, 1, 0, bp->nelem, elem);
  return lo < bp->nelem && bp->elem[lo] == elem ? element_max_penalty(I, lo) : 0.0;
}
