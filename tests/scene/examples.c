/* Every example scene in apps/scenes (directory given as argv[1]) parses and validates,
 * and is consistent: its name is its file stem, the embedded body lies inside the
 * background box, every fixed or moving region holds at least one background node, every
 * traction or pressure region meets the body's box, and it is small enough to run in
 * minutes. The scenes modelled on the papers keep the papers' defining numbers, and the
 * complete examples of apps/scenes/README.md and of the top-level README.md parse. */
#include "scene_util.h"

#include <dirent.h>
#include <math.h>

#define MAX_FILES 64

static int cmp_str(const void *a, const void *b)
{
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Axis-aligned box around the embedded body (from the shape parameters; the corners of
 * that box mapped by the transform when there is one). Returns 0 for file geometries. */
static int body_box(const fcm_scene_geometry *g, double lo[3], double hi[3])
{
  switch (g->kind) {
  case FCM_SCENE_GEOMETRY_BOX:
    for (int d = 0; d < 3; d++)
      lo[d] = g->min[d], hi[d] = g->max[d];
    break;
  case FCM_SCENE_GEOMETRY_BALL:
  case FCM_SCENE_GEOMETRY_HEMISPHERE:
    for (int d = 0; d < 3; d++)
      lo[d] = g->center[d] - g->radius, hi[d] = g->center[d] + g->radius;
    if (g->kind == FCM_SCENE_GEOMETRY_HEMISPHERE) lo[1] = g->center[1];
    break;
  case FCM_SCENE_GEOMETRY_HOLLOW_BALL:
    for (int d = 0; d < 3; d++)
      lo[d] = g->center[d] - g->outer_radius, hi[d] = g->center[d] + g->outer_radius;
    break;
  case FCM_SCENE_GEOMETRY_TUBE:
    for (int d = 0; d < 3; d++) {
      double h = d == g->axis ? g->length / 2 : g->outer_radius;
      lo[d] = g->center[d] - h, hi[d] = g->center[d] + h;
    }
    break;
  default:
    return 0;
  }
  if (g->has_transform) {
    double nlo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, nhi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int c = 0; c < 8; c++) {
      double x[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
      for (int i = 0; i < 3; i++) {
        double y = g->offset[i];
        for (int j = 0; j < 3; j++)
          y += g->transform[3 * i + j] * x[j];
        nlo[i] = fmin(nlo[i], y), nhi[i] = fmax(nhi[i], y);
      }
    }
    memcpy(lo, nlo, sizeof nlo);
    memcpy(hi, nhi, sizeof nhi);
  }
  return 1;
}

/* Number of mesh nodes in a region (node sets: ids in range). */
static fcm_index nodes_in(const fcm_mesh *mesh, const fcm_region *r)
{
  fcm_index n = 0, nn = fcm_mesh_num_nodes(mesh);
  if (r->kind == FCM_REGION_NODES) {
    for (fcm_index i = 0; i < r->num_nodes; i++)
      n += r->nodes[i] < nn;
    return n;
  }
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index a = 0; a < nn; a++)
    n += fcm_region_contains(r, X + 3 * a);
  return n;
}

/* Whether a box or half-space region meets the box [lo, hi]. */
static int region_meets_box(const fcm_region *r, const double lo[3], const double hi[3])
{
  if (r->kind == FCM_REGION_BOX) {
    for (int d = 0; d < 3; d++)
      if (r->max[d] + r->tolerance < lo[d] || r->min[d] - r->tolerance > hi[d]) return 0;
    return 1;
  }
  for (int c = 0; c < 8; c++) { /* some corner of the box lies in the half-space */
    double x[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
    if (fcm_region_contains(r, x)) return 1;
  }
  return 0;
}

static void check_scene(fcm_ctx *ctx, const char *path, const char *file)
{
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &s));
  if (!s) {
    fprintf(stderr, "  in %s\n", path);
    return;
  }
  check_normalized(ctx, s, file);
  char stem[128];
  snprintf(stem, sizeof stem, "%s", file);
  *strrchr(stem, '.') = '\0';
  if (strcmp(fcm_scene_name(s), stem)) TEST_FAIL_("%s: name %s", file, fcm_scene_name(s));
  TEST_TRUE(strlen(fcm_scene_description(s)) > 20);
  TEST_OK(ctx, fcm_material_validate(ctx, fcm_scene_get_material(s)));
  TEST_TRUE(fcm_scene_num_effects(s) >= 1);

  const fcm_scene_background *bg = fcm_scene_get_background(s);
  const fcm_scene_time *t = fcm_scene_get_time(s);
  /* Budget: a few thousand steps x cells at most, so a run takes minutes on 2 cores. */
  TEST_TRUE(t->num_steps <= 1000);
  /* a Gmsh background, or a grid fitted around the geometry when the simulation is built
   * (its node checks need the built geometry: app_sim_check_* runs those scenes) */
  if (bg->kind != FCM_SCENE_BACKGROUND_GRID || bg->fit) {
    fcm_scene_destroy(&s);
    return;
  }
  fcm_index cells = bg->cells[0] * bg->cells[1] * bg->cells[2];
  if (cells > 2000) TEST_FAIL_("%s: %lld background cells", file, (long long)cells);

  double lo[3], hi[3];
  const fcm_scene_geometry *g = fcm_scene_get_geometry(s);
  int has_box = body_box(g, lo, hi);
  if (has_box)
    for (int d = 0; d < 3; d++)
      if (lo[d] < bg->min[d] - 1e-12 || hi[d] > bg->max[d] + 1e-12)
        TEST_FAIL_("%s: body [%g, %g] outside the background [%g, %g] along axis %d", file, lo[d],
                   hi[d], bg->min[d], bg->max[d], d);

  fcm_mesh *mesh = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, bg->element, bg->min, bg->max, bg->cells, &mesh));
  for (int i = 0; mesh && i < fcm_scene_num_effects(s); i++) {
    const fcm_effect *e = fcm_scene_get_effect(s, i);
    const fcm_region *r = NULL;
    int boundary = 0;
    if (e->type == FCM_EFFECT_FIXED) r = &e->fixed.region, boundary = e->fixed.boundary;
    if (e->type == FCM_EFFECT_MOTION) r = &e->motion.region, boundary = e->motion.boundary;
    if (r && !boundary && nodes_in(mesh, r) == 0)
      TEST_FAIL_("%s: effects[%d] holds no node", file, i);
    if (r && boundary && has_box && !region_meets_box(r, lo, hi))
      TEST_FAIL_("%s: effects[%d] misses the body's boundary", file, i);
    if (e->type == FCM_EFFECT_TRACTION) r = &e->traction.region;
    if (e->type == FCM_EFFECT_PRESSURE) r = &e->pressure.region;
    if (r && has_box && (e->type == FCM_EFFECT_TRACTION || e->type == FCM_EFFECT_PRESSURE) &&
        !region_meets_box(r, lo, hi))
      TEST_FAIL_("%s: effects[%d] misses the body", file, i);
  }
  fcm_mesh_destroy(&mesh);
  fcm_scene_destroy(&s);
}

/* The defining numbers of the scenes modelled on Longva et al. 2020. */
static void check_papers(fcm_ctx *ctx, const char *dir)
{
  char path[1024];
  fcm_scene *s = NULL;

  /* §6.2: 16 m hollow cylinder, E = 5e6 Pa, nu = 0.48, Hex20 FCM; one end moved, the other
   * twisted about the cylinder's axis, both until t = 4 s, then held. */
  snprintf(path, sizeof path, "%s/twisting_cylinder.json", dir);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &s));
  if (s) {
    const fcm_material *m = fcm_scene_get_material(s);
    const fcm_scene_geometry *g = fcm_scene_get_geometry(s);
    TEST_TRUE(m->model == FCM_MATERIAL_STABLE_NEO_HOOKEAN && m->young == 5e6 && m->poisson == 0.48);
    TEST_TRUE(fcm_scene_get_background(s)->element == FCM_ELEMENT_HEX20);
    TEST_TRUE(g->kind == FCM_SCENE_GEOMETRY_TUBE && g->length == 16 && g->axis == 1);
    int twisted = 0;
    for (int i = 0; i < fcm_scene_num_effects(s); i++) {
      const fcm_effect *e = fcm_scene_get_effect(s, i);
      if (e->type != FCM_EFFECT_MOTION) continue;
      TEST_TRUE(e->motion.motion.end == 4 && !e->motion.motion.release);
      twisted += e->motion.motion.angular_speed == 0.8 && e->motion.motion.axis[1] == 1.0;
      /* Held after the end: the displacement at 7 s equals that at 4 s. */
      double X[3] = {0.9, 8, 0.1}, u4[3], u7[3];
      fcm_motion_eval(&e->motion.motion, X, 4.0, u4, NULL);
      fcm_motion_eval(&e->motion.motion, X, 7.0, u7, NULL);
      for (int d = 0; d < 3; d++)
        TEST_TRUE(u4[d] == u7[d]);
    }
    TEST_TRUE(twisted == 1);
    TEST_NEAR(fcm_scene_get_time(s)->duration, 7.0, 1e-12, 0);
  }
  fcm_scene_destroy(&s);

  /* §6.4 / Fig. 1: hollow ball with holes, Tet10 FCM, compressed and twisted. */
  snprintf(path, sizeof path, "%s/hollow_ball.json", dir);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &s));
  if (s) {
    const fcm_scene_geometry *g = fcm_scene_get_geometry(s);
    TEST_TRUE(fcm_scene_get_background(s)->element == FCM_ELEMENT_TET10);
    TEST_TRUE(g->kind == FCM_SCENE_GEOMETRY_HOLLOW_BALL && g->hole_radius > 0);
    int compress = 0, twist = 0;
    for (int i = 0; i < fcm_scene_num_effects(s); i++) {
      const fcm_effect *e = fcm_scene_get_effect(s, i);
      if (e->type != FCM_EFFECT_MOTION) continue;
      compress += e->motion.motion.velocity[2] < 0 && e->motion.region.min[2] > 0;
      twist += e->motion.motion.angular_speed != 0 && e->motion.motion.axis[2] == 1.0;
    }
    TEST_TRUE(compress == 1 && twist == 1);
  }
  fcm_scene_destroy(&s);

  /* §6.5-like: pulled and released under gravity. */
  snprintf(path, sizeof path, "%s/slingshot.json", dir);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &s));
  if (s) {
    int released = 0;
    TEST_TRUE(fcm_scene_count_effects(s, FCM_EFFECT_GRAVITY) == 1);
    TEST_TRUE(fcm_scene_count_effects(s, FCM_EFFECT_FIXED) >= 1);
    for (int i = 0; i < fcm_scene_num_effects(s); i++) {
      const fcm_effect *e = fcm_scene_get_effect(s, i);
      if (e->type == FCM_EFFECT_MOTION && e->motion.motion.release) {
        released++;
        TEST_TRUE(fcm_motion_active(&e->motion.motion, e->motion.motion.end));
        TEST_TRUE(!fcm_motion_active(&e->motion.motion, e->motion.motion.end + 0.01));
        TEST_TRUE(e->motion.motion.end < fcm_scene_get_time(s)->duration);
      }
    }
    TEST_TRUE(released == 1);
    TEST_TRUE(fcm_scene_get_solver(s)->integrator.linear_solver != FCM_LINEAR_DIRECT);
  }
  fcm_scene_destroy(&s);

  /* §6.1: one coarse cell, free spin about the centre of mass, no other effect. */
  snprintf(path, sizeof path, "%s/spinning_body.json", dir);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &s));
  if (s) {
    const fcm_scene_background *bg = fcm_scene_get_background(s);
    TEST_TRUE(bg->cells[0] * bg->cells[1] * bg->cells[2] == 1);
    TEST_TRUE(fcm_scene_num_effects(s) == 1);
    const fcm_effect *e = fcm_scene_get_effect(s, 0);
    TEST_TRUE(e && e->type == FCM_EFFECT_INITIAL_VELOCITY && e->initial_velocity.center_of_mass);
    if (e) {
      const double *w = e->initial_velocity.angular_velocity;
      TEST_TRUE(w[0] * w[0] + w[1] * w[1] + w[2] * w[2] > 0);
    }
  }
  fcm_scene_destroy(&s);
}

/* The first ```json block of the document `path` is a complete scene named `name` with
 * `effects` effects. */
static void check_readme(fcm_ctx *ctx, const char *path, const char *name, int effects)
{
  static char text[1 << 17];
  FILE *f = fopen(path, "rb");
  TEST_TRUE(f != NULL);
  if (!f) return;
  size_t n = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  text[n] = '\0';
  char *start = strstr(text, "```json\n");
  char *end = start ? strstr(start + 8, "\n```") : NULL;
  TEST_TRUE(start && end);
  if (!start || !end) return;
  end[1] = '\0';
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, start + 8, path, &s));
  if (s) TEST_TRUE(!strcmp(fcm_scene_name(s), name) && fcm_scene_num_effects(s) == effects);
  fcm_scene_destroy(&s);
}

int main(int argc, char **argv)
{
  if (argc < 2) {
    fprintf(stderr, "usage: %s SCENE_DIR\n", argv[0]);
    return 1;
  }
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();

  DIR *d = opendir(argv[1]);
  TEST_TRUE(d != NULL);
  char *files[MAX_FILES];
  int n = 0;
  for (struct dirent *e = d ? readdir(d) : NULL; e; e = readdir(d)) {
    size_t len = strlen(e->d_name);
    if (len > 5 && !strcmp(e->d_name + len - 5, ".json") && n < MAX_FILES) {
      files[n] = malloc(len + 1);
      if (files[n]) memcpy(files[n++], e->d_name, len + 1);
    }
  }
  if (d) closedir(d);
  qsort(files, (size_t)n, sizeof *files, cmp_str);
  TEST_TRUE(n >= 4);
  const char *required[] = {"hollow_ball.json", "slingshot.json", "spinning_body.json",
                            "twisting_cylinder.json"};
  for (int r = 0; r < 4; r++) {
    int found = 0;
    for (int i = 0; i < n; i++)
      found |= !strcmp(files[i], required[r]);
    if (!found) TEST_FAIL_("%s/%s is missing", argv[1], required[r]);
  }
  for (int i = 0; i < n; i++) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", argv[1], files[i]);
    check_scene(ctx, path, files[i]);
    free(files[i]);
  }
  check_papers(ctx, argv[1]);
  {
    fcm_scene *s = NULL;
    TEST_OK(ctx, fcm_scene_create_default(ctx, &s));
    if (s) check_normalized(ctx, s, "the built-in scene");
    fcm_scene_destroy(&s);
  }
  {
    char path[1024];
    snprintf(path, sizeof path, "%s/README.md", argv[1]);
    check_readme(ctx, path, "example", 4);
    snprintf(path, sizeof path, "%s/../../README.md", argv[1]); /* the top-level README */
    check_readme(ctx, path, "cut_ball", 3);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
