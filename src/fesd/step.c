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
#include <stdio.h>
#define DBG(...) do { if (getenv("FESD_DBG")) fprintf(stderr, __VA_ARGS__); } while (0)
static void dbglog(void *u, const char *m) { (void)u; fprintf(stderr, "      %s\n", m); }
#include <string.h>
#include <stdlib.h>

#include "common/timer.h"
#include "fesd/integrator.h"
#include "fesd/step.h"

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
  if (getenv("FESD_DBG") && !homotopy && sigma == 0 && max_iter == it->set.max_iter) ns.log = dbglog;
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

/* x_{n+1} = x_n + h_n sum_j b_j v_{n,j}, so that the guess is consistent in the states. */
static void propagate_states(fesd_integrator *it, double *z) {
  fesd__system *S = &it->sys;
  for (int n = 0; n < S->N; n++) {
    const double *xn = n == 0 ? S->x0 : z + S->xo[n - 1];
    double h = z[S->ho[n]];
    for (int r = 0; r < S->nx; r++) {
      double acc = 0;
      for (int j = 0; j < S->s; j++) acc += S->tab.b[j] * z[fesd__v(S, n, j) + r];
      z[S->xo[n] + r] = xn[r] + h * acc;
    }
  }
}

/* Copy one stage block (v, theta, lambda, mu) into every stage of element n. */
static void fill_element(fesd_integrator *it, double *z, int n, const double *block) {
  fesd__system *S = &it->sys;
  for (int j = 0; j < S->s; j++) memcpy(z + fesd__v(S, n, j), block, (size_t)S->sb * sizeof(double));
  if (S->lbo[n] >= 0) {
    memcpy(z + S->lbo[n], block + S->nx + S->nth, (size_t)S->nth * sizeof(double));
    memcpy(z + S->lbo[n] + S->nth, block + S->nx + 2 * S->nth, (size_t)S->nsys * sizeof(double));
  }
}

/* Stage block from the LP at x: theta = indicator of the argmin of g per subsystem
 * (ties shared), lambda = g - min g, mu = min g, v = F(x) theta. */
static int lp_block(fesd_integrator *it, const double *x, const double *u, double *block) {
  fesd__model *m = &it->model;
  const int nx = m->nx, nth = m->nth;
  double *th = block + nx, *la = th + nth, *mu = la + nth;
  int st = fesd__model_g(m, x, u, it->gbuf);
  if (st) return st;
  for (int k = 0; k < m->nsys; k++) {
    double gmin = INFINITY;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) gmin = fmin(gmin, it->gbuf[i]);
    double tie = 1e-12 * fmax(1.0, fabs(gmin));
    int cnt = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += it->gbuf[i] <= gmin + tie;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      th[i] = it->gbuf[i] <= gmin + tie ? 1.0 / cnt : 0.0;
      la[i] = it->gbuf[i] - gmin;
    }
    mu[k] = gmin;
  }
  memset(block, 0, (size_t)nx * sizeof(double));
  for (int k = 0; k < m->nsys; k++)
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      if (th[i] == 0.0) continue;
      if ((st = m->user.field(k, i - m->th_off[k], x, u, it->gbuf + nth, m->user.user)) != 0) {
        m->failed = "field";
        return FESD_ERR_CALLBACK;
      }
      for (int r = 0; r < nx; r++) block[r] += th[i] * it->gbuf[nth + r];
    }
  return FESD_OK;
}

static int initial_guess(fesd_integrator *it, const double *u, double T, double *z) {
  fesd__system *S = &it->sys;
  if (it->have_ws) {
    memcpy(it->blk, it->zws + fesd__v(S, S->N - 1, S->s - 1), (size_t)S->sb * sizeof(double));
  } else {
    int st = lp_block(it, it->x, u, it->blk);
    if (st) return st;
  }
  for (int n = 0; n < S->N; n++) {
    fill_element(it, z, n, it->blk);
    z[S->ho[n]] = T / S->N;
  }
  propagate_states(it, z);
  return FESD_OK;
}

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

static int fesd_valid(fesd_integrator *it, const double *z, double *ccm) {
  fesd__system *S = &it->sys;
  for (int n = 0; n < S->N; n++)
    if (!(z[S->ho[n]] > 0)) return 0;
  *ccm = fesd__cc_max(S, z);
  return *ccm <= it->set.cc_tol;
}

/* ---------- switch prediction ---------- */

typedef struct {
  double t;
  int i;
} sw_event;

/* Collect the time-ordered points (step start, then every stage point) and find the
 * sign changes of q_i = lambda_i - theta_i, linearly interpolated. Returns the number
 * of clusters of switch times (events closer than half a nominal element merge) and
 * writes the cluster times (mean) to tc. */
static int predict_switches(fesd_integrator *it, const double *z, double T, double *tc, int max_c) {
  fesd__system *S = &it->sys;
  const int nth = S->nth;
  int np = 0;
  /* point p: time pt_t[p], q values pt_q[p*nth + i], source stage index pt_src[p] (-1 = start) */
  if (it->have_prev_theta) {
    it->pt_t[np] = 0;
    for (int i = 0; i < nth; i++) it->pt_q[i] = it->lam00[i] - it->theta_prev[i];
    it->pt_src[np++] = -1;
  }
  double t0 = 0;
  for (int n = 0; n < S->N; n++) {
    double h = z[S->ho[n]];
    for (int j = 0; j < S->s; j++) {
      it->pt_t[np] = t0 + S->tab.c[j] * h;
      for (int i = 0; i < nth; i++)
        it->pt_q[np * nth + i] = z[fesd__la(S, n, j) + i] - z[fesd__th(S, n, j) + i];
      it->pt_src[np++] = n * S->s + j;
    }
    t0 += h;
  }
  sw_event ev[64];
  int ne = 0;

  for (int i = 0; i < nth; i++) {
    int last = -1;
    for (int p = 0; p < np; p++) {
      double q = it->pt_q[p * nth + i];
      if (fabs(q) <= 1e-13) continue;
      if (last >= 0) {
        double ql = it->pt_q[last * nth + i];
        if ((ql > 0) != (q > 0) && ne < 64) {
          double ta = it->pt_t[last], tb = it->pt_t[p];
          ev[ne].t = ta + (tb - ta) * ql / (ql - q);
          ev[ne++].i = i;
        }
      }
      last = p;
    }
  }
  /* sort by time (insertion sort: few events) */
  for (int a = 1; a < ne; a++)
    for (int b = a; b > 0 && ev[b].t < ev[b - 1].t; b--) {
      sw_event tmp = ev[b];
      ev[b] = ev[b - 1];
      ev[b - 1] = tmp;
    }
  int nc = 0;
  double merge = T / S->N;
  for (int a = 0; a < ne;) {
    int b = a;
    double sum = 0;
    while (b < ne && ev[b].t - ev[a].t <= merge) sum += ev[b++].t;
    if (nc < max_c) tc[nc] = sum / (b - a);
    nc++;
    a = b;
  }
  return nc;
}

/* Stage block (pointer into zsrc) of the predictor point nearest to time tm within (lo, hi);
 * NULL if none. */
static const double *source_block(fesd_integrator *it, const double *zsrc, int np, double lo,
                                  double hi, double tm) {
  fesd__system *S = &it->sys;
  int best = -1;
  for (int p = 0; p < np; p++) {
    if (it->pt_src[p] < 0 || it->pt_t[p] <= lo || it->pt_t[p] >= hi) continue;
    if (best < 0 || fabs(it->pt_t[p] - tm) < fabs(it->pt_t[best] - tm)) best = p;
  }
  if (best < 0) return NULL;
  int src = it->pt_src[best];
  return zsrc + fesd__v(S, src / S->s, src % S->s);
}

/* Build the re-sorted initial guess for the reduced system with switches at times tc[0..nc-1];
 * marks the switching boundaries in sw_at. */
static void resort_guess(fesd_integrator *it, const double *zsrc, double T, const double *tc, int nc,
                         int *sw_at, double *z) {
  fesd__system *S = &it->sys;
  const int N = S->N;
  int np = it->have_prev_theta + N * S->s;
  int *kb = it->kb; /* boundary index of each switch, strictly increasing in 1..N-1 */
  for (int c = 0; c < nc; c++) {
    int k = (int)lround(tc[c] / T * N);
    if (k < c + 1) k = c + 1;
    if (k > N - nc + c) k = N - nc + c;
    if (c > 0 && k <= kb[c - 1]) k = kb[c - 1] + 1;
    kb[c] = k;
  }
  for (int k = 0; k <= N; k++) sw_at[k] = 0;
  for (int c = 0; c < nc; c++) sw_at[kb[c]] = 1;
  memcpy(z, zsrc, (size_t)S->n * sizeof(double));
  for (int c = 0; c <= nc; c++) {
    int n_lo = c == 0 ? 0 : kb[c - 1], n_hi = c == nc ? N : kb[c];
    double t_lo = c == 0 ? 0 : tc[c - 1], t_hi = c == nc ? T : tc[c];
    double h = (t_hi - t_lo) / (n_hi - n_lo);
    for (int n = n_lo; n < n_hi; n++) {
      /* the purest values lie farthest from the switches: the earliest point before the
       * first switch, the latest after the last one, the middle in between */
      double tm = c == 0 ? -INFINITY : c == nc ? INFINITY : t_lo + (n - n_lo + 0.5) * h;
      const double *blk = source_block(it, zsrc, np, t_lo, t_hi, tm);
      if (!blk) {
        if (c == 0 && it->have_ws)
          blk = it->zws + fesd__v(S, N - 1, S->s - 1);
        else
          blk = source_block(it, zsrc, np, c == 0 ? -INFINITY : t_lo, INFINITY, tm);
      }
      if (blk) {
        memcpy(it->blk, blk, (size_t)S->sb * sizeof(double));
        fill_element(it, z, n, it->blk);
      }
      z[S->ho[n]] = h;
    }
  }
  propagate_states(it, z);
}

/* ---------- acceptance: sensitivities, records, events, state update ---------- */

/* lambda00 = g(x) - min g e per subsystem, and (when sensitivities are on) its derivative
 * w.r.t. (x, u) using the argmin (ties: the mode with the largest theta_prev). */
int fesd__update_lambda00(fesd_integrator *it, const double *x, const double *u, int deriv) {
  fesd__model *m = &it->model;
  const int nx = m->nx, nu = m->nu, nth = m->nth;
  fesd__point_eval pe = {0};
  pe.g = it->gbuf;
  double *dg = it->sys.lam00_dp; /* nth x (nx+nu) column-major */
  double *dgdx = it->Dtmp, *dgdu = it->Dtmp + (size_t)nth * nx;
  if (deriv) {
    pe.dgdx = dgdx;
    pe.dgdu = nu > 0 ? dgdu : NULL;
  }
  int st = fesd__model_eval(m, x, u, &pe);
  if (st) return st;
  for (int k = 0; k < m->nsys; k++) {
    int imin = m->th_off[k];
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      double tie = 1e-12 * fmax(1.0, fabs(it->gbuf[imin]));
      if (it->gbuf[i] < it->gbuf[imin] - tie ||
          (fabs(it->gbuf[i] - it->gbuf[imin]) <= tie && it->have_prev_theta &&
           it->theta_prev[i] > it->theta_prev[imin]))
        imin = i;
    }
    double gmin = it->gbuf[imin];
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      it->lam00[i] = fmax(it->gbuf[i] - gmin, 0.0);
      if (deriv) {
        for (int c = 0; c < nx; c++) dg[c * nth + i] = dgdx[c * nth + i] - dgdx[c * nth + imin];
        for (int c = 0; c < nu; c++)
          dg[(nx + c) * nth + i] = dgdu[c * nth + i] - dgdu[c * nth + imin];
      }
    }
  }
  return FESD_OK;
}

/* dx_end/d(x_start, u) of the accepted step by the implicit function theorem, chained into
 * Sx, Su. */
static int chain_sensitivities(fesd_integrator *it, const double *z) {
  fesd__system *S = &it->sys;
  const int nx = it->nx, nu = it->nu, np = nx + nu;
  S->want_u = 1;
  int st = fesd__system_eval(z, it->raw, it->jac, S);
  if (st) {
    S->want_u = 0;
    return S->status ? S->status : FESD_ERR_CALLBACK;
  }
  fesd__system_param_jac(S, z, it->draw);
  S->want_u = 0;
  st = fesd_ncp_sensitivity(it->ncp, z, 0.0, np, it->draw, it->dz);
  if (st) return st;
  /* D = rows of x_N in dz: nx x np */
  const int xN = S->xo[S->N - 1];
  double *D = it->Dtmp;
  for (int c = 0; c < np; c++)
    for (int r = 0; r < nx; r++) D[c * nx + r] = it->dz[(size_t)c * S->n + xN + r];
  /* Sx <- Dx Sx ; Su <- Dx Su + Du */
  double *T = it->Stmp;
  for (int c = 0; c < nx; c++)
    for (int r = 0; r < nx; r++) {
      double acc = 0;
      for (int q = 0; q < nx; q++) acc += D[q * nx + r] * it->Sx[c * nx + q];
      T[c * nx + r] = acc;
    }
  memcpy(it->Sx, T, (size_t)nx * nx * sizeof(double));
  for (int c = 0; c < nu; c++)
    for (int r = 0; r < nx; r++) {
      double acc = D[(nx + c) * nx + r];
      for (int q = 0; q < nx; q++) acc += D[q * nx + r] * it->Su[c * nx + q];
      T[c * nx + r] = acc;
    }
  if (nu > 0) memcpy(it->Su, T, (size_t)nx * nu * sizeof(double));
  return FESD_OK;
}

static unsigned active_bits(const fesd_integrator *it, const double *th, int k) {
  unsigned bits = 0;
  const fesd__model *m = &it->model;
  for (int i = m->th_off[k]; i < m->th_off[k + 1] && i - m->th_off[k] < 32; i++)
    if (th[i] > it->set.active_tol) bits |= 1u << (i - m->th_off[k]);
  return bits;
}

/* Active modes of element n of z (theta above active_tol at any stage). */
static unsigned element_bits(const fesd_integrator *it, const double *z, int n, int k) {
  unsigned bits = 0;
  for (int j = 0; j < it->s; j++) bits |= active_bits(it, z + fesd__th(&it->sys, n, j), k);
  return bits;
}

static void add_event(fesd_integrator *it, double t, int k, unsigned before, unsigned after) {
  if (before == after || it->n_events >= FESD_MAX_EVENTS_PER_STEP) return;
  fesd_event *e = &it->events[it->n_events++];
  e->t = t;
  e->sys = k;
  e->before = before;
  e->after = after;
  if ((after & before) == before)
    e->kind = FESD_EVENT_SLIDING_ENTRY;
  else if ((after & before) == after)
    e->kind = FESD_EVENT_SLIDING_EXIT;
  else
    e->kind = FESD_EVENT_CROSSING;
}

static int accept(fesd_integrator *it, const double *z, const double *u, double T) {
  fesd__system *S = &it->sys;
  const int N = S->N, s = S->s, nx = it->nx, nth = it->nth, nsys = it->nsys;
  int st;
  if (it->set.sensitivities && (st = chain_sensitivities(it, z))) return st;
  /* records */
  double t = it->t;
  for (int n = 0; n < N && it->n_el < it->cap_el; n++) {
    int e = it->n_el++;
    it->rec_h[e] = z[S->ho[n]];
    it->rec_t[e] = t;
    memcpy(it->rec_x + (size_t)e * nx, n == 0 ? S->x0 : z + S->xo[n - 1], (size_t)nx * sizeof(double));
    for (int j = 0; j < s; j++) {
      memcpy(it->rec_th + ((size_t)e * s + j) * nth, z + fesd__th(S, n, j), (size_t)nth * sizeof(double));
      memcpy(it->rec_la + ((size_t)e * s + j) * nth, z + fesd__la(S, n, j), (size_t)nth * sizeof(double));
      memcpy(it->rec_mu + ((size_t)e * s + j) * nsys, z + fesd__mu(S, n, j), (size_t)nsys * sizeof(double));
    }
    /* events at the left boundary of element n */
    for (int k = 0; k < nsys; k++) {
      unsigned before = n == 0 ? (it->have_prev_theta ? active_bits(it, it->theta_prev, k) : 0)
                               : element_bits(it, z, n - 1, k);
      if (n == 0 && !it->have_prev_theta) continue;
      add_event(it, t, k, before, element_bits(it, z, n, k));
    }
    t += z[S->ho[n]];
  }
  it->rec_t[it->n_el] = it->t + T;
  memcpy(it->rec_x + (size_t)it->n_el * nx, z + S->xo[N - 1], (size_t)nx * sizeof(double));
  /* state */
  it->t += T;
  memcpy(it->x, z + S->xo[N - 1], (size_t)nx * sizeof(double));
  memcpy(it->theta_prev, z + fesd__th(S, N - 1, s - 1), (size_t)nth * sizeof(double));
  it->have_prev_theta = 1;
  if ((st = fesd__update_lambda00(it, it->x, u, it->set.sensitivities))) return st;
  memcpy(it->zws, z, (size_t)S->n * sizeof(double));
  it->have_ws = 1;
  return FESD_OK;
}

/* ---------- one attempt at a (sub)step of length T ---------- */

static int try_step(fesd_integrator *it, const double *u, double T, fesd_step_info *info) {
  fesd__system *S = &it->sys;
  const double tol = it->set.newton_tol;
  double *z = it->z, *z0 = it->z0, *zp = it->zpred;
  S->x0 = it->x;
  S->u = u;
  S->lam00 = it->lam00;
  S->T = T;
  int st = initial_guess(it, u, T, z0);
  if (st) return st;
  set_h_bounds(it, T);
  if ((st = rows_select(it, NULL))) return st;
  memcpy(z, z0, (size_t)S->n * sizeof(double));
  st = solve(it, z, 0.0, tol, it->set.max_iter_first, 0, info);
  DBG("t=%.4f T=%.4f std st=%d it=%d\n", it->t, T, st, info->newton_iter);
  if (st == FESD_ERR_CALLBACK) return st;
  if (it->set.method == FESD_METHOD_STANDARD) {
    if (st != FESD_OK) {
      memcpy(z, z0, (size_t)S->n * sizeof(double));
      st = solve(it, z, 0.0, tol, it->set.max_iter, 1, info);
      if (st) return st;
    }
    info->cc_max = fesd__cc_max(S, z);
    return accept(it, z, u, T);
  }
  double ccm = 0;
  if (st == FESD_OK && fesd_valid(it, z, &ccm)) {
    info->cc_max = ccm;
    return accept(it, z, u, T);
  }
  /* (b) predictor */
  if (st == FESD_OK) {
    memcpy(zp, z, (size_t)S->n * sizeof(double));
  } else {
    memcpy(zp, z0, (size_t)S->n * sizeof(double));
    int ok = 0;
    for (double sigma = 1e-1; sigma >= 0.9e-3; sigma *= 0.1) {
      int s2 = solve(it, zp, sigma, 1e-2 * sigma, 20, 0, info);
      if (s2 == FESD_ERR_CALLBACK) return s2;
      ok = (s2 == FESD_OK) || ok;
      if (s2 != FESD_OK) break;
    }
    if (!ok) return FESD_ERR_STEP_FAILED;
  }
  double tc[16];
  int nc = predict_switches(it, zp, T, tc, 16);
  DBG("  predictor from %s: nc=%d tc0=%.6f (abs %.6f)\n", st==FESD_OK?"std":"smoothed", nc, nc?tc[0]:-1, nc?it->t+tc[0]:-1);
  if (nc == 0 || nc > S->N - 1) return FESD_ERR_TOO_MANY_SWITCHES;
  /* (c) reduced square FESD system */
  resort_guess(it, zp, T, tc, nc, it->sw_at, z0);
  if ((st = rows_select(it, it->sw_at))) return st;
  memcpy(z, z0, (size_t)S->n * sizeof(double));
  { fesd_ncp_settings ns = it->set.ncp; ns.log = dbglog; fesd_ncp_update_settings(it->ncp, &ns); }
  st = solve(it, z, 0.0, tol, it->set.max_iter, 0, info);
  DBG("  reduced st=%d valid=%d cc=%.2e h0=%.6f h1=%.6f it=%d\n", st, st==0?fesd_valid(it,z,&ccm):-1, ccm, z[S->ho[0]], z[S->ho[1]], info->newton_iter);
  if (st == FESD_ERR_CALLBACK) return st;
  if (st != FESD_OK || !fesd_valid(it, z, &ccm)) {
    memcpy(z, z0, (size_t)S->n * sizeof(double));
    st = solve(it, z, 0.0, tol, it->set.max_iter, 1, info);
    if (st == FESD_ERR_CALLBACK) return st;
    if (st != FESD_OK) return st;
    if (!fesd_valid(it, z, &ccm)) return FESD_ERR_STEP_FAILED;
  }
  info->cc_max = ccm;
  info->switch_step = 1;
  return accept(it, z, u, T);
}

int fesd__substep(fesd_integrator *it, const double *u, double T, int depth, fesd_step_info *info) {
  int st = try_step(it, u, T, info);
  if (st == FESD_OK || st == FESD_ERR_CALLBACK) return st;
  if (depth >= it->set.max_splits) return st == FESD_ERR_TOO_MANY_SWITCHES ? st : FESD_ERR_STEP_FAILED;
  info->splits++;
  st = fesd__substep(it, u, 0.5 * T, depth + 1, info);
  if (st) return st;
  return fesd__substep(it, u, 0.5 * T, depth + 1, info);
}
