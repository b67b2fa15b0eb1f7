/* apps: the unit sphere triangulation of app_sphere.h. */
#include "app_sphere.h"

#include <math.h>
#include <stdlib.h>

void app_sphere_free(app_sphere_mesh *s)
{
  free(s->x);
  free(s->t);
  s->x = NULL, s->t = NULL;
}

int app_cube_sphere(int m, app_sphere_mesh *s)
{
  const long long side = m + 1;
  long long *id = malloc(sizeof *id * (size_t)(side * side * side));
  s->x = NULL, s->t = NULL, s->nv = 0, s->nt = 12LL * m * m;
  if (!id) return 0;
  for (long long k = 0; k < side; k++)
    for (long long j = 0; j < side; j++)
      for (long long i = 0; i < side; i++) {
        const int on = i == 0 || j == 0 || k == 0 || i == m || j == m || k == m;
        id[i + side * (j + side * k)] = on ? s->nv++ : -1;
      }
  s->x = malloc(sizeof *s->x * 3 * (size_t)s->nv);
  s->t = malloc(sizeof *s->t * 3 * (size_t)s->nt);
  if (!s->x || !s->t) {
    free(id);
    app_sphere_free(s);
    return 0;
  }
  for (long long k = 0; k < side; k++)
    for (long long j = 0; j < side; j++)
      for (long long i = 0; i < side; i++) {
        const long long v = id[i + side * (j + side * k)];
        if (v < 0) continue;
        double p[3] = {2.0 * (double)i / m - 1.0, 2.0 * (double)j / m - 1.0,
                       2.0 * (double)k / m - 1.0};
        const double r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (int d = 0; d < 3; d++)
          s->x[3 * v + d] = p[d] / r;
      }
  long long t = 0;
  for (int d = 0; d < 3; d++)
    for (int sd = 0; sd < 2; sd++) {
      const int u = (d + 1) % 3, w = (d + 2) % 3;
      for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++) {
          long long c[4];
          static const int du[4] = {0, 1, 1, 0}, dw[4] = {0, 0, 1, 1};
          for (int q = 0; q < 4; q++) {
            long long p[3];
            p[d] = sd ? m : 0, p[u] = a + du[q], p[w] = b + dw[q];
            c[q] = id[p[0] + side * (p[1] + side * p[2])];
          }
          /* (c0, c1, c2) turns about +e_d: outward on the side at +1 */
          const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
          for (int h = 0; h < 2; h++, t++)
            for (int q = 0; q < 3; q++)
              s->t[3 * t + q] = c[tri[h][sd ? q : (3 - q) % 3]];
        }
    }
  free(id);
  return 1;
}
