/* Allocation failures in the surface checks and repairs: fcm_surface_check (with the
 * self-intersection search and the loop count), fcm_surface_create_oriented,
 * fcm_surface_create_filled (the minimum-area triangulation and its intersection test) and
 * fcm_geometry_create_from_surface (with Gmsh). Failing the k-th allocation until success
 * gives FCM_ERR_ALLOC, NULL outputs and no leak. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/surface.h"
#include "alloc_loop.h"

#include <stdio.h>

typedef struct fixture {
  fcm_ctx *ctx;
  fcm_surface *open, *closed, *out;
  fcm_geometry *g;
  fcm_surface_report r;
} fixture;

/* the unit cube without its top face (10 triangles) */
static const double X[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
static const fcm_index T[] = {0, 2, 1, 0, 3, 2, 0, 1, 5, 0, 5, 4, 3, 7, 6, 3, 6, 2,
                              0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5, 4, 5, 6, 4, 6, 7};

static fcm_status check(void *u)
{
  fixture *x = u;
  return fcm_surface_check(x->open, NULL, &x->r);
}
static fcm_status orient(void *u)
{
  fixture *x = u;
  x->out = (fcm_surface *)x;
  fcm_status st = fcm_surface_create_oriented(x->ctx, x->open, &x->out, NULL);
  return st != FCM_OK && x->out ? FCM_ERR_INTERNAL : st;
}
static fcm_status fill(void *u)
{
  fixture *x = u;
  fcm_surface_fill_info fi;
  x->out = (fcm_surface *)x;
  fcm_status st = fcm_surface_create_filled(x->ctx, x->open, NULL, &x->out, &fi);
  return st != FCM_OK && x->out ? FCM_ERR_INTERNAL : st;
}
static fcm_status mesh(void *u)
{
  fixture *x = u;
  x->g = (fcm_geometry *)x;
  fcm_status st = fcm_geometry_create_from_surface(x->ctx, x->closed, NULL, &x->g);
  return st != FCM_OK && x->g ? FCM_ERR_INTERNAL : st;
}
static void release(void *u)
{
  fixture *x = u;
  fcm_surface_destroy(&x->out);
  fcm_geometry_destroy(&x->g);
}

int main(void)
{
  failing f;
  static fixture x;
  x.ctx = failing_ctx(&f);
  TEST_TRUE(x.ctx != NULL);
  if (!x.ctx) return TEST_RESULT();
  TEST_OK(x.ctx, fcm_surface_create(x.ctx, 8, X, 10, T, &x.open));
  TEST_OK(x.ctx, fcm_surface_create(x.ctx, 8, X, 12, T, &x.closed));
  alloc_loop(x.ctx, &f, "fcm_surface_check", check, NULL, &x, 3, 1000);
  TEST_TRUE(x.r.num_boundary_edges == 4 && x.r.num_boundary_loops == 1);
  alloc_loop(x.ctx, &f, "fcm_surface_create_oriented", orient, release, &x, 3, 1000);
  alloc_loop(x.ctx, &f, "fcm_surface_create_filled", fill, release, &x, 5, 1000);
  if (fcm_surface_meshing_available())
    alloc_loop(x.ctx, &f, "fcm_geometry_create_from_surface", mesh, release, &x, 5, 1000);
  fcm_surface_destroy(&x.open);
  fcm_surface_destroy(&x.closed);
  TEST_TRUE(fcm_ctx_live_allocations(x.ctx) == 0);
  fcm_ctx_destroy(&x.ctx);
  return TEST_RESULT();
}
