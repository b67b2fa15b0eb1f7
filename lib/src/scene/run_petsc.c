/* scene module: the scene runner on the PETSc backend (built with FCM_WITH_PETSC; fcm/petsc.h).
 * The runner chooses the backend and hands it what it needs: a scene's linear problem for the
 * PETSc linear driver (fcm_petsc_problem_create_from_scene()), and a scene's ordinary
 * simulation whose integrator solves through the PETSc backend (fcm_petsc_simulation_create():
 * the backend partitions the cells, the simulation's cell rules carry this process's share and
 * its integrator sums and solves through the backend, lib/src/fem/fem_backend.h). */
#include "fcm/scene_petsc.h"
#include "scene/run_impl.h"
#include "scene/scene_impl.h"

#include "core/core_impl.h"
#include "petsc/petsc_backend.h"
#include "sim/sim_backend.h"

#include <string.h>

/* What the PETSc backend cannot run of a scene, named (local: every process reads the same). */
static fcm_status check_scene(fcm_ctx *ctx, const fcm_scene *scene)
{
  fcm_status st = FCM_OK;
  const char *name = fcm_scene_name(scene);
  FCM_CHECK(
      fcm_scene_get_material(scene)->model == FCM_MATERIAL_LINEAR, ctx, FCM_ERR_UNSUPPORTED,
      "scene %s: material.model: the PETSc backend solves linear elasticity only (\"linear\"); "
      "run this scene with the serial backend",
      name);
  FCM_CHECK(fcm_scene_get_quadrature(scene)->rules.simplify != FCM_CELL_SIMPLIFY_AUTO, ctx,
            FCM_ERR_UNSUPPORTED,
            "scene %s: quadrature.simplify = \"auto\" is not supported by the PETSc backend (its "
            "choice would differ between processes); use true or false",
            name);
  for (int k = 0; k < fcm_scene_num_effects(scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(scene, k);
    const char *what = NULL;
    switch (e->type) {
    case FCM_EFFECT_GRAVITY:
      break;
    case FCM_EFFECT_FIXED:
      if (e->fixed.boundary) what = "a fixed effect on the \"boundary\" (Nitsche / penalty)";
      break;
    case FCM_EFFECT_MOTION:
      if (e->motion.boundary)
        what = "a motion effect on the \"boundary\" (Nitsche / penalty)";
      else if (e->motion.motion.release)
        what = "a motion effect with \"release\"";
      break;
    default:
      what = fcm_effect_type_name(e->type);
    }
    FCM_CHECK(!what, ctx, FCM_ERR_UNSUPPORTED,
              "scene %s: effects[%d]: %s is not supported by the PETSc backend yet (gravity, "
              "fixed and motion on node regions are); run this scene with the serial backend",
              name, k, what);
  }
cleanup:
  return st;
}

int fcm_petsc_problem_supports_scene(fcm_ctx *ctx, const fcm_scene *scene)
{
  if (!ctx || !scene) return 0;
  fcm_ctx *tmp = NULL; /* the check's message must not replace the caller's error */
  if (fcm_ctx_create(NULL, &tmp) != FCM_OK) return 0;
  const int ok = check_scene(tmp, scene) == FCM_OK;
  fcm_ctx_destroy(&tmp);
  return ok;
}

/* The PETSc solver settings of a scene, the same for both drivers: its solver section's
 * petsc_options and Krylov tolerance and iteration limit (when the scene gives them; else the
 * backend's defaults, fcm_petsc_solver_options_default()), and the partition method. */
static fcm_petsc_solver_options scene_solver(const fcm_scene *scene, fcm_petsc_partition partition)
{
  const fcm_scene_solver *sv = fcm_scene_get_solver(scene);
  const fcm_integrator_options *io = &sv->integrator;
  fcm_petsc_solver_options o = fcm_petsc_solver_options_default();
  o.partition = partition;
  o.petsc_options = sv->petsc_options;
  if (io->krylov_rtol > 0.0) o.rtol = io->krylov_rtol;
  if (io->krylov_max_iterations > 0) o.max_iterations = io->krylov_max_iterations;
  return o;
}

/* The background nodes of a region (as the serial runner picks them). */
static fcm_status scene_region_nodes(fcm_ctx *ctx, const fcm_scene *scene, const fcm_mesh *mesh,
                                     const fcm_region *r, int k, fcm_index **nodes, fcm_index *n)
{
  fcm_status st = FCM_OK;
  const fcm_index nn = fcm_mesh_num_nodes(mesh);
  const double *X = fcm_mesh_coords(mesh);
  fcm_index *out = NULL, m = 0;
  FCM_ALLOC(ctx, (r->kind == FCM_REGION_NODES ? r->num_nodes : nn) + 1, out);
  if (r->kind == FCM_REGION_NODES) {
    for (fcm_index j = 0; j < r->num_nodes; j++) {
      FCM_CHECK(r->nodes[j] >= 0 && r->nodes[j] < nn, ctx, FCM_ERR_ARG,
                "scene %s: effects[%d]: node %lld out of range [0, %lld)", fcm_scene_name(scene), k,
                (long long)r->nodes[j], (long long)nn);
      out[m++] = r->nodes[j];
    }
  } else {
    for (fcm_index a = 0; a < nn; a++)
      if (fcm_region_contains(r, X + 3 * a)) out[m++] = a;
  }
  FCM_CHECK(m > 0, ctx, FCM_ERR_ARG,
            "scene %s: effects[%d]: the region contains no background-mesh node",
            fcm_scene_name(scene), k);
  *nodes = out;
  *n = m;
  out = NULL;
cleanup:
  fcm__free(ctx, out);
  return st;
}

fcm_status fcm_petsc_problem_create_from_scene(fcm_ctx *ctx, MPI_Comm comm, const fcm_scene *scene,
                                               fcm_petsc_partition partition,
                                               fcm_petsc_problem **out)
{
  fcm_status st = FCM_OK;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_petsc_problem *P = NULL;
  fcm_index *nodes = NULL, n = 0;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "petsc: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(ctx && scene, ctx, FCM_ERR_ARG, "petsc: NULL context or scene");
  st = check_scene(ctx, scene);
  if (st == FCM_OK) st = fcm__scene_mesh_geometry(ctx, scene, &mesh, &geom);
  FCM_TRY(ctx, fcm__petsc_agree(ctx, comm, st));
  /* the options as the serial runner derives them (lib/src/scene/run.c) */
  const fcm_cell_rules_options *q = &fcm_scene_get_quadrature(scene)->rules;
  const fcm_scene_solver *sv = fcm_scene_get_solver(scene);
  const fcm_scene_time *tm = fcm_scene_get_time(scene);
  fcm_petsc_options o = fcm_petsc_options_default();
  FCM_CHECK(tm->integrator == FCM_INTEGRATOR_STATIC || tm->scheme == FCM_SCHEME_BACKWARD_EULER, ctx,
            FCM_ERR_UNSUPPORTED,
            "scene %s: time.integrator \"%s\": the PETSc linear driver steps with backward Euler "
            "only; run this scene with the serial backend or the distributed simulation",
            fcm_scene_name(scene), fcm_time_scheme_name(tm->scheme));
  o.kind = tm->integrator;
  o.dt = tm->dt;
  o.solver = scene_solver(scene, partition);
  o.rules = *q;
  o.rules.surface_strength = -1;
  if (sv->threads > 0) FCM_TRY(ctx, fcm_ctx_set_num_threads(ctx, sv->threads));
  const int *str = q->strength;
  o.assembly.stiffness_strength =
      str[FCM_RULE_STIFFNESS] > 0 ? str[FCM_RULE_STIFFNESS] : FCM_DEFAULT;
  o.assembly.mass_strength = str[FCM_RULE_MASS] > 0 ? str[FCM_RULE_MASS] : FCM_DEFAULT;
  FCM_TRY(ctx,
          fcm_petsc_problem_create(ctx, comm, mesh, geom, fcm_scene_get_material(scene), &o, &P));
  const fcm_mesh *bg = mesh;
  fcm__petsc_problem_adopt_mesh(P, mesh);
  mesh = NULL;
  fcm_geometry_destroy(&geom); /* only read while the rules were built */
  for (int k = 0; k < fcm_scene_num_effects(scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(scene, k);
    if (e->type == FCM_EFFECT_GRAVITY) {
      FCM_TRY(ctx, fcm_petsc_problem_add_gravity(P, e->gravity.acceleration));
      continue;
    }
    if (e->type != FCM_EFFECT_FIXED && e->type != FCM_EFFECT_MOTION) continue;
    const fcm_region *r = e->type == FCM_EFFECT_FIXED ? &e->fixed.region : &e->motion.region;
    fcm_motion m = fcm_motion_default();
    if (e->type == FCM_EFFECT_FIXED)
      for (int d = 0; d < 3; d++)
        m.components[d] = e->fixed.components[d];
    else
      m = e->motion.motion;
    fcm__free(ctx, nodes);
    nodes = NULL;
    st = scene_region_nodes(ctx, scene, bg, r, k, &nodes, &n);
    FCM_TRY(ctx, fcm__petsc_agree(ctx, comm, st));
    FCM_TRY(ctx, fcm_petsc_problem_add_constraint(P, n, nodes, &m));
  }
  FCM_TRY(ctx, fcm_petsc_problem_setup(P));
  *out = P;
  P = NULL;
cleanup:
  fcm__free(ctx, nodes);
  fcm_petsc_problem_destroy(&P);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  return st;
}

fcm_status fcm_petsc_simulation_create(fcm_ctx *ctx, MPI_Comm comm, const fcm_scene *scene,
                                       fcm_petsc_partition partition,
                                       const fcm_simulation_options *opts, fcm_simulation **out)
{
  fcm_status st = FCM_OK;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_petsc_problem *P = NULL;
  fcm_simulation *S = NULL;
  unsigned char *mask = NULL;
  fcm__backend backend;
  fcm__rules_exchange exchange;
  /* local checks, agreed in fcm__petsc_backend_create() before the first collective call */
  if (!out)
    st =
        fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__, "petsc: output pointer is NULL");
  else
    *out = NULL;
  if (st == FCM_OK && !(ctx && scene))
    st = fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__, "petsc: NULL context or scene");
  /* the backend's settings from the scene's solver section (the partition is checked there) */
  fcm__petsc_backend_options bo;
  memset(&bo, 0, sizeof bo);
  if (st == FCM_OK) {
    bo.solver = scene_solver(scene, partition);
    bo.direct = fcm_scene_get_solver(scene)->integrator.linear_solver == FCM_LINEAR_DIRECT;
    bo.mat = *fcm_scene_get_material(scene);
  }
  FCM_TRY(ctx, fcm__petsc_backend_create(ctx, comm, st, &bo, &P));
  if (st == FCM_OK) st = fcm__scene_mesh_geometry(ctx, scene, &mesh, &geom);
  FCM_TRY(ctx, fcm__petsc_backend_partition(P, st, mesh, geom, &mask, &backend, &exchange));
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  /* the simulation (its mesh is built again from the scene, the same cells): collective from
   * the rules build's classification exchange on and the backend's setup; a process that fails
   * outside an agreement ends with one (the backend's finish), which meets the agreement the
   * others wait in */
  {
    fcm__simulation_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.opts = opts ? *opts : fcm_simulation_options_default();
    cfg.backend = &backend;
    cfg.cell_mask = mask;
    cfg.exchange = &exchange;
    st = fcm__simulation_create(ctx, scene, &cfg, &S);
  }
  FCM_TRY(ctx, backend.finish(backend.user, st));
  *out = S;
  S = NULL;
cleanup:
  fcm_simulation_destroy(&S);
  fcm__free(ctx, mask);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  fcm__petsc_backend_release(P);
  return st;
}

fcm_status fcm_petsc_simulation_summary_view(fcm_simulation *sim, FILE *f)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(sim, NULL, FCM_ERR_ARG, "petsc: summary_view: NULL simulation");
  FCM_CHECK(fcm__integrator_distributed(sim->integ, NULL), sim->ctx, FCM_ERR_ARG,
            "petsc: summary_view: the simulation is not one of fcm_petsc_simulation_create()");
  {
    /* the backend's traffic so far (before the summary's own sums), per Newton matrix; the
     * largest over the processes */
    fcm_petsc_traffic t;
    MPI_Comm comm = MPI_COMM_NULL;
    FCM_TRY(sim->ctx, fcm_petsc_simulation_traffic(sim, &t));
    FCM_TRY(sim->ctx, fcm__simulation_summary_view_distributed(sim, f));
    fcm__petsc_backend_info(fcm__integrator_backend(sim->integ), NULL, &comm);
    double mine[4] = {(double)t.reduce_bytes, (double)t.matrix_bytes_sent, t.cpu_reduce,
                      t.cpu_matrix},
           all[4];
    int rc = MPI_Allreduce(mine, all, 4, MPI_DOUBLE, MPI_MAX, comm);
    FCM_CHECK(rc == MPI_SUCCESS, sim->ctx, FCM_ERR_INTERNAL,
              "petsc: MPI_Allreduce of the traffic counters failed (error %d)", rc);
    const double per = t.matrices > 0 ? 1.0 / (double)t.matrices : 0.0;
    if (f)
      fprintf(f,
              "  comm      per process (largest): dense sums %.4g MB (%.3g s CPU), matrix stash "
              "%.4g MB (%.3g s CPU); per Newton matrix (%lld): %.4g + %.4g kB\n",
              all[0] / 1e6, all[2], all[1] / 1e6, all[3], t.matrices, all[0] * per / 1e3,
              all[1] * per / 1e3);
  }
cleanup:
  return st;
}

fcm_status fcm_petsc_simulation_traffic(const fcm_simulation *sim, fcm_petsc_traffic *out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(sim && out, sim ? sim->ctx : NULL, FCM_ERR_ARG, "petsc: traffic: NULL argument");
  FCM_CHECK(fcm__petsc_backend_info(fcm__integrator_backend(sim->integ), out, NULL), sim->ctx,
            FCM_ERR_ARG,
            "petsc: traffic: the simulation is not one of fcm_petsc_simulation_create()");
cleanup:
  return st;
}
