/* One integration step: the solve strategy.
 *
 * FESD (plan path): every solve has fixed active sets, so the step system is smooth and
 * Newton converges quadratically:
 *  (a) solve with the start's active set everywhere, equal h, from the warm start;
 *  (b) check the solution (verify.c); each subsystem's earliest violation predicts a switch;
 *  (c) the plan gives every predicted switch its own element boundary with the binding row
 *      (cross complementarity, or a pinned sliding exit), more elements when the step holds
 *      more switches than N_FE - 1; solve from the previous solution regridded onto the new
 *      elements; back to (b) until nothing is violated.
 * A step that holds more switches than max_elements - 1 ends early, midway between two
 * switches (a sub-step), and the rest of the step follows.
 * If a plan cannot be solved, the FB fallback: the FB system with the smoothing homotopy
 * (equal-h solve, smoothed predictor, re-sorted reduced system), verified like the rest.
 * A step that still fails is halved recursively (settings.max_splits): the last resort, for a
 * Zeno accumulation.
 *
 * Standard method: the same smooth solves with per-stage active sets (a sign violated at a
 * stage changes that stage and the later ones). */
#include <float.h>
#include <math.h>
#include <string.h>

#include "common/timer.h"
#include "fesd/integrator.h"
#include "fesd/step.h"
#include "ncp/ncp_defer.h"

/* A callback failed (error code, NaN/Inf) or memory ran out: no other path can succeed. */
int fesd__hard_failure(int st) {
  return st == FESD_ERR_CALLBACK || st == FESD_ERR_NONFINITE || st == FESD_ERR_NOMEM;
}

/* Plan rounds of one step attempt (each one smooth solve). */
#define MAX_ROUNDS 24
/* Newton iterations of a plan solve: a plan with the right active sets converges in a few (it
 * is smooth, from a regridded converged solution); one that does not is changed rather than
 * iterated on. */
#define PLAN_ITER 15
/* ... and one whose residual after PLAN_SLOW_ITER iterations is above PLAN_SLOW_RATIO times its
 * first is not in Newton's reach: it is changed at once. Measured on the stick-slip chains
 * (n = 64, 128, 256; Radau s = 2, 3; Gauss s = 2): converging plan solves have |F| at or below
 * 0.2 of the start after 5 iterations (most converge in 2 to 7), failing ones above 0.5 (they
 * creep on in the damped fallback and ran out the 15 iterations). */
#define PLAN_SLOW_ITER 5
#define PLAN_SLOW_RATIO 0.5
/* Solves with the row weights recomputed at the previous solution: the weights of a guess
 * can be far from those of the solution (a stage value far off makes its rows' sizes
 * large); each further pass starts converged and costs one or two iterations. */
#define WEIGHT_PASSES 5
/* Sub-steps cut short after a failed plan solve, per step attempt (one: when the cut fails
 * too, halving the step is cheaper than cutting again; stick-slip chain, n = 128: the worst
 * step 137 -> 107 Newton iterations with one cut instead of three). */
#define MAX_SHORTEN 1
/* Finest layout after plan cycles: no element longer than T / (N_FE 2^(MAX_SPLIT_LEVEL - 1)). */
#define MAX_SPLIT_LEVEL 3
/* A sub-step ends before this many boundaries when the plan holds more (see plan_cut). */
#define SUB_MARGIN 1
/* After a sub-step cut short by its switches, the next attempt covers at most SUB_GROW times
 * its length, and at least 1 / SUB_MIN_PARTS of the (sub)step (the rest when that leaves less
 * than half a sub-step), not the whole rest: the attempt's first solve and predictions span its
 * length, and over a rest that holds dozens of switches they are far off (stick-slip chain
 * T = 4, Radau s = 2, h = 0.2: n = 256 483 -> 370 Newton iterations, n = 512 824 -> 551 and
 * 12 -> 7 s; growth 1: n = 256, s = 3 465 -> 830; growth 3 no better than 2). The floor keeps
 * attempts macroscopic where sub-steps shrink geometrically, at a Zeno accumulation: without it
 * a sub-step of 3e-7 past the accumulation point passed the checks (its sign violation, 5e-14,
 * is round-off) while the state left the origin (twisting system, hard_zeno). Attempt ends stay
 * piecewise constant in the step's inputs (multiples of dyadic cuts), as the sensitivities
 * need. */
#define SUB_GROW 2.0
#define SUB_MIN_PARTS 64.0

/* ---------- row selections ---------- */

static int rows_select(fesd_integrator *it, const int *switch_at) {
  fesd__system *S = &it->sys;
  it->rk_valid = 0; /* replaces the selection of fesd__rows_active */
  memset(it->eq_active, 1, (size_t)S->n_eq);
  memset(it->bmode, 0, (size_t)(S->N + 1) * sizeof(int));
  for (int k = 1; k < S->N; k++) {
    int sw = switch_at ? switch_at[k] : 0;
    it->eq_active[fesd__rowH(S, k)] = (unsigned char)!sw;
    it->eq_active[fesd__rowC(S, k)] = (unsigned char)(sw != 0);
    it->bmode[k] = sw != 0;
  }
  memset(it->pair_mode, FESD_NCP_PAIR_FB, (size_t)S->n_pair);
  fesd__system_set_exits(S, NULL, NULL);
  fesd__system_set_lb_mask(S, NULL);
  int st = fesd__set_border(it);
  return st ? st : fesd_ncp_set_rows(it->ncp, it->eq_active, it->pair_mode);
}

/* Element lengths in [1e-9 T, T], or in the plan's bounds (fesd__plan_layout); the other
 * unknowns of a level's workspace are never bounded (as set up). */
static int set_h_bounds(fesd_integrator *it, double T, int plan) {
  fesd__system *S = &it->sys;
  for (int n = 0; n < S->N; n++) {
    int st = fesd__ncp_set_bound(it->ncp, S->ho[n], plan ? it->hlo[n] : 1e-9 * T, plan ? it->hhi[n] : T);
    if (st) return st;
  }
  return FESD_OK;
}

static void accumulate(fesd_step_info *info, const fesd_ncp_info *ni) {
  info->newton_iter += ni->iterations;
  info->factorizations += ni->factorizations;
  info->homotopy_stages += ni->homotopy_stages;
  info->solves++;
  info->residual = ni->residual;
}

/* The solver keeps the row weights of one solve fixed (weights.c: from the sizes of the terms
 * at the initial guess); at the solution they are recomputed and the residual checked again,
 * and Newton continues with the new weights when it does not pass (a guess far off in size,
 * e.g. a stiff transient in the warm start). */
static int solve(fesd_integrator *it, double *z, double sigma, double tol, int max_iter,
                 int homotopy, int slow_iter, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  fesd_ncp_settings ns = it->set.ncp;
  ns.tol = tol;
  ns.max_iter = max_iter;
  ns.slow_iter = slow_iter;
  ns.slow_ratio = PLAN_SLOW_RATIO;
  fesd_ncp_update_settings(it->ncp, &ns);
  int st = FESD_OK;
  for (int pass = 0; pass < WEIGHT_PASSES; pass++) {
    if ((st = fesd__system_weights(S, z))) break;
    if (pass > 0) {
      double res;
      if ((st = fesd_ncp_residual(it->ncp, z, sigma, NULL, &res))) break;
      info->residual = res;
      if (res <= tol) return FESD_OK;
      homotopy = 0; /* continue from the solution */
    }
    fesd_ncp_info ni;
    st = homotopy ? fesd_ncp_solve_homotopy(it->ncp, z, &ni) : fesd_ncp_solve(it->ncp, z, sigma, &ni);
    accumulate(info, &ni);
    if (st == FESD_OK && ni.iterations == 0) return FESD_OK; /* z unchanged: its weights hold */
    if (st) break;
    st = FESD_ERR_MAX_ITER;
  }
  if (st == FESD_ERR_CALLBACK || st == FESD_ERR_NONFINITE) {
    int ms = S->status;
    if (ms == FESD_ERR_CALLBACK || ms == FESD_ERR_NONFINITE) st = ms;
    info->failed_callback = it->model.failed;
  }
  return st;
}

/* ---------- FB path: equal-h FB solve, predictor, reduced FB solve ---------- */

/* z0 holds the initial guess (N_FE layout); on success z is a converged solution. */
static int fb_path(fesd_integrator *it, double T, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  const double tol = it->newton_tol;
  double *z = it->z, *z0 = it->z0, *zp = it->zpred;
  int st;
  if ((st = rows_select(it, NULL))) return st;
  memcpy(z, z0, (size_t)S->n * sizeof(double));
  st = solve(it, z, 0.0, tol, it->set.max_iter_first, 0, 0, info);
  if (fesd__hard_failure(st)) return st;
  if (it->set.method == FESD_METHOD_STANDARD) {
    if (st != FESD_OK) {
      memcpy(z, z0, (size_t)S->n * sizeof(double));
      st = solve(it, z, 0.0, tol, it->set.max_iter, 1, 0, info);
    }
    return st;
  }
  double ccm;
  if (st == FESD_OK && fesd__verify(it, z, &ccm) == FESD_OK) return FESD_OK;
  /* predictor */
  if (st == FESD_OK) {
    memcpy(zp, z, (size_t)S->n * sizeof(double));
  } else {
    memcpy(zp, z0, (size_t)S->n * sizeof(double));
    int ok = 0;
    for (double sigma = 1e-1; sigma >= 0.9e-3; sigma *= 0.1) {
      int s2 = solve(it, zp, sigma, 1e-2 * sigma, 20, 0, 0, info);
      if (fesd__hard_failure(s2)) return s2;
      ok = (s2 == FESD_OK) || ok;
      if (s2 != FESD_OK) break;
    }
    if (!ok) return FESD_ERR_STEP_FAILED;
  }
  double tc[16];
  int nc = fesd__predict_switches(it, zp, T, tc, 16);
  if (nc == 0) return FESD_ERR_STEP_FAILED; /* no switch located: not a switch problem */
  if (nc > S->N - 1) return FESD_ERR_TOO_MANY_SWITCHES;
  /* reduced square FESD system */
  if ((st = fesd__resort_guess(it, zp, T, tc, nc, it->sw_at, z0))) return st;
  if ((st = rows_select(it, it->sw_at))) return st;
  memcpy(z, z0, (size_t)S->n * sizeof(double));
  st = solve(it, z, 0.0, tol, it->set.max_iter, 0, 0, info);
  if (fesd__hard_failure(st)) return st;
  if (st != FESD_OK) {
    memcpy(z, z0, (size_t)S->n * sizeof(double));
    st = solve(it, z, 0.0, tol, it->set.max_iter, 1, 0, info);
    if (st != FESD_OK) return st;
  }
  info->switch_step = 1;
  return FESD_OK;
}

/* ---------- smooth solves with fixed active sets ---------- */

/* Solve with the per-stage active sets it->act and boundary rows it->bmode from the guess in z. */
int fesd__fixed_solve(fesd_integrator *it, double *z, int max_iter, int slow_iter, fesd_step_info *info) {
  int st = fesd__rows_active(it, it->act, it->bmode, it->exit_mode);
  if (st) return st;
  st = solve(it, z, 0.0, it->newton_tol, max_iter, 0, slow_iter, info);
  if (st) return st;
  for (int n = 0; n < it->sys.N; n++)
    if (!(z[it->sys.ho[n]] > 0)) return FESD_ERR_STEP_FAILED;
  return FESD_OK;
}

/* A guess that stage Newton solved (every element) with one active mode per subsystem and
 * no look-ahead stage satisfies every row of the step system but the V rows by construction
 * (fesd__consistent_guess): theta is 0/1 and the S rows hold exactly, mu is the active mode's
 * indicator so the active lambdas and boundary LP values are 0 exactly, the other lambdas and
 * x_{n+1} are computed from the G and X rows (residuals of a few eps relative to the rows'
 * weights), the lengths are equal and the cross-complementarity rows are off. So the step is
 * checked on its V rows alone, with the solve's weights: what the solver's residual check
 * would find to round-off, without its evaluation of the whole system (an ordinary step,
 * oscillator s = 5: 6.3k of 60.7k instructions). Returns 1 when certified (info updated). */
static int certified(fesd_integrator *it, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  const fesd__model *m = S->model;
  /* the rows that hold by construction do so to a few eps per term: the sum of the N lengths
   * against T to about N eps, x_{n+1} to about s eps; below that newton_tol is the solver's */
  if (it->full_check || S->look || it->newton_tol < 64.0 * (S->N + S->s) * DBL_EPSILON) return 0;
  for (int k = 0; k < S->nsys; k++)
    if (fesd__one_mode(m, it->act0, k) < 0) return 0;
  if (fesd__rows_active(it, it->act, it->bmode, it->exit_mode) || fesd__system_weights(S, it->z)) return 0;
  const double *z = it->z, *w = S->wraw;
  double res = 0, *g = S->tmp;
  for (int n = 0; n < S->N; n++)
    for (int j = 0; j < S->s; j++) {
      const double *v = z + fesd__v(S, n, j), *th = z + fesd__th(S, n, j);
      const fesd__point_eval *pe = &S->pe[n * S->s + j];
      const double *wv = w + S->rel[n] + j * S->rs;
      fesd__stage_residual(m, pe, v, th, g);
      for (int r = 0; r < S->nx; r++) res = fesd__fmax(res, fabs(g[r] * wv[r]));
    }
  if (!(res <= it->newton_tol)) return 0;
  info->residual = res;
  info->solves++;
  it->n_certified++;
  return 1;
}

/* The start's active set at every stage of the N_FE layout, from the warm start z0. */
int fesd__start_solve(fesd_integrator *it, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  const size_t na = (size_t)S->N * S->s * S->nth; /* act0 at every stage: doubling copies */
  memcpy(it->act, it->act0, (size_t)S->nth);
  for (size_t c = (size_t)S->nth; c < na; c *= 2) memcpy(it->act + c, it->act, c < na - c ? c : na - c);
  memset(it->bmode, 0, (size_t)(S->N + 1) * sizeof(int));
  memcpy(it->z, it->z0, (size_t)S->n * sizeof(double));
  /* z0 came out of a consistent guess solved by stage Newton: if the active set leaves it
   * unchanged (bit for bit), a second consistent guess would return it unchanged. Every theta
   * already the 0/1 indicator of act0 (an ordinary step) is left so by fesd__impose_active. */
  int same = it->z0_fixed;
  for (int n = 0; n < S->N && same; n++)
    for (int j = 0; j < S->s && same; j++) {
      const double *th = it->z + fesd__th(S, n, j);
      for (int i = 0; i < S->nth && same; i++) same = th[i] == (it->act0[i] ? 1.0 : 0.0);
    }
  if (!same) {
    fesd__impose_active(it, it->z, it->act);
    same = it->z0_fixed && !memcmp(it->z, it->z0, (size_t)S->n * sizeof(double));
  }
  it->z0_fixed = 0;
  if (same && certified(it, info)) return FESD_OK;
  int st = same ? FESD_OK : fesd__consistent_guess(it, it->z);
  if (st) return st;
  return fesd__fixed_solve(it, it->z, it->set.max_iter_first, 0, info);
}

/* ---------- FESD plan path ---------- */

/* Shorten the (sub)step to hold the plan's first boundaries only (fesd__plan_cut). */
static void shorten(fesd_integrator *it, double *T) {
  const double cut = fesd__plan_cut(it, it->N_cap - 1 - SUB_MARGIN);
  fesd__plan_truncate(it, cut);
  *T = cut;
  it->sys.T = cut;
}

/* A plan that comes back twice within a few rounds (Gauss-Legendre pins a sliding exit by the
 * extrapolated theta, order about s: the exit lands early, a re-entry follows, the exit is
 * dropped, ...) is solved on finer elements, which place the switches more accurately; a
 * cycle on the finest layout fails the attempt at once instead of running to MAX_ROUNDS
 * (stick-slip chain n = 64, Gauss s = 2: 24 rounds of a 4-plan cycle in one step). */
static int plan_cycle(fesd_integrator *it) {
  const unsigned long sig = fesd__plan_signature(it);
  int seen = 0;
  for (int i = 0; i < PLAN_SIGS; i++) seen += it->plan_sig[i] == sig;
  memmove(it->plan_sig + 1, it->plan_sig, (PLAN_SIGS - 1) * sizeof *it->plan_sig);
  it->plan_sig[0] = sig;
  if (seen < 2) return FESD_OK; /* a single return can be progress (a switch moved by less) */
  if (it->split_layout >= MAX_SPLIT_LEVEL) return FESD_ERR_STEP_FAILED;
  it->split_layout = it->split_layout ? it->split_layout + 1 : 2;
  memset(it->plan_sig, 0, sizeof it->plan_sig);
  return FESD_OK;
}

/* Whether the violations of a solution with the start's sets everywhere are only Filippov's
 * conditions of one subsystem's sliding mode failing at the step's last point, the element end
 * of a family whose last stage is there (that stage's multipliers still hold the mode). */
static int sliding_fails_at_end(const fesd_integrator *it, const fesd__violation *v) {
  const fesd__system *S = &it->sys;
  if (v->filippov <= 0 || !it->tab.c_end_is_one || v->stage != S->N * S->s - 1) return 0;
  int n = 0;
  for (int k = 0; k < it->nsys; k++) n += it->scan_buf[k].found;
  return n == 1;
}

static int plan_path(fesd_integrator *it, double *T, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  double *z = it->z, *zp = it->zp;
  int Np = 0, st, shortened = 0;
  fesd__plan_reset(it);
  it->defer_exit = 0;
  if ((st = fesd__start_solve(it, info))) return fesd__hard_failure(st) ? st : FESD_ERR_STEP_FAILED;
  for (int round = 0;; round++) {
    fesd__plan_times(it, z);
    fesd__violation v;
    if ((st = fesd__scan(it, z, it->act, 0, &v, it->scan_buf))) return st;
    if (!v.found) {
      info->switch_step = it->n_plan > 0;
      return FESD_OK;
    }
    if (round == 0) it->defer_exit = sliding_fails_at_end(it, &v);
    if (round >= MAX_ROUNDS) return FESD_ERR_STEP_FAILED;
    memcpy(zp, z, (size_t)S->n * sizeof(double));
    Np = S->N;
    int r = fesd__plan_update(it, zp, it->scan_buf);
    if (r == FESD_ERR_TOO_MANY_SWITCHES) {
      shorten(it, T);
      r = 1;
    }
    if (r < 0) return r;
    if (r == 0) return FESD_ERR_STEP_FAILED;
    const int nsw = fesd__plan_subsystems(it);
    if (nsw > it->plan_peak) it->plan_peak = nsw;
    if ((st = plan_cycle(it))) return st;
    for (;;) { /* solve the new plan; retreat to fewer new switches while it fails */
      st = fesd__plan_layout(it, S->T, z);
      if (st == FESD_ERR_TOO_MANY_SWITCHES) {
        shorten(it, T);
        st = fesd__plan_layout(it, S->T, z);
      }
      if (st) return st;
      if ((st = set_h_bounds(it, S->T, 1))) return st;
      if ((st = fesd__regrid_guess(it, zp, Np, z))) return st;
      st = fesd__fixed_solve(it, z, it->set.max_iter < PLAN_ITER ? it->set.max_iter : PLAN_ITER, PLAN_SLOW_ITER, info);
      if (st == FESD_OK) break;
      if (fesd__hard_failure(st)) return st;
      /* its first element at the length floor: the entries there move to the start */
      if (fesd__plan_start_fallback(it, z)) continue;
      if (!it->split_layout) { /* first: the same plan without elements longer than T / N_FE */
        const int N0 = S->N;
        it->split_layout = 1;
        if (fesd__plan_layout(it, S->T, z) == FESD_OK && S->N != N0) continue;
      }
      if (fesd__plan_retreat(it)) continue;
      /* one new switch and still no solution: the step may hold more than the plan sees
       * (the trajectory after the switch differs from the predicting one); end the sub-step
       * midway between that switch and the next one, where the prediction still holds */
      const double cut = fesd__plan_cut_after_fresh(it);
      if (!(cut < S->T) || ++shortened > MAX_SHORTEN) return FESD_ERR_STEP_FAILED;
      fesd__plan_truncate(it, cut);
      *T = S->T = cut;
    }
  }
}

/* A sliding mode whose Filippov conditions fail at the step end while the family's own
 * multiplier of the leaving mode is still positive there: the exact exit lies between the last
 * point where the conditions held and the step end, the family's pinned exit after the step end
 * (its multipliers lag by their algebraic error), so the plan's exit rows have no solution in the
 * step. The step is taken with the sliding mode to its end and the exit falls on the next step's
 * start (its first check); the exit time is then nearer the exact one than the pinned exit would
 * be. Fixed steps only (under error control the controller retries shorter). Measured: a sliding
 * exit on a curved surface 3e-5 before a step end, Lobatto IIIC s = 2, h = 1/64: six halvings and
 * FESD_ERR_STEP_FAILED, or exit, entry and exit logged within 1e-12 (which one depended on the
 * BLAS kernel's round-off). Requires an attempt without start jumps (act0 and lambda00 as the
 * start solve had them). */
static int defer_exit(fesd_integrator *it, double T, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  if (!it->defer_exit || it->ec_on || it->start_jumped) return FESD_ERR_STEP_FAILED;
  S->T = T;
  fesd__plan_reset(it);
  int st = fesd__use_level(it, it->set.n_fe);
  if (!st) st = set_h_bounds(it, T, 0);
  if (!st) st = fesd__start_solve(it, info);
  if (st) return fesd__hard_failure(st) ? st : FESD_ERR_STEP_FAILED;
  fesd__plan_times(it, it->z);
  fesd__violation v;
  if ((st = fesd__scan(it, it->z, it->act, 0, &v, it->scan_buf))) return st;
  return v.found && sliding_fails_at_end(it, &v) ? FESD_OK : FESD_ERR_STEP_FAILED;
}

/* ---------- one attempt at a (sub)step of length *T (shortened when the step holds more
 *            switches than the largest layout) ---------- */

static int try_step(fesd_integrator *it, const double *u, double *T, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  const double T_full = *T;
  S->x0 = it->x;
  S->t0 = it->t;
  S->u = u;
  S->lam00 = it->lam00;
  S->T = *T;
  it->f0_ok = 0;
  fesd__system_points_reset(S); /* the callbacks' user data may have changed since the last step */
  int st = fesd__use_level(it, it->set.n_fe);
  if (st) return st;
  for (int k = 0; k < it->nsys; k++) it->jump_in[k] = it->jump_out[k] = -1;
  if ((st = fesd__initial_guess(it, u, *T, it->z0))) return st;
  if ((st = set_h_bounds(it, *T, 0))) return st;
  int nonunique = 0;
  if ((st = fesd__act_start(it, u, it->act0, &nonunique))) return st;
  it->start_jumped = 0;
  it->nonunique = nonunique;
  it->exc_found = 0;
  st = it->set.method == FESD_METHOD_FESD ? plan_path(it, T, info) : fesd__std_path(it, info);
  if (fesd__hard_failure(st)) return st;
  if (st != FESD_OK && it->set.method == FESD_METHOD_FESD) {
    const int sd = defer_exit(it, T_full, info);
    if (fesd__hard_failure(sd)) return sd;
    if (sd == FESD_OK) *T = T_full, st = FESD_OK;
  }
  const int st_path_plan = st == FESD_OK;
  if (st != FESD_OK) {
    info->failed_path = it->set.method == FESD_METHOD_FESD ? "plan" : "standard";
    info->failed_residual = info->residual;
    /* The FB fallback gives each switch one of the N_FE - 1 inner boundaries (the switches of
     * two subsystems at a corner can share one): a step whose plan had more subsystems
     * switching than N_FE is left to halving (stick-slip chain n = 256: a failed FB attempt
     * cost 450 Newton iterations). */
    if (it->set.method == FESD_METHOD_FESD && it->plan_peak > it->set.n_fe) return st;
    *T = T_full;
    S->T = T_full;
    for (int k = 0; k < it->nsys; k++) it->jump_in[k] = it->jump_out[k] = -1;
    if ((st = fesd__use_level(it, it->set.n_fe))) return st;
    if ((st = set_h_bounds(it, *T, 0))) return st;
    if ((st = fb_path(it, *T, info))) {
      info->failed_path = "fb";
      info->failed_residual = info->residual;
      return st;
    }
    info->fallback++;
  }
  /* Gauss-Legendre pins exits only on the plan path (exit_ext); the stiffly accurate methods'
   * last stage is the element end on either path */
  it->exit_pinned = it->set.exit_rows && !it->tab.is_explicit && (!S->bp || st_path_plan);
  it->plan_sets = st_path_plan && it->set.method == FESD_METHOD_FESD;
  double ccm = 0;
  if (it->set.method == FESD_METHOD_FESD && info->fallback && (st = fesd__verify(it, it->z, &ccm)))
    return st;
  info->cc_max = fesd__cc_max(S, it->z);
  if (it->nonunique) info->flags |= FESD_FLAG_NONUNIQUE;
  if (it->ec_on) { /* error control (integrate.c): the estimate against the transformed tolerances */
    double err;
    if ((st = fesd__error_estimate(it, it->z, it->ec_rtol, it->err_atol, &err))) return st;
    info->error_estimate = fmax(info->error_estimate, err);
    /* a direct error, not an embedded estimate of lower order: the user's tolerances */
    if ((st = fesd__exit_error(it, it->z, it->tol.rtol, it->tol_atol, &err))) return st;
    info->error_estimate = fmax(info->error_estimate, err);
  } else if (it->set.coarse_tol > 0 && it->err_ok && (st = fesd__coarse_check(it, info))) {
    return st;
  }
  st = fesd__accept(it, it->z, u, *T);
  if (st) info->failed_path = "accept";
  return st;
}

/* The last resort of a fixed step (below) whose attempts failed after an excursion between check
 * points: the excursion check off, the step flagged. The discrete solution dips below the surface
 * by its own error where the flow only comes close (a near miss of 1e-10 after a crossing, Radau
 * IIA s = 2, h = 0.15: a dip of 1e-4), and the entry planned there has no solution (found by a
 * review: FESD_ERR_STEP_FAILED in 11 of 7200 such runs). Error control takes shorter steps. */
static int try_without_excursions(fesd_integrator *it, const double *u, double *T, fesd_step_info *info) {
  it->exc_off = 1;
  int st = try_step(it, u, T, info);
  it->exc_off = 0;
  if (st == FESD_OK) it->step_flags |= FESD_FLAG_AMBIGUOUS;
  return st;
}

int fesd__substep(fesd_integrator *it, const double *u, double T, int depth, fesd_step_info *info) {
  double done = 0, prev = 0;
  while (done < T) {
    double Ts = T - done;
    const double lim = fmax(SUB_GROW * prev, T / SUB_MIN_PARTS);
    if (prev > 0 && Ts > lim + 0.5 * prev) Ts = lim;
    fesd__save(it, &it->bk_sub);
    const int fb = info->fallback;
    const double Ts0 = Ts;
    int st = try_step(it, u, &Ts, info);
    if (st != FESD_OK && !fesd__hard_failure(st) && depth >= it->set.max_splits && !it->ec_on && it->exc_found) {
      info->fallback = fb;
      fesd__load(it, &it->bk_sub);
      Ts = Ts0;
      st = try_without_excursions(it, u, &Ts, info);
    }
    if (Ts < info->min_substep) info->min_substep = Ts;
    if (st == FESD_OK) {
      info->last_time = it->t;
      if (Ts < T - done) info->substeps++;
      prev = Ts < T - done ? Ts : 0;
      done = Ts < T - done ? done + Ts : T;
      continue;
    }
    info->fallback = fb;
    fesd__load(it, &it->bk_sub); /* accept may have failed half-way */
    if (fesd__hard_failure(st) && st != FESD_ERR_NONFINITE) return st;
    /* under error control a failed (sub)step goes back to the controller, which retries it
     * shorter with a new first solve and prediction: halving it here spent hundreds of Newton
     * iterations on attempts the error test then rejected (Stribeck stick-slip, Radau s = 2,
     * rtol 1e-3: 2542 -> 405 iterations, 1e-1: 2060 -> 815, 1e-6: 2347 -> 770) */
    if (depth >= (it->ec_on ? 0 : it->set.max_splits))
      return st == FESD_ERR_TOO_MANY_SWITCHES || st == FESD_ERR_NONFINITE ? st : FESD_ERR_STEP_FAILED;
    info->splits++;
    const double R = T - done, half = 0.5 * R;
    if (half < info->min_substep) info->min_substep = half;
    st = fesd__substep(it, u, half, depth + 1, info);
    if (st) return st;
    return fesd__substep(it, u, R - half, depth + 1, info);
  }
  return FESD_OK;
}
