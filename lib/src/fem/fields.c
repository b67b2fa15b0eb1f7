/* Fields of a solution for output: DOF vectors per background node, stress, von Mises stress
 * and strain energy density at points and as cell averages, the embedded surface, VTU files.
 * Every file holds reference positions with a `displacement` point array (apps/docs/fcm-sim.md:
 * ParaView). */
#include "fem/fem_impl.h"
#include "la/mat3.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The material prepared once per call: parameters and Psi(I). */
typedef struct stress_model {
  fcm_material_params p;
  double psi0;
} stress_model;

static fcm_status stress_model_setup(fcm_ctx *ctx, const fcm_material *mat, stress_model *m)
{
  fcm_status st = FCM_OK;
  static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  FCM_CHECK(mat, ctx, FCM_ERR_ARG, "stress: material is NULL");
  FCM_TRY(ctx, fcm_material_setup(ctx, mat, &m->p));
  fcm_material_eval(&m->p, I, &m->psi0, NULL, NULL);
cleanup:
  return st;
}

/* Stress measures at reference point xi of element e (cell coordinates X given). */
static void point_stress(const fcm_space *s, const stress_model *m, fcm_index e, const double *X,
                         const double xi[3], const double *u, double sig[6], double *vm,
                         double *sed)
{
  double dN[3 * FCM_ELEMENT_MAX_NODES], J[9], Ji[9], F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double P[9], psi = 0.0;
  fcm_element_eval_grad(s->type, xi, dN);
  fcm_element_jacobian(s->type, X, xi, J);
  fcm__mat3_inv(J, Ji);
  const fcm_index *ed = s->elem_dof + e * s->nn;
  for (int a = 0; a < s->nn; a++) {
    double g[3]; /* dN_a/dX_j = sum_k dN_a/dxi_k (J^-1)_kj */
    for (int j = 0; j < 3; j++)
      g[j] = dN[3 * a] * Ji[j] + dN[3 * a + 1] * Ji[3 + j] + dN[3 * a + 2] * Ji[6 + j];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        F[3 * i + j] += u[ed[a] + i] * g[j];
  }
  fcm_material_eval(&m->p, F, &psi, P, NULL);
  double c[9]; /* Cauchy stress, full */
  if (m->p.model == FCM_MATERIAL_LINEAR) {
    memcpy(c, P, sizeof c);
  } else {
    const double det = fcm__mat3_det(F);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        c[3 * i + j] = det > 0.0 ? (P[3 * i] * F[3 * j] + P[3 * i + 1] * F[3 * j + 1] +
                                    P[3 * i + 2] * F[3 * j + 2]) /
                                       det
                                 : NAN;
  }
  sig[FCM_STRESS_XX] = c[0], sig[FCM_STRESS_YY] = c[4], sig[FCM_STRESS_ZZ] = c[8];
  sig[FCM_STRESS_XY] = 0.5 * (c[1] + c[3]);
  sig[FCM_STRESS_YZ] = 0.5 * (c[5] + c[7]);
  sig[FCM_STRESS_XZ] = 0.5 * (c[2] + c[6]);
  const double dxy = sig[0] - sig[1], dyz = sig[1] - sig[2], dzx = sig[2] - sig[0];
  *vm = sqrt(0.5 * (dxy * dxy + dyz * dyz + dzx * dzx) +
             3.0 * (sig[3] * sig[3] + sig[4] * sig[4] + sig[5] * sig[5]));
  *sed = psi - m->psi0;
}

fcm_status fcm_space_element_stress(const fcm_space *s, const fcm_material *mat, fcm_index elem,
                                    const double xi[3], const double *u, double stress[6],
                                    double *von_mises, double *energy_density)
{
  fcm_status st = FCM_OK;
  stress_model m;
  double X[3 * FCM_ELEMENT_MAX_NODES], sig[6], vm, sed;
  FCM_CHECK(s && xi && u, s ? s->ctx : NULL, FCM_ERR_ARG, "stress: NULL space, point or field");
  FCM_CHECK(elem >= 0 && elem < s->num_elems, s->ctx, FCM_ERR_ARG,
            "stress: element %lld is out of range [0, %lld)", (long long)elem,
            (long long)s->num_elems);
  FCM_TRY(s->ctx, stress_model_setup(s->ctx, mat, &m));
  fcm_mesh_cell_coords(s->mesh, s->elem_cell[elem], X);
  point_stress(s, &m, elem, X, xi, u, sig, &vm, &sed);
  if (stress) memcpy(stress, sig, sizeof sig);
  if (von_mises) *von_mises = vm;
  if (energy_density) *energy_density = sed;
cleanup:
  return st;
}

/* The authentic volume points of element e for integration over the body: the piece's own
 * stiffness rule in a cut cell, else the standard rule `full`. */
static void element_points(const fcm_space *s, const fcm_rule *full, fcm_index e, int *nq,
                           const double **pts, const double **w, const unsigned char **fl)
{
  if (s->rules && fcm_cell_rules_class(s->rules, s->elem_cell[e]) != FCM_CELL_UNCUT) {
    if (fcm_cell_rules_get_piece(s->rules, s->elem_piece[e], FCM_RULE_STIFFNESS, nq, pts, w, fl) !=
        FCM_OK)
      *nq = 0;
    return;
  }
  *nq = fcm_rule_num_points(full);
  *pts = fcm_rule_points(full);
  *w = fcm_rule_weights(full);
  *fl = NULL;
}

fcm_status fcm_space_cell_stress(const fcm_space *s, const fcm_material *mat, const double *u,
                                 double *stress, double *von_mises, double *energy_density)
{
  fcm_status st = FCM_OK;
  fcm_rule *full = NULL;
  stress_model m;
  FCM_CHECK(s && u, s ? s->ctx : NULL, FCM_ERR_ARG, "cell stress: NULL space or field");
  FCM_TRY(s->ctx, stress_model_setup(s->ctx, mat, &m));
  FCM_TRY(s->ctx,
          fcm_element_standard_rule(s->ctx, s->type, FCM_RULE_STIFFNESS, FCM_DEFAULT, &full));
  {
    const fcm_index nc = s->num_cells;
#pragma omp parallel for num_threads(fcm_ctx_num_threads(s->ctx)) schedule(dynamic, 64)
    for (fcm_index c = 0; c < nc; c++) {
      double X[3 * FCM_ELEMENT_MAX_NODES], J[9], acc[8] = {0, 0, 0, 0, 0, 0, 0, 0}, vol = 0.0;
      fcm_mesh_cell_coords(s->mesh, c, X);
      for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++) {
        int nq = 0;
        const double *pts = NULL, *w = NULL;
        const unsigned char *fl = NULL;
        element_points(s, full, e, &nq, &pts, &w, &fl);
        for (int q = 0; q < nq; q++) {
          if (fl && fl[q]) continue; /* fictitious stabilization points: not the body */
          double sig[6], vm, sed;
          const double wd = w[q] * fabs(fcm_element_jacobian(s->type, X, pts + 3 * q, J));
          point_stress(s, &m, e, X, pts + 3 * q, u, sig, &vm, &sed);
          for (int k = 0; k < 6; k++)
            acc[k] += wd * sig[k];
          acc[6] += wd * vm;
          acc[7] += wd * sed;
          vol += wd;
        }
      }
      for (int k = 0; k < 8; k++)
        acc[k] = vol > 0.0 ? acc[k] / vol : 0.0;
      if (stress) memcpy(stress + 6 * c, acc, 6 * sizeof *acc);
      if (von_mises) von_mises[c] = acc[6];
      if (energy_density) energy_density[c] = acc[7];
    }
  }
cleanup:
  fcm_rule_destroy(&full);
  return st;
}

/* The largest |u|^2 at element e's points and `best` (a NaN, once met, stays). */
static double element_max2(const fcm_space *s, const fcm_rule *full, fcm_index e, const double *u,
                           double best)
{
  int nq = 0;
  const double *pts = NULL, *w = NULL;
  const unsigned char *fl = NULL;
  element_points(s, full, e, &nq, &pts, &w, &fl);
  for (int q = 0; q < nq; q++) {
    double v[3];
    if (fl && fl[q]) continue;
    fcm_space_element_eval(s, e, pts + 3 * q, u, v);
    const double n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (!(n2 <= best) && best == best) best = n2;
  }
  return best;
}

fcm_status fcm_space_max_displacement(const fcm_space *s, const double *u, double *max_norm)
{
  fcm_status st = FCM_OK;
  fcm_rule *full = NULL;
  double best = 0.0;
  FCM_CHECK(s && u && max_norm, s ? s->ctx : NULL, FCM_ERR_ARG,
            "max displacement: NULL space, field or output");
  FCM_TRY(s->ctx,
          fcm_element_standard_rule(s->ctx, s->type, FCM_RULE_STIFFNESS, FCM_DEFAULT, &full));
  for (fcm_index e = 0; e < s->num_elems; e++)
    best = element_max2(s, full, e, u, best);
  *max_norm = sqrt(best);
cleanup:
  fcm_rule_destroy(&full);
  return st;
}

fcm_status fcm__space_cell_max_displacement(const fcm_space *s, const double *u, double *cell_max)
{
  fcm_status st = FCM_OK;
  fcm_rule *full = NULL;
  FCM_TRY(s->ctx,
          fcm_element_standard_rule(s->ctx, s->type, FCM_RULE_STIFFNESS, FCM_DEFAULT, &full));
  for (fcm_index c = 0; c < s->num_cells; c++) {
    double best = 0.0;
    for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++)
      best = element_max2(s, full, e, u, best);
    cell_max[c] = sqrt(best);
  }
cleanup:
  fcm_rule_destroy(&full);
  return st;
}

/* The DOF fcm_space_node_field() reads at node a (-1: inactive): its first copy, or with the
 * supports of the copies (NULL when no node has two) the first of the largest support. */
static fcm_index node_field_dof(const fcm_space *s, const double *support, fcm_index a)
{
  fcm_index d = s->node_dof[a];
  if (d >= 0 && support)
    for (fcm_index k = 1; k < s->node_ncopy[a]; k++)
      if (support[s->node_dof[a] / 3 + k] > support[d / 3]) d = s->node_dof[a] + 3 * k;
  return d;
}

/* The copies' supports when some node has two copies (*support NULL otherwise). */
static fcm_status node_field_support(const fcm_space *s, double **support)
{
  fcm_status st = FCM_OK;
  int copies = 0;
  *support = NULL;
  for (fcm_index a = 0; a < s->num_nodes && !copies; a++)
    copies = s->node_ncopy[a] > 1;
  if (copies) {
    FCM_ALLOC(s->ctx, s->num_dofs / 3 + 1, *support);
    fcm__space_copy_support(s, *support);
  }
cleanup:
  return st;
}

fcm_status fcm_space_node_field(const fcm_space *s, const double *dofs, double *node_field)
{
  fcm_status st = FCM_OK;
  double *support = NULL;
  FCM_CHECK(s && dofs && node_field, s ? s->ctx : NULL, FCM_ERR_ARG,
            "node field: NULL space, DOF vector or output");
  FCM_TRY(s->ctx, node_field_support(s, &support));
  for (fcm_index a = 0; a < s->num_nodes; a++) {
    const fcm_index d = node_field_dof(s, support, a);
    for (int i = 0; i < 3; i++)
      node_field[3 * a + i] = d >= 0 ? dofs[d + i] : 0.0;
  }
cleanup:
  fcm__free(s ? s->ctx : NULL, support);
  return st;
}

fcm_status fcm__space_node_field_dofs(const fcm_space *s, fcm_index n, const fcm_index *nodes,
                                      fcm_index *dofs)
{
  fcm_status st = FCM_OK;
  double *support = NULL;
  FCM_TRY(s->ctx, node_field_support(s, &support));
  for (fcm_index i = 0; i < n; i++)
    dofs[i] = node_field_dof(s, support, nodes[i]);
cleanup:
  fcm__free(s->ctx, support);
  return st;
}

static int cmp_node(const void *a, const void *b)
{
  const fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

fcm_status fcm__space_piece_nodes(const fcm_space *s, const unsigned char *keep, fcm_index *num,
                                  fcm_index **nodes)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const int npc = fcm_mesh_nodes_per_cell(s->mesh);
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  fcm_index *list = NULL, len = 0, m = 0;
  *num = 0;
  *nodes = NULL;
  for (fcm_index c = 0; c < s->num_cells; c++)
    len += (!keep || keep[c]) ? npc : 0;
  FCM_ALLOC(ctx, len + 1, list);
  for (fcm_index c = 0; c < s->num_cells; c++)
    if (!keep || keep[c])
      for (int k = 0; k < npc; k++)
        list[m++] = cells[(size_t)npc * c + k];
  qsort(list, (size_t)len, sizeof *list, cmp_node);
  m = 0;
  for (fcm_index i = 0; i < len; i++)
    if (i == 0 || list[i] != list[i - 1]) list[m++] = list[i];
  *num = m;
  *nodes = list;
  list = NULL;
cleanup:
  fcm__free(ctx, list);
  return st;
}

/* Entries of x[0 .. n) that are NaN or infinite. */
static fcm_index count_nonfinite(fcm_index n, const double *x)
{
  fcm_index k = 0;
  for (fcm_index i = 0; i < n; i++)
    k += !isfinite(x[i]);
  return k;
}

fcm_status fcm_space_write_vtu(const fcm_space *s, const fcm_material *mat, const double *u,
                               const double *v, const char *path)
{
  return fcm__space_write_vtu_counted(s, mat, u, v, path, NULL);
}

fcm_status fcm__space_write_vtu_counted(const fcm_space *s, const fcm_material *mat,
                                        const double *u, const double *v, const char *path,
                                        fcm_index *nonfinite)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  fcm_vtu *vtu = NULL;
  double *nu = NULL, *nv = NULL, *phi = NULL, *sig = NULL, *vm = NULL, *sed = NULL, *zero = NULL;
  int32_t *active = NULL;
  if (nonfinite) *nonfinite = 0;
  FCM_CHECK(s && path, ctx, FCM_ERR_ARG, "write vtu: NULL space or path");
  const fcm_index nn = s->num_nodes, nc = s->num_cells;
  FCM_ALLOC(ctx, 3 * nn + 1, nu);
  FCM_ALLOC(ctx, nc + 1, phi);
  FCM_ALLOC(ctx, nc + 1, active);
  if (u) FCM_TRY(ctx, fcm_space_node_field(s, u, nu));
  if (v) {
    FCM_ALLOC(ctx, 3 * nn + 1, nv);
    FCM_TRY(ctx, fcm_space_node_field(s, v, nv));
  }
  for (fcm_index c = 0; c < nc; c++) {
    active[c] = s->active[c] ? 1 : 0;
    phi[c] = s->rules ? fcm_cell_rules_volume_fraction(s->rules, c) : 1.0;
  }
  FCM_TRY(ctx, fcm_vtu_create(ctx, &vtu));
  FCM_TRY(ctx, fcm_vtu_set_points(vtu, nn, fcm_mesh_coords(s->mesh)));
  FCM_TRY(ctx, fcm_vtu_set_cells(vtu, fcm_mesh_get_element_info(s->mesh)->vtk_cell_type, nc,
                                 fcm_mesh_cells(s->mesh)));
  FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "displacement", 3, nn, nu));
  if (nv) FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "velocity", 3, nn, nv));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(vtu, FCM_VTU_CELL_DATA, "active", 1, nc, active));
  FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "volume_fraction", 1, nc, phi));
  if (mat) {
    FCM_ALLOC(ctx, 6 * nc + 1, sig);
    FCM_ALLOC(ctx, nc + 1, vm);
    FCM_ALLOC(ctx, nc + 1, sed);
    if (!u) FCM_ALLOC(ctx, s->num_dofs + 1, zero);
    FCM_TRY(ctx, fcm_space_cell_stress(s, mat, u ? u : zero, sig, vm, sed));
    if (nonfinite) *nonfinite = count_nonfinite(nc, vm);
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "stress", 6, nc, sig));
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "von_mises", 1, nc, vm));
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "strain_energy_density", 1, nc, sed));
  }
  FCM_TRY(ctx, fcm_vtu_write(vtu, path, NULL));
cleanup:
  fcm_vtu_destroy(&vtu);
  void *arrays[] = {nu, nv, phi, sig, vm, sed, zero, active};
  for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
    fcm__free(ctx, arrays[k]);
  return st;
}

/* A piece of the kept cells: np points, the mesh nodes listed ascending in `nodes` (every node
 * of a kept cell), numbered in the order the kept cells first use them; nu, nv: 3 values per
 * listed node (nv NULL: no velocity); with mat, the cells' stress of the full DOF vector u. */
static fcm_status write_piece(const fcm_space *s, const fcm_material *mat, const double *u,
                              const unsigned char *keep, fcm_index np, const fcm_index *nodes,
                              const double *nu, const double *nv, int rank, const char *path,
                              fcm_index *nonfinite)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_vtu *vtu = NULL;
  fcm_index *pid = NULL, *conn = NULL, ncl = 0, next = 0;
  double *xyz = NULL, *pu = NULL, *pv = NULL, *phi = NULL;
  double *sig = NULL, *vm = NULL, *sed = NULL, *csig = NULL, *cvm = NULL, *csed = NULL;
  double *zero = NULL;
  int32_t *owner = NULL, *cid = NULL, *nid = NULL, *active = NULL;
  const fcm_index nn = s->num_nodes, nc = s->num_cells;
  FCM_CHECK(nn < INT32_MAX && nc < INT32_MAX, ctx, FCM_ERR_ARG,
            "write vtu piece: %lld nodes, %lld cells: the indices must fit Int32", (long long)nn,
            (long long)nc);
  const int npc = fcm_mesh_nodes_per_cell(s->mesh);
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  const double *X = fcm_mesh_coords(s->mesh);
  FCM_ALLOC(ctx, np + 1, pid);
  for (fcm_index i = 0; i < np; i++)
    pid[i] = -1;
  for (fcm_index c = 0; c < nc; c++)
    if (!keep || keep[c]) {
      ncl++;
      for (int k = 0; k < npc; k++) {
        const fcm_index *hit =
            bsearch(cells + (size_t)npc * c + k, nodes, (size_t)np, sizeof *nodes, cmp_node);
        FCM_CHECK(hit, ctx, FCM_ERR_INTERNAL, "write vtu piece: node %lld of cell %lld unlisted",
                  (long long)cells[(size_t)npc * c + k], (long long)c);
        if (pid[hit - nodes] < 0) pid[hit - nodes] = next++;
      }
    }
  FCM_CHECK(next == np, ctx, FCM_ERR_INTERNAL,
            "write vtu piece: %lld listed nodes, the kept cells use %lld", (long long)np,
            (long long)next);
  FCM_ALLOC(ctx, 3 * np + 1, xyz);
  FCM_ALLOC(ctx, 3 * np + 1, pu);
  FCM_ALLOC(ctx, 3 * np + 1, pv);
  FCM_ALLOC(ctx, np + 1, nid);
  FCM_ALLOC(ctx, (size_t)npc * ncl + 1, conn);
  FCM_ALLOC(ctx, ncl + 1, phi);
  FCM_ALLOC(ctx, ncl + 1, owner);
  FCM_ALLOC(ctx, ncl + 1, cid);
  FCM_ALLOC(ctx, ncl + 1, active);
  for (fcm_index i = 0; i < np; i++) {
    const fcm_index a = nodes[i], p = pid[i];
    nid[p] = (int32_t)a;
    for (int j = 0; j < 3; j++) {
      xyz[3 * p + j] = X[3 * a + j];
      pu[3 * p + j] = nu[3 * i + j];
      pv[3 * p + j] = nv ? nv[3 * i + j] : 0.0;
    }
  }
  if (mat) {
    FCM_ALLOC(ctx, 6 * nc + 1, sig);
    FCM_ALLOC(ctx, nc + 1, vm);
    FCM_ALLOC(ctx, nc + 1, sed);
    FCM_ALLOC(ctx, 6 * ncl + 1, csig);
    FCM_ALLOC(ctx, ncl + 1, cvm);
    FCM_ALLOC(ctx, ncl + 1, csed);
    if (!u) FCM_ALLOC(ctx, s->num_dofs + 1, zero);
    FCM_TRY(ctx, fcm_space_cell_stress(s, mat, u ? u : zero, sig, vm, sed));
  }
  fcm_index m = 0;
  for (fcm_index c = 0; c < nc; c++)
    if (!keep || keep[c]) {
      for (int k = 0; k < npc; k++) {
        const fcm_index *hit =
            bsearch(cells + (size_t)npc * c + k, nodes, (size_t)np, sizeof *nodes, cmp_node);
        conn[(size_t)npc * m + k] = pid[hit - nodes];
      }
      phi[m] = s->rules ? fcm_cell_rules_volume_fraction(s->rules, c) : 1.0;
      owner[m] = rank;
      cid[m] = (int32_t)c;
      active[m] = s->active[c] ? 1 : 0;
      if (mat) {
        memcpy(csig + 6 * m, sig + 6 * c, 6 * sizeof *csig);
        cvm[m] = vm[c];
        csed[m] = sed[c];
      }
      m++;
    }
  if (mat && nonfinite) *nonfinite = count_nonfinite(ncl, cvm);
  FCM_TRY(ctx, fcm_vtu_create(ctx, &vtu));
  FCM_TRY(ctx, fcm_vtu_set_points(vtu, np, xyz));
  FCM_TRY(ctx,
          fcm_vtu_set_cells(vtu, fcm_mesh_get_element_info(s->mesh)->vtk_cell_type, ncl, conn));
  FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "displacement", 3, np, pu));
  if (nv) FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "velocity", 3, np, pv));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(vtu, FCM_VTU_POINT_DATA, "node_index", 1, np, nid));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(vtu, FCM_VTU_CELL_DATA, "process", 1, ncl, owner));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(vtu, FCM_VTU_CELL_DATA, "cell_index", 1, ncl, cid));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(vtu, FCM_VTU_CELL_DATA, "active", 1, ncl, active));
  FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "volume_fraction", 1, ncl, phi));
  if (mat) {
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "stress", 6, ncl, csig));
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "von_mises", 1, ncl, cvm));
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_CELL_DATA, "strain_energy_density", 1, ncl, csed));
  }
  FCM_TRY(ctx, fcm_vtu_write(vtu, path, NULL));
cleanup:
  fcm_vtu_destroy(&vtu);
  void *arrays[] = {pid,  conn, xyz,  pu,   pv,    phi, sig, vm,    sed,
                    csig, cvm,  csed, zero, owner, cid, nid, active};
  for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
    fcm__free(ctx, arrays[k]);
  return st;
}

fcm_status fcm__space_write_vtu_piece(const fcm_space *s, const fcm_material *mat, const double *u,
                                      const double *v, const unsigned char *keep, int rank,
                                      const char *path, fcm_index *nonfinite)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  fcm_index np = 0, *nodes = NULL, *dofs = NULL;
  double *nu = NULL, *nv = NULL;
  if (nonfinite) *nonfinite = 0;
  FCM_CHECK(s && path, ctx, FCM_ERR_ARG, "write vtu piece: NULL space or path");
  FCM_TRY(ctx, fcm__space_piece_nodes(s, keep, &np, &nodes));
  FCM_ALLOC(ctx, np + 1, dofs);
  FCM_ALLOC(ctx, 3 * np + 1, nu);
  if (v) FCM_ALLOC(ctx, 3 * np + 1, nv);
  FCM_TRY(ctx, fcm__space_node_field_dofs(s, np, nodes, dofs));
  for (fcm_index i = 0; i < np; i++)
    for (int j = 0; j < 3; j++) {
      nu[3 * i + j] = u && dofs[i] >= 0 ? u[dofs[i] + j] : 0.0;
      if (nv) nv[3 * i + j] = dofs[i] >= 0 ? v[dofs[i] + j] : 0.0;
    }
  FCM_TRY(ctx, write_piece(s, mat, u, keep, np, nodes, nu, nv, rank, path, nonfinite));
cleanup:
  fcm__free(ctx, nodes);
  fcm__free(ctx, dofs);
  fcm__free(ctx, nu);
  fcm__free(ctx, nv);
  return st;
}

fcm_status fcm__space_write_vtu_piece_values(const fcm_space *s, const unsigned char *keep,
                                             fcm_index np, const fcm_index *nodes, const double *nu,
                                             const double *nv, int rank, const char *path)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  FCM_CHECK(s && path && (np == 0 || (nodes && nu)), ctx, FCM_ERR_ARG,
            "write vtu piece: NULL space, path, nodes or values");
  FCM_TRY(ctx, write_piece(s, NULL, NULL, keep, np, nodes, nu, nv, rank, path, NULL));
cleanup:
  return st;
}

/* The host's byte order as VTK names it (the pieces are written in it). */
static const char *byte_order(void)
{
  const uint16_t one = 1;
  unsigned char first;
  memcpy(&first, &one, 1);
  return first ? "LittleEndian" : "BigEndian";
}

fcm_status fcm__write_pvtu(fcm_ctx *ctx, const char *path, const char *stem, int nprocs,
                           int with_velocity, int with_stress)
{
  fcm_status st = FCM_OK;
  fcm_atomic_file *af = NULL;
  FCM_CHECK(path && stem && nprocs >= 1, ctx, FCM_ERR_ARG,
            "write pvtu: NULL path or stem, or %d processes (must be >= 1)", nprocs);
  FCM_TRY(ctx, fcm_atomic_file_open(ctx, path, &af));
  FILE *f = fcm_atomic_file_stream(af);
  fprintf(f,
          "<?xml version=\"1.0\"?>\n"
          "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" "
          "header_type=\"UInt64\">\n"
          "  <PUnstructuredGrid GhostLevel=\"0\">\n"
          "    <PPointData>\n"
          "      <PDataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\"/>\n",
          byte_order());
  if (with_velocity)
    fprintf(f, "      <PDataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\"/>\n");
  fprintf(f, "      <PDataArray type=\"Int32\" Name=\"node_index\" NumberOfComponents=\"1\"/>\n"
             "    </PPointData>\n"
             "    <PCellData>\n"
             "      <PDataArray type=\"Int32\" Name=\"process\" NumberOfComponents=\"1\"/>\n"
             "      <PDataArray type=\"Int32\" Name=\"cell_index\" NumberOfComponents=\"1\"/>\n"
             "      <PDataArray type=\"Int32\" Name=\"active\" NumberOfComponents=\"1\"/>\n"
             "      <PDataArray type=\"Float64\" Name=\"volume_fraction\" "
             "NumberOfComponents=\"1\"/>\n");
  if (with_stress)
    fprintf(f, "      <PDataArray type=\"Float64\" Name=\"stress\" NumberOfComponents=\"6\"/>\n"
               "      <PDataArray type=\"Float64\" Name=\"von_mises\" NumberOfComponents=\"1\"/>\n"
               "      <PDataArray type=\"Float64\" Name=\"strain_energy_density\" "
               "NumberOfComponents=\"1\"/>\n");
  fprintf(f, "    </PCellData>\n"
             "    <PPoints>\n"
             "      <PDataArray type=\"Float64\" NumberOfComponents=\"3\"/>\n"
             "    </PPoints>\n");
  for (int r = 0; r < nprocs; r++)
    fprintf(f, "    <Piece Source=\"%s_%d.vtu\"/>\n", stem, r);
  fprintf(f, "  </PUnstructuredGrid>\n</VTKFile>\n");
  FCM_TRY(ctx, fcm_atomic_file_commit(&af));
cleanup:
  fcm_atomic_file_abort(&af);
  return st;
}

/* ---------------------------------------------------------------- embedded surface
 * (the points and their elements: surface.c) */

fcm_status fcm_embedded_surface_stress(const fcm_embedded_surface *es, const fcm_material *mat,
                                       const double *u, double *stress, double *von_mises,
                                       double *energy_density)
{
  fcm_status st = FCM_OK;
  stress_model m;
  FCM_CHECK(es && u, es ? es->ctx : NULL, FCM_ERR_ARG, "embedded surface: NULL surface or field");
  FCM_TRY(es->ctx, stress_model_setup(es->ctx, mat, &m));
  {
    const fcm_space *s = es->space;
    double X[3 * FCM_ELEMENT_MAX_NODES];
    fcm_index last = -1;
    for (fcm_index i = 0; i < es->np; i++) {
      double sig[6], vm, sed;
      const fcm_index c = s->elem_cell[es->elem[i]];
      if (c != last) fcm_mesh_cell_coords(s->mesh, c, X);
      last = c;
      point_stress(s, &m, es->elem[i], X, es->xi + 3 * i, u, sig, &vm, &sed);
      if (stress) memcpy(stress + 6 * i, sig, sizeof sig);
      if (von_mises) von_mises[i] = vm;
      if (energy_density) energy_density[i] = sed;
    }
  }
cleanup:
  return st;
}

fcm_status fcm_embedded_surface_write_vtu(const fcm_embedded_surface *es, const fcm_material *mat,
                                          const double *u, const char *path)
{
  return fcm__embedded_surface_write_vtu_counted(es, mat, u, path, NULL);
}

fcm_status fcm__embedded_surface_write_vtu_counted(const fcm_embedded_surface *es,
                                                   const fcm_material *mat, const double *u,
                                                   const char *path, fcm_index *nonfinite)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es ? es->ctx : NULL;
  fcm_vtu *vtu = NULL;
  double *d = NULL, *sig = NULL, *vm = NULL, *sed = NULL, *zero = NULL;
  if (nonfinite) *nonfinite = 0;
  FCM_CHECK(es && path, ctx, FCM_ERR_ARG, "embedded surface: write vtu: NULL surface or path");
  const fcm_index np = es->np;
  if (!u) {
    FCM_ALLOC(ctx, es->space->num_dofs + 1, zero);
    u = zero;
  }
  FCM_ALLOC(ctx, 3 * np + 1, d);
  FCM_TRY(ctx, fcm_embedded_surface_eval(es, u, d, NULL));
  FCM_TRY(ctx, fcm_vtu_create(ctx, &vtu));
  FCM_TRY(ctx, fcm_vtu_set_points(vtu, np, es->X));
  FCM_TRY(ctx, fcm_vtu_set_cells(vtu, FCM_VTK_TRIANGLE, es->nt, es->tri));
  FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "displacement", 3, np, d));
  FCM_TRY(ctx, fcm_vtu_add_field_int32(vtu, FCM_VTU_POINT_DATA, "cut_face", 1, np, es->flag));
  if (mat) {
    FCM_ALLOC(ctx, 6 * np + 1, sig);
    FCM_ALLOC(ctx, np + 1, vm);
    FCM_ALLOC(ctx, np + 1, sed);
    FCM_TRY(ctx, fcm_embedded_surface_stress(es, mat, u, sig, vm, sed));
    if (nonfinite) *nonfinite = count_nonfinite(np, vm);
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "stress", 6, np, sig));
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "von_mises", 1, np, vm));
    FCM_TRY(ctx, fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "strain_energy_density", 1, np, sed));
  }
  FCM_TRY(ctx, fcm_vtu_write(vtu, path, NULL));
cleanup:
  fcm_vtu_destroy(&vtu);
  void *arrays[] = {d, sig, vm, sed, zero};
  for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
    fcm__free(ctx, arrays[k]);
  return st;
}
