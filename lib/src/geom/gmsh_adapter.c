/* The one file that talks to Gmsh's C API (gmshc.h, Debian libgmsh-dev; built when
 * FCM_HAVE_GMSH is defined, Gmsh loaded at run time): tetrahedralization of a closed
 * triangle surface. */
#include "geom/geom_impl.h"
#include "geom/surface_impl.h"

#include <math.h>
#include <string.h>

fcm_surface_mesh_options fcm_surface_mesh_options_default(void)
{
  fcm_surface_mesh_options o = {0.0, 0.0, 0.3, 1, 1, 1};
  return o;
}

#ifdef FCM_HAVE_GMSH

#include <dlfcn.h>
#include <gmshc.h>
#include <omp.h>
#include <pthread.h>
#include <stdlib.h>

/* Gmsh is loaded on first use (dlopen), not linked: programs that never mesh a surface do
 * not pay its start-up (about 0.13 s of CPU for Gmsh's and OpenCASCADE's initializers), and
 * a machine without the Gmsh runtime still runs everything else. The functions come from
 * the library whose header fcm was compiled against (soname libgmsh.so.MAJOR.MINOR). */
#define GMSH_STR_(x) #x
#define GMSH_STR(x)  GMSH_STR_(x)
#define GMSH_SONAME                                                                                \
  "libgmsh.so." GMSH_STR(GMSH_API_VERSION_MAJOR) "." GMSH_STR(GMSH_API_VERSION_MINOR)

static struct {
  void (*Free)(void *);
  void (*Initialize)(int, char **, const int, int *);
  void (*Finalize)(int *);
  void (*OptionSetNumber)(const char *, const double, int *);
  void (*ModelAdd)(const char *, int *);
  int (*ModelAddDiscreteEntity)(const int, const int, int *, size_t, int *);
  void (*ModelMeshAddNodes)(const int, const int, size_t *, size_t, double *, size_t, double *,
                            size_t, int *);
  void (*ModelMeshAddElementsByType)(const int, const int, size_t *, size_t, size_t *, size_t,
                                     int *);
  int (*ModelGeoAddSurfaceLoop)(int *, size_t, const int, int *);
  int (*ModelGeoAddVolume)(int *, size_t, const int, int *);
  void (*ModelGeoSynchronize)(int *);
  void (*ModelMeshGenerate)(const int, int *);
  void (*ModelMeshGetNodes)(size_t **, size_t *, double **, size_t *, double **, size_t *,
                            const int, const int, const int, const int, int *);
  void (*ModelMeshGetElementsByType)(const int, size_t **, size_t *, size_t **, size_t *, const int,
                                     const size_t, const size_t, int *);
  void (*LoggerGetLastError)(char **, int *);
} G;

/* Guards G, the load and Gmsh's global model and options: one meshing at a time. */
static pthread_mutex_t gmsh_lock = PTHREAD_MUTEX_INITIALIZER;
static int gmsh_state; /* 0: not tried, 1: loaded, -1: failed */
static char gmsh_load_error[256];

/* Resolve one symbol into a function pointer (memcpy: ISO C has no object-to-function
 * pointer conversion). */
static int sym(void *lib, const char *name, void *fp, size_t size)
{
  void *p = dlsym(lib, name);
  if (!p) {
    snprintf(gmsh_load_error, sizeof gmsh_load_error, "%s has no symbol %s", GMSH_SONAME, name);
    return 0;
  }
  memcpy(fp, &p, size);
  return 1;
}

/* With the lock held: load Gmsh once. */
static int gmsh_load(void)
{
  if (gmsh_state != 0) return gmsh_state > 0;
  void *lib = dlopen(GMSH_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (!lib) lib = dlopen("libgmsh.so", RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    const char *e = dlerror();
    snprintf(gmsh_load_error, sizeof gmsh_load_error, "%s", e ? e : "dlopen failed");
    gmsh_state = -1;
    return 0;
  }
#define SYM(field, name) sym(lib, name, &G.field, sizeof G.field)
  int ok = SYM(Free, "gmshFree") && SYM(Initialize, "gmshInitialize") &&
           SYM(Finalize, "gmshFinalize") && SYM(OptionSetNumber, "gmshOptionSetNumber") &&
           SYM(ModelAdd, "gmshModelAdd") &&
           SYM(ModelAddDiscreteEntity, "gmshModelAddDiscreteEntity") &&
           SYM(ModelMeshAddNodes, "gmshModelMeshAddNodes") &&
           SYM(ModelMeshAddElementsByType, "gmshModelMeshAddElementsByType") &&
           SYM(ModelGeoAddSurfaceLoop, "gmshModelGeoAddSurfaceLoop") &&
           SYM(ModelGeoAddVolume, "gmshModelGeoAddVolume") &&
           SYM(ModelGeoSynchronize, "gmshModelGeoSynchronize") &&
           SYM(ModelMeshGenerate, "gmshModelMeshGenerate") &&
           SYM(ModelMeshGetNodes, "gmshModelMeshGetNodes") &&
           SYM(ModelMeshGetElementsByType, "gmshModelMeshGetElementsByType") &&
           SYM(LoggerGetLastError, "gmshLoggerGetLastError");
#undef SYM
  if (!ok) dlclose(lib);
  gmsh_state = ok ? 1 : -1; /* a loaded library stays loaded for the process */
  return ok;
}

int fcm_surface_meshing_available(void)
{
  pthread_mutex_lock(&gmsh_lock);
  int ok = gmsh_load();
  pthread_mutex_unlock(&gmsh_lock);
  return ok;
}

/* Turn a failed Gmsh call into FCM_ERR_GEOMETRY quoting Gmsh's last error. */
#define GMSH(call)                                                                                 \
  do {                                                                                             \
    int ierr_ = 0;                                                                                 \
    call;                                                                                          \
    if (ierr_ != 0) {                                                                              \
      st = gmsh_error(ctx, #call, __LINE__);                                                       \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)
#define IERR &ierr_

static fcm_status gmsh_error(fcm_ctx *ctx, const char *call, int line)
{
  char *msg = NULL;
  int ierr = 0;
  G.LoggerGetLastError(&msg, &ierr);
  const char *text = ierr == 0 && msg && msg[0] ? msg : "no message";
  /* the call's function name: "G.Name(..." or "x = G.Name(..." -> gmshName */
  const char *g = strstr(call, "G.");
  call = g ? g + 2 : call;
  size_t n = strcspn(call, "(");
  fcm_status st =
      fcm__error(ctx, FCM_ERR_GEOMETRY, __FILE__, line, "fcm_geometry_create_from_surface",
                 "surface meshing: Gmsh's gmsh%.*s failed: %s", (int)n, call, text);
  if (msg) G.Free(msg);
  return st;
}

/* The tetrahedralization itself, with the lock held and Gmsh initialized. */
static fcm_status mesh_locked(fcm_ctx *ctx, const fcm_surface *s, const fcm_surface_mesh_options *o,
                              int algorithm, fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  size_t nv = (size_t)s->num_vertices, nt = (size_t)s->num_triangles;
  size_t *ntags = NULL, *etags = NULL, *enodes = NULL;
  size_t *gn = NULL, *ge = NULL, *gen = NULL, ngn = 0, ngc = 0, ngp = 0, nge = 0, ngen = 0;
  double *gc = NULL, *gp = NULL;
  fcm_index *map = NULL, *cells = NULL;
  double size = 0.0;
  if (o->max_volume > 0.0) size = cbrt(6.0 * sqrt(2.0) * o->max_volume);
  if (o->size > 0.0 && (size == 0.0 || o->size < size)) size = o->size;

  GMSH(G.OptionSetNumber("General.Terminal", 0, IERR));
  GMSH(G.OptionSetNumber("General.Verbosity", 0, IERR));
  GMSH(G.ModelAdd("fcm_surface", IERR));
  GMSH(G.OptionSetNumber("Mesh.Algorithm3D", algorithm, IERR));
  GMSH(G.OptionSetNumber("Mesh.OptimizeThreshold", o->quality, IERR));
  /* always set, not left to Gmsh's state between calls (1e22: its default) */
  GMSH(G.OptionSetNumber("Mesh.MeshSizeMax", size > 0.0 ? size : 1e22, IERR));
  GMSH(G.OptionSetNumber("General.NumThreads", 1, IERR));
  GMSH(G.OptionSetNumber("Mesh.MaxNumThreads3D", 1, IERR));
  GMSH(G.OptionSetNumber("Mesh.RandomSeed", 1, IERR));

  FCM_ALLOC_RAW(ctx, nv, ntags);
  FCM_ALLOC_RAW(ctx, nt, etags);
  FCM_ALLOC_RAW(ctx, 3 * nt, enodes);
  for (size_t i = 0; i < nv; i++)
    ntags[i] = i + 1;
  for (size_t t = 0; t < nt; t++) {
    etags[t] = t + 1;
    for (int k = 0; k < 3; k++)
      enodes[3 * t + (size_t)k] = (size_t)s->tris[3 * t + (size_t)k] + 1;
  }
  int surf = 0, loop = 0;
  GMSH(surf = G.ModelAddDiscreteEntity(2, -1, NULL, 0, IERR));
  GMSH(G.ModelMeshAddNodes(2, surf, ntags, nv, s->coords, 3 * nv, NULL, 0, IERR));
  GMSH(G.ModelMeshAddElementsByType(surf, 2, etags, nt, enodes, 3 * nt, IERR));
  GMSH(loop = G.ModelGeoAddSurfaceLoop(&surf, 1, -1, IERR));
  GMSH(G.ModelGeoAddVolume(&loop, 1, -1, IERR));
  GMSH(G.ModelGeoSynchronize(IERR));
  GMSH(G.ModelMeshGenerate(3, IERR));

  GMSH(G.ModelMeshGetNodes(&gn, &ngn, &gc, &ngc, &gp, &ngp, -1, -1, 0, 0, IERR));
  GMSH(G.ModelMeshGetElementsByType(4, &ge, &nge, &gen, &ngen, -1, 0, 1, IERR));
  FCM_CHECK(nge > 0 && ngen == 4 * nge && ngc == 3 * ngn, ctx, FCM_ERR_GEOMETRY,
            "surface meshing: Gmsh returned %zu tetrahedra (%zu node ids) and %zu nodes (%zu "
            "coordinates) for a surface of %zu triangles",
            nge, ngen, ngn, ngc, nt);
  size_t maxtag = 0;
  for (size_t i = 0; i < ngn; i++)
    if (gn[i] > maxtag) maxtag = gn[i];
  FCM_ALLOC_RAW(ctx, maxtag + 1, map);
  for (size_t i = 0; i <= maxtag; i++)
    map[i] = -1;
  for (size_t i = 0; i < ngn; i++)
    map[gn[i]] = (fcm_index)i;
  FCM_ALLOC_RAW(ctx, 4 * nge, cells);
  for (size_t i = 0; i < 4 * nge; i++) {
    FCM_CHECK(gen[i] <= maxtag && map[gen[i]] >= 0, ctx, FCM_ERR_GEOMETRY,
              "surface meshing: Gmsh's tetrahedron %zu names node %zu, which it did not return",
              i / 4, gen[i]);
    cells[i] = map[gen[i]];
  }
  FCM_TRY(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, (fcm_index)ngn, gc, (fcm_index)nge, cells,
                                   geom));
cleanup:
  if (gn) G.Free(gn);
  if (gc) G.Free(gc);
  if (gp) G.Free(gp);
  if (ge) G.Free(ge);
  if (gen) G.Free(gen);
  FCM_FREE(ctx, ntags);
  FCM_FREE(ctx, etags);
  FCM_FREE(ctx, enodes);
  FCM_FREE(ctx, map);
  FCM_FREE(ctx, cells);
  return st;
}

static fcm_status tetrahedralize(fcm_ctx *ctx, const fcm_surface *s,
                                 const fcm_surface_mesh_options *o, fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  int ierr = 0;
  pthread_mutex_lock(&gmsh_lock);
  if (!gmsh_load()) {
    st = fcm__error(ctx, FCM_ERR_UNSUPPORTED, __FILE__, __LINE__, __func__,
                    "surface meshing: cannot load Gmsh (%s): install it (Debian: apt-get "
                    "install libgmsh4.8, or libgmsh-dev)",
                    gmsh_load_error);
    pthread_mutex_unlock(&gmsh_lock);
    return st;
  }
  /* The classic Delaunay mesher (1) keeps the surface mesh and gives the same tetrahedra in
   * every call; HXT (10, Marot et al. 2019) does not: a second call in one process on the
   * same surface returned other tetrahedra (68414 vs 67966 for surface_drop's pebble, so two
   * runs of that scene in one process differed by 3 % on the body). But the classic mesher
   * does not refine inside a surface much coarser than the size asked for (a 12-triangle
   * cube stays 12 tets); only then, when its tets average more than 4x the requested
   * volume, HXT meshes it instead. */
  /* Gmsh applies General.NumThreads (1, set in mesh_locked) with omp_set_num_threads(), which
   * would leave every later OpenMP loop of the calling thread on one thread: restore it. */
  const int omp_threads = omp_get_max_threads();
  int alg = 1;
  double target = 0.0; /* the volume of a regular tet of the requested edge length */
  if (o->max_volume > 0.0) target = o->max_volume;
  if (o->size > 0.0 && (target == 0.0 || o->size * o->size * o->size / (6.0 * sqrt(2.0)) < target))
    target = o->size * o->size * o->size / (6.0 * sqrt(2.0));
  for (int attempt = 0; attempt < 2; attempt++) {
    G.Initialize(0, NULL, 0, &ierr);
    if (ierr != 0) {
      st = gmsh_error(ctx, "G.Initialize(", __LINE__);
      break;
    }
    st = mesh_locked(ctx, s, o, alg, geom);
    G.Finalize(&ierr);
    if (ierr != 0 && st == FCM_OK) {
      fcm_geometry_destroy(geom);
      st = gmsh_error(ctx, "G.Finalize(", __LINE__);
    }
    if (st != FCM_OK || alg == 10 || target <= 0.0 ||
        fcm_geometry_volume(*geom) <= 4.0 * target * (double)fcm_geometry_num_cells(*geom))
      break;
    fcm_geometry_destroy(geom);
    alg = 10;
  }
  omp_set_num_threads(omp_threads);
  pthread_mutex_unlock(&gmsh_lock);
  return st;
}

#else /* no Gmsh */

int fcm_surface_meshing_available(void)
{
  return 0;
}

static fcm_status tetrahedralize(fcm_ctx *ctx, const fcm_surface *s,
                                 const fcm_surface_mesh_options *o, fcm_geometry **geom)
{
  (void)s, (void)o, (void)geom;
  return fcm__error(ctx, FCM_ERR_UNSUPPORTED, __FILE__, __LINE__, __func__,
                    "surface meshing: fcm was built without Gmsh, which tetrahedralizes "
                    "surfaces; install it (Debian: apt-get install libgmsh-dev) and rebuild "
                    "fcm (CMake option FCM_WITH_GMSH, default AUTO)");
}

#endif

fcm_status fcm_geometry_create_from_surface(fcm_ctx *ctx, const fcm_surface *surf,
                                            const fcm_surface_mesh_options *opts,
                                            fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  fcm_surface *oriented = NULL;
  fcm_surface_report rep;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "surface meshing: output pointer is NULL");
  *geom = NULL;
  FCM_CHECK(ctx && surf, ctx, FCM_ERR_ARG, "surface meshing: NULL argument (ctx and surf)");
  fcm_surface_mesh_options o = opts ? *opts : fcm_surface_mesh_options_default();
  FCM_CHECK(o.max_volume >= 0.0 && isfinite(o.max_volume), ctx, FCM_ERR_ARG,
            "surface meshing: max_volume = %g must be finite and >= 0 (0: no limit)", o.max_volume);
  FCM_CHECK(o.size >= 0.0 && isfinite(o.size), ctx, FCM_ERR_ARG,
            "surface meshing: size = %g must be finite and >= 0 (0: from the surface)", o.size);
  FCM_CHECK(o.quality >= 0.0 && o.quality <= 1.0, ctx, FCM_ERR_ARG,
            "surface meshing: quality = %g outside [0, 1]", o.quality);
  const fcm_surface *s = surf;
  if (o.orient) {
    FCM_TRY(ctx, fcm_surface_create_oriented(ctx, surf, &oriented, NULL));
    s = oriented;
  }
  fcm_surface_check_options co = fcm_surface_check_options_default();
  co.self_intersections = o.check_intersections != 0;
  FCM_TRY(ctx, fcm_surface_check(s, &co, &rep));
  FCM_TRY(ctx, fcm_surface_report_check(s, "surface meshing", &rep));
  if (o.volume_mesh)
    FCM_TRY(ctx, tetrahedralize(ctx, s, &o, geom));
  else
    FCM_TRY(ctx, fcm__geom_create_boundary(ctx, "surface", fcm_surface_num_vertices(s),
                                           fcm_surface_coords(s), fcm_surface_num_triangles(s),
                                           fcm_surface_triangles(s), geom));
cleanup:
  fcm_surface_destroy(&oriented);
  return st;
}
