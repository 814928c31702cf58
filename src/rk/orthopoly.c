/* Zeros of shifted Jacobi polynomials and Gauss-Legendre rules on [0,1]. */
#include <math.h>

#include "common/lapack.h"
#include "rk_internal.h"

/* Monic recurrence coefficients on [0,1] for the weight (1-x)^a x^b:
 *   p_{k+1}(x) = (x - ak[k]) p_k(x) - bk[k] p_{k-1}(x),  k = 0..n-1.
 * Obtained from the classical Jacobi coefficients on [-1,1] (weight
 * (1-t)^a (1+t)^b; Gautschi, "Orthogonal polynomials", Table 1.1) under
 * x = (1+t)/2:  ak = (1 + alpha_k)/2,  bk = beta_k / 4. bk[0] is unused. */
static void jacobi_recurrence01(int n, double a, double b, double *ak, double *bk) {
  for (int k = 0; k < n; ++k) {
    double alpha_k = 0.0;
    if (a != b) {
      double t = 2.0 * k + a + b;
      alpha_k = (b * b - a * a) / (t * (t + 2.0));
    }
    ak[k] = 0.5 * (1.0 + alpha_k);
    bk[k] = 0.0;
    if (k >= 1) {
      double t = 2.0 * k + a + b;
      double beta_k = 4.0 * k * (k + a) * (k + b) * (k + a + b) /
                      (t * t * (t + 1.0) * (t - 1.0));
      bk[k] = 0.25 * beta_k;
    }
  }
}

/* p_n(x) and p_n'(x) by the monic three-term recurrence. */
static void eval_monic(int n, const double *ak, const double *bk, double x, double *p,
                       double *dp) {
  double pm = 0.0, p0 = 1.0, dpm = 0.0, dp0 = 0.0;
  for (int k = 0; k < n; ++k) {
    double p1 = (x - ak[k]) * p0 - bk[k] * pm;
    double dp1 = p0 + (x - ak[k]) * dp0 - bk[k] * dpm;
    pm = p0;
    p0 = p1;
    dpm = dp0;
    dp0 = dp1;
  }
  *p = p0;
  *dp = dp0;
}

/* Zeros by simultaneous Newton with deflation (Aberth-Ehrlich) from Chebyshev points, in
 * ascending order. Why not only the eigensolver: at n = 4 LAPACK's dstev with its
 * machine-constant queries costs ~15k instructions, this ~2k, and every fesd_create builds two
 * tableaus. The iteration converges cubically: it stops after the sweep whose steps are all
 * below 1e-9 (the next would be at round-off; the caller's Newton polishing finishes). Returns 0
 * unless it stopped so, the zeros, sorted, are distinct inside (0, 1) and their sum is the
 * trace of the Jacobi matrix, sum ak (two starts on one zero would leave another out); the
 * caller then uses the eigensolver. */
static int aberth_zeros(int n, const double *ak, const double *bk, double *x) {
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < n; ++i) x[i] = 0.5 - 0.5 * cos(pi * (i + 0.5) / n);
  int done = 0;
  for (int it = 0; it < 40 && !done; ++it) {
    done = 1;
    for (int i = 0; i < n; ++i) {
      double p, dp, sum = 0.0;
      eval_monic(n, ak, bk, x[i], &p, &dp);
      for (int j = 0; j < n; ++j)
        if (j != i) sum += 1.0 / (x[i] - x[j]);
      const double r = p / dp, d = r / (1.0 - r * sum);
      if (!isfinite(d)) return 0;
      x[i] -= d;
      if (fabs(d) > 1e-9) done = 0;
    }
  }
  if (!done) return 0;
  for (int i = 1; i < n; ++i) /* the set converges, not each start to its neighbour */
    for (int j = i; j > 0 && x[j] < x[j - 1]; --j) {
      const double t = x[j];
      x[j] = x[j - 1];
      x[j - 1] = t;
    }
  double sx = 0.0, sa = 0.0;
  for (int i = 0; i < n; ++i) sx += x[i], sa += ak[i];
  for (int i = 0; i + 1 < n; ++i)
    if (!(x[i] < x[i + 1])) return 0;
  return x[0] > 0.0 && x[n - 1] < 1.0 && fabs(sx - sa) <= 1e-8;
}

/* Golub-Welsch: the zeros are the eigenvalues of the symmetric tridiagonal Jacobi matrix with
 * diagonal ak and off-diagonal sqrt(bk[1..n-1]) (LAPACK dstev, ascending). */
static int eigen_zeros(int n, const double *ak, const double *bk, double *x) {
  double e[FESD_RK_MAX_STAGES], zdummy[1], wdummy[1];
  for (int k = 0; k < n; ++k) x[k] = ak[k];
  for (int k = 0; k + 1 < n; ++k) e[k] = sqrt(bk[k + 1]);
  int info = 0, ldz = 1;
  dstev_("N", &n, x, e, zdummy, &ldz, wdummy, &info, 1);
  return info == 0 ? FESD_OK : FESD_ERR_LINSOLVE;
}

int fesd__jacobi_zeros01_by(int n, double alpha, double beta, int eigen, double *x) {
  if (n <= 0) return FESD_OK;
  double ak[FESD_RK_MAX_STAGES], bk[FESD_RK_MAX_STAGES];
  jacobi_recurrence01(n, alpha, beta, ak, bk);
  if (eigen || !aberth_zeros(n, ak, bk, x)) {
    int rc = eigen_zeros(n, ak, bk, x);
    if (rc != FESD_OK) return rc;
  }

  /* Newton polishing: either way the zeros are accurate to ~ eps already,
   * so a step is tiny; a large step would mean a wrong branch and is refused. */
  for (int i = 0; i < n; ++i) {
    double xi = x[i];
    for (int it = 0; it < 4; ++it) {
      double p, dp;
      eval_monic(n, ak, bk, xi, &p, &dp);
      if (dp == 0.0 || !isfinite(p) || !isfinite(dp)) break;
      double dx = p / dp;
      if (!(fabs(dx) < 1e-8)) break;
      xi -= dx;
      if (fabs(dx) <= 0x1p-53 * fabs(xi)) break;
    }
    x[i] = xi;
  }

  /* Symmetric weight: zeros symmetric about 1/2. Keep the lower half and
   * mirror it (1 - x is exact for x in [1/2,1], nearly so below). */
  if (alpha == beta) {
    for (int i = 0; i < n / 2; ++i) x[n - 1 - i] = 1.0 - x[i];
    if (n % 2 == 1) x[n / 2] = 0.5;
  }
  return FESD_OK;
}

int fesd__jacobi_zeros01(int n, double alpha, double beta, double *x) {
  return fesd__jacobi_zeros01_by(n, alpha, beta, 0, x);
}

int fesd__gauss_legendre01(int n, double *x, double *w) {
  int rc = fesd__jacobi_zeros01(n, 0.0, 0.0, x);
  if (rc != FESD_OK) return rc;
  /* Orthonormal Legendre on [0,1] (unit total mass): p_0 = 1,
   * sq_{k+1} p_{k+1} = (x - 1/2) p_k - sq_k p_{k-1},  sq_k = k / (2 sqrt(4k^2-1)). */
  double sq[FESD_RK_MAX_STAGES + 1];
  sq[0] = 0.0;
  for (int k = 1; k <= n; ++k) sq[k] = 0.5 * k / sqrt(4.0 * k * k - 1.0);
  for (int i = 0; i < n; ++i) {
    double pm = 0.0, p0 = 1.0, sum = 1.0;
    for (int k = 0; k + 1 < n; ++k) {
      double p1 = ((x[i] - 0.5) * p0 - sq[k] * pm) / sq[k + 1];
      pm = p0;
      p0 = p1;
      sum += p1 * p1;
    }
    w[i] = 1.0 / sum;
  }
  /* Symmetric rule: make the weights exactly symmetric too. */
  for (int i = 0; i < n / 2; ++i) w[n - 1 - i] = w[i];
  return FESD_OK;
}
