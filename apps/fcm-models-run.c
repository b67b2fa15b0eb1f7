/* fcm-models: the measurements themselves — one configuration of a model run through the
 * scene runner in this process (set-up phases, rule statistics, steps, global moments, peak
 * memory), the generated surfaces (a bumpy sphere, a ball) and the ball study. */
#define _POSIX_C_SOURCE 200809L
#include "app_sphere.h"
#include "fcm-models.h"

#include <fcm/simulation.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------- generated surfaces */

/* The bumpy sphere's radius in the direction x (unit): 0.5 m modulated by a few real
 * spherical harmonics (degrees 2 to 4; the sum stays within +-25 %, so the surface remains
 * star-shaped and free of self-intersections). */
static double bumpy_radius(const double x[3])
{
  const double X = x[0], Y = x[1], Z = x[2];
  const double y20 = 0.5 * (3.0 * Z * Z - 1.0), y22 = X * Y * 3.0;
  const double y33 = X * (X * X - 3.0 * Y * Y), y32 = 5.0 * X * Y * Z;
  const double y40 = (35.0 * Z * Z * Z * Z - 30.0 * Z * Z + 3.0) / 8.0;
  return 0.5 * (1.0 + 0.06 * y20 + 0.04 * y22 + 0.05 * y33 + 0.04 * y32 + 0.04 * y40);
}

int models_write_bumpy(const char *path, long long triangles)
{
  int m = (int)lround(sqrt((double)triangles / 12.0));
  if (m < 2) m = 2;
  app_sphere_mesh s;
  if (!app_cube_sphere(m, &s)) {
    fprintf(stderr, PROG ": bumpy: out of memory\n");
    return 0;
  }
  FILE *f = fopen(path, "w");
  int ok = f != NULL;
  if (f) {
    fprintf(f, "# fcm-models: bumpy sphere, %lld triangles\n", s.nt);
    for (long long v = 0; v < s.nv; v++) {
      const double r = bumpy_radius(s.x + 3 * v);
      fprintf(f, "v %.17g %.17g %.17g\n", r * s.x[3 * v], r * s.x[3 * v + 1], r * s.x[3 * v + 2]);
    }
    for (long long t = 0; t < s.nt; t++)
      fprintf(f, "f %lld %lld %lld\n", (long long)s.t[3 * t] + 1, (long long)s.t[3 * t + 1] + 1,
              (long long)s.t[3 * t + 2] + 1);
    ok = !ferror(f);
    ok = fclose(f) == 0 && ok;
  }
  if (!ok) fprintf(stderr, PROG ": cannot write the bumpy sphere to %s\n", path);
  app_sphere_free(&s);
  return ok;
}

/* ------------------------------------------------------------- one configuration */

/* The library's warnings (filled holes, fallbacks) on stderr. */
static void print_warning(void *user, fcm_log_level level, const char *msg)
{
  (void)user;
  if (level == FCM_LOG_WARNING) fprintf(stderr, PROG ": warning: %s\n", msg);
}

/* A line every few seconds while the cell rules are built. */
static void rules_progress(fcm_index done, fcm_index total, void *user)
{
  const double *t0 = user;
  fprintf(stderr, PROG ":   cell rules %lld/%lld cells (%.1f s)\n", (long long)done,
          (long long)total, fcm_wtime() - *t0);
}

/* The peak resident set of this process (VmHWM) in MB, -1 when /proc is not there. */
static double peak_rss_mb(void)
{
  FILE *f = fopen("/proc/self/status", "r");
  char line[256];
  double kb = -1.0;
  while (f && fgets(line, sizeof line, f))
    if (!strncmp(line, "VmHWM:", 6)) kb = atof(line + 6);
  if (f) fclose(f);
  return kb >= 0.0 ? kb / 1024.0 : -1.0;
}

/* `s` as a JSON string body (quotes and backslashes escaped) into out; 0 when too long. */
static int json_escape(const char *s, char *out, size_t cap)
{
  size_t n = 0;
  for (; *s; s++) {
    if (n + 3 > cap || (unsigned char)*s < 0x20) return 0;
    if (*s == '"' || *s == '\\') out[n++] = '\\';
    out[n++] = *s;
  }
  out[n] = 0;
  return 1;
}

/* The scene of one configuration: the model on a fitted grid of cells h (margin h/2), SNH,
 * gravity, the bottom 11 % of the model held, dt 0.01 s; the volume path adds the Gmsh volume
 * mesh and sub-tet rules. */
static int scene_json(const model_input *m, double h, fcm_element_type element, int path, int steps,
                      char *out, size_t cap)
{
  char file[8192], name[160];
  if (!json_escape(m->path, file, sizeof file) || !json_escape(m->name, name, sizeof name))
    return 0;
  const double hold = m->lo[1] + 0.11 * (m->hi[1] - m->lo[1]);
  const int n = snprintf(
      out, cap,
      "{\"version\": 1, \"name\": \"%s-%s\",\n"
      " \"background\": {\"element\": \"%s\", \"fit_background\": {\"cell_size\": %.17g, "
      "\"margin\": %.17g}},\n"
      " \"geometry\": {\"surface\": \"%s\", \"fill_holes\": %s, \"transform\": {\"scale\": "
      "%.17g}%s},\n"
      " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.4, \"density\": 1000},\n"
      " \"quadrature\": {\"simplify\": \"auto\"%s},\n"
      " \"time\": {\"dt\": 0.01, \"duration\": %.17g},\n"
      " \"effects\": [{\"gravity\": {\"acceleration\": [0, -9.81, 0]}},\n"
      "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, %.17g, 0], \"normal\": [0, -1, "
      "0]}}}}]}\n",
      name, path == PATH_OLD ? "old" : "new", fcm_element_get_info(element)->name, h, 0.5 * h, file,
      m->fill_holes ? "true" : "false", m->scale, path == PATH_OLD ? ", \"volume_mesh\": true" : "",
      path == PATH_OLD ? ", \"moments\": \"volume\"" : "", 0.01 * steps, hold);
  return n > 0 && (size_t)n < cap;
}

/* The moments of the mass rules (authentic points) over every cell: the monomials of degree
 * <= the mass strength, and <= the rules' degree per variable in each (Hex8: Q_2), in the
 * coordinates scaled to [-1, 1] over the model's bounding box, in the order (a, b, c) of
 * x^a y^b z^c with a + b + c ascending, then a descending, b descending. */
static int global_moments(const fcm_simulation *sim, const model_input *m, model_run *r)
{
  const fcm_cell_rules *rules = fcm_simulation_cell_rules(sim);
  const fcm_mesh *mesh = fcm_space_mesh(fcm_simulation_space(sim));
  const int s = fcm_cell_rules_strength(rules, FCM_RULE_MASS),
            qa = fcm_cell_rules_axis_degree(rules, FCM_RULE_MASS);
  if (s < 0 || s > MODELS_MAX_STRENGTH) return 0;
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  int exps[MODELS_MAX_MOMENTS][3], nm = 0;
  for (int deg = 0; deg <= s; deg++)
    for (int a = deg; a >= 0; a--)
      for (int b = deg - a; b >= 0; b--)
        if (a <= qa && b <= qa && deg - a - b <= qa)
          exps[nm][0] = a, exps[nm][1] = b, exps[nm][2] = deg - a - b, nm++;
  double c[3], half = 0.0;
  for (int d = 0; d < 3; d++) {
    c[d] = 0.5 * (m->lo[d] + m->hi[d]);
    half = fmax(half, 0.5 * (m->hi[d] - m->lo[d]));
  }
  long double acc[MODELS_MAX_MOMENTS] = {0};
  double X[27 * 3];
  const fcm_index ncells = fcm_cell_rules_num_cells(rules);
  for (fcm_index e = 0; e < ncells; e++) {
    int np = 0;
    const double *xi = NULL, *w = NULL;
    const unsigned char *fl = NULL;
    if (fcm_cell_rules_get(rules, e, FCM_RULE_MASS, &np, &xi, &w, &fl) != FCM_OK) return 0;
    if (np == 0) continue;
    fcm_mesh_cell_coords(mesh, e, X);
    for (int q = 0; q < np; q++) {
      if (fl && fl[q]) continue;
      double x[3], J[9], p[3][MODELS_MAX_STRENGTH + 1];
      fcm_element_map(type, X, xi + 3 * q, x);
      const double wq = w[q] * fcm_element_jacobian(type, X, xi + 3 * q, J) / (half * half * half);
      for (int d = 0; d < 3; d++) {
        p[d][0] = 1.0;
        for (int k = 1; k <= s; k++)
          p[d][k] = p[d][k - 1] * (x[d] - c[d]) / half;
      }
      for (int k = 0; k < nm; k++)
        acc[k] += (long double)(wq * p[0][exps[k][0]] * p[1][exps[k][1]] * p[2][exps[k][2]]);
    }
  }
  r->num_moments = nm;
  for (int k = 0; k < nm; k++)
    r->moments[k] = (double)acc[k];
  r->volume = r->moments[0];
  return 1;
}

/* The set-up's figures: phases, cells, points per cut cell. */
static void setup_figures(const fcm_simulation *sim, model_run *r)
{
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  r->t_geometry = c.time_setup_geometry, r->t_rules = c.time_setup_rules;
  r->t_space = c.time_setup_space, r->t_integrator = c.time_setup_integrator;
  r->t_setup = c.time_setup;
  r->dofs = (long long)c.num_dofs;
  const fcm_cell_rules *rules = fcm_simulation_cell_rules(sim);
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(rules);
  r->cells = (long long)S->num_cells, r->cut_cells = (long long)S->num_cut;
  const double nc = S->num_cut > 0 ? (double)S->num_cut : 1.0;
  for (int k = 0; k < 2; k++) {
    r->points_initial[k] = (double)S->points_initial[k] / nc;
    r->points_final[k] = (double)S->points_simplified[k] / nc;
    r->strength[k] = fcm_cell_rules_strength(rules, (fcm_rule_kind)k);
  }
}

void models_run_config(const model_input *m, double h, fcm_element_type element, int path,
                       int steps, model_run *r)
{
  memset(r, 0, sizeof *r);
  r->ran = 1;
  const double t0 = fcm_wtime();
  fcm_ctx_options co = fcm_ctx_options_default();
  co.log = print_warning;
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  static char json[16384];
  if (fcm_ctx_create(&co, &ctx) != FCM_OK) {
    snprintf(r->note, sizeof r->note, "cannot create a context");
    return;
  }
  if (!scene_json(m, h, element, path, steps, json, sizeof json)) {
    snprintf(r->note, sizeof r->note, "the model's path is too long or holds control characters");
    goto done;
  }
  if (fcm_scene_create_from_string(ctx, json, PROG, &scene) != FCM_OK) goto failed;
  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = steps;
  so.rules_progress = rules_progress;
  so.rules_progress_user = (void *)&t0;
  so.rules_progress_interval = 5.0;
  if (fcm_simulation_create(ctx, scene, &so, &sim) != FCM_OK) goto failed;
  setup_figures(sim, r);
  fcm_simulation_counters c;
  for (int k = 0; k < steps; k++)
    if (fcm_simulation_step(sim, NULL) != FCM_OK) {
      fcm_simulation_get_counters(sim, &c);
      r->steps = c.steps;
      goto failed;
    }
  fcm_simulation_get_counters(sim, &c);
  r->steps = c.steps;
  const double ns = c.steps > 0 ? (double)c.steps : 1.0;
  r->step_s = c.time_steps / ns, r->assembly_s = c.time_step_assembly / ns;
  r->factor_s = c.time_step_factor / ns, r->solve_s = c.time_step_solve / ns;
  r->log_s = c.time_log / ns;
  if (!global_moments(sim, m, r)) {
    snprintf(r->note, sizeof r->note, "the mass rules' moments could not be computed");
    goto done;
  }
  r->ok = 1;
  goto done;
failed: /* the whole message here; the row's note may cut it */
  fprintf(stderr, PROG ": %s %s: %s\n", m->name, path == PATH_OLD ? "old" : "new",
          fcm_ctx_error_message(ctx));
  snprintf(r->note, sizeof r->note, "%s", fcm_ctx_error_message(ctx));
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  r->peak_mb = peak_rss_mb();
  r->wall = fcm_wtime() - t0;
}

/* ------------------------------------------------------------- the ball study */

double models_fit_exponent(const double *x, const double *y, int count)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (int i = 0; i < count; i++) {
    if (!(x[i] > 0.0 && y[i] > 0.0)) continue;
    const double lx = log(x[i]), ly = log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, n++;
  }
  const double den = n * sxx - sx * sx;
  return n >= 2 && den > 0.0 ? (n * sxy - sx * sy) / den : NAN;
}

/* One size: a unit ball (centre slightly off the grid's symmetry) triangulated with edges of
 * about half a cell, in a grid of n + 2 cells per axis of edge 2/n; the rules with the
 * library's defaults (surface moments), timed. */
static void ball_size(fcm_ctx *ctx, int n, fcm_element_type element, ball_row *b)
{
  memset(b, 0, sizeof *b);
  b->n = n;
  const double h = 2.0 / n, c[3] = {0.0137 * h, 0.0071 * h, -0.0093 * h};
  /* the cube grid's edge maps to a quarter arc: pi/2 / m = h/2 */
  const int m = (int)ceil(3.14159265358979323846 / h);
  app_sphere_mesh s;
  fcm_surface *surf = NULL;
  fcm_geometry *geom = NULL;
  fcm_mesh *mesh = NULL;
  fcm_cell_rules *rules = NULL;
  if (!app_cube_sphere(m, &s)) {
    snprintf(b->note, sizeof b->note, "out of memory");
    return;
  }
  for (long long v = 0; v < s.nv; v++)
    for (int d = 0; d < 3; d++)
      s.x[3 * v + d] += c[d];
  b->triangles = s.nt;
  fcm_surface_mesh_options mo = fcm_surface_mesh_options_default();
  mo.volume_mesh = 0;
  const double lo[3] = {-1.0 - h, -1.0 - h, -1.0 - h}, hi[3] = {1.0 + h, 1.0 + h, 1.0 + h};
  const fcm_index cells[3] = {n + 2, n + 2, n + 2};
  if (fcm_surface_create(ctx, s.nv, s.x, s.nt, s.t, &surf) != FCM_OK ||
      fcm_geometry_create_from_surface(ctx, surf, &mo, &geom) != FCM_OK ||
      fcm_mesh_create_box(ctx, element, lo, hi, cells, &mesh) != FCM_OK)
    goto failed;
  const double t0 = fcm_wtime();
  if (fcm_cell_rules_create(ctx, mesh, geom, NULL, &rules) != FCM_OK) goto failed;
  b->rules_s = fcm_wtime() - t0;
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(rules);
  b->cells = (long long)S->num_cells, b->cut_cells = (long long)S->num_cut;
  b->points_final = S->num_cut > 0 ? (double)(S->points_simplified[0] + S->points_simplified[1]) /
                                         (double)S->num_cut
                                   : 0.0;
  for (int k = 0; k < 2; k++)
    b->strength[k] = fcm_cell_rules_strength(rules, (fcm_rule_kind)k);
  b->ok = 1;
  goto done;
failed:
  snprintf(b->note, sizeof b->note, "%s", fcm_ctx_error_message(ctx));
done:
  fcm_cell_rules_destroy(&rules);
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&geom);
  fcm_surface_destroy(&surf);
  app_sphere_free(&s);
}

int models_ball_study(const int *n, int count, fcm_element_type element, ball_row *out)
{
  fcm_ctx_options co = fcm_ctx_options_default();
  co.log = print_warning;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(&co, &ctx) != FCM_OK) return 0;
  int ok = 1;
  for (int i = 0; i < count; i++) {
    fprintf(stderr, PROG ": ball n = %d ...\n", n[i]);
    ball_size(ctx, n[i], element, &out[i]);
    if (!out[i].ok) ok = 0;
    fprintf(stderr, PROG ": ball n = %d: %lld cut cells, rules %.3f s%s%s\n", n[i],
            out[i].cut_cells, out[i].rules_s, out[i].ok ? "" : ", FAILED: ", out[i].note);
  }
  fcm_ctx_destroy(&ctx);
  return ok;
}
