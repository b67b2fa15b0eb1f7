/* VTU writer: VTK XML UnstructuredGrid with raw appended binary data (UInt64 headers,
 * host byte order), built from borrowed point, cell and field arrays. */
#include "io/io_impl.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#define CHUNK 1024 /* entries of the generated arrays (offsets, types) per write */

typedef enum scalar_kind { KIND_F64 = 0, KIND_I32, KIND_I64 } scalar_kind;

static const char *const kind_name[] = {"Float64", "Int32", "Int64"};
static const size_t kind_size[] = {sizeof(double), sizeof(int32_t), sizeof(int64_t)};
static const char *const where_name[] = {"point", "cell"};

typedef struct vtu_field {
  char *name; /* owned */
  fcm_vtu_location where;
  scalar_kind kind;
  int num_components;
  fcm_index num_tuples;
  const void *data; /* borrowed */
} vtu_field;

struct fcm_vtu {
  fcm_ctx *ctx;
  int have_points;
  fcm_index num_points;
  const double *xyz;
  fcm_index num_cells;
  int cell_type;         /* the one type, 0 for mixed */
  const int *cell_types; /* mixed: per cell */
  const fcm_index *conn; /* NULL: identity (vertex cells) */
  vtu_field *fields;
  int num_fields, cap_fields;
};

/* Layout of the appended block: one entry per array in file order. */
typedef struct vtu_layout {
  fcm_index conn_len;
  uint64_t *offset; /* num_fields + 4: fields, points, connectivity, offsets, types */
  uint64_t *bytes;
} vtu_layout;

int fcm_vtk_cell_num_nodes(int vtk_type)
{
  switch (vtk_type) {
  case FCM_VTK_VERTEX:
    return 1;
  case FCM_VTK_TRIANGLE:
    return 3;
  case FCM_VTK_QUAD:
    return 4;
  case FCM_VTK_TETRA:
    return 4;
  case FCM_VTK_HEXAHEDRON:
    return 8;
  case FCM_VTK_QUADRATIC_TRIANGLE:
    return 6;
  case FCM_VTK_QUADRATIC_TETRA:
    return 10;
  case FCM_VTK_QUADRATIC_HEXAHEDRON:
    return 20;
  default:
    return 0;
  }
}

#define SUPPORTED_TYPES "1, 5, 9, 10, 12, 22, 24, 25"

fcm_status fcm_vtu_create(fcm_ctx *ctx, fcm_vtu **out)
{
  fcm_status st = FCM_OK;
  fcm_vtu *vtu = NULL;
  if (!out) return fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__, "vtu: out is NULL");
  *out = NULL;
  if (!ctx) return FCM_ERR_ARG;
  FCM_ALLOC(ctx, 1, vtu);
  vtu->ctx = ctx;
  *out = vtu;
cleanup:
  return st;
}

static void free_fields(fcm_vtu *vtu)
{
  for (int i = 0; i < vtu->num_fields; i++)
    FCM_FREE(vtu->ctx, vtu->fields[i].name);
  vtu->num_fields = 0;
}

void fcm_vtu_clear(fcm_vtu *vtu)
{
  if (!vtu) return;
  free_fields(vtu);
  vtu->have_points = 0;
  vtu->num_points = 0;
  vtu->xyz = NULL;
  vtu->num_cells = 0;
  vtu->cell_type = 0;
  vtu->cell_types = NULL;
  vtu->conn = NULL;
}

void fcm_vtu_destroy(fcm_vtu **vtu)
{
  if (!vtu || !*vtu) return;
  fcm_ctx *ctx = (*vtu)->ctx;
  free_fields(*vtu);
  FCM_FREE(ctx, (*vtu)->fields);
  FCM_FREE(ctx, *vtu);
}

fcm_status fcm_vtu_set_points(fcm_vtu *vtu, fcm_index num_points, const double *xyz)
{
  fcm_status st = FCM_OK;
  if (!vtu) return FCM_ERR_ARG;
  FCM_CHECK(num_points >= 0, vtu->ctx, FCM_ERR_ARG, "vtu: number of points %lld must be >= 0",
            (long long)num_points);
  FCM_CHECK(xyz || num_points == 0, vtu->ctx, FCM_ERR_ARG,
            "vtu: point coordinates are NULL for %lld points", (long long)num_points);
  vtu->have_points = 1;
  vtu->num_points = num_points;
  vtu->xyz = xyz;
cleanup:
  return st;
}

fcm_status fcm_vtu_set_cells(fcm_vtu *vtu, int vtk_type, fcm_index num_cells,
                             const fcm_index *connectivity)
{
  fcm_status st = FCM_OK;
  if (!vtu) return FCM_ERR_ARG;
  FCM_CHECK(fcm_vtk_cell_num_nodes(vtk_type) > 0, vtu->ctx, FCM_ERR_ARG,
            "vtu: unknown VTK cell type %d (supported: " SUPPORTED_TYPES ")", vtk_type);
  FCM_CHECK(num_cells >= 0, vtu->ctx, FCM_ERR_ARG, "vtu: number of cells %lld must be >= 0",
            (long long)num_cells);
  FCM_CHECK(connectivity || num_cells == 0 || vtk_type == FCM_VTK_VERTEX, vtu->ctx, FCM_ERR_ARG,
            "vtu: connectivity is NULL for %lld cells of VTK type %d (only vertex cells may "
            "omit it)",
            (long long)num_cells, vtk_type);
  vtu->num_cells = num_cells;
  vtu->cell_type = vtk_type;
  vtu->cell_types = NULL;
  vtu->conn = connectivity;
cleanup:
  return st;
}

fcm_status fcm_vtu_set_cells_mixed(fcm_vtu *vtu, fcm_index num_cells, const int *vtk_types,
                                   const fcm_index *connectivity)
{
  fcm_status st = FCM_OK;
  if (!vtu) return FCM_ERR_ARG;
  FCM_CHECK(num_cells >= 0, vtu->ctx, FCM_ERR_ARG, "vtu: number of cells %lld must be >= 0",
            (long long)num_cells);
  FCM_CHECK(num_cells == 0 || (vtk_types && connectivity), vtu->ctx, FCM_ERR_ARG,
            "vtu: cell types or connectivity NULL for %lld mixed cells", (long long)num_cells);
  vtu->num_cells = num_cells;
  vtu->cell_type = 0;
  vtu->cell_types = vtk_types;
  vtu->conn = connectivity;
cleanup:
  return st;
}

static fcm_status add_field(fcm_vtu *vtu, fcm_vtu_location where, const char *name,
                            scalar_kind kind, int num_components, fcm_index num_tuples,
                            const void *data)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = vtu->ctx;
  char *copy = NULL;
  FCM_CHECK(where == FCM_VTU_POINT_DATA || where == FCM_VTU_CELL_DATA, ctx, FCM_ERR_ARG,
            "vtu: field location %d is neither point (0) nor cell (1) data", (int)where);
  FCM_CHECK(fcm__io_printable(name), ctx, FCM_ERR_ARG,
            "vtu: field name is NULL, empty or has control characters");
  FCM_CHECK(num_components == 1 || num_components == 3 || num_components == 6 ||
                num_components == 9,
            ctx, FCM_ERR_ARG, "vtu: field '%s' has %d components; supported: 1, 3, 6 or 9", name,
            num_components);
  FCM_CHECK(num_tuples >= 0, ctx, FCM_ERR_ARG, "vtu: field '%s' has %lld tuples, must be >= 0",
            name, (long long)num_tuples);
  FCM_CHECK(data || num_tuples == 0, ctx, FCM_ERR_ARG, "vtu: field '%s' data is NULL", name);
  for (int i = 0; i < vtu->num_fields; i++)
    FCM_CHECK(vtu->fields[i].where != where || strcmp(vtu->fields[i].name, name), ctx, FCM_ERR_ARG,
              "vtu: %s field '%s' added twice", where_name[where], name);
  if (vtu->num_fields == vtu->cap_fields) {
    int cap = vtu->cap_fields ? 2 * vtu->cap_fields : 8;
    FCM_TRY(ctx, fcm__resize(ctx, (void **)&vtu->fields, (size_t)vtu->cap_fields, (size_t)cap,
                             sizeof *vtu->fields));
    vtu->cap_fields = cap;
  }
  FCM_TRY(ctx, fcm__io_strdup(ctx, name, &copy));
  vtu_field *f = &vtu->fields[vtu->num_fields++];
  f->name = copy;
  copy = NULL;
  f->where = where;
  f->kind = kind;
  f->num_components = num_components;
  f->num_tuples = num_tuples;
  f->data = data;
cleanup:
  FCM_FREE(ctx, copy);
  return st;
}

fcm_status fcm_vtu_add_field(fcm_vtu *vtu, fcm_vtu_location where, const char *name,
                             int num_components, fcm_index num_tuples, const double *data)
{
  if (!vtu) return FCM_ERR_ARG;
  return add_field(vtu, where, name, KIND_F64, num_components, num_tuples, data);
}

fcm_status fcm_vtu_add_field_int32(fcm_vtu *vtu, fcm_vtu_location where, const char *name,
                                   int num_components, fcm_index num_tuples, const int32_t *data)
{
  if (!vtu) return FCM_ERR_ARG;
  return add_field(vtu, where, name, KIND_I32, num_components, num_tuples, data);
}

fcm_status fcm_vtu_add_field_int64(fcm_vtu *vtu, fcm_vtu_location where, const char *name,
                                   int num_components, fcm_index num_tuples, const int64_t *data)
{
  if (!vtu) return FCM_ERR_ARG;
  return add_field(vtu, where, name, KIND_I64, num_components, num_tuples, data);
}

/* Bytes of an array of `count` entries of `width` bytes, refused when it cannot be
 * addressed. */
static fcm_status array_bytes(fcm_ctx *ctx, const char *what, fcm_index count, size_t width,
                              uint64_t *out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(count >= 0 && (uint64_t)count <= (SIZE_MAX - 16) / width, ctx, FCM_ERR_ARG,
            "vtu: %s with %lld entries is too large to write", what, (long long)count);
  *out = (uint64_t)count * width;
cleanup:
  return st;
}

/* Count the non-finite values of one array into info. */
static void count_nonfinite(const double *a, fcm_index n, const char *name, fcm_vtu_info *info)
{
  for (fcm_index i = 0; i < n; i++) {
    if (isfinite(a[i])) continue;
    if (!info->num_nonfinite) {
      info->first_nonfinite = name;
      info->first_nonfinite_index = (long long)i;
    }
    info->num_nonfinite++;
  }
}

/* Every check that needs the whole description: cell types, connectivity range,
 * field sizes. Fills the layout of the appended block and the non-finite counts. */
static fcm_status validate(fcm_vtu *vtu, vtu_layout *lay, fcm_vtu_info *info)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = vtu->ctx;
  const fcm_index np = vtu->num_points, nc = vtu->num_cells;
  FCM_CHECK(vtu->have_points, ctx, FCM_ERR_ARG, "vtu: no points set (call fcm_vtu_set_points)");
  FCM_CHECK(np <= INT64_MAX / 32 && nc <= INT64_MAX / 32, ctx, FCM_ERR_ARG,
            "vtu: %lld points and %lld cells exceed the writable range", (long long)np,
            (long long)nc);

  /* Cells: types and connectivity length. */
  fcm_index len = 0;
  if (vtu->cell_type) {
    int nn = fcm_vtk_cell_num_nodes(vtu->cell_type);
    len = nc * nn;
    FCM_CHECK(vtu->conn || nc == np, ctx, FCM_ERR_ARG,
              "vtu: %lld vertex cells without connectivity need as many points, have %lld",
              (long long)nc, (long long)np);
  } else {
    for (fcm_index c = 0; c < nc; c++) {
      int nn = fcm_vtk_cell_num_nodes(vtu->cell_types[c]);
      FCM_CHECK(nn > 0, ctx, FCM_ERR_ARG,
                "vtu: cell %lld has unknown VTK cell type %d (supported: " SUPPORTED_TYPES ")",
                (long long)c, vtu->cell_types[c]);
      len += nn;
    }
  }
  lay->conn_len = len;
  if (vtu->conn) {
    fcm_index c = 0;
    int k = 0;
    for (fcm_index i = 0; i < len; i++) {
      int nn = fcm_vtk_cell_num_nodes(vtu->cell_type ? vtu->cell_type : vtu->cell_types[c]);
      fcm_index v = vtu->conn[i];
      FCM_CHECK(v >= 0 && v < np, ctx, FCM_ERR_ARG,
                "vtu: cell %lld (VTK type %d) node %d is point %lld, out of range [0, %lld)",
                (long long)c, vtu->cell_type ? vtu->cell_type : vtu->cell_types[c], k, (long long)v,
                (long long)np);
      if (++k == nn) {
        k = 0;
        c++;
      }
    }
  }

  /* Fields: sizes; the appended block in file order. */
  uint64_t pos = 0;
  for (int i = 0; i < vtu->num_fields; i++) {
    const vtu_field *f = &vtu->fields[i];
    fcm_index want = f->where == FCM_VTU_POINT_DATA ? np : nc;
    FCM_CHECK(f->num_tuples == want, ctx, FCM_ERR_ARG,
              "vtu: %s field '%s' has %lld tuples, expected %lld (the number of %ss)",
              where_name[f->where], f->name, (long long)f->num_tuples, (long long)want,
              where_name[f->where]);
    FCM_TRY(ctx, array_bytes(ctx, f->name, f->num_tuples * f->num_components, kind_size[f->kind],
                             &lay->bytes[i]));
  }
  int nf = vtu->num_fields;
  FCM_TRY(ctx, array_bytes(ctx, "points", 3 * np, sizeof(double), &lay->bytes[nf]));
  FCM_TRY(ctx, array_bytes(ctx, "connectivity", len, sizeof(int64_t), &lay->bytes[nf + 1]));
  FCM_TRY(ctx, array_bytes(ctx, "offsets", nc, sizeof(int64_t), &lay->bytes[nf + 2]));
  FCM_TRY(ctx, array_bytes(ctx, "types", nc, sizeof(uint8_t), &lay->bytes[nf + 3]));
  for (int i = 0; i < nf + 4; i++) {
    lay->offset[i] = pos;
    pos += sizeof(uint64_t) + lay->bytes[i];
  }

  /* Non-finite values: written as they are, reported. */
  count_nonfinite(vtu->xyz, 3 * np, "Points", info);
  for (int i = 0; i < vtu->num_fields; i++) {
    const vtu_field *f = &vtu->fields[i];
    if (f->kind == KIND_F64)
      count_nonfinite(f->data, f->num_tuples * f->num_components, f->name, info);
  }
cleanup:
  return st;
}

static fcm_status write_array_tag(fcm_ctx *ctx, fcm__atomic_file *af, const char *type,
                                  const char *name, int ncomp, uint64_t offset)
{
  fcm_status st = FCM_OK;
  FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, "        <DataArray type=\"%s\"", type));
  if (name) {
    FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, " Name=\""));
    FCM_TRY(ctx, fcm__io_atomic_write_xml(ctx, af, name));
    FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, "\""));
  }
  if (ncomp) FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, " NumberOfComponents=\"%d\"", ncomp));
  FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, " format=\"appended\" offset=\"%llu\"/>\n",
                                     (unsigned long long)offset));
cleanup:
  return st;
}

static fcm_status write_header(fcm_vtu *vtu, fcm__atomic_file *af, const vtu_layout *lay)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = vtu->ctx;
  const int nf = vtu->num_fields;
  FCM_TRY(ctx, fcm__io_atomic_printf(
                   ctx, af,
                   "<?xml version=\"1.0\"?>\n"
                   "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" "
                   "header_type=\"UInt64\">\n"
                   "  <UnstructuredGrid>\n"
                   "    <Piece NumberOfPoints=\"%lld\" NumberOfCells=\"%lld\">\n",
                   fcm__io_byte_order(), (long long)vtu->num_points, (long long)vtu->num_cells));
  for (int w = 0; w < 2; w++) {
    const char *section = w == 0 ? "PointData" : "CellData";
    int opened = 0;
    for (int i = 0; i < nf; i++) {
      const vtu_field *f = &vtu->fields[i];
      if ((int)f->where != w) continue;
      if (!opened) FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, "      <%s>\n", section));
      opened = 1;
      FCM_TRY(ctx, write_array_tag(ctx, af, kind_name[f->kind], f->name, f->num_components,
                                   lay->offset[i]));
    }
    if (opened) FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, "      </%s>\n", section));
  }
  FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, "      <Points>\n"));
  FCM_TRY(ctx, write_array_tag(ctx, af, "Float64", NULL, 3, lay->offset[nf]));
  FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af, "      </Points>\n      <Cells>\n"));
  FCM_TRY(ctx, write_array_tag(ctx, af, "Int64", "connectivity", 0, lay->offset[nf + 1]));
  FCM_TRY(ctx, write_array_tag(ctx, af, "Int64", "offsets", 0, lay->offset[nf + 2]));
  FCM_TRY(ctx, write_array_tag(ctx, af, "UInt8", "types", 0, lay->offset[nf + 3]));
  FCM_TRY(ctx, fcm__io_atomic_printf(ctx, af,
                                     "      </Cells>\n"
                                     "    </Piece>\n"
                                     "  </UnstructuredGrid>\n"
                                     "  <AppendedData encoding=\"raw\">\n"
                                     "   _"));
cleanup:
  return st;
}

/* One appended array: its UInt64 byte count, then the bytes. */
static fcm_status write_block(fcm_ctx *ctx, fcm__atomic_file *af, const void *data, uint64_t bytes)
{
  fcm_status st = FCM_OK;
  FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, &bytes, sizeof bytes));
  FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, data, (size_t)bytes));
cleanup:
  return st;
}

static int cell_type_of(const fcm_vtu *vtu, fcm_index c)
{
  return vtu->cell_type ? vtu->cell_type : vtu->cell_types[c];
}

/* The generated arrays (identity connectivity, offsets, types), CHUNK entries at a time. */
static fcm_status write_cells(fcm_vtu *vtu, fcm__atomic_file *af, const vtu_layout *lay)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = vtu->ctx;
  const int nf = vtu->num_fields;
  const fcm_index nc = vtu->num_cells;
  int64_t ibuf[CHUNK];
  uint8_t tbuf[CHUNK];
  if (vtu->conn) {
    FCM_TRY(ctx, write_block(ctx, af, vtu->conn, lay->bytes[nf + 1]));
  } else {
    FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, &lay->bytes[nf + 1], sizeof(uint64_t)));
    for (fcm_index c0 = 0; c0 < nc; c0 += CHUNK) {
      int n = (int)FCM_MIN((fcm_index)CHUNK, nc - c0);
      for (int i = 0; i < n; i++)
        ibuf[i] = c0 + i;
      FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, ibuf, (size_t)n * sizeof *ibuf));
    }
  }
  FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, &lay->bytes[nf + 2], sizeof(uint64_t)));
  int64_t end = 0;
  for (fcm_index c0 = 0; c0 < nc; c0 += CHUNK) {
    int n = (int)FCM_MIN((fcm_index)CHUNK, nc - c0);
    for (int i = 0; i < n; i++) {
      end += fcm_vtk_cell_num_nodes(cell_type_of(vtu, c0 + i));
      ibuf[i] = end;
    }
    FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, ibuf, (size_t)n * sizeof *ibuf));
  }
  FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, &lay->bytes[nf + 3], sizeof(uint64_t)));
  for (fcm_index c0 = 0; c0 < nc; c0 += CHUNK) {
    int n = (int)FCM_MIN((fcm_index)CHUNK, nc - c0);
    for (int i = 0; i < n; i++)
      tbuf[i] = (uint8_t)cell_type_of(vtu, c0 + i);
    FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, tbuf, (size_t)n));
  }
cleanup:
  return st;
}

fcm_status fcm__vtu_write_fault(fcm_vtu *vtu, const char *path, fcm_vtu_info *info,
                                const fcm__io_fault *fault)
{
  fcm_status st = FCM_OK;
  fcm_vtu_info local;
  vtu_layout lay = {0, NULL, NULL};
  fcm__atomic_file af;
  memset(&af, 0, sizeof af);
  if (!vtu) return FCM_ERR_ARG;
  fcm_ctx *ctx = vtu->ctx;
  memset(&local, 0, sizeof local);
  local.first_nonfinite_index = -1;
  if (info) *info = local;
  FCM_CHECK(path && *path, ctx, FCM_ERR_ARG, "vtu: output path is NULL or empty");
  FCM_ALLOC(ctx, vtu->num_fields + 4, lay.offset);
  FCM_ALLOC(ctx, vtu->num_fields + 4, lay.bytes);
  FCM_TRY(ctx, validate(vtu, &lay, &local));

  FCM_TRY(ctx, fcm__io_atomic_open(ctx, path, 0, fault, &af));
  FCM_TRY(ctx, write_header(vtu, &af, &lay));
  for (int i = 0; i < vtu->num_fields; i++)
    FCM_TRY(ctx, write_block(ctx, &af, vtu->fields[i].data, lay.bytes[i]));
  FCM_TRY(ctx, write_block(ctx, &af, vtu->xyz, lay.bytes[vtu->num_fields]));
  FCM_TRY(ctx, write_cells(vtu, &af, &lay));
  FCM_TRY(ctx, fcm__io_atomic_printf(ctx, &af, "\n  </AppendedData>\n</VTKFile>\n"));
  local.file_bytes = af.bytes;
  FCM_TRY(ctx, fcm__io_atomic_commit(ctx, &af));
  if (info) *info = local;
cleanup:
  fcm__io_atomic_abort(ctx, &af);
  FCM_FREE(ctx, lay.offset);
  FCM_FREE(ctx, lay.bytes);
  return st;
}

fcm_status fcm_vtu_write(fcm_vtu *vtu, const char *path, fcm_vtu_info *info)
{
  return fcm__vtu_write_fault(vtu, path, info, NULL);
}
