/* Readers of triangle surface files: OBJ, OFF, STL (ASCII and binary) and PLY (ascii and
 * binary_little_endian). Text is scanned in place (bounded by the file length, not by a
 * NUL) with line numbers for messages; binary data is decoded little-endian with byte
 * offsets for messages. Every count a header announces is bounded by the bytes left. */
#include "geom/surface_impl.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- text scanning ---- */

typedef struct text {
  fcm_ctx *ctx;
  const char *path;
  const char *p, *end;
  long line;     /* line of the current position, from 1 */
  char cmt;      /* comment character, '\0' for none */
  char tok[128]; /* the token last read (truncated beyond 127 bytes) */
} text;

static void text_init(text *T, fcm__sbuild *B, const char *buf, size_t len, char cmt)
{
  T->ctx = B->ctx, T->path = B->path, T->p = buf, T->end = buf + len, T->line = 1, T->cmt = cmt;
  T->tok[0] = '\0';
}

static int is_blank(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Next token of the current line into T->tok; 0 when the line (or the file) ends. */
static int tok_line(text *T)
{
  while (T->p < T->end && is_blank(*T->p))
    T->p++;
  if (T->p >= T->end || *T->p == '\n') return 0;
  if (T->cmt && *T->p == T->cmt) {
    while (T->p < T->end && *T->p != '\n')
      T->p++;
    return 0;
  }
  size_t n = 0;
  while (T->p < T->end && *T->p != '\n' && !is_blank(*T->p)) {
    if (n + 1 < sizeof T->tok) T->tok[n++] = *T->p;
    T->p++;
  }
  T->tok[n] = '\0';
  return 1;
}

/* Move to the start of the next line; 0 at the end of the file. */
static int next_line(text *T)
{
  while (T->p < T->end && *T->p != '\n')
    T->p++;
  if (T->p >= T->end) return 0;
  T->p++;
  T->line++;
  return 1;
}

/* Next token, across lines; 0 at the end of the file. */
static int tok_any(text *T)
{
  for (;;) {
    if (tok_line(T)) return 1;
    if (!next_line(T)) return 0;
  }
}

static int parse_num(const char *t, double *v)
{
  char *end;
  errno = 0;
  *v = strtod(t, &end);
  return end != t && *end == '\0' && isfinite(*v);
}

static int parse_int(const char *t, long long *v)
{
  char *end;
  errno = 0;
  *v = strtoll(t, &end, 10);
  return errno == 0 && end != t && *end == '\0';
}

/* Token as a finite number (`what` names it in the message). */
static fcm_status text_num(text *T, int any, const char *what, double *v)
{
  fcm_status st = FCM_OK;
  int got = any ? tok_any(T) : tok_line(T);
  FCM_CHECK(got, T->ctx, FCM_ERR_FORMAT, "surface: %s:%ld: expected %s, got the end of the %s",
            T->path, T->line, what, any ? "file" : "line");
  FCM_CHECK(parse_num(T->tok, v), T->ctx, FCM_ERR_FORMAT,
            "surface: %s:%ld: expected %s (a finite number), got \"%s\"", T->path, T->line, what,
            T->tok);
cleanup:
  return st;
}

/* Token (across lines) as an integer in [lo, hi]. */
static fcm_status text_int(text *T, const char *what, long long lo, long long hi, long long *v)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(tok_any(T), T->ctx, FCM_ERR_FORMAT,
            "surface: %s:%ld: expected %s, got the end of the file", T->path, T->line, what);
  FCM_CHECK(parse_int(T->tok, v), T->ctx, FCM_ERR_FORMAT,
            "surface: %s:%ld: expected %s (an integer), got \"%s\"", T->path, T->line, what,
            T->tok);
  FCM_CHECK(*v >= lo && *v <= hi, T->ctx, FCM_ERR_FORMAT,
            "surface: %s:%ld: %s = %lld outside [%lld, %lld]", T->path, T->line, what, *v, lo, hi);
cleanup:
  return st;
}

/* Token (across lines) that must equal `word`. */
static fcm_status text_word(text *T, const char *word)
{
  fcm_status st = FCM_OK;
  int got = tok_any(T);
  FCM_CHECK(got && strcmp(T->tok, word) == 0, T->ctx, FCM_ERR_FORMAT,
            "surface: %s:%ld: expected \"%s\", got %s%s%s", T->path, T->line, word,
            got ? "\"" : "the end of the file", got ? T->tok : "", got ? "\"" : "");
cleanup:
  return st;
}

/* ---- OBJ ---- */

fcm_status fcm__surface_read_obj(fcm__sbuild *B, char *buf, size_t len)
{
  fcm_status st = FCM_OK;
  text T;
  text_init(&T, B, buf, len, '#');
  B->base = 1; /* OBJ faces number vertices from 1 */
  do {
    if (!tok_line(&T)) continue;
    if (strcmp(T.tok, "v") == 0) {
      double p[3];
      for (int k = 0; k < 3; k++)
        FCM_TRY(B->ctx, text_num(&T, 0, "a vertex coordinate after \"v\"", &p[k]));
      FCM_TRY(B->ctx, fcm__sbuild_vertex(B, p));
    } else if (strcmp(T.tok, "f") == 0) {
      fcm_index first = -1, prev = -1;
      int k = 0;
      while (tok_line(&T)) {
        char *end;
        errno = 0;
        long long v = strtoll(T.tok, &end, 10);
        FCM_CHECK(errno == 0 && end != T.tok && (*end == '\0' || *end == '/'), B->ctx,
                  FCM_ERR_FORMAT,
                  "surface: %s:%ld: expected a vertex index after \"f\", got \"%s\"", T.path,
                  T.line, T.tok);
        long long nv = (long long)B->nv, id = v > 0 ? v - 1 : nv + v;
        FCM_CHECK(v != 0 && id >= 0 && id < nv, B->ctx, FCM_ERR_FORMAT,
                  "surface: %s:%ld: vertex index %lld outside [1, %lld] (or [-%lld, -1] relative)",
                  T.path, T.line, v, nv, nv);
        if (k == 0) first = (fcm_index)id;
        if (k >= 2) FCM_TRY(B->ctx, fcm__sbuild_triangle(B, first, prev, (fcm_index)id));
        prev = (fcm_index)id;
        k++;
      }
      FCM_CHECK(k >= 3, B->ctx, FCM_ERR_FORMAT,
                "surface: %s:%ld: face with %d vertices (expected at least 3)", T.path, T.line, k);
    } /* vt, vn, g, o, s, usemtl, mtllib, l, ...: ignored */
  } while (next_line(&T));
cleanup:
  return st;
}

/* ---- OFF ---- */

fcm_status fcm__surface_read_off(fcm__sbuild *B, char *buf, size_t len)
{
  fcm_status st = FCM_OK;
  text T;
  long long nv = 0, nf = 0, ne = 0, k = 0, id = 0;
  text_init(&T, B, buf, len, '#');
  int got = tok_any(&T);
  const char *h = T.tok; /* OFF, with the optional prefixes ST, C and N (per-vertex data
                            after x y z, skipped) */
  if (strncmp(h, "ST", 2) == 0) h += 2;
  if (*h == 'C') h++;
  if (*h == 'N') h++;
  FCM_CHECK(
      got && strcmp(h, "OFF") == 0, B->ctx, FCM_ERR_FORMAT,
      "surface: %s:%ld: expected the header \"OFF\" (or COFF, NOFF, CNOFF, STOFF), got %s%s%s",
      T.path, T.line, got ? "\"" : "the end of the file", got ? T.tok : "", got ? "\"" : "");
  /* a vertex needs at least "x y z\n" (6 bytes), a face "3 a b c\n" (8 bytes) */
  FCM_TRY(B->ctx, text_int(&T, "the vertex count (bounded by the file size)", 0,
                           (long long)(len / 6), &nv));
  FCM_TRY(B->ctx,
          text_int(&T, "the face count (bounded by the file size)", 0, (long long)(len / 8), &nf));
  FCM_TRY(B->ctx, text_int(&T, "the edge count", 0, (long long)len, &ne));
  next_line(&T);
  for (long long i = 0; i < nv; i++) {
    double p[3];
    for (int c = 0; c < 3; c++)
      FCM_TRY(B->ctx, text_num(&T, 1, "a vertex coordinate", &p[c]));
    FCM_TRY(B->ctx, fcm__sbuild_vertex(B, p));
    next_line(&T); /* colours and the like */
  }
  for (long long i = 0; i < nf; i++) {
    fcm_index first = -1, prev = -1;
    FCM_TRY(B->ctx,
            text_int(&T, "the vertex count of a face (at least 3)", 3, (long long)(len / 2), &k));
    for (long long j = 0; j < k; j++) {
      FCM_TRY(B->ctx, text_int(&T, "a vertex index of a face", 0, nv - 1, &id));
      if (j == 0) first = (fcm_index)id;
      if (j >= 2) FCM_TRY(B->ctx, fcm__sbuild_triangle(B, first, prev, (fcm_index)id));
      prev = (fcm_index)id;
    }
    next_line(&T);
  }
cleanup:
  return st;
}

/* ---- STL ---- */

static uint32_t le32(const unsigned char *b)
{
  return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static float lef32(const unsigned char *b)
{
  uint32_t u = le32(b);
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

static fcm_status stl_ascii(fcm__sbuild *B, char *buf, size_t len)
{
  fcm_status st = FCM_OK;
  text T;
  text_init(&T, B, buf, len, '\0');
  FCM_TRY(B->ctx, text_word(&T, "solid"));
  next_line(&T); /* the solid's name */
  for (;;) {
    FCM_CHECK(tok_any(&T), B->ctx, FCM_ERR_FORMAT,
              "surface: %s:%ld: expected \"facet\" or \"endsolid\", got the end of the file",
              T.path, T.line);
    if (strcmp(T.tok, "endsolid") == 0) { /* another solid may follow */
      next_line(&T);
      if (!tok_any(&T)) break;
      FCM_CHECK(strcmp(T.tok, "solid") == 0, B->ctx, FCM_ERR_FORMAT,
                "surface: %s:%ld: expected \"solid\" or the end of the file, got \"%s\"", T.path,
                T.line, T.tok);
      next_line(&T);
      continue;
    }
    FCM_CHECK(strcmp(T.tok, "facet") == 0, B->ctx, FCM_ERR_FORMAT,
              "surface: %s:%ld: expected \"facet\" or \"endsolid\", got \"%s\"", T.path, T.line,
              T.tok);
    FCM_TRY(B->ctx, text_word(&T, "normal"));
    for (int c = 0; c < 3; c++) /* the normal is recomputed by users: any token */
      FCM_CHECK(tok_any(&T), B->ctx, FCM_ERR_FORMAT,
                "surface: %s:%ld: expected a normal component, got the end of the file", T.path,
                T.line);
    FCM_TRY(B->ctx, text_word(&T, "outer"));
    FCM_TRY(B->ctx, text_word(&T, "loop"));
    for (int v = 0; v < 3; v++) {
      double p[3];
      FCM_TRY(B->ctx, text_word(&T, "vertex"));
      for (int c = 0; c < 3; c++)
        FCM_TRY(B->ctx, text_num(&T, 1, "a vertex coordinate", &p[c]));
      FCM_TRY(B->ctx, fcm__sbuild_vertex(B, p));
    }
    FCM_TRY(B->ctx, text_word(&T, "endloop"));
    FCM_TRY(B->ctx, text_word(&T, "endfacet"));
    fcm_index n = (fcm_index)B->nv;
    FCM_TRY(B->ctx, fcm__sbuild_triangle(B, n - 3, n - 2, n - 1));
  }
cleanup:
  return st;
}

static fcm_status stl_binary(fcm__sbuild *B, const unsigned char *b)
{
  fcm_status st = FCM_OK;
  uint32_t n = le32(b + 80);
  for (uint32_t i = 0; i < n; i++) {
    size_t off = 84 + 50 * (size_t)i + 12;
    for (int v = 0; v < 3; v++) {
      double p[3];
      for (int c = 0; c < 3; c++) {
        size_t at = off + 12 * (size_t)v + 4 * (size_t)c;
        p[c] = lef32(b + at);
        FCM_CHECK(isfinite(p[c]), B->ctx, FCM_ERR_FORMAT,
                  "surface: %s: byte %zu: expected a finite vertex coordinate (triangle %u), "
                  "got %g",
                  B->path, at, i, p[c]);
      }
      FCM_TRY(B->ctx, fcm__sbuild_vertex(B, p));
    }
    fcm_index m = (fcm_index)B->nv;
    FCM_TRY(B->ctx, fcm__sbuild_triangle(B, m - 3, m - 2, m - 1));
  }
cleanup:
  return st;
}

fcm_status fcm__surface_read_stl(fcm__sbuild *B, char *buf, size_t len)
{
  fcm_status st = FCM_OK;
  B->soup = 1;
  const unsigned char *b = (const unsigned char *)buf;
  size_t lead = 0;
  while (lead < len && (is_blank(buf[lead]) || buf[lead] == '\n'))
    lead++;
  int solid = len - lead >= 5 && memcmp(buf + lead, "solid", 5) == 0;
  if (len >= 84 && 84 + 50 * (unsigned long long)le32(b + 80) == len) {
    FCM_TRY(B->ctx, stl_binary(B, b));
  } else if (solid && (len < 84 || !memchr(buf, '\0', len))) { /* ASCII has no NUL byte */
    FCM_TRY(B->ctx, stl_ascii(B, buf, len));
  } else {
    FCM_CHECK(len >= 84, B->ctx, FCM_ERR_FORMAT,
              "surface: %s: byte 0: expected an ASCII STL (\"solid\") or a binary STL (84-byte "
              "header), got %zu bytes",
              B->path, len);
    FCM_CHECK(0, B->ctx, FCM_ERR_FORMAT,
              "surface: %s: byte 80: binary STL declares %lu triangles, which need %llu bytes, "
              "but the file has %zu (truncated?)",
              B->path, (unsigned long)le32(b + 80), 84 + 50 * (unsigned long long)le32(b + 80),
              len);
  }
  FCM_TRY(B->ctx, fcm__sbuild_merge(B));
cleanup:
  return st;
}

/* ---- PLY ---- */

enum { PLY_MAXE = 16, PLY_MAXP = 64 };
enum { ROLE_OTHER, ROLE_X, ROLE_Y, ROLE_Z, ROLE_INDICES };

static const struct {
  const char *name, *alias;
  int size, is_int, is_signed;
} ply_types[] = {{"char", "int8", 1, 1, 1},     {"uchar", "uint8", 1, 1, 0},
                 {"short", "int16", 2, 1, 1},   {"ushort", "uint16", 2, 1, 0},
                 {"int", "int32", 4, 1, 1},     {"uint", "uint32", 4, 1, 0},
                 {"float", "float32", 4, 0, 1}, {"double", "float64", 8, 0, 1}};

typedef struct plyprop {
  int type, ltype; /* ltype: count type of a list, -1 for a scalar */
  int role;
} plyprop;

typedef struct plyel {
  char name[32];
  long long count;
  int np, kind; /* kind: 1 vertex, 2 face, 0 other */
  plyprop p[PLY_MAXP];
} plyel;

typedef struct ply {
  text T;
  int binary;
  const unsigned char *b;
  size_t off, len;
} ply;

static int ply_type(const char *t)
{
  for (int i = 0; i < (int)(sizeof ply_types / sizeof ply_types[0]); i++)
    if (strcmp(t, ply_types[i].name) == 0 || strcmp(t, ply_types[i].alias) == 0) return i;
  return -1;
}

/* One value of `type`; `what` names it in messages. */
static fcm_status ply_value(fcm__sbuild *B, ply *P, int type, int finite, const char *what,
                            double *v)
{
  fcm_status st = FCM_OK;
  if (P->binary) {
    int sz = ply_types[type].size;
    const unsigned char *q = P->b + P->off;
    FCM_CHECK(P->len - P->off >= (size_t)sz, B->ctx, FCM_ERR_FORMAT,
              "surface: %s: byte %zu: expected %s (%s), got the end of the file", B->path, P->off,
              what, ply_types[type].name);
    switch (type) {
    case 0:
      *v = (double)(int8_t)q[0];
      break;
    case 1:
      *v = (double)q[0];
      break;
    case 2:
      *v = (double)(int16_t)(uint16_t)(q[0] | q[1] << 8);
      break;
    case 3:
      *v = (double)(uint16_t)(q[0] | q[1] << 8);
      break;
    case 4:
      *v = (double)(int32_t)le32(q);
      break;
    case 5:
      *v = (double)le32(q);
      break;
    case 6:
      *v = (double)lef32(q);
      break;
    default: {
      uint64_t u = (uint64_t)le32(q) | (uint64_t)le32(q + 4) << 32;
      memcpy(v, &u, sizeof *v);
    }
    }
    FCM_CHECK(!finite || isfinite(*v), B->ctx, FCM_ERR_FORMAT,
              "surface: %s: byte %zu: expected %s (a finite %s), got %g", B->path, P->off, what,
              ply_types[type].name, *v);
    P->off += (size_t)sz;
  } else {
    char *end;
    FCM_CHECK(tok_any(&P->T), B->ctx, FCM_ERR_FORMAT,
              "surface: %s:%ld: expected %s, got the end of the file", B->path, P->T.line, what);
    *v = strtod(P->T.tok, &end);
    FCM_CHECK(end != P->T.tok && *end == '\0' && (!finite || isfinite(*v)), B->ctx, FCM_ERR_FORMAT,
              "surface: %s:%ld: expected %s (a %snumber), got \"%s\"", B->path, P->T.line, what,
              finite ? "finite " : "", P->T.tok);
    FCM_CHECK(!ply_types[type].is_int || *v == floor(*v), B->ctx, FCM_ERR_FORMAT,
              "surface: %s:%ld: expected %s (an integer, %s), got \"%s\"", B->path, P->T.line, what,
              ply_types[type].name, P->T.tok);
  }
cleanup:
  return st;
}

/* Where the next value is, for messages: "path:line" (ascii) or "path: byte N" (binary). */
static void ply_where(const fcm__sbuild *B, const ply *P, char *s, size_t n)
{
  if (P->binary)
    snprintf(s, n, "%s: byte %zu", B->path, P->off);
  else { /* the line of the next token */
    long line = P->T.line;
    for (const char *c = P->T.p; c < P->T.end && (is_blank(*c) || *c == '\n'); c++)
      line += *c == '\n';
    snprintf(s, n, "%s:%ld", B->path, line);
  }
}

static fcm_status ply_header(fcm__sbuild *B, ply *P, plyel *E, int *ne)
{
  fcm_status st = FCM_OK;
  text *T = &P->T;
  int fmt = 0;
  *ne = 0;
  FCM_CHECK(tok_line(T) && strcmp(T->tok, "ply") == 0, B->ctx, FCM_ERR_FORMAT,
            "surface: %s:1: expected \"ply\"", B->path);
  for (;;) {
    FCM_CHECK(next_line(T), B->ctx, FCM_ERR_FORMAT,
              "surface: %s:%ld: expected \"end_header\", got the end of the file", B->path,
              T->line);
    if (!tok_line(T)) continue;
    if (strcmp(T->tok, "end_header") == 0) break;
    if (strcmp(T->tok, "comment") == 0 || strcmp(T->tok, "obj_info") == 0) continue;
    if (strcmp(T->tok, "format") == 0) {
      int got = tok_line(T);
      if (got && strcmp(T->tok, "ascii") == 0)
        fmt = 1;
      else if (got && strcmp(T->tok, "binary_little_endian") == 0)
        fmt = 2;
      else
        FCM_CHECK(!(got && strcmp(T->tok, "binary_big_endian") == 0), B->ctx, FCM_ERR_UNSUPPORTED,
                  "surface: %s:%ld: binary_big_endian PLY is not supported (ascii and "
                  "binary_little_endian are)",
                  B->path, T->line);
      FCM_CHECK(fmt, B->ctx, FCM_ERR_FORMAT,
                "surface: %s:%ld: expected the format ascii or binary_little_endian", B->path,
                T->line);
    } else if (strcmp(T->tok, "element") == 0) {
      FCM_CHECK(*ne < PLY_MAXE, B->ctx, FCM_ERR_FORMAT, "surface: %s:%ld: more than %d elements",
                B->path, T->line, PLY_MAXE);
      plyel *e = &E[(*ne)++];
      memset(e, 0, sizeof *e);
      FCM_CHECK(tok_line(T), B->ctx, FCM_ERR_FORMAT, "surface: %s:%ld: expected an element name",
                B->path, T->line);
      snprintf(e->name, sizeof e->name, "%.31s", T->tok);
      e->kind = strcmp(T->tok, "vertex") == 0 ? 1 : strcmp(T->tok, "face") == 0 ? 2 : 0;
      FCM_CHECK(tok_line(T) && parse_int(T->tok, &e->count) && e->count >= 0, B->ctx,
                FCM_ERR_FORMAT, "surface: %s:%ld: expected the count of element %s (>= 0)", B->path,
                T->line, e->name);
    } else if (strcmp(T->tok, "property") == 0) {
      FCM_CHECK(*ne > 0, B->ctx, FCM_ERR_FORMAT, "surface: %s:%ld: property before any element",
                B->path, T->line);
      plyel *e = &E[*ne - 1];
      FCM_CHECK(e->np < PLY_MAXP, B->ctx, FCM_ERR_FORMAT,
                "surface: %s:%ld: more than %d properties in element %s", B->path, T->line,
                PLY_MAXP, e->name);
      plyprop *p = &e->p[e->np++];
      p->ltype = -1;
      int got = tok_line(T);
      if (got && strcmp(T->tok, "list") == 0) {
        got = tok_line(T);
        p->ltype = got ? ply_type(T->tok) : -1;
        FCM_CHECK(p->ltype >= 0 && ply_types[p->ltype].is_int, B->ctx, FCM_ERR_FORMAT,
                  "surface: %s:%ld: expected an integer list count type (uchar, int, ...)", B->path,
                  T->line);
        got = tok_line(T);
      }
      p->type = got ? ply_type(T->tok) : -1;
      FCM_CHECK(p->type >= 0, B->ctx, FCM_ERR_FORMAT,
                "surface: %s:%ld: expected a property type (char, uchar, short, ushort, int, "
                "uint, float, double)",
                B->path, T->line);
      FCM_CHECK(tok_line(T), B->ctx, FCM_ERR_FORMAT, "surface: %s:%ld: expected a property name",
                B->path, T->line);
      if (e->kind == 1 && p->ltype < 0 && T->tok[1] == '\0' && T->tok[0] >= 'x' && T->tok[0] <= 'z')
        p->role = ROLE_X + (T->tok[0] - 'x');
      if (e->kind == 2 && p->ltype >= 0 &&
          (strcmp(T->tok, "vertex_indices") == 0 || strcmp(T->tok, "vertex_index") == 0)) {
        FCM_CHECK(ply_types[p->type].is_int, B->ctx, FCM_ERR_FORMAT,
                  "surface: %s:%ld: vertex indices must have an integer type", B->path, T->line);
        p->role = ROLE_INDICES;
      }
    } else {
      FCM_CHECK(0, B->ctx, FCM_ERR_FORMAT,
                "surface: %s:%ld: expected a PLY header keyword (format, element, property, "
                "comment, end_header), got \"%s\"",
                B->path, T->line, T->tok);
    }
  }
  FCM_CHECK(fmt, B->ctx, FCM_ERR_FORMAT, "surface: %s: the header has no format line", B->path);
  P->binary = fmt == 2;
  next_line(T);
  P->off = (size_t)(T->p - (const char *)P->b);
cleanup:
  return st;
}

fcm_status fcm__surface_read_ply(fcm__sbuild *B, char *buf, size_t len)
{
  fcm_status st = FCM_OK;
  plyel *E = NULL;
  int ne = 0;
  long long nv = -1;
  char where[1100];
  ply P = {.b = (const unsigned char *)buf, .len = len};
  text_init(&P.T, B, buf, len, '\0');
  FCM_ALLOC(B->ctx, PLY_MAXE, E);
  FCM_TRY(B->ctx, ply_header(B, &P, E, &ne));
  for (int i = 0; i < ne; i++) {
    int roles = 0, lists = 0;
    for (int j = 0; j < E[i].np; j++)
      roles |= 1 << E[i].p[j].role, lists += E[i].p[j].role == ROLE_INDICES;
    if (E[i].kind == 1) {
      FCM_CHECK((roles & 14) == 14, B->ctx, FCM_ERR_FORMAT,
                "surface: %s: the vertex element lacks a scalar x, y or z property", B->path);
      nv = E[i].count;
    }
    if (E[i].kind == 2)
      FCM_CHECK(lists == 1, B->ctx, FCM_ERR_FORMAT,
                "surface: %s: the face element needs one list property vertex_indices", B->path);
  }
  FCM_CHECK(nv >= 0, B->ctx, FCM_ERR_FORMAT, "surface: %s: the header declares no vertex element",
            B->path);
  for (int i = 0; i < ne; i++) {
    plyel *e = &E[i];
    size_t rec = 0, left = len - P.off; /* smallest record: lists of 0 items */
    for (int j = 0; j < e->np; j++)
      rec +=
          P.binary ? (size_t)ply_types[e->p[j].ltype >= 0 ? e->p[j].ltype : e->p[j].type].size : 2;
    ply_where(B, &P, where, sizeof where);
    FCM_CHECK(rec > 0 && (unsigned long long)e->count <= left / rec, B->ctx, FCM_ERR_FORMAT,
              "surface: %s: element %s declares %lld records of at least %zu bytes, but "
              "%zu bytes are left",
              where, e->name, e->count, rec, left);
    for (long long r = 0; r < e->count; r++) {
      double p[3] = {0, 0, 0};
      for (int j = 0; j < e->np; j++) {
        const plyprop *q = &e->p[j];
        double v;
        if (q->ltype < 0) {
          int coord = q->role >= ROLE_X && q->role <= ROLE_Z;
          FCM_TRY(B->ctx, ply_value(B, &P, q->type, coord,
                                    coord ? "a vertex coordinate" : "a property value", &v));
          if (coord) p[q->role - ROLE_X] = v;
          continue;
        }
        double c;
        ply_where(B, &P, where, sizeof where);
        FCM_TRY(B->ctx, ply_value(B, &P, q->ltype, 1, "a list count", &c));
        FCM_CHECK(c >= 0 && (q->role != ROLE_INDICES || c >= 3), B->ctx, FCM_ERR_FORMAT,
                  "surface: %s: record %lld of element %s has a list of %g items (expected %s)",
                  where, r, e->name, c,
                  q->role == ROLE_INDICES ? "at least 3 vertex indices" : ">= 0");
        fcm_index first = -1, prev = -1;
        for (double k = 0; k < c; k++) {
          ply_where(B, &P, where, sizeof where);
          FCM_TRY(B->ctx, ply_value(B, &P, q->type, q->role == ROLE_INDICES, "a list item", &v));
          if (q->role != ROLE_INDICES) continue;
          FCM_CHECK(v >= 0 && v < (double)nv, B->ctx, FCM_ERR_FORMAT,
                    "surface: %s: vertex index %g outside [0, %lld)", where, v, nv);
          if (k == 0) first = (fcm_index)v;
          if (k >= 2) FCM_TRY(B->ctx, fcm__sbuild_triangle(B, first, prev, (fcm_index)v));
          prev = (fcm_index)v;
        }
      }
      if (e->kind == 1) FCM_TRY(B->ctx, fcm__sbuild_vertex(B, p));
    }
  }
cleanup:
  fcm__free(B->ctx, E);
  return st;
}
