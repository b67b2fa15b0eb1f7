/* fcm_space_eval() interpolates a DOF vector at a reference point of a cell: a linear field
 * u(X) = A X + b, given by its nodal values, is reproduced exactly at mapped reference points
 * of every cell (all four element types contain the linear polynomials); a cell without
 * unknowns and a cell out of range are FCM_ERR_ARG. */
#include "fcm/fcm.h"
#include "test.h"

static void field(const double x[3], double u[3])
{
  static const double A[9] = {0.3, -1.2, 0.5, 2.0, 0.1, -0.7, -0.4, 0.9, 1.5};
  static const double b[3] = {0.25, -2.0, 1.0};
  for (int i = 0; i < 3; i++)
    u[i] = A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2] + b[i];
}

int main(int argc, char **argv)
{
  fcm_element_type type;
  if (argc < 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {-1, 0, 2}, hi[3] = {1, 1.5, 3};
  const fcm_index n[3] = {2, 2, 1};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  if (!mesh) return TEST_RESULT();
  const fcm_index nc = fcm_mesh_num_cells(mesh), nn = fcm_mesh_num_nodes(mesh);
  unsigned char *active = malloc((size_t)nc);
  for (fcm_index c = 0; c < nc; c++)
    active[c] = c != 0; /* cell 0 left out */
  TEST_OK(ctx, fcm_space_create(ctx, mesh, active, &space));
  if (!space) return TEST_RESULT();
  const fcm_index ndof = fcm_space_num_dofs(space);
  double *u = calloc((size_t)ndof, sizeof *u);
  const double *X = fcm_mesh_coords(mesh);
  for (fcm_index a = 0; a < nn; a++) {
    fcm_index dof = fcm_space_node_dof(space, a);
    if (dof >= 0) field(X + 3 * a, u + dof);
  }
  const fcm_element_info *info = fcm_mesh_get_element_info(mesh);
  const double *ref = fcm_element_ref_nodes(type);
  const double inner[3] = {0.2, 0.3, 0.1}; /* inside both reference elements */
  double *Xc = malloc(3 * (size_t)info->num_nodes * sizeof *Xc);
  for (fcm_index c = 1; c < nc; c++) {
    fcm_mesh_cell_coords(mesh, c, Xc);
    for (int k = 0; k <= info->num_nodes; k++) {
      const double *xi = k < info->num_nodes ? ref + 3 * k : inner;
      double x[3], want[3], got[3];
      fcm_element_map(type, Xc, xi, x);
      field(x, want);
      TEST_OK(ctx, fcm_space_eval(space, c, xi, u, got));
      for (int i = 0; i < 3; i++)
        TEST_NEAR(got[i], want[i], 1e-13, 1e-13);
    }
  }
  double v[3];
  TEST_ERR(ctx, fcm_space_eval(space, 0, inner, u, v), FCM_ERR_ARG, "cell 0 is out of range");
  char msg[64];
  snprintf(msg, sizeof msg, "cell %lld is out of range", (long long)nc);
  TEST_ERR(ctx, fcm_space_eval(space, nc, inner, u, v), FCM_ERR_ARG, msg);
  free(Xc);
  free(u);
  free(active);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
