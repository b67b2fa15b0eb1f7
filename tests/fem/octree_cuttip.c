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
 *   constrained space: hanging copies follow their masters). */
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
    double u[3], G[9], P[9], dP[3] = {0, 0, 0};
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
    (void)P;
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

int main(int argc, char **argv)
{
  (void)argc, (void)argv;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const fcm_material mat = {FCM_MATERIAL_LINEAR, cuttip_E, cuttip_nu, 1.0};
  TEST_OK(ctx, fcm_material_setup(ctx, &mat, &params));
  check_field();

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
