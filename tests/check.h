/* One assertion macro for the test programs: prints the failure and counts it in the
 * caller's `fails`, without stopping (every check of a test runs). */
#ifndef FESD_TEST_CHECK_H
#define FESD_TEST_CHECK_H
#include <stdio.h>

#define FESD_TEST_CHECK(cond, ...)  \
  do {                              \
    if (!(cond)) {                  \
      printf("FAIL: " __VA_ARGS__); \
      printf("\n");                 \
      fails++;                      \
    }                               \
  } while (0)

#endif
