/* Allocation failures in the geometry entry points the shape loops of errors.c do not
 * cover: fcm_geometry_create (from arrays), fcm_geometry_create_from_gmsh (tet4, hex8),
 * fcm_aabb_tree_create and fcm_aabb_tree_query (a query whose result outgrows the first
 * workspace), fcm_surface_create (from arrays) and fcm_surface_create_from_file (OBJ with
 * quads, ASCII STL with the vertex merge, ASCII PLY). Failing the k-th allocation until
 * success gives FCM_ERR_ALLOC, NULL outputs and no leak. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/geom.h"
#include "fcm/surface.h"
#include "alloc_loop.h"

#include <stdio.h>

typedef struct fixture {
  fcm_ctx *ctx;
  fcm_geometry *g;
  fcm_aabb_tree *tree, *t_out;
  fcm_surface *s;
  const char *path;
  double boxes[6 * 300];
  fcm_index ids[300], count;
} fixture;

static const double P[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
static const fcm_index C[8] = {0, 1, 2, 3, 2, 3, 1, 4};

static fcm_status from_arrays(void *u)
{
  fixture *x = u;
  x->g = (fcm_geometry *)x;
  fcm_status st = fcm_geometry_create(x->ctx, FCM_ELEMENT_TET4, 5, &P[0][0], 2, C, &x->g);
  return st != FCM_OK && x->g ? FCM_ERR_INTERNAL : st;
}
static fcm_status from_gmsh(void *u)
{
  fixture *x = u;
  x->g = (fcm_geometry *)x;
  fcm_status st = fcm_geometry_create_from_gmsh(x->ctx, x->path, &x->g);
  return st != FCM_OK && x->g ? FCM_ERR_INTERNAL : st;
}
static fcm_status tree_create(void *u)
{
  fixture *x = u;
  x->t_out = (fcm_aabb_tree *)x;
  fcm_status st = fcm_aabb_tree_create(x->ctx, 300, x->boxes, &x->t_out);
  return st != FCM_OK && x->t_out ? FCM_ERR_INTERNAL : st;
}
static fcm_status tree_query(void *u)
{
  fixture *x = u;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1000, 1, 1};
  return fcm_aabb_tree_query(x->tree, lo, hi, 300, x->ids, &x->count);
}
static fcm_status surface_arrays(void *u)
{
  fixture *x = u;
  x->s = (fcm_surface *)x;
  fcm_status st = fcm_surface_create(x->ctx, 5, &P[0][0], 2, C, &x->s);
  return st != FCM_OK && x->s ? FCM_ERR_INTERNAL : st;
}
static fcm_status surface_file(void *u)
{
  fixture *x = u;
  x->s = (fcm_surface *)x;
  fcm_status st = fcm_surface_create_from_file(x->ctx, x->path, &x->s);
  return st != FCM_OK && x->s ? FCM_ERR_INTERNAL : st;
}
static void release(void *u)
{
  fixture *x = u;
  fcm_surface_destroy(&x->s);
  fcm_geometry_destroy(&x->g);
  fcm_aabb_tree_destroy(&x->t_out);
}

static void write_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (f) fputs(text, f), fclose(f);
}

int main(void)
{
  failing f;
  static fixture x;
  x.ctx = failing_ctx(&f);
  TEST_TRUE(x.ctx != NULL);
  if (!x.ctx) return TEST_RESULT();
  alloc_loop(x.ctx, &f, "fcm_geometry_create", from_arrays, release, &x, 3, 1000);
  write_file("geom_alloc_tet.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                   "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n"
                                   "$EndNodes\n$Elements\n3\n"
                                   "1 2 2 0 1 1 2 3\n"
                                   "2 4 2 0 1 1 2 3 4\n3 4 2 0 1 3 2 4 5\n$EndElements\n");
  write_file("geom_alloc_hex.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n"
                                   "1 0 0 0\n2 2 0 0\n3 2 2 0\n4 0 2 0\n"
                                   "5 0.5 0.5 1\n6 1.5 0.5 1\n7 1.5 1.5 1\n8 0.5 1.5 1\n"
                                   "$EndNodes\n$Elements\n1\n1 5 2 0 1 1 2 3 4 5 6 7 8\n"
                                   "$EndElements\n");
  x.path = "geom_alloc_tet.msh";
  alloc_loop(x.ctx, &f, "fcm_geometry_create_from_gmsh (tet4)", from_gmsh, release, &x, 3, 1000);
  x.path = "geom_alloc_hex.msh";
  alloc_loop(x.ctx, &f, "fcm_geometry_create_from_gmsh (hex8)", from_gmsh, release, &x, 3, 1000);
  remove("geom_alloc_tet.msh");
  remove("geom_alloc_hex.msh");
  /* 300 unit boxes in a row */
  for (int i = 0; i < 300; i++) {
    double b[6] = {i, 0, 0, i + 1, 1, 1};
    memcpy(x.boxes + 6 * i, b, sizeof b);
  }
  alloc_loop(x.ctx, &f, "fcm_aabb_tree_create", tree_create, release, &x, 3, 1000);
  TEST_OK(x.ctx, fcm_aabb_tree_create(x.ctx, 300, x.boxes, &x.tree));
  alloc_loop(x.ctx, &f, "fcm_aabb_tree_query", tree_query, NULL, &x, 2, 1000);
  TEST_TRUE(x.count == 300 && x.ids[0] == 0 && x.ids[299] == 299);
  fcm_aabb_tree_destroy(&x.tree);

  alloc_loop(x.ctx, &f, "fcm_surface_create", surface_arrays, release, &x, 2, 1000);
  write_file("geom_alloc.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                               "f 1 4 3 2\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n");
  write_file("geom_alloc.stl", "solid t\n"
                               "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\n"
                               "vertex 1 0 0\nendloop\nendfacet\n"
                               "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                               "vertex 0 0 1\nendloop\nendfacet\n"
                               "facet normal -1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\n"
                               "vertex 0 1 0\nendloop\nendfacet\n"
                               "facet normal 1 1 1\nouter loop\nvertex 1 0 0\nvertex 0 1 0\n"
                               "vertex 0 0 1\nendloop\nendfacet\nendsolid t\n");
  write_file("geom_alloc.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\n"
                               "property double y\nproperty double z\nelement face 4\n"
                               "property list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const char *const files[3] = {"geom_alloc.obj", "geom_alloc.stl", "geom_alloc.ply"};
  for (int k = 0; k < 3; k++) {
    char name[96];
    snprintf(name, sizeof name, "fcm_surface_create_from_file (%s)", files[k]);
    x.path = files[k];
    alloc_loop(x.ctx, &f, name, surface_file, release, &x, 2, 1000);
    remove(files[k]);
  }
  TEST_TRUE(fcm_ctx_live_allocations(x.ctx) == 0);
  fcm_ctx_destroy(&x.ctx);
  return TEST_RESULT();
}
