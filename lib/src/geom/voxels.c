/* Voxel images: the image object, and the selected voxels merged greedily into boxes with
 * their exposed faces as the boundary (fcm_geometry_create_from_voxels). */
#include "geom/voxels_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

fcm_status fcm__voxel_check_geometry(fcm_ctx *ctx, const char *who, const fcm_index dims[3],
                                     const double axes[9], const double origin[3])
{
  fcm_status st = FCM_OK;
  double n = 1.0;
  for (int d = 0; d < 3; d++) {
    FCM_CHECK(dims[d] >= 1, ctx, FCM_ERR_ARG, "%s: size %lld of axis %d must be >= 1", who,
              (long long)dims[d], d);
    n *= (double)dims[d];
    FCM_CHECK(isfinite(origin[d]), ctx, FCM_ERR_ARG, "%s: origin[%d] = %g is not finite", who, d,
              origin[d]);
  }
  FCM_CHECK(n <= (double)VOXEL_MAX_COUNT, ctx, FCM_ERR_ARG,
            "%s: %lld x %lld x %lld voxels exceed the limit of 2^40", who, (long long)dims[0],
            (long long)dims[1], (long long)dims[2]);
  for (int i = 0; i < 9; i++)
    FCM_CHECK(isfinite(axes[i]), ctx, FCM_ERR_ARG,
              "%s: axis vector %d component %d = %g is not "
              "finite",
              who, i / 3, i % 3, axes[i]);
  for (int d = 0; d < 3; d++) { /* the farthest voxel corner along coordinate d */
    double reach = fabs(origin[d]);
    for (int k = 0; k < 3; k++)
      reach += ((double)dims[k] + 0.5) * fabs(axes[3 * k + d]);
    FCM_CHECK(reach <= FCM__COORD_MAX, ctx, FCM_ERR_ARG,
              "%s: the image reaches |%c| = %g (origin, axis vectors and sizes), "
              "outside " FCM__COORD_RANGE,
              who, "xyz"[d], reach);
  }
  const double det = fcm__voxel_det3(axes);
  double scale = 1.0;
  for (int d = 0; d < 3; d++)
    scale *= sqrt(axes[3 * d] * axes[3 * d] + axes[3 * d + 1] * axes[3 * d + 1] +
                  axes[3 * d + 2] * axes[3 * d + 2]);
  FCM_CHECK(scale > 0.0 && fabs(det) > 1e-12 * scale, ctx, FCM_ERR_ARG,
            "%s: the axis vectors are (nearly) linearly dependent or zero (det %g, product of "
            "lengths %g); they must span 3D",
            who, det, scale);
cleanup:
  return st;
}

fcm_status fcm_voxel_image_create(fcm_ctx *ctx, const fcm_index dims[3], const double axes[9],
                                  const double origin[3], const double *values,
                                  fcm_voxel_image **img)
{
  fcm_status st = FCM_OK;
  static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, Z[3] = {0, 0, 0};
  fcm_voxel_image *m = NULL;
  FCM_CHECK(ctx && img, ctx, FCM_ERR_ARG, "voxel image: NULL argument");
  *img = NULL;
  FCM_CHECK(dims && values, ctx, FCM_ERR_ARG, "voxel image: dims or values is NULL");
  if (!axes) axes = I;
  if (!origin) origin = Z;
  FCM_TRY(ctx, fcm__voxel_check_geometry(ctx, "voxel image", dims, axes, origin));
  const size_t n = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
  FCM_ALLOC(ctx, 1, m);
  m->ctx = ctx;
  memcpy(m->dims, dims, sizeof m->dims);
  memcpy(m->axes, axes, sizeof m->axes);
  memcpy(m->origin, origin, sizeof m->origin);
  FCM_ALLOC_RAW(ctx, n, m->values);
  memcpy(m->values, values, n * sizeof *values);
  *img = m;
  m = NULL;
cleanup:
  fcm_voxel_image_destroy(&m);
  return st;
}

void fcm_voxel_image_destroy(fcm_voxel_image **img)
{
  if (!img || !*img) return;
  fcm__free((*img)->ctx, (*img)->values);
  fcm__free((*img)->ctx, *img);
  *img = NULL;
}

void fcm_voxel_image_dims(const fcm_voxel_image *img, fcm_index dims[3])
{
  memcpy(dims, img->dims, sizeof img->dims);
}

void fcm_voxel_image_axes(const fcm_voxel_image *img, double axes[9])
{
  memcpy(axes, img->axes, sizeof img->axes);
}

void fcm_voxel_image_origin(const fcm_voxel_image *img, double origin[3])
{
  memcpy(origin, img->origin, sizeof img->origin);
}

const double *fcm_voxel_image_values(const fcm_voxel_image *img)
{
  return img->values;
}

/* ---------------------------------------------------------------- voxels -> boxes */

fcm_voxel_options fcm_voxel_options_default(void)
{
  fcm_voxel_options o = {0};
  o.threshold = 0.5;
  o.merge = 1;
  return o;
}

static int cmp_key(const void *a, const void *b)
{
  const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return (x > y) - (x < y);
}

/* The exposed parts of the faces of the boxes box[0 .. nb) (6 lattice indices each): face
 * cells whose neighbouring voxel across the face is unselected (mask 0) or outside the
 * image, merged greedily into rectangles (runs along the face's first axis, extended along
 * the second). Each rectangle: 4 lattice keys (i + (nx+1)(j + (ny+1)k)), counter-clockwise
 * seen from outside the box in lattice coordinates, and its box. */
static fcm_status exposed_faces(fcm_ctx *ctx, const unsigned char *mask, const fcm_index dims[3],
                                const int64_t *box, size_t nb, int64_t **rect, size_t **rbox,
                                size_t *nr)
{
  fcm_status st = FCM_OK;
  const int64_t n[3] = {dims[0], dims[1], dims[2]}, lx = n[0] + 1, ly = n[1] + 1;
  unsigned char *flag = NULL;
  size_t cap = 0;
  int64_t fmax = 0;
  for (int d = 0; d < 3; d++)
    fmax = FCM_MAX(fmax, n[(d + 1) % 3] * n[(d + 2) % 3]);
  FCM_ALLOC_RAW(ctx, (size_t)fmax, flag);
  for (size_t b = 0; b < nb; b++) {
    const int64_t *lo = box + 6 * b, *hi = lo + 3;
    for (int d = 0; d < 3; d++)
      for (int side = 0; side < 2; side++) {
        const int u = (d + 1) % 3, v = (d + 2) % 3;
        const int64_t plane = side ? hi[d] : lo[d], layer = side ? hi[d] : lo[d] - 1;
        const int64_t nu = hi[u] - lo[u], nv = hi[v] - lo[v];
        for (int64_t b2 = 0; b2 < nv; b2++)
          for (int64_t a = 0; a < nu; a++) {
            int64_t g[3];
            g[d] = layer, g[u] = lo[u] + a, g[v] = lo[v] + b2;
            flag[a + nu * b2] =
                (unsigned char)(layer < 0 || layer >= n[d] ||
                                !mask[(size_t)(g[0] + n[0] * (g[1] + n[1] * g[2]))]);
          }
        for (int64_t b2 = 0; b2 < nv; b2++)
          for (int64_t a = 0; a < nu; a++) {
            if (!flag[a + nu * b2]) continue;
            int64_t a1 = a + 1, c1 = b2 + 1;
            while (a1 < nu && flag[a1 + nu * b2])
              a1++;
            for (int ok = 1; ok && c1 < nv; c1 += ok)
              for (int64_t x = a; ok && x < a1; x++)
                ok = flag[x + nu * c1];
            for (int64_t y = b2; y < c1; y++)
              for (int64_t x = a; x < a1; x++)
                flag[x + nu * y] = 0;
            if (*nr == cap) {
              const size_t nc = cap ? 2 * cap : 256;
              FCM_TRY(ctx, fcm__resize(ctx, (void **)rect, 4 * cap, 4 * nc, sizeof **rect));
              FCM_TRY(ctx, fcm__resize(ctx, (void **)rbox, cap, nc, sizeof **rbox));
              cap = nc;
            }
            /* (u, v) corners counter-clockwise seen from +e_d (e_u x e_v = e_d); reversed
             * on the low side */
            const int64_t cu[4] = {a, a1, a1, a}, cv[4] = {b2, b2, c1, c1};
            for (int c = 0; c < 4; c++) {
              const int k = side ? c : (4 - c) % 4;
              int64_t g[3];
              g[d] = plane, g[u] = lo[u] + cu[k], g[v] = lo[v] + cv[k];
              (*rect)[4 * *nr + (size_t)c] = g[0] + lx * (g[1] + ly * g[2]);
            }
            (*rbox)[(*nr)++] = b;
          }
      }
  }
cleanup:
  fcm__free(ctx, flag);
  return st;
}

/* FCM_ERR_ARG naming the first bad option. */
static fcm_status check_options(fcm_ctx *ctx, const fcm_voxel_options *o)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(o->num_labels >= 0 && o->num_labels <= 256, ctx, FCM_ERR_ARG,
            "voxels: num_labels = %d outside [0, 256]", o->num_labels);
  FCM_CHECK(o->num_labels == 0 || o->labels, ctx, FCM_ERR_ARG,
            "voxels: labels is NULL with num_labels = %d", o->num_labels);
  FCM_CHECK(o->num_labels > 0 || isfinite(o->threshold), ctx, FCM_ERR_ARG,
            "voxels: threshold %g is not finite", o->threshold);
  for (int l = 0; l < o->num_labels; l++)
    FCM_CHECK(isfinite(o->labels[l]), ctx, FCM_ERR_ARG, "voxels: label %d is %g (not finite)", l,
              o->labels[l]);
cleanup:
  return st;
}

/* mask[i] = 1 for the selected voxels (a label of o, or at least the threshold; NaN never),
 * *nsel of them, *nnan NaN values (a warning names the first); FCM_ERR_GEOMETRY when none is
 * selected. */
static fcm_status select_voxels(fcm_ctx *ctx, const fcm_voxel_image *img,
                                const fcm_voxel_options *o, unsigned char *mask, size_t *nsel,
                                size_t *nnan)
{
  fcm_status st = FCM_OK;
  const size_t nx = (size_t)img->dims[0], ny = (size_t)img->dims[1];
  const size_t n = nx * ny * (size_t)img->dims[2];
  size_t first_nan = 0;
  double vmin = HUGE_VAL, vmax = -HUGE_VAL;
  *nsel = *nnan = 0;
  for (size_t i = 0; i < n; i++) {
    const double v = img->values[i];
    if (isnan(v) && (*nnan)++ == 0) first_nan = i;
    int s = 0;
    if (o->num_labels > 0) {
      for (int l = 0; l < o->num_labels && !s; l++)
        s = v == o->labels[l];
    } else {
      s = v >= o->threshold;
    }
    mask[i] = (unsigned char)s;
    *nsel += (size_t)s;
    if (isfinite(v)) vmin = v < vmin ? v : vmin, vmax = v > vmax ? v : vmax;
  }
  if (*nnan > 0)
    fcm__log(ctx, FCM_LOG_WARNING,
             "voxels: %zu of %zu voxel values are NaN and count as outside the body (never "
             "selected); the first is voxel (%lld, %lld, %lld)",
             *nnan, n, (long long)(first_nan % nx), (long long)(first_nan / nx % ny),
             (long long)(first_nan / (nx * ny)));
  if (*nsel == 0) {
    if (o->num_labels > 0)
      FCM_CHECK(0, ctx, FCM_ERR_GEOMETRY,
                "voxels: no voxel has one of the %d labels (first %g); the image values lie in "
                "[%g, %g]%s",
                o->num_labels, o->labels[0], vmin, vmax, *nnan == n ? " (every value is NaN)" : "");
    FCM_CHECK(0, ctx, FCM_ERR_GEOMETRY,
              "voxels: no voxel reaches the threshold %g; the image values lie in [%g, %g]%s",
              o->threshold, vmin, vmax, *nnan == n ? " (every value is NaN)" : "");
  }
cleanup:
  return st;
}

/* The selected voxels (mask 1; set to 2 as they are taken) as boxes (6 per box: i0 j0 k0 i1 j1
 * k1, half-open), in scan order: with `merge` each grows greedily along x, then y, then z;
 * else one box per voxel. */
static fcm_status merge_boxes(fcm_ctx *ctx, const fcm_index dims[3], int merge, unsigned char *mask,
                              int64_t **box_out, size_t *nb_out)
{
  fcm_status st = FCM_OK;
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  int64_t *box = NULL;
  size_t nb = 0, cap = 0;
#define AVAIL(i, j, k) (mask[(size_t)((i) + nx * ((j) + ny * (k)))] == 1)
  for (int64_t k = 0; k < nz; k++)
    for (int64_t j = 0; j < ny; j++)
      for (int64_t i = 0; i < nx; i++) {
        if (!AVAIL(i, j, k)) continue;
        int64_t i1 = i + 1, j1 = j + 1, k1 = k + 1;
        if (merge) {
          while (i1 < nx && AVAIL(i1, j, k))
            i1++;
          for (;; j1++) {
            int ok = j1 < ny;
            for (int64_t a = i; ok && a < i1; a++)
              ok = AVAIL(a, j1, k);
            if (!ok) break;
          }
          for (;; k1++) {
            int ok = k1 < nz;
            for (int64_t b = j; ok && b < j1; b++)
              for (int64_t a = i; ok && a < i1; a++)
                ok = AVAIL(a, b, k1);
            if (!ok) break;
          }
        }
        for (int64_t c = k; c < k1; c++)
          for (int64_t b = j; b < j1; b++)
            for (int64_t a = i; a < i1; a++)
              mask[(size_t)(a + nx * (b + ny * c))] = 2;
        if (nb == cap) {
          size_t nc = cap ? 2 * cap : 64;
          FCM_TRY(ctx, fcm__resize(ctx, (void **)&box, 6 * cap, 6 * nc, sizeof *box));
          cap = nc;
        }
        int64_t *bx = box + 6 * nb++;
        bx[0] = i, bx[1] = j, bx[2] = k, bx[3] = i1, bx[4] = j1, bx[5] = k1;
      }
#undef AVAIL
  *box_out = box, *nb_out = nb;
  box = NULL;
cleanup:
  fcm__free(ctx, box);
  return st;
}

/* The nodes: the lattice corner keys of the boxes and the rectangles, sorted and unique
 * (*keys, *nn of them; key i + (nx+1)(j + (ny+1)k)), their positions X (voxel centres at the
 * integer lattice points minus a half), and the hexahedra (8 node indices per box, positively
 * oriented: a left-handed lattice (`flip`) lists the top face first). */
static fcm_status box_nodes(fcm_ctx *ctx, const fcm_voxel_image *img, const int64_t *box, size_t nb,
                            const int64_t *rect, size_t nr, int flip, int64_t **keys_out,
                            size_t *nn_out, double **X_out, fcm_index **cells_out)
{
  fcm_status st = FCM_OK;
  const int64_t lx = img->dims[0] + 1, ly = img->dims[1] + 1;
  int64_t *keys = NULL;
  double *X = NULL;
  fcm_index *cells = NULL;
  FCM_ALLOC_RAW(ctx, 8 * nb + 4 * nr, keys);
  static const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                   {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (size_t b = 0; b < nb; b++)
    for (int c = 0; c < 8; c++) {
      const int64_t *bx = box + 6 * b;
      const int64_t I = bx[3 * corner[c][0]], J = bx[1 + 3 * corner[c][1]],
                    K = bx[2 + 3 * corner[c][2]];
      keys[8 * b + (size_t)c] = I + lx * (J + ly * K);
    }
  FCM_ALLOC_RAW(ctx, 8 * nb, cells);
  for (size_t q = 0; q < 8 * nb; q++)
    cells[q] = (fcm_index)keys[q];
  memcpy(keys + 8 * nb, rect, 4 * nr * sizeof *keys);
  qsort(keys, 8 * nb + 4 * nr, sizeof *keys, cmp_key);
  size_t nn = 0;
  for (size_t q = 0; q < 8 * nb + 4 * nr; q++)
    if (q == 0 || keys[q] != keys[nn - 1]) keys[nn++] = keys[q];
  FCM_ALLOC_RAW(ctx, 3 * nn, X);
  for (size_t a = 0; a < nn; a++) {
    const int64_t key = keys[a];
    const double p[3] = {(double)(key % lx) - 0.5, (double)((key / lx) % ly) - 0.5,
                         (double)(key / (lx * ly)) - 0.5};
    for (int d = 0; d < 3; d++)
      X[3 * a + (size_t)d] =
          img->origin[d] + p[0] * img->axes[d] + p[1] * img->axes[3 + d] + p[2] * img->axes[6 + d];
  }
  for (size_t b = 0; b < nb; b++) {
    fcm_index *cell = cells + 8 * b, tmp[8];
    for (int c = 0; c < 8; c++) {
      const int64_t key = (int64_t)cell[c];
      const int64_t *hit = bsearch(&key, keys, nn, sizeof *keys, cmp_key);
      tmp[c] = (fcm_index)(hit - keys);
    }
    /* A left-handed lattice: the top face first keeps the hex positively oriented. */
    for (int c = 0; c < 8; c++)
      cell[c] = tmp[flip ? (c + 4) % 8 : c];
  }
  *keys_out = keys, *nn_out = nn, *X_out = X, *cells_out = cells;
  keys = NULL, X = NULL, cells = NULL;
cleanup:
  fcm__free(ctx, keys);
  fcm__free(ctx, X);
  fcm__free(ctx, cells);
  return st;
}

/* Boundary triangles: two per rectangle (its nodes among keys[0 .. nn)), reversed on a
 * left-handed lattice, each with the box of its rectangle. */
static fcm_status boundary_triangles(fcm_ctx *ctx, const int64_t *rect, const size_t *rbox,
                                     size_t nr, const int64_t *keys, size_t nn, int flip,
                                     fcm_index **tris_out, fcm_index **tri_box_out)
{
  fcm_status st = FCM_OK;
  fcm_index *tris = NULL, *tri_box = NULL;
  FCM_ALLOC_RAW(ctx, 6 * nr, tris);
  FCM_ALLOC_RAW(ctx, 2 * nr, tri_box);
  for (size_t q = 0; q < nr; q++) {
    fcm_index v[4];
    for (int c = 0; c < 4; c++) {
      const int64_t *hit = bsearch(rect + 4 * q + c, keys, nn, sizeof *keys, cmp_key);
      v[flip ? 3 - c : c] = (fcm_index)(hit - keys);
    }
    const fcm_index t[6] = {v[0], v[1], v[2], v[0], v[2], v[3]};
    memcpy(tris + 6 * q, t, sizeof t);
    tri_box[2 * q] = tri_box[2 * q + 1] = (fcm_index)rbox[q];
  }
  *tris_out = tris, *tri_box_out = tri_box;
  tris = tri_box = NULL;
cleanup:
  fcm__free(ctx, tris);
  fcm__free(ctx, tri_box);
  return st;
}

fcm_status fcm_geometry_create_from_voxels(fcm_ctx *ctx, const fcm_voxel_image *img,
                                           const fcm_voxel_options *opts, fcm_geometry **geom,
                                           fcm_voxel_info *info)
{
  fcm_status st = FCM_OK;
  unsigned char *mask = NULL;
  int64_t *box = NULL, *keys = NULL; /* box: 6 per box (i0 j0 k0 i1 j1 k1, half-open) */
  int64_t *rect = NULL;              /* exposed rectangles: 4 lattice keys each */
  size_t *rbox = NULL, nr = 0;       /* the box of each rectangle */
  fcm_index *tris = NULL, *tri_box = NULL;
  double *X = NULL;
  fcm_index *cells = NULL;
  size_t nb = 0, nn = 0, nsel = 0, nnan = 0;
  fcm_voxel_options o = opts ? *opts : fcm_voxel_options_default();
  FCM_CHECK(ctx && geom, ctx, FCM_ERR_ARG, "voxels: NULL argument");
  *geom = NULL;
  if (info) memset(info, 0, sizeof *info);
  FCM_CHECK(img, ctx, FCM_ERR_ARG, "voxels: the image is NULL");
  FCM_TRY(ctx, check_options(ctx, &o));
  const size_t n = (size_t)img->dims[0] * (size_t)img->dims[1] * (size_t)img->dims[2];
  FCM_ALLOC_RAW(ctx, n, mask);
  FCM_TRY(ctx, select_voxels(ctx, img, &o, mask, &nsel, &nnan));
  FCM_TRY(ctx, merge_boxes(ctx, img->dims, o.merge, mask, &box, &nb));
  /* The exposed faces of each box (next to an unselected voxel or the image's edge) as
   * rectangles merged greedily on the face: 4 lattice keys each, counter-clockwise seen from
   * outside in lattice coordinates, and the box they belong to. */
  FCM_TRY(ctx, exposed_faces(ctx, mask, img->dims, box, nb, &rect, &rbox, &nr));
  const int flip = fcm__voxel_det3(img->axes) < 0.0;
  FCM_TRY(ctx, box_nodes(ctx, img, box, nb, rect, nr, flip, &keys, &nn, &X, &cells));
  FCM_TRY(ctx, boundary_triangles(ctx, rect, rbox, nr, keys, nn, flip, &tris, &tri_box));
  const double vv = fabs(fcm__voxel_det3(img->axes));
  FCM_TRY(ctx, fcm__geom_create_take(ctx, "voxels", FCM_ELEMENT_HEX8, (fcm_index)nn, &X,
                                     (fcm_index)nb, &cells, 1, geom));
  fcm__free(ctx, (*geom)->tris);
  fcm__free(ctx, (*geom)->tri_cell);
  (*geom)->tris = tris, (*geom)->tri_cell = tri_box, (*geom)->num_tris = (fcm_index)(2 * nr);
  (*geom)->custom_boundary = 1;
  tris = tri_box = NULL;
  if (info) {
    info->num_voxels = (fcm_index)n;
    info->num_selected = (fcm_index)nsel;
    info->num_nan = (fcm_index)nnan;
    info->num_boxes = (fcm_index)nb;
    info->voxel_volume = vv;
  }
cleanup:
  fcm__free(ctx, mask);
  fcm__free(ctx, box);
  fcm__free(ctx, keys);
  fcm__free(ctx, X);
  fcm__free(ctx, cells);
  fcm__free(ctx, rect);
  fcm__free(ctx, rbox);
  fcm__free(ctx, tris);
  fcm__free(ctx, tri_box);
  return st;
}
