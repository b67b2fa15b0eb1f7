/* The integrator after a cut keeps what the cut leaves valid (fcm_integrator_options.cut_reuse):
 * the element blocks of the mass matrix and the loads of the elements the cut leaves as they
 * were, and the fill-reducing ordering of the direct solver's analysis, extended by the new DOFs
 * beside the ones they split from (fem/cut_update.c), so that the new analysis computes only
 * the factor's structure; and it may take the old integrator's large arrays (the matrices'
 * values) for its own, on pages already mapped. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"

#include <string.h>

fcm_status fcm__integrator_set_ordering(fcm_integrator *I, const fcm_index *perm)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I ? I->ctx : NULL;
  FCM_CHECK(I && perm, ctx, FCM_ERR_ARG, "integrator ordering: NULL integrator or ordering");
  FCM_CHECK(!I->is_setup, ctx, FCM_ERR_ARG,
            "integrator ordering: the integrator is set up already (its analysis is done)");
  if (!I->cut_ordering) FCM_ALLOC_RAW(ctx, (size_t)I->n + 1, I->cut_ordering);
  memcpy(I->cut_ordering, perm, sizeof *perm * (size_t)I->n);
cleanup:
  return st;
}

fcm_status fcm__integrator_get_ordering(const fcm_integrator *I, fcm_index *perm)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I ? I->ctx : NULL;
  FCM_CHECK(I && perm, ctx, FCM_ERR_ARG, "integrator ordering: NULL integrator or ordering");
  FCM_CHECK(I->chol, ctx, FCM_ERR_ARG,
            "integrator ordering: the integrator has no CHOLMOD analysis (linear_solver "
            "direct with direct_method cholmod, after fcm_integrator_setup())");
  FCM_TRY(ctx, fcm__direct_get_ordering(I->chol, perm));
cleanup:
  return st;
}

fcm_status fcm__sim_cut_ordering(const fcm_integrator *old, fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  fcm_index *old_perm = NULL;
  if (!(I->opts.cut_reuse & FCM_CUT_REUSE_ORDERING) || !old->chol || I->backend.factor ||
      I->opts.linear_solver != FCM_LINEAR_DIRECT || I->opts.direct_method != FCM_DIRECT_CHOLMOD)
    return FCM_OK;
  FCM_ALLOC_RAW(ctx, (size_t)old->n + 1, old_perm);
  if (!I->cut_ordering) FCM_ALLOC_RAW(ctx, (size_t)I->n + 1, I->cut_ordering);
  FCM_TRY(ctx, fcm__integrator_get_ordering(old, old_perm));
  FCM_TRY(ctx, fcm__space_cut_ordering(old->space, I->space, old_perm, I->cut_ordering));
cleanup:
  fcm__free(ctx, old_perm);
  return st;
}

/* 1 when I keeps element blocks: the option, on a full serial embedded space. */
static int keeps_blocks(const fcm_integrator *I)
{
  return (I->opts.cut_reuse & FCM_CUT_REUSE_BLOCKS) && I->space->rules && !I->space->is_local &&
         !fcm__integrator_distributed(I, NULL);
}

/* The old blocks *give (an array of fcm__calloc_large()) as I's blocks, each kept element's
 * moved to its own place (same[e] <= e, ascending over the kept elements: a pass downwards
 * moves each once), *give then NULL; NULL (nothing taken) when they are not in that order or
 * the array's room does not fit. */
static double *take_blocks(const fcm_integrator *I, int bs, double **give)
{
  const fcm_index ne = I->space->num_elems, *same = I->cut_same;
  int in_order = give && *give && same;
  for (fcm_index e = 0, last = -1; in_order && e < ne; e++)
    if (same[e] >= 0) in_order = same[e] <= e && same[e] > last, last = same[e];
  void *from = in_order ? *give : NULL;
  double *b = fcm__large_take(&from, (size_t)ne * bs + 1, sizeof *b);
  if (!b) return NULL;
  *give = NULL;
  for (fcm_index e = ne - 1; e >= 0; e--)
    if (same[e] >= 0 && same[e] != e)
      memmove(b + (size_t)e * bs, b + (size_t)same[e] * bs, sizeof *b * (size_t)bs);
  return b;
}

fcm_status fcm__sim_assemble_kept(fcm_integrator *I, const fcm_linear_form *form, fcm_csr *A,
                                  double *f, double **blocks, const double *old_blocks,
                                  double **give)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  if (!keeps_blocks(I)) return fcm_assembly_workspace_linear(I->aws, form, A, f);
  const int bs = fcm__assembly_block_size(I->space, form->term);
  const fcm_index ne = I->space->num_elems;
  const fcm_index *same = I->cut_same && old_blocks ? I->cut_same : NULL;
  fcm__free_large(ctx, *blocks);
  *blocks = same && I->cut_give ? take_blocks(I, bs, give) : NULL;
  if (*blocks) { /* in place: each kept element reads its own block */
    if (!I->cut_self) {
      FCM_ALLOC_RAW(ctx, (size_t)ne + 1, I->cut_self);
      for (fcm_index e = 0; e < ne; e++)
        I->cut_self[e] = same[e] >= 0 ? e : -1;
    }
    same = I->cut_self, old_blocks = *blocks;
  } else { /* below FCM__LARGE_MIN fcm__calloc_large() gives no room: a quarter more asked for,
              so that the next cut's blocks fit in place (take_blocks()); the room mapped now
              where a cut will take them, not when it writes them */
    const size_t n = (size_t)ne * bs + 1, room = n * sizeof **blocks < FCM__LARGE_MIN ? n / 4 : 0;
    FCM__ALLOC_WITH(fcm__calloc_large, ctx, n + room, *blocks);
    if (I->opts.cut_reuse & FCM_CUT_REUSE_STORAGE) fcm__large_map(*blocks);
  }
  FCM_TRY(ctx, fcm__assembly_linear_blocks_rows(I->aws, form, A, f, same, old_blocks, *blocks,
                                                I->cut_rows ? I->cut_dirty : NULL));
cleanup:
  return st;
}

/* I->cut_rows: the space's cut_row_from (rows whose terms and their order the cut left)
 * where every element using the copy keeps its block, and only while the old copies ascend
 * (so the rows move within one array: move_rows()). Serial full embedded spaces (keeps_blocks())
 * without hanging nodes. */
static fcm_status prepare_rows(const fcm_integrator *old, fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_space *s = I->space, *from = old->space;
  if (!s->cut_row_from || s->cut_from != from || s->cut_from_dofs != from->num_dofs ||
      s->cut_from_elems != from->num_elems || I->hP || old->hP || !I->cut_same)
    return FCM_OK;
  const fcm_index ncopy = s->num_dofs / 3;
  const int nn = s->nn;
  FCM_ALLOC_RAW(ctx, (size_t)ncopy + 1, I->cut_rows);
  FCM_ALLOC_RAW(ctx, (size_t)ncopy + 1, I->cut_dirty);
  memcpy(I->cut_rows, s->cut_row_from, sizeof *I->cut_rows * (size_t)ncopy);
  for (fcm_index e = 0; e < s->num_elems; e++)
    if (I->cut_same[e] < 0)
      for (int a = 0; a < nn; a++)
        I->cut_rows[s->elem_dof[e * nn + a] / 3] = -1;
  fcm_index last = -1, kept = 0;
  for (fcm_index k = 0; k < ncopy; k++) {
    fcm_index p = I->cut_rows[k];
    if (p >= 0 && (p <= last || s->node_ptr[k + 1] - s->node_ptr[k] !=
                                    from->node_ptr[p + 1] - from->node_ptr[p]))
      p = I->cut_rows[k] = -1;
    if (p >= 0) last = p, kept++;
    I->cut_dirty[k] = (unsigned char)(p < 0);
  }
  I->cut_kept_copies = kept;
cleanup:
  return st;
}

/* Matrix rows by copy: copy k's three rows [rp[3k], rp[3k + 3]) take old copy rows[k]'s
 * [orp[3p], orp[3p + 3]) (as long; rows[k] ascending over the kept copies), the other copies'
 * are zeroed. Within one array (src == dst) the rows moving down go first, lowest first, then
 * the rows moving up, highest first: the destinations and the sources ascend with the copies,
 * so no row's source is written before the row has moved. */
static void move_rows(const fcm_index *rows, fcm_index ncopy, const fcm_index *rp,
                      const fcm_index *orp, const double *src, double *dst)
{
  for (fcm_index k = 0; k < ncopy; k++) {
    const fcm_index p = rows[k], d = rp[3 * k];
    if (p >= 0 && (src != dst || d < orp[3 * p]))
      memmove(dst + d, src + orp[3 * p], sizeof *dst * (size_t)(rp[3 * k + 3] - d));
  }
  for (fcm_index k = ncopy - 1; src == dst && k >= 0; k--) {
    const fcm_index p = rows[k], d = rp[3 * k];
    if (p >= 0 && d > orp[3 * p])
      memmove(dst + d, src + orp[3 * p], sizeof *dst * (size_t)(rp[3 * k + 3] - d));
  }
  for (fcm_index k = 0; k < ncopy; k++)
    if (rows[k] < 0) memset(dst + rp[3 * k], 0, sizeof *dst * (size_t)(rp[3 * k + 3] - rp[3 * k]));
}

fcm_status fcm__sim_cut_mass_matrix(fcm_integrator *I, fcm_csr **M)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  fcm_csr *give = I->cut_give ? I->cut_give->M : NULL;
  int taken = 0;
  if (!I->cut_rows) return fcm__space_matrix_create_rows_from(I->space, give, M);
  FCM_TRY(ctx, fcm__space_matrix_create_rows_keep(I->space, give, M, &taken));
  double *dst = fcm_csr_values(*M);
  const double *src = taken ? dst : fcm_csr_values_read(I->cut_old->M);
  move_rows(I->cut_rows, I->space->num_dofs / 3, I->space->row_ptr, I->cut_old->space->row_ptr, src,
            dst);
cleanup:
  return st;
}

int fcm__sim_cut_rep_force(fcm_integrator *I)
{
  const double *old = I->cut_old ? I->cut_old->Ma : NULL;
  if (!I->cut_rows || !old || !I->M) return 0;
  const fcm_index ncopy = I->space->num_dofs / 3;
  for (fcm_index c = 0; c < ncopy; c++) {
    const fcm_index p = I->cut_rows[c];
    if (p >= 0)
      I->Ma[3 * c] = old[3 * p], I->Ma[3 * c + 1] = old[3 * p + 1],
                I->Ma[3 * c + 2] = old[3 * p + 2];
  }
  fcm__csr_apply_rows(I->M, I->w1, I->Ma, I->cut_dirty);
  return 1;
}

void fcm__sim_cut_load(const fcm_integrator *I, int k, double *f)
{
  const double *of = I->cut_old->loads[k].f;
  const fcm_index ncopy = I->space->num_dofs / 3;
  for (fcm_index c = 0; c < ncopy; c++) {
    const fcm_index p = I->cut_rows[c];
    if (p >= 0) f[3 * c] = of[3 * p], f[3 * c + 1] = of[3 * p + 1], f[3 * c + 2] = of[3 * p + 2];
  }
}

fcm_status fcm__sim_cut_prepare_blocks(const fcm_integrator *old, fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  fcm_index kept = 0;
  if (!keeps_blocks(I) || !keeps_blocks(old)) return FCM_OK;
  FCM_FREE(ctx, I->cut_same);
  FCM_ALLOC_RAW(ctx, (size_t)I->space->num_elems + 1, I->cut_same);
  FCM_TRY(ctx, fcm__space_cut_same_elements(old->space, I->space, I->cut_same, &kept));
  I->cut_old = old;
  I->setup_info.cut_kept_elements = kept;
  FCM_TRY(ctx, prepare_rows(old, I));
cleanup:
  return st;
}

void fcm__sim_cut_give_storage(const fcm_integrator *old, fcm_integrator *I)
{
  /* old's options name the flag (the caller's consent to old's storage going to I): old is
   * destroyed after a successful cut and has its storage back after a failed one, so its
   * arrays are taken although old is given const. Serial only: giving back after a failure
   * assembles old's mass matrix again, which a distributed run would have to agree on. */
  const int serial =
      !fcm__integrator_distributed(old, NULL) && !fcm__integrator_distributed(I, NULL);
  I->cut_give =
      (old->opts.cut_reuse & FCM_CUT_REUSE_STORAGE) && serial ? (fcm_integrator *)old : NULL;
}

void fcm__sim_cut_give_back(fcm_integrator *I, fcm_integrator *old)
{
  fcm_status st = FCM_OK;
  /* the pattern's columns the cut space took from old's space (fcm__space_create_cut_take())
   * go back first: old's matrices name them. The cut space is its owner's to destroy next. */
  if (I->space->col_from == old->space) fcm__space_cut_give_back((fcm_space *)I->space);
  fcm__csr_give_back(I->H, old->H); /* assembled again at old's next iteration */
  old->h_state = SIM_H_INVALID;
  /* the kept factorization stays: the direct solver holds its factor and its copy of the
   * factored values (fcm_direct), none of them given; a backend solves with H itself */
  if (old->backend.factor) old->kept = 0;
  if (I->aws && old->aws) fcm__assembly_corot_give_back(I->aws, old->aws);
  if (fcm__csr_give_back(I->M, old->M)) { /* the mass matrix, assembled again now */
    fcm_index nnz = 0;
    fcm_csr_get_size(old->M, NULL, NULL, &nnz);
    memset(fcm_csr_values(old->M), 0, sizeof(double) * (size_t)nnz);
    fcm_linear_form form = fcm_linear_form_default();
    form.material = &old->mat;
    form.term = FCM_LINEAR_MASS;
    st = fcm_assembly_workspace_linear(old->aws, &form, old->M, NULL);
  }
  if (st != FCM_OK) old->spent = 1, old->is_setup = 0; /* without its mass matrix */
}
