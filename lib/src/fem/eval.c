/* Point evaluation of a field on a space (fcm_space_eval, fcm_space_element_eval) and the
 * body's mass, linear and angular momentum (fcm_space_momentum) from per-element mass blocks
 * integrated once over the authentic points of the mass rules. */
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <omp.h>
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

/* Entries of an element's packed mass block: the upper triangle a <= b, row by row. */
static size_t block_size(int nn)
{
  return (size_t)nn * (size_t)(nn + 1) / 2;
}

/* The mass block of element e with unit density: B[a][b] = sum over the authentic points of
 * w det J N_a N_b (packed, a <= b), zero for an element without points here (another
 * process's cell). */
static fcm_status element_block(const fcm_space *s, fcm_index e, double *B)
{
  fcm_status st = FCM_OK;
  const fcm_index c = s->elem_cell[e];
  const int nn = s->nn;
  int nq = 0;
  const double *pts = NULL, *w = NULL;
  const unsigned char *fl = NULL;
  memset(B, 0, block_size(nn) * sizeof *B);
  if (!fcm__space_owns(s, c)) return FCM_OK; /* another process's cell */
  if (s->rules && fcm_cell_rules_class(s->rules, c) != FCM_CELL_UNCUT) {
    FCM_TRY(s->ctx, fcm_cell_rules_get_piece(s->rules, s->elem_piece[e], FCM_RULE_MASS, &nq, &pts,
                                             &w, &fl));
  } else {
    nq = fcm_rule_num_points(s->mass_rule);
    pts = fcm_rule_points(s->mass_rule);
    w = fcm_rule_weights(s->mass_rule);
  }
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], N[FCM_ELEMENT_MAX_NODES];
  fcm_mesh_cell_coords(s->mesh, c, X);
  for (int q = 0; q < nq; q++) {
    if (fl && fl[q]) continue; /* fictitious stabilization points: not the body */
    const double wd = w[q] * fcm_element_jacobian(s->type, X, pts + 3 * q, J);
    fcm_element_eval_shape(s->type, pts + 3 * q, N);
    double *row = B;
    for (int a = 0; a < nn; a++) {
      const double wa = wd * N[a];
      for (int b = a; b < nn; b++)
        row[b - a] += wa * N[b];
      row += nn - a;
    }
  }
cleanup:
  return st;
}

/* fcm_space_momentum() sums the elements in this many contiguous chunks (threads take whole
 * chunks), then the chunks in order: the result does not depend on the thread count. */
#define MOMENTUM_CHUNKS 64

/* Build the space's mass blocks in parallel over the elements; an element e with same[e] >= 0
 * (same NULL: none) copies block same[e] of from_blocks instead. */
static fcm_status build_blocks(const fcm_space *s, fcm__space_mass_cache *mc, const fcm_index *same,
                               const double *from_blocks)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const size_t nb = block_size(s->nn);
  const fcm_index ne = s->num_elems;
  double *blocks = NULL;
  FCM_ALLOC_RAW(ctx, (size_t)ne * nb + 1, blocks);
  fcm__loop loop;
  fcm__loop_begin(ctx, &loop);
#pragma omp parallel for schedule(dynamic, 16) num_threads(fcm_ctx_num_threads(ctx))
  for (fcm_index e = 0; e < ne; e++) {
    if (fcm__loop_skip(&loop, e)) continue;
    if (same && same[e] >= 0) {
      memcpy(blocks + (size_t)e * nb, from_blocks + (size_t)same[e] * nb, nb * sizeof *blocks);
      continue;
    }
    fcm__loop_iter it;
    fcm__loop_enter(&loop, &it, e);
    fcm__loop_leave(&loop, &it, element_block(s, e, blocks + (size_t)e * nb));
  }
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
  mc->blocks = blocks;
  blocks = NULL;
cleanup:
  fcm__free(ctx, blocks);
  return st;
}

/* Mass, linear and angular momentum (unit density) of elements [e0, e1) into q (m, p, L) from
 * their blocks. The fields are x = sum_a N_a x_a (x_a = X_a + u_a) and v = sum_b N_b v_b, so
 * with (B v)_a = sum_b B_ab v_b the point sums of 1, v and x cross v are m = sum_ab B_ab
 * (sum_a N_a = 1), p = sum_a (B v)_a and L = sum_a x_a cross (B v)_a. */
static void chunk_momentum(const fcm_space *s, const double *blocks, fcm_index e0, fcm_index e1,
                           const double *u, const double *v, double q[7])
{
  const int nn = s->nn;
  const size_t nb = block_size(nn);
  memset(q, 0, 7 * sizeof *q);
  for (fcm_index e = e0; e < e1; e++) {
    const double *B = blocks + (size_t)e * nb;
    const fcm_index *ed = s->elem_dof + e * nn;
    double X[3 * FCM_ELEMENT_MAX_NODES], Bv[3 * FCM_ELEMENT_MAX_NODES], m = 0.0;
    memset(Bv, 0, 3 * (size_t)nn * sizeof *Bv);
    for (int a = 0; a < nn; a++) {
      const double *row = B + (size_t)a * (size_t)(2 * nn - a + 1) / 2;
      m += row[0];
      for (int b = a + 1; b < nn; b++)
        m += 2.0 * row[b - a];
      if (!v) continue;
      const double *va = v + ed[a];
      for (int i = 0; i < 3; i++)
        Bv[3 * a + i] += row[0] * va[i];
      for (int b = a + 1; b < nn; b++) {
        const double *vb = v + ed[b];
        for (int i = 0; i < 3; i++) {
          Bv[3 * a + i] += row[b - a] * vb[i];
          Bv[3 * b + i] += row[b - a] * va[i];
        }
      }
    }
    q[0] += m;
    if (!v) continue;
    fcm_mesh_cell_coords(s->mesh, s->elem_cell[e], X);
    for (int a = 0; a < nn; a++) {
      double x[3];
      for (int i = 0; i < 3; i++)
        x[i] = X[3 * a + i] + (u ? u[ed[a] + i] : 0.0);
      const double *f = Bv + 3 * a;
      for (int i = 0; i < 3; i++)
        q[1 + i] += f[i];
      q[4] += x[1] * f[2] - x[2] * f[1];
      q[5] += x[2] * f[0] - x[0] * f[2];
      q[6] += x[0] * f[1] - x[1] * f[0];
    }
  }
}

fcm_status fcm_space_momentum(const fcm_space *s, double density, const double *u, const double *v,
                              double *mass, double linear[3], double angular[3])
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  double q[7] = {0, 0, 0, 0, 0, 0, 0};
  FCM_CHECK(s, ctx, FCM_ERR_ARG, "momentum: space is NULL");
  FCM_CHECK(isfinite(density) && density >= 0.0, ctx, FCM_ERR_ARG,
            "momentum: density = %g must be finite and >= 0", density);
  FCM_CHECK(!s->rules || fcm_cell_rules_has_kind(s->rules, FCM_RULE_MASS), ctx, FCM_ERR_ARG,
            "momentum: integrates with the mass rules, but the space's cell rules were built "
            "without them (add FCM_RULES_MASS to fcm_cell_rules_options.kinds)");
  fcm__space_mass_cache *mc = s->mass_cache;
  /* the first call builds the blocks; a concurrent first call waits for it */
#pragma omp critical(fcm_space_mass_cache)
  if (!mc->blocks) st = build_blocks(s, mc, NULL, NULL);
  FCM_TRY(ctx, st);
  {
    const fcm_index ne = s->num_elems;
    double sums[7 * MOMENTUM_CHUNKS];
#pragma omp parallel for schedule(static) num_threads(fcm_ctx_num_threads(ctx))
    for (int k = 0; k < MOMENTUM_CHUNKS; k++)
      chunk_momentum(s, mc->blocks, ne * k / MOMENTUM_CHUNKS, ne * (k + 1) / MOMENTUM_CHUNKS, u, v,
                     sums + 7 * k);
    for (int k = 0; k < MOMENTUM_CHUNKS; k++)
      for (int i = 0; i < 7; i++)
        q[i] += sums[7 * k + i];
  }
  if (mass) *mass = density * q[0];
  for (int i = 0; i < 3; i++) {
    if (linear) linear[i] = density * q[1 + i];
    if (angular) angular[i] = density * q[4 + i];
  }
cleanup:
  return st;
}

fcm_status fcm__space_momentum_blocks_from(const fcm_space *s, const fcm_space *from,
                                           const fcm_index *same)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  FCM_CHECK(s && from && same, ctx, FCM_ERR_ARG, "momentum blocks: NULL argument");
  FCM_CHECK(s->nn == from->nn, ctx, FCM_ERR_ARG,
            "momentum blocks: the spaces have %d and %d nodes per cell", s->nn, from->nn);
  if (s->mass_cache->blocks) return FCM_OK;
  st = build_blocks(s, s->mass_cache, from->mass_cache->blocks ? same : NULL,
                    from->mass_cache->blocks);
cleanup:
  return st;
}

double fcm__space_mass_cache_bytes(const fcm_space *s)
{
  return s && s->mass_cache && s->mass_cache->blocks
             ? (double)s->num_elems * (double)block_size(s->nn) * (double)sizeof(double)
             : 0.0;
}

void fcm__space_mass_cache_free(fcm_space *s)
{
  if (!s->mass_cache) return;
  fcm__free(s->ctx, s->mass_cache->blocks);
  FCM_FREE(s->ctx, s->mass_cache);
}
