/* Settings, validation, workspace allocation and the initial guess of the OCP solver. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ocp/ocp_internal.h"

int fesd_ocp_settings_default(fesd_ocp_settings *s) {
  if (!s) return FESD_ERR_NULL;
  memset(s, 0, sizeof(*s));
  fesd_settings_default(&s->integrator);
  s->integrator.sensitivities = 1;
  s->hessian = FESD_OCP_HESSIAN_AUTO;
  s->max_iter = 200;
  s->tol_stat = 1e-8;
  s->tol_feas = 1e-9;
  s->tol_comp = 1e-9;
  s->penalty0 = 1.0;
  s->penalty_max = 1e10;
  s->armijo = 1e-4;
  s->backtrack = 0.5;
  s->max_backtracks = 30;
  s->soc = 1;
  s->nonmonotone = 2;
  s->reg_primal = 1e-9;
  s->reg_dual = 1e-10;
  s->qp_tol = 1e-12;
  s->qp_max_iter = 100;
  s->stall_window = 6;
  s->qp_backend = FESD_NCP_BACKEND_AUTO;
  s->init = FESD_OCP_INIT_SIMULATE;
  s->presolve = 1;
  s->presolve_n_fe = 2;
  return FESD_OK;
}

static int in(double v, double lo, double hi) { return v >= lo && v <= hi; } /* NaN: false */
static int open_in(double v, double lo, double hi) { return v > lo && v < hi; }

static int check_settings(const fesd_ocp_settings *s) {
  if ((int)s->hessian < FESD_OCP_HESSIAN_AUTO || (int)s->hessian > FESD_OCP_HESSIAN_GN_SR1 ||
      s->max_iter < 1 || s->max_iter > 100000 || !in(s->tol_stat, 1e-14, 1) || !in(s->tol_feas, 1e-14, 1) ||
      !in(s->tol_comp, 1e-14, 1) || !in(s->penalty0, 0, 1e12) || !in(s->penalty_max, 1, 1e16) ||
      !open_in(s->armijo, 0, 0.5) || !in(s->backtrack, 0.05, 0.95) || s->max_backtracks < 1 ||
      s->max_backtracks > 60 || (s->soc != 0 && s->soc != 1) || !in(s->reg_primal, 0, 1) ||
      !in(s->reg_dual, 0, 1) || !in(s->qp_tol, 1e-15, 1e-3) || s->qp_max_iter < 1 || s->qp_max_iter > 1000 ||
      s->stall_window < 0 || s->stall_window > 1000 || s->nonmonotone < 1 ||
      s->nonmonotone > FESD_OCP_MAX_NONMONOTONE ||
      (int)s->qp_backend < 0 || (int)s->qp_backend > FESD_NCP_BACKEND_CHOLMOD ||
      !(s->init == FESD_OCP_INIT_SIMULATE || s->init == FESD_OCP_INIT_CONSTANT) || (s->verbose != 0 && s->verbose != 1) ||
      (s->presolve != 0 && s->presolve != 1) || s->presolve_n_fe < 1 || s->presolve_n_fe > 100)
    return FESD_ERR_INVALID_ARG;
  return FESD_OK;
}

/* bounds arrays: NULL is allowed; entries must satisfy lb <= ub, no NaN, lb < inf, ub > -inf */
static int check_bounds(const double *lb, const double *ub, int n) {
  for (int i = 0; i < n; i++) {
    double l = lb ? lb[i] : -INFINITY, u = ub ? ub[i] : INFINITY;
    if (isnan(l) || isnan(u) || l > u || l == INFINITY || u == -INFINITY) return FESD_ERR_INVALID_ARG;
  }
  return FESD_OK;
}

static int check_problem(const fesd_ocp_problem *p, const fesd_ocp_settings *s) {
  if (!p->model || !p->x0) return FESD_ERR_NULL;
  const fesd_model *m = p->model;
  if (m->sparsity || m->drift_sparsity || !m->field || !m->sw || m->nx < 1 || m->nu < 0 || m->nsys < 1 ||
      !m->n_modes)
    return FESD_ERR_MODEL;
  if (p->n_ctrl < 1 || p->n_ctrl > 100000 || !isfinite(p->t0) || !isfinite(p->tf) || !(p->tf > p->t0))
    return FESD_ERR_INVALID_ARG;
  const int counts[5] = {p->n_lagrange_lsq, p->n_mayer_lsq, p->n_l1, p->n_path, p->n_term};
  const void *fns[5] = {(const void *)p->lagrange_lsq, (const void *)p->mayer_lsq, (const void *)p->l1,
                        (const void *)p->path, (const void *)p->terminal};
  for (int i = 0; i < 5; i++) {
    if (counts[i] < 0 || counts[i] > 100000) return FESD_ERR_DIMENSION;
    if (counts[i] > 0 && !fns[i]) return FESD_ERR_NULL;
  }
  if (p->n_l1 > 0) {
    if (!p->l1_weight) return FESD_ERR_NULL;
    for (int i = 0; i < p->n_l1; i++)
      if (!(p->l1_weight[i] > 0) || !isfinite(p->l1_weight[i])) return FESD_ERR_INVALID_ARG;
  }
  for (int i = 0; i < m->nx; i++)
    if (!isfinite(p->x0[i])) return FESD_ERR_INVALID_ARG;
  if (!p->x0_lb != !p->x0_ub) return FESD_ERR_INVALID_ARG; /* both or neither */
  int st = check_bounds(p->x0_lb, p->x0_ub, m->nx);
  if (!st) st = check_bounds(p->x_lb, p->x_ub, m->nx);
  if (!st) st = check_bounds(p->u_lb, p->u_ub, m->nu);
  if (!st) st = check_bounds(p->path_lb, p->path_ub, p->n_path);
  if (!st) st = check_bounds(p->term_lb, p->term_ub, p->n_term);
  if (st) return st;
  if ((s->hessian == FESD_OCP_HESSIAN_GAUSS_NEWTON || s->hessian == FESD_OCP_HESSIAN_GN_SR1) &&
      p->n_lagrange_lsq == 0 && p->n_mayer_lsq == 0)
    return FESD_ERR_INVALID_ARG;
  return FESD_OK;
}

/* allocation helper: every array of the workspace goes through it; a failure is remembered */
static void *get(int *fail, size_t n, size_t size) {
  void *v = calloc(n > 0 ? n : 1, size);
  if (!v) *fail = 1;
  return v;
}

static double *copy_or(int *fail, const double *src, int n, double fill) {
  double *v = get(fail, (size_t)n, sizeof(double));
  if (v)
    for (int i = 0; i < n; i++) v[i] = src ? src[i] : fill;
  return v;
}

static void point_free(ocp_point *p) {
  free(p->w), free(p->c), free(p->grad), free(p->jv), free(p->phi), free(p->Sx), free(p->Su), free(p->gn), free(p->sig);
}

void fesd_ocp_free(fesd_ocp **op) {
  if (!op || !*op) return;
  fesd_ocp *o = *op;
  fesd_free(&o->it);
  fesd_ocp_free(&o->pre);
  fesd__ocp_qp_free(&o->qp);
  fesd__ocp_qp_free(&o->qe);
  for (int i = 0; i < 3; i++) point_free(&o->pt[i]);
  double *arr[] = {o->x0, o->x0_lb, o->x0_ub, o->x_lb, o->x_ub, o->u_lb, o->u_ub, o->path_lb, o->path_ub,
                   o->term_lb, o->term_ub, o->l1_w, o->lb, o->ub, o->mw_f, o->mw_J, o->mw_Ju, o->mw_r,
                   o->mw_rx, o->mw_ru, o->fv, o->fx, o->fu, o->xa, o->Sxa, o->Sua, o->y, o->yq, o->yq2, o->d,
                   o->dsoc, o->gl, o->gl2, o->B, o->A, o->bs, o->by, o->bBs, o->tmp, o->w_best, o->y_best,
                   o->wg, o->m_dyn, o->m_x0, o->m_xb, o->m_ub, o->m_path, o->m_term, o->m_l1};
  for (size_t i = 0; i < sizeof(arr) / sizeof(arr[0]); i++) free(arr[i]);
  free(o->x0_free), free(o->jr), free(o->jc), free(o->rows);
  free(o);
  *op = NULL;
}

/* variable bounds: free x0 components in [x0_lb, x0_ub], states at k >= 1 in [x_lb, x_ub],
 * controls in [u_lb, u_ub]; fixed x0 components have the equality row instead */
static void variable_bounds(fesd_ocp *o) {
  const int nx = o->nx, nu = o->nu, nb = o->nb;
  for (int j = 0; j < o->nw; j++) o->lb[j] = -INFINITY, o->ub[j] = INFINITY;
  for (int k = 0; k <= o->N; k++) {
    for (int i = 0; i < nx; i++) {
      if (k == 0 && !o->x0_free[i]) continue;
      o->lb[k * nb + i] = k == 0 ? o->x0_lb[i] : o->x_lb[i];
      o->ub[k * nb + i] = k == 0 ? o->x0_ub[i] : o->x_ub[i];
    }
    for (int i = 0; i < nu && k < o->N; i++) o->lb[k * nb + nx + i] = o->u_lb[i], o->ub[k * nb + nx + i] = o->u_ub[i];
  }
}

static int alloc_all(fesd_ocp *o) {
  int f = 0;
  const fesd_ocp_problem *p = &o->p;
  const size_t nx = (size_t)o->nx, nu = (size_t)o->nu, nb = (size_t)o->nb, N = (size_t)o->N, nw = (size_t)o->nw;
  const size_t na = (size_t)o->nxa, nL = (size_t)o->nL, nM = (size_t)o->nM;
  const size_t m = (size_t)(o->mE + o->mI);
  int nf = 1;
  const int cnt[5] = {p->n_path, p->n_term, p->n_l1, o->nL, o->nM};
  for (int i = 0; i < 5; i++) nf = cnt[i] > nf ? cnt[i] : nf;
  const size_t nr = nL > 0 ? nL : 1;
  o->mw_f = get(&f, na + nu, sizeof(double)), o->mw_J = get(&f, nx * nx, sizeof(double));
  o->mw_Ju = get(&f, nx * nu, sizeof(double)), o->mw_r = get(&f, nr, sizeof(double));
  o->mw_rx = get(&f, nr * nx, sizeof(double)), o->mw_ru = get(&f, nr * nu, sizeof(double));
  o->fv = get(&f, (size_t)nf, sizeof(double)), o->fx = get(&f, (size_t)nf * nx, sizeof(double));
  o->fu = get(&f, (size_t)nf * nu, sizeof(double));
  o->xa = get(&f, na, sizeof(double)), o->Sxa = get(&f, na * na, sizeof(double)), o->Sua = get(&f, na * nu, sizeof(double));
  for (int i = 0; i < 3; i++) {
    ocp_point *q = &o->pt[i];
    q->w = get(&f, nw, sizeof(double)), q->c = get(&f, m, sizeof(double)), q->grad = get(&f, nw, sizeof(double));
    q->jv = get(&f, (size_t)o->nnzJ, sizeof(double)), q->phi = get(&f, N * nx, sizeof(double));
    q->Sx = get(&f, N * nx * nx, sizeof(double)), q->Su = get(&f, N * nx * nu, sizeof(double));
    q->gn = get(&f, N * 2 * nL * nb + nM * nx, sizeof(double));
    q->sig = get(&f, N, sizeof(unsigned));
  }
  o->y = get(&f, m, sizeof(double)), o->yq = get(&f, m, sizeof(double)), o->yq2 = get(&f, m, sizeof(double));
  o->d = get(&f, nw, sizeof(double)), o->dsoc = get(&f, nw, sizeof(double)), o->gl = get(&f, nw, sizeof(double)), o->gl2 = get(&f, nw, sizeof(double));
  o->B = get(&f, N * nb * nb + nx * nx, sizeof(double)), o->A = get(&f, N * nb * nb + nx * nx, sizeof(double));
  o->bs = get(&f, nb, sizeof(double)), o->by = get(&f, nb, sizeof(double)), o->bBs = get(&f, nb, sizeof(double));
  o->tmp = get(&f, nw > m ? nw : m, sizeof(double));
  o->w_best = get(&f, nw, sizeof(double)), o->y_best = get(&f, m, sizeof(double)), o->wg = get(&f, nw, sizeof(double));
  o->m_dyn = get(&f, N * nx, sizeof(double)), o->m_x0 = get(&f, nx, sizeof(double));
  o->m_xb = get(&f, (N + 1) * nx, sizeof(double)), o->m_ub = get(&f, N * nu, sizeof(double));
  o->m_path = get(&f, (N + 1) * (size_t)p->n_path, sizeof(double));
  o->m_term = get(&f, (size_t)p->n_term, sizeof(double)), o->m_l1 = get(&f, (size_t)p->n_l1, sizeof(double));
  return f ? FESD_ERR_NOMEM : FESD_OK;
}

int fesd_ocp_create(fesd_ocp **op, const fesd_ocp_problem *p, const fesd_ocp_settings *s) {
  if (!op) return FESD_ERR_NULL;
  *op = NULL;
  if (!p) return FESD_ERR_NULL;
  fesd_ocp_settings def;
  if (!s) fesd_ocp_settings_default(&def), s = &def;
  int st = check_settings(s);
  if (!st) st = check_problem(p, s);
  if (st) return st;
  fesd_ocp *o = calloc(1, sizeof(*o));
  if (!o) return FESD_ERR_NOMEM;
  o->p = *p;
  o->umodel = *p->model;
  o->p.model = &o->umodel;
  o->set = *s;
  o->set.integrator.sensitivities = 1;
  if (o->set.hessian == FESD_OCP_HESSIAN_AUTO)
    o->set.hessian = !(!p->lagrange && !p->mayer && (p->n_lagrange_lsq > 0 || p->n_mayer_lsq > 0))
                         ? FESD_OCP_HESSIAN_BFGS
                     /* the standard method's map has kinks wherever a switch crosses a step
                      * boundary: secant pairs across them are garbage (measured on ocp_step_eq:
                      * line search failure); FESD's map is smooth for a fixed switch structure */
                     : o->set.integrator.method == FESD_METHOD_FESD ? FESD_OCP_HESSIAN_GN_SR1
                                                                    : FESD_OCP_HESSIAN_GAUSS_NEWTON;
  o->nx = p->model->nx, o->nu = p->model->nu, o->N = p->n_ctrl, o->nb = o->nx + o->nu;
  o->nL = p->n_lagrange_lsq, o->nM = p->n_mayer_lsq;
  o->cost_state = p->lagrange || o->nL > 0;
  o->nxa = o->nx + o->cost_state;
  o->nw = o->N * o->nb + o->nx + p->n_l1;
  o->T = (p->tf - p->t0) / o->N;
  int f = 0;
  const int nx = o->nx, nu = o->nu;
  o->x0 = copy_or(&f, p->x0, nx, 0), o->x0_lb = copy_or(&f, p->x0_lb, nx, 0), o->x0_ub = copy_or(&f, p->x0_ub, nx, 0);
  o->x_lb = copy_or(&f, p->x_lb, nx, -INFINITY), o->x_ub = copy_or(&f, p->x_ub, nx, INFINITY);
  o->u_lb = copy_or(&f, p->u_lb, nu, -INFINITY), o->u_ub = copy_or(&f, p->u_ub, nu, INFINITY);
  o->path_lb = copy_or(&f, p->path_lb, p->n_path, -INFINITY), o->path_ub = copy_or(&f, p->path_ub, p->n_path, INFINITY);
  o->term_lb = copy_or(&f, p->term_lb, p->n_term, -INFINITY), o->term_ub = copy_or(&f, p->term_ub, p->n_term, INFINITY);
  o->l1_w = copy_or(&f, p->l1_weight, p->n_l1, 0);
  o->x0_free = get(&f, (size_t)nx, 1);
  o->lb = get(&f, (size_t)o->nw, sizeof(double)), o->ub = get(&f, (size_t)o->nw, sizeof(double));
  if (f) {
    fesd_ocp_free(&o);
    return FESD_ERR_NOMEM;
  }
  for (int i = 0; i < nx; i++) {
    o->x0_free[i] = p->x0_lb && o->x0_lb[i] < o->x0_ub[i];
    if (o->x0_free[i]) o->x0[i] = fmin(fmax(o->x0[i], o->x0_lb[i]), o->x0_ub[i]);
  }
  variable_bounds(o);
  fesd__ocp_emit(o, NULL, EMIT_COUNT);
  o->jr = get(&f, (size_t)o->nnzJ, sizeof(int)), o->jc = get(&f, (size_t)o->nnzJ, sizeof(int));
  o->rows = get(&f, (size_t)(o->mE + o->mI), sizeof(ocp_row));
  if (f || (st = alloc_all(o))) {
    fesd_ocp_free(&o);
    return FESD_ERR_NOMEM;
  }
  fesd__ocp_emit(o, NULL, EMIT_PATTERN);
  o->cur = &o->pt[0], o->trial = &o->pt[1], o->spare = &o->pt[2];
  fesd__ocp_model_init(o);
  st = fesd_create(&o->it, &o->model, &o->set.integrator);
  if (!st) st = fesd__ocp_qp_setup(o, &o->qp, 0);
  if (!st) st = fesd__ocp_qp_setup(o, &o->qe, 1);
  if (!st) st = fesd__ocp_presolve_create(o, s);
  if (st) {
    fesd_ocp_free(&o);
    return st;
  }
  *op = o;
  return FESD_OK;
}

int fesd_ocp_set_x0(fesd_ocp *o, const double *x0) {
  if (!o || !x0) return FESD_ERR_NULL;
  for (int i = 0; i < o->nx; i++)
    if (!isfinite(x0[i])) return FESD_ERR_INVALID_ARG;
  for (int i = 0; i < o->nx; i++) o->x0[i] = o->x0_free[i] ? fmin(fmax(x0[i], o->x0_lb[i]), o->x0_ub[i]) : x0[i];
  return FESD_OK;
}

static double clampd(double v, double lo, double hi) { return v < lo ? lo : v > hi ? hi : v; }

int fesd_ocp_set_guess(fesd_ocp *o, const double *x, const double *u) {
  if (!o) return FESD_ERR_NULL;
  const int nx = o->nx, nu = o->nu, nb = o->nb, N = o->N, cN = N * nb;
  double *w = o->wg;
  for (int k = 0; k < N; k++)
    for (int i = 0; i < nu; i++) w[k * nb + nx + i] = u ? u[k * nu + i] : 0.0;
  for (int i = 0; i < nx; i++) w[i] = x && o->x0_free[i] ? x[i] : o->x0[i];
  /* simulated states: by the solve's first evaluation, which integrates the intervals anyway
   * (eval.c: a failed interval keeps the state constant; the SQP repairs what is infeasible) */
  const int simulate = !x && o->set.init == FESD_OCP_INIT_SIMULATE;
  for (int k = 1; k <= N; k++) memcpy(w + k * nb, x ? x + (size_t)k * nx : o->x0, (size_t)nx * sizeof(double));
  for (int j = 0; j < cN + nx; j++) {
    if (!isfinite(w[j])) return FESD_ERR_INVALID_ARG;
    w[j] = clampd(w[j], o->lb[j], o->ub[j]);
  }
  o->guess_pending = simulate;
  /* L1 slacks at |r1(x_N)| */
  if (o->p.n_l1 > 0 && !simulate) {
    int st = fesd__ocp_call(o, o->p.l1, o->p.n_l1, o->p.tf, w + cN, NULL, 0);
    if (st) return st;
    for (int i = 0; i < o->p.n_l1; i++) w[cN + nx + i] = fabs(o->fv[i]);
  }
  memset(o->y_best, 0, (size_t)(o->mE + o->mI) * sizeof(double));
  o->have_guess = 1;
  o->fresh_guess = 1;
  return FESD_OK;
}

int fesd_ocp_dims(const fesd_ocp *o, int *n_var, int *n_eq, int *n_ineq) {
  if (!o) return FESD_ERR_NULL;
  if (n_var) *n_var = o->nw;
  if (n_eq) *n_eq = o->mE;
  if (n_ineq) *n_ineq = o->mI;
  return FESD_OK;
}
