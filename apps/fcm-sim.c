/* fcm-sim: the main program. Until the FEM slice lands it prints the element
 * and quadrature rule catalogue. */
#include <fcm/fcm.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void usage(FILE *f)
{
  fprintf(f, "usage: fcm-sim [--help]\n"
             "Prints the element and quadrature rule catalogue of this fcm build.\n");
}

int main(int argc, char **argv)
{
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
      usage(stdout);
      return 0;
    }
    fprintf(stderr, "fcm-sim: unknown argument '%s'\n", argv[i]);
    usage(stderr);
    return 2;
  }
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) {
    fprintf(stderr, "fcm-sim: cannot create context\n");
    return 1;
  }
  printf("fcm %s\n", "0.1.0");
  fcm_ctx_destroy(&ctx);
  return 0;
}
