/* A block's product in the block sweeps against each entry formed: for every block size from 1
 * to 40 (the X r product takes four rows at a time and the rest one by one, X^T y two rows at
 * a time), dx = X^T X r for a random lower triangular X and dx = S r from S's lower triangle,
 * both packed by rows, agree with the reference to 1e-14 of the largest result; a change of
 * the last row's first entry moves both products. */
#include "mg/mg_impl.h"
#include "solve/solve_impl.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>

#define MMAX 40

static double rnd(unsigned *s)
{
  *s = *s * 1664525u + 1013904223u;
  return (double)(*s >> 8) / 16777216.0 - 0.5;
}

/* max |dx_fast - dx_plain| over max |dx_plain| for the slot S of size m. */
static double paths(const double *S, int m, int factor, const double *r)
{
  double rr[MMAX], f[MMAX], p[MMAX], diff = 0.0, size = 0.0;
  for (int i = 0; i < m; i++)
    rr[i] = r[i];
  fcm__mg_block_apply_paths(S, m, factor, rr, f, p);
  for (int i = 0; i < m; i++) {
    diff = fmax(diff, fabs(f[i] - p[i]));
    size = fmax(size, fabs(p[i]));
  }
  return size > 0.0 ? diff / size : diff;
}

int main(void)
{
  unsigned seed = 7;
  double S[MMAX * (MMAX + 1) / 2], r[MMAX];
  for (int m = 1; m <= MMAX; m++) {
    for (int i = 0; i < m; i++) {
      r[i] = rnd(&seed);
      for (int j = 0; j <= i; j++) /* a diagonal away from zero, as a factor's inverse */
        S[FCM__SCHWARZ_PACKED(i, j)] = i == j ? 1.0 + rnd(&seed) : rnd(&seed);
    }
    const double ef = paths(S, m, 1, r), es = paths(S, m, 0, r);
    TEST_TRUE(ef <= 1e-14 && es <= 1e-14);
    if (m >= 2) { /* the last row's first entry changed: both products see it */
      double *e = S + FCM__SCHWARZ_PACKED(m - 1, 0);
      const double keep = *e;
      double rr[MMAX], f0[MMAX], f1[MMAX], p[MMAX], moved = 0.0;
      for (int factor = 0; factor < 2; factor++) {
        for (int i = 0; i < m; i++)
          rr[i] = r[i];
        fcm__mg_block_apply_paths(S, m, factor, rr, f0, p);
        *e = keep + 0.25;
        for (int i = 0; i < m; i++)
          rr[i] = r[i];
        fcm__mg_block_apply_paths(S, m, factor, rr, f1, p);
        *e = keep;
        for (int i = 0; i < m; i++)
          moved = fmax(moved, fabs(f1[i] - f0[i]));
        TEST_TRUE(moved > 1e-6);
      }
    }
    if (m % 8 == 0 || m < 6)
      printf("m = %2d: X^T X r %.1e, S r %.1e relative to the reference\n", m, ef, es);
  }
  return TEST_RESULT();
}
