/* Multigrid on octree backgrounds (argument: hex8 or hex20, then the refinement depths, default
 * 1 2 3): static linear elasticity of the embedded hemisphere of mg_util.h (radius 1 on y = 0,
 * clamped there) on a 6 x 3 x 6 grid refined along its boundary to each depth, solved as the
 * integrators solve it: (P^T K P + I_h) u = P^T f with P the square hanging-node matrix (the
 * hanging DOFs decoupled identity rows). Checked: the hierarchy coarsens the octree level by
 * level (one level per refinement depth, each with fewer DOFs, then the uniform grid's levels),
 * its prolongations between octree levels are the exact nested interpolation (an affine field
 * on Hex8, a quadratic one on Hex20, reproduced to 1e-12 from the coarse free DOFs alone: the
 * coarse hanging DOFs never read; nothing to the fine hanging DOFs);
 * the V-cycle and the two-grid method contract (factor below 0.5 on Hex8, 0.6 on Hex20); CG +
 * V-cycle needs at most 1.5 x the iterations of the shallowest depth at every depth (flat), and
 * CG + Jacobi does not converge in 3 x those at the deepest; its
 * solution equals CHOLMOD's to the tolerance, with the hanging entries zero. The square matrix
 * K itself (not the constrained operator) is refused. Argument balls (then depths): two balls
 * on an octree and on the uniform grid of its finest cells (balls()). Arguments cut_hex8 and
 * cut_hex20 (then depths): the hemisphere cut through by a plane (cut_hemisphere()).
 * FCM_TEST_VERBOSE=1 prints the figures; FCM_TEST_MG_CYCLE=2 runs the two-body problems (balls,
 * cut_*) with the W-cycle instead. */
#include "mg/levels_impl.h"
#include "mg_util.h"

#include <math.h>
#include <stdio.h>

/* The field the nested prolongations reproduce: affine (Hex8), quadratic (Hex20), per
 * component c. */
static double field(const double *x, int c, int quadratic)
{
  const double a = 1.0 + 0.5 * c + 2.0 * x[0] - x[1] + 0.5 * x[2];
  return quadratic ? a + x[0] * x[0] - 0.7 * x[1] * x[2] + 0.3 * x[2] * x[2] : a;
}

/* The DOF positions of a space (3 per DOF: its node's). */
static double *dof_positions(const fcm_space *sp)
{
  const fcm_mesh *mesh = fcm_space_mesh(sp);
  const double *coords = fcm_mesh_coords(mesh);
  double *X = calloc(3 * (size_t)fcm_space_num_dofs(sp) + 1, sizeof *X);
  for (fcm_index v = 0; v < fcm_mesh_num_nodes(mesh); v++) {
    const fcm_index d0 = fcm_space_node_dof(sp, v);
    for (int c = 0; d0 >= 0 && c < 3; c++)
      memcpy(X + 3 * (d0 + c), coords + 3 * v, 3 * sizeof *X);
  }
  return X;
}

/* The prolongations of the octree levels (the truncations of the octree until it is uniform:
 * the 2:1 balance may make it uniform above level 0) reproduce the field: P_l u_{l+1} =
 * u_l on the free fine DOFs, and 0 on the hanging ones (no correction there). The coarse hanging
 * DOFs take a value far off the field, which a prolongation must not read (it reads their
 * masters). */
static void check_nested(fcm_ctx *ctx, const oct_problem *p, const fcm_mg *mg, int depth,
                         int quadratic)
{
  double err = 0.0, hang = 0.0;
  int noct = 0;
  for (int l = 0; l < depth && l + 1 < fcm_mg_num_levels(mg); l++) {
    const mg_level *F = &mg->lev[l], *C = &mg->lev[l + 1];
    const fcm_space *sf = l == 0 ? p->space : F->sp;
    if (!sf || !C->sp) break; /* the box-grid levels of a uniform truncation */
    TEST_TRUE(fcm_mesh_max_level(fcm_space_mesh(C->sp)) == depth - l - 1);
    noct++;
    fcm_index *cfree = calloc((size_t)C->n + 1, sizeof *cfree);
    fcm_index *ffree = calloc((size_t)F->n + 1, sizeof *ffree);
    fcm_csr *T = NULL;
    TEST_OK(ctx, fcm_space_hanging_matrix_create(C->sp, cfree, &T));
    fcm_csr_destroy(&T);
    TEST_OK(ctx, fcm_space_hanging_matrix_create(sf, ffree, &T));
    fcm_csr_destroy(&T);
    double *X = dof_positions(sf), *Xc = dof_positions(C->sp);
    double *uc = calloc((size_t)C->n + 1, sizeof *uc);
    for (fcm_index J = 0; J < C->n; J++)
      uc[J] = cfree[J] >= 0 ? field(Xc + 3 * J, (int)(J % 3), quadratic) : 1e3;
    for (fcm_index i = 0; i < F->n; i++) {
      double s = 0.0;
      for (fcm_index q = F->P_ptr[i]; q < F->P_ptr[i + 1]; q++)
        s += F->P_val[q] * uc[F->P_col[q]];
      if (ffree[i] < 0)
        hang = fmax(hang, fabs(s));
      else
        err = fmax(err, fabs(s - field(X + 3 * i, (int)(i % 3), quadratic)));
    }
    free(X), free(Xc), free(uc), free(cfree), free(ffree);
  }
  TEST_TRUE(noct >= 1);
  TEST_TRUE(err <= 1e-12);
  TEST_TRUE(hang == 0.0);
}

/* The prolongations between the octree levels of a hierarchy with separated bodies reproduce
 * each body's field (the field plus 3 x its body: the bodies differ) on the fine copies of
 * that body to 1e-12 from the coarse copies of that body, and nothing goes to the fine hanging
 * copies; every level holds both bodies. */
static void check_bodies(fcm_ctx *ctx, const fcm_space *space, const fcm_mg *mg, int quadratic)
{
  double err = 0.0, hang = 0.0;
  int noct = 0;
  fcm_index *free0 = calloc((size_t)fcm_space_num_dofs(space) + 1, sizeof *free0);
  fcm_csr *T = NULL;
  TEST_OK(ctx, fcm_space_hanging_matrix_create(space, free0, &T));
  fcm_csr_destroy(&T);
  for (int l = 0; l + 1 < fcm_mg_num_levels(mg); l++) {
    const mg_level *F = &mg->lev[l], *C = &mg->lev[l + 1];
    if (!F->oct_node || !C->oct_node) break;
    noct++;
    const double *Xf = fcm_mesh_coords(fcm_space_mesh(l == 0 ? space : F->sp));
    const double *Xc = fcm_mesh_coords(fcm_space_mesh(C->sp));
    double *uc = calloc((size_t)C->n + 1, sizeof *uc);
    for (fcm_index J = 0; J < C->n; J++)
      uc[J] =
          field(Xc + 3 * C->oct_node[J / 3], (int)(J % 3), quadratic) + 3.0 * C->oct_body[J / 3];
    for (fcm_index i = 0; i < F->n; i++) {
      double s = 0.0;
      for (fcm_index q = F->P_ptr[i]; q < F->P_ptr[i + 1]; q++)
        s += F->P_val[q] * uc[F->P_col[q]];
      if (l == 0 && free0[i] < 0)
        hang = fmax(hang, fabs(s));
      else
        err = fmax(err, fabs(s - field(Xf + 3 * F->oct_node[i / 3], (int)(i % 3), quadratic) -
                             3.0 * F->oct_body[i / 3]));
    }
    free(uc);
  }
  for (int l = 0; l < fcm_mg_num_levels(mg); l++) {
    fcm_mg_level_info li;
    TEST_OK(ctx, fcm_mg_get_level_info(mg, l, &li));
    TEST_TRUE(li.bodies == 2);
  }
  free(free0);
  TEST_TRUE(noct >= 1);
  TEST_TRUE(err <= 1e-12);
  TEST_TRUE(hang == 0.0);
}

/* The V-cycle's and the two-grid method's (the first coarsening solved exactly) mean factors
 * per cycle on A x = b. */
static void factors(fcm_ctx *ctx, const fcm_space *space, const fcm_csr *A, const double *b,
                    fcm_index n, const fcm_mg *mg, const fcm_mg_options *o, double f[2])
{
  double *x = calloc((size_t)n + 1, sizeof *x);
  fcm_mg_solve_info si;
  fcm_mg *mg2 = NULL;
  TEST_OK(ctx, fcm_mg_solve((fcm_mg *)mg, b, x, 1e-8, 200, &si));
  f[0] = si.convergence_factor;
  fcm_mg_options o2 = *o;
  o2.max_levels = 2;
  TEST_OK(ctx, fcm_mg_create(ctx, space, A, &o2, &mg2));
  memset(x, 0, sizeof *x * (size_t)n);
  if (mg2) TEST_OK(ctx, fcm_mg_solve(mg2, b, x, 1e-8, 200, &si));
  f[1] = si.convergence_factor;
  fcm_mg_destroy(&mg2);
  free(x);
}

/* CG + V-cycle on A x = b (rtol 1e-10) equal to CHOLMOD's solution (1e-7); the iterations, and
 * the bodies of level 0 and of the coarsest level. With cut >= 0 (a cut space; 1: Hex20) the
 * prolongations and bodies are checked (check_bodies()), and with f the factors measured. */
static int cg_mg(fcm_ctx *ctx, const fcm_space *space, const fcm_csr *A, const double *b,
                 fcm_index n, fcm_index bodies[2], int cut, double *f)
{
  fcm_mg_options o = fcm_mg_options_default();
  o.coarse_dofs = 50;
  o.cycle_index = getenv("FCM_TEST_MG_CYCLE") ? atoi(getenv("FCM_TEST_MG_CYCLE")) : 1;
  fcm_mg *mg = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, space, A, &o, &mg));
  if (!mg) return -1;
  if (cut >= 0) check_bodies(ctx, space, mg, cut);
  if (f) factors(ctx, space, A, b, n, mg, &o, f);
  double *x = calloc((size_t)n + 1, sizeof *x), *xd = calloc((size_t)n + 1, sizeof *xd);
  fcm_krylov_options ko = fcm_krylov_options_default();
  ko.rtol = 1e-10;
  ko.max_iterations = 5000;
  fcm_krylov_info ki;
  TEST_OK(ctx,
          fcm_cg_solve(ctx, n, fcm_csr_operator, (void *)A, fcm_mg_operator, mg, b, x, &ko, &ki));
  direct_solve(ctx, A, b, xd);
  double dn = 0.0, xn = 0.0;
  for (fcm_index i = 0; i < n; i++)
    dn += (x[i] - xd[i]) * (x[i] - xd[i]), xn += xd[i] * xd[i];
  TEST_TRUE(sqrt(dn) <= 1e-7 * sqrt(xn));
  fcm_mg_level_info li;
  TEST_OK(ctx, fcm_mg_get_level_info(mg, 0, &li));
  bodies[0] = li.bodies;
  TEST_OK(ctx, fcm_mg_get_level_info(mg, fcm_mg_num_levels(mg) - 1, &li));
  bodies[1] = li.bodies;
  free(x), free(xd);
  fcm_mg_destroy(&mg);
  return ki.iterations;
}

/* Two balls of radius 0.3, 0.3 apart, in [0, 2] x [0, 1]^2 (K + M): on the octree over the
 * 4 x 2 x 2 grid refined along their boundaries to each depth, and on the uniform grid of the
 * same finest cells. Both solve to CHOLMOD's solution and the fine spaces hold two bodies; the
 * box-grid hierarchy keeps them apart on every level, the octree's coarser octrees join them
 * (one DOF per node), which costs iterations (lib/docs/octree.md). */
static void balls(fcm_ctx *ctx, const int *depths, int nd, int verbose)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  const double c1[3] = {0.55, 0.5, 0.5}, c2[3] = {1.45, 0.5, 0.5};
  const fcm_index base[3] = {4, 2, 2};
  for (int s = 0; s < nd; s++) {
    oct_problem p;
    problem q;
    fcm_index bo[2] = {0, 0}, bu[2] = {0, 0};
    memset(&p, 0, sizeof p);
    two_balls(ctx, c1, c2, &p.geom);
    oct_problem_embed(ctx, FCM_ELEMENT_HEX8, lo, hi, base, depths[s], &p);
    oct_problem_assemble(ctx, &p, 1);
    const int it_oct = cg_mg(ctx, p.space, p.A, p.b, p.n, bo, -1, NULL);
    memset(&q, 0, sizeof q);
    const fcm_index cells[3] = {base[0] << depths[s], base[1] << depths[s], base[2] << depths[s]};
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &q.mesh));
    two_balls(ctx, c1, c2, &q.geom);
    fcm_cell_rules_options ro = fcm_cell_rules_options_default();
    ro.simplify = FCM_CELL_SIMPLIFY_OFF;
    TEST_OK(ctx, fcm_cell_rules_create(ctx, q.mesh, q.geom, &ro, &q.rules0));
    TEST_OK(ctx, fcm_space_create_embedded(ctx, q.mesh, q.rules0, &q.space));
    finish_space(ctx, &q, 1);
    const int it_uni = cg_mg(ctx, q.space, q.A, q.b, q.n, bu, -1, NULL);
    TEST_TRUE(bo[0] == 2 && bu[0] == 2 && bu[1] == 2);
    if (verbose)
      printf("two balls, depth %d: octree %lld DOFs, CG+MG %d, bodies %lld on level 0, %lld on "
             "the coarsest; uniform grid %lld DOFs, CG+MG %d, bodies %lld, %lld\n",
             depths[s], (long long)p.n, it_oct, (long long)bo[0], (long long)bo[1], (long long)q.n,
             it_uni, (long long)bu[0], (long long)bu[1]);
    oct_free(&p);
    problem_free(&q);
  }
}

/* The hemisphere of oct_problem_create() cut through by a plane across its clamped face (two
 * bodies, each clamped; the plane leaves slivers in cells of every level): the multigrid on
 * the cut octree space (copies of hanging nodes per material component on level 0, a copy per
 * node and body on the coarser octrees) converges to CHOLMOD's solution, holds the two bodies
 * apart on every level, its prolongations reproduce each body's field (affine on Hex8,
 * quadratic on Hex20) from that body's coarse copies, and CG + V-cycle needs at most 1.5 x the
 * iterations of the shallowest depth at every depth (flat); the iterations per depth go to
 * *its. */
static void cut_hemisphere(fcm_ctx *ctx, fcm_element_type type, const int *depths, int nd,
                           int verbose, int *its)
{
  const double lo[3] = {-1.1, 0, -1.1}, hi[3] = {1.1, 1.1, 1.1}, c[3] = {0, 0, 0};
  const double pp[3] = {0.07, 0.5, 0.03}, pn[3] = {1.0, 0.0, 0.15};
  const double clo[3] = {-1.5, -0.5, -1.5}, chi[3] = {1.5, 1.5, 1.5};
  const fcm_index cells[3] = {6, 3, 6};
  for (int s = 0; s < nd; s++) {
    oct_problem p;
    fcm_surface *cut = NULL;
    fcm_cell_rules *rc = NULL;
    fcm_index bodies[2] = {0, 0};
    memset(&p, 0, sizeof p);
    TEST_OK(ctx, fcm_geometry_create_hemisphere(ctx, c, 1.0, 4, &p.geom));
    oct_problem_embed(ctx, type, lo, hi, cells, depths[s], &p);
    TEST_OK(ctx, fcm_surface_create_plane(ctx, pp, pn, clo, chi, &cut));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, p.mesh, p.geom, p.rules, cut, &rc));
    fcm_space_destroy(&p.space);
    fcm_cell_rules_destroy(&p.rules);
    p.rules = rc;
    TEST_OK(ctx, fcm_space_create_embedded(ctx, p.mesh, p.rules, &p.space));
    TEST_TRUE(fcm_space_num_bodies(p.space) == 2);
    oct_problem_assemble(ctx, &p, 0);
    /* clamp every free copy on y = 0 (both bodies) */
    const double flo[3] = {-2, 0, -2}, fhi[3] = {2, 0, 2};
    fcm_index cnt = 0, ndof = 0;
    TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, p.mesh, flo, fhi, 1e-9, 0, NULL, &cnt));
    fcm_index *nodes = calloc((size_t)cnt + 1, sizeof *nodes);
    fcm_index *dofs = calloc(6 * (size_t)cnt + 1, sizeof *dofs);
    TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, p.mesh, flo, fhi, 1e-9, cnt, nodes, &cnt));
    for (fcm_index i = 0; i < cnt; i++) {
      const fcm_index d0 = fcm_space_node_dof(p.space, nodes[i]);
      for (fcm_index d = 0; d0 >= 0 && d < 3 * fcm_space_node_copies(p.space, nodes[i]); d++)
        if (p.free_dof[d0 + d] >= 0 && ndof < 6 * cnt) dofs[ndof++] = d0 + d;
    }
    TEST_OK(ctx, fcm_space_apply_dirichlet(p.space, ndof, dofs, NULL, p.A, p.b));
    double f[2] = {0.0, 0.0};
    its[s] =
        cg_mg(ctx, p.space, p.A, p.b, p.n, bodies, type == FCM_ELEMENT_HEX20, verbose ? f : NULL);
    TEST_TRUE(its[s] > 0 && bodies[0] == 2 && bodies[1] == 2);
    TEST_TRUE(its[s] <= 1.5 * its[0]);
    if (verbose)
      printf("cut hemisphere, %s, depth %d: %lld DOFs, %lld hanging pairs, %s %.3f, "
             "two-grid %.3f, CG+MG %d\n",
             type == FCM_ELEMENT_HEX20 ? "hex20" : "hex8", depths[s], (long long)p.n,
             (long long)fcm_mesh_num_hanging(p.mesh),
             getenv("FCM_TEST_MG_CYCLE") ? "cycle" : "V-cycle", f[0], f[1], its[s]);
    free(nodes), free(dofs);
    fcm_surface_destroy(&cut);
    oct_free(&p);
  }
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_element_type type = FCM_ELEMENT_HEX8;
  const int two = argc >= 2 && !strcmp(argv[1], "balls");
  const int cut = argc >= 2 && !strncmp(argv[1], "cut_", 4);
  if (argc < 2 || (!two && fcm_element_type_from_name(argv[1] + (cut ? 4 : 0), &type) != FCM_OK))
    return 2;
  int depths[8] = {1, 2, 3}, nd = 3;
  if (argc > 2) {
    nd = 0;
    for (int a = 2; a < argc && nd < 8; a++)
      depths[nd++] = atoi(argv[a]);
  }
  const int verbose = getenv("FCM_TEST_VERBOSE") != NULL;
  /* measured 0.09-0.13 on Hex8, 0.47-0.50 on Hex20 (depths 1-3 and 1-2) */
  const double bound = type == FCM_ELEMENT_HEX20 ? 0.6 : 0.5;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (two) {
    balls(ctx, depths, nd, verbose);
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    fcm_ctx_destroy(&ctx);
    return TEST_RESULT();
  }
  if (cut) {
    int its[8] = {0};
    cut_hemisphere(ctx, type, depths, nd, verbose, its);
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    fcm_ctx_destroy(&ctx);
    return TEST_RESULT();
  }
  int it_mg[8] = {0};
  for (int s = 0; s < nd; s++) {
    oct_problem p;
    oct_problem_create(ctx, type, 6, depths[s], &p);
    fcm_mg_options o = fcm_mg_options_default();
    o.coarse_dofs = 50; /* coarsen as far as the grids allow */
    o.cycle_index = 1;  /* V-cycle */
    fcm_mg *mg = NULL, *mg2 = NULL;
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o, &mg));
    if (!mg) {
      oct_free(&p);
      break;
    }
    check_nested(ctx, &p, mg, depths[s], type == FCM_ELEMENT_HEX20);
    /* one octree level per depth (each smaller), then the uniform grid's */
    const int nl = fcm_mg_num_levels(mg);
    TEST_TRUE(nl >= depths[s] + 2);
    fcm_index prev = p.n + 1;
    for (int l = 0; l < nl; l++) {
      fcm_mg_level_info li;
      TEST_OK(ctx, fcm_mg_get_level_info(mg, l, &li));
      TEST_TRUE(li.dofs < prev);
      prev = li.dofs;
      if (verbose)
        printf("  level %d: cells %lld dofs %lld nnz %lld bodies %lld\n", l, (long long)li.cells,
               (long long)li.dofs, (long long)li.nnz, (long long)li.bodies);
    }
    double *x = calloc((size_t)p.n + 1, sizeof *x), *xd = calloc((size_t)p.n + 1, sizeof *xd);
    fcm_mg_solve_info si, si2;
    TEST_OK(ctx, fcm_mg_solve(mg, p.b, x, 1e-8, 200, &si));
    TEST_TRUE(si.convergence_factor < bound);
    /* the two-grid method: the first octree coarsening solved exactly */
    fcm_mg_options o2 = o;
    o2.max_levels = 2;
    TEST_OK(ctx, fcm_mg_create(ctx, p.space, p.A, &o2, &mg2));
    memset(x, 0, sizeof *x * (size_t)p.n);
    if (mg2) TEST_OK(ctx, fcm_mg_solve(mg2, p.b, x, 1e-8, 200, &si2));
    TEST_TRUE(si2.convergence_factor < bound);
    fcm_mg_destroy(&mg2);
    /* CG + V-cycle against CHOLMOD */
    direct_solve(ctx, p.A, p.b, xd);
    fcm_krylov_options ko = fcm_krylov_options_default();
    ko.rtol = 1e-10;
    ko.max_iterations = 5000;
    fcm_krylov_info ki;
    memset(x, 0, sizeof *x * (size_t)p.n);
    TEST_OK(ctx,
            fcm_cg_solve(ctx, p.n, fcm_csr_operator, p.A, fcm_mg_operator, mg, p.b, x, &ko, &ki));
    it_mg[s] = ki.iterations;
    double dn = 0.0, xn = 0.0, hang = 0.0;
    for (fcm_index i = 0; i < p.n; i++) {
      dn += (x[i] - xd[i]) * (x[i] - xd[i]), xn += xd[i] * xd[i];
      if (p.free_dof[i] < 0) hang = fmax(hang, fabs(x[i]));
    }
    TEST_TRUE(sqrt(dn) <= 1e-7 * sqrt(xn));
    TEST_TRUE(hang <= 1e-14 * sqrt(xn));
    if (s == nd - 1) {
      /* CG + Jacobi does not converge in 3 x the iterations */
      fcm_jacobi *J = NULL;
      TEST_OK(ctx, fcm_jacobi_create(ctx, p.A, FCM_JACOBI_SCALAR, &J));
      memset(x, 0, sizeof *x * (size_t)p.n);
      ko.max_iterations = 3 * it_mg[s];
      TEST_TRUE(fcm_cg_solve(ctx, p.n, fcm_csr_operator, p.A, fcm_jacobi_operator, J, p.b, x, &ko,
                             &ki) == FCM_ERR_NOT_CONVERGED);
      fcm_ctx_error_clear(ctx);
      fcm_jacobi_destroy(&J);
      /* K is not the constrained operator: refused, naming the hanging row */
      TEST_ERR(ctx, fcm_mg_create(ctx, p.space, p.K, &o, &mg2), FCM_ERR_ARG, "hanging DOF");
    }
    if (verbose)
      printf("%s depth %d: %lld DOFs, %lld hanging pairs, %d levels: V-cycle %.3f, two-grid "
             "%.3f, CG+MG %d iterations (rtol 1e-10)\n",
             argv[1], depths[s], (long long)p.n, (long long)fcm_mesh_num_hanging(p.mesh), nl,
             si.convergence_factor, si2.convergence_factor, it_mg[s]);
    free(x);
    free(xd);
    fcm_mg_destroy(&mg);
    oct_free(&p);
  }
  for (int s = 1; s < nd; s++)
    TEST_TRUE(it_mg[s] <= 1.5 * it_mg[0]);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
