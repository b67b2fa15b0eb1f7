/* Running a program from an app test: the exit status of a shell command, whether a path
 * exists (the program's output, or its absence after a refused run), a field of a CSV line. */
#ifndef FCM_TEST_APP_RUN_H
#define FCM_TEST_APP_RUN_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

/* The exit status of `cmd` run by the shell; -1 when it did not exit normally. */
static inline int app_run(const char *cmd)
{
  const int st = system(cmd);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* 1 when `path` names an existing file or directory. */
static inline int app_exists(const char *path)
{
  struct stat sb;
  return stat(path, &sb) == 0;
}

/* 1 when a line of the file `path` holds "warning" other than the library's warning about
 * the BLAS kernels ("warning: BLAS: ..."), which a run on a CPU newer than its OpenBLAS gets
 * when the kernels are kept (FCM_BLAS_CORETYPE=keep, or OPENBLAS_CORETYPE set to older ones). */
static inline int app_has_warning(const char *path)
{
  char line[4096];
  int found = 0;
  FILE *f = fopen(path, "r");
  while (f && !found && fgets(line, sizeof line, f))
    found = strstr(line, "warning") && !strstr(line, "warning: BLAS: ");
  if (f) fclose(f);
  return found;
}

/* 1 when the file `path` starts with the PNG signature. */
static inline int app_is_png(const char *path)
{
  FILE *f = fopen(path, "rb");
  unsigned char magic[8] = {0};
  const int ok = f && fread(magic, 1, 8, f) == 8 && magic[0] == 0x89 && magic[1] == 'P' &&
                 magic[2] == 'N' && magic[3] == 'G';
  if (f) fclose(f);
  return ok;
}

/* The width and height of the PNG `path` from its IHDR chunk (the signature, then the chunk
 * length 13 and type "IHDR", then width and height as big-endian 32-bit integers); 1 when the
 * file is a PNG with that header, else 0. */
static inline int app_png_size(const char *path, unsigned long *width, unsigned long *height)
{
  static const unsigned char head[16] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n',
                                         0,    0,   0,   13,  'I',  'H',  'D',  'R'};
  unsigned char b[24] = {0};
  FILE *f = fopen(path, "rb");
  const int ok = f && fread(b, 1, 24, f) == 24 && !memcmp(b, head, 16);
  if (f) fclose(f);
  if (!ok) return 0;
  *width =
      (unsigned long)b[16] << 24 | (unsigned long)b[17] << 16 | (unsigned long)b[18] << 8 | b[19];
  *height =
      (unsigned long)b[20] << 24 | (unsigned long)b[21] << 16 | (unsigned long)b[22] << 8 | b[23];
  return 1;
}

/* Field k (from 0) of a CSV line without quoting into buf (cap bytes, cut to fit). */
static inline void field(const char *line, int k, char *buf, size_t cap)
{
  const char *p = line;
  for (int i = 0; i < k && p; i++) {
    p = strchr(p, ',');
    if (p) p++;
  }
  size_t m = 0;
  while (p && *p && *p != ',' && *p != '\n' && m + 1 < cap)
    buf[m++] = *p++;
  buf[m] = 0;
}

#endif
