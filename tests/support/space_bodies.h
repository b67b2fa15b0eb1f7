/* Shared by the tests of cut spaces (tests/fem, tests/embed): the body of every element of a
 * space, from the DOF copies the elements share. */
#ifndef FCM_TEST_SPACE_BODIES_H
#define FCM_TEST_SPACE_BODIES_H

#include "fcm/fem.h"
#include "fcm/mesh.h"

#include <stdlib.h>

static inline fcm_index space_bodies_find(fcm_index *uf, fcm_index a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return a;
}

/* Body of every element (0 .. *count-1, numbered by their first element): elements sharing a
 * DOF copy are one body. Returns a malloc'ed array of num_elements labels. */
static inline fcm_index *space_element_bodies(const fcm_space *s, int *count)
{
  const fcm_index ne = fcm_space_num_elements(s), nd = fcm_space_num_dofs(s);
  const int nn = fcm_mesh_nodes_per_cell(fcm_space_mesh(s));
  fcm_index *uf = malloc(sizeof *uf * (size_t)ne), *first = malloc(sizeof *first * (size_t)nd);
  fcm_index *label = malloc(sizeof *label * (size_t)ne), *root = malloc(sizeof *root * (size_t)ne);
  for (fcm_index e = 0; e < ne; e++)
    uf[e] = e, root[e] = -1;
  for (fcm_index k = 0; k < nd; k++)
    first[k] = -1;
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index *ed = fcm_space_element_dofs(s, e);
    for (int a = 0; a < nn; a++) {
      if (first[ed[a]] < 0) {
        first[ed[a]] = e;
        continue;
      }
      const fcm_index x = space_bodies_find(uf, e), y = space_bodies_find(uf, first[ed[a]]);
      if (x != y) uf[x > y ? x : y] = x < y ? x : y;
    }
  }
  int n = 0;
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index r = space_bodies_find(uf, e);
    if (root[r] < 0) root[r] = n++;
    label[e] = root[r];
  }
  *count = n;
  free(uf), free(first), free(root);
  return label;
}

#endif
