/* Local error estimate of an accepted step, element by element. The solution is smooth inside
 * each element (every switch sits on a boundary), so a classical embedded estimate applies:
 * with the same stage derivatives v_j and the field at the element start f_0 (the active
 * modes at x_n; Filippov's multiplier for a 2-mode sliding mode), a second quadrature
 *   x^_{n+1} = x_n + h (b^_0 f_0 + sum_j b^_j v_j)
 * on the nodes {0, c_1..c_{s-1}} (interpolatory: order s; the last stage is left out, since on
 * {0, c_1..c_s} the interpolatory rule is the method's own; Lobatto methods, whose first node
 * is 0 already, use {c_1..c_{s-1}}, order s - 1) differs from x_{n+1} by O(h^q),
 * q = min(p^, p) + 1, p the method's order (s = 3 Radau IIA: q = 4, as the classical Radau5
 * estimate). The estimate is the
 * weighted RMS norm of x^ - x with weights 1 / (atol_r + rtol max(|x_n,r|, |x_n+1,r|)),
 * maximised over the elements (explicit RK: no estimate). */
#include <float.h>
#include <math.h>
#include <string.h>

#include "fesd/step.h"

int fesd__error_setup(fesd_integrator *it) {
  const fesd_tableau *T = &it->tab;
  const int s = T->s;
  double nodes[FESD_RK_MAX_STAGES + 1];
  int m = 0, first = 0;
  it->err_ok = 0;
  if (T->is_explicit) return FESD_OK;
  if (T->c[0] == 0.0) { /* Lobatto: the stages without the last */
    for (int j = 0; j + 1 < s; j++) nodes[m++] = T->c[j];
    first = 1;
  } else {
    nodes[m++] = 0.0;
    for (int j = 0; j + 1 < s; j++) nodes[m++] = T->c[j];
  }
  if (m < 1) return FESD_OK;
  /* interpolatory weights: sum_k w_k nodes_k^q = 1/(q+1), q < m (Vandermonde, Gauss
   * elimination with partial pivoting; m <= 13) */
  double V[FESD_RK_MAX_STAGES + 1][FESD_RK_MAX_STAGES + 2];
  for (int q = 0; q < m; q++) {
    for (int k = 0; k < m; k++) V[q][k] = pow(nodes[k], q);
    V[q][m] = 1.0 / (q + 1);
  }
  for (int c = 0; c < m; c++) {
    int p = c;
    for (int r = c + 1; r < m; r++)
      if (fabs(V[r][c]) > fabs(V[p][c])) p = r;
    for (int k = 0; k <= m; k++) {
      double t = V[c][k];
      V[c][k] = V[p][k];
      V[p][k] = t;
    }
    if (V[c][c] == 0.0) return FESD_OK;
    for (int r = 0; r < m; r++) {
      if (r == c) continue;
      const double f = V[r][c] / V[c][c];
      for (int k = c; k <= m; k++) V[r][k] -= f * V[c][k];
    }
  }
  /* embedded weights in the stage layout: e0 for f_0, e[j] = bhat_j - b_j */
  it->err_e0 = 0;
  for (int j = 0; j < s; j++) it->err_e[j] = -T->b[j];
  for (int k = 0; k < m; k++) {
    const double w = V[k][m] / V[k][k];
    if (first) it->err_e[k] += w;
    else if (k == 0) it->err_e0 = w;
    else it->err_e[k - 1] += w;
  }
  it->err_q = (m < T->order ? m : T->order) + 1; /* interpolatory on m nodes: order m */
  it->err_ok = 1;
  return FESD_OK;
}

/* bp: the family's last stage is not the element end (Gauss-Legendre): a sliding element's
 * estimate from the consistent stage fields (graze.c, fesd__consistent_stages). A constant at
 * each call: the other families' estimate compiles as before it (an ordinary step's cost). */
static inline int estimate(fesd_integrator *it, const double *z, double rtol, const double *atol, double *err,
                           const int bp) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nx = S->nx, s = S->s, nth = S->nth;
  *err = 0;
  if (!it->err_ok) return FESD_OK;
  double tn = S->t0, *f0 = it->ftot, *th0 = it->gbuf; /* nth */
  double *cons = it->ftot + 2 * nx; /* sum_j e_j (consistent field at stage j), when used */
  for (int n = 0; n < S->N; n++) {
    const double h = z[S->ho[n]], *xn = n == 0 ? S->x0 : z + S->xo[n - 1], *x1 = z + S->xo[n];
    int use_cons = 0;
    if (bp) {
      int st = fesd__consistent_stages(it, z, n, tn, h, cons, &use_cons);
      if (st) return st;
    }
    if (it->err_e0 != 0.0) {
      unsigned char *a = it->cand; /* the element's active modes (first stage) */
      fesd__act_from_theta(it, z + fesd__th(S, n, 0), a);
      /* f_0 needs the fields, and the switch Jacobians only for a 2-mode sliding mode
       * (fesd__stage_theta); x_n of a later element is often the last stage point of the one
       * before (c_s = 1), evaluated already */
      int slide = 0;
      for (int k = 0; k < m->nsys && !slide; k++) {
        int cnt = 0;
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i];
        slide = cnt == 2;
      }
      const fesd__point_eval *pr = n > 0 ? fesd__system_record(S, n * s - 1, tn, xn, slide ? 2 : 1) : NULL;
      fesd__point_eval pe = {0};
      if (!pr && n == 0 && !slide && it->f0_ok) { /* the guess evaluated the fields there */
        pe.F = it->f0;
        pr = &pe;
      }
      if (!pr) {
        pe.F = it->pscr.F;
        pe.dgdx = slide ? it->pscr.dgdx : NULL;
        int st = fesd__model_eval(m, tn, xn, S->u, &pe);
        if (st) return st;
        pr = &pe;
      }
      fesd__stage_theta(it, pr, a, th0);
      fesd__total_field(it, pr, th0, f0);
    }
    double sum = 0;
    for (int r = 0; r < nx; r++) {
      double d = it->err_e0 * (it->err_e0 != 0.0 ? f0[r] : 0.0);
      if (use_cons) d += cons[r];
      else
        for (int j = 0; j < s; j++) d += it->err_e[j] * z[fesd__v(S, n, j) + r];
      d *= h;
      const double sc = atol[r] + rtol * fesd__fmax(fabs(xn[r]), fabs(x1[r]));
      const double e = sc > 0 ? d / sc : (d != 0 ? INFINITY : 0.0);
      sum += e * e;
    }
    const double en = sqrt(sum / nx);
    if (!(en <= *err)) *err = en; /* NaN propagates */
    tn += h;
    (void)nth;
  }
  return FESD_OK;
}

int fesd__error_estimate(fesd_integrator *it, const double *z, double rtol, const double *atol, double *err) {
  return it->sys.bp ? estimate(it, z, rtol, atol, err, 1) : estimate(it, z, rtol, atol, err, 0);
}

/* Both Filippov margins (fesd__sliding_margins) of subsystem k sliding on modes i, j in element
 * kb - 1, at its end (p = 0), its start (p = 1), or its end moved by the tolerance of each
 * component (p = 2: all up; p = 3: alternating), from a fresh evaluation unless `fresh` is 0
 * (the point and ftot of the previous call); *speed: the weighted norm of the field there (the
 * state error per unit of time error, in the norm of fesd__error_estimate). */
static int margins_at(fesd_integrator *it, const double *z, const unsigned char *a, int kb, double tb, int p,
                      int fresh, int i, int j, double rtol, const double *atol, double *mi, double *mj,
                      double *speed) {
  fesd__system *S = &it->sys;
  const double *x = p != 1 ? z + S->xo[kb - 1] : kb == 1 ? S->x0 : z + S->xo[kb - 2];
  if (p >= 2) { /* the end point moved by its tolerance, +sc (p = 2) or alternating signs */
    double *xp = it->gbuf + S->nth;
    for (int r = 0; r < S->nx; r++) { /* not a component held exactly (the clock: atol = inf) */
      const double sc = atol[r] + rtol * fabs(x[r]);
      xp[r] = isfinite(sc) ? x[r] + ((p == 3 && r % 2) ? -sc : sc) : x[r];
    }
    x = xp;
  }
  fesd__point_eval pe = fesd__scratch_eval(it);
  if (fresh) {
    int st = fesd__model_eval(&it->model, p == 1 ? tb - z[S->ho[kb - 1]] : tb, x, S->u, &pe);
    if (st) return st;
    fesd__stage_theta(it, &pe, a, it->fil_th);
    fesd__total_field(it, &pe, it->fil_th, it->ftot);
  }
  fesd__sliding_margins(it, &pe, it->fil_th, it->ftot, i, j, mi, mj);
  double sum = 0;
  for (int r = 0; r < S->nx; r++) {
    const double sc = atol[r] + rtol * fabs(x[r]);
    const double e = sc > 0 ? it->ftot[r] / sc : (it->ftot[r] != 0 ? INFINITY : 0.0);
    sum += e * e;
  }
  *speed = sqrt(sum / S->nx);
  return FESD_OK;
}

/* A pinned exit is placed by the family's multiplier of the leaving mode (its last stage, or
 * for Gauss-Legendre its extrapolation to the element end, order about s), not by the state;
 * a step that ends sliding passes Filippov's check with the staying mode's margin down to
 * -1e-4 (FIL_STAGE_TOL), and the exit then falls on the next step's start. Either way the exit
 * is tangential, the state error it causes is quadratic in its time error, and the embedded
 * estimate does not see it. Measured (a forced stick-slip oscillator, Gauss-Legendre s = 2, 3
 * under error control; stuck phases are linear in t, so the steps grow long): exits off by up
 * to 2.3e-2 at rtol 1e-6, x(30) 89 tolerances off. The staying mode's margin is zero at the
 * exit: its values at the exit point (or the step end, where it is negative) and at the sliding
 * element's start give the time to its zero by a linear fit, and that time times the field is
 * the state error an exit that far off is worth. One evaluation per step that ends sliding, two
 * more per exit. Every implicit family: the stiffly accurate ones pin an exit by their last
 * stage's multiplier, off by its order (Radau IIA s = 2 at rtol 1e-11 on a curved surface:
 * 1.7e-8 at first, 7.6e-10 accepted before). Shorter steps before an exit leave the leaving
 * mode's theta below active_tol at a step end, which no longer drops the mode (accept.c,
 * end_set). One sliding subsystem at a time. */
/* What the state's own tolerance makes of the staying mode's margin m0 at the end of element
 * kb - 1: its largest change when the end point moves by the tolerance of each component (two
 * directions). A margin within it is as exact as the state. */
static int margin_noise(fesd_integrator *it, const double *z, const unsigned char *a, int kb, double tb, int i, int j,
                        int stay_i, double m0, double rtol, const double *atol, double *noise) {
  *noise = 0;
  for (int p = 2; p <= 3; p++) {
    double mi, mj, v;
    int st = margins_at(it, z, a, kb, tb, p, 1, i, j, rtol, atol, &mi, &mj, &v);
    if (st) return st;
    *noise = fesd__fmax(*noise, fabs((stay_i ? mi : mj) - m0));
  }
  return FESD_OK;
}

int fesd__exit_error(fesd_integrator *it, const double *z, double rtol, const double *atol, double *err) {
  fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  double tb = S->t0;
  *err = 0;
  for (int kb = 1; kb <= S->N; kb++) {
    tb += z[S->ho[kb - 1]];
    const int end = kb == S->N;
    const unsigned char *a = it->act + (size_t)((kb - 1) * S->s + S->s - 1) * S->nth;
    /* the leaving mode of an exit at boundary kb: pinned (bmode 2), or an unpinned one of the
     * fallback path (a mode of a 2-mode set not active after the boundary; Gauss-Legendre off
     * the plan path: an exit 0.048 late, x(30) 6e6 tolerances off at rtol 1e-10, found by a
     * review) */
    int leave = -1;
    if (!end && it->bmode[kb] == 2) leave = it->exit_mode[kb];
    else if (!end && !it->exit_pinned)
      for (int k = 0; k < m->nsys && leave < 0; k++) {
        int j, i = fesd__two_modes(m, a, k, &j);
        if (i >= 0 && !a[S->nth + i]) leave = i;
        else if (i >= 0 && !a[S->nth + j]) leave = j;
      }
    if (!end && leave < 0) continue;
    /* the fallback path can leave a sliding mode between the stages of the last element (its
     * exit is logged at the step end): the margins of the set it slid on */
    if (end && !it->exit_pinned && fesd__count_two_modes(m, a) == 0)
      a = it->act + (size_t)((kb - 1) * S->s) * S->nth;
    /* with two or more sliding subsystems their multipliers are coupled (a co-dimension-2
     * sliding mode): one subsystem's 2-mode margin with the others' held is not its own
     * (measured: the check on such margins took 66136 steps instead of 984, prop_integrate) */
    if (fesd__count_two_modes(m, a) != 1) continue;
    int fresh = 1;
    for (int k = 0; k < m->nsys; k++) {
      int j, i = fesd__two_modes(m, a, k, &j);
      if (i < 0 || (!end && m->sys_of[leave] != k)) continue;
      double mi, mj, m0, m1, speed, v;
      int st = margins_at(it, z, a, kb, tb, 0, fresh, i, j, rtol, atol, &mi, &mj, &speed);
      if (st) return st;
      fresh = 0;
      /* the staying mode: the one left at a pinned exit; at the step end the one whose margin
       * went negative (none: the mode still slides) */
      const int stay_i = end ? mi < mj : leave != i;
      m0 = stay_i ? mi : mj;
      if (end && !(m0 < 0)) continue;
      if ((st = margins_at(it, z, a, kb, tb, 1, 1, i, j, rtol, atol, &mi, &mj, &v))) return st;
      m1 = stay_i ? mi : mj;
      fresh = 1; /* the end point's evaluation was replaced */
      /* the margin falls to its zero at the exit: a linear fit through both points */
      const double h = z[S->ho[kb - 1]], rate = (m0 - m1) / h;
      if (!(rate < 0) || !isfinite(m0)) continue;
      /* an exit within what the state's tolerance makes of the margin is as exact as the
       * state. Measured in an experiment that kept sliding modes with theta below active_tol
       * across step ends: Gauss s = 2 at rtol 1e-9 retried an exit 6e-10 off at the end of a
       * sliding element of 2.9e-7, which shorter steps did not change, until
       * FESD_ERR_STEP_TOO_SMALL. */
      double noise;
      if ((st = margin_noise(it, z, a, kb, tb, i, j, stay_i, m0, rtol, atol, &noise))) return st;
      const double dt = fesd__fmax(fabs(m0) - noise, 0.0) / -rate;
      /* A pinned exit off by more than its sliding element is long: a shorter step does not
       * move it (Gauss-Legendre's multipliers are not damped, |R(inf)| = 1, and carry an error
       * from earlier elements: an exit 5.9e-8 early after an element of 5.9e-8 at rtol 1e-10,
       * rejected down to FESD_ERR_STEP_TOO_SMALL); a step end past the exit is still measured */
      if (!end && dt >= h) continue;
      const double e = fesd__fmin(dt, h) * speed;
      /* ... nor does it when a retry from the same start put the exit where it was, within its
       * error (an exit 4.7e-9 after a start on the surface: the element before it is the same
       * whatever the step, Radau IIA s = 5 at rtol 1e-9 rejected it to FESD_ERR_STEP_TOO_SMALL;
       * found by a review). Stiffly accurate families: Gauss-Legendre's retries land on the
       * same exit while shorter steps still move it (forced stick-slip, s = 2, 3 at rtol 1e-6:
       * exits 1e-4 off accepted so) */
      if (!end && e > 1 && S->tab.stiffly_accurate) {
        if (S->t0 == it->exr_t0 && fabs(tb - it->exr_tb) <= dt) continue;
        it->exr_t0 = S->t0, it->exr_tb = tb;
      }
      if (!(e <= *err)) *err = e;
    }
  }
  return FESD_OK;
}

int fesd__still_slides(fesd_integrator *it, const double *z, int i, int j, int leave, int *slides) {
  fesd__system *S = &it->sys;
  const unsigned char *a = it->act + (size_t)(S->N * S->s - 1) * S->nth;
  *slides = 0;
  if (fesd__count_two_modes(&it->model, a) != 1) return FESD_OK; /* as fesd__exit_error */
  const double tb = S->t0 + S->T, rtol = it->tol.rtol, *atol = it->tol_atol;
  const int stay_i = leave != i;
  double mi, mj, v, noise = 0;
  int st = margins_at(it, z, a, S->N, tb, 0, 1, i, j, rtol, atol, &mi, &mj, &v);
  if (st) return st;
  const double m0 = stay_i ? mi : mj;
  if (m0 > 0 && (st = margin_noise(it, z, a, S->N, tb, i, j, stay_i, m0, rtol, atol, &noise))) return st;
  *slides = m0 > noise;
  return FESD_OK;
}

/* An element longer than GROWTH_MAX times the time in which the field expands along the
 * element's own increment: an L-stable method damps such a growing mode, and so does its
 * embedded estimate, which then misses the error (measured: Lobatto IIIC s = 3, h = 5.3 through
 * an unstable focus with eigenvalues 1 +- 2i, accepted with a local error of 0.50 while the
 * estimate was 3.4e-3 of coarse_tol). The rate is the Rayleigh quotient
 * q = <dx, f(x_{n+1}) - f(x_n)> / |dx|^2 of dx = x_{n+1} - x_n, free for the stiffly accurate
 * families (v of the last stage is f at the element end; the element before gives f(x_n)) in
 * elements whose active set is the one before them: decaying and rotating modes give q <= 0 */
#define GROWTH_MAX 2.0
static int outgrown(const fesd_integrator *it, double big) {
  /* increments at round-off (a mass stuck at rest moves by 1e-30) show no growth */
  const double dd_min = (64 * DBL_EPSILON * big) * (64 * DBL_EPSILON * big);
  const fesd__system *S = &it->sys;
  if (!S->tab.stiffly_accurate || !S->tab.c_end_is_one) return 0;
  const int s = S->s, nth = S->nth, nx = S->nx;
  const double *z = it->z;
  for (int n = 1; n < S->N; n++) {
    const double *xa = z + S->xo[n - 1], *xb = z + S->xo[n], *fa = z + fesd__v(S, n - 1, s - 1), *fb = z + fesd__v(S, n, s - 1);
    double dd = 0, dg = 0;
    for (int r = 0; r < nx; r++) {
      const double d = xb[r] - xa[r];
      dd += d * d;
      dg += d * (fb[r] - fa[r]);
    }
    if (!(dd > dd_min) || !(z[S->ho[n]] * dg > GROWTH_MAX * dd)) continue;
    /* rare: the quotient means growth only where both element ends have one active set */
    const unsigned char *a0 = it->act + (size_t)(n * s - 1) * nth, *a1 = a0 + (size_t)s * nth;
    if (!memcmp(a0, a1, (size_t)nth)) return 1;
  }
  return 0;
}

/* Flag a step whose local error estimate exceeds coarse_tol, relative to the size of each
 * component (its largest value so far, on this step or before; at least 1e-6 of the largest
 * component), or one with an element that outgrew its field (above): a too coarse step shows
 * without a reference solution. */
int fesd__coarse_check(fesd_integrator *it, fesd_step_info *info) {
  const fesd__system *S = &it->sys;
  double big = 0, *sz = it->err_atol;
  for (int r = 0; r < it->nx; r++) {
    sz[r] = fesd__fmax(S->refX[r], fabs(it->x[r]));
    for (int n = 0; n < S->N; n++) sz[r] = fesd__fmax(sz[r], fabs(it->z[S->xo[n] + r]));
    big = fesd__fmax(big, fesd__fmax(sz[r], S->motX[r]));
  }
  /* a component at rest (all its values 0: a stuck mass) is measured against the motion its
   * fields could make in the step (motX, weights.c) or 1e-6 of the largest size or motion of
   * any component; against its own round-off (1e-30) every stuck step was flagged coarse */
  for (int r = 0; r < it->nx; r++)
    sz[r] = it->set.coarse_tol * fesd__fmax(fesd__fmax(sz[r], 1e-6 * big), 1e-3 * S->motX[r]) + 1e-300;
  double err;
  int st = fesd__error_estimate(it, it->z, 0.0, sz, &err);
  if (st) return st;
  info->error_estimate = fesd__fmax(info->error_estimate, err * it->set.coarse_tol);
  if (!(err <= 1.0) || outgrown(it, big)) it->step_flags |= FESD_FLAG_COARSE;
  return FESD_OK;
}
