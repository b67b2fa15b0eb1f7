/* The pieces' finder of the embedded surface (piece_locate.c) on a box body in a 4^3 Hex8 grid
 * cut by a tilted plane:
 *   - fcm__embed_finder_near_cut(): a point on the plane inside the cut is near it for a width
 *     of 1e-12, one 1e-3 off it only for a width above 1e-3, one beyond the cut's edges never;
 *     without cuts nothing is near;
 *   - every point that parts of two pieces hold (fcm__embed_finder_point() gives -2) is near a
 *     cut within a millionth of the box, and points off the plane inside the body, in a cell
 *     the plane splits, lie in one of the cell's pieces;
 *   - after fcm__embed_finder_release() and the rules set again, every answer is the same. */
#include "embed/embed_impl.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NPT 7 /* points per cell */

static fcm_ctx *ctx;

/* Point k of cell c: its centre moved onto the plane (point at, unit normal n), then along n;
 * returns whether it lies inside the cell and the body, clear of their faces. */
static int cell_point(const fcm_mesh *mesh, fcm_index c, int k, const double n[3],
                      const double at[3], double x[3])
{
  double X[3 * FCM_ELEMENT_MAX_NODES], m[3] = {0, 0, 0};
  fcm_mesh_cell_coords(mesh, c, X);
  for (int a = 0; a < 8; a++)
    for (int d = 0; d < 3; d++)
      m[d] += X[3 * a + d] / 8.0;
  /* the centre moved onto the plane, then off it by -0.05 .. 0.05 along n */
  double s = 0.0;
  for (int d = 0; d < 3; d++)
    s += (m[d] - at[d]) * n[d];
  const double off = 0.05 * (double)(k - NPT / 2) / (double)(NPT / 2);
  int in = 1;
  for (int d = 0; d < 3; d++) {
    x[d] = m[d] - s * n[d] + off * n[d];
    in = in && fabs(x[d]) < 0.69 && fabs(x[d] - m[d]) < 0.249; /* body 0.7, cells 0.25 */
  }
  return in;
}

static void answers(fcm__embed_finder *f, const fcm_mesh *mesh, const fcm_cell_rules *r,
                    const double n[3], const double at[3], fcm_index *ans)
{
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++)
    for (int k = 0; k < NPT; k++) {
      double x[3];
      (void)cell_point(mesh, c, k, n, at, x);
      fcm_index p = -3;
      if (fcm_cell_rules_num_pieces(r) > 0) TEST_OK(ctx, fcm__embed_finder_point(f, c, x, &p));
      ans[NPT * c + k] = p;
    }
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r0 = NULL, *r1 = NULL;
  fcm_surface *plane = NULL;
  fcm__embed_finder *f = NULL;
  fcm_index *ans = NULL, *again = NULL;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, glo[3] = {-0.7, -0.7, -0.7},
               ghi[3] = {0.7, 0.7, 0.7}, bl[3] = {-1.5, -1.5, -1.5}, bh[3] = {1.5, 1.5, 1.5};
  const fcm_index n3[3] = {4, 4, 4};
  const double pp[3] = {0.05, 0.02, -0.03},
               pn[3] = {0.8164965809277261, 0.4082482904638631, 0.4082482904638631};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, n3, &g));
  if (!mesh || !g) goto done;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.kinds = FCM_RULES_STIFFNESS;
  o.simplify = FCM_CELL_SIMPLIFY_OFF;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r0));
  TEST_OK(ctx, fcm_surface_create_plane(ctx, pp, pn, bl, bh, &plane));
  if (!r0 || !plane) goto done;
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r0, plane, &r1));
  TEST_OK(ctx, fcm__embed_finder_create(ctx, mesh, g, &f));
  if (!r1 || !f) goto done;
  double at[3];
  for (int d = 0; d < 3; d++)
    at[d] = pp[d] + fcm_cell_rules_get_stats(r1)->cut_shift[d];

  /* without cuts nothing is near */
  int near = -1;
  TEST_OK(ctx, fcm__embed_finder_set_rules(f, r0));
  TEST_OK(ctx, fcm__embed_finder_near_cut(f, at, 1.0, &near));
  TEST_TRUE(near == 0);

  TEST_OK(ctx, fcm__embed_finder_set_rules(f, r1));
  TEST_OK(ctx, fcm__embed_finder_near_cut(f, at, 1e-12, &near));
  TEST_TRUE(near == 1);
  double x[3];
  for (int d = 0; d < 3; d++)
    x[d] = at[d] + 1e-3 * pn[d];
  TEST_OK(ctx, fcm__embed_finder_near_cut(f, x, 1e-4, &near));
  TEST_TRUE(near == 0);
  TEST_OK(ctx, fcm__embed_finder_near_cut(f, x, 2e-3, &near));
  TEST_TRUE(near == 1);
  /* on the plane, beyond the cut's edges (the plane's square reaches 1.65 from its centre) */
  const double u[3] = {0.0, 0.7071067811865476, -0.7071067811865476}; /* u . pn = 0 */
  for (int d = 0; d < 3; d++)
    x[d] = at[d] + 4.0 * u[d];
  TEST_OK(ctx, fcm__embed_finder_near_cut(f, x, 1e-6, &near));
  TEST_TRUE(near == 0);

  const fcm_index nc = fcm_mesh_num_cells(mesh);
  ans = malloc(sizeof *ans * (size_t)(NPT * nc));
  again = malloc(sizeof *again * (size_t)(NPT * nc));
  if (!ans || !again) goto done;
  answers(f, mesh, r1, pn, at, ans);
  int on = 0, off = 0;
  for (fcm_index c = 0; c < nc; c++) {
    const int split =
        fcm_cell_rules_num_pieces(r1) > 0 && r1->piece_off[c + 1] - r1->piece_off[c] > 1;
    for (int k = 0; k < NPT; k++) {
      const fcm_index p = ans[NPT * c + k];
      double y[3];
      const int in = cell_point(mesh, c, k, pn, at, y);
      if (p == -2) {
        TEST_OK(ctx, fcm__embed_finder_near_cut(f, y, 2e-6, &near));
        TEST_TRUE(near == 1);
        on++;
      }
      if (split && in && k != NPT / 2) { /* off the plane, in a cell it splits: one piece */
        TEST_TRUE(p >= r1->piece_off[c] && p < r1->piece_off[c + 1]);
        off++;
      }
    }
  }
  TEST_TRUE(on > 0 && off > 0);
  /* released, the rules set again: the same answers */
  fcm__embed_finder_release(f);
  fcm__embed_finder_release(f);
  TEST_OK(ctx, fcm__embed_finder_set_rules(f, r1));
  answers(f, mesh, r1, pn, at, again);
  TEST_TRUE(!memcmp(ans, again, sizeof *ans * (size_t)(NPT * nc)));
  fcm__embed_finder_release(NULL);
done:
  free(ans), free(again);
  fcm__embed_finder_destroy(&f);
  fcm_surface_destroy(&plane);
  fcm_cell_rules_destroy(&r1);
  fcm_cell_rules_destroy(&r0);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
