/* Triangle surface readers: the unit cube written by this test as OBJ (quads, mixed index
 * forms, relative indices), OFF, STL ASCII, STL binary (with a header starting "solid"),
 * PLY ascii and PLY binary_little_endian (extra properties and elements of every kind)
 * reads back as 8 vertices and 12 triangles whose enclosed volume (divergence theorem) is
 * 1 to 1e-14 and whose normals all point outwards; a table of malformed files fails with
 * the status and a message naming the file and the line or byte offset; no request
 * above 1 MiB reaches the allocator. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/surface.h"
#include "test.h"

#include <stdint.h>
#include <sys/stat.h>

static size_t largest;

static void *track_alloc(void *user, size_t size)
{
  (void)user;
  if (size > largest) largest = size;
  return malloc(size);
}

static void track_release(void *user, void *p)
{
  (void)user;
  free(p);
}

/* corner i = (bit0, bit1, bit2); quads counter-clockwise seen from outside */
static const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

static double corner(int i, int k)
{
  return (double)((i >> k) & 1);
}

static void write_bytes(const char *path, const void *data, size_t n)
{
  FILE *f = fopen(path, "wb");
  TEST_TRUE(f != NULL);
  if (!f) return;
  TEST_TRUE(fwrite(data, 1, n, f) == n);
  fclose(f);
}

static void write_text(const char *path, const char *text)
{
  write_bytes(path, text, strlen(text));
}

static void cube_obj(const char *path)
{
  char s[2048];
  int n = snprintf(s, sizeof s, "# unit cube\nmtllib cube.mtl\no cube\n");
  for (int i = 0; i < 8; i++)
    n += snprintf(s + n, sizeof s - (size_t)n, "v %g %g %g\nvt 0 0\nvn 0 0 1\n", corner(i, 0),
                  corner(i, 1), corner(i, 2));
  n += snprintf(s + n, sizeof s - (size_t)n, "g side\nusemtl steel\ns off\n");
  for (int f = 0; f < 6; f++) {
    const int *q = quads[f];
    if (f == 1) /* relative indices: -8 is vertex 1 */
      n += snprintf(s + n, sizeof s - (size_t)n, "f %d %d %d %d\n", q[0] - 8, q[1] - 8, q[2] - 8,
                    q[3] - 8);
    else
      n += snprintf(s + n, sizeof s - (size_t)n, "f %d/1/1 %d//1 %d/1 %d # quad\n", q[0] + 1,
                    q[1] + 1, q[2] + 1, q[3] + 1);
  }
  write_text(path, s);
}

static void cube_off(const char *path)
{
  char s[1024];
  int n = snprintf(s, sizeof s, "COFF\n# counts\n8 6 12\n");
  for (int i = 0; i < 8; i++) /* with a colour per vertex and per face */
    n += snprintf(s + n, sizeof s - (size_t)n, "%g %g %g 0.5 0.5 0.5 1\n", corner(i, 0),
                  corner(i, 1), corner(i, 2));
  for (int f = 0; f < 6; f++)
    n += snprintf(s + n, sizeof s - (size_t)n, "4 %d %d %d %d 255 0 0\n", quads[f][0], quads[f][1],
                  quads[f][2], quads[f][3]);
  write_text(path, s);
}

static void tri_of(int t, int v[3])
{
  const int *q = quads[t / 2];
  v[0] = q[0], v[1] = q[1 + t % 2], v[2] = q[2 + t % 2];
}

static void cube_stl_ascii(const char *path)
{
  char s[8192];
  int n = snprintf(s, sizeof s, "solid cube\n");
  for (int t = 0; t < 12; t++) {
    int v[3];
    tri_of(t, v);
    n += snprintf(s + n, sizeof s - (size_t)n, "  facet normal 0 0 0\n    outer loop\n");
    for (int j = 0; j < 3; j++)
      n += snprintf(s + n, sizeof s - (size_t)n, "      vertex %g %g %g\n", corner(v[j], 0),
                    corner(v[j], 1), corner(v[j], 2));
    n += snprintf(s + n, sizeof s - (size_t)n, "    endloop\n  endfacet\n");
    if (t == 5) /* the second half in a second solid */
      n += snprintf(s + n, sizeof s - (size_t)n, "endsolid cube\n\nsolid second half\n");
  }
  snprintf(s + n, sizeof s - (size_t)n, "endsolid cube\n");
  write_text(path, s);
}

static void put32(unsigned char *b, uint32_t u)
{
  for (int k = 0; k < 4; k++)
    b[k] = (unsigned char)(u >> (8 * k));
}

static void putf(unsigned char *b, float f)
{
  uint32_t u;
  memcpy(&u, &f, 4);
  put32(b, u);
}

static void putd(unsigned char *b, double d)
{
  uint64_t u;
  memcpy(&u, &d, 8);
  put32(b, (uint32_t)u);
  put32(b + 4, (uint32_t)(u >> 32));
}

/* binary STL of the cube, cut to `size` bytes; the header starts with "solid" */
static void cube_stl_binary(const char *path, size_t size, float nan_at_first)
{
  unsigned char b[84 + 50 * 12] = {0};
  memcpy(b, "solid binary header", 19);
  put32(b + 80, 12);
  for (int t = 0; t < 12; t++) {
    int v[3];
    tri_of(t, v);
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 3; k++)
        putf(b + 84 + 50 * t + 12 + 12 * j + 4 * k, (float)corner(v[j], k));
  }
  if (nan_at_first != 0) putf(b + 84 + 12, nan_at_first);
  write_bytes(path, b, size);
}

static void cube_ply_ascii(const char *path)
{
  char s[2048];
  int n = snprintf(s, sizeof s,
                   "ply\nformat ascii 1.0\ncomment unit cube\nelement vertex 8\n"
                   "property float x\nproperty uchar red\nproperty float y\nproperty double z\n"
                   "property float quality\n"
                   "element face 6\nproperty list uchar int vertex_indices\nproperty int flags\n"
                   "element edge 1\nproperty list int int ids\nproperty float w\nend_header\n");
  for (int i = 0; i < 8; i++)
    n += snprintf(s + n, sizeof s - (size_t)n, "%g 255 %g %g nan\n", corner(i, 0), corner(i, 1),
                  corner(i, 2));
  for (int f = 0; f < 6; f++)
    n += snprintf(s + n, sizeof s - (size_t)n, "4 %d %d %d %d 7\n", quads[f][0], quads[f][1],
                  quads[f][2], quads[f][3]);
  snprintf(s + n, sizeof s - (size_t)n, "3 0 1 2 0.5\n");
  write_text(path, s);
}

static void cube_ply_binary(const char *path)
{
  unsigned char b[2048];
  const char *h = "ply\nformat binary_little_endian 1.0\nobj_info test\nelement edge 2\n"
                  "property uchar a\nproperty list uchar short b\n"
                  "element vertex 8\nproperty double x\nproperty double y\nproperty double z\n"
                  "property float nx\nelement face 6\nproperty uchar flags\n"
                  "property list int int vertex_indices\nend_header\n";
  size_t n = strlen(h);
  memcpy(b, h, n);
  for (int e = 0; e < 2; e++) { /* edge: a, then a list of 2 shorts */
    b[n++] = 1, b[n++] = 2;
    b[n++] = 3, b[n++] = 0, b[n++] = 4, b[n++] = 0;
  }
  for (int i = 0; i < 8; i++) {
    for (int k = 0; k < 3; k++, n += 8)
      putd(b + n, corner(i, k));
    putf(b + n, 1.0f), n += 4;
  }
  for (int f = 0; f < 6; f++) {
    b[n++] = 9;
    put32(b + n, 4), n += 4;
    for (int j = 0; j < 4; j++, n += 4)
      put32(b + n, (uint32_t)quads[f][j]);
  }
  write_bytes(path, b, n);
}

static void check_cube(fcm_ctx *ctx, const char *path)
{
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_surface_create_from_file(ctx, path, &s));
  if (!s) {
    fprintf(stderr, "  (file %s)\n", path);
    return;
  }
  TEST_TRUE(fcm_surface_num_vertices(s) == 8);
  TEST_TRUE(fcm_surface_num_triangles(s) == 12);
  const double *x = fcm_surface_coords(s);
  const fcm_index *t = fcm_surface_triangles(s);
  int seen = 0;
  for (fcm_index i = 0; i < fcm_surface_num_vertices(s); i++) {
    int id = 0;
    for (int k = 0; k < 3; k++) {
      TEST_TRUE(x[3 * i + k] == 0 || x[3 * i + k] == 1);
      id |= (x[3 * i + k] == 1) << k;
    }
    seen |= 1 << id;
  }
  TEST_TRUE(seen == 255); /* the 8 corners, each once */
  double vol = 0;
  for (fcm_index f = 0; f < fcm_surface_num_triangles(s); f++) {
    const double *a = x + 3 * t[3 * f], *b = x + 3 * t[3 * f + 1], *c = x + 3 * t[3 * f + 2];
    double u[3], v[3], nrm[3], out = 0;
    for (int k = 0; k < 3; k++)
      u[k] = b[k] - a[k], v[k] = c[k] - a[k];
    nrm[0] = u[1] * v[2] - u[2] * v[1];
    nrm[1] = u[2] * v[0] - u[0] * v[2];
    nrm[2] = u[0] * v[1] - u[1] * v[0];
    for (int k = 0; k < 3; k++)
      out += nrm[k] * ((a[k] + b[k] + c[k]) / 3 - 0.5);
    TEST_TRUE(out > 0);                                         /* outward */
    vol += (a[0] * nrm[0] + a[1] * nrm[1] + a[2] * nrm[2]) / 6; /* divergence theorem */
  }
  TEST_NEAR(vol, 1.0, 0, 1e-14);
  double lo[3], hi[3];
  fcm_surface_bounding_box(s, lo, hi);
  for (int k = 0; k < 3; k++)
    TEST_TRUE(lo[k] == 0 && hi[k] == 1);
  fcm_surface_destroy(&s);
  TEST_TRUE(s == NULL);
}

int main(void)
{
  fcm_ctx_options o = fcm_ctx_options_default();
  o.allocator.alloc = track_alloc;
  o.allocator.release = track_release;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(&o, &ctx) != FCM_OK) return 1;
  fcm_surface *s = NULL;
  char bin_index_msg[128];

  cube_obj("sf_cube.obj");
  cube_off("sf_cube.OFF"); /* the extension is case-insensitive */
  cube_stl_ascii("sf_cube_a.stl");
  cube_stl_binary("sf_cube_b.stl", 84 + 50 * 12, 0);
  cube_ply_ascii("sf_cube_a.ply");
  cube_ply_binary("sf_cube_b.ply");
  const char *good[] = {"sf_cube.obj",   "sf_cube.OFF",   "sf_cube_a.stl",
                        "sf_cube_b.stl", "sf_cube_a.ply", "sf_cube_b.ply"};
  for (int i = 0; i < 6; i++)
    check_cube(ctx, good[i]);

  /* from arrays */
  const double tx[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const fcm_index tt[3] = {0, 1, 2}, tbad[3] = {0, 1, 3};
  TEST_OK(ctx, fcm_surface_create(ctx, 3, tx, 1, tt, &s));
  TEST_TRUE(fcm_surface_num_triangles(s) == 1);
  fcm_surface_destroy(&s);
  TEST_ERR(ctx, fcm_surface_create(ctx, 3, tx, 1, tbad, &s), FCM_ERR_ARG, "vertex id 3");
  TEST_ERR(ctx, fcm_surface_create(ctx, 0, tx, 1, tt, &s), FCM_ERR_ARG, "0 vertices");

  /* malformed inputs */
  largest = 0;
  cube_stl_binary("sf_trunc.stl", 84 + 50 * 12 - 10, 0);
  { /* not "solid": the size rule decides, and fails */
    FILE *f = fopen("sf_trunc.stl", "r+b");
    TEST_TRUE(f && fwrite("xxxxx", 1, 5, f) == 5);
    if (f) fclose(f);
  }
  cube_stl_binary("sf_trunc_solid.stl", 84 + 50 * 12 - 1, 0); /* header "solid ..." */
  cube_stl_binary("sf_nan.stl", 84 + 50 * 12, NAN);
  write_text("sf_nan.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                           "property float y\nproperty float z\nend_header\n0 inf 0\n");
  write_text("sf_two.stl", "solid a\nendsolid a\nfacet normal 0 0 1\n");
  write_text("sf_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  write_text("sf_rel.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
  write_text("sf_nan.obj", "v 0 0 0\nv nan 0 0\n");
  write_text("sf_empty.obj", "# nothing\nv 0 0 0\n");
  write_text("sf_face2.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
  write_text("sf_neg.off", "OFF\n-3 1 0\n");
  write_text("sf_4d.off", "4OFF\n1 1 0\n");
  write_text("sf_huge.off", "OFF\n1000000000000 1 0\n0 0 0\n");
  write_text("sf_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  write_text("sf_huge.ply", "ply\nformat ascii 1.0\nelement vertex 1000000000000\n"
                            "property float x\nproperty float y\nproperty float z\nend_header\n");
  write_text("sf_index.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                             "property float y\nproperty float z\nelement face 1\n"
                             "property list uchar int vertex_indices\nend_header\n"
                             "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n");
  { /* binary: the third index (7) at byte strlen(header) + 36 + 1 + 8 */
    const char *h = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                    "property float y\nproperty float z\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n";
    unsigned char b[512] = {0};
    size_t n = strlen(h);
    memcpy(b, h, n);
    b[n + 36] = 3;
    put32(b + n + 37, 0), put32(b + n + 41, 1), put32(b + n + 45, 7);
    write_bytes("sf_index_b.ply", b, n + 49);
    snprintf(bin_index_msg, sizeof bin_index_msg,
             "sf_index_b.ply: byte %zu: vertex index 7 outside [0, 3)", n + 45);
  }
  write_text("sf_face2.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                             "property float y\nproperty float z\nelement face 1\n"
                             "property list uchar int vertex_indices\nend_header\n"
                             "0 0 0\n1 0 0\n0 1 0\n2 0 1\n");
  write_text("sf_big.ply", "ply\nformat binary_big_endian 1.0\nend_header\n");
  write_text("sf_noface.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                              "property float y\nend_header\n0 0\n");
  write_text("sf_short.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1\n"
                             "property float x\nproperty float y\nproperty float z\n"
                             "end_header\n0123456789ab");
  write_text("sf_open.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                            "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n");
  write_text("sf_bad.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                           "vertex 1 0 zero\n");
  write_text("sf_cube.step", "ISO-10303-21;\n");
  mkdir("sf_dir.obj", 0700);
  const struct {
    const char *path;
    fcm_status code;
    const char *msg;
  } bad[] = {
      {"sf_trunc.stl", FCM_ERR_FORMAT, "sf_trunc.stl: byte 80: binary STL declares 12 triangles"},
      {"sf_trunc_solid.stl", FCM_ERR_FORMAT, "sf_trunc_solid.stl: byte 80: binary STL declares 12"},
      {"sf_nan.ply", FCM_ERR_FORMAT,
       "sf_nan.ply:8: expected a vertex coordinate (a finite number), got \"inf\""},
      {"sf_two.stl", FCM_ERR_FORMAT, "sf_two.stl:3: expected \"solid\" or the end of the file"},
      {"sf_nan.stl", FCM_ERR_FORMAT, "sf_nan.stl: byte 96: expected a finite vertex coordinate"},
      {"sf_index.obj", FCM_ERR_FORMAT, "sf_index.obj:4: vertex index 9 outside [1, 3]"},
      {"sf_rel.obj", FCM_ERR_FORMAT, "sf_rel.obj:4: vertex index -4 outside"},
      {"sf_nan.obj", FCM_ERR_FORMAT, "sf_nan.obj:2: expected a vertex coordinate after \"v\""},
      {"sf_empty.obj", FCM_ERR_FORMAT, "sf_empty.obj: empty mesh (1 vertices, 0 triangles)"},
      {"sf_face2.obj", FCM_ERR_FORMAT, "sf_face2.obj:3: face with 2 vertices"},
      {"sf_4d.off", FCM_ERR_FORMAT, "sf_4d.off:1: expected the header \"OFF\""},
      {"sf_neg.off", FCM_ERR_FORMAT, "sf_neg.off:2: the vertex count"},
      {"sf_huge.off", FCM_ERR_FORMAT, "sf_huge.off:2: the vertex count (bounded by the file size)"},
      {"sf_index.off", FCM_ERR_FORMAT,
       "sf_index.off:6: a vertex index of a face = 3 outside [0, 2]"},
      {"sf_huge.ply", FCM_ERR_FORMAT, "sf_huge.ply:8: element vertex declares 1000000000000"},
      {"sf_index.ply", FCM_ERR_FORMAT, "sf_index.ply:13: vertex index 5 outside [0, 3)"},
      {"sf_index_b.ply", FCM_ERR_FORMAT, bin_index_msg},
      {"sf_face2.ply", FCM_ERR_FORMAT,
       "sf_face2.ply:13: record 0 of element face has a list of 2 items (expected at least 3"},
      {"sf_big.ply", FCM_ERR_UNSUPPORTED, "sf_big.ply:2: binary_big_endian"},
      {"sf_noface.ply", FCM_ERR_FORMAT, "sf_noface.ply: the vertex element lacks"},
      {"sf_short.ply", FCM_ERR_FORMAT, "sf_short.ply: empty mesh"},
      {"sf_open.stl", FCM_ERR_FORMAT,
       "sf_open.stl:9: expected \"facet\" or \"endsolid\", got the end"},
      {"sf_bad.stl", FCM_ERR_FORMAT,
       "sf_bad.stl:5: expected a vertex coordinate (a finite number), got \"zero\""},
      {"sf_cube.step", FCM_ERR_UNSUPPORTED, "sf_cube.step: unknown file extension"},
      {"sf_dir.obj", FCM_ERR_IO, "sf_dir.obj"},
      {"sf_missing.obj", FCM_ERR_IO, "sf_missing.obj"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    s = (fcm_surface *)1;
    TEST_ERR(ctx, fcm_surface_create_from_file(ctx, bad[i].path, &s), bad[i].code, bad[i].msg);
    TEST_TRUE(s == NULL);
  }
  TEST_TRUE(largest < ((size_t)1 << 20)); /* huge counts were refused, not allocated */
  TEST_ERR(ctx, fcm_surface_create_from_file(ctx, NULL, &s), FCM_ERR_ARG, "NULL");
  TEST_TRUE(fcm_surface_num_vertices(NULL) == 0 && fcm_surface_coords(NULL) == NULL);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
