/* Acceptance test 1: simplifying / order conditions of every tableau.
 *
 * For every family and s (explicit 1..4, Lobatto 2..12, others 1..12) the
 * conditions the family is known to satisfy (see rk_known_conditions in
 * rk_test_util.h) are checked, plus the 8 rooted-tree order conditions up to
 * order min(p,4):
 *   Gauss-Legendre B(2s) C(s) D(s);  Radau IIA B(2s-1) C(s) D(s-1);
 *   Lobatto IIIA B(2s-2) C(s) D(s-2); Lobatto IIIC B(2s-2) C(s-1) D(s-1);
 *   explicit B(s) C(1) and all rooted trees of order <= s.
 * Tolerance 1e-13 for s <= 9, TOL_HIGH for s = 10..12.
 * Exactness of the order: B(p+1) must FAIL by more than 1e-8 (for explicit
 * p <= 3 some rooted-tree condition of order p+1 must fail instead, since
 * Kutta's 3rd-order method satisfies B(4)). The monomial residual
 * sum b_i c_i^p - 1/(p+1) is the quadrature error of x^p, which is
 * intrinsically tiny at high s (Gauss s=9: (s!)^4/((2s+1)((2s)!)^2) = 2.2e-11,
 * Gauss s=12: 5.5e-15), so the fixed 1e-8 margin is applied to the
 * equivalent centred form: given B(p), B(p+1) holds iff the rule integrates
 * (2x-1)^p exactly, and that error is 2^p times larger (Gauss s=12: 9e-8)
 * while its round-off stays ~1e-16 (|2c-1| <= 1). Both values are printed.
 * Also checks the flags: order == fesd_rk_order == 2s-1/2s/2s-2/s,
 * c_end_is_one == (c_s == 1), stiffly_accurate per family with the last row
 * of A bit-identical to b, is_explicit == strictly lower triangular A,
 * c_1 == 0 exactly (Lobatto, explicit), c_s == 1 exactly (Radau, Lobatto). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rk_test_util.h"

#define TOL 1e-13
#define TOL_HIGH 1e-13 /* measured: the same ~3e-16 as for s <= 9 */
#define FAIL_MARGIN 1e-8

static int failures = 0;

static void check(int ok, const char *what, const char *fam, int s, double val) {
  if (!ok) {
    ++failures;
    printf("FAIL %-9s s=%2d: %s (value %.3e)\n", fam, s, what, val);
  }
}

/* |sum_i b_i (2c_i-1)^p - int_0^1 (2x-1)^p dx|, int = (1 + (-1)^p) / (2(p+1)). */
static double centred_beyond(const fesd_tableau *t, int p) {
  long double sum = 0.0L;
  for (int i = 0; i < t->s; ++i) sum += (long double)t->b[i] * rk_powl(2.0L * t->c[i] - 1.0L, p);
  long double exact = (p % 2 == 0) ? 1.0L / (p + 1) : 0.0L;
  return (double)fabsl(sum - exact);
}

static int expected_order(fesd_rk_family f, int s) {
  switch (f) {
  case FESD_RK_RADAU_IIA: return 2 * s - 1;
  case FESD_RK_GAUSS_LEGENDRE: return 2 * s;
  case FESD_RK_EXPLICIT: return s;
  default: return 2 * s - 2;
  }
}

int main(void) {
  double worst_low[FESD_RK_NUM_FAMILIES] = {0}, worst_high[FESD_RK_NUM_FAMILIES] = {0};
  printf("%-9s %2s %3s %10s %10s %10s %10s %10s %10s\n", "family", "s", "p", "B(p)", "C(q)", "D(r)",
         "trees", "B(p+1)", "beyond");
  for (int fi = 0; fi < FESD_RK_NUM_FAMILIES; ++fi) {
    fesd_rk_family f = rk_all_families[fi];
    const char *fam = fesd_rk_family_name(f);
    for (int s = rk_min_stages(f); s <= rk_max_stages(f); ++s) {
      fesd_tableau t;
      int rc = fesd_tableau_get(f, s, &t);
      check(rc == FESD_OK, "fesd_tableau_get failed", fam, s, rc);
      if (rc != FESD_OK) continue;

      /* structure and flags */
      int p_exp = expected_order(f, s);
      check(t.family == f && t.s == s, "family/s fields", fam, s, 0);
      check(t.order == p_exp && fesd_rk_order(f, s) == p_exp, "order", fam, s, t.order);
      check(t.c_end_is_one == (t.c[s - 1] == 1.0), "c_end_is_one flag", fam, s, t.c[s - 1]);
      if (f == FESD_RK_RADAU_IIA || f == FESD_RK_LOBATTO_IIIA || f == FESD_RK_LOBATTO_IIIC)
        check(t.c[s - 1] == 1.0 && t.c_end_is_one, "c_s == 1 exactly", fam, s, t.c[s - 1]);
      if (f == FESD_RK_GAUSS_LEGENDRE) check(!t.c_end_is_one, "Gauss c_s < 1", fam, s, 0);
      if (f == FESD_RK_LOBATTO_IIIA || f == FESD_RK_LOBATTO_IIIC || f == FESD_RK_EXPLICIT)
        check(t.c[0] == 0.0, "c_1 == 0 exactly", fam, s, t.c[0]);
      int sa_expected = (f != FESD_RK_GAUSS_LEGENDRE && f != FESD_RK_EXPLICIT);
      check(t.stiffly_accurate == sa_expected, "stiffly_accurate flag", fam, s, 0);
      if (sa_expected)
        check(memcmp(t.A[s - 1], t.b, (size_t)s * sizeof(double)) == 0,
              "last row of A bit-identical to b", fam, s, 0);
      int lower = 1;
      for (int i = 0; i < s; ++i)
        for (int j = i; j < s; ++j) lower &= (t.A[i][j] == 0.0);
      check(t.is_explicit == (f == FESD_RK_EXPLICIT) && t.is_explicit == lower, "is_explicit",
            fam, s, 0);
      for (int i = 1; i < s; ++i) /* RK4 has c_2 == c_3 */
        check(t.c[i] > t.c[i - 1] || (t.is_explicit && t.c[i] == t.c[i - 1]), "nodes increasing",
              fam, s, t.c[i]);

      /* known conditions */
      int p, q, r;
      rk_known_conditions(f, s, &p, &q, &r);
      double rb = rk_resid_B(&t, p), rcq = rk_resid_C(&t, q), rd = rk_resid_D(&t, r);
      double by_order[5];
      double rt = rk_resid_trees(&t, p < 4 ? p : 4, by_order);
      double worst = fmax(fmax(rb, rcq), fmax(rd, rt));
      double tol = s <= 9 ? TOL : TOL_HIGH;
      check(worst <= tol, "known conditions residual above tolerance", fam, s, worst);
      if (s <= 9) worst_low[fi] = fmax(worst_low[fi], worst);
      else worst_high[fi] = fmax(worst_high[fi], worst);

      /* order exactly p: a condition of order p+1 fails */
      double beyond = centred_beyond(&t, p);
      if (f == FESD_RK_EXPLICIT && p <= 3) beyond = fmax(beyond, by_order[p + 1]);
      check(beyond > FAIL_MARGIN, "order p+1 condition unexpectedly satisfied", fam, s, beyond);

      printf("%-9s %2d %3d %10.2e %10.2e %10.2e %10.2e %10.2e %10.2e\n", fam, s, p, rb, rcq, rd,
             rt, fabs((double)rk_resid_B1(&t, p + 1)), beyond);
    }
  }
  printf("\nmax residual of the known conditions per family:\n");
  for (int fi = 0; fi < FESD_RK_NUM_FAMILIES; ++fi) {
    fesd_rk_family f = rk_all_families[fi];
    if (f == FESD_RK_EXPLICIT)
      printf("  %-9s s=1..4: %.2e\n", fesd_rk_family_name(f), worst_low[fi]);
    else
      printf("  %-9s s<=9: %.2e   s=10..12: %.2e\n", fesd_rk_family_name(f), worst_low[fi],
             worst_high[fi]);
  }
  printf("%s (%d failures)\n", failures ? "FAILED" : "PASSED", failures);
  return failures ? 1 : 0;
}
