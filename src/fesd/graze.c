/* Grazes inside an error-controlled step. A step that grows past a tangential approach to a
 * surface can hold a whole excursion into the other region between its check points: the
 * error estimate does not see it (zero for a polynomial solution), and the stage signs all lie
 * on the near side. Measured (x1' = x2 + [x1 > 0], x2' = -1 from (-1/2 + d, 1)): Radau s = 4 at
 * rtol 1e-10 stepped over the excursion of height d for every d up to 2e-4 (24 of 51 runs,
 * FESD_OK with x1 0.5 off). The distance of each inactive mode to its region (lambda = g_i -
 * min g) and its rate along the field are known at both ends of an accepted step; when they
 * show a minimum inside (falling at the start, rising at the end, no switch of the subsystem in
 * the step), the cubic Hermite interpolant through them locates it, exactly for the parabolic
 * arrival of a graze. A minimum below the surface rejects the step, and the retry ends at it
 * (integrate.c: without the rounding of step lengths to the span). */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

/* lambda of every mode at the current state and its rate along the total field (theta of the
 * last stage, or the argmin modes at a fresh start); margin[k]: for a subsystem sliding on two
 * modes, the smaller of its fesd__sliding_margins (positive while Filippov's conditions hold),
 * NaN otherwise. */
int fesd__graze_rates(fesd_integrator *it, const double *u, double *lam, double *rate, double *margin) {
  const fesd__model *m = &it->model;
  fesd__point_eval pe = fesd__scratch_eval(it);
  int st = fesd__model_eval(&it->model, it->t, it->x, u, &pe);
  if (st) return st;
  double *th = it->ap_th;
  if (it->have_prev_theta) {
    memcpy(th, it->theta_prev, (size_t)it->nth * sizeof(double));
  } else {
    for (int k = 0; k < m->nsys; k++) {
      int c = 0;
      for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++) c += it->lam00[l] == 0.0;
      for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++) th[l] = it->lam00[l] == 0.0 ? 1.0 / c : 0.0;
    }
  }
  fesd__total_field(it, &pe, th, it->ftot);
  for (int k = 0; k < m->nsys; k++) {
    int i2 = -1, j2 = -1, na = 0;
    for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++)
      if (th[l] > it->set.active_tol) na++, i2 = j2, j2 = l;
    margin[k] = NAN;
    if (na == 2) {
      double mi, mj;
      fesd__sliding_margins(it, &pe, th, it->ftot, i2, j2, &mi, &mj);
      margin[k] = fmin(mi, mj);
    }
    int jmin = -1;
    for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++)
      if (it->lam00[l] == 0.0 && (jmin < 0 || th[l] > th[jmin])) jmin = l;
    const double gj = jmin >= 0 ? fesd__dg_dot(m, &pe, jmin, it->ftot) : 0.0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      lam[i] = it->lam00[i];
      rate[i] = jmin >= 0 && i != jmin ? fesd__dg_dot(m, &pe, i, it->ftot) - gj : 0.0;
    }
  }
  return FESD_OK;
}

double fesd__hermite_min(double a, double b, double da, double db, double *tau) {
  /* p = a + da t + c2 t^2 + c3 t^3 */
  const double c3 = 2 * (a - b) + da + db, c2 = 3 * (b - a) - 2 * da - db;
  double best = fmin(a, b), tb = a < b ? 0.0 : 1.0;
  const double A = 3 * c3, B = 2 * c2, C = da; /* p' = A t^2 + B t + C */
  double r[2];
  int nr = 0;
  if (fabs(A) < 1e-14 * (fabs(B) + fabs(C))) {
    if (B != 0) r[nr++] = -C / B;
  } else {
    const double D = B * B - 4 * A * C;
    if (D >= 0) {
      const double q = -0.5 * (B + copysign(sqrt(D), B));
      r[nr++] = q / A;
      if (q != 0) r[nr++] = C / q;
    }
  }
  for (int i = 0; i < nr; i++)
    if (r[i] > 0 && r[i] < 1) {
      const double t = r[i], p = a + t * (da + t * (c2 + t * c3));
      if (p < best) best = p, tb = t;
    }
  *tau = tb;
  return best;
}

double fesd__hermite_first_zero(double a, double b, double da, double db, double tau) {
  const double c3 = 2 * (a - b) + da + db, c2 = 3 * (b - a) - 2 * da - db;
  double lo = 0, hi = tau; /* p(lo) > 0 >= p(hi) */
  for (int i = 0; i < 60 && hi - lo > 1e-15; i++) {
    const double t = 0.5 * (lo + hi), p = a + t * (da + t * (c2 + t * c3));
    if (p > 0) lo = t;
    else hi = t;
  }
  return hi;
}

/* A dip of some inactive mode below its surface inside the last step of length hh (lam_a,
 * rate_a at its start, lam_b, rate_b at its end, in g's units): the earliest one's time from
 * the step start, 0 when none. Subsystems that switched in the step are left to the step's own
 * checks (their lambda is not smooth across it). */
double fesd__graze_dip(const fesd_integrator *it, double hh, const double *lam_a, const double *rate_a,
                       const double *lam_b, const double *rate_b) {
  const fesd__model *m = &it->model;
  const fesd_event *ev;
  int ne;
  fesd_last_events(it, &ev, &ne);
  double t_dip = 0;
  for (int k = 0; k < m->nsys; k++) {
    int switched = 0;
    /* a stop condition's event names its index among the conditions, not its subsystem */
    for (int e = 0; e < ne && !switched; e++)
      switched = (ev[e].kind == FESD_EVENT_ROOT ? ev[e].sys + it->wrap.kr : ev[e].sys) == k;
    if (switched) continue;
    /* sliding at either end (a margin there, fesd__graze_rates): its modes are active, and
     * their lambda is the distance off the surface of an element end that is not a stage point
     * (Gauss-Legendre: 1e-9 relative and more), not the approach of an inactive mode: read as a
     * dip, it rejected every step of a sliding mode on a curved surface down to
     * FESD_ERR_STEP_TOO_SMALL (s = 2, rtol 1e-4; found by a review) */
    if (isfinite(it->ap_m[k]) || isfinite(it->ap_m_b[k])) continue;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      /* inactive at both ends (lambda > 0 beyond round-off), falling, then rising */
      const double w = it->sys.wth[i];
      if (!(lam_a[i] * w > 1e-9 && lam_b[i] * w > 1e-9 && rate_a[i] < 0 && rate_b[i] > 0)) continue;
      double tau;
      const double p = fesd__hermite_min(lam_a[i], lam_b[i], hh * rate_a[i], hh * rate_b[i], &tau);
      if (p < 0 && (t_dip == 0 || tau * hh < t_dip)) t_dip = tau * hh;
    }
  }
  return t_dip;
}

/* The longest next step for the sliding modes whose Filippov margin (fesd__graze_rates) fell
 * over the last step from m_a to m_b > 0, hh long: 1.5 times the time to the margin's zero,
 * extrapolated linearly (INFINITY when none falls). A sliding mode whose state is linear in t
 * has a zero error estimate and its steps grow; the end of the mode was then stepped over
 * between check points (measured: a forced stick-slip oscillator, Lobatto IIIC s = 2 at rtol
 * 1e-6, a short slip missed; the higher-order families by the midpoint check's allowance). The
 * step may pass the predicted zero (no Zeno-like approach), its stage checks then see it. */
#define SLIDE_CUBIC 0.1
#define SLIDE_YOUNG 2.0
double fesd__slide_cap(const fesd_integrator *it, double hh, const double *m_a, const double *m_b) {
  double cap = INFINITY;
  for (int k = 0; k < it->model.nsys; k++) {
    if (m_b[k] > 0 && m_a[k] > m_b[k]) cap = fmin(cap, 1.5 * hh * m_b[k] / (m_a[k] - m_b[k]));
    /* the margin can turn: a stuck phase of a forced stick-slip oscillator whose margin rose
     * over the last steps and dipped below zero inside the next one (a slip of 0.66 inside a
     * step of 5.5, Radau IIA s = 3, rtol 1e-9: x(30) 1.3e4 tolerances off, FESD_OK; found by a
     * review). The parabola through the margins at the last three step ends (the accepted
     * step before this one too): the next step ends shortly after its first zero */
    const double h2 = it->ap_h2, m2 = it->ap_m2[k], h3 = it->ap_h3, m3 = it->ap_m3[k];
    /* until four step ends of the sliding mode give its margin a model (below), the steps grow
     * by SLIDE_YOUNG at most: after an entry, steps of 0.23, 1.15 and 5.7 (growth 5) went over a
     * slip of 0.66 (the same stuck phase, Radau IIA s = 3, rtol 1e-6: x(30) 13 tolerances off) */
    if (m_b[k] > 0 && !(m_a[k] > 0 && h2 > 0 && m2 > 0 && h3 > 0 && m3 > 0)) cap = fmin(cap, SLIDE_YOUNG * hh);
    if (!(h2 > 0) || !(m2 > 0 && m_a[k] > 0 && m_b[k] > 0)) continue;
    /* m(t) = m_b + b t + c t^2, t from the step end; the points t = -hh (m_a), -hh - h2 (m2) */
    const double d1 = (m_b[k] - m_a[k]) / hh, d2 = (m_a[k] - m2) / h2, c = (d1 - d2) / (hh + h2);
    /* the parabola models the margin over the next step only while the margin's cubic term
     * stays small against it: |m'''| h^3 / 6 <= SLIDE_CUBIC m_b, m''' / 6 the third divided
     * difference of the margins at the last four step ends. A stuck phase whose margin had
     * risen to its maximum (the parabola opened upwards) took a step of 6.3 (growth 5; the
     * margin's period 13) over a slip of 0.66 (Gauss-Legendre s = 2, rtol 1e-8: x(30) 1.3e3
     * tolerances off, FESD_OK; found by a review) */
    if (h3 > 0 && m3 > 0) {
      const double d3 = (m2 - m3) / h3, e2 = (d2 - d3) / (h2 + h3), f = (c - e2) / (hh + h2 + h3);
      if (f != 0) cap = fmin(cap, cbrt(SLIDE_CUBIC * m_b[k] / fabs(f)));
    }
    const double b = d1 + c * hh; /* m'(0) */
    if (!(c < 0) && !(b < 0)) continue;
    const double D = b * b - 4 * c * m_b[k];
    if (c == 0 || D < 0) continue;
    const double q = -0.5 * (b + copysign(sqrt(D), b)), r1 = q / c, r2 = q != 0 ? m_b[k] / q : INFINITY;
    double t0 = INFINITY;
    if (r1 > 0) t0 = r1;
    if (r2 > 0 && r2 < t0) t0 = r2;
    if (isfinite(t0)) cap = fmin(cap, 1.1 * t0);
  }
  return cap;
}

/* Gauss-Legendre in a sliding element: its stage multipliers are not damped (|R(inf)| = 1), an
 * inconsistency they carry grows like 1/h (index 2), and they alternate from stage to stage,
 * which the b-weights cancel in the state but the embedded weights do not: the estimate stayed
 * O(1) as h fell, and the run ended in FESD_ERR_STEP_TOO_SMALL while sliding (a curved surface,
 * s = 2..4, every rtol from 1e-4 to 1e-10; the stage multipliers 0.40 / 0.40 at h = 1e-2, 4.4 /
 * -3.6 at h = 1.3e-8; found by a review). There the estimate takes the field with Filippov's
 * multipliers at each stage state (one model evaluation per stage): what the state's error
 * depends on. *on = 0 when the element has no 2-mode sliding subsystem. */
int fesd__consistent_stages(fesd_integrator *it, const double *z, int n, double tn, double h, double *acc,
                            int *on) {
  fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  const int s = S->s, nx = S->nx, nth = S->nth;
  *on = 0;
  const unsigned char *a0 = it->act + (size_t)n * s * nth;
  if (!fesd__any_two_modes(m, a0)) return FESD_OK;
  double *X = it->gbuf + nth, *fc = it->ftot + 3 * nx;
  for (int r = 0; r < nx; r++) acc[r] = 0;
  for (int j = 0; j < s; j++) {
    fesd__stage_state(S, z, n, j, X);
    fesd__point_eval pe = fesd__scratch_eval(it);
    int st = fesd__model_eval(&it->model, tn + S->tab.c[j] * h, X, S->u, &pe);
    if (st) return st;
    fesd__stage_theta(it, &pe, a0 + (size_t)j * nth, it->fil_th);
    fesd__total_field(it, &pe, it->fil_th, fc);
    for (int r = 0; r < nx; r++) acc[r] += it->err_e[j] * fc[r];
  }
  *on = 1;
  return FESD_OK;
}
