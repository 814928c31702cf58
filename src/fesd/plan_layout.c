/* The element layout of a plan (fesd__plan_layout): one boundary per cluster of switches, the
 * elements of the step distributed over the segments between them, each boundary's row, and
 * the bounds of the element lengths (plan.c builds and corrects the plan itself). */
#include <math.h>
#include <string.h>

#include "fesd/step.h"

/* A segment between switches shorter than this fraction of the nominal element T / N_FE does
 * not count towards the N_FE elements of the step (fesd__plan_layout). */
#define TINY_SEGMENT 0.1

/* Boundaries of the sorted plan: clusters of entering switches of different subsystems within
 * merge_tol T share one; an exit has its own. Writes bt[1..nb] and returns nb. */
static int cluster(fesd_integrator *it, double T, int *first_of) {
  int nb = 0;
  for (int e = 0; e < it->n_plan; e++) {
    const fesd__switch *w = &it->plan[e];
    int join = 0;
    if (nb > 0 && !w->exit) {
      const int f = first_of[nb - 1];
      join = !it->plan[f].exit && w->t - it->plan[f].t <= it->merge_tol * T;
      for (int q = f; q < e && join; q++) join = it->plan[q].sys != w->sys && !it->plan[q].exit;
    }
    if (!join) {
      first_of[nb] = e;
      it->bt[++nb] = w->t;
    }
    it->plan[e].kb = nb; /* cluster index for now; element boundary below */
  }
  return nb;
}

int fesd__plan_layout(fesd_integrator *it, double T, double *z) {
  fesd__system *S = &it->sys;
  const int nth = it->nth, s = it->s;
  fesd__plan_sort(it);
  int *first_of = it->kb;
  const int nb = cluster(it, T, first_of);
  if (nb + 1 > it->N_cap) return FESD_ERR_TOO_MANY_SWITCHES;
  /* boundary times strictly increasing inside (0, T) */
  double *bt = it->bt;
  const double gap = 1e-8 * T;
  bt[0] = 0;
  bt[nb + 1] = T;
  for (int q = 1; q <= nb; q++) {
    if (bt[q] < bt[q - 1] + gap) bt[q] = bt[q - 1] + gap;
    if (bt[q] > T - (nb + 1 - q) * gap) bt[q] = T - (nb + 1 - q) * gap;
  }
  /* A segment much shorter than a nominal element (a switch just after the start, or two
   * switches close together) gets an element beyond N_FE instead of taking one from the long
   * segments: as such a switch moves to the start, the layout then tends to the layout without
   * it plus an element of zero length, and the step map stays continuous. Measured
   * (ocp_step_eq's dynamics, implicit Euler, N_FE = 3, a start at the co-dimension-2 point):
   * 1e-8 off it, an entry at the start took an element from the free motion after the exit,
   * whose end state jumped by 0.022 against the start on the point, and the optimal control
   * solve, whose node x_3 sits there, stalled. (Implicit Euler only: with more stages the
   * layouts' results differ by far less, and the extra element changed the error-controlled
   * runs of the randomised tests.)
   * With implicit Euler a segment that ends in a pinned exit needs two elements: the
   * only stage of its last element is the exit point, where the leaving mode's theta is zero,
   * so a single element there integrates the remaining mode alone and binds nothing at its
   * start (its entry's cross-complementarity row vanishes): the plan cycled between the entry
   * and the exit (same problem, a start 1e-8 below c1 = 0: 106 Newton iterations, 9 elements,
   * and another end state). */
  int *cnt = it->bseg, base = 0, n_tiny = 0;
  const int euler = s == 1 && it->tab.c_end_is_one; /* implicit Euler: its stage is the element end */
  const double tiny = TINY_SEGMENT * T / it->set.n_fe;
  for (int q = 0; q <= nb; q++) {
    n_tiny += euler && bt[q + 1] - bt[q] < tiny;
    cnt[q] = euler && q < nb && it->plan[first_of[q]].exit ? 2 : 1;
    base += cnt[q];
  }
  if (base > it->N_cap)
    for (int q = 0; q <= nb; q++) cnt[q] = 1, base = nb + 1;
  int want = base > it->set.n_fe + n_tiny ? base : it->set.n_fe + n_tiny;
  /* After a failed solve (split_layout): no element longer than the nominal T / N_FE where
   * the cap allows, a switch splits an element instead of stretching its neighbour. With
   * N_FE = 2 one early switch leaves a single element of almost T after it, where the
   * fixed-active-set Newton of a coupled chain did not converge (stick-slip chain, n = 64:
   * 40 Newton iterations in such a step, 8 with the split). Not the default: it costs an
   * element per switch step and a workspace level more. */
  if (it->split_layout) {
    const double h_nom = T / (it->set.n_fe * (double)(1 << (it->split_layout - 1)));
    int split = 0;
    for (int q = 0; q <= nb; q++) {
      const int c = (int)ceil((bt[q + 1] - bt[q]) / h_nom - 1e-6);
      split += c > 1 ? c : 1;
    }
    if (split > want && split <= it->N_cap) want = split;
  }
  const int N = fesd__ladder(it, want);
  int st = fesd__use_level(it, N);
  if (st) return st;
  /* elements per segment: the least above, the rest to the segment with the longest elements */
  for (int extra = N - base; extra > 0; extra--) {
    int best = 0;
    for (int q = 1; q <= nb; q++)
      if ((bt[q + 1] - bt[q]) * cnt[best] > (bt[best + 1] - bt[best]) * cnt[q]) best = q;
    cnt[best]++;
  }
  /* bounds of the element lengths: a fresh switch stays in its bracket, the others move
   * freely (bt_lo/bt_hi: bounds of the boundary times) */
  {
    double lo_prev = 0, hi_prev = 0;
    int e = 0;
    for (int q = 0; q <= nb; q++) {
      double lo_next = T, hi_next = T;
      if (q < nb) {
        lo_next = 0, hi_next = T;
        for (; e < it->n_plan && it->plan[e].kb == q + 1; e++)
          if (it->plan[e].fresh) {
            lo_next = lo_next > it->plan[e].lo ? lo_next : it->plan[e].lo;
            hi_next = hi_next < it->plan[e].hi ? hi_next : it->plan[e].hi;
          }
        if (!(lo_next < hi_next)) lo_next = 0, hi_next = T;
      }
      double lo = (lo_next - hi_prev) / cnt[q], hi = (hi_next - lo_prev) / cnt[q];
      it->bseg_lo[q] = lo > 1e-9 * T ? lo : 1e-9 * T;
      it->bseg_hi[q] = hi < T ? hi : T;
      lo_prev = lo_next, hi_prev = hi_next;
    }
  }
  /* active sets, boundary rows and element lengths */
  unsigned char *cur = it->cand;
  memcpy(cur, it->act0, (size_t)nth);
  memset(it->bmode, 0, (size_t)(N + 1) * sizeof(int));
  int n = 0, e = 0;
  for (int q = 0; q <= nb; q++) {
    if (q > 0) {
      for (; e < it->n_plan && it->plan[e].kb == q; e++) {
        fesd__switch *w = &it->plan[e];
        const int a = it->model.th_off[w->sys], b = it->model.th_off[w->sys + 1];
        memcpy(cur + a, fesd__plan_after(it, e) + a, (size_t)(b - a));
        it->bmode[n] = w->exit ? 2 : 1;
        it->exit_mode[n] = w->mode;
        w->kb = n;
      }
    }
    for (int c = 0; c < cnt[q]; c++, n++) {
      for (int j = 0; j < s; j++) memcpy(it->act + (size_t)(n * s + j) * nth, cur, (size_t)nth);
      z[S->ho[n]] = (bt[q + 1] - bt[q]) / cnt[q];
      it->hlo[n] = it->bseg_lo[q];
      it->hhi[n] = it->bseg_hi[q];
    }
  }
  return FESD_OK;
}

