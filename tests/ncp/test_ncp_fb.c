/* fesd_fb: accuracy against a long-double reference (no cancellation where
 * a + b - r nearly cancels), derivatives against central differences, the kink
 * element at a = b = sigma = 0, huge arguments, and the smoothed zero set. */
#include "ncp_test_util.h"

/* long double, in the cancellation-free form as well (the plain form loses ~16 digits
 * at a = 1e8, b = 1e-8 even in extended precision) */
static long double fb_ref(long double a, long double b, long double s) {
  long double r = sqrtl(a * a + b * b + 2.0L * s);
  return a + b > 0 ? 2.0L * (a * b - s) / (a + b + r) : a + b - r;
}

int main(void) {
  printf("Fischer-Burmeister function\n");
  /* relative accuracy where phi is tiny compared with a and b */
  const double cases[][3] = {{1e8, 1e-8, 0}, {1.0, 1e-12, 0}, {3.0, 4.0, 0}, {1e-3, 2e-3, 1e-7},
                             {5.0, 5.0, 25.0}, {-1.0, 2.0, 0}, {-3.0, -4.0, 0}, {0.0, 7.0, 0},
                             {1e-200, 1e-200, 0}, {2.0, 0.5, 0.5}};
  double worst = 0.0;
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    double a = cases[k][0], b = cases[k][1], s = cases[k][2];
    long double ref = fb_ref(a, b, s);
    double phi = fesd_fb(a, b, s, NULL, NULL);
    double rel = ref != 0.0L ? (double)fabsl((phi - ref) / ref) : fabs(phi);
    worst = fmax(worst, rel);
    CHECK(rel <= 4e-16, "phi(%g, %g, %g) = %.17g, reference %.17Lg (rel %.1e)", a, b, s, phi, ref,
          rel);
  }
  printf("  max relative error vs long double: %.1e\n", worst);
  /* the naive formula loses everything here; ours keeps full precision */
  double tiny = fesd_fb(1e8, 1e-8, 0.0, NULL, NULL);
  CHECK(fabs(tiny - 1e-8) <= 1e-23, "phi(1e8, 1e-8) = %.17g, want ~1e-8", tiny);

  /* derivatives */
  double dmax = 0.0;
  rng_t r = {11};
  for (int k = 0; k < 200; k++) {
    double a = 4 * rng_sym(&r), b = 4 * rng_sym(&r), s = k % 2 ? 0.0 : rng_uniform(&r), da, db;
    if (fabs(a) + fabs(b) < 1e-3 && s == 0.0) continue;
    fesd_fb(a, b, s, &da, &db);
    double h = 1e-6;
    double fa = (fesd_fb(a + h, b, s, NULL, NULL) - fesd_fb(a - h, b, s, NULL, NULL)) / (2 * h);
    double fb = (fesd_fb(a, b + h, s, NULL, NULL) - fesd_fb(a, b - h, s, NULL, NULL)) / (2 * h);
    dmax = fmax(dmax, fmax(fabs(fa - da), fabs(fb - db)));
  }
  printf("  derivatives vs central differences: max error %.1e\n", dmax);
  CHECK(dmax <= 1e-7, "derivative error %.2e", dmax);

  /* kink: (1 - 1/sqrt2, 1 - 1/sqrt2) at a = b = sigma = 0 */
  double da, db, p0 = fesd_fb(0.0, 0.0, 0.0, &da, &db);
  CHECK(p0 == 0.0 && fabs(da - (1 - 1 / sqrt(2.0))) < 1e-16 && fabs(db - da) == 0.0,
        "kink element (%g, %g)", da, db);
  /* huge arguments: no overflow */
  double big = fesd_fb(1e300, 1e300, 0.0, &da, &db);
  CHECK(isfinite(big) && fabs(big - (2.0 - sqrt(2.0)) * 1e300) <= 1e285 && isfinite(da),
        "phi(1e300, 1e300) = %g", big);
  CHECK(fesd_fb(1e300, 0.0, 0.0, NULL, NULL) == 0.0, "phi(1e300, 0) = 0");
  CHECK(fesd_fb(-1e300, 1e300, 0.0, NULL, NULL) < 0.0, "phi(-1e300, 1e300) < 0");
  /* zero set: a, b >= 0, a b = sigma */
  CHECK(fabs(fesd_fb(2.0, 0.25, 0.5, NULL, NULL)) <= 1e-16 && fesd_fb(2.0, 0.0, 0.0, NULL, NULL) == 0.0 &&
            fesd_fb(-2.0, 0.0, 0.0, NULL, NULL) < 0.0 && fesd_fb(0.5, 0.5, 0.0, NULL, NULL) > 0.0,
        "zero set");
  return test_summary("test_ncp_fb");
}
