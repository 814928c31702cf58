/* The event log of error-controlled integration and its stop conditions (integrate.c): the
 * step's events appended to the log, an entry that undoes the last logged exit at the same
 * time removed with it, and a stop condition's crossing taken as a stop once per direction. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fesd/step.h"

/* Whether a stop condition's event is a crossing into r > 0 ({1} -> {0}). */
static int crosses_up(const fesd_event *ev) { return ev->n_after == 1 && ev->after[0] == 0; }

/* A crossing of the last stop's condition in the stop's direction is that stop again until
 * the condition has crossed back (an event of the other direction, earlier in the same step or
 * in an earlier one: re-armed then, log_events). The step that stopped ends on its root only to
 * the method's accuracy: the next step finds the same crossing at once, or, when the condition
 * crosses slowly (near its extremum), after a delay that no window in time bounds (measured,
 * relay feedback system, Lobatto IIIC s = 4, rtol 4e-5, a stop located to 5e-6: stops at
 * 7.457300834 and 7.457301074 for one crossing, 3 of 60 runs; a window of 1e-6 of the step
 * length was used before). Each condition keeps its last stop's direction (stop_dir). ev[0..ne)
 * are the step's events, e one of them. */
static int same_stop(const fesd_integrator *it, const fesd_event *ev, int ne, const fesd_event *e) {
  const int up = crosses_up(e);
  if (it->stop_dir[e->sys] != (up ? 1 : -1)) return 0;
  for (int q = 0; q < ne; q++)
    if (ev[q].kind == FESD_EVENT_ROOT && ev[q].sys == e->sys && crosses_up(&ev[q]) != up && ev[q].t < e->t) return 0;
  return 1;
}

/* A zero crossing of stop condition ev->sys in its direction (model.root_dir). */
static int root_wanted(const fesd_integrator *it, const fesd_event *ev) {
  const int up = crosses_up(ev);
  const int dir = it->wrap.user.root_dir ? it->wrap.user.root_dir[ev->sys] : 0;
  return !((dir > 0 && !up) || (dir < 0 && up));
}

/* Append one event (its mode lists copied into the pool; grown outside the Newton loop). */
static int log_append(fesd_integrator *it, const fesd_event *ev) {
  const int need = ev->n_before + ev->n_after;
  if (it->log_n == it->log_cap || it->log_pool_n + need > it->log_pool_cap) {
    int cap = it->log_cap ? 2 * it->log_cap : 64;
    size_t pcap = it->log_pool_cap ? 2 * it->log_pool_cap : 256;
    while (pcap < it->log_pool_n + (size_t)need) pcap *= 2;
    fesd_event *nl = realloc(it->log, (size_t)cap * sizeof(*nl));
    if (!nl) return FESD_ERR_NOMEM;
    it->log = nl;
    it->log_cap = cap;
    int *np = realloc(it->log_pool, pcap * sizeof(int));
    if (!np) return FESD_ERR_NOMEM;
    it->log_pool = np;
    it->log_pool_cap = pcap;
    size_t off = 0; /* the pool moved: point the logged lists into it again */
    for (int q = 0; q < it->log_n; q++) {
      it->log[q].before = np + off;
      it->log[q].after = np + off + it->log[q].n_before;
      off += (size_t)(it->log[q].n_before + it->log[q].n_after);
    }
  }
  fesd_event *d = &it->log[it->log_n++];
  *d = *ev;
  int *p = it->log_pool + it->log_pool_n;
  memcpy(p, ev->before, (size_t)ev->n_before * sizeof(int));
  memcpy(p + ev->n_before, ev->after, (size_t)ev->n_after * sizeof(int));
  d->before = p;
  d->after = p + ev->n_before;
  it->log_pool_n += (size_t)need;
  return FESD_OK;
}

static int same_modes(const int *a, int na, const int *b, int nb) {
  return na == nb && !memcmp(a, b, (size_t)na * sizeof(int));
}

/* A sliding entry that undoes the last logged exit of its subsystem at the same time (a step
 * ended on the exit, at a stop condition or an output time within the exit's accuracy, and the
 * next one found the mode sliding on) removes that exit and is not logged: a phase of zero length.
 * Found by a review: a stop 1e-7 before an exit logged exit, stop, entry at the stop and the exit
 * 1e-7 later (Radau s = 5, Lobatto IIIC s = 3 at rtol 1e-6). Returns 1 when it did. */
static int cancels_exit(fesd_integrator *it, const fesd_event *ev) {
  if (ev->kind != FESD_EVENT_SLIDING_ENTRY) return 0;
  for (int q = it->log_n - 1; q >= 0; q--) {
    fesd_event *x = &it->log[q];
    if (x->kind == FESD_EVENT_ROOT) continue; /* the stop there (its time is the root's) */
    /* the same time: a step's end, and the next one's start (summed otherwise: 5e-16 apart) */
    if (!(fabs(x->t - ev->t) <= 64 * DBL_EPSILON * (1 + fabs(ev->t)))) return 0;
    if (x->sys != ev->sys) continue;
    if (x->kind != FESD_EVENT_SLIDING_EXIT || !same_modes(x->before, x->n_before, ev->after, ev->n_after) ||
        !same_modes(x->after, x->n_after, ev->before, ev->n_before))
      return 0;
    const int len = x->n_before + x->n_after; /* its mode lists out of the pool, the rest moved up */
    int *at = it->log_pool + (x->before - it->log_pool), *end = it->log_pool + it->log_pool_n;
    memmove(at, at + len, (size_t)(end - at - len) * sizeof(int));
    it->log_pool_n -= (size_t)len;
    for (int r = q + 1; r < it->log_n; r++) {
      it->log[r - 1] = it->log[r];
      it->log[r - 1].before -= len;
      it->log[r - 1].after -= len;
    }
    it->log_n--;
    return 1;
  }
  return 0;
}

/* Append the last step's events to the log (stop conditions only where they stop; a stop
 * logged when the integration stopped on it is not logged again when the next step starts
 * from it). */
int fesd__log_events(fesd_integrator *it, int stopping, int stop_up) {
  const fesd_event *ev;
  int ne;
  fesd_last_events(it, &ev, &ne);
  for (int e = 0; e < ne; e++) {
    if (ev[e].kind == FESD_EVENT_ROOT) {
      /* a step that ends on its stop: its crossings in the stop's direction are the stop */
      if (!root_wanted(it, &ev[e]) || (ev[e].sys == stopping && crosses_up(&ev[e]) == stop_up) ||
          same_stop(it, ev, ne, &ev[e]))
        continue;
    }
    if (cancels_exit(it, &ev[e])) continue;
    int st = log_append(it, &ev[e]);
    if (st) return st;
  }
  fesd__rearm_stops(it);
  return FESD_OK;
}

void fesd__rearm_stops(fesd_integrator *it) {
  const fesd_event *ev;
  int ne;
  fesd_last_events(it, &ev, &ne);
  for (int e = 0; e < ne; e++)
    if (ev[e].kind == FESD_EVENT_ROOT && it->stop_dir[ev[e].sys] == (crosses_up(&ev[e]) ? -1 : 1))
      it->stop_dir[ev[e].sys] = 0;
}

/* The stop at t_root on condition k: logged now (the step ends on the root, so the change of
 * the condition's sign shows only at the start of the next step). dir of the crossing:
 * +1 increasing ({1} -> {0}), -1 decreasing. */
static int log_stop(fesd_integrator *it, int k, double t_root, int dir) {
  static const int modes[2] = {0, 1};
  fesd_event ev = {.t = t_root, .sys = k, .kind = FESD_EVENT_ROOT, .n_before = 1, .n_after = 1};
  ev.before = dir > 0 ? &modes[1] : &modes[0];
  ev.after = dir > 0 ? &modes[0] : &modes[1];
  return log_append(it, &ev);
}

/* The integration stops on condition k at the current time (dir of its crossing): its
 * direction remembered (same_stop), the stop logged. FESD_ROOT, or the log's failure. */
int fesd__take_stop(fesd_integrator *it, int k, int dir, fesd_integrate_info *info) {
  it->stop_dir[k] = (signed char)(dir > 0 ? 1 : -1);
  it->last_stop_t = it->t;
  const int st = log_stop(it, k, it->t, dir);
  if (st) return st;
  info->events++;
  info->root = k;
  return FESD_ROOT;
}

int fesd_event_log(const fesd_integrator *it, const fesd_event **events, int *count) {
  if (!it || !events || !count) return FESD_ERR_NULL;
  *events = it->log;
  *count = it->log_n;
  return FESD_OK;
}

/* The earliest stop condition crossed in the last step in its direction after t_from
 * (-1: none); *t_root its time, *dir its direction (+1 increasing). */
int fesd__root_crossed(const fesd_integrator *it, double t_from, double *t_root, int *dir) {
  const fesd_event *ev;
  int ne, best = -1;
  fesd_last_events(it, &ev, &ne);
  for (int e = 0; e < ne; e++) {
    if (ev[e].kind != FESD_EVENT_ROOT || !(ev[e].t > t_from) || !root_wanted(it, &ev[e])) continue;
    if (same_stop(it, ev, ne, &ev[e])) continue;
    if (best < 0 || ev[e].t < ev[best].t) best = e;
  }
  if (best >= 0) *t_root = ev[best].t, *dir = crosses_up(&ev[best]) ? 1 : -1;
  return best >= 0 ? ev[best].sys : -1;
}

