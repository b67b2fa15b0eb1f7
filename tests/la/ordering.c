/* The grouped AMD ordering (fcm__amd_group_ordering) on a vector field's 7-point stencil on a
 * G^3 grid, its DOFs numbered at random and some nodes holding fewer than three DOFs: the
 * ordering is a permutation with each node's DOFs together and ascending; given to CHOLMOD it
 * makes a factor within 10 % of AMD's on the DOFs, 50 % of CHOLMOD's best of AMD and METIS (a
 * regular grid, where METIS's nested dissection wins) and under a fifth of the numbering's
 * own, and solves to a relative residual of 1e-10; argument errors;
 * allocation failures. */
#include "alloc_loop.h"
#include "la/la_impl.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>

enum { G = 10, NNODE = G * G * G };

/* The DOFs: node v's component c is DOF dof[3 v + c] (-1: the node lacks it; every 7th node
 * its last component, every 11th its first), numbered in a random order; group[i]: DOF i's
 * node. Returns the number of DOFs. */
static fcm_index make_dofs(rng *r, fcm_index *dof, fcm_index *group)
{
  fcm_index n = 0;
  for (fcm_index v = 0; v < NNODE; v++)
    for (int c = 0; c < 3; c++)
      dof[3 * v + c] = (c == 2 && v % 7 == 3) || (c == 0 && v % 11 == 5) ? -1 : n++;
  fcm_index *shuffle = malloc((size_t)n * sizeof *shuffle);
  for (fcm_index i = 0; i < n; i++)
    shuffle[i] = i;
  for (fcm_index i = n - 1; i > 0; i--) {
    const fcm_index j = (fcm_index)((rng_uniform(r) + 1.0) * 0.5 * (double)(i + 1)) % (i + 1);
    const fcm_index t = shuffle[i];
    shuffle[i] = shuffle[j], shuffle[j] = t;
  }
  for (fcm_index v = 0; v < NNODE; v++)
    for (int c = 0; c < 3; c++)
      if (dof[3 * v + c] >= 0) {
        dof[3 * v + c] = shuffle[dof[3 * v + c]];
        group[dof[3 * v + c]] = v;
      }
  free(shuffle);
  return n;
}

/* The vector 7-point stencil: every DOF of a node coupled with every DOF of the node and of
 * its six neighbours; diagonal 12 + 6 (definite), off-diagonal -1 / (1 + |c - d|). */
static fcm_csr *stencil_matrix(fcm_ctx *ctx, const fcm_index *dof, fcm_index n)
{
  const size_t cap = (size_t)NNODE * 7 * 9;
  fcm_index *ti = malloc(cap * sizeof *ti), *tj = malloc(cap * sizeof *tj), t = 0;
  double *tv = malloc(cap * sizeof *tv);
  const int nb[7][3] = {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0},
                        {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  for (int z = 0; z < G; z++)
    for (int y = 0; y < G; y++)
      for (int x = 0; x < G; x++) {
        const fcm_index v = x + (fcm_index)G * (y + (fcm_index)G * z);
        for (int k = 0; k < 7; k++) {
          const int xx = x + nb[k][0], yy = y + nb[k][1], zz = z + nb[k][2];
          if (xx < 0 || yy < 0 || zz < 0 || xx >= G || yy >= G || zz >= G) continue;
          const fcm_index w = xx + (fcm_index)G * (yy + (fcm_index)G * zz);
          for (int c = 0; c < 3; c++)
            for (int d = 0; d < 3; d++) {
              if (dof[3 * v + c] < 0 || dof[3 * w + d] < 0) continue;
              ti[t] = dof[3 * v + c], tj[t] = dof[3 * w + d];
              tv[t++] = k == 0 && c == d ? 18.0 : -1.0 / (1.0 + abs(c - d));
            }
        }
      }
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, n, n, t, ti, tj, tv, FCM_CSR_SYMMETRIC, &A));
  free(ti), free(tj), free(tv);
  return A;
}

/* The factor's entries of A analyzed with the ordering perm (NULL: CHOLMOD's own). */
static double factor_entries(fcm_ctx *ctx, const fcm_csr *A, const fcm_index *perm)
{
  fcm_direct *s = NULL;
  fcm_direct_info info = {0};
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &s));
  if (perm) TEST_OK(ctx, fcm__direct_set_ordering(s, perm));
  TEST_OK(ctx, fcm_direct_analyze(s));
  fcm_direct_get_info(s, &info);
  fcm_direct_destroy(&s);
  return info.factor_nnz;
}

typedef struct alloc_case {
  fcm_ctx *ctx;
  const fcm_csr *A;
  fcm_index ngroup;
  const fcm_index *group;
  fcm_index *perm;
} alloc_case;

static fcm_status alloc_call_order(void *user)
{
  alloc_case *c = user;
  return fcm__amd_group_ordering(c->ctx, c->A, c->ngroup, c->group, c->perm);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  rng r = {12345};
  fcm_index *dof = malloc(3 * (size_t)NNODE * sizeof *dof);
  fcm_index *group = malloc(3 * (size_t)NNODE * sizeof *group);
  const fcm_index n = make_dofs(&r, dof, group);
  fcm_csr *A = stencil_matrix(ctx, dof, n);
  fcm_index *perm = malloc((size_t)n * sizeof *perm), *natural = malloc((size_t)n * sizeof *perm);
  TEST_OK(ctx, fcm__amd_group_ordering(ctx, A, NNODE, group, perm));

  /* a permutation, each node's DOFs together and ascending */
  unsigned char *seen = calloc((size_t)n, 1), *done = calloc(NNODE, 1);
  int bad = 0;
  for (fcm_index k = 0; k < n && !bad; k++) {
    if (perm[k] < 0 || perm[k] >= n || seen[perm[k]]) {
      bad = 1;
      break;
    }
    seen[perm[k]] = 1;
    const fcm_index v = group[perm[k]];
    const int same = k > 0 && group[perm[k - 1]] == v;
    if (same ? perm[k - 1] >= perm[k] : done[v]) bad = 1; /* split or out of order */
    done[v] = 1;
  }
  TEST_TRUE(!bad);

  /* the factor against CHOLMOD's orderings and the numbering's own */
  for (fcm_index i = 0; i < n; i++)
    natural[i] = i;
  fcm_index *alone = malloc((size_t)n * sizeof *alone);
  TEST_OK(ctx, fcm__amd_group_ordering(ctx, A, n, natural, alone)); /* a group per DOF: AMD */
  const double grouped = factor_entries(ctx, A, perm), amd = factor_entries(ctx, A, alone),
               own = factor_entries(ctx, A, NULL);
  const double plain = factor_entries(ctx, A, natural);
  printf("factor entries: grouped AMD %.0f, AMD on the DOFs %.0f, CHOLMOD's AMD and METIS %.0f, "
         "the numbering %.0f\n",
         grouped, amd, own, plain);
  TEST_TRUE(grouped > 0.0 && grouped <= 1.1 * amd);
  TEST_TRUE(grouped <= 1.5 * own);
  TEST_TRUE(grouped < 0.2 * plain);

  /* a solve on the grouped ordering */
  {
    fcm_direct *s = NULL;
    double *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x);
    for (fcm_index i = 0; i < n; i++)
      b[i] = rng_uniform(&r);
    TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &s));
    TEST_OK(ctx, fcm__direct_set_ordering(s, perm));
    TEST_OK(ctx, fcm_direct_analyze(s));
    TEST_OK(ctx, fcm_direct_factor(s, fcm_csr_values_read(A)));
    TEST_OK(ctx, fcm_direct_solve(s, b, x));
    double rmax = 0.0, bmax = 0.0;
    fcm_csr_apply(A, 1.0, x, -1.0, b); /* b := A x - b */
    for (fcm_index i = 0; i < n; i++)
      rmax = fmax(rmax, fabs(b[i])), bmax = fmax(bmax, fabs(x[i]));
    TEST_TRUE(rmax <= 1e-10 * 24.0 * bmax);
    fcm_direct_destroy(&s);
    free(b), free(x);
  }

  /* argument errors */
  group[7] = NNODE;
  TEST_ERR(ctx, fcm__amd_group_ordering(ctx, A, NNODE, group, perm), FCM_ERR_ARG,
           "outside [0, 1000)");
  group[7] = -1;
  TEST_ERR(ctx, fcm__amd_group_ordering(ctx, A, NNODE, group, perm), FCM_ERR_ARG, "outside");
  TEST_ERR(ctx, fcm__amd_group_ordering(ctx, A, -1, group, perm), FCM_ERR_ARG, "ngroup = -1");
  TEST_ERR(ctx, fcm__amd_group_ordering(ctx, A, NNODE, NULL, perm), FCM_ERR_ARG, "NULL");
  {
    fcm_csr *B = NULL;
    const fcm_index ti[1] = {0}, tj[1] = {1};
    const double tv[1] = {1.0};
    TEST_OK(ctx, fcm_csr_create_triplets(ctx, 3, 4, 1, ti, tj, tv, FCM_CSR_GENERAL, &B));
    TEST_ERR(ctx, fcm__amd_group_ordering(ctx, B, 1, group, perm), FCM_ERR_ARG, "not square");
    fcm_csr_destroy(&B);
  }
  group[7] = 7 / 3; /* any node: only the range is checked */

  fcm_csr_destroy(&A);
  fcm_ctx_destroy(&ctx);
  {
    failing f;
    fcm_ctx *fctx = failing_ctx(&f);
    TEST_TRUE(fctx != NULL);
    fcm_csr *Af = stencil_matrix(fctx, dof, n);
    alloc_case c = {fctx, Af, NNODE, group, perm};
    for (fcm_index i = 0; i < 3 * NNODE; i++)
      if (dof[i] >= 0) group[dof[i]] = i / 3;
    alloc_loop(fctx, &f, "amd_group_ordering", alloc_call_order, NULL, &c, 4, 50);
    fcm_csr_destroy(&Af);
    fcm_ctx_destroy(&fctx);
  }
  free(dof), free(group), free(perm), free(natural), free(seen), free(done), free(alone);
  return TEST_RESULT();
}
