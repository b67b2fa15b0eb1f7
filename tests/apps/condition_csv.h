/* Shared by the fcm-condition tests: run the program, read its CSV rows, look rows up. */
#ifndef FCM_TEST_CONDITION_CSV_H
#define FCM_TEST_CONDITION_CSV_H

#include "test.h"

#include "app_run.h"

#define CONDITION_HEADER                                                                           \
  "element,preconditioner,stabilization,min_volume_fraction,condition_number,nominal_fraction,"    \
  "lambda_min_abs,lambda_max_abs,negative_eigenvalues,dofs,schwarz_blocks,clamped_eigenvalues,"    \
  "minres_iterations,minres_reason,minres_true_residual,tangent,fictitious,"                       \
  "preconditioner_tangent\n"

typedef struct cond_row {
  char element[16], prec[16], reason[32], tangent[16], fictitious[16], pc_tangent[16];
  double alpha, phi_min, kappa, phi_nominal, lmin, lmax, true_res;
  long long negative, dofs, blocks, clamped;
  int iterations;
} cond_row;

enum { COND_MAX_ROWS = 256 };

/* Read a CSV written by fcm-condition: header checked, rows into `rows`; returns the
 * number of rows, or -1 (missing file, bad header or malformed row). */
static int cond_read(const char *path, cond_row *rows, int cap)
{
  FILE *f = fopen(path, "r");
  char line[1024];
  int n = 0;
  if (!f) return -1;
  if (!fgets(line, sizeof line, f) || strcmp(line, CONDITION_HEADER) != 0) {
    fclose(f);
    return -1;
  }
  while (fgets(line, sizeof line, f)) {
    cond_row r;
    if (n >= cap ||
        sscanf(line,
               "%15[^,],%15[^,],%lf,%lf,%lf,%lf,%lf,%lf,%lld,%lld,%lld,%lld,%d,%31[^,],%lf,%15[^,],"
               "%15[^,],%15s",
               r.element, r.prec, &r.alpha, &r.phi_min, &r.kappa, &r.phi_nominal, &r.lmin, &r.lmax,
               &r.negative, &r.dofs, &r.blocks, &r.clamped, &r.iterations, r.reason, &r.true_res,
               r.tangent, r.fictitious, r.pc_tangent) != 18) {
      fclose(f);
      return -1;
    }
    rows[n++] = r;
  }
  fclose(f);
  return n;
}

/* The row of (element, preconditioner, stabilized?, nominal fraction), or NULL. */
static const cond_row *cond_find(const cond_row *rows, int n, const char *element, const char *prec,
                                 int stabilized, double phi)
{
  for (int k = 0; k < n; k++)
    if (!strcmp(rows[k].element, element) && !strcmp(rows[k].prec, prec) &&
        (rows[k].alpha > 0.0) == (stabilized != 0) && rows[k].phi_nominal == phi)
      return &rows[k];
  return NULL;
}

#endif /* FCM_TEST_CONDITION_CSV_H */
