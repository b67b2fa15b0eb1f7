/* Generalized enrichment (Ton-That et al. 2024) on all four element types: a body
 * cut through by a plane has exactly 12 rigid-body modes in its stiffness (two free bodies;
 * 6 before the cut), the cube diced by 10 planes into 36 sticks has 216 (Hex8: one cell and
 * a 2x2x2 grid; Tet4: 5 tets), the mass is unchanged by a cut (1^T M 1 = rho V), every node
 * copy lies in a component of the node's support, and under gravity M a = f gives a = g on
 * every DOF: all pieces fall together, also those that touch no node. */
#include "fcm/fcm.h"
#include "fem_util.h"
#include "dice.h"

static fcm_ctx *ctx;

static fcm_element_type parse(const char *s)
{
  static const char *names[] = {"tet4", "tet10", "hex8", "hex20"};
  static const fcm_element_type types[] = {FCM_ELEMENT_TET4, FCM_ELEMENT_TET10, FCM_ELEMENT_HEX8,
                                           FCM_ELEMENT_HEX20};
  for (int i = 0; i < 4; i++)
    if (!strcmp(s, names[i])) return types[i];
  return FCM_ELEMENT_COUNT;
}

/* Zero eigenvalues (below 1e-10 of the largest) of the linear stiffness of `space`. */
static int rigid_modes(const fcm_space *space)
{
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e3, 0.3, 1.0};
  fcm_csr *K = NULL;
  const fcm_index n = fcm_space_num_dofs(space);
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &mat, NULL, K));
  double *A = calloc((size_t)n * (size_t)n, sizeof *A), *w = malloc((size_t)n * sizeof *w);
  const fcm_index *rp = fcm_csr_row_ptr(K);
  const int *ci = fcm_csr_col_idx(K);
  const double *v = fcm_csr_values_read(K);
  for (fcm_index i = 0; i < n; i++)
    for (fcm_index e = rp[i]; e < rp[i + 1]; e++)
      A[(size_t)i * (size_t)n + (size_t)ci[e]] = v[e];
  TEST_OK(ctx, fcm_dense_spectrum_eval(ctx, (int)n, A, NULL, w, NULL));
  int zero = 0;
  for (fcm_index i = 0; i < n; i++)
    zero += fabs(w[i]) < 1e-10 * w[n - 1];
  free(A);
  free(w);
  fcm_csr_destroy(&K);
  return zero;
}

/* Volume of a background cell (affine hexes and tets here: the reference rule of degree 0). */
static double cell_volume(const fcm_mesh *mesh, fcm_index c)
{
  double X[3 * 27], J[9];
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const double xi[3] = {0.25, 0.25, 0.25};
  fcm_mesh_cell_coords(mesh, c, X);
  return fcm_element_jacobian(info->type, X, xi, J) *
         (info->shape == FCM_SHAPE_TET ? 1.0 / 6 : 8.0);
}

/* 1^T M 1 / 3 (the mass) and the gravity check: M a = f has a = g on every DOF. */
static void mass_and_gravity(const fcm_space *space, double rho, double volume)
{
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e3, 0.3, rho};
  const double g[3] = {0.3, -9.81, 1.5};
  const fcm_index n = fcm_space_num_dofs(space);
  fcm_csr *M = NULL;
  double *one = malloc((size_t)n * sizeof *one), *Mo = calloc((size_t)n, sizeof *Mo),
         *f = calloc((size_t)n, sizeof *f), *a = calloc((size_t)n, sizeof *a);
  TEST_OK(ctx, fcm_space_matrix_create(space, &M));
  TEST_OK(ctx, fcm_assemble_mass(space, &mat, NULL, M));
  for (fcm_index i = 0; i < n; i++)
    one[i] = 1.0;
  TEST_OK(ctx, fcm_csr_apply(M, 1.0, one, 0.0, Mo));
  double m = 0.0, stab = 0.0;
  for (fcm_index i = 0; i < n; i++)
    m += Mo[i] / 3.0;
  /* the stabilization points of each piece of a cut cell add alpha x the cell's mass */
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const fcm_cell_rules *r = fcm_space_cell_rules(space);
  for (fcm_index e = 0; e < fcm_space_num_elements(space); e++)
    if (fcm_cell_rules_class(r, fcm_space_element_cell(space, e)) == FCM_CELL_CUT)
      stab += 1e-6 * cell_volume(mesh, fcm_space_element_cell(space, e));
  TEST_NEAR(m, rho * (volume + stab), 1e-12, 0);
  TEST_OK(ctx, fcm_assemble_body_force(space, &mat, g, NULL, f));
  TEST_OK(ctx, direct_solve(ctx, M, f, a));
  for (fcm_index i = 0; i < n; i++)
    TEST_NEAR(a[i], g[i % 3], 1e-8, 1e-8);
  free(one);
  free(Mo);
  free(f);
  free(a);
  fcm_csr_destroy(&M);
}

/* Every element's DOFs are copies of its cell's nodes; a node's copies are consecutive. */
static void check_layout(const fcm_space *space)
{
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const int npc = fcm_mesh_nodes_per_cell(mesh);
  for (fcm_index e = 0; e < fcm_space_num_elements(space); e++) {
    const fcm_index c = fcm_space_element_cell(space, e);
    const fcm_index *d = fcm_space_element_dofs(space, e);
    for (int a = 0; a < npc; a++) {
      const fcm_index node = fcm_mesh_cells(mesh)[c * npc + a];
      const fcm_index d0 = fcm_space_node_dof(space, node);
      TEST_TRUE(d[a] >= d0 && d[a] < d0 + 3 * fcm_space_node_copies(space, node) &&
                (d[a] - d0) % 3 == 0);
    }
  }
}

static void plane(fcm_element_type type)
{
  const double lo[3] = {-0.25, -0.25, -0.25}, hi[3] = {1.25, 1.25, 1.25};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 1, 1};
  const fcm_index n[3] = {3, 3, 3}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_surface *cut = NULL;
  fcm_space *s0 = NULL, *s1 = NULL;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0;
  /* body forces of trilinear functions exactly: M a = f then has a = g exactly */
  if (type == FCM_ELEMENT_HEX8) o.strength[FCM_RULE_STIFFNESS] = 3;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r0));
  const double p[3] = {0.6, 0.5, 0.5}, nx[3] = {1, 0.1, -0.05}, bl[3] = {-0.1, -0.1, -0.1},
               bh[3] = {1.1, 1.1, 1.1};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nx, bl, bh, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r0, &s0));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r1, &s1));
  TEST_TRUE(s0 && s1);
  if (s0 && s1) {
    TEST_TRUE(fcm_space_num_dofs(s1) > fcm_space_num_dofs(s0));
    TEST_TRUE(fcm_space_num_elements(s1) > fcm_space_num_elements(s0));
    check_layout(s1);
    const int z0 = rigid_modes(s0), z1 = rigid_modes(s1);
    if (z0 != 6 || z1 != 12) fprintf(stderr, "rigid modes %d, %d (expected 6, 12)\n", z0, z1);
    TEST_TRUE(z0 == 6 && z1 == 12);
    mass_and_gravity(s0, 900.0, 1.0);
    mass_and_gravity(s1, 900.0, 1.0);
  }
  fcm_space_destroy(&s0);
  fcm_space_destroy(&s1);
  fcm_cell_rules_destroy(&r0);
  fcm_cell_rules_destroy(&r1);
  fcm_surface_destroy(&cut);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

/* The 36 sticks (Ton-That et al. 2024, Fig. 5). */
static void dice(const char *what)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index two[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r = NULL;
  fcm_space *s = NULL;
  TEST_OK(ctx, dice_mesh(ctx, what, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, two, &g));
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_STIFFNESS] = 3;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  if (r) TEST_OK(ctx, dice_cuts(ctx, mesh, g, &r));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r, &s));
  if (s) {
    check_layout(s);
    const int z = rigid_modes(s);
    if (z != 216) fprintf(stderr, "%s: %d rigid modes (expected 216)\n", what, z);
    TEST_TRUE(z == 216);
    mass_and_gravity(s, 1000.0, 1.0);
  }
  fcm_space_destroy(&s);
  fcm_cell_rules_destroy(&r);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

/* Koschier's constraint of tiny copies (fcm_space_options.constrain_ratio), and a cut along
 * cell faces. (a) The cube of 5 tets with the corner (1, 1, 1) cut off 1e-4 deep: the corner
 * is separated completely and all its copies are tiny (volume ~1e-12 of the supports), so
 * it follows one anchor copy: the default space has the uncut cube's 24 DOFs and 6 rigid
 * modes; without the constraint the corner has copies of its own. (b) A 2 x 2 x 1 Hex8 body
 * cut at x = 1 + 1e-7 with the ratio 1e-6: in the right cells the slice next to x = 1 belongs
 * to the left body, and its copies at the 6 nodes x = 2 are tiny; they move with the left
 * body's copies at x = 1, so the space has 18 + 6 copies (the nodes x = 1 have two) and 6
 * constrained copies; the stiffness has 9 zero modes: the right body's 6 and the left body's
 * 3 translations (moving with a copy at another node is exact for translations only: a
 * rotation strains the slice, with an energy of the slice's relative volume, 1e-7). (c) The same
 * body cut at x = 1 + 1e-13, within the tolerance of the cell faces x = 1: the cut lies in the
 * faces, splits no cell and still separates two bodies (18 + 6 copies, 12 rigid modes, nothing
 * constrained). Mass and a = g hold throughout (the constrained elements keep the partition of
 * unity). */
static void constraint(void)
{
  const double lo[3] = {0, 0, 0}, hi1[3] = {1, 1, 1}, hi2[3] = {2, 2, 1};
  const double bl[3] = {-1, -1, -1}, bh[3] = {3, 3, 2};
  const double at[3] = {1.0 - 1e-4 / 3, 1.0 + 1e-7, 1.0 + 1e-13};
  const fcm_index one[3] = {1, 1, 1}, grid[3] = {2, 2, 1}, constrained[3] = {-1, 6, 0};
  for (int c = 0; c < 3; c++) {
    fcm_mesh *mesh = NULL;
    fcm_geometry *g = NULL;
    fcm_cell_rules *r0 = NULL, *r1 = NULL;
    fcm_surface *cut = NULL;
    fcm_space *s = NULL, *s_off = NULL;
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.min_fraction = 0.0;
    if (c) o.strength[FCM_RULE_STIFFNESS] = 3;
    const double p[3] = {at[c], c ? 0.5 : at[c], c ? 0.5 : at[c]};
    const double n[3] = {1, c ? 0 : 1, c ? 0 : 1};
    if (c == 0)
      TEST_OK(ctx, dice_mesh(ctx, "tet5", &mesh));
    else
      TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi2, grid, &mesh));
    TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, c ? hi2 : hi1, one, &g));
    TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r0));
    TEST_OK(ctx, fcm_surface_create_plane(ctx, p, n, bl, bh, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1));
    fcm_space_options so = fcm_space_options_default();
    if (c == 1) so.constrain_ratio = 1e-6;
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, r1, &so, &s));
    so.constrain_ratio = 0.0;
    TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, r1, &so, &s_off));
    if (s && s_off) {
      const fcm_index nodes = fcm_mesh_num_nodes(mesh), k = fcm_space_num_constrained_copies(s);
      const int z = rigid_modes(s);
      const int zero[3] = {6, 9, 12};
      if (z != zero[c] || (c == 0 ? k == 0 : k != constrained[c]))
        fprintf(stderr, "constraint case %d: %d rigid modes, %lld constrained copies\n", c, z,
                (long long)k);
      TEST_TRUE(fcm_space_num_dofs(s) == 3 * (c ? nodes + 6 : nodes));
      TEST_TRUE(c == 0 ? k > 0 : k == constrained[c]);
      TEST_TRUE(z == zero[c]);
      TEST_TRUE(c == 2 ? fcm_space_num_dofs(s_off) == fcm_space_num_dofs(s)
                       : fcm_space_num_dofs(s_off) > fcm_space_num_dofs(s));
      TEST_TRUE(fcm_space_num_constrained_copies(s_off) == 0);
      mass_and_gravity(s, 1000.0, c ? 4.0 : 1.0);
      mass_and_gravity(s_off, 1000.0, c ? 4.0 : 1.0);
      /* the Schwarz blocks of every cell list each DOF once although elements use
       * constrained copies of other nodes (a block listing one twice is refused) */
      unsigned char *flag = calloc((size_t)fcm_mesh_num_cells(mesh), 1);
      for (fcm_index q = 0; q < fcm_mesh_num_cells(mesh); q++)
        flag[q] = fcm_space_cell_elements(s, q, NULL) > 0;
      fcm_index nb = 0, nd = 0;
      TEST_OK(ctx, fcm_space_cell_blocks(s, flag, &nb, &nd, NULL, NULL));
      fcm_index *bp = calloc((size_t)nb + 1, sizeof *bp), *bd = calloc((size_t)nd + 1, sizeof *bd);
      TEST_OK(ctx, fcm_space_cell_blocks(s, flag, &nb, &nd, bp, bd));
      TEST_TRUE(k == 0 || nd < 3 * nb * fcm_mesh_nodes_per_cell(mesh));
      fcm_csr *A = NULL;
      fcm_schwarz *S = NULL;
      const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e5, 0.3, 1000.0};
      TEST_OK(ctx, fcm_space_matrix_create(s, &A));
      TEST_OK(ctx, fcm_assemble_mass(s, &mat, NULL, A));
      TEST_OK(ctx, fcm_schwarz_create(ctx, A, nb, bp, bd, NULL, &S));
      fcm_schwarz_destroy(&S);
      fcm_csr_destroy(&A);
      free(flag);
      free(bp);
      free(bd);
    }
    fcm_space_destroy(&s);
    fcm_space_destroy(&s_off);
    fcm_cell_rules_destroy(&r0);
    fcm_cell_rules_destroy(&r1);
    fcm_surface_destroy(&cut);
    fcm_geometry_destroy(&g);
    fcm_mesh_destroy(&mesh);
  }
}

int main(int argc, char **argv)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  if (argc > 1 && !strcmp(argv[1], "constraint")) {
    constraint();
  } else if (argc > 1 && !strcmp(argv[1], "dice")) {
    dice("tet5");
    dice("hex1");
    dice("hex8");
  } else {
    const fcm_element_type type = argc > 1 ? parse(argv[1]) : FCM_ELEMENT_HEX8;
    TEST_TRUE(type != FCM_ELEMENT_COUNT);
    if (type != FCM_ELEMENT_COUNT) plane(type);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
