/* fcm__embed_crop_geometry() (the part of the geometry a distributed rules build reads, the
 * PETSc backend's crop), serially: a ball sticking out of a Hex8 grid (outside volumes), the
 * cells with centroid x < 0.45 classified here, every other one of them owned (points). Asserts
 * - the crop: fewer cells than the whole, every boundary triangle (the surface path reads
 *   lines through the whole body; with moments = volume fewer triangles), original order (ascending
 *   original ids), coordinates of every kept cell and triangle bit for bit the original ones,
 *   the whole geometry's volume and bounding box, triangle cells mapped or -1;
 * - a distributed build on the crop (the other cells' classes handed over from the whole
 *   build, as the exchange of fcm/petsc.h does) equals the build on the whole geometry bit for
 *   bit: every cell's class, fraction, pieces and piece volumes, the owned cells' volume and
 *   surface rules (original triangle ids), and the statistics of the whole geometry (volume,
 *   bounding box, embedded volume, outside volume per side);
 * - errors: invalid options give the rules build's message; a crop used with another mesh
 *   is refused. */
#include "embed/embed_impl.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int same_bits(const double *a, const double *b, size_t n)
{
  return n == 0 || memcmp(a, b, n * sizeof *a) == 0;
}

/* The serial stand-in of the PETSc exchange: the remote cells' class, fraction and embedded
 * volume from the build on the whole geometry. */
typedef struct handover {
  const fcm_cell_rules *whole;
  const fcm_mesh *mesh;
  const unsigned char *remote;
  fcm_ctx *ctx;
} handover;

static fcm_status exchange(void *user, fcm_status st, unsigned char *cls, double *fraction,
                           double *volume, fcm__embed_counts *counts)
{
  const handover *h = user;
  (void)counts;
  if (st != FCM_OK) return st;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(h->mesh); c++) {
    if (!h->remote[c]) continue;
    fcm__embed_cell cell;
    st = fcm__embed_cell_setup(h->ctx, h->mesh, c, fcm_cell_rules_options_default().clip_rtol,
                               &cell);
    if (st != FCM_OK) return st;
    cls[c] = (unsigned char)fcm_cell_rules_class(h->whole, c);
    fraction[c] = fcm_cell_rules_volume_fraction(h->whole, c);
    volume[c] = fraction[c] * cell.volume; /* as the build records it */
  }
  return FCM_OK;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL, *other = NULL;
  fcm_geometry *geom = NULL, *crop = NULL;
  fcm_cell_rules *whole = NULL, *part = NULL, *r = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, centre[3] = {0.72, 0.49, 0.47};
  const fcm_index n[3] = {6, 6, 6};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, centre, 0.41, 3, &geom));
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  unsigned char *classify = calloc((size_t)nc, 1), *own = calloc((size_t)nc, 1),
                *remote = calloc((size_t)nc, 1);
  TEST_TRUE(classify && own && remote);
  if (!classify || !own || !remote) return 1;
  fcm_index k_own = 0;
  for (fcm_index c = 0; c < nc; c++) {
    double X[24], x = 0.0;
    fcm_mesh_cell_coords(mesh, c, X);
    for (int a = 0; a < 8; a++)
      x += X[3 * a] / 8.0;
    classify[c] = x < 0.45;
    remote[c] = !classify[c];
    own[c] = classify[c] && k_own++ % 2 == 0;
  }
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.surface_strength = 2;
  o.simplify = FCM_CELL_SIMPLIFY_ON;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, geom, &o, &whole));

  /* the crop itself */
  TEST_OK(ctx, fcm__embed_crop_geometry(ctx, mesh, geom, &o, classify, own, &crop));
  if (!whole || !crop) return 1;
  TEST_TRUE(crop->num_cells > 0 && crop->num_cells < geom->num_cells);
  /* the surface path (the default) keeps every boundary triangle: lines through the body */
  TEST_TRUE(crop->num_tris == geom->num_tris);
  {
    fcm_geometry *vcrop = NULL;
    fcm_cell_rules_options ov = o;
    ov.moments = FCM_CELL_MOMENTS_VOLUME;
    TEST_OK(ctx, fcm__embed_crop_geometry(ctx, mesh, geom, &ov, classify, own, &vcrop));
    TEST_TRUE(vcrop && vcrop->num_tris > 0 && vcrop->num_tris < geom->num_tris);
    fcm_geometry_destroy(&vcrop);
  }
  TEST_TRUE(crop->orig_cells == geom->num_cells && crop->orig_tris == geom->num_tris);
  TEST_TRUE(same_bits(&crop->volume, &geom->volume, 1));
  TEST_TRUE(same_bits(crop->lo, geom->lo, 3) && same_bits(crop->hi, geom->hi, 3));
  TEST_TRUE(crop->has_outside && crop->outside_side[1] > 0.0);
  for (fcm_index i = 0; i < crop->num_cells; i++) {
    const fcm_index e = crop->cell_orig[i];
    TEST_TRUE(e >= 0 && e < geom->num_cells && (i == 0 || e > crop->cell_orig[i - 1]));
    for (int a = 0; a < crop->npc && e >= 0 && e < geom->num_cells; a++)
      TEST_TRUE(same_bits(crop->coords + 3 * crop->cells[crop->npc * i + a],
                          geom->coords + 3 * geom->cells[geom->npc * e + a], 3));
  }
  for (fcm_index i = 0; i < crop->num_tris; i++) {
    const fcm_index t = crop->tri_orig[i];
    TEST_TRUE(t >= 0 && t < geom->num_tris && (i == 0 || t > crop->tri_orig[i - 1]));
    if (t < 0 || t >= geom->num_tris) continue;
    for (int a = 0; a < 3; a++)
      TEST_TRUE(same_bits(crop->coords + 3 * crop->tris[3 * i + a],
                          geom->coords + 3 * geom->tris[3 * t + a], 3));
    const fcm_index tc = crop->tri_cell[i];
    TEST_TRUE(tc == -1 ||
              (tc >= 0 && tc < crop->num_cells && crop->cell_orig[tc] == geom->tri_cell[t]));
  }

  /* the distributed build on the crop equals the build on the whole geometry */
  handover h = {whole, mesh, remote, ctx};
  const fcm__rules_exchange x = {remote, exchange, &h};
  fcm_cell_rules_options om = o;
  om.cell_mask = own;
  TEST_OK(ctx, fcm__cell_rules_create_distributed(ctx, mesh, crop, &om, NULL, &x, &part));
  if (!part) return 1;
  fcm_index nown_cut = 0, nown_surf = 0;
  for (fcm_index c = 0; c < nc; c++) {
    TEST_TRUE(fcm_cell_rules_class(part, c) == fcm_cell_rules_class(whole, c));
    const double fa = fcm_cell_rules_volume_fraction(whole, c),
                 fb = fcm_cell_rules_volume_fraction(part, c);
    TEST_TRUE(same_bits(&fa, &fb, 1));
    fcm_index p0a = 0, p0b = 0;
    const fcm_index npa = fcm_cell_rules_cell_pieces(whole, c, &p0a),
                    npb = fcm_cell_rules_cell_pieces(part, c, &p0b);
    TEST_TRUE(npa == npb && p0a == p0b);
    for (fcm_index p = p0a; p < p0a + npa && npa == npb; p++) {
      const double va = fcm_cell_rules_piece_volume(whole, p),
                   vb = fcm_cell_rules_piece_volume(part, p);
      TEST_TRUE(same_bits(&va, &vb, 1));
    }
    if (!own[c]) continue;
    if (fcm_cell_rules_class(whole, c) == FCM_CELL_CUT) {
      nown_cut++;
      for (int kind = 0; kind < FCM_RULE_KIND_COUNT; kind++) {
        int na = 0, nb = 0;
        const double *xa, *wa, *xb, *wb;
        const unsigned char *ga, *gb;
        TEST_OK(ctx, fcm_cell_rules_get(whole, c, (fcm_rule_kind)kind, &na, &xa, &wa, &ga));
        TEST_OK(ctx, fcm_cell_rules_get(part, c, (fcm_rule_kind)kind, &nb, &xb, &wb, &gb));
        TEST_TRUE(na > 0 && na == nb);
        if (na != nb) continue;
        TEST_TRUE(same_bits(xa, xb, 3 * (size_t)na) && same_bits(wa, wb, (size_t)na));
        TEST_TRUE(memcmp(ga, gb, (size_t)na) == 0);
      }
    }
    int na = 0, nb = 0;
    const double *xa, *wa, *ma, *xb, *wb, *mb;
    const fcm_index *ta, *tb;
    TEST_OK(ctx, fcm_cell_rules_get_surface(whole, c, &na, &xa, &wa, &ma, &ta));
    TEST_OK(ctx, fcm_cell_rules_get_surface(part, c, &nb, &xb, &wb, &mb, &tb));
    TEST_TRUE(na == nb);
    nown_surf += na > 0;
    if (na != nb || na == 0) continue;
    TEST_TRUE(same_bits(xa, xb, 3 * (size_t)na) && same_bits(wa, wb, (size_t)na) &&
              same_bits(ma, mb, 3 * (size_t)na));
    TEST_TRUE(memcmp(ta, tb, (size_t)na * sizeof *ta) == 0); /* original triangle ids */
  }
  TEST_TRUE(nown_cut > 0 && nown_surf > 0);
  const fcm_cell_rules_stats *a = fcm_cell_rules_get_stats(whole),
                             *b = fcm_cell_rules_get_stats(part);
  TEST_TRUE(same_bits(&a->geometry_volume, &b->geometry_volume, 1));
  TEST_TRUE(same_bits(a->geometry_lo, b->geometry_lo, 3) &&
            same_bits(a->geometry_hi, b->geometry_hi, 3));
  TEST_TRUE(same_bits(&a->embedded_volume, &b->embedded_volume, 1));
  TEST_TRUE(same_bits(a->outside_side_volume, b->outside_side_volume, 6));
  TEST_TRUE(a->outside_side_volume[1] > 0.0 && a->outside_volume > 0.0);
  TEST_NEAR(b->outside_volume, a->outside_volume, 1e-12, 1e-300);

  /* errors */
  fcm_geometry *g2 = NULL;
  fcm_cell_rules_options bad = o;
  bad.clip_rtol = 0.5;
  TEST_ERR(ctx, fcm__embed_crop_geometry(ctx, mesh, geom, &bad, classify, own, &g2), FCM_ERR_ARG,
           "clip_rtol = 0.5");
  TEST_TRUE(g2 == NULL);
  const fcm_index n2[3] = {4, 4, 4};
  const double hi2[3] = {1.2, 1, 1};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi2, n2, &other));
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, other, crop, &o, &r), FCM_ERR_INTERNAL,
           "another background mesh");
  TEST_TRUE(r == NULL);

  fcm_cell_rules_destroy(&part);
  fcm_cell_rules_destroy(&whole);
  fcm_geometry_destroy(&crop);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&other);
  fcm_mesh_destroy(&mesh);
  free(classify);
  free(own);
  free(remote);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
