/* fcm-quadrature: subcommands implemented outside fcm-quadrature.c and the option parsing
 * they share. Each subcommand takes its arguments from its own name on (argv[0] = the name)
 * and returns the exit code. */
#ifndef FCM_QUADRATURE_APP_H
#define FCM_QUADRATURE_APP_H

#include "cli.h"

#include <fcm/fcm.h>
#include <stdio.h>

/** Parse a subcommand's options `opts` (messages start "fcm-quadrature NAME:"); --help prints
 *  help(stdout, opts). Returns -1 to go on, else the exit code: 0 after --help, 2 on a usage
 *  error. */
int fcm_quadrature_parse(const cli_option *opts, int argc, char **argv,
                         void (*help)(FILE *f, const cli_option *opts));

/** The settings `embed` and `export` share: the background grid, the embedded geometry and
 *  the cell rules (fcm-quadrature-grid.c). */
typedef struct fcm_quadrature_grid {
  fcm_element_type type;
  double box[6], alpha, phimin, max_volume;
  int cells[3], strength, mstrength, no_simplify, have_box, fill_holes;
  const char *geometry;
} fcm_quadrature_grid;

/** Number of options fcm_quadrature_grid_init() fills. */
#define FCM_QUADRATURE_GRID_OPTIONS 11

/** Defaults into *g and its options (--element, --box, --cells, --geometry, --fill-holes,
 *  --max-volume, --strength, --mass-strength, --no-simplify, --stabilization, --min-fraction)
 *  into opts, pointing into *g; the caller appends its own and the terminator. */
void fcm_quadrature_grid_init(fcm_quadrature_grid *g, cli_option opts[FCM_QUADRATURE_GRID_OPTIONS]);

/** The required options present and the box not empty; else the exit code 2 after saying why
 *  (messages start "fcm-quadrature CMD:"); -1 when fine. */
int fcm_quadrature_grid_check(const fcm_quadrature_grid *g, const char *cmd);

/** The cell rules options of the command line (strengths, simplification, stabilization,
 *  minimum fraction). */
fcm_cell_rules_options fcm_quadrature_grid_rules_options(const fcm_quadrature_grid *g);

/** The box grid and the geometry (a shape spec or a file by its extension); 0, else the exit
 *  code after saying why (2: a geometry that is neither a readable file nor a shape). */
int fcm_quadrature_grid_build(fcm_ctx *ctx, const fcm_quadrature_grid *g, const char *cmd,
                              fcm_mesh **mesh, fcm_geometry **geom);

int fcm_quadrature_cmd_accuracy(int argc, char **argv);
int fcm_quadrature_cmd_export(int argc, char **argv);
int fcm_quadrature_cmd_embed(int argc, char **argv);

#endif
