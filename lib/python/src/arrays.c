/* fcm's Python binding: checked array and vector inputs, copies out, options set by keyword,
 * captured view output, Python callables called by fcm. */
#define _POSIX_C_SOURCE 200809L /* open_memstream */
#include "fcmpy.h"

#include <stdlib.h>
#include <string.h>

PyObject *fcmpy_copy(const void *data, int typenum, int nd, const npy_intp *dims)
{
  PyObject *a = PyArray_SimpleNew(nd, (npy_intp *)dims, typenum);
  if (!a) return NULL;
  size_t bytes = (size_t)PyArray_NBYTES((PyArrayObject *)a);
  if (bytes > 0 && data) memcpy(PyArray_DATA((PyArrayObject *)a), data, bytes);
  return a;
}

PyArrayObject *fcmpy_input(PyObject *obj, int typenum, int nd, npy_intp cols, const char *what)
{
  PyArray_Descr *want = PyArray_DescrFromType(typenum);
  if (!want) return NULL;
  PyArrayObject *src = (PyArrayObject *)PyArray_FROMANY(obj, NPY_NOTYPE, 0, 0, 0);
  if (!src) {
    Py_DECREF(want);
    return NULL;
  }
  if (!PyArray_CanCastArrayTo(src, want, NPY_SAFE_CASTING)) {
    PyErr_Format(PyExc_TypeError, "%s: dtype %S cannot be converted to %S without loss", what,
                 (PyObject *)PyArray_DESCR(src), (PyObject *)want);
    Py_DECREF(want);
    Py_DECREF(src);
    return NULL;
  }
  PyArrayObject *a = (PyArrayObject *)PyArray_FromArray(src, want, NPY_ARRAY_IN_ARRAY);
  Py_DECREF(src);
  if (!a) return NULL;
  int ok = PyArray_NDIM(a) == nd && (nd < 2 || cols < 0 || PyArray_DIM(a, 1) == cols);
  if (!ok) {
    PyObject *shape = PyObject_GetAttrString((PyObject *)a, "shape");
    if (nd == 2 && cols >= 0)
      PyErr_Format(PyExc_ValueError, "%s: expected shape (n, %zd), got %S", what, (Py_ssize_t)cols,
                   shape ? shape : Py_None);
    else
      PyErr_Format(PyExc_ValueError, "%s: expected a %d-D array, got shape %S", what, nd,
                   shape ? shape : Py_None);
    Py_XDECREF(shape);
    Py_DECREF(a);
    return NULL;
  }
  return a;
}

int fcmpy_vec(PyObject *obj, double *out, int n, const char *what)
{
  PyArrayObject *a = fcmpy_input(obj, NPY_DOUBLE, 1, -1, what);
  if (!a) return -1;
  if (PyArray_DIM(a, 0) != n) {
    PyErr_Format(PyExc_ValueError, "%s: expected %d numbers, got %zd", what, n,
                 (Py_ssize_t)PyArray_DIM(a, 0));
    Py_DECREF(a);
    return -1;
  }
  memcpy(out, PyArray_DATA(a), (size_t)n * sizeof *out);
  Py_DECREF(a);
  return 0;
}

int fcmpy_index3(PyObject *obj, fcm_index out[3], const char *what)
{
  PyArrayObject *a = fcmpy_input(obj, NPY_INT64, 1, -1, what);
  if (!a) return -1;
  if (PyArray_DIM(a, 0) != 3) {
    PyErr_Format(PyExc_ValueError, "%s: expected 3 integers, got %zd", what,
                 (Py_ssize_t)PyArray_DIM(a, 0));
    Py_DECREF(a);
    return -1;
  }
  memcpy(out, PyArray_DATA(a), 3 * sizeof *out);
  Py_DECREF(a);
  return 0;
}

/* One entry of an option from a Python number. */
static int set_one(char type, char *p, PyObject *v, const char *name)
{
  if (type == 'd') {
    double x = PyFloat_AsDouble(v);
    if (x == -1.0 && PyErr_Occurred()) goto bad;
    memcpy(p, &x, sizeof x);
    return 0;
  }
  if (PyFloat_Check(v)) goto bad;
  long long x = PyLong_AsLongLong(v);
  if (x == -1 && PyErr_Occurred()) goto bad;
  if (type == 'n') {
    fcm_index y = (fcm_index)x;
    memcpy(p, &y, sizeof y);
  } else if (type == 'u') {
    if (x < 0 || x > (long long)0xffffffffu) goto range;
    unsigned y = (unsigned)x;
    memcpy(p, &y, sizeof y);
  } else {
    if (x < -2147483647LL - 1 || x > 2147483647LL) goto range;
    int y = (int)x;
    memcpy(p, &y, sizeof y);
  }
  return 0;
range:
  PyErr_Format(PyExc_ValueError, "option %s = %lld is out of range", name, x);
  return -1;
bad:
  PyErr_Clear();
  PyErr_Format(PyExc_TypeError, "option %s: expected %s, got %.100s", name,
               type == 'd' ? "a number" : "an integer", Py_TYPE(v)->tp_name);
  return -1;
}

static size_t type_size(char type)
{
  return type == 'd' ? sizeof(double) : type == 'n' ? sizeof(fcm_index) : sizeof(int);
}

int fcmpy_set_options(const fcmpy_option *table, void *opts, PyObject *kwargs, const char *what)
{
  if (!kwargs || kwargs == Py_None) return 0;
  if (!PyDict_Check(kwargs)) {
    PyErr_Format(PyExc_TypeError, "%s: options must be a dict", what);
    return -1;
  }
  PyObject *key, *value;
  Py_ssize_t pos = 0;
  while (PyDict_Next(kwargs, &pos, &key, &value)) {
    const char *name = PyUnicode_Check(key) ? PyUnicode_AsUTF8(key) : NULL;
    if (!name) {
      PyErr_Format(PyExc_TypeError, "%s: option names must be strings", what);
      return -1;
    }
    const fcmpy_option *o = table;
    while (o->name && strcmp(o->name, name) != 0)
      o++;
    if (!o->name) {
      PyObject *names = PyList_New(0);
      for (const fcmpy_option *t = table; names && t->name; t++) {
        PyObject *s = PyUnicode_FromString(t->name);
        if (!s || PyList_Append(names, s) < 0) Py_CLEAR(names);
        Py_XDECREF(s);
      }
      PyErr_Format(PyExc_TypeError, "%s: unknown option '%s' (valid: %S)", what, name,
                   names ? names : Py_None);
      Py_XDECREF(names);
      return -1;
    }
    char *base = (char *)opts + o->offset;
    size_t sz = type_size(o->type);
    if (o->count > 1 && PySequence_Check(value)) {
      if (PySequence_Size(value) != o->count) {
        PyErr_Format(PyExc_ValueError, "%s: option %s takes %d values", what, name, o->count);
        return -1;
      }
      for (int i = 0; i < o->count; i++) {
        PyObject *item = PySequence_GetItem(value, i);
        int rc = item ? set_one(o->type, base + (size_t)i * sz, item, name) : -1;
        Py_XDECREF(item);
        if (rc < 0) return -1;
      }
    } else {
      for (int i = 0; i < o->count; i++)
        if (set_one(o->type, base + (size_t)i * sz, value, name) < 0) return -1;
    }
  }
  return 0;
}

static PyObject *get_one(char type, const char *p)
{
  if (type == 'd') {
    double x;
    memcpy(&x, p, sizeof x);
    return PyFloat_FromDouble(x);
  }
  if (type == 'n') {
    fcm_index x;
    memcpy(&x, p, sizeof x);
    return PyLong_FromLongLong((long long)x);
  }
  if (type == 'u') {
    unsigned x;
    memcpy(&x, p, sizeof x);
    return PyLong_FromUnsignedLong(x);
  }
  int x;
  memcpy(&x, p, sizeof x);
  return PyLong_FromLong(x);
}

PyObject *fcmpy_options_dict(const fcmpy_option *table, const void *opts)
{
  PyObject *d = PyDict_New();
  for (const fcmpy_option *o = table; d && o->name; o++) {
    const char *base = (const char *)opts + o->offset;
    PyObject *v;
    if (o->count > 1) {
      v = PyTuple_New(o->count);
      for (int i = 0; v && i < o->count; i++) {
        PyObject *x = get_one(o->type, base + (size_t)i * type_size(o->type));
        if (!x)
          Py_CLEAR(v);
        else
          PyTuple_SET_ITEM(v, i, x);
      }
    } else {
      v = get_one(o->type, base);
    }
    if (!v || PyDict_SetItemString(d, o->name, v) < 0) Py_CLEAR(d);
    Py_XDECREF(v);
  }
  return d;
}

FILE *fcmpy_stream_open(char **buf, size_t *len)
{
  *buf = NULL;
  *len = 0;
  FILE *f = open_memstream(buf, len);
  if (!f) PyErr_NoMemory();
  return f;
}

PyObject *fcmpy_stream_close(FILE *f, char **buf, size_t *len)
{
  fclose(f); /* sets *buf and *len */
  PyObject *s = PyUnicode_DecodeUTF8(*buf ? *buf : "", (Py_ssize_t)*len, "replace");
  free(*buf);
  *buf = NULL;
  return s;
}

/* ---------------------------------------------------------------- callbacks */

static void callback_free(PyObject *capsule)
{
  fcmpy_callback *cb = PyCapsule_GetPointer(capsule, "fcm.callback");
  if (!cb) return;
  Py_XDECREF(cb->fn);
  Py_XDECREF(cb->type);
  Py_XDECREF(cb->value);
  Py_XDECREF(cb->traceback);
  PyMem_Free(cb);
}

fcmpy_callback *fcmpy_callback_new(PyObject *fn, PyObject **capsule)
{
  if (!PyCallable_Check(fn)) {
    PyErr_Format(PyExc_TypeError, "expected a callable, got %.100s", Py_TYPE(fn)->tp_name);
    return NULL;
  }
  fcmpy_callback *cb = PyMem_Calloc(1, sizeof *cb);
  if (!cb) {
    PyErr_NoMemory();
    return NULL;
  }
  Py_INCREF(fn);
  cb->fn = fn;
  *capsule = PyCapsule_New(cb, "fcm.callback", callback_free);
  if (!*capsule) {
    Py_DECREF(fn);
    PyMem_Free(cb);
    return NULL;
  }
  return cb;
}

void fcmpy_callback_fail(fcmpy_callback *cb)
{
  if (cb->type) { /* keep the first exception */
    PyErr_Clear();
    return;
  }
  PyErr_Fetch(&cb->type, &cb->value, &cb->traceback);
  if (!cb->type) { /* failed without an exception: say so */
    PyErr_SetString(PyExc_RuntimeError, "an fcm callback failed without an exception");
    PyErr_Fetch(&cb->type, &cb->value, &cb->traceback);
  }
}

int fcmpy_callback_restore(fcmpy_callback *cb)
{
  if (!cb || !cb->type) return 0;
  PyErr_Restore(cb->type, cb->value, cb->traceback);
  cb->type = cb->value = cb->traceback = NULL;
  return 1;
}

int fcmpy_callbacks_restore(PyObject *keep)
{
  int found = 0;
  for (Py_ssize_t i = 0; keep && i < PyList_GET_SIZE(keep); i++) {
    PyObject *o = PyList_GET_ITEM(keep, i);
    if (!PyCapsule_CheckExact(o)) continue;
    fcmpy_callback *cb = PyCapsule_GetPointer(o, "fcm.callback");
    if (!found)
      found = fcmpy_callback_restore(cb);
    else if (cb && cb->type) { /* only the first is raised */
      Py_CLEAR(cb->type);
      Py_CLEAR(cb->value);
      Py_CLEAR(cb->traceback);
    }
  }
  return found;
}

int fcmpy_material(PyObject *obj, fcm_material *mat)
{
  PyObject *t = PySequence_Check(obj) ? PySequence_Tuple(obj) : NULL;
  int model = 0;
  if (!t || !PyArg_ParseTuple(t, "iddd;material: expected (model, young, poisson, density)", &model,
                              &mat->young, &mat->poisson, &mat->density)) {
    if (!t && !PyErr_Occurred())
      PyErr_SetString(PyExc_TypeError, "material: expected (model, young, poisson, density)");
    Py_XDECREF(t);
    return -1;
  }
  Py_DECREF(t);
  mat->model = (fcm_material_model)model; /* the library validates the range */
  return 0;
}
