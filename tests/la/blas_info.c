/* The BLAS kernel query: the level of the kernels OpenBLAS names against the CPU's, a fallback
 * exactly when the kernels are below the CPU, and its warning logged once per context (at the
 * query and at a direct solver's analysis) with the OPENBLAS_CORETYPE that fixes it.
 * Run as "blas_info" (whatever kernels OpenBLAS chose) and as "blas_info prescott" under
 * OPENBLAS_CORETYPE=Prescott, where every CPU with AVX or more must see a fallback. */
#include "la/la_impl.h"
#include "test.h"

typedef struct log_count {
  int warnings;
  char last[1024];
} log_count;

static void count_log(void *user, fcm_log_level level, const char *msg)
{
  log_count *c = user;
  if (level != FCM_LOG_WARNING || !strstr(msg, "BLAS:")) return;
  c->warnings++;
  snprintf(c->last, sizeof c->last, "%s", msg);
}

static fcm_ctx *logging_ctx(log_count *c)
{
  fcm_ctx_options o = fcm_ctx_options_default();
  o.log = count_log;
  o.log_user = c;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(&o, &ctx) != FCM_OK) return NULL;
  return ctx;
}

/* Analyze a 2 x 2 SPD matrix with `method` (the analysis checks the kernels). */
static void analyze_small(fcm_ctx *ctx, fcm_direct_method method)
{
  const fcm_index ti[] = {0, 0, 1, 1}, tj[] = {0, 1, 0, 1};
  const double tv[] = {4.0, 1.0, 1.0, 3.0};
  fcm_csr *A = NULL;
  fcm_direct *s = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, 2, 2, 4, ti, tj, tv, FCM_CSR_SYMMETRIC, &A));
  TEST_OK(ctx, fcm_direct_create(ctx, method, A, &s));
  TEST_OK(ctx, fcm_direct_analyze(s));
  fcm_direct_destroy(&s);
  fcm_csr_destroy(&A);
}

int main(int argc, char **argv)
{
  const int prescott = argc > 1 && strcmp(argv[1], "prescott") == 0;
  log_count c1 = {0, ""}, c2 = {0, ""};
  fcm_ctx *ctx = logging_ctx(&c1), *ctx2 = logging_ctx(&c2);
  TEST_TRUE(ctx && ctx2);
  if (!ctx || !ctx2) return TEST_RESULT();

  TEST_ERR(ctx, fcm_blas_info_get(ctx, NULL), FCM_ERR_ARG, "info is NULL");
  TEST_TRUE(strcmp(fcm_isa_name(FCM_ISA_AVX512), "AVX-512") == 0);
  TEST_TRUE(strcmp(fcm_isa_name((fcm_isa)99), "unknown") == 0);

  fcm_blas_info b;
  TEST_OK(ctx, fcm_blas_info_get(ctx, &b));
  TEST_TRUE(b.name && b.config && b.core && b.cpu_core);
  /* fcm links OpenBLAS: it names its kernels, and on x86-64 the table knows them */
  TEST_TRUE(strcmp(b.name, "OpenBLAS") == 0);
  TEST_TRUE(strstr(b.config, "OpenBLAS") != NULL);
#if defined(__x86_64__)
  TEST_TRUE(b.core_isa != FCM_ISA_UNKNOWN);
  TEST_TRUE(b.cpu_isa >= FCM_ISA_SSE2);
  /* the kernel set proposed for the CPU is of the CPU's level */
  if (b.cpu_isa >= FCM_ISA_AVX) TEST_TRUE(b.cpu_core[0] != '\0');
#endif
  TEST_TRUE(b.fallback ==
            (b.core_isa != FCM_ISA_UNKNOWN && b.cpu_core[0] && b.core_isa < b.cpu_isa));
  if (prescott) {
    TEST_TRUE(strcmp(b.core, "Prescott") == 0);
    TEST_TRUE(b.core_isa == FCM_ISA_SSE3);
    TEST_TRUE(b.fallback == (b.cpu_isa >= FCM_ISA_AVX));
  }

  /* the warning: once per context, naming the fix; none without a fallback */
  TEST_OK(ctx, fcm_blas_info_get(ctx, &b));
  analyze_small(ctx, FCM_DIRECT_CHOLMOD);
  analyze_small(ctx2, FCM_DIRECT_UMFPACK);
  analyze_small(ctx2, FCM_DIRECT_CHOLMOD);
  TEST_TRUE(c1.warnings == b.fallback);
  TEST_TRUE(c2.warnings == b.fallback);
  if (b.fallback) {
    char fix[64];
    snprintf(fix, sizeof fix, "OPENBLAS_CORETYPE=%s", b.cpu_core);
    TEST_TRUE(strstr(c1.last, fix) != NULL);
    TEST_TRUE(strstr(c1.last, b.core) != NULL);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  fcm_ctx_destroy(&ctx2);
  return TEST_RESULT();
}
