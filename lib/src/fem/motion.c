/* Prescribed motions of node sets (fcm/motion.h): the default fixed motion, whether a motion
 * holds its nodes at a time, and the displacement and velocity it prescribes. */
#include "fcm/motion.h"

#include <math.h>
#include <string.h>

fcm_motion fcm_motion_default(void)
{
  fcm_motion m;
  memset(&m, 0, sizeof m);
  m.axis[2] = 1.0;
  m.end = HUGE_VAL;
  m.components[0] = m.components[1] = m.components[2] = 1;
  return m;
}

int fcm_motion_active(const fcm_motion *m, double t)
{
  return !(m->release && t > m->end);
}

void fcm_motion_eval(const fcm_motion *m, const double X[3], double t, double u[3], double v[3])
{
  double span = m->end - m->start, tau = t - m->start;
  if (!(tau > 0.0)) tau = 0.0;
  if (tau > span) tau = span;
  double a[3] = {m->axis[0], m->axis[1], m->axis[2]};
  double an = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  /* Rodrigues: R r = r + s (a x r) + (1 - c) a x (a x r); u = (R r - r) + velocity tau, so a
   * pure translation is exact and the axial component of a rotation is exactly zero. */
  double r[3], du[3] = {0, 0, 0};
  for (int i = 0; i < 3; i++)
    r[i] = X[i] - m->center[i];
  if (an > 0.0 && m->angular_speed != 0.0) {
    for (int i = 0; i < 3; i++)
      a[i] /= an;
    double phi = m->angular_speed * tau, c = cos(phi), s = sin(phi);
    double axr[3] = {a[1] * r[2] - a[2] * r[1], a[2] * r[0] - a[0] * r[2],
                     a[0] * r[1] - a[1] * r[0]};
    double aaxr[3] = {a[1] * axr[2] - a[2] * axr[1], a[2] * axr[0] - a[0] * axr[2],
                      a[0] * axr[1] - a[1] * axr[0]};
    for (int i = 0; i < 3; i++)
      du[i] = s * axr[i] + (1.0 - c) * aaxr[i];
  } else {
    an = 0.0;
  }
  for (int i = 0; i < 3; i++)
    u[i] = du[i] + m->velocity[i] * tau;
  if (v) {
    int moving = t >= m->start && t < m->end;
    for (int i = 0; i < 3; i++)
      v[i] = moving ? m->velocity[i] : 0.0;
    if (moving && an > 0.0) {
      double w = m->angular_speed, rr[3];
      for (int i = 0; i < 3; i++)
        rr[i] = r[i] + du[i];
      v[0] += w * (a[1] * rr[2] - a[2] * rr[1]);
      v[1] += w * (a[2] * rr[0] - a[0] * rr[2]);
      v[2] += w * (a[0] * rr[1] - a[1] * rr[0]);
    }
  }
}
