"""Stop conditions (events=): the README's friction oscillator x'' = -x - sign(x') from
x = 5.5 at rest; x = 1 + 4.5 cos t until t = pi, so x crosses 0 downwards at
t* = acos(-1/4.5) and 1 + 4.5 cos t = 0.5 ... Exact times and states, direction, terminal
(bool and count), in both modes."""
import math

import numpy as np
import pytest

import fesd
from fesd import problems as P

T_DOWN = math.acos(-1 / 4.5)           # x = 0, decreasing (first swing)
T_UP = math.pi + math.acos(-1 / 2.5)   # x = 0, increasing: x = -1 - 2.5 cos(t - pi) in the 2nd swing


def x_exact(t):
    assert t <= math.pi
    return np.array([1 + 4.5 * math.cos(t), -4.5 * math.sin(t)])


def ev_x(direction=0, terminal=False):
    return fesd.StopCondition(lambda t, x, u: x[0], direction=direction, terminal=terminal)


@pytest.mark.parametrize("mode", [dict(rtol=1e-10, atol=1e-12), dict(h=0.05)])
def test_terminal_down(mode):
    res = fesd.solve_ivp(P.friction(), (0, 12), [5.5, 0.0], stages=3, events=[ev_x(-1, True)], **mode)
    assert res.status == 1 and res.success and "termination" in res.message
    assert res.t_events[0].shape == (1,)
    assert abs(res.t_events[0][0] - T_DOWN) < 1e-9
    np.testing.assert_allclose(res.y_events[0][0], x_exact(T_DOWN), atol=1e-8)
    assert abs(res.t[-1] - T_DOWN) < 1e-9  # the run ends on the stop condition
    np.testing.assert_allclose(res.y[:, -1], x_exact(T_DOWN), atol=1e-8)


def test_direction_and_nonterminal():
    # x = 0 crossings: down at T_DOWN, up at T_UP, then the swing of amplitude 0.5 about +1 stays > 0
    up, down, both = ev_x(+1), ev_x(-1), ev_x(0)
    res = fesd.solve_ivp(P.friction(), (0, 12), [5.5, 0.0], stages=3, rtol=1e-10, atol=1e-12,
                         events=[up, down, both])
    assert res.status == 0 and abs(res.t[-1] - 12) < 1e-12
    np.testing.assert_allclose(res.t_events[0], [T_UP], atol=1e-8)
    np.testing.assert_allclose(res.t_events[1], [T_DOWN], atol=1e-8)
    np.testing.assert_allclose(res.t_events[2], [T_DOWN, T_UP], atol=1e-8)
    np.testing.assert_allclose(res.y_events[2][:, 0], [0, 0], atol=1e-9)
    # the switches of the friction subsystem: reversals at pi, 2 pi, sticking at 3 pi
    sw = res.switch_events
    assert [e.kind for e in sw] == ["crossing", "crossing", "sliding_entry"]
    np.testing.assert_allclose([e.t for e in sw], [math.pi, 2 * math.pi, 3 * math.pi], atol=1e-7)
    assert sw[0].before == (1,) and sw[0].after == (0,) and sw[2].after == (0, 1)
    np.testing.assert_allclose(res.y[:, -1], [0.5, 0.0], atol=1e-8)


def test_terminal_count():
    ev = ev_x(0, terminal=2)  # stop at the second crossing
    res = fesd.solve_ivp(P.friction(), (0, 12), [5.5, 0.0], stages=3, h=0.05, events=[ev])
    assert res.status == 1
    np.testing.assert_allclose(res.t_events[0], [T_DOWN, T_UP], atol=1e-7)
    assert abs(res.t[-1] - T_UP) < 1e-7


def test_integrator_root_status():
    it = fesd.Integrator(P.friction(), stages=3, events=[ev_x(-1)])
    it.set_state(0.0, [5.5, 0.0])
    st, info = it.integrate(12.0)
    assert st == 1 and info["root"] == 0 and abs(it.t - T_DOWN) < 1e-6
    st, info = it.integrate(12.0)
    assert st == 0 and it.t == 12.0
    kinds = [e.kind for e in it.event_log()]
    assert kinds.count("root") == 1 and kinds.count("crossing") == 2
