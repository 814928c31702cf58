/* One allocation for the many arrays of a workspace (block.h). */
#include "common/block.h"

#include <stdlib.h>
#include <string.h>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#define BLOCK_REDZONE 64
#else
#define BLOCK_REDZONE 0
#endif

enum { BLOCK_ALIGN = 64 }; /* offsets from the base (malloc's alignment, 16, for the base) */

static size_t round_up(size_t n) { return (n + BLOCK_ALIGN - 1) / BLOCK_ALIGN * BLOCK_ALIGN; }

void *fesd__block_take(fesd__block *b, size_t bytes, int zero) {
  if (bytes == 0) bytes = 1;
  const size_t at = b->used;
  b->used = at + round_up(bytes + BLOCK_REDZONE);
  if (!b->base) return NULL;
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
  b->base = malloc(size); /* malloc (not aligned_alloc): one allocator for every workspace */
#if BLOCK_REDZONE
  if (b->base) ASAN_POISON_MEMORY_REGION(b->base, size);
#endif
  return b->base;
}

/* ASan's free re-poisons the whole chunk as freed, red zones included */
void fesd__block_free(void *base) { free(base); }
