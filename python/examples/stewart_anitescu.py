#!/usr/bin/env python3
"""Stewart-Anitescu (paper Sec. 5.3, Fig. ivp_problem left): V(x0) = int_0^2 x^2 dt +
(x(2) - 5/3)^2 for x' in 2 - sign(x), and dV/dx0 from the sensitivities. Gauss-Legendre s = 2,
N_FE = 25, one step over [0, 2] (as the paper and examples/stewart_anitescu.c). FESD gives V and
dV/dx0 to round-off; the standard method's V has spurious local minima. A secant shooting on
dV/dx0 from a few starts finds x0* = (9 - sqrt(417))/8 with FESD. Writes stewart_anitescu.png.

    PYTHONPATH=python python3 python/examples/stewart_anitescu.py [OUTDIR] [--quick]

--quick: 36 values of x0 and 3 starts (the test's run).
"""
import math
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fesd  # noqa: E402
from fesd import problems as P  # noqa: E402


def value(it, x0):
    it.set_state(0.0, [x0, 0.0])
    it.step(2.0)
    x, q = it.x
    Sx, _ = it.sensitivities()
    return q + (x - 5 / 3) ** 2, Sx[1, 0] + 2 * (x - 5 / 3) * Sx[0, 0]


def shoot(it, x_start, iters=50):
    xa, xb = x_start, x_start + 1e-2
    ga, gb = value(it, xa)[1], value(it, xb)[1]
    for _ in range(iters):
        if abs(gb) <= 1e-12 or gb == ga:
            break
        step = max(-1.0, min(1.0, -gb * (xb - xa) / (gb - ga)))
        xa, ga = xb, gb
        xb += step
        gb = value(it, xb)[1]
    return xb


def main(outdir=".", quick=False):
    model = P.stewart_anitescu()
    kw = dict(family="gauss", stages=2, n_fe=25, sensitivities=True)
    its = {m: fesd.Integrator(model, method=m, **kw) for m in ("fesd", "standard")}
    xs = np.linspace(-3, 0.5, 36 if quick else 141)
    exact = np.array([P.stewart_anitescu_exact(x) for x in xs])
    vals = {m: np.array([value(it, x) for x in xs]) for m, it in its.items()}
    away = np.abs(xs) > 1e-3
    for m, v in vals.items():
        print(f"{m:9s} max |V - exact| = {np.abs(v[away, 0] - exact[away, 0]).max():.1e}   "
              f"max |dV/dx0 - exact| = {np.abs(v[away, 1] - exact[away, 1]).max():.1e}")
    xstar = (9 - math.sqrt(417)) / 8
    starts = [-3.0, -1.0, 0.5] if quick else [-3.0, -2.0, -1.0, 0.0, 0.5]
    print(f"secant shooting on dV/dx0 (x0* = {xstar:.10f}):")
    for s in starts:
        print(f"  start {s:5.2f}: FESD {shoot(its['fesd'], s):.10f}   standard {shoot(its['standard'], s):.10f}")
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(xs, exact[:, 0], "k-", lw=3, alpha=0.3, label="exact")
    a2.plot(xs, exact[:, 1], "k-", lw=3, alpha=0.3, label="exact")
    for m, style in (("fesd", "C0-"), ("standard", "C3--")):
        a1.plot(xs, vals[m][:, 0], style, label=m)
        a2.plot(xs, vals[m][:, 1], style, label=m)
    a1.axvline(xstar, color="gray", lw=0.8)
    a1.set_xlabel("x0")
    a1.set_ylabel("V(x0)")
    a2.set_xlabel("x0")
    a2.set_ylabel("dV/dx0")
    a1.legend()
    a2.legend()
    fig.suptitle("Stewart-Anitescu, Gauss-Legendre s=2, N_FE=25, one step")
    path = os.path.join(outdir, "stewart_anitescu.png")
    fig.savefig(path, dpi=120)
    print("wrote", path)
    return path


if __name__ == "__main__":
    main(*[a for a in sys.argv[1:2] if a != "--quick"], quick="--quick" in sys.argv)
