/* fcm-converge end to end: `--quick --rates-csv FILE` prints the rates table and writes the
 * documented CSV files — the rates file holds element,method,norm,rate for every element x
 * {fcm, fem} x {L2, H1} and equals a refit of the levels file; each level row is consistent
 * (h = 1/res, t_total = sum of the phases, rel = err / norm, FCM errors measured over all
 * of Omega, FEM over less); the sweep covers m = 2..5; the PNGs are PNGs (when gnuplot is
 * installed) and no .tmp file is left. `payoff --quick` (Tet4, Hex8) reports per element and
 * rule kind fewer points with simplification and a finite positive break-even equal to
 * its measured columns. Bad options, and options of the other subcommand, exit 2 and write
 * nothing.
 * Usage: app_converge PATH_TO_fcm-converge WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include "converge_csv.h"

static cv_level levels[CV_MAX_ROWS];
static cv_rate_row rates[CV_MAX_ROWS];

static int is_png(const char *path)
{
  unsigned char sig[8] = {0};
  FILE *f = fopen(path, "rb");
  const int ok = f && fread(sig, 1, 8, f) == 8 && !memcmp(sig, "\x89PNG\r\n\x1a\n", 8);
  if (f) fclose(f);
  return ok;
}

int main(int argc, char **argv)
{
  if (argc != 3) return 2;
  const char *prog = argv[1], *dir = argv[2];
  static const char *const elements[4] = {"tet4", "tet10", "hex8", "hex20"};
  static const char *const methods[2] = {"fcm", "fem"};
  static const char *const files[] = {"-levels.csv", "-sweep.csv", "-convergence.png",
                                      "-pareto.png", "-sweep.png"};
  char cmd[8192], pre[1024], path[1200], rcsv[1024], out[1024];
  snprintf(pre, sizeof pre, "%s/converge-quick", dir);
  snprintf(rcsv, sizeof rcsv, "%s/converge-quick-myrates.csv", dir);
  snprintf(out, sizeof out, "%s/converge-quick.out", dir);
  for (size_t k = 0; k < sizeof files / sizeof *files; k++) {
    snprintf(path, sizeof path, "%s%s", pre, files[k]);
    remove(path);
  }
  remove(rcsv);

  snprintf(cmd, sizeof cmd,
           "OMP_WAIT_POLICY=passive '%s' --quick --rates-csv '%s' --out '%s' > '%s' 2> /dev/null",
           prog, rcsv, pre, out);
  TEST_TRUE(app_run(cmd) == 0);
  snprintf(cmd, sizeof cmd, "grep -q '^fitted rates' '%s' && grep -q '^accuracy versus time' '%s'",
           out, out);
  TEST_TRUE(app_run(cmd) == 0);

  /* rates: 4 elements x 2 methods x 2 norms, once each, finite */
  const int nr = cv_read_rates(rcsv, rates, CV_MAX_ROWS);
  TEST_TRUE(nr == 16);
  snprintf(path, sizeof path, "%s-levels.csv", pre);
  const int n = cv_read_levels(path, levels, CV_MAX_ROWS);
  TEST_TRUE(n == 4 * 2 * 3);
  for (int e = 0; e < 4; e++)
    for (int m = 0; m < 2; m++) {
      const cv_level *lv[16];
      const int cnt = cv_select(levels, n, elements[e], methods[m], lv, 16);
      TEST_TRUE(cnt == 3);
      for (int k = 0; k < cnt; k++) {
        const cv_level *r = lv[k];
        TEST_TRUE(r->res == 2 + k && r->failed == 0 && r->dofs > 0 && r->points > 0);
        TEST_NEAR(r->h, 1.0 / r->res, 1e-14, 0.0);
        TEST_NEAR(r->t_total, r->t_rules + r->t_assembly + r->t_solve, 0.0, 5e-6);
        TEST_NEAR(r->c_total, r->c_rules + r->c_assembly + r->c_solve, 0.0, 5e-6);
        TEST_TRUE(r->c_rules >= 0.0 && r->c_assembly >= 0.0 && r->c_solve >= 0.0);
        TEST_NEAR(r->rel_l2, r->err_l2 / r->norm_l2, 1e-5, 0.0);
        TEST_NEAR(r->rel_h1, r->err_h1 / r->norm_h1, 1e-5, 0.0);
        TEST_TRUE(r->err_l2 > 0.0 && r->err_h1 > 0.0 && r->domain > 0.0);
        if (m == 0) {
          TEST_NEAR(r->measured, r->domain, 1e-9, 0.0);
          TEST_TRUE(r->cut > 0 && r->cut <= r->cells);
        } else {
          TEST_TRUE(r->measured < r->domain && r->measured > 0.5 * r->domain && r->cut == 0);
        }
      }
      for (int norm = 0; norm < 2; norm++) {
        const cv_rate_row *rr =
            cv_find_rate(rates, nr, elements[e], methods[m], norm ? "H1" : "L2");
        TEST_TRUE(rr != NULL);
        if (rr && cnt == 3) TEST_NEAR(rr->rate, cv_refit(lv, cnt, 3, norm), 1e-4, 1e-5);
      }
    }

  /* sweep: Hex20 FCM at res 2, m = 2..5 */
  snprintf(path, sizeof path, "%s-sweep.csv", pre);
  FILE *f = fopen(path, "r");
  char line[2048];
  int rows = 0;
  TEST_TRUE(f && fgets(line, sizeof line, f) &&
            !strcmp(line, "element,method,res,h,strength,points,dofs,t_rules,t_assembly,t_solve,"
                          "t_total,err_l2,err_h1,rel_l2,rel_h1,failed,note,cpu_rules,cpu_assembly,"
                          "cpu_solve,cpu_total\n"));
  while (f && fgets(line, sizeof line, f)) {
    char el[16], me[8];
    int res = 0, m = 0;
    TEST_TRUE(sscanf(line, "%15[^,],%7[^,],%d,%*[^,],%d,", el, me, &res, &m) == 4);
    TEST_TRUE(!strcmp(el, "hex20") && !strcmp(me, "fcm") && res == 2 && m == 2 + rows);
    rows++;
  }
  if (f) fclose(f);
  TEST_TRUE(rows == 4);

  /* plots and atomic writes */
  const int gnuplot = app_run("gnuplot --version > /dev/null 2>&1") == 0;
  for (size_t k = 0; k < sizeof files / sizeof *files; k++) {
    snprintf(path, sizeof path, "%s%s", pre, files[k]);
    if (strstr(files[k], ".png")) TEST_TRUE(!gnuplot || is_png(path));
    snprintf(path, sizeof path, "%s%s.tmp", pre, files[k]);
    TEST_TRUE(!app_exists(path));
  }

  /* payoff: per element and rule kind fewer points with simplification, a positive
   * simplification time, and a finite positive break-even equal to the measured columns'
   * t_simplify / (t_assembly_plain - t_assembly_simplified) */
  snprintf(path, sizeof path, "%s/converge-payoff.csv", dir);
  remove(path);
  snprintf(cmd, sizeof cmd,
           "OMP_WAIT_POLICY=passive '%s' payoff --quick --geom-n 3 --elements tet4,hex8 --csv '%s' "
           "> '%s' 2> /dev/null",
           prog, path, out);
  TEST_TRUE(app_run(cmd) == 0);
  f = fopen(path, "r");
  TEST_TRUE(f && fgets(line, sizeof line, f) &&
            !strcmp(line, "element,res,kind,strength,cut_cells,points_plain,points_simplified,"
                          "t_simplify,t_assembly_plain,t_assembly_simplified,point_cost,"
                          "simplify_per_cell,break_even_assemblies\n"));
  static const char *const prow[4][2] = {
      {"tet4", "stiffness"}, {"tet4", "mass"}, {"hex8", "stiffness"}, {"hex8", "mass"}};
  rows = 0;
  while (f && rows < 4 && fgets(line, sizeof line, f)) {
    char el[16] = "", kind[16] = "";
    int res = 0, m = 0;
    long long cut = 0, pp = 0, ps = 0;
    double ts = 0, tp = 0, tq = 0, pc = 0, pcell = 0, be = 0;
    TEST_TRUE(sscanf(line, "%15[^,],%d,%15[^,],%d,%lld,%lld,%lld,%lf,%lf,%lf,%lf,%lf,%lf", el, &res,
                     kind, &m, &cut, &pp, &ps, &ts, &tp, &tq, &pc, &pcell, &be) == 13);
    TEST_TRUE(!strcmp(el, prow[rows][0]) && !strcmp(kind, prow[rows][1]) && res == 3);
    TEST_TRUE(m >= 1 && cut > 0 && ps > 0 && ps < pp && ts > 0.0 && tp > 0.0 && tq >= 0.0);
    TEST_TRUE(tp > tq && isfinite(be) && be > 0.0);
    if (tp > tq) {
      TEST_NEAR(be, ts / (tp - tq), 1e-6, 0.0);
      TEST_NEAR(pc, (tp - tq) / (double)(pp - ps), 1e-6, 0.0);
      TEST_NEAR(pcell, ts / (double)cut, 1e-6, 0.0);
    }
    rows++;
  }
  if (f) fclose(f);
  TEST_TRUE(rows == 4);
  snprintf(cmd, sizeof cmd, "grep -q '^hex8   mass ' '%s' && grep -q 'break-even' '%s'", out, out);
  TEST_TRUE(app_run(cmd) == 0);
  snprintf(path, sizeof path, "%s/converge-payoff.csv.tmp", dir);
  TEST_TRUE(!app_exists(path));

  /* usage errors: status 2, nothing written */
  static const char *const bad[] = {
      "--levels 0", "--levels 2,2", "--elements tet5", "--methods xfem", "--simplify maybe",
      "--radius 1.5", "--fem-traction none", "--strength 0", "--bogus 1", "--fit 1",
      "payoff --elements hex9", "--levels", "--time gpu", "--methods fcm,fcm",
      "--elements hex8,hex8", "--boundary dirichlet", "--boundary nitsche --reference",
      /* each subcommand takes only its own options */
      "--res 3", "--element hex8", "payoff --error-strength 6", "payoff --no-plots", "payof"};
  snprintf(path, sizeof path, "%s/converge-bad-levels.csv", dir);
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    remove(path);
    if (!strncmp(bad[k], "payoff", 6))
      snprintf(cmd, sizeof cmd, "'%s' %s > /dev/null 2>&1", prog, bad[k]);
    else
      snprintf(cmd, sizeof cmd, "'%s' --quick --csv '%s' %s > /dev/null 2>&1", prog, path, bad[k]);
    const int rc = app_run(cmd);
    if (rc != 2) fprintf(stderr, "'%s' exited with %d\n", bad[k], rc);
    TEST_TRUE(rc == 2);
    TEST_TRUE(!app_exists(path));
  }
  snprintf(cmd, sizeof cmd, "'%s' --help | grep -q 'element,method,norm,rate'", prog);
  TEST_TRUE(app_run(cmd) == 0);
  return TEST_RESULT();
}
