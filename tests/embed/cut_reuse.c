/* What a cut takes over from the rules it extends, for a body given by its surface alone: the
 * body's volume in each whole cell (fcm_cell_rules' cell_mvol), the face polygons of the region
 * cells no new cut reaches (face_nfp, face_meta, face_x), the volume of each cell's corner
 * polyhedron (cell_volume: the cells whose rules a cut copies are not set up) and the rules of
 * the cells it copies (borrowed, copied once when gathered). A hollow ball with a hole in an 8 x 8
 * x 7 Hex8 grid, with the stiffness on the mass space, cut in sequence by blades along the grid's
 * planes (a plane, rectangles that end inside cells, overlapping regions) and a tilted plane.
 * Asserts
 * - after every cut, the rules equal those of the same cuts made from rules stripped of what
 *   they keep (every cell measured and split again): classes, fractions, pieces, their
 *   volumes, components, points, weights, flags, cut faces, links and the embedded volume,
 *   bit for bit, and the kept cell volumes equal those measured again;
 * - the kept values are used: whole cells' volumes and face polygons are kept after the
 *   cuts, and cells that take them occur;
 * - a kept volume off by 1e-3 (the control) changes the next cut's rules, and a kept cell
 *   volume off by 1e-3 its embedded volume;
 * - the links equal those of the cut without its shortcuts (fcm__cell_rules_create_cut_keep()
 *   with keep = 0: every region cell split for its face polygons, those without pieces too);
 * - the face overlaps' shortcut: every kept face polygon of a part the body fills (fmeta's
 *   flag), larger than 4 times the area threshold, is covered by the body by the prism's
 *   moments (fcm__material_on_face()), as the links take it without them; polygons of other
 *   parts that are not covered occur (the test tells them apart). */
#include "embed/embed_impl.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static fcm_ctx *ctx;

enum { NCUT = 5 };

typedef struct blade {
  double p[3], n[3], lo[3], hi[3];
} blade;

static const blade blades[NCUT] = {
    {{-0.31, 0.0, 0.0}, {1.0, 0.0, 0.0}, {-3, -3, -3}, {3, 3, 3}},
    {{0.0, 0.23, 0.0}, {0.0, 1.0, 0.0}, {-3, -3, -3}, {3, 3, 0.21}},
    {{-0.02, 0.0, 0.0}, {1.0, 0.0, 0.0}, {-3, -0.4, -3}, {3, 3, 3}},
    {{0.0, -0.17, 0.0}, {0.0, 1.0, 0.0}, {-3, -3, -0.35}, {3, 3, 3}},
    {{0.05, -0.3, 0.1}, {0.3, 0.2, 1.0}, {-3, -3, -3}, {3, 3, 3}},
};

/* Free what r keeps for the next cut. */
static void strip(fcm_cell_rules *r)
{
  for (fcm_index c = 0; r->face_nfp && c < r->num_cells; c++) {
    fcm__free(ctx, r->face_meta[c]);
    fcm__free(ctx, r->face_x[c]);
  }
  fcm__free(ctx, r->face_nfp);
  fcm__free(ctx, r->face_meta);
  fcm__free(ctx, r->face_x);
  fcm__free(ctx, r->cell_mvol);
  fcm__free(ctx, r->cell_volume);
  r->face_nfp = NULL, r->face_meta = NULL, r->face_x = NULL, r->cell_mvol = NULL;
  r->cell_volume = NULL;
}

static int same_array(const void *a, const void *b, size_t bytes)
{
  return bytes == 0 || (a && b && !memcmp(a, b, bytes));
}

/* Whether a and b are the same rules, bit for bit. */
static int same_rules(const fcm_cell_rules *a, const fcm_cell_rules *b)
{
  const fcm_index nc = a->num_cells, np = a->num_pieces;
  if (nc != b->num_cells || np != b->num_pieces || a->num_links != b->num_links) return 0;
  if (memcmp(&a->stats.embedded_volume, &b->stats.embedded_volume, sizeof(double))) return 0;
  int same = same_array(a->cls, b->cls, (size_t)nc) &&
             same_array(a->fraction, b->fraction, (size_t)nc * sizeof(double)) &&
             same_array(a->piece_off, b->piece_off, (size_t)(nc + 1) * sizeof(fcm_index)) &&
             same_array(a->piece_volume, b->piece_volume, (size_t)np * sizeof(double)) &&
             same_array(a->piece_component, b->piece_component, (size_t)np * sizeof(int)) &&
             same_array(a->links, b->links, 2 * (size_t)a->num_links * sizeof(fcm_index)) &&
             same_array(a->cfoff, b->cfoff, (size_t)(np + 1) * sizeof(fcm_index)) &&
             same_array(a->cfxi, b->cfxi, 9 * (size_t)a->cfoff[np] * sizeof(double));
  for (int k = 0; k < FCM_RULE_KIND_COUNT && same; k++) {
    const size_t n = (size_t)a->off[k][np];
    same = same_array(a->off[k], b->off[k], (size_t)(np + 1) * sizeof(fcm_index)) &&
           same_array(a->points[k], b->points[k], 3 * n * sizeof(double)) &&
           same_array(a->weights[k], b->weights[k], n * sizeof(double)) &&
           same_array(a->flags[k], b->flags[k], n);
  }
  return same;
}

static fcm_cell_rules *next_cut(const fcm_mesh *mesh, const fcm_geometry *g,
                                const fcm_cell_rules *r, int k)
{
  fcm_surface *s = NULL;
  fcm_cell_rules *next = NULL;
  const blade *b = blades + k;
  TEST_OK(ctx, fcm_surface_create_plane(ctx, b->p, b->n, b->lo, b->hi, &s));
  if (s) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r, s, &next));
  fcm_surface_destroy(&s);
  return next;
}

/* The kept face polygons of r against the prism's moments: parts the body fills (*full of
 * them, *full_covered covered) and the others (*other, *other_open not covered). */
static void check_full_faces(const fcm_mesh *mesh, const fcm_geometry *g, const fcm_cell_rules *r,
                             long *full, long *full_covered, long *other, long *other_open)
{
  fcm__material *m = NULL;
  TEST_OK(ctx, fcm__material_create(ctx, g, &m));
  for (fcm_index c = 0; m && r->face_nfp && c < r->num_cells; c++) {
    if (r->face_nfp[c] <= 0) continue;
    fcm__embed_cell cell;
    TEST_OK(ctx, fcm__embed_cell_setup(ctx, mesh, c, 1e-12, &cell));
    const double h = 1e-6 * cell.size, atol = 1e-9 * cell.size * cell.size;
    size_t x0 = 0;
    for (int i = 0; i < r->face_nfp[c]; i++) {
      const int *meta = r->face_meta[c] + FCM__EMBED_FMETA * i;
      const double *x = r->face_x[c] + 3 * x0;
      x0 += (size_t)(meta[2] + meta[3]);
      if (meta[1] < 0) continue;
      double a[3] = {0.0, 0.0, 0.0};
      for (int k = 1; k + 1 < meta[2]; k++) {
        double e1[3], e2[3];
        for (int d = 0; d < 3; d++)
          e1[d] = x[3 * k + d] - x[d], e2[d] = x[3 * (k + 1) + d] - x[d];
        a[0] += 0.5 * (e1[1] * e2[2] - e1[2] * e2[1]);
        a[1] += 0.5 * (e1[2] * e2[0] - e1[0] * e2[2]);
        a[2] += 0.5 * (e1[0] * e2[1] - e1[1] * e2[0]);
      }
      if (!(sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) > 4.0 * atol)) continue;
      const int cov =
          fcm__material_on_face(ctx, m, &cell, x, meta[2], cell.planes[meta[0]].n, h, atol);
      TEST_OK(ctx, fcm__material_status(m));
      if (meta[4]) {
        (*full)++;
        *full_covered += cov;
      } else {
        (*other)++;
        *other_open += !cov;
      }
    }
  }
  fcm__material_destroy(ctx, &m);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const int verbose = getenv("FCM_TEST_VERBOSE") != NULL;
  const double c0[3] = {0.05, -0.03, 0.02}, lo[3] = {-1.2, -1.1, -1.1}, hi[3] = {1.1, 1.2, 1.15};
  const fcm_index n[3] = {8, 8, 7};
  fcm_geometry *tets = NULL, *surf = NULL;
  fcm_surface *s = NULL;
  fcm_mesh *mesh = NULL;
  TEST_OK(ctx, fcm_geometry_create_hollow_ball(ctx, c0, 0.25, 1.0, 0.15, 4, 3, &tets));
  if (!tets) return TEST_RESULT();
  TEST_OK(ctx, fcm_surface_create(ctx, fcm_geometry_num_nodes(tets), fcm_geometry_coords(tets),
                                  fcm_geometry_num_boundary_triangles(tets),
                                  fcm_geometry_boundary_triangles(tets), &s));
  fcm_surface_mesh_options mo = fcm_surface_mesh_options_default();
  mo.volume_mesh = 0;
  TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, s, &mo, &surf));
  fcm_surface_destroy(&s);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  if (!mesh || !surf) return TEST_RESULT();
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.moments = FCM_CELL_MOMENTS_SURFACE;
  o.stiffness_on_mass_space = 1;
  fcm_cell_rules *a = NULL, *b = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, surf, &o, &a));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, surf, &o, &b));
  long reused = 0, volumes = 0, faces = 0, full = 0, full_cov = 0, other = 0, other_open = 0;
  int control_differs = 0, volume_control_differs = 0;
  long volumes_kept = 0, volumes_wrong = 0;
  for (int k = 0; k < NCUT && a && b; k++) {
    /* the control: the next cut from a copy whose kept volumes are off by 1e-3 */
    if (k == 2 && a->cell_mvol) {
      fcm_cell_rules *wrong = NULL, *ref = NULL;
      for (fcm_index c = 0; c < a->num_cells; c++)
        if (isfinite(a->cell_mvol[c]) && a->cell_mvol[c] > 0.0) a->cell_mvol[c] *= 1.0 + 1e-3;
      wrong = next_cut(mesh, surf, a, k);
      for (fcm_index c = 0; c < a->num_cells; c++)
        if (isfinite(a->cell_mvol[c]) && a->cell_mvol[c] > 0.0) a->cell_mvol[c] /= 1.0 + 1e-3;
      strip(b);
      ref = next_cut(mesh, surf, b, k);
      control_differs = wrong && ref && !same_rules(wrong, ref);
      fcm_cell_rules_destroy(&wrong);
      /* the control of the cell volumes: the same, off by 1e-3 */
      for (fcm_index c = 0; a->cell_volume && c < a->num_cells; c++)
        a->cell_volume[c] *= 1.0 + 1e-3;
      wrong = next_cut(mesh, surf, a, k);
      for (fcm_index c = 0; a->cell_volume && c < a->num_cells; c++)
        a->cell_volume[c] /= 1.0 + 1e-3;
      volume_control_differs = wrong && ref && !same_rules(wrong, ref);
      fcm_cell_rules_destroy(&wrong);
      fcm_cell_rules_destroy(&ref);
    }
    for (fcm_index c = 0; a->face_nfp && c < a->num_cells; c++)
      reused += a->face_nfp[c] >= 0 && a->reached && !a->reached[c];
    for (fcm_index c = 0; k > 0 && a->cell_volume && c < a->num_cells; c++)
      volumes_kept += !isnan(a->cell_volume[c]);
    fcm_cell_rules *plain = NULL;
    {
      fcm_surface *ps = NULL;
      const blade *bl = blades + k;
      TEST_OK(ctx, fcm_surface_create_plane(ctx, bl->p, bl->n, bl->lo, bl->hi, &ps));
      if (ps) TEST_OK(ctx, fcm__cell_rules_create_cut_keep(ctx, mesh, surf, a, ps, 0, &plain));
      fcm_surface_destroy(&ps);
    }
    fcm_cell_rules *na = next_cut(mesh, surf, a, k);
    const int same_links_plain =
        plain && na && plain->num_links == na->num_links &&
        same_array(plain->links, na->links, 2 * (size_t)na->num_links * sizeof(fcm_index));
    fcm_cell_rules_destroy(&plain);
    TEST_TRUE(same_links_plain);
    strip(b);
    fcm_cell_rules *nb = next_cut(mesh, surf, b, k);
    fcm_cell_rules_destroy(&a);
    fcm_cell_rules_destroy(&b);
    a = na, b = nb;
    if (!a || !b) break;
    const int same = same_rules(a, b);
    long v = 0, f = 0;
    for (fcm_index c = 0; c < a->num_cells; c++) {
      /* a kept cell volume is the one measured again (b measures every cell) */
      if (a->cell_volume && !isnan(a->cell_volume[c]))
        volumes_wrong +=
            !b->cell_volume || memcmp(a->cell_volume + c, b->cell_volume + c, sizeof(double)) != 0;
      v += a->cell_mvol && isfinite(a->cell_mvol[c]);
      f += a->face_nfp && a->face_nfp[c] >= 0;
    }
    volumes += v, faces += f;
    if (verbose)
      printf("cut %d: %lld pieces, %lld links; %ld whole cells' volumes and %ld cells' face "
             "polygons kept; the same rules as from stripped rules: %s\n",
             k + 1, (long long)a->num_pieces, (long long)a->num_links, v, f, same ? "yes" : "NO");
    TEST_TRUE(same);
    check_full_faces(mesh, surf, a, &full, &full_cov, &other, &other_open);
  }
  if (verbose) {
    printf("cells that may take kept face polygons: %ld; the control (volumes off by 1e-3) "
           "changes the rules: %s\n",
           reused, control_differs ? "yes" : "NO");
    printf("cell volumes kept before cuts 2 to %d: %ld (%ld not those measured again); the "
           "control (off by 1e-3) changes the embedded volume: %s\n",
           NCUT, volumes_kept, volumes_wrong, volume_control_differs ? "yes" : "NO");
    printf("kept face polygons of filled parts: %ld, covered by the prism's moments: %ld; of "
           "other parts: %ld, not covered: %ld\n",
           full, full_cov, other, other_open);
  }
  TEST_TRUE(volumes > 0 && faces > 0 && reused > 0);
  TEST_TRUE(control_differs);
  TEST_TRUE(volumes_kept > 0 && volumes_wrong == 0 && volume_control_differs);
  TEST_TRUE(full > 0 && full_cov == full && other_open > 0);
  fcm_cell_rules_destroy(&a);
  fcm_cell_rules_destroy(&b);
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&surf);
  fcm_geometry_destroy(&tets);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
