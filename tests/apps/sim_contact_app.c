/* fcm-sim on bad contact input: each refusal exits 2 with a message naming the field (the
 * scene key, or the obstacle, the point and its depth) and no traceback without --debug: a
 * negative friction, a box with max <= min, a body starting inside a sphere and inside a
 * closed surface, and an obstacle surface that is not closed. */
#include "app_run.h"
#include "test.h"

/* 1 when the file holds `s`. */
static int file_has(const char *path, const char *s)
{
  static char buf[1 << 16];
  FILE *f = fopen(path, "r");
  size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
  if (f) fclose(f);
  buf[n] = '\0';
  return strstr(buf, s) != NULL;
}

static void write_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (!f) return;
  fputs(text, f);
  fclose(f);
}

/* A ball of radius 0.35 at the origin with one contact effect (the object's members). */
static void scene(const char *path, const char *contact)
{
  char text[4096];
  snprintf(text, sizeof text,
           "{\"version\": 1, \"name\": \"c\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.4, -0.4, -0.4],"
           "   \"max\": [0.4, 0.4, 0.4]}, \"cells\": [4, 4, 4]},"
           " \"geometry\": {\"shape\": \"ball\", \"center\": [0, 0, 0], \"radius\": 0.35},"
           " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3},"
           " \"time\": {\"dt\": 0.02, \"duration\": 0.02},"
           " \"effects\": [{\"contact\": {%s}}]}",
           contact);
  write_file(path, text);
}

/* fcm-sim --check on the scene: exit 2 with `want` on stderr, no source file named. */
static void refused(const char *sim, const char *path, const char *err, const char *want)
{
  char cmd[8192];
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  if (!file_has(err, want)) TEST_FAIL_("stderr lacks \"%s\"", want);
  TEST_TRUE(!file_has(err, "contact.c") && !file_has(err, "contact_obstacle.c"));
}

int main(int argc, char **argv)
{
  if (argc != 3) return 2;
  const char *sim = argv[1], *work = argv[2];
  char path[1024], err[1024], obj[1024], open_obj[1024], contact[2200];
  snprintf(path, sizeof path, "%s/contact-bad.json", work);
  snprintf(err, sizeof err, "%s/contact-stderr.txt", work);
  snprintf(obj, sizeof obj, "%s/contact-block.obj", work);
  snprintf(open_obj, sizeof open_obj, "%s/contact-open.obj", work);
  static const char cube[] = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                             "v -1 -1 -0.3\nv 1 -1 -0.3\nv 1 1 -0.3\nv -1 1 -0.3\n"
                             "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
                             "f 3 4 8\nf 3 8 7\nf 2 3 7\nf 2 7 6\nf 1 5 8\n";
  char closed[1024];
  snprintf(closed, sizeof closed, "%sf 1 8 4\n", cube);
  write_file(obj, closed);
  write_file(open_obj, cube);

  scene(path, "\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]}, \"friction\": -0.2");
  refused(sim, path, err, "effects[0].contact.friction");
  scene(path, "\"box\": {\"min\": [0, 0, -1], \"max\": [1, -1, 0]}");
  refused(sim, path, err, "effects[0].contact.box.max");
  scene(path, "\"sphere\": {\"center\": [0, 0, -0.6], \"radius\": 0.3}");
  refused(sim, path, err, "contact sphere 0: the body starts in penetration");
  TEST_TRUE(file_has(err, "inside the obstacle)"));
  snprintf(contact, sizeof contact, "\"surface\": {\"mesh\": \"%s\"}", obj);
  scene(path, contact);
  refused(sim, path, err, "contact surface 0: the body starts in penetration");
  snprintf(contact, sizeof contact, "\"surface\": {\"mesh\": \"%s\"}", open_obj);
  scene(path, contact);
  refused(sim, path, err, "contact surface 0: not closed: 3 edges belong to one triangle only");
  remove(path);
  remove(err);
  remove(obj);
  remove(open_obj);
  return TEST_RESULT();
}
