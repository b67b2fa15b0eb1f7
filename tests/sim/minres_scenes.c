/* "Stabilized Schwarz-preconditioned MINRES" works on the systems it is meant for.
 * Every example scene in the directory argv[1] runs argv[2] steps twice from its own JSON,
 * once with solver {"method": "minres", "preconditioner": "schwarz"} (rtol 1e-9, at most
 * 5000 iterations; the scene's own Newton settings and material, unprojected tangent) and
 * once with the direct solver (CHOLMOD, UMFPACK fallback). Asserted for every step: both
 * converge; every Newton step's MINRES solve reached its tolerance (no solve stopped at
 * the iteration limit, no projection fallback: the unprojected systems were solved); and
 * the displacements agree, max |u_minres - u_direct| <= 1e-6 max |u_direct| (both runs stop
 * Newton at the scene's relative residual tolerance, 1e-5 by default). That agreement is set by
 * the MINRES tolerance, not by Newton's: where Newton converges in one iteration (a free fall:
 * the first steps of ball_on_floor.json, before any contact) nothing corrects the linear
 * solve's error, which is its residual tolerance times the preconditioned system's condition
 * number (about 100 there: 1.06e-6 with rtol 1e-8, 6.7e-8 with 1e-9, 1.9e-8 with 1e-10), so
 * MINRES runs at 1e-9, ten times below the asserted 1e-6 for such conditioning; the other
 * scenes measured at most 5e-9 with 1e-8. MINRES iterations per Newton step are
 * printed with "-v". Octree scenes are skipped (Schwarz is refused on hanging nodes). Further
 * arguments name the scenes to run (default: every scene of the directory, at least five, and the
 * built-in default scene unless it is one of them byte for byte; "default" names the built-in one);
 * "tangent=NAME" sets solver.preconditioner_tangent (default: the scene default, "projected": the
 * Schwarz blocks are built from the PSD-projected tangent while MINRES solves the exact,
 * unprojected Newton system). Usage: sim_minres_scenes SCENE_DIR STEPS [-v] [tangent=NAME]
 * [default] [NAME.json ...] */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_FILES 64

static int cmp_str(const void *a, const void *b)
{
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static char *read_text(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *buf = NULL;
  if (fseek(f, 0, SEEK_END) == 0) {
    long n = ftell(f);
    if (n >= 0 && fseek(f, 0, SEEK_SET) == 0 && (buf = malloc((size_t)n + 1))) {
      if (fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
      } else {
        buf[n] = '\0';
      }
    }
  }
  fclose(f);
  return buf;
}

/* End (one past the closing brace) of the object starting at s[0] == '{' (no braces
 * inside strings in the example scenes' solver objects), or NULL. */
static const char *object_end(const char *s)
{
  int depth = 0;
  for (const char *p = s; *p; p++) {
    if (*p == '{') depth++;
    if (*p == '}' && --depth == 0) return p + 1;
  }
  return NULL;
}

/* The scene text with its top-level "solver" object replaced by `solver` (which gets the
 * scene's "newton" object appended when it has one), full Newton in both runs (a kept
 * factorization changes the path within the Newton tolerance, not the linear solver's
 * agreement this compares); `newton` (may be empty) is added to the Newton settings.
 * malloc'ed. */
static char *with_solver(const char *json, const char *solver, const char *newton_extra)
{
  const char *key = strstr(json, "\"solver\"");
  const char *newton = NULL, *newton_open = NULL, *newton_end = NULL, *obj = NULL, *end = NULL;
  if (key) {
    obj = strchr(key, '{');
    end = obj ? object_end(obj) : NULL;
    if (!end) return NULL;
    const char *nk = strstr(obj, "\"newton\"");
    if (nk && nk < end) {
      newton = nk;
      const char *no = strchr(nk, '{');
      newton_open = no;
      newton_end = no ? object_end(no) : NULL;
      if (!newton_end || newton_end > end) return NULL;
    }
  }
  size_t n = strlen(json) + strlen(solver) + (newton ? (size_t)(newton_end - newton) : 0) + 128;
  char *out = malloc(n);
  if (!out) return NULL;
  char inner[512];
  if (newton)
    snprintf(inner, sizeof inner, "{%s, \"newton\": {\"reuse_factorization\": false%s, %.*s}",
             solver, newton_extra, (int)(newton_end - newton_open - 1), newton_open + 1);
  else
    snprintf(inner, sizeof inner, "{%s, \"newton\": {\"reuse_factorization\": false%s}}", solver,
             newton_extra);
  if (key)
    snprintf(out, n, "%.*s%s%s", (int)(obj - json), json, inner, end);
  else { /* insert after the opening brace of the document */
    const char *open = strchr(json, '{');
    if (!open) {
      free(out);
      return NULL;
    }
    snprintf(out, n, "%.*s\"solver\": %s, %s", (int)(open - json + 1), json, inner, open + 1);
  }
  return out;
}

typedef struct run {
  fcm_scene *scene;
  fcm_simulation *sim;
} run;

static int start(fcm_ctx *ctx, const char *json, const char *path, run *r)
{
  memset(r, 0, sizeof *r);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, path, &r->scene));
  if (!r->scene) return 0;
  TEST_OK(ctx, fcm_simulation_create(ctx, r->scene, NULL, &r->sim));
  return r->sim != NULL;
}

static void stop(run *r)
{
  fcm_simulation_destroy(&r->sim);
  fcm_scene_destroy(&r->scene);
}

static void check_scene(fcm_ctx *ctx, const char *path, const char *file, int steps, int verbose,
                        const char *tangent)
{
  /* "<default>": the built-in default scene */
  char *json = strcmp(path, "<default>") ? read_text(path) : strdup(fcm_scene_default_json());
  TEST_TRUE(json != NULL);
  if (!json) return;
  if (strstr(json, "\"octree\"")) { /* refused there, with a message (tests/sim/octree.c) */
    printf("%s: skipped: the Schwarz preconditioner is not available on octree backgrounds\n",
           file);
    free(json);
    return;
  }
  char ms[256];
  snprintf(ms, sizeof ms,
           "\"method\": \"minres\", \"preconditioner\": \"schwarz\", \"rtol\": 1e-9, "
           "\"max_iterations\": 5000%s%s%s",
           tangent ? ", \"preconditioner_tangent\": \"" : "", tangent ? tangent : "",
           tangent ? "\"" : "");
  /* Contact between bodies: the barrier between pieces makes the converged state depend on
   * where Newton stops far more than on the linear solves (at the default tolerance, 1e-5 of
   * the residual, the dice of dice_on_floor.json differ by 3e-4 of max |u| after one step),
   * so both runs solve Newton far tighter there. Even then the pieces' contact state switches
   * discretely (the two sides of a cut change from the penalty to the barrier once they are
   * d^ apart at a substep's start), and round-off decides the step at which it does: on the
   * dice both runs agree to 3e-14 for five steps, then differ by 2e-6 to 1e-4. So those
   * scenes are compared after their first step only; every later step still has to
   * converge with every MINRES solve reaching its tolerance. */
  const int bodies = strstr(json, "\"bodies\"") != NULL;
  const char *tight = bodies ? ", \"rtol\": 1e-11" : "";
  char *jm = with_solver(json, ms, tight);
  char *jd = with_solver(json, "\"method\": \"direct\", \"direct\": \"cholmod\"", tight);
  TEST_TRUE(jm && jd);
  run m = {NULL, NULL}, d = {NULL, NULL};
  int ok = jm && jd && start(ctx, jm, path, &m);
  ok = ok && start(ctx, jd, path, &d);
  for (int k = 0; ok && k < steps && !fcm_simulation_done(m.sim); k++) {
    fcm_step_info im, id;
    TEST_OK(ctx, fcm_simulation_step(m.sim, &im));
    TEST_OK(ctx, fcm_simulation_step(d.sim, &id));
    if (im.reason != FCM_STEP_CONVERGED || id.reason != FCM_STEP_CONVERGED) {
      TEST_FAIL_("%s step %d: minres %s, direct %s", file, k, fcm_step_reason_name(im.reason),
                 fcm_step_reason_name(id.reason));
      break;
    }
    if (im.inexact_solves != 0 || im.projection_fallbacks != 0 || im.failed_attempts != 0)
      TEST_FAIL_("%s step %d: %d MINRES solves stopped early, %d projection fallbacks, %d "
                 "rejected attempts",
                 file, k, im.inexact_solves, im.projection_fallbacks, im.failed_attempts);
    const fcm_integrator *Im = fcm_simulation_integrator(m.sim),
                         *Id = fcm_simulation_integrator(d.sim);
    const fcm_index n = fcm_integrator_num_dofs(Im);
    TEST_TRUE(n == fcm_integrator_num_dofs(Id));
    const double *um = fcm_integrator_displacement(Im), *ud = fcm_integrator_displacement(Id);
    double diff = 0.0, ref = 0.0;
    for (fcm_index i = 0; i < n; i++) {
      diff = fmax(diff, fabs(um[i] - ud[i]));
      ref = fmax(ref, fabs(ud[i]));
    }
    if (!(diff <= 1e-6 * ref) && (!bodies || k == 0))
      TEST_FAIL_("%s step %d: max |u_minres - u_direct| = %.3e, max |u_direct| = %.3e", file, k,
                 diff, ref);
    if (verbose)
      printf("%-22s step %d: %lld dofs, newton %d (direct %d), minres %lld iterations = %.1f per "
             "newton step, |du|/|u| = %.2e\n",
             file, k, (long long)n, im.newton_iterations, id.newton_iterations,
             im.linear_iterations,
             (double)im.linear_iterations / (im.newton_iterations > 0 ? im.newton_iterations : 1),
             ref > 0 ? diff / ref : diff);
  }
  stop(&m);
  stop(&d);
  free(json);
  free(jm);
  free(jd);
}

int main(int argc, char **argv)
{
  if (argc < 3) return 2;
  const int steps = atoi(argv[2]);
  int verbose = 0, nsel = 0, with_default = 0;
  const char *sel[MAX_FILES], *tangent = NULL;
  for (int a = 3; a < argc; a++) {
    if (!strcmp(argv[a], "-v"))
      verbose = 1;
    else if (!strncmp(argv[a], "tangent=", 8))
      tangent = argv[a] + 8;
    else if (!strcmp(argv[a], "default"))
      with_default = 1;
    else if (nsel < MAX_FILES)
      sel[nsel++] = argv[a];
  }
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  DIR *dir = opendir(argv[1]);
  TEST_TRUE(dir != NULL);
  char *files[MAX_FILES];
  int nf = 0;
  for (struct dirent *e; dir && (e = readdir(dir)) && nf < MAX_FILES;) {
    size_t len = strlen(e->d_name);
    int chosen = nsel == 0;
    for (int k = 0; k < nsel; k++)
      if (!strcmp(e->d_name, sel[k])) chosen = 1;
    if (chosen && len > 5 && !strcmp(e->d_name + len - 5, ".json")) files[nf++] = strdup(e->d_name);
  }
  if (dir) closedir(dir);
  qsort(files, (size_t)nf, sizeof *files, cmp_str);
  TEST_TRUE(nsel ? nf == nsel : nf >= 5);
  /* The built-in default scene, unless it is one of the files run (it is the example
   * twisting_cylinder.json, embedded byte for byte). */
  int default_is_file = 0;
  for (int i = 0; i < nf && !with_default; i++) {
    char path[2048];
    snprintf(path, sizeof path, "%s/%s", argv[1], files[i]);
    char *text = read_text(path);
    if (text && !strcmp(text, fcm_scene_default_json())) default_is_file = 1;
    free(text);
  }
  if (with_default || (nsel == 0 && !default_is_file))
    check_scene(ctx, "<default>", "<default>", steps, verbose, tangent);
  for (int i = 0; i < nf; i++) {
    char path[2048];
    snprintf(path, sizeof path, "%s/%s", argv[1], files[i]);
    check_scene(ctx, path, files[i], steps, verbose, tangent);
    free(files[i]);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
