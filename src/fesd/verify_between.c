/* Checks of a step solution away from its stage points (verify.c has those at the stage
 * points): the switch points themselves, and the trajectory between the stage points. */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

/* Filippov check at the midpoints between stage points, where the polynomial is an
 * interpolant: only a clear crossing counts there. (Tighter under error control, 100 rtol for
 * methods of order >= 3, it found the end of stuck phases of a forced stick-slip oscillator,
 * but on a curved sliding surface with a stiff normal term (K = 3e4..3e6) the midpoints' distance
 * from the surface, amplified by K, failed it where Filippov held: spurious exits and up to 7.5
 * times the Newton iterations. The sliding margin's step cap (graze.c) does that job.) */
#define FIL_MID_TOL 0.1
/* Interpolation allowance of the midpoint region check, in units of cc_tol. */
#define INTERIOR_TOL 1e3
/* Switch-point check: the entered field pointing back by more than this fraction of the two
 * normal components' sizes. Under error control 1e3 rtol where that is less (not below 1e-8):
 * the switch point's state is then accurate to rtol. Measured (a review, forced stick-slip,
 * Radau IIA s = 5 at rtol 1e-10): a near-tangential arrival whose stick lasts 4.2e-3 logged as a
 * crossing, x(30) 2.4e3 tolerances off, FESD_OK. */
#define SWITCH_TOL 1e-2
static double switch_tol(const fesd_integrator *it) {
  return it->ec_on ? fmin(SWITCH_TOL, fmax(1e3 * it->tol.rtol, 1e-8)) : SWITCH_TOL;
}

/* Lobatto IIIC has no collocation polynomial: its interior check uses the interpolant through
 * x_n and the stage states at c_j > 0 (its stage at c = 0 lies O(h^2) off x_n),
 * x(tau) = x_n + h sum_l (sum_j L_j(tau) A_jl) v_l. Measured before (randomised relay with a
 * ramp input, tests/hard/test_switch_point.c): s = 3 stepped over sliding phases of 0.05 to
 * 0.07 inside elements of 0.46 to 0.9 unflagged (21 of 4345 runs). */
static void interp_weights(const fesd_tableau *T, double tau, double *w) {
  for (int l = 0; l < T->s; l++) w[l] = 0;
  for (int j = 0; j < T->s; j++) {
    if (!(T->c[j] > 0)) continue;
    double L = tau / T->c[j];
    for (int m = 0; m < T->s; m++)
      if (m != j && T->c[m] > 0) L *= (tau - T->c[m]) / (T->c[j] - T->c[m]);
    for (int l = 0; l < T->s; l++) w[l] += L * T->A[j][l];
  }
}

void fesd__interior_setup(fesd_integrator *it) {
  const fesd_tableau *T = &it->tab;
  if (T->is_explicit) { /* explicit stages are low-order predictions: no interior check */
    it->n_mid = 0;
    return;
  }
  double nodes[FESD_RK_MAX_STAGES + 2];
  int nn = 0;
  nodes[nn++] = 0.0;
  for (int j = 0; j < T->s; j++)
    if (T->c[j] > nodes[nn - 1]) nodes[nn++] = T->c[j];
  if (nodes[nn - 1] < 1.0) nodes[nn++] = 1.0;
  it->n_mid = nn - 1;
  for (int p = 0; p + 1 < nn; p++) {
    it->mid_tau[p] = 0.5 * (nodes[p] + nodes[p + 1]);
    if (fesd__collocation(it)) fesd__colloc_weights(it, it->mid_tau[p], it->mid_w + p * FESD_RK_MAX_STAGES);
    else interp_weights(T, it->mid_tau[p], it->mid_w + p * FESD_RK_MAX_STAGES);
    int jn = 0;
    for (int j = 1; j < T->s; j++)
      if (fabs(T->c[j] - it->mid_tau[p]) < fabs(T->c[jn] - it->mid_tau[p])) jn = j;
    it->mid_stage[p] = jn;
  }
  /* stages (c_j > 0) and midpoints merged in time order; a midpoint between equal nodes comes
   * after them */
  it->n_exc = 1;
  it->exc_tau[0] = 0; /* the element start, when it is a node */
  for (int j = 0, p = 0; j < T->s || p < it->n_mid;) {
    const int stage = j < T->s && (p >= it->n_mid || T->c[j] <= it->mid_tau[p]);
    if (stage && !(T->c[j] > 0)) {
      it->exc_stage[j++] = -1;
      continue;
    }
    it->exc_tau[it->n_exc] = stage ? T->c[j] : it->mid_tau[p];
    if (stage) it->exc_stage[j++] = it->n_exc++;
    else it->exc_mid[p++] = it->n_exc++;
  }
}

/* The states at count points of element n with weights w + q FESD_RK_MAX_STAGES, into
 * x + q nx (the interior check's midpoints of an element at once). */
static void poly_states(const fesd_integrator *it, const double *z, int n, const double *w, int count, double *x) {
  const fesd__system *S = &it->sys;
  const int nx = S->nx, s = S->s, sb = S->sb;
  const double *xn = n == 0 ? S->x0 : z + S->xo[n - 1], h = z[S->ho[n]], *ve = z + S->el[n];
  for (int q = 0; q < count; q++, w += FESD_RK_MAX_STAGES, x += nx) {
    if (nx <= s) { /* per component: x_n, then the stages in order (a short vector) */
      for (int r = 0; r < nx; r++) {
        double a = xn[r];
        for (int j = 0; j < s; j++) a += h * w[j] * ve[j * sb + r];
        x[r] = a;
      }
      continue;
    }
    memcpy(x, xn, (size_t)nx * sizeof(double)); /* the same sums, stage by stage over the vector */
    for (int j = 0; j < s; j++) {
      const double hw = h * w[j], *v = ve + j * sb;
      for (int r = 0; r < nx; r++) x[r] += hw * v[r];
    }
  }
}

void fesd__poly_state(const fesd_integrator *it, const double *z, int n, const double *w, double *x) {
  poly_states(it, z, n, w, 1, x);
}

/* The start itself: a subsystem that starts in one mode j within round-off of another mode's
 * region, its field at x0 carrying it there in a tiny fraction of the first element, reaches
 * the surface at once; the stage points, a good part of an element later, may all lie on j's
 * side again (measured: ocp_step_eq, Radau IIA s = 1, a start 2e-9 below c1 = 0 whose field
 * points up for 0.19 of the step: one element of implicit Euler stayed below, with an end state
 * 0.047 off the sliding solution that a start 2e-9 above gets). The linear arrival time is
 * accurate there, and the plan decides at it between a crossing and a sliding mode.
 * A mode that a start jump of this attempt removed (the solution showed its exit at the start)
 * is not re-entered here: near an exit the fields at x0 can still hold the sliding mode while a
 * family's multipliers end it (Lobatto IIIC s = 2: its c = 0 stage's multiplier carries an O(h)
 * error), and the two decisions alternated until the step failed (a curved surface in fixed
 * steps of 20/1599, the exit 7e-4 after the step start; found by a review). */
#define START_REL 1e-6 /* distance to the surface, in units of the indicator scale */
#define START_HIT 1e-3 /* arrival time, as a fraction of the first element */

/* ... nor, under error control, a mode whose exit the log holds at this start (the last step
 * ended on it: a stop condition or an output time at the exit, or accept.c's end_set): the
 * fields at an exit are tangent, and the start check re-entered it, logging an entry and a
 * second exit 4e-9 later (a stop condition at the exit; found by a review). */
static int exited_at_start(const fesd_integrator *it, int k, int i) {
  if (!it->ec_on) return 0;
  const int mi = i - it->model.th_off[k];
  for (int e = it->log_n - 1; e >= 0 && it->log[e].t >= it->sys.t0; e--) {
    const fesd_event *v = &it->log[e];
    if (v->sys != k || v->kind != FESD_EVENT_SLIDING_EXIT) continue;
    int before = 0, after = 0;
    for (int q = 0; q < v->n_before; q++) before |= v->before[q] == mi;
    for (int q = 0; q < v->n_after; q++) after |= v->after[q] == mi;
    return v->t == it->sys.t0 && before && !after;
  }
  return 0;
}

int fesd__scan_start(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  fesd__point_eval pe;
  int evaluated = 0;
  for (int i = 0; i < S->nth; i++) {
    /* inactive modes within round-off of their region first: one test per mode on ordinary steps */
    if (act[i] || !(it->lam00[i] * S->wth[i] < START_REL)) continue;
    if (it->start_jumped && it->act_first[i] && !it->act0[i]) continue;
    const int k = m->sys_of[i], j = fesd__one_mode(m, act, k);
    if (exited_at_start(it, k, i)) continue;
    if (j < 0) continue;
    const double *th = z + fesd__th(S, 0, 0);
    if (!evaluated) {
      pe = fesd__scratch_eval(it);
      int st = fesd__model_eval(m, S->t0, S->x0, S->u, &pe);
      if (st) return st;
      fesd__total_field(it, &pe, th, it->ftot);
      evaluated = 1;
    }
    double ai, aj; /* psi = g_i - g_j = lam00_i >= 0 here; along j it changes at rate aj */
    fesd__normal_components(it, &pe, th, it->ftot, i, j, &ai, &aj);
    if (!(aj < 0)) continue;
    const double t_hit = it->lam00[i] / -aj;
    if (!(t_hit <= START_HIT * z[S->ho[0]])) continue;
    fesd__violation v = {1, t_hit, i, k, 1, 0, 0, 0, 0, t_hit, t_hit, 0};
    fesd__note_violation(&ps[k], &v);
  }
  return FESD_OK;
}

/* Filippov's conditions at the switch points themselves: a crossing into mode j, or an exit
 * from a sliding mode onto j, needs j's field at the boundary state to leave the surface into
 * j's region (or run along it). The equations see the fields only at stage points; on a long
 * element whose only stage is its end (implicit Euler) both a crossing and an early exit stay
 * consistent there while the field at the switch points back (measured, ocp_step_eq, Radau
 * IIA s = 1, a start at the co-dimension-2 point: a crossing at t = 2 where the exact flow
 * slides to 2.4255, and an exit at 2.2835; the step map jumped between three solutions). Exits
 * are checked where they are pinned at a stage (c_s = 1): there the remaining field is tangent
 * up to round-off, while an extrapolated exit (Gauss-Legendre) is off by its order. */
int fesd__scan_switch_points(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nth = S->nth, s = S->s, exits = S->tab.c_end_is_one;
  fesd__point_eval pe;
  double tb = 0;
  for (int n = 1; n < S->N; n++) {
    tb += z[S->ho[n - 1]];
    const unsigned char *P = act + (size_t)(n * s - 1) * nth, *Q = act + (size_t)(n * s) * nth;
    int same = 1; /* a byte loop: this runs on every ordinary step, a memcmp call cost more */
    for (int l = 0; l < nth && same; l++) same = P[l] == Q[l];
    if (same) continue;
    int evaluated = 0;
    for (int k = 0; k < m->nsys; k++) {
      int i = -1, j = -1, np = 0, nq = 0, shared = 0;
      for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++) {
        np += P[l], nq += Q[l], shared += P[l] && Q[l];
        if (Q[l] && !P[l]) j = l;
        if (P[l] && !Q[l]) i = l;
      }
      if (np == shared && nq == shared) continue; /* k's set unchanged */
      if (nq != 1) continue;                      /* entries into sliding modes: scan_filippov */
      if (np == 1 && shared == 0) { /* a crossing i -> j */
      } else if (np == 2 && shared == 1 && exits) { /* an exit: i leaves, j stays */
        for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++)
          if (Q[l]) j = l;
      } else {
        continue;
      }
      if (i < 0 || j < 0) continue;
      const double *th = z + fesd__th(S, n, 0);
      if (!evaluated) {
        pe = fesd__scratch_eval(it);
        int st = fesd__model_eval(m, S->t0 + tb, z + S->xo[n - 1], S->u, &pe);
        if (st) return st;
        fesd__total_field(it, &pe, th, it->ftot);
        evaluated = 1;
      }
      double ai, aj; /* psi = g_i - g_j < 0 in region i: j leaves into its region when aj > 0 */
      fesd__normal_components(it, &pe, th, it->ftot, i, j, &ai, &aj);
      if (!(aj < -switch_tol(it) * (fabs(ai) + fabs(aj)))) continue;
      /* the switch chose wrong: a crossing slides (j wants out), an exit is early (i wants in) */
      fesd__violation v = {1, tb, np == 1 ? j : i, k, np == 1 ? 0 : 1, n, n * s, 1, 0, tb, tb, 0};
      fesd__note_violation(&ps[k], &v);
    }
  }
  return FESD_OK;
}

/* Implicit Euler (one stage, at the element end) sees an element only at its two ends: a
 * trajectory that reaches another mode's region and turns back between them is stepped over
 * (measured: the dynamics of ocp_step_eq, Radau IIA s = 1, a start 1e-3 below c1 = 0 in mode
 * 2, whose flow slides on c1 = 0 from 0.0065 to 0.198: the element of 0.33 ended below the
 * surface again, FESD_OK after 0 Newton iterations and 0.08 off the sliding solution that a
 * start above the surface got; the step map jumped across the surface and the SQP of the
 * optimal control problem stalled there). The distance of each inactive mode to its region
 * (g_i - g_j, j the element's mode) and its rate along the field at both element ends give
 * the cubic Hermite interpolant, as between error-controlled steps (graze.c); a dip below
 * the surface is an entry at its first zero. More stages see such an excursion at their inner
 * stage points, so this runs for one-stage methods only (one model evaluation per element). */
int fesd__scan_hermite(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nth = S->nth;
  double *la = it->herm, *ra = it->herm + nth, tn = 0;
  fesd__point_eval pe = fesd__scratch_eval(it);
  for (int p = 0; p <= S->N; p++) { /* element boundary p: the end of element p - 1, the start of p */
    int st = fesd__model_eval(m, S->t0 + tn, p == 0 ? S->x0 : z + S->xo[p - 1], S->u, &pe);
    if (st) return st;
    for (int side = 0; side < 2; side++) {
      const int n = side == 0 ? p - 1 : p;
      if (n < 0 || n >= S->N) continue;
      const unsigned char *a = act + (size_t)n * nth;
      const double h = z[S->ho[n]], *f = z + fesd__v(S, n, 0);
      if (side == 1) {
        fesd__total_field(it, &pe, z + fesd__th(S, n, 0), it->ftot);
        f = it->ftot;
      }
      for (int k = 0; k < m->nsys; k++) {
        const int j = fesd__one_mode(m, a, k);
        if (j < 0) continue;
        const double gj = pe.g[j], rj = fesd__dg_dot(m, &pe, j, f);
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
          if (i == j) continue;
          const double l = pe.g[i] - gj, r = fesd__dg_dot(m, &pe, i, f) - rj, w = S->wth[i];
          if (side == 1) {
            la[i] = l, ra[i] = r;
            continue;
          }
          /* off the surface at both ends, falling, then rising */
          if (!(la[i] * w > 1e-9 && l * w > 1e-9 && ra[i] < 0 && r > 0)) continue;
          double tau;
          const double pm = fesd__hermite_min(la[i], l, h * ra[i], h * r, &tau);
          if (!(pm * w < -INTERIOR_TOL * it->set.cc_tol)) continue;
          const double t0 = tn - h, tz = fesd__hermite_first_zero(la[i], l, h * ra[i], h * r, tau);
          fesd__violation v = {1, t0 + tz * h, i, k, 1, n, n + 1, 0, 0, t0, t0 + tau * h, 0};
          fesd__note_violation(&ps[k], &v);
        }
      }
    }
    if (p < S->N) tn += z[S->ho[p]];
  }
  return FESD_OK;
}

/* Whether the 2-mode sliding of subsystem k in the active sets a (all subsystems) satisfies
 * Filippov's conditions at time t of z (*out = 1), to the switch-point check's tolerance. */
int fesd__sliding_stands(fesd_integrator *it, const double *z, double t, const unsigned char *a, int k, int *out) {
  *out = 0;
  int j, i = fesd__two_modes(&it->model, a, k, &j);
  if (i < 0) return FESD_OK;
  double *x = it->gbuf + it->nth;
  fesd__state_at(it, z, it->sys.N, t, x);
  fesd__point_eval pe = fesd__scratch_eval(it);
  int st = fesd__model_eval(&it->model, it->sys.t0 + t, x, it->sys.u, &pe);
  if (st) return st;
  fesd__stage_theta(it, &pe, a, it->fil_th); /* uses ftot: before the total field */
  fesd__total_field(it, &pe, it->fil_th, it->ftot);
  *out = fesd__filippov(it, &pe, it->fil_th, it->ftot, i, j, switch_tol(it)) == -2;
  return FESD_OK;
}

/* The parabola through (t[q-1..q+1], v[q-1..q+1]) at x. */
static double parabola_at(const double *t, const double *v, int q, double x) {
  const double d1 = (v[q] - v[q - 1]) / (t[q] - t[q - 1]), d2 = (v[q + 1] - v[q]) / (t[q + 1] - t[q]);
  return v[q - 1] + (x - t[q - 1]) * (d1 + (d2 - d1) / (t[q + 1] - t[q - 1]) * (x - t[q]));
}

/* An excursion into an inactive mode's region shorter than the distance between two check
 * points: the distance to the region (lambda = g_i - g_j, weighted) at the element start, the
 * stage points and the midpoints falls and rises again on the right side of the surface, and
 * the parabola through the smallest and its neighbours dips below it. Measured (a review): a
 * 4-mass friction chain under error control, Radau IIA s = 5, rtol 1e-7, whose mass arrives
 * at the belt speed nearly tangentially and sticks for 0.0116 inside an element of 0.44 (the
 * slip trajectory crosses the belt speed by 1.5e-5 and returns): stepped over, 9 events of 11,
 * x(10) 131 tolerances off, FESD_OK. The parabolas through the smallest value and the points
 * two before or after it must dip too, so that the interpolation's own error is not taken for
 * an excursion. gm: per midpoint and subsystem, the least other mode's indicator minus the
 * active one's (scan_interior). */
static void scan_excursions(fesd_integrator *it, const double *z, const unsigned char *act, int n, double tn,
                            double h, const double *gm, fesd__violation *ps) {
  const fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  const int s = S->s, nth = S->nth, np = it->n_exc;
  const unsigned char *a = act + (size_t)(n * s) * nth;
  const double tol = INTERIOR_TOL * it->set.cc_tol, *t = it->exc_tau;
  if (it->exc_off) return;
  for (int k = 0; k < m->nsys; k++) {
    const int ja = fesd__one_mode(m, a, k), i0 = m->th_off[k], i1 = m->th_off[k + 1];
    if (ja < 0) continue;
    /* the smallest lambda of the other modes at the nodes (the midpoints': gm), while ja is
     * the only mode at every stage (a switch inside: the sign checks'), and at the element
     * start when it is a node: the step start, or the element before's last stage */
    double v[2 * FESD_RK_MAX_STAGES + 2];
    int same = 1;
    for (int j = 0; j < s && same; j++) {
      const double *l = z + fesd__la(S, n, j);
      const unsigned char *aj = a + (size_t)j * nth;
      double w = INFINITY;
      for (int i = i0; i < i1; i++)
        if (i != ja) {
          same &= !aj[i];
          w = l[i] < w ? l[i] : w;
        }
      same &= aj[ja];
      if (it->exc_stage[j] > 0) v[it->exc_stage[j]] = w;
    }
    if (!same) continue;
    /* not after a switch of k at the element start: the distance to the region left grows
     * from zero there, and where the start is no node (Gauss-Legendre) the first nodes'
     * values made a dip of it (a slip after a sliding exit taken for a re-entry: the plan
     * failed, and the fallback's step put the exit at its end, 0.048 late; found by a review) */
    const unsigned char *b = n == 0 ? it->act0 : a - (size_t)nth;
    for (int i = i0; i < i1 && same; i++) same = b[i] == a[i];
    if (!same) continue;
    const int start = n == 0 ? S->tab.c[0] > 0 : S->tab.c[s - 1] == 1.0;
    v[0] = INFINITY;
    const double *l0 = !start ? NULL : n == 0 ? it->lam00 : z + fesd__la(S, n - 1, s - 1);
    for (int i = i0; i < i1 && l0; i++)
      if (i != ja && l0[i] < v[0]) v[0] = l0[i];
    for (int p = 0; p < it->n_mid; p++) v[it->exc_mid[p]] = gm[p * m->nsys + k];
    int q = 1;
    for (int r = 2; r < np; r++)
      if (v[r] < v[q]) q = r;
    if ((q == 1 && !(start && v[0] > v[1])) || q == np - 1) continue; /* falls to an end */
    const double d1 = (v[q] - v[q - 1]) / (t[q] - t[q - 1]), d2 = (v[q + 1] - v[q]) / (t[q + 1] - t[q]);
    const double c2 = (d2 - d1) / (t[q + 1] - t[q - 1]);
    if (!(c2 > 0)) continue;
    const double tv = 0.5 * (t[q - 1] + t[q]) - 0.5 * d1 / c2; /* the vertex */
    if (!(v[q] * S->wG[k] > -tol)) {
      /* below the surface at a check point (the sign checks' entry): where it turns back */
      if (ps[k].found && ps[k].enter && ps[k].element == n && ps[k].t <= tn + t[q + 1] * h) ps[k].back = tn + tv * h;
      continue;
    }
    double pv = parabola_at(t, v, q, tv);
    if (!(pv * S->wG[k] < -tol)) continue;
    if (q >= 2 && isfinite(v[q - 2])) pv = fmax(pv, parabola_at(t, v, q - 1, tv));
    if (q + 2 < np) pv = fmax(pv, parabola_at(t, v, q + 1, tv));
    if (!(pv * S->wG[k] < -tol)) continue;
    /* the mode: the other one nearest its region at the stage nearest the vertex */
    int jn = 0, mode = -1;
    for (int j = 1; j < s; j++)
      if (fabs(S->tab.c[j] - tv) < fabs(S->tab.c[jn] - tv)) jn = j;
    const double *l = z + fesd__la(S, n, jn);
    for (int i = i0; i < i1; i++)
      if (i != ja && (mode < 0 || l[i] < l[mode])) mode = i;
    const double tz = fmax(t[q - 1], tv - sqrt(-pv / c2)); /* its first zero */
    fesd__violation c = {1, tn + tz * h, mode, k, 1, n, n * s + s, 0, 0, tn + t[q - 1] * h, tn + tv * h, tn + tv * h};
    fesd__note_violation(&ps[k], &c);
    it->exc_found = 1;
  }
}

/* Between the stage points (implicit methods): the region of the polynomial, and
 * Filippov's conditions of 2-mode sliding modes (with theta of the nearest stage). */
int fesd__scan_interior(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int s = S->s, nth = S->nth;
  double *xm = it->gbuf + nth; /* the midpoint states of an element, then their gaps (gm) */
  double *gm = xm + (size_t)(FESD_RK_MAX_STAGES + 1) * S->nx;
  fesd__point_eval pe = fesd__scratch_eval(it);
  double tn = 0;
  for (int n = 0; n < S->N; n++) {
    const double h = z[S->ho[n]];
    const unsigned char *a = act + (size_t)(n * s) * nth;
    const int sliding = fesd__any_two_modes(m, a);
    poly_states(it, z, n, it->mid_w, it->n_mid, xm);
    for (int p = 0; p < it->n_mid; p++) {
      const double *x = xm + (size_t)p * S->nx;
      fesd__point_eval q = pe;
      if (!sliding) q.F = q.dgdx = NULL;
      const double t = tn + it->mid_tau[p] * h;
      int st = fesd__model_eval(m, S->t0 + t, x, S->u, &q);
      if (st) return st;
      const double *th = z + fesd__th(S, n, it->mid_stage[p]); /* the nearest stage's */
      if (sliding) fesd__total_field(it, &q, th, it->ftot);
      for (int k = 0; k < m->nsys; k++) {
        double gact = INFINITY, gin = INFINITY;
        int lin = -1;
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
          if (a[i]) gact = pe.g[i] < gact ? pe.g[i] : gact;
          else if (pe.g[i] < gin) gin = pe.g[i], lin = i;
        }
        gm[p * m->nsys + k] = gin - gact;
        if (lin >= 0 && (gin - gact) * S->wG[k] < -INTERIOR_TOL * it->set.cc_tol) {
          fesd__violation v = {1, t, lin, k, 1, n, n * s + s, 0, 0, tn, t, 0};
          fesd__note_violation(&ps[k], &v);
          continue;
        }
        if (!sliding) continue;
        int j, i = fesd__two_modes(&it->model, a, k, &j);
        if (i < 0) continue;
        int c = fesd__filippov(it, &q, th, it->ftot, i, j, FIL_MID_TOL);
        if (c == -2 || !fesd__alternative_exists(it, &q, a, k, i, j)) continue;
        fesd__violation v = {1, t, c < 0 ? i : c, k, 0, n, n * s + s, 0, c < 0 ? -1 : 1, 0, 0, 0};
        fesd__note_violation(&ps[k], &v);
      }
    }
    scan_excursions(it, z, act, n, tn, h, gm, ps);
    tn += h;
  }
  return FESD_OK;
}
