"""Output: t_eval (both modes), dense output (sol), exact solutions and the integration order
of FESD on the oscillator (paper Fig. integrator_order), element data."""
import math

import numpy as np
import pytest

import fesd
from fesd import problems as P

T_OSC = math.pi / 2


def osc_exact(ts):
    return np.column_stack([P.oscillator_exact(t) for t in ts])


@pytest.mark.parametrize("kw", [dict(h=T_OSC / 40), dict(rtol=1e-10, atol=1e-12), dict(rtol=1e-10, atol=1e-12,
                                                                                     dense_output=True)])
def test_t_eval(kw):
    t_eval = np.linspace(0, T_OSC, 23)
    res = fesd.solve_ivp(P.oscillator(), (0, T_OSC), P.OSCILLATOR_X0, stages=3, t_eval=t_eval, **kw)
    assert res.success and np.array_equal(res.t, t_eval) and res.y.shape == (2, 23)
    err = np.abs(res.y - osc_exact(t_eval)).max()
    assert err < (2e-6 if "h" in kw else 1e-8), err


def test_t_eval_needs_collocation_between_steps():
    with pytest.raises(ValueError, match="dense output"):
        fesd.solve_ivp(P.oscillator(), (0, T_OSC), P.OSCILLATOR_X0, family="lobatto3c", stages=3, h=T_OSC / 10,
                       t_eval=[0.1234])
    # on the step grid it works
    res = fesd.solve_ivp(P.oscillator(), (0, 1.0), P.OSCILLATOR_X0, family="lobatto3c", stages=3, h=0.1,
                         t_eval=[0.5, 1.0])
    np.testing.assert_allclose(res.y, osc_exact([0.5, 1.0]), atol=5e-3)
    assert np.abs(res.y - osc_exact([0.5, 1.0])).max() > 0  # a Lobatto IIIC result, not the exact one


def test_dense_output_matches_library_and_exact():
    m = P.oscillator()
    h = T_OSC / 12
    res = fesd.solve_ivp(m, (0, T_OSC), P.OSCILLATOR_X0, stages=3, h=h, dense_output=True, record_elements=True)
    sol = res.sol
    assert sol is not None and sol.t_min == 0 and abs(sol.t_max - T_OSC) < 1e-14
    # the last step's polynomial from the library itself
    it = fesd.Integrator(m, stages=3)
    it.set_state(0, P.OSCILLATOR_X0)
    for _ in range(12):
        it.step(h)
    ts = np.linspace(T_OSC - h, T_OSC, 9)
    lib = np.column_stack([it.dense_output(t) for t in ts])
    np.testing.assert_allclose(sol(ts), lib, rtol=0, atol=1e-13)
    # everywhere: the error of the method's dense output, of order s + 1 = 4
    tt = np.linspace(0, T_OSC, 400)
    e12 = np.abs(sol(tt) - osc_exact(tt)).max()
    fine = fesd.solve_ivp(m, (0, T_OSC), P.OSCILLATOR_X0, stages=3, h=h / 2, dense_output=True)
    e24 = np.abs(fine.sol(tt) - osc_exact(tt)).max()
    assert e12 < 1e-3 and math.log2(e12 / e24) > 3.5, (e12, e24)
    # at the step ends it is the step result
    np.testing.assert_allclose(sol(res.t), res.y, rtol=0, atol=1e-13)
    assert sol(0.3).shape == (2,)
    with pytest.raises(ValueError):
        sol(T_OSC + 0.1)
    # element boundaries: N_FE = 2 per step, the switch at t = 1 is one of them
    bounds = np.unique(np.round(np.concatenate(res.element_t), 12))
    t_sw = res.switch_events[0].t
    assert bounds.size == 2 * 12 + 1 and abs(t_sw - 1.0) < 1e-4 and np.abs(bounds - t_sw).min() < 1e-12


def test_sign_c_exact():
    # sliding on x = 0 until t = 1, then (t-1)^2/2: reproduced to round-off (Radau s = 2)
    res = fesd.solve_ivp(P.sign_c(), (0, 2.1), [0.0, 0.0], h=0.1)
    ex = np.column_stack([P.sign_c_exact(t) for t in res.t])
    assert np.abs(res.y - ex).max() < 1e-13
    kinds = [(e.kind, e.before, e.after) for e in res.switch_events]
    assert kinds == [("sliding_exit", (0, 1), (0,))] and abs(res.switch_events[0].t - 1.0) < 1e-13


def test_ocp_exact_switch_times():
    res = fesd.solve_ivp(P.ocp_dynamics(), (0, 4.0), P.OCP_X0, u=[0.0, 0.0], h=0.1, stages=2)
    t1, t2 = P.ocp_t1(), 2 * math.pi / 3
    ev = [(round(e.t, 9), e.sys, e.kind) for e in res.switch_events]
    assert ev == [(round(t1, 9), 1, "sliding_entry"), (round(t2, 9), 0, "sliding_entry")]
    ex = np.column_stack([P.ocp_exact(t) for t in res.t])
    assert np.abs(res.y - ex).max() < 1e-12


def test_integration_order_oscillator():
    # FESD keeps the order 2s - 1 of Radau IIA across the crossing; standard time-stepping drops to ~1
    def err(method, s, n):
        res = fesd.solve_ivp(P.oscillator(), (0, T_OSC), P.OSCILLATOR_X0, h=T_OSC / n, method=method, stages=s)
        return np.abs(res.y[:, -1] - P.oscillator_exact(T_OSC)).max()
    for s, lo in ((2, 2.7), (3, 4.6)):
        e1, e2 = err("fesd", s, 20), err("fesd", s, 40)
        assert math.log2(e1 / e2) > lo, (s, e1, e2)
    ns = np.array([20, 40, 80, 160])
    es = np.array([err("standard", 3, n) for n in ns])
    slope = -np.polyfit(np.log(ns), np.log(es), 1)[0]
    assert slope < 1.6 and es[-1] > 1e-4, (slope, es)
