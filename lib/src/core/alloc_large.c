/* Large arrays on 2 MiB boundaries, backed by transparent huge pages where the system offers
 * them on request (Linux's madvise mode): the assembled matrices' values are scattered into
 * all over, and with 4 KiB pages their tens of megabytes miss the TLB on most element rows. */
#define _DEFAULT_SOURCE /* madvise, MADV_HUGEPAGE */
#include "core_impl.h"

#include <stdint.h>
#include <string.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

/* The huge page size aimed at, and the smallest array given one (below it the padding and
 * a partly used last page cost more than the few TLB entries saved). */
enum { HUGE_PAGE = 2 << 20, LARGE_MIN = 8 << 20, SMALL_ALIGN = 64 };

void *fcm__calloc_large(fcm_ctx *ctx, size_t n, size_t size)
{
  if (size && n > SIZE_MAX / size) {
    fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
               "allocation of %zu elements of %zu bytes overflows size_t", n, size);
    return NULL;
  }
  const size_t bytes = n * size;
  const size_t align = bytes >= LARGE_MIN ? HUGE_PAGE : SMALL_ALIGN;
  /* The block from ctx's allocator holds the caller's array on an `align` boundary and, just
   * before it, the block's own address for fcm__free_large(). */
  if (bytes > SIZE_MAX - align - sizeof(void *)) {
    fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
               "allocation of %zu bytes with %zu-byte alignment overflows size_t", bytes, align);
    return NULL;
  }
  unsigned char *raw = fcm__malloc(ctx, bytes + align + sizeof(void *), 1);
  if (!raw) return NULL;
  const uintptr_t first = (uintptr_t)(raw + sizeof(void *));
  unsigned char *p = raw + sizeof(void *) + (size_t)((align - first % align) % align);
  memcpy(p - sizeof(void *), &raw, sizeof raw);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  /* Before the first touch (the zero fill below), so that the pages fault in as huge ones.
   * Advice only: refused (kernel without transparent huge pages), the array still works. */
  if (align == HUGE_PAGE) (void)madvise(p, bytes - bytes % HUGE_PAGE, MADV_HUGEPAGE);
#endif
  memset(p, 0, bytes);
  return p;
}

void fcm__free_large(fcm_ctx *ctx, void *ptr)
{
  if (!ptr) return;
  void *raw;
  memcpy(&raw, (unsigned char *)ptr - sizeof(void *), sizeof raw);
  fcm__free(ctx, raw);
}
