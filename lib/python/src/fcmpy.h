/* fcm's Python binding (the extension module fcm._fcm): what its source files share — the
 * handle every fcm object lives in, NumPy views and inputs, errors, options and callbacks. */
#ifndef FCMPY_H
#define FCMPY_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define PY_ARRAY_UNIQUE_SYMBOL fcmpy_ARRAY_API
#ifndef FCMPY_IMPORT_ARRAY
#define NO_IMPORT_ARRAY
#endif
#include <numpy/arrayobject.h>

#include <fcm/fcm.h>

#include <stddef.h>
#include <stdio.h>

/** What an fcm handle holds. */
typedef enum fcmpy_kind {
  FCMPY_CTX = 0,
  FCMPY_MESH,
  FCMPY_GEOMETRY,
  FCMPY_SURFACE,
  FCMPY_VOXELS,
  FCMPY_RULES,
  FCMPY_SPACE,
  FCMPY_INTEGRATOR,
  FCMPY_EMBEDDED_SURFACE,
  FCMPY_SCENE,
  FCMPY_SIMULATION,
  FCMPY_KIND_COUNT
} fcmpy_kind;

/** One fcm object. It is destroyed once it is closed (close() or the handle's end) and no
 * handle made from it (users) and no NumPy view into its memory (views) is left: a view or
 * a dependent object keeps what it reads alive, and a closed handle refuses every call. */
typedef struct fcmpy_handle {
  PyObject_HEAD fcmpy_kind kind;
  void *ptr;        /**< the fcm object; NULL once destroyed */
  fcm_ctx *ctx;     /**< the context its errors are recorded in */
  int closed;       /**< 1 after close(): no further use */
  Py_ssize_t users; /**< live handles made from this one */
  Py_ssize_t views; /**< live NumPy views into its memory */
  PyObject *keep;   /**< list: the handles it was made from and the callables it calls */
} fcmpy_handle;

/** A Python callable called by the library, with the first exception it raised. */
typedef struct fcmpy_callback {
  PyObject *fn;
  PyObject *type, *value, *traceback; /**< the pending exception (NULL: none) */
} fcmpy_callback;

/** A member of an options struct set by keyword: 'i' int (enums too), 'u' unsigned, 'd'
 * double, 'n' fcm_index; count > 1: an array (a scalar sets every entry). */
typedef struct fcmpy_option {
  const char *name;
  char type;
  int count;
  size_t offset;
} fcmpy_option;

extern PyTypeObject fcmpy_handle_type;
extern PyObject *fcmpy_error_type;

/* module.c */
PyObject *fcmpy_view(PyObject *owner, const void *data, int typenum, int nd, const npy_intp *dims);
PyObject *fcmpy_handle_new(fcmpy_kind kind, void *ptr, fcm_ctx *ctx, PyObject *const *deps,
                           int num_deps);
fcmpy_handle *fcmpy_handle_of(PyObject *obj, fcmpy_kind kind);
void *fcmpy_get(PyObject *obj, fcmpy_kind kind);
int fcmpy_keep(PyObject *handle, PyObject *obj);
void fcmpy_handle_release_user(fcmpy_handle *h);
/* Keep an object alive across a call that runs Python code (a callback, or another thread
 * while the GIL is released), even if that code closes it. */
void fcmpy_pin(fcmpy_handle *h);
void fcmpy_unpin(fcmpy_handle *h);
PyObject *fcmpy_raise(fcm_ctx *ctx, fcm_status st);
PyObject *fcmpy_made(fcm_status st, fcmpy_handle *parent, fcmpy_kind kind, void *ptr,
                     PyObject *dep1, PyObject *dep2);

/* arrays.c */
PyObject *fcmpy_copy(const void *data, int typenum, int nd, const npy_intp *dims);
PyArrayObject *fcmpy_input(PyObject *obj, int typenum, int nd, npy_intp cols, const char *what);
int fcmpy_vec(PyObject *obj, double *out, int n, const char *what);
int fcmpy_index3(PyObject *obj, fcm_index out[3], const char *what);
int fcmpy_set_options(const fcmpy_option *table, void *opts, PyObject *kwargs, const char *what);
PyObject *fcmpy_options_dict(const fcmpy_option *table, const void *opts);
FILE *fcmpy_stream_open(char **buf, size_t *len);
PyObject *fcmpy_stream_close(FILE *f, char **buf, size_t *len);
fcmpy_callback *fcmpy_callback_new(PyObject *fn, PyObject **capsule);
void fcmpy_callback_fail(fcmpy_callback *cb);
int fcmpy_callback_restore(fcmpy_callback *cb);
int fcmpy_callbacks_restore(PyObject *keep);
int fcmpy_material(PyObject *obj, fcm_material *mat);

/* The functions of each part, added to the module. */
extern PyMethodDef fcmpy_geometry_methods[];
extern PyMethodDef fcmpy_rules_methods[];
extern PyMethodDef fcmpy_simulation_methods[];
extern PyMethodDef fcmpy_scene_methods[];

/* The members of fcm_step_info, for the step reports of integrators and simulations. */
extern const fcmpy_option fcmpy_step_table[];

#endif /* FCMPY_H */
