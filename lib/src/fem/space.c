/* Finite element space: active nodes, DOF numbering, the node graph and scalar
 * CSR pattern built once, per-cell scatter offsets, and the cell colouring. */
#include "fem/fem_impl.h"

#include <stdlib.h>
#include <string.h>

/* qsort comparator for fcm_index. */
static int cmp_index(const void *a, const void *b)
{
  fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

/* Node -> cells incidence (active cells only) as CSR: inc_ptr[num_nodes+1], inc. */
static fcm_status build_incidence(fcm_space *s, fcm_index **inc_ptr, fcm_index **inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  fcm_index *ptr = NULL, *list = NULL, *fill = NULL;
  FCM_ALLOC(ctx, s->num_nodes + 1, ptr);
  for (fcm_index c = 0; c < s->num_cells; c++)
    if (s->active[c])
      for (int a = 0; a < s->nn; a++)
        ptr[cells[c * s->nn + a] + 1]++;
  for (fcm_index n = 0; n < s->num_nodes; n++)
    ptr[n + 1] += ptr[n];
  FCM_ALLOC(ctx, ptr[s->num_nodes], list);
  FCM_ALLOC(ctx, s->num_nodes, fill);
  for (fcm_index c = 0; c < s->num_cells; c++)
    if (s->active[c])
      for (int a = 0; a < s->nn; a++) {
        fcm_index n = cells[c * s->nn + a];
        list[ptr[n] + fill[n]++] = c;
      }
  *inc_ptr = ptr;
  *inc = list;
  ptr = list = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, list);
  fcm__free(ctx, fill);
  return st;
}

/* Node graph over active ranks: neighbours through shared active cells, sorted. */
static fcm_status build_node_graph(fcm_space *s, const fcm_index *inc_ptr, const fcm_index *inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  fcm_index nact = s->num_dofs / 3;
  fcm_index *mark = NULL;
  FCM_ALLOC(ctx, s->num_nodes, mark);
  for (fcm_index n = 0; n < s->num_nodes; n++)
    mark[n] = -1;
  FCM_ALLOC(ctx, nact + 1, s->node_ptr);
  /* Pass 1 counts, pass 2 fills: the mark array avoids duplicates without sorting twice. */
  for (int pass = 0; pass < 2; pass++) {
    for (fcm_index n = 0; n < s->num_nodes; n++) {
      fcm_index k = s->node_dof[n];
      if (k < 0) continue;
      k /= 3;
      fcm_index cnt = 0, base = pass ? s->node_ptr[k] : 0;
      for (fcm_index e = inc_ptr[n]; e < inc_ptr[n + 1]; e++) {
        const fcm_index *cn = cells + inc[e] * s->nn;
        for (int b = 0; b < s->nn; b++) {
          fcm_index m = cn[b];
          if (mark[m] == n) continue;
          mark[m] = n;
          if (pass) s->node_adj[base + cnt] = s->node_dof[m] / 3;
          cnt++;
        }
      }
      if (pass)
        qsort(s->node_adj + base, (size_t)cnt, sizeof *s->node_adj, cmp_index);
      else
        s->node_ptr[k + 1] = cnt;
    }
    if (!pass) {
      for (fcm_index k = 0; k < nact; k++)
        s->node_ptr[k + 1] += s->node_ptr[k];
      FCM_ALLOC(ctx, s->node_ptr[nact], s->node_adj);
      for (fcm_index n = 0; n < s->num_nodes; n++)
        mark[n] = -1;
    }
  }
cleanup:
  fcm__free(ctx, mark);
  return st;
}

/* Scalar pattern from the node graph, and the per-cell offsets. */
static fcm_status build_pattern(fcm_space *s)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_index nact = s->num_dofs / 3;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  FCM_ALLOC(ctx, s->num_dofs + 1, s->row_ptr);
  for (fcm_index k = 0; k < nact; k++) {
    fcm_index deg = s->node_ptr[k + 1] - s->node_ptr[k];
    for (int i = 0; i < 3; i++)
      s->row_ptr[3 * k + i + 1] = s->row_ptr[3 * k + i] + 3 * deg;
  }
  FCM_ALLOC(ctx, s->row_ptr[s->num_dofs], s->col_idx);
  for (fcm_index k = 0; k < nact; k++)
    for (int i = 0; i < 3; i++) {
      int *cols = s->col_idx + s->row_ptr[3 * k + i];
      for (fcm_index e = s->node_ptr[k]; e < s->node_ptr[k + 1]; e++)
        for (int j = 0; j < 3; j++)
          *cols++ = (int)(3 * s->node_adj[e] + j);
    }
  FCM_ALLOC(ctx, (size_t)s->num_cells * s->nn * s->nn, s->cell_off);
  for (fcm_index c = 0; c < s->num_cells; c++) {
    if (!s->active[c]) continue;
    const fcm_index *cn = cells + c * s->nn;
    int *off = s->cell_off + (size_t)c * s->nn * s->nn;
    for (int a = 0; a < s->nn; a++) {
      fcm_index ka = s->node_dof[cn[a]] / 3;
      const fcm_index *row = s->node_adj + s->node_ptr[ka];
      size_t len = (size_t)(s->node_ptr[ka + 1] - s->node_ptr[ka]);
      for (int b = 0; b < s->nn; b++) {
        fcm_index kb = s->node_dof[cn[b]] / 3;
        const fcm_index *hit = bsearch(&kb, row, len, sizeof *row, cmp_index);
        FCM_ASSERT(hit != NULL, ctx);
        off[a * s->nn + b] = (int)(hit - row);
      }
    }
  }
cleanup:
  return st;
}

/* Greedy colouring: a cell takes the smallest colour not used by a cell sharing a node. */
static fcm_status build_colors(fcm_space *s, const fcm_index *inc_ptr, const fcm_index *inc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  int *color = NULL, ncol = 0;
  fcm_index *forbid = NULL, *fill = NULL;
  enum { MAX_COLORS = 4096 };
  FCM_ALLOC(ctx, s->num_cells, color);
  FCM_ALLOC(ctx, MAX_COLORS, forbid);
  for (int k = 0; k < MAX_COLORS; k++)
    forbid[k] = -1;
  for (fcm_index c = 0; c < s->num_cells; c++) {
    color[c] = -1;
    if (!s->active[c]) continue;
    for (int a = 0; a < s->nn; a++) {
      fcm_index n = cells[c * s->nn + a];
      for (fcm_index e = inc_ptr[n]; e < inc_ptr[n + 1]; e++)
        if (color[inc[e]] >= 0) forbid[color[inc[e]]] = c;
    }
    int k = 0;
    while (k < MAX_COLORS && forbid[k] == c)
      k++;
    FCM_CHECK(k < MAX_COLORS, ctx, FCM_ERR_UNSUPPORTED,
              "space: cell %lld needs more than %d colours (a node shared by too many cells)",
              (long long)c, MAX_COLORS);
    color[c] = k;
    ncol = FCM_MAX(ncol, k + 1);
  }
  s->num_colors = ncol;
  FCM_ALLOC(ctx, ncol + 1, s->color_ptr);
  for (fcm_index c = 0; c < s->num_cells; c++)
    if (color[c] >= 0) s->color_ptr[color[c] + 1]++;
  for (int k = 0; k < ncol; k++)
    s->color_ptr[k + 1] += s->color_ptr[k];
  FCM_ALLOC(ctx, s->color_ptr[ncol], s->color_cells);
  FCM_ALLOC(ctx, ncol, fill);
  for (fcm_index c = 0; c < s->num_cells; c++)
    if (color[c] >= 0) s->color_cells[s->color_ptr[color[c]] + fill[color[c]]++] = c;
cleanup:
  fcm__free(ctx, color);
  fcm__free(ctx, forbid);
  fcm__free(ctx, fill);
  return st;
}

/* Shared by fcm_space_create() and fcm_space_create_embedded(). */
static fcm_status space_create(fcm_ctx *ctx, const fcm_mesh *mesh, const unsigned char *cell_active,
                               const fcm_cell_rules *rules, fcm_space **out)
{
  fcm_status st = FCM_OK;
  fcm_space *s = NULL;
  fcm_index *inc_ptr = NULL, *inc = NULL, nact = 0, nactive_cells = 0;
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
  FCM_ALLOC(ctx, s->num_cells, s->active);
  for (fcm_index c = 0; c < s->num_cells; c++) {
    s->active[c] = cell_active ? (cell_active[c] != 0) : 1;
    if (rules) {
      fcm_cell_class cls = fcm_cell_rules_class(rules, c);
      s->active[c] = cls != FCM_CELL_DROPPED;
      for (int k = 0; k < FCM_RULE_KIND_COUNT && cls == FCM_CELL_CUT; k++) {
        int np = 0;
        FCM_TRY(ctx, fcm_cell_rules_get(rules, c, (fcm_rule_kind)k, &np, NULL, NULL, NULL));
        s->max_cut_points = FCM_MAX(s->max_cut_points, np);
      }
    }
    nactive_cells += s->active[c];
  }
  FCM_CHECK(nactive_cells > 0, ctx, FCM_ERR_ARG, "space: none of the %lld cells is active",
            (long long)s->num_cells);
  FCM_ALLOC(ctx, s->num_nodes, s->node_dof);
  {
    const fcm_index *cells = fcm_mesh_cells(mesh);
    for (fcm_index n = 0; n < s->num_nodes; n++)
      s->node_dof[n] = -1;
    for (fcm_index c = 0; c < s->num_cells; c++)
      if (s->active[c])
        for (int a = 0; a < s->nn; a++)
          s->node_dof[cells[c * s->nn + a]] = 0;
    for (fcm_index n = 0; n < s->num_nodes; n++)
      if (s->node_dof[n] == 0) s->node_dof[n] = 3 * nact++;
  }
  s->num_dofs = 3 * nact;
  {
    int dummy;
    FCM_TRY(ctx, fcm__index_to_int(ctx, s->num_dofs, "space: number of DOFs", &dummy));
  }
  FCM_TRY(ctx, build_incidence(s, &inc_ptr, &inc));
  FCM_TRY(ctx, build_node_graph(s, inc_ptr, inc));
  FCM_TRY(ctx, build_pattern(s));
  FCM_TRY(ctx, build_colors(s, inc_ptr, inc));
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
  return space_create(ctx, mesh, cell_active, NULL, out);
}

fcm_status fcm_space_create_embedded(fcm_ctx *ctx, const fcm_mesh *mesh,
                                     const fcm_cell_rules *rules, fcm_space **out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(out, ctx, FCM_ERR_ARG, "space: output pointer is NULL");
  *out = NULL;
  FCM_CHECK(mesh && rules, ctx, FCM_ERR_ARG, "space: mesh or cell rules is NULL");
  FCM_CHECK(fcm_cell_rules_num_cells(rules) == fcm_mesh_num_cells(mesh) &&
                fcm_cell_rules_element_type(rules) == fcm_mesh_element_type(mesh),
            ctx, FCM_ERR_ARG,
            "space: the cell rules (%lld cells) were not built on this mesh (%lld cells)",
            (long long)fcm_cell_rules_num_cells(rules), (long long)fcm_mesh_num_cells(mesh));
  FCM_TRY(ctx, space_create(ctx, mesh, NULL, rules, out));
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
  fcm__free(ctx, s->node_dof);
  fcm__free(ctx, s->node_ptr);
  fcm__free(ctx, s->node_adj);
  fcm__free(ctx, s->row_ptr);
  fcm__free(ctx, s->col_idx);
  fcm__free(ctx, s->cell_off);
  fcm__free(ctx, s->color_ptr);
  fcm__free(ctx, s->color_cells);
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

fcm_status fcm_space_matrix_create(const fcm_space *s, fcm_csr **A)
{
  fcm_status st = FCM_OK;
  FCM_TRY(s->ctx, fcm_csr_create(s->ctx, s->num_dofs, s->num_dofs, s->row_ptr, s->col_idx,
                                 FCM_CSR_SYMMETRIC, A));
cleanup:
  return st;
}

void fcm__eliminate_marked(fcm_csr *A, double *b, const unsigned char *con, const double *g)
{
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  double *v = fcm_csr_values(A);
#pragma omp parallel for schedule(static)
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
