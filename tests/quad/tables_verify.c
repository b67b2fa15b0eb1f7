/* Re-verifies every stored rule table in quadrature_tables/ (directory in argv[1]):
 * exactness on all monomials up to the strength, positive weights, interior points,
 * fewer points than the computed rule, and the compiled-in copy identical to the file. */
#include "moments.h"

#define RTOL       1e-13 /* relative error on monomials with non-zero integral */
#define ZTOL       1e-14 /* |Q| / measure on monomials with zero integral */
#define MAX_POINTS 4096

static const fcm_shape shapes[] = {FCM_SHAPE_TRI, FCM_SHAPE_QUAD, FCM_SHAPE_TET, FCM_SHAPE_HEX};

typedef struct table {
  int strength, n;
  char shape[16];
  double x[3 * MAX_POINTS], w[MAX_POINTS];
} table;

/* Parse a table file; returns 0 (with a test failure) when it is malformed. */
static int read_table(const char *path, int dim, table *t)
{
  FILE *f = fopen(path, "r");
  char line[1024];
  int rows = 0, lineno = 0, ok = 1;
  t->strength = t->n = -1;
  t->shape[0] = '\0';
  if (!f) return 0;
  while (ok && fgets(line, sizeof line, f)) {
    lineno++;
    if (line[0] == '#') {
      if (sscanf(line, "# shape: %15s", t->shape) == 1) continue;
      if (sscanf(line, "# strength: %d", &t->strength) == 1) continue;
      if (sscanf(line, "# points: %d", &t->n) == 1) continue;
      continue;
    }
    char *p = line, *end;
    double v[4];
    int k = 0;
    for (; k < 4; k++) {
      v[k] = strtod(p, &end);
      if (end == p) break;
      p = end;
    }
    if (k == 0) continue; /* blank line */
    if (k != dim + 1 || rows >= MAX_POINTS) {
      TEST_FAIL_("%s:%d: %d numbers (expected %d) or more than %d rows", path, lineno, k, dim + 1,
                 MAX_POINTS);
      ok = 0;
      break;
    }
    for (int d = 0; d < dim; d++)
      t->x[rows * dim + d] = v[d];
    t->w[rows++] = v[dim];
  }
  fclose(f);
  if (ok && rows != t->n) {
    TEST_FAIL_("%s: header says %d points, file has %d", path, t->n, rows);
    ok = 0;
  }
  return ok;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  static table t;
  int found = 0;
  if (argc < 2) {
    fprintf(stderr, "usage: %s QUADRATURE_TABLES_DIR\n", argv[0]);
    return 2;
  }
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; s++) {
    fcm_shape shape = shapes[s];
    const char *name = fcm_shape_name(shape);
    int dim = mom_dim(shape);
    for (int m = 0; m <= FCM_RULE_MAX_STRENGTH; m++) {
      char path[1024];
      fcm_rule *file_rule = NULL, *cat = NULL, *comp = NULL;
      snprintf(path, sizeof path, "%s/%s/%s_%02d.txt", argv[1], name, name, m);
      FILE *probe = fopen(path, "r");
      TEST_OK(ctx, fcm_rule_create(ctx, shape, m, &cat));
      if (!cat) continue;
      if (!probe) { /* no file: the catalogue must not claim a table */
        if (fcm_rule_get_origin(cat) != FCM_RULE_COMPUTED)
          TEST_FAIL_("%s m=%d: no table file but the catalogue rule has origin %d", name, m,
                     (int)fcm_rule_get_origin(cat));
        fcm_rule_destroy(&cat);
        continue;
      }
      fclose(probe);
      found++;
      if (read_table(path, dim, &t)) {
        if (strcmp(t.shape, name) || t.strength != m)
          TEST_FAIL_("%s: header shape '%s' strength %d, expected %s %d", path, t.shape, t.strength,
                     name, m);
        TEST_OK(ctx, fcm_rule_create_from_arrays(ctx, shape, m, t.n, t.x, t.w, &file_rule));
        TEST_OK(ctx, fcm_rule_create_computed(ctx, shape, m, &comp));
      }
      if (file_rule && comp) {
        if (mom_check_exact(file_rule, m, RTOL, ZTOL, NULL) || mom_check_inside_positive(file_rule))
          TEST_FAIL_("%s failed verification", path);
        if (!(t.n <= fcm_rule_num_points(comp)))
          TEST_FAIL_("%s: %d points, more than the computed rule's %d", path, t.n,
                     fcm_rule_num_points(comp));
        /* the compiled-in copy is the file, bit for bit */
        if (fcm_rule_get_origin(cat) != FCM_RULE_TABLE || fcm_rule_num_points(cat) != t.n ||
            memcmp(fcm_rule_points(cat), t.x, sizeof(double) * (size_t)t.n * dim) ||
            memcmp(fcm_rule_weights(cat), t.w, sizeof(double) * (size_t)t.n))
          TEST_FAIL_("%s m=%d: catalogue rule (origin %d, %d points) differs from %s", name, m,
                     (int)fcm_rule_get_origin(cat), fcm_rule_num_points(cat), path);
      }
      fcm_rule_destroy(&file_rule);
      fcm_rule_destroy(&comp);
      fcm_rule_destroy(&cat);
    }
  }
  if (found == 0) TEST_FAIL_("no table found under %s", argv[1]);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
