/* A cut on an octree background that leaves sliver pieces next to hanging nodes, on a space whose
 * tiny DOF copies are constrained to move with their piece (fcm_space_options.constrain_ratio):
 * the plane x = 1/2 + 1e-4 cuts a 1e-4 thick sliver off the cells right of x = 1/2 (levels 1-3),
 * whose copies at the cells' nodes right of the cut are tiny, among them copies of hanging
 * nodes, and the coarse cells with such slivers are the sources of hanging copies.
 * - the space builds with constrained copies, and its hanging-node matrix T with them;
 * - T gives every hanging copy its side's value, from the DOFs its coarse piece reads: for a
 *   rigid translation of each side at every copy (1e-12); for an affine field on each side at
 *   every hanging copy of side 1 and of side 0 at x <= 1/2 (1e-12). Not at the other hanging
 *   copies of side 0: their coarse piece is a sliver that reads, at its constrained slots, the
 *   copies it follows, so its field is exact for translations only (Hex20's mid-edge copies of
 *   the fine cut cells are not tiny and hang there; Hex8 measures 1e-16 everywhere);
 * - patch test through T^T K T: side 1 in an affine field (uniaxial stress along the cut plane,
 *   a rotation, a translation), side 0 (which holds the slivers: exact for translations) in a
 *   translation, prescribed on the box-boundary copies, reproduced at every copy (1e-9);
 * - a short dynamic run under gravity steps, and its displacement stays in the range of T. */
#include "octree_cut_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double cut_x = 0.5 + 1e-4;

/* The field of side s; `affine0`: side 0 affine too (else a translation). E = 1, nu = 0.3. */
static int affine0;
static void field(int s, const double x[3], double u[3])
{
  static const double t[3] = {0.0, 1.0, -0.5}; /* in the cut plane */
  static const double w[3] = {0.01, -0.02, 0.03}, b[2][3] = {{0.01, -0.02, 0.03}, {0.5, 0.2, -0.4}};
  const double nu = 0.3, sig = 0.2, tt = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
  for (int i = 0; i < 3; i++) {
    u[i] = b[s][i];
    if (s == 0 && !affine0) continue;
    for (int j = 0; j < 3; j++)
      u[i] += ((1 + nu) * sig * t[i] * t[j] / tt - (i == j ? nu * sig : 0.0)) * x[j];
    const double wx[3] = {w[1] * x[2] - w[2] * x[1], w[2] * x[0] - w[0] * x[2],
                          w[0] * x[1] - w[1] * x[0]};
    u[i] += wx[i];
  }
}

/* The side of element e: of its cell's centre, or of the sliver for the small piece. */
static int elem_side(const fcm_space *s, const fcm_cell_rules *R, fcm_index e)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const fcm_index c = fcm_space_element_cell(s, e);
  const int npc = fcm_mesh_nodes_per_cell(m);
  const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * c;
  const double *X = fcm_mesh_coords(m);
  double lo = X[3 * cn[0]], hi = lo;
  for (int a = 1; a < npc; a++)
    lo = fmin(lo, X[3 * cn[a]]), hi = fmax(hi, X[3 * cn[a]]);
  fcm_index fe = 0, fp = 0;
  const fcm_index ne = fcm_space_cell_elements(s, c, &fe);
  fcm_cell_rules_cell_pieces(R, c, &fp);
  if (ne == 1) return 0.5 * (lo + hi) > cut_x;
  /* a cut cell: the smaller piece is the sliver on side 0 */
  const double v = fcm_cell_rules_piece_volume(R, fp + (e - fe)),
               vo = fcm_cell_rules_piece_volume(R, fp + (e - fe == 0 ? 1 : 0));
  TEST_TRUE(ne == 2 && lo < cut_x && cut_x < hi);
  return v > vo;
}

/* ue at every copy read through an unconstrained slot (each copy serves one side); away[r]:
 * copy r is on side 1 or at x <= 1/2, away from the cells with slivers. */
static void copy_values(const fcm_space *s, const fcm_cell_rules *R, int *side, double *ue,
                        unsigned char *away)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const int npc = fcm_mesh_nodes_per_cell(m);
  for (fcm_index r = 0; r < fcm_space_num_dofs(s) / 3; r++)
    side[r] = -1;
  for (fcm_index e = 0; e < fcm_space_num_elements(s); e++) {
    const int sd = elem_side(s, R, e);
    const fcm_index *ed = fcm_space_element_dofs(s, e);
    const fcm_index *cn = fcm_mesh_cells(m) + (size_t)npc * fcm_space_element_cell(s, e);
    for (int a = 0; a < npc; a++) {
      if (s->elem_con && s->elem_con[(size_t)npc * e + a]) continue;
      const fcm_index r = ed[a] / 3;
      TEST_TRUE(side[r] < 0 || side[r] == sd);
      side[r] = sd;
      field(sd, fcm_mesh_coords(m) + 3 * cn[a], ue + 3 * r);
      away[r] = sd == 1 || fcm_mesh_coords(m)[3 * cn[a]] <= 0.5;
    }
  }
}

/* The patch solve's largest error against ue. */
static double patch_error(fcm_ctx *ctx, const fcm_space *s, const fcm_csr *K, const fcm_csr *T,
                          const fcm_index *free_dof, const double *ue)
{
  const fcm_index n = fcm_space_num_dofs(s);
  double *u = calloc((size_t)n, sizeof *u);
  octree_patch_solve(ctx, s, K, T, free_dof, ue, u);
  double err = 0.0;
  for (fcm_index i = 0; i < n; i++)
    err = fmax(err, fabs(u[i] - ue[i]));
  free(u);
  return err;
}

/* Constrained slots at hanging nodes, and in the coarse cells of hanging pairs. */
static void count_slivers(const fcm_space *s, fcm_index *at_hanging, fcm_index *in_coarse)
{
  const fcm_mesh *m = s->mesh;
  const fcm_index nh = fcm_mesh_num_hanging(m);
  unsigned char *hang = calloc((size_t)fcm_mesh_num_nodes(m), 1),
                *coarse = calloc((size_t)fcm_mesh_num_cells(m), 1);
  for (fcm_index i = 0; i < nh; i++) {
    fcm_index c = 0, h = 0;
    fcm_mesh_get_hanging(m, i, &c, &h, NULL);
    hang[h] = coarse[c] = 1;
  }
  *at_hanging = *in_coarse = 0;
  for (fcm_index e = 0; e < s->num_elems; e++)
    for (int a = 0; a < s->nn; a++) {
      if (!s->elem_con[(size_t)s->nn * e + a]) continue;
      *at_hanging += hang[fcm_mesh_cells(m)[(size_t)s->nn * s->elem_cell[e] + a]];
      *in_coarse += coarse[s->elem_cell[e]];
    }
  free(hang), free(coarse);
}

/* A few backward Euler steps under gravity: converged, finite, u = T u_free. */
static void dynamic_run(fcm_ctx *ctx, const fcm_space *space, const fcm_csr *T,
                        const fcm_index *free_dof)
{
  fcm_integrator *integ = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e5, 0.35, 800.0};
  const double g[3] = {0.0, 0.0, -9.81};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.01;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  const double v0[3] = {0.3, -0.2, 0.1}, omega[3] = {1.0, 2.0, 3.0}, c[3] = {0.5, 0.5, 0.5};
  TEST_OK(ctx, fcm_integrator_set_rigid_velocity(integ, v0, omega, c));
  for (int s = 0; s < 3; s++) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  }
  const fcm_index nd = fcm_space_num_dofs(space);
  const double *u = fcm_integrator_displacement(integ);
  double umax = 0.0;
  for (fcm_index i = 0; i < nd; i++) {
    TEST_TRUE(isfinite(u[i]));
    umax = fmax(umax, fabs(u[i]));
  }
  TEST_TRUE(umax > 1e-3 && umax < 0.1);
  const double err = octree_t_error(ctx, T, free_dof, u, nd, NULL);
  TEST_NEAR(err, 0.0, 0.0, 1e-13 * umax);
  fcm_integrator_destroy(&integ);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_csr *K = NULL, *T = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  /* levels 0-3 in a slab the cut crosses: hanging nodes on the planes x = 1/2 .. 3/4 */
  const double cp[3] = {cut_x, 0.5, 0.5}, cn[3] = {1.0, 0.0, 0.0};
  octree_cut_case t;
  octree_cut_case_create(ctx, type, 3, cp, cn, 1e-3, &t);
  const fcm_mesh *mesh = t.mesh;
  const fcm_space *space = t.space;
  const fcm_cell_rules *cut_rules = t.cut_rules;
  fcm_index at_hanging = 0, in_coarse = 0;
  TEST_TRUE(fcm_space_num_constrained_copies(space) > 0);
  count_slivers(space, &at_hanging, &in_coarse);
  TEST_TRUE(at_hanging > 0 && in_coarse > 0);

  const fcm_index nd = fcm_space_num_dofs(space);
  fcm_index *free_dof = malloc(sizeof *free_dof * (size_t)nd);
  int *side = malloc(sizeof *side * (size_t)nd / 3);
  unsigned char *away = calloc((size_t)nd / 3, 1);
  double *ue = calloc((size_t)nd, sizeof *ue);
  TEST_OK(ctx, fcm_space_hanging_matrix_create(space, free_dof, &T));
  fcm_index hang[2] = {0, 0};
  copy_values(space, cut_rules, side, ue, away); /* translations */
  for (fcm_index r = 0; r < nd / 3; r++) {
    TEST_TRUE(side[r] >= 0);
    if (free_dof[3 * r] < 0) hang[side[r]]++;
  }
  TEST_TRUE(hang[0] > 0 && hang[1] > 0);
  const double err_tr = octree_t_error(ctx, T, free_dof, ue, nd, NULL);
  TEST_NEAR(err_tr, 0.0, 0.0, 1e-12);
  affine0 = 1;
  copy_values(space, cut_rules, side, ue, away);
  const double err_aff = octree_t_error(ctx, T, free_dof, ue, nd, away);
  TEST_NEAR(err_aff, 0.0, 0.0, 1e-12);

  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0, 0.3, 1.0};
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, K));
  affine0 = 0;
  copy_values(space, cut_rules, side, ue, away);
  const double err_patch = patch_error(ctx, space, K, T, free_dof, ue);
  TEST_NEAR(err_patch, 0.0, 0.0, 1e-9);
  printf("%s: %lld cells, %lld hanging pairs, %lld DOFs, %lld constrained copies (slots: %lld at "
         "hanging nodes, %lld in coarse cells), hanging copies %lld | %lld; T error: "
         "translations %.2e, affine %.2e; patch error %.2e\n",
         argv[1], (long long)fcm_mesh_num_cells(mesh), (long long)fcm_mesh_num_hanging(mesh),
         (long long)nd, (long long)fcm_space_num_constrained_copies(space), (long long)at_hanging,
         (long long)in_coarse, (long long)hang[0], (long long)hang[1], err_tr, err_aff, err_patch);

  dynamic_run(ctx, space, T, free_dof);

  free(free_dof), free(side), free(ue), free(away);
  fcm_csr_destroy(&K);
  fcm_csr_destroy(&T);
  octree_cut_case_destroy(&t);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
