/* One integration step: the solve strategy (measured in ../shared/notes/solver_prototype.md,
 * strategy S2c, verified in C):
 *  (a) solve the equal-h (standard) system at sigma = 0 from the warm start; if it
 *      converges and every cross-complementarity product vanishes, equal h is an
 *      exact FESD solution: accept;
 *  (b) otherwise predict the switch times from the sign changes of
 *      q_i = lambda_i - theta_i along the stage points (of (a)'s solution, or of a
 *      short smoothed predictor sigma = 1e-1..1e-3 when (a) failed);
 *  (c) re-sort the elements around the predicted switches and solve the square
 *      FESD system whose boundary rows are the binding ones (Theorem 3): the
 *      compact cross-complementarity row at a switching boundary, h_k = h_{k-1}
 *      elsewhere, and sum h = T; sigma-homotopy as fallback;
 *  (d) verify (all sparse cross products, h > 0); on failure the caller halves the step. */
#include <math.h>
#include <string.h>

#include "common/timer.h"
#include "fesd/integrator.h"
#include "fesd/step.h"

/* A callback failed (error code, NaN/Inf): no other path of this attempt can succeed. */
static int cb_failed(int st) { return st == FESD_ERR_CALLBACK || st == FESD_ERR_NONFINITE; }

/* ---------- row selections ---------- */

static int rows_select(fesd_integrator *it, const int *switch_at) {
  fesd__system *S = &it->sys;
  memset(it->eq_active, 1, (size_t)S->n_eq);
  for (int k = 1; k < S->N; k++) {
    int sw = switch_at ? switch_at[k] : 0;
    it->eq_active[fesd__rowH(S, k)] = (unsigned char)!sw;
    it->eq_active[fesd__rowC(S, k)] = (unsigned char)(sw != 0);
  }
  memset(it->pair_mode, FESD_NCP_PAIR_FB, (size_t)S->n_pair);
  return fesd_ncp_set_rows(it->ncp, it->eq_active, it->pair_mode);
}

static void set_h_bounds(fesd_integrator *it, double T) {
  fesd__system *S = &it->sys;
  for (int i = 0; i < S->n; i++) {
    it->lb[i] = -INFINITY;
    it->ub[i] = INFINITY;
  }
  for (int n = 0; n < S->N; n++) {
    it->lb[S->ho[n]] = 1e-9 * T;
    it->ub[S->ho[n]] = T;
  }
  fesd_ncp_set_bounds(it->ncp, it->lb, it->ub);
}

static void accumulate(fesd_step_info *info, const fesd_ncp_info *ni) {
  info->newton_iter += ni->iterations;
  info->factorizations += ni->factorizations;
  info->homotopy_stages += ni->homotopy_stages;
  info->solves++;
  info->residual = ni->residual;
}

static int solve(fesd_integrator *it, double *z, double sigma, double tol, int max_iter,
                 int homotopy, fesd_step_info *info) {
  fesd_ncp_settings ns = it->set.ncp;
  ns.tol = tol;
  ns.max_iter = max_iter;
  fesd_ncp_update_settings(it->ncp, &ns);
  fesd_ncp_info ni;
  int st = homotopy ? fesd_ncp_solve_homotopy(it->ncp, z, &ni) : fesd_ncp_solve(it->ncp, z, sigma, &ni);
  accumulate(info, &ni);
  if (st == FESD_ERR_CALLBACK || st == FESD_ERR_NONFINITE) {
    int ms = it->sys.status;
    if (ms == FESD_ERR_CALLBACK || ms == FESD_ERR_NONFINITE) st = ms;
    info->failed_callback = it->model.failed;
  }
  return st;
}

/* ---------- initial guesses ---------- */

/* ---------- checks ---------- */

/* Max over elements, modes and stage pairs m != m' of theta_{n,m,i} lambda_{n,m',i}
 * (boundary lambdas included): the sparse cross complementarity (eq. cross_cc_true). */
double fesd__cc_max(const fesd__system *S, const double *z) {
  double worst = 0;
  for (int n = 0; n < S->N; n++) {
    const double *L = fesd__left_lambda(S, z, n);
    const double *R = S->bp ? fesd__right_lambda(S, z, n) : NULL;
    for (int i = 0; i < S->nth; i++)
      for (int m = 0; m < S->s; m++) {
        double th = z[fesd__th(S, n, m) + i];
        if (th <= 0) continue;
        double lmax = fmax(L[i], R ? R[i] : 0.0);
        for (int mp = 0; mp < S->s; mp++)
          if (mp != m) lmax = fmax(lmax, z[fesd__la(S, n, mp) + i]);
        worst = fmax(worst, th * lmax);
      }
  }
  return worst;
}

int fesd__valid(fesd_integrator *it, const double *z, double *ccm) {
  fesd__system *S = &it->sys;
  for (int n = 0; n < S->N; n++)
    if (!(z[S->ho[n]] > 0)) return 0;
  *ccm = fesd__cc_max(S, z);
  /* boundary LP points (methods with c_s != 1): lambda >= 0 there too, otherwise the
   * active set changed between the last stage and the element end */
  if (S->bp)
    for (int n = 0; n < S->N; n++)
      for (int i = 0; i < S->nth; i++) *ccm = fmax(*ccm, -z[S->lbo[n] + i]);
  return *ccm <= it->set.cc_tol;
}

/* ---------- FB path: equal-h FB solve, predictor, reduced FB solve (S2c) ---------- */

/* z0 holds the initial guess; on success z is an accepted solution. */
static int fb_path(fesd_integrator *it, double T, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  const double tol = it->set.newton_tol;
  double *z = it->z, *z0 = it->z0, *zp = it->zpred, ccm = 0;
  int st;
  if ((st = rows_select(it, NULL))) return st;
  memcpy(z, z0, (size_t)S->n * sizeof(double));
  st = solve(it, z, 0.0, tol, it->set.max_iter_first, 0, info);
  if (cb_failed(st)) return st;
  if (it->set.method == FESD_METHOD_STANDARD) {
    if (st != FESD_OK) {
      memcpy(z, z0, (size_t)S->n * sizeof(double));
      st = solve(it, z, 0.0, tol, it->set.max_iter, 1, info);
    }
    return st;
  }
  if (st == FESD_OK && fesd__valid(it, z, &ccm)) return FESD_OK;
  /* predictor */
  if (st == FESD_OK) {
    memcpy(zp, z, (size_t)S->n * sizeof(double));
  } else {
    memcpy(zp, z0, (size_t)S->n * sizeof(double));
    int ok = 0;
    for (double sigma = 1e-1; sigma >= 0.9e-3; sigma *= 0.1) {
      int s2 = solve(it, zp, sigma, 1e-2 * sigma, 20, 0, info);
      if (cb_failed(s2)) return s2;
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
  st = solve(it, z, 0.0, tol, it->set.max_iter, 0, info);
  if (cb_failed(st)) return st;
  if (st != FESD_OK || !fesd__valid(it, z, &ccm)) {
    memcpy(z, z0, (size_t)S->n * sizeof(double));
    st = solve(it, z, 0.0, tol, it->set.max_iter, 1, info);
    if (st != FESD_OK) return st;
    if (!fesd__valid(it, z, &ccm)) return FESD_ERR_STEP_FAILED;
  }
  info->switch_step = 1;
  return FESD_OK;
}

/* ---------- active-set path ---------- */

/* Solve with the per-stage active sets it->act and boundary modes it->bmode from the
 * guess in z; success means converged and sign-verified (v reports a violation). */
static int active_solve(fesd_integrator *it, double *z, int max_iter, fesd__violation *v,
                        fesd_step_info *info) {
  int st = fesd__rows_active(it, it->act, it->bmode, it->exit_mode);
  if (st) return st;
  st = solve(it, z, 0.0, it->set.newton_tol, max_iter, 0, info);
  if (st) return st;
  for (int n = 0; n < it->N; n++)
    if (!(z[it->sys.ho[n]] > 0)) return FESD_ERR_STEP_FAILED;
  fesd__find_violation(it, z, it->act, it->set.method == FESD_METHOD_STANDARD, v);
  return v->found ? FESD_ERR_STEP_FAILED : FESD_OK;
}

/* d/dt (g_i - g_j) along f_j at x: > 0 means mode j keeps the lead after a switch from i
 * to j (a crossing), < 0 that f_j pushes back to the surface (sliding). */
static int crossing_first(fesd_integrator *it, const double *x, int i, int j, int *cross) {
  fesd__model *m = &it->model;
  fesd__point_eval pe = {0};
  pe.F = it->pscr.F;
  pe.g = it->pscr.g;
  pe.dgdx = it->pscr.dgdx;
  int st = fesd__model_eval(m, x, it->sys.u, &pe);
  if (st) return st;
  double *f = it->vtmp;
  memset(f, 0, (size_t)m->nx * sizeof(double));
  fesd__F_axpy(m, &pe, j, 1.0, f);
  *cross = fesd__dg_dot(m, &pe, i, f) - fesd__dg_dot(m, &pe, j, f) > 0;
  return FESD_OK;
}

/* State of the fast-path solution z at time t (relative): the stage state nearest before t. */
static const double *state_near(fesd_integrator *it, const double *z, double t) {
  fesd__system *S = &it->sys;
  const double *best = S->x0;
  double tn = 0;
  for (int n = 0; n < S->N; n++) {
    if (tn > t) break;
    best = n == 0 ? S->x0 : z + S->xo[n - 1];
    tn += z[S->ho[n]];
  }
  return best;
}

/* Candidate active sets of subsystem v->sys after the violation v, best first: an exit
 * drops the mode; an entering mode j replaces the set (crossing) or joins it (sliding), in
 * the order given by the direction of f_j at x. cur: the active flags before. */
static int candidates(fesd_integrator *it, const fesd__violation *v, const unsigned char *cur,
                      const double *x, unsigned char cands[2][64], int *i_old_out) {
  const fesd__model *m = &it->model;
  const int k0 = m->th_off[v->sys], k1 = m->th_off[v->sys + 1];
  if (k1 - k0 > 64) return 0;
  if (!v->enter) {
    for (int i = k0; i < k1; i++) cands[0][i - k0] = cur[i] && i != v->mode;
    return 1;
  }
  int i_old = -1;
  for (int i = k0; i < k1; i++)
    if (cur[i] && i_old < 0) i_old = i;
  if (i_old < 0) return 0;
  int cross = 1;
  if (crossing_first(it, x, i_old, v->mode, &cross)) return 0;
  for (int i = k0; i < k1; i++) {
    cands[!cross][i - k0] = i == v->mode;           /* crossing: j replaces the set */
    cands[cross][i - k0] = cur[i] || i == v->mode;  /* sliding: j joins the set */
  }
  *i_old_out = i_old;
  return 2;
}

/* Standard method: its equations hold stage by stage, so a violation at stage p0 changes the
 * active set of that stage and of all later ones; repeated for later violations (a few
 * rounds), each solve smooth. Falls back to the FB path when this does not settle. */
static int std_switch(fesd_integrator *it, fesd__violation v, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  const int nth = S->nth, ns = S->N * S->s;
  const fesd__model *m = &it->model;
  double *z = it->z;
  for (int round = 0; round < 4; round++) {
    const int p0 = v.stage, k0 = m->th_off[v.sys], k1 = m->th_off[v.sys + 1];
    if (p0 >= ns) return FESD_ERR_STEP_FAILED;
    unsigned char cands[2][64];
    int i_old = -1;
    const double *x = S->X + (size_t)p0 * S->nx; /* the stage state of the last solve */
    int nc = candidates(it, &v, it->act + (size_t)p0 * nth, x, cands, &i_old);
    if (nc == 0) return FESD_ERR_STEP_FAILED;
    memcpy(it->zpred, z, (size_t)S->n * sizeof(double));
    int advanced = 0;
    for (int c = 0; c < nc && !advanced; c++) {
      memcpy(z, it->zpred, (size_t)S->n * sizeof(double));
      for (int p = p0; p < ns; p++) memcpy(it->act + (size_t)p * nth + k0, cands[c], (size_t)(k1 - k0));
      fesd__impose_active(it, z, it->act);
      int st = fesd__consistent_guess(it, z);
      if (st) return st;
      fesd__violation v2;
      v2.found = 0;
      st = active_solve(it, z, it->set.max_iter, &v2, info);
      if (cb_failed(st)) return st;
      if (st == FESD_OK) {
        info->switch_step = 1; /* the active set changed inside the step */
        return FESD_OK;
      }
      if (v2.found && v2.stage > p0) {
        v = v2;
        advanced = 1;
      }
    }
    if (!advanced) return FESD_ERR_STEP_FAILED;
  }
  return FESD_ERR_STEP_FAILED;
}

static int active_path(fesd_integrator *it, double T, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  const int N = S->N, nth = S->nth, s = S->s;
  double *z = it->z, *zf = it->zfast;
  fesd__violation v;
  int st;
  /* fast path: the start's active set at every stage, equal h */
  for (int p = 0; p < N * s; p++) memcpy(it->act + (size_t)p * nth, it->act0, (size_t)nth);
  memset(it->bmode, 0, (size_t)(N + 1) * sizeof(int));
  memcpy(z, it->z0, (size_t)S->n * sizeof(double));
  fesd__impose_active(it, z, it->act);
  if ((st = fesd__consistent_guess(it, z))) return st;
  st = active_solve(it, z, it->set.max_iter_first, &v, info);
  if (st == FESD_OK) return FESD_OK;
  if (st != FESD_ERR_STEP_FAILED || !v.found) return cb_failed(st) ? st : FESD_ERR_STEP_FAILED;
  if (it->set.method == FESD_METHOD_STANDARD) return std_switch(it, v, info);
  memcpy(zf, z, (size_t)S->n * sizeof(double));
  /* candidate active sets after the switch */
  const fesd__model *m = &it->model;
  int k0 = m->th_off[v.sys], k1 = m->th_off[v.sys + 1], ncand = 0;
  unsigned char cands[2][64];
  if (k1 - k0 > 64) return FESD_ERR_STEP_FAILED;
  int is_exit = !v.enter, i_old_mode = -1;
  if (is_exit) {
    if (!it->set.exit_rows || S->bp) return FESD_ERR_STEP_FAILED; /* paper formulation: FB path */
    for (int i = k0; i < k1; i++) cands[0][i - k0] = it->act0[i] && i != v.mode;
    ncand = 1;
  } else {
    int i_old = k0;
    i_old_mode = k0;
    for (int i = k0; i < k1; i++)
      if (it->act0[i] && (!it->act0[i_old] || zf[fesd__th(S, 0, 0) + i] > zf[fesd__th(S, 0, 0) + i_old])) i_old = i;
    int cross = 1;
    i_old_mode = i_old;
    if ((st = crossing_first(it, state_near(it, zf, v.t), i_old, v.mode, &cross))) return st;
    for (int i = k0; i < k1; i++) {
      cands[!cross][i - k0] = i == v.mode;                 /* crossing: j replaces the set */
      cands[cross][i - k0] = it->act0[i] || i == v.mode;   /* sliding: j joins the set */
    }
    ncand = 2;
  }
  /* boundary carrying the switch; a switch at the very start changes the whole step */
  const double tstar = v.t;
  int kb = (int)lround(tstar / T * N);
  if (kb < 1) kb = 1;
  if (kb > N - 1) kb = N - 1;
  int at_start = tstar <= 1e-9 * T;
  for (int c = 0; c < ncand; c++) {
    memcpy(z, zf, (size_t)S->n * sizeof(double));
    memset(it->bmode, 0, (size_t)(N + 1) * sizeof(int));
    for (int n = 0; n < N; n++) {
      for (int j = 0; j < s; j++) {
        unsigned char *a = it->act + (size_t)(n * s + j) * nth;
        memcpy(a, it->act0, (size_t)nth);
        if (at_start || n >= kb) memcpy(a + k0, cands[c], (size_t)(k1 - k0));
      }
      z[S->ho[n]] = at_start ? T / N : (n < kb ? tstar / kb : (T - tstar) / (N - kb));
    }
    if (!at_start) {
      it->bmode[kb] = is_exit ? 2 : 1;
      it->exit_mode[kb] = v.mode;
    }
    fesd__impose_active(it, z, it->act);
    if ((st = fesd__consistent_guess(it, z))) return st;
    fesd__violation v2;
    st = active_solve(it, z, it->set.max_iter, &v2, info);
    if (cb_failed(st)) return st;
    if (st == FESD_OK) {
      info->switch_step = !at_start;
      /* a crossing or entry exactly at the step start: the step equations see no switch,
       * so the sensitivities get the saltation matrix explicitly (fesd__start_jump) */
      if (at_start && !is_exit) {
        it->jump_in = v.mode;
        it->jump_out = i_old_mode;
      }
      return FESD_OK;
    }
  }
  return FESD_ERR_STEP_FAILED;
}

/* ---------- one attempt at a (sub)step of length T ---------- */

static int try_step(fesd_integrator *it, const double *u, double T, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  S->x0 = it->x;
  S->u = u;
  S->lam00 = it->lam00;
  S->T = T;
  int st = fesd__initial_guess(it, u, T, it->z0);
  if (st) return st;
  set_h_bounds(it, T);
  if ((st = fesd__act_start(it, u, it->act0))) return st;
  it->jump_in = -1;
  st = active_path(it, T, info);
  if (cb_failed(st)) return st;
  if (st != FESD_OK) {
    st = fb_path(it, T, info);
    if (st) return st;
    info->fallback++;
    it->jump_in = -1;
  }
  double ccm = 0;
  if (it->set.method == FESD_METHOD_FESD && !fesd__valid(it, it->z, &ccm)) return FESD_ERR_STEP_FAILED;
  if (it->set.method == FESD_METHOD_FESD && (st = fesd__interior_check(it, it->z))) return st;
  info->cc_max = it->set.method == FESD_METHOD_FESD ? ccm : fesd__cc_max(S, it->z);
  return fesd__accept(it, it->z, u, T);
}

int fesd__substep(fesd_integrator *it, const double *u, double T, int depth, fesd_step_info *info) {
  fesd__save(it, &it->bk_sub);
  int st = try_step(it, u, T, info);
  if (st == FESD_OK) return st;
  fesd__load(it, &it->bk_sub); /* accept may have failed half-way */
  if (st == FESD_ERR_CALLBACK || st == FESD_ERR_NOMEM) return st;
  if (depth >= it->set.max_splits)
    return st == FESD_ERR_TOO_MANY_SWITCHES || st == FESD_ERR_NONFINITE ? st : FESD_ERR_STEP_FAILED;
  info->splits++;
  st = fesd__substep(it, u, 0.5 * T, depth + 1, info);
  if (st) return st;
  return fesd__substep(it, u, 0.5 * T, depth + 1, info);
}
