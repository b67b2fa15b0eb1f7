/* Assembly over a LOCAL space's rows (the PETSc backend's integrator path, fem_impl.h): a ball
 * embedded in a box grid (optionally cut by a crack plane: pieces, nodes with several copies),
 * its cells split in two halves (slabs of the cell numbering, then a checkerboard of the grid's
 * octants). For each half: cell rules built with the half as cell_mask, a local space
 * (fcm__space_create_local()) localized on the half (fcm__space_localize(): own cells and one layer
 * of ghosts), matrices over its rows (fcm__space_matrix_create_rows()), and the workspace assembly
 * of the stiffness, the mass, body force, surface traction and the hyperelastic energy / force /
 * tangent at a random displacement. Asserted against the full space (unmasked rules,
 * fcm_space_matrix_create()): (1) every local row placed at its DOF (fcm__space_row_dof()), summed
 * over the halves, is the full matrix to 1e-12 relative (of each full row's largest entry); the
 * local patterns are subsets of the full one; the vectors sum likewise, the energies to 1e-12
 * relative; (2) each row of a copy used by an own cell has exactly the full row's columns; (3)
 * fcm__space_matrix_apply() of each half's mass, summed, is the full M x (1e-12 of |M||x|); (4) the
 * accessors: fcm__space_local_elem / _elem_local / _elem_row / _row_dof agree with the numbering,
 * the colours hold each local element position once; (5) fcm__space_check_assemble() (and so the
 * assembly) refuses a local space whose rules give points outside its local cells (rules masked
 * with every cell, space localized on a half; unmasked rules) and the matrix of a full space, a
 * full space passes; fcm__space_localize() refuses a full space; (6) on the full space
 * fcm__space_matrix_create_rows() is fcm_space_matrix_create() (size, kind, pattern) and
 * fcm__space_matrix_apply() is fcm_csr_apply() bit for bit. With FCM_TEST_VERBOSE set: the topology
 * bytes (fcm__space_memory()) and matrix entries of each half against the full space. Arguments:
 * element type, grid cells per side, [cut]. */
#include "fem/fem_impl.h"
#include "fem_util.h"

static void pressure(void *user, const double x[3], const double n[3], double t[3])
{
  (void)user;
  for (int i = 0; i < 3; i++)
    t[i] = -(2.0 + x[0]) * n[i];
}

/* max_i |a_i - b_i| <= rtol * scale_i with scale_i = max(|b_i|, floor). */
static int vec_close(fcm_index n, const double *a, const double *b, double rtol)
{
  double bmax = 0.0;
  for (fcm_index i = 0; i < n; i++)
    bmax = FCM_MAX(bmax, fabs(b[i]));
  for (fcm_index i = 0; i < n; i++)
    if (!(fabs(a[i] - b[i]) <= rtol * bmax)) {
      fprintf(stderr, "vector entry %lld: %.17g vs %.17g\n", (long long)i, a[i], b[i]);
      return 0;
    }
  return 1;
}

/* Add the rows of A (over l's rows) into sum (the full matrix F's value layout); returns 0 when
 * an entry is not in F's pattern. */
static int add_rows(const fcm_space *l, const fcm_csr *A, const fcm_csr *F, double *sum)
{
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  for (fcm_index r = 0; r < fcm__space_num_rows(l); r++) {
    const fcm_index d = fcm__space_row_dof(l, r);
    for (fcm_index p = rp[r]; p < rp[r + 1]; p++) {
      const fcm_index q = fcm_csr_position(F, d, ci[p]);
      if (q < 0) return 0;
      sum[q] += v[p];
    }
  }
  return 1;
}

/* sum equals F's values to rtol of each row's largest |entry|. */
static int matrix_close(const fcm_csr *F, const double *sum, double rtol)
{
  fcm_index n = 0;
  fcm_csr_get_size(F, &n, NULL, NULL);
  const fcm_index *rp = fcm_csr_row_ptr(F);
  const double *v = fcm_csr_values_read(F);
  for (fcm_index i = 0; i < n; i++) {
    double m = 0.0;
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      m = FCM_MAX(m, fabs(v[p]));
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      if (!(fabs(sum[p] - v[p]) <= rtol * m)) {
        fprintf(stderr, "matrix row %lld entry %lld: %.17g vs %.17g (row max %g)\n", (long long)i,
                (long long)(p - rp[i]), sum[p], v[p], m);
        return 0;
      }
  }
  return 1;
}

static int cmp_idx(const void *a, const void *b)
{
  const fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

/* The accessors of local space l against the numbering (4) and the complete rows (2). */
static void check_local(const fcm_space *l, const fcm_space *full, const unsigned char *own)
{
  const int nn = l->nn;
  TEST_TRUE(l->is_local && fcm__space_num_rows(l) == 3 * l->num_local_copies);
  fcm_index le_expect = 0;
  for (fcm_index e = 0; e < l->num_elems; e++) {
    const fcm_index le = fcm__space_elem_local(l, e);
    const int local = l->cell_local[l->elem_cell[e]] != 0;
    TEST_TRUE(local ? le == le_expect : le == -1);
    if (!local) continue;
    le_expect++;
    TEST_TRUE(fcm__space_local_elem(l, le) == e);
    for (int a = 0; a < nn; a++) {
      const fcm_index r = fcm__space_elem_row(l, le, a);
      TEST_TRUE(r % 3 == 0 && r >= 0 && r < fcm__space_num_rows(l));
      if (r < 0 || r >= fcm__space_num_rows(l)) continue;
      TEST_TRUE(fcm__space_row_dof(l, r) == l->elem_dof[e * nn + a] &&
                fcm__space_row_dof(l, r + 2) == l->elem_dof[e * nn + a] + 2);
    }
  }
  TEST_TRUE(le_expect == l->num_local_elems);
  TEST_TRUE(fcm__space_elem_local(l, -1) == -1 && fcm__space_elem_local(l, l->num_elems) == -1);
  /* colours: local positions, each once */
  unsigned char *seen = calloc((size_t)l->num_local_elems + 1, 1);
  TEST_TRUE(l->color_ptr[l->num_colors] == l->num_local_elems);
  for (fcm_index j = 0; seen && j < l->color_ptr[l->num_colors]; j++) {
    const fcm_index le = l->color_elems[j];
    TEST_TRUE(le >= 0 && le < l->num_local_elems && !seen[le]);
    if (le >= 0 && le < l->num_local_elems) seen[le] = 1;
  }
  free(seen);
  /* (2) the rows of the own cells' copies are the full rows */
  fcm_index checked = 0;
  for (fcm_index c = 0; c < l->num_cells; c++) {
    if (!own[c] || !l->active[c]) continue;
    TEST_TRUE(l->cell_local[c]);
    for (fcm_index e = l->cell_elem[c]; e < l->cell_elem[c + 1]; e++)
      for (int a = 0; a < nn; a++) {
        const fcm_index k = l->elem_dof[e * nn + a] / 3;
        const fcm_index *hit =
            bsearch(&k, l->local_copy, (size_t)l->num_local_copies, sizeof k, cmp_idx);
        TEST_TRUE(hit != NULL);
        if (!hit) continue;
        const fcm_index lk = hit - l->local_copy;
        for (int i = 0; i < 3; i++) {
          const fcm_index r = 3 * lk + i, f = 3 * k + i;
          const fcm_index len = l->row_ptr[r + 1] - l->row_ptr[r];
          TEST_TRUE(len == full->row_ptr[f + 1] - full->row_ptr[f] &&
                    memcmp(l->col_idx + l->row_ptr[r], full->col_idx + full->row_ptr[f],
                           sizeof(int) * (size_t)len) == 0);
          checked++;
        }
      }
  }
  TEST_TRUE(checked > 0);
}

typedef struct outputs {
  fcm_csr *K, *M, *T;
  double *f, *fb, *ft, *Mx, E;
} outputs;

static void outputs_free(outputs *o)
{
  fcm_csr_destroy(&o->K);
  fcm_csr_destroy(&o->M);
  fcm_csr_destroy(&o->T);
  free(o->f), free(o->fb), free(o->ft), free(o->Mx);
  memset(o, 0, sizeof *o);
}

/* Every assembly of the test on space s into o (matrices over its rows). */
static void assemble_all(fcm_ctx *ctx, const fcm_space *s, const fcm_material *mat,
                         const fcm_material_params *p, const double *u, const double *x, outputs *o)
{
  fcm_assembly_workspace *ws = NULL;
  const fcm_index n = fcm_space_num_dofs(s);
  const double g[3] = {0.3, -0.2, -9.81};
  o->f = calloc((size_t)n + 1, sizeof *o->f);
  o->fb = calloc((size_t)n + 1, sizeof *o->fb);
  o->ft = calloc((size_t)n + 1, sizeof *o->ft);
  o->Mx = calloc((size_t)n + 1, sizeof *o->Mx);
  TEST_TRUE(o->f && o->fb && o->ft && o->Mx);
  TEST_OK(ctx, fcm__space_matrix_create_rows(s, &o->K));
  TEST_OK(ctx, fcm__space_matrix_create_rows(s, &o->M));
  TEST_OK(ctx, fcm__space_matrix_create_rows(s, &o->T));
  TEST_OK(ctx, fcm_assembly_workspace_create(s, NULL, &ws));
  if (test_failures_) goto done;
  fcm_linear_form form = fcm_linear_form_default();
  form.material = mat;
  form.term = FCM_LINEAR_STIFFNESS;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, o->K, NULL));
  form.term = FCM_LINEAR_MASS;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, o->M, NULL));
  form.term = FCM_LINEAR_BODY_FORCE;
  form.accel = g;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, NULL, o->fb));
  form.term = FCM_LINEAR_SURFACE_TRACTION;
  form.field = pressure;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, NULL, o->ft));
  TEST_OK(ctx, fcm_assembly_workspace_hyperelastic(ws, p, u, &o->E, o->f, o->T));
  TEST_OK(ctx, fcm__space_matrix_apply(s, o->M, x, o->Mx));
done:
  fcm_assembly_workspace_destroy(&ws);
}

/* Rules of the ball (cut by the crack plane when `crack`) with cell_mask `mask` (NULL: none). */
static fcm_status make_rules(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                             const fcm_surface *crack, const unsigned char *mask,
                             fcm_cell_rules **out)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  fcm_cell_rules *r0 = NULL;
  o.surface_strength = 2;
  o.simplify = FCM_CELL_SIMPLIFY_OFF; /* AUTO refuses a mask */
  o.cell_mask = mask;
  fcm_status st = fcm_cell_rules_create(ctx, mesh, geom, &o, crack ? &r0 : out);
  if (st == FCM_OK && crack) st = fcm_cell_rules_create_cut(ctx, mesh, geom, r0, crack, out);
  fcm_cell_rules_destroy(&r0);
  return st;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_surface *crack = NULL;
  fcm_cell_rules *rfull = NULL, *rall = NULL;
  fcm_space *full = NULL, *bad = NULL;
  fcm_element_type type;
  outputs F;
  memset(&F, 0, sizeof F);
  if (argc < 3 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const fcm_index n = atoll(argv[2]);
  const int cut = argc > 3 && strcmp(argv[3], "cut") == 0;
  if (n < 2) return 2;
  const int verbose = getenv("FCM_TEST_VERBOSE") != NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, centre[3] = {0.52, 0.49, 0.47};
  const fcm_index cells[3] = {n, n, n};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, centre, 0.41, 3, &geom));
  if (cut) {
    const double p[3] = {0.53, 0.5, 0.5}, nx[3] = {1, 0.1, -0.05}, bl[3] = {-0.1, 0.2, -0.1},
                 bh[3] = {1.1, 1.1, 1.1}; /* a crack: the plane inside [bl, bh] only */
    TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nx, bl, bh, &crack));
  }
  if (test_failures_) goto done;
  TEST_OK(ctx, make_rules(ctx, mesh, geom, crack, NULL, &rfull));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rfull, &full));
  if (test_failures_) goto done;
  const fcm_index nd = full->num_dofs, nc = full->num_cells;
  if (cut) {
    fcm_index split = 0;
    for (fcm_index a = 0; a < full->num_nodes; a++)
      split += full->node_ncopy[a] > 1;
    TEST_TRUE(split > 0); /* the crack gives nodes several copies */
  }
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e4, 0.3, 1000.0};
  const fcm_material nh = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e4, 0.3, 1000.0};
  fcm_material_params p;
  TEST_OK(ctx, fcm_material_setup(ctx, &nh, &p));
  double *u = calloc((size_t)nd + 1, sizeof *u), *x = calloc((size_t)nd + 1, sizeof *x);
  double *sK = calloc((size_t)full->row_ptr[nd] + 1, sizeof *sK);
  double *sM = calloc((size_t)full->row_ptr[nd] + 1, sizeof *sM);
  double *sT = calloc((size_t)full->row_ptr[nd] + 1, sizeof *sT);
  double *sv[4] = {calloc((size_t)nd + 1, sizeof(double)), calloc((size_t)nd + 1, sizeof(double)),
                   calloc((size_t)nd + 1, sizeof(double)), calloc((size_t)nd + 1, sizeof(double))};
  unsigned char *mask[2] = {calloc((size_t)nc + 1, 1), calloc((size_t)nc + 1, 1)};
  unsigned char *all = calloc((size_t)nc + 1, 1);
  TEST_TRUE(u && x && sK && sM && sT && sv[0] && sv[1] && sv[2] && sv[3] && mask[0] && mask[1] &&
            all);
  if (test_failures_) goto cleanup;
  unsigned long long seed = 2024;
  for (fcm_index i = 0; i < nd; i++)
    u[i] = 0.01 * urand(&seed), x[i] = urand(&seed);
  assemble_all(ctx, full, &mat, &p, u, x, &F);
  if (test_failures_) goto cleanup;

  /* (6) the full space: the rows API is the full space's own */
  {
    fcm_csr *A = NULL;
    TEST_TRUE(fcm__space_num_rows(full) == nd);
    for (fcm_index r = 0; r < nd; r++)
      TEST_TRUE(fcm__space_row_dof(full, r) == r);
    for (fcm_index e = 0; e < full->num_elems; e++) {
      TEST_TRUE(fcm__space_elem_local(full, e) == e && fcm__space_local_elem(full, e) == e);
      for (int a = 0; a < full->nn; a++)
        TEST_TRUE(fcm__space_elem_row(full, e, a) == full->elem_dof[e * full->nn + a]);
    }
    TEST_OK(ctx, fcm_space_matrix_create(full, &A));
    fcm_index r1 = -1, c1 = -1, z1 = -1, r2 = -2, c2 = -2, z2 = -2;
    fcm_csr_get_size(A, &r1, &c1, &z1);
    fcm_csr_get_size(F.M, &r2, &c2, &z2);
    TEST_TRUE(r1 == r2 && c1 == c2 && z1 == z2 && fcm_csr_get_kind(F.M) == FCM_CSR_SYMMETRIC &&
              memcmp(fcm_csr_row_ptr(A), fcm_csr_row_ptr(F.M),
                     sizeof(fcm_index) * (size_t)(nd + 1)) == 0 &&
              memcmp(fcm_csr_col_idx(A), fcm_csr_col_idx(F.M), sizeof(int) * (size_t)z1) == 0);
    double *y = calloc((size_t)nd + 1, sizeof *y);
    TEST_OK(ctx, fcm_csr_apply(F.M, 1.0, x, 0.0, y));
    TEST_TRUE(y && memcmp(y, F.Mx, sizeof *y * (size_t)nd) == 0);
    free(y);
    fcm_csr_destroy(&A);
    TEST_OK(ctx, fcm__space_check_assemble(full, "full"));
    TEST_ERR(ctx, fcm__space_localize(full, mask[0]), FCM_ERR_ARG, "full space");
  }
  double topo_full = 0.0;
  fcm__space_memory(full, NULL, &topo_full);
  if (verbose)
    fprintf(stderr,
            "%s n=%lld%s: %lld DOFs, %lld elements; full space: topology %.0f bytes, "
            "%lld matrix entries\n",
            argv[1], (long long)n, cut ? " cut" : "", (long long)nd, (long long)full->num_elems,
            topo_full, (long long)full->row_ptr[nd]);

  for (int split = 0; split < 2; split++) { /* 0: slabs of the numbering, 1: octants */
    for (fcm_index c = 0; c < nc; c++) {
      const fcm_index i = c % n, j = (c / n) % n, k = c / (n * n); /* octant checkerboard */
      const int h = split == 0 ? 2 * c >= nc : (int)((2 * i / n + 2 * j / n + 2 * k / n) & 1);
      mask[0][c] = (unsigned char)!h;
      mask[1][c] = (unsigned char)h;
    }
    memset(sK, 0, sizeof *sK * (size_t)full->row_ptr[nd]);
    memset(sM, 0, sizeof *sM * (size_t)full->row_ptr[nd]);
    memset(sT, 0, sizeof *sT * (size_t)full->row_ptr[nd]);
    for (int k = 0; k < 4; k++)
      memset(sv[k], 0, sizeof(double) * (size_t)nd);
    double Esum = 0.0;
    for (int h = 0; h < 2; h++) {
      fcm_cell_rules *r = NULL;
      fcm_space *l = NULL;
      outputs L;
      memset(&L, 0, sizeof L);
      const fcm_space_options so = fcm_space_options_default();
      TEST_OK(ctx, make_rules(ctx, mesh, geom, crack, mask[h], &r));
      if (r) TEST_OK(ctx, fcm__space_create_local(ctx, mesh, NULL, r, &so, NULL, &l));
      if (l) TEST_OK(ctx, fcm__space_localize(l, mask[h]));
      if (test_failures_) {
        fcm_space_destroy(&l);
        fcm_cell_rules_destroy(&r);
        goto cleanup;
      }
      TEST_TRUE(l->num_dofs == nd && l->num_elems == full->num_elems);
      TEST_OK(ctx, fcm__space_check_assemble(l, "half"));
      check_local(l, full, mask[h]);
      assemble_all(ctx, l, &mat, &p, u, x, &L);
      if (!test_failures_) {
        fcm_index rows = -1, cols = -1, nnz = -1;
        fcm_csr_get_size(L.K, &rows, &cols, &nnz);
        TEST_TRUE(rows == fcm__space_num_rows(l) && rows <= nd && cols == nd &&
                  nnz == l->row_ptr[rows] && fcm_csr_get_kind(L.K) == FCM_CSR_GENERAL);
        TEST_TRUE(add_rows(l, L.K, F.K, sK) && add_rows(l, L.M, F.M, sM) &&
                  add_rows(l, L.T, F.T, sT));
        double *lv[4] = {L.f, L.fb, L.ft, L.Mx};
        for (int k = 0; k < 4; k++)
          for (fcm_index i = 0; i < nd; i++)
            sv[k][i] += lv[k][i];
        Esum += L.E;
        /* the full-space matrix does not fit a local space with fewer rows (a half
         * may have every cell local: its rows are then the full space's) */
        if (rows < nd)
          TEST_ERR(ctx, fcm_assemble_stiffness(l, &mat, NULL, F.K), FCM_ERR_ARG,
                   "fcm__space_matrix_create_rows");
        if (verbose) {
          double topo = 0.0;
          fcm_index own = 0, ghost = 0;
          fcm__space_memory(l, NULL, &topo);
          for (fcm_index c = 0; c < nc; c++) {
            own += mask[h][c] && l->active[c];
            ghost += l->cell_local[c] && !mask[h][c];
          }
          fprintf(stderr,
                  "  split %s half %d: %lld own + %lld ghost active cells, %lld local elements, "
                  "%lld rows; topology %.0f bytes (%.2f of full), matrix entries %lld (%.2f of "
                  "full)\n",
                  split ? "octants" : "slabs", h, (long long)own, (long long)ghost,
                  (long long)l->num_local_elems, (long long)rows, topo, topo / topo_full,
                  (long long)nnz, (double)nnz / (double)full->row_ptr[nd]);
        }
      }
      outputs_free(&L);
      fcm_space_destroy(&l);
      fcm_cell_rules_destroy(&r);
    }
    if (test_failures_) goto cleanup;
    /* (1), (3), energies */
    TEST_TRUE(matrix_close(F.K, sK, 1e-12));
    TEST_TRUE(matrix_close(F.M, sM, 1e-12));
    TEST_TRUE(matrix_close(F.T, sT, 1e-12));
    TEST_TRUE(vec_close(nd, sv[0], F.f, 1e-12));
    TEST_TRUE(vec_close(nd, sv[1], F.fb, 1e-12));
    TEST_TRUE(vec_close(nd, sv[2], F.ft, 1e-12));
    TEST_TRUE(vec_close(nd, sv[3], F.Mx, 1e-12));
    TEST_NEAR(Esum, F.E, 1e-12, 0.0);
    TEST_TRUE(F.E != 0.0 && isfinite(F.E)); /* a nontrivial sum */
  }

  /* (5) rules that give points outside the local cells are refused */
  for (fcm_index c = 0; c < nc; c++)
    all[c] = 1;
  TEST_OK(ctx, make_rules(ctx, mesh, geom, crack, all, &rall));
  {
    const fcm_space_options so = fcm_space_options_default();
    TEST_OK(ctx, fcm__space_create_local(ctx, mesh, NULL, rall, &so, NULL, &bad));
    /* own: the first active cell only (its ghosts do not cover the grid) */
    memset(mask[0], 0, (size_t)nc);
    for (fcm_index c = 0; c < nc; c++)
      if (full->active[c]) {
        mask[0][c] = 1;
        break;
      }
    if (bad) {
      TEST_OK(ctx, fcm__space_localize(bad, mask[0]));
      TEST_TRUE(bad->num_local_elems < bad->num_elems);
      TEST_ERR(ctx, fcm__space_check_assemble(bad, "probe"), FCM_ERR_ARG, "probe: ");
      TEST_ERR(ctx, fcm__space_check_assemble(bad, "probe"), FCM_ERR_ARG, "cell_mask");
      fcm_assembly_workspace *ws = NULL;
      fcm_csr *A = NULL;
      TEST_OK(ctx, fcm_assembly_workspace_create(bad, NULL, &ws));
      TEST_OK(ctx, fcm__space_matrix_create_rows(bad, &A));
      fcm_linear_form form = fcm_linear_form_default();
      form.material = &mat;
      if (ws && A)
        TEST_ERR(ctx, fcm_assembly_workspace_linear(ws, &form, A, NULL), FCM_ERR_ARG,
                 "linear assembly: ");
      fcm_csr_destroy(&A);
      fcm_assembly_workspace_destroy(&ws);
      /* localized on every cell it passes */
      TEST_OK(ctx, fcm__space_localize(bad, all));
      TEST_OK(ctx, fcm__space_check_assemble(bad, "probe"));
      fcm_space_destroy(&bad);
    }
    /* unmasked rules: every cell has points */
    TEST_OK(ctx, fcm__space_create_local(ctx, mesh, NULL, rfull, &so, NULL, &bad));
    if (bad) {
      TEST_OK(ctx, fcm__space_localize(bad, mask[0]));
      TEST_ERR(ctx, fcm__space_check_assemble(bad, "probe"), FCM_ERR_ARG, "without a cell_mask");
    }
  }

cleanup:
  free(u), free(x), free(sK), free(sM), free(sT), free(all);
  for (int k = 0; k < 4; k++)
    free(sv[k]);
  free(mask[0]), free(mask[1]);
done:
  outputs_free(&F);
  fcm_space_destroy(&bad);
  fcm_space_destroy(&full);
  fcm_cell_rules_destroy(&rall);
  fcm_cell_rules_destroy(&rfull);
  fcm_surface_destroy(&crack);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(!ctx || fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
