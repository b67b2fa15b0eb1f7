/* fcm-sim end to end. Modes:
 *   sim_app check FCM_SIM SCENE       `fcm-sim SCENE --check` exits 0 and prints the summary
 *                                     (SCENE "-": the built-in scene, no file)
 *   sim_app run FCM_SIM WORK_DIR      a small scene run with -o and --steps writes the frames,
 *                                     both PVDs and a CSV log with one row per step, and its
 *                                     summary names the three
 *   sim_app resume FCM_SIM WORK_DIR   a run cut short with checkpoints and resumed ends with
 *                                     frames byte-identical to the uninterrupted run's, the
 *                                     same log (but wall times) and a complete PVD; bad,
 *                                     corrupted and foreign checkpoints are refused
 *   sim_app default FCM_SIM WORK_DIR  `fcm-sim` without arguments (the README quick start) runs
 *                                     the built-in scene to the end and writes its 71 frames
 *                                     into fcm-output/twisting_cylinder with a 210-row log
 *   sim_app default-quick FCM_SIM WORK_DIR
 *                                     the same with --steps 6: frames at steps 0, 3, 6 (every
 *                                     3rd step), PVDs listing them at t = 0, 0.1, 0.2, and
 *                                     6 log rows at t = k/30 with converged Newton steps
 *   sim_app errors FCM_SIM WORK_DIR   invalid scenes and options exit non-zero with the
 *                                     parser's message and create no output directory; a bad
 *                                     output path or checkpoint exits 2 before the set-up */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "output_check.h"
#include "app_run.h"
#include "test.h"

#include <sys/stat.h>
#include <unistd.h>

static void write_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (f) {
    fputs(text, f);
    fclose(f);
  }
}

/* Whether the file contains `needle`. */
/* One CSV row of numbers into v (at most cap); returns the count, -1 on a non-number. */
static int csv_numbers(const char *line, double *v, int cap)
{
  int n = 0;
  const char *p = line;
  while (*p && *p != '\n' && n < cap) {
    char *end;
    v[n++] = strtod(p, &end);
    if (end == p) return -1;
    p = *end == ',' ? end + 1 : end;
  }
  return n;
}

static int file_has(const char *path, const char *needle)
{
  static char buf[1 << 16];
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[n] = '\0';
  return strstr(buf, needle) != NULL;
}

static const char small_scene[] =
    "{\"version\": 1, \"name\": \"small\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1.5, 0.5, "
    "0.5]},"
    "   \"cells\": [3, 1, 1]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.5, 0.5],"
    "   \"cells\": [3, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"dt\": 0.01, \"steps\": 10},"
    " \"output\": {\"directory\": \"unused-by-test\", \"frame_interval\": 2},"
    " \"effects\": [{\"gravity\": {}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, "
    "0]}}}}]}";

/* The numbers after `key` in the first line of the file `path` holding it (at most n); their
 * count. */
static int numbers_after(const char *path, const char *key, long long *v, int n)
{
  char line[4096];
  int m = 0;
  FILE *f = fopen(path, "r");
  while (f && fgets(line, sizeof line, f)) {
    const char *p = strstr(line, key);
    if (!p) continue;
    for (p += strlen(key); *p && m < n; p++)
      if (*p >= '0' && *p <= '9') {
        char *end;
        v[m++] = strtoll(p, &end, 10);
        p = end - 1;
      }
    break;
  }
  if (f) fclose(f);
  return m;
}

/* --check runs (at most 3 steps, finite, the summary); --preview writes its files, and its
 * coarse cell classes are conservative against the rules' (a cell inside is uncut, one outside
 * dropped, every cut cell is cut). */
static int mode_check(const char *sim, const char *scene)
{
  char cmd[8192], out[1024], pv[1024], dir[64] = "/tmp/fcm-sim-preview-XXXXXX";
  snprintf(out, sizeof out, "%s.check-%ld.txt", "/tmp/fcm-sim-check", (long)getpid());
  snprintf(pv, sizeof pv, "%s.preview-%ld.txt", "/tmp/fcm-sim-check", (long)getpid());
  if (!mkdtemp(dir)) return 1;
  const char *file = strcmp(scene, "-") ? scene : "";
  snprintf(cmd, sizeof cmd, "'%s' %s%s%s --check > '%s' 2> /dev/null", sim, *file ? "'" : "", file,
           *file ? "'" : "", out);
  TEST_TRUE(app_run(cmd) == 0);
  TEST_TRUE(file_has(out, "steps,") || file_has(out, " steps, "));
  TEST_TRUE(file_has(out, "computed  inertia") || file_has(out, "skipped   inertia"));
  snprintf(cmd, sizeof cmd, "'%s' %s%s%s --preview -o '%s' > '%s' 2> /dev/null", sim,
           *file ? "'" : "", file, *file ? "'" : "", dir, pv);
  TEST_TRUE(app_run(cmd) == 0);
  long long exact[4], coarse[5];
  if (numbers_after(out, "  cells     ", exact, 4) == 4 &&
      numbers_after(pv, "  background  ", coarse, 5) == 5) {
    /* coarse: the element's digits, cells, inside, cut, outside; exact: cells, uncut, cut,
     * dropped */
    TEST_TRUE(coarse[1] == exact[0]);
    TEST_TRUE(coarse[2] <= exact[1] && coarse[4] <= exact[3] && exact[2] <= coarse[3]);
  }
  snprintf(cmd, sizeof cmd, "test -s \"$(ls '%s'/*_preview.pvd)\" && ls '%s'/*_preview_grid.vtu",
           dir, dir);
  TEST_TRUE(app_run(cmd) == 0 && file_has(pv, "preview of scene"));
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  app_run(cmd);
  remove(out);
  remove(pv);
  return TEST_RESULT();
}

static int mode_run(const char *sim, const char *work)
{
  char cmd[8192], scene[1024], dir[1024], path[4096];
  snprintf(scene, sizeof scene, "%s/small.json", work);
  snprintf(dir, sizeof dir, "%s/small-out/nested", work);
  write_file(scene, small_scene);
  snprintf(cmd, sizeof cmd, "rm -rf '%s/small-out'", work);
  app_run(cmd);
  /* 10 steps in the scene, cut to 4; frames at steps 0, 2, 4 */
  snprintf(cmd, sizeof cmd,
           "mkdir -p '%s' && '%s' '%s' -o '%s' --steps 4 > '%s/small-run.txt' 2>&1", work, sim,
           scene, dir, work);
  TEST_TRUE(app_run(cmd) == 0);
  /* the summary's output line names every series written */
  snprintf(path, sizeof path, "%s/small-run.txt", work);
  char want[4096];
  snprintf(want, sizeof want,
           "  output    %s/small_background.pvd, %s/small_surface.pvd, %s/small_log.csv\n", dir,
           dir, dir);
  TEST_TRUE(file_has(path, want));
  const char *files[] = {"small_background_0000.vtu", "small_background_0002.vtu",
                         "small_surface_0000.vtu",    "small_surface_0002.vtu",
                         "small_background.pvd",      "small_surface.pvd"};
  for (int k = 0; k < 6; k++) {
    snprintf(path, sizeof path, "%s/%s", dir, files[k]);
    TEST_TRUE(app_exists(path));
  }
  snprintf(path, sizeof path, "%s/small_background_0003.vtu", dir);
  TEST_TRUE(!app_exists(path));
  snprintf(path, sizeof path, "%s/small_log.csv", dir);
  FILE *f = fopen(path, "r");
  TEST_TRUE(f != NULL);
  if (f) {
    char line[512];
    /* the fixed effect (index 1) adds its reaction force and moment, then come the inverted
     * points and the NaN stresses of the step's frame, the Newton tolerance, then the wall
     * time */
    TEST_TRUE(fgets(line, sizeof line, f) &&
              !strcmp(line,
                      "step,time,newton_iterations,linear_iterations,residual,energy,"
                      "pieces,mass,momentum_x,momentum_y,momentum_z,reaction_1_x,"
                      "reaction_1_y,reaction_1_z,moment_1_x,moment_1_y,moment_1_z,"
                      "inverted_points,nonfinite_stresses,tolerance,kinetic_energy,elastic_energy,"
                      "load_work,wall_time\n"));
    int rows = 0;
    double v[32];
    while (fgets(line, sizeof line, f) && csv_numbers(line, v, 32) == 24) {
      const double mass = v[7], wall = v[23], res = v[4];
      /* converged steps: the residual is within the stopping rule's tolerance */
      TEST_TRUE(v[19] > 0.0 && res <= v[19]);
      /* a hanging beam: nothing inverted; a frame (NaN-free) after every second step */
      TEST_TRUE(v[17] == 0.0 && (rows % 2 == 1 ? v[18] == 0.0 : isnan(v[18])));
      TEST_TRUE(v[6] == 1 && mass > 0.0);
      rows++;
      TEST_TRUE(v[0] == rows);
      TEST_NEAR(v[1], 0.01 * rows, 1e-12, 1e-14);
      TEST_TRUE(v[2] >= 1 && v[3] == 0 && res >= 0 && wall >= 0);
      /* the support carries the (falling) body: an upward reaction */
      TEST_TRUE(isfinite(v[11]) && v[13] > 0.0);
    }
    TEST_TRUE(rows == 4);
    fclose(f);
  }
  /* the surface VTU holds triangles */
  snprintf(path, sizeof path, "%s/small_surface_0002.vtu", dir);
  TEST_TRUE(file_has(path, "UnstructuredGrid"));

  return TEST_RESULT();
}

static int mode_errors(const char *sim, const char *work)
{
  char cmd[8192], scene[1024], dir[1024], err[1024];
  snprintf(dir, sizeof dir, "%s/must-not-exist", work);
  snprintf(err, sizeof err, "%s/errors-stderr.txt", work);
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  app_run(cmd);
  struct {
    const char *json, *message;
  } bad[] = {{"{\"version\": 1, \"background\": {", ":1:"}, /* malformed JSON */
             {"{\"version\": 1, \"bogus\": 3}", "bogus"},   /* unknown key */
             {"{\"version\": 1, \"name\": \"x\", \"output\": {\"directory\": \"DIR\"},"
              " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
              " \"max\": [1, 1, 1]}, \"cells\": [1, 1, 1]},"
              " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
              " \"effects\": [{\"wind\": {}}]}",
              "wind"}}; /* unknown effect */
  for (int k = 0; k < 3; k++) {
    snprintf(scene, sizeof scene, "%s/bad%d.json", work, k);
    write_file(scene, bad[k].json);
    /* with the scene's directory and with -o */
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' '%s' 2> '%s' > /dev/null", work, sim, scene, err);
    int rc = app_run(cmd);
    TEST_TRUE(rc != 0);
    if (!file_has(err, bad[k].message)) TEST_FAIL_("bad%d: stderr lacks '%s'", k, bad[k].message);
    snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s' 2> /dev/null > /dev/null", sim, scene, dir);
    TEST_TRUE(app_run(cmd) != 0);
    TEST_TRUE(!app_exists(dir));
  }
  snprintf(cmd, sizeof cmd, "cd '%s' && test ! -e DIR", work);
  TEST_TRUE(app_run(cmd) == 0);
  /* a missing file, bad options */
  snprintf(cmd, sizeof cmd, "'%s' '%s/no-such-scene.json' -o '%s' 2> '%s'", sim, work, dir, err);
  TEST_TRUE(app_run(cmd) != 0);
  TEST_TRUE(file_has(err, "no-such-scene.json"));
  TEST_TRUE(!app_exists(dir));
  const char *bad_opts[] = {"--steps 0",
                            "--checkpoint-every 0",
                            "--check --resume x.fcmck",
                            "--cells 4 1 1",
                            "--cantilever",
                            "--resume",
                            "--steps 2.5",
                            "--steps 3x",
                            "--steps=",
                            "--check=1",
                            "-o ''"};
  for (int k = 0; k < (int)(sizeof bad_opts / sizeof *bad_opts); k++) {
    snprintf(cmd, sizeof cmd, "'%s' %s -o '%s' 2> /dev/null", sim, bad_opts[k], dir);
    if (app_run(cmd) != 2) TEST_FAIL_("'%s' should exit 2", bad_opts[k]);
  }
  snprintf(cmd, sizeof cmd, "'%s' a.json b.json 2> /dev/null", sim);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(!app_exists(dir));
  /* inputs of a valid scene checked before the set-up (no "building" line): an output path
   * that is a file, or under one; a --resume file that is not a checkpoint */
  char file[1024];
  snprintf(file, sizeof file, "%s/a-file", work);
  write_file(file, "not a directory\n");
  const char *early[][2] = {{"-o", "a-file"}, {"-o", "a-file/sub"}, {"--resume", "a-file"}};
  for (int k = 0; k < 3; k++) {
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' %s %s --steps 1 2> '%s' > /dev/null", work, sim,
             early[k][0], early[k][1], err);
    if (app_run(cmd) != 2) TEST_FAIL_("'%s %s' should exit 2", early[k][0], early[k][1]);
    TEST_TRUE(!file_has(err, "building") &&
              file_has(err, k < 2 ? "exists and is not a directory" : "not an fcm checkpoint"));
  }
  remove(file);
  /* a region whose nodes are all inactive holds nothing: refused before the cell rules (no
   * such phase with --progress), the scene named once, --preview suggested */
  snprintf(scene, sizeof scene, "%s/inactive.json", work);
  write_file(scene,
             "{\"version\": 1, \"name\": \"inactive\","
             " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
             " \"max\": [2, 1, 1]}, \"cells\": [4, 2, 2]},"
             " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 1, 1]},"
             " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
             " \"effects\": [{\"fixed\": {\"region\": {\"half_space\": {\"point\": [1.9, 0, 0],"
             " \"normal\": [1, 0, 0]}}}}]}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s' --progress 2> '%s' > /dev/null", sim, scene, dir,
           err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "fcm-sim: scene inactive: effects[0]: the fixed region (half_space "
                          "through (1.9, 0, 0) with normal (1, 0, 0)) selects 9 background-mesh "
                          "nodes, none of them active"));
  TEST_TRUE(file_has(err, "fcm-sim: building the background grid") && !file_has(err, "cell rules"));
  TEST_TRUE(file_has(err, "--preview writes each region's nodes"));
  /* --preview of it: the files and the counts, then the same refusal */
  char out[1024], pv[1100];
  snprintf(out, sizeof out, "%s/preview.out", work);
  snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s' --preview 2> '%s' > '%s'", sim, scene, dir, err,
           out);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(out, "effects[0]  fixed: region selects 9 nodes, 0 active"));
  TEST_TRUE(file_has(err, "none of them active"));
  const char *parts[] = {"preview.pvd", "preview_grid.vtu", "preview_surface.vtu",
                         "preview_nodes.vtu"};
  for (int k = 0; k < 4; k++) {
    snprintf(pv, sizeof pv, "%s/inactive_%s", dir, parts[k]);
    TEST_TRUE(app_exists(pv));
    remove(pv);
  }
  /* the exact check after the rules: a sliver of 2e-5 m (volume fraction 4e-5, below
   * quadrature.min_fraction) in the last cells makes their nodes look active before the rules,
   * which drop those cells */
  write_file(scene,
             "{\"version\": 1, \"name\": \"inactive\","
             " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
             " \"max\": [2, 1, 1]}, \"cells\": [4, 2, 2]},"
             " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.50002, 1, 1]},"
             " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
             " \"effects\": [{\"fixed\": {\"region\": {\"half_space\": {\"point\": [1.9, 0, 0],"
             " \"normal\": [1, 0, 0]}}}}]}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s' 2> '%s' > /dev/null", sim, scene, dir, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "fcm-sim: scene inactive: effects[0]: the region's 9 background-mesh "
                          "nodes are all inactive"));
  remove(out);
  remove(scene);
  remove(err);
  return TEST_RESULT();
}

/* Whole file into buf (NUL-terminated); its length, or -1. */
static long slurp(const char *path, char *buf, size_t cap)
{
  FILE *f = fopen(path, "rb");
  if (!f) return -1;
  size_t n = fread(buf, 1, cap - 1, f);
  fclose(f);
  buf[n] = '\0';
  return (long)n;
}

static int mode_resume(const char *sim, const char *work)
{
  static char a[1 << 20], b[1 << 20];
  char cmd[8192], scene[1024], full[1024], cut[1024], path[4096], path2[4096], err[1024];
  snprintf(scene, sizeof scene, "%s/resume.json", work);
  snprintf(full, sizeof full, "%s/resume-full", work);
  snprintf(cut, sizeof cut, "%s/resume-cut", work);
  snprintf(err, sizeof err, "%s/resume-stderr.txt", work);
  /* a nonlinear embedded body under gravity with damping (YOUNG: the material) */
#define RESUME_SCENE(young)                                                                        \
  "{\"version\": 1, \"name\": \"small\","                                                          \
  " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"                         \
  "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"                                           \
  " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.5, 0.5],"              \
  "   \"cells\": [3, 1, 1]},"                                                                      \
  " \"material\": {\"model\": \"snh\", \"young\": " young                                          \
  ", \"poisson\": 0.3, \"density\": 1000},"                                                        \
  " \"time\": {\"dt\": 0.02, \"steps\": 10},"                                                      \
  " \"output\": {\"frame_interval\": 2},"                                                          \
  " \"effects\": [{\"gravity\": {}}, {\"damping\": {\"stiffness\": 0.01}},"                        \
  "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"                             \
  "   \"normal\": [-1, 0, 0]}}}}]}"
  char json[4096];
  snprintf(json, sizeof json, "%s", RESUME_SCENE("1e5"));
  write_file(scene, json);
  snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s'", full, cut);
  app_run(cmd);
  /* uninterrupted: 10 steps, frames 0..5 */
  snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s' -q", sim, scene, full);
  TEST_TRUE(app_run(cmd) == 0);
  /* cut at step 4 with a checkpoint every 2 steps, then resumed from step 4 */
  snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s' -q --steps 4 --checkpoint-every 2", sim, scene, cut);
  TEST_TRUE(app_run(cmd) == 0);
  snprintf(path, sizeof path, "%s/small_checkpoint_000002.fcmck", cut);
  TEST_TRUE(app_exists(path));
  snprintf(path, sizeof path, "%s/small_checkpoint_000004.fcmck", cut);
  TEST_TRUE(app_exists(path));
  snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s' -q --resume '%s/small_checkpoint_000004.fcmck'", sim,
           scene, cut, cut);
  TEST_TRUE(app_run(cmd) == 0);
  /* every frame identical byte for byte, the log identical but for the wall times */
  const char *kinds[] = {"background", "surface"};
  for (int k = 0; k < 2; k++)
    for (int f = 0; f <= 5; f++) {
      snprintf(path, sizeof path, "%s/small_%s_%04d.vtu", full, kinds[k], f);
      snprintf(path2, sizeof path2, "%s/small_%s_%04d.vtu", cut, kinds[k], f);
      long na = slurp(path, a, sizeof a), nb = slurp(path2, b, sizeof b);
      if (na <= 0 || na != nb || memcmp(a, b, (size_t)na))
        TEST_FAIL_("%s differs from the uninterrupted run", path2);
    }
  snprintf(path, sizeof path, "%s/small_log.csv", full);
  snprintf(path2, sizeof path2, "%s/small_log.csv", cut);
  TEST_TRUE(slurp(path, a, sizeof a) > 0 && slurp(path2, b, sizeof b) > 0);
  oc_strip_last_column(a);
  oc_strip_last_column(b);
  TEST_TRUE(!strcmp(a, b));
  /* the PVD index lists all 6 frames with the same times */
  snprintf(path, sizeof path, "%s/small_background.pvd", full);
  snprintf(path2, sizeof path2, "%s/small_background.pvd", cut);
  TEST_TRUE(slurp(path, a, sizeof a) > 0 && slurp(path2, b, sizeof b) > 0);
  {
    int ca = 0, cb = 0;
    for (char *p = a; (p = strstr(p, "<DataSet")); p++)
      ca++;
    for (char *p = b; (p = strstr(p, "<DataSet")); p++)
      cb++;
    TEST_TRUE(ca == 6 && cb == 6);
  }
  /* a corrupted checkpoint: checksum */
  snprintf(path, sizeof path, "%s/small_checkpoint_000002.fcmck", cut);
  long n = slurp(path, a, sizeof a);
  TEST_TRUE(n > 100);
  if (n > 100) {
    a[n / 2] ^= 0x20;
    snprintf(path2, sizeof path2, "%s/corrupt.fcmck", work);
    FILE *f = fopen(path2, "wb");
    TEST_TRUE(f && fwrite(a, 1, (size_t)n, f) == (size_t)n);
    if (f) fclose(f);
    snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s/x' -q --resume '%s' 2> '%s'", sim, scene, work,
             path2, err);
    TEST_TRUE(app_run(cmd) == 2);
    TEST_TRUE(file_has(err, "checksum") && file_has(err, "corrupt.fcmck"));
    /* truncated */
    f = fopen(path2, "wb");
    TEST_TRUE(f && fwrite(a, 1, 40, f) == 40);
    if (f) fclose(f);
    TEST_TRUE(app_run(cmd) == 2);
    TEST_TRUE(file_has(err, "corrupt.fcmck"));
    /* not a checkpoint at all */
    TEST_TRUE(app_run((snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s/x' -q --resume '%s' 2> '%s'",
                                sim, scene, work, scene, err),
                       cmd)) == 2);
    TEST_TRUE(file_has(err, "not an fcm checkpoint"));
    remove(path2);
  }
  /* another scene (stiffer material) refuses the checkpoint */
  char other[1024];
  snprintf(other, sizeof other, "%s/resume-other.json", work);
  {
    snprintf(json, sizeof json, "%s", RESUME_SCENE("2e5"));
    write_file(other, json);
    snprintf(cmd, sizeof cmd, "'%s' '%s' -o '%s/x' -q --resume '%s' 2> '%s'", sim, other, work,
             path, err);
    TEST_TRUE(app_run(cmd) == 2);
    TEST_TRUE(file_has(err, "different scene"));
    remove(other);
  }
  snprintf(path, sizeof path, "%s/x", work);
  TEST_TRUE(!app_exists(path)); /* refused resumes write nothing */
  remove(err);
  return TEST_RESULT();
}

static int mode_default(const char *sim, const char *work)
{
  static char buf[1 << 20];
  char cmd[8192], path[4096];
  snprintf(cmd, sizeof cmd, "rm -rf '%s/default-run' && mkdir -p '%s/default-run'", work, work);
  TEST_TRUE(app_run(cmd) == 0);
  snprintf(cmd, sizeof cmd, "cd '%s/default-run' && '%s' -q", work, sim);
  TEST_TRUE(app_run(cmd) == 0);
  const char *dir = "default-run/fcm-output/twisting_cylinder";
  const char *kinds[] = {"background", "surface"};
  for (int k = 0; k < 2; k++) {
    snprintf(path, sizeof path, "%s/%s/twisting_cylinder_%s_0070.vtu", work, dir, kinds[k]);
    TEST_TRUE(app_exists(path) && file_has(path, "UnstructuredGrid"));
    snprintf(path, sizeof path, "%s/%s/twisting_cylinder_%s_0071.vtu", work, dir, kinds[k]);
    TEST_TRUE(!app_exists(path));
    snprintf(path, sizeof path, "%s/%s/twisting_cylinder_%s.pvd", work, dir, kinds[k]);
    int sets = 0;
    if (slurp(path, buf, sizeof buf) > 0)
      for (char *p = buf; (p = strstr(p, "<DataSet")); p++)
        sets++;
    TEST_TRUE(sets == 71);
  }
  snprintf(path, sizeof path, "%s/%s/twisting_cylinder_log.csv", work, dir);
  int lines = 0;
  if (slurp(path, buf, sizeof buf) > 0)
    for (char *p = buf; *p; p++)
      lines += *p == '\n';
  TEST_TRUE(lines == 211); /* header + 210 steps */
  return TEST_RESULT();
}

/* The built-in scene's first 6 steps, written where `fcm-sim` writes without -o. */
static int mode_default_quick(const char *sim, const char *work)
{
  static char buf[1 << 16];
  char cmd[8192], path[4096];
  const double dt = 0.03333333333333333; /* twisting_cylinder.json */
  snprintf(cmd, sizeof cmd, "rm -rf '%s/default-quick' && mkdir -p '%s/default-quick'", work, work);
  TEST_TRUE(app_run(cmd) == 0);
  snprintf(cmd, sizeof cmd, "cd '%s/default-quick' && '%s' --steps 6 -q", work, sim);
  TEST_TRUE(app_run(cmd) == 0);
  const char *dir = "default-quick/fcm-output/twisting_cylinder";
  const char *kinds[] = {"background", "surface"};
  for (int k = 0; k < 2; k++) {
    for (int f = 0; f <= 3; f++) { /* steps 0, 3, 6: frames 0..2, no frame 3 */
      snprintf(path, sizeof path, "%s/%s/twisting_cylinder_%s_%04d.vtu", work, dir, kinds[k], f);
      if (f < 3 && !(app_exists(path) && file_has(path, "UnstructuredGrid")))
        TEST_FAIL_("%s missing or not a VTU", path);
      if (f == 3 && app_exists(path)) TEST_FAIL_("%s should not exist", path);
    }
    snprintf(path, sizeof path, "%s/%s/twisting_cylinder_%s.pvd", work, dir, kinds[k]);
    int sets = 0;
    if (slurp(path, buf, sizeof buf) > 0)
      for (char *p = buf; (p = strstr(p, "<DataSet")); p++) {
        double t = -1.0;
        const char *q = strstr(p, "timestep=\"");
        TEST_TRUE(q && sscanf(q + 10, "%lf", &t) == 1);
        TEST_NEAR(t, 3 * dt * sets, 1e-12, 1e-14);
        sets++;
      }
    TEST_TRUE(sets == 3);
  }
  snprintf(path, sizeof path, "%s/%s/twisting_cylinder_log.csv", work, dir);
  FILE *f = fopen(path, "r");
  TEST_TRUE(f != NULL);
  if (f) {
    char line[512];
    TEST_TRUE(fgets(line, sizeof line, f) && !strncmp(line, "step,time,newton_iterations,", 28));
    /* two motion effects (indices 1 and 2): 12 reaction columns before the wall time */
    TEST_TRUE(strstr(line, ",moment_1_z,reaction_2_x,") &&
              strstr(line, ",moment_2_z,inverted_points,nonfinite_stresses,tolerance,"
                           "kinetic_energy,elastic_energy,load_work,wall_time\n"));
    int rows = 0;
    double v[32];
    while (fgets(line, sizeof line, f) && csv_numbers(line, v, 32) == 30) {
      TEST_TRUE(v[23] == 0.0); /* the tube buckles, but no point inverts */
      TEST_TRUE(v[6] == 1 && v[7] > 0.0);
      rows++;
      TEST_TRUE(v[0] == rows);
      TEST_NEAR(v[1], dt * rows, 1e-12, 1e-14);
      /* every step needs Newton work (the ends move) and ends converged and finite */
      TEST_TRUE(v[2] >= 1 && v[2] <= 50 && isfinite(v[4]) && v[4] >= 0 && isfinite(v[5]));
      for (int k = 11; k < 23; k++)
        TEST_TRUE(isfinite(v[k]));
    }
    TEST_TRUE(rows == 6);
    fclose(f);
  }
  return TEST_RESULT();
}

int main(int argc, char **argv)
{
  if (argc != 4) return 2;
  if (!strcmp(argv[1], "check")) return mode_check(argv[2], argv[3]);
  if (!strcmp(argv[1], "run")) return mode_run(argv[2], argv[3]);
  if (!strcmp(argv[1], "errors")) return mode_errors(argv[2], argv[3]);
  if (!strcmp(argv[1], "resume")) return mode_resume(argv[2], argv[3]);
  if (!strcmp(argv[1], "default")) return mode_default(argv[2], argv[3]);
  if (!strcmp(argv[1], "default-quick")) return mode_default_quick(argv[2], argv[3]);
  return 2;
}
