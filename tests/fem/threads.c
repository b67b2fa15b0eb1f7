/* The context's thread count governs the library's parallel loops: a body-force density
 * evaluated inside the assembly's parallel region sees a team of exactly the context's
 * count (fcm_ctx_set_num_threads()), whatever OpenMP's default is, and OpenMP's default
 * when the count is FCM_DEFAULT; the force is bitwise the same for every count. */
#include "fem_util.h"

#include <omp.h>
#include <string.h>

static int team; /* the largest team size the field saw */

static void field(void *user, const double x[3], const double normal[3], double value[3])
{
  (void)user, (void)normal;
  const int n = omp_get_num_threads();
#pragma omp critical(fcm_test_threads)
  if (n > team) team = n;
  value[0] = x[1], value[1] = -x[0], value[2] = 1.0 + x[2];
}

/* Assemble the body force with the context's count `ctx_threads` and OpenMP's default
 * `omp_threads`; the team size the field saw goes to *seen. */
static void assemble(fcm_ctx *ctx, const fcm_space *space, int ctx_threads, int omp_threads,
                     double *f, int *seen)
{
  omp_set_num_threads(omp_threads);
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, ctx_threads));
  memset(f, 0, sizeof *f * (size_t)fcm_space_num_dofs(space));
  team = 0;
  TEST_OK(ctx, fcm_assemble_body_force_field(space, field, NULL, NULL, f));
  *seen = team;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  omp_set_dynamic(0);
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, distorted_box(ctx, FCM_ELEMENT_HEX8, 4, 0.2, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  const fcm_index n = fcm_space_num_dofs(space);
  double *f1 = calloc((size_t)n, sizeof *f1), *f2 = calloc((size_t)n, sizeof *f2),
         *f3 = calloc((size_t)n, sizeof *f3);
  int seen = 0;
  assemble(ctx, space, 1, 3, f1, &seen);
  TEST_TRUE(seen == 1); /* the context's 1, not OpenMP's 3 */
  assemble(ctx, space, 2, 1, f2, &seen);
  TEST_TRUE(seen == 2); /* the context's 2, not OpenMP's 1 */
  assemble(ctx, space, FCM_DEFAULT, 3, f3, &seen);
  TEST_TRUE(seen == 3); /* OpenMP's default */
  TEST_TRUE(fcm_ctx_num_threads(ctx) == 3);
  TEST_TRUE(memcmp(f1, f2, sizeof *f1 * (size_t)n) == 0);
  TEST_TRUE(memcmp(f1, f3, sizeof *f1 * (size_t)n) == 0);
  free(f1), free(f2), free(f3);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
