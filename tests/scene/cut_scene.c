/* The "cut" effect in scene runs: a spinning body cut in two during the run has one body in
 * the log before the cut and two after, the same mass on every row (1e-12), every DOF count
 * and counter as expected (one cut, only cells near the plane integrated again); a cut at
 * t = 0 (a slab in three slices) gives three bodies from the first step; a plane that
 * misses the body is a counted no-op and a crack that ends inside it separates nothing; a
 * malformed cut mesh fails when the simulation is built (effect and file:line named); bad cuts
 * are refused with messages naming the key. */
#include "scene_util.h"

#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *cut_scene(char *buf, size_t cap, const char *cuts, const char *extra)
{
  snprintf(buf, cap,
           "{\"version\": 1, \"name\": \"cut\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.25, -0.25, -0.25],"
           "   \"max\": [1.25, 0.75, 0.75]}, \"cells\": [3, 2, 2]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1, 0.5, 0.5],"
           "   \"cells\": [2, 1, 1]},"
           " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"time\": {\"dt\": 0.02, \"steps\": 5}%s,"
           " \"effects\": [{\"initial_velocity\": {\"angular_velocity\": [0, 0, 4]}}%s]}",
           extra, cuts);
  return buf;
}

/* Triangles of the last frame's embedded surface (boundary + cut faces). */
static long last_surface_cells;

/* The run summary of sim now (malloc'ed text). */
static char *summary_text(fcm_simulation *sim)
{
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  if (f) {
    fcm_simulation_summary_view(sim, f);
    fclose(f);
  }
  return text;
}

/* The line of text starting with `head` (static copy; "" when there is none). */
static const char *summary_line(const char *text, const char *head)
{
  static char line[1024];
  const char *l = text ? strstr(text, head) : NULL;
  const char *e = l ? strchr(l, '\n') : NULL;
  const size_t n = !e ? 0 : (size_t)(e - l) < sizeof line - 1 ? (size_t)(e - l) : sizeof line - 1;
  if (n) memcpy(line, l, n);
  line[n] = '\0';
  return line;
}

/* The summary after the set-up and after the run (NULL: not wanted; free them), and what its
 * memory line must say of the set-up's rules: 33 bytes per point held (each cut cell's
 * initial points with its stabilization points until the gather, and the gathered ones). */
static char *summary_setup, *summary_end;
static char rules_mib[128];
static int want_summaries;

/* Run to the end; return the log's columns pieces and mass per row. */
static int run(fcm_ctx *ctx, const char *json, long long *pieces, double *mass,
               fcm_simulation_counters *c, int *rows)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  int ok = 0;
  *rows = 0;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "cut.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim) {
    if (want_summaries) {
      const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(fcm_simulation_cell_rules(sim));
      double held = 0.0;
      for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
        held += 33.0 * (double)(rs->points_initial[k] + rs->points_simplified[k] +
                                2 * rs->points_stabilization[k]);
      snprintf(rules_mib, sizeof rules_mib, "; the set-up's cut-cell rules held about %.1f MiB ",
               held / 1048576.0);
      summary_setup = summary_text(sim);
    }
    while (!fcm_simulation_done(sim)) {
      fcm_step_info si;
      fcm_status st = fcm_simulation_step(sim, &si);
      TEST_OK(ctx, st);
      if (st != FCM_OK) break;
    }
    char path[] = "cut_scene_log.csv";
    TEST_OK(ctx, fcm_simulation_write_log(sim, path));
    FILE *f = fopen(path, "r");
    char line[1024];
    if (f && fgets(line, sizeof line, f)) {
      long long step, nw, lin;
      double t, res, en, p[3], inverted, nonfinite, tol, ek, el, wk, wall;
      while (*rows < 16 &&
             fscanf(f,
                    "%lld,%lf,%lld,%lld,%lf,%lf,%lld,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf\n",
                    &step, &t, &nw, &lin, &res, &en, &pieces[*rows], &mass[*rows], &p[0], &p[1],
                    &p[2], &inverted, &nonfinite, &tol, &ek, &el, &wk, &wall) == 18)
        (*rows)++;
    }
    if (f) fclose(f);
    remove(path);
    fcm_simulation_get_counters(sim, c);
    if (want_summaries) summary_end = summary_text(sim);
    /* a frame: the embedded surface holds the boundary and, after a cut, the cut faces */
    TEST_TRUE(mkdir("scene_cut_frames", 0755) == 0 || errno == EEXIST);
    TEST_OK(ctx, fcm_simulation_write_frame(sim, "scene_cut_frames", 0));
    FILE *vf = fopen("scene_cut_frames/cut_surface_0000.vtu", "rb");
    char head[2048] = "";
    if (vf) {
      size_t got = fread(head, 1, sizeof head - 1, vf);
      head[got] = '\0';
      fclose(vf);
    }
    const char *nc = strstr(head, "NumberOfCells=\"");
    const long cells = nc ? strtol(nc + 15, NULL, 10) : -1;
    TEST_TRUE(strstr(head, "Name=\"cut_face\"") != NULL);
    TEST_TRUE(cells >= (long)c->surface_triangles);
    last_surface_cells = cells;
    remove("scene_cut_frames/cut_surface_0000.vtu");
    remove("scene_cut_frames/cut_surface.pvd");
    remove("scene_cut_frames/cut_background_0000.vtu");
    remove("scene_cut_frames/cut_background.pvd");
    rmdir("scene_cut_frames");
    ok = 1;
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return ok;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  char buf[4096];
  long long pieces[16];
  double mass[16];
  int rows;
  fcm_simulation_counters c;

  /* cut at t = 0.04: applied before step 3 */
  want_summaries = 1;
  if (run(ctx,
          cut_scene(
              buf, sizeof buf,
              ", {\"cut\": {\"time\": 0.04, \"surface\": {\"plane\": {\"point\": [0.43, 0.25, "
              "0.25], \"normal\": [1, 0.1, 0]}}}}",
              ""),
          pieces, mass, &c, &rows)) {
    TEST_TRUE(rows == 5);
    for (int k = 0; k < rows; k++) {
      TEST_TRUE(pieces[k] == (k < 2 ? 1 : 2));
      TEST_NEAR(mass[k], 1000.0 * 0.25, 1e-12, 0);
    }
    TEST_TRUE(c.cuts == 1 && c.cuts_missed == 0 && c.pieces == 2);
    TEST_TRUE(c.cut_cells > 0 && c.cut_cells < 12);
    TEST_TRUE(last_surface_cells > (long)c.surface_triangles); /* cut faces written */
    /* the summary's set-up lines stay the set-up's; the cut has a line of its own */
    char cells[1024], cut[1024];
    snprintf(cells, sizeof cells, "%s", summary_line(summary_setup, "  cells "));
    TEST_TRUE(cells[0] != '\0' && !strcmp(cells, summary_line(summary_end, "  cells ")));
    TEST_TRUE(summary_line(summary_setup, "  cut 1 ")[0] == '\0');
    snprintf(cut, sizeof cut, "  cut 1     t = 0.04 s: %lld cells integrated again, ",
             (long long)c.cut_cells);
    TEST_TRUE(strstr(summary_end ? summary_end : "", cut) != NULL);
    TEST_TRUE(strstr(summary_line(summary_end, "  memory    peak resident "), rules_mib) != NULL);
  }
  free(summary_setup), free(summary_end);
  want_summaries = 0;
  /* two cuts at t = 0 (listed out of order, the later one first): three slices */
  if (run(ctx,
          cut_scene(buf, sizeof buf,
                    ", {\"cut\": {\"time\": 0.02, \"surface\": {\"disc\": {\"center\": [0.7, 0.25, "
                    "0.25], \"normal\": [1, 0, 0], \"radius\": 2}}}}"
                    ", {\"cut\": {\"surface\": {\"rectangle\": {\"center\": [0.3, 0.25, 0.25], "
                    "\"normal\": [1, 0, 0], \"axis\": [0, 1, 0], \"size\": [3, 3]}}}}",
                    ""),
          pieces, mass, &c, &rows)) {
    TEST_TRUE(rows == 5);
    for (int k = 0; k < rows; k++)
      TEST_TRUE(pieces[k] == (k < 1 ? 2 : 3));
    TEST_TRUE(c.cuts == 2 && c.pieces == 3);
  }
  /* a plane that misses the body, and a rectangle that ends inside it: nothing separates */
  if (run(ctx,
          cut_scene(
              buf, sizeof buf,
              ", {\"cut\": {\"surface\": {\"plane\": {\"point\": [5, 5, 5], \"normal\": [0, 0, "
              "1]}}}}, {\"cut\": {\"surface\": {\"rectangle\": {\"center\": [0.5, 0.25, 0], "
              "\"normal\": [1, 0, 0], \"axis\": [0, 0, 1], \"size\": [0.5, 2]}}}}",
              ""),
          pieces, mass, &c, &rows)) {
    TEST_TRUE(c.cuts == 2 && c.cuts_missed == 1 && c.pieces == 1);
    TEST_TRUE(c.num_dofs > 3 * 36); /* the crack did enrich nodes */
    for (int k = 0; k < rows; k++)
      TEST_TRUE(pieces[k] == 1);
  }
  /* errors */
  fcm_scene *scene = NULL;
  TEST_ERR(
      ctx,
      fcm_scene_create_from_string(
          ctx,
          cut_scene(buf, sizeof buf,
                    ", {\"cut\": {\"time\": 0.5, \"surface\": {\"plane\": {\"point\": [0, 0, 0], "
                    "\"normal\": [1, 0, 0]}}}}",
                    ""),
          "c.json", &scene),
      FCM_ERR_ARG, "effects[1].cut.time");
  TEST_ERR(
      ctx,
      fcm_scene_create_from_string(
          ctx,
          cut_scene(buf, sizeof buf,
                    ", {\"cut\": {\"surface\": {\"plane\": {\"point\": [0, 0, 0], \"normal\": [0, "
                    "0, 0]}}}}",
                    ""),
          "c.json", &scene),
      FCM_ERR_ARG, "effects[1].cut.surface.plane.normal");
  TEST_ERR(ctx,
           fcm_scene_create_from_string(
               ctx, cut_scene(buf, sizeof buf, ", {\"cut\": {\"surface\": {\"sphere\": {}}}}", ""),
               "c.json", &scene),
           FCM_ERR_ARG, "effects[1].cut.surface");
  TEST_ERR(ctx,
           fcm_scene_create_from_string(
               ctx,
               cut_scene(buf, sizeof buf,
                         ", {\"cut\": {\"surface\": {\"rectangle\": {\"center\": [0, 0, 0], "
                         "\"normal\": [1, 0, 0], \"axis\": [2, 0, 0], \"size\": [1, 1]}}}}",
                         ""),
               "c.json", &scene),
           FCM_ERR_ARG, "axis");
  TEST_ERR(ctx,
           fcm_scene_create_from_string(
               ctx,
               cut_scene(buf, sizeof buf,
                         ", {\"cut\": {\"surface\": {\"mesh\": \"no-such-cut.obj\"}}}", ""),
               "c.json", &scene),
           FCM_ERR_IO, "no-such-cut.obj");
  /* a malformed cut mesh fails when the simulation is built, naming the effect and the line */
  FILE *bad = fopen("scene_cut_bad.obj", "w");
  TEST_TRUE(bad != NULL);
  if (bad) {
    fputs("v 0 0 0\nv 1 0 0\nf 1 2 7\n", bad);
    fclose(bad);
    TEST_OK(ctx, fcm_scene_create_from_string(
                     ctx,
                     cut_scene(buf, sizeof buf,
                               ", {\"cut\": {\"time\": 0.02, \"surface\": {\"mesh\": "
                               "\"scene_cut_bad.obj\"}}}",
                               ""),
                     "c.json", &scene));
    fcm_simulation *sim = NULL;
    if (scene) {
      TEST_TRUE(fcm_simulation_create(ctx, scene, NULL, &sim) == FCM_ERR_FORMAT && !sim);
      TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "effects[1].cut.surface.mesh") &&
                strstr(fcm_ctx_error_message(ctx), "scene_cut_bad.obj:3"));
      fcm_ctx_error_clear(ctx);
    }
    fcm_scene_destroy(&scene);
    remove("scene_cut_bad.obj");
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
