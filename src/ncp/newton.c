/* Semismooth Newton (square) and Levenberg-Marquardt (over-determined) iterations
 * with an Armijo line search on psi = 1/2 ||F||^2, the plain solve, the smoothing
 * homotopy and the public residual. */
#include "common/timer.h"
#include "ncp/ncp_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* LM: ||J'F|| <= STATIONARY ||J||_F ||F|| is a stationary point of psi. */
#define LM_STATIONARY 1e-12
/* LM: a step that reduces ||F|| by less than STALL_GAIN while the angle measure
 * ||J'F|| / (||J|| ||F||) is below STALL_ANGLE counts as stagnation; STALL_COUNT
 * of them in a row (or a failed line search there) prove inconsistency. */
#define LM_STALL_GAIN 1e-3
#define LM_STALL_ANGLE 1e-3
#define LM_STALL_COUNT 3
/* Square systems: STALL_COUNT iterations in a row that reduce ||F|| by less than
 * STALL_GAIN mean a nonzero local minimizer of psi: FESD_ERR_LINE_SEARCH. */
#define STALL_GAIN 1e-6
#define STALL_COUNT 5
/* Trials for a Newton direction (smallest step 0.5^9 ~ 2e-3 with the default
 * backtrack factor) before the damped fallback direction takes over. */
#define NEWTON_TRIALS 10
#define LM_LAMBDA_STEP 4.0
#define LM_LAMBDA_MIN 1e-10
#define LM_LAMBDA_MAX 1e10

enum { DIR_NEWTON, DIR_LM, DIR_GRADIENT };
static const char *const dir_name[] = {"newton", "lm", "gradient"};

int fesd__ncp_call(fesd_ncp *ws, const double *z, double *raw, double *jac, fesd__ncp_stats *st) {
  double t0 = fesd__wall_time();
  int rc = ws->eval(z, raw, jac, ws->user);
  st->time_eval += fesd__wall_time() - t0;
  st->evals++;
  if (jac) st->jac_evals++;
  if (rc != 0) return FESD_ERR_CALLBACK;
  if (!fesd__all_finite(raw, ws->n_raw) || (jac && !fesd__all_finite(jac, ws->nnz)))
    return FESD_ERR_NONFINITE;
  return FESD_OK;
}

static double dot(const double *x, const double *y, int n) {
  double s = 0.0;
  for (int i = 0; i < n; i++) s += x[i] * y[i];
  return s;
}

/* (no fmax/fmin in these loops: they are libm calls; x is finite here) */
static double norm_inf(const double *x, int n) {
  double s = 0.0;
  for (int i = 0; i < n; i++) {
    const double a = fabs(x[i]);
    s = a > s ? a : s;
  }
  return s;
}

static void swap(double **a, double **b) {
  double *t = *a;
  *a = *b;
  *b = t;
}

static void project(const fesd_ncp *ws, double *z) {
  if (!ws->has_box) return;
  for (int i = 0; i < ws->n; i++) {
    const double lo = z[i] < ws->lb[i] ? ws->lb[i] : z[i];
    z[i] = lo > ws->ub[i] ? ws->ub[i] : lo;
  }
}

static void history_push(fesd_ncp_info *info, double r) {
  if (info->history_len == FESD_NCP_HISTORY) { /* keep the most recent entries */
    memmove(info->residual_history, info->residual_history + 1,
            (FESD_NCP_HISTORY - 1) * sizeof(double));
    info->history_len--;
  }
  info->residual_history[info->history_len++] = r;
}

/* Factorization and solve d = -J^{-1} rhs (LU) or -(J'J + mu I)^{-1} rhs (normal), timed
 * as one region (two clock reads per direction: at a few microseconds per factorization of
 * the small FESD systems, every clock read shows). */
static int factor_solve(fesd_ncp *ws, fesd__ls *ls, double mu, const double *rhs, fesd__ncp_stats *st) {
  const double t0 = fesd__wall_time();
  int rc = ls->ops->factor(ls, ws->vals, mu);
  st->factorizations++;
  if (rc == FESD_OK) {
    for (int i = 0; i < ws->n; i++) ws->d[i] = -rhs[i];
    rc = ls->ops->solve(ls, ws->d);
    if (rc == FESD_OK && !fesd__all_finite(ws->d, ws->n)) rc = FESD_ERR_SINGULAR;
  }
  st->time_linsolve += fesd__wall_time() - t0;
  return fesd__ncp_note(ws, rc);
}

/* d = -(J'J + mu I)^{-1} g; raises mu when the factorization is not positive definite. */
static int lm_step(fesd_ncp *ws, fesd__ls *ls, double mu, double jnorm, fesd__ncp_stats *st) {
  const double floor_mu = 1e-14 * jnorm * jnorm;
  mu = fmax(mu, floor_mu);
  for (int attempt = 0; attempt < 6; attempt++) {
    int rc = factor_solve(ws, ls, mu, ws->g, st);
    if (rc == FESD_OK || rc == FESD_ERR_NOMEM) return rc;
    mu = fmax(100.0 * mu, 1e-10 * jnorm * jnorm);
  }
  return FESD_ERR_SINGULAR;
}

/* g = J'F (the gradient of psi) and its 2-norm, from the assembled J; the dense LU
 * overwrites J, so it is assembled again after a factorization. */
static double gradient(fesd_ncp *ws, const double *jac, int factorized) {
  if (factorized && ws->active->ops->destroys_values) fesd__ncp_jacobian(ws, jac);
  fesd__ncp_jt_mul(ws, ws->F_c, ws->g);
  return sqrt(dot(ws->g, ws->g, ws->n));
}

/* Newton direction J d = -F; FESD_ERR_SINGULAR when the factorization fails or d is not
 * finite. grad psi . d = F'J d = -||F||^2 for the solved d, so it is a descent direction; the
 * classic safeguard grad psi . d <= -rho ||d||^p (De Luca, Facchinei, Kanzow 1996) is not used:
 * it compares residual units with unknown units, and with row weights (a caller that makes
 * its rows dimensionless) it rejected good directions (measured: every step of a stiff problem
 * from a far guess). A poor direction shows in the Armijo test instead, and the fallback
 * follows. */
static int newton_step(fesd_ncp *ws, fesd__ncp_stats *st) {
  int rc = factor_solve(ws, ws->active, 0.0, ws->F_c, st);
  if (rc != FESD_OK) return rc == FESD_ERR_NOMEM ? rc : FESD_ERR_SINGULAR;
  return FESD_OK;
}

/* Fallback when Newton fails (after a factorization): an LM-regularized step on the dense
 * path, a Cauchy-scaled steepest-descent step on the sparse LU paths (J stays intact). */
static int fallback_step(fesd_ncp *ws, const double *jac, double mu, double *gnorm_out,
                         fesd__ncp_stats *st, int *dir) {
  const double gnorm = gradient(ws, jac, 1);
  *gnorm_out = gnorm;
  if (gnorm == 0.0) return FESD_ERR_SINGULAR; /* stationary point of psi with F != 0 */
  if (ws->dense) {
    *dir = DIR_LM;
    return lm_step(ws, ws->normal, mu, fesd__ncp_frobenius(ws), st);
  }
  *dir = DIR_GRADIENT;
  fesd__ncp_j_mul(ws, ws->g, ws->tmp);
  double jg2 = dot(ws->tmp, ws->tmp, ws->m);
  double scale = jg2 > 0.0 ? gnorm * gnorm / jg2 : 1.0;
  for (int i = 0; i < ws->n; i++) ws->d[i] = -scale * ws->g[i];
  return FESD_OK;
}

typedef struct {
  double sigma;
  double nrm, f2; /* ||F||_inf and ||F||_2^2 at the current point */
  int jac_ok;     /* jac_c belongs to the current point */
} stage_state;

/* Armijo backtracking along d. Trials evaluate the residual only: the Jacobian is asked for
 * at the accepted point when another iteration follows, so the last iteration of a solve
 * (often the only one after a converged warm start) evaluates none (measured: 1-5 % faster
 * integrations than a Jacobian at the first trial). Returns FESD_OK (accepted),
 * FESD_ERR_LINE_SEARCH, or FESD_ERR_CALLBACK. */
static int line_search(fesd_ncp *ws, double *z, stage_state *ss, double gd, int max_trials,
                       fesd__ncp_stats *st, int *ntrial, double *step, double *psi_first) {
  const fesd_ncp_settings *s = &ws->set;
  const int n = ws->n;
  const double psi = 0.5 * ss->f2;
  double t = 1.0;
  *psi_first = INFINITY;
  for (int k = 0; k < max_trials; k++) {
    if (k) {
      t *= s->backtrack;
      st->backtracks++;
    }
    int finite = 1;
    for (int i = 0; i < n; i++) {
      ws->zt[i] = z[i] + t * ws->d[i];
      finite &= isfinite(ws->zt[i]);
    }
    /* a direction with NaN/Inf (a factorization that overflowed) gives no trial point: the
     * callbacks are never called with non-finite arguments (a user's model may assert on them) */
    if (!finite) continue;
    project(ws, ws->zt);
    int rc = fesd__ncp_call(ws, ws->zt, ws->raw_t, NULL, st);
    if (rc == FESD_ERR_CALLBACK) return rc;
    if (rc != FESD_OK) continue; /* NaN/Inf at a trial point: reject the trial */
    fesd__ncp_residual(ws, ws->raw_t, ss->sigma, ws->F_t);
    double f2 = dot(ws->F_t, ws->F_t, ws->m);
    if (k == 0 && !isnan(f2)) *psi_first = 0.5 * f2;
    if (!(0.5 * f2 <= psi + s->armijo * t * gd)) continue; /* also rejects NaN */
    swap(&ws->raw_c, &ws->raw_t);
    swap(&ws->F_c, &ws->F_t);
    ss->jac_ok = 0;
    memcpy(z, ws->zt, (size_t)n * sizeof *z);
    ss->f2 = f2;
    ss->nrm = norm_inf(ws->F_c, ws->m);
    *ntrial = k + 1;
    *step = t;
    return FESD_OK;
  }
  *ntrial = max_trials;
  return FESD_ERR_LINE_SEARCH;
}

static void log_iteration(const fesd_ncp *ws, int it, const stage_state *ss, double gnorm,
                          double step, int ntrial, int dir) {
  if (!ws->set.log) return;
  char line[160];
  snprintf(line, sizeof line,
           "ncp it %3d sigma %.1e |F|inf %.3e |J'F| %.2e step %.2e trials %d dir %s", it,
           ss->sigma, ss->nrm, gnorm, step, ntrial, dir_name[dir]);
  ws->set.log(ws->set.log_user, line);
}

/* One sigma stage from z. *cached: 0 = nothing known at z, 1 = raw_c is at z,
 * 2 = raw_c and jac_c are at z; updated on return for the next stage. */
static int stage(fesd_ncp *ws, double *z, double sigma, double tol, fesd__ncp_stats *st,
                 fesd_ncp_info *info, int *cached, double *res) {
  const fesd_ncp_settings *s = &ws->set;
  const int lm = ws->active->ops->kind == FESD__LS_NORMAL;
  stage_state ss = {sigma, 0.0, 0.0, *cached == 2};
  const int newton_trials = s->max_backtracks < NEWTON_TRIALS ? s->max_backtracks : NEWTON_TRIALS;
  double lambda = s->lm_mu0, angle = 1.0;
  int stall = 0, status = FESD_ERR_MAX_ITER, rc;

  st->stages++;
  if (!*cached) { /* residual only: warm starts are often converged already */
    rc = fesd__ncp_call(ws, z, ws->raw_c, NULL, st);
    if (rc != FESD_OK) return rc;
  }
  *cached = 0;
  fesd__ncp_residual(ws, ws->raw_c, sigma, ws->F_c);
  ss.nrm = norm_inf(ws->F_c, ws->m);
  ss.f2 = ss.nrm <= tol ? 0.0 : dot(ws->F_c, ws->F_c, ws->m); /* the iterations' merit only */

  double nrm1 = INFINITY; /* after the first iteration (the progress check) */
  for (int it = 0;; it++) {
    history_push(info, ss.nrm);
    *res = ss.nrm;
    if (ss.nrm <= tol) {
      status = FESD_OK;
      break;
    }
    if (it == 1) nrm1 = ss.nrm;
    if (it > 1 && it == s->slow_iter && ss.nrm > s->slow_ratio * nrm1) {
      status = FESD_ERR_LINE_SEARCH; /* the caller's progress check (settings.slow_iter) */
      break;
    }
    if (stall >= (lm ? LM_STALL_COUNT : STALL_COUNT)) {
      status = lm ? FESD_ERR_INCONSISTENT : FESD_ERR_LINE_SEARCH;
      break;
    }
    if (it >= s->max_iter) {
      status = lm && angle <= LM_STALL_ANGLE ? FESD_ERR_INCONSISTENT : FESD_ERR_MAX_ITER;
      break;
    }
    const double t_it = fesd__wall_time();
    if (!ss.jac_ok) {
      rc = fesd__ncp_call(ws, z, ws->raw_c, ws->jac_c, st);
      if (rc != FESD_OK) return rc;
      ss.jac_ok = 1;
    }
    if ((rc = fesd__ncp_ensure_pattern(ws)) != FESD_OK) return rc;
    st->iterations++;
    fesd__ncp_weights(ws, ws->raw_c, sigma);
    fesd__ncp_jacobian(ws, ws->jac_c);
    /* LM damping proportional to ||F|| (Fan & Yuan): quadratic convergence on
     * consistent systems, and scale-robust far away (unlike ||J'F||). The gradient J'F
     * is formed only where it is used: LM, the fallbacks, the log. */
    const double mu = lambda * sqrt(ss.f2);
    double gnorm = (lm || s->log) ? gradient(ws, ws->jac_c, 0) : NAN;
    int dir = lm ? DIR_LM : DIR_NEWTON;
    if (lm) {
      const double jnorm = fesd__ncp_frobenius(ws);
      angle = jnorm > 0.0 ? gnorm / (jnorm * sqrt(ss.f2)) : 0.0;
      if (angle <= LM_STATIONARY) {
        status = FESD_ERR_INCONSISTENT;
        st->time_iter += fesd__wall_time() - t_it;
        break;
      }
      rc = lm_step(ws, ws->active, mu, jnorm, st);
    } else {
      rc = newton_step(ws, st);
      if (rc == FESD_ERR_SINGULAR) rc = fallback_step(ws, ws->jac_c, mu, &gnorm, st, &dir);
    }
    if (rc != FESD_OK) {
      status = rc;
      st->time_iter += fesd__wall_time() - t_it;
      break;
    }
    const double f2_old = ss.f2;
    int ntrial = 0;
    double step = 0.0, psi_first = INFINITY;
    if (dir == DIR_NEWTON) {
      /* A Newton step that needs more than NEWTON_TRIALS cuts points along a
       * valley of psi; the damped direction makes better progress there. */
      rc = line_search(ws, z, &ss, -ss.f2, newton_trials, st, &ntrial, &step, &psi_first);
      if (rc == FESD_ERR_LINE_SEARCH) {
        log_iteration(ws, it, &ss, gnorm, 0.0, ntrial, dir);
        rc = fallback_step(ws, ws->jac_c, mu, &gnorm, st, &dir);
        if (rc == FESD_ERR_SINGULAR) rc = FESD_ERR_LINE_SEARCH;
        if (rc == FESD_OK)
          rc = line_search(ws, z, &ss, dot(ws->g, ws->d, ws->n), s->max_backtracks, st, &ntrial, &step,
                           &psi_first);
      }
    } else {
      rc = line_search(ws, z, &ss, dot(ws->g, ws->d, ws->n), s->max_backtracks, st, &ntrial, &step, &psi_first);
    }
    log_iteration(ws, it, &ss, gnorm, rc == FESD_OK ? step : 0.0, ntrial, dir);
    st->time_iter += fesd__wall_time() - t_it;
    if (rc != FESD_OK) {
      status = (rc == FESD_ERR_LINE_SEARCH && lm && angle <= LM_STALL_ANGLE)
                   ? FESD_ERR_INCONSISTENT
                   : rc;
      if (status == FESD_ERR_CALLBACK) return status;
      break;
    }
    /* Damping follows the gain ratio of the full LM step (actual over predicted
     * decrease of psi), as in trust-region methods; J is still the one of d. */
    if (dir == DIR_LM) {
      fesd__ncp_j_mul(ws, ws->d, ws->tmp);
      double pred = -dot(ws->g, ws->d, ws->n) - 0.5 * dot(ws->tmp, ws->tmp, ws->m);
      double gain = pred > 0.0 ? (0.5 * f2_old - psi_first) / pred : -1.0;
      if (gain > 0.75) lambda = fmax(lambda / LM_LAMBDA_STEP, LM_LAMBDA_MIN);
      else if (gain < 0.25) lambda = fmin(lambda * LM_LAMBDA_STEP, LM_LAMBDA_MAX);
    }
    if (lm) {
      int small_gain = sqrt(ss.f2) > (1.0 - LM_STALL_GAIN) * sqrt(f2_old);
      stall = (small_gain && angle <= LM_STALL_ANGLE) ? stall + 1 : 0;
    } else {
      stall = sqrt(ss.f2) > (1.0 - STALL_GAIN) * sqrt(f2_old) ? stall + 1 : 0;
    }
  }
  *cached = ss.jac_ok ? 2 : 1;
  return status;
}

/* Fatal outcomes stop the homotopy; the others let the next stage try. */
static int fatal(int rc) {
  return rc == FESD_ERR_CALLBACK || rc == FESD_ERR_NONFINITE || rc == FESD_ERR_NOMEM ||
         rc == FESD_ERR_LINSOLVE;
}

static int begin(fesd_ncp *ws, double *z, double sigma, fesd_ncp_info *info,
                 fesd__ncp_stats *st) {
  memset(info, 0, sizeof *info);
  if (!ws || !z) return FESD_ERR_NULL;
  if (!(sigma >= 0.0) || !isfinite(sigma)) return FESD_ERR_INVALID_ARG;
  int rc = fesd__ncp_ensure_rows(ws);
  if (rc != FESD_OK) return rc;
  *st = ws->pending;
  memset(&ws->pending, 0, sizeof ws->pending);
  project(ws, z);
  return FESD_OK;
}

static int finish(const fesd_ncp *ws, fesd_ncp_info *info, const fesd__ncp_stats *st, int rc,
                  double t0, double res) {
  info->status = rc;
  info->iterations = st->iterations;
  info->homotopy_stages = st->stages;
  info->factorizations = st->factorizations;
  info->evals = st->evals;
  info->jac_evals = st->jac_evals;
  info->backtracks = st->backtracks;
  info->backend = ws->active->backend;
  info->m = ws->m;
  info->residual = res;
  info->time_eval = st->time_eval;
  info->time_linsolve = st->time_linsolve;
  info->time_iterations = st->time_iter;
  info->time_total = fesd__wall_time() - t0;
  return rc;
}

int fesd_ncp_solve(fesd_ncp *ws, double *z, double sigma, fesd_ncp_info *info) {
  double t0 = fesd__wall_time(), res = INFINITY;
  fesd_ncp_info local;
  fesd__ncp_stats st;
  if (!info) info = &local;
  int rc = begin(ws, z, sigma, info, &st);
  if (rc != FESD_OK) return info->status = rc;
  int cached = 0;
  rc = stage(ws, z, sigma, ws->set.tol, &st, info, &cached, &res);
  return finish(ws, info, &st, rc, t0, res);
}

int fesd_ncp_solve_homotopy(fesd_ncp *ws, double *z, fesd_ncp_info *info) {
  double t0 = fesd__wall_time(), res = INFINITY;
  fesd_ncp_info local;
  fesd__ncp_stats st;
  if (!info) info = &local;
  int rc = begin(ws, z, 0.0, info, &st);
  if (rc != FESD_OK) return info->status = rc;
  const fesd_ncp_settings *s = &ws->set;
  int cached = 0;
  memcpy(ws->z0, z, (size_t)ws->n * sizeof *z);
  rc = stage(ws, z, 0.0, s->tol, &st, info, &cached, &res);
  if (rc == FESD_OK || fatal(rc)) return finish(ws, info, &st, rc, t0, res);

  memcpy(z, ws->z0, (size_t)ws->n * sizeof *z);
  cached = 0;
  for (double sigma = s->sigma0; sigma >= s->sigma_min * (1.0 - 1e-9); sigma *= s->sigma_factor) {
    rc = stage(ws, z, sigma, fmax(s->tol, s->homotopy_tol_factor * sigma), &st, info, &cached,
               &res);
    if (fatal(rc)) return finish(ws, info, &st, rc, t0, res);
  }
  rc = stage(ws, z, 0.0, s->tol, &st, info, &cached, &res);
  return finish(ws, info, &st, rc, t0, res);
}

int fesd_ncp_residual(fesd_ncp *ws, const double *z, double sigma, double *F, double *norm_inf_out) {
  if (!ws || !z) return FESD_ERR_NULL;
  if (!(sigma >= 0.0) || !isfinite(sigma)) return FESD_ERR_INVALID_ARG;
  int rc0 = fesd__ncp_ensure_rows(ws);
  if (rc0 != FESD_OK) return rc0;
  fesd__ncp_stats st;
  memset(&st, 0, sizeof st);
  int rc = fesd__ncp_call(ws, z, ws->raw_t, NULL, &st);
  if (rc != FESD_OK) return rc;
  double *out = F ? F : ws->F_t;
  fesd__ncp_residual(ws, ws->raw_t, sigma, out);
  if (norm_inf_out) *norm_inf_out = norm_inf(out, ws->m);
  return FESD_OK;
}
