/* A hierarchy created from the one before a cut (fcm__mg_create_from()) equals the one
 * fcm_mg_create() builds on the new space and matrix, bit for bit: every level's size, inactive
 * rows, prolongation, Galerkin matrix (pattern and values), diagonal and transposed positions,
 * row slabs, block smoother (blocks and their inverses) and block slabs, and the output of a
 * cycle and of a CG + multigrid solve. The embedded hemisphere of mg_util.h (Hex8 and Hex20)
 * is cut three times in sequence (partial planes: the first splits the top, the second crosses
 * it, the third cuts off a corner), each time from the previous hierarchy detached from its
 * matrix and space, which are destroyed first as in a simulation. A hierarchy created from
 * one on the same space and matrix keeps everything: every plan, row order, block smoother
 * and the coarsest analysis. fcm_mg_setup() (new values, every step) makes no allocation
 * through the context (CHOLMOD's numeric factorization of the coarsest level allocates through
 * its own). Tet4 and Tet10 have no multigrid (fcm_mg_create() needs a box grid). */
#include "mg/levels_impl.h"
#include "mg_util.h"
#include "test_alloc.h"

#include <stdio.h>

static int same_bytes(const void *a, const void *b, size_t n)
{
  if (n == 0) return 1;
  if (!a || !b) return a == b;
  return memcmp(a, b, n) == 0;
}

static int same_csr(const fcm_csr *a, const fcm_csr *b)
{
  fcm_index na = 0, za = 0, nb = 0, zb = 0;
  fcm_csr_get_size(a, &na, NULL, &za);
  fcm_csr_get_size(b, &nb, NULL, &zb);
  return na == nb && za == zb &&
         same_bytes(fcm_csr_row_ptr(a), fcm_csr_row_ptr(b), sizeof(fcm_index) * (size_t)(na + 1)) &&
         same_bytes(fcm_csr_col_idx(a), fcm_csr_col_idx(b), sizeof(int) * (size_t)za) &&
         same_bytes(fcm_csr_values_read(a), fcm_csr_values_read(b), sizeof(double) * (size_t)za);
}

static int same_slabs(const slab_order *a, const slab_order *b, fcm_index nitem)
{
  if (a->nslab != b->nslab || a->first != b->first) return 0;
  if (!a->ptr || !b->ptr) return a->ptr == b->ptr;
  return same_bytes(a->ptr, b->ptr, sizeof *a->ptr * (size_t)(a->nslab + 1)) &&
         same_bytes(a->item, b->item, sizeof *a->item * (size_t)nitem) &&
         same_bytes(a->mid, b->mid, sizeof *a->mid * (size_t)a->nslab);
}

static int same_blocks(const fcm_schwarz *a, const fcm_schwarz *b)
{
  if (!a || !b) return a == b;
  const fcm_index nb = fcm__schwarz_num_blocks(a);
  if (nb != fcm__schwarz_num_blocks(b)) return 0;
  for (fcm_index k = 0; k < nb; k++) {
    const fcm_index *da = NULL, *db = NULL;
    const double *Sa = NULL, *Sb = NULL;
    const int ma = fcm__schwarz_block(a, k, &da, &Sa), mb = fcm__schwarz_block(b, k, &db, &Sb);
    if (ma != mb || !same_bytes(da, db, sizeof *da * (size_t)ma) ||
        fcm__schwarz_slot_size(a, k) != fcm__schwarz_slot_size(b, k) ||
        !same_bytes(Sa, Sb, sizeof *Sa * fcm__schwarz_slot_size(a, k)))
      return 0;
  }
  return 1;
}

/* Every level of a and b the same bits (0 and a message naming the first difference). */
static int same_hierarchy(const fcm_mg *a, const fcm_mg *b)
{
  if (a->nlev != b->nlev) {
    printf("  levels %d and %d\n", a->nlev, b->nlev);
    return 0;
  }
  for (int l = 0; l < a->nlev; l++) {
    const mg_level *A = &a->lev[l], *B = &b->lev[l];
    const char *what = NULL;
    const fcm_index n = A->n;
    if (A->n != B->n)
      what = "size";
    else if (!same_bytes(A->inactive, B->inactive, (size_t)n))
      what = "inactive rows";
    else if (!same_csr(fcm__mg_level_matrix(A), fcm__mg_level_matrix(B)))
      what = "matrix";
    else if (!same_bytes(A->diag, B->diag, sizeof *A->diag * (size_t)n))
      what = "diagonal";
    else if (!same_bytes(A->dinv, B->dinv, sizeof *A->dinv * (size_t)n))
      what = "1 / diagonal";
    else if (!same_blocks(A->blk, B->blk))
      what = "block smoother";
    else if (!same_slabs(&A->rows, &B->rows, n))
      what = "row slabs";
    else if (A->blk && !same_slabs(&A->blocks, &B->blocks, fcm__schwarz_num_blocks(A->blk)))
      what = "block slabs";
    else if (l > 0) {
      fcm_index nz = 0;
      fcm_csr_get_size(A->Aown, NULL, NULL, &nz);
      if (!same_bytes(A->tpos, B->tpos, sizeof *A->tpos * (size_t)nz))
        what = "transposed positions";
    }
    if (!what && l + 1 < a->nlev) {
      const fcm_index nz = A->P_ptr[n];
      if (B->P_ptr[n] != nz ||
          !same_bytes(A->P_ptr, B->P_ptr, sizeof *A->P_ptr * (size_t)(n + 1)) ||
          !same_bytes(A->P_col, B->P_col, sizeof *A->P_col * (size_t)nz) ||
          !same_bytes(A->P_val, B->P_val, sizeof *A->P_val * (size_t)nz))
        what = "prolongation";
      else if (!same_bytes(A->R_ptr, B->R_ptr, sizeof *A->R_ptr * (size_t)(b->lev[l + 1].n + 1)) ||
               !same_bytes(A->R_col, B->R_col, sizeof *A->R_col * (size_t)nz) ||
               !same_bytes(A->R_val, B->R_val, sizeof *A->R_val * (size_t)nz))
        what = "restriction";
    }
    if (what) {
      printf("  level %d: the %s differs\n", l, what);
      return 0;
    }
  }
  return 1;
}

/* Three cycles from 0 (each on the last output) and a CG + MG solve to 1e-9: 4 n values. */
static void run(fcm_ctx *ctx, fcm_mg *mg, const problem *p, double *out)
{
  const fcm_index n = p->n;
  TEST_OK(ctx, fcm_mg_operator(mg, p->b, out));
  TEST_OK(ctx, fcm_mg_operator(mg, out, out + n));
  TEST_OK(ctx, fcm_mg_operator(mg, out + n, out + 2 * n));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = 1e-9;
  fcm_krylov_info ki;
  memset(out + 3 * n, 0, sizeof *out * (size_t)n);
  TEST_OK(ctx, fcm_cg_solve(ctx, n, fcm_csr_operator, p->A, fcm_mg_operator, mg, p->b, out + 3 * n,
                            &ko, &ki));
}

/* The space and clamped matrix of `rules` (mesh and geometry borrowed from base). */
static void problem_on(fcm_ctx *ctx, const problem *base, const fcm_cell_rules *rules, problem *p)
{
  memset(p, 0, sizeof *p);
  p->mesh = base->mesh;
  TEST_OK(ctx, fcm_space_create_embedded(ctx, p->mesh, rules, &p->space));
  finish_space(ctx, p, 0);
  const double flo[3] = {-2, 0, -2}, fhi[3] = {2, 0, 2};
  clamp_box(ctx, p, flo, fhi);
}

static void problem_drop(problem *p)
{
  fcm_csr_destroy(&p->A);
  fcm_space_destroy(&p->space);
  free(p->b);
  memset(p, 0, sizeof *p);
}

/* Compare the hierarchy created from *old (consumed) with a fresh one on p; the kept parts. */
static failing counter = {0, -1}; /* the allocator of the test's context, counting */

static fcm_mg *compare(fcm_ctx *ctx, fcm_mg **old, const problem *p, const fcm_mg_options *o,
                       const char *what, fcm__mg_kept *kept)
{
  fcm_mg *updated = NULL, *fresh = NULL;
  TEST_OK(ctx, fcm__mg_create_from(ctx, old, p->space, p->A, o, &updated));
  TEST_TRUE(*old == NULL);
  TEST_OK(ctx, fcm_mg_create(ctx, p->space, p->A, o, &fresh));
  fcm__mg_get_kept(updated, kept);
  const int same = same_hierarchy(updated, fresh);
  const size_t bytes = sizeof(double) * 4 * (size_t)p->n;
  double *x1 = malloc(bytes), *x2 = malloc(bytes);
  run(ctx, updated, p, x1);
  run(ctx, fresh, p, x2);
  const int same_run = memcmp(x1, x2, bytes) == 0;
  printf("%s: %d levels, %lld DOFs; kept %d plans, %d row orders, %d block smoothers, "
         "analysis %d; hierarchy %s, cycles and solve %s\n",
         what, fcm_mg_num_levels(fresh), (long long)p->n, kept->plans, kept->row_orders,
         kept->block_smoothers, kept->analysis, same ? "identical" : "DIFFER",
         same_run ? "identical" : "DIFFER");
  TEST_TRUE(same);
  TEST_TRUE(same_run);
  const long long before = counter.count;
  TEST_OK(ctx, fcm_mg_setup(updated));
  TEST_TRUE(counter.count == before);
  free(x1);
  free(x2);
  fcm_mg_destroy(&fresh);
  return updated;
}

static void cut_sequence(fcm_ctx *ctx, fcm_element_type type, int cycle_index)
{
  const char *name = type == FCM_ELEMENT_HEX8 ? "hex8" : "hex20";
  problem base;
  problem_hemisphere_of(ctx, type, 8, 0, fcm_space_options_default().constrain_ratio, &base);
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 100;
  o.cycle_index = cycle_index;
  fcm_mg *mg = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, base.space, base.A, &o, &mg));
  TEST_TRUE(fcm_mg_num_levels(mg) >= 3);

  /* the same space and matrix: everything kept */
  fcm__mg_kept kept;
  char what[96];
  snprintf(what, sizeof what, "%s, cycle %d, no change", name, cycle_index);
  mg = compare(ctx, &mg, &base, &o, what, &kept);
  TEST_TRUE(kept.plans == fcm_mg_num_levels(mg) - 1);
  TEST_TRUE(kept.row_orders == fcm_mg_num_levels(mg) - 1);
  TEST_TRUE(kept.analysis == 1);
  int nblk = 0;
  for (int l = 0; l < mg->nlev; l++)
    nblk += mg->lev[l].blk != NULL;
  TEST_TRUE(nblk > 0 && kept.block_smoothers == nblk);

  /* three cuts in sequence, each from the previous hierarchy with its matrix gone */
  const double pt[3][3] = {{0.05, 0, 0}, {0, 0, 0.13}, {0.5, 0.5, 0.5}};
  const double nrm[3][3] = {{1, 0, 0}, {0, 0.2, 1}, {1, 1, 1}};
  const double blo[3][3] = {{-0.1, 0.4, -2}, {-2, 0.6, -0.5}, {-2, -2, -2}};
  const double bhi[3][3] = {{0.2, 2, 2}, {2, 2, 0.5}, {2, 2, 2}};
  const fcm_cell_rules *prev = base.rules0;
  fcm_cell_rules *rules[3] = {NULL, NULL, NULL};
  problem cur;
  memset(&cur, 0, sizeof cur);
  for (int k = 0; k < 3; k++) {
    fcm_surface *s = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, pt[k], nrm[k], blo[k], bhi[k], &s));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, base.mesh, base.geom, prev, s, &rules[k]));
    fcm_surface_destroy(&s);
    prev = rules[k];
    fcm__mg_detach(mg); /* as the simulation: the old matrix and space go first */
    problem_drop(&cur);
    problem next;
    problem_on(ctx, &base, rules[k], &next);
    snprintf(what, sizeof what, "%s, cycle %d, cut %d", name, cycle_index, k + 1);
    mg = compare(ctx, &mg, &next, &o, what, &kept);
    cur = next;
  }
  fcm_mg_destroy(&mg);
  problem_drop(&cur);
  for (int k = 0; k < 3; k++)
    fcm_cell_rules_destroy(&rules[k]);
  problem_free(&base);
}

int main(void)
{
  fcm_ctx *ctx = failing_ctx(&counter);
  TEST_TRUE(ctx != NULL);
  cut_sequence(ctx, FCM_ELEMENT_HEX8, 1);
  cut_sequence(ctx, FCM_ELEMENT_HEX8, 2);
  cut_sequence(ctx, FCM_ELEMENT_HEX20, 1);
  cut_sequence(ctx, FCM_ELEMENT_HEX20, 2);
  fcm_ctx_destroy(&ctx);
  printf("ok\n");
  return TEST_RESULT();
}
