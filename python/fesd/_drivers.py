"""The loops behind fesd.solve_ivp: fixed steps (fesd_step), error-controlled output grid
(fesd_integrate_grid) and error-controlled step by step (fesd_integrate one step per call).

A Run keeps what every driver records: output points, switches, stop conditions, the
statistics, and the sensitivities across restarts (fesd_set_state resets them to the
identity: the totals are composed, dX/dx0 = S_new S_old, dX/du = S_new Su_old + Su_new).
"""
import numpy as np

from . import _lib
from .dense import DenseSolution, sample_nodes
from .errors import CallbackError, FesdError
from .model import event_direction, event_terminal

_STAT_SUM = ("steps", "switch_steps", "newton_iter", "factorizations", "solves", "homotopy_stages", "splits",
             "fallback_steps", "substeps", "nonunique_steps", "sens_inaccurate_steps", "exit_not_pinned_steps",
             "coarse_steps", "failed_steps", "rejected_steps", "events", "time", "ambiguous_steps")


class Stop(Exception):
    """Ends a driver loop: status 1 (terminal event) or -1 (library failure)."""

    def __init__(self, status, message):
        super().__init__(message)
        self.status, self.message = status, message


class Run:
    def __init__(self, it, events, u, dense, record_elements):
        self.it, self.events, self.u = it, events, u
        self.ts, self.ys = [], []
        self.switch_events = []
        self.t_events = [[] for _ in events]
        self.y_events = [[] for _ in events]
        self.terminal = [event_terminal(e) for e in events]
        self.dirs = [event_direction(e) for e in events]
        self.stats_acc = {k: 0 for k in _STAT_SUM}
        self.extra = {"failed_attempts": 0, "restarts": 0}
        self.S_acc = None  # (Sx, Su) at the last restart
        self.dense = None
        if dense and it.family in _lib.COLLOCATION:
            self.dense = DenseSolution(sample_nodes(it.stages), it.nx)
        self.record_elements = record_elements
        self.element_t = []  # boundaries of every accepted element (fixed-step and step paths)

    # ---- outputs ----
    def out(self, t, x):
        self.ts.append(float(t))
        self.ys.append(np.array(x, dtype=float))

    def record_step(self):
        """After an accepted step: its elements (for plots) and its polynomials (dense)."""
        if self.dense is None and not self.record_elements:
            return
        d = self.it.last_step_data()
        if self.record_elements:
            self.element_t.append(d.t)
        if self.dense is not None:
            for e in range(d.h.size):
                t0, h = d.t[e], d.h[e]
                if h <= 0:
                    continue
                vals = [self.it.dense_output(min(t0 + tau * h, d.t[-1])) for tau in self.dense.nodes]
                self.dense.add_element(t0, h, vals)

    def root_hit(self, i, t, x):
        """A stop condition i crossed in its direction at (t, x); True if it ends the run. A
        crossing within 1e-9 of the last one of the same condition is the same one (found at a
        stop and again by the library's next step)."""
        if self.t_events[i] and abs(t - self.t_events[i][-1]) <= 1e-9 * max(1.0, abs(t)):
            return False
        self.t_events[i].append(float(t))
        self.y_events[i].append(np.array(x, dtype=float))
        return self.terminal[i] > 0 and len(self.t_events[i]) >= self.terminal[i]

    # ---- restarts: sensitivities and statistics carried over ----
    def restart(self, t, x, S_total=None):
        """fesd_set_state at (t, x); S_total: the sensitivities there (default: the current)."""
        it = self.it
        st = it.stats()
        for k in _STAT_SUM:
            self.stats_acc[k] += st[k]
        if it.sensitivities_on:
            self.S_acc = S_total if S_total is not None else self.sensitivities()
        it.set_state(t, x, self.u)
        self.extra["restarts"] += 1

    def sensitivities(self):
        Sx, Su = self.it.sensitivities()
        if self.S_acc is None:
            return Sx, Su
        Sx0, Su0 = self.S_acc
        return Sx @ Sx0, Sx @ Su0 + Su

    def stats(self):
        st = self.it.stats()
        out = {k: self.stats_acc[k] + st[k] for k in _STAT_SUM}
        out.update(self.extra)
        return out

    def fail(self, err):
        """A library failure: CallbackError propagates, others end the run with status -1."""
        if isinstance(err, CallbackError):
            raise err
        raise Stop(-1, str(err))


def _root_events(run, evs, t_from):
    """Stop-condition crossings in their direction after t_from, earliest first."""
    out = []
    for ev in evs:
        if ev.kind != "root" or not ev.t > t_from:
            continue
        up = ev.after == (0,)
        d = run.dirs[ev.sys]
        if (d > 0 and not up) or (d < 0 and up):
            continue
        out.append(ev)
    return sorted(out, key=lambda e: e.t)


def _roots_at_stop(run, root, t_prev, x_prev):
    """After FESD_ROOT (stop condition `root` at the current state): the stop conditions that
    crossed zero in their direction at the same time. fesd_integrate reports one index, and the
    stop's event reaches the event log only with the next call's first step (a condition that
    crossed at the same instant never stops a later call), so the others are found here: r_j
    changed sign (or reached 0) from the state before the call (t_prev, x_prev) to the stop, in
    its direction (r_j within 1e-9 max(1, |r_j(x_prev)|) of zero counts). True if one of
    them ends the run."""
    it = run.it
    t, x = it.t, it.x
    hit = [root]
    if len(run.events) > 1:
        u = run.u if run.u is not None else np.zeros(0)
        for j, ev in enumerate(run.events):
            if j == root:
                continue
            r0, r1 = float(np.reshape(ev(t_prev, x_prev, u), ())), float(np.reshape(ev(t, x, u), ()))
            d = run.dirs[j]
            # at the stop r_j is zero up to the solver's accuracy, of either sign
            crossed = r0 * r1 <= 0 or abs(r1) <= 1e-9 * max(1.0, abs(r0))
            if r0 != 0 and crossed and (d == 0 or d * r0 < 0):
                hit.append(j)
    ends = False
    for i in sorted(hit):
        ends |= run.root_hit(i, t, x)
    return ends


def _tol_from(t):
    return t + 1e-12 * max(1.0, abs(t))


# ---- fixed steps ----
def run_fixed(run, t0, tf, h, t_eval):
    it, u = run.it, run.u
    n = max(1, int(np.ceil((tf - t0) / h - 1e-9)))  # steps of h, the last one to tf
    te = list(t_eval) if t_eval is not None else None
    k_eval = 0
    if te is None:
        run.out(t0, it.x)
    while k_eval < (len(te) if te is not None else 0) and te[k_eval] <= t0:
        run.out(te[k_eval], it.x)
        k_eval += 1
    for k in range(n):
        t_start, x_start = it.t, it.x
        S_start = run.sensitivities() if it.sensitivities_on else None
        try:
            it.step(h if k < n - 1 else tf - t_start, u)
        except FesdError as e:
            run.fail(e)
        evs = it.last_events()
        run.switch_events.extend(e for e in evs if e.kind != "root")
        stop = None
        for ev in _root_events(run, evs, _tol_from(t_start)):  # earliest first
            if stop is not None and ev.t > _tol_from(stop.t):
                break  # after the stop
            if run.root_hit(ev.sys, ev.t, _boundary_state(it, ev.t)) and stop is None:
                stop = ev
        if stop is not None:  # end on the stop condition: the step again, to its time
            run.restart(t_start, x_start, S_start)
            try:
                it.step(stop.t - t_start, u)
            except FesdError as e:
                run.fail(e)
            run.switch_events.extend(e for e in it.last_events() if e.kind != "root" and e.t < stop.t)
        run.record_step()
        t_end = it.t
        if te is None:
            run.out(t_end, it.x)
        else:
            while k_eval < len(te) and te[k_eval] <= t_end + 1e-12 * max(1.0, abs(t_end)):
                run.out(te[k_eval], _state_at(it, te[k_eval], t_end))
                k_eval += 1
        if stop is not None:
            raise Stop(1, "A termination event occurred.")


def _boundary_state(it, t):
    """State at an element boundary of the last step (switches and roots are boundaries)."""
    d = it.last_step_data()
    j = int(np.argmin(np.abs(d.t - t)))
    return d.x[j]


def _state_at(it, t, t_end):
    if abs(t - t_end) <= 1e-12 * max(1.0, abs(t_end)):
        return it.x
    if it.family not in _lib.COLLOCATION:
        raise ValueError(f"t_eval point {t} is not a step end and family {it.family!r} has no dense output: "
                         "use a collocation family (radau, gauss, lobatto3a) or t_eval on the step grid")
    return it.dense_output(t)


# ---- error control, output grid ----
def run_grid(run, t0, tf, t_eval):
    it, u = run.it, run.u
    te = np.asarray(t_eval, dtype=float)
    done = 0
    while done < te.size:
        t_prev, x_prev = it.t, it.x
        st, xo, info = it.integrate_grid(te[done:], u, raise_on_error=False)
        for j in range(info["n_done"]):
            run.out(te[done + j], xo[j])
        done += info["n_done"]
        if st < 0:
            try:
                it._raise(st, "fesd_integrate_grid")
            except FesdError as e:
                run.fail(e)
        for k in ("failed_attempts",):
            run.extra[k] += info[k]
        if st == _lib.FESD_ROOT and _roots_at_stop(run, info["root"], t_prev, x_prev):
            raise Stop(1, "A termination event occurred.")
    run.switch_events.extend(e for e in it.event_log() if e.kind != "root")


# ---- error control, every step ----
def run_steps(run, t0, tf, tol, max_steps):
    """One error-controlled step per fesd_integrate_step call (the controller keeps its state
    between calls). After a stop condition the integration restarts from its state."""
    it, u = run.it, run.u
    run.out(t0, it.x)
    it.set_tolerances(tol["rtol"], tol["atol"], h_init=tol["h_init"], h_max=tol["h_max"], h_min=tol["h_min"])
    attempts = 0
    while it.t < tf:
        attempts += 1
        if attempts > max_steps:
            raise Stop(-1, f"FESD_ERR_TOO_MANY_STEPS: more than max_steps = {max_steps} steps")
        t_prev, x_prev = it.t, it.x
        try:
            st, info = it.integrate_step(tf, u)
        except FesdError as e:
            run.fail(e)
        run.extra["failed_attempts"] += info["failed_attempts"]
        if info["steps"] == 0:
            continue
        run.switch_events.extend(e for e in it.last_events() if e.kind != "root")
        run.record_step()
        run.out(it.t, it.x)
        if st == _lib.FESD_ROOT:
            if _roots_at_stop(run, info["root"], t_prev, x_prev):
                raise Stop(1, "A termination event occurred.")
            run.restart(it.t, it.x)
