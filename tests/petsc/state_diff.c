/* petsc_state_diff A B RTOL: the displacement and velocity of two checkpoints agree to RTOL
 * relative (||u_A - u_B|| <= RTOL ||u_B||, the same for v; RTOL 0: bit for bit). Either file
 * may be a checkpoint container (io/checkpoint_file.c: "FCMCKPT", num_dofs at byte 32, u and v
 * the last 2n doubles before the 8-byte checksum) of fcm-sim or of the PETSc backend's linear
 * driver, or an older linear driver's .fcmpk ("fcm-petsc-ck-1", n at byte 16, u and v from byte
 * 64); all hold the state in the space's
 * DOF numbering, which is the same for every backend and process count. Used by the shell
 * tests of tests/petsc; prints the norms, exits 1 when they differ by more.
 * petsc_state_diff --vtu A.vtu B.vtu RTOL: the same for the background frames of fcm-sim
 * (fcm_space_write_vtu()): each of the point arrays displacement, velocity and the cell arrays
 * stress, von_mises, strain_energy_density (those in B must be in A). A may be a parallel
 * frame (.pvtu: a distributed run's pieces, fcm__space_write_vtu_piece()): its pieces' values
 * are placed by their node_index / cell_index (the mesh's node and cell) into the whole mesh's
 * arrays first; every cell in at most one piece, every node with the same values in each piece
 * that holds it, and a cell or node in no piece compares as 0 (an inactive cell has none). */
#include "../io/vtk_reader.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct state {
  long long n;
  double *u, *v;
} state;

static int load(const char *path, state *s)
{
  FILE *f = fopen(path, "rb");
  if (!f) {
    fprintf(stderr, "petsc_state_diff: cannot open %s\n", path);
    return 0;
  }
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *b = size > 0 ? malloc((size_t)size) : NULL;
  int ok = b && fread(b, 1, (size_t)size, f) == (size_t)size;
  fclose(f);
  int64_t n = -1;
  size_t at = 0;
  if (ok && size >= 40 && memcmp(b, "FCMCKPT", 8) == 0) {
    memcpy(&n, b + 32, sizeof n);
    ok = n >= 0 && (size_t)size >= 48 + 16 * (size_t)n;
    if (ok) at = (size_t)size - 8 - 16 * (size_t)n;
  } else if (ok && size >= 64 && memcmp(b, "fcm-petsc-ck-1\n", 16) == 0) {
    memcpy(&n, b + 16, sizeof n);
    ok = n >= 0 && (size_t)size == 64 + 16 * (size_t)n;
    at = 64;
  } else {
    ok = 0;
  }
  if (!ok) {
    fprintf(stderr, "petsc_state_diff: %s is not a whole checkpoint of fcm\n", path);
    free(b);
    return 0;
  }
  s->n = n;
  s->u = malloc(sizeof(double) * ((size_t)n + 1));
  s->v = malloc(sizeof(double) * ((size_t)n + 1));
  memcpy(s->u, b + at, sizeof(double) * (size_t)n);
  memcpy(s->v, b + at + sizeof(double) * (size_t)n, sizeof(double) * (size_t)n);
  free(b);
  return 1;
}

/* ||a - b|| <= rtol ||b|| (a NaN fails). */
static int within(const char *what, long long n, const double *a, const double *b, double rtol)
{
  double d = 0.0, nb = 0.0;
  for (long long i = 0; i < n; i++) {
    d += (a[i] - b[i]) * (a[i] - b[i]);
    nb += b[i] * b[i];
  }
  d = sqrt(d), nb = sqrt(nb);
  printf("%s: |A - B| = %.3e, |B| = %.6e, relative %.3e (tolerance %.1e)\n", what, d, nb,
         nb > 0.0 ? d / nb : d, rtol);
  return d <= rtol * nb;
}

/* The raw values of array `name` of `parent` in a VTU file (malloc'ed) and their count, of
 * `size` bytes each; NULL if absent. */
static void *read_raw(const char *path, const char *parent, const char *name, size_t size,
                      long long *count)
{
  vr_doc d;
  unsigned char *out = NULL;
  *count = 0;
  if (!vr_load(&d, path)) return NULL;
  if (vr_parse_vtu(&d)) {
    const vr_tag *t = vr_data_array(&d, parent, name);
    if (t) {
      uint64_t bytes = 0;
      const unsigned char *p = vr_array(&d, t, &bytes);
      out = malloc(bytes + 1);
      if (out) memcpy(out, p, bytes);
      *count = (long long)(bytes / size);
    }
  }
  vr_free(&d);
  return out;
}

/* Float64 array `name` of `parent` in a VTU file (malloc'ed) and its count; NULL if absent. */
static double *read_array(const char *path, const char *parent, const char *name, long long *count)
{
  return read_raw(path, parent, name, sizeof(double), count);
}

/* Int32 array `name` of `parent` in a VTU file (malloc'ed) and its count; NULL if absent. */
static int32_t *read_int32(const char *path, const char *parent, const char *name, long long *count)
{
  return read_raw(path, parent, name, sizeof(int32_t), count);
}

/* The whole mesh's array (nb values, ncomp per entity) of a .pvtu's pieces: NULL when a piece
 * lacks it, an index is out of range, a cell is in two pieces or a node differs between
 * pieces. */
static double *read_pvtu_array(const char *pvtu, const char *parent, const char *name, long long nb,
                               int ncomp)
{
  vr_doc d;
  double *out = NULL;
  char dir[4096], src[1024], path[8192];
  if (!vr_load(&d, pvtu)) return NULL;
  if (!vr_parse_xml(&d)) {
    fprintf(stderr, "petsc_state_diff: %s: %s\n", pvtu, d.error);
    vr_free(&d);
    return NULL;
  }
  snprintf(dir, sizeof dir, "%s", pvtu);
  char *slash = strrchr(dir, '/');
  if (slash)
    *slash = 0;
  else
    snprintf(dir, sizeof dir, ".");
  const int cell = strcmp(parent, "CellData") == 0;
  out = calloc((size_t)nb + 1, sizeof *out);
  char *seen = calloc((size_t)(nb / ncomp) + 1, 1);
  int ok = out && seen, pieces = 0;
  for (int i = 0; ok; i++) {
    const vr_tag *t = vr_find(&d, "Piece", "PUnstructuredGrid", i);
    if (!t) break;
    pieces++;
    ok = vr_attr(t, "Source", src, sizeof src);
    snprintf(path, sizeof path, "%s/%s", dir, src);
    long long nv = 0, ni = 0;
    double *x = ok ? read_array(path, parent, name, &nv) : NULL;
    int32_t *id = ok ? read_int32(path, parent, cell ? "cell_index" : "node_index", &ni) : NULL;
    ok = x && id && nv == ni * ncomp;
    for (long long k = 0; ok && k < ni; k++) {
      ok = id[k] >= 0 && (long long)id[k] * ncomp < nb;
      if (!ok) break;
      double *y = out + (size_t)id[k] * (size_t)ncomp;
      if (seen[id[k]]) {
        ok = !cell; /* a node shared by pieces: the same (replicated) values */
        for (int c = 0; ok && c < ncomp; c++)
          ok = y[c] == x[k * ncomp + c];
      }
      seen[id[k]] = 1;
      for (int c = 0; ok && c < ncomp; c++)
        y[c] = x[k * ncomp + c];
    }
    if (!ok)
      fprintf(stderr, "petsc_state_diff: %s: piece %s: %s missing, out of range or repeated\n",
              pvtu, path, name);
    free(x), free(id);
  }
  ok = ok && pieces > 0;
  vr_free(&d);
  free(seen);
  if (!ok) free(out), out = NULL;
  return out;
}

static int vtu_main(const char *a, const char *b, double rtol)
{
  const size_t la = strlen(a);
  const int parallel = la > 5 && strcmp(a + la - 5, ".pvtu") == 0;
  static const char *const arrays[5][2] = {{"PointData", "displacement"},
                                           {"PointData", "velocity"},
                                           {"CellData", "stress"},
                                           {"CellData", "von_mises"},
                                           {"CellData", "strain_energy_density"}};
  int ok = 1, found = 0;
  for (int k = 0; k < 5; k++) {
    static const int ncomp[5] = {3, 3, 6, 1, 1};
    long long na = 0, nb = 0;
    double *y = read_array(b, arrays[k][0], arrays[k][1], &nb);
    double *x = NULL;
    if (!parallel)
      x = read_array(a, arrays[k][0], arrays[k][1], &na);
    else if (y && (x = read_pvtu_array(a, arrays[k][0], arrays[k][1], nb, ncomp[k])))
      na = nb;
    if (y) {
      found++;
      if (!x || na != nb) {
        fprintf(stderr, "petsc_state_diff: %s: %s has %lld values, %s %lld\n", arrays[k][1], a, na,
                b, nb);
        ok = 0;
      } else {
        ok = within(arrays[k][1], na, x, y, rtol) && ok;
      }
    }
    free(x), free(y);
  }
  if (found < 3) {
    fprintf(stderr, "petsc_state_diff: %s: no displacement or cell fields\n", b);
    ok = 0;
  }
  return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
  if (argc == 5 && strcmp(argv[1], "--vtu") == 0) return vtu_main(argv[2], argv[3], atof(argv[4]));
  state a = {0, NULL, NULL}, b = {0, NULL, NULL};
  if (argc != 4) {
    fprintf(stderr, "usage: petsc_state_diff A B RTOL\n");
    return 2;
  }
  const double rtol = atof(argv[3]);
  if (!load(argv[1], &a) || !load(argv[2], &b)) return 1;
  int ok = a.n == b.n;
  if (!ok) fprintf(stderr, "petsc_state_diff: %lld DOFs against %lld\n", a.n, b.n);
  ok = ok && within("displacement", a.n, a.u, b.u, rtol);
  ok = ok && within("velocity", a.n, a.v, b.v, rtol);
  free(a.u), free(a.v), free(b.u), free(b.v);
  return ok ? 0 : 1;
}
