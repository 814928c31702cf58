/* The presolve (settings.presolve): the same OCP discretised by the standard method with
 * implicit Euler (Radau IIA s = 1, presolve_n_fe elements per interval), solved from the guess;
 * the SQP of the requested discretisation then starts from its solution and multipliers.
 * Why: that solve costs a few ms and lands near the solution's switching structure, so the
 * expensive SQP skips its globalisation phase (measured on ocp_step_eq, docs/ocp.md). */
#include <stdio.h>
#include <string.h>

#include "ocp/ocp_internal.h"

/* the presolve's log lines, marked, into the solve's sink */
static void log_presolve(void *user, const char *msg) {
  const fesd_ocp *o = user;
  char buf[300];
  snprintf(buf, sizeof(buf), "  presolve | %s", msg);
  if (o->set.log) o->set.log(o->set.log_user, buf);
  else printf("%s\n", buf);
}

int fesd__ocp_presolve_create(fesd_ocp *o, const fesd_ocp_settings *s) {
  const fesd_settings *is = &s->integrator;
  if (!s->presolve) return FESD_OK;
  /* a discretisation no finer than the presolve's gains nothing from it */
  if (is->method == FESD_METHOD_STANDARD && is->stages * is->n_fe <= s->presolve_n_fe) return FESD_OK;
  fesd_ocp_settings ps = *s;
  ps.presolve = 0;
  ps.integrator.method = FESD_METHOD_STANDARD;
  ps.integrator.family = FESD_RK_RADAU_IIA;
  ps.integrator.stages = 1;
  ps.integrator.n_fe = s->presolve_n_fe;
  ps.log = log_presolve;
  ps.log_user = o;
  return fesd_ocp_create(&o->pre, &o->p, &ps);
}

int fesd__ocp_presolve(fesd_ocp *o) {
  fesd_ocp *q = o->pre;
  if (!q || !o->fresh_guess) return 0;
  const size_t nw = (size_t)o->nw, m = (size_t)(o->mE + o->mI); /* the same NLP layout */
  memcpy(q->x0, o->x0, (size_t)o->nx * sizeof(double));            /* fesd_ocp_set_x0 */
  memcpy(q->wg, o->wg, nw * sizeof(double));
  memset(q->y_best, 0, m * sizeof(double));
  q->guess_pending = o->guess_pending;
  q->have_guess = 1;
  q->warm = 0;
  fesd_ocp_info qi;
  const int st = fesd_ocp_solve(q, &qi);
  fesd_ocp_info *r = &o->info;
  r->presolve_run = 1;
  r->presolve_status = st;
  r->presolve_iterations = qi.iterations;
  r->integrations += qi.integrations;
  r->integrator_failures += qi.integrator_failures;
  o->t_int += qi.time_integration;
  o->t_qp += qi.time_qp;
  if (st) return 0;
  memcpy(o->cur->w, q->w_best, nw * sizeof(double));
  memcpy(o->y, q->y_best, m * sizeof(double));
  return 1;
}
