/* Results of the OCP solver in the user's layout: solution, multipliers, interval data. */
#include <math.h>
#include <string.h>

#include "ocp/ocp_internal.h"

void fesd__ocp_unpack_multipliers(fesd_ocp *o, const double *mult) {
  const fesd_ocp_problem *p = &o->p;
  const size_t nx = (size_t)o->nx, nu = (size_t)o->nu, N = (size_t)o->N;
  memset(o->m_dyn, 0, N * nx * sizeof(double));
  memset(o->m_x0, 0, nx * sizeof(double));
  memset(o->m_xb, 0, (N + 1) * nx * sizeof(double));
  memset(o->m_ub, 0, N * nu * sizeof(double));
  memset(o->m_path, 0, (N + 1) * (size_t)p->n_path * sizeof(double));
  memset(o->m_term, 0, (size_t)p->n_term * sizeof(double));
  memset(o->m_l1, 0, (size_t)p->n_l1 * sizeof(double));
  for (int r = 0; r < o->mE + o->mI; r++) {
    const ocp_row *w = &o->rows[r];
    const double v = w->sign * mult[r];
    switch (w->kind) {
    case ROW_INIT: o->m_x0[w->idx] = v; break;
    case ROW_DYN: o->m_dyn[w->idx] = v; break;
    case ROW_XBND: o->m_xb[w->idx] += v; break;
    case ROW_UBND: o->m_ub[w->idx] += v; break;
    case ROW_PATH: o->m_path[w->idx] += v; break;
    case ROW_TERM: o->m_term[w->idx] += v; break;
    default: o->m_l1[w->idx] += v; break;
    }
  }
}

int fesd_ocp_get_solution(const fesd_ocp *o, double *x, double *u) {
  if (!o) return FESD_ERR_NULL;
  if (!o->have_guess) return FESD_ERR_NOT_READY;
  const int nx = o->nx, nu = o->nu, nb = o->nb;
  for (int k = 0; k <= o->N; k++) {
    if (x) memcpy(x + (size_t)k * nx, o->w_best + (size_t)k * nb, (size_t)nx * sizeof(double));
    if (u && k < o->N) memcpy(u + (size_t)k * nu, o->w_best + (size_t)k * nb + nx, (size_t)nu * sizeof(double));
  }
  return FESD_OK;
}

int fesd_ocp_get_multipliers(const fesd_ocp *o, fesd_ocp_multipliers *m) {
  if (!o || !m) return FESD_ERR_NULL;
  *m = (fesd_ocp_multipliers){o->m_dyn, o->m_x0, o->m_xb, o->m_ub, o->m_path, o->m_term, o->m_l1};
  return FESD_OK;
}

int fesd_ocp_interval(fesd_ocp *o, int k, fesd_step_data *data, const fesd_event **events, int *n_events) {
  if (!o) return FESD_ERR_NULL;
  if (k < 0 || k >= o->N) return FESD_ERR_INVALID_ARG;
  if (!o->have_guess) return FESD_ERR_NOT_READY;
  const double *w = o->w_best + (size_t)k * o->nb;
  double l;
  int st = fesd__ocp_simulate(o, k, w, w + o->nx, o->tmp, &l, 0, NULL);
  if (st) return st;
  if (data && (st = fesd_last_step_data(o->it, data))) return st;
  if (events || n_events) {
    const fesd_event *ev;
    int n;
    if ((st = fesd_last_events(o->it, &ev, &n))) return st;
    if (events) *events = ev;
    if (n_events) *n_events = n;
  }
  return FESD_OK;
}
