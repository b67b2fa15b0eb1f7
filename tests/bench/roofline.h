/* bench_roofline's parts (tests/bench/bench_roofline.c has the whole picture): a row's result,
 * the table of rows, the timing helpers, and the rows each part measures. */
#ifndef FCM_BENCH_ROOFLINE_H
#define FCM_BENCH_ROOFLINE_H

#include "fcm/fcm.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One measurement: the problem size, the best time and the work done in it (flops or bytes). */
typedef struct bench_result {
  double size; /* n of DGEMM, doubles per triad array, DOFs of the factorization */
  double seconds;
  double work;
  double check; /* a number every kernel set must reproduce to round-off (0: none) */
} bench_result;

typedef struct bench_item {
  const char *name; /* the row's name */
  const char *unit; /* "GFLOP/s" (work in flops) or "GB/s" (work in bytes) */
  const char *peak; /* the row whose best rate is the peak this one is a fraction of */
  int (*run)(fcm_ctx *ctx, int cells, bench_result *r);
} bench_item;

/* The checks of the row files: test.h counts its failures per source file, so these count in
 * roofline_failures, which the driver adds to its own before it exits. */
extern int roofline_failures;
#define ROOFLINE_CHECK(cond)                                                                       \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);                     \
      roofline_failures++;                                                                         \
    }                                                                                              \
  } while (0)

/* CPU seconds of the process (one thread in the child): on cores shared with other work the
 * wall clock would also measure that work. */
double roofline_cpu_seconds(void);
/* The least time of reps calls of fn(arg), CPU seconds. */
double roofline_best_of(int reps, void (*fn)(void *), void *arg);

/* The core's peaks and the factorization (roofline_peaks.c). */
int run_dgemm(fcm_ctx *ctx, int cells, bench_result *r);
int run_triad(fcm_ctx *ctx, int cells, bench_result *r);
int run_cholmod(fcm_ctx *ctx, int cells, bench_result *r);

/* fcm's element kernels and CSR SpMV (roofline_kernels.c). */
int run_hex8_stiffness(fcm_ctx *ctx, int cells, bench_result *r);
int run_hex20_stiffness(fcm_ctx *ctx, int cells, bench_result *r);
int run_tet10_stiffness(fcm_ctx *ctx, int cells, bench_result *r);
int run_hex20_snh(fcm_ctx *ctx, int cells, bench_result *r);
int run_hex20_mass(fcm_ctx *ctx, int cells, bench_result *r);
int run_spmv(fcm_ctx *ctx, int cells, bench_result *r);

/* Simplification at strength m (roofline_simplify.c): the default fit, the rank-1 and the
 * blocked elimination. */
#define ROOFLINE_SIMP_DECL(m)                                                                      \
  int run_simp_fit_m##m(fcm_ctx *ctx, int cells, bench_result *r);                                 \
  int run_simp_elim1_m##m(fcm_ctx *ctx, int cells, bench_result *r);                               \
  int run_simp_elim_m##m(fcm_ctx *ctx, int cells, bench_result *r);
ROOFLINE_SIMP_DECL(3)
ROOFLINE_SIMP_DECL(5)
ROOFLINE_SIMP_DECL(7)
ROOFLINE_SIMP_DECL(9)
#undef ROOFLINE_SIMP_DECL

#endif /* FCM_BENCH_ROOFLINE_H */
