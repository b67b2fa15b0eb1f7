/* fcm quad, internal: the compiled-in rule tables. The data file is generated at
 * build time from quadrature_tables/<shape>/<shape>_<mm>.txt by lib/cmake/embed_tables.cmake. */
#ifndef FCM_QUAD_TABLES_IMPL_H
#define FCM_QUAD_TABLES_IMPL_H

#include "fcm/element.h"

/* One stored rule: n points (n x dim, row-major, reference coordinates) and weights. */
typedef struct fcm__quad_table {
  fcm_shape shape;
  int strength;
  int n;
  const double *points;
  const double *weights;
  const char *description;
} fcm__quad_table;

/* The tables (fcm__quad_num_tables entries; a single empty sentinel when none). */
extern const fcm__quad_table fcm__quad_tables[];
extern const int fcm__quad_num_tables;

#endif /* FCM_QUAD_TABLES_IMPL_H */
