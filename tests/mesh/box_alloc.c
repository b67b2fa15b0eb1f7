/* Allocation-failure torture for fcm_mesh_create_box: failing the k-th allocation
 * (k = 0, 1, ... until success) returns FCM_ERR_ALLOC, leaves *mesh NULL and leaks
 * nothing, for every element type. */
#include "alloc_loop.h"
#include "mesh_util.h"

typedef struct box_case {
  fcm_ctx *ctx;
  fcm_element_type type;
  fcm_mesh *m;
} box_case;

static fcm_status create_box(void *user)
{
  box_case *c = user;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
  const fcm_index n[3] = {2, 2, 3};
  c->m = (fcm_mesh *)c; /* must be reset to NULL on failure */
  fcm_status st = fcm_mesh_create_box(c->ctx, c->type, lo, hi, n, &c->m);
  if (st == FCM_OK)
    TEST_TRUE(c->m && fcm_mesh_num_cells(c->m) == (c->type <= FCM_ELEMENT_TET10 ? 72 : 12));
  return st != FCM_OK && c->m ? FCM_ERR_INTERNAL : st;
}

static void destroy_box(void *user)
{
  fcm_mesh_destroy(&((box_case *)user)->m);
}

int main(void)
{
  failing f;
  box_case c = {failing_ctx(&f), FCM_ELEMENT_HEX8, NULL};
  TEST_TRUE(c.ctx != NULL);
  if (!c.ctx) return TEST_RESULT();
  /* every allocation up to success is a distinct failure point: at least 4 */
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++) {
    c.type = (fcm_element_type)t;
    alloc_loop(c.ctx, &f, fcm_element_get_info(c.type)->name, create_box, destroy_box, &c, 4, 100);
  }
  fcm_ctx_destroy(&c.ctx);
  return TEST_RESULT();
}
