/* Cut-cell rules out to a file for other finite element codes: a JSON header with the table of
 * arrays, then the arrays raw and little-endian (format: lib/docs/rules_format.md). */
#include "embed/rules_impl.h"
#include "io/io_impl.h"

#include <stdarg.h>
#include <stdint.h>
#include <string.h>

#define RULES_MAGIC "FCMRULES"
/* Version 2 adds a rule's "axis_degree" below its strength (a rule exact on a capped space,
 * as Hex8's mass on Q_2); a file without such a rule is written as version 1, which every
 * reader of version 1 reads right. A version-1 reader refuses version 2 instead of taking a
 * capped rule for exact on all of P_m. */
#define RULES_VERSION_CAPPED 2
#define RULES_MAX_ARRAYS     32 /* at most 5 per cell and piece + 2 x 6 volume + 6 surface + 2 mesh */

/* Where an array's values come from. */
typedef enum source {
  SRC_CELL_CLASS,
  SRC_CELL_FRACTION,
  SRC_CELL_PIECE_OFFSETS,
  SRC_PIECE_CELL,
  SRC_PIECE_VOLUME,
  SRC_OFFSETS, /* per piece, of the points of `kind` (FCM_RULE_KIND_COUNT: surface) */
  SRC_POINTS_REF,
  SRC_POINTS_PHYS,
  SRC_WEIGHTS_REF,
  SRC_WEIGHTS_PHYS,
  SRC_FLAGS,
  SRC_NORMALS,
  SRC_TRIANGLES,
  SRC_MESH_NODES,
  SRC_MESH_CELLS
} source;

typedef enum dtype { DT_F64, DT_I64, DT_I32, DT_U8 } dtype;

static const char *const dtype_names[] = {"float64", "int64", "int32", "uint8"};
static const int dtype_sizes[] = {8, 8, 4, 1};

typedef struct array_desc {
  char name[40];
  dtype type;
  fcm_index rows;
  int cols; /* 0: one-dimensional */
  source src;
  int kind;         /* fcm_rule_kind, or FCM_RULE_KIND_COUNT for the surface rule */
  long long offset; /* from the start of the data section */
} array_desc;

/* The growing JSON text of the header. */
typedef struct text {
  fcm_ctx *ctx;
  char *s;
  size_t len, cap;
} text;

static fcm_status text_printf(text *t, const char *fmt, ...) FCM__PRINTF(2, 3);

static fcm_status text_printf(text *t, const char *fmt, ...)
{
  fcm_status st = FCM_OK;
  va_list ap;
  va_start(ap, fmt);
  const int n = vsnprintf(t->s ? t->s + t->len : NULL, t->s ? t->cap - t->len : 0, fmt, ap);
  va_end(ap);
  FCM_CHECK(n >= 0, t->ctx, FCM_ERR_INTERNAL, "cell rules write: header formatting failed");
  if (t->len + (size_t)n + 1 > t->cap) {
    size_t cap = 2 * (t->len + (size_t)n + 1) + 256;
    char *s = NULL;
    FCM_ALLOC_RAW(t->ctx, cap, s);
    if (t->s) memcpy(s, t->s, t->len);
    fcm__free(t->ctx, t->s);
    t->s = s;
    t->cap = cap;
    va_start(ap, fmt);
    vsnprintf(t->s + t->len, t->cap - t->len, fmt, ap);
    va_end(ap);
  }
  t->len += (size_t)n;
cleanup:
  return st;
}

/* Buffered little-endian output, independent of the host's byte order. */
typedef struct sink {
  fcm_ctx *ctx;
  fcm__atomic_file *af;
  unsigned char buf[1 << 14];
  size_t n;
} sink;

static fcm_status sink_flush(sink *k)
{
  fcm_status st = fcm__io_atomic_write(k->ctx, k->af, k->buf, k->n);
  k->n = 0;
  return st;
}

static fcm_status put_u64(sink *k, uint64_t v, int bytes)
{
  if (k->n + 8 > sizeof k->buf) {
    const fcm_status st = sink_flush(k);
    if (st != FCM_OK) return st;
  }
  for (int b = 0; b < bytes; b++)
    k->buf[k->n++] = (unsigned char)(v >> (8 * b));
  return FCM_OK;
}

static fcm_status put_f64(sink *k, double x)
{
  uint64_t v;
  memcpy(&v, &x, sizeof v);
  return put_u64(k, v, 8);
}

static fcm_status put_i64(sink *k, long long x)
{
  return put_u64(k, (uint64_t)x, 8);
}

/* ------------------------------------------------------------------------ array table */

static void add_array(array_desc *a, int *n, const char *prefix, const char *name, dtype type,
                      fcm_index rows, int cols, source src, int kind)
{
  array_desc *d = &a[(*n)++];
  snprintf(d->name, sizeof d->name, "%s%s", prefix, name);
  d->type = type;
  d->rows = rows;
  d->cols = cols;
  d->src = src;
  d->kind = kind;
}

/* Number of points of `kind` (FCM_RULE_KIND_COUNT: surface) over all pieces. */
static fcm_index count_points(const fcm_cell_rules *R, int kind)
{
  fcm_index total = 0;
  for (fcm_index p = 0; p < R->num_pieces; p++) {
    int n = 0;
    if (kind == FCM_RULE_KIND_COUNT)
      fcm_cell_rules_get_piece_surface(R, p, &n, NULL, NULL, NULL, NULL);
    else
      fcm_cell_rules_get_piece(R, p, (fcm_rule_kind)kind, &n, NULL, NULL, NULL);
    total += n;
  }
  return total;
}

/* The arrays the file holds, in file order, with their offsets; returns their number. */
static int array_table(const fcm_cell_rules *R, const fcm_mesh *mesh,
                       const fcm_cell_rules_write_options *o, const fcm_index npts[], array_desc *a)
{
  int n = 0;
  const fcm_index C = R->num_cells, P = R->num_pieces;
  add_array(a, &n, "", "cell_class", DT_I32, C, 0, SRC_CELL_CLASS, 0);
  add_array(a, &n, "", "cell_volume_fraction", DT_F64, C, 0, SRC_CELL_FRACTION, 0);
  add_array(a, &n, "", "cell_piece_offsets", DT_I64, C + 1, 0, SRC_CELL_PIECE_OFFSETS, 0);
  add_array(a, &n, "", "piece_cell", DT_I64, P, 0, SRC_PIECE_CELL, 0);
  add_array(a, &n, "", "piece_volume", DT_F64, P, 0, SRC_PIECE_VOLUME, 0);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!fcm_cell_rules_has_kind(R, (fcm_rule_kind)k)) continue;
    char pre[24];
    snprintf(pre, sizeof pre, "%s/", fcm_rule_kind_name((fcm_rule_kind)k));
    add_array(a, &n, pre, "piece_offsets", DT_I64, P + 1, 0, SRC_OFFSETS, k);
    add_array(a, &n, pre, "points_ref", DT_F64, npts[k], 3, SRC_POINTS_REF, k);
    add_array(a, &n, pre, "weights_ref", DT_F64, npts[k], 0, SRC_WEIGHTS_REF, k);
    add_array(a, &n, pre, "flags", DT_U8, npts[k], 0, SRC_FLAGS, k);
    if (o->include_physical) {
      add_array(a, &n, pre, "points_phys", DT_F64, npts[k], 3, SRC_POINTS_PHYS, k);
      add_array(a, &n, pre, "weights_phys", DT_F64, npts[k], 0, SRC_WEIGHTS_PHYS, k);
    }
  }
  if (fcm_cell_rules_surface_strength(R) >= 0) {
    const int s = FCM_RULE_KIND_COUNT;
    add_array(a, &n, "surface/", "piece_offsets", DT_I64, P + 1, 0, SRC_OFFSETS, s);
    add_array(a, &n, "surface/", "points_ref", DT_F64, npts[s], 3, SRC_POINTS_REF, s);
    add_array(a, &n, "surface/", "weights", DT_F64, npts[s], 0, SRC_WEIGHTS_REF, s);
    add_array(a, &n, "surface/", "normals", DT_F64, npts[s], 3, SRC_NORMALS, s);
    add_array(a, &n, "surface/", "triangles", DT_I64, npts[s], 0, SRC_TRIANGLES, s);
    if (o->include_physical)
      add_array(a, &n, "surface/", "points_phys", DT_F64, npts[s], 3, SRC_POINTS_PHYS, s);
  }
  if (o->include_mesh) {
    add_array(a, &n, "mesh/", "nodes", DT_F64, fcm_mesh_num_nodes(mesh), 3, SRC_MESH_NODES, 0);
    add_array(a, &n, "mesh/", "cells", DT_I64, C, fcm_mesh_nodes_per_cell(mesh), SRC_MESH_CELLS, 0);
  }
  long long off = 0;
  for (int i = 0; i < n; i++) {
    a[i].offset = off;
    off += (long long)a[i].rows * (a[i].cols ? a[i].cols : 1) * dtype_sizes[a[i].type];
    off = (off + 7) / 8 * 8;
  }
  return n;
}

/* ----------------------------------------------------------------------------- header */

/* `s` as a JSON string (quotes and backslashes escaped; `s` has no control characters). */
static fcm_status json_string(text *t, const char *s)
{
  fcm_status st = FCM_OK;
  FCM_TRY(t->ctx, text_printf(t, "\""));
  for (; *s; s++)
    FCM_TRY(t->ctx, text_printf(t, *s == '"' || *s == '\\' ? "\\%c" : "%c", *s));
  FCM_TRY(t->ctx, text_printf(t, "\""));
cleanup:
  return st;
}

static fcm_status json_vec3(text *t, const char *name, const double v[3])
{
  char b[3][32];
  for (int d = 0; d < 3; d++)
    fcm__io_format_double(v[d], b[d]);
  return text_printf(t, "\"%s\": [%s, %s, %s]", name, b[0], b[1], b[2]);
}

/* Rules, counts, the mesh description (everything but the array table). */
static fcm_status header_body(text *t, const fcm_cell_rules *R, const fcm_mesh *mesh,
                              const fcm_cell_rules_write_options *o, const fcm_index npts[])
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = t->ctx;
  const fcm_element_info *ei = fcm_element_get_info(R->type);
  double lo[3], hi[3];
  fcm_mesh_bounding_box(mesh, lo, hi);
  int version = 1;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    if (fcm_cell_rules_has_kind(R, (fcm_rule_kind)k) &&
        fcm_cell_rules_axis_degree(R, (fcm_rule_kind)k) <
            fcm_cell_rules_strength(R, (fcm_rule_kind)k))
      version = RULES_VERSION_CAPPED;
  FCM_TRY(ctx,
          text_printf(t, "{\n  \"format\": \"fcm-cell-rules\",\n  \"version\": %d,\n", version));
  FCM_TRY(ctx, text_printf(t, "  \"byte_order\": \"little\",\n  \"element\": \"%s\",\n", ei->name));
  FCM_TRY(ctx, text_printf(t, "  \"reference_cell\": \"%s\",\n",
                           ei->shape == FCM_SHAPE_HEX ? "[-1,1]^3" : "unit tetrahedron"));
  FCM_TRY(ctx, text_printf(t, "  \"nodes_per_cell\": %d,\n", ei->num_nodes));
  FCM_TRY(ctx, text_printf(t, "  \"num_cells\": %lld,\n  \"num_pieces\": %lld,\n",
                           (long long)R->num_cells, (long long)R->num_pieces));
  FCM_TRY(ctx, text_printf(t, "  \"cell_classes\": [\"uncut\", \"cut\", \"dropped\"],\n"));
  FCM_TRY(ctx, text_printf(t, "  \"rules\": {"));
  int first = 1;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    if (!fcm_cell_rules_has_kind(R, (fcm_rule_kind)k)) continue;
    FCM_TRY(ctx, text_printf(t,
                             "%s\n    \"%s\": {\"strength\": %d, \"axis_degree\": %d, "
                             "\"num_points\": %lld}",
                             first ? "" : ",", fcm_rule_kind_name((fcm_rule_kind)k),
                             fcm_cell_rules_strength(R, (fcm_rule_kind)k),
                             fcm_cell_rules_axis_degree(R, (fcm_rule_kind)k), (long long)npts[k]));
    first = 0;
  }
  FCM_TRY(ctx, text_printf(t, "\n  },\n"));
  if (fcm_cell_rules_surface_strength(R) >= 0)
    FCM_TRY(ctx,
            text_printf(t, "  \"surface\": {\"strength\": %d, \"num_points\": %lld},\n",
                        fcm_cell_rules_surface_strength(R), (long long)npts[FCM_RULE_KIND_COUNT]));
  else
    FCM_TRY(ctx, text_printf(t, "  \"surface\": null,\n"));
  FCM_TRY(ctx, text_printf(t, "  \"num_cuts\": %d,\n", fcm_cell_rules_num_cuts(R)));
  FCM_TRY(ctx, text_printf(t, "  \"mesh\": {\"num_nodes\": %lld, \"num_cells\": %lld, ",
                           (long long)fcm_mesh_num_nodes(mesh), (long long)R->num_cells));
  FCM_TRY(ctx, json_vec3(t, "lo", lo));
  FCM_TRY(ctx, text_printf(t, ", "));
  FCM_TRY(ctx, json_vec3(t, "hi", hi));
  FCM_TRY(ctx, text_printf(t, ", \"included\": %s},\n", o->include_mesh ? "true" : "false"));
  FCM_TRY(ctx, text_printf(t, "  \"description\": "));
  if (o->description)
    FCM_TRY(ctx, json_string(t, o->description));
  else
    FCM_TRY(ctx, text_printf(t, "null"));
  FCM_TRY(ctx, text_printf(t, ",\n"));
cleanup:
  return st;
}

/* The whole header, padded with spaces so that the data section starts 8-byte aligned. */
static fcm_status header(text *t, const fcm_cell_rules *R, const fcm_mesh *mesh,
                         const fcm_cell_rules_write_options *o, const fcm_index npts[],
                         const array_desc *a, int na, long long data_bytes)
{
  fcm_status st = FCM_OK;
  FCM_TRY(t->ctx, header_body(t, R, mesh, o, npts));
  FCM_TRY(t->ctx, text_printf(t, "  \"data_bytes\": %lld,\n  \"arrays\": [", data_bytes));
  for (int i = 0; i < na; i++) {
    FCM_TRY(t->ctx, text_printf(t, "%s\n    {\"name\": \"%s\", \"dtype\": \"%s\", ", i ? "," : "",
                                a[i].name, dtype_names[a[i].type]));
    if (a[i].cols)
      FCM_TRY(t->ctx, text_printf(t, "\"shape\": [%lld, %d], ", (long long)a[i].rows, a[i].cols));
    else
      FCM_TRY(t->ctx, text_printf(t, "\"shape\": [%lld], ", (long long)a[i].rows));
    FCM_TRY(t->ctx, text_printf(t, "\"offset\": %lld, \"byte_order\": \"little\"}", a[i].offset));
  }
  FCM_TRY(t->ctx, text_printf(t, "\n  ]\n}\n"));
  while ((16 + t->len) % 8)
    FCM_TRY(t->ctx, text_printf(t, " "));
cleanup:
  return st;
}

/* ----------------------------------------------------------------------------- arrays */

/* The points of `kind` (FCM_RULE_KIND_COUNT: surface) of one piece. */
static void piece_points(const fcm_cell_rules *R, fcm_index p, int kind, int *n, const double **x,
                         const double **w, const unsigned char **f, const double **nrm,
                         const fcm_index **tri)
{
  if (kind == FCM_RULE_KIND_COUNT) {
    fcm_cell_rules_get_piece_surface(R, p, n, x, w, nrm, tri);
    *f = NULL;
  } else {
    fcm_cell_rules_get_piece(R, p, (fcm_rule_kind)kind, n, x, w, f);
    *nrm = NULL;
    *tri = NULL;
  }
}

/* The per-point values of array `a`, piece by piece. */
static fcm_status write_points(sink *k, const fcm_cell_rules *R, const fcm_mesh *mesh,
                               const array_desc *a)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = k->ctx;
  double x[3], det;
  for (fcm_index p = 0; p < R->num_pieces; p++) {
    int n = 0;
    const double *pt, *w, *nrm;
    const unsigned char *f;
    const fcm_index *tri;
    piece_points(R, p, a->kind, &n, &pt, &w, &f, &nrm, &tri);
    for (int j = 0; j < n; j++) {
      const double *xi = pt + 3 * j;
      if (a->src == SRC_POINTS_PHYS || a->src == SRC_WEIGHTS_PHYS)
        FCM_TRY(ctx, fcm_cell_rules_map_points(R, mesh, R->piece_cell[p], 1, xi, x, &det));
      switch (a->src) {
      case SRC_POINTS_REF:
        for (int d = 0; d < 3; d++)
          FCM_TRY(ctx, put_f64(k, xi[d]));
        break;
      case SRC_POINTS_PHYS:
        for (int d = 0; d < 3; d++)
          FCM_TRY(ctx, put_f64(k, x[d]));
        break;
      case SRC_WEIGHTS_REF:
        FCM_TRY(ctx, put_f64(k, w[j]));
        break;
      case SRC_WEIGHTS_PHYS:
        FCM_TRY(ctx, put_f64(k, w[j] * det));
        break;
      case SRC_FLAGS:
        FCM_TRY(ctx, put_u64(k, f[j], 1));
        break;
      case SRC_NORMALS:
        for (int d = 0; d < 3; d++)
          FCM_TRY(ctx, put_f64(k, nrm[3 * j + d]));
        break;
      default: /* SRC_TRIANGLES */
        FCM_TRY(ctx, put_i64(k, tri[j]));
        break;
      }
    }
  }
cleanup:
  return st;
}

/* The values of array `a` (per cell, per piece, offsets or the mesh). */
static fcm_status write_array(sink *k, const fcm_cell_rules *R, const fcm_mesh *mesh,
                              const array_desc *a)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = k->ctx;
  long long sum = 0;
  switch (a->src) {
  case SRC_CELL_CLASS:
    for (fcm_index c = 0; c < R->num_cells; c++)
      FCM_TRY(ctx, put_u64(k, (uint64_t)fcm_cell_rules_class(R, c), 4));
    break;
  case SRC_CELL_FRACTION:
    for (fcm_index c = 0; c < R->num_cells; c++)
      FCM_TRY(ctx, put_f64(k, fcm_cell_rules_volume_fraction(R, c)));
    break;
  case SRC_CELL_PIECE_OFFSETS:
    for (fcm_index c = 0; c <= R->num_cells; c++)
      FCM_TRY(ctx, put_i64(k, R->piece_off[c]));
    break;
  case SRC_PIECE_CELL:
    for (fcm_index p = 0; p < R->num_pieces; p++)
      FCM_TRY(ctx, put_i64(k, R->piece_cell[p]));
    break;
  case SRC_PIECE_VOLUME:
    for (fcm_index p = 0; p < R->num_pieces; p++)
      FCM_TRY(ctx, put_f64(k, R->piece_volume[p]));
    break;
  case SRC_OFFSETS:
    FCM_TRY(ctx, put_i64(k, 0));
    for (fcm_index p = 0; p < R->num_pieces; p++) {
      int n = 0;
      const double *x, *w, *nrm;
      const unsigned char *f;
      const fcm_index *tri;
      piece_points(R, p, a->kind, &n, &x, &w, &f, &nrm, &tri);
      sum += n;
      FCM_TRY(ctx, put_i64(k, sum));
    }
    break;
  case SRC_MESH_NODES:
    for (fcm_index i = 0; i < 3 * fcm_mesh_num_nodes(mesh); i++)
      FCM_TRY(ctx, put_f64(k, fcm_mesh_coords(mesh)[i]));
    break;
  case SRC_MESH_CELLS:
    for (fcm_index i = 0; i < R->num_cells * fcm_mesh_nodes_per_cell(mesh); i++)
      FCM_TRY(ctx, put_i64(k, fcm_mesh_cells(mesh)[i]));
    break;
  default:
    FCM_TRY(ctx, write_points(k, R, mesh, a));
    break;
  }
cleanup:
  return st;
}

/* ------------------------------------------------------------------------------ front */

fcm_cell_rules_write_options fcm_cell_rules_write_options_default(void)
{
  fcm_cell_rules_write_options o;
  memset(&o, 0, sizeof o);
  o.include_mesh = 1;
  o.include_physical = 1;
  o.description = NULL;
  return o;
}

/* `mesh` is the mesh of `rules` (its cell count and element type); FCM_ERR_ARG otherwise. */
static fcm_status check_mesh(const fcm_cell_rules *R, const fcm_mesh *mesh, const char *what)
{
  fcm_status st = FCM_OK;
  const fcm_element_type mt = fcm_mesh_element_type(mesh);
  FCM_CHECK(fcm_mesh_num_cells(mesh) == R->num_cells && mt == R->type, R->ctx, FCM_ERR_ARG,
            "%s: mesh (%lld %s cells) is not the rules' mesh (%lld %s cells)", what,
            (long long)fcm_mesh_num_cells(mesh), fcm_element_get_info(mt)->name,
            (long long)R->num_cells, fcm_element_get_info(R->type)->name);
cleanup:
  return st;
}

fcm_status fcm_cell_rules_map_points(const fcm_cell_rules *rules, const fcm_mesh *mesh,
                                     fcm_index cell, int num_points, const double *xi, double *x,
                                     double *det)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9];
  FCM_CHECK(rules && mesh && (xi || num_points == 0), ctx, FCM_ERR_ARG,
            "cell rules map: NULL argument (rules, mesh and xi are required)");
  FCM_CHECK(num_points >= 0, ctx, FCM_ERR_ARG, "cell rules map: num_points = %d must be >= 0",
            num_points);
  FCM_CHECK(cell >= 0 && cell < rules->num_cells, ctx, FCM_ERR_ARG,
            "cell rules map: cell %lld out of range [0,%lld)", (long long)cell,
            (long long)rules->num_cells);
  FCM_TRY(ctx, check_mesh(rules, mesh, "cell rules map"));
  fcm_mesh_cell_coords(mesh, cell, X);
  for (int j = 0; j < num_points; j++) {
    if (x) fcm_element_map(rules->type, X, xi + 3 * j, x + 3 * j);
    if (det) det[j] = fcm_element_jacobian(rules->type, X, xi + 3 * j, J);
  }
cleanup:
  return st;
}

fcm_status fcm_cell_rules_write(const fcm_cell_rules *rules, const fcm_mesh *mesh, const char *path,
                                const fcm_cell_rules_write_options *opts)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  const fcm_cell_rules_write_options o = opts ? *opts : fcm_cell_rules_write_options_default();
  fcm__atomic_file af;
  text t = {ctx, NULL, 0, 0};
  sink *k = NULL;
  array_desc a[RULES_MAX_ARRAYS];
  fcm_index npts[FCM_RULE_KIND_COUNT + 1] = {0};
  memset(&af, 0, sizeof af);
  FCM_CHECK(rules && mesh && path, ctx, FCM_ERR_ARG,
            "cell rules write: NULL argument (rules, mesh and path are required)");
  FCM_CHECK(*path, ctx, FCM_ERR_ARG, "cell rules write: path is empty");
  FCM_TRY(ctx, check_mesh(rules, mesh, "cell rules write"));
  FCM_CHECK(!o.description || !*o.description || fcm__io_printable(o.description), ctx, FCM_ERR_ARG,
            "cell rules write: description has control characters (printable text "
            "only)");
  for (int kind = 0; kind <= FCM_RULE_KIND_COUNT; kind++)
    if (kind == FCM_RULE_KIND_COUNT || fcm_cell_rules_has_kind(rules, (fcm_rule_kind)kind))
      npts[kind] = count_points(rules, kind);
  const int na = array_table(rules, mesh, &o, npts, a);
  const array_desc *last = &a[na - 1];
  const long long data_bytes =
      (last->offset +
       (long long)last->rows * (last->cols ? last->cols : 1) * dtype_sizes[last->type] + 7) /
      8 * 8;
  FCM_TRY(ctx, header(&t, rules, mesh, &o, npts, a, na, data_bytes));
  FCM_ALLOC(ctx, 1, k);
  k->ctx = ctx;
  k->af = &af;
  FCM_TRY(ctx, fcm__io_atomic_open(ctx, path, 0, NULL, &af));
  FCM_TRY(ctx, fcm__io_atomic_write(ctx, &af, RULES_MAGIC, 8));
  FCM_TRY(ctx, put_u64(k, (uint64_t)t.len, 8));
  FCM_TRY(ctx, sink_flush(k));
  FCM_TRY(ctx, fcm__io_atomic_write(ctx, &af, t.s, t.len));
  for (int i = 0; i < na; i++) {
    FCM_TRY(ctx, write_array(k, rules, mesh, &a[i]));
    const long long end =
        a[i].offset + (long long)a[i].rows * (a[i].cols ? a[i].cols : 1) * dtype_sizes[a[i].type];
    for (long long pad = end; pad < (i + 1 < na ? a[i + 1].offset : data_bytes); pad++)
      FCM_TRY(ctx, put_u64(k, 0, 1));
  }
  FCM_TRY(ctx, sink_flush(k));
  FCM_TRY(ctx, fcm__io_atomic_commit(ctx, &af));
cleanup:
  fcm__io_atomic_abort(ctx, &af);
  fcm__free(ctx, k);
  fcm__free(ctx, t.s);
  return st;
}
