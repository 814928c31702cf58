/* Public Fischer-Burmeister function. */
#include "fesd_ncp.h"
#include "ncp/fb.h"

double fesd_fb(double a, double b, double sigma, double *da, double *db) {
  double ga, gb;
  double phi = fesd__fb(a, b, sigma, &ga, &gb);
  if (da) *da = ga;
  if (db) *db = gb;
  return phi;
}
