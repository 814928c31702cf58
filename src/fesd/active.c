/* Active-set path of the step solve. With the active set of every element fixed
 * (pair rows theta_i = 0 for inactive modes, lambda_i = 0 for active ones) the step
 * system is smooth and Newton converges quadratically; the complementarity signs are
 * then verified (theta >= 0 on active modes, lambda >= 0 on inactive ones). A violated
 * sign locates the next switch accurately: lambda of an inactive mode is a smooth
 * difference of indicators along the computed trajectory, theta of an active mode a
 * smooth sliding multiplier; their linear zero crossing predicts the switch time. */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

/* Active modes of one theta vector (theta > active_tol); every subsystem keeps at least
 * its largest mode. */
void fesd__act_from_theta(const fesd_integrator *it, const double *theta, unsigned char *a) {
  const fesd__model *m = &it->model;
  for (int k = 0; k < m->nsys; k++) {
    int best = m->th_off[k], any = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      a[i] = theta[i] > it->set.active_tol;
      any |= a[i];
      if (theta[i] > theta[best]) best = i;
    }
    if (!any) a[best] = 1;
  }
}

/* x0 on a switching surface (several modes tie for min g): taking all tied modes active
 * means sliding, whose DAE has no solution when every field crosses the surface the same
 * way (e.g. both point outwards: equal normal components, singular in theta). A tied
 * mode i whose field keeps it the strict minimum, d/dt (g_j - g_i) > 0 along the total
 * field with f_i for every other tied j, is entered alone when it is the only such mode
 * (a crossing); otherwise (sliding, or a non-unique spontaneous switch) all stay active.
 * The other subsystems contribute with uniform weights on their tied modes. */
static int resolve_ties(fesd_integrator *it, const double *u, unsigned char *a) {
  fesd__model *m = &it->model;
  const int nx = m->nx, nth = m->nth;
  fesd__point_eval pe = {0};
  pe.F = it->pscr.F;
  pe.g = it->pscr.g;
  pe.dgdx = it->pscr.dgdx;
  int st = fesd__model_eval(m, it->x, u, &pe);
  if (st) return st;
  double *ftot = it->gbuf + nth, *f = it->vtmp; /* nx each */
  memset(ftot, 0, (size_t)nx * sizeof(double));
  for (int k = 0; k < m->nsys; k++) {
    int cnt = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i];
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++)
      if (a[i]) fesd__F_axpy(m, &pe, i, 1.0 / cnt, ftot);
  }
  for (int k = 0; k < m->nsys; k++) {
    int cnt = 0, pick = -1, n_ok = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i];
    if (cnt < 2) continue;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      if (!a[i]) continue;
      int ok = 1;
      for (int j = m->th_off[k]; j < m->th_off[k + 1] && ok; j++) {
        if (j == i || !a[j]) continue;
        /* total field with mode i alone in subsystem k */
        memcpy(f, ftot, (size_t)nx * sizeof(double));
        fesd__F_axpy(m, &pe, i, 1.0, f);
        for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++)
          if (a[l]) fesd__F_axpy(m, &pe, l, -1.0 / cnt, f);
        ok = fesd__dg_dot(m, &pe, j, f) - fesd__dg_dot(m, &pe, i, f) > 0;
      }
      if (ok) pick = i, n_ok++;
    }
    if (n_ok == 1)
      for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) a[i] = i == pick;
  }
  return FESD_OK;
}

/* Active set at the step start: the previous step's last stage, or the argmin of g. */
int fesd__act_start(fesd_integrator *it, const double *u, unsigned char *a) {
  if (it->have_prev_theta) {
    fesd__act_from_theta(it, it->theta_prev, a);
    return FESD_OK;
  }
  fesd__model *m = &it->model;
  int st = fesd__model_g(m, it->x, u, it->gbuf);
  if (st) return st;
  int tied = 0;
  for (int k = 0; k < m->nsys; k++) {
    double gmin = INFINITY;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) gmin = fmin(gmin, it->gbuf[i]);
    double tie = 1e-12 * fmax(1.0, fabs(gmin));
    int cnt = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i] = it->gbuf[i] <= gmin + tie;
    tied |= cnt > 1;
  }
  return tied ? resolve_ties(it, u, a) : FESD_OK;
}

/* theta restricted to the active set of each stage (act: N*s blocks of nth flags), renormalised per subsystem; a
 * subsystem where some active mode has (almost) no weight in the guess (a newly active
 * mode, e.g. a sliding candidate) starts from uniform weights, which keeps the
 * cross-complementarity row of that mode non-degenerate. */
void fesd__impose_active(fesd_integrator *it, double *z, const unsigned char *act) {
  fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  for (int n = 0; n < S->N; n++) {
    for (int j = 0; j < S->s; j++) {
      const unsigned char *a = act + (size_t)(n * S->s + j) * S->nth;
      double *th = z + fesd__th(S, n, j);
      for (int k = 0; k < m->nsys; k++) {
        double sum = 0, low = INFINITY;
        int cnt = 0;
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
          if (!a[i]) {
            th[i] = 0;
            continue;
          }
          th[i] = fmax(th[i], 0.0);
          sum += th[i];
          low = fmin(low, th[i]);
          cnt++;
        }
        int uniform = cnt > 0 && (low < 1e-3 * sum || sum <= 0);
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++)
          if (a[i]) th[i] = uniform ? 1.0 / cnt : th[i] / sum;
      }
    }
  }
}

/* Rows for fixed active sets: pairs A (theta = 0) or B (lambda = 0) per stage;
 * boundary k: bmode[k] = 0 -> h_k = h_{k-1}; 1 -> cross-complementarity row;
 * 2 -> sliding exit of mode exit_mode[k]: the pair of its last stage before the boundary
 * is pinned (theta = lambda = 0) and neither boundary row is used. */
int fesd__rows_active(fesd_integrator *it, const unsigned char *act, const int *bmode,
                      const int *exit_mode) {
  fesd__system *S = &it->sys;
  memset(it->eq_active, 1, (size_t)S->n_eq);
  for (int k = 1; k < S->N; k++) {
    int b = bmode ? bmode[k] : 0;
    it->eq_active[fesd__rowH(S, k)] = (unsigned char)(b == 0);
    it->eq_active[fesd__rowC(S, k)] = (unsigned char)(b == 1);
  }
  for (int n = 0; n < S->N; n++)
    for (int j = 0; j < S->s; j++)
      for (int i = 0; i < S->nth; i++)
        it->pair_mode[fesd__pair(S, n, j, i)] =
            act[(size_t)(n * S->s + j) * S->nth + i] ? FESD_NCP_PAIR_B : FESD_NCP_PAIR_A;
  for (int k = 1; k < S->N; k++)
    if (bmode && bmode[k] == 2) it->pair_mode[fesd__pair(S, k - 1, S->s - 1, exit_mode[k])] = FESD_NCP_PAIR_PIN;
  return fesd_ncp_set_rows(it->ncp, it->eq_active, it->pair_mode);
}

/* Earliest sign violation of the fixed active sets in z, scanning the step start and the
 * stage (and boundary LP) points in time order. strict (the standard method, whose
 * equations hold at every stage): every stage is checked. */
int fesd__find_violation(fesd_integrator *it, const double *z, const unsigned char *act,
                         int strict, fesd__violation *v) {
  fesd__system *S = &it->sys;
  const int nth = S->nth, s = S->s;
  const double tol = it->set.cc_tol;
  v->found = 0;
  v->t = INFINITY;
  for (int i = 0; i < nth; i++) {
    double t0 = 0, v0 = NAN; /* last point value of the monitored quantity */
    int aprev = act[i];
    if (act[i])
      v0 = it->have_prev_theta ? it->theta_prev[i] : 1.0;
    else
      v0 = it->lam00[i];
    double tn = 0;
    int done = 0;
    for (int n = 0; n < S->N && !done; n++) {
      double h = z[S->ho[n]];
      for (int j = 0; j <= s; j++) {
        double t, val;
        const int a = act[(size_t)(n * s + (j < s ? j : s - 1)) * nth + i];
        if (a != aprev) v0 = NAN; /* the active set changes here: no interpolation across */
        aprev = a;
        if (j < s) {
          /* Stage states at c_j = 0 (Lobatto, explicit RK) lie O(h^2) off the element start,
           * and explicit stages are low-order predictions that can overshoot a surface the
           * trajectory does not reach: for FESD their indicator signs are not switches
           * (explicit methods are checked at the element ends). */
          if (!strict && (S->tab.c[j] == 0.0 || (S->tab.is_explicit && !a))) continue;
          t = tn + S->tab.c[j] * h;
          val = a ? z[fesd__th(S, n, j) + i] : z[fesd__la(S, n, j) + i];
        } else {
          if (!S->bp || a) continue; /* boundary LP point: lambda of inactive modes */
          t = tn + h;
          val = z[S->lbo[n] + i];
        }
        if (val < -tol) {
          double tc = isnan(v0) ? tn : (v0 > 0 ? t0 + (t - t0) * v0 / (v0 - val) : t0);
          if (tc < v->t) {
            v->found = 1;
            v->t = tc;
            v->mode = i;
            v->sys = it->model.sys_of[i];
            v->enter = !a;
            v->element = n;
            v->stage = n * s + (j < s ? j : s); /* j == s: the element-end LP point */
          }
          done = 1;
          break;
        }
        t0 = t;
        v0 = val;
      }
      tn += h;
    }
  }
  return v->found;
}

/* Signs between the stage points. Cross complementarity only sees the stage points, so an
 * element can pass through a region its active set does not own (a short excursion, or the
 * many switches of a Zeno accumulation) and still converge: a wrong answer. The collocation
 * polynomial u(tau) = x_n + h sum_j (int_0^tau l_j) v_j is checked at the midpoints between
 * its nodes 0, c_1..c_s (, 1): some inactive mode's indicator below every active one by more
 * than 1e3 cc_tol (interpolation error allowance) rejects the step, which is then halved. */
void fesd__interior_setup(fesd_integrator *it) {
  const fesd_tableau *T = &it->tab;
  double nodes[FESD_RK_MAX_STAGES + 2];
  int nn = 0;
  nodes[nn++] = 0.0;
  for (int j = 0; j < T->s; j++)
    if (T->c[j] > nodes[nn - 1]) nodes[nn++] = T->c[j];
  if (nodes[nn - 1] < 1.0) nodes[nn++] = 1.0;
  it->n_mid = nn - 1;
  for (int p = 0; p + 1 < nn; p++)
    fesd__colloc_weights(it, 0.5 * (nodes[p] + nodes[p + 1]), it->mid_w + p * FESD_RK_MAX_STAGES);
}

int fesd__interior_check(fesd_integrator *it, const double *z) {
  const fesd_tableau *T = &it->tab;
  if (T->family != FESD_RK_RADAU_IIA && T->family != FESD_RK_GAUSS_LEGENDRE &&
      T->family != FESD_RK_LOBATTO_IIIA)
    return FESD_OK;
  fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  const int s = S->s, nx = S->nx;
  const double tol = 1e3 * it->set.cc_tol, atol = it->set.active_tol;
  double *g = it->gbuf, *x = it->gbuf + S->nth;
  for (int n = 0; n < S->N; n++) {
    const double *xn = n == 0 ? S->x0 : z + S->xo[n - 1], h = z[S->ho[n]];
    for (int p = 0; p < it->n_mid; p++) {
      const double *w = it->mid_w + p * FESD_RK_MAX_STAGES;
      memcpy(x, xn, (size_t)nx * sizeof(double));
      for (int j = 0; j < s; j++) {
        const double hw = h * w[j], *v = z + fesd__v(S, n, j);
        for (int r = 0; r < nx; r++) x[r] += hw * v[r];
      }
      int st = fesd__model_g(&it->model, x, S->u, g);
      if (st) return st;
      for (int k = 0; k < m->nsys; k++) {
        double gact = INFINITY, gin = INFINITY;
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
          int act = 0;
          for (int j = 0; j < s; j++) act |= z[fesd__th(S, n, j) + i] > atol;
          if (act) gact = g[i] < gact ? g[i] : gact;
          else gin = g[i] < gin ? g[i] : gin;
        }
        if (gin < gact - tol) return FESD_ERR_STEP_FAILED;
      }
    }
  }
  return FESD_OK;
}
