/* rk_table: print the Butcher tableaus of libfesd for s = 1..4, one line per
 * (family, s): order, c_s, stiffly accurate, and the largest residual of the
 * order/simplifying conditions the family satisfies
 *   Gauss B(2s) C(s) D(s), Radau IIA B(2s-1) C(s) D(s-1),
 *   Lobatto IIIA B(2s-2) C(s) D(s-2), Lobatto IIIC B(2s-2) C(s-1) D(s-1),
 *   explicit B(s) C(1)
 * (tests/rk also checks the rooted-tree order conditions and the stability function).
 * Usage: rk_table [-v]   (-v also prints each tableau) */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fesd_rk.h"

static double ipow(double x, int k) {
  double r = 1.0;
  while (k-- > 0) r *= x;
  return r;
}

/* max residual of B(p), C(q), D(r) */
static double bcd_residual(const fesd_tableau *t, int p, int q, int r) {
  const int s = t->s;
  double m = 0.0;
  for (int k = 1; k <= p; ++k) {
    double sum = 0.0;
    for (int i = 0; i < s; ++i) sum += t->b[i] * ipow(t->c[i], k - 1);
    m = fmax(m, fabs(sum - 1.0 / k));
  }
  for (int k = 1; k <= q; ++k)
    for (int i = 0; i < s; ++i) {
      double sum = 0.0;
      for (int j = 0; j < s; ++j) sum += t->A[i][j] * ipow(t->c[j], k - 1);
      m = fmax(m, fabs(sum - ipow(t->c[i], k) / k));
    }
  for (int k = 1; k <= r; ++k)
    for (int j = 0; j < s; ++j) {
      double sum = 0.0;
      for (int i = 0; i < s; ++i) sum += t->b[i] * ipow(t->c[i], k - 1) * t->A[i][j];
      m = fmax(m, fabs(sum - t->b[j] * (1.0 - ipow(t->c[j], k)) / k));
    }
  return m;
}

static void known_conditions(const fesd_tableau *t, int *p, int *q, int *r) {
  const int s = t->s;
  switch (t->family) {
  case FESD_RK_GAUSS_LEGENDRE: *p = 2 * s, *q = s, *r = s; break;
  case FESD_RK_RADAU_IIA: *p = 2 * s - 1, *q = s, *r = s - 1; break;
  case FESD_RK_LOBATTO_IIIA: *p = 2 * s - 2, *q = s, *r = s - 2; break;
  case FESD_RK_LOBATTO_IIIC: *p = 2 * s - 2, *q = s - 1, *r = s - 1; break;
  default: *p = s, *q = 1, *r = 0; break;
  }
}

static void print_tableau(const fesd_tableau *t) {
  for (int i = 0; i < t->s; ++i) {
    printf("    %10.6f |", t->c[i]);
    for (int j = 0; j < t->s; ++j) printf(" %10.6f", t->A[i][j]);
    printf("\n");
  }
  printf("    %10s |", "");
  for (int j = 0; j < t->s; ++j) printf(" %10.6f", t->b[j]);
  printf("\n\n");
}

int main(int argc, char **argv) {
  int verbose = argc > 1 && strcmp(argv[1], "-v") == 0;
  printf("%-10s %2s %5s %10s %8s %9s %14s\n", "family", "s", "order", "c_s", "stiffly", "explicit",
         "max residual");
  for (int f = 0; f < FESD_RK_NUM_FAMILIES; ++f) {
    for (int s = 1; s <= 4; ++s) {
      fesd_tableau t;
      int rc = fesd_tableau_get((fesd_rk_family)f, s, &t);
      if (rc == FESD_ERR_UNSUPPORTED_TABLEAU) continue; /* Lobatto s = 1 */
      if (rc != FESD_OK) {
        fprintf(stderr, "%s s=%d: %s\n", fesd_rk_family_name((fesd_rk_family)f), s,
                fesd_status_string(rc));
        return 1;
      }
      int p, q, r;
      known_conditions(&t, &p, &q, &r);
      printf("%-10s %2d %5d %10.6f %8s %9s %14.2e\n", fesd_rk_family_name(t.family), s, t.order,
             t.c[s - 1], t.stiffly_accurate ? "yes" : "no", t.is_explicit ? "yes" : "no",
             bcd_residual(&t, p, q, r));
      if (verbose) print_tableau(&t);
    }
  }
  return 0;
}
