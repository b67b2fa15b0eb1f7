/* The cJSON adapter: the only file that includes cJSON. It parses a text into a tree
 * (reporting the byte offset of a syntax error) and exposes read-only accessors. */
#include "scene/scene_impl.h"

#include <cJSON.h>

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
