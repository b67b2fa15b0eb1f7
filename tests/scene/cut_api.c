/* fcm_simulation_cut(): a host's cut between steps.
 * - In the reference frame it is the scene's cut effect: a spinning box cut by a rectangle
 *   through fcm_simulation_cut() after two steps has, after five, the same displacement bits,
 *   log and counters as the same rectangle given as a cut effect due before the third step.
 * - In the deformed frame a blade is carried back to the material: with the state set to an
 *   affine motion x = A X + b (a rotation, then also stretches and a shear; the trilinear
 *   elements map it exactly), the blade A B + b cut in the deformed frame gives the cut of B
 *   at rest: the same DOFs, cells, pieces and piece volumes, and after a step the same centre
 *   of mass (and, after the rigid motion, the same displacement to 1e-9 of its size). The
 *   blade is a grid whose inner vertices lie in the mesh (taken by the element holding them)
 *   and whose outer ones beyond it (taken by the nearest element's motion).
 *   fcm_simulation_rest_positions() gives A^-1 (x - b) (1e-12) in the body, beyond it and
 *   beyond the mesh.
 * - A blade beyond the body is a counted miss; the run goes on. One through the cells above
 *   the body keeps the run's rules and integrator, and its steps are those without the cut,
 *   bit for bit; a crack into the body's top is a miss too, but makes them again.
 * - Refused, the run unchanged: NULL arguments, a frame out of range, a blade without area, a
 *   scene without geometry, every allocation failed in turn; a checkpoint after such a cut. */
#include "scene_util.h"

static const char *box_scene(char *buf, size_t cap, const char *effects)
{
  snprintf(buf, cap,
           "{\"version\": 1, \"name\": \"cut_api\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.25, -0.25, -0.25],"
           "   \"max\": [1.25, 0.75, 0.75]}, \"cells\": [3, 2, 2]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1, 0.5, 0.5],"
           "   \"cells\": [2, 1, 1]},"
           " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3,"
           "   \"density\": 1000},"
           " \"time\": {\"dt\": 0.02, \"steps\": 5}, \"solver\": {\"newton\": {\"rtol\": 1e-12}},"
           " \"output\": {\"surface\": true},"
           " \"effects\": [%s]}",
           effects);
  return buf;
}

/* The scenes of the simulations made so far (a simulation reads its scene for its life):
 * destroyed by drop_scenes() once those simulations are. */
static fcm_scene *scenes[16];
static int num_scenes;

static int checkpoint_interval = FCM_DEFAULT; /* of the simulations make_with() makes */

static fcm_simulation *make_with(fcm_ctx *ctx, const char *json, int host_cuts)
{
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  fcm_simulation_options o = fcm_simulation_options_default();
  o.host_cuts = host_cuts;
  o.checkpoint_interval = checkpoint_interval;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "cut_api.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, &o, &sim));
  if (scene && num_scenes < 16)
    scenes[num_scenes++] = scene;
  else
    fcm_scene_destroy(&scene);
  return sim;
}

/* A simulation of the scene whose host will cut it. */
static fcm_simulation *make(fcm_ctx *ctx, const char *json)
{
  return make_with(ctx, json, 1);
}

static void drop_scenes(void)
{
  while (num_scenes > 0)
    fcm_scene_destroy(&scenes[--num_scenes]);
}

static int steps(fcm_ctx *ctx, fcm_simulation *sim, int n)
{
  for (int k = 0; k < n; k++)
    if (fcm_simulation_step(sim, NULL) != FCM_OK) {
      TEST_OK(ctx, FCM_ERR_ARG);
      return 0;
    }
  return 1;
}

/* a and b have as many DOFs and the same displacement, bit for bit. */
static void same_displacement(fcm_simulation *a, fcm_simulation *b)
{
  const fcm_integrator *ia = fcm_simulation_integrator(a), *ib = fcm_simulation_integrator(b);
  const fcm_index n = fcm_integrator_num_dofs(ia);
  TEST_TRUE(n == fcm_integrator_num_dofs(ib));
  if (n == fcm_integrator_num_dofs(ib))
    TEST_TRUE(memcmp(fcm_integrator_displacement(ia), fcm_integrator_displacement(ib),
                     (size_t)n * sizeof(double)) == 0);
}

/* The log as text without its wall_time column (the last). */
static char *log_text(fcm_simulation *sim)
{
  const char *path = "cut_api_log.csv";
  if (fcm_simulation_write_log(sim, path) != FCM_OK) return NULL;
  FILE *f = fopen(path, "r");
  char *text = calloc(1, 1 << 16), line[4096];
  size_t len = 0;
  while (f && text && fgets(line, sizeof line, f)) {
    char *c = strrchr(line, ',');
    if (c) *c = '\0';
    len += (size_t)snprintf(text + len, (1 << 16) - len, "%s\n", line);
  }
  if (f) fclose(f);
  remove(path);
  return text;
}

/* host_cuts 1: the cut keeps the elements it leaves (the same bits); 0: integrates all. */
static void reference_is_the_effect(fcm_ctx *ctx, int host_cuts)
{
  char buf[4096];
  const double center[3] = {0.55, 0.25, 0.25}, normal[3] = {1, 0, 0}, axis[3] = {0, 1, 0},
               size[2] = {3, 3};
  fcm_simulation *a =
      make(ctx, box_scene(buf, sizeof buf,
                          "{\"initial_velocity\": {\"angular_velocity\": [0, 0, 4]}},"
                          " {\"cut\": {\"time\": 0.04, \"surface\": {\"rectangle\": {\"center\": "
                          "[0.55, 0.25, 0.25], \"normal\": [1, 0, 0], \"axis\": [0, 1, 0], "
                          "\"size\": [3, 3]}}}}"));
  fcm_simulation *b = make_with(
      ctx, box_scene(buf, sizeof buf, "{\"initial_velocity\": {\"angular_velocity\": [0, 0, 4]}}"),
      host_cuts);
  fcm_surface *blade = NULL;
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, center, normal, axis, size, &blade));
  if (a && b && blade && steps(ctx, a, 5) && steps(ctx, b, 2)) {
    fcm_cut_info info;
    const fcm_index n0 = fcm_space_num_dofs(fcm_simulation_space(b));
    TEST_OK(ctx, fcm_simulation_cut(b, blade, FCM_CUT_FRAME_REFERENCE, &info));
    TEST_TRUE(!info.missed && info.dofs_before == n0 && info.dofs_after > n0);
    TEST_TRUE(info.dofs_after == fcm_space_num_dofs(fcm_simulation_space(b)));
    TEST_TRUE(info.cells_integrated > 0 && info.seconds >= info.seconds_rules);
    steps(ctx, b, 3);
    same_displacement(a, b);
    char *la = log_text(a), *lb = log_text(b);
    TEST_TRUE(la && lb && strcmp(la, lb) == 0);
    free(la), free(lb);
    fcm_simulation_counters ca, cb;
    fcm_simulation_get_counters(a, &ca);
    fcm_simulation_get_counters(b, &cb);
    TEST_TRUE(ca.cuts == 1 && cb.cuts == 1 && cb.cuts_missed == 0 && cb.pieces == 2);
    TEST_TRUE(ca.cut_cells == cb.cut_cells && ca.num_dofs == cb.num_dofs);
    TEST_TRUE(cb.time_cuts > 0.0 && cb.time_cut_rules > 0.0);
    /* the summary lists the cut, at the time it was made */
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (f) {
      fcm_simulation_summary_view(b, f);
      fclose(f);
    }
    TEST_TRUE(text && strstr(text, "  cut 1     t = 0.04 s: ") != NULL);
    free(text);
    /* a checkpoint cannot hold it */
    TEST_ERR(ctx, fcm_simulation_write_checkpoint(b, "cut_api.ckpt"), FCM_ERR_UNSUPPORTED,
             "fcm_simulation_cut()");
    TEST_TRUE(access("cut_api.ckpt", F_OK) != 0);
  }
  fcm_surface_destroy(&blade);
  fcm_simulation_destroy(&a);
  fcm_simulation_destroy(&b);
  drop_scenes();
}

/* A grid of (m + 1)^2 vertices on the slanted plane x = 0.45 + 0.1 y + 0.05 z over
 * y, z in [-0.4, 0.9] (the outer ones beyond the background mesh), mapped by x -> A x + t. */
static fcm_surface *grid_blade(fcm_ctx *ctx, const double A[9], const double t[3])
{
  enum { m = 4 };
  double v[3 * (m + 1) * (m + 1)];
  fcm_index tri[3 * 2 * m * m];
  for (int i = 0; i <= m; i++)
    for (int j = 0; j <= m; j++) {
      const double y = -0.37 + 1.3 * i / m, z = -0.41 + 1.3 * j / m, x = 0.45 + 0.1 * y + 0.05 * z;
      const double p[3] = {x, y, z};
      for (int r = 0; r < 3; r++)
        v[3 * (i * (m + 1) + j) + r] =
            A[3 * r] * p[0] + A[3 * r + 1] * p[1] + A[3 * r + 2] * p[2] + t[r];
    }
  int k = 0;
  for (int i = 0; i < m; i++)
    for (int j = 0; j < m; j++) {
      const fcm_index a = i * (m + 1) + j, b = a + 1, c = a + m + 1, d = c + 1;
      const fcm_index q[6] = {a, b, d, a, d, c};
      memcpy(tri + 6 * k++, q, sizeof q);
    }
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_surface_create(ctx, (m + 1) * (m + 1), v, 2 * m * m, tri, &s));
  return s;
}

/* A displacement field: u at the rest position X (user: its parameters). */
typedef void (*field_fn)(const double X[3], const void *user, double u[3]);

/* Set the state of sim to the field f at every element's nodes (their DOF copies), at rest
 * (zero velocity). */
static void set_field(fcm_ctx *ctx, fcm_simulation *sim, field_fn f, const void *user)
{
  fcm_integrator *I = fcm_simulation_integrator(sim);
  const fcm_space *space = fcm_simulation_space(sim);
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const fcm_index n = fcm_integrator_num_dofs(I), ne = fcm_space_num_elements(space);
  double *u = calloc((size_t)n, sizeof *u), *v = calloc((size_t)n, sizeof *v), X[3 * 27];
  const int nn = fcm_element_get_info(fcm_mesh_element_type(mesh))->num_nodes;
  for (fcm_index e = 0; u && e < ne; e++) {
    const fcm_index *dof = fcm_space_element_dofs(space, e);
    fcm_mesh_cell_coords(mesh, fcm_space_element_cell(space, e), X);
    for (int a = 0; a < nn; a++)
      f(X + 3 * a, user, u + dof[a]);
  }
  double tt = 0.0;
  long long k = 0;
  fcm_integrator_get_state(I, NULL, NULL, &tt, &k);
  if (u && v) TEST_OK(ctx, fcm_integrator_set_state(I, u, v, tt, k));
  free(u), free(v);
}

/* x = A X + t: user holds A (row-major) and then t. */
static void affine_field(const double X[3], const void *user, double u[3])
{
  const double *A = user, *t = A + 9;
  for (int r = 0; r < 3; r++)
    u[r] = A[3 * r] * X[0] + A[3 * r + 1] * X[1] + A[3 * r + 2] * X[2] + t[r] - X[r];
}

/* A smooth field that no element maps affinely. */
static void curved_field(const double X[3], const void *user, double u[3])
{
  (void)user;
  u[0] = 0.1 * sin(3 * X[1]) + 0.05 * X[2] * X[2];
  u[1] = 0.15 * X[0] * X[0] + 0.05 * sin(2 * X[2]);
  u[2] = -0.2 * X[0] * X[0] * (1 + X[1]);
}

/* Set the state of sim to x = A X + t at rest. */
static void set_affine(fcm_ctx *ctx, fcm_simulation *sim, const double A[9], const double t[3])
{
  double At[12];
  memcpy(At, A, 9 * sizeof *A);
  memcpy(At + 9, t, 3 * sizeof *t);
  set_field(ctx, sim, affine_field, At);
}

/* The cut of blade A B + t in the deformed frame, the state x = A X + t, against that of B at
 * rest: the same DOFs, cells, pieces and piece volumes (1e-12), and after a step the same
 * centre of mass (1e-12 m); with `nodal` the same displacement at every DOF (1e-9 of the
 * largest). Not so after a strain: a node whose support holds little material takes a
 * displacement that the rounding of its elements' rules moves (the centre of mass, weighted
 * by the material, does not). */
static void deformed_is_carried_back(fcm_ctx *ctx, const double A[9], const double t[3], int nodal)
{
  char buf[4096];
  const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, zero[3] = {0, 0, 0};
  fcm_simulation *a =
      make(ctx, box_scene(buf, sizeof buf, "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}"));
  fcm_simulation *b =
      make(ctx, box_scene(buf, sizeof buf, "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}"));
  fcm_surface *rest = grid_blade(ctx, I3, zero), *moved = grid_blade(ctx, A, t);
  if (a && b && rest && moved) {
    set_affine(ctx, a, A, t);
    set_affine(ctx, b, A, t);
    /* points carried back: in the body, in the mesh beyond it, beyond the mesh */
    const double P[12] = {0.5, 0.25, 0.25, 0.9, 0.1, 0.45, 1.2, 0.7, -0.2, -1.0, 2.0, 3.0};
    double x[12], Xb[12];
    for (int i = 0; i < 4; i++)
      for (int r = 0; r < 3; r++)
        x[3 * i + r] =
            A[3 * r] * P[3 * i] + A[3 * r + 1] * P[3 * i + 1] + A[3 * r + 2] * P[3 * i + 2] + t[r];
    TEST_OK(ctx, fcm_simulation_rest_positions(b, 4, x, Xb));
    for (int i = 0; i < 12; i++)
      TEST_NEAR(Xb[i], P[i], 0.0, 1e-12);
    x[4] = NAN;
    TEST_ERR(ctx, fcm_simulation_rest_positions(b, 4, x, Xb), FCM_ERR_ARG, "point 1");
    TEST_ERR(ctx, fcm_simulation_rest_positions(b, -1, x, Xb), FCM_ERR_ARG, "n >= 0");
    TEST_OK(ctx, fcm_simulation_rest_positions(b, 0, NULL, NULL));
    fcm_cut_info ia, ib;
    TEST_OK(ctx, fcm_simulation_cut(a, rest, FCM_CUT_FRAME_REFERENCE, &ia));
    TEST_OK(ctx, fcm_simulation_cut(b, moved, FCM_CUT_FRAME_DEFORMED, &ib));
    TEST_TRUE(!ia.missed && !ib.missed && ia.dofs_after > ia.dofs_before);
    TEST_TRUE(ia.dofs_after == ib.dofs_after && ia.cells_integrated == ib.cells_integrated);
    fcm_simulation_counters ca, cb;
    fcm_simulation_get_counters(a, &ca);
    fcm_simulation_get_counters(b, &cb);
    TEST_TRUE(ca.pieces == 2 && cb.pieces == 2);
    /* the same pieces, of the same volumes */
    const fcm_cell_rules *ra = fcm_simulation_cell_rules(a), *rb = fcm_simulation_cell_rules(b);
    const fcm_index np = fcm_cell_rules_num_pieces(ra);
    TEST_TRUE(np == fcm_cell_rules_num_pieces(rb));
    double vmax = 0.0, dv = 0.0;
    for (fcm_index q = 0; q < np && np == fcm_cell_rules_num_pieces(rb); q++) {
      TEST_TRUE(fcm_cell_rules_piece_cell(ra, q) == fcm_cell_rules_piece_cell(rb, q));
      const double va = fcm_cell_rules_piece_volume(ra, q), vb = fcm_cell_rules_piece_volume(rb, q);
      vmax = fmax(vmax, va), dv = fmax(dv, fabs(va - vb));
    }
    TEST_TRUE(vmax > 0.0 && dv <= 1e-12 * vmax);
    steps(ctx, a, 1);
    steps(ctx, b, 1);
    double ma[3], mb[3];
    TEST_OK(ctx, fcm_simulation_center_of_mass(a, ma));
    TEST_OK(ctx, fcm_simulation_center_of_mass(b, mb));
    for (int d = 0; d < 3; d++)
      TEST_NEAR(ma[d], mb[d], 0.0, 1e-12);
    if (nodal) {
      const fcm_index n = fcm_integrator_num_dofs(fcm_simulation_integrator(a));
      TEST_TRUE(n == fcm_integrator_num_dofs(fcm_simulation_integrator(b)));
      if (n == fcm_integrator_num_dofs(fcm_simulation_integrator(b))) {
        const double *ua = fcm_integrator_displacement(fcm_simulation_integrator(a)),
                     *ub = fcm_integrator_displacement(fcm_simulation_integrator(b));
        double dmax = 0.0, umax = 0.0;
        for (fcm_index i = 0; i < n; i++)
          dmax = fmax(dmax, fabs(ua[i] - ub[i])), umax = fmax(umax, fabs(ua[i]));
        TEST_TRUE(umax > 0.1 && dmax <= 1e-9 * umax);
      }
    }
  }
  fcm_surface_destroy(&rest);
  fcm_surface_destroy(&moved);
  fcm_simulation_destroy(&a);
  fcm_simulation_destroy(&b);
  drop_scenes();
}

/* A rigid motion (a turn by 0.4 about (1, 2, 2)/3 and a shift), and with stretches and a shear
 * after the turn. */
static void deformed_frames(fcm_ctx *ctx)
{
  const double c = cos(0.4), s = sin(0.4), w[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3};
  const double cross[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
  const double D[9] = {1.1, 0.08, 0, 0, 0.95, 0, 0.03, 0, 1.02}, t[3] = {0.3, -0.2, 0.1};
  double Q[9], A[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      Q[3 * i + j] = c * (i == j) + s * cross[3 * i + j] + (1 - c) * w[i] * w[j];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      A[3 * i + j] = Q[3 * i] * D[j] + Q[3 * i + 1] * D[3 + j] + Q[3 * i + 2] * D[6 + j];
  deformed_is_carried_back(ctx, Q, t, 1);
  deformed_is_carried_back(ctx, A, t, 0);
}

/* A scene whose cut effect is due at t = 0 (applied at the set-up) saves and restores as
 * before; a simulation cut by the host neither saves (fcm_simulation_checkpoint_due() 0 from
 * then on) nor restores. */
static void checkpoints(fcm_ctx *ctx)
{
  char buf[4096];
  const char *cut0 = "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}, {\"cut\": {\"surface\": "
                     "{\"plane\": {\"point\": [0.55, 0, 0], \"normal\": [1, 0, 0]}}}}";
  fcm_simulation *a = make(ctx, box_scene(buf, sizeof buf, cut0));
  fcm_simulation *b = make(ctx, box_scene(buf, sizeof buf, cut0));
  if (a && b && steps(ctx, a, 1)) {
    TEST_OK(ctx, fcm_simulation_write_checkpoint(a, "cut_api_t0.ckpt"));
    TEST_OK(ctx, fcm_simulation_read_checkpoint(b, "cut_api_t0.ckpt"));
    steps(ctx, a, 1);
    steps(ctx, b, 1);
    const fcm_index n = fcm_integrator_num_dofs(fcm_simulation_integrator(a));
    TEST_TRUE(n == fcm_integrator_num_dofs(fcm_simulation_integrator(b)) &&
              memcmp(fcm_integrator_displacement(fcm_simulation_integrator(a)),
                     fcm_integrator_displacement(fcm_simulation_integrator(b)),
                     (size_t)n * sizeof(double)) == 0);
  }
  fcm_simulation_destroy(&a);
  fcm_simulation_destroy(&b);
  checkpoint_interval = 1;
  a = make(ctx, box_scene(buf, sizeof buf, "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}"));
  checkpoint_interval = FCM_DEFAULT;
  const double center[3] = {0.55, 0.25, 0.25}, normal[3] = {1, 0, 0}, axis[3] = {0, 1, 0},
               size[2] = {3, 3};
  fcm_surface *blade = NULL;
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, center, normal, axis, size, &blade));
  if (a && blade && steps(ctx, a, 1)) {
    TEST_TRUE(fcm_simulation_checkpoint_due(a) == 1);
    TEST_OK(ctx, fcm_simulation_cut(a, blade, FCM_CUT_FRAME_REFERENCE, NULL));
    TEST_ERR(ctx, fcm_simulation_read_checkpoint(a, "cut_api_t0.ckpt"), FCM_ERR_ARG,
             "fcm_simulation_cut()");
    steps(ctx, a, 1);
    TEST_TRUE(fcm_simulation_checkpoint_due(a) == 0);
  }
  remove("cut_api_t0.ckpt");
  fcm_surface_destroy(&blade);
  fcm_simulation_destroy(&a);
  drop_scenes();
}

/* The element search of the pull-back under a state no element maps affinely (a smooth
 * nonlinear field at the nodes): 200 material points of the body, pushed forward through their
 * own element, come back to within 1e-11 (an affine state, exact from any element, cannot
 * tell a wrong element from the right one). */
static void element_search(fcm_ctx *ctx)
{
  char buf[4096];
  fcm_simulation *sim =
      make(ctx, box_scene(buf, sizeof buf, "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}"));
  if (!sim) return;
  set_field(ctx, sim, curved_field, NULL);
  const fcm_space *space = fcm_simulation_space(sim);
  const fcm_mesh *mesh = fcm_space_mesh(space);
  const double *u = fcm_integrator_displacement(fcm_simulation_integrator(sim));
  double worst = 0.0, X[24];
  rng r = {12345};
  for (int i = 0; i < 200; i++) {
    const double P[3] = {0.5 + 0.49 * rng_uniform(&r), 0.25 + 0.24 * rng_uniform(&r),
                         0.25 + 0.24 * rng_uniform(&r)};
    fcm_index cell;
    double xi[3], xn[24], p[3], R[3];
    TEST_OK(ctx, fcm_space_locate(space, 1, P, &cell, xi, NULL));
    const fcm_index e = fcm_space_point_element(space, cell, xi);
    const fcm_index *dof = fcm_space_element_dofs(space, e);
    fcm_mesh_cell_coords(mesh, cell, X);
    for (int a = 0; a < 8; a++)
      for (int c = 0; c < 3; c++)
        xn[3 * a + c] = X[3 * a + c] + u[dof[a] + c];
    fcm_element_map(FCM_ELEMENT_HEX8, xn, xi, p);
    TEST_OK(ctx, fcm_simulation_rest_positions(sim, 1, p, R));
    for (int c = 0; c < 3; c++)
      worst = fmax(worst, fabs(R[c] - P[c]));
  }
  TEST_TRUE(worst <= 1e-11);
  fcm_simulation_destroy(&sim);
  drop_scenes();
}

/* A blade through the cells above the body, in the air (z = 0.6; the body's top is at 0.5 in
 * cells 0.5 high): a miss that leaves the run's rules and integrator as they were, and its
 * steps those of a run without the cut, bit for bit. A blade into the body's top, down to
 * z = 0.3 (a crack: the material below joins its sides), also misses, but gives the pieces it
 * divides faces on the cut (it counts from a cut that completes it): a new integrator. */
static void miss_keeps_run(fcm_ctx *ctx)
{
  char buf[4096];
  const char *fx = "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}";
  fcm_simulation *a = make(ctx, box_scene(buf, sizeof buf, fx)),
                 *b = make(ctx, box_scene(buf, sizeof buf, fx));
  const double air[3] = {0.5, 0.25, 0.6}, up[3] = {0, 0, 1}, ax[3] = {1, 0, 0},
               air_size[2] = {1.2, 0.7}, crack[3] = {0.6, 0.25, 0.55}, across[3] = {1, 0, 0},
               vertical[3] = {0, 0, 1}, crack_size[2] = {0.5, 0.7};
  fcm_surface *above = NULL, *into = NULL;
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, air, up, ax, air_size, &above));
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, crack, across, vertical, crack_size, &into));
  if (a && b && above && into && steps(ctx, a, 2) && steps(ctx, b, 2)) {
    fcm_cut_info info;
    const fcm_integrator *I = fcm_simulation_integrator(b);
    const fcm_cell_rules *R = fcm_simulation_cell_rules(b);
    TEST_OK(ctx, fcm_simulation_cut(b, above, FCM_CUT_FRAME_REFERENCE, &info));
    TEST_TRUE(info.missed && info.cells_integrated == 0 && info.seconds_integrator == 0.0);
    TEST_TRUE(fcm_simulation_integrator(b) == I && fcm_simulation_cell_rules(b) == R);
    steps(ctx, a, 2), steps(ctx, b, 2);
    same_displacement(a, b);
    TEST_OK(ctx, fcm_simulation_cut(b, into, FCM_CUT_FRAME_REFERENCE, &info));
    TEST_TRUE(info.missed && fcm_simulation_integrator(b) != I);
    fcm_simulation_counters c;
    fcm_simulation_get_counters(b, &c);
    TEST_TRUE(c.cuts == 2 && c.cuts_missed == 2);
    steps(ctx, b, 1);
  }
  fcm_surface_destroy(&above);
  fcm_surface_destroy(&into);
  fcm_simulation_destroy(&a);
  fcm_simulation_destroy(&b);
  drop_scenes();
}

static void misses_and_errors(fcm_ctx *ctx)
{
  char buf[4096];
  fcm_simulation *sim =
      make(ctx, box_scene(buf, sizeof buf, "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}"));
  const double far[3] = {5, 5, 5}, normal[3] = {0, 0, 1}, axis[3] = {1, 0, 0}, size[2] = {1, 1};
  const double line[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
  const fcm_index tri[3] = {0, 1, 2};
  fcm_surface *away = NULL, *flat = NULL;
  TEST_OK(ctx, fcm_surface_create_rectangle(ctx, far, normal, axis, size, &away));
  TEST_OK(ctx, fcm_surface_create(ctx, 3, line, 1, tri, &flat));
  if (sim && away && flat) {
    fcm_cut_info info;
    const fcm_index n0 = fcm_space_num_dofs(fcm_simulation_space(sim));
    TEST_OK(ctx, fcm_simulation_cut(sim, away, FCM_CUT_FRAME_DEFORMED, &info));
    TEST_TRUE(info.missed && info.dofs_after == n0 && info.cells_integrated == 0);
    TEST_ERR(ctx, fcm_simulation_cut(NULL, away, FCM_CUT_FRAME_REFERENCE, NULL), FCM_ERR_ARG, "");
    TEST_ERR(ctx, fcm_simulation_cut(sim, NULL, FCM_CUT_FRAME_REFERENCE, NULL), FCM_ERR_ARG,
             "a blade");
    TEST_ERR(ctx, fcm_simulation_cut(sim, away, (fcm_cut_frame)7, NULL), FCM_ERR_ARG, "frame 7");
    TEST_ERR(ctx, fcm_simulation_cut(sim, flat, FCM_CUT_FRAME_REFERENCE, &info), FCM_ERR_GEOMETRY,
             "the blade");
    fcm_simulation_counters c;
    fcm_simulation_get_counters(sim, &c);
    TEST_TRUE(c.cuts == 1 && c.cuts_missed == 1);
    steps(ctx, sim, 1);
  }
  fcm_simulation_destroy(&sim);
  drop_scenes();
  /* a scene without geometry */
  fcm_scene *scene = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(
                   ctx,
                   "{\"version\": 1, \"name\": \"plain\", \"background\": {\"element\": \"hex8\","
                   " \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, \"cells\": [1, 1, 1]},"
                   " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3,"
                   " \"density\": 1000}, \"time\": {\"dt\": 0.01, \"steps\": 1}}",
                   "plain.json", &scene));
  if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (sim && away)
    TEST_ERR(ctx, fcm_simulation_cut(sim, away, FCM_CUT_FRAME_REFERENCE, NULL), FCM_ERR_ARG,
             "no embedded geometry");
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  fcm_surface_destroy(&away);
  fcm_surface_destroy(&flat);
}

/* Every allocation of a deformed-frame cut failed in turn: FCM_ERR_ALLOC, the run unchanged
 * (its counters, its DOFs) and able to step; then the cut succeeds. */
static void allocation_failures(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx_with(&f, failing_alloc_atomic);
  char buf[4096];
  fcm_simulation *sim =
      ctx ? make(ctx,
                 box_scene(buf, sizeof buf, "{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}"))
          : NULL;
  const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, zero[3] = {0, 0, 0};
  fcm_surface *blade = ctx ? grid_blade(ctx, I3, zero) : NULL;
  if (!sim || !blade) {
    TEST_TRUE(0);
  } else {
    steps(ctx, sim, 1);
    const fcm_index n0 = fcm_space_num_dofs(fcm_simulation_space(sim));
    int failures = 0, done = 0;
    for (long long k = 0; k < 100000 && !done; k++) {
      f.count = 0;
      f.fail_at = k;
      const fcm_status st = fcm_simulation_cut(sim, blade, FCM_CUT_FRAME_DEFORMED, NULL);
      f.fail_at = -1;
      if (st == FCM_OK) {
        done = 1;
        break;
      }
      failures++;
      TEST_TRUE(st == FCM_ERR_ALLOC);
      fcm_ctx_error_clear(ctx);
      fcm_simulation_counters c;
      fcm_simulation_get_counters(sim, &c);
      TEST_TRUE(c.cuts == 0 && fcm_space_num_dofs(fcm_simulation_space(sim)) == n0);
      if (st != FCM_ERR_ALLOC || c.cuts != 0) break;
    }
    TEST_TRUE(done && failures > 20);
    TEST_TRUE(fcm_space_num_dofs(fcm_simulation_space(sim)) > n0);
    steps(ctx, sim, 1);
  }
  fcm_surface_destroy(&blade);
  fcm_simulation_destroy(&sim);
  drop_scenes();
  fcm_ctx_destroy(&ctx);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_TRUE(fcm_ctx_create(NULL, &ctx) == FCM_OK);
  reference_is_the_effect(ctx, 1);
  reference_is_the_effect(ctx, 0);
  checkpoints(ctx);
  element_search(ctx);
  deformed_frames(ctx);
  misses_and_errors(ctx);
  miss_keeps_run(ctx);
  allocation_failures();
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
