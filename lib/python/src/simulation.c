/* fcm's Python binding: spaces, integrators (a host-owned time loop, cuts between steps, loads,
 * constraints and boundary selectors given by Python callables, contact planes) and embedded
 * surfaces. */
#include "fcmpy.h"

#include <math.h>

#define IO(member) offsetof(fcm_integrator_options, member)
static const fcmpy_option integrator_table[] = {
    {"kind", 'i', 1, IO(kind)},
    {"scheme", 'i', 1, IO(scheme)},
    {"hht_alpha", 'd', 1, IO(hht_alpha)},
    {"rho_inf", 'd', 1, IO(rho_inf)},
    {"dt", 'd', 1, IO(dt)},
    {"load_steps", 'i', 1, IO(load_steps)},
    {"max_halvings", 'i', 1, IO(max_halvings)},
    {"newton_max_iterations", 'i', 1, IO(newton_max_iterations)},
    {"tolerance_mode", 'i', 1, IO(tolerance_mode)},
    {"newton_tolerance", 'd', 1, IO(newton_tolerance)},
    {"newton_atol", 'd', 1, IO(newton_atol)},
    {"rep_acceleration", 'd', 1, IO(rep_acceleration)},
    {"line_search", 'i', 1, IO(line_search)},
    {"armijo", 'd', 1, IO(armijo)},
    {"backtrack", 'd', 1, IO(backtrack)},
    {"max_backtracks", 'i', 1, IO(max_backtracks)},
    {"project_psd", 'i', 1, IO(project_psd)},
    {"reuse_factorization", 'i', 1, IO(reuse_factorization)},
    {"reuse_contraction", 'd', 1, IO(reuse_contraction)},
    {"newton_fixed_iterations", 'i', 1, IO(newton_fixed_iterations)},
    {"cut_reuse", 'i', 1, IO(cut_reuse)},
    {"linear_solver", 'i', 1, IO(linear_solver)},
    {"direct_method", 'i', 1, IO(direct_method)},
    {"preconditioner", 'i', 1, IO(preconditioner)},
    {"preconditioner_tangent", 'i', 1, IO(preconditioner_tangent)},
    {"krylov_rtol", 'd', 1, IO(krylov_rtol)},
    {"krylov_atol", 'd', 1, IO(krylov_atol)},
    {"krylov_max_iterations", 'i', 1, IO(krylov_max_iterations)},
    {"multigrid_fixed_cycles", 'i', 1, IO(multigrid_fixed_cycles)},
    {"krylov_stagnation_window", 'i', 1, IO(krylov_stagnation_window)},
    {"schwarz_theta", 'd', 1, IO(schwarz_theta)},
    {"rayleigh_mass", 'd', 1, IO(rayleigh_mass)},
    {"rayleigh_stiffness", 'd', 1, IO(rayleigh_stiffness)},
    {NULL, 0, 0, 0}};
#undef IO

/* long long and fcm_index are both 64-bit integers: 'n'. */
#define SI(member) offsetof(fcm_step_info, member)
const fcmpy_option fcmpy_step_table[] = {
    {"reason", 'i', 1, SI(reason)},
    {"newton_iterations", 'i', 1, SI(newton_iterations)},
    {"line_search_backtracks", 'i', 1, SI(line_search_backtracks)},
    {"linear_iterations", 'n', 1, SI(linear_iterations)},
    {"multigrid_cycles", 'n', 1, SI(multigrid_cycles)},
    {"residual", 'd', 1, SI(residual)},
    {"tolerance", 'd', 1, SI(tolerance)},
    {"residual_reference", 'd', 1, SI(residual_reference)},
    {"dt", 'd', 1, SI(dt)},
    {"halvings", 'i', 1, SI(halvings)},
    {"substeps", 'i', 1, SI(substeps)},
    {"failed_attempts", 'i', 1, SI(failed_attempts)},
    {"time", 'd', 1, SI(time)},
    {"kinetic_energy", 'd', 1, SI(kinetic_energy)},
    {"elastic_energy", 'd', 1, SI(elastic_energy)},
    {"external_work", 'd', 1, SI(external_work)},
    {"total_energy", 'd', 1, SI(total_energy)},
    {"load_work", 'd', 1, SI(load_work)},
    {"inverted_points", 'n', 1, SI(inverted_points)},
    {"inverted_cell", 'n', 1, SI(inverted_cell)},
    {"inverted_position", 'd', 3, SI(inverted_position)},
    {"inverted_det", 'd', 1, SI(inverted_det)},
    {"tangent_assemblies", 'i', 1, SI(tangent_assemblies)},
    {"factorizations", 'i', 1, SI(factorizations)},
    {"direct_fallbacks", 'i', 1, SI(direct_fallbacks)},
    {"projection_fallbacks", 'i', 1, SI(projection_fallbacks)},
    {"reused_factorizations", 'i', 1, SI(reused_factorizations)},
    {"inexact_solves", 'i', 1, SI(inexact_solves)},
    {"total_analyses", 'n', 1, SI(total_analyses)},
    {"total_factorizations", 'n', 1, SI(total_factorizations)},
    {"total_direct_fallbacks", 'n', 1, SI(total_direct_fallbacks)},
    {"total_multigrid_creations", 'n', 1, SI(total_multigrid_creations)},
    {"time_assembly", 'd', 1, SI(time_assembly)},
    {"time_factor", 'd', 1, SI(time_factor)},
    {"time_solve", 'd', 1, SI(time_solve)},
    {"time_total", 'd', 1, SI(time_total)},
    {NULL, 0, 0, 0}};
#undef SI

#define MO(member) offsetof(fcm_motion, member)
static const fcmpy_option motion_table[] = {{"velocity", 'd', 3, MO(velocity)},
                                            {"center", 'd', 3, MO(center)},
                                            {"axis", 'd', 3, MO(axis)},
                                            {"angular_speed", 'd', 1, MO(angular_speed)},
                                            {"start", 'd', 1, MO(start)},
                                            {"end", 'd', 1, MO(end)},
                                            {"release", 'i', 1, MO(release)},
                                            {"components", 'i', 3, MO(components)},
                                            {NULL, 0, 0, 0}};
#undef MO

#define BO(member) offsetof(fcm_boundary_options, member)
static const fcmpy_option boundary_table[] = {{"method", 'i', 1, BO(method)},
                                              {"nitsche_safety", 'd', 1, BO(nitsche_safety)},
                                              {"penalty", 'd', 1, BO(penalty)},
                                              {NULL, 0, 0, 0}};
#undef BO

static fcmpy_callback *kept_callback(fcmpy_handle *h, PyObject *fn);

/* A DOF vector of `n` doubles (a copy when it is not one already). */
static PyArrayObject *dof_vector(PyObject *obj, fcm_index n, const char *what)
{
  PyArrayObject *a = fcmpy_input(obj, NPY_DOUBLE, 1, -1, what);
  if (a && PyArray_DIM(a, 0) != n) {
    PyErr_Format(PyExc_ValueError, "%s: expected %lld values (the space's DOFs), got %zd", what,
                 (long long)n, (Py_ssize_t)PyArray_DIM(a, 0));
    Py_CLEAR(a);
  }
  return a;
}

/* ---------------------------------------------------------------- spaces */

static PyObject *space_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *mh, *rh;
  if (!PyArg_ParseTuple(args, "OOO", &ch, &mh, &rh)) return NULL;
  fcmpy_handle *c = fcmpy_handle_of(ch, FCMPY_CTX);
  fcmpy_handle *m = c ? fcmpy_handle_of(mh, FCMPY_MESH) : NULL;
  if (!m) return NULL;
  fcm_space *space = NULL;
  fcm_status st;
  if (rh == Py_None) {
    st = fcm_space_create(c->ptr, m->ptr, NULL, &space);
  } else {
    fcmpy_handle *r = fcmpy_handle_of(rh, FCMPY_RULES);
    if (!r) return NULL;
    st = fcm_space_create_embedded(c->ptr, m->ptr, r->ptr, &space);
  }
  return fcmpy_made(st, c, FCMPY_SPACE, space, mh, rh == Py_None ? NULL : rh);
}

static PyObject *space_info(PyObject *self, PyObject *sh)
{
  (void)self;
  const fcm_space *s = fcmpy_get(sh, FCMPY_SPACE);
  if (!s) return NULL;
  return Py_BuildValue("{s:L,s:L,s:L,s:i,s:L}", "num_dofs", (long long)fcm_space_num_dofs(s),
                       "num_elements", (long long)fcm_space_num_elements(s), "num_bodies",
                       (long long)fcm_space_num_bodies(s), "num_colors", fcm_space_num_colors(s),
                       "num_nodes", (long long)fcm_mesh_num_nodes(fcm_space_mesh(s)));
}

/* The first DOF of every mesh node (-1: inactive) and its number of copies: copies. */
static PyObject *space_node_dofs(PyObject *self, PyObject *sh)
{
  (void)self;
  const fcm_space *s = fcmpy_get(sh, FCMPY_SPACE);
  if (!s) return NULL;
  npy_intp dims[1] = {fcm_mesh_num_nodes(fcm_space_mesh(s))};
  PyObject *first = PyArray_SimpleNew(1, dims, NPY_INT64);
  PyObject *copies = PyArray_SimpleNew(1, dims, NPY_INT64);
  if (!first || !copies) {
    Py_XDECREF(first);
    Py_XDECREF(copies);
    return NULL;
  }
  for (npy_intp a = 0; a < dims[0]; a++) {
    ((int64_t *)PyArray_DATA((PyArrayObject *)first))[a] = fcm_space_node_dof(s, a);
    ((int64_t *)PyArray_DATA((PyArrayObject *)copies))[a] = fcm_space_node_copies(s, a);
  }
  return Py_BuildValue("NN", first, copies);
}

static PyObject *space_node_field(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *sh, *u_o;
  if (!PyArg_ParseTuple(args, "OO", &sh, &u_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(sh, FCMPY_SPACE);
  PyArrayObject *u = h ? dof_vector(u_o, fcm_space_num_dofs(h->ptr), "dofs") : NULL;
  if (!u) return NULL;
  npy_intp dims[2] = {fcm_mesh_num_nodes(fcm_space_mesh(h->ptr)), 3};
  PyObject *out = PyArray_SimpleNew(2, dims, NPY_DOUBLE);
  fcm_status st =
      out ? fcm_space_node_field(h->ptr, PyArray_DATA(u), PyArray_DATA((PyArrayObject *)out))
          : FCM_ERR_ALLOC;
  Py_DECREF(u);
  if (!out) return NULL;
  if (st != FCM_OK) {
    Py_DECREF(out);
    return fcmpy_raise(h->ctx, st);
  }
  return out;
}

static PyObject *space_cell_stress(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *sh, *mat_o, *u_o;
  fcm_material mat;
  if (!PyArg_ParseTuple(args, "OOO", &sh, &mat_o, &u_o) || fcmpy_material(mat_o, &mat) < 0)
    return NULL;
  fcmpy_handle *h = fcmpy_handle_of(sh, FCMPY_SPACE);
  PyArrayObject *u = h ? dof_vector(u_o, fcm_space_num_dofs(h->ptr), "u") : NULL;
  if (!u) return NULL;
  const fcm_index nc = fcm_mesh_num_cells(fcm_space_mesh(h->ptr));
  npy_intp d2[2] = {nc, 6}, d1[1] = {nc};
  PyObject *s = PyArray_SimpleNew(2, d2, NPY_DOUBLE), *vm = PyArray_SimpleNew(1, d1, NPY_DOUBLE);
  PyObject *e = PyArray_SimpleNew(1, d1, NPY_DOUBLE);
  fcm_status st = FCM_ERR_ALLOC;
  if (s && vm && e)
    st = fcm_space_cell_stress(h->ptr, &mat, PyArray_DATA(u), PyArray_DATA((PyArrayObject *)s),
                               PyArray_DATA((PyArrayObject *)vm), PyArray_DATA((PyArrayObject *)e));
  Py_DECREF(u);
  if (st != FCM_OK) {
    Py_XDECREF(s);
    Py_XDECREF(vm);
    Py_XDECREF(e);
    return s && vm && e ? fcmpy_raise(h->ctx, st) : NULL;
  }
  return Py_BuildValue("NNN", s, vm, e);
}

static PyObject *space_momentum(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *sh, *u_o, *v_o;
  double rho, mass = 0, p[3], L[3];
  if (!PyArg_ParseTuple(args, "OdOO", &sh, &rho, &u_o, &v_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(sh, FCMPY_SPACE);
  const fcm_index n = h ? fcm_space_num_dofs(h->ptr) : 0;
  PyArrayObject *u = h ? dof_vector(u_o, n, "u") : NULL;
  PyArrayObject *v = u ? dof_vector(v_o, n, "v") : NULL;
  if (!v) {
    Py_XDECREF(u);
    return NULL;
  }
  fcm_status st = fcm_space_momentum(h->ptr, rho, PyArray_DATA(u), PyArray_DATA(v), &mass, p, L);
  Py_DECREF(u);
  Py_DECREF(v);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  return Py_BuildValue("d(ddd)(ddd)", mass, p[0], p[1], p[2], L[0], L[1], L[2]);
}

static PyObject *space_max_displacement(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *sh, *u_o;
  double m = 0;
  if (!PyArg_ParseTuple(args, "OO", &sh, &u_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(sh, FCMPY_SPACE);
  PyArrayObject *u = h ? dof_vector(u_o, fcm_space_num_dofs(h->ptr), "u") : NULL;
  if (!u) return NULL;
  fcm_status st = fcm_space_max_displacement(h->ptr, PyArray_DATA(u), &m);
  Py_DECREF(u);
  return st == FCM_OK ? PyFloat_FromDouble(m) : fcmpy_raise(h->ctx, st);
}

static PyObject *space_write_vtu(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *sh, *mat_o, *u_o, *v_o;
  const char *path;
  fcm_material mat;
  if (!PyArg_ParseTuple(args, "OOOOs", &sh, &mat_o, &u_o, &v_o, &path) ||
      fcmpy_material(mat_o, &mat) < 0)
    return NULL;
  fcmpy_handle *h = fcmpy_handle_of(sh, FCMPY_SPACE);
  const fcm_index n = h ? fcm_space_num_dofs(h->ptr) : 0;
  PyArrayObject *u = h ? dof_vector(u_o, n, "u") : NULL;
  PyArrayObject *v = u && v_o != Py_None ? dof_vector(v_o, n, "v") : NULL;
  if (!u || (v_o != Py_None && !v)) {
    Py_XDECREF(u);
    return NULL;
  }
  fcm_status st =
      fcm_space_write_vtu(h->ptr, &mat, PyArray_DATA(u), v ? PyArray_DATA(v) : NULL, path);
  Py_DECREF(u);
  Py_XDECREF(v);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  Py_RETURN_NONE;
}

static PyObject *space_transfer(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *fh, *th, *x_o;
  if (!PyArg_ParseTuple(args, "OOO", &fh, &th, &x_o)) return NULL;
  fcmpy_handle *from = fcmpy_handle_of(fh, FCMPY_SPACE);
  fcmpy_handle *to = from ? fcmpy_handle_of(th, FCMPY_SPACE) : NULL;
  PyArrayObject *x = to ? dof_vector(x_o, fcm_space_num_dofs(from->ptr), "x") : NULL;
  if (!x) return NULL;
  npy_intp dims[1] = {fcm_space_num_dofs(to->ptr)};
  PyObject *out = PyArray_SimpleNew(1, dims, NPY_DOUBLE);
  fcm_status st = out ? fcm_space_transfer(from->ptr, to->ptr, PyArray_DATA(x),
                                           PyArray_DATA((PyArrayObject *)out))
                      : FCM_ERR_ALLOC;
  Py_DECREF(x);
  if (!out) return NULL;
  if (st != FCM_OK) {
    Py_DECREF(out);
    return fcmpy_raise(from->ctx, st);
  }
  return out;
}

/* ---------------------------------------------------------------- integrators */

static PyObject *integrator_defaults(PyObject *self, PyObject *noargs)
{
  (void)self;
  (void)noargs;
  const fcm_integrator_options o = fcm_integrator_options_default();
  return fcmpy_options_dict(integrator_table, &o);
}

static PyObject *integrator_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *sh, *mat_o, *opts_o;
  fcm_material mat;
  fcm_integrator_options o = fcm_integrator_options_default();
  if (!PyArg_ParseTuple(args, "OOOO", &ch, &sh, &mat_o, &opts_o) ||
      fcmpy_material(mat_o, &mat) < 0 ||
      fcmpy_set_options(integrator_table, &o, opts_o, "Integrator") < 0)
    return NULL;
  fcmpy_handle *c = fcmpy_handle_of(ch, FCMPY_CTX);
  fcmpy_handle *s = c ? fcmpy_handle_of(sh, FCMPY_SPACE) : NULL;
  if (!s) return NULL;
  fcm_integrator *integ = NULL;
  fcm_status st = fcm_integrator_create(c->ptr, s->ptr, &mat, &o, &integ);
  return fcmpy_made(st, c, FCMPY_INTEGRATOR, integ, sh, NULL);
}

static PyObject *integrator_create_cut(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ih, *sh;
  if (!PyArg_ParseTuple(args, "OO", &ih, &sh)) return NULL;
  fcmpy_handle *old = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  fcmpy_handle *s = old ? fcmpy_handle_of(sh, FCMPY_SPACE) : NULL;
  if (!s) return NULL;
  fcm_integrator *integ = NULL;
  fcm_status st;
  PyObject *h = NULL;
  fcmpy_pin(old);
  fcmpy_pin(s);
  PyThreadState *gil = PyEval_SaveThread();
  st = fcm_integrator_create_cut(old->ptr, s->ptr, &integ);
  PyEval_RestoreThread(gil);
  if (fcmpy_callbacks_restore(old->keep)) {
    fcm_integrator_destroy(&integ);
    fcm_ctx_error_clear(old->ctx);
  } else {
    h = fcmpy_made(st, old, FCMPY_INTEGRATOR, integ, sh, NULL);
  }
  /* the new integrator calls the old one's callables: it keeps them */
  for (Py_ssize_t i = 0; h && i < PyList_GET_SIZE(old->keep); i++) {
    PyObject *o = PyList_GET_ITEM(old->keep, i);
    if (PyCapsule_CheckExact(o) && fcmpy_keep(h, o) < 0) Py_CLEAR(h);
  }
  fcmpy_unpin(s);
  fcmpy_unpin(old);
  return h;
}

static PyObject *integrator_add_constraint(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ih, *nodes_o, *motion_o;
  fcm_motion motion = fcm_motion_default();
  if (!PyArg_ParseTuple(args, "OOO", &ih, &nodes_o, &motion_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  if (!h || fcmpy_set_options(motion_table, &motion, motion_o, "motion") < 0) return NULL;
  PyArrayObject *nodes = fcmpy_input(nodes_o, NPY_INT64, 1, -1, "nodes");
  if (!nodes) return NULL;
  int id = -1;
  fcm_status st = fcm_integrator_add_constraint(h->ptr, PyArray_DIM(nodes, 0), PyArray_DATA(nodes),
                                                &motion, &id);
  Py_DECREF(nodes);
  return st == FCM_OK ? PyLong_FromLong(id) : fcmpy_raise(h->ctx, st);
}

/* The Python selector of boundary points: called with X and the normal (float64 arrays of
 * shape (3,)); truthy selects. After an exception it selects nothing more and the setup
 * raises it. */
static int boundary_select(void *user, const double X[3], const double normal[3])
{
  fcmpy_callback *cb = user;
  PyGILState_STATE gil = PyGILState_Ensure();
  int r = 0;
  if (!cb->type) {
    npy_intp dims[1] = {3};
    PyObject *x = fcmpy_copy(X, NPY_DOUBLE, 1, dims), *n = fcmpy_copy(normal, NPY_DOUBLE, 1, dims);
    PyObject *v = x && n ? PyObject_CallFunctionObjArgs(cb->fn, x, n, NULL) : NULL;
    r = v ? PyObject_IsTrue(v) : -1;
    Py_XDECREF(x);
    Py_XDECREF(n);
    Py_XDECREF(v);
    if (r < 0) {
      fcmpy_callback_fail(cb);
      r = 0;
    }
  }
  PyGILState_Release(gil);
  return r;
}

static PyObject *integrator_add_boundary_constraint(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ih, *fn, *motion_o, *opts_o;
  fcm_motion motion = fcm_motion_default();
  fcm_boundary_options bo = fcm_boundary_options_default();
  if (!PyArg_ParseTuple(args, "OOOO", &ih, &fn, &motion_o, &opts_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  if (!h || fcmpy_set_options(motion_table, &motion, motion_o, "motion") < 0 ||
      fcmpy_set_options(boundary_table, &bo, opts_o, "boundary options") < 0)
    return NULL;
  fcmpy_callback *cb = kept_callback(h, fn);
  if (!cb) return NULL;
  int id = -1;
  fcm_status st =
      fcm_integrator_add_boundary_constraint(h->ptr, boundary_select, cb, &motion, &bo, &id);
  return st == FCM_OK ? PyLong_FromLong(id) : fcmpy_raise(h->ctx, st);
}

/* The Python field of a body force or traction: value = field(x, normal) (normal None for
 * volume fields), called from the assembly's threads (each takes the GIL). After an
 * exception the value is NaN, which fails the step; the exception is raised instead. */
static void field_eval(void *user, const double x[3], const double normal[3], double value[3])
{
  fcmpy_callback *cb = user;
  PyGILState_STATE gil = PyGILState_Ensure();
  value[0] = value[1] = value[2] = NAN;
  if (!cb->type) {
    npy_intp dims[1] = {3};
    PyObject *xa = fcmpy_copy(x, NPY_DOUBLE, 1, dims);
    PyObject *na = normal ? fcmpy_copy(normal, NPY_DOUBLE, 1, dims) : Py_NewRef(Py_None);
    PyObject *r = xa && na ? PyObject_CallFunctionObjArgs(cb->fn, xa, na, NULL) : NULL;
    double v[3];
    if (r && fcmpy_vec(r, v, 3, "the field's value") == 0) memcpy(value, v, sizeof v);
    Py_XDECREF(xa);
    Py_XDECREF(na);
    Py_XDECREF(r);
    if (PyErr_Occurred()) fcmpy_callback_fail(cb);
  }
  PyGILState_Release(gil);
}

/* The Python time scale of a load: scale(t), a float. */
static double time_scale(void *user, double t)
{
  fcmpy_callback *cb = user;
  PyGILState_STATE gil = PyGILState_Ensure();
  double v = NAN;
  if (!cb->type) {
    PyObject *r = PyObject_CallFunction(cb->fn, "d", t);
    v = r ? PyFloat_AsDouble(r) : NAN;
    Py_XDECREF(r);
    if (PyErr_Occurred()) {
      fcmpy_callback_fail(cb);
      v = NAN;
    }
  }
  PyGILState_Release(gil);
  return v;
}

/* A callable kept by the integrator for as long as the library may call it. */
static fcmpy_callback *kept_callback(fcmpy_handle *h, PyObject *fn)
{
  PyObject *capsule = NULL;
  fcmpy_callback *cb = fcmpy_callback_new(fn, &capsule);
  if (!cb) return NULL;
  int rc = fcmpy_keep((PyObject *)h, capsule);
  Py_DECREF(capsule);
  return rc < 0 ? NULL : cb;
}

/* ("gravity", accel, scale) | ("body_force" | "traction", field, scale); scale None: 1. */
static PyObject *integrator_add_load(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ih, *what_o, *scale_o;
  const char *what;
  if (!PyArg_ParseTuple(args, "OsOO", &ih, &what, &what_o, &scale_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  if (!h) return NULL;
  fcmpy_callback *scale = NULL, *field = NULL;
  double g[3];
  if (scale_o != Py_None && !(scale = kept_callback(h, scale_o))) return NULL;
  fcm_time_fn sfn = scale ? time_scale : NULL;
  fcm_status st;
  if (!strcmp(what, "gravity")) {
    if (fcmpy_vec(what_o, g, 3, "acceleration") < 0) return NULL;
    st = fcm_integrator_add_gravity(h->ptr, g, sfn, scale);
  } else if (!strcmp(what, "body_force") || !strcmp(what, "traction")) {
    if (!(field = kept_callback(h, what_o))) return NULL;
    st = what[0] == 'b' ? fcm_integrator_add_body_force(h->ptr, field_eval, field, sfn, scale)
                        : fcm_integrator_add_traction(h->ptr, field_eval, field, sfn, scale);
  } else {
    return PyErr_Format(PyExc_ValueError, "unknown load '%s'", what);
  }
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  Py_RETURN_NONE;
}

static PyObject *integrator_add_contact_plane(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ih, *p_o, *n_o, *v_o;
  double p[3], n[3], v[3], distance, stiffness;
  if (!PyArg_ParseTuple(args, "OOOOdd", &ih, &p_o, &n_o, &v_o, &distance, &stiffness)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  if (!h || fcmpy_vec(p_o, p, 3, "point") < 0 || fcmpy_vec(n_o, n, 3, "normal") < 0 ||
      fcmpy_vec(v_o, v, 3, "velocity") < 0)
    return NULL;
  fcm_contact_options o = fcm_contact_options_default();
  o.distance = distance;
  o.stiffness = stiffness;
  int id = -1;
  fcm_status st = fcm_integrator_add_contact_plane(h->ptr, p, n, v, &o, &id);
  return st == FCM_OK ? PyLong_FromLong(id) : fcmpy_raise(h->ctx, st);
}

static PyObject *integrator_contact_info(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ih;
  int id;
  double f[3], dmin = 0, dhat = 0, kappa = 0;
  if (!PyArg_ParseTuple(args, "Oi", &ih, &id)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  if (!h) return NULL;
  fcm_status st = fcm_integrator_contact_info(h->ptr, id, f, &dmin, &dhat, &kappa);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  return Py_BuildValue("{s:(ddd),s:d,s:d,s:d}", "force", f[0], f[1], f[2], "min_distance", dmin,
                       "distance", dhat, "stiffness", kappa);
}

/* Call the integrator, the GIL released (a boundary selector may run on any thread); a
 * selector's exception is raised in place of the library's error. */
static PyObject *integrator_call(fcmpy_handle *h, fcm_status st)
{
  if (fcmpy_callbacks_restore(h->keep)) {
    fcm_ctx_error_clear(h->ctx);
    return NULL;
  }
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  Py_RETURN_NONE;
}

static PyObject *integrator_setup(PyObject *self, PyObject *ih)
{
  (void)self;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  if (!h) return NULL;
  fcmpy_pin(h);
  PyThreadState *gil = PyEval_SaveThread();
  fcm_status st = fcm_integrator_setup(h->ptr);
  PyEval_RestoreThread(gil);
  PyObject *r = integrator_call(h, st);
  fcmpy_unpin(h);
  return r;
}

/* One step of an integrator or of a simulation (the handle says which): its report. */
static PyObject *take_step(PyObject *self, PyObject *obj)
{
  (void)self;
  const int sim = PyObject_TypeCheck(obj, &fcmpy_handle_type) &&
                  ((fcmpy_handle *)obj)->kind == FCMPY_SIMULATION;
  fcmpy_handle *h = fcmpy_handle_of(obj, sim ? FCMPY_SIMULATION : FCMPY_INTEGRATOR);
  if (!h) return NULL;
  fcm_step_info info;
  fcm_status st;
  memset(&info, 0, sizeof info);
  fcmpy_pin(h);
  PyThreadState *gil = PyEval_SaveThread();
  st = sim ? fcm_simulation_step(h->ptr, &info) : fcm_integrator_step(h->ptr, &info);
  PyEval_RestoreThread(gil);
  PyObject *r = integrator_call(h, st);
  fcmpy_unpin(h);
  if (!r) return NULL;
  Py_DECREF(r);
  return fcmpy_options_dict(fcmpy_step_table, &info);
}

/* (u, v, t, steps): copies (the integrator overwrites its state every step). */
static PyObject *integrator_state(PyObject *self, PyObject *ih)
{
  (void)self;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  if (!h) return NULL;
  npy_intp dims[1] = {fcm_integrator_num_dofs(h->ptr)};
  PyObject *u = PyArray_SimpleNew(1, dims, NPY_DOUBLE), *v = PyArray_SimpleNew(1, dims, NPY_DOUBLE);
  if (!u || !v) {
    Py_XDECREF(u);
    Py_XDECREF(v);
    return NULL;
  }
  double t = 0;
  long long steps = 0;
  fcm_integrator_get_state(h->ptr, PyArray_DATA((PyArrayObject *)u),
                           PyArray_DATA((PyArrayObject *)v), &t, &steps);
  return Py_BuildValue("NNdL", u, v, t, steps);
}

static PyObject *integrator_set_state(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ih, *u_o, *v_o;
  double t;
  long long steps;
  if (!PyArg_ParseTuple(args, "OOOdL", &ih, &u_o, &v_o, &t, &steps)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  const fcm_index n = h ? fcm_integrator_num_dofs(h->ptr) : 0;
  PyArrayObject *u = h ? dof_vector(u_o, n, "u") : NULL;
  PyArrayObject *v = u ? dof_vector(v_o, n, "v") : NULL;
  if (!v) {
    Py_XDECREF(u);
    return NULL;
  }
  fcm_status st = fcm_integrator_set_state(h->ptr, PyArray_DATA(u), PyArray_DATA(v), t, steps);
  Py_DECREF(u);
  Py_DECREF(v);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  Py_RETURN_NONE;
}

static PyObject *integrator_reaction(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ih;
  int id, boundary;
  double f[3], m[3];
  if (!PyArg_ParseTuple(args, "Oip", &ih, &id, &boundary)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  if (!h) return NULL;
  fcm_status st = boundary ? fcm_integrator_boundary_reaction(h->ptr, id, f, m)
                           : fcm_integrator_reaction(h->ptr, id, f, m);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  return Py_BuildValue("(ddd)(ddd)", f[0], f[1], f[2], m[0], m[1], m[2]);
}

static PyObject *integrator_energy(PyObject *self, PyObject *ih)
{
  (void)self;
  fcmpy_handle *h = fcmpy_handle_of(ih, FCMPY_INTEGRATOR);
  double k = 0, e = 0, w = 0, p[3], L[3];
  if (!h) return NULL;
  fcm_status st = fcm_integrator_energy(h->ptr, &k, &e, &w);
  if (st == FCM_OK) st = fcm_integrator_momentum(h->ptr, p, L);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  return Py_BuildValue("{s:d,s:d,s:d,s:(ddd),s:(ddd),s:d,s:L}", "kinetic", k, "elastic", e,
                       "external_work", w, "linear_momentum", p[0], p[1], p[2], "angular_momentum",
                       L[0], L[1], L[2], "time", fcm_integrator_time(h->ptr), "step_count",
                       fcm_integrator_step_count(h->ptr));
}

/* ---------------------------------------------------------------- embedded surfaces */

static PyObject *esurf_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *sh, *gh;
  if (!PyArg_ParseTuple(args, "OO", &sh, &gh)) return NULL;
  fcmpy_handle *s = fcmpy_handle_of(sh, FCMPY_SPACE);
  const fcm_geometry *g = s ? fcmpy_get(gh, FCMPY_GEOMETRY) : NULL;
  if (!g) return NULL;
  fcm_embedded_surface *es = NULL;
  fcm_status st = fcm_embedded_surface_create(s->ptr, g, &es);
  return fcmpy_made(st, s, FCMPY_EMBEDDED_SURFACE, es, sh, gh);
}

static PyObject *esurf_set_space(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *eh, *sh;
  if (!PyArg_ParseTuple(args, "OO", &eh, &sh)) return NULL;
  fcmpy_handle *e = fcmpy_handle_of(eh, FCMPY_EMBEDDED_SURFACE);
  fcmpy_handle *s = e ? fcmpy_handle_of(sh, FCMPY_SPACE) : NULL;
  if (!s) return NULL;
  fcm_status st = fcm_embedded_surface_set_space(e->ptr, s->ptr);
  if (st != FCM_OK) return fcmpy_raise(e->ctx, st);
  /* depend on the new space instead of the old one */
  for (Py_ssize_t i = 0; i < PyList_GET_SIZE(e->keep); i++) {
    PyObject *o = PyList_GET_ITEM(e->keep, i);
    if (PyObject_TypeCheck(o, &fcmpy_handle_type) && ((fcmpy_handle *)o)->kind == FCMPY_SPACE) {
      Py_INCREF(o);
      Py_INCREF(s);
      s->users++;
      if (PyList_SetItem(e->keep, i, (PyObject *)s) < 0) { /* steals s */
        Py_DECREF(o);
        return NULL;
      }
      fcmpy_handle_release_user((fcmpy_handle *)o);
      Py_DECREF(o);
      break;
    }
  }
  Py_RETURN_NONE;
}

static PyObject *esurf_arrays(PyObject *self, PyObject *eh)
{
  (void)self;
  const fcm_embedded_surface *e = fcmpy_get(eh, FCMPY_EMBEDDED_SURFACE);
  if (!e) return NULL;
  npy_intp dp[2] = {fcm_embedded_surface_num_points(e), 3};
  npy_intp dt[2] = {fcm_embedded_surface_num_triangles(e), 3};
  return Py_BuildValue("NN", fcmpy_view(eh, fcm_embedded_surface_points(e), NPY_DOUBLE, 2, dp),
                       fcmpy_view(eh, fcm_embedded_surface_triangles(e), NPY_INT64, 2, dt));
}

static PyObject *esurf_eval(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *eh, *u_o;
  if (!PyArg_ParseTuple(args, "OO", &eh, &u_o)) return NULL;
  fcmpy_handle *e = fcmpy_handle_of(eh, FCMPY_EMBEDDED_SURFACE);
  if (!e) return NULL;
  PyArrayObject *u = fcmpy_input(u_o, NPY_DOUBLE, 1, -1, "u");
  if (!u) return NULL;
  npy_intp dims[2] = {fcm_embedded_surface_num_points(e->ptr), 3};
  PyObject *d = PyArray_SimpleNew(2, dims, NPY_DOUBLE), *x = PyArray_SimpleNew(2, dims, NPY_DOUBLE);
  fcm_status st = FCM_ERR_ALLOC;
  if (d && x)
    st = fcm_embedded_surface_eval(e->ptr, PyArray_DATA(u), PyArray_DATA((PyArrayObject *)d),
                                   PyArray_DATA((PyArrayObject *)x));
  Py_DECREF(u);
  if (st != FCM_OK) {
    Py_XDECREF(d);
    Py_XDECREF(x);
    return d && x ? fcmpy_raise(e->ctx, st) : NULL;
  }
  return Py_BuildValue("NN", d, x);
}

static PyObject *esurf_write_vtu(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *eh, *mat_o, *u_o;
  const char *path;
  fcm_material mat;
  if (!PyArg_ParseTuple(args, "OOOs", &eh, &mat_o, &u_o, &path) || fcmpy_material(mat_o, &mat) < 0)
    return NULL;
  fcmpy_handle *e = fcmpy_handle_of(eh, FCMPY_EMBEDDED_SURFACE);
  PyArrayObject *u = e ? fcmpy_input(u_o, NPY_DOUBLE, 1, -1, "u") : NULL;
  if (!u) return NULL;
  fcm_status st = fcm_embedded_surface_write_vtu(e->ptr, &mat, PyArray_DATA(u), path);
  Py_DECREF(u);
  if (st != FCM_OK) return fcmpy_raise(e->ctx, st);
  Py_RETURN_NONE;
}

PyMethodDef fcmpy_simulation_methods[] = {
    {"space_create", space_create, METH_VARARGS, NULL},
    {"space_info", space_info, METH_O, NULL},
    {"space_node_dofs", space_node_dofs, METH_O, NULL},
    {"space_node_field", space_node_field, METH_VARARGS, NULL},
    {"space_cell_stress", space_cell_stress, METH_VARARGS, NULL},
    {"space_momentum", space_momentum, METH_VARARGS, NULL},
    {"space_max_displacement", space_max_displacement, METH_VARARGS, NULL},
    {"space_write_vtu", space_write_vtu, METH_VARARGS, NULL},
    {"space_transfer", space_transfer, METH_VARARGS, NULL},
    {"integrator_defaults", integrator_defaults, METH_NOARGS, NULL},
    {"integrator_create", integrator_create, METH_VARARGS, NULL},
    {"integrator_create_cut", integrator_create_cut, METH_VARARGS, NULL},
    {"integrator_add_load", integrator_add_load, METH_VARARGS, NULL},
    {"integrator_add_contact_plane", integrator_add_contact_plane, METH_VARARGS, NULL},
    {"integrator_contact_info", integrator_contact_info, METH_VARARGS, NULL},
    {"integrator_add_constraint", integrator_add_constraint, METH_VARARGS, NULL},
    {"integrator_add_boundary_constraint", integrator_add_boundary_constraint, METH_VARARGS, NULL},
    {"integrator_setup", integrator_setup, METH_O, NULL},
    {"step", take_step, METH_O, NULL},
    {"integrator_state", integrator_state, METH_O, NULL},
    {"integrator_set_state", integrator_set_state, METH_VARARGS, NULL},
    {"integrator_reaction", integrator_reaction, METH_VARARGS, NULL},
    {"integrator_energy", integrator_energy, METH_O, NULL},
    {"esurf_create", esurf_create, METH_VARARGS, NULL},
    {"esurf_set_space", esurf_set_space, METH_VARARGS, NULL},
    {"esurf_arrays", esurf_arrays, METH_O, NULL},
    {"esurf_eval", esurf_eval, METH_VARARGS, NULL},
    {"esurf_write_vtu", esurf_write_vtu, METH_VARARGS, NULL},
    {NULL, NULL, 0, NULL}};
