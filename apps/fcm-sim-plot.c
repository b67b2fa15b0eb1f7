/* fcm-sim --plot: the per-step log <name>_log.csv drawn against time with gnuplot into
 * <name>_log.png, through the script <name>_log.gp kept beside it (the log's columns as a
 * data block, then the panels: `gnuplot <name>_log.gp` draws it again). Panels: the total
 * energy (J), the linear momentum (kg m/s), the Newton iterations per step and, when the scene
 * has fixed or motion effects, their reactions (N). */
#include "fcm-sim-plot.h"

#include "cli.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Columns of the log the plot uses: time, energy, momentum x y z, newton, then per reaction
 * effect its x y z (at most SIM_PLOT_MAX_REACTIONS effects). */
#define SIM_PLOT_MAX_REACTIONS 8
#define SIM_PLOT_COLS          (6 + 3 * SIM_PLOT_MAX_REACTIONS)

typedef struct plot_columns {
  int index[SIM_PLOT_COLS]; /* the log's column of each plotted value */
  int effect[SIM_PLOT_MAX_REACTIONS];
  int num_reactions;
} plot_columns;

/* The log's header line into cols; 0 when a column the plot needs is missing. */
static int find_columns(char *header, plot_columns *cols)
{
  static const char *const fixed[6] = {"time",       "energy",     "momentum_x",
                                       "momentum_y", "momentum_z", "newton_iterations"};
  for (int k = 0; k < SIM_PLOT_COLS; k++)
    cols->index[k] = -1;
  cols->num_reactions = 0;
  int c = 0;
  for (char *tok = strtok(header, ",\r\n"); tok; tok = strtok(NULL, ",\r\n"), c++) {
    for (int k = 0; k < 6; k++)
      if (!strcmp(tok, fixed[k])) cols->index[k] = c;
    int effect = 0, used = 0;
    char axis = 0;
    if (sscanf(tok, "reaction_%d_%c%n", &effect, &axis, &used) == 2 && tok[used] == '\0' &&
        axis >= 'x' && axis <= 'z') {
      int r = 0;
      while (r < cols->num_reactions && cols->effect[r] != effect)
        r++;
      if (r == cols->num_reactions) {
        if (r == SIM_PLOT_MAX_REACTIONS) continue; /* the first ones are drawn */
        cols->effect[cols->num_reactions++] = effect;
      }
      cols->index[6 + 3 * r + (axis - 'x')] = c;
    }
  }
  for (int k = 0; k < 6 + 3 * cols->num_reactions; k++)
    if (cols->index[k] < 0) return 0;
  return 1;
}

typedef struct text {
  char *s;
  size_t n, cap;
} text;

static int text_add(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Append to t (grown as needed); 0 when out of memory. */
static int text_add(text *t, const char *fmt, ...)
{
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    const int w = vsnprintf(t->s ? t->s + t->n : NULL, t->s ? t->cap - t->n : 0, fmt, ap);
    va_end(ap);
    if (w < 0) return 0;
    if (t->s && t->n + (size_t)w < t->cap) {
      t->n += (size_t)w;
      return 1;
    }
    const size_t cap = 2 * (t->cap + (size_t)w) + 4096;
    char *q = realloc(t->s, cap);
    if (!q) return 0;
    t->s = q, t->cap = cap;
  }
}

/* The log's rows as a gnuplot data block $LOG of the plotted columns; *rows counts them. */
static int add_data(text *t, FILE *f, const plot_columns *cols, long long *rows, double *newton)
{
  char line[16384];
  const int n = 6 + 3 * cols->num_reactions;
  *rows = 0;
  *newton = 0;
  if (!text_add(t, "$LOG << EOD\n# time energy momentum_x momentum_y momentum_z newton")) return 0;
  for (int r = 0; r < cols->num_reactions; r++)
    for (int a = 0; a < 3; a++)
      if (!text_add(t, " reaction_%d_%c", cols->effect[r], 'x' + a)) return 0;
  if (!text_add(t, "\n")) return 0;
  while (fgets(line, sizeof line, f)) {
    const char *field[512];
    int nf = 0;
    for (char *tok = strtok(line, ",\r\n"); tok && nf < 512; tok = strtok(NULL, ",\r\n"))
      field[nf++] = tok;
    for (int k = 0; k < n; k++)
      if (cols->index[k] >= nf || !text_add(t, k ? " %s" : "%s", field[cols->index[k]])) return 0;
    const double it = strtod(field[cols->index[5]], NULL);
    if (it > *newton) *newton = it;
    if (!text_add(t, "\n")) return 0;
    (*rows)++;
  }
  return text_add(t, "EOD\n");
}

/* The panels: energy, momentum, Newton iterations and, with reaction columns, the reactions. */
static int add_panels(text *t, const char *logname, const plot_columns *cols, double newton)
{
  const int panels = cols->num_reactions ? 4 : 3;
  /* the energy as its change from the first row's (a body's potential energy may be orders
   * larger than the change), the iterations with integer ticks; the keys in a quarter of
   * headroom above the data */
  if (!text_add(
          t,
          "set termoption noenhanced\n"
          "set multiplot layout %s title '%s: the per-step log against time' font ',13'\n"
          "set grid\nset xlabel 'time t (s)'\nset format y '%%.3g'\n"
          "set key top right horizontal font ',10' opaque box\nset offsets 0, 0, graph 0.25, 0\n"
          "set lmargin 13\n"
          "stats $LOG using 2 every ::0::0 nooutput\nE0 = STATS_min\n"
          "set title 'total energy (kinetic + elastic + potential)'\n"
          "set ylabel 'E - E(first step) (J)'\n"
          "plot $LOG using 1:($2 - E0) with lines lw 2 lc rgb '%s' "
          "title sprintf('E(first step) = %%.6g J', E0)\n"
          "set title 'linear momentum'\nset ylabel 'momentum (kg m/s)'\n"
          "plot $LOG using 1:3 with lines lw 2 lc rgb '%s' title 'x', '' using 1:4 with "
          "lines lw 2 lc rgb '%s' title 'y', '' using 1:5 with lines lw 2 lc rgb '%s' "
          "title 'z'\n"
          "set title 'Newton iterations per step'\nset ylabel 'iterations'\n"
          "set yrange [0:%g]\nset ytics %g\nset format y '%%g'\n"
          "plot $LOG using 1:6 with linespoints lw 2 pt 7 ps 0.6 lc rgb '%s' "
          "title 'Newton iterations of the step'\n"
          "set yrange [*:*]\nset ytics autofreq\nset format y '%%.3g'\n",
          panels == 4 ? "2,2" : "1,3", logname, cli_palette[0], cli_palette[0], cli_palette[1],
          cli_palette[2], newton + 1, newton > 8 ? ceil(newton / 8) : 1.0, cli_palette[0]))
    return 0;
  if (panels == 3) return text_add(t, "unset multiplot\n");
  /* one colour per component for one effect; per effect (dash per component) for several */
  if (!text_add(t, "set title 'reactions of the fixed and motion effects'\n"
                   "set ylabel 'force on the body (N)'\nplot"))
    return 0;
  for (int r = 0; r < cols->num_reactions; r++)
    for (int a = 0; a < 3; a++) {
      const int one = cols->num_reactions == 1;
      const char *colour = cli_palette[one ? a : r % CLI_PALETTE_SIZE];
      if (!text_add(t, "%s $LOG using 1:%d with lines lw 2 dt %d lc rgb '%s' title 'effect %d, %c'",
                    r || a ? "," : "", 7 + 3 * r + a, one ? 1 : a + 1, colour, cols->effect[r],
                    'x' + a))
        return 0;
    }
  return text_add(t, "\nunset multiplot\n");
}

int sim_plot_log(const char *prog, const char *logpath)
{
  char script[4096], png[4096], header[16384];
  const size_t len = strlen(logpath);
  if (len < 4 || strcmp(logpath + len - 4, ".csv") != 0 || len + 1 > sizeof script) {
    fprintf(stderr, "%s: --plot: the log %s does not end in .csv\n", prog, logpath);
    return 0;
  }
  snprintf(script, sizeof script, "%.*s.gp", (int)(len - 4), logpath);
  snprintf(png, sizeof png, "%.*s.png", (int)(len - 4), logpath);
  FILE *f = fopen(logpath, "r");
  if (!f) {
    fprintf(stderr, "%s: --plot: cannot read %s\n", prog, logpath);
    return 0;
  }
  plot_columns cols;
  text t = {NULL, 0, 0};
  long long rows = 0;
  double newton = 0;
  int ok = fgets(header, sizeof header, f) != NULL && find_columns(header, &cols);
  if (!ok) fprintf(stderr, "%s: --plot: %s lacks the columns of a log\n", prog, logpath);
  const char *base = strrchr(logpath, '/');
  ok = ok && add_data(&t, f, &cols, &rows, &newton) &&
       add_panels(&t, base ? base + 1 : logpath, &cols, newton);
  fclose(f);
  if (ok && rows == 0) {
    fprintf(stderr, "%s: --plot: %s has no step yet; %s not written\n", prog, logpath, png);
    free(t.s);
    return 1;
  }
  ok = ok && cli_gnuplot_script_png(
                 prog, script, cols.num_reactions ? "1200,900 font ',11'" : "1500,500 font ',11'",
                 png, t.s);
  free(t.s);
  return ok;
}
