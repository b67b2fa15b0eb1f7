/* fcm's Python binding: background meshes, embedded geometries (procedural, files, level
 * sets with a Python phi, voxel images, triangle surfaces) and triangle surfaces. */
#include "fcmpy.h"

#include <math.h>

/* A new handle for an object made in `ctx` (ctx_h its handle) from the handles `deps`, or
 * the error of the call that made it. */
static PyObject *made(fcm_status st, fcm_ctx *ctx, fcmpy_kind kind, void *ptr, PyObject *ctx_h,
                      PyObject *dep)
{
  if (st != FCM_OK) return fcmpy_raise(ctx, st);
  PyObject *deps[2] = {ctx_h, dep};
  return fcmpy_handle_new(kind, ptr, ctx, deps, dep ? 2 : 1);
}

static PyObject *ctx_handle(PyObject *obj, fcm_ctx **ctx)
{
  fcmpy_handle *h = fcmpy_handle_of(obj, FCMPY_CTX);
  if (!h) return NULL;
  *ctx = h->ptr;
  return (PyObject *)h;
}

static int element_type(int type, fcm_element_type *out)
{
  if (type < 0 || type > FCM_ELEMENT_HEX20) {
    PyErr_Format(PyExc_ValueError, "element type %d out of range [0, %d]", type,
                 (int)FCM_ELEMENT_HEX20);
    return -1;
  }
  *out = (fcm_element_type)type;
  return 0;
}

/* Nodes (n x 3 doubles) and cells (m x npc indices) of a mesh or geometry. */
static int nodes_cells(PyObject *coords, PyObject *cells, fcm_element_type type, PyArrayObject **x,
                       PyArrayObject **c)
{
  const int npc = fcm_element_get_info(type)->num_nodes;
  *x = fcmpy_input(coords, NPY_DOUBLE, 2, 3, "coords");
  *c = *x ? fcmpy_input(cells, NPY_INT64, 2, npc, "cells") : NULL;
  if (!*c) {
    Py_XDECREF(*x);
    return -1;
  }
  return 0;
}

/* ---------------------------------------------------------------- meshes */

/* A mesh, or (geometry true) a geometry, from caller arrays. */
static PyObject *mesh_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *coords, *cells;
  int type, geometry;
  fcm_ctx *ctx;
  fcm_element_type et;
  PyArrayObject *x, *c;
  if (!PyArg_ParseTuple(args, "OiOOp", &ch, &type, &coords, &cells, &geometry) ||
      !ctx_handle(ch, &ctx) || element_type(type, &et) < 0 ||
      nodes_cells(coords, cells, et, &x, &c) < 0)
    return NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_status st = geometry ? fcm_geometry_create(ctx, et, PyArray_DIM(x, 0), PyArray_DATA(x),
                                                 PyArray_DIM(c, 0), PyArray_DATA(c), &g)
                           : fcm_mesh_create(ctx, et, PyArray_DIM(x, 0), PyArray_DATA(x),
                                             PyArray_DIM(c, 0), PyArray_DATA(c), &mesh);
  Py_DECREF(x);
  Py_DECREF(c);
  if (geometry) return made(st, ctx, FCMPY_GEOMETRY, g, ch, NULL);
  return made(st, ctx, FCMPY_MESH, mesh, ch, NULL);
}

static PyObject *mesh_box(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *lo_o, *hi_o, *n_o;
  int type;
  fcm_ctx *ctx;
  fcm_element_type et;
  double lo[3], hi[3];
  fcm_index n[3];
  if (!PyArg_ParseTuple(args, "OiOOO", &ch, &type, &lo_o, &hi_o, &n_o) || !ctx_handle(ch, &ctx) ||
      element_type(type, &et) < 0 || fcmpy_vec(lo_o, lo, 3, "lo") < 0 ||
      fcmpy_vec(hi_o, hi, 3, "hi") < 0 || fcmpy_index3(n_o, n, "n") < 0)
    return NULL;
  fcm_mesh *mesh = NULL;
  fcm_status st = fcm_mesh_create_box(ctx, et, lo, hi, n, &mesh);
  return made(st, ctx, FCMPY_MESH, mesh, ch, NULL);
}

static PyObject *mesh_octree(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *lo_o, *hi_o, *n_o, *rlo_o, *rhi_o, *geom_o;
  int type, region_level, refine_level;
  fcm_ctx *ctx;
  fcm_element_type et;
  double lo[3], hi[3];
  fcm_index n[3];
  fcm_octree_options o = fcm_octree_options_default();
  if (!PyArg_ParseTuple(args, "OiOOOiOOiO", &ch, &type, &lo_o, &hi_o, &n_o, &region_level, &rlo_o,
                        &rhi_o, &refine_level, &geom_o) ||
      !ctx_handle(ch, &ctx) || element_type(type, &et) < 0 || fcmpy_vec(lo_o, lo, 3, "lo") < 0 ||
      fcmpy_vec(hi_o, hi, 3, "hi") < 0 || fcmpy_index3(n_o, n, "n") < 0)
    return NULL;
  o.region_level = region_level;
  if (region_level > 0 && (fcmpy_vec(rlo_o, o.region_lo, 3, "region_lo") < 0 ||
                           fcmpy_vec(rhi_o, o.region_hi, 3, "region_hi") < 0))
    return NULL;
  if (geom_o != Py_None) { /* refine along the boundary of an embedded geometry */
    o.refine_user = fcmpy_get(geom_o, FCMPY_GEOMETRY);
    if (!o.refine_user) return NULL;
    o.refine = fcm_geometry_boundary_meets_box;
    o.refine_level = refine_level;
  }
  fcm_mesh *mesh = NULL;
  fcm_status st = fcm_mesh_create_octree(ctx, et, lo, hi, n, &o, &mesh);
  return made(st, ctx, FCMPY_MESH, mesh, ch, NULL);
}

static PyObject *mesh_refined(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *mh, *flags_o;
  if (!PyArg_ParseTuple(args, "OO", &mh, &flags_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(mh, FCMPY_MESH);
  if (!h) return NULL;
  PyArrayObject *f = fcmpy_input(flags_o, NPY_UINT8, 1, -1, "flags");
  if (!f) return NULL;
  if (PyArray_DIM(f, 0) != fcm_mesh_num_cells(h->ptr)) {
    Py_DECREF(f);
    return PyErr_Format(PyExc_ValueError, "flags: expected %lld entries (one per cell), got %zd",
                        (long long)fcm_mesh_num_cells(h->ptr), (Py_ssize_t)PyArray_DIM(f, 0));
  }
  fcm_mesh *out = NULL;
  fcm_status st = fcm_mesh_create_refined(h->ctx, h->ptr, PyArray_DATA(f), &out);
  Py_DECREF(f);
  PyObject *ctx_h = PyList_GET_ITEM(h->keep, 0);
  return made(st, h->ctx, FCMPY_MESH, out, ctx_h, NULL);
}

/* Objects read from files: ("mesh" | "geometry" | "surface" | "voxels", path) or
 * ("tetgen", node_path, ele_path). */
static PyObject *read_file(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch;
  const char *what, *path, *ele = NULL;
  fcm_ctx *ctx;
  if (!PyArg_ParseTuple(args, "Oss|s", &ch, &what, &path, &ele) || !ctx_handle(ch, &ctx))
    return NULL;
  void *obj = NULL;
  fcmpy_kind kind = FCMPY_GEOMETRY;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_surface *surf = NULL;
  fcm_voxel_image *img = NULL;
  fcm_status st;
  if (!strcmp(what, "mesh")) {
    kind = FCMPY_MESH;
    st = fcm_mesh_create_from_gmsh(ctx, path, &mesh);
    obj = mesh;
  } else if (!strcmp(what, "geometry") || (!strcmp(what, "tetgen") && ele)) {
    st = ele ? fcm_geometry_create_from_tetgen(ctx, path, ele, &geom)
             : fcm_geometry_create_from_gmsh(ctx, path, &geom);
    obj = geom;
  } else if (!strcmp(what, "surface")) {
    kind = FCMPY_SURFACE;
    st = fcm_surface_create_from_file(ctx, path, &surf);
    obj = surf;
  } else if (!strcmp(what, "voxels")) {
    kind = FCMPY_VOXELS;
    st = fcm_voxel_image_create_from_file(ctx, path, &img);
    obj = img;
  } else {
    return PyErr_Format(PyExc_ValueError, "read_file: cannot read a '%s'", what);
  }
  return made(st, ctx, kind, obj, ch, NULL);
}

static PyObject *mesh_info(PyObject *self, PyObject *mh)
{
  (void)self;
  const fcm_mesh *m = fcmpy_get(mh, FCMPY_MESH);
  if (!m) return NULL;
  double lo[3], hi[3];
  fcm_mesh_bounding_box(m, lo, hi);
  return Py_BuildValue("{s:i,s:i,s:L,s:L,s:i,s:i,s:L,s:(ddd),s:(ddd)}", "element_type",
                       (int)fcm_mesh_element_type(m), "nodes_per_cell", fcm_mesh_nodes_per_cell(m),
                       "num_nodes", (long long)fcm_mesh_num_nodes(m), "num_cells",
                       (long long)fcm_mesh_num_cells(m), "is_octree", fcm_mesh_is_octree(m),
                       "max_level", fcm_mesh_max_level(m), "num_boundary_faces",
                       (long long)fcm_mesh_num_boundary_faces(m), "lo", lo[0], lo[1], lo[2], "hi",
                       hi[0], hi[1], hi[2]);
}

/* Read-only views of a mesh's arrays: "coords", "cells", "neighbors", "boundary_faces",
 * "levels" (a copy). */
static PyObject *mesh_array(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *mh;
  const char *which;
  if (!PyArg_ParseTuple(args, "Os", &mh, &which)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(mh, FCMPY_MESH);
  if (!h) return NULL;
  const fcm_mesh *m = h->ptr;
  const fcm_index nc = fcm_mesh_num_cells(m);
  npy_intp dims[2] = {fcm_mesh_num_nodes(m), 3};
  if (!strcmp(which, "coords")) return fcmpy_view(mh, fcm_mesh_coords(m), NPY_DOUBLE, 2, dims);
  dims[0] = nc;
  dims[1] = fcm_mesh_nodes_per_cell(m);
  if (!strcmp(which, "cells")) return fcmpy_view(mh, fcm_mesh_cells(m), NPY_INT64, 2, dims);
  dims[1] = fcm_mesh_get_element_info(m)->num_faces;
  if (!strcmp(which, "neighbors")) return fcmpy_view(mh, fcm_mesh_neighbors(m), NPY_INT64, 2, dims);
  dims[0] = fcm_mesh_num_boundary_faces(m);
  dims[1] = 2;
  if (!strcmp(which, "boundary_faces"))
    return fcmpy_view(mh, fcm_mesh_boundary_faces(m), NPY_INT64, 2, dims);
  if (!strcmp(which, "levels")) {
    dims[0] = nc;
    PyObject *a = PyArray_SimpleNew(1, dims, NPY_INT32);
    if (!a) return NULL;
    int32_t *lv = PyArray_DATA((PyArrayObject *)a);
    for (fcm_index c = 0; c < nc; c++)
      lv[c] = fcm_mesh_cell_level(m, c);
    return a;
  }
  return PyErr_Format(PyExc_ValueError, "unknown mesh array '%s'", which);
}

static PyObject *mesh_nodes_in_box(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *mh, *lo_o, *hi_o;
  double lo[3], hi[3], tol;
  if (!PyArg_ParseTuple(args, "OOOd", &mh, &lo_o, &hi_o, &tol)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(mh, FCMPY_MESH);
  if (!h || fcmpy_vec(lo_o, lo, 3, "lo") < 0 || fcmpy_vec(hi_o, hi, 3, "hi") < 0) return NULL;
  fcm_index count = 0;
  fcm_status st = fcm_mesh_nodes_in_box(h->ctx, h->ptr, lo, hi, tol, 0, NULL, &count);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  npy_intp dims[1] = {count};
  PyObject *a = PyArray_SimpleNew(1, dims, NPY_INT64);
  if (!a) return NULL;
  st = fcm_mesh_nodes_in_box(h->ctx, h->ptr, lo, hi, tol, count, PyArray_DATA((PyArrayObject *)a),
                             &count);
  if (st != FCM_OK) {
    Py_DECREF(a);
    return fcmpy_raise(h->ctx, st);
  }
  return a;
}

/* ---------------------------------------------------------------- geometries */

/* Procedural shapes: ("box", lo, hi, n), ("ball" | "hemisphere", center, radius, n),
 * ("hollow_ball", center, r_in, r_out, hole_radius, n, layers),
 * ("tube", center, axis, r_in, r_out, length, n_r, n_theta, n_axial). */
static PyObject *geometry_shape(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *a_o, *b_o = NULL, *n_o = NULL;
  const char *shape;
  double c[3], lo[3], hi[3], r = 0, r2 = 0, r3 = 0, len = 0;
  int n = 0, n2 = 0, n3 = 0, axis = 0;
  fcm_index nn[3];
  fcm_ctx *ctx;
  fcm_geometry *g = NULL;
  fcm_status st;
  if (PyTuple_GET_SIZE(args) < 3 || !PyUnicode_Check(PyTuple_GET_ITEM(args, 1)))
    return PyErr_Format(PyExc_TypeError, "geometry_shape(ctx, shape, ...)");
  ch = PyTuple_GET_ITEM(args, 0);
  shape = PyUnicode_AsUTF8(PyTuple_GET_ITEM(args, 1));
  if (!shape) return NULL;
  if (!ctx_handle(ch, &ctx)) return NULL;
  if (!strcmp(shape, "box")) {
    if (!PyArg_ParseTuple(args, "OsOOO", &ch, &shape, &a_o, &b_o, &n_o) ||
        fcmpy_vec(a_o, lo, 3, "lo") < 0 || fcmpy_vec(b_o, hi, 3, "hi") < 0 ||
        fcmpy_index3(n_o, nn, "n") < 0)
      return NULL;
    st = fcm_geometry_create_box(ctx, lo, hi, nn, &g);
  } else if (!strcmp(shape, "ball") || !strcmp(shape, "hemisphere")) {
    if (!PyArg_ParseTuple(args, "OsOdi", &ch, &shape, &a_o, &r, &n) ||
        fcmpy_vec(a_o, c, 3, "center") < 0)
      return NULL;
    st = shape[0] == 'b' ? fcm_geometry_create_ball(ctx, c, r, n, &g)
                         : fcm_geometry_create_hemisphere(ctx, c, r, n, &g);
  } else if (!strcmp(shape, "hollow_ball")) {
    if (!PyArg_ParseTuple(args, "OsOdddii", &ch, &shape, &a_o, &r, &r2, &r3, &n, &n2) ||
        fcmpy_vec(a_o, c, 3, "center") < 0)
      return NULL;
    st = fcm_geometry_create_hollow_ball(ctx, c, r, r2, r3, n, n2, &g);
  } else if (!strcmp(shape, "tube")) {
    if (!PyArg_ParseTuple(args, "OsOidddiii", &ch, &shape, &a_o, &axis, &r, &r2, &len, &n, &n2,
                          &n3) ||
        fcmpy_vec(a_o, c, 3, "center") < 0)
      return NULL;
    st = fcm_geometry_create_tube(ctx, c, axis, r, r2, len, n, n2, n3, &g);
  } else {
    return PyErr_Format(PyExc_ValueError, "unknown shape '%s'", shape);
  }
  return made(st, ctx, FCMPY_GEOMETRY, g, ch, NULL);
}

static PyObject *geometry_transformed(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *gh, *A_o, *b_o;
  double A[9], b[3];
  if (!PyArg_ParseTuple(args, "OOO", &gh, &A_o, &b_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(gh, FCMPY_GEOMETRY);
  PyArrayObject *a = h ? fcmpy_input(A_o, NPY_DOUBLE, 2, 3, "A") : NULL;
  if (!a) return NULL;
  int ok = PyArray_DIM(a, 0) == 3;
  if (ok) memcpy(A, PyArray_DATA(a), sizeof A);
  Py_DECREF(a);
  if (!ok) return PyErr_Format(PyExc_ValueError, "A: expected shape (3, 3)");
  if (fcmpy_vec(b_o, b, 3, "b") < 0) return NULL;
  fcm_geometry *g = NULL;
  fcm_status st = fcm_geometry_create_transformed(h->ctx, h->ptr, A, b, &g);
  return made(st, h->ctx, FCMPY_GEOMETRY, g, PyList_GET_ITEM(h->keep, 0), NULL);
}

/* phi of a level set: the Python callable, called with a float64 array of shape (3,). The
 * first exception is kept and every later call returns NaN at once, which fails the build
 * (phi not finite); the exception is then raised in place of the library's error. */
static double level_set_phi(const double x[3], void *user)
{
  fcmpy_callback *cb = user;
  if (cb->type) return NAN;
  npy_intp dims[1] = {3};
  PyObject *p = fcmpy_copy(x, NPY_DOUBLE, 1, dims);
  PyObject *r = p ? PyObject_CallOneArg(cb->fn, p) : NULL;
  Py_XDECREF(p);
  double v = r ? PyFloat_AsDouble(r) : NAN;
  Py_XDECREF(r);
  if (PyErr_Occurred()) {
    fcmpy_callback_fail(cb);
    return NAN;
  }
  return v;
}

static const fcmpy_option level_set_table[] = {
    {"refinement", 'i', 1, offsetof(fcm_level_set_options, refinement)},
    {"estimate_error", 'i', 1, offsetof(fcm_level_set_options, estimate_error)},
    {"refine_inside", 'i', 1, offsetof(fcm_level_set_options, refine_inside)},
    {"max_subcells", 'n', 1, offsetof(fcm_level_set_options, max_subcells)},
    {NULL, 0, 0, 0}};

static PyObject *geometry_from_level_set(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *fn, *lo_o, *hi_o, *n_o, *opts_o, *capsule = NULL, *pinned;
  double lo[3], hi[3];
  fcm_index n[3];
  fcm_ctx *ctx;
  fcm_level_set_options o = fcm_level_set_options_default();
  if (!PyArg_ParseTuple(args, "OOOOOO", &ch, &fn, &lo_o, &hi_o, &n_o, &opts_o) ||
      !(pinned = ctx_handle(ch, &ctx)) || fcmpy_vec(lo_o, lo, 3, "lo") < 0 ||
      fcmpy_vec(hi_o, hi, 3, "hi") < 0 || fcmpy_index3(n_o, n, "n") < 0 ||
      fcmpy_set_options(level_set_table, &o, opts_o, "Geometry.from_level_set") < 0)
    return NULL;
  fcmpy_callback *cb = fcmpy_callback_new(fn, &capsule);
  if (!cb) return NULL;
  fcm_geometry *g = NULL;
  fcm_level_set_info info;
  PyObject *h = NULL;
  fcmpy_pin((fcmpy_handle *)pinned); /* phi may close the context */
  fcm_status st =
      fcm_geometry_create_from_level_set(ctx, level_set_phi, cb, lo, hi, n, &o, &g, &info);
  if (fcmpy_callback_restore(cb)) {
    fcm_geometry_destroy(&g);
    fcm_ctx_error_clear(ctx);
  } else {
    h = made(st, ctx, FCMPY_GEOMETRY, g, pinned, NULL);
  }
  Py_DECREF(capsule);
  fcmpy_unpin((fcmpy_handle *)pinned);
  if (!h) return NULL;
  return Py_BuildValue("N{s:L,s:L,s:L,s:L,s:L,s:d,s:d,s:d,s:d}", h, "cells_inside",
                       (long long)info.cells_inside, "cells_cut", (long long)info.cells_cut,
                       "cells_outside", (long long)info.cells_outside, "num_tets",
                       (long long)info.num_tets, "subcells", (long long)info.subcells, "h", info.h,
                       "volume", info.volume, "volume_fine", info.volume_fine, "error_estimate",
                       info.error_estimate);
}

#define IM(member) offsetof(fcm_implicit, member)
static const fcmpy_option implicit_table[] = {{"kind", 'i', 1, IM(kind)},
                                              {"center", 'd', 3, IM(center)},
                                              {"radius", 'd', 1, IM(radius)},
                                              {"minor_radius", 'd', 1, IM(minor_radius)},
                                              {"axis", 'i', 1, IM(axis)},
                                              {"min", 'd', 3, IM(min)},
                                              {"max", 'd', 3, IM(max)},
                                              {"period", 'd', 1, IM(period)},
                                              {"thickness", 'd', 1, IM(thickness)},
                                              {"sheet", 'i', 1, IM(sheet)},
                                              {"a", 'i', 1, IM(a)},
                                              {"b", 'i', 1, IM(b)},
                                              {NULL, 0, 0, 0}};
#undef IM

/* A level set from a tree of built-in implicit functions (a list of dicts of fcm_implicit
 * members, the root last), evaluated by the library itself. */
static PyObject *geometry_from_implicit(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *nodes_o, *lo_o, *hi_o, *n_o, *opts_o;
  double lo[3], hi[3];
  fcm_index n[3];
  fcm_ctx *ctx;
  fcm_level_set_options o = fcm_level_set_options_default();
  fcm_implicit nodes[FCM_IMPLICIT_MAX_NODES];
  if (!PyArg_ParseTuple(args, "OO!OOOO", &ch, &PyList_Type, &nodes_o, &lo_o, &hi_o, &n_o,
                        &opts_o) ||
      !ctx_handle(ch, &ctx) || fcmpy_vec(lo_o, lo, 3, "lo") < 0 ||
      fcmpy_vec(hi_o, hi, 3, "hi") < 0 || fcmpy_index3(n_o, n, "n") < 0 ||
      fcmpy_set_options(level_set_table, &o, opts_o, "Geometry.from_implicit") < 0)
    return NULL;
  const Py_ssize_t count = PyList_GET_SIZE(nodes_o);
  if (count < 1 || count > FCM_IMPLICIT_MAX_NODES)
    return PyErr_Format(PyExc_ValueError, "implicit tree: %zd nodes, expected 1 to %d", count,
                        FCM_IMPLICIT_MAX_NODES);
  memset(nodes, 0, sizeof nodes);
  for (Py_ssize_t i = 0; i < count; i++)
    if (fcmpy_set_options(implicit_table, &nodes[i], PyList_GET_ITEM(nodes_o, i), "implicit node") <
        0)
      return NULL;
  const fcm_implicit_tree tree = {(int)count, nodes};
  fcm_status st = fcm_implicit_check(ctx, &tree);
  fcm_geometry *g = NULL;
  fcm_level_set_info info;
  if (st == FCM_OK)
    st = fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, (void *)&tree, lo, hi, n, &o,
                                            &g, &info);
  PyObject *h = made(st, ctx, FCMPY_GEOMETRY, g, ch, NULL);
  if (!h) return NULL;
  return Py_BuildValue("N{s:L,s:L,s:L,s:L,s:d,s:d}", h, "cells_cut", (long long)info.cells_cut,
                       "num_tets", (long long)info.num_tets, "subcells", (long long)info.subcells,
                       "cells_inside", (long long)info.cells_inside, "volume", info.volume,
                       "error_estimate", info.error_estimate);
}

static const fcmpy_option surface_mesh_table[] = {
    {"max_volume", 'd', 1, offsetof(fcm_surface_mesh_options, max_volume)},
    {"size", 'd', 1, offsetof(fcm_surface_mesh_options, size)},
    {"quality", 'd', 1, offsetof(fcm_surface_mesh_options, quality)},
    {"check_intersections", 'i', 1, offsetof(fcm_surface_mesh_options, check_intersections)},
    {"orient", 'i', 1, offsetof(fcm_surface_mesh_options, orient)},
    {"volume_mesh", 'i', 1, offsetof(fcm_surface_mesh_options, volume_mesh)},
    {NULL, 0, 0, 0}};

static PyObject *geometry_from_surface(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *sh, *opts_o;
  fcm_surface_mesh_options o = fcm_surface_mesh_options_default();
  if (!PyArg_ParseTuple(args, "OO", &sh, &opts_o)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(sh, FCMPY_SURFACE);
  if (!h || fcmpy_set_options(surface_mesh_table, &o, opts_o, "Geometry.from_surface") < 0)
    return NULL;
  fcm_geometry *g = NULL;
  fcm_status st = fcm_geometry_create_from_surface(h->ctx, h->ptr, &o, &g);
  return made(st, h->ctx, FCMPY_GEOMETRY, g, PyList_GET_ITEM(h->keep, 0), NULL);
}

static PyObject *voxels_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *values_o, *axes_o, *origin_o;
  double axes[9], origin[3];
  fcm_ctx *ctx;
  if (!PyArg_ParseTuple(args, "OOOO", &ch, &values_o, &axes_o, &origin_o) ||
      !ctx_handle(ch, &ctx) || fcmpy_vec(axes_o, axes, 9, "axes") < 0 ||
      fcmpy_vec(origin_o, origin, 3, "origin") < 0)
    return NULL;
  PyArrayObject *v = fcmpy_input(values_o, NPY_DOUBLE, 3, -1, "values");
  if (!v) return NULL;
  /* values[k, j, i]: i fastest, as the library stores them */
  const fcm_index dims[3] = {PyArray_DIM(v, 2), PyArray_DIM(v, 1), PyArray_DIM(v, 0)};
  fcm_voxel_image *img = NULL;
  fcm_status st = fcm_voxel_image_create(ctx, dims, axes, origin, PyArray_DATA(v), &img);
  Py_DECREF(v);
  return made(st, ctx, FCMPY_VOXELS, img, ch, NULL);
}

static PyObject *voxels_values(PyObject *self, PyObject *vh)
{
  (void)self;
  const fcm_voxel_image *img = fcmpy_get(vh, FCMPY_VOXELS);
  if (!img) return NULL;
  fcm_index d[3];
  fcm_voxel_image_dims(img, d);
  npy_intp dims[3] = {d[2], d[1], d[0]};
  return fcmpy_view(vh, fcm_voxel_image_values(img), NPY_DOUBLE, 3, dims);
}

static PyObject *geometry_from_voxels(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *vh, *labels_o;
  double threshold;
  int merge;
  if (!PyArg_ParseTuple(args, "OdOi", &vh, &threshold, &labels_o, &merge)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(vh, FCMPY_VOXELS);
  if (!h) return NULL;
  fcm_voxel_options o = fcm_voxel_options_default();
  o.threshold = threshold;
  o.merge = merge;
  PyArrayObject *labels = NULL;
  if (labels_o != Py_None) {
    labels = fcmpy_input(labels_o, NPY_DOUBLE, 1, -1, "labels");
    if (!labels) return NULL;
    o.labels = PyArray_DATA(labels);
    o.num_labels = (int)PyArray_DIM(labels, 0);
  }
  fcm_geometry *g = NULL;
  fcm_voxel_info info;
  fcm_status st = fcm_geometry_create_from_voxels(h->ctx, h->ptr, &o, &g, &info);
  Py_XDECREF(labels);
  PyObject *gh = made(st, h->ctx, FCMPY_GEOMETRY, g, PyList_GET_ITEM(h->keep, 0), NULL);
  if (!gh) return NULL;
  return Py_BuildValue("N{s:L,s:L,s:L,s:L,s:d}", gh, "num_voxels", (long long)info.num_voxels,
                       "num_selected", (long long)info.num_selected, "num_nan",
                       (long long)info.num_nan, "num_boxes", (long long)info.num_boxes,
                       "voxel_volume", info.voxel_volume);
}

static PyObject *geometry_info(PyObject *self, PyObject *gh)
{
  (void)self;
  const fcm_geometry *g = fcmpy_get(gh, FCMPY_GEOMETRY);
  if (!g) return NULL;
  double lo[3], hi[3];
  fcm_geometry_bounding_box(g, lo, hi);
  return Py_BuildValue(
      "{s:i,s:L,s:L,s:L,s:d,s:(ddd),s:(ddd)}", "element_type", (int)fcm_geometry_cell_type(g),
      "num_nodes", (long long)fcm_geometry_num_nodes(g), "num_cells",
      (long long)fcm_geometry_num_cells(g), "num_boundary_triangles",
      (long long)fcm_geometry_num_boundary_triangles(g), "volume", fcm_geometry_volume(g), "lo",
      lo[0], lo[1], lo[2], "hi", hi[0], hi[1], hi[2]);
}

/* Views: "coords", "cells", "boundary_triangles", "boundary_cells". */
static PyObject *geometry_array(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *gh;
  const char *which;
  if (!PyArg_ParseTuple(args, "Os", &gh, &which)) return NULL;
  const fcm_geometry *g = fcmpy_get(gh, FCMPY_GEOMETRY);
  if (!g) return NULL;
  npy_intp dims[2] = {fcm_geometry_num_nodes(g), 3};
  if (!strcmp(which, "coords")) return fcmpy_view(gh, fcm_geometry_coords(g), NPY_DOUBLE, 2, dims);
  dims[0] = fcm_geometry_num_cells(g);
  dims[1] = fcm_geometry_nodes_per_cell(g);
  if (!strcmp(which, "cells")) return fcmpy_view(gh, fcm_geometry_cells(g), NPY_INT64, 2, dims);
  dims[0] = fcm_geometry_num_boundary_triangles(g);
  dims[1] = 3;
  if (!strcmp(which, "boundary_triangles"))
    return fcmpy_view(gh, fcm_geometry_boundary_triangles(g), NPY_INT64, 2, dims);
  if (!strcmp(which, "boundary_cells"))
    return fcmpy_view(gh, fcm_geometry_boundary_cells(g), NPY_INT64, 1, dims);
  return PyErr_Format(PyExc_ValueError, "unknown geometry array '%s'", which);
}

/* ---------------------------------------------------------------- triangle surfaces */

static PyObject *surface_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *coords, *tris;
  fcm_ctx *ctx;
  if (!PyArg_ParseTuple(args, "OOO", &ch, &coords, &tris) || !ctx_handle(ch, &ctx)) return NULL;
  PyArrayObject *x = fcmpy_input(coords, NPY_DOUBLE, 2, 3, "coords");
  PyArrayObject *t = x ? fcmpy_input(tris, NPY_INT64, 2, 3, "triangles") : NULL;
  if (!t) {
    Py_XDECREF(x);
    return NULL;
  }
  fcm_surface *s = NULL;
  fcm_status st = fcm_surface_create(ctx, PyArray_DIM(x, 0), PyArray_DATA(x), PyArray_DIM(t, 0),
                                     PyArray_DATA(t), &s);
  Py_DECREF(x);
  Py_DECREF(t);
  return made(st, ctx, FCMPY_SURFACE, s, ch, NULL);
}

static PyObject *surface_plane(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *p_o, *n_o, *lo_o, *hi_o;
  double p[3], n[3], lo[3], hi[3];
  fcm_ctx *ctx;
  if (!PyArg_ParseTuple(args, "OOOOO", &ch, &p_o, &n_o, &lo_o, &hi_o) || !ctx_handle(ch, &ctx) ||
      fcmpy_vec(p_o, p, 3, "point") < 0 || fcmpy_vec(n_o, n, 3, "normal") < 0 ||
      fcmpy_vec(lo_o, lo, 3, "lo") < 0 || fcmpy_vec(hi_o, hi, 3, "hi") < 0)
    return NULL;
  fcm_surface *s = NULL;
  fcm_status st = fcm_surface_create_plane(ctx, p, n, lo, hi, &s);
  return made(st, ctx, FCMPY_SURFACE, s, ch, NULL);
}

static PyObject *surface_array(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *sh;
  const char *which;
  if (!PyArg_ParseTuple(args, "Os", &sh, &which)) return NULL;
  const fcm_surface *s = fcmpy_get(sh, FCMPY_SURFACE);
  if (!s) return NULL;
  npy_intp dims[2] = {fcm_surface_num_vertices(s), 3};
  if (!strcmp(which, "coords")) return fcmpy_view(sh, fcm_surface_coords(s), NPY_DOUBLE, 2, dims);
  dims[0] = fcm_surface_num_triangles(s);
  if (!strcmp(which, "triangles"))
    return fcmpy_view(sh, fcm_surface_triangles(s), NPY_INT64, 2, dims);
  return PyErr_Format(PyExc_ValueError, "unknown surface array '%s'", which);
}

PyMethodDef fcmpy_geometry_methods[] = {
    {"mesh_create", mesh_create, METH_VARARGS, NULL},
    {"mesh_box", mesh_box, METH_VARARGS, NULL},
    {"mesh_octree", mesh_octree, METH_VARARGS, NULL},
    {"mesh_refined", mesh_refined, METH_VARARGS, NULL},
    {"read_file", read_file, METH_VARARGS, NULL},
    {"mesh_info", mesh_info, METH_O, NULL},
    {"mesh_array", mesh_array, METH_VARARGS, NULL},
    {"mesh_nodes_in_box", mesh_nodes_in_box, METH_VARARGS, NULL},
    {"geometry_shape", geometry_shape, METH_VARARGS, NULL},
    {"geometry_transformed", geometry_transformed, METH_VARARGS, NULL},
    {"geometry_from_level_set", geometry_from_level_set, METH_VARARGS, NULL},
    {"geometry_from_implicit", geometry_from_implicit, METH_VARARGS, NULL},
    {"geometry_from_surface", geometry_from_surface, METH_VARARGS, NULL},
    {"geometry_from_voxels", geometry_from_voxels, METH_VARARGS, NULL},
    {"geometry_info", geometry_info, METH_O, NULL},
    {"geometry_array", geometry_array, METH_VARARGS, NULL},
    {"voxels_create", voxels_create, METH_VARARGS, NULL},
    {"voxels_values", voxels_values, METH_O, NULL},
    {"surface_create", surface_create, METH_VARARGS, NULL},
    {"surface_plane", surface_plane, METH_VARARGS, NULL},
    {"surface_array", surface_array, METH_VARARGS, NULL},
    {NULL, NULL, 0, NULL}};
