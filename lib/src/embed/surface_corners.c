/* The winding numbers of recent cell corners kept by their bits (fcm__crossings.corner_*):
 * a fan tet's corner seen again (by a neighbouring tet, or the same part's moments at another
 * degree) takes its winding number without a half line of its own (surface_moments.c). */
#include "embed/embed_impl.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

/* The corner table's entry for x (its bits hashed). */
static size_t corner_slot(const double x[3])
{
  uint64_t h = 1469598103934665603u;
  for (int d = 0; d < 3; d++) {
    uint64_t b;
    memcpy(&b, x + d, sizeof b);
    h = (h ^ b) * 1099511628211u;
    h ^= h >> 29;
  }
  return (size_t)(h % FCM__CORNERS);
}

int fcm__embed_corner_find(const fcm__crossings *cr, const fcm_aabb_tree *tree, const double x[3],
                           int *w)
{
  const size_t i = corner_slot(x);
  if (cr->corner_tree != tree || !cr->corner_used[i] || memcmp(cr->corner_x[i], x, 3 * sizeof *x))
    return 0;
  *w = cr->corner_w[i];
  return 1;
}

void fcm__embed_corner_keep(fcm__crossings *cr, const fcm_aabb_tree *tree, const double x[3], int w)
{
  if (cr->corner_tree != tree) {
    memset(cr->corner_used, 0, sizeof cr->corner_used);
    cr->corner_tree = tree;
  }
  const size_t i = corner_slot(x);
  memcpy(cr->corner_x[i], x, 3 * sizeof *x);
  cr->corner_w[i] = w;
  cr->corner_used[i] = 1;
}

int fcm__embed_corner_near(const fcm__crossings *cr)
{
  for (size_t k = 0; k < cr->n; k++)
    if (fabs(cr->z[k] - 1.0) <= FCM__CORNER_GAP) return 1;
  return 0;
}
