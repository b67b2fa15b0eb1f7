/* Benchmark of the element hot paths (label "bench"): nanoseconds per call of
 * shape values, gradients, map, Jacobian and inverse map for every element type. */
#include "fcm/element.h"
#include <math.h>
#include <stdio.h>

#define REPS 100000

static volatile double sink; /* keeps the loops from being optimized away */

int main(void)
{
  printf("%-6s %9s %9s %9s %9s %12s %12s\n", "type", "shape", "grad", "map", "jacobian",
         "inv(affine)", "inv(newton)");
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++) {
    const fcm_element_info *info = fcm_element_get_info((fcm_element_type)t);
    const double *ref = fcm_element_ref_nodes(info->type);
    const int n = info->num_nodes;
    double X[3 * FCM_ELEMENT_MAX_NODES], Xd[3 * FCM_ELEMENT_MAX_NODES];
    for (int a = 0; a < n; a++)
      for (int d = 0; d < 3; d++) {
        X[3 * a + d] = 2.0 * ref[3 * a + d] + 0.3 * ref[3 * a + (d + 1) % 3];
        Xd[3 * a + d] = X[3 * a + d] + 0.05 * sin(3.0 * a + d);
      }
    double N[FCM_ELEMENT_MAX_NODES], dN[3 * FCM_ELEMENT_MAX_NODES], J[9], x[3], s = 0.0;
    double ns[6];
    const double c = info->shape == FCM_SHAPE_TET ? 0.2 : 0.1;
    for (int k = 0; k < 6; k++) {
      const int reps = k >= 4 ? REPS / 10 : REPS;
      ns[k] = INFINITY;
      for (int trial = 0; trial < 3; trial++) { /* best of three: the machine may be shared */
        double t0 = fcm_wtime();
        for (int r = 0; r < reps; r++) {
          double xi[3] = {c + 1e-7 * (r & 15), c, c};
          switch (k) {
          case 0:
            fcm_element_eval_shape(info->type, xi, N), s += N[n - 1];
            break;
          case 1:
            fcm_element_eval_grad(info->type, xi, dN), s += dN[3 * n - 1];
            break;
          case 2:
            fcm_element_map(info->type, X, xi, x), s += x[0];
            break;
          case 3:
            s += fcm_element_jacobian(info->type, X, xi, J);
            break;
          case 4:
          case 5: {
            double y[3] = {0.1 + 1e-7 * (r & 15), 0.2, 0.05}, eta[3];
            if (fcm_element_inverse_map(NULL, info->type, k == 4 ? X : Xd, y, eta) != FCM_OK)
              return 1;
            s += eta[0];
          } break;
          default:
            break;
          }
        }
        ns[k] = fmin(ns[k], 1e9 * (fcm_wtime() - t0) / reps);
      }
    }
    sink = s;
    printf("%-6s %9.1f %9.1f %9.1f %9.1f %12.1f %12.1f\n", info->name, ns[0], ns[1], ns[2], ns[3],
           ns[4], ns[5]);
  }
  return 0;
}
