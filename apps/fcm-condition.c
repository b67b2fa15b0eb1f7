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
#include <fcm/core.h>
#include <fcm/dense.h>
#include <fcm/element.h>
#include <fcm/embed.h>
#include <fcm/fem.h>
#include <fcm/geom.h>
#include <fcm/la.h>
#include <fcm/material.h>
#include <fcm/mesh.h>
#include <fcm/solve.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PROG "fcm-condition"
#define MAX_FRACTIONS 64

/* ---------------------------------------------------------------- options */

enum { PREC_NONE, PREC_JACOBI, PREC_SCHWARZ, PREC_SCHWARZ_PAPER, PREC_COUNT };
static const char *const prec_names[PREC_COUNT] = {"none", "jacobi", "schwarz", "schwarz-paper"};

typedef struct config {
  fcm_element_type elements[4];
  int num_elements;
  double fractions[MAX_FRACTIONS];
  int num_fractions;
  int precs[PREC_COUNT];
  int num_precs;
  int stab_on, stab_off; /* which stabilization settings to run */
  double alpha;          /* stabilization weight factor when on */
  fcm_stabilization_mode stab_mode;
  double theta;   /* Schwarz: cut cells with phi < theta get a block */
  double epsilon; /* Schwarz eigenvalue threshold */
  int simplify;
  int project; /* 1: PSD-projected material tangent */
  double density, young, poisson, dt;
  double u_scale; /* u(X) = u_scale X_1 (1, 1, -1) */
  double rtol;
  int minres_max;
  const char *csv, *png;
  int quick;
} config;

typedef struct result {
  fcm_element_type element;
  int prec;
  double alpha; /* 0: no stabilization */
  double phi_nominal, phi_min;
  double kappa, lmin_abs, lmax_abs;
  fcm_index negative;
  fcm_index dofs;
  fcm_index blocks, clamped;
  int iterations;
  fcm_krylov_reason reason;
  double true_residual;
} result;

static void usage(FILE *f)
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
      fprintf(stderr, PROG ": %s: malformed list (empty item, item too long or more than %d items)\n",
              opt, cap);
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
        while (p < PREC_COUNT && strcmp(tok[k], prec_names[p])) p++;
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

/* ---------------------------------------------------------------- one system */

/* The reduced system of one (element, fraction, stabilization) case. */
typedef struct linsys {
  fcm_mesh *mesh; /* borrowed */
  fcm_geometry *geom;
  fcm_cell_rules *rules;
  fcm_space *space;
  fcm_csr *A;   /* full M + dt^2 K */
  fcm_csr *Af;  /* reduced to the free DOFs */
  fcm_index *map; /* full DOF -> reduced index, or -1 */
  fcm_index n;    /* reduced size */
  double phi_min;
} linsys;

static void system_free(linsys *s)
{
  fcm_csr_destroy(&s->Af);
  fcm_csr_destroy(&s->A);
  fcm_space_destroy(&s->space);
  fcm_cell_rules_destroy(&s->rules);
  fcm_geometry_destroy(&s->geom);
  free(s->map);
  s->map = NULL;
}

#define TRY(call)                                                                                  \
  do {                                                                                             \
    st = (call);                                                                                   \
    if (st != FCM_OK) goto done;                                                                   \
  } while (0)

static fcm_status alloc_fail(fcm_ctx *ctx)
{
  (void)ctx;
  fprintf(stderr, PROG ": out of memory\n");
  return FCM_ERR_ALLOC;
}

/* Build rules, space, A = M + dt^2 K(u) and the reduced matrix. */
static fcm_status system_build(fcm_ctx *ctx, const config *c, fcm_mesh *mesh, double phi,
                               double alpha, linsys *s, double *t_rules)
{
  fcm_status st = FCM_OK;
  fcm_csr *K = NULL;
  double *u = NULL;
  fcm_index *fixed = NULL, *rp = NULL;
  int *ci = NULL;
  memset(s, 0, sizeof *s);
  s->mesh = mesh;
  const double eps = cbrt(phi);
  const double lo[3] = {0, 0, 0}, hi[3] = {1 + eps / 3, 1 + eps / 3, 1 + eps / 3};
  const fcm_index one[3] = {1, 1, 1};
  TRY(fcm_geometry_create_box(ctx, lo, hi, one, &s->geom));

  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.min_fraction = 0.0;  /* keep every non-empty cell, however small */
  ro.sliver_rtol = 1e-20; /* the corner pieces have ~phi/24 of the cell volume */
  ro.simplify = c->simplify;
  ro.stabilization.mode = alpha > 0.0 ? c->stab_mode : FCM_STABILIZATION_OFF;
  if (alpha > 0.0) ro.stabilization.alpha = alpha;
  double t0 = fcm_wtime();
  TRY(fcm_cell_rules_create(ctx, mesh, s->geom, &ro, &s->rules));
  *t_rules = fcm_wtime() - t0;
  TRY(fcm_space_create_embedded(ctx, mesh, s->rules, &s->space));

  const fcm_index nc = fcm_mesh_num_cells(mesh);
  s->phi_min = 1.0;
  for (fcm_index k = 0; k < nc; k++) {
    double f = fcm_cell_rules_volume_fraction(s->rules, k);
    if (f > 0.0 && f < s->phi_min) s->phi_min = f;
  }

  /* u(X) = X_1 (1, 1, -1) at the nodes */
  const fcm_index nd = fcm_space_num_dofs(s->space), nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  if (!(u = calloc((size_t)nd, sizeof *u))) {
    st = alloc_fail(ctx);
    goto done;
  }
  for (fcm_index a = 0; a < nn; a++) {
    fcm_index d = fcm_space_node_dof(s->space, a);
    if (d < 0) continue;
    u[d] = c->u_scale * X[3 * a];
    u[d + 1] = c->u_scale * X[3 * a];
    u[d + 2] = -c->u_scale * X[3 * a];
  }
  fcm_material m = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, c->young, c->poisson, c->density};
  fcm_material_params mp;
  TRY(fcm_material_setup(ctx, &m, &mp));
  mp.project_psd = c->project; /* default 0: the unprojected tangent */
  fcm_material el = {FCM_MATERIAL_LINEAR, c->young, c->poisson, c->density};
  TRY(fcm_space_matrix_create(s->space, &s->A));
  TRY(fcm_space_matrix_create(s->space, &K));
  TRY(fcm_assemble_mass(s->space, &el, NULL, s->A));
  TRY(fcm_assemble_hyperelastic(s->space, &mp, u, NULL, NULL, NULL, K));
  fcm_index nnz;
  fcm_csr_get_size(s->A, NULL, NULL, &nnz);
  double *av = fcm_csr_values(s->A);
  const double *kv = fcm_csr_values(K);
  for (fcm_index p = 0; p < nnz; p++)
    av[p] += c->dt * c->dt * kv[p];

  /* eliminate the DOFs of the nodes on X = 0 */
  const double plo[3] = {0, -HUGE_VAL, -HUGE_VAL}, phi_[3] = {0, HUGE_VAL, HUGE_VAL};
  fcm_index nfix = 0;
  TRY(fcm_mesh_nodes_in_box(ctx, mesh, plo, phi_, 1e-12, 0, NULL, &nfix));
  if (!(fixed = malloc(sizeof *fixed * (size_t)(nfix + 1))) ||
      !(s->map = malloc(sizeof *s->map * (size_t)nd))) {
    st = alloc_fail(ctx);
    goto done;
  }
  TRY(fcm_mesh_nodes_in_box(ctx, mesh, plo, phi_, 1e-12, nfix, fixed, &nfix));
  for (fcm_index i = 0; i < nd; i++) s->map[i] = 0;
  for (fcm_index k = 0; k < nfix; k++) {
    fcm_index d = fcm_space_node_dof(s->space, fixed[k]);
    if (d >= 0) s->map[d] = s->map[d + 1] = s->map[d + 2] = -1;
  }
  s->n = 0;
  for (fcm_index i = 0; i < nd; i++)
    s->map[i] = s->map[i] < 0 ? -1 : s->n++;
  const fcm_index *arp = fcm_csr_row_ptr(s->A);
  const int *aci = fcm_csr_col_idx(s->A);
  if (!(rp = malloc(sizeof *rp * (size_t)(s->n + 1))) ||
      !(ci = malloc(sizeof *ci * (size_t)nnz))) {
    st = alloc_fail(ctx);
    goto done;
  }
  fcm_index q = 0;
  rp[0] = 0;
  for (fcm_index i = 0; i < nd; i++) {
    if (s->map[i] < 0) continue;
    for (fcm_index p = arp[i]; p < arp[i + 1]; p++)
      if (s->map[aci[p]] >= 0) ci[q++] = (int)s->map[aci[p]];
    rp[s->map[i] + 1] = q;
  }
  TRY(fcm_csr_create(ctx, s->n, s->n, rp, ci, FCM_CSR_SYMMETRIC, &s->Af));
  double *fv = fcm_csr_values(s->Af);
  q = 0;
  for (fcm_index i = 0; i < nd; i++) {
    if (s->map[i] < 0) continue;
    for (fcm_index p = arp[i]; p < arp[i + 1]; p++)
      if (s->map[aci[p]] >= 0) fv[q++] = av[p];
  }
done:
  fcm_csr_destroy(&K);
  free(u);
  free(fixed);
  free(rp);
  free(ci);
  return st;
}

/* Schwarz on the reduced matrix: one block per cut cell with phi < theta, holding the free
 * DOFs of its nodes. */
static fcm_status schwarz_build(fcm_ctx *ctx, const config *c, const linsys *s,
                                fcm_schwarz_clamp clamp, fcm_schwarz **P)
{
  fcm_status st = FCM_OK;
  const fcm_index nc = fcm_mesh_num_cells(s->mesh);
  const int npc = fcm_mesh_nodes_per_cell(s->mesh);
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  fcm_index *ptr = malloc(sizeof *ptr * (size_t)(nc + 1)),
            *dofs = malloc(sizeof *dofs * (size_t)(nc * 3 * npc + 1));
  fcm_index nb = 0, q = 0;
  if (!ptr || !dofs) {
    st = alloc_fail(ctx);
    goto done;
  }
  ptr[0] = 0;
  for (fcm_index k = 0; k < nc; k++) {
    if (fcm_cell_rules_class(s->rules, k) != FCM_CELL_CUT ||
        !(fcm_cell_rules_volume_fraction(s->rules, k) < c->theta))
      continue;
    fcm_index q0 = q;
    for (int a = 0; a < npc; a++) {
      fcm_index d = fcm_space_node_dof(s->space, cells[k * npc + a]);
      for (int i = 0; d >= 0 && i < 3; i++)
        if (s->map[d + i] >= 0) dofs[q++] = s->map[d + i];
    }
    if (q > q0) ptr[++nb] = q;
  }
  fcm_schwarz_options so = fcm_schwarz_options_default();
  so.epsilon = c->epsilon;
  so.clamp = clamp;
  TRY(fcm_schwarz_create(ctx, s->Af, nb, ptr, dofs, &so, P));
done:
  free(ptr);
  free(dofs);
  return st;
}

/* kappa of S A for one preconditioner, and a MINRES solve of A x = A 1. */
static fcm_status measure(fcm_ctx *ctx, const config *c, const linsys *s, int prec,
                          const double *Ad, double *Sd, double *Bd, double *w, result *r)
{
  fcm_status st = FCM_OK;
  fcm_jacobi *J = NULL;
  fcm_schwarz *P = NULL;
  fcm_krylov *ws = NULL;
  double *e = NULL, *b = NULL, *x = NULL;
  const fcm_index n = s->n;
  const size_t nn = (size_t)n * (size_t)n;
  int ni = (int)n;
  fcm_operator_fn Sop = NULL;
  void *Suser = NULL;
  r->blocks = r->clamped = 0;
  if (prec == PREC_JACOBI) {
    TRY(fcm_jacobi_create(ctx, s->Af, FCM_JACOBI_SCALAR, &J));
    Sop = fcm_jacobi_operator;
    Suser = J;
  } else if (prec == PREC_SCHWARZ || prec == PREC_SCHWARZ_PAPER) {
    TRY(schwarz_build(ctx, c, s,
                      prec == PREC_SCHWARZ ? FCM_SCHWARZ_CLAMP : FCM_SCHWARZ_PAPER, &P));
    fcm_schwarz_info si;
    fcm_schwarz_get_info(P, &si);
    r->blocks = si.num_blocks;
    r->clamped = si.clamped_eigenvalues;
    Sop = fcm_schwarz_operator;
    Suser = P;
  }

  /* spectrum */
  if (!Sop) {
    TRY(fcm_dense_spectrum_eval(ctx, ni, Ad, NULL, w, NULL));
  } else {
    if (!(e = calloc((size_t)n, sizeof *e))) {
      st = alloc_fail(ctx);
      goto done;
    }
    for (fcm_index j = 0; j < n; j++) { /* S column by column */
      e[j] = 1.0;
      TRY(Sop(Suser, e, Sd + (size_t)j * n));
      e[j] = 0.0;
    }
    int diagonal = 1; /* Jacobi, or Schwarz without blocks */
    for (fcm_index j = 0; j < n && diagonal; j++)
      for (fcm_index i = 0; i < n; i++)
        if (i != j && Sd[i + (size_t)j * n] != 0.0) {
          diagonal = 0;
          break;
        }
    if (diagonal) { /* diagonal S: scale A symmetrically, no Cholesky needed */
      for (fcm_index j = 0; j < n; j++)
        for (fcm_index i = 0; i < n; i++)
          Bd[i + (size_t)j * n] = sqrt(Sd[i + (size_t)i * n] * Sd[j + (size_t)j * n]) *
                                  Ad[i + (size_t)j * n];
      TRY(fcm_dense_spectrum_eval(ctx, ni, Bd, NULL, w, NULL));
    } else {
      for (size_t p = 0; p < nn; p++) /* symmetrize the rounding of the block sums */
        Bd[p] = Sd[p];
      for (fcm_index j = 0; j < n; j++)
        for (fcm_index i = 0; i < n; i++)
          Sd[i + (size_t)j * n] = 0.5 * (Bd[i + (size_t)j * n] + Bd[j + (size_t)i * n]);
      TRY(fcm_dense_spectrum_eval(ctx, ni, Ad, Sd, w, NULL));
    }
  }
  double lmin = HUGE_VAL, lmax = 0.0;
  r->negative = 0;
  for (fcm_index k = 0; k < n; k++) {
    double l = fabs(w[k]);
    if (l < lmin) lmin = l;
    if (l > lmax) lmax = l;
    if (w[k] < 0.0) r->negative++;
  }
  r->lmin_abs = lmin;
  r->lmax_abs = lmax;
  r->kappa = lmin > 0.0 ? lmax / lmin : HUGE_VAL;

  /* MINRES on A x = A 1 */
  if (!(b = malloc(sizeof *b * (size_t)n)) || !(x = calloc((size_t)n, sizeof *x))) {
    st = alloc_fail(ctx);
    goto done;
  }
  for (fcm_index i = 0; i < n; i++) x[i] = 1.0;
  TRY(fcm_csr_apply(s->Af, 1.0, x, 0.0, b));
  for (fcm_index i = 0; i < n; i++) x[i] = 0.0;
  TRY(fcm_krylov_create(ctx, n, &ws));
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = c->rtol;
  ko.max_iterations = c->minres_max;
  ko.check_true_residual = 1;
  fcm_krylov_info ki;
  st = fcm_krylov_minres(ws, fcm_csr_operator, s->Af, Sop, Suser, b, x, &ko, &ki);
  if (st == FCM_ERR_NOT_CONVERGED || st == FCM_ERR_NUMERIC) { /* a result, not a failure */
    fcm_ctx_error_clear(ctx);
    st = FCM_OK;
  }
  TRY(st);
  r->iterations = ki.iterations;
  r->reason = ki.reason;
  r->true_residual = ki.true_residual;
done:
  fcm_jacobi_destroy(&J);
  fcm_schwarz_destroy(&P);
  fcm_krylov_destroy(&ws);
  free(e);
  free(b);
  free(x);
  return st;
}

/* All preconditioners for one (element, fraction, alpha); appends to res. */
static fcm_status run_case(fcm_ctx *ctx, const config *c, fcm_mesh *mesh, double phi,
                           double alpha, result *res, int *nres)
{
  fcm_status st = FCM_OK;
  linsys s;
  double *Ad = NULL, *Sd = NULL, *Bd = NULL, *w = NULL, t_rules = 0.0;
  const double t0 = fcm_wtime();
  const char *ename = fcm_element_get_info(fcm_mesh_element_type(mesh))->name;
  st = system_build(ctx, c, mesh, phi, alpha, &s, &t_rules);
  if (st != FCM_OK) goto done;
  const fcm_index n = s.n;
  const size_t nn = (size_t)n * (size_t)n;
  if (!(Ad = calloc(nn, sizeof *Ad)) || !(Sd = calloc(nn, sizeof *Sd)) ||
      !(Bd = calloc(nn, sizeof *Bd)) || !(w = calloc((size_t)n, sizeof *w))) {
    st = alloc_fail(ctx);
    goto done;
  }
  {
    const fcm_index *rp = fcm_csr_row_ptr(s.Af);
    const int *ci = fcm_csr_col_idx(s.Af);
    const double *v = fcm_csr_values(s.Af);
    for (fcm_index i = 0; i < n; i++)
      for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
        Ad[i + (size_t)ci[p] * n] = v[p];
  }
  const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(s.rules);
  fprintf(stderr, "[%s phi=%-7.2g alpha=%-5.2g] %lld dofs, %lld cut cells, rules %.2f s%s", ename,
          phi, alpha, (long long)n, (long long)rs->num_cut, t_rules,
          rs->simplify_fallbacks[0] + rs->simplify_fallbacks[1] > 0 ? " (simplify fallbacks)"
                                                                     : "");
  for (int k = 0; k < c->num_precs; k++) {
    result *r = &res[*nres];
    memset(r, 0, sizeof *r);
    r->element = fcm_mesh_element_type(mesh);
    r->prec = c->precs[k];
    r->alpha = alpha;
    r->phi_nominal = phi;
    r->phi_min = s.phi_min;
    r->dofs = n;
    TRY(measure(ctx, c, &s, c->precs[k], Ad, Sd, Bd, w, r));
    fprintf(stderr, ", %s %.2e/%d", prec_names[r->prec], r->kappa, r->iterations);
    (*nres)++;
  }
  fprintf(stderr, " (%.1f s)\n", fcm_wtime() - t0);
done:
  system_free(&s);
  free(Ad);
  free(Sd);
  free(Bd);
  free(w);
  return st;
}

/* ---------------------------------------------------------------- output */

static int write_csv(const char *path, const result *res, int nres, int project)
{
  char tmp[4096];
  if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) {
    fprintf(stderr, PROG ": --csv: path too long\n");
    return 0;
  }
  FILE *f = fopen(tmp, "w");
  if (!f) {
    fprintf(stderr, PROG ": cannot write %s: %s\n", tmp, strerror(errno));
    return 0;
  }
  fprintf(f, "element,preconditioner,stabilization,min_volume_fraction,condition_number,"
             "nominal_fraction,lambda_min_abs,lambda_max_abs,negative_eigenvalues,dofs,"
             "schwarz_blocks,clamped_eigenvalues,minres_iterations,minres_reason,"
             "minres_true_residual,tangent\n");
  for (int k = 0; k < nres; k++) {
    const result *r = &res[k];
    fprintf(f, "%s,%s,%g,%.6e,%.6e,%g,%.6e,%.6e,%lld,%lld,%lld,%lld,%d,%s,%.3e,%s\n",
            fcm_element_get_info(r->element)->name, prec_names[r->prec], r->alpha, r->phi_min,
            r->kappa, r->phi_nominal, r->lmin_abs, r->lmax_abs, (long long)r->negative,
            (long long)r->dofs, (long long)r->blocks, (long long)r->clamped, r->iterations,
            fcm_krylov_reason_str(r->reason), r->true_residual,
            project ? "projected" : "unprojected");
  }
  if (ferror(f) | (fclose(f) != 0) || rename(tmp, path) != 0) {
    fprintf(stderr, PROG ": cannot write %s: %s\n", path, strerror(errno));
    remove(tmp);
    return 0;
  }
  return 1;
}

/* Tables on stdout: one row per (element, stabilization, preconditioner), one column per
 * fraction; kappa, then MINRES iterations. */
static void print_tables(const config *c, const result *res, int nres)
{
  for (int table = 0; table < 2; table++) {
    printf("\n%s\n", table == 0 ? "condition number kappa(S A)"
                                : "MINRES iterations to rtol (x0 = 0, b = A 1; * = not converged)");
    printf("%-6s %-14s %-7s", "elem", "precond", "alpha");
    for (int f = 0; f < c->num_fractions; f++) printf(" %9.0e", c->fractions[f]);
    printf("\n");
    for (int e = 0; e < c->num_elements; e++)
      for (int sb = 0; sb < 2; sb++) {
        if (!(sb == 0 ? c->stab_on : c->stab_off)) continue;
        double alpha = sb == 0 ? c->alpha : 0.0;
        for (int p = 0; p < c->num_precs; p++) {
          printf("%-6s %-14s %-7.0e", fcm_element_get_info(c->elements[e])->name,
                 prec_names[c->precs[p]], alpha);
          for (int f = 0; f < c->num_fractions; f++) {
            const result *r = NULL;
            for (int k = 0; k < nres && !r; k++)
              if (res[k].element == c->elements[e] && res[k].prec == c->precs[p] &&
                  res[k].alpha == alpha && res[k].phi_nominal == c->fractions[f])
                r = &res[k];
            if (!r)
              printf(" %9s", "-");
            else if (table == 0)
              printf(" %9.2e", r->kappa);
            else
              printf(" %8d%c", r->iterations, r->reason == FCM_KRYLOV_CONVERGED_RTOL ? ' ' : '*');
          }
          printf("\n");
        }
      }
  }
}

static int write_png(const config *c, const char *path, const result *res, int nres)
{
  char tmp[4096], script[4096], cmd[8400];
  if (system(NULL) == 0 || system("gnuplot --version > /dev/null 2>&1") != 0) {
    fprintf(stderr, PROG ": gnuplot not found (Debian package gnuplot-nox): %s not written; "
                    "the CSV is unaffected\n",
            path);
    return 1;
  }
  if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp ||
      snprintf(script, sizeof script, "%s.gp.tmp", path) >= (int)sizeof script) {
    fprintf(stderr, PROG ": --png: path too long\n");
    return 0;
  }
  FILE *f = fopen(script, "w");
  if (!f) {
    fprintf(stderr, PROG ": cannot write %s: %s\n", script, strerror(errno));
    return 0;
  }
  static const char *const colors[PREC_COUNT] = {"#000000", "#1f77b4", "#d62728", "#2ca02c"};
  /* one datablock per (stabilization, element, preconditioner) series with finite values;
   * panels: rows = stabilization settings run, columns = element shapes run */
  int series = 0, ids[2][4][PREC_COUNT], row_on[2] = {0, 0}, col_on[2] = {0, 0};
  for (int sb = 0; sb < 2; sb++)
    for (int e = 0; e < 4; e++)
      for (int p = 0; p < PREC_COUNT; p++) {
        ids[sb][e][p] = -1;
        int any = 0;
        for (int k = 0; k < nres; k++) {
          const result *r = &res[k];
          if ((int)r->element != e || r->prec != p || (r->alpha > 0.0) != (sb == 0)) continue;
          row_on[sb] = col_on[fcm_element_get_info(r->element)->shape == FCM_SHAPE_TET ? 0 : 1] =
              1;
          if (!isfinite(r->kappa)) continue;
          if (!any) fprintf(f, "$S%d << EOD\n", series);
          any = 1;
          fprintf(f, "%.6e %.6e\n", r->phi_min, r->kappa);
        }
        if (any) {
          fprintf(f, "EOD\n");
          ids[sb][e][p] = series++;
        }
      }
  const int nrows = row_on[0] + row_on[1], ncols = col_on[0] + col_on[1];
  fprintf(f, "set terminal png size %d,%d font ',11'\nset output '%s'\n", 200 + 600 * ncols,
          100 + 450 * nrows, tmp);
  fprintf(f, "set logscale xy\nset xrange [*:*] reverse\nset format x '10^{%%L}'\n"
             "set format y '10^{%%L}'\nset grid\nset key top left font ',9'\n"
             "set xlabel 'smallest volume fraction'\nset ylabel 'kappa(SA)'\n");
  fprintf(f, "set multiplot layout %d,%d title 'kappa(S (M + dt^2 K)), 4x4x4 grid, box "
             "[0,1+eps/3]^3 (Longva et al. 2020, Fig. 5)'\n",
          nrows, ncols);
  for (int sb = 0; sb < 2; sb++)
    for (int shape = 0; shape < 2; shape++) {
      if (!row_on[sb] || !col_on[shape]) continue;
      /* the linear and the quadratic element of this shape */
      int e0 = -1, e1 = -1;
      for (int e = 0; e < 4; e++) {
        const fcm_element_info *in = fcm_element_get_info((fcm_element_type)e);
        if (!in || (in->shape == FCM_SHAPE_TET) != (shape == 0)) continue;
        if (in->order == 1)
          e0 = e;
        else
          e1 = e;
      }
      fprintf(f, "set title '%s, %s'\n", shape == 0 ? "tetrahedra" : "hexahedra",
              sb == 0 ? "with stabilization" : "without stabilization");
      int first = 1;
      for (int which = 0; which < 2; which++) {
        int e = which == 0 ? e0 : e1;
        if (e < 0) continue;
        /* schwarz-paper under schwarz, wider, so coinciding curves stay visible */
        static const int order[PREC_COUNT] = {PREC_NONE, PREC_JACOBI, PREC_SCHWARZ_PAPER,
                                              PREC_SCHWARZ};
        for (int q = 0; q < PREC_COUNT; q++) {
          int p = order[q], id = ids[sb][e][p];
          if (id < 0) continue;
          fprintf(f,
                  "%s $S%d using 1:2 with linespoints lw %g dt %d pt %d lc rgb '%s' title '%s %s'",
                  first ? "plot" : ",", id, p == PREC_SCHWARZ_PAPER ? 5.0 : 2.0,
                  which == 0 ? 2 : 1, which == 0 ? 6 : 7, colors[p],
                  fcm_element_get_info((fcm_element_type)e)->name, prec_names[p]);
          first = 0;
        }
      }
      if (first) /* nothing finite to draw: keep the panel, say so */
        fprintf(f, "plot [1e-12:1] 1 lc rgb '#ffffff' title 'no finite values'");
      fprintf(f, "\n");
    }
  fprintf(f, "unset multiplot\nset output\n");
  (void)c;
  if (ferror(f) | (fclose(f) != 0)) {
    fprintf(stderr, PROG ": cannot write %s\n", script);
    remove(script);
    return 0;
  }
  snprintf(cmd, sizeof cmd, "gnuplot '%s'", script);
  int rc = system(cmd);
  remove(script);
  if (rc != 0 || rename(tmp, path) != 0) {
    fprintf(stderr, PROG ": gnuplot failed (status %d) or %s could not be renamed\n", rc, tmp);
    remove(tmp);
    return 0;
  }
  return 1;
}

/* ---------------------------------------------------------------- main */

int main(int argc, char **argv)
{
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  config c;
  memset(&c, 0, sizeof c);
  for (int e = 0; e < 4; e++) c.elements[e] = (fcm_element_type)e;
  c.num_elements = 4;
  c.num_precs = PREC_COUNT;
  for (int p = 0; p < PREC_COUNT; p++) c.precs[p] = p;
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
          st = run_case(ctx, &c, mesh, c.fractions[f], sb == 0 ? c.alpha : 0.0, res, &nres);
    fcm_mesh_destroy(&mesh);
  }
  if (st != FCM_OK) {
    fprintf(stderr, PROG ": failed: %s\n", fcm_status_str(st));
    fcm_ctx_error_view(ctx, stderr);
    rc = 1;
  } else {
    fprintf(stderr, PROG ": %d results in %.1f s\n", nres, fcm_wtime() - t0);
    print_tables(&c, res, nres);
    if (c.csv && !write_csv(c.csv, res, nres, c.project)) rc = 1;
    if (c.png && !write_png(&c, c.png, res, nres)) rc = 1;
  }
  free(res);
  fcm_ctx_destroy(&ctx);
  return rc;
}
