/* fcm-condition end to end: `--quick --csv --png` writes the documented columns, one row
 * per (element, fraction, stabilization, preconditioner), with facts that hold whatever the
 * numbers: the measured smallest fraction is eps^3 = the nominal one, kappa = max|l|/min|l|
 * >= 1, 3 x (5^3 - 5^2) free DOFs, no cut cell at fraction 1 (so Schwarz = Jacobi there and
 * stabilization changes nothing), equal Schwarz variants when no eigenvalue was clamped;
 * the PNG is a PNG (when gnuplot is installed); the ideal preconditioner P^-1 gives kappa 1
 * when A = P and keeps the inertia of A; --stiffness-strength changes the cut cells' rules
 * exactly where the integrand's degree says it must; bad options (an indefinite P for
 * "exact" among them) exit 2 and write nothing.
 * Usage: app_condition PATH_TO_fcm-condition WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include "condition_csv.h"

int main(int argc, char **argv)
{
  if (argc != 3) return 2;
  char cmd[8192], csv[1024], png[1024], tmp[1100];
  static cond_row rows[COND_MAX_ROWS];
  snprintf(csv, sizeof csv, "%s/condition-quick.csv", argv[2]);
  snprintf(png, sizeof png, "%s/condition-quick.png", argv[2]);
  remove(csv);
  remove(png);

  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 '%s' --quick --csv '%s' --png '%s' "
           "> /dev/null 2>&1",
           argv[1], csv, png);
  TEST_TRUE(app_run(cmd) == 0);
  int n = cond_read(csv, rows, COND_MAX_ROWS);
  TEST_TRUE(n == 2 * 2 * 2 * 4); /* tet4, hex8 x {1, 1e-8} x {on, off} x 4 preconditioners */
  for (int k = 0; k < n; k++) {
    const cond_row *r = &rows[k];
    TEST_TRUE(!strcmp(r->element, "tet4") || !strcmp(r->element, "hex8"));
    TEST_TRUE(r->alpha == 1e-6 || r->alpha == 0.0);
    TEST_TRUE(r->phi_nominal == 1.0 || r->phi_nominal == 1e-8);
    TEST_NEAR(r->phi_min, r->phi_nominal, 1e-6, 0.0);
    TEST_TRUE(r->lmin > 0.0 && r->lmax >= r->lmin && r->kappa >= 1.0);
    TEST_NEAR(r->kappa, r->lmax / r->lmin, 2e-6, 0.0);
    TEST_TRUE(r->dofs == 3 * (125 - 25));
    TEST_TRUE(r->negative >= 0 && r->negative <= r->dofs && r->iterations >= 0);
    TEST_TRUE(!strcmp(r->tangent, "unprojected"));
    TEST_TRUE(!strcmp(r->reason, "converged-rtol") || !strcmp(r->reason, "max-iterations"));
    if (r->phi_nominal == 1.0) TEST_TRUE(r->blocks == 0 && r->clamped == 0);
    if (strncmp(r->prec, "schwarz", 7) != 0) TEST_TRUE(r->blocks == 0);
  }
  static const char *const el[2] = {"tet4", "hex8"};
  for (int e = 0; e < 2; e++) {
    const cond_row *j = cond_find(rows, n, el[e], "jacobi", 1, 1.0);
    for (int s = 0; s < 2; s++) {
      const cond_row *a = cond_find(rows, n, el[e], "schwarz", s, 1.0),
                     *b = cond_find(rows, n, el[e], "schwarz", !s, 1.0);
      TEST_TRUE(j && a && b);
      if (j && a && b) {
        TEST_NEAR(a->kappa, j->kappa, 1e-8, 0.0);
        TEST_NEAR(a->kappa, b->kappa, 1e-8, 0.0);
      }
      const cond_row *c = cond_find(rows, n, el[e], "schwarz", s, 1e-8),
                     *p = cond_find(rows, n, el[e], "schwarz-paper", s, 1e-8);
      TEST_TRUE(c && p && c->blocks > 0 && c->blocks == p->blocks);
      if (c && p && c->clamped == 0 && p->clamped == 0) TEST_NEAR(c->kappa, p->kappa, 1e-8, 0.0);
    }
  }
  snprintf(tmp, sizeof tmp, "%s.tmp", csv);
  TEST_TRUE(!app_exists(tmp));
  if (app_run("gnuplot --version > /dev/null 2>&1") == 0) {
    FILE *f = fopen(png, "rb");
    unsigned char sig[8] = {0};
    TEST_TRUE(f && fread(sig, 1, 8, f) == 8 && !memcmp(sig, "\x89PNG\r\n\x1a\n", 8));
    if (f) fclose(f);
    snprintf(tmp, sizeof tmp, "%s.tmp", png);
    TEST_TRUE(!app_exists(tmp));
  }

  /* the ideal preconditioner S = P^-1 ("exact"): with --project on A = P, so kappa = 1 and
   * MINRES converges at once; with the unprojected A, P^-1 A keeps the inertia of A */
  static cond_row ex[COND_MAX_ROWS];
  for (int proj = 0; proj < 2; proj++) {
    snprintf(cmd, sizeof cmd,
             "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 '%s' --quick --stabilization on "
             "--project %s --preconditioners exact,none --csv '%s' > /dev/null 2>&1",
             argv[1], proj ? "on" : "off", csv);
    TEST_TRUE(app_run(cmd) == 0);
    const int ne = cond_read(csv, ex, COND_MAX_ROWS);
    TEST_TRUE(ne == 2 * 2 * 2);
    for (int k = 0; k < ne; k++) {
      if (strcmp(ex[k].prec, "exact")) continue;
      const cond_row *none = cond_find(ex, ne, ex[k].element, "none", 1, ex[k].phi_nominal);
      TEST_TRUE(none != NULL && none->negative == ex[k].negative && ex[k].blocks == 0);
      if (proj) {
        TEST_NEAR(ex[k].kappa, 1.0, 1e-6, 0.0);
        TEST_TRUE(ex[k].negative == 0 && ex[k].iterations <= 2);
      }
    }
  }

  /* --stiffness-strength reaches the rules: for the constant deformation gradient the Hex8
   * stiffness integrand has total degree 4, so strengths 4 and 5 give the same system;
   * strength 2 underintegrates the cut cells (not the uncut ones: tensor Gauss) */
  double kap[3][2];
  static const int strength[3] = {2, 4, 5};
  for (int k = 0; k < 3; k++) {
    snprintf(cmd, sizeof cmd,
             "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 '%s' --quick --elements hex8 "
             "--stabilization on --preconditioners none --stiffness-strength %d --csv '%s' "
             "> /dev/null 2>&1",
             argv[1], strength[k], csv);
    TEST_TRUE(app_run(cmd) == 0);
    const int ne = cond_read(csv, ex, COND_MAX_ROWS);
    const cond_row *a = cond_find(ex, ne, "hex8", "none", 1, 1.0),
                   *b = cond_find(ex, ne, "hex8", "none", 1, 1e-8);
    TEST_TRUE(ne == 2 && a && b);
    kap[k][0] = a ? a->kappa : NAN;
    kap[k][1] = b ? b->kappa : NAN;
  }
  TEST_NEAR(kap[0][0], kap[1][0], 1e-8, 0.0);
  TEST_NEAR(kap[2][0], kap[1][0], 1e-8, 0.0);
  TEST_NEAR(kap[2][1], kap[1][1], 1e-6, 0.0);
  TEST_TRUE(fabs(kap[0][1] - kap[1][1]) > 1e-3 * kap[1][1]);

  /* usage errors: status 2, nothing written */
  static const char *const bad[] = {"--fractions 0",
                                    "--fractions 1,2",
                                    "--fractions 1:1e-3:1",
                                    "--elements tet5",
                                    "--preconditioners ilu",
                                    "--stabilization maybe",
                                    "--alpha -1",
                                    "--stiffness-strength 0",
                                    "--stiffness-strength 21",
                                    "--preconditioners exact --pc-tangent exact",
                                    "--bogus 1",
                                    "--csv"};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    remove(csv);
    snprintf(cmd, sizeof cmd, "'%s' --quick %s --csv '%s' > /dev/null 2>&1", argv[1], bad[k], csv);
    if (!strcmp(bad[k], "--csv"))
      snprintf(cmd, sizeof cmd, "'%s' --quick --csv > /dev/null 2>&1", argv[1]);
    int rc = app_run(cmd);
    if (rc != 2) fprintf(stderr, "'%s' exited with %d\n", bad[k], rc);
    TEST_TRUE(rc == 2);
    TEST_TRUE(!app_exists(csv));
  }
  snprintf(cmd, sizeof cmd, "'%s' --help | grep -q min_volume_fraction", argv[1]);
  TEST_TRUE(app_run(cmd) == 0);
  return TEST_RESULT();
}
