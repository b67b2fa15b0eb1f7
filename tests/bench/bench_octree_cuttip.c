/* Convergence toward a crack front, adaptive against uniform: the cut-tip problem of
 * tests/fem/cuttip.h (the unit cube cut by a half-plane crack whose straight front runs
 * through the body, the exact mixed-mode plane-strain Williams field prescribed on the whole
 * boundary), Hex8 or Hex20 (argument, default hex8). Uniform grids n = 4..32 (Hex20 4..16)
 * against two octree sequences grown from the 2^3 grid:
 * - "jumps": Doerfler marking on the stress-jump indicator (fcm_space_stress_jumps(): the
 *   largest indicators holding half of sum eta^2), an a posteriori sequence;
 * - "front": a cell of size h at distance d from the front refined while h > c max(d, h)^(3/5)
 *   (the grading h = c r^(3/5) equidistributes the Hex8 interpolation error of the r^(1/2)
 *   field, h^5 r^-3 per cell, down to the cells at the front, of size c^(5/2)),
 *   c = 0.6 x 0.85^k at step k: an a priori sequence.
 * Each solved through the hanging-node constraints (T^T K T) with the cut rules of the crack.
 * Prints the DOFs of the reduced system (hanging copies eliminated, boundary DOFs included),
 * cells and the relative H1-seminorm error of each, then for every uniform grid the DOFs and
 * cells each adaptive sequence needs for the same error (log-log interpolation between its
 * steps), and the fitted rates. */
#include "../fem/cuttip.h"

#include <string.h>

#define MAX_STEPS 16

static int by_eta_desc(const void *a, const void *b)
{
  const double x = *(const double *)a, y = *(const double *)b;
  return (x < y) - (x > y);
}

typedef struct sequence {
  int steps;
  double err[MAX_STEPS], energy[MAX_STEPS], dofs[MAX_STEPS], cells[MAX_STEPS];
} sequence;

static void print_step(const char *name, int step, double nf, const fcm_mesh *m,
                       const double err[2])
{
  printf("%6s %4d  %9.0f  %7lld  %9d  %.4e  %.4e\n", name, step, nf,
         (long long)fcm_mesh_num_cells(m), fcm_mesh_max_level(m), err[0], err[1]);
  fflush(stdout);
}

/* Doerfler on the stress jumps from the 2^3 octree until max_dofs. */
static void run_jumps(fcm_ctx *ctx, fcm_element_type type, double max_dofs, sequence *q)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n2[3] = {2, 2, 2};
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n2, NULL, &m));
  q->steps = 0;
  for (int step = 0; step < MAX_STEPS; step++) {
    const fcm_index nc = fcm_mesh_num_cells(m);
    double *eta = calloc((size_t)nc, sizeof *eta), *sorted = calloc((size_t)nc, sizeof *sorted);
    fcm_index nf = 0;
    double e2[2];
    TEST_OK(ctx, cuttip_solve(ctx, m, &nf, e2, NULL, eta));
    q->err[step] = e2[0], q->energy[step] = e2[1];
    q->dofs[step] = (double)nf, q->cells[step] = (double)nc, q->steps = step + 1;
    print_step("jumps", step, (double)nf, m, e2);
    double total = 0.0, acc = 0.0, cut = HUGE_VAL;
    for (fcm_index c = 0; c < nc; c++)
      sorted[c] = eta[c] * eta[c], total += sorted[c];
    qsort(sorted, (size_t)nc, sizeof *sorted, by_eta_desc);
    for (fcm_index c = 0; c < nc && acc < 0.5 * total; c++)
      acc += sorted[c], cut = sorted[c];
    unsigned char *flags = calloc((size_t)nc, 1);
    for (fcm_index c = 0; c < nc; c++)
      flags[c] = eta[c] * eta[c] >= cut;
    fcm_mesh *next = NULL;
    if (q->dofs[step] < max_dofs) TEST_OK(ctx, fcm_mesh_create_refined(ctx, m, flags, &next));
    free(eta), free(sorted), free(flags);
    fcm_mesh_destroy(&m);
    if (!next) break;
    m = next;
  }
}

/* The a priori sequence: c = 0.6 x 0.85^k, until max_dofs. */
static void run_front(fcm_ctx *ctx, fcm_element_type type, double max_dofs, sequence *q)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n2[3] = {2, 2, 2};
  q->steps = 0;
  for (int step = 0; step < MAX_STEPS; step++) {
    double c = 0.6 * pow(0.85, step);
    fcm_octree_options o = fcm_octree_options_default();
    o.refine = cuttip_near_front, o.refine_user = &c, o.refine_level = FCM_OCTREE_MAX_LEVEL;
    fcm_mesh *m = NULL;
    fcm_index nf = 0;
    double e2[2];
    TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n2, &o, &m));
    TEST_OK(ctx, cuttip_solve(ctx, m, &nf, e2, NULL, NULL));
    q->err[step] = e2[0], q->energy[step] = e2[1];
    q->dofs[step] = (double)nf, q->cells[step] = (double)fcm_mesh_num_cells(m);
    q->steps = step + 1;
    print_step("front", step, (double)nf, m, e2);
    fcm_mesh_destroy(&m);
    if (nf >= max_dofs) break;
  }
}

/* The DOFs and cells of sequence q at error e (log-log between its steps; -1 out of range). */
static void at_error(const sequence *q, double e, double *dofs, double *cells)
{
  *dofs = *cells = -1.0;
  for (int j = 0; j + 1 < q->steps; j++) {
    const double a = q->err[j], b = q->err[j + 1];
    if (!((a >= e && e >= b) || (a <= e && e <= b)) || a == b) continue;
    const double t = log(e / a) / log(b / a);
    *dofs = q->dofs[j] * pow(q->dofs[j + 1] / q->dofs[j], t);
    *cells = q->cells[j] * pow(q->cells[j + 1] / q->cells[j], t);
  }
}

/* Least-squares slope of log err against log x over entries [first, last]. */
static double fit_rate(const double *x, const double *err, int first, int last)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const int n = last - first + 1;
  for (int k = first; k <= last; k++) {
    const double lx = log(x[k]), ly = log(err[k]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_element_type type = FCM_ELEMENT_HEX8;
  if (argc > 1 && fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const int hex20 = type == FCM_ELEMENT_HEX20;
  static const int sizes8[] = {4, 6, 8, 12, 16, 24, 32}, sizes20[] = {4, 6, 8, 12, 16};
  const int nu = hex20 ? 5 : 7;
  const int *sizes = hex20 ? sizes20 : sizes8;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  double udofs[8], uerr[8], uen[8], uh[8];
  printf("%s, crack front x = %.2f, y = %.2f; relative H1-seminorm errors\n",
         hex20 ? "Hex20" : "Hex8", CUTTIP_X0, CUTTIP_Y0);
  printf("uniform n  free DOFs  cells  H1 error    energy error\n");
  for (int k = 0; k < nu; k++) {
    fcm_mesh *m = NULL;
    const fcm_index n3[3] = {sizes[k], sizes[k], sizes[k]};
    fcm_index nf = 0;
    double e2[2];
    TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n3, &m));
    TEST_OK(ctx, cuttip_solve(ctx, m, &nf, e2, NULL, NULL));
    uerr[k] = e2[0], uen[k] = e2[1];
    udofs[k] = (double)nf, uh[k] = 1.0 / sizes[k];
    printf("%9d  %9lld  %5lld  %.4e  %.4e\n", sizes[k], (long long)nf,
           (long long)fcm_mesh_num_cells(m), uerr[k], uen[k]);
    fflush(stdout);
    fcm_mesh_destroy(&m);
  }
  sequence qj, qf;
  printf("  seq step  free DOFs    cells  max level  H1 error    energy error\n");
  run_jumps(ctx, type, 1.5 * udofs[nu - 1], &qj);
  run_front(ctx, type, 1.5 * udofs[nu - 1], &qf);
  printf("\nuniform n  error       uniform DOFs  uniform cells | jumps: DOFs  ratio  cells  ratio "
         "| front: DOFs  ratio  cells  ratio\n");
  for (int k = 0; k < nu; k++) {
    const double ucells = (double)sizes[k] * sizes[k] * sizes[k];
    double jd, jc, fd, fc;
    at_error(&qj, uerr[k], &jd, &jc);
    at_error(&qf, uerr[k], &fd, &fc);
    printf(
        "%9d  %.4e  %12.0f  %13.0f | %11.0f  %5.1f  %5.0f  %5.1f | %11.0f  %5.1f  %5.0f  %5.1f\n",
        sizes[k], uerr[k], udofs[k], ucells, jd, jd > 0 ? udofs[k] / jd : 0.0, jc,
        jc > 0 ? ucells / jc : 0.0, fd, fd > 0 ? udofs[k] / fd : 0.0, fc,
        fc > 0 ? ucells / fc : 0.0);
  }
  printf("H1 rates: uniform h^%.2f (last three grids), N^-%.3f; jumps N^-%.3f, front N^-%.3f "
         "(last three steps)\n",
         fit_rate(uh, uerr, nu - 3, nu - 1), -fit_rate(udofs, uerr, nu - 3, nu - 1),
         -fit_rate(qj.dofs, qj.err, qj.steps - 3, qj.steps - 1),
         -fit_rate(qf.dofs, qf.err, qf.steps - 3, qf.steps - 1));
  printf("energy rates: uniform h^%.2f, N^-%.3f; jumps N^-%.3f, front N^-%.3f\n",
         fit_rate(uh, uen, nu - 3, nu - 1), -fit_rate(udofs, uen, nu - 3, nu - 1),
         -fit_rate(qj.dofs, qj.energy, qj.steps - 3, qj.steps - 1),
         -fit_rate(qf.dofs, qf.energy, qf.steps - 3, qf.steps - 1));
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
