/* fcm_mesh_create_box for Tet4, Tet10, Hex8, Hex20: counts, total volume, positive
 * Jacobians, distinct nodes, mid-edge nodes at edge midpoints, conforming faces,
 * boundary faces (count, outward normals, area), plane queries, determinism. */
#include "mesh_util.h"

typedef struct face_rec {
  fcm_index key[4]; /* sorted corner ids, -1 padded */
  fcm_index all[8]; /* sorted ids of all face nodes, -1 padded */
  fcm_index cell;
  int face;
} face_rec;

static int cmp_face(const void *a, const void *b)
{
  const face_rec *p = a, *q = b;
  for (int k = 0; k < 4; k++)
    if (p->key[k] != q->key[k]) return p->key[k] < q->key[k] ? -1 : 1;
  return 0;
}

static int cmp_index(const void *a, const void *b)
{
  fcm_index p = *(const fcm_index *)a, q = *(const fcm_index *)b;
  return (p > q) - (p < q);
}

static int cmp_point(const void *a, const void *b)
{
  const double *p = a, *q = b;
  for (int d = 0; d < 3; d++)
    if (p[d] != q[d]) return p[d] < q[d] ? -1 : 1;
  return 0;
}

static void check_box(fcm_ctx *ctx, fcm_element_type type, const fcm_index n[3])
{
  const double lo[3] = {-1.0, 0.5, -3.0}, hi[3] = {2.0, 1.0, -1.0};
  const double L[3] = {3.0, 0.5, 2.0}, size = 3.0;
  const double vol = L[0] * L[1] * L[2], area = 2 * (L[0] * L[1] + L[1] * L[2] + L[2] * L[0]);
  const int tet = is_tet_type(type);
  fcm_mesh *m = NULL;
  face_rec *faces = NULL;
  double *pts = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &m));
  if (!m) return;
  const fcm_element_info *info = fcm_element_get_info(type);
  const int npc = info->num_nodes, nf = info->num_faces;
  const fcm_index nx = n[0], ny = n[1], nz = n[2];

  /* Counts. Corners (nx+1)(ny+1)(nz+1); edges along the axes; tets add one diagonal per
   * grid face and one per cube. */
  const fcm_index corners = (nx + 1) * (ny + 1) * (nz + 1);
  const fcm_index axis_edges =
      nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz;
  const fcm_index diagonals = nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz;
  fcm_index nn = corners;
  if (type == FCM_ELEMENT_HEX20) nn += axis_edges;
  if (type == FCM_ELEMENT_TET10) nn += axis_edges + diagonals + nx * ny * nz;
  const fcm_index nc = (tet ? 6 : 1) * nx * ny * nz;
  TEST_TRUE(fcm_mesh_element_type(m) == type);
  TEST_TRUE(fcm_mesh_num_nodes(m) == nn);
  TEST_TRUE(fcm_mesh_num_cells(m) == nc);
  TEST_TRUE(fcm_mesh_nodes_per_cell(m) == npc);
  const double *x = fcm_mesh_coords(m);
  const fcm_index *cells = fcm_mesh_cells(m);

  /* Total volume; every cell's det J > 0 at its nodes' reference points and at the
   * 2x2x2 Gauss points; mid-edge nodes at edge midpoints. */
  double total = 0.0;
  int nmid = 0;
  const int(*mid)[3] = vtk_mid_edges(type, &nmid);
  const double *ref = fcm_element_ref_nodes(type);
  for (fcm_index c = 0; c < nc; c++) {
    double X[3 * FCM_ELEMENT_MAX_NODES], J[9];
    fcm_mesh_cell_coords(m, c, X);
    double v = cell_volume(type, X);
    TEST_TRUE(v > 0);
    total += v;
    for (int a = 0; a < npc; a++)
      TEST_TRUE(fcm_element_jacobian(type, X, ref + 3 * a, J) > 0);
    for (int e = 0; e < nmid; e++)
      for (int d = 0; d < 3; d++)
        TEST_NEAR(X[3 * mid[e][0] + d], 0.5 * (X[3 * mid[e][1] + d] + X[3 * mid[e][2] + d]), 0,
                  1e-14 * size);
  }
  TEST_NEAR(total, vol, 1e-12, 0);
  const double g = 1.0 / sqrt(3.0);
  const double gauss[24] = {-g, -g, -g, g, -g, -g, -g, g, -g, g, g, -g,
                            -g, -g, g,  g, -g, g,  -g, g, g,  g, g, g};
  const double tetpts[6] = {0.25, 0.25, 0.25, 0.1, 0.2, 0.3};
  double min_det = 0;
  TEST_OK(ctx, fcm_mesh_validate(ctx, m, tet ? 2 : 8, tet ? tetpts : gauss, &min_det));
  TEST_TRUE(min_det > 0);

  /* Every node inside the box, used by a cell, and no two nodes at the same place. */
  pts = malloc(sizeof *pts * 3 * (size_t)nn);
  char *used = calloc((size_t)nn, 1);
  for (fcm_index i = 0; i < nc * npc; i++)
    used[cells[i]] = 1;
  for (fcm_index a = 0; a < nn; a++) {
    TEST_TRUE(used[a]);
    for (int d = 0; d < 3; d++)
      TEST_TRUE(x[3 * a + d] >= lo[d] && x[3 * a + d] <= hi[d]);
  }
  free(used);
  memcpy(pts, x, sizeof *pts * 3 * (size_t)nn);
  qsort(pts, (size_t)nn, 3 * sizeof *pts, cmp_point);
  for (fcm_index a = 1; a < nn; a++) {
    const double *p = pts + 3 * (a - 1), *q = pts + 3 * a;
    double dist = fabs(p[0] - q[0]) + fabs(p[1] - q[1]) + fabs(p[2] - q[2]);
    if (!(dist > 1e-9 * size)) TEST_FAIL_("nodes coincide at (%g, %g, %g)", q[0], q[1], q[2]);
  }

  /* Conforming: faces keyed by sorted corners appear once (boundary) or twice (interior);
   * the two copies of an interior face have the same nodes, mid-edge nodes included, and
   * the mesh adjacency agrees. */
  faces = malloc(sizeof *faces * (size_t)(nc * nf));
  for (fcm_index c = 0; c < nc; c++)
    for (int f = 0; f < nf; f++) {
      face_rec *r = faces + nf * c + f;
      r->cell = c;
      r->face = f;
      for (int k = 0; k < 4; k++)
        r->key[k] = -1;
      for (int k = 0; k < 8; k++)
        r->all[k] = -1;
      for (int k = 0; k < info->face_num_corners[f]; k++)
        r->key[k] = cells[npc * c + info->face_nodes[f][k]];
      for (int k = 0; k < info->face_num_nodes[f]; k++)
        r->all[k] = cells[npc * c + info->face_nodes[f][k]];
      qsort(r->key, (size_t)info->face_num_corners[f], sizeof(fcm_index), cmp_index);
      qsort(r->all, (size_t)info->face_num_nodes[f], sizeof(fcm_index), cmp_index);
    }
  qsort(faces, (size_t)(nc * nf), sizeof *faces, cmp_face);
  const fcm_index *nb = fcm_mesh_neighbors(m);
  fcm_index boundary = 0;
  for (fcm_index i = 0; i < nc * nf;) {
    fcm_index j = i + 1;
    while (j < nc * nf && cmp_face(faces + i, faces + j) == 0)
      j++;
    const face_rec *p = faces + i, *q = faces + i + 1;
    if (j - i == 1) {
      boundary++;
      TEST_TRUE(nb[nf * p->cell + p->face] == -1);
    } else if (j - i == 2) {
      TEST_TRUE(memcmp(p->all, q->all, sizeof p->all) == 0);
      TEST_TRUE(nb[nf * p->cell + p->face] == q->cell);
      TEST_TRUE(nb[nf * q->cell + q->face] == p->cell);
    } else {
      TEST_FAIL_("face shared by %lld cells", (long long)(j - i));
    }
    i = j;
  }
  const fcm_index expect_boundary = (tet ? 4 : 2) * (nx * ny + ny * nz + nz * nx);
  TEST_TRUE(boundary == expect_boundary);
  TEST_TRUE(fcm_mesh_num_boundary_faces(m) == expect_boundary);

  /* Boundary faces: unit outward normal along an axis, centroid on that side of the box,
   * pointing away from the box centre; areas add up to the box surface. */
  const fcm_index *bf = fcm_mesh_boundary_faces(m);
  double sum_area = 0.0;
  for (fcm_index i = 0; i < fcm_mesh_num_boundary_faces(m); i++) {
    const fcm_index c = bf[2 * i];
    const int f = (int)bf[2 * i + 1], fc = info->face_num_corners[f];
    double P[12], a[3], cen[3] = {0, 0, 0};
    for (int k = 0; k < fc; k++)
      for (int d = 0; d < 3; d++) {
        P[3 * k + d] = x[3 * cells[npc * c + info->face_nodes[f][k]] + d];
        cen[d] += P[3 * k + d] / fc;
      }
    polygon_area_vector(fc, P, a);
    const double len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    sum_area += len;
    double out = 0.0;
    for (int d = 0; d < 3; d++)
      out += a[d] * (cen[d] - 0.5 * (lo[d] + hi[d]));
    TEST_TRUE(out > 0);
    int axis = 0;
    for (int d = 1; d < 3; d++)
      if (fabs(a[d]) > fabs(a[axis])) axis = d;
    TEST_NEAR(fabs(a[axis]), len, 1e-12, 0);
    TEST_NEAR(cen[axis], a[axis] > 0 ? hi[axis] : lo[axis], 0, 1e-14 * size);
  }
  TEST_NEAR(sum_area, area, 1e-12, 0);

  /* Nodes on the plane x = lo[0]: all of them, and only them. */
  const double plo[3] = {lo[0], -HUGE_VAL, -HUGE_VAL}, phi[3] = {lo[0], HUGE_VAL, HUGE_VAL};
  fcm_index count = -1, expect = 0, got = 0;
  for (fcm_index a = 0; a < nn; a++)
    expect += x[3 * a] == lo[0];
  fcm_index plane_corners = (ny + 1) * (nz + 1);
  fcm_index plane_nodes = plane_corners;
  if (type == FCM_ELEMENT_HEX20) plane_nodes += ny * (nz + 1) + (ny + 1) * nz;
  if (type == FCM_ELEMENT_TET10) plane_nodes += ny * (nz + 1) + (ny + 1) * nz + ny * nz;
  TEST_TRUE(expect == plane_nodes);
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, m, plo, phi, 1e-12, 0, NULL, &count));
  TEST_TRUE(count == expect);
  fcm_index *ids = malloc(sizeof *ids * (size_t)(count + 1));
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, m, plo, phi, 1e-12, count, ids, &got));
  TEST_TRUE(got == count);
  for (fcm_index i = 0; i < got && i < count; i++) {
    TEST_TRUE(x[3 * ids[i]] == lo[0]);
    if (i > 0) TEST_TRUE(ids[i] > ids[i - 1]);
  }
  /* A short array receives the first ids; the count is still the full one. */
  ids[1] = -7;
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, m, plo, phi, 1e-12, 1, ids, &got));
  TEST_TRUE(got == count && ids[1] == -7);
  free(ids);

  /* Every cell of a box grid is convex. */
  fcm_index nonconvex = -1;
  TEST_OK(ctx, fcm_mesh_convex_cells(ctx, m, 1e-12, NULL, &nonconvex));
  TEST_TRUE(nonconvex == 0);

  /* Deterministic numbering. */
  fcm_mesh *m2 = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &m2));
  if (m2) {
    TEST_TRUE(memcmp(fcm_mesh_coords(m2), x, sizeof *x * 3 * (size_t)nn) == 0);
    TEST_TRUE(memcmp(fcm_mesh_cells(m2), cells, sizeof *cells * (size_t)(npc * nc)) == 0);
  }
  fcm_mesh_destroy(&m2);
  free(faces);
  free(pts);
  fcm_mesh_destroy(&m);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  const fcm_index sizes[3][3] = {{1, 1, 1}, {2, 3, 4}, {5, 1, 2}};
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++)
    for (int s = 0; s < 3; s++)
      check_box(ctx, (fcm_element_type)t, sizes[s]);

  /* The node numbering documented in mesh.h: corner (i, j, k) at lo + (i, j, k) h. */
  fcm_mesh *m = NULL;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 3, 4};
  const fcm_index n[3] = {2, 3, 4};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX20, lo, hi, n, &m));
  if (m) {
    const double *x = fcm_mesh_coords(m);
    for (int k = 0; k <= 4; k++)
      for (int j = 0; j <= 3; j++)
        for (int i = 0; i <= 2; i++) {
          const double *p = x + 3 * (i + 3 * (j + 4 * k));
          TEST_TRUE(p[0] == i && p[1] == j && p[2] == k);
        }
  }
  fcm_mesh_destroy(&m);

  /* Errors. */
  const fcm_index bad_n[3] = {2, 0, 1};
  const double bad_hi[3] = {2, 3, 0};
  TEST_ERR(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, bad_n, &m), FCM_ERR_ARG,
           "axis 1: 0 cells out of range [1,");
  TEST_ERR(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_TET4, lo, bad_hi, n, &m), FCM_ERR_ARG,
           "axis 2: need finite lo < hi, got [0, 0]");
  TEST_ERR(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_COUNT, lo, hi, n, &m), FCM_ERR_ARG,
           "element type 4 out of range");
  TEST_ERR(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, NULL, hi, n, &m), FCM_ERR_ARG,
           "must not be NULL");
  TEST_TRUE(m == NULL);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &m));
  fcm_index count = 0;
  const double qlo[3] = {0, 0, 0}, qhi[3] = {1, NAN, 1};
  TEST_ERR(ctx, fcm_mesh_nodes_in_box(ctx, m, qlo, qhi, 0.0, 0, NULL, &count), FCM_ERR_ARG,
           "axis 1: lo = 0 > hi = nan");
  TEST_ERR(ctx, fcm_mesh_nodes_in_box(ctx, m, qlo, qlo, -1.0, 0, NULL, &count), FCM_ERR_ARG,
           "tol = -1 must be finite and >= 0");
  TEST_ERR(ctx, fcm_mesh_nodes_in_box(ctx, m, qlo, qlo, 0.0, 3, NULL, &count), FCM_ERR_ARG,
           "capacity = 3 needs a non-NULL nodes array");
  /* A closed box with zero tolerance holds exactly the grid corners inside it. */
  const double blo[3] = {0, 0, 0}, bhi[3] = {1, 1, 1};
  TEST_OK(ctx, fcm_mesh_nodes_in_box(ctx, m, blo, bhi, 0.0, 0, NULL, &count));
  TEST_TRUE(count == 8);
  fcm_mesh_destroy(&m);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
