/* Roofline benchmark: what one core can do and what fcm's kernels get of it, with the
 * OpenBLAS kernels OpenBLAS falls back to on a CPU it does not know (Prescott, SSE3) and with
 * the ones fcm selects for the CPU (fcm_blas_info_get(): SkylakeX, Zen, Haswell, ...).
 *
 *   bench_roofline [CSV [CELLS]]   CSV: the table as CSV (default bench_roofline.csv),
 *                                  CELLS: Hex8 cells per direction of the elasticity box (24)
 *
 * OpenBLAS reads OPENBLAS_CORETYPE only when it loads, so the program runs itself once per
 * kernel set ("child" mode, one OpenMP and one BLAS thread, times in CPU seconds: on cores
 * shared with other work the wall clock would measure that work too) and collects the rows;
 * OpenBLAS's own choice is measured too when it is neither. `bench_roofline child CELLS [ROW]`
 * prints the raw rows of the kernels it is started with (e.g. another BLAS preloaded), or the
 * one row named ROW (`once` likewise). fcm's own element
 * kernels and CSR SpMV do not use the BLAS: one more child (`bench_roofline once CELLS`) measures
 * them once, kernel set "any" in the table, and a last line gives their time per cell. Each row
 * is a time, a rate (GFLOP/s or GB/s) and the fraction of the core's measured peak: the best DGEMM
 * rate for flop-bound rows, the best STREAM triad bandwidth for memory-bound rows. Prints the
 * table, writes the CSV and ends with a one-line summary. Asserts that each CHOLMOD solve has a
 * small residual and that the kernel sets give the same solution to round-off. Label bench: never
 * in the default run. The simplification rows end with one line per
 * strength comparing their paths (run_simp()).
 * This file is the driver (the rows' table, the children, the report); the rows are measured in
 * roofline_peaks.c (DGEMM, triad, CHOLMOD), roofline_kernels.c (fcm's element kernels, SpMV)
 * and roofline_simplify.c (simplification), declared in roofline.h. */
#define _POSIX_C_SOURCE 200809L /* popen, readlink */
#include "roofline.h"
#include "test.h"

#include <unistd.h>

enum { MAX_ROWS = 64 };

#define SIMP_ITEMS(m)                                                                              \
  {"simp_fit_m" #m, "GFLOP/s", "dgemm", run_simp_fit_m##m},                                        \
      {"simp_elim1_m" #m, "GFLOP/s", "dgemm", run_simp_elim1_m##m},                                \
  {                                                                                                \
    "simp_elim_m" #m, "GFLOP/s", "dgemm", run_simp_elim_m##m                                       \
  }

/* The rows, in order. A kernel of fcm goes here as one more entry (element stiffness and
 * tangent assembly against "dgemm", CSR SpMV and mass assembly against "triad"); the peaks
 * ("dgemm", "triad") come first. */
static const bench_item items[] = {
    {"dgemm", "GFLOP/s", "dgemm", run_dgemm},
    {"triad", "GB/s", "triad", run_triad},
    {"cholmod_factor", "GFLOP/s", "dgemm", run_cholmod},
    SIMP_ITEMS(3),
    SIMP_ITEMS(5),
    SIMP_ITEMS(7),
    SIMP_ITEMS(9),
};
enum { NITEMS = sizeof items / sizeof items[0] };

/* fcm's kernels that do not use the BLAS: measured once (kernel set "any"), not per set. */
static const bench_item once_items[] = {
    {"hex8_stiffness", "GFLOP/s", "dgemm", run_hex8_stiffness},
    {"hex20_stiffness", "GFLOP/s", "dgemm", run_hex20_stiffness},
    {"tet10_stiffness", "GFLOP/s", "dgemm", run_tet10_stiffness},
    {"hex20_snh", "GFLOP/s", "dgemm", run_hex20_snh},
    {"hex20_mass", "GB/s", "triad", run_hex20_mass},
    {"csr_spmv", "GB/s", "triad", run_spmv},
};
enum { NALL = NITEMS + (int)(sizeof once_items / sizeof once_items[0]) };

/* Item i of items[] followed by once_items[] (i < NALL). */
static const bench_item *item_at(int i)
{
  return i < NITEMS ? &items[i] : &once_items[i - NITEMS];
}

/* The number of items measured per kernel set (once = 0) or once (once = 1). */
static int count_items(int once)
{
  return once ? NALL - NITEMS : NITEMS;
}

/* Child: one line "ROW item size seconds work check" per item measured per kernel set
 * (once = 0) or once (once = 1) on stdout; only the item named `only` when it is not NULL. */
static int child(int cells, int once, const char *only)
{
  fcm_blas_set_num_threads(1);
  fcm_ctx_options o = fcm_ctx_options_default();
  o.num_threads = 1;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(&o, &ctx));
  if (!ctx) return 1;
  for (int i = once ? NITEMS : 0; i < (once ? NALL : NITEMS); i++) {
    bench_result r = {0, 0, 0, 0};
    if (only && strcmp(only, item_at(i)->name)) continue;
    if (!item_at(i)->run(ctx, cells, &r)) {
      TEST_FAIL_("bench_roofline: %s failed", item_at(i)->name);
      continue;
    }
    printf("ROW %s %.17g %.17g %.17g %.17g\n", item_at(i)->name, r.size, r.seconds, r.work,
           r.check);
    fflush(stdout);
  }
  fcm_ctx_destroy(&ctx);
  test_failures_ += roofline_failures;
  return TEST_RESULT();
}

/* ------------------------------------------------------------------ parent: the table */

typedef struct row {
  char set[32];  /* kernel set */
  char role[16]; /* "fallback", "selected", "loaded" */
  int item;
  bench_result r;
} row;

/* The index of the item named `name` in items[] then once_items[], -1 when none is. */
static int item_index(const char *name)
{
  for (int i = 0; i < NALL; i++)
    if (!strcmp(item_at(i)->name, name)) return i;
  return -1;
}

/* The children's environment: one BLAS and one OpenMP thread. OMP_THREAD_LIMIT too: CHOLMOD
 * (SuiteSparse 5.x) runs the scatter loops of its supernodal factorization in OpenMP teams of a
 * size fixed when it was built (num_threads(CHOLMOD_OMP_NUM_THREADS), 4 in Debian's build),
 * which OMP_NUM_THREADS does not limit; their CPU time would count in a one-thread row. */
#define ONE_THREAD "OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 OMP_THREAD_LIMIT=1"

/* Run `self child CELLS` (once: `self once CELLS`, the items that do not use the BLAS) under
 * OPENBLAS_CORETYPE=core (NULL: as loaded) and append its rows. */
static void measure(const char *self, int cells, const char *core, const char *role, int once,
                    row *rows, int *nrows)
{
  char cmd[4200];
  const char *mode = once ? "once" : "child";
  if (core)
    snprintf(cmd, sizeof cmd, "OPENBLAS_CORETYPE=%s " ONE_THREAD " '%s' %s %d", core, self, mode,
             cells);
  else
    snprintf(cmd, sizeof cmd, ONE_THREAD " '%s' %s %d", self, mode, cells);
  FILE *p = popen(cmd, "r");
  TEST_TRUE(p != NULL);
  if (!p) return;
  char line[512], name[64];
  int got = 0;
  while (fgets(line, sizeof line, p)) {
    row w;
    memset(&w, 0, sizeof w);
    if (*nrows >= MAX_ROWS || sscanf(line, "ROW %63s %lf %lf %lf %lf", name, &w.r.size,
                                     &w.r.seconds, &w.r.work, &w.r.check) != 5)
      continue;
    w.item = item_index(name);
    if (w.item < 0) continue;
    snprintf(w.set, sizeof w.set, "%s", once ? "any" : core ? core : "as loaded");
    snprintf(w.role, sizeof w.role, "%s", role);
    rows[(*nrows)++] = w;
    got++;
  }
  TEST_TRUE(pclose(p) == 0);
  TEST_TRUE(got == count_items(once));
}

/* GFLOP/s or GB/s (work in flops or bytes). */
static double rate(const row *w)
{
  return w->r.seconds > 0 ? 1e-9 * w->r.work / w->r.seconds : 0.0;
}

/* The best rate of the item named `name` over all rows (the peak), 0 when none. */
static double peak_of(const row *rows, int nrows, const char *name)
{
  double p = 0.0;
  for (int i = 0; i < nrows; i++)
    if (!strcmp(item_at(rows[i].item)->name, name)) p = fmax(p, rate(&rows[i]));
  return p;
}

/* The row of item `name` measured with the kernel set of role `role`, or NULL. */
static const row *find(const row *rows, int nrows, const char *name, const char *role)
{
  for (int i = 0; i < nrows; i++)
    if (!strcmp(item_at(rows[i].item)->name, name) && !strcmp(rows[i].role, role)) return &rows[i];
  return NULL;
}

static void report(const row *rows, int nrows, const char *csv_path)
{
  FILE *csv = fopen(csv_path, "w");
  TEST_TRUE(csv != NULL);
  if (csv) fprintf(csv, "kernels,role,item,size,cpu_seconds,rate,unit,peak,fraction_of_peak\n");
  printf("%-12s %-9s %-15s %10s %10s %10s %-8s %7s\n", "kernels", "role", "item", "size", "cpu s",
         "rate", "unit", "peak");
  for (int i = 0; i < nrows; i++) {
    const row *w = &rows[i];
    const bench_item *it = item_at(w->item);
    const double pk = peak_of(rows, nrows, it->peak), x = rate(w);
    printf("%-12s %-9s %-15s %10.0f %10.4f %10.2f %-8s %6.1f%%\n", w->set, w->role, it->name,
           w->r.size, w->r.seconds, x, it->unit, pk > 0 ? 100.0 * x / pk : 0.0);
    if (csv)
      fprintf(csv, "%s,%s,%s,%.0f,%.6g,%.6g,%s,%s,%.4f\n", w->set, w->role, it->name, w->r.size,
              w->r.seconds, x, it->unit, it->peak, pk > 0 ? x / pk : 0.0);
  }
  if (csv) TEST_TRUE(fclose(csv) == 0);
}

/* One line: the peaks, and CHOLMOD with the selected kernels against the fallback. */
static void summary(const row *rows, int nrows)
{
  const row *gs = find(rows, nrows, "dgemm", "selected"),
            *gf = find(rows, nrows, "dgemm", "fallback");
  const row *cs = find(rows, nrows, "cholmod_factor", "selected");
  const row *cf = find(rows, nrows, "cholmod_factor", "fallback");
  const double dpk = peak_of(rows, nrows, "dgemm"), tpk = peak_of(rows, nrows, "triad");
  printf("roofline: DGEMM peak %.1f GFLOP/s, triad %.1f GB/s", dpk, tpk);
  if (gs && gf) printf("; DGEMM %s %.1f vs %s %.1f GFLOP/s", gs->set, rate(gs), gf->set, rate(gf));
  if (cs && cf)
    printf("; CHOLMOD factor (%.0f DOFs) %.3f s (%.0f%% of peak) vs %.3f s: %.2fx", cs->r.size,
           cs->r.seconds, 100.0 * rate(cs) / dpk, cf->r.seconds, cf->r.seconds / cs->r.seconds);
  printf("\n");
}

/* fcm's kernels (the rows measured once): time per cell (per SpMV for csr_spmv) and the
 * fraction of the peak, one line. */
static void report_kernels(const row *rows, int nrows)
{
  const double dpk = peak_of(rows, nrows, "dgemm"), tpk = peak_of(rows, nrows, "triad");
  printf("fcm kernels (any kernel set):");
  for (int i = 0; i < nrows; i++) {
    const row *w = &rows[i];
    const bench_item *it = item_at(w->item);
    if (w->item < NITEMS) continue;
    const double pk = strcmp(it->peak, "dgemm") ? tpk : dpk;
    if (strcmp(it->name, "csr_spmv"))
      printf(" %s %.2f us/cell %.1f%%;", it->name, 1e6 * w->r.seconds / w->r.size,
             pk > 0 ? 100.0 * rate(w) / pk : 0.0);
    else
      printf(" %s %.2f ms %.1f%%;", it->name, 1e3 * w->r.seconds,
             pk > 0 ? 100.0 * rate(w) / pk : 0.0);
  }
  printf("\n");
}

/* One line per strength: ms per cell of the default path (the surface path's fit), the rank-1
 * elimination (the old path) and the blocked one, with the kernels fcm selects (or the only set
 * measured), and the default and the blocked elimination against the rank-1 one. */
static void simp_summary(const row *rows, int nrows)
{
  const char *role = find(rows, nrows, "dgemm", "selected") ? "selected" : "loaded";
  static const int ms[] = {3, 5, 7, 9};
  for (int k = 0; k < 4; k++) {
    char n[3][32];
    const row *w[3];
    snprintf(n[0], sizeof n[0], "simp_fit_m%d", ms[k]);
    snprintf(n[1], sizeof n[1], "simp_elim1_m%d", ms[k]);
    snprintf(n[2], sizeof n[2], "simp_elim_m%d", ms[k]);
    for (int p = 0; p < 3; p++)
      w[p] = find(rows, nrows, n[p], role);
    if (!w[0] || !w[1] || !w[2]) continue;
    printf("simplification m = %d (%s kernels), ms per cell: default (fit) %.3f, elimination "
           "rank-1 (old) %.3f, blocked %.3f; against the old: default %.2fx, blocked %.2fx\n",
           ms[k], role, 1e3 * w[0]->r.seconds, 1e3 * w[1]->r.seconds, 1e3 * w[2]->r.seconds,
           w[1]->r.seconds / w[0]->r.seconds, w[1]->r.seconds / w[2]->r.seconds);
  }
}

int main(int argc, char **argv)
{
  if (argc >= 3 && !strcmp(argv[1], "child")) return child(atoi(argv[2]), 0, argv[3]);
  if (argc >= 3 && !strcmp(argv[1], "once")) return child(atoi(argv[2]), 1, argv[3]);
  const char *csv = argc > 1 ? argv[1] : "bench_roofline.csv";
  const int cells = argc > 2 ? atoi(argv[2]) : 24;
  if (cells < 2 || cells > 200) {
    fprintf(stderr, "usage: bench_roofline [CSV [CELLS in 2..200]]\n");
    return 2;
  }
  char self[4096];
  const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
  if (len <= 0) {
    fprintf(stderr, "bench_roofline: cannot find its own executable\n");
    return 1;
  }
  self[len] = '\0';

  fcm_blas_info b;
  TEST_TRUE(fcm_blas_info_get(NULL, &b) == FCM_OK);
  printf("BLAS: %s, kernels %s (%s) as loaded%s; CPU %s: %s\n", b.config[0] ? b.config : b.name,
         b.core[0] ? b.core : "unknown", fcm_isa_name(b.core_isa),
         b.fallback ? " (a fallback)" : "", fcm_isa_name(b.cpu_isa),
         b.cpu_core[0] ? b.cpu_core : "no kernel set to select");
  row rows[MAX_ROWS];
  int nrows = 0;
  if (strcmp(b.name, "OpenBLAS") == 0 && b.cpu_core[0]) {
    /* the set OpenBLAS falls back to on a CPU it does not know, then the selected one */
    measure(self, cells, "Prescott", "fallback", 0, rows, &nrows);
    measure(self, cells, b.cpu_core, "selected", 0, rows, &nrows);
    /* and OpenBLAS's own choice, when it is a third set */
    if (b.core[0] && strcmp(b.core, "Prescott") && strcmp(b.core, b.cpu_core))
      measure(self, cells, b.core, "loaded", 0, rows, &nrows);
    measure(self, cells, b.cpu_core, "fcm", 1, rows, &nrows);
  } else {
    measure(self, cells, NULL, "loaded", 0, rows, &nrows);
    measure(self, cells, NULL, "fcm", 1, rows, &nrows);
  }
  report(rows, nrows, csv);
  /* the same solution, to round-off, with every kernel set */
  const row *c0 = find(rows, nrows, "cholmod_factor", "fallback");
  const row *c1 = find(rows, nrows, "cholmod_factor", "selected");
  if (c0 && c1) TEST_NEAR(c1->r.check, c0->r.check, 1e-10, 0.0);
  summary(rows, nrows);
  report_kernels(rows, nrows);
  simp_summary(rows, nrows);
  return TEST_RESULT();
}
