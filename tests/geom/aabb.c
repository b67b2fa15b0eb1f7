/* AABB tree: queries return exactly the boxes a brute-force scan finds, ascending, for
 * random boxes of mixed sizes (including degenerate flat and point boxes); an empty tree
 * answers nothing; count > capacity reports the count; bad arguments fail cleanly. The bounds
 * (fcm__geom_tree_bounds()) are the boxes' least and greatest coordinates; an empty tree has
 * none. */
#include "fcm/geom.h"
#include "geom/geom_impl.h"
#include "exact.h"
#include "test.h"

#include <stdlib.h>

#define NBOX 2000

static double boxes[6 * NBOX];

static int overlap(const double *b, const double lo[3], const double hi[3])
{
  for (int d = 0; d < 3; d++)
    if (b[d] > hi[d] || lo[d] > b[3 + d]) return 0;
  return 1;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  unsigned long long rng = 99;
  for (int i = 0; i < NBOX; i++)
    for (int d = 0; d < 3; d++) {
      const double c = exact_rand(&rng), h = i % 7 == 0 ? 0.0 : 0.05 * exact_rand(&rng);
      boxes[6 * i + d] = c - h, boxes[6 * i + 3 + d] = c + h;
    }
  fcm_aabb_tree *tree = NULL;
  TEST_OK(ctx, fcm_aabb_tree_create(ctx, NBOX, boxes, &tree));
  fcm_index *ids = malloc(NBOX * sizeof *ids);
  if (tree) {
    double blo[3], bhi[3];
    int same = fcm__geom_tree_bounds(tree, blo, bhi);
    for (int d = 0; d < 3; d++) {
      double a = boxes[d], b = boxes[3 + d];
      for (int i = 1; i < NBOX; i++)
        a = boxes[6 * i + d] < a ? boxes[6 * i + d] : a,
        b = boxes[6 * i + 3 + d] > b ? boxes[6 * i + 3 + d] : b;
      same = same && blo[d] == a && bhi[d] == b;
    }
    TEST_TRUE(same);
  }
  for (int q = 0; q < 300; q++) {
    double lo[3], hi[3];
    for (int d = 0; d < 3; d++) {
      const double c = 1.2 * exact_rand(&rng) - 0.1, h = q % 5 == 0 ? 0.0 : 0.2 * exact_rand(&rng);
      lo[d] = c - h, hi[d] = c + h;
    }
    fcm_index count = -1;
    TEST_OK(ctx, fcm_aabb_tree_query(tree, lo, hi, NBOX, ids, &count));
    fcm_index expect = 0, k = 0;
    int same = 1;
    for (int i = 0; i < NBOX; i++)
      if (overlap(boxes + 6 * i, lo, hi)) {
        expect++;
        same &= k < count && ids[k++] == i; /* ascending, the same ids */
      }
    TEST_TRUE(count == expect && same);
    if (expect > 1) { /* too small a buffer: count only */
      fcm_index c2 = -1;
      TEST_OK(ctx, fcm_aabb_tree_query(tree, lo, hi, 1, ids, &c2));
      TEST_TRUE(c2 == expect);
    }
  }
  /* Touching boxes (closed intervals) overlap. */
  {
    const double lo[3] = {boxes[3], boxes[4], boxes[5]}, hi[3] = {2, 2, 2};
    fcm_index count = 0;
    TEST_OK(ctx, fcm_aabb_tree_query(tree, lo, hi, NBOX, ids, &count));
    int found = 0;
    for (fcm_index i = 0; i < count; i++)
      found |= ids[i] == 0;
    TEST_TRUE(found);
  }
  /* Errors. */
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, nanv[3] = {NAN, 0, 0};
  fcm_index count;
  TEST_ERR(ctx, fcm_aabb_tree_query(tree, nanv, hi, NBOX, ids, &count), FCM_ERR_ARG, "NaN");
  TEST_ERR(ctx, fcm_aabb_tree_query(tree, lo, hi, 5, NULL, &count), FCM_ERR_ARG, "capacity");
  TEST_ERR(ctx, fcm_aabb_tree_query(tree, lo, hi, 5, ids, NULL), FCM_ERR_ARG, "NULL");
  fcm_aabb_tree_destroy(&tree);
  TEST_TRUE(tree == NULL);
  double bad[6] = {0, 0, 0, 1, -1, 1};
  tree = (fcm_aabb_tree *)ids;
  TEST_ERR(ctx, fcm_aabb_tree_create(ctx, 1, bad, &tree), FCM_ERR_ARG, "box 0 has lo[1]");
  TEST_TRUE(tree == NULL);
  TEST_ERR(ctx, fcm_aabb_tree_create(ctx, -1, bad, &tree), FCM_ERR_ARG, "n = -1");
  /* Empty tree. */
  TEST_OK(ctx, fcm_aabb_tree_create(ctx, 0, NULL, &tree));
  TEST_OK(ctx, fcm_aabb_tree_query(tree, lo, hi, 0, NULL, &count));
  TEST_TRUE(count == 0);
  double elo[3], ehi[3];
  if (tree) TEST_TRUE(fcm__geom_tree_bounds(tree, elo, ehi) == 0);
  fcm_aabb_tree_destroy(&tree);
  fcm_aabb_tree_destroy(NULL);
  free(ids);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
