/* Error-controlled integration to an output time (the front of the library): step lengths
 * from the embedded local error estimate of every element (error.c), a step-size controller
 * with rejection, stop conditions located like switches (wrap.h: they are element boundaries of
 * the FESD equations), and the log of all events (event_log.c).
 *
 * Tolerances. The estimate is of order q = min(s, p) + 1 (Radau IIA: q = s + 1 < 2s = p + 1),
 * so controlling it to rtol would make the actual error far smaller than asked for at tight
 * tolerances; as in Hairer's RADAU5 the tolerance is transformed, tol_e = c tol^(q/p): with steps
 * h ~ tol_e^(1/q) the global error ~ h^p then follows tol (tolerance proportionality is tested;
 * RADAU5's exponent q/(p+1) makes the local error follow tol, and the global error only
 * tol^(p/(p+1)): measured 56 tol at 1e-3 to 2100 tol at 1e-12 on the oscillator). Controller:
 * h_new = h min(5, max(0.2, 0.9 err^(-1/q))), no growth right after a rejection, and no longer
 * than the switches of the last step allow (switch_limit). */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

/* c of the tolerance transform (measured, docs/solver.md) */
#define TOL_FACTOR 0.2

int fesd_tolerances_default(fesd_tolerances *tol) {
  if (!tol) return FESD_ERR_NULL;
  memset(tol, 0, sizeof(*tol));
  tol->rtol = 1e-6;
  tol->atol = 1e-9;
  tol->max_steps = 100000;
  return FESD_OK;
}

int fesd_set_tolerances(fesd_integrator *it, const fesd_tolerances *tol) {
  if (!it || !tol) return FESD_ERR_NULL;
  if (!(tol->rtol >= 1e-14 && tol->rtol <= 0.5) || !(tol->atol >= 0 && isfinite(tol->atol)) ||
      !(tol->h_init >= 0 && isfinite(tol->h_init)) || !(tol->h_max >= 0) || !(tol->h_min >= 0 && isfinite(tol->h_min)) ||
      tol->max_steps < 1)
    return FESD_ERR_INVALID_ARG;
  if (tol->atol_v)
    for (int r = 0; r < it->nxu; r++)
      if (!(tol->atol_v[r] >= 0 && isfinite(tol->atol_v[r]))) return FESD_ERR_INVALID_ARG;
  if (!it->err_ok) return FESD_ERR_UNSUPPORTED_TABLEAU; /* explicit RK: no estimate */
  it->tol = *tol;
  it->tol.atol_v = NULL;
  for (int r = 0; r < it->nx; r++) it->tol_atol[r] = r < it->nxu && tol->atol_v ? tol->atol_v[r] : tol->atol;
  if (it->wrap.td) it->tol_atol[it->nxu] = INFINITY; /* the clock is exact */
  it->have_tol = 1;
  return FESD_OK;
}

/* Transformed tolerances of the estimate (see the top). */
static void error_tolerances(fesd_integrator *it) {
  const double e = (double)it->err_q / it->tab.order;
  const double rt = TOL_FACTOR * pow(it->tol.rtol, e);
  it->ec_rtol = rt;
  for (int r = 0; r < it->nx; r++) it->err_atol[r] = it->tol_atol[r] * rt / it->tol.rtol;
}

/* The step solves' tolerance (newton_tol is relative to the size of each row's terms, about
 * |x|_inf for the state rows) at a tenth of the tightest tolerance the error test holds a
 * component to, relative to |x|_inf, when that is below settings.newton_tol; not below
 * NEWTON_TOL_FLOOR, which Newton still reaches on the step systems. Why: with rtol 1e-11 and
 * atol 1e-13 a component passing zero asks for 1e-13 while the sliding constraint was solved to
 * 1e-12: the estimate stayed above the tolerance however short the step (a circle-sliding
 * problem, Radau s = 2: 674k Newton iterations, FESD_ERR_TOO_MANY_STEPS at t = 0.81 of 3; with
 * the tolerance so coupled 16k iterations to T). */
#define NEWTON_TOL_SHARE 0.1
#define NEWTON_TOL_FLOOR 1e-14
static double solve_tolerance(const fesd_integrator *it) {
  double big = 0, tight = INFINITY;
  for (int r = 0; r < it->nxu; r++) {
    big = fmax(big, fabs(it->x[r]));
    tight = fmin(tight, it->tol_atol[r] + it->tol.rtol * fabs(it->x[r]));
  }
  const double tau = big > 0 ? NEWTON_TOL_SHARE * tight / big : INFINITY;
  return fmin(it->set.newton_tol, fmax(NEWTON_TOL_FLOOR, tau));
}

/* First step: 0.01 of the time the field needs to change the state by its own size
 * (weighted norms), at most the interval; the controller adapts from there. */
static double first_step(fesd_integrator *it, const double *u, double span) {
  fesd__model *m = &it->model;
  fesd__point_eval pe = fesd__scratch_eval(it);
  double *th = it->gbuf;
  if (it->have_prev_theta) {
    memcpy(th, it->theta_prev, (size_t)it->nth * sizeof(double));
  } else {
    unsigned char *a = it->cand;
    int nonunique = 0;
    if (fesd__act_start(it, u, a, &nonunique)) return 1e-6 * span;
    for (int k = 0; k < m->nsys; k++) {
      int cnt = 0;
      for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i];
      for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) th[i] = a[i] ? 1.0 / cnt : 0.0;
    }
  }
  if (fesd__model_eval(m, it->t, it->x, u, &pe)) return 1e-6 * span;
  fesd__total_field(it, &pe, th, it->ftot);
  const int nx = it->nxu;
  double d0 = 0, d1 = 0, *x1 = it->ftot + it->nx, *f1 = x1 + it->nx, *w = f1 + it->nx;
  for (int r = 0; r < nx; r++) {
    w[r] = it->tol_atol[r] + it->tol.rtol * fabs(it->x[r]);
    d0 = fmax(d0, fabs(it->x[r]) / w[r]);
    d1 = fmax(d1, fabs(it->ftot[r]) / w[r]);
  }
  double h0 = d0 > 1e-5 && d1 > 1e-5 ? 0.01 * d0 / d1 : 1e-6 * span;
  h0 = fmin(h0, span);
  /* Hairer, Norsett & Wanner's starting step: the second derivative from an Euler step with
   * the same modes, h1 = (0.01 / max(d1, d2))^(1/q) for the estimate's order q */
  for (int r = 0; r < nx; r++) x1[r] = it->x[r] + h0 * it->ftot[r];
  for (int r = nx; r < it->nx; r++) x1[r] = it->x[r] + h0; /* the clock */
  if (fesd__model_eval(m, it->t + h0, x1, u, &pe)) return h0;
  memcpy(f1, it->ftot, (size_t)it->nx * sizeof(double));
  fesd__total_field(it, &pe, th, it->ftot);
  double d2 = 0;
  for (int r = 0; r < nx; r++) d2 = fmax(d2, fabs(it->ftot[r] - f1[r]) / w[r] / h0);
  const double dm = fmax(d1, d2);
  const double h1 = dm > 1e-15 ? pow(0.01 / dm, 1.0 / it->err_q) : fmax(1e-6, 1e-3 * h0);
  return fmin(fmin(100 * h0, h1), span);
}

/* Undo the last accepted step (a rejection): the state, sensitivities and records of its start. */
static void rollback(fesd_integrator *it) {
  /* the step's work stays counted (iterations, factorizations); its events and its share
   * of the per-step means go */
  fesd_stats *S = &it->stats;
  S->events -= it->n_events;
  S->steps--;
  S->rejected_steps++;
  if (it->last_sw) {
    S->switch_steps--;
    it->sum_iter_sw -= it->last_iter;
    S->mean_iter_switch_step = S->switch_steps > 0 ? it->sum_iter_sw / S->switch_steps : 0;
  } else {
    it->sum_iter_ord -= it->last_iter;
    const int ord = S->steps - S->switch_steps;
    S->mean_iter_ordinary_step = ord > 0 ? it->sum_iter_ord / ord : 0;
  }
  fesd__load(it, &it->bk);
  it->n_el = 0;
  it->n_events = 0;
}

/* Longest next step for a scene that switched E times in the last step of length hh: about as
 * many switches as one solve resolves (max_elements - 2, the sub-step capacity of step.c), at
 * the last step's rate. The error estimate does not see what a step with many switches costs:
 * its solves grow with the switches they hold (stick-slip chain n = 256, Radau s = 3, T = 4,
 * rtol 1e-3: 16 steps, one of 0.59 with 154 switches and 466 Newton iterations, 702 in all,
 * 8.1 s; limited: 46 steps, 364 iterations, 3.8 s; rtol 1e-6: 4.6 -> 3.4 s). At most a
 * fivefold cut, so that a burst of simultaneous switches costs a few steps, not a collapse. */
static double switch_limit(const fesd_integrator *it, double hh, int E) {
  const int cap = it->set.max_elements - 2 > 1 ? it->set.max_elements - 2 : 1;
  return E > cap ? hh * fmax(0.2, (double)cap / E) : INFINITY;
}

/* Integrate to t_out (one_step: return after one accepted step). */
static int integrate(fesd_integrator *it, const double *u, double t_out, fesd_integrate_info *info, int one_step) {
  memset(info, 0, sizeof(*info));
  info->root = -1;
  info->failed_time = NAN;
  if (!it) return info->status = FESD_ERR_NULL;
  if (!it->have_state) return info->status = FESD_ERR_NOT_READY;
  if (!isfinite(t_out) || t_out < it->t) return info->status = FESD_ERR_INVALID_ARG;
  if (!it->have_tol) {
    fesd_tolerances d;
    fesd_tolerances_default(&d);
    int st = fesd_set_tolerances(it, &d);
    if (st) return info->status = st;
  }
  error_tolerances(it);
  it->ec_on = 1;
  const double span = t_out - it->t, hmax = it->tol.h_max > 0 ? it->tol.h_max : INFINITY;
  double h = it->h_next > 0 ? it->h_next : it->tol.h_init > 0 ? it->tol.h_init : first_step(it, u, span);
  const double hmin = it->tol.h_min > 0 ? it->tol.h_min : 1e-14 * fmax(fabs(it->t), fabs(t_out));
  int st = FESD_OK, graze_retry = 0;
  /* the graze check's values at the start: again on every call (u or the callbacks' data may
   * have changed since the last one at this time) */
  it->ap_t = NAN;
  /* the margins at the last step ends (fesd__slide_cap) stay valid from call to call (one call
   * or many, fesd_integrate_step and fesd_integrate_grid, take the same steps; the history was
   * cleared on every call, which left the caps out of those), unless the input changed */
  if (it->nu > 0 && memcmp(it->u_cur, u, (size_t)it->nu * sizeof(double)) != 0) it->ap_h2 = it->ap_h3 = NAN;
  if (it->nu > 0) memcpy(it->u_cur, u, (size_t)it->nu * sizeof(double));
  /* the controller's memory (it->ec_rejected, it->ec_err_prev) lives in the integrator: one
   * call or many (fesd_integrate_grid steps one at a time) take the same steps */
  while (it->t < t_out) {
    if (info->steps + info->rejected >= it->tol.max_steps) {
      st = FESD_ERR_TOO_MANY_STEPS;
      break;
    }
    h = fmin(h, hmax);
    const double left = t_out - it->t, t_start = it->t;
    /* a retry after a graze ends at the dip (the rounding to the span could repeat the step
     * whose last 1 % holds it, forever) */
    double hh = graze_retry ? fmin(h, left) : h >= 0.99 * left ? left : (h > 0.5 * left ? 0.5 * left : h);
    graze_retry = 0;
    fesd_step_info si;
    if (!(it->ap_t == it->t) && (st = fesd__graze_rates(it, u, it->ap_lam, it->ap_rate, it->ap_m))) break;
    it->ap_t = it->t;
    it->newton_tol = solve_tolerance(it);
    st = fesd_step(it, u, hh, &si);
    info->newton_iter += si.newton_iter;
    if (st != FESD_OK) {
      info->failed_time = si.failed_time;
      if (si.failed_callback) info->failed_callback = si.failed_callback;
    }
    if (st == FESD_ERR_CALLBACK || st == FESD_ERR_NOMEM || st == FESD_ERR_NULL || st == FESD_ERR_INVALID_ARG)
      break;
    if (st != FESD_OK) { /* no solution of this step: shorter steps */
      info->failed_attempts++;
      h = 0.25 * hh;
      it->ec_rejected = 1;
      if (h < hmin) {
        st = FESD_ERR_STEP_TOO_SMALL;
        break;
      }
      continue;
    }
    const double err = si.error_estimate;
    const double fac = err > 0 ? 0.9 * pow(err, -1.0 / it->err_q) : 5.0;
    if (!(err <= 1.0)) { /* error test failed */
      rollback(it);
      info->rejected++;
      h = hh * fmax(0.2, fmin(fac, 0.9));
      it->ec_rejected = 1;
      if (h < hmin) {
        st = FESD_ERR_STEP_TOO_SMALL;
        break;
      }
      continue;
    }
    /* a graze inside the step (graze.c): retried to end at it */
    if ((st = fesd__graze_rates(it, u, it->ap_lam_b, it->ap_rate_b, it->ap_m_b))) break;
    const double t_dip = fesd__graze_dip(it, hh, it->ap_lam, it->ap_rate, it->ap_lam_b, it->ap_rate_b);
    if (t_dip > 0) {
      rollback(it);
      info->rejected++;
      it->ec_rejected = 1;
      h = fmax(t_dip, hmin);
      graze_retry = 1;
      continue;
    }
    const double cap = fesd__slide_cap(it, hh, it->ap_m, it->ap_m_b);
    memcpy(it->ap_m3, it->ap_m2, (size_t)it->nsys * sizeof(double));
    memcpy(it->ap_m2, it->ap_m, (size_t)it->nsys * sizeof(double));
    it->ap_h3 = it->ap_h2, it->ap_h2 = hh;
    memcpy(it->ap_m, it->ap_m_b, (size_t)it->nsys * sizeof(double));
    memcpy(it->ap_lam, it->ap_lam_b, (size_t)it->nth * sizeof(double));
    memcpy(it->ap_rate, it->ap_rate_b, (size_t)it->nth * sizeof(double));
    it->ap_t = it->t;
    double t_root;
    int root_dir = 0;
    /* crossings at the step start are not stops (the state was taken there), except right after
     * a stop: another condition crossing at the same time (two conditions crossing together:
     * the first stop ended the step there, the other's crossing came at the next step's start;
     * measured by the review: 14 stops returned where the log held 18) */
    const double t_eps = 1e-12 * fmax(1.0, fabs(t_start));
    const int root = fesd__root_crossed(it, it->last_stop_t == t_start ? t_start - t_eps : t_start + t_eps, &t_root, &root_dir);
    if (root >= 0 && !(t_root > t_start + t_eps)) { /* a stop at the start: the step is undone */
      rollback(it);
      it->stats.rejected_steps--;
      st = fesd__take_stop(it, root, root_dir, info);
      break;
    }
    if (root >= 0 && t_root < it->t) { /* end the step on the stop condition */
      rollback(it);
      it->stats.rejected_steps--;
      st = fesd_step(it, u, t_root - t_start, &si);
      info->newton_iter += si.newton_iter;
      if (st) break;
      it->ap_h2 = t_root - t_start; /* the margin history's last step */
    }
    /* the step re-solved to end on the root finds that crossing inside itself too (1.5e-9
     * before its end, relay feedback system, Lobatto IIIC s = 4: logged twice, 7 of 60 runs):
     * the stop counts from here, and log_stop logs it once */
    const int logged = it->log_n;
    if ((st = fesd__log_events(it, root, root_dir > 0))) break;
    info->steps++;
    info->switch_steps += it->log_n > logged;
    info->events += it->log_n - logged;
    if (root >= 0) {
      st = fesd__take_stop(it, root, root_dir, info);
      break;
    }
    if (hh == left) break;
    /* PI control (Gustafsson): the previous accepted error damps the reaction to the noisy
     * estimate (fewer rejections than err^(-1/q) alone) */
    double fpi = fac;
    if (it->ec_err_prev > 0 && err > 0)
      fpi = 0.9 * pow(err, -0.7 / it->err_q) * pow(it->ec_err_prev, 0.4 / it->err_q);
    h = hh * fmin(it->ec_rejected ? 1.0 : 5.0, fmax(0.2, fpi));
    h = fmin(h, switch_limit(it, hh, it->log_n - logged));
    h = fmax(fmin(h, cap), hmin);
    it->ec_err_prev = fmax(err, 1e-4);
    it->ec_rejected = 0;
    if (one_step) break;
  }
  it->ec_on = 0;
  it->newton_tol = it->set.newton_tol;
  if (st == FESD_OK || st == FESD_ROOT) it->h_next = h;
  info->t = it->t;
  info->h_next = h;
  return info->status = st;
}

int fesd_integrate(fesd_integrator *it, const double *u, double t_out, fesd_integrate_info *info) {
  fesd_integrate_info local;
  return integrate(it, u, t_out, info ? info : &local, 0);
}

int fesd_integrate_step(fesd_integrator *it, const double *u, double t_out, fesd_integrate_info *info) {
  fesd_integrate_info local;
  return integrate(it, u, t_out, info ? info : &local, 1);
}

int fesd_integrate_grid(fesd_integrator *it, const double *u, int n, const double *t_out, double *x_out,
                        fesd_integrate_info *info) {
  fesd_integrate_info local;
  if (!info) info = &local;
  memset(info, 0, sizeof(*info));
  info->root = -1;
  info->failed_time = NAN;
  if (!it || (n > 0 && (!t_out || !x_out))) return info->status = FESD_ERR_NULL;
  for (int i = 0; i < n; i++)
    if (!isfinite(t_out[i]) || (i > 0 && t_out[i] < t_out[i - 1])) return info->status = FESD_ERR_INVALID_ARG;
  int st = FESD_OK, done = 0;
  const int dense = fesd__collocation(it);
  while (done < n) {
    /* with dense output: one call to the last time, the grid from the step polynomials */
    const double target = dense ? t_out[n - 1] : t_out[done];
    fesd_integrate_info si;
    if (dense) { /* step by step, so that each step's polynomials are still there */
      while (done < n && t_out[done] <= it->t) {
        memcpy(x_out + (size_t)done * it->nxu, it->x, (size_t)it->nxu * sizeof(double));
        done++;
      }
      if (done == n) break;
      st = integrate(it, u, target, &si, 1);
    } else {
      st = fesd_integrate(it, u, target, &si);
    }
    info->steps += si.steps;
    info->switch_steps += si.switch_steps;
    info->events += si.events;
    info->rejected += si.rejected;
    info->failed_attempts += si.failed_attempts;
    info->newton_iter += si.newton_iter;
    info->failed_callback = si.failed_callback;
    info->failed_time = si.failed_time;
    if (st != FESD_OK && st != FESD_ROOT) break;
    if (dense) {
      while (done < n && t_out[done] <= it->t) {
        /* at the step end the state itself (the polynomial gives it up to round-off) */
        if (t_out[done] == it->t || fesd_dense_output(it, t_out[done], x_out + (size_t)done * it->nxu))
          memcpy(x_out + (size_t)done * it->nxu, it->x, (size_t)it->nxu * sizeof(double));
        done++;
      }
    } else if (st == FESD_OK) {
      memcpy(x_out + (size_t)done * it->nxu, it->x, (size_t)it->nxu * sizeof(double));
      done++;
    }
    if (st == FESD_ROOT) {
      info->root = si.root;
      break;
    }
    /* max_steps counts per call of this function too (the dense path integrates step by step:
     * each call's own count never reached it; measured: 6450 steps with max_steps = 50) */
    if (done < n && info->steps + info->rejected >= it->tol.max_steps) {
      st = FESD_ERR_TOO_MANY_STEPS;
      break;
    }
  }
  info->t = it->t;
  info->n_done = done;
  return info->status = st;
}
