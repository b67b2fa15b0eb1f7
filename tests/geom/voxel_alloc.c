/* Allocation failures in the voxel and level-set entry points: fcm_voxel_image_create,
 * fcm_voxel_image_create_from_file (attached NRRD; MetaImage with a detached raw file),
 * fcm_geometry_create_from_voxels (merged boxes and one cell per voxel, growing the box
 * list) and fcm_geometry_create_from_level_set (a sphere: tet list growth, the error
 * estimate). Failing the k-th allocation until success gives FCM_ERR_ALLOC, NULL outputs and
 * no leak. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/levelset.h"
#include "fcm/voxels.h"
#include "alloc_loop.h"

#include <stdio.h>

enum { N = 6 };

typedef struct fixture {
  fcm_ctx *ctx;
  fcm_voxel_image *img, *src;
  fcm_geometry *g;
  const char *path;
  double values[N * N * N];
  int merge;
} fixture;

static fcm_status image_create(void *u)
{
  fixture *x = u;
  const fcm_index d[3] = {N, N, N};
  x->img = (fcm_voxel_image *)x;
  fcm_status st = fcm_voxel_image_create(x->ctx, d, NULL, NULL, x->values, &x->img);
  return st != FCM_OK && x->img ? FCM_ERR_INTERNAL : st;
}
static fcm_status image_file(void *u)
{
  fixture *x = u;
  x->img = (fcm_voxel_image *)x;
  fcm_status st = fcm_voxel_image_create_from_file(x->ctx, x->path, &x->img);
  return st != FCM_OK && x->img ? FCM_ERR_INTERNAL : st;
}
static fcm_status voxels(void *u)
{
  fixture *x = u;
  fcm_voxel_options o = fcm_voxel_options_default();
  o.merge = x->merge;
  x->g = (fcm_geometry *)x;
  fcm_status st = fcm_geometry_create_from_voxels(x->ctx, x->src, &o, &x->g, NULL);
  return st != FCM_OK && x->g ? FCM_ERR_INTERNAL : st;
}
static fcm_status level_set(void *u)
{
  fixture *x = u;
  fcm_implicit s = {0};
  s.kind = FCM_IMPLICIT_SPHERE, s.radius = 0.8;
  fcm_implicit_tree t = {1, &s};
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {3, 3, 3};
  x->g = (fcm_geometry *)x;
  fcm_status st = fcm_geometry_create_from_level_set(x->ctx, fcm_implicit_eval, &t, lo, hi, n, NULL,
                                                     &x->g, NULL);
  return st != FCM_OK && x->g ? FCM_ERR_INTERNAL : st;
}
static void release(void *u)
{
  fixture *x = u;
  fcm_voxel_image_destroy(&x->img);
  fcm_geometry_destroy(&x->g);
}

int main(void)
{
  failing f;
  static fixture x;
  x.ctx = failing_ctx(&f);
  TEST_TRUE(x.ctx != NULL);
  if (!x.ctx) return TEST_RESULT();
  for (int i = 0; i < N * N * N; i++)
    x.values[i] = (i * 7919) % 5 != 0; /* scattered holes */
  alloc_loop(x.ctx, &f, "fcm_voxel_image_create", image_create, release, &x, 2, 1000);

  FILE *fp = fopen("vox_alloc.nrrd", "wb");
  FILE *raw = fopen("vox_alloc.raw", "wb");
  FILE *mhd = fopen("vox_alloc.mhd", "w");
  TEST_TRUE(fp && raw && mhd);
  if (!fp || !raw || !mhd) return TEST_RESULT();
  fprintf(fp, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: %d %d %d\nencoding: raw\n\n", N, N, N);
  fprintf(mhd,
          "NDims = 3\nDimSize = %d %d %d\nElementType = MET_UCHAR\n"
          "ElementDataFile = vox_alloc.raw\n",
          N, N, N);
  for (int i = 0; i < N * N * N; i++)
    fputc((int)x.values[i], fp), fputc((int)x.values[i], raw);
  fclose(fp), fclose(raw), fclose(mhd);
  x.path = "vox_alloc.nrrd";
  alloc_loop(x.ctx, &f, "fcm_voxel_image_create_from_file (nrrd)", image_file, release, &x, 2,
             1000);
  x.path = "vox_alloc.mhd";
  alloc_loop(x.ctx, &f, "fcm_voxel_image_create_from_file (mhd)", image_file, release, &x, 3, 1000);
  TEST_OK(x.ctx, fcm_voxel_image_create_from_file(x.ctx, "vox_alloc.nrrd", &x.src));
  remove("vox_alloc.nrrd"), remove("vox_alloc.raw"), remove("vox_alloc.mhd");
  if (x.src) {
    x.merge = 1;
    alloc_loop(x.ctx, &f, "fcm_geometry_create_from_voxels (merged)", voxels, release, &x, 4, 1000);
    x.merge = 0;
    alloc_loop(x.ctx, &f, "fcm_geometry_create_from_voxels (per voxel)", voxels, release, &x, 4,
               1000);
    fcm_voxel_image_destroy(&x.src);
  }
  alloc_loop(x.ctx, &f, "fcm_geometry_create_from_level_set", level_set, release, &x, 5, 1000);
  TEST_TRUE(fcm_ctx_live_allocations(x.ctx) == 0);
  fcm_ctx_destroy(&x.ctx);
  return TEST_RESULT();
}
