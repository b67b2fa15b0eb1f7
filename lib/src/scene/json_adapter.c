/* The cJSON adapter: the only file that includes cJSON. It parses a text into a tree
 * (reporting the byte offset of a syntax error) and exposes read-only accessors. */
#include "scene/scene_impl.h"

#include <cJSON.h>
#include <stdlib.h>
#include <string.h>

/* cJSON's global hooks are left alone: the tree is allocated with malloc. The error
 * position comes from return_parse_end, not from the global cJSON_GetErrorPtr(). */
fcm__json *fcm__json_parse(const char *text, size_t length, size_t *error_offset)
{
  const char *end = NULL;
  cJSON *root = cJSON_ParseWithLengthOpts(text, length + 1, &end, 1);
  if (!root) {
    *error_offset = (end && end >= text) ? (size_t)(end - text) : 0;
    if (*error_offset > length) *error_offset = length;
  }
  return (fcm__json *)root;
}

void fcm__json_delete(fcm__json *root)
{
  cJSON_Delete((cJSON *)root);
}

fcm__json_kind fcm__json_get_kind(const fcm__json *node)
{
  const cJSON *j = (const cJSON *)node;
  if (!j) return FCM__JSON_INVALID;
  if (cJSON_IsNull(j)) return FCM__JSON_NULL;
  if (cJSON_IsBool(j)) return FCM__JSON_BOOL;
  if (cJSON_IsNumber(j)) return FCM__JSON_NUMBER;
  if (cJSON_IsString(j)) return FCM__JSON_STRING;
  if (cJSON_IsArray(j)) return FCM__JSON_ARRAY;
  if (cJSON_IsObject(j)) return FCM__JSON_OBJECT;
  return FCM__JSON_INVALID;
}

const char *fcm__json_key(const fcm__json *node)
{
  return node ? ((const cJSON *)node)->string : NULL;
}

double fcm__json_number(const fcm__json *node)
{
  return ((const cJSON *)node)->valuedouble;
}

int fcm__json_bool(const fcm__json *node)
{
  return cJSON_IsTrue((const cJSON *)node) ? 1 : 0;
}

const char *fcm__json_string(const fcm__json *node)
{
  return ((const cJSON *)node)->valuestring;
}

const fcm__json *fcm__json_child(const fcm__json *node)
{
  return node ? (const fcm__json *)((const cJSON *)node)->child : NULL;
}

const fcm__json *fcm__json_next(const fcm__json *node)
{
  return node ? (const fcm__json *)((const cJSON *)node)->next : NULL;
}

int fcm__json_size(const fcm__json *node)
{
  return cJSON_GetArraySize((const cJSON *)node);
}

const fcm__json *fcm__json_member(const fcm__json *object, const char *key)
{
  return (const fcm__json *)cJSON_GetObjectItemCaseSensitive((const cJSON *)object, key);
}

/* ---------------------------------------------------------------- the normalized tree */

const fcm__json *fcm__json_empty_object(void)
{
  static cJSON empty = {.type = cJSON_Object};
  return (const fcm__json *)&empty;
}

fcm__json *fcm__json_new_object(void)
{
  return (fcm__json *)cJSON_CreateObject();
}

/* The next component of a path ("a.b[2].c") at *s: a key (into key, `index` -1) or an index
 * ([i]: index i); *s moves past it and its '.'. 0 on a malformed index. */
static int next_component(const char **s, char key[128], long *index)
{
  const char *p = *s;
  size_t n = 0;
  *index = -1;
  key[0] = '\0';
  if (*p == '[') {
    char *end = NULL;
    *index = strtol(p + 1, &end, 10);
    if (!end || *end != ']' || *index < 0) return 0;
    p = end + 1;
  } else {
    while (*p && *p != '.' && *p != '[' && n < 127)
      key[n++] = *p++;
    key[n] = '\0';
  }
  if (*p == '.') p++;
  *s = p;
  return 1;
}

/* Put `value` (taken over; NULL: an allocation failed) at `path` ("a.b[2].c") under the object
 * `root`, creating the objects (or, before an index, arrays) on the way; an existing value there
 * is replaced, or kept when `keep` is set. 0 when it could not be placed. */
static int put(cJSON *root, const char *path, cJSON *value, int keep)
{
  cJSON *cur = root;
  const char *s = path;
  if (!value) return 0;
  while (cur && *s) {
    char key[128];
    long index = -1;
    if (!next_component(&s, key, &index)) break;
    const int last = *s == '\0', next_index = *s == '[';
    cJSON *next = NULL;
    if (index >= 0) {
      if (!cJSON_IsArray(cur)) break;
      while (cJSON_GetArraySize(cur) <= index) {
        cJSON *o = cJSON_CreateObject();
        if (!o || !cJSON_AddItemToArray(cur, o)) {
          cJSON_Delete(o);
          cur = NULL;
          break;
        }
      }
      if (!cur) break;
      if (last) {
        if (keep || !cJSON_ReplaceItemInArray(cur, (int)index, value)) break;
        return 1;
      }
      next = cJSON_GetArrayItem(cur, (int)index);
    } else {
      if (!cJSON_IsObject(cur)) break;
      next = cJSON_GetObjectItemCaseSensitive(cur, key);
      if (last) {
        if (next && keep) break;
        if (next ? !cJSON_ReplaceItemInObjectCaseSensitive(cur, key, value)
                 : !cJSON_AddItemToObject(cur, key, value))
          break;
        return 1;
      }
      if (!next) {
        next = next_index ? cJSON_CreateArray() : cJSON_CreateObject();
        if (!next || !cJSON_AddItemToObject(cur, key, next)) {
          cJSON_Delete(next);
          break;
        }
      }
    }
    cur = next;
  }
  cJSON_Delete(value);
  return keep; /* kept: what was there stays, which is not a failure */
}

void fcm__json_remove_path(fcm__json *root, const char *path)
{
  cJSON *cur = (cJSON *)root;
  const char *s = path;
  while (cur && *s) {
    char key[128];
    long index = -1;
    if (!next_component(&s, key, &index)) return;
    if (*s == '\0') {
      if (index >= 0)
        cJSON_DeleteItemFromArray(cur, (int)index);
      else
        cJSON_DeleteItemFromObjectCaseSensitive(cur, key);
      return;
    }
    cur = index >= 0 ? cJSON_GetArrayItem(cur, (int)index)
                     : cJSON_GetObjectItemCaseSensitive(cur, key);
  }
}

int fcm__json_put_copy(fcm__json *root, const char *path, const fcm__json *value)
{
  return put((cJSON *)root, path, cJSON_Duplicate((const cJSON *)value, 1), 1);
}

int fcm__json_put_number(fcm__json *root, const char *path, double x)
{
  return put((cJSON *)root, path, cJSON_CreateNumber(x), 0);
}

int fcm__json_put_bool(fcm__json *root, const char *path, int b)
{
  return put((cJSON *)root, path, cJSON_CreateBool(b), 0);
}

int fcm__json_put_string(fcm__json *root, const char *path, const char *s)
{
  return put((cJSON *)root, path, cJSON_CreateString(s), 0);
}

int fcm__json_put_numbers(fcm__json *root, const char *path, const double *x, int n)
{
  return put((cJSON *)root, path, cJSON_CreateDoubleArray(x, n), 0);
}

char *fcm__json_print(const fcm__json *root)
{
  /* cJSON indents with tabs and puts a tab after each colon: two spaces and one space here */
  char *t = cJSON_Print((const cJSON *)root);
  if (!t) return NULL;
  size_t tabs = 0, n = 0;
  for (const char *c = t; *c; c++)
    tabs += *c == '\t';
  char *out = cJSON_malloc(strlen(t) + tabs + 1);
  if (!out) {
    cJSON_free(t);
    return NULL;
  }
  int in_string = 0, escaped = 0;
  for (const char *c = t; *c; c++) {
    if (in_string) {
      in_string = escaped || *c != '"';
      escaped = !escaped && *c == '\\';
    } else if (*c == '"') {
      in_string = 1;
    }
    if (*c == '\t' && !in_string) { /* cJSON escapes tabs inside strings */
      const int after_colon = n > 0 && out[n - 1] == ':';
      out[n++] = ' ';
      if (!after_colon) out[n++] = ' ';
      continue;
    }
    out[n++] = *c;
  }
  out[n] = '\0';
  cJSON_free(t);
  return out;
}

void fcm__json_free_text(char *text)
{
  cJSON_free(text);
}
