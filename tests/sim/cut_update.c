/* A cut that keeps what it leaves (fcm_integrator_options.cut_reuse) equals a rebuild bit for
 * bit. An embedded box under gravity, with its base held, is stepped and cut three times: a
 * plane across it, a partial rectangle (a slit from the top face ending inside the body) and a
 * plane across the first one (into cells already cut). After each cut the integrator of
 * fcm_integrator_create_cut() with FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_ORDERING (kept element
 * blocks, CHOLMOD's ordering extended) is compared with one built from scratch on the same
 * space and started from the same transferred state, given the same ordering: the mass matrix,
 * the gravity load, M a_rep and the state are the same bits, the cut kept some elements'
 * blocks and integrated others again, and three further steps give the same displacement and
 * velocity bits. The extended ordering is a permutation of the new DOFs, and a cut without
 * the option keeps nothing (and its full assembly gives the same mass matrix). The momentum's
 * mass blocks kept over the cut equal a new space's, and copying every element's block from its
 * parent (stale blocks of the cut cells) does not. After every step the Newton matrix is exactly
 * symmetric. Usage: sim_cut_update <element> */
#include "fem/fem_impl.h"
#include "la/la_impl.h"
#include "sim/sim_impl.h"
#include "sim_util.h"

#include <string.h>

static fcm_ctx *ctx;

static int same_bits(const double *a, const double *b, fcm_index n)
{
  return memcmp(a, b, sizeof *a * (size_t)n) == 0;
}

static const fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2.0e4, 0.3, 1000.0};
static const double gravity[3] = {0.0, -9.81, 0.0};

/* The held base: nodes with y <= 0.05 (below the body: every copy of them is held). */
static fcm_status hold_base(fcm_integrator *I, const fcm_mesh *mesh)
{
  const double lo[3] = {-10, -10, -10}, hi[3] = {10, 0.05, 10};
  return hold_box(ctx, I, mesh, lo, hi);
}

/* Steps both integrators and checks they stay the same bits. */
static void step_both(fcm_integrator *a, fcm_integrator *b, int steps)
{
  const fcm_index n = fcm_integrator_num_dofs(a);
  for (int s = 0; s < steps; s++) {
    fcm_step_info ia, ib;
    TEST_OK(ctx, fcm_integrator_step(a, &ia));
    TEST_OK(ctx, fcm_integrator_step(b, &ib));
    TEST_TRUE(ia.reason == FCM_STEP_CONVERGED && ib.reason == FCM_STEP_CONVERGED);
    TEST_TRUE(ia.newton_iterations == ib.newton_iterations);
    double asym = 1.0; /* the cut pieces' Newton matrix: exactly symmetric */
    TEST_TRUE(a->H != NULL);
    TEST_OK(ctx, fcm_csr_asymmetry(a->H, &asym));
    TEST_TRUE(asym == 0.0);
  }
  TEST_TRUE(same_bits(fcm_integrator_displacement(a), fcm_integrator_displacement(b), n));
  TEST_TRUE(same_bits(fcm_integrator_velocity(a), fcm_integrator_velocity(b), n));
}

/* The momentum's mass blocks of the cut space `to`, kept from `from`'s, are those of a space
 * built anew on the same rules; a stale map (every element as its parent) is not. */
static void check_momentum_blocks(const fcm_space *from, fcm_space *to, const fcm_mesh *mesh,
                                  const fcm_cell_rules *rules)
{
  const fcm_index ne = fcm_space_num_elements(to);
  const size_t nb = (size_t)ne * (size_t)(to->nn * (to->nn + 1) / 2);
  fcm_index *same = malloc(sizeof *same * (size_t)ne), kept = 0;
  fcm_space *fresh = NULL, *stale = NULL;
  TEST_OK(ctx, fcm_space_momentum(from, 1.0, NULL, NULL, NULL, NULL, NULL));
  TEST_OK(ctx, fcm__space_cut_same_elements(from, to, same, &kept));
  TEST_TRUE(kept > 0 && kept < ne);
  TEST_OK(ctx, fcm__space_momentum_blocks_from(to, from, same));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &fresh));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &stale));
  if (fresh && stale) {
    TEST_OK(ctx, fcm_space_momentum(fresh, 1.0, NULL, NULL, NULL, NULL, NULL));
    TEST_TRUE(same_bits(to->mass_cache->blocks, fresh->mass_cache->blocks, (fcm_index)nb));
    fcm_index *parent = malloc(sizeof *parent * (size_t)ne);
    for (fcm_index e = 0; e < ne; e++) /* the element of the parent piece, as the transfer */
      parent[e] = fcm__space_cut_parent_elem(from, to, e);
    TEST_OK(ctx, fcm__space_momentum_blocks_from(stale, from, parent));
    TEST_TRUE(!same_bits(stale->mass_cache->blocks, fresh->mass_cache->blocks, (fcm_index)nb));
    free(parent);
  }
  fcm_space_destroy(&fresh);
  fcm_space_destroy(&stale);
  free(same);
}

/* The integrator of `space` built from scratch, in the state old's cut leaves. */
static fcm_integrator *rebuild(const fcm_integrator *old, const fcm_integrator *cut,
                               const fcm_space *space, const fcm_mesh *mesh)
{
  fcm_integrator *I = NULL;
  fcm_integrator_options o = old->opts;
  const fcm_index n = fcm_space_num_dofs(space);
  double *u = malloc(sizeof *u * (size_t)n), *v = malloc(sizeof *v * (size_t)n);
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, gravity, NULL, NULL));
  TEST_OK(ctx, hold_base(I, mesh));
  TEST_TRUE(cut->cut_ordering != NULL);
  if (cut->cut_ordering) TEST_OK(ctx, fcm__integrator_set_ordering(I, cut->cut_ordering));
  TEST_OK(ctx, fcm_integrator_setup(I));
  TEST_OK(ctx, fcm_space_transfer(old->space, space, old->u, u));
  TEST_OK(ctx, fcm_space_transfer(old->space, space, old->v, v));
  TEST_OK(ctx, fcm_integrator_set_state(I, u, v, old->t, old->steps));
  free(u);
  free(v);
  return I;
}

/* The kept integrator `cut` against the rebuild `ref` right after the cut. */
static void compare(const fcm_integrator *cut, const fcm_integrator *ref)
{
  const fcm_index n = cut->n;
  fcm_index nnz = 0, nnz_ref = 0;
  TEST_TRUE(ref->n == n);
  fcm_csr_get_size(fcm_integrator_mass(cut), NULL, NULL, &nnz);
  fcm_csr_get_size(fcm_integrator_mass(ref), NULL, NULL, &nnz_ref);
  TEST_TRUE(nnz == nnz_ref);
  TEST_TRUE(same_bits(fcm_csr_values_read(fcm_integrator_mass(cut)),
                      fcm_csr_values_read(fcm_integrator_mass(ref)), nnz));
  TEST_TRUE(same_bits(cut->loads[0].f, ref->loads[0].f, n));
  TEST_TRUE(same_bits(cut->Ma, ref->Ma, n));
  TEST_TRUE(same_bits(cut->u, ref->u, n) && same_bits(cut->v, ref->v, n));
  /* kept blocks: some elements kept, the cut cells' integrated again */
  fcm_integrator_setup_info info;
  fcm_integrator_get_setup_info(cut, &info);
  TEST_TRUE(info.cut_kept_elements > 0);
  TEST_TRUE(info.cut_kept_elements < fcm_space_num_elements(cut->space));
  /* the given ordering is a permutation of the DOFs; CHOLMOD analysed with it */
  unsigned char *seen = calloc((size_t)n, 1);
  int perm_ok = 1;
  for (fcm_index k = 0; k < n; k++) {
    const fcm_index d = cut->cut_ordering[k];
    perm_ok &= d >= 0 && d < n && !seen[d];
    if (d >= 0 && d < n) seen[d] = 1;
  }
  TEST_TRUE(perm_ok);
  free(seen);
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-0.3, -0.3, -0.3}, hi[3] = {1.3, 0.9, 0.9};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  const fcm_index nc[3] = {4, 3, 3}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules[4] = {NULL, NULL, NULL, NULL};
  fcm_space *space[4] = {NULL, NULL, NULL, NULL};
  fcm_integrator *integ[4] = {NULL, NULL, NULL, NULL}, *plain = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[0], &space[0]));
  fcm_integrator_options o = fcm_integrator_options_default();
  o.dt = 0.01;
  o.cut_reuse = FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_ORDERING;
  TEST_OK(ctx, fcm_integrator_create(ctx, space[0], &mat, &o, &integ[0]));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ[0], gravity, NULL, NULL));
  TEST_OK(ctx, hold_base(integ[0], mesh));
  TEST_OK(ctx, fcm_integrator_setup(integ[0]));
  for (int s = 0; s < 2; s++) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(integ[0], &info));
  }
  /* the cuts: a plane, a partial rectangle from the top, a plane across the first */
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  const double p1[3] = {0.47, 0.3, 0.3}, n1[3] = {1.0, 0.05, 0.0};
  const double c2[3] = {0.73, 0.55, 0.3}, n2[3] = {1.0, 0.0, 0.1}, a2[3] = {0.0, 1.0, 0.0},
               size2[2] = {0.5, 2.0};
  const double p3[3] = {0.5, 0.33, 0.3}, n3[3] = {0.04, 1.0, 0.02};
  for (int k = 1; k <= 3; k++) {
    fcm_surface *cut = NULL;
    if (k == 1) TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, box_lo, box_hi, &cut));
    if (k == 2) TEST_OK(ctx, fcm_surface_create_rectangle(ctx, c2, n2, a2, size2, &cut));
    if (k == 3) TEST_OK(ctx, fcm_surface_create_plane(ctx, p3, n3, box_lo, box_hi, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &rules[k]));
    fcm_surface_destroy(&cut);
    if (!rules[k]) break;
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[k], &space[k]));
    printf("cut %d: %lld -> %lld DOFs\n", k, (long long)fcm_space_num_dofs(space[k - 1]),
           (long long)fcm_space_num_dofs(space[k]));
    TEST_TRUE(fcm_space_num_dofs(space[k]) > fcm_space_num_dofs(space[k - 1]));
    TEST_OK(ctx, fcm_integrator_create_cut(integ[k - 1], space[k], &integ[k]));
    if (!integ[k]) break;
    check_momentum_blocks(space[k - 1], space[k], mesh, rules[k]);
    fcm_integrator *ref = rebuild(integ[k - 1], integ[k], space[k], mesh);
    if (ref) {
      compare(integ[k], ref);
      step_both(integ[k], ref, 3);
    }
    fcm_integrator_destroy(&ref);
  }
  /* without the option: no ordering given, no blocks kept, CHOLMOD's own analysis */
  if (integ[2] && space[3]) {
    fcm_integrator_options op = integ[2]->opts;
    op.cut_reuse = 0;
    fcm_integrator *a = NULL;
    TEST_OK(ctx, fcm_integrator_create(ctx, space[2], &mat, &op, &a));
    TEST_OK(ctx, fcm_integrator_add_gravity(a, gravity, NULL, NULL));
    TEST_OK(ctx, hold_base(a, mesh));
    TEST_OK(ctx, fcm_integrator_setup(a));
    TEST_OK(ctx, fcm_integrator_create_cut(a, space[3], &plain));
    if (plain) {
      fcm_integrator_setup_info info;
      fcm_integrator_get_setup_info(plain, &info);
      TEST_TRUE(plain->cut_ordering == NULL && plain->blk_mass == NULL);
      TEST_TRUE(info.cut_kept_elements == 0);
      fcm_index nnz = 0;
      fcm_csr_get_size(fcm_integrator_mass(plain), NULL, NULL, &nnz);
      /* the mass matrix of the full assembly is the kept one's, bit for bit */
      if (integ[3])
        TEST_TRUE(same_bits(fcm_csr_values_read(fcm_integrator_mass(plain)),
                            fcm_csr_values_read(fcm_integrator_mass(integ[3])), nnz));
    }
    fcm_integrator_destroy(&a);
  }
  fcm_integrator_destroy(&plain);
  { /* a value that is no sum of the flags is refused at the setup */
    fcm_integrator_options ob = o;
    ob.cut_reuse = 8;
    fcm_integrator *bad = NULL;
    TEST_OK(ctx, fcm_integrator_create(ctx, space[0], &mat, &ob, &bad));
    TEST_TRUE(fcm_integrator_setup(bad) == FCM_ERR_ARG);
    fcm_ctx_error_clear(ctx);
    fcm_integrator_destroy(&bad);
  }
  for (int k = 3; k >= 0; k--) {
    fcm_integrator_destroy(&integ[k]);
    fcm_space_destroy(&space[k]);
    fcm_cell_rules_destroy(&rules[k]);
  }
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
