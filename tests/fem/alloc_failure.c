/* Allocation failures in the fem module: failing the k-th allocation (k = 0, 1, ... until
 * success) of fcm_space_create, fcm_space_create_embedded, fcm_space_matrix_create, every
 * assembly (stiffness, mass, body force, body-force field, surface traction, hyperelastic),
 * fcm_space_apply_dirichlet, fcm_space_locate (points inside cells and extrapolated ones),
 * the first fcm_space_momentum of a space (its mass blocks),
 * fcm_element_standard_rule and the output fields (cell stress, max displacement, VTU of the
 * space, the embedded surface and its VTU), a local space localized on some cells
 * (fcm__space_create_local() + fcm__space_localize()) and its matrix over the local rows
 * (fcm__space_matrix_create_rows()), a second cut (fcm_cell_rules_create_cut() on rules that
 * have one) and a space with constrained copies of a cut (fcm_space_create_embedded_with())
 * returns FCM_ERR_ALLOC, NULL outputs and leaks nothing. */
#include "fcm/fcm.h"
#include "alloc_loop.h"
#include "fem/fem_impl.h"

#include <omp.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct fixture {
  fcm_ctx *ctx;
  fcm_mesh *mesh;
  fcm_cell_rules *rules;
  fcm_space *space; /* embedded */
  fcm_csr *K;
  fcm_material mat;
  fcm_material_params hyper;
  double *f, *u;
  fcm_index ndof;
  fcm_index ncon, con[6];
  double X[3 * 4];
  fcm_index cell[4];
  double xi[3 * 4];
  int ext[4];
  /* outputs of the creating calls */
  fcm_space *s_out;
  fcm_csr *A_out;
  fcm_rule *r_out;
  fcm_embedded_surface *es_out;
  fcm_geometry *geom;
  fcm_embedded_surface *es;
  fcm_cell_rules *cut1, *rules_out; /* one cut; the output of the second */
  fcm_space *s_cut;                 /* the space of cut1 */
  fcm_surface *plane;
  fcm_space_options so;
  double *cell_out; /* 8 x num_cells */
} fixture;

static void field(void *user, const double x[3], const double normal[3], double value[3])
{
  (void)user;
  value[0] = x[1];
  value[1] = normal ? normal[0] : 1.0;
  value[2] = -x[0];
}

#define OUT_CHECK(st, out) ((st) != FCM_OK && (out) != NULL ? FCM_ERR_INTERNAL : (st))

static fcm_status space_create(void *u)
{
  fixture *x = u;
  x->s_out = (fcm_space *)x;
  fcm_status st = fcm_space_create(x->ctx, x->mesh, NULL, &x->s_out);
  return OUT_CHECK(st, x->s_out);
}
static fcm_status space_create_embedded(void *u)
{
  fixture *x = u;
  x->s_out = (fcm_space *)x;
  fcm_status st = fcm_space_create_embedded(x->ctx, x->mesh, x->rules, &x->s_out);
  return OUT_CHECK(st, x->s_out);
}
/* A new embedded space and its first fcm_space_momentum() (which builds the mass blocks the
 * space keeps): each of the two allocations can fail. */
static fcm_status momentum(void *u)
{
  fixture *x = u;
  double m, p[3], L[3];
  fcm_status st = fcm_space_create_embedded(x->ctx, x->mesh, x->rules, &x->s_out);
  if (st == FCM_OK) st = fcm_space_momentum(x->s_out, 1000.0, NULL, NULL, &m, p, L);
  return st;
}
static fcm_status matrix_create(void *u)
{
  fixture *x = u;
  x->A_out = (fcm_csr *)x;
  fcm_status st = fcm_space_matrix_create(x->space, &x->A_out);
  return OUT_CHECK(st, x->A_out);
}
static fcm_status standard_rule(void *u)
{
  fixture *x = u;
  x->r_out = (fcm_rule *)x;
  fcm_status st = fcm_element_standard_rule(x->ctx, FCM_ELEMENT_HEX20, FCM_RULE_MASS, 0, &x->r_out);
  return OUT_CHECK(st, x->r_out);
}
static fcm_status surface_create(void *u)
{
  fixture *x = u;
  x->es_out = (fcm_embedded_surface *)x;
  fcm_status st = fcm_embedded_surface_create(x->space, x->geom, &x->es_out);
  return OUT_CHECK(st, x->es_out);
}
static fcm_status cell_stress(void *u)
{
  fixture *x = u;
  const fcm_index nc = fcm_mesh_num_cells(x->mesh);
  return fcm_space_cell_stress(x->space, &x->mat, x->u, x->cell_out, x->cell_out + 6 * nc,
                               x->cell_out + 7 * nc);
}
static fcm_status max_displacement(void *u)
{
  fixture *x = u;
  double m = 0.0;
  return fcm_space_max_displacement(x->space, x->u, &m);
}
static fcm_status space_vtu(void *u)
{
  fixture *x = u;
  return fcm_space_write_vtu(x->space, &x->mat, x->u, x->u, "fem_alloc_out/bg.vtu");
}
static fcm_status surface_vtu(void *u)
{
  fixture *x = u;
  return fcm_embedded_surface_write_vtu(x->es, &x->mat, x->u, "fem_alloc_out/s.vtu");
}
static fcm_status surface_cut(void *u)
{
  fixture *x = u;
  return fcm_embedded_surface_set_space(x->es, x->s_cut);
}
/* The surface back on the uncut space, made anew: a cut space's surface keeps what it found
 * for the next cut (allocations that stay), the uncut one nothing. */
static void surface_uncut(void *u)
{
  fixture *x = u;
  fcm_embedded_surface_destroy(&x->es);
  if (fcm_embedded_surface_create(x->space, x->geom, &x->es) != FCM_OK) x->es = NULL;
}
static fcm_status second_cut(void *u)
{
  fixture *x = u;
  x->rules_out = (fcm_cell_rules *)x;
  fcm_status st =
      fcm_cell_rules_create_cut(x->ctx, x->mesh, x->geom, x->cut1, x->plane, &x->rules_out);
  return OUT_CHECK(st, x->rules_out);
}
static fcm_status constrained_space(void *u)
{
  fixture *x = u;
  x->s_out = (fcm_space *)x;
  fcm_status st = fcm_space_create_embedded_with(x->ctx, x->mesh, x->cut1, &x->so, &x->s_out);
  return OUT_CHECK(st, x->s_out);
}
static void release(void *u)
{
  fixture *x = u;
  fcm_cell_rules_destroy(&x->rules_out);
  fcm_embedded_surface_destroy(&x->es_out);
  fcm_space_destroy(&x->s_out);
  fcm_csr_destroy(&x->A_out);
  fcm_rule_destroy(&x->r_out);
}
static fcm_status stiffness(void *u)
{
  fixture *x = u;
  return fcm_assemble_stiffness(x->space, &x->mat, NULL, x->K);
}
static fcm_status mass(void *u)
{
  fixture *x = u;
  return fcm_assemble_mass(x->space, &x->mat, NULL, x->K);
}
static fcm_status body_force(void *u)
{
  fixture *x = u;
  const double g[3] = {0, 0, -9.81};
  return fcm_assemble_body_force(x->space, &x->mat, g, NULL, x->f);
}
static fcm_status body_force_field(void *u)
{
  fixture *x = u;
  return fcm_assemble_body_force_field(x->space, field, NULL, NULL, x->f);
}
static fcm_status traction(void *u)
{
  fixture *x = u;
  return fcm_assemble_surface_traction(x->space, field, NULL, x->f);
}
static fcm_status hyperelastic(void *u)
{
  fixture *x = u;
  double E = 0;
  return fcm_assemble_hyperelastic(x->space, &x->hyper, x->u, NULL, &E, x->f, x->K);
}
static fcm_status dirichlet(void *u)
{
  fixture *x = u;
  const double vals[6] = {0, 0, 0, 1e-3, 0, 0};
  return fcm_space_apply_dirichlet(x->space, x->ncon, x->con, vals, x->K, x->f);
}
static unsigned char own_cells[4] = {1, 0, 0, 0};
static fcm_status local_space(void *u)
{
  fixture *x = u;
  x->s_out = (fcm_space *)x;
  fcm_status st = fcm__space_create_local(x->ctx, x->mesh, NULL, x->rules, NULL, NULL, &x->s_out);
  if (st != FCM_OK) return OUT_CHECK(st, x->s_out);
  return fcm__space_localize(x->s_out, own_cells); /* released: the space */
}
static fcm_status rows_matrix(void *u)
{
  fixture *x = u;
  x->A_out = (fcm_csr *)x;
  fcm_status st = fcm__space_matrix_create_rows(x->s_out, &x->A_out);
  return OUT_CHECK(st, x->A_out);
}
static void release_matrix(void *u)
{
  fixture *x = u;
  fcm_csr_destroy(&x->A_out);
}
static fcm_status locate(void *u)
{
  fixture *x = u;
  return fcm_space_locate(x->space, 4, x->X, x->cell, x->xi, x->ext);
}

int main(void)
{
  omp_set_num_threads(1); /* the failing allocator counts calls in order */
  failing f;
  static fixture x;
  x.ctx = failing_ctx(&f);
  TEST_TRUE(x.ctx != NULL);
  if (!x.ctx) return TEST_RESULT();
  fcm_ctx *ctx = x.ctx;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, c0[3] = {0.1, 0, 0};
  const fcm_index n[3] = {2, 2, 1};
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &x.mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.9, 1, &g));
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1));
  o.surface_strength = 1;
  o.strength[FCM_RULE_MASS] = 2;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, x.mesh, g, &o, &x.rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, x.mesh, x.rules, &x.space));
  TEST_OK(ctx, fcm_space_matrix_create(x.space, &x.K));
  if (!x.K) return TEST_RESULT();
  x.mat = (fcm_material){FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000};
  fcm_material m = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000};
  TEST_OK(ctx, fcm_material_setup(ctx, &m, &x.hyper));
  x.ndof = fcm_space_num_dofs(x.space);
  x.f = calloc((size_t)x.ndof, sizeof *x.f);
  x.u = calloc((size_t)x.ndof, sizeof *x.u);
  for (fcm_index i = 0; i < x.ndof; i++)
    x.u[i] = 1e-3 * (double)(i % 7);
  for (int k = 0; k < 2; k++) { /* two nodes, all components */
    fcm_index dof = -1;
    for (fcm_index a = k; dof < 0; a++)
      dof = fcm_space_node_dof(x.space, a);
    for (int d = 0; d < 3; d++)
      x.con[3 * k + d] = dof + d;
  }
  x.ncon = 6;
  /* inside cells, on the embedded surface, outside the active cells (extrapolated) */
  const double pts[12] = {0.1, 0.2, 0.3, -0.5, -0.5, 0.5, 0.95, 0, 0, 1.5, 0.2, 0.1};
  memcpy(x.X, pts, sizeof pts);

  alloc_loop(ctx, &f, "fcm_space_create", space_create, release, &x, 3, 1000);
  alloc_loop(ctx, &f, "fcm_space_create_embedded", space_create_embedded, release, &x, 3, 1000);
  alloc_loop(ctx, &f, "fcm_space_matrix_create", matrix_create, release, &x, 2, 1000);
  alloc_loop(ctx, &f, "fcm_space_momentum (the mass blocks)", momentum, release, &x, 4, 1000);
  alloc_loop(ctx, &f, "fcm_element_standard_rule", standard_rule, release, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_assemble_stiffness", stiffness, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_assemble_mass", mass, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_assemble_body_force", body_force, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_assemble_body_force_field", body_force_field, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_assemble_surface_traction", traction, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_assemble_hyperelastic", hyperelastic, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_space_apply_dirichlet", dirichlet, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_space_locate", locate, NULL, &x, 2, 1000);
  TEST_TRUE(x.ext[0] == 0 && x.ext[3] == 1); /* the last round located both kinds */
  alloc_loop(ctx, &f, "fcm__space_create_local + fcm__space_localize", local_space, release, &x, 5,
             1000);
  TEST_OK(ctx, local_space(&x));
  alloc_loop(ctx, &f, "fcm__space_matrix_create_rows", rows_matrix, release_matrix, &x, 2, 1000);
  release(&x);
  x.geom = g;
  x.cell_out = malloc(sizeof *x.cell_out * 8 * (size_t)fcm_mesh_num_cells(x.mesh));
  TEST_OK(ctx, fcm_embedded_surface_create(x.space, g, &x.es));
  mkdir("fem_alloc_out", 0755);
  alloc_loop(ctx, &f, "fcm_embedded_surface_create", surface_create, release, &x, 5, 1000);
  alloc_loop(ctx, &f, "fcm_space_cell_stress", cell_stress, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_space_max_displacement", max_displacement, NULL, &x, 1, 1000);
  alloc_loop(ctx, &f, "fcm_space_write_vtu", space_vtu, NULL, &x, 5, 1000);
  alloc_loop(ctx, &f, "fcm_embedded_surface_write_vtu", surface_vtu, NULL, &x, 3, 1000);
  remove("fem_alloc_out/bg.vtu");
  remove("fem_alloc_out/s.vtu");
  rmdir("fem_alloc_out");
  fcm_embedded_surface_destroy(&x.es);
  free(x.cell_out);

  /* a cut 1e-7 off the cell faces x = 0 (slices of the right cells whose copies are tiny
   * with the ratio 1e-6), then a second cut across it */
  const double p1[3] = {1e-7, 0, 0}, n1[3] = {1, 0, 0}, p2[3] = {0, 0.2, 0}, n2[3] = {0.1, 1, 0.2};
  const double blo[3] = {-1.2, -1.2, -1.2}, bhi[3] = {1.2, 1.2, 1.2};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p1, n1, blo, bhi, &x.plane));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, x.mesh, g, x.rules, x.plane, &x.cut1));
  fcm_surface_destroy(&x.plane);
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p2, n2, blo, bhi, &x.plane));
  x.so = fcm_space_options_default();
  x.so.constrain_ratio = 1e-6;
  TEST_OK(ctx, constrained_space(&x));
  TEST_TRUE(x.s_out && fcm_space_num_constrained_copies(x.s_out) > 0);
  release(&x);
  alloc_loop(ctx, &f, "fcm_cell_rules_create_cut (a second cut)", second_cut, release, &x, 5,
             10000);
  alloc_loop(ctx, &f, "fcm_space_create_embedded_with (constrained copies)", constrained_space,
             release, &x, 5, 1000);
  /* the surface moved onto the cut space: the crossed triangles split */
  TEST_OK(ctx, fcm_space_create_embedded(ctx, x.mesh, x.cut1, &x.s_cut));
  TEST_OK(ctx, fcm_embedded_surface_create(x.space, g, &x.es));
  alloc_loop(ctx, &f, "fcm_embedded_surface_set_space (a cut space)", surface_cut, surface_uncut,
             &x, 5, 1000);
  TEST_TRUE(x.es != NULL);
  if (x.es) TEST_OK(ctx, fcm_embedded_surface_set_space(x.es, x.s_cut));
  TEST_TRUE(fcm_embedded_surface_num_split_triangles(x.es) > 0);
  fcm_embedded_surface_destroy(&x.es);
  fcm_space_destroy(&x.s_cut);
  fcm_surface_destroy(&x.plane);
  fcm_cell_rules_destroy(&x.cut1);

  free(x.f), free(x.u);
  fcm_csr_destroy(&x.K);
  fcm_space_destroy(&x.space);
  fcm_cell_rules_destroy(&x.rules);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&x.mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
