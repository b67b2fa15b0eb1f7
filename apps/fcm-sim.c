/* fcm-sim: the main program. `fcm-sim scene.json` runs a scene file through fcm_simulation;
 * without a file, the built-in default scene (a twisting hollow cylinder). `--cantilever`
 * runs the beam demo: a cantilever under gravity, clamped at x = 0, solved statically on a
 * quadratic background grid, written for ParaView and compared with Timoshenko theory. */
#define _POSIX_C_SOURCE 200809L
#include <fcm/fcm.h>
#include <fcm/simulation.h>

#include <errno.h>
#include <omp.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct options {
  fcm_element_type element;
  fcm_index cells[3];
  double length, width, height;
  fcm_material mat;
  double gravity;
  const char *outdir;
  int quiet;
} options;

static void usage(FILE *f)
{
  fprintf(f,
          "usage: fcm-sim [SCENE.json] [scene options]\n"
          "       fcm-sim --cantilever [cantilever options]\n"
          "\n"
          "Runs a scene file (schema: apps/scenes/README.md) with only the effects it names;\n"
          "without a file, the built-in default scene: a hollow cylinder, one end pushed in and\n"
          "the other twisted (Longva et al. 2020, 6.2; Hex20 FCM, about 40 s on 2 cores).\n"
          "Frames go to the scene's output directory: <name>_background_NNNN.vtu,\n"
          "<name>_surface_NNNN.vtu, <name>_background.pvd, <name>_surface.pvd (open the .pvd\n"
          "files in ParaView) and the per-step log <name>_log.csv.\n"
          "\n"
          "scene options:\n"
          "  -o, --output DIR         output directory (overrides the scene's)\n"
          "  --steps N                stop once N steps in all are taken (N >= 1)\n"
          "  --check                  run at most 3 steps without output, check the state is\n"
          "                           finite and print the run summary\n"
          "  --checkpoint-every K     write <name>_checkpoint_NNNNNN.fcmck every K steps (K >= 1;\n"
          "                           overrides the scene's output.checkpoint_interval)\n"
          "  --resume FILE            continue from a checkpoint of the same scene, bit for bit\n"
          "                           as the uninterrupted run; frames and log go on in the\n"
          "                           output directory\n"
          "  --print-scene            print the scene with every default filled in and exit\n"
          "  -q, --quiet              print only errors\n"
          "  -h, --help               this text\n"
          "\n"
          "--cantilever: a steel cantilever beam (8 x 1 x 1 m, clamped at x = 0) under gravity\n"
          "on a Hex20 grid, solved statically; frames go to fcm-output/ (VTU + PVD) and the tip\n"
          "deflection is compared with Timoshenko beam theory.\n"
          "\n"
          "cantilever options:\n"
          "  --element NAME     tet4 | tet10 | hex8 | hex20            (default hex20)\n"
          "  --cells NX NY NZ   grid cells along the beam, width, height  (default 32 4 4)\n"
          "  --size L W H       beam length, width, height in m           (default 8 1 1)\n"
          "  --young E          Young's modulus in Pa, > 0                (default 2.1e11)\n"
          "  --poisson NU       Poisson's ratio in (-1, 0.5)               (default 0.3)\n"
          "  --density RHO      density in kg/m^3, >= 0                    (default 7850)\n"
          "  --gravity G        gravitational acceleration in m/s^2        (default 9.81)\n"
          "  -o, --output DIR   output directory                           (default fcm-output)\n"
          "  -q, --quiet        print only errors\n");
}

/* Parse a finite double from argv[*i + 1]; a message names the option on failure. */
static int parse_double(int argc, char **argv, int *i, double *out)
{
  if (*i + 1 >= argc) {
    fprintf(stderr, "fcm-sim: %s needs a number\n", argv[*i]);
    return 0;
  }
  char *end = NULL;
  errno = 0;
  double v = strtod(argv[*i + 1], &end);
  if (errno || end == argv[*i + 1] || *end || !isfinite(v)) {
    fprintf(stderr, "fcm-sim: %s: '%s' is not a finite number\n", argv[*i], argv[*i + 1]);
    return 0;
  }
  *out = v;
  (*i)++;
  return 1;
}

static int parse_args(int argc, char **argv, options *o)
{
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      usage(stdout);
      exit(0);
    } else if (!strcmp(a, "--element")) {
      if (i + 1 >= argc || fcm_element_type_from_name(argv[i + 1], &o->element) != FCM_OK) {
        fprintf(stderr, "fcm-sim: --element needs one of tet4, tet10, hex8, hex20\n");
        return 0;
      }
      i++;
    } else if (!strcmp(a, "--cells")) {
      for (int d = 0; d < 3; d++) {
        double v;
        if (!parse_double(argc, argv, &i, &v)) return 0;
        if (v < 1 || v > 1e4 || v != floor(v)) {
          fprintf(stderr, "fcm-sim: --cells: %g must be a whole number in [1, 10000]\n", v);
          return 0;
        }
        o->cells[d] = (fcm_index)v;
      }
    } else if (!strcmp(a, "--size")) {
      double *dst[3] = {&o->length, &o->width, &o->height};
      for (int d = 0; d < 3; d++) {
        if (!parse_double(argc, argv, &i, dst[d])) return 0;
        if (*dst[d] <= 0) {
          fprintf(stderr, "fcm-sim: --size: %g must be positive\n", *dst[d]);
          return 0;
        }
      }
    } else if (!strcmp(a, "--young")) {
      if (!parse_double(argc, argv, &i, &o->mat.young)) return 0;
    } else if (!strcmp(a, "--poisson")) {
      if (!parse_double(argc, argv, &i, &o->mat.poisson)) return 0;
    } else if (!strcmp(a, "--density")) {
      if (!parse_double(argc, argv, &i, &o->mat.density)) return 0;
    } else if (!strcmp(a, "--gravity")) {
      if (!parse_double(argc, argv, &i, &o->gravity)) return 0;
    } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
      if (i + 1 >= argc || !argv[i + 1][0]) {
        fprintf(stderr, "fcm-sim: %s needs a directory name\n", a);
        return 0;
      }
      o->outdir = argv[++i];
    } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
      o->quiet = 1;
    } else if (!strcmp(a, "--cantilever")) {
      continue;
    } else {
      fprintf(stderr, "fcm-sim: unknown --cantilever option '%s' (see --help)\n", a);
      return 0;
    }
  }
  return 1;
}

/* Timoshenko tip deflection under the uniform load q = rho g b h, with
 * Cowper's shear coefficient for a rectangle. */
static double timoshenko_tip(const options *o)
{
  double A = o->width * o->height, I = o->width * pow(o->height, 3) / 12.0;
  double q = o->mat.density * o->gravity * A, L = o->length;
  double G = o->mat.young / (2.0 * (1.0 + o->mat.poisson));
  double kappa = 10.0 * (1.0 + o->mat.poisson) / (12.0 + 11.0 * o->mat.poisson);
  return q * pow(L, 4) / (8.0 * o->mat.young * I) + q * L * L / (2.0 * kappa * G * A);
}

/* Von Mises stress at the reference centroid of each cell. */
static void cell_von_mises(const fcm_space *space, const options *o, const double *u, double *vm)
{
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  double lambda = 0, mu = 0;
  fcm_material_lame(NULL, &o->mat, &lambda, &mu);
  double xi[3] = {0, 0, 0};
  if (info->shape == FCM_SHAPE_TET) xi[0] = xi[1] = xi[2] = 0.25;
  double dN[3 * FCM_ELEMENT_MAX_NODES];
  fcm_element_eval_grad(info->type, xi, dN);
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    double X[3 * FCM_ELEMENT_MAX_NODES], J[9], G[9] = {0};
    fcm_mesh_cell_coords(mesh, c, X);
    fcm_element_jacobian(info->type, X, xi, J);
    /* physical gradients g = J^{-T} dN, via the inverse of J by cofactors */
    double det = J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) +
                 J[2] * (J[3] * J[7] - J[4] * J[6]);
    double Ji[9] = {(J[4] * J[8] - J[5] * J[7]) / det, (J[2] * J[7] - J[1] * J[8]) / det,
                    (J[1] * J[5] - J[2] * J[4]) / det, (J[5] * J[6] - J[3] * J[8]) / det,
                    (J[0] * J[8] - J[2] * J[6]) / det, (J[2] * J[3] - J[0] * J[5]) / det,
                    (J[3] * J[7] - J[4] * J[6]) / det, (J[1] * J[6] - J[0] * J[7]) / det,
                    (J[0] * J[4] - J[1] * J[3]) / det};
    const fcm_index *cn = fcm_mesh_cells(mesh) + c * info->num_nodes;
    for (int a = 0; a < info->num_nodes; a++) {
      const double *ua = u + fcm_space_node_dof(space, cn[a]);
      for (int j = 0; j < 3; j++) {
        double g = Ji[j] * dN[3 * a] + Ji[3 + j] * dN[3 * a + 1] + Ji[6 + j] * dN[3 * a + 2];
        for (int i = 0; i < 3; i++)
          G[3 * i + j] += ua[i] * g;
      }
    }
    double s[9], tr = G[0] + G[4] + G[8];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        s[3 * i + j] = mu * (G[3 * i + j] + G[3 * j + i]) + (i == j ? lambda * tr : 0.0);
    double p = (s[0] + s[4] + s[8]) / 3.0, q = 0.0;
    for (int i = 0; i < 9; i++) {
      double d = s[i] - ((i % 4 == 0) ? p : 0.0);
      q += d * d;
    }
    vm[c] = sqrt(1.5 * q);
  }
}

/* Create `dir` (one level) unless it exists as a directory. */
static int ensure_dir(const char *dir)
{
  struct stat sb;
  if (stat(dir, &sb) == 0) {
    if (S_ISDIR(sb.st_mode)) return 1;
    fprintf(stderr, "fcm-sim: output path '%s' exists and is not a directory\n", dir);
    return 0;
  }
  if (mkdir(dir, 0777) != 0) {
    fprintf(stderr, "fcm-sim: cannot create output directory '%s': %s\n", dir, strerror(errno));
    return 0;
  }
  return 1;
}

#define CHECK(call)                                                                                \
  do {                                                                                             \
    if ((call) != FCM_OK) {                                                                        \
      fcm_ctx_error_view(ctx, stderr);                                                             \
      goto done;                                                                                   \
    }                                                                                              \
  } while (0)

static int demo_main(int argc, char **argv)
{
  options o = {FCM_ELEMENT_HEX20,     {32, 4, 4}, 8.0,          1.0, 1.0,
               {FCM_MATERIAL_LINEAR, 2.1e11, 0.3, 7850.0}, 9.81, "fcm-output", 0};
  if (!parse_args(argc, argv, &o)) return 2;

  int rc = 1;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_csr *K = NULL;
  fcm_direct *solver = NULL;
  fcm_vtu *vtu = NULL;
  fcm_pvd *pvd = NULL;
  double *f = NULL, *u = NULL, *upts = NULL, *vm = NULL;
  fcm_index *nodes = NULL, *dofs = NULL;
  char path[4096];
  double t[8];

  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) {
    fprintf(stderr, "fcm-sim: cannot create the fcm context\n");
    return 1;
  }
  {
    double lam, mu; /* validate the material before any work or output */
    if (fcm_material_lame(ctx, &o.mat, &lam, &mu) != FCM_OK) {
      fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
      rc = 2;
      goto done;
    }
  }
  const double lo[3] = {0, 0, 0}, hi[3] = {o.length, o.width, o.height};
  t[0] = fcm_wtime();
  CHECK(fcm_mesh_create_box(ctx, o.element, lo, hi, o.cells, &mesh));
  t[1] = fcm_wtime();
  CHECK(fcm_space_create(ctx, mesh, NULL, &space));
  CHECK(fcm_space_matrix_create(space, &K));
  fcm_index ndof = fcm_space_num_dofs(space), nnz = 0, nnodes = fcm_mesh_num_nodes(mesh);
  fcm_csr_get_size(K, NULL, NULL, &nnz);
  f = calloc((size_t)ndof, sizeof *f);
  u = calloc((size_t)ndof, sizeof *u);
  upts = calloc(3 * (size_t)nnodes, sizeof *upts);
  vm = calloc((size_t)fcm_mesh_num_cells(mesh), sizeof *vm);
  if (!f || !u || !upts || !vm) {
    fprintf(stderr, "fcm-sim: out of memory\n");
    goto done;
  }
  t[2] = fcm_wtime();
  const double accel[3] = {0, 0, -o.gravity};
  CHECK(fcm_assemble_stiffness(space, &o.mat, NULL, K));
  CHECK(fcm_assemble_body_force(space, &o.mat, accel, NULL, f));
  t[3] = fcm_wtime();
  {
    const double plo[3] = {0, -HUGE_VAL, -HUGE_VAL}, phi[3] = {0, HUGE_VAL, HUGE_VAL};
    double tol = 1e-9 * o.length;
    fcm_index nfix = 0;
    CHECK(fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, tol, 0, NULL, &nfix));
    nodes = calloc((size_t)nfix + 1, sizeof *nodes);
    dofs = calloc(3 * (size_t)nfix + 1, sizeof *dofs);
    if (!nodes || !dofs) goto done;
    CHECK(fcm_mesh_nodes_in_box(ctx, mesh, plo, phi, tol, nfix, nodes, &nfix));
    for (fcm_index k = 0; k < nfix; k++)
      for (int d = 0; d < 3; d++)
        dofs[3 * k + d] = fcm_space_node_dof(space, nodes[k]) + d;
    CHECK(fcm_space_apply_dirichlet(space, 3 * nfix, dofs, NULL, K, f));
  }
  t[4] = fcm_wtime();
  CHECK(fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, K, &solver));
  CHECK(fcm_direct_analyze(solver));
  CHECK(fcm_direct_factor(solver, fcm_csr_values(K)));
  t[5] = fcm_wtime();
  CHECK(fcm_direct_solve(solver, f, u));
  for (fcm_index i = 0; i < ndof; i++)
    if (!isfinite(u[i])) {
      fprintf(stderr, "fcm-sim: the solution has a non-finite entry at DOF %lld\n", (long long)i);
      goto done;
    }
  t[6] = fcm_wtime();

  /* Output: displacement per node, von Mises stress per cell; atomic files. */
  for (fcm_index n = 0; n < nnodes; n++)
    for (int d = 0; d < 3; d++)
      upts[3 * n + d] = u[fcm_space_node_dof(space, n) + d];
  cell_von_mises(space, &o, u, vm);
  if (!ensure_dir(o.outdir)) goto done;
  snprintf(path, sizeof path, "%s/cantilever.pvd", o.outdir);
  CHECK(fcm_pvd_create(ctx, path, &pvd));
  CHECK(fcm_vtu_create(ctx, &vtu));
  CHECK(fcm_vtu_set_points(vtu, nnodes, fcm_mesh_coords(mesh)));
  CHECK(fcm_vtu_set_cells(vtu, fcm_mesh_get_element_info(mesh)->vtk_cell_type,
                          fcm_mesh_num_cells(mesh), fcm_mesh_cells(mesh)));
  CHECK(fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "displacement", 3, nnodes, upts));
  CHECK(fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "von_mises", 1, fcm_mesh_num_cells(mesh), vm));
  snprintf(path, sizeof path, "%s/cantilever_0000.vtu", o.outdir);
  CHECK(fcm_vtu_write(vtu, path, NULL));
  CHECK(fcm_pvd_add(pvd, 0.0, path));
  t[7] = fcm_wtime();

  /* Tip deflection: mean vertical displacement of the nodes on the tip face. */
  {
    const double tlo[3] = {o.length, -HUGE_VAL, -HUGE_VAL}, thi[3] = {o.length, HUGE_VAL, HUGE_VAL};
    fcm_index ntip = 0;
    CHECK(fcm_mesh_nodes_in_box(ctx, mesh, tlo, thi, 1e-9 * o.length, 0, NULL, &ntip));
    fcm_index *tip = calloc((size_t)ntip + 1, sizeof *tip);
    if (!tip) goto done;
    fcm_mesh_nodes_in_box(ctx, mesh, tlo, thi, 1e-9 * o.length, ntip, tip, &ntip);
    double w = 0.0;
    for (fcm_index k = 0; k < ntip; k++)
      w += u[fcm_space_node_dof(space, tip[k]) + 2];
    free(tip);
    w = -w / (double)ntip;
    double ref = timoshenko_tip(&o);
    fcm_direct_info di;
    fcm_direct_get_info(solver, &di);
    if (!o.quiet) {
      const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
      printf("fcm-sim: cantilever %g x %g x %g m, %s, %lld x %lld x %lld cells\n", o.length,
             o.width, o.height, info->name, (long long)o.cells[0], (long long)o.cells[1],
             (long long)o.cells[2]);
      printf("  material     E = %g Pa, nu = %g, rho = %g kg/m^3, g = %g m/s^2\n", o.mat.young,
             o.mat.poisson, o.mat.density, o.gravity);
      printf("  system       %lld nodes, %lld DOFs, %lld non-zeros, factor %.3g non-zeros\n",
             (long long)nnodes, (long long)ndof, (long long)nnz, di.factor_nnz);
      printf("  tip deflection  %.6e m (mean over the tip face)\n", w);
      printf("  Timoshenko      %.6e m  (difference %+.2f %%)\n", ref, 100.0 * (w - ref) / ref);
      printf("  time [s]     mesh %.3f  space %.3f  assembly %.3f  dirichlet %.3f  "
             "factor %.3f  solve %.3f  output %.3f\n",
             t[1] - t[0], t[2] - t[1], t[3] - t[2], t[4] - t[3], t[5] - t[4], t[6] - t[5],
             t[7] - t[6]);
      printf(
          "  output       %s/cantilever.pvd (open in ParaView; Warp By Vector on 'displacement')\n",
          o.outdir);
    }
  }
  rc = 0;
done:
  free(f), free(u), free(upts), free(vm), free(nodes), free(dofs);
  fcm_vtu_destroy(&vtu);
  fcm_pvd_destroy(&pvd);
  fcm_direct_destroy(&solver);
  fcm_csr_destroy(&K);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return rc;
}

/* ---------------------------------------------------------------- scene runs */

typedef struct scene_options {
  const char *path; /* NULL: the built-in scene */
  const char *outdir;
  const char *resume; /* checkpoint to continue from, or NULL */
  long long steps;
  int checkpoint_every; /* -1: the scene's */
  int check, quiet, print_scene;
} scene_options;

/* A whole number in [lo, hi] from argv[*i + 1]; a message names the option on failure. */
static int parse_count(int argc, char **argv, int *i, long long lo, long long hi, long long *out)
{
  char *end = NULL;
  errno = 0;
  long long v = *i + 1 < argc ? strtoll(argv[*i + 1], &end, 10) : 0;
  if (*i + 1 >= argc || errno || end == argv[*i + 1] || *end || v < lo || v > hi) {
    fprintf(stderr, "fcm-sim: %s needs a whole number in [%lld, %lld]\n", argv[*i], lo, hi);
    return 0;
  }
  *out = v;
  (*i)++;
  return 1;
}

static int parse_scene_args(int argc, char **argv, scene_options *o)
{
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    long long v = 0;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      usage(stdout);
      exit(0);
    } else if (!strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "--resume")) {
      if (i + 1 >= argc || !argv[i + 1][0]) {
        fprintf(stderr, "fcm-sim: %s needs a %s\n", a,
                strcmp(a, "--resume") ? "directory name" : "checkpoint file");
        return 0;
      }
      if (!strcmp(a, "--resume"))
        o->resume = argv[++i];
      else
        o->outdir = argv[++i];
    } else if (!strcmp(a, "--steps")) {
      if (!parse_count(argc, argv, &i, 1, 1000000000000LL, &v)) return 0;
      o->steps = v;
    } else if (!strcmp(a, "--checkpoint-every")) {
      if (!parse_count(argc, argv, &i, 1, 1000000000, &v)) return 0;
      o->checkpoint_every = (int)v;
    } else if (!strcmp(a, "--check")) {
      o->check = 1;
    } else if (!strcmp(a, "--print-scene")) {
      o->print_scene = 1;
    } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
      o->quiet = 1;
    } else if (a[0] == '-') {
      fprintf(stderr,
              "fcm-sim: unknown option '%s' (see --help; the beam options need "
              "--cantilever)\n",
              a);
      return 0;
    } else if (o->path) {
      fprintf(stderr, "fcm-sim: one scene file only ('%s' and '%s')\n", o->path, a);
      return 0;
    } else {
      o->path = a;
    }
  }
  if (o->check && (o->resume || o->checkpoint_every > 0)) {
    fprintf(stderr, "fcm-sim: --check writes nothing: no --resume or --checkpoint-every\n");
    return 0;
  }
  return 1;
}

/* mkdir -p: create `dir` and its missing parents. */
static int make_dirs(const char *dir)
{
  char buf[4096];
  size_t n = strlen(dir);
  if (n == 0 || n >= sizeof buf) {
    fprintf(stderr, "fcm-sim: bad output directory '%s'\n", dir);
    return 0;
  }
  memcpy(buf, dir, n + 1);
  for (size_t k = 1; k <= n; k++) {
    if (buf[k] != '/' && buf[k] != '\0') continue;
    char c = buf[k];
    buf[k] = '\0';
    struct stat sb;
    if (stat(buf, &sb) != 0) {
      if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "fcm-sim: cannot create output directory '%s': %s\n", buf, strerror(errno));
        return 0;
      }
    } else if (!S_ISDIR(sb.st_mode)) {
      fprintf(stderr, "fcm-sim: output path '%s' exists and is not a directory\n", buf);
      return 0;
    }
    buf[k] = c;
  }
  return 1;
}

/* One progress report per step on stderr: a bar with ETA on a terminal, else a line. */
/* k of n steps of this process done; step `step` of `total` in all. */
static void progress(int tty, long long k, long long n, long long step, long long total,
                     const fcm_step_info *si, double elapsed)
{
  if (tty) {
    int width = 30, fill = (int)(width * step / (total > 0 ? total : 1));
    double eta = k > 0 ? elapsed / (double)k * (double)(n - k) : 0.0;
    char bar[64];
    for (int i = 0; i < width; i++)
      bar[i] = i < fill ? '#' : '.';
    bar[width] = '\0';
    fprintf(stderr, "\r[%s] %lld/%lld t=%.4g s newton %d  ETA %.0f s   ", bar, step, total,
            si->time, si->newton_iterations, eta);
    if (k == n) fputc('\n', stderr);
  } else {
    fprintf(stderr,
            "fcm-sim: step %lld/%lld t=%.6g s newton %d linear %lld residual %.3e (%.3f s)\n", step,
            total, si->time, si->newton_iterations, si->linear_iterations, si->residual,
            si->time_total);
  }
}

/* Write a checkpoint <dir>/<name>_checkpoint_NNNNNN.fcmck of the current step. */
static int write_checkpoint(fcm_ctx *ctx, fcm_simulation *sim, const char *dir, const char *name,
                            int quiet)
{
  char path[4096];
  snprintf(path, sizeof path, "%s/%s_checkpoint_%06lld.fcmck", dir, name,
           fcm_simulation_step_count(sim));
  if (fcm_simulation_write_checkpoint(sim, path) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    return 0;
  }
  if (!quiet && !isatty(2)) fprintf(stderr, "fcm-sim: checkpoint %s\n", path);
  return 1;
}

static int scene_main(int argc, char **argv)
{
  scene_options o = {NULL, NULL, NULL, 0, -1, 0, 0, 0};
  if (!parse_scene_args(argc, argv, &o)) return 2;
  int rc = 1;
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  char logpath[4096];
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) {
    fprintf(stderr, "fcm-sim: cannot create the fcm context\n");
    return 1;
  }
  fcm_status st = o.path ? fcm_scene_create_from_file(ctx, o.path, &scene)
                         : fcm_scene_create_default(ctx, &scene);
  if (st != FCM_OK) { /* invalid scene: the parser's message, nothing written */
    fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
    rc = 2;
    goto done;
  }
  if (o.print_scene) {
    fcm_scene_view(scene, stdout);
    rc = 0;
    goto done;
  }
  if (fcm_scene_get_solver(scene)->threads > 0) /* every OpenMP loop of the run */
    omp_set_num_threads(fcm_scene_get_solver(scene)->threads);
  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = o.check ? (o.steps > 0 && o.steps < 3 ? o.steps : 3)
                         : (o.steps > 0 ? o.steps : FCM_DEFAULT);
  so.checkpoint_interval = o.check ? 0 : o.checkpoint_every;
  const char *name = fcm_scene_name(scene);
  if (!o.quiet)
    fprintf(stderr, "fcm-sim: scene %s (%s): building\n", name, fcm_scene_source(scene));
  if (fcm_simulation_create(ctx, scene, &so, &sim) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    goto done;
  }
  if (o.resume) {
    if (fcm_simulation_read_checkpoint(sim, o.resume) != FCM_OK) {
      fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
      rc = 2;
      goto done;
    }
    if (!o.quiet)
      fprintf(stderr, "fcm-sim: resumed from %s at step %lld (t = %.9g s)\n", o.resume,
              fcm_simulation_step_count(sim), fcm_integrator_time(fcm_simulation_integrator(sim)));
  }
  const char *dir = o.outdir ? o.outdir : fcm_scene_get_output(scene)->directory;
  int write = !o.check;
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  int frame = (int)c.frames, frames_at_start = frame;
  if (write) {
    if (!make_dirs(dir)) goto done;
    snprintf(logpath, sizeof logpath, "%s/%s_log.csv", dir, name);
    if ((!o.resume && fcm_simulation_write_frame(sim, dir, frame++) != FCM_OK) ||
        fcm_simulation_write_log(sim, logpath) != FCM_OK) {
      fcm_ctx_error_view(ctx, stderr);
      goto done;
    }
  }
  int tty = !o.quiet && isatty(2);
  double t0 = fcm_wtime();
  long long n = fcm_simulation_num_steps(sim), first = fcm_simulation_step_count(sim);
  while (!fcm_simulation_done(sim)) {
    fcm_step_info si;
    if (fcm_simulation_step(sim, &si) != FCM_OK) {
      if (tty) fputc('\n', stderr);
      fcm_ctx_error_view(ctx, stderr);
      if (write) fcm_simulation_write_log(sim, logpath);
      goto done;
    }
    if (!fcm_simulation_state_finite(sim)) {
      fprintf(stderr, "fcm-sim: non-finite state after step %lld\n",
              fcm_simulation_step_count(sim));
      goto done;
    }
    long long k = fcm_simulation_step_count(sim);
    if (!o.quiet) progress(tty, k - first, n - first, k, n, &si, fcm_wtime() - t0);
    if (write && fcm_simulation_frame_due(sim)) {
      if (fcm_simulation_write_frame(sim, dir, frame++) != FCM_OK ||
          fcm_simulation_write_log(sim, logpath) != FCM_OK) {
        fcm_ctx_error_view(ctx, stderr);
        goto done;
      }
    }
    if (write && fcm_simulation_checkpoint_due(sim) &&
        !write_checkpoint(ctx, sim, dir, name, o.quiet))
      goto done;
  }
  if (write && fcm_simulation_write_log(sim, logpath) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    goto done;
  }
  if (!o.quiet) {
    fcm_simulation_summary_view(sim, stdout);
    if (write) {
      fcm_simulation_get_counters(sim, &c);
      if (c.frames > 0 && (int)c.frames > frames_at_start)
        printf("  output    %s/%s_background.pvd, %s/%s_log.csv\n", dir, name, dir, name);
      else
        printf("  output    %s/%s_log.csv (no new frame)\n", dir, name);
    }
  }
  rc = 0;
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return rc;
}

int main(int argc, char **argv)
{
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  for (int i = 1; i < argc; i++)
    if (!strcmp(argv[i], "--cantilever")) return demo_main(argc, argv);
  return scene_main(argc, argv);
}
