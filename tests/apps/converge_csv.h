/* Shared by the fcm-converge tests: run the program, read its level and rate CSV files,
 * refit rates, look rows up. */
#ifndef FCM_TEST_CONVERGE_CSV_H
#define FCM_TEST_CONVERGE_CSV_H

#include "test.h"

#include "app_run.h"

#define CONVERGE_LEVELS_HEADER                                                                     \
  "element,method,res,h,dofs,active_cells,cut_cells,points,strength,t_rules,t_assembly,t_solve,"   \
  "t_total,err_l2,err_h1,norm_l2,norm_h1,rel_l2,rel_h1,measured_volume,domain_volume,failed,"      \
  "note,cpu_rules,cpu_assembly,cpu_solve,cpu_total\n"
#define CONVERGE_RATES_HEADER "element,method,norm,rate\n"

typedef struct cv_level {
  char element[16], method[16];
  int res, strength, failed;
  double h, t_rules, t_assembly, t_solve, t_total, err_l2, err_h1, norm_l2, norm_h1, rel_l2, rel_h1,
      measured, domain, c_rules, c_assembly, c_solve, c_total;
  long long dofs, cells, cut, points;
} cv_level;

typedef struct cv_rate_row {
  char element[16], method[16], norm[8];
  double rate;
} cv_rate_row;

enum { CV_MAX_ROWS = 256 };

/* Rows of a levels CSV (header checked); -1 on a missing file, bad header or bad row. The
 * note field must be empty (every run of the tests is expected to be clean). */
static inline int cv_read_levels(const char *path, cv_level *rows, int cap)
{
  FILE *f = fopen(path, "r");
  char line[2048];
  int n = 0;
  if (!f) return -1;
  if (!fgets(line, sizeof line, f) || strcmp(line, CONVERGE_LEVELS_HEADER) != 0) {
    fclose(f);
    return -1;
  }
  while (fgets(line, sizeof line, f)) {
    cv_level r;
    if (n >= cap ||
        sscanf(line,
               "%15[^,],%15[^,],%d,%lf,%lld,%lld,%lld,%lld,%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,"
               "%lf,%lf,%lf,%d,,%lf,%lf,%lf,%lf",
               r.element, r.method, &r.res, &r.h, &r.dofs, &r.cells, &r.cut, &r.points, &r.strength,
               &r.t_rules, &r.t_assembly, &r.t_solve, &r.t_total, &r.err_l2, &r.err_h1, &r.norm_l2,
               &r.norm_h1, &r.rel_l2, &r.rel_h1, &r.measured, &r.domain, &r.failed, &r.c_rules,
               &r.c_assembly, &r.c_solve, &r.c_total) != 26) {
      fclose(f);
      return -1;
    }
    rows[n++] = r;
  }
  fclose(f);
  return n;
}

/* Rows of a rates CSV (header checked); -1 on error. */
static inline int cv_read_rates(const char *path, cv_rate_row *rows, int cap)
{
  FILE *f = fopen(path, "r");
  char line[256];
  int n = 0;
  if (!f) return -1;
  if (!fgets(line, sizeof line, f) || strcmp(line, CONVERGE_RATES_HEADER) != 0) {
    fclose(f);
    return -1;
  }
  while (fgets(line, sizeof line, f)) {
    cv_rate_row r;
    if (n >= cap ||
        sscanf(line, "%15[^,],%15[^,],%7[^,],%lf", r.element, r.method, r.norm, &r.rate) != 4) {
      fclose(f);
      return -1;
    }
    rows[n++] = r;
  }
  fclose(f);
  return n;
}

static inline const cv_rate_row *cv_find_rate(const cv_rate_row *rows, int n, const char *element,
                                              const char *method, const char *norm)
{
  for (int k = 0; k < n; k++)
    if (!strcmp(rows[k].element, element) && !strcmp(rows[k].method, method) &&
        !strcmp(rows[k].norm, norm))
      return &rows[k];
  return NULL;
}

/* The levels of (element, method) sorted coarse to fine into out (pointers); their count. */
static inline int cv_select(const cv_level *rows, int n, const char *element, const char *method,
                            const cv_level **out, int cap)
{
  int m = 0;
  for (int k = 0; k < n; k++)
    if (!strcmp(rows[k].element, element) && !strcmp(rows[k].method, method) && m < cap)
      out[m++] = &rows[k];
  for (int a = 0; a < m; a++)
    for (int b = a + 1; b < m; b++)
      if (out[b]->h > out[a]->h) {
        const cv_level *t = out[a];
        out[a] = out[b], out[b] = t;
      }
  return m;
}

/* Least-squares slope of log err against log h over the last `fit` of the m levels. */
static inline double cv_refit(const cv_level *const *lv, int m, int fit, int h1)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (int k = m - fit; k < m; k++) {
    if (k < 0) continue;
    const double x = log(lv[k]->h), y = log(h1 ? lv[k]->err_h1 : lv[k]->err_l2);
    sx += x, sy += y, sxx += x * x, sxy += x * y, n++;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

#endif /* FCM_TEST_CONVERGE_CSV_H */
