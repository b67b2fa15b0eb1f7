/* fcm-quadrature: subcommands implemented outside fcm-quadrature.c and the option parsing
 * they share. Each subcommand takes its arguments from its own name on (argv[0] = the name)
 * and returns the exit code. */
#ifndef FCM_QUADRATURE_APP_H
#define FCM_QUADRATURE_APP_H

#include "cli.h"

#include <stdio.h>

/** Parse a subcommand's options `opts` (messages start "fcm-quadrature NAME:"); --help prints
 *  help(stdout, opts). Returns -1 to go on, else the exit code: 0 after --help, 2 on a usage
 *  error. */
int fcm_quadrature_parse(const cli_option *opts, int argc, char **argv,
                         void (*help)(FILE *f, const cli_option *opts));

int fcm_quadrature_cmd_accuracy(int argc, char **argv);
int fcm_quadrature_cmd_embed(int argc, char **argv);

#endif
