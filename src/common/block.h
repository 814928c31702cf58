/* One allocation for the many arrays of a workspace.
 *
 * A workspace made of dozens of short arrays paid a malloc and a free for each (measured,
 * callgrind: ~550 instructions per array with glibc, a tenth of a whole fixed-step integration
 * of the paper's oscillator at 1e-10 once creation and release are counted). The arrays are
 * instead laid out by a function that runs twice: a sizing pass (base == NULL; every take
 * returns NULL and only adds up) and the real pass over one malloc'd block. Each array starts at
 * a multiple of 64 bytes from the base; under AddressSanitizer (gcc or clang) a poisoned red
 * zone follows each one, so overflows into the next array are still caught; arrays taken
 * without zeroing stay undefined for valgrind, as with malloc. */
#ifndef FESD_COMMON_BLOCK_H
#define FESD_COMMON_BLOCK_H

#include <stddef.h>

typedef struct {
  char *base;  /* NULL in the sizing pass */
  size_t used; /* bytes laid out so far (saturates at SIZE_MAX) */
  size_t cap;  /* the block's size (fesd__block_open) */
} fesd__block;

/* Room for `bytes` (at least 8), zeroed when `zero`; NULL in the sizing pass (and past the
 * block's end, which fesd__block_ok reports). */
void *fesd__block_take(fesd__block *b, size_t bytes, int zero);

/* The real pass's block for the size counted in `b` (NULL when out of memory); b restarts. */
void *fesd__block_open(fesd__block *b);

/* After the carving pass: the block exists and every take fitted in it (the two passes asked
 * for the same sizes). */
int fesd__block_ok(const fesd__block *b);

/* Release of a block from fesd__block_open (NULL allowed). */
void fesd__block_free(void *base);

static inline double *fesd__block_doubles(fesd__block *b, size_t n) {
  return (double *)fesd__block_take(b, n * sizeof(double), 1);
}

#endif
