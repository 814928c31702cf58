"""fesd.Integrator: one libfesd integrator object (fesd_create ... fesd_free) with a Python
model. Thin: every method is one library call, results as numpy arrays and plain objects."""
import ctypes
import warnings
from dataclasses import dataclass

import numpy as np

from . import _lib
from ._callbacks import Bridge
from ._common import Handle
from .errors import CallbackError, FesdError
from .model import Model, event_direction

_byref = ctypes.byref


@dataclass(frozen=True)
class SwitchEvent:
    """A switch at an element boundary (fesd_event): kind is "crossing", "sliding_entry",
    "sliding_exit" or "root" (a stop condition; sys is then its index and before/after are
    (1,) -> (0,) when it increases through 0, (0,) -> (1,) when it decreases)."""
    t: float
    sys: int
    kind: str
    before: tuple
    after: tuple


@dataclass
class StepData:
    """Elements of the last accepted step (fesd_last_step_data), copied: h (n,), t (n+1,),
    x (n+1, nx), theta and lambda_ (n, s, n_theta), mu (n, s, nsys_internal)."""
    h: np.ndarray
    t: np.ndarray
    x: np.ndarray
    theta: np.ndarray
    lambda_: np.ndarray
    mu: np.ndarray


def _events(ptr, n):
    out = []
    for e in range(n):
        ev = ptr[e]
        out.append(SwitchEvent(ev.t, ev.sys, _lib.EVENT_KINDS[ev.kind], tuple(ev.before[i] for i in range(ev.n_before)),
                               tuple(ev.after[i] for i in range(ev.n_after))))
    return out


def _dptr(a):
    return a.ctypes.data_as(_lib.P_double)


def fill_settings(s, method, family, stages, n_fe, sensitivities, settings):
    """Fill a fesd_settings struct (defaults already in it): method, family, stages, n_fe,
    sensitivities and any other field by name (ncp_* for the solver's). Unknown names raise
    TypeError, unknown method/family ValueError; values are checked by the library."""
    if method not in _lib.METHODS:
        raise ValueError(f"method must be one of {sorted(_lib.METHODS)}")
    if family not in _lib.FAMILIES:
        raise ValueError(f"family must be one of {sorted(_lib.FAMILIES)}")
    s.method, s.family, s.stages, s.n_fe = _lib.METHODS[method], _lib.FAMILIES[family], stages, n_fe
    s.sensitivities = 1 if sensitivities else 0
    for k, v in settings.items():
        target, name = (s.ncp, k[4:]) if k.startswith("ncp_") else (s, k)
        if name not in dict(type(target)._fields_) or name in ("ncp", "log", "log_user"):
            raise TypeError(f"unknown setting {k!r}")
        setattr(target, name, v)
    return s


def build_model_struct(m, b, events=()):
    """The fesd_model struct of a fesd.Model with the callbacks of its Bridge b; returns
    (struct, keep): keep holds the arrays the struct points to (keep them alive with it)."""
    nsys = m.nsys
    n_modes = (ctypes.c_int * nsys)(*[s.n_modes for s in m.subsystems])
    n_switch = (ctypes.c_int * nsys)(*[s.n_switch for s in m.subsystems])
    keep = [n_modes, n_switch]
    sign_ptr = None
    if any(s.sign is not None for s in m.subsystems):
        PB = ctypes.POINTER(ctypes.c_byte)
        arr = (PB * nsys)()
        for k, s in enumerate(m.subsystems):
            if s.sign is not None:
                buf = (ctypes.c_byte * s.sign.size)(*s.sign.ravel().tolist())
                keep.append(buf)
                arr[k] = ctypes.cast(buf, PB)
        keep.append(arr)
        sign_ptr = arr
    ms = _lib.ModelStruct()
    ms.nx, ms.nu, ms.nsys = m.nx, m.nu, nsys
    ms.n_modes = ctypes.cast(n_modes, _lib.P_int)
    ms.n_switch = ctypes.cast(n_switch, _lib.P_int)
    if sign_ptr is not None:
        ms.sign = ctypes.cast(sign_ptr, type(ms.sign))
    ms.field, ms.field_jac, ms.sw, ms.sw_jac = b.c_field, b.c_field_jac, b.c_sw, b.c_sw_jac
    ms.time_dependent = 1 if m.time_dependent else 0
    ms.drift, ms.drift_jac = b.c_drift, b.c_drift_jac
    if events:
        dirs = (ctypes.c_int * len(events))(*[event_direction(e) for e in events])
        keep.append(dirs)
        ms.n_roots, ms.roots, ms.root_dir = len(events), b.c_roots, ctypes.cast(dirs, _lib.P_int)
    return ms, keep


def step_data(d, model, n_extra=0):
    """Copies of a fesd_step_data's arrays for a fesd.Model: (h, t, x, theta, lambda_, mu) with
    x's first model.nx + n_extra internal states (n_extra = 1: the OCP's cost state), theta and
    lambda_ of the user's modes, mu of the user's subsystems."""
    n, s, nth = d.n_elements, d.stages, d.n_theta
    nsys_int = d.n_sys  # stride of mu: the user's subsystems first, then the drift / clock / stops
    n_user = sum(sub.n_modes for sub in model.subsystems)

    def arr(p, size):
        return np.ctypeslib.as_array(p, shape=(size,)).copy() if size > 0 and p else np.zeros(0)
    x = arr(d.x, (n + 1) * d.nx).reshape(n + 1, d.nx)[:, : model.nx + n_extra]
    th = arr(d.theta, n * s * nth).reshape(n, s, nth)[:, :, :n_user]
    la = arr(d.lambda_, n * s * nth).reshape(n, s, nth)[:, :, :n_user]
    mu = arr(d.mu, n * s * nsys_int).reshape(n, s, nsys_int)[:, :, : model.nsys]
    return arr(d.h, n), arr(d.t, n + 1), x, th, la, mu


class Integrator(Handle):
    """A FESD (or standard time-stepping) integrator for a fesd.Model.

    method: "fesd" or "standard"; family: "radau", "gauss", "lobatto3a", "lobatto3c", "explicit";
    stages, n_fe: RK stages and finite elements per step; sensitivities: propagate dx/dx0 and
    dx/du; events: stop conditions r(t, x, u) (callables; .direction as in scipy; the library
    stops fesd_integrate where one crosses zero in its direction); settings: any other field of
    fesd_settings by name (newton_tol, max_iter, cc_tol, active_tol, exit_rows, max_splits, ...),
    ncp_* for the solver's (e.g. ncp_backend=3 for KLU).
    """

    _HANDLE, _FREE, _WHAT = "_it", "fesd_free", "integrator"

    def __init__(self, model, *, method="fesd", family="radau", stages=2, n_fe=2, sensitivities=False,
                 events=None, **settings):
        if not isinstance(model, Model):
            raise TypeError("model must be a fesd.Model")
        self.model = model
        self.events = list(events or [])
        for ev in self.events:
            if not callable(ev):
                raise TypeError("events must be callables r(t, x, u)")
        self.nx, self.nu = model.nx, model.nu
        self._it = ctypes.c_void_p()
        self.bridge = Bridge(model, self.events)
        s = _lib.Settings()
        _lib.lib.fesd_settings_default(_byref(s))
        fill_settings(s, method, family, stages, n_fe, sensitivities, settings)
        self.settings = s
        self.method, self.family, self.stages, self.n_fe = method, family, stages, n_fe
        self.sensitivities_on = bool(sensitivities)
        self._keep = self._build_model()
        st = _lib.lib.fesd_create(_byref(self._it), _byref(self._mstruct), _byref(s))
        if st != _lib.FESD_OK:
            raise FesdError(st, _lib.status_name(st), _lib.status_string(st), "fesd_create")
        self._x = np.zeros(self.nx)
        self._t = ctypes.c_double()
        self._u0 = np.zeros(max(self.nu, 1))
        self._sinfo = _lib.StepInfo()
        self._iinfo = _lib.IntegrateInfo()

    def _build_model(self):
        self._mstruct, keep = build_model_struct(self.model, self.bridge, self.events)
        return keep

    # ---- errors ----
    def _u(self, u):
        if self.nu == 0:
            return None, None
        if u is None:
            raise ValueError(f"the model has nu = {self.nu}: u is required")
        ua = np.ascontiguousarray(u, dtype=np.float64).reshape(-1)
        if ua.size != self.nu:
            raise ValueError(f"u has {ua.size} values, expected {self.nu}")
        return ua, _dptr(ua)

    def _raise(self, st, what, failed_callback=None, failed_time=None):
        """Raise for a negative status; a callback failure becomes CallbackError (from the
        Python exception)."""
        f = self.bridge.failure
        name, text = _lib.status_name(st), _lib.status_string(st)
        lib_part = f"{what}"
        if failed_callback:
            lib_part += f"; the library names callback {failed_callback!r}"
        if failed_time is not None:
            lib_part += f", step from t = {failed_time!r}"
        if f is not None:
            if isinstance(f.exc, (KeyboardInterrupt, SystemExit)):
                raise f.exc
            err = CallbackError(st, name, text, f"{lib_part}; {f.describe()}", f.role, f.sys, f.mode, f.t)
            raise err from f.exc
        raise FesdError(st, name, text, lib_part)

    def _after(self, st, what, failed_callback=None, failed_time=None):
        f = self.bridge.failure
        if st < 0:
            self._raise(st, what, failed_callback, failed_time)
        if f is not None and not isinstance(f.exc, FloatingPointError):
            if isinstance(f.exc, (KeyboardInterrupt, SystemExit)):
                raise f.exc
            warnings.warn(f"{what} succeeded although {f.describe()} (the library did not need that value)",
                          RuntimeWarning, stacklevel=3)
        return st

    # ---- state ----
    def set_state(self, t0, x0, u=None):
        """Set time and state (resets sensitivities, the event log and the statistics)."""
        x = np.ascontiguousarray(x0, dtype=np.float64).reshape(-1)
        if x.size != self.nx:
            raise ValueError(f"x0 has {x.size} values, expected {self.nx}")
        ua, up = self._u(u)
        self.bridge.reset()
        st = _lib.lib.fesd_set_state(self._ptr(), float(t0), _dptr(x), up)
        self._after(st, "fesd_set_state")

    @property
    def t(self):
        _lib.lib.fesd_get_state(self._ptr(), _byref(self._t), None)
        return self._t.value

    @property
    def x(self):
        x = np.empty(self.nx)
        _lib.lib.fesd_get_state(self._ptr(), None, _dptr(x))
        return x

    def sensitivities(self):
        """(dx/dx0 (nx, nx), dx/du (nx, nu)) since set_state."""
        Sx, Su = np.empty(self.nx * self.nx), np.empty(max(self.nx * self.nu, 1))
        st = _lib.lib.fesd_get_sensitivities(self._ptr(), _dptr(Sx), _dptr(Su))
        if st < 0:
            self._raise(st, "fesd_get_sensitivities (create the integrator with sensitivities=True)")
        return (Sx.reshape(self.nx, self.nx, order="F"),
                Su[: self.nx * self.nu].reshape(self.nx, self.nu, order="F"))

    # ---- stepping ----
    def step(self, h, u=None):
        """One step of length h (fesd_step). Returns the step's statistics (dict of
        fesd_step_info). Raises FesdError / CallbackError on failure (state unchanged)."""
        ua, up = self._u(u)
        self.bridge.reset()
        info = self._sinfo
        st = _lib.lib.fesd_step(self._ptr(), up, float(h), _byref(info))
        fc = info.failed_callback.decode() if info.failed_callback else None
        self._after(st, "fesd_step", fc, info.failed_time if st < 0 else None)
        return _lib.struct_dict(info)

    def set_tolerances(self, rtol=1e-6, atol=1e-9, *, h_init=0.0, h_max=0.0, h_min=0.0, max_steps=100000):
        """Error control of integrate/integrate_grid; atol may be a scalar or nx values."""
        tol = _lib.Tolerances()
        _lib.lib.fesd_tolerances_default(_byref(tol))
        tol.rtol, tol.h_init, tol.h_max, tol.h_min, tol.max_steps = rtol, h_init, h_max, h_min, int(max_steps)
        av = np.asarray(atol, dtype=np.float64)
        keep = None
        if av.ndim == 0:
            tol.atol = float(av)
        else:
            keep = np.ascontiguousarray(av.reshape(-1))
            if keep.size != self.nx:
                raise ValueError(f"atol has {keep.size} values, expected {self.nx}")
            tol.atol, tol.atol_v = 0.0, _dptr(keep)
        st = _lib.lib.fesd_set_tolerances(self._ptr(), _byref(tol))
        if st < 0:
            self._raise(st, "fesd_set_tolerances")

    def integrate(self, t_out, u=None, allow=()):
        """Error-controlled steps to t_out (fesd_integrate). Returns (status, info): status 0
        (reached t_out) or 1 (FESD_ROOT: a stop condition; info["root"] its index); info: dict
        of fesd_integrate_info. Raises on failure (the state is the last accepted one) unless the
        status is in allow (then returned)."""
        ua, up = self._u(u)
        self.bridge.reset()
        info = self._iinfo
        st = _lib.lib.fesd_integrate(self._ptr(), up, float(t_out), _byref(info))
        if st not in allow:
            self._after(st, "fesd_integrate")
        return st, _lib.struct_dict(info)

    def integrate_step(self, t_out, u=None):
        """One error-controlled step towards t_out (fesd_integrate_step): (status, info) as
        integrate; info["steps"] is 1 after an accepted step."""
        ua, up = self._u(u)
        self.bridge.reset()
        info = self._iinfo
        st = _lib.lib.fesd_integrate_step(self._ptr(), up, float(t_out), _byref(info))
        self._after(st, "fesd_integrate_step")
        return st, _lib.struct_dict(info)

    def integrate_grid(self, t_out, u=None, raise_on_error=True):
        """States at increasing output times (fesd_integrate_grid): (status, x_out (n, nx) with
        the first info["n_done"] rows filled, info)."""
        ts = np.ascontiguousarray(t_out, dtype=np.float64).reshape(-1)
        xo = np.full((ts.size, self.nx), np.nan)
        ua, up = self._u(u)
        self.bridge.reset()
        info = self._iinfo
        st = _lib.lib.fesd_integrate_grid(self._ptr(), up, ts.size, _dptr(ts), _dptr(xo), _byref(info))
        if raise_on_error:
            self._after(st, "fesd_integrate_grid")
        return st, xo, _lib.struct_dict(info)

    # ---- records ----
    def last_events(self):
        """Switches of the last step (fesd_last_events), stop conditions in both directions."""
        p, n = ctypes.POINTER(_lib.EventStruct)(), ctypes.c_int()
        _lib.lib.fesd_last_events(self._ptr(), _byref(p), _byref(n))
        return _events(p, n.value)

    def event_log(self):
        """All events that integrate/integrate_grid accepted since set_state (fesd_event_log)."""
        p, n = ctypes.POINTER(_lib.EventStruct)(), ctypes.c_int()
        _lib.lib.fesd_event_log(self._ptr(), _byref(p), _byref(n))
        return _events(p, n.value)

    def last_step_data(self):
        """Element data of the last accepted step (copies)."""
        d = _lib.StepData()
        st = _lib.lib.fesd_last_step_data(self._ptr(), _byref(d))
        if st < 0:
            self._raise(st, "fesd_last_step_data")
        return StepData(*step_data(d, self.model))

    def dense_output(self, t):
        """x(t) inside the last accepted step (collocation families)."""
        x = np.empty(self.nx)
        st = _lib.lib.fesd_dense_output(self._ptr(), float(t), _dptr(x))
        if st < 0:
            self._raise(st, f"fesd_dense_output(t = {t!r})")
        return x

    def stats(self):
        """Accumulated statistics since set_state (dict of fesd_stats)."""
        s = _lib.Stats()
        _lib.lib.fesd_get_stats(self._ptr(), _byref(s))
        return _lib.struct_dict(s)

    def order(self):
        """Classical order of the tableau."""
        return _lib.lib.fesd_rk_order(_lib.FAMILIES[self.family], self.stages)
