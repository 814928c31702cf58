"""The C callbacks of a model: ctypes trampolines that call the Python callables, check their
outputs and copy them into the library's buffers.

A trampoline never lets an exception reach ctypes: a callable that raises or returns an array
of the wrong shape makes it return 1 (the library then fails the step with FESD_ERR_CALLBACK);
a NaN or Inf is written through (the library reports FESD_ERR_NONFINITE, or recovers by a
shorter step). Either way the first failure since the last reset() is kept in .failure for the
exception the caller raises (a raised exception replaces a non-finite value seen before it).

Vectorised fields (Subsystem.fields, fields_jac) are evaluated once per point and subsystem:
the results are kept in a small first-in-first-out cache keyed by (t, x, u), large enough for
the library's central differences (which visit x +- h e_j for every mode in turn).

Hot path: pointers arrive as ints, x and u are read with one string_at each (also the cache
key), outputs leave as bytes (ndarray.tobytes, C order) through memmove; the finiteness check is
a sum over a memoryview (finite iff the sum is, up to overflow, which falls back to numpy).
"""
import ctypes
import math

import numpy as np

from . import _lib
from .errors import NonFiniteOutputError, OutputShapeError

_memmove, _string_at, _isfinite = ctypes.memmove, ctypes.string_at, math.isfinite
_asarray, _frombuffer, _f64 = np.asarray, np.frombuffer, np.float64


class Failure:
    """The first failure of a callable since the last reset."""

    def __init__(self, role, sys, mode, t, x, exc):
        self.role, self.sys, self.mode, self.t, self.x, self.exc = role, sys, mode, t, x, exc

    def where(self):
        s = f"callback {self.role!r}"
        if self.sys is not None:
            s += f" of subsystem {self.sys}"
        if self.mode is not None:
            s += f" (mode {self.mode})"
        return s + f" at t = {self.t!r}"

    def describe(self):
        e = self.exc
        return f"{self.where()}: {type(e).__name__}: {e}"


def _out(res, shape, role, transpose=None):
    """Bytes (C order) of a float64 array of exactly `shape`; a 1-D shape also takes a scalar
    (n = 1) or any array of that many entries with at most one dimension. transpose: axes
    permutation applied before (column-major Jacobians)."""
    a = _asarray(res, dtype=_f64)
    if a.shape != shape:
        if len(shape) == 1 and a.ndim <= 1 and a.size == shape[0]:
            a = a.reshape(shape)
        else:
            raise OutputShapeError(f"{role} returned shape {a.shape}, expected {shape}")
    return (a if transpose is None else a.transpose(transpose)).tobytes()


def _finite(buf):
    if _isfinite(sum(memoryview(buf).cast("d"))):
        return True
    return bool(np.isfinite(_frombuffer(buf)).all())  # the sum overflowed, or a NaN/Inf


def _pair(res, role, nu):
    """(d/dx, d/du) from a Jacobian callable's result: an array, or a pair when nu > 0."""
    if isinstance(res, tuple):
        if len(res) != 2:
            raise OutputShapeError(f"{role} returned a tuple of {len(res)}, expected (d/dx, d/du)")
        return res
    if nu > 0:
        raise OutputShapeError(f"{role} must return (d/dx, d/du) since the model has nu = {nu} > 0")
    return res, None


class _Fifo(dict):
    """Results keyed by the point; the oldest entries dropped beyond cap."""
    __slots__ = ("cap",)

    def __init__(self, cap):
        super().__init__()
        self.cap = cap

    def put(self, key, val):
        self[key] = val
        if len(self) > self.cap:
            del self[next(iter(self))]


class Bridge:
    """ctypes callbacks for one integrator: model (fesd.Model), events: stop conditions."""

    def __init__(self, model, events=()):
        self.model, self.events = model, list(events)
        self.subs = model.subsystems
        self.nx, self.nu = model.nx, model.nu
        self.nbx, self.nbu = 8 * model.nx, 8 * model.nu
        self.failure = None
        self.abort = False  # set by a KeyboardInterrupt / SystemExit: later calls fail at once
        self.nonfinite_seen = 0
        cap = 2 * (model.nx + model.nu) + 2
        subs = self.subs
        self.fcache = [_Fifo(cap) for _ in subs]
        self.jcache = [_Fifo(2) for _ in subs]
        self.scache = [_Fifo(cap) for _ in subs]
        self.rcache = _Fifo(cap)
        self.c_field = _lib.FIELD_FN(self._field)
        self.c_field_jac = _lib.FIELD_JAC_FN(self._field_jac) if all(
            s.fields_jac is not None or s.field_jac is not None for s in subs) else _lib.FIELD_JAC_FN()
        self.c_sw = _lib.SWITCH_FN(self._switch)
        self.c_sw_jac = _lib.SWITCH_JAC_FN(self._switch_jac) if all(
            s.switch_jac is not None for s in subs) else _lib.SWITCH_JAC_FN()
        self.c_drift = _lib.DRIFT_FN(self._drift) if model.drift is not None else _lib.DRIFT_FN()
        self.c_drift_jac = _lib.DRIFT_JAC_FN(self._drift_jac) if model.drift_jac is not None else _lib.DRIFT_JAC_FN()
        self.c_roots = _lib.ROOT_FN(self._roots) if self.events else _lib.ROOT_FN()
        self._u_empty = np.zeros(0)
        self._u_empty.setflags(write=False)

    # ---- bookkeeping ----
    def reset(self):
        self.failure, self.abort = None, False
        for c in self.fcache + self.jcache + self.scache:
            c.clear()
        self.rcache.clear()

    def _fail(self, role, sys, mode, t, x, exc):
        if self.failure is None or (isinstance(self.failure.exc, FloatingPointError)
                                    and not isinstance(exc, FloatingPointError)):  # a raise beats a NaN
            self.failure = Failure(role, sys, mode, t, _frombuffer(_string_at(x, self.nbx)).copy(), exc)
        if isinstance(exc, (KeyboardInterrupt, SystemExit)):
            self.abort = True  # a long library call (an OCP solve) then ends soon
        return 1

    def _nonfinite(self, role, sys, mode, t, x):
        """NaN/Inf are written through (the library decides); the first one is remembered."""
        self.nonfinite_seen += 1
        if self.failure is None:
            self._fail(role, sys, mode, t, x, NonFiniteOutputError(f"{role} returned a non-finite value"))

    def _key(self, t, x, u):
        return (t, _string_at(x, self.nbx), _string_at(u, self.nbu) if self.nbu else b"")

    def _args(self, key):
        return key[0], _frombuffer(key[1]), _frombuffer(key[2]) if self.nbu else self._u_empty

    # ---- fields ----
    def _field(self, sys, mode, t, x, u, f, user):
        if self.abort:
            return 1
        try:
            sub, nb = self.subs[sys], self.nbx
            if sub.fields is not None:
                key = self._key(t, x, u)
                cache = self.fcache[sys]
                buf = cache.get(key)
                if buf is None:
                    buf = _out(sub.fields(*self._args(key)), (sub.n_modes, self.nx), "fields")
                    if not _finite(buf):
                        self._nonfinite("fields", sys, None, t, x)
                    cache.put(key, buf)
                _memmove(f, buf[mode * nb:(mode + 1) * nb], nb)
            else:
                buf = _out(sub.field(mode, *self._args(self._key(t, x, u))), (self.nx,), "field")
                if not _finite(buf):
                    self._nonfinite("field", sys, mode, t, x)
                _memmove(f, buf, nb)
            return 0
        except BaseException as e:  # noqa: B902 - reported by the caller after the C call
            vec = self.subs[sys].fields is not None  # one call for all modes: no mode to name
            return self._fail("fields" if vec else "field", sys, None if vec else mode, t, x, e)

    def _jac(self, res, role, lead, transpose, sys, mode, t, x):
        """A Jacobian callback's result as C-order buffers (d/dx of shape lead + (nx,), d/du of
        lead + (nu,)), checked finite."""
        dx, du = _pair(res, role, self.nu)
        bx = _out(dx, lead + (self.nx,), role, transpose)
        bu = _out(du, lead + (self.nu,), role + " (d/du)", transpose) if self.nu else b""
        if not (_finite(bx) and _finite(bu)):
            self._nonfinite(role, sys, mode, t, x)
        return bx, bu

    def _put_jac(self, dx_ptr, du_ptr, bx, bu):
        _memmove(dx_ptr, bx, len(bx))
        if du_ptr and self.nu:
            _memmove(du_ptr, bu, len(bu))

    def _field_jac(self, sys, mode, t, x, u, dfdx, dfdu, user):
        try:
            sub, nx, nu = self.subs[sys], self.nx, self.nu
            nbx, nbu = 8 * nx * nx, 8 * nx * nu
            if sub.fields_jac is not None:
                key = self._key(t, x, u)
                cache = self.jcache[sys]
                hit = cache.get(key)
                if hit is None:
                    hit = self._jac(sub.fields_jac(*self._args(key)), "fields_jac", (sub.n_modes, nx), (0, 2, 1),
                                    sys, None, t, x)
                    cache.put(key, hit)
                self._put_jac(dfdx, dfdu, hit[0][mode * nbx:(mode + 1) * nbx], hit[1][mode * nbu:(mode + 1) * nbu])
            else:
                res = sub.field_jac(mode, *self._args(self._key(t, x, u)))
                self._put_jac(dfdx, dfdu, *self._jac(res, "field_jac", (nx,), (1, 0), sys, mode, t, x))
            return 0
        except BaseException as e:  # noqa: B902
            vec = self.subs[sys].fields_jac is not None
            return self._fail("fields_jac" if vec else "field_jac", sys, None if vec else mode, t, x, e)

    # ---- switching functions / indicators ----
    def _switch(self, sys, t, x, u, c, user):
        if self.abort:
            return 1
        try:
            sub = self.subs[sys]
            key = self._key(t, x, u)
            cache = self.scache[sys]
            buf = cache.get(key)
            if buf is None:
                role = "switch" if sub.switch is not None else "indicators"
                buf = _out(sub.region_fn(*self._args(key)), (sub.n_rows,), role)
                if not _finite(buf):
                    self._nonfinite(role, sys, None, t, x)
                cache.put(key, buf)
            _memmove(c, buf, len(buf))
            return 0
        except BaseException as e:  # noqa: B902
            return self._fail("switch" if self.subs[sys].switch is not None else "indicators", sys, None, t, x, e)

    def _switch_jac(self, sys, t, x, u, dcdx, dcdu, user):
        try:
            sub = self.subs[sys]
            res = sub.switch_jac(*self._args(self._key(t, x, u)))
            self._put_jac(dcdx, dcdu, *self._jac(res, "switch_jac", (sub.n_rows,), (1, 0), sys, None, t, x))
            return 0
        except BaseException as e:  # noqa: B902
            return self._fail("switch_jac", sys, None, t, x, e)

    # ---- drift and stop conditions ----
    def _drift(self, t, x, u, f, user):
        try:
            buf = _out(self.model.drift(*self._args(self._key(t, x, u))), (self.nx,), "drift")
            if not _finite(buf):
                self._nonfinite("drift", None, None, t, x)
            _memmove(f, buf, self.nbx)
            return 0
        except BaseException as e:  # noqa: B902
            return self._fail("drift", None, None, t, x, e)

    def _drift_jac(self, t, x, u, dfdx, dfdu, user):
        try:
            res = self.model.drift_jac(*self._args(self._key(t, x, u)))
            self._put_jac(dfdx, dfdu, *self._jac(res, "drift_jac", (self.nx,), (1, 0), None, None, t, x))
            return 0
        except BaseException as e:  # noqa: B902
            return self._fail("drift_jac", None, None, t, x, e)

    def _roots(self, t, x, u, r, user):
        """All stop conditions at once (the library asks once per condition: cached)."""
        try:
            key = self._key(t, x, u)
            buf = self.rcache.get(key)
            if buf is None:
                args = self._args(key)
                vals = []
                for i, ev in enumerate(self.events):
                    v = _asarray(ev(*args), dtype=_f64)
                    if v.size != 1:
                        raise OutputShapeError(f"event {i} returned shape {v.shape}, expected a scalar")
                    vals.append(float(v.reshape(())))
                buf = np.array(vals).tobytes()
                if not _finite(buf):
                    self._nonfinite("events", None, None, t, x)
                self.rcache.put(key, buf)
            _memmove(r, buf, len(buf))
            return 0
        except BaseException as e:  # noqa: B902
            return self._fail("events", None, None, t, x, e)
