/* fcm-quadrature export: a background grid, an embedded geometry (and optionally a cut), and
 * every cell's rules written to a file for other codes (fcm_cell_rules_write()). */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "fcm-quadrature.h"

#include <fcm/fcm.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* The settings of `export` beyond the grid's. */
typedef struct export_args {
  int sstrength, no_mesh, reference_only;
  const char *cut, *output;
} export_args;

static void export_usage(FILE *f, const cli_option *opts)
{
  fprintf(f, "usage: fcm-quadrature export --element {tet4,tet10,hex8,hex20}\n"
             "           --box X0 Y0 Z0 X1 Y1 Z1 --cells NX NY NZ --geometry FILE|SHAPE\n"
             "           --strength M --output FILE [--mass-strength M] [--surface-strength M]\n"
             "           [--cut SURFACE] [--no-simplify] [--stabilization A] [--min-fraction PHI]\n"
             "           [--no-mesh] [--reference-only] [--fill-holes] [--max-volume V]\n"
             "\n"
             "Builds the background grid (cells numbered i + NX (j + NY k) for hex elements,\n"
             "six tets per cube for tet elements), embeds the geometry, optionally cuts it, and\n"
             "writes every cell's rules to FILE: class and volume fraction per cell; volume,\n"
             "stiffness and mass points per material piece in reference and physical\n"
             "coordinates with weights and flags (1: stabilization point); the surface rule\n"
             "with normals; the mesh. Format: a JSON header and little-endian arrays,\n"
             "lib/docs/rules_format.md. The file is replaced only when complete.\n"
             "\n");
  cli_print_options(f, opts);
}

/* --output given, naming a file in an existing directory; else the exit code after saying why
 * (-1: fine). */
static int export_check(const export_args *a)
{
  if (!a->output) {
    fprintf(stderr, "fcm-quadrature export: --output is required (see --help)\n");
    return 2;
  }
  char dir[4096];
  const char *slash = strrchr(a->output, '/');
  snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - a->output) + 1 : 1,
           slash ? a->output : ".");
  struct stat sb;
  if (!*a->output || (slash && !slash[1]) || stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
    fprintf(stderr, "fcm-quadrature export: --output '%s': not a file in an existing directory\n",
            a->output);
    return 2;
  }
  return -1;
}

/* The arguments joined by spaces into buf (the file's description; cut to fit, control
 * characters replaced by '?'). */
static void join_args(int argc, char **argv, char *buf, size_t cap)
{
  size_t n = (size_t)snprintf(buf, cap, "fcm-quadrature");
  for (int i = 0; i < argc; i++) {
    const int k = snprintf(buf + n, cap - n, " %s", argv[i]);
    if (k < 0 || (size_t)k >= cap - n) break;
    n += (size_t)k;
  }
  for (char *p = buf; *p; p++)
    if ((unsigned char)*p < 0x20 || *p == 0x7f) *p = '?';
}

/* The rules with the cut applied when one is given (*rules replaced); the exit code. */
static int apply_cut(fcm_ctx *ctx, const export_args *a, const fcm_mesh *mesh,
                     const fcm_geometry *geom, fcm_cell_rules **rules)
{
  fcm_surface *cut = NULL;
  fcm_cell_rules *next = NULL;
  if (fcm_surface_create_from_file(ctx, a->cut, &cut) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    fprintf(stderr, "fcm-quadrature export: --cut '%s': not a readable surface file\n", a->cut);
    return 2;
  }
  const fcm_status st = fcm_cell_rules_create_cut(ctx, mesh, geom, *rules, cut, &next);
  fcm_surface_destroy(&cut);
  if (st != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    return 1;
  }
  fcm_cell_rules_destroy(rules);
  *rules = next;
  return 0;
}

/* The grid, the geometry, the rules (cut when asked) and the file; the exit code. */
static int export_run(const fcm_quadrature_grid *g, const export_args *a, const char *description)
{
  int rc = 1;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_cell_rules *rules = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  if ((rc = fcm_quadrature_grid_build(ctx, g, "export", &mesh, &geom)) != 0) goto done;
  rc = 1;
  fcm_cell_rules_options ro = fcm_quadrature_grid_rules_options(g);
  ro.surface_strength = a->sstrength ? a->sstrength : g->strength;
  if (fcm_cell_rules_create(ctx, mesh, geom, &ro, &rules) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    goto done;
  }
  if (a->cut && (rc = apply_cut(ctx, a, mesh, geom, &rules)) != 0) goto done;
  rc = 1;
  fcm_cell_rules_write_options wo = fcm_cell_rules_write_options_default();
  wo.include_mesh = !a->no_mesh;
  wo.include_physical = !a->reference_only;
  wo.description = description;
  if (fcm_cell_rules_write(rules, mesh, a->output, &wo) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    goto done;
  }
  const fcm_cell_rules_stats *s = fcm_cell_rules_get_stats(rules);
  printf("%s: %lld cells (%lld uncut, %lld cut, %lld dropped), %lld pieces, %lld stiffness, "
         "%lld mass, %lld surface points\n",
         a->output, (long long)s->num_cells, (long long)s->num_uncut, (long long)s->num_cut,
         (long long)s->num_dropped, (long long)fcm_cell_rules_num_pieces(rules),
         (long long)s->points_total[FCM_RULE_STIFFNESS], (long long)s->points_total[FCM_RULE_MASS],
         (long long)s->surface_points);
  rc = 0;
done:
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return rc;
}

int fcm_quadrature_cmd_export(int argc, char **argv)
{
  fcm_quadrature_grid g;
  export_args a;
  memset(&a, 0, sizeof a);
  cli_option opts[FCM_QUADRATURE_GRID_OPTIONS + 6];
  fcm_quadrature_grid_init(&g, opts);
  const cli_option own[] = {
      {"--surface-strength", NULL, CLI_INT, &a.sstrength, "M",
       "surface rule strength 1..20 (default --strength)", 1, 20, 0, NULL, NULL, NULL},
      {"--cut", NULL, CLI_STRING, &a.cut, "SURFACE",
       "a cut (triangle surface .obj, .off, .stl, .ply in the\n"
       "geometry's coordinates): cells it splits get one\npiece per side",
       0, 0, 0, NULL, NULL, NULL},
      {"--no-mesh", NULL, CLI_FLAG, &a.no_mesh, NULL,
       "leave the mesh's nodes and cells out of the file", 0, 0, 0, NULL, NULL, NULL},
      {"--reference-only", NULL, CLI_FLAG, &a.reference_only, NULL,
       "leave the physical points and weights out", 0, 0, 0, NULL, NULL, NULL},
      {"--output", "-o", CLI_STRING, &a.output, "FILE", "the rules file (required)", 0, 0, 0, NULL,
       NULL, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  memcpy(opts + FCM_QUADRATURE_GRID_OPTIONS, own, sizeof own);
  const int prc = fcm_quadrature_parse(opts, argc, argv, export_usage);
  if (prc >= 0) return prc;
  int crc = fcm_quadrature_grid_check(&g, "export");
  if (crc < 0) crc = export_check(&a);
  if (crc >= 0) return crc;
  char description[2048];
  join_args(argc, argv, description, sizeof description);
  return export_run(&g, &a, description);
}
