/* Switch prediction. For the FB fallback path (docs/solver.md, strategy S2c): sign changes of
 * q_i = lambda_i - theta_i along the stage points, refined by linear extrapolation of lambda_i
 * from the side where mode i is inactive, and the re-sorted initial guess around the
 * predicted switches. For the plan path: the entry time of a mode on the solution's
 * collocation polynomial (fesd__refine_entry). */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

typedef struct {
  double t;
  int i;
} sw_event;

/* Collect the time-ordered points (step start, then every stage point) and find the
 * sign changes of q_i = lambda_i - theta_i, linearly interpolated. Returns the number
 * of clusters of switch times (events closer than half a nominal element merge) and
 * writes the cluster times (mean) to tc. */
int fesd__predict_switches(fesd_integrator *it, const double *z, double T, double *tc, int max_c) {
  fesd__system *S = &it->sys;
  const int nth = S->nth;
  int np = 0;
  /* point p: time pt_t[p], q values pt_q[p*nth + i], source stage index pt_src[p] (-1 = start) */
  double *L = it->pt_l;
  if (it->have_prev_theta) {
    it->pt_t[np] = 0;
    for (int i = 0; i < nth; i++) {
      it->pt_q[i] = it->lam00[i] - it->theta_prev[i];
      L[i] = it->lam00[i];
    }
    it->pt_src[np++] = -1;
  }
  double t0 = 0;
  for (int n = 0; n < S->N; n++) {
    double h = z[S->ho[n]];
    for (int j = 0; j < S->s; j++) {
      it->pt_t[np] = t0 + S->tab.c[j] * h;
      for (int i = 0; i < nth; i++) {
        L[np * nth + i] = z[fesd__la(S, n, j) + i];
        it->pt_q[np * nth + i] = L[np * nth + i] - z[fesd__th(S, n, j) + i];
      }
      it->pt_src[np++] = n * S->s + j;
    }
    if (S->bp) { /* boundary LP point at t_{n+1}: theta borrowed from the last stage */
      const double *LB = z + S->lbo[n], *th = z + fesd__th(S, n, S->s - 1);
      it->pt_t[np] = t0 + h;
      for (int i = 0; i < nth; i++) {
        L[np * nth + i] = LB[i];
        it->pt_q[np * nth + i] = LB[i] - th[i];
      }
      it->pt_src[np++] = -2;
    }
    t0 += h;
  }
  sw_event ev[64];
  int ne = 0;

  for (int i = 0; i < nth; i++) {
    int last = -1, prev = -1; /* last two informative points */
    for (int p = 0; p < np; p++) {
      double q = it->pt_q[p * nth + i];
      if (fabs(q) <= 1e-13) continue;
      if (last >= 0) {
        double ql = it->pt_q[last * nth + i];
        if ((ql > 0) != (q > 0) && ne < 64) {
          double ta = it->pt_t[last], tb = it->pt_t[p];
          double t = ta + (tb - ta) * ql / (ql - q);
          /* refine: lambda_i is smooth on the side where mode i is inactive (there it is a
           * difference of indicators); extrapolate it linearly to zero from that side */
          if (ql > 0 && prev >= 0 && it->pt_q[prev * nth + i] > 0) {
            double l1 = L[prev * nth + i], l2 = L[last * nth + i], t1 = it->pt_t[prev];
            if (l1 > l2 && l2 >= 0) t = ta + (ta - t1) * l2 / (l1 - l2);
          } else if (ql < 0) {
            int nxt = -1;
            for (int r = p + 1; r < np; r++)
              if (it->pt_q[r * nth + i] > 1e-13) {
                nxt = r;
                break;
              }
            if (nxt >= 0) {
              double l1 = L[p * nth + i], l2 = L[nxt * nth + i], t2 = it->pt_t[nxt];
              if (l2 > l1 && l1 >= 0) t = tb - (t2 - tb) * l1 / (l2 - l1);
            }
          }
          ev[ne].t = fmin(fmax(t, ta), tb);
          ev[ne++].i = i;
        }
      }
      prev = last;
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
int fesd__resort_guess(fesd_integrator *it, const double *zsrc, double T, const double *tc, int nc,
                         int *sw_at, double *z) {
  fesd__system *S = &it->sys;
  const int N = S->N;
  int np = it->have_prev_theta + N * (S->s + S->bp);
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
          blk = it->ws_blk;
        else
          blk = source_block(it, zsrc, np, c == 0 ? -INFINITY : t_lo, INFINITY, tm);
      }
      if (blk) {
        memcpy(it->blk, blk, (size_t)S->sb * sizeof(double));
        fesd__fill_element(it, z, n, it->blk);
      }
      z[S->ho[n]] = h;
    }
  }
  return fesd__consistent_guess(it, z);
}

/* Points per bracket and regula falsi steps of fesd__refine_entry. */
#define REFINE_PTS 4
#define REFINE_STEPS 3

/* lambda of the entering mode j (g_j minus the least g of the set P of its subsystem) at time
 * t on the solution's collocation polynomial. */
static int lambda_on_path(fesd_integrator *it, const double *z, double t, const unsigned char *P, int j,
                          double *out) {
  fesd__system *S = &it->sys;
  double *x = it->gbuf + it->nth, *g = it->pscr.g; /* indicators only: no fields, no Jacobians */
  fesd__state_at(it, z, S->N, t, x);
  int st = fesd__model_g(&it->model, S->t0 + t, x, S->u, g);
  if (st) return st;
  const fesd__model *m = &it->model;
  const int k = m->sys_of[j];
  double gmin = INFINITY;
  for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++)
    if (P[i] && g[i] < gmin) gmin = g[i];
  *out = g[j] - gmin;
  return FESD_OK;
}

/* The time at which mode v->mode enters: the first zero of its lambda on the solution's
 * polynomial in the scan's bracket (lo, hi). The scan interpolates lambda linearly between
 * the two points around the sign change; on a long element a nearly tangential arrival is
 * then misplaced by a large part of the element, and the plan solve converges to the wrong
 * root or not at all (stick-slip chain, n = 256, element of 0.071: predicted 0.0705, true
 * 0.0655). Equally spaced points find the first sign change, regula falsi the zero; when the
 * polynomial shows no sign change the scan's time stays. */
int fesd__refine_entry(fesd_integrator *it, const double *z, const fesd__violation *v, const unsigned char *P,
                        double *t) {
  const double lo = v->lo, hi = v->hi;
  if (!(hi > lo)) return FESD_OK;
  double ta = lo, la = 0, tb = hi, lb = 0;
  int st = lambda_on_path(it, z, lo, P, v->mode, &la);
  if (st || !(la > 0)) return st;
  int found = 0;
  for (int p = 1; p <= REFINE_PTS && !found; p++) {
    const double tp = lo + (hi - lo) * p / REFINE_PTS;
    double lp;
    if ((st = lambda_on_path(it, z, tp, P, v->mode, &lp))) return st;
    if (lp < 0) tb = tp, lb = lp, found = 1;
    else ta = tp, la = lp;
  }
  if (!found) return FESD_OK;
  for (int r = 0; r < REFINE_STEPS; r++) {
    const double tm = ta + (tb - ta) * la / (la - lb);
    double lm;
    if ((st = lambda_on_path(it, z, tm, P, v->mode, &lm))) return st;
    if (lm < 0) tb = tm, lb = lm;
    else ta = tm, la = lm;
  }
  *t = ta + (tb - ta) * la / (la - lb);
  return FESD_OK;
}
