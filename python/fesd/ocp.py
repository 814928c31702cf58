"""fesd.OCP: direct optimal control with FESD (include/fesd_ocp.h, docs/ocp.md) for a fesd.Model.

    ocp = fesd.OCP(model, n_ctrl=6, t0=0, tf=4, x0=x0, u_lb=..., u_ub=...,
                   lagrange_lsq=lambda t, x, u: [...], l1=lambda x: [...], l1_weight=[1e3, 1e3],
                   stages=2, n_fe=2)
    res = ocp.solve(u_guess=...)
    res.status_name, res.objective, res.x, res.u, res.multipliers, res.intervals

One fesd_ocp object (fesd_ocp_create ... fesd_ocp_free). The OCP functions are Python callables:
stage functions (lagrange, lagrange_lsq, path) take (t, x, u), terminal ones (mayer, mayer_lsq,
l1, terminal) take (x) (the library evaluates them at x_N, t = tf). Their Jacobians are optional
callables with the same arguments returning d/dx (n, nx) and, for stage functions, d/du (n, nu)
as a pair (dx, du) (rows = outputs, as the model's Jacobians); without one the wrapper computes
central differences in Python (see FD_STEP). A callable that raises, returns the wrong shape
or NaN/Inf makes its trampoline return nonzero (or write the NaN through, which the library
turns into FESD_ERR_NONFINITE): at a trial point of the line search the library only rejects
the trial, elsewhere the solve stops, and solve() raises fesd.CallbackError (see OCP.solve).
"""
import ctypes
import math
import warnings
from dataclasses import dataclass

import numpy as np

from . import _lib
from ._callbacks import Bridge, Failure, _finite
from ._common import AttrDict, Handle
from .errors import CallbackError, FesdError, OutputShapeError
from .integrator import _events, build_model_struct, fill_settings, step_data
from .model import Model

_byref, _string_at, _memmove = ctypes.byref, ctypes.string_at, ctypes.memmove
_frombuffer, _f64 = np.frombuffer, np.float64

#: relative step of the central differences of OCP functions without a Jacobian: variable z_j
#: moves by h_j = FD_STEP * max(1, |z_j|) both ways (eps^(1/3), the step that balances the
#: O(h^2) truncation against the O(eps / h) round-off: about 1e-10 relative error for smooth
#: functions of unit scale). OCP(fd_step=...) overrides it.
FD_STEP = float(np.finfo(float).eps) ** (1.0 / 3.0)

HESSIANS = {"auto": 0, "gauss_newton": 1, "bfgs": 2, "gn_sr1": 3}
INITS = {"simulate": 0, "constant": 1}
QP_BACKENDS = {"auto": 0, "dense": 1, "umfpack": 2, "klu": 3, "cholmod": 4}
_ENUMS = {"hessian": HESSIANS, "init": INITS, "qp_backend": QP_BACKENDS}
_INT_MIN, _INT_MAX = -(2 ** 31), 2 ** 31 - 1


# ---------------------------------------------------------------------------------------------
# OCP functions: the trampolines
# ---------------------------------------------------------------------------------------------
class _Fn:
    """The C trampoline (fesd_ocp_fn) of one OCP function: role ("lagrange", "path", ...),
    fun/jac the Python callables, n outputs; terminal: called as fun(x) (the library passes
    u = NULL and du = NULL)."""

    def __init__(self, owner, role, fun, jac, n, terminal):
        self.owner, self.role, self.fun, self.jac, self.n, self.terminal = owner, role, fun, jac, n, terminal
        self.nx, self.nu = owner.nx, owner.nu
        self.nbx, self.nbu = 8 * owner.nx, 8 * owner.nu
        self.c = _lib.OCP_FN(self._call)

    def _eval(self, t, x, u):
        return self.fun(x) if self.terminal else self.fun(t, x, u)

    def _value(self, t, x, u):
        return _asvec(self._eval(t, x, u), self.n, self.role)

    def _jacobians(self, t, x, u):
        """(dx (n, nx), du (n, nu) or None) from the user's Jacobian or central differences."""
        n, nx, nu = self.n, self.nx, self.nu
        want_u = not self.terminal and nu > 0
        if self.jac is not None:
            res = self.jac(x) if self.terminal else self.jac(t, x, u)
            role = self.role + "_jac"
            if isinstance(res, tuple):
                if len(res) != 2:
                    raise OutputShapeError(f"{role} returned a tuple of {len(res)}, expected (d/dx, d/du)")
                dx, du = res
            elif want_u:
                raise OutputShapeError(f"{role} must return (d/dx, d/du) since the model has nu = {nu} > 0")
            else:
                dx, du = res, None
            dx = _asmat(dx, (n, nx), role)
            du = _asmat(du, (n, nu), role + " (d/du)") if want_u else None
            return dx, du
        h0 = self.owner.fd_step
        dx = _central(lambda xx: self._value(t, xx, u), x, n, h0)
        du = _central(lambda uu: self._value(t, x, uu), u, n, h0) if want_u else None
        return dx, du

    def _call(self, t, x, u, val, dx, du, user):
        o = self.owner
        if o.abort:
            return 1
        try:
            xa = _frombuffer(_string_at(x, self.nbx))
            ua = _frombuffer(_string_at(u, self.nbu)) if (u and self.nbu) else o.u_empty
            v = self._value(t, xa, ua)
            buf = v.tobytes()
            ok = _finite(buf)
            _memmove(val, buf, len(buf))
            if dx:
                Jx, Ju = self._jacobians(t, xa, ua)
                bx = Jx.T.tobytes()  # column-major (n x nx)
                ok = ok and _finite(bx)
                _memmove(dx, bx, len(bx))
                if du and Ju is not None:
                    bu = Ju.T.tobytes()
                    ok = ok and _finite(bu)
                    _memmove(du, bu, len(bu))
            if not ok:  # written through: the library reports FESD_ERR_NONFINITE (or rejects a trial)
                o._fail(self.role, t, x, FloatingPointError(f"{self.role} returned a non-finite value"))
            return 0
        except BaseException as e:  # noqa: B902 - reported by solve() after the C call
            return o._fail(self.role, t, x, e)


def _central(f, z, n, h0):
    """(n, len(z)) central differences of f at z, steps h0 max(1, |z_j|) (the divisor is the
    step as represented: (z_j + h) - (z_j - h))."""
    d = np.empty((n, len(z)))
    for j in range(len(z)):
        zp, zm = np.array(z), np.array(z)
        h = h0 * max(1.0, abs(z[j]))
        zp[j] += h
        zm[j] -= h
        d[:, j] = (f(zp) - f(zm)) / (zp[j] - zm[j])
    return d


def _asvec(res, n, role):
    a = np.asarray(res, dtype=_f64)
    if a.size != n or a.ndim > 1 and not (a.ndim == 2 and 1 in a.shape):
        raise OutputShapeError(f"{role} returned shape {a.shape}, expected ({n},)")
    return a.reshape(n)


def _asmat(res, shape, role):
    a = np.asarray(res, dtype=_f64)
    if a.shape != shape:
        if shape[0] == 1 and a.ndim <= 1 and a.size == shape[1]:  # gradient of a scalar function
            a = a.reshape(shape)
        else:
            raise OutputShapeError(f"{role} returned shape {a.shape}, expected {shape}")
    return a


# ---------------------------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------------------------
@dataclass
class OcpMultipliers:
    """Multipliers of the returned iterate (fesd_ocp_multipliers; signs: L = f - y'c, a two-sided
    constraint's multiplier positive when its lower bound is active, negative at the upper):
    dynamics (N, nx): row k multiplies Phi_k(x_k, q_k) - x_{k+1}; x0 (nx,): fixed x0 components;
    x_bound (N+1, nx): state bounds (row 0: free x0 components); u_bound (N, nu); path
    (N+1, n_path); terminal (n_term,); l1 (n_l1,): in [-w_i, w_i]."""
    dynamics: np.ndarray
    x0: np.ndarray
    x_bound: np.ndarray
    u_bound: np.ndarray
    path: np.ndarray
    terminal: np.ndarray
    l1: np.ndarray


@dataclass
class OcpInterval:
    """Interval k of the returned iterate re-simulated (fesd_ocp_interval): its elements' lengths
    h (n,), boundaries t (n+1,), states x (n+1, nx), cost (n+1,) the Lagrange term integrated
    from t_k (None without one), theta and lambda_ (n, s, modes), mu (n, s, nsys), and the
    switches (SwitchEvent) at the element boundaries."""
    k: int
    h: np.ndarray
    t: np.ndarray
    x: np.ndarray
    cost: object
    theta: np.ndarray
    lambda_: np.ndarray
    mu: np.ndarray
    events: list


class OcpResult(AttrDict):
    """Result of OCP.solve (a dict with attribute access, as fesd.OdeResult).

    status (0 or a negative fesd status), status_name, message (the library's status string),
    success (status == 0); t (N+1,) the control grid, x (N+1, nx) the states x_k, u (N, nu) the
    controls q_k: the best iterate whatever the status; objective; KKT residuals stationarity,
    stationarity_rel, feasibility, complementarity, min_multiplier; iterations, integrations;
    CPU seconds time_total = time_integration + time_qp + time_other; stalled, stall_interval;
    presolve_run, presolve_status (a status name), presolve_iterations, presolve_used;
    multipliers (OcpMultipliers); intervals (list of OcpInterval, or None with
    solve(intervals=False); an entry is None when its re-simulation failed); info (dict of every
    fesd_ocp_info field); callback_failure (a description, or None): a Python callable that
    raised or returned the wrong shape during the solve at a point the library then rejected
    (a non-finite output is not reported there: the integrator's Newton line search may itself
    evaluate the model at a non-finite iterate and recover).
    """

    _REPR_KEYS = ("status_name", "message", "objective", "iterations", "integrations", "stationarity_rel",
                  "feasibility", "complementarity", "time_total")

    def summary(self):
        """A few lines: status, objective, KKT residuals, work."""
        r = self
        lines = [f"status {r.status_name} ({r.message})",
                 f"objective {r.objective:.12g}",
                 f"KKT: stationarity {r.stationarity_rel:.1e} (rel), feasibility {r.feasibility:.1e}, "
                 f"complementarity {r.complementarity:.1e}, min multiplier {r.min_multiplier:.1e}",
                 f"SQP iterations {r.iterations}, integrations {r.integrations}, CPU {1e3 * r.time_total:.1f} ms "
                 f"(integration {1e3 * r.time_integration:.1f}, QP {1e3 * r.time_qp:.1f}, "
                 f"other {1e3 * r.time_other:.1f})"]
        if r.presolve_run:
            lines.append(f"presolve {r.presolve_status}, {r.presolve_iterations} iterations, "
                         f"{'used' if r.presolve_used else 'not used'}")
        if r.stalled:
            lines.append(f"stalled (interval {r.stall_interval})")
        return "\n".join(lines)


def _dvec(v, n, name, fill=None):
    """Contiguous float64 copy of n values (a scalar broadcasts); None stays None."""
    if v is None:
        return None
    a = np.asarray(v, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(n, float(a))
    a = np.ascontiguousarray(a.reshape(-1))
    if a.size != n:
        raise ValueError(f"{name} has {a.size} values, expected {n}")
    return a


def _ptr(a):
    return None if a is None else a.ctypes.data_as(_lib.P_double)


# ---------------------------------------------------------------------------------------------
# the problem
# ---------------------------------------------------------------------------------------------
class OCP(Handle):
    """Discretised optimal control problem (fesd_ocp_problem) and its SQP solver.

    model: fesd.Model (dense: no sparsity); n_ctrl: control intervals N; t0 < tf; x0 (nx,);
    x0_lb, x0_ub: component i of x_0 is free in [x0_lb_i, x0_ub_i] where x0_lb_i < x0_ub_i (x0_i
    its initial guess), both or neither; x_lb, x_ub: state bounds at k = 1..N; u_lb, u_ub:
    control bounds (None or +-inf entries: none; scalars broadcast).

    Cost (any combination): lagrange(t, x, u) -> scalar, lagrange_lsq(t, x, u) -> r (L adds
    ||r||^2), mayer(x) -> scalar, mayer_lsq(x) -> r, l1(x) -> r with l1_weight (sum w_i |r_i|,
    w > 0; a scalar broadcasts). Constraints: path(t, x, u) at the boundaries k = 0..N (u_N =
    u_{N-1}) with path_lb/path_ub, terminal(x) with term_lb/term_ub (None or +-inf: one-sided;
    lb == ub: equality; the numbers of outputs are those of the bounds). Each function f has an
    optional f_jac: stage functions (t, x, u) -> (dx (n, nx), du (n, nu)) (dx alone when
    nu == 0), terminal ones (x) -> dx (n, nx); without it, central differences with
    fd_step (default FD_STEP). n_lagrange_lsq, n_mayer_lsq, n_l1: output counts, found by one
    evaluation at (t0, x0, u = 0 clamped to the bounds) when not given.

    Integrator: method ("fesd", "standard"), family, stages, n_fe (elements per interval) and
    integrator = {other fesd_settings fields by name, ncp_* for its solver} as for
    fesd.Integrator (sensitivities are always on). OCP settings (fesd_ocp_settings) as keyword
    arguments: hessian ("auto", "gauss_newton", "bfgs", "gn_sr1"), max_iter, tol_stat,
    tol_feas, tol_comp, penalty0, penalty_max, armijo, backtrack, max_backtracks, soc,
    nonmonotone, reg_primal, reg_dual, qp_tol, qp_max_iter, stall_window, qp_backend ("auto",
    "dense", "umfpack", "klu", "cholmod"), init ("simulate", "constant"), presolve,
    presolve_n_fe, verbose; log: a callable taking each log line (verbose=True without log:
    print). Values are checked by the library: an invalid one raises FesdError
    (FESD_ERR_INVALID_ARG) from the constructor; an unknown name raises TypeError.
    """

    _HANDLE, _FREE, _WHAT = "_o", "fesd_ocp_free", "OCP"

    def __init__(self, model, n_ctrl, t0, tf, x0, *, x0_lb=None, x0_ub=None, x_lb=None, x_ub=None, u_lb=None,
                 u_ub=None, lagrange=None, lagrange_jac=None, lagrange_lsq=None, lagrange_lsq_jac=None,
                 n_lagrange_lsq=None, mayer=None, mayer_jac=None, mayer_lsq=None, mayer_lsq_jac=None,
                 n_mayer_lsq=None, l1=None, l1_jac=None, l1_weight=None, n_l1=None, path=None, path_jac=None,
                 path_lb=None, path_ub=None, terminal=None, terminal_jac=None, term_lb=None, term_ub=None,
                 method="fesd", family="radau", stages=2, n_fe=2, integrator=None, fd_step=None, log=None,
                 **settings):
        if not isinstance(model, Model):
            raise TypeError("model must be a fesd.Model")
        self.model, self.nx, self.nu = model, model.nx, model.nu
        nx, nu = self.nx, self.nu
        self.N = int(n_ctrl)
        self.t0, self.tf = float(t0), float(tf)
        self.fd_step = FD_STEP if fd_step is None else float(fd_step)
        if not self.fd_step > 0:
            raise ValueError("fd_step must be positive")
        self._o = ctypes.c_void_p()
        self.failure, self.abort = None, False
        self.u_empty = np.zeros(0)
        self.u_empty.setflags(write=False)
        self.bridge = Bridge(model)
        ms, keep = build_model_struct(model, self.bridge)
        self._mstruct = ms
        keep.append(ms)

        # ---- arrays (copied by fesd_ocp_create; kept here for the guesses) ----
        arr = {}
        arr["x0"] = _dvec(x0, nx, "x0")
        if (x0_lb is None) != (x0_ub is None):
            raise ValueError("give both x0_lb and x0_ub (free components of x0) or neither")
        for name, v, n in (("x0_lb", x0_lb, nx), ("x0_ub", x0_ub, nx), ("x_lb", x_lb, nx), ("x_ub", x_ub, nx),
                           ("u_lb", u_lb, nu), ("u_ub", u_ub, nu)):
            arr[name] = _dvec(v, n, name)
        for f, nm in ((lagrange, "lagrange"), (lagrange_lsq, "lagrange_lsq"), (mayer, "mayer"),
                      (mayer_lsq, "mayer_lsq"), (l1, "l1"), (path, "path"), (terminal, "terminal"),
                      (lagrange_jac, "lagrange_jac"), (lagrange_lsq_jac, "lagrange_lsq_jac"),
                      (mayer_jac, "mayer_jac"), (mayer_lsq_jac, "mayer_lsq_jac"), (l1_jac, "l1_jac"),
                      (path_jac, "path_jac"), (terminal_jac, "terminal_jac"), (log, "log")):
            if f is not None and not callable(f):
                raise TypeError(f"{nm}= must be callable")
        for f, j, nm in ((lagrange, lagrange_jac, "lagrange"), (lagrange_lsq, lagrange_lsq_jac, "lagrange_lsq"),
                         (mayer, mayer_jac, "mayer"), (mayer_lsq, mayer_lsq_jac, "mayer_lsq"), (l1, l1_jac, "l1"),
                         (path, path_jac, "path"), (terminal, terminal_jac, "terminal")):
            if j is not None and f is None:
                raise ValueError(f"{nm}_jac= without {nm}=")

        # output counts: given, from the bounds / weights, or by one evaluation
        u_probe = np.zeros(nu)
        if arr["u_lb"] is not None:
            u_probe = np.maximum(u_probe, arr["u_lb"])
        if arr["u_ub"] is not None:
            u_probe = np.minimum(u_probe, arr["u_ub"])
        x_probe = arr["x0"].copy()
        x_probe.setflags(write=False)
        u_probe.setflags(write=False)

        def count(fun, term, given, name):
            if given is not None:
                return int(given)
            v = np.asarray(fun(x_probe) if term else fun(self.t0, x_probe, u_probe), dtype=float)
            return int(v.size)

        n_lsq_l = count(lagrange_lsq, False, n_lagrange_lsq, "lagrange_lsq") if lagrange_lsq is not None else 0
        n_lsq_m = count(mayer_lsq, True, n_mayer_lsq, "mayer_lsq") if mayer_lsq is not None else 0
        if l1 is not None:
            if l1_weight is None:
                raise ValueError("l1= needs l1_weight=")
            w = np.asarray(l1_weight, dtype=float)
            nl1 = int(n_l1) if n_l1 is not None else (int(w.size) if w.ndim > 0 else count(l1, True, None, "l1"))
            arr["l1_weight"] = _dvec(w, nl1, "l1_weight")
        else:
            if l1_weight is not None:
                raise ValueError("l1_weight= without l1=")
            nl1 = 0

        def nbounds(fun, lb, ub, name):
            if fun is None:
                if lb is not None or ub is not None:
                    raise ValueError(f"{name} bounds without the {name} function")
                return 0, None, None
            if lb is None and ub is None:
                raise ValueError(f"{name}= needs its bounds ({name}_lb and/or {name}_ub)")
            n = np.asarray(lb if lb is not None else ub).size
            return n, _dvec(lb, n, name + "_lb"), _dvec(ub, n, name + "_ub")

        n_path, arr["path_lb"], arr["path_ub"] = nbounds(path, path_lb, path_ub, "path")
        n_term, arr["term_lb"], arr["term_ub"] = nbounds(terminal, term_lb, term_ub, "term")
        self.n_path, self.n_term, self.n_l1 = n_path, n_term, nl1
        self.n_lagrange_lsq, self.n_mayer_lsq = n_lsq_l, n_lsq_m
        self._arr = arr

        # ---- trampolines ----
        self.fns = {}
        for role, fun, jac, n, term in (("lagrange", lagrange, lagrange_jac, 1, False),
                                        ("lagrange_lsq", lagrange_lsq, lagrange_lsq_jac, n_lsq_l, False),
                                        ("mayer", mayer, mayer_jac, 1, True),
                                        ("mayer_lsq", mayer_lsq, mayer_lsq_jac, n_lsq_m, True),
                                        ("l1", l1, l1_jac, nl1, True),
                                        ("path", path, path_jac, n_path, False),
                                        ("terminal", terminal, terminal_jac, n_term, True)):
            if fun is not None:
                self.fns[role] = _Fn(self, role, fun, jac, n, term)

        p = _lib.OcpProblem()
        p.model = ctypes.pointer(ms)
        p.n_ctrl, p.t0, p.tf = self.N, self.t0, self.tf
        for name in ("x0", "x0_lb", "x0_ub", "x_lb", "x_ub", "u_lb", "u_ub", "path_lb", "path_ub", "term_lb",
                     "term_ub"):
            setattr(p, name, _ptr(arr[name]))
        p.l1_weight = _ptr(arr.get("l1_weight"))
        c = {r: f.c for r, f in self.fns.items()}
        p.lagrange = c.get("lagrange", _lib.OCP_FN())
        p.n_lagrange_lsq, p.lagrange_lsq = n_lsq_l, c.get("lagrange_lsq", _lib.OCP_FN())
        p.mayer = c.get("mayer", _lib.OCP_FN())
        p.n_mayer_lsq, p.mayer_lsq = n_lsq_m, c.get("mayer_lsq", _lib.OCP_FN())
        p.n_l1, p.l1 = nl1, c.get("l1", _lib.OCP_FN())
        p.n_path, p.path = n_path, c.get("path", _lib.OCP_FN())
        p.n_term, p.terminal = n_term, c.get("terminal", _lib.OCP_FN())
        self._problem = p

        # ---- settings ----
        s = _lib.OcpSettings()
        _lib.lib.fesd_ocp_settings_default(_byref(s))
        fill_settings(s.integrator, method, family, stages, n_fe, True, dict(integrator or {}))
        self.method, self.family, self.stages, self.n_fe = method, family, stages, n_fe
        fields = dict(_lib.OcpSettings._fields_)
        for k, v in settings.items():
            if k not in fields or k in ("integrator", "log", "log_user"):
                raise TypeError(f"unknown OCP setting {k!r}" + (
                    " (integrator settings go in integrator={...})" if k in dict(_lib.Settings._fields_) else ""))
            if k in _ENUMS and isinstance(v, str):
                v = _ENUMS[k].get(v.lower(), -1)  # an unknown name: out of range, refused by the library
            if fields[k] is ctypes.c_int:
                if isinstance(v, float) and v.is_integer():
                    v = int(v)
                if not isinstance(v, (int, np.integer)):
                    raise TypeError(f"OCP setting {k!r} takes an integer (or a name), not {v!r}")
                v = min(max(int(v), _INT_MIN), _INT_MAX)  # beyond int: out of every range
            else:
                v = float(v)
            setattr(s, k, v)
        self._log_fn = log if log is not None else (print if s.verbose == 1 else None)
        if self._log_fn is not None:
            self._c_log = _lib.OCP_LOG_FN(self._log)
            s.log = self._c_log
        self.settings = s
        self._keep = keep
        self._info = _lib.OcpInfo()
        st = _lib.lib.fesd_ocp_create(_byref(self._o), _byref(p), _byref(s))
        if st != _lib.FESD_OK:
            self._raise(st, "fesd_ocp_create")
        nv, ne, ni = ctypes.c_int(), ctypes.c_int(), ctypes.c_int()
        _lib.lib.fesd_ocp_dims(self._o, _byref(nv), _byref(ne), _byref(ni))
        self.n_var, self.n_eq, self.n_ineq = nv.value, ne.value, ni.value

    # ---- failures ----
    def _log(self, user, msg):
        try:
            self._log_fn(msg.decode(errors="replace"))
        except BaseException as e:  # noqa: B902 - a log sink must not unwind through C
            if self.failure is None:
                self.failure = Failure("log", None, None, math.nan, np.zeros(0), e)

    def _fail(self, role, t, x, exc):
        if self.failure is None or (isinstance(self.failure.exc, FloatingPointError)
                                    and not isinstance(exc, FloatingPointError)):  # a raise beats a NaN
            self.failure = Failure(role, None, None, t, _frombuffer(_string_at(x, 8 * self.nx)).copy(), exc)
        if isinstance(exc, (KeyboardInterrupt, SystemExit)):
            self.abort = True  # every later callback fails at once: the solve ends soon
        return 1

    def _reset(self):
        self.failure, self.abort = None, False
        self.bridge.reset()

    def _first_failure(self):
        """The OCP functions' failure or the model's (Bridge), whichever the library met (the
        model's when both: a failed integration ends the evaluation before the functions)."""
        return self.failure if self.failure is not None else self.bridge.failure

    def _raise(self, st, what, result=None, failure=None):
        f = failure if failure is not None else self._first_failure()
        name, text = _lib.status_name(st), _lib.status_string(st)
        if f is not None:
            if isinstance(f.exc, (KeyboardInterrupt, SystemExit)):
                raise f.exc
            err = CallbackError(st, name, text, f"{what}; {f.describe()}", f.role, f.sys, f.mode, f.t)
            err.result = result
            raise err from f.exc
        err = FesdError(st, name, text, what)
        err.result = result
        raise err

    # ---- problem data ----
    def set_guess(self, x=None, u=None):
        """Initial guess of the next solve (fesd_ocp_set_guess): states x (N+1, nx) and/or
        controls u (N, nu); None: from settings init (states) and zero controls."""
        xa = None if x is None else np.ascontiguousarray(x, dtype=np.float64).reshape(-1)
        ua = None if u is None else np.ascontiguousarray(u, dtype=np.float64).reshape(-1)
        if xa is not None and xa.size != (self.N + 1) * self.nx:
            raise ValueError(f"x guess has {xa.size} values, expected (N+1) * nx = {(self.N + 1) * self.nx}")
        if ua is not None and ua.size != self.N * self.nu:
            raise ValueError(f"u guess has {ua.size} values, expected N * nu = {self.N * self.nu}")
        self._reset()
        st = _lib.lib.fesd_ocp_set_guess(self._ptr(), _ptr(xa), _ptr(ua))
        if st < 0:
            self._raise(st, "fesd_ocp_set_guess")

    def set_x0(self, x0):
        """Replace the initial state (fesd_ocp_set_x0); the guess is kept."""
        xa = _dvec(x0, self.nx, "x0")
        st = _lib.lib.fesd_ocp_set_x0(self._ptr(), _ptr(xa))
        if st < 0:
            self._raise(st, "fesd_ocp_set_x0")

    def dims(self):
        """(variables, equality constraints, inequality constraints) of the NLP."""
        return self.n_var, self.n_eq, self.n_ineq

    @property
    def t_grid(self):
        return self.t0 + (self.tf - self.t0) * np.arange(self.N + 1) / self.N

    # ---- solving ----
    def solve(self, x_guess=None, u_guess=None, *, intervals=True):
        """Solve (fesd_ocp_solve) and return an OcpResult with the best iterate whatever the
        status. x_guess / u_guess: passed to set_guess first (without either, the solve starts
        from the last solution, the first one from settings init). intervals: re-simulate every
        interval of the result for its elements and switches (N more integrations).

        Raises CallbackError (its .result holds the OcpResult) when a Python callable of the
        model or of the OCP failed and the solve stopped with FESD_ERR_CALLBACK /
        FESD_ERR_NONFINITE; FesdError for those statuses without a Python failure.
        KeyboardInterrupt in a callable ends the solve (every later call fails) and is
        re-raised. A failure the library recovered from (a rejected trial point) leaves the
        status as it is: a RuntimeWarning and result.callback_failure say so."""
        if x_guess is not None or u_guess is not None:
            self.set_guess(x_guess, u_guess)
        self._reset()
        info = self._info
        st = _lib.lib.fesd_ocp_solve(self._ptr(), _byref(info))
        failure = self._first_failure()
        if failure is not None and isinstance(failure.exc, (KeyboardInterrupt, SystemExit)):
            raise failure.exc
        res = self._result(st, info, intervals and st not in (_lib.FESD_ERR_CALLBACK, _lib.FESD_ERR_NONFINITE))
        raised = failure is not None and not isinstance(failure.exc, FloatingPointError)
        res.callback_failure = failure.describe() if raised else None
        if st in (_lib.FESD_ERR_CALLBACK, _lib.FESD_ERR_NONFINITE):
            self._raise(st, "fesd_ocp_solve", res, failure)
        # NaN / Inf met at a rejected point (the integrator's Newton line search may evaluate the
        # model at a non-finite iterate) is the library's business, as for fesd.Integrator
        if raised:
            warnings.warn(f"fesd_ocp_solve ended with {res.status_name} although {failure.describe()} "
                          "(the library rejected that point)", RuntimeWarning, stacklevel=2)
        return res

    def solution(self):
        """(x (N+1, nx), u (N, nu)) of the returned iterate."""
        x, u = np.empty((self.N + 1, self.nx)), np.empty((self.N, max(self.nu, 0)))
        st = _lib.lib.fesd_ocp_get_solution(self._ptr(), _ptr(x), _ptr(u) if self.nu else None)
        if st < 0:
            self._raise(st, "fesd_ocp_get_solution")
        return x, u

    def multipliers(self):
        """OcpMultipliers of the returned iterate (copies)."""
        m = _lib.OcpMultipliers()
        st = _lib.lib.fesd_ocp_get_multipliers(self._ptr(), _byref(m))
        if st < 0:
            self._raise(st, "fesd_ocp_get_multipliers")
        N, nx, nu = self.N, self.nx, self.nu

        def arr(p, shape):
            size = int(np.prod(shape))
            return np.ctypeslib.as_array(p, shape=(size,)).copy().reshape(shape) if size > 0 and p else np.zeros(shape)
        return OcpMultipliers(arr(m.dynamics, (N, nx)), arr(m.x0, (nx,)), arr(m.x_bound, (N + 1, nx)),
                              arr(m.u_bound, (N, nu)), arr(m.path, (N + 1, self.n_path)),
                              arr(m.terminal, (self.n_term,)), arr(m.l1, (self.n_l1,)))

    def interval(self, k):
        """Interval k of the returned iterate re-simulated (fesd_ocp_interval): an OcpInterval."""
        if not 0 <= k < self.N:
            raise IndexError(f"interval {k} outside 0..{self.N - 1}")
        d = _lib.StepData()
        p, n = ctypes.POINTER(_lib.EventStruct)(), ctypes.c_int()
        self._reset()
        st = _lib.lib.fesd_ocp_interval(self._ptr(), int(k), _byref(d), _byref(p), _byref(n))
        if st < 0:
            self._raise(st, f"fesd_ocp_interval({k})")
        events = _events(p, n.value)
        has_cost = "lagrange" in self.fns or "lagrange_lsq" in self.fns
        h, t, x, th, la, mu = step_data(d, self.model, 1 if has_cost else 0)
        cost = x[:, self.nx].copy() if has_cost else None
        return OcpInterval(int(k), h, t, x[:, : self.nx].copy(), cost, th, la, mu, events)

    def _result(self, st, info, intervals):
        d = _lib.struct_dict(info)
        x, u = self.solution()
        res = OcpResult(status=st, status_name=_lib.status_name(st), message=_lib.status_string(st),
                        success=st == _lib.FESD_OK, t=self.t_grid, x=x, u=u, info=d)
        for k in ("objective", "stationarity", "stationarity_rel", "feasibility", "complementarity",
                  "min_multiplier", "iterations", "integrations", "time_total", "time_integration", "time_qp",
                  "time_other", "stall_interval", "presolve_run", "presolve_iterations", "presolve_used"):
            res[k] = d[k]
        res.stalled = bool(d["stalled"])
        res.presolve_run, res.presolve_used = bool(d["presolve_run"]), bool(d["presolve_used"])
        res.presolve_status = _lib.status_name(d["presolve_status"])
        res.multipliers = self.multipliers()
        res.intervals = None
        if intervals:
            out = []
            for k in range(self.N):
                try:
                    out.append(self.interval(k))
                except FesdError:
                    out.append(None)
            res.intervals = out
        return res


__all__ = ["OCP", "OcpResult", "OcpMultipliers", "OcpInterval", "FD_STEP", "HESSIANS", "INITS", "QP_BACKENDS"]
