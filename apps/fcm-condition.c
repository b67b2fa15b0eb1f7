/* fcm-condition: the conditioning study of Longva et al. 2020, §5.4 / Fig. 5 (DESIGN §7):
 * kappa(S A) of a backward-Euler step A = M + dt^2 K(u) on a 4x4x4 grid of [0, 4/3]^3 with
 * the box [0, 1 + eps/3]^3 embedded, for S in {none, Jacobi, Schwarz (clamp and as printed)}
 * with and without quadrature stabilization, plus MINRES iteration counts on the same systems.
 *
 * Setup (paper §5.4): cell size 1/3; the box reaches eps/3 into the last layer, so the corner
 * cell keeps the volume (eps/3)^3 and the smallest volume fraction is phi = eps^3 (the swept
 * quantity; eps = phi^(1/3)). Stable Neo-Hookean E = 3e6 Pa, nu = 0.4; u(X) = X_1 (1, 1, -1),
 * which vanishes on the clamped face X_1 = 0; dt = 1/60; K is the unprojected tangent at u
 * (possibly indefinite, then kappa = max|lambda| / min|lambda|). The clamped DOFs are
 * eliminated (removed), and every preconditioner is built on the reduced matrix. */
#include "fcm-condition-study.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- options */

static void usage(FILE *f)
{
  fprintf(
      f,
      "usage: " PROG " [options]\n"
      "\n"
      "Condition numbers kappa(S A) of A = M + dt^2 K(u) for the embedded-box experiment of\n"
      "Longva et al. 2020, Fig. 5: a 4x4x4 grid on [0,4/3]^3, the box [0,1+eps/3]^3 embedded,\n"
      "smallest volume fraction phi = eps^3; Stable Neo-Hookean E = 3e6, nu = 0.4,\n"
      "u(X) = X (1,1,-1), u = 0 on X = 0 (eliminated), dt = 1/60. Dense eigenvalues of\n"
      "S^(1/2) A S^(1/2); kappa = max|lambda| / min|lambda| (A may be indefinite). Values\n"
      "above ~1e13 are at the resolution of double precision (rounding-level eigenvalues).\n"
      "MINRES (x0 = 0, b = A 1, rtol on the preconditioned residual; unpreconditioned for\n"
      "'none') is run on each system.\n"
      "\n"
      "options:\n"
      "  --elements LIST        comma list of tet4,tet10,hex8,hex20      (default all)\n"
      "  --fractions SPEC       smallest volume fractions in (0,1]: a comma list\n"
      "                         (1,1e-4,1e-8) or a log sweep A:B:N       (default 1:1e-12:13)\n"
      "  --preconditioners LIST none,jacobi,schwarz,schwarz-paper     (default all)\n"
      "                         schwarz: eigenvalues below eps*lambda_max become\n"
      "                         1/(eps lambda_max) (authors' code); schwarz-paper:\n"
      "                         eps/lambda_max (eq. 14 as printed)\n"
      "  --stabilization LIST   on,off                                   (default on,off)\n"
      "  --alpha A              stabilization weight factor, > 0         (default 1e-6)\n"
      "  --stab-mode MODE       mass+stiffness | mass                    (default mass+stiffness)\n"
      "  --theta T              Schwarz blocks on cut cells with phi < T (default 0.5)\n"
      "  --epsilon E            Schwarz eigenvalue threshold in (0,1)    (default 1e-13)\n"
      "  --simplify on|off      simplify cut-cell rules (LP)             (default on)\n"
      "  --project on|off       PSD-project the material tangent         (default off)\n"
      "  --density RHO          density in kg/m^3, > 0                   (default 1000)\n"
      "  --u-scale S            u(X) = S X (1,1,-1); 0: linearization at rest (default 1)\n"
      "  --rtol R               MINRES relative tolerance                (default 1e-8)\n"
      "  --minres-max N         MINRES iteration limit                   (default 5000)\n"
      "  --csv FILE             write the results as CSV (atomically: FILE.tmp, rename)\n"
      "  --png FILE             plot kappa against phi with gnuplot (2x2 panels: tets /\n"
      "                         hexes, with / without stabilization); without gnuplot a\n"
      "                         message is printed and the CSV is still written\n"
      "  --quick                reduced study: tet4,hex8, phi in {1, 1e-8}, no\n"
      "                         simplification, MINRES limit 1000 (a few seconds; explicit\n"
      "                         options override these)\n"
      "  -h, --help             this text\n"
      "\n"
      "CSV columns: element,preconditioner,stabilization,min_volume_fraction,condition_number,\n"
      "  then nominal_fraction,lambda_min_abs,lambda_max_abs,negative_eigenvalues,dofs,\n"
      "  schwarz_blocks,clamped_eigenvalues,minres_iterations,minres_reason,\n"
      "  minres_true_residual,tangent. stabilization is the weight factor alpha (0 = off);\n"
      "  min_volume_fraction the measured smallest phi of the non-empty cells.\n"
      "stdout: kappa and MINRES tables; stderr: progress. Exit 0 on success, 1 on a\n"
      "computation or output error, 2 on a usage error.\n");
}

static int parse_double(const char *opt, const char *s, double *out)
{
  char *end = NULL;
  errno = 0;
  double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v)) {
    fprintf(stderr, PROG ": %s: '%s' is not a finite number\n", opt, s);
    return 0;
  }
  *out = v;
  return 1;
}

/* Split a comma list into at most `cap` tokens of at most 31 characters. */
static int split_list(const char *opt, const char *s, char tok[][32], int cap, int *n)
{
  *n = 0;
  while (*s) {
    const char *c = strchr(s, ',');
    size_t len = c ? (size_t)(c - s) : strlen(s);
    if (len == 0 || len > 31 || *n >= cap) {
      fprintf(stderr,
              PROG ": %s: malformed list (empty item, item too long or more than %d items)\n", opt,
              cap);
      return 0;
    }
    memcpy(tok[*n], s, len);
    tok[*n][len] = '\0';
    (*n)++;
    s += len + (c ? 1 : 0);
    if (c && !*s) {
      fprintf(stderr, PROG ": %s: trailing comma\n", opt);
      return 0;
    }
  }
  if (*n == 0) fprintf(stderr, PROG ": %s: empty list\n", opt);
  return *n > 0;
}

static int parse_fractions(const char *s, config *c)
{
  char tok[MAX_FRACTIONS][32];
  int n = 0;
  if (strchr(s, ':')) {
    double a, b, cnt;
    char buf[128];
    if (strlen(s) >= sizeof buf) {
      fprintf(stderr, PROG ": --fractions: sweep spec too long\n");
      return 0;
    }
    strcpy(buf, s);
    char *p1 = strchr(buf, ':'), *p2 = p1 ? strchr(p1 + 1, ':') : NULL;
    if (!p1 || !p2) {
      fprintf(stderr, PROG ": --fractions: a sweep is A:B:N, got '%s'\n", s);
      return 0;
    }
    *p1 = *p2 = '\0';
    if (!parse_double("--fractions", buf, &a) || !parse_double("--fractions", p1 + 1, &b) ||
        !parse_double("--fractions", p2 + 1, &cnt))
      return 0;
    if (!(cnt >= 2 && cnt <= MAX_FRACTIONS && cnt == floor(cnt))) {
      fprintf(stderr, PROG ": --fractions: N = %g must be an integer in [2, %d]\n", cnt,
              MAX_FRACTIONS);
      return 0;
    }
    n = (int)cnt;
    for (int k = 0; k < n; k++)
      c->fractions[k] = exp(log(a) + (log(b) - log(a)) * k / (n - 1));
    c->fractions[0] = a;
    c->fractions[n - 1] = b;
    for (int k = 1; k + 1 < n; k++) /* round decades exactly: 1e-3, not 0.0010000000000000002 */
      c->fractions[k] = strtod((snprintf(buf, sizeof buf, "%.12g", c->fractions[k]), buf), NULL);
  } else {
    if (!split_list("--fractions", s, tok, MAX_FRACTIONS, &n)) return 0;
    for (int k = 0; k < n; k++)
      if (!parse_double("--fractions", tok[k], &c->fractions[k])) return 0;
  }
  for (int k = 0; k < n; k++)
    if (!(c->fractions[k] > 0.0 && c->fractions[k] <= 1.0)) {
      fprintf(stderr, PROG ": --fractions: %g is outside (0, 1]\n", c->fractions[k]);
      return 0;
    }
  c->num_fractions = n;
  return 1;
}

static int parse_args(int argc, char **argv, config *c)
{
  int have_el = 0, have_frac = 0, have_simplify = 0, have_minres = 0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      usage(stdout);
      exit(0);
    }
    if (!strcmp(a, "--quick")) {
      c->quick = 1;
      continue;
    }
    if (a[0] != '-' || a[1] != '-') {
      fprintf(stderr, PROG ": unexpected argument '%s' (see --help)\n", a);
      return 0;
    }
    if (i + 1 >= argc) {
      fprintf(stderr, PROG ": %s needs a value (see --help)\n", a);
      return 0;
    }
    const char *v = argv[++i];
    char tok[8][32];
    int n = 0;
    if (!strcmp(a, "--elements")) {
      if (!split_list(a, v, tok, 4, &n)) return 0;
      for (int k = 0; k < n; k++)
        if (fcm_element_type_from_name(tok[k], &c->elements[k]) != FCM_OK) {
          fprintf(stderr, PROG ": --elements: unknown element '%s' (tet4, tet10, hex8, hex20)\n",
                  tok[k]);
          return 0;
        }
      c->num_elements = n;
      have_el = 1;
    } else if (!strcmp(a, "--fractions")) {
      if (!parse_fractions(v, c)) return 0;
      have_frac = 1;
    } else if (!strcmp(a, "--preconditioners")) {
      if (!split_list(a, v, tok, PREC_COUNT, &n)) return 0;
      for (int k = 0; k < n; k++) {
        int p = 0;
        while (p < PREC_COUNT && strcmp(tok[k], prec_names[p]))
          p++;
        if (p == PREC_COUNT) {
          fprintf(stderr,
                  PROG ": --preconditioners: unknown '%s' (none, jacobi, schwarz, schwarz-paper)\n",
                  tok[k]);
          return 0;
        }
        c->precs[k] = p;
      }
      c->num_precs = n;
    } else if (!strcmp(a, "--stabilization")) {
      if (!split_list(a, v, tok, 2, &n)) return 0;
      c->stab_on = c->stab_off = 0;
      for (int k = 0; k < n; k++) {
        if (!strcmp(tok[k], "on"))
          c->stab_on = 1;
        else if (!strcmp(tok[k], "off"))
          c->stab_off = 1;
        else {
          fprintf(stderr, PROG ": --stabilization: '%s' is not on or off\n", tok[k]);
          return 0;
        }
      }
    } else if (!strcmp(a, "--stab-mode")) {
      if (!strcmp(v, "mass+stiffness"))
        c->stab_mode = FCM_STABILIZATION_MASS_STIFFNESS;
      else if (!strcmp(v, "mass"))
        c->stab_mode = FCM_STABILIZATION_MASS;
      else {
        fprintf(stderr, PROG ": --stab-mode: '%s' is not mass+stiffness or mass\n", v);
        return 0;
      }
    } else if (!strcmp(a, "--simplify")) {
      if (strcmp(v, "on") && strcmp(v, "off")) {
        fprintf(stderr, PROG ": --simplify: '%s' is not on or off\n", v);
        return 0;
      }
      c->simplify = !strcmp(v, "on");
      have_simplify = 1;
    } else if (!strcmp(a, "--project")) {
      if (strcmp(v, "on") && strcmp(v, "off")) {
        fprintf(stderr, PROG ": --project: '%s' is not on or off\n", v);
        return 0;
      }
      c->project = !strcmp(v, "on");
    } else if (!strcmp(a, "--minres-max")) {
      double m;
      if (!parse_double(a, v, &m)) return 0;
      if (!(m >= 1 && m <= 1e7 && m == floor(m))) {
        fprintf(stderr, PROG ": --minres-max: %g must be an integer in [1, 1e7]\n", m);
        return 0;
      }
      c->minres_max = (int)m;
      have_minres = 1;
    } else if (!strcmp(a, "--csv")) {
      c->csv = v;
    } else if (!strcmp(a, "--png")) {
      if (strchr(v, '\'') || strchr(v, '"') || strchr(v, '\\')) {
        fprintf(stderr, PROG ": --png: the file name must not contain quotes or backslashes\n");
        return 0;
      }
      c->png = v;
    } else {
      double x;
      double *dst = !strcmp(a, "--alpha")     ? &c->alpha
                    : !strcmp(a, "--theta")   ? &c->theta
                    : !strcmp(a, "--epsilon") ? &c->epsilon
                    : !strcmp(a, "--density") ? &c->density
                    : !strcmp(a, "--rtol")    ? &c->rtol
                    : !strcmp(a, "--u-scale") ? &c->u_scale
                                              : NULL;
      if (!dst) {
        fprintf(stderr, PROG ": unknown option '%s' (see --help)\n", a);
        return 0;
      }
      if (!parse_double(a, v, &x)) return 0;
      int ok = dst == &c->alpha     ? x > 0.0
               : dst == &c->theta   ? x > 0.0 && x <= 1.0
               : dst == &c->epsilon ? x > 0.0 && x < 1.0
               : dst == &c->density ? x > 0.0
               : dst == &c->u_scale ? fabs(x) <= 10.0
                                    : x > 0.0 && x < 1.0;
      if (!ok) {
        fprintf(stderr, PROG ": %s: %g is out of range (see --help)\n", a, x);
        return 0;
      }
      *dst = x;
    }
  }
  if (c->quick) {
    if (!have_el) {
      c->elements[0] = FCM_ELEMENT_TET4;
      c->elements[1] = FCM_ELEMENT_HEX8;
      c->num_elements = 2;
    }
    if (!have_frac) {
      c->fractions[0] = 1.0;
      c->fractions[1] = 1e-8;
      c->num_fractions = 2;
    }
    if (!have_simplify) c->simplify = 0;
    if (!have_minres) c->minres_max = 1000;
  }
  return 1;
}

/* ---------------------------------------------------------------- main */

int main(int argc, char **argv)
{
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  config c;
  memset(&c, 0, sizeof c);
  for (int e = 0; e < 4; e++)
    c.elements[e] = (fcm_element_type)e;
  c.num_elements = 4;
  c.num_precs = PREC_COUNT;
  for (int p = 0; p < PREC_COUNT; p++)
    c.precs[p] = p;
  c.stab_on = c.stab_off = 1;
  c.alpha = 1e-6;
  c.stab_mode = FCM_STABILIZATION_MASS_STIFFNESS;
  c.theta = 0.5;
  c.epsilon = 1e-13;
  c.simplify = 1;
  c.density = 1000.0;
  c.young = 3e6;
  c.poisson = 0.4;
  c.dt = 1.0 / 60.0;
  c.rtol = 1e-8;
  c.u_scale = 1.0;
  c.minres_max = 5000;
  if (!parse_fractions("1:1e-12:13", &c)) return 2;
  if (!parse_args(argc, argv, &c)) return 2;
  for (int e = 0; e < c.num_elements; e++)
    if (!fcm_element_get_info(c.elements[e])) return 2;

  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  result *res = NULL;
  int nres = 0, rc = 0;
  fcm_status st = fcm_ctx_create(NULL, &ctx);
  if (st != FCM_OK) {
    fprintf(stderr, PROG ": cannot create a context: %s\n", fcm_status_str(st));
    return 1;
  }
  res = calloc((size_t)(c.num_elements * c.num_fractions * 2 * c.num_precs), sizeof *res);
  if (!res) {
    fprintf(stderr, PROG ": out of memory\n");
    fcm_ctx_destroy(&ctx);
    return 1;
  }
  fprintf(stderr,
          PROG ": %d element(s) x %d fraction(s) x %d stabilization setting(s) x %d "
               "preconditioner(s); simplification %s, alpha %g, theta %g, epsilon %g, %s tangent, "
               "u = %g X (1,1,-1)\n",
          c.num_elements, c.num_fractions, c.stab_on + c.stab_off, c.num_precs,
          c.simplify ? "on" : "off", c.alpha, c.theta, c.epsilon,
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
    fprintf(stderr, PROG ": failed: %s\n", fcm_status_str(st));
    fcm_ctx_error_view(ctx, stderr);
    rc = 1;
  } else {
    fprintf(stderr, PROG ": %d results in %.1f s\n", nres, fcm_wtime() - t0);
    condition_print_tables(&c, res, nres);
    if (c.csv && !condition_write_csv(c.csv, res, nres, c.project)) rc = 1;
    if (c.png && !condition_write_png(&c, c.png, res, nres)) rc = 1;
  }
  free(res);
  fcm_ctx_destroy(&ctx);
  return rc;
}
