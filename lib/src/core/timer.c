/* Wall-clock timers from the POSIX monotonic clock. */
#define _POSIX_C_SOURCE 199309L
#include "core_impl.h"

#include <time.h>

double fcm_wtime(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

fcm_timer fcm_timer_init(void)
{
  fcm_timer t = {0.0, -1.0, 0};
  return t;
}

void fcm_timer_start(fcm_timer *t)
{
  if (t->started < 0.0) t->started = fcm_wtime();
}

void fcm_timer_stop(fcm_timer *t)
{
  if (t->started < 0.0) return;
  t->total += fcm_wtime() - t->started;
  t->started = -1.0;
  t->count++;
}
