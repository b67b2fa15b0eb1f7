/* The look before the set-up: the coarse cell classification (exact for axis-aligned faces,
 * conservative against the rules build on a ball), a region on inactive nodes refused before the
 * cell rules, and fcm_simulation_write_preview()'s files counted by hand on a box grid. */
#include "scene_util.h"

#include "../io/vtk_reader.h"
#include "alloc_loop.h"
#include "embed/embed_impl.h"

#include <math.h>
#include <stdint.h>

/* The grid of the scenes below: [0, 4] x [0, 1] x [0, 1] in 8 x 2 x 2 Hex8 cells of 0.5 m
 * (9 x 3 x 3 = 81 nodes), the body the box [1.2, 3.8] x [0.1, 0.9] x [0.1, 0.9]: the cells of
 * x < 1 are outside, every other cell is cut (each meets a face of the body), so the nodes
 * with x >= 1 (7 x 9 = 63) are active and those at x = 0 and 0.5 (18) are not. */
#define SCENE_HEAD                                                                                 \
  "{\"version\": 1, \"name\": \"pv\",\n"                                                           \
  " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [4, 1, 1]},"    \
  " \"cells\": [8, 2, 2]},\n"                                                                      \
  " \"geometry\": {\"shape\": \"box\", \"min\": [1.2, 0.1, 0.1], \"max\": [3.8, 0.9, 0.9],"        \
  " \"cells\": [4, 1, 1]},\n"                                                                      \
  " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},\n" \
  " \"time\": {\"static\": true, \"steps\": 1},\n"

/* effects[0]: x <= 1 holds 27 nodes, 9 of them active (x = 1); effects[1]: a traction on the
 * end x >= 3.7; effects[2]: a plane cut at x = 2.5. */
static const char good_scene[] = SCENE_HEAD
    " \"effects\": [\n"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [1, 0, 0], \"normal\": [-1, 0, 0],"
    "   \"tolerance\": 1e-6}}}},\n"
    "  {\"traction\": {\"region\": {\"half_space\": {\"point\": [3.7, 0, 0], \"normal\": [1, 0, "
    "0]}}, \"value\": [0, 0, -100]}},\n"
    "  {\"cut\": {\"surface\": {\"plane\": {\"point\": [2.5, 0.5, 0.5], \"normal\": [1, 0, 0]}}}}\n"
    " ]}\n";

/* effects[1]: x <= 0.75 holds the 18 nodes at x = 0 and 0.5, none active. */
static const char bad_scene[] =
    SCENE_HEAD " \"effects\": [\n"
               "  {\"gravity\": {}},\n"
               "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.75, 0, 0], \"normal\": "
               "[-1, 0, 0]}}}}\n"
               " ]}\n";

/* The set-up phases that started. */
static void count_phase(const fcm_setup_phase_event *ev, void *user)
{
  int *started = user;
  if (!ev->finished) started[ev->phase]++;
}

/* The coarse classes of `geom` in `mesh` (1000 cells) are those of the rules build; counts. */
static void check_same(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                       fcm_index inside, fcm_index cut, fcm_index outside)
{
  unsigned char cls[1000];
  fcm_index counts[3];
  fcm_cell_rules *rules = NULL;
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.simplify = FCM_CELL_SIMPLIFY_OFF;
  TEST_OK(ctx, fcm__embed_classify_coarse(ctx, mesh, geom, cls, counts));
  TEST_TRUE(counts[FCM_CELL_UNCUT] == inside && counts[FCM_CELL_CUT] == cut &&
            counts[FCM_CELL_DROPPED] == outside);
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, geom, &ro, &rules));
  int same = rules != NULL;
  for (fcm_index k = 0; rules && k < 1000; k++)
    same &= fcm_cell_rules_class(rules, k) == (fcm_cell_class)cls[k];
  TEST_TRUE(same);
  fcm_cell_rules_destroy(&rules);
}

/* Coarse classes against the exact rules: for axis-aligned faces, off the grid planes or on
 * them, they are the same; on a ball the coarse class is conservative (inside and outside only
 * where the rules agree, every cell the rules cut is cut). */
static void check_classes(fcm_ctx *ctx)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, blo[3] = {0.23, 0.23, 0.23},
               bhi[3] = {0.77, 0.77, 0.77}, glo[3] = {0.2, 0.2, 0.2}, ghi[3] = {0.8, 0.8, 0.8},
               c[3] = {0.5, 0.5, 0.5};
  const fcm_index n[3] = {10, 10, 10}, one[3] = {1, 1, 1}, two[3] = {2, 3, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *box = NULL, *grid_box = NULL, *ball = NULL;
  fcm_cell_rules *rules = NULL;
  unsigned char cls[1000];
  fcm_index counts[3];
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, blo, bhi, one, &box));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, two, &grid_box));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.37, 3, &ball));
  if (!mesh || !box || !grid_box || !ball) goto done;
  /* cells 3..6 per axis inside, 2..7 reached: 64 inside, 216 - 64 cut */
  check_same(ctx, mesh, box, 64, 152, 784);
  /* faces on grid planes: cells 2..7 inside, none cut, the cells beside the faces outside */
  check_same(ctx, mesh, grid_box, 216, 0, 784);
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.simplify = FCM_CELL_SIMPLIFY_OFF;
  TEST_OK(ctx, fcm__embed_classify_coarse(ctx, mesh, ball, cls, counts));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, ball, &ro, &rules));
  int conservative = rules != NULL;
  for (fcm_index k = 0; rules && k < 1000; k++) {
    const fcm_cell_class exact = fcm_cell_rules_class(rules, k);
    if (cls[k] == FCM_CELL_UNCUT) conservative &= exact == FCM_CELL_UNCUT;
    if (cls[k] == FCM_CELL_DROPPED) conservative &= exact == FCM_CELL_DROPPED;
    if (exact == FCM_CELL_CUT) conservative &= cls[k] == FCM_CELL_CUT;
  }
  TEST_TRUE(conservative);
  TEST_TRUE(counts[FCM_CELL_UNCUT] > 0 && counts[FCM_CELL_CUT] > 0);
done:
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&box);
  fcm_geometry_destroy(&grid_box);
  fcm_geometry_destroy(&ball);
  fcm_mesh_destroy(&mesh);
}

/* A fixed region on inactive nodes only: refused before the cell rules start. */
static void check_refused(fcm_ctx *ctx)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  int started[FCM_SETUP_PHASE_COUNT] = {0};
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, bad_scene, NULL, &scene));
  if (!scene) return;
  fcm_simulation_options so = fcm_simulation_options_default();
  so.setup_phase = count_phase;
  so.setup_phase_user = started;
  const fcm_status st = fcm_simulation_create(ctx, scene, &so, &sim);
  const char *msg = fcm_ctx_error_message(ctx);
  TEST_TRUE(st == FCM_ERR_ARG && sim == NULL);
  TEST_TRUE(strstr(msg, "effects[1]") && strstr(msg, "fixed region (half_space"));
  TEST_TRUE(strstr(msg, "selects 18 background-mesh nodes, none of them active"));
  TEST_TRUE(strstr(msg, "(63 of 81 nodes are active)"));
  TEST_TRUE(started[FCM_SETUP_BACKGROUND] == 1 && started[FCM_SETUP_GEOMETRY] == 1);
  TEST_TRUE(started[FCM_SETUP_CELL_RULES] == 0 && started[FCM_SETUP_SPACE] == 0);
  fcm_ctx_error_clear(ctx);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

/* The values of the array `name` of section `parent` of a VTU ("Points", name NULL: the
 * points), items of `size` bytes, at most cap into out; their count, -1 when it is missing. */
static long long read_array(const vr_doc *d, const char *parent, const char *name, size_t size,
                            void *out, size_t cap)
{
  const vr_tag *t = vr_data_array(d, parent, name);
  if (!t) return -1;
  uint64_t bytes;
  const unsigned char *p = vr_array(d, t, &bytes);
  const size_t n = bytes / size < cap ? bytes / size : cap;
  memcpy(out, p, n * size);
  return (long long)n;
}

/* Int32 point arrays and the points (x 3) of a VTU. */
static long long int32_points(const vr_doc *d, const char *name, int32_t *out, size_t cap)
{
  return read_array(d, "PointData", name, 4, out, cap);
}

static long long points(const vr_doc *d, double *x, size_t cap)
{
  return read_array(d, "Points", NULL, 24, x, cap);
}

static int load_vtu(vr_doc *d, const char *dir, const char *part)
{
  char path[512];
  snprintf(path, sizeof path, "%s/pv_preview_%s.vtu", dir, part);
  if (!vr_load(d, path) || !vr_parse_vtu(d)) {
    fprintf(stderr, "%s: %s\n", path, d->error);
    return 0;
  }
  return 1;
}

/* The files of the good scene, counted by hand. */
static void check_files(fcm_ctx *ctx, const char *dir)
{
  fcm_scene *scene = NULL;
  fcm_simulation_preview_info info;
  fcm_preview_effect eff[3];
  vr_doc d;
  static int32_t v[20000];
  static double x[3 * 20000];
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, good_scene, NULL, &scene));
  if (!scene) return;
  TEST_OK(ctx, fcm_simulation_write_preview(ctx, scene, NULL, dir, &info, eff));
  TEST_TRUE(info.num_cells == 32 && info.num_nodes == 81 && info.active_nodes == 63);
  TEST_TRUE(info.cells[FCM_CELL_UNCUT] == 0 && info.cells[FCM_CELL_CUT] == 24 &&
            info.cells[FCM_CELL_DROPPED] == 8);
  TEST_TRUE(info.files == 6 && info.surface_triangles == 36);
  TEST_TRUE(eff[0].selects == FCM_PREVIEW_NODES && eff[0].nodes == 27 && eff[0].active_nodes == 9);
  TEST_TRUE(eff[1].selects == FCM_PREVIEW_BOUNDARY && eff[1].boundary_points > 0);
  TEST_TRUE(eff[2].selects == FCM_PREVIEW_NOTHING && eff[2].cut_triangles > 0);

  /* the grid: cell classes and active nodes as counted */
  if (load_vtu(&d, dir, "grid")) {
    TEST_TRUE(int32_points(&d, "active", v, 20000) == 81);
    long long active = 0;
    for (int a = 0; a < 81; a++)
      active += v[a];
    TEST_TRUE(active == 63);
    TEST_TRUE(vr_data_array(&d, "CellData", "class") != NULL);
  }
  vr_free(&d);
  /* the nodes of effects[0]: 27 points at x <= 1, 9 of them active (x = 1) */
  if (load_vtu(&d, dir, "nodes")) {
    TEST_TRUE(points(&d, x, 20000) == 27);
    TEST_TRUE(int32_points(&d, "effect", v, 20000) == 27);
    int ok = 1;
    for (int j = 0; j < 27; j++)
      ok &= v[j] == 0 && x[3 * j] <= 1.0 + 1e-12;
    TEST_TRUE(ok);
    TEST_TRUE(int32_points(&d, "active", v, 20000) == 27);
    long long active = 0;
    for (int j = 0; j < 27; j++)
      active += v[j] && fabs(x[3 * j] - 1.0) < 1e-12;
    TEST_TRUE(active == 9);
  }
  vr_free(&d);
  /* the traction's points: on the body's surface, in its region */
  if (load_vtu(&d, dir, "boundary_points")) {
    const long long n = points(&d, x, 20000);
    TEST_TRUE(n == eff[1].boundary_points);
    int ok = 1;
    for (long long j = 0; j < n; j++) {
      const double *p = x + 3 * j;
      const double face = fmin(fmin(fabs(p[0] - 3.8), fmin(fabs(p[1] - 0.1), fabs(p[1] - 0.9))),
                               fmin(fabs(p[2] - 0.1), fabs(p[2] - 0.9)));
      ok &= p[0] >= 3.7 - 1e-9 && p[0] <= 3.8 + 1e-12 && face < 1e-12;
    }
    TEST_TRUE(ok);
  }
  vr_free(&d);
  /* the cut: the plane x = 2.5 */
  if (load_vtu(&d, dir, "cuts")) {
    const long long n = points(&d, x, 20000);
    int ok = n >= 3;
    for (long long j = 0; j < n; j++)
      ok &= fabs(x[3 * j] - 2.5) < 1e-12;
    TEST_TRUE(ok);
  }
  vr_free(&d);
  char path[512];
  snprintf(path, sizeof path, "%s/pv_preview.pvd", dir);
  TEST_TRUE(vr_load(&d, path) && vr_parse_xml(&d));
  int parts = 0;
  while (vr_find(&d, "DataSet", "Collection", parts))
    parts++;
  TEST_TRUE(parts == 5);
  vr_free(&d);

  /* the bad region: the files are written, then the region is refused */
  fcm_scene_destroy(&scene);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, bad_scene, NULL, &scene));
  if (scene)
    TEST_ERR(ctx, fcm_simulation_write_preview(ctx, scene, NULL, dir, &info, eff), FCM_ERR_ARG,
             "none of them active");
  TEST_TRUE(info.files == 4 && eff[1].nodes == 18 && eff[1].active_nodes == 0);
  fcm_scene_destroy(&scene);
}

/* The allocation-failure loop over fcm_simulation_write_preview(): FCM_ERR_ALLOC, no leak. */
typedef struct preview_call {
  fcm_ctx *ctx;
  const fcm_scene *scene;
  const char *dir;
} preview_call;

static fcm_status call_preview(void *user)
{
  preview_call *c = user;
  fcm_simulation_preview_info info;
  fcm_preview_effect eff[3];
  return fcm_simulation_write_preview(c->ctx, c->scene, NULL, c->dir, &info, eff);
}

static void check_alloc(const char *dir)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  fcm_scene *scene = NULL;
  if (!ctx) return;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, good_scene, NULL, &scene));
  preview_call c = {ctx, scene, dir};
  if (scene) alloc_loop(ctx, &f, "write_preview", call_preview, NULL, &c, 20, 5000);
  fcm_scene_destroy(&scene);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  char dir[64];
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK || !make_temp_dir(dir, sizeof dir)) return 1;
  check_classes(ctx);
  check_refused(ctx);
  check_files(ctx, dir);
  check_alloc(dir);
  vr_rmdir(dir);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
