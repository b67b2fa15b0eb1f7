/* fcm-converge: what accuracy costs in time — convergence rates of FCM (exact embedded
 * geometry, cut-cell rules) versus staircase FEM, error versus time, a quadrature-strength
 * sweep, and the payoff of rule simplification (Longva et al. 2020 §6.2, §6.3, §6.6).
 *
 * Study: static linear elasticity on a tet-meshed hemisphere (radius 0.9, flat face on
 * y = 0) in the background box [-1,1] x [0,1] x [-1,1] with h = 1/res, for Tet4, Tet10,
 * Hex8 and Hex20 grids; a manufactured solution makes the exact error known (see
 * fcm-converge-study.c; the curved boundary carries its traction or, with --boundary nitsche,
 * its displacement imposed by symmetric Nitsche), or --reference runs the authors' localized-load
 * problem against a boundary-conforming Tet10 reference. `payoff` measures, per element and rule
 * kind, the simplification time and the assembly time it saves: the break-even number of
 * assemblies. */
#include "app_env.h"
#include "cli.h"
#include "fcm-converge-study.h"

#include <fcm/material.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_LEVELS 32
#define MAX_SWEEP  24

typedef struct config {
  cv_setup setup;
  fcm_element_type elements[FCM_ELEMENT_COUNT];
  int num_elements;
  int methods[CV_METHOD_COUNT];
  int num_methods;
  int nitsche; /* --boundary nitsche */
  int levels[MAX_LEVELS];
  int num_levels;
  int fit;
  int quick;
  int sweep;
  fcm_element_type sweep_element;
  int sweep_res;
  int sweep_strengths[MAX_SWEEP];
  int num_sweep;
  const char *out;
  const char *csv, *rates_csv, *sweep_csv;
  int plots;
  int cpu_time; /* accuracy-vs-time table and plot on CPU seconds */
  /* payoff */
  int payoff;
  int payoff_res;
  int repeat;
  const char *payoff_csv;
} config;

/* ---------------------------------------------------------------- options */

/* A comma list of integers in [lo, hi], at most cap of them, into values[0..*count-1]. */
typedef struct int_list {
  int *values, *count;
  int cap, lo, hi;
} int_list;

static int parse_int_list(const char *prog, const char *opt, const char *s, void *dest)
{
  const int_list *l = dest;
  char tok[MAX_LEVELS > MAX_SWEEP ? MAX_LEVELS : MAX_SWEEP][CLI_TOKEN];
  long long v = 0;
  int n = 0;
  if (!cli_list(prog, opt, s, tok, l->cap, &n)) return 0;
  for (int k = 0; k < n; k++) {
    if (!cli_int(prog, opt, tok[k], l->lo, l->hi, &v)) return 0;
    l->values[k] = (int)v;
  }
  *l->count = n;
  return 1;
}

static int parse_elements(const char *prog, const char *opt, const char *s, void *dest)
{
  config *c = dest;
  return cli_element_list(prog, opt, s, c->elements, &c->num_elements);
}

static int parse_methods(const char *prog, const char *opt, const char *s, void *dest)
{
  static const char *const names[CV_METHOD_COUNT + 1] = {"fcm", "fem", "fcm-nitsche", NULL};
  config *c = dest;
  char tok[CV_METHOD_COUNT][CLI_TOKEN];
  int n = 0;
  if (!cli_list(prog, opt, s, tok, CV_METHOD_COUNT, &n)) return 0;
  for (int k = 0; k < n; k++) {
    if (!cli_choice(prog, opt, tok[k], names, &c->methods[k])) return 0;
    for (int j = 0; j < k; j++)
      if (c->methods[j] == c->methods[k]) {
        fprintf(stderr, "%s: %s: '%s' given twice\n", prog, opt, tok[k]);
        return 0;
      }
  }
  c->num_methods = n;
  return 1;
}

/* What the option table writes besides the config: flags and choices that map onto it, the
 * list descriptors, and which options were given (the --quick defaults yield to them). */
typedef struct parse_state {
  int reference, no_sweep, no_plots, fem_traction, boundary;
  int_list levels, sweep_strengths;
  struct {
    int levels, ref_refine, geom, sweep_res, sweep, error_strength, res, repeat;
  } given;
} parse_state;

static const char *const on_off[] = {"off", "on", NULL};
static const char *const traction_names[] = {"projected", "naive", "face", NULL};
static const char *const boundary_names[] = {"traction", "nitsche", NULL};
static const char *const time_names[] = {"wall", "cpu", NULL};

enum { CMD_STUDY = 1, CMD_PAYOFF = 2, CMD_BOTH = 3 };

/* One option and the subcommands (CMD_*) that take it. */
typedef struct cv_option {
  unsigned cmds;
  cli_option o;
} cv_option;

#define NUM_OPTIONS 33 /* entries of the table below, sentinel included */

/* The options of subcommand `cmd` (CMD_STUDY or CMD_PAYOFF) writing into c and p. One table
 * of all the options: splitting it would scatter them, so it stays long. */
static void option_table(unsigned cmd, config *c, parse_state *p, cli_option t[NUM_OPTIONS])
{
  cv_setup *s = &c->setup;
  p->levels = (int_list){c->levels, &c->num_levels, MAX_LEVELS, 1, 64};
  p->sweep_strengths = (int_list){c->sweep_strengths, &c->num_sweep, MAX_SWEEP, 1, 20};
  const cv_option all[NUM_OPTIONS] = {
      {CMD_STUDY,
       {"--elements", NULL, CLI_CUSTOM, c, "LIST", "tet4,tet10,hex8,hex20 (default all)", 0, 0, 0,
        NULL, parse_elements, NULL}},
      {CMD_PAYOFF,
       {"--elements", "--element", CLI_CUSTOM, c, "LIST",
        "tet4,tet10,hex8,hex20 (--element E: one)\n"
        "(default all)",
        0, 0, 0, NULL, parse_elements, NULL}},
      {CMD_STUDY,
       {"--methods", NULL, CLI_CUSTOM, c, "LIST", "fcm,fem,fcm-nitsche (default fcm,fem)", 0, 0, 0,
        NULL, parse_methods, NULL}},
      {CMD_STUDY,
       {"--levels", NULL, CLI_CUSTOM, &p->levels, "LIST",
        "resolutions res in [1, 64], h = 1/res (default 2,3,4,6,8)", 0, 0, 0, NULL, parse_int_list,
        &p->given.levels}},
      {CMD_STUDY,
       {"--quick", NULL, CLI_FLAG, &c->quick, NULL,
        "levels 2,3,4, geometry n 6, sweep res 2 with m = 2..5,\n"
        "error strength 6 (rates as with 8 to 3 digits),\n"
        "--ref-refine 0; explicit options override these",
        0, 0, 0, NULL, NULL, NULL}},
      {CMD_PAYOFF,
       {"--quick", NULL, CLI_FLAG, &c->quick, NULL,
        "res 3, geometry n 6, repeat 2; explicit options\n"
        "override these",
        0, 0, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--reference", NULL, CLI_FLAG, &p->reference, NULL,
        "the authors' problem: E = 5e4, nu = 0, load -5e5 y\n"
        "exp(-1/(1-9r^2)) e_y (3r < 1), u = 0 on y = 0, traction\n"
        "free; errors against boundary-conforming Tet10 on the\n"
        "geometry's tets refined --ref-refine times",
        0, 0, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--ref-refine", NULL, CLI_INT, &s->ref_refine, "N",
        "refinements of the reference, 0..3 (default 1; quick 0)", 0, 3, 0, NULL, NULL,
        &p->given.ref_refine}},
      {CMD_BOTH,
       {"--radius", NULL, CLI_DOUBLE, &s->radius, "R",
        "hemisphere radius in [0.05, 0.999] (default 0.9)", 0.05, 0.999, 0, NULL, NULL, NULL}},
      {CMD_BOTH,
       {"--geom-n", NULL, CLI_INT, &s->geom_n, "N",
        "geometry resolution, 24 N^3 tets, N in [1, 64]\n"
        "(default 8; quick 6)",
        1, 64, 0, NULL, NULL, &p->given.geom}},
      {CMD_BOTH,
       {"--strength", NULL, CLI_INT, &s->strength, "M",
        "FCM cut-cell stiffness strength, 1..20 (default element's)", 1, 20, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--surface-strength", NULL, CLI_INT, &s->surface_strength, "M",
        "traction rules (FCM and FEM faces), 0..20 (default 2p+2)", 0, 20, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--simplify", NULL, CLI_CHOICE, &s->simplify, "on|off",
        "simplify FCM cut-cell rules (default on)", 0, 0, 0, on_off, NULL, NULL}},
      {CMD_STUDY,
       {"--stabilization", NULL, CLI_DOUBLE, &s->stab_alpha, "A",
        "FCM stabilization alpha in [0, 1], 0 = off (default 0)", 0, 1, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--min-fraction", NULL, CLI_DOUBLE, &s->min_fraction, "F",
        "FCM: drop cells with volume fraction < F, F in [0, 0.5]\n"
        "(default 0: only empty cells; a dropped cell takes its\n"
        "share of the surface load with it, ~sqrt(F) h^2 each,\n"
        "which stalls convergence)",
        0, 0.5, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--error-strength", NULL, CLI_INT, &s->error_strength, "M",
        "strength of the error rules, 2..20 (default 8; quick 6)", 2, 20, 0, NULL, NULL,
        &p->given.error_strength}},
      {CMD_STUDY,
       {"--boundary", NULL, CLI_CHOICE, &p->boundary, "MODE",
        "what FCM imposes on the hemisphere's curved boundary\n"
        "(manufactured problem; default traction): traction:\n"
        "sigma(u) n; nitsche: the exact displacement, weakly by\n"
        "symmetric Nitsche (the library's boundary constraints,\n"
        "penalty per cell from its eigenvalue estimate); its rows\n"
        "are method fcm-nitsche",
        0, 0, 0, boundary_names, NULL, NULL}},
      {CMD_STUDY,
       {"--fem-traction", NULL, CLI_CHOICE, &p->fem_traction, "MODE",
        "surface load of the staircase FEM (default projected)\n"
        "projected: the true load t(y) = sigma(u(y)) n(y) on the\n"
        "polyhedron carried along rays from the centre to the\n"
        "staircase faces (weight |y|^2 (d.n_face) / (|x|^2 (d.n)):\n"
        "the total force is that of the true surface);\n"
        "naive: sigma(u(x)) n_true(x) per staircase face area\n"
        "(n_true: facet met by the ray; the load grows with the\n"
        "staircase's excess area, so this FEM does not converge);\n"
        "face: sigma(u(x)) n_face, the exact data of the staircase\n"
        "domain itself (control: optimal rates, no geometric error)",
        0, 0, 0, traction_names, NULL, NULL}},
      {CMD_STUDY,
       {"--fit", NULL, CLI_INT, &c->fit, "N", "levels in the rate fit, 2..32 (default 3)", 2,
        MAX_LEVELS, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--sweep-element", NULL, CLI_CUSTOM, &c->sweep_element, "E",
        "element of the strength sweep (FCM) (default hex20)", 0, 0, 0, NULL, cli_element, NULL}},
      {CMD_STUDY,
       {"--sweep-res", NULL, CLI_INT, &c->sweep_res, "R",
        "resolution of the sweep, 1..64 (default 4; quick 2)", 1, 64, 0, NULL, NULL,
        &p->given.sweep_res}},
      {CMD_STUDY,
       {"--sweep-strengths", NULL, CLI_CUSTOM, &p->sweep_strengths, "LIST",
        "strengths m in [1, 20] (default 1..8; quick 2..5)", 0, 0, 0, NULL, parse_int_list,
        &p->given.sweep}},
      {CMD_STUDY,
       {"--no-sweep", NULL, CLI_FLAG, &p->no_sweep, NULL, "skip the strength sweep", 0, 0, 0, NULL,
        NULL, NULL}},
      {CMD_STUDY,
       {"--time", NULL, CLI_CHOICE, &c->cpu_time, "wall|cpu",
        "time base of the accuracy-vs-time table and plot\n"
        "(default wall; cpu = process CPU seconds of all threads,\n"
        "steadier on a shared machine)",
        0, 0, 0, time_names, NULL, NULL}},
      {CMD_STUDY,
       {"--out", NULL, CLI_STRING, &c->out, "PREFIX", "output prefix (default fcm-converge)", 0, 0,
        0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--csv", NULL, CLI_STRING, &c->csv, "FILE", "per-level CSV (default PREFIX-levels.csv)", 0,
        0, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--rates-csv", NULL, CLI_STRING, &c->rates_csv, "FILE",
        "fitted rates CSV (default PREFIX-rates.csv)", 0, 0, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--sweep-csv", NULL, CLI_STRING, &c->sweep_csv, "FILE",
        "strength sweep CSV (default PREFIX-sweep.csv)", 0, 0, 0, NULL, NULL, NULL}},
      {CMD_STUDY,
       {"--no-plots", NULL, CLI_FLAG, &p->no_plots, NULL,
        "no PNG files (else PREFIX-convergence.png,\n"
        "PREFIX-pareto.png, PREFIX-sweep.png through gnuplot;\n"
        "without gnuplot a message is printed and the CSV files\n"
        "are still written)",
        0, 0, 0, NULL, NULL, NULL}},
      {CMD_PAYOFF,
       {"--res", NULL, CLI_INT, &c->payoff_res, "R", "resolution, 1..64 (default 8; quick 3)", 1,
        64, 0, NULL, NULL, &p->given.res}},
      {CMD_PAYOFF,
       {"--repeat", NULL, CLI_INT, &c->repeat, "N",
        "timed assemblies per variant, minimum kept, 1..100\n"
        "(default 3; quick 2)",
        1, 100, 0, NULL, NULL, &p->given.repeat}},
      {CMD_PAYOFF,
       {"--csv", NULL, CLI_STRING, &c->payoff_csv, "FILE", "write the table as CSV", 0, 0, 0, NULL,
        NULL, NULL}},
      {CMD_BOTH, {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}}};
  int n = 0;
  for (int k = 0; k < NUM_OPTIONS; k++)
    if (all[k].cmds & cmd) t[n++] = all[k].o;
}

/* Both subcommands' options (`opts`, the one parsed, is not used). */
static void usage(FILE *f, const cli_option *opts)
{
  config c;
  parse_state p;
  cli_option all[NUM_OPTIONS];
  (void)opts;
  fprintf(
      f, "usage: " CV_PROG " [options]           convergence, accuracy vs time, strength sweep\n"
         "       " CV_PROG " payoff [options]    simplification payoff (Longva et al. 2020 §6.3)\n"
         "\n"
         "Static linear elasticity on a hemisphere (tet mesh of radius R, flat face on y = 0)\n"
         "embedded in the box [-1,1]x[0,1]x[-1,1] meshed with 2res x res x 2res cubes (h = 1/res;\n"
         "tets: 6 per cube). FCM integrates the exact polyhedron with cut-cell rules; FEM keeps\n"
         "the cells whose centroid lies inside the polyhedron (point-in-tet test on the geometry\n"
         "mesh) and integrates them fully - the staircase a plain FEM would use.\n"
         "Default problem: manufactured u_i = A_i sin(k_i.x + phi_i) (E = 1, nu = 0.3); body\n"
         "force -div sigma(u); FCM traction sigma(u) n on the embedded boundary (facet normals);\n"
         "the FEM knows only its staircase boundary and receives the true surface load there\n"
         "(--fem-traction); body force b(x) on all kept cells; u = u_exact on all nodes on y = 0.\n"
         "With --boundary nitsche, FCM imposes u = u_exact weakly on the curved boundary instead\n"
         "of the traction (symmetric Nitsche, fcm_integrator_add_boundary_constraint()); its\n"
         "rows carry the method name fcm-nitsche.\n"
         "Errors: ||u_h - u||_L2 and |u_h - u|_H1 with strength-8 rules of the polyhedron on the\n"
         "same grid (FCM: all of Omega, dropped cells extrapolated from a face neighbour; FEM:\n"
         "Omega inside the kept cells - column 'meas' is that volume / |Omega|).\n"
         "Rates: least-squares slope of log err vs log h over the finest --fit levels.\n"
         "\n"
         "study options:\n");
  option_table(CMD_STUDY, &c, &p, all);
  cli_print_options(f, all);
  fprintf(
      f, "\n"
         "payoff options (FCM on the hemisphere with the manufactured displacement; per element\n"
         "and rule kind the rules are built without and with simplification and one assembly of\n"
         "each is timed: the break-even is the number of assemblies at which simplifying pays):\n");
  option_table(CMD_PAYOFF, &c, &p, all);
  cli_print_options(f, all);
  fprintf(
      f, "\n"
         "CSV columns. levels: element,method,res,h,dofs,active_cells,cut_cells,points,\n"
         "  strength,t_rules,t_assembly,t_solve,t_total,err_l2,err_h1,norm_l2,norm_h1,rel_l2,\n"
         "  rel_h1,measured_volume,domain_volume,failed,note,cpu_rules,cpu_assembly,cpu_solve,\n"
         "  cpu_total (cpu_*: process CPU seconds of the phases). points: stiffness quadrature\n"
         "  points of all stored cells (FCM) or kept cells x standard rule (FEM); strength: the\n"
         "  FCM cut-cell strength or the FEM full-cell rule's; t_rules: FCM cell rules (stiffness\n"
         "  rules of the cut-cell strength, surface rules, mass rules of strength 0 - a static\n"
         "  problem assembles no mass) or the FEM centroid classification; t_assembly: space,\n"
         "  pattern, stiffness, loads, Dirichlet\n"
         "  elimination; t_solve: CHOLMOD analyze+factor+solve; times are wall-clock seconds;\n"
         "  err_*: absolute errors, norm_*: the exact (reference) norms over the same domain.\n"
         "  rates: element,method,norm,rate (method fcm|fem|fcm-nitsche, norm L2|H1).\n"
         "  sweep: element,method,res,h,strength,points,dofs,t_rules,t_assembly,t_solve,t_total,\n"
         "  err_l2,err_h1,rel_l2,rel_h1,failed,note,cpu_rules,cpu_assembly,cpu_solve,cpu_total.\n"
         "  payoff: element,res,kind,strength,cut_cells,points_plain,points_simplified,\n"
         "  t_simplify,t_assembly_plain,t_assembly_simplified,point_cost,simplify_per_cell,\n"
         "  break_even_assemblies (kind stiffness|mass; points: cut-cell points before\n"
         "  stabilization; times in core-seconds: the kind's simplification, one assembly (CPU);\n"
         "  point_cost = assembly time saved / points saved; break_even = t_simplify / assembly\n"
         "  time saved, inf when none is saved).\n"
         "Timings are wall-clock with the OpenMP threads of the environment; on a loaded machine\n"
         "set OMP_WAIT_POLICY=passive (spinning threads inflate small phases).\n"
         "stdout: tables; stderr: progress. Exit 0 on success, 1 on a computation or output\n"
         "error, 2 on a usage error.\n");
}

static void defaults(config *c)
{
  memset(c, 0, sizeof *c);
  cv_setup *s = &c->setup;
  s->problem = CV_MANUFACTURED;
  s->radius = 0.9;
  s->geom_n = 8;
  s->young = 1.0;
  s->poisson = 0.3;
  s->strength = -1;
  s->surface_strength = -1;
  s->simplify = 1;
  s->stab_alpha = 0.0;
  s->min_fraction = 0.0;
  s->error_strength = 8;
  s->fem_traction = CV_TRACTION_PROJECTED;
  s->ref_refine = 1;
  for (int e = 0; e < FCM_ELEMENT_COUNT; e++)
    c->elements[e] = (fcm_element_type)e;
  c->num_elements = FCM_ELEMENT_COUNT;
  c->methods[0] = CV_FCM, c->methods[1] = CV_FEM;
  c->num_methods = 2;
  static const int lv[] = {2, 3, 4, 6, 8};
  c->num_levels = (int)(sizeof lv / sizeof *lv);
  memcpy(c->levels, lv, sizeof lv);
  c->fit = 3;
  c->sweep = 1;
  c->sweep_element = FCM_ELEMENT_HEX20;
  c->sweep_res = 4;
  c->num_sweep = 8;
  for (int k = 0; k < 8; k++)
    c->sweep_strengths[k] = k + 1;
  c->out = CV_PROG;
  c->plots = 1;
  c->payoff_res = 8;
  c->repeat = 3;
}

/* The --quick defaults of the options not given. */
static void quick_defaults(config *c, const parse_state *p)
{
  static const int lv[] = {2, 3, 4};
  if (!p->given.levels) {
    c->num_levels = 3;
    memcpy(c->levels, lv, sizeof lv);
  }
  if (!p->given.geom) c->setup.geom_n = 6;
  if (!p->given.ref_refine) c->setup.ref_refine = 0;
  if (!p->given.sweep_res) c->sweep_res = 2;
  if (!p->given.error_strength) c->setup.error_strength = 6;
  if (!p->given.sweep) {
    c->num_sweep = 4;
    for (int k = 0; k < 4; k++)
      c->sweep_strengths[k] = k + 2;
  }
  if (!p->given.res) c->payoff_res = 3;
  if (!p->given.repeat) c->repeat = 2;
}

/* -1 when the arguments are parsed into `c`, else the exit code (0 after --help, 2). */
static int parse_args(int argc, char **argv, config *c)
{
  parse_state p;
  cli_option opts[NUM_OPTIONS];
  memset(&p, 0, sizeof p);
  p.fem_traction = (int)c->setup.fem_traction;
  c->payoff = argc > 1 && !strcmp(argv[1], "payoff");
  option_table(c->payoff ? CMD_PAYOFF : CMD_STUDY, c, &p, opts);
  /* the payoff options from argv[2] on: cli_parse skips its argv[0] */
  const int rc = cli_parse_args(c->payoff ? CV_PROG " payoff" : CV_PROG, opts, argc - c->payoff,
                                argv + c->payoff, NULL, 0, NULL, usage);
  if (rc >= 0) return rc;
  if (p.reference) c->setup.problem = CV_REFERENCE;
  if (p.boundary == 1) {
    if (p.reference) {
      fprintf(stderr, CV_PROG ": --boundary nitsche needs the manufactured problem (not "
                              "--reference)\n");
      return 2;
    }
    int n = 0; /* fcm -> fcm-nitsche, once */
    for (int k = 0; k < c->num_methods; k++) {
      const int m = c->methods[k] == CV_FCM ? CV_NITSCHE : c->methods[k];
      int dup = 0;
      for (int j = 0; j < n; j++)
        dup |= c->methods[j] == m;
      if (!dup) c->methods[n++] = m;
    }
    c->num_methods = n;
  }
  c->nitsche = p.boundary == 1;
  c->setup.fem_traction = (cv_fem_traction)p.fem_traction;
  c->sweep = !p.no_sweep;
  c->plots = !p.no_plots;
  if (c->quick) quick_defaults(c, &p);
  if (c->setup.problem == CV_REFERENCE) {
    c->setup.young = 5e4;
    c->setup.poisson = 0.0;
  }
  for (int a = 0; a < c->num_levels; a++)
    for (int b = a + 1; b < c->num_levels; b++)
      if (c->levels[a] == c->levels[b]) {
        fprintf(stderr, CV_PROG ": --levels: %d given twice\n", c->levels[a]);
        return 2;
      }
  return -1;
}

/* ---------------------------------------------------------------- study */

static void progress(const cv_result *r)
{
  if (r->failed)
    fprintf(stderr, CV_PROG ": %-5s %s res %2d: FAILED (%s)\n",
            fcm_element_get_info(r->element)->name, cv_method_name(r->method), r->res, r->note);
  else
    fprintf(stderr,
            CV_PROG ": %-5s %s res %2d: %7lld dofs, rules %.2f s, assembly %.2f s, solve %.2f s,"
                    " L2 %.3e, H1 %.3e\n",
            fcm_element_get_info(r->element)->name, cv_method_name(r->method), r->res,
            (long long)r->dofs, r->t_rules, r->t_assembly, r->t_solve,
            r->norm_l2 > 0 ? r->err_l2 / r->norm_l2 : NAN,
            r->norm_h1 > 0 ? r->err_h1 / r->norm_h1 : NAN);
}

static fcm_status run_level(cv_study *study, fcm_ctx *ctx, fcm_element_type type, int res,
                            const int *methods, int nmethods, const cv_run_options *ro,
                            cv_result *out, int *nout)
{
  fcm_mesh *mesh = NULL;
  fcm_cell_rules *er = NULL;
  fcm_status st = cv_mesh_create(ctx, type, res, &mesh);
  const double t0 = fcm_wtime();
  if (st == FCM_OK) st = cv_error_rules_create(study, mesh, &er);
  if (st == FCM_OK && study && nmethods > 0)
    fprintf(stderr, CV_PROG ": %-5s res %2d: error rules %.2f s (%lld points)\n",
            fcm_element_get_info(type)->name, res, fcm_wtime() - t0,
            (long long)fcm_cell_rules_get_stats(er)->points_total[FCM_RULE_STIFFNESS]);
  for (int m = 0; m < nmethods && st == FCM_OK; m++) {
    cv_result *r = &out[*nout];
    memset(r, 0, sizeof *r);
    r->res = res;
    r->h = 1.0 / res;
    st = cv_run(study, mesh, er, (cv_method)methods[m], ro, r);
    if (st == FCM_OK) {
      progress(r);
      (*nout)++;
    }
  }
  fcm_cell_rules_destroy(&er);
  fcm_mesh_destroy(&mesh);
  return st;
}

static int output_path(char *buf, size_t cap, const char *given, const char *prefix,
                       const char *suffix)
{
  if (given) return snprintf(buf, cap, "%s", given) < (int)cap;
  return snprintf(buf, cap, "%s%s", prefix, suffix) < (int)cap;
}

static int run_study(const config *c, fcm_ctx *ctx)
{
  cv_study *study = NULL;
  cv_result *res = NULL, *sw = NULL;
  cv_rate rates[2 * CV_METHOD_COUNT * FCM_ELEMENT_COUNT];
  int nres = 0, nsw = 0, nrates = 0, rc = 0;
  char path[4096];
  const double t0 = fcm_wtime();
  fcm_status st = cv_study_create(ctx, &c->setup, &study);
  if (st != FCM_OK) goto fail;
  res = calloc((size_t)(c->num_elements * c->num_levels * CV_METHOD_COUNT), sizeof *res);
  sw = calloc((size_t)c->num_sweep, sizeof *sw);
  if (!res || !sw) {
    st = FCM_ERR_ALLOC;
    goto fail;
  }
  fprintf(stderr,
          CV_PROG ": %s problem, hemisphere R = %g (%lld tets, volume %.6f), %d element(s) x %d "
                  "level(s) x %d method(s); simplification %s, stabilization %g\n",
          c->setup.problem == CV_MANUFACTURED ? "manufactured" : "reference", c->setup.radius,
          (long long)fcm_geometry_num_cells(cv_study_geometry(study)),
          fcm_geometry_volume(cv_study_geometry(study)), c->num_elements, c->num_levels,
          c->num_methods, c->setup.simplify ? "on" : "off", c->setup.stab_alpha);
  int levels[MAX_LEVELS];
  memcpy(levels, c->levels, sizeof levels);
  for (int a = 0; a < c->num_levels; a++) /* coarse to fine */
    for (int b = a + 1; b < c->num_levels; b++)
      if (levels[b] < levels[a]) {
        const int t = levels[a];
        levels[a] = levels[b], levels[b] = t;
      }
  for (int e = 0; e < c->num_elements && st == FCM_OK; e++)
    for (int l = 0; l < c->num_levels && st == FCM_OK; l++)
      st = run_level(study, ctx, c->elements[e], levels[l], c->methods, c->num_methods, NULL, res,
                     &nres);
  if (st != FCM_OK) goto fail;
  nrates = cv_rates_compute(res, nres, c->fit, rates);

  if (c->sweep) {
    const int fcm_only[1] = {c->nitsche ? CV_NITSCHE : CV_FCM};
    for (int k = 0; k < c->num_sweep && st == FCM_OK; k++) {
      cv_run_options ro = {c->sweep_strengths[k], -1};
      st = run_level(study, ctx, c->sweep_element, c->sweep_res, fcm_only, 1, &ro, sw, &nsw);
    }
    if (st != FCM_OK) goto fail;
  }
  fprintf(stderr, CV_PROG ": done in %.1f s\n", fcm_wtime() - t0);

  if (c->setup.problem == CV_REFERENCE) {
    fcm_index rd = 0;
    double rt = 0.0;
    cv_study_reference_info(study, &rd, &rt);
    printf("reference: boundary-conforming Tet10, %lld DOFs, %.1f s\n", (long long)rd, rt);
  }
  cv_print_levels(stdout, res, nres);
  cv_print_rates(stdout, rates, nrates);
  cv_print_pareto(stdout, res, nres, c->cpu_time);
  if (c->sweep) cv_print_sweep(stdout, sw, nsw);
  fflush(stdout);

  const char *what = c->setup.problem == CV_MANUFACTURED ? "manufactured solution"
                                                         : "localized load vs Tet10 reference";
  char title[256];
  snprintf(title, sizeof title, "FCM vs staircase FEM on an embedded hemisphere (%s)", what);
  if (!output_path(path, sizeof path, c->csv, c->out, "-levels.csv") ||
      !cv_write_levels_csv(path, res, nres))
    rc = 1;
  else
    fprintf(stderr, CV_PROG ": wrote %s\n", path);
  if (!output_path(path, sizeof path, c->rates_csv, c->out, "-rates.csv") ||
      !cv_write_rates_csv(path, rates, nrates))
    rc = 1;
  else
    fprintf(stderr, CV_PROG ": wrote %s\n", path);
  if (c->sweep) {
    if (!output_path(path, sizeof path, c->sweep_csv, c->out, "-sweep.csv") ||
        !cv_write_sweep_csv(path, sw, nsw))
      rc = 1;
    else
      fprintf(stderr, CV_PROG ": wrote %s\n", path);
  }
  if (c->plots && cv_have_gnuplot()) {
    if (!output_path(path, sizeof path, NULL, c->out, "-convergence.png") ||
        !cv_plot_convergence(path, res, nres, rates, nrates, title))
      rc = 1;
    else
      fprintf(stderr, CV_PROG ": wrote %s\n", path);
    snprintf(title, sizeof title, "accuracy versus time and DOFs (%s)", what);
    if (!output_path(path, sizeof path, NULL, c->out, "-pareto.png") ||
        !cv_plot_pareto(path, res, nres, c->cpu_time, title))
      rc = 1;
    else
      fprintf(stderr, CV_PROG ": wrote %s\n", path);
    if (c->sweep) {
      snprintf(title, sizeof title, "%s FCM, res %d: error and time vs cut-cell strength m (%s)",
               fcm_element_get_info(c->sweep_element)->name, c->sweep_res, what);
      if (!output_path(path, sizeof path, NULL, c->out, "-sweep.png") ||
          !cv_plot_sweep(path, sw, nsw, title))
        rc = 1;
      else
        fprintf(stderr, CV_PROG ": wrote %s\n", path);
    }
  }
  free(res);
  free(sw);
  cv_study_destroy(&study);
  return rc;
fail:
  fprintf(stderr, CV_PROG ": failed: %s\n", fcm_status_name(st));
  fcm_ctx_error_view(ctx, stderr);
  free(res);
  free(sw);
  cv_study_destroy(&study);
  return 1;
}

/* ---------------------------------------------------------------- payoff */

/* One variant (plain or simplified rules) of one element: per rule kind the cut-cell points,
 * the simplification time and the CPU time of one assembly through a kept workspace. */
typedef struct payoff_variant_result {
  fcm_index cut_cells;
  fcm_index points[FCM_RULE_KIND_COUNT]; /* cut-cell points before stabilization */
  int strength[FCM_RULE_KIND_COUNT];
  double t_simplify[FCM_RULE_KIND_COUNT]; /* core-seconds (fcm_simplify's own times) */
  double t_assembly[FCM_RULE_KIND_COUNT]; /* CPU seconds of one assembly, fastest of repeat */
  double t_rules;                         /* wall seconds of fcm_cell_rules_create */
} payoff_variant_result;

/* One row of the table: an element and a rule kind. */
typedef struct payoff_row {
  fcm_element_type element;
  fcm_rule_kind kind;
  int strength;
  fcm_index cut_cells, points_plain, points_simplified;
  double t_simplify, t_plain, t_simplified; /* core-seconds */
  double point_cost;                        /* core-seconds per point per assembly */
  double per_cell;                          /* simplification core-seconds per cut cell */
  double break_even;                        /* assemblies; INFINITY when nothing is saved */
} payoff_row;

static double cpu_seconds(void)
{
  return (double)clock() / CLOCKS_PER_SEC;
}

/* Build the rules (OFF or ON), then time `repeat` assemblies of each kind after an untimed
 * warm-up: stiffness = stable Neo-Hookean force + tangent at the manufactured displacement
 * (what a Newton iteration assembles), mass = the consistent mass matrix. */
static fcm_status payoff_variant(fcm_ctx *ctx, const config *c, const fcm_mesh *mesh,
                                 const fcm_geometry *geom, int simplify, payoff_variant_result *p)
{
  fcm_status st = FCM_OK;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_assembly_workspace *ws = NULL;
  fcm_csr *A = NULL;
  double *u = NULL, *g = NULL;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_STIFFNESS] = c->setup.strength;
  o.simplify = simplify ? FCM_CELL_SIMPLIFY_ON : FCM_CELL_SIMPLIFY_OFF;
  o.moments = FCM_CELL_MOMENTS_VOLUME; /* the payoff of simplifying the tet rules */
  double t0 = fcm_wtime();
  st = fcm_cell_rules_create(ctx, mesh, geom, &o, &rules);
  if (st != FCM_OK) return st;
  p->t_rules = fcm_wtime() - t0;
  const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(rules);
  p->cut_cells = rs->num_cut;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    p->points[k] = rs->points_simplified[k];
    p->t_simplify[k] = rs->decision[k].time_simplify;
    p->strength[k] = fcm_cell_rules_strength(rules, (fcm_rule_kind)k);
  }
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 5e4, 0.4, 1000.0};
  fcm_material_params mp;
  st = fcm_material_setup(ctx, &mat, &mp);
  if (st == FCM_OK) st = fcm_space_create_embedded(ctx, mesh, rules, &space);
  if (st == FCM_OK) st = fcm_space_matrix_create(space, &A);
  if (st == FCM_OK) st = fcm_assembly_workspace_create(space, NULL, &ws);
  if (st != FCM_OK) goto done;
  const fcm_index n = fcm_space_num_dofs(space), nn = fcm_mesh_num_nodes(mesh);
  u = calloc((size_t)n, sizeof *u), g = calloc((size_t)n, sizeof *g);
  if (!u || !g) {
    st = FCM_ERR_ALLOC;
    goto done;
  }
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index a = 0; a < nn; a++) { /* the manufactured field: strains ~ 1e-2 */
    const fcm_index d = fcm_space_node_dof(space, a);
    if (d >= 0) cv_exact(X + 3 * a, u + d, NULL);
  }
  fcm_linear_form mass = fcm_linear_form_default();
  mass.term = FCM_LINEAR_MASS;
  mass.material = &mat;
  for (int k = 0; k < FCM_RULE_KIND_COUNT && st == FCM_OK; k++) {
    p->t_assembly[k] = INFINITY;
    for (int r = -1; r < c->repeat && st == FCM_OK; r++) { /* r = -1: warm-up */
      fcm_csr_set_zero(A);
      memset(g, 0, sizeof *g * (size_t)n);
      const double c0 = cpu_seconds();
      st = k == FCM_RULE_STIFFNESS ? fcm_assembly_workspace_hyperelastic(ws, &mp, u, NULL, g, A)
                                   : fcm_assembly_workspace_linear(ws, &mass, A, NULL);
      const double dt = cpu_seconds() - c0;
      if (r >= 0) p->t_assembly[k] = fmin(p->t_assembly[k], dt);
    }
  }
  if (st == FCM_OK)
    fprintf(stderr,
            CV_PROG ": payoff: %s: rules %s simplification %.3f s; %lld + %lld cut-cell points; "
                    "assembly %.4f + %.4f CPU s (stiffness + mass, fastest of %d)\n",
            fcm_element_get_info(fcm_mesh_element_type(mesh))->name, simplify ? "with" : "without",
            p->t_rules, (long long)p->points[0], (long long)p->points[1], p->t_assembly[0],
            p->t_assembly[1], c->repeat);
done:
  free(u), free(g);
  fcm_assembly_workspace_destroy(&ws);
  fcm_csr_destroy(&A);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  return st;
}

static void payoff_rows(fcm_element_type e, const payoff_variant_result v[2], payoff_row rows[2])
{
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    payoff_row *r = rows + k;
    r->element = e;
    r->kind = (fcm_rule_kind)k;
    r->strength = v[1].strength[k];
    r->cut_cells = v[1].cut_cells;
    r->points_plain = v[0].points[k], r->points_simplified = v[1].points[k];
    r->t_simplify = v[1].t_simplify[k];
    r->t_plain = v[0].t_assembly[k], r->t_simplified = v[1].t_assembly[k];
    const double gain = r->t_plain - r->t_simplified;
    const double saved = (double)(r->points_plain - r->points_simplified);
    r->point_cost = saved > 0.0 && gain > 0.0 ? gain / saved : NAN;
    r->per_cell = r->cut_cells > 0 ? r->t_simplify / (double)r->cut_cells : NAN;
    r->break_even = gain > 0.0 ? r->t_simplify / gain : INFINITY;
  }
}

static int payoff_write_csv(const char *path, const config *c, const payoff_row *rows, int n)
{
  cli_output *out = NULL;
  FILE *f = cli_output_open(CV_PROG, path, &out);
  if (!f) return 0;
  fprintf(f, "element,res,kind,strength,cut_cells,points_plain,points_simplified,t_simplify,"
             "t_assembly_plain,t_assembly_simplified,point_cost,simplify_per_cell,"
             "break_even_assemblies\n");
  for (int i = 0; i < n; i++) {
    const payoff_row *r = rows + i;
    fprintf(f, "%s,%d,%s,%d,%lld,%lld,%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
            fcm_element_get_info(r->element)->name, c->payoff_res,
            r->kind == FCM_RULE_MASS ? "mass" : "stiffness", r->strength, (long long)r->cut_cells,
            (long long)r->points_plain, (long long)r->points_simplified, r->t_simplify, r->t_plain,
            r->t_simplified, r->point_cost, r->per_cell, r->break_even);
  }
  if (!cli_output_commit(CV_PROG, &out)) return 0;
  fprintf(stderr, CV_PROG ": wrote %s\n", path);
  return 1;
}

static int run_payoff(const config *c, fcm_ctx *ctx)
{
  fcm_geometry *geom = NULL;
  fcm_mesh *mesh = NULL;
  payoff_row rows[2 * FCM_ELEMENT_COUNT];
  int nrows = 0, rc = 0;
  const double center[3] = {0, 0, 0};
  fcm_status st =
      fcm_geometry_create_hemisphere(ctx, center, c->setup.radius, c->setup.geom_n, &geom);
  for (int e = 0; e < c->num_elements && st == FCM_OK; e++) {
    payoff_variant_result v[2];
    memset(v, 0, sizeof v);
    st = cv_mesh_create(ctx, c->elements[e], c->payoff_res, &mesh);
    if (st == FCM_OK)
      fprintf(stderr, CV_PROG ": payoff: %s res %d (%lld cells), hemisphere %lld tets\n",
              fcm_element_get_info(c->elements[e])->name, c->payoff_res,
              (long long)fcm_mesh_num_cells(mesh), (long long)fcm_geometry_num_cells(geom));
    if (st == FCM_OK) st = payoff_variant(ctx, c, mesh, geom, 0, &v[0]);
    if (st == FCM_OK) st = payoff_variant(ctx, c, mesh, geom, 1, &v[1]);
    if (st == FCM_OK) payoff_rows(c->elements[e], v, rows + nrows), nrows += 2;
    fcm_mesh_destroy(&mesh);
  }
  if (st != FCM_OK) {
    fprintf(stderr, CV_PROG ": payoff failed: %s\n", fcm_status_name(st));
    fcm_ctx_error_view(ctx, stderr);
    rc = 1;
    goto done;
  }
  printf("\nsimplification payoff: FCM on the hemisphere (R = %g, %lld tets), res %d (h = %.4f), "
         "manufactured displacement\n",
         c->setup.radius, (long long)fcm_geometry_num_cells(geom), c->payoff_res,
         1.0 / c->payoff_res);
  printf("%-6s %-9s %2s %6s %10s %9s %9s %10s %10s %10s %10s %11s\n", "elem", "kind", "m", "cut",
         "pts plain", "pts simpl", "t_simpl", "t_asm pl", "t_asm si", "s/point", "s/cell",
         "break-even");
  for (int i = 0; i < nrows; i++) {
    const payoff_row *r = rows + i;
    printf("%-6s %-9s %2d %6lld %10lld %9lld %9.4f %10.5f %10.5f %10.3g %10.3g %11.4g\n",
           fcm_element_get_info(r->element)->name, r->kind == FCM_RULE_MASS ? "mass" : "stiffness",
           r->strength, (long long)r->cut_cells, (long long)r->points_plain,
           (long long)r->points_simplified, r->t_simplify, r->t_plain, r->t_simplified,
           r->point_cost, r->per_cell, r->break_even);
  }
  printf(
      "(core-seconds: t_simpl = simplification of the kind's cut-cell rules; t_asm = one\n"
      " assembly with plain / simplified rules, CPU time, fastest of %d: stiffness = Neo-Hookean\n"
      " force + tangent, mass = consistent mass; s/point = (t_asm pl - t_asm si) / (pts plain -\n"
      " pts simpl); break-even = t_simpl / (t_asm pl - t_asm si): simplification pays for\n"
      " more assemblies than that)\n",
      c->repeat);
  if (c->payoff_csv && !payoff_write_csv(c->payoff_csv, c, rows, nrows)) rc = 1;
done:
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&geom);
  return rc;
}

/* ---------------------------------------------------------------- main */

int main(int argc, char **argv)
{
  app_env_init(argc, argv);    /* OpenMP waiting, the CPU's BLAS kernels, huge pages (app_env.h) */
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  config c;
  fcm_ctx *ctx = NULL;
  defaults(&c);
  const int parsed = parse_args(argc, argv, &c);
  if (parsed >= 0) return parsed;
  fcm_status st = fcm_ctx_create(NULL, &ctx);
  if (st != FCM_OK) {
    fprintf(stderr, CV_PROG ": cannot create a context: %s\n", fcm_status_name(st));
    return 1;
  }
  const int rc = c.payoff ? run_payoff(&c, ctx) : run_study(&c, ctx);
  fcm_ctx_destroy(&ctx);
  return rc;
}
