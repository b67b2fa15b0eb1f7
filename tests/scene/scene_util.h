/* Shared helpers of the scene tests: a scene that sets every key, a failing allocator,
 * temporary directories and files. */
#ifndef FCM_TEST_SCENE_UTIL_H
#define FCM_TEST_SCENE_UTIL_H

#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"
#include "test_alloc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Every top-level key and every effect type, with values that differ from the defaults
 * and from each other, so that a value landing in the wrong field is noticed. */
static const char full_scene_json[] =
    "{\n"
    "  \"version\": 1,\n"
    "  \"name\": \"full-scene.v1\",\n"
    "  \"description\": \"every key set\",\n"
    "  \"background\": {\"element\": \"tet10\", \"box\": {\"min\": [-1, -2, -3], "
    "\"max\": [4, 5, 6]}, \"cells\": [2, 3, 4]},\n"
    "  \"geometry\": {\"shape\": \"tube\", \"center\": [0.5, 1.5, 2.5], \"axis\": \"x\",\n"
    "    \"inner_radius\": 0.25, \"outer_radius\": 0.75, \"length\": 3, \"radial_cells\": 3,\n"
    "    \"angular_cells\": 12, \"axial_cells\": 7,\n"
    "    \"transform\": {\"scale\": [1, 2, 3], \"rotation\": {\"axis\": [0, 0, 2], "
    "\"angle\": 1.5707963267948966},\n"
    "      \"translation\": [7, 8, 9]}},\n"
    "  \"material\": {\"model\": \"stvk\", \"young\": 2.5e6, \"poisson\": 0.35, "
    "\"density\": 1200},\n"
    "  \"quadrature\": {\"stiffness_strength\": 5, \"mass_strength\": 7, \"surface_strength\": 6,\n"
    "    \"simplify\": false, \"simplify_method\": \"recombine\",\n"
    "    \"stabilization\": {\"mode\": \"mass\", \"alpha\": 1e-8}, \"min_fraction\": 0.001},\n"
    "  \"solver\": {\"method\": \"minres\", \"direct\": \"umfpack\", \"preconditioner\": "
    "\"block_jacobi\",\n"
    "    \"schwarz\": {\"threshold\": 0.25, \"epsilon\": 1e-12, \"clamp\": \"paper\"},\n"
    "    \"rtol\": 1e-6, \"atol\": 1e-12, \"max_iterations\": 321, \"on_inversion\": \"stop\",\n"
    "    \"stagnation_window\": 37,\n"
    "    \"newton\": {\"rtol\": 1e-4, \"max_iterations\": 17, \"line_search\": false,\n"
    "      \"project_psd\": true, \"rule\": \"relative\", \"representative_acceleration\": 10,\n"
    "      \"fixed_iterations\": 2},\n"
    "    \"threads\": 3},\n"
    "  \"time\": {\"static\": false, \"integrator\": \"backward_euler\", \"dt\": 0.02, "
    "\"duration\": 1.5},\n"
    "  \"output\": {\"directory\": \"out/full\", \"frame_interval\": 4, \"checkpoint_interval\": "
    "9,\n"
    "    \"background\": false,\n"
    "    \"surface\": false},\n"
    "  \"effects\": [\n"
    "    {\"gravity\": {\"acceleration\": [0, -9.81, 0]}},\n"
    "    {\"fixed\": {\"region\": {\"nodes\": [5, 3, 11]}, \"components\": \"zx\"}},\n"
    "    {\"motion\": {\"region\": {\"box\": {\"min\": [-1, -2, -3], \"max\": [4, -2, 6], "
    "\"tolerance\": 0.01}},\n"
    "      \"velocity\": [0.1, 0.2, 0.3], \"rotation\": {\"axis\": [0, 3, 0], \"center\": [1, 0, "
    "1],\n"
    "      \"speed\": -0.5}, \"start\": 0.25, \"end\": 1.25, \"release\": true}},\n"
    "    {\"initial_velocity\": {\"region\": {\"half_space\": {\"point\": [0, 0, 1], "
    "\"normal\": [0, 0, -2]}},\n"
    "      \"velocity\": [1, 2, 3], \"angular_velocity\": [0.5, -0.5, 2], "
    "\"center\": [1, 1, 1]}},\n"
    "    {\"damping\": {\"mass\": 0.1, \"stiffness\": 0.02}},\n"
    "    {\"traction\": {\"region\": {\"box\": {\"min\": [3, -2, -3], \"max\": [4, 5, 6]}},\n"
    "      \"value\": [10, 20, 30], \"start\": 0.5}},\n"
    "    {\"pressure\": {\"region\": {\"half_space\": {\"point\": [0, 4, 0], "
    "\"normal\": [0, 1, 0]}},\n"
    "      \"value\": -250, \"end\": 1}},\n"
    "    {\"initial_velocity\": {\"velocity\": [0, 0, -1]}},\n"
    "    {\"cut\": {\"time\": 0.5, \"surface\": {\"rectangle\": {\"center\": [1, 2, 3], "
    "\"normal\": [0, 0, 2],\n"
    "      \"axis\": [1, 0, 1], \"size\": [0.5, 0.25], \"transform\": {\"translation\": [0, 0, "
    "1]}}}}},\n"
    "    {\"contact\": {\"plane\": {\"point\": [0, 0, -2], \"normal\": [0, 0, 3], "
    "\"velocity\": [0, 0, 0.5]},\n"
    "      \"distance\": 0.01, \"stiffness\": 2e6}}\n"
    "  ]\n"
    "}\n";

/* Write `n` bytes to a file; returns 0 on success. */
static inline int write_bytes(const char *path, const char *data, size_t n)
{
  FILE *fp = fopen(path, "wb");
  if (!fp) return 1;
  int bad = fwrite(data, 1, n, fp) != n;
  bad |= fclose(fp) != 0;
  return bad;
}

static inline int write_text(const char *path, const char *text)
{
  return write_bytes(path, text, strlen(text));
}

/* Remove the n files named in `files` from the directory `dir`, then the directory. */
static inline void remove_temp_dir(const char *dir, const char *const *files, int n)
{
  char path[1024];
  for (int i = 0; i < n; i++) {
    snprintf(path, sizeof path, "%s/%s", dir, files[i]);
    remove(path);
  }
  rmdir(dir);
}

/* A fresh directory under /tmp (template in buf, at least 32 bytes); NULL on failure. */
static inline char *make_temp_dir(char *buf, size_t len)
{
  snprintf(buf, len, "/tmp/fcm-scene-XXXXXX");
  return mkdtemp(buf);
}

/* A fresh directory under /tmp made the working directory (buf as make_temp_dir()); 0 (and a
 * failed check) when that fails. */
static inline int enter_temp_dir(char *buf, size_t len)
{
  if (make_temp_dir(buf, len) && chdir(buf) == 0) return 1;
  TEST_FAIL_("cannot make a temporary directory");
  return 0;
}

/* fcm_scene_view() of a scene without its first line (name and source). */
static inline char *view_body(const fcm_scene *s)
{
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  if (!f) return NULL;
  fcm_scene_view(s, f);
  fclose(f);
  char *nl = text ? strchr(text, '\n') : NULL;
  if (nl) memmove(text, nl + 1, strlen(nl + 1) + 1);
  /* file names relative to the working directory come back absolute: the same files */
  char cwd[1024];
  if (text && getcwd(cwd, sizeof cwd - 1)) {
    strcat(cwd, "/");
    const size_t n = strlen(cwd);
    for (char *at = strstr(text, cwd); at; at = strstr(at, cwd))
      memmove(at, at + n, strlen(at + n) + 1);
  }
  return text;
}

/* The normalized JSON of a scene, parsed again from another directory, is the same scene
 * (the same view but for the source) and normalizes to the same text. */
static inline void check_normalized(fcm_ctx *ctx, const fcm_scene *s, const char *file)
{
  fcm_scene *again = NULL;
  TEST_OK(ctx,
          fcm_scene_create_from_string(ctx, fcm_scene_json(s), "/nonexistent/again.json", &again));
  if (!again) {
    fprintf(stderr, "  normalized %s:\n%s\n", file, fcm_scene_json(s));
    return;
  }
  char *a = view_body(s), *b = view_body(again);
  TEST_TRUE(a && b);
  if (a && b && strcmp(a, b)) TEST_FAIL_("%s: normalized scene differs:\n%s\nvs\n%s", file, a, b);
  if (strcmp(fcm_scene_json(s), fcm_scene_json(again)))
    TEST_FAIL_("%s: normalizing twice changes the text", file);
  /* every default is filled in: the sections a scene may leave out are there */
  const char *keys[] = {"\"quadrature\"", "\"solver\"", "\"newton\"", "\"time\"", "\"output\""};
  for (int k = 0; k < 5; k++)
    if (!strstr(fcm_scene_json(s), keys[k]))
      TEST_FAIL_("%s: no %s in the normalized scene", file, keys[k]);
  free(a);
  free(b);
  fcm_scene_destroy(&again);
}

#endif
