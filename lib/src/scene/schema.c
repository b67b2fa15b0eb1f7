/* Typed readers of scene-file values: each checks type and range and reports errors as
 * "<source>: <json.path>: expected <what is allowed>, got <value>". */
#define _POSIX_C_SOURCE 200809L
#include "scene/scene_impl.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define DESC_LEN  96
#define RANGE_LEN 96

fcm_status fcm__scene_error(fcm__scene_parser *p, fcm_status code, const char *file, int line,
                            const char *func, const char *fmt, ...)
{
  char msg[768];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  if (p->path_len > 0)
    return fcm__error(p->ctx, code, file, line, func, "%s: %s: %s", p->source, p->path, msg);
  return fcm__error(p->ctx, code, file, line, func, "%s: %s", p->source, msg);
}

/* Append text to the path; a path that would overflow ends in "..." instead. */
static void path_append(fcm__scene_parser *p, const char *text)
{
  size_t n = strlen(text), cap = sizeof p->path;
  if (p->path_len + n + 1 <= cap) {
    memcpy(p->path + p->path_len, text, n + 1);
    p->path_len += n;
  } else if (p->path_len + 4 <= cap) {
    memcpy(p->path + p->path_len, "...", 4);
    p->path_len += 3;
  }
}

size_t fcm__scene_path_push_key(fcm__scene_parser *p, const char *key)
{
  size_t old = p->path_len;
  char part[72];
  /* Keys are echoed in messages: cut long ones and replace control characters. */
  size_t n = 0, k = 0;
  if (old > 0) part[n++] = '.';
  for (; key[k] && k < 60; k++)
    part[n++] = ((unsigned char)key[k] < 0x20 || key[k] == 0x7f) ? '?' : key[k];
  if (key[k]) {
    memcpy(part + n, "...", 3);
    n += 3;
  }
  part[n] = '\0';
  path_append(p, part);
  return old;
}

size_t fcm__scene_path_push_index(fcm__scene_parser *p, int index)
{
  size_t old = p->path_len;
  char part[24];
  snprintf(part, sizeof part, "[%d]", index);
  path_append(p, part);
  return old;
}

void fcm__scene_path_pop(fcm__scene_parser *p, size_t old_len)
{
  p->path_len = old_len;
  p->path[old_len] = '\0';
}

/* Shortest of %.15g, %.16g, %.17g that reads back as x ("inf", "-inf" for overflow). */
static void format_number(double x, char *buf, size_t len)
{
  char t[32]; /* %.17g of a double takes at most 24 characters */
  for (int prec = 15; prec <= 17; prec++) {
    snprintf(t, sizeof t, "%.*g", prec, x);
    if (!isfinite(x) || strtod(t, NULL) == x) break;
  }
  snprintf(buf, len, "%s", t);
}

void fcm__scene_describe(const fcm__json *node, char *buf, size_t len)
{
  switch (fcm__json_get_kind(node)) {
  case FCM__JSON_NULL:
    snprintf(buf, len, "null");
    break;
  case FCM__JSON_BOOL:
    snprintf(buf, len, "%s", fcm__json_bool(node) ? "true" : "false");
    break;
  case FCM__JSON_NUMBER:
    format_number(fcm__json_number(node), buf, len);
    break;
  case FCM__JSON_STRING: {
    const char *s = fcm__json_string(node);
    size_t n = 0, max = len > 8 ? FCM_MIN(len - 6, (size_t)40) : 0;
    if (len < 8) {
      snprintf(buf, len, "\"\"");
      break;
    }
    buf[n++] = '"';
    for (; *s && n < max; s++)
      buf[n++] = ((unsigned char)*s < 0x20 || *s == 0x7f) ? '?' : *s;
    if (*s) {
      memcpy(buf + n, "...", 3);
      n += 3;
    }
    buf[n++] = '"';
    buf[n] = '\0';
    break;
  }
  case FCM__JSON_ARRAY:
    snprintf(buf, len, "an array of %d", fcm__json_size(node));
    break;
  case FCM__JSON_OBJECT:
    snprintf(buf, len, "an object");
    break;
  default:
    snprintf(buf, len, "an invalid value");
    break;
  }
}

void fcm__scene_range_text(fcm__range r, char *buf, size_t len)
{
  char lo[40], hi[40];
  format_number(r.lo, lo, sizeof lo);
  format_number(r.hi, hi, sizeof hi);
  int has_lo = r.lo > -HUGE_VAL, has_hi = r.hi < HUGE_VAL;
  if (has_lo && has_hi)
    snprintf(buf, len, "a finite number in %c%s, %s%c", r.lo_open ? '(' : '[', lo, hi,
             r.hi_open ? ')' : ']');
  else if (has_lo)
    snprintf(buf, len, "a finite number %s %s", r.lo_open ? ">" : ">=", lo);
  else if (has_hi)
    snprintf(buf, len, "a finite number %s %s", r.hi_open ? "<" : "<=", hi);
  else
    snprintf(buf, len, "a finite number");
}

static int in_range(double x, fcm__range r)
{
  if (!isfinite(x)) return 0;
  if (r.lo_open ? !(x > r.lo) : !(x >= r.lo)) return 0;
  if (r.hi_open ? !(x < r.hi) : !(x <= r.hi)) return 0;
  return 1;
}

/* Check a number node at the current path. */
static fcm_status check_number(fcm__scene_parser *p, const fcm__json *v, fcm__range range,
                               double *out)
{
  fcm_status st = FCM_OK;
  char want[RANGE_LEN], got[DESC_LEN];
  fcm__scene_range_text(range, want, sizeof want);
  fcm__scene_describe(v, got, sizeof got);
  SCENE_CHECK(fcm__json_get_kind(v) == FCM__JSON_NUMBER, p, FCM_ERR_ARG, "expected %s, got %s",
              want, got);
  SCENE_CHECK(in_range(fcm__json_number(v), range), p, FCM_ERR_ARG, "expected %s, got %s", want,
              got);
  *out = fcm__json_number(v);
cleanup:
  return st;
}

static fcm_status check_int(fcm__scene_parser *p, const fcm__json *v, long long lo, long long hi,
                            long long *out)
{
  fcm_status st = FCM_OK;
  char got[DESC_LEN];
  fcm__scene_describe(v, got, sizeof got);
  double x = fcm__json_get_kind(v) == FCM__JSON_NUMBER ? fcm__json_number(v) : NAN;
  SCENE_CHECK(isfinite(x) && x == floor(x) && x >= (double)lo && x <= (double)hi, p, FCM_ERR_ARG,
              "expected an integer in [%lld, %lld], got %s", lo, hi, got);
  *out = (long long)x;
cleanup:
  return st;
}

/* ------------------------------------------------------ the normalized tree (p->norm) */

static void note(fcm__scene_parser *p, int ok)
{
  if (!ok) p->norm_failed = 1;
}

/* The value at the current path + key: a number, a bool, a string, an array of numbers. */
static void put_number(fcm__scene_parser *p, const char *key, double x)
{
  if (!p->norm) return;
  size_t o = key ? fcm__scene_path_push_key(p, key) : p->path_len;
  note(p, fcm__json_put_number(p->norm, p->path, x));
  fcm__scene_path_pop(p, o);
}

static void put_bool(fcm__scene_parser *p, const char *key, int b)
{
  if (!p->norm) return;
  size_t o = key ? fcm__scene_path_push_key(p, key) : p->path_len;
  note(p, fcm__json_put_bool(p->norm, p->path, b));
  fcm__scene_path_pop(p, o);
}

static void put_string(fcm__scene_parser *p, const char *key, const char *s)
{
  if (!p->norm || !s) return;
  size_t o = key ? fcm__scene_path_push_key(p, key) : p->path_len;
  note(p, fcm__json_put_string(p->norm, p->path, s));
  fcm__scene_path_pop(p, o);
}

static void put_numbers(fcm__scene_parser *p, const char *key, const double *x, int n)
{
  if (!p->norm) return;
  size_t o = key ? fcm__scene_path_push_key(p, key) : p->path_len;
  note(p, fcm__json_put_numbers(p->norm, p->path, x, n));
  fcm__scene_path_pop(p, o);
}

void fcm__scene_forget(fcm__scene_parser *p, const char *key)
{
  if (!p->norm) return;
  size_t o = fcm__scene_path_push_key(p, key);
  fcm__json_remove_path(p->norm, p->path);
  fcm__scene_path_pop(p, o);
}

void fcm__scene_put_resolved_time(fcm__scene_parser *p, const fcm_scene_time *t)
{
  if (!p->norm) return;
  const int is_static = t->integrator == FCM_INTEGRATOR_STATIC;
  size_t o = fcm__scene_path_push_key(p, "time");
  put_bool(p, "static", is_static);
  if (!is_static) put_string(p, "integrator", fcm_time_scheme_name(t->scheme));
  if (!is_static && t->scheme == FCM_SCHEME_HHT) put_number(p, "alpha", t->hht_alpha);
  if (!is_static && t->scheme == FCM_SCHEME_GENERALIZED_ALPHA) put_number(p, "rho_inf", t->rho_inf);
  put_number(p, "dt", t->dt);
  put_number(p, "steps", (double)t->num_steps);
  if (is_static) put_number(p, "load_steps", (double)t->load_steps);
  fcm__scene_path_pop(p, o);
}

fcm_status fcm__scene_field(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                            int required, const char *want, fcm__json_kind kind, int len,
                            const fcm__json **out)
{
  fcm_status st = FCM_OK;
  char got[DESC_LEN];
  const fcm__json *v = fcm__json_member(obj, key);
  size_t old = fcm__scene_path_push_key(p, key);
  *out = NULL;
  if (!v) {
    SCENE_CHECK(!required, p, FCM_ERR_ARG, "missing; expected %s", want);
    fcm__scene_path_pop(p, old);
    return FCM_OK;
  }
  if (kind != FCM__SCENE_ANY_KIND) {
    fcm__scene_describe(v, got, sizeof got);
    SCENE_CHECK(fcm__json_get_kind(v) == kind && (len < 0 || fcm__json_size(v) == len), p,
                FCM_ERR_ARG, "expected %s, got %s", want, got);
  }
  if (p->norm) note(p, fcm__json_put_copy(p->norm, p->path, v));
  *out = v;
cleanup:
  return st;
}

fcm_status fcm__scene_read_number(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, fcm__range range, double *out)
{
  fcm_status st = FCM_OK;
  const fcm__json *v = NULL;
  char want[RANGE_LEN];
  size_t old = p->path_len;
  fcm__scene_range_text(range, want, sizeof want);
  FCM_TRY(p->ctx, fcm__scene_field(p, obj, key, required, want, FCM__SCENE_ANY_KIND, -1, &v));
  if (!v) { /* the default, where it is a value the key takes */
    if (in_range(*out, range)) put_number(p, key, *out);
    return FCM_OK;
  }
  FCM_TRY(p->ctx, check_number(p, v, range, out));
  put_number(p, NULL, *out);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_int(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                               int required, long long lo, long long hi, long long *out)
{
  fcm_status st = FCM_OK;
  const fcm__json *v = NULL;
  char want[RANGE_LEN];
  size_t old = p->path_len;
  snprintf(want, sizeof want, "an integer in [%lld, %lld]", lo, hi);
  FCM_TRY(p->ctx, fcm__scene_field(p, obj, key, required, want, FCM__SCENE_ANY_KIND, -1, &v));
  if (!v) {
    if (*out >= lo && *out <= hi) put_number(p, key, (double)*out);
    return FCM_OK;
  }
  FCM_TRY(p->ctx, check_int(p, v, lo, hi, out));
  put_number(p, NULL, (double)*out);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_bool(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                int required, int *out)
{
  fcm_status st = FCM_OK;
  const fcm__json *v = NULL;
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_field(p, obj, key, required, "true or false", FCM__JSON_BOOL, -1, &v));
  if (!v) {
    if (*out == 0 || *out == 1) put_bool(p, key, *out);
    return FCM_OK;
  }
  *out = fcm__json_bool(v);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_bool_or_word(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                        int required, const char *word, int word_value, int *out)
{
  fcm_status st = FCM_OK;
  const fcm__json *v = NULL;
  char want[DESC_LEN], got[DESC_LEN];
  size_t old = p->path_len;
  snprintf(want, sizeof want, "true, false or \"%s\"", word);
  FCM_TRY(p->ctx, fcm__scene_field(p, obj, key, required, want, FCM__SCENE_ANY_KIND, -1, &v));
  if (!v) {
    if (*out == word_value)
      put_string(p, key, word);
    else if (*out == 0 || *out == 1)
      put_bool(p, key, *out);
    return FCM_OK;
  }
  if (fcm__json_get_kind(v) == FCM__JSON_BOOL) {
    *out = fcm__json_bool(v);
  } else {
    fcm__scene_describe(v, got, sizeof got);
    SCENE_CHECK(fcm__json_get_kind(v) == FCM__JSON_STRING && !strcmp(fcm__json_string(v), word), p,
                FCM_ERR_ARG, "expected %s, got %s", want, got);
    *out = word_value;
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_strdup(fcm__scene_parser *p, const char *s, const char **out)
{
  fcm_status st = FCM_OK;
  size_t n = strlen(s);
  char *copy = fcm__scene_alloc(p->scene, n + 1, 1);
  if (!copy) {
    st = FCM_ERR_ALLOC;
    fcm__trace(p->ctx, __FILE__, __LINE__, __func__);
    return st;
  }
  memcpy(copy, s, n + 1);
  *out = copy;
  return st;
}

/* A string member at the current path + key: non-empty, no control characters. */
static fcm_status string_node(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                              int required, const char *want, const char **raw)
{
  fcm_status st = FCM_OK;
  const fcm__json *v = NULL;
  size_t old = p->path_len;
  *raw = NULL;
  FCM_TRY(p->ctx, fcm__scene_field(p, obj, key, required, want, FCM__JSON_STRING, -1, &v));
  if (!v) return FCM_OK;
  const char *s = fcm__json_string(v);
  SCENE_CHECK(s[0] != '\0', p, FCM_ERR_ARG, "expected %s, got an empty string", want);
  for (const char *c = s; *c; c++)
    SCENE_CHECK((unsigned char)*c >= 0x20 && *c != 0x7f, p, FCM_ERR_ARG,
                "expected %s, got a string with a control character at offset %d", want,
                (int)(c - s));
  *raw = s;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_string(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, const char **out)
{
  fcm_status st = FCM_OK;
  const char *raw = NULL;
  FCM_TRY(p->ctx, string_node(p, obj, key, required, "a non-empty string", &raw));
  if (raw) FCM_TRY(p->ctx, fcm__scene_strdup(p, raw, out));
  if (!raw && *out && **out) put_string(p, key, *out); /* a default, if any (not "") */
cleanup:
  return st;
}

fcm_status fcm__scene_read_vec3(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                int required, fcm__range range, double out[3])
{
  fcm_status st = FCM_OK;
  const fcm__json *v = NULL;
  char want[RANGE_LEN + 32];
  size_t old = p->path_len;
  double tmp[3];
  {
    /* "a finite number > 0" -> "an array of 3 finite numbers > 0" */
    char r[RANGE_LEN];
    fcm__scene_range_text(range, r, sizeof r);
    const char *tail = strstr(r, "number");
    snprintf(want, sizeof want, "an array of 3 finite numbers%s", tail ? tail + 6 : "");
  }
  FCM_TRY(p->ctx, fcm__scene_field(p, obj, key, required, want, FCM__JSON_ARRAY, 3, &v));
  if (!v) {
    if (in_range(out[0], range) && in_range(out[1], range) && in_range(out[2], range))
      put_numbers(p, key, out, 3);
    return FCM_OK;
  }
  int i = 0;
  for (const fcm__json *c = fcm__json_child(v); c; c = fcm__json_next(c), i++) {
    size_t o = fcm__scene_path_push_index(p, i);
    FCM_TRY(p->ctx, check_number(p, c, range, &tmp[i]));
    fcm__scene_path_pop(p, o);
  }
  memcpy(out, tmp, sizeof tmp);
  put_numbers(p, NULL, out, 3);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_ivec3(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                 int required, long long lo, long long hi, fcm_index out[3])
{
  fcm_status st = FCM_OK;
  const fcm__json *v = NULL;
  char want[RANGE_LEN];
  size_t old = p->path_len;
  long long tmp[3];
  snprintf(want, sizeof want, "an array of 3 integers in [%lld, %lld]", lo, hi);
  FCM_TRY(p->ctx, fcm__scene_field(p, obj, key, required, want, FCM__JSON_ARRAY, 3, &v));
  if (!v) {
    double x[3] = {(double)out[0], (double)out[1], (double)out[2]};
    if (out[0] >= lo && out[0] <= hi && out[1] >= lo && out[1] <= hi && out[2] >= lo &&
        out[2] <= hi)
      put_numbers(p, key, x, 3);
    return FCM_OK;
  }
  int i = 0;
  for (const fcm__json *c = fcm__json_child(v); c; c = fcm__json_next(c), i++) {
    size_t o = fcm__scene_path_push_index(p, i);
    FCM_TRY(p->ctx, check_int(p, c, lo, hi, &tmp[i]));
    fcm__scene_path_pop(p, o);
  }
  for (int d = 0; d < 3; d++)
    out[d] = (fcm_index)tmp[d];
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "one of \"a\", \"b\", \"c\"" */
static void list_names(const char *const *names, int n, const char *prefix, char *buf, size_t len)
{
  size_t used = (size_t)snprintf(buf, len, "%s", prefix);
  for (int i = 0; i < n && used < len; i++)
    used += (size_t)snprintf(buf + used, len - used, "%s\"%s\"", i ? ", " : "", names[i]);
}

fcm_status fcm__scene_read_choice(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, const char *const *names, int n, int *out)
{
  fcm_status st = FCM_OK;
  const char *raw = NULL;
  char want[384];
  size_t old = p->path_len;
  list_names(names, n, "one of ", want, sizeof want);
  FCM_TRY(p->ctx, string_node(p, obj, key, required, want, &raw));
  if (!raw) {
    if (*out >= 0 && *out < n) put_string(p, key, names[*out]);
    return FCM_OK;
  }
  fcm__scene_path_push_key(p, key);
  int found = -1;
  for (int i = 0; i < n && found < 0; i++)
    if (!strcmp(raw, names[i])) found = i;
  char got[DESC_LEN];
  fcm__scene_describe(fcm__json_member(obj, key), got, sizeof got);
  SCENE_CHECK(found >= 0, p, FCM_ERR_ARG, "expected %s, got %s", want, got);
  *out = found;
  put_string(p, NULL, names[found]);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_object(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, const fcm__json **out)
{
  fcm_status st = FCM_OK;
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_field(p, obj, key, required, "an object", FCM__JSON_OBJECT, -1, out));
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_check_object(fcm__scene_parser *p, const fcm__json *node,
                                   const char *const *allowed, int n)
{
  fcm_status st = FCM_OK;
  char got[DESC_LEN], list[512];
  fcm__scene_describe(node, got, sizeof got);
  SCENE_CHECK(fcm__json_get_kind(node) == FCM__JSON_OBJECT, p, FCM_ERR_ARG,
              "expected an object, got %s", got);
  for (const fcm__json *c = fcm__json_child(node); c; c = fcm__json_next(c)) {
    const char *key = fcm__json_key(c);
    int ok = 0;
    for (int i = 0; i < n && !ok; i++)
      ok = !strcmp(key, allowed[i]);
    if (!ok) {
      size_t old = fcm__scene_path_push_key(p, key);
      list_names(allowed, n, "", list, sizeof list);
      st = fcm__scene_error(p, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                            "unknown key; allowed keys here: %s", list);
      fcm__scene_path_pop(p, old);
      goto cleanup;
    }
    for (const fcm__json *d = fcm__json_child(node); d != c; d = fcm__json_next(d)) {
      if (strcmp(fcm__json_key(d), key)) continue;
      size_t old = fcm__scene_path_push_key(p, key);
      st = fcm__scene_error(p, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                            "duplicate key (each key may appear once)");
      fcm__scene_path_pop(p, old);
      goto cleanup;
    }
  }
cleanup:
  return st;
}

/* Thread-safe text of a system error (the XSI strerror_r). */
static void sys_error(int err, char *buf, size_t len)
{
  if (strerror_r(err, buf, len) != 0) snprintf(buf, len, "system error %d", err);
}

fcm_status fcm__scene_read_file(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                int required, const char *suffix, const char **out)
{
  fcm_status st = FCM_OK;
  const char *raw = NULL;
  char *full = NULL, err[128];
  size_t old = p->path_len;
  FILE *f = NULL;
  FCM_TRY(p->ctx, string_node(p, obj, key, required, "a file name (a non-empty string)", &raw));
  if (!raw) return FCM_OK;
  fcm__scene_path_push_key(p, key);
  const char *base = raw[0] == '/' ? "" : p->base_dir;
  if (!suffix) suffix = "";
  size_t n = strlen(base) + strlen(raw) + strlen(suffix) + 1;
  full = fcm__scene_alloc(p->scene, n, 1);
  if (!full) {
    st = FCM_ERR_ALLOC;
    fcm__trace(p->ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  snprintf(full, n, "%s%s%s", base, raw, suffix);
  if (p->norm) { /* absolute, so that the normalized scene reads the same file from anywhere */
    char cwd[4096], name[8192];
    const int rel = full[0] != '/' && getcwd(cwd, sizeof cwd);
    snprintf(name, sizeof name, "%s%s%s%s", rel ? cwd : "", rel ? "/" : "", base, raw);
    put_string(p, NULL, name);
  }
  struct stat sb;
  if (stat(full, &sb) != 0) {
    sys_error(errno, err, sizeof err);
    SCENE_CHECK(0, p, FCM_ERR_IO, "cannot open '%s': %s", full, err);
  }
  SCENE_CHECK(S_ISREG(sb.st_mode), p, FCM_ERR_IO, "'%s' is not a regular file", full);
  f = fopen(full, "rb");
  if (!f) {
    sys_error(errno, err, sizeof err);
    SCENE_CHECK(0, p, FCM_ERR_IO, "cannot open '%s': %s", full, err);
  }
  *out = full;
cleanup:
  if (f) fclose(f);
  fcm__scene_path_pop(p, old);
  return st;
}
