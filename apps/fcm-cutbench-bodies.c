/* fcm-cutbench: the rows whose bodies are generated for them — Koschier's plate with attached
 * objects cut by a long bumpy surface, Ton-That's accordion (a hanging cube cut half through at
 * many levels, then ripped by a vertical cut) and octopus (a mouth carved, the jaw freed, the
 * tentacles cut) — written as scene files with their bodies and cut surfaces as OBJ files. */
#define _POSIX_C_SOURCE 200809L
#include "app_sphere.h"
#include "fcm-cutbench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

/* Add triangle (a, b, c) of s with its normal turned towards `out`. */
static void oriented(soup *s, long long a, long long b, long long c, const double out[3])
{
  if (!s->ok) return;
  const double *p = s->x + 3 * a, *q = s->x + 3 * b, *r = s->x + 3 * c;
  const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
  const double v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
  if (n[0] * out[0] + n[1] * out[1] + n[2] * out[2] >= 0.0)
    soup_triangle(s, a, b, c);
  else
    soup_triangle(s, a, c, b);
}

/* Write the closed surface s as the row's body <dir>/<surf_dir>/<name>_body.obj, its measures
 * into m and the path the scene names (relative to the scene) into m->path. */
static int write_body(soup *s, const char *dir, const char *surf_dir, const char *name,
                      cutbench_model *m)
{
  char path[8192];
  snprintf(path, sizeof path, "%s/%s/%s_body.obj", dir, surf_dir, name);
  soup_measure(s, m);
  snprintf(m->path, sizeof m->path, "%s/%s_body.obj", surf_dir, name);
  const int ok = soup_write(s, path);
  soup_clear(s);
  return ok && m->volume > 0.0;
}

/* ------------------------------------------------------------- Koschier's plate */

/* The plate: 1.2 x 0.05 x 0.8 m (x, y up, z), objects standing on it: domes (kind 0), posts
 * (kind 1: cylinders) and a ridge (kind 2: x0, z0 the centre, r the half length along x, a the
 * height); five of them straddle the cut's line z = 0.4. */
#define PLATE_LX 1.2
#define PLATE_LZ 0.8
#define PLATE_T  0.05
typedef struct plate_object {
  int kind;
  double x, z, r, a;
} plate_object;
static const plate_object plate_objects[] = {
    {0, 0.20, 0.36, 0.12, 0.10}, {1, 0.45, 0.42, 0.08, 0.18}, {2, 0.75, 0.41, 0.15, 0.08},
    {0, 0.70, 0.62, 0.14, 0.12}, {1, 0.95, 0.22, 0.07, 0.15}, {0, 1.05, 0.45, 0.10, 0.09},
    {1, 0.20, 0.64, 0.06, 0.22}, {0, 0.45, 0.15, 0.09, 0.07}};

/* The height of the objects at (x, z); w the width of the posts' and ridge's flanks. */
static double plate_height(double x, double z, double w)
{
  double y = 0.0;
  for (size_t k = 0; k < sizeof plate_objects / sizeof *plate_objects; k++) {
    const plate_object *o = &plate_objects[k];
    const double rho = hypot(x - o->x, z - o->z);
    double h = 0.0;
    if (o->kind == 0)
      h = rho < o->r ? o->a * sqrt(1.0 - rho * rho / (o->r * o->r)) : 0.0;
    else if (o->kind == 1)
      h = o->a * fmin(1.0, fmax(0.0, (o->r - rho) / w));
    else {
      const double in = fmin(o->r - fabs(x - o->x), 0.05 - fabs(z - o->z));
      h = o->a * fmin(1.0, fmax(0.0, in / w));
    }
    y = fmax(y, h);
  }
  return y;
}

/* The plate's closed surface: the top a height field over an nx x nz grid, the flat bottom on
 * the same grid, the four sides joining their boundary vertices. */
static void plate_surface(soup *s, long long triangles)
{
  int nx = (int)lround(sqrt(0.25 * (double)triangles * PLATE_LX / PLATE_LZ));
  if (nx < 12) nx = 12;
  const int nz = (int)fmax(8.0, lround(nx * PLATE_LZ / PLATE_LX));
  const double dx = PLATE_LX / nx, dz = PLATE_LZ / nz, w = 1.5 * fmax(dx, dz);
  const long long top = s->nv;
  for (int j = 0; j <= nz; j++)
    for (int i = 0; i <= nx; i++) {
      const double x = i * dx, z = j * dz;
      const double p[3] = {x, PLATE_T + plate_height(x, z, w), z};
      soup_vertex(s, p);
    }
  const long long bot = s->nv;
  for (int j = 0; j <= nz; j++)
    for (int i = 0; i <= nx; i++) {
      const double p[3] = {i * dx, 0.0, j * dz};
      soup_vertex(s, p);
    }
  static const double up[3] = {0, 1, 0}, down[3] = {0, -1, 0};
  for (int j = 0; j < nz; j++)
    for (int i = 0; i < nx; i++) {
      const long long a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
      oriented(s, top + a, top + b, top + c, up), oriented(s, top + a, top + c, top + d, up);
      oriented(s, bot + a, bot + b, bot + c, down), oriented(s, bot + a, bot + c, bot + d, down);
    }
  /* the sides: each boundary edge (a, b) of the grid with its top and bottom vertices */
  for (int side = 0; side < 4; side++) {
    const int n = side < 2 ? nx : nz;
    const double out[3] = {side == 2   ? -1
                           : side == 3 ? 1
                                       : 0,
                           0,
                           side == 0   ? -1
                           : side == 1 ? 1
                                       : 0};
    for (int k = 0; k < n; k++) {
      long long a, b;
      if (side < 2) /* z = 0 (side 0) or z = Lz (side 1) */
        a = (side ? (long long)nz * (nx + 1) : 0) + k, b = a + 1;
      else /* x = 0 (side 2) or x = Lx (side 3) */
        a = (long long)k * (nx + 1) + (side == 3 ? nx : 0), b = a + nx + 1;
      oriented(s, bot + a, bot + b, top + b, out), oriented(s, bot + a, top + b, top + a, out);
    }
  }
}

/* The bumpy cut: the sheet z = 0.4 + noise(x, y) over x in [par[0], par[1]] (u), y in
 * [par[2], par[3]] (v); the noise of wavelengths down to 61 mm, about three cells, its
 * amplitude such that the sheet leaves and re-enters cells: some are cut into more than two
 * pieces by the same surface. */
static void bumpy_patch(double u, double v, const double *par, double p[3])
{
  const double x = (1.0 - u) * par[0] + u * par[1], y = (1.0 - v) * par[2] + v * par[3];
  p[0] = x, p[1] = y;
  p[2] = 0.4 + 0.025 * sin(2.0 * PI * x / 0.23 + 1.3 * sin(2.0 * PI * y / 0.17)) +
         0.012 * sin(2.0 * PI * x / 0.061 + 0.5) * cos(2.0 * PI * y / 0.083);
}

/* The plate's background: the grid placed so that each of the plate's flat faces (x = 0, Lx;
 * y = 0, T; z = 0, Lz) lies at least a tenth of a cell from the grid's planes (a face within a
 * sliver of a grid plane leaves a cell with a thin sheet of material whose rule the surface
 * moments cannot fit), the objects' tops covered. */
static void plate_grid(cutbench_text *t, const cutbench_model *m, double h)
{
  const double thick[3] = {PLATE_LX, PLATE_T, PLATE_LZ};
  double lo[3];
  long long n[3];
  for (int d = 0; d < 3; d++) {
    /* the faces at 0 and thick[d]: the far one a fraction phi of a cell past the near one */
    const double phi = thick[d] / h - floor(thick[d] / h);
    const double a = phi <= 0.8 ? 0.5 * (1.0 - phi) : 1.0 - 0.5 * phi;
    lo[d] = -a * h;
    n[d] = (long long)ceil((m->hi[d] - lo[d]) / h - 1e-9);
  }
  char grid[6144];
  snprintf(grid, sizeof grid,
           "  \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [%.9g, %.9g, %.9g], "
           "\"max\": [%.9g, %.9g, %.9g]}, \"cells\": [%lld, %lld, %lld]},\n"
           "  \"geometry\": {\"surface\": \"%s\", \"fill_holes\": false},\n",
           lo[0], lo[1], lo[2], lo[0] + n[0] * h, lo[1] + n[1] * h, lo[2] + n[2] * h, n[0], n[1],
           n[2], m->path);
  scene_insert(t, "  \"material\"", grid);
}

int cutbench_koschier_plate(cutbench_text *t, const cutbench_paper *p, double scale,
                            long long triangles, const char *solver, const char *dir,
                            const char *surf_dir, const char *name, cutbench_scene *sc)
{
  soup s = {0};
  s.ok = 1;
  plate_surface(&s, triangles);
  cutbench_model m;
  memset(&m, 0, sizeof m);
  int ok = write_body(&s, dir, surf_dir, name, &m);
  /* the nodes of a thin plate's active cells: the factor fitted to the DOFs at scale 1 */
  sc->h = 0.926 * size_for(m.volume, m.area, p->size_target * scale / 3.0, 1.45);
  /* five events, each cutting the next fifth of the length; triangles of about 0.7 cells (the
   * rules' cost grows with the triangles per cell; at scale 1 four per shortest wavelength) */
  const double x0 = -0.05, x1 = PLATE_LX + 0.05, e = 0.7 * sc->h;
  double par[4] = {0, 0, -0.04, m.hi[1] + 0.03};
  const int nu = (int)ceil((x1 - x0) / 5.0 / e), nv = (int)ceil((par[3] - par[2]) / e);
  sc->events = 5, sc->steps = 12;
  for (int k = 0; k < sc->events; k++) {
    sc->event_step[k] = 2 + 2 * k;
    par[0] = x0 + (x1 - x0) * k / 5.0, par[1] = x0 + (x1 - x0) * (k + 1) / 5.0;
    soup_patch(&s, bumpy_patch, par, nu, nv);
    ok = write_event(&s, dir, surf_dir, name, k) && ok;
  }
  soup_clear(&s);
  free(s.x), free(s.t);
  scene_head(
      t, name,
      "After Koschier et al. 2017 (section 7, Fig. 1 left): a 1.2 x 0.05 x 0.8 m plate "
      "with domes, posts and a ridge standing on it, held at both ends under gravity, cut "
      "along its length by a long bumpy surface (noise down to three cells' wavelength, "
      "some cells cut into several pieces by it) in five steps. Stable Neo-Hookean, Hex8, dt 5 ms.",
      NULL, NULL, 0.0, "snh", 1e6, 0.4, solver, 0.005, sc->steps);
  plate_grid(t, &m, sc->h);
  /* cells holding less than 0.5 % material (the objects' rims barely entering a cell layer)
   * are dropped rather than given a rule */
  scene_insert(t, "  \"material\"", "  \"quadrature\": {\"min_fraction\": 0.005},\n");
  cutbench_put(t, "    {\"gravity\": {\"acceleration\": [0, -9.81, 0]}},\n");
  cutbench_put(t, "    {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0.03, 0, 0], "
                  "\"normal\": [-1, 0, 0]}}}},\n");
  cutbench_put(t,
               "    {\"fixed\": {\"region\": {\"half_space\": {\"point\": [%.6g, 0, 0], "
               "\"normal\": [1, 0, 0]}}}},\n",
               PLATE_LX - 0.03);
  scene_cuts(t, sc, surf_dir, name, 0.005);
  return ok;
}

/* ------------------------------------------------------------- Ton-That's accordion */

/* The unit cube hanging from its top (y > 0.96 held) under gravity, cut half through at eight
 * levels from alternate sides (x < 0.75, then x > 0.25), two levels per event from the top,
 * so that the layers hang as an accordion; then a vertical cut x = 0.5 between the two top
 * cuts, crossing both, frees everything below from the held top. */
int cutbench_tonthat_accordion(cutbench_text *t, const cutbench_paper *p, double scale,
                               const char *solver, const char *dir, const char *surf_dir,
                               const char *name, cutbench_scene *sc)
{
  const double L[3] = {1.0, 1.0, 1.0};
  fcm_index n[3];
  sc->h = slab_size(p->size_target * scale, L, n);
  soup s = {0};
  s.ok = 1;
  int ok = 1;
  sc->events = 5, sc->steps = 14;
  for (int k = 0; k < 4; k++) {
    sc->event_step[k] = 2 + 2 * k;
    for (int j = 0; j < 2; j++) {
      const double y = 0.873 - 0.1 * (2 * k + j);
      const double lo[3] = {j ? 0.25 : -0.05, y, -0.05}, hi[3] = {j ? 1.05 : 0.75, y, 1.05};
      soup_rect(&s, 1, y, lo, hi);
    }
    ok = write_event(&s, dir, surf_dir, name, k) && ok;
  }
  sc->event_step[4] = 11;
  const double lo[3] = {0.5, 0.743, -0.05}, hi[3] = {0.5, 0.903, 1.05};
  soup_rect(&s, 0, 0.5, lo, hi);
  ok = write_event(&s, dir, surf_dir, name, 4) && ok;
  soup_clear(&s);
  free(s.x), free(s.t);
  scene_head(t, name,
             "After Ton-That et al. 2024 (section 5.1, Fig. 7, Table 2): a 1 m cube hanging from "
             "its top, cut half through at eight levels from alternate sides into an accordion "
             "(two levels per cut event), then a vertical cut between the top two levels frees "
             "everything below them. Stable Neo-Hookean (E = 1e6 Pa, nu = 0.4), Hex8, dt 0.033 "
             "s.",
             NULL, NULL, 0.0, "snh", 1e6, 0.4, solver, 0.033, sc->steps);
  if (!scene_box_grid(t, L, sc->h, n)) return 0;
  cutbench_put(t, "    {\"gravity\": {\"acceleration\": [0, -9.81, 0]}},\n");
  cutbench_put(t, "    {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0.96, 0], "
                  "\"normal\": [0, 1, 0]}}}},\n");
  scene_cuts(t, sc, surf_dir, name, 0.033);
  return ok;
}

/* ------------------------------------------------------------- Ton-That's octopus */

/* The octopus about its head's centre (0, 1.6, 0): an ellipsoidal head (0.5 x 0.6 x 0.5 m)
 * and eight tentacles 1.4 m long reaching out and down (50 degrees below the horizontal) as
 * narrow bumps of the radius; a positive radius over the sphere keeps the surface closed and
 * free of self-intersections. */
#define OCTO_Y 1.6
static double octopus_radius(const double u[3])
{
  const double e = 1.0 / sqrt(u[0] * u[0] / 0.25 + u[1] * u[1] / 0.36 + u[2] * u[2] / 0.25);
  double r = e;
  const double el = -50.0 * PI / 180.0, s = 0.09;
  for (int k = 0; k < 8; k++) {
    const double az = PI / 8.0 + k * PI / 4.0;
    const double d[3] = {cos(az) * cos(el), sin(el), sin(az) * cos(el)};
    const double c = u[0] * d[0] + u[1] * d[1] + u[2] * d[2];
    r += 1.4 * exp(-(1.0 - c) / (s * s));
  }
  return r;
}

static int octopus_surface(soup *s, long long triangles)
{
  int m = (int)lround(sqrt((double)triangles / 12.0));
  if (m < 2) m = 2;
  app_sphere_mesh g;
  if (!app_cube_sphere(m, &g)) return s->ok = 0, 0;
  for (long long v = 0; v < g.nv; v++) {
    const double *u = g.x + 3 * v, r = octopus_radius(u);
    const double p[3] = {r * u[0], OCTO_Y + r * u[1], r * u[2]};
    soup_vertex(s, p);
  }
  for (long long k = 0; k < g.nt; k++)
    soup_triangle(s, g.t[3 * k], g.t[3 * k + 1], g.t[3 * k + 2]);
  app_sphere_free(&g);
  return s->ok;
}

/* The mouth: a wavy smile y = 1.45 + 0.1 (z / 0.35)^2 + 0.04 sin(2 pi z / 0.175) over z in
 * [-0.35, 0.35] (u), reaching from outside the head's front (x = 0.65) to x = 0.2 inside (v). */
static void mouth_patch(double u, double v, const double *par, double p[3])
{
  (void)par;
  const double z = -0.35 + 0.7 * u, q = z / 0.35;
  p[0] = 0.65 - 0.45 * v, p[2] = z;
  p[1] = OCTO_Y - 0.15 + 0.1 * q * q + 0.04 * sin(2.0 * PI * z / 0.175);
}

int cutbench_tonthat_octopus(cutbench_text *t, const cutbench_paper *p, double scale,
                             long long triangles, const char *solver, const char *dir,
                             const char *surf_dir, const char *name, cutbench_scene *sc)
{
  soup s = {0};
  s.ok = 1;
  octopus_surface(&s, triangles);
  cutbench_model m;
  memset(&m, 0, sizeof m);
  int ok = write_body(&s, dir, surf_dir, name, &m);
  sc->h = size_for(m.volume, m.area, p->size_target * scale / 3.0, 2.0);
  sc->events = 3, sc->steps = 10;
  sc->event_step[0] = 2, sc->event_step[1] = 5, sc->event_step[2] = 8;
  const double e = 0.5 * sc->h;
  soup_patch(&s, mouth_patch, NULL, (int)ceil(0.7 / e * 4.0), (int)ceil(0.45 / e));
  ok = write_event(&s, dir, surf_dir, name, 0) && ok;
  /* the jaw: a vertical cut behind the chin crossing the mouth's back part */
  const double jlo[3] = {0.3, OCTO_Y - 0.45, -0.3}, jhi[3] = {0.3, OCTO_Y + 0.05, 0.3};
  soup_rect(&s, 0, 0.3, jlo, jhi);
  ok = write_event(&s, dir, surf_dir, name, 1) && ok;
  /* the tentacles: a horizontal cut through all eight below the head */
  const double tlo[3] = {m.lo[0] - 0.1, 0, m.lo[2] - 0.1},
               thi[3] = {m.hi[0] + 0.1, 0, m.hi[2] + 0.1};
  soup_rect(&s, 1, OCTO_Y - 0.95, tlo, thi);
  ok = write_event(&s, dir, surf_dir, name, 2) && ok;
  soup_clear(&s);
  free(s.x), free(s.t);
  scene_head(t, name,
             "After Ton-That et al. 2024 (section 5.1, Fig. 8, Table 2): a generated octopus "
             "(a head and eight tentacles, 1.4 m long) held at the top of its head under "
             "gravity; a wavy cut carves its mouth, a second cut crossing the mouth's back "
             "frees the jaw to drop, a third cuts all tentacles. Stable Neo-Hookean (E = 1e7 "
             "Pa, nu = 0.4), Hex8, dt 0.033 s.",
             &m, m.path, sc->h, "snh", 1e7, 0.4, solver, 0.033, sc->steps);
  cutbench_put(t, "    {\"gravity\": {\"acceleration\": [0, -9.81, 0]}},\n");
  cutbench_put(t,
               "    {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, %.6g, 0], "
               "\"normal\": [0, 1, 0]}}}},\n",
               OCTO_Y + 0.5);
  scene_cuts(t, sc, surf_dir, name, 0.033);
  return ok;
}
