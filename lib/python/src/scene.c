/* fcm's Python binding: JSON scenes and their simulations (a host loop of steps, or a run
 * with a Python monitor after each step), their state, frames, logs and checkpoints. */
#include "fcmpy.h"

static PyObject *scene_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch;
  const char *how, *text = NULL, *name = NULL;
  if (!PyArg_ParseTuple(args, "Os|zz", &ch, &how, &text, &name)) return NULL;
  fcmpy_handle *c = fcmpy_handle_of(ch, FCMPY_CTX);
  if (!c) return NULL;
  fcm_scene *scene = NULL;
  fcm_status st;
  if (!strcmp(how, "file") && text)
    st = fcm_scene_create_from_file(c->ptr, text, &scene);
  else if (!strcmp(how, "string") && text)
    st = fcm_scene_create_from_string(c->ptr, text, name, &scene);
  else if (!strcmp(how, "default"))
    st = fcm_scene_create_default(c->ptr, &scene);
  else
    return PyErr_Format(PyExc_ValueError, "scene_create: unknown source '%s'", how);
  return fcmpy_made(st, c, FCMPY_SCENE, scene, NULL, NULL);
}

static PyObject *scene_info(PyObject *self, PyObject *sh)
{
  (void)self;
  const fcm_scene *s = fcmpy_get(sh, FCMPY_SCENE);
  if (!s) return NULL;
  const fcm_material *m = fcm_scene_get_material(s);
  return Py_BuildValue("{s:s,s:s,s:s,s:s,s:i,s:(iddd)}", "name", fcm_scene_name(s), "description",
                       fcm_scene_description(s), "source", fcm_scene_source(s), "json",
                       fcm_scene_json(s), "num_effects", fcm_scene_num_effects(s), "material",
                       (int)m->model, m->young, m->poisson, m->density);
}

static PyObject *simulation_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *sh;
  long long max_steps;
  int host_cuts = 0;
  if (!PyArg_ParseTuple(args, "OOL|p", &ch, &sh, &max_steps, &host_cuts)) return NULL;
  fcmpy_handle *c = fcmpy_handle_of(ch, FCMPY_CTX);
  const fcm_scene *scene = c ? fcmpy_get(sh, FCMPY_SCENE) : NULL;
  if (!scene) return NULL;
  fcm_simulation_options o = fcm_simulation_options_default();
  o.max_steps = (fcm_index)max_steps;
  o.host_cuts = host_cuts;
  fcm_simulation *sim = NULL;
  fcmpy_handle *scene_h = fcmpy_handle_of(sh, FCMPY_SCENE);
  fcmpy_pin(c);
  fcmpy_pin(scene_h);
  PyThreadState *gil = PyEval_SaveThread();
  fcm_status st = fcm_simulation_create(c->ptr, scene, &o, &sim);
  PyEval_RestoreThread(gil);
  PyObject *h = fcmpy_made(st, c, FCMPY_SIMULATION, sim, sh, NULL);
  fcmpy_unpin(scene_h);
  fcmpy_unpin(c);
  return h;
}

/* The monitor of fcm_simulation_run(): the Python callable gets (step, num_steps, info);
 * False stops the run (FCM_OK returned: a host's own choice), an exception too (raised). */
typedef struct monitor_state {
  fcmpy_callback *cb;
  int stopped;
} monitor_state;

static fcm_status run_monitor(void *user, fcm_simulation *sim, const fcm_simulation_step_event *ev)
{
  (void)sim;
  monitor_state *ms = user;
  PyGILState_STATE gil = PyGILState_Ensure();
  PyObject *info = fcmpy_options_dict(fcmpy_step_table, ev->info);
  PyObject *r =
      info ? PyObject_CallFunction(ms->cb->fn, "LLO", ev->step, ev->num_steps, info) : NULL;
  Py_XDECREF(info);
  fcm_status st = FCM_OK;
  if (!r) {
    fcmpy_callback_fail(ms->cb);
    st = FCM_ERR_INTERNAL;
  } else if (r == Py_False) {
    ms->stopped = 1;
    st = FCM_ERR_INTERNAL;
  }
  Py_XDECREF(r);
  PyGILState_Release(gil);
  return st;
}

static PyObject *simulation_run(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *simh, *fn, *capsule = NULL;
  if (!PyArg_ParseTuple(args, "OO", &simh, &fn)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(simh, FCMPY_SIMULATION);
  if (!h) return NULL;
  monitor_state ms = {NULL, 0};
  if (fn != Py_None && !(ms.cb = fcmpy_callback_new(fn, &capsule))) return NULL;
  fcmpy_pin(h); /* the monitor may close the simulation */
  PyThreadState *gil = PyEval_SaveThread();
  fcm_status st = fcm_simulation_run(h->ptr, ms.cb ? run_monitor : NULL, &ms);
  PyEval_RestoreThread(gil);
  PyObject *r = NULL;
  if (fcmpy_callback_restore(ms.cb)) {
    fcm_ctx_error_clear(h->ctx);
  } else if (ms.stopped) {
    fcm_ctx_error_clear(h->ctx);
    r = Py_NewRef(Py_False);
  } else {
    r = st == FCM_OK ? Py_NewRef(Py_True) : fcmpy_raise(h->ctx, st);
  }
  Py_XDECREF(capsule);
  fcmpy_unpin(h);
  return r;
}

static PyObject *simulation_info(PyObject *self, PyObject *simh)
{
  (void)self;
  fcm_simulation *s = fcmpy_get(simh, FCMPY_SIMULATION);
  if (!s) return NULL;
  return Py_BuildValue("{s:i,s:L,s:L,s:i,s:i}", "done", fcm_simulation_done(s), "step_count",
                       fcm_simulation_step_count(s), "num_steps", fcm_simulation_num_steps(s),
                       "frame_due", fcm_simulation_frame_due(s), "state_finite",
                       fcm_simulation_state_finite(s));
}

/* (u, v, t, node displacement (num_nodes, 3)): copies of the current state. */
static PyObject *simulation_state(PyObject *self, PyObject *simh)
{
  (void)self;
  fcmpy_handle *h = fcmpy_handle_of(simh, FCMPY_SIMULATION);
  if (!h) return NULL;
  fcm_integrator *integ = fcm_simulation_integrator(h->ptr);
  const fcm_space *space = fcm_simulation_space(h->ptr);
  npy_intp dims[1] = {fcm_integrator_num_dofs(integ)};
  npy_intp dn[2] = {fcm_mesh_num_nodes(fcm_space_mesh(space)), 3};
  PyObject *u = PyArray_SimpleNew(1, dims, NPY_DOUBLE), *v = PyArray_SimpleNew(1, dims, NPY_DOUBLE);
  PyObject *un = PyArray_SimpleNew(2, dn, NPY_DOUBLE);
  double t = 0;
  long long steps = 0;
  fcm_status st = FCM_ERR_ALLOC;
  if (u && v && un) {
    fcm_integrator_get_state(integ, PyArray_DATA((PyArrayObject *)u),
                             PyArray_DATA((PyArrayObject *)v), &t, &steps);
    st = fcm_space_node_field(space, PyArray_DATA((PyArrayObject *)u),
                              PyArray_DATA((PyArrayObject *)un));
  }
  if (st != FCM_OK) {
    Py_XDECREF(u);
    Py_XDECREF(v);
    Py_XDECREF(un);
    return u && v && un ? fcmpy_raise(h->ctx, st) : NULL;
  }
  return Py_BuildValue("NNdN", u, v, t, un);
}

static PyObject *simulation_write(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *simh;
  const char *what, *path;
  int index = 0;
  if (!PyArg_ParseTuple(args, "Oss|i", &simh, &what, &path, &index)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(simh, FCMPY_SIMULATION);
  if (!h) return NULL;
  fcm_status st;
  if (!strcmp(what, "log"))
    st = fcm_simulation_write_log(h->ptr, path);
  else if (!strcmp(what, "frame"))
    st = fcm_simulation_write_frame(h->ptr, path, index);
  else if (!strcmp(what, "checkpoint"))
    st = fcm_simulation_write_checkpoint(h->ptr, path);
  else if (!strcmp(what, "restore"))
    st = fcm_simulation_read_checkpoint(h->ptr, path);
  else
    return PyErr_Format(PyExc_ValueError, "simulation_write: unknown output '%s'", what);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  Py_RETURN_NONE;
}

/* fcm_simulation_cut(): (simulation, surface, frame 0 or 1) -> fcm_cut_info as a dict. */
static PyObject *simulation_cut(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *simh, *surfh;
  int frame;
  if (!PyArg_ParseTuple(args, "OOi", &simh, &surfh, &frame)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(simh, FCMPY_SIMULATION);
  fcmpy_handle *bh = h ? fcmpy_handle_of(surfh, FCMPY_SURFACE) : NULL;
  if (!bh) return NULL;
  fcm_cut_info info;
  fcmpy_pin(h); /* both stay open while the GIL is released */
  fcmpy_pin(bh);
  PyThreadState *gil = PyEval_SaveThread();
  const fcm_status st = fcm_simulation_cut(h->ptr, bh->ptr, (fcm_cut_frame)frame, &info);
  PyEval_RestoreThread(gil);
  fcmpy_unpin(bh);
  fcmpy_unpin(h);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  return Py_BuildValue(
      "{s:O,s:L,s:L,s:L,s:d,s:d,s:d,s:d,s:d}", "missed", info.missed ? Py_True : Py_False,
      "dofs_before", (long long)info.dofs_before, "dofs_after", (long long)info.dofs_after,
      "cells_integrated", (long long)info.cells_integrated, "seconds", info.seconds,
      "seconds_rules", info.seconds_rules, "seconds_space", info.seconds_space,
      "seconds_integrator", info.seconds_integrator, "seconds_solver", info.seconds_solver);
}

/* fcm_simulation_rest_positions(): (simulation, x (n, 3)) -> X (n, 3). */
static PyObject *simulation_rest_positions(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *simh, *xo;
  if (!PyArg_ParseTuple(args, "OO", &simh, &xo)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(simh, FCMPY_SIMULATION);
  if (!h) return NULL;
  PyArrayObject *x = fcmpy_input(xo, NPY_DOUBLE, 2, 3, "points");
  if (!x) return NULL;
  npy_intp dims[2] = {PyArray_DIM(x, 0), 3};
  PyObject *X = PyArray_SimpleNew(2, dims, NPY_DOUBLE);
  if (!X) {
    Py_DECREF(x);
    return NULL;
  }
  const fcm_status st = fcm_simulation_rest_positions(h->ptr, dims[0], PyArray_DATA(x),
                                                      PyArray_DATA((PyArrayObject *)X));
  Py_DECREF(x);
  if (st != FCM_OK) {
    Py_DECREF(X);
    return fcmpy_raise(h->ctx, st);
  }
  return X;
}

PyMethodDef fcmpy_scene_methods[] = {
    {"simulation_cut", simulation_cut, METH_VARARGS, NULL},
    {"simulation_rest_positions", simulation_rest_positions, METH_VARARGS, NULL},
    {"scene_create", scene_create, METH_VARARGS, NULL},
    {"scene_info", scene_info, METH_O, NULL},
    {"simulation_create", simulation_create, METH_VARARGS, NULL},
    {"simulation_run", simulation_run, METH_VARARGS, NULL},
    {"simulation_info", simulation_info, METH_O, NULL},
    {"simulation_state", simulation_state, METH_O, NULL},
    {"simulation_write", simulation_write, METH_VARARGS, NULL},
    {NULL, NULL, 0, NULL}};
