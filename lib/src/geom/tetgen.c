/* TetGen .node/.ele reader for the embedded geometry: whole-file read, line by line
 * tokenizing with '#' comments, 0- or 1-based consecutive indices, errors "path:line". */
#include "geom/geom_impl.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_TOKENS 64

typedef struct lines {
  const char *path;
  char *buf;  /* whole file, NUL-terminated */
  char *pos;  /* start of the next line */
  size_t len; /* bytes in the file */
  long line;  /* number of the line last returned */
  char *tok[MAX_TOKENS];
  int ntok; /* tokens of the current line; more than MAX_TOKENS are counted, not kept */
} lines;

/* Files above this size are refused before reading (4 GiB: ~200 million points). */
#define TETGEN_MAX_BYTES ((size_t)1 << 32)

static fcm_status read_file(fcm_ctx *ctx, const char *path, lines *L)
{
  fcm_status st = FCM_OK;
  size_t len = 0;
  L->path = path, L->buf = NULL, L->line = 0, L->len = 0;
  FCM_CHECK(path, ctx, FCM_ERR_ARG, "tetgen: file name is NULL");
  FCM_TRY(ctx, fcm__file_read_all(ctx, "tetgen", path, TETGEN_MAX_BYTES, &L->buf, &len));
  L->len = len;
  FCM_CHECK(strlen(L->buf) == len, ctx, FCM_ERR_FORMAT,
            "tetgen: %s contains a NUL byte (binary file?)", path);
  L->pos = L->buf;
cleanup:
  return st;
}

/* Largest count of records of `ntok` tokens the file can hold: each needs at least
 * ntok one-character tokens, ntok - 1 separators and a line break (except the last),
 * so counts announced beyond that are malformed and must not size an allocation. */
static long long max_records(const lines *L, int ntok)
{
  return (long long)((L->len + 1) / (size_t)(2 * ntok));
}

/* Next line with at least one token (comments stripped); 0 at the end of the file. */
static int next_line(lines *L)
{
  while (*L->pos) {
    char *s = L->pos, *e = strchr(s, '\n');
    if (e) {
      *e = '\0';
      L->pos = e + 1;
    } else {
      L->pos = s + strlen(s);
    }
    L->line++;
    char *hash = strchr(s, '#');
    if (hash) *hash = '\0';
    L->ntok = 0;
    while (*s) { /* split at blanks and commas (strtok is not thread safe) */
      while (*s && strchr(" \t\r,", *s))
        *s++ = '\0';
      if (!*s) break;
      if (L->ntok < MAX_TOKENS) L->tok[L->ntok] = s;
      L->ntok++;
      while (*s && !strchr(" \t\r,", *s))
        s++;
    }
    if (L->ntok > 0) return 1;
  }
  return 0;
}

static int parse_ll(const char *t, long long *v)
{
  char *end;
  errno = 0;
  *v = strtoll(t, &end, 10);
  return errno == 0 && end != t && *end == '\0';
}

static int parse_d(const char *t, double *v)
{
  char *end;
  errno = 0;
  *v = strtod(t, &end);
  return errno == 0 && end != t && *end == '\0' && isfinite(*v);
}

/* Integer token k of the current line in [lo, hi]. */
static fcm_status token_int(fcm_ctx *ctx, const lines *L, int k, const char *what, long long lo,
                            long long hi, long long *v)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(k < L->ntok && k < MAX_TOKENS, ctx, FCM_ERR_FORMAT, "%s:%ld: expected %s", L->path,
            L->line, what);
  FCM_CHECK(parse_ll(L->tok[k], v), ctx, FCM_ERR_FORMAT, "%s:%ld: expected %s, got \"%s\"", L->path,
            L->line, what, L->tok[k]);
  FCM_CHECK(*v >= lo && *v <= hi, ctx, FCM_ERR_FORMAT, "%s:%ld: %s = %lld outside [%lld, %lld]",
            L->path, L->line, what, *v, lo, hi);
cleanup:
  return st;
}

fcm_status fcm_geometry_create_from_tetgen(fcm_ctx *ctx, const char *node_path,
                                           const char *ele_path, fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  lines N = {0}, E = {0};
  double *x = NULL;
  fcm_index *cells = NULL;
  long long np = 0, dim = 0, nattr = 0, nmark = 0, nt = 0, npe = 0, tattr = 0, v = 0;
  long long base = 0, tbase = 0;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "tetgen: output pointer is NULL");
  *geom = NULL;
  FCM_CHECK(ctx && node_path && ele_path, ctx, FCM_ERR_ARG,
            "tetgen: NULL argument (ctx, node and ele file names are required)");
  /* .node */
  FCM_TRY(ctx, read_file(ctx, node_path, &N));
  FCM_CHECK(next_line(&N), ctx, FCM_ERR_FORMAT,
            "%s:%ld: expected the header \"count 3 attributes "
            "markers\", got the end of the file",
            node_path, N.line);
  FCM_TRY(ctx, token_int(ctx, &N, 0, "number of points (bounded by the file size)", 0,
                         max_records(&N, 4), &np));
  FCM_TRY(ctx, token_int(ctx, &N, 1, "dimension", 0, 1000, &dim));
  FCM_CHECK(dim == 3, ctx, FCM_ERR_UNSUPPORTED, "%s:%ld: dimension %lld is not supported (need 3)",
            node_path, N.line, dim);
  if (N.ntok > 2) FCM_TRY(ctx, token_int(ctx, &N, 2, "number of attributes", 0, 50, &nattr));
  if (N.ntok > 3) FCM_TRY(ctx, token_int(ctx, &N, 3, "boundary-marker flag", 0, 1, &nmark));
  FCM_CHECK(np > 0, ctx, FCM_ERR_FORMAT, "%s:%ld: the file declares no points", node_path, N.line);
  FCM_ALLOC(ctx, 3 * (size_t)np, x);
  for (long long i = 0; i < np; i++) {
    FCM_CHECK(next_line(&N), ctx, FCM_ERR_FORMAT,
              "%s:%ld: expected point %lld of %lld, got the end of the file", node_path, N.line,
              i + 1, np);
    FCM_CHECK(N.ntok >= 4 && N.ntok <= 4 + nattr + nmark, ctx, FCM_ERR_FORMAT,
              "%s:%ld: expected \"index x y z\" and %lld attribute(s)%s, got %d value(s)",
              node_path, N.line, nattr, nmark ? " and a marker" : "", N.ntok);
    if (i == 0) {
      FCM_TRY(ctx, token_int(ctx, &N, 0, "first point index (0 or 1)", 0, 1, &base));
    } else {
      FCM_TRY(ctx, token_int(ctx, &N, 0, "point index", base + i, base + i, &v));
    }
    for (int d = 0; d < 3; d++) {
      FCM_CHECK(parse_d(N.tok[1 + d], x + 3 * i + d), ctx, FCM_ERR_FORMAT,
                "%s:%ld: expected a finite coordinate, got \"%s\"", node_path, N.line,
                N.tok[1 + d]);
      FCM_CHECK(fabs(x[3 * i + d]) <= FCM__COORD_MAX, ctx, FCM_ERR_FORMAT,
                "%s:%ld: point %lld (%lld-based, as the file numbers them): coordinate %c = %g is "
                "outside " FCM__COORD_RANGE,
                node_path, N.line, base + i, base, "xyz"[d], x[3 * i + d]);
    }
  }
  /* .ele */
  FCM_TRY(ctx, read_file(ctx, ele_path, &E));
  FCM_CHECK(next_line(&E), ctx, FCM_ERR_FORMAT,
            "%s:%ld: expected the header \"count 4 attributes\", got the end of the file", ele_path,
            E.line);
  FCM_TRY(ctx, token_int(ctx, &E, 0, "number of tetrahedra (bounded by the file size)", 0,
                         max_records(&E, 5), &nt));
  FCM_TRY(ctx, token_int(ctx, &E, 1, "nodes per tetrahedron", 0, 1000, &npe));
  FCM_CHECK(npe != 10, ctx, FCM_ERR_UNSUPPORTED,
            "%s:%ld: 10-node tetrahedra are not supported (embedded cells must be straight "
            "4-node tetrahedra)",
            ele_path, E.line);
  FCM_CHECK(npe == 4, ctx, FCM_ERR_FORMAT, "%s:%ld: nodes per tetrahedron = %lld (need 4)",
            ele_path, E.line, npe);
  if (E.ntok > 2) FCM_TRY(ctx, token_int(ctx, &E, 2, "number of attributes", 0, 50, &tattr));
  FCM_ALLOC(ctx, 4 * (size_t)nt, cells);
  for (long long t = 0; t < nt; t++) {
    FCM_CHECK(next_line(&E), ctx, FCM_ERR_FORMAT,
              "%s:%ld: expected tetrahedron %lld of %lld, got the end of the file", ele_path,
              E.line, t + 1, nt);
    FCM_CHECK(E.ntok >= 5 && E.ntok <= 5 + tattr, ctx, FCM_ERR_FORMAT,
              "%s:%ld: expected \"index n0 n1 n2 n3\" and %lld attribute(s), got %d value(s)",
              ele_path, E.line, tattr, E.ntok);
    if (t == 0) {
      FCM_TRY(ctx, token_int(ctx, &E, 0, "first tetrahedron index (0 or 1)", 0, 1, &tbase));
    } else {
      FCM_TRY(ctx, token_int(ctx, &E, 0, "tetrahedron index", tbase + t, tbase + t, &v));
    }
    for (int a = 0; a < 4; a++) {
      FCM_TRY(ctx, token_int(ctx, &E, 1 + a, "node index", base, base + np - 1, &v));
      cells[4 * t + a] = (fcm_index)(v - base);
    }
  }
  FCM_TRY(ctx, fcm__geom_create_take(ctx, "tetgen", FCM_ELEMENT_TET4, (fcm_index)np, &x,
                                     (fcm_index)nt, &cells, 0, geom));
cleanup:
  fcm__free(ctx, N.buf);
  fcm__free(ctx, E.buf);
  fcm__free(ctx, x);
  fcm__free(ctx, cells);
  return st;
}
