/* The PETSc backend's local topology (label mpi; 1, 2 and 3 processes): phase 1 builds its
 * space with fcm__space_create_local() for the own cells and their ghosts (the cells with an
 * element using a DOF copy the process owns). Asserted on every process, against the full
 * space fcm_space_create_embedded() builds from the same rules (or fcm_space_create() without
 * geometry):
 * - the numbering bit for bit: DOF count, active cells, node DOFs and copies, elements (cell,
 *   piece, DOFs), cell -> elements, constrained copies;
 * - the local elements are exactly those of the own and ghost cells; every owned copy is
 *   local, and its graph row and its three pattern rows (row_ptr lengths, col_idx) equal the
 *   full space's: the preallocation is that of the full pattern;
 * - every local row is a subset of the full row, every local element's offsets name its
 *   copies, the colours cover each local element once and no colour has two elements sharing a
 *   copy;
 * - the ghosts are needed: with the own cells alone (fcm__space_create_local() with that mask)
 *   some owned row is incomplete on some process when there are several (none on one);
 * - the assembled MATMPIAIJ (stiffness) has exactly the full pattern's entries in the owned
 *   rows, none allocated in vain;
 * - the whole-pattern function fcm_space_matrix_create() refuses the local space (FCM_ERR_ARG,
 *   "local space"); the workspace assembly takes it exactly when fcm__space_check_assemble()
 *   does (rules masked with the own cells, or every active cell local), else FCM_ERR_ARG;
 * - a frame (fcm_petsc_problem_write_frame(): the piece's node values scattered, not the whole
 *   state) is byte for byte the piece fcm__space_write_vtu_piece() writes from the gathered
 *   state, after a backward Euler step under gravity.
 * Arguments: element type, geometry (ball: a body with cut cells; none: the uncut box; cut:
 * cut_check() below, serial: phase 1 has no cuts, so its nodes have one copy each), output
 * directory. */
#include "fcm/fcm.h"
#include "fcm/petsc.h"
#include "petsc/petsc_impl.h"
#include "test_mpi.h"

#include <sys/stat.h>

static int same(const void *a, const void *b, size_t bytes)
{
  return bytes == 0 || memcmp(a, b, bytes) == 0;
}

static int cmp_idx(const void *a, const void *b)
{
  const fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

/* The local position of copy k in s (-1: not local). */
static fcm_index local_pos(const fcm_space *s, fcm_index k)
{
  if (!s->local_copy) return k;
  const fcm_index *hit = bsearch(&k, s->local_copy, (size_t)s->num_local_copies, sizeof k, cmp_idx);
  return hit ? hit - s->local_copy : -1;
}

/* Whether local row lk of l is full row k of f (graph and the three pattern rows). */
static int row_equal(const fcm_space *l, fcm_index lk, const fcm_space *f, fcm_index k)
{
  const fcm_index dl = l->node_ptr[lk + 1] - l->node_ptr[lk],
                  df = f->node_ptr[k + 1] - f->node_ptr[k];
  if (dl != df || !same(l->node_adj + l->node_ptr[lk], f->node_adj + f->node_ptr[k],
                        sizeof(fcm_index) * (size_t)dl))
    return 0;
  for (int i = 0; i < 3; i++) {
    const fcm_index rl = l->row_ptr[3 * lk + i], rf = f->row_ptr[3 * k + i];
    const fcm_index nl = l->row_ptr[3 * lk + i + 1] - rl, nf = f->row_ptr[3 * k + i + 1] - rf;
    if (nl != nf || !same(l->col_idx + rl, f->col_idx + rf, sizeof(int) * (size_t)nl)) return 0;
  }
  return 1;
}

/* The numbering of the local space l equals the full space f's, bit for bit. */
static void compare_numbering(const fcm_space *l, const fcm_space *f)
{
  TEST_TRUE(l->is_local && !f->is_local);
  TEST_TRUE(l->num_dofs == f->num_dofs && l->num_elems == f->num_elems &&
            l->num_cells == f->num_cells && l->num_nodes == f->num_nodes);
  TEST_TRUE(l->num_constrained == f->num_constrained);
  if (test_failures_) return;
  const size_t B = sizeof(fcm_index);
  TEST_TRUE(same(l->active, f->active, (size_t)f->num_cells));
  TEST_TRUE(same(l->node_dof, f->node_dof, B * (size_t)f->num_nodes));
  TEST_TRUE(same(l->node_ncopy, f->node_ncopy, B * (size_t)f->num_nodes));
  TEST_TRUE(same(l->cell_elem, f->cell_elem, B * (size_t)(f->num_cells + 1)));
  TEST_TRUE(same(l->elem_cell, f->elem_cell, B * (size_t)f->num_elems));
  TEST_TRUE(same(l->elem_piece, f->elem_piece, B * (size_t)f->num_elems));
  TEST_TRUE(same(l->elem_dof, f->elem_dof, B * (size_t)f->num_elems * (size_t)f->nn));
}

/* The local topology of l (flags cell_flag) against the full space f. */
static void check_topology(const fcm_space *l, const fcm_space *f, const unsigned char *cell_flag)
{
  const int nn = f->nn;
  /* local elements: those of the flagged active cells, ascending */
  fcm_index ne = 0;
  for (fcm_index c = 0; c < f->num_cells; c++)
    if (cell_flag[c] && f->active[c])
      for (fcm_index e = f->cell_elem[c]; e < f->cell_elem[c + 1]; e++) {
        TEST_TRUE(ne < l->num_local_elems && l->local_elem[ne] == e);
        ne++;
      }
  TEST_TRUE(ne == l->num_local_elems);
  if (test_failures_) return;
  /* every local row within the full row; offsets name the element's copies */
  for (fcm_index lk = 0; lk < l->num_local_copies; lk++) {
    const fcm_index k = l->local_copy[lk];
    TEST_TRUE(lk == 0 || l->local_copy[lk - 1] < k);
    for (fcm_index j = l->node_ptr[lk]; j < l->node_ptr[lk + 1]; j++) {
      const fcm_index m = l->node_adj[j];
      TEST_TRUE(bsearch(&m, f->node_adj + f->node_ptr[k],
                        (size_t)(f->node_ptr[k + 1] - f->node_ptr[k]), sizeof m, cmp_idx) != NULL);
    }
  }
  fcm_index *mark = calloc((size_t)l->num_local_copies + 1, sizeof *mark);
  unsigned char *seen = calloc((size_t)f->num_elems + 1, 1);
  TEST_TRUE(mark && seen);
  if (!mark || !seen) goto done;
  for (fcm_index le = 0; le < l->num_local_elems; le++) {
    const fcm_index *ed = l->elem_dof + l->local_elem[le] * nn;
    const int *off = l->elem_off + (size_t)le * nn * nn;
    for (int a = 0; a < nn; a++) {
      const fcm_index la = local_pos(l, ed[a] / 3);
      TEST_TRUE(la >= 0);
      if (la < 0) continue;
      for (int b = 0; b < nn; b++) {
        TEST_TRUE(l->node_adj[l->node_ptr[la] + off[a * nn + b]] == ed[b] / 3);
        for (int i = 0; i < 3; i++)
          TEST_TRUE(l->col_idx[l->row_ptr[3 * la + i] + 3 * off[a * nn + b]] == (int)ed[b]);
      }
    }
  }
  /* colours: each local element once; no two of a colour share a copy */
  for (fcm_index k = 0; k <= l->num_local_copies; k++)
    mark[k] = -1;
  TEST_TRUE(l->color_ptr[l->num_colors] == l->num_local_elems);
  for (int col = 0; col < l->num_colors; col++)
    for (fcm_index j = l->color_ptr[col]; j < l->color_ptr[col + 1]; j++) {
      const fcm_index e = l->local_elem[l->color_elems[j]]; /* colours hold local positions */
      TEST_TRUE(e >= 0 && e < f->num_elems && !seen[e] && cell_flag[f->elem_cell[e]]);
      if (e < 0 || e >= f->num_elems) continue;
      seen[e] = 1;
      for (int a = 0; a < nn; a++) {
        const fcm_index la = local_pos(l, l->elem_dof[e * nn + a] / 3);
        if (la < 0) continue;
        int dup = 0; /* the element itself may use a copy twice (constrained copies) */
        for (int b = 0; b < a; b++)
          dup |= l->elem_dof[e * nn + b] / 3 == l->elem_dof[e * nn + a] / 3;
        TEST_TRUE(dup || mark[la] != col);
        mark[la] = col;
      }
    }
done:
  free(mark);
  free(seen);
}

/* Owned copies whose local row differs from the full row (an owned copy not local counts). */
static fcm_index incomplete_rows(const fcm_petsc_problem *P, const fcm_space *l, const fcm_space *f)
{
  fcm_index bad = 0;
  for (fcm_index k = 0; k < P->ncopy; k++) {
    if (P->copy_owner[k] != P->rank) continue;
    const fcm_index lk = local_pos(l, k);
    bad += lk < 0 || !row_equal(l, lk, f, k);
  }
  return bad;
}

/* The whole bytes of a file (NULL on failure), its length in *len. */
static unsigned char *slurp(const char *path, size_t *len)
{
  FILE *fp = fopen(path, "rb");
  unsigned char *buf = NULL;
  *len = 0;
  if (!fp) return NULL;
  if (fseek(fp, 0, SEEK_END) == 0) {
    long n = ftell(fp);
    if (n >= 0 && fseek(fp, 0, SEEK_SET) == 0 && (buf = malloc((size_t)n + 1)) != NULL) {
      *len = fread(buf, 1, (size_t)n, fp);
      if (*len != (size_t)n) {
        free(buf);
        buf = NULL;
      }
    }
  }
  fclose(fp);
  return buf;
}

/* Without PETSc: a cut (fcm_cell_rules_create_cut(): pieces, several copies per node, the
 * constrained copies of fcm_space_create_embedded()) on the same cube, local spaces for the
 * cells of each third of the cell numbering (slabs), against the full space: numbering, topology,
 * and complete rows exactly for the local copies all of whose elements are local; a mask of every
 * cell gives the full space's topology array for array. */
static void cut_check(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom)
{
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_surface *cut = NULL;
  fcm_space *full = NULL, *l = NULL;
  unsigned char *mask = NULL;
  const fcm_cell_rules_options o = fcm_cell_rules_options_default();
  const fcm_space_options so = fcm_space_options_default();
  const double p[3] = {0.53, 0.5, 0.5}, nx[3] = {1, 0.1, -0.05}, bl[3] = {-0.1, 0.2, -0.1},
               bh[3] = {1.1, 1.1, 1.1}; /* a crack: the plane inside the box [bl, bh] only */
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, geom, &o, &r0));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nx, bl, bh, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, geom, r0, cut, &r1));
  TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, r1, &so, &full));
  if (!full) goto done;
  fcm_index split = 0;
  for (fcm_index a = 0; a < full->num_nodes; a++)
    split += full->node_ncopy[a] > 1;
  TEST_TRUE(split > 0); /* the case has nodes with several copies */
  mask = calloc((size_t)full->num_cells + 1, 1);
  TEST_TRUE(mask != NULL);
  if (!mask) goto done;
  for (int part = 0; part < 4; part++) { /* part 3: every cell */
    for (fcm_index c = 0; c < full->num_cells; c++)
      mask[c] = part == 3 || 3 * c / full->num_cells == part;
    TEST_OK(ctx, fcm__space_create_local(ctx, mesh, NULL, r1, &so, mask, &l));
    if (!l) break;
    compare_numbering(l, full);
    if (test_failures_) break;
    check_topology(l, full, mask);
    fcm_index complete = 0, expect = 0;
    for (fcm_index lk = 0; lk < l->num_local_copies; lk++) {
      const fcm_index k = l->local_copy[lk];
      int all_local = 1; /* every element using copy k is local */
      for (fcm_index e = 0; e < full->num_elems; e++)
        for (int a = 0; a < full->nn; a++)
          if (full->elem_dof[e * full->nn + a] / 3 == k && !mask[full->elem_cell[e]]) all_local = 0;
      expect += all_local;
      complete += all_local && row_equal(l, lk, full, k);
    }
    TEST_TRUE(complete == expect && expect > 0);
    if (part == 3) {
      const size_t I8 = sizeof(fcm_index), ncp = (size_t)full->num_dofs / 3;
      TEST_TRUE(l->num_local_copies == (fcm_index)ncp && l->num_local_elems == full->num_elems);
      TEST_TRUE(same(l->node_ptr, full->node_ptr, I8 * (ncp + 1)) &&
                same(l->node_adj, full->node_adj, I8 * (size_t)full->node_ptr[ncp]) &&
                same(l->row_ptr, full->row_ptr, I8 * (3 * ncp + 1)) &&
                same(l->col_idx, full->col_idx, sizeof(int) * (size_t)full->row_ptr[3 * ncp]) &&
                same(l->elem_off, full->elem_off,
                     sizeof(int) * (size_t)full->num_elems * (size_t)(full->nn * full->nn)) &&
                l->num_colors == full->num_colors &&
                same(l->color_ptr, full->color_ptr, I8 * (size_t)(full->num_colors + 1)) &&
                same(l->color_elems, full->color_elems, I8 * (size_t)full->num_elems));
    }
    fcm_space_destroy(&l);
  }
done:
  free(mask);
  fcm_space_destroy(&l);
  fcm_space_destroy(&full);
  fcm_surface_destroy(&cut);
  fcm_cell_rules_destroy(&r1);
  fcm_cell_rules_destroy(&r0);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_petsc_problem *P = NULL;
  fcm_space *full = NULL, *own = NULL;
  double *u = NULL, *v = NULL;
  unsigned char *own_mask = NULL, *local_mask = NULL;
  fcm_element_type type;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 4 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const char *shape = argv[2], *dir = argv[3];
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int quadratic = type == FCM_ELEMENT_HEX20 || type == FCM_ELEMENT_TET10;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n = quadratic ? 4 : 6, cells[3] = {n, n, n};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  if (strcmp(shape, "ball") == 0) {
    const double centre[3] = {0.52, 0.49, 0.47};
    TEST_OK(ctx, fcm_geometry_create_ball(ctx, centre, 0.41, 3, &geom));
  } else if (strcmp(shape, "cut") == 0) {
    const double glo[3] = {0.1, 0.12, 0.08}, ghi[3] = {0.9, 0.88, 0.91};
    const fcm_index gn[3] = {2, 2, 2};
    TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &geom));
    if (geom) cut_check(ctx, mesh, geom);
    goto done;
  } else if (strcmp(shape, "none") != 0) {
    return 2;
  }
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e6, 0.3, 1000.0};
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_BACKWARD_EULER; /* no constraint needed */
  po.dt = 1e-3;
  po.solver.rtol = 1e-10;
  TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P));
  if (!P) goto done;
  const fcm_space *l = P->space;
  /* the full space of the same rules (the numbering's input) */
  if (P->rules)
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, P->rules, &full));
  else
    TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &full));
  if (!full) goto done;
  compare_numbering(l, full);
  if (test_failures_) goto done;

  /* own and ghost cells */
  const fcm_index nc = full->num_cells;
  own_mask = calloc((size_t)nc + 1, 1);
  local_mask = calloc((size_t)nc + 1, 1);
  TEST_TRUE(own_mask && local_mask);
  if (!own_mask || !local_mask) goto done;
  fcm_index nghost = 0;
  for (fcm_index e = 0; e < full->num_elems; e++) {
    const fcm_index c = full->elem_cell[e];
    own_mask[c] = P->cell_owner[c] == rank;
    int flag = own_mask[c];
    for (int a = 0; a < full->nn; a++)
      flag |= P->copy_owner[full->elem_dof[e * full->nn + a] / 3] == rank;
    if (flag) local_mask[c] = 1;
  }
  for (fcm_index c = 0; c < nc; c++)
    nghost += local_mask[c] && !own_mask[c];
  check_topology(l, full, local_mask);
  fcm_index owned = 0;
  for (fcm_index k = 0; k < P->ncopy; k++)
    owned += P->copy_owner[k] == rank;
  TEST_TRUE(owned == (fcm_index)P->nlocal);
  TEST_TRUE(incomplete_rows(P, l, full) == 0);

  /* without the ghosts some owned row is incomplete (with several processes) */
  {
    const fcm_space_options so = fcm_space_options_default();
    TEST_OK(ctx, fcm__space_create_local(ctx, mesh, NULL, P->rules, P->rules ? &so : NULL, own_mask,
                                         &own));
    long long bad = own ? (long long)incomplete_rows(P, own, full) : -1, bad_all = 0;
    long long ghosts = (long long)nghost, ghosts_all = 0;
    MPI_Allreduce(&bad, &bad_all, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    MPI_Allreduce(&ghosts, &ghosts_all, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    TEST_TRUE(size == 1 ? bad_all == 0 && ghosts_all == 0 : bad_all > 0 && ghosts_all > 0);
  }

  /* the whole-pattern functions refuse the local space */
  {
    fcm_csr *A = NULL;
    TEST_TRUE(fcm_space_matrix_create(l, &A) == FCM_ERR_ARG && !A);
    TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "local space") != NULL);
    double *f = calloc((size_t)l->num_dofs + 1, sizeof *f);
    fcm_linear_form form = fcm_linear_form_default();
    const double g[3] = {0, 0, -9.81};
    form.material = &mat;
    form.term = FCM_LINEAR_BODY_FORCE;
    form.accel = g;
    const fcm_status want = (P->rules || size == 1) ? FCM_OK : FCM_ERR_ARG;
    TEST_TRUE(fcm__space_check_assemble(l, "ghost") == want);
    TEST_TRUE(f && fcm_assembly_workspace_linear(P->aws, &form, NULL, f) == want);
    if (want != FCM_OK) TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "local space") != NULL);
    free(f);
  }

  /* a step, then the assembled pattern and a frame */
  const double g[3] = {0.3, -0.2, -9.81};
  TEST_OK(ctx, fcm_petsc_problem_add_gravity(P, g));
  TEST_OK(ctx, fcm_petsc_problem_setup(P));
  TEST_OK(ctx, fcm_petsc_problem_step(P, NULL));
  if (test_failures_) goto done;
  {
    MatInfo mi;
    fcm_index expect = 0;
    for (fcm_index k = 0; k < P->ncopy; k++)
      if (P->copy_owner[k] == rank) expect += 9 * (full->node_ptr[k + 1] - full->node_ptr[k]);
    TEST_TRUE(MatGetInfo(P->K, MAT_LOCAL, &mi) == 0);
    TEST_TRUE(mi.nz_used == (double)expect && mi.nz_allocated == (double)expect &&
              mi.nz_unneeded == 0.0);
  }
  if (rank == 0) mkdir(dir, 0777);
  MPI_Barrier(MPI_COMM_WORLD);
  TEST_OK(ctx, fcm_petsc_problem_write_frame(P, dir, "ghost"));
  TEST_OK(ctx, fcm_petsc_problem_write_frame(P, dir, "ghost2")); /* the cached scatter */
  u = calloc((size_t)P->n + 1, sizeof *u);
  v = calloc((size_t)P->n + 1, sizeof *v);
  TEST_TRUE(u && v);
  if (!u || !v) goto done;
  TEST_OK(ctx, fcm_petsc_problem_get_state(P, u, v));
  {
    double umax = 0.0;
    for (fcm_index i = 0; i < P->n; i++)
      umax = fmax(umax, fabs(u[i]));
    TEST_TRUE(umax > 0.0 && isfinite(umax)); /* the frame shows a state that moved */
    char ref[4096], got[4096], got2[4096];
    snprintf(ref, sizeof ref, "%s/ref_%d.vtu", dir, rank);
    snprintf(got, sizeof got, "%s/ghost_%d.vtu", dir, rank);
    snprintf(got2, sizeof got2, "%s/ghost2_%d.vtu", dir, rank);
    TEST_OK(ctx, fcm__space_write_vtu_piece(l, NULL, u, v, own_mask, rank, ref, NULL));
    size_t nr = 0, ng = 0, ng2 = 0;
    unsigned char *br = slurp(ref, &nr), *bg = slurp(got, &ng), *bg2 = slurp(got2, &ng2);
    TEST_TRUE(br && bg && bg2 && nr > 0 && nr == ng && ng == ng2);
    TEST_TRUE(br && bg && bg2 && nr == ng && ng == ng2 && memcmp(br, bg, nr) == 0 &&
              memcmp(bg, bg2, ng) == 0);
    free(br);
    free(bg);
    free(bg2);
  }
done:
  free(u);
  free(v);
  free(own_mask);
  free(local_mask);
  fcm_space_destroy(&own);
  fcm_space_destroy(&full);
  fcm_petsc_problem_destroy(&P);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
