/* Shared parts of the surface-path cut tests: a piece's monomial moments and a geometry's
 * boundary as a surface body without a volume mesh. */
#ifndef FCM_TEST_EMBED_CUT_UTIL_H
#define FCM_TEST_EMBED_CUT_UTIL_H

#include "fcm/embed.h"
#include "fcm/surface.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TEST_TRUE_MSG(cond, ...)                                                                   \
  do {                                                                                             \
    if (!(cond)) TEST_FAIL_(__VA_ARGS__);                                                          \
  } while (0)

/* Moments of x^a y^b z^c (a + b + c <= m, each at most the rules' fcm_cell_rules_axis_degree())
 * of piece p's authentic points of kind k; returns their number. */
static inline int piece_monomials(fcm_ctx *ctx, const fcm_cell_rules *r, fcm_index p,
                                  fcm_rule_kind k, int m, double *mom)
{
  int n, M = 0;
  const double *x, *w;
  const unsigned char *fl;
  const int q = fcm_cell_rules_axis_degree(r, k); /* the rules' degree cap per variable */
  TEST_OK(ctx, fcm_cell_rules_get_piece(r, p, k, &n, &x, &w, &fl));
  for (int a = 0; a <= m && a <= q; a++)
    for (int b = 0; a + b <= m && b <= q; b++)
      for (int c = 0; a + b + c <= m && c <= q; c++, M++) {
        double s = 0.0;
        for (int j = 0; j < n; j++)
          if (!fl[j]) s += w[j] * pow(x[3 * j], a) * pow(x[3 * j + 1], b) * pow(x[3 * j + 2], c);
        mom[M] = s;
      }
  return M;
}

/* The boundary of g as a surface geometry without a volume mesh. */
static inline void surface_of(fcm_ctx *ctx, const fcm_geometry *g, fcm_geometry **gs)
{
  const fcm_index nt = fcm_geometry_num_boundary_triangles(g), nv = fcm_geometry_num_nodes(g);
  const fcm_index *t = fcm_geometry_boundary_triangles(g);
  const double *x = fcm_geometry_coords(g);
  fcm_index *id = malloc((size_t)nv * sizeof *id), *tv = malloc(3 * (size_t)nt * sizeof *tv), n = 0;
  double *y = malloc(3 * (size_t)nv * sizeof *y);
  for (fcm_index v = 0; v < nv; v++)
    id[v] = -1;
  for (fcm_index k = 0; k < 3 * nt; k++) {
    if (id[t[k]] < 0) {
      memcpy(y + 3 * n, x + 3 * t[k], 3 * sizeof *y);
      id[t[k]] = n++;
    }
    tv[k] = id[t[k]];
  }
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_surface_create(ctx, n, y, nt, tv, &s));
  fcm_surface_mesh_options mo = fcm_surface_mesh_options_default();
  mo.volume_mesh = 0;
  TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, s, &mo, gs));
  fcm_surface_destroy(&s);
  free(id);
  free(tv);
  free(y);
}

/* The rules of both paths on mesh: the volume geometry gv's (*rv) and those of its boundary as
 * a surface geometry (*gs, *rs), every piece kept (min_fraction 0) and fitted to 1e-14
 * relative residual of its moments. */
static inline void both_paths(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *gv,
                              fcm_geometry **gs, fcm_cell_rules **rv, fcm_cell_rules **rs)
{
  surface_of(ctx, gv, gs);
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0;
  o.simplify_options.residual_tol = 1e-14;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, gv, &o, rv));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, *gs, &o, rs));
}

#endif
