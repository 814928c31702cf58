"""The Python interface gives the C API's results (python/tests/reference.c on the same problems
of src/problems, with the same Jacobians) to 1e-12: fixed steps (FESD and standard, states,
events, sensitivities), fesd_integrate and fesd_integrate_grid."""
import math

import numpy as np
import pytest

import fesd
from fesd import problems as P

KINDS = fesd._lib.EVENT_KINDS
MODELS = {"oscillator": (P.oscillator, P.OSCILLATOR_X0), "sign-c": (P.sign_c, np.zeros(2)),
          "ocp-dynamics": (P.ocp_dynamics, P.OCP_X0)}


def _events(res):
    return [(e.t, e.sys, e.kind, e.before, e.after) for e in res]


def _same_events(py, c):
    assert len(py) == len(c), (py, c)
    for (t, sys, kind, b, a), (tc, sysc, kc, bc, ac) in zip(py, c):
        assert abs(t - tc) <= 1e-12 and sys == sysc and kind == KINDS[kc] and b == bc and a == ac


@pytest.mark.parametrize("name,method,family,s,nsim,T,u", [
    ("oscillator", "fesd", "radau", 3, 20, math.pi / 2, ()),
    ("oscillator", "standard", "radau", 2, 20, math.pi / 2, ()),
    ("oscillator", "fesd", "gauss", 2, 16, math.pi / 2, ()),
    ("sign-c", "fesd", "radau", 2, 21, 2.1, ()),
    ("sign-c", "fesd", "lobatto3c", 3, 10, 2.1, ()),
    ("ocp-dynamics", "fesd", "radau", 2, 40, 4.0, (0.1, -0.05)),
])
def test_fixed_steps(reference, name, method, family, s, nsim, T, u):
    c = reference("fixed", name, method, family, s, 2, nsim, repr(T), *u)
    assert c["status"] == 0
    make, x0 = MODELS[name]
    model = make()
    res = fesd.solve_ivp(model, (0, T), x0, h=T / nsim, method=method, family=family, stages=s, n_fe=2,
                         sensitivities=True, u=np.array(u) if u else None)
    assert res.status == 0 and res.y.shape == (model.nx, nsim + 1)
    np.testing.assert_allclose(res.t[1:], c["t"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.y[:, 1:].T, c["x"], rtol=0, atol=1e-12)
    _same_events(_events(res.switch_events), c["event"])
    nx = model.nx
    np.testing.assert_allclose(res.dxdx0, np.reshape(c["Sx"], (nx, nx), order="F"), rtol=1e-12, atol=1e-12)
    if u:
        np.testing.assert_allclose(res.dxdu, np.reshape(c["Su"], (nx, len(u)), order="F"), rtol=1e-12, atol=1e-12)
        assert np.abs(res.dxdu).max() > 0.1  # u really enters
    assert res.stats["steps"] == c["stats"][0] and res.stats["newton_iter"] == c["stats"][2]


@pytest.mark.parametrize("name,family,T,u", [
    ("oscillator", "radau", math.pi / 2, ()),
    ("sign-c", "radau", 2.1, ()),
    ("ocp-dynamics", "lobatto3c", 4.0, (0.1, -0.05)),
])
def test_integrate(reference, name, family, T, u):
    c = reference("integrate", name, family, 3, 1e-8, 1e-10, repr(T), *u)
    assert c["status"] == 0
    make, x0 = MODELS[name]
    with fesd.Integrator(make(), family=family, stages=3) as it:
        ua = np.array(u) if u else None
        it.set_state(0.0, x0, ua)
        it.set_tolerances(1e-8, 1e-10)
        st, info = it.integrate(T, ua)
        assert st == 0 and it.t == c["t"][0]
        np.testing.assert_allclose(it.x, c["xend"], rtol=0, atol=1e-12)
        assert [info["steps"], info["rejected"], info["newton_iter"]] == c["info"]
        _same_events(_events(it.event_log()), c["event"])


@pytest.mark.parametrize("name,t_out,u", [
    ("oscillator", (0.25, 0.5, 1.0, 1.3, math.pi / 2), ()),
    ("ocp-dynamics", (1.0, 2.0, 4.0), (0.1, -0.05)),
])
def test_integrate_grid(reference, name, t_out, u):
    c = reference("grid", name, "radau", 3, 1e-8, 1e-10, len(t_out), *map(repr, t_out), *u)
    assert c["status"] == 0
    make, x0 = MODELS[name]
    res = fesd.solve_ivp(make(), (0, t_out[-1]), x0, stages=3, rtol=1e-8, atol=1e-10, t_eval=t_out,
                         u=np.array(u) if u else None)
    assert res.status == 0
    np.testing.assert_allclose(res.t, t_out, rtol=0, atol=0)
    np.testing.assert_allclose(res.y.T, c["x"], rtol=0, atol=1e-12)
    _same_events(_events(res.switch_events), c["event"])
