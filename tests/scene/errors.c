/* Bad scene input, one class per row: malformed JSON (FCM_ERR_FORMAT with line:column),
 * unknown keys and effects, wrong types, out-of-range and non-finite values, missing keys,
 * missing files (FCM_ERR_IO naming the resolved path). Each row checks the status, the
 * source name and the JSON path in the message, a NULL scene and no leak. The whole run
 * happens in an empty working directory that must stay empty (no output is created). */
#include "scene_util.h"

#include <dirent.h>
#include <sys/stat.h>

#define BG                                                                                         \
  "\"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, "    \
  "\"cells\": [1, 1, 1]}"
#define MAT  "\"material\": {\"young\": 1e6, \"poisson\": 0.3}"
#define OUT  "\"output\": {\"directory\": \"out\"}"
#define BASE BG ", " MAT ", " OUT
#define FIX  "{\"fixed\": {\"region\": {\"box\": {\"min\": [0, 0, 0], \"max\": [0, 1, 1]}}}}"

typedef struct bad_case {
  const char *json;
  fcm_status status;
  const char *substr;  /* must appear in the message */
  const char *substr2; /* a second fragment (the allowed values), or NULL */
} bad_case;

static const bad_case cases[] = {
    /* ---- malformed JSON: FCM_ERR_FORMAT with line:column */
    {"{\n  \"name\": \"x\",\n}\n", FCM_ERR_FORMAT, "t.json:3:", "malformed JSON near '}'"},
    {"{" BASE ", \"time\": {\"dt\": NaN}}", FCM_ERR_FORMAT, "malformed JSON near '", "NaN}}'"},
    {"{" BASE ", \"time\": {\"dt\": -Infinity}}", FCM_ERR_FORMAT, "malformed JSON", NULL},
    {"{" BASE ", \"time\": {\"dt\": 0.1} /* comment */}", FCM_ERR_FORMAT, "malformed JSON", NULL},
    {"", FCM_ERR_FORMAT, "t.json:1:1: malformed JSON: unexpected end of input", NULL},
    {"{" BASE "} trailing", FCM_ERR_FORMAT, "malformed JSON near '", "} trailing'"},
    {"{\"background\": {\"element\": \"hex8\"", FCM_ERR_FORMAT, "unexpected end of input", NULL},
    /* ---- not an object, unknown keys, duplicates, missing keys */
    {"[1, 2]", FCM_ERR_ARG, "t.json: expected a JSON object at the top level", NULL},
    {"{" BASE ", \"materail\": {}}", FCM_ERR_ARG, "t.json: materail: unknown key",
     "\"background\", \"geometry\", \"material\""},
    {"{" BASE ", \"time\": {\"dt\": 0.1, \"step\": 3}}", FCM_ERR_ARG, "time.step: unknown key",
     "\"steps\""},
    {"{" BG ", \"material\": {\"young\": 1e6, \"poisson\": 0.3, \"young\": 2e6}}", FCM_ERR_ARG,
     "material.young: duplicate key", NULL},
    {"{" BG "}", FCM_ERR_ARG, "t.json: material: missing; expected an object", NULL},
    {"{" BG ", \"material\": {\"young\": 1e6}}", FCM_ERR_ARG,
     "material.poisson: missing; expected a finite number in (-1, 0.5)", NULL},
    {"{" MAT ", \"background\": {\"element\": \"hex8\", \"cells\": [1, 1, 1]}}", FCM_ERR_ARG,
     "background: expected either \"box\"", NULL},
    {"{" MAT ", \"background\": {\"mesh\": \"m.msh\", \"cells\": [1, 1, 1]}}", FCM_ERR_ARG,
     "background.cells: not allowed with \"mesh\"", NULL},
    /* ---- effects: unknown type, shape of the list, unknown parameter, limits */
    {"{" BASE ", \"effects\": [" FIX ", {\"gravty\": {}}]}", FCM_ERR_ARG,
     "effects[1].gravty: unknown effect", "\"gravity\", \"fixed\", \"motion\""},
    {"{" BASE ", \"effects\": [{\"gravity\": {}, \"damping\": {}}]}", FCM_ERR_ARG,
     "effects[0]: expected an object with one key naming the effect", NULL},
    {"{" BASE ", \"effects\": {\"gravity\": {}}}", FCM_ERR_ARG,
     "effects: expected an array of effects", NULL},
    {"{" BASE ", \"effects\": [{\"motion\": {\"region\": {\"nodes\": [1]}, \"sped\": 3}}]}",
     FCM_ERR_ARG, "effects[0].motion.sped: unknown key", "\"velocity\", \"rotation\""},
    {"{" BASE ", \"effects\": [{\"gravity\": {}}, {\"gravity\": {}}]}", FCM_ERR_ARG,
     "effects[1].gravity: at most 1 gravity effect", NULL},
    {"{" BASE ", \"time\": {\"static\": true}, \"effects\": [{\"damping\": {\"mass\": 1}}]}",
     FCM_ERR_ARG, "effects[0].damping: not allowed in a static scene", NULL},
    {"{" BASE ", \"effects\": [{\"gravity\": 9.81}]}", FCM_ERR_ARG,
     "effects[0].gravity: expected an object of parameters", NULL},
    /* ---- wrong types */
    {"{" BG ", \"material\": {\"young\": \"5e6\", \"poisson\": 0.3}}", FCM_ERR_ARG,
     "material.young: expected a finite number > 0, got \"5e6\"", NULL},
    {"{" MAT ", \"background\": {\"element\": \"hex8\", \"box\": {\"min\": 0, \"max\": [1, 1, "
     "1]}, \"cells\": [1, 1, 1]}}",
     FCM_ERR_ARG, "background.box.min: expected an array of 3 finite numbers, got 0", NULL},
    {"{" BASE ", \"quadrature\": {\"simplify\": 1}}", FCM_ERR_ARG,
     "quadrature.simplify: expected true, false or \"auto\", got 1", NULL},
    {"{" BASE ", \"quadrature\": {\"simplify\": \"sometimes\"}}", FCM_ERR_ARG,
     "quadrature.simplify: expected true, false or \"auto\", got \"sometimes\"", NULL},
    {"{" BASE ", \"effects\": [" FIX ", " FIX ", {\"motion\": {\"region\": {\"nodes\": [0]}, "
     "\"rotation\": {\"speed\": \"fast\"}}}]}",
     FCM_ERR_ARG, "effects[2].motion.rotation.speed: expected a finite number, got \"fast\"", NULL},
    {"{" MAT ", \"background\": {\"element\": \"hex27\", \"box\": {\"min\": [0, 0, 0], \"max\": "
     "[1, 1, 1]}, \"cells\": [1, 1, 1]}}",
     FCM_ERR_ARG,
     "background.element: expected one of \"tet4\", \"tet10\", \"hex8\", \"hex20\", "
     "got \"hex27\"",
     NULL},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"region\": {\"box\": {\"min\": [0, 0, 0], \"max\": "
     "[1, 1, 1]}, \"half_space\": {}}}}]}",
     FCM_ERR_ARG, "effects[0].fixed.region: expected an object with exactly one of", NULL},
    {"{" BASE ", \"effects\": [{\"traction\": {\"region\": {\"nodes\": [1]}, \"value\": [0, 0, "
     "1]}}]}",
     FCM_ERR_ARG, "effects[0].traction.region.nodes: unknown key", "\"box\", \"half_space\""},
    /* ---- out of range */
    {"{" BG ", \"material\": {\"young\": 1e6, \"poisson\": 0.5}}", FCM_ERR_ARG,
     "material.poisson: expected a finite number in (-1, 0.5), got 0.5", NULL},
    {"{" BG ", \"material\": {\"young\": 0, \"poisson\": 0.3}}", FCM_ERR_ARG,
     "material.young: expected a finite number > 0, got 0", NULL},
    {"{" BG ", \"material\": {\"young\": 1e6, \"poisson\": 0.3, \"density\": -1}}", FCM_ERR_ARG,
     "material.density: expected a finite number >= 0, got -1", NULL},
    {"{" BASE ", \"time\": {\"dt\": -1}}", FCM_ERR_ARG,
     "time.dt: expected a finite number > 0, got -1", NULL},
    {"{" MAT ", \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": "
     "[1, 1, 1]}, \"cells\": [1, 0, 1]}}",
     FCM_ERR_ARG, "background.cells[1]: expected an integer in [1, 1000000], got 0", NULL},
    {"{" MAT ", \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": "
     "[1, 1, 1]}, \"cells\": [1, 2.5, 1]}}",
     FCM_ERR_ARG, "background.cells[1]: expected an integer in [1, 1000000], got 2.5", NULL},
    {"{" MAT ", \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [2, 0, 0], \"max\": "
     "[1, 1, 1]}, \"cells\": [1, 1, 1]}}",
     FCM_ERR_ARG, "background.box: expected min[0] < max[0], got min[0] = 2 >= max[0] = 1", NULL},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"region\": {\"box\": {\"min\": [0, 0, 3], \"max\": "
     "[1, 1, 1]}}}}]}",
     FCM_ERR_ARG, "effects[0].fixed.region.box: expected min[2] <= max[2]", NULL},
    {"{" BASE ", \"effects\": [{\"motion\": {\"region\": {\"nodes\": [0]}, \"start\": 2, \"end\": "
     "1}}]}",
     FCM_ERR_ARG, "effects[0].motion.end: expected a finite number > 2, got 1", NULL},
    {"{" BASE ", \"effects\": [{\"motion\": {\"region\": {\"nodes\": [0]}, \"release\": true}}]}",
     FCM_ERR_ARG, "effects[0].motion.release: true needs an \"end\" time", NULL},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], "
     "\"normal\": [0, 0, 0]}}}}]}",
     FCM_ERR_ARG, "effects[0].fixed.region.half_space.normal: expected a non-zero vector", NULL},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"region\": {\"nodes\": [4, 2, 4]}}}]}", FCM_ERR_ARG,
     "effects[0].fixed.region.nodes: expected distinct node ids, got 4 more than once", NULL},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"region\": {\"nodes\": [1, -2]}}}]}", FCM_ERR_ARG,
     "effects[0].fixed.region.nodes[1]: expected a node id", NULL},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"region\": {\"nodes\": [1]}, \"components\": "
     "\"xw\"}}]}",
     FCM_ERR_ARG, "effects[0].fixed.components: expected distinct letters from \"xyz\"", NULL},
    /* ---- fixed / motion on the embedded boundary */
    {"{" BASE ", \"effects\": [{\"fixed\": {\"region\": {\"nodes\": [1]}, \"boundary\": "
     "\"all\"}}]}",
     FCM_ERR_ARG, "effects[0].fixed: expected one of \"region\"", "got both"},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"components\": \"x\"}}]}", FCM_ERR_ARG,
     "effects[0].fixed: missing \"region\"", "\"boundary\""},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"boundary\": {\"nodes\": [1]}}}]}", FCM_ERR_ARG,
     "effects[0].fixed.boundary.nodes: unknown key", "\"box\", \"half_space\""},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"boundary\": \"everything\"}}]}", FCM_ERR_ARG,
     "effects[0].fixed.boundary: expected \"all\" or a region object", NULL},
    {"{" BASE ", \"effects\": [{\"motion\": {\"boundary\": \"all\", \"method\": \"lagrange\"}}]}",
     FCM_ERR_ARG, "effects[0].motion.method:", "\"nitsche\""},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"boundary\": \"all\", \"nitsche_safety\": 0.5}}]}",
     FCM_ERR_ARG, "effects[0].fixed.nitsche_safety: expected a finite number > 1, got 0.5", NULL},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"boundary\": \"all\", \"penalty\": 0}}]}", FCM_ERR_ARG,
     "effects[0].fixed.penalty: expected a finite number > 0", NULL},
    {"{" BASE ", \"effects\": [{\"fixed\": {\"region\": {\"nodes\": [1]}, \"method\": "
     "\"penalty\"}}]}",
     FCM_ERR_ARG, "effects[0].fixed.method: allowed only with \"boundary\"", NULL},
    {"{" BASE ", \"quadrature\": {\"stiffness_strength\": 21}}", FCM_ERR_ARG,
     "quadrature.stiffness_strength: expected an integer in [0, 20], got 21", NULL},
    {"{" BASE ", \"geometry\": {\"shape\": \"tube\", \"inner_radius\": 1.2, \"outer_radius\": 1, "
     "\"length\": 2}}",
     FCM_ERR_ARG, "geometry.inner_radius: expected a finite number in (0, 1), got 1.2", NULL},
    {"{" BASE ", \"geometry\": {\"shape\": \"ball\", \"radius\": 1, \"length\": 2}}", FCM_ERR_ARG,
     "geometry.length: unknown key", "\"center\", \"radius\", \"resolution\""},
    {"{" BASE ", \"geometry\": {\"shape\": \"ball\", \"mesh\": \"x.msh\", \"radius\": 1}}",
     FCM_ERR_ARG, "geometry: expected exactly one of \"shape\"", NULL},
    {"{" BASE ", \"time\": {\"duration\": 2, \"steps\": 10}}", FCM_ERR_ARG,
     "time: expected either \"duration\" or \"steps\", got both", NULL},
    {"{" BASE ", \"time\": {\"load_steps\": 2}}", FCM_ERR_ARG,
     "time.load_steps: only for static scenes", NULL},
    /* ---- the time schemes: names, ranges, each parameter with its scheme only */
    {"{" BASE ", \"time\": {\"integrator\": \"newmarc\"}}", FCM_ERR_ARG, "time.integrator",
     "\"backward_euler\", \"newmark\", \"hht\", \"generalized_alpha\""},
    {"{" BASE ", \"time\": {\"integrator\": \"hht\", \"alpha\": -0.5}}", FCM_ERR_ARG, "time.alpha",
     "-0.5"},
    {"{" BASE ", \"time\": {\"integrator\": \"generalized_alpha\", \"rho_inf\": 1.2}}", FCM_ERR_ARG,
     "time.rho_inf", "1.2"},
    {"{" BASE ", \"time\": {\"integrator\": \"newmark\", \"rho_inf\": 0.5}}", FCM_ERR_ARG,
     "time.rho_inf: only for \"integrator\": \"generalized_alpha\"", "is \"newmark\""},
    {"{" BASE ", \"time\": {\"static\": true, \"alpha\": -0.1}}", FCM_ERR_ARG,
     "time.alpha: only for \"integrator\": \"hht\"", "is \"static\""},
    {"{" BASE ", \"name\": \"a/b\"}", FCM_ERR_ARG, "name: expected 1 to 64 characters", NULL},
    {"{" BASE ", \"version\": 2}", FCM_ERR_ARG, "version: expected an integer in [1, 1], got 2",
     NULL},
    {"{" BG ", " MAT ", \"output\": {\"directory\": \"\"}}", FCM_ERR_ARG,
     "output.directory: expected a non-empty string, got an empty string", NULL},
    {"{" BG ", " MAT ", \"output\": {\"checkpoint_interval\": -1}}", FCM_ERR_ARG,
     "output.checkpoint_interval: expected an integer in [0, 1000000000], got -1", NULL},
    {"{" BG ", " MAT ", \"solver\": {\"stagnation_window\": -1}}", FCM_ERR_ARG,
     "solver.stagnation_window: expected an integer in [0, 1000000000], got -1", NULL},
    {"{" BG ", " MAT ", \"solver\": {\"fixed_cycles\": 3}}", FCM_ERR_ARG,
     "solver.fixed_cycles: 3 fixed cycles need \"method\": \"multigrid\", the method is "
     "\"direct\"",
     NULL},
    {"{" BG ", " MAT ", \"solver\": {\"method\": \"multigrid\", \"fixed_cycles\": 1001}}",
     FCM_ERR_ARG, "solver.fixed_cycles: expected an integer in [0, 1000], got 1001", NULL},
    {"{" BG ", " MAT ", \"solver\": {\"newton\": {\"fixed_iterations\": -1}}}", FCM_ERR_ARG,
     "solver.newton.fixed_iterations: expected an integer in [0, 1000000], got -1", NULL},
    {"{" BG ", " MAT ", \"solver\": {\"newton\": {\"rule\": \"absolute\"}}}", FCM_ERR_ARG,
     "solver.newton.rule:", "\"representative\""},
    {"{" BG ", " MAT ", \"solver\": {\"on_inversion\": \"abort\"}}", FCM_ERR_ARG,
     "solver.on_inversion:", "\"warn\", \"stop\""},
    {"{" BG ", " MAT ", \"solver\": {\"on_inversion\": true}}", FCM_ERR_ARG,
     "solver.on_inversion:", NULL},
    /* ---- non-finite: 1e999 parses to infinity */
    {"{" BG ", \"material\": {\"young\": 1e999, \"poisson\": 0.3}}", FCM_ERR_ARG,
     "material.young: expected a finite number > 0, got inf", NULL},
    {"{" BASE ", \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -1e999]}}]}", FCM_ERR_ARG,
     "effects[0].gravity.acceleration[2]: expected a finite number, got -inf", NULL},
    {"{" BASE ", \"time\": {\"dt\": 1e-300, \"duration\": 1e300}}", FCM_ERR_ARG,
     "time.duration: expected at most 1e9 steps", NULL},
    /* ---- missing files: FCM_ERR_IO naming the resolved path */
    {"{" MAT ", \"background\": {\"mesh\": \"meshes/none.msh\"}}", FCM_ERR_IO,
     "background.mesh: cannot open 'scenes/meshes/none.msh'", "No such file"},
    {"{" BASE ", \"geometry\": {\"tetgen\": \"body\"}}", FCM_ERR_IO,
     "geometry.tetgen: cannot open 'scenes/body.node'", NULL},
    {"{" BASE ", \"geometry\": {\"mesh\": \"/nonexistent/dir/g.msh\"}}", FCM_ERR_IO,
     "geometry.mesh: cannot open '/nonexistent/dir/g.msh'", NULL},
};

/* Source name for row i: the IO rows live in "scenes/" to show path resolution. */
static const char *source_of(const bad_case *c)
{
  return c->status == FCM_ERR_IO ? "scenes/t.json" : "t.json";
}

static int dir_is_empty(const char *path)
{
  DIR *d = opendir(path);
  if (!d) return 0;
  int n = 0;
  for (struct dirent *e = readdir(d); e; e = readdir(d))
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
  closedir(d);
  return n == 0;
}

int main(void)
{
  char dir[64], old_cwd[4096];
  TEST_TRUE(getcwd(old_cwd, sizeof old_cwd) != NULL);
  if (!make_temp_dir(dir, sizeof dir) || chdir(dir) != 0) {
    TEST_TRUE(!"cannot create and enter a temporary directory");
    return TEST_RESULT();
  }
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();

  int n = (int)(sizeof cases / sizeof *cases), classes[FCM_STATUS_COUNT_] = {0};
  TEST_TRUE(n >= 20);
  for (int i = 0; i < n; i++) {
    const bad_case *c = &cases[i];
    fcm_scene *s = (fcm_scene *)&n; /* must come back NULL */
    fcm_status st = fcm_scene_create_from_string(ctx, c->json, source_of(c), &s);
    const char *msg = fcm_ctx_error_message(ctx);
    if (st != c->status || !strstr(msg, c->substr) || (c->substr2 && !strstr(msg, c->substr2)) ||
        strncmp(msg, source_of(c), strlen(source_of(c))))
      TEST_FAIL_("case %d: got %s \"%s\"; expected %s with \"%s\"%s%s", i, fcm_status_name(st), msg,
                 fcm_status_name(c->status), c->substr, c->substr2 ? " and " : "",
                 c->substr2 ? c->substr2 : "");
    TEST_TRUE(s == NULL);
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    classes[c->status]++;
    fcm_ctx_error_clear(ctx);
  }
  TEST_TRUE(classes[FCM_ERR_FORMAT] >= 5 && classes[FCM_ERR_ARG] >= 20 && classes[FCM_ERR_IO] >= 3);

  /* The column of a syntax error is where the bad token starts (1-based). */
  {
    const char *text = "{\"material\": {\"young\": nan}}";
    char expect[64];
    fcm_scene *s = NULL;
    snprintf(expect, sizeof expect, "t.json:1:%d:", (int)(strstr(text, "nan") - text) + 1);
    TEST_ERR(ctx, fcm_scene_create_from_string(ctx, text, "t.json", &s), FCM_ERR_FORMAT, expect);
    TEST_TRUE(s == NULL);
  }

  /* Files: a missing scene file, a NUL byte inside one, a directory as mesh. */
  {
    fcm_scene *s = NULL;
    TEST_ERR(ctx, fcm_scene_create_from_file(ctx, "no-such-scene.json", &s), FCM_ERR_IO,
             "scene: cannot open 'no-such-scene.json': No such file");
    TEST_TRUE(s == NULL);
    const char nul_text[] = "{\"name\": \"a\"\0}";
    TEST_TRUE(write_bytes("nul.json", nul_text, sizeof nul_text - 1) == 0);
    TEST_ERR(ctx, fcm_scene_create_from_file(ctx, "nul.json", &s), FCM_ERR_FORMAT,
             "nul.json:1:13: malformed JSON: NUL byte");
    TEST_TRUE(s == NULL && remove("nul.json") == 0);
    TEST_TRUE(mkdir("d.msh", 0700) == 0);
    TEST_ERR(ctx,
             fcm_scene_create_from_string(ctx, "{" MAT ", \"background\": {\"mesh\": \"d.msh\"}}",
                                          "t.json", &s),
             FCM_ERR_IO, "background.mesh: 'd.msh' is not a regular file");
    TEST_TRUE(s == NULL && remove("d.msh") == 0);
  }

  /* NULL arguments. */
  {
    fcm_scene *s = NULL;
    TEST_ERR(ctx, fcm_scene_create_from_string(ctx, NULL, "t.json", &s), FCM_ERR_ARG, "json_text");
    TEST_ERR(ctx, fcm_scene_create_from_file(ctx, NULL, &s), FCM_ERR_ARG, "path");
    TEST_ERR(ctx, fcm_scene_create_from_file(ctx, "x.json", NULL), FCM_ERR_ARG, "output pointer");
  }

  /* A valid scene naming "out" as output directory: parsing creates nothing. */
  {
    fcm_scene *s = NULL;
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, "{" BASE "}", "t.json", &s));
    fcm_scene_destroy(&s);
  }
  struct stat sb;
  TEST_TRUE(stat("out", &sb) != 0);
  TEST_TRUE(dir_is_empty("."));

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  TEST_TRUE(chdir(old_cwd) == 0);
  TEST_TRUE(rmdir(dir) == 0);
  return TEST_RESULT();
}
