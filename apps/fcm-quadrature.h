/* fcm-quadrature: subcommands implemented outside fcm-quadrature.c. Each takes
 * the arguments after the subcommand name and returns the exit code. */
#ifndef FCM_QUADRATURE_APP_H
#define FCM_QUADRATURE_APP_H

int fcm_quadrature_cmd_accuracy(int argc, char **argv);
int fcm_quadrature_cmd_embed(int argc, char **argv);

#endif
