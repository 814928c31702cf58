"""Model description in Python: subsystems of modes with their fields and switching functions
(or Stewart indicators), optional Jacobians, optional drift.

Every callable takes (t, x, u): t a float, x the state (read-only float64 array of nx values),
u the controls/parameters (nu values; an empty array when nu == 0).
"""
import math

import numpy as np


class Subsystem:
    """One Stewart subsystem (a Filippov convexification over its modes).

    Fields, one of:
      fields(t, x, u) -> array (n_modes, nx): all mode fields at once (vectorised; one Python
          call per point, the wrapper hands the rows to the library's per-mode callbacks);
      field(mode, t, x, u) -> array (nx,): one mode's field.
    Regions, one of:
      switch(t, x, u) -> array (n_switch,): switching functions c; mode i is active where the
          signs of c match row i of the sign matrix. Default sign matrix (n_modes == 2**n_switch):
          row i has -1 in column j if bit (n_switch-1-j) of i is set, else +1 (one switching
          function: mode 0 is c > 0, mode 1 is c < 0);
      indicators(t, x, u) -> array (n_modes,): Stewart indicators g directly (mode i active
          where g_i is the smallest).
    sign: optional sign matrix (n_modes x n_switch, entries +-1; nosnoc's S as it is).
    n_switch: number of switching functions (default: sign.shape[1], else log2(n_modes)).
    Jacobians (optional; central differences in the library otherwise), rows = outputs:
      fields_jac(t, x, u) -> dfdx (n_modes, nx, nx) [i.e. d f_mode[r] / d x[c] at (mode, r, c)],
          or a pair (dfdx, dfdu) with dfdu (n_modes, nx, nu) (required when nu > 0);
      field_jac(mode, t, x, u) -> dfdx (nx, nx) or (dfdx, dfdu (nx, nu));
      switch_jac(t, x, u) -> dcdx (rows, nx) or (dcdx, dcdu (rows, nu)), rows = n_switch (or
          n_modes with indicators).
    """

    def __init__(self, n_modes, *, fields=None, field=None, switch=None, indicators=None, n_switch=None,
                 sign=None, fields_jac=None, field_jac=None, switch_jac=None, name=None):
        self.n_modes = int(n_modes)
        if self.n_modes < 2:
            raise ValueError("a subsystem needs at least 2 modes")
        if (fields is None) == (field is None):
            raise ValueError("give exactly one of fields= (all modes at once) or field= (one mode)")
        if (switch is None) == (indicators is None):
            raise ValueError("give exactly one of switch= (switching functions) or indicators=")
        if fields_jac is not None and field_jac is not None:
            raise ValueError("give at most one of fields_jac= and field_jac=")
        for nm, f in (("fields", fields), ("field", field), ("switch", switch), ("indicators", indicators),
                      ("fields_jac", fields_jac), ("field_jac", field_jac), ("switch_jac", switch_jac)):
            if f is not None and not callable(f):
                raise TypeError(f"{nm}= must be callable")
        self.fields, self.field, self.fields_jac, self.field_jac = fields, field, fields_jac, field_jac
        self.switch, self.indicators, self.switch_jac = switch, indicators, switch_jac
        self.name = name
        self.sign = None
        if indicators is not None:
            if sign is not None or n_switch not in (None, 0):
                raise ValueError("indicators= takes no sign matrix or n_switch")
            self.n_switch = 0
        else:
            if sign is not None:
                S = np.asarray(sign)
                if S.ndim != 2 or S.shape[0] != self.n_modes or not np.all(np.abs(S) == 1):
                    raise ValueError(f"sign must be an n_modes x n_switch matrix of +-1 ({self.n_modes} rows)")
                if n_switch is not None and n_switch != S.shape[1]:
                    raise ValueError("n_switch differs from the sign matrix's columns")
                self.sign = S.astype(np.int8)
                self.n_switch = S.shape[1]
            elif n_switch is not None:
                self.n_switch = int(n_switch)
            else:
                k = int(round(math.log2(self.n_modes)))
                if 2 ** k != self.n_modes:
                    raise ValueError("n_modes is not a power of 2: give n_switch and sign, or indicators")
                self.n_switch = k
            if self.n_switch < 1:
                raise ValueError("n_switch must be >= 1 with switch= (use indicators= otherwise)")

    @property
    def n_rows(self):
        """Outputs of the switch callable: n_switch, or n_modes for indicators."""
        return self.n_switch if self.n_switch > 0 else self.n_modes

    @property
    def region_fn(self):
        return self.switch if self.switch is not None else self.indicators


class Model:
    """x' = f0(t,x,u) + sum_k F^k(t,x,u) theta^k with one Subsystem per k.

    nx: states; nu: controls/parameters (constant over a step); subsystems: list of Subsystem;
    drift(t, x, u) -> (nx,): optional part shared by all modes (evaluated once per point);
    drift_jac(t, x, u) -> dfdx (nx, nx) or (dfdx, dfdu);
    time_dependent: True if any callable depends on t (the library then carries t as a state so
    that the element lengths see it); with False the callables still receive t.
    """

    def __init__(self, nx, subsystems, *, nu=0, drift=None, drift_jac=None, time_dependent=False):
        self.nx, self.nu = int(nx), int(nu)
        if self.nx < 1 or self.nu < 0:
            raise ValueError("nx >= 1 and nu >= 0 required")
        if isinstance(subsystems, Subsystem):
            subsystems = [subsystems]
        self.subsystems = list(subsystems)
        if not self.subsystems or not all(isinstance(s, Subsystem) for s in self.subsystems):
            raise TypeError("subsystems must be a non-empty list of fesd.Subsystem")
        if drift_jac is not None and drift is None:
            raise ValueError("drift_jac= without drift=")
        for nm, f in (("drift", drift), ("drift_jac", drift_jac)):
            if f is not None and not callable(f):
                raise TypeError(f"{nm}= must be callable")
        self.drift, self.drift_jac = drift, drift_jac
        self.time_dependent = bool(time_dependent)

    @property
    def nsys(self):
        return len(self.subsystems)


class StopCondition:
    """A stop condition r(t, x, u) (scalar) with scipy's attributes: direction (+1: only where r
    increases through 0, -1: decreases, 0: both) and terminal (stop the integration there)."""

    def __init__(self, fun, direction=0, terminal=False):
        self.fun, self.direction, self.terminal = fun, direction, terminal

    def __call__(self, t, x, u):
        return self.fun(t, x, u)


def event_direction(ev):
    d = getattr(ev, "direction", 0)
    d = 0 if d is None else float(d)
    return 0 if d == 0 else (1 if d > 0 else -1)


def event_terminal(ev):
    """scipy's convention: True/False, or an int k = terminal after k occurrences."""
    term = getattr(ev, "terminal", False)
    if isinstance(term, bool) or term is None:
        return 1 if term else 0
    return int(term)
