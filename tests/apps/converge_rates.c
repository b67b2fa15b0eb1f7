/* fcm-converge convergence rates on the manufactured problem (exact error known): FCM on
 * the embedded hemisphere converges at the optimal rates — L2 >= 1.9 for Tet4/Hex8 and
 * >= 2.8 for Tet10/Hex20, H1 seminorm >= 0.9 and >= 1.9 — with errors decreasing at every
 * refinement, while the staircase FEM of the quadratic elements is held near first order by
 * its geometry: L2 rate <= 1.2 and at least 1.5 below FCM's, H1 rate <= 0.9, fitted like
 * the study (finest 3 of res 6, 8, 12, 16: 1.18 for Tet10, 1.15 for Hex20). The staircase's
 * fit to the surface changes irregularly from level to level, so its 3-level rates wander
 * (0.8 to 1.5 over other level choices; 1.10 and 1.22 fitted over res 6, 8, 10, 12, 16)
 * around the asymptotic first order. The rates in the rates CSV must equal a refit of the
 * levels CSV, and every FCM error is measured over all of Omega.
 * With --boundary nitsche (the exact displacement imposed on the curved boundary by
 * symmetric Nitsche instead of the traction; method fcm-nitsche) the same rates hold, with
 * tolerances L2 >= 1.8 / 2.7, H1 >= 0.9 / 1.8.
 * Usage: app_converge_rates quick|full PATH_TO_fcm-converge WORK_DIR
 *   quick (default suite): Hex8 and Tet10 FCM on levels 3, 4, 6 (geometry n = 4);
 *   full (label slow): every element: FCM Tet4/Hex8 on res 6, 8, 12, 16, Tet10/Hex20 on
 *   4, 6, 8; the staircase FEM of Tet10/Hex20 on 6, 8, 12, 16. */
#define _POSIX_C_SOURCE 200809L
#include "converge_csv.h"

static cv_level levels[CV_MAX_ROWS];
static cv_rate_row rates[CV_MAX_ROWS];

/* Run one study; returns the number of level rows (and fills `rates`), or -1. */
static int study(const char *prog, const char *dir, const char *name, const char *args, int fit,
                 int *nrates)
{
  char cmd[8192], csv[1024], rcsv[1024];
  snprintf(csv, sizeof csv, "%s/%s-levels.csv", dir, name);
  snprintf(rcsv, sizeof rcsv, "%s/%s-rates.csv", dir, name);
  remove(csv);
  remove(rcsv);
  snprintf(cmd, sizeof cmd,
           "OMP_WAIT_POLICY=passive '%s' %s --fit %d --no-sweep --no-plots --out '%s/%s' "
           "> /dev/null 2> '%s/%s.log'",
           prog, args, fit, dir, name, dir, name);
  const int rc = app_run(cmd);
  if (rc != 0) fprintf(stderr, "%s exited with %d (log %s/%s.log)\n", name, rc, dir, name);
  TEST_TRUE(rc == 0);
  *nrates = cv_read_rates(rcsv, rates, CV_MAX_ROWS);
  TEST_TRUE(*nrates > 0);
  const int n = cv_read_levels(csv, levels, CV_MAX_ROWS);
  TEST_TRUE(n > 0);
  return n;
}

/* Rate bounds and monotone decrease of one (element, method) series; returns the L2 rate. */
static double check(int n, int nrates, int fit, const char *element, const char *method,
                    double l2_lo, double l2_hi, double h1_lo, double h1_hi)
{
  const cv_level *lv[64];
  const int m = cv_select(levels, n, element, method, lv, 64);
  TEST_TRUE(m >= 3);
  for (int k = 0; k < m; k++) {
    TEST_TRUE(lv[k]->failed == 0 && lv[k]->dofs > 0);
    if (strcmp(method, "fem")) TEST_NEAR(lv[k]->measured, lv[k]->domain, 1e-9, 0.0);
    if (!strcmp(method, "fem")) TEST_TRUE(lv[k]->measured <= lv[k]->domain * (1.0 + 1e-12));
    if (k > 0) {
      if (!(lv[k]->err_l2 < lv[k - 1]->err_l2 && lv[k]->err_h1 < lv[k - 1]->err_h1))
        fprintf(stderr, "%s %s: error grew from res %d to %d\n", element, method, lv[k - 1]->res,
                lv[k]->res);
      TEST_TRUE(lv[k]->err_l2 < lv[k - 1]->err_l2);
      TEST_TRUE(lv[k]->err_h1 < lv[k - 1]->err_h1);
    }
  }
  const cv_rate_row *l2 = cv_find_rate(rates, nrates, element, method, "L2");
  const cv_rate_row *h1 = cv_find_rate(rates, nrates, element, method, "H1");
  TEST_TRUE(l2 && h1);
  if (!l2 || !h1 || m < 2) return NAN;
  TEST_NEAR(l2->rate, cv_refit(lv, m, fit, 0), 1e-4, 1e-5);
  TEST_NEAR(h1->rate, cv_refit(lv, m, fit, 1), 1e-4, 1e-5);
  if (!(l2->rate >= l2_lo && l2->rate <= l2_hi && h1->rate >= h1_lo && h1->rate <= h1_hi))
    fprintf(stderr, "%s %s: L2 rate %.3f (expected [%g, %g]), H1 rate %.3f (expected [%g, %g])\n",
            element, method, l2->rate, l2_lo, l2_hi, h1->rate, h1_lo, h1_hi);
  TEST_TRUE(l2->rate >= l2_lo && l2->rate <= l2_hi);
  TEST_TRUE(h1->rate >= h1_lo && h1->rate <= h1_hi);
  return l2->rate;
}

int main(int argc, char **argv)
{
  if (argc != 4) return 2;
  const char *prog = argv[2], *dir = argv[3];
  int n = 0, nr = 0;
  if (!strcmp(argv[1], "quick")) {
    n = study(prog, dir, "converge-rates-quick",
              "--elements hex8,tet10 --methods fcm --levels 3,4,6 --geom-n 4", 3, &nr);
    check(n, nr, 3, "hex8", "fcm", 1.9, 2.6, 0.9, 1.6);
    check(n, nr, 3, "tet10", "fcm", 2.8, 3.6, 1.9, 2.6);
    /* the exact displacement imposed weakly on the curved boundary (symmetric
     * Nitsche, --boundary nitsche): the same optimal rates (measured 2.08 / 1.07 for Hex8,
     * 2.97 / 1.96 for Tet10 on these levels) */
    n = study(prog, dir, "converge-rates-nitsche-quick",
              "--boundary nitsche --elements hex8,tet10 --methods fcm --levels 3,4,6 --geom-n 4", 3,
              &nr);
    check(n, nr, 3, "hex8", "fcm-nitsche", 1.8, 2.6, 0.9, 1.6);
    check(n, nr, 3, "tet10", "fcm-nitsche", 2.7, 3.6, 1.8, 2.6);
  } else if (!strcmp(argv[1], "full")) {
    n = study(prog, dir, "converge-rates-linear",
              "--elements tet4,hex8 --methods fcm --levels 6,8,12,16", 3, &nr);
    check(n, nr, 3, "tet4", "fcm", 1.9, 2.6, 0.9, 1.6);
    check(n, nr, 3, "hex8", "fcm", 1.9, 2.6, 0.9, 1.6);
    n = study(prog, dir, "converge-rates-quadratic",
              "--elements tet10,hex20 --methods fcm --levels 4,6,8", 3, &nr);
    const double t10 = check(n, nr, 3, "tet10", "fcm", 2.8, 3.6, 1.9, 2.6);
    const double h20 = check(n, nr, 3, "hex20", "fcm", 2.8, 3.6, 1.9, 2.6);
    n = study(prog, dir, "converge-rates-staircase",
              "--elements tet10,hex20 --methods fem --levels 6,8,12,16", 3, &nr);
    TEST_TRUE(check(n, nr, 3, "tet10", "fem", 0.0, 1.2, 0.0, 0.9) <= t10 - 1.5);
    TEST_TRUE(check(n, nr, 3, "hex20", "fem", 0.0, 1.2, 0.0, 0.9) <= h20 - 1.5);
    n = study(prog, dir, "converge-rates-nitsche-linear",
              "--boundary nitsche --elements tet4,hex8 --methods fcm --levels 6,8,12,16", 3, &nr);
    check(n, nr, 3, "tet4", "fcm-nitsche", 1.8, 2.6, 0.9, 1.6);
    check(n, nr, 3, "hex8", "fcm-nitsche", 1.8, 2.6, 0.9, 1.6);
    n = study(prog, dir, "converge-rates-nitsche-quadratic",
              "--boundary nitsche --elements tet10,hex20 --methods fcm --levels 4,6,8", 3, &nr);
    check(n, nr, 3, "tet10", "fcm-nitsche", 2.7, 3.6, 1.8, 2.6);
    check(n, nr, 3, "hex20", "fcm-nitsche", 2.7, 3.6, 1.8, 2.6);
  } else {
    return 2;
  }
  return TEST_RESULT();
}
