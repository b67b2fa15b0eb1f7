/* Assembly's blocks (runs of FCM__SPACE_BLOCK Morton-ordered cells, coloured by the mesh nodes
 * they touch) on spaces without a plain structured grid: every local element in exactly one
 * block, in a block of its own cell, and no two blocks of one colour sharing a DOF copy, on
 * - a Hex8 octree refined around a ball (hanging nodes; cells of three sizes),
 * - a Tet4 box with an embedded box cut by a plane, tiny copies constrained (Koschier: an
 *   element uses a copy of another node in a tiny copy's place),
 * - a local space of half the cells of the octree (the blocks over the local cells only);
 * and a cut space patched from the one before (no constrained copies) takes the blocks and
 * their colours (blocks_kept, the same block_cells, block_color_ptr and block_list) while a
 * space built anew on the same rules has the same arrays; on a larger box the cut space takes
 * the rows of 95 % or more of the copies away from the cut (their elements keep their places
 * in the visit). Usage: fem_block_colors */
#include "cut_away.h"
#include "fem/fem_impl.h"
#include "test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

/* Each local element once in the blocks, in its cell's block; the blocks of a colour pairwise
 * without a shared copy. Returns the number of blocks. */
static fcm_index check_blocks(const fcm_space *s)
{
  const fcm_index ne = s->num_local_elems, nb = s->num_blocks, ncopy = s->num_dofs / 3;
  TEST_TRUE(nb == (s->num_block_cells + FCM__SPACE_BLOCK - 1) / FCM__SPACE_BLOCK);
  TEST_TRUE(s->num_block_colors >= 1 && s->block_color_ptr[s->num_block_colors] == nb);
  TEST_TRUE(s->block_ptr[0] == 0 && s->block_ptr[nb] == ne);
  unsigned char *seen = calloc((size_t)nb + 1, 1), *once = calloc((size_t)ne + 1, 1);
  fcm_index *owner = malloc(sizeof *owner * (size_t)(ncopy + 1));
  fcm_index *cell_block = malloc(sizeof *cell_block * (size_t)(s->num_cells + 1));
  for (fcm_index c = 0; c < s->num_cells; c++)
    cell_block[c] = -1;
  for (fcm_index i = 0; i < s->num_block_cells; i++)
    cell_block[s->block_cells[i]] = i / FCM__SPACE_BLOCK;
  for (int c = 0; c < s->num_block_colors; c++) {
    for (fcm_index k = 0; k < ncopy; k++)
      owner[k] = -1;
    for (fcm_index i = s->block_color_ptr[c]; i < s->block_color_ptr[c + 1]; i++) {
      const fcm_index b = s->block_list[i];
      TEST_TRUE(b >= 0 && b < nb && !seen[b]);
      if (b < 0 || b >= nb) continue;
      seen[b] = 1;
      for (fcm_index j = s->block_ptr[b]; j < s->block_ptr[b + 1]; j++) {
        const fcm_index le = s->block_elems[j];
        TEST_TRUE(le >= 0 && le < ne && !once[le]);
        if (le < 0 || le >= ne) continue;
        once[le] = 1;
        const fcm_index e = s->local_elem ? s->local_elem[le] : le;
        TEST_TRUE(cell_block[s->elem_cell[e]] == b);
        for (int a = 0; a < s->nn; a++) {
          const fcm_index k = s->elem_dof[e * s->nn + a] / 3;
          TEST_TRUE(owner[k] < 0 || owner[k] == b);
          owner[k] = b;
        }
      }
    }
  }
  for (fcm_index b = 0; b < nb; b++)
    TEST_TRUE(seen[b]);
  for (fcm_index le = 0; le < ne; le++)
    TEST_TRUE(once[le]);
  free(seen), free(once), free(owner), free(cell_block);
  return nb;
}

static int same_index(const fcm_index *a, const fcm_index *b, fcm_index n)
{
  return n == 0 || (a && b && memcmp(a, b, sizeof *a * (size_t)n) == 0);
}

/* The octree around a ball: the full space and a local space of every other cell. */
static void octree(void)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.48, 0.51, 0.5};
  const fcm_index cells[3] = {6, 6, 6};
  fcm_geometry *ball = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *s = NULL, *loc = NULL;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.3, 3, &ball));
  fcm_octree_options o = fcm_octree_options_default();
  o.refine = fcm_geometry_boundary_meets_box;
  o.refine_user = ball;
  o.refine_level = 2;
  TEST_OK(ctx, fcm_mesh_create_octree(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &o, &mesh));
  TEST_TRUE(fcm_mesh_max_level(mesh) == 2 && fcm_mesh_num_hanging(mesh) > 0);
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &s));
  if (s) TEST_TRUE(check_blocks(s) >= 8 && s->num_block_colors > 1);
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  unsigned char *mask = calloc((size_t)nc, 1);
  for (fcm_index i = 0; i < nc; i += 2)
    mask[i] = 1;
  TEST_OK(ctx, fcm__space_create_local(ctx, mesh, NULL, NULL, NULL, mask, &loc));
  if (loc) TEST_TRUE(check_blocks(loc) >= 4 && loc->num_local_elems < loc->num_elems);
  free(mask);
  fcm_space_destroy(&loc);
  fcm_space_destroy(&s);
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&ball);
}

/* The share of the copies away from the cut whose rows the cut space takes from the space
 * before it (cut_row_from): a copy is away when no element using it lies in a cell touching a
 * node of a cell the cut reached (a cell with other elements, or an element integrated
 * otherwise). *num_away: their number. */
static double away_share(const fcm_space *s0, const fcm_space *s1, fcm_index *num_away)
{
  const fcm_index ncopy = s1->num_dofs / 3;
  unsigned char *away = malloc((size_t)ncopy + 1);
  const fcm_index n = cut_away_copies(ctx, s0, s1, away);
  fcm_index taken = 0;
  for (fcm_index k = 0; k < ncopy; k++)
    taken += away[k] && s1->cut_row_from && s1->cut_row_from[k] >= 0;
  free(away);
  *num_away = n;
  return n ? (double)taken / (double)n : 0.0;
}

/* A Hex8 box of 8,000 cells (63 blocks) with an embedded box cut by a plane through its
 * middle: the elements away from the cut keep their places in the assembly's visit, so the
 * cut space takes the rows of every copy away from the cut. */
static void away_rows(void)
{
  const double lo[3] = {-0.05, -0.05, -0.05}, hi[3] = {1.05, 1.05, 1.05};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 1, 1};
  const fcm_index nc[3] = {20, 20, 20}, gn[3] = {2, 2, 2};
  const double p[3] = {0.52, 0.5, 0.5}, n[3] = {1.0, 0.1, 0.05};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_surface *cut = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_space *s0 = NULL, *s1 = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &r0));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, r0, &s0));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, n, lo, hi, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1));
  if (r1) TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, r1, NULL, s0, &s1));
  if (s0 && s1) {
    fcm_index away = 0;
    const double share = away_share(s0, s1, &away);
    if (getenv("FCM_TEST_VERBOSE"))
      printf("rows taken: %.3f of %lld copies away from the cut (%lld copies)\n", share,
             (long long)away, (long long)(s1->num_dofs / 3));
    TEST_TRUE(s0->num_blocks > 32 && away > s1->num_dofs / 3 / 4 && share >= 0.95);
  }
  fcm_space_destroy(&s1);
  fcm_space_destroy(&s0);
  fcm_cell_rules_destroy(&r1);
  fcm_cell_rules_destroy(&r0);
  fcm_surface_destroy(&cut);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

/* An embedded box cut by a plane (constraint ratio `ratio`); returns 1 when the cut space had
 * constrained copies. */
static int cut_box(fcm_element_type type, double ratio)
{
  const double lo[3] = {-0.3, -0.3, -0.3}, hi[3] = {1.3, 0.9, 0.9};
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.6, 0.6};
  const fcm_index nc[3] = {12, 9, 9}, gn[3] = {2, 2, 2};
  const double box_lo[3] = {-0.2, -0.2, -0.2}, box_hi[3] = {1.2, 0.8, 0.8};
  const double p[3] = {0.47, 0.3, 0.3}, n[3] = {1.0, 0.05, 0.0};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_surface *cut = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_space *s0 = NULL, *s1 = NULL, *fresh = NULL;
  fcm_space_options so = fcm_space_options_default();
  so.constrain_ratio = ratio;
  int con = 0;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, nc, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, NULL, &r0));
  TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, r0, &so, &s0));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, n, box_lo, box_hi, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, cut, &r1));
  if (r1) TEST_OK(ctx, fcm__space_create_cut(ctx, mesh, r1, &so, s0, &s1));
  if (r1) TEST_OK(ctx, fcm_space_create_embedded_with(ctx, mesh, r1, &so, &fresh));
  if (s0 && s1 && fresh) {
    con = s1->elem_con != NULL;
    check_blocks(s0);
    TEST_TRUE(check_blocks(s1) > 1);
    TEST_TRUE(s1->num_elems > s0->num_elems && s1->blocks_kept == !con && !fresh->blocks_kept);
    /* the same blocks and colours whether patched or built anew; without constrained copies
     * the cut changes neither (only the elements of the cells it reaches) */
    TEST_TRUE(s1->num_blocks == fresh->num_blocks &&
              s1->num_block_colors == fresh->num_block_colors);
    TEST_TRUE(same_index(s1->block_cells, fresh->block_cells, s1->num_block_cells) &&
              same_index(s1->block_list, fresh->block_list, s1->num_blocks) &&
              same_index(s1->block_ptr, fresh->block_ptr, s1->num_blocks + 1) &&
              same_index(s1->block_elems, fresh->block_elems, s1->num_elems) &&
              same_index(s1->block_color_ptr, fresh->block_color_ptr, s1->num_block_colors + 1));
    if (!con)
      TEST_TRUE(s1->num_block_colors == s0->num_block_colors &&
                same_index(s1->block_list, s0->block_list, s0->num_blocks) &&
                same_index(s1->block_cells, s0->block_cells, s0->num_block_cells));
  }
  fcm_space_destroy(&fresh);
  fcm_space_destroy(&s1);
  fcm_space_destroy(&s0);
  fcm_cell_rules_destroy(&r1);
  fcm_cell_rules_destroy(&r0);
  fcm_surface_destroy(&cut);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  return con;
}

int main(void)
{
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  octree();
  TEST_TRUE(cut_box(FCM_ELEMENT_TET4, 0.2) == 1); /* constrained copies */
  TEST_TRUE(cut_box(FCM_ELEMENT_TET4, fcm_space_options_default().constrain_ratio) == 0);
  TEST_TRUE(cut_box(FCM_ELEMENT_HEX8, fcm_space_options_default().constrain_ratio) == 0);
  away_rows();
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
