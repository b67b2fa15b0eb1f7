/* The cut-tip problem shared by the crack-tip test and its convergence study: the unit cube
 * (E = 1, nu = 0.3) cut by the half-plane crack y = Y0, x < X0 (a rectangle reaching beyond
 * the faces x = 0, z = 0, z = 1), whose straight front x = X0, y = Y0 runs through the body
 * along z. The exact solution is the plane-strain Williams field of the front, mixed mode
 * (K_I = 1, K_II = 0.5), constant along z with u_z = 0: it solves the 3D equations without body
 * force (nothing depends on z, so eps_zz = 0 and sigma_zz = nu (sigma_xx + sigma_yy) is
 * constant along z), and its crack faces (theta = +-pi) are traction-free. The static problem
 * prescribes it on the whole outer boundary (every copy of a boundary node takes the field of
 * its side of the crack) and is solved through the hanging-node constraints, T^T K T. The
 * error is the relative H1 seminorm against the exact field, integrated per side of the crack:
 * every cell is split at y = Y0 and x = X0, each part takes the element of its side (the one
 * piece of a cell the crack does not separate), and parts near the front are split toward it
 * until their distance to the front is at least their size (4^3 Gauss points each), so the
 * r^(-1/2) gradient is integrated accurately. */
#ifndef FCM_TEST_CUTTIP_H
#define FCM_TEST_CUTTIP_H

#include "fem/fem_impl.h"
#include "fem_util.h"

#include <math.h>
#include <stdlib.h>

/* Non-dyadic, so the crack plane and the front lie on no grid plane of the meshes studied. */
#define CUTTIP_X0 0.5
#define CUTTIP_Y0 0.47
#define CUTTIP_PI 3.14159265358979323846
static const double cuttip_E = 1.0, cuttip_nu = 0.3, cuttip_K1 = 1.0, cuttip_K2 = 0.5;

/* The angle around the front on branch `side`: 0 the principal one (theta in (-pi, pi], the
 * branch cut on the crack); +1 the upper side's field continued across the crack below it
 * (theta in (pi, 3pi/2)); -1 the lower side's continued above it (theta in [-3pi/2, -pi],
 * -pi on the crack itself). */
static inline double cuttip_theta(double dx, double dy, int side)
{
  double t = atan2(dy, dx);
  if (side > 0 && dy < 0.0 && dx < 0.0) t += 2.0 * CUTTIP_PI;
  if (side < 0 && dy >= 0.0 && dx < 0.0) t -= 2.0 * CUTTIP_PI; /* on the crack: -pi */
  return t;
}

/* The field u and (G != NULL) its gradient G[3 i + j] = du_i/dx_j at x on branch `side`. */
static inline void cuttip_exact(const double x[3], int side, double u[3], double G[9])
{
  const double mu = cuttip_E / (2.0 * (1.0 + cuttip_nu)), kap = 3.0 - 4.0 * cuttip_nu;
  const double dx = x[0] - CUTTIP_X0, dy = x[1] - CUTTIP_Y0, r = sqrt(dx * dx + dy * dy);
  const double th = cuttip_theta(dx, dy, side), s = sin(0.5 * th), c = cos(0.5 * th);
  const double A = 1.0 / (2.0 * mu * sqrt(2.0 * CUTTIP_PI)), K1 = cuttip_K1, K2 = cuttip_K2;
  /* u = A sqrt(r) g(theta): mode I and mode II angular functions and their derivatives */
  const double gx = K1 * c * (kap - 1.0 + 2.0 * s * s) + K2 * s * (kap + 1.0 + 2.0 * c * c);
  const double gy = K1 * s * (kap + 1.0 - 2.0 * c * c) - K2 * c * (kap - 1.0 - 2.0 * s * s);
  const double dgx = K1 * (-0.5 * s * (kap - 1.0 + 2.0 * s * s) + 2.0 * s * c * c) +
                     K2 * (0.5 * c * (kap + 1.0 + 2.0 * c * c) - 2.0 * s * s * c);
  const double dgy = K1 * (0.5 * c * (kap + 1.0 - 2.0 * c * c) + 2.0 * s * s * c) +
                     K2 * (0.5 * s * (kap - 1.0 - 2.0 * s * s) + 2.0 * s * c * c);
  const double sr = sqrt(r);
  u[0] = A * sr * gx, u[1] = A * sr * gy, u[2] = 0.0;
  if (!G) return;
  for (int k = 0; k < 9; k++)
    G[k] = 0.0;
  if (r == 0.0) return;
  const double ct = cos(th), st = sin(th), g[2] = {gx, gy}, dg[2] = {dgx, dgy};
  for (int i = 0; i < 2; i++) {
    const double ur = A * g[i] / (2.0 * sr), ut = A * sr * dg[i];
    G[3 * i + 0] = ct * ur - st / r * ut;
    G[3 * i + 1] = st * ur + ct / r * ut;
  }
}

/* The box of cell c (corner nodes 0 and 6 of a hexahedron). */
static inline void cuttip_cell_box(const fcm_mesh *m, fcm_index c, double lo[3], double hi[3])
{
  const int npc = fcm_mesh_nodes_per_cell(m);
  const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
  const double *X = fcm_mesh_coords(m);
  for (int d = 0; d < 3; d++)
    lo[d] = X[3 * cn[0] + d], hi[d] = X[3 * cn[6] + d];
}

/* The side of element e (+1 above the crack plane, -1 below, 0 a piece the crack does not
 * separate from the other side: the cells the front passes, and cells beyond it). */
static inline int cuttip_elem_side(const fcm_space *s, fcm_index e)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const fcm_index c = fcm_space_element_cell(s, e);
  double lo[3], hi[3];
  cuttip_cell_box(m, c, lo, hi);
  if (hi[1] <= CUTTIP_Y0) return -1;
  if (lo[1] >= CUTTIP_Y0) return 1;
  fcm_index fe = 0, fp = 0;
  if (fcm_space_cell_elements(s, c, &fe) < 2) return 0;
  const fcm_cell_rules *R = fcm_space_cell_rules(s);
  fcm_cell_rules_cell_pieces(R, c, &fp);
  int np = 0;
  const double *xi = NULL;
  const unsigned char *fict = NULL;
  if (fcm_cell_rules_get_piece(R, fp + (e - fe), FCM_RULE_STIFFNESS, &np, &xi, NULL, &fict) !=
      FCM_OK)
    return 0;
  double best = 0.0;
  for (int q = 0; q < np; q++) {
    if (fict && fict[q]) continue; /* stabilization points fill the whole cell */
    const double y = lo[1] + 0.5 * (xi[3 * q + 1] + 1.0) * (hi[1] - lo[1]);
    if (fabs(y - CUTTIP_Y0) > fabs(best)) best = y - CUTTIP_Y0;
  }
  return best > 0.0 ? 1 : -1;
}

/* The branch of every copy (num_dofs / 3 entries): +1 or -1 when all its elements lie on that
 * side, else 0 (the principal branch). */
static inline void cuttip_copy_branches(const fcm_space *s, int *branch)
{
  const int npc = fcm_mesh_nodes_per_cell(fcm_space_mesh(s));
  const fcm_index nr = fcm_space_num_dofs(s) / 3;
  unsigned char *seen = calloc((size_t)nr, 1);
  for (fcm_index e = 0; e < fcm_space_num_elements(s); e++) {
    const int sd = cuttip_elem_side(s, e);
    const fcm_index *ed = fcm_space_element_dofs(s, e);
    for (int a = 0; a < npc; a++)
      seen[ed[a] / 3] |= sd > 0 ? 1 : sd < 0 ? 2 : 4;
  }
  for (fcm_index r = 0; r < nr; r++)
    branch[r] = seen[r] == 1 ? 1 : seen[r] == 2 ? -1 : 0;
  free(seen);
}

static const double cuttip_gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                    0.8611363115940526};
static const double cuttip_gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                    0.3478548451374538};

/* Adds, over the box [a, b] (inside cell [lo, hi], on one side of the crack) of the element with
 * DOFs ed, the squared H1 seminorms of the error and of the exact field (acc[0], acc[1]) and
 * their energies, the integrals of eps : C eps (acc[2], acc[3]). */
static inline void cuttip_box_error(const fcm_space *s, const fcm_index *ed, const double *u,
                                    const double lo[3], const double hi[3], const double a[3],
                                    const double b[3], int depth, double acc[4])
{
  const double cx = fmin(fabs(a[0] - CUTTIP_X0), fabs(b[0] - CUTTIP_X0)),
               cy = fmin(fabs(a[1] - CUTTIP_Y0), fabs(b[1] - CUTTIP_Y0));
  const double dist = hypot(a[0] < CUTTIP_X0 && b[0] > CUTTIP_X0 ? 0.0 : cx,
                            a[1] < CUTTIP_Y0 && b[1] > CUTTIP_Y0 ? 0.0 : cy);
  const double size = fmax(b[0] - a[0], b[1] - a[1]);
  if (dist < size && depth < 16) {
    const double mx = 0.5 * (a[0] + b[0]), my = 0.5 * (a[1] + b[1]);
    for (int k = 0; k < 4; k++) {
      const double a2[3] = {k & 1 ? mx : a[0], k & 2 ? my : a[1], a[2]};
      const double b2[3] = {k & 1 ? b[0] : mx, k & 2 ? b[1] : my, b[2]};
      cuttip_box_error(s, ed, u, lo, hi, a2, b2, depth + 1, acc);
    }
    return;
  }
  const fcm_element_type type = fcm_mesh_element_type(fcm_space_mesh(s));
  const int npc = fcm_mesh_nodes_per_cell(fcm_space_mesh(s));
  const int side = 0.5 * (a[1] + b[1]) > CUTTIP_Y0 ? 1 : -1;
  const double mu = cuttip_E / (2.0 * (1.0 + cuttip_nu)),
               lam = cuttip_E * cuttip_nu / ((1.0 + cuttip_nu) * (1.0 - 2.0 * cuttip_nu));
  for (int q = 0; q < 64; q++) {
    const int iq[3] = {q % 4, (q / 4) % 4, q / 16};
    double x[3], xi[3], wq = 1.0, dN[3 * FCM_ELEMENT_MAX_NODES], Gh[9] = {0}, Ge[9], ue[3];
    for (int d = 0; d < 3; d++) {
      x[d] = a[d] + 0.5 * (cuttip_gx[iq[d]] + 1.0) * (b[d] - a[d]);
      xi[d] = 2.0 * (x[d] - lo[d]) / (hi[d] - lo[d]) - 1.0;
      wq *= 0.5 * cuttip_gw[iq[d]] * (b[d] - a[d]);
    }
    fcm_element_eval_grad(type, xi, dN);
    for (int n = 0; n < npc; n++)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          Gh[3 * i + j] += u[ed[n] + i] * dN[3 * n + j] * 2.0 / (hi[j] - lo[j]);
    cuttip_exact(x, side, ue, Ge);
    double D[9], tr_d = 0.0, tr_e = 0.0, dd = 0.0, ee = 0.0;
    for (int k = 0; k < 9; k++) {
      D[k] = Gh[k] - Ge[k];
      acc[0] += wq * D[k] * D[k], acc[1] += wq * Ge[k] * Ge[k];
    }
    for (int i = 0; i < 3; i++) {
      tr_d += D[4 * i], tr_e += Ge[4 * i];
      for (int j = 0; j < 3; j++) {
        const double sd = 0.5 * (D[3 * i + j] + D[3 * j + i]);
        const double se = 0.5 * (Ge[3 * i + j] + Ge[3 * j + i]);
        dd += sd * sd, ee += se * se;
      }
    }
    acc[2] += wq * (lam * tr_d * tr_d + 2.0 * mu * dd);
    acc[3] += wq * (lam * tr_e * tr_e + 2.0 * mu * ee);
  }
}

/* The relative errors of u (all DOFs of the cut space s): err[0] in the H1 seminorm, err[1] in
 * the energy norm. */
static inline void cuttip_errors(const fcm_space *s, const double *u, double err[2])
{
  const fcm_mesh *m = fcm_space_mesh(s);
  double acc[4] = {0.0, 0.0, 0.0, 0.0};
  for (fcm_index c = 0; c < fcm_mesh_num_cells(m); c++) {
    double lo[3], hi[3];
    cuttip_cell_box(m, c, lo, hi);
    fcm_index fe = 0;
    const fcm_index ne = fcm_space_cell_elements(s, c, &fe);
    int eside[2] = {0, 0};
    for (fcm_index k = 0; k < ne && k < 2; k++)
      eside[k] = cuttip_elem_side(s, fe + k);
    const double xs[3] = {lo[0], fmin(fmax(CUTTIP_X0, lo[0]), hi[0]), hi[0]};
    const double ys[3] = {lo[1], fmin(fmax(CUTTIP_Y0, lo[1]), hi[1]), hi[1]};
    for (int i = 0; i < 2; i++)
      for (int j = 0; j < 2; j++) {
        if (xs[i + 1] <= xs[i] || ys[j + 1] <= ys[j]) continue;
        const int side = j ? 1 : -1;
        const fcm_index e = ne == 2 && eside[1] == side ? fe + 1 : fe;
        const double a[3] = {xs[i], ys[j], lo[2]}, b[3] = {xs[i + 1], ys[j + 1], hi[2]};
        cuttip_box_error(s, fcm_space_element_dofs(s, e), u, lo, hi, a, b, 0, acc);
      }
  }
  err[0] = sqrt(acc[0] / acc[1]), err[1] = sqrt(acc[2] / acc[3]);
}

/* Octree refinement toward the front: a cell of size h at distance d from the front is split
 * while h > c max(d, h)^(3/5), c = *(double *)user. The grading h = c r^(3/5) equidistributes
 * the Hex8 interpolation error of the r^(1/2) field (h^5 r^-3 per cell) down to the cells at
 * the front, of size c^(5/2). */
static inline int cuttip_near_front(const double lo[3], const double hi[3], int level, void *user)
{
  (void)level;
  const double c = *(const double *)user, h = hi[0] - lo[0];
  const double dx = fmax(fmax(lo[0] - CUTTIP_X0, CUTTIP_X0 - hi[0]), 0.0);
  const double dy = fmax(fmax(lo[1] - CUTTIP_Y0, CUTTIP_Y0 - hi[1]), 0.0);
  return h > c * pow(fmax(hypot(dx, dy), h), 0.6);
}

/* Cut rules of the crack on mesh m (body: the unit cube). */
static inline fcm_status cuttip_rules(fcm_ctx *ctx, const fcm_mesh *m, fcm_cell_rules **out)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, xmin = -0.3;
  const double center[3] = {0.5 * (xmin + CUTTIP_X0), CUTTIP_Y0, 0.5}, normal[3] = {0, 1, 0};
  const double axis[3] = {1, 0, 0}, size[2] = {CUTTIP_X0 - xmin, 1.6};
  const fcm_index n1[3] = {1, 1, 1};
  fcm_geometry *body = NULL;
  fcm_surface *crack = NULL;
  fcm_cell_rules *r0 = NULL;
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  fcm_status st = fcm_geometry_create_box(ctx, lo, hi, n1, &body);
  if (st == FCM_OK) st = fcm_surface_create_rectangle(ctx, center, normal, axis, size, &crack);
  if (st == FCM_OK) st = fcm_cell_rules_create(ctx, m, body, &ro, &r0);
  if (st == FCM_OK) st = fcm_cell_rules_create_cut(ctx, m, body, r0, crack, out);
  fcm_cell_rules_destroy(&r0);
  fcm_surface_destroy(&crack);
  fcm_geometry_destroy(&body);
  return st;
}

/* The cut-tip problem on mesh m: the reduced system's size (hanging copies eliminated, boundary
 * DOFs included), the relative errors of cuttip_errors() (error[2]), (interp != NULL) those of
 * the interpolant in the constrained space (every free copy at the exact field of its branch,
 * the hanging ones following: u = T v) and (eta != NULL) the stress-jump indicator per cell. */
static inline fcm_status cuttip_solve(fcm_ctx *ctx, const fcm_mesh *m, fcm_index *nfree,
                                      double error[2], double interp[2], double *eta)
{
  fcm_cell_rules *R = NULL;
  fcm_space *s = NULL;
  fcm_csr *K = NULL, *T = NULL, *Kr = NULL;
  fcm_index *free_dof = NULL, nr = 0;
  double *b = NULL, *g = NULL, *v = NULL, *u = NULL;
  int *branch = NULL;
  unsigned char *con = NULL;
  fcm_material mat = {FCM_MATERIAL_LINEAR, cuttip_E, cuttip_nu, 1.0};
  fcm_status st = cuttip_rules(ctx, m, &R);
  if (st == FCM_OK) st = fcm_space_create_embedded(ctx, m, R, &s);
  const fcm_index n = st == FCM_OK ? fcm_space_num_dofs(s) : 0;
  if (st == FCM_OK) {
    free_dof = malloc(sizeof *free_dof * (size_t)n);
    branch = malloc(sizeof *branch * (size_t)(n / 3));
    st = fcm_space_hanging_matrix_create(s, free_dof, &T);
  }
  if (st == FCM_OK) st = fcm_space_matrix_create(s, &K);
  if (st == FCM_OK) st = fcm_assemble_stiffness(s, &mat, NULL, K);
  if (st == FCM_OK) st = fcm_csr_create_ptap(ctx, K, T, &Kr);
  if (st != FCM_OK) goto done;
  fcm_csr_get_size(Kr, &nr, NULL, NULL);
  b = calloc((size_t)nr, sizeof *b), g = calloc((size_t)nr, sizeof *g);
  v = calloc((size_t)nr, sizeof *v), u = calloc((size_t)n, sizeof *u);
  con = calloc((size_t)nr, 1);
  cuttip_copy_branches(s, branch);
  const double *X = fcm_mesh_coords(m);
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(m); a++) {
    const fcm_index d0 = fcm_space_node_dof(s, a);
    int bnd = 0;
    for (int d = 0; d < 3; d++)
      bnd |= X[3 * a + d] == 0.0 || X[3 * a + d] == 1.0;
    for (fcm_index k = 0; d0 >= 0 && k < fcm_space_node_copies(s, a); k++) {
      const fcm_index dk = d0 + 3 * k;
      if (free_dof[dk] < 0) continue;
      double ue[3];
      cuttip_exact(X + 3 * a, branch[dk / 3], ue, NULL);
      for (int i = 0; i < 3; i++)
        con[free_dof[dk + i]] = (unsigned char)bnd, g[free_dof[dk + i]] = ue[i];
    }
  }
  if (interp) {
    st = fcm_csr_apply(T, 1.0, g, 0.0, u);
    if (st != FCM_OK) goto done;
    cuttip_errors(s, u, interp);
  }
  for (fcm_index i = 0; i < nr; i++)
    if (!con[i]) g[i] = 0.0;
  fcm__eliminate_marked(Kr, b, con, g);
  st = direct_solve(ctx, Kr, b, v);
  if (st == FCM_OK) st = fcm_csr_apply(T, 1.0, v, 0.0, u);
  if (st == FCM_OK) {
    *nfree = nr;
    cuttip_errors(s, u, error);
    if (eta) st = fcm_space_stress_jumps(s, &mat, u, eta);
  }
done:
  free(b), free(g), free(v), free(u), free(con), free(free_dof), free(branch);
  fcm_csr_destroy(&Kr);
  fcm_csr_destroy(&T);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&s);
  fcm_cell_rules_destroy(&R);
  return st;
}

#endif
