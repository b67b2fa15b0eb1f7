/* Geometric checks of a mesh: positive Jacobian determinant at corners and at
 * caller-given reference points, and the convex / planar-face / straight-edge test. */
#include "mesh_impl.h"
#include "la/vec3.h"

#include <math.h>

fcm_status fcm_mesh_validate(fcm_ctx *ctx, const fcm_mesh *mesh, int num_points,
                             const double *points, double *min_det)
{
  fcm_status st = FCM_OK;
  double mind = HUGE_VAL;
  FCM_CHECK(mesh, ctx, FCM_ERR_ARG, "mesh_validate: mesh must not be NULL");
  FCM_CHECK(num_points >= 0 && (points || num_points == 0), ctx, FCM_ERR_ARG,
            "mesh_validate: num_points = %d must be >= 0, with a non-NULL points array when > 0",
            num_points);
  for (int i = 0; i < 3 * num_points; i++)
    FCM_CHECK(isfinite(points[i]), ctx, FCM_ERR_ARG,
              "mesh_validate: coordinate %d of reference point %d is %g; must be finite", i % 3,
              i / 3, points[i]);
  const fcm_element_type type = mesh->type;
  const fcm_element_info *info = mesh->info;
  const double *ref = fcm_element_ref_nodes(type);
  FCM_CHECK(ref, ctx, FCM_ERR_INTERNAL, "mesh_validate: no reference nodes for %s", info->name);
  const int nc = info->num_corners;
  for (fcm_index c = 0; c < mesh->num_cells; c++) {
    double X[3 * FCM_ELEMENT_MAX_NODES], J[9];
    fcm_mesh_cell_coords(mesh, c, X);
    for (int p = 0; p < nc + num_points; p++) {
      const double *xi = p < nc ? ref + 3 * p : points + 3 * (p - nc);
      double det = fcm_element_jacobian(type, X, xi, J);
      if (det < mind || isnan(det)) mind = det;
      if (!(det > 0)) {
        double x[3];
        fcm_element_map(type, X, xi, x);
        FCM_CHECK(0, ctx, FCM_ERR_GEOMETRY,
                  "mesh: %s cell %lld has det J = %.6g (must be > 0) at %s %d, reference point "
                  "(%g, %g, %g), physical point (%g, %g, %g); the cell is inverted or degenerate",
                  info->name, (long long)c, det, p < nc ? "corner" : "point", p < nc ? p : p - nc,
                  xi[0], xi[1], xi[2], x[0], x[1], x[2]);
      }
    }
  }
cleanup:
  if (min_det) *min_det = mind;
  return st;
}

int fcm_mesh_cell_is_convex(const fcm_mesh *mesh, fcm_index cell, double rtol)
{
  const fcm_element_info *info = mesh->info;
  const int nc = info->num_corners;
  double X[3 * FCM_ELEMENT_MAX_NODES];
  fcm_mesh_cell_coords(mesh, cell, X);

  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (int a = 0; a < nc; a++)
    for (int d = 0; d < 3; d++) {
      lo[d] = FCM_MIN(lo[d], X[3 * a + d]);
      hi[d] = FCM_MAX(hi[d], X[3 * a + d]);
    }
  double diag[3];
  fcm__vec3_sub(hi, lo, diag);
  const double tol = rtol * sqrt(fcm__vec3_dot(diag, diag));

  for (int f = 0; f < info->num_faces; f++) {
    const int fc = info->face_num_corners[f];
    const int *fn = info->face_nodes[f];
    double cen[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    for (int k = 0; k < fc; k++)
      for (int d = 0; d < 3; d++)
        cen[d] += X[3 * fn[k] + d] / fc;
    /* Newell's normal: sum of cross products of consecutive corners about the centroid. */
    for (int k = 0; k < fc; k++) {
      double p[3], q[3];
      fcm__vec3_sub(X + 3 * fn[k], cen, p);
      fcm__vec3_sub(X + 3 * fn[(k + 1) % fc], cen, q);
      n[0] += p[1] * q[2] - p[2] * q[1];
      n[1] += p[2] * q[0] - p[0] * q[2];
      n[2] += p[0] * q[1] - p[1] * q[0];
    }
    const double len = sqrt(fcm__vec3_dot(n, n));
    if (!(len > 0)) return 0;
    for (int d = 0; d < 3; d++)
      n[d] /= len;
    for (int k = 0; k < fc; k++) {
      double p[3];
      fcm__vec3_sub(X + 3 * fn[k], cen, p);
      if (!(fabs(fcm__vec3_dot(n, p)) <= tol)) return 0; /* corner off the face plane */
    }
    for (int a = 0; a < nc; a++) {
      double p[3];
      fcm__vec3_sub(X + 3 * a, cen, p);
      if (!(fcm__vec3_dot(n, p) <= tol)) return 0; /* corner outside the face plane */
    }
  }

  if (info->order > 1) {
    for (int e = 0; e < info->num_edges; e++) {
      const double *p = X + 3 * info->edge_nodes[e][0], *q = X + 3 * info->edge_nodes[e][1];
      const double *m = X + 3 * info->edge_nodes[e][2];
      double pq[3], pm[3], r[3];
      fcm__vec3_sub(q, p, pq);
      fcm__vec3_sub(m, p, pm);
      const double l2 = fcm__vec3_dot(pq, pq);
      if (!(l2 > 0)) return 0;
      const double t = fcm__vec3_dot(pm, pq) / l2;
      for (int d = 0; d < 3; d++)
        r[d] = pm[d] - t * pq[d];
      if (!(sqrt(fcm__vec3_dot(r, r)) <= tol) || !(t > 0.25 && t < 0.75)) return 0;
    }
  }
  return 1;
}

fcm_status fcm_mesh_convex_cells(fcm_ctx *ctx, const fcm_mesh *mesh, double rtol,
                                 unsigned char *is_convex, fcm_index *num_nonconvex)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(mesh, ctx, FCM_ERR_ARG, "mesh_convex_cells: mesh must not be NULL");
  FCM_CHECK(rtol >= 0 && isfinite(rtol), ctx, FCM_ERR_ARG,
            "mesh_convex_cells: rtol = %g must be finite and >= 0", rtol);
  fcm_index bad = 0;
  for (fcm_index c = 0; c < mesh->num_cells; c++) {
    int ok = fcm_mesh_cell_is_convex(mesh, c, rtol);
    if (is_convex) is_convex[c] = (unsigned char)ok;
    bad += !ok;
  }
  if (num_nonconvex) *num_nonconvex = bad;
cleanup:
  return st;
}
