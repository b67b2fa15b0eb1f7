/* Error paths of fcm_cell_rules_create: a non-convex background cell is rejected naming
 * the cell; bad strengths, thresholds, tolerances, thread counts and stabilization
 * settings are FCM_ERR_ARG with the value in the message; *rules stays NULL; a cut surface
 * of zero-area triangles only is refused (FCM_ERR_GEOMETRY). Then the
 * allocation-failure loop (fail the k-th allocation, k = 0, 1, ... until success; one
 * thread): FCM_ERR_ALLOC, NULL output, nothing leaked. */
#include "fcm/embed.h"
#include "embed/embed_impl.h"
#include "geom/geom_impl.h"
#include "fcm/surface.h"
#include "test.h"
#include "test_alloc.h"

#include <stdlib.h>
#include <string.h>

static void arguments(fcm_ctx *ctx)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1}, c0[3] = {1, 0.5, 0.5};
  const fcm_index n[3] = {2, 1, 1};
  fcm_mesh *box = NULL, *warped = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r = (fcm_cell_rules *)ctx;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &box));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.4, 1, &g));
  if (!box || !g) return;
  /* Lift corner (2,1,1), which only cell 1 uses: its faces are no longer planar. */
  double x[36];
  memcpy(x, fcm_mesh_coords(box), sizeof x);
  x[3 * 11 + 2] += 0.3;
  TEST_OK(ctx, fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, 12, x, 2, fcm_mesh_cells(box), &warped));
  if (warped)
    TEST_ERR(ctx, fcm_cell_rules_create(ctx, warped, g, NULL, &r), FCM_ERR_GEOMETRY,
             "background cell 1 (hex8) is not a convex polyhedron");
  TEST_TRUE(r == NULL);
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_MASS] = 21;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, box, g, &o, &r), FCM_ERR_ARG,
           "mass strength = 21 outside [0, 20]");
  o.simplify = 0; /* without simplification the catalogue limit applies */
  o.strength[FCM_RULE_MASS] = FCM_RULE_MAX_STRENGTH + 1;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, box, g, &o, &r), FCM_ERR_ARG, "mass strength");
  o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_STIFFNESS] = -2;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, box, g, &o, &r), FCM_ERR_ARG, "stiffness strength = -2");
  o = fcm_cell_rules_options_default();
  o.min_fraction = 0.5, o.uncut_fraction = 0.4;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, box, g, &o, &r), FCM_ERR_ARG,
           "min_fraction = 0.5, uncut_fraction = 0.4");
  o = fcm_cell_rules_options_default();
  o.clip_rtol = -1e-12;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, box, g, &o, &r), FCM_ERR_ARG, "clip_rtol = -1e-12");
  o = fcm_cell_rules_options_default();
  /* the context's thread count: FCM_DEFAULT (-1) is the OpenMP default; 0 threads means nothing */
  TEST_ERR(ctx, fcm_ctx_set_num_threads(ctx, 0), FCM_ERR_ARG, "num_threads = 0");
  TEST_ERR(ctx, fcm_ctx_set_num_threads(ctx, -2), FCM_ERR_ARG, "num_threads = -2");
  TEST_TRUE(fcm_ctx_num_threads(ctx) >= 1);
  o = fcm_cell_rules_options_default();
  o.stabilization.alpha = 0.0;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, box, g, &o, &r), FCM_ERR_ARG, "alpha = 0");
  o = fcm_cell_rules_options_default();
  o.surface_strength = -3;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, box, g, &o, &r), FCM_ERR_ARG, "surface strength = -3");
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, NULL, g, NULL, &r), FCM_ERR_ARG, "NULL");
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, box, g, NULL, NULL), FCM_ERR_ARG, "output");
  TEST_TRUE(r == NULL);
  fcm_mesh_destroy(&box);
  fcm_mesh_destroy(&warped);
  fcm_geometry_destroy(&g);
}

static void allocation_failures(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c0[3] = {0.1, 0, 0};
  const fcm_index n[3] = {2, 2, 1};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.9, 1, &g));
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1)); /* the failing allocator's counter is not atomic */
  o.surface_strength = 1;
  o.strength[FCM_RULE_MASS] = 2;
  { /* one build first: the geometry keeps the search trees it makes (a cache, not a leak) */
    fcm_cell_rules *r = NULL;
    TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
    fcm_cell_rules_destroy(&r);
  }
  const long long live = fcm_ctx_live_allocations(ctx);
  int ok = 0, fails = 0;
  for (long k = 0; k < 100000 && !ok && mesh && g; k++) {
    fcm_cell_rules *r = (fcm_cell_rules *)&f;
    f.count = 0, f.fail_at = k;
    const fcm_status st = fcm_cell_rules_create(ctx, mesh, g, &o, &r);
    f.fail_at = -1;
    if (st == FCM_OK) {
      ok = 1;
      TEST_TRUE(r != NULL && fcm_cell_rules_get_stats(r)->num_cut > 0);
      fcm_cell_rules_destroy(&r);
    } else {
      fails++;
      if (!(st == FCM_ERR_ALLOC && r == NULL))
        TEST_FAIL_("allocation %ld failing: status %s, rules %p", k, fcm_status_name(st),
                   (void *)r);
    }
    if (fcm_ctx_live_allocations(ctx) != live)
      TEST_FAIL_("allocation %ld failing: %lld allocations leaked", k,
                 fcm_ctx_live_allocations(ctx) - live);
    fcm_ctx_error_clear(ctx);
  }
  TEST_TRUE(ok && fails > 20);
  /* a fresh geometry each time: the failure also hits the search trees it builds and keeps;
   * nothing of them outlives the geometry */
  ok = 0;
  for (long k = 0; k < 100000 && !ok && mesh; k++) {
    fcm_geometry *g2 = NULL;
    const long long live0 = fcm_ctx_live_allocations(ctx);
    TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.9, 1, &g2));
    fcm_cell_rules *r = NULL;
    f.count = 0, f.fail_at = k;
    const fcm_status st = g2 ? fcm_cell_rules_create(ctx, mesh, g2, &o, &r) : FCM_ERR_ALLOC;
    f.fail_at = -1;
    ok = st == FCM_OK && g2->trees[0] && g2->trees[1];
    if (st != FCM_OK && !(st == FCM_ERR_ALLOC && r == NULL))
      TEST_FAIL_("fresh geometry, allocation %ld failing: status %s", k, fcm_status_name(st));
    fcm_cell_rules_destroy(&r);
    fcm_geometry_destroy(&g2);
    if (fcm_ctx_live_allocations(ctx) != live0)
      TEST_FAIL_("fresh geometry, allocation %ld failing: %lld allocations leaked", k,
                 fcm_ctx_live_allocations(ctx) - live0);
    fcm_ctx_error_clear(ctx);
  }
  TEST_TRUE(ok);
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&g);
  fcm_ctx_destroy(&ctx);
}

/* The allocation-failure loop of a cut (fcm_cell_rules_create_cut()) of a body given by its
 * surface alone, with the stiffness on the mass space (the pieces' fits, their candidates, the
 * links between cells, the gathering of the copied cells' rules): FCM_ERR_ALLOC, NULL output,
 * nothing leaked; the cut that succeeds equals the cut made without failures, bit for bit. The
 * allocator fills every block with garbage: what the library reads unwritten shows. */
static void *poisoned_alloc(void *user, size_t size)
{
  void *p = failing_alloc(user, size);
  if (p) memset(p, 0xA5, size);
  return p;
}

/* The cut of the allocation-failure tests: a surface ball (no volume mesh) on a 4 x 4 x 3 Hex8
 * grid with its rules (surface moments, the stiffness on the mass space), and a slanted blade. */
typedef struct cut_case {
  fcm_mesh *mesh;
  fcm_geometry *tets, *g;
  fcm_surface *s, *blade;
  fcm_cell_rules *r0;
} cut_case;

static void cut_case_make(fcm_ctx *ctx, cut_case *c)
{
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c0[3] = {0.07, -0.03, 0.02};
  const fcm_index n[3] = {4, 4, 3};
  const double p[3] = {0.11, 0.0, 0.0}, nrm[3] = {1.0, 0.2, 0.1}, plo[3] = {-2, -2, -2},
               phi[3] = {2, 2, 2};
  memset(c, 0, sizeof *c);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &c->mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.8, 1, &c->tets));
  if (c->tets)
    TEST_OK(ctx,
            fcm_surface_create(ctx, fcm_geometry_num_nodes(c->tets), fcm_geometry_coords(c->tets),
                               fcm_geometry_num_boundary_triangles(c->tets),
                               fcm_geometry_boundary_triangles(c->tets), &c->s));
  fcm_surface_mesh_options mo = fcm_surface_mesh_options_default();
  mo.volume_mesh = 0;
  if (c->s) TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, c->s, &mo, &c->g));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nrm, plo, phi, &c->blade));
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.moments = FCM_CELL_MOMENTS_SURFACE;
  o.stiffness_on_mass_space = 1;
  if (c->mesh && c->g) TEST_OK(ctx, fcm_cell_rules_create(ctx, c->mesh, c->g, &o, &c->r0));
}

static void cut_case_free(cut_case *c)
{
  fcm_cell_rules_destroy(&c->r0);
  fcm_surface_destroy(&c->blade);
  fcm_surface_destroy(&c->s);
  fcm_geometry_destroy(&c->g);
  fcm_geometry_destroy(&c->tets);
  fcm_mesh_destroy(&c->mesh);
}

/* c's blade applied to its rules (fcm_cell_rules_create_cut()). */
static fcm_status cut_once(fcm_ctx *ctx, const cut_case *c, fcm_cell_rules **r)
{
  return fcm_cell_rules_create_cut(ctx, c->mesh, c->g, c->r0, c->blade, r);
}

static void cut_allocation_failures(void)
{
  failing f;
  /* what is read before it is written is garbage */
  fcm_ctx *ctx = failing_ctx_with(&f, poisoned_alloc);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1)); /* the failing allocator's counter is not atomic */
  cut_case cc;
  cut_case_make(ctx, &cc);
  fcm_cell_rules *ref = NULL;
  if (cc.r0 && cc.blade) TEST_OK(ctx, cut_once(ctx, &cc, &ref));
  const long long live = fcm_ctx_live_allocations(ctx);
  int ok = 0, fails = 0;
  for (long k = 0; k < 1000000 && !ok && ref; k++) {
    fcm_cell_rules *r = (fcm_cell_rules *)&f;
    f.count = 0, f.fail_at = k;
    const fcm_status st = cut_once(ctx, &cc, &r);
    f.fail_at = -1;
    if (st == FCM_OK) {
      ok = 1;
      const fcm_index np = fcm_cell_rules_num_pieces(r);
      int same = np == fcm_cell_rules_num_pieces(ref) && r->num_links == ref->num_links &&
                 !memcmp(r->links, ref->links, 2 * (size_t)r->num_links * sizeof *r->links);
      for (int kind = 0; kind < FCM_RULE_KIND_COUNT && same; kind++) {
        const size_t m = (size_t)ref->off[kind][np];
        same = !memcmp(r->off[kind], ref->off[kind], ((size_t)np + 1) * sizeof(fcm_index)) &&
               !memcmp(r->points[kind], ref->points[kind], 3 * m * sizeof(double)) &&
               !memcmp(r->weights[kind], ref->weights[kind], m * sizeof(double)) &&
               !memcmp(r->flags[kind], ref->flags[kind], m);
      }
      TEST_TRUE(same && ref->num_links > 0 && ref->off[FCM_RULE_MASS][np] > 0);
      fcm_cell_rules_destroy(&r);
    } else {
      fails++;
      if (!(st == FCM_ERR_ALLOC && r == NULL))
        TEST_FAIL_("cut, allocation %ld failing: status %s, rules %p", k, fcm_status_name(st),
                   (void *)r);
    }
    if (fcm_ctx_live_allocations(ctx) != live)
      TEST_FAIL_("cut, allocation %ld failing: %lld allocations leaked", k,
                 fcm_ctx_live_allocations(ctx) - live);
    fcm_ctx_error_clear(ctx);
  }
  TEST_TRUE(ok && fails > 100);
  fcm_cell_rules_destroy(&ref);
  cut_case_free(&cc);
  fcm_ctx_destroy(&ctx);
}

/* The same cut on two threads (an atomic counter): wherever an allocation fails among the
 * cut's, spread over all of them (the parallel loops', and the kept face polygons' beside the
 * statistics), the cut returns FCM_ERR_ALLOC without rules and leaks nothing; without a
 * failure it gives the rules of the cut made first, bit for bit. */
static void cut_allocation_failures_two_threads(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx_with(&f, failing_alloc_atomic);
  TEST_TRUE(ctx != NULL);
  if (!ctx) return;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 2));
  cut_case cc;
  cut_case_make(ctx, &cc);
  fcm_cell_rules *ref = NULL;
  long long total = 0;
  if (cc.r0 && cc.blade) {
    f.count = 0;
    TEST_OK(ctx, cut_once(ctx, &cc, &ref));
    total = f.count;
  }
  const long long live = fcm_ctx_live_allocations(ctx);
  int fails = 0;
  for (long long k = 0; k < total && ref; k += 1 + total / 150) {
    fcm_cell_rules *r = (fcm_cell_rules *)&f;
    f.count = 0, f.fail_at = k;
    const fcm_status st = cut_once(ctx, &cc, &r);
    f.fail_at = -1;
    if (st == FCM_OK) { /* the failing allocation was not reached on this path */
      const fcm_index np = fcm_cell_rules_num_pieces(r);
      TEST_TRUE(np == fcm_cell_rules_num_pieces(ref) && r->num_links == ref->num_links &&
                !memcmp(r->links, ref->links, 2 * (size_t)r->num_links * sizeof *r->links));
      fcm_cell_rules_destroy(&r);
    } else {
      fails++;
      if (!(st == FCM_ERR_ALLOC && r == NULL))
        TEST_FAIL_("cut on two threads, allocation %lld failing: status %s, rules %p", k,
                   fcm_status_name(st), (void *)r);
    }
    if (fcm_ctx_live_allocations(ctx) != live)
      TEST_FAIL_("cut on two threads, allocation %lld failing: %lld allocations leaked", k,
                 fcm_ctx_live_allocations(ctx) - live);
    fcm_ctx_error_clear(ctx);
  }
  TEST_TRUE(total > 0 && fails > 100);
  fcm_cell_rules_destroy(&ref);
  cut_case_free(&cc);
  fcm_ctx_destroy(&ctx);
}

/* A cut surface whose triangles all lack area (collinear, repeated or sliver vertices) would
 * separate nothing: refused with FCM_ERR_GEOMETRY giving the count and the first; one
 * triangle of positive area among them makes a cut (the others are skipped). */
static void degenerate_cut(fcm_ctx *ctx)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1}, c0[3] = {1, 0.5, 0.5};
  const fcm_index n[3] = {2, 1, 1};
  fcm_mesh *box = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_surface *flat = NULL, *mixed = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &box));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.4, 2, &g));
  if (box && g) TEST_OK(ctx, fcm_cell_rules_create(ctx, box, g, NULL, &r0));
  /* in the plane x = 0.9: collinear; repeated; a sliver 1e-16 off its longest edge; and a
   * triangle across the whole ball */
  const double x[] = {0.9,   0,   0, 0.9, 0.5, 0.5, 0.9, 1,   1, 0.9, 0,   1,  0.9, 1,
                      1e-16, 0.9, 2, 0,   0.9, -1,  -1,  0.9, 3, -1,  0.9, -1, 3};
  const fcm_index degenerate[] = {0, 1, 2, 0, 0, 3, 0, 4, 5}, with_one[] = {0, 1, 2, 6, 7, 8};
  TEST_OK(ctx, fcm_surface_create(ctx, 9, x, 3, degenerate, &flat));
  TEST_OK(ctx, fcm_surface_create(ctx, 9, x, 2, with_one, &mixed));
  if (r0 && flat && mixed) {
    TEST_ERR(ctx, fcm_cell_rules_create_cut(ctx, box, g, r0, flat, &r1), FCM_ERR_GEOMETRY,
             "embed cut: all 3 triangle(s) of the cut surface have zero area (the first: (0.9, "
             "0, 0), (0.9, 0.5, 0.5), (0.9, 1, 1)), so the cut would separate nothing");
    TEST_TRUE(r1 == NULL);
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, box, g, r0, mixed, &r1));
    if (r1) TEST_TRUE(fcm_cell_rules_num_cuts(r1) == 1 && fcm_cell_rules_num_pieces(r1) > 2);
  }
  fcm_cell_rules_destroy(&r1);
  fcm_cell_rules_destroy(&r0);
  fcm_surface_destroy(&flat);
  fcm_surface_destroy(&mixed);
  fcm_mesh_destroy(&box);
  fcm_geometry_destroy(&g);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  arguments(ctx);
  degenerate_cut(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  allocation_failures();
  cut_allocation_failures();
  cut_allocation_failures_two_threads();
  return TEST_RESULT();
}
