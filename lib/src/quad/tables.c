/* Compiled-in rule tables from quadrature_tables/: lookup over the arrays that the
 * build generates (lib/cmake/embed_tables.cmake). The catalogue asks here first. */
#include "quad_impl.h"
#include "tables_impl.h"

int fcm__quad_table_lookup(fcm_shape shape, int strength, int *n, const double **points,
                           const double **weights, const char **description)
{
  for (int i = 0; i < fcm__quad_num_tables; i++) {
    const fcm__quad_table *t = &fcm__quad_tables[i];
    if (t->shape != shape || t->strength != strength || t->n <= 0) continue;
    *n = t->n;
    *points = t->points;
    *weights = t->weights;
    *description = t->description;
    return 1;
  }
  return 0;
}
