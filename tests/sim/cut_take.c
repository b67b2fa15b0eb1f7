/* A cut space made in the pattern storage of the space before the cut
 * (fcm__space_create_cut_take()), as the scenes cut, with an integrator that takes the old one's
 * storage (FCM_CUT_REUSE_STORAGE), equals the cut onto a space built anew with an integrator
 * that keeps its own, bit for bit. Two integrators of one embedded box under gravity (Hex8,
 * element-corotated linear, 3 multigrid V-cycles and one Newton iteration a step) are stepped
 * and cut twice (a plane across the box, then a slit from the top face). Before the first cut,
 * the integrator's cut fails twice (an allocation in its setup, its last allocation) onto a
 * space that took the old space's columns: the old space has them back, the same bits at the
 * same address, before the old integrator assembles its mass matrix again, which equals the
 * other's; it steps on as the other does. After each cut the mass matrix, the gravity load,
 * M a_rep, the state and a further step are the same bits. */
#include "fem/assemble_impl.h"
#include "la/la_impl.h"
#include "sim/sim_impl.h"
#include "sim_util.h"
#include "test_alloc.h"

#include <string.h>

static fcm_ctx *ctx;
static failing fl; /* ctx's allocator: counts, fails one allocation where armed */

static const fcm_material mat = {FCM_MATERIAL_COROTATED_LINEAR, 2.0e4, 0.3, 1000.0};

static int same_bits(const void *a, const void *b, size_t bytes)
{
  return a && b && memcmp(a, b, bytes) == 0;
}

static fcm_integrator *make(const fcm_space *space, const fcm_mesh *mesh, int cut_reuse)
{
  return cut_chain_integrator(ctx, space, mesh, &mat, cut_reuse);
}

/* Steps both; the displacement and velocity stay the same bits. */
static void step_both(fcm_integrator *a, fcm_integrator *b, int steps)
{
  for (int s = 0; s < steps; s++) {
    fcm_step_info ia, ib;
    TEST_OK(ctx, fcm_integrator_step(a, &ia));
    TEST_OK(ctx, fcm_integrator_step(b, &ib));
    TEST_TRUE(ia.linear_iterations == ib.linear_iterations);
  }
  const size_t n = (size_t)fcm_integrator_num_dofs(a);
  TEST_TRUE((size_t)fcm_integrator_num_dofs(b) == n);
  TEST_TRUE(same_bits(fcm_integrator_displacement(a), fcm_integrator_displacement(b),
                      n * sizeof(double)));
  TEST_TRUE(same_bits(fcm_integrator_velocity(a), fcm_integrator_velocity(b), n * sizeof(double)));
}

/* The allocations of a successful cut of c onto a space taking c's space's columns (c and
 * that space are destroyed, the columns go back). */
static long long cut_allocations(fcm_integrator *c, fcm_space *from, const fcm_mesh *mesh,
                                 const fcm_cell_rules *rules)
{
  fcm_integrator *c1 = NULL;
  fcm_space *t = NULL;
  const fcm_space_options so = fcm_space_options_default();
  TEST_OK(ctx, fcm__space_create_cut_take(ctx, mesh, rules, &so, from, &t));
  fl.count = 0;
  TEST_OK(ctx, fcm_integrator_create_cut(c, t, &c1));
  const long long n = fl.count;
  TEST_TRUE(c1 != NULL && c->spent);
  fcm_integrator_destroy(&c1);
  fcm_space_destroy(&t);
  return n;
}

/* A cut of a (with the option) onto a space that took the columns of a's space, failing at
 * allocation k: a's space has its columns back (the same address and bits) and a its storage;
 * its mass matrix is b's bits again and a step of each after it the same bits. */
static void cut_failing(fcm_integrator *a, fcm_integrator *b, fcm_space *from, const fcm_mesh *mesh,
                        const fcm_cell_rules *rules, long long k)
{
  fcm_integrator *a1 = NULL;
  fcm_space *t = NULL;
  const int *cols = from->col_idx;
  const size_t nnz = (size_t)from->row_ptr[from->num_dofs];
  int *copy = malloc(sizeof *copy * (nnz + 1));
  memcpy(copy, cols, sizeof *copy * nnz);
  fcm_space_options so = fcm_space_options_default();
  TEST_OK(ctx, fcm__space_create_cut_take(ctx, mesh, rules, &so, from, &t));
  TEST_TRUE(t && t->col_idx == cols && from->col_idx == NULL); /* taken */
  fl.count = 0;
  fl.fail_at = k;
  const fcm_status st = fcm_integrator_create_cut(a, t, &a1);
  fl.fail_at = -1;
  TEST_TRUE(st == FCM_ERR_ALLOC && a1 == NULL);
  fcm_ctx_error_clear(ctx);
  TEST_TRUE(from->col_idx == cols && same_bits(cols, copy, sizeof *copy * nnz));
  fcm_space_destroy(&t);
  TEST_TRUE(from->col_idx == cols);
  TEST_TRUE(!a->spent && a->is_setup);
  fcm_index mnnz = 0;
  fcm_csr_get_size(a->M, NULL, NULL, &mnnz);
  TEST_TRUE(same_bits(fcm_csr_values_read(a->M), fcm_csr_values_read(b->M),
                      sizeof(double) * (size_t)mnnz));
  step_both(a, b, 1);
  free(copy);
}

/* Cuts a onto ta (a space that took the columns of a's space) and b onto tb (built anew). */
static void cut_both(fcm_integrator **a, fcm_integrator **b, fcm_space *ta, const fcm_space *tb)
{
  fcm_integrator *a1 = NULL, *b1 = NULL;
  TEST_OK(ctx, fcm_integrator_create_cut(*a, ta, &a1));
  TEST_OK(ctx, fcm_integrator_create_cut(*b, tb, &b1));
  if (a1 && b1) {
    const size_t n = (size_t)a1->n;
    fcm_index nnz = 0;
    fcm_csr_get_size(a1->M, NULL, NULL, &nnz);
    TEST_TRUE(fcm_csr_col_idx(a1->M) == ta->col_idx);
    TEST_TRUE(same_bits(fcm_csr_col_idx(a1->M), fcm_csr_col_idx(b1->M), sizeof(int) * (size_t)nnz));
    TEST_TRUE(same_bits(fcm_csr_values_read(a1->M), fcm_csr_values_read(b1->M),
                        sizeof(double) * (size_t)nnz));
    TEST_TRUE(same_bits(a1->loads[0].f, b1->loads[0].f, n * sizeof(double)));
    TEST_TRUE(same_bits(a1->Ma, b1->Ma, n * sizeof(double)));
    TEST_TRUE(same_bits(a1->u, b1->u, n * sizeof(double)));
  }
  fcm__space_cut_keep(ta); /* the cut succeeded */
  fcm_integrator_destroy(a);
  fcm_integrator_destroy(b);
  *a = a1;
  *b = b1;
}

int main(void)
{
  ctx = failing_ctx(&fl);
  TEST_TRUE(ctx != NULL);
  const long long live0 = fcm_ctx_live_allocations(ctx);
  const double lo[3] = {-0.1, -0.1, -0.1}, hi[3] = {1.1, 0.7, 0.7};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  const fcm_index nc[3] = {27, 18, 18}, gn[3] = {2, 2, 2};
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules[3] = {NULL, NULL, NULL};
  fcm_space *sa[3] = {NULL, NULL, NULL}, *sb[3] = {NULL, NULL, NULL};
  fcm_integrator *a = NULL, *b = NULL, *c = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[0], &sa[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[0], &sb[0]));
  if (sa[0] && sb[0]) {
    a = make(sa[0], mesh, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE);
    b = make(sb[0], mesh, FCM_CUT_REUSE_BLOCKS);
    c = make(sa[0], mesh, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE);
  }
  if (a && b && c) {
    step_both(a, b, 1);
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(c, &info));
  }
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  const double c2[3] = {0.73, 0.55, 0.3}, n2[3] = {1.0, 0.0, 0.1}, a2[3] = {0.0, 1.0, 0.0},
               size2[2] = {0.5, 2.0};
  for (int k = 1; k <= 2 && a && b; k++) {
    fcm_surface *cut = NULL;
    if (k == 1) TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &cut));
    if (k == 2) TEST_OK(ctx, fcm_surface_create_rectangle(ctx, c2, n2, a2, size2, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &rules[k]));
    fcm_surface_destroy(&cut);
    if (!rules[k]) break;
    if (k == 1 && c) { /* failed cuts, in the setup and at the end (one thread: see
                          sim_cut_storage) */
      const int nt = fcm_ctx_num_threads(ctx);
      TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1));
      const long long n_alloc = cut_allocations(c, sa[0], mesh, rules[1]);
      cut_failing(a, b, sa[0], mesh, rules[1], n_alloc / 2);
      cut_failing(a, b, sa[0], mesh, rules[1], n_alloc - 1);
      TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, nt));
    }
    const fcm_space_options so = fcm_space_options_default();
    const int *block = sa[k - 1]->col_idx;
    TEST_OK(ctx, fcm__space_create_cut_take(ctx, mesh, rules[k], &so, sa[k - 1], &sa[k]));
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[k], &sb[k]));
    if (!sa[k] || !sb[k]) break;
    TEST_TRUE(sa[k]->col_idx == block); /* a few per cent more entries: within the room */
    printf("cut %d: %lld -> %lld DOFs\n", k, (long long)fcm_space_num_dofs(sa[k - 1]),
           (long long)fcm_space_num_dofs(sa[k]));
    cut_both(&a, &b, sa[k], sb[k]);
    if (a && b) step_both(a, b, 1);
  }
  fcm_integrator_destroy(&a);
  fcm_integrator_destroy(&b);
  fcm_integrator_destroy(&c);
  for (int k = 2; k >= 0; k--) {
    fcm_space_destroy(&sa[k]);
    fcm_space_destroy(&sb[k]);
    fcm_cell_rules_destroy(&rules[k]);
  }
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == live0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
