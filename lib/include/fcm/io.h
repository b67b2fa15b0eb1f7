/* fcm — output for ParaView: VTK XML UnstructuredGrid (.vtu) files with raw appended
 * binary data, and PVD time-series indices. Every file is written atomically: data
 * goes to a temporary file beside the target, which replaces the target only when
 * complete, so a reader (or an interrupted run) never sees a half-written file.
 *
 * Typical use, one frame per time step:
 *   fcm_vtu_create(ctx, &vtu);
 *   fcm_vtu_set_points(vtu, n_nodes, xyz);                       (borrowed)
 *   fcm_vtu_set_cells(vtu, FCM_VTK_QUADRATIC_HEXAHEDRON, n_cells, conn);
 *   fcm_vtu_add_field(vtu, FCM_VTU_POINT_DATA, "displacement", 3, n_nodes, u);
 *   fcm_pvd_create(ctx, "out/run.pvd", &pvd);
 *   for each step: update xyz/u in place; fcm_vtu_write(vtu, "out/f_0007.vtu", &info);
 *                  fcm_pvd_add(pvd, t, "out/f_0007.vtu");
 * An embedded surface is a .vtu with FCM_VTK_TRIANGLE cells; quadrature points are a
 * .vtu of FCM_VTK_VERTEX cells (connectivity NULL: one vertex per point). */
#ifndef FCM_IO_H
#define FCM_IO_H

#include "fcm/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** VTK cell types the VTU writer accepts (the values are VTK's ids; node order is
 * VTK's, which is fcm's element node order). */
typedef enum fcm_vtk_cell_type {
  FCM_VTK_VERTEX = 1,
  FCM_VTK_TRIANGLE = 5,
  FCM_VTK_QUAD = 9,
  FCM_VTK_TETRA = 10,
  FCM_VTK_HEXAHEDRON = 12,
  FCM_VTK_QUADRATIC_TRIANGLE = 22,
  FCM_VTK_QUADRATIC_TETRA = 24,
  FCM_VTK_QUADRATIC_HEXAHEDRON = 25
} fcm_vtk_cell_type;

/** Number of nodes of a VTK cell type (1, 3, 4, 4, 8, 6, 10, 20), or 0 when the
 * writer does not support `vtk_type`. No allocation; thread safe. */
FCM_API int fcm_vtk_cell_num_nodes(int vtk_type);

/** Where a field lives: one tuple per point or one tuple per cell. */
typedef enum fcm_vtu_location { FCM_VTU_POINT_DATA = 0, FCM_VTU_CELL_DATA = 1 } fcm_vtu_location;

/** What fcm_vtu_write() reports. Non-finite values (NaN, +-Inf) in the points or in
 * a Float64 field are written unchanged (VTK reads them) and counted here: the
 * library does not print, so the caller decides whether a count > 0 is an error. */
typedef struct fcm_vtu_info {
  long long num_nonfinite;         /**< non-finite doubles written (points and fields) */
  const char *first_nonfinite;     /**< name of the first array holding one ("Points" or
                                        the field name; owned by the writer, valid until
                                        it is cleared or destroyed), NULL when none */
  long long first_nonfinite_index; /**< index of that value in its array, -1 when none */
  long long file_bytes;            /**< size of the file written */
} fcm_vtu_info;

/** A VTU writer: points, cells and named fields, all borrowed from the caller, then
 * written as one VTK XML UnstructuredGrid file (format "appended", encoding "raw",
 * header_type UInt64, host byte order detected at run time, no compression; Float64
 * points and fields, Int64 connectivity and offsets, UInt8 types). */
typedef struct fcm_vtu fcm_vtu;

/** Create an empty writer (no points, no cells, no fields).
 * @param[in]  ctx allocation and errors; must outlive the writer
 * @param[out] vtu the new writer, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (ctx or vtu NULL), FCM_ERR_ALLOC. Allocates; release with
 * fcm_vtu_destroy(). A writer is used by one thread at a time. */
FCM_API fcm_status fcm_vtu_create(fcm_ctx *ctx, fcm_vtu **vtu);

/** Destroy a writer (the borrowed arrays are not touched); accepts NULL, sets *vtu = NULL. */
FCM_API void fcm_vtu_destroy(fcm_vtu **vtu);

/** Forget points, cells and fields, keeping the writer for another mesh. */
FCM_API void fcm_vtu_clear(fcm_vtu *vtu);

/** Set (or replace) the points.
 * @param[in] num_points n >= 0
 * @param[in] xyz        n x 3 coordinates, row-major; borrowed: must stay valid until the
 *                       last fcm_vtu_write() (it is read at each write, so it may be updated
 *                       in place between frames); may be NULL when n == 0
 * @return FCM_OK, FCM_ERR_ARG. No allocation. */
FCM_API fcm_status fcm_vtu_set_points(fcm_vtu *vtu, fcm_index num_points, const double *xyz);

/** Set (or replace) the cells, all of one type.
 * @param[in] vtk_type     one of fcm_vtk_cell_type
 * @param[in] num_cells    m >= 0
 * @param[in] connectivity m x fcm_vtk_cell_num_nodes(vtk_type) point indices in VTK node
 *                         order, borrowed like the points; NULL is allowed only for
 *                         FCM_VTK_VERTEX and means cell i = point i (then m must equal the
 *                         number of points when written)
 * @return FCM_OK, FCM_ERR_ARG (unknown type, m < 0, NULL connectivity). Indices are checked
 * against [0, num_points) by fcm_vtu_write(). No allocation. */
FCM_API fcm_status fcm_vtu_set_cells(fcm_vtu *vtu, int vtk_type, fcm_index num_cells,
                                     const fcm_index *connectivity);

/** Set (or replace) cells of mixed types: cell c has type vtk_types[c] and its nodes
 * follow those of cell c-1 in `connectivity` (length = sum of the node counts). Both
 * arrays are borrowed; types and indices are checked by fcm_vtu_write().
 * @return FCM_OK, FCM_ERR_ARG (m < 0, NULL arrays with m > 0). No allocation. */
FCM_API fcm_status fcm_vtu_set_cells_mixed(fcm_vtu *vtu, fcm_index num_cells, const int *vtk_types,
                                           const fcm_index *connectivity);

/** Add a Float64 field of `num_components` (1, 3, 6 or 9) values per tuple (6: a symmetric
 * tensor in VTK's order xx, yy, zz, xy, yz, xz; 9: a full tensor, row-major).
 * @param[in] where          point data (one tuple per point) or cell data (one per cell)
 * @param[in] name           non-empty, printable (copied; XML-escaped on output); unique
 *                           among the fields of the same location
 * @param[in] num_tuples     must equal the number of points or cells when written
 * @param[in] data           num_tuples x num_components, row-major; borrowed like the points
 * @return FCM_OK, FCM_ERR_ARG (bad location, name, component count, duplicate name, NULL
 * data with tuples), FCM_ERR_ALLOC. Allocates (the name). */
FCM_API fcm_status fcm_vtu_add_field(fcm_vtu *vtu, fcm_vtu_location where, const char *name,
                                     int num_components, fcm_index num_tuples, const double *data);

/** Add an Int32 field (a cell class flag, a material id, ...); as fcm_vtu_add_field(). */
FCM_API fcm_status fcm_vtu_add_field_int32(fcm_vtu *vtu, fcm_vtu_location where, const char *name,
                                           int num_components, fcm_index num_tuples,
                                           const int32_t *data);

/** Add an Int64 field (global ids, ...); as fcm_vtu_add_field(). */
FCM_API fcm_status fcm_vtu_add_field_int64(fcm_vtu *vtu, fcm_vtu_location where, const char *name,
                                           int num_components, fcm_index num_tuples,
                                           const int64_t *data);

/** Validate and write the file atomically (the hidden ".<name>.tmp.<pid>.<n>" in the same
 * directory, flushed and closed with checks, then renamed over `path`; temporaries left there
 * by dead processes are removed by the first write of a process into the directory).
 * @param[in]  path target file; an existing file is replaced only on success
 * @param[out] info counts of non-finite values and the file size; may be NULL
 * @return FCM_OK; FCM_ERR_ARG (no points set, cell type unknown, connectivity index out of
 * [0, num_points), field tuple count mismatch; the message names the cell or field);
 * FCM_ERR_IO (cannot create, write, close or rename; the message names the path and the
 * system error; the temporary is removed and the previous file is left intact);
 * FCM_ERR_ALLOC. Allocates only transiently; not thread safe on the same writer. */
FCM_API fcm_status fcm_vtu_write(fcm_vtu *vtu, const char *path, fcm_vtu_info *info);

/** A ParaView PVD index of a time series: a list of (time, file) entries rewritten
 * atomically at every addition, so the index on disk is valid after each step. */
typedef struct fcm_pvd fcm_pvd;

/** Create an index at `path` and write it (empty) at once; an existing file there is
 * replaced.
 * @param[in]  path the .pvd file (copied)
 * @param[out] pvd  the new index, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG, FCM_ERR_IO (as fcm_vtu_write()), FCM_ERR_ALLOC. Allocates;
 * release with fcm_pvd_destroy(). One thread at a time per index. */
FCM_API fcm_status fcm_pvd_create(fcm_ctx *ctx, const char *path, fcm_pvd **pvd);

/** Destroy an index (the file stays); accepts NULL, sets *pvd = NULL. */
FCM_API void fcm_pvd_destroy(fcm_pvd **pvd);

/** Append the entry (time, file) and rewrite the index atomically.
 * @param[in] time finite simulation time (written with 17 significant digits)
 * @param[in] file data file, relative to the index's directory; when it starts with that
 *                 directory as written in the index path ("out/f_3.vtu" for "out/run.pvd"),
 *                 the prefix is removed, so the path given to fcm_vtu_write() may be used
 * @return FCM_OK, FCM_ERR_ARG (non-finite time, empty or unprintable file name),
 * FCM_ERR_IO, FCM_ERR_ALLOC. On failure the entry is not added and the previous index
 * file is intact. Allocates. */
FCM_API fcm_status fcm_pvd_add(fcm_pvd *pvd, double time, const char *file);

/** Number of entries in the index. */
FCM_API fcm_index fcm_pvd_num_entries(const fcm_pvd *pvd);

/** An output file replaced atomically, for callers writing their own formats (CSV tables,
 * plot scripts) with stdio: the data goes to a temporary "<path>.tmp.<pid>.<n>" beside the
 * target (created exclusively), which replaces `path` only at fcm_atomic_file_commit(). The
 * library's own writers use the same code. One thread at a time per file. */
typedef struct fcm_atomic_file fcm_atomic_file;

/** Create the temporary for `path`.
 * @param[in]  path target file (copied); an existing file is replaced only at commit
 * @param[out] file the open file, NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (path NULL or empty); FCM_ERR_IO (the temporary cannot be
 * created; the message names `path` and the system error); FCM_ERR_ALLOC. Nothing is left
 * on disk on failure. Allocates; release with fcm_atomic_file_commit() or _abort(). */
FCM_API fcm_status fcm_atomic_file_open(fcm_ctx *ctx, const char *path, fcm_atomic_file **file);

/** The stream to write to (owned by `file`; do not close it). */
FCM_API FILE *fcm_atomic_file_stream(fcm_atomic_file *file);

/** Check the stream for earlier write errors, flush, close (each checked) and rename the
 * temporary over the target; releases the file and sets *file = NULL either way.
 * @return FCM_OK; FCM_ERR_ARG (file NULL); FCM_ERR_IO (a write, flush, close or rename
 * failed; the message names the path; the temporary is removed and the target untouched). */
FCM_API fcm_status fcm_atomic_file_commit(fcm_atomic_file **file);

/** Close and remove the temporary and release the file; accepts NULL and *file == NULL,
 * sets *file = NULL. Never fails. */
FCM_API void fcm_atomic_file_abort(fcm_atomic_file **file);

#ifdef __cplusplus
}
#endif
#endif /* FCM_IO_H */
