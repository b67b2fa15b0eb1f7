/* fcm-condition: the conditioning study of Longva et al. 2020, §5.4 / Fig. 5 (lib/METHOD.md §7):
 * kappa(S A) of a backward-Euler step A = M + dt^2 K(u) on a 4x4x4 grid of [0, 4/3]^3 with
 * the box [0, 1 + eps/3]^3 embedded, for S in {none, Jacobi, Schwarz (clamp and as printed)}
 * and on request the ideal S = P^-1, with and without quadrature stabilization, plus MINRES
 * iteration counts on the same systems.
 *
 * Setup (paper §5.4): cell size 1/3; the box reaches eps/3 into the last layer, so the corner
 * cell keeps the volume (eps/3)^3 and the smallest volume fraction is phi = eps^3 (the swept
 * quantity; eps = phi^(1/3)). Stable Neo-Hookean E = 3e6 Pa, nu = 0.4; u(X) = X_1 (1, 1, -1),
 * which vanishes on the clamped face X_1 = 0; dt = 1/60; K is the unprojected tangent at u
 * (possibly indefinite, then kappa = max|lambda| / min|lambda|). The clamped DOFs are
 * eliminated (removed), and every preconditioner is built on the reduced matrix
 * P = M + dt^2 K_pc with K_pc the PSD-projected tangent by default (--pc-tangent, as the
 * integrator's preconditioner_tangent): the exact tangent's small cut-cell blocks are
 * indefinite or nearly singular and their Schwarz inverses poor. */
#include "cli.h"
#include "fcm-condition-study.h"
#include "app_env.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- options */

static int parse_fractions(const char *prog, const char *opt, const char *s, void *dest)
{
  config *c = dest;
  int n = 0;
  if (strchr(s, ':')) {
    double a, b;
    long long cnt;
    char buf[128];
    if (strlen(s) >= sizeof buf) {
      fprintf(stderr, "%s: %s: sweep spec too long\n", prog, opt);
      return 0;
    }
    strcpy(buf, s);
    char *p1 = strchr(buf, ':'), *p2 = p1 ? strchr(p1 + 1, ':') : NULL;
    if (!p1 || !p2) {
      fprintf(stderr, "%s: %s: a sweep is A:B:N, got '%s'\n", prog, opt, s);
      return 0;
    }
    *p1 = *p2 = '\0';
    if (!cli_double(prog, opt, buf, 0.0, 1.0, CLI_LO_OPEN, &a) ||
        !cli_double(prog, opt, p1 + 1, 0.0, 1.0, CLI_LO_OPEN, &b) ||
        !cli_int(prog, opt, p2 + 1, 2, MAX_FRACTIONS, &cnt))
      return 0;
    n = (int)cnt;
    for (int k = 0; k < n; k++)
      c->fractions[k] = exp(log(a) + (log(b) - log(a)) * k / (n - 1));
    c->fractions[0] = a;
    c->fractions[n - 1] = b;
    for (int k = 1; k + 1 < n; k++) /* round decades exactly: 1e-3, not 0.0010000000000000002 */
      c->fractions[k] = strtod((snprintf(buf, sizeof buf, "%.12g", c->fractions[k]), buf), NULL);
  } else {
    char tok[MAX_FRACTIONS][CLI_TOKEN];
    if (!cli_list(prog, opt, s, tok, MAX_FRACTIONS, &n)) return 0;
    for (int k = 0; k < n; k++)
      if (!cli_double(prog, opt, tok[k], 0.0, 1.0, CLI_LO_OPEN, &c->fractions[k])) return 0;
  }
  c->num_fractions = n;
  return 1;
}

static int parse_elements(const char *prog, const char *opt, const char *s, void *dest)
{
  static const char *const names[] = {"tet4", "tet10", "hex8", "hex20", NULL};
  config *c = dest;
  char tok[4][CLI_TOKEN];
  int n = 0;
  if (!cli_list(prog, opt, s, tok, 4, &n)) return 0;
  for (int k = 0; k < n; k++)
    if (!cli_choice(prog, opt, tok[k], names, &(int){0}) ||
        fcm_element_type_from_name(tok[k], &c->elements[k]) != FCM_OK)
      return 0;
  c->num_elements = n;
  return 1;
}

static int parse_precs(const char *prog, const char *opt, const char *s, void *dest)
{
  static const char *const names[PREC_COUNT + 1] = {"none",          "jacobi", "schwarz",
                                                    "schwarz-paper", "exact",  NULL};
  config *c = dest;
  char tok[PREC_COUNT][CLI_TOKEN];
  int n = 0;
  if (!cli_list(prog, opt, s, tok, PREC_COUNT, &n)) return 0;
  for (int k = 0; k < n; k++)
    if (!cli_choice(prog, opt, tok[k], names, &c->precs[k])) return 0;
  c->num_precs = n;
  return 1;
}

static int parse_stabilization(const char *prog, const char *opt, const char *s, void *dest)
{
  static const char *const names[] = {"on", "off", NULL};
  config *c = dest;
  char tok[2][CLI_TOKEN];
  int n = 0, which = 0;
  if (!cli_list(prog, opt, s, tok, 2, &n)) return 0;
  c->stab_on = c->stab_off = 0;
  for (int k = 0; k < n; k++) {
    if (!cli_choice(prog, opt, tok[k], names, &which)) return 0;
    *(which == 0 ? &c->stab_on : &c->stab_off) = 1;
  }
  return 1;
}

static int parse_png(const char *prog, const char *opt, const char *s, void *dest)
{
  if (!*s || strpbrk(s, "'\"\\")) {
    fprintf(stderr, "%s: %s: the file name must be non-empty, without quotes or backslashes\n",
            prog, opt);
    return 0;
  }
  *(const char **)dest = s;
  return 1;
}

/* Options given on the command line (for the --quick defaults). */
typedef struct seen {
  int elements, fractions, simplify, minres;
} seen;

static const char *const on_off[] = {"off", "on", NULL};
static const char *const stab_modes[] = {"mass+stiffness", "mass", NULL};

#define NUM_OPTIONS 23
static void option_table(config *c, int *stab_mode, seen *g, cli_option t[NUM_OPTIONS])
{
  const cli_option o[NUM_OPTIONS] = {
      {"--elements", NULL, CLI_CUSTOM, c, "LIST",
       "comma list of tet4,tet10,hex8,hex20            (default all)", 0, 0, 0, NULL,
       parse_elements, &g->elements},
      {"--fractions", NULL, CLI_CUSTOM, c, "SPEC",
       "smallest volume fractions in (0,1]: a comma list\n"
       "(1,1e-4,1e-8) or a log sweep A:B:N             (default 1:1e-12:13)",
       0, 0, 0, NULL, parse_fractions, &g->fractions},
      {"--preconditioners", NULL, CLI_CUSTOM, c, "LIST",
       "comma list of none,jacobi,schwarz,schwarz-paper,\n"
       "exact                                          (default all but exact)\n"
       "schwarz: eigenvalues below eps*lambda_max become\n"
       "1/(eps lambda_max) (authors' code); schwarz-paper:\n"
       "eps/lambda_max (eq. 14 as printed); exact: S = P^-1\n"
       "(sparse Cholesky), the ideal preconditioner from P:\n"
       "kappa(P^-1 A) is the part of kappa(S A) that comes\n"
       "from A's indefiniteness and that no preconditioner\n"
       "built from P removes",
       0, 0, 0, NULL, parse_precs, NULL},
      {"--stabilization", NULL, CLI_CUSTOM, c, "LIST",
       "on,off                                         (default on,off)", 0, 0, 0, NULL,
       parse_stabilization, NULL},
      {"--alpha", NULL, CLI_DOUBLE, &c->alpha, "A",
       "stabilization weight factor, > 0               (default 1e-6)", 0, HUGE_VAL, CLI_LO_OPEN,
       NULL, NULL, NULL},
      {"--stab-mode", NULL, CLI_CHOICE, stab_mode, "MODE",
       "mass+stiffness | mass                          (default mass+stiffness)", 0, 0, 0,
       stab_modes, NULL, NULL},
      {"--theta", NULL, CLI_DOUBLE, &c->theta, "T",
       "Schwarz blocks on cut cells with phi < T, (0,1] (default 0.5)", 0, 1, CLI_LO_OPEN, NULL,
       NULL, NULL},
      {"--epsilon", NULL, CLI_DOUBLE, &c->epsilon, "E",
       "Schwarz eigenvalue threshold in (0,1)          (default 1e-13)", 0, 1,
       CLI_LO_OPEN | CLI_HI_OPEN, NULL, NULL, NULL},
      {"--simplify", NULL, CLI_CHOICE, &c->simplify, "on|off",
       "simplify cut-cell rules (at most M points)     (default on)", 0, 0, 0, on_off, NULL,
       &g->simplify},
      {"--stiffness-strength", NULL, CLI_INT, &c->stiffness_strength, "N",
       "strength of the stiffness rules in [1, 20]     (default the element's)\n"
       "(tet4 2, tet10 3, hex8 2, hex20 4)",
       1, 20, 0, NULL, NULL, NULL},
      {"--project", NULL, CLI_CHOICE, &c->project, "on|off",
       "PSD-project the material tangent               (default off)", 0, 0, 0, on_off, NULL, NULL},
      {"--fictitious", NULL, CLI_CHOICE, &c->fictitious, "MODEL",
       "tangent at the stabilization points: projected |\n"
       "linear | exact                                 (default projected)",
       0, 0, 0, tangent_model_names, NULL, NULL},
      {"--pc-tangent", NULL, CLI_CHOICE, &c->pc_tangent, "MODEL",
       "tangent the preconditioners are built from:\n"
       "projected (PSD-projected at u) | linear (linear\n"
       "elastic at rest) | exact (A itself); without\n"
       "effect with --project on                       (default projected)",
       0, 0, 0, tangent_model_names, NULL, NULL},
      {"--density", NULL, CLI_DOUBLE, &c->density, "RHO",
       "density in kg/m^3, > 0                         (default 1000)", 0, HUGE_VAL, CLI_LO_OPEN,
       NULL, NULL, NULL},
      {"--u-scale", NULL, CLI_DOUBLE, &c->u_scale, "S",
       "u(X) = S X (1,1,-1), |S| <= 10; 0: at rest     (default 1)", -10, 10, 0, NULL, NULL, NULL},
      {"--rtol", NULL, CLI_DOUBLE, &c->rtol, "R",
       "MINRES relative tolerance in (0,1)             (default 1e-8)", 0, 1,
       CLI_LO_OPEN | CLI_HI_OPEN, NULL, NULL, NULL},
      {"--minres-max", NULL, CLI_INT, &c->minres_max, "N",
       "MINRES iteration limit in [1, 1e7]             (default 5000)", 1, 1e7, 0, NULL, NULL,
       &g->minres},
      {"--csv", NULL, CLI_STRING, &c->csv, "FILE", "write the results as CSV (atomically)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--png", NULL, CLI_CUSTOM, &c->png, "FILE",
       "plot kappa against phi with gnuplot (2x2 panels: tets /\n"
       "hexes, with / without stabilization); without gnuplot a\n"
       "message is printed and the CSV is still written",
       0, 0, 0, NULL, parse_png, NULL},
      {"--quick", NULL, CLI_FLAG, &c->quick, NULL,
       "reduced study: tet4,hex8, phi in {1, 1e-8}, no\n"
       "simplification, MINRES limit 1000 (a few seconds; explicit\n"
       "options override these)",
       0, 0, 0, NULL, NULL, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  memcpy(t, o, sizeof o);
}

static void usage(FILE *f, const cli_option *opts)
{
  fprintf(f,
          "usage: " PROG " [options]\n"
          "\n"
          "Condition numbers kappa(S A) of A = M + dt^2 K(u) for the embedded-box experiment of\n"
          "Longva et al. 2020, Fig. 5: a 4x4x4 grid on [0,4/3]^3, the box [0,1+eps/3]^3 embedded,\n"
          "smallest volume fraction phi = eps^3; Stable Neo-Hookean E = 3e6, nu = 0.4,\n"
          "u(X) = X (1,1,-1), u = 0 on X = 0 (eliminated), dt = 1/60. Dense eigenvalues of\n"
          "S^(1/2) A S^(1/2); kappa = max|lambda| / min|lambda| (A may be indefinite). Values\n"
          "above ~1e13 are at the resolution of double precision (rounding-level eigenvalues).\n"
          "MINRES (x0 = 0, b = A 1, rtol on the preconditioned residual; unpreconditioned for\n"
          "'none') is run on each system. The preconditioners are built from\n"
          "P = M + dt^2 K_pc (--pc-tangent; the library's default, fcm_integrator_options.\n"
          "preconditioner_tangent): A stays the Krylov operator.\n"
          "\n"
          "options:\n");
  cli_print_options(f, opts);
  fprintf(
      f, "\n"
         "CSV columns: element,preconditioner,stabilization,min_volume_fraction,condition_number,\n"
         "  then nominal_fraction,lambda_min_abs,lambda_max_abs,negative_eigenvalues,dofs,\n"
         "  schwarz_blocks,clamped_eigenvalues,minres_iterations,minres_reason,\n"
         "  minres_true_residual,tangent,fictitious,preconditioner_tangent. stabilization is\n"
         "  the weight factor alpha (0 = off); tangent projected|unprojected (--project);\n"
         "  min_volume_fraction the measured smallest phi of the non-empty cells.\n"
         "stdout: kappa and MINRES tables; stderr: progress. Exit 0 on success, 1 on a\n"
         "computation or output error, 2 on a usage error.\n");
}

/* -1 when the arguments are parsed into `c`, else the exit code (0 after --help, 2). */
static int parse_args(int argc, char **argv, config *c)
{
  seen g = {0, 0, 0, 0};
  int mode = c->stab_mode == FCM_STABILIZATION_MASS ? 1 : 0;
  cli_option opts[NUM_OPTIONS];
  option_table(c, &mode, &g, opts);
  const int rc = cli_parse_args(PROG, opts, argc, argv, NULL, 0, NULL, usage);
  if (rc >= 0) return rc;
  c->stab_mode = mode == 1 ? FCM_STABILIZATION_MASS : FCM_STABILIZATION_MASS_STIFFNESS;
  if (c->quick) {
    if (!g.elements) {
      c->elements[0] = FCM_ELEMENT_TET4;
      c->elements[1] = FCM_ELEMENT_HEX8;
      c->num_elements = 2;
    }
    if (!g.fractions) {
      c->fractions[0] = 1.0;
      c->fractions[1] = 1e-8;
      c->num_fractions = 2;
    }
    if (!g.simplify) c->simplify = 0;
    if (!g.minres) c->minres_max = 1000;
  }
  for (int k = 0; k < c->num_precs; k++)
    if (c->precs[k] == PREC_EXACT && c->pc_tangent == FCM_FICTITIOUS_EXACT && !c->project) {
      fprintf(stderr, PROG ": --preconditioners exact factors P by Cholesky; with --pc-tangent "
                           "exact and --project off P = A is indefinite (use --pc-tangent "
                           "projected or linear, or --project on)\n");
      return 2;
    }
  return -1;
}

/* ---------------------------------------------------------------- main */

int main(int argc, char **argv)
{
  app_env_init(argc, argv);    /* OpenMP waiting, the CPU's BLAS kernels, huge pages (app_env.h) */
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  config c;
  memset(&c, 0, sizeof c);
  for (int e = 0; e < 4; e++)
    c.elements[e] = (fcm_element_type)e;
  c.num_elements = 4;
  c.num_precs = PREC_DEFAULT_COUNT;
  for (int p = 0; p < PREC_DEFAULT_COUNT; p++)
    c.precs[p] = p;
  c.stab_on = c.stab_off = 1;
  c.alpha = 1e-6;
  c.stab_mode = FCM_STABILIZATION_MASS_STIFFNESS;
  c.theta = 0.5;
  c.epsilon = 1e-13;
  c.simplify = 1;
  c.stiffness_strength = FCM_DEFAULT;
  c.density = 1000.0;
  c.young = 3e6;
  c.poisson = 0.4;
  c.dt = 1.0 / 60.0;
  c.rtol = 1e-8;
  c.u_scale = 1.0;
  c.fictitious = FCM_FICTITIOUS_PROJECTED;
  c.pc_tangent = FCM_FICTITIOUS_PROJECTED;
  c.minres_max = 5000;
  if (!parse_fractions(PROG, "--fractions", "1:1e-12:13", &c)) return 2;
  const int parsed = parse_args(argc, argv, &c);
  if (parsed >= 0) return parsed;
  for (int e = 0; e < c.num_elements; e++)
    if (!fcm_element_get_info(c.elements[e])) return 2;

  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  result *res = NULL;
  int nres = 0, rc = 0;
  fcm_status st = fcm_ctx_create(NULL, &ctx);
  if (st != FCM_OK) {
    fprintf(stderr, PROG ": cannot create a context: %s\n", fcm_status_name(st));
    return 1;
  }
  res = calloc((size_t)(c.num_elements * c.num_fractions * 2 * c.num_precs), sizeof *res);
  if (!res) {
    fprintf(stderr, PROG ": out of memory\n");
    fcm_ctx_destroy(&ctx);
    return 1;
  }
  char strength[16] = "default";
  if (c.stiffness_strength != FCM_DEFAULT)
    snprintf(strength, sizeof strength, "%d", c.stiffness_strength);
  fprintf(stderr,
          PROG ": %d element(s) x %d fraction(s) x %d stabilization setting(s) x %d "
               "preconditioner(s); simplification %s, stiffness strength %s, alpha %g, theta %g, "
               "epsilon %g, %s tangent, u = %g X (1,1,-1)\n",
          c.num_elements, c.num_fractions, c.stab_on + c.stab_off, c.num_precs,
          c.simplify ? "on" : "off", strength, c.alpha, c.theta, c.epsilon,
          c.project ? "projected" : "unprojected", c.u_scale);
  const double t0 = fcm_wtime();
  for (int e = 0; e < c.num_elements && st == FCM_OK; e++) {
    const double lo[3] = {0, 0, 0}, hi[3] = {4.0 / 3, 4.0 / 3, 4.0 / 3};
    const fcm_index n4[3] = {4, 4, 4};
    st = fcm_mesh_create_box(ctx, c.elements[e], lo, hi, n4, &mesh);
    for (int f = 0; f < c.num_fractions && st == FCM_OK; f++)
      for (int sb = 0; sb < 2 && st == FCM_OK; sb++)
        if (sb == 0 ? c.stab_on : c.stab_off)
          st = condition_run_case(ctx, &c, mesh, c.fractions[f], sb == 0 ? c.alpha : 0.0, res,
                                  &nres);
    fcm_mesh_destroy(&mesh);
  }
  if (st != FCM_OK) {
    fprintf(stderr, PROG ": failed: %s\n", fcm_status_name(st));
    fcm_ctx_error_view(ctx, stderr);
    rc = 1;
  } else {
    fprintf(stderr, PROG ": %d results in %.1f s\n", nres, fcm_wtime() - t0);
    condition_print_tables(&c, res, nres);
    if (c.csv && !condition_write_csv(c.csv, &c, res, nres)) rc = 1;
    if (c.png && !condition_write_png(&c, c.png, res, nres)) rc = 1;
  }
  free(res);
  fcm_ctx_destroy(&ctx);
  return rc;
}
