/* sim: continue a run on a refined background (fcm_integrator_create_refined()): the old
 * integrator's effects on the new space, its node constraints mapped onto the new nodes, and
 * its state interpolated at the new nodes. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <string.h>

/* Where the new space's DOF nodes lie in the old space. */
typedef struct refine_map {
  fcm_index num;   /* DOF nodes of the new space */
  fcm_index *node; /* num: their node ids in the new mesh */
  fcm_index *cell; /* num: the old active cell holding each (fcm_space_locate()) */
  double *xi;      /* num x 3: the reference coordinates there */
  int *extra;      /* num: 1 when in no old active cell (extrapolated) */
  double *val;     /* num x 3: scratch for interpolated values */
} refine_map;

static void refine_map_free(fcm_ctx *ctx, refine_map *m)
{
  fcm__free(ctx, m->node);
  fcm__free(ctx, m->cell);
  fcm__free(ctx, m->xi);
  fcm__free(ctx, m->extra);
  fcm__free(ctx, m->val);
}

static fcm_status refine_map_build(const fcm_space *from, const fcm_space *to, refine_map *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to->ctx;
  double *X = NULL;
  const fcm_mesh *mesh = fcm_space_mesh(to);
  const double *coords = fcm_mesh_coords(mesh);
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  fcm_index num = 0;
  for (fcm_index n = 0; n < nn; n++)
    num += fcm_space_node_dof(to, n) >= 0;
  const size_t cap = (size_t)FCM_MAX(num, 1);
  FCM_ALLOC_RAW(ctx, cap, m->node);
  FCM_ALLOC_RAW(ctx, cap, m->cell);
  FCM_ALLOC_RAW(ctx, 3 * cap, m->xi);
  FCM_ALLOC_RAW(ctx, cap, m->extra);
  FCM_ALLOC_RAW(ctx, 3 * cap, m->val);
  FCM_ALLOC_RAW(ctx, 3 * cap, X);
  for (fcm_index n = 0; n < nn; n++) {
    if (fcm_space_node_dof(to, n) < 0) continue;
    m->node[m->num] = n;
    memcpy(X + 3 * m->num, coords + 3 * n, 3 * sizeof *X);
    m->num++;
  }
  FCM_TRY(ctx, fcm_space_locate(from, m->num, X, m->cell, m->xi, m->extra));
cleanup:
  fcm__free(ctx, X);
  return st;
}

/* x_new = the old field x_old interpolated at the new DOF nodes (extrapolated from the nearest
 * old active cell where a node lies in none). */
static fcm_status refine_map_field(const fcm_space *from, const fcm_space *to, refine_map *m,
                                   const double *x_old, double *x_new)
{
  fcm_status st = fcm_space_interpolate(from, m->num, m->cell, m->xi, x_old, m->val);
  if (st != FCM_OK) return st;
  memset(x_new, 0, sizeof *x_new * (size_t)fcm_space_num_dofs(to));
  for (fcm_index i = 0; i < m->num; i++)
    memcpy(x_new + fcm_space_node_dof(to, m->node[i]), m->val + 3 * i, 3 * sizeof *x_new);
  return FCM_OK;
}

/* The new nodes constraint c holds: those whose old field depends on held old nodes only
 * (every node of the old cell whose shape function is nonzero there is held): an old held
 * node, and a new node on an edge, a face or inside an old cell whose nodes there are all
 * held. The prescribed motions are affine in the position, which the old space reproduces, so
 * the old constraint already fixed the field at these points. */
static fcm_status map_constraint(fcm_integrator *I, const fcm_integrator *old,
                                 const sim_constraint *c, const refine_map *m, unsigned char *held,
                                 fcm_index *nodes)
{
  const fcm_mesh *om = fcm_space_mesh(old->space);
  const int npc = fcm_mesh_nodes_per_cell(om);
  const fcm_index *cells = fcm_mesh_cells(om);
  const fcm_element_type type = fcm_mesh_element_type(om);
  double N[FCM_ELEMENT_MAX_NODES];
  fcm_index num = 0;
  memset(held, 0, (size_t)fcm_mesh_num_nodes(om));
  for (fcm_index j = 0; j < c->num_nodes; j++)
    held[c->nodes[j]] = 1;
  for (fcm_index i = 0; i < m->num; i++) {
    int all = 1;
    fcm_element_eval_shape(type, m->xi + 3 * i, N);
    for (int a = 0; a < npc && all; a++)
      all = fabs(N[a]) <= 1e-10 || held[cells[(size_t)npc * m->cell[i] + a]];
    if (all) nodes[num++] = m->node[i];
  }
  return fcm_integrator_add_constraint(I, num, nodes, &c->motion, NULL);
}

static fcm_status check_spaces(fcm_ctx *ctx, const fcm_integrator *old, const fcm_space *space)
{
  fcm_status st = FCM_OK;
  const fcm_mesh *om = fcm_space_mesh(old->space), *nm = fcm_space_mesh(space);
  FCM_CHECK(old->is_setup, ctx, FCM_ERR_ARG,
            "integrator refine: the integrator must be set up (fcm_integrator_setup())");
  FCM_CHECK(!fcm__integrator_distributed(old, NULL), ctx, FCM_ERR_UNSUPPORTED,
            "integrator refine: an integrator with a distributed backend cannot be refined");
  FCM_CHECK(fcm_mesh_element_type(om) == fcm_mesh_element_type(nm), ctx, FCM_ERR_ARG,
            "integrator refine: the new space's element type (%d) differs from the old one's (%d)",
            (int)fcm_mesh_element_type(nm), (int)fcm_mesh_element_type(om));
  for (int k = 0; k < 2; k++) {
    const fcm_space *s = k ? space : old->space;
    const fcm_index nn = fcm_mesh_num_nodes(fcm_space_mesh(s));
    for (fcm_index n = 0; n < nn; n++)
      FCM_CHECK(fcm_space_node_copies(s, n) <= 1, ctx, FCM_ERR_UNSUPPORTED,
                "integrator refine: node %lld of the %s space has %lld DOF copies (a cut "
                "space); refinement during a run is supported before the first cut only",
                (long long)n, k ? "new" : "old", (long long)fcm_space_node_copies(s, n));
  }
cleanup:
  return st;
}

fcm_status fcm_integrator_create_refined(const fcm_integrator *old, const fcm_space *space,
                                         fcm_integrator **integ)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = old ? old->ctx : NULL;
  fcm_integrator *I = NULL;
  refine_map m;
  unsigned char *held = NULL;
  fcm_index *nodes = NULL;
  double *x = NULL;
  memset(&m, 0, sizeof m);
  FCM_CHECK(integ, ctx, FCM_ERR_ARG, "integrator refine: output pointer is NULL");
  *integ = NULL;
  FCM_CHECK(old && space, ctx, FCM_ERR_ARG, "integrator refine: NULL integrator or space");
  FCM_TRY(ctx, check_spaces(ctx, old, space));
  FCM_TRY(ctx, refine_map_build(old->space, space, &m));
  FCM_TRY(ctx, fcm_integrator_create(ctx, space, &old->mat, &old->opts, &I));
  FCM_TRY(ctx, fcm__sim_copy_effects(old, I));
  FCM_ALLOC_RAW(ctx, (size_t)fcm_mesh_num_nodes(fcm_space_mesh(old->space)) + 1, held);
  FCM_ALLOC_RAW(ctx, (size_t)m.num + 1, nodes);
  for (int k = 0; k < old->num_cons; k++)
    FCM_TRY(ctx, map_constraint(I, old, &old->cons[k], &m, held, nodes));
  FCM_TRY(ctx, fcm_integrator_setup(I));
  {
    const size_t n = (size_t)I->n + 1;
    FCM_ALLOC_RAW(ctx, 2 * n, x);
    FCM_TRY(ctx, refine_map_field(old->space, space, &m, old->u, x));
    FCM_TRY(ctx, refine_map_field(old->space, space, &m, old->v, x + n));
    FCM_TRY(ctx, fcm_integrator_set_state(I, x, x + n, old->t, old->steps));
    if (old->a_valid) {
      FCM_TRY(ctx, refine_map_field(old->space, space, &m, old->a, x));
      FCM_TRY(ctx, fcm_integrator_set_acceleration(I, x));
    }
  }
  I->load_work = old->load_work;
  I->setup_info.refine_extrapolated = 0;
  for (fcm_index i = 0; i < m.num; i++)
    I->setup_info.refine_extrapolated += m.extra[i] != 0;
  *integ = I;
  I = NULL;
cleanup:
  if (!ctx) return st;
  refine_map_free(ctx, &m);
  fcm__free(ctx, held);
  fcm__free(ctx, nodes);
  fcm__free(ctx, x);
  fcm_integrator_destroy(&I);
  return st;
}
