/* The SQP iteration: QP step (normal, or elastic when the linearisation is inconsistent),
 * l1 exact-penalty line search with a second-order correction, Hessian update, KKT test. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "common/timer.h"
#include "ocp/ocp_internal.h"

static void say(fesd_ocp *o, const char *fmt, ...) {
  if (!o->set.verbose) return;
  char buf[256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof(buf), fmt, ap);
  va_end(ap);
  if (o->set.log) o->set.log(o->set.log_user, buf);
  else printf("%s\n", buf);
}

static double inf_norm(const double *v, int n) {
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

/* KKT residuals of pt with multipliers mult into info fields; returns the score
 * max(residual / tolerance) (<= 1: converged) */
static double kkt(fesd_ocp *o, const ocp_point *pt, const double *mult, fesd_ocp_info *r) {
  const int mE = o->mE, mI = o->mI;
  fesd__ocp_lagrangian_grad(o, pt, mult, o->gl);
  r->stationarity = inf_norm(o->gl, o->nw);
  r->stationarity_rel = r->stationarity / fmax(1.0, inf_norm(pt->grad, o->nw));
  double feas = 0, comp = 0, mn = 0;
  for (int i = 0; i < mE; i++) feas = fmax(feas, fabs(pt->c[i]));
  for (int i = mE; i < mE + mI; i++) {
    feas = fmax(feas, -pt->c[i]);
    comp = fmax(comp, fabs(mult[i] * pt->c[i]));
    mn = fmin(mn, mult[i]);
  }
  r->feasibility = feas;
  r->complementarity = comp;
  r->min_multiplier = mn;
  r->objective = pt->f;
  r->integrator_flags = pt->flags;
  const fesd_ocp_settings *s = &o->set;
  return fmax(fmax(r->stationarity_rel / s->tol_stat, feas / s->tol_feas), fmax(comp, -mn) / s->tol_comp);
}

/* QP step at the current point: d, yq, the linearised violation; elastic mode while the
 * linearisation is inconsistent, with the penalty steered so that the step achieves a tenth of
 * the best possible decrease of the linearised violation (Byrd, Nocedal, Waltz); *infeasible
 * when no decrease is possible at a point that violates the constraints. */
static int qp_step(fesd_ocp *o, double *nu, int *elastic, double *vlin, int *infeasible) {
  const ocp_point *c = o->cur;
  const int m = o->mE + o->mI;
  int st;
  *infeasible = 0;
  if (!*elastic) {
    st = fesd__ocp_qp_solve(o, &o->qp, c, c->c, 0.0, o->d, o->yq, vlin);
    if (st == FESD_ERR_NOMEM) return st;
    /* The QP's dual regularisation solves an inconsistent linearisation too, with multipliers of
     * c / reg_dual and a step that leaves the violation: a consistent QP takes it to about 0.
     * Measured: a mass stuck by friction (dPhi/du = 0) asked to move, viol 1 for 200 iterations
     * with |d| = 1e-16 and the penalty at 1e11, ITER_LIMIT instead of INFEASIBLE. */
    if (!st && !(c->viol > o->set.tol_feas && *vlin > fmax(o->set.tol_feas, 0.5 * c->viol))) return st;
    o->info.qp_failures++;
    if (st) say(o, "  QP failed: %s after %d iterations; elastic mode", fesd_status_name(st), o->qp.iterations);
    else say(o, "  QP leaves the linearised violation at %.2e of %.2e: inconsistent; elastic mode", *vlin, c->viol);
    *elastic = 1;
  }
  double nue = fmax(*nu, 1.0);
  st = fesd__ocp_qp_solve(o, &o->qe, c, c->c, nue, o->d, o->yq, vlin);
  o->info.qp_elastic++;
  if (st) say(o, "  elastic QP failed: %s after %d iterations", fesd_status_name(st), o->qe.iterations);
  if (st) return st == FESD_ERR_NOMEM ? st : FESD_ERR_QP;
  if (*vlin <= o->set.tol_feas) {
    *elastic = 0; /* consistent again: back to the normal QP */
    return FESD_OK;
  }
  double vinf;
  st = fesd__ocp_qp_solve(o, &o->qe, c, c->c, o->set.penalty_max, o->dsoc, o->yq2, &vinf);
  o->info.qp_elastic++;
  if (st) say(o, "  elastic QP (nu = %.1e) failed: %s after %d iterations", o->set.penalty_max, fesd_status_name(st), o->qe.iterations);
  if (st) return st == FESD_ERR_NOMEM ? st : FESD_ERR_QP;
  const double v = c->viol;
  if (v > o->set.tol_feas && v - vinf <= fmax(o->set.tol_feas, 1e-9 * v)) {
    *infeasible = 1;
    return FESD_OK;
  }
  while (v - *vlin < 0.1 * (v - vinf) && nue < o->set.penalty_max) {
    nue = fmin(10 * nue, o->set.penalty_max);
    if (nue >= o->set.penalty_max) {
      memcpy(o->d, o->dsoc, (size_t)o->nw * sizeof(double));
      memcpy(o->yq, o->yq2, (size_t)m * sizeof(double));
      *vlin = vinf;
      break;
    }
    st = fesd__ocp_qp_solve(o, &o->qe, c, c->c, nue, o->d, o->yq, vlin);
    o->info.qp_elastic++;
    if (st) return st == FESD_ERR_NOMEM ? st : FESD_ERR_QP;
  }
  *nu = fmax(*nu, nue);
  return FESD_OK;
}

/* the first interval whose switch structure differs between a and b (-1: none) */
static int first_change(const fesd_ocp *o, const ocp_point *a, const ocp_point *b) {
  for (int k = 0; k < o->N; k++)
    if (a->sig[k] != b->sig[k]) return k;
  return -1;
}

/* the intervals whose switch structure differs between a and b, as text (verbose log) */
static const char *changed(const fesd_ocp *o, const ocp_point *a, const ocp_point *b, char *buf, size_t n) {
  size_t len = 0;
  buf[0] = 0;
  for (int k = 0; k < o->N && len + 8 < n; k++)
    if (a->sig[k] != b->sig[k]) len += (size_t)snprintf(buf + len, n - len, " %d", k);
  return len ? buf : " none";
}

static void step_to(const fesd_ocp *o, ocp_point *t, const double *d, double alpha) {
  const double *w = o->cur->w;
  for (int j = 0; j < o->nw; j++) {
    double v = w[j] + alpha * d[j];
    t->w[j] = v < o->lb[j] ? o->lb[j] : v > o->ub[j] ? o->ub[j] : v; /* round-off only */
  }
}

static void swap(ocp_point **a, ocp_point **b) {
  ocp_point *t = *a;
  *a = *b;
  *b = t;
}

/* Second-order correction: the QP again with constants c(w + d) - J(w) d */
static int soc_step(fesd_ocp *o, int elastic, double nu, double phi0, double D, double noise) {
  const int m = o->mE + o->mI;
  fesd__ocp_jmul(o, o->cur, o->d, o->tmp); /* c + J d */
  for (int r = 0; r < m; r++) o->tmp[r] = o->trial->c[r] - (o->tmp[r] - o->cur->c[r]);
  double vl;
  int st = fesd__ocp_qp_solve(o, elastic ? &o->qe : &o->qp, o->cur, o->tmp, elastic ? fmax(nu, 1.0) : 0.0, o->dsoc,
                              o->yq2, &vl);
  if (st) return 0;
  step_to(o, o->spare, o->dsoc, 1.0);
  if (fesd__ocp_eval(o, o->spare)) return 0;
  return o->spare->f + nu * o->spare->viol <= phi0 + o->set.armijo * D + noise;
}

/* The merit memory applies in the local phase only: after LOCAL_PHASE consecutive full steps
 * (alpha = 1) and with a QP step shorter than the last one. Measured on ocp_step_eq, memory 2:
 * with the memory in every iteration, wild early steps got through (FESD Radau IIA s = 2,
 * N_FE = 2: 33 iterations instead of 11; the standard method's s = 2, N_FE = 2 failed); after
 * 2 full steps the standard method's s = 2, N_FE = 2 still failed; after 3, the memory only
 * skips second-order corrections (docs/ocp.md). */
#define LOCAL_PHASE 3

/* Merit memory (settings.nonmonotone): the current iterate enters it; the reference merit is
 * the largest one remembered, evaluated with the current penalty. */
static void remember(fesd_ocp *o) {
  const int m = o->set.nonmonotone;
  for (int i = o->hist_n < m ? o->hist_n : m - 1; i > 0; i--) {
    o->hist_f[i] = o->hist_f[i - 1];
    o->hist_v[i] = o->hist_v[i - 1];
  }
  o->hist_f[0] = o->cur->f, o->hist_v[0] = o->cur->viol;
  if (o->hist_n < m) o->hist_n++;
}

static double reference_merit(const fesd_ocp *o, double nu) {
  double r = o->cur->f + nu * o->cur->viol;
  for (int i = 0; i < o->hist_n; i++) r = fmax(r, o->hist_f[i] + nu * o->hist_v[i]);
  return r;
}

/* l1 merit line search along o->d; the accepted point becomes o->trial. With a merit memory
 * (settings.nonmonotone > 1) the Armijo test is against the largest remembered merit: a full
 * step that raises the merit a little (the Maratos effect of the nonlinear interval maps near
 * the solution) is taken without the second-order correction's extra evaluation. */
static int line_search(fesd_ocp *o, double nu, int elastic, double vlin, int relax, double *alpha_out) {
  const ocp_point *c = o->cur;
  const double phi0 = relax ? reference_merit(o, nu) : c->f + nu * c->viol;
  double gd = 0;
  for (int j = 0; j < o->nw; j++) gd += c->grad[j] * o->d[j];
  const double D = fmin(gd + nu * (vlin - c->viol), 0.0);
  /* merit values carry the integrator's round-off: a predicted decrease below it cannot be
   * verified, and such a step is taken when it does not increase the merit beyond it */
  const double noise = 1e-12 * (1 + fabs(phi0));
  const double slack = -D <= noise ? noise : 0.0;
  const double dmax = inf_norm(o->d, o->nw), wmax = inf_norm(c->w, o->nw);
  double alpha = 1.0;
  for (int ls = 0; ls < o->set.max_backtracks; ls++) {
    if (ls > 0 && alpha * dmax <= 1e-15 * (1 + wmax)) break; /* no change of w left to try */
    if (ls > 0) o->info.line_search_trials++;
    step_to(o, o->trial, o->d, alpha);
    int st = fesd__ocp_eval(o, o->trial);
    if (st == FESD_ERR_NOMEM) return st;
    if (o->set.verbose) {
      char buf[96];
      if (st) say(o, "    alpha %.3g: %s", alpha, fesd_status_name(st));
      else
        say(o, "    alpha %.3g: merit %+.3e (f %+.3e, viol %.2e) vs %+.3e; structure changed in:%s", alpha,
            o->trial->f + nu * o->trial->viol - phi0, o->trial->f - c->f, o->trial->viol, o->set.armijo * alpha * D + slack,
            changed(o, c, o->trial, buf, sizeof(buf)));
    }
    if (!st && o->trial->f + nu * o->trial->viol <= phi0 + o->set.armijo * alpha * D + slack) {
      *alpha_out = alpha;
      return FESD_OK;
    }
    if (!st && first_change(o, c, o->trial) >= 0) o->kink = first_change(o, c, o->trial);
    if (!st && ls == 0 && o->set.soc && soc_step(o, elastic, nu, phi0, D, slack)) {
      swap(&o->trial, &o->spare);
      o->info.soc_steps++;
      *alpha_out = 1.0;
      return FESD_OK;
    }
    alpha *= o->set.backtrack;
  }
  return FESD_ERR_LINE_SEARCH;
}

static void keep_best(fesd_ocp *o, double score, const fesd_ocp_info *r) {
  if (!(score < o->best_score)) return;
  o->best_score = score;
  memcpy(o->w_best, o->cur->w, (size_t)o->nw * sizeof(double));
  memcpy(o->y_best, o->y, (size_t)(o->mE + o->mI) * sizeof(double));
  o->best_info = *r;
}

/* No-progress rule. An accepted step with alpha < 0.1 means the QP model was poor along d; when
 * stall_window such steps follow one another and the best KKT score has not halved meanwhile,
 * the solve is stalled (measured cause: a step map that is discontinuous or kinked at the
 * iterate, e.g. a node at a switching-structure change, where no Hessian helps). GN_SR1 then
 * falls back to plain Gauss-Newton for the rest of the solve (its SR1 pairs straddle the kink);
 * a second stall, or one with any other Hessian, ends the solve with FESD_ERR_LINE_SEARCH and
 * the best iterate, instead of up to max_iter costly damped iterations. */
typedef struct {
  int n;         /* consecutive poor steps without the score halving */
  double ref;    /* best score when the count restarted */
} stall_track;

/* returns 1 when the window is full (and restarts the count) */
static int stalled(const fesd_ocp *o, stall_track *t, double alpha) {
  if (o->set.stall_window <= 0) return 0;
  if (alpha >= 0.1 || o->best_score <= 0.5 * t->ref) {
    t->n = 0;
    t->ref = o->best_score;
    return 0;
  }
  if (++t->n < o->set.stall_window) return 0;
  t->n = 0;
  t->ref = o->best_score;
  return 1;
}

/* warm: the start has multipliers (a previous solve or the presolve), so it may pass the KKT
 * test at once */
static int iterate(fesd_ocp *o, int warm) {
  const int m = o->mE + o->mI;
  double nu = o->set.penalty0;
  int elastic = 0, reset_done = 0, st;
  fesd_ocp_hessian hess = o->set.hessian; /* GN_SR1 may fall back to GAUSS_NEWTON */
  stall_track stall = {0, INFINITY};
  o->kink = -1;
  o->info.stall_interval = -1;
  o->hist_n = 0;
  double prev_d = INFINITY;
  int n_full = 0;
  for (int iter = 0;; iter++) {
    remember(o);
    fesd_ocp_info r = {0};
    const double score = kkt(o, o->cur, o->y, &r);
    keep_best(o, score, &r);
    if ((iter > 0 || warm) && score <= 1.0) return FESD_OK;
    if (iter >= o->set.max_iter) return FESD_ERR_ITER_LIMIT;
    if (hess == FESD_OCP_HESSIAN_GAUSS_NEWTON) fesd__ocp_hessian_gn(o, o->cur);
    if (hess == FESD_OCP_HESSIAN_GN_SR1) fesd__ocp_hessian_gn_sr1(o, o->cur);
    double vlin;
    int infeasible;
    st = qp_step(o, &nu, &elastic, &vlin, &infeasible);
    if (st == FESD_ERR_QP && hess == FESD_OCP_HESSIAN_GN_SR1) {
      /* an indefinite SR1 correction can make the (elastic) QP unbounded: retry with GN */
      fesd__ocp_sr1_reset(o);
      fesd__ocp_hessian_gn_sr1(o, o->cur);
      o->info.hessian_resets++;
      st = qp_step(o, &nu, &elastic, &vlin, &infeasible);
    }
    if (st) return st;
    if (infeasible) return FESD_ERR_INFEASIBLE;
    /* exact penalty: nu above the multipliers (in elastic mode they are bounded by nu and the
     * steering in qp_step sets it) */
    if (!elastic) {
      double need = 0;
      for (int i = 0; i < m; i++) need = fmax(need, fabs(o->yq[i]));
      if (nu < 1.1 * need) nu = 2 * need;
    }
    double alpha = 0;
    const double dn = inf_norm(o->d, o->nw);
    const int relax = !elastic && n_full >= LOCAL_PHASE && dn < prev_d;
    st = line_search(o, nu, elastic, vlin, relax, &alpha);
    n_full = alpha == 1.0 ? n_full + 1 : 0, prev_d = dn;
    o->info.max_step = inf_norm(o->d, o->nw);
    say(o, "it %3d  f %.10e  viol %.2e  stat %.2e  comp %.2e  |d| %.2e  alpha %.3g  nu %.2e  qp %d  flags %x%s",
        iter, o->cur->f, o->cur->viol, r.stationarity_rel, r.complementarity, o->info.max_step, alpha, nu,
        (elastic ? o->qe.iterations : o->qp.iterations), o->cur->flags, elastic ? " elastic" : "");
    const int qn = hess == FESD_OCP_HESSIAN_BFGS || hess == FESD_OCP_HESSIAN_GN_SR1;
    if (st == FESD_ERR_LINE_SEARCH && qn && !reset_done) {
      /* a poor quasi-Newton model: start it again once */
      if (hess == FESD_OCP_HESSIAN_BFGS) fesd__ocp_hessian_reset(o);
      else fesd__ocp_sr1_reset(o);
      reset_done = 1;
      o->info.hessian_resets++;
      continue;
    }
    if (st) return st;
    reset_done = 0;
    if (hess == FESD_OCP_HESSIAN_BFGS) fesd__ocp_bfgs_update(o, o->cur, o->trial, o->yq);
    if (hess == FESD_OCP_HESSIAN_GN_SR1) {
      /* a backtracking step: the model was poor (far from the solution, or a switch structure
       * change in between); curvature learnt there misleads later, so restart from GN */
      if (alpha < 1.0 || elastic) { /* elastic: the multipliers are the penalty's, not the NLP's */
        fesd__ocp_sr1_reset(o);
        o->info.hessian_resets++;
      } else {
        fesd__ocp_sr1_update(o, o->cur, o->trial, o->yq);
      }
    }
    swap(&o->cur, &o->trial);
    memcpy(o->y, o->yq, (size_t)m * sizeof(double));
    o->info.iterations++;
    o->info.penalty = nu;
    if (alpha >= 0.1) o->kink = -1; /* only rejections within a run of poor steps count */
    if (stalled(o, &stall, alpha)) {
      if (hess != FESD_OCP_HESSIAN_GN_SR1) {
        o->info.stalled = 1;
        o->info.stall_interval = o->kink;
        if (o->kink >= 0)
          say(o, "  no progress in %d iterations: stop (trial points rejected where the switch structure of interval %d "
                 "changes: its step map is discontinuous or kinked there)", o->set.stall_window, o->kink);
        else
          say(o, "  no progress in %d iterations: stop", o->set.stall_window);
        return FESD_ERR_LINE_SEARCH;
      }
      say(o, "  no progress in %d iterations: Gauss-Newton from here", o->set.stall_window);
      hess = FESD_OCP_HESSIAN_GAUSS_NEWTON;
      o->info.hessian_fallback = 1;
    }
  }
}

/* The SQP's start at the guess wg (a guess still pending is simulated, into wg too), with the
 * multipliers y0 (NULL: zero). */
static int start_at_guess(fesd_ocp *o, const double *y0) {
  const int m = o->mE + o->mI;
  memcpy(o->cur->w, o->wg, (size_t)o->nw * sizeof(double));
  if (y0) memcpy(o->y, y0, (size_t)m * sizeof(double));
  else memset(o->y, 0, (size_t)m * sizeof(double));
  const int st = o->guess_pending ? fesd__ocp_eval_guess(o, o->cur) : fesd__ocp_eval(o, o->cur);
  if (o->guess_pending) memcpy(o->wg, o->cur->w, (size_t)o->nw * sizeof(double)); /* the simulated guess */
  return st;
}

/* A run of the SQP from the current point, with fresh Hessian approximations. */
static int run(fesd_ocp *o, int warm) {
  fesd__ocp_hessian_reset(o);
  fesd__ocp_sr1_reset(o);
  return iterate(o, warm);
}

int fesd_ocp_solve(fesd_ocp *o, fesd_ocp_info *info) {
  if (!o) return FESD_ERR_NULL;
  const double t0 = fesd__thread_cpu_time();
  const int m = o->mE + o->mI;
  memset(&o->info, 0, sizeof(o->info));
  o->info.stall_interval = -1;
  o->t_int = o->t_qp = 0;
  int st = FESD_OK;
  o->info.presolve_status = FESD_OK;
  if (!o->have_guess) st = fesd_ocp_set_guess(o, NULL, NULL);
  int pre = !st && fesd__ocp_presolve(o);
  if (pre) {
    say(o, "presolve (standard method, implicit Euler): %d iterations, %s", o->info.presolve_iterations,
        fesd_status_name(o->info.presolve_status));
    st = fesd__ocp_eval(o, o->cur);
    pre = !st;
    if (st && st != FESD_ERR_NOMEM) st = FESD_OK; /* its point cannot be evaluated: from the guess */
  }
  if (!pre && !st) st = start_at_guess(o, o->y_best); /* y_best: zero unless warm */
  o->info.presolve_used = pre;
  const int pending = o->guess_pending;
  o->guess_pending = 0;
  o->fresh_guess = 0;
  o->best_score = INFINITY;
  memset(&o->best_info, 0, sizeof(o->best_info));
  memcpy(o->w_best, o->cur->w, (size_t)o->nw * sizeof(double));
  if (!st) st = run(o, o->warm || pre);
  /* The presolve's point can be worse than the guess (measured: a relay oscillator, 3 crossings
   * per interval, T = 4, N = 8: LINE_SEARCH at iteration 0 from it, objective 250 and
   * infeasibility 2.1, where the guess converges to 23.763): a solve that fails from it at once
   * (within 2 iterations) is repeated from the guess, and the better best iterate of the two is
   * returned. Not one that fails later (the stall rule at a nonsmooth point): it would fail again
   * from the guess, at twice the cost (ocp_step_eq, Radau IIA s = 1: 0.55-1.6 s, not 0.2-0.3). */
  if (pre && st != FESD_OK && st != FESD_ERR_NOMEM && !o->warm && o->info.iterations <= 2) {
    const int st_pre = st;
    say(o, "from the presolve: %s; again from the guess", fesd_status_name(st));
    o->guess_pending = pending;
    st = start_at_guess(o, NULL);
    o->guess_pending = 0;
    if (!st) {
      const double best = o->best_score;
      st = run(o, 0);
      o->info.presolve_used = o->best_score < best ? 0 : 1;
      if (o->info.presolve_used) st = st_pre; /* the status of the run whose iterate is returned */
    } else if (st != FESD_ERR_NOMEM) {
      st = st_pre; /* the guess cannot be evaluated: the first run's iterate and status stand */
    }
  }
  /* the returned iterate: the best one (the last one on success) */
  fesd_ocp_info *r = &o->info;
  if (isfinite(o->best_score)) {
    r->objective = o->best_info.objective;
    r->stationarity = o->best_info.stationarity;
    r->stationarity_rel = o->best_info.stationarity_rel;
    r->feasibility = o->best_info.feasibility;
    r->complementarity = o->best_info.complementarity;
    r->min_multiplier = o->best_info.min_multiplier;
    r->integrator_flags = o->best_info.integrator_flags;
    memcpy(o->wg, o->w_best, (size_t)o->nw * sizeof(double));
    o->warm = 1;
  } else {
    r->objective = r->stationarity = r->stationarity_rel = r->feasibility = r->complementarity = NAN;
    memset(o->y_best, 0, (size_t)m * sizeof(double));
    o->warm = 0;
  }
  o->have_guess = 1;
  fesd__ocp_unpack_multipliers(o, o->y_best);
  r->status = st;
  r->time_total = fesd__thread_cpu_time() - t0;
  r->time_integration = o->t_int;
  r->time_qp = o->t_qp;
  r->time_other = r->time_total - o->t_int - o->t_qp;
  if (info) *info = *r;
  return st;
}
