/* Assembly workspaces, for every element type: after the first assembly of each
 * term, repeated assembly through a workspace makes no allocation through the ctx
 * allocator; workspace results equal the one-shot functions' bit for bit; two
 * workspaces used at the same time on one (const) space give the serial results;
 * bad terms and NULL arguments are FCM_ERR_ARG. */
#include "fem_util.h"
#include "test_alloc.h"

#include <string.h>

static void gravity_field(void *user, const double x[3], const double normal[3], double value[3])
{
  (void)user, (void)normal;
  value[0] = 0.1 * x[1];
  value[1] = -2.0;
  value[2] = x[0] * x[2];
}

/* Every linear term and the hyperelastic energy, force and tangent at u. */
static void assemble_all(fcm_ctx *ctx, fcm_assembly_workspace *ws, const fcm_material *el,
                         const fcm_material_params *p, const double *u, fcm_csr *K, fcm_csr *M,
                         fcm_csr *T, double *f, double *fint, double *E)
{
  static const double g[3] = {0.0, 0.0, -9.81};
  fcm_linear_form form = fcm_linear_form_default();
  form.material = el;
  form.term = FCM_LINEAR_STIFFNESS;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, K, NULL));
  form.term = FCM_LINEAR_MASS;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, M, NULL));
  form.term = FCM_LINEAR_BODY_FORCE;
  form.accel = g;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, NULL, f));
  form.term = FCM_LINEAR_BODY_FORCE_FIELD;
  form.field = gravity_field;
  TEST_OK(ctx, fcm_assembly_workspace_linear(ws, &form, NULL, f));
  TEST_OK(ctx, fcm_assembly_workspace_hyperelastic(ws, p, u, E, fint, T));
}

static int same(const double *a, const double *b, fcm_index n)
{
  return memcmp(a, b, sizeof *a * (size_t)n) == 0;
}

int main(int argc, char **argv)
{
  failing fa;
  fcm_ctx *ctx = failing_ctx(&fa);
  fcm_mesh *mesh = NULL;
  fcm_space *owned = NULL;
  fcm_assembly_workspace *ws = NULL, *ws2 = NULL;
  fcm_csr *K = NULL, *M = NULL, *T = NULL, *K1 = NULL, *M1 = NULL, *T1 = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_TRUE(ctx != NULL);
  TEST_OK(ctx, distorted_box(ctx, type, 2, 0.2, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &owned));
  const fcm_space *space = owned; /* assembly only reads the space */
  fcm_index n = fcm_space_num_dofs(space), nnz = 0;
  double *u = calloc((size_t)n, sizeof *u), *u2 = calloc((size_t)n, sizeof *u2);
  double *f = calloc((size_t)n, sizeof *f), *fint = calloc((size_t)n, sizeof *fint);
  double *f1 = calloc((size_t)n, sizeof *f1), *fint1 = calloc((size_t)n, sizeof *fint1);
  unsigned long long seed = 7;
  for (fcm_index i = 0; i < n; i++)
    u[i] = 0.05 * urand(&seed), u2[i] = 0.05 * urand(&seed);
  fcm_material snh = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e4, 0.3, 2.0};
  fcm_material_params p;
  TEST_OK(ctx, fcm_material_setup(ctx, &snh, &p));
  const fcm_material el = snh; /* linear terms use its E, nu and density */
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_space_matrix_create(space, &M));
  TEST_OK(ctx, fcm_space_matrix_create(space, &T));
  TEST_OK(ctx, fcm_space_matrix_create(space, &K1));
  TEST_OK(ctx, fcm_space_matrix_create(space, &M1));
  TEST_OK(ctx, fcm_space_matrix_create(space, &T1));
  fcm_csr_get_size(K, NULL, NULL, &nnz);
  TEST_OK(ctx, fcm_assembly_workspace_create(space, NULL, &ws));

  /* The first round builds the standard rules; later rounds allocate nothing. */
  double E = 0.0, E1 = 0.0;
  assemble_all(ctx, ws, &el, &p, u, K, M, T, f, fint, &E);
  long long before = fa.count, live = fcm_ctx_live_allocations(ctx);
  for (int round = 0; round < 3; round++) {
    fcm_csr_set_zero(K), fcm_csr_set_zero(M), fcm_csr_set_zero(T);
    memset(f, 0, sizeof *f * (size_t)n), memset(fint, 0, sizeof *fint * (size_t)n);
    assemble_all(ctx, ws, &el, &p, u, K, M, T, f, fint, &E);
  }
  TEST_TRUE(fa.count == before);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == live);

  /* The one-shot functions give the same bits. */
  static const double g[3] = {0.0, 0.0, -9.81};
  TEST_OK(ctx, fcm_assemble_stiffness(space, &el, NULL, K1));
  TEST_TRUE(fa.count > before); /* the counter sees the one-shot function's workspace */
  TEST_OK(ctx, fcm_assemble_mass(space, &el, NULL, M1));
  TEST_OK(ctx, fcm_assemble_body_force(space, &el, g, NULL, f1));
  TEST_OK(ctx, fcm_assemble_body_force_field(space, gravity_field, NULL, NULL, f1));
  TEST_OK(ctx, fcm_assemble_hyperelastic(space, &p, u, NULL, &E1, fint1, T1));
  TEST_TRUE(same(fcm_csr_values_read(K), fcm_csr_values_read(K1), nnz));
  TEST_TRUE(same(fcm_csr_values_read(M), fcm_csr_values_read(M1), nnz));
  TEST_TRUE(same(fcm_csr_values_read(T), fcm_csr_values_read(T1), nnz));
  TEST_TRUE(same(f, f1, n));
  TEST_TRUE(same(fint, fint1, n));
  TEST_TRUE(E == E1 && E != 0.0);

  /* Two workspaces on one space at the same time (the old per-space scratch made this
   * a race): each gives its serial energy and force. */
  double E2 = 0.0, Ea = 0.0, Eb = 0.0;
  TEST_OK(ctx, fcm_assembly_workspace_create(space, NULL, &ws2));
  memset(f1, 0, sizeof *f1 * (size_t)n);
  TEST_OK(ctx, fcm_assembly_workspace_hyperelastic(ws2, &p, u2, &E2, f1, NULL));
  memset(f, 0, sizeof *f * (size_t)n), memset(fint, 0, sizeof *fint * (size_t)n);
  fcm_status sa = FCM_ERR_INTERNAL, sb = FCM_ERR_INTERNAL;
#pragma omp parallel sections num_threads(2)
  {
#pragma omp section
    sa = fcm_assembly_workspace_hyperelastic(ws, &p, u, &Ea, fint, NULL);
#pragma omp section
    sb = fcm_assembly_workspace_hyperelastic(ws2, &p, u2, &Eb, f, NULL);
  }
  TEST_TRUE(sa == FCM_OK && sb == FCM_OK);
  TEST_TRUE(Ea == E1 && Eb == E2 && E1 != E2);
  TEST_TRUE(same(fint, fint1, n) && same(f, f1, n));

  /* Errors. */
  fcm_linear_form bad = fcm_linear_form_default();
  bad.term = (fcm_linear_term)17;
  TEST_ERR(ctx, fcm_assembly_workspace_linear(ws, &bad, K, f), FCM_ERR_ARG, "term = 17");
  TEST_ERR(ctx, fcm_assembly_workspace_linear(ws, NULL, K, f), FCM_ERR_ARG, "NULL");
  bad.term = FCM_LINEAR_STIFFNESS; /* material NULL */
  TEST_ERR(ctx, fcm_assembly_workspace_linear(ws, &bad, K, NULL), FCM_ERR_ARG, "NULL");
  bad.term = FCM_LINEAR_SURFACE_TRACTION; /* a plain space has no surface rules */
  bad.field = gravity_field;
  TEST_ERR(ctx, fcm_assembly_workspace_linear(ws, &bad, NULL, f), FCM_ERR_ARG, "surface rules");
  TEST_ERR(ctx, fcm_assembly_workspace_hyperelastic(ws, NULL, u, &E, NULL, NULL), FCM_ERR_ARG,
           "NULL");
  TEST_TRUE(fcm_assembly_workspace_create(space, NULL, NULL) == FCM_ERR_ARG);

  fcm_assembly_workspace_destroy(&ws);
  fcm_assembly_workspace_destroy(&ws2);
  fcm_assembly_workspace_destroy(&ws2); /* NULL is accepted */
  TEST_TRUE(ws == NULL && ws2 == NULL);
  fcm_csr_destroy(&K), fcm_csr_destroy(&M), fcm_csr_destroy(&T);
  fcm_csr_destroy(&K1), fcm_csr_destroy(&M1), fcm_csr_destroy(&T1);
  free(u), free(u2), free(f), free(fint), free(f1), free(fint1);
  fcm_space_destroy(&owned);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
