/* What a scene run writes for the engineer: the log's reaction columns of each
 * constraint effect (an embedded beam clamped at one end hangs under gravity: the reaction is
 * minus the assembled weight, rho g |body| to the stabilization's share, and its moment minus
 * the weight's moment; a dynamic clamped block: the reaction is the log's change of momentum
 * per step minus the weight), the frames' stress arrays (cell averages in the background,
 * point values on the surface), the surface at reference positions (every point on the
 * undeformed box's boundary although the beam sags) and the summary's maximum displacement
 * over the body (without embedding: the largest nodal |u|). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"
#include "../io/vtk_reader.h"

#include <stdint.h>

static const char static_json[] =
    "{\"version\": 1, \"name\": \"hang\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.3, -0.2, -0.15],"
    "   \"max\": [2.3, 0.7, 0.65]}, \"cells\": [8, 3, 3]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [2, 0.5, 0.5],"
    "   \"cells\": [4, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 2e6, \"poisson\": 0.3, \"density\": 800},"
    " \"solver\": {\"method\": \"direct\", \"newton\": {\"rtol\": 1e-11}},"
    " \"time\": {\"static\": true, \"steps\": 1, \"dt\": 1},"
    " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.1, 0, 0], \"normal\": [-1, 0, "
    "0]}}}}]}";

static const char dynamic_json[] =
    "{\"version\": 1, \"name\": \"dyn\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [2, 1, 1]},"
    "   \"cells\": [4, 2, 2]},"
    " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"solver\": {\"method\": \"direct\", \"newton\": {\"rule\": \"relative\", \"rtol\": 1e-12}},"
    " \"time\": {\"dt\": 0.01, \"steps\": 4},"
    " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, "
    "0]}}}}]}";

/* The log: header and rows of numbers (at most 8 rows of 32). */
static int read_log(fcm_simulation *sim, char *header, size_t cap, double rows[8][32], int *ncol)
{
  const char *path = "scene_output_log.csv";
  int n = 0;
  *ncol = 0;
  TEST_TRUE(fcm_simulation_write_log(sim, path) == FCM_OK);
  FILE *f = fopen(path, "r");
  char line[4096];
  if (f && fgets(header, (int)cap, f))
    while (n < 8 && fgets(line, sizeof line, f)) {
      int c = 0;
      char *p = line, *end;
      while (*p && *p != '\n' && c < 32) {
        rows[n][c++] = strtod(p, &end);
        p = *end == ',' ? end + 1 : end;
      }
      *ncol = c;
      n++;
    }
  if (f) fclose(f);
  remove(path);
  return n;
}

static double *read_array(const char *path, const char *parent, const char *name, size_t *count,
                          int *components)
{
  vr_doc d;
  double *out = NULL;
  *count = 0;
  if (!vr_load(&d, path)) return NULL;
  if (vr_parse_vtu(&d)) {
    const vr_tag *t = vr_data_array(&d, parent, name);
    if (t) {
      uint64_t bytes = 0;
      const unsigned char *p = vr_array(&d, t, &bytes);
      out = malloc(bytes + 1);
      memcpy(out, p, bytes);
      *count = bytes / sizeof(double);
      if (components) *components = (int)vr_attr_ll(t, "NumberOfComponents");
    }
  }
  vr_free(&d);
  return out;
}

static void static_hang(fcm_ctx *ctx)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, static_json, "hang.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  TEST_OK(ctx, fcm_simulation_step(sim, NULL));
  char header[1024] = "";
  double rows[8][32];
  int ncol = 0;
  TEST_TRUE(read_log(sim, header, sizeof header, rows, &ncol) == 1 && ncol == 24);
  TEST_TRUE(strstr(header,
                   ",momentum_z,reaction_1_x,reaction_1_y,reaction_1_z,moment_1_x,"
                   "moment_1_y,moment_1_z,inverted_points,nonfinite_stresses,"
                   "tolerance,kinetic_energy,elastic_energy,load_work,wall_time\n") != NULL);
  TEST_TRUE(rows[0][19] > 0.0 && rows[0][4] <= rows[0][19]); /* converged: residual <= tol */
  TEST_TRUE(rows[0][17] == 0.0 && isnan(rows[0][18]));       /* nothing inverted, no frame */
  /* static: no kinetic energy; gravity did work on the sagging body */
  TEST_TRUE(rows[0][20] == 0.0 && rows[0][22] > 0.0);
  /* minus the assembled weight and its moment: sum f and sum (X + u) x f over all copies */
  const fcm_space *space = fcm_simulation_space(sim);
  fcm_integrator *integ = fcm_simulation_integrator(sim);
  const fcm_index n = fcm_space_num_dofs(space);
  const double g[3] = {0, 0, -9.81}, *u = fcm_integrator_displacement(integ);
  double *f = calloc((size_t)n, sizeof *f), F[3] = {0, 0, 0}, M[3] = {0, 0, 0};
  TEST_OK(ctx, fcm_assemble_body_force(space, fcm_scene_get_material(scene), g, NULL, f));
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++) {
    const fcm_index d0 = fcm_space_node_dof(space, a);
    for (fcm_index k = 0; d0 >= 0 && k < fcm_space_node_copies(space, a); k++) {
      const fcm_index d = d0 + 3 * k;
      double x[3];
      for (int i = 0; i < 3; i++)
        x[i] = X[3 * a + i] + u[d + i], F[i] += f[d + i];
      M[0] += x[1] * f[d + 2] - x[2] * f[d + 1];
      M[1] += x[2] * f[d] - x[0] * f[d + 2];
      M[2] += x[0] * f[d + 1] - x[1] * f[d];
    }
  }
  const double W = fabs(F[2]), WM = fabs(M[0]) + fabs(M[1]) + fabs(M[2]);
  for (int i = 0; i < 3; i++) {
    TEST_NEAR(rows[0][11 + i], -F[i], 0, 1e-8 * W);
    TEST_NEAR(rows[0][14 + i], -M[i], 0, 1e-8 * WM);
  }
  TEST_NEAR(rows[0][13], 800.0 * 9.81 * 0.5, 1e-3, 0); /* rho g |body| */
  free(f);
  /* the frame: stress arrays; the surface at reference positions although the beam sags */
  TEST_TRUE(vr_mkdir("scene_output_frames"));
  TEST_OK(ctx, fcm_simulation_write_frame(sim, "scene_output_frames", 0));
  size_t cnt = 0;
  int comp = 0;
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  double *sig =
      read_array("scene_output_frames/hang_background_0000.vtu", "CellData", "stress", &cnt, &comp);
  TEST_TRUE(sig && comp == 6 && cnt == 6 * (size_t)nc);
  free(sig);
  double *vm = read_array("scene_output_frames/hang_background_0000.vtu", "CellData", "von_mises",
                          &cnt, NULL);
  double vmax = 0.0;
  for (size_t c = 0; vm && c < cnt; c++)
    vmax = vm[c] > vmax ? vm[c] : vmax;
  TEST_TRUE(vm && cnt == (size_t)nc && vmax > 0.0);
  free(vm);
  double *sed = read_array("scene_output_frames/hang_background_0000.vtu", "CellData",
                           "strain_energy_density", &cnt, NULL);
  TEST_TRUE(sed && cnt == (size_t)nc);
  free(sed);
  double *pts = read_array("scene_output_frames/hang_surface_0000.vtu", "Points", NULL, &cnt, NULL);
  size_t np = cnt / 3, sum = 0;
  double *sd = read_array("scene_output_frames/hang_surface_0000.vtu", "PointData", "displacement",
                          &cnt, NULL);
  TEST_TRUE(pts && sd && cnt == 3 * np && np > 0);
  double umax = 0.0;
  for (size_t i = 0; pts && sd && i < np; i++) {
    const double *p = pts + 3 * i, hi[3] = {2, 0.5, 0.5};
    int on_face = 0, inside = 1;
    for (int k = 0; k < 3; k++) {
      on_face |= p[k] == 0.0 || p[k] == hi[k];
      inside &= p[k] >= 0.0 && p[k] <= hi[k];
    }
    sum += on_face && inside;
    umax = fabs(sd[3 * i + 2]) > umax ? fabs(sd[3 * i + 2]) : umax;
  }
  TEST_TRUE(sum == np);
  TEST_TRUE(umax > 1e-4); /* it does sag: the points are not deformed ones */
  free(pts), free(sd);
  double *svm =
      read_array("scene_output_frames/hang_surface_0000.vtu", "PointData", "von_mises", &cnt, NULL);
  TEST_TRUE(svm && cnt == np);
  free(svm);
  vr_rmdir("scene_output_frames");
  /* the summary: max |u| over the body */
  {
    char *text = NULL;
    size_t len = 0;
    FILE *mf = open_memstream(&text, &len);
    fcm_simulation_summary_view(sim, mf);
    fclose(mf);
    const char *line = text ? strstr(text, "max |u| ") : NULL;
    TEST_TRUE(line && strstr(line, "over the body"));
    if (line) TEST_NEAR(strtod(line + 8, NULL), umax, 0.2, 0); /* the tip's sag dominates */
    free(text);
  }
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

/* FNV-1a 64, the checkpoint's checksum. */
static uint64_t fnv(const unsigned char *p, size_t n)
{
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t k = 0; k < n; k++)
    h = (h ^ p[k]) * 0x100000001b3ull;
  return h;
}

/* An older checkpoint made from a current one (version 5) of a one-row log: the `cut` bytes at
 * row offset `at` (from the row's start) dropped, the version set and the checksum redone. */
static void derive_checkpoint(const unsigned char *buf, long size, uint64_t version, size_t at,
                              size_t cut, const char *path)
{
  unsigned char *b = malloc((size_t)size);
  if (!b) return;
  memcpy(b, buf, (size_t)size);
  /* header 8 x 8 + 3 counters, frames (0), rows (1), then the row */
  size_t pos = 8 * 8 + 3 * 8;
  int64_t frames = 0;
  memcpy(&frames, b + pos, 8);
  pos += 8 + 8 * (size_t)frames + 8;
  memmove(b + pos + at, b + pos + at + cut, (size_t)size - pos - at - cut);
  size -= (long)cut;
  memcpy(b + 8, &version, 8);
  const uint64_t sum = fnv(b, (size_t)size - 8);
  memcpy(b + size - 8, &sum, 8);
  FILE *f = fopen(path, "wb");
  TEST_TRUE(f && fwrite(b, 1, (size_t)size, f) == (size_t)size);
  if (f) fclose(f);
  free(b);
}

/* Checkpoints keep the reaction columns (version 3), the inversion counts (version 4), the
 * Newton tolerance (version 5), the energies (version 6, with the time scheme's block of
 * 5 x 8 bytes after the rows) and the contact columns (version 7: 1 i64 + 3 f64 per row, not in
 * this scene's log: a version-6 file restores the same log); a version-5 file restores with NaN
 * energies, a version-4 file with a NaN tolerance too, a version-3 file with NaN counts too, a
 * version-2 file (rows without reactions either) with NaN there too. Row: 8 f64 + 3 i64, the one
 * constraint's 6 f64, 3 i64 counts, 1 f64 tolerance, 3 f64 energies, the contact block. */
static void checkpoint_versions(fcm_ctx *ctx)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL, *back = NULL;
  unsigned char *buf = NULL;
  const char *v5 = "scene_output_v7.fcmck",
             *old[5] = {"scene_output_v6.fcmck", "scene_output_v5.fcmck", "scene_output_v4.fcmck",
                        "scene_output_v3.fcmck", "scene_output_v2.fcmck"};
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, static_json, "hang.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  TEST_OK(ctx, fcm_simulation_step(sim, NULL));
  TEST_OK(ctx, fcm_simulation_write_checkpoint(sim, v5));
  char h1[1024] = "", h2[1024] = "";
  double r1[8][32], r2[8][32];
  int n1 = 0, n2 = 0;
  TEST_TRUE(read_log(sim, h1, sizeof h1, r1, &n1) == 1 && n1 == 24);
  TEST_TRUE(r1[0][17] == 0.0 && isnan(r1[0][18])); /* nothing inverted; no frame */
  TEST_TRUE(r1[0][19] > 0.0);                      /* the Newton tolerance */
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &back));
  if (back) TEST_OK(ctx, fcm_simulation_read_checkpoint(back, v5));
  if (back) TEST_TRUE(read_log(back, h2, sizeof h2, r2, &n2) == 1 && n2 == n1);
  for (int k = 0; k < 23 && back; k++) /* bit for bit: reactions, count, tolerance, energies */
    TEST_TRUE(k == 18 || r1[0][k] == r2[0][k]);
  if (back) TEST_TRUE(isnan(r2[0][18]));
  fcm_simulation_destroy(&back);
  FILE *f = fopen(v5, "rb");
  long size = 0;
  if (f && fseek(f, 0, SEEK_END) == 0) size = ftell(f);
  buf = calloc((size_t)size + 256, 1);
  if (f) rewind(f);
  TEST_TRUE(f && size > 0 && fread(buf, 1, (size_t)size, f) == (size_t)size);
  if (f) fclose(f);
  if (size < 256) {
    TEST_FAIL_("checkpoint %s has only %ld bytes", v5, size);
    goto done;
  }
  const size_t contact = 4 * 8;                /* the row's contact block */
  const size_t tail = 3 * 8 + contact + 5 * 8; /* the energies, contact and the scheme's block */
  derive_checkpoint(buf, size, 6, 8 * 8 + 3 * 8 + 6 * 8 + 3 * 8 + 8 + 3 * 8, contact, old[0]);
  derive_checkpoint(buf, size, 5, 8 * 8 + 3 * 8 + 6 * 8 + 3 * 8 + 8, tail, old[1]);
  derive_checkpoint(buf, size, 4, 8 * 8 + 3 * 8 + 6 * 8 + 3 * 8, 8 + tail, old[2]);
  derive_checkpoint(buf, size, 3, 8 * 8 + 3 * 8 + 6 * 8, 3 * 8 + 8 + tail, old[3]);
  derive_checkpoint(buf, size, 2, 8 * 8 + 3 * 8, 6 * 8 + 3 * 8 + 8 + tail, old[4]);
  for (int v = 0; v < 5; v++) {
    /* the columns the version recorded */
    const int kept = v == 0 ? 23 : v == 1 ? 20 : v == 2 ? 18 : v == 3 ? 17 : 11;
    TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &back));
    if (back) TEST_OK(ctx, fcm_simulation_read_checkpoint(back, old[v]));
    if (back) TEST_TRUE(read_log(back, h2, sizeof h2, r2, &n2) == 1 && n2 == n1);
    for (int k = 0; k < kept && back; k++)
      TEST_TRUE(k == 18 || r1[0][k] == r2[0][k]); /* 18: no frame, NaN */
    for (int k = kept; k < 23 && back; k++)
      TEST_TRUE(k == 18 || isnan(r2[0][k])); /* not recorded by that version */
    fcm_simulation_destroy(&back);
  }
done:
  free(buf);
  remove(v5);
  remove(old[0]);
  remove(old[1]);
  remove(old[2]);
  remove(old[3]);
  remove(old[4]);
  fcm_simulation_destroy(&back);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

/* Dynamics: reaction = (p_{n+1} - p_n)/dt - W with the log's momentum (plain mesh: the
 * momentum over the mass rules is 1^T M v exactly). */
static void dynamic_block(fcm_ctx *ctx)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, dynamic_json, "dyn.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) goto done;
  while (!fcm_simulation_done(sim))
    TEST_OK(ctx, fcm_simulation_step(sim, NULL));
  char header[1024] = "";
  double rows[8][32];
  int ncol = 0;
  TEST_TRUE(read_log(sim, header, sizeof header, rows, &ncol) == 4 && ncol == 24);
  /* backward Euler dissipates (linear material, at rest at t = 0): kinetic + elastic energy stay
   * below the work of gravity, and kinetic + elastic - work decreases step by step */
  for (int k = 0; k < 4; k++) {
    TEST_TRUE(rows[k][22] > 0.0 && rows[k][20] + rows[k][21] <= rows[k][22]);
    if (k > 0)
      TEST_TRUE(rows[k][20] + rows[k][21] - rows[k][22] <=
                rows[k - 1][20] + rows[k - 1][21] - rows[k - 1][22]);
  }
  const double W[3] = {0, 0, -1000.0 * 9.81 * 2.0};
  double p0[3] = {0, 0, 0};
  for (int k = 0; k < 4; k++) {
    for (int i = 0; i < 3; i++) {
      const double p1 = rows[k][8 + i];
      TEST_NEAR(rows[k][11 + i], (p1 - p0[i]) / 0.01 - W[i], 0, 1e-8 * fabs(W[2]));
      p0[i] = p1;
    }
  }
  TEST_TRUE(fabs(rows[0][10]) > 1e-3); /* the block moves: inertia is part of it */
  /* no embedding: the mesh is the body, max |u| includes the nodes */
  {
    const double *u = fcm_integrator_displacement(fcm_simulation_integrator(sim));
    double umax = 0.0;
    for (fcm_index i = 0; i < fcm_integrator_num_dofs(fcm_simulation_integrator(sim)); i += 3) {
      const double m = sqrt(u[i] * u[i] + u[i + 1] * u[i + 1] + u[i + 2] * u[i + 2]);
      umax = m > umax ? m : umax;
    }
    char *text = NULL;
    size_t len = 0;
    FILE *mf = open_memstream(&text, &len);
    fcm_simulation_summary_view(sim, mf);
    fclose(mf);
    const char *line = text ? strstr(text, "max |u| ") : NULL;
    TEST_TRUE(line && strstr(line, "its nodes"));
    if (line) TEST_NEAR(strtod(line + 8, NULL), umax, 1e-5, 0); /* printed with 6 digits */
    free(text);
  }
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  static_hang(ctx);
  dynamic_block(ctx);
  checkpoint_versions(ctx);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
