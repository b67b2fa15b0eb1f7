/* fcm's Python binding: the module fcm._fcm, the handle type every fcm object lives in and
 * the NumPy views that keep it alive, the exception fcm.Error, and the context. */
#define FCMPY_IMPORT_ARRAY
#include "fcmpy.h"

PyObject *fcmpy_error_type = NULL;

static const char *const kind_names[FCMPY_KIND_COUNT] = {
    "Context", "Mesh",       "Geometry",        "Surface", "VoxelImage", "CellRules",
    "Space",   "Integrator", "EmbeddedSurface", "Scene",   "Simulation"};

static void destroy_ptr(fcmpy_kind kind, void *ptr)
{
  switch (kind) {
  case FCMPY_CTX:
    fcm_ctx_destroy((fcm_ctx **)&ptr);
    break;
  case FCMPY_MESH:
    fcm_mesh_destroy((fcm_mesh **)&ptr);
    break;
  case FCMPY_GEOMETRY:
    fcm_geometry_destroy((fcm_geometry **)&ptr);
    break;
  case FCMPY_SURFACE:
    fcm_surface_destroy((fcm_surface **)&ptr);
    break;
  case FCMPY_VOXELS:
    fcm_voxel_image_destroy((fcm_voxel_image **)&ptr);
    break;
  case FCMPY_RULES:
    fcm_cell_rules_destroy((fcm_cell_rules **)&ptr);
    break;
  case FCMPY_SPACE:
    fcm_space_destroy((fcm_space **)&ptr);
    break;
  case FCMPY_INTEGRATOR:
    fcm_integrator_destroy((fcm_integrator **)&ptr);
    break;
  case FCMPY_EMBEDDED_SURFACE:
    fcm_embedded_surface_destroy((fcm_embedded_surface **)&ptr);
    break;
  case FCMPY_SCENE:
    fcm_scene_destroy((fcm_scene **)&ptr);
    break;
  case FCMPY_SIMULATION:
    fcm_simulation_destroy((fcm_simulation **)&ptr);
    break;
  case FCMPY_KIND_COUNT:
    break;
  }
}

/* Destroy the object once nothing reads it any more, then let go of what it was made from. */
static void try_release(fcmpy_handle *h)
{
  if (!h->closed || h->users > 0 || h->views > 0 || !h->ptr) return;
  destroy_ptr(h->kind, h->ptr);
  h->ptr = NULL;
  PyObject *keep = h->keep;
  h->keep = NULL;
  if (!keep) return;
  for (Py_ssize_t i = 0; i < PyList_GET_SIZE(keep); i++) {
    PyObject *o = PyList_GET_ITEM(keep, i);
    if (PyObject_TypeCheck(o, &fcmpy_handle_type)) {
      fcmpy_handle *dep = (fcmpy_handle *)o;
      dep->users--;
      try_release(dep);
    }
  }
  Py_DECREF(keep);
}

void fcmpy_handle_release_user(fcmpy_handle *h)
{
  h->users--;
  try_release(h);
}

void fcmpy_pin(fcmpy_handle *h)
{
  Py_INCREF(h);
  h->views++;
}

void fcmpy_unpin(fcmpy_handle *h)
{
  h->views--;
  try_release(h);
  Py_DECREF(h);
}

/* The base object of a view: holds the handle and counts itself in its views, so the fcm
 * object outlives every view into it even when the handle is closed first. */
typedef struct guard {
  PyObject_HEAD fcmpy_handle *owner;
} guard;

static void guard_dealloc(guard *g)
{
  fcmpy_handle *h = g->owner;
  g->owner = NULL;
  if (h) {
    h->views--;
    try_release(h);
    Py_DECREF(h);
  }
  PyObject_Free(g);
}

static PyTypeObject fcmpy_guard_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "fcm._fcm.ViewOwner",
    .tp_basicsize = sizeof(guard),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Keeps an fcm object alive while a NumPy view reads its memory.",
    .tp_dealloc = (destructor)guard_dealloc,
};

PyObject *fcmpy_view(PyObject *owner, const void *data, int typenum, int nd, const npy_intp *dims)
{
  npy_intp size = 1;
  for (int d = 0; d < nd; d++)
    size *= dims[d];
  if (!data || size == 0) { /* nothing to share: an empty (or zero) array of its own */
    PyObject *a = PyArray_ZEROS(nd, (npy_intp *)dims, typenum, 0);
    if (a) PyArray_CLEARFLAGS((PyArrayObject *)a, NPY_ARRAY_WRITEABLE);
    return a;
  }
  guard *g = PyObject_New(guard, &fcmpy_guard_type);
  if (!g) return NULL;
  fcmpy_handle *h = (fcmpy_handle *)owner;
  Py_INCREF(h);
  h->views++;
  g->owner = h;
  PyObject *a = PyArray_New(&PyArray_Type, nd, (npy_intp *)dims, typenum, NULL, (void *)data, 0,
                            NPY_ARRAY_CARRAY_RO, NULL);
  if (!a) {
    Py_DECREF(g);
    return NULL;
  }
  if (PyArray_SetBaseObject((PyArrayObject *)a, (PyObject *)g) < 0) { /* steals g */
    Py_DECREF(a);
    return NULL;
  }
  return a;
}

PyObject *fcmpy_handle_new(fcmpy_kind kind, void *ptr, fcm_ctx *ctx, PyObject *const *deps,
                           int num_deps)
{
  fcmpy_handle *h = PyObject_GC_New(fcmpy_handle, &fcmpy_handle_type);
  if (!h) {
    destroy_ptr(kind, ptr);
    return NULL;
  }
  h->kind = kind;
  h->ptr = ptr;
  h->ctx = ctx;
  h->closed = 0;
  h->users = 0;
  h->views = 0;
  h->keep = PyList_New(0);
  if (!h->keep) {
    h->closed = 1;
    Py_DECREF(h);
    return NULL;
  }
  for (int i = 0; i < num_deps; i++) {
    if (!deps[i]) continue;
    fcmpy_handle *dep = (fcmpy_handle *)deps[i];
    if (!PyObject_TypeCheck(deps[i], &fcmpy_handle_type)) { /* a wrapper: its handle */
      PyObject *inner = PyObject_GetAttrString(deps[i], "_h");
      Py_XDECREF(inner); /* the wrapper keeps it */
      if (!inner || !PyObject_TypeCheck(inner, &fcmpy_handle_type)) {
        PyErr_Clear();
        PyErr_SetString(PyExc_TypeError, "an fcm object was expected");
        h->closed = 1;
        Py_DECREF(h);
        return NULL;
      }
      dep = (fcmpy_handle *)inner;
    }
    if (PyList_Append(h->keep, (PyObject *)dep) < 0) {
      h->closed = 1;
      Py_DECREF(h);
      return NULL;
    }
    dep->users++;
  }
  PyObject_GC_Track(h);
  return (PyObject *)h;
}

fcmpy_handle *fcmpy_handle_of(PyObject *obj, fcmpy_kind kind)
{
  PyObject *inner = NULL;
  if (!PyObject_TypeCheck(obj, &fcmpy_handle_type)) { /* a wrapper class: its _h */
    inner = PyObject_GetAttrString(obj, "_h");
    if (!inner || !PyObject_TypeCheck(inner, &fcmpy_handle_type)) {
      PyErr_Clear();
      Py_XDECREF(inner);
      PyErr_Format(PyExc_TypeError, "expected an fcm %s, got %.200s", kind_names[kind],
                   Py_TYPE(obj)->tp_name);
      return NULL;
    }
    Py_DECREF(inner); /* the wrapper keeps it */
    obj = inner;
  }
  fcmpy_handle *h = (fcmpy_handle *)obj;
  if (h->kind != kind) {
    PyErr_Format(PyExc_TypeError, "expected an fcm %s, got an fcm %s", kind_names[kind],
                 kind_names[h->kind]);
    return NULL;
  }
  if (h->closed || !h->ptr) {
    PyErr_Format(PyExc_ValueError, "the %s is closed (close() was called)", kind_names[kind]);
    return NULL;
  }
  return h;
}

void *fcmpy_get(PyObject *obj, fcmpy_kind kind)
{
  fcmpy_handle *h = fcmpy_handle_of(obj, kind);
  return h ? h->ptr : NULL;
}

int fcmpy_keep(PyObject *handle, PyObject *obj)
{
  fcmpy_handle *h = (fcmpy_handle *)handle;
  return h->keep ? PyList_Append(h->keep, obj) : 0;
}

/* A new handle of `kind` made in the context of `parent` from the handles `deps`. */
PyObject *fcmpy_made(fcm_status st, fcmpy_handle *parent, fcmpy_kind kind, void *ptr,
                     PyObject *dep1, PyObject *dep2)
{
  if (st != FCM_OK) return fcmpy_raise(parent->ctx, st);
  PyObject *ctx_h =
      parent->kind == FCMPY_CTX ? (PyObject *)parent : PyList_GET_ITEM(parent->keep, 0);
  PyObject *deps[3] = {ctx_h, dep1, dep2};
  return fcmpy_handle_new(kind, ptr, parent->ctx, deps, 3);
}

PyObject *fcmpy_raise(fcm_ctx *ctx, fcm_status st)
{
  const char *msg = ctx ? fcm_ctx_error_message(ctx) : "";
  if (!msg || !msg[0]) msg = fcm_status_name(st);
  PyObject *text = PyUnicode_DecodeUTF8(msg, (Py_ssize_t)strlen(msg), "replace");
  PyObject *exc = text ? PyObject_CallFunctionObjArgs(fcmpy_error_type, text, NULL) : NULL;
  Py_XDECREF(text);
  if (!exc) return NULL;
  PyObject *code = PyLong_FromLong((long)st);
  PyObject *name = PyUnicode_FromString(fcm_status_name(st));
  if (code && name && PyObject_SetAttrString(exc, "status", code) == 0 &&
      PyObject_SetAttrString(exc, "status_name", name) == 0)
    PyErr_SetObject(fcmpy_error_type, exc);
  Py_XDECREF(code);
  Py_XDECREF(name);
  Py_DECREF(exc);
  if (ctx) fcm_ctx_error_clear(ctx);
  return NULL;
}

/* ---------------------------------------------------------------- the handle type */

static int handle_traverse(fcmpy_handle *h, visitproc visit, void *arg)
{
  Py_VISIT(h->keep);
  return 0;
}

static int handle_clear(fcmpy_handle *h)
{
  h->closed = 1;
  try_release(h); /* a handle others still use keeps what it holds */
  return 0;
}

static void handle_dealloc(fcmpy_handle *h)
{
  PyObject_GC_UnTrack(h);
  h->closed = 1;
  h->users = 0; /* nothing refers to this handle any more */
  h->views = 0;
  try_release(h);
  Py_CLEAR(h->keep);
  PyObject_GC_Del(h);
}

static PyObject *handle_close(fcmpy_handle *h, PyObject *noargs)
{
  (void)noargs;
  h->closed = 1;
  try_release(h);
  Py_RETURN_NONE;
}

static PyObject *handle_get_closed(fcmpy_handle *h, void *closure)
{
  (void)closure;
  return PyBool_FromLong(h->closed);
}

static PyObject *handle_get_kind(fcmpy_handle *h, void *closure)
{
  (void)closure;
  return PyUnicode_FromString(kind_names[h->kind]);
}

static PyObject *handle_get_released(fcmpy_handle *h, void *closure)
{
  (void)closure;
  return PyBool_FromLong(h->ptr == NULL);
}

static PyObject *handle_repr(fcmpy_handle *h)
{
  return PyUnicode_FromFormat("<fcm %s handle%s>", kind_names[h->kind],
                              h->closed ? " (closed)" : "");
}

static PyMethodDef handle_methods[] = {
    {"close", (PyCFunction)handle_close, METH_NOARGS,
     "Close the object: it refuses further calls, and the C object is destroyed as soon as no "
     "view or object made from it is left."},
    {NULL, NULL, 0, NULL}};

static PyGetSetDef handle_getset[] = {
    {"closed", (getter)handle_get_closed, NULL, "True after close()", NULL},
    {"kind", (getter)handle_get_kind, NULL, "the fcm class the handle holds", NULL},
    {"released", (getter)handle_get_released, NULL, "True once the C object is destroyed", NULL},
    {NULL, NULL, NULL, NULL, NULL}};

PyTypeObject fcmpy_handle_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "fcm._fcm.Handle",
    .tp_basicsize = sizeof(fcmpy_handle),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "An fcm object owned by Python (internal; wrapped by the classes of fcm).",
    .tp_dealloc = (destructor)handle_dealloc,
    .tp_traverse = (traverseproc)handle_traverse,
    .tp_clear = (inquiry)handle_clear,
    .tp_repr = (reprfunc)handle_repr,
    .tp_methods = handle_methods,
    .tp_getset = handle_getset,
};

/* ---------------------------------------------------------------- the context */

static PyObject *ctx_create(PyObject *self, PyObject *args)
{
  (void)self;
  int num_threads = FCM_DEFAULT;
  if (!PyArg_ParseTuple(args, "i", &num_threads)) return NULL;
  fcm_ctx_options o = fcm_ctx_options_default();
  o.num_threads = num_threads;
  fcm_ctx *ctx = NULL;
  fcm_status st = fcm_ctx_create(&o, &ctx);
  if (st != FCM_OK) {
    if (st == FCM_ERR_ARG)
      return PyErr_Format(PyExc_ValueError,
                          "num_threads = %d: must be >= 1 or -1 (the OpenMP default)", num_threads);
    return fcmpy_raise(NULL, st);
  }
  return fcmpy_handle_new(FCMPY_CTX, ctx, ctx, NULL, 0);
}

static PyObject *ctx_num_threads(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *h;
  int n = 0;
  if (!PyArg_ParseTuple(args, "O|i", &h, &n)) return NULL;
  fcm_ctx *ctx = fcmpy_get(h, FCMPY_CTX);
  if (!ctx) return NULL;
  if (PyTuple_GET_SIZE(args) > 1) {
    fcm_status st = fcm_ctx_set_num_threads(ctx, n);
    if (st != FCM_OK) return fcmpy_raise(ctx, st);
  }
  return PyLong_FromLong(fcm_ctx_num_threads(ctx));
}

static PyObject *ctx_live_allocations(PyObject *self, PyObject *h)
{
  (void)self;
  fcm_ctx *ctx = fcmpy_get(h, FCMPY_CTX);
  return ctx ? PyLong_FromLongLong(fcm_ctx_live_allocations(ctx)) : NULL;
}

static PyObject *status_name(PyObject *self, PyObject *arg)
{
  (void)self;
  long st = PyLong_AsLong(arg);
  if (st == -1 && PyErr_Occurred()) return NULL;
  return PyUnicode_FromString(fcm_status_name((fcm_status)st));
}

/* The text an fcm_x_view() prints for a mesh, geometry, rules or simulation. */
static PyObject *object_text(PyObject *self, PyObject *obj)
{
  (void)self;
  PyObject *inner = PyObject_TypeCheck(obj, &fcmpy_handle_type) ? NULL : obj;
  fcmpy_handle *h = (fcmpy_handle *)obj;
  if (inner || h->closed || !h->ptr)
    return PyErr_Format(PyExc_TypeError, "text: expected an open fcm handle");
  char *buf;
  size_t len;
  FILE *f = fcmpy_stream_open(&buf, &len);
  if (!f) return NULL;
  switch (h->kind) {
  case FCMPY_MESH:
    fcm_mesh_view(h->ptr, f);
    break;
  case FCMPY_GEOMETRY:
    fcm_geometry_view(h->ptr, f);
    break;
  case FCMPY_RULES:
    fcm_cell_rules_view(h->ptr, f);
    break;
  case FCMPY_SIMULATION:
    fcm_simulation_summary_view(h->ptr, f);
    break;
  default:
    break;
  }
  return fcmpy_stream_close(f, &buf, &len);
}

static PyMethodDef module_methods[] = {{"ctx_create", ctx_create, METH_VARARGS, NULL},
                                       {"ctx_num_threads", ctx_num_threads, METH_VARARGS, NULL},
                                       {"ctx_live_allocations", ctx_live_allocations, METH_O, NULL},
                                       {"status_name", status_name, METH_O, NULL},
                                       {"text", object_text, METH_O, NULL},
                                       {NULL, NULL, 0, NULL}};

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, .m_name = "fcm._fcm",
    .m_doc = "fcm's C API for Python (internal: use the package fcm).", .m_size = -1,
    .m_methods = module_methods};

/* The status codes as module constants without the prefix: OK, ERR_ARG, ... */
static int add_statuses(PyObject *m)
{
#define FCMPY_ADD_STATUS_(name, msg) PyModule_AddIntConstant(m, #name + 4, name) ||
  return FCM_STATUS_LIST(FCMPY_ADD_STATUS_) 0 ? -1 : 0;
#undef FCMPY_ADD_STATUS_
}

PyMODINIT_FUNC PyInit__fcm(void);
PyMODINIT_FUNC PyInit__fcm(void)
{
  import_array();
  if (PyType_Ready(&fcmpy_handle_type) < 0 || PyType_Ready(&fcmpy_guard_type) < 0) return NULL;
  PyObject *m = PyModule_Create(&module_def);
  if (!m) return NULL;
  fcmpy_error_type = PyErr_NewExceptionWithDoc(
      "fcm.Error",
      "An fcm call failed: `status` is the fcm_status code (an int), `status_name` its "
      "description, and the message is the library's (naming the object, the value and the "
      "valid range).",
      PyExc_RuntimeError, NULL);
  if (!fcmpy_error_type || PyModule_AddObjectRef(m, "Error", fcmpy_error_type) < 0 ||
      PyModule_AddObjectRef(m, "Handle", (PyObject *)&fcmpy_handle_type) < 0 ||
      PyModule_AddStringConstant(m, "version", fcm_version()) < 0 ||
      PyModule_AddStringConstant(m, "header_version", FCM_VERSION_STRING) < 0 ||
      PyModule_AddIntConstant(m, "DEFAULT", FCM_DEFAULT) < 0 || add_statuses(m) < 0 ||
      PyModule_AddFunctions(m, fcmpy_geometry_methods) < 0 ||
      PyModule_AddFunctions(m, fcmpy_rules_methods) < 0 ||
      PyModule_AddFunctions(m, fcmpy_simulation_methods) < 0 ||
      PyModule_AddFunctions(m, fcmpy_scene_methods) < 0) {
    Py_DECREF(m);
    return NULL;
  }
  return m;
}
