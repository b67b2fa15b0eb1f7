/* The scene runner, building: the pipeline a scene asks for (cell rules, space, integrator with
 * exactly its effects, on the backend the configuration names) and its set-up phases, the cuts
 * applied later, and its destruction. Background mesh and geometry: run_mesh.c; stepping:
 * run_step.c; output: run_output.c; summary: run_summary.c; the effects' run-time hooks:
 * run_effects.c. */
#include "scene/run_impl.h"
#include "scene/scene_impl.h"

#include "core/core_impl.h"
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"
#include "sim/sim_backend.h"
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/geom.h"
#include "fcm/io.h"
#include "fcm/mesh.h"
#include "io/io_impl.h"

#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

fcm_simulation_options fcm_simulation_options_default(void)
{
  fcm_simulation_options o;
  memset(&o, 0, sizeof o);
  o.max_steps = FCM_DEFAULT;
  o.checkpoint_interval = FCM_DEFAULT;
  o.rules_progress_interval = 0.1;
  return o;
}

const char *fcm_setup_phase_name(fcm_setup_phase phase)
{
  static const char *const names[FCM_SETUP_PHASE_COUNT] = {
      "reading",       "filling holes", "surface checks",  "volume meshing (Gmsh)",
      "geometry",      "transform",     "background mesh", "cell rules",
      "space",         "integrator",    "log mass blocks", "cuts at t = 0",
      "output surface"};
  return phase >= 0 && phase < FCM_SETUP_PHASE_COUNT ? names[phase] : "?";
}

void fcm__sim_phase_begin(fcm_simulation *S, fcm_setup_phase p, int progress, const char *what, ...)
{
  va_list ap;
  va_start(ap, what);
  vsnprintf(S->phase_what, sizeof S->phase_what, what, ap);
  va_end(ap);
  S->phase = (int)p;
  S->phase_progress = progress;
  if (S->opts.setup_phase) {
    const fcm_setup_phase_event ev = {p, S->phase_what, 0, 0.0, progress};
    S->opts.setup_phase(&ev, S->opts.setup_phase_user);
  }
  S->phase_t0 = fcm_wtime();
}

void fcm__sim_phase_end(fcm_simulation *S)
{
  const double t = fcm_wtime() - S->phase_t0;
  const fcm_setup_phase p = (fcm_setup_phase)S->phase;
  S->c.time_setup_phase[p] = t;
  S->phases_run |= 1u << p;
  S->phase = -1;
  if (S->opts.setup_phase) {
    const fcm_setup_phase_event ev = {p, S->phase_what, 1, t, S->phase_progress};
    S->opts.setup_phase(&ev, S->opts.setup_phase_user);
  }
}

/* The set-up rules' boundary area in dropped cells into the counters and, when there is any,
 * into the words of the rules' phase (its end tells the host). */
static void dropped_boundary(fcm_simulation *S)
{
  const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(S->rules);
  S->c.dropped_area = rs->dropped_area;
  S->c.boundary_area = rs->embedded_area + rs->dropped_area;
  if (!(rs->dropped_area > 0.0)) return;
  const size_t n = strlen(S->phase_what);
  snprintf(S->phase_what + n, sizeof S->phase_what - n,
           "; %.3g%% of the boundary area (%.3g of %.6g m^2) in dropped cells",
           100.0 * S->c.dropped_area / S->c.boundary_area, S->c.dropped_area, S->c.boundary_area);
}

fcm_status fcm__sim_grow(fcm_ctx *ctx, void **array, long long *cap, long long need, size_t size)
{
  fcm_status st = FCM_OK;
  if (need <= *cap) return FCM_OK;
  long long c = *cap ? *cap : 64;
  while (c < need)
    c *= 2;
  FCM_TRY(ctx, fcm__resize(ctx, array, (size_t)*cap, (size_t)c, size));
  *cap = c;
cleanup:
  return st;
}

void fcm__sim_name_section(fcm_ctx *ctx, const char *path)
{
  if (!strstr(fcm_ctx_error_message(ctx), path)) fcm__error_prefix(ctx, path);
}

/* Stiffness assemblies per time or load step that FCM_CELL_SIMPLIFY_AUTO assumes: the default
 * scene takes 508 Newton iterations in 210 steps (2.4 per step), each assembling force and
 * tangent, plus line-search and predictor force evaluations. */
#define RUN_ASSEMBLIES_PER_STEP 3.0

/* Every pass the run will make over the points of each rule kind (fcm__auto_uses): the
 * set-up's space and integrator and those of every cut integrate all cells again (body
 * forces; mass matrix and the log's mass blocks when dynamic), the Newton iterations
 * assemble force and tangent, and each frame evaluates the stresses. */
static fcm__auto_uses expected_uses(const fcm_scene *scene, int dynamic)
{
  fcm__auto_uses u;
  const fcm_scene_time *tm = fcm_scene_get_time(scene);
  const double spaces = 1.0 + (double)fcm_scene_count_effects(scene, FCM_EFFECT_CUT);
  const double steps = (double)tm->num_steps;
  const int every = fcm_scene_get_output(scene)->frame_interval;
  u.steps = RUN_ASSEMBLIES_PER_STEP * steps * (dynamic ? 1.0 : (double)tm->load_steps);
  u.loads = spaces * (double)fcm_scene_count_effects(scene, FCM_EFFECT_GRAVITY);
  u.frames = 1.0 + ceil(steps / (double)(every > 0 ? every : 1)); /* the first and the last */
  u.matrix = dynamic ? spaces : 0.0;
  u.momentum = dynamic ? spaces : 0.0;
  return u;
}

static fcm_status build_rules(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  const fcm_cell_rules_options *q = &fcm_scene_get_quadrature(S->scene)->rules;
  const fcm_scene_solver *sv = fcm_scene_get_solver(S->scene);
  fcm_cell_rules_options ro = *q;
  int nsurf = 0;
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    nsurf += !!(fcm__scene_effect_type(e->type)->needs & FCM__NEEDS_SURFACE_RULES);
    nsurf += (e->type == FCM_EFFECT_FIXED && e->fixed.boundary) ||
             (e->type == FCM_EFFECT_MOTION && e->motion.boundary); /* Nitsche's points */
  }
  /* Only the rules the scene calls for: mass rules serve the mass matrix (inertia, Rayleigh
   * damping) and the momentum, so a static scene builds none (the log's mass then comes from
   * the piece volumes, see log_momentum()). */
  const int dynamic = fcm_scene_get_time(S->scene)->integrator != FCM_INTEGRATOR_STATIC;
  ro.kinds = FCM_RULES_STIFFNESS | (dynamic ? FCM_RULES_MASS : 0u);
  if (q->surface_strength < 0 && nsurf > 0) /* automatic */
    ro.surface_strength = q->strength[FCM_RULE_STIFFNESS] >= 0
                              ? q->strength[FCM_RULE_STIFFNESS]
                              : fcm_mesh_get_element_info(S->mesh)->stiffness_strength;
  if (q->simplify == FCM_CELL_SIMPLIFY_AUTO) { /* every pass the run expects, by kind */
    const fcm__auto_uses u = expected_uses(S->scene, dynamic);
    S->auto_uses = u;
    ro.expected_assemblies[FCM_RULE_STIFFNESS] = u.steps + u.loads + u.frames;
    ro.expected_assemblies[FCM_RULE_MASS] = u.matrix + u.momentum;
  }
  if (sv->threads > 0) FCM_TRY(S->ctx, fcm_ctx_set_num_threads(S->ctx, sv->threads));
  ro.progress = S->opts.rules_progress;
  ro.progress_user = S->opts.rules_progress_user;
  ro.progress_interval = S->opts.rules_progress_interval;
  const fcm__simulation_config *cfg = S->config;
  const fcm__backend *b = cfg ? cfg->backend : NULL;
  ro.cell_mask = cfg ? cfg->cell_mask : NULL;
  fcm__rules_reduce red = {b ? b->reduce : NULL, b ? b->user : NULL, 0};
  if (cfg && cfg->exchange) /* distributed: each process classifies its share of the cells */
    FCM_TRY(S->ctx, fcm__cell_rules_create_distributed(S->ctx, S->mesh, S->geom, &ro,
                                                       b ? &red : NULL, cfg->exchange, &S->rules));
  else if (b) /* distributed: the auto choice's inputs summed over the processes */
    FCM_TRY(S->ctx, fcm__cell_rules_create_reduced(S->ctx, S->mesh, S->geom, &ro, &red, &S->rules));
  else
    FCM_TRY(S->ctx, fcm_cell_rules_create(S->ctx, S->mesh, S->geom, &ro, &S->rules));
  S->setup_stats = *fcm_cell_rules_get_stats(S->rules);
  S->c.cell_rules = 1;
  S->c.surface_rules = ro.surface_strength >= 0;
  S->c.rule_kinds = fcm_cell_rules_get_stats(S->rules)->kinds;
cleanup:
  return st;
}

static fcm_integrator_options integrator_options(fcm_simulation *S)
{
  const int *q = fcm_scene_get_quadrature(S->scene)->rules.strength;
  const fcm_scene_time *tm = fcm_scene_get_time(S->scene);
  fcm_integrator_options o = fcm_scene_get_solver(S->scene)->integrator;
  o.kind = tm->integrator;
  o.scheme = tm->scheme;
  o.hht_alpha = tm->hht_alpha;
  o.rho_inf = tm->rho_inf;
  o.dt = tm->dt;
  o.load_steps = tm->load_steps;
  /* Full cells: the scene's strength, except that 0 keeps the element's rule there (as the
   * scene README documents for strength 0: only cut cells get the strength-0 rule). */
  o.assembly.stiffness_strength = q[FCM_RULE_STIFFNESS] > 0 ? q[FCM_RULE_STIFFNESS] : FCM_DEFAULT;
  o.assembly.mass_strength = q[FCM_RULE_MASS] > 0 ? q[FCM_RULE_MASS] : FCM_DEFAULT;
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    const fcm__effect_type *t = fcm__scene_effect_type(e->type);
    if (t->configure) t->configure(e, &o);
  }
  return o;
}

/* Schwarz blocks the integrator would build: active cut cells below the threshold. */
static fcm_index count_schwarz_blocks(const fcm_simulation *S, double theta)
{
  fcm_index n = 0;
  if (!S->rules) return 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(S->mesh); c++)
    if (fcm_space_cell_active(S->space, c) && fcm_cell_rules_class(S->rules, c) == FCM_CELL_CUT &&
        fcm_cell_rules_volume_fraction(S->rules, c) < theta)
      n++;
  return n;
}

/* The embedded surface written per frame: the boundary triangles' vertices located once
 * (fcm_embedded_surface_create()), the triangles the cuts cross split and the cut faces added
 * after every cut. */
static fcm_status build_surface(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  unsigned char *seen = NULL;
  FCM_TRY(S->ctx, fcm_embedded_surface_create(S->space, S->geom, &S->surf));
  /* the counters name the geometry's boundary only (split parts and cut faces come and go
   * with the cuts): its triangles and their distinct vertices */
  const fcm_index nb = fcm_geometry_num_boundary_triangles(S->geom);
  const fcm_index *tri = fcm_geometry_boundary_triangles(S->geom);
  FCM_ALLOC(S->ctx, (size_t)fcm_geometry_num_nodes(S->geom) + 1, seen);
  S->c.surface_triangles = nb;
  S->c.surface_points = 0;
  for (fcm_index k = 0; k < 3 * nb; k++) {
    S->c.surface_points += !seen[tri[k]];
    seen[tri[k]] = 1;
  }
cleanup:
  fcm__free(S->ctx, seen);
  return st;
}

fcm_status fcm__sim_cut_surface(fcm_simulation *S, const fcm_effect_cut *c, fcm_surface **surf)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_surface *raw = NULL;
  *surf = NULL;
  switch (c->kind) {
  case FCM_CUT_PLANE: {
    double lo[3], hi[3], diag = 0.0;
    fcm_geometry_bounding_box(S->geom, lo, hi);
    for (int d = 0; d < 3; d++)
      diag += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    diag = sqrt(diag);
    for (int d = 0; d < 3; d++)
      lo[d] -= 0.1 * diag, hi[d] += 0.1 * diag;
    st = fcm_surface_create_plane(ctx, c->point, c->normal, lo, hi, &raw);
    if (st == FCM_ERR_GEOMETRY) { /* misses the body: a counted no-op */
      fcm_ctx_error_clear(ctx);
      st = FCM_OK;
      goto cleanup;
    }
    FCM_TRY(ctx, st);
  } break;
  case FCM_CUT_RECTANGLE:
    FCM_TRY(ctx, fcm_surface_create_rectangle(ctx, c->point, c->normal, c->axis, c->size, &raw));
    break;
  case FCM_CUT_DISC:
    FCM_TRY(ctx, fcm_surface_create_disc(ctx, c->point, c->normal, c->radius, c->segments, &raw));
    break;
  case FCM_CUT_MESH:
    FCM_TRY(ctx, fcm_surface_create_from_file(ctx, c->mesh, &raw));
    break;
  }
  if (c->has_transform) {
    FCM_TRY(ctx, fcm_surface_create_transformed(ctx, raw, c->transform, c->offset, surf));
  } else {
    *surf = raw;
    raw = NULL;
  }
cleanup:
  fcm_surface_destroy(&raw);
  return st;
}

/* The space of the rules (NULL: plain FEM on the background mesh): a full space; in a
 * distributed run (own: this process's cells, the rules' cell mask or the configuration's) a
 * local one, the topology of the process's own cells and one layer of ghosts around them
 * (fcm__space_localize(): every copy an own cell uses has its full row, as the backend's matrix
 * preallocation needs; without rules the space keeps `own` as the cells it integrates), the
 * numbering the full space's bit for bit. */
static fcm_status create_space(fcm_simulation *S, const fcm_cell_rules *rules,
                               const unsigned char *own, fcm_space **out)
{
  fcm_status st = FCM_OK;
  const fcm_space_options o = fcm_space_options_default();
  if (!own) {
    if (!rules) return fcm_space_create(S->ctx, S->mesh, NULL, out);
    return fcm_space_create_embedded(S->ctx, S->mesh, rules, out);
  }
  FCM_TRY(S->ctx,
          fcm__space_create_local(S->ctx, S->mesh, NULL, rules, rules ? &o : NULL, NULL, out));
  FCM_TRY(S->ctx, fcm__space_localize(*out, own));
cleanup:
  if (st != FCM_OK) fcm_space_destroy(out);
  return st;
}

/* The element mass blocks of the log's mass and momentum (fcm_space_momentum() keeps them in
 * the space), built with the space rather than in the first step's log; nothing when the
 * rules carry no mass rules (a static scene: the log then uses the piece volumes). */
static fcm_status build_log_blocks(fcm_simulation *S)
{
  if (S->rules && !fcm_cell_rules_has_kind(S->rules, FCM_RULE_MASS)) return FCM_OK;
  return fcm_space_momentum(S->space, 0.0, NULL, NULL, NULL, NULL, NULL);
}

/* After a cut: the log's mass blocks of the cut space, those of the elements the cut left as
 * they were copied from the space before it (the same bits as building them anew). */
static fcm_status keep_log_blocks(fcm_simulation *S, const fcm_space *space)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_index *same = NULL;
  if (S->rules && !fcm_cell_rules_has_kind(S->rules, FCM_RULE_MASS)) return FCM_OK;
  FCM_ALLOC_RAW(ctx, (size_t)fcm_space_num_elements(space) + 1, same);
  FCM_TRY(ctx, fcm__space_cut_same_elements(S->space, space, same, NULL));
  FCM_TRY(ctx, fcm__space_momentum_blocks_from(space, S->space, same));
cleanup:
  fcm__free(ctx, same);
  return st;
}

/* The octree mesh refined along the surfaces `surf` (n, NULL entries skipped) to `level`:
 * the cells a surface meets split until they reach it (2:1 balanced each pass); *out NULL when
 * no cell needs it. */
static fcm_status refine_along(fcm_simulation *S, fcm_surface **surf, int n, int level,
                               fcm_mesh **out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  unsigned char *flags = NULL;
  fcm_mesh *mesh = NULL, *next = NULL;
  double X[3 * FCM_ELEMENT_MAX_NODES];
  *out = NULL;
  for (int pass = 0; pass < level; pass++) {
    const fcm_mesh *m = mesh ? mesh : S->mesh;
    const fcm_index nc = fcm_mesh_num_cells(m);
    const int npc = fcm_mesh_nodes_per_cell(m);
    fcm_index count = 0;
    FCM_FREE(ctx, flags);
    FCM_ALLOC(ctx, (size_t)nc + 1, flags);
    for (fcm_index c = 0; c < nc; c++) {
      const int lev = fcm_mesh_cell_level(m, c);
      double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
      if (lev >= level) continue;
      fcm_mesh_cell_coords(m, c, X);
      for (int a = 0; a < npc; a++)
        for (int d = 0; d < 3; d++)
          lo[d] = fmin(lo[d], X[3 * a + d]), hi[d] = fmax(hi[d], X[3 * a + d]);
      for (int k = 0; k < n && !flags[c]; k++)
        flags[c] = surf[k] && fcm_surface_meets_box(lo, hi, lev, surf[k]) > 0;
      count += flags[c];
    }
    if (count == 0) break;
    FCM_TRY(ctx, fcm_mesh_create_refined(ctx, m, flags, &next));
    fcm_mesh_destroy(&mesh);
    mesh = next;
    next = NULL;
  }
  *out = mesh;
  mesh = NULL;
cleanup:
  fcm__free(ctx, flags);
  fcm_mesh_destroy(&mesh);
  return st;
}

/* "octree": {"cuts": {"when": "cut"}}: before the first cut, the background refined along
 * every cut's surface, the rules, space and integrator built on it and the state carried over
 * (fcm_integrator_create_refined()). */
static fcm_status refine_for_cuts(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_scene_background *bg = fcm_scene_get_background(S->scene);
  fcm_surface **surf = NULL;
  fcm_mesh *mesh = NULL, *old_mesh = S->mesh;
  fcm_cell_rules *old_rules = S->rules;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  const double t0 = fcm_wtime();
  S->refined = 1;
  FCM_CHECK(!S->distributed, ctx, FCM_ERR_UNSUPPORTED,
            "background.octree.cuts.when: \"cut\" (refinement during the run) is not supported "
            "in a distributed run; use \"setup\"");
  FCM_ALLOC(ctx, (size_t)S->num_cuts, surf);
  for (int k = 0; k < S->num_cuts; k++)
    FCM_TRY(ctx, fcm__sim_cut_surface(S, &S->cuts[k]->cut, &surf[k]));
  FCM_TRY(ctx, refine_along(S, surf, S->num_cuts, bg->octree_cuts, &mesh));
  S->refined_at = fcm_integrator_time(S->integ);
  S->refine_cells[0] = S->refine_cells[1] = fcm_mesh_num_cells(S->mesh);
  if (!mesh) goto cleanup;
  S->mesh = mesh;
  S->rules = NULL;
  st = build_rules(S);
  if (st == FCM_OK) st = create_space(S, S->rules, NULL, &space);
  if (st == FCM_OK) st = fcm_integrator_create_refined(S->integ, space, &integ);
  if (st != FCM_OK) { /* back to the run as it was */
    fcm_cell_rules_destroy(&S->rules);
    S->mesh = old_mesh, S->rules = old_rules;
    fcm__sim_name_section(ctx, "background.octree.cuts");
    goto cleanup;
  }
  fcm_integrator_destroy(&S->integ);
  fcm_space_destroy(&S->space);
  fcm_cell_rules_destroy(&old_rules);
  fcm_mesh_destroy(&old_mesh);
  S->integ = integ, S->space = space;
  integ = NULL, space = NULL;
  S->refine_cells[1] = fcm_mesh_num_cells(S->mesh);
  S->nn = fcm_mesh_num_nodes(S->mesh);
  S->c.num_dofs = fcm_space_num_dofs(S->space);
  S->c.constrained_dofs = fcm_integrator_num_constrained(S->integ);
  S->pieces = S->c.pieces = fcm_space_num_bodies(S->space);
  if (S->surf) {
    fcm_embedded_surface_destroy(&S->surf);
    FCM_TRY(ctx, build_surface(S));
  }
  FCM_TRY(ctx, build_log_blocks(S));
cleanup:
  S->refine_seconds = fcm_wtime() - t0;
  for (int k = 0; surf && k < S->num_cuts; k++)
    fcm_surface_destroy(&surf[k]);
  fcm__free(ctx, surf);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
  if (S->mesh != mesh) fcm_mesh_destroy(&mesh);
  return st;
}

/* The parts of a cut's work on the cut space, as iterations of loop L (their order the order
 * of the errors reported): the new integrator's values (fcm__integrator_cut_values()), the
 * linear solver's structure (fcm__integrator_cut_structure()), the output surface split
 * again, the log's mass blocks and the space's bodies. */
enum { CUT_VALUES, CUT_STRUCTURE, CUT_SURFACE, CUT_LOG_BLOCKS, CUT_PARTS };

static void cut_part(fcm_simulation *S, fcm__loop *L, int part, const fcm_space *space,
                     fcm__integrator_cut *cut)
{
  fcm_status st = FCM_OK;
  fcm__loop_iter it;
  if (fcm__loop_skip(L, part)) return;
  fcm__loop_enter(L, &it, part);
  if (part == CUT_VALUES)
    st = fcm__integrator_cut_values(cut);
  else if (part == CUT_STRUCTURE)
    st = fcm__integrator_cut_structure(cut);
  else if (part == CUT_SURFACE)
    st = S->surf ? fcm_embedded_surface_set_space(S->surf, space) : FCM_OK;
  else if ((st = keep_log_blocks(S, space)) == FCM_OK)
    S->cut_pieces = fcm_space_num_bodies(space);
  fcm__loop_leave(L, &it, st);
}

/* The new integrator on the cut space (fcm__integrator_cut_begin(), on every thread) and the
 * parts of the cut's work on it (cut_part()), on two threads where the context has them: each
 * thread takes the next part when it is free, the solver's structure first (the longest: Dick's
 * Bunny 2 0.07 s, the values 0.02 s, the surface 0.04 s), then the values, the surface and the
 * log's blocks; on one thread the values come first, as fcm_integrator_create_cut() makes
 * them. None reads what another writes (the structure reads the new integrator's pattern and
 * constraints' DOFs, which the first stage wrote, and old's hierarchy; the values the old
 * integrator and the new space; the surface the new space, its rules and the geometry; the
 * log's blocks and bodies the two spaces' elements and mass caches, which only they write),
 * and each gives the bits it gives alone (the loops inside run on one thread then, and give
 * the bits they give on two). A distributed run makes them on the calling thread in turn. A failed
 * part gives the storage back to the old integrator, which goes on. The structure leaves
 * level 0's smoothers to a task (fcm__integrator_cut's `beside`), which the thread that
 * reaches the team's barrier first runs, and which is completed after the barrier as part
 * of the structure (fcm__integrator_cut_join(): its error is the structure's, ranked as
 * such). seconds[1]: the solver's structure (the structure part's wall time, its task's,
 * and the direct solver's symbolic analysis, which the values make), seconds[0]: the rest of
 * the integrator's; side by side each its own, so they may add up to more than the cut. */
static fcm_status cut_parts(fcm_simulation *S, const fcm_space *space, fcm_integrator **integ,
                            double *seconds)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm__loop L;
  fcm__integrator_cut cut;
  const int two_threads = !S->distributed && !fcm__integrator_distributed(S->integ, NULL) &&
                          fcm_ctx_num_threads(ctx) > 1 && !S->cuts_in_turn;
  int team = 1, next = 0;
  st = fcm__integrator_cut_begin(S->integ, space, &cut);
  if (st == FCM_OK) {
    /* side by side when a second long part goes beside the values: the structure or the
     * surface (the log's blocks alone would leave the values' loops one thread for little) */
    const int two = two_threads && (S->surf || fcm__integrator_cut_has_structure(&cut));
    cut.beside = two; /* the structure may leave level 0's smoothers to the free thread */
    fcm__loop_begin(ctx, &L);
#pragma omp parallel num_threads(2) if (two)
    {
      const int nt = omp_get_num_threads();
      static const int order[2][CUT_PARTS] = {
          {CUT_VALUES, CUT_STRUCTURE, CUT_SURFACE, CUT_LOG_BLOCKS},
          {CUT_STRUCTURE, CUT_VALUES, CUT_SURFACE, CUT_LOG_BLOCKS}};
      if (omp_get_thread_num() == 0) team = nt;
      for (;;) {
        int k;
#pragma omp atomic capture
        k = next++;
        if (k >= CUT_PARTS) break;
        cut_part(S, &L, order[nt > 1][k], space, &cut);
      }
    }
    if (!fcm__loop_skip(&L, CUT_STRUCTURE)) { /* the structure's task, done past the barrier */
      fcm__loop_iter it;
      fcm__loop_enter(&L, &it, CUT_STRUCTURE);
      fcm__loop_leave(&L, &it, fcm__integrator_cut_join(&cut));
    }
    st = fcm__loop_end(&L, NULL);
  }
  st = fcm__integrator_cut_end(&cut, st, integ);
  if (st == FCM_OK) {
    fcm_integrator_setup_info si;
    fcm_integrator_get_setup_info(*integ, &si);
    /* the direct solver's analysis (made with the values) counts as the structure */
    seconds[1] = si.solver_seconds;
    seconds[0] = fmax(0.0, cut.seconds[0] - (si.solver_seconds - cut.seconds[1]));
  }
  S->cuts_side_by_side += team > 1;
  return st;
}

fcm_status fcm__sim_cut_room(fcm_simulation *S, int k)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  /* each array grows from the same capacity to the same new one */
  long long c[4] = {S->cut_cap, S->cut_cap, S->cut_cap, S->cut_cap};
  if (k < S->cut_cap) return FCM_OK;
  FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&S->cut_stats, c, k + 1, sizeof *S->cut_stats));
  FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&S->cut_time, c + 1, k + 1, sizeof *S->cut_time));
  FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&S->cut_solver, c + 2, k + 1, sizeof *S->cut_solver));
  FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&S->cut_at, c + 3, k + 1, sizeof *S->cut_at));
  S->cut_cap = c[0];
cleanup:
  return st;
}

/* Whether the rules of a cut that missed (the same pieces and DOF copies) change nothing else,
 * in a serial run: no cell integrated again and no piece with other faces on the cuts (a crack
 * the blade leaves inside cells keeps their pieces and rules but gives them faces on it, and
 * counts from the cut that completes it; a blade on the body's surface gives faces too). The
 * blade then divides no part, now or after later cuts (their parts lie in these), so the run's
 * rules, space and integrator serve as they are, and its next steps are those it would have
 * taken without the cut, bit for bit. (On a body given by its surface alone a cell's parts
 * include its empty part; a blade through it alone splits them, but the pieces' cut faces end
 * at the body, so it gives none.) */
static int unchanged(const fcm_simulation *S, const fcm_cell_rules *rules)
{
  const fcm_cell_rules *old = S->rules;
  if (fcm_cell_rules_get_stats(rules)->num_integrated != 0 || S->distributed ||
      fcm__integrator_distributed(S->integ, NULL))
    return 0;
  for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(rules); p++)
    if (fcm_cell_rules_get_piece_cut_faces(rules, p, NULL) !=
        fcm_cell_rules_get_piece_cut_faces(old, p, NULL))
      return 0;
  return 1;
}

fcm_status fcm__sim_cut_along(fcm_simulation *S, const fcm_surface *surf, double at, double t0)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  const int k = S->c.cuts; /* this cut's entry of the per-cut statistics */
  S->cut_phase[0] = S->cut_phase[1] = S->cut_phase[2] = S->cut_phase[3] = 0.0;
  /* A distributed run (the integrator has a backend, sim_backend.h): the rules keep the
   * process's cell mask, the new integrator gets the backend again (its cut hook, which
   * agrees first), and fcm__integrator_finish() at the end agrees on the outcome, so a
   * process that fails in the local work meets the others wherever they wait. */
  FCM_TRY(ctx, fcm__sim_cut_room(S, k));
  S->cut_at[k] = at;
  memset(&S->cut_stats[k], 0, sizeof S->cut_stats[k]);
  S->cut_time[k] = S->cut_solver[k] = 0.0;
  S->c.cuts++;
  if (!surf) {
    S->c.cuts_missed++;
    goto cleanup;
  }
  FCM_TRY(ctx, fcm_cell_rules_create_cut(ctx, S->mesh, S->geom, S->rules, surf, &rules));
  S->cut_phase[0] = fcm_wtime() - t0;
  S->cut_stats[k] = *fcm_cell_rules_get_stats(rules);
  S->c.cut_cells += S->cut_stats[k].num_integrated;
  if (fcm__integrator_distributed(S->integ, NULL)) {
    FCM_TRY(ctx, create_space(S, rules, rules->own, &space));
  } else { /* fcm_space_create_embedded()'s space, its topology patched from the last one's
              and its pattern in the last one's storage (given back if the cut fails) */
    const fcm_space_options so = fcm_space_options_default();
    FCM_TRY(ctx, fcm__space_create_cut_take(ctx, S->mesh, rules, &so, S->space, &space));
  }
  S->cut_phase[1] = fcm_wtime() - t0 - S->cut_phase[0];
  /* missed: no cell got a new piece and no node a new copy (a cut along cell faces adds copies
   * without splitting any cell) */
  const int missed = fcm_cell_rules_num_pieces(rules) == fcm_cell_rules_num_pieces(S->rules) &&
                     fcm_space_num_dofs(space) == fcm_space_num_dofs(S->space);
  S->c.cuts_missed += missed;
  if (missed && unchanged(S, rules))
    goto cleanup; /* the run goes on with its own; the new space gives the pattern back */
  FCM_TRY(ctx, cut_parts(S, space, &integ, &S->cut_phase[2]));
  /* the new integrator counts from zero: keep the totals so far */
  S->base_factorizations = S->c.factorizations;
  S->base_analyses = S->c.analyses;
  S->base_fallbacks = S->c.direct_fallbacks;
  fcm__space_cut_keep(space); /* the last space's pattern is the new one's for good */
  fcm_integrator_destroy(&S->integ);
  fcm_space_destroy(&S->space);
  fcm_cell_rules_destroy(&S->rules);
  S->integ = integ, S->space = space, S->rules = rules;
  integ = NULL, space = NULL, rules = NULL;
  S->c.num_dofs = fcm_space_num_dofs(S->space);
  S->c.constrained_dofs = fcm_integrator_num_constrained(S->integ);
  S->pieces = S->cut_pieces;
  S->c.pieces = S->pieces;
  FCM_TRY(ctx, build_log_blocks(S));
cleanup:
  /* a failed cut leaves the run as it was: the output surface on the space it keeps */
  if (st != FCM_OK && S->surf && space && S->surf->space == space)
    (void)fcm_embedded_surface_set_space(S->surf, S->space);
  if (k < S->cut_cap) S->cut_time[k] = fcm_wtime() - t0, S->cut_solver[k] = S->cut_phase[3];
  st = fcm__integrator_finish(S->integ, st);
  fcm_integrator_destroy(&integ);
  fcm_space_destroy(&space);
  fcm_cell_rules_destroy(&rules);
  return st;
}

fcm_status fcm__sim_apply_cut(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_effect *e = S->cuts[S->cuts_applied];
  fcm_surface *surf = NULL;
  const double t0 = fcm_wtime();
  if (S->c.cuts == 0 && !S->refined && fcm_scene_get_background(S->scene)->octree_cuts_at_cut)
    FCM_TRY(ctx, refine_for_cuts(S));
  FCM_TRY(ctx, fcm__sim_cut_surface(S, &e->cut, &surf));
  FCM_TRY(ctx, fcm__sim_cut_room(S, S->c.cuts)); /* the cut is counted once it is consumed */
  S->cuts_applied++;
  FCM_TRY(ctx, fcm__sim_cut_along(S, surf, e->cut.time, t0));
cleanup:
  fcm_surface_destroy(&surf);
  return st;
}

void fcm__sim_count_cut(fcm_simulation *S, double seconds)
{
  S->c.time_steps += seconds;
  S->c.time_cuts += seconds;
  S->c.time_cut_rules += S->cut_phase[0];
  S->c.time_cut_space += S->cut_phase[1];
  S->c.time_cut_integrator += S->cut_phase[2];
  S->c.time_cut_solver += S->cut_phase[3];
  S->c.time_cut_other +=
      fmax(0.0, seconds - S->cut_phase[0] - S->cut_phase[1] - S->cut_phase[2] - S->cut_phase[3]);
}

/* The scene's cut effects in time order (stable); they need an embedded geometry. */
static fcm_status collect_cuts(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const int n = fcm_scene_count_effects(S->scene, FCM_EFFECT_CUT);
  if (n == 0) return FCM_OK;
  FCM_ALLOC(ctx, (size_t)n, S->cuts);
  FCM_TRY(ctx, fcm__sim_cut_room(S, n - 1));
  for (int k = 0; k < fcm_scene_num_effects(S->scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(S->scene, k);
    if (e->type != FCM_EFFECT_CUT) continue;
    FCM_CHECK(S->rules, ctx, FCM_ERR_ARG,
              "scene %s: effects[%d].cut needs an embedded geometry (\"geometry\"): cuts split "
              "the embedded body",
              fcm_scene_name(S->scene), k);
    if (e->cut.kind == FCM_CUT_MESH) { /* read it now: a bad file fails before the run */
      fcm_surface *probe = NULL;
      st = fcm_surface_create_from_file(ctx, e->cut.mesh, &probe);
      if (st == FCM_OK) st = fcm__embed_cut_check(ctx, probe, e->cut.mesh);
      fcm_surface_destroy(&probe);
      if (st != FCM_OK) {
        char section[64];
        snprintf(section, sizeof section, "effects[%d].cut.surface.mesh", k);
        fcm__sim_name_section(ctx, section);
        goto cleanup;
      }
    }
    int i = S->num_cuts++;
    while (i > 0 && S->cuts[i - 1]->cut.time > e->cut.time) {
      S->cuts[i] = S->cuts[i - 1];
      i--;
    }
    S->cuts[i] = e;
  }
cleanup:
  return st;
}

/* The integrator with the scene's effects, set up (the integrator phase): effects, constraints,
 * the mass matrix and body forces, the solver's set-up; the counters of what it built. */
static fcm_status build_integrator(fcm_simulation *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_scene *scene = S->scene;
  S->c.num_dofs = fcm_space_num_dofs(S->space);
  S->c.inverted_first_cell = -1;
  S->c.nonfinite_first_step = -1;
  S->c.contact_min_distance = HUGE_VAL;
  fcm_integrator_options io = integrator_options(S);
  /* a scene with cuts, or a host that will cut: each cut integrates only the elements it
   * changes, on the old arrays */
  if (S->rules && (fcm_scene_count_effects(scene, FCM_EFFECT_CUT) > 0 || S->opts.host_cuts))
    io.cut_reuse |= FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_STORAGE;
  S->c.inertia = io.kind == FCM_INTEGRATOR_BACKWARD_EULER;
  S->c.damping = io.rayleigh_mass > 0.0 || io.rayleigh_stiffness > 0.0;
  S->c.krylov = io.linear_solver == FCM_LINEAR_CG || io.linear_solver == FCM_LINEAR_MINRES;
  S->c.multigrid = io.linear_solver == FCM_LINEAR_MULTIGRID ||
                   (S->c.krylov && io.preconditioner == FCM_PRECOND_MULTIGRID);
  fcm__sim_phase_begin(S, FCM_SETUP_INTEGRATOR, 0, "setting up the integrator (%s%s)",
                       S->c.inertia ? "mass matrix, " : "",
                       S->c.krylov ? "preconditioner"
                                   : (S->c.multigrid ? "multigrid" : "factorization"));
  if (S->c.krylov && io.preconditioner == FCM_PRECOND_SCHWARZ) {
    S->c.schwarz_blocks = count_schwarz_blocks(S, io.schwarz_theta);
    if (S->c.schwarz_blocks == 0) io.preconditioner = FCM_PRECOND_JACOBI; /* nothing to block */
  }
  FCM_TRY(ctx, fcm_integrator_create(ctx, S->space, fcm_scene_get_material(scene), &io, &S->integ));
  for (int k = 0; k < fcm_scene_num_effects(scene); k++) {
    const fcm_effect *e = fcm_scene_get_effect(scene, k);
    const fcm__effect_type *t = fcm__scene_effect_type(e->type);
    if (t->apply) FCM_TRY(ctx, t->apply(S, e));
  }
  if (S->config) FCM_TRY(ctx, fcm__integrator_attach_backend(S->integ, S->config->backend));
  FCM_TRY(ctx, fcm_integrator_setup(S->integ));
  /* the multigrid hierarchy's structure is the set-up's, as the analysis of the direct solver
   * is: the first step sets up its values as every later step does */
  FCM_TRY(ctx, fcm_integrator_prepare_solver(S->integ));
  {
    fcm_integrator_setup_info si;
    fcm_integrator_get_setup_info(S->integ, &si);
    S->c.mass_assemblies = si.mass_assemblies;
    S->c.body_force_assemblies = si.body_force_assemblies;
    S->c.traction_assemblies = si.traction_assemblies;
    S->c.scale_assemblies = si.scale_assemblies;
    S->c.boundary_points = si.boundary_points;
  }
  S->c.constrained_dofs = fcm_integrator_num_constrained(S->integ);
  fcm__sim_phase_end(S);
cleanup:
  return st;
}

fcm_status fcm_simulation_create(fcm_ctx *ctx, const fcm_scene *scene,
                                 const fcm_simulation_options *opts, fcm_simulation **out)
{
  fcm__simulation_config cfg;
  memset(&cfg, 0, sizeof cfg);
  cfg.opts = opts ? *opts : fcm_simulation_options_default();
  return fcm__simulation_create(ctx, scene, &cfg, out);
}

fcm_status fcm__simulation_create(fcm_ctx *ctx, const fcm_scene *scene,
                                  const fcm__simulation_config *cfg, fcm_simulation **out)
{
  fcm_status st = FCM_OK;
  fcm_simulation *S = NULL;
  FCM_CHECK(ctx && scene && cfg && out, ctx, FCM_ERR_ARG, "simulation: NULL argument");
  *out = NULL;
  double t0 = fcm_wtime();
  FCM_ALLOC(ctx, 1, S);
  S->ctx = ctx;
  S->config = cfg->backend ? cfg : NULL;
  S->distributed = cfg->backend != NULL;
  S->scene = scene;
  S->opts = cfg->opts;
  FCM_CHECK(S->opts.max_steps >= 1 || S->opts.max_steps == FCM_DEFAULT, ctx, FCM_ERR_ARG,
            "simulation: max_steps = %lld must be >= 1, or FCM_DEFAULT (-1: the scene's)",
            (long long)S->opts.max_steps);
  FCM_CHECK(S->opts.checkpoint_interval >= 0 || S->opts.checkpoint_interval == FCM_DEFAULT, ctx,
            FCM_ERR_ARG,
            "simulation: checkpoint_interval = %d must be >= 0, or FCM_DEFAULT (-1: the scene's)",
            S->opts.checkpoint_interval);
  const fcm_scene_time *tm = fcm_scene_get_time(scene);
  S->num_steps = tm->num_steps;
  if (S->opts.max_steps > 0 && S->opts.max_steps < S->num_steps) S->num_steps = S->opts.max_steps;

  FCM_CHECK(S->opts.rules_progress_interval >= 0.0, ctx, FCM_ERR_ARG,
            "simulation: rules_progress_interval = %g must be >= 0 seconds",
            S->opts.rules_progress_interval);

  double tp = fcm_wtime(); /* the phases' times */
  FCM_TRY(ctx, fcm__sim_build_mesh_geometry(S));
  S->c.time_setup_geometry = fcm_wtime() - tp;
  /* a region that can hold nothing is refused now, not after the cell rules */
  FCM_TRY(ctx, fcm__sim_check_regions(S));
  const fcm_scene_geometry *g = fcm_scene_get_geometry(scene);

  /* cell rules only when the scene embeds a geometry */
  if (g->kind != FCM_SCENE_GEOMETRY_NONE) {
    tp = fcm_wtime();
    fcm__sim_phase_begin(S, FCM_SETUP_CELL_RULES, S->opts.rules_progress != NULL,
                         "classifying %lld cells and building the cut cells' rules",
                         (long long)fcm_mesh_num_cells(S->mesh));
    st = build_rules(S);
    if (st != FCM_OK) fcm__error_prefix(ctx, st == FCM_ERR_GEOMETRY ? "geometry" : "quadrature");
    FCM_TRY(ctx, st);
    dropped_boundary(S);
    fcm__sim_phase_end(S);
    S->c.time_setup_rules = fcm_wtime() - tp;
    const fcm_cell_rules_stats *rs = fcm_cell_rules_get_stats(S->rules);
    FCM_CHECK(rs->num_uncut + rs->num_cut > 0, ctx, FCM_ERR_GEOMETRY,
              "geometry: every one of the %lld background cells holds less than "
              "quadrature.min_fraction = %g of its volume of the body (embedded volume %g of "
              "%g m^3): the body is too small or thin for the grid; refine the background or "
              "lower quadrature.min_fraction",
              (long long)rs->num_cells, fcm_scene_get_quadrature(scene)->rules.min_fraction,
              rs->embedded_volume, rs->geometry_volume);
    tp = fcm_wtime();
    fcm__sim_phase_begin(S, FCM_SETUP_SPACE, 0, "building the space (DOFs, element data)");
    st = create_space(S, S->rules, S->config && S->config->cell_mask ? S->rules->own : NULL,
                      &S->space);
    if (st != FCM_OK) fcm__error_prefix(ctx, "geometry");
    FCM_TRY(ctx, st);
  } else {
    tp = fcm_wtime();
    fcm__sim_phase_begin(S, FCM_SETUP_SPACE, 0, "building the space (DOFs, element data)");
    FCM_TRY(ctx, create_space(S, NULL, S->config ? S->config->cell_mask : NULL, &S->space));
  }
  fcm__sim_phase_end(S);
  S->c.time_setup_space = fcm_wtime() - tp;
  tp = fcm_wtime();
  FCM_TRY(ctx, build_integrator(S));
  S->c.time_setup_integrator = fcm_wtime() - tp;
  if (S->c.inertia) FCM_TRY(ctx, fcm__sim_initialize_effects(S));
  if (!S->rules || fcm_cell_rules_has_kind(S->rules, FCM_RULE_MASS)) {
    fcm__sim_phase_begin(S, FCM_SETUP_LOG, 0,
                         "assembling the element mass blocks of the log's mass and momentum");
    FCM_TRY(ctx, build_log_blocks(S));
    fcm__sim_phase_end(S);
  }
  S->free_body = S->c.inertia && S->c.constraints == 0 && S->c.body_force_assemblies == 0 &&
                 S->c.traction_assemblies == 0;
  if (S->free_body) FCM_TRY(ctx, fcm__sim_center_of_mass(S, NULL, S->com0));
  S->base_dofs = S->c.num_dofs;
  S->base_nodes = S->nn;
  S->base_cells = fcm_mesh_num_cells(S->mesh);
  S->base_constrained = S->c.constrained_dofs;
  S->pieces = fcm_space_num_bodies(S->space);
  S->c.pieces = S->pieces;
  FCM_TRY(ctx, collect_cuts(S));
  if (S->num_cuts > 0 && S->cuts[0]->cut.time <= 0.0) {
    fcm__sim_phase_begin(S, FCM_SETUP_CUTS, 0, "applying the cuts at t = 0");
    while (S->cuts_applied < S->num_cuts && S->cuts[S->cuts_applied]->cut.time <= 0.0)
      FCM_TRY(ctx, fcm__sim_apply_cut(S));
    fcm__sim_phase_end(S);
  }

  if (S->geom && fcm_scene_get_output(scene)->write_surface) {
    fcm__sim_phase_begin(S, FCM_SETUP_OUTPUT_SURFACE, 0,
                         "locating the output surface's %lld triangles in the background cells",
                         (long long)fcm_geometry_num_boundary_triangles(S->geom));
    FCM_TRY(ctx, build_surface(S));
    fcm__sim_phase_end(S);
  }
  S->c.time_setup = fcm_wtime() - t0;
  S->config = NULL; /* borrowed for the create only */
  *out = S;
  S = NULL;
cleanup:
  fcm_simulation_destroy(&S);
  return st;
}

const fcm_cell_rules *fcm_simulation_cell_rules(const fcm_simulation *sim)
{
  return sim ? sim->rules : NULL;
}

void fcm_simulation_destroy(fcm_simulation **sim)
{
  if (!sim || !*sim) return;
  fcm_simulation *S = *sim;
  fcm_ctx *ctx = S->ctx;
  fcm_pvd_destroy(&S->pvd_bg);
  fcm_pvd_destroy(&S->pvd_surf);
  fcm_embedded_surface_destroy(&S->surf);
  fcm_integrator_destroy(&S->integ);
  fcm_space_destroy(&S->space);
  fcm_cell_rules_destroy(&S->rules);
  fcm_geometry_destroy(&S->geom);
  fcm_mesh_destroy(&S->mesh);
  void *arrays[] = {S->log,          S->frame_time, S->loads,      S->cuts,
                    S->cut_stats,    S->cut_time,   S->cut_solver, S->cut_at,
                    S->react_effect, S->react_id,   S->react_log};
  for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
    fcm__free(ctx, arrays[k]);
  fcm__free(ctx, S);
  *sim = NULL;
}
