/* fcm_space_locate on a crowded mesh and on failure:
 * - a fan of 2,000 thin tets around the z axis puts a point in hundreds of cell boxes
 *   (more than the 256 candidates the search keeps at first): every point built inside a
 *   cell is found in that cell, not extrapolated, and maps back to itself;
 * - with an allocator failing the k-th allocation, every failing call returns
 *   FCM_ERR_ALLOC with an out-of-memory message (not a geometry error), and the first
 *   k that succeeds gives the same cells as without failures;
 * - several points far from every cell: FCM_ERR_GEOMETRY naming the lowest such point,
 *   the same on every run and with 1 or several threads. */
#include "fem_util.h"

#include <omp.h>
#include <stdatomic.h>

enum { NFAN = 2000, NP = 200 };

static atomic_llong alloc_count;
static long long fail_at = -1;

static void *counting_alloc(void *user, size_t size)
{
  (void)user;
  long long k = atomic_fetch_add(&alloc_count, 1);
  return fail_at >= 0 && k == fail_at ? NULL : malloc(size);
}

static void counting_release(void *user, void *p)
{
  (void)user;
  free(p);
}

/* Tets (O, Z, P_k, P_k+1) with O, Z on the axis and P_k on a circle at mid-height. */
static fcm_status fan_mesh(fcm_ctx *ctx, fcm_mesh **mesh)
{
  double *X = malloc(sizeof *X * 3 * (NFAN + 2));
  fcm_index *cells = malloc(sizeof *cells * 4 * NFAN);
  X[0] = X[1] = X[2] = 0.0;
  X[3] = X[4] = 0.0, X[5] = 1.0;
  for (int k = 0; k < NFAN; k++) {
    double t = 2.0 * 3.14159265358979323846 * k / NFAN;
    X[3 * (k + 2)] = cos(t), X[3 * (k + 2) + 1] = sin(t), X[3 * (k + 2) + 2] = 0.5;
  }
  for (int k = 0; k < NFAN; k++) {
    fcm_index *c = cells + 4 * k;
    /* positively oriented: det(P_k - O, P_k+1 - O, Z - O) = sin(2 pi / NFAN) > 0 */
    c[0] = 0, c[1] = k + 2, c[2] = (k + 1) % NFAN + 2, c[3] = 1;
  }
  fcm_status st = fcm_mesh_create(ctx, FCM_ELEMENT_TET4, NFAN + 2, X, NFAN, cells, mesh);
  free(X), free(cells);
  return st;
}

int main(void)
{
  fcm_ctx_options o = fcm_ctx_options_default();
  o.allocator.alloc = counting_alloc;
  o.allocator.release = counting_release;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  TEST_OK(ctx, fcm_ctx_create(&o, &ctx));
  TEST_OK(ctx, fan_mesh(ctx, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  if (!space) return TEST_RESULT();

  /* points inside cells 0, 10, 20, ...: convex combinations with weights >= 0.1 */
  double P[3 * NP], xi[3 * NP];
  fcm_index cell[NP], home[NP];
  int ex[NP];
  unsigned long long seed = 3;
  const double *Xn = fcm_mesh_coords(mesh);
  for (int i = 0; i < NP; i++) {
    fcm_index c = (fcm_index)i * (NFAN / NP);
    const fcm_index *cn = fcm_mesh_cells(mesh) + 4 * c;
    double w[4], sum = 0.0;
    for (int a = 0; a < 4; a++)
      sum += (w[a] = 0.1 + 0.5 * (1.0 + urand(&seed)));
    for (int d = 0; d < 3; d++) {
      P[3 * i + d] = 0.0;
      for (int a = 0; a < 4; a++)
        P[3 * i + d] += w[a] / sum * Xn[3 * cn[a] + d];
    }
    home[i] = c;
  }
  TEST_OK(ctx, fcm_space_locate(space, NP, P, cell, xi, ex));
  int extrapolated = 0, wrong = 0;
  for (int i = 0; i < NP; i++) {
    double Xc[12], x[3];
    extrapolated += ex[i] != 0;
    wrong += cell[i] != home[i];
    fcm_mesh_cell_coords(mesh, cell[i], Xc);
    fcm_element_map(FCM_ELEMENT_TET4, Xc, xi + 3 * i, x);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(x[d], P[3 * i + d], 0.0, 1e-12);
  }
  TEST_TRUE(extrapolated == 0);
  TEST_TRUE(wrong == 0);
  if (extrapolated || wrong)
    fprintf(stderr, "%d of %d points extrapolated, %d in another cell\n", extrapolated, NP, wrong);

  /* allocation failures: FCM_ERR_ALLOC every time, until the call succeeds */
  {
    enum { NA = 16 };
    fcm_index c2[NA];
    int failures = 0, other = 0;
    for (long long k = 0;; k++) {
      atomic_store(&alloc_count, 0);
      fail_at = k;
      fcm_status st = fcm_space_locate(space, NA, P, c2, xi, ex);
      fail_at = -1;
      if (st == FCM_OK) break;
      failures++;
      if (st != FCM_ERR_ALLOC || !strstr(fcm_ctx_error_message(ctx), "out of memory")) {
        if (other++ < 3)
          fprintf(stderr, "allocation %lld failed: %s \"%s\"\n", k, fcm_status_name(st),
                  fcm_ctx_error_message(ctx));
      }
      fcm_ctx_error_clear(ctx);
      if (k > 100000) break;
    }
    TEST_TRUE(failures > NA && other == 0); /* at least one allocation per point failed */
    for (int i = 0; i < NA; i++)
      TEST_TRUE(c2[i] == home[i]);
  }

  /* points 5, 9 and 13 far from every cell: the error names point 5, on every run */
  {
    double Q[3 * 20];
    fcm_index c3[20];
    memcpy(Q, P, sizeof Q);
    const int far[3] = {13, 5, 9};
    for (int j = 0; j < 3; j++)
      Q[3 * far[j]] = 1e12 * (j + 1);
    const int threads[3] = {1, 2, 4};
    for (int run = 0; run < 12; run++) {
      omp_set_num_threads(threads[run % 3]);
      TEST_ERR(ctx, fcm_space_locate(space, 20, Q, c3, xi, ex), FCM_ERR_GEOMETRY,
               "point 5 (2e+12, ");
    }
  }
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
