/* Which kernel set the BLAS runs on, against the instruction set of the CPU: the query
 * fcm_blas_info_get() and the warning, once per context, when the kernels are a fallback.
 *
 * A DYNAMIC_ARCH OpenBLAS picks its kernels from the CPU's family and model when it loads;
 * a CPU newer than the OpenBLAS release gets a generic set (Debian 12's 0.3.21 runs its SSE3
 * "Prescott" kernels on Intel family 6 model 207, AVX-512: DGEMM at a fifth of the core's
 * peak), silently. Comparing the level of the kernels it names with what cpuid reports finds
 * that; OPENBLAS_CORETYPE, read when OpenBLAS loads, selects the right set. */
#include "la/la_impl.h"

#include <ctype.h>
#include <string.h>

/* OpenBLAS's kernel sets for x86-64 (driver/others/dynamic.c) and their instruction sets. */
static const struct {
  const char *name;
  fcm_isa isa;
} core_table[] = {
    {"Katmai", FCM_ISA_SSE2},       {"Coppermine", FCM_ISA_SSE2},
    {"Northwood", FCM_ISA_SSE2},    {"Banias", FCM_ISA_SSE2},
    {"Athlon", FCM_ISA_SSE2},       {"Opteron", FCM_ISA_SSE2},
    {"Prescott", FCM_ISA_SSE3},     {"Atom", FCM_ISA_SSE3},
    {"Core2", FCM_ISA_SSE3},        {"Penryn", FCM_ISA_SSE3},
    {"Dunnington", FCM_ISA_SSE3},   {"Nehalem", FCM_ISA_SSE3},
    {"Opteron_SSE3", FCM_ISA_SSE3}, {"Barcelona", FCM_ISA_SSE3},
    {"Nano", FCM_ISA_SSE3},         {"Bobcat", FCM_ISA_SSE3},
    {"Sandybridge", FCM_ISA_AVX},   {"Bulldozer", FCM_ISA_AVX},
    {"Piledriver", FCM_ISA_AVX},    {"Steamroller", FCM_ISA_AVX},
    {"Excavator", FCM_ISA_AVX},     {"Haswell", FCM_ISA_AVX2},
    {"Zen", FCM_ISA_AVX2},          {"SkylakeX", FCM_ISA_AVX512},
    {"Cooperlake", FCM_ISA_AVX512}, {"SapphireRapids", FCM_ISA_AVX512},
};

static int same_name(const char *a, const char *b)
{
  for (; *a && *b; a++, b++)
    if (tolower((unsigned char)*a) != tolower((unsigned char)*b)) return 0;
  return *a == *b;
}

static fcm_isa core_isa(const char *core)
{
  for (size_t i = 0; i < sizeof core_table / sizeof core_table[0]; i++)
    if (same_name(core, core_table[i].name)) return core_table[i].isa;
  return FCM_ISA_UNKNOWN;
}

/* What the CPU and the OS support (GCC's cpuid reading also checks that the OS saves the
 * AVX and AVX-512 registers), and the OpenBLAS kernel set made for it. */
static fcm_isa cpu_isa(const char **cpu_core)
{
  *cpu_core = "";
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl")) {
    *cpu_core = "SkylakeX";
    return FCM_ISA_AVX512;
  }
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    *cpu_core = __builtin_cpu_is("amd") ? "Zen" : "Haswell";
    return FCM_ISA_AVX2;
  }
  if (__builtin_cpu_supports("avx")) {
    *cpu_core = "Sandybridge";
    return FCM_ISA_AVX;
  }
  if (__builtin_cpu_supports("sse3")) return FCM_ISA_SSE3;
  return FCM_ISA_SSE2;
#else
  return FCM_ISA_UNKNOWN;
#endif
}

/* Everything of fcm_blas_info but the config string (the part that is thread safe). */
static void find_kernels(fcm_blas_info *info)
{
  memset(info, 0, sizeof *info);
  info->core = fcm__blas_core_name();
  info->name = info->core[0] ? "OpenBLAS" : "unknown";
  info->config = "";
  info->core_isa = core_isa(info->core);
  info->cpu_isa = cpu_isa(&info->cpu_core);
  info->fallback =
      info->core_isa != FCM_ISA_UNKNOWN && info->cpu_core[0] && info->core_isa < info->cpu_isa;
}

const char *fcm_isa_name(fcm_isa isa)
{
  static const char *const names[] = {"unknown", "SSE2", "SSE3", "AVX", "AVX2", "AVX-512"};
  if ((int)isa < 0 || (size_t)isa >= sizeof names / sizeof names[0]) return "unknown";
  return names[isa];
}

static void warn(fcm_ctx *ctx, const fcm_blas_info *b)
{
  if (!b->fallback || !fcm__ctx_once(ctx, FCM__ONCE_BLAS_KERNELS)) return;
  fcm__log(ctx, FCM_LOG_WARNING,
           "BLAS: %s runs its %s kernels (%s) on a CPU with %s: dense products (DGEMM, and "
           "so the sparse direct solvers) run several times slower than they can; set "
           "OPENBLAS_CORETYPE=%s in the environment before the program starts",
           b->name, b->core, fcm_isa_name(b->core_isa), fcm_isa_name(b->cpu_isa), b->cpu_core);
}

void fcm__blas_check(fcm_ctx *ctx)
{
  if (!ctx) return;
  fcm_blas_info b;
  find_kernels(&b);
  warn(ctx, &b);
}

fcm_status fcm_blas_info_get(fcm_ctx *ctx, fcm_blas_info *info)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(info, ctx, FCM_ERR_ARG, "blas_info: info is NULL");
  find_kernels(info);
  info->config = fcm__blas_config();
  warn(ctx, info);
cleanup:
  return st;
}
