/* Allocation-failure torture for the octree: fcm_mesh_create_octree, fcm_mesh_create_refined,
 * fcm_space_hanging_matrix_create and fcm_csr_create_ptap, and on a cut octree
 * fcm_space_hanging_matrix_create (copies per component), Hex8 and Hex20: failing the k-th
 * allocation (k = 0, 1, ... until success) returns FCM_ERR_ALLOC, leaves the output NULL and
 * leaks nothing. */
#include "alloc_loop.h"
#include "fcm/fcm.h"

#include <math.h>
#include <string.h>

typedef struct octree_case {
  fcm_ctx *ctx;
  failing *f;
  fcm_element_type type;
  const fcm_mesh *base;
  const fcm_space *space;
  const fcm_csr *K, *T;
  const unsigned char *flags;
  fcm_mesh *m;
  fcm_csr *C;
} octree_case;

static double plane(const double x[3], void *user)
{
  (void)user;
  return x[0] + 0.7 * x[1] - 0.9;
}

static fcm_status create(void *user)
{
  octree_case *c = user;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {2, 2, 1};
  fcm_octree_options o = fcm_octree_options_default();
  o.surface = plane;
  o.surface_level = 2;
  c->m = (fcm_mesh *)c; /* must be reset to NULL on failure */
  fcm_status st = fcm_mesh_create_octree(c->ctx, c->type, lo, hi, n, &o, &c->m);
  if (st == FCM_OK) TEST_TRUE(c->m && fcm_mesh_num_hanging(c->m) > 0);
  return st != FCM_OK && c->m ? FCM_ERR_INTERNAL : st;
}

static fcm_status refine(void *user)
{
  octree_case *c = user;
  c->m = (fcm_mesh *)c;
  fcm_status st = fcm_mesh_create_refined(c->ctx, c->base, c->flags, &c->m);
  return st != FCM_OK && c->m ? FCM_ERR_INTERNAL : st;
}

static fcm_status hanging(void *user)
{
  octree_case *c = user;
  c->C = (fcm_csr *)c;
  fcm_status st = fcm_space_hanging_matrix_create(c->space, NULL, &c->C);
  return st != FCM_OK && c->C ? FCM_ERR_INTERNAL : st;
}

static fcm_status ptap(void *user)
{
  octree_case *c = user;
  c->C = (fcm_csr *)c;
  fcm_status st = fcm_csr_create_ptap(c->ctx, c->K, c->T, &c->C);
  return st != FCM_OK && c->C ? FCM_ERR_INTERNAL : st;
}

static void release(void *user)
{
  octree_case *c = user;
  fcm_mesh_destroy(&c->m);
  fcm_csr_destroy(&c->C);
}

/* The cut octree: a box body cut through by a tilted plane across the level changes. */
static void cut_case(octree_case *c)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, clo[3] = {-1, -1, -1}, chi[3] = {2, 2, 2};
  const double p[3] = {0.43, 0.5, 0.5}, n[3] = {1, 0.2, 0.1};
  const fcm_index nb[3] = {1, 1, 1};
  fcm_geometry *body = NULL;
  fcm_cell_rules *rules = NULL, *cr = NULL;
  fcm_surface *plane_cut = NULL;
  fcm_space *space = NULL;
  TEST_OK(c->ctx, fcm_geometry_create_box(c->ctx, lo, hi, nb, &body));
  TEST_OK(c->ctx, fcm_cell_rules_create(c->ctx, c->base, body, NULL, &rules));
  TEST_OK(c->ctx, fcm_surface_create_plane(c->ctx, p, n, clo, chi, &plane_cut));
  TEST_OK(c->ctx, fcm_cell_rules_create_cut(c->ctx, c->base, body, rules, plane_cut, &cr));
  TEST_OK(c->ctx, fcm_space_create_embedded(c->ctx, c->base, cr, &space));
  TEST_TRUE(space && fcm_space_num_bodies(space) == 2);
  c->space = space;
  alloc_loop(c->ctx, c->f, "hanging_matrix_create (cut)", hanging, release, c, 5, 400);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&cr);
  fcm_cell_rules_destroy(&rules);
  fcm_surface_destroy(&plane_cut);
  fcm_geometry_destroy(&body);
}

int main(void)
{
  failing f;
  octree_case c;
  memset(&c, 0, sizeof c);
  c.ctx = failing_ctx(&f), c.f = &f, c.type = FCM_ELEMENT_HEX8;
  TEST_TRUE(c.ctx != NULL);
  if (!c.ctx) return TEST_RESULT();
  for (int t = 0; t < 2; t++) {
    c.type = t ? FCM_ELEMENT_HEX20 : FCM_ELEMENT_HEX8;
    fcm_mesh *base = NULL;
    fcm_space *space = NULL;
    fcm_csr *K = NULL, *T = NULL;
    alloc_loop(c.ctx, &f, "create_octree", create, release, &c, 8, 400);
    TEST_OK(c.ctx, create(&c));
    base = c.m;
    c.m = NULL;
    c.base = base;
    unsigned char *flags = calloc((size_t)fcm_mesh_num_cells(base), 1);
    flags[0] = flags[fcm_mesh_num_cells(base) - 1] = 1;
    c.flags = flags;
    alloc_loop(c.ctx, &f, "create_refined", refine, release, &c, 8, 400);
    TEST_OK(c.ctx, fcm_space_create(c.ctx, base, NULL, &space));
    c.space = space;
    alloc_loop(c.ctx, &f, "hanging_matrix_create", hanging, release, &c, 3, 400);
    TEST_OK(c.ctx, fcm_space_hanging_matrix_create(space, NULL, &T));
    TEST_OK(c.ctx, fcm_space_matrix_create(space, &K));
    c.K = K, c.T = T;
    alloc_loop(c.ctx, &f, "create_ptap", ptap, release, &c, 3, 400);
    cut_case(&c);
    fcm_csr_destroy(&K);
    fcm_csr_destroy(&T);
    fcm_space_destroy(&space);
    fcm_mesh_destroy(&base);
    free(flags);
  }
  TEST_TRUE(fcm_ctx_live_allocations(c.ctx) == 0);
  fcm_ctx_destroy(&c.ctx);
  return TEST_RESULT();
}
