"""dx(T)/dx0 and dx(T)/du against central differences of the end state (the same fixed steps:
the map x0 -> x(T) of FESD is differentiable, its switch times move with x0), and against the
exact derivative of the Stewart-Anitescu value function."""
import numpy as np
import pytest

import fesd
from fesd import problems as P


def _end(model, x0, T, u=None, **kw):
    res = fesd.solve_ivp(model, (0, T), x0, u=u, **kw)
    assert res.success
    return res.y[:, -1]


@pytest.mark.parametrize("kw", [dict(h=np.pi / 2 / 20, stages=3), dict(h=np.pi / 2 / 10, stages=2, family="gauss")])
def test_oscillator_dxdx0(kw):
    m, x0, T = P.oscillator(), P.OSCILLATOR_X0, np.pi / 2
    res = fesd.solve_ivp(m, (0, T), x0, sensitivities=True, **kw)
    eps = 1e-6
    fd = np.column_stack([(_end(m, x0 + eps * e, T, **kw) - _end(m, x0 - eps * e, T, **kw)) / (2 * eps)
                          for e in np.eye(2)])
    assert np.abs(fd).max() > 10  # the crossing amplifies perturbations: a real test
    np.testing.assert_allclose(res.dxdx0, fd, rtol=1e-6, atol=1e-6)


def test_ocp_dxdu_and_dxdx0():
    m, x0, T = P.ocp_dynamics(), P.OCP_X0, 1.5
    u = np.array([0.3, -0.2])
    kw = dict(h=T / 30, stages=2)
    res = fesd.solve_ivp(m, (0, T), x0, u=u, sensitivities=True, **kw)
    assert res.dxdu.shape == (4, 2) and res.dxdx0.shape == (4, 4)
    eps = 1e-6
    fdu = np.column_stack([(_end(m, x0, T, u + eps * e, **kw) - _end(m, x0, T, u - eps * e, **kw)) / (2 * eps)
                           for e in np.eye(2)])
    fdx = np.column_stack([(_end(m, x0 + eps * e, T, u, **kw) - _end(m, x0 - eps * e, T, u, **kw)) / (2 * eps)
                           for e in np.eye(4)])
    np.testing.assert_allclose(res.dxdu, fdu, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(res.dxdx0, fdx, rtol=1e-6, atol=1e-6)
    assert np.abs(res.dxdu).max() > 0.5


def test_sensitivities_across_a_stop():
    # a non-terminal stop condition restarts the integration: the sensitivities are composed
    m, x0, T = P.oscillator(), P.OSCILLATOR_X0, np.pi / 2
    ev = fesd.StopCondition(lambda t, x, u: x[0], direction=1)  # x1 = e^(t-1) cos(2 pi t) increases at t = 0.75
    kw = dict(stages=3, rtol=1e-10, atol=1e-12)
    res = fesd.solve_ivp(m, (0, T), x0, events=[ev], sensitivities=True, **kw)
    assert res.stats["restarts"] == 1 and abs(res.t_events[0][0] - 0.75) < 1e-8
    plain = fesd.solve_ivp(m, (0, T), x0, sensitivities=True, **kw)
    np.testing.assert_allclose(res.dxdx0, plain.dxdx0, rtol=1e-6)
    eps = 1e-6
    fd = np.column_stack([(_end(m, x0 + eps * e, T, **kw) - _end(m, x0 - eps * e, T, **kw)) / (2 * eps)
                          for e in np.eye(2)])
    np.testing.assert_allclose(res.dxdx0, fd, rtol=1e-4, atol=1e-4)


@pytest.mark.parametrize("x0", [-2.0, -0.7, 0.4])
def test_stewart_anitescu_gradient(x0):
    res = fesd.solve_ivp(P.stewart_anitescu(), (0, 2), [x0, 0.0], h=2.0, family="gauss", stages=2, n_fe=25,
                         sensitivities=True)
    x, q = res.y[:, -1]
    V = q + (x - 5 / 3) ** 2
    dV = res.dxdx0[1, 0] + 2 * (x - 5 / 3) * res.dxdx0[0, 0]
    V_ex, dV_ex = P.stewart_anitescu_exact(x0)
    assert abs(V - V_ex) < 1e-12 and abs(dV - dV_ex) < 1e-12
