/* The corotated model's store of element matrices over a chain of cuts, taken by each cut
 * (FCM_CUT_REUSE_STORAGE) while its room lasts and copied into a new store when the cut's
 * elements outnumber its slots, equals a chain that copies it at every cut, bit for bit. An
 * embedded box under gravity (Hex8, element-corotated linear, 3 multigrid V-cycles and one
 * Newton iteration a step) is cut five times by planes through its cells (each adds about a
 * tenth more elements; the store has a quarter more slots than its first elements) by two
 * chains: `a` gives its storage to each cut, `b` keeps it. At a cut whose elements fit the old
 * store's slots a's store is the old one (the same address and slot count), each element the
 * cut leaves keeps its parent's slot and every element has a slot of its own; at a cut whose
 * elements do not fit, a's store is a new one (slot e for element e, a quarter more slots).
 * Both kinds occur. After each cut the states and a step's displacement and velocity of `a`
 * and `b` are the same bits; each cut's set-up builds the element matrices of the elements the
 * cut changed (every element has its matrix after it), and a step builds none. Nothing is left
 * allocated. */
#include "fem/assemble_impl.h"
#include "fem/fem_impl.h"
#include "sim/sim_impl.h"
#include "sim_util.h"

#include <string.h>

static fcm_ctx *ctx;

static const fcm_material mat = {FCM_MATERIAL_COROTATED_LINEAR, 2.0e4, 0.3, 1000.0};

static int same_bits(const double *a, const double *b, fcm_index n)
{
  return a && b && memcmp(a, b, sizeof *a * (size_t)n) == 0;
}

static fcm_integrator *make(const fcm_space *space, const fcm_mesh *mesh, int cut_reuse)
{
  return cut_chain_integrator(ctx, space, mesh, &mat, cut_reuse);
}

/* Steps both once: the same bits, and no element matrix built in either. */
static void step_both(fcm_integrator *a, fcm_integrator *b)
{
  fcm_step_info ia, ib;
  const fcm_index built_a = fcm__assembly_corot_built(a->aws);
  const fcm_index built_b = fcm__assembly_corot_built(b->aws);
  TEST_OK(ctx, fcm_integrator_step(a, &ia));
  TEST_OK(ctx, fcm_integrator_step(b, &ib));
  TEST_TRUE(a->n == b->n);
  TEST_TRUE(same_bits(a->u, b->u, a->n) && same_bits(a->v, b->v, a->n));
  TEST_TRUE(fcm__assembly_corot_built(a->aws) == built_a &&
            fcm__assembly_corot_built(b->aws) == built_b);
}

/* The slots of a1's store after the cut from a (a's store as it was before the cut: K, cap,
 * slot and have copied by the caller). Returns 1 when a1 took a's store, 0 when it made its
 * own; *changed: the elements the cut changed (built again by the cut's set-up). */
static int check_slots(const fcm_integrator *a, const fcm_integrator *a1, const double *old_K,
                       fcm_index old_cap, const fcm_index *old_slot, const unsigned char *old_have,
                       fcm_index *changed)
{
  const corot_store *c = &a1->aws->corot;
  const fcm_index ne = a1->space->num_elems;
  fcm_index *same = malloc(sizeof *same * (size_t)(ne + 1));
  unsigned char *used = calloc((size_t)(ne > old_cap ? ne : old_cap) + 1, 1);
  int took = ne <= old_cap, ok = 1;
  *changed = 0;
  TEST_OK(ctx, fcm__space_cut_same_elements(a->space, a1->space, same, NULL));
  TEST_TRUE(c->K != NULL && c->slot != NULL);
  if (took) { /* the old store, each kept element at its parent's slot */
    TEST_TRUE(c->K == old_K && c->cap == old_cap && a->aws->corot.K == NULL);
  } else { /* a new store, a quarter more slots; a keeps its own */
    TEST_TRUE(c->K != old_K && c->cap == ne + ne / 4 + 1 && a->aws->corot.K == old_K);
  }
  for (fcm_index e = 0; e < ne && c->K && c->slot; e++) {
    const int kept = same[e] >= 0 && old_have[same[e]];
    *changed += !kept;
    if (took && kept) ok &= c->slot[e] == old_slot[same[e]];
    if (!took) ok &= c->slot[e] == e;
    ok &= c->slot[e] >= 0 && c->slot[e] < c->cap && !used[c->slot[e]]; /* one element a slot */
    if (c->slot[e] >= 0 && c->slot[e] < c->cap) used[c->slot[e]] = 1;
    ok &= c->have[e] == 1; /* kept: its matrix there; the others built by the set-up */
  }
  TEST_TRUE(ok);
  free(same);
  free(used);
  return took;
}

/* Cuts a (with the option) and b (without) onto space; returns 1 when a's cut took a's store,
 * 0 when it made a new one, -1 on failure. */
static int cut_both(fcm_integrator **a, fcm_integrator **b, const fcm_space *space)
{
  fcm_integrator *a1 = NULL, *b1 = NULL;
  const corot_store *o = &(*a)->aws->corot;
  const fcm_index ne0 = (*a)->space->num_elems, cap = o->cap;
  const double *K = o->K;
  fcm_index *slot = malloc(sizeof *slot * (size_t)(ne0 + 1)), changed = 0;
  unsigned char *have = malloc((size_t)ne0 + 1);
  int took = -1;
  TEST_TRUE(K != NULL && o->slot != NULL && o->have != NULL);
  if (o->slot) memcpy(slot, o->slot, sizeof *slot * (size_t)ne0);
  if (o->have) memcpy(have, o->have, (size_t)ne0);
  TEST_OK(ctx, fcm_integrator_create_cut(*a, space, &a1));
  TEST_OK(ctx, fcm_integrator_create_cut(*b, space, &b1));
  if (a1 && b1 && K) {
    took = check_slots(*a, a1, K, cap, slot, have, &changed);
    TEST_TRUE(a1->n == b1->n);
    TEST_TRUE(same_bits(a1->u, b1->u, a1->n) && same_bits(a1->v, b1->v, a1->n));
    TEST_TRUE(fcm__assembly_corot_built(a1->aws) == changed && changed > 0);
    TEST_TRUE(fcm__assembly_corot_built(b1->aws) == changed);
    step_both(a1, b1);
    if (getenv("FCM_TEST_VERBOSE"))
      printf("%lld -> %lld elements, %lld slots: %s, %lld element matrices built\n", (long long)ne0,
             (long long)a1->space->num_elems, (long long)cap, took ? "taken" : "new store",
             (long long)changed);
  }
  free(slot);
  free(have);
  fcm_integrator_destroy(a);
  fcm_integrator_destroy(b);
  *a = a1;
  *b = b1;
  return took;
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  const long long live0 = fcm_ctx_live_allocations(ctx);
  const double lo[3] = {-0.3, -0.3, -0.3}, hi[3] = {1.3, 0.9, 0.9};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  const fcm_index nc[3] = {12, 9, 9}, gn[3] = {2, 2, 2};
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  /* planes through the cells' middles (not along their faces) */
  const double p[5][3] = {
      {0.27, 0.3, 0.3}, {0.61, 0.3, 0.3}, {0.5, 0.31, 0.3}, {0.5, 0.3, 0.17}, {0.87, 0.3, 0.3}};
  const double n[5][3] = {
      {1.0, 0.05, 0.0}, {1.0, 0.0, 0.07}, {0.03, 1.0, 0.02}, {0.02, 0.04, 1.0}, {1.0, 0.06, 0.03}};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *rules[6] = {NULL};
  fcm_space *space[6] = {NULL};
  fcm_integrator *a = NULL, *b = NULL;
  int taken = 0, fresh = 0;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &rules[0]));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[0], &space[0]));
  if (space[0]) {
    a = make(space[0], mesh, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE);
    b = make(space[0], mesh, FCM_CUT_REUSE_BLOCKS);
  }
  if (a && b) { /* the element matrices built by the set-up, none by a step */
    TEST_TRUE(fcm__assembly_corot_built(a->aws) == fcm_space_num_elements(space[0]) &&
              fcm__assembly_corot_built(b->aws) == fcm_space_num_elements(space[0]));
    step_both(a, b);
  }
  for (int k = 1; k <= 5 && a && b; k++) {
    fcm_surface *cut = NULL;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, p[k - 1], n[k - 1], box_lo, box_hi, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, rules[k - 1], cut, &rules[k]));
    fcm_surface_destroy(&cut);
    if (!rules[k]) break;
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules[k], &space[k]));
    if (!space[k]) break;
    const int took = cut_both(&a, &b, space[k]);
    taken += took == 1;
    fresh += took == 0;
  }
  TEST_TRUE(taken >= 1 && fresh >= 1); /* both ways of the store */
  fcm_integrator_destroy(&a);
  fcm_integrator_destroy(&b);
  for (int k = 5; k >= 0; k--) {
    fcm_space_destroy(&space[k]);
    fcm_cell_rules_destroy(&rules[k]);
  }
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == live0); /* no store left behind */
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
