/* Scene sections of how it is simulated: "quadrature" (fcm_cell_rules_options), "solver"
 * (fcm_integrator_options, multigrid and its cross checks), "time" and "output". Each section
 * starts from the library's default options and overwrites the members whose keys are given. */
#include "scene/scene_impl.h"

#include <string.h>

#define GIB (1024.0 * 1024.0 * 1024.0)

static const char *const cycle_names[] = {"v", "w"};
static const int cycle_values[] = {1, 2};
static const char *const blocks_names[] = {"all", "vertex", "element"};
static const int blocks_values[] = {FCM_MG_BLOCKS_ALL, FCM_MG_BLOCKS_VERTEX, FCM_MG_BLOCKS_ELEMENT};
static const char *const block_sweep_names[] = {"symmetric", "one_way"};
static const int block_sweep_values[] = {0, 1};
/* background elements the multigrid supports (fcm_mg_create()) */
static const fcm_element_type multigrid_elements[] = {FCM_ELEMENT_HEX8, FCM_ELEMENT_HEX20};

/* ---------------------------------------------------------------- quadrature */

fcm_status fcm__scene_read_quadrature(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"stiffness_strength",
                                     "mass_strength",
                                     "surface_strength",
                                     "simplify",
                                     "simplify_method",
                                     "stabilization",
                                     "min_fraction",
                                     "max_rule_memory_gib",
                                     "moments",
                                     "stiffness_on_mass_space"};
  static const char *const skeys[] = {"mode", "alpha"};
  fcm_cell_rules_options *q = &p->scene->quadrature.rules;
  const fcm__json *o = NULL, *stab = NULL;
  size_t old = p->path_len;
  *q = fcm_cell_rules_options_default();
  double gib = q->max_rule_memory / GIB;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "quadrature", 0, &o));
  if (!o) o = fcm__json_empty_object(); /* the defaults, recorded in the normalized scene */
  SCENE_ENTER(p, "quadrature");
  size_t here = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, SCENE_COUNT(keys)));
  SCENE_READ_INT(p, o, "stiffness_strength", 0, 0, 20, q->strength[FCM_RULE_STIFFNESS]);
  SCENE_READ_INT(p, o, "mass_strength", 0, 0, 20, q->strength[FCM_RULE_MASS]);
  SCENE_READ_INT(p, o, "surface_strength", 0, 0, 20, q->surface_strength);
  /* A model that integrates the stiffness once (element-corotated) pays for the larger
   * stiffness rules only at set-up and at cuts, and gets the cut cells' stiffness exact. */
  q->stiffness_on_mass_space = p->scene->material.model == FCM_MATERIAL_COROTATED_LINEAR;
  FCM_TRY(p->ctx,
          fcm__scene_read_bool(p, o, "stiffness_on_mass_space", 0, &q->stiffness_on_mass_space));
  {
    int simplify = (int)q->simplify;
    FCM_TRY(p->ctx, fcm__scene_read_bool_or_word(p, o, "simplify", 0, "auto",
                                                 FCM_CELL_SIMPLIFY_AUTO, &simplify));
    q->simplify = (fcm_cell_simplify)simplify;
  }
  SCENE_READ_CHOICE(p, o, "simplify_method", 0, fcm__scene_simplify_names,
                    q->simplify_options.method);
  SCENE_READ_CHOICE(p, o, "moments", 0, fcm__scene_moments_names, q->moments);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "stabilization", 0, &stab));
  if (!stab) stab = fcm__json_empty_object();
  {
    SCENE_ENTER(p, "stabilization");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, stab, skeys, SCENE_COUNT(skeys)));
    SCENE_READ_CHOICE(p, stab, "mode", 0, fcm__scene_stabilization_names, q->stabilization.mode);
    FCM_TRY(p->ctx, fcm__scene_read_number(p, stab, "alpha", 0, (fcm__range){0.0, 1.0, 1, 0},
                                           &q->stabilization.alpha));
    fcm__scene_path_pop(p, here);
  }
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "min_fraction", 0, (fcm__range){0.0, 1.0, 0, 1},
                                         &q->min_fraction));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "max_rule_memory_gib", 0,
                                         (fcm__range){0.0, 1048576.0, 0, 0}, &gib));
  q->max_rule_memory = gib * GIB;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- solver */

/* "solver.multigrid": the fcm_mg_options of the multigrid (preconditioner or solver). */
static fcm_status read_multigrid(fcm__scene_parser *p, const fcm__json *mg,
                                 fcm_integrator_options *s)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"smoother",        "omega",       "pre_smooth",
                                     "post_smooth",     "cycle",       "coarse_dofs",
                                     "block_smoothing", "blocks",      "block_fraction",
                                     "block_sweep",     "point_sweep", "coarse_interval"};
  fcm_mg_options *m = &s->multigrid;
  size_t old = SCENE_ENTER(p, "multigrid");
  long long coarse = (long long)m->coarse_dofs;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, mg, keys, SCENE_COUNT(keys)));
  SCENE_READ_CHOICE_AS(p, mg, "smoother", 0, fcm__scene_smoother_names, fcm__scene_smoother_values,
                       m->smoother);
  /* 0 (the library's default): the smoother's own, fcm_mg_smoother_omega() */
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, mg, "omega", 0, (fcm__range){0.0, 2.0, 0, 1}, &m->omega));
  if (m->smoother == FCM_MG_SMOOTHER_JACOBI && m->omega > 1.0) {
    fcm__scene_path_push_key(p, "omega");
    SCENE_CHECK(0, p, FCM_ERR_ARG,
                "expected a finite number in (0, 1] with the \"jacobi\" smoother, or 0 (its "
                "own, 0.6), got %g ((0, 2) for the Gauss-Seidel smoothers)",
                m->omega);
  }
  SCENE_READ_INT(p, mg, "pre_smooth", 0, 0, 100, m->pre_smooth);
  SCENE_READ_INT(p, mg, "post_smooth", 0, 0, 100, m->post_smooth);
  SCENE_READ_CHOICE_AS(p, mg, "cycle", 0, cycle_names, cycle_values, m->cycle_index);
  FCM_TRY(p->ctx, fcm__scene_read_int(p, mg, "coarse_dofs", 0, 1, 1000000000, &coarse));
  m->coarse_dofs = (fcm_index)coarse;
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, mg, "block_smoothing", 0, &m->block_smoothing));
  SCENE_READ_CHOICE_AS(p, mg, "blocks", 0, blocks_names, blocks_values, m->blocks);
  FCM_TRY(p->ctx, fcm__scene_read_number(p, mg, "block_fraction", 0, (fcm__range){0.0, 1.0, 1, 0},
                                         &m->block_fraction));
  SCENE_READ_CHOICE_AS(p, mg, "block_sweep", 0, block_sweep_names, block_sweep_values,
                       m->block_sweep);
  SCENE_READ_CHOICE_AS(p, mg, "point_sweep", 0, block_sweep_names, block_sweep_values,
                       m->point_sweep);
  SCENE_READ_INT(p, mg, "coarse_interval", 0, 1, 1000000, m->coarse_interval);
  if (m->point_sweep && m->smoother != FCM_MG_SMOOTHER_SGS) {
    fcm__scene_path_push_key(p, "point_sweep");
    SCENE_CHECK(0, p, FCM_ERR_ARG,
                "expected \"symmetric\": \"one_way\" needs the \"sgs\" smoother");
  }
  SCENE_CHECK(m->pre_smooth + m->post_smooth >= 1, p, FCM_ERR_ARG,
              "pre_smooth = %d and post_smooth = %d: at least one smoothing step is needed",
              m->pre_smooth, m->post_smooth);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* Cross checks of the multigrid choice: a grid background of a supported element, and a
 * symmetric cycle when it preconditions CG or MINRES. The path is "solver.<key>". */
static fcm_status check_multigrid(fcm__scene_parser *p, const fcm_integrator_options *s)
{
  fcm_status st = FCM_OK;
  const int as_solver = s->linear_solver == FCM_LINEAR_MULTIGRID;
  const int as_pc = (s->linear_solver == FCM_LINEAR_CG || s->linear_solver == FCM_LINEAR_MINRES) &&
                    s->preconditioner == FCM_PRECOND_MULTIGRID;
  const fcm_scene_background *b = &p->scene->background;
  size_t old = p->path_len;
  if (!as_solver && !as_pc) return FCM_OK;
  SCENE_ENTER(p, as_solver ? "method" : "preconditioner");
  SCENE_CHECK(b->kind == FCM_SCENE_BACKGROUND_GRID, p, FCM_ERR_ARG,
              "\"multigrid\" needs a \"background\" grid (\"box\" and \"cells\": a structured "
              "box grid of hex8 or hex20 cells); a Gmsh background mesh is not supported");
  int supported = 0;
  for (size_t k = 0; k < SCENE_COUNT(multigrid_elements); k++)
    supported |= b->element == multigrid_elements[k];
  SCENE_CHECK(supported, p, FCM_ERR_ARG,
              "\"multigrid\" supports \"hex8\" and \"hex20\" background grids only, the "
              "background has \"element\": \"%s\"",
              (int)b->element >= 0 && (size_t)b->element < SCENE_COUNT(fcm__scene_element_names)
                  ? fcm__scene_element_names[b->element]
                  : "?");
  fcm__scene_path_pop(p, old);
  if (as_pc) {
    SCENE_ENTER(p, "multigrid");
    SCENE_CHECK(
        s->multigrid.pre_smooth == s->multigrid.post_smooth, p, FCM_ERR_ARG,
        "pre_smooth = %d and post_smooth = %d must be equal when the multigrid "
        "preconditions \"%s\" (the cycle must be symmetric positive definite)",
        s->multigrid.pre_smooth, s->multigrid.post_smooth,
        SCENE_CHOICE_NAME(fcm__scene_solver_names, fcm__scene_solver_values, s->linear_solver));
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_solver(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"method",         "direct",
                                     "preconditioner", "schwarz",
                                     "rtol",           "atol",
                                     "max_iterations", "newton",
                                     "threads",        "preconditioner_tangent",
                                     "multigrid",      "petsc_options",
                                     "on_inversion",   "stagnation_window",
                                     "fixed_cycles"};
  static const char *const skeys[] = {"threshold", "epsilon", "clamp"};
  static const char *const nkeys[] = {"rtol",
                                      "max_iterations",
                                      "line_search",
                                      "project_psd",
                                      "rule",
                                      "representative_acceleration",
                                      "reuse_factorization",
                                      "reuse_contraction",
                                      "fixed_iterations"};
  fcm_scene_solver *sv = &p->scene->solver;
  fcm_integrator_options *s = &sv->integrator;
  const fcm__json *o = NULL, *sw = NULL, *nw = NULL, *mg = NULL;
  size_t old = p->path_len;
  *s = fcm_integrator_options_default();
  sv->threads = FCM_DEFAULT;
  sv->petsc_options = NULL;
  sv->stop_on_inversion = 0;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "solver", 0, &o));
  if (!o) o = fcm__json_empty_object();
  SCENE_ENTER(p, "solver");
  size_t here = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, SCENE_COUNT(keys)));
  SCENE_READ_CHOICE_AS(p, o, "method", 0, fcm__scene_solver_names, fcm__scene_solver_values,
                       s->linear_solver);
  SCENE_READ_CHOICE(p, o, "direct", 0, fcm__scene_direct_names, s->direct_method);
  SCENE_READ_CHOICE(p, o, "preconditioner", 0, fcm__scene_preconditioner_names, s->preconditioner);
  SCENE_READ_CHOICE(p, o, "preconditioner_tangent", 0, fcm__scene_tangent_names,
                    s->preconditioner_tangent);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "schwarz", 0, &sw));
  if (!sw) sw = fcm__json_empty_object();
  {
    SCENE_ENTER(p, "schwarz");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, sw, skeys, SCENE_COUNT(skeys)));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, sw, "threshold", 0, (fcm__range){0.0, 1.0, 1, 0},
                                           &s->schwarz_theta));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, sw, "epsilon", 0, (fcm__range){0.0, 1.0, 1, 1},
                                           &s->schwarz.epsilon));
    SCENE_READ_CHOICE(p, sw, "clamp", 0, fcm__scene_clamp_names, s->schwarz.clamp);
    fcm__scene_path_pop(p, here);
  }
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "rtol", 0, (fcm__range){0.0, 1.0, 0, 1}, &s->krylov_rtol));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "atol", 0, FCM__NONNEGATIVE, &s->krylov_atol));
  SCENE_READ_INT(p, o, "max_iterations", 0, 1, 1000000000, s->krylov_max_iterations);
  SCENE_READ_INT(p, o, "stagnation_window", 0, 0, 1000000000, s->krylov_stagnation_window);
  SCENE_READ_INT(p, o, "fixed_cycles", 0, 0, 1000, s->multigrid_fixed_cycles);
  if (s->multigrid_fixed_cycles > 0) {
    fcm__scene_path_push_key(p, "fixed_cycles");
    SCENE_CHECK(
        s->linear_solver == FCM_LINEAR_MULTIGRID, p, FCM_ERR_ARG,
        "%d fixed cycles need \"method\": \"multigrid\", the method is \"%s\" (a direct "
        "solve is exact; \"cg\" and \"minres\" stop at \"rtol\")",
        s->multigrid_fixed_cycles,
        SCENE_CHOICE_NAME(fcm__scene_solver_names, fcm__scene_solver_values, s->linear_solver));
    fcm__scene_path_pop(p, here);
  }
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "newton", 0, &nw));
  if (!nw) nw = fcm__json_empty_object();
  {
    SCENE_ENTER(p, "newton");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, nw, nkeys, SCENE_COUNT(nkeys)));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, nw, "rtol", 0, (fcm__range){0.0, 1.0, 1, 1},
                                           &s->newton_tolerance));
    SCENE_READ_INT(p, nw, "max_iterations", 0, 1, 1000000, s->newton_max_iterations);
    SCENE_READ_INT(p, nw, "fixed_iterations", 0, 0, 1000000, s->newton_fixed_iterations);
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, nw, "line_search", 0, &s->line_search));
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, nw, "project_psd", 0, &s->project_psd));
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, nw, "reuse_factorization", 0, &s->reuse_factorization));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, nw, "reuse_contraction", 0,
                                           (fcm__range){0.0, 1.0, 1, 1}, &s->reuse_contraction));
    SCENE_READ_CHOICE_AS(p, nw, "rule", 0, fcm__scene_newton_rule_names,
                         fcm__scene_newton_rule_values, s->tolerance_mode);
    FCM_TRY(p->ctx, fcm__scene_read_number(p, nw, "representative_acceleration", 0, FCM__POSITIVE,
                                           &s->rep_acceleration));
    fcm__scene_path_pop(p, here);
  }
  SCENE_READ_INT(p, o, "threads", 0, 0, 4096, sv->threads);
  if (sv->threads == 0) sv->threads = FCM_DEFAULT; /* "threads": 0, the OpenMP default */
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "multigrid", 0, &mg));
  FCM_TRY(p->ctx, read_multigrid(p, mg ? mg : fcm__json_empty_object(), s));
  FCM_TRY(p->ctx, check_multigrid(p, s));
  FCM_TRY(p->ctx, fcm__scene_read_string(p, o, "petsc_options", 0, &sv->petsc_options));
  SCENE_READ_CHOICE(p, o, "on_inversion", 0, fcm__scene_inversion_names, sv->stop_on_inversion);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- time */

fcm_status fcm__scene_read_time(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"static", "integrator", "alpha", "rho_inf",
                                     "dt",     "duration",   "steps", "load_steps"};
  fcm_scene_time *t = &p->scene->time;
  const fcm__json *o = NULL;
  size_t old = p->path_len;
  double duration = 0.0;
  long long steps = 0;
  size_t here = 0;
  int is_static = 0;
  const fcm_integrator_options def = fcm_integrator_options_default();
  t->scheme = def.scheme;
  t->hht_alpha = def.hht_alpha;
  t->rho_inf = def.rho_inf;
  t->dt = 1.0 / 60.0;
  t->load_steps = 1;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "time", 0, &o));
  if (o) {
    SCENE_ENTER(p, "time");
    here = p->path_len;
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, SCENE_COUNT(keys)));
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "static", 0, &is_static));
    SCENE_READ_CHOICE_AS(p, o, "integrator", 0, fcm__scene_integrator_names,
                         fcm__scene_integrator_values, t->scheme);
    FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "alpha", 0, (fcm__range){-1.0 / 3.0, 0.0, 0, 0},
                                           &t->hht_alpha));
    FCM_TRY(p->ctx,
            fcm__scene_read_number(p, o, "rho_inf", 0, (fcm__range){0.0, 1.0, 0, 0}, &t->rho_inf));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "dt", 0, FCM__POSITIVE, &t->dt));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "duration", 0, FCM__POSITIVE, &duration));
    FCM_TRY(p->ctx, fcm__scene_read_int(p, o, "steps", 0, 1, 1000000000, &steps));
    SCENE_READ_INT(p, o, "load_steps", 0, 1, 1000000, t->load_steps);
    SCENE_CHECK(!(duration > 0.0 && steps > 0), p, FCM_ERR_ARG,
                "expected either \"duration\" or \"steps\", got both");
    if (fcm__json_member(o, "load_steps")) {
      fcm__scene_path_push_key(p, "load_steps");
      SCENE_CHECK(is_static, p, FCM_ERR_ARG, "only for static scenes (\"static\": true)");
      fcm__scene_path_pop(p, here);
    }
    if (fcm__json_member(o, "integrator")) {
      fcm__scene_path_push_key(p, "integrator");
      SCENE_CHECK(!is_static, p, FCM_ERR_ARG, "not used by static scenes (\"static\": true)");
      fcm__scene_path_pop(p, here);
    }
    /* each scheme's parameter only with that scheme */
    static const char *const param[] = {"alpha", "rho_inf"};
    static const fcm_time_scheme owner[] = {FCM_SCHEME_HHT, FCM_SCHEME_GENERALIZED_ALPHA};
    for (int k = 0; k < 2; k++) {
      if (!fcm__json_member(o, param[k])) continue;
      fcm__scene_path_push_key(p, param[k]);
      SCENE_CHECK(!is_static && t->scheme == owner[k], p, FCM_ERR_ARG,
                  "only for \"integrator\": \"%s\" (the integrator is \"%s\")",
                  fcm_time_scheme_name(owner[k]),
                  is_static ? "static" : fcm_time_scheme_name(t->scheme));
      fcm__scene_path_pop(p, here);
    }
  }
  t->integrator = is_static ? FCM_INTEGRATOR_STATIC : FCM_INTEGRATOR_DYNAMIC;
  if (steps == 0 && !(duration > 0.0)) {
    if (is_static)
      steps = 1;
    else
      duration = 1.0;
  }
  if (steps == 0) {
    /* A duration that is a whole number of steps up to rounding keeps that number. */
    double n = duration / t->dt, r = floor(n + 0.5);
    double count = fabs(n - r) <= 1e-9 * FCM_MAX(r, 1.0) ? r : ceil(n);
    if (o) fcm__scene_path_push_key(p, fcm__json_member(o, "duration") ? "duration" : "dt");
    SCENE_CHECK(count >= 1.0 && count <= 1e9, p, FCM_ERR_ARG,
                "expected at most 1e9 steps of dt = %g, got duration / dt = %g", t->dt, n);
    steps = (long long)FCM_MAX(count, 1.0);
  }
  t->num_steps = (fcm_index)steps;
  t->duration = (double)steps * t->dt;
  SCENE_CHECK(isfinite(t->duration), p, FCM_ERR_ARG,
              "expected a finite simulated time, got steps * dt = %g", t->duration);
  if (p->norm) { /* the normalized section says what was resolved: keys for this kind only */
    fcm__json_remove_path(p->norm, "time");
    fcm__scene_path_pop(p, old);
    fcm__scene_put_resolved_time(p, t);
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- output */

fcm_status fcm__scene_read_output(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"directory", "frame_interval", "checkpoint_interval",
                                     "background", "surface"};
  fcm_scene_output *out = &p->scene->output;
  const fcm__json *o = NULL;
  size_t old = p->path_len;
  out->directory = "fcm-output";
  out->frame_interval = 1;
  out->write_background = 1;
  out->write_surface = 1;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "output", 0, &o));
  if (!o) o = fcm__json_empty_object();
  SCENE_ENTER(p, "output");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, SCENE_COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_string(p, o, "directory", 0, &out->directory));
  SCENE_READ_INT(p, o, "frame_interval", 0, 1, 1000000000, out->frame_interval);
  SCENE_READ_INT(p, o, "checkpoint_interval", 0, 0, 1000000000, out->checkpoint_interval);
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "background", 0, &out->write_background));
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "surface", 0, &out->write_surface));
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}
