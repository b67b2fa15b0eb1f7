/* Output fields of a solution: an affine displacement u = G X + t (which every element
 * reproduces, also on distorted cells) has a constant F = I + G, so the Cauchy stress, von
 * Mises stress and strain energy density are the analytic constants of the model (linear,
 * St. Venant-Kirchhoff, Stable Neo-Hookean; formulas written out here) at every point and as
 * every cell average, cut cells of an embedded ball included; node fields are G X_a + t;
 * the largest |u| of a translation is |t|; the VTU files hold the reference positions
 * (mesh nodes, the geometry's boundary vertices) and the arrays. After a plane cut, a node
 * with two copies shows the one of the larger support, and both sides of every cut face are
 * written, each moving with its own body. */
#include "fem_util.h"
#include "../io/vtk_reader.h"
#include "la/mat3.h"

#include <stdint.h>

static fcm_ctx *ctx;

static const double G[9] = {0.08, 0.02, -0.03, 0.04, -0.05, 0.01, 0.0, 0.05, 0.06};
static const double T[3] = {0.3, -0.2, 0.1};

static void mat3_mul(const double A[9], const double B[9], double C[9])
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* The analytic Cauchy stress (VTK order), von Mises stress and Psi(F) - Psi(I) of F = I + G. */
static void analytic(const fcm_material *m, double sig[6], double *vm, double *sed)
{
  const double mu = m->young / (2 * (1 + m->poisson));
  const double lam = m->young * m->poisson / ((1 + m->poisson) * (1 - 2 * m->poisson));
  double F[9], Ft[9], c[9], S[9], tmp[9];
  for (int k = 0; k < 9; k++)
    F[k] = G[k] + (k % 4 == 0);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      Ft[3 * i + j] = F[3 * j + i];
  const double J = fcm__mat3_det(F);
  double psi = 0.0;
  if (m->model == FCM_MATERIAL_LINEAR) {
    double eps[9], tr = G[0] + G[4] + G[8], ee = 0.0;
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        eps[3 * i + j] = 0.5 * (G[3 * i + j] + G[3 * j + i]);
    for (int k = 0; k < 9; k++)
      c[k] = 2 * mu * eps[k] + (k % 4 == 0) * lam * tr, ee += eps[k] * eps[k];
    psi = mu * ee + 0.5 * lam * tr * tr;
  } else if (m->model == FCM_MATERIAL_STVK) {
    double C[9], E[9], EE = 0.0;
    mat3_mul(Ft, F, C);
    for (int k = 0; k < 9; k++)
      E[k] = 0.5 * (C[k] - (k % 4 == 0)), EE += E[k] * E[k];
    const double tr = E[0] + E[4] + E[8];
    for (int k = 0; k < 9; k++)
      S[k] = 2 * mu * E[k] + (k % 4 == 0) * lam * tr;
    mat3_mul(F, S, tmp);
    mat3_mul(tmp, Ft, c);
    for (int k = 0; k < 9; k++)
      c[k] /= J;
    psi = mu * EE + 0.5 * lam * tr * tr;
  } else { /* Stable Neo-Hookean */
    const double mup = 4.0 * mu / 3.0, lamp = lam + 5.0 * mu / 6.0;
    const double alpha = 1.0 + 3.0 * mup / (4.0 * lamp);
    double Ic = 0.0, cof[9], P[9];
    for (int k = 0; k < 9; k++)
      Ic += F[k] * F[k];
    cof[0] = F[4] * F[8] - F[5] * F[7], cof[1] = F[5] * F[6] - F[3] * F[8];
    cof[2] = F[3] * F[7] - F[4] * F[6], cof[3] = F[2] * F[7] - F[1] * F[8];
    cof[4] = F[0] * F[8] - F[2] * F[6], cof[5] = F[1] * F[6] - F[0] * F[7];
    cof[6] = F[1] * F[5] - F[2] * F[4], cof[7] = F[2] * F[3] - F[0] * F[5];
    cof[8] = F[0] * F[4] - F[1] * F[3];
    for (int k = 0; k < 9; k++)
      P[k] = mup * (1 - 1 / (Ic + 1)) * F[k] + lamp * (J - alpha) * cof[k];
    mat3_mul(P, Ft, c);
    for (int k = 0; k < 9; k++)
      c[k] /= J;
    psi = 0.5 * mup * (Ic - 3) - 0.5 * mup * log(Ic + 1) + 0.5 * lamp * (J - alpha) * (J - alpha);
    psi -= -0.5 * mup * log(4.0) + 0.5 * lamp * (1 - alpha) * (1 - alpha);
  }
  sig[0] = c[0], sig[1] = c[4], sig[2] = c[8];
  sig[3] = c[1], sig[4] = c[5], sig[5] = c[2];
  const double a = sig[0] - sig[1], b = sig[1] - sig[2], d = sig[2] - sig[0];
  *vm = sqrt(0.5 * (a * a + b * b + d * d) +
             3 * (sig[3] * sig[3] + sig[4] * sig[4] + sig[5] * sig[5]));
  *sed = psi;
}

/* u = G X + t at every DOF copy of every node. */
static double *affine_field(const fcm_space *space)
{
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const double *X = fcm_mesh_coords(mesh);
  double *u = calloc((size_t)fcm_space_num_dofs(space) + 1, sizeof *u);
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++) {
    const fcm_index d0 = fcm_space_node_dof(space, a);
    for (fcm_index k = 0; d0 >= 0 && k < fcm_space_node_copies(space, a); k++)
      for (int i = 0; i < 3; i++)
        u[d0 + 3 * k + i] =
            T[i] + G[3 * i] * X[3 * a] + G[3 * i + 1] * X[3 * a + 1] + G[3 * i + 2] * X[3 * a + 2];
  }
  return u;
}

static void check_stress(const double *sig, double vm, double sed, const double *s0, double vm0,
                         double sed0)
{
  const double scale = vm0 + fabs(s0[0]) + fabs(s0[1]) + fabs(s0[2]);
  for (int k = 0; k < 6; k++)
    TEST_NEAR(sig[k], s0[k], 0, 1e-10 * scale);
  TEST_NEAR(vm, vm0, 1e-10, 0);
  TEST_NEAR(sed, sed0, 1e-10, 0);
}

/* Every material: cell averages (active cells; inactive 0) and point values are analytic. */
static void stress_checks(const fcm_space *space, const double *u, const fcm_embedded_surface *es)
{
  static const fcm_material_model models[3] = {FCM_MATERIAL_LINEAR, FCM_MATERIAL_STVK,
                                               FCM_MATERIAL_STABLE_NEO_HOOKEAN};
  const fcm_index nc = fcm_mesh_num_cells(fcm_space_mesh(space));
  double *sig = malloc(sizeof *sig * 6 * (size_t)nc), *vm = malloc(sizeof *vm * (size_t)nc);
  double *sed = malloc(sizeof *sed * (size_t)nc);
  for (int m = 0; m < 3; m++) {
    const fcm_material mat = {models[m], 2.0e5, 0.3, 1000.0};
    double s0[6], vm0, sed0;
    analytic(&mat, s0, &vm0, &sed0);
    TEST_OK(ctx, fcm_space_cell_stress(space, &mat, u, sig, vm, sed));
    for (fcm_index c = 0; c < nc; c++) {
      if (fcm_space_cell_active(space, c))
        check_stress(sig + 6 * c, vm[c], sed[c], s0, vm0, sed0);
      else
        TEST_TRUE(vm[c] == 0.0 && sed[c] == 0.0 && sig[6 * c] == 0.0);
    }
    const fcm_index ne = fcm_space_num_elements(space);
    for (fcm_index e = 0; e < ne; e += 1 + ne / 7) {
      const double xi[3] = {0.2, 0.3, 0.1};
      double ps[6], pv, pe;
      TEST_OK(ctx, fcm_space_element_stress(space, &mat, e, xi, u, ps, &pv, &pe));
      check_stress(ps, pv, pe, s0, vm0, sed0);
    }
    if (es) {
      const fcm_index np = fcm_embedded_surface_num_points(es);
      double *ps = malloc(sizeof *ps * 6 * (size_t)np), *pv = malloc(sizeof *pv * (size_t)np);
      double *pe = malloc(sizeof *pe * (size_t)np);
      TEST_OK(ctx, fcm_embedded_surface_stress(es, &mat, u, ps, pv, pe));
      for (fcm_index i = 0; i < np; i++)
        check_stress(ps + 6 * i, pv[i], pe[i], s0, vm0, sed0);
      free(ps), free(pv), free(pe);
    }
  }
  free(sig), free(vm), free(sed);
}

/* Float64 array `name` of `parent` in a VTU file: its values (malloc'ed) and count. */
static double *read_array(const char *path, const char *parent, const char *name, size_t *count)
{
  vr_doc d;
  double *out = NULL;
  *count = 0;
  if (!vr_load(&d, path)) return NULL;
  if (vr_parse_vtu(&d)) {
    const vr_tag *t = vr_data_array(&d, parent, name);
    if (t) {
      uint64_t bytes = 0;
      const unsigned char *p = vr_array(&d, t, &bytes);
      out = malloc(bytes + 1);
      memcpy(out, p, bytes);
      *count = bytes / sizeof(double);
    }
  }
  vr_free(&d);
  return out;
}

/* `name`: the element's, so that the tests of the four elements, which may run at once, write
 * apart. */
static void plain(fcm_element_type type, const char *name)
{
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  TEST_OK(ctx, distorted_box(ctx, type, 3, 0.15, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  if (!space) goto done;
  double *u = affine_field(space);
  stress_checks(space, u, NULL);
  /* node field: G X + t at every node */
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  double *nf = malloc(sizeof *nf * 3 * (size_t)nn);
  TEST_OK(ctx, fcm_space_node_field(space, u, nf));
  for (fcm_index a = 0; a < nn; a++)
    for (int i = 0; i < 3; i++)
      TEST_NEAR(nf[3 * a + i],
                T[i] + G[3 * i] * X[3 * a] + G[3 * i + 1] * X[3 * a + 1] +
                    G[3 * i + 2] * X[3 * a + 2],
                0, 1e-14);
  /* a translation: max |u| = |t| */
  double *tr = malloc(sizeof *tr * (size_t)fcm_space_num_dofs(space)), mx = 0.0;
  for (fcm_index i = 0; i < fcm_space_num_dofs(space); i++)
    tr[i] = T[i % 3];
  TEST_OK(ctx, fcm_space_max_displacement(space, tr, &mx));
  TEST_NEAR(mx, sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]), 1e-14, 0);
  /* the VTU: reference positions, node displacements, cell stress */
  const fcm_material mat = {FCM_MATERIAL_STVK, 2.0e5, 0.3, 1000.0};
  double s0[6], vm0, sed0;
  analytic(&mat, s0, &vm0, &sed0);
  char dir[64], vtu[80];
  snprintf(dir, sizeof dir, "fem_fields_out_%s", name);
  snprintf(vtu, sizeof vtu, "%s/bg.vtu", dir);
  TEST_TRUE(vr_mkdir(dir));
  TEST_OK(ctx, fcm_space_write_vtu(space, &mat, u, NULL, vtu));
  size_t n = 0;
  double *pts = read_array(vtu, "Points", NULL, &n);
  TEST_TRUE(pts && n == 3 * (size_t)nn && !memcmp(pts, X, n * sizeof *pts));
  free(pts);
  double *disp = read_array(vtu, "PointData", "displacement", &n);
  TEST_TRUE(disp && n == 3 * (size_t)nn && !memcmp(disp, nf, n * sizeof *disp));
  free(disp);
  double *sv = read_array(vtu, "CellData", "stress", &n);
  TEST_TRUE(sv && n == 6 * (size_t)fcm_mesh_num_cells(mesh));
  for (size_t c = 0; sv && c < n / 6; c++)
    for (int k = 0; k < 6; k++)
      TEST_NEAR(sv[6 * c + k], s0[k], 0, 1e-10 * vm0);
  free(sv);
  double *vv = read_array(vtu, "CellData", "von_mises", &n);
  TEST_TRUE(vv && n == (size_t)fcm_mesh_num_cells(mesh) && fabs(vv[0] - vm0) <= 1e-10 * vm0);
  free(vv);
  vr_rmdir(dir);
  /* errors name what is wrong */
  const double xi0[3] = {0, 0, 0};
  TEST_ERR(ctx, fcm_space_element_stress(space, &mat, -1, xi0, u, NULL, NULL, NULL), FCM_ERR_ARG,
           "element -1 is out of range");
  fcm_material bad = mat;
  bad.poisson = 0.5;
  TEST_ERR(ctx, fcm_space_cell_stress(space, &bad, u, NULL, NULL, NULL), FCM_ERR_ARG, "0.5");
  free(u), free(nf), free(tr);
done:
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
}

/* A ball in a grid: cut cells average exactly; the surface is written at reference positions. */
static void embedded(fcm_element_type type, const char *name)
{
  fcm_mesh *mesh = NULL;
  fcm_geometry *ball = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_embedded_surface *es = NULL;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c[3] = {0.1, -0.05, 0.03};
  const fcm_index cells[3] = {3, 3, 3};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.8, 2, &ball));
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, ball, &ro, &rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
  TEST_OK(ctx, fcm_embedded_surface_create(space, ball, &es));
  if (!es) goto done;
  TEST_TRUE(fcm_cell_rules_get_stats(rules)->num_cut > 0);
  double *u = affine_field(space);
  stress_checks(space, u, es);
  /* the points are the boundary vertices of the geometry, triangle by triangle */
  const fcm_index np = fcm_embedded_surface_num_points(es),
                  nt = fcm_embedded_surface_num_triangles(es);
  const double *P = fcm_embedded_surface_points(es), *GX = fcm_geometry_coords(ball);
  const fcm_index *tri = fcm_embedded_surface_triangles(es),
                  *gtri = fcm_geometry_boundary_triangles(ball);
  TEST_TRUE(nt == fcm_geometry_num_boundary_triangles(ball));
  for (fcm_index k = 0; k < 3 * nt; k++)
    TEST_TRUE(!memcmp(P + 3 * tri[k], GX + 3 * gtri[k], 3 * sizeof *P));
  double *d = malloc(sizeof *d * 3 * (size_t)np), *x = malloc(sizeof *x * 3 * (size_t)np);
  TEST_OK(ctx, fcm_embedded_surface_eval(es, u, d, x));
  for (fcm_index i = 0; i < np; i++)
    for (int k = 0; k < 3; k++) {
      const double ex =
          T[k] + G[3 * k] * P[3 * i] + G[3 * k + 1] * P[3 * i + 1] + G[3 * k + 2] * P[3 * i + 2];
      TEST_NEAR(d[3 * i + k], ex, 0, 1e-13);
      TEST_NEAR(x[3 * i + k], P[3 * i + k] + ex, 0, 1e-13);
    }
  /* the file: reference positions and the displacement (not deformed points) */
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 2.0e5, 0.3, 1000.0};
  char dir[64], vtu[80];
  snprintf(dir, sizeof dir, "fem_fields_surf_%s", name);
  snprintf(vtu, sizeof vtu, "%s/s.vtu", dir);
  TEST_TRUE(vr_mkdir(dir));
  TEST_OK(ctx, fcm_embedded_surface_write_vtu(es, &mat, u, vtu));
  size_t n = 0;
  double *pts = read_array(vtu, "Points", NULL, &n);
  TEST_TRUE(pts && n == 3 * (size_t)np && !memcmp(pts, P, n * sizeof *pts));
  free(pts);
  double *disp = read_array(vtu, "PointData", "displacement", &n);
  TEST_TRUE(disp && n == 3 * (size_t)np && !memcmp(disp, d, n * sizeof *disp));
  free(disp);
  double *sed = read_array(vtu, "PointData", "strain_energy_density", &n);
  TEST_TRUE(sed && n == (size_t)np);
  free(sed);
  vr_rmdir(dir);
  free(u), free(d), free(x);
done:
  fcm_embedded_surface_destroy(&es);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&mesh);
}

/* The side of the cut plane x = 0.6 an element lies on: its first authentic point. */
static int element_side(const fcm_space *space, fcm_index e)
{
  const fcm_cell_rules *r = fcm_space_cell_rules(space);
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const fcm_index c = fcm_space_element_cell(space, e);
  fcm_index first = 0, e0 = 0;
  fcm_cell_rules_cell_pieces(r, c, &first);
  fcm_space_cell_elements(space, c, &e0);
  int nq = 0;
  const double *pts = NULL;
  const unsigned char *fl = NULL;
  fcm_cell_rules_get_piece(r, first + (e - e0), FCM_RULE_STIFFNESS, &nq, &pts, NULL, &fl);
  double X[3 * 27], x[3] = {0, 0, 0};
  fcm_mesh_cell_coords(mesh, c, X);
  for (int q = 0; q < nq; q++)
    if (!fl || !fl[q]) {
      fcm_element_map(fcm_mesh_element_type(mesh), X, pts + 3 * q, x);
      break;
    }
  return x[0] < 0.6 ? 1 : -1;
}

static void cut(fcm_element_type type)
{
  const double lo[3] = {-0.25, -0.25, -0.25}, hi[3] = {1.25, 1.25, 1.25};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 1, 1};
  const fcm_index n3[3] = {3, 3, 3}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_surface *plane = NULL;
  fcm_space *s0 = NULL, *s1 = NULL;
  fcm_embedded_surface *es = NULL;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n3, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r0));
  const double p[3] = {0.6, 0.5, 0.5}, nx[3] = {1, 0, 0}, bl[3] = {-0.1, -0.1, -0.1},
               bh[3] = {1.1, 1.1, 1.1};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nx, bl, bh, &plane));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, plane, &r1));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r0, &s0));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r1, &s1));
  TEST_OK(ctx, fcm_embedded_surface_create(s0, g, &es));
  if (!es || !s1) goto done;
  const fcm_index nt0 = fcm_embedded_surface_num_triangles(es);
  TEST_OK(ctx, fcm_embedded_surface_set_space(es, s1));
  fcm_space_destroy(&s0); /* the surface no longer needs it */
  TEST_TRUE(fcm_embedded_surface_num_triangles(es) > nt0);
  /* each body translates rigidly: the left by +1 in x, the right by -1 */
  const fcm_index n = fcm_space_num_dofs(s1), nn = fcm_mesh_num_nodes(mesh);
  const int nper = fcm_mesh_nodes_per_cell(mesh);
  double *u = calloc((size_t)n, sizeof *u), *nf = malloc(sizeof *nf * 3 * (size_t)nn);
  for (fcm_index e = 0; e < fcm_space_num_elements(s1); e++) {
    const int side = element_side(s1, e);
    const fcm_index *ed = fcm_space_element_dofs(s1, e);
    for (int a = 0; a < nper; a++)
      u[ed[a]] = side;
  }
  TEST_OK(ctx, fcm_space_node_field(s1, u, nf));
  /* hexahedra: nodes at x = 0.25 (support [0, 0.6] vs [0.6, 0.75]) go left, x = 0.75
   * ([0.6, 1] vs [0.25, 0.6]) go right; every type: the copy of the largest support (the
   * volume of the pieces that use it), summed here from the public element view */
  const fcm_cell_rules *rr = fcm_space_cell_rules(s1);
  double *support = calloc((size_t)n / 3 + 1, sizeof *support);
  for (fcm_index e = 0; e < fcm_space_num_elements(s1); e++) {
    const fcm_index c = fcm_space_element_cell(s1, e);
    fcm_index first = 0, e0 = 0;
    fcm_cell_rules_cell_pieces(rr, c, &first);
    fcm_space_cell_elements(s1, c, &e0);
    const double vol = fcm_cell_rules_piece_volume(rr, first + (e - e0));
    const fcm_index *ed = fcm_space_element_dofs(s1, e);
    for (int a = 0; a < nper; a++)
      support[ed[a] / 3] += vol;
  }
  const int hex = type == FCM_ELEMENT_HEX8 || type == FCM_ELEMENT_HEX20;
  const double *X = fcm_mesh_coords(mesh);
  int n25 = hex ? 0 : 1, n75 = hex ? 0 : 1;
  for (fcm_index a = 0; a < nn; a++) {
    const fcm_index ncp = fcm_space_node_copies(s1, a), d0 = fcm_space_node_dof(s1, a);
    if (ncp < 2) continue;
    fcm_index best = d0;
    for (fcm_index k = 1; k < ncp; k++)
      if (support[d0 / 3 + k] > support[best / 3]) best = d0 + 3 * k;
    TEST_TRUE(nf[3 * a] == u[best]);
    if (hex && fabs(X[3 * a] - 0.25) < 1e-12) {
      TEST_TRUE(nf[3 * a] == 1.0);
      n25++;
    }
    if (hex && fabs(X[3 * a] - 0.75) < 1e-12) {
      TEST_TRUE(nf[3 * a] == -1.0);
      n75++;
    }
  }
  free(support);
  TEST_TRUE(n25 > 0 && n75 > 0);
  /* cut faces: on the plane, both sides, each moving with its body */
  const fcm_index np = fcm_embedded_surface_num_points(es);
  const int32_t *flag = fcm_embedded_surface_cut_flags(es);
  const double *P = fcm_embedded_surface_points(es);
  double *d = malloc(sizeof *d * 3 * (size_t)np);
  TEST_OK(ctx, fcm_embedded_surface_eval(es, u, d, NULL));
  int left = 0, right = 0;
  for (fcm_index i = 0; i < np; i++) {
    if (!flag[i]) continue;
    TEST_NEAR(P[3 * i], 0.6, 0, 1e-12);
    TEST_TRUE(fabs(fabs(d[3 * i]) - 1.0) < 1e-12);
    if (d[3 * i] > 0)
      left++;
    else
      right++;
  }
  TEST_TRUE(left > 0 && left == right);
  free(u), free(nf), free(d);
done:
  fcm_embedded_surface_destroy(&es);
  fcm_space_destroy(&s0);
  fcm_space_destroy(&s1);
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&r1);
  fcm_surface_destroy(&plane);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc < 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  plain(type, argv[1]);
  embedded(type, argv[1]);
  cut(type);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
