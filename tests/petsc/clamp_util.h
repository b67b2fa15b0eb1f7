/* Shared by the PETSc multigrid tests (tests/petsc/pcmg.c, pcmg_failure.c): the clamped nodes
 * of a body embedded in a box grid. */
#ifndef FCM_TESTS_PETSC_CLAMP_UTIL_H
#define FCM_TESTS_PETSC_CLAMP_UTIL_H

#include "fcm/fem.h"
#include "fcm/mesh.h"

#include <stdlib.h>

/* Nodes with DOFs on the lowest z with DOFs (calloc'ed; *nfix of them; NULL when out of
 * memory). */
static inline fcm_index *clamped(const fcm_mesh *mesh, const fcm_space *space, fcm_index *nfix)
{
  const double *X = fcm_mesh_coords(mesh);
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  fcm_index *fix = calloc((size_t)nn + 1, sizeof *fix);
  double zmin = 2.0;
  *nfix = 0;
  if (!fix) return NULL;
  for (fcm_index k = 0; k < nn; k++)
    if (fcm_space_node_dof(space, k) >= 0 && X[3 * k + 2] < zmin) zmin = X[3 * k + 2];
  for (fcm_index k = 0; k < nn; k++)
    if (fcm_space_node_dof(space, k) >= 0 && X[3 * k + 2] <= zmin + 1e-12) fix[(*nfix)++] = k;
  return fix;
}

#endif
