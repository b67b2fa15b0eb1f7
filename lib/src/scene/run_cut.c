/* Cuts a host applies between steps (fcm_simulation_cut()): the blade taken as it is (the
 * body at rest) or carried back from the deformed body, then the scene's own cut
 * (fcm__sim_cut_along(), run.c). */
#include "scene/run_impl.h"
#include "scene/scene_impl.h"

#include "core/core_impl.h"
#include "la/mat3.h"
#include "embed/embed_impl.h"
#include "sim/sim_backend.h"
#include "fcm/element.h"
#include "fcm/fem.h"
#include "fcm/geom.h"
#include "fcm/mesh.h"

#include <math.h>
#include <string.h>

/* Reference coordinates within this much of the element count as inside it: a blade vertex
 * on a face shared by two elements is taken by the first (ascending) that holds it. */
#define INSIDE_TOL 1e-9

static int inside_reference(fcm_shape shape, const double xi[3])
{
  if (shape == FCM_SHAPE_HEX) {
    for (int d = 0; d < 3; d++)
      if (!(fabs(xi[d]) <= 1.0 + INSIDE_TOL)) return 0;
    return 1;
  }
  return xi[0] >= -INSIDE_TOL && xi[1] >= -INSIDE_TOL && xi[2] >= -INSIDE_TOL &&
         xi[0] + xi[1] + xi[2] <= 1.0 + INSIDE_TOL;
}

/* The deformed positions x_a = X_a + u_a of element e's nodes (its cell's nodes, the copies
 * the element uses) into x, its cell's rest positions into X. */
static void element_nodes(const fcm_space *space, const fcm_mesh *mesh, const double *u, int nn,
                          fcm_index e, double *X, double *x)
{
  const fcm_index *dof = fcm_space_element_dofs(space, e);
  fcm_mesh_cell_coords(mesh, fcm_space_element_cell(space, e), X);
  for (int a = 0; a < nn; a++)
    for (int d = 0; d < 3; d++)
      x[3 * a + d] = X[3 * a + d] + u[dof[a] + d];
}

/* The rest position X of the point p of the deformed body by the affine motion of element e
 * at its reference centre c: X = X(c) + (dX/dxi) (dx/dxi)^-1 (p - x(c)), which an affine
 * motion of the element gives exactly; far from the element a trilinear map's own
 * extrapolation may fold over, this does not. */
static fcm_status affine_back(fcm_simulation *S, fcm_element_type type,
                              const fcm_element_info *info, int nn, fcm_index e, const double p[3],
                              double X0[3])
{
  fcm_status st = FCM_OK;
  double X[3 * FCM_ELEMENT_MAX_NODES], x[3 * FCM_ELEMENT_MAX_NODES], JX[9], Jx[9], Jxi[9] = {0};
  double c[3] = {0.0, 0.0, 0.0}, xc[3], d[3], dxi[3];
  if (info->shape != FCM_SHAPE_HEX) c[0] = c[1] = c[2] = 0.25;
  element_nodes(S->space, S->mesh, fcm_integrator_displacement(S->integ), nn, e, X, x);
  fcm_element_jacobian(type, X, c, JX);
  fcm_element_jacobian(type, x, c, Jx);
  const double det = fcm__mat3_inv(Jx, Jxi);
  FCM_CHECK(det > 0.0 && isfinite(det), S->ctx, FCM_ERR_GEOMETRY,
            "simulation %s: the point (%g, %g, %g) lies in no element of the deformed body, and "
            "the element nearest to it (%lld) is inverted (det J = %g): it cannot be carried "
            "back",
            fcm_scene_name(S->scene), p[0], p[1], p[2], (long long)e, det);
  fcm_element_map(type, x, c, xc);
  fcm_element_map(type, X, c, X0);
  for (int k = 0; k < 3; k++)
    d[k] = p[k] - xc[k];
  fcm__mat3_mulv(Jxi, d, dxi);
  for (int k = 0; k < 3; k++)
    X0[k] += JX[3 * k] * dxi[0] + JX[3 * k + 1] * dxi[1] + JX[3 * k + 2] * dxi[2];
cleanup:
  return st;
}

/* The points p (nv of them) of the deformed body (x = X + u of the current space and
 * displacement) carried back to the rest positions of the material points they lie on, into
 * rest: each point goes to the first element (ascending) whose deformed map reaches it at
 * reference coordinates that lie in the element's cell, and in a cell that cuts split, in the
 * element's piece (fcm_space_point_element(): the piece of the nearest authentic quadrature
 * point); a point in no such element (beyond the mesh's active cells, where a blade usually
 * starts and ends) goes by the affine motion of the element whose deformed node centroid is
 * nearest, taken at its centre (affine_back(); a scan of the elements per such point). */
static fcm_status rest_positions(fcm_simulation *S, fcm_index nv, const double *p, double *rest)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_space *space = S->space;
  const fcm_mesh *mesh = S->mesh;
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  const fcm_element_info *info = fcm_element_get_info(type);
  const int nn = info->num_nodes;
  const fcm_index ne = fcm_space_num_elements(space);
  const double *u = fcm_integrator_displacement(S->integ);
  double *box = NULL, *cen = NULL, X[3 * FCM_ELEMENT_MAX_NODES], x[3 * FCM_ELEMENT_MAX_NODES];
  fcm_index *ids = NULL, cap = 64;
  fcm_aabb_tree *tree = NULL;
  FCM_CHECK(ne > 0, ctx, FCM_ERR_GEOMETRY,
            "simulation %s: the body has no elements to carry points back through",
            fcm_scene_name(S->scene));
  FCM_ALLOC_RAW(ctx, 6 * (size_t)ne, box);
  FCM_ALLOC_RAW(ctx, 3 * (size_t)ne, cen);
  FCM_ALLOC_RAW(ctx, (size_t)cap, ids);
  for (fcm_index e = 0; e < ne; e++) {
    double *b = box + 6 * e, size = 0.0;
    element_nodes(space, mesh, u, nn, e, X, x);
    for (int d = 0; d < 3; d++) {
      b[d] = HUGE_VAL, b[3 + d] = -HUGE_VAL, cen[3 * e + d] = 0.0;
      for (int a = 0; a < nn; a++) {
        b[d] = fmin(b[d], x[3 * a + d]), b[3 + d] = fmax(b[3 + d], x[3 * a + d]);
        cen[3 * e + d] += x[3 * a + d] / nn;
      }
      size = fmax(size, b[3 + d] - b[d]);
    }
    FCM_CHECK(isfinite(size), ctx, FCM_ERR_NUMERIC,
              "simulation %s: element %lld's deformed nodes are not finite",
              fcm_scene_name(S->scene), (long long)e);
    for (int d = 0; d < 3; d++) /* a curved deformed face may bulge past its nodes' box */
      b[d] -= 0.25 * size, b[3 + d] += 0.25 * size;
  }
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, ne, box, &tree));
  for (fcm_index i = 0; i < nv; i++) {
    const double *pi = p + 3 * i;
    double xi[3];
    fcm_index count = 0, found = -1;
    for (;;) {
      FCM_TRY(ctx, fcm_aabb_tree_query(tree, pi, pi, cap, ids, &count));
      if (count <= cap) break;
      cap = count;
      fcm__free(ctx, ids);
      ids = NULL;
      FCM_ALLOC_RAW(ctx, (size_t)cap, ids);
    }
    for (fcm_index k = 0; k < count && found < 0; k++) {
      const fcm_index e = ids[k];
      element_nodes(space, mesh, u, nn, e, X, x);
      if (fcm_element_inverse_map(NULL, type, x, pi, xi) != FCM_OK) continue;
      if (inside_reference(info->shape, xi) &&
          fcm_space_point_element(space, fcm_space_element_cell(space, e), xi) == e)
        found = e;
    }
    if (found < 0) { /* in no element's material: the nearest element's motion at its centre */
      double best = HUGE_VAL;
      for (fcm_index e = 0; e < ne; e++) {
        double r2 = 0.0;
        for (int d = 0; d < 3; d++)
          r2 += (cen[3 * e + d] - pi[d]) * (cen[3 * e + d] - pi[d]);
        if (r2 < best) best = r2, found = e;
      }
      FCM_TRY(ctx, affine_back(S, type, info, nn, found, pi, rest + 3 * i));
      continue;
    }
    fcm_element_map(type, X, xi, rest + 3 * i); /* X: the found element's cell, from the search */
  }
cleanup:
  fcm_aabb_tree_destroy(&tree);
  fcm__free(ctx, box);
  fcm__free(ctx, cen);
  fcm__free(ctx, ids);
  return st;
}

/* The blade's vertices carried back (rest_positions()); the triangles are the blade's. */
static fcm_status pull_back(fcm_simulation *S, const fcm_surface *blade, fcm_surface **out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_index nv = fcm_surface_num_vertices(blade);
  double *rest = NULL;
  FCM_ALLOC_RAW(ctx, 3 * (size_t)nv, rest);
  FCM_TRY(ctx, rest_positions(S, nv, fcm_surface_coords(blade), rest));
  FCM_TRY(ctx, fcm_surface_create(ctx, nv, rest, fcm_surface_num_triangles(blade),
                                  fcm_surface_triangles(blade), out));
cleanup:
  fcm__free(ctx, rest);
  return st;
}

fcm_status fcm_simulation_rest_positions(fcm_simulation *S, fcm_index n, const double *x, double *X)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(S && n >= 0 && (n == 0 || (x && X)), S ? S->ctx : NULL, FCM_ERR_ARG,
            "simulation: rest_positions needs a simulation, n >= 0 (got %lld) and both arrays",
            (long long)n);
  fcm_ctx *ctx = S->ctx;
  FCM_CHECK(!fcm__integrator_distributed(S->integ, NULL), ctx, FCM_ERR_UNSUPPORTED,
            "simulation %s: rest_positions: a distributed run holds only its own part of the "
            "deformed body",
            fcm_scene_name(S->scene));
  for (fcm_index i = 0; i < 3 * n; i++)
    FCM_CHECK(isfinite(x[i]), ctx, FCM_ERR_ARG,
              "simulation %s: rest_positions: point %lld is not finite (component %d: %g)",
              fcm_scene_name(S->scene), (long long)(i / 3), (int)(i % 3), x[i]);
  if (n > 0) FCM_TRY(ctx, rest_positions(S, n, x, X));
cleanup:
  return st;
}

fcm_status fcm_simulation_cut(fcm_simulation *S, const fcm_surface *blade, fcm_cut_frame frame,
                              fcm_cut_info *info)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(S && blade, S ? S->ctx : NULL, FCM_ERR_ARG,
            "simulation: cut needs a simulation and a blade");
  fcm_ctx *ctx = S->ctx;
  fcm_surface *rest = NULL;
  const fcm_simulation_counters c0 = S->c;
  const double t0 = fcm_wtime();
  const fcm_index n0 = fcm_space_num_dofs(S->space);
  if (info) memset(info, 0, sizeof *info);
  FCM_CHECK(frame == FCM_CUT_FRAME_REFERENCE || frame == FCM_CUT_FRAME_DEFORMED, ctx, FCM_ERR_ARG,
            "simulation %s: cut: frame %d is not FCM_CUT_FRAME_REFERENCE (0) or "
            "FCM_CUT_FRAME_DEFORMED (1)",
            fcm_scene_name(S->scene), (int)frame);
  FCM_CHECK(S->rules, ctx, FCM_ERR_ARG,
            "simulation %s: cut: the scene has no embedded geometry (\"geometry\"): cuts split "
            "the embedded body",
            fcm_scene_name(S->scene));
  FCM_CHECK(!fcm_scene_get_background(S->scene)->octree_cuts_at_cut, ctx, FCM_ERR_UNSUPPORTED,
            "simulation %s: cut: the background is refined along the scene's cuts when the "
            "first is applied (\"octree\": {\"cuts\": {\"when\": \"cut\"}}), which cannot "
            "know a blade given later: refine along the cuts at the set-up instead",
            fcm_scene_name(S->scene));
  FCM_CHECK(frame == FCM_CUT_FRAME_REFERENCE || !fcm__integrator_distributed(S->integ, NULL), ctx,
            FCM_ERR_UNSUPPORTED,
            "simulation %s: cut: a distributed run holds only its own part of the deformed "
            "body; give the blade in the reference frame (FCM_CUT_FRAME_REFERENCE)",
            fcm_scene_name(S->scene));
  FCM_TRY(ctx, fcm__embed_cut_check(ctx, blade, "simulation: cut: the blade"));
  if (frame == FCM_CUT_FRAME_DEFORMED) FCM_TRY(ctx, pull_back(S, blade, &rest));
  const fcm_space *before = S->space;
  st = fcm__sim_cut_along(S, rest ? rest : blade, fcm_integrator_time(S->integ), t0);
  if (st != FCM_OK && S->space == before) {
    S->c = c0; /* the run is as it was: its counters too */
    goto cleanup;
  }
  /* the body is cut (a failure after the new space took over, e.g. the log's blocks, still
   * leaves it cut): counted, and kept out of checkpoints */
  S->api_cuts++;
  const double seconds = fcm_wtime() - t0;
  fcm__sim_count_cut(S, seconds);
  if (st != FCM_OK) goto cleanup;
  if (info) {
    const fcm_cell_rules_stats *r = &S->cut_stats[S->c.cuts - 1];
    info->missed = S->c.cuts_missed > c0.cuts_missed;
    info->dofs_before = n0;
    info->dofs_after = fcm_space_num_dofs(S->space);
    info->cells_integrated = r->num_integrated;
    info->seconds = seconds;
    info->seconds_rules = S->cut_phase[0];
    info->seconds_space = S->cut_phase[1];
    info->seconds_integrator = S->cut_phase[2];
    info->seconds_solver = S->cut_phase[3];
  }
cleanup:
  fcm_surface_destroy(&rest);
  return st;
}
