/* apps: a closed, outward-oriented triangulation of the unit sphere that the programs deform
 * into their generated test surfaces (fcm-models' bumpy sphere and ball, fcm-cutbench's
 * bunny-like body). Not part of the library. */
#ifndef FCM_APP_SPHERE_H
#define FCM_APP_SPHERE_H

#include <fcm/core.h>

/** A sphere triangulation: the surface grid of the cube [-1,1]^3 with m segments per edge (two
 * triangles per square, 12 m^2 in all, oriented outward), every vertex pushed onto the unit
 * sphere. Vertices on the cube's edges are shared, so the surface is closed and manifold. */
typedef struct app_sphere_mesh {
  long long nv, nt;
  double *x;    /* nv x 3 */
  fcm_index *t; /* nt x 3 */
} app_sphere_mesh;

/** Build it with m >= 1 segments per cube edge; 0 when out of memory (s holds nothing). */
int app_cube_sphere(int m, app_sphere_mesh *s);

/** Release its arrays; accepts an empty mesh. */
void app_sphere_free(app_sphere_mesh *s);

#endif /* FCM_APP_SPHERE_H */
