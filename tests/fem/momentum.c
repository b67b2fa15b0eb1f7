/* fcm_space_momentum() from its per-element mass blocks against the sum over the quadrature
 * points it replaces: a ball embedded in a 3 x 3 x 3 grid (uncut and cut cells, unsimplified
 * and simplified rules with stabilization points), then cut by two planes (XFEM copies and
 * cells split into pieces), with random displacement and velocity on every DOF (so the copies
 * of a node differ). For each space:
 *   - mass, linear and angular momentum equal the sums over the authentic mass-rule points of
 *     rho, rho v and rho x cross v (computed here from the rules, independently of the space's
 *     blocks) to 1e-12 of m, m max|v| and m max|x| max|v|: a lumped or diagonal reduction, or
 *     one counting the stabilization points, is off by far more;
 *   - a second call (blocks kept) and a call on one thread give the same bits;
 *   - u = NULL is the reference position, v = NULL zero momenta with the same mass.
 * Usage: fem_momentum <element> */
#include "fcm/fcm.h"
#include "fem_util.h"

#define RTOL 1e-12

static fcm_ctx *ctx;

/* The sums over the authentic mass-rule points of space s: q = m, p, L. */
static void point_sums(const fcm_space *s, double rho, const double *u, const double *v,
                       double q[7])
{
  const fcm_mesh *mesh = fcm_space_mesh(s);
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const fcm_cell_rules *r = fcm_space_cell_rules(s);
  fcm_rule *full = NULL;
  TEST_OK(ctx, fcm_element_standard_rule(ctx, info->type, FCM_RULE_MASS, FCM_DEFAULT, &full));
  memset(q, 0, 7 * sizeof *q);
  for (fcm_index e = 0; e < fcm_space_num_elements(s) && full; e++) {
    const fcm_index c = fcm_space_element_cell(s, e);
    fcm_index pfirst, efirst;
    fcm_cell_rules_cell_pieces(r, c, &pfirst);
    fcm_space_cell_elements(s, c, &efirst);
    int nq = fcm_rule_num_points(full);
    const double *pts = fcm_rule_points(full), *w = fcm_rule_weights(full);
    const unsigned char *fl = NULL;
    if (fcm_cell_rules_class(r, c) != FCM_CELL_UNCUT)
      TEST_OK(ctx, fcm_cell_rules_get_piece(r, pfirst + (e - efirst), FCM_RULE_MASS, &nq, &pts, &w,
                                            &fl));
    const fcm_index *ed = fcm_space_element_dofs(s, e);
    double X[3 * FCM_ELEMENT_MAX_NODES], J[9], N[FCM_ELEMENT_MAX_NODES];
    fcm_mesh_cell_coords(mesh, c, X);
    for (int k = 0; k < nq; k++) {
      if (fl && fl[k]) continue;
      const double wd = rho * w[k] * fcm_element_jacobian(info->type, X, pts + 3 * k, J);
      double x[3] = {0, 0, 0}, vq[3] = {0, 0, 0};
      fcm_element_eval_shape(info->type, pts + 3 * k, N);
      for (int a = 0; a < info->num_nodes; a++)
        for (int i = 0; i < 3; i++) {
          x[i] += N[a] * (X[3 * a + i] + u[ed[a] + i]);
          vq[i] += N[a] * v[ed[a] + i];
        }
      q[0] += wd;
      for (int i = 0; i < 3; i++) {
        const int j = (i + 1) % 3, l = (i + 2) % 3;
        q[1 + i] += wd * vq[i];
        q[4 + i] += wd * (x[j] * vq[l] - x[l] * vq[j]);
      }
    }
  }
  fcm_rule_destroy(&full);
}

/* One space of rules r: the blocks' momenta against the point sums. */
static void check_space(const fcm_mesh *mesh, const fcm_cell_rules *r, unsigned long long *seed)
{
  const double rho = 870.0;
  fcm_space *s = NULL;
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r, &s));
  if (!s) return;
  const fcm_index nd = fcm_space_num_dofs(s);
  double *u = malloc((size_t)nd * sizeof *u), *v = malloc((size_t)nd * sizeof *v);
  double vmax = 0.0, xmax = 0.0;
  for (fcm_index i = 0; i < nd; i++) {
    u[i] = 0.05 * urand(seed);
    v[i] = 2.0 + urand(seed); /* a drift plus noise: p does not cancel */
    vmax = fmax(vmax, fabs(v[i]));
  }
  for (fcm_index i = 0; i < 3 * fcm_mesh_num_nodes(mesh); i++)
    xmax = fmax(xmax, fabs(fcm_mesh_coords(mesh)[i]) + 0.05);
  double ref[7], m, p[3], L[3];
  point_sums(s, rho, u, v, ref);
  TEST_OK(ctx, fcm_space_momentum(s, rho, u, v, &m, p, L));
  const double sp = ref[0] * vmax, sl = ref[0] * xmax * vmax;
  TEST_NEAR(m, ref[0], RTOL, 0.0);
  for (int i = 0; i < 3; i++) {
    TEST_NEAR(p[i], ref[1 + i], 0.0, RTOL * sp);
    TEST_NEAR(L[i], ref[4 + i], 0.0, RTOL * sl);
  }
  /* the kept blocks, and one thread, give the same bits */
  const int nt = fcm_ctx_num_threads(ctx);
  for (int k = 0; k < 2; k++) {
    double m2, p2[3], L2[3];
    if (k == 1) TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1));
    TEST_OK(ctx, fcm_space_momentum(s, rho, u, v, &m2, p2, L2));
    TEST_TRUE(m2 == m && !memcmp(p2, p, sizeof p) && !memcmp(L2, L, sizeof L));
  }
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, nt));
  /* u NULL: the reference position; v NULL: no momentum, the same mass */
  {
    double m0, p0[3], L0[3];
    double *zero = calloc((size_t)nd, sizeof *zero);
    point_sums(s, rho, zero, v, ref);
    TEST_OK(ctx, fcm_space_momentum(s, rho, NULL, v, &m0, p0, L0));
    for (int i = 0; i < 3; i++) {
      TEST_NEAR(p0[i], ref[1 + i], 0.0, RTOL * sp);
      TEST_NEAR(L0[i], ref[4 + i], 0.0, RTOL * sl);
    }
    TEST_OK(ctx, fcm_space_momentum(s, rho, u, NULL, &m0, p0, L0));
    TEST_TRUE(m0 == m);
    for (int i = 0; i < 3; i++)
      TEST_TRUE(p0[i] == 0.0 && L0[i] == 0.0);
    free(zero);
  }
  free(u), free(v);
  fcm_space_destroy(&s);
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc < 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, ctr[3] = {0.47, 0.52, 0.5};
  const double bl[3] = {-0.5, -0.5, -0.5}, bh[3] = {1.5, 1.5, 1.5};
  const double p1[3] = {0.5, 0.43, 0.5}, n1[3] = {0.2, 1.0, -0.1};
  const double p2[3] = {0.61, 0.5, 0.5}, n2[3] = {1.0, 0.3, 0.25};
  const fcm_index n[3] = {3, 3, 3};
  unsigned long long seed = 29;
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, ctr, 0.44, 2, &g));
  /* unsimplified rules cut twice; simplified rules (Hex20's mass: M = 165, slow) once */
  for (int simplify = 0; simplify < 2 && mesh && g; simplify++) {
    if (simplify && type == FCM_ELEMENT_HEX20) break;
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.simplify = simplify ? FCM_CELL_SIMPLIFY_ON : FCM_CELL_SIMPLIFY_OFF;
    fcm_cell_rules *r[3] = {NULL, NULL, NULL};
    TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r[0]));
    for (int k = 0; k < 2 && r[k]; k++) {
      fcm_surface *cut = NULL;
      TEST_OK(ctx, fcm_surface_create_plane(ctx, k ? p2 : p1, k ? n2 : n1, bl, bh, &cut));
      if (cut) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r[k], cut, &r[k + 1]));
      fcm_surface_destroy(&cut);
    }
    TEST_TRUE(r[2] && fcm_cell_rules_get_stats(r[2])->num_split > 0);
    for (int k = 0; k < 3; k++)
      if (r[k]) check_space(mesh, r[k], &seed);
    for (int k = 0; k < 3; k++)
      fcm_cell_rules_destroy(&r[k]);
  }
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
