/* Voxel images: volumes are exactly (selected voxels) x (voxel volume); a full block merges
 * into one box and a porous block into far fewer boxes than voxels; without merging the
 * boundary is exact; NRRD (attached, detached, every type, both endians, ascii, byte skip)
 * and MetaImage (.mhd + raw, .mha) round trips of a generated image; header errors name
 * file:line and the field; a missing or short detached data file is named with its header;
 * an image reaching beyond 1e50 is out of range; no selected voxel is an error giving the
 * value range; NaN values are never selected, counted and logged as one warning. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/voxels.h"
#include "test.h"

#include <stdint.h>
#include <stdio.h>

enum { NX = 7, NY = 5, NZ = 4 };

/* A porous block: 1 except spherical-ish holes and a tunnel, with labels 1..3 by layer. */
static double porous(int i, int j, int k)
{
  if ((i - 2) * (i - 2) + (j - 2) * (j - 2) + (k - 1) * (k - 1) <= 2) return 0;
  if (j == 4 && k == 2) return 0;
  return 1 + (k % 3);
}

static void put(FILE *f, double v, int type, int big)
{
  unsigned char b[8];
  uint64_t u = 0;
  int n = 1;
  switch (type) {
  case 0: /* uint8 */
    u = (uint8_t)v, n = 1;
    break;
  case 1: /* int8 */
    u = (uint8_t)(int8_t)(-v), n = 1;
    break;
  case 2: /* uint16 */
    u = (uint16_t)(1000 * v), n = 2;
    break;
  case 3: /* int16 */
    u = (uint16_t)(int16_t)(-1000 * v), n = 2;
    break;
  case 4: /* uint32 */
    u = (uint32_t)(100000 * v), n = 4;
    break;
  case 5: /* int32 */
    u = (uint32_t)(int32_t)(-100000 * v), n = 4;
    break;
  case 6: { /* float */
    float x = (float)(0.25 * v);
    uint32_t w;
    memcpy(&w, &x, 4);
    u = w, n = 4;
    break;
  }
  default: { /* double */
    double x = 0.1 * v;
    memcpy(&u, &x, 8);
    n = 8;
    break;
  }
  }
  for (int i = 0; i < n; i++)
    b[big ? n - 1 - i : i] = (unsigned char)(u >> (8 * i));
  fwrite(b, 1, (size_t)n, f);
}

static double expected(double v, int type)
{
  static const double s[8] = {1, -1, 1000, -1000, 100000, -100000, 0.25, 0.1};
  return type == 7 ? 0.1 * v : s[type] * v;
}

static void write_text(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (f) fputs(text, f), fclose(f);
}

static void check_values(const fcm_voxel_image *img, int type, const char *what)
{
  fcm_index d[3];
  fcm_voxel_image_dims(img, d);
  TEST_TRUE(d[0] == NX && d[1] == NY && d[2] == NZ);
  const double *v = fcm_voxel_image_values(img);
  int bad = 0;
  for (int k = 0; k < NZ; k++)
    for (int j = 0; j < NY; j++)
      for (int i = 0; i < NX; i++)
        bad += v[i + NX * (j + NY * k)] != expected(porous(i, j, k), type);
  if (bad) TEST_FAIL_("%s: %d values differ", what, bad);
}

static void round_trips(fcm_ctx *ctx)
{
  static const char *const names[8] = {"uint8", "int8",    "uint16", "short",
                                       "uint",  "int32_t", "float",  "double"};
  for (int type = 0; type < 8; type++)
    for (int big = 0; big < 2; big++) {
      FILE *f = fopen("vox_rt.nrrd", "wb");
      TEST_TRUE(f != NULL);
      if (!f) return;
      fprintf(f,
              "NRRD0004\n# generated\ntype: %s\ndimension: 3\nspace: left-posterior-superior\n"
              "sizes: %d %d %d\nspace directions: (0.5,0,0) (0,0.25,0) (0,0,2)\n"
              "kinds: domain domain domain\nendian: %s\nencoding: raw\n"
              "space origin: (1,2,3)\nmykey:=myvalue\n\n",
              names[type], NX, NY, NZ, big ? "big" : "little");
      for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
          for (int i = 0; i < NX; i++)
            put(f, porous(i, j, k), type, big);
      fclose(f);
      fcm_voxel_image *img = NULL;
      TEST_OK(ctx, fcm_voxel_image_create_from_file(ctx, "vox_rt.nrrd", &img));
      if (!img) continue;
      char what[64];
      snprintf(what, sizeof what, "nrrd %s %s", names[type], big ? "big" : "little");
      check_values(img, type, what);
      double A[9], o[3];
      fcm_voxel_image_axes(img, A);
      fcm_voxel_image_origin(img, o);
      TEST_TRUE(A[0] == 0.5 && A[4] == 0.25 && A[8] == 2 && A[1] == 0 && A[3] == 0);
      TEST_TRUE(o[0] == 1 && o[1] == 2 && o[2] == 3);
      fcm_voxel_image_destroy(&img);
    }
  remove("vox_rt.nrrd");

  /* Detached NRRD with a byte skip and spacings; the data file has 5 junk bytes first. */
  FILE *f = fopen("vox_rt.raw", "wb");
  TEST_TRUE(f != NULL);
  if (!f) return;
  fputs("JUNK!", f);
  for (int k = 0; k < NZ; k++)
    for (int j = 0; j < NY; j++)
      for (int i = 0; i < NX; i++)
        put(f, porous(i, j, k), 2, 1);
  fclose(f);
  char hdr[512];
  snprintf(hdr, sizeof hdr,
           "NRRD0005\ntype: unsigned short\ndimension: 3\nsizes: %d %d %d\nspacings: 2 3 4\n"
           "endian: big\nencoding: raw\nbyte skip: 5\ndata file: vox_rt.raw\n",
           NX, NY, NZ);
  write_text("vox_rt.nhdr", hdr);
  fcm_voxel_image *img = NULL;
  TEST_OK(ctx, fcm_voxel_image_create_from_file(ctx, "vox_rt.nhdr", &img));
  if (img) {
    check_values(img, 2, "detached nrrd");
    double A[9];
    fcm_voxel_image_axes(img, A);
    TEST_TRUE(A[0] == 2 && A[4] == 3 && A[8] == 4);
    fcm_voxel_image_destroy(&img);
  }
  /* byte skip -1: the data are the last bytes */
  snprintf(hdr, sizeof hdr,
           "NRRD0005\ntype: uint16\ndimension: 3\nsizes: %d %d %d\nendian: big\n"
           "encoding: raw\nbyte skip: -1\ndata file: vox_rt.raw\n",
           NX, NY, NZ);
  write_text("vox_rt.nhdr", hdr);
  TEST_OK(ctx, fcm_voxel_image_create_from_file(ctx, "vox_rt.nhdr", &img));
  if (img) check_values(img, 2, "byte skip -1"), fcm_voxel_image_destroy(&img);
  /* MetaImage: .mhd + raw with a header size, big endian. */
  snprintf(hdr, sizeof hdr,
           "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = True\n"
           "CompressedData = False\nTransformMatrix = 0 1 0 1 0 0 0 0 1\nOffset = -1 0 1\n"
           "ElementSpacing = 0.5 0.5 1\nDimSize = %d %d %d\nElementType = MET_USHORT\n"
           "HeaderSize = 5\nElementDataFile = vox_rt.raw\n",
           NX, NY, NZ);
  write_text("vox_rt.mhd", hdr);
  TEST_OK(ctx, fcm_voxel_image_create_from_file(ctx, "vox_rt.mhd", &img));
  if (img) {
    check_values(img, 2, "mhd");
    double A[9], o[3];
    fcm_voxel_image_axes(img, A);
    fcm_voxel_image_origin(img, o);
    TEST_TRUE(A[1] == 0.5 && A[3] == 0.5 && A[8] == 1 && A[0] == 0);
    TEST_TRUE(o[0] == -1 && o[1] == 0 && o[2] == 1);
    fcm_voxel_image_destroy(&img);
  }
  remove("vox_rt.raw");
  remove("vox_rt.nhdr");
  remove("vox_rt.mhd");
  /* MetaImage .mha (LOCAL, doubles, little endian) and NRRD ascii. */
  f = fopen("vox_rt.mha", "wb");
  FILE *g = fopen("vox_rt_ascii.nrrd", "w");
  TEST_TRUE(f && g);
  if (!f || !g) return;
  fprintf(f,
          "NDims = 3\nDimSize = %d %d %d\nElementType = MET_DOUBLE\n"
          "ElementByteOrderMSB = False\nElementDataFile = LOCAL\n",
          NX, NY, NZ);
  fprintf(g, "NRRD0001\ntype: double\ndimension: 3\nsizes: %d %d %d\nencoding: ascii\n\n", NX, NY,
          NZ);
  for (int k = 0; k < NZ; k++)
    for (int j = 0; j < NY; j++) {
      for (int i = 0; i < NX; i++) {
        put(f, porous(i, j, k), 7, 0);
        fprintf(g, "%.17g ", expected(porous(i, j, k), 7));
      }
      fputc('\n', g);
    }
  fclose(f);
  fclose(g);
  TEST_OK(ctx, fcm_voxel_image_create_from_file(ctx, "vox_rt.mha", &img));
  if (img) check_values(img, 7, "mha"), fcm_voxel_image_destroy(&img);
  TEST_OK(ctx, fcm_voxel_image_create_from_file(ctx, "vox_rt_ascii.nrrd", &img));
  if (img) check_values(img, 7, "nrrd ascii"), fcm_voxel_image_destroy(&img);
  remove("vox_rt.mha");
  remove("vox_rt_ascii.nrrd");
}

/* The volume a closed, outward oriented boundary encloses (divergence theorem: the sum of
 * det(a, b, c) / 6 over its triangles) and its area. */
static void enclosed(const fcm_geometry *g, double *volume, double *area)
{
  const double *X = fcm_geometry_coords(g);
  const fcm_index *t = fcm_geometry_boundary_triangles(g);
  *volume = *area = 0;
  for (fcm_index k = 0; k < fcm_geometry_num_boundary_triangles(g); k++) {
    const double *a = X + 3 * t[3 * k], *b = X + 3 * t[3 * k + 1], *c = X + 3 * t[3 * k + 2];
    *volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                a[2] * (b[0] * c[1] - b[1] * c[0])) /
               6.0;
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                         u[0] * w[1] - u[1] * w[0]};
    *area += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
}

/* Area of the exposed voxel faces of the porous block with value >= 0.5 (the exact
 * boundary) for voxels of size s[0] x s[1] x s[2]. */
static double exposed_area(const double s[3])
{
  const double fa[3] = {s[1] * s[2], s[0] * s[2], s[0] * s[1]};
  double n = 0;
  for (int k = 0; k < NZ; k++)
    for (int j = 0; j < NY; j++)
      for (int i = 0; i < NX; i++) {
        if (porous(i, j, k) < 0.5) continue;
        const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                              {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        for (int f = 0; f < 6; f++) {
          const int *q = nb[f];
          if (q[0] < 0 || q[0] >= NX || q[1] < 0 || q[1] >= NY || q[2] < 0 || q[2] >= NZ ||
              porous(q[0], q[1], q[2]) < 0.5)
            n += fa[f / 2];
        }
      }
  return n;
}

/* The boundary is the exact voxel surface, closed and outward, merged or not, on a sheared
 * left-handed lattice and after a mirroring transform; its area on a box lattice. */
static void boundaries(fcm_ctx *ctx)
{
  double v[NX * NY * NZ];
  for (int k = 0; k < NZ; k++)
    for (int j = 0; j < NY; j++)
      for (int i = 0; i < NX; i++)
        v[i + NX * (j + NY * k)] = porous(i, j, k);
  const fcm_index dims[3] = {NX, NY, NZ};
  const double sheared[9] = {0.5, 0, 0, 0.1, 0.25, 0, 0, 0, -2};
  const double boxed[9] = {0.5, 0, 0, 0, 0.25, 0, 0, 0, 2}, o[3] = {1, 2, 3};
  for (int lattice = 0; lattice < 2; lattice++)
    for (int merge = 0; merge < 2; merge++) {
      fcm_voxel_image *img = NULL;
      fcm_geometry *g = NULL, *m = NULL;
      TEST_OK(ctx, fcm_voxel_image_create(ctx, dims, lattice ? boxed : sheared, o, v, &img));
      fcm_voxel_options vo = fcm_voxel_options_default();
      vo.merge = merge;
      if (img) TEST_OK(ctx, fcm_geometry_create_from_voxels(ctx, img, &vo, &g, NULL));
      if (g) {
        double vol, area;
        enclosed(g, &vol, &area);
        TEST_NEAR(vol, fcm_geometry_volume(g), 1e-12, 0);
        const double spacing[3] = {0.5, 0.25, 2};
        if (lattice == 1) TEST_NEAR(area, exposed_area(spacing), 1e-12, 0);
        const double A[9] = {-1, 0, 0, 0, 1, 0, 0, 0, 1}, b[3] = {0, 0, 0};
        TEST_OK(ctx, fcm_geometry_create_transformed(ctx, g, A, b, &m));
        if (m) {
          double vm, am;
          enclosed(m, &vm, &am);
          TEST_NEAR(vm, fcm_geometry_volume(g), 1e-12, 0);
          TEST_NEAR(am, area, 1e-12, 0);
          TEST_TRUE(fcm_geometry_num_boundary_triangles(m) ==
                    fcm_geometry_num_boundary_triangles(g));
        }
      }
      fcm_geometry_destroy(&m);
      fcm_geometry_destroy(&g);
      fcm_voxel_image_destroy(&img);
    }
}

static void volumes(fcm_ctx *ctx)
{
  double v[NX * NY * NZ];
  fcm_index selected = 0, label2 = 0;
  for (int k = 0; k < NZ; k++)
    for (int j = 0; j < NY; j++)
      for (int i = 0; i < NX; i++) {
        v[i + NX * (j + NY * k)] = porous(i, j, k);
        selected += porous(i, j, k) >= 0.5;
        label2 += porous(i, j, k) == 2 || porous(i, j, k) == 3;
      }
  const fcm_index dims[3] = {NX, NY, NZ};
  /* a sheared, left-handed lattice: parallelepiped cells, volume |det| = 0.5 * 0.25 * 2 */
  const double A[9] = {0.5, 0, 0, 0.1, 0.25, 0, 0, 0, -2}, o[3] = {1, 2, 3};
  fcm_voxel_image *img = NULL;
  fcm_geometry *g = NULL;
  fcm_voxel_info info;
  TEST_OK(ctx, fcm_voxel_image_create(ctx, dims, A, o, v, &img));
  if (!img) return;
  TEST_OK(ctx, fcm_geometry_create_from_voxels(ctx, img, NULL, &g, &info));
  if (g) {
    TEST_TRUE(info.num_voxels == NX * NY * NZ && info.num_selected == selected);
    TEST_NEAR(info.voxel_volume, 0.25, 1e-15, 0);
    TEST_NEAR(fcm_geometry_volume(g), (double)selected * 0.25, 1e-13, 0);
    TEST_TRUE(info.num_boxes == fcm_geometry_num_cells(g));
    TEST_TRUE(info.num_boxes * 4 < selected); /* merging pays on this block */
    fcm_geometry_destroy(&g);
  }
  /* labels 2 and 3, no merging: one cell per voxel */
  const double labels[2] = {3, 2};
  fcm_voxel_options vo = fcm_voxel_options_default();
  vo.labels = labels, vo.num_labels = 2, vo.merge = 0;
  TEST_OK(ctx, fcm_geometry_create_from_voxels(ctx, img, &vo, &g, &info));
  if (g) {
    TEST_TRUE(info.num_selected == label2 && info.num_boxes == label2);
    TEST_NEAR(fcm_geometry_volume(g), (double)label2 * 0.25, 1e-13, 0);
    fcm_geometry_destroy(&g);
  }
  vo.labels = NULL, vo.num_labels = 0, vo.threshold = 10;
  TEST_ERR(ctx, fcm_geometry_create_from_voxels(ctx, img, &vo, &g, NULL), FCM_ERR_GEOMETRY,
           "the image values lie in [0, 3]");
  TEST_TRUE(g == NULL);
  fcm_voxel_image_destroy(&img);

  /* A full 6 x 4 x 3 block of unit voxels at origin 0: one box [-0.5, 5.5] x ...; without
   * merging, the shared lattice nodes leave exactly the outer faces as boundary. */
  double full[72];
  for (int i = 0; i < 72; i++)
    full[i] = 1;
  const fcm_index d2[3] = {6, 4, 3};
  TEST_OK(ctx, fcm_voxel_image_create(ctx, d2, NULL, NULL, full, &img));
  if (!img) return;
  TEST_OK(ctx, fcm_geometry_create_from_voxels(ctx, img, NULL, &g, &info));
  if (g) {
    double lo[3], hi[3];
    fcm_geometry_bounding_box(g, lo, hi);
    TEST_TRUE(info.num_boxes == 1 && info.num_selected == 72);
    TEST_TRUE(fcm_geometry_num_boundary_triangles(g) == 12); /* one rectangle per face */
    TEST_TRUE(lo[0] == -0.5 && hi[0] == 5.5 && lo[2] == -0.5 && hi[2] == 2.5);
    TEST_NEAR(fcm_geometry_volume(g), 72.0, 1e-14, 0);
    fcm_geometry_destroy(&g);
  }
  vo = fcm_voxel_options_default();
  vo.merge = 0;
  TEST_OK(ctx, fcm_geometry_create_from_voxels(ctx, img, &vo, &g, &info));
  if (g) {
    TEST_TRUE(info.num_boxes == 72 && fcm_geometry_num_nodes(g) == 7 * 5 * 4);
    TEST_TRUE(fcm_geometry_num_boundary_triangles(g) == 2 * 2 * (6 * 4 + 4 * 3 + 6 * 3));
    fcm_geometry_destroy(&g);
  }
  fcm_voxel_image_destroy(&img);
}

static void errors(fcm_ctx *ctx)
{
  fcm_voxel_image *img = NULL;
  static const struct {
    const char *text, *msg;
    fcm_status code;
  } cases[] = {
      {"NRRD0009\n", "vox_err.nrrd:1: not a NRRD file", FCM_ERR_FORMAT},
      {"NRRD0004\ntype: complex\n", "vox_err.nrrd:2: type: 'complex'", FCM_ERR_FORMAT},
      {"NRRD0004\ndimension: 2\n", "vox_err.nrrd:2: dimension: 2; only 3D", FCM_ERR_UNSUPPORTED},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2\n", "vox_err.nrrd:4: sizes: '2 2'",
       FCM_ERR_FORMAT},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n",
       "vox_err.nrrd:5: encoding: 'gzip' is not supported", FCM_ERR_UNSUPPORTED},
      {"NRRD0004\ntype: uint16\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n0123",
       "need an 'endian' field", FCM_ERR_FORMAT},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n0123",
       "vox_err.nrrd: 2 x 2 x 2 raw values need at least 8 bytes of data, the file has 4",
       FCM_ERR_FORMAT},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nbyte skip: 2\n\n"
       "01234567",
       "raw data: 6 bytes after the 2 skipped, expected 8", FCM_ERR_FORMAT},
      /* an announced size far beyond the data fails before anything that large is allocated */
      {"NRRD0004\ntype: double\ndimension: 3\nsizes: 100000 100000 100\nendian: little\n"
       "encoding: raw\n\n01234567",
       "values need at least 8000000000000 bytes", FCM_ERR_FORMAT},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nfoo: bar\n\n",
       "vox_err.nrrd:6: 'foo' is not a NRRD field", FCM_ERR_FORMAT},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspace directions: (1,0,0) (2,0,0) "
       "(0,0,1)\nencoding: raw\n\n01234567",
       "linearly dependent", FCM_ERR_ARG},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n\n1 2 3 x 5 6 7 8",
       "value 3 'x' is not a number", FCM_ERR_FORMAT},
      /* a detached data file: missing or short, named with the header that refers to it */
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: "
       "vox_missing.raw\n",
       "voxel image: vox_err.nrrd:6: data file: cannot open 'vox_missing.raw': No such file",
       FCM_ERR_IO},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: "
       "vox_short.raw\n",
       "vox_short.raw (the data file of vox_err.nrrd): 2 x 2 x 2 raw values need at least 8 "
       "bytes of data, the file has 3",
       FCM_ERR_FORMAT},
      /* voxels reaching beyond 1e50: out of range, whatever the computations would make */
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspacings: 1e50 1 1\nencoding: "
       "raw\n\n01234567",
       "vox_err.nrrd: the image reaches |x| = 2.5e+50 (origin, axis vectors and sizes), "
       "outside the supported range [-1e50, 1e50]",
       FCM_ERR_ARG},
  };
  write_text("vox_short.raw", "abc");
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    write_text("vox_err.nrrd", cases[c].text);
    TEST_ERR(ctx, fcm_voxel_image_create_from_file(ctx, "vox_err.nrrd", &img), cases[c].code,
             cases[c].msg);
    TEST_TRUE(img == NULL);
  }
  remove("vox_err.nrrd");
  remove("vox_short.raw");
  write_text("vox_err.mhd", "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
                            "ElementDataFile = vox_missing.raw\n");
  TEST_ERR(ctx, fcm_voxel_image_create_from_file(ctx, "vox_err.mhd", &img), FCM_ERR_IO,
           "voxel image: vox_err.mhd:4: data file: cannot open 'vox_missing.raw'");
  write_text("vox_err.mhd", "NDims = 3\nDimSize = 2 2 -1\n");
  TEST_ERR(ctx, fcm_voxel_image_create_from_file(ctx, "vox_err.mhd", &img), FCM_ERR_FORMAT,
           "vox_err.mhd:2: DimSize: '2 2 -1' is not 3 integers in [1, 2^40]");
  write_text("vox_err.mhd", "NDims = 3\nDimSize = 2 2 2\nElementType = MET_FLOAT\n");
  TEST_ERR(ctx, fcm_voxel_image_create_from_file(ctx, "vox_err.mhd", &img), FCM_ERR_FORMAT,
           "without 'ElementDataFile");
  write_text("vox_err.mhd", "NDims = 3\nDimSize = 2 2 2\nElementType = MET_INT8\n");
  TEST_ERR(ctx, fcm_voxel_image_create_from_file(ctx, "vox_err.mhd", &img), FCM_ERR_FORMAT,
           "vox_err.mhd:3: ElementType: 'MET_INT8' is not one of");
  write_text("vox_err.mhd", "NDims = 3\nCompressedData = True\n");
  TEST_ERR(ctx, fcm_voxel_image_create_from_file(ctx, "vox_err.mhd", &img), FCM_ERR_UNSUPPORTED,
           "vox_err.mhd:2: CompressedData");
  remove("vox_err.mhd");
  TEST_ERR(ctx, fcm_voxel_image_create_from_file(ctx, "image.tif", &img), FCM_ERR_UNSUPPORTED,
           "unknown extension");
  const fcm_index bad[3] = {2, 0, 2};
  const double one = 1;
  TEST_ERR(ctx, fcm_voxel_image_create(ctx, bad, NULL, NULL, &one, &img), FCM_ERR_ARG,
           "size 0 of axis 1 must be >= 1");
}

/* What the log callback received: warnings and the last one. */
typedef struct logbook {
  int warnings;
  char last[1024];
} logbook;

static void log_fn(void *user, fcm_log_level level, const char *msg)
{
  logbook *b = user;
  if (level != FCM_LOG_WARNING) return;
  b->warnings++;
  snprintf(b->last, sizeof b->last, "%s", msg);
}

/* NaN values are never selected; they are counted and logged as one warning naming the
 * first; an image of NaN only says so. */
static void nan_values(void)
{
  logbook book = {0, ""};
  fcm_ctx_options co = fcm_ctx_options_default();
  co.log = log_fn, co.log_user = &book;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(&co, &ctx));
  if (!ctx) return;
  double v[NX * NY * NZ];
  fcm_index selected = 0, nans = 0;
  for (int k = 0; k < NZ; k++)
    for (int j = 0; j < NY; j++)
      for (int i = 0; i < NX; i++) {
        const int hole = (i + 2 * j + 3 * k) % 5 == 1; /* the first: (1, 0, 0) */
        v[i + NX * (j + NY * k)] = hole ? NAN : porous(i, j, k);
        nans += hole;
        selected += !hole && porous(i, j, k) >= 0.5;
      }
  const fcm_index dims[3] = {NX, NY, NZ};
  fcm_voxel_image *img = NULL;
  fcm_geometry *g = NULL;
  fcm_voxel_info info;
  TEST_OK(ctx, fcm_voxel_image_create(ctx, dims, NULL, NULL, v, &img));
  if (img) TEST_OK(ctx, fcm_geometry_create_from_voxels(ctx, img, NULL, &g, &info));
  if (g) {
    TEST_TRUE(info.num_nan == nans && info.num_selected == selected);
    TEST_NEAR(fcm_geometry_volume(g), (double)selected, 1e-13, 0);
    char expect[160];
    snprintf(expect, sizeof expect, "voxels: %lld of %d voxel values are NaN", (long long)nans,
             NX * NY * NZ);
    TEST_TRUE(book.warnings == 1 && strstr(book.last, expect) &&
              strstr(book.last, "the first is voxel (1, 0, 0)"));
  }
  fcm_geometry_destroy(&g);
  fcm_voxel_image_destroy(&img);
  /* without NaN: no warning */
  for (int i = 0; i < NX * NY * NZ; i++)
    v[i] = isnan(v[i]) ? 0 : v[i];
  book.warnings = 0;
  TEST_OK(ctx, fcm_voxel_image_create(ctx, dims, NULL, NULL, v, &img));
  if (img) TEST_OK(ctx, fcm_geometry_create_from_voxels(ctx, img, NULL, &g, &info));
  TEST_TRUE(book.warnings == 0 && (!g || info.num_nan == 0));
  fcm_geometry_destroy(&g);
  fcm_voxel_image_destroy(&img);
  for (int i = 0; i < NX * NY * NZ; i++)
    v[i] = NAN;
  TEST_OK(ctx, fcm_voxel_image_create(ctx, dims, NULL, NULL, v, &img));
  if (img)
    TEST_ERR(ctx, fcm_geometry_create_from_voxels(ctx, img, NULL, &g, NULL), FCM_ERR_GEOMETRY,
             "(every value is NaN)");
  fcm_voxel_image_destroy(&img);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  round_trips(ctx);
  volumes(ctx);
  boundaries(ctx);
  errors(ctx);
  nan_values();
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
