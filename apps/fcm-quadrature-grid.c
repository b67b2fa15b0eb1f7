/* fcm-quadrature: what `embed` and `export` share: the options of the background grid, the
 * embedded geometry and the cell rules, their checks, and building the grid and the geometry. */
#include "cli.h"
#include "fcm-quadrature.h"

#include <fcm/fcm.h>

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int has_ext(const char *path, const char *ext)
{
  size_t n = strlen(path), e = strlen(ext);
  if (n <= e) return 0;
  for (size_t i = 0; i < e; i++)
    if (tolower((unsigned char)path[n - e + i]) != ext[i]) return 0;
  return 1;
}

/* A triangle surface file: read, holes closed when asked (reported on stderr),
 * tetrahedralized. */
static fcm_status load_surface(fcm_ctx *ctx, const char *path, int fill_holes, double max_volume,
                               fcm_geometry **g)
{
  fcm_surface *s = NULL, *f = NULL;
  fcm_status st = fcm_surface_create_from_file(ctx, path, &s);
  if (st == FCM_OK && fill_holes) {
    fcm_surface_fill_info fi;
    st = fcm_surface_create_filled(ctx, s, NULL, &f, &fi);
    if (st == FCM_OK) {
      fprintf(stderr,
              "fcm-quadrature embed: %s: fill_holes closed %lld of %lld hole(s), adding %lld "
              "triangles of total area %g\n",
              path, (long long)fi.num_filled, (long long)fi.num_loops,
              (long long)fi.triangles_added, fi.area_added);
      fcm_surface_destroy(&s);
      s = f;
    }
  }
  if (st == FCM_OK) {
    fcm_surface_mesh_options mo = fcm_surface_mesh_options_default();
    mo.max_volume = max_volume;
    st = fcm_geometry_create_from_surface(ctx, s, &mo, g);
  }
  fcm_surface_destroy(&s);
  return st;
}

/* A voxel image (NRRD, MetaImage): the voxels >= 0.5 merged into boxes. */
static fcm_status load_voxels(fcm_ctx *ctx, const char *path, fcm_geometry **g)
{
  fcm_voxel_image *img = NULL;
  fcm_status st = fcm_voxel_image_create_from_file(ctx, path, &img);
  if (st == FCM_OK) st = fcm_geometry_create_from_voxels(ctx, img, NULL, g, NULL);
  fcm_voxel_image_destroy(&img);
  return st;
}

/* Procedural geometry "name:a,b,c,..." or a file, by its extension; FCM_ERR_ARG without a
 * context error for a spec that is neither. */
static fcm_status load_geometry(fcm_ctx *ctx, const char *spec, int fill_holes, double max_volume,
                                fcm_geometry **g)
{
  double v[8];
  int n = 0;
  const char *colon = strchr(spec, ':');
  if (colon && !strchr(spec, '/') && colon - spec <= 12) {
    char name[16] = {0};
    memcpy(name, spec, (size_t)(colon - spec));
    const char *p = colon + 1;
    while (*p && n < 8) {
      char *end = NULL;
      v[n++] = strtod(p, &end);
      if (end == p) return FCM_ERR_ARG;
      p = *end == ',' ? end + 1 : end;
      if (*end && *end != ',') return FCM_ERR_ARG;
    }
    if (!strcmp(name, "ball") && n == 5)
      return fcm_geometry_create_ball(ctx, v, v[3], (int)v[4], g);
    if (!strcmp(name, "hemisphere") && n == 5)
      return fcm_geometry_create_hemisphere(ctx, v, v[3], (int)v[4], g);
    if (!strcmp(name, "box") && n == 7) {
      fcm_index nn[3] = {(fcm_index)v[6], (fcm_index)v[6], (fcm_index)v[6]};
      return fcm_geometry_create_box(ctx, v, v + 3, nn, g);
    }
    return FCM_ERR_ARG;
  }
  size_t len = strlen(spec);
  if (has_ext(spec, ".node") || has_ext(spec, ".ele")) { /* TetGen: base.node + base.ele */
    char node[4096], ele[4096];
    int base = (int)(len - (has_ext(spec, ".node") ? 5 : 4));
    snprintf(node, sizeof node, "%.*s.node", base, spec);
    snprintf(ele, sizeof ele, "%.*s.ele", base, spec);
    return fcm_geometry_create_from_tetgen(ctx, node, ele, g);
  }
  if (has_ext(spec, ".obj") || has_ext(spec, ".off") || has_ext(spec, ".stl") ||
      has_ext(spec, ".ply"))
    return load_surface(ctx, spec, fill_holes, max_volume, g);
  if (has_ext(spec, ".nrrd") || has_ext(spec, ".nhdr") || has_ext(spec, ".mhd") ||
      has_ext(spec, ".mha"))
    return load_voxels(ctx, spec, g);
  return fcm_geometry_create_from_gmsh(ctx, spec, g);
}

void fcm_quadrature_grid_init(fcm_quadrature_grid *g, cli_option opts[FCM_QUADRATURE_GRID_OPTIONS])
{
  memset(g, 0, sizeof *g);
  g->type = FCM_ELEMENT_COUNT;
  g->alpha = 1e-6;
  g->phimin = 1e-4;
  const cli_option o[FCM_QUADRATURE_GRID_OPTIONS] = {
      {"--element", NULL, CLI_CUSTOM, &g->type, "E", "background element: tet4, tet10, hex8, hex20",
       0, 0, 0, NULL, cli_element, NULL},
      {"--box", NULL, CLI_DOUBLE, g->box, "X0 Y0 Z0 X1 Y1 Z1", "background box corners", -1e12,
       1e12, 0, NULL, NULL, &g->have_box},
      {"--cells", NULL, CLI_INT, g->cells, "NX NY NZ", "background cells per direction, 1..100000",
       1, 100000, 0, NULL, NULL, NULL},
      {"--geometry", NULL, CLI_STRING, &g->geometry, "FILE|SHAPE",
       "by extension: Gmsh .msh (tetrahedra), TetGen\n"
       "FILE.node / FILE.ele (both read), a closed triangle\n"
       "surface .obj, .off, .stl, .ply (tetrahedralized\n"
       "with Gmsh), a voxel image .nrrd, .nhdr, .mhd, .mha\n"
       "(voxels >= 0.5, merged into boxes); or a shape: ball:CX,CY,CZ,R,N |\n"
       "hemisphere:CX,CY,CZ,R,N | box:X0,Y0,Z0,X1,Y1,Z1,N",
       0, 0, 0, NULL, NULL, NULL},
      {"--fill-holes", NULL, CLI_FLAG, &g->fill_holes, NULL,
       "surfaces: close holes before tetrahedralizing", 0, 0, 0, NULL, NULL, NULL},
      {"--max-volume", NULL, CLI_DOUBLE, &g->max_volume, "V",
       "surfaces: largest tet volume wanted (default 0:\nsizes follow the surface)", 0, 1e300, 0,
       NULL, NULL, NULL},
      {"--strength", NULL, CLI_INT, &g->strength, "M", "stiffness rule strength 1..20", 1, 20, 0,
       NULL, NULL, NULL},
      {"--mass-strength", NULL, CLI_INT, &g->mstrength, "M",
       "mass rule strength 1..20 (default the element's)", 1, 20, 0, NULL, NULL, NULL},
      {"--no-simplify", NULL, CLI_FLAG, &g->no_simplify, NULL,
       "keep the initial (tetrahedralized) rules", 0, 0, 0, NULL, NULL, NULL},
      {"--stabilization", NULL, CLI_DOUBLE, &g->alpha, "A",
       "append the full cell's rule x A to cut cells,\n"
       "A in [0, 1] (0: off; default 1e-6)",
       0, 1, 0, NULL, NULL, NULL},
      {"--min-fraction", NULL, CLI_DOUBLE, &g->phimin, "PHI",
       "drop cells with volume fraction below PHI, in [0, 1]\n(default 1e-4)", 0, 1, 0, NULL, NULL,
       NULL}};
  memcpy(opts, o, sizeof o);
}

int fcm_quadrature_grid_check(const fcm_quadrature_grid *g, const char *cmd)
{
  const char *missing = g->type == FCM_ELEMENT_COUNT ? "--element"
                        : !g->have_box               ? "--box"
                        : !g->cells[0]               ? "--cells"
                        : !g->geometry               ? "--geometry"
                        : !g->strength               ? "--strength"
                                                     : NULL;
  if (missing) {
    fprintf(stderr, "fcm-quadrature %s: %s is required (see --help)\n", cmd, missing);
    return 2;
  }
  for (int d = 0; d < 3; d++)
    if (!(g->box[d] < g->box[d + 3])) {
      fprintf(stderr, "fcm-quadrature %s: --box: X0 Y0 Z0 must be below X1 Y1 Z1\n", cmd);
      return 2;
    }
  return -1;
}

fcm_cell_rules_options fcm_quadrature_grid_rules_options(const fcm_quadrature_grid *g)
{
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  ro.strength[FCM_RULE_STIFFNESS] = g->strength;
  if (g->mstrength) ro.strength[FCM_RULE_MASS] = g->mstrength;
  ro.simplify = !g->no_simplify;
  ro.min_fraction = g->phimin;
  if (g->alpha > 0)
    ro.stabilization.alpha = g->alpha;
  else
    ro.stabilization.mode = FCM_STABILIZATION_OFF;
  return ro;
}

int fcm_quadrature_grid_build(fcm_ctx *ctx, const fcm_quadrature_grid *g, const char *cmd,
                              fcm_mesh **mesh, fcm_geometry **geom)
{
  const fcm_index n[3] = {g->cells[0], g->cells[1], g->cells[2]};
  if (fcm_mesh_create_box(ctx, g->type, g->box, g->box + 3, n, mesh) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    return 1;
  }
  if (load_geometry(ctx, g->geometry, g->fill_holes, g->max_volume, geom) != FCM_OK) {
    if (fcm_ctx_error_status(ctx) != FCM_OK)
      fcm_ctx_error_view(ctx, stderr);
    else
      fprintf(stderr,
              "fcm-quadrature %s: --geometry '%s': not a readable file or a shape spec (see "
              "--help)\n",
              cmd, g->geometry);
    return 2;
  }
  return 0;
}
