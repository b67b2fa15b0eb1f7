/* The cut-tip problem of cuttip.h (a half-plane crack ending inside the unit cube, the exact
 * mixed-mode Williams field of its front prescribed on the boundary), Hex8:
 * - the exact field: its gradient equals central differences of the field (1e-6), the library's
 *   stress of it (fcm_material_eval(), linear) is in equilibrium (central differences of the
 *   stress, 1e-5 of its scale), vanishes in traction on both crack faces (1e-12 of the scale)
 *   and has the stress intensity factors ahead of the front (sigma_yy, sigma_xy =
 *   K_I, K_II / sqrt(2 pi r), 1e-12);
 * - uniform grids n = 4, 8, 16: the H1 error falls, like h^(1/2) (rate 0.35..0.65 from 8 to
 *   16), and the Galerkin solution's energy error is at most that of the interpolant with the
 *   same boundary values (the solution minimizes the energy among them);
 * - an octree graded toward the front (levels 0-4) reaches a smaller error than the uniform
 *   16^3 grid (0.133 against 0.189) with fewer DOFs and cells (8,841 and 2,864 against 15,555
 *   and 4,096), and is optimal in energy against its interpolant too (the interpolant in the
 *   constrained space: hanging copies follow their masters);
 * - the stress-jump indicator is zero on a through-cut with each side's own affine field. */
#include "cuttip.h"

#include <string.h>

static fcm_material_params params;

/* The library's stress of the exact field at x on branch side (linear material: P = sigma). */
static void stress(const double x[3], int side, double P[9])
{
  double u[3], G[9], F[9];
  cuttip_exact(x, side, u, G);
  for (int k = 0; k < 9; k++)
    F[k] = G[k] + (k % 4 == 0 ? 1.0 : 0.0);
  fcm_material_eval(&params, F, NULL, P, NULL);
}

static void check_field(void)
{
  unsigned long long seed = 7;
  const double h = 1e-6, pi = CUTTIP_PI;
  double gerr = 0.0, div = 0.0, trac = 0.0, sif = 0.0;
  for (int k = 0; k < 200; k++) {
    const int side = k % 3 - 1;
    const double x[3] = {0.5 + 0.5 * urand(&seed), 0.5 + 0.5 * urand(&seed),
                         0.5 + 0.5 * urand(&seed)};
    const double r = hypot(x[0] - CUTTIP_X0, x[1] - CUTTIP_Y0);
    if (r < 0.05 || fabs(x[1] - CUTTIP_Y0) < 0.01) continue;
    double u[3], G[9], dP[3] = {0, 0, 0};
    cuttip_exact(x, side, u, G);
    const double scale = 1.0 / sqrt(r); /* of the gradient and the stress */
    for (int j = 0; j < 3; j++) {
      double xp[3], xm[3], up[3], um[3], Pp[9], Pm[9];
      memcpy(xp, x, sizeof xp), memcpy(xm, x, sizeof xm);
      xp[j] += h, xm[j] -= h;
      cuttip_exact(xp, side, up, NULL), cuttip_exact(xm, side, um, NULL);
      for (int i = 0; i < 3; i++)
        gerr = fmax(gerr, fabs(G[3 * i + j] - (up[i] - um[i]) / (2 * h)) / scale);
      stress(xp, side, Pp), stress(xm, side, Pm);
      for (int i = 0; i < 3; i++)
        dP[i] += (Pp[3 * i + j] - Pm[3 * i + j]) / (2 * h);
    }
    for (int i = 0; i < 3; i++)
      div = fmax(div, fabs(dP[i]) / (scale / r));
  }
  /* on the crack faces (theta = +-pi) and ahead of the front (theta = 0) */
  for (int k = 1; k <= 20; k++) {
    const double r = 0.02 * k, sc = 1.0 / sqrt(2 * pi * r);
    const double above[3] = {CUTTIP_X0 - r, CUTTIP_Y0, 0.3},
                 ahead[3] = {CUTTIP_X0 + r, CUTTIP_Y0, 0.7};
    double Pu[9], Pl[9], Pa[9];
    stress(above, 1, Pu);  /* theta = +pi: atan2(+0, -r) */
    stress(above, -1, Pl); /* theta = -pi: the lower face */
    stress(ahead, 0, Pa);
    for (int i = 0; i < 3; i++)
      trac = fmax(trac, fmax(fabs(Pu[3 * i + 1]), fabs(Pl[3 * i + 1])) / sc);
    /* sigma_xx on the faces: -2 K_II / sqrt(2 pi r) (upper), +2 K_II (lower): nonzero */
    TEST_NEAR(Pu[0], -2.0 * cuttip_K2 * sc, 1e-12, 0.0);
    TEST_NEAR(Pl[0], 2.0 * cuttip_K2 * sc, 1e-12, 0.0);
    sif = fmax(sif, fabs(Pa[4] - cuttip_K1 * sc) / sc);
    sif = fmax(sif, fabs(Pa[1] - cuttip_K2 * sc) / sc);
  }
  if (getenv("FCM_TEST_VERBOSE"))
    printf("field: gradient %.1e, div sigma %.1e, crack-face traction %.1e, K %.1e\n", gerr, div,
           trac, sif);
  TEST_NEAR(gerr, 0.0, 0.0, 1e-6);
  TEST_NEAR(div, 0.0, 0.0, 1e-5);
  TEST_NEAR(trac, 0.0, 0.0, 1e-12);
  TEST_NEAR(sif, 0.0, 0.0, 1e-12);
}

/* The stress-jump indicator on a through-cut (the plane y = Y0) of an octree mesh with each
 * side's own affine field: every element's stress is its side's constant, so the indicator is
 * zero wherever the enrichment separates the sides (a cell-averaged indicator over nodes
 * would see the jump across the cut). */
static void check_indicator(fcm_ctx *ctx, const fcm_material *mat)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, blo[3] = {-0.2, -0.2, -0.2},
               bhi[3] = {1.2, 1.2, 1.2}, p[3] = {0.5, CUTTIP_Y0, 0.5}, nrm[3] = {0, 1, 0};
  const fcm_index n2[3] = {2, 2, 2}, n1[3] = {1, 1, 1};
  double c = 0.4;
  fcm_octree_options o = fcm_octree_options_default();
  o.refine = cuttip_near_front, o.refine_user = &c, o.refine_level = FCM_OCTREE_MAX_LEVEL;
  fcm_mesh *m = NULL;
  fcm_geometry *body = NULL;
  fcm_surface *plane = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_space *s = NULL;
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, FCM_ELEMENT_HEX8, lo, hi, n2, &o, &m));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n1, &body));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nrm, blo, bhi, &plane));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, m, body, &ro, &r0));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, m, body, r0, plane, &r1));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, m, r1, &s));
  TEST_TRUE(fcm_space_num_bodies(s) == 2);
  const fcm_index nd = fcm_space_num_dofs(s), nc = fcm_mesh_num_cells(m);
  int *branch = malloc(sizeof *branch * (size_t)(nd / 3));
  double *u = calloc((size_t)nd, sizeof *u), *eta = calloc((size_t)nc, sizeof *eta);
  cuttip_copy_branches(s, branch);
  static const double A[2][9] = {{0.1, 0.02, 0.0, -0.03, 0.05, 0.01, 0.0, 0.04, -0.02},
                                 {-0.2, 0.0, 0.03, 0.06, 0.1, 0.0, 0.02, -0.05, 0.07}};
  const double *X = fcm_mesh_coords(m);
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(m); a++) {
    const fcm_index d0 = fcm_space_node_dof(s, a);
    for (fcm_index k = 0; d0 >= 0 && k < fcm_space_node_copies(s, a); k++) {
      const fcm_index r = d0 / 3 + k;
      TEST_TRUE(branch[r] != 0);
      const double *Ak = A[branch[r] > 0];
      for (int i = 0; i < 3; i++)
        u[3 * r + i] =
            Ak[3 * i] * X[3 * a] + Ak[3 * i + 1] * X[3 * a + 1] + Ak[3 * i + 2] * X[3 * a + 2];
    }
  }
  TEST_OK(ctx, fcm_space_stress_jumps(s, mat, u, eta));
  double emax = 0.0;
  for (fcm_index k = 0; k < nc; k++)
    emax = fmax(emax, eta[k]);
  if (getenv("FCM_TEST_VERBOSE"))
    printf("indicator on a through-cut, %lld cells: largest %.1e\n", (long long)nc, emax);
  TEST_NEAR(emax, 0.0, 0.0, 1e-12);
  free(branch), free(u), free(eta);
  fcm_space_destroy(&s);
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&r1);
  fcm_surface_destroy(&plane);
  fcm_geometry_destroy(&body);
  fcm_mesh_destroy(&m);
}

int main(int argc, char **argv)
{
  (void)argc, (void)argv;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const fcm_material mat = {FCM_MATERIAL_LINEAR, cuttip_E, cuttip_nu, 1.0};
  TEST_OK(ctx, fcm_material_setup(ctx, &mat, &params));
  check_field();
  check_indicator(ctx, &mat);

  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  static const int sizes[3] = {4, 8, 16};
  double err[3][2], ierr[3][2], dofs[3];
  for (int k = 0; k < 3; k++) {
    fcm_mesh *m = NULL;
    const fcm_index n3[3] = {sizes[k], sizes[k], sizes[k]};
    fcm_index nf = 0;
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &m));
    TEST_OK(ctx, cuttip_solve(ctx, m, &nf, err[k], ierr[k], NULL));
    dofs[k] = (double)nf;
    if (getenv("FCM_TEST_VERBOSE"))
      printf("uniform %2d: %6.0f DOFs, H1 error %.4f, energy %.4f (interpolant %.4f)\n", sizes[k],
             dofs[k], err[k][0], err[k][1], ierr[k][1]);
    TEST_TRUE(err[k][1] <= ierr[k][1] * (1.0 + 1e-6));
    fcm_mesh_destroy(&m);
  }
  TEST_TRUE(err[1][0] < err[0][0] && err[2][0] < err[1][0]);
  const double rate = log(err[1][0] / err[2][0]) / log(2.0);
  TEST_TRUE(rate > 0.35 && rate < 0.65);

  /* an octree graded toward the front against the uniform 16^3 grid */
  fcm_octree_options o = fcm_octree_options_default();
  double c = 0.3;
  const fcm_index n2[3] = {2, 2, 2};
  o.refine = cuttip_near_front, o.refine_user = &c, o.refine_level = FCM_OCTREE_MAX_LEVEL;
  fcm_mesh *m = NULL;
  fcm_index nf = 0;
  double oerr[2], oierr[2];
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, FCM_ELEMENT_HEX8, lo, hi, n2, &o, &m));
  TEST_TRUE(fcm_mesh_num_hanging(m) > 0);
  TEST_OK(ctx, cuttip_solve(ctx, m, &nf, oerr, oierr, NULL));
  if (getenv("FCM_TEST_VERBOSE"))
    printf("octree c = %.2f: levels 0-%d, %lld cells, %lld DOFs, H1 error %.4f, energy %.4f "
           "(interpolant %.4f)\n",
           c, fcm_mesh_max_level(m), (long long)fcm_mesh_num_cells(m), (long long)nf, oerr[0],
           oerr[1], oierr[1]);
  TEST_TRUE(oerr[0] < err[2][0]);
  TEST_TRUE((double)nf < dofs[2]);
  TEST_TRUE(fcm_mesh_num_cells(m) < 16 * 16 * 16);
  TEST_TRUE(oerr[1] <= oierr[1] * (1.0 + 1e-6));
  fcm_mesh_destroy(&m);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
