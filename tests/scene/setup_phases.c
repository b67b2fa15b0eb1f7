/* The set-up's phases (fcm_simulation_options.setup_phase): for scenes that take different
 * paths (a surface alone with holes filled and a transform on a fitted grid; the same through
 * Gmsh when fcm has it; a level set on a grid; a box cut at t = 0; a voxel image with NaN
 * values; no geometry) every phase the scene needs is reported once, in the set-up's order,
 * its start before its end with the same words, the end's seconds >= 0 and equal to its counter;
 * skipped phases count 0 s; the phases fit in their parts of the set-up (time_setup_geometry,
 * _rules, _space, _integrator) and all of them in time_setup. The progress of the cell rules
 * and of the level set is reported inside their phase, and the phase says so; the library's
 * warnings (holes filled, NaN voxels) reach the context's log during the phase that raises
 * them. A set-up that fails reports the failing phase's start and no end. The summary prints
 * each part's phases. */
#include "scene_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define MAX_EVENTS 64

/* What the callbacks heard. */
typedef struct recorder {
  int n;
  fcm_setup_phase phase[MAX_EVENTS];
  int finished[MAX_EVENTS], progress[MAX_EVENTS];
  double seconds[MAX_EVENTS];
  char what[MAX_EVENTS][160];
  int open;                      /* the phase running (-1: none) */
  int progress_in, progress_out; /* progress calls inside / outside the phase that reports it */
  int warnings, warning_phase;   /* warnings logged, and the phase running at the last one */
  int order_broken;              /* a start while a phase ran, or an end of another phase */
} recorder;

static void on_phase(const fcm_setup_phase_event *ev, void *user)
{
  recorder *r = user;
  if (r->n >= MAX_EVENTS) return;
  const int k = r->n++;
  r->phase[k] = ev->phase;
  r->finished[k] = ev->finished;
  r->progress[k] = ev->progress;
  r->seconds[k] = ev->seconds;
  snprintf(r->what[k], sizeof r->what[k], "%s", ev->what ? ev->what : "");
  if (!ev->finished) {
    r->order_broken |= r->open != -1;
    r->open = (int)ev->phase;
  } else {
    r->order_broken |= r->open != (int)ev->phase;
    r->open = -1;
  }
}

/* A progress call: counted inside or outside the phase that reports it. */
static void count_progress(recorder *r, fcm_setup_phase phase)
{
  if (r->open == (int)phase)
    r->progress_in++;
  else
    r->progress_out++;
}

static void on_rules_progress(fcm_index done, fcm_index total, void *user)
{
  (void)done, (void)total;
  count_progress(user, FCM_SETUP_CELL_RULES);
}

static void on_geometry_progress(fcm_index done, fcm_index total, void *user)
{
  (void)done, (void)total;
  count_progress(user, FCM_SETUP_GEOMETRY);
}

static recorder *log_target; /* the recorder of the running set-up, for the context's log */

static void on_log(void *user, fcm_log_level level, const char *msg)
{
  (void)user;
  /* the BLAS kernel warning depends on the machine and the environment, not on the scene */
  if (level != FCM_LOG_WARNING || !log_target || !strncmp(msg, "BLAS:", 5)) return;
  log_target->warnings++;
  log_target->warning_phase = log_target->open;
}

/* scene_json() with an output section. */
static void scene_json_output(char *buf, size_t n, const char *background, const char *geometry,
                              int dynamic, double fix_z, const char *extra, const char *output)
{
  char geom[512] = "";
  if (geometry) snprintf(geom, sizeof geom, " \"geometry\": %s,", geometry);
  snprintf(buf, n,
           "{\"version\": 1, \"name\": \"phases\", \"background\": %s,%s"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"time\": %s, \"output\": %s,"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
           "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, %g],"
           "   \"normal\": [0, 0, -1]}}}}%s]}",
           background, geom,
           dynamic ? "{\"dt\": 0.01, \"steps\": 1}" : "{\"static\": true, \"steps\": 1}", output,
           fix_z, extra ? extra : "");
}

/* A scene: background, geometry, dynamic (dt 0.01) or static, gravity, the nodes with z <=
 * fix_z held, then `extra` effects (may be NULL). */
static void scene_json(char *buf, size_t n, const char *background, const char *geometry,
                       int dynamic, double fix_z, const char *extra)
{
  scene_json_output(buf, n, background, geometry, dynamic, fix_z, extra, "{}");
}

static const char grid_bg[] =
    "{\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
    " \"cells\": [3, 3, 3]}";
static const char fit_bg[] =
    "{\"element\": \"hex8\", \"fit_background\": {\"cell_size\": 0.25, \"margin\": 0.1}}";

/* Build the scene `json` (as dir/scene.json) with the phases recorded; the simulation, or NULL
 * when the create failed with `fail` (FCM_OK: expected to succeed). */
static fcm_simulation *build(fcm_ctx *ctx, const char *dir, const char *json, recorder *r,
                             int with_progress, fcm_status fail, fcm_scene **scene)
{
  char path[512];
  fcm_simulation *sim = NULL;
  memset(r, 0, sizeof *r);
  r->open = -1;
  r->warning_phase = -1;
  snprintf(path, sizeof path, "%s/scene.json", dir);
  TEST_TRUE(write_text(path, json) == 0);
  *scene = NULL;
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, scene));
  if (!*scene) return NULL;
  fcm_simulation_options o = fcm_simulation_options_default();
  o.setup_phase = on_phase;
  o.setup_phase_user = r;
  if (with_progress) {
    o.rules_progress = on_rules_progress;
    o.rules_progress_user = r;
    o.geometry_progress = on_geometry_progress;
    o.geometry_progress_user = r;
  }
  log_target = r;
  const fcm_status st = fcm_simulation_create(ctx, *scene, &o, &sim);
  log_target = NULL;
  if (fail == FCM_OK)
    TEST_OK(ctx, st);
  else {
    TEST_TRUE(st == fail && sim == NULL);
    fcm_ctx_error_clear(ctx);
  }
  return sim;
}

/* The events are the phases `want` (n of them) in order, each a start then its end; the
 * counters agree with them. Bit p of `progress`: phase p reports its progress. */
static void check_phases(const fcm_simulation *sim, const recorder *r, const fcm_setup_phase *want,
                         int n, unsigned progress)
{
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  TEST_TRUE(!r->order_broken && r->open == -1);
  TEST_TRUE(r->n == 2 * n);
  if (r->n != 2 * n) {
    for (int k = 0; k < r->n; k++)
      fprintf(stderr, "  event %d: phase %d finished %d (%s)\n", k, (int)r->phase[k],
              r->finished[k], r->what[k]);
    return;
  }
  int seen[FCM_SETUP_PHASE_COUNT] = {0};
  for (int i = 0; i < n; i++) {
    const int s = 2 * i, e = 2 * i + 1;
    TEST_TRUE(r->phase[s] == want[i] && r->phase[e] == want[i]);
    TEST_TRUE(r->finished[s] == 0 && r->finished[e] == 1);
    TEST_TRUE(r->seconds[s] == 0.0 && r->seconds[e] >= 0.0);
    TEST_TRUE(r->seconds[e] == c.time_setup_phase[want[i]]);
    TEST_TRUE(r->what[s][0] != '\0' && strcmp(r->what[s], r->what[e]) == 0);
    TEST_TRUE(r->progress[s] == (int)((progress >> want[i]) & 1u) &&
              r->progress[e] == r->progress[s]);
    TEST_TRUE(strcmp(fcm_setup_phase_name(want[i]), "?") != 0);
    seen[want[i]] = 1;
  }
  double sum = 0.0, geometry = 0.0;
  for (int p = 0; p < FCM_SETUP_PHASE_COUNT; p++) {
    if (!seen[p]) TEST_TRUE(c.time_setup_phase[p] == 0.0);
    sum += c.time_setup_phase[p];
    if (p <= FCM_SETUP_BACKGROUND) geometry += c.time_setup_phase[p];
  }
  TEST_TRUE(geometry <= c.time_setup_geometry);
  TEST_TRUE(c.time_setup_phase[FCM_SETUP_CELL_RULES] <= c.time_setup_rules);
  TEST_TRUE(c.time_setup_phase[FCM_SETUP_SPACE] <= c.time_setup_space);
  TEST_TRUE(c.time_setup_phase[FCM_SETUP_INTEGRATOR] <= c.time_setup_integrator);
  TEST_TRUE(sum <= c.time_setup);
  TEST_TRUE(c.time_setup_geometry + c.time_setup_rules + c.time_setup_space +
                c.time_setup_integrator <=
            c.time_setup);
  if (progress) TEST_TRUE(r->progress_in > 0);
  TEST_TRUE(r->progress_out == 0);
}

/* The words of phase p's start event (empty when it was not reported). */
static const char *what_of(const recorder *r, fcm_setup_phase p)
{
  for (int k = 0; k < r->n; k++)
    if (r->phase[k] == p) return r->what[k];
  return "";
}

/* The run summary of sim (malloc'ed text). */
static char *summary_text(const fcm_simulation *sim)
{
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  if (!f) return NULL;
  fcm_simulation_summary_view(sim, f);
  fclose(f);
  return text;
}

/* OBJ of the cube [0,1]^3 shifted up by 0.5 without its top face. */
static int write_open_cube(const char *path)
{
  static const double x[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                             0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  static const int t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                          3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
  char text[1024];
  size_t n = 0;
  for (int v = 0; v < 8; v++)
    n += (size_t)snprintf(text + n, sizeof text - n, "v %g %g %g\n", x[3 * v], x[3 * v + 1],
                          x[3 * v + 2] + 0.5);
  for (int k = 0; k < 12; k++)
    if (k != 2 && k != 3)
      n += (size_t)snprintf(text + n, sizeof text - n, "f %d %d %d\n", t[3 * k] + 1,
                            t[3 * k + 1] + 1, t[3 * k + 2] + 1);
  return write_text(path, text);
}

/* The open cube closed by fill_holes and translated, on a fitted grid: the surface alone
 * (volume_mesh false) or tetrahedralized by Gmsh. */
static void surface_scenes(fcm_ctx *ctx, const char *dir)
{
  char json[4096];
  recorder r;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  for (int gmsh = 0; gmsh < 2; gmsh++) {
    if (gmsh && !fcm_surface_meshing_available()) break;
    char geometry[256];
    snprintf(geometry, sizeof geometry,
             "{\"surface\": \"open.obj\", \"fill_holes\": true, \"volume_mesh\": %s,"
             " \"transform\": {\"translation\": [0.1, 0, 0]}}",
             gmsh ? "true" : "false");
    scene_json(json, sizeof json, fit_bg, geometry, 1, 0.5, NULL);
    sim = build(ctx, dir, json, &r, 1, FCM_OK, &scene);
    if (sim) {
      const fcm_setup_phase want[] = {
          FCM_SETUP_READ,          FCM_SETUP_FILL_HOLES,
          FCM_SETUP_SURFACE_CHECK, gmsh ? FCM_SETUP_VOLUME_MESH : FCM_SETUP_GEOMETRY,
          FCM_SETUP_TRANSFORM,     FCM_SETUP_BACKGROUND,
          FCM_SETUP_CELL_RULES,    FCM_SETUP_SPACE,
          FCM_SETUP_INTEGRATOR,    FCM_SETUP_LOG,
          FCM_SETUP_OUTPUT_SURFACE};
      check_phases(sim, &r, want, (int)(sizeof want / sizeof want[0]), 1u << FCM_SETUP_CELL_RULES);
      /* the hole-filling warning, logged while its phase ran */
      TEST_TRUE(r.warnings == 1 && r.warning_phase == FCM_SETUP_FILL_HOLES);
      TEST_TRUE(strstr(what_of(&r, FCM_SETUP_READ), "open.obj") != NULL);
      if (gmsh) TEST_TRUE(strstr(what_of(&r, FCM_SETUP_VOLUME_MESH), "Gmsh") != NULL);
      char *text = summary_text(sim);
      TEST_TRUE(text != NULL);
      if (text) {
        TEST_TRUE(strstr(text, "  set-up    [s] mesh and geometry ") != NULL);
        TEST_TRUE(strstr(text, "            [s] mesh and geometry: reading ") != NULL);
        TEST_TRUE(strstr(text, ", filling holes ") && strstr(text, ", surface checks ") &&
                  strstr(text, ", transform ") && strstr(text, ", background mesh "));
        TEST_TRUE(strstr(text, gmsh ? ", volume meshing (Gmsh) " : ", geometry ") != NULL);
        TEST_TRUE(strstr(text, "            [s] cell rules: index and tet rules ") != NULL);
        TEST_TRUE(strstr(text, "            [s] the rest: log mass blocks ") != NULL);
        TEST_TRUE(strstr(text, ", output surface ") != NULL);
        free(text);
      }
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  }

  /* without fill_holes the check fails: its start is reported, no end */
  scene_json(json, sizeof json, fit_bg, "{\"surface\": \"open.obj\", \"volume_mesh\": false}", 1,
             0.5, NULL);
  sim = build(ctx, dir, json, &r, 0, FCM_ERR_GEOMETRY, &scene);
  TEST_TRUE(r.n == 3 && r.phase[0] == FCM_SETUP_READ && r.finished[1] == 1 &&
            r.phase[2] == FCM_SETUP_SURFACE_CHECK && r.finished[2] == 0);
  TEST_TRUE(r.warnings == 0);
  fcm_scene_destroy(&scene);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_ctx_options co = fcm_ctx_options_default();
  co.log = on_log;
  char dir[64], path[512], json[4096];
  if (fcm_ctx_create(&co, &ctx) != FCM_OK) return 1;
  if (!make_temp_dir(dir, sizeof dir)) return 1;
  snprintf(path, sizeof path, "%s/open.obj", dir);
  TEST_TRUE(write_open_cube(path) == 0);
  snprintf(path, sizeof path, "%s/nan.nrrd", dir);
  TEST_TRUE(write_text(path, "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\n"
                             "spacings: 0.25 0.25 0.25\nspace origin: (0.375,0.375,0.375)\n"
                             "encoding: ascii\n\n1 1 nan 1 1 nan 1 1\n") == 0);

  surface_scenes(ctx, dir);

  recorder r;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  {
    /* a level set on a grid, static: the background first, the geometry's progress inside its
     * phase, no mass rules and so no log blocks */
    scene_json(json, sizeof json, grid_bg,
               "{\"level_set\": {\"sphere\": {\"center\": [0.5, 0.5, 0.5], \"radius\": 0.4}}}", 0,
               0.1, NULL);
    sim = build(ctx, dir, json, &r, 1, FCM_OK, &scene);
    if (sim) {
      const fcm_setup_phase want[] = {FCM_SETUP_BACKGROUND, FCM_SETUP_GEOMETRY,
                                      FCM_SETUP_CELL_RULES, FCM_SETUP_SPACE,
                                      FCM_SETUP_INTEGRATOR, FCM_SETUP_OUTPUT_SURFACE};
      check_phases(sim, &r, want, 6, 1u << FCM_SETUP_GEOMETRY | 1u << FCM_SETUP_CELL_RULES);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  }
  {
    /* a box cut at t = 0, no output surface */
    scene_json_output(json, sizeof json,
                      "{\"element\": \"hex8\", \"box\": {\"min\": [-0.25, -0.25, -0.25],"
                      " \"max\": [1.25, 0.75, 0.75]}, \"cells\": [3, 2, 2]}",
                      "{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1, 0.5, 0.5],"
                      " \"cells\": [2, 1, 1]}",
                      1, -0.2,
                      ", {\"cut\": {\"surface\": {\"plane\": {\"point\": [0.3, 0.25, 0.25],"
                      " \"normal\": [1, 0, 0]}}}}",
                      "{\"surface\": false}");
    sim = build(ctx, dir, json, &r, 0, FCM_OK, &scene);
    if (sim) {
      const fcm_setup_phase want[] = {
          FCM_SETUP_BACKGROUND, FCM_SETUP_GEOMETRY, FCM_SETUP_CELL_RULES, FCM_SETUP_SPACE,
          FCM_SETUP_INTEGRATOR, FCM_SETUP_LOG,      FCM_SETUP_CUTS};
      check_phases(sim, &r, want, 7, 0);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  }
  {
    /* voxels with NaN values: read, then merged (its warning logged there) */
    scene_json(json, sizeof json, grid_bg, "{\"voxels\": \"nan.nrrd\"}", 1, 0.1, NULL);
    sim = build(ctx, dir, json, &r, 0, FCM_OK, &scene);
    if (sim) {
      const fcm_setup_phase want[] = {
          FCM_SETUP_BACKGROUND, FCM_SETUP_READ,       FCM_SETUP_GEOMETRY, FCM_SETUP_CELL_RULES,
          FCM_SETUP_SPACE,      FCM_SETUP_INTEGRATOR, FCM_SETUP_LOG,      FCM_SETUP_OUTPUT_SURFACE};
      check_phases(sim, &r, want, 8, 0);
      TEST_TRUE(r.warnings == 1 && r.warning_phase == FCM_SETUP_GEOMETRY);
      TEST_TRUE(strstr(what_of(&r, FCM_SETUP_READ), "nan.nrrd") != NULL);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  }
  {
    /* no geometry: no cell rules, and the summary has no phase lines but the part's */
    scene_json(json, sizeof json, grid_bg, NULL, 1, 0.1, NULL);
    sim = build(ctx, dir, json, &r, 1, FCM_OK, &scene);
    if (sim) {
      const fcm_setup_phase want[] = {FCM_SETUP_BACKGROUND, FCM_SETUP_SPACE, FCM_SETUP_INTEGRATOR,
                                      FCM_SETUP_LOG};
      check_phases(sim, &r, want, 4, 0);
      char *text = summary_text(sim);
      TEST_TRUE(text && strstr(text, "[s] mesh and geometry: background mesh ") &&
                !strstr(text, "[s] cell rules:") && strstr(text, "[s] the rest: log mass"));
      free(text);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&scene);
  }
  TEST_TRUE(fcm_setup_phase_name(FCM_SETUP_PHASE_COUNT)[0] == '?');

  const char *const files[] = {"open.obj", "nan.nrrd", "scene.json"};
  remove_temp_dir(dir, files, 3);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
