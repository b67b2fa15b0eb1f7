/* PVD time-series index for ParaView: (time, file) entries, the whole index rewritten
 * atomically after each addition so the file on disk is always a valid collection. */
#include "io/io_impl.h"

#include <math.h>
#include <string.h>

typedef struct pvd_entry {
  double time;
  char *file; /* owned, relative to the index's directory */
} pvd_entry;

struct fcm_pvd {
  fcm_ctx *ctx;
  char *path;     /* owned */
  size_t dir_len; /* length of the directory prefix of path, including the last '/' */
  pvd_entry *entries;
  fcm_index num_entries, cap_entries;
};

/* Write a collection of n entries to `path`: the data set entries[i].file at entries[i].time;
 * names NULL: all part 0 (a time series); else entry i is part i, named names[i]. */
static fcm_status write_collection(fcm_ctx *ctx, const char *path, fcm_index n,
                                   const pvd_entry *entries, const char *const *names,
                                   const fcm__io_fault *fault)
{
  fcm_status st = FCM_OK;
  fcm__atomic_file af;
  char num[32];
  memset(&af, 0, sizeof af);
  FCM_TRY(ctx, fcm__io_atomic_open(ctx, path, 0, fault, &af));
  FCM_TRY(ctx, fcm__io_atomic_printf(ctx, &af,
                                     "<?xml version=\"1.0\"?>\n"
                                     "<VTKFile type=\"Collection\" version=\"0.1\" "
                                     "byte_order=\"%s\">\n"
                                     "  <Collection>\n",
                                     fcm__io_byte_order()));
  for (fcm_index i = 0; i < n; i++) {
    fcm__io_format_double(entries[i].time, num);
    FCM_TRY(ctx, fcm__io_atomic_printf(ctx, &af,
                                       "    <DataSet timestep=\"%s\" group=\"\" part=\"%lld\" ",
                                       num, names ? (long long)i : 0LL));
    if (names) {
      FCM_TRY(ctx, fcm__io_atomic_printf(ctx, &af, "name=\""));
      FCM_TRY(ctx, fcm__io_atomic_write_xml(ctx, &af, names[i]));
      FCM_TRY(ctx, fcm__io_atomic_printf(ctx, &af, "\" "));
    }
    FCM_TRY(ctx, fcm__io_atomic_printf(ctx, &af, "file=\""));
    FCM_TRY(ctx, fcm__io_atomic_write_xml(ctx, &af, entries[i].file));
    FCM_TRY(ctx, fcm__io_atomic_printf(ctx, &af, "\"/>\n"));
  }
  FCM_TRY(ctx, fcm__io_atomic_printf(ctx, &af, "  </Collection>\n</VTKFile>\n"));
  FCM_TRY(ctx, fcm__io_atomic_commit(ctx, &af));
cleanup:
  fcm__io_atomic_abort(ctx, &af);
  return st;
}

/* Write the index with its first n entries. */
static fcm_status rewrite(fcm_pvd *pvd, fcm_index n, const fcm__io_fault *fault)
{
  return write_collection(pvd->ctx, pvd->path, n, pvd->entries, NULL, fault);
}

fcm_status fcm__pvd_write_parts(fcm_ctx *ctx, const char *path, int n, const char *const *names,
                                const char *const *files)
{
  fcm_status st = FCM_OK;
  pvd_entry parts[FCM__PVD_MAX_PARTS];
  FCM_CHECK(n >= 0 && n <= FCM__PVD_MAX_PARTS && fcm__io_printable(path), ctx, FCM_ERR_ARG,
            "pvd: %d parts outside [0, %d], or the path is empty or unprintable", n,
            FCM__PVD_MAX_PARTS);
  for (int i = 0; i < n; i++) {
    FCM_CHECK(fcm__io_printable(names[i]) && fcm__io_printable(files[i]), ctx, FCM_ERR_ARG,
              "pvd '%s': part %d has an empty or unprintable name or file", path, i);
    parts[i].time = 0.0;
    parts[i].file = (char *)files[i]; /* read only */
  }
  FCM_TRY(ctx, write_collection(ctx, path, n, parts, names, NULL));
cleanup:
  return st;
}

fcm_status fcm_pvd_create(fcm_ctx *ctx, const char *path, fcm_pvd **out)
{
  fcm_status st = FCM_OK;
  fcm_pvd *pvd = NULL;
  if (!out) return fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__, "pvd: out is NULL");
  *out = NULL;
  if (!ctx) return FCM_ERR_ARG;
  FCM_CHECK(fcm__io_printable(path), ctx, FCM_ERR_ARG,
            "pvd: index path is NULL, empty or has control characters");
  FCM_ALLOC(ctx, 1, pvd);
  pvd->ctx = ctx;
  FCM_TRY(ctx, fcm__io_strdup(ctx, path, &pvd->path));
  const char *slash = strrchr(path, '/');
  pvd->dir_len = slash ? (size_t)(slash - path) + 1 : 0;
  FCM_TRY(ctx, rewrite(pvd, 0, NULL));
  *out = pvd;
  pvd = NULL;
cleanup:
  fcm_pvd_destroy(&pvd);
  return st;
}

void fcm_pvd_destroy(fcm_pvd **pvd)
{
  if (!pvd || !*pvd) return;
  fcm_ctx *ctx = (*pvd)->ctx;
  for (fcm_index i = 0; i < (*pvd)->num_entries; i++)
    FCM_FREE(ctx, (*pvd)->entries[i].file);
  FCM_FREE(ctx, (*pvd)->entries);
  FCM_FREE(ctx, (*pvd)->path);
  FCM_FREE(ctx, *pvd);
}

fcm_status fcm__pvd_add_fault(fcm_pvd *pvd, double time, const char *file,
                              const fcm__io_fault *fault)
{
  fcm_status st = FCM_OK;
  char *copy = NULL;
  if (!pvd) return FCM_ERR_ARG;
  fcm_ctx *ctx = pvd->ctx;
  FCM_CHECK(isfinite(time), ctx, FCM_ERR_ARG, "pvd '%s': time %g is not finite", pvd->path, time);
  FCM_CHECK(fcm__io_printable(file), ctx, FCM_ERR_ARG,
            "pvd '%s': data file name is NULL, empty or has control characters", pvd->path);
  if (pvd->dir_len && !strncmp(file, pvd->path, pvd->dir_len) && file[pvd->dir_len])
    file += pvd->dir_len;
  if (pvd->num_entries == pvd->cap_entries) {
    fcm_index cap = pvd->cap_entries ? 2 * pvd->cap_entries : 16;
    FCM_TRY(ctx, fcm__resize(ctx, (void **)&pvd->entries, (size_t)pvd->cap_entries, (size_t)cap,
                             sizeof *pvd->entries));
    pvd->cap_entries = cap;
  }
  FCM_TRY(ctx, fcm__io_strdup(ctx, file, &copy));
  pvd->entries[pvd->num_entries].time = time;
  pvd->entries[pvd->num_entries].file = copy;
  FCM_TRY(ctx, rewrite(pvd, pvd->num_entries + 1, fault));
  pvd->num_entries++;
  copy = NULL;
cleanup:
  if (copy && pvd->entries[pvd->num_entries].file == copy)
    pvd->entries[pvd->num_entries].file = NULL;
  FCM_FREE(ctx, copy);
  return st;
}

fcm_status fcm_pvd_add(fcm_pvd *pvd, double time, const char *file)
{
  return fcm__pvd_add_fault(pvd, time, file, NULL);
}

fcm_index fcm_pvd_num_entries(const fcm_pvd *pvd)
{
  return pvd ? pvd->num_entries : 0;
}
