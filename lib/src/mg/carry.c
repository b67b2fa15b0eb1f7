/* A hierarchy carried over a cut (fcm__mg_create_pattern_cut()): the new hierarchy's cells,
 * copies and prolongations are built anew (they are cheap), and each level's Galerkin plan
 * takes the rows of A P and of the coarse pattern that the cut left from the hierarchy before
 * the cut, through maps from the old numbering of each level to the new one; every row taken
 * is checked entry by entry against its inputs (fcm__ptap_create_from()), so the result is
 * fcm__mg_create_pattern()'s bit for bit whatever the maps are, provided level 0's matrices
 * have their spaces' patterns (the old one at its creation, the new one now: level 0's rows
 * are compared through the two spaces' copy graphs, not the matrices). Where that, or any
 * other precondition, fails nothing is carried (the plain creation), without an error.
 *
 * The maps: level 0's from the space (a copy of the new space that is the only child of a copy
 * before the cut: fcm__space_cut_copy_map()); level l + 1's from level l's and the two
 * prolongations: a fine row that maps, with as many entries in P_l before and after, pairs its
 * coarse columns position by position; a coarse row paired with two different ones, or two
 * old rows paired with one new row, map to nothing. */
#include "fem/fem_impl.h"
#include "mg/levels_impl.h"

#include <string.h>

const fcm_space *fcm__mg_pattern_of(const fcm_space *space, const fcm_csr *A)
{
  if (!space || !A || space->is_local || !space->row_ptr || !space->col_idx) return NULL;
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  if (rp == space->row_ptr && ci == space->col_idx) return space; /* shared (borrowed) */
  fcm_index n = 0;
  fcm_csr_get_size(A, &n, NULL, NULL);
  if (n != space->num_dofs || memcmp(rp, space->row_ptr, sizeof *rp * (size_t)(n + 1)) != 0 ||
      memcmp(ci, space->col_idx, sizeof *ci * (size_t)rp[n]) != 0)
    return NULL;
  return space;
}

/* May level 0 be mapped: both hierarchies grid ones on their spaces' patterns (old on
 * old_space's), the spaces full and a cut pair with their copy graphs
 * (fcm__space_cut_copy_map()'s preconditions, tested without recording an error)? */
static int carry_possible(const fcm_mg *m, const mg_carry *c)
{
  const fcm_mg *old = c->old;
  const fcm_space *from = c->old_space, *to = m->space;
  if (!from || !to || old->oct_mesh[1] || m->oct_mesh[1]) return 0;
  if (old->pattern_of != from || m->pattern_of != to) return 0;
  if (old->lev[0].n != fcm_space_num_dofs(from) || m->lev[0].n != fcm_space_num_dofs(to)) return 0;
  if (from->mesh != to->mesh || !from->rules || !to->rules || from->local_elem || to->local_elem ||
      !from->node_ptr || !from->node_adj || !to->node_ptr || !to->node_adj)
    return 0;
  const fcm_index pieces = fcm_cell_rules_parent_num_pieces(to->rules);
  return pieces > 0 && pieces == fcm_cell_rules_num_pieces(from->rules);
}

/* m's space when level 0 is on its pattern, a full space with its copy graph; else NULL. */
static const fcm_space *level0_graph(const fcm_mg *m)
{
  const fcm_space *sp = m->pattern_of;
  return sp && sp == m->space && !sp->local_copy && sp->node_ptr && sp->node_adj &&
                 m->lev[0].n == 3 * sp->num_local_copies
             ? sp
             : NULL;
}

/* The first place in copy k's graph row whose copy is not below k (k's own, if it is there). */
static fcm_index own_slot(const fcm_space *sp, fcm_index k)
{
  return fcm__lower_bound(sp->node_adj, 1, sp->node_ptr[k], sp->node_ptr[k + 1], k);
}

int fcm__mg_space_triples(const fcm_mg *m, unsigned char *triple)
{
  const fcm_space *sp = level0_graph(m);
  if (!sp) return 0;
  const fcm_index nk = sp->num_local_copies;
  int ok = 1;
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) reduction(&& : ok) \
    if (nk > 4096)
  for (fcm_index k = 0; k < nk; k++) { /* the row holds its own copy: the diagonal's node */
    const fcm_index lo = own_slot(sp, k);
    const int own = lo < sp->node_ptr[k + 1] && sp->node_adj[lo] == k;
    ok = ok && own;
    triple[3 * k] = (unsigned char)(own ? FCM__MG_TRIPLE_NODES : 0);
    triple[3 * k + 1] = triple[3 * k + 2] = 0;
  }
  return ok;
}

int fcm__mg_space_diag(const fcm_mg *m, fcm_index *diag)
{
  const fcm_space *sp = level0_graph(m);
  if (!sp) return 0;
  const fcm_index nk = sp->num_local_copies, *rp = sp->row_ptr;
  int ok = 1;
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) reduction(&& : ok) \
    if (nk > 4096)
  for (fcm_index k = 0; k < nk; k++) {
    const fcm_index lo = own_slot(sp, k);
    /* the row's columns are the graph row's copies' three each (the space's pattern), so
     * its length and k's place in the graph row tell where column i lies (the columns are
     * not read: a cache miss a row) */
    const fcm_index deg = sp->node_ptr[k + 1] - sp->node_ptr[k], q = lo - sp->node_ptr[k];
    const int own = lo < sp->node_ptr[k + 1] && sp->node_adj[lo] == k;
    for (fcm_index c = 0; c < 3; c++) {
      const fcm_index i = 3 * k + c;
      const int found = own && rp[i + 1] - rp[i] == 3 * deg;
      ok = ok && found;
      diag[i] = found ? rp[i] + 3 * q + c : -1;
    }
  }
  return ok;
}

int fcm__mg_space_reach(const fcm_mg *m, fcm_index *reach)
{
  const fcm_space *sp = level0_graph(m);
  if (!sp) return 0;
  const fcm_index nk = sp->num_local_copies, *rp = sp->row_ptr;
  int ok = 1;
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) reduction(&& : ok) \
    if (nk > 4096)
  for (fcm_index k = 0; k < nk; k++) {
    /* the last column: the graph row's last copy's third (its columns are not read) */
    const fcm_index deg = sp->node_ptr[k + 1] - sp->node_ptr[k];
    const fcm_index last = deg > 0 ? 3 * sp->node_adj[sp->node_ptr[k + 1] - 1] + 2 : -1;
    for (fcm_index c = 0; c < 3; c++) {
      const fcm_index i = 3 * k + c;
      ok = ok && rp[i + 1] - rp[i] == 3 * deg;
      reach[i] = FCM_MAX(i, last);
    }
  }
  return ok;
}

void fcm__mg_carry_free(fcm_ctx *ctx, mg_carry *c)
{
  for (int l = 0; l < MG_MAX_LEVELS; l++) {
    fcm__free(ctx, c->row_old[l]);
    fcm__free(ctx, c->row_new[l]);
    fcm__free(ctx, c->crow_same[l]);
  }
  fcm__free(ctx, c->copy_same);
  c->copy_same = NULL;
  memset(c->crow_same, 0, sizeof c->crow_same);
  memset(c->row_old, 0, sizeof c->row_old);
  memset(c->row_new, 0, sizeof c->row_new);
  c->nlev = 0;
}

/* Level l + 1's maps from level l's and the prolongations P_l of old and m. */
static fcm_status coarse_map(fcm_mg *m, mg_carry *c, int l)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const mg_level *O = &c->old->lev[l], *L = &m->lev[l];
  const fcm_index no = c->old->lev[l + 1].n, nn = m->lev[l + 1].n;
  fcm_index *cand = NULL, *back = NULL;
  FCM_ALLOC_RAW(ctx, no + 1, cand); /* every entry written below */
  FCM_ALLOC_RAW(ctx, nn + 1, back);
  for (fcm_index o = 0; o < no; o++)
    cand[o] = -1;
  for (fcm_index i = 0; i < nn; i++)
    back[i] = -1;
  const fcm_index *ro = c->row_old[l];
  for (fcm_index i = 0; i < L->n; i++) {
    const fcm_index io = ro[i];
    if (io < 0) continue;
    const fcm_index len = L->P_ptr[i + 1] - L->P_ptr[i];
    if (O->P_ptr[io + 1] - O->P_ptr[io] != len) continue;
    for (fcm_index q = 0; q < len; q++) {
      const fcm_index o = O->P_col[O->P_ptr[io] + q], w = L->P_col[L->P_ptr[i] + q];
      cand[o] = cand[o] == -1 || cand[o] == w ? w : -2;
    }
  }
  for (fcm_index o = 0; o < no; o++)
    if (cand[o] >= 0) back[cand[o]] = back[cand[o]] == -1 ? o : -2;
  for (fcm_index o = 0; o < no; o++)
    if (cand[o] >= 0 && back[cand[o]] != o) cand[o] = -1;
  for (fcm_index i = 0; i < nn; i++)
    if (back[i] < 0) back[i] = -1;
  for (fcm_index o = 0; o < no; o++)
    if (cand[o] < 0) cand[o] = -1;
  c->row_new[l + 1] = cand, c->row_old[l + 1] = back;
  cand = back = NULL;
cleanup:
  fcm__free(ctx, cand);
  fcm__free(ctx, back);
  return st;
}

/* Are copy k's three rows of level 0's matrix the old copy's rows mapped, column for column
 * in the same order (the copy graphs' rows: old graph[0], graph[1]; new graph[2], graph[3])? */
static int same_copy_rows(const mg_carry *c, fcm_index k)
{
  const fcm_index *ro = c->row_old[0] + 3 * k, *rn = c->row_new[0];
  if (ro[0] < 0 || ro[0] % 3 != 0 || ro[1] != ro[0] + 1 || ro[2] != ro[0] + 2) return 0;
  const fcm_index g = ro[0] / 3, deg = c->graph[0][g + 1] - c->graph[0][g];
  if (c->graph[2][k + 1] - c->graph[2][k] != deg) return 0;
  const fcm_index *adj = c->graph[1] + c->graph[0][g], *nadj = c->graph[3] + c->graph[2][k];
  for (fcm_index q = 0; q < deg; q++)
    if (rn[3 * adj[q]] != 3 * nadj[q]) return 0; /* the DOFs of a copy map together */
  return 1;
}

fcm_status fcm__mg_carry_maps(fcm_mg *m, mg_carry *c)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  fcm_index *old_copy = NULL;
  const fcm_mg *old = c->old;
  const fcm_index n = m->lev[0].n, no = old->lev[0].n;
  c->nlev = 0;
  if (!carry_possible(m, c)) return FCM_OK;
  FCM_ALLOC(ctx, n / 3 + 1, old_copy);
  FCM_TRY(ctx, fcm__space_cut_copy_map(c->old_space, m->space, old_copy, c->graph));
  FCM_ALLOC(ctx, n + 1, c->row_old[0]);
  FCM_ALLOC(ctx, no + 1, c->row_new[0]);
  for (fcm_index i = 0; i < no; i++)
    c->row_new[0][i] = -1;
  for (fcm_index i = 0; i < n; i++) {
    const fcm_index k = old_copy[i / 3];
    c->row_old[0][i] = k >= 0 ? 3 * k + i % 3 : -1;
    if (k >= 0) c->row_new[0][3 * k + i % 3] = i;
  }
  FCM_ALLOC_RAW(ctx, n / 3 + 1, c->copy_same); /* every entry written below */
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) if (n / 3 > 4096)
  for (fcm_index k = 0; k < n / 3; k++)
    c->copy_same[k] = (unsigned char)same_copy_rows(c, k);
  c->nlev = 1;
  const int nl = FCM_MIN(m->nlev, old->nlev);
  for (int l = 0; l + 1 < nl; l++) {
    if (!old->lev[l].P_ptr || !m->lev[l].P_ptr) break;
    FCM_TRY(ctx, coarse_map(m, c, l));
    c->nlev = l + 2;
  }
cleanup:
  fcm__free(ctx, old_copy);
  return st;
}

fcm_status fcm__mg_carry_blocks_prior(const fcm_mg *m, const mg_carry *c, int l,
                                      fcm__schwarz_prior *pr, unsigned char **rows_same, int *has)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  *has = 0;
  *rows_same = NULL;
  if (!c || c->nlev <= l || l >= c->old->nlev || !c->old->lev[l].blk || l + 1 >= m->nlev ||
      (l > 0 && !c->crow_same[l]))
    return FCM_OK;
  const fcm_index nk = m->lev[l].n / 3;
  const unsigned char *cs = c->crow_same[l];
  unsigned char *same = NULL;
  FCM_ALLOC_RAW(ctx, nk + 1, same); /* every entry written below */
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) if (nk > 4096)
  for (fcm_index k = 0; k < nk; k++)
    same[k] =
        (unsigned char)(l == 0 ? c->copy_same[k] : cs[3 * k] && cs[3 * k + 1] && cs[3 * k + 2]);
  pr->old = c->old->lev[l].blk;
  pr->row_old = c->row_old[l];
  pr->same = same;
  *rows_same = same;
  *has = 1;
cleanup:
  return st;
}

int fcm__mg_carry_prior(const fcm_mg *m, const mg_carry *c, int l, fcm__ptap_prior *pr)
{
  if (!c || l + 1 >= c->nlev) return 0;
  const mg_level *O = &c->old->lev[l], *OC = &c->old->lev[l + 1];
  if (!O->ptap || !OC->Aown || m->lev[l + 1].n <= 0) return 0;
  memset(pr, 0, sizeof *pr);
  pr->plan = O->ptap;
  pr->C = OC->Aown;
  if (l == 0) {
    pr->A_ptr = c->graph[0], pr->A_adj = c->graph[1];
    pr->G_ptr = c->graph[2], pr->G_adj = c->graph[3];
    pr->copy_same = c->copy_same;
  } else {
    pr->A_ptr = fcm_csr_row_ptr(O->Aown), pr->A_col = fcm_csr_col_idx(O->Aown);
  }
  pr->row_old = c->row_old[l], pr->row_new = c->row_new[l];
  pr->crow_old = c->row_old[l + 1], pr->crow_new = c->row_new[l + 1];
  return 1;
}
