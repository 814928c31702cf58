/* Evaluation of the NLP at a point: one integrator step per control interval (state, cost
 * state and their IFT sensitivities), objective and gradient, constraints and Jacobian
 * (emit.c), and the Gauss-Newton data of the least-squares terms. */
#include <math.h>
#include <string.h>

#include "common/timer.h"
#include "ocp/ocp_internal.h"

static int all_finite(const double *v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

int fesd__ocp_call(fesd_ocp *o, fesd_ocp_fn fn, int n, double t, const double *x, const double *u, int jac) {
  const size_t nx = (size_t)o->nx, nu = (size_t)o->nu, nn = (size_t)n;
  for (size_t i = 0; i < nn; i++) o->fv[i] = NAN;
  if (jac) {
    for (size_t i = 0; i < nn * nx; i++) o->fx[i] = NAN;
    for (size_t i = 0; i < nn * nu; i++) o->fu[i] = NAN;
  }
  const int wu = jac && u && nu > 0;
  if (fn(t, x, u, o->fv, jac ? o->fx : NULL, wu ? o->fu : NULL, o->p.user)) return FESD_ERR_CALLBACK;
  if (!all_finite(o->fv, nn) || (jac && !all_finite(o->fx, nn * nx)) || (wu && !all_finite(o->fu, nn * nu)))
    return FESD_ERR_NONFINITE;
  return FESD_OK;
}

int fesd__ocp_simulate(fesd_ocp *o, int k, const double *s, const double *q, double *xend, double *l, int sens,
                       int *flags) {
  const int nx = o->nx, na = o->nxa;
  const double t0 = fesd__thread_cpu_time();
  memcpy(o->xa, s, (size_t)nx * sizeof(double));
  if (o->cost_state) o->xa[nx] = 0.0; /* the cost state restarts in every interval */
  fesd_step_info si;
  int st = fesd_set_state(o->it, o->p.t0 + k * o->T, o->xa, q);
  if (!st) st = fesd_step(o->it, q, o->T, &si);
  o->info.integrations++;
  if (!st) {
    fesd_get_state(o->it, NULL, o->xa);
    memcpy(xend, o->xa, (size_t)nx * sizeof(double));
    *l = o->cost_state ? o->xa[nx] : 0.0;
    if (flags) *flags |= si.flags;
    o->last_split = si.splits + si.substeps;
    if (sens) st = fesd_get_sensitivities(o->it, o->Sxa, o->nu > 0 ? o->Sua : NULL);
  } else {
    o->info.integrator_failures++;
  }
  (void)na;
  o->t_int += fesd__thread_cpu_time() - t0;
  return st;
}

/* The switch structure of the last step: FNV-1a over its events' subsystems, kinds and active
 * sets (not their times) and over the integrator's halvings and sub-steps (split: a halved step
 * is another discretisation of the interval). Two points whose interval k has different hashes
 * lie on different pieces of Phi_k, which need not join continuously (docs/ocp.md); the
 * verbose log and info.stall_interval name such intervals. */
static unsigned structure_hash(const fesd_integrator *it, int split) {
  const fesd_event *ev;
  int n;
  unsigned h = 2166136261u;
  if (fesd_last_events(it, &ev, &n)) return 0;
#define MIX(v) (h = (h ^ (unsigned)(v)) * 16777619u)
  MIX(split);
  for (int e = 0; e < n; e++) {
    MIX(ev[e].sys), MIX(ev[e].kind), MIX(ev[e].n_before), MIX(ev[e].n_after);
    for (int i = 0; i < ev[e].n_before; i++) MIX(ev[e].before[i]);
    for (int i = 0; i < ev[e].n_after; i++) MIX(ev[e].after[i]);
  }
#undef MIX
  return h;
}

/* Gauss-Newton data of interval k: the least-squares residual's Jacobian w.r.t. (x_k, q_k) at
 * the interval start and, by the chain rule through the sensitivities, at its end */
static int gn_interval(fesd_ocp *o, ocp_point *pt, int k) {
  const int nx = o->nx, nu = o->nu, nb = o->nb, nL = o->nL;
  const double *w = pt->w + (size_t)k * nb, *Sx = pt->Sx + (size_t)k * nx * nx, *Su = pt->Su + (size_t)k * nx * nu;
  double *J0 = pt->gn + (size_t)k * 2 * nL * nb, *J1 = J0 + (size_t)nL * nb;
  const double tk = o->p.t0 + k * o->T;
  int st = fesd__ocp_call(o, o->p.lagrange_lsq, nL, tk, w, w + nx, 1);
  if (st) return st;
  memcpy(J0, o->fx, (size_t)nL * nx * sizeof(double));
  memcpy(J0 + (size_t)nL * nx, o->fu, (size_t)nL * nu * sizeof(double));
  st = fesd__ocp_call(o, o->p.lagrange_lsq, nL, tk + o->T, pt->phi + (size_t)k * nx, w + nx, 1);
  if (st) return st;
  for (int i = 0; i < nL; i++) {
    for (int j = 0; j < nx; j++) {
      double a = 0;
      for (int l = 0; l < nx; l++) a += o->fx[(size_t)l * nL + i] * Sx[(size_t)j * nx + l];
      J1[(size_t)j * nL + i] = a;
    }
    for (int j = 0; j < nu; j++) {
      double a = o->fu[(size_t)j * nL + i];
      for (int l = 0; l < nx; l++) a += o->fx[(size_t)l * nL + i] * Su[(size_t)j * nx + l];
      J1[(size_t)(nx + j) * nL + i] = a;
    }
  }
  return FESD_OK;
}

/* The end of the guess's chain x_{k+1} = Phi_k(x_k, q_k) (evaluate with chain): after a failed
 * interval the state stays constant; then every state is clamped to its bounds (returns 1 when
 * one moved by more than round-off: the intervals were integrated from the unclamped states,
 * not at the guess; ocp_step_eq's guess reaches |v| = 2 at k = 3 and overshoots by 1 ulp) and
 * the L1 slacks are set at |r1(x_N)|. */
static int chain_end(fesd_ocp *o, ocp_point *pt, int failed_at) {
  const int nx = o->nx, nb = o->nb, N = o->N, cN = N * nb;
  double *w = pt->w;
  for (int k = failed_at + 1; k <= N; k++) memcpy(w + k * nb, w + (k - 1) * nb, (size_t)nx * sizeof(double));
  int clamped = 0;
  for (int j = nb; j < cN + nx; j++) {
    const double v = w[j] < o->lb[j] ? o->lb[j] : w[j] > o->ub[j] ? o->ub[j] : w[j];
    clamped |= fabs(v - w[j]) > 1e-14 * (1 + fabs(v)); /* more than round-off */
    w[j] = v;
  }
  if (o->p.n_l1 > 0) {
    int st = fesd__ocp_call(o, o->p.l1, o->p.n_l1, o->p.tf, w + cN, NULL, 0);
    if (st) return st;
    for (int i = 0; i < o->p.n_l1; i++) w[cN + nx + i] = fabs(o->fv[i]);
  }
  return clamped;
}

/* Everything at pt->w; chain: the guess, whose states are simulated on the way. */
static int evaluate(fesd_ocp *o, ocp_point *pt, int chain) {
  const fesd_ocp_problem *p = &o->p;
  const int nx = o->nx, nu = o->nu, na = o->nxa, nb = o->nb, N = o->N, cN = N * nb;
  double *w = pt->w;
  double *g = pt->grad;
  int st;
  memset(g, 0, (size_t)o->nw * sizeof(double));
  pt->f = 0.0;
  pt->flags = 0;
  for (int k = 0; k < N; k++) {
    double l;
    st = fesd__ocp_simulate(o, k, w + k * nb, w + k * nb + nx, pt->phi + (size_t)k * nx, &l, 1, &pt->flags);
    if (st) {
      if (chain && st != FESD_ERR_NOMEM) chain_end(o, pt, k);
      return st;
    }
    pt->sig[k] = structure_hash(o->it, o->last_split);
    if (chain) memcpy(w + (k + 1) * nb, pt->phi + (size_t)k * nx, (size_t)nx * sizeof(double));
    double *Sx = pt->Sx + (size_t)k * nx * nx, *Su = pt->Su + (size_t)k * nx * nu;
    for (int j = 0; j < nx; j++) memcpy(Sx + (size_t)j * nx, o->Sxa + (size_t)j * na, (size_t)nx * sizeof(double));
    for (int j = 0; j < nu; j++) memcpy(Su + (size_t)j * nx, o->Sua + (size_t)j * na, (size_t)nx * sizeof(double));
    if (o->cost_state) {
      pt->f += l;
      for (int j = 0; j < nx; j++) g[k * nb + j] += o->Sxa[(size_t)j * na + nx];
      for (int j = 0; j < nu; j++) g[k * nb + nx + j] += o->Sua[(size_t)j * na + nx];
    }
    if (o->nL > 0 && (st = gn_interval(o, pt, k))) return st;
  }
  if (chain && (st = chain_end(o, pt, N))) return st;
  if (p->mayer) {
    if ((st = fesd__ocp_call(o, p->mayer, 1, p->tf, w + cN, NULL, 1))) return st;
    pt->f += o->fv[0];
    for (int j = 0; j < nx; j++) g[cN + j] += o->fx[j];
  }
  if (o->nM > 0) {
    const int nM = o->nM;
    if ((st = fesd__ocp_call(o, p->mayer_lsq, nM, p->tf, w + cN, NULL, 1))) return st;
    for (int i = 0; i < nM; i++) pt->f += o->fv[i] * o->fv[i];
    for (int j = 0; j < nx; j++)
      for (int i = 0; i < nM; i++) g[cN + j] += 2 * o->fv[i] * o->fx[(size_t)j * nM + i];
    memcpy(pt->gn + (size_t)N * 2 * o->nL * nb, o->fx, (size_t)nM * nx * sizeof(double));
  }
  for (int i = 0; i < p->n_l1; i++) {
    pt->f += o->l1_w[i] * w[cN + nx + i];
    g[cN + nx + i] = o->l1_w[i];
  }
  if ((st = fesd__ocp_emit(o, pt, EMIT_VALUES))) return st;
  pt->viol = fesd__ocp_violation(o, pt->c);
  return FESD_OK;
}

int fesd__ocp_eval(fesd_ocp *o, ocp_point *pt) { return evaluate(o, pt, 0); }

int fesd__ocp_eval_guess(fesd_ocp *o, ocp_point *pt) {
  const int st = evaluate(o, pt, 1);
  return st == 1 ? evaluate(o, pt, 0) : st; /* clamped: at the guess again */
}

double fesd__ocp_violation(const fesd_ocp *o, const double *c) {
  double v = 0;
  for (int r = 0; r < o->mE; r++) v += fabs(c[r]);
  for (int r = o->mE; r < o->mE + o->mI; r++) v += c[r] < 0 ? -c[r] : 0.0;
  return v;
}

void fesd__ocp_lagrangian_grad(const fesd_ocp *o, const ocp_point *pt, const double *mult, double *out) {
  memcpy(out, pt->grad, (size_t)o->nw * sizeof(double));
  for (int e = 0; e < o->nnzJ; e++) out[o->jc[e]] -= pt->jv[e] * mult[o->jr[e]];
}

void fesd__ocp_jmul(const fesd_ocp *o, const ocp_point *pt, const double *d, double *out) {
  memcpy(out, pt->c, (size_t)(o->mE + o->mI) * sizeof(double));
  for (int e = 0; e < o->nnzJ; e++) out[o->jr[e]] += pt->jv[e] * d[o->jc[e]];
}
