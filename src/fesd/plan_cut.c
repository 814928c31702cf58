/* Where a step's plan is cut into sub-steps, and the bookkeeping of failing plans (retreat to
 * fewer new switches, cycle signatures, the number of switching subsystems): the decisions the
 * step takes about a plan as a whole (plan.c builds and corrects the plan itself). */
#include <math.h>

#include "fesd/step.h"

/* A sub-step ends in a gap between switches at least this fraction of the widest one. */
#define CUT_GAP 0.1

/* Where a sub-step ends between two predicted switches at ta < tb of a (sub)step of length T:
 * the dyadic fraction T k / 2^m with the smallest m in the middle half of (ta, tb). The
 * predictions move smoothly with the step's start state and controls; a cut that followed them
 * (the midpoint) would make the step map depend on them through the sub-step lengths, a term
 * the sensitivities of the sub-steps do not contain (measured: dx/dx0 off by 5e-5 from
 * differences of the map, Radau IIA s = 2, an entry and an exit in one step of 0.67). The
 * dyadic point is constant while the middle half does not reach another one. */
static double dyadic_cut(double ta, double tb, double T) {
  const double a = (ta + 0.25 * (tb - ta)) / T, b = (tb - 0.25 * (tb - ta)) / T;
  for (int m = 1; m <= 52; m++) {
    const double k = ceil(ldexp(a, m)), c = ldexp(k, -m);
    if (c < b) return T * c;
  }
  return 0.5 * (ta + tb);
}

double fesd__plan_cut(fesd_integrator *it, int n_max) {
  fesd__plan_sort(it);
  if (it->n_plan <= n_max) return it->sys.T;
  /* the last gap at least CUT_GAP times the widest one: a cut inside a cluster of nearly
   * simultaneous switches leaves out a member whose predicted time may be off by more than
   * the gap, and the plan solve fails (stick-slip chain, n = 128: four masses within 2.5 us,
   * the sub-step ended 0.5 us after the third; n = 512: a cluster of 17 within 20 us was cut
   * into, and failed, in one sub-step after another) */
  double widest = 0;
  for (int r = 1; r <= n_max; r++) widest = fmax(widest, it->plan[r].t - it->plan[r - 1].t);
  int q = n_max;
  while (q > 1 && it->plan[q].t - it->plan[q - 1].t < CUT_GAP * widest) q--;
  return dyadic_cut(q > 0 ? it->plan[q - 1].t : 0.0, it->plan[q].t, it->sys.T);
}

unsigned long fesd__plan_signature(fesd_integrator *it) {
  fesd__plan_sort(it);
  /* FNV-1a over subsystem, mode, kind and time (in units of 1e-6 T: a cycle repeats its
   * plans up to round-off, progress moves the times) of each switch */
  unsigned long h = 1469598103934665603ul;
  const double unit = 1e-6 * it->sys.T;
  for (int e = 0; e < it->n_plan; e++) {
    const unsigned long w[4] = {(unsigned long)it->plan[e].sys, (unsigned long)it->plan[e].mode,
                                (unsigned long)it->plan[e].exit, (unsigned long)lround(it->plan[e].t / unit)};
    for (int i = 0; i < 4; i++) h = (h ^ w[i]) * 1099511628211ul;
  }
  return h ^ (unsigned long)it->n_plan;
}

int fesd__plan_subsystems(const fesd_integrator *it) {
  int count = 0;
  for (int e = 0; e < it->n_plan; e++) {
    int seen = 0;
    for (int q = 0; q < e && !seen; q++) seen = it->plan[q].sys == it->plan[e].sys;
    count += !seen;
  }
  return count;
}

int fesd__plan_retreat(fesd_integrator *it) {
  int nf = 0;
  for (int e = 0; e < it->n_plan; e++) nf += it->plan[e].fresh;
  if (nf < 2) return 0;
  fesd__plan_sort(it);
  /* keep the earlier half of the fresh switches (at least one) */
  int keep = nf / 2, seen = 0;
  for (int e = 0; e < it->n_plan; e++)
    if (it->plan[e].fresh && seen++ >= keep) it->plan[e].fresh = 2;
  for (int e = it->n_plan - 1; e >= 0; e--)
    if (it->plan[e].fresh == 2) fesd__plan_remove(it, e);
  return 1;
}

double fesd__plan_cut_after_fresh(fesd_integrator *it) {
  fesd__plan_sort(it);
  for (int e = 0; e < it->n_plan; e++)
    if (it->plan[e].fresh) {
      const double next = e + 1 < it->n_plan ? it->plan[e + 1].t : it->sys.T;
      return dyadic_cut(it->plan[e].t, next, it->sys.T);
    }
  return it->sys.T;
}
