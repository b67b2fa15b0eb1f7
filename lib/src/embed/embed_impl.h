/* fcm embed, internal part: the rule-storage struct and the per-background-cell
 * kernels (cell setup, clipping into tets, rule mapping, surface clipping). */
#ifndef FCM_EMBED_IMPL_H
#define FCM_EMBED_IMPL_H

#include "core/core_impl.h"
#include "fcm/embed.h"
#include "fcm/quad.h"
#include "geom/geom_impl.h"

struct fcm_cell_rules {
  fcm_ctx *ctx;
  fcm_index num_cells;
  fcm_element_type type;
  int strength[FCM_RULE_KIND_COUNT];
  int surface_strength;
  unsigned char *cls; /* num_cells fcm_cell_class values */
  double *fraction;   /* num_cells volume fractions */
  /* Cut cells: entries [off[c], off[c+1]) of the concatenated arrays (empty otherwise). */
  fcm_index *off[FCM_RULE_KIND_COUNT];
  double *points[FCM_RULE_KIND_COUNT]; /* x 3 */
  double *weights[FCM_RULE_KIND_COUNT];
  unsigned char *flags[FCM_RULE_KIND_COUNT];
  /* Uncut cells share the catalogue rule of each kind (flags all 0). */
  fcm_rule *uncut[FCM_RULE_KIND_COUNT];
  unsigned char *uncut_flags[FCM_RULE_KIND_COUNT];
  /* Surface rules of non-dropped cells: entries [soff[c], soff[c+1]). */
  fcm_index *soff;
  double *spoints;  /* x 3 */
  double *sweights; /* area weights */
  double *snormals; /* x 3 */
  fcm_index *stris; /* boundary triangle of each point */
  fcm_cell_rules_stats stats;
};

/* A background cell prepared for clipping and mapping. */
typedef struct fcm__embed_cell {
  fcm_element_type type;
  const fcm_element_info *info;
  fcm_index id;
  double X[3 * FCM_ELEMENT_MAX_NODES]; /* nodal coordinates */
  fcm__plane planes[FCM_ELEMENT_MAX_FACES];
  int num_planes;
  double size;         /* diagonal of the corners' bounding box */
  double tol;          /* clipping tolerance: clip_rtol * size */
  double volume;       /* |K| of the corner polyhedron */
  double lo[3], hi[3]; /* corner bounding box widened by tol */
  int affine;          /* closed-form inverse map */
  double A[9], Ainv[9], xi0[3], detA;
} fcm__embed_cell;

/* Per-thread workspace of the kernels; zero-initialize, release with
 * fcm__embed_ws_free(). */
typedef struct fcm__embed_ws {
  fcm__idbuf cand;
  double *tets; /* 12 per tet: c, a, b, e */
  double *vol;  /* signed volume per tet */
  size_t num_tets, tet_cap;
  double *spts; /* surface scratch: physical points (x 3), weights, normals (x 3), tris */
  double *sw, *snrm;
  fcm_index *stri;
  size_t num_spts, spt_cap;
  fcm__poly poly, scratch;
} fcm__embed_ws;

void fcm__embed_ws_free(fcm_ctx *ctx, fcm__embed_ws *ws);

/* Gather cell `id` of `mesh` and compute its planes, size, tolerance, volume and map.
 * FCM_ERR_GEOMETRY when the corner polyhedron has no positive volume. */
fcm_status fcm__embed_cell_setup(fcm_ctx *ctx, const fcm_mesh *mesh, fcm_index id, double clip_rtol,
                                 fcm__embed_cell *cell);

/* Counters of the per-cell kernels (summed over cells into the statistics). */
typedef struct fcm__embed_counts {
  fcm_index candidates;        /* (background cell, embedded cell) pairs from the tree */
  fcm_index pieces;            /* non-empty clipped polyhedra */
  fcm_index tets;              /* tets kept */
  fcm_index slivers;           /* tets dropped as slivers */
  fcm_index surface_triangles; /* clipped boundary triangles kept */
  double sliver_volume;        /* summed volume of the dropped slivers */
} fcm__embed_counts;

/* Clip every candidate embedded cell E by the planes of `cell` and tetrahedralize the
 * pieces into ws->tets / ws->vol. Both tolerances follow the smaller of the two scales,
 * so that geometry much thinner than the background cell keeps its volume: a vertex is
 * on a plane within min(cell->tol, clip_rtol * t_E), t_E = 6 |E| / diam(E)^2 being E's
 * thickness, and tets with volume <= sliver_rtol * min(|K|, |E|) are dropped (counted,
 * with their volume). *volume = sum of the kept tets' volumes. */
fcm_status fcm__embed_cell_tets(fcm_ctx *ctx, const fcm_geometry *geom, const fcm_aabb_tree *tree,
                                const fcm__embed_cell *cell, double clip_rtol, double sliver_rtol,
                                fcm__embed_ws *ws, fcm__embed_counts *counts, double *volume);

/* Reference coordinates xi and det J_K(xi) of the physical point x. */
fcm_status fcm__embed_to_reference(fcm_ctx *ctx, const fcm__embed_cell *cell, const double x[3],
                                   double xi[3], double *det);

/* Map the tet rule `rule` onto every tet of ws and into the reference cell: writes
 * ws->num_tets * rule points to pts (x 3) and reference weights to w. */
fcm_status fcm__embed_map_tets(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__embed_ws *ws,
                               const fcm_rule *rule, double *pts, double *w);

/* Clip the candidate boundary triangles by the planes of `cell` (a triangle flat on a
 * cell plane is kept only when its outward normal agrees with the plane's) and map the
 * triangle rule onto the fan triangles: physical points, area weights, unit normals and
 * triangle ids into ws->spts, ws->sw, ws->snrm, ws->stri (ws->num_spts of them).
 * counts->surface_triangles += clipped triangles kept. */
fcm_status fcm__embed_cell_surface(fcm_ctx *ctx, const fcm_geometry *geom,
                                   const fcm_aabb_tree *tri_tree, const fcm__embed_cell *cell,
                                   double sliver_rtol, const fcm_rule *tri_rule, fcm__embed_ws *ws,
                                   fcm__embed_counts *counts);

/* The embedding diagnostics of the statistics S (geometry, embedded and sliver volumes
 * already set): bounding boxes, volume ratio, the volume outside the mesh and beyond each
 * face of its bounding box. FCM_ERR_GEOMETRY, with both bounding boxes, when a geometry of
 * positive volume has none inside the mesh; FCM_ERR_ALLOC. Single-threaded. */
fcm_status fcm__embed_outside(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                              fcm_cell_rules_stats *S);

#endif /* FCM_EMBED_IMPL_H */
