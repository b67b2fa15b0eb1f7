/* The rules file (fcm_cell_rules_write()) read back: every cell's points, weights and flags
 * equal the accessors' bit for bit, piece by piece (also after a cut splits cells); the
 * physical weights of each piece add up to its volume and integrate every monomial of degree
 * <= the strength over a box exactly; the surface rule closes: sum w n = 0 and
 * sum w x.n = 3 |body|; optional arrays left out on request; bad arguments refused naming the
 * problem, leaving an existing file intact and no temporary behind. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "rules_file.h"
#include "test.h"

#include <dirent.h>
#include <sys/stat.h>

#define WORK "embed_rules_write.d"

static fcm_ctx *ctx;

/* The box body [B0, B1] in the grid [0, 3]^3 of 3^3 cells: every cell is cut or empty. */
static const double B0[3] = {0.4, 0.2, 0.5}, B1[3] = {2.3, 2.6, 2.45};
#define STRENGTH 4

static double box_monomial(const int e[3])
{
  double v = 1.0;
  for (int d = 0; d < 3; d++)
    v *= (pow(B1[d], e[d] + 1) - pow(B0[d], e[d] + 1)) / (e[d] + 1);
  return v;
}

static int entries(void)
{
  int n = 0;
  DIR *d = opendir(WORK);
  if (!d) return -1;
  for (struct dirent *e; (e = readdir(d));)
    n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
  closedir(d);
  return n;
}

/* The file's piece structure and volume points equal the accessors' bit for bit. */
static void check_same(const rf_file *f, const fcm_cell_rules *r, const char *kind_name,
                       fcm_rule_kind kind)
{
  long long rows, np;
  int cols;
  char name[64];
  const int32_t *cls = rf_array(f, "cell_class", &rows, &cols);
  const double *frac = rf_array(f, "cell_volume_fraction", &rows, &cols);
  const int64_t *coff = rf_array(f, "cell_piece_offsets", &rows, &cols);
  const int64_t *pcell = rf_array(f, "piece_cell", &np, &cols);
  snprintf(name, sizeof name, "%s/piece_offsets", kind_name);
  const int64_t *poff = rf_array(f, name, &rows, &cols);
  snprintf(name, sizeof name, "%s/points_ref", kind_name);
  const double *xi = rf_array(f, name, &rows, &cols);
  TEST_TRUE(cols == 3);
  snprintf(name, sizeof name, "%s/weights_ref", kind_name);
  const double *w = rf_array(f, name, &rows, &cols);
  snprintf(name, sizeof name, "%s/flags", kind_name);
  const uint8_t *fl = rf_array(f, name, &rows, &cols);
  TEST_TRUE(cls && frac && coff && pcell && poff && xi && w && fl);
  if (!(cls && frac && coff && pcell && poff && xi && w && fl)) return;
  TEST_TRUE(np == fcm_cell_rules_num_pieces(r));
  for (fcm_index c = 0; c < fcm_cell_rules_num_cells(r); c++) {
    fcm_index first;
    const fcm_index npc = fcm_cell_rules_cell_pieces(r, c, &first);
    TEST_TRUE(cls[c] == (int32_t)fcm_cell_rules_class(r, c));
    TEST_TRUE(frac[c] == fcm_cell_rules_volume_fraction(r, c));
    TEST_TRUE(coff[c] == first && coff[c + 1] == first + npc);
    int n;
    const double *p, *wc;
    const unsigned char *fc;
    TEST_OK(ctx, fcm_cell_rules_get(r, c, kind, &n, &p, &wc, &fc));
    /* the cell's points are those of its pieces, contiguous */
    const int64_t j0 = poff[coff[c]], j1 = poff[coff[c + 1]];
    TEST_TRUE(j1 - j0 == n);
    if (j1 - j0 != n) continue;
    for (int j = 0; j < n; j++) {
      TEST_TRUE(!memcmp(p + 3 * j, xi + 3 * (j0 + j), 3 * sizeof(double)));
      TEST_TRUE(wc[j] == w[j0 + j] && fc[j] == fl[j0 + j]);
    }
    for (fcm_index q = first; q < first + npc; q++)
      TEST_TRUE(pcell[q] == c);
  }
}

/* Exactness facts of the physical arrays (stabilization points, flag 1, left out). */
static void check_exact(const rf_file *f, const fcm_cell_rules *r)
{
  long long n, np, ns;
  int cols;
  const int64_t *poff = rf_array(f, "stiffness/piece_offsets", &np, &cols);
  const double *x = rf_array(f, "stiffness/points_phys", &n, &cols);
  const double *w = rf_array(f, "stiffness/weights_phys", &n, &cols);
  const uint8_t *fl = rf_array(f, "stiffness/flags", &n, &cols);
  const double *pv = rf_array(f, "piece_volume", &np, &cols);
  TEST_TRUE(poff && x && w && fl && pv);
  if (!(poff && x && w && fl && pv)) return;
  double body = 1.0;
  for (int d = 0; d < 3; d++)
    body *= B1[d] - B0[d];
  for (long long q = 0; q < np; q++) { /* per piece: its volume */
    double v = 0.0;
    for (int64_t j = poff[q]; j < poff[q + 1]; j++)
      v += fl[j] ? 0.0 : w[j];
    TEST_NEAR(v, pv[q], 1e-12, 1e-14);
    TEST_NEAR(pv[q], fcm_cell_rules_piece_volume(r, (fcm_index)q), 0, 0);
  }
  for (int a = 0; a <= STRENGTH; a++) /* over the body: every monomial of degree <= m */
    for (int b = 0; a + b <= STRENGTH; b++)
      for (int c = 0; a + b + c <= STRENGTH; c++) {
        const int e[3] = {a, b, c};
        double q = 0.0;
        for (long long j = 0; j < n; j++)
          if (!fl[j]) q += w[j] * pow(x[3 * j], a) * pow(x[3 * j + 1], b) * pow(x[3 * j + 2], c);
        TEST_NEAR(q, box_monomial(e), 1e-12, 0);
      }
  const double *sx = rf_array(f, "surface/points_phys", &ns, &cols);
  const double *sw = rf_array(f, "surface/weights", &ns, &cols);
  const double *sn = rf_array(f, "surface/normals", &ns, &cols);
  TEST_TRUE(sx && sw && sn && ns > 0);
  if (!(sx && sw && sn)) return;
  double area = 0.0, flux[3] = {0, 0, 0}, xn = 0.0;
  for (long long j = 0; j < ns; j++) {
    area += sw[j];
    for (int d = 0; d < 3; d++) {
      flux[d] += sw[j] * sn[3 * j + d];
      xn += sw[j] * sx[3 * j + d] * sn[3 * j + d];
    }
  }
  const double l[3] = {B1[0] - B0[0], B1[1] - B0[1], B1[2] - B0[2]};
  TEST_NEAR(area, 2 * (l[0] * l[1] + l[1] * l[2] + l[0] * l[2]), 1e-12, 0);
  for (int d = 0; d < 3; d++)
    TEST_NEAR(flux[d], 0.0, 0, 1e-12 * area);
  TEST_NEAR(xn, 3 * body, 1e-12, 0); /* divergence theorem for x: div x = 3 */
}

static void write_and_check(const fcm_mesh *mesh, const fcm_cell_rules *r, const char *path)
{
  rf_file f;
  TEST_OK(ctx, fcm_cell_rules_write(r, mesh, path, NULL));
  TEST_TRUE(rf_load(path, &f));
  if (!f.header) return;
  TEST_TRUE(strstr(f.header, "\"format\": \"fcm-cell-rules\"") &&
            strstr(f.header, "\"element\": \"hex8\""));
  TEST_TRUE(rf_number_after(f.header, "\"num_pieces\": ") == fcm_cell_rules_num_pieces(r));
  /* version 2 exactly when a rule is exact on a capped space only (Hex8's mass on Q_2) */
  const int capped =
      fcm_cell_rules_axis_degree(r, FCM_RULE_MASS) < fcm_cell_rules_strength(r, FCM_RULE_MASS);
  TEST_TRUE(rf_number_after(f.header, "\"version\": ") == (capped ? 2 : 1));
  check_same(&f, r, "stiffness", FCM_RULE_STIFFNESS);
  check_same(&f, r, "mass", FCM_RULE_MASS);
  check_exact(&f, r);
  long long rows;
  int cols;
  const int64_t *cells = rf_array(&f, "mesh/cells", &rows, &cols);
  TEST_TRUE(cells && rows == fcm_mesh_num_cells(mesh) && cols == 8);
  if (cells) TEST_TRUE(!memcmp(cells, fcm_mesh_cells(mesh), (size_t)rows * 8 * sizeof(int64_t)));
  rf_free(&f);
}

static void errors(const fcm_mesh *mesh, const fcm_cell_rules *r)
{
  const char *path = WORK "/keep.fcmr";
  fcm_mesh *other = NULL;
  const double lo[3] = {0, 0, 0}, hi[3] = {3, 3, 3};
  const fcm_index n2[3] = {2, 2, 2};
  TEST_OK(ctx, fcm_cell_rules_write(r, mesh, path, NULL));
  struct stat before, after;
  TEST_TRUE(stat(path, &before) == 0);
  const int files = entries();
  TEST_TRUE(fcm_cell_rules_write(NULL, mesh, path, NULL) == FCM_ERR_ARG);
  TEST_ERR(ctx, fcm_cell_rules_write(r, NULL, path, NULL), FCM_ERR_ARG, "mesh");
  TEST_ERR(ctx, fcm_cell_rules_write(r, mesh, "", NULL), FCM_ERR_ARG, "path is empty");
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n2, &other));
  TEST_ERR(ctx, fcm_cell_rules_write(r, other, path, NULL), FCM_ERR_ARG, "not the rules' mesh");
  fcm_cell_rules_write_options o = fcm_cell_rules_write_options_default();
  o.description = "two\nlines";
  TEST_ERR(ctx, fcm_cell_rules_write(r, mesh, path, &o), FCM_ERR_ARG, "control characters");
  TEST_ERR(ctx, fcm_cell_rules_write(r, mesh, WORK "/missing/dir/x.fcmr", NULL), FCM_ERR_IO,
           WORK "/missing/dir/x.fcmr");
  TEST_TRUE(stat(path, &after) == 0 && after.st_size == before.st_size &&
            after.st_mtime == before.st_mtime);
  TEST_TRUE(entries() == files); /* no temporary left */
  const double xi[3] = {0, 0, 0};
  double x[3], det;
  TEST_ERR(ctx, fcm_cell_rules_map_points(r, mesh, 27, 1, xi, x, &det), FCM_ERR_ARG,
           "cell 27 out of range [0,27)");
  TEST_OK(ctx, fcm_cell_rules_map_points(r, mesh, 13, 1, xi, x, &det)); /* the middle cell */
  TEST_NEAR(det, 0.125, 1e-15, 0);
  for (int d = 0; d < 3; d++)
    TEST_NEAR(x[d], 1.5, 1e-15, 0);
  /* without mesh and physical arrays, with a description */
  o = fcm_cell_rules_write_options_default();
  o.include_mesh = o.include_physical = 0;
  o.description = "a \"box\" \\ cut";
  TEST_OK(ctx, fcm_cell_rules_write(r, mesh, path, &o));
  rf_file f;
  TEST_TRUE(rf_load(path, &f));
  if (f.header) {
    long long rows;
    int cols;
    TEST_TRUE(!rf_array(&f, "mesh/nodes", &rows, &cols) &&
              !rf_array(&f, "stiffness/points_phys", &rows, &cols) &&
              rf_array(&f, "stiffness/points_ref", &rows, &cols));
    TEST_TRUE(strstr(f.header, "\"description\": \"a \\\"box\\\" \\\\ cut\""));
    rf_free(&f);
  }
  fcm_mesh_destroy(&other);
}

int main(void)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {3, 3, 3};
  const fcm_index n[3] = {3, 3, 3}, gn[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *r = NULL, *rc = NULL;
  fcm_surface *cut = NULL;
  mkdir(WORK, 0777);
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, B0, B1, gn, &g));
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_STIFFNESS] = STRENGTH;
  o.surface_strength = STRENGTH;
  o.min_fraction = 0.0;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  write_and_check(mesh, r, WORK "/box.fcmr");
  /* a plane cut through the body splits the cells it crosses into two pieces each */
  const double p[3] = {1.23, 1.4, 1.45}, nrm[3] = {1.0, 0.3, 0.2};
  const double clo[3] = {-1, -1, -1}, chi[3] = {4, 4, 4};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, p, nrm, clo, chi, &cut));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, g, r, cut, &rc));
  TEST_TRUE(fcm_cell_rules_num_pieces(rc) > fcm_cell_rules_num_pieces(r));
  write_and_check(mesh, rc, WORK "/cut.fcmr");
  TEST_TRUE(fcm_cell_rules_axis_degree(rc, FCM_RULE_MASS) == 2); /* the default: version 2 */
  /* the mass rules on all of P_6 (an explicit strength): a version-1 file */
  fcm_cell_rules *r6 = NULL;
  o.strength[FCM_RULE_MASS] = 6;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r6));
  TEST_TRUE(fcm_cell_rules_axis_degree(r6, FCM_RULE_MASS) == 6);
  write_and_check(mesh, r6, WORK "/p6.fcmr");
  fcm_cell_rules_destroy(&r6);
  errors(mesh, r);
  fcm_surface_destroy(&cut);
  fcm_cell_rules_destroy(&rc);
  fcm_cell_rules_destroy(&r);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
