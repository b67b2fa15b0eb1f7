/* The integrator after a cut onto a space patched from the one before it
 * (fcm__space_create_cut()) takes the mass matrix rows and the load entries the cut leaves
 * from the old integrator (I->cut_rows) and sums only the others again; the result equals an
 * integrator built from scratch on the same space, bit for bit. An embedded box under gravity
 * (argv[1]: tet4, tet10, hex8 or hex20) is cut three times (a plane, a slit from the top face
 * ending inside the body, a plane across the first) by two chains of integrators: `a` gives its
 * storage to each cut (FCM_CUT_REUSE_STORAGE: the rows and the element blocks moved within the
 * old arrays), `b` keeps it (copied). After each cut the mass matrix, the gravity load, M a_rep and
 * the state of both equal a fresh integrator's on the same space, some copies but not all were
 * taken, and a step of `a` and `b` gives the same bits. Before the second cut: a cut of `a` failing
 * at an allocation leaves `a` as it was (its mass matrix `b`'s bits, a step alike: the direct
 * solver's factor kept from before the cut serves it as it serves `b`), and a bit mark in `b`'s
 * mass matrix shows in the rows the cut counts as taken. */
#include "fem/fem_impl.h"
#include "la/la_impl.h"
#include "sim/sim_impl.h"
#include "cut_away.h"
#include "sim_util.h"
#include "test_alloc.h"

#include <string.h>

static fcm_ctx *ctx;
static failing fl;
static int hex; /* Hex8, Hex20: the multigrid's interactive set; tets: direct, SNH */

static const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2.0e4, 0.3, 1000.0};
static const double gravity[3] = {0.0, -9.81, 0.0};

static int same_bits(const double *a, const double *b, fcm_index n)
{
  return a && b && memcmp(a, b, sizeof *a * (size_t)n) == 0;
}

static fcm_integrator *make(const fcm_space *space, const fcm_mesh *mesh, int cut_reuse)
{
  fcm_integrator *I = NULL;
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.01;
  o.cut_reuse = cut_reuse;
  if (hex) { /* 3 V-cycles, one Newton iteration */
    o.linear_solver = FCM_LINEAR_MULTIGRID;
    o.multigrid_fixed_cycles = 3;
    o.newton_fixed_iterations = 1;
  }
  const double lo[3] = {-10, -10, -10}, hi[3] = {10, 0.05, 10};
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, gravity, NULL, NULL));
  TEST_OK(ctx, hold_box(ctx, I, mesh, lo, hi));
  return I;
}

static const double *mass_values(const fcm_integrator *I, fcm_index *nnz)
{
  fcm_csr_get_size(fcm_integrator_mass(I), NULL, NULL, nnz);
  return fcm_csr_values_read(fcm_integrator_mass(I));
}

/* The cut integrator c against one built from scratch on its space, in old's state. */
static void compare_fresh(const fcm_integrator *old, const fcm_integrator *c, const fcm_mesh *mesh)
{
  fcm_integrator *f = make(c->space, mesh, 0);
  const fcm_index n = c->n;
  double *u = malloc(sizeof *u * (size_t)n), *v = malloc(sizeof *v * (size_t)n);
  TEST_OK(ctx, fcm_integrator_setup(f));
  TEST_OK(ctx, fcm_space_transfer(old->space, c->space, old->u, u));
  TEST_OK(ctx, fcm_space_transfer(old->space, c->space, old->v, v));
  TEST_OK(ctx, fcm_integrator_set_state(f, u, v, old->t, old->steps));
  fcm_index nnz = 0, nnz_f = 0;
  const double *mc = mass_values(c, &nnz), *mf = mass_values(f, &nnz_f);
  TEST_TRUE(f->n == n && nnz == nnz_f);
  TEST_TRUE(same_bits(mc, mf, nnz));
  TEST_TRUE(same_bits(c->loads[0].f, f->loads[0].f, n));
  TEST_TRUE(same_bits(c->Ma, f->Ma, n));
  TEST_TRUE(same_bits(c->u, f->u, n) && same_bits(c->v, f->v, n));
  /* the patch ran: some copies' rows taken, the cut's neighbourhood summed again; at least as
   * many as 95 % of the copies away from the cut (cut_away_copies(): the cut leaves every row
   * there, fem_block_colors) */
  const fcm_index ncopy = n / 3;
  unsigned char *away = malloc((size_t)ncopy + 1);
  const fcm_index num_away = cut_away_copies(ctx, old->space, c->space, away);
  if (getenv("FCM_TEST_VERBOSE"))
    printf("  copies taken %lld of %lld, away from the cut %lld\n", (long long)c->cut_kept_copies,
           (long long)ncopy, (long long)num_away);
  TEST_TRUE(c->cut_kept_copies > 0 && c->cut_kept_copies < ncopy);
  TEST_TRUE(num_away > ncopy / 8 && (double)c->cut_kept_copies >= 0.95 * (double)num_away);
  free(away);
  free(u);
  free(v);
  fcm_integrator_destroy(&f);
}

/* Steps both once: the same displacement and velocity bits, as many factorizations made and
 * kept ones used (the direct solver's kept factor survives a's failed cut). */
static void step_both(fcm_integrator *a, fcm_integrator *b)
{
  fcm_step_info ia, ib;
  TEST_OK(ctx, fcm_integrator_step(a, &ia));
  TEST_OK(ctx, fcm_integrator_step(b, &ib));
  TEST_TRUE(a->n == b->n);
  TEST_TRUE(ia.factorizations == ib.factorizations &&
            ia.reused_factorizations == ib.reused_factorizations);
  TEST_TRUE(same_bits(a->u, b->u, a->n) && same_bits(a->v, b->v, a->n));
}

/* The allocations of a cut onto t of an integrator of a's kind on `from`, failing at its
 * allocation k (-1: none): -1 when it failed. */
static long long cut_allocations(const fcm_space *from, const fcm_space *t, const fcm_mesh *mesh,
                                 long long k)
{
  fcm_integrator *twin = make(from, mesh, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE);
  fcm_integrator *c = NULL;
  TEST_OK(ctx, fcm_integrator_setup(twin));
  TEST_OK(ctx, fcm_integrator_prepare_solver(twin)); /* a hierarchy the cut carries, as a's */
  fl.count = 0;
  fl.fail_at = k;
  const fcm_status st = fcm_integrator_create_cut(twin, t, &c);
  fl.fail_at = -1;
  const long long n = st == FCM_OK ? fl.count : -1;
  fcm_ctx_error_clear(ctx);
  fcm_integrator_destroy(&c);
  fcm_integrator_destroy(&twin);
  return n;
}

/* A cut of a onto t failing at its allocation k: a goes on as b (same mass bits, a step). */
static void cut_failing(fcm_integrator *a, fcm_integrator *b, const fcm_space *t, long long k)
{
  fcm_integrator *a1 = NULL;
  fl.count = 0;
  fl.fail_at = k;
  const fcm_status st = fcm_integrator_create_cut(a, t, &a1);
  fl.fail_at = -1;
  TEST_TRUE(st == FCM_ERR_ALLOC && a1 == NULL);
  fcm_ctx_error_clear(ctx);
  TEST_TRUE(!a->spent && a->is_setup);
  fcm_index nnz = 0, nnz_b = 0;
  const double *ma = mass_values(a, &nnz), *mb = mass_values(b, &nnz_b);
  TEST_TRUE(nnz == nnz_b && same_bits(ma, mb, nnz));
  step_both(a, b);
}

/* b's mass values overwritten by a value no sum gives: the rows of the cut onto t that hold
 * it are the ones it took from b, as many as it counts (three rows a copy), and 95 % of the
 * copies away from the cut at least hold it in all three rows. */
static void tampered(fcm_integrator *b, const fcm_space *t)
{
  const double mark = 12345.0;
  fcm_integrator *c = NULL;
  fcm_index nnz = 0;
  mass_values(b, &nnz);
  double *mv = fcm_csr_values(b->M), *keep = malloc(sizeof *keep * (size_t)nnz);
  memcpy(keep, mv, sizeof *keep * (size_t)nnz);
  for (fcm_index i = 0; i < nnz; i++)
    mv[i] = mark;
  TEST_OK(ctx, fcm_integrator_create_cut(b, t, &c));
  memcpy(mv, keep, sizeof *keep * (size_t)nnz);
  free(keep);
  if (!c) return;
  const double *cv = fcm_csr_values_read(c->M);
  const fcm_index ncopy = c->n / 3;
  unsigned char *away = malloc((size_t)ncopy + 1);
  const fcm_index num_away = cut_away_copies(ctx, b->space, t, away);
  fcm_index marked = 0, away_taken = 0;
  for (fcm_index r = 0; r < c->n; r++)
    marked += cv[t->row_ptr[r]] == mark;
  for (fcm_index k = 0; k < ncopy; k++) /* all three rows of an away copy taken */
    away_taken += away[k] && cv[t->row_ptr[3 * k]] == mark && cv[t->row_ptr[3 * k + 1]] == mark &&
                  cv[t->row_ptr[3 * k + 2]] == mark;
  if (getenv("FCM_TEST_VERBOSE"))
    printf("  marked rows of %lld of %lld copies away from the cut\n", (long long)away_taken,
           (long long)num_away);
  TEST_TRUE(c->cut_kept_copies > 0 && marked == 3 * c->cut_kept_copies);
  TEST_TRUE(num_away > 0 && (double)away_taken >= 0.95 * (double)num_away);
  free(away);
  fcm_integrator_destroy(&c);
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  ctx = failing_ctx(&fl);
  TEST_TRUE(ctx != NULL);
  const double lo[3] = {-0.3, -0.3, -0.3}, hi[3] = {1.3, 0.9, 0.9};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  hex = type == FCM_ELEMENT_HEX8 || type == FCM_ELEMENT_HEX20;
  const fcm_index nc[3] = {hex ? 12 : 10, hex ? 9 : 8, hex ? 9 : 8}, gn[3] = {2, 2, 2};
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules[4] = {NULL, NULL, NULL, NULL};
  fcm_space *sa[4] = {NULL, NULL, NULL, NULL}, *sb[4] = {NULL, NULL, NULL, NULL};
  fcm_integrator *a = NULL, *b = NULL;
  int moved_in_place = 0;
  const fcm_space_options so = fcm_space_options_default();
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[0], &sa[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[0], &sb[0]));
  if (sa[0] && sb[0]) {
    a = make(sa[0], mesh, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE);
    b = make(sb[0], mesh, FCM_CUT_REUSE_BLOCKS);
    TEST_OK(ctx, fcm_integrator_setup(a));
    TEST_OK(ctx, fcm_integrator_setup(b));
    step_both(a, b);
  }
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  const double c2[3] = {0.73, 0.55, 0.3}, n2[3] = {1.0, 0.0, 0.1}, a2[3] = {0.0, 1.0, 0.0},
               size2[2] = {0.5, 2.0};
  const double p3[3] = {0.5, 0.33, 0.3}, n3[3] = {0.04, 1.0, 0.02};
  for (int k = 1; k <= 3 && a && b; k++) {
    fcm_surface *cut = NULL;
    if (k == 1) TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &cut));
    if (k == 2) TEST_OK(ctx, fcm_surface_create_rectangle(ctx, c2, n2, a2, size2, &cut));
    if (k == 3) TEST_OK(ctx, fcm_surface_create_plane(ctx, p3, n3, box_lo, box_hi, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &rules[k]));
    fcm_surface_destroy(&cut);
    if (!rules[k]) break;
    TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[k], &so, sa[k - 1], &sa[k]));
    TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, rules[k], &so, sb[k - 1], &sb[k]));
    if (!sa[k] || !sb[k]) break;
    TEST_TRUE(sa[k]->cut_row_from != NULL && sb[k]->cut_row_from != NULL);
    if (getenv("FCM_TEST_VERBOSE"))
      printf("cut %d: %lld -> %lld DOFs\n", k, (long long)fcm_space_num_dofs(sa[k - 1]),
             (long long)fcm_space_num_dofs(sa[k]));
    if (k == 2) {
      const int nt = fcm_ctx_num_threads(ctx);
      TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1));
      const long long n_alloc = cut_allocations(sa[k - 1], sa[k], mesh, -1);
      /* an allocation in the set-up's middle whose failure fails the cut, and the last */
      long long mid = n_alloc / 2;
      while (mid < n_alloc - 1 && cut_allocations(sa[k - 1], sa[k], mesh, mid) >= 0)
        mid++;
      cut_failing(a, b, sa[k], mid);
      cut_failing(a, b, sa[k], n_alloc - 1);
      TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, nt));
      tampered(b, sb[k]);
    }
    fcm_integrator *a1 = NULL, *b1 = NULL;
    const double *blk = a->blk_mass, *lblk = a->loads[0].blk;
    TEST_OK(ctx, fcm_integrator_create_cut(a, sa[k], &a1));
    if (a1) moved_in_place += a1->blk_mass == blk && a1->loads[0].blk == lblk;
    TEST_OK(ctx, fcm_integrator_create_cut(b, sb[k], &b1));
    if (a1) compare_fresh(a, a1, mesh);
    if (b1) compare_fresh(b, b1, mesh);
    TEST_TRUE(a->spent && !b->spent);
    fcm_integrator_destroy(&a);
    fcm_integrator_destroy(&b);
    a = a1, b = b1;
    if (a && b) step_both(a, b);
  }
  /* the element blocks moved within a's arrays at some cut (a few per cent more elements) */
  if (getenv("FCM_TEST_VERBOSE"))
    printf("element blocks moved in place at %d of 3 cuts\n", moved_in_place);
  TEST_TRUE(moved_in_place > 0);
  fcm_integrator_destroy(&a);
  fcm_integrator_destroy(&b);
  for (int k = 3; k >= 0; k--) {
    fcm_space_destroy(&sa[k]);
    fcm_space_destroy(&sb[k]);
    fcm_cell_rules_destroy(&rules[k]);
  }
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
