/* The switch plan of a step: which subsystem switches to which active set at which
 * (predicted) time. Every switch gets an element boundary of its own, with the binding row of
 * Theorem 3 (cross complementarity; a pinned exit for a mode leaving a sliding mode) and
 * equal element lengths elsewhere, so one smooth solve resolves all the switches of a step:
 * of one subsystem or of many, at different times. Switches of different subsystems at the
 * same instant share one boundary, whose cross-complementarity row then vanishes only when
 * all of them hold (its derivative in the boundary time is the sum of theirs).
 *
 * A solve whose solution still violates a sign changes the plan (plan_update): a violation
 * right after a switch of its subsystem means that switch chose the wrong modes (a crossing
 * that should slide, a sliding mode that Filippov's conditions reject, a second mode joining
 * at a corner), any other adds a switch at its predicted time and drops the later switches
 * of that subsystem (they were predicted with the wrong modes). */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

/* Active sets tried after one switch before the plan gives up on it. */
#define MAX_TRIES 4
/* Modes within this distance of the least indicator (units of the indicator scale) at a predicted
 * switch count as tied there (a corner reached at the predicted time, to its accuracy). */
#define CORNER_TIE 1e-6
/* A switch predicted this close to the step start (fraction of T) happens at the start. */
#define AT_START 1e-9
/* ... and one predicted this close (not farther than the prediction error of an entry just
 * after the start, 14 % measured) may be moved there when its element cannot be that short
 * (fesd__plan_start_fallback). */
#define START_REACH 1e-8

void fesd__plan_reset(fesd_integrator *it) {
  it->n_plan = 0;
  it->plan_peak = 0;
  it->merge_tol = 1e-9;
  it->split_layout = 0;
  memset(it->plan_sig, 0, sizeof it->plan_sig);
}

static unsigned char *after(fesd_integrator *it, int e) { return fesd__plan_after(it, e); }

static void swap_switch(fesd_integrator *it, int a, int b) {
  fesd__switch t = it->plan[a];
  it->plan[a] = it->plan[b];
  it->plan[b] = t;
  unsigned char *pa = after(it, a), *pb = after(it, b), *tmp = it->swap_set;
  memcpy(tmp, pa, (size_t)it->nth);
  memcpy(pa, pb, (size_t)it->nth);
  memcpy(pb, tmp, (size_t)it->nth);
}

void fesd__plan_remove(fesd_integrator *it, int e) {
  for (int q = e; q + 1 < it->n_plan; q++) swap_switch(it, q, q + 1);
  it->n_plan--;
}

/* Drop the switches of subsystem k after time t. */
static void drop_after(fesd_integrator *it, int k, double t) {
  for (int e = it->n_plan - 1; e >= 0; e--)
    if (it->plan[e].sys == k && it->plan[e].t > t) fesd__plan_remove(it, e);
}

void fesd__plan_truncate(fesd_integrator *it, double t) {
  for (int e = it->n_plan - 1; e >= 0; e--)
    if (it->plan[e].t >= t) fesd__plan_remove(it, e);
}

void fesd__plan_sort(fesd_integrator *it) {
  for (int a = 1; a < it->n_plan; a++)
    for (int b = a; b > 0 && it->plan[b].t < it->plan[b - 1].t; b--) swap_switch(it, b, b - 1);
}

void fesd__plan_times(fesd_integrator *it, const double *z) {
  const fesd__system *S = &it->sys;
  for (int e = 0; e < it->n_plan; e++) {
    double t = 0;
    for (int n = 0; n < it->plan[e].kb; n++) t += z[S->ho[n]];
    it->plan[e].t = t;
  }
}

/* The active set of subsystem k just before time t: the start set or the set after its
 * latest switch before t; *e_out: that switch (-1: the start). */
static const unsigned char *set_before(fesd_integrator *it, int k, double t, int *e_out) {
  int best = -1;
  for (int e = 0; e < it->n_plan; e++)
    if (it->plan[e].sys == k && it->plan[e].t <= t && (best < 0 || it->plan[e].t >= it->plan[best].t)) best = e;
  *e_out = best;
  return best < 0 ? it->act0 : after(it, best);
}

/* The active set of subsystem plan[e].sys just before switch e (the start set or the set
 * after its previous switch). */
static const unsigned char *set_before_switch(fesd_integrator *it, int e) {
  const int k = it->plan[e].sys;
  int best = -1;
  for (int q = 0; q < it->n_plan; q++)
    if (q != e && it->plan[q].sys == k && it->plan[q].t < it->plan[e].t &&
        (best < 0 || it->plan[q].t >= it->plan[best].t))
      best = q;
  return best < 0 ? it->act0 : after(it, best);
}

/* Fields, indicators and their state gradients at time t of the current solution z (its
 * collocation polynomial), in the scratch buffers (valid until the next scratch use). */
static int eval_on_path(fesd_integrator *it, const double *z, double t, fesd__point_eval *pe) {
  fesd__system *S = &it->sys;
  double *x = it->gbuf + it->nth;
  fesd__state_at(it, z, S->N, t, x);
  *pe = fesd__scratch_eval(it);
  return fesd__model_eval(&it->model, S->t0 + t, x, S->u, pe);
}

/* A mode j entering next to a sliding mode P of a subsystem with more modes (a corner of one
 * subsystem: an AND of two thresholds in a gene network) can end the sliding mode at once: the
 * state leaves through the corner into a region of its own. The mode of P and j that alone
 * keeps itself the strict minimum of g (d/dt (g_c - g_l) > 0 along the field with l alone, for
 * every other candidate c), when exactly one does; else -1 (a sliding mode with j). Measured:
 * x2 sliding on 0.7 under [x1 > 0.35][x2 < 0.7] while x1 falls through 0.35: the plan grew the
 * sliding mode to 3 modes, cycled and failed (FESD_ERR_STEP_FAILED in 27 of 48 runs, every
 * family; a 5-gene network could not be integrated past its first sliding exit). */
static int consistent_alone(fesd_integrator *it, const fesd__point_eval *pe, const double *th, int k,
                            const unsigned char *P, int j) {
  const fesd__model *m = &it->model;
  const int nx = m->nx;
  double *f = it->ftot + nx; /* ftot: the total field at the point (the caller's) */
  unsigned char *cand = it->swap_set;
  double gmin = INFINITY;
  for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++) gmin = fmin(gmin, pe->g[l]);
  /* candidates: P, j, and the modes tied with them at the point (the far side of the corner) */
  for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++)
    cand[l] = P[l] || l == j || (pe->g[l] - gmin) * it->sys.wth[l] <= CORNER_TIE;
  /* the total field without subsystem k, then with each candidate alone */
  double *rest = f + nx;
  memcpy(rest, it->ftot, (size_t)nx * sizeof(double));
  for (int q = m->th_off[k]; q < m->th_off[k + 1]; q++)
    if (th[q] != 0.0) fesd__F_axpy(m, pe, q, -th[q], rest);
  int pick = -1, n_ok = 0;
  for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++) {
    if (!cand[l]) continue;
    memcpy(f, rest, (size_t)nx * sizeof(double));
    fesd__F_axpy(m, pe, l, 1.0, f);
    if (fesd__keeps_alone(m, pe, k, cand, l, f)) pick = l, n_ok++;
  }
  return n_ok == 1 ? pick : -1;
}

/* Entering mode j next to the set P of subsystem k at time t of the solution z: a crossing
 * (j alone) when j's field points into j's region, else a sliding mode (P and j); next to a
 * sliding mode, the one candidate that is consistent alone (above) when there is one. */
static int enter_set(fesd_integrator *it, const double *z, double t, int k, const unsigned char *P, int j,
                     unsigned char *out) {
  const fesd__model *m = &it->model;
  int n_act = 0, i_old = -1;
  for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++)
    if (P[i]) n_act++, i_old = i;
  int cross = 0, alone = -1;
  {
    fesd__system *S = &it->sys;
    fesd__point_eval pe;
    int st = eval_on_path(it, z, t, &pe);
    if (st) return st;
    /* thetas of the other subsystems: the stage nearest before t */
    double tn = 0;
    int n = 0;
    while (n + 1 < S->N && t >= tn + z[S->ho[n]]) tn += z[S->ho[n++]];
    const double *th = z + fesd__th(S, n, 0);
    fesd__total_field(it, &pe, th, it->ftot);
    if (n_act == 1) {
      double ai, aj;
      fesd__normal_components(it, &pe, th, it->ftot, i_old, j, &ai, &aj);
      cross = aj > 0;
    } else {
      alone = consistent_alone(it, &pe, th, k, P, j);
    }
  }
  for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++)
    out[i] = alone >= 0 ? i == alone : cross ? i == j : (P[i] || i == j);
  return FESD_OK;
}

static int empty_set(const fesd_integrator *it, const unsigned char *a, int k) {
  for (int i = it->model.th_off[k]; i < it->model.th_off[k + 1]; i++)
    if (a[i]) return 0;
  return 1;
}

/* Exits are pinned with exit rows by the implicit methods (stiffly accurate: the last stage's
 * pair; Gauss-Legendre: theta extrapolated to the element end); otherwise the FB path. */
static int can_pin_exit(const fesd_integrator *it) { return it->set.exit_rows && !it->tab.is_explicit; }

/* A switch at the step start: the start set of k changes (the saltation of the sensitivities
 * is applied explicitly, accept.c). */
static void start_jump(fesd_integrator *it, int k, const unsigned char *newset) {
  const fesd__model *m = &it->model;
  if (!it->start_jumped) { /* the start's classification, for the first step's events (accept.c) */
    memcpy(it->act_first, it->act0, (size_t)it->nth);
    it->start_jumped = 1;
  }
  int in = -1, out = -1;
  for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
    if (newset[i] && !it->act0[i] && in < 0) in = i;
    if (!newset[i] && it->act0[i] && out < 0) out = i;
  }
  if (in >= 0 && out >= 0) {
    it->jump_in[k] = in;
    it->jump_out[k] = out;
  }
  memcpy(it->act0 + m->th_off[k], newset + m->th_off[k], (size_t)(m->th_off[k + 1] - m->th_off[k]));
  /* The start now counts as on the surface: lambda00 of the start set's modes is zero (it
   * enters the first boundary's cross-complementarity row through element 0). Left at
   * g(x0) - min g, a start 2.6e-10 off the sliding surface (ocp_step_eq, Lobatto IIIC s = 2)
   * carried 5e-10 into that row, which the solve balanced by lambda = -5.2e-9 (relative) of the
   * other subsystem's entering mode at that boundary: a sign violation every round, a plan
   * cycle and a finer layout (5 elements instead of 2). Restored with the state when the
   * attempt fails (fesd__load). */
  for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
    if (!newset[i]) continue;
    it->lam00[i] = 0.0;
    if (it->set.sensitivities)
      for (int c = 0; c < it->np; c++) it->sys.lam00_dp[(size_t)c * it->nth + i] = 0.0;
  }
}

/* A plan solve that failed with its first element at the floor of its length (1e-9 T, the
 * bound of every element) while the first boundary carries entries: those switches lie closer
 * to the start than an element can be short, and their predictions only just missed the
 * step-start rule (AT_START). Measured (ocp_step_eq, Lobatto IIIC s = 2, a start 4.3e-10 off
 * the sliding surface): an entry predicted at 6.76e-10 > 6.67e-10 = AT_START T, true 5.9e-10;
 * three plan solves stalled at residual 3.5e-10 with h_0 at the bound and the step ended in
 * two sub-steps (5 elements). They move to the start; the other switches' brackets came from
 * the trajectory before that change and are released. Returns 1 when the plan changed. */
int fesd__plan_start_fallback(fesd_integrator *it, const double *z) {
  const fesd__system *S = &it->sys;
  const double T = S->T;
  if (S->N < 2 || !(z[S->ho[0]] <= 1.000001e-9 * T)) return 0;
  int moved = 0;
  for (int e = it->n_plan - 1; e >= 0; e--) {
    /* only switches predicted near the start: a wrong plan can drive h_0 to the floor too
     * (bang-bang oscillator, hard_silent: crossings predicted mid-step moved to the start gave
     * FESD_OK with errors of 0.63) */
    if (it->plan[e].kb != 1 || it->plan[e].exit || !(it->plan[e].t <= START_REACH * T)) continue;
    start_jump(it, it->plan[e].sys, after(it, e));
    fesd__plan_remove(it, e);
    moved = 1;
  }
  for (int e = 0; e < it->n_plan && moved; e++) it->plan[e].lo = 0.0, it->plan[e].hi = T;
  return moved;
}

/* Whether the switch of subsystem j can make theta of subsystem k jump at time t: some
 * field difference of j's modes has a component along grad (g_i - g_l) of k (i the leaving
 * mode, l another active one), relative to the sizes (1e-8). Otherwise k's sliding
 * multiplier is continuous there and its exit is a pinned one. */
static int coupled(fesd_integrator *it, const double *z, double t, int k, int i, int j, int *out) {
  fesd__model *m = &it->model;
  *out = 0;
  fesd__point_eval pe;
  int st = eval_on_path(it, z, t, &pe);
  if (st) return st;
  int l = -1; /* another mode of k active just before t */
  const unsigned char *P = it->act0;
  for (int e = 0; e < it->n_plan; e++)
    if (it->plan[e].sys == k && it->plan[e].t <= t) P = after(it, e);
  for (int q = m->th_off[k]; q < m->th_off[k + 1]; q++)
    if (q != i && P[q]) l = q;
  if (l < 0) return FESD_OK;
  double *gd = it->gdense; /* zero outside this call */
  fesd__dg_axpy(m, &pe, i, 1.0, gd);
  fesd__dg_axpy(m, &pe, l, -1.0, gd);
  const int *rows = m->rows[j], nr = m->nr[j], a = m->th_off[j], b = m->th_off[j + 1];
  double gmax = 0, fmx = 0, dmax = 0;
  for (int c = 0; c < m->ncol[k]; c++) gmax = fmax(gmax, fabs(gd[m->cols[k][c]]));
  for (int p = a; p < b; p++)
    for (int r = 0; r < nr; r++) fmx = fmax(fmx, fabs(pe.F[m->Foff[p] + r]));
  for (int p = a + 1; p < b; p++) {
    double d = 0;
    for (int r = 0; r < nr; r++) d += gd[rows[r]] * (pe.F[m->Foff[p] + r] - pe.F[m->Foff[a] + r]);
    dmax = fmax(dmax, fabs(d));
  }
  for (int c = 0; c < m->ncol[k]; c++) gd[m->cols[k][c]] = 0.0;
  *out = dmax > 1e-8 * gmax * fmx;
  return FESD_OK;
}

/* A switch that a correction left without a change is removed: its boundary row holds for any
 * boundary time, so the solve could settle anywhere in a family of solutions (fuzzing, Gauss
 * s = 1: another subsystem's crossing moved by 1e-4, or dx(T)/dx0 off by 11, with FESD_OK) or
 * let an element step over the region. */
static void remove_if_unchanged(fesd_integrator *it, int e) {
  const fesd__model *m = &it->model;
  const int a = m->th_off[it->plan[e].sys], b = m->th_off[it->plan[e].sys + 1];
  if (!memcmp(after(it, e) + a, set_before_switch(it, e) + a, (size_t)(b - a))) fesd__plan_remove(it, e);
}

/* Whether subsystem k's sliding mode satisfies Filippov's conditions at switch e of the
 * current layout (the step start when e < 0), with the sets of all subsystems there. */
static int stands_at(fesd_integrator *it, const double *z, int e, int k, int *stands) {
  const unsigned char *A = e < 0 ? it->act : it->act + (size_t)it->plan[e].kb * it->sys.s * it->nth;
  return fesd__sliding_stands(it, z, e < 0 ? 0.0 : it->plan[e].t, A, k, stands);
}

/* Returns 1 when the plan changed, 2 when the start's set changed (a switch at the step start),
 * 0 when it gives up, < 0 on errors. */
static int update_one(fesd_integrator *it, const double *z, const fesd__violation *v, double T) {
  const fesd__model *m = &it->model;
  const int k = v->sys, a = m->th_off[k], b = m->th_off[k + 1];
  unsigned char *ns = it->cand; /* new set of subsystem k (slice a..b used) */
  int e;
  const unsigned char *P = set_before(it, k, v->t, &e);
  fesd__violation later;
  if (v->filippov > 0 && can_pin_exit(it)) {
    /* Filippov's conditions fail at a point after the step start (or after the sliding entry
     * before it) where they held: the sliding mode ends in between, an exit of the mode that
     * does not continue, not a crossing from the start (or from that entry). Measured: a stuck
     * phase of a forced stick-slip oscillator under error control whose slip began between a
     * stage and a midpoint: the start jumped to slipping, whose own start then violated the
     * stick condition, and the plan cycled. */
    const double t_a = e < 0 ? 0.0 : it->plan[e].t;
    int stands = 0;
    if (v->t > t_a + AT_START * T && (e < 0 || !it->plan[e].exit)) {
      int st = stands_at(it, z, e, k, &stands);
      if (st) return st;
    }
    if (stands) {
      int j, i = fesd__two_modes(&it->model, P, k, &j);
      later = *v;
      later.filippov = 0;
      later.enter = 0;
      later.first = 0;
      later.mode = i == v->mode ? j : i;
      later.lo = t_a;
      later.hi = v->t;
      later.t = 0.5 * (t_a + v->t);
      v = &later;
    }
  }
  if (v->filippov) {
    /* not a sliding mode: the mode whose field points into its own region continues */
    if (v->filippov < 0) it->nonunique = 1;
    memset(ns + a, 0, (size_t)(b - a));
    ns[v->mode] = 1;
    if (e < 0) {
      start_jump(it, k, ns);
      drop_after(it, k, -1.0);
      return 2;
    }
    if (++it->plan[e].tries > MAX_TRIES || !memcmp(after(it, e) + a, ns + a, (size_t)(b - a))) return 0;
    memcpy(after(it, e) + a, ns + a, (size_t)(b - a));
    it->plan[e].fresh = 1;
    drop_after(it, k, it->plan[e].t);
    remove_if_unchanged(it, e);
    return 1;
  }
  if (v->first && e >= 0 && !v->enter && it->sys.s == 1 && it->tab.c_end_is_one && !it->plan[e].exit) {
    /* With one stage per element the first point checked after a sliding entry is the end of
     * the element that follows it, possibly far from the entry: when Filippov's conditions hold
     * at the entry itself, the entry stands and the mode leaves later (measured: ocp_step_eq's
     * dynamics, implicit Euler, a start 1e-4 above c1 = 0 sliding until 0.198 of a step of
     * 0.67: the exit was taken for a wrong entry, the plan cycled, and the finer layout it fell
     * back to gave another solution than a start on the surface: the step map jumped) */
    int stands;
    int st = stands_at(it, z, e, k, &stands);
    if (st) return st;
    if (stands) {
      later = *v;
      later.first = 0;
      later.lo = fmax(v->lo, it->plan[e].t);
      if (!(later.t > later.lo && later.t < later.hi)) later.t = 0.5 * (later.lo + later.hi);
      v = &later;
    }
  }
  if (v->first && e >= 0) {
    /* the switch before chose the wrong modes: add the mode that wants in, drop the one
     * that wants out; a mode that this switch brought in alone (a crossing) and that wants
     * out again makes it a sliding mode with the modes before */
    fesd__switch *w = &it->plan[e];
    unsigned char *A = after(it, e);
    if (++w->tries > MAX_TRIES || A[v->mode] == (unsigned char)v->enter) return 0;
    const unsigned char *B = set_before_switch(it, e);
    int crossing = 1;
    for (int i = a; i < b; i++) crossing &= !(A[i] && B[i]);
    if (!v->enter && A[v->mode] && !B[v->mode] && crossing) {
      for (int i = a; i < b; i++) A[i] = (unsigned char)(A[i] || B[i]);
    } else {
      A[v->mode] = (unsigned char)v->enter;
    }
    w->fresh = 1;
    if (empty_set(it, A, k)) return 0;
    drop_after(it, k, w->t);
    remove_if_unchanged(it, e);
    return 1;
  }
  /* a new switch at the predicted time */
  drop_after(it, k, v->t);
  P = set_before(it, k, v->t, &e);
  double t_v = v->t;
  if (v->enter) {
    int st = fesd__refine_entry(it, z, v, P, &t_v);
    if (!st) st = enter_set(it, z, t_v, k, P, v->mode, ns);
    if (st) return st;
  } else {
    if (!can_pin_exit(it)) return 0;
    memcpy(ns + a, P + a, (size_t)(b - a));
    ns[v->mode] = 0;
    if (empty_set(it, ns, k)) return 0;
  }
  if (t_v <= AT_START * T && e < 0) {
    start_jump(it, k, ns);
    return 2;
  }
  /* An exit whose sign change brackets a switch of another subsystem: at a corner the other
   * subsystem's switch makes theta jump (design of a sliding mode that cannot continue past
   * the second surface), so the mode leaves at that switch, not pinned where theta would
   * reach zero continuously. (If it should stay, its lambda turns negative right after and
   * the "first" rule puts it back.) */
  double t_new = t_v;
  int jump = 0;
  if (!v->enter)
    for (int q = 0; q < it->n_plan && !jump; q++) {
      const fesd__switch *o = &it->plan[q];
      if (o->sys == k || o->exit || !(o->t >= v->lo && o->t < v->hi)) continue;
      int st = coupled(it, z, o->t, k, v->mode, o->sys, &jump);
      if (st) return st;
      if (jump) t_new = o->t;
    }
  if (it->n_plan >= it->cap_plan) return FESD_ERR_TOO_MANY_SWITCHES;
  fesd__switch *w = &it->plan[it->n_plan];
  w->t = t_new;
  w->sys = k;
  w->mode = v->mode;
  w->exit = !v->enter && !jump;
  w->kb = -1;
  w->tries = 0;
  w->fresh = 1;
  w->lo = jump ? 0.0 : v->lo; /* a jump moves with the switch it joins */
  w->hi = jump ? T : v->hi;
  memcpy(after(it, it->n_plan) + a, ns + a, (size_t)(b - a));
  it->n_plan++;
  /* An excursion into a region whose field pushes back (the entry slides): the sliding mode
   * ends about where the trajectory turned back (the staying mode's field is tangent there
   * again), so its exit is planned with the entry. Alone, the entry's plan slid to the step
   * end, which has no solution, and the step fell back to the FB path, which stepped over it
   * (a touch x1 = d - (t - 1)^2 / 2 with d = 1e-5, Radau IIA s = 3, h = 0.375: x1(1.5) off by
   * d, FESD_OK). */
  int jo;
  if (v->enter && v->back > t_new && v->back < T && can_pin_exit(it) && fesd__two_modes(m, ns, k, &jo) >= 0) {
    if (it->n_plan >= it->cap_plan) return FESD_ERR_TOO_MANY_SWITCHES;
    fesd__switch *x = &it->plan[it->n_plan];
    *x = *w;
    x->t = v->back, x->mode = v->mode, x->exit = 1, x->lo = t_new, x->hi = T;
    memcpy(after(it, it->n_plan) + a, P + a, (size_t)(b - a));
    it->n_plan++;
  }
  return 1;
}

int fesd__plan_update(fesd_integrator *it, const double *z, const fesd__violation *per_sys) {
  const double T = it->sys.T;
  int changed = 0;
  for (int e = 0; e < it->n_plan; e++) it->plan[e].fresh = 0;
  /* A violation that corrects an earlier switch (first) means the trajectory after that switch
   * was wrong: the other subsystems' violations after it are left for the next round (a
   * sliding mode of another subsystem that "fails" after a wrong crossing at a corner). */
  double t_first = INFINITY;
  for (int k = 0; k < it->nsys; k++)
    if (per_sys[k].found && per_sys[k].first) t_first = fmin(t_first, per_sys[k].t);
  double t_new = INFINITY;
  for (int k = 0; k < it->nsys; k++) {
    if (!per_sys[k].found) continue;
    if (!per_sys[k].first && per_sys[k].t > t_first + 1e-9 * T) continue;
    int r = update_one(it, z, &per_sys[k], T);
    if (r < 0) return r;
    if (r == 0) return 0;
    if (r == 2) t_new = 0.0; /* a switch moved to the step start changes the whole trajectory */
    changed = 1;
  }
  /* The brackets of the new switches come from the predicting trajectory; after the earliest
   * new switch (or a change of the start's set) that trajectory changes (coupled subsystems: a
   * mass that sticks moves its neighbours' exits; ocp_step_eq, Radau IIA s = 2, a start
   * 2.6e-10 off the sliding surface c2 = 0: the other subsystem's entry at 0.4436 was
   * bracketed in [0.4444, 0.6667] by the trajectory that crossed c2, the plan solve stalled at
   * residual 1.3e-3 and the step was halved), so the later ones may move anywhere after it. */
  for (int e = 0; e < it->n_plan; e++)
    if (it->plan[e].fresh) t_new = fmin(t_new, it->plan[e].t);
  for (int e = 0; e < it->n_plan; e++) {
    fesd__switch *w = &it->plan[e];
    if (w->fresh && w->t > t_new + 1e-9 * T) w->lo = fmin(w->lo, t_new), w->hi = T;
  }
  return changed;
}
