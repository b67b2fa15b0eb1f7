/* Cut-cell rules: names, destruction, accessors, statistics and the views. */
#include "embed/rules_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *fcm_rule_kind_name(fcm_rule_kind kind)
{
  static const char *const names[FCM_RULE_KIND_COUNT] = {"stiffness", "mass"};
  return (int)kind >= 0 && kind < FCM_RULE_KIND_COUNT ? names[kind] : "invalid";
}

const char *fcm_cell_simplify_name(fcm_cell_simplify mode)
{
  static const char *const names[FCM_CELL_SIMPLIFY_COUNT] = {"off", "on", "auto"};
  return (int)mode >= 0 && mode < FCM_CELL_SIMPLIFY_COUNT ? names[mode] : "invalid";
}

const char *fcm_cell_moments_name(fcm_cell_moments path)
{
  static const char *const names[FCM_CELL_MOMENTS_COUNT] = {"auto", "volume", "surface"};
  return (int)path >= 0 && path < FCM_CELL_MOMENTS_COUNT ? names[path] : "invalid";
}

void fcm_cell_rules_destroy(fcm_cell_rules **rules)
{
  if (!rules || !*rules) return;
  fcm_cell_rules *R = *rules;
  fcm_ctx *ctx = R->ctx;
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    fcm__free(ctx, R->off[k]);
    fcm__free(ctx, R->points[k]);
    fcm__free(ctx, R->weights[k]);
    fcm__free(ctx, R->flags[k]);
    fcm_rule_destroy(&R->uncut[k]);
    fcm__free(ctx, R->uncut_flags[k]);
  }
  fcm__free(ctx, R->cls);
  fcm__free(ctx, R->own);
  fcm__free(ctx, R->fraction);
  fcm__free(ctx, R->piece_off);
  fcm__free(ctx, R->piece_cell);
  fcm__free(ctx, R->piece_volume);
  fcm__free(ctx, R->piece_parent);
  fcm__free(ctx, R->piece_component);
  fcm__free(ctx, R->piece_copied);
  fcm__free(ctx, R->cut_tris);
  fcm__free(ctx, R->links);
  fcm__free(ctx, R->reached);
  fcm__free(ctx, R->cell_mvol);
  fcm__free(ctx, R->cell_volume);
  for (fcm_index c = 0; R->face_meta && R->face_x && c < R->num_cells; c++) {
    fcm__free(ctx, R->face_meta[c]);
    fcm__free(ctx, R->face_x[c]);
  }
  fcm__free(ctx, R->face_nfp);
  fcm__free(ctx, R->face_meta);
  fcm__free(ctx, R->face_x);
  fcm__free(ctx, R->soff);
  fcm__free(ctx, R->cfoff);
  fcm__free(ctx, R->cfxi);
  fcm__free(ctx, R->spoints);
  fcm__free(ctx, R->sweights);
  fcm__free(ctx, R->snormals);
  fcm__free(ctx, R->stris);
  fcm__free(ctx, R);
  *rules = NULL;
}

fcm_index fcm_cell_rules_num_cells(const fcm_cell_rules *rules)
{
  return rules->num_cells;
}

fcm_element_type fcm_cell_rules_element_type(const fcm_cell_rules *rules)
{
  return rules->type;
}

int fcm_cell_rules_surface_strength(const fcm_cell_rules *rules)
{
  return rules->surface_strength;
}

int fcm_cell_rules_has_kind(const fcm_cell_rules *rules, fcm_rule_kind kind)
{
  return rules && (int)kind >= 0 && kind < FCM_RULE_KIND_COUNT && rules->uncut[kind] != NULL;
}

/* FCM_ERR_ARG (set on ctx) unless the rules of `kind` were built; `what` names the caller. */
static fcm_status check_kind(const fcm_cell_rules *R, fcm_rule_kind kind, const char *what)
{
  fcm_status st = FCM_OK;
  FCM_CHECK((int)kind >= 0 && kind < FCM_RULE_KIND_COUNT, R->ctx, FCM_ERR_ARG,
            "%s: kind %d out of range [0,%d)", what, (int)kind, (int)FCM_RULE_KIND_COUNT);
  FCM_CHECK(R->uncut[kind], R->ctx, FCM_ERR_ARG,
            "%s: no %s rules were built (fcm_cell_rules_options.kinds = 0x%x lacks "
            "FCM_RULES_%s = 0x%x; request them when creating the rules)",
            what, fcm_rule_kind_name(kind), R->stats.kinds,
            kind == FCM_RULE_MASS ? "MASS" : "STIFFNESS", 1u << (unsigned)kind);
cleanup:
  return st;
}

int fcm_cell_rules_strength(const fcm_cell_rules *rules, fcm_rule_kind kind)
{
  return (int)kind >= 0 && kind < FCM_RULE_KIND_COUNT ? rules->strength[kind] : -1;
}

int fcm_cell_rules_axis_degree(const fcm_cell_rules *rules, fcm_rule_kind kind)
{
  return (int)kind >= 0 && kind < FCM_RULE_KIND_COUNT ? rules->axis_degree[kind] : -1;
}

fcm_cell_class fcm_cell_rules_class(const fcm_cell_rules *rules, fcm_index cell)
{
  if (cell < 0 || cell >= rules->num_cells) return FCM_CELL_DROPPED;
  return (fcm_cell_class)rules->cls[cell];
}

double fcm_cell_rules_volume_fraction(const fcm_cell_rules *rules, fcm_index cell)
{
  if (cell < 0 || cell >= rules->num_cells) return 0.0;
  return rules->fraction[cell];
}

/* The volume rule of kind k over the pieces [p0, p1) of a cell of class cls: the catalogue
 * rule for an uncut cell, else the stored points of those pieces (consecutive). */
static void rule_range(const fcm_cell_rules *R, fcm_cell_class cls, fcm_rule_kind k, fcm_index p0,
                       fcm_index p1, int *n, const double **p, const double **w,
                       const unsigned char **f)
{
  *n = 0, *p = *w = NULL, *f = NULL;
  if (cls == FCM_CELL_UNCUT) {
    *n = fcm_rule_num_points(R->uncut[k]);
    *p = fcm_rule_points(R->uncut[k]);
    *w = fcm_rule_weights(R->uncut[k]);
    *f = R->uncut_flags[k];
  } else if (cls == FCM_CELL_CUT) {
    const fcm_index o0 = R->off[k][p0];
    *n = (int)(R->off[k][p1] - o0);
    *p = R->points[k] + 3 * o0;
    *w = R->weights[k] + o0;
    *f = R->flags[k] + o0;
  }
}

fcm_status fcm_cell_rules_get(const fcm_cell_rules *rules, fcm_index cell, fcm_rule_kind kind,
                              int *num_points, const double **points, const double **weights,
                              const unsigned char **flags)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  int n = 0;
  const double *p = NULL, *w = NULL;
  const unsigned char *f = NULL;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(cell >= 0 && cell < rules->num_cells, ctx, FCM_ERR_ARG,
            "cell rules: cell %lld out of range [0,%lld)", (long long)cell,
            (long long)rules->num_cells);
  FCM_TRY(ctx, check_kind(rules, kind, "cell rules"));
  rule_range(rules, (fcm_cell_class)rules->cls[cell], kind, rules->piece_off[cell],
             rules->piece_off[cell + 1], &n, &p, &w, &f);
cleanup:
  if (num_points) *num_points = n;
  if (points) *points = p;
  if (weights) *weights = w;
  if (flags) *flags = f;
  return st;
}

/* The surface points [s0, s1) into the outputs (each may be NULL; NULL pointers and 0 points
 * when empty or R is NULL). */
static void surface_range(const fcm_cell_rules *R, fcm_index s0, fcm_index s1, int *num_points,
                          const double **points, const double **weights, const double **normals,
                          const fcm_index **triangles)
{
  const int n = R ? (int)(s1 - s0) : 0;
  if (num_points) *num_points = n;
  if (points) *points = n ? R->spoints + 3 * s0 : NULL;
  if (weights) *weights = n ? R->sweights + s0 : NULL;
  if (normals) *normals = n ? R->snormals + 3 * s0 : NULL;
  if (triangles) *triangles = n ? R->stris + s0 : NULL;
}

fcm_status fcm_cell_rules_get_surface(const fcm_cell_rules *rules, fcm_index cell, int *num_points,
                                      const double **points, const double **weights,
                                      const double **normals, const fcm_index **triangles)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  fcm_index s0 = 0, s1 = 0;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(cell >= 0 && cell < rules->num_cells, ctx, FCM_ERR_ARG,
            "cell rules: cell %lld out of range [0,%lld)", (long long)cell,
            (long long)rules->num_cells);
  s0 = rules->soff[rules->piece_off[cell]];
  s1 = rules->soff[rules->piece_off[cell + 1]];
cleanup:
  surface_range(rules, s0, s1, num_points, points, weights, normals, triangles);
  return st;
}

fcm_index fcm_cell_rules_num_pieces(const fcm_cell_rules *rules)
{
  return rules ? rules->num_pieces : 0;
}

fcm_index fcm_cell_rules_cell_pieces(const fcm_cell_rules *rules, fcm_index cell, fcm_index *first)
{
  if (!rules || cell < 0 || cell >= rules->num_cells) {
    if (first) *first = 0;
    return 0;
  }
  if (first) *first = rules->piece_off[cell];
  return rules->piece_off[cell + 1] - rules->piece_off[cell];
}

fcm_index fcm_cell_rules_piece_cell(const fcm_cell_rules *rules, fcm_index piece)
{
  if (!rules || piece < 0 || piece >= rules->num_pieces) return -1;
  return rules->piece_cell[piece];
}

double fcm_cell_rules_piece_volume(const fcm_cell_rules *rules, fcm_index piece)
{
  if (!rules || piece < 0 || piece >= rules->num_pieces) return 0.0;
  return rules->piece_volume[piece];
}

fcm_status fcm_cell_rules_get_piece(const fcm_cell_rules *rules, fcm_index piece,
                                    fcm_rule_kind kind, int *num_points, const double **points,
                                    const double **weights, const unsigned char **flags)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  int n = 0;
  const double *p = NULL, *w = NULL;
  const unsigned char *f = NULL;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(piece >= 0 && piece < rules->num_pieces, ctx, FCM_ERR_ARG,
            "cell rules: piece %lld out of range [0,%lld)", (long long)piece,
            (long long)rules->num_pieces);
  FCM_TRY(ctx, check_kind(rules, kind, "cell rules"));
  rule_range(rules, (fcm_cell_class)rules->cls[rules->piece_cell[piece]], kind, piece, piece + 1,
             &n, &p, &w, &f);
cleanup:
  if (num_points) *num_points = n;
  if (points) *points = n ? p : NULL;
  if (weights) *weights = n ? w : NULL;
  if (flags) *flags = n ? f : NULL;
  return st;
}

fcm_status fcm_cell_rules_get_piece_surface(const fcm_cell_rules *rules, fcm_index piece,
                                            int *num_points, const double **points,
                                            const double **weights, const double **normals,
                                            const fcm_index **triangles)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  fcm_index s0 = 0, s1 = 0;
  FCM_CHECK(rules, ctx, FCM_ERR_ARG, "cell rules: rules is NULL");
  FCM_CHECK(piece >= 0 && piece < rules->num_pieces, ctx, FCM_ERR_ARG,
            "cell rules: piece %lld out of range [0,%lld)", (long long)piece,
            (long long)rules->num_pieces);
  s0 = rules->soff[piece];
  s1 = rules->soff[piece + 1];
cleanup:
  surface_range(rules, s0, s1, num_points, points, weights, normals, triangles);
  return st;
}

fcm_index fcm_cell_rules_piece_parent(const fcm_cell_rules *rules, fcm_index piece)
{
  if (!rules || piece < 0 || piece >= rules->num_pieces) return -1;
  return rules->piece_parent[piece];
}

fcm_index fcm_cell_rules_parent_num_pieces(const fcm_cell_rules *rules)
{
  return rules ? rules->prev_num_pieces : 0;
}

fcm_index fcm_cell_rules_get_piece_cut_faces(const fcm_cell_rules *rules, fcm_index piece,
                                             const double **xi)
{
  if (!rules || piece < 0 || piece >= rules->num_pieces) {
    if (xi) *xi = NULL;
    return 0;
  }
  const fcm_index n = rules->cfoff[piece + 1] - rules->cfoff[piece];
  if (xi) *xi = n ? rules->cfxi + 9 * rules->cfoff[piece] : NULL;
  return n;
}

fcm_index fcm_cell_rules_num_links(const fcm_cell_rules *rules)
{
  return rules ? rules->num_links : 0;
}

const fcm_index *fcm_cell_rules_links(const fcm_cell_rules *rules)
{
  return rules ? rules->links : NULL;
}

int fcm_cell_rules_num_cuts(const fcm_cell_rules *rules)
{
  return rules ? rules->num_cuts : 0;
}

const fcm_cell_rules_stats *fcm_cell_rules_get_stats(const fcm_cell_rules *rules)
{
  return &rules->stats;
}

void fcm_cell_rules_view(const fcm_cell_rules *rules, FILE *stream)
{
  if (!rules || !stream) return;
  const fcm_cell_rules_stats *S = &rules->stats;
  static const char *names[FCM_RULE_KIND_COUNT] = {"stiffness", "mass"};
  fprintf(stream,
          "cell rules: %s, %lld cells: %lld uncut, %lld cut, %lld dropped (%d threads)\n"
          "  candidates %lld, convex parts %lld, tets %lld, slivers dropped %lld (volume %.3g)\n"
          "  embedded volume %.17g (geometry %.17g, in dropped cells %.3g",
          fcm_element_get_info(rules->type)->name, (long long)S->num_cells, (long long)S->num_uncut,
          (long long)S->num_cut, (long long)S->num_dropped, S->num_threads,
          (long long)S->num_candidates, (long long)S->num_parts, (long long)S->num_tets,
          (long long)S->num_slivers, S->sliver_volume, S->embedded_volume, S->geometry_volume,
          S->dropped_volume);
  if (rules->surface_strength >= 0) /* the boundary those cells' surface rules lose */
    fprintf(stream, ", boundary area in dropped cells %.3g", S->dropped_area);
  fputs(")\n", stream);
  fprintf(stream, "  embedded / geometry volume %.6f; outside the background mesh %.3g",
          S->volume_ratio, S->outside_volume);
  static const char *const sides[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  for (int k = 0; k < 6; k++)
    if (S->outside_side_volume[k] > 0.0)
      fprintf(stream, ", beyond %s %.3g", sides[k], S->outside_side_volume[k]);
  fputc('\n', stream);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++)
    if (!rules->uncut[k])
      fprintf(stream, "  %-9s not built (fcm_cell_rules_options.kinds)\n", names[k]);
    else
      fprintf(stream,
              "  %-9s strength %d, degree <= %d per variable: cut-cell points %lld initial -> %lld "
              "simplified (+%lld stabilization), total %lld; skipped %lld, fallbacks %lld, max "
              "residual %.3g\n",
              names[k], rules->strength[k], rules->axis_degree[k], (long long)S->points_initial[k],
              (long long)S->points_simplified[k], (long long)S->points_stabilization[k],
              (long long)S->points_total[k], (long long)S->simplify_skipped[k],
              (long long)S->simplify_fallbacks[k], S->max_residual[k]);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    const fcm_simplify_decision *d = &S->decision[k];
    if (d->point_cost > 0.0)
      fprintf(stream,
              "  %-9s simplify auto: %s for %g assemblies (%.3g core-s per point): estimated "
              "%.3g core-s simplifying to %.0f points; assembly %.3g core-s plain vs %.3g "
              "simplify + assembly\n",
              names[k], d->simplified ? "on" : "off", d->expected_assemblies, d->point_cost,
              d->estimated_time, d->estimated_kept, d->cost_plain, d->cost_simplified);
  }
  if (rules->surface_strength >= 0)
    fprintf(stream, "  surface strength %d: %lld triangles, %lld points, area %.17g\n",
            rules->surface_strength, (long long)S->surface_triangles, (long long)S->surface_points,
            S->embedded_area);
  fprintf(stream,
          "  time: setup %.3g s, intersect %.3g core-s, simplify %.3g core-s, gather %.3g s, "
          "total %.3g s\n",
          S->time_setup, S->time_intersect, S->time_simplify, S->time_gather, S->time_total);
}

fcm_status fcm_cell_rules_view_points(const fcm_cell_rules *rules, const fcm_mesh *mesh,
                                      fcm_rule_kind kind, FILE *stream)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = rules ? rules->ctx : NULL;
  double x[3], det;
  FCM_CHECK(rules && mesh && stream, ctx, FCM_ERR_ARG,
            "cell rules view: NULL argument (rules, mesh and stream are required)");
  FCM_TRY(ctx, check_kind(rules, kind, "cell rules view"));
  FCM_CHECK(fcm_mesh_num_cells(mesh) == rules->num_cells &&
                fcm_mesh_element_type(mesh) == rules->type,
            ctx, FCM_ERR_ARG, "cell rules view: mesh (%lld cells) is not the rules' mesh (%lld)",
            (long long)fcm_mesh_num_cells(mesh), (long long)rules->num_cells);
  FCM_CHECK(fprintf(stream, "# cell xi eta zeta X Y Z w_ref w_phys flag\n") > 0, ctx, FCM_ERR_IO,
            "cell rules view: write failed");
  for (fcm_index c = 0; c < rules->num_cells; c++) {
    int n;
    const double *p, *w;
    const unsigned char *f;
    FCM_TRY(ctx, fcm_cell_rules_get(rules, c, kind, &n, &p, &w, &f));
    for (int j = 0; j < n; j++) {
      FCM_TRY(ctx, fcm_cell_rules_map_points(rules, mesh, c, 1, p + 3 * j, x, &det));
      FCM_CHECK(fprintf(stream, "%lld %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %d\n",
                        (long long)c, p[3 * j], p[3 * j + 1], p[3 * j + 2], x[0], x[1], x[2], w[j],
                        w[j] * det, (int)f[j]) > 0,
                ctx, FCM_ERR_IO, "cell rules view: write failed");
    }
  }
cleanup:
  return st;
}

fcm_status fcm__embed_selected_area(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                    const fcm_cell_rules *rules, fcm__embed_select_fn select,
                                    void *user, double *kept, double *dropped)
{
  fcm_status st = FCM_OK;
  fcm__embed_ws ws;
  fcm__embed_counts none;
  fcm_rule *tri_rule = NULL;
  const fcm_aabb_tree *tree = NULL;
  double X[3 * FCM_ELEMENT_MAX_NODES], x[3];
  memset(&ws, 0, sizeof ws);
  memset(&none, 0, sizeof none);
  *kept = *dropped = 0.0;
  if (rules->surface_strength < 0) return FCM_OK;
  FCM_TRY(ctx, fcm_rule_create(ctx, FCM_SHAPE_TRI, rules->surface_strength, &tri_rule));
  FCM_TRY(ctx, fcm__geom_tree(ctx, geom, 1, &tree));
  for (fcm_index c = 0; c < rules->num_cells; c++) {
    if (rules->masked && !rules->own[c]) continue; /* another process's cell */
    if (rules->cls[c] != FCM_CELL_DROPPED) {
      const fcm_index s0 = rules->soff[rules->piece_off[c]],
                      s1 = rules->soff[rules->piece_off[c + 1]];
      if (s0 == s1) continue;
      fcm_mesh_cell_coords(mesh, c, X);
      for (fcm_index s = s0; s < s1; s++) {
        fcm_element_map(rules->type, X, rules->spoints + 3 * s, x);
        if (select(user, x, rules->snormals + 3 * s)) *kept += rules->sweights[s];
      }
      continue;
    }
    fcm__embed_cell cell; /* a dropped cell: its surface clipped as a kept cell's would be */
    FCM_TRY(ctx, fcm__embed_cell_setup(ctx, mesh, c, rules->opts.clip_rtol, &cell));
    FCM_TRY(ctx, fcm__embed_cell_surface(ctx, geom, tree, &cell, NULL, 0, rules->opts.sliver_rtol,
                                         tri_rule, &ws, &none));
    for (size_t j = 0; j < ws.num_spts; j++)
      if (select(user, ws.spts + 3 * j, ws.snrm + 3 * j)) *dropped += ws.sw[j];
  }
cleanup:
  fcm__embed_ws_free(ctx, &ws);
  fcm_rule_destroy(&tri_rule);
  return st;
}
