/* The distributed classification of the PETSc backend (label mpi; 1 and 2 processes): each
 * process intersects only its share of the background cells and the classes are gathered
 * (fcm__cell_rules_create_distributed()), so the result must be that of the serial build bit
 * for bit. Asserted on every process against fcm_cell_rules_create() + fcm_space_create_embedded()
 * on the same mesh, geometry and options:
 * - every cell's class, volume fraction (bits), pieces and piece volumes (bits);
 * - the space: DOF count, node DOFs and copies, elements (cell and DOFs of each);
 * - the volume rules (both kinds) of every cut cell and the surface rules of every cell: on
 *   exactly one process (its owner) with points, there bit for bit the serial ones, on the
 *   others none;
 * - the statistics the classification sums: cell counts, embedded volume (bits), candidates,
 *   parts, tets, slivers, surface triangles (the per-process counters are summed).
 * - the whole geometry's quantities in the statistics (volume, bounding box, outside volumes),
 *   although on several processes each reads only part of the geometry (the crop), and the
 *   crop itself (check_crop()): less than the whole on every process, the union holding every
 *   geometry cell and boundary triangle whose box meets an active cell's.
 * Phase 1 (fcm_petsc_problem_create(): a ball in a box and one sticking out of it, the element
 * and partition given) and,
 * when a scene is given, phase 2 (fcm_petsc_simulation_create() against fcm_simulation_create():
 * the rules after the create, so with a scene cut at t = 0 those the cut extended, and with
 * quadrature.simplify = "auto" those of the choice summed over the processes).
 * Arguments: element type, partition (ordered|ptscotch), [scenes directory, scene file]. */
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "test_mpi.h"

#include <math.h>
#include <stdlib.h>

static int same_bits(const double *a, const double *b, size_t n)
{
  return n == 0 || memcmp(a, b, n * sizeof *a) == 0;
}

/* Whether the distributed rules d (this process's) agree with the serial rules s as described
 * above; the failures are counted by the TEST_ macros. */
static void compare_rules(fcm_ctx *ctx, const fcm_cell_rules *s, const fcm_cell_rules *d)
{
  const fcm_index nc = fcm_cell_rules_num_cells(s);
  TEST_TRUE(fcm_cell_rules_num_cells(d) == nc);
  TEST_TRUE(fcm_cell_rules_num_pieces(d) == fcm_cell_rules_num_pieces(s));
  if (test_failures_) return;
  fcm_index ncut = 0, owned = 0;
  for (fcm_index c = 0; c < nc; c++) {
    const fcm_cell_class cls = fcm_cell_rules_class(s, c);
    TEST_TRUE(fcm_cell_rules_class(d, c) == cls);
    const double fs = fcm_cell_rules_volume_fraction(s, c),
                 fd = fcm_cell_rules_volume_fraction(d, c);
    TEST_TRUE(same_bits(&fs, &fd, 1));
    fcm_index p0s = 0, p0d = 0;
    const fcm_index nps = fcm_cell_rules_cell_pieces(s, c, &p0s),
                    npd = fcm_cell_rules_cell_pieces(d, c, &p0d);
    TEST_TRUE(nps == npd && p0s == p0d);
    for (fcm_index p = p0s; p < p0s + nps && nps == npd; p++) {
      const double vs = fcm_cell_rules_piece_volume(s, p), vd = fcm_cell_rules_piece_volume(d, p);
      TEST_TRUE(same_bits(&vs, &vd, 1));
      TEST_TRUE(fcm_cell_rules_piece_cell(d, p) == c);
    }
    if (cls != FCM_CELL_CUT) continue;
    /* a cut cell: points on this process when it owns the cell, then the serial ones */
    ncut++;
    int has = 0, kinds = 0;
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      if (!fcm_cell_rules_has_kind(s, (fcm_rule_kind)k)) continue;
      kinds++;
      int ns = 0, nd = 0;
      const double *xs = NULL, *ws = NULL, *xd = NULL, *wd = NULL;
      const unsigned char *gs = NULL, *gd = NULL;
      TEST_OK(ctx, fcm_cell_rules_get(s, c, (fcm_rule_kind)k, &ns, &xs, &ws, &gs));
      TEST_OK(ctx, fcm_cell_rules_get(d, c, (fcm_rule_kind)k, &nd, &xd, &wd, &gd));
      TEST_TRUE(ns > 0);
      if (nd == 0) continue;
      has++;
      TEST_TRUE(nd == ns);
      if (nd != ns) continue;
      TEST_TRUE(same_bits(xs, xd, 3 * (size_t)ns) && same_bits(ws, wd, (size_t)ns));
      TEST_TRUE(memcmp(gs, gd, (size_t)ns) == 0);
    }
    TEST_TRUE(has == 0 || has == kinds); /* an owned cell has every kind */
    owned += has > 0;
  }
  /* the surface rules: each cell's on at most one process (its owner), the serial ones */
  fcm_index nsurf = 0, shown = 0;
  for (fcm_index c = 0; c < nc; c++) {
    int ns = 0, nd = 0;
    const double *xs, *ws, *ms, *xd, *wd, *md;
    const fcm_index *ts, *td;
    TEST_OK(ctx, fcm_cell_rules_get_surface(s, c, &ns, &xs, &ws, &ms, &ts));
    TEST_OK(ctx, fcm_cell_rules_get_surface(d, c, &nd, &xd, &wd, &md, &td));
    nsurf += ns > 0;
    if (nd == 0) continue;
    shown++;
    TEST_TRUE(nd == ns);
    if (nd != ns) continue;
    TEST_TRUE(same_bits(xs, xd, 3 * (size_t)ns) && same_bits(ws, wd, (size_t)ns) &&
              same_bits(ms, md, 3 * (size_t)ns));
    TEST_TRUE(memcmp(ts, td, (size_t)ns * sizeof *ts) == 0);
  }
  /* each cut cell has its points on exactly one process */
  long long mine[4] = {(long long)owned, (long long)ncut, (long long)shown, (long long)nsurf},
            all[4];
  MPI_Allreduce(mine, all, 4, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  TEST_TRUE(all[0] == (long long)ncut && all[1] == (long long)ncut * size);
  TEST_TRUE(all[2] == (long long)nsurf && all[3] == (long long)nsurf * size);
  TEST_TRUE(ncut > 0);
  /* the statistics (the counters summed over the processes by the exchange) */
  const fcm_cell_rules_stats *a = fcm_cell_rules_get_stats(s), *b = fcm_cell_rules_get_stats(d);
  TEST_TRUE(a->num_uncut == b->num_uncut && a->num_cut == b->num_cut &&
            a->num_dropped == b->num_dropped);
  TEST_TRUE(same_bits(&a->embedded_volume, &b->embedded_volume, 1));
  TEST_TRUE(a->num_candidates == b->num_candidates && a->num_parts == b->num_parts &&
            a->num_tets == b->num_tets && a->num_slivers == b->num_slivers);
  TEST_TRUE(a->surface_triangles == b->surface_triangles);
  TEST_NEAR(b->sliver_volume, a->sliver_volume, 1e-12, 1e-300);
  /* the whole geometry's quantities, although each process read only a part of it (the crop) */
  TEST_TRUE(same_bits(&a->geometry_volume, &b->geometry_volume, 1));
  TEST_TRUE(same_bits(a->geometry_lo, b->geometry_lo, 3) &&
            same_bits(a->geometry_hi, b->geometry_hi, 3));
  TEST_TRUE(same_bits(a->mesh_lo, b->mesh_lo, 3) && same_bits(a->mesh_hi, b->mesh_hi, 3));
  TEST_TRUE(same_bits(&a->volume_ratio, &b->volume_ratio, 1));
  TEST_NEAR(b->outside_volume, a->outside_volume, 1e-12, 1e-300);
  TEST_TRUE(same_bits(a->outside_side_volume, b->outside_side_volume, 6));
}

/* The crop (phase 1): each process's rules build read a part of the geometry (info, and
 * fcm_petsc_problem_geometry_kept()): on several processes less than the whole on every
 * process (cells and boundary triangles), the kept ids ascending and in range, and the union
 * over the processes holds every geometry cell and boundary triangle whose box meets the box
 * of an active background cell (the serial space's); on one process the whole geometry. */
static void check_crop(fcm_ctx *ctx, fcm_petsc_problem *P, const fcm_mesh *mesh,
                       const fcm_geometry *geom, const fcm_space *serial)
{
  fcm_petsc_info info;
  TEST_OK(ctx, fcm_petsc_problem_get_info(P, &info));
  const fcm_index ng = fcm_geometry_num_cells(geom), nt = fcm_geometry_num_boundary_triangles(geom);
  TEST_TRUE(info.geometry_cells == ng && info.geometry_triangles == nt);
  fcm_index nkc = -1, nkt = -1;
  const fcm_index *kc = NULL, *kt = NULL;
  TEST_OK(ctx, fcm_petsc_problem_geometry_kept(P, &nkc, &kc, &nkt, &kt));
  if (info.size == 1) {
    TEST_TRUE(info.geometry_cells_kept == ng && info.geometry_triangles_kept == nt);
    TEST_TRUE(nkc == 0 && kc == NULL && nkt == 0 && kt == NULL);
    TEST_TRUE(info.geometry_bytes_kept == info.geometry_bytes);
    return;
  }
  TEST_TRUE(info.geometry_cells_kept == nkc && info.geometry_triangles_kept == nkt);
  /* every boundary triangle: the surface path (the default) reads lines through the body */
  TEST_TRUE(nkc > 0 && nkc < ng && nkt == nt);
  /* (bytes: the kept part also holds its ids' map, so on a coarse mesh it may exceed the whole) */
  TEST_TRUE(info.geometry_bytes_kept > 0.0 &&
            info.max_geometry_bytes_kept >= info.geometry_bytes_kept);
  int *have = calloc((size_t)(ng + nt) + 1, sizeof *have), *all = NULL;
  all = calloc((size_t)(ng + nt) + 1, sizeof *all);
  TEST_TRUE(have && all); /* (no return before the collective below) */
  for (fcm_index i = 0; have && i < nkc; i++) {
    TEST_TRUE(kc[i] >= 0 && kc[i] < ng && (i == 0 || kc[i] > kc[i - 1]));
    if (kc[i] >= 0 && kc[i] < ng) have[kc[i]] = 1;
  }
  for (fcm_index i = 0; have && i < nkt; i++) {
    TEST_TRUE(kt[i] >= 0 && kt[i] < nt && (i == 0 || kt[i] > kt[i - 1]));
    if (kt[i] >= 0 && kt[i] < nt) have[ng + kt[i]] = 1;
  }
  int ok = have && all, all_ok = 0;
  MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (!all_ok) goto done;
  MPI_Allreduce(have, all, (int)(ng + nt), MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  /* the boxes of the geometry cells and triangles, and of each active background cell */
  const double *X = fcm_geometry_coords(geom);
  for (int tris = 0; tris < 2; tris++) {
    const fcm_index n = tris ? nt : ng;
    const int npv = tris ? 3 : fcm_geometry_nodes_per_cell(geom);
    const fcm_index *conn = tris ? fcm_geometry_boundary_triangles(geom) : fcm_geometry_cells(geom);
    double *boxes = malloc(6 * (size_t)n * sizeof *boxes);
    fcm_index *ids = malloc((size_t)n * sizeof *ids);
    fcm_aabb_tree *tree = NULL;
    TEST_TRUE(boxes && ids);
    if (!boxes || !ids) {
      free(boxes);
      free(ids);
      goto done;
    }
    for (fcm_index i = 0; i < n; i++)
      for (int d = 0; d < 3; d++) {
        boxes[6 * i + d] = HUGE_VAL, boxes[6 * i + 3 + d] = -HUGE_VAL;
        for (int a = 0; a < npv; a++) {
          const double v = X[3 * conn[(size_t)npv * i + a] + d];
          boxes[6 * i + d] = fmin(boxes[6 * i + d], v);
          boxes[6 * i + 3 + d] = fmax(boxes[6 * i + 3 + d], v);
        }
      }
    TEST_OK(ctx, fcm_aabb_tree_create(ctx, n, boxes, &tree));
    const int nn = fcm_mesh_nodes_per_cell(mesh);
    const double *MX = fcm_mesh_coords(mesh);
    const fcm_index *mc = fcm_mesh_cells(mesh);
    fcm_index missing = 0, met = 0;
    for (fcm_index c = 0; tree && c < fcm_mesh_num_cells(mesh); c++) {
      if (!fcm_space_cell_active(serial, c)) continue;
      double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
      for (int a = 0; a < nn; a++)
        for (int d = 0; d < 3; d++) {
          lo[d] = fmin(lo[d], MX[3 * mc[(size_t)nn * c + a] + d]);
          hi[d] = fmax(hi[d], MX[3 * mc[(size_t)nn * c + a] + d]);
        }
      fcm_index k = 0;
      TEST_OK(ctx, fcm_aabb_tree_query(tree, lo, hi, n, ids, &k));
      for (fcm_index i = 0; i < k; i++) {
        met++;
        missing += !all[(tris ? ng : 0) + ids[i]];
      }
    }
    TEST_TRUE(met > 0 && missing == 0);
    fcm_aabb_tree_destroy(&tree);
    free(boxes);
    free(ids);
  }
done:
  free(have);
  free(all);
}

/* The spaces' DOF numbering and elements agree exactly. */
static void compare_spaces(const fcm_space *s, const fcm_space *d)
{
  const fcm_mesh *mesh = fcm_space_mesh(s);
  TEST_TRUE(fcm_space_num_dofs(d) == fcm_space_num_dofs(s));
  TEST_TRUE(fcm_space_num_elements(d) == fcm_space_num_elements(s));
  TEST_TRUE(fcm_space_num_constrained_copies(d) == fcm_space_num_constrained_copies(s));
  if (test_failures_) return;
  for (fcm_index k = 0; k < fcm_mesh_num_nodes(mesh); k++) {
    TEST_TRUE(fcm_space_node_dof(d, k) == fcm_space_node_dof(s, k));
    TEST_TRUE(fcm_space_node_copies(d, k) == fcm_space_node_copies(s, k));
  }
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++)
    TEST_TRUE(fcm_space_cell_active(d, c) == fcm_space_cell_active(s, c));
  const int nn = fcm_mesh_nodes_per_cell(mesh);
  for (fcm_index e = 0; e < fcm_space_num_elements(s); e++) {
    TEST_TRUE(fcm_space_element_cell(d, e) == fcm_space_element_cell(s, e));
    TEST_TRUE(memcmp(fcm_space_element_dofs(d, e), fcm_space_element_dofs(s, e),
                     (size_t)nn * sizeof(fcm_index)) == 0);
  }
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_cell_rules *rules = NULL;
  fcm_space *space = NULL;
  fcm_petsc_problem *P = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *ser = NULL, *par = NULL;
  fcm_element_type type;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 3 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  const fcm_petsc_partition part =
      strcmp(argv[2], "ptscotch") == 0 ? FCM_PETSC_PARTITION_PTSCOTCH : FCM_PETSC_PARTITION_ORDERED;

  /* phase 1: a ball (curved boundary: many cut cells, some nearly empty) in a box */
  const int quadratic = type == FCM_ELEMENT_HEX20 || type == FCM_ELEMENT_TET10;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, centre[3] = {0.52, 0.49, 0.47};
  const fcm_index n = quadratic ? 3 : 5, cells[3] = {n, n, n};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, cells, &mesh));
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e6, 0.3, 1000.0};
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_BACKWARD_EULER; /* both volume kinds */
  po.solver.partition = part;
  po.rules.simplify = FCM_CELL_SIMPLIFY_ON;
  po.rules.surface_strength = 2;
  fcm_cell_rules_options ro = po.rules; /* as the backend builds them */
  ro.kinds = FCM_RULES_ALL;
  /* the ball inside the box, then one sticking out of it (beyond x = 1: outside volumes) */
  const double centres[2][3] = {{centre[0], centre[1], centre[2]}, {0.83, 0.49, 0.47}};
  for (int body = 0; body < 2 && !test_failures_; body++) {
    TEST_OK(ctx, fcm_geometry_create_ball(ctx, centres[body], 0.41, 3, &geom));
    TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, geom, &ro, &rules));
    TEST_OK(ctx, fcm_space_create_embedded(ctx, mesh, rules, &space));
    TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P));
    if (rules && space && P) {
      const fcm_space *ds = fcm_petsc_problem_space(P);
      compare_rules(ctx, rules, fcm_space_cell_rules(ds));
      compare_spaces(space, ds);
      check_crop(ctx, P, mesh, geom, space);
      const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(rules);
      TEST_TRUE(body == 0 ? S->outside_volume == 0.0 : S->outside_side_volume[1] > 0.0);
    }
    fcm_petsc_problem_destroy(&P);
    fcm_space_destroy(&space);
    fcm_cell_rules_destroy(&rules);
    if (body == 0) fcm_geometry_destroy(&geom);
  }

  /* phase 2: a scene through fcm_petsc_simulation_create() */
  if (argc >= 5 && !test_failures_) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", argv[3], argv[4]);
    TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
    fcm_simulation_options so = fcm_simulation_options_default();
    so.max_steps = 1;
    TEST_OK(ctx, fcm_simulation_create(ctx, scene, &so, &ser));
    TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, part, &so, &par));
    if (ser && par) {
      compare_rules(ctx, fcm_simulation_cell_rules(ser), fcm_simulation_cell_rules(par));
      compare_spaces(fcm_simulation_space(ser), fcm_simulation_space(par));
    }
  }
  fcm_simulation_destroy(&par);
  fcm_simulation_destroy(&ser);
  fcm_scene_destroy(&scene);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
