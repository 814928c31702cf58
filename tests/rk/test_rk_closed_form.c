/* Acceptance test 2: the computed tableaus agree to 1e-14 (max abs entry
 * difference over A, b, c) with closed-form tableaus typed in HERE (the
 * library computes them): Radau IIA s=1,2,3; Gauss s=1,2; Lobatto IIIA s=2,3;
 * Lobatto IIIC s=2,3; explicit Euler, Heun, Kutta-3, RK4. Unused entries
 * (index >= s) must be zero. */
#include <math.h>
#include <stdio.h>

#include "fesd_rk.h"
#include "rk/rk_internal.h"

#define TOL 1e-14
#define S_MAX 4

typedef struct {
  const char *label;
  fesd_rk_family family;
  int s;
  double c[S_MAX], b[S_MAX], A[S_MAX][S_MAX];
} reference;

static int compare(const reference *ref) {
  fesd_tableau t;
  int rc = fesd_tableau_get(ref->family, ref->s, &t);
  if (rc != FESD_OK) {
    printf("FAIL %-24s fesd_tableau_get returned %d\n", ref->label, rc);
    return 1;
  }
  double d = 0.0, outside = 0.0;
  for (int i = 0; i < FESD_RK_MAX_STAGES; ++i) {
    if (i < ref->s) {
      d = fmax(d, fabs(t.c[i] - ref->c[i]));
      d = fmax(d, fabs(t.b[i] - ref->b[i]));
    } else {
      outside = fmax(outside, fmax(fabs(t.c[i]), fabs(t.b[i])));
    }
    for (int j = 0; j < FESD_RK_MAX_STAGES; ++j) {
      if (i < ref->s && j < ref->s) d = fmax(d, fabs(t.A[i][j] - ref->A[i][j]));
      else outside = fmax(outside, fabs(t.A[i][j]));
    }
  }
  int ok = d <= TOL && outside == 0.0;
  printf("%s %-24s max |diff| = %.2e%s\n", ok ? "ok  " : "FAIL", ref->label, d,
         outside == 0.0 ? "" : "  (nonzero entries beyond s)");
  return !ok;
}

int main(void) {
  const double r6 = sqrt(6.0), r3 = sqrt(3.0);
  const reference refs[] = {
      {"radau s=1 (impl. Euler)", FESD_RK_RADAU_IIA, 1, {1}, {1}, {{1}}},
      {"radau s=2", FESD_RK_RADAU_IIA, 2, {1.0 / 3, 1}, {0.75, 0.25},
       {{5.0 / 12, -1.0 / 12}, {0.75, 0.25}}},
      {"radau s=3", FESD_RK_RADAU_IIA, 3,
       {(4 - r6) / 10, (4 + r6) / 10, 1},
       {(16 - r6) / 36, (16 + r6) / 36, 1.0 / 9},
       {{(88 - 7 * r6) / 360, (296 - 169 * r6) / 1800, (-2 + 3 * r6) / 225},
        {(296 + 169 * r6) / 1800, (88 + 7 * r6) / 360, (-2 - 3 * r6) / 225},
        {(16 - r6) / 36, (16 + r6) / 36, 1.0 / 9}}},
      {"gauss s=1 (midpoint)", FESD_RK_GAUSS_LEGENDRE, 1, {0.5}, {1}, {{0.5}}},
      {"gauss s=2", FESD_RK_GAUSS_LEGENDRE, 2, {0.5 - r3 / 6, 0.5 + r3 / 6}, {0.5, 0.5},
       {{0.25, 0.25 - r3 / 6}, {0.25 + r3 / 6, 0.25}}},
      {"lobatto3a s=2 (trapez.)", FESD_RK_LOBATTO_IIIA, 2, {0, 1}, {0.5, 0.5},
       {{0, 0}, {0.5, 0.5}}},
      {"lobatto3a s=3", FESD_RK_LOBATTO_IIIA, 3, {0, 0.5, 1}, {1.0 / 6, 2.0 / 3, 1.0 / 6},
       {{0, 0, 0}, {5.0 / 24, 1.0 / 3, -1.0 / 24}, {1.0 / 6, 2.0 / 3, 1.0 / 6}}},
      {"lobatto3c s=2", FESD_RK_LOBATTO_IIIC, 2, {0, 1}, {0.5, 0.5}, {{0.5, -0.5}, {0.5, 0.5}}},
      {"lobatto3c s=3", FESD_RK_LOBATTO_IIIC, 3, {0, 0.5, 1}, {1.0 / 6, 2.0 / 3, 1.0 / 6},
       {{1.0 / 6, -1.0 / 3, 1.0 / 6}, {1.0 / 6, 5.0 / 12, -1.0 / 12}, {1.0 / 6, 2.0 / 3, 1.0 / 6}}},
      {"erk s=1 (expl. Euler)", FESD_RK_EXPLICIT, 1, {0}, {1}, {{0}}},
      {"erk s=2 (Heun)", FESD_RK_EXPLICIT, 2, {0, 1}, {0.5, 0.5}, {{0, 0}, {1, 0}}},
      {"erk s=3 (Kutta-3)", FESD_RK_EXPLICIT, 3, {0, 0.5, 1}, {1.0 / 6, 2.0 / 3, 1.0 / 6},
       {{0, 0, 0}, {0.5, 0, 0}, {-1, 2, 0}}},
      {"erk s=4 (classic RK4)", FESD_RK_EXPLICIT, 4, {0, 0.5, 0.5, 1},
       {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6},
       {{0, 0, 0, 0}, {0.5, 0, 0, 0}, {0, 0.5, 0, 0}, {0, 0, 1, 0}}},
  };
  int failures = 0;
  for (size_t k = 0; k < sizeof refs / sizeof refs[0]; ++k) failures += compare(&refs[k]);
  /* The nodes of every s: the Aberth-Ehrlich path against Golub-Welsch (LAPACK's eigensolver,
   * the fallback), both polished by the same Newton steps on the recurrence. */
  const double wts[3][2] = {{0, 0}, {1, 0}, {1, 1}}; /* Gauss, Radau, Lobatto interiors */
  double worst = 0;
  for (int w = 0; w < 3; ++w)
    for (int n = 1; n <= FESD_RK_MAX_STAGES; ++n) {
      double xa[FESD_RK_MAX_STAGES], xe[FESD_RK_MAX_STAGES];
      if (fesd__jacobi_zeros01_by(n, wts[w][0], wts[w][1], 0, xa) ||
          fesd__jacobi_zeros01_by(n, wts[w][0], wts[w][1], 1, xe)) {
        printf("FAIL zeros n=%d (%g, %g): a path failed\n", n, wts[w][0], wts[w][1]);
        failures++;
        continue;
      }
      for (int i = 0; i < n; ++i) worst = fmax(worst, fabs(xa[i] - xe[i]));
    }
  printf("Jacobi zeros, Aberth-Ehrlich against Golub-Welsch, n = 1..%d, three weights: max |diff| %.1e (tolerance 1e-15)\n",
         FESD_RK_MAX_STAGES, worst);
  if (!(worst <= 1e-15)) failures++;
  printf("%s (%d failures, tolerance %.0e)\n", failures ? "FAILED" : "PASSED", failures, TOL);
  return failures ? 1 : 0;
}
