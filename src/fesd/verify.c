/* Checks of a converged step solution against what it claims. With the active sets fixed
 * the step system is smooth, so a converged solution still has to show that:
 *  - the signs hold at every point the equations see: theta >= 0 on active modes, lambda >= 0
 *    on inactive ones (stage points, boundary LP points);
 *  - between the stage points the collocation polynomial stays in the regions of its active
 *    modes (cross complementarity only sees the stage points: a short excursion, or the many
 *    switches of a Zeno accumulation, pass through an element unseen);
 *  - a 2-mode sliding mode is one in Filippov's sense: the fields of both modes point towards
 *    the surface. The discrete sliding equations also have spurious solutions: a long element
 *    whose stage points all lie on the surface (or at a point where both normal components
 *    vanish) while the polynomial between them crosses it (measured: a bang-bang oscillator
 *    with two crossings in one step collapsed to the origin as a "sliding mode").
 * A violation locates the next switch: lambda of an inactive mode is a smooth difference of
 * indicators along the computed trajectory, theta of an active mode a smooth sliding
 * multiplier, so their linear zero crossing predicts the switch time.
 * Tolerances are relative: lambda in units of its subsystem's indicator scale (system.h). */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

/* Filippov check: normal components of the same sign whose smaller one exceeds this fraction
 * of the larger one at a stage point (a field clearly pointing away from the surface)... */
#define FIL_STAGE_TOL 1e-4

int fesd__collocation(const fesd_integrator *it) {
  const int f = it->tab.family;
  return f == FESD_RK_RADAU_IIA || f == FESD_RK_GAUSS_LEGENDRE || f == FESD_RK_LOBATTO_IIIA;
}

void fesd__state_at(fesd_integrator *it, const double *z, int N, double t, double *x) {
  const fesd__system *S = &it->sys;
  const int nx = S->nx, s = S->s;
  double tn = 0;
  int n = 0;
  while (n + 1 < N && t >= tn + z[S->ho[n]]) tn += z[S->ho[n++]];
  const double h = z[S->ho[n]];
  double tau = h > 0 ? (t - tn) / h : 0.0;
  tau = tau < 0 ? 0 : tau > 1 ? 1 : tau;
  if (fesd__collocation(it)) {
    double w[FESD_RK_MAX_STAGES];
    fesd__colloc_weights(it, tau, w);
    fesd__poly_state(it, z, n, w, x);
    return;
  }
  /* piecewise linear through (0, x_n), (c_j, X_j) for c_j > 0, (1, x_{n+1}). A stage at c_j = 0
   * is not the element start: Lobatto IIIC's X_1 = x_n + h (v_1 - v_2) / 2 lies O(h^2) off it.
   * Through X_1 the path began 1e-2 off x_0 in lambda (ocp_step_eq, s = 2, h = 1/3), and the
   * refinement of an entry 1.8e-10 after the step start returned 2.0e-2 (predict.c), beyond
   * the reach of the step-start rule (plan.c, AT_START), which the plan then could not solve
   * (the element length's lower bound 1e-9 T is above the true 1.9e-10). */
  const double *xn = n == 0 ? S->x0 : z + S->xo[n - 1], *x1 = z + S->xo[n];
  double ca = 0, cb = 1;
  int ja = -1, jb = -1;
  for (int j = 0; j < s; j++) {
    double c = S->tab.c[j];
    if (c == 0.0) continue;
    if (c <= tau && c >= ca) ca = c, ja = j;
    if (c > tau && c < cb) cb = c, jb = j;
  }
  double *xa = it->vtmp, *xb = it->vtmp + nx;
  for (int r = 0; r < nx; r++) {
    double ka = 0, kb = 0;
    for (int l = 0; l < s; l++) {
      if (ja >= 0) ka += S->tab.A[ja][l] * z[fesd__v(S, n, l) + r];
      if (jb >= 0) kb += S->tab.A[jb][l] * z[fesd__v(S, n, l) + r];
    }
    xa[r] = ja >= 0 ? xn[r] + h * ka : xn[r];
    xb[r] = jb >= 0 ? xn[r] + h * kb : x1[r];
  }
  const double f = cb > ca ? (tau - ca) / (cb - ca) : 0.0;
  for (int r = 0; r < nx; r++) x[r] = xa[r] + f * (xb[r] - xa[r]);
}


/* Whether subsystem k's active set changes at the boundary starting element n (act per stage). */
static int set_changes(const fesd_integrator *it, const unsigned char *act, int n, int k) {
  if (n == 0) return 0;
  const int nth = it->nth, s = it->s, a = it->model.th_off[k], b = it->model.th_off[k + 1];
  const unsigned char *p = act + (size_t)(n * s - 1) * nth, *q = act + (size_t)(n * s) * nth;
  return memcmp(p + a, q + a, (size_t)(b - a)) != 0;
}

/* Sign violations at the points the equations see (step start, stage points, boundary LP
 * points), earliest per mode, folded into per subsystem. A violation is attributed to the
 * active-set change just before it (first) when the violating mode's own activity changed
 * there and no point was checked in between (the change chose wrong: a crossing that should
 * slide), or when its predicted time falls on that boundary (a second mode that joins at a
 * corner). */
static void scan_signs(fesd_integrator *it, const double *z, const unsigned char *act, int strict,
                       fesd__violation *ps) {
  fesd__system *S = &it->sys;
  const int nth = S->nth, s = S->s;
  const double tol = it->set.cc_tol, t_eps = 1e-9 * S->T;
  for (int i = 0; i < nth; i++) {
    const int k = it->model.sys_of[i];
    double t0 = 0, v0 = NAN, t_change = -INFINITY; /* last point value of the monitored quantity */
    int aprev = act[i];
    v0 = act[i] ? (it->have_prev_theta ? it->theta_prev[i] : 1.0) : it->lam00[i] * S->wth[i];
    double tn = 0;
    int done = 0, kept = 0;
    for (int n = 0; n < S->N && !done; n++) {
      const double h = z[S->ho[n]];
      if (set_changes(it, act, n, k)) {
        t_change = tn;
        /* the mode stays active across the change (its subsystem entered a sliding mode) */
        kept = act[(size_t)(n * s - 1) * nth + i] && act[(size_t)(n * s) * nth + i];
      }
      for (int j = 0; j <= s; j++) {
        double t, val;
        const int a = act[(size_t)(n * s + (j < s ? j : s - 1)) * nth + i];
        if (a != aprev) v0 = NAN; /* the active set changes here: no interpolation across */
        aprev = a;
        if (j < s) {
          /* Stage states at c_j = 0 (Lobatto, explicit RK) lie O(h^2) off the element start,
           * and explicit stages are low-order predictions that can overshoot a surface the
           * trajectory does not reach: for FESD their indicator signs are not switches
           * (explicit methods are checked at the element ends). The Filippov weights of an
           * implicit c_j = 0 stage are still part of the field the step integrates (b_j > 0):
           * a negative one there (a sliding element whose first stage pulls the state onto
           * the surface from off it) is checked like any other. */
          const int c0 = S->tab.c[j] == 0.0;
          if (!strict && (S->tab.is_explicit ? c0 || !a : c0 && !a)) continue;
          t = tn + S->tab.c[j] * h;
          val = a ? z[fesd__th(S, n, j) + i] : z[fesd__la(S, n, j) + i] * S->wth[i];
        } else {
          if (!S->bp) continue;
          /* element end of a boundary-point method: lambda (boundary LP) of inactive modes,
           * theta extrapolated from the stages of active ones (an exit after the last stage) */
          t = tn + h;
          if (a) {
            if (S->tab.is_explicit) continue;
            val = 0;
            for (int l = 0; l < s; l++) val += S->ext[l] * z[fesd__th(S, n, l) + i];
          } else {
            /* a mode that enters at this boundary: its boundary lambda is the switching
             * value (zero up to the cross-complementarity tolerance; the LP values of a
             * boundary-point method are not sign-constrained) */
            if (n + 1 < S->N && act[(size_t)((n + 1) * s) * nth + i]) continue;
            val = z[S->lbo[n] + i] * S->wth[i];
          }
        }
        if (val < -tol) {
          fesd__violation c = {0};
          c.found = 1;
          c.t = isnan(v0) ? tn : (v0 > 0 ? t0 + (t - t0) * v0 / (v0 - val) : t0);
          c.lo = isnan(v0) ? tn : t0;
          c.hi = t;
          c.mode = i;
          c.sys = k;
          c.enter = !a;
          c.element = n;
          c.stage = n * s + (j < s ? j : s); /* j == s: the element-end LP point */
          /* a mode kept through a sliding entry whose theta is negative at the first point
           * after it: the entry should have been a crossing (a corner) */
          c.first = isnan(v0) || c.t <= t_change + t_eps || (kept && a && t0 <= t_change + t_eps);
          c.filippov = 0;
          fesd__note_violation(&ps[k], &c);
          done = 1;
          break;
        }
        t0 = t;
        v0 = val;
      }
      tn += h;
    }
  }
}

void fesd__total_field(fesd_integrator *it, const fesd__point_eval *pe, const double *th, double *f) {
  memset(f, 0, (size_t)it->nx * sizeof(double));
  for (int i = 0; i < it->nth; i++)
    if (th[i] != 0.0) fesd__F_axpy(&it->model, pe, i, th[i], f);
}

/* O(size of subsystem k's fields and switching functions), not O(n_x): with many subsystems
 * (a friction chain) a dense copy of the field per subsystem made the checks quadratic. */
void fesd__normal_components(fesd_integrator *it, const fesd__point_eval *pe, const double *theta,
                             const double *ftot, int i, int j, double *ai, double *aj) {
  const fesd__model *m = &it->model;
  const int k = m->sys_of[i], *cols = m->cols[k], nc = m->ncol[k], *rows = m->rows[k], nr = m->nr[k];
  double *gd = it->gdense; /* dense grad (g_i - g_j), zero outside this call */
  fesd__dg_axpy(m, pe, i, 1.0, gd);
  fesd__dg_axpy(m, pe, j, -1.0, gd);
  double base = 0;
  for (int c = 0; c < nc; c++) base += gd[cols[c]] * ftot[cols[c]];
  double di = 0, dj = 0;
  for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++) {
    if (theta[l] == 0.0 && l != i && l != j) continue;
    const double *f = pe->F + m->Foff[l];
    double d = 0;
    for (int r = 0; r < nr; r++) d += gd[rows[r]] * f[r];
    base -= theta[l] * d;
    if (l == i) di = d;
    if (l == j) dj = d;
  }
  *ai = base + di;
  *aj = base + dj;
  for (int c = 0; c < nc; c++) gd[cols[c]] = 0.0;
}

/* Filippov's conditions of the 2-mode sliding of subsystem k with modes i, j at an evaluated
 * point: with psi = g_i - g_j (< 0 in region i) sliding needs d psi/dt >= 0 along mode i and
 * <= 0 along mode j. Returns the mode whose field clearly points into its own region (the one
 * that continues), -1 for both (repulsive), -2 for none. */
int fesd__filippov(fesd_integrator *it, const fesd__point_eval *pe, const double *th, const double *ftot,
                    int i, int j, double rel) {
  double ai, aj;
  fesd__normal_components(it, pe, th, ftot, i, j, &ai, &aj);
  const double tol = rel * (fabs(ai) + fabs(aj));
  const int bad_i = ai < -tol, bad_j = aj > tol;
  if (bad_i && bad_j) return -1;
  return bad_i ? i : bad_j ? j : -2;
}

/* With several subsystems sliding at one point (a co-dimension-2 sliding mode of a Cartesian
 * product), subsystem k's own test holds the others' multipliers fixed, but they change with
 * k's mode: the sliding mode stands if neither of k's modes, alone and with the other sliding
 * subsystems' multipliers solved again, is a consistent continuation (its field keeps it in
 * its region and the others still slide). Returns 1 if some alternative is consistent. */
int fesd__alternative_exists(fesd_integrator *it, const fesd__point_eval *pe, const unsigned char *a, int k, int i,
                              int j) {
  const fesd__model *m = &it->model;
  const int nth = m->nth, nx = m->nx;
  int coupled = 0;
  for (int l = 0; l < m->nsys && !coupled; l++) {
    int jl;
    coupled = l != k && fesd__two_modes(&it->model, a, l, &jl) >= 0;
  }
  if (!coupled) return 1; /* a single sliding subsystem: its own test decides */
  double *keep = it->ftot + 2 * nx, *f2 = it->ftot + nx, *th2 = it->fil_th;
  unsigned char *a2 = it->fil_a;
  memcpy(keep, it->ftot, (size_t)nx * sizeof(double)); /* fesd__stage_theta uses ftot */
  int found = 0;
  for (int alt = 0; alt < 2 && !found; alt++) {
    const int p = alt ? j : i, q = alt ? i : j;
    memcpy(a2, a, (size_t)nth);
    a2[q] = 0;
    fesd__stage_theta(it, pe, a2, th2);
    fesd__total_field(it, pe, th2, f2);
    double dp, dq; /* normal components of mode p alone and of the other mode, at th2 */
    fesd__normal_components(it, pe, th2, f2, p, q, &dp, &dq);
    /* p stays in its region (psi = g_p - g_q < 0) when psi does not increase along the field
     * of p (dp, in the units of fesd__normal_components / filippov) */
    int ok = dp <= FIL_STAGE_TOL * (fabs(dp) + fabs(dq));
    for (int l = 0; l < m->nsys && ok; l++) {
      int jl, il = fesd__two_modes(&it->model, a2, l, &jl);
      if (il >= 0) ok = fesd__filippov(it, pe, th2, f2, il, jl, FIL_STAGE_TOL) == -2;
    }
    found = ok;
  }
  memcpy(it->ftot, keep, (size_t)nx * sizeof(double));
  return found;
}

void fesd__sliding_margins(fesd_integrator *it, const fesd__point_eval *pe, const double *th, const double *ftot,
                           int i, int j, double *mi, double *mj) {
  double ai, aj;
  fesd__normal_components(it, pe, th, ftot, i, j, &ai, &aj);
  const double d = fabs(ai) + fabs(aj);
  *mi = d > 0 ? ai / d : NAN;
  *mj = d > 0 ? -aj / d : NAN;
}

/* Between the stage points of a sliding element: the normalised normal components a_i / d and
 * -a_j / d (d = |a_i| + |a_j|; both >= 0 while Filippov's conditions hold) are smooth in time and
 * known at the stage points, which lie on the surface (the stage equations hold them there);
 * their interpolating polynomial at the midpoints between consecutive stages below
 * -FIL_INTERP_TOL is a violation there. The midpoint states themselves lie off the surface by the
 * polynomial's error, which a stiff normal term (K = 3e6) amplified past any tolerance tied to
 * rtol (found by the review), so the components are interpolated rather than evaluated there.
 * Measured: a forced stick-slip oscillator under error control, Radau IIA s = 3, rtol 2.7e-6,
 * whose stick condition failed for a short slip at t = 49.27 between stages: missed, x(100)
 * 4.4e3 tolerances off. One subsystem sliding at a time (a co-dimension-2 sliding mode couples
 * the multipliers: the stage test's alternative check decides those). */
#define FIL_INTERP_TOL 2e-3
static void interp_margins(fesd_integrator *it, const unsigned char *a, int n, double tn, double h,
                           fesd__violation *ps) {
  const fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  const int s = S->s;
  if (fesd__count_two_modes(m, a) != 1 || s < 2) return;
  for (int k = 0; k < m->nsys; k++) {
    int j, i = fesd__two_modes(m, a, k, &j);
    if (i < 0) continue;
    const double *mi = it->fil_mi + k * s, *mj = it->fil_mj + k * s;
    /* nodes: the element start where the element before slid on the same modes and ended in a
     * stage (c_s = 1: on the surface too), then the stages. With two stages (Radau IIA s = 2)
     * the stages alone give a line: a stuck phase of a forced stick-slip oscillator whose stick
     * condition failed between them (a slip of 0.66 inside an element of 0.93, rtol 1e-8) was
     * stepped over, x(30) 1.3e3 tolerances off, FESD_OK (found by a review) */
    double nc[FESD_RK_MAX_STAGES + 1], ni[FESD_RK_MAX_STAGES + 1], nj[FESD_RK_MAX_STAGES + 1];
    int nn = 0;
    if (isfinite(it->fil_pm[2 * k]) && isfinite(it->fil_pm[2 * k + 1]) && S->tab.c[0] > 0)
      nc[nn] = 0, ni[nn] = it->fil_pm[2 * k], nj[nn++] = it->fil_pm[2 * k + 1];
    for (int q = 0; q < s; q++)
      if (isfinite(mi[q]) && isfinite(mj[q])) nc[nn] = S->tab.c[q], ni[nn] = mi[q], nj[nn++] = mj[q];
    for (int p = 0; p + 1 < nn; p++) {
      const double tau = 0.5 * (nc[p] + nc[p + 1]);
      double vi = 0, vj = 0;
      for (int l = 0; l < nn; l++) {
        double L = 1;
        for (int r = 0; r < nn; r++)
          if (r != l) L *= (tau - nc[r]) / (nc[l] - nc[r]);
        vi += L * ni[l], vj += L * nj[l];
      }
      const int bi = vi < -FIL_INTERP_TOL, bj = vj < -FIL_INTERP_TOL;
      if (!bi && !bj) continue;
      fesd__violation v = {1, tn + tau * h, bi ? i : j, k, 0, n, n * s + s, 0, bi && bj ? -1 : 1, 0, 0, 0};
      fesd__note_violation(&ps[k], &v);
      break;
    }
  }
}

/* Filippov's conditions at the stage points of the elements where a subsystem slides on
 * two modes. */
static int scan_filippov(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nth = S->nth, s = S->s;
  fesd__point_eval pe = fesd__scratch_eval(it);
  double tn = 0;
  int slid = 0; /* the element before slid (its margins are in fil_mi, fil_mj) */
  for (int n = 0; n < S->N; n++) {
    const double h = z[S->ho[n]];
    const unsigned char *a = act + (size_t)(n * s) * nth;
    if (!fesd__any_two_modes(m, a)) {
      slid = 0;
    } else {
      /* the last stage's margins of the element before, if it slid and no subsystem switched at
       * the boundary between (another's switch makes the multipliers jump there) */
      const int same = slid && S->tab.c[s - 1] == 1.0 && !memcmp(a - (size_t)nth, a, (size_t)nth);
      for (int k = 0; k < m->nsys; k++) {
        it->fil_pm[2 * k] = same ? it->fil_mi[k * s + s - 1] : NAN;
        it->fil_pm[2 * k + 1] = same ? it->fil_mj[k * s + s - 1] : NAN;
      }
      /* the step start, the last step's last stage (c_s = 1) with the same sets: its multipliers
       * (a stuck phase of 5.5 in one step, Radau IIA s = 3, whose stick condition failed between
       * the stages of its first element: a slip of 0.66 missed, x(30) 1.3e3 tolerances off) */
      if (n == 0 && it->have_prev_theta && S->tab.c[s - 1] == 1.0 && S->tab.c[0] > 0 &&
          !memcmp(it->act0, a, (size_t)nth)) {
        int st = fesd__model_eval(m, S->t0, S->x0, S->u, &pe);
        if (st) return st;
        fesd__total_field(it, &pe, it->theta_prev, it->ftot);
        for (int k = 0; k < m->nsys; k++) {
          int j, i = fesd__two_modes(m, a, k, &j);
          if (i >= 0)
            fesd__sliding_margins(it, &pe, it->theta_prev, it->ftot, i, j, it->fil_pm + 2 * k, it->fil_pm + 2 * k + 1);
        }
      }
      slid = 1;
      for (int q = 0; q < m->nsys * s; q++) it->fil_mi[q] = it->fil_mj[q] = NAN;
      for (int q = 0; q < s; q++) {
        if (S->tab.c[q] == 0.0 && n > 0) continue; /* the element start: checked before */
        double *X = it->gbuf + nth;
        fesd__stage_state(S, z, n, q, X);
        int st = fesd__model_eval(m, S->t0 + tn + S->tab.c[q] * h, X, S->u, &pe);
        if (st) return st;
        const double *th = z + fesd__th(S, n, q);
        fesd__total_field(it, &pe, th, it->ftot);
        for (int k = 0; k < m->nsys; k++) {
          int j, i = fesd__two_modes(&it->model, a, k, &j);
          if (i < 0) continue;
          /* the element end where k's set changes is the switch point itself (a sliding exit:
           * the remaining field is tangent there) */
          if (S->tab.c[q] == 1.0 && n + 1 < S->N && set_changes(it, act, n + 1, k)) continue;
          fesd__sliding_margins(it, &pe, th, it->ftot, i, j, it->fil_mi + k * s + q, it->fil_mj + k * s + q);
          int c = fesd__filippov(it, &pe, th, it->ftot, i, j, FIL_STAGE_TOL);
          if (c == -2 || !fesd__alternative_exists(it, &pe, a, k, i, j)) continue;
          fesd__violation v = {1, tn + S->tab.c[q] * h, c < 0 ? i : c, k, 0, n, n * s + q, 0, 1, 0, 0, 0};
          v.filippov = c < 0 ? -1 : 1;
          fesd__note_violation(&ps[k], &v);
        }
      }
      interp_margins(it, a, n, tn, h, ps);
    }
    tn += h;
  }
  return FESD_OK;
}

int fesd__scan(fesd_integrator *it, const double *z, const unsigned char *act, int strict,
               fesd__violation *v, fesd__violation *per_sys) {
  const int K = it->nsys;
  fesd__violation *ps = per_sys ? per_sys : it->scan_buf;
  memset(ps, 0, (size_t)K * sizeof(*ps));
  scan_signs(it, z, act, strict, ps);
  int st = FESD_OK;
  if (!strict && it->set.method == FESD_METHOD_FESD) {
    st = scan_filippov(it, z, act, ps);
    if (!st && !it->sys.tab.is_explicit) st = fesd__scan_switch_points(it, z, act, ps);
    if (!st && !it->sys.tab.is_explicit) st = fesd__scan_start(it, z, act, ps);
    if (!st && it->n_mid > 0) st = fesd__scan_interior(it, z, act, ps);
    if (!st && it->sys.s == 1 && it->sys.tab.c_end_is_one) st = fesd__scan_hermite(it, z, act, ps);
  }
  memset(v, 0, sizeof(*v));
  for (int k = 0; k < K; k++)
    if (ps[k].found) fesd__note_violation(v, &ps[k]);
  return st;
}

/* Max over elements, modes and stage pairs m != m' of theta_{n,m,i} lambda_{n,m',i}
 * (boundary lambdas included, weighted like the rows): the sparse cross complementarity
 * (eq. cross_cc_true). */
double fesd__cc_max(const fesd__system *S, const double *z) {
  const int s = S->s, sb = S->sb, nx = S->nx, nth = S->nth;
  double worst = 0;
  for (int n = 0; n < S->N; n++) {
    const double *L = fesd__left_lambda(S, z, n);
    const double *R = S->bp ? fesd__right_lambda(S, z, n) : NULL;
    const double *th = z + S->el[n] + nx, *la = th + nth; /* stage m: + m sb */
    for (int i = 0; i < nth; i++) {
      /* the largest stage lambda and the largest but the one at stage m1 (the max over the
       * stages m' != m of every m without a loop over them) */
      double l1 = -INFINITY, l2 = -INFINITY;
      int m1 = -1;
      for (int m = 0; m < s; m++) {
        const double l = la[m * sb + i];
        if (l > l1) l2 = l1, l1 = l, m1 = m;
        else if (l > l2) l2 = l;
      }
      const double base = fesd__fmax(L[i], R ? R[i] : 0.0);
      for (int m = 0; m < s; m++) {
        const double t = th[m * sb + i];
        if (t <= 0) continue;
        const double lmax = fesd__fmax(base, m == m1 ? l2 : l1);
        worst = fesd__fmax(worst, t * lmax * S->wth[i]);
      }
    }
  }
  return worst;
}

int fesd__verify(fesd_integrator *it, const double *z, double *ccm) {
  fesd__system *S = &it->sys;
  for (int n = 0; n < S->N; n++)
    if (!(z[S->ho[n]] > 0)) return FESD_ERR_STEP_FAILED;
  *ccm = fesd__cc_max(S, z);
  /* boundary LP points (methods with c_s != 1): lambda >= 0 there too, otherwise the
   * active set changed between the last stage and the element end */
  if (S->bp)
    for (int n = 0; n < S->N; n++)
      for (int i = 0; i < S->nth; i++) {
        const double l = -z[S->lbo[n] + i] * S->wth[i];
        *ccm = l > *ccm ? l : *ccm;
      }
  if (!(*ccm <= it->set.cc_tol)) return FESD_ERR_STEP_FAILED;
  /* the active sets the solution claims, stage by stage */
  for (int p = 0; p < S->N * S->s; p++)
    fesd__act_from_theta(it, z + fesd__th(S, p / S->s, p % S->s), it->act + (size_t)p * S->nth);
  fesd__violation v;
  int st = fesd__scan(it, z, it->act, 0, &v, NULL);
  if (st) return st;
  return v.found ? FESD_ERR_STEP_FAILED : FESD_OK;
}
