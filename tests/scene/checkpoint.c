/* Checkpoints of scene runs: for a static run with load steps, surface loads and CG with
 * Schwarz blocks, a dynamic nonlinear run with damping, a released motion and MINRES, and a
 * free spinning body with the direct solver, the dynamic run on Hex8 with MINRES and the
 * multigrid preconditioner, and a spinning body cut in two during the run
 * (checkpoints before and after the cut), and the dynamic run with Newmark and HHT and the cut
 * one with generalized-alpha, running K steps, saving, restoring into a new
 * simulation and running on gives bit for bit the state (acceleration included), time and
 * per-step log (but wall times) of the uninterrupted run; a checkpoint of another time scheme
 * is refused. Error paths: restoring into a stepped simulation, a
 * missing file, a directory, a checkpoint beyond the steps to take, an unwritable path (nothing
 * left behind), a simulation of another scene, a corrupted and a truncated file (format errors
 * naming the file); allocation failures while restoring leave the simulation usable and leak
 * nothing. A checkpoint without a scene (the PETSc linear driver's: the container's source word
 * 0 with DOF and element counts, kind, dt, step count and state, written here through io's
 * container) restores the state bit for bit and is refused when its dt differs. */
#include "scene_util.h"

#include "io/io_impl.h"

#include <sys/stat.h>

/* static: embedded box, gravity, a traction on for 1.5 <= t <= 4.5 and a pressure for
 * 5.5 <= t <= 7.5, 3 load steps: the load changes into and out of a checkpoint at step 5,
 * where the last load increment lp + 1 (f - lp) must come out as f itself */
static const char static_json[] =
    "{\"version\": 1, \"name\": \"ck_static\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
    "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.5, 0.5],"
    "   \"cells\": [3, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000},"
    " \"quadrature\": {\"surface_strength\": 2},"
    " \"solver\": {\"method\": \"cg\", \"preconditioner\": \"schwarz\", \"rtol\": 1e-10,"
    "   \"max_iterations\": 2000},"
    " \"time\": {\"static\": true, \"steps\": 8, \"dt\": 1, \"load_steps\": 3},"
    " \"effects\": [{\"gravity\": {\"acceleration\": [0.013, -0.7, -9.81]}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, 0]}}}},"
    "  {\"traction\": {\"region\": {\"box\": {\"min\": [1.19, -1, -1], \"max\": [2, 1, 1]}},"
    "    \"value\": [37.3, 11.1, -3000.7], \"start\": 1.5, \"end\": 4.5}},"
    "  {\"pressure\": {\"region\": {\"half_space\": {\"point\": [0, 0.49, 0],"
    "    \"normal\": [0, 1, 0]}}, \"value\": 123.456, \"start\": 5.5, \"end\": 7.5}}]}";

/* dynamic: nonlinear, damping, a pulled patch released at t = 0.06, MINRES + Schwarz */
static const char dynamic_json[] =
    "{\"version\": 1, \"name\": \"ck_dynamic\","
    " \"background\": {\"element\": \"tet10\", \"box\": {\"min\": [0, 0, 0],"
    "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.5, 0.5],"
    "   \"cells\": [3, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.4, \"density\": 1000},"
    " \"solver\": {\"method\": \"minres\", \"preconditioner\": \"schwarz\", \"rtol\": 1e-8,"
    "   \"max_iterations\": 2000},"
    " \"time\": {\"dt\": 0.02, \"steps\": 6},"
    " \"effects\": [{\"gravity\": {}}, {\"damping\": {\"stiffness\": 0.01, \"mass\": 0.1}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, 0]}}}},"
    "  {\"motion\": {\"region\": {\"half_space\": {\"point\": [1.5, 0, 0], \"normal\": [1, 0, 0]}},"
    "    \"velocity\": [0, 0, 1], \"end\": 0.06, \"release\": true}}]}";

/* the dynamic run on a Hex8 grid with MINRES preconditioned by the multigrid: the
 * restored run builds its hierarchy anew at its first step, the uninterrupted one had it since
 * step 1, the motion's release at t = 0.06 rebuilds it in both */
static const char mg_json[] =
    "{\"version\": 1, \"name\": \"ck_multigrid\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
    "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [6, 2, 2]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.45, 0.4],"
    "   \"cells\": [3, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.4, \"density\": 1000},"
    " \"solver\": {\"method\": \"minres\", \"preconditioner\": \"multigrid\", \"rtol\": 1e-8,"
    "   \"max_iterations\": 2000, \"multigrid\": {\"coarse_dofs\": 30}},"
    " \"time\": {\"dt\": 0.02, \"steps\": 6},"
    " \"effects\": [{\"gravity\": {}}, {\"damping\": {\"stiffness\": 0.01, \"mass\": 0.1}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, 0]}}}},"
    "  {\"motion\": {\"region\": {\"half_space\": {\"point\": [1.25, 0, 0], \"normal\": [1, 0, "
    "0]}},"
    "    \"velocity\": [0, 0, 1], \"end\": 0.06, \"release\": true}}]}";

/* a free body spinning in one cell */
static const char spin_json[] =
    "{\"version\": 1, \"name\": \"ck_spin\","
    " \"background\": {\"element\": \"hex20\", \"box\": {\"min\": [-1, -1, -1],"
    "   \"max\": [1, 1, 1]}, \"cells\": [1, 1, 1]},"
    " \"geometry\": {\"shape\": \"hemisphere\", \"center\": [0, -0.4, 0], \"radius\": 0.9,"
    "   \"resolution\": 2},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"dt\": 0.01, \"steps\": 6},"
    " \"effects\": [{\"initial_velocity\": {\"angular_velocity\": [0, 0, 3]}}]}";

/* a spinning free body cut in two at t = 0.04 (before step 3): checkpoints before and after
 * the cut */
static const char cut_json[] =
    "{\"version\": 1, \"name\": \"ck_cut\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.25, -0.25, -0.25],"
    "   \"max\": [1.25, 0.75, 0.75]}, \"cells\": [3, 2, 2]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1, 0.5, 0.5],"
    "   \"cells\": [2, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"dt\": 0.02, \"steps\": 6},"
    " \"effects\": [{\"initial_velocity\": {\"angular_velocity\": [0, 0, 4]}},"
    "  {\"cut\": {\"time\": 0.04, \"surface\": {\"plane\": {\"point\": [0.43, 0.25, 0.25],"
    "    \"normal\": [1, 0.1, 0]}}}}]}";

/* Build `out` from a scene text with its "time" section replaced by `time` (the other time
 * schemes on the scenes above: their state holds the acceleration too). */
static void with_time(const char *json, const char *time, char *out, size_t cap)
{
  const char *a = strstr(json, " \"time\": {"), *b = a ? strchr(a, '}') : NULL;
  out[0] = '\0';
  if (!a || !b) return;
  snprintf(out, cap, "%.*s \"time\": %s%s", (int)(a - json), json, time, b + 1);
}

typedef struct run_state {
  fcm_index n;
  double *u, *v, *a, t;
  int a_known;
  long long steps;
  fcm_simulation_counters c;
} run_state;

static void capture(fcm_simulation *sim, run_state *r)
{
  fcm_integrator *I = fcm_simulation_integrator(sim);
  r->n = fcm_integrator_num_dofs(I);
  r->u = calloc((size_t)r->n, sizeof *r->u);
  r->v = calloc((size_t)r->n, sizeof *r->v);
  r->a = calloc((size_t)r->n, sizeof *r->a);
  if (r->u && r->v) fcm_integrator_get_state(I, r->u, r->v, &r->t, &r->steps);
  if (r->a) r->a_known = fcm_integrator_get_acceleration(I, r->a);
  fcm_simulation_get_counters(sim, &r->c);
}

static void release(run_state *r)
{
  free(r->u);
  free(r->v);
  free(r->a);
  memset(r, 0, sizeof *r);
}

static void step_to(fcm_ctx *ctx, fcm_simulation *sim, long long k)
{
  while (fcm_simulation_step_count(sim) < k && !fcm_simulation_done(sim)) {
    fcm_step_info si;
    fcm_status st = fcm_simulation_step(sim, &si);
    TEST_OK(ctx, st);
    if (st != FCM_OK) return;
  }
}

/* The log file without the wall-time column. */
static void log_text(fcm_ctx *ctx, fcm_simulation *sim, const char *path, char *buf, size_t cap)
{
  buf[0] = '\0';
  TEST_OK(ctx, fcm_simulation_write_log(sim, path));
  FILE *f = fopen(path, "r");
  TEST_TRUE(f != NULL);
  if (!f) return;
  char line[512];
  size_t used = 0;
  while (fgets(line, sizeof line, f)) {
    char *comma = strrchr(line, ',');
    if (comma) *comma = '\0';
    used += (size_t)snprintf(buf + used, cap - used, "%s\n", line);
  }
  fclose(f);
  remove(path);
}

static void check_scene(fcm_ctx *ctx, const char *json, const char *dir, long long K)
{
  char ck[256], logp[256];
  static char log_a[1 << 16], log_b[1 << 16];
  snprintf(ck, sizeof ck, "%s/run.fcmck", dir);
  snprintf(logp, sizeof logp, "%s/log.csv", dir);
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  run_state full = {0};
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "ck.json", &scene));
  if (!scene) return;

  /* uninterrupted, with a checkpoint written (and ignored) on the way */
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  step_to(ctx, sim, K);
  TEST_OK(ctx, fcm_simulation_write_checkpoint(sim, ck));
  step_to(ctx, sim, fcm_simulation_num_steps(sim));
  TEST_TRUE(fcm_simulation_done(sim));
  capture(sim, &full);
  log_text(ctx, sim, logp, log_a, sizeof log_a);
  /* restoring into a simulation that has stepped is refused */
  TEST_ERR(ctx, fcm_simulation_read_checkpoint(sim, ck), FCM_ERR_ARG, "new simulation");
  fcm_simulation_destroy(&sim);

  /* a fresh scene object and simulation, restored at step K and run to the end */
  fcm_scene_destroy(&scene);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "ck.json", &scene));
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  TEST_OK(ctx, fcm_simulation_read_checkpoint(sim, ck));
  TEST_TRUE(fcm_simulation_step_count(sim) == K);
  step_to(ctx, sim, fcm_simulation_num_steps(sim));
  run_state res = {0};
  capture(sim, &res);
  log_text(ctx, sim, logp, log_b, sizeof log_b);
  TEST_TRUE(res.n == full.n && res.steps == full.steps);
  TEST_TRUE(!memcmp(&res.t, &full.t, sizeof res.t));
  if (res.u && full.u && res.n == full.n) {
    TEST_TRUE(!memcmp(res.u, full.u, sizeof *res.u * (size_t)res.n));
    TEST_TRUE(!memcmp(res.v, full.v, sizeof *res.v * (size_t)res.n));
    TEST_TRUE(res.a_known == full.a_known && !memcmp(res.a, full.a, sizeof *res.a * (size_t)res.n));
  }
  /* the log is complete and equal; the cumulative iteration counts continue */
  TEST_TRUE(log_a[0] && !strcmp(log_a, log_b));
  TEST_TRUE(res.c.steps == full.c.steps && res.c.newton_iterations == full.c.newton_iterations &&
            res.c.linear_iterations == full.c.linear_iterations);
  /* not a trivial run: the state moved */
  double umax = 0.0;
  for (fcm_index i = 0; i < full.n && full.u; i++)
    umax = fabs(full.u[i]) > umax ? fabs(full.u[i]) : umax;
  TEST_TRUE(umax > 1e-6);
  release(&res);
done:
  release(&full);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  remove(ck);
}

/* Copies of the checkpoint ck in dir/bad.fcmck: one byte flipped, the last byte missing. */
static void check_damaged(fcm_ctx *ctx, fcm_scene *scene, const char *ck, char *path,
                          const char *dir)
{
  FILE *f = fopen(ck, "rb");
  static unsigned char b[1 << 20];
  size_t n = f ? fread(b, 1, sizeof b, f) : 0;
  if (f) fclose(f);
  TEST_TRUE(n > 64 && n < sizeof b);
  snprintf(path, 256, "%s/bad.fcmck", dir);
  for (int k = 0; k < 2 && n > 64; k++) {
    if (k == 0) b[n / 2] ^= 1;
    f = fopen(path, "wb");
    TEST_TRUE(f && fwrite(b, 1, n - (size_t)k, f) == n - (size_t)k);
    if (f) fclose(f);
    if (k == 0) b[n / 2] ^= 1;
    fcm_simulation *sim = NULL;
    TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
    TEST_ERR(ctx, fcm_simulation_read_checkpoint(sim, path), FCM_ERR_FORMAT,
             "bad.fcmck: checksum mismatch");
    TEST_TRUE(fcm_simulation_step_count(sim) == 0);
    fcm_simulation_destroy(&sim);
  }
  remove(path);
}

/* A checkpoint without a scene made from the restored state of ck (dt scaled by dt_factor). */
static void write_linear(fcm_ctx *ctx, const fcm_scene *scene, fcm_simulation *src,
                         const char *path, double dt_factor)
{
  const fcm_scene_time *tm = fcm_scene_get_time(scene);
  const fcm_integrator *in = fcm_simulation_integrator(src);
  const fcm__ckpt_linear h = {(long long)fcm_integrator_num_dofs(in),
                              (long long)fcm_space_num_elements(fcm_simulation_space(src)),
                              fcm_simulation_step_count(src),
                              (long long)tm->integrator,
                              fcm_integrator_time(in),
                              tm->dt * dt_factor};
  fcm__ckpt_writer w;
  TEST_OK(ctx, fcm__ckpt_open(ctx, path, FCM__CKPT_MAGIC,
                              4u /* the first version with this payload */, &w));
  TEST_OK(ctx, fcm__ckpt_put_linear(&w, &h, fcm_integrator_displacement(in),
                                    fcm_integrator_velocity(in)));
  TEST_OK(ctx, fcm__ckpt_commit(&w));
}

static void check_linear(fcm_ctx *ctx, fcm_scene *scene, const char *ck, char *path,
                         const char *dir)
{
  fcm_simulation *src = NULL, *sim = NULL;
  snprintf(path, 256, "%s/linear.fcmck", dir);
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &src));
  TEST_OK(ctx, fcm_simulation_read_checkpoint(src, ck));
  if (!src) return;
  write_linear(ctx, scene, src, path, 1.0);
  const fcm_integrator *a = fcm_simulation_integrator(src);
  const fcm_index n = fcm_integrator_num_dofs(a);
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  TEST_OK(ctx, fcm_simulation_read_checkpoint(sim, path));
  const fcm_integrator *b = fcm_simulation_integrator(sim);
  TEST_TRUE(fcm_integrator_num_dofs(b) == n && n > 0);
  TEST_TRUE(fcm_simulation_step_count(sim) == fcm_simulation_step_count(src));
  TEST_TRUE(fcm_integrator_time(b) == fcm_integrator_time(a));
  TEST_TRUE(!memcmp(fcm_integrator_displacement(b), fcm_integrator_displacement(a),
                    sizeof(double) * (size_t)n));
  TEST_TRUE(
      !memcmp(fcm_integrator_velocity(b), fcm_integrator_velocity(a), sizeof(double) * (size_t)n));
  fcm_simulation_destroy(&sim);
  /* another dt: another problem */
  write_linear(ctx, scene, src, path, 2.0);
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  TEST_ERR(ctx, fcm_simulation_read_checkpoint(sim, path), FCM_ERR_ARG, "another problem");
  fcm_simulation_destroy(&sim);
  fcm_simulation_destroy(&src);
  remove(path);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  char dir[64];
  if (!ctx || !make_temp_dir(dir, sizeof dir)) return TEST_RESULT();
  check_scene(ctx, static_json, dir, 5);
  check_scene(ctx, dynamic_json, dir, 2);
  check_scene(ctx, mg_json, dir, 2);
  check_scene(ctx, spin_json, dir, 3);
  check_scene(ctx, cut_json, dir, 1); /* before the cut */
  check_scene(ctx, cut_json, dir, 4); /* after it */
  { /* Newmark (nonlinear, damping, a release, MINRES) and generalized-alpha across a cut */
    static char nm[4096], ga[4096], hht[4096];
    with_time(dynamic_json, "{\"integrator\": \"newmark\", \"dt\": 0.02, \"steps\": 6}", nm,
              sizeof nm);
    with_time(cut_json,
              "{\"integrator\": \"generalized_alpha\", \"rho_inf\": 0.6, \"dt\": 0.02, "
              "\"steps\": 6}",
              ga, sizeof ga);
    with_time(dynamic_json,
              "{\"integrator\": \"hht\", \"alpha\": -0.2, \"dt\": 0.02, \"steps\": 6}", hht,
              sizeof hht);
    check_scene(ctx, nm, dir, 3);
    check_scene(ctx, ga, dir, 2); /* before the cut */
    check_scene(ctx, ga, dir, 4); /* after it */
    check_scene(ctx, hht, dir, 2);
    /* a checkpoint of another scheme (not part of the fingerprint) is refused, named */
    fcm_scene *a = NULL, *b = NULL;
    fcm_simulation *sa = NULL, *sb = NULL;
    char ckp[256];
    snprintf(ckp, sizeof ckp, "%s/scheme.fcmck", dir);
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, nm, "ck.json", &a));
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, hht, "ck.json", &b));
    if (a) TEST_OK(ctx, fcm_simulation_create(ctx, a, NULL, &sa));
    if (b) TEST_OK(ctx, fcm_simulation_create(ctx, b, NULL, &sb));
    if (sa && sb) {
      step_to(ctx, sa, 1);
      TEST_OK(ctx, fcm_simulation_write_checkpoint(sa, ckp));
      TEST_ERR(ctx, fcm_simulation_read_checkpoint(sb, ckp), FCM_ERR_ARG,
               "written with time.integrator \"newmark\"");
    }
    remove(ckp);
    fcm_simulation_destroy(&sa);
    fcm_simulation_destroy(&sb);
    fcm_scene_destroy(&a);
    fcm_scene_destroy(&b);
  }

  /* error paths */
  fcm_scene *scene = NULL, *other = NULL;
  fcm_simulation *sim = NULL, *sim2 = NULL;
  char ck[256], path[256];
  snprintf(ck, sizeof ck, "%s/e.fcmck", dir);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, spin_json, "ck.json", &scene));
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, dynamic_json, "ck.json", &other));
  if (scene && other) {
    TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
    step_to(ctx, sim, 4);
    TEST_OK(ctx, fcm_simulation_write_checkpoint(sim, ck));
    /* an unwritable path: FCM_ERR_IO naming it, nothing left behind */
    snprintf(path, sizeof path, "%s/no-such-dir/e.fcmck", dir);
    TEST_ERR(ctx, fcm_simulation_write_checkpoint(sim, path), FCM_ERR_IO, "no-such-dir");
    fcm_simulation_destroy(&sim);
    /* a missing file */
    fcm_simulation_options so = fcm_simulation_options_default();
    TEST_OK(ctx, fcm_simulation_create(ctx, scene, &so, &sim));
    snprintf(path, sizeof path, "%s/missing.fcmck", dir);
    TEST_ERR(ctx, fcm_simulation_read_checkpoint(sim, path), FCM_ERR_IO, "missing.fcmck");
    /* a directory is not a checkpoint (and must not be sized by seeking) */
    TEST_ERR(ctx, fcm_simulation_read_checkpoint(sim, dir), FCM_ERR_IO, "not a regular file");
    fcm_simulation_destroy(&sim);
    /* a run cut to 3 steps cannot take a checkpoint of step 4 */
    so.max_steps = 3;
    TEST_OK(ctx, fcm_simulation_create(ctx, scene, &so, &sim));
    TEST_ERR(ctx, fcm_simulation_read_checkpoint(sim, ck), FCM_ERR_ARG, "beyond the 3 steps");
    TEST_TRUE(fcm_simulation_step_count(sim) == 0);
    fcm_simulation_destroy(&sim);
    check_damaged(ctx, scene, ck, path, dir);
    check_linear(ctx, scene, ck, path, dir);
    /* another scene */
    TEST_OK(ctx, fcm_simulation_create(ctx, other, NULL, &sim2));
    TEST_ERR(ctx, fcm_simulation_read_checkpoint(sim2, ck), FCM_ERR_ARG, "different scene");
    fcm_simulation_destroy(&sim2);
    /* checkpoint cadence: the option overrides the scene's (0 there) */
    so = fcm_simulation_options_default();
    so.checkpoint_interval = 2;
    TEST_OK(ctx, fcm_simulation_create(ctx, scene, &so, &sim));
    TEST_TRUE(!fcm_simulation_checkpoint_due(sim));
    step_to(ctx, sim, 1);
    TEST_TRUE(!fcm_simulation_checkpoint_due(sim));
    step_to(ctx, sim, 2);
    TEST_TRUE(fcm_simulation_checkpoint_due(sim));
    fcm_simulation_destroy(&sim);
    so.checkpoint_interval = -2;
    TEST_ERR(ctx, fcm_simulation_create(ctx, scene, &so, &sim), FCM_ERR_ARG, "checkpoint_interval");
  }
  fcm_scene_destroy(&other);

  /* allocation failures while restoring: FCM_ERR_ALLOC, the simulation still fresh */
  failing f;
  fcm_ctx *fctx = failing_ctx(&f);
  fcm_scene *fs = NULL;
  if (fctx) TEST_OK(fctx, fcm_scene_create_from_string(fctx, spin_json, "ck.json", &fs));
  int ok = 0, failures = 0;
  for (long long k = 0; fs && k < 200 && !ok; k++) {
    fcm_simulation *s = NULL;
    f.fail_at = -1;
    TEST_OK(fctx, fcm_simulation_create(fctx, fs, NULL, &s));
    if (!s) break;
    f.count = 0;
    f.fail_at = k;
    fcm_status st = fcm_simulation_read_checkpoint(s, ck);
    f.fail_at = -1;
    if (st == FCM_OK) {
      ok = 1;
      TEST_TRUE(fcm_simulation_step_count(s) == 4);
    } else {
      failures++;
      TEST_TRUE(st == FCM_ERR_ALLOC && fcm_simulation_step_count(s) == 0);
      TEST_OK(fctx, fcm_simulation_read_checkpoint(s, ck)); /* and then it works */
    }
    fcm_simulation_destroy(&s);
  }
  TEST_TRUE(ok && failures >= 3);
  fcm_scene_destroy(&fs);
  if (fctx) TEST_TRUE(fcm_ctx_live_allocations(fctx) == 0);
  fcm_ctx_destroy(&fctx);

  remove(ck);
  fcm_scene_destroy(&scene);
  TEST_TRUE(rmdir(dir) == 0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
