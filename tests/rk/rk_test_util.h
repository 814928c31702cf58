/* Helpers shared by the src/rk tests: order-condition residuals evaluated in
 * long double from the (double) tableau entries, so that the residual
 * measures the tableau and not the test's own rounding. */
#ifndef FESD_RK_TEST_UTIL_H
#define FESD_RK_TEST_UTIL_H

#include <math.h>
#include <stdio.h>

#include "fesd_rk.h"

static const fesd_rk_family rk_all_families[FESD_RK_NUM_FAMILIES] = {
    FESD_RK_RADAU_IIA, FESD_RK_GAUSS_LEGENDRE, FESD_RK_LOBATTO_IIIA, FESD_RK_LOBATTO_IIIC,
    FESD_RK_EXPLICIT};

static inline int rk_min_stages(fesd_rk_family f) {
  return (f == FESD_RK_LOBATTO_IIIA || f == FESD_RK_LOBATTO_IIIC) ? 2 : 1;
}
static inline int rk_max_stages(fesd_rk_family f) {
  return f == FESD_RK_EXPLICIT ? 4 : FESD_RK_MAX_STAGES;
}

static inline long double rk_powl(long double x, int k) {
  long double r = 1.0L;
  for (int i = 0; i < k; ++i) r *= x;
  return r;
}

/* B(k) residual: sum_i b_i c_i^{k-1} - 1/k (signed). */
static inline long double rk_resid_B1(const fesd_tableau *t, int k) {
  long double sum = 0.0L;
  for (int i = 0; i < t->s; ++i) sum += (long double)t->b[i] * rk_powl(t->c[i], k - 1);
  return sum - 1.0L / k;
}
/* max_{k<=p} |B(k)| */
static inline double rk_resid_B(const fesd_tableau *t, int p) {
  long double m = 0.0L;
  for (int k = 1; k <= p; ++k) m = fmaxl(m, fabsl(rk_resid_B1(t, k)));
  return (double)m;
}
/* max_{k<=q, i} |sum_j a_ij c_j^{k-1} - c_i^k / k| */
static inline double rk_resid_C(const fesd_tableau *t, int q) {
  long double m = 0.0L;
  for (int k = 1; k <= q; ++k)
    for (int i = 0; i < t->s; ++i) {
      long double sum = 0.0L;
      for (int j = 0; j < t->s; ++j) sum += (long double)t->A[i][j] * rk_powl(t->c[j], k - 1);
      m = fmaxl(m, fabsl(sum - rk_powl(t->c[i], k) / k));
    }
  return (double)m;
}
/* max_{k<=r, j} |sum_i b_i c_i^{k-1} a_ij - b_j (1 - c_j^k) / k| */
static inline double rk_resid_D(const fesd_tableau *t, int r) {
  long double m = 0.0L;
  for (int k = 1; k <= r; ++k)
    for (int j = 0; j < t->s; ++j) {
      long double sum = 0.0L;
      for (int i = 0; i < t->s; ++i)
        sum += (long double)t->b[i] * rk_powl(t->c[i], k - 1) * t->A[i][j];
      m = fmaxl(m, fabsl(sum - (long double)t->b[j] * (1.0L - rk_powl(t->c[j], k)) / k));
    }
  return (double)m;
}

/* The 8 rooted-tree order conditions up to order 4 (Butcher):
 *  1: sum b = 1          2: sum b c = 1/2
 *  3: sum b c^2 = 1/3    3: sum b A c = 1/6
 *  4: sum b c^3 = 1/4    4: sum b c (A c) = 1/8
 *  4: sum b A c^2 = 1/12 4: sum b A A c = 1/24
 * Returns max |residual| over the trees of order <= p (p <= 4); the signed
 * residuals of the trees of order exactly p are stored in by_order[...] when
 * non-NULL (max |.| among the trees of order exactly k in by_order[k]). */
static inline double rk_resid_trees(const fesd_tableau *t, int p, double by_order[5]) {
  const int s = t->s;
  long double Ac[FESD_RK_MAX_STAGES], Ac2[FESD_RK_MAX_STAGES], AAc[FESD_RK_MAX_STAGES];
  for (int i = 0; i < s; ++i) {
    Ac[i] = Ac2[i] = 0.0L;
    for (int j = 0; j < s; ++j) {
      Ac[i] += (long double)t->A[i][j] * t->c[j];
      Ac2[i] += (long double)t->A[i][j] * t->c[j] * t->c[j];
    }
  }
  for (int i = 0; i < s; ++i) {
    AAc[i] = 0.0L;
    for (int j = 0; j < s; ++j) AAc[i] += (long double)t->A[i][j] * Ac[j];
  }
  long double sb = 0, sbc = 0, sbc2 = 0, sbAc = 0, sbc3 = 0, sbcAc = 0, sbAc2 = 0, sbAAc = 0;
  for (int i = 0; i < s; ++i) {
    long double b = t->b[i], c = t->c[i];
    sb += b;
    sbc += b * c;
    sbc2 += b * c * c;
    sbAc += b * Ac[i];
    sbc3 += b * c * c * c;
    sbcAc += b * c * Ac[i];
    sbAc2 += b * Ac2[i];
    sbAAc += b * AAc[i];
  }
  long double r[5];
  r[0] = 0.0L;
  r[1] = fabsl(sb - 1.0L);
  r[2] = fabsl(sbc - 0.5L);
  r[3] = fmaxl(fabsl(sbc2 - 1.0L / 3), fabsl(sbAc - 1.0L / 6));
  r[4] = fmaxl(fmaxl(fabsl(sbc3 - 0.25L), fabsl(sbcAc - 0.125L)),
               fmaxl(fabsl(sbAc2 - 1.0L / 12), fabsl(sbAAc - 1.0L / 24)));
  long double m = 0.0L;
  for (int k = 1; k <= p && k <= 4; ++k) m = fmaxl(m, r[k]);
  if (by_order)
    for (int k = 0; k < 5; ++k) by_order[k] = (double)r[k];
  return (double)m;
}

/* Simplifying conditions each family is known to satisfy (p = order):
 *   Gauss-Legendre   B(2s)   C(s)    D(s)
 *   Radau IIA        B(2s-1) C(s)    D(s-1)
 *   Lobatto IIIA     B(2s-2) C(s)    D(s-2)
 *   Lobatto IIIC     B(2s-2) C(s-1)  D(s-1)
 *   explicit (s<=4)  B(s)    C(1)    D(0)   (+ the rooted trees up to order s) */
static inline void rk_known_conditions(fesd_rk_family f, int s, int *p, int *q, int *r) {
  switch (f) {
  case FESD_RK_GAUSS_LEGENDRE: *p = 2 * s; *q = s; *r = s; break;
  case FESD_RK_RADAU_IIA: *p = 2 * s - 1; *q = s; *r = s - 1; break;
  case FESD_RK_LOBATTO_IIIA: *p = 2 * s - 2; *q = s; *r = s - 2; break;
  case FESD_RK_LOBATTO_IIIC: *p = 2 * s - 2; *q = s - 1; *r = s - 1; break;
  default: *p = s; *q = 1; *r = 0; break;
  }
}

/* Max residual of all the conditions the family is known to satisfy. */
static inline double rk_max_condition_residual(const fesd_tableau *t) {
  int p, q, r;
  rk_known_conditions(t->family, t->s, &p, &q, &r);
  double m = fmax(rk_resid_B(t, p), fmax(rk_resid_C(t, q), rk_resid_D(t, r)));
  return fmax(m, rk_resid_trees(t, t->order < 4 ? t->order : 4, NULL));
}

#endif
