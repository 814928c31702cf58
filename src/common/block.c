/* One allocation for the many arrays of a workspace (block.h). */
#include "common/block.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* AddressSanitizer: gcc defines __SANITIZE_ADDRESS__, clang answers __has_feature */
#if defined(__SANITIZE_ADDRESS__)
#define BLOCK_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define BLOCK_ASAN 1
#endif
#endif
#ifdef BLOCK_ASAN
#include <sanitizer/asan_interface.h>
#define BLOCK_REDZONE 64
#else
#define BLOCK_REDZONE 0
#endif

enum { BLOCK_ALIGN = 64 }; /* offsets from the base (malloc's alignment, 16, for the base) */

/* n rounded up to the alignment; SIZE_MAX when that overflows (malloc then fails) */
static size_t round_up(size_t n) {
  return n > SIZE_MAX - BLOCK_ALIGN ? SIZE_MAX : (n + BLOCK_ALIGN - 1) / BLOCK_ALIGN * BLOCK_ALIGN;
}

void *fesd__block_take(fesd__block *b, size_t bytes, int zero) {
  if (bytes < sizeof(double)) bytes = sizeof(double); /* as calloc(1, sizeof(double)) did */
  const size_t at = b->used, step = round_up(bytes > SIZE_MAX - BLOCK_REDZONE ? SIZE_MAX : bytes + BLOCK_REDZONE);
  b->used = at > SIZE_MAX - step ? SIZE_MAX : at + step; /* saturates: the block's malloc fails */
  if (!b->base) return NULL;
  if (b->used > b->cap) return NULL; /* more than the sizing pass asked for: fesd__block_ok says so */
  char *p = b->base + at;
#if BLOCK_REDZONE
  ASAN_UNPOISON_MEMORY_REGION(p, bytes);
#endif
  if (zero) memset(p, 0, bytes);
  return p;
}

void *fesd__block_open(fesd__block *b) {
  const size_t size = b->used > 0 ? b->used : 1;
  b->used = 0;
  b->cap = size;
  b->base = size == SIZE_MAX ? NULL : malloc(size); /* malloc: one allocator for every workspace */
#if BLOCK_REDZONE
  if (b->base) ASAN_POISON_MEMORY_REGION(b->base, size);
#endif
  return b->base;
}

int fesd__block_ok(const fesd__block *b) { return b->base && b->used <= b->cap; }

/* ASan's free re-poisons the whole chunk as freed, red zones included */
void fesd__block_free(void *base) { free(base); }
