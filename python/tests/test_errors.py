"""Faults in Python callables: an exception, a wrong shape, a NaN. The library fails the step
(FESD_ERR_CALLBACK / FESD_ERR_NONFINITE, or gives up on the step after that), Python raises
CallbackError naming the callable, with the library's status text and the original exception
as __cause__; the integrator stays usable: the state is the one before the failed call and a
later step gives what a clean run gives."""
import math

import numpy as np
import pytest

import fesd
from fesd import problems as P


def faulty_oscillator(fault, where="fields", t_bad=0.5):
    """The oscillator with a fault switched on by fault["on"] for t >= t_bad (time as seen by
    the callable: the model is time dependent so that t is the stage time)."""
    good = P.oscillator()
    sub = good.subsystems[0]

    def wrap(fn, role):
        def f(t, x, u):
            if fault["on"] and where == role and t >= t_bad:
                kind = fault["kind"]
                if kind == "raise":
                    raise ZeroDivisionError("boom in the model")
                if kind == "shape":
                    return np.zeros(7)
                if kind == "nan":
                    out = np.array(fn(t, x, u), dtype=float)
                    out.flat[0] = math.nan
                    return out
            return fn(t, x, u)
        return f
    s2 = fesd.Subsystem(2, fields=wrap(sub.fields, "fields"), switch=wrap(sub.switch, "switch"),
                        fields_jac=wrap(sub.fields_jac, "fields_jac"), switch_jac=wrap(sub.switch_jac, "switch_jac"))
    return fesd.Model(2, [s2], time_dependent=True)


@pytest.mark.parametrize("kind,where,status", [
    ("raise", "fields", "FESD_ERR_CALLBACK"), ("raise", "switch", "FESD_ERR_CALLBACK"),
    ("raise", "fields_jac", "FESD_ERR_CALLBACK"), ("shape", "fields", "FESD_ERR_CALLBACK"),
    ("shape", "switch_jac", "FESD_ERR_CALLBACK"), ("nan", "fields", "FESD_ERR_NONFINITE"),
    ("nan", "switch", "FESD_ERR_NONFINITE"),
])
def test_fixed_step_fault(kind, where, status):
    fault = {"on": False, "kind": kind}
    model = faulty_oscillator(fault, where)
    clean = fesd.Integrator(P.oscillator(), stages=3)
    clean.set_state(0.0, P.OSCILLATOR_X0)
    it = fesd.Integrator(model, stages=3)
    it.set_state(0.0, P.OSCILLATOR_X0)
    h = 0.1
    for _ in range(4):  # to t = 0.4
        it.step(h)
        clean.step(h)
    fault["on"] = True
    t_before, x_before = it.t, it.x
    with pytest.raises(fesd.CallbackError) as ei:
        it.step(h)  # stages beyond t = 0.5
    err = ei.value
    assert err.status_name == status and err.status_text == fesd.status_string(err.status)
    assert err.callback == where and err.sys == 0 and err.t >= 0.5
    assert where in str(err) and status in str(err)
    cause = err.__cause__
    expected = {"raise": ZeroDivisionError, "shape": fesd.OutputShapeError, "nan": fesd.NonFiniteOutputError}[kind]
    assert isinstance(cause, expected)
    # the integrator is usable: unchanged state, and the same step without the fault is the clean one
    assert it.t == t_before and np.array_equal(it.x, x_before)
    fault["on"] = False
    it.step(h)
    clean.step(h)
    assert it.t == clean.t
    np.testing.assert_allclose(it.x, clean.x, rtol=0, atol=1e-13)


@pytest.mark.parametrize("kind", ["raise", "shape", "nan"])
def test_solve_ivp_fault(kind):
    fault = {"on": True, "kind": kind}
    model = faulty_oscillator(fault, "fields", t_bad=0.3)
    with pytest.raises(fesd.CallbackError) as ei:
        fesd.solve_ivp(model, (0, 1.0), P.OSCILLATOR_X0, stages=3, rtol=1e-6)
    assert ei.value.callback == "fields" and ei.value.t >= 0.3 and ei.value.__cause__ is not None
    # the same model without the fault runs through
    fault["on"] = False
    res = fesd.solve_ivp(model, (0, 1.0), P.OSCILLATOR_X0, stages=3, rtol=1e-6)
    assert res.success and abs(res.t[-1] - 1.0) < 1e-14


def test_integrate_fault_keeps_last_state():
    fault = {"on": True, "kind": "raise"}
    it = fesd.Integrator(faulty_oscillator(fault, "switch", t_bad=0.6), stages=3)
    it.set_state(0.0, P.OSCILLATOR_X0)
    it.set_tolerances(1e-8, 1e-10)
    with pytest.raises(fesd.CallbackError) as ei:
        it.integrate(1.5)
    assert ei.value.status_name == "FESD_ERR_CALLBACK" and ei.value.callback == "switch"
    assert "the library names callback 'switch'" in str(ei.value) or "switch" in str(ei.value)
    t_fail = it.t
    assert 0 < t_fail < 0.6
    np.testing.assert_allclose(it.x, P.oscillator_exact(t_fail), atol=1e-7)
    fault["on"] = False
    st, info = it.integrate(1.5)
    assert st == 0 and it.t == 1.5
    np.testing.assert_allclose(it.x, P.oscillator_exact(1.5), atol=1e-6)


def test_drift_and_event_faults_are_named():
    model = fesd.Model(1, [fesd.Subsystem(2, fields=lambda t, x, u: [[-1.0], [1.0]], switch=lambda t, x, u: x)],
                       drift=lambda t, x, u: [1 / 0 if t > 0.2 else 0.0], time_dependent=True)
    with pytest.raises(fesd.CallbackError) as ei:
        fesd.solve_ivp(model, (0, 1), [1.0], h=0.1)
    assert ei.value.callback == "drift" and isinstance(ei.value.__cause__, ZeroDivisionError)
    model = fesd.Model(1, [fesd.Subsystem(2, fields=lambda t, x, u: [[-1.0], [1.0]], switch=lambda t, x, u: x)])
    with pytest.raises(fesd.CallbackError) as ei:
        fesd.solve_ivp(model, (0, 1), [1.0], h=0.1, events=[lambda t, x, u: [1.0, 2.0]])
    assert ei.value.callback == "events" and isinstance(ei.value.__cause__, fesd.OutputShapeError)


def test_keyboard_interrupt_passes_through():
    def fields(t, x, u):
        raise KeyboardInterrupt
    model = fesd.Model(1, [fesd.Subsystem(2, fields=fields, switch=lambda t, x, u: x)])
    with pytest.raises(KeyboardInterrupt):
        fesd.solve_ivp(model, (0, 1), [1.0], h=0.5)


def test_bad_arguments():
    m = P.oscillator()
    with pytest.raises(ValueError, match="t_span"):
        fesd.solve_ivp(m, (1, 0), P.OSCILLATOR_X0)
    with pytest.raises(ValueError, match="x0 has 3"):
        fesd.solve_ivp(m, (0, 1), [1, 2, 3])
    with pytest.raises(ValueError, match="rtol"):
        fesd.solve_ivp(m, (0, 1), P.OSCILLATOR_X0, h=0.1, rtol=1e-3)
    with pytest.raises(TypeError, match="unknown setting"):
        fesd.Integrator(m, bogus=1)
    with pytest.raises(fesd.FesdError, match="FESD_ERR_UNSUPPORTED_TABLEAU"):
        fesd.Integrator(m, family="explicit", stages=7)
    with pytest.raises(fesd.FesdError, match="FESD_ERR_INVALID_ARG"):
        fesd.Integrator(m, newton_tol=1.0)
    with pytest.raises(ValueError, match="power of 2"):
        fesd.Subsystem(3, fields=lambda t, x, u: 0, switch=lambda t, x, u: 0)
    with pytest.raises(ValueError, match="u="):
        fesd.solve_ivp(P.ocp_dynamics(), (0, 1), P.OCP_X0)
    # a control for a model without controls was ignored; max_steps = 0 returned status -1
    with pytest.raises(ValueError, match="nu = 0"):
        fesd.solve_ivp(m, (0, 1), P.OSCILLATOR_X0, u=[1.0])
    with pytest.raises(ValueError, match="max_steps"):
        fesd.solve_ivp(m, (0, 1), P.OSCILLATOR_X0, max_steps=0)
