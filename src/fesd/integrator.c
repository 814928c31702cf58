#include "fesd/integrator.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/timer.h"
#include "fesd/step.h"
#include "ncp/ncp_defer.h"
#include "ncp/ncp_nomem.h"
#include "rk/rk_internal.h"

int fesd_settings_default(fesd_settings *s) {
  if (!s) return FESD_ERR_NULL;
  memset(s, 0, sizeof(*s));
  s->method = FESD_METHOD_FESD;
  s->family = FESD_RK_RADAU_IIA;
  s->stages = 2;
  s->n_fe = 2;
  s->newton_tol = 1e-12;
  s->max_iter_first = 12;
  s->max_iter = 40;
  s->cc_tol = 1e-9;
  s->active_tol = 1e-6;
  s->exit_rows = 1;
  s->max_splits = 6;
  s->sensitivities = 0;
  s->max_sweeps = 8;
  s->max_elements = 8;
  s->coarse_tol = 1e-2;
  fesd_ncp_settings_default(&s->ncp);
  return FESD_OK;
}

/* Ranges of the settings (documented in include/fesd_integrator.h). Outside them a step
 * either cannot be solved or returns a state that is not a FESD solution (newton_tol = 1e3
 * gave sum h != T), so they are refused here; NaN fails every comparison. */
static int in_range(double v, double lo, double hi) { return v >= lo && v <= hi; }
static int int_in(int v, int lo, int hi) { return v >= lo && v <= hi; }

static int validate_settings(const fesd_settings *s) {
  if (s->method != FESD_METHOD_FESD && s->method != FESD_METHOD_STANDARD) return FESD_ERR_INVALID_ARG;
  if (!int_in(s->n_fe, s->method == FESD_METHOD_FESD ? 2 : 1, 1000)) return FESD_ERR_INVALID_ARG;
  if (!in_range(s->newton_tol, 1e-16, 1e-3)) return FESD_ERR_INVALID_ARG;
  if (!int_in(s->max_iter_first, 1, 1000) || !int_in(s->max_iter, 1, 1000)) return FESD_ERR_INVALID_ARG;
  if (!(s->cc_tol > 0 && s->cc_tol <= 1e-2) || !(s->active_tol > 0 && s->active_tol <= 0.1))
    return FESD_ERR_INVALID_ARG;
  if (!int_in(s->exit_rows, 0, 1) || !int_in(s->sensitivities, 0, 1)) return FESD_ERR_INVALID_ARG;
  if (!int_in(s->max_splits, 0, 12) || !int_in(s->max_sweeps, 1, 50)) return FESD_ERR_INVALID_ARG;
  if (!int_in(s->max_elements, 2, 4096)) return FESD_ERR_INVALID_ARG;
  if (!in_range(s->coarse_tol, 0.0, 1.0)) return FESD_ERR_INVALID_ARG;
  return FESD_OK;
}

static void level_free(fesd__level *L) {
  fesd_ncp_free(&L->ncp);
  free(L->draw);
  free(L->dz);
  memset(L, 0, sizeof(*L));
}

void fesd_free(fesd_integrator **itp) {
  if (!itp || !*itp) return;
  fesd_integrator *it = *itp;
  for (int l = 0; l < it->n_lv; l++) level_free(&it->lv[l]);
  fesd__system_free(&it->sys);
  fesd__model_free(&it->model);
  fesd__wrap_free(&it->wrap);
  free(it->log);
  free(it->log_pool);
  double *recs[] = {it->rec_h, it->rec_t, it->rec_x, it->rec_th, it->rec_la, it->rec_mu, it->rec_v};
  for (size_t i = 0; i < sizeof(recs) / sizeof(recs[0]); i++) free(recs[i]);
  free(it->events);
  free(it->ev_pool);
  fesd__block_free(it->mem);
  free(it);
  *itp = NULL;
}

int fesd__ladder(const fesd_integrator *it, int N) {
  /* every count up to 8, then steps of about 1.5 (few workspaces, at most 50 % spare) */
  int L = it->set.n_fe;
  while (L < N) L = L < 8 ? L + 1 : L + (L + 1) / 2;
  return L < it->N_cap ? L : it->N_cap;
}

int fesd__use_level(fesd_integrator *it, int N) {
  fesd__system *S = &it->sys;
  int l = 0;
  while (l < it->n_lv && it->lv[l].N != N) l++;
  if (l == it->n_lv) {
    if (it->n_lv == FESD__MAX_LEVELS) return FESD_ERR_TOO_MANY_SWITCHES;
    fesd__system_set_N(S, N);
    fesd__level *L = &it->lv[l];
    memset(L, 0, sizeof(*L));
    L->N = N;
    const size_t nnz = (size_t)S->nnz;
    int *row = malloc((nnz > 0 ? nnz : 1) * sizeof(int)), *col = malloc((nnz > 0 ? nnz : 1) * sizeof(int));
    int st = row && col ? FESD_OK : FESD_ERR_NOMEM;
    if (st == FESD_OK) {
      fesd__system_pattern(S, row, col);
      fesd_ncp_problem p = {S->n, S->n_eq, S->n_pair, S->nnz, row, col, fesd__system_eval, S};
      fesd_ncp_settings ns = it->set.ncp;
      ns.tol = it->set.newton_tol; /* tol and max_iter are set per solve (step.c) */
      ns.max_iter = it->set.max_iter;
      st = fesd_ncp_setup(&L->ncp, &p, &ns);
      /* an ordinary step's solve starts converged: its selection needs no analysis */
      if (st == FESD_OK) fesd__ncp_defer_analysis(L->ncp);
    }
    free(row);
    free(col);
    if (st == FESD_OK && it->set.sensitivities) {
      const size_t np = (size_t)it->np;
      L->draw = malloc((size_t)S->n_raw * np * sizeof(double) + 1);
      L->dz = malloc((size_t)S->n * np * sizeof(double) + 1);
      if (!L->draw || !L->dz) st = FESD_ERR_NOMEM;
    }
    if (st) {
      level_free(L);
      fesd__system_set_N(S, it->lv_cur < it->n_lv ? it->lv[it->lv_cur].N : N);
      return st;
    }
    it->n_lv++;
  }
  it->lv_cur = l;
  it->ncp = it->lv[l].ncp;
  if (S->N != N) fesd__system_set_N(S, N);
  return FESD_OK;
}

/* The arrays of the integrator, in one block (common/block.h): sizes from the layout at
 * creation (N_cap elements, the largest system); the event lists and the step records grow,
 * and stay separate allocations. */
static void lay_out(fesd_integrator *it, const fesd_settings *settings, fesd__block *B) {
  const fesd__system *S = &it->sys;
  const size_t n = (size_t)S->n, nx = (size_t)it->nx, nu = (size_t)it->nu, nth = (size_t)it->nth;
  const size_t np = (size_t)it->np, N = (size_t)it->N_cap, s = (size_t)S->s, nsys = (size_t)it->nsys;
  const size_t cp = (size_t)it->cap_plan;
  it->x = fesd__block_doubles(B, nx);
  it->lam00 = fesd__block_doubles(B, nth);
  it->theta_prev = fesd__block_doubles(B, nth);
  it->ap_lam = fesd__block_doubles(B, nth);
  it->ap_rate = fesd__block_doubles(B, nth);
  it->ap_lam_b = fesd__block_doubles(B, nth);
  it->ap_rate_b = fesd__block_doubles(B, nth);
  it->ap_th = fesd__block_doubles(B, nth);
  it->ap_m = fesd__block_doubles(B, nsys);
  it->ap_m_b = fesd__block_doubles(B, nsys);
  it->ap_m2 = fesd__block_doubles(B, nsys);
  it->ap_m3 = fesd__block_doubles(B, nsys);
  it->u_cur = fesd__block_doubles(B, nu);
  it->ws_blk = fesd__block_doubles(B, (size_t)S->sb);
  it->z = fesd__block_doubles(B, n);
  it->z0 = fesd__block_doubles(B, n);
  it->zpred = fesd__block_doubles(B, n);
  it->zp = fesd__block_doubles(B, n);
  /* sensitivity storage is O(n_x^2): only when asked for */
  const size_t sx = settings->sensitivities ? nx : 1;
  for (fesd__saved *b = &it->bk; b <= &it->bk_sub; b++) {
    b->x = fesd__block_doubles(B, nx);
    b->lam = fesd__block_doubles(B, nth);
    b->th = fesd__block_doubles(B, nth);
    b->blk = fesd__block_doubles(B, (size_t)S->sb);
    b->Sx = fesd__block_doubles(B, sx * sx);
    b->Su = fesd__block_doubles(B, sx * nu);
    b->ldp = fesd__block_doubles(B, settings->sensitivities ? nth * np : 1);
    b->act = fesd__block_take(B, nth > 0 ? nth : 1, 0);
  }
  it->Sx = fesd__block_doubles(B, sx * sx);
  it->Su = fesd__block_doubles(B, sx * nu);
  it->Dtmp = fesd__block_doubles(B, settings->sensitivities ? (nx > nth ? nx : nth) * np : 1);
  it->Stmp = fesd__block_doubles(B, settings->sensitivities ? nx * (nx > nu ? nx : nu) : 1);
  /* + the midpoint states and indicators */
  it->gbuf = fesd__block_doubles(B, nth + (size_t)(FESD_RK_MAX_STAGES + 1) * (nx + nth));
  it->blk = fesd__block_doubles(B, (size_t)S->sb);
  it->vtmp = fesd__block_doubles(B, 2 * nx);
  it->ftot = fesd__block_doubles(B, 4 * nx); /* total field; first_step: two more states, weights */
  it->err_atol = fesd__block_doubles(B, nx);
  it->tol_atol = fesd__block_doubles(B, nx);
  it->gdense = fesd__block_doubles(B, nx); /* calloc: zero */
  it->pt_t = fesd__block_doubles(B, N * (s + 1) + 1);
  it->pt_q = fesd__block_doubles(B, (N * (s + 1) + 1) * nth);
  it->pt_l = fesd__block_doubles(B, (N * (s + 1) + 1) * nth);
  it->zfast = fesd__block_doubles(B, n);
  it->bt = fesd__block_doubles(B, cp + 2);
  it->bseg_lo = fesd__block_doubles(B, cp + 2);
  it->bseg_hi = fesd__block_doubles(B, cp + 2);
  it->hlo = fesd__block_doubles(B, N);
  it->hhi = fesd__block_doubles(B, N);
  it->eq_active = fesd__block_take(B, (size_t)S->n_eq, 0);
  it->act_prev = fesd__block_take(B, nth > 0 ? nth : 1, 0);
  it->pair_mode = fesd__block_take(B, (size_t)(S->n_pair > 0 ? S->n_pair : 1), 0);
  it->raw_border = fesd__block_take(B, (size_t)S->n_raw, 0);
  it->col_border = fesd__block_take(B, n, 0);
  it->pt_src = fesd__block_take(B, (N * (s + 1) + 1) * sizeof(int), 0);
  it->kb = fesd__block_take(B, (cp + N + 2) * sizeof(int), 0);
  it->sw_at = fesd__block_take(B, (N + 1) * sizeof(int), 0);
  it->act = fesd__block_take(B, N * s * nth, 0); /* per stage */
  it->act0 = fesd__block_take(B, nth, 0);
  it->act_first = fesd__block_take(B, nth, 0);
  it->cand = fesd__block_take(B, nth, 0);
  it->swap_set = fesd__block_take(B, nth, 0);
  it->bmode = fesd__block_take(B, (N + 1) * sizeof(int), 1);
  it->exit_mode = fesd__block_take(B, (N + 1) * sizeof(int), 1);
  it->rk_act = fesd__block_take(B, N * s * nth, 0);
  it->rk_bmode = fesd__block_take(B, (2 * (N + 1)) * sizeof(int), 1); /* bmode, then exit_mode */
  it->jump_in = fesd__block_take(B, nsys * sizeof(int), 0);
  it->stop_dir = fesd__block_take(B, nsys, 0);
  it->jump_out = fesd__block_take(B, nsys * sizeof(int), 0);
  it->scan_buf = fesd__block_take(B, nsys * sizeof(*it->scan_buf), 0);
  it->plan = fesd__block_take(B, cp * sizeof(*it->plan), 0);
  it->plan_after = fesd__block_take(B, cp * nth, 0);
  it->bseg = fesd__block_take(B, (cp + 2) * sizeof(int), 0);
  it->fil_th = fesd__block_doubles(B, nth);
  it->herm = fesd__block_doubles(B, 2 * nth);
  it->fil_mi = fesd__block_doubles(B, nsys * s);
  it->fil_mj = fesd__block_doubles(B, nsys * s);
  it->fil_pm = fesd__block_doubles(B, 2 * nsys);
  it->slide_tmp = fesd__block_doubles(B, 2 * nx);
  it->fil_a = fesd__block_take(B, nth, 0);
  fesd__point_take(&it->model, &it->pscr, 1, B);
  it->f0 = fesd__block_doubles(B, (size_t)(it->model.nF > 0 ? it->model.nF : 1));
  const int gq = s * nx; /* the guess's stage Newton: small systems only */
  if (gq <= FESD__GN_MAX && !it->tab.is_explicit) {
    it->gn = fesd__block_doubles(B, (size_t)gq * gq + 2 * (size_t)gq + (size_t)nx * nx);
    const size_t nk = 1 + (size_t)s * (size_t)it->model.pf_nnz;
    it->gn_key = fesd__block_doubles(B, 2 * nk);
    it->gn_memo = it->gn_key ? it->gn_key + nk : NULL;
    it->gn_piv = fesd__block_take(B, (size_t)gq * sizeof(int), 0);
    it->gn_full_at = 1;
  }
}

int fesd_create(fesd_integrator **itp, const fesd_model *model, const fesd_settings *settings) {
  if (!itp) return FESD_ERR_NULL;
  *itp = NULL;
  if (!model) return FESD_ERR_NULL;
  fesd_settings def;
  if (!settings) {
    fesd_settings_default(&def);
    settings = &def;
  }
  int st = validate_settings(settings);
  if (st) return st;
  fesd_tableau tab;
  if ((st = fesd_tableau_get(settings->family, settings->stages, &tab))) return st;
  fesd_integrator *it = calloc(1, sizeof(*it));
  if (!it) return FESD_ERR_NOMEM;
  it->set = *settings;
  it->newton_tol = settings->newton_tol;
  if (model->nsys >= 1 && model->n_modes)
    for (int k = 0; k < model->nsys; k++)
      if (model->n_modes[k] < 2) {
        free(it);
        return FESD_ERR_MODEL;
      }
  fesd_model internal;
  if ((st = fesd__wrap_init(&it->wrap, model, &internal))) {
    free(it);
    return st;
  }
  if ((st = fesd__model_init(&it->model, &internal))) {
    fesd__wrap_free(&it->wrap);
    free(it);
    return st;
  }
  it->nxu = model->nx;
  it->nsysu = model->nsys;
  it->N_cap = settings->max_elements > settings->n_fe ? settings->max_elements : settings->n_fe;
  if ((st = fesd__system_init(&it->sys, &it->model, &tab, it->N_cap, settings->sensitivities))) {
    fesd__model_free(&it->model);
    fesd__wrap_free(&it->wrap);
    free(it);
    return st;
  }
  fesd__system *S = &it->sys;
  it->tab = tab;
  fesd__lagrange_denominators(tab.s, tab.c, it->lag_inv);
  for (int j = 0; j < tab.s; j++) /* explicit RK (repeated nodes): no collocation polynomial, not used */
    it->lag_inv[j] = it->lag_inv[j] != 0 ? 1 / it->lag_inv[j] : 0;
  fesd_tableau_get(FESD_RK_GAUSS_LEGENDRE, tab.s, &it->quad);
  fesd__interior_setup(it);
  fesd__error_setup(it);
  it->n = S->n; /* unknowns of the largest layout */
  it->nx = internal.nx;
  it->nu = model->nu;
  it->nth = it->model.nth;
  it->nsys = internal.nsys;
  it->s = S->s;
  it->np = it->nx + it->nu;
  it->cap_plan = 2 * it->N_cap;
  fesd__block B = {0};
  lay_out(it, settings, &B); /* sizing pass */
  it->mem = fesd__block_open(&B);
  if (it->mem) lay_out(it, settings, &B);
  int fail = !fesd__block_ok(&B);
  int max_nf = 0;
  for (int k = 0; k < it->nsys; k++) max_nf = it->model.nf[k] > max_nf ? it->model.nf[k] : max_nf;
  it->ev_span = 2 * max_nf;
  it->ev_max = FESD_EVENTS_INIT;
  it->events = malloc((size_t)it->ev_max * sizeof(fesd_event));
  it->ev_pool = malloc((size_t)it->ev_max * (size_t)it->ev_span * sizeof(int));
  if (fail || !it->events || !it->ev_pool) {
    fesd_free(&it);
    return FESD_ERR_NOMEM;
  }
  if ((st = fesd__grow_records(it, 2 * it->N_cap)) || (st = fesd__use_level(it, settings->n_fe))) {
    fesd_free(&it);
    return st;
  }
  *itp = it;
  return FESD_OK;
}

/* The sum of the mode fields (f) at x0 at time t, and the indicators (*g: the scratch point's,
 * valid until its next use). */
static int autonomy_probe(fesd_integrator *it, double t, const double *u, double *f, const double **g) {
  fesd__model *m = &it->model;
  fesd__point_eval pe = fesd__scratch_eval(it);
  pe.dgdx = NULL;
  int st = fesd__model_eval(m, t, it->x, u, &pe);
  if (st) return st;
  memset(f, 0, (size_t)m->nx * sizeof(double));
  for (int i = 0; i < m->nth; i++) fesd__F_axpy(m, &pe, i, 1.0, f);
  *g = pe.g;
  return FESD_OK;
}

/* A model declared time-independent (time_dependent = 0) whose callbacks depend on t: the step
 * system's derivatives leave out d/dt, and a switch that only time drives cannot be solved
 * (measured: a stop condition r = t - 0.9 ended FESD_ERR_STEP_TOO_SMALL after 36 failed
 * attempts, with nothing saying why). The indicators and the sum of the mode fields at x0 are
 * compared at t0 and a later time; any difference is FESD_ERR_MODEL. */
static int check_autonomous(fesd_integrator *it, const double *u) {
  const int nx = it->model.nx, nth = it->model.nth;
  double *g0 = it->gbuf, *f0 = it->ftot, *f1 = it->ftot + nx;
  const double *g;
  int st = autonomy_probe(it, it->t, u, f0, &g);
  if (st) return st;
  memcpy(g0, g, (size_t)nth * sizeof(double));
  if ((st = autonomy_probe(it, it->t + 1e-3 * fmax(1.0, fabs(it->t)) + 0.5, u, f1, &g))) return st;
  for (int i = 0; i < nth; i++)
    if (g[i] != g0[i]) return FESD_ERR_MODEL;
  for (int r = 0; r < nx; r++)
    if (f1[r] != f0[r]) return FESD_ERR_MODEL;
  return FESD_OK;
}

int fesd_set_state(fesd_integrator *it, double t0, const double *x0, const double *u) {
  if (!it || !x0 || (it->nu > 0 && !u)) return FESD_ERR_NULL;
  if (!isfinite(t0)) return FESD_ERR_INVALID_ARG;
  for (int i = 0; i < it->nxu; i++)
    if (!isfinite(x0[i])) return FESD_ERR_INVALID_ARG;
  it->t = t0;
  it->t_c = 0.0;
  memcpy(it->x, x0, (size_t)it->nxu * sizeof(double));
  if (it->wrap.td) it->x[it->nxu] = t0; /* time as the last state */
  it->have_ws = 0;
  it->have_prev_theta = 0;
  it->gn_warm = 0; /* a new integration takes the stage Newton's path of a new object */
  fesd__system_reset_refs(&it->sys);
  if (it->set.sensitivities) {
    memset(it->Sx, 0, (size_t)it->nx * it->nx * sizeof(double));
    for (int i = 0; i < it->nx; i++) it->Sx[i * it->nx + i] = 1.0;
    if (it->nu > 0) memset(it->Su, 0, (size_t)it->nx * it->nu * sizeof(double));
  }
  memset(&it->stats, 0, sizeof(it->stats));
  it->sum_iter_ord = it->sum_iter_sw = 0;
  it->n_el = 0;
  it->n_events = 0;
  it->h_next = 0;
  it->log_n = 0;
  memset(it->stop_dir, 0, (size_t)it->nsys);
  it->last_stop_t = NAN;
  it->ap_t = NAN;
  it->ap_h2 = it->ap_h3 = NAN; /* no margin history (fesd__slide_cap) */
  it->ec_rejected = 0;
  it->ec_err_prev = 0;
  it->log_pool_n = 0;
  /* lambda00 = g(x0) - min g (paper Sec. 3.2.2), with its derivative for sensitivities */
  int st = fesd__update_lambda00(it, it->x, u, it->set.sensitivities, NULL);
  if (st == FESD_OK && !it->wrap.td) st = check_autonomous(it, u);
  it->have_state = (st == FESD_OK);
  return st;
}

void fesd__save(fesd_integrator *it, fesd__saved *b) {
  const size_t nx = (size_t)it->nx, nth = (size_t)it->nth, nu = (size_t)it->nu;
  b->t = it->t;
  b->t_c = it->t_c;
  b->have_ws = it->have_ws;
  b->have_prev_theta = it->have_prev_theta;
  b->n_el = it->n_el;
  b->n_events = it->n_events;
  b->gn_warm = it->gn_warm;
  memcpy(b->x, it->x, nx * sizeof(double));
  memcpy(b->lam, it->lam00, nth * sizeof(double));
  memcpy(b->th, it->theta_prev, nth * sizeof(double));
  for (size_t i = 0; i < nth; i++) b->act[i] = it->act_prev[i]; /* a few bytes: no call */
  memcpy(b->blk, it->ws_blk, (size_t)it->sys.sb * sizeof(double));
  if (!it->set.sensitivities) return; /* O(n_x^2) state only then */
  memcpy(b->Sx, it->Sx, nx * nx * sizeof(double));
  memcpy(b->Su, it->Su, nx * nu * sizeof(double));
  memcpy(b->ldp, it->sys.lam00_dp, nth * (size_t)it->np * sizeof(double));
}

void fesd__load(fesd_integrator *it, const fesd__saved *b) {
  const size_t nx = (size_t)it->nx, nth = (size_t)it->nth, nu = (size_t)it->nu;
  it->t = b->t;
  it->t_c = b->t_c;
  it->have_ws = b->have_ws;
  it->have_prev_theta = b->have_prev_theta;
  it->n_el = b->n_el;
  it->n_events = b->n_events;
  it->gn_warm = b->gn_warm;
  memcpy(it->x, b->x, nx * sizeof(double));
  memcpy(it->lam00, b->lam, nth * sizeof(double));
  memcpy(it->theta_prev, b->th, nth * sizeof(double));
  for (size_t i = 0; i < nth; i++) it->act_prev[i] = b->act[i];
  memcpy(it->ws_blk, b->blk, (size_t)it->sys.sb * sizeof(double));
  if (!it->set.sensitivities) return;
  memcpy(it->Sx, b->Sx, nx * nx * sizeof(double));
  memcpy(it->Su, b->Su, nx * nu * sizeof(double));
  memcpy(it->sys.lam00_dp, b->ldp, nth * (size_t)it->np * sizeof(double));
}

/* Allocation failures met by the solver workspaces of every layout. */
static long nomem_count(const fesd_integrator *it) {
  long c = 0;
  for (int l = 0; l < it->n_lv; l++) c += fesd__ncp_nomem_count(it->lv[l].ncp);
  return c;
}

int fesd_step(fesd_integrator *it, const double *u, double T, fesd_step_info *info) {
  fesd_step_info local;
  if (!info) info = &local;
  memset(info, 0, sizeof(*info));
  if (!it) return info->status = FESD_ERR_NULL;
  if (it->nu > 0 && !u) return info->status = FESD_ERR_NULL;
  if (!it->have_state) return info->status = FESD_ERR_NOT_READY;
  if (!(T > 0) || !isfinite(T)) return info->status = FESD_ERR_INVALID_ARG;
  for (int i = 0; i < it->nu; i++)
    if (!isfinite(u[i])) return info->status = FESD_ERR_INVALID_ARG;
  double t0 = fesd__wall_time();
  if (!it->ec_on) it->ap_h2 = it->ap_h3 = NAN; /* a step outside error control: no margin history */
  it->n_el = 0;
  it->n_events = 0;
  fesd__save(it, &it->bk);
  it->model.failed = NULL;
  const double t_start = it->t;
  it->step_flags = 0;
  info->min_substep = T;
  info->last_time = t_start;
  const long nomem0 = nomem_count(it);
  int st = fesd__substep(it, u, T, 0, info);
  /* an allocation that failed inside the step (the step may have gone on by another path
   * or by halving) fails the step: its result would differ from the one of a clean run */
  if (nomem_count(it) != nomem0) st = FESD_ERR_NOMEM;
  if (st == FESD_OK) {
    /* sub-steps add up to T up to round-off; compensated summation keeps a long run of
     * steps at the exact sum of the step lengths (a plain sum drifts by ~N eps t) */
    const double y = T - it->t_c, tt = t_start + y;
    it->t_c = (tt - t_start) - y;
    it->t = tt;
    if (it->wrap.td) it->x[it->nxu] = it->t;
  }
  info->time = fesd__wall_time() - t0;
  info->status = st;
  if (st != FESD_ERR_CALLBACK && st != FESD_ERR_NONFINITE) info->failed_callback = NULL;
  if (st != FESD_OK) {
    info->failed_time = it->t; /* start of the sub-step that failed */
    if (st == FESD_ERR_CALLBACK || st == FESD_ERR_NONFINITE) info->failed_callback = it->model.failed;
    fesd__load(it, &it->bk); /* the state is unchanged; no records */
    if (!info->failed_path) info->failed_path = st == FESD_ERR_CALLBACK || st == FESD_ERR_NONFINITE ? "callback" : "step";
    /* the work of a failed step counts */
    fesd_stats *F = &it->stats;
    F->failed_steps++;
    F->newton_iter += info->newton_iter;
    F->factorizations += info->factorizations;
    F->solves += info->solves;
    F->homotopy_stages += info->homotopy_stages;
    F->splits += info->splits;
    F->time += info->time;
    return st;
  }
  fesd_stats *S = &it->stats;
  S->steps++;
  S->newton_iter += info->newton_iter;
  S->factorizations += info->factorizations;
  S->solves += info->solves;
  S->homotopy_stages += info->homotopy_stages;
  S->splits += info->splits;
  S->fallback_steps += info->fallback;
  S->substeps += info->substeps;
  info->flags |= it->step_flags;
  info->failed_path = NULL; /* a path that failed before another one succeeded */
  info->failed_residual = 0;
  S->nonunique_steps += (info->flags & FESD_FLAG_NONUNIQUE) != 0;
  S->sens_inaccurate_steps += (info->flags & FESD_FLAG_SENS_INACCURATE) != 0;
  S->exit_not_pinned_steps += (info->flags & FESD_FLAG_EXIT_NOT_PINNED) != 0;
  S->coarse_steps += (info->flags & FESD_FLAG_COARSE) != 0;
  S->ambiguous_steps += (info->flags & FESD_FLAG_AMBIGUOUS) != 0;
  S->events += it->n_events;
  S->time += info->time;
  /* a stop condition crossing back in a step of plain fesd_step: its next crossing in the stop's
   * direction is a new stop (measured: skipped, the integration stopped a period later) */
  if (!it->ec_on && it->n_events > 0) fesd__rearm_stops(it);
  int sw = info->switch_step || info->splits > 0 || info->substeps > 0;
  it->last_sw = sw;
  it->last_iter = info->newton_iter;
  if (sw) {
    S->switch_steps++;
    it->sum_iter_sw += info->newton_iter;
    if (info->newton_iter > S->max_iter_switch_step) S->max_iter_switch_step = info->newton_iter;
    S->mean_iter_switch_step = it->sum_iter_sw / S->switch_steps;
  } else {
    int ord = S->steps - S->switch_steps;
    it->sum_iter_ord += info->newton_iter;
    if (info->newton_iter > S->max_iter_ordinary_step) S->max_iter_ordinary_step = info->newton_iter;
    S->mean_iter_ordinary_step = it->sum_iter_ord / ord;
  }
  return FESD_OK;
}
