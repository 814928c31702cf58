/* Interposed malloc/calloc/realloc/free for the allocation tests (the library and the
 * shared SuiteSparse libraries resolve to these definitions): g_count counts allocations,
 * g_live the blocks not yet freed, and allocation number g_fail_at (counted from the last
 * reset of g_count; -1: none) returns NULL. Include in one translation unit per program.
 * Under AddressSanitizer, which owns malloc itself, nothing is interposed and
 * ALLOC_HOOK_ACTIVE is 0 (the test then skips with exit status 77). */
#ifndef FESD_TEST_ALLOC_HOOK_H
#define FESD_TEST_ALLOC_HOOK_H
#include <stddef.h>

#if defined(__SANITIZE_ADDRESS__)
#define ALLOC_HOOK_ACTIVE 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ALLOC_HOOK_ACTIVE 0
#endif
#endif
#ifndef ALLOC_HOOK_ACTIVE
#define ALLOC_HOOK_ACTIVE 1
#endif

#if ALLOC_HOOK_ACTIVE
void *__libc_malloc(size_t n);
void *__libc_calloc(size_t n, size_t size);
void *__libc_realloc(void *p, size_t n);
void __libc_free(void *p);

static long g_live = 0, g_count = 0, g_fail_at = -1;

static int alloc_hook_fail(void) {
  long k = g_count++;
  return g_fail_at >= 0 && k == g_fail_at;
}

/* default visibility: the project builds with -fvisibility=hidden */
#define ALLOC_HOOK_EXPORT __attribute__((visibility("default")))
ALLOC_HOOK_EXPORT void *malloc(size_t n) {
  if (alloc_hook_fail()) return NULL;
  void *p = __libc_malloc(n);
  if (p) g_live++;
  return p;
}
ALLOC_HOOK_EXPORT void *calloc(size_t n, size_t size) {
  if (alloc_hook_fail()) return NULL;
  void *p = __libc_calloc(n, size);
  if (p) g_live++;
  return p;
}
ALLOC_HOOK_EXPORT void *realloc(void *p, size_t n) {
  if (!p) return malloc(n);
  if (alloc_hook_fail()) return NULL;
  return __libc_realloc(p, n);
}
ALLOC_HOOK_EXPORT void free(void *p) {
  if (p) g_live--;
  __libc_free(p);
}
#endif
#endif
