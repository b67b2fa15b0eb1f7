/* fcm's Python binding: cut-cell rules (every option of fcm_cell_rules_options), their
 * per-cell and per-piece rules as NumPy views, whole-mesh gathers, statistics, cuts. */
#include "fcmpy.h"

#define RO(member) offsetof(fcm_cell_rules_options, member)
static const fcmpy_option rules_table[] = {
    {"kinds", 'u', 1, RO(kinds)},
    {"strength", 'i', FCM_RULE_KIND_COUNT, RO(strength)},
    {"axis_degree", 'i', FCM_RULE_KIND_COUNT, RO(axis_degree)},
    {"stiffness_on_mass_space", 'i', 1, RO(stiffness_on_mass_space)},
    {"surface_strength", 'i', 1, RO(surface_strength)},
    {"min_fraction", 'd', 1, RO(min_fraction)},
    {"uncut_fraction", 'd', 1, RO(uncut_fraction)},
    {"clip_rtol", 'd', 1, RO(clip_rtol)},
    {"sliver_rtol", 'd', 1, RO(sliver_rtol)},
    {"convex_rtol", 'd', 1, RO(convex_rtol)},
    {"simplify", 'i', 1, RO(simplify)},
    {"moments", 'i', 1, RO(moments)},
    {"expected_assemblies", 'd', FCM_RULE_KIND_COUNT, RO(expected_assemblies)},
    {"point_cost", 'd', FCM_RULE_KIND_COUNT, RO(point_cost)},
    {"simplify_method", 'i', 1, RO(simplify_options.method)},
    {"simplify_rank_tol", 'd', 1, RO(simplify_options.rank_tol)},
    {"simplify_residual_tol", 'd', 1, RO(simplify_options.residual_tol)},
    {"simplify_lp_iteration_limit", 'i', 1, RO(simplify_options.lp_iteration_limit)},
    {"simplify_lp_time_limit", 'd', 1, RO(simplify_options.lp_time_limit)},
    {"simplify_elimination_block", 'i', 1, RO(simplify_options.elimination_block)},
    {"max_rule_memory", 'd', 1, RO(max_rule_memory)},
    {"stabilization_mode", 'i', 1, RO(stabilization.mode)},
    {"stabilization_alpha", 'd', 1, RO(stabilization.alpha)},
    {NULL, 0, 0, 0}};
#undef RO

#define RS(member) offsetof(fcm_cell_rules_stats, member)
static const fcmpy_option stats_table[] = {
    {"num_cells", 'n', 1, RS(num_cells)},
    {"num_uncut", 'n', 1, RS(num_uncut)},
    {"num_cut", 'n', 1, RS(num_cut)},
    {"num_dropped", 'n', 1, RS(num_dropped)},
    {"num_candidates", 'n', 1, RS(num_candidates)},
    {"num_parts", 'n', 1, RS(num_parts)},
    {"num_material_pieces", 'n', 1, RS(num_material_pieces)},
    {"num_split", 'n', 1, RS(num_split)},
    {"num_links", 'n', 1, RS(num_links)},
    {"num_integrated", 'n', 1, RS(num_integrated)},
    {"num_kept", 'n', 1, RS(num_kept)},
    {"num_degenerate", 'n', 1, RS(num_degenerate)},
    {"cut_shift", 'd', 3, RS(cut_shift)},
    {"cut_attempts", 'i', 1, RS(cut_attempts)},
    {"split_change", 'd', 1, RS(split_change)},
    {"num_tets", 'n', 1, RS(num_tets)},
    {"num_slivers", 'n', 1, RS(num_slivers)},
    {"sliver_volume", 'd', 1, RS(sliver_volume)},
    {"moved_volume", 'd', 1, RS(moved_volume)},
    {"kinds", 'u', 1, RS(kinds)},
    {"points_initial", 'n', FCM_RULE_KIND_COUNT, RS(points_initial)},
    {"points_simplified", 'n', FCM_RULE_KIND_COUNT, RS(points_simplified)},
    {"points_stabilization", 'n', FCM_RULE_KIND_COUNT, RS(points_stabilization)},
    {"points_total", 'n', FCM_RULE_KIND_COUNT, RS(points_total)},
    {"simplify_skipped", 'n', FCM_RULE_KIND_COUNT, RS(simplify_skipped)},
    {"simplify_fallbacks", 'n', FCM_RULE_KIND_COUNT, RS(simplify_fallbacks)},
    {"max_residual", 'd', FCM_RULE_KIND_COUNT, RS(max_residual)},
    {"num_surface_cells", 'n', 1, RS(num_surface_cells)},
    {"num_surface_fallbacks", 'n', 1, RS(num_surface_fallbacks)},
    {"surface_triangles", 'n', 1, RS(surface_triangles)},
    {"surface_points", 'n', 1, RS(surface_points)},
    {"embedded_volume", 'd', 1, RS(embedded_volume)},
    {"dropped_volume", 'd', 1, RS(dropped_volume)},
    {"embedded_area", 'd', 1, RS(embedded_area)},
    {"dropped_area", 'd', 1, RS(dropped_area)},
    {"geometry_volume", 'd', 1, RS(geometry_volume)},
    {"outside_volume", 'd', 1, RS(outside_volume)},
    {"outside_side_volume", 'd', 6, RS(outside_side_volume)},
    {"volume_ratio", 'd', 1, RS(volume_ratio)},
    {"mesh_lo", 'd', 3, RS(mesh_lo)},
    {"mesh_hi", 'd', 3, RS(mesh_hi)},
    {"geometry_lo", 'd', 3, RS(geometry_lo)},
    {"geometry_hi", 'd', 3, RS(geometry_hi)},
    {"time_setup", 'd', 1, RS(time_setup)},
    {"time_intersect", 'd', 1, RS(time_intersect)},
    {"time_simplify", 'd', 1, RS(time_simplify)},
    {"time_gather", 'd', 1, RS(time_gather)},
    {"time_total", 'd', 1, RS(time_total)},
    {"num_threads", 'i', 1, RS(num_threads)},
    {"stiffness_simplified", 'i', 1, RS(decision[FCM_RULE_STIFFNESS].simplified)},
    {"mass_simplified", 'i', 1, RS(decision[FCM_RULE_MASS].simplified)},
    {NULL, 0, 0, 0}};
#undef RS

static PyObject *rules_defaults(PyObject *self, PyObject *noargs)
{
  (void)self;
  (void)noargs;
  const fcm_cell_rules_options o = fcm_cell_rules_options_default();
  return fcmpy_options_dict(rules_table, &o);
}

static PyObject *rules_create(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *mh, *gh, *opts_o, *mask_o;
  if (!PyArg_ParseTuple(args, "OOOOO", &ch, &mh, &gh, &opts_o, &mask_o)) return NULL;
  fcm_ctx *ctx = fcmpy_get(ch, FCMPY_CTX);
  const fcm_mesh *mesh = ctx ? fcmpy_get(mh, FCMPY_MESH) : NULL;
  const fcm_geometry *geom = mesh ? fcmpy_get(gh, FCMPY_GEOMETRY) : NULL;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  if (!geom || fcmpy_set_options(rules_table, &o, opts_o, "CellRules") < 0) return NULL;
  PyArrayObject *mask = NULL;
  if (mask_o != Py_None) {
    mask = fcmpy_input(mask_o, NPY_UINT8, 1, -1, "cell_mask");
    if (!mask) return NULL;
    if (PyArray_DIM(mask, 0) != fcm_mesh_num_cells(mesh)) {
      Py_DECREF(mask);
      return PyErr_Format(PyExc_ValueError, "cell_mask: expected %lld entries, got %zd",
                          (long long)fcm_mesh_num_cells(mesh), (Py_ssize_t)PyArray_DIM(mask, 0));
    }
    o.cell_mask = PyArray_DATA(mask);
  }
  fcm_cell_rules *rules = NULL;
  fcm_status st = fcm_cell_rules_create(ctx, mesh, geom, &o, &rules);
  Py_XDECREF(mask);
  if (st != FCM_OK) return fcmpy_raise(ctx, st);
  PyObject *ctx_h = (PyObject *)fcmpy_handle_of(ch, FCMPY_CTX);
  return fcmpy_handle_new(FCMPY_RULES, rules, ctx, &ctx_h, 1);
}

static PyObject *rules_cut(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *ch, *mh, *gh, *ph, *sh;
  if (!PyArg_ParseTuple(args, "OOOOO", &ch, &mh, &gh, &ph, &sh)) return NULL;
  fcm_ctx *ctx = fcmpy_get(ch, FCMPY_CTX);
  const fcm_mesh *mesh = ctx ? fcmpy_get(mh, FCMPY_MESH) : NULL;
  const fcm_geometry *geom = mesh ? fcmpy_get(gh, FCMPY_GEOMETRY) : NULL;
  const fcm_cell_rules *prev = geom ? fcmpy_get(ph, FCMPY_RULES) : NULL;
  const fcm_surface *cut = prev ? fcmpy_get(sh, FCMPY_SURFACE) : NULL;
  if (!cut) return NULL;
  fcm_cell_rules *rules = NULL;
  fcm_status st = fcm_cell_rules_create_cut(ctx, mesh, geom, prev, cut, &rules);
  if (st != FCM_OK) return fcmpy_raise(ctx, st);
  PyObject *ctx_h = (PyObject *)fcmpy_handle_of(ch, FCMPY_CTX);
  return fcmpy_handle_new(FCMPY_RULES, rules, ctx, &ctx_h, 1);
}

static PyObject *rules_info(PyObject *self, PyObject *rh)
{
  (void)self;
  const fcm_cell_rules *r = fcmpy_get(rh, FCMPY_RULES);
  if (!r) return NULL;
  return Py_BuildValue(
      "{s:L,s:i,s:(ii),s:(ii),s:i,s:(ii),s:i,s:L,s:L}", "num_cells",
      (long long)fcm_cell_rules_num_cells(r), "element_type", (int)fcm_cell_rules_element_type(r),
      "strength", fcm_cell_rules_strength(r, FCM_RULE_STIFFNESS),
      fcm_cell_rules_strength(r, FCM_RULE_MASS), "axis_degree",
      fcm_cell_rules_axis_degree(r, FCM_RULE_STIFFNESS),
      fcm_cell_rules_axis_degree(r, FCM_RULE_MASS), "surface_strength",
      fcm_cell_rules_surface_strength(r), "has_kind",
      fcm_cell_rules_has_kind(r, FCM_RULE_STIFFNESS), fcm_cell_rules_has_kind(r, FCM_RULE_MASS),
      "num_cuts", fcm_cell_rules_num_cuts(r), "num_pieces", (long long)fcm_cell_rules_num_pieces(r),
      "num_links", (long long)fcm_cell_rules_num_links(r));
}

static PyObject *rules_stats(PyObject *self, PyObject *rh)
{
  (void)self;
  const fcm_cell_rules *r = fcmpy_get(rh, FCMPY_RULES);
  return r ? fcmpy_options_dict(stats_table, fcm_cell_rules_get_stats(r)) : NULL;
}

static int rule_kind(int kind)
{
  if (kind < 0 || kind >= FCM_RULE_KIND_COUNT) {
    PyErr_Format(PyExc_ValueError, "rule kind %d out of range [0, %d)", kind, FCM_RULE_KIND_COUNT);
    return -1;
  }
  return 0;
}

/* (points (n, 3), weights (n,), flags (n,)) of a cell or (piece != 0) a piece: views. */
static PyObject *rules_get(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *rh;
  long long which;
  int kind, piece;
  if (!PyArg_ParseTuple(args, "OLip", &rh, &which, &kind, &piece) || rule_kind(kind) < 0)
    return NULL;
  fcmpy_handle *h = fcmpy_handle_of(rh, FCMPY_RULES);
  if (!h) return NULL;
  int n = 0;
  const double *x = NULL, *w = NULL;
  const unsigned char *f = NULL;
  fcm_status st = piece ? fcm_cell_rules_get_piece(h->ptr, which, kind, &n, &x, &w, &f)
                        : fcm_cell_rules_get(h->ptr, which, kind, &n, &x, &w, &f);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  npy_intp d2[2] = {n, 3}, d1[1] = {n};
  return Py_BuildValue("NNN", fcmpy_view(rh, x, NPY_DOUBLE, 2, d2),
                       fcmpy_view(rh, w, NPY_DOUBLE, 1, d1), fcmpy_view(rh, f, NPY_UINT8, 1, d1));
}

/* (points (n, 3), weights (n,), normals (n, 3), triangles (n,)) of a cell or a piece: views. */
static PyObject *rules_get_surface(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *rh;
  long long which;
  int piece;
  if (!PyArg_ParseTuple(args, "OLp", &rh, &which, &piece)) return NULL;
  fcmpy_handle *h = fcmpy_handle_of(rh, FCMPY_RULES);
  if (!h) return NULL;
  int n = 0;
  const double *x = NULL, *w = NULL, *nr = NULL;
  const fcm_index *t = NULL;
  fcm_status st = piece ? fcm_cell_rules_get_piece_surface(h->ptr, which, &n, &x, &w, &nr, &t)
                        : fcm_cell_rules_get_surface(h->ptr, which, &n, &x, &w, &nr, &t);
  if (st != FCM_OK) return fcmpy_raise(h->ctx, st);
  npy_intp d2[2] = {n, 3}, d1[1] = {n};
  return Py_BuildValue("NNNN", fcmpy_view(rh, x, NPY_DOUBLE, 2, d2),
                       fcmpy_view(rh, w, NPY_DOUBLE, 1, d1), fcmpy_view(rh, nr, NPY_DOUBLE, 2, d2),
                       fcmpy_view(rh, t, NPY_INT64, 1, d1));
}

/* Every point of a kind (kind < 0: the surface rules) over all cells, copied, with its
 * physical position: a dict of cell, xi, x, weight (volume: reference weight; surface:
 * physical area), physical_weight (volume: w det J; surface: w), flag or normal. */
static PyObject *rules_gather(PyObject *self, PyObject *args)
{
  (void)self;
  PyObject *rh, *mh;
  int kind;
  if (!PyArg_ParseTuple(args, "OOi", &rh, &mh, &kind) || (kind >= 0 && rule_kind(kind) < 0))
    return NULL;
  fcmpy_handle *h = fcmpy_handle_of(rh, FCMPY_RULES);
  const fcm_mesh *mesh = h ? fcmpy_get(mh, FCMPY_MESH) : NULL;
  if (!mesh) return NULL;
  const fcm_cell_rules *r = h->ptr;
  const fcm_index nc = fcm_cell_rules_num_cells(r);
  if (nc != fcm_mesh_num_cells(mesh) ||
      fcm_mesh_element_type(mesh) != fcm_cell_rules_element_type(r))
    return PyErr_Format(PyExc_ValueError,
                        "the mesh is not the one the rules were built on "
                        "(%lld cells, rules of %lld)",
                        (long long)fcm_mesh_num_cells(mesh), (long long)nc);
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  npy_intp total = 0;
  for (int pass = 0; pass < 2; pass++) {
    PyObject *cell_a = NULL, *xi_a = NULL, *x_a = NULL, *w_a = NULL, *pw_a = NULL, *extra_a = NULL;
    if (pass == 1) {
      npy_intp d1[1] = {total}, d2[2] = {total, 3};
      cell_a = PyArray_SimpleNew(1, d1, NPY_INT64);
      xi_a = PyArray_SimpleNew(2, d2, NPY_DOUBLE);
      x_a = PyArray_SimpleNew(2, d2, NPY_DOUBLE);
      w_a = PyArray_SimpleNew(1, d1, NPY_DOUBLE);
      pw_a = PyArray_SimpleNew(1, d1, NPY_DOUBLE);
      extra_a =
          kind >= 0 ? PyArray_SimpleNew(1, d1, NPY_UINT8) : PyArray_SimpleNew(2, d2, NPY_DOUBLE);
      if (!cell_a || !xi_a || !x_a || !w_a || !pw_a || !extra_a) goto fail;
    }
    npy_intp k = 0;
    double X[3 * 27];
    for (fcm_index c = 0; c < nc; c++) {
      int n = 0;
      const double *xi = NULL, *w = NULL, *nr = NULL;
      const unsigned char *f = NULL;
      fcm_status st = kind >= 0 ? fcm_cell_rules_get(r, c, kind, &n, &xi, &w, &f)
                                : fcm_cell_rules_get_surface(r, c, &n, &xi, &w, &nr, NULL);
      if (st != FCM_OK) {
        fcmpy_raise(h->ctx, st);
        goto fail;
      }
      if (pass == 0) {
        total += n;
        continue;
      }
      fcm_mesh_cell_coords(mesh, c, X);
      for (int j = 0; j < n; j++, k++) {
        double J[9];
        ((int64_t *)PyArray_DATA((PyArrayObject *)cell_a))[k] = c;
        double *xik = (double *)PyArray_DATA((PyArrayObject *)xi_a) + 3 * k;
        double *xk = (double *)PyArray_DATA((PyArrayObject *)x_a) + 3 * k;
        memcpy(xik, xi + 3 * j, 3 * sizeof *xik);
        fcm_element_map(type, X, xi + 3 * j, xk);
        ((double *)PyArray_DATA((PyArrayObject *)w_a))[k] = w[j];
        ((double *)PyArray_DATA((PyArrayObject *)pw_a))[k] =
            kind >= 0 ? w[j] * fcm_element_jacobian(type, X, xi + 3 * j, J) : w[j];
        if (kind >= 0)
          ((unsigned char *)PyArray_DATA((PyArrayObject *)extra_a))[k] = f[j];
        else
          memcpy((double *)PyArray_DATA((PyArrayObject *)extra_a) + 3 * k, nr + 3 * j,
                 3 * sizeof(double));
      }
    }
    if (pass == 1)
      return Py_BuildValue("{s:N,s:N,s:N,s:N,s:N,s:N}", "cell", cell_a, "xi", xi_a, "x", x_a,
                           "weight", w_a, "physical_weight", pw_a, kind >= 0 ? "flag" : "normal",
                           extra_a);
    continue;
  fail:
    Py_XDECREF(cell_a);
    Py_XDECREF(xi_a);
    Py_XDECREF(x_a);
    Py_XDECREF(w_a);
    Py_XDECREF(pw_a);
    Py_XDECREF(extra_a);
    return NULL;
  }
  return NULL;
}

/* Per cell: class (int8) and volume fraction; per piece: cell, volume and parent; the cells'
 * first piece and piece count; the links (views where the library stores them). */
static PyObject *rules_cells(PyObject *self, PyObject *rh)
{
  (void)self;
  const fcm_cell_rules *r = fcmpy_get(rh, FCMPY_RULES);
  if (!r) return NULL;
  const fcm_index nc = fcm_cell_rules_num_cells(r), np = fcm_cell_rules_num_pieces(r);
  npy_intp dc[1] = {nc}, dp[1] = {np}, dl[2] = {fcm_cell_rules_num_links(r), 2};
  PyObject *cls = PyArray_SimpleNew(1, dc, NPY_INT8), *frac = PyArray_SimpleNew(1, dc, NPY_DOUBLE);
  PyObject *first = PyArray_SimpleNew(1, dc, NPY_INT64),
           *count = PyArray_SimpleNew(1, dc, NPY_INT64);
  PyObject *pcell = PyArray_SimpleNew(1, dp, NPY_INT64),
           *pvol = PyArray_SimpleNew(1, dp, NPY_DOUBLE);
  PyObject *parent = PyArray_SimpleNew(1, dp, NPY_INT64);
  PyObject *links = fcmpy_view(rh, fcm_cell_rules_links(r), NPY_INT64, 2, dl);
  if (!cls || !frac || !first || !count || !pcell || !pvol || !parent || !links) {
    Py_XDECREF(cls);
    Py_XDECREF(frac);
    Py_XDECREF(first);
    Py_XDECREF(count);
    Py_XDECREF(pcell);
    Py_XDECREF(pvol);
    Py_XDECREF(parent);
    Py_XDECREF(links);
    return NULL;
  }
  for (fcm_index c = 0; c < nc; c++) {
    fcm_index f0 = 0;
    ((int8_t *)PyArray_DATA((PyArrayObject *)cls))[c] = (int8_t)fcm_cell_rules_class(r, c);
    ((double *)PyArray_DATA((PyArrayObject *)frac))[c] = fcm_cell_rules_volume_fraction(r, c);
    ((int64_t *)PyArray_DATA((PyArrayObject *)count))[c] = fcm_cell_rules_cell_pieces(r, c, &f0);
    ((int64_t *)PyArray_DATA((PyArrayObject *)first))[c] = f0;
  }
  for (fcm_index p = 0; p < np; p++) {
    ((int64_t *)PyArray_DATA((PyArrayObject *)pcell))[p] = fcm_cell_rules_piece_cell(r, p);
    ((double *)PyArray_DATA((PyArrayObject *)pvol))[p] = fcm_cell_rules_piece_volume(r, p);
    ((int64_t *)PyArray_DATA((PyArrayObject *)parent))[p] = fcm_cell_rules_piece_parent(r, p);
  }
  return Py_BuildValue("{s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:N}", "cell_class", cls, "volume_fraction",
                       frac, "cell_first_piece", first, "cell_num_pieces", count, "piece_cell",
                       pcell, "piece_volume", pvol, "piece_parent", parent, "links", links);
}

PyMethodDef fcmpy_rules_methods[] = {{"rules_defaults", rules_defaults, METH_NOARGS, NULL},
                                     {"rules_create", rules_create, METH_VARARGS, NULL},
                                     {"rules_cut", rules_cut, METH_VARARGS, NULL},
                                     {"rules_info", rules_info, METH_O, NULL},
                                     {"rules_stats", rules_stats, METH_O, NULL},
                                     {"rules_get", rules_get, METH_VARARGS, NULL},
                                     {"rules_get_surface", rules_get_surface, METH_VARARGS, NULL},
                                     {"rules_gather", rules_gather, METH_VARARGS, NULL},
                                     {"rules_cells", rules_cells, METH_O, NULL},
                                     {NULL, NULL, 0, NULL}};
