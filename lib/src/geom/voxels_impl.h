/* fcm geom, internal part of the voxel images: the image struct and what the readers
 * (voxel_read.c) share with the image object and its boxes (voxels.c). */
#ifndef FCM_VOXELS_IMPL_H
#define FCM_VOXELS_IMPL_H

#include "fcm/voxels.h"
#include "geom/geom_impl.h"

struct fcm_voxel_image {
  fcm_ctx *ctx;
  fcm_index dims[3];
  double axes[9]; /* row d: axis vector d */
  double origin[3];
  double *values;
};

#define VOXEL_MAX_COUNT ((fcm_index)1 << 40)
#define VOXEL_MAX_FILE  ((size_t)1 << 44)

/* The determinant of the 3 x 3 matrix a (row-major). */
static inline double fcm__voxel_det3(const double *a)
{
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
         a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/* FCM_ERR_ARG (messages start with `who`) unless the sizes, axis vectors and origin describe a
 * valid image: sizes >= 1, at most 2^40 voxels, finite values within the coordinate range,
 * axis vectors that span 3D. (voxels.c) */
fcm_status fcm__voxel_check_geometry(fcm_ctx *ctx, const char *who, const fcm_index dims[3],
                                     const double axes[9], const double origin[3]);

#endif /* FCM_VOXELS_IMPL_H */
