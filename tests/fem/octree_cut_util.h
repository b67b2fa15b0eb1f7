/* Shared parts of the octree cut tests: a box body on an octree refined in a slab the cut
 * crosses, cut by a plane; the hanging-node matrix T applied to a field's free copies; the
 * patch solve through T^T K T with a field prescribed on the box boundary. */
#ifndef FCM_TEST_OCTREE_CUT_UTIL_H
#define FCM_TEST_OCTREE_CUT_UTIL_H

#include "fcm/fcm.h"
#include "fem/fem_impl.h"
#include "fem_util.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The unit box body on an octree of `type` (2^3 level-0 cells, levels up to `region_level` in
 * the slab [0,1] x [0,0.3] x [0,0.6]), cut by the plane through p with normal n, its space with
 * `constrain_ratio` (stabilization off, so slivers show). */
typedef struct {
  fcm_mesh *mesh;
  fcm_geometry *body;
  fcm_surface *cut;
  fcm_cell_rules *rules, *cut_rules;
  fcm_space *space;
} octree_cut_case;

static inline void octree_cut_case_create(fcm_ctx *ctx, fcm_element_type type, int region_level,
                                          const double p[3], const double n[3],
                                          double constrain_ratio, octree_cut_case *t)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, clo[3] = {-0.2, -0.2, -0.2},
               chi[3] = {1.2, 1.2, 1.2};
  const fcm_index n2[3] = {2, 2, 2};
  memset(t, 0, sizeof *t);
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, n2, &t->body));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, n, clo, chi, &t->cut));
  fcm_octree_options o = fcm_octree_options_default();
  o.region_level = region_level;
  memcpy(o.region_hi, (double[3]){1.0, 0.3, 0.6}, sizeof o.region_hi);
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, type, lo, hi, n2, &o, &t->mesh));
  TEST_TRUE(fcm_mesh_max_level(t->mesh) == region_level && fcm_mesh_num_hanging(t->mesh) > 0);
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.stabilization.mode = FCM_STABILIZATION_OFF;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, t->mesh, t->body, &ro, &t->rules));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, t->mesh, t->body, t->rules, t->cut, &t->cut_rules));
  fcm_space_options so = fcm_space_options_default();
  so.constrain_ratio = constrain_ratio;
  TEST_OK(ctx, fcm_space_create_embedded_with(ctx, t->mesh, t->cut_rules, &so, &t->space));
  TEST_TRUE(fcm_space_num_bodies(t->space) == 2);
}

static inline void octree_cut_case_destroy(octree_cut_case *t)
{
  fcm_space_destroy(&t->space);
  fcm_cell_rules_destroy(&t->cut_rules);
  fcm_cell_rules_destroy(&t->rules);
  fcm_surface_destroy(&t->cut);
  fcm_geometry_destroy(&t->body);
  fcm_mesh_destroy(&t->mesh);
}

/* The largest |T u_free - ue| over the nd DOFs (only[r] != 0: over the hanging copies r with
 * only[r] set). */
static inline double octree_t_error(fcm_ctx *ctx, const fcm_csr *T, const fcm_index *free_dof,
                                    const double *ue, fcm_index nd, const unsigned char *only)
{
  fcm_index ncol = 0;
  fcm_csr_get_size(T, NULL, &ncol, NULL);
  double *uf = calloc((size_t)ncol, sizeof *uf), *ut = calloc((size_t)nd, sizeof *ut);
  for (fcm_index i = 0; i < nd; i++)
    if (free_dof[i] >= 0) uf[free_dof[i]] = ue[i];
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, uf, 0.0, ut));
  double err = 0.0;
  for (fcm_index i = 0; i < nd; i++)
    if (!only || (only[i / 3] && free_dof[i] < 0)) err = fmax(err, fabs(ut[i] - ue[i]));
  free(uf), free(ut);
  return err;
}

/* u = T v with v the static solve of T^T K T v = 0, ue prescribed on the free copies of the
 * nodes on the box's boundary. */
static inline void octree_patch_solve(fcm_ctx *ctx, const fcm_space *s, const fcm_csr *K,
                                      const fcm_csr *T, const fcm_index *free_dof, const double *ue,
                                      double *u)
{
  const fcm_mesh *m = fcm_space_mesh(s);
  const double *X = fcm_mesh_coords(m);
  fcm_index nr = 0;
  fcm_csr_get_size(T, NULL, &nr, NULL);
  fcm_csr *Kr = NULL;
  TEST_OK(ctx, fcm_csr_create_ptap(ctx, K, T, &Kr));
  double *b = calloc((size_t)nr, sizeof *b), *v = calloc((size_t)nr, sizeof *v);
  double *g = calloc((size_t)nr, sizeof *g);
  unsigned char *con = calloc((size_t)nr, 1);
  for (fcm_index a = 0; a < fcm_mesh_num_nodes(m); a++) {
    int boundary = 0;
    for (int d = 0; d < 3; d++)
      boundary |= X[3 * a + d] == 0.0 || X[3 * a + d] == 1.0;
    const fcm_index d0 = fcm_space_node_dof(s, a);
    for (fcm_index k = 0; boundary && d0 >= 0 && k < 3 * fcm_space_node_copies(s, a); k++)
      if (free_dof[d0 + k] >= 0) con[free_dof[d0 + k]] = 1, g[free_dof[d0 + k]] = ue[d0 + k];
  }
  fcm__eliminate_marked(Kr, b, con, g);
  TEST_OK(ctx, direct_solve(ctx, Kr, b, v));
  TEST_OK(ctx, fcm_csr_apply(T, 1.0, v, 0.0, u));
  free(b), free(v), free(g), free(con);
  fcm_csr_destroy(&Kr);
}

#endif
