/* Acceptance of a converged step: sensitivities by the implicit function theorem,
 * element records, event classification and the state update. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fesd/step.h"

/* lambda00 = g(x) - min g e per subsystem, and (when sensitivities are on) its derivative
 * w.r.t. (x, u) using the argmin (ties: the mode with the largest theta_prev). */
int fesd__update_lambda00(fesd_integrator *it, const double *x, const double *u, int deriv,
                          const fesd__point_eval *rec) {
  fesd__model *m = &it->model;
  const int nx = m->nx, nu = m->nu, nth = m->nth;
  fesd__point_eval pe = {0};
  pe.g = it->gbuf;
  double *dg = it->sys.lam00_dp; /* nth x (nx+nu) column-major */
  const double *dgdu = it->pscr.dgdu;
  double *t = it->vtmp;
  if (rec) { /* an evaluation at (it->t, x) made in this step */
    memcpy(it->gbuf, rec->g, (size_t)nth * sizeof(double));
    pe.dgdx = rec->dgdx;
    dgdu = rec->dgdu;
  } else {
    if (deriv) {
      pe.dgdx = it->pscr.dgdx;
      pe.dgdu = nu > 0 ? it->pscr.dgdu : NULL;
    }
    int st = fesd__model_eval(m, it->t, x, u, &pe);
    if (st) return st;
  }
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
      it->lam00[i] = fesd__fmax(it->gbuf[i] - gmin, 0.0);
      if (deriv) {
        memset(t, 0, (size_t)nx * sizeof(double));
        fesd__dg_axpy(m, &pe, i, 1.0, t);
        fesd__dg_axpy(m, &pe, imin, -1.0, t);
        for (int c = 0; c < nx; c++) dg[c * nth + i] = t[c];
        for (int c = 0; c < nu; c++)
          dg[(nx + c) * nth + i] = dgdu[c * nth + i] - dgdu[c * nth + imin];
      }
    }
  }
  return FESD_OK;
}

/* Saltation at a crossing or sliding entry of subsystem k that falls exactly on the step start
 * (the previous step ended on the surface): S <- (I + (f+ - f-) grad psi' / (grad psi' f-)) S,
 * psi = g_in - g_out, f- = F theta_prev, f+ = F theta of the first stage (paper Prop. 4);
 * for u also the direct dependence of psi on u. */
static int start_jump(fesd_integrator *it, const double *z, int k) {
  fesd__model *m = &it->model;
  const int nx = m->nx, nu = m->nu, nth = m->nth, a = it->jump_in[k], b = it->jump_out[k];
  fesd__point_eval pe = fesd__scratch_eval(it);
  pe.dgdu = nu > 0 ? it->pscr.dgdu : NULL;
  int st = fesd__model_eval(m, it->t, it->x, it->sys.u, &pe);
  if (st) return st;
  const double *th1 = z + fesd__th(&it->sys, 0, 0);
  double *df = it->vtmp, *fm = it->vtmp + nx; /* f+ - f-, f- */
  memset(df, 0, 2 * (size_t)nx * sizeof(double));
  for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) fesd__F_axpy(m, &pe, i, th1[i] - it->theta_prev[i], df);
  for (int i = 0; i < nth; i++) fesd__F_axpy(m, &pe, i, it->theta_prev[i], fm);
  double den = fesd__dg_dot(m, &pe, a, fm) - fesd__dg_dot(m, &pe, b, fm);
  if (fabs(den) < 1e-300) return FESD_OK; /* grazing: no transversal saltation */
  /* S <- S + df (grad psi' S) / den, column by column */
  for (int c = 0; c < nx + nu; c++) {
    double *col = c < nx ? it->Sx + (size_t)c * nx : it->Su + (size_t)(c - nx) * nx;
    double gs = fesd__dg_dot(m, &pe, a, col) - fesd__dg_dot(m, &pe, b, col);
    if (c >= nx) gs += pe.dgdu[(c - nx) * nth + a] - pe.dgdu[(c - nx) * nth + b];
    for (int r = 0; r < nx; r++) col[r] += df[r] * gs / den;
  }
  return FESD_OK;
}

/* Relative residual of the implicit-function solve above which its result is not trusted
 * (round-off gives ~1e-16; the refinement of src/ncp leaves ~1e-15 on sound systems). */
#define SENS_RESIDUAL_MAX 1e-8
/* Forward-error estimate (one refinement step's correction, relative) above which the
 * sensitivities are flagged: a well-conditioned step gives 1e-15 .. 1e-12. */
#define SENS_FERR_MAX 1e-7

/* A complementarity pair with theta and lambda both at zero at a stage point where no
 * boundary row binds it: the active set is ambiguous there (a switch exactly at a stage
 * point), the step map has one-sided derivatives only, and the implicit-function theorem on
 * one active set gives one of them. The last stage before a switch boundary (its pair is the
 * switch, bound by the cross-complementarity row or the pinned exit), a stage at the element
 * start after one (c = 0), and the step end (the next step applies the saltation) are not
 * degenerate. */
static int degenerate_pair(fesd_integrator *it, const double *z) {
  const fesd__system *S = &it->sys;
  const int s = S->s, nth = S->nth;
  for (int n = 0; n < S->N; n++)
    for (int j = 0; j < s; j++) {
      if (n == S->N - 1 && j == s - 1) continue;
      if (j == s - 1 && it->bmode[n + 1] != 0) continue;
      if (S->tab.c[j] == 0.0 && n > 0 && it->bmode[n] != 0) continue;
      if (S->tab.c[j] == 0.0 && n == 0) continue; /* the step start: given */
      const double *th = z + fesd__th(S, n, j), *la = z + fesd__la(S, n, j);
      for (int i = 0; i < nth; i++)
        if (fabs(th[i]) <= it->set.active_tol && fabs(la[i]) * S->wth[i] <= it->set.cc_tol) return 1;
    }
  return 0;
}

/* After a switch at the step start, lambda00 of subsystem k lives on the new side: its
 * derivative is taken against the mode that became active (g_i - g_in), not against the mode
 * the previous step ended in (at the tie both give lambda00 = 0, but only the new one is the
 * derivative of the step map: the old one couples the other subsystems' switch times to
 * this one's state). */
static int jump_lambda00(fesd_integrator *it, int k) {
  fesd__model *m = &it->model;
  const int nx = m->nx, nu = m->nu, nth = m->nth, in = it->jump_in[k];
  fesd__point_eval pe = {0};
  pe.g = it->pscr.g;
  pe.dgdx = it->pscr.dgdx;
  pe.dgdu = nu > 0 ? it->pscr.dgdu : NULL;
  int st = fesd__model_eval(m, it->sys.t0, it->sys.x0, it->sys.u, &pe);
  if (st) return st;
  double *dg = it->sys.lam00_dp, *t = it->vtmp;
  for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
    memset(t, 0, (size_t)nx * sizeof(double));
    fesd__dg_axpy(m, &pe, i, 1.0, t);
    fesd__dg_axpy(m, &pe, in, -1.0, t);
    for (int c = 0; c < nx; c++) dg[c * nth + i] = t[c];
    for (int c = 0; c < nu; c++) dg[(nx + c) * nth + i] = pe.dgdu[c * nth + i] - pe.dgdu[c * nth + in];
  }
  return FESD_OK;
}

/* dx_end/d(x_start, u) of the accepted step by the implicit function theorem on the rows of
 * the last solve (the binding rows of the accepted solution), chained into Sx, Su. */
static int chain_sensitivities(fesd_integrator *it, const double *z) {
  for (int k = 0; k < it->nsys; k++)
    if (it->jump_in[k] >= 0) {
      int sj = start_jump(it, z, k);
      if (sj) return sj;
      if ((sj = jump_lambda00(it, k))) return sj;
    }
  /* A sliding entry moved to the step start (a mode joins, none leaves: no saltation applied
   * here). The stiffly accurate families' step equations project the sensitivities onto the
   * surface by themselves; Gauss-Legendre's do not (b^T A^-1 1 = 1 - R(inf)): a user's entry
   * 1e-10 before a step end gave dx/dx0 = I and dx/du = 0 where the map's differences and the
   * flow give [1 0.5; 0 0] and (-0.5, 1); inside the step (1e-9 T on) it is exact. */
  if (it->start_jumped && !it->tab.stiffly_accurate)
    for (int k = 0; k < it->nsys; k++) {
      int in = 0, out = 0;
      for (int l = it->model.th_off[k]; l < it->model.th_off[k + 1]; l++)
        in |= it->act0[l] && !it->act_first[l], out |= it->act_first[l] && !it->act0[l];
      if (in && !out) it->step_flags |= FESD_FLAG_SENS_INACCURATE;
    }
  fesd__system *S = &it->sys;
  fesd__level *L = &it->lv[it->lv_cur];
  const int nx = it->nx, nu = it->nu, np = nx + nu;
  /* the stage points with their u-derivatives; want_u stays on through the solver's evaluation
   * at z, which then finds them and only assembles its rows */
  S->want_u = 1;
  int st = S->status = fesd__system_points(S, z, 1);
  if (!st) {
    fesd__system_param_jac(S, z, L->draw);
    st = fesd_ncp_sensitivity(it->ncp, z, 0.0, np, L->draw, L->dz);
  }
  S->want_u = 0;
  if (st == FESD_ERR_CALLBACK && S->status) st = S->status; /* the model's own status */
  if (st) return st;
  double rel = 0, ferr = 0;
  fesd_ncp_sensitivity_residual(it->ncp, &rel);
  fesd_ncp_sensitivity_error(it->ncp, &ferr);
  if (!(rel <= SENS_RESIDUAL_MAX) || !(ferr <= SENS_FERR_MAX) || degenerate_pair(it, z))
    it->step_flags |= FESD_FLAG_SENS_INACCURATE;
  /* D = rows of x_N in dz: nx x np */
  const int xN = S->xo[S->N - 1];
  double *D = it->Dtmp;
  for (int c = 0; c < np; c++)
    for (int r = 0; r < nx; r++) D[c * nx + r] = L->dz[(size_t)c * S->n + xN + r];
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

/* Active modes of subsystem k (indices within the subsystem, ascending) into out; returns
 * their number. From flags (an active set): */
static int flagged_modes(const fesd_integrator *it, const unsigned char *a, int k, int *out) {
  const fesd__model *m = &it->model;
  int c = 0;
  for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++)
    if (a[i]) out[c++] = i - m->th_off[k];
  return c;
}

/* ... and element n of z under error control, for a plan path solution: also a mode of a
 * 2-mode sliding set of the solve whose theta is below active_tol but above the solves'
 * round-off (see end_set). */
static int element_modes_kept(const fesd_integrator *it, const double *z, int n, int k, int *out) {
  const fesd__model *m = &it->model;
  const int s = it->s, sb = it->sys.sb, a = m->th_off[k], b = m->th_off[k + 1], nth = m->nth;
  const double tol = it->set.active_tol, lo = fesd__theta_floor(it), *th = z + fesd__th(&it->sys, n, 0);
  const unsigned char *A = it->act + (size_t)n * s * nth;
  int j2, c = 0;
  const int two = fesd__two_modes(m, A, k, &j2) >= 0;
  for (int i = a; i < b; i++)
    for (int j = 0; j < s; j++)
      if (th[j * sb + i] > (two && A[j * nth + i] ? lo : tol)) {
        out[c++] = i - a;
        break;
      }
  return c;
}

/* ... and element n of z (active at any stage). */
static int element_modes(const fesd_integrator *it, const double *z, int n, int k, int *out) {
  const fesd__model *m = &it->model;
  const int s = it->s, sb = it->sys.sb, a = m->th_off[k], b = m->th_off[k + 1];
  const double tol = it->set.active_tol, *th = z + fesd__th(&it->sys, n, 0); /* stage j: + j sb */
  int c = 0;
  for (int i = a; i < b; i++)
    for (int j = 0; j < s; j++)
      if (th[j * sb + i] > tol) {
        out[c++] = i - a;
        break;
      }
  return c;
}

/* The modes of element n (c of them in out) and the one whose exit is pinned at its end: its
 * theta falls to zero there, and in a short element it can lie below active_tol at every stage:
 * implicit Euler (zero at its only stage) showed the sliding phase one element short or not at
 * all; Gauss-Legendre s = 2 under error control (the exit-time check of error.c shortens the
 * steps before an exit) logged an exit 3.6e-6 early, at the start of the element before it. */
static int pinned_exit(const fesd_integrator *it, int n, int k, int *out, int c) {
  const int a = it->model.th_off[k], x = it->exit_mode[n + 1] - a;
  if (it->bmode[n + 1] != 2 || x < 0 || x >= it->model.th_off[k + 1] - a) return c;
  int p = 0; /* into the ascending list, once */
  while (p < c && out[p] < x) p++;
  if (p < c && out[p] == x) return c;
  memmove(out + p + 1, out + p, (size_t)(c - p) * sizeof(int));
  out[p] = x;
  return c + 1;
}

/* The active set at the end of the step, the next one's start set (act_prev): theta above
 * active_tol, and under error control a mode of a 2-mode sliding set of the solve whose theta
 * fell below active_tol (not to round-off) while the other mode's Filippov margin still holds
 * (fesd__still_slides). Near an exit theta falls to zero, and the exit-time check shortens the
 * steps before it: a step ending within active_tol / |theta'| of the exit had dropped the mode,
 * logging the exit there (Radau IIA s = 2, rtol 1e-11, a curved surface: 4e-7 early). An exit
 * at the step end itself leaves the margin within its noise: dropped, logged at the step end. */
static int end_set(fesd_integrator *it, const double *z, unsigned char *a) {
  const fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  const double *th = z + fesd__th(S, S->N - 1, S->s - 1);
  fesd__act_from_theta(it, th, a);
  if (!it->ec_on || !it->plan_sets) return FESD_OK;
  const unsigned char *A = it->act + (size_t)(S->N * S->s - 1) * S->nth;
  for (int k = 0; k < m->nsys; k++) {
    int j, i = fesd__two_modes(m, A, k, &j);
    if (i < 0 || (a[i] && a[j])) continue;
    const int leave = a[i] ? j : i;
    if (!(th[leave] > fesd__theta_floor(it))) continue;
    int slides, st = fesd__still_slides(it, z, i, j, leave, &slides);
    if (st) return st;
    if (slides) a[leave] = 1;
  }
  return FESD_OK;
}

/* Room for need events (doubling; at acceptance, outside the Newton loop: a step with more
 * switches than any before). A step records at most nsys events per element boundary and at
 * its end, and a large scene can switch thousands of times in one step (stick-slip chain,
 * n = 1024: 300+ in one step), so the store grows rather than caps. The events' mode lists
 * point into the pool: they move with it. */
static int grow_events(fesd_integrator *it, int need) {
  if (need <= it->ev_max) return FESD_OK;
  int cap = it->ev_max;
  while (cap < need) cap *= 2;
  fesd_event *e = realloc(it->events, (size_t)cap * sizeof *e);
  if (!e) return FESD_ERR_NOMEM;
  it->events = e;
  int *pool = malloc((size_t)cap * (size_t)it->ev_span * sizeof(int));
  if (!pool) return FESD_ERR_NOMEM;
  const size_t used = it->n_events ? (size_t)(e[it->n_events - 1].after + e[it->n_events - 1].n_after - it->ev_pool) : 0;
  memcpy(pool, it->ev_pool, used * sizeof(int));
  for (int i = 0; i < it->n_events; i++) {
    e[i].before = pool + (e[i].before - it->ev_pool);
    e[i].after = pool + (e[i].after - it->ev_pool);
  }
  free(it->ev_pool);
  it->ev_pool = pool;
  it->ev_max = cap;
  return FESD_OK;
}

/* Free room of the event pool for one more event (before and after lists of up to ev_span
 * ints; fesd__accept has grown the store for the step's boundaries). The used part ends after
 * the last event's lists, so a sub-step restored by fesd__load frees its events' lists too. */
static int *event_room(fesd_integrator *it) {
  const fesd_event *last = it->n_events ? &it->events[it->n_events - 1] : NULL;
  return it->ev_pool + (last ? (last->after - it->ev_pool) + last->n_after : 0);
}

/* a (na entries) is a subset of b (nb); both ascending */
static int subset(const int *a, int na, const int *b, int nb) {
  for (int i = 0, j = 0; i < na; i++, j++) {
    while (j < nb && b[j] < a[i]) j++;
    if (j == nb || b[j] != a[i]) return 0;
  }
  return 1;
}

/* Two switches of one subsystem closer than this (relative to max(1, |t|)) make a phase of
 * numerically zero length. */
#define ZERO_PHASE 1e-9

/* Record a switch of subsystem k at t if the active sets differ; before (nb) and after (na)
 * lie in the room given by event_room, after = before + nb. */
static void add_event(fesd_integrator *it, double t, int k, const int *before, int nb, int na, int boundary) {
  const int *after = before + nb;
  if (nb == na && !memcmp(before, after, (size_t)nb * sizeof(int))) return;
  /* A second switch of the subsystem at the same instant (a phase of zero length: measured, an
   * exit, a re-entry and an exit within 2e-12 after six halvings of a Lobatto IIIC step, where
   * one exit was right) is an order decided below the resolution of the checks: flagged */
  for (int i = it->n_events - 1; i >= 0; i--)
    if (it->events[i].sys == k) {
      if (t - it->events[i].t <= ZERO_PHASE * fmax(1.0, fabs(t))) it->step_flags |= FESD_FLAG_AMBIGUOUS;
      break;
    }
  fesd_event *e = &it->events[it->n_events++];
  e->t = t;
  e->sys = k;
  e->n_before = nb;
  e->n_after = na;
  e->before = before;
  e->after = after;
  if (k >= it->nsysu) { /* a stop condition (the drift has one mode: no events) */
    e->kind = FESD_EVENT_ROOT;
    e->sys = k - it->wrap.kr;
  } else if (subset(before, nb, after, na))
    e->kind = FESD_EVENT_SLIDING_ENTRY;
  else if (subset(after, na, before, nb)) {
    e->kind = FESD_EVENT_SLIDING_EXIT;
    /* pinned with exit rows on the plan path of the implicit methods (plan.c) */
    if (!it->exit_pinned) it->step_flags |= FESD_FLAG_EXIT_NOT_PINNED;
    /* An exit at an inner boundary that no exit row pins: another subsystem's switch there
     * ended the sliding mode, its theta jumps (plan.c, the exit coupled to that switch). The
     * implicit-function theorem on such a boundary's rows gave dx/dx0 of 7.6e9 and 1.1e3 where
     * the map's differences are 0.6 (a user's random case, two subsystems, Lobatto IIIA s = 3
     * and Radau IIA s = 4, N_FE = 3; a well-conditioned solve, nothing else flagged): not
     * trusted. */
    else if (it->set.sensitivities && boundary > 0 && it->bmode[boundary] != 2 && it->set.method == FESD_METHOD_FESD)
      it->step_flags |= FESD_FLAG_SENS_INACCURATE;
  } else
    e->kind = FESD_EVENT_CROSSING;
}

/* Element records for need elements (doubling; outside the Newton loop: a step with more
 * sub-steps or switches than any before). */
int fesd__grow_records(fesd_integrator *it, int need) {
  if (need <= it->cap_el) return FESD_OK;
  int cap = it->cap_el > 0 ? it->cap_el : 8;
  while (cap < need) cap *= 2;
  const size_t c = (size_t)cap, nx = (size_t)it->nx, nth = (size_t)it->nth, s = (size_t)it->s;
  double **arr[] = {&it->rec_h, &it->rec_t, &it->rec_x, &it->rec_th, &it->rec_la, &it->rec_mu, &it->rec_v};
  const size_t len[] = {c, c + 1, (c + 1) * nx, c * s * nth, c * s * nth, c * s * (size_t)it->nsys, c * s * nx};
  for (int a = 0; a < 7; a++) {
    double *p = realloc(*arr[a], (len[a] > 0 ? len[a] : 1) * sizeof(double));
    if (!p) return FESD_ERR_NOMEM; /* the arrays grown so far stay valid */
    *arr[a] = p;
  }
  it->cap_el = cap;
  return FESD_OK;
}

/* A subsystem whose side the sign checks could not resolve while it mattered: in an element
 * where it has one active mode i, an inactive mode j's indicator gap stays within the checks'
 * tolerance (|lambda_j| wth_j <= cc_tol) at its start and every stage point, so the solution runs along the
 * surface between i and j without sliding, and the other side's field would have moved the
 * state by more than AMBIG_EFFECT (units of the state rows' weights) over the element.
 * Measured: the twisting system just past its Zeno point (hard_zeno's model), where the side of
 * x1 ~ 1e-13 was decided below the floor of the sign checks and x2 left the origin at rate 1
 * (x2 = 6e-7 .. 1.2e-6 instead of 0, FESD_OK). */
#define AMBIG_EFFECT 1e-6
static int ambiguous_side(fesd_integrator *it, const double *z) {
  fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  const int s = S->s;
  /* explicit stages are predictions (not checked for signs), and the standard method's
   * per-stage sets claim no switch detection */
  if (it->tab.is_explicit || it->set.method != FESD_METHOD_FESD || fesd__system_points(S, z, 0)) return 0;
  int *act = event_room(it); /* scratch: the events of this step are recorded after this */
  for (int n = 0; n < S->N; n++) {
    const double h = z[S->ho[n]], *lam0 = fesd__left_lambda(S, z, n);
    for (int k = 0; k < it->nsys; k++) {
      if (element_modes(it, z, n, k, act) != 1) continue;
      const int i = m->th_off[k] + act[0];
      for (int q = m->th_off[k]; q < m->th_off[k + 1]; q++) {
        if (q == i) continue;
        /* the gap at the element start too (a one-stage method's only stage point is the end,
         * where a crossing of the element's end boundary has a zero gap); wrong side: beyond
         * the equations' own resolution (newton_tol, relative), where a zero gap (a switch on
         * the element boundary) shows as round-off of either sign (measured 1e-35 and -7e-17
         * weighted at legitimate entries; -1.6e-11 to -1.8e-10 past the Zeno point) */
        const double w = S->wth[q], l0 = lam0[q], lo = -it->newton_tol;
        int band = fabs(l0) * w <= it->set.cc_tol, wrong = l0 * w < lo;
        for (int j = 0; j < s && band; j++) {
          if (S->tab.c[j] == 0.0) continue; /* Lobatto's first stage lies O(h^2) off the start */
          const double l = z[fesd__la(S, n, j) + q];
          band = fabs(l) * w <= it->set.cc_tol;
          wrong |= l * w < lo;
        }
        if (!band || !wrong) continue;
        double eff = 0;
        for (int j = 0; j < s; j++) {
          const double *Fi = S->pe[n * s + j].F + m->Foff[i], *Fq = S->pe[n * s + j].F + m->Foff[q];
          for (int r = 0; r < m->nr[k]; r++)
            eff = fmax(eff, h * fabs(Fq[r] - Fi[r]) * S->wraw[S->rx[n] + m->rows[k][r]]);
        }
        if (eff > AMBIG_EFFECT) return 1;
      }
    }
  }
  return 0;
}

int fesd__accept(fesd_integrator *it, const double *z, const double *u, double T) {
  fesd__system *S = &it->sys;
  const int N = S->N, s = S->s, nx = it->nx, nth = it->nth, nsys = it->nsys;
  int st;
  if ((st = fesd__grow_records(it, it->n_el + N)) || (st = grow_events(it, it->n_events + (N + 1) * nsys)))
    return st;
  if (ambiguous_side(it, z)) it->step_flags |= FESD_FLAG_AMBIGUOUS;
  fesd__system_update_refs(S); /* the sizes of the last weighting: at z (step.c, solve) */
  if (it->set.sensitivities && (st = chain_sensitivities(it, z))) return st;
  /* records; the pinned exits of the one-stage methods and Gauss-Legendre (pinned_exit) */
  const int pinned_modes = s == 1 || S->bp, kept = it->ec_on && it->plan_sets; /* element_modes_kept */
  double t = it->t;
  for (int n = 0; n < N; n++) {
    int e = it->n_el++;
    it->rec_h[e] = z[S->ho[n]];
    it->rec_t[e] = t;
    memcpy(it->rec_x + (size_t)e * nx, n == 0 ? S->x0 : z + S->xo[n - 1], (size_t)nx * sizeof(double));
    for (int j = 0; j < s; j++) {
      memcpy(it->rec_th + ((size_t)e * s + j) * nth, z + fesd__th(S, n, j), (size_t)nth * sizeof(double));
      memcpy(it->rec_la + ((size_t)e * s + j) * nth, z + fesd__la(S, n, j), (size_t)nth * sizeof(double));
      memcpy(it->rec_mu + ((size_t)e * s + j) * nsys, z + fesd__mu(S, n, j), (size_t)nsys * sizeof(double));
      memcpy(it->rec_v + ((size_t)e * s + j) * nx, z + fesd__v(S, n, j), (size_t)nx * sizeof(double));
    }
    /* events at the left boundary of element n */
    for (int k = 0; k < nsys; k++) {
      int *b = event_room(it);
      /* the first step after fesd_set_state: when the plan moved a switch to the start (an
       * entry 1e-9 T after it), against the start's classification, so that it is logged as in
       * any later step (otherwise nothing to compare: element 0's modes at any stage would
       * show a crossing inside element 0 of the standard method as an entry at t0) */
      if (n == 0 && !it->have_prev_theta && !it->start_jumped) continue;
      int nb = n > 0 ? (kept ? element_modes_kept : element_modes)(it, z, n - 1, k, b)
               : flagged_modes(it, it->have_prev_theta ? it->act_prev : it->act_first, k, b);
      if (n > 0 && pinned_modes) nb = pinned_exit(it, n - 1, k, b, nb);
      int na = (kept ? element_modes_kept : element_modes)(it, z, n, k, b + nb);
      if (pinned_modes) na = pinned_exit(it, n, k, b + nb, na);
      add_event(it, t, k, b, nb, na, n);
    }
    t += z[S->ho[n]];
  }
  /* a mode that drops out exactly at the step end (a sliding exit on the step grid): its
   * theta vanishes only at the last stage, so the next step starts without it and neither
   * boundary comparison sees the change */
  if ((st = end_set(it, z, it->act_prev))) return st;
  for (int k = 0; k < nsys; k++) {
    int *b = event_room(it);
    int nb = (kept ? element_modes_kept : element_modes)(it, z, N - 1, k, b);
    add_event(it, it->t + T, k, b, nb, flagged_modes(it, it->act_prev, k, b + nb), -1);
  }
  it->rec_t[it->n_el] = it->t + T;
  memcpy(it->rec_x + (size_t)it->n_el * nx, z + S->xo[N - 1], (size_t)nx * sizeof(double));
  /* state */
  it->t += T;
  memcpy(it->x, z + S->xo[N - 1], (size_t)nx * sizeof(double));
  memcpy(it->theta_prev, z + fesd__th(S, N - 1, s - 1), (size_t)nth * sizeof(double));
  it->have_prev_theta = 1;
  /* x is the last stage point when c_s = 1: its record (this step's) holds g there */
  const int need = it->set.sensitivities ? (it->nu > 0 ? 3 : 2) : 1;
  const fesd__point_eval *rec = fesd__system_record(S, N * s - 1, it->t, it->x, need);
  if ((st = fesd__update_lambda00(it, it->x, u, it->set.sensitivities, rec))) return st;
  memcpy(it->ws_blk, z + fesd__v(S, N - 1, s - 1), (size_t)S->sb * sizeof(double));
  it->have_ws = 1;
  return FESD_OK;
}

