/* Initial guesses of the step system: warm start from the previous step, the LP at
 * the state for the first step, consistency sweeps, and the re-sorted guess around
 * predicted switches (FB fallback path). */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

/* LP values of a stage block at the evaluated point: mu the theta-weighted indicator (so the
 * modes theta marks active get lambda = 0 on the surface), lambda = g - mu. */
static void stage_lp(const fesd__model *m, const double *g, const double *th, double *la, double *mu) {
  for (int k = 0; k < m->nsys; k++) {
    double num = 0, den = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) num += th[i] * g[i], den += th[i];
    mu[k] = den > 0 ? num / den : g[m->th_off[k]];
  }
  for (int i = 0; i < m->nth; i++) la[i] = g[i] - mu[m->sys_of[i]];
}

/* Make a guess consistent with its theta and h: a few fixed-point sweeps
 * v_j = F(X_j) theta_j with X_j = x_n + h sum_l a_jl v_l (exact for explicit methods after
 * s sweeps), then lambda, mu from the LP rows with mu the theta-weighted indicator (so the
 * modes that theta marks active get lambda = 0), x_{n+1} by the quadrature, and the boundary
 * LP values. Only the rows that carry the switch (cross complementarity) stay inconsistent. */
int fesd__consistent_guess(fesd_integrator *it, double *z) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nx = S->nx, nth = S->nth, s = S->s;
  double *g = it->pscr.g, *X = S->X; /* X: scratch of the sweeps (the stage points: S->X + p nx) */
  fesd__system_points_stale(S);
  fesd__point_eval pe = {0}, pg = {0}; /* fields only in the sweeps; indicators once after */
  pe.F = it->pscr.F;
  pg.g = g;
  double tn = S->t0;
  it->guess_fixed = 1;
  int full = 1; /* every stage point evaluated in full at the stage Newton's state */
  for (int n = 0; n < S->N; n++) {
    const double *xn = n == 0 ? S->x0 : z + S->xo[n - 1];
    double h = z[S->ho[n]];
    /* The sweeps contract like (h |A| |dF/dx|)^k. They cost no Jacobian and no factorization,
     * so up to settings.max_sweeps (8) are spent while they contract fast (ratio <= 1/4): a converged guess saves
     * the Newton iteration of an ordinary step (measured: oscillator, Radau s = 3, N_sim = 40:
     * 40 iterations with 3 sweeps, 2 with converged sweeps). Slow contraction stops them
     * (Newton is then cheaper). A stiff mode makes them diverge (the guess overflows and
     * Newton fails), so when a sweep changes v clearly more than the previous one, the
     * stages are frozen at x_n for a last sweep: v_j = F(x_n) theta_j. */
    const int newton_ok = fesd__stage_newton(it, z, n, xn, h, tn) == 0;
    const int n_sweep = newton_ok ? 0 : S->tab.is_explicit ? s : it->set.max_sweeps;
    it->guess_fixed &= newton_ok;
    int frozen = 0;
    double prev = INFINITY, vmax = 0;
    for (int sweep = 0; sweep < n_sweep; sweep++) {
      double change = 0;
      for (int j = 0; j < s; j++) {
        for (int r = 0; r < nx; r++) {
          double acc = 0;
          for (int l = 0; l < s; l++) acc += S->tab.A[j][l] * z[fesd__v(S, n, l) + r];
          X[r] = xn[r] + (frozen ? 0.0 : h * acc);
        }
        const double *th = z + fesd__th(S, n, j);
        int st = fesd__model_fields_active(m, tn + S->tab.c[j] * h, X, S->u, pe.F, th);
        if (st) return st;
        double *v = z + fesd__v(S, n, j);
        double *vold = it->vtmp; /* the previous v, to measure the sweep's change */
        memcpy(vold, v, (size_t)nx * sizeof(double));
        memset(v, 0, (size_t)nx * sizeof(double));
        for (int i = 0; i < nth; i++)
          if (th[i] != 0.0) fesd__F_axpy(m, &pe, i, th[i], v);
        for (int r = 0; r < nx; r++) { /* (no fmax: a libm call here, v is finite) */
          const double dv = fabs(v[r] - vold[r]), av = fabs(v[r]);
          change = dv > change ? dv : change;
          vmax = av > vmax ? av : vmax;
        }
      }
      if (!frozen && !S->tab.is_explicit && !(change <= 2 * prev || change <= 1e-10)) {
        frozen = 1;
        sweep = n_sweep - 2; /* one more (frozen) sweep */
      } else if (!frozen && !S->tab.is_explicit && sweep >= 2 &&
                 (change <= 1e-15 * (1 + vmax) || change > 0.25 * prev)) {
        break; /* converged, or contracting too slowly to beat a Newton iteration */
      }
      prev = change;
    }
    /* lambda, mu from the LP rows at the final stage states */
    for (int j = 0; j < s; j++) {
      double *Xj = S->X + (size_t)(n * s + j) * nx; /* as the stage Newton left it */
      for (int r = 0; r < nx && !newton_ok; r++) {
        double acc = 0;
        for (int l = 0; l < s; l++) acc += S->tab.A[j][l] * z[fesd__v(S, n, l) + r];
        Xj[r] = xn[r] + h * acc;
      }
      /* in full (Jacobians too): the weights of the solve that follows evaluate these points
       * again when the guess is its solution (an ordinary step); g alone if that fails (a
       * failing Jacobian callback is reported by the solve, as without this) */
      const double tj = tn + S->tab.c[j] * h;
      const fesd__point_eval *pf = fesd__system_stage_eval(S, n * s + j, tj, Xj, 1);
      full &= pf != NULL;
      if (!pf) {
        int st = fesd__model_eval(m, tj, Xj, S->u, &pg);
        if (st) return st;
      }
      stage_lp(m, pf ? pf->g : g, z + fesd__th(S, n, j), z + fesd__la(S, n, j), z + fesd__mu(S, n, j));
    }
    for (int r = 0; r < nx; r++) {
      double acc = 0;
      for (int j = 0; j < s; j++) acc += S->tab.b[j] * z[fesd__v(S, n, j) + r];
      z[S->xo[n] + r] = xn[r] + h * acc;
    }
    if (S->bp) {
      int st = fesd__model_g(m, tn + h, z + S->xo[n], S->u, g);
      if (st) return st;
      double *LB = z + S->lbo[n];
      stage_lp(m, g, z + fesd__th(S, n, s - 1), LB, LB + nth);
    }
    tn += h;
  }
  if (it->guess_fixed && full && !S->bp && !S->look) fesd__system_points_adopt(S, z);
  return FESD_OK;
}

/* Copy one stage block (v, theta, lambda, mu) into every stage of element n. */
void fesd__fill_element(fesd_integrator *it, double *z, int n, const double *block) {
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
  int st = fesd__model_g(m, it->t, x, u, it->gbuf);
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
  fesd__point_eval pe = {0};
  pe.F = it->pscr.F;
  if ((st = fesd__model_eval(m, it->t, x, u, &pe))) return st;
  memset(block, 0, (size_t)nx * sizeof(double));
  for (int i = 0; i < nth; i++)
    if (th[i] != 0.0) fesd__F_axpy(m, &pe, i, th[i], block);
  return FESD_OK;
}

int fesd__initial_guess(fesd_integrator *it, const double *u, double T, double *z) {
  fesd__system *S = &it->sys;
  if (it->have_ws) {
    memcpy(it->blk, it->ws_blk, (size_t)S->sb * sizeof(double));
  } else {
    int st = lp_block(it, it->x, u, it->blk);
    if (st) return st;
  }
  for (int n = 0; n < S->N; n++) {
    fesd__fill_element(it, z, n, it->blk);
    z[S->ho[n]] = T / S->N;
  }
  int st = fesd__consistent_guess(it, z);
  it->z0_fixed = !st && it->guess_fixed;
  return st;
}


/* Sliding subsystems solved together (a dense system of this size; more: the sweeps alone). */
#define SLIDE_DIRECT_MAX 8

/* The multipliers t_k of the ns coupled 2-mode sliding modes (theta_i = t_k, theta_j = 1 - t_k
 * of pair k) that make the total field tangent to every surface psi_k = g_i - g_j:
 *   sum_l grad psi_k . (F_i_l - F_j_l) t_l = -grad psi_k . (f_rest + sum_l F_j_l),
 * solved by elimination with partial pivoting. Gauss-Seidel sweeps converge only when the
 * surfaces' couplings are weak: two sliding subsystems of a random constant field (prop_integrate)
 * left f_0 of the error estimate O(1) off after 4 sweeps (and 60 did no better), the estimate
 * then fell only like h and fesd_integrate took 210,000 steps. Writes th and ftot (the total
 * field) and returns 1 when every t_k lies in [0, 1]; else 0 and changes nothing. */
static int coupled_sliding(fesd_integrator *it, const fesd__point_eval *pe, const int *pi, const int *pj, int ns,
                           double *th, double *ftot) {
  const fesd__model *m = &it->model;
  const int nx = m->nx;
  double M[SLIDE_DIRECT_MAX][SLIDE_DIRECT_MAX + 1], *w = it->slide_tmp, *d = it->slide_tmp + nx;
  memcpy(w, ftot, (size_t)nx * sizeof(double)); /* f_rest + sum_l F_j_l */
  for (int l = 0; l < ns; l++) {
    fesd__F_axpy(m, pe, pi[l], -th[pi[l]], w);
    fesd__F_axpy(m, pe, pj[l], 1.0 - th[pj[l]], w);
  }
  for (int l = 0; l < ns; l++) {
    memset(d, 0, (size_t)nx * sizeof(double));
    fesd__F_axpy(m, pe, pi[l], 1.0, d);
    fesd__F_axpy(m, pe, pj[l], -1.0, d);
    for (int k = 0; k < ns; k++) M[k][l] = fesd__dg_dot(m, pe, pi[k], d) - fesd__dg_dot(m, pe, pj[k], d);
  }
  for (int k = 0; k < ns; k++) M[k][ns] = -(fesd__dg_dot(m, pe, pi[k], w) - fesd__dg_dot(m, pe, pj[k], w));
  double big = 0;
  for (int k = 0; k < ns; k++)
    for (int l = 0; l < ns; l++) big = fmax(big, fabs(M[k][l]));
  for (int c = 0; c < ns; c++) {
    int p = c;
    for (int r = c + 1; r < ns; r++)
      if (fabs(M[r][c]) > fabs(M[p][c])) p = r;
    if (!(fabs(M[p][c]) > 1e-12 * big)) return 0; /* singular: no unique tangent combination */
    for (int k = 0; k <= ns; k++) {
      const double t = M[c][k];
      M[c][k] = M[p][k], M[p][k] = t;
    }
    for (int r = 0; r < ns; r++)
      if (r != c) {
        const double f = M[r][c] / M[c][c];
        for (int k = c; k <= ns; k++) M[r][k] -= f * M[c][k];
      }
  }
  for (int k = 0; k < ns; k++) {
    const double t = M[k][ns] / M[k][k];
    if (!(t >= 0.0 && t <= 1.0)) return 0;
  }
  memcpy(ftot, w, (size_t)nx * sizeof(double));
  for (int k = 0; k < ns; k++) {
    const double t = M[k][ns] / M[k][k];
    th[pi[k]] = t, th[pj[k]] = 1.0 - t;
    fesd__F_axpy(m, pe, pi[k], t, ftot);
    fesd__F_axpy(m, pe, pj[k], -t, ftot);
  }
  return 1;
}

/* theta of the stage for the active flags a at the evaluated point pe: the indicator of a
 * single mode; for a 2-mode sliding mode Filippov's multiplier (the convex combination
 * tangent to the surface, other subsystems at th; several sliding subsystems together), else
 * uniform weights. */
void fesd__stage_theta(fesd_integrator *it, const fesd__point_eval *pe, const unsigned char *a,
                        double *th) {
  const fesd__model *m = &it->model;
  for (int k = 0; k < m->nsys; k++) {
    int cnt = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i];
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) th[i] = a[i] ? 1.0 / cnt : 0.0;
  }
  int ns = 0, pi[SLIDE_DIRECT_MAX], pj[SLIDE_DIRECT_MAX];
  for (int k = 0; k < m->nsys; k++) {
    int j, i = fesd__two_modes(m, a, k, &j);
    if (i < 0) continue;
    if (ns < SLIDE_DIRECT_MAX) pi[ns] = i, pj[ns] = j;
    ns++;
  }
  if (!ns) return;
  double *ftot = it->ftot;
  fesd__total_field(it, pe, th, ftot);
  if (ns > 1 && ns <= SLIDE_DIRECT_MAX && coupled_sliding(it, pe, pi, pj, ns, th, ftot)) return;
  /* one sliding subsystem (one sweep is exact), or many, or no tangent combination inside
   * [0, 1]: Gauss-Seidel sweeps over the 2-mode multipliers, each updated only where its
   * surface attracts */
  for (int sweep = 0; sweep < 4; sweep++)
    for (int k = 0; k < m->nsys; k++) {
      int j, i = fesd__two_modes(m, a, k, &j);
      if (i < 0) continue;
      double ai, aj;
      fesd__normal_components(it, pe, th, ftot, i, j, &ai, &aj);
      if (ai > 0 && aj < 0) { /* a sliding mode at this point */
        const double ti = -aj / (ai - aj), tj = ai / (ai - aj);
        fesd__F_axpy(m, pe, i, ti - th[i], ftot);
        fesd__F_axpy(m, pe, j, tj - th[j], ftot);
        th[i] = ti;
        th[j] = tj;
      }
    }
}

int fesd__regrid_guess(fesd_integrator *it, const double *zp, int Np, double *z) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nx = S->nx, nth = S->nth, s = S->s;
  double *X = S->X; /* scratch: one state */
  fesd__system_points_stale(S);
  fesd__point_eval pe = fesd__scratch_eval(it);
  double tn = 0;
  for (int n = 0; n < S->N; n++) {
    const double h = z[S->ho[n]];
    for (int j = 0; j < s; j++) {
      fesd__state_at(it, zp, Np, tn + S->tab.c[j] * h, X);
      int st = fesd__model_eval(m, S->t0 + tn + S->tab.c[j] * h, X, S->u, &pe);
      if (st) return st;
      double *v = z + fesd__v(S, n, j), *th = z + fesd__th(S, n, j);
      fesd__stage_theta(it, &pe, it->act + (size_t)(n * s + j) * nth, th);
      memset(v, 0, (size_t)nx * sizeof(double));
      for (int i = 0; i < nth; i++)
        if (th[i] != 0.0) fesd__F_axpy(m, &pe, i, th[i], v);
      stage_lp(m, pe.g, th, z + fesd__la(S, n, j), z + fesd__mu(S, n, j));
    }
    tn += h;
    fesd__state_at(it, zp, Np, tn, z + S->xo[n]);
    if (S->bp) {
      int st = fesd__model_g(m, S->t0 + tn, z + S->xo[n], S->u, pe.g);
      if (st) return st;
      double *LB = z + S->lbo[n];
      stage_lp(m, pe.g, z + fesd__th(S, n, s - 1), LB, LB + nth);
    }
  }
  return FESD_OK;
}
