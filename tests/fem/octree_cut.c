/* Cuts (XFEM) on octree backgrounds (Hex8, Hex20): a box body on an octree whose level
 * transitions the cut crosses, cut through by a tilted plane.
 * - two bodies, and every DOF copy serves one side of the cut;
 * - the constraints reproduce, on each side, that side's affine field: T applied to the free
 *   copies' values gives every hanging copy its side's value (1e-13);
 * - patch test across hanging nodes: the static solve of T^T K T with each side's affine field
 *   prescribed on its box-boundary copies reproduces both fields at every copy (1e-7: without
 *   stabilization, copies whose support is a sliver of 1e-3 of a cell amplify the rounding;
 *   Hex20 measures 5e-9 there, 1e-11 on copies of larger support, Hex8 2e-14);
 * - the sides move independently: one side pulled, the other held at rest stays at rest
 *   (1e-12);
 * - the cut on an octree that is uniform (the finest level) around the cut equals the cut on the
 *   uniform grid of the finest cells: the same pieces in every cell the cut reaches, piece by
 *   piece (volumes to 1e-13), and the same volume on each side, the exact one. */
#include "octree_cut_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The cut plane: n . (x - p) = 0, tilted against every axis. */
static const double cut_p[3] = {0.43, 0.5, 0.5}, cut_n[3] = {1.0, 0.2, 0.1};

static double side_dist(const double x[3])
{
  return cut_n[0] * (x[0] - cut_p[0]) + cut_n[1] * (x[1] - cut_p[1]) + cut_n[2] * (x[2] - cut_p[2]);
}

/* The affine field of side s (0: n.(x - p) < 0, 1: beyond): uniaxial stress sig t t^T along a
 * direction t in the cut plane (so the cut faces are traction-free: the field solves each side's
 * problem), plus an infinitesimal rotation and a translation; `rest`: side 0 at rest. E = 1,
 * nu = 0.3. */
static int rest;
static void affine(int s, const double x[3], double u[3])
{
  static const double t[2][3] = {{0.2, -1.0, 0.0}, {0.1, 0.0, -1.0}}; /* both orthogonal to n */
  static const double sig[2] = {0.2, -0.3}, w[2][3] = {{0.01, -0.02, 0.03}, {-0.02, 0.05, 0.01}};
  static const double b[2][3] = {{0.01, -0.02, 0.03}, {0.5, 0.2, -0.4}};
  const double nu = 0.3, tt = t[s][0] * t[s][0] + t[s][1] * t[s][1] + t[s][2] * t[s][2];
  for (int i = 0; i < 3; i++) {
    u[i] = 0.0;
    if (s == 0 && rest) continue;
    double ex = 0.0;
    for (int j = 0; j < 3; j++)
      ex += ((1 + nu) * sig[s] * t[s][i] * t[s][j] / tt - (i == j ? nu * sig[s] : 0.0)) * x[j];
    const double wx[3] = {w[s][1] * x[2] - w[s][2] * x[1], w[s][2] * x[0] - w[s][0] * x[2],
                          w[s][0] * x[1] - w[s][1] * x[0]};
    u[i] = ex + wx[i] + b[s][i];
  }
}

/* The side of element e: of its piece's quadrature point farthest from the cut plane. */
static int elem_side(const fcm_space *s, const fcm_cell_rules *R, fcm_index e)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const fcm_index c = fcm_space_element_cell(s, e);
  fcm_index fe = 0, fp = 0;
  fcm_space_cell_elements(s, c, &fe);
  fcm_cell_rules_cell_pieces(R, c, &fp);
  int np = 0;
  const double *xi = NULL;
  TEST_TRUE(fcm_cell_rules_get_piece(R, fp + (e - fe), FCM_RULE_STIFFNESS, &np, &xi, NULL, NULL) ==
            FCM_OK);
  const int npc = fcm_mesh_nodes_per_cell(m);
  const double *X = fcm_mesh_coords(m);
  const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
  double lo[3], hi[3], best = 0.0;
  for (int d = 0; d < 3; d++)
    lo[d] = hi[d] = X[3 * cn[0] + d];
  for (int a = 1; a < npc; a++)
    for (int d = 0; d < 3; d++)
      lo[d] = fmin(lo[d], X[3 * cn[a] + d]), hi[d] = fmax(hi[d], X[3 * cn[a] + d]);
  for (int q = 0; q < np; q++) {
    double x[3];
    for (int d = 0; d < 3; d++)
      x[d] = lo[d] + 0.5 * (xi[3 * q + d] + 1.0) * (hi[d] - lo[d]);
    const double sd = side_dist(x);
    if (fabs(sd) > fabs(best)) best = sd;
  }
  TEST_TRUE(best != 0.0);
  return best > 0.0;
}

/* side[r] of every copy r (all its elements on one side) and the exact field ue at every DOF. */
static void copy_sides(const fcm_space *s, const fcm_cell_rules *R, int *side, double *ue)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const int npc = fcm_mesh_nodes_per_cell(m);
  const fcm_index nd = fcm_space_num_dofs(s);
  for (fcm_index r = 0; r < nd / 3; r++)
    side[r] = -1;
  for (fcm_index e = 0; e < fcm_space_num_elements(s); e++) {
    const int sd = elem_side(s, R, e);
    const fcm_index *ed = fcm_space_element_dofs(s, e);
    const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * fcm_space_element_cell(s, e);
    for (int a = 0; a < npc; a++) {
      const fcm_index r = ed[a] / 3;
      TEST_TRUE(side[r] < 0 || side[r] == sd);
      side[r] = sd;
      affine(sd, fcm_mesh_coords(m) + 3 * cn[a], ue + 3 * r);
    }
  }
}

/* The patch solve's largest error against ue, and of side 0's copies against 0. */
static void patch_errors(fcm_ctx *ctx, const fcm_space *s, const fcm_csr *K, const fcm_csr *T,
                         const fcm_index *free_dof, const int *side, const double *ue,
                         double *err_all, double *err_side0)
{
  const fcm_index n = fcm_space_num_dofs(s);
  double *u = calloc((size_t)n, sizeof *u);
  octree_patch_solve(ctx, s, K, T, free_dof, ue, u);
  *err_all = *err_side0 = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    *err_all = fmax(*err_all, fabs(u[i] - ue[i]));
    if (side[i / 3] == 0) *err_side0 = fmax(*err_side0, fabs(u[i]));
  }
  free(u);
}

/* The pieces of cell c (volumes sorted, at most 8) and their volumes by side. */
static int cell_piece_volumes(const fcm_cell_rules *R, fcm_index c, double *v)
{
  fcm_index first = 0;
  const int n = (int)fcm_cell_rules_cell_pieces(R, c, &first);
  TEST_TRUE(n <= 8);
  for (int i = 0; i < n && i < 8; i++)
    v[i] = fcm_cell_rules_piece_volume(R, first + i);
  for (int i = 1; i < n && i < 8; i++)
    for (int j = i; j > 0 && v[j - 1] > v[j]; j--) {
      const double t = v[j];
      v[j] = v[j - 1], v[j - 1] = t;
    }
  return n;
}

/* The lower corner of cell c on the lattice of spacing 1/8. */
static void cell_key(const fcm_mesh *m, fcm_index c, long k[3])
{
  const int npc = fcm_mesh_nodes_per_cell(m);
  const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
  const double *X = fcm_mesh_coords(m);
  for (int d = 0; d < 3; d++) {
    double lo = X[3 * cn[0] + d];
    for (int a = 1; a < npc; a++)
      lo = fmin(lo, X[3 * cn[a] + d]);
    k[d] = lrint(8.0 * lo);
  }
}

/* Side volumes of a cut space: the pieces' volumes by the side of their elements. */
static void side_volumes(const fcm_space *s, const fcm_cell_rules *R, double vol[2])
{
  vol[0] = vol[1] = 0.0;
  for (fcm_index e = 0; e < fcm_space_num_elements(s); e++) {
    const fcm_index c = fcm_space_element_cell(s, e);
    fcm_index fe = 0, fp = 0;
    fcm_space_cell_elements(s, c, &fe);
    fcm_cell_rules_cell_pieces(R, c, &fp);
    vol[elem_side(s, R, e)] += fcm_cell_rules_piece_volume(R, fp + (e - fe));
  }
}

/* The cut on an octree refined along the cut to level 2 against the uniform 8^3 grid. */
static void against_uniform(fcm_ctx *ctx, fcm_element_type type, const fcm_geometry *body,
                            const fcm_surface *cut, const fcm_cell_rules_options *ro)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n2[3] = {2, 2, 2}, n8[3] = {8, 8, 8};
  fcm_mesh *mo = NULL, *mu = NULL;
  fcm_cell_rules *r0 = NULL, *ro_cut = NULL, *u0 = NULL, *ru_cut = NULL;
  fcm_space *so = NULL, *su = NULL;
  fcm_octree_options o = fcm_octree_options_default();
  o.refine = fcm_surface_meets_box;
  o.refine_user = (void *)cut;
  o.refine_level = 2;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n2, &o, &mo));
  TEST_TRUE(fcm_mesh_num_hanging(mo) > 0);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n8, &mu));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mo, body, ro, &r0));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mo, body, r0, cut, &ro_cut));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mu, body, ro, &u0));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mu, body, u0, cut, &ru_cut));
  /* uniform cells by their lattice corner */
  fcm_index *at = malloc(sizeof *at * 512);
  for (fcm_index c = 0; c < 512; c++) {
    long k[3];
    cell_key(mu, c, k);
    at[k[0] + 8 * k[1] + 64 * k[2]] = c;
  }
  fcm_index compared = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mo); c++) {
    double vo[8], vu[8];
    const int no = cell_piece_volumes(ro_cut, c, vo);
    if (no < 2) continue;
    TEST_TRUE(fcm_mesh_cell_level(mo, c) == 2);
    long k[3];
    cell_key(mo, c, k);
    const int nu = cell_piece_volumes(ru_cut, at[k[0] + 8 * k[1] + 64 * k[2]], vu);
    TEST_TRUE(no == nu);
    for (int i = 0; i < no && i < nu; i++)
      TEST_NEAR(vo[i], vu[i], 1e-13 / 512, 0.0);
    compared++;
  }
  TEST_TRUE(compared > 20);
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mo, ro_cut, &so));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mu, ru_cut, &su));
  TEST_TRUE(fcm_space_num_bodies(so) == 2 && fcm_space_num_bodies(su) == 2);
  double vol_o[2], vol_u[2];
  side_volumes(so, ro_cut, vol_o);
  side_volumes(su, ru_cut, vol_u);
  TEST_NEAR(vol_o[0], vol_u[0], 1e-13, 0.0);
  TEST_NEAR(vol_o[1], vol_u[1], 1e-13, 0.0);
  /* the plane's x over the (y, z) square, p_x - 0.2 (y - 1/2) - 0.1 (z - 1/2), stays in (0, 1)
   * and averages p_x: side 0 holds p_x of the unit cube */
  TEST_NEAR(vol_o[0], cut_p[0], 1e-12, 0.0);
  TEST_NEAR(vol_o[0] + vol_o[1], 1.0, 1e-12, 0.0);
  if (getenv("FCM_TEST_VERBOSE"))
    printf("octree %lld cells, %lld pieces compared; side volumes %.15f %.15f\n",
           (long long)fcm_mesh_num_cells(mo), (long long)compared, vol_o[0], vol_o[1]);
  free(at);
  fcm_space_destroy(&so);
  fcm_space_destroy(&su);
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&ro_cut);
  fcm_cell_rules_destroy(&u0);
  fcm_cell_rules_destroy(&ru_cut);
  fcm_mesh_destroy(&mo);
  fcm_mesh_destroy(&mu);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_csr *K = NULL, *T = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  /* levels 0-2 in a slab the cut crosses: level transitions on both sides of the cut */
  octree_cut_case t;
  octree_cut_case_create(ctx, type, 2, cut_p, cut_n, fcm_space_options_default().constrain_ratio,
                         &t);
  const fcm_mesh *mesh = t.mesh;
  const fcm_space *space = t.space;
  const fcm_cell_rules *cut_rules = t.cut_rules;
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.stabilization.mode = FCM_STABILIZATION_OFF;

  const fcm_index nd = fcm_space_num_dofs(space);
  fcm_index *free_dof = malloc(sizeof *free_dof * (size_t)nd);
  int *side = malloc(sizeof *side * (size_t)nd / 3);
  double *ue = calloc((size_t)nd, sizeof *ue);
  TEST_OK(ctx, fcm_space_hanging_matrix_create(space, free_dof, &T));
  /* hanging copies on both sides of the cut */
  fcm_index hang[2] = {0, 0};
  copy_sides(space, cut_rules, side, ue);
  for (fcm_index r = 0; r < nd / 3; r++) {
    TEST_TRUE(side[r] >= 0);
    if (free_dof[3 * r] < 0) hang[side[r]]++;
  }
  TEST_TRUE(hang[0] > 0 && hang[1] > 0);
  /* T reproduces each side's affine field from the free copies */
  const double err = octree_t_error(ctx, T, free_dof, ue, nd, NULL);
  TEST_NEAR(err, 0.0, 0.0, 1e-13);

  /* patch test across the hanging nodes, then one side pulled and the other at rest */
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0, 0.3, 1.0};
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, K));
  double err_all = 0.0, err0 = 0.0;
  patch_errors(ctx, space, K, T, free_dof, side, ue, &err_all, &err0);
  TEST_NEAR(err_all, 0.0, 0.0, 1e-7);
  rest = 1;
  copy_sides(space, cut_rules, side, ue);
  patch_errors(ctx, space, K, T, free_dof, side, ue, &err_all, &err0);
  TEST_NEAR(err_all, 0.0, 0.0, 1e-7);
  TEST_NEAR(err0, 0.0, 0.0, 1e-12);
  if (getenv("FCM_TEST_VERBOSE"))
    printf("%s: %lld cells, %lld hanging pairs, %lld DOFs, hanging copies %lld | %lld, patch "
           "error %.2e, side at rest %.2e\n",
           argv[1], (long long)fcm_mesh_num_cells(mesh), (long long)fcm_mesh_num_hanging(mesh),
           (long long)nd, (long long)hang[0], (long long)hang[1], err_all, err0);

  against_uniform(ctx, type, t.body, t.cut, &ro);

  free(free_dof), free(side), free(ue);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&T);
  octree_cut_case_destroy(&t);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
