"""ctypes view of libfesd: library lookup, the public structs and function prototypes.

The struct layouts mirror include/fesd_integrator.h, fesd_ncp.h, fesd_ocp.h and fesd_status.h field by
field; python/tests/test_layout.py checks them against sizeof/offsetof printed by a C
program compiled with the headers.
"""
import ctypes
import ctypes.util
import os

c_int, c_double, c_void_p, c_char_p = ctypes.c_int, ctypes.c_double, ctypes.c_void_p, ctypes.c_char_p
P_double, P_int = ctypes.POINTER(c_double), ctypes.POINTER(c_int)

# ---- callbacks (fesd_integrator.h); pointers as c_void_p (plain ints: the cheapest for ctypes
# to hand to Python, read with ctypes.string_at and written with ctypes.memmove) ----
_V = c_void_p
FIELD_FN = ctypes.CFUNCTYPE(c_int, c_int, c_int, c_double, _V, _V, _V, _V)
FIELD_JAC_FN = ctypes.CFUNCTYPE(c_int, c_int, c_int, c_double, _V, _V, _V, _V, _V)
SWITCH_FN = ctypes.CFUNCTYPE(c_int, c_int, c_double, _V, _V, _V, _V)
SWITCH_JAC_FN = ctypes.CFUNCTYPE(c_int, c_int, c_double, _V, _V, _V, _V, _V)
DRIFT_FN = ctypes.CFUNCTYPE(c_int, c_double, _V, _V, _V, _V)
DRIFT_JAC_FN = ctypes.CFUNCTYPE(c_int, c_double, _V, _V, _V, _V, _V)
ROOT_FN = DRIFT_FN  # r(t, x, u, r, user): same signature as the drift


class NcpSettings(ctypes.Structure):
    _fields_ = [("tol", c_double), ("max_iter", c_int), ("backend", c_int), ("dense_max_n", c_int),
                ("armijo", c_double), ("backtrack", c_double), ("max_backtracks", c_int),
                ("sigma0", c_double), ("sigma_factor", c_double), ("sigma_min", c_double),
                ("homotopy_tol_factor", c_double), ("lm_mu0", c_double),
                ("slow_iter", c_int), ("slow_ratio", c_double), ("log", c_void_p),
                ("log_user", c_void_p)]


class Settings(ctypes.Structure):
    _fields_ = [("method", c_int), ("family", c_int), ("stages", c_int), ("n_fe", c_int),
                ("newton_tol", c_double), ("max_iter_first", c_int), ("max_iter", c_int),
                ("cc_tol", c_double), ("active_tol", c_double), ("exit_rows", c_int),
                ("max_splits", c_int), ("sensitivities", c_int), ("max_sweeps", c_int),
                ("coarse_tol", c_double), ("max_elements", c_int), ("ncp", NcpSettings)]


class ModelStruct(ctypes.Structure):
    _fields_ = [("nx", c_int), ("nu", c_int), ("nsys", c_int), ("n_modes", P_int), ("n_switch", P_int),
                ("sign", ctypes.POINTER(ctypes.POINTER(ctypes.c_byte))), ("field", FIELD_FN),
                ("field_jac", FIELD_JAC_FN), ("sw", SWITCH_FN), ("sw_jac", SWITCH_JAC_FN),
                ("user", c_void_p), ("sparsity", c_void_p), ("time_dependent", c_int),
                ("drift", DRIFT_FN), ("drift_jac", DRIFT_JAC_FN), ("drift_sparsity", c_void_p),
                ("n_roots", c_int), ("roots", ROOT_FN), ("root_dir", P_int)]


class StepInfo(ctypes.Structure):
    _fields_ = [("status", c_int), ("newton_iter", c_int), ("factorizations", c_int), ("solves", c_int),
                ("homotopy_stages", c_int), ("splits", c_int), ("substeps", c_int), ("flags", c_int),
                ("switch_step", c_int), ("fallback", c_int), ("residual", c_double), ("cc_max", c_double),
                ("error_estimate", c_double), ("time", c_double), ("failed_callback", c_char_p),
                ("failed_time", c_double), ("failed_path", c_char_p), ("failed_residual", c_double),
                ("min_substep", c_double), ("last_time", c_double)]


class EventStruct(ctypes.Structure):
    _fields_ = [("t", c_double), ("sys", c_int), ("kind", c_int), ("n_before", c_int), ("n_after", c_int),
                ("before", P_int), ("after", P_int)]


class StepData(ctypes.Structure):
    _fields_ = [("n_elements", c_int), ("h", P_double), ("t", P_double), ("x", P_double),
                ("theta", P_double), ("lambda_", P_double), ("mu", P_double), ("n_theta", c_int),
                ("stages", c_int), ("nx", c_int), ("n_sys", c_int)]


class Tolerances(ctypes.Structure):
    _fields_ = [("rtol", c_double), ("atol", c_double), ("atol_v", P_double), ("h_init", c_double),
                ("h_max", c_double), ("h_min", c_double), ("max_steps", c_int)]


class IntegrateInfo(ctypes.Structure):
    _fields_ = [("status", c_int), ("t", c_double), ("steps", c_int), ("switch_steps", c_int),
                ("events", c_int), ("rejected", c_int), ("failed_attempts", c_int), ("newton_iter", c_int),
                ("root", c_int), ("n_done", c_int), ("h_next", c_double), ("failed_callback", ctypes.c_char_p),
                ("failed_time", c_double)]


class Stats(ctypes.Structure):
    _fields_ = [(n, c_int) for n in (
        "steps", "switch_steps", "newton_iter", "factorizations", "solves", "homotopy_stages", "splits",
        "fallback_steps", "substeps", "nonunique_steps", "sens_inaccurate_steps", "exit_not_pinned_steps",
        "coarse_steps", "failed_steps", "rejected_steps", "events")] + [
        (n, c_double) for n in ("time", "max_iter_ordinary_step", "mean_iter_ordinary_step",
                                "max_iter_switch_step", "mean_iter_switch_step")] + [("ambiguous_steps", c_int)]


# ---- optimal control (fesd_ocp.h) ----
OCP_FN = ctypes.CFUNCTYPE(c_int, c_double, _V, _V, _V, _V, _V, _V)  # (t, x, u, val, dx, du, user)
OCP_LOG_FN = ctypes.CFUNCTYPE(None, c_void_p, c_char_p)               # (log_user, msg)


class OcpProblem(ctypes.Structure):
    _fields_ = [("model", ctypes.POINTER(ModelStruct)), ("n_ctrl", c_int), ("t0", c_double),
                ("tf", c_double), ("x0", P_double), ("x0_lb", P_double), ("x0_ub", P_double),
                ("x_lb", P_double), ("x_ub", P_double), ("u_lb", P_double), ("u_ub", P_double),
                ("lagrange", OCP_FN), ("n_lagrange_lsq", c_int), ("lagrange_lsq", OCP_FN),
                ("mayer", OCP_FN), ("n_mayer_lsq", c_int), ("mayer_lsq", OCP_FN),
                ("n_l1", c_int), ("l1", OCP_FN), ("l1_weight", P_double),
                ("n_path", c_int), ("path", OCP_FN), ("path_lb", P_double), ("path_ub", P_double),
                ("n_term", c_int), ("terminal", OCP_FN), ("term_lb", P_double), ("term_ub", P_double),
                ("user", c_void_p)]


class OcpSettings(ctypes.Structure):
    _fields_ = [("integrator", Settings), ("hessian", c_int), ("max_iter", c_int), ("tol_stat", c_double),
                ("tol_feas", c_double), ("tol_comp", c_double), ("penalty0", c_double),
                ("penalty_max", c_double), ("armijo", c_double), ("backtrack", c_double),
                ("max_backtracks", c_int), ("soc", c_int), ("nonmonotone", c_int), ("reg_primal", c_double),
                ("reg_dual", c_double), ("qp_tol", c_double), ("qp_max_iter", c_int), ("stall_window", c_int),
                ("qp_backend", c_int), ("init", c_int), ("presolve", c_int), ("presolve_n_fe", c_int),
                ("verbose", c_int), ("log", OCP_LOG_FN), ("log_user", c_void_p)]


class OcpInfo(ctypes.Structure):
    _fields_ = [(n, c_int) for n in (
        "status", "iterations", "qp_iterations", "qp_elastic", "qp_failures", "line_search_trials", "soc_steps",
        "hessian_updates", "hessian_skipped", "hessian_resets", "integrations", "integrator_failures",
        "integrator_flags")] + [(n, c_double) for n in (
        "objective", "stationarity", "stationarity_rel", "feasibility", "complementarity", "min_multiplier",
        "penalty", "max_step", "time_total", "time_integration", "time_qp", "time_other")] + [(n, c_int) for n in (
        "hessian_fallback", "stalled", "stall_interval", "presolve_run", "presolve_status",
        "presolve_iterations", "presolve_used")]


class OcpMultipliers(ctypes.Structure):
    _fields_ = [(n, P_double) for n in ("dynamics", "x0", "x_bound", "u_bound", "path", "terminal", "l1")]


STRUCTS = {"fesd_ncp_settings": NcpSettings, "fesd_settings": Settings, "fesd_model": ModelStruct,
           "fesd_step_info": StepInfo, "fesd_event": EventStruct, "fesd_step_data": StepData,
           "fesd_tolerances": Tolerances, "fesd_integrate_info": IntegrateInfo, "fesd_stats": Stats,
           "fesd_ocp_problem": OcpProblem, "fesd_ocp_settings": OcpSettings, "fesd_ocp_info": OcpInfo,
           "fesd_ocp_multipliers": OcpMultipliers}

# ---- constants (fesd_status.h, fesd_rk.h, fesd_integrator.h) ----
FESD_ROOT, FESD_OK = 1, 0
FESD_ERR_CALLBACK, FESD_ERR_NONFINITE, FESD_ERR_TOO_MANY_STEPS = -6, -7, -19
FESD_ERR_INVALID_ARG = -2
FAMILIES = {"radau": 0, "gauss": 1, "lobatto3a": 2, "lobatto3c": 3, "explicit": 4}
COLLOCATION = ("radau", "gauss", "lobatto3a")  # families with a collocation polynomial
METHODS = {"fesd": 0, "standard": 1}
EVENT_KINDS = ("crossing", "sliding_entry", "sliding_exit", "root")
FLAGS = {0x1: "nonunique", 0x2: "sens_inaccurate", 0x4: "exit_not_pinned", 0x8: "coarse", 0x10: "ambiguous"}

_HERE = os.path.dirname(os.path.abspath(__file__))


def library_candidates():
    """Where the shared library is looked for, in order (see load_library)."""
    out = []
    env = os.environ.get("FESD_LIBRARY")
    if env:
        out.append(("FESD_LIBRARY", env))
    out.append(("build directory", os.path.normpath(os.path.join(_HERE, "..", "..", "build", "libfesd.so"))))
    found = ctypes.util.find_library("fesd")
    if found:
        out.append(("find_library", found))
    return out


def load_library():
    """Load libfesd: $FESD_LIBRARY, else build/libfesd.so of this source tree, else the system's
    (ctypes.util.find_library). FESD_LIBRARY is used alone when set (no silent fallback)."""
    cands = library_candidates()
    if cands and cands[0][0] == "FESD_LIBRARY":
        cands = cands[:1]
        if not os.path.exists(cands[0][1]):
            raise OSError(f"FESD_LIBRARY={cands[0][1]!r}: no such file")
    tried = []
    for origin, path in cands:
        if origin == "build directory" and not os.path.exists(path):
            tried.append(f"{path} (missing)")
            continue
        try:
            return ctypes.CDLL(path), path
        except OSError as e:
            tried.append(f"{path} ({e})")
    raise OSError("libfesd not found; build it (meson setup build && meson compile -C build) or set "
                  "FESD_LIBRARY to the path of libfesd.so. Tried: " + "; ".join(tried or ["find_library('fesd')"]))


lib, LIBRARY_PATH = load_library()


def _proto(name, res, *args):
    f = getattr(lib, name)
    f.restype, f.argtypes = res, list(args)
    return f


P = ctypes.POINTER
_proto("fesd_status_string", c_char_p, c_int)
_proto("fesd_status_name", c_char_p, c_int)
_proto("fesd_rk_order", c_int, c_int, c_int)
_proto("fesd_settings_default", c_int, P(Settings))
_proto("fesd_create", c_int, P(c_void_p), P(ModelStruct), P(Settings))
_proto("fesd_free", None, P(c_void_p))
_proto("fesd_set_state", c_int, c_void_p, c_double, P_double, P_double)
_proto("fesd_step", c_int, c_void_p, P_double, c_double, P(StepInfo))
_proto("fesd_get_state", c_int, c_void_p, P_double, P_double)
_proto("fesd_get_sensitivities", c_int, c_void_p, P_double, P_double)
_proto("fesd_last_events", c_int, c_void_p, P(P(EventStruct)), P_int)
_proto("fesd_event_log", c_int, c_void_p, P(P(EventStruct)), P_int)
_proto("fesd_last_step_data", c_int, c_void_p, P(StepData))
_proto("fesd_dense_output", c_int, c_void_p, c_double, P_double)
_proto("fesd_tolerances_default", c_int, P(Tolerances))
_proto("fesd_set_tolerances", c_int, c_void_p, P(Tolerances))
_proto("fesd_integrate", c_int, c_void_p, P_double, c_double, P(IntegrateInfo))
_proto("fesd_integrate_step", c_int, c_void_p, P_double, c_double, P(IntegrateInfo))
_proto("fesd_integrate_grid", c_int, c_void_p, P_double, c_int, P_double, P_double, P(IntegrateInfo))
_proto("fesd_get_stats", c_int, c_void_p, P(Stats))
_proto("fesd_dims", c_int, c_void_p, P_int, P_int)
_proto("fesd_ocp_settings_default", c_int, P(OcpSettings))
_proto("fesd_ocp_create", c_int, P(c_void_p), P(OcpProblem), P(OcpSettings))
_proto("fesd_ocp_free", None, P(c_void_p))
_proto("fesd_ocp_set_guess", c_int, c_void_p, P_double, P_double)
_proto("fesd_ocp_set_x0", c_int, c_void_p, P_double)
_proto("fesd_ocp_solve", c_int, c_void_p, P(OcpInfo))
_proto("fesd_ocp_get_solution", c_int, c_void_p, P_double, P_double)
_proto("fesd_ocp_get_multipliers", c_int, c_void_p, P(OcpMultipliers))
_proto("fesd_ocp_interval", c_int, c_void_p, c_int, P(StepData), P(P(EventStruct)), P_int)
_proto("fesd_ocp_dims", c_int, c_void_p, P_int, P_int, P_int)


def status_name(code):
    return lib.fesd_status_name(int(code)).decode()


def status_string(code):
    return lib.fesd_status_string(int(code)).decode()


def struct_dict(s):
    """Plain dict of a ctypes struct's scalar fields (bytes decoded)."""
    out = {}
    for name, _ in s._fields_:
        v = getattr(s, name)
        if isinstance(v, bytes):
            v = v.decode()
        if isinstance(v, (int, float, str)) or v is None:
            out[name] = v
    return out
