/* fcm_cell_rules_options.cell_mask (the distributed build of fcm/petsc.h): a ball in a Hex8
 * grid with every third cell flagged. Every cell keeps its class, volume fraction and pieces
 * (so the space has the same elements and DOFs); flagged cells have exactly the points,
 * weights and flags of the unmasked build (volume and surface rules), unflagged cut cells
 * none; the element matrices of flagged elements are equal; a mask with simplify = auto is
 * refused. */
#include "fcm/fcm.h"
#include "fem/fem_impl.h"
#include "test.h"

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_cell_rules *full = NULL, *part = NULL, *r = NULL;
  fcm_space *sf = NULL, *sp = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.52, 0.47, 0.5};
  const fcm_index n[3] = {5, 5, 5};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.41, 3, &geom));
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  unsigned char *mask = calloc((size_t)nc, 1);
  for (fcm_index k = 0; k < nc; k++)
    mask[k] = k % 3 == 0;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.surface_strength = 2;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, geom, &o, &full));
  o.cell_mask = mask;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, geom, &o, &part));
  int ncut_flagged = 0, ncut_other = 0;
  for (fcm_index k = 0; k < nc; k++) {
    TEST_TRUE(fcm_cell_rules_class(full, k) == fcm_cell_rules_class(part, k));
    TEST_TRUE(fcm_cell_rules_volume_fraction(full, k) == fcm_cell_rules_volume_fraction(part, k));
    TEST_TRUE(fcm_cell_rules_cell_pieces(full, k, NULL) ==
              fcm_cell_rules_cell_pieces(part, k, NULL));
    if (fcm_cell_rules_class(full, k) != FCM_CELL_CUT) continue;
    for (int kind = 0; kind < FCM_RULE_KIND_COUNT; kind++) {
      int na = 0, nb = 0;
      const double *pa = NULL, *pb = NULL, *wa = NULL, *wb = NULL;
      const unsigned char *fa = NULL, *fb = NULL;
      TEST_OK(ctx, fcm_cell_rules_get(full, k, (fcm_rule_kind)kind, &na, &pa, &wa, &fa));
      TEST_OK(ctx, fcm_cell_rules_get(part, k, (fcm_rule_kind)kind, &nb, &pb, &wb, &fb));
      TEST_TRUE(na > 0);
      if (mask[k]) {
        TEST_TRUE(na == nb);
        if (na == nb && na > 0) {
          TEST_TRUE(memcmp(pa, pb, sizeof(double) * 3 * (size_t)na) == 0);
          TEST_TRUE(memcmp(wa, wb, sizeof(double) * (size_t)na) == 0);
          TEST_TRUE(memcmp(fa, fb, (size_t)na) == 0);
        }
      } else {
        TEST_TRUE(nb == 0);
      }
    }
    int sa = 0, sb = 0;
    TEST_OK(ctx, fcm_cell_rules_get_surface(full, k, &sa, NULL, NULL, NULL, NULL));
    TEST_OK(ctx, fcm_cell_rules_get_surface(part, k, &sb, NULL, NULL, NULL, NULL));
    TEST_TRUE(mask[k] ? sa == sb && sa > 0 : sb == 0);
    ncut_flagged += mask[k] != 0;
    ncut_other += mask[k] == 0;
  }
  TEST_TRUE(ncut_flagged > 0 && ncut_other > 0);

  /* the same space; equal element matrices on flagged elements */
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, full, &sf));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, part, &sp));
  TEST_TRUE(fcm_space_num_dofs(sf) == fcm_space_num_dofs(sp));
  TEST_TRUE(fcm_space_num_elements(sf) == fcm_space_num_elements(sp));
  fcm_assembly_workspace *wf = NULL, *wp = NULL;
  TEST_OK(ctx, fcm_assembly_workspace_create(sf, NULL, &wf));
  TEST_OK(ctx, fcm_assembly_workspace_create(sp, NULL, &wp));
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  fcm_linear_form form = fcm_linear_form_default();
  form.material = &mat;
  double Ka[24 * 24], Kb[24 * 24];
  int compared = 0;
  for (fcm_index e = 0; e < fcm_space_num_elements(sf); e++) {
    const fcm_index cell = fcm_space_element_cell(sf, e);
    TEST_TRUE(cell == fcm_space_element_cell(sp, e));
    TEST_TRUE(memcmp(fcm_space_element_dofs(sf, e), fcm_space_element_dofs(sp, e),
                     8 * sizeof(fcm_index)) == 0);
    if (!mask[cell]) continue;
    TEST_OK(ctx, fcm__assembly_element_linear(wf, &form, e, Ka, NULL));
    TEST_OK(ctx, fcm__assembly_element_linear(wp, &form, e, Kb, NULL));
    TEST_TRUE(memcmp(Ka, Kb, sizeof Ka) == 0);
    compared++;
  }
  TEST_TRUE(compared > 0);
  /* the one-element assembly adds up to the space's assembly */
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_space_matrix_create(sf, &A));
  TEST_OK(ctx, fcm_assembly_workspace_linear(wf, &form, A, NULL));
  const fcm_index nd = fcm_space_num_dofs(sf);
  double *dsum = calloc((size_t)nd, sizeof *dsum), dmax = 0.0, derr = 0.0;
  for (fcm_index e = 0; e < fcm_space_num_elements(sf); e++) {
    const fcm_index *ed = fcm_space_element_dofs(sf, e);
    TEST_OK(ctx, fcm__assembly_element_linear(wf, &form, e, Ka, NULL));
    for (int a = 0; a < 8; a++)
      for (int i = 0; i < 3; i++)
        dsum[ed[a] + i] += Ka[(3 * a + i) * 24 + 3 * a + i];
  }
  const double *av = fcm_csr_values(A);
  for (fcm_index i = 0; i < nd; i++) {
    const double aii = av[fcm_csr_position(A, i, i)];
    dmax = fmax(dmax, fabs(aii));
    derr = fmax(derr, fabs(aii - dsum[i]));
  }
  TEST_TRUE(dmax > 0.0 && derr <= 1e-12 * dmax);
  TEST_ERR(ctx, fcm__assembly_element_linear(wf, &form, -1, Ka, NULL), FCM_ERR_ARG, "outside");
  free(dsum);
  fcm_csr_destroy(&A);
  fcm_assembly_workspace_destroy(&wf);
  fcm_assembly_workspace_destroy(&wp);

  /* AUTO depends on the whole set of cells */
  o.simplify = FCM_CELL_SIMPLIFY_AUTO;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, mesh, geom, &o, &r), FCM_ERR_ARG, "cell_mask");
  TEST_TRUE(r == NULL);

  fcm_space_destroy(&sf);
  fcm_space_destroy(&sp);
  fcm_cell_rules_destroy(&full);
  fcm_cell_rules_destroy(&part);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  free(mask);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
