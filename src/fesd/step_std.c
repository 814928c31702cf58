/* Standard time-stepping (settings.method = FESD_METHOD_STANDARD): fixed element lengths, the
 * same smooth solves as the FESD plan path (step.c) with per-stage active sets; explicit
 * tableaus computed forward stage by stage. */
#include <string.h>

#include "fesd/step.h"

/* Candidate active sets of subsystem v->sys after the violation v (standard method), best
 * first: an exit drops the mode; an entering mode j replaces the set (crossing) or joins it
 * (sliding), in the order given by the direction of the fields at the stage state. */
static int candidates(fesd_integrator *it, const fesd__violation *v, const unsigned char *cur,
                      double t, const double *x, const double *theta, unsigned char cands[2][64]) {
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
  fesd__point_eval pe = fesd__scratch_eval(it);
  if (fesd__model_eval(&it->model, t, x, it->sys.u, &pe)) return 0;
  double ai, aj;
  fesd__total_field(it, &pe, theta, it->ftot);
  fesd__normal_components(it, &pe, theta, it->ftot, i_old, v->mode, &ai, &aj);
  const int cross = aj > 0;
  for (int i = k0; i < k1; i++) {
    cands[!cross][i - k0] = i == v->mode;          /* crossing: j replaces the set */
    cands[cross][i - k0] = cur[i] || i == v->mode; /* sliding: j joins the set */
  }
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
    const double *x = S->X + (size_t)p0 * S->nx; /* the stage state of the last solve */
    double tp = S->t0; /* the time of stage p0 */
    for (int n = 0; n < p0 / S->s; n++) tp += z[S->ho[n]];
    tp += S->tab.c[p0 % S->s] * z[S->ho[p0 / S->s]];
    int nc = candidates(it, &v, it->act + (size_t)p0 * nth, tp, x, z + fesd__th(S, p0 / S->s, p0 % S->s), cands);
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
      st = fesd__fixed_solve(it, z, it->set.max_iter, 0, info);
      if (fesd__hard_failure(st)) return st;
      if (st == FESD_OK) {
        if ((st = fesd__scan(it, z, it->act, 1, &v2, NULL))) return st;
        if (!v2.found) {
          info->switch_step = 1; /* the active set changed inside the step */
          return FESD_OK;
        }
        if (v2.stage > p0) {
          v = v2;
          advanced = 1;
        }
      }
    }
    if (!advanced) return FESD_ERR_STEP_FAILED;
  }
  return FESD_ERR_STEP_FAILED;
}

/* Standard method with an explicit RK tableau: its equations are explicit stage by stage, the
 * LP at each stage state picks the mode (argmin of the indicators; at an exact tie the mode of
 * the stage before), so the step is computed forward without Newton. (Solving it with fixed
 * active sets failed where the state chatters within round-off of a surface: a sliding set
 * cannot hold at an explicit stage.) */
static int explicit_std(fesd_integrator *it) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nx = S->nx, nth = S->nth, s = S->s;
  double *z = it->z, *X = S->X, *g = it->pscr.g;
  fesd__system_points_stale(S);
  fesd__point_eval pe = {0};
  pe.F = it->pscr.F;
  pe.g = g;
  const unsigned char *prev = it->act0;
  for (int n = 0; n < S->N; n++) {
    const double h = S->T / S->N, *xn = n == 0 ? S->x0 : z + S->xo[n - 1];
    z[S->ho[n]] = h;
    for (int j = 0; j < s; j++) {
      for (int r = 0; r < nx; r++) {
        double acc = 0;
        for (int l = 0; l < j; l++) acc += S->tab.A[j][l] * z[fesd__v(S, n, l) + r];
        X[r] = xn[r] + h * acc;
      }
      int st = fesd__model_eval(m, S->t0 + (n + S->tab.c[j]) * h, X, S->u, &pe);
      if (st) return st;
      unsigned char *a = it->act + (size_t)(n * s + j) * nth;
      double *th = z + fesd__th(S, n, j), *la = z + fesd__la(S, n, j), *mu = z + fesd__mu(S, n, j);
      for (int k = 0; k < m->nsys; k++) {
        int best = -1;
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++)
          if (best < 0 || g[i] < g[best] || (g[i] == g[best] && prev[i] && !prev[best])) best = i;
        mu[k] = g[best];
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
          a[i] = i == best;
          th[i] = a[i];
          la[i] = g[i] - g[best];
        }
      }
      fesd__total_field(it, &pe, th, z + fesd__v(S, n, j));
      prev = a;
    }
    for (int r = 0; r < nx; r++) {
      double acc = 0;
      for (int j = 0; j < s; j++) acc += S->tab.b[j] * z[fesd__v(S, n, j) + r];
      z[S->xo[n] + r] = xn[r] + h * acc;
    }
    if (S->bp) {
      int st = fesd__model_g(m, S->t0 + (n + 1) * h, z + S->xo[n], S->u, g);
      if (st) return st;
      const double *th = z + fesd__th(S, n, s - 1);
      double *LB = z + S->lbo[n], *MB = LB + nth;
      for (int k = 0; k < m->nsys; k++) {
        MB[k] = 0;
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) MB[k] += th[i] * g[i];
      }
      for (int i = 0; i < nth; i++) LB[i] = g[i] - MB[m->sys_of[i]];
    }
  }
  memset(it->bmode, 0, (size_t)(S->N + 1) * sizeof(int));
  return fesd__rows_active(it, it->act, it->bmode, it->exit_mode);
}

int fesd__std_path(fesd_integrator *it, fesd_step_info *info) {
  if (it->tab.is_explicit) return explicit_std(it);
  int st = fesd__start_solve(it, info);
  if (st) return fesd__hard_failure(st) ? st : FESD_ERR_STEP_FAILED;
  fesd__violation v;
  if ((st = fesd__scan(it, it->z, it->act, 1, &v, NULL))) return st;
  return v.found ? std_switch(it, v, info) : FESD_OK;
}
