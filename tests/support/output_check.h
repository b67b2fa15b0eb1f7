/* Completeness of the final files a simulation run leaves in a directory (for the fault
 * tests): every VTU parses (header, balanced tags, appended arrays of the announced sizes),
 * every PVD is balanced XML whose data sets name existing files, every CSV log has its
 * header and whole rows numbered 1, 2, ..., and every checkpoint restores into a fresh
 * simulation of its scene. Temporaries (names containing ".tmp") are not final files and
 * are skipped. */
#ifndef FCM_TEST_OUTPUT_CHECK_H
#define FCM_TEST_OUTPUT_CHECK_H

#include "fcm/fcm.h"
#include "fcm/simulation.h"
#include "../io/vtk_reader.h"

#include <dirent.h>
#include <sys/stat.h>
#include <stdio.h>
#include <string.h>

typedef struct oc_counts {
  int vtu, pvd, csv, checkpoint, tmp, bad;
  char first_error[512];
} oc_counts;

/* Drop the last column (the wall time) of every line of a CSV text, in place: what stays is
 * what a repeated or resumed run must reproduce exactly. */
static inline void oc_strip_last_column(char *csv)
{
  char *w = csv;
  for (char *line = csv; *line;) {
    char *nl = strchr(line, '\n');
    size_t len = nl ? (size_t)(nl - line) : strlen(line);
    char *comma = NULL;
    for (size_t k = 0; k < len; k++)
      if (line[k] == ',') comma = line + k;
    size_t keep = comma ? (size_t)(comma - line) : len;
    memmove(w, line, keep);
    w += keep;
    *w++ = '\n';
    line += len + (nl ? 1 : 0);
  }
  *w = '\0';
}

static inline int oc_ends_with(const char *s, const char *suffix)
{
  size_t n = strlen(s), m = strlen(suffix);
  return n >= m && !strcmp(s + n - m, suffix);
}

static inline void oc_bad(oc_counts *c, const char *path, const char *why)
{
  if (!c->bad++) snprintf(c->first_error, sizeof c->first_error, "%.250s: %.250s", path, why);
}

/* A CSV log: the header (the fixed columns, reaction columns per constraint effect, then
 * wall_time), then rows "k,<as many more fields>\n" for k = 1, 2, ... */
static inline int oc_check_csv(const char *path, char *why, size_t cap)
{
  long n = 0;
  unsigned char *buf = vr_slurp(path, &n);
  int ok = 0;
  if (!buf) {
    snprintf(why, cap, "unreadable");
    return 0;
  }
  const char *hdr = "step,time,newton_iterations,linear_iterations,residual,energy,pieces,mass,"
                    "momentum_x,momentum_y,momentum_z,";
  const char *p = (const char *)buf, *end = p + n;
  const char *hnl = memchr(p, '\n', (size_t)n);
  if ((size_t)n < strlen(hdr) || memcmp(p, hdr, strlen(hdr)) || !hnl || hnl - p < 10 ||
      memcmp(hnl - 10, ",wall_time", 10)) {
    snprintf(why, cap, "no header");
    goto done;
  }
  int hcommas = 0;
  for (const char *q = p; q < hnl; q++)
    hcommas += *q == ',';
  p = hnl + 1;
  for (long long row = 1; p < end; row++) {
    const char *nl = memchr(p, '\n', (size_t)(end - p));
    if (!nl) {
      snprintf(why, cap, "row %lld is cut", row);
      goto done;
    }
    int commas = 0;
    for (const char *q = p; q < nl; q++)
      commas += *q == ',';
    if (commas != hcommas || strtoll(p, NULL, 10) != row) {
      snprintf(why, cap, "row %lld malformed", row);
      goto done;
    }
    p = nl + 1;
  }
  ok = 1;
done:
  free(buf);
  return ok;
}

/* A PVD: balanced XML; each DataSet's file exists. */
static inline int oc_check_pvd(vr_doc *d, const char *path, char *why, size_t cap)
{
  if (!vr_load(d, path)) return snprintf(why, cap, "unreadable"), 0;
  int ok = vr_parse_xml(d);
  if (!ok) snprintf(why, cap, "%s", d->error);
  for (int i = 0; ok; i++) {
    const vr_tag *t = vr_find(d, "DataSet", NULL, i);
    char file[1024];
    if (!t) break;
    if (!vr_attr(t, "file", file, sizeof file)) {
      snprintf(why, cap, "DataSet %d without file", i);
      ok = 0;
    } else {
      FILE *f = fopen(file, "rb");
      if (!f) {
        /* relative to the PVD's directory */
        char full[2048];
        const char *slash = strrchr(path, '/');
        snprintf(full, sizeof full, "%.*s/%s", slash ? (int)(slash - path) : 1, slash ? path : ".",
                 file);
        f = fopen(full, "rb");
      }
      if (f)
        fclose(f);
      else
        snprintf(why, cap, "DataSet '%.200s' missing", file), ok = 0;
    }
  }
  vr_free(d);
  return ok;
}

/* Checkpoints already restored once (name, size, modification time): not opened again. */
typedef struct oc_seen {
  int n;
  struct {
    char name[256];
    long long size, mtime_ns;
  } e[256];
} oc_seen;

static inline int oc_seen_before(oc_seen *seen, const char *name, const struct stat *sb)
{
  long long t = (long long)sb->st_mtim.tv_sec * 1000000000LL + sb->st_mtim.tv_nsec;
  for (int i = 0; seen && i < seen->n; i++)
    if (!strcmp(seen->e[i].name, name) && seen->e[i].size == (long long)sb->st_size &&
        seen->e[i].mtime_ns == t)
      return 1;
  if (seen && seen->n < 256) {
    snprintf(seen->e[seen->n].name, sizeof seen->e[0].name, "%s", name);
    seen->e[seen->n].size = (long long)sb->st_size;
    seen->e[seen->n++].mtime_ns = t;
  }
  return 0;
}

/* Check every final file of `dir`. `scene` (may be NULL: checkpoints are then not opened)
 * is the scene the checkpoints belong to; `ctx` creates the simulations for them; `seen`
 * (may be NULL) skips the checkpoints restored by an earlier call. */
static inline oc_counts oc_check_dir_seen(const char *dir, fcm_ctx *ctx, const fcm_scene *scene,
                                          oc_seen *seen)
{
  oc_counts c;
  memset(&c, 0, sizeof c);
  DIR *dp = opendir(dir);
  if (!dp) return c;
  vr_doc *d = malloc(sizeof *d);
  struct dirent *e;
  while (d && (e = readdir(dp))) {
    char path[1024], why[256] = "";
    if (e->d_name[0] == '.' && (!e->d_name[1] || !strcmp(e->d_name, ".."))) continue;
    if (strstr(e->d_name, ".tmp")) {
      c.tmp++;
      continue;
    }
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    if (oc_ends_with(e->d_name, ".vtu")) {
      c.vtu++;
      if (!vr_load(d, path) || !vr_parse_vtu(d)) oc_bad(&c, path, d->error);
      vr_free(d);
    } else if (oc_ends_with(e->d_name, ".pvd")) {
      c.pvd++;
      if (!oc_check_pvd(d, path, why, sizeof why)) oc_bad(&c, path, why);
    } else if (oc_ends_with(e->d_name, ".csv")) {
      c.csv++;
      if (!oc_check_csv(path, why, sizeof why)) oc_bad(&c, path, why);
    } else if (oc_ends_with(e->d_name, ".fcmck")) {
      c.checkpoint++;
      struct stat sb;
      if (scene && !(stat(path, &sb) == 0 && oc_seen_before(seen, e->d_name, &sb))) {
        fcm_simulation *sim = NULL;
        fcm_status st = fcm_simulation_create(ctx, scene, NULL, &sim);
        if (st == FCM_OK) st = fcm_simulation_read_checkpoint(sim, path);
        if (st != FCM_OK) oc_bad(&c, path, fcm_ctx_error_message(ctx));
        fcm_ctx_error_clear(ctx);
        fcm_simulation_destroy(&sim);
      }
    }
  }
  free(d);
  closedir(dp);
  return c;
}

static inline oc_counts oc_check_dir(const char *dir, fcm_ctx *ctx, const fcm_scene *scene)
{
  return oc_check_dir_seen(dir, ctx, scene, NULL);
}

#endif
