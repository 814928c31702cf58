/* Fischer-Burmeister function, inlined into the assembly loops (internal). */
#ifndef FESD_NCP_FB_H
#define FESD_NCP_FB_H

#include <math.h>

/* 1 - 1/sqrt(2): an element of the generalized gradient at a = b = 0, sigma = 0. */
#define FESD__FB_KINK 0.29289321881345247560

/* phi_sigma(a,b) = a + b - sqrt(a^2 + b^2 + 2 sigma) and its partial derivatives.
 * For a + b > 0 the difference a + b - r cancels; use the identity
 * (a + b)^2 - r^2 = 2(ab - sigma) instead. Huge and tiny arguments are scaled so
 * that a^2 can neither overflow nor underflow. */
static inline double fesd__fb(double a, double b, double sigma, double *da, double *db) {
  double s = fmax(fabs(a), fabs(b));
  double phi, r;
  if (s > 1e150 || (s < 1e-150 && s > 0.0)) {
    double as = a / s, bs = b / s, ss = 2.0 * sigma / s / s;
    double rs = sqrt(as * as + bs * bs + ss);
    r = s * rs;
    phi = (as + bs > 0.0) ? s * ((2.0 * as * bs - ss) / (as + bs + rs)) : (a + b) - r;
  } else {
    r = sqrt(a * a + b * b + 2.0 * sigma);
    phi = (a + b > 0.0) ? 2.0 * (a * b - sigma) / (a + b + r) : (a + b) - r;
  }
  if (r > 0.0) {
    *da = 1.0 - a / r;
    *db = 1.0 - b / r;
  } else {
    *da = FESD__FB_KINK;
    *db = FESD__FB_KINK;
  }
  return phi;
}

#endif
