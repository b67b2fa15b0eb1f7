/* Reader for Gmsh MSH files, ASCII versions 4.1 and 2.x: volume elements tet4, tet10,
 * hex8, hex20 are converted from Gmsh's node order to VTK's; the rest is skipped.
 *
 * Gmsh orders the mid-edge nodes of its second-order elements by its own edge lists
 * (Gmsh reference manual, "Node ordering"): tet10 edges 01 12 20 03 23 13 (VTK: 01 12 20
 * 03 13 23); hex20 edges 01 03 04 12 15 23 26 37 45 47 56 67 (VTK: 01 12 23 30 45 56 67
 * 74 04 15 26 37). Corners agree. Errors name the file and the line. */
#include "mesh_impl.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TOK_MAX         64
#define SUPPORTED_TYPES "4 (tet4), 11 (tet10), 5 (hex8), 17 (hex20)"

/* Token reader over the whole file held in memory. */
typedef struct reader {
  fcm_ctx *ctx;
  const char *path;
  char *buf;
  size_t len, pos;
  long line;         /* line of buf[pos], 1-based */
  long tokline;      /* line of the last token */
  size_t toklen;     /* full length of the last token */
  char tok[TOK_MAX]; /* the last token, truncated, non-printable bytes as '?' */
} reader;

/* The permutation vtk[a] = gmsh[perm[a]] for each supported Gmsh type. */
static const int perm_tet10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
static const int perm_hex20[20] = {0,  1, 2,  3,  4,  5,  6,  7,  8,  11,
                                   13, 9, 16, 18, 19, 17, 10, 12, 14, 15};

/* 1 and *type for a supported Gmsh volume type, else 0. */
static int gmsh_volume_type(long long t, fcm_element_type *type)
{
  switch (t) {
  case 4:
    *type = FCM_ELEMENT_TET4;
    return 1;
  case 11:
    *type = FCM_ELEMENT_TET10;
    return 1;
  case 5:
    *type = FCM_ELEMENT_HEX8;
    return 1;
  case 17:
    *type = FCM_ELEMENT_HEX20;
    return 1;
  default:
    return 0;
  }
}

/* Other Gmsh volume types (prisms, pyramids, hex27, higher-order tets and hexes). */
static int gmsh_other_volume(long long t)
{
  static const int other[] = {6, 7, 12, 13, 14, 18, 19, 29, 30, 31, 92, 93};
  for (size_t i = 0; i < sizeof other / sizeof other[0]; i++)
    if (t == other[i]) return 1;
  return 0;
}

/* Files above this size are refused before reading (16 GiB). */
#define GMSH_MAX_BYTES ((size_t)1 << 34)

static fcm_status read_whole_file(fcm_ctx *ctx, const char *path, char **out, size_t *out_len)
{
  return fcm__file_read_all(ctx, "mesh: Gmsh file", path, GMSH_MAX_BYTES, out, out_len);
}

static int is_space(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

/* Advance to the next token; 0 at end of file. */
static int next_token(reader *r)
{
  while (r->pos < r->len && is_space(r->buf[r->pos])) {
    if (r->buf[r->pos] == '\n') r->line++;
    r->pos++;
  }
  r->tokline = r->line;
  if (r->pos >= r->len) {
    r->toklen = 0;
    r->tok[0] = '\0';
    return 0;
  }
  size_t start = r->pos;
  while (r->pos < r->len && !is_space(r->buf[r->pos]))
    r->pos++;
  r->toklen = r->pos - start;
  size_t n = FCM_MIN(r->toklen, (size_t)TOK_MAX - 1);
  for (size_t i = 0; i < n; i++) {
    char c = r->buf[start + i];
    r->tok[i] = (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  r->tok[n] = '\0';
  return 1;
}

/* Next token, failing with "unexpected end of file" when there is none. */
static fcm_status expect_token(reader *r, const char *what)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(next_token(r), r->ctx, FCM_ERR_FORMAT, "%s:%ld: unexpected end of file; expected %s",
            r->path, r->tokline, what);
cleanup:
  return st;
}

static fcm_status expect_word(reader *r, const char *word)
{
  fcm_status st = FCM_OK;
  FCM_TRY(r->ctx, expect_token(r, word));
  FCM_CHECK(strcmp(r->tok, word) == 0 && r->toklen < TOK_MAX, r->ctx, FCM_ERR_FORMAT,
            "%s:%ld: expected %s, found '%s'", r->path, r->tokline, word, r->tok);
cleanup:
  return st;
}

static fcm_status read_int(reader *r, const char *what, long long min, long long max, long long *v)
{
  fcm_status st = FCM_OK;
  char *end = NULL;
  FCM_TRY(r->ctx, expect_token(r, what));
  errno = 0;
  long long x = strtoll(r->tok, &end, 10);
  FCM_CHECK(r->toklen < TOK_MAX && end != r->tok && *end == '\0' && errno == 0, r->ctx,
            FCM_ERR_FORMAT, "%s:%ld: expected %s (an integer), found '%s'", r->path, r->tokline,
            what, r->tok);
  FCM_CHECK(x >= min && x <= max, r->ctx, FCM_ERR_FORMAT,
            "%s:%ld: %s = %lld out of range [%lld, %lld]", r->path, r->tokline, what, x, min, max);
  *v = x;
cleanup:
  return st;
}

static fcm_status read_double(reader *r, const char *what, double *v)
{
  fcm_status st = FCM_OK;
  char *end = NULL;
  FCM_TRY(r->ctx, expect_token(r, what));
  double x = strtod(r->tok, &end);
  FCM_CHECK(r->toklen < TOK_MAX && end != r->tok && *end == '\0' && isfinite(x), r->ctx,
            FCM_ERR_FORMAT, "%s:%ld: expected %s (a finite number), found '%s'", r->path,
            r->tokline, what, r->tok);
  *v = x;
cleanup:
  return st;
}

/* Skip the rest of the current line (through its newline). */
static fcm_status skip_line(reader *r, const char *what)
{
  fcm_status st = FCM_OK;
  while (r->pos < r->len && r->buf[r->pos] != '\n')
    r->pos++;
  FCM_CHECK(r->pos < r->len, r->ctx, FCM_ERR_FORMAT, "%s:%ld: unexpected end of file; expected %s",
            r->path, r->line, what);
  r->pos++;
  r->line++;
cleanup:
  return st;
}

/* Everything read from the file before the mesh is built. */
typedef struct msh_data {
  fcm_index num_nodes;
  fcm_index *tags;  /* file order */
  double *coords;   /* file order, num_nodes x 3 */
  fcm_index *slots; /* hash of tags -> file index */
  size_t cap;
  int have_type;
  fcm_element_type type;
  long long gmsh_type;
  int npc;
  fcm_index num_cells, cells_cap;
  fcm_index *cells; /* file node indices, VTK order */
} msh_data;

static size_t tag_slot(const msh_data *m, fcm_index tag)
{
  size_t h = (size_t)fcm__mesh_mix((uint64_t)tag) & (m->cap - 1);
  while (m->slots[h] >= 0 && m->tags[m->slots[h]] != tag)
    h = (h + 1) & (m->cap - 1);
  return h;
}

static fcm_status alloc_nodes(reader *r, msh_data *m, long long count)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(m->tags == NULL, r->ctx, FCM_ERR_FORMAT, "%s:%ld: second $Nodes section", r->path,
            r->tokline);
  FCM_ALLOC(r->ctx, count, m->tags);
  FCM_ALLOC(r->ctx, 3 * count, m->coords);
  FCM_TRY(r->ctx, fcm__mesh_hash_capacity(r->ctx, count, &m->cap));
  FCM_ALLOC(r->ctx, m->cap, m->slots);
  for (size_t i = 0; i < m->cap; i++)
    m->slots[i] = -1;
cleanup:
  return st;
}

static fcm_status add_node(reader *r, msh_data *m, fcm_index tag)
{
  fcm_status st = FCM_OK;
  size_t h = tag_slot(m, tag);
  FCM_CHECK(m->slots[h] < 0, r->ctx, FCM_ERR_FORMAT,
            "%s:%ld: node tag %lld appears twice in $Nodes", r->path, r->tokline, (long long)tag);
  m->slots[h] = m->num_nodes;
  m->tags[m->num_nodes++] = tag;
cleanup:
  return st;
}

/* A count announced by the file: every entry needs at least `min_bytes` bytes of text
 * (two for a one-digit token and a separator; eight for a node "t x y z" in either
 * version), so a count beyond what the file can hold is malformed and must not turn
 * into a huge allocation. */
static fcm_status read_count(reader *r, const char *what, size_t min_bytes, long long *v)
{
  return read_int(r, what, 0, (long long)FCM_MIN(r->len / min_bytes, (size_t)1 << 40), v);
}

enum { MIN_ENTRY_BYTES = 2, MIN_NODE_BYTES = 8 };

/* The coordinates of the node with Gmsh tag `tag`. */
static fcm_status read_coords(reader *r, long long tag, double *x)
{
  fcm_status st = FCM_OK;
  FCM_TRY(r->ctx, read_double(r, "node x coordinate", &x[0]));
  FCM_TRY(r->ctx, read_double(r, "node y coordinate", &x[1]));
  FCM_TRY(r->ctx, read_double(r, "node z coordinate", &x[2]));
  for (int d = 0; d < 3; d++)
    FCM_CHECK(fabs(x[d]) <= FCM__COORD_MAX, r->ctx, FCM_ERR_FORMAT,
              "%s:%ld: node tag %lld (Gmsh tags, from 1): coordinate %c = %g is "
              "outside " FCM__COORD_RANGE,
              r->path, r->tokline, tag, "xyz"[d], x[d]);
cleanup:
  return st;
}

static fcm_status read_nodes_v4(reader *r, msh_data *m)
{
  fcm_status st = FCM_OK;
  long long nblocks, count, mintag, maxtag;
  FCM_TRY(r->ctx, read_count(r, "number of node blocks", MIN_ENTRY_BYTES, &nblocks));
  FCM_TRY(r->ctx, read_count(r, "number of nodes", MIN_NODE_BYTES, &count));
  FCM_TRY(r->ctx, read_int(r, "minimum node tag", 0, INT64_MAX, &mintag));
  FCM_TRY(r->ctx, read_int(r, "maximum node tag", 0, INT64_MAX, &maxtag));
  FCM_TRY(r->ctx, alloc_nodes(r, m, count));
  for (long long b = 0; b < nblocks; b++) {
    long long dim, etag, param, n;
    FCM_TRY(r->ctx, read_int(r, "node block entity dimension", 0, 3, &dim));
    FCM_TRY(r->ctx, read_int(r, "node block entity tag", INT64_MIN, INT64_MAX, &etag));
    FCM_TRY(r->ctx, read_int(r, "node block parametric flag", 0, 1, &param));
    FCM_TRY(r->ctx, read_int(r, "number of nodes in block", 0, count - m->num_nodes, &n));
    const fcm_index first = m->num_nodes;
    for (long long i = 0; i < n; i++) {
      long long tag;
      FCM_TRY(r->ctx, read_int(r, "node tag", FCM_MAX(mintag, 1), maxtag, &tag));
      FCM_TRY(r->ctx, add_node(r, m, tag));
    }
    for (long long i = 0; i < n; i++) {
      double uvw;
      FCM_TRY(r->ctx, read_coords(r, (long long)m->tags[first + i], m->coords + 3 * (first + i)));
      for (long long k = 0; param && k < dim; k++)
        FCM_TRY(r->ctx, read_double(r, "parametric node coordinate", &uvw));
    }
  }
  FCM_CHECK(m->num_nodes == count, r->ctx, FCM_ERR_FORMAT,
            "%s:%ld: the $Nodes header announces %lld nodes but its blocks hold %lld", r->path,
            r->tokline, count, (long long)m->num_nodes);
  FCM_TRY(r->ctx, expect_word(r, "$EndNodes"));
cleanup:
  return st;
}

static fcm_status read_nodes_v2(reader *r, msh_data *m)
{
  fcm_status st = FCM_OK;
  long long count;
  FCM_TRY(r->ctx, read_count(r, "number of nodes", MIN_NODE_BYTES, &count));
  FCM_TRY(r->ctx, alloc_nodes(r, m, count));
  for (long long i = 0; i < count; i++) {
    long long tag;
    FCM_TRY(r->ctx, read_int(r, "node tag", 1, INT64_MAX, &tag));
    FCM_TRY(r->ctx, add_node(r, m, tag));
    FCM_TRY(r->ctx, read_coords(r, tag, m->coords + 3 * i));
  }
  FCM_TRY(r->ctx, expect_word(r, "$EndNodes"));
cleanup:
  return st;
}

/* Read one supported volume element's node tags (Gmsh order) and store it in VTK order. */
static fcm_status read_cell(reader *r, msh_data *m, long long gmsh_type)
{
  fcm_status st = FCM_OK;
  fcm_element_type type = FCM_ELEMENT_TET4;
  fcm_index g[FCM_ELEMENT_MAX_NODES];
  gmsh_volume_type(gmsh_type, &type);
  if (!m->have_type) {
    const fcm_element_info *info = fcm_element_get_info(type);
    FCM_CHECK(info, r->ctx, FCM_ERR_INTERNAL, "mesh: no element info for type %d", (int)type);
    m->have_type = 1;
    m->type = type;
    m->gmsh_type = gmsh_type;
    m->npc = info->num_nodes;
  }
  FCM_CHECK(type == m->type, r->ctx, FCM_ERR_UNSUPPORTED,
            "%s:%ld: volume element of Gmsh type %lld after elements of type %lld; a mesh holds "
            "one element type only",
            r->path, r->tokline, gmsh_type, m->gmsh_type);
  for (int a = 0; a < m->npc; a++) {
    long long tag;
    FCM_TRY(r->ctx, read_int(r, "element node tag", 1, INT64_MAX, &tag));
    size_t h = tag_slot(m, tag);
    FCM_CHECK(m->slots[h] >= 0, r->ctx, FCM_ERR_FORMAT,
              "%s:%ld: element node tag %lld is not defined in $Nodes", r->path, r->tokline, tag);
    g[a] = m->slots[h];
  }
  if (m->num_cells == m->cells_cap) {
    fcm_index ncap = FCM_MAX(16, 2 * m->cells_cap);
    FCM_TRY(r->ctx, fcm__resize(r->ctx, (void **)&m->cells, (size_t)(m->cells_cap * m->npc),
                                (size_t)(ncap * m->npc), sizeof *m->cells));
    m->cells_cap = ncap;
  }
  fcm_index *cell = m->cells + m->npc * m->num_cells++;
  for (int a = 0; a < m->npc; a++)
    cell[a] = g[type == FCM_ELEMENT_TET10   ? perm_tet10[a]
                : type == FCM_ELEMENT_HEX20 ? perm_hex20[a]
                                            : a];
cleanup:
  return st;
}

static fcm_status check_volume_type(reader *r, long long t)
{
  fcm_status st = FCM_OK;
  fcm_element_type type;
  FCM_CHECK(
      gmsh_volume_type(t, &type), r->ctx, FCM_ERR_UNSUPPORTED,
      "%s:%ld: volume element type %lld is not supported; supported Gmsh types: " SUPPORTED_TYPES,
      r->path, r->tokline, t);
cleanup:
  return st;
}

static fcm_status read_elements_v4(reader *r, msh_data *m)
{
  fcm_status st = FCM_OK;
  long long nblocks, count, mintag, maxtag, seen = 0;
  FCM_TRY(r->ctx, read_count(r, "number of element blocks", MIN_ENTRY_BYTES, &nblocks));
  FCM_TRY(r->ctx, read_count(r, "number of elements", MIN_ENTRY_BYTES, &count));
  FCM_TRY(r->ctx, read_int(r, "minimum element tag", 0, INT64_MAX, &mintag));
  FCM_TRY(r->ctx, read_int(r, "maximum element tag", 0, INT64_MAX, &maxtag));
  for (long long b = 0; b < nblocks; b++) {
    long long dim, etag, type, n;
    FCM_TRY(r->ctx, read_int(r, "element block entity dimension", 0, 3, &dim));
    FCM_TRY(r->ctx, read_int(r, "element block entity tag", INT64_MIN, INT64_MAX, &etag));
    FCM_TRY(r->ctx, read_int(r, "element type", 1, INT32_MAX, &type));
    FCM_TRY(r->ctx, read_int(r, "number of elements in block", 0, count - seen, &n));
    seen += n;
    if (dim < 3) {
      FCM_TRY(r->ctx, skip_line(r, "end of the element block header"));
      for (long long i = 0; i < n; i++)
        FCM_TRY(r->ctx, skip_line(r, "an element line"));
      continue;
    }
    FCM_TRY(r->ctx, check_volume_type(r, type));
    for (long long i = 0; i < n; i++) {
      long long tag;
      FCM_TRY(r->ctx, read_int(r, "element tag", FCM_MAX(mintag, 1), maxtag, &tag));
      FCM_TRY(r->ctx, read_cell(r, m, type));
    }
  }
  FCM_CHECK(seen == count, r->ctx, FCM_ERR_FORMAT,
            "%s:%ld: the $Elements header announces %lld elements but its blocks hold %lld",
            r->path, r->tokline, count, seen);
  FCM_TRY(r->ctx, expect_word(r, "$EndElements"));
cleanup:
  return st;
}

static fcm_status read_elements_v2(reader *r, msh_data *m)
{
  fcm_status st = FCM_OK;
  long long count;
  FCM_TRY(r->ctx, read_count(r, "number of elements", MIN_ENTRY_BYTES, &count));
  for (long long i = 0; i < count; i++) {
    long long tag, type, ntags, t;
    fcm_element_type et;
    FCM_TRY(r->ctx, read_int(r, "element tag", 1, INT64_MAX, &tag));
    FCM_TRY(r->ctx, read_int(r, "element type", 1, INT32_MAX, &type));
    if (!gmsh_volume_type(type, &et)) {
      FCM_CHECK(!gmsh_other_volume(type), r->ctx, FCM_ERR_UNSUPPORTED,
                "%s:%ld: volume element type %lld is not supported; supported Gmsh "
                "types: " SUPPORTED_TYPES,
                r->path, r->tokline, type);
      FCM_TRY(r->ctx, skip_line(r, "end of the element line"));
      continue;
    }
    FCM_TRY(r->ctx, read_int(r, "number of element tags", 0, 64, &ntags));
    for (long long k = 0; k < ntags; k++)
      FCM_TRY(r->ctx, read_int(r, "element tag value", INT64_MIN, INT64_MAX, &t));
    FCM_TRY(r->ctx, read_cell(r, m, type));
  }
  FCM_TRY(r->ctx, expect_word(r, "$EndElements"));
cleanup:
  return st;
}

/* Skip an unknown section $Name ... $EndName. */
static fcm_status skip_section(reader *r)
{
  fcm_status st = FCM_OK;
  char end[TOK_MAX + 4];
  long opened = r->tokline;
  snprintf(end, sizeof end, "$End%s", r->tok + 1);
  while (next_token(r))
    if (strcmp(r->tok, end) == 0) goto cleanup;
  FCM_CHECK(0, r->ctx, FCM_ERR_FORMAT,
            "%s:%ld: unexpected end of file; expected %s to close the "
            "section opened at line %ld",
            r->path, r->line, end, opened);
cleanup:
  return st;
}

fcm_status fcm_mesh_create_from_gmsh(fcm_ctx *ctx, const char *path, fcm_mesh **mesh)
{
  fcm_status st = FCM_OK;
  reader r;
  msh_data m;
  fcm_index *newid = NULL, *cells = NULL;
  double *coords = NULL;
  memset(&r, 0, sizeof r);
  memset(&m, 0, sizeof m);
  FCM_CHECK(ctx && path && mesh, ctx, FCM_ERR_ARG,
            "mesh_create_from_gmsh: ctx, path and mesh must not be NULL");
  *mesh = NULL;
  r.ctx = ctx;
  r.path = path;
  r.line = 1;
  FCM_TRY(ctx, read_whole_file(ctx, path, &r.buf, &r.len));

  /* $MeshFormat: version, file type (0 ASCII, 1 binary), data size. */
  long long file_type, data_size;
  FCM_TRY(ctx, expect_word(&r, "$MeshFormat"));
  FCM_TRY(ctx, expect_token(&r, "MSH version"));
  const long version_line = r.tokline;
  char version[TOK_MAX];
  memcpy(version, r.tok, sizeof version);
  const int v4 = strcmp(version, "4.1") == 0;
  const int v2 = strcmp(version, "2.2") == 0 || strcmp(version, "2.1") == 0 ||
                 strcmp(version, "2.0") == 0 || strcmp(version, "2") == 0;
  FCM_TRY(ctx, read_int(&r, "file type (0 ASCII, 1 binary)", 0, 1, &file_type));
  FCM_CHECK(file_type == 0, ctx, FCM_ERR_UNSUPPORTED,
            "%s:%ld: binary MSH files are not supported; save the mesh as ASCII (Gmsh option "
            "Mesh.Binary = 0)",
            path, r.tokline);
  FCM_CHECK(v4 || v2, ctx, FCM_ERR_FORMAT,
            "%s:%ld: unknown MSH version '%s'; expected 4.1 or 2.2 (or 2.0, 2.1)", path,
            version_line, version);
  FCM_TRY(ctx, read_int(&r, "data size", 1, 64, &data_size));
  FCM_TRY(ctx, expect_word(&r, "$EndMeshFormat"));

  int have_elements = 0;
  while (next_token(&r)) {
    FCM_CHECK(r.tok[0] == '$', ctx, FCM_ERR_FORMAT,
              "%s:%ld: expected a section header ($Name), found '%s'", path, r.tokline, r.tok);
    if (strcmp(r.tok, "$Nodes") == 0) {
      FCM_TRY(ctx, v4 ? read_nodes_v4(&r, &m) : read_nodes_v2(&r, &m));
    } else if (strcmp(r.tok, "$Elements") == 0) {
      FCM_CHECK(m.tags, ctx, FCM_ERR_FORMAT, "%s:%ld: $Elements before $Nodes", path, r.tokline);
      FCM_CHECK(!have_elements, ctx, FCM_ERR_FORMAT, "%s:%ld: second $Elements section", path,
                r.tokline);
      have_elements = 1;
      FCM_TRY(ctx, v4 ? read_elements_v4(&r, &m) : read_elements_v2(&r, &m));
    } else {
      FCM_TRY(ctx, skip_section(&r));
    }
  }
  FCM_CHECK(have_elements, ctx, FCM_ERR_FORMAT, "%s:%ld: no $Elements section in the file", path,
            r.line);
  FCM_CHECK(m.num_cells > 0, ctx, FCM_ERR_UNSUPPORTED,
            "%s: no volume elements; supported Gmsh types: " SUPPORTED_TYPES, path);

  /* Keep the nodes used by cells, in file order. */
  FCM_ALLOC(ctx, m.num_nodes, newid);
  for (fcm_index i = 0; i < m.num_nodes; i++)
    newid[i] = -1;
  for (fcm_index i = 0; i < m.num_cells * m.npc; i++)
    newid[m.cells[i]] = 0;
  fcm_index used = 0;
  for (fcm_index i = 0; i < m.num_nodes; i++)
    if (newid[i] == 0) newid[i] = used++;
  FCM_ALLOC(ctx, 3 * used, coords);
  FCM_ALLOC(ctx, m.num_cells * m.npc, cells);
  for (fcm_index i = 0; i < m.num_nodes; i++)
    if (newid[i] >= 0)
      for (int d = 0; d < 3; d++)
        coords[3 * newid[i] + d] = m.coords[3 * i + d];
  for (fcm_index i = 0; i < m.num_cells * m.npc; i++)
    cells[i] = newid[m.cells[i]];
  FCM_TRY(ctx, fcm__mesh_create_take(ctx, m.type, used, &coords, m.num_cells, &cells, mesh));
cleanup:
  if (ctx) {
    fcm__free(ctx, r.buf);
    fcm__free(ctx, m.tags);
    fcm__free(ctx, m.coords);
    fcm__free(ctx, m.slots);
    fcm__free(ctx, m.cells);
    fcm__free(ctx, newid);
    fcm__free(ctx, coords);
    fcm__free(ctx, cells);
  }
  return st;
}
