/* Benchmark (label "bench"): the latency of a cut's cell-rule update
 * (fcm_cell_rules_create_cut()) on a bunny-like body in Hex8 grids of the papers' sizes
 * (active cells: Koschier 2017's bunny ~1.5k, Dick 2011's Bunny 3 5.48k and Bunny 2 26.1k),
 * for a plane through the body and a curved groove (a half cylinder carved into its top, which
 * cuts a piece off). Printed per cut: wall time of the call and its phases (set-up with the
 * cuts' region, the per-cell loop: clipping and classification, moments or points, then
 * simplification, both in core-seconds summed over the threads; gathering with the links),
 * cells integrated again, cells split, initial and kept mass points. "cpu": the process's CPU
 * time of the call (clock(), all threads), which a machine busy with other work inflates less.
 * The body: a generated star-shaped closed surface (a cube sphere with lobes, about 60k
 * triangles, the size of the Stanford bunny) tetrahedralized with Gmsh, or a model given by
 * path (holes filled). Without Gmsh it prints so and exits 0.
 * Usage: embed_cut_bench [--model path] [--sizes n1,n2,...] [--threads t] [--resolution m]
 *   (defaults: the generated body of 12 m^2 triangles, m = 70, sizes 1500,5480,26100,
 *   threads OMP_NUM_THREADS, read before Gmsh can change OpenMP's default) */
#include "fcm/embed.h"
#include "fcm/geom.h"
#include "fcm/mesh.h"
#include "fcm/surface.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define CHECK(call)                                                                                \
  do {                                                                                             \
    const fcm_status s_ = (call);                                                                  \
    if (s_ != FCM_OK) {                                                                            \
      fprintf(stderr, "%s:%d: %s: %s\n", __FILE__, __LINE__, #call, fcm_ctx_error_message(ctx));   \
      exit(1);                                                                                     \
    }                                                                                              \
  } while (0)

static fcm_ctx *ctx;

/* The radius of the generated body in the unit direction d: a ball with two ear-like lobes,
 * a tail bump and a wavy skin. */
static double radius(const double d[3])
{
  static const double lobes[4][4] = {{0.35, 0.85, 0.40, 0.55},
                                     {-0.20, 0.90, 0.38, 0.50},
                                     {-0.95, 0.10, 0.0, 0.25},
                                     {0.70, -0.30, -0.64, 0.15}};
  double r = 1.0 + 0.04 * sin(7.0 * d[0]) * sin(5.0 * d[1]) * cos(6.0 * d[2]);
  for (int k = 0; k < 4; k++) {
    const double *l = lobes[k];
    const double n = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    const double c = (l[0] * d[0] + l[1] * d[1] + l[2] * d[2]) / n;
    r += l[3] * exp(-(1.0 - c) * 40.0);
  }
  return r;
}

/* A closed star-shaped surface: the six faces of a cube of m x m cells each, projected onto
 * the body's radius, scaled to about the bunny's size (0.155 x 0.15 x 0.12 m). */
static fcm_surface *star_surface(int m)
{
  const int g = 2 * m + 1;
  fcm_index *id = malloc((size_t)g * g * g * sizeof *id);
  double *x = malloc((size_t)6 * (m + 1) * (m + 1) * 3 * sizeof *x);
  fcm_index *tri = malloc((size_t)12 * m * m * 3 * sizeof *tri);
  fcm_index *v = malloc((size_t)(m + 1) * (m + 1) * sizeof *v);
  fcm_index nv = 0, nt = 0;
  for (size_t i = 0; i < (size_t)g * g * g; i++)
    id[i] = -1;
  for (int a = 0; a < 3; a++)
    for (int s = -1; s <= 1; s += 2) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      for (int i = 0; i <= m; i++)
        for (int j = 0; j <= m; j++) {
          int q[3];
          q[a] = s > 0 ? 2 * m : 0, q[b] = 2 * i, q[c] = 2 * j;
          fcm_index *slot = id + ((size_t)q[0] * g + q[1]) * g + q[2];
          if (*slot < 0) {
            double p[3], n = 0.0;
            for (int d = 0; d < 3; d++)
              p[d] = (double)q[d] / m - 1.0, n += p[d] * p[d];
            n = sqrt(n);
            for (int d = 0; d < 3; d++)
              p[d] /= n;
            const double r = 0.055 * radius(p);
            static const double scale[3] = {1.1, 1.0, 0.85};
            for (int d = 0; d < 3; d++)
              x[3 * nv + d] = r * scale[d] * p[d];
            *slot = nv++;
          }
          v[i * (m + 1) + j] = *slot;
        }
      for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
          const fcm_index v00 = v[i * (m + 1) + j], v10 = v[(i + 1) * (m + 1) + j];
          const fcm_index v01 = v[i * (m + 1) + j + 1], v11 = v[(i + 1) * (m + 1) + j + 1];
          const fcm_index t[6] = {v00, v10, v11, v00, v11, v01};
          for (int k = 0; k < 6; k += 3) { /* outward: counter-clockwise for s > 0 */
            tri[3 * nt] = t[k];
            tri[3 * nt + 1] = s > 0 ? t[k + 1] : t[k + 2];
            tri[3 * nt + 2] = s > 0 ? t[k + 2] : t[k + 1];
            nt++;
          }
        }
    }
  fcm_surface *surf = NULL;
  CHECK(fcm_surface_create(ctx, nv, x, nt, tri, &surf));
  free(id);
  free(v);
  free(x);
  free(tri);
  return surf;
}

/* Grid cells over [lo, lo + n h] whose box meets a tet's box (about the active cells). */
static fcm_index count_cells(const fcm_aabb_tree *tree, const double lo[3], double h,
                             const fcm_index n[3])
{
  fcm_index count = 0;
  for (fcm_index k = 0; k < n[2]; k++)
    for (fcm_index j = 0; j < n[1]; j++)
      for (fcm_index i = 0; i < n[0]; i++) {
        const double a[3] = {lo[0] + i * h, lo[1] + j * h, lo[2] + k * h};
        const double b[3] = {a[0] + h, a[1] + h, a[2] + h};
        fcm_index nf = 0;
        CHECK(fcm_aabb_tree_query(tree, a, b, 0, NULL, &nf));
        count += nf > 0;
      }
  return count;
}

/* The cell size whose grid around the body has about `target` cells meeting it. */
static double fit_cell_size(const fcm_geometry *g, fcm_index target, double lo[3], fcm_index n[3])
{
  const fcm_index nc = fcm_geometry_num_cells(g);
  const int npc = fcm_geometry_nodes_per_cell(g);
  const double *X = fcm_geometry_coords(g);
  const fcm_index *cells = fcm_geometry_cells(g);
  double *boxes = malloc((size_t)6 * nc * sizeof *boxes), glo[3], ghi[3];
  for (fcm_index c = 0; c < nc; c++)
    for (int d = 0; d < 3; d++) {
      double a = HUGE_VAL, b = -HUGE_VAL;
      for (int v = 0; v < npc; v++)
        a = fmin(a, X[3 * cells[(size_t)npc * c + v] + d]),
        b = fmax(b, X[3 * cells[(size_t)npc * c + v] + d]);
      boxes[6 * c + d] = a, boxes[6 * c + 3 + d] = b;
    }
  fcm_aabb_tree *tree = NULL;
  CHECK(fcm_aabb_tree_create(ctx, nc, boxes, &tree));
  fcm_geometry_bounding_box(g, glo, ghi);
  double a = 1e-4, b = 0.2, h = 0.0;
  for (int it = 0; it < 30; it++) {
    h = sqrt(a * b);
    for (int d = 0; d < 3; d++) {
      n[d] = (fcm_index)ceil((ghi[d] - glo[d]) / h) + 2;
      lo[d] = 0.5 * (glo[d] + ghi[d]) - 0.5 * n[d] * h;
    }
    if (count_cells(tree, lo, h, n) > target)
      a = h;
    else
      b = h;
  }
  fcm_aabb_tree_destroy(&tree);
  free(boxes);
  return h;
}

/* The groove: a half cylinder (axis along x at the top of the body's box, radius a third of
 * its height) reaching over the body's whole length, 64 x 32 quads. */
static fcm_surface *groove(const double glo[3], const double ghi[3])
{
  enum { NX = 64, NA = 32 };
  double x[(NX + 1) * (NA + 1) * 3];
  fcm_index tri[NX * NA * 6];
  const double rho = (ghi[1] - glo[1]) / 3.0, zc = 0.5 * (glo[2] + ghi[2]);
  const double span = ghi[0] - glo[0];
  for (int i = 0; i <= NX; i++)
    for (int j = 0; j <= NA; j++) {
      const double t = 3.14159265358979323846 * j / NA;
      double *q = x + 3 * (i * (NA + 1) + j);
      q[0] = glo[0] - 0.1 * span + 1.2 * span * i / NX;
      q[1] = ghi[1] + 0.001 - rho * sin(t);
      q[2] = zc + rho * cos(t);
    }
  fcm_index nt = 0;
  for (int i = 0; i < NX; i++)
    for (int j = 0; j < NA; j++) {
      const fcm_index a = i * (NA + 1) + j, b = a + NA + 1;
      const fcm_index t[6] = {a, b, b + 1, a, b + 1, a + 1};
      memcpy(tri + 3 * nt, t, sizeof t);
      nt += 2;
    }
  fcm_surface *s = NULL;
  CHECK(fcm_surface_create(ctx, (NX + 1) * (NA + 1), x, nt, tri, &s));
  return s;
}

static void report(const char *what, const fcm_cell_rules *r, double wall, double cpu)
{
  const fcm_cell_rules_stats s = *fcm_cell_rules_get_stats(r);
  printf(
      "  %-7s %7.3f s (cpu %7.3f s): setup %6.3f, cells %6.3f (clip, points %6.3f + simplify %6.3f "
      "core-s), gather %6.3f | integrated %4lld kept %4lld split %4lld, mass points %9lld -> "
      "%6lld\n",
      what, wall, cpu, s.time_setup, s.time_total - s.time_setup - s.time_gather, s.time_intersect,
      s.time_simplify, s.time_gather, (long long)s.num_integrated, (long long)s.num_kept,
      (long long)s.num_split, (long long)s.points_initial[FCM_RULE_MASS],
      (long long)s.points_simplified[FCM_RULE_MASS]);
  fflush(stdout);
}

int main(int argc, char **argv)
{
  const char *model = NULL;
  char sizes[256] = "1500,5480,26100";
  int threads = getenv("OMP_NUM_THREADS") ? atoi(getenv("OMP_NUM_THREADS")) : FCM_DEFAULT;
  if (threads < 1) threads = FCM_DEFAULT;
  int resolution = 70;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--model") && i + 1 < argc)
      model = argv[++i];
    else if (!strcmp(argv[i], "--sizes") && i + 1 < argc)
      snprintf(sizes, sizeof sizes, "%s", argv[++i]);
    else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
      threads = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--resolution") && i + 1 < argc)
      resolution = atoi(argv[++i]);
    else {
      fprintf(stderr,
              "usage: %s [--model path] [--sizes n1,n2,...] [--threads t] "
              "[--resolution m]\n",
              argv[0]);
      return 2;
    }
  }
  CHECK(fcm_ctx_create(NULL, &ctx));
  if (!fcm_surface_meshing_available()) {
    printf("Gmsh is not available: nothing to measure\n");
    fcm_ctx_destroy(&ctx);
    return 0;
  }
  fcm_surface *surf = NULL, *closed = NULL;
  if (model) {
    fcm_surface *raw = NULL;
    CHECK(fcm_surface_create_from_file(ctx, model, &raw));
    CHECK(fcm_surface_create_filled(ctx, raw, NULL, &surf, NULL));
    fcm_surface_destroy(&raw);
  } else {
    surf = star_surface(resolution);
  }
  closed = surf;
  fcm_geometry *g = NULL;
  double t0 = fcm_wtime();
  CHECK(fcm_geometry_create_from_surface(ctx, closed, NULL, &g));
  CHECK(fcm_ctx_set_num_threads(ctx, threads)); /* Gmsh may have changed OpenMP's default */
  printf("body: %s, %lld surface triangles, %lld tets (Gmsh %.1f s); %d threads\n",
         model ? "model" : "generated", (long long)fcm_surface_num_triangles(closed),
         (long long)fcm_geometry_num_cells(g), fcm_wtime() - t0, fcm_ctx_num_threads(ctx));
  double glo[3], ghi[3];
  fcm_geometry_bounding_box(g, glo, ghi);
  for (char *tok = strtok(sizes, ","); tok; tok = strtok(NULL, ",")) {
    const fcm_index target = atoll(tok);
    double lo[3], hi[3];
    fcm_index n[3];
    const double h = fit_cell_size(g, target, lo, n);
    for (int d = 0; d < 3; d++)
      hi[d] = lo[d] + n[d] * h;
    fcm_mesh *mesh = NULL;
    fcm_cell_rules *r0 = NULL, *r1 = NULL, *r2 = NULL;
    CHECK(fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
    t0 = fcm_wtime();
    CHECK(fcm_cell_rules_create(ctx, mesh, g, NULL, &r0));
    const fcm_cell_rules_stats s0 = *fcm_cell_rules_get_stats(r0);
    printf("grid %lld x %lld x %lld, h %.4g m: %lld active cells (%lld cut); rules %.2f s\n",
           (long long)n[0], (long long)n[1], (long long)n[2], h,
           (long long)(s0.num_cut + s0.num_uncut), (long long)s0.num_cut, fcm_wtime() - t0);
    /* through the body's centre, off the grid planes */
    const double centre[3] = {0.5 * (glo[0] + ghi[0]) + 0.37 * h, 0.5 * (glo[1] + ghi[1]),
                              0.5 * (glo[2] + ghi[2])};
    const double normal[3] = {1, 0, 0};
    fcm_surface *plane = NULL, *grv = groove(glo, ghi);
    CHECK(fcm_surface_create_plane(ctx, centre, normal, lo, hi, &plane));
    clock_t c0 = clock();
    t0 = fcm_wtime();
    CHECK(fcm_cell_rules_create_cut(ctx, mesh, g, r0, plane, &r1));
    report("plane", r1, fcm_wtime() - t0, (double)(clock() - c0) / CLOCKS_PER_SEC);
    c0 = clock();
    t0 = fcm_wtime();
    CHECK(fcm_cell_rules_create_cut(ctx, mesh, g, r0, grv, &r2));
    report("groove", r2, fcm_wtime() - t0, (double)(clock() - c0) / CLOCKS_PER_SEC);
    fcm_cell_rules_destroy(&r1);
    c0 = clock();
    t0 = fcm_wtime();
    CHECK(fcm_cell_rules_create_cut(ctx, mesh, g, r2, plane, &r1));
    report("+plane", r1, fcm_wtime() - t0, (double)(clock() - c0) / CLOCKS_PER_SEC);
    fcm_surface_destroy(&plane);
    fcm_surface_destroy(&grv);
    fcm_cell_rules_destroy(&r0);
    fcm_cell_rules_destroy(&r1);
    fcm_cell_rules_destroy(&r2);
    fcm_mesh_destroy(&mesh);
  }
  fcm_geometry_destroy(&g);
  fcm_surface_destroy(&closed);
  fcm_ctx_destroy(&ctx);
  return 0;
}
