#!/usr/bin/env python3
"""Python overhead per step: the oscillator (Radau IIA s = 3, N_FE = 2, 40 fixed steps over
[0, pi/2], one crossing) with Python callbacks against the same model in C
(src/problems/problems.c, timed by python/tests/reference.c "time"). CPU time of the thread,
best of REPS integrations (fesd_set_state + 40 fesd_step). Also counts the library's callback
calls per step (C -> Python) and the Python model calls per step.

    PYTHONPATH=python python3 python/bench/overhead.py [REPS]   (after meson compile -C build)
"""
import math
import os
import subprocess
import sys
import time

import numpy as np

import fesd
from fesd import problems as P
from fesd._callbacks import Bridge

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
T, NSIM, S = math.pi / 2, 40, 3
W = 2 * math.pi


def per_mode_oscillator():
    """The oscillator with one Python call per mode (field=, field_jac=)."""
    def field(mode, t, x, u):
        s = 1.0 if mode == 0 else -1.0
        return np.array([x[0] + s * W * x[1], -s * W * x[0] + x[1]])

    def field_jac(mode, t, x, u):
        s = 1.0 if mode == 0 else -1.0
        return np.array([[1.0, s * W], [-s * W, 1.0]])
    sub = fesd.Subsystem(2, field=field, field_jac=field_jac, switch=lambda t, x, u: x[0] ** 2 + x[1] ** 2 - 1,
                         switch_jac=lambda t, x, u: np.array([[2 * x[0], 2 * x[1]]]))
    return fesd.Model(2, [sub])


def c_baseline(reps):
    exe = os.environ.get("FESD_PY_REFERENCE", os.path.join(ROOT, "build", "python", "fesd_py_reference"))
    out = subprocess.run([exe, "time", "oscillator", "radau", str(S), str(NSIM), repr(T), str(reps)], check=True,
                         capture_output=True, text=True).stdout
    rec = dict(line.split(" ", 1) for line in out.splitlines())
    return float(rec["us_per_step"]), np.array(rec["xend"].split(), dtype=float)


def python_time(model, reps):
    it = fesd.Integrator(model, stages=S)
    best = math.inf
    for _ in range(reps):
        t0 = time.thread_time()
        it.set_state(0.0, P.OSCILLATOR_X0)
        for _ in range(NSIM):
            it.step(T / NSIM)
        best = min(best, (time.thread_time() - t0) / NSIM * 1e6)
    return best, it.x


def call_counts(model):
    """(library callback calls, Python model calls) per step."""
    lib_calls, py_calls = [0], [0]
    names = ("_field", "_field_jac", "_switch", "_switch_jac")
    saved = {n: getattr(Bridge, n) for n in names}

    def counting(orig):
        def f(self, *a):
            lib_calls[0] += 1
            return orig(self, *a)
        return f
    sub = model.subsystems[0]
    for attr in ("fields", "field", "fields_jac", "field_jac", "switch", "switch_jac"):
        fn = getattr(sub, attr)
        if fn is not None:
            def wrapped(*a, _fn=fn):
                py_calls[0] += 1
                return _fn(*a)
            setattr(sub, attr, wrapped)
    try:
        for n in names:
            setattr(Bridge, n, counting(saved[n]))
        python_time(model, 1)
    finally:
        for n in names:
            setattr(Bridge, n, saved[n])
    return lib_calls[0] / NSIM, py_calls[0] / NSIM


def main(reps=20):
    reps = int(reps)
    c_us, c_x = c_baseline(reps)
    print(f"oscillator, Radau IIA s={S}, N_FE=2, {NSIM} steps; CPU time per step, best of {reps}")
    print(f"{'model':44s} {'us/step':>9s} {'vs C':>6s} {'lib calls':>9s} {'py calls':>8s}  max |x - x_C|")
    print(f"{'C callbacks (src/problems)':44s} {c_us:9.1f} {1.0:6.0f}")
    for label, make in (("Python, vectorised fields + Jacobians", P.oscillator),
                        ("Python, per-mode field + Jacobians", per_mode_oscillator),
                        ("Python, vectorised fields, no Jacobians (FD)", lambda: P.oscillator(jacobians=False))):
        us, x = python_time(make(), reps)
        lib, py = call_counts(make())
        print(f"{label:44s} {us:9.1f} {us / c_us:6.0f} {lib:9.1f} {py:8.1f}  {np.abs(x - c_x).max():.1e}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
