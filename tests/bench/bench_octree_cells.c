/* Cells of octree backgrounds refined along an embedded boundary against the uniform grid of the
 * same finest cell size (after Dick et al. 2011, Table 1): an exact sphere (crossed cells by the
 * distance bounds of each box) and the bunny-like body of the cutbench scenes (its surface,
 * fcm_geometry_boundary_meets_box()). Prints per finest level: uniform cells, octree cells (and per
 * level), the cells the boundary crosses and, for the sphere, the active cells (crossed or
 * inside) of both; the ratios. Asserts the octree has the uniform grid's crossed cells at the
 * finest level (the same resolution of the boundary). Argument: the body's OBJ file. */
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>

static const double centre[3] = {0.5, 0.5, 0.5}, radius = 0.37;

/* -1 inside, 1 outside, 0 crossed by the sphere. */
static int sphere_side(const double lo[3], const double hi[3])
{
  double dmin = 0.0, dmax = 0.0;
  for (int d = 0; d < 3; d++) {
    const double a = lo[d] - centre[d], b = hi[d] - centre[d];
    const double near = a > 0 ? a : b < 0 ? b : 0.0;
    dmin += near * near;
    dmax += fmax(a * a, b * b);
  }
  return sqrt(dmax) < radius ? -1 : sqrt(dmin) > radius ? 1 : 0;
}

static int sphere_refine(const double lo[3], const double hi[3], int level, void *user)
{
  (void)level, (void)user;
  return sphere_side(lo, hi) == 0;
}

/* Cells of the octree of `m` crossed (side 0) and active (side <= 0) by the criterion `side`. */
static void count(const fcm_mesh *m, int (*side)(const double *, const double *, void *),
                  void *user, long long *crossed, long long *active, long long per_level[16])
{
  const double *X = fcm_mesh_coords(m);
  const int npc = fcm_mesh_nodes_per_cell(m);
  *crossed = *active = 0;
  for (int l = 0; l < 16; l++)
    per_level[l] = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(m); c++) {
    const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
    double lo[3], hi[3];
    for (int d = 0; d < 3; d++)
      lo[d] = X[3 * cn[0] + d], hi[d] = X[3 * cn[6] + d];
    const int s = side(lo, hi, user);
    *crossed += s == 0;
    *active += s <= 0;
    per_level[fcm_mesh_cell_level(m, c)]++;
  }
}

static int sphere_side_fn(const double *lo, const double *hi, void *user)
{
  (void)user;
  return sphere_side(lo, hi);
}

/* The body: 0 crossed, 1 not (no inside test for a surface). */
static int body_side_fn(const double *lo, const double *hi, void *user)
{
  return fcm_geometry_boundary_meets_box(lo, hi, 0, user) > 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_surface *surf = NULL;
  fcm_geometry *body = NULL;
  if (argc != 2) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_surface_create_from_file(ctx, argv[1], &surf));
  fcm_surface_mesh_options so = fcm_surface_mesh_options_default();
  so.volume_mesh = 0;
  TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, surf, &so, &body));
  const fcm_index n0 = 8, n[3] = {n0, n0, n0};
  printf("model   finest  uniform cells  octree cells  ratio  crossed (uniform/octree)  "
         "active uniform  active octree  ratio  octree cells per level\n");
  for (int model = 0; model < 2; model++) {
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    if (model == 1) { /* the body's box with a margin of 2% */
      fcm_geometry_bounding_box(body, lo, hi);
      for (int d = 0; d < 3; d++) {
        const double w = hi[d] - lo[d];
        lo[d] -= 0.02 * w, hi[d] += 0.02 * w;
      }
    }
    for (int L = 1; L <= 4; L++) {
      fcm_mesh *oct = NULL, *uni = NULL;
      fcm_octree_options o = fcm_octree_options_default();
      o.refine = model == 0 ? sphere_refine : fcm_geometry_boundary_meets_box;
      o.refine_user = model == 0 ? NULL : body;
      o.refine_level = L;
      TEST_OK(ctx, fcm_mesh_create_octree(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &o, &oct));
      const fcm_index nu[3] = {n0 << L, n0 << L, n0 << L};
      TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, nu, &uni));
      long long oc = 0, oa = 0, uc = 0, ua = 0, per[16], uper[16];
      int (*side)(const double *, const double *, void *) =
          model == 0 ? sphere_side_fn : body_side_fn;
      count(oct, side, body, &oc, &oa, per);
      count(uni, side, body, &uc, &ua, uper);
      /* the finest octree cells resolve the boundary as the uniform grid does */
      TEST_TRUE(per[L] >= uc);
      const long long nuc = (long long)fcm_mesh_num_cells(uni), noc = fcm_mesh_num_cells(oct);
      printf("%-7s %6d  %13lld  %12lld  %5.2f  %9lld / %-9lld", model == 0 ? "sphere" : "body", L,
             nuc, noc, (double)nuc / (double)noc, uc, oc);
      if (model == 0)
        printf("     %11lld  %13lld  %5.2f  ", ua, oa, (double)ua / (double)oa);
      else
        printf("     %11s  %13s  %5s  ", "-", "-", "-");
      for (int l = 0; l <= L; l++)
        printf("%s%lld", l ? " " : "", per[l]);
      printf("\n");
      fcm_mesh_destroy(&oct);
      fcm_mesh_destroy(&uni);
    }
  }
  fcm_geometry_destroy(&body);
  fcm_surface_destroy(&surf);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
