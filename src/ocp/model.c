/* The integrator's model of an OCP: the user's model plus a cost state l' = L(t, x, u) (the
 * Lagrange term) carried by the drift, so that the Runge-Kutta method of the step integrates
 * the cost and its IFT sensitivities give the cost gradient exactly. The cost state is the last
 * state (index nx); no field or switching function depends on it. */
#include <math.h>
#include <string.h>

#include "ocp/ocp_internal.h"

static const fesd_model *um(const fesd_ocp *o) { return o->p.model; }

static int m_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *ud) {
  fesd_ocp *o = ud;
  int rc = um(o)->field(sys, mode, t, x, u, f, um(o)->user);
  f[o->nx] = 0.0;
  return rc;
}

/* user block (n x n, n x nu) into the augmented layout (n+1 x n+1, n+1 x nu): zero row and
 * column for the cost state */
static void widen(const fesd_ocp *o, const double *J, const double *Ju, double *Ja, double *Jua) {
  const int nx = o->nx, na = o->nxa, nu = o->nu;
  for (int c = 0; c < nx; c++) {
    memcpy(Ja + (size_t)c * na, J + (size_t)c * nx, (size_t)nx * sizeof(double));
    Ja[(size_t)c * na + nx] = 0.0;
  }
  memset(Ja + (size_t)nx * na, 0, (size_t)na * sizeof(double));
  if (!Jua) return;
  for (int c = 0; c < nu; c++) {
    if (Ju) memcpy(Jua + (size_t)c * na, Ju + (size_t)c * nx, (size_t)nx * sizeof(double));
    else memset(Jua + (size_t)c * na, 0, (size_t)nx * sizeof(double));
    Jua[(size_t)c * na + nx] = 0.0;
  }
}

static void fill_nan(double *v, size_t n) {
  for (size_t i = 0; i < n; i++) v[i] = NAN; /* an entry the user leaves unwritten stays NaN */
}

static int m_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                       void *ud) {
  fesd_ocp *o = ud;
  const size_t nx = (size_t)o->nx, nu = (size_t)o->nu;
  fill_nan(o->mw_J, nx * nx);
  if (Ju) fill_nan(o->mw_Ju, nx * nu);
  int rc = um(o)->field_jac(sys, mode, t, x, u, o->mw_J, Ju ? o->mw_Ju : NULL, um(o)->user);
  widen(o, o->mw_J, o->mw_Ju, J, Ju);
  return rc;
}

static int m_sw(int sys, double t, const double *x, const double *u, double *c, void *ud) {
  fesd_ocp *o = ud;
  return um(o)->sw(sys, t, x, u, c, um(o)->user);
}

/* dc/dx is column-major (rows x nx): the user's block is the leading part; the cost-state
 * column follows it */
static int m_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *ud) {
  fesd_ocp *o = ud;
  const fesd_model *m = um(o);
  int rows = (m->n_switch && m->n_switch[sys] > 0) ? m->n_switch[sys] : m->n_modes[sys];
  int rc = m->sw_jac(sys, t, x, u, J, Ju, m->user);
  memset(J + (size_t)rows * o->nx, 0, (size_t)rows * sizeof(double));
  return rc;
}

static int m_roots(double t, const double *x, const double *u, double *r, void *ud) {
  fesd_ocp *o = ud;
  return um(o)->roots(t, x, u, r, um(o)->user);
}

/* L(t,x,u) = L_gen + ||r_L||^2 and, when gx != NULL, its gradients (gu: nu values) */
static int lagrange_eval(fesd_ocp *o, double t, const double *x, const double *u, double *L, double *gx,
                         double *gu) {
  const fesd_ocp_problem *p = &o->p;
  const int nx = o->nx, nu = o->nu;
  *L = 0.0;
  if (gx) memset(gx, 0, (size_t)nx * sizeof(double));
  if (gu) memset(gu, 0, (size_t)nu * sizeof(double));
  if (p->lagrange) {
    double v = NAN;
    fill_nan(o->mw_rx, (size_t)nx);
    fill_nan(o->mw_ru, (size_t)nu);
    if (p->lagrange(t, x, u, &v, gx ? o->mw_rx : NULL, gx && nu ? o->mw_ru : NULL, p->user)) return 1;
    *L += v;
    if (gx) {
      for (int j = 0; j < nx; j++) gx[j] += o->mw_rx[j];
      for (int j = 0; j < nu; j++) gu[j] += o->mw_ru[j];
    }
  }
  if (p->n_lagrange_lsq > 0) {
    const int nr = o->nL;
    fill_nan(o->mw_r, (size_t)nr);
    fill_nan(o->mw_rx, (size_t)nr * nx);
    fill_nan(o->mw_ru, (size_t)nr * nu);
    if (p->lagrange_lsq(t, x, u, o->mw_r, gx ? o->mw_rx : NULL, gx && nu ? o->mw_ru : NULL, p->user)) return 1;
    for (int i = 0; i < nr; i++) *L += o->mw_r[i] * o->mw_r[i];
    if (gx) {
      for (int j = 0; j < nx; j++)
        for (int i = 0; i < nr; i++) gx[j] += 2 * o->mw_r[i] * o->mw_rx[(size_t)j * nr + i];
      for (int j = 0; j < nu; j++)
        for (int i = 0; i < nr; i++) gu[j] += 2 * o->mw_r[i] * o->mw_ru[(size_t)j * nr + i];
    }
  }
  return 0;
}

static int m_drift(double t, const double *x, const double *u, double *f, void *ud) {
  fesd_ocp *o = ud;
  const fesd_model *m = um(o);
  int rc = 0;
  if (m->drift) rc = m->drift(t, x, u, f, m->user);
  else memset(f, 0, (size_t)o->nx * sizeof(double));
  if (rc) return rc;
  return lagrange_eval(o, t, x, u, &f[o->nx], NULL, NULL);
}

static int m_drift_jac(double t, const double *x, const double *u, double *J, double *Ju, void *ud) {
  fesd_ocp *o = ud;
  const fesd_model *m = um(o);
  const size_t nx = (size_t)o->nx, nu = (size_t)o->nu, na = (size_t)o->nxa;
  if (m->drift) {
    fill_nan(o->mw_J, nx * nx);
    if (Ju) fill_nan(o->mw_Ju, nx * nu);
    if (m->drift_jac(t, x, u, o->mw_J, Ju ? o->mw_Ju : NULL, m->user)) return 1;
  } else {
    memset(o->mw_J, 0, nx * nx * sizeof(double));
    memset(o->mw_Ju, 0, nx * nu * sizeof(double));
  }
  widen(o, o->mw_J, o->mw_Ju, J, Ju);
  double L;
  if (lagrange_eval(o, t, x, u, &L, o->mw_f, o->mw_f + nx)) return 1;
  for (size_t c = 0; c < nx; c++) J[c * na + nx] = o->mw_f[c];
  if (Ju)
    for (size_t c = 0; c < nu; c++) Ju[c * na + nx] = o->mw_f[nx + c];
  return 0;
}

int fesd__ocp_model_init(fesd_ocp *o) {
  const fesd_model *m = um(o);
  o->model = *m;
  if (!o->cost_state) return FESD_OK;
  fesd_model *a = &o->model;
  a->nx = o->nxa;
  a->user = o;
  a->field = m_field;
  a->field_jac = m->field_jac ? m_field_jac : NULL;
  a->sw = m_sw;
  a->sw_jac = m->sw_jac ? m_sw_jac : NULL;
  a->drift = m_drift;
  /* exact drift Jacobian unless the user's drift has none (then central differences of all) */
  a->drift_jac = (!m->drift || m->drift_jac) ? m_drift_jac : NULL;
  a->roots = m->n_roots > 0 ? m_roots : NULL;
  if (!m->time_dependent) {
    /* A Lagrange term that depends on t makes the cost state's field depend on t, so the
     * integrator needs t as a state (fesd_set_state refuses a model declared time-independent
     * whose fields change with t: a cost weighted by (1 + t / 2) on time-independent dynamics).
     * Probed at three points (x0 + q, controls q clamped into their bounds, q = 0, 1, -1: at
     * x0 = 0, u = 0 a weight (1 + t) u^2 shows nothing) at t0 and a later time. */
    double *u = o->d, *x = o->d + o->nu;
    const double t0 = o->p.t0, t1 = t0 + 1e-3 * fmax(1.0, fabs(t0)) + 0.5;
    for (int q = 0; q < 3 && !a->time_dependent; q++) {
      const double v = q == 0 ? 0.0 : q == 1 ? 1.0 : -1.0;
      for (int j = 0; j < o->nu; j++) u[j] = fmin(fmax(v, o->u_lb[j]), o->u_ub[j]);
      for (int i = 0; i < o->nx; i++) x[i] = o->x0[i] + v;
      double L0 = 0, L1 = 0;
      if (!lagrange_eval(o, t0, x, u, &L0, NULL, NULL) && !lagrange_eval(o, t1, x, u, &L1, NULL, NULL) && L0 != L1)
        a->time_dependent = 1;
    }
  }
  return FESD_OK;
}
