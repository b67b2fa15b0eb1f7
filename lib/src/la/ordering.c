/* A fill-reducing ordering of a symmetric pattern whose rows come in groups (the DOFs of a
 * node): AMD on the graph of the groups, each group's rows then kept together. */
#include "la/la_impl.h"

#include <amd.h>
#include <string.h>

fcm_status fcm__amd_group_ordering(fcm_ctx *ctx, const fcm_csr *A, fcm_index ngroup,
                                   const fcm_index *group, fcm_index *perm)
{
  fcm_status st = FCM_OK;
  SuiteSparse_long *gp = NULL, *gi = NULL, *order = NULL;
  fcm_index *mark = NULL, *rp = NULL, *rows = NULL;
  FCM_CHECK(ctx && A && (group || A->nrows == 0) && (perm || A->nrows == 0) && ngroup >= 0, ctx,
            FCM_ERR_ARG, "amd_group_ordering: NULL argument or ngroup = %lld < 0",
            (long long)ngroup);
  const fcm_index n = A->nrows;
  FCM_CHECK(A->ncols == n, ctx, FCM_ERR_ARG, "amd_group_ordering: A is %lld x %lld, not square",
            (long long)n, (long long)A->ncols);
  if (n == 0) goto cleanup;
  /* the rows of each group, ascending (a counting sort) */
  FCM_ALLOC(ctx, ngroup + 2, rp);
  FCM_ALLOC_RAW(ctx, n, rows);
  for (fcm_index i = 0; i < n; i++) {
    FCM_CHECK(group[i] >= 0 && group[i] < ngroup, ctx, FCM_ERR_ARG,
              "amd_group_ordering: row %lld is in group %lld, outside [0, %lld)", (long long)i,
              (long long)group[i], (long long)ngroup);
    rp[group[i] + 2]++;
  }
  for (fcm_index g = 0; g < ngroup; g++)
    rp[g + 2] += rp[g + 1];
  for (fcm_index i = 0; i < n; i++)
    rows[rp[group[i] + 1]++] = i;
  /* the groups' graph, column by column: a group neighbours every group one of its rows has
   * an entry in (the diagonal block left out, as AMD ignores it) */
  FCM_ALLOC_RAW(ctx, ngroup, mark);
  for (fcm_index g = 0; g < ngroup; g++)
    mark[g] = -1;
  FCM_ALLOC(ctx, ngroup + 1, gp);
  for (int pass = 0; pass < 2; pass++) {
    SuiteSparse_long cnt = 0;
    for (fcm_index g = 0; g < ngroup; g++) {
      mark[g] = pass ? -2 - g : g;
      for (fcm_index q = rp[g]; q < rp[g + 1]; q++)
        for (fcm_index p = A->row_ptr[rows[q]]; p < A->row_ptr[rows[q] + 1]; p++) {
          const fcm_index h = group[A->col_idx[p]];
          if (mark[h] == (pass ? -2 - g : g)) continue;
          mark[h] = pass ? -2 - g : g;
          if (pass) gi[cnt] = (SuiteSparse_long)h;
          cnt++;
        }
      if (!pass) gp[g + 1] = cnt;
    }
    if (!pass) FCM_ALLOC_RAW(ctx, (size_t)FCM_MAX(cnt, 1), gi);
  }
  FCM_ALLOC_RAW(ctx, ngroup + 1, order);
  double control[AMD_CONTROL], info[AMD_INFO];
  amd_l_defaults(control);
  const SuiteSparse_long ok = amd_l_order((SuiteSparse_long)ngroup, gp, gi, order, control, info);
  FCM_CHECK(ok != AMD_OUT_OF_MEMORY, ctx, FCM_ERR_ALLOC,
            "amd_group_ordering: AMD ran out of memory on %lld groups", (long long)ngroup);
  FCM_CHECK(ok == AMD_OK || ok == AMD_OK_BUT_JUMBLED, ctx, FCM_ERR_INTERNAL,
            "amd_group_ordering: AMD refused the graph of %lld groups (status %ld)",
            (long long)ngroup, (long)ok);
  fcm_index k = 0;
  for (fcm_index j = 0; j < ngroup; j++) {
    const fcm_index g = (fcm_index)order[j];
    for (fcm_index q = rp[g]; q < rp[g + 1]; q++)
      perm[k++] = rows[q];
  }
cleanup:
  fcm__free(ctx, gp);
  fcm__free(ctx, gi);
  fcm__free(ctx, order);
  fcm__free(ctx, mark);
  fcm__free(ctx, rp);
  fcm__free(ctx, rows);
  return st;
}
