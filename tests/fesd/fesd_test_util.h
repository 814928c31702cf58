/* Shared helpers of the src/fesd tests: run a reference problem and collect the
 * element boundaries, element lengths, active sets and events of every step. */
#ifndef FESD_TEST_UTIL_H
#define FESD_TEST_UTIL_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fesd.h"
#include "../check.h"
#include "problems/problems.h"

#define TU_MAX_EL 20000
#define TU_MAX_EV 1000

typedef struct {
  int n_el;                  /* recorded elements */
  double t[TU_MAX_EL + 1];   /* element start times (+ final time) */
  double x[TU_MAX_EL + 1][FESD_PROBLEM_MAX_NX];
  double h[TU_MAX_EL];
  unsigned act[TU_MAX_EL][2]; /* active modes of the last stage per subsystem (up to 2) */
  double th_min, th_sum_err;  /* min theta and max |sum theta - 1| over all stages */
  int step_of[TU_MAX_EL];
  int n_ev;
  fesd_event ev[TU_MAX_EV]; /* before/after point into the integrator: not valid after the run */
  int status;
  fesd_stats stats;
  double xT[FESD_PROBLEM_MAX_NX];
} tu_run;

static inline int tu_integrate(const fesd_problem *P, const fesd_settings *set, int nsim, double T,
                               tu_run *r) {
  memset(r, 0, sizeof(*r));
  r->th_min = INFINITY;
  fesd_integrator *it;
  int st = fesd_create(&it, &P->model, set);
  if (st) return r->status = st;
  fesd_set_state(it, 0, P->x0, P->u);
  int nx = P->model.nx, nth, nsys;
  fesd_dims(it, &nth, &nsys);
  for (int k = 0; k < nsim; k++) {
    st = fesd_step(it, P->u, T / nsim, NULL);
    if (st) break;
    fesd_step_data d;
    fesd_last_step_data(it, &d);
    for (int e = 0; e < d.n_elements && r->n_el < TU_MAX_EL; e++) {
      int q = r->n_el++;
      r->t[q] = d.t[e];
      memcpy(r->x[q], d.x + (size_t)e * nx, nx * sizeof(double));
      r->h[q] = d.h[e];
      r->step_of[q] = k;
      int off = 0;
      for (int sy = 0; sy < nsys && sy < 2; sy++) {
        int nm = P->model.n_modes[sy];
        unsigned a = 0;
        for (int i = 0; i < nm; i++)
          if (d.theta[((size_t)e * d.stages + d.stages - 1) * nth + off + i] > set->active_tol) a |= 1u << i;
        r->act[q][sy] = a;
        off += nm;
      }
      for (int j = 0; j < d.stages; j++) {
        const double *th = d.theta + ((size_t)e * d.stages + j) * nth;
        int o = 0;
        for (int sy = 0; sy < nsys; sy++) {
          double sum = 0;
          for (int i = 0; i < P->model.n_modes[sy]; i++) {
            r->th_min = fmin(r->th_min, th[o + i]);
            sum += th[o + i];
          }
          r->th_sum_err = fmax(r->th_sum_err, fabs(sum - 1));
          o += P->model.n_modes[sy];
        }
      }
    }
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    for (int e = 0; e < ne && r->n_ev < TU_MAX_EV; e++) r->ev[r->n_ev++] = ev[e];
  }
  double t;
  fesd_get_state(it, &t, r->xT);
  r->t[r->n_el] = t;
  memcpy(r->x[r->n_el], r->xT, nx * sizeof(double));
  fesd_get_stats(it, &r->stats);
  fesd_free(&it);
  return r->status = st;
}

#define TU_CHECK FESD_TEST_CHECK

#endif
