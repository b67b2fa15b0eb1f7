/* fcm geom, internal part: the geometry and AABB-tree structs, and the convex
 * polyhedron / polygon clipping kernels the embed module runs per background cell.
 * What geom may use: lib/docs/architecture.md. */
#ifndef FCM_GEOM_IMPL_H
#define FCM_GEOM_IMPL_H

#include "core/core_impl.h"
#include "fcm/geom.h"
#include "fcm/levelset.h"

struct fcm_geometry {
  fcm_ctx *ctx;
  fcm_element_type type; /* FCM_ELEMENT_TET4 or FCM_ELEMENT_HEX8 */
  int npc;               /* nodes per cell: 4 or 8 */
  fcm_index num_nodes;
  fcm_index num_cells;
  double *coords;   /* num_nodes x 3 */
  fcm_index *cells; /* num_cells x npc */
  fcm_index num_tris;
  fcm_index *tris;     /* num_tris x 3 node ids, counter-clockwise seen from outside */
  fcm_index *tri_cell; /* num_tris: the cell each boundary triangle belongs to */
  double volume;       /* sum of the cell volumes */
  int custom_boundary; /* 1: tris were not derived from the cells (voxel boxes: the exposed
                          voxel faces); fcm_geometry_create_transformed() keeps them */
  double lo[3], hi[3]; /* bounding box of the nodes */
  /* A subset (fcm__geom_create_subset()): the original id of each kept cell and boundary
   * triangle (NULL: not a subset), the original counts; volume and lo/hi stay those of the
   * original geometry, tri_cell is the kept cell's id or -1 when that cell was not kept.
   * outside_*: set by the embed module's crop (fcm__embed_crop_geometry()): the volume of the
   * ORIGINAL geometry beyond each side of the background mesh box outside_mesh_lo/hi. */
  fcm_index *cell_orig, *tri_orig;
  fcm_index orig_cells, orig_tris;
  int has_outside;
  double outside_mesh_lo[3], outside_mesh_hi[3], outside_side[6];
  /* Search trees of the boxes of the cells [0] and of the boundary triangles [1]: built on
   * first use (fcm__geom_tree()), then only read, by every rules build on this geometry,
   * until the geometry is destroyed. */
  fcm_aabb_tree *trees[2];
};

/* Create a geometry that takes ownership of *coords and *cells (allocated with
 * fcm__calloc on ctx); both are NULL on return, success or failure. Validates ids,
 * finiteness and (Hex8) convexity; a negatively oriented Tet4 is reoriented, a
 * negatively oriented Hex8 rejected. With `require_positive` (procedural shapes, which
 * orient their tets themselves), nothing is reoriented and a cell of zero or negative
 * volume is an FCM_ERR_INTERNAL. `who` names the caller in messages. Builds the
 * boundary triangles. */
fcm_status fcm__geom_create_take(fcm_ctx *ctx, const char *who, fcm_element_type type,
                                 fcm_index num_nodes, double **coords, fcm_index num_cells,
                                 fcm_index **cells, int require_positive, fcm_geometry **geom);

/* A geometry without cells: the closed, outward-oriented triangle surface (nv vertices, nt
 * triangles, copied) as its boundary; volume by the divergence theorem (FCM_ERR_GEOMETRY when
 * not positive: an inward surface). Tet4 type, num_cells 0, tri_cell -1. */
fcm_status fcm__geom_create_boundary(fcm_ctx *ctx, const char *who, fcm_index nv,
                                     const double *coords, fcm_index nt, const fcm_index *tris,
                                     fcm_geometry **geom);

/* A subset of g: the cells with keep_cell[c] and the boundary triangles with keep_tri[t] (not
 * rebuilt from the kept cells), both in their original order, and the nodes they use in
 * theirs (coordinates copied bit for bit); volume and bounding box those of g. Original ids
 * in cell_orig / tri_orig (composed when g is a subset itself). For the embedding's kernels
 * (fcm__embed_crop_geometry()): sorted candidate ids of the subset map to sorted ids of g. */
fcm_status fcm__geom_create_subset(fcm_ctx *ctx, const fcm_geometry *g,
                                   const unsigned char *keep_cell, const unsigned char *keep_tri,
                                   fcm_geometry **out);

/* 1 when the sampling spacing h resolves the smallest feature of implicit node q (the rule
 * of fcm_implicit_check_spacing()); else 0 with *key the member that sets the feature (its
 * scene key; NULL for a box, whose message names the side) and `msg` the reason with the
 * value and h. CSG nodes are always resolved. */
int fcm__implicit_resolved(const fcm_implicit *q, double h, const char **key, char *msg,
                           size_t len);

/* Bytes of the geometry's arrays (coordinates, cells, triangles, maps) and struct. */
FCM_COMPONENT_API double fcm__geom_bytes(const fcm_geometry *g);

/* ---------------------------------------------------------------- AABB tree */

typedef struct fcm__aabb_node {
  double lo[3], hi[3];
  fcm_index first; /* leaf: first slot in perm; inner: index of the left child */
  fcm_index count; /* leaf: number of items (> 0); inner: 0 (right child = left + 1) */
} fcm__aabb_node;

struct fcm_aabb_tree {
  fcm_ctx *ctx;
  fcm_index num_items;
  fcm_index num_nodes;
  fcm__aabb_node *nodes; /* node 0 is the root (absent when num_items == 0) */
  fcm_index *perm;       /* item ids, leaves own contiguous ranges */
  double *boxes;         /* num_items x 6 copy: lo[3], hi[3] */
  double *slot_boxes;    /* the same in slot order (box s is that of item perm[s]) */
};

/* Growable id buffer for queries from many threads (one buffer per thread). */
typedef struct fcm__idbuf {
  fcm_index *ids;
  size_t n, cap;
} fcm__idbuf;

/* Ids of the items whose box intersects [lo, hi] (closed boxes), ascending, into
 * buf (grown through ctx as needed; buf->n is reset first). Thread safe for distinct
 * buffers. */
fcm_status fcm__geom_tree_query(fcm_ctx *ctx, const fcm_aabb_tree *tree, const double lo[3],
                                const double hi[3], fcm__idbuf *buf);

/* The box of all the tree's items into lo, hi (the root's); 0 for a tree without items. */
int fcm__geom_tree_bounds(const fcm_aabb_tree *tree, double lo[3], double hi[3]);

/* Boxes (n x 6: lo[3], hi[3], allocated on ctx) of g's cells (tris = 0) or boundary
 * triangles (tris = 1). */
fcm_status fcm__geom_boxes(fcm_ctx *ctx, const fcm_geometry *g, int tris, double **out,
                           fcm_index *n);

/* The search tree of g's cells (tris = 0) or boundary triangles (tris = 1), built on the first
 * call and kept by g (allocated on g's context; thread safe). Errors: FCM_ERR_ALLOC, on ctx. */
fcm_status fcm__geom_tree(fcm_ctx *ctx, const fcm_geometry *g, int tris,
                          const fcm_aabb_tree **tree);

/* Ids of the items whose box, widened by pad, meets the segment p0 -> p1, ascending, into
 * buf (as fcm__geom_tree_query()). */
fcm_status fcm__geom_tree_segment(fcm_ctx *ctx, const fcm_aabb_tree *tree, const double p0[3],
                                  const double p1[3], double pad, fcm__idbuf *buf);

/* Release a buffer's storage. */
void fcm__geom_idbuf_free(fcm_ctx *ctx, fcm__idbuf *buf);

/* ---------------------------------------------------------------- convex clipping */

#define FCM__POLY_MAX_VERTS 128
#define FCM__POLY_MAX_FACES 64
#define FCM__POLY_MAX_FV    64

/* A half-space {x : n.x <= d} with unit outward normal n. */
typedef struct fcm__plane {
  double n[3];
  double d;
} fcm__plane;

/* A convex polyhedron: vertex positions and faces as vertex cycles, counter-
 * clockwise seen from outside, each with the plane it lies on (outward): the plane of the
 * cell face it came from, or the clipping plane that made it. Carrying the plane, instead of
 * fitting one to the face's vertices, keeps it exact on sliver faces, whose fitted plane is
 * ill-conditioned (two sides of one face must agree on it). nf == 0 means empty. Plain
 * value type (~26 kB). */
typedef struct fcm__poly {
  int nv, nf;
  double x[FCM__POLY_MAX_VERTS][3];
  int fn[FCM__POLY_MAX_FACES];
  int fv[FCM__POLY_MAX_FACES][FCM__POLY_MAX_FV];
  fcm__plane fp[FCM__POLY_MAX_FACES];
} fcm__poly;

/* Polyhedron of a Tet4 (4 nodes) or convex Hex8 (8 nodes, VTK order) cell from its
 * corner coordinates X (npc x 3), faces from the element's face tables, their planes from
 * fcm__geom_cell_planes(). */
void fcm__geom_poly_from_cell(fcm_element_type type, const double *X, fcm__poly *p);

/* fcm__geom_poly_from_cell() without the faces' planes (p->fp left as it is): what
 * fcm__geom_poly_volume() and fcm__geom_poly_tets() need. */
void fcm__geom_poly_from_cell_shape(fcm_element_type type, const double *X, fcm__poly *p);

/* Outward half-spaces of the planar faces of a convex cell from its corners (Newell
 * normal, through the face-corner centroid). Returns the number of planes (4 or 6);
 * a degenerate face (zero normal) gets n = 0, d = 0 (never clips). */
int fcm__geom_cell_planes(const fcm_element_info *info, const double *X, fcm__plane *planes);

/* Copy the used part of src into dst (counts, vertices, faces and planes up to the counts;
 * the struct is ~26 kB, mostly unused): what a polyhedron's readers read. */
void fcm__geom_poly_copy(fcm__poly *dst, const fcm__poly *src);

/* Clip p by the half-space `pl` in place. Each vertex is classified once against
 * the plane: outside when n.x - d > tol, inside when < -tol, on the plane otherwise;
 * on-plane vertices are kept where they are and new vertices are made only on edges
 * whose ends are strictly on opposite sides (one per edge, shared by its two faces).
 * `scratch` is workspace. Returns 0, or -1 when a capacity FCM__POLY_MAX_* would be
 * exceeded (p is then left empty). */
int fcm__geom_poly_clip(fcm__poly *p, const fcm__plane *pl, double tol, fcm__poly *scratch);

/* Number of tetrahedra fcm__geom_poly_tets() makes: sum over faces of (fn - 2). */
int fcm__geom_poly_num_tets(const fcm__poly *p);

/* Tetrahedralize p by a fan from its vertex centroid c over a fan triangulation of
 * each face: tet k is (c, a, b, e) stored as 12 doubles in tets[12 k ...] and its
 * signed volume in vol[k] (positive for a convex p with outward faces). When some come out
 * negative (a part the tolerances left slightly non-convex), the fan from the vertex with the
 * least negative volume instead (its own faces' triangles skipped); the signed volumes add
 * up to the same total either way. Returns the number of tets written (at most
 * fcm__geom_poly_num_tets()). */
int fcm__geom_poly_tets(const fcm__poly *p, double *tets, double *vol);

/* Volume of p (sum of the signed fan volumes). */
double fcm__geom_poly_volume(const fcm__poly *p);

/* Clip the polygon (n vertices x 3, in/out, capacity `cap` vertices) by the half-
 * space with the same classification rule as fcm__geom_poly_clip; `work` holds cap x 3
 * doubles. Returns the new vertex count (0: empty), or -1 on overflow. When every
 * vertex is on the plane the polygon is kept iff keep_coplanar is set. */
int fcm__geom_polygon_clip(double *x, int n, int cap, const fcm__plane *pl, double tol,
                           int keep_coplanar, double *work);

#endif /* FCM_GEOM_IMPL_H */
