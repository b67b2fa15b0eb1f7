/* fcm — voxel images (CT scans, labelled segmentations) as embedded geometries: an image
 * read from NRRD (.nrrd attached, .nhdr detached) or MetaImage (.mhd + raw data, .mha
 * attached), the voxels selected by a threshold or a label set, merged into boxes and
 * returned as an fcm_geometry of Hex8 cells.
 *
 * Geometry of an image: voxel (i, j, k) (i fastest in the file) is centred at
 * origin + i a0 + j a1 + k a2, where a_d are the axis vectors (spacing times direction);
 * it occupies the parallelepiped origin + (i - 1/2 .. i + 1/2) a0 + ... (the convention of
 * NRRD "space origin" and MetaImage "Offset": the origin is the first voxel's centre). */
#ifndef FCM_VOXELS_H
#define FCM_VOXELS_H

#include "fcm/core.h"
#include "fcm/geom.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A 3D scalar image (opaque): dims[0] x dims[1] x dims[2] values as double, i fastest
 * (8 bytes per voxel whatever the file's type: a 512^3 CT scan takes 1 GiB, plus the file
 * while it is read and a byte per voxel while it is turned into boxes). */
typedef struct fcm_voxel_image fcm_voxel_image;

/** Create an image by copying caller values.
 * @param[in] dims   voxels per axis, each >= 1 (product at most 2^40)
 * @param[in] axes   3 x 3 row-major, row d = axis vector a_d (spacing x direction); NULL:
 *                   the identity (unit spacing); must have a non-zero, finite determinant
 * @param[in] origin centre of voxel (0,0,0); NULL: (0,0,0)
 * @param[in] values dims[0] dims[1] dims[2] values, i fastest, copied (NaN allowed: never
 *                   selected)
 * @param[out] img   the image, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (NULL, bad dims, singular or non-finite axes/origin, voxels
 *         reaching beyond +-1e50), FCM_ERR_ALLOC.
 * Allocates; release with fcm_voxel_image_destroy(). */
FCM_API fcm_status fcm_voxel_image_create(fcm_ctx *ctx, const fcm_index dims[3],
                                          const double axes[9], const double origin[3],
                                          const double *values, fcm_voxel_image **img);

/** Read an image; the format comes from the extension: ".nrrd" / ".nhdr" (NRRD, magic
 * NRRD0001..NRRD0005: dimension 3; types int8, uint8, int16, uint16, int32, uint32, int64,
 * uint64, float, double under their NRRD names; encodings raw and ascii (gzip, bzip2 and
 * hex are refused: fcm has no zlib); endian; "space directions" or "spacings"; "space
 * origin"; "byte skip" (-1: data at the end), "line skip"; "data file" relative to the
 * header) or ".mhd" / ".mha" (MetaImage: NDims = 3, DimSize, ElementType MET_CHAR ..
 * MET_DOUBLE, ElementSpacing, Offset / Origin / Position, TransformMatrix, ElementByteOrderMSB,
 * HeaderSize, ElementDataFile = file or LOCAL; compressed data refused).
 * @return FCM_OK; FCM_ERR_IO (cannot open/read, naming the file; for a detached data file
 *         also the header and its line that name it); FCM_ERR_FORMAT ("path:line: field:
 *         ..." naming the bad field, its value and the valid values or range; data files
 *         shorter than announced, with the byte counts and the header they belong to);
 *         FCM_ERR_UNSUPPORTED (compressed encodings, dimension other than 3, several channels,
 *         other extensions); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_voxel_image_create_from_file(fcm_ctx *ctx, const char *path,
                                                    fcm_voxel_image **img);

/** Destroy an image; accepts NULL and `*img == NULL`, sets `*img = NULL`. */
FCM_API void fcm_voxel_image_destroy(fcm_voxel_image **img);

/** Accessors (img must not be NULL): voxels per axis; the 3 x 3 axis vectors (row d =
 * a_d); the centre of voxel (0,0,0); the values (i fastest, valid for the image's life). */
FCM_API void fcm_voxel_image_dims(const fcm_voxel_image *img, fcm_index dims[3]);
FCM_API void fcm_voxel_image_axes(const fcm_voxel_image *img, double axes[9]);
FCM_API void fcm_voxel_image_origin(const fcm_voxel_image *img, double origin[3]);
FCM_API const double *fcm_voxel_image_values(const fcm_voxel_image *img);

/** Which voxels make the body, and how they become cells. */
typedef struct fcm_voxel_options {
  double threshold;     /**< with no labels: a voxel is selected when value >= threshold;
                             default 0.5 (binary 0/1 images) */
  const double *labels; /**< label set (borrowed): a voxel is selected when its value equals
                             one of them; NULL (default): use the threshold */
  int num_labels;       /**< length of labels, 0 (default) to 256 */
  int merge;            /**< 1 (default): greedy merging of selected voxels into boxes (runs
                             along i, extended along j, then k); 0: one cell per voxel */
} fcm_voxel_options;

/** Defaults as documented on each member. */
FCM_API fcm_voxel_options fcm_voxel_options_default(void);

/** What fcm_geometry_create_from_voxels() did. */
typedef struct fcm_voxel_info {
  fcm_index num_voxels;   /**< voxels in the image */
  fcm_index num_selected; /**< voxels selected */
  fcm_index num_nan;      /**< voxels whose value is NaN: never selected (outside the body);
                               when > 0 a warning is logged (FCM_LOG_WARNING) with the count
                               and the first one */
  fcm_index num_boxes;    /**< Hex8 cells created (= num_selected without merging) */
  double voxel_volume;    /**< |det axes| */
} fcm_voxel_info;

/** The selected voxels as a geometry of Hex8 cells (parallelepipeds; boxes when the axes
 * are orthogonal): the volume is num_selected x voxel_volume up to rounding. Cells share
 * the lattice nodes at their corners. The boundary triangles are the exact voxel surface:
 * the box faces next to an unselected voxel or the image's edge, merged into rectangles
 * per box (their corners are extra lattice nodes, not used by any cell), two triangles
 * each, owned by that box, outward; fcm_geometry_create_transformed() keeps them. NaN
 * values are never selected; they are counted (info->num_nan) and logged as a warning.
 * @param[in] opts NULL for defaults; @param[out] info may be NULL
 * @return FCM_OK; FCM_ERR_ARG (NULL, num_labels outside [0, 256], labels NULL with
 *         num_labels > 0, non-finite threshold or label); FCM_ERR_GEOMETRY (no voxel
 *         selected, giving the value range of the image); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_geometry_create_from_voxels(fcm_ctx *ctx, const fcm_voxel_image *img,
                                                   const fcm_voxel_options *opts,
                                                   fcm_geometry **geom, fcm_voxel_info *info);

#ifdef __cplusplus
}
#endif
#endif /* FCM_VOXELS_H */
