/* Large arrays on 2 MiB boundaries, backed by transparent huge pages where the system offers
 * them on request (Linux's madvise mode): the assembled matrices' values are scattered into
 * all over, and with 4 KiB pages their tens of megabytes miss the TLB on most element rows.
 * A large array has a quarter more room than asked, address space only (never touched before
 * it is used), so that a slightly larger array of its successor (a cut's new matrix) can take
 * it over (fcm__calloc_large_from()): the first touch of fresh pages, huge ones above all,
 * costs several times the zero fill of pages already mapped. The arrays a successor takes
 * (fcm__calloc_large_mapped(), fcm__calloc_large_from()) have their room mapped when they are
 * created, so that a cut growing into it pays no page faults: a quarter more resident memory
 * for those arrays (only; the others' room stays address space). */
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
} large_header;

/* alloc_large()'s flags: fill the n elements with zeros (else left untouched); map the room
 * beyond them too (one write per small page: the pages fault in now, not at the first write
 * of the array's successor). */
enum { LARGE_ZERO = 1, LARGE_MAP_ROOM = 2 };

/* A write of zero to each 4 KiB page of [p, end) (an array's room, contents undefined). */
static void map_pages(unsigned char *p, unsigned char *end)
{
  if (p >= end) return;
  for (; p < end; p += 4096)
    *p = 0;
  end[-1] = 0; /* the last page, when the stride stepped over its start */
}

/* The array p (bytes asked for, capacity of room) as flags ask. */
static void *fill(unsigned char *p, size_t bytes, size_t capacity, int flags)
{
  if (flags & LARGE_ZERO) memset(p, 0, bytes);
  if (flags & LARGE_MAP_ROOM) map_pages(p + ((flags & LARGE_ZERO) ? bytes : 0), p + capacity);
  return p;
}

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
  const large_header h = {raw, capacity};
  memcpy(p - sizeof h, &h, sizeof h);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  /* Before the first touch (the zero fill below), so that the pages fault in as huge ones.
   * Advice only: refused (kernel without transparent huge pages), the array still works. */
  if (align == HUGE_PAGE) (void)madvise(p, capacity - capacity % HUGE_PAGE, MADV_HUGEPAGE);
#endif
  return fill(p, bytes, capacity, flags);
}

void *fcm__calloc_large(fcm_ctx *ctx, size_t n, size_t size)
{
  return alloc_large(ctx, n, size, LARGE_ZERO);
}

void *fcm__malloc_large(fcm_ctx *ctx, size_t n, size_t size)
{
  return alloc_large(ctx, n, size, 0);
}

void *fcm__calloc_large_mapped(fcm_ctx *ctx, size_t n, size_t size)
{
  return alloc_large(ctx, n, size, LARGE_ZERO | LARGE_MAP_ROOM);
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
  if (!p) return fcm__calloc_large_mapped(ctx, n, size);
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
