/* VTU round trip: two-cell Tet10 and Hex20 meshes, a point cloud and a mixed mesh are
 * written, then parsed back by an independent reader: balanced tags, counts, appended
 * arrays tiling the block with UInt64 sizes, values equal to the inputs bit for bit. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/io.h"
#include "test.h"
#include "vtk_reader.h"

#include <math.h>

#define DIR  "io_vtu_roundtrip.d"
#define MAXP 64

typedef struct mesh {
  int np, nc, nn, vtk_type;
  double x[3 * MAXP];
  int64_t conn[2 * 20];
  int64_t edge[MAXP][3]; /* (a, b, mid-edge point) for a < b */
  int ne;
} mesh;

static const int tet10_edges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
static const int hex20_edges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                       {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

static int64_t mid_point(mesh *m, int64_t a, int64_t b)
{
  int64_t lo = a < b ? a : b, hi = a < b ? b : a;
  for (int e = 0; e < m->ne; e++)
    if (m->edge[e][0] == lo && m->edge[e][1] == hi) return m->edge[e][2];
  int64_t p = m->np++;
  for (int d = 0; d < 3; d++)
    m->x[3 * p + d] = 0.5 * (m->x[3 * a + d] + m->x[3 * b + d]);
  m->edge[m->ne][0] = lo;
  m->edge[m->ne][1] = hi;
  m->edge[m->ne++][2] = p;
  return p;
}

/* Corners given; mid-edge nodes shared between the two cells; coordinates then
 * scaled and perturbed so that every double has a full mantissa. */
static void build(mesh *m, int vtk_type, int ncorner, const double *corners, const int *cells,
                  int nn, int ncells_corner, const int (*edges)[2], int nedges)
{
  memset(m, 0, sizeof *m);
  m->vtk_type = vtk_type;
  m->nn = nn;
  m->nc = 2;
  m->np = ncorner;
  memcpy(m->x, corners, sizeof(double) * 3 * (size_t)ncorner);
  for (int c = 0; c < 2; c++) {
    for (int k = 0; k < ncells_corner; k++)
      m->conn[c * nn + k] = cells[c * ncells_corner + k];
    for (int e = 0; e < nedges; e++)
      m->conn[c * nn + ncells_corner + e] =
          mid_point(m, m->conn[c * nn + edges[e][0]], m->conn[c * nn + edges[e][1]]);
  }
  for (int i = 0; i < 3 * m->np; i++)
    m->x[i] = 0.37 * m->x[i] + 0.011 * sin(1.0 + i);
}

static void check_array(const vr_doc *d, const char *parent, const char *name, const char *type,
                        int ncomp, const void *want, size_t want_bytes)
{
  char buf[64];
  uint64_t bytes = 0;
  const vr_tag *t = vr_data_array(d, parent, name);
  if (!t) {
    TEST_FAIL_("no DataArray '%s' in <%s>", name ? name : "(points)", parent);
    return;
  }
  TEST_TRUE(vr_attr(t, "type", buf, sizeof buf) && !strcmp(buf, type));
  TEST_TRUE(vr_attr(t, "format", buf, sizeof buf) && !strcmp(buf, "appended"));
  if (ncomp) TEST_TRUE(vr_attr_ll(t, "NumberOfComponents") == ncomp);
  const unsigned char *p = vr_array(d, t, &bytes);
  if (bytes != want_bytes)
    TEST_FAIL_("array '%s': UInt64 size %llu, expected %zu", name ? name : "(points)",
               (unsigned long long)bytes, want_bytes);
  else if (memcmp(p, want, want_bytes))
    TEST_FAIL_("array '%s': decoded values differ from the input", name ? name : "(points)");
}

static const char *host_order(void)
{
  union {
    uint32_t u;
    unsigned char c[4];
  } probe = {0x01020304u};
  return probe.c[0] == 4 ? "LittleEndian" : "BigEndian";
}

/* Parse `path`, check the header and the mesh arrays; leaves the doc loaded. */
static int parse_vtu(vr_doc *d, const char *path, long long np, long long nc)
{
  char buf[64];
  if (!vr_load(d, path) || !vr_parse_vtu(d)) {
    TEST_FAIL_("%s: %s", path, d->error);
    return 0;
  }
  const vr_tag *f = vr_find(d, "VTKFile", "", 0), *piece = vr_find(d, "Piece", NULL, 0);
  TEST_TRUE(f && piece);
  if (!f || !piece) return 0;
  TEST_TRUE(vr_attr(f, "type", buf, sizeof buf) && !strcmp(buf, "UnstructuredGrid"));
  TEST_TRUE(vr_attr(f, "header_type", buf, sizeof buf) && !strcmp(buf, "UInt64"));
  TEST_TRUE(vr_attr(f, "byte_order", buf, sizeof buf) && !strcmp(buf, host_order()));
  TEST_TRUE(vr_find(d, "AppendedData", "VTKFile", 0) != NULL);
  TEST_TRUE(vr_attr(vr_find(d, "AppendedData", "VTKFile", 0), "encoding", buf, sizeof buf) &&
            !strcmp(buf, "raw"));
  TEST_TRUE(vr_attr_ll(piece, "NumberOfPoints") == np);
  TEST_TRUE(vr_attr_ll(piece, "NumberOfCells") == nc);
  return 1;
}

static void check_cells(const vr_doc *d, long long nc, const int64_t *conn, const int *nodes,
                        const int *types)
{
  int64_t offsets[64];
  uint8_t t8[64];
  long long len = 0;
  for (long long c = 0; c < nc; c++) {
    len += nodes[c];
    offsets[c] = len;
    t8[c] = (uint8_t)types[c];
  }
  check_array(d, "Cells", "connectivity", "Int64", 0, conn, (size_t)len * 8);
  check_array(d, "Cells", "offsets", "Int64", 0, offsets, (size_t)nc * 8);
  check_array(d, "Cells", "types", "UInt8", 0, t8, (size_t)nc);
}

static long file_size(const char *path)
{
  struct stat sb;
  return stat(path, &sb) ? -1 : (long)sb.st_size;
}

static void roundtrip(fcm_ctx *ctx, const mesh *m, const char *path, int nonfinite)
{
  fcm_vtu *vtu = NULL;
  fcm_vtu_info info;
  double u[3 * MAXP], sig[9 * MAXP], phi[2] = {0.25, 1.0}, pr[MAXP];
  int32_t cls[2] = {1, -2};
  int64_t gid[2] = {(int64_t)1 << 40, -3};
  const char *odd = "p<&>\"'q";
  for (int i = 0; i < 3 * m->np; i++)
    u[i] = 1e-3 * cos(0.7 * i);
  for (int i = 0; i < 9 * m->np; i++)
    sig[i] = 1e5 * sin(0.3 * i) + 1.0 / 3.0;
  for (int i = 0; i < m->np; i++)
    pr[i] = exp(-0.1 * i);
  if (nonfinite) {
    u[5] = NAN;
    u[7] = INFINITY;
    sig[9] = -INFINITY;
  }

  TEST_OK(ctx, fcm_vtu_create(ctx, &vtu));
  TEST_OK(ctx, fcm_vtu_set_points(vtu, m->np, m->x));
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, m->vtk_type, m->nc, m->conn));
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "displacement", 3, m->np, u));
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "volume_fraction", 1, m->nc, phi));
  TEST_OK(ctx, fcm_vtu_add_field_int32(vtu, FCM_VTU_CELL_DATA, "cell_class", 1, m->nc, cls));
  TEST_OK(ctx, fcm_vtu_add_field_int64(vtu, FCM_VTU_CELL_DATA, "global_id", 1, m->nc, gid));
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "stress", 9, m->np, sig));
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, odd, 1, m->np, pr));
  /* The same name is allowed once per location. */
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "displacement", 1, m->nc, phi));
  TEST_OK(ctx, fcm_vtu_write(vtu, path, &info));

  TEST_TRUE(info.file_bytes == file_size(path));
  if (nonfinite) {
    TEST_TRUE(info.num_nonfinite == 3);
    TEST_TRUE(info.first_nonfinite && !strcmp(info.first_nonfinite, "displacement"));
    TEST_TRUE(info.first_nonfinite_index == 5);
  } else {
    TEST_TRUE(info.num_nonfinite == 0 && info.first_nonfinite == NULL);
    TEST_TRUE(info.first_nonfinite_index == -1);
  }

  vr_doc *d = malloc(sizeof *d);
  if (parse_vtu(d, path, m->np, m->nc)) {
    int nodes[2] = {m->nn, m->nn}, types[2] = {m->vtk_type, m->vtk_type};
    check_array(d, "Points", NULL, "Float64", 3, m->x, (size_t)m->np * 3 * 8);
    check_cells(d, m->nc, m->conn, nodes, types);
    check_array(d, "PointData", "displacement", "Float64", 3, u, (size_t)m->np * 3 * 8);
    check_array(d, "PointData", "stress", "Float64", 9, sig, (size_t)m->np * 9 * 8);
    check_array(d, "PointData", odd, "Float64", 1, pr, (size_t)m->np * 8);
    check_array(d, "CellData", "volume_fraction", "Float64", 1, phi, 2 * 8);
    check_array(d, "CellData", "displacement", "Float64", 1, phi, 2 * 8);
    check_array(d, "CellData", "cell_class", "Int32", 1, cls, 2 * 4);
    check_array(d, "CellData", "global_id", "Int64", 1, gid, 2 * 8);
    /* 7 fields + points + 3 cell arrays, nothing else. */
    int arrays = 0;
    while (vr_find(d, "DataArray", NULL, arrays))
      arrays++;
    TEST_TRUE(arrays == 11);
  }
  vr_free(d);

  /* Borrowed arrays are read at each write: update in place, write again. */
  for (int i = 0; i < 3 * m->np; i++)
    u[i] = -2.0 * i;
  char path2[256];
  snprintf(path2, sizeof path2, "%s.again.vtu", path);
  TEST_OK(ctx, fcm_vtu_write(vtu, path2, &info));
  TEST_TRUE(info.num_nonfinite == (nonfinite ? 1 : 0));
  if (parse_vtu(d, path2, m->np, m->nc))
    check_array(d, "PointData", "displacement", "Float64", 3, u, (size_t)m->np * 3 * 8);
  vr_free(d);
  free(d);
  fcm_vtu_destroy(&vtu);
  TEST_TRUE(vtu == NULL);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_TRUE(vr_mkdir(DIR));
  TEST_TRUE(fcm_vtk_cell_num_nodes(FCM_VTK_QUADRATIC_HEXAHEDRON) == 20);
  TEST_TRUE(fcm_vtk_cell_num_nodes(FCM_VTK_QUADRATIC_TETRA) == 10);
  TEST_TRUE(fcm_vtk_cell_num_nodes(7) == 0);

  /* Tet10: two positively oriented tets sharing face (1,2,3); 5 corners + 9 edges. */
  static const double tet_corners[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  static const int tet_cells[] = {0, 1, 2, 3, 1, 2, 3, 4};
  mesh *m = malloc(sizeof *m);
  build(m, FCM_VTK_QUADRATIC_TETRA, 5, tet_corners, tet_cells, 10, 4, tet10_edges, 6);
  TEST_TRUE(m->np == 14);
  roundtrip(ctx, m, DIR "/tet10.vtu", 1);

  /* Hex20: two unit cubes sharing the face x = 1; 12 corners + 20 edges. */
  static const double hex_corners[] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0,
                                       0, 0, 1, 1, 0, 1, 2, 0, 1, 0, 1, 1, 1, 1, 1, 2, 1, 1};
  static const int hex_cells[] = {0, 1, 4, 3, 6, 7, 10, 9, 1, 2, 5, 4, 7, 8, 11, 10};
  build(m, FCM_VTK_QUADRATIC_HEXAHEDRON, 12, hex_corners, hex_cells, 20, 8, hex20_edges, 12);
  TEST_TRUE(m->np == 32);
  roundtrip(ctx, m, DIR "/hex20.vtu", 0);

  /* Point cloud: vertex cells, identity connectivity generated by the writer. */
  fcm_vtu *vtu = NULL;
  vr_doc *d = malloc(sizeof *d);
  double w[14];
  int64_t ident[14];
  int ones[14], vt[14];
  for (int i = 0; i < 14; i++) {
    w[i] = 1.0 / (i + 3);
    ident[i] = i;
    ones[i] = 1;
    vt[i] = FCM_VTK_VERTEX;
  }
  TEST_OK(ctx, fcm_vtu_create(ctx, &vtu));
  TEST_OK(ctx, fcm_vtu_set_points(vtu, 14, m->x));
  TEST_OK(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_VERTEX, 14, NULL));
  TEST_OK(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "weight", 1, 14, w));
  TEST_OK(ctx, fcm_vtu_write(vtu, DIR "/cloud.vtu", NULL));
  if (parse_vtu(d, DIR "/cloud.vtu", 14, 14)) {
    check_cells(d, 14, ident, ones, vt);
    check_array(d, "PointData", "weight", "Float64", 1, w, 14 * 8);
  }
  vr_free(d);

  /* Mixed cells (a surface triangle, a quad and a linear tet) on a cleared writer;
   * no fields, so no PointData/CellData sections. */
  fcm_vtu_clear(vtu);
  int mtypes[3] = {FCM_VTK_TRIANGLE, FCM_VTK_QUAD, FCM_VTK_TETRA}, mnodes[3] = {3, 4, 4};
  int64_t mconn[11] = {0, 1, 2, 0, 1, 4, 3, 5, 6, 7, 8};
  TEST_OK(ctx, fcm_vtu_set_points(vtu, 9, m->x));
  TEST_OK(ctx, fcm_vtu_set_cells_mixed(vtu, 3, mtypes, mconn));
  TEST_OK(ctx, fcm_vtu_write(vtu, DIR "/mixed.vtu", NULL));
  if (parse_vtu(d, DIR "/mixed.vtu", 9, 3)) {
    check_cells(d, 3, mconn, mnodes, mtypes);
    check_array(d, "Points", NULL, "Float64", 3, m->x, 9 * 3 * 8);
    TEST_TRUE(!vr_find(d, "PointData", NULL, 0) && !vr_find(d, "CellData", NULL, 0));
  }
  vr_free(d);

  /* An empty grid is still a valid file. */
  fcm_vtu_clear(vtu);
  TEST_OK(ctx, fcm_vtu_set_points(vtu, 0, NULL));
  TEST_OK(ctx, fcm_vtu_write(vtu, DIR "/empty.vtu", NULL));
  if (parse_vtu(d, DIR "/empty.vtu", 0, 0)) check_cells(d, 0, mconn, mnodes, mtypes);
  vr_free(d);

  fcm_vtu_destroy(&vtu);
  free(d);
  free(m);
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  if (!test_failures_) vr_rmdir(DIR);
  return TEST_RESULT();
}
