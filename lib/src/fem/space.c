/* Finite element space: creation (active cells, then the numbering of numbering.c and the
 * topology of topology.c), destruction, accessors, matrices on its pattern, local spaces,
 * Dirichlet elimination and the transfer of a field over a cut. */
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The most points of any rule of cut cell c's pieces (in *most). */
static fcm_status cell_cut_points(fcm_ctx *ctx, const fcm_cell_rules *rules, fcm_index c, int *most)
{
  fcm_status st = FCM_OK;
  fcm_index first = 0;
  const fcm_index np = fcm_cell_rules_cell_pieces(rules, c, &first);
  *most = 0;
  for (fcm_index p = first; p < first + np; p++)
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      int n = 0;
      if (!fcm_cell_rules_has_kind(rules, (fcm_rule_kind)k)) continue; /* not built */
      FCM_TRY(ctx, fcm_cell_rules_get_piece(rules, p, (fcm_rule_kind)k, &n, NULL, NULL, NULL));
      *most = FCM_MAX(*most, n);
    }
cleanup:
  return st;
}

/* Shared by fcm_space_create(), fcm_space_create_embedded(), fcm__space_create_local() (local
 * != 0: the topology of the cells flagged in cell_mask only) and fcm__space_create_cut() (from:
 * the space before the cut, whose topology the new one patches). */
static fcm_status space_create(fcm_ctx *ctx, const fcm_mesh *mesh, const unsigned char *cell_active,
                               const fcm_cell_rules *rules, const fcm_space_options *opts,
                               int local, const unsigned char *cell_mask, const fcm_space *from,
                               fcm_space *give, fcm_space **out)
{
  fcm_status st = FCM_OK;
  fcm_space *s = NULL;
  fcm_index *inc_ptr = NULL, *inc = NULL, nactive_cells = 0;
  int max_points = 0;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "space: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(mesh, ctx, FCM_ERR_ARG, "space: mesh is NULL");
  FCM_ALLOC(ctx, 1, s);
  s->ctx = ctx;
  s->mesh = mesh;
  s->rules = rules;
  s->type = fcm_mesh_element_type(mesh);
  s->nn = fcm_mesh_nodes_per_cell(mesh);
  s->num_cells = fcm_mesh_num_cells(mesh);
  s->num_nodes = fcm_mesh_num_nodes(mesh);
  FCM_ALLOC_RAW(ctx, s->num_cells + 1, s->active); /* every cell's written below */
  fcm__loop loop;
  fcm__loop_begin(ctx, &loop);
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx)) schedule(static) \
    reduction(+ : nactive_cells) reduction(max : max_points)
  for (fcm_index c = 0; c < s->num_cells; c++) {
    s->active[c] = cell_active ? (cell_active[c] != 0) : 1;
    if (rules) {
      fcm_cell_class cls = fcm_cell_rules_class(rules, c);
      s->active[c] = cls != FCM_CELL_DROPPED;
      if (cls == FCM_CELL_CUT && !fcm__loop_skip(&loop, c)) {
        fcm__loop_iter it;
        int n = 0;
        fcm__loop_enter(&loop, &it, c);
        fcm__loop_leave(&loop, &it, cell_cut_points(ctx, rules, c, &n));
        max_points = FCM_MAX(max_points, n);
      }
    }
    nactive_cells += s->active[c];
  }
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
  s->max_cut_points = max_points;
  FCM_CHECK(nactive_cells > 0, ctx, FCM_ERR_ARG, "space: none of the %lld cells is active",
            (long long)s->num_cells);
  FCM_ALLOC(ctx, s->num_nodes, s->node_dof);
  FCM_TRY(ctx, fcm__space_build_elements(s));
  FCM_TRY(ctx, fcm__space_build_incidence(s, &inc_ptr, &inc));
  FCM_TRY(ctx, fcm__space_build_copies(s, inc_ptr, inc));
  if (rules && opts && opts->constrain_ratio > 0.0)
    FCM_TRY(ctx, fcm__space_constrain_copies(s, opts->constrain_ratio, inc_ptr, inc));
  {
    int dummy;
    FCM_TRY(ctx, fcm__index_to_int(ctx, s->num_dofs, "space: number of DOFs", &dummy));
  }
  /* the numbering's incidence is not needed any more: free it before the topology's peak */
  FCM_FREE(ctx, inc_ptr);
  FCM_FREE(ctx, inc);
  s->is_local = local;
  if (from && !local)
    FCM_TRY(ctx, fcm__space_build_topology_cut(s, from, give));
  else
    FCM_TRY(ctx, fcm__space_build_topology(s, local, cell_mask));
  FCM_TRY(ctx, fcm_element_standard_rule(ctx, s->type, FCM_RULE_MASS, FCM_DEFAULT, &s->mass_rule));
  FCM_ALLOC(ctx, 1, s->mass_cache);
  *out = s;
  s = NULL;
cleanup:
  fcm__free(ctx, inc_ptr);
  fcm__free(ctx, inc);
  fcm_space_destroy(&s);
  return st;
}

fcm_status fcm_space_create(fcm_ctx *ctx, const fcm_mesh *mesh, const unsigned char *cell_active,
                            fcm_space **out)
{
  return space_create(ctx, mesh, cell_active, NULL, NULL, 0, NULL, NULL, NULL, out);
}

fcm_space_options fcm_space_options_default(void)
{
  fcm_space_options o;
  memset(&o, 0, sizeof o);
  o.constrain_ratio = 1e-9;
  return o;
}

fcm_status fcm_space_create_embedded(fcm_ctx *ctx, const fcm_mesh *mesh,
                                     const fcm_cell_rules *rules, fcm_space **out)
{
  const fcm_space_options o = fcm_space_options_default();
  return fcm_space_create_embedded_with(ctx, mesh, rules, &o, out);
}

/* The arguments of an embedded space (rules built on this mesh, constrain_ratio in range). */
static fcm_status check_embedded(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_cell_rules *rules,
                                 const fcm_space_options *opts)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(mesh && rules, ctx, FCM_ERR_ARG, "space: mesh or cell rules is NULL");
  FCM_CHECK(fcm_cell_rules_num_cells(rules) == fcm_mesh_num_cells(mesh) &&
                fcm_cell_rules_element_type(rules) == fcm_mesh_element_type(mesh),
            ctx, FCM_ERR_ARG,
            "space: the cell rules (%lld cells) were not built on this mesh (%lld cells)",
            (long long)fcm_cell_rules_num_cells(rules), (long long)fcm_mesh_num_cells(mesh));
  FCM_CHECK(!opts || (isfinite(opts->constrain_ratio) && opts->constrain_ratio >= 0.0 &&
                      opts->constrain_ratio < 0.5),
            ctx, FCM_ERR_ARG, "space: constrain_ratio = %g outside [0, 0.5)",
            opts ? opts->constrain_ratio : 0.0);
cleanup:
  return st;
}

fcm_status fcm_space_create_embedded_with(fcm_ctx *ctx, const fcm_mesh *mesh,
                                          const fcm_cell_rules *rules,
                                          const fcm_space_options *opts, fcm_space **out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "space: output pointer is NULL");
  *out = NULL;
  FCM_TRY(ctx, check_embedded(ctx, mesh, rules, opts));
  FCM_TRY(ctx, space_create(ctx, mesh, NULL, rules, opts, 0, NULL, NULL, NULL, out));
cleanup:
  return st;
}

/* The cut space patched from `from`, writing its columns in take's (NULL: its own). */
static fcm_status create_cut(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_cell_rules *rules,
                             const fcm_space_options *opts, const fcm_space *from, fcm_space *take,
                             fcm_space **out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "cut space: output pointer is NULL");
  *out = NULL;
  FCM_TRY(ctx, check_embedded(ctx, mesh, rules, opts));
  FCM_TRY(ctx, space_create(ctx, mesh, NULL, rules, opts, 0, NULL, from, take, out));
cleanup:
  return st;
}

fcm_status fcm__space_create_cut(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_cell_rules *rules,
                                 const fcm_space_options *opts, const fcm_space *from,
                                 fcm_space **out)
{
  return create_cut(ctx, mesh, rules, opts, from, NULL, out);
}

fcm_status fcm__space_create_cut_take(fcm_ctx *ctx, const fcm_mesh *mesh,
                                      const fcm_cell_rules *rules, const fcm_space_options *opts,
                                      fcm_space *from, fcm_space **out)
{
  return create_cut(ctx, mesh, rules, opts, from, from, out);
}

fcm_status fcm__space_create_local(fcm_ctx *ctx, const fcm_mesh *mesh,
                                   const unsigned char *cell_active, const fcm_cell_rules *rules,
                                   const fcm_space_options *opts, const unsigned char *cell_mask,
                                   fcm_space **out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "space: output pointer is NULL");
  *out = NULL;
  if (rules) {
    FCM_CHECK(!cell_active, ctx, FCM_ERR_ARG,
              "local space: give the cell rules or cell_active, not both (the rules decide "
              "which cells are active)");
    FCM_TRY(ctx, check_embedded(ctx, mesh, rules, opts));
  }
  FCM_TRY(ctx, space_create(ctx, mesh, cell_active, rules, rules ? opts : NULL, 1, cell_mask, NULL,
                            NULL, out));
cleanup:
  return st;
}

fcm_status fcm__space_set_local_cells(fcm_space *s, const unsigned char *cell_mask)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  FCM_CHECK(s, ctx, FCM_ERR_ARG, "local space: NULL space");
  FCM_CHECK(s->is_local, ctx, FCM_ERR_ARG,
            "local space: the space is a full space (fcm_space_create*()); only a space of "
            "fcm__space_create_local() takes a cell mask");
  FCM_TRY(ctx, fcm__space_build_topology(s, 1, cell_mask));
cleanup:
  return st;
}

const fcm_cell_rules *fcm_space_cell_rules(const fcm_space *s)
{
  return s->rules;
}

void fcm_space_destroy(fcm_space **sp)
{
  if (!sp || !*sp) return;
  fcm_space *s = *sp;
  fcm_ctx *ctx = s->ctx;
  fcm__free(ctx, s->active);
  fcm__free(ctx, s->own);
  fcm__free(ctx, s->node_dof);
  fcm__free(ctx, s->node_ncopy);
  fcm__free(ctx, s->cell_elem);
  fcm__free(ctx, s->elem_cell);
  fcm__free(ctx, s->elem_piece);
  fcm__free(ctx, s->elem_dof);
  fcm__free(ctx, s->elem_con);
  fcm__space_free_topology(s);
  fcm_rule_destroy(&s->mass_rule);
  fcm__space_mass_cache_free(s);
  fcm__free(ctx, s);
  *sp = NULL;
}

fcm_index fcm_space_num_dofs(const fcm_space *s)
{
  return s->num_dofs;
}

fcm_index fcm_space_node_dof(const fcm_space *s, fcm_index node)
{
  return (node < 0 || node >= s->num_nodes) ? -1 : s->node_dof[node];
}

fcm_index fcm_space_node_copies(const fcm_space *s, fcm_index node)
{
  return (node < 0 || node >= s->num_nodes) ? 0 : s->node_ncopy[node];
}

fcm_index fcm_space_num_constrained_copies(const fcm_space *s)
{
  return s->num_constrained;
}

int fcm_space_element_constrained(const fcm_space *s, fcm_index elem)
{
  int n = 0;
  if (!s || !s->elem_con || elem < 0 || elem >= s->num_elems) return 0;
  for (int a = 0; a < s->nn; a++)
    n += s->elem_con[elem * s->nn + a];
  return n;
}

fcm_index fcm_space_num_elements(const fcm_space *s)
{
  return s->num_elems;
}

fcm_index fcm_space_cell_elements(const fcm_space *s, fcm_index cell, fcm_index *first)
{
  if (cell < 0 || cell >= s->num_cells) {
    if (first) *first = 0;
    return 0;
  }
  if (first) *first = s->cell_elem[cell];
  return s->cell_elem[cell + 1] - s->cell_elem[cell];
}

fcm_index fcm_space_element_cell(const fcm_space *s, fcm_index elem)
{
  return (elem < 0 || elem >= s->num_elems) ? -1 : s->elem_cell[elem];
}

const fcm_index *fcm_space_element_dofs(const fcm_space *s, fcm_index elem)
{
  return (elem < 0 || elem >= s->num_elems) ? NULL : s->elem_dof + elem * s->nn;
}

int fcm_space_num_colors(const fcm_space *s)
{
  return s->num_colors;
}

int fcm_space_cell_active(const fcm_space *s, fcm_index cell)
{
  return cell >= 0 && cell < s->num_cells && s->active[cell];
}

const fcm_mesh *fcm_space_mesh(const fcm_space *s)
{
  return s->mesh;
}

fcm_status fcm__space_check_full(const fcm_space *s, const char *what)
{
  if (!s->is_local) return FCM_OK;
  fcm_index nl = 0;
  for (fcm_index c = 0; s->cell_local && c < s->num_cells; c++)
    nl += s->cell_local[c] != 0;
  return fcm__error(s->ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "%s: the space is a local space (its pattern covers the elements of %lld of "
                    "its %lld cells: a distributed run's own and ghost cells); this needs the "
                    "whole pattern: build the space with fcm_space_create() or "
                    "fcm_space_create_embedded()",
                    what, (long long)nl, (long long)s->num_cells);
}

void fcm__space_memory(const fcm_space *s, double *numbering, double *topology)
{
  const double I = (double)sizeof(fcm_index), nn = (double)s->nn;
  const double ne = (double)s->num_elems, nc = (double)s->num_cells, np = (double)s->num_nodes;
  const double nl = (double)s->num_local_copies, nle = (double)s->num_local_elems;
  const double nadj = s->node_ptr ? (double)s->node_ptr[s->num_local_copies] : 0.0;
  if (numbering) /* active, node_dof, node_ncopy, cell_elem, elem_cell, elem_piece, elem_dof,
                   elem_con */
    *numbering = nc + 2.0 * I * np + I * (nc + 1.0) + 2.0 * I * ne + I * nn * ne +
                 (s->elem_con ? nn * ne : 0.0);
  if (topology) /* node_ptr, node_adj, row_ptr, col_idx (9 per graph entry), elem_off, colours,
                   local lists, elem_lcopy */
    *topology = I * (nl + 1.0) + I * nadj + I * (3.0 * nl + 1.0) +
                (double)sizeof(int) * 9.0 * nadj + (double)sizeof(int) * nn * nn * nle +
                I * ((double)s->num_colors + 1.0) + I * nle +
                (s->is_local ? I * (nl + nle) + nc + (double)sizeof(int) * nn * nle : 0.0);
}

/* FCM_OK when s has its pattern's columns; else FCM_ERR_ARG: a cut space took them. */
static fcm_status check_pattern(const fcm_space *s, const char *what)
{
  if (s->col_idx || !s->row_ptr || s->row_ptr[fcm__space_num_rows(s)] == 0) return FCM_OK;
  return fcm__error(s->ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "%s: the space's pattern went to the space of a cut "
                    "(fcm__space_create_cut_take()); it can only be destroyed, or get its "
                    "pattern back from that space (fcm__space_cut_give_back())",
                    what);
}

fcm_status fcm_space_matrix_create(const fcm_space *s, fcm_csr **A)
{
  fcm_status st = FCM_OK;
  FCM_TRY(s->ctx, fcm__space_check_full(s, "space matrix"));
  FCM_TRY(s->ctx, check_pattern(s, "space matrix"));
  FCM_TRY(s->ctx, fcm_csr_create(s->ctx, s->num_dofs, s->num_dofs, s->row_ptr, s->col_idx,
                                 FCM_CSR_SYMMETRIC, A));
cleanup:
  return st;
}

fcm_index fcm__space_elem_local(const fcm_space *s, fcm_index e)
{
  if (e < 0 || e >= s->num_elems) return -1;
  if (!s->local_elem) return s->is_local ? -1 : e; /* a local space without local elements */
  const fcm_index lo = fcm__lower_bound(s->local_elem, 1, 0, s->num_local_elems, e);
  return (lo < s->num_local_elems && s->local_elem[lo] == e) ? lo : -1;
}

fcm_status fcm__space_matrix_create_rows(const fcm_space *s, fcm_csr **A)
{
  return fcm__space_matrix_create_rows_from(s, NULL, A);
}

fcm_status fcm__space_matrix_create_rows_from(const fcm_space *s, fcm_csr *give, fcm_csr **A)
{
  return fcm__space_matrix_create_rows_keep(s, give, A, NULL);
}

fcm_status fcm__space_matrix_create_rows_unzeroed(const fcm_space *s, fcm_csr *give, fcm_csr **A)
{
  int taken = 0; /* either way the caller writes every entry */
  return fcm__space_matrix_create_rows_keep(s, give, A, &taken);
}

fcm_status fcm__space_matrix_create_rows_keep(const fcm_space *s, fcm_csr *give, fcm_csr **A,
                                              int *taken)
{
  fcm_status st = FCM_OK;
  if (taken) *taken = 0;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  FCM_CHECK(s && A, ctx, FCM_ERR_ARG, "space matrix (rows): NULL space or output pointer");
  *A = NULL;
  FCM_CHECK(s->row_ptr, ctx, FCM_ERR_ARG,
            "space matrix (rows): the local space has no topology (a failed rebuild)");
  FCM_TRY(ctx, check_pattern(s, "space matrix (rows)"));
  /* the space's pattern, shared (borrowed: the space outlives the matrices made on it) */
  FCM_TRY(ctx, fcm__csr_share_pattern_keep(
                   ctx, fcm__space_num_rows(s), s->num_dofs, s->row_ptr, s->col_idx,
                   s->is_local ? FCM_CSR_GENERAL : FCM_CSR_SYMMETRIC, give, A, taken));
cleanup:
  return st;
}

fcm_status fcm__space_matrix_apply(const fcm_space *s, const fcm_csr *A, const double *x, double *y)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  fcm_index nr = -1, nc = -1, nnz = -1;
  FCM_CHECK(s && A, ctx, FCM_ERR_ARG, "space matrix apply: NULL space or matrix");
  if (!s->is_local) {
    FCM_TRY(ctx, fcm_csr_apply(A, 1.0, x, 0.0, y));
    goto cleanup;
  }
  const fcm_index nrow = fcm__space_num_rows(s);
  fcm_csr_get_size(A, &nr, &nc, &nnz);
  FCM_CHECK(nr == nrow && nc == s->num_dofs && s->row_ptr && nnz == s->row_ptr[nrow], ctx,
            FCM_ERR_ARG,
            "space matrix apply: matrix is %lld x %lld with %lld entries; the local space's "
            "rows need %lld x %lld (create it with fcm__space_matrix_create_rows)",
            (long long)nr, (long long)nc, (long long)nnz, (long long)nrow, (long long)s->num_dofs);
  FCM_CHECK((x && y) || s->num_dofs == 0, ctx, FCM_ERR_ARG, "space matrix apply: x or y is NULL");
  FCM_CHECK(!x || x != y, ctx, FCM_ERR_ARG,
            "space matrix apply: x and y must not be the same array");
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  for (fcm_index i = 0; i < s->num_dofs; i++)
    y[i] = 0.0;
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx)) schedule(static) if (nnz >= 20000)
  for (fcm_index r = 0; r < nrow; r++) { /* distinct rows write distinct DOFs */
    double sum = 0.0;
    for (fcm_index p = rp[r]; p < rp[r + 1]; p++)
      sum += v[p] * x[ci[p]];
    y[fcm__space_row_dof(s, r)] = 1.0 * sum; /* as fcm_csr_apply(A, 1, x, 0, y) */
  }
cleanup:
  return st;
}

fcm_status fcm__space_localize(fcm_space *s, const unsigned char *own)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  unsigned char *mark = NULL, *mask = NULL;
  FCM_CHECK(s && own, ctx, FCM_ERR_ARG, "localize: NULL space or own-cell flags");
  FCM_CHECK(s->is_local, ctx, FCM_ERR_ARG,
            "localize: the space is a full space (fcm_space_create*()); only a space of "
            "fcm__space_create_local() takes local cells");
  const fcm_index ncopy = s->num_dofs / 3, nn = s->nn;
  FCM_ALLOC(ctx, ncopy + 1, mark);
  FCM_ALLOC(ctx, s->num_cells + 1, mask);
  for (fcm_index c = 0; c < s->num_cells; c++) /* the copies of the own cells' elements */
    if (own[c] && s->active[c])
      for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++)
        for (int a = 0; a < nn; a++)
          mark[s->elem_dof[e * nn + a] / 3] = 1;
  for (fcm_index c = 0; c < s->num_cells; c++) { /* own cells and their ghosts */
    if (!s->active[c]) continue;
    int hit = own[c] != 0;
    for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1] && !hit; e++)
      for (int a = 0; a < nn && !hit; a++)
        hit = mark[s->elem_dof[e * nn + a] / 3];
    mask[c] = (unsigned char)hit;
  }
  FCM_TRY(ctx, fcm__space_set_local_cells(s, mask));
  if (!s->rules) { /* no cell mask of rules: the space keeps which cells get points here */
    if (!s->own) FCM_ALLOC(ctx, s->num_cells + 1, s->own);
    for (fcm_index c = 0; c < s->num_cells; c++)
      s->own[c] = own[c] != 0;
  }
cleanup:
  if (s) {
    fcm__free(ctx, mark);
    fcm__free(ctx, mask);
  }
  return st;
}

fcm_status fcm__space_check_assemble(const fcm_space *s, const char *what)
{
  if (!s) return FCM_ERR_ARG;
  if (!s->is_local) return FCM_OK;
  /* points go to the cells fcm__space_owns() flags (the rules' cell mask, a space without
   * rules its own cells; all without either): each active one must be local, or its elements
   * would scatter into rows the space lacks */
  for (fcm_index c = 0; c < s->num_cells; c++) {
    if (!s->active[c] || !fcm__space_owns(s, c) || (s->cell_local && s->cell_local[c])) continue;
    if (!s->rules && !s->own)
      return fcm__error(s->ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                        "%s: the space is a local space without cell rules or own cells: every "
                        "active cell gets points, and active cell %lld is not a local cell "
                        "(localize the space on the own cells: fcm__space_localize())",
                        what, (long long)c);
    if (s->rules && !s->rules->own)
      return fcm__error(s->ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                        "%s: the space is a local space, but its cell rules were built without a "
                        "cell_mask: every active cell gets points, and active cell %lld is not a "
                        "local cell (build the rules with fcm_cell_rules_options.cell_mask "
                        "flagging the own cells)",
                        what, (long long)c);
    return fcm__error(s->ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                      "%s: the space's cell rules flag active cell %lld in their cell_mask (it "
                      "gets points), but the local space does not cover it (localize the space "
                      "on the cells the rules flag: fcm__space_localize())",
                      what, (long long)c);
  }
  return FCM_OK;
}

void fcm__eliminate_marked(fcm_csr *A, double *b, const unsigned char *con, const double *g)
{
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  double *v = fcm_csr_values(A);
#pragma omp parallel for num_threads(fcm_ctx_num_threads(A->ctx)) schedule(static)
  for (fcm_index i = 0; i < n; i++) {
    if (con[i]) {
      double diag = 1.0;
      for (fcm_index e = rp[i]; e < rp[i + 1]; e++) {
        if (ci[e] == i && v[e] > 0.0) diag = v[e];
        v[e] = 0.0;
      }
      for (fcm_index e = rp[i]; e < rp[i + 1]; e++)
        if (ci[e] == i) v[e] = diag;
      if (b) b[i] = diag * g[i];
    } else {
      double acc = 0.0;
      for (fcm_index e = rp[i]; e < rp[i + 1]; e++)
        if (con[ci[e]]) {
          if (b) acc += v[e] * g[ci[e]];
          v[e] = 0.0;
        }
      if (b) b[i] -= acc;
    }
  }
}

fcm_status fcm_space_apply_dirichlet(const fcm_space *s, fcm_index ncon, const fcm_index *dofs,
                                     const double *values, fcm_csr *A, double *b)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  unsigned char *con = NULL;
  double *g = NULL;
  fcm_index n = 0, nr, nc;
  FCM_CHECK(A && b && (ncon == 0 || dofs), ctx, FCM_ERR_ARG, "dirichlet: NULL argument");
  fcm_csr_get_size(A, &nr, &nc, NULL);
  FCM_CHECK(nr == nc, ctx, FCM_ERR_ARG, "dirichlet: matrix is %lld x %lld, not square",
            (long long)nr, (long long)nc);
  n = nr;
  FCM_ALLOC(ctx, n, con);
  FCM_ALLOC(ctx, n, g);
  for (fcm_index k = 0; k < ncon; k++) {
    fcm_index d = dofs[k];
    FCM_CHECK(d >= 0 && d < n, ctx, FCM_ERR_ARG,
              "dirichlet: dofs[%lld] = %lld out of range [0, %lld)", (long long)k, (long long)d,
              (long long)n);
    FCM_CHECK(!con[d], ctx, FCM_ERR_ARG, "dirichlet: DOF %lld is constrained twice", (long long)d);
    con[d] = 1;
    g[d] = values ? values[k] : 0.0;
  }
  fcm__eliminate_marked(A, b, con, g);
cleanup:
  fcm__free(ctx, con);
  fcm__free(ctx, g);
  return st;
}

fcm_status fcm_space_transfer(const fcm_space *from, const fcm_space *to, const double *x_from,
                              double *x_to)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = to ? to->ctx : NULL;
  FCM_CHECK(from && to && x_from && x_to, ctx, FCM_ERR_ARG, "space transfer: NULL argument");
  FCM_TRY(ctx, fcm__space_check_cut_pair(from, to, "space transfer"));
  for (fcm_index e = 0; e < to->num_elems; e++) {
    const fcm_index fe = fcm__space_cut_parent_elem(from, to, e);
    FCM_CHECK(fe >= 0, ctx, FCM_ERR_INTERNAL,
              "space transfer: element %lld (cell %lld) has its parent piece outside the cell's "
              "pieces in the source",
              (long long)e, (long long)to->elem_cell[e]);
    for (int a = 0; a < to->nn; a++) {
      const fcm_index d = to->elem_dof[e * to->nn + a];
      /* a constrained copy's place holds the copy it moves with (of another node, or another
       * copy of this one): that copy's own elements set it, from their parents' values */
      if (to->elem_con && to->elem_con[e * to->nn + a]) continue;
      for (int i = 0; i < 3; i++)
        x_to[d + i] = x_from[from->elem_dof[fe * from->nn + a] + i];
    }
  }
cleanup:
  return st;
}
