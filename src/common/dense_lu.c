/* Small dense LU (shared by the dense backend of src/ncp and the stage Newton of the
 * integrator's guess). */
#include "common/dense_lu.h"

#include <math.h>
#include <stddef.h>

/* Right-looking LU with partial pivoting, column-major; 0-based pivots.
 * Returns k+1 when column k has no nonzero pivot (as dgetrf's info). */
int fesd__dense_lu(int n, double *a, int *piv) {
  for (int k = 0; k < n; k++) {
    double *ck = a + (size_t)k * n, big = fabs(ck[k]);
    int p = k;
    for (int i = k + 1; i < n; i++)
      if (fabs(ck[i]) > big) {
        big = fabs(ck[i]);
        p = i;
      }
    piv[k] = p;
    if (big == 0.0) return k + 1;
    if (p != k)
      for (int j = 0; j < n; j++) {
        double t = a[k + (size_t)j * n];
        a[k + (size_t)j * n] = a[p + (size_t)j * n];
        a[p + (size_t)j * n] = t;
      }
    const double inv = 1.0 / ck[k];
    for (int i = k + 1; i < n; i++) ck[i] *= inv;
    for (int j = k + 1; j < n; j++) {
      double *cj = a + (size_t)j * n, f = cj[k];
      if (f != 0.0)
        for (int i = k + 1; i < n; i++) cj[i] -= f * ck[i];
    }
  }
  return 0;
}

void fesd__dense_lu_solve(int n, const double *a, const int *piv, double *x) {
  for (int k = 0; k < n; k++)
    if (piv[k] != k) {
      double t = x[k];
      x[k] = x[piv[k]];
      x[piv[k]] = t;
    }
  for (int k = 0; k < n; k++) { /* L y = P b, unit diagonal */
    const double *ck = a + (size_t)k * n, xk = x[k];
    for (int i = k + 1; i < n; i++) x[i] -= ck[i] * xk;
  }
  for (int k = n - 1; k >= 0; k--) { /* U x = y */
    const double *ck = a + (size_t)k * n;
    x[k] /= ck[k];
    const double xk = x[k];
    for (int i = 0; i < k; i++) x[i] -= ck[i] * xk;
  }
}

