/* Small 3-vector helpers for geometry loops (internal). Vectors are double[3]; the results
 * may alias an argument only where said. Beside mat3.h, which holds the 3x3 matrix ones. */
#ifndef FCM_VEC3_H
#define FCM_VEC3_H

#include <math.h>

/* a . b */
static inline double fcm__vec3_dot(const double a[3], const double b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* c = a - b (c may alias a or b). */
static inline void fcm__vec3_sub(const double a[3], const double b[3], double c[3])
{
  c[0] = a[0] - b[0], c[1] = a[1] - b[1], c[2] = a[2] - b[2];
}

/* c = a x b (c may not alias a or b). */
static inline void fcm__vec3_cross(const double a[3], const double b[3], double c[3])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

/* |a| */
static inline double fcm__vec3_norm(const double a[3])
{
  return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/* u . (v x w), the determinant of the matrix with rows u, v, w (fcm__mat3_det's order). */
static inline double fcm__vec3_det(const double u[3], const double v[3], const double w[3])
{
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

#endif
