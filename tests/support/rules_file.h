/* Reading fcm's cell-rules file (lib/docs/rules_format.md) in the tests: the whole file in
 * memory, the header's text, and an array by name (its shape and a pointer to its values).
 * The array table is found by the exact text the writer prints; the values are read in
 * place, so only on a little-endian host (rf_load() refuses others). */
#ifndef FCM_TEST_RULES_FILE_H
#define FCM_TEST_RULES_FILE_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct rf_file {
  unsigned char *bytes;
  long size;
  char *header;      /* NUL-terminated copy of the JSON header */
  long long data_at; /* where the data section starts */
} rf_file;

static inline void rf_free(rf_file *f)
{
  free(f->bytes);
  free(f->header);
  memset(f, 0, sizeof *f);
}

/* 1 when `path` is a complete rules file of a little-endian host, else 0 (nothing to free). */
static inline int rf_load(const char *path, rf_file *f)
{
  const uint16_t one = 1;
  memset(f, 0, sizeof *f);
  FILE *fp = fopen(path, "rb");
  if (!fp || *(const unsigned char *)&one != 1) {
    if (fp) fclose(fp);
    return 0;
  }
  fseek(fp, 0, SEEK_END);
  f->size = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  f->bytes = malloc((size_t)f->size + 1);
  const int ok =
      f->bytes && f->size >= 16 && fread(f->bytes, 1, (size_t)f->size, fp) == (size_t)f->size;
  fclose(fp);
  uint64_t len = 0;
  if (ok) memcpy(&len, f->bytes + 8, 8);
  if (!ok || memcmp(f->bytes, "FCMRULES", 8) || 16 + len > (uint64_t)f->size || (16 + len) % 8 ||
      !(f->header = malloc(len + 1))) {
    rf_free(f);
    return 0;
  }
  memcpy(f->header, f->bytes + 16, len);
  f->header[len] = 0;
  f->data_at = 16 + (long long)len;
  return 1;
}

/* A number after `key` in the header's text from `from` on; -1 when absent. */
static inline long long rf_number_after(const char *from, const char *key)
{
  const char *p = from ? strstr(from, key) : NULL;
  return p ? strtoll(p + strlen(key), NULL, 10) : -1;
}

/* The array `name`: its values (NULL when absent or beyond the file), rows and columns (0 for
 * a one-dimensional array). */
static inline const void *rf_array(const rf_file *f, const char *name, long long *rows, int *cols)
{
  char key[96];
  snprintf(key, sizeof key, "{\"name\": \"%s\", ", name);
  const char *e = strstr(f->header, key);
  *rows = 0;
  *cols = 0;
  if (!e) return NULL;
  const char *shape = strstr(e, "\"shape\": [");
  const char *end = strchr(e, '}');
  if (!shape || shape > end) return NULL;
  char *q = NULL;
  *rows = strtoll(shape + 10, &q, 10);
  if (*q == ',') *cols = (int)strtol(q + 1, NULL, 10);
  const long long off = rf_number_after(e, "\"offset\": ");
  const char *dt = strstr(e, "\"dtype\": \"");
  const int size = !dt || dt > end ? 0 : dt[10] == 'u' ? 1 : dt[13] == '3' ? 4 : 8;
  if (off < 0 || !size || f->data_at + off + *rows * (*cols ? *cols : 1) * size > f->size)
    return NULL;
  return f->bytes + f->data_at + off;
}

#endif
