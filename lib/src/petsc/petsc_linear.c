/* petsc module: the linear driver (fcm_petsc_problem_*): creation, gravity and node
 * constraints, the assembly into a MATMPIAIJ, the KSP setup from the options database, the
 * static and backward Euler steps, and its queries. */
#include "petsc/petsc_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static fcm_status check_inputs(fcm_petsc_problem *P, const fcm_petsc_options *o)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  FCM_TRY(ctx, fcm_material_validate(ctx, &P->mat));
  FCM_CHECK(P->mat.model == FCM_MATERIAL_LINEAR, ctx, FCM_ERR_UNSUPPORTED,
            "petsc: material model %d: the PETSc backend solves linear elasticity only (model "
            "linear); use the serial backend for hyperelastic materials",
            (int)P->mat.model);
  FCM_CHECK(o->kind == FCM_INTEGRATOR_STATIC || o->kind == FCM_INTEGRATOR_BACKWARD_EULER, ctx,
            FCM_ERR_ARG, "petsc: kind = %d is neither static (0) nor backward Euler (1)",
            (int)o->kind);
  FCM_CHECK(isfinite(o->dt) && o->dt > 0.0, ctx, FCM_ERR_ARG, "petsc: dt = %g must be > 0", o->dt);
  FCM_CHECK(o->rules.simplify != FCM_CELL_SIMPLIFY_AUTO, ctx, FCM_ERR_UNSUPPORTED,
            "petsc: rules.simplify = auto is not supported (the choice would differ between "
            "processes); use on or off");
cleanup:
  return st;
}

/* The start of both creators: after their local argument checks (st), allocate the problem
 * (*out, also when the processes then fail: its ctx, comm and single reference set for the
 * destroy), agree on st and the allocation before the first collective call, so bad input or
 * a failed allocation on one process ends them all, then duplicate comm. Collective. */
fcm_status fcm__petsc_new_problem(fcm_ctx *ctx, MPI_Comm comm, fcm_status st,
                                  fcm_petsc_problem **out)
{
  fcm_petsc_problem *P = NULL;
  if (st == FCM_OK) {
    P = fcm__calloc(ctx, 1, sizeof *P);
    if (!P)
      st = fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__, "petsc: out of memory");
  }
  if (P) {
    P->ctx = ctx;
    P->comm = MPI_COMM_NULL;
    P->refs = 1;
  }
  *out = P;
  FCM_TRY(ctx, fcm__petsc_agree(ctx, comm, st));
  if (MPI_Comm_dup(comm, &P->comm) != MPI_SUCCESS) {
    P->comm = MPI_COMM_NULL;
    FCM_CHECK(0, ctx, FCM_ERR_ARG, "petsc: MPI_Comm_dup failed (invalid communicator?)");
  }
  MPI_Comm_size(P->comm, &P->size);
  MPI_Comm_rank(P->comm, &P->rank);
cleanup:
  return st;
}

fcm_status fcm_petsc_problem_create(fcm_ctx *ctx, MPI_Comm comm, const fcm_mesh *mesh,
                                    const fcm_geometry *geom, const fcm_material *mat,
                                    const fcm_petsc_options *opts, fcm_petsc_problem **out)
{
  fcm_status st = FCM_OK;
  fcm_petsc_problem *P = NULL;
  unsigned char *mask = NULL;
  fcm_geometry *crop = NULL;
  const double t0 = fcm_wtime();
  /* local checks, agreed in fcm__petsc_new_problem() before the first collective call */
  if (!out)
    st =
        fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__, "petsc: output pointer is NULL");
  else
    *out = NULL;
  if (st == FCM_OK && !(ctx && mesh && mat))
    st = fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "petsc: NULL argument (ctx, mesh, material)");
  FCM_TRY(ctx, fcm__petsc_new_problem(ctx, comm, st, &P));
  P->mesh = mesh;
  P->mat = *mat;
  P->opts = opts ? *opts : fcm_petsc_options_default();
  fcm__petsc_set_prefix(P);
  st = check_inputs(P, &P->opts);
  const fcm_petsc_solver_options solver = P->opts.solver;
  if (st == FCM_OK) st = fcm__petsc_adopt_solver(P, &solver);
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));

  /* 1., 2. the candidate cells and their partition */
  const double tr = fcm_wtime();
  FCM_TRY(ctx, fcm__petsc_partition_cells(P, geom, &mask));

  /* 3. the rules, with points on this process's cells only (each cell is classified by one
   * process, the classes gathered on every process), from the part of the geometry they read
   * (the crop), and the space; candidates the rules drop own nothing */
  FCM_TRY(ctx, fcm__petsc_problem_agree(P, fcm__petsc_crop_geometry(P, geom, mask, &crop)));
  st = fcm__petsc_build_space(P, crop ? crop : geom, mask);
  fcm_geometry_destroy(&crop);
  if (st == FCM_OK) st = fcm__petsc_own_active_cells(P);
  FCM_TRY(ctx, P->agreed_fail
                   ? st
                   : fcm__petsc_problem_agree(P, st)); /* the exchange agreed on a failure */
  FCM_FREE(ctx, P->classifier);
  FCM_FREE(ctx, P->remote);
  P->time_rules = fcm_wtime() - tr;
  st = fcm_assembly_workspace_create(P->space, &P->opts.assembly, &P->aws);
  if (st == FCM_OK) st = fcm__petsc_number_dofs(P);
  if (st == FCM_OK) st = fcm__petsc_localize_space(P);
  if (st == FCM_OK) {
    P->is_con = fcm__calloc(ctx, (size_t)P->n + 1, 1);
    if (!P->is_con) st = FCM_ERR_ALLOC;
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));

  /* 4. matrices and vectors (collective) */
  st = fcm__petsc_create_matrix(P, &P->K);
  if (st == FCM_OK && P->opts.kind == FCM_INTEGRATOR_BACKWARD_EULER)
    st = fcm__petsc_create_matrix(P, &P->M);
  if (st == FCM_OK) st = fcm__petsc_create_vectors(P);
  FCM_TRY(ctx, P->agreed_fail ? st : fcm__petsc_problem_agree(P, st)); /* agreed already */
  P->time_setup = fcm_wtime() - t0;
  *out = P;
  P = NULL;
cleanup:
  fcm__free(ctx, mask);
  fcm_geometry_destroy(&crop);
  fcm_petsc_problem_destroy(&P);
  return st;
}

void fcm_petsc_problem_destroy(fcm_petsc_problem **problem)
{
  if (!problem || !*problem) return;
  fcm_petsc_problem *P = *problem;
  fcm_ctx *ctx = P->ctx;
  KSPDestroy(&P->ksp);
  Mat *ms[] = {&P->K, &P->M, &P->S, &P->Se};
  for (size_t i = 0; i < sizeof ms / sizeof ms[0]; i++)
    MatDestroy(ms[i]);
  Vec *vs[] = {&P->f, &P->u, &P->v, &P->b, &P->x, &P->g, &P->w};
  for (size_t i = 0; i < sizeof vs / sizeof vs[0]; i++)
    VecDestroy(vs[i]);
  PetscFree(P->rows);
  VecScatterDestroy(&P->to_all);
  VecDestroy(&P->all);
  VecScatterDestroy(&P->frame_sc);
  VecDestroy(&P->frame_vec);
  fcm__free(ctx, P->frame_nodes);
  fcm_assembly_workspace_destroy(&P->aws);
  if (!P->borrowed_space) fcm_space_destroy(&P->space);
  fcm_cell_rules_destroy(&P->rules);
  void *arrays[] = {P->petsc_options, P->weight,     P->cell_owner, P->copy_owner,
                    P->perm,          P->con_dof,    P->con_node,   P->con_comp,
                    P->con_motion,    P->motions,    P->is_con,     P->classifier,
                    P->remote,        P->kept_cells, P->kept_tris,  P->owned_dof};
  for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
    fcm__free(ctx, arrays[i]);
  if (P->comm != MPI_COMM_NULL) MPI_Comm_free(&P->comm);
  fcm_geometry_destroy(&P->own_geom);
  fcm_mesh_destroy(&P->own_mesh);
  fcm__free(ctx, P);
  *problem = NULL;
}

/* ---------------------------------------------------------------- configuration */

fcm_status fcm_petsc_problem_add_gravity(fcm_petsc_problem *P, const double accel[3])
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  if (P->is_setup)
    st = fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "petsc: add_gravity after setup");
  else if (!accel || !isfinite(accel[0]) || !isfinite(accel[1]) || !isfinite(accel[2]))
    st = fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                    "petsc: gravity acceleration is NULL or not finite");
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  for (int i = 0; i < 3; i++)
    P->gravity[i] += accel[i];
  P->has_gravity = 1;
cleanup:
  return st;
}

static int finite3(const double x[3])
{
  return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]);
}

/* Check a constraint (local, no change). */
static fcm_status check_constraint(fcm_petsc_problem *P, fcm_index num_nodes,
                                   const fcm_index *nodes, const fcm_motion *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  FCM_CHECK(!P->is_setup, ctx, FCM_ERR_ARG, "petsc: add_constraint after setup");
  FCM_CHECK(m && num_nodes >= 0 && (num_nodes == 0 || nodes), ctx, FCM_ERR_ARG,
            "petsc: constraint: NULL motion or nodes, or num_nodes = %lld < 0",
            (long long)num_nodes);
  FCM_CHECK(finite3(m->velocity) && finite3(m->center) && finite3(m->axis) &&
                isfinite(m->angular_speed) && isfinite(m->start) && !isnan(m->end) &&
                m->end >= m->start,
            ctx, FCM_ERR_ARG, "petsc: constraint: motion with a non-finite member or end < start");
  FCM_CHECK(!m->release, ctx, FCM_ERR_UNSUPPORTED,
            "petsc: constraint: release (a constraint set that changes in time) is not "
            "supported by the PETSc backend");
  for (fcm_index k = 0; k < num_nodes; k++) {
    FCM_CHECK(nodes[k] >= 0 && nodes[k] < s->num_nodes, ctx, FCM_ERR_ARG,
              "petsc: constraint: node %lld (entry %lld) outside [0, %lld)", (long long)nodes[k],
              (long long)k, (long long)s->num_nodes);
    for (fcm_index c = 0; c < s->node_ncopy[nodes[k]]; c++)
      for (int i = 0; i < 3; i++)
        FCM_CHECK(!m->components[i] || !P->is_con[s->node_dof[nodes[k]] + 3 * c + i], ctx,
                  FCM_ERR_ARG,
                  "petsc: constraint %d: component %d of node %lld is constrained already (by "
                  "constraint %d); a DOF may belong to one constraint only",
                  P->num_motions, i, (long long)nodes[k],
                  (int)P->is_con[s->node_dof[nodes[k]] + 3 * c + i] - 1);
  }
cleanup:
  return st;
}

/* Add a validated constraint (local; only allocation can fail). */
static fcm_status apply_constraint(fcm_petsc_problem *P, fcm_index num_nodes,
                                   const fcm_index *nodes, const fcm_motion *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  fcm_index add = 0;
  for (fcm_index k = 0; k < num_nodes; k++)
    add += 3 * s->node_ncopy[nodes[k]];
  FCM_CHECK(fcm__resize(ctx, (void **)&P->motions, (size_t)P->num_motions,
                        (size_t)P->num_motions + 1, sizeof *P->motions) == FCM_OK &&
                fcm__resize(ctx, (void **)&P->con_dof, (size_t)P->ncon, (size_t)(P->ncon + add),
                            sizeof *P->con_dof) == FCM_OK &&
                fcm__resize(ctx, (void **)&P->con_node, (size_t)P->ncon, (size_t)(P->ncon + add),
                            sizeof *P->con_node) == FCM_OK &&
                fcm__resize(ctx, (void **)&P->con_comp, (size_t)P->ncon, (size_t)(P->ncon + add),
                            sizeof *P->con_comp) == FCM_OK &&
                fcm__resize(ctx, (void **)&P->con_motion, (size_t)P->ncon, (size_t)(P->ncon + add),
                            sizeof *P->con_motion) == FCM_OK,
            ctx, FCM_ERR_ALLOC, "petsc: constraint: out of memory");
  P->motions[P->num_motions] = *m;
  for (fcm_index k = 0; k < num_nodes; k++) {
    const fcm_index nd = nodes[k];
    for (fcm_index c = 0; c < s->node_ncopy[nd]; c++)
      for (int i = 0; i < 3; i++) {
        if (!m->components[i]) continue;
        const fcm_index d = s->node_dof[nd] + 3 * c + i;
        if (P->is_con[d]) continue; /* listed twice in this set (others: check_constraint) */
        P->is_con[d] = (unsigned char)(P->num_motions + 1 > 255 ? 255 : P->num_motions + 1);
        P->con_dof[P->ncon] = d;
        P->con_node[P->ncon] = nd;
        P->con_comp[P->ncon] = i;
        P->con_motion[P->ncon] = P->num_motions;
        P->ncon++;
      }
  }
  P->num_motions++;
cleanup:
  return st;
}

fcm_status fcm_petsc_problem_add_constraint(fcm_petsc_problem *P, fcm_index num_nodes,
                                            const fcm_index *nodes, const fcm_motion *motion)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  /* every process checks its input before any changes its state */
  st = check_constraint(P, num_nodes, nodes, motion);
  FCM_TRY(P->ctx, fcm__petsc_agree(P->ctx, P->comm, st));
  st = apply_constraint(P, num_nodes, nodes, motion);
  FCM_TRY(P->ctx, fcm__petsc_agree(P->ctx, P->comm, st));
cleanup:
  return st;
}

/* ---------------------------------------------------------------- setup */

/* Add this process's elements of `form` into A (matrix terms) or f (vector terms). */
static fcm_status assemble_local(fcm_petsc_problem *P, const fcm_linear_form *form, Mat A, Vec f)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const fcm_space *s = P->space;
  const int nn = s->nn, nd = 3 * nn;
  double *Ke = NULL, *fe = NULL;
  PetscInt *idx = NULL;
  FCM_ALLOC(ctx, (size_t)nd * nd, Ke);
  FCM_ALLOC(ctx, nd, fe);
  FCM_ALLOC(ctx, nd, idx);
  for (fcm_index e = 0; e < s->num_elems; e++) {
    if (P->cell_owner[s->elem_cell[e]] != P->rank) continue;
    FCM_TRY(ctx, fcm__assembly_element_linear(P->aws, form, e, A ? Ke : NULL, f ? fe : NULL));
    for (int a = 0; a < nn; a++) {
      const fcm_index d = s->elem_dof[e * nn + a];
      for (int i = 0; i < 3; i++)
        idx[3 * a + i] = 3 * P->perm[d / 3] + i;
    }
    if (A) PCALL(ctx, MatSetValues(A, nd, idx, nd, idx, Ke, ADD_VALUES));
    if (f) PCALL(ctx, VecSetValues(f, nd, idx, fe, ADD_VALUES));
  }
cleanup:
  fcm__free(ctx, Ke);
  fcm__free(ctx, fe);
  fcm__free(ctx, idx);
  return st;
}

/* The assembly of all terms of this process: local element loops (errors agreed on before
 * the collective MatAssembly). */
static fcm_status assemble_all(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  fcm_linear_form form = fcm_linear_form_default();
  form.material = &P->mat;
  form.term = FCM_LINEAR_STIFFNESS;
  st = assemble_local(P, &form, P->K, NULL);
  if (st == FCM_OK && P->M) {
    form.term = FCM_LINEAR_MASS;
    st = assemble_local(P, &form, P->M, NULL);
  }
  if (st == FCM_OK && P->has_gravity) {
    form.term = FCM_LINEAR_BODY_FORCE;
    form.accel = P->gravity;
    st = assemble_local(P, &form, NULL, P->f);
  }
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, st));
  PCALL(ctx, MatAssemblyBegin(P->K, MAT_FINAL_ASSEMBLY));
  PCALL(ctx, MatAssemblyEnd(P->K, MAT_FINAL_ASSEMBLY));
  if (P->M) {
    PCALL(ctx, MatAssemblyBegin(P->M, MAT_FINAL_ASSEMBLY));
    PCALL(ctx, MatAssemblyEnd(P->M, MAT_FINAL_ASSEMBLY));
  }
  PCALL(ctx, VecAssemblyBegin(P->f));
  PCALL(ctx, VecAssemblyEnd(P->f));
cleanup:
  return st;
}

/* 1 when the option name carries a problem's prefix ("-fcm12_ksp_type"). */
static int has_problem_prefix(const char *name)
{
  if (strncmp(name, "-fcm", 4) != 0 || !(name[4] >= '0' && name[4] <= '9')) return 0;
  const char *q = name + 4;
  while (*q >= '0' && *q <= '9')
    q++;
  return *q == '_';
}

/* The options database, scoped to this problem (the KSP carries the prefix P->prefix, and
 * through it the PC and its inner solvers): the problem's string under the prefix, then every
 * option the database held before (the command line, option files, PETSC_OPTIONS, values set
 * by the program) copied under the prefix, so a key both give takes the database's value; last
 * the options that name this problem's prefix themselves ("-fcm2_ksp_type") as they were, so
 * they win over both. Options of other problems' prefixes are not copied: one problem's string
 * never reaches another problem's solver. (Values are split at spaces, as PETSc lists them.) */
fcm_status fcm__petsc_insert_options(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  char *all = NULL, **name = NULL, **value = NULL;
  int pushed = 0;
  size_t count = 0;
  PCALL(ctx, PetscOptionsGetAll(NULL, &all));
  {
    const size_t len = strlen(all);
    name = fcm__calloc(ctx, len / 2 + 1, sizeof *name);
    value = fcm__calloc(ctx, len / 2 + 1, sizeof *value);
    FCM_CHECK(name && value, ctx, FCM_ERR_ALLOC, "petsc: out of memory (options)");
    char *save = NULL;
    for (char *tok = strtok_r(all, " \t\n", &save); tok; tok = strtok_r(NULL, " \t\n", &save)) {
      const int is_name = tok[0] == '-' && ((tok[1] >= 'a' && tok[1] <= 'z') ||
                                            (tok[1] >= 'A' && tok[1] <= 'Z') || tok[1] == '_');
      if (is_name)
        name[count++] = tok;
      else if (count > 0 && !value[count - 1])
        value[count - 1] = tok;
    }
  }
  PCALL(ctx, PetscOptionsPrefixPush(NULL, P->prefix));
  pushed = 1;
  if (P->petsc_options && *P->petsc_options)
    PCALL(ctx, PetscOptionsInsertString(NULL, P->petsc_options));
  for (size_t k = 0; k < count; k++)
    if (!has_problem_prefix(name[k])) PCALL(ctx, PetscOptionsSetValue(NULL, name[k], value[k]));
  pushed = 0;
  PCALL(ctx, PetscOptionsPrefixPop(NULL));
  const size_t plen = strlen(P->prefix);
  for (size_t k = 0; k < count; k++)
    if (strncmp(name[k] + 1, P->prefix, plen) == 0)
      PCALL(ctx, PetscOptionsSetValue(NULL, name[k], value[k]));
cleanup:
  if (pushed) PetscOptionsPrefixPop(NULL);
  fcm__free(ctx, name);
  fcm__free(ctx, value);
  PetscFree(all);
  return st;
}

/* 1 when the options database names this problem's PC type (-<prefix>pc_type: the problem's
 * string and the command line are under the prefix after fcm__petsc_insert_options()). */
static int pc_type_given(const fcm_petsc_problem *P)
{
  char key[64];
  PetscBool has = PETSC_FALSE;
  snprintf(key, sizeof key, "-%spc_type", P->prefix);
  return PetscOptionsHasName(NULL, NULL, key, &has) == 0 && has;
}

fcm_status fcm_petsc_problem_setup(fcm_petsc_problem *P)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  const double t0 = fcm_wtime();
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm,
                                P->is_setup ? fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__,
                                                         __func__, "petsc: setup called twice")
                                            : FCM_OK));
  long long ncon_all = 0, ncon = (long long)P->ncon;
  MPI_Allreduce(&ncon, &ncon_all, 1, MPI_LONG_LONG, MPI_MAX, P->comm);
  FCM_TRY(ctx,
          fcm__petsc_agree(ctx, P->comm,
                           P->opts.kind == FCM_INTEGRATOR_STATIC && ncon_all == 0
                               ? fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__, __func__,
                                            "petsc: a static problem without any constraint: the "
                                            "body's rigid-body modes are free (K is singular)")
                               : FCM_OK));
  /* 1. assembly */
  const double ta = fcm_wtime();
  FCM_TRY(ctx, assemble_all(P));
  P->time_assembly = fcm_wtime() - ta;
  /* 2. the system matrix S = K (static) or M/h^2 + K, and its eliminated copy */
  PCALL(ctx, MatDuplicate(P->K, MAT_COPY_VALUES, &P->S));
  if (P->M) PCALL(ctx, MatAXPY(P->S, 1.0 / (P->opts.dt * P->opts.dt), P->M, SAME_NONZERO_PATTERN));
  PCALL(ctx, MatDuplicate(P->S, MAT_COPY_VALUES, &P->Se));
  {
    PetscReal dsum = 0.0;
    PCALL(ctx, MatGetDiagonal(P->S, P->w));
    PCALL(ctx, VecNorm(P->w, NORM_1, &dsum));
    P->diag = P->n > 0 ? dsum / (double)P->n : 1.0;
    if (!(P->diag > 0.0)) P->diag = 1.0;
  }
  P->nrows = 0;
  for (fcm_index k = 0; k < P->ncon; k++)
    P->nrows += P->copy_owner[P->con_dof[k] / 3] == P->rank;
  PCALL(ctx, PetscMalloc1(P->nrows + 1, &P->rows));
  P->nrows = 0;
  for (fcm_index k = 0; k < P->ncon; k++) {
    const fcm_index d = P->con_dof[k];
    if (P->copy_owner[d / 3] == P->rank) P->rows[P->nrows++] = 3 * P->perm[d / 3] + d % 3;
  }
  PCALL(ctx, MatZeroRowsColumns(P->Se, P->nrows, P->rows, P->diag, NULL, NULL));
  PCALL(ctx, MatSetOption(P->Se, MAT_SPD, PETSC_TRUE));
  FCM_TRY(ctx, fcm__petsc_near_null_space(P, P->Se));
  /* 3. the KSP: defaults, then the options database */
  /* local (fcm allocations): agreed before the collective KSPCreate and PCMG setup below */
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm, fcm__petsc_insert_options(P)));
  PCALL(ctx, KSPCreate(P->comm, &P->ksp));
  PCALL(ctx, KSPSetOptionsPrefix(P->ksp, P->prefix));
  PCALL(ctx, KSPSetOperators(P->ksp, P->Se, P->Se));
  PCALL(ctx, KSPSetType(P->ksp, KSPCG));
  {
    PC pc;
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    PCALL(ctx, PCSetType(pc, PCGAMG));
  }
  PCALL(ctx, KSPSetTolerances(P->ksp, P->opts.solver.rtol, PETSC_DEFAULT, PETSC_DEFAULT,
                              P->opts.solver.max_iterations));
  PCALL(ctx, KSPSetFromOptions(P->ksp));
  {
    PC pc;
    PetscBool mg = PETSC_FALSE;
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    PCALL(ctx, PetscObjectTypeCompare((PetscObject)pc, PCMG, &mg));
    /* the default on Hex20 box grids: fcm's geometric multigrid as PCMG (pcmg.c; CG + GAMG
     * needs hundreds of iterations there), GAMG when the mesh is no box grid */
    const int by_default =
        !mg && !pc_type_given(P) && fcm_mesh_element_type(P->mesh) == FCM_ELEMENT_HEX20;
    if (mg || by_default) {
      int levels = 0;
      if (by_default) PCALL(ctx, PCSetType(pc, PCMG));
      FCM_TRY(ctx, fcm__petsc_pcmg_setup(P, pc, P->is_con, by_default, &levels)); /* agreed */
      if (levels == 0) { /* not a box grid: GAMG */
        PCALL(ctx, PCSetType(pc, PCGAMG));
        PCALL(ctx, PCSetFromOptions(pc));
      }
    }
  }
  P->is_setup = 1;
  P->time_setup += fcm_wtime() - t0;
cleanup:
  return st;
}

/* ---------------------------------------------------------------- steps */

/* g: the prescribed values at time t on the owned constrained DOFs, 0 elsewhere. */
static fcm_status constraint_values(fcm_petsc_problem *P, double t)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  const double *X = fcm_mesh_coords(P->mesh);
  PCALL(ctx, VecSet(P->g, 0.0));
  for (fcm_index k = 0; k < P->ncon; k++) {
    const fcm_index d = P->con_dof[k];
    if (P->copy_owner[d / 3] != P->rank) continue;
    double u[3];
    fcm_motion_eval(&P->motions[P->con_motion[k]], X + 3 * P->con_node[k], t, u, NULL);
    PCALL(ctx,
          VecSetValue(P->g, 3 * P->perm[d / 3] + P->con_comp[k], u[P->con_comp[k]], INSERT_VALUES));
  }
  PCALL(ctx, VecAssemblyBegin(P->g));
  PCALL(ctx, VecAssemblyEnd(P->g));
cleanup:
  return st;
}

static fcm_status energies(fcm_petsc_problem *P, fcm_petsc_step_info *info)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  PetscScalar e = 0.0;
  PCALL(ctx, MatMult(P->K, P->u, P->w));
  PCALL(ctx, VecDot(P->u, P->w, &e));
  info->elastic_energy = 0.5 * e;
  PCALL(ctx, VecDot(P->f, P->u, &e));
  info->external_work = e;
  info->kinetic_energy = 0.0;
  if (P->M) {
    PCALL(ctx, MatMult(P->M, P->v, P->w));
    PCALL(ctx, VecDot(P->v, P->w, &e));
    info->kinetic_energy = 0.5 * e;
  }
cleanup:
  return st;
}

fcm_status fcm_petsc_problem_step(fcm_petsc_problem *P, fcm_petsc_step_info *info)
{
  fcm_status st = FCM_OK;
  fcm_petsc_step_info si;
  memset(&si, 0, sizeof si);
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  fcm_ctx *ctx = P->ctx;
  FCM_TRY(ctx, fcm__petsc_agree(ctx, P->comm,
                                !P->is_setup ? fcm__error(ctx, FCM_ERR_ARG, __FILE__, __LINE__,
                                                          __func__, "petsc: step before setup")
                                             : FCM_OK));
  const double h = P->opts.dt, t1 = P->t + h;
  double t0 = fcm_wtime();
  /* b = f (+ M/h^2 (u + h v)) - S g, then b = diag g on the constrained rows */
  FCM_TRY(ctx, constraint_values(P, t1));
  PCALL(ctx, VecCopy(P->f, P->b));
  if (P->M) {
    PCALL(ctx, VecWAXPY(P->x, h, P->v, P->u));
    PCALL(ctx, MatMult(P->M, P->x, P->w));
    PCALL(ctx, VecAXPY(P->b, 1.0 / (h * h), P->w));
  }
  PCALL(ctx, MatMult(P->S, P->g, P->w));
  PCALL(ctx, VecAXPY(P->b, -1.0, P->w));
  {
    PetscScalar *bb = NULL;
    const PetscScalar *gg = NULL;
    PCALL(ctx, VecGetArray(P->b, &bb));
    PCALL(ctx, VecGetArrayRead(P->g, &gg));
    for (PetscInt k = 0; k < P->nrows; k++) {
      const PetscInt r = P->rows[k] - 3 * P->first;
      bb[r] = P->diag * gg[r];
    }
    PCALL(ctx, VecRestoreArrayRead(P->g, &gg));
    PCALL(ctx, VecRestoreArray(P->b, &bb));
  }
  si.time_rhs = fcm_wtime() - t0;
  /* solve */
  t0 = fcm_wtime();
  KSPConvergedReason reason;
  PetscInt its = 0;
  PetscReal rnorm = 0.0;
  PCALL(ctx, KSPSolve(P->ksp, P->b, P->x)); /* zero initial guess (preonly needs it) */
  PCALL(ctx, KSPGetConvergedReason(P->ksp, &reason));
  PCALL(ctx, KSPGetIterationNumber(P->ksp, &its));
  PCALL(ctx, KSPGetResidualNorm(P->ksp, &rnorm));
  si.time_solve = fcm_wtime() - t0;
  si.iterations = (int)its;
  si.reason = (int)reason;
  si.residual = rnorm;
  P->total_iterations += its;
  if (reason < 0) {
    KSPType kt = NULL;
    PC pc;
    PCType pt = NULL;
    KSPGetType(P->ksp, &kt);
    KSPGetPC(P->ksp, &pc);
    PCGetType(pc, &pt);
    FCM_CHECK(0, ctx, FCM_ERR_NOT_CONVERGED,
              "petsc: t = %g: KSP %s with PC %s did not converge: %s (KSPConvergedReason %d) "
              "after %d iterations, residual norm %g (rtol %g); change the solver with "
              "-ksp_type / -pc_type or solver.petsc_options",
              t1, kt ? kt : "?", pt ? pt : "?", KSPConvergedReasons[reason], (int)reason, (int)its,
              (double)rnorm, P->opts.solver.rtol);
  }
  /* accept: v = (u1 - u0)/h (dynamic), u = u1 */
  if (P->M) {
    PCALL(ctx, VecWAXPY(P->w, -1.0, P->u, P->x));
    PCALL(ctx, VecScale(P->w, 1.0 / h));
    PCALL(ctx, VecCopy(P->w, P->v));
  }
  PCALL(ctx, VecCopy(P->x, P->u));
  P->t = t1;
  P->steps++;
  si.time = P->t;
  FCM_TRY(ctx, energies(P, &si));
  if (info) *info = si;
cleanup:
  return st;
}

/* ---------------------------------------------------------------- queries */

fcm_index fcm_petsc_problem_num_dofs(const fcm_petsc_problem *P)
{
  return P ? P->n : 0;
}

const fcm_space *fcm_petsc_problem_space(const fcm_petsc_problem *P)
{
  return P ? P->space : NULL;
}

fcm_status fcm_petsc_problem_geometry_kept(const fcm_petsc_problem *P, fcm_index *num_cells,
                                           const fcm_index **cells, fcm_index *num_triangles,
                                           const fcm_index **triangles)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P && num_cells && cells && num_triangles && triangles, P ? P->ctx : NULL, FCM_ERR_ARG,
            "petsc: NULL argument (problem, num_cells, cells, num_triangles, triangles)");
  *num_cells = P->kept_cells ? P->geom_cells_kept : 0;
  *num_triangles = P->kept_tris ? P->geom_tris_kept : 0;
  *cells = P->kept_cells;
  *triangles = P->kept_tris;
cleanup:
  return st;
}

/* The whole vector x in the space's numbering into out (n values) on every process (to_zero:
 * on process 0 only; out is not read elsewhere). O(n) memory and traffic per receiving
 * process: for fcm_petsc_problem_get_state() (every process) and the checkpoint (process 0);
 * frames and energies do without it. Collective. */
fcm_status fcm__petsc_gather(fcm_petsc_problem *P, Vec x, double *out, int to_zero)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  VecScatter sc = NULL;
  Vec all = NULL;
  const PetscScalar *a = NULL;
  if (to_zero)
    PCALL(ctx, VecScatterCreateToZero(x, &sc, &all));
  else
    PCALL(ctx, VecScatterCreateToAll(x, &sc, &all));
  PCALL(ctx, VecScatterBegin(sc, x, all, INSERT_VALUES, SCATTER_FORWARD));
  PCALL(ctx, VecScatterEnd(sc, x, all, INSERT_VALUES, SCATTER_FORWARD));
  if (to_zero && P->rank != 0) goto cleanup;
  PCALL(ctx, VecGetArrayRead(all, &a));
  for (fcm_index k = 0; k < P->ncopy; k++)
    for (int i = 0; i < 3; i++)
      out[3 * k + i] = a[3 * P->perm[k] + i];
  PCALL(ctx, VecRestoreArrayRead(all, &a));
cleanup:
  VecScatterDestroy(&sc);
  VecDestroy(&all);
  return st;
}

fcm_status fcm_petsc_problem_get_state(fcm_petsc_problem *P, double *u, double *v)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P, NULL, FCM_ERR_ARG, "petsc: NULL problem");
  if (u) FCM_TRY(P->ctx, fcm__petsc_gather(P, P->u, u, 0));
  if (v) FCM_TRY(P->ctx, fcm__petsc_gather(P, P->v, v, 0));
cleanup:
  return st;
}

fcm_status fcm_petsc_problem_get_info(fcm_petsc_problem *P, fcm_petsc_info *info)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(P && info, NULL, FCM_ERR_ARG, "petsc: NULL problem or info");
  fcm_ctx *ctx = P->ctx;
  memset(info, 0, sizeof *info);
  info->size = P->size;
  info->rank = P->rank;
  info->partition = P->size == 1 && P->opts.solver.partition == FCM_PETSC_PARTITION_AUTO
                        ? FCM_PETSC_PARTITION_ORDERED
                        : P->partition;
  info->num_dofs = P->n;
  info->local_dofs = 3 * (fcm_index)P->nlocal;
  info->local_elements = P->nelem_own;
  long long ne = (long long)P->nelem_own, mx = 0, mn = 0;
  MPI_Allreduce(&ne, &mx, 1, MPI_LONG_LONG, MPI_MAX, P->comm);
  MPI_Allreduce(&ne, &mn, 1, MPI_LONG_LONG, MPI_MIN, P->comm);
  info->max_local_elements = (fcm_index)mx;
  info->min_local_elements = (fcm_index)mn;
  if (P->M && P->is_setup) { /* 1_x^T M 1_x */
    PetscScalar *a = NULL, m = 0.0;
    PCALL(ctx, VecGetArray(P->x, &a));
    for (PetscInt i = 0; i < 3 * P->nlocal; i++)
      a[i] = i % 3 == 0 ? 1.0 : 0.0;
    PCALL(ctx, VecRestoreArray(P->x, &a));
    PCALL(ctx, MatMult(P->M, P->x, P->w));
    PCALL(ctx, VecDot(P->x, P->w, &m));
    info->mass = m;
  }
  info->time_rules = P->time_rules;
  info->time_assembly = P->time_assembly;
  info->time_setup = P->time_setup;
  PetscLogDouble mem = 0.0;
  PCALL(ctx, PetscMemoryGetCurrentUsage(&mem));
  info->memory_local = mem;
  MPI_Allreduce(&info->memory_local, &info->memory_total, 1, MPI_DOUBLE, MPI_SUM, P->comm);
  if (P->Se) {
    MatInfo mi; /* values and column indices of the stored nonzeros (mi.memory is not kept) */
    PCALL(ctx, MatGetInfo(P->Se, MAT_GLOBAL_SUM, &mi));
    info->matrix_memory = mi.nz_allocated * (double)(sizeof(PetscScalar) + sizeof(PetscInt));
  }
  info->geometry_cells = P->geom_cells;
  info->geometry_triangles = P->geom_tris;
  info->geometry_cells_kept = P->geom_cells_kept;
  info->geometry_triangles_kept = P->geom_tris_kept;
  info->geometry_bytes = P->geom_bytes;
  info->geometry_bytes_kept = P->geom_bytes_kept;
  MPI_Allreduce(&info->geometry_bytes_kept, &info->max_geometry_bytes_kept, 1, MPI_DOUBLE, MPI_MAX,
                P->comm);
  info->steps = P->steps;
  info->total_iterations = P->total_iterations;
  snprintf(info->options_prefix, sizeof info->options_prefix, "%s", P->prefix);
  if (P->ksp) {
    KSPType kt = NULL;
    PCType pt = NULL;
    PC pc;
    PCALL(ctx, KSPGetType(P->ksp, &kt));
    PCALL(ctx, KSPGetPC(P->ksp, &pc));
    PCALL(ctx, PCGetType(pc, &pt));
    snprintf(info->ksp_type, sizeof info->ksp_type, "%s", kt ? kt : "");
    snprintf(info->pc_type, sizeof info->pc_type, "%s", pt ? pt : "");
    if (pt && (!strcmp(pt, PCLU) || !strcmp(pt, PCCHOLESKY))) {
      MatSolverType mst = NULL;
      PCALL(ctx, PCFactorGetMatSolverType(pc, &mst));
      snprintf(info->factor_package, sizeof info->factor_package, "%s", mst ? mst : "");
    }
  }
cleanup:
  return st;
}
