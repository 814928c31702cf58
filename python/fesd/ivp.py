"""fesd.solve_ivp: scipy.integrate.solve_ivp's shape over libfesd."""
import numpy as np

from . import _drivers
from ._common import AttrDict
from .integrator import Integrator

MESSAGES = {0: "The solver successfully reached the end of the integration interval.",
            1: "A termination event occurred."}


class OdeResult(AttrDict):
    """Result of solve_ivp (a dict with attribute access, as scipy's).

    t (nt,), y (nx, nt): output points (the steps, or t_eval); sol: DenseSolution or None;
    t_events, y_events: per stop condition, the times (array) and states (array (n, nx));
    switch_events: list of SwitchEvent (time, subsystem, kind, modes before/after);
    status (-1 failure, 0 end reached, 1 terminal event), message, success;
    dxdx0 (nx, nx), dxdu (nx, nu): sensitivities at t[-1] (sensitivities=True, else None);
    stats: steps, rejected_steps, failed_attempts, newton_iter, factorizations, events, ...;
    element_t: boundaries of the elements of every step (list of arrays; fixed steps and
    step-by-step error control).
    """

    _REPR_KEYS = ("status", "message", "success", "t", "y", "t_events", "switch_events", "stats")


def solve_ivp(model, t_span, y0, *, method="fesd", family="radau", stages=2, n_fe=2, rtol=None, atol=None,
              h=None, t_eval=None, dense_output=False, events=None, sensitivities=False, u=None, max_step=None,
              first_step=None, min_step=None, max_steps=100000, record_elements=False, **settings):
    """Integrate a fesd.Model over t_span = (t0, tf) from y0.

    Two modes:
      - error control (h=None, default): rtol/atol (defaults 1e-6 / 1e-9; atol may be per state),
        max_step, first_step, min_step, max_steps as in fesd_tolerances. Without t_eval every
        accepted step is an output point (one step per fesd_integrate call); with t_eval the
        library's fesd_integrate_grid fills them (dense output inside the steps);
      - fixed steps (h given): steps of length h with fesd_step (the last one shortened to land on
        tf); method="standard" gives standard time-stepping with the same RK method and n_fe.
    events: stop conditions r(t, x, u) with .direction and .terminal (True/False or a count) as
    in scipy; sensitivities: dx(t_end)/dx0 and dx/du in the result; u: constant controls/
    parameters (model.nu values); dense_output: sol(t) from the collocation polynomials
    (radau, gauss, lobatto3a); settings: other fesd_settings fields (see fesd.Integrator).
    Raises CallbackError when a model callable fails; other library failures return status -1
    with the output up to there.
    """
    t0, tf = map(float, t_span)
    if not tf > t0:
        raise ValueError("t_span must be increasing (t0 < tf)")
    events = [events] if callable(events) else list(events or [])
    if h is not None:
        if rtol is not None or atol is not None:
            raise ValueError("rtol/atol set the error control; with h= the steps are fixed")
        if not h > 0:
            raise ValueError("h must be positive")
    if t_eval is not None:
        t_eval = np.asarray(t_eval, dtype=float).reshape(-1)
        if np.any(np.diff(t_eval) < 0) or (t_eval.size and (t_eval[0] < t0 or t_eval[-1] > tf)):
            raise ValueError("t_eval must be increasing and within t_span")
    y0 = np.asarray(y0, dtype=float).reshape(-1)
    if model.nu > 0 and u is None:
        raise ValueError(f"the model has nu = {model.nu}: pass u=")
    if model.nu == 0 and u is not None and np.size(u) > 0:
        raise ValueError("the model has nu = 0: u= would be ignored")
    if int(max_steps) < 1:
        raise ValueError(f"max_steps must be >= 1 (got {max_steps})")
    it = Integrator(model, method=method, family=family, stages=stages, n_fe=n_fe, sensitivities=sensitivities,
                    events=events, **settings)
    try:
        it.set_state(t0, y0, u)
        run = _drivers.Run(it, events, u, dense_output, record_elements)
        status, message = 0, MESSAGES[0]
        try:
            if h is not None:
                _drivers.run_fixed(run, t0, tf, float(h), t_eval)
            else:
                tol = {"rtol": 1e-6 if rtol is None else rtol, "atol": 1e-9 if atol is None else atol,
                       "h_init": first_step or 0.0, "h_max": max_step or 0.0, "h_min": min_step or 0.0}
                if t_eval is not None and not dense_output:
                    it.set_tolerances(tol["rtol"], tol["atol"], h_init=tol["h_init"], h_max=tol["h_max"],
                                      h_min=tol["h_min"], max_steps=max_steps)
                    _drivers.run_grid(run, t0, tf, t_eval)
                else:
                    _drivers.run_steps(run, t0, tf, tol, max_steps)
        except _drivers.Stop as s:
            status, message = s.status, s.message
        sol = run.dense.finalize() if run.dense is not None and run.dense._t0 else None
        t_out, y_out = np.asarray(run.ts), np.asarray(run.ys).reshape(-1, model.nx).T
        if h is None and t_eval is not None and dense_output:
            keep = t_eval[t_eval <= (sol.t_max if sol is not None else t0)]
            t_out, y_out = keep, (sol(keep) if sol is not None else np.zeros((model.nx, 0)))
        dxdx0 = dxdu = None
        if sensitivities:
            dxdx0, dxdu = run.sensitivities()
        res = OdeResult(t=t_out, y=y_out, sol=sol, status=status, message=message, success=status >= 0,
                        t_events=[np.asarray(v) for v in run.t_events] if events else None,
                        y_events=[np.asarray(v).reshape(-1, model.nx) for v in run.y_events] if events else None,
                        switch_events=run.switch_events, dxdx0=dxdx0, dxdu=dxdu, stats=run.stats(),
                        element_t=run.element_t, method=method, family=family, stages=stages, n_fe=n_fe)
        return res
    finally:
        it.close()
