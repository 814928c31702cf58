/* Shared helpers of the hard cases (tests/hard): integrate a model step by step through
 * the public API and collect element boundaries, active sets, events and statistics. */
#ifndef HARD_UTIL_H
#define HARD_UTIL_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fesd.h"
#include "../check.h"

#define HD_MAX_NX 8
#define HD_PI 3.14159265358979323846
#define HD_MAX_EL 8000
#define HD_MAX_EV 512
#define HD_MAX_SYS 4

typedef struct {
  int n_el;                            /* recorded elements */
  double t[HD_MAX_EL + 1];             /* element start times (+ final time) */
  double x[HD_MAX_EL + 1][HD_MAX_NX];  /* element start states (+ final state) */
  unsigned act[HD_MAX_EL][HD_MAX_SYS]; /* active modes of the last stage, per subsystem */
  int n_ev;
  fesd_event ev[HD_MAX_EV];
  int status, steps_done;
  fesd_step_info info; /* of the last (or failing) step */
  fesd_stats stats;
  double t_end, x_end[HD_MAX_NX];
} hd_run;

/* Active modes per subsystem of stage j of element e of the step data. */
static inline void hd_active(const fesd_integrator *it, const fesd_step_data *d, int e, int j,
                             const int *n_modes, double tol, unsigned *out) {
  int nth, nsys;
  fesd_dims(it, &nth, &nsys);
  const double *th = d->theta + ((size_t)e * d->stages + j) * nth;
  for (int k = 0, off = 0; k < nsys && k < HD_MAX_SYS; off += n_modes[k], k++) {
    out[k] = 0;
    for (int i = 0; i < n_modes[k]; i++)
      if (th[off + i] > tol) out[k] |= 1u << i;
  }
}

/* Append the elements and events of the last accepted step. */
static inline void hd_collect(const fesd_integrator *it, const fesd_model *m, double tol, hd_run *r) {
  fesd_step_data d;
  fesd_last_step_data(it, &d);
  for (int e = 0; e < d.n_elements && r->n_el < HD_MAX_EL; e++) {
    int q = r->n_el++;
    r->t[q] = d.t[e];
    memcpy(r->x[q], d.x + (size_t)e * m->nx, (size_t)m->nx * sizeof(double));
    hd_active(it, &d, e, d.stages - 1, m->n_modes, tol, r->act[q]);
  }
  const fesd_event *ev;
  int ne;
  fesd_last_events(it, &ev, &ne);
  for (int e = 0; e < ne && r->n_ev < HD_MAX_EV; e++) r->ev[r->n_ev++] = ev[e];
}

static inline void hd_finish(fesd_integrator *it, const fesd_model *m, hd_run *r) {
  fesd_get_state(it, &r->t_end, r->x_end);
  r->t[r->n_el] = r->t_end;
  memcpy(r->x[r->n_el], r->x_end, (size_t)m->nx * sizeof(double));
  fesd_get_stats(it, &r->stats);
}

/* nsim steps of length T / nsim from (t0, x0) with constant u; stops at the first failure. */
static inline int hd_integrate(const fesd_model *m, const fesd_settings *set, double t0,
                               const double *x0, const double *u, double T, int nsim, hd_run *r) {
  memset(r, 0, sizeof(*r));
  fesd_integrator *it;
  int st = fesd_create(&it, m, set);
  if (st) return r->status = st;
  st = fesd_set_state(it, t0, x0, u);
  for (int k = 0; k < nsim && !st; k++) {
    st = fesd_step(it, u, T / nsim, &r->info);
    if (!st) {
      r->steps_done++;
      hd_collect(it, m, set->active_tol, r);
    }
  }
  hd_finish(it, m, r);
  fesd_free(&it);
  return r->status = st;
}

/* An error-controlled run as a user makes it: fesd_integrate from (t0, x0) to T with the
 * settings set and tolerances rtol, atol; the event log into r->ev (r->n_ev), the state
 * reached into r->x_end, the statistics into *info. */
static inline int hd_integrate_set(const fesd_model *m, const fesd_settings *set, double rtol, double atol,
                                   double t0, const double *x0, double T, hd_run *r, fesd_integrate_info *info) {
  memset(r, 0, sizeof(*r));
  memset(info, 0, sizeof(*info));
  fesd_integrator *it;
  int st = fesd_create(&it, m, set);
  if (st) return r->status = st;
  fesd_tolerances tol;
  fesd_tolerances_default(&tol);
  tol.rtol = rtol;
  tol.atol = atol;
  st = fesd_set_tolerances(it, &tol);
  if (!st) st = fesd_set_state(it, t0, x0, NULL);
  if (!st) st = fesd_integrate(it, NULL, T, info);
  const fesd_event *ev;
  int ne = 0;
  fesd_event_log(it, &ev, &ne);
  for (int e = 0; e < ne && r->n_ev < HD_MAX_EV; e++) r->ev[r->n_ev++] = ev[e];
  fesd_get_state(it, &r->t_end, r->x_end);
  fesd_free(&it);
  return r->status = st;
}

/* ... with Radau IIA of `stages` stages and atol = 1e-3 rtol. */
static inline int hd_integrate_tol(const fesd_model *m, int stages, double rtol, double t0, const double *x0,
                                   double T, hd_run *r, fesd_integrate_info *info) {
  fesd_settings set;
  fesd_settings_default(&set);
  set.stages = stages;
  return hd_integrate_set(m, &set, rtol, 1e-3 * rtol, t0, x0, T, r, info);
}

/* Number of element boundaries where some subsystem's active set changes. */
static inline int hd_changes(const hd_run *r, int nsys) {
  int c = 0;
  for (int e = 1; e < r->n_el; e++)
    for (int k = 0; k < nsys; k++)
      if (r->act[e][k] != r->act[e - 1][k]) {
        c++;
        break;
      }
  return c;
}

static inline double hd_maxdiff(const double *a, const double *b, int n) {
  double d = 0;
  for (int i = 0; i < n; i++) d = fmax(d, fabs(a[i] - b[i]));
  return d;
}

/* Time of the first event of subsystem sys and kind (kind < 0: any) at or after t_from. */
static inline double hd_event_time(const hd_run *r, int sys, int kind, double t_from) {
  for (int e = 0; e < r->n_ev; e++)
    if (r->ev[e].sys == sys && (kind < 0 || (int)r->ev[e].kind == kind) && r->ev[e].t >= t_from)
      return r->ev[e].t;
  return NAN;
}

/* Least-squares slope of -log(e) against log(n) over m points (e > 0): the observed order
 * when n counts steps. */
static inline double hd_slope(const double *n, const double *e, int m) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int i = 0; i < m; i++) {
    double a = log(n[i]), b = log(e[i]);
    sx += a, sy += b, sxx += a * a, sxy += a * b;
  }
  return -(m * sxy - sx * sy) / (m * sxx - sx * sx);
}

#define HD_CHECK FESD_TEST_CHECK

#endif
