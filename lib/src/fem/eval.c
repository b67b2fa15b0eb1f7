/* Point evaluation of a field on a space (fcm_space_eval, fcm_space_element_eval) and the
 * body's mass, linear and angular momentum (fcm_space_momentum) over the mass rules. */
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <string.h>

fcm_status fcm_space_eval(const fcm_space *s, fcm_index cell, const double xi[3], const double *u,
                          double value[3])
{
  fcm_status st = FCM_OK;
  FCM_CHECK(cell >= 0 && cell < s->num_cells && s->active[cell], s->ctx, FCM_ERR_ARG,
            "space eval: cell %lld is out of range [0, %lld) or inactive", (long long)cell,
            (long long)s->num_cells);
  FCM_CHECK(s->cell_elem[cell + 1] - s->cell_elem[cell] == 1, s->ctx, FCM_ERR_ARG,
            "space eval: cell %lld is split into %lld pieces by cuts: evaluate per element "
            "(fcm_space_element_eval())",
            (long long)cell, (long long)(s->cell_elem[cell + 1] - s->cell_elem[cell]));
  FCM_TRY(s->ctx, fcm_space_element_eval(s, s->cell_elem[cell], xi, u, value));
cleanup:
  return st;
}

fcm_status fcm_space_element_eval(const fcm_space *s, fcm_index elem, const double xi[3],
                                  const double *u, double value[3])
{
  fcm_status st = FCM_OK;
  double N[FCM_ELEMENT_MAX_NODES];
  FCM_CHECK(elem >= 0 && elem < s->num_elems, s->ctx, FCM_ERR_ARG,
            "space eval: element %lld is out of range [0, %lld)", (long long)elem,
            (long long)s->num_elems);
  fcm_element_eval_shape(s->type, xi, N);
  value[0] = value[1] = value[2] = 0.0;
  {
    for (int a = 0; a < s->nn; a++) {
      fcm_index d = s->elem_dof[elem * s->nn + a];
      for (int i = 0; i < 3; i++)
        value[i] += N[a] * u[d + i];
    }
  }
cleanup:
  return st;
}

fcm_status fcm_space_momentum(const fcm_space *s, double density, const double *u, const double *v,
                              double *mass, double linear[3], double angular[3])
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  double m = 0.0, p[3] = {0, 0, 0}, L[3] = {0, 0, 0};
  FCM_CHECK(s, ctx, FCM_ERR_ARG, "momentum: space is NULL");
  FCM_CHECK(isfinite(density) && density >= 0.0, ctx, FCM_ERR_ARG,
            "momentum: density = %g must be finite and >= 0", density);
  FCM_CHECK(!s->rules || fcm_cell_rules_has_kind(s->rules, FCM_RULE_MASS), ctx, FCM_ERR_ARG,
            "momentum: integrates with the mass rules, but the space's cell rules were built "
            "without them (add FCM_RULES_MASS to fcm_cell_rules_options.kinds)");
  const fcm_rule *full = s->mass_rule;
  for (fcm_index e = 0; e < s->num_elems; e++) {
    const fcm_index c = s->elem_cell[e];
    int nq = 0;
    const double *pts = NULL, *w = NULL;
    const unsigned char *fl = NULL;
    if (!fcm__cell_rules_owns(s->rules, c)) continue; /* another process's cell (cell_mask) */
    if (s->rules && fcm_cell_rules_class(s->rules, c) != FCM_CELL_UNCUT) {
      FCM_TRY(ctx, fcm_cell_rules_get_piece(s->rules, s->elem_piece[e], FCM_RULE_MASS, &nq, &pts,
                                            &w, &fl));
    } else {
      nq = fcm_rule_num_points(full);
      pts = fcm_rule_points(full);
      w = fcm_rule_weights(full);
    }
    double X[3 * FCM_ELEMENT_MAX_NODES], J[9], N[FCM_ELEMENT_MAX_NODES];
    fcm_mesh_cell_coords(s->mesh, c, X);
    const fcm_index *ed = s->elem_dof + e * s->nn;
    for (int q = 0; q < nq; q++) {
      if (fl && fl[q]) continue; /* fictitious stabilization points: not the body */
      const double wd = density * w[q] * fcm_element_jacobian(s->type, X, pts + 3 * q, J);
      fcm_element_eval_shape(s->type, pts + 3 * q, N);
      double x[3] = {0, 0, 0}, vq[3] = {0, 0, 0};
      for (int a = 0; a < s->nn; a++)
        for (int i = 0; i < 3; i++) {
          x[i] += N[a] * (X[3 * a + i] + (u ? u[ed[a] + i] : 0.0));
          vq[i] += N[a] * (v ? v[ed[a] + i] : 0.0);
        }
      m += wd;
      for (int i = 0; i < 3; i++)
        p[i] += wd * vq[i];
      L[0] += wd * (x[1] * vq[2] - x[2] * vq[1]);
      L[1] += wd * (x[2] * vq[0] - x[0] * vq[2]);
      L[2] += wd * (x[0] * vq[1] - x[1] * vq[0]);
    }
  }
  if (mass) *mass = m;
  if (linear) memcpy(linear, p, sizeof p);
  if (angular) memcpy(angular, L, sizeof L);
cleanup:
  return st;
}
