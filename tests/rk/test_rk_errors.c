/* Acceptance test 4: error paths and names.
 *  - unsupported (family, s): s=0, s=-1, s=13 for every family, Lobatto IIIA/IIIC
 *    s=1, explicit s=5..12, family=99 and -1 -> FESD_ERR_UNSUPPORTED_TABLEAU,
 *    fesd_rk_order -> -1, and the output is left untouched;
 *  - NULL out -> FESD_ERR_NULL (also for an unsupported pair);
 *  - every supported pair succeeds and fesd_rk_order agrees with t.order;
 *  - names: fesd_rk_family_name / fesd_rk_family_parse round-trip for all
 *    families, unknown names -> FESD_ERR_INVALID_ARG, NULL -> FESD_ERR_NULL,
 *    unknown family -> NULL name. */
#include <stdio.h>
#include <string.h>

#include "fesd_rk.h"

static int failures = 0;

#define CHECK_MSG(cond, what)                                \
  do {                                                       \
    if (cond) {                                              \
      printf("ok   %s\n", what);                             \
    } else {                                                 \
      printf("FAIL %s (line %d)\n", what, __LINE__);         \
      ++failures;                                            \
    }                                                        \
  } while (0)
#define CHECK(cond) CHECK_MSG(cond, #cond)

static int unsupported_untouched(int family, int s) {
  fesd_tableau t, ref;
  memset(&t, 0xA5, sizeof t);
  memcpy(&ref, &t, sizeof t);
  int rc = fesd_tableau_get((fesd_rk_family)family, s, &t);
  int ok = rc == FESD_ERR_UNSUPPORTED_TABLEAU && memcmp(&t, &ref, sizeof t) == 0 &&
           fesd_rk_order((fesd_rk_family)family, s) == -1;
  if (!ok) printf("     unsupported pair (family %d, s %d): rc %d\n", family, s, rc);
  return ok;
}

int main(void) {
  int all = 1;
  for (int f = 0; f < FESD_RK_NUM_FAMILIES; ++f)
    all &= unsupported_untouched(f, 0) & unsupported_untouched(f, -1) &
           unsupported_untouched(f, FESD_RK_MAX_STAGES + 1);
  CHECK_MSG(all, "s = 0, -1, 13 unsupported for every family (output untouched)");
  CHECK(unsupported_untouched(FESD_RK_LOBATTO_IIIA, 1));
  CHECK(unsupported_untouched(FESD_RK_LOBATTO_IIIC, 1));
  all = 1;
  for (int s = 5; s <= FESD_RK_MAX_STAGES; ++s) all &= unsupported_untouched(FESD_RK_EXPLICIT, s);
  CHECK_MSG(all, "explicit s = 5..12 unsupported");
  CHECK(unsupported_untouched(99, 1));
  CHECK(unsupported_untouched(-1, 1));
  CHECK(unsupported_untouched(FESD_RK_NUM_FAMILIES, 2));

  CHECK(fesd_tableau_get(FESD_RK_RADAU_IIA, 3, NULL) == FESD_ERR_NULL);
  CHECK(fesd_tableau_get(FESD_RK_EXPLICIT, 4, NULL) == FESD_ERR_NULL);
  CHECK(fesd_tableau_get((fesd_rk_family)99, 0, NULL) == FESD_ERR_NULL);

  all = 1;
  int count = 0;
  for (int f = 0; f < FESD_RK_NUM_FAMILIES; ++f)
    for (int s = 1; s <= FESD_RK_MAX_STAGES; ++s) {
      int p = fesd_rk_order((fesd_rk_family)f, s);
      if (p < 0) continue;
      fesd_tableau t;
      int rc = fesd_tableau_get((fesd_rk_family)f, s, &t);
      all &= rc == FESD_OK && t.order == p && t.s == s && (int)t.family == f;
      ++count;
    }
  CHECK_MSG(all, "every supported pair succeeds, order == fesd_rk_order");
  CHECK(count == 12 + 12 + 11 + 11 + 4); /* number of supported pairs */

  all = 1;
  for (int f = 0; f < FESD_RK_NUM_FAMILIES; ++f) {
    const char *name = fesd_rk_family_name((fesd_rk_family)f);
    fesd_rk_family back = (fesd_rk_family)-1;
    int rc = name ? fesd_rk_family_parse(name, &back) : -100;
    printf("     family %d <-> \"%s\" (parse rc %d)\n", f, name ? name : "(null)", rc);
    all &= name != NULL && rc == FESD_OK && (int)back == f;
  }
  CHECK_MSG(all, "names round-trip through fesd_rk_family_parse");
  CHECK(strcmp(fesd_rk_family_name(FESD_RK_RADAU_IIA), "radau") == 0);
  CHECK(strcmp(fesd_rk_family_name(FESD_RK_GAUSS_LEGENDRE), "gauss") == 0);
  CHECK(strcmp(fesd_rk_family_name(FESD_RK_LOBATTO_IIIA), "lobatto3a") == 0);
  CHECK(strcmp(fesd_rk_family_name(FESD_RK_LOBATTO_IIIC), "lobatto3c") == 0);
  CHECK(strcmp(fesd_rk_family_name(FESD_RK_EXPLICIT), "erk") == 0);
  CHECK(fesd_rk_family_name((fesd_rk_family)99) == NULL);
  CHECK(fesd_rk_family_name((fesd_rk_family)-1) == NULL);

  fesd_rk_family out = FESD_RK_GAUSS_LEGENDRE;
  CHECK(fesd_rk_family_parse("rk4", &out) == FESD_ERR_INVALID_ARG);
  CHECK(fesd_rk_family_parse("", &out) == FESD_ERR_INVALID_ARG);
  CHECK(fesd_rk_family_parse("radau ", &out) == FESD_ERR_INVALID_ARG);
  CHECK(out == FESD_RK_GAUSS_LEGENDRE); /* untouched on error */
  CHECK(fesd_rk_family_parse(NULL, &out) == FESD_ERR_NULL);
  CHECK(fesd_rk_family_parse("radau", NULL) == FESD_ERR_NULL);

  printf("%s (%d failures)\n", failures ? "FAILED" : "PASSED", failures);
  return failures ? 1 : 0;
}
