/* Large arrays on 2 MiB boundaries, backed by transparent huge pages where the system offers
 * them on request (Linux's madvise mode): the assembled matrices' values are scattered into
 * all over, and with 4 KiB pages their tens of megabytes miss the TLB on most element rows.
 * A large array has a quarter more room than asked, address space only (never touched before
 * it is used), so that a slightly larger array of its successor (a cut's new matrix) can take
 * it over (fcm__calloc_large_from()): the first touch of fresh pages, huge ones above all,
 * costs several times the zero fill of pages already mapped. An owner whose arrays a successor
 * will take (an integrator with FCM_CUT_REUSE_STORAGE) maps their room when it makes them
 * (fcm__large_map()), so that a cut growing into it pays no page faults: a quarter more
 * resident memory for those arrays only; every other array's room stays address space. */
#define _DEFAULT_SOURCE /* madvise, MADV_HUGEPAGE */
#include "core_impl.h"

#include <stdint.h>
#include <string.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

/* The huge page size aimed at; the smallest array given one is FCM__LARGE_MIN (below it the
 * padding and a partly used last page cost more than the few TLB entries saved). */
enum { HUGE_PAGE = 2 << 20, SMALL_ALIGN = 64 };

/* Kept just before the caller's array: the block from ctx's allocator and the room from the
 * array's start on. */
typedef struct {
  void *raw;
  size_t capacity;
  size_t mapped; /* the room is mapped (fcm__large_map()) */
} large_header;

/* alloc_large()'s flag: fill the n elements with zeros (else left untouched). */
enum { LARGE_ZERO = 1 };

/* fcm__calloc_large() and its variants (flags: LARGE_*). */
static void *alloc_large(fcm_ctx *ctx, size_t n, size_t size, int flags)
{
  if (size && n > SIZE_MAX / size) {
    fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
               "allocation of %zu elements of %zu bytes overflows size_t", n, size);
    return NULL;
  }
  const size_t bytes = n * size;
  const size_t align = bytes >= FCM__LARGE_MIN ? HUGE_PAGE : SMALL_ALIGN;
  const size_t capacity = align == HUGE_PAGE && bytes <= SIZE_MAX / 2 ? bytes + bytes / 4 : bytes;
  /* The block from ctx's allocator holds the caller's array on an `align` boundary and, just
   * before it, its header for fcm__free_large() and fcm__calloc_large_from(). */
  if (capacity > SIZE_MAX - align - sizeof(large_header)) {
    fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
               "allocation of %zu bytes with %zu-byte alignment overflows size_t", bytes, align);
    return NULL;
  }
  unsigned char *raw = fcm__malloc(ctx, capacity + align + sizeof(large_header), 1);
  if (!raw) return NULL;
  const uintptr_t first = (uintptr_t)(raw + sizeof(large_header));
  unsigned char *p = raw + sizeof(large_header) + (size_t)((align - first % align) % align);
  const large_header h = {raw, capacity, 0};
  memcpy(p - sizeof h, &h, sizeof h);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  /* Before the first touch (the zero fill below), so that the pages fault in as huge ones.
   * Advice only: refused (kernel without transparent huge pages), the array still works. */
  if (align == HUGE_PAGE) (void)madvise(p, capacity - capacity % HUGE_PAGE, MADV_HUGEPAGE);
#endif
  if (flags & LARGE_ZERO) memset(p, 0, bytes);
  return p;
}

void *fcm__calloc_large(fcm_ctx *ctx, size_t n, size_t size)
{
  return alloc_large(ctx, n, size, LARGE_ZERO);
}

void *fcm__malloc_large(fcm_ctx *ctx, size_t n, size_t size)
{
  return alloc_large(ctx, n, size, 0);
}

void fcm__large_map(void *p)
{
  if (!p) return;
  large_header h;
  memcpy(&h, (unsigned char *)p - sizeof h, sizeof h);
  if (h.mapped || h.capacity == 0) return; /* once per array, whoever takes it later */
  /* each page read and written back: its contents kept, the page faulted in now */
  volatile unsigned char *q = p;
  for (size_t o = 0; o < h.capacity; o += 4096)
    q[o] = q[o];
  q[h.capacity - 1] = q[h.capacity - 1]; /* the last page, when the stride stepped over it */
  h.mapped = 1;
  memcpy((unsigned char *)p - sizeof h, &h, sizeof h);
}

void *fcm__large_take(void **from, size_t n, size_t size)
{
  if (!from || !*from || !size || n > SIZE_MAX / size) return NULL;
  large_header h;
  memcpy(&h, (unsigned char *)*from - sizeof h, sizeof h);
  const size_t bytes = n * size;
  if (bytes > h.capacity || bytes < h.capacity / 2) return NULL;
  void *p = *from;
  *from = NULL;
  return p;
}

void *fcm__calloc_large_from(fcm_ctx *ctx, void **from, size_t n, size_t size)
{
  void *p = fcm__large_take(from, n, size);
  if (!p) return fcm__calloc_large(ctx, n, size);
  memset(p, 0, n * size);
  return p;
}

void fcm__free_large(fcm_ctx *ctx, void *ptr)
{
  if (!ptr) return;
  large_header h;
  memcpy(&h, (unsigned char *)ptr - sizeof h, sizeof h);
  fcm__free(ctx, h.raw);
}
