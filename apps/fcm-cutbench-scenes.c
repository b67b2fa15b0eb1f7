/* fcm-cutbench: the papers' figures, the generated bunny-like body, the helpers every scene
 * writer shares, and the scenes of the bunny and slab rows written as scene files with their
 * cut surfaces (triangle surfaces in OBJ files beside them), so that a row runs exactly what
 * `fcm-sim` would run from those files (the rows with bodies of their own:
 * fcm-cutbench-bodies.c). */
#define _POSIX_C_SOURCE 200809L
#include "app_sphere.h"
#include "cli.h"
#include "fcm-cutbench.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

/* ------------------------------------------------------------- the papers */

const cutbench_paper cutbench_papers[ROW_COUNT] = {
    {"dick-bunny3", "Dick 2011 Table 1", "Bunny 3", "5.48k -> 8.27k hexahedra", 5480, 1, 0.0286,
     0.0928, 0, 0.5, "1 core of a 2.8 GHz Xeon X5560; corotated linear; 3 V-cycles", "hex8",
     "corotated_linear", 1},
    {"dick-bunny2", "Dick 2011 Table 1", "Bunny 2", "26.1k -> 42.4k hexahedra", 26100, 1, 0.143,
     0.498, 0, 0.5, "1 core of a 2.8 GHz Xeon X5560; corotated linear; 3 V-cycles", "hex8",
     "corotated_linear", 0},
    {"dick-bunny", "Dick 2011 Table 1", "Bunny", "118k -> 197k hexahedra", 118000, 1, 0.693, 2.42,
     0, 0.5, "1 core of a 2.8 GHz Xeon X5560; corotated linear; 3 V-cycles", "hex8",
     "corotated_linear", 0},
    {"koschier-bunny", "Koschier 2017 sec. 7", "bunny: groove carved then peeled",
     "5326 -> 9432 DOFs", 5326, 0, 0.646, 1.375, 0, 0.1,
     "i7-6700HQ 4 cores; implicit Euler; StVK (cut: 47 % of a step)", "hex8", "snh", 1},
    {"koschier-plate", "Koschier 2017 sec. 7", "plate with attached objects: bumpy cut",
     "47643 -> 53326 DOFs", 47643, 0, 1.639, 9.365, 0, 0.1,
     "i7-6700HQ 4 cores; implicit Euler; StVK (cut: 17.5 % of a step)", "hex8", "snh", 0},
    {"tonthat-slab", "Ton-That 2024 Table 2", "thin slab: multiple intersecting cuts", "7.2k DOFs",
     7200, 0, 0.0, 0.627, 3.355, 0.1, "i9-13900K; SNH; 1 Newton iteration", "hex8", "snh", 1},
    {"tonthat-accordion", "Ton-That 2024 Table 2", "accordion: hanging cube cut into pleats",
     "22.8k DOFs", 22800, 0, 0.0, 5.785, 9.203, 0.1, "i9-13900K; SNH; 1 Newton iteration", "hex8",
     "snh", 0},
    {"tonthat-octopus", "Ton-That 2024 Table 2", "octopus: mouth carved, jaw and tentacles cut",
     "20.8k DOFs", 20800, 0, 0.0, 2.05, 17.3, 0.1, "i9-13900K; SNH; 1 Newton iteration", "hex8",
     "snh", 0},
};

/* ------------------------------------------------------------- the bunny-like body */

/* A bump of height a in the direction d (unit) of angular width about s radians. */
static double lobe(const double u[3], const double d[3], double a, double s)
{
  const double c = u[0] * d[0] + u[1] * d[1] + u[2] * d[2];
  return a * exp(-(1.0 - c) / (s * s));
}

static void unit(double v[3])
{
  const double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int d = 0; d < 3; d++)
    v[d] /= n;
}

/* The body's radius from its centre (0, 0.055, 0) in the unit direction u: an ellipsoid
 * (0.07 x 0.055 x 0.05 m) with a head, two ears and a tail as smooth bumps. A positive radius
 * over the sphere makes a star-shaped surface: closed and free of self-intersections. */
static double lobed_radius(const double u[3])
{
  static int init = 0;
  static double head[3] = {0.8, 0.6, 0.0}, ear1[3] = {0.3, 1.0, 0.28}, ear2[3] = {0.3, 1.0, -0.28},
                tail[3] = {-1.0, 0.25, 0.0};
  if (!init) {
    unit(head), unit(ear1), unit(ear2), unit(tail);
    init = 1;
  }
  const double e = 1.0 / sqrt(u[0] * u[0] / (0.07 * 0.07) + u[1] * u[1] / (0.055 * 0.055) +
                              u[2] * u[2] / (0.05 * 0.05));
  return e + lobe(u, head, 0.028, 0.4) + lobe(u, ear1, 0.05, 0.2) + lobe(u, ear2, 0.05, 0.2) +
         lobe(u, tail, 0.012, 0.25);
}

int cutbench_write_lobed(const char *path, long long triangles)
{
  int m = (int)lround(sqrt((double)triangles / 12.0));
  if (m < 2) m = 2;
  app_sphere_mesh s;
  if (!app_cube_sphere(m, &s)) {
    fprintf(stderr, PROG ": the generated body: out of memory\n");
    return 0;
  }
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, path, &out);
  if (f) {
    fprintf(f, "# fcm-cutbench: a bunny-like lobed body, %lld triangles\n", s.nt);
    for (long long v = 0; v < s.nv; v++) {
      const double r = lobed_radius(s.x + 3 * v);
      fprintf(f, "v %.9g %.9g %.9g\n", r * s.x[3 * v], 0.055 + r * s.x[3 * v + 1],
              r * s.x[3 * v + 2]);
    }
    for (long long t = 0; t < s.nt; t++)
      fprintf(f, "f %lld %lld %lld\n", (long long)s.t[3 * t] + 1, (long long)s.t[3 * t + 1] + 1,
              (long long)s.t[3 * t + 2] + 1);
  }
  app_sphere_free(&s);
  return f && cli_output_commit(PROG, &out);
}

/* Adds triangle abc's area and its signed volume against the origin (the divergence theorem's
 * term: a closed surface's sum is its enclosed volume). */
static void triangle_measure(const double *a, const double *b, const double *c, double *vol,
                             double *area)
{
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
  *area += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  *vol += (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / 6.0;
}

int cutbench_model_measure(fcm_ctx *ctx, cutbench_model *m)
{
  fcm_surface *s = NULL;
  if (fcm_surface_create_from_file(ctx, m->path, &s) != FCM_OK) {
    fprintf(stderr, PROG ": %s: %s\n", m->path, fcm_ctx_error_message(ctx));
    return 0;
  }
  fcm_surface_bounding_box(s, m->lo, m->hi);
  const double *x = fcm_surface_coords(s);
  const fcm_index *t = fcm_surface_triangles(s), nt = fcm_surface_num_triangles(s);
  double vol = 0.0, area = 0.0;
  for (fcm_index k = 0; k < nt; k++) {
    const double *a = x + 3 * t[3 * k], *b = x + 3 * t[3 * k + 1], *c = x + 3 * t[3 * k + 2];
    triangle_measure(a, b, c, &vol, &area);
  }
  m->volume = fabs(vol), m->area = area;
  fcm_surface_destroy(&s);
  if (!(m->volume > 0.0)) {
    fprintf(stderr, PROG ": %s: the surface encloses no volume\n", m->path);
    return 0;
  }
  return 1;
}

/* ------------------------------------------------------------- cut surfaces */

long long soup_vertex(soup *s, const double p[3])
{
  if (s->nv == s->capv) {
    s->capv = s->capv ? 2 * s->capv : 256;
    double *x = realloc(s->x, sizeof *x * 3 * (size_t)s->capv);
    if (!x) return s->ok = 0, 0;
    s->x = x;
  }
  memcpy(s->x + 3 * s->nv, p, 3 * sizeof *p);
  return s->nv++;
}

void soup_triangle(soup *s, long long a, long long b, long long c)
{
  if (!s->ok) return;
  if (s->nt == s->capt) {
    s->capt = s->capt ? 2 * s->capt : 256;
    long long *t = realloc(s->t, sizeof *t * 3 * (size_t)s->capt);
    if (!t) {
      s->ok = 0;
      return;
    }
    s->t = t;
  }
  s->t[3 * s->nt] = a, s->t[3 * s->nt + 1] = b, s->t[3 * s->nt + 2] = c;
  s->nt++;
}

void soup_patch(soup *s, patch_fn f, const double *par, int nu, int nv)
{
  const long long base = s->nv;
  for (int j = 0; j <= nv; j++)
    for (int i = 0; i <= nu; i++) {
      double p[3];
      f((double)i / nu, (double)j / nv, par, p);
      soup_vertex(s, p);
    }
  for (int j = 0; j < nv; j++)
    for (int i = 0; i < nu; i++) {
      const long long a = base + j * (nu + 1) + i;
      soup_triangle(s, a, a + 1, a + nu + 2);
      soup_triangle(s, a, a + nu + 2, a + nu + 1);
    }
}

/* A rectangle: par = centre (3), the side along u (3, full length), the side along v (3). */
static void rect_patch(double u, double v, const double *par, double p[3])
{
  for (int d = 0; d < 3; d++)
    p[d] = par[d] + (u - 0.5) * par[3 + d] + (v - 0.5) * par[6 + d];
}

void soup_rect(soup *s, int axis, double value, const double lo[3], const double hi[3])
{
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  double par[9] = {0};
  par[axis] = value;
  par[a] = 0.5 * (lo[a] + hi[a]), par[b] = 0.5 * (lo[b] + hi[b]);
  par[3 + a] = hi[a] - lo[a];
  par[6 + b] = hi[b] - lo[b];
  soup_patch(s, rect_patch, par, 1, 1);
}

/* The groove's knife, a curved band about the vertical axis through (par[0], par[2]): angle
 * par[3] + u (par[4] - par[3]), height par[5] + v (par[6] - par[5]), radius par[7] (1 +
 * 0.08 sin 3θ + 0.06 sin πv). */
static void band_patch(double u, double v, const double *par, double p[3])
{
  const double th = par[3] + u * (par[4] - par[3]);
  const double r = par[7] * (1.0 + 0.08 * sin(3.0 * th) + 0.06 * sin(PI * v));
  p[0] = par[0] + r * cos(th), p[2] = par[2] + r * sin(th);
  p[1] = par[5] + v * (par[6] - par[5]);
}

/* The peeling cut: the ring at height par[6] from the band's top edge (v = 1) out to par[8]. */
static void ring_patch(double u, double v, const double *par, double p[3])
{
  const double th = 2.0 * PI * u;
  const double r0 = par[7] * (1.0 + 0.08 * sin(3.0 * th)), r = r0 + v * (par[8] - r0);
  p[0] = par[0] + r * cos(th), p[2] = par[2] + r * sin(th), p[1] = par[6];
}

int soup_write(soup *s, const char *path)
{
  if (!s->ok) {
    fprintf(stderr, PROG ": %s: out of memory\n", path);
    return 0;
  }
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, path, &out);
  if (!f) return 0;
  fprintf(f, "# fcm-cutbench: a cut surface, %lld triangles\n", s->nt);
  for (long long v = 0; v < s->nv; v++)
    fprintf(f, "v %.9g %.9g %.9g\n", s->x[3 * v], s->x[3 * v + 1], s->x[3 * v + 2]);
  for (long long t = 0; t < s->nt; t++)
    fprintf(f, "f %lld %lld %lld\n", s->t[3 * t] + 1, s->t[3 * t + 1] + 1, s->t[3 * t + 2] + 1);
  return cli_output_commit(PROG, &out);
}

void soup_clear(soup *s)
{
  free(s->x);
  free(s->t);
  memset(s, 0, sizeof *s);
  s->ok = 1;
}

void soup_measure(const soup *s, cutbench_model *m)
{
  double vol = 0.0, area = 0.0;
  for (int d = 0; d < 3; d++)
    m->lo[d] = HUGE_VAL, m->hi[d] = -HUGE_VAL;
  for (long long v = 0; v < s->nv; v++)
    for (int d = 0; d < 3; d++)
      m->lo[d] = fmin(m->lo[d], s->x[3 * v + d]), m->hi[d] = fmax(m->hi[d], s->x[3 * v + d]);
  for (long long k = 0; k < s->nt; k++) {
    const double *a = s->x + 3 * s->t[3 * k], *b = s->x + 3 * s->t[3 * k + 1],
                 *c = s->x + 3 * s->t[3 * k + 2];
    triangle_measure(a, b, c, &vol, &area);
  }
  m->volume = fabs(vol), m->area = area;
}

/* ------------------------------------------------------------- sizes */

/* The cell size h at which a body of volume V and area A has about n active cells (interior
 * V/h^3 plus a layer of cut cells, c A/h^2): c = 0.75 for cells, 2.0 for the nodes of the
 * active cells (fitted to the Stanford bunny at h = 6 mm: 4,752 cells, 6,740 nodes). */
double size_for(double V, double A, double n, double c)
{
  double lo = 1e-6, hi = 10.0 * cbrt(V) + 1.0;
  for (int it = 0; it < 200; it++) {
    const double h = sqrt(lo * hi), k = V / (h * h * h) + c * A / (h * h);
    if (k > n)
      lo = h;
    else
      hi = h;
  }
  return sqrt(lo * hi);
}

/* ------------------------------------------------------------- scenes */

void cutbench_put(cutbench_text *t, const char *fmt, ...)
{
  if (!t->ok) return;
  va_list ap;
  va_start(ap, fmt);
  const int k = vsnprintf(t->s + t->n, sizeof t->s - t->n, fmt, ap);
  va_end(ap);
  if (k < 0 || (size_t)k >= sizeof t->s - t->n)
    t->ok = 0;
  else
    t->n += (size_t)k;
}

void scene_head(cutbench_text *t, const char *name, const char *desc, const cutbench_model *m,
                const char *body, double h, const char *material, double young, double poisson,
                const char *solver, double dt, int steps)
{
  cutbench_put(t, "{\n  \"version\": 1,\n  \"name\": \"%s\",\n  \"description\": \"%s\",\n", name,
               desc);
  if (m) {
    cutbench_put(
        t,
        "  \"background\": {\"element\": \"hex8\", \"fit_background\": {\"cell_size\": %.6g, "
        "\"margin\": %.6g}},\n",
        h, 0.5 * h);
    cutbench_put(t, "  \"geometry\": {\"surface\": \"%s\", \"fill_holes\": %s},\n", body,
                 m->fill_holes ? "true" : "false");
  }
  cutbench_put(
      t,
      "  \"material\": {\"model\": \"%s\", \"young\": %g, \"poisson\": %g, \"density\": 1000},\n",
      material, young, poisson);
  /* Dick's corotated linear model integrates the stiffness once per element and keeps it: its
   * cut cells' stiffness rules on the mass rules' space (Hex8: Q_2, exact on box cells) cost
   * no step time and share one fit with the mass */
  if (!strcmp(material, "corotated_linear"))
    cutbench_put(t, "  \"quadrature\": {\"stiffness_on_mass_space\": true},\n");
  if (solver && solver[0]) cutbench_put(t, "  \"solver\": {%s},\n", solver);
  cutbench_put(t, "  \"time\": {\"dt\": %g, \"duration\": %.9g},\n", dt, dt * steps);
  cutbench_put(t, "  \"output\": {\"directory\": \"fcm-output/%s\", \"frame_interval\": 1},\n",
               name);
  cutbench_put(t, "  \"effects\": [\n");
}

void scene_cuts(cutbench_text *t, const cutbench_scene *sc, const char *surf_dir, const char *name,
                double dt)
{
  for (int k = 0; k < sc->events; k++)
    cutbench_put(
        t, "    {\"cut\": {\"time\": %.9g, \"surface\": {\"mesh\": \"%s/%s_cut%d.obj\"}}}%s\n",
        dt * (sc->event_step[k] - 1), surf_dir, name, k + 1, k + 1 < sc->events ? "," : "");
  cutbench_put(t, "  ]\n}\n");
}

int write_event(soup *s, const char *dir, const char *surf_dir, const char *name, int k)
{
  char path[8192];
  snprintf(path, sizeof path, "%s/%s/%s_cut%d.obj", dir, surf_dir, name, k + 1);
  const int ok = soup_write(s, path);
  soup_clear(s);
  return ok;
}

/* Dick: a grid of six square blades (three across x, three across z) pushed down into the
 * body from above in `events` steps (every other step), each step cutting the next band of
 * depth; the bands share their edges, so any count cuts the same surface in the end. */
static int dick_cuts(const cutbench_model *m, int events, const char *dir, const char *surf_dir,
                     const char *name, cutbench_scene *sc)
{
  static const double frac[3] = {0.253, 0.507, 0.741};
  const double Ly = m->hi[1] - m->lo[1], top = m->hi[1] + 0.02 * Ly, depth = 0.57 * Ly;
  soup s = {0};
  s.ok = 1;
  sc->events = events;
  int ok = 1;
  for (int k = 0; k < sc->events; k++) {
    sc->event_step[k] = 2 + 2 * k;
    double lo[3], hi[3];
    for (int d = 0; d < 3; d++) {
      const double L = m->hi[d] - m->lo[d];
      lo[d] = m->lo[d] - 0.05 * L, hi[d] = m->hi[d] + 0.05 * L;
    }
    hi[1] = top - depth * k / sc->events, lo[1] = top - depth * (k + 1) / sc->events;
    for (int i = 0; i < 3; i++) {
      soup_rect(&s, 0, m->lo[0] + frac[i] * (m->hi[0] - m->lo[0]), lo, hi);
      soup_rect(&s, 2, m->lo[2] + frac[i] * (m->hi[2] - m->lo[2]), lo, hi);
    }
    ok = write_event(&s, dir, surf_dir, name, k) && ok;
  }
  soup_clear(&s);
  free(s.x), free(s.t);
  sc->steps = 2 * events + 1;
  return ok;
}

/* Koschier: the knife carves a groove (a curved band about the vertical axis, inside the
 * body's flanks) a quarter turn per event while the body turns; then a ring at the band's top
 * edge peels the shell outside it off as a flap hanging from its lower edge. */
static int koschier_cuts(const cutbench_model *m, const char *dir, const char *surf_dir,
                         const char *name, cutbench_scene *sc)
{
  const double Lx = m->hi[0] - m->lo[0], Ly = m->hi[1] - m->lo[1], Lz = m->hi[2] - m->lo[2];
  double par[9] = {0.5 * (m->lo[0] + m->hi[0]), 0, 0.5 * (m->lo[2] + m->hi[2])};
  par[5] = m->lo[1] + 0.22 * Ly, par[6] = m->lo[1] + 0.4 * Ly;
  par[7] = 0.36 * fmin(Lx, Lz), par[8] = 0.75 * fmax(Lx, Lz);
  soup s = {0};
  s.ok = 1;
  int ok = 1;
  sc->events = 5;
  /* triangles of about 0.7 cells: each cut cell sees a few of them */
  const double e = 0.7 * sc->h;
  const int nth = (int)fmax(4.0, ceil(0.5 * PI * par[7] / e));
  const int ny = (int)fmax(2.0, ceil((par[6] - par[5]) / e));
  const int nr = (int)fmax(2.0, ceil((par[8] - par[7]) / e));
  for (int k = 0; k < 4; k++) {
    sc->event_step[k] = 2 + 2 * k;
    par[3] = 0.5 * PI * k, par[4] = 0.5 * PI * (k + 1);
    soup_patch(&s, band_patch, par, nth, ny);
    ok = write_event(&s, dir, surf_dir, name, k) && ok;
  }
  sc->event_step[4] = 10;
  soup_patch(&s, ring_patch, par, 4 * nth, nr);
  ok = write_event(&s, dir, surf_dir, name, 4) && ok;
  soup_clear(&s);
  free(s.x), free(s.t);
  sc->steps = 12;
  return ok;
}

/* Ton-That: a 2 x 0.6 x 0.4 m slab cut into sheets (z = 0.2; then 0.1 and 0.3; then 0.05 and
 * 0.15, re-entering the cells the earlier cuts split), then a cut across all sheets (y = 0.3
 * from x = 0.6 to the free end). */
static int slab_cuts(const char *dir, const char *surf_dir, const char *name, cutbench_scene *sc)
{
  static const double z[3][2] = {{0.2, -1}, {0.1, 0.3}, {0.05, 0.15}};
  const double lo[3] = {-0.2, -0.06, -0.04}, hi[3] = {2.2, 0.66, 0.44};
  soup s = {0};
  s.ok = 1;
  int ok = 1;
  sc->events = 4;
  for (int k = 0; k < 3; k++) {
    sc->event_step[k] = 2 + 3 * k;
    for (int j = 0; j < 2; j++)
      if (z[k][j] > 0) soup_rect(&s, 2, z[k][j], lo, hi);
    ok = write_event(&s, dir, surf_dir, name, k) && ok;
  }
  sc->event_step[3] = 11;
  const double plo[3] = {0.6, 0, -0.1}, phi[3] = {2.2, 0, 0.5};
  soup_rect(&s, 1, 0.3, plo, phi);
  ok = write_event(&s, dir, surf_dir, name, 3) && ok;
  soup_clear(&s);
  free(s.x), free(s.t);
  sc->steps = 14;
  return ok;
}

/* The background starts half a cell before the box and ends in the first cell past it, n_d =
 * ceil((L_d + h/2) / h) cells and n_d + 1 nodes per axis, every cell meeting the body. */
double slab_size(double dofs, const double L[3], fcm_index n[3])
{
  double best = 0.1, err = HUGE_VAL;
  for (int i = 0; i < 4000; i++) {
    const double h = 0.005 * pow(100.0, i / 4000.0);
    double nodes = 1.0;
    for (int d = 0; d < 3; d++)
      nodes *= ceil((L[d] + 0.5 * h) / h - 1e-9) + 1.0;
    if (fabs(3.0 * nodes - dofs) < err) err = fabs(3.0 * nodes - dofs), best = h;
  }
  for (int d = 0; d < 3; d++)
    n[d] = (fcm_index)ceil((L[d] + 0.5 * best) / best - 1e-9);
  return best;
}

int scene_insert(cutbench_text *t, const char *key, const char *text)
{
  char *at = t->ok ? strstr(t->s, key) : NULL;
  const size_t g = strlen(text);
  if (!at || t->n + g + 1 >= sizeof t->s) return t->ok = 0, 0;
  memmove(at + g, at, strlen(at) + 1);
  memcpy(at, text, g);
  t->n += g;
  return 1;
}

int scene_box_grid(cutbench_text *t, const double L[3], double h, const fcm_index n[3])
{
  char grid[512];
  snprintf(grid, sizeof grid,
           "  \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [%.6g, %.6g, %.6g], "
           "\"max\": [%.6g, %.6g, %.6g]}, \"cells\": [%lld, %lld, %lld]},\n"
           "  \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [%.6g, %.6g, "
           "%.6g]},\n",
           -0.5 * h, -0.5 * h, -0.5 * h, -0.5 * h + n[0] * h, -0.5 * h + n[1] * h,
           -0.5 * h + n[2] * h, (long long)n[0], (long long)n[1], (long long)n[2], L[0], L[1],
           L[2]);
  return scene_insert(t, "  \"material\"", grid);
}

int cutbench_write_scene(cutbench_row_id row, const cutbench_model *m, const char *body,
                         double scale, int dick_events, const char *solver, const char *dir,
                         const char *surf_dir, const char *name, cutbench_scene *sc)
{
  static cutbench_text t;
  const cutbench_paper *p = &cutbench_papers[row];
  memset(sc, 0, sizeof *sc);
  t.n = 0, t.ok = 1;
  char sub[8192];
  snprintf(sub, sizeof sub, "%s/%s", dir, surf_dir);
  if (!cli_make_dirs(PROG, sub)) return 0;
  const double target = p->size_target * scale;
  const double Ly = m ? m->hi[1] - m->lo[1] : 0.0;
  int ok = 1;
  if (row == ROW_KOSCHIER_PLATE)
    ok = cutbench_koschier_plate(&t, p, scale, m->triangles, solver, dir, surf_dir, name, sc);
  else if (row == ROW_TONTHAT_ACCORDION)
    ok = cutbench_tonthat_accordion(&t, p, scale, solver, dir, surf_dir, name, sc);
  else if (row == ROW_TONTHAT_OCTOPUS)
    ok = cutbench_tonthat_octopus(&t, p, scale, m->triangles, solver, dir, surf_dir, name, sc);
  else if (row <= ROW_DICK_BUNNY) {
    sc->h = size_for(m->volume, m->area, target, 0.75);
    if (dick_events < 1 || dick_events > CUTBENCH_MAX_EVENTS) {
      fprintf(stderr, PROG ": Dick's cut events: %d, not in [1, %d]\n", dick_events,
              CUTBENCH_MAX_EVENTS);
      return 0;
    }
    ok = dick_cuts(m, dick_events, dir, surf_dir, name, sc);
    static const char *const words[CUTBENCH_MAX_EVENTS + 1] = {
        "",     "one", "two",    "three",  "four",     "five",     "six",     "seven",  "eight",
        "nine", "ten", "eleven", "twelve", "thirteen", "fourteen", "fifteen", "sixteen"};
    char desc[512], steps[64] = "in one step (one cut)";
    if (dick_events > 1)
      snprintf(steps, sizeof steps, "in %s steps (one cut per step)", words[dick_events]);
    snprintf(desc, sizeof desc,
             "After Dick et al. 2011 (Table 1, %s): a bunny-like body on a Hex8 grid sized to "
             "about %.0f active cells, corotated linear, its base held under gravity; a grid of "
             "six square blades is pushed down into it %s.",
             p->model, target, steps);
    scene_head(&t, name, desc, m, body, sc->h, p->material, 1e5, 0.4, solver, 0.01, sc->steps);
    cutbench_put(&t, "    {\"gravity\": {\"acceleration\": [0, -9.81, 0]}},\n");
    cutbench_put(
        &t,
        "    {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, %.6g, 0], \"normal\": [0, "
        "-1, 0]}}}},\n",
        m->lo[1] + 0.1 * Ly);
  } else if (row == ROW_KOSCHIER_BUNNY) {
    sc->h = size_for(m->volume, m->area, target / 3.0, 2.0);
    ok = koschier_cuts(m, dir, surf_dir, name, sc);
    scene_head(
        &t, name,
        "After Koschier et al. 2017 (section 7, Fig. 1 right): a bunny-like body turning about "
        "a vertical axis (its base held by a rotating region) while a knife carves a "
        "curved groove into its flanks, a quarter turn per cut; a last cut peels the "
        "shell outside the groove off. Stable Neo-Hookean, Hex8, dt 5 ms.",
        m, body, sc->h, "snh", 2e5, 0.4, solver, 0.005, sc->steps);
    const double cx = 0.5 * (m->lo[0] + m->hi[0]), cz = 0.5 * (m->lo[2] + m->hi[2]);
    const double rx = 0.2 * (m->hi[0] - m->lo[0]), rz = 0.2 * (m->hi[2] - m->lo[2]);
    cutbench_put(&t, "    {\"gravity\": {\"acceleration\": [0, -9.81, 0]}},\n");
    cutbench_put(
        &t,
        "    {\"motion\": {\"region\": {\"box\": {\"min\": [%.6g, %.6g, %.6g], \"max\": [%.6g, "
        "%.6g, %.6g]}},\n      \"rotation\": {\"axis\": [0, 1, 0], \"center\": [%.6g, 0, %.6g], "
        "\"speed\": 4}}},\n",
        cx - rx, m->lo[1] - sc->h, cz - rz, cx + rx, m->lo[1] + 0.2 * Ly, cz + rz, cx, cz);
  } else {
    const double L[3] = {2.0, 0.6, 0.4};
    fcm_index n[3];
    sc->h = slab_size(target, L, n);
    ok = slab_cuts(dir, surf_dir, name, sc);
    scene_head(&t, name,
               "After Ton-That et al. 2024 (section 5.1, Fig. 1, Table 2): a 2 x 0.6 x 0.4 m slab "
               "clamped at x = 0 cut into ever thinner sheets by cuts that re-enter the cells "
               "earlier cuts split, then by a cut across all sheets. Stable Neo-Hookean (E = "
               "1e6 Pa, nu = 0.4), Hex8, dt 0.033 s.",
               NULL, NULL, 0.0, "snh", 1e6, 0.4, solver, 0.033, sc->steps);
    /* the background before the material: inserted after the description */
    if (!scene_box_grid(&t, L, sc->h, n)) return 0;
    cutbench_put(&t, "    {\"gravity\": {\"acceleration\": [0, 0, -9.81]}},\n");
    cutbench_put(
        &t, "    {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, "
            "0, 0]}}}},\n");
  }
  if (row <= ROW_KOSCHIER_BUNNY || row == ROW_TONTHAT_SLAB)
    scene_cuts(&t, sc, surf_dir, name,
               row == ROW_KOSCHIER_BUNNY ? 0.005
               : row == ROW_TONTHAT_SLAB ? 0.033
                                         : 0.01);
  if (!ok || !t.ok) {
    fprintf(stderr, PROG ": %s: the scene could not be written\n", name);
    return 0;
  }
  snprintf(sc->json_path, sizeof sc->json_path, "%s/%s.json", dir, name);
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, sc->json_path, &out);
  if (!f) return 0;
  fputs(t.s, f);
  return cli_output_commit(PROG, &out);
}
