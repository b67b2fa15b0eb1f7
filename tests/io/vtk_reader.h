/* A small reader for the io tests, independent of the library: loads a file, checks
 * that its XML tags balance, collects the tags with their attributes and decodes the
 * raw appended arrays of a VTU (UInt64 headers). Standard C plus POSIX dirent. */
#ifndef FCM_TEST_VTK_READER_H
#define FCM_TEST_VTK_READER_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define VR_MAX_TAGS  256
#define VR_MAX_DEPTH 32

typedef struct vr_tag {
  char name[32];
  char parent[32];   /* enclosing element, "" at the top */
  const char *attrs; /* inside the tag: from after the name to before '>' or '/>' */
  size_t attrs_len;
} vr_tag;

typedef struct vr_doc {
  unsigned char *data;
  size_t size;
  vr_tag tags[VR_MAX_TAGS];
  int num_tags;
  char stack[VR_MAX_DEPTH][32];
  int depth;
  char error[256];
  const unsigned char *bin; /* VTU: first byte after the '_' marker */
} vr_doc;

static inline int vr_load(vr_doc *d, const char *path)
{
  memset(d, 0, sizeof *d);
  FILE *f = fopen(path, "rb");
  if (!f) return snprintf(d->error, sizeof d->error, "cannot open %.200s", path), 0;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  if (n < 0) return fclose(f), 0;
  d->data = malloc((size_t)n + 1);
  d->size = fread(d->data, 1, (size_t)n, f) == (size_t)n ? (size_t)n : 0;
  d->data[n] = 0;
  fclose(f);
  return d->size == (size_t)n;
}

static inline void vr_free(vr_doc *d)
{
  free(d->data);
  d->data = NULL;
}

static inline int vr_is_space(int c)
{
  return c == ' ' || c == '\n' || c == '\r' || c == '\t';
}

static inline int vr_is_name(int c)
{
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == ':' || c == '.';
}

/* Check the attribute list: name="value" pairs separated by white space, no '<' in
 * a value. */
static inline int vr_check_attrs(vr_doc *d, const char *p, const char *end)
{
  while (p < end) {
    if (vr_is_space(*p)) {
      p++;
      continue;
    }
    const char *n0 = p;
    while (p < end && vr_is_name(*p))
      p++;
    if (p == n0 || p >= end || *p != '=' || p + 1 >= end || p[1] != '"')
      return snprintf(d->error, sizeof d->error, "bad attribute near '%.20s'", n0), 0;
    p += 2;
    while (p < end && *p != '"') {
      if (*p == '<') return snprintf(d->error, sizeof d->error, "'<' in attribute value"), 0;
      p++;
    }
    if (p >= end) return snprintf(d->error, sizeof d->error, "unterminated attribute value"), 0;
    p++;
    if (p < end && !vr_is_space(*p))
      return snprintf(d->error, sizeof d->error, "no space after attribute value"), 0;
  }
  return 1;
}

/* Scan [p, end): tags balance against the running stack; text between tags must
 * be white space. Returns 1 when well formed. */
static inline int vr_scan(vr_doc *d, const char *p, const char *end)
{
  while (p < end) {
    if (vr_is_space(*p)) {
      p++;
      continue;
    }
    if (*p != '<') return snprintf(d->error, sizeof d->error, "text outside tags: '%.20s'", p), 0;
    const char *q = memchr(p, '>', (size_t)(end - p));
    if (!q) return snprintf(d->error, sizeof d->error, "unterminated tag"), 0;
    if (p[1] == '?') { /* declaration */
      if (q[-1] != '?') return snprintf(d->error, sizeof d->error, "bad declaration"), 0;
      p = q + 1;
      continue;
    }
    if (p[1] == '/') { /* closing tag */
      char name[32] = "";
      size_t len = (size_t)(q - p - 2);
      if (len == 0 || len >= sizeof name || d->depth == 0)
        return snprintf(d->error, sizeof d->error, "bad closing tag"), 0;
      memcpy(name, p + 2, len);
      if (strcmp(name, d->stack[d->depth - 1]))
        return snprintf(d->error, sizeof d->error, "</%s> closes <%s>", name,
                        d->stack[d->depth - 1]),
               0;
      d->depth--;
      p = q + 1;
      continue;
    }
    const char *n0 = p + 1, *n1 = n0;
    while (n1 < q && vr_is_name(*n1))
      n1++;
    int self_closing = q[-1] == '/';
    const char *a_end = self_closing ? q - 1 : q;
    if (n1 == n0 || (size_t)(n1 - n0) >= 32 || (n1 < a_end && !vr_is_space(*n1)))
      return snprintf(d->error, sizeof d->error, "bad tag name near '%.20s'", p), 0;
    if (!vr_check_attrs(d, n1, a_end)) return 0;
    if (d->num_tags == VR_MAX_TAGS) return snprintf(d->error, sizeof d->error, "too many tags"), 0;
    vr_tag *t = &d->tags[d->num_tags++];
    memset(t, 0, sizeof *t);
    memcpy(t->name, n0, (size_t)(n1 - n0));
    if (d->depth) strcpy(t->parent, d->stack[d->depth - 1]);
    t->attrs = n1;
    t->attrs_len = (size_t)(a_end - n1);
    if (!self_closing) {
      if (d->depth == VR_MAX_DEPTH) return snprintf(d->error, sizeof d->error, "too deep"), 0;
      strcpy(d->stack[d->depth++], t->name);
    }
    p = q + 1;
  }
  return 1;
}

/* Attribute value of a tag, XML escapes decoded; 0 when absent. */
static inline int vr_attr(const vr_tag *t, const char *key, char *out, size_t cap)
{
  const char *p = t->attrs, *end = t->attrs + t->attrs_len;
  size_t klen = strlen(key);
  while (p < end) {
    while (p < end && vr_is_space(*p))
      p++;
    const char *n0 = p;
    while (p < end && *p != '=')
      p++;
    const char *v0 = p + 2, *v1 = v0;
    while (v1 < end && *v1 != '"')
      v1++;
    if ((size_t)(p - n0) == klen && !memcmp(n0, key, klen)) {
      size_t k = 0;
      for (const char *s = v0; s < v1 && k + 1 < cap; s++) {
        static const char *const ent[][2] = {
            {"&amp;", "&"}, {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&apos;", "'"}};
        int hit = 0;
        for (int e = 0; e < 5 && !hit; e++) {
          size_t el = strlen(ent[e][0]);
          if ((size_t)(v1 - s) >= el && !memcmp(s, ent[e][0], el)) {
            out[k++] = ent[e][1][0];
            s += el - 1;
            hit = 1;
          }
        }
        if (!hit) out[k++] = *s;
      }
      out[k] = 0;
      return 1;
    }
    p = v1 + 1;
  }
  return 0;
}

static inline long long vr_attr_ll(const vr_tag *t, const char *key)
{
  char buf[64];
  return vr_attr(t, key, buf, sizeof buf) ? strtoll(buf, NULL, 10) : -1;
}

/* The i-th tag called `name` (with `parent` unless NULL), or NULL. */
static inline const vr_tag *vr_find(const vr_doc *d, const char *name, const char *parent, int i)
{
  for (int k = 0; k < d->num_tags; k++)
    if (!strcmp(d->tags[k].name, name) && (!parent || !strcmp(d->tags[k].parent, parent)))
      if (i-- == 0) return &d->tags[k];
  return NULL;
}

/* A plain XML file (PVD): the whole file balances. */
static inline int vr_parse_xml(vr_doc *d)
{
  if (!vr_scan(d, (const char *)d->data, (const char *)d->data + d->size)) return 0;
  if (d->depth) return snprintf(d->error, sizeof d->error, "<%s> not closed", d->stack[0]), 0;
  return 1;
}

/* A VTU with raw appended data: the header up to '_' balances with VTKFile and
 * AppendedData open; the appended arrays tile [0, end) exactly (each a UInt64
 * byte count then the bytes); after them the trailer closes both tags. */
static inline int vr_parse_vtu(vr_doc *d)
{
  const char *text = (const char *)d->data;
  const char *ad = strstr(text, "<AppendedData");
  if (!ad) return snprintf(d->error, sizeof d->error, "no <AppendedData>"), 0;
  const char *us = strchr(ad, '_');
  if (!us) return snprintf(d->error, sizeof d->error, "no '_' marker"), 0;
  if (!vr_scan(d, text, us)) return 0;
  if (d->depth != 2 || strcmp(d->stack[0], "VTKFile") || strcmp(d->stack[1], "AppendedData"))
    return snprintf(d->error, sizeof d->error, "header leaves %d open tags", d->depth), 0;
  d->bin = (const unsigned char *)us + 1;
  size_t avail = d->size - (size_t)(d->bin - d->data);

  /* Collect offsets, sort, walk. */
  long long offs[VR_MAX_TAGS];
  int n = 0;
  for (int k = 0; k < d->num_tags; k++)
    if (!strcmp(d->tags[k].name, "DataArray")) offs[n++] = vr_attr_ll(&d->tags[k], "offset");
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && offs[j - 1] > offs[j]; j--) {
      long long t = offs[j];
      offs[j] = offs[j - 1];
      offs[j - 1] = t;
    }
  uint64_t pos = 0;
  for (int i = 0; i < n; i++) {
    if (offs[i] < 0 || (uint64_t)offs[i] != pos)
      return snprintf(d->error, sizeof d->error, "array at offset %lld, expected %llu", offs[i],
                      (unsigned long long)pos),
             0;
    uint64_t count;
    if (pos + 8 > avail) return snprintf(d->error, sizeof d->error, "header past the end"), 0;
    memcpy(&count, d->bin + pos, 8);
    if (count > avail - pos - 8)
      return snprintf(d->error, sizeof d->error, "array past the end"), 0;
    pos += 8 + count;
  }
  if (!vr_scan(d, (const char *)d->bin + pos, text + d->size)) return 0;
  if (d->depth) return snprintf(d->error, sizeof d->error, "<%s> not closed", d->stack[0]), 0;
  return 1;
}

/* Locate the appended array of a DataArray tag: its UInt64 count and its bytes. */
static inline const unsigned char *vr_array(const vr_doc *d, const vr_tag *t, uint64_t *bytes)
{
  long long off = vr_attr_ll(t, "offset");
  memcpy(bytes, d->bin + off, 8);
  return d->bin + off + 8;
}

/* The DataArray named `name` inside section `parent` ("PointData", "CellData",
 * "Points", "Cells"), or NULL. Points' array has no name: pass NULL. */
static inline const vr_tag *vr_data_array(const vr_doc *d, const char *parent, const char *name)
{
  char buf[256];
  for (int i = 0;; i++) {
    const vr_tag *t = vr_find(d, "DataArray", parent, i);
    if (!t) return NULL;
    if (!name || (vr_attr(t, "Name", buf, sizeof buf) && !strcmp(buf, name))) return t;
  }
}

/* ---- scratch directories for the io tests ---- */

/* Remove every file in `dir` and the directory itself (one level only). */
static inline void vr_rmdir(const char *dir)
{
  DIR *dp = opendir(dir);
  if (!dp) return;
  struct dirent *e;
  char path[1024];
  while ((e = readdir(dp))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    remove(path);
  }
  closedir(dp);
  rmdir(dir);
}

/* A fresh empty directory. */
static inline int vr_mkdir(const char *dir)
{
  vr_rmdir(dir);
  return mkdir(dir, 0777) == 0;
}

/* Number of entries of `dir` whose name contains `part` (".tmp." for temporaries). */
static inline int vr_count_entries(const char *dir, const char *part)
{
  DIR *dp = opendir(dir);
  if (!dp) return -1;
  int n = 0;
  struct dirent *e;
  while ((e = readdir(dp)))
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strstr(e->d_name, part)) n++;
  closedir(dp);
  return n;
}

/* Whole file into a malloc'ed buffer; size -1 when missing. */
static inline unsigned char *vr_slurp(const char *path, long *size)
{
  vr_doc d;
  if (!vr_load(&d, path)) {
    free(d.data);
    *size = -1;
    return NULL;
  }
  *size = (long)d.size;
  return d.data;
}

#endif
