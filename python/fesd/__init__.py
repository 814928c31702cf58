"""fesd: Python interface of libfesd (FESD integrator for nonsmooth Filippov ODEs), over ctypes.

    import fesd
    model = fesd.Model(nx, [fesd.Subsystem(n_modes, fields=..., switch=...)])
    res = fesd.solve_ivp(model, (t0, tf), x0, rtol=1e-8)
    ocp = fesd.OCP(model, n_ctrl, t0, tf, x0, lagrange_lsq=..., u_lb=..., u_ub=...); ocp.solve()

See docs/python.md.
"""
try:
    import numpy  # noqa: F401
except ImportError as e:  # pragma: no cover - depends on the interpreter
    raise ImportError("fesd needs numpy: install python3-numpy (tools/setup.sh) and use Debian's python3 "
                      "(/usr/bin/python3; another python3 first in PATH, e.g. pyenv's, may lack it)") from e
from ._lib import LIBRARY_PATH, status_name, status_string
from .errors import CallbackError, FesdError, NonFiniteOutputError, OutputShapeError
from .integrator import Integrator, StepData, SwitchEvent
from .model import Model, StopCondition, Subsystem

__all__ = ["Model", "Subsystem", "StopCondition", "Integrator", "SwitchEvent", "StepData", "FesdError",
           "CallbackError", "OutputShapeError", "NonFiniteOutputError", "status_name", "status_string",
           "LIBRARY_PATH"]
from .dense import DenseSolution  # noqa: E402
from .ivp import OdeResult, solve_ivp  # noqa: E402

__all__ += ["solve_ivp", "OdeResult", "DenseSolution"]
from .ocp import OCP, OcpInterval, OcpMultipliers, OcpResult  # noqa: E402

__all__ += ["OCP", "OcpResult", "OcpMultipliers", "OcpInterval"]
