/* A cut whose new integrator takes the old one's storage (FCM_CUT_REUSE_STORAGE) equals a cut
 * without it bit for bit. Two integrators of one embedded box under gravity (Hex8, element-
 * corotated linear, 3 multigrid V-cycles and one Newton iteration a step, as the interactive
 * scenes), one with the option, are stepped and cut twice (a plane across the box, then a slit
 * from the top face): the one with the option gets its mass and Newton matrices on the old
 * ones' storage (the same addresses; the matrices' values are 8 MiB and more, whose room is a
 * quarter larger than asked) and its corotated element matrices in the old store (each kept
 * element at its slot), the other on new storage (the kept element matrices copied), and the mass
 * matrix, the gravity load, M a_rep, the state and a further step's displacement and velocity are
 * the same bits. The Newton matrix the cut takes is filled with NaN before the cut (taken
 * unzeroed: every step writes it whole before any read), and the step after the cut equals
 * one of an integrator built from scratch in the same state. The integrator that gave its
 * storage refuses to step, to be set up and to be cut again, and is destroyed. Before the first
 * cut, the cut fails twice (an allocation in its setup, the last one of the cut): the
 * integrator has its storage back and steps on as the other does. */
#include "fem/assemble_impl.h"
#include "la/la_impl.h"
#include "sim/sim_impl.h"
#include "sim_util.h"
#include "test_alloc.h"

#include <string.h>

static fcm_ctx *ctx;
static failing fl; /* ctx's allocator: counts, fails one allocation where armed */

static const fcm_material mat = {FCM_MATERIAL_COROTATED_LINEAR, 2.0e4, 0.3, 1000.0};

static int same_bits(const double *a, const double *b, fcm_index n)
{
  return a && b && memcmp(a, b, sizeof *a * (size_t)n) == 0;
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
  const fcm_index n = fcm_integrator_num_dofs(a);
  TEST_TRUE(fcm_integrator_num_dofs(b) == n);
  TEST_TRUE(same_bits(fcm_integrator_displacement(a), fcm_integrator_displacement(b), n));
  TEST_TRUE(same_bits(fcm_integrator_velocity(a), fcm_integrator_velocity(b), n));
}

/* Steps a and b once and an integrator built from scratch on a's space in a's state: the
 * three the same bits (a's Newton matrix on values the cut left unzeroed). */
static void step_fresh(fcm_integrator *a, fcm_integrator *b, const fcm_mesh *mesh)
{
  fcm_integrator *f = make(a->space, mesh, 0);
  fcm_step_info info;
  const fcm_index n = fcm_integrator_num_dofs(a);
  TEST_TRUE(f != NULL);
  if (!f) return;
  TEST_OK(ctx, fcm_integrator_set_state(f, a->u, a->v, a->t, a->steps));
  step_both(a, b, 1);
  TEST_OK(ctx, fcm_integrator_step(f, &info));
  TEST_TRUE(same_bits(fcm_integrator_displacement(a), fcm_integrator_displacement(f), n));
  TEST_TRUE(same_bits(fcm_integrator_velocity(a), fcm_integrator_velocity(f), n));
  fcm_integrator_destroy(&f);
}

/* A cut of a (with the option) failing at its allocation k (of n_alloc: a twin's cut made
 * n_alloc) gives a its storage back: the same addresses, its mass matrix b's bits again, and
 * a step of each after it the same bits (a builds its Newton and element matrices again). */
static void cut_failing(fcm_integrator *a, fcm_integrator *b, const fcm_space *space, long long k)
{
  fcm_integrator *a1 = NULL;
  const double *am = fcm_csr_values_read(a->M), *ah = fcm_csr_values_read(a->H);
  const double *ak = a->aws->corot.K;
  fl.count = 0;
  fl.fail_at = k;
  const fcm_status st = fcm_integrator_create_cut(a, space, &a1);
  fl.fail_at = -1;
  TEST_TRUE(st == FCM_ERR_ALLOC && a1 == NULL);
  fcm_ctx_error_clear(ctx);
  fcm_integrator_destroy(&a1);
  TEST_TRUE(!a->spent && a->is_setup);
  TEST_TRUE(fcm_csr_values_read(a->M) == am && fcm_csr_values_read(a->H) == ah);
  TEST_TRUE(a->aws->corot.K == ak);
  fcm_index nnz = 0;
  fcm_csr_get_size(a->M, NULL, NULL, &nnz);
  TEST_TRUE(same_bits(fcm_csr_values_read(a->M), fcm_csr_values_read(b->M), nnz));
  step_both(a, b, 1);
}

/* The allocations of a successful cut of c (with the option; c is destroyed). */
static long long cut_allocations(fcm_integrator *c, const fcm_space *space)
{
  fcm_integrator *c1 = NULL;
  fl.count = 0;
  TEST_OK(ctx, fcm_integrator_create_cut(c, space, &c1));
  const long long n = fl.count;
  TEST_TRUE(c1 != NULL && c->spent);
  fcm_integrator_destroy(&c1);
  return n;
}

/* Cuts a (with the option) and b (without) onto `space`: a's new matrices on a's storage; a's
 * Newton matrix values are NaN before the cut (its steps write them whole before any read). */
static void cut_both(fcm_integrator **a, fcm_integrator **b, const fcm_space *space)
{
  fcm_integrator *a1 = NULL, *b1 = NULL;
  const double *am = fcm_csr_values_read((*a)->M), *ah = fcm_csr_values_read((*a)->H);
  const double *bm = fcm_csr_values_read((*b)->M);
  const double *ak = (*a)->aws->corot.K, *bk = (*b)->aws->corot.K;
  TEST_TRUE(ak && bk); /* the element matrices built by the steps */
  fcm_index hnz = 0;
  fcm_csr_get_size((*a)->H, NULL, NULL, &hnz);
  double *hv = fcm_csr_values((*a)->H); /* a1 takes these values unzeroed: none may be read */
  for (fcm_index i = 0; i < hnz; i++)
    hv[i] = NAN;
  TEST_OK(ctx, fcm_integrator_create_cut(*a, space, &a1));
  TEST_OK(ctx, fcm_integrator_create_cut(*b, space, &b1));
  if (!a1 || !b1) goto done;
  const fcm_index n = a1->n;
  fcm_index nnz = 0;
  fcm_csr_get_size(a1->M, NULL, NULL, &nnz);
  TEST_TRUE((size_t)nnz * sizeof(double) >= (8u << 20)); /* large: a quarter more room */
  /* a's storage taken (a is spent), b's kept by b */
  TEST_TRUE(fcm_csr_values_read(a1->M) == am && fcm_csr_values_read(a1->H) == ah);
  TEST_TRUE(fcm_csr_values_read((*a)->M) == NULL && fcm_csr_values_read((*a)->H) == NULL);
  TEST_TRUE(fcm_csr_values_read((*b)->M) == bm && fcm_csr_values_read(b1->M) != bm);
  /* the corotated element matrices in a's store (each kept element at its slot), copied from
   * b's */
  TEST_TRUE(a1->aws->corot.K == ak && (*a)->aws->corot.K == NULL);
  TEST_TRUE(b1->aws->corot.K != bk && (*b)->aws->corot.K == bk);
  TEST_TRUE(same_bits(fcm_csr_values_read(a1->M), fcm_csr_values_read(b1->M), nnz));
  TEST_TRUE(same_bits(a1->loads[0].f, b1->loads[0].f, n));
  TEST_TRUE(same_bits(a1->Ma, b1->Ma, n));
  TEST_TRUE(same_bits(a1->u, b1->u, n) && same_bits(a1->v, b1->v, n));
  /* the spent integrator: its state still read, no step, no new setup */
  fcm_step_info info;
  TEST_TRUE(fcm_integrator_time((*a)) == fcm_integrator_time(a1));
  TEST_ERR(ctx, fcm_integrator_step(*a, &info), FCM_ERR_ARG, "fcm_integrator_setup");
  TEST_ERR(ctx, fcm_integrator_setup(*a), FCM_ERR_ARG, "FCM_CUT_REUSE_STORAGE");
  fcm_integrator *again = NULL;
  TEST_ERR(ctx, fcm_integrator_create_cut(*a, space, &again), FCM_ERR_ARG, "set up");
  TEST_TRUE(again == NULL);
done:
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
  fcm_space *space[3] = {NULL, NULL, NULL};
  fcm_integrator *a = NULL, *b = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[0], &space[0]));
  a = make(space[0], mesh, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE);
  b = make(space[0], mesh, FCM_CUT_REUSE_BLOCKS);
  fcm_integrator *c = make(space[0], mesh, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE);
  if (a && b && c) {
    step_both(a, b, 1);
    for (int s = 0; s < 1; s++) {
      fcm_step_info info;
      TEST_OK(ctx, fcm_integrator_step(c, &info));
    }
    step_both(a, c, 0); /* c a twin of a */
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
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[k], &space[k]));
    if (!space[k]) break;
    printf("cut %d: %lld -> %lld DOFs\n", k, (long long)fcm_space_num_dofs(space[k - 1]),
           (long long)fcm_space_num_dofs(space[k]));
    if (k == 1 && c) { /* a failed cut, in the setup and at the end, before the cut */
      /* one thread: the Galerkin pattern's buffers grow as the threads' schedule falls, so
       * with two the count of a cut's allocations varies from run to run */
      const int nt = fcm_ctx_num_threads(ctx);
      TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1));
      const long long n_alloc = cut_allocations(c, space[k]);
      cut_failing(a, b, space[k], n_alloc / 2);
      cut_failing(a, b, space[k], n_alloc - 1);
      TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, nt));
    }
    cut_both(&a, &b, space[k]);
    if (a && b) step_fresh(a, b, mesh);
  }
  fcm_integrator_destroy(&a);
  fcm_integrator_destroy(&b);
  fcm_integrator_destroy(&c);
  for (int k = 2; k >= 0; k--) {
    fcm_space_destroy(&space[k]);
    fcm_cell_rules_destroy(&rules[k]);
  }
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == live0); /* nothing kept beyond the integrators */
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
