/* Voxel image files: NRRD and MetaImage readers (headers parsed line by line with path:line
 * messages, raw or ascii data). */
#include "geom/voxels_impl.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- headers */

typedef enum vtype { T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_I64, T_U64, T_F32, T_F64 } vtype;

static const int type_size[] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};

/* What a header says about the data. */
typedef struct header {
  fcm_ctx *ctx;
  const char *path; /* the header file */
  fcm_index dims[3];
  int have_dims, have_type, have_axes, ascii, big_endian, have_endian;
  vtype type;
  double axes[9], origin[3];
  long long byte_skip; /* -1: the data are the last bytes of the data file */
  long long line_skip;
  char data_file[4096]; /* "": attached */
  long data_line;       /* the header line naming data_file */
  size_t data_offset;   /* attached: offset of the data in the header file */
} header;

/* Lines of a text buffer: [*b, *e) of line number *line; 0 at the end. */
typedef struct lines {
  const char *p, *end;
  long line;
} lines;

static int next_text_line(lines *L, const char **b, const char **e)
{
  if (L->p >= L->end) return 0;
  *b = L->p;
  const char *q = memchr(L->p, '\n', (size_t)(L->end - L->p));
  *e = q ? q : L->end;
  L->p = q ? q + 1 : L->end;
  L->line++;
  /* strip the trailing \r and blanks */
  while (*e > *b && ((*e)[-1] == '\r' || (*e)[-1] == ' ' || (*e)[-1] == '\t'))
    (*e)--;
  return 1;
}

static void copy_trim(char *dst, size_t cap, const char *b, const char *e)
{
  while (b < e && (*b == ' ' || *b == '\t'))
    b++;
  while (e > b && (e[-1] == ' ' || e[-1] == '\t'))
    e--;
  size_t n = (size_t)(e - b) < cap - 1 ? (size_t)(e - b) : cap - 1;
  memcpy(dst, b, n);
  dst[n] = '\0';
}

/* Parse exactly n numbers (separated by blanks, commas or parentheses when `vec`) from s. */
static int parse_numbers(const char *s, int n, double *out)
{
  for (int i = 0; i < n; i++) {
    while (*s == ' ' || *s == '\t' || *s == ',' || *s == '(' || *s == ')')
      s++;
    char *end;
    errno = 0;
    out[i] = strtod(s, &end);
    if (end == s || !isfinite(out[i])) return 0;
    s = end;
  }
  while (*s == ' ' || *s == '\t' || *s == ',' || *s == ')')
    s++;
  return *s == '\0';
}

static int parse_sizes(const char *s, fcm_index out[3])
{
  double v[3];
  if (!parse_numbers(s, 3, v)) return 0;
  for (int d = 0; d < 3; d++) {
    if (!(v[d] >= 1 && v[d] <= (double)VOXEL_MAX_COUNT && v[d] == floor(v[d]))) return 0;
    out[d] = (fcm_index)v[d];
  }
  return 1;
}

static int parse_integer(const char *s, long long lo, long long hi, long long *out)
{
  char *end;
  errno = 0;
  long long v = strtoll(s, &end, 10);
  while (*end == ' ' || *end == '\t')
    end++;
  if (end == s || *end != '\0' || errno || v < lo || v > hi) return 0;
  *out = v;
  return 1;
}

static int lower_eq(const char *a, const char *b)
{
  for (; *a && *b; a++, b++)
    if ((*a | 0x20) != (*b | 0x20)) return 0;
  return *a == *b;
}

static int word_in(const char *v, const char *const *list, int n)
{
  for (int i = 0; i < n; i++)
    if (strcmp(v, list[i]) == 0) return i;
  return -1;
}

#define HDR_CHECK(cond, H, line, ...) FCM_CHECK(cond, (H)->ctx, FCM_ERR_FORMAT, __VA_ARGS__)

static fcm_status nrrd_type(header *H, long line, const char *v)
{
  fcm_status st = FCM_OK;
  static const struct {
    const char *name;
    vtype t;
  } names[] = {{"signed char", T_I8},
               {"int8", T_I8},
               {"int8_t", T_I8},
               {"uchar", T_U8},
               {"unsigned char", T_U8},
               {"uint8", T_U8},
               {"uint8_t", T_U8},
               {"short", T_I16},
               {"short int", T_I16},
               {"signed short", T_I16},
               {"signed short int", T_I16},
               {"int16", T_I16},
               {"int16_t", T_I16},
               {"ushort", T_U16},
               {"unsigned short", T_U16},
               {"unsigned short int", T_U16},
               {"uint16", T_U16},
               {"uint16_t", T_U16},
               {"int", T_I32},
               {"signed int", T_I32},
               {"int32", T_I32},
               {"int32_t", T_I32},
               {"uint", T_U32},
               {"unsigned int", T_U32},
               {"uint32", T_U32},
               {"uint32_t", T_U32},
               {"longlong", T_I64},
               {"long long", T_I64},
               {"long long int", T_I64},
               {"signed long long", T_I64},
               {"signed long long int", T_I64},
               {"int64", T_I64},
               {"int64_t", T_I64},
               {"ulonglong", T_U64},
               {"unsigned long long", T_U64},
               {"unsigned long long int", T_U64},
               {"uint64", T_U64},
               {"uint64_t", T_U64},
               {"float", T_F32},
               {"double", T_F64}};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (strcmp(v, names[i].name) == 0) {
      H->type = names[i].t;
      H->have_type = 1;
      return FCM_OK;
    }
  HDR_CHECK(0, H, line,
            "%s:%ld: type: '%s' is not a NRRD scalar type (int8, uint8, int16, uint16, int32, "
            "uint32, int64, uint64, float, double or their C names)",
            H->path, line, v);
cleanup:
  return st;
}

/* Directory part of `path` joined with `name` (unless name is absolute). */
static fcm_status join_path(header *H, long line, const char *name)
{
  fcm_status st = FCM_OK;
  const char *slash = strrchr(H->path, '/');
  size_t dn = name[0] == '/' || !slash ? 0 : (size_t)(slash - H->path) + 1;
  HDR_CHECK(name[0] != '\0', H, line, "%s:%ld: data file: empty name", H->path, line);
  HDR_CHECK(dn + strlen(name) < sizeof H->data_file, H, line,
            "%s:%ld: data file: the path is longer than %zu bytes", H->path, line,
            sizeof H->data_file - 1);
  memcpy(H->data_file, H->path, dn);
  strcpy(H->data_file + dn, name);
  H->data_line = line;
cleanup:
  return st;
}

/* The NRRD fields that place the image in space (space directions, spacings, space origin,
 * space dimension, space): *handled = 1 for those. */
static fcm_status nrrd_space_field(header *H, long line, const char *field, const char *value,
                                   double spacings[3], int *have_spacings, int *handled)
{
  fcm_status st = FCM_OK;
  *handled = 1;
  if (strcmp(field, "space directions") == 0) {
    HDR_CHECK(strstr(value, "none") == NULL && parse_numbers(value, 9, H->axes), H, line,
              "%s:%ld: space directions: '%s' is not three 3-vectors '(x,y,z) (x,y,z) (x,y,z)'",
              H->path, line, value);
    H->have_axes = 1;
  } else if (strcmp(field, "spacings") == 0) {
    HDR_CHECK(parse_numbers(value, 3, spacings) && spacings[0] > 0 && spacings[1] > 0 &&
                  spacings[2] > 0,
              H, line, "%s:%ld: spacings: '%s' is not 3 positive numbers", H->path, line, value);
    *have_spacings = 1;
  } else if (strcmp(field, "space origin") == 0) {
    HDR_CHECK(parse_numbers(value, 3, H->origin), H, line,
              "%s:%ld: space origin: '%s' is not a 3-vector '(x,y,z)'", H->path, line, value);
  } else if (strcmp(field, "space dimension") == 0) {
    HDR_CHECK(strcmp(value, "3") == 0, H, line,
              "%s:%ld: space dimension: '%s'; only 3 is supported", H->path, line, value);
  } else if (strcmp(field, "space") == 0) {
    static const char *const spaces[] = {"right-anterior-superior",
                                         "RAS",
                                         "left-anterior-superior",
                                         "LAS",
                                         "left-posterior-superior",
                                         "LPS",
                                         "scanner-xyz",
                                         "3D-right-handed",
                                         "3D-left-handed"};
    HDR_CHECK(word_in(value, spaces, 9) >= 0, H, line,
              "%s:%ld: space: '%s' is not a 3D space (right-anterior-superior, "
              "left-anterior-superior, left-posterior-superior, scanner-xyz, 3D-right-handed, "
              "3D-left-handed)",
              H->path, line, value);
  } else {
    *handled = 0;
  }
cleanup:
  return st;
}

/* One 'field: value' line of a NRRD header other than the fields of nrrd_space_field():
 * the layout of the data; fields fcm does not need are accepted, unknown ones refused. */
static fcm_status nrrd_field(header *H, long line, const char *field, const char *value,
                             int *dimension)
{
  fcm_status st = FCM_OK;
  if (strcmp(field, "dimension") == 0) {
    long long v;
    HDR_CHECK(parse_integer(value, 1, 16, &v), H, line,
              "%s:%ld: dimension: '%s' is not an integer in [1, 16]", H->path, line, value);
    FCM_CHECK(v == 3, H->ctx, FCM_ERR_UNSUPPORTED,
              "%s:%ld: dimension: %lld; only 3D scalar images (dimension 3) are supported", H->path,
              line, v);
    *dimension = 3;
  } else if (strcmp(field, "type") == 0) {
    FCM_TRY(H->ctx, nrrd_type(H, line, value));
  } else if (strcmp(field, "sizes") == 0) {
    HDR_CHECK(*dimension == 3, H, line, "%s:%ld: sizes: must follow 'dimension: 3'", H->path, line);
    HDR_CHECK(parse_sizes(value, H->dims), H, line,
              "%s:%ld: sizes: '%s' is not 3 integers in [1, 2^40]", H->path, line, value);
    H->have_dims = 1;
  } else if (strcmp(field, "encoding") == 0) {
    if (strcmp(value, "raw") == 0)
      H->ascii = 0;
    else if (strcmp(value, "ascii") == 0 || strcmp(value, "text") == 0 || strcmp(value, "txt") == 0)
      H->ascii = 1;
    else {
      static const char *const known[] = {"gzip", "gz", "bzip2", "bz2", "hex", "zrl"};
      FCM_CHECK(word_in(value, known, 6) < 0, H->ctx, FCM_ERR_UNSUPPORTED,
                "%s:%ld: encoding: '%s' is not supported (fcm reads raw and ascii; "
                "decompress first, e.g. unu save -e raw)",
                H->path, line, value);
      HDR_CHECK(0, H, line, "%s:%ld: encoding: '%s' is not a NRRD encoding (raw, ascii)", H->path,
                line, value);
    }
  } else if (strcmp(field, "endian") == 0) {
    HDR_CHECK(strcmp(value, "little") == 0 || strcmp(value, "big") == 0, H, line,
              "%s:%ld: endian: '%s' must be little or big", H->path, line, value);
    H->big_endian = strcmp(value, "big") == 0;
    H->have_endian = 1;
  } else if (strcmp(field, "byte skip") == 0) {
    HDR_CHECK(parse_integer(value, -1, LLONG_MAX / 2, &H->byte_skip), H, line,
              "%s:%ld: byte skip: '%s' is not an integer >= -1", H->path, line, value);
  } else if (strcmp(field, "line skip") == 0) {
    HDR_CHECK(parse_integer(value, 0, LLONG_MAX / 2, &H->line_skip), H, line,
              "%s:%ld: line skip: '%s' is not an integer >= 0", H->path, line, value);
  } else if (strcmp(field, "data file") == 0 || strcmp(field, "datafile") == 0) {
    FCM_CHECK(strncmp(value, "LIST", 4) != 0 && !strchr(value, '%'), H->ctx, FCM_ERR_UNSUPPORTED,
              "%s:%ld: data file: '%s': multi-file data (LIST or a format) is not supported",
              H->path, line, value);
    FCM_TRY(H->ctx, join_path(H, line, value));
  } else {
    static const char *const ignored[] = {"content",
                                          "kinds",
                                          "labels",
                                          "units",
                                          "space units",
                                          "centers",
                                          "centerings",
                                          "thicknesses",
                                          "axis mins",
                                          "axismins",
                                          "axis maxs",
                                          "axismaxs",
                                          "min",
                                          "max",
                                          "old min",
                                          "oldmin",
                                          "old max",
                                          "oldmax",
                                          "measurement frame",
                                          "sample units",
                                          "sampleunits",
                                          "block size",
                                          "blocksize",
                                          "number"};
    HDR_CHECK(word_in(field, ignored, (int)(sizeof ignored / sizeof ignored[0])) >= 0, H, line,
              "%s:%ld: '%s' is not a NRRD field", H->path, line, field);
  }
cleanup:
  return st;
}

static fcm_status parse_nrrd(header *H, const char *buf, size_t len)
{
  fcm_status st = FCM_OK;
  lines L = {buf, buf + len, 0};
  const char *b, *e;
  char field[64], value[4096];
  int dimension = 0, have_spacings = 0;
  double spacings[3] = {1, 1, 1};
  HDR_CHECK(next_text_line(&L, &b, &e) && e - b == 8 && memcmp(b, "NRRD000", 7) == 0 &&
                b[7] >= '1' && b[7] <= '5',
            H, 1, "%s:1: not a NRRD file: expected the magic NRRD0001 .. NRRD0005", H->path);
  for (;;) {
    if (!next_text_line(&L, &b, &e)) {
      HDR_CHECK(H->data_file[0], H, L.line,
                "%s:%ld: the header ends without the blank line before the attached data and "
                "without a 'data file' field",
                H->path, L.line);
      break;
    }
    const long line = L.line;
    if (b == e) break; /* blank line: attached data follow */
    if (*b == '#') continue;
    const char *kv = NULL, *sep = NULL;
    for (const char *q = b; q + 1 < e; q++)
      if (q[0] == ':' && q[1] == '=') {
        kv = q;
        break;
      } else if (q[0] == ':' && q[1] == ' ') {
        sep = q;
        break;
      }
    if (kv) continue; /* key/value pair: not needed */
    HDR_CHECK(sep, H, line, "%s:%ld: expected 'field: value' or 'key:=value'", H->path, line);
    copy_trim(field, sizeof field, b, sep);
    copy_trim(value, sizeof value, sep + 2, e);
    int handled = 0;
    FCM_TRY(H->ctx, nrrd_space_field(H, line, field, value, spacings, &have_spacings, &handled));
    if (!handled) FCM_TRY(H->ctx, nrrd_field(H, line, field, value, &dimension));
  }
  HDR_CHECK(dimension == 3 && H->have_dims, H, L.line,
            "%s: the header lacks 'dimension: 3' or 'sizes'", H->path);
  HDR_CHECK(H->have_type, H, L.line, "%s: the header lacks 'type'", H->path);
  HDR_CHECK(H->ascii || type_size[H->type] == 1 || H->have_endian, H, L.line,
            "%s: raw %d-byte data need an 'endian' field (little or big)", H->path,
            type_size[H->type]);
  if (!H->have_axes)
    for (int d = 0; d < 3; d++)
      H->axes[4 * d] = spacings[d];
  else
    HDR_CHECK(!have_spacings, H, L.line,
              "%s: both 'space directions' and 'spacings' given; NRRD allows one of them", H->path);
  H->data_offset = (size_t)(L.p - buf);
cleanup:
  return st;
}

static fcm_status parse_mhd(header *H, const char *buf, size_t len)
{
  fcm_status st = FCM_OK;
  lines L = {buf, buf + len, 0};
  const char *b, *e;
  char key[64], value[4096];
  int ndims = 0, have_file = 0;
  double spacing[3] = {1, 1, 1}, R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  while (!have_file) {
    HDR_CHECK(next_text_line(&L, &b, &e), H, L.line,
              "%s:%ld: the header ends without 'ElementDataFile = ...' (it must be the last "
              "field)",
              H->path, L.line);
    const long line = L.line;
    if (b == e || *b == '#') continue;
    const char *eq = memchr(b, '=', (size_t)(e - b));
    HDR_CHECK(eq, H, line, "%s:%ld: expected 'Key = Value'", H->path, line);
    copy_trim(key, sizeof key, b, eq);
    copy_trim(value, sizeof value, eq + 1, e);
    if (strcmp(key, "NDims") == 0) {
      long long v;
      HDR_CHECK(parse_integer(value, 1, 16, &v), H, line,
                "%s:%ld: NDims: '%s' is not an integer in [1, 16]", H->path, line, value);
      FCM_CHECK(v == 3, H->ctx, FCM_ERR_UNSUPPORTED,
                "%s:%ld: NDims: %lld; only 3D images are supported", H->path, line, v);
      ndims = 3;
    } else if (strcmp(key, "DimSize") == 0) {
      HDR_CHECK(parse_sizes(value, H->dims), H, line,
                "%s:%ld: DimSize: '%s' is not 3 integers in [1, 2^40]", H->path, line, value);
      H->have_dims = 1;
    } else if (strcmp(key, "ElementType") == 0) {
      static const char *const names[] = {
          "MET_CHAR", "MET_UCHAR",     "MET_SHORT",      "MET_USHORT", "MET_INT",
          "MET_UINT", "MET_LONG_LONG", "MET_ULONG_LONG", "MET_FLOAT",  "MET_DOUBLE"};
      int t = word_in(value, names, 10);
      HDR_CHECK(t >= 0, H, line,
                "%s:%ld: ElementType: '%s' is not one of MET_CHAR, MET_UCHAR, MET_SHORT, "
                "MET_USHORT, MET_INT, MET_UINT, MET_LONG_LONG, MET_ULONG_LONG, MET_FLOAT, "
                "MET_DOUBLE",
                H->path, line, value);
      H->type = (vtype)t;
      H->have_type = 1;
    } else if (strcmp(key, "ElementSpacing") == 0 || strcmp(key, "ElementSize") == 0) {
      double s[3];
      HDR_CHECK(parse_numbers(value, 3, s) && s[0] > 0 && s[1] > 0 && s[2] > 0, H, line,
                "%s:%ld: %s: '%s' is not 3 positive numbers", H->path, line, key, value);
      if (strcmp(key, "ElementSpacing") == 0) memcpy(spacing, s, sizeof s);
    } else if (strcmp(key, "Offset") == 0 || strcmp(key, "Origin") == 0 ||
               strcmp(key, "Position") == 0) {
      HDR_CHECK(parse_numbers(value, 3, H->origin), H, line, "%s:%ld: %s: '%s' is not 3 numbers",
                H->path, line, key, value);
    } else if (strcmp(key, "TransformMatrix") == 0 || strcmp(key, "Rotation") == 0 ||
               strcmp(key, "Orientation") == 0) {
      HDR_CHECK(parse_numbers(value, 9, R), H, line, "%s:%ld: %s: '%s' is not 9 numbers", H->path,
                line, key, value);
    } else if (strcmp(key, "ElementByteOrderMSB") == 0 ||
               strcmp(key, "BinaryDataByteOrderMSB") == 0) {
      HDR_CHECK(lower_eq(value, "true") || lower_eq(value, "false"), H, line,
                "%s:%ld: %s: '%s' must be True or False", H->path, line, key, value);
      H->big_endian = lower_eq(value, "true");
    } else if (strcmp(key, "BinaryData") == 0) {
      HDR_CHECK(lower_eq(value, "true") || lower_eq(value, "false"), H, line,
                "%s:%ld: BinaryData: '%s' must be True or False", H->path, line, value);
      H->ascii = lower_eq(value, "false");
    } else if (strcmp(key, "CompressedData") == 0) {
      FCM_CHECK(!lower_eq(value, "true"), H->ctx, FCM_ERR_UNSUPPORTED,
                "%s:%ld: CompressedData = True is not supported (fcm has no zlib); save the "
                "image uncompressed",
                H->path, line);
    } else if (strcmp(key, "ElementNumberOfChannels") == 0) {
      FCM_CHECK(strcmp(value, "1") == 0, H->ctx, FCM_ERR_UNSUPPORTED,
                "%s:%ld: ElementNumberOfChannels = %s; only scalar images (1) are supported",
                H->path, line, value);
    } else if (strcmp(key, "HeaderSize") == 0) {
      HDR_CHECK(parse_integer(value, -1, LLONG_MAX / 2, &H->byte_skip), H, line,
                "%s:%ld: HeaderSize: '%s' is not an integer >= -1", H->path, line, value);
    } else if (strcmp(key, "ObjectType") == 0) {
      HDR_CHECK(strcmp(value, "Image") == 0, H, line, "%s:%ld: ObjectType: '%s'; expected Image",
                H->path, line, value);
    } else if (strcmp(key, "ElementDataFile") == 0) {
      FCM_CHECK(strcmp(value, "LIST") != 0 && !strchr(value, '%'), H->ctx, FCM_ERR_UNSUPPORTED,
                "%s:%ld: ElementDataFile = %s: multi-file data are not supported", H->path, line,
                value);
      if (strcmp(value, "LOCAL") != 0) FCM_TRY(H->ctx, join_path(H, line, value));
      have_file = 1;
    } /* other keys (Comment, AnatomicalOrientation, CenterOfRotation, ...) are not needed */
  }
  HDR_CHECK(ndims == 3 && H->have_dims, H, L.line, "%s: the header lacks 'NDims = 3' or 'DimSize'",
            H->path);
  HDR_CHECK(H->have_type, H, L.line, "%s: the header lacks 'ElementType'", H->path);
  for (int d = 0; d < 3; d++)
    for (int c = 0; c < 3; c++)
      H->axes[3 * d + c] = spacing[d] * R[3 * d + c];
  H->data_offset = (size_t)(L.p - buf);
cleanup:
  return st;
}

/* ---------------------------------------------------------------- data */

static double decode(const unsigned char *p, vtype t, int big)
{
  unsigned char b[8];
  const int n = type_size[t];
  for (int i = 0; i < n; i++)
    b[i] = p[big ? n - 1 - i : i];
  uint64_t u = 0;
  for (int i = n - 1; i >= 0; i--)
    u = (u << 8) | b[i];
  switch (t) {
  case T_I8:
    return (double)(int8_t)(uint8_t)u;
  case T_U8:
    return (double)(uint8_t)u;
  case T_I16:
    return (double)(int16_t)(uint16_t)u;
  case T_U16:
    return (double)(uint16_t)u;
  case T_I32:
    return (double)(int32_t)(uint32_t)u;
  case T_U32:
    return (double)(uint32_t)u;
  case T_I64:
    return (double)(int64_t)u;
  case T_U64:
    return (double)u;
  case T_F32: {
    uint32_t w = (uint32_t)u;
    float f;
    memcpy(&f, &w, sizeof f);
    return (double)f;
  }
  default: {
    double v;
    memcpy(&v, &u, sizeof v);
    return v;
  }
  }
}

static fcm_status read_data(header *H, const char *dpath, const char *data, size_t len,
                            double *values)
{
  fcm_status st = FCM_OK;
  const size_t n = (size_t)H->dims[0] * (size_t)H->dims[1] * (size_t)H->dims[2];
  size_t off = 0;
  for (long long l = 0; l < H->line_skip; l++) {
    const char *q = memchr(data + off, '\n', len - off);
    FCM_CHECK(q, H->ctx, FCM_ERR_FORMAT, "%s: line skip %lld: the data file has only %lld lines",
              dpath, H->line_skip, l);
    off = (size_t)(q - data) + 1;
  }
  if (H->ascii) {
    FCM_CHECK(H->byte_skip >= 0, H->ctx, FCM_ERR_FORMAT,
              "%s: byte skip -1 is only valid for raw data", dpath);
    FCM_CHECK((size_t)H->byte_skip <= len - off, H->ctx, FCM_ERR_FORMAT,
              "%s: byte skip %lld is beyond the end of the data (%zu bytes)", dpath, H->byte_skip,
              len - off);
    const char *p = data + off + H->byte_skip, *end = data + len;
    for (size_t i = 0; i < n; i++) {
      while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r' || *p == ','))
        p++;
      char tok[64];
      size_t k = 0;
      for (; p < end && !(*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r' || *p == ','); p++)
        if (k < sizeof tok - 1)
          tok[k++] = *p;
        else
          k = sizeof tok; /* too long: reported below */
      FCM_CHECK(k < sizeof tok, H->ctx, FCM_ERR_FORMAT,
                "%s: ascii data: value %zu is longer than %zu characters", dpath, i,
                sizeof tok - 1);
      tok[k] = '\0';
      FCM_CHECK(k > 0, H->ctx, FCM_ERR_FORMAT,
                "%s: ascii data: %zu values, expected %zu (sizes %lld x %lld x %lld)", dpath, i, n,
                (long long)H->dims[0], (long long)H->dims[1], (long long)H->dims[2]);
      char *e;
      values[i] = strtod(tok, &e);
      FCM_CHECK(*e == '\0', H->ctx, FCM_ERR_FORMAT,
                "%s: ascii data: value %zu '%s' is not a "
                "number",
                dpath, i, tok);
    }
  } else {
    const size_t need = n * (size_t)type_size[H->type];
    size_t start;
    if (H->byte_skip < 0) {
      FCM_CHECK(len - off >= need, H->ctx, FCM_ERR_FORMAT,
                "%s: raw data: %zu bytes, expected at least %zu (%zu values of %d bytes)", dpath,
                len - off, need, n, type_size[H->type]);
      start = len - need;
    } else {
      start = off + (size_t)H->byte_skip;
      FCM_CHECK(start <= len && len - start >= need, H->ctx, FCM_ERR_FORMAT,
                "%s: raw data: %zu bytes after the %zu skipped, expected %zu (%zu values of %d "
                "bytes)",
                dpath, start <= len ? len - start : 0, start, need, n, type_size[H->type]);
    }
    const unsigned char *p = (const unsigned char *)data + start;
    for (size_t i = 0; i < n; i++)
      values[i] = decode(p + i * (size_t)type_size[H->type], H->type, H->big_endian);
  }
cleanup:
  return st;
}

static int ends_with(const char *s, const char *suffix)
{
  size_t a = strlen(s), b = strlen(suffix);
  return a >= b && lower_eq(s + a - b, suffix);
}

fcm_status fcm_voxel_image_create_from_file(fcm_ctx *ctx, const char *path, fcm_voxel_image **img)
{
  fcm_status st = FCM_OK;
  char *buf = NULL, *dbuf = NULL;
  size_t len = 0, dlen = 0;
  header *H = NULL;
  fcm_voxel_image *m = NULL;
  char what[8400];
  FCM_CHECK(ctx && img, ctx, FCM_ERR_ARG, "voxel image: NULL argument");
  *img = NULL;
  FCM_CHECK(path, ctx, FCM_ERR_ARG, "voxel image: file name is NULL");
  const int nrrd = ends_with(path, ".nrrd") || ends_with(path, ".nhdr");
  const int mhd = ends_with(path, ".mhd") || ends_with(path, ".mha");
  FCM_CHECK(nrrd || mhd, ctx, FCM_ERR_UNSUPPORTED,
            "voxel image: '%s': unknown extension; expected .nrrd or .nhdr (NRRD), .mhd or .mha "
            "(MetaImage)",
            path);
  FCM_ALLOC(ctx, 1, H);
  H->ctx = ctx, H->path = path;
  FCM_TRY(ctx, fcm__file_read_all(ctx, "voxel image", path, VOXEL_MAX_FILE, &buf, &len));
  if (nrrd)
    FCM_TRY(ctx, parse_nrrd(H, buf, len));
  else
    FCM_TRY(ctx, parse_mhd(H, buf, len));
  FCM_TRY(ctx, fcm__voxel_check_geometry(ctx, path, H->dims, H->axes, H->origin));
  const char *dpath = path, *data = buf + H->data_offset;
  size_t dl = len - H->data_offset;
  if (H->data_file[0]) {
    /* messages about the data name the header that refers to them */
    snprintf(what, sizeof what, "voxel image: %s:%ld: data file", path, H->data_line);
    FCM_TRY(ctx, fcm__file_read_all(ctx, what, H->data_file, VOXEL_MAX_FILE, &dbuf, &dlen));
    snprintf(what, sizeof what, "%s (the data file of %s)", H->data_file, path);
    dpath = what, data = dbuf, dl = dlen;
  }
  /* The announced size must fit in the data before the values are allocated: raw values take
   * their size each, ascii values at least 2 bytes but the last. */
  const size_t n = (size_t)H->dims[0] * (size_t)H->dims[1] * (size_t)H->dims[2];
  const size_t least = H->ascii ? 2 * n - 1 : n * (size_t)type_size[H->type];
  FCM_CHECK(least <= dl, ctx, FCM_ERR_FORMAT,
            "%s: %lld x %lld x %lld %s values need at least %zu bytes of data, the file has %zu",
            dpath, (long long)H->dims[0], (long long)H->dims[1], (long long)H->dims[2],
            H->ascii ? "ascii" : "raw", least, dl);
  FCM_ALLOC(ctx, 1, m);
  m->ctx = ctx;
  memcpy(m->dims, H->dims, sizeof m->dims);
  memcpy(m->axes, H->axes, sizeof m->axes);
  memcpy(m->origin, H->origin, sizeof m->origin);
  FCM_ALLOC_RAW(ctx, n, m->values);
  FCM_TRY(ctx, read_data(H, dpath, data, dl, m->values));
  *img = m;
  m = NULL;
cleanup:
  fcm__free(ctx, buf);
  fcm__free(ctx, dbuf);
  fcm__free(ctx, H);
  fcm_voxel_image_destroy(&m);
  return st;
}
