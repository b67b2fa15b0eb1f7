/* The background key "octree": refinement along the embedded boundary and in a region parses
 * into the background's fields, round-trips through the normalized JSON, and bad input is
 * refused naming the key (tetrahedra, a boundary criterion without a geometry, an octree over a
 * mesh file, no criterion, a level beyond the limit, refinement along cuts without cut effects);
 * a scene with an octree background builds and runs a step with the cells of every level it
 * asked for, and one refined along a cut and the boundary cuts the ball in two during the run;
 * with "cuts": {"when": "cut"} (Hex8, Hex20) the refinement along the cut happens during the
 * run, just before the cut, which then applies on the refined background, and a checkpoint
 * of that run restores on a new simulation; a bad "when" and an unknown key refused. */
#include "scene_util.h"

#include "fcm/simulation.h"

#define GEOM "\"geometry\": {\"shape\": \"ball\", \"center\": [0, 0, 0], \"radius\": 0.6}, "
#define CUT                                                                                        \
  "{\"cut\": {\"time\": 0.005, \"surface\": {\"plane\": {\"point\": [0.03, 0, 0], "                \
  "\"normal\": [1, 0.1, 0]}}}}"
#define HOLD                                                                                       \
  "{\"fixed\": {\"region\": {\"half_space\": {\"point\": [-0.3, 0, 0], \"normal\": [-1, 0, 0]}}}}"
#define REST                                                                                       \
  "\"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000}, "      \
  "\"output\": {\"directory\": \"out\"}, \"time\": {\"dt\": 0.01, \"steps\": 2}"

static fcm_scene *parse(fcm_ctx *ctx, const char *element, const char *octree, const char *geom,
                        const char *effects, fcm_status expect, const char *msg)
{
  char text[4096];
  fcm_scene *s = NULL;
  snprintf(text, sizeof text,
           "{\"background\": {\"element\": \"%s\", \"box\": {\"min\": [-1, -1, -1], \"max\": [1, "
           "1, 1]}, \"cells\": [2, 2, 2], %s}, %s" REST ", \"effects\": [%s]}",
           element, octree, geom, effects);
  if (expect == FCM_OK) {
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, text, "t.json", &s));
    if (s) check_normalized(ctx, s, octree);
  } else {
    TEST_ERR(ctx, fcm_scene_create_from_string(ctx, text, "t.json", &s), expect, msg);
  }
  return s;
}

/* The summary of `sim` as a string (malloc'ed). */
static char *summary(fcm_simulation *sim)
{
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  fcm_simulation_summary_view(sim, f);
  fclose(f);
  return text;
}

/* A scene refining along its cut when the cut applies: levels 0..1 at set-up, 0..2 after the
 * first step (the cut at t = 0.005 applies once the run has passed it, at t = 0.01), the cut
 * applied after the refinement, two bodies, and the run goes on. */
static void refine_at_cut(fcm_ctx *ctx, const fcm_scene *s)
{
  fcm_simulation *sim = NULL;
  TEST_TRUE(fcm_scene_get_background(s)->octree_cuts == 2);
  TEST_TRUE(fcm_scene_get_background(s)->octree_cuts_at_cut == 1);
  TEST_OK(ctx, fcm_simulation_create(ctx, s, NULL, &sim));
  if (!sim) return;
  char *text = summary(sim);
  TEST_TRUE(text && strstr(text, "per level 0..1:") && !strstr(text, "refined along the cuts"));
  free(text);
  for (int k = 0; k < 2; k++)
    TEST_OK(ctx, fcm_simulation_step(sim, NULL));
  text = summary(sim);
  TEST_TRUE(text && strstr(text, "per level 0..2:") &&
            strstr(text, "refined along the cuts at t = 0.01 s, before the first cut") &&
            strstr(text, "1 applied") && strstr(text, "2 bodies") && strstr(text, "2 of 2 steps"));
  if (text && !strstr(text, "refined along the cuts at t = 0.01 s")) fputs(text, stderr);
  free(text);
  /* a checkpoint of the refined, cut run restores on a new simulation (the refinement and the
   * cut replayed onto the same space) */
  fcm_simulation *again = NULL;
  TEST_OK(ctx, fcm_simulation_write_checkpoint(sim, "refined.fcmck"));
  TEST_OK(ctx, fcm_simulation_create(ctx, s, NULL, &again));
  if (again) TEST_OK(ctx, fcm_simulation_read_checkpoint(again, "refined.fcmck"));
  if (again) {
    fcm_integrator *a = fcm_simulation_integrator(sim), *b = fcm_simulation_integrator(again);
    const fcm_index n = fcm_integrator_num_dofs(a);
    int same = n == fcm_integrator_num_dofs(b) && fcm_integrator_time(a) == fcm_integrator_time(b);
    for (fcm_index i = 0; same && i < n; i++)
      same = fcm_integrator_displacement(a)[i] == fcm_integrator_displacement(b)[i] &&
             fcm_integrator_velocity(a)[i] == fcm_integrator_velocity(b)[i];
    TEST_TRUE(same);
    text = summary(again);
    TEST_TRUE(text && strstr(text, "per level 0..2:") && strstr(text, "2 bodies"));
    free(text);
  }
  fcm_simulation_destroy(&again);
  fcm_simulation_destroy(&sim);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  char dir[256];
  if (!enter_temp_dir(dir, sizeof dir)) return TEST_RESULT();
  const char *both = "\"octree\": {\"boundary\": {\"level\": 2}, \"region\": {\"min\": [-1, -1, "
                     "-1], \"max\": [0, 0, -0.5], \"level\": 1}}";
  fcm_scene *s = parse(ctx, "hex8", both, GEOM, "{\"gravity\": {}}", FCM_OK, NULL);
  if (s) {
    const fcm_scene_background *b = fcm_scene_get_background(s);
    TEST_TRUE(b->octree == 1 && b->octree_boundary == 2 && b->octree_region == 1);
    TEST_TRUE(b->octree_region_min[0] == -1 && b->octree_region_max[2] == -0.5);
    /* it builds and steps: cells of levels 0 to 2, hanging nodes constrained */
    fcm_simulation *sim = NULL;
    TEST_OK(ctx, fcm_simulation_create(ctx, s, NULL, &sim));
    if (sim) {
      TEST_OK(ctx, fcm_simulation_step(sim, NULL));
      char *text = NULL;
      size_t len = 0;
      FILE *f = open_memstream(&text, &len);
      fcm_simulation_summary_view(sim, f);
      fclose(f);
      TEST_TRUE(text && strstr(text, "octree background") && strstr(text, "per level 0..2:"));
      free(text);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&s);
  }
  s = parse(ctx, "hex20",
            "\"octree\": {\"region\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1], "
            "\"level\": 1}}",
            "", "{\"gravity\": {}}", FCM_OK, NULL);
  if (s) TEST_TRUE(fcm_scene_get_background(s)->octree_boundary == 0);
  fcm_scene_destroy(&s);

  /* refined along a cut (before it applies) and the boundary; the cut applies during the run
   * and separates the ball into two bodies */
  s = parse(ctx, "hex8", "\"octree\": {\"boundary\": {\"level\": 1}, \"cuts\": {\"level\": 2}}",
            GEOM, CUT, FCM_OK, NULL);
  if (s) {
    TEST_TRUE(fcm_scene_get_background(s)->octree_cuts == 2);
    TEST_TRUE(fcm_scene_get_background(s)->octree_cuts_at_cut == 0);
    TEST_TRUE(strstr(fcm_scene_json(s), "\"setup\"") != NULL); /* the default, normalized */
    fcm_simulation *sim = NULL;
    TEST_OK(ctx, fcm_simulation_create(ctx, s, NULL, &sim));
    if (sim) {
      TEST_OK(ctx, fcm_simulation_step(sim, NULL));
      TEST_OK(ctx, fcm_simulation_step(sim, NULL));
      char *text = NULL;
      size_t len = 0;
      FILE *f = open_memstream(&text, &len);
      fcm_simulation_summary_view(sim, f);
      fclose(f);
      TEST_TRUE(text && strstr(text, "per level 0..2:") && strstr(text, "1 applied") &&
                strstr(text, "2 bodies"));
      if (!(text && strstr(text, "2 bodies")) && text) fputs(text, stderr);
      free(text);
    }
    fcm_simulation_destroy(&sim);
    fcm_scene_destroy(&s);
  }
  /* "when": "cut": the run starts without the cuts' refinement and refines when the first cut
   * applies, just before it (Hex8 and Hex20, the left side held) */
  for (int el = 0; el < 2; el++) {
    s = parse(ctx, el ? "hex20" : "hex8",
              "\"octree\": {\"boundary\": {\"level\": 1}, \"cuts\": {\"level\": 2, \"when\": "
              "\"cut\"}}",
              GEOM, HOLD ", " CUT, FCM_OK, NULL);
    if (s) refine_at_cut(ctx, s);
    fcm_scene_destroy(&s);
  }
  parse(ctx, "hex8", "\"octree\": {\"cuts\": {\"level\": 1, \"when\": \"later\"}}", GEOM, CUT,
        FCM_ERR_ARG, "background.octree.cuts.when");
  parse(ctx, "hex8", "\"octree\": {\"cuts\": {\"level\": 1, \"at\": 0}}", GEOM, CUT, FCM_ERR_ARG,
        "background.octree.cuts");
  parse(ctx, "tet10", both, GEOM, "", FCM_ERR_ARG, "needs hexahedra");
  parse(ctx, "hex8", "\"octree\": {\"boundary\": {\"level\": 1}}", "", "", FCM_ERR_ARG,
        "background.octree.boundary");
  parse(ctx, "hex8", "\"octree\": {}", GEOM, "", FCM_ERR_ARG, "at least one refinement");
  parse(ctx, "hex8", "\"octree\": {\"boundary\": {\"level\": 13}}", GEOM, "", FCM_ERR_ARG,
        "background.octree.boundary.level");
  parse(ctx, "hex8", "\"octree\": {\"cuts\": {\"level\": 1}}", GEOM, "", FCM_ERR_ARG,
        "background.octree.cuts");
  TEST_ERR(ctx,
           fcm_scene_create_from_string(
               ctx,
               "{\"background\": {\"mesh\": \"m.msh\", \"octree\": {\"boundary\": {\"level\": "
               "1}}}, " REST ", \"effects\": []}",
               "t.json", &s),
           FCM_ERR_ARG, "background.octree");

  if (chdir("/") != 0) TEST_FAIL_("cannot leave the temporary directory");
  const char *files[] = {"refined.fcmck"};
  remove_temp_dir(dir, files, 1);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
