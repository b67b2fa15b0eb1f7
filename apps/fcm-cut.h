/* fcm-cut: the parts of the program shared between its files (fcm-cut.c: dice, condition and
 * main; fcm-cut-accuracy.c: the accuracy study). */
#ifndef FCM_APPS_FCM_CUT_H
#define FCM_APPS_FCM_CUT_H

#include <fcm/fcm.h>

#define PROG "fcm-cut"

/* The context's last error on stderr, prefixed with the program's name. */
void fcm_cut_report(fcm_ctx *ctx);

/* The accuracy study (Koschier et al. 2017, Table 1 analogue) for strengths 1..max_strength;
 * CSV and PNG when their paths are given. 0 when the claims hold, 1 otherwise. */
int fcm_cut_accuracy(fcm_ctx *ctx, const char *csvpath, const char *pngpath, int max_strength);

#endif
