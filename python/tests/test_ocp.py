"""fesd.OCP (the optimal-control layer, include/fesd_ocp.h) from Python:

1. LQ problems with independent solutions: the double integrator with a state and control cost
   (exact zero-order-hold discretisation by Gauss-Legendre quadrature of the polynomial
   trajectories, discrete Riccati recursion written here: controls, states, objective, the
   costates -2 P_k x_k as dynamics multipliers, the integrated interval cost), with a free x0
   component; and tests/ocp/test_ocp_lq.c's closed form (terminal equalities, |u| <= 4.2 as
   control bounds and as path constraints: multipliers and their signs);
2. the paper's ocp_step_eq against the same problem solved through the C API in the same run
   (python/tests/reference.c): objective, controls, states, multipliers, element lengths and
   events; also with the OCP functions' Jacobians by the wrapper's central differences;
3. an infeasible problem: FESD_ERR_INFEASIBLE and the least-violation point (computed by hand);
4. invalid settings raise FesdError with the library's status;
5. failing Python callables (OCP functions and the model) raise CallbackError, not crash, and
   the OCP stays usable;
and the ctypes mirrors of the OCP structs against the C compiler's layout."""
import ctypes
import math
import os
import subprocess

import numpy as np
import pytest

import fesd
from fesd import _lib
from fesd import problems as P


# ---------------------------------------------------------------------------------------------
# layout
# ---------------------------------------------------------------------------------------------
def test_ocp_struct_layout(reference):
    rec = reference("ocp_layout")
    names = {"fesd_ocp_problem", "fesd_ocp_settings", "fesd_ocp_info", "fesd_ocp_multipliers"}
    assert set(rec["sizes"]) == names
    for cname, size in rec["sizes"].items():
        assert ctypes.sizeof(_lib.STRUCTS[cname]) == size, cname
    seen = {c: set() for c in names}
    for key, off in rec["offsets"].items():
        cname, field = key.split(".")
        assert getattr(_lib.STRUCTS[cname], field).offset == off, key
        seen[cname].add(field)
    for cname in names:  # every field of every mirror is checked
        assert seen[cname] == {f for f, _ in _lib.STRUCTS[cname]._fields_}, cname


# ---------------------------------------------------------------------------------------------
# 1. LQ
# ---------------------------------------------------------------------------------------------
def double_integrator():
    """p' = v, v' = u: one subsystem whose two modes share the field (smooth; never switches)."""
    J = np.array([[0.0, 1.0], [0.0, 0.0]])
    Ju = np.array([[0.0], [1.0]])
    sub = fesd.Subsystem(2, fields=lambda t, x, u: np.array([[x[1], u[0]], [x[1], u[0]]]),
                         switch=lambda t, x, u: np.array([x[0] + 100.0]),
                         fields_jac=lambda t, x, u: (np.array([J, J]), np.array([Ju, Ju])),
                         switch_jac=lambda t, x, u: (np.array([[1.0, 0.0]]), np.zeros((1, 1))))
    return fesd.Model(2, [sub], nu=1)


def zoh_lq(h, q, r):
    """Exact discretisation of p' = v, v' = u with constant u over [0, h] and stage cost
    int q0 p^2 + q1 v^2 + r u^2 dt = z' M z, z = (p, v, u): A, B, M. The trajectory is
    polynomial (degree 2), so 5-point Gauss-Legendre quadrature of the cost is exact."""
    A = np.array([[1.0, h], [0.0, 1.0]])
    B = np.array([[h * h / 2], [h]])
    nodes, weights = np.polynomial.legendre.leggauss(5)
    M = np.zeros((3, 3))
    for s, w in zip(nodes, weights):
        t = 0.5 * h * (s + 1)
        G = np.array([[1.0, t, t * t / 2], [0.0, 1.0, t], [0.0, 0.0, 1.0]])  # z(t) = G z(0)
        M += 0.5 * h * w * G.T @ np.diag([q[0], q[1], r]) @ G
    return A, B, M


def riccati(A, B, M, Qf, N):
    """Discrete LQ with cross terms: min sum z_k' M z_k + x_N' Qf x_N, x_{k+1} = A x_k + B u_k.
    Returns the gains K_k (u_k = -K_k x_k) and the cost-to-go matrices P_k."""
    nx = A.shape[0]
    Mxx, Mxu, Muu = M[:nx, :nx], M[:nx, nx:], M[nx:, nx:]
    P_ = [None] * (N + 1)
    K = [None] * N
    P_[N] = Qf
    for k in range(N - 1, -1, -1):
        Pn = P_[k + 1]
        K[k] = np.linalg.solve(Muu + B.T @ Pn @ B, Mxu.T + B.T @ Pn @ A)
        P_[k] = Mxx + A.T @ Pn @ A - (Mxu + A.T @ Pn @ B) @ K[k]
        P_[k] = 0.5 * (P_[k] + P_[k].T)
    return K, P_


LQ_Q, LQ_R, LQ_QF, LQ_N, LQ_T = (1.0, 0.5), 0.2, np.diag([10.0, 3.0]), 5, 2.0


def lq_ocp(x0, **kw):
    q, r, qf = LQ_Q, LQ_R, LQ_QF
    sq = np.sqrt([q[0], q[1], r])
    return fesd.OCP(double_integrator(), LQ_N, 0.0, LQ_T, x0,
                    lagrange_lsq=lambda t, x, u: sq * np.array([x[0], x[1], u[0]]),
                    lagrange_lsq_jac=lambda t, x, u: (np.array([[sq[0], 0.0], [0.0, sq[1]], [0.0, 0.0]]),
                                                      np.array([[0.0], [0.0], [sq[2]]])),
                    mayer_lsq=lambda x: np.sqrt(np.diag(qf)) * x,  # no Jacobian: central differences
                    stages=3, n_fe=2, tol_stat=1e-12, **kw)


@pytest.mark.parametrize("method", ["fesd", "standard"])
def test_lq_riccati(method):
    x0 = np.array([1.0, -0.5])
    A, B, M = zoh_lq(LQ_T / LQ_N, LQ_Q, LQ_R)
    K, Pk = riccati(A, B, M, LQ_QF, LQ_N)
    xs, us = [x0], []
    for k in range(LQ_N):
        us.append(-K[k] @ xs[-1])
        xs.append(A @ xs[-1] + B @ us[-1])
    xs, us = np.array(xs), np.array(us)
    f_exact = float(x0 @ Pk[0] @ x0)

    with lq_ocp(x0, method=method) as ocp:
        assert ocp.dims() == (LQ_N * 3 + 2, (LQ_N + 1) * 2, 0)
        res = ocp.solve()
        assert res.status == 0 and res.success and res.status_name == "FESD_OK"
        np.testing.assert_allclose(res.u, us, rtol=0, atol=1e-9)
        np.testing.assert_allclose(res.x, xs, rtol=0, atol=1e-9)
        assert abs(res.objective - f_exact) <= 1e-10 * f_exact
        # costates: stationarity in x_{k+1} gives y_k = -2 P_{k+1} x_{k+1}
        y_exact = np.array([-2 * Pk[k + 1] @ xs[k + 1] for k in range(LQ_N)])
        np.testing.assert_allclose(res.multipliers.dynamics, y_exact, rtol=0, atol=1e-7)
        np.testing.assert_allclose(res.t, np.linspace(0, LQ_T, LQ_N + 1), rtol=0, atol=1e-15)
        # the integrated interval cost is z' M z; the elements cover the interval
        for k, iv in enumerate(res.intervals):
            z = np.concatenate([xs[k], us[k]])
            assert abs(iv.cost[-1] - z @ M @ z) <= 1e-10 * max(1.0, z @ M @ z)
            assert iv.cost[0] == 0.0 and not iv.events
            assert abs(iv.h.sum() - LQ_T / LQ_N) < 1e-14 and abs(iv.t[0] - res.t[k]) < 1e-14
            np.testing.assert_allclose(iv.x[-1], xs[k + 1], rtol=0, atol=1e-9)
        assert res.info["integrations"] == res.integrations > 0
        assert res.time_total >= res.time_integration >= 0


def test_lq_free_x0_and_set_x0():
    """p(0) free in a box (v(0) = -0.5 fixed): p(0)* minimises x0' P_0 x0 on the box; inside it
    the bound multiplier is 0, at the lower bound it is d/dp0 x0' P_0 x0 (> 0: lower active).
    Then set_x0 with p(0) fixed: the warm-started solve gives x0' P_0 x0 of the new x0."""
    A, B, M = zoh_lq(LQ_T / LQ_N, LQ_Q, LQ_R)
    K, Pk = riccati(A, B, M, LQ_QF, LQ_N)
    v0 = -0.5
    p_free = -Pk[0][0, 1] * v0 / Pk[0][0, 0]
    for lo, hi, active in ((p_free - 0.25, p_free + 0.5, False), (p_free + 0.1, p_free + 0.5, True)):
        p0 = lo if active else p_free
        x0 = np.array([p0, v0])
        with lq_ocp([hi, v0], x0_lb=[lo, v0], x0_ub=[hi, v0]) as ocp:  # lb == ub: v(0) fixed
            res = ocp.solve()
            assert res.success
            assert abs(res.x[0, 0] - p0) <= 1e-8 and res.x[0, 1] == v0
            assert abs(res.objective - x0 @ Pk[0] @ x0) <= 1e-10
            m = 2 * (Pk[0][0] @ x0) if active else 0.0
            assert abs(res.multipliers.x_bound[0, 0] - m) <= 1e-7 and res.multipliers.x0[0] == 0.0
            assert active == (m > 0.1)
    with lq_ocp([1.0, v0]) as ocp:
        r1 = ocp.solve()
        x0 = np.array([0.3, 0.2])
        ocp.set_x0(x0)
        r2 = ocp.solve()
        assert r1.success and r2.success and not r2.presolve_run
        assert abs(r2.objective - x0 @ Pk[0] @ x0) <= 1e-10 and np.allclose(r2.x[0], x0, rtol=0, atol=1e-12)


def test_lq_bounds_closed_form():
    """tests/ocp/test_ocp_lq.c: x(0) = 0, min int u^2, p(1) = 1, v(1) = 0, |u| <= 4.2, N = 4;
    its closed form (active bounds on u_0 and u_3) recomputed here. The bound as control
    bounds (lagrange: general form, BFGS) and as path constraints -4.2 <= u <= 4.2 (applied at
    k = 0..N with u_N = u_{N-1}: u_3's multiplier is shared by k = 3 and 4)."""
    N, h, UMAX = 4, 0.25, 4.2
    bk = np.array([h * h * (N - k - 0.5) for k in range(N)])
    uex = np.array([UMAX, 0.0, 0.0, -UMAX])
    uex[1] = (1 - bk[0] * uex[0] - bk[3] * uex[3]) / (bk[1] - bk[2])
    uex[2] = -uex[1]
    b = 2 * h * (uex[1] - uex[2]) / (bk[1] - bk[2])
    a = (2 * h * uex[1] - b * bk[1]) / h
    m0, m3 = 2 * h * uex[0] - a * h - b * bk[0], 2 * h * uex[3] - a * h - b * bk[3]
    fex = h * float(uex @ uex)
    assert m0 < 0 < m3
    common = dict(terminal=lambda x: x, terminal_jac=lambda x: np.eye(2), term_lb=[1.0, 0.0], term_ub=[1.0, 0.0],
                  stages=2, n_fe=2)
    # control bounds, general Lagrange term (AUTO: BFGS), gradient by central differences
    ocp = fesd.OCP(double_integrator(), N, 0.0, 1.0, [0.0, 0.0], u_lb=-UMAX, u_ub=UMAX,
                   lagrange=lambda t, x, u: u[0] ** 2, **common)
    res = ocp.solve()
    assert res.success, res.status_name
    np.testing.assert_allclose(res.u[:, 0], uex, rtol=0, atol=1e-8)
    assert abs(res.objective - fex) <= 1e-9 * fex
    mu = res.multipliers
    np.testing.assert_allclose(mu.u_bound[:, 0], [m0, 0, 0, m3], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(mu.terminal, [b, a], rtol=1e-6)
    # path constraints instead of bounds (least squares: Gauss-Newton)
    ocp = fesd.OCP(double_integrator(), N, 0.0, 1.0, [0.0, 0.0], lagrange_lsq=lambda t, x, u: u,
                   lagrange_lsq_jac=lambda t, x, u: (np.zeros((1, 2)), np.ones((1, 1))),
                   path=lambda t, x, u: u, path_jac=lambda t, x, u: (np.zeros((1, 2)), np.ones((1, 1))),
                   path_lb=[-UMAX], path_ub=[UMAX], **common)
    res = ocp.solve()
    assert res.success, res.status_name
    np.testing.assert_allclose(res.u[:, 0], uex, rtol=0, atol=1e-8)
    assert abs(res.objective - fex) <= 1e-9 * fex
    mp = res.multipliers.path[:, 0]
    assert mp.shape == (N + 1,)
    assert abs(mp[0] - m0) <= 1e-6 * abs(m0) and abs(mp[1]) <= 1e-9 and abs(mp[2]) <= 1e-9
    assert abs(mp[3] + mp[4] - m3) <= 1e-6 * abs(m3) and mp[3] >= -1e-9 and mp[4] >= -1e-9


# ---------------------------------------------------------------------------------------------
# 2. ocp_step_eq against the C API
# ---------------------------------------------------------------------------------------------
def c_step_eq(reference, method, stages, n_fe, n_ctrl=6):
    """fesd_py_reference ocp_step_eq: the C API's solve of the same problem."""
    out = subprocess.run([reference.exe, "ocp_step_eq", method, "radau", str(stages), str(n_fe), str(n_ctrl)],
                         check=True, capture_output=True, text=True).stdout
    rec = {"interval": [], "events": []}
    for line in out.splitlines():
        name, *v = line.split()
        if name == "interval":
            rec["interval"].append(np.array([float(w) for w in v[2:]]))
            rec["events"].append([])
        elif name == "event":
            rec["events"][-1].append((float(v[0]), int(v[1]), _lib.EVENT_KINDS[int(v[2])]))
        elif name == "status":
            rec["status"] = int(v[0])
        else:
            rec[name] = np.array([float(w) for w in v])
    return rec


@pytest.mark.parametrize("method,n_fe", [("fesd", 6), ("standard", 2)])
def test_step_eq_against_c(reference, method, n_fe):
    c = c_step_eq(reference, method, 2, n_fe)
    assert c["status"] == 0
    ocp = P.ocp_step_eq(method=method, stages=2, n_fe=n_fe)
    res = ocp.solve(u_guess=P.ocp_step_eq_guess(6))
    assert res.status == 0, res.summary()
    f_c = c["objective"][0]
    assert abs(res.objective - f_c) <= 1e-8 * abs(f_c), (res.objective, f_c)
    np.testing.assert_allclose(res.u.ravel(), c["u"], rtol=0, atol=1e-8)
    np.testing.assert_allclose(res.x.ravel(), c["xsol"], rtol=0, atol=1e-8)
    np.testing.assert_allclose(res.multipliers.dynamics.ravel(), c["m_dynamics"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(res.multipliers.l1, c["m_l1"], rtol=0, atol=1e-6)
    assert [res.iterations, res.integrations, int(res.presolve_run), res.presolve_iterations] == \
        [int(v) for v in c["work"]]
    for k, iv in enumerate(res.intervals):
        np.testing.assert_allclose(iv.h, c["interval"][k], rtol=0, atol=1e-10)
        assert [(e.sys, e.kind) for e in iv.events] == [(s, kd) for _, s, kd in c["events"][k]]
        np.testing.assert_allclose([e.t for e in iv.events], [t for t, _, _ in c["events"][k]], rtol=0, atol=1e-10)
    if method == "fesd":
        # the paper's switching structure: two sliding entries, two sliding exits
        kinds = [e.kind for iv in res.intervals for e in iv.events]
        assert kinds == ["sliding_entry", "sliding_entry", "sliding_exit", "sliding_exit"]
        assert res.objective == pytest.approx(9.1496, abs=1e-3)
        assert np.all(np.abs(res.multipliers.l1) <= 1e3 * (1 + 1e-9))


def test_step_eq_finite_differences(reference):
    """The OCP functions without Jacobians: the wrapper's central differences (fesd.ocp.FD_STEP)
    reach the C solution's KKT point."""
    c = c_step_eq(reference, "fesd", 2, 2)
    ocp = P.ocp_step_eq(stages=2, n_fe=2, jacobians=False)
    assert ocp.fns["l1"].jac is None and ocp.fns["lagrange_lsq"].jac is None
    res = ocp.solve(u_guess=P.ocp_step_eq_guess(6), intervals=False)
    assert res.success and res.intervals is None
    assert abs(res.objective - c["objective"][0]) <= 1e-8 * c["objective"][0]
    np.testing.assert_allclose(res.u.ravel(), c["u"], rtol=0, atol=1e-6)
    assert res.stationarity_rel <= 1e-8 and res.feasibility <= 1e-9


def test_resolve():
    """A second solve starts from the last solution: no presolve, at most one iteration."""
    ocp = P.ocp_step_eq(stages=2, n_fe=2)
    r1 = ocp.solve(u_guess=P.ocp_step_eq_guess(6), intervals=False)
    r2 = ocp.solve(intervals=False)
    assert r1.success and r2.success and r1.presolve_run and not r2.presolve_run and r2.iterations <= 1
    assert abs(r2.objective - r1.objective) <= 1e-9 * r1.objective
    x, u = ocp.solution()
    np.testing.assert_array_equal(u, r2.u)
    np.testing.assert_array_equal(x, r2.x)


# ---------------------------------------------------------------------------------------------
# 3. infeasible
# ---------------------------------------------------------------------------------------------
def test_infeasible_returns_best_iterate():
    """tests/ocp/test_ocp_infeasible.c, problem 1: x(0) = 0, |u| <= 1, N = 4, p(1) = 10, v(1) = 0.
    The least l1 violation |p(1) - 10| + |v(1)| is 9.75 at u = (1, 1, -1, -1) (p(1) = sum h^2
    (N - k - 1/2) u_k = 1/4): a linear program solved by hand."""
    ocp = fesd.OCP(double_integrator(), 4, 0.0, 1.0, [0.0, 0.0], u_lb=-1.0, u_ub=1.0,
                   lagrange_lsq=lambda t, x, u: u, terminal=lambda x: x, term_lb=[10.0, 0.0], term_ub=[10.0, 0.0])
    res = ocp.solve()
    assert res.status_name == "FESD_ERR_INFEASIBLE" and not res.success and res.status == -21
    assert res.message == _lib.status_string(-21) and "infeasible" in res.message
    viol = abs(res.x[-1, 0] - 10) + abs(res.x[-1, 1])
    assert abs(viol - 9.75) <= 1e-6
    np.testing.assert_allclose(res.u[:, 0], [1, 1, -1, -1], rtol=0, atol=1e-6)
    assert res.feasibility > 9 and len(res.intervals) == 4


# ---------------------------------------------------------------------------------------------
# 4. invalid settings
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kw,status", [
    ({"tol_stat": 0.0}, "FESD_ERR_INVALID_ARG"),
    ({"tol_feas": math.nan}, "FESD_ERR_INVALID_ARG"),
    ({"armijo": 0.5}, "FESD_ERR_INVALID_ARG"),
    ({"max_iter": 0}, "FESD_ERR_INVALID_ARG"),
    ({"max_iter": 2 ** 40}, "FESD_ERR_INVALID_ARG"),  # not truncated to a valid int
    ({"hessian": "newton"}, "FESD_ERR_INVALID_ARG"),
    ({"hessian": 7}, "FESD_ERR_INVALID_ARG"),
    ({"init": "random"}, "FESD_ERR_INVALID_ARG"),
    ({"presolve_n_fe": 101}, "FESD_ERR_INVALID_ARG"),
    ({"nonmonotone": 17}, "FESD_ERR_INVALID_ARG"),
    ({"hessian": "gauss_newton", "lsq": False}, "FESD_ERR_INVALID_ARG"),  # GN without least squares
    ({"integrator": {"newton_tol": -1.0}}, None),                          # fesd_create's check
    ({"stages": 0}, None),
])
def test_invalid_settings(kw, status):
    kw = dict(kw)
    lsq = kw.pop("lsq", True)
    cost = {"lagrange_lsq": lambda t, x, u: u} if lsq else {"lagrange": lambda t, x, u: u[0] ** 2}
    with pytest.raises(fesd.FesdError) as ei:
        fesd.OCP(double_integrator(), 4, 0.0, 1.0, [0.0, 0.0], **cost, **kw)
    e = ei.value
    assert not isinstance(e, fesd.CallbackError) and e.status < 0
    assert e.status_text == _lib.status_string(e.status) and e.status_name in str(e)
    if status is not None:
        assert e.status_name == status and e.status_text == "invalid argument or setting"


def test_unknown_settings():
    with pytest.raises(TypeError, match="unknown OCP setting"):
        fesd.OCP(double_integrator(), 4, 0.0, 1.0, [0.0, 0.0], lagrange_lsq=lambda t, x, u: u, tolerance=1e-3)
    with pytest.raises(TypeError, match="integrator="):
        fesd.OCP(double_integrator(), 4, 0.0, 1.0, [0.0, 0.0], lagrange_lsq=lambda t, x, u: u, newton_tol=1e-3)
    with pytest.raises(TypeError, match="integer"):
        fesd.OCP(double_integrator(), 4, 0.0, 1.0, [0.0, 0.0], lagrange_lsq=lambda t, x, u: u, max_iter=2.5)
    with pytest.raises(ValueError, match="x0"):
        fesd.OCP(double_integrator(), 4, 0.0, 1.0, [0.0], lagrange_lsq=lambda t, x, u: u)


def test_valid_settings_and_log():
    lines = []
    ocp = fesd.OCP(double_integrator(), 4, 0.0, 1.0, [0.0, 0.0], lagrange_lsq=lambda t, x, u: u,
                   terminal=lambda x: x, term_lb=[1.0, 0.0], term_ub=[1.0, 0.0], hessian="bfgs", max_iter=50,
                   tol_stat=1e-10, qp_backend="dense", init="constant", presolve=False, verbose=True,
                   log=lines.append, integrator={"newton_tol": 1e-12, "ncp_backend": 1})
    s = ocp.settings
    assert (s.hessian, s.max_iter, s.qp_backend, s.init, s.presolve, s.verbose) == (2, 50, 1, 1, 0, 1)
    assert s.integrator.newton_tol == 1e-12 and s.integrator.ncp.backend == 1 and s.integrator.sensitivities == 1
    res = ocp.solve()
    assert res.success and not res.presolve_run and res.presolve_status == "FESD_OK"
    assert len(lines) >= res.iterations > 0 and all(isinstance(ln, str) for ln in lines)


# ---------------------------------------------------------------------------------------------
# 5. failing callables
# ---------------------------------------------------------------------------------------------
def test_callback_exception_reported():
    fault = {"on": True}

    def lsq(t, x, u):
        if fault["on"]:
            raise ZeroDivisionError("boom in the cost")
        return np.array([u[0], u[1], x[2], x[3]])

    ocp = P.ocp_step_eq(stages=2, n_fe=2)
    ocp.fns["lagrange_lsq"].fun = lsq
    with pytest.raises(fesd.CallbackError) as ei:
        ocp.solve(u_guess=P.ocp_step_eq_guess(6))
    e = ei.value
    assert e.callback == "lagrange_lsq" and isinstance(e.__cause__, ZeroDivisionError)
    assert e.status_name in ("FESD_ERR_CALLBACK", "FESD_ERR_NONFINITE") and "boom in the cost" in str(e)
    assert isinstance(e.result, fesd.OcpResult) and e.result.status == e.status
    # usable afterwards: the clean problem gives its solution
    fault["on"] = False
    res = ocp.solve(u_guess=P.ocp_step_eq_guess(6), intervals=False)
    assert res.success and res.objective == pytest.approx(9.1496, abs=1e-3) and res.callback_failure is None


@pytest.mark.parametrize("where", ["terminal_shape", "model"])
def test_callback_faults(where):
    if where == "terminal_shape":  # the wrong number of outputs
        ocp = P.ocp_step_eq(stages=2, n_fe=2)
        ocp.fns["l1"].fun = lambda x: np.zeros(3)
        role, cause = "l1", fesd.OutputShapeError
    else:  # the model's fields raise: the integrator fails, the solve stops
        model = P.ocp_dynamics()
        sub = model.subsystems[0]
        good = sub.fields

        def bad(t, x, u):
            if x[0] < 1.5:
                raise KeyError("model fault")
            return good(t, x, u)
        sub.fields = bad
        ocp = fesd.OCP(model, 6, 0.0, 4.0, P.OCP_X0, u_lb=-10, u_ub=10, lagrange_lsq=lambda t, x, u: u)
        role, cause = "fields", KeyError
    with pytest.raises(fesd.CallbackError) as ei:
        ocp.solve(u_guess=P.ocp_step_eq_guess(6))
    assert ei.value.callback == role and isinstance(ei.value.__cause__, cause)


def test_rejected_trial_point_warns():
    """l1 raises once, at a trial point of the main solve's line search (its 10th call): the
    library rejects that trial and converges; the failure is reported by a warning."""
    ocp = P.ocp_step_eq(stages=2, n_fe=2)
    good, calls = ocp.fns["l1"].fun, [0]

    def l1(x):
        calls[0] += 1
        if calls[0] == 10:
            raise ValueError("once")
        return good(x)
    ocp.fns["l1"].fun = l1
    with pytest.warns(RuntimeWarning, match="callback 'l1'.*ValueError: once"):
        res = ocp.solve(u_guess=P.ocp_step_eq_guess(6), intervals=False)
    assert res.success and "ValueError: once" in res.callback_failure
    assert res.objective == pytest.approx(9.1496064477, abs=1e-8)


def test_keyboard_interrupt_ends_the_solve():
    ocp = P.ocp_step_eq(stages=2, n_fe=2)
    good, calls = ocp.fns["lagrange_lsq"].fun, [0]

    def lsq(t, x, u):
        calls[0] += 1
        if calls[0] == 500:
            raise KeyboardInterrupt
        return good(t, x, u)
    ocp.fns["lagrange_lsq"].fun = lsq
    with pytest.raises(KeyboardInterrupt):
        ocp.solve(u_guess=P.ocp_step_eq_guess(6))
    n_at_interrupt = calls[0]
    ocp.fns["lagrange_lsq"].fun = good
    res = ocp.solve(u_guess=P.ocp_step_eq_guess(6), intervals=False)
    assert res.success and n_at_interrupt == 500  # no call reached Python after the interrupt


def test_docs_example():
    """The fesd.OCP block of docs/python.md runs as it is."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "python.md")
    text = open(path, encoding="utf-8").read()
    a = text.index("## Optimal control")
    b = text.index("```python", a) + len("```python")
    ns = {}
    exec(compile(text[b:text.index("```", b)], "docs/python.md", "exec"), ns)
    res = ns["res"]
    assert res.success and abs(res.objective - 9.1496064477) < 1e-8
    assert [e.kind for iv in res.intervals for e in iv.events] == ["sliding_entry", "sliding_entry",
                                                                 "sliding_exit", "sliding_exit"]
